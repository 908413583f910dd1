#!/usr/bin/env bash
# The main job: set up a fresh Debian 12 machine, build, and render the bundled default scene headless
# (no window, no display) to a PNG, printing its path. Extra arguments go to rtr-view.
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)" --target rtr-view rtr_shaders assets
mkdir -p out
exec build/release/bin/rtr-view build/release/assets/temple.rtrscene --headless --size 1920x1080 --mosaic compute \
  --screenshot out/temple.png --force "$@"
