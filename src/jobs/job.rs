//! A long render as a job: rendered to its sample count, or stopped by a
//! signal or a time budget with its work kept, checkpointed on the way and
//! resumable (`quadray render --checkpoint/--resume/--time-limit`).
//!
//! Stopping happens between two dispatches (one tile of one sample): the
//! dispatch in flight finishes, then the accumulation is read back. A
//! resumed render restores it and goes on from the same tile and sample,
//! so its image is bit-identical to an uninterrupted render's.

use std::path::PathBuf;
use std::sync::atomic::{AtomicBool, Ordering};
use std::sync::Arc;
use std::time::{Duration, Instant};

use crate::model::scene::{DenoiseQuality, Scene};
use crate::passes::checkpoint::{render_key, Checkpoint, CheckpointError};
use crate::passes::{GpuScene, PixelBounds, RenderOutput, RenderVariant, Renderer};
use crate::{vk, RenderError};

/// How a job renders and when it stops.
#[derive(Clone, Debug)]
pub struct JobOptions {
    /// The pixels to render (a crop or tile, or the whole frame).
    pub bounds: PixelBounds,
    /// Where to write checkpoints (none: no checkpoints).
    pub checkpoint: Option<PathBuf>,
    /// Time between checkpoints.
    pub checkpoint_every: Duration,
    /// A checkpoint to continue from.
    pub resume: Option<PathBuf>,
    /// Stop after this much wall time (from the job's start).
    pub time_limit: Option<Duration>,
    /// Set (by a signal handler) to stop at the next dispatch boundary.
    pub stop: Arc<AtomicBool>,
    /// A name for the scene in checkpoint descriptions (its file).
    pub scene_name: String,
}

/// How a job ended.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum JobEnd {
    /// Every sample rendered.
    Complete,
    /// Stopped by [`JobOptions::stop`] (a signal).
    Interrupted,
    /// Stopped by [`JobOptions::time_limit`].
    TimeLimit,
}

/// Why a job failed.
#[derive(Debug, thiserror::Error)]
pub enum JobError {
    /// The render failed.
    #[error(transparent)]
    Render(#[from] RenderError),
    /// A checkpoint could not be read, used or written.
    #[error(transparent)]
    Checkpoint(#[from] CheckpointError),
}

/// What a finished or stopped job has.
pub struct JobResult {
    /// The image so far (the whole render when `end` is `Complete`).
    pub output: RenderOutput,
    /// How the job ended.
    pub end: JobEnd,
    /// The samples per pixel the job resumed from (0 when it started afresh).
    pub resumed_from: u32,
}

/// A description of a render for checkpoint messages.
fn describe(scene: &Scene, name: &str, bounds: PixelBounds) -> String {
    let im = &scene.image;
    format!(
        "{name}, {}x{} pixels{}, {} spp, seed {}",
        im.width,
        im.height,
        if bounds.is_full(im.width, im.height) { String::new() } else { format!(" (bounds {bounds})") },
        im.spp,
        im.seed
    )
}

/// The checkpoint key of `scene` rendered with `variant` over `bounds`.
pub fn job_key(scene: &Scene, variant: RenderVariant, bounds: PixelBounds) -> u64 {
    render_key(&*keyed(scene), &(keyed_variant(variant), bounds))
}

/// The key the images of `scene` rendered with `variant` carry (any pixel
/// bounds): tiles merge only with tiles of the same key.
pub fn image_key(scene: &Scene, variant: RenderVariant) -> u64 {
    render_key(&*keyed(scene), &keyed_variant(variant))
}

/// `variant` without the switches that leave the image as it is: the path
/// kernel (the megakernel and the wavefront pass run the same code on the
/// same random numbers; measured identical to the bit on lavapipe,
/// tests/render/kernels.rs), so that a render checkpointed with one
/// resumes with the other and their tiles merge.
fn keyed_variant(variant: RenderVariant) -> RenderVariant {
    RenderVariant { kernel: None, ..variant }
}

/// `scene` with the settings that do not change the render (denoising,
/// applied to the finished image) at their defaults, for the keys.
fn keyed(scene: &Scene) -> std::borrow::Cow<'_, Scene> {
    let plain = (false, DenoiseQuality::default());
    if (scene.image.denoise, scene.image.denoise_quality) == plain {
        return std::borrow::Cow::Borrowed(scene);
    }
    let mut s = scene.clone();
    (s.image.denoise, s.image.denoise_quality) = plain;
    std::borrow::Cow::Owned(s)
}

/// The GPU state of a job: the scene uploaded and the passes built once,
/// then reused for every frame a process renders (lavapipe compiles each
/// shader at its first dispatch, which would otherwise be paid per frame).
pub struct Job {
    // The renderer first: dropped before the scene its descriptors name.
    renderer: Renderer,
    gpu: GpuScene,
    cmds: vk::Commands,
    variant: RenderVariant,
    bounds: PixelBounds,
    // Whether the renderer is at the camera of the scene it was built with.
    fresh: bool,
}

impl Job {
    /// Uploads `scene` (its objects, materials and lights: every frame
    /// renders these) and builds the passes for `bounds` of its frame.
    pub fn new(
        ctx: &vk::Context,
        scene: &Scene,
        variant: RenderVariant,
        bounds: PixelBounds,
    ) -> Result<Self, JobError> {
        let mut cmds = vk::Commands::new(&ctx.device).map_err(RenderError::from)?;
        let gpu = GpuScene::for_render(&ctx.device, &mut cmds, scene)?;
        let renderer = Renderer::with_bounds(&ctx.device, &mut cmds, &gpu, scene, bounds, variant)?;
        Ok(Self { renderer, gpu, cmds, variant, bounds, fresh: true })
    }

    /// Renders `scene` (the job's scene, or another frame of it: the same
    /// objects, another camera): continues from `resume` (the checkpoint
    /// [`read_resume`] read for this scene), writes checkpoints every
    /// `options.checkpoint_every`, and stops (writing a last checkpoint) when
    /// `options.stop` is set or the time limit passes. `progress` gets
    /// (done, total) in tile-samples of the whole render.
    pub fn render(
        &mut self,
        scene: &Scene,
        options: &JobOptions,
        resume: Option<Checkpoint>,
        progress: &mut dyn FnMut(u64, u64),
    ) -> Result<JobResult, JobError> {
        let start = Instant::now();
        let im = &scene.image;
        let key = job_key(scene, self.variant, self.bounds);
        let description = describe(scene, &options.scene_name, self.bounds);
        let (renderer, cmds) = (&mut self.renderer, &mut self.cmds);
        if !self.fresh {
            renderer.set_camera(cmds, &self.gpu, scene)?;
        }
        self.fresh = false;
        let resumed_from = match &resume {
            Some(c) => {
                renderer.restore(cmds, &c.accumulation)?;
                c.accumulation.samples
            }
            None => 0,
        };
        let checkpoint = |renderer: &mut Renderer, cmds: &mut vk::Commands| -> Result<(), JobError> {
            if let Some(path) = &options.checkpoint {
                let accumulation = renderer.accumulation(cmds)?;
                Checkpoint { key, target_spp: im.spp, description: description.clone(), accumulation }.write(path)?;
            }
            Ok(())
        };
        let tiles_per_sample = renderer.tiles_per_sample() as u64;
        let total = tiles_per_sample * im.spp as u64;
        let mut last_checkpoint = Instant::now();
        let end = loop {
            let base = tiles_per_sample * renderer.samples() as u64 + renderer.partial_tiles() as u64;
            let mut why = None;
            let done = renderer.add_samples_until(cmds, im.spp, &mut |d, _| progress(base + d, total), &mut || {
                if options.stop.load(Ordering::SeqCst) {
                    why = Some(JobEnd::Interrupted);
                } else if options.time_limit.is_some_and(|limit| start.elapsed() >= limit) {
                    why = Some(JobEnd::TimeLimit);
                }
                why.is_some() || (options.checkpoint.is_some() && last_checkpoint.elapsed() >= options.checkpoint_every)
            })?;
            if done {
                break JobEnd::Complete;
            }
            checkpoint(renderer, cmds)?;
            last_checkpoint = Instant::now();
            if let Some(end) = why {
                break end;
            }
        };
        let mut output = renderer.output(cmds)?;
        renderer.read_caustic_statistics(&mut output);
        Ok(JobResult { output, end, resumed_from })
    }
}

/// Reads the checkpoint `options.resume` names, if any, and checks that it
/// is one of `scene` rendered with `variant` over `options.bounds`. Called
/// before the job's GPU work, so that a wrong checkpoint is refused at once.
pub fn read_resume(
    scene: &Scene,
    variant: RenderVariant,
    options: &JobOptions,
) -> Result<Option<Checkpoint>, JobError> {
    let Some(path) = &options.resume else { return Ok(None) };
    let key = job_key(scene, variant, options.bounds);
    Ok(Some(Checkpoint::read_for(path, key, &describe(scene, &options.scene_name, options.bounds))?))
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The key of the built-in default scene, pinned: it comes from a
    /// stable serialisation (`render_key`), so only a change to the scene
    /// model, the variant, `KEY_VERSION` or `scenes/default.toml` itself
    /// moves it. When this fails, old checkpoints no longer resume: bump
    /// `KEY_VERSION` if the image an unchanged scene file makes has changed
    /// (not for an edit of default.toml), and update the value.
    #[test]
    fn the_default_scenes_key_is_stable() {
        let scene = crate::model::scene::parse_scene(crate::model::scene::DEFAULT_SCENE, "default").unwrap();
        let (w, h) = (scene.image.width, scene.image.height);
        let key = job_key(&scene, RenderVariant::default(), PixelBounds::full(w, h));
        println!("default scene key: {key:016x}");
        assert_eq!(key, PINNED_DEFAULT_KEY, "{key:016x}");
        // The path kernel makes the same image: not in the key.
        let wavefront = RenderVariant { kernel: Some(crate::passes::PathKernel::Wavefront), ..Default::default() };
        assert_eq!(job_key(&scene, wavefront, PixelBounds::full(w, h)), key);
    }

    const PINNED_DEFAULT_KEY: u64 = 0x9edc_c645_0a5f_e305;

    #[test]
    fn denoising_does_not_change_the_keys() {
        let scene = crate::model::scene::parse_scene(crate::model::scene::DEFAULT_SCENE, "default").unwrap();
        let mut denoised = scene.clone();
        (denoised.image.denoise, denoised.image.denoise_quality) = (true, crate::jobs::denoise::DenoiseQuality::Fast);
        let (v, b) = (RenderVariant::default(), PixelBounds::full(4, 4));
        assert_eq!(job_key(&scene, v, b), job_key(&denoised, v, b));
        assert_eq!(image_key(&scene, v), image_key(&denoised, v));
        let mut more = scene.clone();
        more.image.spp += 1;
        assert_ne!(job_key(&scene, v, b), job_key(&more, v, b));
    }
}
