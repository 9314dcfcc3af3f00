//! The probe pass: closest hits of an explicit list of rays. Used by the
//! GPU-vs-CPU geometry tests and by the ray-throughput benchmark.

use std::sync::Arc;

use super::gpu::{GpuHit, GpuRay, ProbePush};
use super::scene_gpu::GpuScene;
use crate::shader_interface::PROBE_GROUP;
use crate::vk::{vk, Binding, BindingKind, Buffer, Commands, ComputePipeline, Device, MemoryLocation, Timestamps};
use crate::{shaders, RenderError};

/// Rays per dispatch: short enough never to trip a driver watchdog.
const RAYS_PER_DISPATCH: u32 = 1 << 16;

/// A ray-tracing pass over a fixed ray list.
pub struct ProbePass {
    pipeline: ComputePipeline,
    rays: Buffer,
    hits: Buffer,
    count: u32,
    timestamps: Timestamps,
}

impl ProbePass {
    /// Uploads `rays` and binds them with the scene; `mode` is one of the
    /// `INTERSECT_*` constants (`INTERSECT_FULL` for the real intersection);
    /// `curvature` asks for the hits' curvatures (zero otherwise).
    pub fn new(
        device: &Arc<Device>,
        scene: &GpuScene,
        rays: &[GpuRay],
        mode: u32,
        curvature: bool,
    ) -> Result<Self, RenderError> {
        let kinds = [
            BindingKind::AccelerationStructure,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
            BindingKind::StorageBuffer,
        ];
        let pipeline = ComputePipeline::new(
            device,
            &shaders::probe(),
            &kinds,
            std::mem::size_of::<ProbePush>() as u32,
            &[mode, u32::from(curvature)],
        )?;
        let rays_buf = Buffer::with_data(device, "probe rays", rays, vk::BufferUsageFlags::STORAGE_BUFFER)?;
        let hits = Buffer::new(
            device,
            "probe hits",
            (rays.len() * std::mem::size_of::<GpuHit>()) as u64,
            vk::BufferUsageFlags::STORAGE_BUFFER,
            MemoryLocation::GpuToCpu,
        )?;
        let [tlas, objects, cells, perturbations, lists] = scene.geometry_bindings();
        pipeline.bind(&[
            tlas,
            objects,
            cells,
            perturbations,
            lists,
            Binding::Buffer(&rays_buf),
            Binding::Buffer(&hits),
        ]);
        let timestamps = Timestamps::new(device, 2)?;
        Ok(Self { pipeline, rays: rays_buf, hits, count: rays.len() as u32, timestamps })
    }

    /// Traces every ray; returns the hits and the GPU time in nanoseconds.
    pub fn run(&self, cmds: &mut Commands) -> Result<(Vec<GpuHit>, f64), RenderError> {
        let _ = &self.rays;
        cmds.run(|_, cmd| {
            self.timestamps.reset(cmd);
            self.timestamps.write(cmd, 0);
            let mut first = 0;
            while first < self.count {
                let n = (self.count - first).min(RAYS_PER_DISPATCH);
                let push = ProbePush { first, count: n };
                self.pipeline.dispatch(cmd, bytemuck::bytes_of(&push), [n.div_ceil(PROBE_GROUP), 1, 1]);
                first += n;
            }
            self.timestamps.write(cmd, 1);
        })?;
        let ts = self.timestamps.read_ns()?;
        let mut hits: Vec<GpuHit> = self.hits.read();
        hits.truncate(self.count as usize);
        Ok((hits, ts[1] - ts[0]))
    }
}
