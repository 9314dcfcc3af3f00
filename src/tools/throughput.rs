//! `quadray throughput`: samples per second and CPU use, measured as a user
//! sees them, optionally against an older binary in the same run.
//!
//! Every render is a separate `quadray render` process (this binary, or the
//! `--baseline` one), so that both binaries are measured the same way and an
//! old binary needs nothing but its `render` subcommand. For each scene,
//! each binary first renders a small untimed image (lavapipe compiles each
//! shader variant at its first dispatch and caches it on disk); then the
//! binaries render the timed image in turn, new and baseline alternately,
//! `runs` times each, so that the machine's drift affects both alike.
//!
//! Per render: samples per second (pixels × spp over the GPU time the
//! binary reports for its passes), the wall time of the whole process, and
//! its CPU use (user + system time of the child over its wall time, from
//! `getrusage`). Medians are reported, and the new/baseline ratio of
//! samples per second is the median of the ratios of runs taken side by
//! side. The last images of both binaries are compared with each other
//! (bit-identical, or their relative MSE) and, with `reference_spp`, with a
//! reference rendered by the new binary with another seed (relative MSE on
//! linear radiance, then FLIP): "unchanged in expectation" means both
//! binaries' errors against it agree.

use std::path::{Path, PathBuf};
use std::process::Command;
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::passes::RenderOutput;
use crate::tools::metrics::{flip_mean, relative_mse, MetricError};

/// Errors of the throughput benchmark.
#[derive(Debug, thiserror::Error)]
pub enum ThroughputError {
    /// A render process could not be started or failed.
    #[error("{command}: {message}")]
    Render {
        /// The command line.
        command: String,
        /// What went wrong (its exit status and the end of its stderr).
        message: String,
    },
    /// A render's output could not be read.
    #[error("{}: {source}", .path.display())]
    Read {
        /// The image.
        path: PathBuf,
        /// Why.
        source: crate::model::texture::TextureError,
    },
    /// Comparing images failed.
    #[error(transparent)]
    Metric(#[from] MetricError),
    /// A file could not be written.
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// What to measure.
#[derive(Clone, Debug)]
pub struct Config {
    /// Scene files; `default` is the built-in default scene.
    pub scenes: Vec<String>,
    /// Image size of the timed renders.
    pub size: (u32, u32),
    /// Samples per pixel of the timed renders.
    pub spp: u32,
    /// Timed renders per binary and scene.
    pub runs: u32,
    /// The new binary (normally this one).
    pub binary: PathBuf,
    /// An older binary to measure beside it.
    pub baseline: Option<PathBuf>,
    /// Measure the new binary two ways side by side (each backend, or each
    /// path kernel) instead of beside a baseline.
    pub side_by_side: Option<SideBySide>,
    /// Samples per pixel of a reference (rendered once per scene by the new
    /// binary, cached in `out_dir/cache`); none: no reference.
    pub reference_spp: Option<u32>,
    /// Where the report, the images and the cache go.
    pub out_dir: PathBuf,
    /// Environment variables removed from the render processes (ones this
    /// process set itself, so that each binary runs with its own defaults).
    pub env_remove: Vec<String>,
    /// The command line, recorded in the report.
    pub command: String,
}

/// Two ways of running the new binary, measured side by side.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum SideBySide {
    /// `--backend ray-query`, then `--backend pipeline`.
    Backends,
    /// `--kernel megakernel`, then `--kernel wavefront` (ray queries).
    Kernels,
}

impl SideBySide {
    /// The two ways: each one's name and the render flags that select it.
    fn ways(self) -> [(&'static str, Vec<String>); 2] {
        let flags = |f: &[&str]| f.iter().map(|s| s.to_string()).collect::<Vec<_>>();
        match self {
            Self::Backends => {
                [("ray-query", flags(&["--backend", "ray-query"])), ("pipeline", flags(&["--backend", "pipeline"]))]
            }
            Self::Kernels => [
                ("megakernel", flags(&["--backend", "ray-query", "--kernel", "megakernel"])),
                ("wavefront", flags(&["--backend", "ray-query", "--kernel", "wavefront"])),
            ],
        }
    }
}

/// One render process's measurements.
#[derive(Clone, Copy, Debug, Serialize, Deserialize)]
pub struct Run {
    /// GPU time the binary reported for its passes, s.
    pub gpu_seconds: f64,
    /// Wall time of the whole process, s.
    pub wall_seconds: f64,
    /// User + system CPU time of the process, s.
    pub cpu_seconds: f64,
}

/// One binary on one scene.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct BinaryResult {
    /// "new" or "baseline"; "ray-query" or "pipeline" when the backends are
    /// compared, "megakernel" or "wavefront" when the kernels are
    /// compared.
    pub binary: String,
    /// Its path.
    pub path: String,
    /// Median samples per second (pixels × spp / GPU seconds).
    pub samples_per_second: f64,
    /// Median GPU seconds.
    pub gpu_seconds: f64,
    /// Median wall seconds of the process.
    pub wall_seconds: f64,
    /// Median CPU use of the process, percent of one core.
    pub cpu_percent: f64,
    /// Relative MSE of its last image against the reference.
    pub relative_mse: Option<f64>,
    /// Mean FLIP of its last image against the reference.
    pub flip: Option<f64>,
    /// Every run.
    pub runs: Vec<Run>,
}

/// One scene's results.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SceneResult {
    /// The scene (file or `default`).
    pub scene: String,
    /// The new binary, then the baseline if any.
    pub binaries: Vec<BinaryResult>,
    /// Median over runs of the first's samples/s ÷ the second's (new ÷
    /// baseline, or ray-query ÷ pipeline).
    pub speedup: Option<f64>,
    /// True when the last images of both binaries are the same bit for bit.
    pub identical: Option<bool>,
    /// Relative MSE between the two binaries' last images.
    pub relative_mse_between: Option<f64>,
}

/// The report (`throughput.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    /// The command that made it.
    pub command: String,
    /// Image size.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Timed runs per binary.
    pub runs: u32,
    /// Reference spp, if any.
    pub reference_spp: Option<u32>,
    /// Per scene.
    pub scenes: Vec<SceneResult>,
}

/// CPU time (user + system, s) of this process's waited-for children.
fn children_cpu_seconds() -> f64 {
    let mut usage = std::mem::MaybeUninit::<libc::rusage>::zeroed();
    // SAFETY: getrusage writes a rusage into the pointer it is given.
    // RUSAGE_CHILDREN is a valid `who` and the pointer is to a live, writable rusage; even if the call
    // failed, the zeroed value is a valid rusage (plain integers), so `assume_init` is sound either way.
    let usage = unsafe {
        libc::getrusage(libc::RUSAGE_CHILDREN, usage.as_mut_ptr());
        usage.assume_init()
    };
    let secs = |t: libc::timeval| t.tv_sec as f64 + t.tv_usec as f64 * 1e-6;
    secs(usage.ru_utime) + secs(usage.ru_stime)
}

/// The GPU seconds in a `quadray render` line such as
/// `wrote a.png, a.exr (64x48, 1 spp, 0.52 s on llvmpipe ...)`.
fn reported_seconds(stderr: &str) -> Option<f64> {
    let line = stderr.lines().rev().find(|l| l.starts_with("wrote "))?;
    let after = &line[line.find(" spp, ")? + 6..];
    after[..after.find(" s on ")?].trim().parse().ok()
}

/// One `render` process: `binary render [scene] flags -o output`.
fn render(
    config: &Config,
    binary: &Path,
    scene: &str,
    flags: &[String],
    output: &Path,
) -> Result<Run, ThroughputError> {
    let mut cmd = Command::new(binary);
    // Each binary chooses its Vulkan driver from the user's environment.
    crate::vk::runtime::restore_env(&mut cmd);
    cmd.arg("render");
    if scene != "default" {
        cmd.arg(scene);
    }
    cmd.args(flags).arg("-o").arg(output);
    for k in &config.env_remove {
        cmd.env_remove(k);
    }
    let line = format!("{} render {scene} {} -o {}", binary.display(), flags.join(" "), output.display());
    let cpu0 = children_cpu_seconds();
    let start = Instant::now();
    let out = cmd.output().map_err(|e| ThroughputError::Render { command: line.clone(), message: e.to_string() })?;
    let wall = start.elapsed().as_secs_f64();
    let cpu = children_cpu_seconds() - cpu0;
    let stderr = String::from_utf8_lossy(&out.stderr);
    if !out.status.success() {
        let tail: Vec<&str> = stderr.lines().rev().take(5).collect();
        let tail: Vec<&str> = tail.into_iter().rev().collect();
        return Err(ThroughputError::Render {
            command: line,
            message: format!("{}: {}", out.status, tail.join(" / ")),
        });
    }
    let gpu = reported_seconds(&stderr).ok_or_else(|| ThroughputError::Render {
        command: line.clone(),
        message: "no `wrote ... (W x H, N spp, S s on DEVICE)` line on stderr".into(),
    })?;
    Ok(Run { gpu_seconds: gpu, wall_seconds: wall, cpu_seconds: cpu })
}

fn median(mut v: Vec<f64>) -> f64 {
    v.sort_by(f64::total_cmp);
    if v.is_empty() {
        return f64::NAN;
    }
    let n = v.len();
    if n % 2 == 1 {
        v[n / 2]
    } else {
        0.5 * (v[n / 2 - 1] + v[n / 2])
    }
}

fn read_exr(path: &Path) -> Result<RenderOutput, ThroughputError> {
    let (width, height, texels) = crate::model::texture::read_exr_image(path)
        .map_err(|source| ThroughputError::Read { path: path.into(), source })?;
    Ok(RenderOutput::from_radiance(width, height, texels.iter().map(|t| [t[0], t[1], t[2]]).collect()))
}

/// A file-name-safe name for a scene.
fn scene_stem(scene: &str) -> String {
    Path::new(scene).file_stem().map_or("scene".into(), |s| s.to_string_lossy().into_owned())
}

/// Runs the benchmark, printing a line per render on stderr, and writes
/// `throughput.json` and `throughput.md` into `config.out_dir`.
pub fn run(config: &Config) -> Result<Report, ThroughputError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| ThroughputError::Io { path, source }
    };
    let images = config.out_dir.join("images");
    let cache = config.out_dir.join("cache");
    for dir in [&images, &cache] {
        std::fs::create_dir_all(dir).map_err(io(dir))?;
    }
    let (w, h) = config.size;
    let flags = vec![
        "--width".to_string(),
        w.to_string(),
        "--height".into(),
        h.to_string(),
        "--spp".into(),
        config.spp.to_string(),
        // Samples are measured, not the denoiser (the default scene asks for it).
        "--no-denoise".into(),
    ];
    let warm_flags: Vec<String> =
        ["--width", "64", "--height", "48", "--spp", "1", "--no-denoise"].map(String::from).to_vec();
    // What is measured: (name, binary, extra flags).
    let mut binaries: Vec<(&str, PathBuf, Vec<String>)> = match config.side_by_side {
        Some(two) => two.ways().into_iter().map(|(name, flags)| (name, config.binary.clone(), flags)).collect(),
        None => vec![("new", config.binary.clone(), Vec::new())],
    };
    if let Some(b) = &config.baseline {
        binaries.push(("baseline", b.clone(), Vec::new()));
    }
    let with = |base: &[String], extra: &[String]| -> Vec<String> { base.iter().chain(extra).cloned().collect() };
    let samples = w as f64 * h as f64 * config.spp as f64;
    let mut scenes = Vec::new();
    for scene in &config.scenes {
        let stem = scene_stem(scene);
        let output = |name: &str| images.join(format!("{stem}-{name}.exr"));
        for (name, bin, extra) in &binaries {
            eprintln!("{stem}: warming up {name} (shader compilation)");
            render(config, bin, scene, &with(&warm_flags, extra), &images.join(format!("{stem}-{name}-warm.exr")))?;
        }
        let mut runs: Vec<Vec<Run>> = vec![Vec::new(); binaries.len()];
        for r in 0..config.runs {
            for (i, (name, bin, extra)) in binaries.iter().enumerate() {
                let run = render(config, bin, scene, &with(&flags, extra), &output(name))?;
                eprintln!(
                    "{stem}: {name} run {}/{}: {:.0} samples/s, {:.2} s GPU, {:.2} s wall, {:.0} % CPU",
                    r + 1,
                    config.runs,
                    samples / run.gpu_seconds,
                    run.gpu_seconds,
                    run.wall_seconds,
                    100.0 * run.cpu_seconds / run.wall_seconds
                );
                runs[i].push(run);
            }
        }
        let reference = match config.reference_spp {
            Some(spp) => {
                let text = if scene == "default" {
                    crate::model::scene::DEFAULT_SCENE.to_string()
                } else {
                    std::fs::read_to_string(scene).map_err(io(Path::new(scene)))?
                };
                let key = crate::tools::filter_bench::fnv1a_hex(format!("{text}\n{w}x{h}\n{spp}").as_bytes());
                let path = cache.join(format!("{stem}-reference-{key}.exr"));
                if !path.exists() {
                    eprintln!("{stem}: rendering the reference ({spp} spp, seed 77777)");
                    let reference_flags = vec![
                        "--width".to_string(),
                        w.to_string(),
                        "--height".into(),
                        h.to_string(),
                        "--spp".into(),
                        spp.to_string(),
                        "--seed".into(),
                        "77777".into(),
                        "--no-denoise".into(),
                    ];
                    render(config, &config.binary, scene, &reference_flags, &path)?;
                }
                Some(read_exr(&path)?)
            }
            None => None,
        };
        let mut results = Vec::new();
        for (i, (name, bin, _)) in binaries.iter().enumerate() {
            let image = read_exr(&output(name))?;
            let (rel, flip) = match &reference {
                Some(r) => (Some(relative_mse(r, &image)?), Some(flip_mean(r, &image, 0.0)?)),
                None => (None, None),
            };
            let rs = &runs[i];
            results.push(BinaryResult {
                binary: name.to_string(),
                path: bin.display().to_string(),
                samples_per_second: median(rs.iter().map(|r| samples / r.gpu_seconds).collect()),
                gpu_seconds: median(rs.iter().map(|r| r.gpu_seconds).collect()),
                wall_seconds: median(rs.iter().map(|r| r.wall_seconds).collect()),
                cpu_percent: median(rs.iter().map(|r| 100.0 * r.cpu_seconds / r.wall_seconds).collect()),
                relative_mse: rel,
                flip,
                runs: rs.clone(),
            });
        }
        let (speedup, identical, between) = if binaries.len() == 2 {
            let ratios = runs[0].iter().zip(&runs[1]).map(|(a, b)| b.gpu_seconds / a.gpu_seconds).collect();
            let (a, b) = (read_exr(&output(binaries[0].0))?, read_exr(&output(binaries[1].0))?);
            (Some(median(ratios)), Some(a.radiance == b.radiance), Some(relative_mse(&b, &a)?))
        } else {
            (None, None, None)
        };
        scenes.push(SceneResult {
            scene: scene.clone(),
            binaries: results,
            speedup,
            identical,
            relative_mse_between: between,
        });
    }
    let report = Report {
        command: config.command.clone(),
        width: w,
        height: h,
        spp: config.spp,
        runs: config.runs,
        reference_spp: config.reference_spp,
        scenes,
    };
    let json = config.out_dir.join("throughput.json");
    let text = serde_json::to_string_pretty(&report).expect("the report serialises");
    std::fs::write(&json, text).map_err(io(&json))?;
    let md = config.out_dir.join("throughput.md");
    std::fs::write(&md, markdown(&report)).map_err(io(&md))?;
    Ok(report)
}

/// The report as a Markdown table.
pub fn markdown(report: &Report) -> String {
    let mut s = format!(
        "`{}`\n\n{}x{}, {} spp, median of {} runs per binary (alternated); samples/s from the GPU time each binary \
         reports, CPU % of one core over the whole process{}.\n\n",
        report.command,
        report.width,
        report.height,
        report.spp,
        report.runs,
        report.reference_spp.map_or(String::new(), |n| format!("; errors against a {n}-spp reference of another seed"))
    );
    s += "| scene | binary | samples/s | GPU s | wall s | CPU % | speed-up | relMSE | FLIP | images |\n";
    s += "|---|---|---:|---:|---:|---:|---:|---:|---:|---|\n";
    let opt = |v: Option<f64>, digits: usize| v.map_or("–".to_string(), |v| format!("{v:.digits$}"));
    for sc in &report.scenes {
        for (i, b) in sc.binaries.iter().enumerate() {
            let is_new = i == 0;
            let images = match (is_new, sc.identical, sc.relative_mse_between) {
                (true, Some(true), _) => "identical".to_string(),
                (true, Some(false), Some(r)) => format!("differ (relMSE {r:.2e})"),
                _ => String::new(),
            };
            s += &format!(
                "| {} | {} | {:.0} | {:.2} | {:.2} | {:.0} | {} | {} | {} | {} |\n",
                sc.scene,
                b.binary,
                b.samples_per_second,
                b.gpu_seconds,
                b.wall_seconds,
                b.cpu_percent,
                if is_new { opt(sc.speedup, 2) } else { String::new() },
                opt(b.relative_mse, 5),
                opt(b.flip, 4),
                images
            );
        }
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn reads_the_seconds_of_a_render_line() {
        let err = "caustics: ...\nwrote x.png, x.exr (64x48, 1 spp, 0.52 s on llvmpipe (LLVM 15.0.6, 256 bits))\n";
        assert_eq!(reported_seconds(err), Some(0.52));
        assert_eq!(reported_seconds("nothing"), None);
    }

    #[test]
    fn medians() {
        assert_eq!(median(vec![3.0, 1.0, 2.0]), 2.0);
        assert_eq!(median(vec![4.0, 1.0, 2.0, 3.0]), 2.5);
    }
}
