//! SPIR-V of the compute shaders, compiled from `glsl/` by build.rs.

/// Converts embedded SPIR-V bytes to words (copying: `include_bytes!` gives
/// no alignment guarantee).
fn words(bytes: &[u8]) -> Vec<u32> {
    bytemuck::pod_collect_to_vec(bytes)
}

/// One function per shader, returning the SPIR-V that build.rs compiled
/// from `glsl/NAME.comp`, and [`all`] of them with their names.
macro_rules! shaders {
    ($($(#[doc = $doc:literal])* $name:ident,)*) => {
        $(
            $(#[doc = $doc])*
            pub fn $name() -> Vec<u32> {
                words(include_bytes!(concat!(env!("OUT_DIR"), "/", stringify!($name), ".comp.spv")))
            }
        )*

        /// Every compiled shader with its file stem, for interface checks.
        pub fn all() -> Vec<(&'static str, Vec<u32>)> {
            vec![$((stringify!($name), $name())),*]
        }
    };
}

shaders! {
    /// `glsl/render.comp`: the path tracer.
    render,
    /// `glsl/twins.comp`: BSDF and light sampling routines on given inputs, for
    /// the test that compares them with their CPU twins (`sampling`).
    twins,
    /// `glsl/probe.comp`: closest hits of a list of rays.
    probe,
    /// `glsl/texprobe.comp`: filtered texture lookups on given footprints.
    texprobe,
    /// `glsl/gbuffer.comp`: the surface seen through each pixel centre.
    gbuffer,
    /// `glsl/caustic_trace.comp`: caustic rays from the lights through the
    /// specular objects.
    caustic_trace,
    /// `glsl/caustic_splat.comp`: caustic cells splatted into the caustic map.
    caustic_splat,
    /// `glsl/caustic_beams.comp`: volumetric caustics from the caustic rays' last
    /// segments through the fog.
    caustic_beams,
    /// `glsl/volume.comp`: single scattering in the fog toward positional lights.
    volume,
    /// `glsl/light_map.comp`: the volume pass's light maps.
    light_map,
    /// `glsl/loop_budget.comp`: calibrates the loop-budget counter (a test
    /// spends known back-edges, then reads the budget left).
    loop_budget,
}

/// The stages of the ray-tracing-pipeline backend, compiled from
/// `glsl/NAME.EXT` with RAY_TRACING_PIPELINE defined.
macro_rules! pipeline_shaders {
    ($($(#[doc = $doc:literal])* $name:ident = $file:literal,)*) => {
        $(
            $(#[doc = $doc])*
            pub fn $name() -> Vec<u32> {
                words(include_bytes!(concat!(env!("OUT_DIR"), "/", $file, ".spv")))
            }
        )*

        /// Every pipeline stage with its file name, for interface checks.
        pub fn pipeline_all() -> Vec<(&'static str, Vec<u32>)> {
            vec![$(($file, $name())),*]
        }
    };
}

pipeline_shaders! {
    /// `glsl/render.rgen`: the path tracer's ray generation.
    render_rgen = "render.rgen",
    /// `glsl/gbuffer.rgen`: the caustic passes' G-buffer.
    gbuffer_rgen = "gbuffer.rgen",
    /// `glsl/caustic_trace.rgen`: the caustic rays.
    caustic_trace_rgen = "caustic_trace.rgen",
    /// `glsl/volume.rgen`: the volume pass.
    volume_rgen = "volume.rgen",
    /// `glsl/light_map.rgen`: the volume pass's light maps.
    light_map_rgen = "light_map.rgen",
    /// `glsl/probe.rgen`: the probe pass's ray generation.
    probe_rgen = "probe.rgen",
    /// `glsl/intersect.rint`: the first root in a candidate box.
    intersect_rint = "intersect.rint",
    /// `glsl/closest_hit.rchit`: the closest hit into the payload.
    closest_hit_rchit = "closest_hit.rchit",
    /// `glsl/miss.rmiss`: a miss into the payload.
    miss_rmiss = "miss.rmiss",
}
