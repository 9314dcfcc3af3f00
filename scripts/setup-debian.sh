#!/usr/bin/env bash
# Installs what a fresh Debian 12 (bookworm) or Ubuntu machine lacks to build,
# run and test the renderer without a GPU:
#   - the Vulkan loader and the Khronos validation layer,
#   - Mesa's lavapipe software driver with VK_KHR_ray_query (Mesa >= 24.1;
#     on Debian 12 it comes from bookworm-backports),
#   - Debian's shaderc / glslang / SPIRV-Tools libraries, linked statically
#     (see .cargo/config.toml) so that shaderc is not compiled from source,
#   - a C/C++ toolchain for linking (gcc, g++, libc6-dev) and make,
#   - curl, with which scripts/setup-vulkan-runtime.sh fetches the pinned
#     Mesa 26.2 runtime from Debian unstable,
#   - python3 with pip and unzip, which scripts/setup-oidn.sh uses to fetch
#     Intel Open Image Denoise (the denoiser) from its pinned PyPI wheel,
#   - Xvfb and the X11 client libraries winit loads at run time, for the
#     viewer (`quadray view`) and its test under a virtual display,
#   - Slurm (slurmctld, slurmd, slurm-client) and MUNGE for `quadray farm
#     slurm` and its one-node-cluster test (without Recommends, which would
#     pull in Slurm's development packages; no service is started: the test
#     starts its own daemons). Optional: where they cannot be installed,
#     setup warns and the farm test is skipped with the reason.
# Idempotent: it installs only what is missing and does nothing when all is there.
# Prints one line per step; apt's output goes to a log file that is shown
# (its tail) only when a step fails. QUADRAY_SETUP_LOG overrides its path.
set -euo pipefail

SUDO=""
if [[ $(id -u) -ne 0 ]]; then SUDO="sudo"; fi

need_pkgs=(libvulkan1 vulkan-validationlayers libshaderc-dev glslang-dev spirv-tools
           pkg-config gcc g++ libc6-dev make ca-certificates curl mesa-vulkan-drivers
           python3 python3-pip unzip
           xvfb libx11-6 libx11-xcb1 libxcursor1 libxrandr2 libxi6 libxkbcommon-x11-0)

farm_pkgs=(slurmctld slurmd slurm-client munge)

have_pkg() { dpkg-query -W -f='${Status}' "$1" 2>/dev/null | grep -q "install ok installed"; }

mesa_has_ray_query() {
  # lavapipe advertises VK_KHR_ray_query from Mesa 24.1 on.
  local v
  v=$(dpkg-query -W -f='${Version}' mesa-vulkan-drivers 2>/dev/null || true)
  [[ -n $v ]] && dpkg --compare-versions "$v" ge 24.1
}

missing=()
for p in "${need_pkgs[@]}"; do have_pkg "$p" || missing+=("$p"); done
farm_missing=()
for p in "${farm_pkgs[@]}"; do have_pkg "$p" || farm_missing+=("$p"); done
if [[ ${#missing[@]} -eq 0 && ${#farm_missing[@]} -eq 0 ]] && mesa_has_ray_query; then
  echo "setup: all system packages present"
  exit 0
fi

log=${QUADRAY_SETUP_LOG:-${TMPDIR:-/tmp}/quadray-setup.log}
: >"$log"

# Runs a step with its output appended to the log; on failure shows the
# log's tail and stops.
step() {
  local what=$1
  shift
  echo "setup: $what"
  if ! "$@" >>"$log" 2>&1; then
    echo "setup: FAILED: $what (command: $*); last lines of $log:" >&2
    tail -n 40 "$log" >&2
    exit 1
  fi
}

apt_get() { $SUDO env DEBIAN_FRONTEND=noninteractive apt-get -y -q "$@"; }

codename=""
if [[ -r /etc/os-release ]]; then . /etc/os-release; codename=${VERSION_CODENAME:-}; fi

if [[ $codename == bookworm ]] && ! grep -rqs "bookworm-backports" /etc/apt/sources.list /etc/apt/sources.list.d/; then
  # Use the same mirror as the existing Debian source.
  mirror=$(grep -rhoE 'https?://[^ ]+/debian/?( |$)' /etc/apt/sources.list /etc/apt/sources.list.d/ 2>/dev/null \
             | grep -v security | head -n1 | tr -d " " || true)
  mirror=${mirror:-http://deb.debian.org/debian}
  step "adding bookworm-backports from $mirror" \
    $SUDO tee /etc/apt/sources.list.d/bookworm-backports.sources \
    < <(printf 'Types: deb\nURIs: %s\nSuites: bookworm-backports\nComponents: main\nSigned-By: /usr/share/keyrings/debian-archive-keyring.gpg\n' "$mirror")
fi

all_missing=("${missing[@]}" "${farm_missing[@]}")
mesa_has_ray_query || all_missing+=("mesa-vulkan-drivers >= 24.1")
echo "setup: missing: ${all_missing[*]} (apt log: $log)"
step "apt-get update" apt_get update
if [[ ${#farm_missing[@]} -gt 0 ]]; then
  echo "setup: installing ${farm_missing[*]} (for quadray farm slurm)"
  if ! apt_get install --no-install-recommends "${farm_missing[@]}" >>"$log" 2>&1; then
    echo "setup: WARNING: could not install ${farm_missing[*]}: the Slurm farm test will be skipped (see $log)" >&2
  fi
fi
if [[ ${#missing[@]} -eq 0 ]] && mesa_has_ray_query; then
  echo "setup: done"
  exit 0
fi
if [[ $codename == bookworm ]]; then
  step "installing mesa-vulkan-drivers from bookworm-backports" \
    apt_get install -t bookworm-backports mesa-vulkan-drivers
else
  step "installing mesa-vulkan-drivers" apt_get install mesa-vulkan-drivers
fi
others=()
for p in "${need_pkgs[@]}"; do [[ $p == mesa-vulkan-drivers ]] || others+=("$p"); done
step "installing ${others[*]}" apt_get install "${others[@]}"
mesa_has_ray_query || { echo "setup: mesa-vulkan-drivers is older than 24.1: lavapipe has no ray queries" >&2; exit 1; }
echo "setup: done"
