#!/usr/bin/env bash
# The main job: set up a fresh Debian 12 machine, build, and render the bundled default scene headless
# (no window, no display): out/temple.png, the scene as it is, and out/temple-mosaic.png, the same frame
# through the 5x3 mosaic post-process the course's assignment asks for. Prints both paths. Extra
# arguments go to rtr-view (both renders).
set -euo pipefail
cd "$(dirname "$0")/.."
bash tools/setup.sh
cmake --preset release >/dev/null
cmake --build --preset release -j "$(nproc)" --target rtr-view rtr_shaders assets
mkdir -p out
view=(build/release/bin/rtr-view build/release/assets/temple.rtrscene --headless --size 1920x1080 --force)
"${view[@]}" --screenshot out/temple.png "$@"
"${view[@]}" --mosaic compute --screenshot out/temple-mosaic.png "$@"
