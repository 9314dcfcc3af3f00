//! Compiles every compute shader under `glsl/` (`*.comp`: compute passes,
//! ray queries) and every ray-tracing-pipeline stage (`*.rgen`, `*.rint`,
//! `*.rchit`, `*.rmiss`: the pipeline backend, built with
//! RAY_TRACING_PIPELINE defined), in whichever folder, to SPIR-V 1.4 for
//! Vulkan 1.2 with shaderc (glslang), with the constants of
//! `src/gpu/shader_interface.rs` as #defines; `#include "name.glsl"` finds the
//! file by name anywhere in `glsl/`. The SPIR-V lands in OUT_DIR with the
//! list of shaders (`shaders.rs`, one function each), which
//! `src/gpu/shaders.rs` includes.
//!
//! It also generates, from the table `src/gpu_structs.toml`, the structs
//! the host shares with the shaders: the GLSL header `gpu_structs.glsl`
//! (OUT_DIR, found by `#include` after `glsl/`) and the Rust structs with
//! their `host_layouts` (`gpu_structs.rs`, included by
//! `src/passes/gpu.rs`).

use std::path::Path;

#[path = "src/vk/naming.rs"]
mod naming;
use naming::snake_case;

/// The table of shared structs.
const STRUCTS: &str = "src/gpu_structs.toml";

fn interface_defines() -> Vec<(String, String)> {
    let text = std::fs::read_to_string("src/gpu/shader_interface.rs").expect("read src/gpu/shader_interface.rs");
    text.lines()
        .filter_map(|l| l.strip_prefix("pub const "))
        .filter_map(|l| {
            let (name, rest) = l.split_once(':')?;
            let value = rest.split_once('=')?.1.trim().trim_end_matches(';').trim();
            Some((name.trim().to_string(), format!("{value}u")))
        })
        .collect()
}

/// One struct of `src/gpu_structs.toml`: its GLSL and Rust names, its doc,
/// the Rust derives, and its fields (GLSL name, GLSL type, doc).
struct SharedStruct {
    glsl: String,
    rust: String,
    doc: String,
    derive: Vec<String>,
    fields: Vec<[String; 3]>,
}

/// Reads `src/gpu_structs.toml` (its format is described at its top).
fn shared_structs() -> Vec<SharedStruct> {
    let text = std::fs::read_to_string(STRUCTS).unwrap_or_else(|e| panic!("{STRUCTS}: {e}"));
    let table: toml::Table = text.parse().unwrap_or_else(|e| panic!("{STRUCTS}: {e}"));
    let string = |v: &toml::Value, what: &str| -> String {
        v.as_str().unwrap_or_else(|| panic!("{STRUCTS}: {what} is not a string")).to_string()
    };
    let mut out: Vec<SharedStruct> = Vec::new();
    for s in table["struct"].as_array().unwrap_or_else(|| panic!("{STRUCTS}: no [[struct]] entries")) {
        let glsl = string(&s["glsl"], "glsl");
        let get = |key: &str| s.get(key).unwrap_or_else(|| panic!("{STRUCTS}: {glsl} has no `{key}`"));
        let derive = match s.get("derive") {
            Some(list) => list.as_array().expect("derive: a list").iter().map(|d| string(d, "derive")).collect(),
            None => ["Clone", "Copy", "Debug", "Default", "Pod", "Zeroable"].map(String::from).to_vec(),
        };
        let fields = get("fields")
            .as_array()
            .expect("fields: a list")
            .iter()
            .map(|f| {
                let f = f
                    .as_array()
                    .filter(|f| f.len() == 3)
                    .unwrap_or_else(|| panic!("{STRUCTS}: {glsl}: a field is [name, GLSL type, doc]"));
                [string(&f[0], "field"), string(&f[1], "type"), string(&f[2], "doc")]
            })
            .collect();
        let rust = string(get("rust"), "rust");
        let doc = string(get("doc"), "doc");
        out.push(SharedStruct { glsl, rust, doc, derive, fields });
    }
    out
}

/// A GLSL type `T` or `T[N]` as its element type and length.
fn split_array(ty: &str) -> (&str, Option<&str>) {
    match ty.split_once('[') {
        Some((element, rest)) => (element, Some(rest.trim_end_matches(']'))),
        None => (ty, None),
    }
}

/// The Rust type of a GLSL type of the table (scalar block layout): a
/// vector is an array of its components, a struct one of the `earlier`
/// structs (GLSL declares a struct before its use) as its Rust twin, an
/// array's length a number or a constant of `src/gpu/shader_interface.rs`.
fn rust_type(ty: &str, earlier: &[SharedStruct], owner: &str) -> String {
    let (element, len) = split_array(ty);
    let base = match element {
        "float" => "f32".to_string(),
        "uint" => "u32".to_string(),
        "int" => "i32".to_string(),
        "double" => "f64".to_string(),
        "vec2" => "[f32; 2]".to_string(),
        "vec3" => "[f32; 3]".to_string(),
        "vec4" => "[f32; 4]".to_string(),
        "uvec2" => "[u32; 2]".to_string(),
        "uvec3" => "[u32; 3]".to_string(),
        "ivec2" => "[i32; 2]".to_string(),
        other => match earlier.iter().find(|s| s.glsl == other) {
            Some(s) => s.rust.clone(),
            None => panic!("{STRUCTS}: {owner}: unknown type {other} (a struct must come before its use)"),
        },
    };
    match len {
        Some(n) if n.chars().all(|c| c.is_ascii_digit()) => format!("[{base}; {n}]"),
        Some(n) => format!("[{base}; crate::gpu::shader_interface::{n} as usize]"),
        None => base,
    }
}

/// `text` as comment lines of at most 100 columns after `prefix`.
fn comment(text: &str, prefix: &str) -> String {
    let mut lines = Vec::new();
    let mut line = String::new();
    for word in text.split_whitespace() {
        if !line.is_empty() && prefix.len() + line.len() + 1 + word.len() > 100 {
            lines.push(std::mem::take(&mut line));
        }
        if !line.is_empty() {
            line.push(' ');
        }
        line.push_str(word);
    }
    lines.push(line);
    lines.iter().map(|l| format!("{prefix}{l}\n")).collect()
}

/// The GLSL header `gpu_structs.glsl`: every struct of the table.
fn glsl_structs(structs: &[SharedStruct]) -> String {
    let mut out = format!(
        "// Generated by build.rs from {STRUCTS}: edit that table, not this file.\n\
         // The structs the host shares with the shaders (scalar block layout).\n\
         #ifndef GPU_STRUCTS_GLSL\n#define GPU_STRUCTS_GLSL\n"
    );
    for s in structs {
        out.push('\n');
        out.push_str(&comment(&s.doc, "// "));
        out.push_str(&format!("struct {} {{\n", s.glsl));
        for [name, ty, doc] in &s.fields {
            out.push_str(&comment(doc, "    // "));
            let (element, len) = split_array(ty);
            match len {
                Some(n) => out.push_str(&format!("    {element} {name}[{n}];\n")),
                None => out.push_str(&format!("    {element} {name};\n")),
            }
        }
        out.push_str("};\n");
    }
    out.push_str("\n#endif\n");
    out
}

/// The Rust structs of the table and `host_layouts`, included by
/// `src/passes/gpu.rs`.
fn rust_structs(structs: &[SharedStruct]) -> String {
    let mut out = format!("// Generated by build.rs from {STRUCTS}: edit that table, not this file.\n");
    for (i, s) in structs.iter().enumerate() {
        out.push('\n');
        out.push_str(&comment(&s.doc, "/// "));
        out.push_str(&format!("///\n/// GLSL: `{}` (`gpu_structs.glsl`).\n", s.glsl));
        out.push_str(&format!("#[repr(C)]\n#[derive({})]\npub struct {} {{\n", s.derive.join(", "), s.rust));
        for [name, ty, doc] in &s.fields {
            out.push_str(&comment(doc, "    /// "));
            out.push_str(&format!("    pub {}: {},\n", snake_case(name), rust_type(ty, &structs[..i], &s.glsl)));
        }
        out.push_str("}\n");
    }
    out.push_str(
        "\n/// Every struct the host shares with the shaders, for the member-by-member\n\
         /// check against their SPIR-V (`tests/scene/interface.rs`): names (GLSL\n\
         /// `camelCase` as Rust `snake_case`), order, offsets, sizes.\n\
         pub fn host_layouts() -> Vec<crate::vk::reflect::HostLayout> {\n    vec![\n",
    );
    for s in structs {
        let fields: Vec<String> = s.fields.iter().map(|[name, _, _]| snake_case(name)).collect();
        out.push_str(&format!(
            "        crate::host_layout!({} as \"{}\" {{ {} }}),\n",
            s.rust,
            s.glsl,
            fields.join(", ")
        ));
    }
    out.push_str("    ]\n}\n");
    out
}

/// The shader stage of a file extension, or None for other files.
fn shader_kind(extension: &str) -> Option<shaderc::ShaderKind> {
    Some(match extension {
        "comp" => shaderc::ShaderKind::Compute,
        "rgen" => shaderc::ShaderKind::RayGeneration,
        "rint" => shaderc::ShaderKind::Intersection,
        "rchit" => shaderc::ShaderKind::ClosestHit,
        "rmiss" => shaderc::ShaderKind::Miss,
        _ => return None,
    })
}

/// Every file under `glsl/`, sorted; file names must be unique across the
/// folders (includes are found by name).
fn glsl_tree() -> Vec<std::path::PathBuf> {
    fn walk(dir: &Path, out: &mut Vec<std::path::PathBuf>) {
        for entry in std::fs::read_dir(dir).unwrap_or_else(|e| panic!("{}: {e}", dir.display())) {
            let path = entry.unwrap().path();
            if path.is_dir() {
                walk(&path, out);
            } else {
                out.push(path);
            }
        }
    }
    let mut files = Vec::new();
    walk(Path::new("glsl"), &mut files);
    files.sort();
    let mut seen = std::collections::BTreeMap::new();
    for f in &files {
        if let Some(other) = seen.insert(f.file_name().unwrap().to_owned(), f.clone()) {
            panic!(
                "{} and {}: file names in glsl/ must be unique (includes are found by name)",
                other.display(),
                f.display()
            );
        }
    }
    files
}

/// The doc comment of a shader: the comment lines at its top (after
/// `#version`), up to the first line that is not one.
fn shader_doc(path: &Path) -> Vec<String> {
    let text = std::fs::read_to_string(path).unwrap();
    text.lines()
        .skip_while(|l| l.starts_with("#version"))
        .map_while(|l| l.strip_prefix("//"))
        .map(|l| l.trim().replace('`', "'"))
        .collect()
}

/// The Rust source of the shader list (`include!`d by `src/gpu/shaders.rs`):
/// one function per shader returning its SPIR-V words, named by the file's
/// stem (compute shaders) or stem and extension (ray-tracing stages), each
/// documented by the shader's own top comment; and `all()` and
/// `pipeline_all()`, every shader with its name.
fn shader_list(sources: &[std::path::PathBuf]) -> String {
    let mut out = String::from("// Generated by build.rs from the shaders under glsl/.\n\n");
    let mut compute = Vec::new();
    let mut pipeline = Vec::new();
    for path in sources {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let (stem, ext) = name.rsplit_once('.').unwrap();
        let function = if ext == "comp" { stem.to_string() } else { format!("{stem}_{ext}") };
        out += &format!("/// `{}`:\n", path.display());
        for line in shader_doc(path) {
            out += &format!("/// {line}\n");
        }
        out += &format!(
            "pub fn {function}() -> Vec<u32> {{\n    words(include_bytes!(concat!(env!(\"OUT_DIR\"), \"/{name}.spv\")))\n}}\n\n"
        );
        if ext == "comp" {
            compute.push((stem.to_string(), function));
        } else {
            pipeline.push((name.clone(), function));
        }
    }
    let list = |items: &[(String, String)]| -> String {
        items.iter().map(|(n, f)| format!("(\"{n}\", {f}())")).collect::<Vec<_>>().join(", ")
    };
    out += &format!(
        "/// Every compute shader with its file stem, for interface checks.\npub fn all() -> Vec<(&'static str, Vec<u32>)> {{\n    vec![{}]\n}}\n\n",
        list(&compute)
    );
    out += &format!(
        "/// Every ray-tracing stage with its file name, for interface checks.\npub fn pipeline_all() -> Vec<(&'static str, Vec<u32>)> {{\n    vec![{}]\n}}\n",
        list(&pipeline)
    );
    out
}

fn main() {
    println!("cargo:rerun-if-changed=glsl");
    println!("cargo:rerun-if-changed=src/gpu/shader_interface.rs");
    println!("cargo:rerun-if-changed={STRUCTS}");
    let out_dir = std::env::var("OUT_DIR").unwrap();
    let structs = shared_structs();
    std::fs::write(Path::new(&out_dir).join("gpu_structs.glsl"), glsl_structs(&structs)).unwrap();
    std::fs::write(Path::new(&out_dir).join("gpu_structs.rs"), rust_structs(&structs)).unwrap();
    let compiler = shaderc::Compiler::new().expect("shaderc compiler");
    let defines = interface_defines();
    let files = glsl_tree();
    // Includes are found by file name wherever they sit in glsl/ (names
    // are unique: glsl_tree checks).
    let by_name: std::collections::BTreeMap<String, std::path::PathBuf> =
        files.iter().map(|p| (p.file_name().unwrap().to_string_lossy().into_owned(), p.clone())).collect();
    let sources: Vec<_> = files
        .iter()
        .filter(|p| p.extension().and_then(|e| e.to_str()).is_some_and(|e| shader_kind(e).is_some()))
        .cloned()
        .collect();
    let mut failed = false;
    for path in &sources {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let source = std::fs::read_to_string(path).unwrap();
        let mut options = shaderc::CompileOptions::new().unwrap();
        options.set_target_env(shaderc::TargetEnv::Vulkan, shaderc::EnvVersion::Vulkan1_2 as u32);
        options.set_target_spirv(shaderc::SpirvVersion::V1_4);
        options.set_optimization_level(shaderc::OptimizationLevel::Performance);
        options.set_generate_debug_info();
        for (k, v) in &defines {
            options.add_macro_definition(k, Some(v));
        }
        let extension = path.extension().and_then(|e| e.to_str()).unwrap_or_default();
        let kind = shader_kind(extension).expect("filtered above");
        if kind != shaderc::ShaderKind::Compute {
            options.add_macro_definition("RAY_TRACING_PIPELINE", Some("1"));
        }
        options.set_include_callback(|requested, _, _, _| {
            let p = by_name.get(requested).cloned().unwrap_or_else(|| Path::new(&out_dir).join(requested));
            std::fs::read_to_string(&p)
                .map(|content| shaderc::ResolvedInclude { resolved_name: p.to_string_lossy().into_owned(), content })
                .map_err(|e| format!("{}: {e}", p.display()))
        });
        match compiler.compile_into_spirv(&source, kind, &name, "main", Some(&options)) {
            Ok(artifact) => {
                if !artifact.get_warning_messages().is_empty() {
                    println!("cargo:warning={name}: {}", artifact.get_warning_messages());
                }
                std::fs::write(Path::new(&out_dir).join(format!("{name}.spv")), artifact.as_binary_u8()).unwrap();
            }
            Err(e) => {
                eprintln!("{e}");
                failed = true;
            }
        }
    }
    std::fs::write(Path::new(&out_dir).join("shaders.rs"), shader_list(&sources)).unwrap();
    if failed {
        panic!("shader compilation failed (see above)");
    }
}
