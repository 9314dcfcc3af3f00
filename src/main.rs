//! The `quadray` command line: render a scene file to PNG and EXR.

use std::path::{Path, PathBuf};

use anyhow::{bail, Context as _, Result};
use clap::{Parser, Subcommand};
use quadray::output::{write_exr, write_outputs_with, ExrPrecision, OutputKind};
use quadray::progress::ProgressBar;
use quadray::scene::{load_scene, parse_scene, FilterMode, Preset, Scene, DEFAULT_SCENE, DEFAULT_SCENE_NAME};

/// A Vulkan path tracer for functionally defined objects (perturbed quadrics).
///
/// With no subcommand, renders the built-in default scene to render.png and render.exr.
#[derive(Parser, Debug)]
#[command(version, about)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
}

#[derive(Subcommand, Debug)]
enum Command {
    /// Render a scene file (or the built-in default scene) to an image.
    Render(RenderArgs),
    /// Measure the texture-filtering modes' speed/accuracy trade against a
    /// brute-force reference: FLIP and relative MSE against GPU time (JSON,
    /// Markdown and PNG plots), the time each mode takes to reach the error
    /// of `none` at the largest spp, and temporal stability over a camera pan.
    FilterBench(FilterBenchArgs),
    /// Open a window that renders a scene progressively, with an orbit and
    /// fly camera and keys for the filtering mode, preset, caustics, volume
    /// and screenshots (README.md, "The viewer").
    View(ViewArgs),
    /// Measure the quality presets' speed/accuracy trade: each scene rendered
    /// at each preset and compared with its `reference` render (FLIP and
    /// relative MSE against GPU time per pass); writes bench.json, bench.md,
    /// bench.png (error against time) and the renders.
    Bench(BenchArgs),
    /// Find samples that gain energy: render a scene by brute force, report
    /// the pixels whose largest single sample exceeds the bound the scene's
    /// emitters allow, and print the path of the worst ones, event by event.
    /// Exits with status 3 when any pixel exceeds the bound.
    Outliers(OutliersArgs),
    /// Compare a render with a reference: FLIP (mean, from nv-flip) and
    /// relative MSE between two EXR files of the same size.
    Compare(CompareArgs),
    /// Assemble tiles or crops of one render (EXR files of `render --tile`
    /// or `--crop`) into the whole frame: PNG and EXR with the AOVs. Refuses
    /// tiles of different scenes, settings or frames, unfinished tiles, gaps
    /// and overlaps, and then writes nothing.
    Merge(MergeArgs),
    /// Render on a Slurm cluster: a job array of one task per tile and frame
    /// (each idempotent and resumable), then a merge job (README.md, "Long
    /// renders and farms").
    #[command(subcommand)]
    Farm(FarmCommand),
    /// Measure samples per second and CPU use of whole `quadray render`
    /// processes on the throughput scenes, optionally beside an older binary
    /// (`--baseline`) in the same run; writes throughput.json and
    /// throughput.md.
    Throughput(ThroughputArgs),
}

/// `quadray farm`: Slurm job arrays of tiles and frames.
#[derive(Subcommand, Debug)]
enum FarmCommand {
    /// Set up a farm folder and submit it: `sbatch` job array of tiles x
    /// frames, then a merge job that runs when every task succeeded. Run it
    /// again (or `farm resume`) after failures: only missing tiles are
    /// submitted.
    Slurm(FarmSlurmArgs),
    /// Submit the tasks of a farm whose tiles are missing (after failed,
    /// cancelled or pre-empted tasks), and a new merge job.
    Resume {
        /// The farm folder.
        dir: PathBuf,
    },
    /// Print a farm's progress: per frame, the tiles done and checkpointed,
    /// and whether it is merged.
    Status {
        /// The farm folder.
        dir: PathBuf,
    },
    /// One task of the array (what task.sh runs): renders its tile of its
    /// frame unless it is already there, resuming its checkpoint if any.
    #[command(hide = true)]
    Task {
        /// The farm folder.
        dir: PathBuf,
        /// The task number (SLURM_ARRAY_TASK_ID).
        index: u32,
    },
    /// Merge every frame whose tiles are all there into DIR/NAME[.FFFF].png
    /// and .exr (what merge.sh runs); fails, naming them, when tiles are
    /// missing.
    Merge {
        /// The farm folder.
        dir: PathBuf,
    },
}

#[derive(Parser, Debug)]
struct FarmSlurmArgs {
    /// Scene file (TOML, see scenes/README.md).
    scene: PathBuf,
    /// Tiles per frame (`render --tile i/N`: bands of whole rows).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=16384))]
    tiles: u32,
    /// Frames of the scene's camera animation, A-B or A-B:STEP; without it,
    /// the still camera.
    #[arg(long)]
    frames: Option<FrameRange>,
    /// The farm folder: tiles, checkpoints, logs, merged frames.
    #[arg(short, long)]
    output: PathBuf,
    /// CPUs per task (`sbatch --cpus-per-task`; lavapipe runs two threads per CPU).
    #[arg(long, default_value_t = 1, value_parser = clap::value_parser!(u32).range(1..=1024))]
    cpus_per_task: u32,
    /// Seconds between a task's checkpoints (what a task killed without
    /// warning loses at most; SIGTERM writes one at once).
    #[arg(long, default_value_t = 120.0, value_parser = positive_seconds)]
    checkpoint_every: f64,
    /// A further `sbatch` argument for every submission, e.g.
    /// `--sbatch-arg=--partition=render` (repeatable).
    #[arg(long = "sbatch-arg", allow_hyphen_values = true)]
    sbatch_args: Vec<String>,
    /// `quadray render` flags of every task, after `--`: quality, size,
    /// seed (e.g. `-- --spp 256 --width 1920 --height 1080`).
    #[arg(last = true)]
    render_args: Vec<String>,
}

#[derive(Parser, Debug)]
struct ThroughputArgs {
    /// Scene files; `default` is the built-in default scene. Default: the
    /// default scene, figure 1 left, the glass vessel and two spheres over a
    /// textured plane.
    #[arg(default_values = ["default", "scenes/figure1_left.toml", "scenes/glass_vessel.toml", "scenes/spheres.toml"])]
    scenes: Vec<String>,
    /// An older quadray binary to measure beside this one, run for run.
    #[arg(long)]
    baseline: Option<PathBuf>,
    /// Image width of the timed renders.
    #[arg(long, default_value_t = 1024, value_parser = clap::value_parser!(u32).range(8..=16384))]
    width: u32,
    /// Image height of the timed renders.
    #[arg(long, default_value_t = 768, value_parser = clap::value_parser!(u32).range(8..=16384))]
    height: u32,
    /// Samples per pixel of the timed renders.
    #[arg(long, default_value_t = 16, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    spp: u32,
    /// Timed renders per binary and scene (alternated between the binaries).
    #[arg(long, default_value_t = 3, value_parser = clap::value_parser!(u32).range(1..=100))]
    runs: u32,
    /// Also render a reference of this many samples per pixel (another seed;
    /// cached) and report each binary's relative MSE and FLIP against it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    reference_spp: Option<u32>,
    /// Output folder (created if missing).
    #[arg(short, long, default_value = "results/throughput")]
    out: PathBuf,
}

#[derive(Parser, Debug)]
#[command(after_help = concat!("Keys:\n", "mouse: left drag orbits, right drag turns the view, wheel dollies\n",
    "W A S D: fly forward, left, back, right    Q E: down, up    (arrow keys: orbit)\n",
    "F: next filtering mode    P: next preset    1 2 3 4: preview, interactive, final, reference\n",
    "C: caustics on/off    V: volume on/off    R: reset camera\n",
    "F12 or O: screenshot (PNG + EXR)    Esc: close"))]
struct ViewArgs {
    /// Scene file (TOML). Omit it to view the built-in default scene.
    scene: Option<PathBuf>,
    /// Quality preset to start with (default: the scene's, else `interactive`).
    #[command(flatten)]
    quality: QualityArgs,
    /// Initial window width (overrides `image.width`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: Option<u32>,
    /// Initial window height (overrides `image.height`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: Option<u32>,
    /// Samples per pixel to accumulate before the view stops refining
    /// (default: the preset's or scene's spp).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    max_spp: Option<u32>,
    /// Start with the caustic and volume passes off (brute force).
    #[arg(long)]
    brute_force: bool,
    /// Folder for screenshots.
    #[arg(long, default_value = ".")]
    screenshot_dir: PathBuf,
    /// Steps to run, separated by `;` (for automation and tests): `wait N`
    /// (N spp on screen), `frames N`, `screenshot [NAME]`, `key K`,
    /// `orbit YAW PITCH`, `resize WxH`, `minimize`, `restore`, `close`.
    #[arg(long)]
    script: Option<String>,
    /// Enable the Khronos validation layer; the command fails if it reports errors.
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    validation: bool,
}

#[derive(Parser, Debug)]
struct MergeArgs {
    /// The tiles' EXR files.
    #[arg(required = true)]
    tiles: Vec<PathBuf>,
    /// Output path, as `render -o`: `NAME.png`, `NAME.exr`, or a name
    /// without those extensions for both.
    #[arg(short, long)]
    output: PathBuf,
    /// Write the EXR with 16-bit half floats instead of 32-bit floats.
    #[arg(long)]
    half: bool,
}

#[derive(Parser, Debug)]
struct BenchArgs {
    /// Scene files; `default` is the built-in default scene. Default: the
    /// default scene and the figure scenes (figure 1 left and right, the
    /// glass vessel of figure 2).
    #[arg(default_values = ["default", "scenes/figure1_left.toml", "scenes/figure1_right.toml", "scenes/glass_vessel.toml"])]
    scenes: Vec<String>,
    /// The presets to measure against `reference`, comma separated.
    #[arg(long, value_delimiter = ',', default_values = ["preview", "interactive", "final"])]
    presets: Vec<Preset>,
    /// Image width of every render (the scenes' own sizes make the
    /// references slow on a CPU driver).
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(8..=16384))]
    width: u32,
    /// Image height of every render.
    #[arg(long, default_value_t = 192, value_parser = clap::value_parser!(u32).range(8..=16384))]
    height: u32,
    /// Samples per pixel of the reference (default: the `reference` preset's 1024).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    reference_spp: Option<u32>,
    /// Output folder (created if missing); references are cached in its `cache/`.
    #[arg(short, long, default_value = "results/bench")]
    out: PathBuf,
    /// Print progress even when stderr is not a terminal.
    #[arg(long)]
    progress: bool,
    /// Enable the Khronos validation layer (fails on any error).
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    validation: bool,
}

#[derive(Parser, Debug)]
struct CompareArgs {
    /// The reference image (EXR).
    reference: PathBuf,
    /// The image to compare with it (EXR).
    test: PathBuf,
    /// Exposure in stops applied to both before FLIP's tone mapping.
    #[arg(long, default_value_t = 0.0, allow_negative_numbers = true)]
    exposure: f32,
}

#[derive(Parser, Debug)]
struct FilterBenchArgs {
    /// Scene files (default: the three texture-dominated scenes and the two
    /// figure-1 scenes, lighting-dominated controls).
    #[arg(default_values = [
        "scenes/glints.toml",
        "scenes/glossy_window.toml",
        "scenes/anisotropic.toml",
        "scenes/figure1_left.toml",
        "scenes/figure1_right.toml",
    ])]
    scenes: Vec<PathBuf>,
    /// Output folder (created if missing); references are cached in its `cache/`.
    #[arg(short, long, default_value = "results/filtering")]
    out: PathBuf,
    /// Image width.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(8..=4096))]
    width: u32,
    /// Image height.
    #[arg(long, default_value_t = 192, value_parser = clap::value_parser!(u32).range(8..=4096))]
    height: u32,
    /// Samples per pixel of the reference (filtering `none`), rendered as two
    /// halves with different seeds so that its own noise is measured and
    /// subtracted from every error.
    #[arg(long, default_value_t = 2048, value_parser = clap::value_parser!(u32).range(2..=1_000_000))]
    reference_spp: u32,
    /// Each mode renders at 1, 2, 4, … up to this many samples per pixel.
    #[arg(long, default_value_t = 64, value_parser = clap::value_parser!(u32).range(1..=65536))]
    max_spp: u32,
    /// Independent renders (seeds) per measured point: the error splits into
    /// variance (across them) and bias².
    #[arg(long, default_value_t = 8, value_parser = clap::value_parser!(u32).range(2..=1024))]
    seeds: u32,
    /// The targets: `none`'s error at these spp (each must be on the spp
    /// ladder up to --max-spp), comma-separated.
    #[arg(long, value_delimiter = ',', default_values_t = [16u32, 64])]
    targets: Vec<u32>,
    /// Frames of the camera pan for temporal stability (0 skips it).
    #[arg(long, default_value_t = 6)]
    frames: u32,
    /// Samples per pixel of each mode's pan frames.
    #[arg(long, default_value_t = 4, value_parser = clap::value_parser!(u32).range(1..=65536))]
    frame_spp: u32,
    /// Samples per pixel of the reference pan frames.
    #[arg(long, default_value_t = 256, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    reference_frame_spp: u32,
    /// Camera motion per pan frame, as a fraction of the camera's distance to
    /// its look-at point, along its right vector (0.004 is about a pixel at
    /// the look-at distance for a 192-pixel-high, 40° view).
    #[arg(long, default_value_t = 0.004)]
    pan_step: f64,
    /// What the renders compute: `full` (the path tracer), `albedo` (texture
    /// transport alone: the albedo seen directly and through perfect mirrors,
    /// no lighting; isolates what filtering does from lighting noise) or
    /// `glossy-albedo` (the albedo also seen through glossy reflections and
    /// refractions, their lobes sampled).
    #[arg(long, value_enum, default_value_t = BenchShading::Full)]
    shading: BenchShading,
    /// The filtered modes' texture lookup: `probes` (trilinear probes along
    /// the footprint's major axis) or `ewa` (the reference lookup).
    #[arg(long, value_enum, default_value_t = Lookup::Probes)]
    lookup: Lookup,
    /// Render nothing: read the reports earlier runs wrote in the output
    /// folder for these scenes and write `summary.md` and `headline.json`
    /// over them.
    #[arg(long)]
    summarize_only: bool,
    /// Enable the Khronos validation layer (fails on any error).
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    validation: bool,
}

/// Shading of `filter-bench --shading`.
#[derive(clap::ValueEnum, Clone, Copy, Debug, PartialEq, Eq)]
enum BenchShading {
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
enum Lookup {
    /// Trilinear probes along the footprint's major axis.
    #[default]
    Probes,
    /// Elliptical weighted averaging over one mip level (the reference lookup).
    Ewa,
}

impl Lookup {
    fn constant(self) -> u32 {
        match self {
            Self::Probes => quadray::shader_interface::LOOKUP_PROBES,
            Self::Ewa => quadray::shader_interface::LOOKUP_EWA,
        }
    }
}

/// Image size and seed overrides of `render` and `outliers`.
#[derive(Parser, Debug, Default, Clone)]
struct FrameArgs {
    /// Image width in pixels (overrides `image.width`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    width: Option<u32>,
    /// Image height in pixels (overrides `image.height`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=16384))]
    height: Option<u32>,
    /// Random seed (overrides `image.seed`).
    #[arg(long)]
    seed: Option<u32>,
}

#[derive(Parser, Debug)]
struct OutliersArgs {
    /// Scene file (TOML). Omit it to check the built-in default scene.
    scene: Option<PathBuf>,
    #[command(flatten)]
    frame: FrameArgs,
    #[command(flatten)]
    quality: QualityArgs,
    /// The bound on a sample's luminance (default: the one the scene's
    /// emitters and depth allow; needed for scenes with point or
    /// directional lights).
    #[arg(long)]
    bound: Option<f32>,
    /// How many of the worst pixels to trace and print.
    #[arg(long, default_value_t = 3)]
    worst: usize,
    /// Write the largest-sample AOV (luminance, sample index) and the
    /// radiance to this EXR.
    #[arg(short, long)]
    output: Option<PathBuf>,
    /// Also render a reference with this many samples per pixel (another
    /// seed) and print the relative MSE of the whole image and of each
    /// region (the pixels that see one object, silhouettes left out): a
    /// whole-image error far above the mean of the regions' says that a few
    /// pixels dominate it.
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    regions: Option<u32>,
    /// Enable the Khronos validation layer; the command fails if it reports errors.
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    validation: bool,
}

#[derive(Parser, Debug, Default)]
struct RenderArgs {
    /// Scene file (TOML, see scenes/README.md). Omit it to render the built-in default scene.
    scene: Option<PathBuf>,
    /// Output path. `NAME.png` writes only a PNG, `NAME.exr` only an EXR, a
    /// name without one of those extensions writes both `NAME.png` and `NAME.exr`.
    #[arg(short, long, default_value = "render")]
    output: PathBuf,
    #[command(flatten)]
    frame: FrameArgs,
    /// Write the EXR with 16-bit half floats instead of 32-bit floats.
    #[arg(long)]
    half: bool,
    /// Enable the Khronos validation layer; the command fails if it reports errors.
    /// QUADRAY_VALIDATION=1 (or true/yes/on) in the environment does the same.
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    validation: bool,
    /// Print progress even when stderr is not a terminal.
    #[arg(long)]
    progress: bool,
    /// Benchmark mode: after an untimed warm-up (lavapipe compiles shaders at
    /// their first dispatch), time the render and variants of it with parts of
    /// the work switched off (perturbation root finding, shading and
    /// secondary rays, intersection), print samples per second for each, and
    /// write the full render's outputs.
    #[arg(long)]
    bench: bool,
    #[command(flatten)]
    quality: QualityArgs,
    /// Brute force: no caustic or volume passes; the path tracer alone
    /// estimates caustics and the light scattered by the fog (the reference
    /// those passes are compared with).
    #[arg(long)]
    brute_force: bool,
    /// Write checkpoints of the work so far to this file (atomically), every
    /// --checkpoint-every seconds and when the render is stopped by SIGINT,
    /// SIGTERM or --time-limit; removed once the render completes and its
    /// images are written. Default with --resume: the file resumed from.
    #[arg(long)]
    checkpoint: Option<PathBuf>,
    /// Seconds between checkpoints.
    #[arg(long, default_value_t = 300.0, value_parser = positive_seconds)]
    checkpoint_every: f64,
    /// Continue the render saved in this checkpoint (refused unless the
    /// scene file and every flag that changes the image are the same).
    #[arg(long)]
    resume: Option<PathBuf>,
    /// Render until this many seconds have passed, then write the image so
    /// far (and the checkpoint, with --checkpoint) and exit with status 0;
    /// the images' `quadray.spp` metadata says how many samples they have.
    #[arg(long, value_parser = positive_seconds)]
    time_limit: Option<f64>,
    /// Render only these pixel bounds of the frame: x0,x1,y0,y1 (columns
    /// x0..x1, rows y0..y1, half-open, row 0 at the top; pbrt-v4's
    /// --pixelbounds). The EXR's data window is the crop, its display
    /// window the frame.
    #[arg(long, conflicts_with = "tile")]
    crop: Option<quadray::passes::PixelBounds>,
    /// Render tile i of N: the frame split into N bands of whole rows, band
    /// i covering rows floor(i·H/N) to floor((i+1)·H/N). `quadray merge`
    /// assembles the tiles.
    #[arg(long)]
    tile: Option<quadray::passes::TileIndex>,
    /// Render frame F of the scene's camera animation (`[[camera.keyframes]]`,
    /// frame F at time F / camera.fps); outputs are numbered: NAME.0002.png.
    #[arg(long = "frame", conflicts_with = "frames")]
    animation_frame: Option<u32>,
    /// Render frames A to B (inclusive), every STEP-th (default 1), in one
    /// process that builds its shaders once: A-B or A-B:STEP. Outputs are
    /// numbered: NAME.0001.exr, NAME.0002.exr, ...
    #[arg(long)]
    frames: Option<FrameRange>,
}

/// `--frames A-B[:STEP]`.
#[derive(Clone, Copy, Debug)]
struct FrameRange {
    first: u32,
    last: u32,
    step: u32,
}

impl std::str::FromStr for FrameRange {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, String> {
        let err = || format!("{s:?}: a frame range is A-B or A-B:STEP (e.g. 1-48 or 1-48:2), A <= B, STEP >= 1");
        let (range, step) = s.split_once(':').map_or((s, "1"), |(r, st)| (r, st));
        let (a, b) = range.split_once('-').ok_or_else(err)?;
        let parse = |v: &str| v.trim().parse::<u32>().map_err(|_| err());
        let (first, last, step) = (parse(a)?, parse(b)?, parse(step)?);
        if first > last || step == 0 {
            return Err(err());
        }
        Ok(Self { first, last, step })
    }
}

/// Exit status of a render stopped by SIGINT or SIGTERM after it wrote its
/// image so far (and its checkpoint): EX_TEMPFAIL of sysexits.h, "try
/// again later".
const EXIT_INTERRUPTED: i32 = 75;

fn positive_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("{s:?} is not a positive number of seconds")),
    }
}

/// Which files `-o` asks for.
fn output_paths(output: &Path) -> Vec<PathBuf> {
    match output.extension().and_then(|e| e.to_str()).map(|e| e.to_ascii_lowercase()) {
        Some(e) if e == "png" || e == "exr" => vec![output.to_path_buf()],
        _ => {
            let mut png = output.as_os_str().to_owned();
            png.push(".png");
            let mut exr = output.as_os_str().to_owned();
            exr.push(".exr");
            vec![PathBuf::from(png), PathBuf::from(exr)]
        }
    }
}

/// What to write to each of `paths`: a PNG at `exposure` (stops) where the
/// extension says `png`, else an EXR (16-bit with `half`).
fn output_files(paths: &[PathBuf], exposure: f32, half: bool) -> Vec<(PathBuf, OutputKind)> {
    let precision = if half { ExrPrecision::Half } else { ExrPrecision::Float };
    paths
        .iter()
        .map(|p| {
            let is_png = p.extension().is_some_and(|e| e.eq_ignore_ascii_case("png"));
            (p.clone(), if is_png { OutputKind::Png { exposure } } else { OutputKind::Exr(precision) })
        })
        .collect()
}

/// The quality settings of `render`, `view` and `bench`: a preset, then
/// single overrides.
#[derive(Parser, Debug, Default, Clone)]
struct QualityArgs {
    /// Quality preset: `preview`, `interactive`, `final` or `reference`
    /// (README.md, "Quality presets"). Replaces all the scene's quality
    /// settings (spp, max_depth, filter, caustic rays and light samples,
    /// volume samples); the flags below override single ones.
    #[arg(long)]
    preset: Option<Preset>,
    /// Samples per pixel (overrides the scene's or preset's `image.spp`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1_000_000))]
    spp: Option<u32>,
    /// Longest light path in bounces (overrides `image.max_depth`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=64))]
    max_depth: Option<u32>,
    /// Texture filtering (overrides `image.filter`): `none` (bilinear lookups
    /// of the finest mip level; with many samples per pixel, the reference),
    /// `ray-cones` (EWA lookups over ray-cone footprints, Akenine-Möller et
    /// al. 2021) or `covariance` (EWA lookups over covariance footprints
    /// carried along the path).
    #[arg(long)]
    filter: Option<FilterMode>,
    /// Caustic rays per light and light sample (overrides `caustics.rays`; 0
    /// switches the caustic passes off).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=16_777_216))]
    caustic_rays: Option<u32>,
    /// Points on each sphere light that emit caustic rays (overrides
    /// `caustics.light_samples`).
    #[arg(long, value_parser = clap::value_parser!(u32).range(1..=1024))]
    caustic_light_samples: Option<u32>,
    /// Camera rays per pixel and render sample of the volume pass (overrides
    /// `volume.samples`; 0 switches the volume pass off).
    #[arg(long, value_parser = clap::value_parser!(u32).range(0..=65536))]
    volume_samples: Option<u32>,
}

impl QualityArgs {
    /// Applies the preset, then the single overrides, to `scene`.
    fn apply(&self, scene: &mut Scene) {
        if let Some(p) = self.preset {
            scene.apply_preset(p);
        }
        let mut q = scene.quality();
        q.spp = self.spp.unwrap_or(q.spp);
        q.max_depth = self.max_depth.unwrap_or(q.max_depth);
        q.filter = self.filter.unwrap_or(q.filter);
        q.caustic_rays = self.caustic_rays.unwrap_or(q.caustic_rays);
        q.caustic_light_samples = self.caustic_light_samples.unwrap_or(q.caustic_light_samples);
        q.volume_samples = self.volume_samples.unwrap_or(q.volume_samples);
        scene.set_quality(q);
    }
}

/// Reads `path` (or the built-in default scene when `None`).
fn read_scene(path: Option<&Path>) -> Result<Scene> {
    Ok(match path {
        Some(path) => load_scene(path)?,
        None => parse_scene(DEFAULT_SCENE, DEFAULT_SCENE_NAME)?,
    })
}

fn load(args: &RenderArgs) -> Result<Scene> {
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
fn requested_frames(args: &RenderArgs) -> Option<Vec<u32>> {
    match (args.animation_frame, args.frames) {
        (Some(f), _) => Some(vec![f]),
        (None, Some(r)) => Some((r.first..=r.last).step_by(r.step as usize).collect()),
        (None, None) => None,
    }
}

/// `path` with the frame number before its extension: `out.exr` →
/// `out.0002.exr`.
fn frame_path(path: &Path, frame: u32) -> PathBuf {
    let stem = path.file_stem().map_or(String::new(), |s| s.to_string_lossy().into_owned());
    let name = match path.extension() {
        Some(e) => format!("{stem}.{frame:04}.{}", e.to_string_lossy()),
        None => format!("{stem}.{frame:04}"),
    };
    path.with_file_name(name)
}

fn render(args: RenderArgs) -> Result<()> {
    let scene = load(&args)?;
    if args.output.is_dir() || args.output.as_os_str().to_string_lossy().ends_with(std::path::MAIN_SEPARATOR) {
        bail!(
            "-o {}: give a file name (e.g. {}/render), not a directory",
            args.output.display(),
            args.output.display()
        );
    }
    let outputs = output_paths(&args.output);
    for p in &outputs {
        if let Some(dir) = p.parent().filter(|d| !d.as_os_str().is_empty()) {
            if !dir.is_dir() {
                bail!("output directory {} does not exist", dir.display());
            }
        }
    }
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
    let ctx = quadray::vk::Context::new(args.validation).context("cannot start Vulkan")?;
    let counters = ctx.counters();
    let filter = scene.image.filter.constant();
    let variant = quadray::passes::RenderVariant {
        filter,
        caustics: !args.brute_force,
        volume: !args.brute_force,
        ..Default::default()
    };
    let mut interrupted = false;
    if args.bench {
        let out = bench(&ctx, &scene, filter)?;
        write_render(&args, &ctx, &scene, variant, &outputs, None, &out, quadray::job::JobEnd::Complete)?;
    } else {
        let stop = std::sync::Arc::new(std::sync::atomic::AtomicBool::new(false));
        for signal in [signal_hook::consts::SIGINT, signal_hook::consts::SIGTERM] {
            // A second signal ends the process at once (exit status 1).
            signal_hook::flag::register_conditional_shutdown(signal, 1, stop.clone())?;
            signal_hook::flag::register(signal, stop.clone())?;
        }
        let options = quadray::job::JobOptions {
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
        let mut resume = quadray::job::read_resume(&first, variant, &options)?;
        let mut job = quadray::job::Job::new(&ctx, &first, variant, bounds).context("render failed")?;
        for frame in list {
            let frame_scene = frame.map_or_else(|| scene.clone(), |f| scene.at_frame(f));
            let mut progress = ProgressBar::new(args.progress);
            let result = job.render(&frame_scene, &options, resume.take(), &mut |d, t| progress.update(d, t));
            progress.finish();
            let result = result.context("render failed")?;
            if result.resumed_from > 0 {
                eprintln!("resumed at {} of {} spp", result.resumed_from, frame_scene.image.spp);
            }
            let paths: Vec<PathBuf> = match frame {
                Some(f) => outputs.iter().map(|p| frame_path(p, f)).collect(),
                None => outputs.clone(),
            };
            write_render(&args, &ctx, &frame_scene, variant, &paths, frame, &result.output, result.end)?;
            if result.end != quadray::job::JobEnd::Complete {
                interrupted = result.end == quadray::job::JobEnd::Interrupted;
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

/// Writes one render's (or frame's) files with their metadata, handles its
/// checkpoint and prints what was done.
#[allow(clippy::too_many_arguments)]
fn write_render(
    args: &RenderArgs,
    ctx: &quadray::vk::Context,
    scene: &Scene,
    variant: quadray::passes::RenderVariant,
    outputs: &[PathBuf],
    frame: Option<u32>,
    out: &quadray::passes::RenderOutput,
    end: quadray::job::JobEnd,
) -> Result<()> {
    if ctx.counters().errors() > 0 {
        bail!("the validation layer reported {} error(s); no output written", ctx.counters().errors());
    }
    let files = output_files(outputs, scene.image.exposure, args.half);
    let key = quadray::job::image_key(scene, variant);
    let mut metadata: Vec<(String, String)> = [
        (quadray::output::METADATA_SPP, out.spp.to_string()),
        (quadray::output::METADATA_TARGET_SPP, scene.image.spp.to_string()),
        (quadray::output::METADATA_SEED, scene.image.seed.to_string()),
        (quadray::output::METADATA_EXPOSURE, scene.image.exposure.to_string()),
        (quadray::output::METADATA_SCENE_KEY, format!("{key:016x}")),
    ]
    .map(|(k, v)| (k.to_string(), v))
    .to_vec();
    if let Some(f) = frame {
        metadata.push((quadray::output::METADATA_FRAME.to_string(), f.to_string()));
    }
    write_outputs_with(out, &files, &metadata)?;
    let checkpoint = args.checkpoint.as_ref().or(args.resume.as_ref());
    match (end, checkpoint) {
        (quadray::job::JobEnd::Complete, Some(path)) if path.exists() => {
            // The images are the render now; a checkpoint left behind would
            // only be resumed into the same images.
            std::fs::remove_file(path).with_context(|| format!("cannot remove {}", path.display()))?;
        }
        (quadray::job::JobEnd::Complete, _) => {}
        (stopped, path) => eprintln!(
            "{}: wrote the image so far ({} spp of {}{}){}",
            if stopped == quadray::job::JobEnd::Interrupted { "interrupted" } else { "time limit reached" },
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
    let names: Vec<String> = outputs.iter().map(|p| p.display().to_string()).collect();
    eprintln!(
        "wrote {} ({}x{}, {} spp, {:.2} s on {})",
        names.join(", "),
        out.width,
        out.height,
        out.spp,
        out.seconds,
        ctx.device.name
    );
    Ok(())
}

/// `quadray merge`: tiles into the whole frame.
fn merge(args: MergeArgs) -> Result<()> {
    let tiles =
        args.tiles.iter().map(|p| Ok((p.clone(), quadray::output::read_render_exr(p)?))).collect::<Result<Vec<_>>>()?;
    let (out, metadata) = quadray::merge::merge(&tiles)?;
    let exposure = metadata
        .iter()
        .find(|(k, _)| k == quadray::output::METADATA_EXPOSURE)
        .and_then(|(_, v)| v.parse().ok())
        .unwrap_or(0.0);
    let files = output_files(&output_paths(&args.output), exposure, args.half);
    write_outputs_with(&out, &files, &metadata)?;
    let names: Vec<String> = files.iter().map(|(p, _)| p.display().to_string()).collect();
    eprintln!("merged {} tiles into {} ({}x{}, {} spp)", tiles.len(), names.join(", "), out.width, out.height, out.spp);
    Ok(())
}

/// `quadray farm`.
fn farm(cmd: FarmCommand) -> Result<()> {
    use quadray::farm::{Farm, Manifest, MANIFEST_VERSION};
    match cmd {
        FarmCommand::Slurm(args) => {
            let scene =
                std::fs::canonicalize(&args.scene).with_context(|| format!("scene file {}", args.scene.display()))?;
            let frames: Option<Vec<u32>> = args.frames.map(|r| (r.first..=r.last).step_by(r.step as usize).collect());
            // The tasks' render command, checked here (flags, scene, tiles)
            // rather than in every task.
            let mut check = vec!["quadray".to_string(), "render".into(), scene.display().to_string()];
            check.extend(args.render_args.iter().cloned());
            check.extend(["--tile".into(), format!("0/{}", args.tiles)]);
            if let Some(f) = frames.as_ref() {
                check.extend(["--frame".into(), f[0].to_string()]);
            }
            let owned = quadray::farm::FARM_OWNED_FLAGS;
            if let Some(flag) = args.render_args.iter().find(|a| owned.iter().any(|f| a.split('=').next() == Some(f))) {
                bail!("{flag} is set by the farm for each task; leave it out of the render flags");
            }
            let Some(Command::Render(render_args)) = Cli::try_parse_from(&check)?.command else {
                unreachable!("a render command line")
            };
            let loaded = load(&render_args)?;
            quadray::passes::PixelBounds::tile(0, args.tiles, loaded.image.width, loaded.image.height)?;
            if frames.is_some() && loaded.camera.keyframes.is_empty() {
                bail!("--frames: {} has no camera animation ([[camera.keyframes]], scenes/README.md)", scene.display());
            }
            let manifest = Manifest {
                version: MANIFEST_VERSION,
                name: scene.file_stem().map_or("render".into(), |s| s.to_string_lossy().into_owned()),
                scene,
                tiles: args.tiles,
                frames,
                render_args: args.render_args,
                quadray: std::env::current_exe().context("cannot find the quadray binary")?,
                cpus_per_task: args.cpus_per_task,
                checkpoint_every: args.checkpoint_every,
                sbatch_args: args.sbatch_args,
                submissions: Vec::new(),
            };
            let mut farm = Farm::create(&args.output, manifest)?;
            farm_submit(&mut farm)
        }
        FarmCommand::Resume { dir } => farm_submit(&mut Farm::open(&dir)?),
        FarmCommand::Status { dir } => {
            print!("{}", Farm::open(&dir)?.status());
            Ok(())
        }
        FarmCommand::Task { dir, index } => {
            let farm = Farm::open(&dir)?;
            let task = farm.manifest.task(index)?;
            let what = format!(
                "task {index} ({}tile {}/{})",
                task.frame.map_or(String::new(), |f| format!("frame {f}, ")),
                task.tile,
                farm.manifest.tiles
            );
            let Some(resume) = farm.prepare_task(task) else {
                farm.journal(&format!("skip {what}: its tile is there"))?;
                eprintln!("{what}: {} is there already; nothing to do", farm.tile_path(task).display());
                return Ok(());
            };
            farm.journal(&format!("start {what}{}", if resume { " from its checkpoint" } else { "" }))?;
            let (output, _) = farm.partial_paths(task);
            let mut argv = vec!["quadray".to_string(), "render".into()];
            argv.extend(farm.manifest.render_args_of(task, &output, &farm.checkpoint_path(task), resume));
            eprintln!("{what}: quadray {}", argv[1..].join(" "));
            let Some(Command::Render(args)) = Cli::try_parse_from(&argv)?.command else {
                unreachable!("a render command line")
            };
            // Exits with status 75 (and the checkpoint written) when stopped.
            render(args)?;
            farm.finish_task(task)?;
            farm.journal(&format!("done {what}"))?;
            Ok(())
        }
        FarmCommand::Merge { dir } => {
            let farm = Farm::open(&dir)?;
            let missing = farm.missing_tasks();
            for frame in farm.manifest.frame_list() {
                let tasks = farm.manifest.frame_tasks(frame);
                if tasks.iter().any(|t| missing.contains(t)) {
                    continue;
                }
                merge(MergeArgs {
                    tiles: tasks.iter().map(|t| farm.tile_path(*t)).collect(),
                    output: farm.frame_output(frame),
                    half: false,
                })?;
            }
            if !missing.is_empty() {
                let list: Vec<String> = missing.iter().map(|t| t.index.to_string()).collect();
                bail!(
                    "tiles of tasks {} are missing; `quadray farm resume {}` renders them",
                    list.join(", "),
                    farm.dir.display()
                );
            }
            Ok(())
        }
    }
}

/// Submits what a farm lacks and says what was submitted.
fn farm_submit(farm: &mut quadray::farm::Farm) -> Result<()> {
    match farm.submit()? {
        None => {
            eprintln!("farm {}: every tile is rendered and every frame merged; nothing to submit", farm.dir.display())
        }
        Some(s) => {
            if s.array_job.is_empty() {
                eprintln!("every tile is there: submitted merge job {}", s.merge_job);
            } else {
                eprintln!(
                    "submitted job array {} ({} task(s): {}) and merge job {} (runs once every task succeeded)",
                    s.array_job,
                    s.tasks.len(),
                    quadray::farm::array_spec(&s.tasks),
                    s.merge_job
                );
            }
            eprintln!(
                "`quadray farm status {0}` shows progress; after failures `quadray farm resume {0}` submits what is missing",
                farm.dir.display()
            );
        }
    }
    Ok(())
}

/// `quadray outliers`: samples over the scene's bound, and their paths.
fn outliers(args: OutliersArgs) -> Result<()> {
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
            let media =
                if b.media { format!(" + 0.5 x {} segments in media", 4 * b.max_depth + 8) } else { String::new() };
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
    let variant = RenderVariant { filter: im.filter.constant(), caustics: false, volume: false, ..Default::default() };
    // Renders `spp` samples of `s` (this scene, perhaps with another seed).
    let render = |cmds: &mut quadray::vk::Commands, s: &Scene, spp: u32| {
        let mut progress = ProgressBar::new(false);
        let out = quadray::passes::render(device, cmds, &gpu, s, (im.width, im.height, spp), variant, &mut |d, t| {
            progress.update(d, t)
        });
        progress.finish();
        out
    };
    let out = render(&mut cmds, &scene, im.spp)?;
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
        let mut recorder = Renderer::new(device, &mut cmds, &gpu, &scene, (im.width, im.height, 1), record)?;
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
        let reference = render(&mut cmds, &reference_scene, reference_spp)?;
        let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
        let e = quadray::metrics::region_relative_mse(&reference, &out, 2, 64)?;
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

/// The benchmark mode of `render --bench`; returns the full render.
fn bench(ctx: &quadray::vk::Context, scene: &Scene, filter: u32) -> Result<quadray::passes::RenderOutput> {
    use quadray::passes::{render, GpuScene, RenderVariant};
    use quadray::shader_interface::{INTERSECT_BASE, INTERSECT_BOXES, INTERSECT_FULL, SHADING_FULL, SHADING_NONE};
    let device = &ctx.device;
    let mut cmds = quadray::vk::Commands::new(device)?;
    let gpu = GpuScene::for_render(device, &mut cmds, scene)?;
    let im = &scene.image;
    let variants = [
        (
            "full render",
            RenderVariant { intersect: INTERSECT_FULL, shading: SHADING_FULL, filter, ..Default::default() },
        ),
        (
            "perturbation root finding off",
            RenderVariant { intersect: INTERSECT_BASE, shading: SHADING_FULL, filter, ..Default::default() },
        ),
        (
            "shading and secondary rays off",
            RenderVariant { intersect: INTERSECT_FULL, shading: SHADING_NONE, filter, ..Default::default() },
        ),
        (
            "traversal only (boxes are hits, no shading)",
            RenderVariant { intersect: INTERSECT_BOXES, shading: SHADING_NONE, filter, ..Default::default() },
        ),
    ];
    eprintln!(
        "benchmark: {}x{}, {} spp, max depth {}, {} objects ({} perturbations, {} cells) on {}",
        im.width,
        im.height,
        im.spp,
        im.max_depth,
        scene.objects.len(),
        gpu.stats.perturbations,
        gpu.stats.cells,
        device.name
    );
    let mut full = None;
    let mut rows = Vec::new();
    for (name, variant) in variants {
        // Untimed warm-up: the shader variant compiles at its first dispatch.
        render(device, &mut cmds, &gpu, scene, (8, 8, 1), variant, &mut |_, _| {})?;
        let out = render(device, &mut cmds, &gpu, scene, (im.width, im.height, im.spp), variant, &mut |_, _| {})?;
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
    let full = full.expect("the full render");
    print_frame_table(&full, rows[2].1, im.spp);
    Ok(full)
}

/// Per-pass times of one frame in the layout of the paper's table 1: a
/// frame is one sample per pixel plus the caustic passes as configured.
/// Geometry is the render without shading (camera rays and first-hit
/// albedo), shading the rest of the render pass.
fn print_frame_table(full: &quadray::passes::RenderOutput, geometry_seconds: f64, spp: u32) {
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

fn compare(args: CompareArgs) -> Result<()> {
    let read = |path: &Path| -> Result<quadray::passes::RenderOutput> {
        let (width, height, texels) =
            quadray::texture::read_exr_image(path).with_context(|| format!("cannot read {}", path.display()))?;
        Ok(quadray::passes::RenderOutput::from_radiance(
            width,
            height,
            texels.iter().map(|t| [t[0], t[1], t[2]]).collect(),
        ))
    };
    let reference = read(&args.reference)?;
    let test = read(&args.test)?;
    if (reference.width, reference.height) != (test.width, test.height) {
        bail!(
            "{} is {}x{} but {} is {}x{}",
            args.reference.display(),
            reference.width,
            reference.height,
            args.test.display(),
            test.width,
            test.height
        );
    }
    let flip = quadray::metrics::flip_mean(&reference, &test, args.exposure)?;
    let rel_mse = quadray::metrics::relative_mse(&reference, &test)?;
    let lum = |p: &[f32; 3]| 0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2];
    let (worst, _) =
        reference.radiance.iter().zip(&test.radiance).enumerate().fold((0, -1.0f32), |best, (i, (r, t))| {
            let d = (lum(r) - lum(t)).abs();
            if d > best.1 {
                (i, d)
            } else {
                best
            }
        });
    println!("FLIP {flip:.4}  relative MSE {rel_mse:.5}");
    println!(
        "largest luminance difference at pixel ({}, {}): reference {:.4}, test {:.4}",
        worst as u32 % reference.width,
        worst as u32 / reference.width,
        lum(&reference.radiance[worst]),
        lum(&test.radiance[worst])
    );
    Ok(())
}

fn filter_bench(args: FilterBenchArgs) -> Result<()> {
    for s in &args.scenes {
        if !s.is_file() {
            bail!("scene file {} not found", s.display());
        }
    }
    let command = std::iter::once("quadray".to_string()).chain(std::env::args().skip(1)).collect::<Vec<_>>().join(" ");
    let config = quadray::filter_bench::Config {
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
            BenchShading::Full => quadray::shader_interface::SHADING_FULL,
            BenchShading::Albedo => quadray::shader_interface::SHADING_MIRRORED_ALBEDO,
            BenchShading::GlossyAlbedo => quadray::shader_interface::SHADING_GLOSSY_ALBEDO,
        },
        lookup: args.lookup.constant(),
        command,
    };
    if args.summarize_only {
        quadray::filter_bench::summarize(&config)?;
        return Ok(());
    }
    let ctx = quadray::vk::Context::new(args.validation).context("cannot start Vulkan")?;
    let counters = ctx.counters();
    let reports = quadray::filter_bench::run(&ctx, &config)?;
    for r in &reports {
        for e in quadray::filter_bench::headline_entries(r) {
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

fn view(args: ViewArgs) -> Result<()> {
    let mut scene = read_scene(args.scene.as_deref())?;
    if scene.image.preset.is_none() && args.quality.preset.is_none() {
        // A scene without a preset is viewed at `interactive` quality, its
        // own explicit settings aside: the scene's spp is meant for a final
        // render and would make a slow first view.
        let own = scene.quality();
        scene.apply_preset(Preset::Interactive);
        scene.image.max_depth = own.max_depth;
    }
    args.quality.apply(&mut scene);
    if let Some(w) = args.width {
        scene.image.width = w;
    }
    if let Some(h) = args.height {
        scene.image.height = h;
    }
    let script = match &args.script {
        Some(text) => quadray::viewer::actions::parse_script(text)?,
        None => Vec::new(),
    };
    if !args.screenshot_dir.is_dir() {
        bail!("--screenshot-dir {}: no such folder", args.screenshot_dir.display());
    }
    let name = args
        .scene
        .as_ref()
        .and_then(|p| p.file_stem())
        .map_or("default".to_string(), |s| s.to_string_lossy().into_owned());
    let summary = quadray::viewer::run(quadray::viewer::ViewerConfig {
        scene,
        name,
        validation: args.validation,
        max_spp: args.max_spp,
        brute_force: args.brute_force,
        screenshot_dir: args.screenshot_dir.clone(),
        script,
    })
    .context("viewer failed")?;
    eprintln!("viewer closed after {} frames", summary.frames);
    if let Some(c) = summary.counters {
        if c.errors() > 0 {
            bail!("the validation layer reported {} error(s)", c.errors());
        }
    }
    Ok(())
}

fn bench_presets(args: BenchArgs) -> Result<()> {
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
        scenes.push(quadray::bench::BenchScene { name: scene_name, scene, source });
    }
    let command = std::iter::once("quadray".to_string()).chain(std::env::args().skip(1)).collect::<Vec<_>>().join(" ");
    let config = quadray::bench::Config {
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
    let report = quadray::bench::run(&ctx, &config)?;
    println!("{}", quadray::bench::markdown(&report));
    eprintln!("wrote {}/bench.json, bench.md and bench.png", args.out.display());
    drop(ctx);
    if counters.errors() > 0 {
        bail!("the validation layer reported {} error(s)", counters.errors());
    }
    Ok(())
}

/// The threads lavapipe runs compute dispatches on, when the user has not
/// set `LP_NUM_THREADS`: twice the CPUs this process may use (those Slurm
/// gives a task, `SLURM_CPUS_PER_TASK`, else the affinity mask), at most 32.
/// lavapipe hands each thread one contiguous share of a dispatch's
/// workgroups; with one thread per core a core idles while the other
/// finishes its share, with two per core the operating system fills it.
/// Measured on 2 cores (default scene, 1024x768, 8 spp, 3 runs alternated):
/// 188 % CPU against 178 %, 0.97x the wall time.
/// Returns true when it set the variable.
fn default_lavapipe_threads() -> bool {
    if std::env::var_os("LP_NUM_THREADS").is_some() {
        return false;
    }
    let slurm = std::env::var("SLURM_CPUS_PER_TASK").ok().and_then(|v| v.trim().parse::<usize>().ok());
    let cpus = slurm.filter(|&n| n > 0).unwrap_or_else(|| std::thread::available_parallelism().map_or(1, |n| n.get()));
    // Safe: called first thing in main, before any other thread exists.
    std::env::set_var("LP_NUM_THREADS", (2 * cpus).min(32).to_string());
    true
}

/// `quadray throughput`.
fn throughput(args: ThroughputArgs, set_threads: bool) -> Result<()> {
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
    let config = quadray::throughput::Config {
        scenes: args.scenes,
        size: (args.width, args.height),
        spp: args.spp,
        runs: args.runs,
        binary: std::env::current_exe().context("cannot find this binary's path")?,
        baseline: args.baseline,
        reference_spp: args.reference_spp,
        out_dir: args.out.clone(),
        // Each binary picks its own lavapipe thread count, as it would alone.
        env_remove: if set_threads { vec!["LP_NUM_THREADS".into()] } else { vec![] },
        command,
    };
    let report = quadray::throughput::run(&config)?;
    println!("{}", quadray::throughput::markdown(&report));
    eprintln!("wrote {}/throughput.json and throughput.md", args.out.display());
    Ok(())
}

fn main() -> Result<()> {
    let set_threads = default_lavapipe_threads();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    let cli = Cli::parse();
    match cli.command {
        Some(Command::Render(args)) => render(args),
        Some(Command::FilterBench(args)) => filter_bench(args),
        Some(Command::Compare(args)) => compare(args),
        Some(Command::Outliers(args)) => outliers(args),
        Some(Command::Bench(args)) => bench_presets(args),
        Some(Command::View(args)) => view(args),
        Some(Command::Throughput(args)) => throughput(args, set_threads),
        Some(Command::Merge(args)) => merge(args),
        Some(Command::Farm(cmd)) => farm(cmd),
        None => render(RenderArgs { output: PathBuf::from("render"), ..Default::default() }),
    }
}
