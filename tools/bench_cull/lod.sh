#!/usr/bin/env bash
# Level of detail against speed (docs/virtual-geometry.md): the temple at scales S baked with and without
# its cluster hierarchy (bake times), then per size, view and --lod-error one rtr-view run that times FRAMES
# frames (per pass, clusters and triangles listed) and writes a screenshot, whose error against
# --lod-error 0 `rtr-frame-compare --flip` prints: the ꟻLIP-style mean (docs/flip.md) and the largest channel
# difference's mean and max (the shaded image: debug views such as normals are drawn by the forward path,
# always at full detail).
#   tools/bench_cull/lod.sh DIR > out.txt    DIR: a bundle (tools/bundle_device.sh, has run.sh) or a build
#                                            folder (has bin/rtr-view)
# Settings (environment), fast by default (a few minutes on the GPU machine):
#   SCALES="100"  SIZES="3840x2160"  VIEWS="stored inside outside"  LODS="0 0.25 0.5 1 2 4"
#   CULLS="off"   FRAMES=30          OUT=/tmp/lod
set -u
if [ -x "$1/run.sh" ]; then R=("$1/run.sh"); else R=(); B="$1/bin/"; fi
run() { "${R[@]}" "${B:-}$1" "${@:2}"; }
OUT=${OUT:-/tmp/lod}
for S in ${SCALES:-100}; do
  run scenegen --scale $S --out $OUT/s$S >/dev/null 2>&1
  echo "== bake S=$S (without and with the hierarchy)"
  run rtr-bake $OUT/s$S/temple.obj.zst $OUT/s$S/plain.rtrscene --force --no-lod --view 0,2.2,-2.5,0,-3 2>&1 | grep -E "time|output"
  run rtr-bake $OUT/s$S/temple.obj.zst $OUT/s$S/t.rtrscene --force --view 0,2.2,-2.5,0,-3 2>&1 | grep -E "time|output"
done
for S in ${SCALES:-100}; do for size in ${SIZES:-3840x2160}; do for view in ${VIEWS:-stored inside outside}; do
  case $view in
    stored) cam=() ;;                                          # the baked view
    inside) cam=(--camera 0,1.5,0,30,-5) ;;                   # in the courtyard, looking along it
    outside) cam=(--camera 16.34,17.74,16.06,30,-25) ;;       # orbitFrame, yaw 30, pitch -25
    *) echo "unknown view $view (stored, inside, outside)" >&2; exit 2 ;;
  esac
  for cull in ${CULLS:-off}; do for lod in ${LODS:-0 0.25 0.5 1 2 4}; do
    echo "== S=$S $size $view --cull $cull --lod-error $lod"
    out=$OUT/s$S-$size-$view-$cull-$lod.png
    run rtr-view $OUT/s$S/t.rtrscene --headless --size $size --bench ${FRAMES:-30} --raster compute \
      --shading-path visibility --cull $cull --lod-error $lod "${cam[@]}" --screenshot $out --force 2>&1 | grep -v -E "^csv|^/|^rtr-view|ms GPU$"
    base=$OUT/s$S-$size-$view-$cull-0.png
    [ "$lod" != 0 ] && [ -f $base ] && echo "image error shaded: $(run rtr-frame-compare --flip $base $out 2>&1)"
  done; done
done; done; done
