#!/bin/bash
# The C++ files that tools/test.sh holds to .clang-format (clang-format --dry-run --Werror): every
# C++ file of src, tools, tests and bake. GLSL (shaders/, shared headers included) is not held to it.
set -euo pipefail
cd "$(dirname "$0")/.."
git ls-files 'src/*' 'tools/*' 'tests/*' 'bake/*' | grep -E '\.(cpp|hpp|h|inl)$'
