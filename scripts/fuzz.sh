#!/usr/bin/env bash
# Coverage-guided fuzzing of the scene parser (cargo-fuzz, libFuzzer) for a
# bounded time. Usage: scripts/fuzz.sh [SECONDS] (default 300).
# Seeds the corpus with the scene files of scenes/. A crash is written to
# fuzz/artifacts/scene_parser/; copy it to tests/fuzz_crashes/NAME.toml so
# that `make test` replays it (tests/scene/parser_fuzz.rs).
# Needs the nightly toolchain (rustup toolchain install nightly) and
# cargo-fuzz (installed here if missing). Memory is capped at 2 GB: the
# parser may legitimately generate large textures (up to 16384² texels),
# so the fuzzer's dictionary-free mutations rarely reach them.
set -euo pipefail
cd "$(dirname "$0")/.."
seconds="${1:-300}"
command -v cargo-fuzz >/dev/null || cargo install cargo-fuzz
mkdir -p fuzz/corpus/scene_parser
for f in scenes/*.toml scenes/tests/*.toml; do
    cp "$f" "fuzz/corpus/scene_parser/$(echo "$f" | tr / _)"
done
cargo +nightly fuzz run scene_parser fuzz/corpus/scene_parser -- \
    -max_total_time="$seconds" -rss_limit_mb=2048 -max_len=4096
