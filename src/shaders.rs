//! SPIR-V of the compute shaders, compiled from `glsl/` by build.rs.

/// Converts embedded SPIR-V bytes to words (copying: `include_bytes!` gives
/// no alignment guarantee).
fn words(bytes: &[u8]) -> Vec<u32> {
    bytemuck::pod_collect_to_vec(bytes)
}

/// `glsl/render.comp`: camera rays and direct lighting.
pub fn render() -> Vec<u32> {
    words(include_bytes!(concat!(env!("OUT_DIR"), "/render.comp.spv")))
}

/// `glsl/twins.comp`: BSDF and light sampling routines on given inputs, for
/// the test that compares them with their CPU twins (`sampling`).
pub fn twins() -> Vec<u32> {
    words(include_bytes!(concat!(env!("OUT_DIR"), "/twins.comp.spv")))
}

/// `glsl/probe.comp`: closest hits of a list of rays.
pub fn probe() -> Vec<u32> {
    words(include_bytes!(concat!(env!("OUT_DIR"), "/probe.comp.spv")))
}

/// `glsl/texprobe.comp`: filtered texture lookups on given footprints.
pub fn texprobe() -> Vec<u32> {
    words(include_bytes!(concat!(env!("OUT_DIR"), "/texprobe.comp.spv")))
}

/// `glsl/gbuffer.comp`: the surface seen through each pixel centre.
pub fn gbuffer() -> Vec<u32> {
    words(include_bytes!(concat!(env!("OUT_DIR"), "/gbuffer.comp.spv")))
}

/// `glsl/caustic_trace.comp`: caustic rays from the lights through the
/// specular objects.
pub fn caustic_trace() -> Vec<u32> {
    words(include_bytes!(concat!(env!("OUT_DIR"), "/caustic_trace.comp.spv")))
}

/// `glsl/caustic_splat.comp`: caustic cells splatted into the caustic map.
pub fn caustic_splat() -> Vec<u32> {
    words(include_bytes!(concat!(env!("OUT_DIR"), "/caustic_splat.comp.spv")))
}

/// `glsl/volume.comp`: single scattering in the fog toward positional lights.
pub fn volume() -> Vec<u32> {
    words(include_bytes!(concat!(env!("OUT_DIR"), "/volume.comp.spv")))
}

/// `glsl/caustic_beams.comp`: volumetric caustics from the caustic rays' last
/// segments through the fog.
pub fn caustic_beams() -> Vec<u32> {
    words(include_bytes!(concat!(env!("OUT_DIR"), "/caustic_beams.comp.spv")))
}

/// Every compiled shader with its file stem, for interface checks.
pub fn all() -> Vec<(&'static str, Vec<u32>)> {
    vec![
        ("render", render()),
        ("twins", twins()),
        ("probe", probe()),
        ("texprobe", texprobe()),
        ("gbuffer", gbuffer()),
        ("caustic_trace", caustic_trace()),
        ("caustic_splat", caustic_splat()),
        ("caustic_beams", caustic_beams()),
        ("volume", volume()),
    ]
}
