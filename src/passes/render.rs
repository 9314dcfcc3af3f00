//! The render pass: for every sample and every tile, a path from every
//! pixel of the tile (the path tracer of glsl/render/render.glsl), run by one
//! dispatch of the megakernel (glsl/render/render.comp, render.rgen) or by the
//! wavefront pass's stage kernels ([`super::wavefront`]). Tiles keep each
//! submission short; progress is reported after each.

use std::sync::Arc;

use super::caustics::{emitters, CausticMap, CausticReport};
use super::config::RenderConfig;
use super::film::{Accumulation, PixelBounds, RenderOutput};
use super::gpu::{GpuAov, GpuCausticRay, GpuEmitter, GpuFrame, GpuMedium, GpuPathRecord, GpuPathVertex, RenderPush};
use super::scene_gpu::{camera_basis, GpuScene};
use super::tracer::Tracer;
use super::volume::VolumeLight;
use super::wavefront::{WaveProfile, Wavefront};
use super::RenderError;
use super::{PathKernel, RenderVariant, ShadingMode};
use crate::gpu::shader_interface::{
    BINDING_ACCUM, BINDING_AOV, BINDING_ENV_CDF, BINDING_RENDER_MAX_SAMPLE, BINDING_RENDER_PATH, NO_TEXTURE,
    PATH_RECORD_VERTICES, RENDER_GROUP, RENDER_TILE,
};
use crate::gpu::shaders;
use crate::model::scene::Scene;
use crate::vk::{
    vk, Access, Backend, Binding, Buffer, Commands, Device, GpuTimer, Image, MemoryLocation, ShaderStage, VkError,
};

/// Pixels per tile side: a tile is one dispatch of one sample.
const TILE: u32 = RENDER_TILE;

/// The render pass's paths, run by one of two kernels ([`PathKernel`]).
enum PathPass {
    /// One invocation a path, on either backend.
    Megakernel(Box<Tracer>),
    /// Stage kernels over queues (ray queries).
    Wavefront(Box<Wavefront>),
}

impl PathPass {
    /// The backend that traces.
    fn backend(&self) -> Backend {
        match self {
            PathPass::Megakernel(t) => t.backend(),
            PathPass::Wavefront(_) => Backend::RayQuery,
        }
    }

    /// The shader stage whose accesses the pass's barriers name.
    fn stage(&self) -> ShaderStage {
        self.backend().into()
    }

    fn bind(&self, resources: &[(u32, Binding<'_>)]) -> Result<(), VkError> {
        match self {
            PathPass::Megakernel(t) => t.bind(resources),
            PathPass::Wavefront(w) => w.bind(resources),
        }
    }

    /// Adds one sample of the tile `push` names, after `before` (with
    /// `access`, the pass's own); returns its GPU time in seconds.
    fn run_tile(
        &self,
        cmds: &mut Commands,
        timer: &GpuTimer,
        push: RenderPush,
        (before, access): (&[Access], &[Access]),
    ) -> Result<f64, VkError> {
        match self {
            PathPass::Megakernel(t) => {
                let size = push.tile_size;
                let group = if size == [1, 1] { [1, 1] } else { [RENDER_GROUP, RENDER_GROUP] };
                let ((), seconds) = timer.run(cmds, |rec| {
                    rec.barrier(before, access);
                    t.run(rec.cmd, bytemuck::bytes_of(&push), size, group)
                })?;
                Ok(seconds)
            }
            PathPass::Wavefront(w) => w.render_tile(cmds, timer, push, before),
        }
    }
}

/// The events of one recorded path ([`Renderer::trace_path`]).
#[derive(Clone, Debug, Default)]
pub struct RecordedPath {
    /// The events in order. A path with more events than the record holds
    /// (`PATH_RECORD_VERTICES`) keeps its first ones and its end.
    pub events: Vec<GpuPathVertex>,
    /// How many events before the end did not fit in the record.
    pub left_out: u32,
}

/// Progress of a render: (work done, total work), in tile-samples.
pub type Progress<'a> = &'a mut dyn FnMut(u64, u64);

/// Renders `scene` at its image settings (size, samples per pixel, depth,
/// filter, seed) with the shader `variant`.
pub fn render(
    device: &Arc<Device>,
    cmds: &mut Commands,
    gpu: &GpuScene,
    scene: &Scene,
    variant: RenderVariant,
    progress: Progress<'_>,
) -> Result<RenderOutput, RenderError> {
    let mut renderer = Renderer::new(device, cmds, gpu, scene, variant)?;
    renderer.add_samples(cmds, scene.image.spp, progress)?;
    let mut out = renderer.output(cmds)?;
    renderer.read_caustic_statistics(&mut out);
    Ok(out)
}

/// The pixel filter of every mode and of the reference: a Gaussian of this
/// σ, in pixels (pbrt-v4's default Gaussian filter has the same σ). The
/// camera rays sample it (camera.glsl, cameraJitter); the filtered modes
/// split it between jitter and footprint.
pub const PIXEL_FILTER_SIGMA: f32 = 0.5;

/// How far from its pixel's centre a camera ray can land, in pixels: the
/// jitter is a Box-Muller Gaussian of σ = [`PIXEL_FILTER_SIGMA`] driven by
/// 24-bit uniform numbers, so its radius is at most σ·√(−2 ln 2⁻²⁴)
/// = 2.884 px (`gaussianPixelOffset` in glsl/intersection/frame.glsl). Tests that skip
/// pixels near an edge skip this far.
pub const PIXEL_FILTER_REACH: f32 = PIXEL_FILTER_SIGMA * 5.768_108;

/// The largest share of the pixel filter's variance that a filtered mode's
/// footprint carries (at one sample per pixel); the rest is jitter, which
/// antialiases what texture filtering cannot (object edges, shading).
pub const FOOTPRINT_FRACTION_MAX: f32 = 0.75;

/// The share of the pixel filter's variance that the filtered modes'
/// footprints carry at `spp` samples per pixel: 1/√spp, at most
/// [`FOOTPRINT_FRACTION_MAX`]. Any share in [0, 1] leaves the estimate
/// unbiased where the texture mapping is locally affine (jitter ⊛ footprint
/// is the pixel filter); shrinking it with the sample count (as pbrt scales
/// its ray differentials by max(1/8, 1/√spp)) makes the error that
/// filtering leaves elsewhere (object edges, curved mappings, LEAN's
/// approximation of a glossy lobe) vanish as samples grow, at the rate of
/// the noise.
pub fn footprint_fraction(spp: u32) -> f32 {
    FOOTPRINT_FRACTION_MAX.min(1.0 / (spp.max(1) as f32).sqrt())
}

/// The camera and image parameters of the shaders' `Frame` block, for a
/// render of `spp` samples per pixel.
fn gpu_frame(scene: &Scene, gpu: &GpuScene, width: u32, height: u32, spp: u32) -> GpuFrame {
    let [eye, forward, right, up] = camera_basis(scene, width, height);
    GpuFrame {
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
        pixel_sigma: PIXEL_FILTER_SIGMA,
        // Without maps there is nothing to filter: every mode jitters over
        // the whole pixel filter, as `none` does.
        footprint_fraction: if scene.has_texture_maps() { footprint_fraction(spp) } else { 0.0 },
    }
}

/// A progressive render: the passes a scene needs, built once for an image
/// size and a [`RenderVariant`], and an accumulation image that samples are
/// added to. The viewer keeps one and resets it when the camera moves; an
/// offscreen [`render`] adds all its samples to a fresh one.
///
/// The caustic and volume passes run when the renderer is made and after
/// each [`Renderer::set_camera`], the volume pass with `[volume] samples` ×
/// `spp` camera rays per pixel, so that a render of `spp` samples gets the
/// same estimate however it is split.
pub struct Renderer {
    // Pipelines first: dropped before the buffers their descriptors name.
    pipeline: PathPass,
    device: Arc<Device>,
    caustics: Option<CausticMap>,
    volume: Option<VolumeLight>,
    frame: Buffer,
    // Bound in place of the outputs of passes that do not run; only held.
    _placeholder: Buffer,
    accum: Image,
    max_sample: Image,
    readback: Buffer,
    path: Buffer,
    /// The AOVs and feature sums (device memory), and their host copy.
    aov: Buffer,
    aov_readback: Buffer,
    timer: GpuTimer,
    tiles: Vec<[u32; 4]>,
    // Tiles of sample `samples` already added (an interrupted sample).
    tiles_done: usize,
    size: (u32, u32),
    bounds: PixelBounds,
    // The samples per pixel the render was made for (the footprints' share).
    spp: u32,
    volume_samples: u32,
    samples: u32,
    render_seconds: f64,
}

impl Renderer {
    /// Builds the passes `scene` needs for an image of its size (the
    /// footprints and the volume pass sized for its samples per pixel), runs
    /// the caustic and volume passes for the scene's camera, and clears the
    /// accumulation.
    pub fn new(
        device: &Arc<Device>,
        cmds: &mut Commands,
        gpu: &GpuScene,
        scene: &Scene,
        variant: RenderVariant,
    ) -> Result<Self, RenderError> {
        let full = PixelBounds::full(scene.image.width, scene.image.height);
        Self::with_bounds(device, cmds, gpu, scene, full, variant)
    }

    /// [`Renderer::new`] for the pixels of `bounds` alone (a crop or tile
    /// of the scene's frame): samples are taken only there, with
    /// the same random numbers as in a render of the whole frame. The
    /// caustic and volume passes still cover the whole frame.
    pub fn with_bounds(
        device: &Arc<Device>,
        cmds: &mut Commands,
        gpu: &GpuScene,
        scene: &Scene,
        bounds: PixelBounds,
        variant: RenderVariant,
    ) -> Result<Self, RenderError> {
        let im = &scene.image;
        Self::build(device, cmds, gpu, scene, (im.width, im.height, im.spp), bounds, variant)
    }

    /// [`Renderer::new`] for a view that accumulates `spp` samples per
    /// pixel in place of the scene's (the viewer's target).
    pub fn with_samples(
        device: &Arc<Device>,
        cmds: &mut Commands,
        gpu: &GpuScene,
        scene: &Scene,
        spp: u32,
        variant: RenderVariant,
    ) -> Result<Self, RenderError> {
        let (width, height) = (scene.image.width, scene.image.height);
        Self::build(device, cmds, gpu, scene, (width, height, spp), PixelBounds::full(width, height), variant)
    }

    /// Renders one sample of an 8x8 image of `scene` with `variant` and
    /// drops it: lavapipe compiles each pipeline at its first dispatch, so
    /// timed renders warm up first (without copying the scene, whose maps
    /// may be large).
    pub fn warm_up(
        device: &Arc<Device>,
        cmds: &mut Commands,
        gpu: &GpuScene,
        scene: &Scene,
        variant: RenderVariant,
    ) -> Result<(), RenderError> {
        let mut r = Self::build(device, cmds, gpu, scene, (8, 8, 1), PixelBounds::full(8, 8), variant)?;
        r.add_samples(cmds, 1, &mut |_, _| {})
    }

    fn build(
        device: &Arc<Device>,
        cmds: &mut Commands,
        gpu: &GpuScene,
        scene: &Scene,
        (width, height, spp): (u32, u32, u32),
        bounds: PixelBounds,
        variant: RenderVariant,
    ) -> Result<Self, RenderError> {
        let bounds = bounds.check(width, height)?;
        // One backend for every tracing pass, resolved once.
        let backend = device.backend_for(variant.backend)?;
        let pixels = width as u64 * height as u64;
        let frame = Buffer::with_data(
            device,
            "frame",
            &[gpu_frame(scene, gpu, width, height, spp)],
            vk::BufferUsageFlags::STORAGE_BUFFER,
        )?;
        let caustics = caustic_map(device, gpu, scene, &frame, (width, height), variant, backend)?;
        let volume = if variant.volume && variant.shading == ShadingMode::Full && scene.needs_volume() {
            let positional = (0u32..).zip(&scene.lights).filter(|(_, l)| l.is_positional()).map(|(i, _)| i).collect();
            Some(VolumeLight::new(device, gpu, &frame, (width, height), backend, positional)?)
        } else {
            None
        };
        // Bound in place of the outputs of the passes that did not run.
        let placeholder = Buffer::storage(device, "placeholder", 24, MemoryLocation::GpuOnly)?;
        let accum =
            Image::storage(device, "accumulation", vk::Extent2D { width, height }, vk::Format::R32G32B32A32_SFLOAT)?;
        let max_sample =
            Image::storage(device, "largest sample", vk::Extent2D { width, height }, vk::Format::R32G32_SFLOAT)?;
        // Holds the accumulation, then the largest samples (half its size).
        let readback = Buffer::new(
            device,
            "accumulation readback",
            pixels * 16,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        // The AOVs and the denoiser's feature sums: read and written by every
        // sample, so in device memory; copied to `aov_readback` to be read.
        let aov_bytes = pixels * std::mem::size_of::<GpuAov>() as u64;
        let aov_usage = vk::BufferUsageFlags::STORAGE_BUFFER
            | vk::BufferUsageFlags::TRANSFER_SRC
            | vk::BufferUsageFlags::TRANSFER_DST;
        let aov = Buffer::new(device, "aov", aov_bytes, aov_usage, MemoryLocation::GpuOnly)?;
        let aov_readback = Buffer::new(
            device,
            "aov readback",
            aov_bytes,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        // The recorded path (`GpuPathRecord`): a count, then the vertices.
        let path_bytes = std::mem::size_of::<GpuPathRecord>() as u64;
        let path = Buffer::storage(device, "recorded path", path_bytes, MemoryLocation::GpuToCpu)?;
        let pipeline = render_pipeline(device, gpu, scene, (variant, backend), caustics.as_ref(), volume.is_some())?;
        {
            let mut bindings = gpu.frame_bindings(&frame);
            bindings.extend([
                (BINDING_ACCUM, Binding::Image(&accum)),
                (BINDING_AOV, Binding::Buffer(&aov)),
                gpu.texture_binding(),
                (BINDING_ENV_CDF, Binding::Buffer(&gpu.env_cdf)),
                (BINDING_RENDER_MAX_SAMPLE, Binding::Image(&max_sample)),
                (BINDING_RENDER_PATH, Binding::Buffer(&path)),
            ]);
            // What the passes that ran before made (placeholders for those
            // that did not).
            bindings.extend(CausticMap::render_bindings(caustics.as_ref(), &placeholder));
            bindings.extend(VolumeLight::render_bindings(volume.as_ref(), &placeholder));
            pipeline.bind(&bindings)?;
        }
        // Cleared next (restart), then written by the samples.
        let first_use = [Access::TransferWrite];
        cmds.run(|rec| {
            for image in [&accum, &max_sample] {
                image.transition(rec, (&[], vk::ImageLayout::UNDEFINED), (&first_use, vk::ImageLayout::GENERAL));
            }
        })?;
        let PixelBounds { x0, x1, y0, y1 } = bounds;
        let tiles = (y0..y1)
            .step_by(TILE as usize)
            .flat_map(|y| (x0..x1).step_by(TILE as usize).map(move |x| [x, y, TILE.min(x1 - x), TILE.min(y1 - y)]))
            .collect();
        let mut renderer = Self {
            pipeline,
            device: device.clone(),
            caustics,
            volume,
            frame,
            _placeholder: placeholder,
            accum,
            max_sample,
            readback,
            path,
            aov,
            aov_readback,
            timer: GpuTimer::new(device)?,
            tiles,
            tiles_done: 0,
            size: (width, height),
            bounds,
            spp,
            volume_samples: scene.volume.samples.saturating_mul(spp),
            samples: 0,
            render_seconds: 0.0,
        };
        renderer.restart(cmds)?;
        Ok(renderer)
    }

    /// Moves to `scene`'s camera (and its other frame parameters: seed,
    /// depth, background, fog): reruns the caustic and volume passes and
    /// clears the accumulated samples. The scene's objects, lights and
    /// materials must be those the renderer was built with.
    pub fn set_camera(&mut self, cmds: &mut Commands, gpu: &GpuScene, scene: &Scene) -> Result<(), RenderError> {
        let (width, height) = self.size;
        self.frame.write(0, bytemuck::bytes_of(&gpu_frame(scene, gpu, width, height, self.spp)));
        self.restart(cmds)
    }

    /// Runs the caustic and volume passes and clears the accumulation.
    fn restart(&mut self, cmds: &mut Commands) -> Result<(), RenderError> {
        if let Some(c) = &mut self.caustics {
            c.run(cmds, &self.timer)?;
        }
        if let Some(v) = &mut self.volume {
            v.run(cmds, &self.timer, self.volume_samples)?;
        }
        let (accum, max_sample) = (&self.accum, &self.max_sample);
        // The last samples read and wrote the images the clear overwrites.
        let samples = [Access::ShaderWrite(self.pipeline.stage())];
        cmds.run(|rec| {
            rec.barrier(&samples, &[Access::TransferWrite]);
            accum.clear(rec.cmd);
            max_sample.clear(rec.cmd);
        })?;
        self.samples = 0;
        self.tiles_done = 0;
        self.render_seconds = 0.0;
        Ok(())
    }

    /// What a sample's dispatch waits for, and its own access: what earlier
    /// submissions wrote must be visible to it (the clear or a restored
    /// accumulation, the caustic and volume passes in compute shaders or
    /// the tracing stage, the last sample).
    fn sample_dependency(&self) -> ([Access; 3], [Access; 1]) {
        let sample = Access::ShaderWrite(self.pipeline.stage());
        ([Access::TransferWrite, Access::ShaderWrite(ShaderStage::Compute), sample], [sample])
    }

    /// Samples per pixel accumulated since the last reset.
    pub fn samples(&self) -> u32 {
        self.samples
    }

    /// Image width and height in pixels.
    pub fn size(&self) -> (u32, u32) {
        self.size
    }

    /// GPU time of the work since the last reset (s): the caustic and volume
    /// passes and the samples.
    pub fn seconds(&self) -> f64 {
        self.render_seconds
            + self.caustics.as_ref().map_or(0.0, |c| c.report.seconds())
            + self.volume_seconds().unwrap_or(0.0)
    }

    /// Where the wavefront pass's GPU time went, stage by stage (none with
    /// the megakernel).
    pub fn wave_profile(&self) -> Option<WaveProfile> {
        match &self.pipeline {
            PathPass::Wavefront(w) => Some(w.profile()),
            PathPass::Megakernel(_) => None,
        }
    }

    /// GPU time of the volume pass's last run (s), when the pass runs.
    pub fn volume_seconds(&self) -> Option<f64> {
        self.volume.as_ref().map(|v| v.seconds)
    }

    /// Adds `count` samples per pixel, one dispatch per tile and sample,
    /// reporting progress in tile-samples.
    pub fn add_samples(&mut self, cmds: &mut Commands, count: u32, progress: Progress<'_>) -> Result<(), RenderError> {
        let target = self.samples + count;
        self.add_samples_until(cmds, target, progress, &mut || false)?;
        Ok(())
    }

    /// Adds samples until `target` samples per pixel are accumulated, one
    /// dispatch per tile and sample, reporting progress in tile-samples
    /// (of the work left when called). `stop` is asked after every dispatch;
    /// when it says so, the render stops there (between two tiles of a
    /// sample, maybe) and returns false: [`Renderer::accumulation`] then
    /// holds the work so far, and [`Renderer::restore`] continues it as if
    /// nothing had happened. Returns true when `target` is reached.
    pub fn add_samples_until(
        &mut self,
        cmds: &mut Commands,
        target: u32,
        progress: Progress<'_>,
        stop: &mut dyn FnMut() -> bool,
    ) -> Result<bool, RenderError> {
        let tiles = self.tiles.len() as u64;
        let total = (tiles * target as u64).saturating_sub(tiles * self.samples as u64 + self.tiles_done as u64);
        let mut done = 0;
        while self.samples < target {
            let t = self.tiles[self.tiles_done];
            let push = RenderPush {
                tile_origin: [t[0], t[1]],
                tile_size: [t[2], t[3]],
                sample_index: self.samples,
                write_aov: (self.samples == 0) as u32,
                wave: 0,
            };
            let (before, sample) = self.sample_dependency();
            let seconds = self.pipeline.run_tile(cmds, &self.timer, push, (&before, &sample))?;
            self.render_seconds += seconds;
            self.tiles_done += 1;
            if self.tiles_done == self.tiles.len() {
                self.tiles_done = 0;
                self.samples += 1;
            }
            done += 1;
            progress(done, total);
            if self.samples < target && stop() {
                return Ok(false);
            }
        }
        Ok(true)
    }

    /// Dispatches (tiles) per sample.
    pub fn tiles_per_sample(&self) -> u32 {
        self.tiles.len() as u32
    }

    /// Tiles of the next sample already added (non-zero only after
    /// [`Renderer::add_samples_until`] stopped early).
    pub fn partial_tiles(&self) -> u32 {
        self.tiles_done as u32
    }

    /// The pixels of `bounds` and the number of samples each has: `samples`,
    /// plus one in the tiles of the interrupted next sample that finished.
    fn sample_counts(&self) -> Vec<u32> {
        let b = self.bounds;
        let mut counts = vec![self.samples; b.pixels()];
        for t in &self.tiles[..self.tiles_done] {
            for y in t[1]..t[1] + t[3] {
                for x in t[0]..t[0] + t[2] {
                    counts[((y - b.y0) * b.width() + x - b.x0) as usize] += 1;
                }
            }
        }
        counts
    }

    /// The work so far, as a checkpoint stores it: the accumulation's sums
    /// and finite-sample counts, the largest samples and the AOVs, for the
    /// pixels of the renderer's bounds.
    pub fn accumulation(&mut self, cmds: &mut Commands) -> Result<Accumulation, RenderError> {
        let (width, _) = self.size;
        let pixels = (self.size.0 * self.size.1) as usize;
        let sums: Vec<[f32; 4]> = self.read_image(cmds, &self.accum)?;
        let max_sample: Vec<[f32; 2]> = self.read_image(cmds, &self.max_sample)?;
        let (aov_buffer, aov_readback) = (&self.aov, &self.aov_readback);
        let samples = [Access::ShaderWrite(self.pipeline.stage())];
        cmds.run(|rec| {
            // The last read-back's copy wrote the host copy (its host read
            // came after the fence); the samples wrote the AOVs.
            rec.barrier(&[Access::TransferWrite, samples[0]], &[Access::TransferRead, Access::TransferWrite]);
            aov_buffer.copy_to(rec, aov_readback);
            rec.barrier(&[Access::TransferRead], &samples);
        })?;
        let aov: Vec<GpuAov> = self.aov_readback.read();
        Ok(Accumulation {
            frame_size: self.size,
            bounds: self.bounds,
            samples: self.samples,
            partial_tiles: self.tiles_done as u32,
            render_seconds: self.render_seconds,
            sums: self.bounds.extract(&sums[..pixels], width),
            max_sample: self.bounds.extract(&max_sample[..pixels], width),
            aov: self.bounds.extract(&aov[..pixels], width),
        })
    }

    /// Continues from `acc` (of a renderer with the same frame, bounds and
    /// scene): its sums, largest samples and AOVs are uploaded and the next
    /// sample is the one it stopped at, so that the render goes on with the
    /// same random numbers and the same order of additions.
    pub fn restore(&mut self, cmds: &mut Commands, acc: &Accumulation) -> Result<(), RenderError> {
        let (width, height) = self.size;
        let pixels = (width * height) as usize;
        let n = self.bounds.pixels();
        if acc.frame_size != self.size
            || acc.bounds != self.bounds
            || acc.partial_tiles as usize >= self.tiles.len()
            || [acc.sums.len(), acc.max_sample.len(), acc.aov.len()] != [n; 3]
        {
            return Err(RenderError::Accumulation(format!(
                "{}x{} frame, bounds {}, {} tiles a sample; the accumulation has a {}x{} frame, bounds {}, {} \
                 tiles done",
                width,
                height,
                self.bounds,
                self.tiles.len(),
                acc.frame_size.0,
                acc.frame_size.1,
                acc.bounds,
                acc.partial_tiles
            )));
        }
        let mut sums = vec![[0f32; 4]; pixels];
        self.bounds.insert(&acc.sums, &mut sums, width);
        let mut largest = vec![[0f32; 2]; pixels];
        self.bounds.insert(&acc.max_sample, &mut largest, width);
        // Pixels outside the bounds are never rendered: zero.
        let mut aov = vec![GpuAov::default(); self.aov.size as usize / std::mem::size_of::<GpuAov>()];
        self.bounds.insert(&acc.aov, &mut aov[..pixels], width);
        let aov_upload = Buffer::with_data(&self.device, "aov upload", &aov, vk::BufferUsageFlags::TRANSFER_SRC)?;
        let mut staging = Buffer::new(
            &self.device,
            "accumulation upload",
            pixels as u64 * 24,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        )?;
        staging.write(0, bytemuck::cast_slice(&sums));
        staging.write(pixels * 16, bytemuck::cast_slice(&largest));
        let (accum, max_sample, aov_buffer) = (&self.accum, &self.max_sample, &self.aov);
        let samples = [Access::ShaderWrite(self.pipeline.stage())];
        let upload = [Access::TransferWrite];
        cmds.run(|rec| {
            rec.barrier(&samples, &upload);
            aov_upload.copy_to(rec, aov_buffer);
            rec.barrier(&upload, &samples);
            for (image, offset) in [(accum, 0), (max_sample, pixels as u64 * 16)] {
                image.transition(
                    rec,
                    (&samples, vk::ImageLayout::GENERAL),
                    (&upload, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
                );
                image.copy_from_buffer(rec.cmd, &staging, &[image.rows_region(0, 0, height, offset)]);
                image.transition(
                    rec,
                    (&upload, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
                    (&samples, vk::ImageLayout::GENERAL),
                );
            }
        })?;
        self.samples = acc.samples;
        self.tiles_done = acc.partial_tiles as usize;
        self.render_seconds = acc.render_seconds;
        Ok(())
    }

    /// Fills the caustic report of `out` with the statistics the caustic
    /// passes keep on the GPU (rays landed, the irradiance deposited).
    pub fn read_caustic_statistics(&mut self, out: &mut RenderOutput) {
        if let (Some(report), Some(map)) = (&mut out.caustics, &mut self.caustics) {
            map.read_statistics();
            report.landed = map.report.landed;
            report.irradiance = std::mem::take(&mut map.report.irradiance);
        }
    }

    /// Copies `image` (one of the renderer's, in GENERAL layout) into the
    /// readback buffer and reads it as texels of type `T`; the vector may be
    /// longer than the image (the buffer fits the largest of them).
    fn read_image<T: bytemuck::Pod>(&self, cmds: &mut Commands, image: &Image) -> Result<Vec<T>, RenderError> {
        let readback = &self.readback;
        let samples = [Access::ShaderWrite(self.pipeline.stage())];
        let copy = [Access::TransferRead];
        cmds.run(|rec| {
            // The last read-back's copy wrote the buffer (its host read
            // came after the fence).
            rec.barrier(&[Access::TransferWrite], &[Access::TransferWrite]);
            image.transition(rec, (&samples, vk::ImageLayout::GENERAL), (&copy, vk::ImageLayout::TRANSFER_SRC_OPTIMAL));
            image.copy_to_buffer(rec.cmd, vk::ImageLayout::TRANSFER_SRC_OPTIMAL, readback);
            image.transition(rec, (&copy, vk::ImageLayout::TRANSFER_SRC_OPTIMAL), (&samples, vk::ImageLayout::GENERAL));
        })?;
        Ok(readback.read())
    }

    /// Reads back the mean of the samples so far, the AOVs and the times,
    /// for the pixels of the renderer's bounds.
    pub fn output(&mut self, cmds: &mut Commands) -> Result<RenderOutput, RenderError> {
        let acc = self.accumulation(cmds)?;
        Ok(RenderOutput {
            caustics: self.caustics.as_ref().map(|c| CausticReport { irradiance: Vec::new(), ..c.report.clone() }),
            volume_seconds: self.volume_seconds(),
            seconds: self.seconds(),
            backend: Some(self.pipeline.backend()),
            wave_profile: self.wave_profile(),
            ..acc.into_output(&self.sample_counts())
        })
    }

    /// Traces sample `sample` of pixel `(x, y)` alone (the same random
    /// numbers as in a render) and returns the events of its path, in order.
    /// Needs a renderer built with [`RenderVariant::record_path`]; the
    /// sample is also added to the accumulation (without counting it: use
    /// such a renderer only to record).
    pub fn trace_path(
        &mut self,
        cmds: &mut Commands,
        (x, y): (u32, u32),
        sample: u32,
    ) -> Result<RecordedPath, RenderError> {
        assert!(x < self.size.0 && y < self.size.1, "pixel ({x}, {y}) outside the image");
        self.path.write(0, &[0u8; 4]);
        let push = RenderPush { tile_origin: [x, y], tile_size: [1, 1], sample_index: sample, write_aov: 0, wave: 0 };
        let (before, sample) = self.sample_dependency();
        self.pipeline.run_tile(cmds, &self.timer, push, (&before, &sample))?;
        let bytes: Vec<u8> = self.path.read();
        let total = u32::from_le_bytes([bytes[0], bytes[1], bytes[2], bytes[3]]);
        let kept = total.min(PATH_RECORD_VERTICES) as usize;
        let (first, size) = (std::mem::offset_of!(GpuPathRecord, vertices), std::mem::size_of::<GpuPathVertex>());
        let events =
            (0..kept).map(|i| bytemuck::pod_read_unaligned(&bytes[first + i * size..first + (i + 1) * size])).collect();
        Ok(RecordedPath { events, left_out: total - kept as u32 })
    }
}

/// The render pass's kernels specialised for `variant` and the passes that
/// run.
fn render_pipeline(
    device: &Arc<Device>,
    gpu: &GpuScene,
    scene: &Scene,
    (variant, backend): (RenderVariant, Backend),
    caustics: Option<&CausticMap>,
    volume: bool,
) -> Result<PathPass, RenderError> {
    let constants = RenderConfig::new(gpu, scene, variant, caustics, volume).constants();
    Ok(match variant.kernel.unwrap_or(PathKernel::auto(backend)) {
        PathKernel::Megakernel => PathPass::Megakernel(Box::new(Tracer::new(
            device,
            backend,
            shaders::render,
            shaders::render_rgen,
            &constants,
        )?)),
        PathKernel::Wavefront if backend == Backend::RayQuery => {
            PathPass::Wavefront(Box::new(Wavefront::new(device, &constants, scene.image.max_depth)?))
        }
        PathKernel::Wavefront => return Err(RenderError::WavefrontNeedsRayQueries),
    })
}

/// Runs the caustic passes when `variant` asks for them and the scene needs
/// them: a light that emits caustic rays, a specular object, a diffuse
/// receiver, and a path depth that allows a specular vertex between a
/// receiver and a light (max_depth ≥ 2).
fn caustic_map(
    device: &Arc<Device>,
    gpu: &GpuScene,
    scene: &Scene,
    frame: &Buffer,
    size: (u32, u32),
    variant: RenderVariant,
    backend: Backend,
) -> Result<Option<CausticMap>, RenderError> {
    let max_depth = scene.image.max_depth.max(1);
    if !variant.caustics || variant.shading != ShadingMode::Full || !scene.needs_caustics() || max_depth < 2 {
        return Ok(None);
    }
    // A caustic path from the camera: the receiver (a bounce), the specular
    // vertices (a bounce each, the last vertex included), then the light
    // found by the segment after them (render.glsl, "the last vertex").
    let Some(mut grids) = emitters(scene, gpu.origin, max_depth - 1, scene.caustics.rays) else {
        log::warn!("a light is inside the bounds of the specular objects: caustics are left to the path tracer");
        return Ok(None);
    };
    // The ray buffer is one storage buffer: fewer rays per grid when all of
    // them would not fit in the device's largest binding.
    let ray_bytes = std::mem::size_of::<GpuCausticRay>() as u64;
    let fits = device.properties.limits.max_storage_buffer_range as u64 / ray_bytes;
    let total = |g: &[GpuEmitter]| g.iter().map(|e| e.grid[0] as u64 * e.grid[1] as u64).sum::<u64>();
    if total(&grids) > fits {
        let asked = total(&grids);
        let scale = fits as f64 / asked as f64;
        let fewer = ((scene.caustics.rays as f64 * scale * 0.95) as u32).max(1);
        grids = emitters(scene, gpu.origin, max_depth - 1, fewer).unwrap_or_default();
        log::warn!(
            "{asked} caustic rays do not fit in one storage buffer of this device ({fits} rays); tracing {} \
             ({} per light and light sample)",
            total(&grids),
            fewer
        );
    }
    Ok(Some(CausticMap::new(device, gpu, scene, frame, size, &grids, backend)?))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn pixel_filter_reach_is_the_largest_box_muller_radius() {
        // The smallest 1 - u of a 24-bit uniform number is 2⁻²⁴.
        let reach = PIXEL_FILTER_SIGMA as f64 * (-2.0 * (2.0f64).powi(-24).ln()).sqrt();
        assert!((PIXEL_FILTER_REACH as f64 - reach).abs() < 1e-5, "{reach}");
    }
}
