//! The library's modules form layers (docs/architecture.md): no module uses
//! one that uses it back, directly or through others. Read from the source:
//! every `crate::a::b` and `super::a` path in code (comments left out) is an
//! edge from the file's module to the module it names. Checked at two
//! levels: between the top-level modules of `src/` (the crate root, which
//! holds the error types every layer returns, left out), and between the
//! children of every folder module (files such as `passes/render.rs` and
//! `passes/checkpoint.rs`).

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    for entry in std::fs::read_dir(dir).unwrap() {
        let path = entry.unwrap().path();
        if path.is_dir() {
            rust_files(&path, out);
        } else if path.extension().is_some_and(|e| e == "rs") {
            out.push(path);
        }
    }
}

/// The module path of a file relative to `src/`: `passes/film/mod.rs` is
/// `["passes", "film"]`, `passes/render.rs` is `["passes", "render"]`.
fn module_of(relative: &Path) -> Vec<String> {
    let mut parts: Vec<String> = relative.iter().map(|p| p.to_string_lossy().into_owned()).collect();
    let last = parts.pop().unwrap();
    let stem = last.trim_end_matches(".rs");
    if !matches!(stem, "mod" | "lib" | "main") {
        parts.push(stem.to_string());
    }
    parts
}

/// The identifiers of the path that starts at byte `start` of `line`:
/// `crate::passes::gpu::GpuAov` gives `["passes", "gpu", "GpuAov"]`.
fn path_at(line: &str, start: usize) -> Vec<String> {
    let rest = &line[start..];
    let end = rest.find(|c: char| !(c.is_alphanumeric() || c == '_' || c == ':')).unwrap_or(rest.len());
    rest[..end].split("::").filter(|s| !s.is_empty()).map(str::to_string).collect()
}

/// The modules a file names: `crate::` paths as they are, `super::` paths
/// resolved against the file's module (`self` paths stay inside it).
fn referenced_modules(module: &[String], text: &str) -> Vec<Vec<String>> {
    let mut out = Vec::new();
    for line in text.lines() {
        let code = line.split("//").next().unwrap();
        // `super` is the parent of the file's module (a folder's mod.rs is
        // the folder's module).
        let parent = module[..module.len().saturating_sub(1)].to_vec();
        for (prefix, base) in [("crate::", Vec::new()), ("super::", parent)] {
            let mut from = 0;
            while let Some(i) = code[from..].find(prefix) {
                let at = from + i;
                from = at + prefix.len();
                // `super::super::x` and `crate::` within a longer word.
                let before = code[..at].chars().last();
                if before.is_some_and(|c| c.is_alphanumeric() || c == '_' || c == ':') {
                    continue;
                }
                let mut path = base.clone();
                path.extend(path_at(code, from));
                out.push(path);
            }
        }
    }
    out
}

/// A cycle in `graph`, if any (as the nodes along it).
fn find_cycle(graph: &BTreeMap<String, BTreeSet<String>>) -> Option<Vec<String>> {
    fn visit(
        node: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        state: &mut BTreeMap<String, u8>,
        stack: &mut Vec<String>,
    ) -> Option<Vec<String>> {
        state.insert(node.to_string(), 1);
        stack.push(node.to_string());
        for next in graph.get(node).into_iter().flatten() {
            match state.get(next.as_str()).copied().unwrap_or(0) {
                1 => {
                    let start = stack.iter().position(|n| n == next).unwrap();
                    let mut cycle = stack[start..].to_vec();
                    cycle.push(next.clone());
                    return Some(cycle);
                }
                0 => {
                    if let Some(c) = visit(next, graph, state, stack) {
                        return Some(c);
                    }
                }
                _ => {}
            }
        }
        stack.pop();
        state.insert(node.to_string(), 2);
        None
    }
    let mut state = BTreeMap::new();
    for node in graph.keys() {
        if state.get(node).copied().unwrap_or(0) == 0 {
            if let Some(c) = visit(node, graph, &mut state, &mut Vec::new()) {
                return Some(c);
            }
        }
    }
    None
}

#[test]
fn modules_form_layers_without_cycles() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    // Every module of the crate, to tell module names from items in paths.
    let modules: BTreeSet<Vec<String>> =
        files.iter().map(|f| module_of(f.strip_prefix(&src).unwrap())).filter(|m| !m.is_empty()).collect();
    // Edges between the modules two paths' longest module prefixes name.
    let mut edges: BTreeSet<(Vec<String>, Vec<String>)> = BTreeSet::new();
    for file in &files {
        let relative = file.strip_prefix(&src).unwrap();
        let module = module_of(relative);
        // main.rs is the binary (it uses the library by name); the root
        // (lib.rs) holds the shared error types.
        if module.is_empty() {
            continue;
        }
        let text = std::fs::read_to_string(file).unwrap();
        for path in referenced_modules(&module, &text) {
            let target = (1..=path.len()).rev().map(|n| path[..n].to_vec()).find(|p| modules.contains(p));
            if let Some(target) = target {
                edges.insert((module.clone(), target));
            }
        }
    }
    // The top level, then the children of every folder module.
    let mut levels: Vec<Vec<String>> = vec![vec![]];
    levels.extend(modules.iter().filter(|m| modules.iter().any(|c| c.len() > m.len() && c.starts_with(m))).cloned());
    let mut checked = 0;
    for parent in &levels {
        let mut graph: BTreeMap<String, BTreeSet<String>> = BTreeMap::new();
        let depth = parent.len();
        for (from, to) in &edges {
            if from.len() > depth && to.len() > depth && from.starts_with(parent) && to.starts_with(parent) {
                let (a, b) = (&from[depth], &to[depth]);
                if a != b {
                    graph.entry(a.clone()).or_default().insert(b.clone());
                }
            }
        }
        checked += graph.values().map(BTreeSet::len).sum::<usize>();
        if let Some(cycle) = find_cycle(&graph) {
            let within = if parent.is_empty() { "the crate".to_string() } else { parent.join("::") };
            panic!("a module cycle within {within}: {}", cycle.join(" -> "));
        }
    }
    println!("{} modules, {} edges between siblings, no cycle", modules.len(), checked);
    assert!(checked > 50, "too few edges were read ({checked}): is the source where the test looks?");
}
