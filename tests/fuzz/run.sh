#!/bin/sh
# Short fuzz run for CI: tests/fuzz/run.sh SECONDS (default 30) runs each target for SECONDS.
# Longer runs (see docs/rtrscene-format.md): tests/fuzz/run.sh 3600.
set -eu
seconds=${1:-30}
root=$(cd "$(dirname "$0")/../.." && pwd)
cd "$root"
cmake --preset fuzz >/dev/null
cmake --build --preset fuzz --target fuzz_loader fuzz_obj
work=$(mktemp -d)
trap 'rm -rf "$work"' EXIT
for t in fuzz_loader fuzz_obj; do
  mkdir -p "$work/$t"
  cp tests/fuzz/corpus/$t/* "$work/$t/" 2>/dev/null || true
  echo "== $t for ${seconds}s"
  ./build/fuzz/bin/$t -max_total_time="$seconds" -max_len=65536 -rss_limit_mb=2048 -timeout=10 \
    -artifact_prefix="$work/$t-" "$work/$t" || { echo "$t found a crash:"; ls "$work"/$t-* ; cp "$work"/$t-* . ; exit 1; }
done
echo "fuzzing: no crashes"
