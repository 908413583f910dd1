#!/usr/bin/env bash
# Installs every system dependency of the project from Debian packages (Debian 12 "bookworm").
# Idempotent: when everything is present it only checks and returns in about a second.
# Run as root, or with sudo available; otherwise it prints the exact commands to run.
set -euo pipefail

BOOKWORM_PKGS=(
  build-essential cmake ninja-build pkg-config git ca-certificates
  libvulkan-dev vulkan-validationlayers vulkan-tools glslang-tools glslang-dev spirv-tools spirv-headers
  libglm-dev libglfw3-dev libstb-dev libzstd-dev zstd libsquish-dev zlib1g-dev libtinyexr-dev libjpeg62-turbo-dev libpng-dev
  libgtest-dev libgmock-dev libbenchmark-dev libembree-dev libcli11-dev libtinyobjloader-dev libmeshoptimizer-dev
  libdraco-dev gltfpack assimp-utils
  libimgui-dev xvfb xdotool x11-utils clang libclang-rt-14-dev clang-format python3 assimp-testmodels
  libsimdjson-dev
)
# Not in bookworm: taken from later suites through a low apt pin (priority 100), by name only.
PINNED_PKGS=(libspirv-reflect-dev/sid libvulkan-memory-allocator-dev/trixie)
# Mesa 25 (lavapipe with Vulkan 1.4, descriptor indexing, timestamps that bracket compute work).
BACKPORT_PKGS=(mesa-vulkan-drivers/bookworm-backports)

SOURCES=/etc/apt/sources.list.d/rtr-extra-suites.sources
PREFS=/etc/apt/preferences.d/rtr-extra-suites
SOURCES_TEXT='Types: deb
URIs: http://deb.debian.org/debian
Suites: bookworm-backports trixie sid
Components: main
Signed-By: /usr/share/keyrings/debian-archive-keyring.gpg'
PREFS_TEXT='Package: *
Pin: release n=trixie
Pin-Priority: 100

Package: *
Pin: release n=sid
Pin-Priority: 100

Package: *
Pin: release n=bookworm-backports
Pin-Priority: 100'

mesa_ok() {
  local v; v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  [[ -n "$v" ]] && dpkg --compare-versions "$v" ge 25
}
missing() {
  local p out=()
  for p in "${BOOKWORM_PKGS[@]}" libspirv-reflect-dev libvulkan-memory-allocator-dev; do
    dpkg-query -W -f='${Status}' "$p" 2>/dev/null | grep -q 'install ok installed' || out+=("$p")
  done
  mesa_ok || out+=(mesa-vulkan-drivers)
  echo "${out[@]:-}"
}

need=$(missing)
if [[ -z "$need" ]]; then echo "setup: all dependencies present"; exit 0; fi
echo "setup: missing: $need"

SUDO=""
if [[ $(id -u) -ne 0 ]]; then
  if command -v sudo >/dev/null && sudo -n true 2>/dev/null; then SUDO="sudo"; else
    cat <<MSG
setup: not root and no password-less sudo. Run these as root, then run this script again:
  printf '%s\n' '${SOURCES_TEXT//$'\n'/\\n}' > $SOURCES
  printf '%s\n' '${PREFS_TEXT//$'\n'/\\n}' > $PREFS
  apt-get update
  apt-get install -y ${BOOKWORM_PKGS[*]}
  apt-get install -y ${PINNED_PKGS[*]} ${BACKPORT_PKGS[*]}
MSG
    exit 1
  fi
fi
export DEBIAN_FRONTEND=noninteractive
[[ -f $SOURCES ]] || printf '%s\n' "$SOURCES_TEXT" | $SUDO tee $SOURCES >/dev/null
[[ -f $PREFS ]] || printf '%s\n' "$PREFS_TEXT" | $SUDO tee $PREFS >/dev/null
$SUDO apt-get update -qq
$SUDO apt-get install -y -qq --no-install-recommends "${BOOKWORM_PKGS[@]}"
$SUDO apt-get install -y -qq --no-install-recommends "${PINNED_PKGS[@]}" "${BACKPORT_PKGS[@]}"
need=$(missing)
[[ -z "$need" ]] || { echo "setup: still missing after install: $need" >&2; exit 1; }
echo "setup: done"
