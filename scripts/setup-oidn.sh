#!/usr/bin/env bash
# Installs Intel Open Image Denoise 2.5.1 (Apache-2.0) for `quadray render
# --denoise`, `quadray denoise` and the viewer's denoise key: the four files
# its CPU device needs, from the official build that the PyPI wheel `pyoidn`
# 2.5.1.0 ships (no Debian release packages OIDN), into third_party/oidn/lib
# (ignored by git), with the licence and notices beside them. The wheel is
# pinned by its SHA-256; the files find each other through their RPATH
# ($ORIGIN/../lib). Idempotent: one line and nothing else when present.
# Needs python3 with pip and unzip (scripts/setup-debian.sh installs them).
set -euo pipefail
cd "$(dirname "$0")/.."

wheel=pyoidn-2.5.1.0-py3-none-manylinux2014_x86_64.whl
sha256=32ad13368f8de1ef63001942ad05b02a00cd732d1206d97f352d3a3f606d823e
dest=third_party/oidn/lib
files=(libOpenImageDenoise.so.2.5.1 libOpenImageDenoise_core.so.2.5.1 libOpenImageDenoise_device_cpu.so.2.5.1
       libtbb.so.12)

present=1
for f in "${files[@]}" LICENSE.txt NOTICE.md; do [[ -s $dest/$f ]] || present=0; done
if [[ $present == 1 ]]; then
  echo "setup: Open Image Denoise 2.5.1 present ($dest)"
  exit 0
fi
if [[ $(uname -m) != x86_64 || $(uname -s) != Linux ]]; then
  echo "setup: WARNING: the pinned Open Image Denoise build is for Linux x86_64; install OIDN 2 yourself and set" \
       "QUADRAY_OIDN_LIB to its libOpenImageDenoise.so.2 for --denoise" >&2
  exit 0
fi
echo "setup: installing Open Image Denoise 2.5.1 into $dest (from $wheel)"
tmp=$(mktemp -d)
trap 'rm -rf "$tmp"' EXIT
printf 'pyoidn==2.5.1.0 --hash=sha256:%s\n' "$sha256" >"$tmp/requirements.txt"
if ! python3 -m pip download --quiet --disable-pip-version-check --no-deps --only-binary=:all: \
       --platform manylinux2014_x86_64 --require-hashes -r "$tmp/requirements.txt" -d "$tmp" >"$tmp/pip.log" 2>&1; then
  echo "setup: FAILED: could not download $wheel from PyPI:" >&2
  tail -n 20 "$tmp/pip.log" >&2
  exit 1
fi
mkdir -p "$dest"
unzip -q -j -o "$tmp/$wheel" "${files[@]/#/pyoidn/oidn/lib/}" -d "$tmp/lib"
# The name the system would find (SONAME), for QUADRAY_OIDN_LIB users.
ln -sf libOpenImageDenoise.so.2.5.1 "$tmp/lib/libOpenImageDenoise.so.2"
cp third_party/oidn/LICENSE.txt third_party/oidn/NOTICE.md "$tmp/lib/"
cp -a "$tmp/lib/." "$dest/"
echo "setup: Open Image Denoise installed ($(du -sh "$dest" | cut -f1))"
