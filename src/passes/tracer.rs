//! How a pass traces rays, one of two backends: a compute shader with ray
//! queries (`VK_KHR_ray_query`), or a ray-tracing pipeline whose
//! intersection shader solves the perturbed quadric's first root in each
//! candidate box (`VK_KHR_ray_tracing_pipeline`; GPUs without RT cores offer
//! only these). Both run the same GLSL: the pass's body is an include that
//! `NAME.comp` and `NAME.rgen` call.

use std::sync::Arc;

use crate::gpu::shaders;
use crate::vk::{
    vk, Backend, Binding, ComputePipeline, Device, RayTracingPipeline, RayTracingStages, ShaderStage, VkError,
};

/// A pass's shader on one backend.
pub enum Tracer {
    /// Ray queries in a compute shader.
    RayQuery(ComputePipeline),
    /// A ray-tracing pipeline.
    Pipeline(RayTracingPipeline),
}

impl Tracer {
    /// The pass's pipeline for `backend`: the compute shader `compute`, or
    /// the ray-generation shader `raygen` with the shared miss,
    /// intersection and closest-hit stages; `specialization` as
    /// [`ComputePipeline::new`]. A backend the device was not created with is
    /// an error ([`VkError::BackendUnavailable`]), not a fallback.
    pub fn new(
        device: &Arc<Device>,
        backend: Backend,
        compute: fn() -> Vec<u32>,
        raygen: fn() -> Vec<u32>,
        specialization: &[(u32, u32)],
    ) -> Result<Self, VkError> {
        let backend = device.backend_for(Some(backend))?;
        Ok(match backend {
            Backend::RayQuery => Tracer::RayQuery(ComputePipeline::new(device, &compute(), specialization)?),
            Backend::Pipeline => {
                let stages = RayTracingStages {
                    raygen: raygen(),
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
        }
    }

    /// The shader stage whose accesses the pass's barriers name.
    pub fn stage(&self) -> ShaderStage {
        self.backend().into()
    }

    /// Points the shader's bindings at resources.
    pub fn bind(&self, resources: &[(u32, Binding<'_>)]) -> Result<(), VkError> {
        match self {
            Tracer::RayQuery(p) => p.bind(resources),
            Tracer::Pipeline(p) => p.bind(resources),
        }
    }

    /// Records `size` = (width, height) invocations with push `constants`:
    /// workgroups of `group` invocations a side (rounded up) on ray
    /// queries, one launch each on the pipeline.
    pub fn run(&self, cmd: vk::CommandBuffer, constants: &[u8], size: [u32; 2], group: [u32; 2]) {
        match self {
            Tracer::RayQuery(p) => {
                p.dispatch(cmd, constants, [size[0].div_ceil(group[0]), size[1].div_ceil(group[1]), 1])
            }
            Tracer::Pipeline(p) => p.trace(cmd, constants, [size[0], size[1], 1]),
        }
    }
}
