//! The switches of the render shader beside the scene's own settings: the
//! benchmark breakdowns (intersection and shading modes), the texture
//! lookup of the filtered modes, the passes to run and path recording. The
//! scene carries everything else (size, samples, depth, filter, seed), and
//! every render entry point takes it from there.

use crate::gpu::shader_interface::{
    INTERSECT_BASE, INTERSECT_BOXES, INTERSECT_FULL, LOOKUP_EWA, LOOKUP_PROBES, SAMPLER_INDEPENDENT, SAMPLER_SOBOL,
    SHADING_ALBEDO, SHADING_FULL, SHADING_GLOSSY_ALBEDO, SHADING_MIRRORED_ALBEDO,
};
use crate::vk::Backend;

/// How candidate boxes are intersected (`SPEC_INTERSECT_MODE`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub enum IntersectMode {
    /// The exact first root of F' (the renderer's mode).
    #[default]
    Full,
    /// Perturbations ignored: the base quadric's roots in each box.
    Base,
    /// Every candidate box is a hit where the ray enters it (traversal cost
    /// only).
    Boxes,
}

impl IntersectMode {
    /// The `INTERSECT_*` value the shaders are specialised with.
    pub fn constant(self) -> u32 {
        match self {
            Self::Full => INTERSECT_FULL,
            Self::Base => INTERSECT_BASE,
            Self::Boxes => INTERSECT_BOXES,
        }
    }
}

/// What the render shader computes at a hit (`SPEC_SHADING_MODE`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub enum ShadingMode {
    /// The path tracer (the renderer's mode).
    #[default]
    Full,
    /// The first hit's albedo only: no light sampling, shadow rays or
    /// bounces (benchmark breakdowns).
    Albedo,
    /// The albedo of the first hit that is not a perfect mirror (filtering
    /// tests through mirrors).
    MirroredAlbedo,
    /// The albedo seen through glossy reflections (filtering tests).
    GlossyAlbedo,
}

impl ShadingMode {
    /// The `SHADING_*` value the render shader is specialised with.
    pub fn constant(self) -> u32 {
        match self {
            Self::Full => SHADING_FULL,
            Self::Albedo => SHADING_ALBEDO,
            Self::MirroredAlbedo => SHADING_MIRRORED_ALBEDO,
            Self::GlossyAlbedo => SHADING_GLOSSY_ALBEDO,
        }
    }
}

/// The texture lookup of the filtered modes (`SPEC_LOOKUP_MODE`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub enum LookupMode {
    /// Trilinear probes along the footprint's major axis (the renderer's
    /// lookup).
    #[default]
    Probes,
    /// Elliptical weighted average (the reference lookup).
    Ewa,
}

impl LookupMode {
    /// The `LOOKUP_*` value the shaders are specialised with.
    pub fn constant(self) -> u32 {
        match self {
            Self::Probes => LOOKUP_PROBES,
            Self::Ewa => LOOKUP_EWA,
        }
    }
}

/// Where the path tracer's random decisions take their numbers
/// (`SPEC_SAMPLER`; glsl/lib/sobol.glsl). The camera jitter keeps its own
/// stratified sequence in both.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash, serde::Serialize)]
pub enum SamplerMode {
    /// Owen-scrambled Sobol points (Burley 2020), one dimension pair per
    /// decision along the path (the renderer's sampler).
    #[default]
    Sobol,
    /// Independent uniform random numbers (the reference for the error's
    /// distribution: its per-pixel errors are plain Monte Carlo noise).
    Independent,
}

impl SamplerMode {
    /// Every sampler, in the order `--sampler` lists them.
    pub const ALL: [SamplerMode; 2] = [SamplerMode::Sobol, SamplerMode::Independent];

    /// The name `--sampler` takes.
    pub fn name(self) -> &'static str {
        match self {
            Self::Sobol => "sobol",
            Self::Independent => "independent",
        }
    }

    /// The `SAMPLER_*` value the render shader is specialised with.
    pub fn constant(self) -> u32 {
        match self {
            Self::Sobol => SAMPLER_SOBOL,
            Self::Independent => SAMPLER_INDEPENDENT,
        }
    }
}

impl std::fmt::Display for SamplerMode {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for SamplerMode {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        crate::model::scene::preset::from_name(&Self::ALL, Self::name, "sampler", s)
    }
}

/// How the render pass runs its paths.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum PathKernel {
    /// One invocation runs a whole path (glsl/render/render.comp, render.rgen).
    Megakernel,
    /// Stage kernels over queues of paths (glsl/render/wavefront.glsl,
    /// [`super::wavefront`]); ray queries only.
    Wavefront,
}

impl PathKernel {
    /// Both, in the order `--kernel` lists them.
    pub const ALL: [PathKernel; 2] = [PathKernel::Megakernel, PathKernel::Wavefront];

    /// The name `--kernel` takes.
    pub fn name(self) -> &'static str {
        match self {
            Self::Megakernel => "megakernel",
            Self::Wavefront => "wavefront",
        }
    }

    /// The kernel a render takes when none is asked for, on `backend`: the
    /// megakernel on the pipeline backend (the wavefront pass traces with
    /// ray queries), else the one measured faster
    /// (docs/benchmarks.md, "Megakernel and wavefront").
    pub fn auto(backend: Backend) -> Self {
        match backend {
            Backend::Pipeline => Self::Megakernel,
            Backend::RayQuery => AUTO_RAY_QUERY_KERNEL,
        }
    }
}

/// What `auto` takes with ray queries (measured: docs/benchmarks.md).
const AUTO_RAY_QUERY_KERNEL: PathKernel = PathKernel::Megakernel;

impl std::fmt::Display for PathKernel {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Variants of the render shader that switch parts of the work off, to
/// measure what bounds a render (the benchmark mode) or to test parts of it.
/// `Default` renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub struct RenderVariant {
    /// How candidate boxes are intersected.
    pub intersect: IntersectMode,
    /// What is computed at a hit.
    pub shading: ShadingMode,
    /// Run the caustic passes when the scene needs them (false: the path
    /// tracer alone estimates caustics, by brute force).
    pub caustics: bool,
    /// Run the volume pass when the scene needs it (false: the path tracer
    /// alone estimates the light scattered by the fog).
    pub volume: bool,
    /// Record the events of one pixel's path
    /// ([`Renderer::trace_path`](super::Renderer::trace_path)); false
    /// compiles the recording out.
    pub record_path: bool,
    /// The filtered modes' texture lookup.
    pub lookup: LookupMode,
    /// The path tracer's samples.
    pub sampler: SamplerMode,
    /// How every tracing pass (render, caustic G-buffer and rays, volume)
    /// traces rays: ray queries, or a ray-tracing pipeline with the
    /// intersection shader. `None` takes the device's preferred one
    /// ([`Device::backend_for`](crate::vk::Device::backend_for)); a backend
    /// asked for that the device lacks is an error, never a fallback.
    /// [`RenderOutput::backend`](super::RenderOutput::backend) says which ran.
    pub backend: Option<Backend>,
    /// How the render pass runs its paths; `None` takes
    /// [`PathKernel::auto`] for the backend. The wavefront pass on the
    /// pipeline backend is an error.
    pub kernel: Option<PathKernel>,
}

impl Default for RenderVariant {
    fn default() -> Self {
        Self {
            intersect: IntersectMode::Full,
            shading: ShadingMode::Full,
            caustics: true,
            volume: true,
            record_path: false,
            lookup: LookupMode::Probes,
            sampler: SamplerMode::Sobol,
            backend: None,
            kernel: None,
        }
    }
}
