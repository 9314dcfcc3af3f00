//! Compiles every `glsl/*.comp` (compute passes, ray queries) and every
//! ray-tracing-pipeline stage (`*.rgen`, `*.rint`, `*.rchit`, `*.rmiss`:
//! the pipeline backend, built with RAY_TRACING_PIPELINE defined) to SPIR-V
//! 1.4 for Vulkan 1.2 with shaderc (glslang), with the constants of
//! `src/shader_interface.rs` as #defines.
//! The SPIR-V lands in OUT_DIR and is embedded by `src/shaders.rs`.

use std::path::Path;

fn interface_defines() -> Vec<(String, String)> {
    let text = std::fs::read_to_string("src/shader_interface.rs").expect("read src/shader_interface.rs");
    text.lines()
        .filter_map(|l| l.strip_prefix("pub const "))
        .filter_map(|l| {
            let (name, rest) = l.split_once(':')?;
            let value = rest.split_once('=')?.1.trim().trim_end_matches(';').trim();
            Some((name.trim().to_string(), format!("{value}u")))
        })
        .collect()
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

fn main() {
    println!("cargo:rerun-if-changed=glsl");
    println!("cargo:rerun-if-changed=src/shader_interface.rs");
    let out_dir = std::env::var("OUT_DIR").unwrap();
    let compiler = shaderc::Compiler::new().expect("shaderc compiler");
    let defines = interface_defines();
    let mut sources: Vec<_> = std::fs::read_dir("glsl")
        .expect("glsl/")
        .map(|e| e.unwrap().path())
        .filter(|p| p.extension().and_then(|e| e.to_str()).is_some_and(|e| shader_kind(e).is_some()))
        .collect();
    sources.sort();
    let mut failed = false;
    for path in sources {
        let name = path.file_name().unwrap().to_string_lossy().into_owned();
        let source = std::fs::read_to_string(&path).unwrap();
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
            let p = Path::new("glsl").join(requested);
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
    if failed {
        panic!("shader compilation failed (see above)");
    }
}
