#!/usr/bin/env bash
# Installs what a fresh Debian 12 (bookworm) or Ubuntu machine lacks to build,
# run and test the renderer without a GPU:
#   - the Vulkan loader and the Khronos validation layer,
#   - Mesa's lavapipe software driver with VK_KHR_ray_query (Mesa >= 23;
#     on Debian 12 it comes from bookworm-backports),
#   - Debian's shaderc / glslang / SPIRV-Tools libraries, linked statically by
#     build.rs so that shaderc is not compiled from source.
# Idempotent: it installs only what is missing and does nothing when all is there.
set -euo pipefail

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi

need_pkgs=(libvulkan1 vulkan-validationlayers libshaderc-dev glslang-dev spirv-tools
           pkg-config mesa-vulkan-drivers)

have_pkg() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }

mesa_has_ray_query() {
  # lavapipe advertises VK_KHR_ray_query from Mesa 24.1 on.
  local v
  v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  [[ -n $v ]] && dpkg --compare-versions "$v" ge 24.1
}

missing=()
for p in "${need_pkgs[@]}"; do have_pkg "$p" || missing+=("$p"); done
if [[ ${#missing[@]} -eq 0 ]] && mesa_has_ray_query; then
  echo "setup: all system packages present"
  exit 0
fi

codename=""
if [[ -r /etc/os-release ]]; then . /etc/os-release; codename=${VERSION_CODENAME:-}; fi

if [[ $codename == bookworm ]] && ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
  # Use the same mirror as the existing Debian source.
  mirror=$(grep -rhoE 'https?://[^ ]+/debian/?( |$)' /etc/apt/sources.list /etc/apt/sources.list.d/ 2>/dev/null \
             | grep -v security | head -n1 | tr -d " " || true)
  mirror=${mirror:-http://deb.debian.org/debian}
  echo "setup: adding bookworm-backports from $mirror"
  printf 'Types: deb\nURIs: %s\nSuites: bookworm-backports\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' \
    "$mirror" | $SUDO tee /etc/apt/sources.list.d/bookworm-backports.sources >/dev/null
fi

echo "setup: installing ${missing[*]:-mesa-vulkan-drivers (newer)}"
$SUDO apt-get update -qq
export DEBIAN_FRONTEND=noninteractive
if [[ $codename == bookworm ]]; then
  $SUDO apt-get install -y -qq -t bookworm-backports mesa-vulkan-drivers
else
  $SUDO apt-get install -y -qq mesa-vulkan-drivers
fi
$SUDO apt-get install -y -qq "${need_pkgs[@]/mesa-vulkan-drivers/}"
mesa_has_ray_query || { echo "setup: mesa-vulkan-drivers is older than 24.1: lavapipe has no ray queries" >&2; exit 1; }
echo "setup: done"
