#!/usr/bin/env bash
# Fetches a pinned, current Mesa lavapipe with its own runtime (glibc, LLVM,
# the Vulkan loader, the Khronos validation layer) from Debian unstable's
# binary packages into third_party/vulkan-runtime/root (ignored by git).
# quadray restarts itself through that runtime's dynamic loader
# (src/vk/runtime.rs; docs/vulkan-runtime.md), so the binary built on
# Debian 12 runs unchanged on Mesa 26.2: shaders compile 3-6x sooner and
# render 1.2-1.5x faster than on Debian 12's Mesa 25.0.7.
#
#   scripts/setup-vulkan-runtime.sh          fetch what packages.lock pins (idempotent)
#   scripts/setup-vulkan-runtime.sh --repin  resolve Debian unstable anew and rewrite packages.lock
#
# The packages and their SHA-256s are pinned in
# third_party/vulkan-runtime/packages.lock; every file fetched is checked
# against it. Debian unstable keeps only its current versions, so a pin ages
# out when a package in it is updated: setup then warns, leaves the runtime
# it has (or none), and quadray uses the system's driver until --repin (which
# resolves through apt with Debian's signed indices, into a private apt
# state: the system's apt is untouched). The environment variable
# QUADRAY_DEBIAN_MIRROR overrides the mirror.
set -euo pipefail
cd "$(dirname "$0")/.."

dir=third_party/vulkan-runtime
lock=$dir/packages.lock
root=$dir/root
stamp=$root/.packages.lock.sha256
# What the runtime is resolved from: the driver, the loader, the validation
# layer and the C library (the rest is their dependency closure).
roots=(mesa-vulkan-drivers libvulkan1 vulkan-validationlayers libc6)
# The oldest Mesa --repin accepts (26.1.6 segfaults on our perturbation
# scenes: docs/stability.md).
min_mesa=26.2

mirror=${QUADRAY_DEBIAN_MIRROR:-}
if [[ -z $mirror ]]; then
  mirror=$(grep -rhoE 'https?://[^ ]+/debian/?( |$)' /etc/apt/sources.list /etc/apt/sources.list.d/ 2>/dev/null \
             | grep -v security | head -n1 | tr -d " " || true)
  mirror=${mirror:-http://deb.debian.org/debian}
fi
mirror=${mirror%/}

if [[ $(uname -m) != x86_64 || $(uname -s) != Linux ]]; then
  echo "setup: the pinned Vulkan runtime is for Linux x86_64; quadray uses the system's Vulkan driver"
  exit 0
fi

repin() {
  local state
  state=$(mktemp -d)
  trap 'rm -rf "$state"' RETURN
  mkdir -p "$state/etc/apt/sources.list.d" "$state/etc/apt/preferences.d" "$state/lists/partial" "$state/archives/partial"
  : >"$state/status"
  printf 'deb [signed-by=/usr/share/keyrings/debian-archive-keyring.gpg] %s sid main\n' "$mirror" \
    >"$state/etc/apt/sources.list"
  local apt=(-o "Dir::Etc=$state/etc/apt" -o "Dir::State::Lists=$state/lists"
             -o "Dir::State::status=$state/status" -o "Dir::Cache=$state" -o "Dir::Cache::archives=$state/archives"
             -o APT::Architecture=amd64 -o APT::Architectures::=amd64 -o Debug::NoLocking=1
             -o Acquire::Languages=none -o Acquire::IndexTargets::deb::DEP-11::DefaultEnabled=false)
  echo "setup: resolving ${roots[*]} in Debian unstable ($mirror)"
  apt-get "${apt[@]}" -q update >"$state/update.log" 2>&1 || { tail -n 20 "$state/update.log" >&2; return 1; }
  # An empty dpkg status: apt resolves the whole dependency closure.
  local names
  names=$(apt-get "${apt[@]}" -s install --no-install-recommends "${roots[@]}" | awk '/^Inst /{print $2}')
  local mesa
  mesa=$(apt-cache "${apt[@]}" show --no-all-versions mesa-vulkan-drivers | awk '/^Version:/{print $2; exit}')
  if ! dpkg --compare-versions "$mesa" ge "$min_mesa"; then
    echo "setup: Debian unstable has Mesa $mesa, older than $min_mesa: packages.lock left as it is" >&2
    return 1
  fi
  local out=$lock.new
  {
    echo "# The Vulkan runtime scripts/setup-vulkan-runtime.sh fetches: Debian unstable (amd64) binary"
    echo "# packages, the dependency closure of ${roots[*]}."
    echo "# Resolved $(date -u +%Y-%m-%d) with --repin; Mesa $mesa. Columns: package, version, SHA-256, pool path."
    local n
    for n in $names; do
      apt-cache "${apt[@]}" show --no-all-versions "$n" \
        | awk -v n="$n" '/^Version:/{v=$2} /^SHA256:/{s=$2} /^Filename:/{f=$2} END{print n, v, s, f}'
    done
  } >"$out"
  mv "$out" "$lock"
  echo "setup: wrote $lock ($(grep -vc '^#' "$lock") packages, Mesa $mesa)"
}

if [[ ${1:-} == --repin ]]; then
  repin
  shift
fi
[[ $# -eq 0 ]] || { echo "usage: $0 [--repin]" >&2; exit 2; }

want=$(sha256sum "$lock" | cut -d' ' -f1)
if [[ -f $stamp && $(cat "$stamp") == "$want" ]]; then
  echo "setup: Vulkan runtime present ($root: $(grep -m1 '^mesa-vulkan-drivers ' "$lock" | cut -d' ' -f1-2))"
  exit 0
fi

tmp=$(mktemp -d "$dir/.fetch.XXXXXX")
trap 'rm -rf "$tmp"' EXIT
echo "setup: fetching the Vulkan runtime ($(grep -vc '^#' "$lock") Debian unstable packages, $(grep -m1 '^mesa-vulkan-drivers ' "$lock" | cut -d' ' -f1-2)) into $root"
failed=()
while read -r name version sha path; do
  [[ -z $name || $name == \#* ]] && continue
  deb=$tmp/${path##*/}
  if ! curl -fsSL --retry 2 -o "$deb" "$mirror/$path"; then
    failed+=("$name $version (not on $mirror)")
    continue
  fi
  if [[ $(sha256sum "$deb" | cut -d' ' -f1) != "$sha" ]]; then
    failed+=("$name $version (SHA-256 differs from packages.lock)")
    continue
  fi
  dpkg-deb -x "$deb" "$tmp/root"
  rm -f "$deb"
done <"$lock"

if [[ ${#failed[@]} -gt 0 ]]; then
  echo "setup: WARNING: the Vulkan runtime was not installed; quadray uses the system's Vulkan driver. Failed:" >&2
  printf 'setup:   %s\n' "${failed[@]}" >&2
  echo "setup: Debian unstable moves on; scripts/setup-vulkan-runtime.sh --repin pins its current packages" >&2
  exit 0
fi

# Only lavapipe is used: the other drivers and the documentation except the
# licences are left out (about 200 MB).
r=$tmp/root
find "$r/usr/share/vulkan/icd.d" -type f ! -name 'lvp_icd.json' -delete
find "$r/usr/lib/x86_64-linux-gnu" -maxdepth 1 -name 'libvulkan_*.so' ! -name 'libvulkan_lvp.so' -delete
rm -rf "$r/usr/share/man" "$r/usr/share/lintian" "$r/usr/share/locale" "$r/usr/share/bug"
find "$r/usr/share/doc" -type f ! -name copyright -delete 2>/dev/null || true
for f in usr/lib64/ld-linux-x86-64.so.2 usr/lib/x86_64-linux-gnu/libvulkan_lvp.so usr/lib/x86_64-linux-gnu/libvulkan.so.1 \
         usr/share/vulkan/icd.d/lvp_icd.json usr/share/vulkan/explicit_layer.d/VkLayer_khronos_validation.json; do
  [[ -e $r/$f ]] || { echo "setup: FAILED: the fetched packages lack $f" >&2; exit 1; }
done
echo "$want" >"$r/.packages.lock.sha256"
rm -rf "$root"
mv "$r" "$root"
echo "setup: Vulkan runtime installed ($(du -sh "$root" | cut -f1)); quadray uses it (--system-vulkan keeps the system's driver)"
