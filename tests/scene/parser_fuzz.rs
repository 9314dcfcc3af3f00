//! A deterministic mutation fuzz of the scene parser, run by `make test`:
//! scene files from `scenes/` (those that generate no large textures) are
//! mutated one edit at a time (a byte deleted, duplicated or replaced, lines
//! swapped or dropped, the text truncated, a number replaced by an extreme
//! value) and each result must parse or fail with an error, never panic.
//! Every input the coverage-guided fuzzer (`scripts/fuzz.sh`, cargo-fuzz)
//! ever crashed on is kept in `tests/fuzz_crashes/` and replayed here too.

use std::panic::{catch_unwind, AssertUnwindSafe};
use std::path::Path;

use quadray::model::scene::parse_scene;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Mutations per corpus file.
const MUTATIONS: usize = 1500;

const EXTREMES: [&str; 14] =
    ["-1", "0", "0.5", "1e30", "-1e30", "nan", "inf", "-inf", "1e-300", "4294967296", "-0", "\"x\"", "true", "[]"];

fn mutate(text: &str, rng: &mut Pcg64) -> String {
    let bytes = text.as_bytes();
    let at = rng.gen_range(0..bytes.len().max(1));
    let lossy = |b: Vec<u8>| String::from_utf8_lossy(&b).into_owned();
    match rng.gen_range(0..7) {
        0 => lossy([&bytes[..at], &bytes[(at + 1).min(bytes.len())..]].concat()),
        1 => lossy([&bytes[..at], &bytes[at..(at + 1).min(bytes.len())], &bytes[at..]].concat()),
        2 => {
            let replacement =
                [b'[', b']', b'{', b'}', b'=', b'"', b',', b'\n', b'.', b'-', b'9', b'#'][rng.gen_range(0..12)];
            let mut b = bytes.to_vec();
            if !b.is_empty() {
                b[at] = replacement;
            }
            lossy(b)
        }
        3 => lossy(bytes[..at].to_vec()),
        4 => {
            let mut lines: Vec<&str> = text.lines().collect();
            let (i, j) = (rng.gen_range(0..lines.len()), rng.gen_range(0..lines.len()));
            lines.swap(i, j);
            lines.join("\n")
        }
        5 => {
            let mut lines: Vec<&str> = text.lines().collect();
            lines.remove(rng.gen_range(0..lines.len()));
            lines.join("\n")
        }
        _ => {
            // Replace the n-th number by an extreme value.
            let numbers: Vec<(usize, usize)> = number_spans(text);
            if numbers.is_empty() {
                return text.to_owned();
            }
            let (s, e) = numbers[rng.gen_range(0..numbers.len())];
            format!("{}{}{}", &text[..s], EXTREMES[rng.gen_range(0..EXTREMES.len())], &text[e..])
        }
    }
}

/// Byte ranges of the numeric literals of a TOML text (outside comments).
fn number_spans(text: &str) -> Vec<(usize, usize)> {
    let mut spans = Vec::new();
    let mut offset = 0;
    for line in text.split_inclusive('\n') {
        let code = line.split('#').next().unwrap_or("");
        let b = code.as_bytes();
        let mut i = 0;
        while i < b.len() {
            let starts = (b[i].is_ascii_digit() || b[i] == b'-') && (i == 0 || !b[i - 1].is_ascii_alphanumeric());
            if starts {
                let mut j = i + 1;
                while j < b.len() && (b[j].is_ascii_digit() || b"+-.eE".contains(&b[j])) {
                    j += 1;
                }
                if b[i..j].iter().any(|c| c.is_ascii_digit()) {
                    spans.push((offset + i, offset + j));
                }
                i = j;
            } else {
                i += 1;
            }
        }
        offset += line.len();
    }
    spans
}

fn parses_without_panic(text: &str, name: &str) -> Result<(), String> {
    catch_unwind(AssertUnwindSafe(|| {
        let _ = parse_scene(text, name);
    }))
    .map_err(|e| {
        let msg = e.downcast_ref::<String>().cloned().or_else(|| e.downcast_ref::<&str>().map(|s| s.to_string()));
        format!("panic {msg:?} on input:\n{text}")
    })
}

#[test]
fn mutated_scenes_parse_or_fail_cleanly() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut corpus = Vec::new();
    for dir in ["scenes", "scenes/tests"] {
        for entry in std::fs::read_dir(root.join(dir)).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_some_and(|e| e == "toml") {
                let text = std::fs::read_to_string(&path).unwrap();
                // Generated textures make each parse slow (megatexels); the
                // texture specs are covered by the cargo-fuzz target.
                if !["checker =", "bumps =", "sky =", "map ="].iter().any(|k| text.contains(k)) {
                    corpus.push((path, text));
                }
            }
        }
    }
    assert!(corpus.len() >= 3, "corpus too small: {}", corpus.len());
    let mut rng = Pcg64::seed_from_u64(7);
    let (mut ok, mut errors) = (0, 0);
    for (path, text) in &corpus {
        let name = path.display().to_string();
        for _ in 0..MUTATIONS {
            let mutated = mutate(text, &mut rng);
            if let Err(e) = parses_without_panic(&mutated, &name) {
                panic!("{name}: {e}");
            }
            match parse_scene(&mutated, &name) {
                Ok(_) => ok += 1,
                Err(_) => errors += 1,
            }
        }
    }
    println!(
        "{} corpus files x {MUTATIONS} mutations: {ok} parsed, {errors} rejected with an error, 0 panics",
        corpus.len()
    );
}

/// Every file of `tests/<folder>/`, read as (lossy) UTF-8 as the fuzz
/// target reads its input.
fn replay(folder: &str) -> Vec<(String, String)> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("tests").join(folder);
    let mut files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap_or_else(|e| panic!("{}: {e}", dir.display()))
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().is_some_and(|n| n != "README.md"))
        .collect();
    files.sort();
    files
        .into_iter()
        .map(|p| (p.display().to_string(), String::from_utf8_lossy(&std::fs::read(&p).unwrap()).into_owned()))
        .collect()
}

/// The inputs the coverage-guided fuzzer once crashed on
/// (`tests/fuzz_crashes/`, where `scripts/fuzz.sh` copies every new crash)
/// and its minimised corpus (`tests/fuzz_corpus/`: the inputs that reached
/// new coverage in its runs, `cargo fuzz cmin`) parse or fail with an error,
/// never panic. The corpus is never empty: a run that lost it fails here.
#[test]
fn recorded_fuzzer_inputs_no_longer_crash() {
    let crashes = replay("fuzz_crashes");
    let corpus = replay("fuzz_corpus");
    assert!(!corpus.is_empty(), "tests/fuzz_corpus/ is empty: run scripts/fuzz.sh to regenerate it");
    for (name, text) in crashes.iter().chain(&corpus) {
        if let Err(e) = parses_without_panic(text, name) {
            panic!("{name}: {e}");
        }
    }
    println!("{} recorded fuzzer crashes and {} corpus inputs replayed without a panic", crashes.len(), corpus.len());
}
