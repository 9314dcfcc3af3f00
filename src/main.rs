//! The `quadray` command line: render a scene file to PNG and EXR.

mod cli;

use anyhow::Result;
use clap::{Parser, Subcommand};

use cli::bench::*;
use cli::devices::*;
use cli::export::*;
use cli::farm::*;
use cli::images::*;
use cli::render::*;
#[cfg(feature = "viewer")]
use cli::view::*;

/// A Vulkan path tracer for functionally defined objects (perturbed quadrics).
///
/// `quadray render` with no scene renders the built-in default scene to
/// render.png and render.exr (denoised; the raw radiance kept in the EXR).
#[derive(Parser, Debug)]
#[command(
    version,
    about,
    after_help = "Start with:\n  quadray render                          the built-in default scene: render.png, render.exr\n  \
                  quadray render scenes/spheres.toml -o spheres\n  quadray view scenes/default.toml        a window (headless: xvfb-run -a quadray view ...)\n  \
                  quadray devices                         which Vulkan driver and device render\n\n\
                  Scene files: scenes/README.md; the rest: README.md and docs/."
)]
struct Cli {
    #[command(subcommand)]
    command: Option<Command>,
    /// Use the system's Vulkan driver instead of the Vulkan runtime `make
    /// setup` fetched (a current Mesa lavapipe, docs/vulkan-runtime.md).
    /// QUADRAY_SYSTEM_VULKAN=1 does the same; QUADRAY_VULKAN_RUNTIME=DIR
    /// names another runtime.
    #[arg(long, global = true, env = "QUADRAY_SYSTEM_VULKAN", value_parser = clap::builder::BoolishValueParser::new())]
    system_vulkan: bool,
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
    /// and screenshots (docs/viewer.md).
    #[cfg(feature = "viewer")]
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
    /// Denoise a render's EXR with Intel Open Image Denoise, guided by its
    /// albedo and normal channels: writes PNG and EXR (RGB denoised, the raw
    /// radiance kept as `noisy.RGB`). Needs the library (`make setup`).
    Denoise(DenoiseArgs),
    /// Render on a Slurm cluster: a job array of one task per tile and frame
    /// (each idempotent and resumable), then a merge job (docs/farms.md).
    #[command(subcommand)]
    Farm(FarmCommand),
    /// List the Vulkan devices: driver, version, the ray-tracing extensions
    /// and features the renderer uses (ray queries, ray-tracing pipelines,
    /// acceleration structures, float64, 64-bit atomics, timestamps), what
    /// each lacks per backend, and which device and backend a render takes.
    Devices(DevicesArgs),
    /// Measure samples per second and CPU use of whole `quadray render`
    /// processes on the throughput scenes, optionally beside an older binary
    /// (`--baseline`) in the same run; writes throughput.json and
    /// throughput.md.
    Throughput(ThroughputArgs),
    /// Export a scene for other renderers: each object as a triangle mesh
    /// (PLY in world space with normals and texture coordinates; surface
    /// nets projected onto the exact surface, cut by the clip box), each
    /// texture map as EXR, and the resolved scene as scene.json (used by
    /// scripts/mitsuba_side_by_side.py).
    Export(ExportArgs),
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

/// Prints an error as `Error: ...` with its causes. A backtrace only where
/// the error is internal (a Vulkan call that failed, a host/shader interface
/// mismatch: a bug to report) and `RUST_BACKTRACE` asks for one; a mistake
/// in the input or the setup gets its message alone.
fn report(e: &anyhow::Error) {
    eprintln!("Error: {e}");
    let causes: Vec<String> = e.chain().skip(1).map(|c| c.to_string()).collect();
    if !causes.is_empty() {
        eprintln!("\nCaused by:");
        for c in &causes {
            eprintln!("    {c}");
        }
    }
    use quadray::vk::VkError;
    let internal =
        e.chain().any(|c| matches!(c.downcast_ref::<VkError>(), Some(VkError::Vk(_) | VkError::Interface(_))));
    if internal {
        if e.backtrace().status() == std::backtrace::BacktraceStatus::Captured {
            eprintln!("\nStack backtrace:\n{}", e.backtrace());
        } else {
            eprintln!("\n(an internal error: please report it with the scene; RUST_BACKTRACE=1 shows where it arose)");
        }
    }
}

fn main() -> std::process::ExitCode {
    match run() {
        Ok(()) => std::process::ExitCode::SUCCESS,
        Err(e) => {
            report(&e);
            std::process::ExitCode::FAILURE
        }
    }
}

fn run() -> Result<()> {
    // A closed pipe on stdout (`quadray compare a.exr b.exr | head -1`) ends
    // the process quietly, as it does other command-line tools, instead of
    // a panic in println!.
    // SAFETY: called first, before any thread exists; SIG_DFL is a valid
    // disposition for SIGPIPE.
    unsafe { libc::signal(libc::SIGPIPE, libc::SIG_DFL) };
    let cli = Cli::parse();
    // Before any thread and any Vulkan call: may restart the process through
    // the fetched Vulkan runtime's loader.
    quadray::vk::runtime::enter(cli.system_vulkan)?;
    let set_threads = default_lavapipe_threads();
    env_logger::Builder::from_env(env_logger::Env::default().default_filter_or("warn")).init();
    match cli.command {
        Some(Command::Render(args)) => render(args),
        Some(Command::FilterBench(args)) => filter_bench(args),
        Some(Command::Compare(args)) => compare(args),
        Some(Command::Outliers(args)) => outliers(args),
        Some(Command::Bench(args)) => bench_presets(args),
        #[cfg(feature = "viewer")]
        Some(Command::View(args)) => view(args),
        Some(Command::Throughput(args)) => throughput(args, set_threads),
        Some(Command::Merge(args)) => merge(args),
        Some(Command::Denoise(args)) => denoise(args),
        Some(Command::Farm(cmd)) => farm(cmd),
        Some(Command::Devices(args)) => devices(args),
        Some(Command::Export(args)) => export(args),
        None => {
            // Bare `quadray`: the usage, as pbrt and Mitsuba print theirs.
            use clap::CommandFactory;
            Cli::command().print_help()?;
            Ok(())
        }
    }
}
