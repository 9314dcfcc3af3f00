#!/usr/bin/env bash
# The hardware check: run a prebuilt quadray release binary on a machine
# with a GPU and a Vulkan loader (no network, no Rust toolchain needed), and
# write everything it finds to one folder.
#
#   scripts/gpu-check.sh BINARY [OUT_DIR]      the check (OUT_DIR default: gpu-check-<time>)
#   scripts/gpu-check.sh --references BINARY   render the references into
#                                              results/gpu-check/references/ (done on lavapipe)
#
# Steps, each logged to OUT_DIR/report.txt:
#  1. `ldd BINARY`: the libraries it needs; anything beyond the C library
#     and the compiler's runtime is reported (libvulkan.so.1 is loaded at
#     run time by ash, so ldd does not list it; nv-flip's C++ brings
#     libstdc++.so.6, which is reported).
#  2. `quadray devices` and `--json`: the devices, what each offers, the backend auto takes.
#  3. Every test scene (scenes/tests/*.toml) at 64x48, 4 spp, its own seed,
#     with each backend the device offers (and the wavefront pass, on ray
#     queries: `--kernel wavefront`), compared with the lavapipe
#     reference (`quadray compare`: FLIP and relative MSE). Bound: FLIP at
#     most FLIP_BOUND (0.05). On lavapipe the two backends agree to FLIP
#     0.000000 (tests/render/backends.rs); another GPU rounds sin, exp and
#     fused multiply-adds its own way, so a path through glass may diverge;
#     the bound is provisional until measured on hardware.
#  4. `quadray bench` at its defaults (the presets against their references).
#  5. The paper's table 1 row for the glass vessel at 1024x768: `quadray
#     render scenes/glass_vessel.toml --width 1024 --height 768 --bench`.
# Steps 4 and 5 run under a time limit each (STEP_TIMEOUT, 150 s), so the
# whole check ends within 8 minutes on a GPU.
set -uo pipefail

root=$(cd "$(dirname "$0")/.." && pwd)
FLIP_BOUND=${FLIP_BOUND:-0.05}
STEP_TIMEOUT=${STEP_TIMEOUT:-150}
SIZE=(--width 64 --height 48 --spp 4)
references="$root/results/gpu-check/references"

scenes() { ls "$root"/scenes/tests/*.toml | sort; }

if [[ "${1:-}" == "--references" ]]; then
  bin=${2:?usage: scripts/gpu-check.sh --references BINARY}
  mkdir -p "$references"
  for scene in $(scenes); do
    name=$(basename "$scene" .toml)
    "$bin" render "$scene" "${SIZE[@]}" --backend ray-query -o "$references/$name.exr" || exit 1
  done
  echo "wrote $(ls "$references" | wc -l) references to $references"
  exit 0
fi

bin=${1:?usage: scripts/gpu-check.sh BINARY [OUT_DIR]}
bin=$(cd "$(dirname "$bin")" && pwd)/$(basename "$bin")
out=${2:-gpu-check-$(date +%Y%m%d-%H%M%S)}
mkdir -p "$out"
out=$(cd "$out" && pwd)
exec > >(tee "$out/report.txt") 2>&1
failures=0
section() { printf '\n==== %s  (%ds)\n' "$*" "$SECONDS"; }

section "1. libraries the binary needs"
ldd "$bin" | tee "$out/ldd.txt"
extra=$(grep -v -E 'linux-vdso|ld-linux|libc\.so|libm\.so|libdl\.so|libpthread|librt\.so|libgcc_s|libvulkan\.so\.1' "$out/ldd.txt" || true)
if [[ -n "$extra" ]]; then
  echo "beyond libvulkan.so.1 and the C runtime it needs:"; echo "$extra"
fi

section "2. devices"
"$bin" devices || failures=$((failures + 1))
"$bin" devices --json > "$out/devices.json" || failures=$((failures + 1))

section "3. test scenes against the lavapipe references (FLIP bound $FLIP_BOUND)"
printf '%-20s %-10s %-10s %s\n' scene backend FLIP "relative MSE"
# `wavefront`: ray queries with the wavefront pass (--kernel wavefront).
for backend in ray-query pipeline wavefront; do
  flags=(--backend "$backend")
  [[ $backend == wavefront ]] && flags=(--backend ray-query --kernel wavefront)
  for scene in $(scenes); do
    name=$(basename "$scene" .toml)
    image="$out/$name-$backend.exr"
    if ! "$bin" render "$scene" "${SIZE[@]}" "${flags[@]}" -o "$image" > "$out/$name-$backend.log" 2>&1; then
      if grep -q "offers no" "$out/$name-$backend.log"; then
        printf '%-20s %-10s %s\n' "$name" "$backend" "not offered by this device"
        break
      fi
      printf '%-20s %-10s %s\n' "$name" "$backend" "FAILED: $(tail -1 "$out/$name-$backend.log")"
      failures=$((failures + 1))
      continue
    fi
    line=$("$bin" compare "$references/$name.exr" "$image" | head -1)
    flip=$(echo "$line" | awk '{print $2}')
    rel=$(echo "$line" | awk '{print $5}')
    verdict=ok
    if awk -v f="$flip" -v b="$FLIP_BOUND" 'BEGIN { exit !(f > b) }'; then verdict="over the bound"; failures=$((failures + 1)); fi
    printf '%-20s %-10s %-10s %-12s %s\n' "$name" "$backend" "$flip" "$rel" "$verdict"
  done
done

section "4. quality presets (quadray bench)"
(cd "$out" && timeout "$STEP_TIMEOUT" "$bin" bench --out "$out/bench" \
  default "$root/scenes/figure1_left.toml" "$root/scenes/figure1_right.toml" "$root/scenes/glass_vessel.toml") \
  || echo "bench: stopped or failed (status $?)"

section "5. table 1: the glass vessel at 1024x768"
(cd "$out" && timeout "$STEP_TIMEOUT" "$bin" render "$root/scenes/glass_vessel.toml" --width 1024 --height 768 --bench \
  -o "$out/glass_vessel") || echo "table 1: stopped or failed (status $?)"

section "done: $failures failure(s); everything is in $out"
exit $((failures > 0))
