//! `quadray render`: a scene to PNG and EXR, with checkpoints, crops, tiles
//! and frames, and its `--bench` mode.

use std::path::PathBuf;

use super::common::*;
use anyhow::{bail, Context as _, Result};
use clap::Parser;
use quadray::jobs::output::write_outputs_with;
use quadray::model::scene::{Scene, DEFAULT_SCENE_NAME};
use quadray::passes::{IntersectMode, SamplerMode, ShadingMode};
use quadray::util::progress::ProgressBar;

#[derive(Parser, Debug, Default)]
pub(crate) struct RenderArgs {
    /// Scene file (TOML, see scenes/README.md). Omit it to render the built-in default scene.
    pub(crate) scene: Option<PathBuf>,
    /// Output path. `NAME.png` writes only a PNG, `NAME.exr` only an EXR, a
    /// name without one of those extensions writes both `NAME.png` and `NAME.exr`.
    #[arg(short, long, default_value = "render")]
    pub(crate) output: PathBuf,
    #[command(flatten)]
    pub(crate) frame: FrameArgs,
    /// Write the EXR with 16-bit half floats instead of 32-bit floats.
    #[arg(long)]
    pub(crate) half: bool,
    /// Enable the Khronos validation layer; the command fails if it reports errors.
    /// QUADRAY_VALIDATION=1 (or true/yes/on) in the environment does the same.
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    pub(crate) validation: bool,
    /// Print progress even when stderr is not a terminal.
    #[arg(long)]
    pub(crate) progress: bool,
    /// Benchmark mode: after an untimed warm-up (lavapipe compiles shaders at
    /// their first dispatch), time the render and variants of it with parts of
    /// the work switched off (perturbation root finding, shading and
    /// secondary rays, intersection), print samples per second for each, and
    /// write the full render's outputs.
    #[arg(long)]
    pub(crate) bench: bool,
    #[command(flatten)]
    pub(crate) quality: QualityArgs,
    /// Brute force: no caustic or volume passes; the path tracer alone
    /// estimates caustics and the light scattered by the fog (the reference
    /// those passes are compared with).
    #[arg(long)]
    pub(crate) brute_force: bool,
    /// How every tracing pass traces rays: `auto` (ray queries where the
    /// device has them), `ray-query`, or `pipeline` (a ray-tracing pipeline
    /// whose intersection shader solves the first roots; the render, caustic
    /// and volume passes alike). The images agree to float rounding.
    #[arg(long, value_enum, default_value_t = BackendChoice::Auto, env = "QUADRAY_BACKEND")]
    pub(crate) backend: BackendChoice,
    /// How the render pass runs its paths: `auto`, `megakernel` (one
    /// invocation a whole path) or `wavefront` (stage kernels over queues of
    /// paths: camera rays, tracing, shading; ray queries only). The images
    /// agree to float rounding.
    #[arg(long, value_enum, default_value_t = KernelChoice::Auto, env = "QUADRAY_KERNEL")]
    pub(crate) kernel: KernelChoice,
    /// The path tracer's samples: `sobol` (Owen-scrambled Sobol points, one
    /// dimension pair per decision along the path; lower error at equal
    /// spp) or `independent` (independent random numbers, whose per-pixel
    /// errors are plain Monte Carlo noise). Both are unbiased; the camera
    /// jitter is the same stratified sequence in both.
    #[arg(long, default_value_t = SamplerMode::Sobol)]
    pub(crate) sampler: SamplerMode,
    /// Write checkpoints of the work so far to this file (atomically), every
    /// --checkpoint-every seconds and when the render is stopped by SIGINT,
    /// SIGTERM or --time-limit; removed once the render completes and its
    /// images are written. Default with --resume: the file resumed from.
    #[arg(long)]
    pub(crate) checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    #[arg(long, default_value_t = 300.0, value_parser = positive_seconds)]
    pub(crate) checkpoint_every: f64,
    /// Continue the render saved in this checkpoint (refused unless the
    /// scene file and every flag that changes the image are the same).
    #[arg(long)]
    pub(crate) resume: Option<PathBuf>,
    /// Render until this many seconds have passed, then write the image so
    /// far (and the checkpoint, with --checkpoint) and exit with status 0;
    /// the images' `quadray.spp` metadata says how many samples they have.
    #[arg(long, value_parser = positive_seconds)]
    pub(crate) time_limit: Option<f64>,
    /// Render only these pixel bounds of the frame: x0,x1,y0,y1 (columns
    /// x0..x1, rows y0..y1, half-open, row 0 at the top; pbrt-v4's
    /// --pixelbounds). The EXR's data window is the crop, its display
    /// window the frame.
    #[arg(long, conflicts_with = "tile")]
    pub(crate) crop: Option<quadray::passes::PixelBounds>,
    /// Render tile i of N: the frame split into N bands of whole rows, band
    /// i covering rows floor(i·H/N) to floor((i+1)·H/N). `quadray merge`
    /// assembles the tiles.
    #[arg(long)]
    pub(crate) tile: Option<quadray::passes::TileIndex>,
    /// Render frame F of the scene's camera animation (`[[camera.keyframes]]`,
    /// frame F at time F / camera.fps); outputs are numbered: NAME.0002.png.
    #[arg(long = "frame", conflicts_with = "frames")]
    pub(crate) animation_frame: Option<u32>,
    /// Render frames A to B (inclusive), every STEP-th (default 1), in one
    /// process that builds its shaders once: A-B or A-B:STEP. Outputs are
    /// numbered: NAME.0001.exr, NAME.0002.exr, ...
    #[arg(long)]
    pub(crate) frames: Option<FrameRange>,
}

pub(crate) fn load(args: &RenderArgs) -> Result<Scene> {
    let mut scene = read_scene(args.scene.as_deref())?;
    args.quality.apply(&mut scene);
    if let Some(w) = args.frame.width {
        scene.image.width = w;
    }
    if let Some(h) = args.frame.height {
        scene.image.height = h;
    }
    if let Some(s) = args.frame.seed {
        scene.image.seed = s;
    }
    Ok(scene)
}

/// Which frames `--frame` and `--frames` ask for (none: the still camera,
/// outputs without a frame number).
pub(crate) fn requested_frames(args: &RenderArgs) -> Option<Vec<u32>> {
    match (args.animation_frame, args.frames) {
        (Some(f), _) => Some(vec![f]),
        (None, Some(r)) => Some(r.frames()),
        (None, None) => None,
    }
}

pub(crate) fn render(args: RenderArgs) -> Result<()> {
    let scene = load(&args)?;
    // Before any GPU work: a render is never lost to an unwritable output.
    let outputs = checked_outputs(&args.output)?;
    let frames = requested_frames(&args);
    if frames.as_ref().is_some_and(|f| f.len() > 1) && (args.checkpoint.is_some() || args.resume.is_some()) {
        bail!("--checkpoint and --resume take one frame at a time (--frame F), not a --frames range");
    }
    let bounds = match (args.crop, args.tile) {
        (Some(crop), _) => crop.check(scene.image.width, scene.image.height)?,
        (None, Some(t)) => quadray::passes::PixelBounds::tile(t.index, t.count, scene.image.width, scene.image.height)?,
        (None, None) => quadray::passes::PixelBounds::full(scene.image.width, scene.image.height),
    };
    if args.bench
        && (args.checkpoint.is_some()
            || args.resume.is_some()
            || args.time_limit.is_some()
            || frames.is_some()
            || !bounds.is_full(scene.image.width, scene.image.height))
    {
        bail!(
            "--bench renders the whole frame at once: it takes no --checkpoint, --resume, --time-limit, --crop, \
             --tile, --frame or --frames"
        );
    }
    // A missing denoiser is an error before any work, with nothing written.
    let mut denoiser = if scene.image.denoise { Some(quadray::jobs::denoise::Denoiser::load()?) } else { None };
    let ctx = quadray::vk::Context::new(args.validation).context("cannot start Vulkan")?;
    let counters = ctx.counters();
    let backend = args.backend.resolve(&ctx.device)?;
    let variant = quadray::passes::RenderVariant {
        caustics: !args.brute_force,
        volume: !args.brute_force,
        sampler: args.sampler,
        backend: Some(backend),
        kernel: args.kernel.kernel(),
        ..Default::default()
    };
    let mut interrupted = false;
    if args.bench {
        let mut out = bench(&ctx, &scene, backend)?;
        let end = quadray::jobs::job::JobEnd::Complete;
        write_render(&args, &ctx, &scene, variant, &outputs, None, &mut out, end, denoiser.as_mut())?;
    } else {
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            // A second signal ends the process at once (exit status 1).
            signal_hook::flag::register_conditional_shutdown(signal, 1, stop.clone())?;
            signal_hook::flag::register(signal, stop.clone())?;
        }
        let options = quadray::jobs::job::JobOptions {
            bounds,
            checkpoint: args.checkpoint.clone().or_else(|| args.resume.clone()),
            checkpoint_every: std::time::Duration::from_secs_f64(args.checkpoint_every),
            resume: args.resume.clone(),
            time_limit: args.time_limit.map(std::time::Duration::from_secs_f64),
            stop,
            scene_name: args.scene.as_ref().map_or(DEFAULT_SCENE_NAME.to_string(), |p| p.display().to_string()),
        };
        // One job for every frame: the scene is uploaded and the shaders
        // built once.
        let list: Vec<Option<u32>> = frames.map_or(vec![None], |f| f.into_iter().map(Some).collect());
        let first = list[0].map_or_else(|| scene.clone(), |f| scene.at_frame(f));
        // A wrong checkpoint is refused before any GPU work.
        let mut resume = quadray::jobs::job::read_resume(&first, variant, &options)?;
        // The shaders compile from here to the first dispatch's end.
        let mut first_progress = Some(ProgressBar::new(args.progress).compiling());
        let mut job = quadray::jobs::job::Job::new(&ctx, &first, variant, bounds).context("render failed")?;
        for frame in list {
            let frame_scene = frame.map_or_else(|| scene.clone(), |f| scene.at_frame(f));
            let mut progress = first_progress.take().unwrap_or_else(|| ProgressBar::new(args.progress));
            let result = job.render(&frame_scene, &options, resume.take(), &mut |d, t| progress.update(d, t));
            progress.finish();
            let result = result.context("render failed")?;
            if result.resumed_from > 0 {
                eprintln!("resumed at {} of {} spp", result.resumed_from, frame_scene.image.spp);
            }
            let paths: Vec<PathBuf> = match frame {
                Some(f) => outputs.iter().map(|p| quadray::jobs::output::frame_path(p, f)).collect(),
                None => outputs.clone(),
            };
            let mut out = result.output;
            write_render(&args, &ctx, &frame_scene, variant, &paths, frame, &mut out, result.end, denoiser.as_mut())?;
            if result.end != quadray::jobs::job::JobEnd::Complete {
                interrupted = result.end == quadray::jobs::job::JobEnd::Interrupted;
                break;
            }
        }
    }
    drop(ctx);
    if counters.errors() > 0 {
        bail!("the validation layer reported {} error(s) at shutdown", counters.errors());
    }
    if interrupted {
        std::process::exit(EXIT_INTERRUPTED);
    }
    Ok(())
}

/// Writes one render's (or frame's) files with their metadata, denoised
/// first when the scene asks (`denoiser`), handles its checkpoint and
/// prints what was done.
#[allow(clippy::too_many_arguments)]
pub(crate) fn write_render(
    args: &RenderArgs,
    ctx: &quadray::vk::Context,
    scene: &Scene,
    variant: quadray::passes::RenderVariant,
    outputs: &[PathBuf],
    frame: Option<u32>,
    out: &mut quadray::passes::RenderOutput,
    end: quadray::jobs::job::JobEnd,
    denoiser: Option<&mut quadray::jobs::denoise::Denoiser>,
) -> Result<()> {
    if ctx.counters().errors() > 0 {
        bail!("the validation layer reported {} error(s); no output written", ctx.counters().errors());
    }
    let denoised = match denoiser {
        Some(d) => Some(denoise_into(d, out, scene.image.denoise_quality)?),
        None => None,
    };
    let files = output_files(outputs, scene.image.exposure, args.half);
    let key = quadray::jobs::job::image_key(scene, variant);
    let mut metadata: Vec<(String, String)> = [
        (quadray::jobs::output::METADATA_SPP, out.spp.to_string()),
        (quadray::jobs::output::METADATA_TARGET_SPP, scene.image.spp.to_string()),
        (quadray::jobs::output::METADATA_SEED, scene.image.seed.to_string()),
        (quadray::jobs::output::METADATA_EXPOSURE, scene.image.exposure.to_string()),
        (quadray::jobs::output::METADATA_SCENE_KEY, format!("{key:016x}")),
    ]
    .map(|(k, v)| (k.to_string(), v))
    .to_vec();
    if let Some(f) = frame {
        metadata.push((quadray::jobs::output::METADATA_FRAME.to_string(), f.to_string()));
    }
    if let Some(b) = out.backend {
        metadata.push((quadray::jobs::output::METADATA_BACKEND.to_string(), b.to_string()));
    }
    metadata.push((quadray::jobs::output::METADATA_DEVICE.to_string(), ctx.device.name.clone()));
    metadata.push((quadray::jobs::output::METADATA_DRIVER.to_string(), ctx.device.driver.clone()));
    if let Some((d, _)) = &denoised {
        metadata.push((quadray::jobs::output::METADATA_DENOISED.to_string(), d.clone()));
    }
    write_outputs_with(out, &files, &metadata)?;
    let checkpoint = args.checkpoint.as_ref().or(args.resume.as_ref());
    match (end, checkpoint) {
        (quadray::jobs::job::JobEnd::Complete, Some(path)) if path.exists() => {
            // The images are the render now; a checkpoint left behind would
            // only be resumed into the same images.
            std::fs::remove_file(path).with_context(|| format!("cannot remove {}", path.display()))?;
        }
        (quadray::jobs::job::JobEnd::Complete, _) => {}
        (stopped, path) => eprintln!(
            "{}: wrote the image so far ({} spp of {}{}){}",
            if stopped == quadray::jobs::job::JobEnd::Interrupted { "interrupted" } else { "time limit reached" },
            out.spp,
            scene.image.spp,
            if out.partial_tiles > 0 {
                format!(", {} tiles of the next sample", out.partial_tiles)
            } else {
                String::new()
            },
            path.map_or(String::from("; no checkpoint (--checkpoint PATH would keep the work)"), |p| format!(
                "; checkpoint {} (continue with --resume {})",
                p.display(),
                p.display()
            ))
        ),
    }
    if let Some(c) = &out.caustics {
        eprintln!(
            "caustics: {} rays in {} grid(s), {} landed on a receiver; {:.3} s (G-buffer {:.3}, rays {:.3}, cells {:.3}, beams {:.3})",
            c.rays,
            c.grids,
            c.landed,
            c.seconds(),
            c.gbuffer_seconds,
            c.trace_seconds,
            c.splat_seconds,
            c.beam_seconds
        );
    }
    if let Some(v) = out.volume_seconds {
        eprintln!("volume: {} camera rays per pixel; {v:.3} s", scene.volume.samples.saturating_mul(out.spp));
    }
    if out.dropped_samples > 0 {
        log::warn!(
            "{} of {} samples came out NaN or infinite and were counted as black (a renderer bug: please report it \
             with the scene)",
            out.dropped_samples,
            out.width as u64 * out.height as u64 * out.spp as u64
        );
    }
    if let Some((d, seconds)) = &denoised {
        eprintln!("denoised: {d}; {seconds:.2} s");
    }
    let names: Vec<String> = outputs.iter().map(|p| p.display().to_string()).collect();
    eprintln!(
        "wrote {} ({}x{}, {} spp, {:.2} s on {}, driver {})",
        names.join(", "),
        out.width,
        out.height,
        out.spp,
        out.seconds,
        ctx.device.name,
        ctx.device.driver
    );
    Ok(())
}

/// Denoises `out` in place (its `denoised` image) and returns what was done,
/// as the metadata and the message say it.
/// Returns the metadata's description (without the time, so that the same
/// render denoised twice, or resumed, writes the same bytes) and the
/// seconds it took.
pub(crate) fn denoise_into(
    denoiser: &mut quadray::jobs::denoise::Denoiser,
    out: &mut quadray::passes::RenderOutput,
    quality: quadray::jobs::denoise::DenoiseQuality,
) -> Result<(String, f64)> {
    let start = std::time::Instant::now();
    let features = quadray::jobs::denoise::has_features(out);
    out.denoised = Some(quadray::jobs::denoise::denoise_output(denoiser, out, quality)?);
    let v = denoiser.version;
    let what = format!(
        "Intel Open Image Denoise {}.{}.{}, {quality} quality, {}",
        v / 10000,
        v / 100 % 100,
        v % 100,
        if features { "with the albedo and normal images" } else { "colour only" },
    );
    Ok((what, start.elapsed().as_secs_f64()))
}

/// The benchmark mode of `render --bench`; returns the full render.
pub(crate) fn bench(
    ctx: &quadray::vk::Context,
    scene: &Scene,
    backend: quadray::vk::Backend,
) -> Result<quadray::passes::RenderOutput> {
    use quadray::passes::{GpuScene, RenderVariant};
    use quadray::vk::Backend;

    let device = &ctx.device;
    let mut cmds = quadray::vk::Commands::new(device)?;
    let gpu = GpuScene::for_render(device, &mut cmds, scene)?;
    let im = &scene.image;
    let variants = [
        (
            "full render",
            RenderVariant {
                intersect: IntersectMode::Full,
                shading: ShadingMode::Full,
                backend: Some(backend),
                ..Default::default()
            },
        ),
        (
            "perturbation root finding off",
            RenderVariant {
                intersect: IntersectMode::Base,
                shading: ShadingMode::Full,
                backend: Some(backend),
                ..Default::default()
            },
        ),
        (
            "shading and secondary rays off",
            RenderVariant {
                intersect: IntersectMode::Full,
                shading: ShadingMode::Albedo,
                backend: Some(backend),
                ..Default::default()
            },
        ),
        (
            "traversal only (boxes are hits, no shading)",
            RenderVariant {
                intersect: IntersectMode::Boxes,
                shading: ShadingMode::Albedo,
                backend: Some(backend),
                ..Default::default()
            },
        ),
    ];
    eprintln!(
        "benchmark: {}x{}, {} spp, max depth {}, {} objects ({} perturbations, {} cells) on {}, {} backend",
        im.width,
        im.height,
        im.spp,
        im.max_depth,
        scene.objects.len(),
        gpu.stats.perturbations,
        gpu.stats.cells,
        device.name,
        backend
    );
    let mut full = None;
    let mut rows = Vec::new();
    for (name, variant) in variants {
        let out = timed_render(device, &mut cmds, &gpu, scene, variant)?;
        let samples = im.width as f64 * im.height as f64 * im.spp as f64;
        rows.push((name, out.seconds, samples / out.seconds));
        if full.is_none() {
            full = Some(out);
        }
    }
    let full_seconds = rows[0].1;
    eprintln!("{:<46} {:>9} {:>14} {:>12}", "variant", "seconds", "samples/s", "of full time");
    for (name, seconds, rate) in &rows {
        eprintln!("{name:<46} {seconds:>9.3} {rate:>14.0} {:>11.1}%", 100.0 * seconds / full_seconds);
    }
    // The full render on every backend the device offers, side by side.
    let mut by_backend = vec![(backend, rows[0].2)];
    for other in Backend::ALL.into_iter().filter(|&b| b != backend && device.offers(b)) {
        let variant = RenderVariant { backend: Some(other), ..variants[0].1 };
        let out = timed_render(device, &mut cmds, &gpu, scene, variant)?;
        by_backend.push((other, im.width as f64 * im.height as f64 * im.spp as f64 / out.seconds));
    }
    let line: Vec<String> = by_backend.iter().map(|(b, rate)| format!("{b} {rate:.0}")).collect();
    eprintln!("full render, samples/s by backend: {}", line.join(", "));
    let full = full.expect("the full render");
    if device.offers(Backend::RayQuery) {
        print_kernels(device, &mut cmds, &gpu, scene, (variants[0].1, &full))?;
    }
    print_frame_table(&full, rows[2].1, im.spp);
    Ok(full)
}

/// Renders `scene` with `variant` after an untimed warm-up (lavapipe
/// compiles the shader variant at its first dispatch).
fn timed_render(
    device: &std::sync::Arc<quadray::vk::Device>,
    cmds: &mut quadray::vk::Commands,
    gpu: &quadray::passes::GpuScene,
    scene: &Scene,
    variant: quadray::passes::RenderVariant,
) -> Result<quadray::passes::RenderOutput> {
    quadray::passes::Renderer::warm_up(device, cmds, gpu, scene, variant)?;
    Ok(quadray::passes::render(device, cmds, gpu, scene, variant, &mut |_, _| {})?)
}

/// The render pass with each kernel (ray queries), side by side, and where
/// the wavefront pass's time goes stage by stage. `full` is the benchmark's
/// full render and its variant: the kernel it ran is not rendered again.
fn print_kernels(
    device: &std::sync::Arc<quadray::vk::Device>,
    cmds: &mut quadray::vk::Commands,
    gpu: &quadray::passes::GpuScene,
    scene: &Scene,
    (variant, full): (quadray::passes::RenderVariant, &quadray::passes::RenderOutput),
) -> Result<()> {
    use quadray::passes::{PathKernel, RenderVariant};
    use quadray::vk::Backend;
    let samples = scene.image.width as f64 * scene.image.height as f64 * scene.image.spp as f64;
    let ran = if full.wave_profile.is_some() { PathKernel::Wavefront } else { PathKernel::Megakernel };
    let mut rates = Vec::new();
    let mut profile = full.wave_profile;
    for kernel in PathKernel::ALL {
        let seconds = if full.backend == Some(Backend::RayQuery) && kernel == ran {
            full.render_seconds
        } else {
            let v = RenderVariant { kernel: Some(kernel), backend: Some(Backend::RayQuery), ..variant };
            let out = timed_render(device, cmds, gpu, scene, v)?;
            profile = profile.or(out.wave_profile);
            out.render_seconds
        };
        rates.push(format!("{kernel} {:.0}", samples / seconds));
    }
    eprintln!("render pass, samples/s by kernel (ray queries): {}", rates.join(", "));
    if let Some(p) = profile {
        let total = p.start + p.trace + p.shade + p.other;
        let share = |s: f64| 100.0 * s / total;
        eprintln!(
            "wavefront stages: camera rays {:.3} s ({:.0}%), trace {:.3} s ({:.0}%), shade {:.3} s ({:.0}%), \
             between stages {:.3} s ({:.0}%); {} iterations in {} waves",
            p.start,
            share(p.start),
            p.trace,
            share(p.trace),
            p.shade,
            share(p.shade),
            p.other,
            share(p.other),
            p.iterations,
            p.waves
        );
    }
    Ok(())
}

/// Per-pass times of one frame in the layout of the paper's table 1: a
/// frame is one sample per pixel plus the caustic passes as configured.
/// Geometry is the render without shading (camera rays and first-hit
/// albedo), shading the rest of the render pass.
pub(crate) fn print_frame_table(full: &quadray::passes::RenderOutput, geometry_seconds: f64, spp: u32) {
    let ms = |s: f64| 1e3 * s;
    let spp = spp.max(1) as f64;
    let caustics = full.caustics.as_ref().map_or(0.0, |c| c.seconds());
    let volume = full.volume_seconds.unwrap_or(0.0);
    let render_pass = (full.seconds - caustics - volume) / spp;
    let geometry = geometry_seconds / spp;
    let shading = (render_pass - geometry).max(0.0);
    let frame = render_pass + volume / spp + caustics;
    eprintln!("\nOne frame (1 spp plus the caustic passes), as in the paper's table 1:");
    eprintln!("| geometry (ms) | shading (ms) | caustic rays | caustics (ms) | volume (ms) | frame (ms) | frames/s |");
    eprintln!("|---:|---:|---:|---:|---:|---:|---:|");
    eprintln!(
        "| {:.2} | {:.2} | {} | {:.2} | {:.2} | {:.2} | {:.3} |",
        ms(geometry),
        ms(shading),
        full.caustics.as_ref().map_or(0, |c| c.rays),
        ms(caustics),
        ms(volume / spp),
        ms(frame),
        1.0 / frame
    );
    if let Some(c) = &full.caustics {
        eprintln!(
            "caustic passes: G-buffer {:.2} ms, rays {:.2} ms, cells {:.2} ms, beams {:.2} ms; {} of {} rays landed on a receiver",
            ms(c.gbuffer_seconds),
            ms(c.trace_seconds),
            ms(c.splat_seconds),
            ms(c.beam_seconds),
            c.landed,
            c.rays
        );
    }
}
