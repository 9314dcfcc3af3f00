//! Fuzz target: the scene parser must return a scene or an error for any
//! UTF-8 text, never panic (run with `scripts/fuzz.sh`).
#![no_main]

use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    if let Ok(text) = std::str::from_utf8(data) {
        // A name inside a directory without texture files: `file = ...`
        // paths resolve against it and fail to load, as they should.
        let _ = quadray::model::scene::parse_scene(text, "fuzz/scene.toml");
    }
});
