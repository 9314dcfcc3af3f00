#!/usr/bin/env bash
# relMSE per sample of two quadray binaries on the throughput scenes, run for
# run: each renders every scene at 16 and 64 spp with seeds 1..8, and each
# image is compared (quadray compare, linear radiance) with one reference
# per scene that OLD renders at REF_SPP with seed 1000 (both samplers are
# unbiased, so one reference serves both; its own noise adds the same small
# amount to both errors, which pulls their ratio toward 1).
#
#   scripts/sampler-error.sh OLD NEW OUT [WIDTH HEIGHT REF_SPP]
#
# Prints one line per scene and spp: mean relMSE of OLD and NEW over the
# seeds and OLD/NEW (above 1: NEW has the lower error). Issue 28 item 3
# (Owen-scrambled Sobol against independent samples) used it with OLD the
# binary of main before the sampler and NEW after it.
set -euo pipefail
old=$1 new=$2 out=$3
width=${4:-160} height=${5:-120} ref_spp=${6:-1024}
scenes=(default scenes/figure1_left.toml scenes/glass_vessel.toml scenes/spheres.toml)
mkdir -p "$out"
relmse() { "$new" compare "$1" "$2" | sed -n 's/.*relative MSE \([0-9.eE+-]*\).*/\1/p' | head -1; }
scene_arg() { [ "$1" = default ] && echo "" || echo "$1"; }
for scene in "${scenes[@]}"; do
    name=$(basename "$scene" .toml)
    ref="$out/$name-ref.exr"
    if [ ! -f "$ref" ]; then
        "$old" render $(scene_arg "$scene") --width "$width" --height "$height" --spp "$ref_spp" --seed 1000 \
            -o "$out/$name-ref" >/dev/null
    fi
    for spp in 16 64; do
        sum_old=0 sum_new=0
        for seed in 1 2 3 4 5 6 7 8; do
            for which in old new; do
                bin=$old; [ $which = new ] && bin=$new
                img="$out/$name-$which-$spp-$seed"
                "$bin" render $(scene_arg "$scene") --width "$width" --height "$height" --spp $spp --seed $seed \
                    -o "$img" >/dev/null
                e=$(relmse "$ref" "$img.exr")
                if [ $which = old ]; then sum_old=$(echo "$sum_old + $e" | bc -l); else sum_new=$(echo "$sum_new + $e" | bc -l); fi
            done
        done
        printf '%-14s %3d spp  old %.5f  new %.5f  old/new %.3f\n' "$name" $spp \
            "$(echo "$sum_old / 8" | bc -l)" "$(echo "$sum_new / 8" | bc -l)" "$(echo "$sum_old / $sum_new" | bc -l)"
    done
done
