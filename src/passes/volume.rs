//! The volumetric-lighting pass (`volume.comp`), run before the render pass
//! when the scene has fog and a positional light
//! ([`crate::scene::Scene::needs_volume`]):
//! single scattering toward each point, sphere and rect light along the
//! camera rays' first segments, with shadow rays (light shafts). The render
//! pass adds its per-pixel mean and leaves that part out of its own estimate.

use std::sync::Arc;
use std::time::Instant;

use super::scene_gpu::GpuScene;
use crate::shader_interface::{INTERSECT_FULL, RENDER_GROUP};
use crate::vk::{full_barrier, vk, Binding, BindingKind, Buffer, Commands, ComputePipeline, Device, MemoryLocation};
use crate::{shaders, RenderError};

/// Camera rays per pixel in one dispatch of the volume pass.
pub const BATCH: u32 = 16;

/// The volume pass's output: in-scattered radiance per pixel.
pub struct VolumeLight {
    /// Mean in-scattered radiance per pixel (three `f32`).
    pub radiance: Buffer,
    /// Wall time of the pass (s).
    pub seconds: f64,
}

impl VolumeLight {
    /// Runs the pass for a `width` x `height` image whose frame parameters
    /// are in `frame` (`GpuFrame`), with `samples` camera rays per pixel
    /// (dispatched in batches of at most [`BATCH`]).
    pub fn compute(
        device: &Arc<Device>,
        cmds: &mut Commands,
        gpu: &GpuScene,
        frame: &Buffer,
        (width, height): (u32, u32),
        samples: u32,
    ) -> Result<Self, RenderError> {
        let radiance = Buffer::new(
            device,
            "volume radiance",
            width as u64 * height as u64 * 12,
            vk::BufferUsageFlags::STORAGE_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        let mut kinds = vec![BindingKind::AccelerationStructure];
        kinds.extend([BindingKind::StorageBuffer; 8]);
        let pipeline = ComputePipeline::new(device, &shaders::volume(), &kinds, 12, &[INTERSECT_FULL])?;
        let mut bindings = gpu.frame_bindings(frame);
        bindings.push(Binding::Buffer(&radiance));
        pipeline.bind(&bindings);
        let start = Instant::now();
        cmds.run(|d, cmd| unsafe { d.cmd_fill_buffer(cmd, radiance.raw, 0, vk::WHOLE_SIZE, 0) })?;
        for first in (0..samples).step_by(BATCH as usize) {
            let push = [first, BATCH.min(samples - first), samples];
            cmds.run(|d, cmd| {
                full_barrier(d, cmd);
                pipeline.dispatch(
                    cmd,
                    bytemuck::bytes_of(&push),
                    [width.div_ceil(RENDER_GROUP), height.div_ceil(RENDER_GROUP), 1],
                );
                full_barrier(d, cmd);
            })?;
        }
        Ok(Self { radiance, seconds: start.elapsed().as_secs_f64() })
    }
}
