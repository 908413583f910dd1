#!/bin/sh
# Runs the libFuzzer targets: tests/fuzz/run.sh SECONDS [TARGET...] (default 15 s each, all targets).
# First replays tests/fuzz/crashes/TARGET/* (each must now pass), then fuzzes from the committed seeds
# plus the corpus kept in build/fuzz/corpus/TARGET. Prints one summary line per target; a crash leaves
# its input in build/fuzz/artifacts/ and makes the script exit 1 after the other targets have run.
# RTR_FUZZ_FORK=N runs N processes per target (libFuzzer -fork, crashes collected, fuzzing goes on).
# The long run and the numbers it gave: docs/fuzzing.md.
set -eu
seconds=${1:-15}
[ $# -gt 0 ] && shift
targets=${*:-fuzz_rtrscene fuzz_course fuzz_obj fuzz_mtl fuzz_texture fuzz_pose fuzz_spirv}
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
mkdir -p "$spirv_seeds"
for f in build/fuzz/shaders/*.spv; do [ "$(wc -c <"$f")" -le 8192 ] && cp "$f" "$spirv_seeds/"; done
for p in vis vis_alpha mosaic text; do
  cat "build/fuzz/shaders/$p.vert.spv" "build/fuzz/shaders/$p.frag.spv" >"$spirv_seeds/$p.pipeline"
done

fork=${RTR_FUZZ_FORK:+-fork=$RTR_FUZZ_FORK -ignore_crashes=1}
failed=
for t in $targets; do
  if [ -d "tests/fuzz/crashes/$t" ] && ! "$bin/$t" tests/fuzz/crashes/$t/* >"$art/$t.replay.log" 2>&1; then
    echo "$t: a known crash input still fails (tests/fuzz/crashes/$t, log $art/$t.replay.log)"
    failed="$failed $t"
  fi
  corpus=build/fuzz/corpus/$t
  mkdir -p "$corpus"
  seeds=tests/fuzz/corpus/$t
  [ "$t" = fuzz_spirv ] && seeds=$spirv_seeds
  log=$art/$t.log
  before=$(ls "$art" | grep -c "^$t-" || true)
  rc=0
  # shellcheck disable=SC2086
  "$bin/$t" -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -timeout=10 $fork \
    -artifact_prefix="$art/$t-" "$corpus" "$seeds" >"$log" 2>&1 || rc=$?
  if [ "$rc" -ne 0 ] || [ "$(ls "$art" | grep -c "^$t-" || true)" -ne "$before" ]; then
    echo "$t: CRASH (exit $rc), see $log and $art/$t-*"
    case "$failed " in *" $t "*) ;; *) failed="$failed $t" ;; esac
  fi
  last=$(grep -E '^#[0-9]+' "$log" | tail -1)
  execs=$(echo "$last" | sed -n 's/^#\([0-9]*\).*/\1/p')
  cov=$(echo "$last" | sed -n 's/.* cov: \([0-9]*\).*/\1/p')
  ft=$(echo "$last" | sed -n 's/.* ft: \([0-9]*\).*/\1/p')
  echo "$t: ${execs:-?} executions in ${seconds}s, cov ${cov:-?} edges, ft ${ft:-?} features, corpus $(ls "$corpus" | wc -l) files"
done
[ -z "$failed" ] || { echo "fuzzing found crashes in:$failed"; exit 1; }
echo "fuzzing: no crashes"
