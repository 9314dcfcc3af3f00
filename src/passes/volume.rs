//! The volumetric-lighting pass (`volume.comp`), run before the render pass
//! when the scene has fog and a positional light
//! ([`crate::model::scene::Scene::needs_volume`]): single scattering toward each
//! point, sphere and rect light along the camera rays' first segments, with
//! shadows (light shafts). The render pass adds its per-pixel mean and
//! leaves that part out of its own estimate.
//!
//! Visibility is shared: each pass first traces, per positional light, a
//! light map (`light_map.comp`: from one point on the light, the distance
//! to the first surface in every direction of an octahedral map), then casts
//! one camera ray per pixel and tests [`VOLUME_POINTS`] points along it
//! against the maps, with a shadow ray only where a map cannot tell (a
//! shadow's edge). `glsl/volume/light_map.glsl` says why that converges.

use std::sync::Arc;

use super::gpu::{LightMapPush, VolumePush};
use super::scene_gpu::GpuScene;
use super::tracer::Tracer;
use super::IntersectMode;
use super::RenderError;
use crate::gpu::shader_interface::{BINDING_LIGHT_MAPS, BINDING_VOLUME, RENDER_GROUP, SPEC_INTERSECT_MODE};
use crate::gpu::shaders;
use crate::vk::{Access, Backend, Binding, Buffer, Commands, Device, GpuTimer, MemoryLocation};

pub use crate::gpu::shader_interface::VOLUME_POINTS;

/// Texels on a side of a light map for a `width` x `height` image: the
/// power of two nearest above the square root of the pixel count (a map
/// traces about as many rays as a camera ray per pixel), 64 to 1024.
pub fn light_map_size(width: u32, height: u32) -> u32 {
    let side = (f64::from(width) * f64::from(height)).sqrt().ceil() as u32;
    side.next_power_of_two().clamp(64, 1024)
}

/// The volume pass: its pipelines, light maps and output, in-scattered
/// radiance per pixel. [`VolumeLight::new`] builds it for one image size;
/// [`VolumeLight::run`] (re)computes it for the camera in the frame buffer.
pub struct VolumeLight {
    pipeline: Tracer,
    maps: Tracer,
    /// The positional lights' indices (one map each).
    lights: Vec<u32>,
    map_size: u32,
    /// Mean in-scattered radiance per pixel (three `f32`).
    pub radiance: Buffer,
    // Kept alive for the pipelines' bindings.
    _light_maps: Buffer,
    size: (u32, u32),
    /// GPU time of the last run (s).
    pub seconds: f64,
}

impl VolumeLight {
    /// What the render pass reads from the volume pass: its radiance, or
    /// `placeholder` where the pass did not run (`volume` is `None`).
    pub fn render_bindings<'a>(volume: Option<&'a VolumeLight>, placeholder: &'a Buffer) -> [(u32, Binding<'a>); 1] {
        [(BINDING_VOLUME, Binding::Buffer(volume.map_or(placeholder, |v| &v.radiance)))]
    }

    /// Creates the pipelines and buffers for a `width` x `height` image
    /// whose frame parameters are in `frame` (`GpuFrame`), tracing with
    /// `backend`; `positional` are the indices of the scene's point, sphere
    /// and rect lights. Nothing runs yet.
    pub fn new(
        device: &Arc<Device>,
        gpu: &GpuScene,
        frame: &Buffer,
        (width, height): (u32, u32),
        backend: Backend,
        positional: Vec<u32>,
    ) -> Result<Self, RenderError> {
        let radiance =
            Buffer::storage(device, "volume radiance", width as u64 * height as u64 * 12, MemoryLocation::GpuToCpu)?;
        let map_size = light_map_size(width, height);
        // Indexed by light index (lights without a map leave theirs unused).
        let slots = positional.iter().max().map_or(1, |&i| u64::from(i) + 1);
        let light_maps = Buffer::storage(
            device,
            "light maps",
            slots * u64::from(map_size) * u64::from(map_size) * 4,
            MemoryLocation::GpuOnly,
        )?;
        let constants = [
            [(SPEC_INTERSECT_MODE, gpu.intersect_mode(IntersectMode::Full).constant())].as_slice(),
            &gpu.scene_constants(),
        ]
        .concat();
        let pipeline = Tracer::new(device, backend, shaders::volume, shaders::volume_rgen, &constants)?;
        let maps = Tracer::new(device, backend, shaders::light_map, shaders::light_map_rgen, &constants)?;
        let mut bindings = gpu.frame_bindings(frame);
        bindings.push((BINDING_VOLUME, Binding::Buffer(&radiance)));
        bindings.push((BINDING_LIGHT_MAPS, Binding::Buffer(&light_maps)));
        pipeline.bind(&bindings)?;
        maps.bind(&bindings)?;
        Ok(Self {
            pipeline,
            maps,
            lights: positional,
            map_size,
            radiance,
            _light_maps: light_maps,
            size: (width, height),
            seconds: 0.0,
        })
    }

    /// Computes the in-scattered radiance in `passes` passes (one camera ray
    /// per pixel and one light map per positional light each).
    pub fn run(&mut self, cmds: &mut Commands, timer: &GpuTimer, passes: u32) -> Result<(), RenderError> {
        let (width, height) = self.size;
        let radiance = &self.radiance;
        let stage = self.pipeline.stage();
        let (read, write) = (Access::ShaderRead(stage), Access::ShaderWrite(stage));
        // The render pass (same backend) read the last run's radiance.
        let ((), mut seconds) = timer.run(cmds, |rec| {
            rec.barrier(&[read], &[Access::TransferWrite]);
            radiance.fill(rec, 0);
        })?;
        let size = self.map_size;
        for pass in 0..passes {
            let ((), t) = timer.run(cmds, |rec| {
                // The maps: the last pass's gathering read them.
                rec.barrier(&[read], &[write]);
                for (i, &light) in self.lights.iter().enumerate() {
                    // Each light writes its own map; the 1.4 validation
                    // layer sees the whole buffer, so they are ordered.
                    if i > 0 {
                        rec.barrier(&[write], &[write]);
                    }
                    let push = LightMapPush { pass, passes, light, map_size: size };
                    self.maps.run(rec.cmd, bytemuck::bytes_of(&push), [size, size], [RENDER_GROUP, RENDER_GROUP]);
                }
                // The gathering reads the maps and adds to what the fill or
                // the last pass left.
                rec.barrier(&[write, Access::TransferWrite], &[read, write]);
                let push = VolumePush { pass, passes, map_size: size };
                self.pipeline.run(rec.cmd, bytemuck::bytes_of(&push), [width, height], [RENDER_GROUP, RENDER_GROUP]);
            })?;
            seconds += t;
        }
        self.seconds = seconds;
        Ok(())
    }
}
