#!/usr/bin/env bash
# Runs every benchmark and comparison of docs/BENCHMARKS.md on this machine and keeps their raw output:
# OUT/<row>.txt (stdout + stderr of one command, the command on its first line) and OUT/meta.txt (machine,
# driver, date). tools/report/render.py turns the folders of all machines into the report.
#
#   tools/report/collect.sh OUT [--quick] [--runner CMD] [--skip LIST]
#     --runner CMD  how to start a binary: "CMD NAME ARGS" (e.g. .device/run.sh on the GPU machine);
#                   default: build/release/bin/NAME
#     --quick       fewer frames and runs (lavapipe at 4K takes about a second a frame)
#     --skip LIST   comma-separated row groups to leave out: gpu,frame,big,compare,env,trace,bake,startup,load,textures,scale
# The rows and their exact arguments are fixed here, so a rerun measures the same thing (fixed seeds and
# poses: tests/reference/poses.txt, the generated scenes).
set -uo pipefail
out=${1:?usage: collect.sh OUT [--quick] [--runner CMD] [--skip LIST]}
shift
runner="" quick=0 skip=""
while (($#)); do
  case $1 in
    --quick) quick=1 ;;
    --runner) runner=$2; shift ;;
    --skip) skip=$2; shift ;;
    *) echo "collect.sh: unknown option $1" >&2; exit 2 ;;
  esac
  shift
done
root=$(cd "$(dirname "$0")/../.." && pwd)
mkdir -p "$out"
out=$(cd "$out" && pwd)
bin() {  # bin NAME ARGS...; with timed=1, under /usr/bin/time -v (wall, CPU, peak memory)
  local t=()
  [[ ${timed:-0} == 1 ]] && t=(/usr/bin/time -v)
  if [[ -n $runner ]]; then "${t[@]}" "$runner" "$@"; else "${t[@]}" "$root/build/release/bin/$1" "${@:2}"; fi
}
skipped() { [[ ",$skip," == *",$1,"* ]]; }
# tool NAME ARGS...: a program from outside this build (gltfpack): the bundle's copy, else this machine's.
tool() {
  if [[ -n $runner ]] && "$runner" "$@" 2>/dev/null; then return 0; fi
  command -v "$1" >/dev/null && "$@"
}
# row ID NAME ARGS...: runs one command, its output to $out/ID.txt; a failure is recorded, not fatal.
row() {
  local id=$1; shift
  local t0=$SECONDS
  local shown="$*"
  shown=${shown//$root\//}  # paths relative to the repository, as a reader re-runs them
  { echo "\$ $shown"; bin "$@" 2>&1; echo "# exit $? after $((SECONDS - t0)) s"; } >"$out/$id.txt"
  echo "collect: $id ($((SECONDS - t0)) s)" >&2
}

if ((quick)); then runs=5 warm=2 frames=5 cmpframes=5; else runs=50 warm=10 frames=100 cmpframes=50; fi
assets=${RTR_ASSET_DIR:-$root/build/release/assets}
temple=$assets/temple.rtrscene
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT

{
  echo "date: $(date -u +%Y-%m-%dT%H:%MZ)"
  echo "host: $(uname -srm)"
  echo "cpu: $(grep -m1 'model name' /proc/cpuinfo | cut -d: -f2- | sed 's/^ *//') ($(nproc) threads)"
  command -v nvidia-smi >/dev/null && echo "gpu: $(nvidia-smi --query-gpu=name,driver_version,clocks.max.sm --format=csv,noheader)"
  echo "commit: ${RTR_COMMIT:-$(git -C "$root" rev-parse --short HEAD 2>/dev/null || echo unknown)}"
  echo "quick: $quick"
} >"$out/meta.txt"
# The Vulkan device and driver, as the renderer sees them.
bin rtr-view "$temple" --headless --size 64x64 --screenshot "$work/meta.png" 2>&1 | grep -m1 ' on ' | sed 's/^/vulkan: /' >>"$out/meta.txt"

if ! skipped gpu; then
  row gpu-passes rtr-bench-gpu --runs $runs --warmup $warm
fi
# Whole frame per pass: PBR (visibility path, the default; forward) + mosaic (both post paths), and the
# plain textured (mode 13) baseline.
frame_rows() {  # frame_rows TAG SCENE SIZES...
  local tag=$1 scene=$2; shift 2
  for size in "$@"; do
    row "frame-$tag-$size-pbr" rtr-view "$scene" --headless --size "$size" --bench $frames --mosaic compute --shading-path visibility
    row "frame-$tag-$size-pbr-forward" rtr-view "$scene" --headless --size "$size" --bench $frames --shading-path forward --mosaic compute
    # The same with light from the generated sky (--env: split-sum shading and the backdrop; its
    # prefiltering is said on stderr, outside the frame).
    row "frame-$tag-$size-pbr-env" rtr-view "$scene" --headless --size "$size" --bench $frames --mosaic compute --shading-path visibility --env sky
    row "frame-$tag-$size-pbr-graphics" rtr-view "$scene" --headless --size "$size" --bench $frames --mosaic graphics --shading-path visibility
    row "frame-$tag-$size-textured" rtr-view "$scene" --headless --size "$size" --bench $frames --mode 13 --mosaic compute
  done
}
if ! skipped frame; then
  frame_rows default "$temple" 1920x1080 3840x2160
  # rtr-view's own defaults (visibility path, compute rasteriser on a GPU, no mosaic: the shading pass writes
  # the display), the default temple at 4K in the three views of issue 30's goal (<= 0.35 ms)
  for v in "display" "display-inside --camera 0,1.5,0,30,-5" "display-outside --camera 0,3,8,0,-15"; do
    read -r name cam <<<"$v"
    row "frame-default-3840x2160-$name" rtr-view "$temple" --headless --size 3840x2160 --bench $frames --timings $cam
  done
fi
if ! skipped big; then  # the Sun-Temple-size version of the default scene
  bin scenegen --out "$work/big" --scale 100 >/dev/null 2>&1 &&
    bin rtr-bake "$work/big/temple.obj.zst" "$work/big/temple.rtrscene" --view 0,2.2,-2.5,0,-3 >"$out/bake-big.txt" 2>&1 &&
    frame_rows big "$work/big/temple.rtrscene" 1920x1080 3840x2160
fi
if ! skipped compare; then  # GPU raster vs CPU trace, same view and shading model, with the image error
  row frame-compare rtr-frame-compare --size 1920x1080 --frames $cmpframes
fi
if ! skipped env; then  # light from the sky: the GPU's split sum vs the tracer converged (1024 sample pairs a
  # pixel; its noise is in the table), and the tracer's error against its sample count (docs/environment.md)
  if ((quick)); then envsize=320x180 envref=1024; else envsize=640x360 envref=4096; fi
  row env-compare rtr-frame-compare --env-cases --size $envsize --spp 1024 --frames $cmpframes
  row env-spp rtr-frame-compare --spp-curve env_sphere_grid --size $envsize --spp $envref
fi
if ! skipped trace; then  # tracer vs Embree on the 1M-triangle sphere and the Sun-Temple-size scene,
  # 1 thread and every core, plus the ray-triangle routines alone (one run of bench-trace does all);
  # --alone-sweep: our packets also timed with each hand-off threshold (docs/bench/trace.md, round 12)
  bin scenegen --out "$work/plain" --scale 100 --plain >/dev/null 2>&1 &&
    row trace bench-trace --threads "$(nproc)" --scene "$work/plain/temple.obj" --alone-sweep 1,2,4,6
fi
if ! skipped bake; then  # ours vs tinyobjloader on the 175 MB temple (scale 300)
  if bin scenegen --out "$work/bake" --scale 300 --plain >/dev/null 2>&1 &&
     bin scenegen --out "$work/bake" --scale 300 >/dev/null 2>&1; then
    RTR_BENCH_OBJ="$work/bake/temple.obj" row bake bench_bake --benchmark_min_time=$((quick ? 1 : 3))
  fi
fi
if ! skipped startup; then  # start-up phases (--timings) at 4K: the default temple and generated 1M/3M/10M
  # scenes baked with a stored view, each cold (an empty pipeline cache) and then warm (the cache filled)
  sc=$work/startup
  for s in 100 300 1000; do
    bin scenegen --out "$sc/s$s" --scale $s >/dev/null 2>&1 &&
      bin rtr-bake "$sc/s$s/temple.obj.zst" "$sc/s$s/temple.rtrscene" --view 0,2.2,-2.5,0,-3 >/dev/null 2>&1
  done
  sync  # the bakes' written pages out to disk first: their write-back would run during the timed starts
  for s in default 100 300 1000; do
    scene=$sc/s$s/temple.rtrscene
    [[ $s == default ]] && scene=$temple
    [[ -f $scene ]] || continue
    rm -rf "$sc/cache"
    for run in cold warm; do
      RTR_PIPELINE_CACHE=$sc/cache row "startup-$s-$run" rtr-view "$scene" --headless --size 3840x2160 --timings \
        --screenshot "$work/startup.png" --force
    done
  done
fi
if ! skipped textures; then  # start-up of a 200-texture scene (issue 29): PNG files, lossless and BC
  # baked chains (rtr-bake --textures), first frame with the textures in, warm pipeline cache
  tx=$work/tex
  if bin scenegen --out "$tx" --textures $((quick ? 4 : 200)) >/dev/null 2>&1; then
    for form in files lossless bc; do
      mkdir -p "$tx/$form"
      row "textures-bake-$form" rtr-bake "$tx/temple.obj.zst" "$tx/$form/temple.rtrscene" --textures $form
      du -sb "$tx/$form" >>"$out/textures-bake-$form.txt" 2>/dev/null || true
      [[ -f $tx/$form/temple.rtrscene ]] || continue
      for run in 1 2 3; do  # the texture cache off: the files rows are the PNG path every time
        RTR_TEXTURE_CACHE=off RTR_PIPELINE_CACHE=$tx/cache row "textures-$form-$run" rtr-view "$tx/$form/temple.rtrscene" \
          --headless --size 1920x1080 --timings --wait-textures --screenshot "$work/tex-$form.png" --force
      done
    done
    # The OBJ opened directly, three times with an emptied texture cache: the first open decodes and fills
    # it, the second and third read it (docs/startup.md, "Texture cache").
    for round in 1 2 3; do
      rm -rf "$tx/tcache"
      for open in first second; do
        RTR_TEXTURE_CACHE=$tx/tcache RTR_PIPELINE_CACHE=$tx/cache row "textures-direct-$open-$round" rtr-view \
          "$tx/temple.obj.zst" --headless --size 1920x1080 --timings --wait-textures --screenshot "$work/tex-direct.png" --force
      done
    done
  fi
fi
if ! skipped load; then  # time to the scene in memory: the 1M-triangle temple as .rtrscene, OBJ, GLB and
  # meshopt GLB (gltfpack -cc), the meshopt decode rate, and `assimp info` on the GLBs, in one run
  ld=$work/load
  if bin scenegen --out "$ld" --scale 100 --plain >/dev/null 2>&1 &&
     bin rtr-bake "$ld/temple.obj" "$ld/temple.rtrscene" >/dev/null 2>&1; then
    glbs=() note=""
    if tool gltfpack -i "$ld/temple.obj" -o "$ld/temple.glb" >/dev/null 2>&1 &&
       tool gltfpack -i "$ld/temple.obj" -o "$ld/temple-cc.glb" -cc >/dev/null 2>&1; then
      glbs=("$ld/temple.glb" "$ld/temple-cc.glb")
    else
      note="# gltfpack is neither in the bundle nor on this machine: no GLB rows (tools/setup.sh installs it)"
    fi
    row load bench-load --runs $((quick ? 3 : 10)) "$ld/temple.rtrscene" "$ld/temple.obj" "${glbs[@]}"
    [[ -z $note ]] || echo "$note" >>"$out/load.txt"
  fi
fi
if ! skipped scale; then  # issues 29 and 30 at scale: the temple at 100M triangles (quick: 10M) baked without
  # and with the hierarchy (phases, CPU, peak memory), its start-up and frames by view and level of detail,
  # and 100 instances of the 10M temple (quick: of the 1M) against their base mesh alone
  sd=$work/scale big=$((quick ? 1000 : 10000)) base=$((quick ? 100 : 1000))
  size=$([[ $quick == 1 ]] && echo 1920x1080 || echo 3840x2160)
  views=("stored" "inside --camera 0,1.5,0,30,-5" "outside --camera 0,3,8,0,-15")
  frame() {  # frame ID SCENE [ARGS...]: one --bench row at each level of detail, full detail and 1 px, two-phase
    # culling; and 1 px with one culling pass (frustum and cones, no pyramid: ID-1f)
    local id=$1 scene=$2; shift 2
    local f=(rtr-view "$scene" --headless --size "$size" --bench $((quick ? 3 : 50)) --timings --shading-path visibility --raster compute)
    for e in 0 1; do
      row "$id-$e" "${f[@]}" --cull on --lod-error $e "$@"
    done
    row "$id-1f" "${f[@]}" --cull frustum --lod-error 1 "$@"
  }
  if bin scenegen --out "$sd/big" --scale $big >/dev/null 2>&1; then
    sync  # the OBJ written out before the timed bakes read it
    timed=1 row "scale-bake-$big-nolod" rtr-bake "$sd/big/temple.obj.zst" "$sd/big/nolod.rtrscene" --no-lod --view 0,2.2,-2.5,0,-3
    ls -l "$sd/big/nolod.rtrscene" >>"$out/scale-bake-$big-nolod.txt"
    rm -f "$sd/big/nolod.rtrscene"
    timed=1 row "scale-bake-$big-lod" rtr-bake "$sd/big/temple.obj.zst" "$sd/big/temple.rtrscene" --view 0,2.2,-2.5,0,-3
    ls -l "$sd/big/temple.rtrscene" >>"$out/scale-bake-$big-lod.txt"
    rm -f "$sd/big/temple.obj.zst"
    if ((!quick)); then  # the startup group's rows, one scale up (quick runs have 10M there already)
      sync  # the 4.4 GB just written out first (on the H200 host its write-back doubled the start: 1.46 s)
      rm -rf "$sd/cache"
      for run in cold warm; do
        RTR_PIPELINE_CACHE=$sd/cache row "startup-$big-$run" rtr-view "$sd/big/temple.rtrscene" --headless \
          --size 3840x2160 --timings --screenshot "$work/startup.png" --force
      done
    fi
    for v in "${views[@]}"; do
      read -r name cam <<<"$v"
      frame "scale-frame-$big-$name" "$sd/big/temple.rtrscene" $cam
    done
    rm -rf "$sd/big"
  fi
  if bin scenegen --out "$sd/grid" --scale $base --instances 100 >"$out/scale-grid-gen.txt" 2>&1 &&
     bin rtr-bake "$sd/grid/temple.obj.zst" "$sd/grid/temple.rtrscene" --view 0,2.2,-2.5,0,-3 >/dev/null 2>&1; then
    frame "scale-frame-$base-stored" "$sd/grid/temple.rtrscene"
    for v in "stored" "inside --camera 0,1.5,0,30,-5" "outside --camera 16.34,17.74,16.06,30,-25"; do
      read -r name cam <<<"$v"
      frame "scale-frame-grid$base-$name" "$sd/grid/temple-grid.rtrscene" $cam
    done
  fi
fi
echo "collect: done -> $out" >&2
