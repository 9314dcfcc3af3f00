//! The library's modules form layers (docs/architecture.md, "Layers"): no
//! module uses one that uses it back, directly or through others, and no
//! module uses a layer above its own. Read from the source: every
//! `crate::` and `super::` path in code (comments and unit-test modules
//! left out), grouped
//! imports (`use super::{a::B, c::{d, e}}`) expanded, and names a folder's
//! `mod.rs` re-exports (`pub use sync::Access`) followed to the file that
//! defines them, is an edge from the file's module to the module it names.
//! Cycles are checked at two levels: between the top-level modules of
//! `src/` (the crate root, which holds the error types every layer returns,
//! left out), and between the children of every folder module. The order is
//! checked between top-level modules against the table of
//! docs/architecture.md, read from the page itself: a module may use its
//! own layer's modules and those of the rows above it. The check is shown
//! to see faults by injecting two into a copy of the source: a cycle inside
//! `src/vk` through a grouped import, and a core module using a tool.

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// Every `.rs` file under `dir`.
fn rust_files(dir: &Path) -> Vec<PathBuf> {
    crate::common::files_under(dir).into_iter().filter(|p| p.extension().is_some_and(|e| e == "rs")).collect()
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

/// The file's code without its comments (line comments; doc comments are
/// line comments too) and without its inline unit tests: everything from
/// the `#[cfg(test)]` line of a `mod NAME {` on (the test module, which by
/// the project's convention closes the file), whose imports are test-only
/// edges. (Out-of-line test modules, `#[cfg(test)] mod tests;`, are left
/// out whole: `test_files`.)
fn code_of(text: &str) -> String {
    let lines: Vec<&str> = text.lines().collect();
    let end = (0..lines.len())
        .find(|&i| {
            lines[i].trim() == "#[cfg(test)]"
                && lines.get(i + 1).is_some_and(|l| l.starts_with("mod ") && l.trim_end().ends_with('{'))
        })
        .unwrap_or(lines.len());
    lines[..end].iter().map(|l| l.split("//").next().unwrap()).collect::<Vec<_>>().join("\n")
}

/// The files of out-of-line unit-test modules: `#[cfg(test)]` then
/// `mod NAME;` in a file makes `NAME.rs` beside it (or in its folder, for a
/// `mod.rs`) a test file.
fn test_files(src: &Path, sources: &[Source]) -> BTreeSet<PathBuf> {
    let mut out = BTreeSet::new();
    for source in sources {
        let file = &source.file;
        let lines: Vec<&str> = source.text.lines().collect();
        for w in lines.windows(2) {
            let Some(name) = w[1].trim().strip_prefix("mod ").and_then(|r| r.strip_suffix(';')) else { continue };
            if w[0].trim() != "#[cfg(test)]" {
                continue;
            }
            let stem = file.file_stem().unwrap().to_string_lossy();
            let dir = if matches!(stem.as_ref(), "mod" | "lib" | "main") {
                file.parent().unwrap().to_path_buf()
            } else {
                file.with_extension("")
            };
            for candidate in [dir.join(format!("{name}.rs")), dir.join(name).join("mod.rs")] {
                if candidate.starts_with(src) && candidate.exists() {
                    out.insert(candidate);
                }
            }
        }
    }
    out
}

/// A source file, read once: its path, module, text and code (`code_of`).
struct Source {
    file: PathBuf,
    module: Vec<String>,
    text: String,
    code: String,
}

fn is_ident(c: u8) -> bool {
    c.is_ascii_alphanumeric() || c == b'_'
}

/// One path of a use tree, as its identifiers, and the alias it is
/// imported under (`e as f`), if any.
type UsePath = (Vec<String>, Option<String>);

/// The paths of the use tree (or plain path) at byte `*i` of `s`:
/// `a::{b, c::{d, e as f}, self}` gives `[a, b]`, `[a, c, d]`, `[a, c, e]`
/// (alias `f`) and `[a]`. Stops where the tree ends.
fn use_tree(s: &[u8], i: &mut usize) -> Vec<UsePath> {
    let skip_ws = |i: &mut usize| {
        while *i < s.len() && s[*i].is_ascii_whitespace() {
            *i += 1;
        }
    };
    skip_ws(i);
    if *i < s.len() && s[*i] == b'{' {
        *i += 1;
        let mut out = Vec::new();
        loop {
            skip_ws(i);
            if *i >= s.len() {
                return out;
            }
            if s[*i] == b'}' {
                *i += 1;
                return out;
            }
            out.extend(use_tree(s, i));
            skip_ws(i);
            if *i < s.len() && s[*i] == b',' {
                *i += 1;
            } else if *i < s.len() && s[*i] != b'}' {
                // Not a use tree after all (a struct literal, a block).
                return out;
            }
        }
    }
    let start = *i;
    while *i < s.len() && (is_ident(s[*i]) || s[*i] == b'*') {
        *i += 1;
    }
    let segment = String::from_utf8_lossy(&s[start..*i]).into_owned();
    if segment.is_empty() {
        return Vec::new();
    }
    if s[*i..].starts_with(b"::") {
        *i += 2;
        let rest = use_tree(s, i);
        let mut out: Vec<UsePath> = rest
            .into_iter()
            .map(|(mut p, alias)| {
                p.insert(0, segment.clone());
                (p, alias)
            })
            .collect();
        if out.is_empty() {
            out.push((vec![segment], None));
        }
        return out;
    }
    // `name as alias`: the alias is what the file uses; the path is `name`.
    let mut alias = None;
    let mut j = *i;
    while j < s.len() && s[j].is_ascii_whitespace() {
        j += 1;
    }
    if s[j..].starts_with(b"as") && s.get(j + 2).is_some_and(|c| c.is_ascii_whitespace()) {
        j += 2;
        while j < s.len() && s[j].is_ascii_whitespace() {
            j += 1;
        }
        let start = j;
        while j < s.len() && is_ident(s[j]) {
            j += 1;
        }
        alias = Some(String::from_utf8_lossy(&s[start..j]).into_owned());
        *i = j;
    }
    // `self` names the path so far; `*` and other names are items.
    if segment == "self" {
        return vec![(vec![], alias)];
    }
    vec![(vec![segment], alias)]
}

/// The paths a file names from the crate root: `crate::` paths as they
/// are, `super::` (and `super::super::`) paths resolved against the file's
/// module, grouped imports expanded.
fn referenced_paths(module: &[String], code: &str) -> Vec<Vec<String>> {
    let s = code.as_bytes();
    let mut out = Vec::new();
    let mut i = 0;
    while i < s.len() {
        let rest = &s[i..];
        let boundary = i == 0 || !(is_ident(s[i - 1]) || s[i - 1] == b':');
        if boundary && rest.starts_with(b"crate::") {
            let mut j = i + "crate::".len();
            out.extend(use_tree(s, &mut j).into_iter().map(|(p, _)| p));
            i = j.max(i + 1);
        } else if boundary && rest.starts_with(b"super::") {
            // `super` is the parent of the file's module (a folder's mod.rs
            // is the folder's module), once per `super::`.
            let mut base = module.to_vec();
            let mut j = i;
            while s[j..].starts_with(b"super::") {
                base.pop();
                j += "super::".len();
            }
            for (p, _) in use_tree(s, &mut j) {
                let mut full = base.clone();
                full.extend(p);
                out.push(full);
            }
            i = j.max(i + 1);
        } else {
            i += 1;
        }
    }
    out
}

/// What each folder module re-exports from its children: the names of
/// `pub use child::{A, B as C}` in its `mod.rs` (or `lib.rs`), by folder
/// and name (the alias where there is one), to the child that defines them.
fn re_exports(sources: &[Source], modules: &BTreeSet<Vec<String>>) -> BTreeMap<(Vec<String>, String), String> {
    let mut out = BTreeMap::new();
    for source in sources {
        let s = source.code.as_bytes();
        let mut from = 0;
        while let Some(k) = source.code[from..].find("pub use ") {
            let mut j = from + k + "pub use ".len();
            from = j;
            for (path, alias) in use_tree(s, &mut j) {
                let (Some(child), Some(last)) = (path.first(), path.last()) else { continue };
                let mut child_module = source.module.clone();
                child_module.push(child.clone());
                if path.len() >= 2 && modules.contains(&child_module) {
                    out.insert((source.module.clone(), alias.unwrap_or_else(|| last.clone())), child.clone());
                }
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

/// The layers of docs/architecture.md's table, bottom first: each row's
/// top-level modules (`src/NAME.rs` or `src/NAME/` in its "where" column).
fn documented_layers(page: &str) -> Vec<(String, BTreeSet<String>)> {
    let table = page.split("## Layers").nth(1).expect("a Layers section").split("\n## ").next().unwrap();
    let mut layers = Vec::new();
    for row in table.lines().filter(|l| l.starts_with("| ") && !l.starts_with("| layer")) {
        let cells: Vec<&str> = row.split(" | ").collect();
        let (Some(name), Some(place)) = (cells.first(), cells.get(1)) else { continue };
        let modules: BTreeSet<String> = place
            .split('`')
            .skip(1)
            .step_by(2)
            .filter_map(|p| p.strip_prefix("src/"))
            .filter_map(|p| p.split('/').next())
            .map(|m| m.trim_end_matches(".rs").to_string())
            .filter(|m| !m.is_empty() && !m.contains('.'))
            .collect();
        if !modules.is_empty() {
            layers.push((name.trim_start_matches("| ").to_string(), modules));
        }
    }
    layers
}

/// What the check found: modules, edges between siblings, edges between
/// layers.
struct Layering {
    modules: usize,
    sibling_edges: usize,
    layer_edges: usize,
}

/// Checks the sources under `src` against `page` (docs/architecture.md):
/// cycles at every level, and the layer order at the top. Errors say what
/// is wrong, one line each.
fn check(src: &Path, page: &str) -> Result<Layering, Vec<String>> {
    let files = rust_files(src);
    let sources: Vec<Source> = files
        .into_iter()
        .map(|file| {
            let text = std::fs::read_to_string(&file).unwrap();
            let code = code_of(&text);
            Source { module: module_of(file.strip_prefix(src).unwrap()), file, text, code }
        })
        .collect();
    // Every module of the crate, to tell module names from items in paths.
    let modules: BTreeSet<Vec<String>> = sources.iter().map(|s| s.module.clone()).filter(|m| !m.is_empty()).collect();
    let exports = re_exports(&sources, &modules);
    let tests = test_files(src, &sources);
    // Edges between the modules two paths' longest module prefixes name
    // (through a folder's re-export to the child that defines the name).
    let mut edges: BTreeSet<(Vec<String>, Vec<String>)> = BTreeSet::new();
    for Source { file, module, code, .. } in &sources {
        // main.rs is the binary (it uses the library by name); the root
        // (lib.rs) holds the shared error types.
        if module.is_empty() || tests.contains(file) {
            continue;
        }
        for path in referenced_paths(module, code) {
            // A name the crate root re-exports (`crate::RenderError`) is
            // its defining module's.
            let path = match path.first().and_then(|name| exports.get(&(Vec::new(), name.clone()))) {
                Some(child) if !modules.contains(&path[..1]) => {
                    let mut p = vec![child.clone()];
                    p.extend(path);
                    p
                }
                _ => path,
            };
            let Some(n) = (1..=path.len()).rev().find(|&n| modules.contains(&path[..n])) else { continue };
            let mut target = path[..n].to_vec();
            if let Some(child) = path.get(n).and_then(|item| exports.get(&(target.clone(), item.clone()))) {
                target.push(child.clone());
            }
            edges.insert((module.clone(), target));
        }
    }
    let mut errors = Vec::new();
    // Cycles: the top level, then the children of every folder module.
    let mut levels: Vec<Vec<String>> = vec![vec![]];
    levels.extend(modules.iter().filter(|m| modules.iter().any(|c| c.len() > m.len() && c.starts_with(m))).cloned());
    let mut sibling_edges = 0;
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
        sibling_edges += graph.values().map(BTreeSet::len).sum::<usize>();
        if let Some(cycle) = find_cycle(&graph) {
            let within = if parent.is_empty() { "the crate".to_string() } else { parent.join("::") };
            errors.push(format!("a module cycle within {within}: {}", cycle.join(" -> ")));
        }
    }
    // The layer order between top-level modules.
    let layers = documented_layers(page);
    let mut rank: BTreeMap<&str, usize> = BTreeMap::new();
    for (r, (name, ms)) in layers.iter().enumerate() {
        for m in ms {
            if let Some(other) = rank.insert(m.as_str(), r) {
                errors.push(format!("module `{m}` is in two layers of the table: {} and {name}", layers[other].0));
            }
        }
    }
    let top: BTreeSet<&str> = modules.iter().map(|m| m[0].as_str()).collect();
    for m in &top {
        if !rank.contains_key(m) {
            errors.push(format!("module `{m}` is in no layer of docs/architecture.md's table"));
        }
    }
    let mut layer_edges = 0;
    for (from, to) in &edges {
        let (a, b) = (from[0].as_str(), to[0].as_str());
        if a == b {
            continue;
        }
        let (Some(&ra), Some(&rb)) = (rank.get(a), rank.get(b)) else { continue };
        layer_edges += 1;
        if rb > ra {
            errors.push(format!(
                "`{}` ({}) uses `{}` ({}), a layer above it",
                from.join("::"),
                layers[ra].0,
                to.join("::"),
                layers[rb].0
            ));
        }
    }
    if errors.is_empty() {
        Ok(Layering { modules: modules.len(), sibling_edges, layer_edges })
    } else {
        Err(errors)
    }
}

fn project() -> (PathBuf, String) {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    (root.join("src"), std::fs::read_to_string(root.join("docs/architecture.md")).unwrap())
}

#[test]
fn modules_form_layers_in_the_documented_order_without_cycles() {
    let (src, page) = project();
    let layers = documented_layers(&page);
    assert!(layers.len() >= 6, "the layers table: {layers:?}");
    match check(&src, &page) {
        Ok(l) => {
            println!(
                "{} modules in {} layers; {} edges between siblings, {} between layers; no cycle, none upward",
                l.modules,
                layers.len(),
                l.sibling_edges,
                l.layer_edges
            );
            assert!(
                l.sibling_edges > 100,
                "too few edges were read ({}): is the source where the test looks?",
                l.sibling_edges
            );
        }
        Err(errors) => panic!("{}", errors.join("\n")),
    }
}

#[test]
fn grouped_imports_and_re_exports_are_read() {
    let code = "use super::{device::Device, sync::{Access, Recording}, self};\nuse crate::{a::b as c, d};";
    let paths = referenced_paths(&["vk".into(), "buffer".into()], code);
    let expected: Vec<Vec<String>> = [
        vec!["vk", "device", "Device"],
        vec!["vk", "sync", "Access"],
        vec!["vk", "sync", "Recording"],
        vec!["vk"],
        vec!["a", "b"],
        vec!["d"],
    ]
    .iter()
    .map(|p| p.iter().map(|s| s.to_string()).collect())
    .collect();
    assert_eq!(paths, expected);
    // The alias a re-export is known by.
    let uses = use_tree(b"a::{b as c, d}", &mut 0);
    assert_eq!(
        uses,
        vec![
            (vec!["a".to_string(), "b".to_string()], Some("c".to_string())),
            (vec!["a".to_string(), "d".to_string()], None)
        ]
    );
    // An out-of-line test module at the top keeps the rest of the file;
    // an inline one at the end is cut.
    let code = code_of("#[cfg(test)]\nmod tests;\nuse crate::a::b;\n#[cfg(test)]\nmod more {\nuse crate::c;\n}");
    assert_eq!(referenced_paths(&["x".into()], &code), vec![vec!["a".to_string(), "b".to_string()]]);
}

/// A copy of the source with `insert` added after the first line of
/// `file`, checked.
fn check_with(file: &str, insert: &str) -> Result<Layering, Vec<String>> {
    let (src, page) = project();
    let dir = tempfile::tempdir().unwrap();
    let copy = dir.path().join("src");
    for f in &rust_files(&src) {
        let to = copy.join(f.strip_prefix(&src).unwrap());
        std::fs::create_dir_all(to.parent().unwrap()).unwrap();
        std::fs::copy(f, &to).unwrap();
    }
    let target = copy.join(file);
    let text = std::fs::read_to_string(&target).unwrap();
    let (first, rest) = text.split_once('\n').unwrap();
    std::fs::write(&target, format!("{first}\n{insert}\n{rest}")).unwrap();
    check(&copy, &page)
}

#[test]
fn an_injected_cycle_inside_vk_through_a_grouped_import_is_caught() {
    // buffer.rs uses sync's Recording (through vk's re-export); sync using
    // buffer back closes a cycle.
    let errors = check_with("vk/sync.rs", "use super::{buffer::Buffer, Device};").err().expect("a cycle");
    println!("{}", errors.join("\n"));
    assert!(errors.iter().any(|e| e.starts_with("a module cycle within vk:")), "{errors:?}");
}

#[test]
fn an_injected_core_module_using_a_tool_is_caught() {
    let errors = check_with("model/geometry/mod.rs", "use crate::{tools::metrics::relative_mse};")
        .err()
        .expect("an upward edge");
    println!("{}", errors.join("\n"));
    assert!(errors.iter().any(|e| e.contains("uses `tools::metrics`") && e.contains("a layer above it")), "{errors:?}");
}
