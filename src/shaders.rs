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
}
