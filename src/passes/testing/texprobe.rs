//! The texture probe pass: filtered lookups (EWA, LEAN widening) of a scene's
//! textures on an explicit list of footprints. Used by the texture-filtering
//! tests to compare the shader's filters with analytic answers.

use std::sync::Arc;

use crate::gpu::shader_interface::{BINDING_TEXPROBE_QUERIES, BINDING_TEXPROBE_RESULTS, PROBE_GROUP, SPEC_LOOKUP_MODE};
use crate::gpu::shaders;
use crate::passes::gpu::{GpuTexQuery, GpuTexResult, ProbePush};
use crate::passes::scene_gpu::GpuScene;
use crate::passes::{LookupMode, RenderError};
use crate::vk::{vk, Access, Binding, Buffer, Commands, ComputePipeline, Device, MemoryLocation, ShaderStage};

/// Lookups per dispatch.
const QUERIES_PER_DISPATCH: u32 = 1 << 14;

/// A texture-lookup pass over a fixed list of footprints.
pub struct TexProbePass {
    pipeline: ComputePipeline,
    _queries: Buffer,
    results: Buffer,
    count: u32,
}

impl TexProbePass {
    /// Uploads `queries` and binds them with the scene's textures; EWA lookups.
    pub fn new(device: &Arc<Device>, scene: &GpuScene, queries: &[GpuTexQuery]) -> Result<Self, RenderError> {
        Self::with_lookup(device, scene, queries, LookupMode::Ewa)
    }

    /// As [`TexProbePass::new`], with the lookup `LookupMode::Ewa` or `LookupMode::Probes`.
    pub fn with_lookup(
        device: &Arc<Device>,
        scene: &GpuScene,
        queries: &[GpuTexQuery],
        lookup: LookupMode,
    ) -> Result<Self, RenderError> {
        let pipeline = ComputePipeline::new(device, &shaders::texprobe(), &[(SPEC_LOOKUP_MODE, lookup.constant())])?;
        let query_buf = Buffer::with_data(device, "texture queries", queries, vk::BufferUsageFlags::STORAGE_BUFFER)?;
        let results = Buffer::storage(
            device,
            "texture query results",
            (queries.len().max(1) * std::mem::size_of::<GpuTexResult>()) as u64,
            MemoryLocation::GpuToCpu,
        )?;
        pipeline.bind(&[
            scene.texture_binding(),
            (BINDING_TEXPROBE_QUERIES, Binding::Buffer(&query_buf)),
            (BINDING_TEXPROBE_RESULTS, Binding::Buffer(&results)),
        ])?;
        Ok(Self { pipeline, _queries: query_buf, results, count: queries.len() as u32 })
    }

    /// Runs every lookup and returns the results in query order.
    pub fn run(&self, cmds: &mut Commands) -> Result<Vec<GpuTexResult>, RenderError> {
        let written = [Access::ShaderWrite(ShaderStage::Compute)];
        cmds.run(|rec| {
            // An earlier run wrote the same results.
            rec.barrier(&written, &written);
            let mut first = 0;
            while first < self.count {
                // Each dispatch writes its own range (ordered for the 1.4
                // validation layer, which sees the whole buffer).
                if first > 0 {
                    rec.barrier(&written, &written);
                }
                let n = (self.count - first).min(QUERIES_PER_DISPATCH);
                let push = ProbePush { first, count: n };
                self.pipeline.dispatch(rec.cmd, bytemuck::bytes_of(&push), [n.div_ceil(PROBE_GROUP), 1, 1]);
                first += n;
            }
        })?;
        let mut results: Vec<GpuTexResult> = self.results.read();
        results.truncate(self.count as usize);
        Ok(results)
    }
}
