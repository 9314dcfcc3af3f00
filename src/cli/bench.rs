//! The measuring commands: `bench` (presets), `filter-bench`, `throughput`
//! and `outliers`.

use std::path::{Path, PathBuf};

use super::common::*;
use super::render::*;
use anyhow::{bail, Context as _, Result};
use clap::Parser;
use quadray::jobs::output::{write_exr, ExrPrecision};
use quadray::model::scene::MAX_IMAGE_SIZE;
use quadray::model::scene::{parse_scene, Preset, Scene, DEFAULT_SCENE, DEFAULT_SCENE_NAME};
use quadray::passes::{LookupMode, ShadingMode};
use quadray::util::progress::ProgressBar;

#[derive(Parser, Debug)]
pub(crate) struct ThroughputArgs {
    /// Scene files; `default` is the built-in default scene. Default: the
    /// default scene, figure 1 left, the glass vessel and two spheres over a
    /// textured plane.
    #[arg(default_values = ["default", "scenes/figure1_left.toml", "scenes/glass_vessel.toml", "scenes/spheres.toml"])]
    pub(crate) scenes: Vec<String>,
    /// An older quadray binary to measure beside this one, run for run.
    #[arg(long, conflicts_with = "backends")]
    pub(crate) baseline: Option<PathBuf>,
    /// Measure this binary with each backend side by side (`--backend
    /// ray-query`, then `--backend pipeline`, run for run) instead of beside
    /// a baseline.
    #[arg(long)]
    pub(crate) backends: bool,
    /// Measure this binary with each path kernel side by side (`--kernel
    /// megakernel`, then `--kernel wavefront`, with ray queries, run for
    /// run) instead of beside a baseline; the speed-up column is the
    /// megakernel's over the wavefront pass's.
    #[arg(long, conflicts_with_all = ["backends", "baseline"])]
    pub(crate) kernels: bool,
    /// Image width of the timed renders.
    #[arg(long, default_value_t = 1024, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(8..=MAX_IMAGE_SIZE))]
    pub(crate) width: u32,
    /// Image height of the timed renders.
    #[arg(long, default_value_t = 768, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(8..=MAX_IMAGE_SIZE))]
    pub(crate) height: u32,
    /// Samples per pixel of the timed renders.
    #[arg(long, default_value_t = 16, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=quadray::model::scene::MAX_SPP))]
    pub(crate) spp: u32,
    /// Timed renders per binary and scene (alternated between the binaries).
    #[arg(long, default_value_t = 3, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=100))]
    pub(crate) runs: u32,
    /// Also render a reference of this many samples per pixel (another seed;
    /// cached) and report each binary's relative MSE and FLIP against it.
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=quadray::model::scene::MAX_SPP))]
    pub(crate) reference_spp: Option<u32>,
    /// Output folder (created if missing).
    #[arg(short, long, default_value = "results/throughput")]
    pub(crate) out: PathBuf,
}

#[derive(Parser, Debug)]
pub(crate) struct BenchArgs {
    /// Scene files; `default` is the built-in default scene. Default: the
    /// default scene and the figure scenes (figure 1 left and right, the
    /// glass vessel of figure 2).
    #[arg(default_values = ["default", "scenes/figure1_left.toml", "scenes/figure1_right.toml", "scenes/glass_vessel.toml"])]
    pub(crate) scenes: Vec<String>,
    /// The presets to measure against `reference`, comma separated.
    #[arg(long, value_delimiter = ',', default_values = ["preview", "interactive", "final"])]
    pub(crate) presets: Vec<Preset>,
    /// Image width of every render (the scenes' own sizes make the
    /// references slow on a CPU driver).
    #[arg(long, default_value_t = 256, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(8..=MAX_IMAGE_SIZE))]
    pub(crate) width: u32,
    /// Image height of every render.
    #[arg(long, default_value_t = 192, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(8..=MAX_IMAGE_SIZE))]
    pub(crate) height: u32,
    /// Samples per pixel of the reference (default: the `reference` preset's 1024).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=quadray::model::scene::MAX_SPP))]
    pub(crate) reference_spp: Option<u32>,
    /// Output folder (created if missing); references are cached in its `cache/`.
    #[arg(short, long, default_value = "results/bench")]
    pub(crate) out: PathBuf,
    /// Print progress even when stderr is not a terminal.
    #[arg(long)]
    pub(crate) progress: bool,
    /// Render nothing: read the `bench.json` an earlier run wrote in the
    /// output folder and draw `bench.png` again.
    #[arg(long)]
    pub(crate) replot: bool,
    /// Enable the Khronos validation layer (fails on any error).
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    pub(crate) validation: bool,
}

#[derive(Parser, Debug)]
pub(crate) struct FilterBenchArgs {
    /// Scene files (default: the four texture-dominated scenes and the two
    /// figure-1 scenes, lighting-dominated controls).
    #[arg(default_values = [
        "scenes/glints.toml",
        "scenes/glossy_window.toml",
        "scenes/anisotropic.toml",
        "scenes/curved_mirrors.toml",
        "scenes/figure1_left.toml",
        "scenes/figure1_right.toml",
    ])]
    pub(crate) scenes: Vec<PathBuf>,
    /// Output folder (created if missing); references are cached in its `cache/`.
    #[arg(short, long, default_value = "results/filtering")]
    pub(crate) out: PathBuf,
    /// Image width.
    #[arg(long, default_value_t = 256, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub(crate) width: u32,
    /// Image height.
    #[arg(long, default_value_t = 192, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(8..=4096))]
    pub(crate) height: u32,
    /// Samples per pixel of the reference (filtering `none`), rendered as two
    /// halves with different seeds so that its own noise is measured and
    /// subtracted from every error.
    #[arg(long, default_value_t = 2048, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(2..=quadray::model::scene::MAX_SPP))]
    pub(crate) reference_spp: u32,
    /// Each mode renders at 1, 2, 4, … up to this many samples per pixel.
    #[arg(long, default_value_t = 64, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub(crate) max_spp: u32,
    /// Independent renders (seeds) per measured point: the error splits into
    /// variance (across them) and bias².
    #[arg(long, default_value_t = 8, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(2..=1024))]
    pub(crate) seeds: u32,
    /// The targets: `none`'s error at these spp (each must be on the spp
    /// ladder up to --max-spp), comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [16u32, 64])]
    pub(crate) targets: Vec<u32>,
    /// Frames of the camera pan for temporal stability (0 skips it).
    #[arg(long, default_value_t = 6)]
    pub(crate) frames: u32,
    /// Samples per pixel of each mode's pan frames.
    #[arg(long, default_value_t = 4, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=65536))]
    pub(crate) frame_spp: u32,
    /// Samples per pixel of the reference pan frames.
    #[arg(long, default_value_t = 256, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=quadray::model::scene::MAX_SPP))]
    pub(crate) reference_frame_spp: u32,
    /// Camera motion per pan frame, as a fraction of the camera's distance to
    /// its look-at point, along its right vector (0.004 is about a pixel at
    /// the look-at distance for a 192-pixel-high, 40° view).
    #[arg(long, default_value_t = 0.004)]
    pub(crate) pan_step: f64,
    /// What the renders compute: `full` (the path tracer), `albedo` (texture
    /// transport alone: the albedo seen directly and through perfect mirrors,
    /// no lighting; isolates what filtering does from lighting noise) or
    /// `glossy-albedo` (the albedo also seen through glossy reflections and
    /// refractions, their lobes sampled).
    #[arg(long, value_enum, default_value_t = BenchShading::Full)]
    pub(crate) shading: BenchShading,
    /// The filtered modes' texture lookup: `probes` (trilinear probes along
    /// the footprint's major axis) or `ewa` (the reference lookup).
    #[arg(long, value_enum, default_value_t = Lookup::Probes)]
    pub(crate) lookup: Lookup,
    /// Render nothing: read the reports earlier runs wrote in the output
    /// folder for these scenes, draw their plots again and write
    /// `summary.md` and `headline.json` over them.
    #[arg(long)]
    pub(crate) summarize_only: bool,
    /// Enable the Khronos validation layer (fails on any error).
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    pub(crate) validation: bool,
}

/// Shading of `filter-bench --shading`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
pub(crate) enum BenchShading {
    /// The path tracer.
    Full,
    /// The albedo seen directly and through perfect mirrors, no lighting.
    Albedo,
    /// The albedo seen directly and through mirrors, glossy reflections and
    /// refractions, no lighting.
    GlossyAlbedo,
}

/// The filtered modes' texture lookup (`--lookup`).
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq, Default)]
pub(crate) enum Lookup {
    /// Trilinear probes along the footprint's major axis.
    #[default]
    Probes,
    /// Elliptical weighted averaging over one mip level (the reference lookup).
    Ewa,
}

impl Lookup {
    fn mode(self) -> LookupMode {
        match self {
            Self::Probes => LookupMode::Probes,
            Self::Ewa => LookupMode::Ewa,
        }
    }
}

pub(crate) fn filter_bench(args: FilterBenchArgs) -> Result<()> {
    for s in &args.scenes {
        if !s.is_file() {
            bail!("scene file {} not found", s.display());
        }
    }
    let command = std::iter::once("quadray".to_string()).chain(std::env::args().skip(1)).collect::<Vec<_>>().join(" ");
    let config = quadray::tools::filter_bench::Config {
        scenes: args.scenes,
        out_dir: args.out,
        width: args.width,
        height: args.height,
        reference_spp: args.reference_spp,
        max_spp: args.max_spp,
        seeds: args.seeds,
        targets: args.targets,
        frames: args.frames,
        frame_spp: args.frame_spp,
        reference_frame_spp: args.reference_frame_spp,
        pan_step: args.pan_step,
        shading: match args.shading {
            BenchShading::Full => ShadingMode::Full,
            BenchShading::Albedo => ShadingMode::MirroredAlbedo,
            BenchShading::GlossyAlbedo => ShadingMode::GlossyAlbedo,
        },
        lookup: args.lookup.mode(),
        command,
    };
    if args.summarize_only {
        quadray::tools::filter_bench::summarize(&config)?;
        return Ok(());
    }
    let ctx = quadray::vk::Context::new(args.validation).context("cannot start Vulkan")?;
    let counters = ctx.counters();
    let reports = quadray::tools::filter_bench::run(&ctx, &config)?;
    for r in &reports {
        for e in quadray::tools::filter_bench::headline_entries(r) {
            let speedups = e
                .speedup_vs_none
                .iter()
                .map(|(m, v)| format!("{m} {}", v.map_or("not reached".into(), |v| format!("{v:.2}x"))))
                .collect::<Vec<_>>()
                .join(", ");
            eprintln!("{}: texture share {:.3}, target {}: {speedups}", e.scene, e.texture_share, e.target);
        }
    }
    drop(ctx);
    if counters.errors() > 0 {
        bail!("the validation layer reported {} error(s)", counters.errors());
    }
    Ok(())
}

pub(crate) fn bench_presets(args: BenchArgs) -> Result<()> {
    if args.replot {
        quadray::tools::bench::replot(&args.out)?;
        eprintln!("wrote {}/bench.png", args.out.display());
        return Ok(());
    }
    let mut scenes = Vec::new();
    for name in &args.scenes {
        let (scene_name, source, file) = if name == "default" {
            ("default".to_string(), DEFAULT_SCENE.to_string(), DEFAULT_SCENE_NAME.to_string())
        } else {
            let path = Path::new(name);
            let text = std::fs::read_to_string(path).with_context(|| format!("cannot read the scene file {name}"))?;
            let stem = path.file_stem().map_or("scene".into(), |s| s.to_string_lossy().into_owned());
            (stem, text, name.clone())
        };
        let scene = parse_scene(&source, &file)?;
        scenes.push(quadray::tools::bench::BenchScene { name: scene_name, scene, source });
    }
    let command = std::iter::once("quadray".to_string()).chain(std::env::args().skip(1)).collect::<Vec<_>>().join(" ");
    let config = quadray::tools::bench::Config {
        scenes,
        presets: args.presets,
        size: (args.width, args.height),
        reference_spp: args.reference_spp,
        out_dir: args.out.clone(),
        command,
        progress: args.progress,
    };
    let ctx = quadray::vk::Context::new(args.validation).context("cannot start Vulkan")?;
    let counters = ctx.counters();
    let report = quadray::tools::bench::run(&ctx, &config)?;
    println!("{}", quadray::tools::bench::markdown(&report));
    eprintln!("wrote {}/bench.json, bench.md and bench.png", args.out.display());
    drop(ctx);
    if counters.errors() > 0 {
        bail!("the validation layer reported {} error(s)", counters.errors());
    }
    Ok(())
}

/// `quadray throughput`.
pub(crate) fn throughput(args: ThroughputArgs, set_threads: bool) -> Result<()> {
    let command = std::iter::once("quadray".to_string()).chain(std::env::args().skip(1)).collect::<Vec<_>>().join(" ");
    for scene in &args.scenes {
        if scene != "default" && !Path::new(scene).is_file() {
            bail!("scene file {scene} not found (run from the repository root, or give the scenes' paths)");
        }
    }
    if let Some(b) = &args.baseline {
        if !b.is_file() {
            bail!("baseline binary {} not found", b.display());
        }
    }
    let config = quadray::tools::throughput::Config {
        scenes: args.scenes,
        size: (args.width, args.height),
        spp: args.spp,
        runs: args.runs,
        binary: quadray::vk::runtime::current_exe().context("cannot find this binary's path")?,
        baseline: args.baseline,
        side_by_side: if args.backends {
            Some(quadray::tools::throughput::SideBySide::Backends)
        } else if args.kernels {
            Some(quadray::tools::throughput::SideBySide::Kernels)
        } else {
            None
        },
        reference_spp: args.reference_spp,
        out_dir: args.out.clone(),
        // Each binary picks its own lavapipe thread count, as it would alone.
        env_remove: if set_threads { vec!["LP_NUM_THREADS".into()] } else { vec![] },
        command,
    };
    let report = quadray::tools::throughput::run(&config)?;
    println!("{}", quadray::tools::throughput::markdown(&report));
    eprintln!("wrote {}/throughput.json and throughput.md", args.out.display());
    Ok(())
}

#[derive(Parser, Debug)]
pub(crate) struct OutliersArgs {
    /// Scene file (TOML). Omit it to check the built-in default scene.
    pub(crate) scene: Option<PathBuf>,
    #[command(flatten)]
    pub(crate) frame: FrameArgs,
    #[command(flatten)]
    pub(crate) quality: QualityArgs,
    /// The bound on a sample's luminance (default: the one the scene's
    /// emitters and depth allow; needed for scenes with point or
    /// directional lights).
    #[arg(long)]
    pub(crate) bound: Option<f32>,
    /// How many of the worst pixels to trace and print.
    #[arg(long, default_value_t = 3)]
    pub(crate) worst: usize,
    /// Write the largest-sample AOV (luminance, sample index) and the
    /// radiance to this EXR.
    #[arg(short, long)]
    pub(crate) output: Option<PathBuf>,
    /// Also render a reference with this many samples per pixel (another
    /// seed) and print the relative MSE of the whole image and of each
    /// region (the pixels that see one object, silhouettes left out): a
    /// whole-image error far above the mean of the regions' says that a few
    /// pixels dominate it.
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=quadray::model::scene::MAX_SPP))]
    pub(crate) regions: Option<u32>,
    /// Enable the Khronos validation layer; the command fails if it reports errors.
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    pub(crate) validation: bool,
    /// Render with the caustic and volume passes the scene needs instead of
    /// by brute force: the samples and paths left are those the passes do not
    /// cover (a sample at a vertex the caustic map covers includes the map's
    /// per-pixel estimate, so the bound may not hold for it)
    #[arg(long)]
    pub(crate) passes: bool,
}

/// `quadray outliers`: samples over the scene's bound, and their paths.
pub(crate) fn outliers(args: OutliersArgs) -> Result<()> {
    use quadray::passes::outliers::{describe_path, largest_sample, outliers, SampleBound};
    use quadray::passes::{GpuScene, RenderVariant, Renderer};
    let render_args = RenderArgs {
        scene: args.scene.clone(),
        frame: args.frame.clone(),
        quality: args.quality.clone(),
        ..Default::default()
    };
    let scene = load(&render_args)?;
    let bound = match args.bound {
        Some(b) => b,
        None => {
            let b = SampleBound::of(&scene).context("give the bound with --bound")?;
            let media = if b.media {
                format!(" + 0.5 x {} segments in media) x 2 (guided directions in media", 4 * b.max_depth + 8)
            } else {
                String::new()
            };
            eprintln!(
                "bound: {:.4} = largest emitted luminance {:.4} x (1 + 1.5 x {} bounces{media})",
                b.luminance, b.emitted, b.max_depth
            );
            b.luminance
        }
    };
    let ctx = quadray::vk::Context::new(args.validation).context("cannot start Vulkan")?;
    let counters = ctx.counters();
    let device = &ctx.device;
    let mut cmds = quadray::vk::Commands::new(device)?;
    let gpu = GpuScene::for_render(device, &mut cmds, &scene)?;
    let im = &scene.image;
    let variant = if args.passes {
        RenderVariant::default()
    } else {
        RenderVariant { caustics: false, volume: false, ..Default::default() }
    };
    // Renders `s` (this scene, or its reference with another seed and spp).
    let render = |cmds: &mut quadray::vk::Commands, s: &Scene| {
        let mut progress = ProgressBar::new(false);
        let out = quadray::passes::render(device, cmds, &gpu, s, variant, &mut |d, t| progress.update(d, t));
        progress.finish();
        out
    };
    let out = render(&mut cmds, &scene)?;
    let samples = out.width as u64 * out.height as u64 * out.spp as u64;
    let found = outliers(&out, bound);
    if let Some(m) = largest_sample(&out) {
        eprintln!(
            "{samples} samples ({}x{}, {} spp, seed {}): largest sample {:.4} at pixel ({}, {}), sample {}",
            out.width, out.height, out.spp, im.seed, m.luminance, m.x, m.y, m.sample
        );
    }
    println!("{} pixel(s) with a sample over the bound {bound:.4}", found.len());
    for o in found.iter().take(20) {
        println!("  pixel ({}, {}): sample {} of luminance {:.4}", o.x, o.y, o.sample, o.luminance);
    }
    if !found.is_empty() && args.worst > 0 {
        let record = RenderVariant { record_path: true, ..variant };
        let mut recorder = Renderer::with_samples(device, &mut cmds, &gpu, &scene, 1, record)?;
        for o in found.iter().take(args.worst) {
            let path = recorder.trace_path(&mut cmds, (o.x, o.y), o.sample)?;
            println!("\npixel ({}, {}), sample {} (luminance {:.4}):", o.x, o.y, o.sample, o.luminance);
            print!("{}", describe_path(&scene, &path));
        }
    }
    if let Some(path) = &args.output {
        write_exr(&out, ExrPrecision::Float, path)?;
    }
    if let Some(reference_spp) = args.regions {
        let mut reference_scene = scene.clone();
        reference_scene.image.seed = scene.image.seed ^ 0x9e37_79b9;
        reference_scene.image.spp = reference_spp;
        let reference = render(&mut cmds, &reference_scene)?;
        let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
        let e = quadray::tools::metrics::region_relative_mse(&reference, &out, 2, 64)?;
        println!("\nrelative MSE at {} spp against {reference_spp} spp:", out.spp);
        for (object, pixels, error) in &e.regions {
            let name = names.get(*object as usize).copied().unwrap_or("background");
            println!("  {name:<24} {pixels:>7} pixels  {error:.5}");
        }
        println!(
            "  whole image {:.5}, mean of the regions {:.5}: ratio {:.3}",
            e.whole,
            e.mean_of_regions(),
            e.ratio()
        );
    }
    if counters.errors() > 0 {
        bail!("the validation layer reported {} error(s)", counters.errors());
    }
    if !found.is_empty() {
        std::process::exit(3);
    }
    Ok(())
}
