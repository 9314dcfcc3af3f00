#!/usr/bin/env bash
# One render with an empty Mesa shader cache: the wall time a user waits
# for the first render of a scene (lavapipe compiles the shaders at their
# first dispatch). The figures in docs/vulkan-runtime.md come from pairs of
#   scripts/cold-render.sh [--system-vulkan] SCENE|default
# at 64x48, 1 spp, timed whole-process in turn (system driver, runtime).
#   scripts/cold-render.sh [--system-vulkan] SCENE|default [more render flags]
set -euo pipefail
bin=${QUADRAY:-$(dirname "$0")/../target/release/quadray}
flags=()
if [[ ${1:-} == --system-vulkan ]]; then flags+=(--system-vulkan); shift; fi
scene=${1:?usage: $0 [--system-vulkan] SCENE|default [render flags]}
shift
[[ $scene == default ]] && scene=""
cache=$(mktemp -d)
out=$(mktemp -d)
trap 'rm -rf "$cache" "$out"' EXIT
MESA_SHADER_CACHE_DIR=$cache "$bin" "${flags[@]}" render $scene --width 64 --height 48 --spp 1 --no-denoise \
  -o "$out/render" "$@"
