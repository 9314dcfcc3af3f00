//! The render pass: for every sample and every tile, one dispatch that traces
//! camera rays and lights the first hit directly (render.comp). Tiles keep
//! each submission short; progress is reported after each.

use std::sync::Arc;
use std::time::Instant;

use super::caustics::{emitters, CausticMap, CausticReport};
use super::gpu::{GpuAov, GpuFrame, GpuMedium, RenderPush};
use super::scene_gpu::{camera_basis, GpuScene};
use super::volume::VolumeLight;
use crate::scene::Scene;
use crate::shader_interface::{FILTER_NONE, INTERSECT_FULL, MAX_TEXTURES, NO_TEXTURE, RENDER_GROUP, SHADING_FULL};
use crate::vk::{
    full_barrier, vk, Binding, BindingKind, Buffer, Commands, ComputePipeline, Device, Image, MemoryLocation,
};
use crate::{shaders, RenderError};

/// Pixels per tile side: a tile is one dispatch of one sample.
const TILE: u32 = 256;

/// What a render produces: linear radiance and AOVs, row 0 at the top.
pub struct RenderOutput {
    /// Width in pixels.
    pub width: u32,
    /// Height in pixels.
    pub height: u32,
    /// Mean radiance per pixel (linear RGB).
    pub radiance: Vec<[f32; 3]>,
    /// Depth, normal and albedo per pixel from the pixel-centre ray.
    pub aov: Vec<GpuAov>,
    /// Samples per pixel taken.
    pub spp: u32,
    /// Wall time of the GPU work in seconds (the caustic and volume passes included).
    pub seconds: f64,
    /// What the caustic passes did, when they ran.
    pub caustics: Option<CausticReport>,
    /// Wall time of the volume pass (s), when it ran.
    pub volume_seconds: Option<f64>,
}

/// Progress of a render: (work done, total work), in tile-samples.
pub type Progress<'a> = &'a mut dyn FnMut(u64, u64);

/// Variants of the render shader that switch parts of the work off, to
/// measure what bounds a render (the benchmark mode). `Default` renders.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct RenderVariant {
    /// `INTERSECT_FULL`, `INTERSECT_BASE` (perturbation root finding off) or
    /// `INTERSECT_BOXES` (every candidate box is a hit: traversal only).
    pub intersect: u32,
    /// `SHADING_FULL` or `SHADING_NONE` (the first hit's albedo: no light
    /// sampling, no shadow rays, no bounces).
    pub shading: u32,
    /// Texture filtering: `FILTER_NONE`, `FILTER_RAY_CONES` or `FILTER_COVARIANCE`.
    pub filter: u32,
    /// Run the caustic passes when the scene needs them (false: the path
    /// tracer alone estimates caustics, by brute force).
    pub caustics: bool,
    /// Run the volume pass when the scene needs it (false: the path tracer
    /// alone estimates the light scattered by the fog).
    pub volume: bool,
}

impl Default for RenderVariant {
    fn default() -> Self {
        Self { intersect: INTERSECT_FULL, shading: SHADING_FULL, filter: FILTER_NONE, caustics: true, volume: true }
    }
}

/// Renders `scene` at `width` x `height` with `spp` samples per pixel.
pub fn render(
    device: &Arc<Device>,
    cmds: &mut Commands,
    gpu: &GpuScene,
    scene: &Scene,
    (width, height, spp): (u32, u32, u32),
    variant: RenderVariant,
    progress: Progress<'_>,
) -> Result<RenderOutput, RenderError> {
    let pixels = width as u64 * height as u64;
    let [eye, forward, right, up] = camera_basis(scene, width, height);
    let frame = GpuFrame {
        // Relative to the GPU frame's origin (the camera, for renders).
        eye: (eye - gpu.origin).as_vec3().to_array(),
        forward: forward.as_vec3().to_array(),
        right: right.as_vec3().to_array(),
        up: up.as_vec3().to_array(),
        background: scene.background.to_array(),
        width,
        height,
        seed: scene.image.seed,
        light_count: gpu.light_count,
        max_depth: scene.image.max_depth.max(1),
        env_map: gpu.environment.map_or(NO_TEXTURE, |e| e.0),
        env_width: gpu.environment.map_or(0, |e| e.1),
        env_height: gpu.environment.map_or(0, |e| e.2),
        env_scale: gpu.environment.map_or(0.0, |e| e.3),
        fog: GpuMedium::from(scene.fog.as_ref()),
    };
    let frame_buf = Buffer::with_data(device, "frame", &[frame], vk::BufferUsageFlags::STORAGE_BUFFER)?;
    let caustics = caustic_map(device, cmds, gpu, scene, &frame_buf, (width, height), variant)?;
    // Bound in place of the outputs of the passes that did not run.
    let placeholder =
        Buffer::new(device, "placeholder", 24, vk::BufferUsageFlags::STORAGE_BUFFER, MemoryLocation::GpuOnly)?;
    let receivers = caustics.as_ref().map_or(&placeholder, |c| &c.receivers);
    let caustic_map = caustics.as_ref().map_or(&placeholder, |c| &c.map);
    let beam_map = caustics.as_ref().map_or(&placeholder, |c| &c.beams);
    let volume = if variant.volume && variant.shading == SHADING_FULL && scene.needs_volume() {
        Some(VolumeLight::compute(
            device,
            cmds,
            gpu,
            &frame_buf,
            (width, height),
            scene.volume.samples.saturating_mul(spp),
        )?)
    } else {
        None
    };
    let volume_radiance = volume.as_ref().map_or(&placeholder, |v| &v.radiance);
    let accum = Image::new(
        device,
        "accumulation",
        vk::Extent2D { width, height },
        vk::Format::R32G32B32A32_SFLOAT,
        vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST,
    )?;
    let readback = Buffer::new(
        device,
        "accumulation readback",
        pixels * 16,
        vk::BufferUsageFlags::TRANSFER_DST,
        MemoryLocation::GpuToCpu,
    )?;
    let aov = Buffer::new(
        device,
        "aov",
        pixels * std::mem::size_of::<GpuAov>() as u64,
        vk::BufferUsageFlags::STORAGE_BUFFER,
        MemoryLocation::GpuToCpu,
    )?;

    let mut kinds = vec![BindingKind::AccelerationStructure];
    kinds.extend([BindingKind::StorageBuffer; 7]);
    kinds.extend([
        BindingKind::StorageImage,
        BindingKind::StorageBuffer,
        BindingKind::SampledImages(MAX_TEXTURES),
        BindingKind::StorageBuffer,
        BindingKind::StorageBuffer,
        BindingKind::StorageBuffer,
        BindingKind::StorageBuffer,
        BindingKind::StorageBuffer,
    ]);
    let pipeline = ComputePipeline::new(
        device,
        &shaders::render(),
        &kinds,
        std::mem::size_of::<RenderPush>() as u32,
        &[
            variant.intersect,
            variant.shading,
            variant.filter,
            u32::from(scene.has_media()),
            u32::from(caustics.is_some()),
            u32::from(volume.is_some()),
            u32::from(caustics.as_ref().is_some_and(|c| c.has_beams)),
        ],
    )?;
    let mut bindings = gpu.frame_bindings(&frame_buf);
    bindings.extend([
        Binding::Image(&accum),
        Binding::Buffer(&aov),
        gpu.texture_binding(),
        Binding::Buffer(&gpu.env_cdf),
        Binding::Buffer(receivers),
        Binding::Buffer(caustic_map),
        Binding::Buffer(volume_radiance),
        Binding::Buffer(beam_map),
    ]);
    pipeline.bind(&bindings);

    let tiles: Vec<[u32; 4]> = (0..height)
        .step_by(TILE as usize)
        .flat_map(|y| (0..width).step_by(TILE as usize).map(move |x| [x, y, TILE.min(width - x), TILE.min(height - y)]))
        .collect();
    let total = tiles.len() as u64 * spp as u64;
    cmds.run(|_, cmd| {
        accum.transition(cmd, vk::ImageLayout::UNDEFINED, vk::ImageLayout::GENERAL);
        accum.clear(cmd);
    })?;
    let start = Instant::now();
    let mut done = 0;
    for sample in 0..spp {
        for t in &tiles {
            let push = RenderPush {
                tile_origin: [t[0], t[1]],
                tile_size: [t[2], t[3]],
                sample_index: sample,
                write_aov: (sample == 0) as u32,
            };
            cmds.run(|d, cmd| {
                // Earlier submissions' writes to the accumulation image must be visible.
                full_barrier(d, cmd);
                pipeline.dispatch(
                    cmd,
                    bytemuck::bytes_of(&push),
                    [t[2].div_ceil(RENDER_GROUP), t[3].div_ceil(RENDER_GROUP), 1],
                )
            })?;
            done += 1;
            progress(done, total);
        }
    }
    let report = caustics.map(|c| c.report);
    let volume_seconds = volume.as_ref().map(|v| v.seconds);
    let seconds = start.elapsed().as_secs_f64()
        + report.as_ref().map_or(0.0, CausticReport::seconds)
        + volume_seconds.unwrap_or(0.0);

    cmds.run(|d, cmd| {
        full_barrier(d, cmd);
        accum.transition(cmd, vk::ImageLayout::GENERAL, vk::ImageLayout::TRANSFER_SRC_OPTIMAL);
        accum.copy_to_buffer(cmd, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, &readback);
        full_barrier(d, cmd);
    })?;
    let sums: Vec<[f32; 4]> = readback.read();
    let radiance = sums[..pixels as usize]
        .iter()
        .map(|s| {
            let n = s[3].max(1.0);
            [s[0] / n, s[1] / n, s[2] / n]
        })
        .collect();
    let mut aovs: Vec<GpuAov> = aov.read();
    aovs.truncate(pixels as usize);
    Ok(RenderOutput { width, height, radiance, aov: aovs, spp, seconds, caustics: report, volume_seconds })
}

/// Runs the caustic passes when `variant` asks for them and the scene needs
/// them: a light that emits caustic rays, a specular object, a diffuse
/// receiver, and a path depth that allows a specular vertex between a
/// receiver and a light (max_depth ≥ 3).
fn caustic_map(
    device: &Arc<Device>,
    cmds: &mut Commands,
    gpu: &GpuScene,
    scene: &Scene,
    frame: &Buffer,
    size: (u32, u32),
    variant: RenderVariant,
) -> Result<Option<CausticMap>, RenderError> {
    let max_depth = scene.image.max_depth.max(1);
    if !variant.caustics || variant.shading != SHADING_FULL || !scene.needs_caustics() || max_depth < 3 {
        return Ok(None);
    }
    // A caustic path from the camera: the receiver (a bounce), the specular
    // vertices (a bounce each), then the light found by the next segment.
    let Some(grids) = emitters(scene, gpu.origin, max_depth - 2) else {
        log::warn!("a light is inside the bounds of the specular objects: caustics are left to the path tracer");
        return Ok(None);
    };
    Ok(Some(CausticMap::compute(device, cmds, gpu, scene, frame, size, &grids)?))
}
