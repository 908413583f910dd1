#!/usr/bin/env bash
# Level of detail against speed (docs/virtual-geometry.md): the temple at scales S baked with its cluster
# hierarchy, then per size, view and --lod-error: rtr-view --bench 50 (frame time per pass, clusters and
# triangles listed) and a screenshot, whose error against --lod-error 0 pngdiff.py prints (the shaded view:
# debug views such as normals are drawn by the forward path, always at full detail). Runs from a bundle (tools/bundle_device.sh): tools/bench_cull/lod.sh BUNDLE_DIR [S...] > out.txt
set -u
R="$1/run.sh"
shift
SCALES="${*:-1 100 1000}"
D=$(dirname "$0")
for S in $SCALES; do
  $R scenegen --scale $S --out /tmp/lod/s$S >/dev/null 2>&1
  echo "== bake S=$S (with and without the hierarchy)"
  $R rtr-bake /tmp/lod/s$S/temple.obj.zst /tmp/lod/s$S/plain.rtrscene --force --no-lod --view 0,2.2,-2.5,0,-3 2>&1 | grep -E "time|output"
  $R rtr-bake /tmp/lod/s$S/temple.obj.zst /tmp/lod/s$S/t.rtrscene --force --view 0,2.2,-2.5,0,-3 2>&1 | grep -E "time|output"
done
for S in $SCALES; do for size in ${SIZES:-3840x2160 1920x1080}; do for view in inside outside; do
  cam=""; [ $view = outside ] && cam="--camera 16.34,17.74,16.06,30,-25"  # orbitFrame, yaw 30, pitch -25
  for cull in off on; do for lod in 0 0.25 0.5 1 2 4; do
    echo "== S=$S $size $view --cull $cull --lod-error $lod"
    out=/tmp/lod/s$S-$size-$view-$cull-$lod
    $R rtr-view /tmp/lod/s$S/t.rtrscene --headless --size $size --bench ${FRAMES:-50} --raster compute --shading-path visibility \
      --cull $cull --lod-error $lod $cam 2>&1 | grep -v "^csv"
    [ $cull = on ] && continue
    $R rtr-view /tmp/lod/s$S/t.rtrscene --headless --size $size --raster compute --shading-path visibility --lod-error $lod \
      $cam --screenshot $out.png >/dev/null 2>&1
    base=/tmp/lod/s$S-$size-$view-off-0
    echo "image error shaded: $(python3 $D/pngdiff.py $base.png $out.png)"
  done; done
done; done; done
