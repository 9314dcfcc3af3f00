//! Sampling routines of the path tracer: the CPU twins, in f64, of the GLSL
//! versions the renderer runs in f32.
//!
//! Every routine takes its uniform random numbers (u1, u2, u3 ∈ [0, 1))
//! explicitly and is deterministic, so that the GPU versions can be fed the
//! same numbers and compared, and every sampler has a density function that
//! [`chi2`] tests it against.
//!
//! Conventions (shared with the GLSL):
//! - The local shading frame has the normal on +z; directions are unit
//!   vectors, `wo` points away from the surface toward the viewer (previous
//!   vertex), `wi` toward the next vertex or light; cos θ = w.z.
//! - Perceptual roughness r ∈ [0, 1] gives the GGX α = r²; α <
//!   [`ggx::DELTA_ALPHA`] makes a lobe a delta (perfect specular) lobe.
//! - A BSDF sample ([`BsdfSample`]) carries wi, weight = f |cos θi| / pdf
//!   per RGB channel, and the solid-angle pdf (`None` for a delta lobe).
//!
//! Modules: [`warp`] (hemisphere, sphere and cone warps), [`ggx`] (the
//! microfacet distribution, Smith masking, visible-normal sampling),
//! [`fresnel`], [`bsdf`] (diffuse, conductor, mirror, smooth dielectric),
//! [`lights`] (sphere, rectangle, directional, point and environment lights,
//! the power heuristic), [`envmap`] (importance sampling of a lat-long
//! environment map), [`phase`] (the Henyey–Greenstein phase function of
//! participating media) and [`chi2`] (the chi-square test harness).

pub mod bsdf;
pub mod chi2;
pub mod envmap;
pub mod fresnel;
pub mod ggx;
pub mod lights;
pub mod phase;
pub mod sobol;
pub mod warp;

pub use bsdf::{
    reflect, refract, Bsdf, BsdfSample, Conductor, Diffuse, FresnelModel, Mirror, RoughDielectric, SmoothDielectric,
};
pub use envmap::{direction_to_uv, procedural_sky, uv_to_direction, EnvironmentMap};
pub use fresnel::{fresnel_conductor, fresnel_dielectric, fresnel_schlick};
pub use lights::{
    pdf_rect_light, pdf_sphere_light, pdf_uniform_environment, power_heuristic, sample_directional_light,
    sample_point_light, sample_rect_light, sample_sphere_light, sample_uniform_environment, LightSample,
};
pub use warp::{
    frame_around, pdf_cosine_hemisphere, pdf_uniform_cone, pdf_uniform_sphere, sample_cosine_hemisphere,
    sample_uniform_cone, sample_uniform_sphere, spherical_direction,
};
