//! SPIR-V of the shaders, compiled from `glsl/` by build.rs: one function
//! per shader, named by its file (`render()` for `glsl/render/render.comp`,
//! `render_rgen()` for `render.rgen`), documented by the shader's own top
//! comment. build.rs generates the list by walking `glsl/`, so a new shader
//! is its file alone.

/// Converts embedded SPIR-V bytes to words (copying: `include_bytes!` gives
/// no alignment guarantee).
fn words(bytes: &[u8]) -> Vec<u32> {
    bytemuck::pod_collect_to_vec(bytes)
}

include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
