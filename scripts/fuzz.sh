#!/usr/bin/env bash
# Coverage-guided fuzzing of the scene parser (cargo-fuzz, libFuzzer) for a
# bounded time. Usage: scripts/fuzz.sh [SECONDS] (default 300).
# Seeds the corpus with the scene files of scenes/ and with the kept corpus
# tests/fuzz_corpus/. After the run:
#   - every crash, out-of-memory or timeout input libFuzzer saved in
#     fuzz/artifacts/scene_parser/ is copied to tests/fuzz_crashes/KIND-HASH.toml
#     (minimised with `cargo fuzz tmin` where it reproduces), so that
#     `make test` replays it (tests/scene/parser_fuzz.rs); the script then
#     exits 1 and names them;
#   - the corpus is minimised (`cargo fuzz cmin`: the inputs that reach all
#     the coverage) into tests/fuzz_corpus/, which `make test` replays too.
# Commit both folders. Needs the nightly toolchain (rustup toolchain install
# nightly) and cargo-fuzz (installed here if missing). Memory is capped at
# 2 GB: the parser may legitimately generate large textures (up to 16384²
# texels), so the fuzzer's dictionary-free mutations rarely reach them.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-300}"
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz
corpus=fuzz/corpus/scene_parser
artifacts=fuzz/artifacts/scene_parser
mkdir -p "$corpus" "$artifacts" tests/fuzz_crashes tests/fuzz_corpus
for f in scenes/*.toml scenes/tests/*.toml; do
    cp "$f" "$corpus/$(echo "$f" | tr / _)"
done
cp tests/fuzz_corpus/* "$corpus/" 2>/dev/null || true
status=0
cargo +nightly fuzz run scene_parser "$corpus" -- \
    -max_total_time="$seconds" -rss_limit_mb=2048 -max_len=4096 || status=$?

new=()
for a in "$artifacts"/crash-* "$artifacts"/oom-* "$artifacts"/timeout-*; do
    [[ -e $a ]] || continue
    name=$(basename "$a")
    kept="tests/fuzz_crashes/${name%%-*}-$(sha1sum "$a" | cut -c1-16).toml"
    [[ -e $kept ]] && continue
    min="$artifacts/minimised-$name"
    if cargo +nightly fuzz tmin scene_parser "$a" -- -rss_limit_mb=2048 -exact_artifact_path="$min" >/dev/null 2>&1 \
        && [[ -s $min ]]; then
        cp "$min" "$kept"
    else
        cp "$a" "$kept"
    fi
    new+=("$kept")
done

# The corpus, minimised to the inputs that keep all its coverage.
cargo +nightly fuzz cmin scene_parser "$corpus" -- -rss_limit_mb=2048 >/dev/null 2>&1
rm -f tests/fuzz_corpus/*
for f in "$corpus"/*; do
    case $(basename "$f") in scenes_*) continue ;; esac  # the seeds live in scenes/
    cp "$f" tests/fuzz_corpus/
done
echo "fuzz: $(ls tests/fuzz_corpus | wc -l) corpus inputs kept in tests/fuzz_corpus/"

if ((${#new[@]})); then
    echo "fuzz: ${#new[@]} new crashing input(s), kept for make test: ${new[*]}" >&2
    exit 1
fi
if ((status != 0)); then
    echo "fuzz: libFuzzer exited with $status and left no artifact" >&2
    exit "$status"
fi
echo "fuzz: no crash in $seconds s"
