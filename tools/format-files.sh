#!/bin/bash
# The C++ files that tools/test.sh holds to .clang-format (clang-format --dry-run --Werror).
# Until the one mass format, the allow-list (tools/format-allowlist.txt); the mass format is
# `ALL=1 tools/format-files.sh | xargs clang-format -i`, after which the flip below makes every file count.
set -euo pipefail
cd "$(dirname "$0")/.."
ALL=${ALL:-0}  # the flip after the mass format: ALL=${ALL:-1}
if [[ $ALL == 1 ]]; then
  git ls-files 'src/*' 'tools/*' 'tests/*' 'bake/*' | grep -E '\.(cpp|hpp|h|inl)$'
else
  grep -v '^#' tools/format-allowlist.txt
fi
