//! How a pass traces rays, one of three backends: a compute shader with ray
//! queries (`VK_KHR_ray_query`), a ray-tracing pipeline whose intersection
//! shader solves the perturbed quadric's first root in each candidate box
//! (`VK_KHR_ray_tracing_pipeline`; GPUs without RT cores offer only these),
//! or a compute shader that walks the project's own BVH (no ray-tracing
//! extension). All run the same GLSL: the pass's body is an include that
//! `NAME.comp` (also built as `NAME.bvh.comp`) and `NAME.rgen` call.

use std::sync::Arc;

use crate::shaders;
use crate::vk::{
    vk, Backend, Binding, ComputePipeline, Device, RayTracingPipeline, RayTracingStages, ShaderStage, VkError,
};

/// A pass's shader on one backend.
pub enum Tracer {
    /// Ray queries in a compute shader.
    RayQuery(ComputePipeline),
    /// A ray-tracing pipeline.
    Pipeline(RayTracingPipeline),
    /// The project's BVH walked in a compute shader.
    Compute(ComputePipeline),
}

/// A pass's shader for each backend (functions of [`crate::shaders`]).
#[derive(Clone, Copy)]
pub struct TracerShaders {
    /// The compute shader with ray queries (`glsl/NAME.comp`).
    pub ray_query: fn() -> Vec<u32>,
    /// The ray-generation shader (`glsl/NAME.rgen`).
    pub raygen: fn() -> Vec<u32>,
    /// The compute shader that walks the BVH (`NAME.bvh.comp`).
    pub compute: fn() -> Vec<u32>,
}

impl TracerShaders {
    /// The path tracer.
    pub const RENDER: Self = Self::of(shaders::render, shaders::render_rgen, shaders::render_bvh);
    /// The caustic passes' G-buffer.
    pub const GBUFFER: Self = Self::of(shaders::gbuffer, shaders::gbuffer_rgen, shaders::gbuffer_bvh);
    /// The caustic rays.
    pub const CAUSTIC_TRACE: Self =
        Self::of(shaders::caustic_trace, shaders::caustic_trace_rgen, shaders::caustic_trace_bvh);
    /// The volume pass.
    pub const VOLUME: Self = Self::of(shaders::volume, shaders::volume_rgen, shaders::volume_bvh);
    /// The probe pass.
    pub const PROBE: Self = Self::of(shaders::probe, shaders::probe_rgen, shaders::probe_bvh);

    const fn of(ray_query: fn() -> Vec<u32>, raygen: fn() -> Vec<u32>, compute: fn() -> Vec<u32>) -> Self {
        Self { ray_query, raygen, compute }
    }
}

impl Tracer {
    /// The pass's pipeline for `backend`: the compute shader with ray
    /// queries, the ray-generation shader with the shared miss,
    /// intersection and closest-hit stages, or the compute shader that
    /// walks the BVH; `specialization` as
    /// [`ComputePipeline::new`]. A backend the device was not created with is
    /// an error ([`VkError::BackendUnavailable`]), not a fallback.
    pub fn new(
        device: &Arc<Device>,
        backend: Backend,
        shaders: TracerShaders,
        specialization: &[(u32, u32)],
    ) -> Result<Self, VkError> {
        let backend = device.backend_for(Some(backend))?;
        Ok(match backend {
            Backend::RayQuery => {
                Tracer::RayQuery(ComputePipeline::new(device, &(shaders.ray_query)(), specialization)?)
            }
            Backend::Compute => Tracer::Compute(ComputePipeline::new(device, &(shaders.compute)(), specialization)?),
            Backend::Pipeline => {
                let stages = RayTracingStages {
                    raygen: (shaders.raygen)(),
                    miss: shaders::miss_rmiss(),
                    intersection: shaders::intersect_rint(),
                    closest_hit: shaders::closest_hit_rchit(),
                };
                Tracer::Pipeline(RayTracingPipeline::new(device, &stages, specialization)?)
            }
        })
    }

    /// The backend that runs the pass.
    pub fn backend(&self) -> Backend {
        match self {
            Tracer::RayQuery(_) => Backend::RayQuery,
            Tracer::Pipeline(_) => Backend::Pipeline,
            Tracer::Compute(_) => Backend::Compute,
        }
    }

    /// The shader stage whose accesses the pass's barriers name.
    pub fn stage(&self) -> ShaderStage {
        self.backend().into()
    }

    /// Points the shader's bindings at resources.
    pub fn bind(&self, resources: &[(u32, Binding<'_>)]) -> Result<(), VkError> {
        match self {
            Tracer::RayQuery(p) | Tracer::Compute(p) => p.bind(resources),
            Tracer::Pipeline(p) => p.bind(resources),
        }
    }

    /// Records `size` = (width, height) invocations with push `constants`:
    /// workgroups of `group` invocations a side (rounded up) in compute
    /// shaders, one launch each on the pipeline.
    pub fn run(&self, cmd: vk::CommandBuffer, constants: &[u8], size: [u32; 2], group: [u32; 2]) {
        match self {
            Tracer::RayQuery(p) | Tracer::Compute(p) => {
                p.dispatch(cmd, constants, [size[0].div_ceil(group[0]), size[1].div_ceil(group[1]), 1])
            }
            Tracer::Pipeline(p) => p.trace(cmd, constants, [size[0], size[1], 1]),
        }
    }
}
