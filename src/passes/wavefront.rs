//! The wavefront render pass: the path tracer split into stage kernels over
//! queues in device memory (glsl/render/wavefront.glsl), beside the megakernel
//! (glsl/render/render.comp), which runs a whole path in one invocation.
//!
//! Laine, Karras and Aila, "Megakernels Considered Harmful: Wavefront Path
//! Tracing on GPUs" (HPG 2013); pbrt-v4's wavefront integrator
//! (`src/pbrt/wavefront/`). One wave is one sample of every pixel of a tile
//! (a path per slot): the start kernel makes the camera rays and queues
//! every path; then, until the queue is empty, the trace kernel traces each
//! queued path's next ray (its segment or a waiting shadow ray) and the
//! shade kernel hands the hit to the path (the megakernel's own code), which
//! queues its next ray or adds its sample. The queues' lengths drive
//! indirect dispatches, so that every SIMD batch holds live paths.
//!
//! The waves run in submissions of [`ITERATIONS_PER_SUBMISSION`]
//! iterations; after each the host reads the queue's length and stops at
//! zero. Ray queries only: the pipeline backend keeps the megakernel.

use std::cell::Cell;
use std::sync::Arc;

use crate::gpu::shader_interface::{
    BINDING_WAVE_HITS, BINDING_WAVE_PATHS, BINDING_WAVE_QUEUE, BINDING_WAVE_RAYS, RENDER_GROUP, RENDER_TILE,
};
use crate::gpu::shaders;
use crate::passes::gpu::RenderPush;
use crate::vk::reflect::ShaderInterface;
use crate::vk::{
    vk, Access, Binding, Buffer, Commands, ComputePipeline, Device, GpuTimer, MemoryLocation, ShaderStage,
};
use crate::vk::{Recording, Timestamps, VkError};

/// Slots in a wave: one per pixel of the largest tile (`WAVE_SLOTS`).
const SLOTS: u64 = RENDER_TILE as u64 * RENDER_TILE as u64;
/// Invocations per workgroup of the trace and shade kernels (`WAVE_GROUP`).
const GROUP: u32 = 64;
/// Trace-and-shade iterations recorded per submission, between two reads of
/// the queue's length.
pub const ITERATIONS_PER_SUBMISSION: u32 = 6;
/// The queue header: indirect arguments of both queues (3 words each), then
/// their lengths (`WaveQueue` in wavefront.glsl).
const HEADER_WORDS: u64 = 8;
const COUNTS_OFFSET: u64 = 24;

/// The wavefront pass: its four kernels and the wave's buffers.
pub struct Wavefront {
    start: ComputePipeline,
    trace: ComputePipeline,
    shade: ComputePipeline,
    centre: ComputePipeline,
    paths: Buffer,
    rays: Buffer,
    hits: Buffer,
    queue: Buffer,
    /// The queues' lengths, read by the host after each submission.
    counts: Buffer,
    /// Iterations after which every path has ended (its segments and
    /// shadow rays bounded: render.glsl, pathGoesOn).
    max_iterations: u32,
    /// Timestamps around each stage of a submission (none on a queue
    /// without them), and the times they add up to.
    stamps: Option<Timestamps>,
    profile: Cell<WaveProfile>,
}

/// Where a wavefront render's GPU time went, stage by stage (seconds), and
/// its iterations and waves.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct WaveProfile {
    /// Camera rays and the pixel-centre AOVs (start and centre kernels).
    pub start: f64,
    /// The trace kernel: every path's next ray, closest or any hit.
    pub trace: f64,
    /// The shade kernel: the paths' events, and their samples added.
    pub shade: f64,
    /// Between the stages: emptying queues, the barriers, submissions (the
    /// copy of the queues' lengths falls in the last shade's interval).
    pub other: f64,
    /// Trace-and-shade iterations run.
    pub iterations: u64,
    /// Waves run (tile samples).
    pub waves: u64,
}

/// Timestamps per submission: three per iteration and one at its end.
const STAMPS: u32 = 3 * ITERATIONS_PER_SUBMISSION + 1;

/// The size of struct `name` as the shader lays it out in a buffer.
fn struct_size(interface: &ShaderInterface, name: &str) -> Result<u64, VkError> {
    interface
        .structs
        .get(name)
        .map(|s| s.size() as u64)
        .ok_or_else(|| VkError::Interface(crate::vk::reflect::InterfaceError::Reflect(format!("no struct {name}"))))
}

impl Wavefront {
    /// The pass's kernels specialised with `specialization` (each takes the
    /// constants it declares) for paths of at most `max_depth` bounces.
    pub fn new(device: &Arc<Device>, specialization: &[(u32, u32)], max_depth: u32) -> Result<Self, VkError> {
        let kernel = |spirv: Vec<u32>| -> Result<(ComputePipeline, ShaderInterface), VkError> {
            let interface = ShaderInterface::reflect(&spirv)?;
            let constants: Vec<(u32, u32)> =
                specialization.iter().copied().filter(|(id, _)| interface.spec_constants.contains_key(id)).collect();
            Ok((ComputePipeline::new(device, &spirv, &constants)?, interface))
        };
        let (start, _) = kernel(shaders::wavefront_start())?;
        let (trace, _) = kernel(shaders::wavefront_trace())?;
        let (shade, interface) = kernel(shaders::wavefront_shade())?;
        let (centre, _) = kernel(shaders::wavefront_centre())?;
        let storage = |name: &str, bytes: u64| Buffer::storage(device, name, bytes, MemoryLocation::GpuOnly);
        let paths = storage("wave paths", SLOTS * struct_size(&interface, "WavePath")?)?;
        let rays = storage("wave rays", SLOTS * struct_size(&interface, "NextRay")?)?;
        let hits = storage("wave hits", SLOTS * struct_size(&interface, "SceneHit")?)?;
        let queue = Buffer::new(
            device,
            "wave queues",
            (HEADER_WORDS + 2 * SLOTS) * 4,
            vk::BufferUsageFlags::STORAGE_BUFFER
                | vk::BufferUsageFlags::INDIRECT_BUFFER
                | vk::BufferUsageFlags::TRANSFER_DST
                | vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::GpuOnly,
        )?;
        let counts = Buffer::new(
            device,
            "wave queue lengths",
            COUNTS_OFFSET + 8,
            vk::BufferUsageFlags::TRANSFER_DST,
            MemoryLocation::GpuToCpu,
        )?;
        // A path traces at most 4 maxDepth + 8 segments (pathGoesOn), each
        // followed by at most two shadow rays; the shade stage that answers
        // its last ray adds its sample.
        let max_iterations = 3 * (4 * max_depth.max(1) + 8);
        let stamps = if GpuTimer::available(device) { Some(Timestamps::new(device, STAMPS)?) } else { None };
        Ok(Self {
            start,
            trace,
            shade,
            centre,
            paths,
            rays,
            hits,
            queue,
            counts,
            max_iterations,
            stamps,
            profile: Cell::new(WaveProfile::default()),
        })
    }

    /// Where the GPU time of the waves so far went.
    pub fn profile(&self) -> WaveProfile {
        self.profile.get()
    }

    /// Points every kernel's bindings at `resources` (the render pass's)
    /// and the wave's own buffers.
    pub fn bind(&self, resources: &[(u32, Binding<'_>)]) -> Result<(), VkError> {
        let mut all = resources.to_vec();
        all.extend([
            (BINDING_WAVE_PATHS, Binding::Buffer(&self.paths)),
            (BINDING_WAVE_RAYS, Binding::Buffer(&self.rays)),
            (BINDING_WAVE_HITS, Binding::Buffer(&self.hits)),
            (BINDING_WAVE_QUEUE, Binding::Buffer(&self.queue)),
        ]);
        for kernel in [&self.start, &self.trace, &self.shade, &self.centre] {
            kernel.bind(&all)?;
        }
        Ok(())
    }

    /// Renders one sample of the tile `push` names (its AOVs first when
    /// `push.write_aov`): `before` is what earlier work wrote that the
    /// sample reads. Returns the GPU time in seconds.
    pub fn render_tile(
        &self,
        cmds: &mut Commands,
        timer: &GpuTimer,
        push: RenderPush,
        before: &[Access],
    ) -> Result<f64, VkError> {
        let compute = Access::ShaderWrite(ShaderStage::Compute);
        let [w, h] = push.tile_size;
        let n = w * h;
        let bytes = |wave: u32| bytemuck::bytes_of(&RenderPush { wave, ..push }).to_vec();
        let ((), mut seconds) = timer.run(cmds, |rec| {
            let mut prev = before.to_vec();
            prev.push(Access::IndirectRead);
            rec.barrier(&prev, &[compute, Access::TransferWrite]);
            // Queue 0 holds every path; queue 1 is empty.
            self.queue.update(rec, 0, &[n.div_ceil(GROUP), 1, 1, 0, 1, 1, n, 0]);
            rec.barrier(&[Access::TransferWrite], &[compute]);
            let groups = [w.div_ceil(RENDER_GROUP), h.div_ceil(RENDER_GROUP), 1];
            if push.write_aov != 0 {
                self.centre.dispatch(rec.cmd, &bytes(0), groups);
            }
            self.start.dispatch(rec.cmd, &bytes(0), groups);
        })?;
        let mut profile = self.profile.get();
        profile.start += seconds;
        profile.waves += 1;
        let mut iteration = 0;
        while iteration < self.max_iterations {
            let chunk = ITERATIONS_PER_SUBMISSION.min(self.max_iterations - iteration);
            let ((), s) = timer.run(cmds, |rec| {
                if let Some(stamps) = &self.stamps {
                    stamps.reset(rec.cmd);
                }
                for (k, i) in (iteration..iteration + chunk).enumerate() {
                    self.record_iteration(rec, &bytes(i % 2), i % 2, 3 * k as u32);
                }
                rec.barrier(&[compute], &[Access::TransferRead]);
                self.queue.copy_range_to(rec, &self.counts, COUNTS_OFFSET, 8);
                rec.barrier(&[Access::TransferWrite], &[Access::HostRead]);
                if let Some(stamps) = &self.stamps {
                    // The end, and every query a short chunk leaves unused
                    // (all are read below).
                    for index in 3 * chunk..STAMPS {
                        stamps.write(rec.cmd, index);
                    }
                }
            })?;
            seconds += s;
            let mut staged = 0.0;
            if let Some(stamps) = &self.stamps {
                let ns = stamps.read_ns()?;
                for k in 0..chunk as usize {
                    let [a, b, c, d] = [ns[3 * k], ns[3 * k + 1], ns[3 * k + 2], ns[3 * k + 3]];
                    profile.trace += (b - a) * 1e-9;
                    profile.shade += (d - c) * 1e-9;
                    staged += (b - a + d - c) * 1e-9;
                }
            }
            profile.other += (s - staged).max(0.0);
            profile.iterations += chunk as u64;
            iteration += chunk;
            let counts: Vec<u32> = self.counts.read();
            let live = counts[(COUNTS_OFFSET / 4) as usize + (iteration % 2) as usize];
            if live == 0 {
                break;
            }
            if iteration >= self.max_iterations {
                // Cannot happen (the bound holds every path); were it to, the
                // pixels' finite-sample counts would fall short and the
                // render would report the samples as dropped.
                log::warn!("wavefront pass: {live} paths still live after {iteration} iterations");
            }
        }
        self.profile.set(profile);
        Ok(seconds)
    }

    /// Records one iteration reading queue `wave`: trace its paths' rays,
    /// empty the other queue, shade (which fills it).
    /// Timestamps `stamp`, `stamp + 1` and `stamp + 2` (with the next
    /// iteration's first) time the trace and shade kernels.
    fn record_iteration(&self, rec: Recording<'_>, push: &[u8], wave: u32, stamp: u32) {
        let compute = Access::ShaderWrite(ShaderStage::Compute);
        let next = 1 - wave;
        let time = |index: u32| {
            if let Some(stamps) = &self.stamps {
                stamps.write(rec.cmd, index);
            }
        };
        // The last shade filled this queue and its arguments.
        rec.barrier(&[compute, Access::TransferWrite], &[compute, Access::IndirectRead]);
        time(stamp);
        self.trace.dispatch_indirect(rec.cmd, push, &self.queue, wave as u64 * 12);
        rec.barrier(&[compute], &[compute]);
        time(stamp + 1);
        // The other queue was read by the last iteration; empty it.
        rec.barrier(&[compute, Access::IndirectRead], &[Access::TransferWrite]);
        self.queue.update(rec, next as u64 * 12, &[0, 1, 1]);
        self.queue.update(rec, COUNTS_OFFSET + next as u64 * 4, &[0]);
        rec.barrier(&[compute, Access::TransferWrite], &[compute, Access::IndirectRead]);
        time(stamp + 2);
        self.shade.dispatch_indirect(rec.cmd, push, &self.queue, wave as u64 * 12);
    }
}
