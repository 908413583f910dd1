#!/usr/bin/env bash
# Bundles the release binaries, compiled shaders, baked assets and every shared library they need that
# a bare Ubuntu/Debian machine may lack into .device/ (git-ignored), for running the benchmarks and the
# Vulkan test suite on a GPU machine that has only a driver. Run there: .device/run.sh BINARY ARGS...,
# or the whole Vulkan suite with validation: .device/run-tests.sh (docs/gpu-machine.md).
# Usage: tools/bundle_device.sh [BUILD_DIR [OUT_DIR]]   (defaults: build/release, .device)
set -euo pipefail
B=$(realpath "${1:-build/release}")
out=$(realpath -m "${2:-.device}")
cd "$(dirname "$0")/.."
rm -rf "$out"
mkdir -p "$out/bin" "$out/lib"
bins=()
for b in rtr-view rtr-bench-gpu rtr-trace bench-trace rtr-bake scenegen rtr-frame-compare bench_bake rtr-reflect rtr-bench-upload \
         vk_test render_test view_test reference_test rtr-bench-cull rtr-lod-cut bench-load; do
  [[ -x $B/bin/$b ]] && cp "$B/bin/$b" "$out/bin/" && bins+=("$B/bin/$b")
done
# Debian's tools the load benchmark makes its GLB inputs with and compares against, where this machine has them.
for t in gltfpack assimp; do
  p=$(command -v "$t" || true)
  [[ -n $p ]] && cp "$p" "$out/bin/" && bins+=("$p")
done
cp -r "$B/shaders" "$out/shaders"
cp -r "$B/assets" "$out/assets"
# What the tests read from the source tree (tests/test_paths.hpp finds it in src/).
mkdir -p "$out/src/tests/vk" "$out/src/tests/fuzz/crashes" "$out/src/assets-src"
cp -r tests/vk/data "$out/src/tests/vk/"
cp -r tests/fuzz/crashes/fuzz_spirv "$out/src/tests/fuzz/crashes/"  # SPIR-V that SPIRV-Reflect crashes on
cp -r tests/reference "$out/src/tests/"
cp -r shaders "$out/src/"
cp -r assets-src/rt "$out/src/assets-src/"
cp README.md "$out/src/"
# The validation layer, its manifest pointing at the copy beside it (VK_LAYER_PATH, run.sh).
layer=$(find /usr/lib /usr/local/lib -name libVkLayer_khronos_validation.so 2>/dev/null | head -1 || true)
manifest=$(find /usr/share/vulkan /usr/local/share/vulkan -name VkLayer_khronos_validation.json 2>/dev/null | head -1 || true)
mkdir -p "$out/layers"
cp -L "$layer" "$out/layers/"
sed 's|"library_path": *"[^"]*"|"library_path": "./libVkLayer_khronos_validation.so"|' "$manifest" > "$out/layers/VkLayer_khronos_validation.json"
# Libraries outside the C/C++ runtime (which the target has, newer).
ldd "${bins[@]}" | awk '/=> \//{print $3}' | sort -u |
  grep -v -E '/(libc|libm|libdl|libpthread|librt|libgcc_s|libstdc\+\+|ld-linux-x86-64)\.so' |
  while read -r lib; do cp -L "$lib" "$out/lib/"; done
strip --strip-unneeded "$out"/bin/* "$out"/lib/* 2>/dev/null || true  # debug info stays here
cat > "$out/run.sh" <<'RUN'
#!/usr/bin/env bash
# Runs a bundled binary with the bundled libraries and the NVIDIA Vulkan driver.
here=$(cd "$(dirname "$0")" && pwd)
export LD_LIBRARY_PATH="$here/lib${LD_LIBRARY_PATH:+:$LD_LIBRARY_PATH}"
export RTR_SHADER_DIR="$here/shaders" RTR_ASSET_DIR="$here/assets" RTR_BINARY_DIR="$here" RTR_SOURCE_DIR="$here/src"
export VK_LAYER_PATH="$here/layers"
[[ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]] &&
  export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
bin=$1; shift
exec "$here/bin/$bin" "$@"
RUN
cat > "$out/run-tests.sh" <<'RUN'
#!/usr/bin/env bash
# Runs every Vulkan test binary with validation (core + synchronization: any message fails a test).
# Prints each binary's gtest summary and, at the end, tests run / passed / validation messages.
here=$(cd "$(dirname "$0")" && pwd)
export RTR_VALIDATION=1 RTR_PIPELINE_CACHE=off
run=0 passed=0 messages=0 status=0
for t in vk_test render_test view_test reference_test; do
  log=$(mktemp)
  "$here/run.sh" "$t" --gtest_brief=1 >"$log" 2>&1 || status=1
  grep -E '^\[  (PASSED|FAILED)  \]|^\[==========\]|cannot allocate|error while loading' "$log" | sed "s/^/$t: /"
  r=$(grep -oE '^\[==========\] ([0-9]+) tests? from' "$log" | grep -oE '[0-9]+' | head -1)
  p=$(grep -oE '^\[  PASSED  \] ([0-9]+) test' "$log" | grep -oE '[0-9]+' | head -1)
  m=$(grep -c '^\[vulkan ' "$log")
  run=$((run + ${r:-0})) passed=$((passed + ${p:-0})) messages=$((messages + m))
  [[ $m -gt 0 ]] && grep '^\[vulkan ' "$log" | head -5 | cut -c1-400
  cp "$log" "${RTR_TEST_LOGS:-/tmp}/$t.log" 2>/dev/null; rm -f "$log"
done
echo "Vulkan suite: $run tests run, $passed passed, $messages validation messages"
exit $status
RUN
chmod +x "$out/run.sh" "$out/run-tests.sh"
du -sh "$out"
