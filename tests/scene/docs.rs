//! The documentation says what exists: every relative link of README.md,
//! docs/*.md and scenes/README.md reaches a file (and a heading, for an
//! anchor); every `quadray COMMAND --flag` written in them, and in the
//! program's own help, names a command and a flag the program has; the
//! README's scene file parses.

use std::collections::{BTreeMap, BTreeSet};
use std::path::PathBuf;
use std::process::Command;

fn root() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
}

/// The Markdown files checked.
fn pages() -> Vec<PathBuf> {
    let mut pages = vec![root().join("README.md"), root().join("scenes/README.md")];
    let mut docs: Vec<PathBuf> = std::fs::read_dir(root().join("docs"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().is_some_and(|e| e == "md"))
        .collect();
    docs.sort();
    pages.extend(docs);
    pages
}

/// GitHub's anchor of a heading: lower case, punctuation dropped, spaces
/// to hyphens.
fn slug(heading: &str) -> String {
    heading
        .trim()
        .to_lowercase()
        .chars()
        .filter(|c| c.is_alphanumeric() || *c == ' ' || *c == '-' || *c == '_')
        .map(|c| if c == ' ' { '-' } else { c })
        .collect()
}

/// The anchors of a page's headings (outside code blocks).
fn anchors(text: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut seen: BTreeMap<String, usize> = BTreeMap::new();
    let mut code = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            code = !code;
            continue;
        }
        if code || !line.starts_with('#') {
            continue;
        }
        let s = slug(line.trim_start_matches('#'));
        let n = seen.entry(s.clone()).or_insert(0);
        out.insert(if *n == 0 { s.clone() } else { format!("{s}-{n}") });
        *n += 1;
    }
    out
}

/// The targets of a page's inline links `[text](target)` (outside code).
fn links(text: &str) -> Vec<String> {
    let mut out = Vec::new();
    let mut code = false;
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            code = !code;
            continue;
        }
        if code {
            continue;
        }
        let mut rest = line;
        while let Some(i) = rest.find("](") {
            let after = &rest[i + 2..];
            let Some(end) = after.find(')') else { break };
            out.push(after[..end].split_whitespace().next().unwrap_or("").to_string());
            rest = &after[end..];
        }
    }
    out
}

#[test]
fn every_relative_link_reaches_a_file_and_heading() {
    let mut broken = Vec::new();
    let mut checked = 0;
    for page in pages() {
        let text = std::fs::read_to_string(&page).unwrap();
        for link in links(&text) {
            if link.is_empty() || link.contains("://") || link.starts_with("mailto:") {
                continue;
            }
            checked += 1;
            let (file, anchor) = link.split_once('#').unwrap_or((&link, ""));
            let target = if file.is_empty() { page.clone() } else { page.parent().unwrap().join(file) };
            if !target.exists() {
                broken.push(format!("{}: {link} (no such file)", page.display()));
                continue;
            }
            if !anchor.is_empty() && target.extension().is_some_and(|e| e == "md") {
                let there = anchors(&std::fs::read_to_string(&target).unwrap());
                if !there.contains(anchor) {
                    broken.push(format!("{}: {link} (no such heading)", page.display()));
                }
            }
        }
    }
    println!("{checked} relative links checked");
    assert!(checked > 100, "the link scan found only {checked} links");
    assert!(broken.is_empty(), "dangling links:\n{}", broken.join("\n"));
}

fn help(args: &[&str]) -> String {
    let out = Command::new(env!("CARGO_BIN_EXE_quadray")).args(args).arg("--help").output().unwrap();
    assert!(out.status.success(), "quadray {args:?} --help failed");
    String::from_utf8_lossy(&out.stdout).into_owned()
}

/// The program's subcommands, from its usage.
fn commands() -> BTreeSet<String> {
    let text = help(&[]);
    let list = text.split("Commands:").nth(1).unwrap().split("Options:").next().unwrap();
    list.lines().filter_map(|l| l.split_whitespace().next()).filter(|w| *w != "help").map(String::from).collect()
}

/// Every `quadray WORD ...` in code spans and code blocks of `text`: the
/// word and the `--flags` after it on that line.
fn invocations(text: &str) -> Vec<(String, Vec<String>)> {
    // The code: code blocks' lines (less shell comments) and the code spans
    // of each paragraph (a span may wrap).
    let mut code: Vec<String> = Vec::new();
    let mut in_block = false;
    let mut paragraph = String::new();
    let spans_of = |p: &mut String, code: &mut Vec<String>| {
        code.extend(p.split('`').skip(1).step_by(2).map(String::from));
        p.clear();
    };
    for line in text.lines() {
        if line.trim_start().starts_with("```") {
            in_block = !in_block;
            spans_of(&mut paragraph, &mut code);
            continue;
        }
        if in_block {
            let end = line.find(" #").or_else(|| line.trim_start().starts_with('#').then_some(0));
            code.push(line[..end.unwrap_or(line.len())].to_string());
        } else if line.trim().is_empty() {
            spans_of(&mut paragraph, &mut code);
        } else {
            paragraph.push(' ');
            paragraph.push_str(line);
        }
    }
    spans_of(&mut paragraph, &mut code);
    let mut out = Vec::new();
    for span in &code {
        let words: Vec<&str> = span.split_whitespace().collect();
        for (i, w) in words.iter().enumerate() {
            if !(*w == "quadray" || w.ends_with("/quadray")) || i + 1 >= words.len() {
                continue;
            }
            let cmd = words[i + 1];
            if !cmd.chars().all(|c| c.is_ascii_lowercase() || c == '-') || cmd.starts_with('-') {
                continue;
            }
            let flags = words[i + 2..]
                .iter()
                .take_while(|w| **w != "|" && **w != "&&" && **w != ";")
                .filter(|w| w.starts_with("--") && w.len() > 2)
                .map(|w| w.split('=').next().unwrap().trim_end_matches([',', ')', '`', '.']).to_string())
                .collect();
            out.push((cmd.to_string(), flags));
        }
    }
    out
}

#[test]
fn the_commands_and_flags_the_docs_name_exist() {
    let commands = commands();
    assert!(commands.contains("render") && commands.contains("devices"), "{commands:?}");
    let mut flags_of: BTreeMap<String, String> = BTreeMap::new();
    let mut wrong = Vec::new();
    let mut checked = 0;
    let mut texts: Vec<(String, String)> =
        pages().iter().map(|p| (p.display().to_string(), std::fs::read_to_string(p).unwrap())).collect();
    texts.push(("quadray --help".into(), help(&[])));
    for c in &commands {
        texts.push((format!("quadray {c} --help"), help(&[c])));
    }
    for (name, text) in &texts {
        for (cmd, flags) in invocations(text) {
            // `quadray farm slurm`: the first word is the command.
            if !commands.contains(&cmd) {
                wrong.push(format!("{name}: `quadray {cmd}`: no such command"));
                continue;
            }
            let command_help = flags_of.entry(cmd.clone()).or_insert_with(|| help(&[&cmd]));
            for flag in flags {
                checked += 1;
                let farm = cmd == "farm"; // its flags belong to `farm slurm` and to `render` after `--`
                if !farm && !command_help.contains(&format!("{flag} ")) && !command_help.contains(&format!("{flag}\n"))
                {
                    wrong.push(format!("{name}: `quadray {cmd} {flag}`: no such flag"));
                }
            }
        }
    }
    println!("{checked} command-line flags checked");
    assert!(checked > 50, "only {checked} flags found");
    assert!(wrong.is_empty(), "the docs name what does not exist:\n{}", wrong.join("\n"));
}

#[test]
fn the_readme_scene_file_parses() {
    let text = std::fs::read_to_string(root().join("README.md")).unwrap();
    let block = text.split("```toml").nth(1).expect("a TOML block in the README").split("```").next().unwrap();
    quadray::model::scene::parse_scene(block, "README.md").unwrap_or_else(|e| panic!("the README's scene file: {e}"));
}

#[test]
fn the_scene_comments_name_real_commands() {
    // Scene files' comments often say how to render them.
    let commands = commands();
    let mut wrong = Vec::new();
    for dir in [root().join("scenes"), root().join("scenes/tests")] {
        for entry in std::fs::read_dir(&dir).unwrap() {
            let path = entry.unwrap().path();
            if path.extension().is_none_or(|e| e != "toml") {
                continue;
            }
            let text = std::fs::read_to_string(&path).unwrap();
            let comments: String =
                text.lines().filter_map(|l| l.trim_start().strip_prefix('#')).map(|l| format!("{l}\n")).collect();
            for (cmd, flags) in invocations(&comments) {
                if !commands.contains(&cmd) {
                    wrong.push(format!("{}: quadray {cmd}", path.display()));
                    continue;
                }
                let h = help(&[&cmd]);
                for f in flags {
                    if !h.contains(&format!("{f} ")) && !h.contains(&format!("{f}\n")) {
                        wrong.push(format!("{}: quadray {cmd} {f}", path.display()));
                    }
                }
            }
        }
    }
    assert!(wrong.is_empty(), "scene comments name what does not exist:\n{}", wrong.join("\n"));
}
