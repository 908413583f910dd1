#!/usr/bin/env bash
# Sets up a fresh Debian 12 machine, builds everything and runs every test (Vulkan tests on lavapipe
# with the validation layer; any validation message fails a test). Usage: tools/test.sh [ctest args]
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
# The files that follow .clang-format stay so (every C++ file tools/format-files.sh lists).
tools/format-files.sh | xargs clang-format --dry-run --Werror
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)"
export RTR_VALIDATION=1
# Tests that want a texture cache name their own temporary folder; no run writes to the user's.
export RTR_TEXTURE_CACHE=off
# The tests run headless; no display is needed. The windowed test starts its own Xvfb.
ctest --preset release -j "$(nproc)" "$@"
# A short libFuzzer run of every decoder (scenes, OBJ/MTL, textures, poses, SPIR-V; clang, ASan + UBSan,
# docs/fuzzing.md) that first replays every crash input found so far. RTR_FUZZ_SECONDS=0 skips it.
if [[ ${RTR_FUZZ_SECONDS:-15} -gt 0 ]]; then bash tests/fuzz/run.sh "${RTR_FUZZ_SECONDS:-15}"; fi
