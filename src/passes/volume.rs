//! The volumetric-lighting pass (`volume.comp`), run before the render pass
//! when the scene has fog and a positional light
//! ([`crate::scene::Scene::needs_volume`]):
//! single scattering toward each point, sphere and rect light along the
//! camera rays' first segments, with shadow rays (light shafts). The render
//! pass adds its per-pixel mean and leaves that part out of its own estimate.

use std::sync::Arc;

use super::gpu::VolumePush;
use super::scene_gpu::GpuScene;
use super::tracer::Tracer;
use super::IntersectMode;
use crate::shader_interface::{BINDING_VOLUME, RENDER_GROUP, SPEC_INTERSECT_MODE};
use crate::vk::{Access, Backend, Binding, Buffer, Commands, Device, GpuTimer, MemoryLocation};
use crate::{shaders, RenderError};

/// Camera rays per pixel in one dispatch of the volume pass.
pub const BATCH: u32 = 16;

/// The volume pass: its pipeline and its output, in-scattered radiance per
/// pixel. [`VolumeLight::new`] builds it for one image size;
/// [`VolumeLight::run`] (re)computes it for the camera in the frame buffer.
pub struct VolumeLight {
    pipeline: Tracer,
    /// Mean in-scattered radiance per pixel (three `f32`).
    pub radiance: Buffer,
    size: (u32, u32),
    /// GPU time of the last run (s).
    pub seconds: f64,
}

impl VolumeLight {
    /// Creates the pipeline and the output for a `width` x `height` image
    /// whose frame parameters are in `frame` (`GpuFrame`), tracing with
    /// `backend`; nothing runs yet.
    pub fn new(
        device: &Arc<Device>,
        gpu: &GpuScene,
        frame: &Buffer,
        (width, height): (u32, u32),
        backend: Backend,
    ) -> Result<Self, RenderError> {
        let radiance =
            Buffer::storage(device, "volume radiance", width as u64 * height as u64 * 12, MemoryLocation::GpuToCpu)?;
        let pipeline = Tracer::new(
            device,
            backend,
            shaders::volume,
            shaders::volume_rgen,
            &[
                [(SPEC_INTERSECT_MODE, gpu.intersect_mode(IntersectMode::Full).constant())].as_slice(),
                &gpu.scene_constants(),
            ]
            .concat(),
        )?;
        let mut bindings = gpu.frame_bindings(frame);
        bindings.push((BINDING_VOLUME, Binding::Buffer(&radiance)));
        pipeline.bind(&bindings)?;
        Ok(Self { pipeline, radiance, size: (width, height), seconds: 0.0 })
    }

    /// Computes the in-scattered radiance with `samples` camera rays per
    /// pixel (dispatched in batches of at most [`BATCH`]).
    pub fn run(&mut self, cmds: &mut Commands, timer: &GpuTimer, samples: u32) -> Result<(), RenderError> {
        let (width, height) = self.size;
        let radiance = &self.radiance;
        let stage = self.pipeline.stage();
        let batch = [Access::ShaderWrite(stage)];
        // The render pass (same backend) read the last run's radiance.
        let ((), mut seconds) = timer.run(cmds, |rec| {
            rec.barrier(&[Access::ShaderRead(stage)], &[Access::TransferWrite]);
            radiance.fill(rec, 0);
        })?;
        for first in (0..samples).step_by(BATCH as usize) {
            let push = VolumePush { first_sample: first, samples: BATCH.min(samples - first), total: samples };
            let ((), t) = timer.run(cmds, |rec| {
                // Each batch adds to what the fill or the last batch left.
                rec.barrier(&[Access::TransferWrite, batch[0]], &batch);
                self.pipeline.run(rec.cmd, bytemuck::bytes_of(&push), [width, height], [RENDER_GROUP, RENDER_GROUP]);
            })?;
            seconds += t;
        }
        self.seconds = seconds;
        Ok(())
    }
}
