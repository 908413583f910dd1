#!/usr/bin/env bash
# Bundles the release binaries, compiled shaders, baked assets and every shared library they need that
# a bare Ubuntu/Debian machine may lack into .device/ (git-ignored), for running the benchmarks on a GPU
# machine that has only a driver. Run there: .device/run.sh BINARY ARGS...
# Usage: tools/bundle_device.sh [BUILD_DIR [OUT_DIR]]   (defaults: build/release, .device)
set -euo pipefail
B=$(realpath "${1:-build/release}")
out=$(realpath -m "${2:-.device}")
cd "$(dirname "$0")/.."
rm -rf "$out"
mkdir -p "$out/bin" "$out/lib"
bins=()
for b in rtr-view rtr-bench-gpu rtr-trace bench-trace rtr-bake scenegen rtr-frame-compare bench_bake; do
  [[ -x $B/bin/$b ]] && cp "$B/bin/$b" "$out/bin/" && bins+=("$B/bin/$b")
done
cp -r "$B/shaders" "$out/shaders"
cp -r "$B/assets" "$out/assets"
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
export RTR_SHADER_DIR="$here/shaders" RTR_ASSET_DIR="$here/assets"
export RTR_SOURCE_DIR=${RTR_SOURCE_DIR:-$(dirname "$here")}  # the bundle sits in the repository's root
[[ -f /usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json ]] &&
  export VK_DRIVER_FILES=${VK_DRIVER_FILES:-/usr/local/nvidia/share/vulkan/icd.d/nvidia_icd.json}
bin=$1; shift
exec "$here/bin/$bin" "$@"
RUN
chmod +x "$out/run.sh"
du -sh "$out"
