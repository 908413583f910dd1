#!/usr/bin/env bash
# One command for docs/BENCHMARKS.md: builds, runs every benchmark and comparison on this machine (lavapipe
# and the CPU) into docs/bench/data/<label>/, then writes the report and its plots from the data of every
# machine there. The H200 folder comes from the same collector run on the GPU machine, which has only a
# driver: `bash tools/bundle_device.sh`, then there `tools/report/collect.sh OUT --runner .device/run.sh`,
# and copy OUT to docs/bench/data/h200/ (docs/bench/data/NOTES.md gives the exact call).
#   tools/report.sh [collect.sh options: --quick, --skip LIST]     RTR_REPORT_LABEL=name (default vm-lavapipe)
set -euo pipefail
cd "$(dirname "$0")/.."
label=${RTR_REPORT_LABEL:-vm-lavapipe}
bash tools/setup.sh
if ! /usr/bin/python3 -c 'import matplotlib' 2>/dev/null; then  # only the report needs it
  if [[ $(id -u) == 0 ]]; then apt-get install -y -q python3-matplotlib; else sudo apt-get install -y -q python3-matplotlib; fi
fi
cmake --preset release >/dev/null
cmake --build build/release -j"$(nproc)"
rm -rf "docs/bench/data/$label"
tools/report/collect.sh "docs/bench/data/$label" "$@"
/usr/bin/python3 tools/report/render.py
