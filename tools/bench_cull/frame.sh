#!/usr/bin/env bash
# The culled frame against the unculled one and the hardware (docs/raster.md, "With cluster culling"):
# scenes S = 1, 100, 1000 generated and baked, then rtr-view --bench 50 per scene, size, view, rasteriser
# and --cull. Runs from a bundle (tools/bundle_device.sh): tools/bench_cull/frame.sh BUNDLE_DIR > out.txt
set -u
R="$1/run.sh"
for S in 1 100 1000; do
  $R scenegen --scale $S --out /tmp/sc/s$S >/dev/null 2>&1
  $R rtr-bake /tmp/sc/s$S/temple.obj.zst /tmp/sc/s$S/t.rtrscene --view 0,2.2,-2.5,0,-3 --light -0.2972,7.3100,-11.9532 >/dev/null 2>&1
done
for S in 1 100 1000; do for size in 3840x2160 1920x1080; do for view in inside outside; do
  cam=""; [ $view = outside ] && cam="--camera 16.34,17.74,16.06,30,-25"  # orbitFrame, yaw 30, pitch -25
  for mode in "hardware" "compute --cull off" "compute --cull on"; do
    echo "== S=$S $size $view $mode"
    $R rtr-view /tmp/sc/s$S/t.rtrscene --headless --size $size --bench 50 --shading-path visibility $cam --raster $mode 2>&1 | grep -v "^csv"
  done
done; done; done
