#!/bin/sh
# Runs the libFuzzer targets: tests/fuzz/run.sh SECONDS [TARGET...] (default 15 s each, all targets, one
# after the other: CI's short step). RTR_FUZZ_CORES=N instead runs all targets at once for SECONDS on N
# cores (libFuzzer -fork, crashes collected and fuzzing goes on; slow targets get more processes): the
# long run, see docs/fuzzing.md.
# Each target first replays tests/fuzz/crashes/TARGET/* (each must now pass), then fuzzes from the
# committed seeds plus the corpus kept in build/fuzz/corpus/TARGET. One summary line per target; a crash
# leaves its input in build/fuzz/artifacts/ and makes the script exit 1 once every target has run.
# RTR_FUZZ_NO_BUILD=1 uses the binaries in build/fuzz/bin as they are; RTR_FUZZ_WRAP prefixes each run
# (e.g. "setarch x86_64 -R" where the kernel's address randomisation breaks this clang's ASan).
set -eu
seconds=${1:-15}
[ $# -gt 0 ] && shift
targets=${*:-fuzz_rtrscene fuzz_course fuzz_obj fuzz_mtl fuzz_texture fuzz_pose fuzz_spirv fuzz_gltf_compress fuzz_clusters fuzz_bake fuzz_gltf fuzz_texture_cache}
cores=${RTR_FUZZ_CORES:-}
wrap=${RTR_FUZZ_WRAP:-}
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
if [ -z "${RTR_FUZZ_NO_BUILD:-}" ]; then
  cmake --preset fuzz >/dev/null
  cmake --build --preset fuzz -j "$(nproc)" --target rtr_shaders $targets
fi
bin=build/fuzz/bin
art=build/fuzz/artifacts
mkdir -p "$art"

# SPIR-V seeds: the project's own small shaders, and vertex+fragment pairs (two modules in one input).
spirv_seeds=build/fuzz/corpus/spirv-seeds
if [ -d build/fuzz/shaders ]; then
  mkdir -p "$spirv_seeds"
  for f in build/fuzz/shaders/*.spv; do [ "$(wc -c <"$f")" -le 8192 ] && cp "$f" "$spirv_seeds/"; done
  for p in vis mosaic imgui; do
    cat "build/fuzz/shaders/$p.vert.spv" "build/fuzz/shaders/$p.frag.spv" >"$spirv_seeds/$p.pipeline"
  done
fi

# Share of 16 cores in the long run: the targets that run slowest per input get more.
share() {
  case $1 in fuzz_spirv) echo 6 ;; fuzz_obj) echo 3 ;; fuzz_rtrscene | fuzz_texture) echo 2 ;; *) echo 1 ;; esac
}

fuzz() {  # fuzz TARGET: fuzzes it for $seconds, leaving its log in $art/TARGET.log and its exit code beside it
  t=$1
  seeds=tests/fuzz/corpus/$t
  [ "$t" = fuzz_spirv ] && seeds=$spirv_seeds
  mkdir -p "build/fuzz/corpus/$t"
  opts=
  if [ -n "$cores" ]; then
    n=$(( (cores * $(share "$t") + 8) / 16 ))
    opts="-fork=$(( n > 0 ? n : 1 )) -ignore_crashes=1"
  fi
  rc=0
  # shellcheck disable=SC2086
  $wrap "$bin/$t" -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -timeout=10 $opts \
    -artifact_prefix="$art/$t-" "build/fuzz/corpus/$t" "$seeds" >"$art/$t.log" 2>&1 || rc=$?
  echo $rc >"$art/$t.rc"
}

failed=
for t in $targets; do
  if [ -d "tests/fuzz/crashes/$t" ] && ! $wrap "$bin/$t" tests/fuzz/crashes/$t/* >"$art/$t.replay.log" 2>&1; then
    echo "$t: a known crash input still fails (tests/fuzz/crashes/$t, log $art/$t.replay.log)"
    failed="$failed $t"
  fi
  ls "$art" | grep "^$t-" >"$art/$t.before" || true
  if [ -n "$cores" ]; then fuzz "$t" & else fuzz "$t"; fi
done
wait

for t in $targets; do
  log=$art/$t.log
  rc=$(cat "$art/$t.rc")
  new=$(ls "$art" | grep "^$t-" | grep -v -x -F -f "$art/$t.before" | wc -l || true)
  if [ "$rc" -ne 0 ] || [ "$new" -ne 0 ]; then
    echo "$t: CRASH (exit $rc, $new new inputs in $art/$t-*), see $log"
    case "$failed " in *" $t "*) ;; *) failed="$failed $t" ;; esac
  fi
  # The last status line: "#N DONE cov: C ft: F ..." (one process) or "#N: cov: C ft: F ..." (-fork).
  last=$(grep -E '^#[0-9]+' "$log" | tail -1)
  execs=$(echo "$last" | sed -n 's/^#\([0-9]*\).*/\1/p')
  if [ -n "$cores" ]; then  # -fork counts coverage its own way: load the corpus in one process to compare
    seeds=tests/fuzz/corpus/$t
    [ "$t" = fuzz_spirv ] && seeds=$spirv_seeds
    $wrap "$bin/$t" -runs=0 -max_len=65536 -rss_limit_mb=2048 "build/fuzz/corpus/$t" "$seeds" >"$art/$t.final.log" 2>&1 || true
    last=$(grep -E '^#[0-9]+[[:space:]]+INITED' "$art/$t.final.log" | tail -1)
  fi
  cov=$(echo "$last" | sed -n 's/.* cov: \([0-9]*\).*/\1/p')
  ft=$(echo "$last" | sed -n 's/.* ft: \([0-9]*\).*/\1/p')
  echo "$t: ${execs:-?} executions in ${seconds}s, cov ${cov:-?} edges, ft ${ft:-?} features," \
    "corpus $(ls "build/fuzz/corpus/$t" | wc -l) files"
done
[ -z "$failed" ] || { echo "fuzzing found crashes in:$failed"; exit 1; }
echo "fuzzing: no crashes"
