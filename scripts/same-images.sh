#!/usr/bin/env bash
# Checks that a change leaves every image as it was, to the bit: renders
# every scene of scenes/ and scenes/tests/ at 96x64, 4 spp, on both backends,
# with an old and a new quadray binary, then compares each pair with
# `quadray compare` (which says whether the radiance is identical).
# Usage: scripts/same-images.sh OLD_BINARY NEW_BINARY OUT_DIR
set -u
old=$1 new=$2 out=$3
cd "$(dirname "$0")/.."
for which in old new; do
    bin=${!which}
    mkdir -p "$out/$which"
    for s in scenes/*.toml scenes/tests/*.toml; do
        name=$(echo "$s" | tr / _ | sed 's/.toml$//')
        for b in ray-query pipeline; do
            "$bin" render "$s" --width 96 --height 64 --spp 4 --backend $b -o "$out/$which/$name-$b.exr" \
                >/dev/null 2>"$out/$which/$name-$b.log" || echo "FAILED: $which $name $b (see the log)"
        done
    done
done
same=0 differ=0
for f in "$out"/old/*.exr; do
    n=$(basename "$f")
    verdict=$("$new" compare "$f" "$out/new/$n" 2>&1 | tail -n 1)
    if [[ $verdict == identical* ]]; then same=$((same + 1)); else differ=$((differ + 1)); echo "$n: $verdict"; fi
done
echo "$same images identical to the bit, $differ differ"
[[ $differ -eq 0 ]]
