//! The prefiltering benchmark (`quadray filter-bench`): the speed/accuracy
//! trade of the texture-filtering modes, measured against a brute-force
//! reference.
//!
//! For each scene:
//! 1. a reference: filtering `none` (bilinear lookups of mip 0) with many
//!    samples per pixel, cached on disk with the settings that made it and
//!    re-rendered only when they change;
//! 2. each mode (`none`, `ray-cones`, `covariance`) at 1, 2, 4, … samples per
//!    pixel, after an untimed warm-up (lavapipe compiles a shader variant at
//!    its first dispatch), timed on the GPU, with its FLIP and relative MSE
//!    against the reference;
//! 3. the headline: the time each mode takes to reach the FLIP error that
//!    `none` reaches at the largest measured spp (log-log interpolation
//!    between measured points), as a speed-up over `none`;
//! 4. temporal stability: a short camera pan rendered at low spp in every
//!    mode, and with the reference settings; the mean frame-to-frame change
//!    of each mode against the reference's (the change the motion itself
//!    causes).
//!
//! Outputs per scene, in the output folder: `<scene>.json`, `<scene>.md`,
//! `<scene>-flip.png` and `<scene>-relmse.png` (error against time, one curve
//! per mode), and the reference and a few renders as PNG; `summary.md` over
//! all scenes.

use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::geometry::CellParams;
use crate::metrics::{change_error, flip_mean, mean_display_change, relative_mse, MetricError};
use crate::output::{write_all_or_nothing, write_png};
use crate::passes::{render, GpuScene, RenderOutput, RenderVariant};
use crate::plot::{write_log_log_plot, HLine, PlotError, Series};
use crate::scene::{load_scene, Scene};
use crate::shader_interface::{FILTER_COVARIANCE, FILTER_NONE, FILTER_RAY_CONES, SHADING_FULL};
use crate::vk::{Commands, Context};
use crate::RenderError;

/// The filtering modes, by their CLI names.
pub const MODES: [(&str, u32); 3] =
    [("none", FILTER_NONE), ("ray-cones", FILTER_RAY_CONES), ("covariance", FILTER_COVARIANCE)];

/// What to measure.
#[derive(Clone, Debug)]
pub struct Config {
    /// Scene files.
    pub scenes: Vec<PathBuf>,
    /// Output folder (created if missing); the reference cache is `cache/` in it.
    pub out_dir: PathBuf,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Samples per pixel of the reference.
    pub reference_spp: u32,
    /// The modes run at 1, 2, 4, … up to this many samples per pixel.
    pub max_spp: u32,
    /// Frames of the temporal-stability pan (0: skip it).
    pub frames: u32,
    /// Samples per pixel of each mode's pan frames.
    pub frame_spp: u32,
    /// Samples per pixel of the reference pan frames.
    pub reference_frame_spp: u32,
    /// Camera motion per frame, as a fraction of the distance from the
    /// camera to its look-at point, along the camera's right vector.
    pub pan_step: f64,
    /// The render shader's shading: `SHADING_FULL` (the path tracer) or
    /// `SHADING_MIRRORED_ALBEDO` (texture transport alone: the albedo seen
    /// directly and through perfect mirrors, no lighting, no noise but the
    /// pixel's own).
    pub shading: u32,
    /// The command line, recorded in the reports.
    pub command: String,
}

/// Why the benchmark stopped.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A scene file could not be loaded.
    #[error("{0}")]
    Scene(#[from] crate::scene::SceneError),
    /// Rendering failed.
    #[error("render failed: {0}")]
    Render(#[from] RenderError),
    /// Vulkan failed outside a render.
    #[error("Vulkan: {0}")]
    Vk(#[from] crate::vk::VkError),
    /// Comparing images failed.
    #[error("metric: {0}")]
    Metric(#[from] MetricError),
    /// Writing a plot failed.
    #[error("plot {path}: {source}")]
    Plot {
        /// The plot's path.
        path: PathBuf,
        /// The cause.
        source: PlotError,
    },
    /// Reading or writing a file failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: std::io::Error,
    },
    /// A cached reference is unreadable.
    #[error("cached reference {0} is corrupt; delete it to re-render")]
    CorruptCache(PathBuf),
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> BenchError + '_ {
    move |source| BenchError::Io { path: path.to_path_buf(), source }
}

/// One measured render.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Run {
    /// Filtering mode.
    pub mode: String,
    /// Samples per pixel.
    pub spp: u32,
    /// GPU time in seconds.
    pub seconds: f64,
    /// Mean FLIP against the reference.
    pub flip: f64,
    /// Relative MSE against the reference.
    pub relative_mse: f64,
}

/// The time a mode takes to reach the target error.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Headline {
    /// Filtering mode.
    pub mode: String,
    /// Seconds to reach the target FLIP (None: not reached in the measured range).
    pub seconds_to_target: Option<f64>,
    /// `none`'s time at its largest spp over this mode's time to the target.
    pub speedup_over_none: Option<f64>,
    /// True when the mode's first (1-spp) render was already at or below the
    /// target: the time is then an upper bound (the speed-up a lower bound).
    pub reached_at_first_point: bool,
    /// The lowest FLIP this mode reached, and at what spp.
    pub best_flip: f64,
    /// The spp of `best_flip`.
    pub best_spp: u32,
}

/// Temporal stability of one mode.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Stability {
    /// Filtering mode (or "reference").
    pub mode: String,
    /// Samples per pixel per frame.
    pub spp: u32,
    /// Mean over consecutive frame pairs of the mean absolute change of the
    /// tone-mapped image (0..1 per channel).
    pub mean_change: f64,
    /// `mean_change` over the reference's.
    pub ratio_to_reference: f64,
    /// Mean over consecutive frame pairs of the change the reference's
    /// change does not explain ([`change_error`]): flicker and lost motion.
    pub change_error: f64,
}

/// Everything measured on one scene.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct SceneReport {
    /// Scene file.
    pub scene: String,
    /// The command that made this report.
    pub command: String,
    /// The Vulkan device.
    pub device: String,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Reference settings.
    pub reference: ReferenceInfo,
    /// The measured renders, by mode then spp.
    pub runs: Vec<Run>,
    /// The target: `none`'s FLIP at its largest spp.
    pub target_flip: f64,
    /// The spp of the target.
    pub target_spp: u32,
    /// `none`'s time at the target spp.
    pub target_seconds: f64,
    /// Time to the target per mode.
    pub headline: Vec<Headline>,
    /// Temporal stability (empty when skipped).
    pub stability: Vec<Stability>,
}

/// How a reference image was made (the cache key, compared field by field).
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ReferenceInfo {
    /// FNV-1a hash of the scene file's text.
    pub scene_hash: String,
    /// Image size.
    pub width: u32,
    /// Image size.
    pub height: u32,
    /// Samples per pixel.
    pub spp: u32,
    /// Random seed.
    pub seed: u32,
    /// Camera offset along its right vector (temporal frames), scene units.
    pub camera_offset: f64,
    /// The shading variant (`SHADING_*`).
    #[serde(default)]
    pub shading: u32,
    /// Renderer version.
    pub version: String,
    /// Seconds it took (not part of the key).
    #[serde(default)]
    pub seconds: f64,
}

impl ReferenceInfo {
    fn same_settings(&self, other: &Self) -> bool {
        Self { seconds: 0.0, ..self.clone() } == Self { seconds: 0.0, ..other.clone() }
    }
}

/// FNV-1a (64 bit) of `bytes`, in hex: a stable cache key.
pub fn fnv1a_hex(bytes: &[u8]) -> String {
    let hash = bytes.iter().fold(0xcbf2_9ce4_8422_2325u64, |h, &b| (h ^ u64::from(b)).wrapping_mul(0x0100_0000_01b3));
    format!("{hash:016x}")
}

/// The time at which a curve of (seconds, error) points, in the order of
/// increasing effort, first reaches `target`: log-log interpolation between
/// the last point above and the first at or below it; the first point's time
/// when it is already below; `None` when no point reaches it.
pub fn time_to_reach(points: &[(f64, f64)], target: f64) -> Option<f64> {
    let first = points.iter().position(|&(_, e)| e <= target)?;
    if first == 0 {
        return Some(points[0].0);
    }
    let ((t0, e0), (t1, e1)) = (points[first - 1], points[first]);
    if e0 <= 0.0 || e1 <= 0.0 || t0 <= 0.0 || t1 <= 0.0 || e0 == e1 {
        return Some(t1);
    }
    let s = (target.ln() - e0.ln()) / (e1.ln() - e0.ln());
    Some((t0.ln() + s * (t1.ln() - t0.ln())).exp())
}

/// The spp ladder 1, 2, 4, … up to `max` (with `max` itself last).
pub fn spp_ladder(max: u32) -> Vec<u32> {
    let mut v: Vec<u32> = std::iter::successors(Some(1u32), |&s| s.checked_mul(2)).take_while(|&s| s < max).collect();
    v.push(max.max(1));
    v
}

/// Runs the benchmark over every scene; prints progress on stderr.
pub fn run(ctx: &Context, config: &Config) -> Result<Vec<SceneReport>, BenchError> {
    std::fs::create_dir_all(&config.out_dir).map_err(io_error(&config.out_dir))?;
    let mut reports = Vec::new();
    for path in &config.scenes {
        let report = bench_scene(ctx, config, path)?;
        reports.push(report);
    }
    let summary = config.out_dir.join("summary.md");
    let text = summary_markdown(config, &reports);
    write_all_or_nothing(std::slice::from_ref(&summary), |_, p| std::fs::write(p, &text))
        .map_err(io_error(&summary))?;
    eprintln!("wrote {}", summary.display());
    Ok(reports)
}

/// The renderer state shared by a scene's renders.
struct Bench<'a> {
    ctx: &'a Context,
    cmds: Commands,
    gpu: GpuScene,
    scene: Scene,
    size: (u32, u32),
    shading: u32,
}

impl Bench<'_> {
    /// Renders with `filter` at `spp`, the camera moved by `offset` along its
    /// right vector.
    fn render(&mut self, filter: u32, spp: u32, seed: u32, offset: f64) -> Result<RenderOutput, BenchError> {
        let mut scene = self.scene.clone();
        scene.image.seed = seed;
        let c = &mut scene.camera;
        let right = (c.look_at - c.position).cross(c.up).normalize_or(DVec3::X);
        c.position += right * offset;
        c.look_at += right * offset;
        let (w, h) = self.size;
        let variant = self.variant(filter);
        Ok(render(&self.ctx.device, &mut self.cmds, &self.gpu, &scene, (w, h, spp), variant, &mut |_, _| {})?)
    }

    /// The render shader variant of `filter` with the bench's shading.
    fn variant(&self, filter: u32) -> RenderVariant {
        RenderVariant { filter, shading: self.shading, ..Default::default() }
    }

    /// An untimed 8x8 render that makes lavapipe compile `filter`'s shader
    /// variant (it does so at the first dispatch) before the timed renders.
    fn warm_up(&mut self, filter: u32) -> Result<(), BenchError> {
        let variant = self.variant(filter);
        render(&self.ctx.device, &mut self.cmds, &self.gpu, &self.scene, (8, 8, 1), variant, &mut |_, _| {})?;
        Ok(())
    }
}

fn stem_of(path: &Path) -> String {
    path.file_stem().map_or_else(|| "scene".into(), |s| s.to_string_lossy().into_owned())
}

fn bench_scene(ctx: &Context, config: &Config, path: &Path) -> Result<SceneReport, BenchError> {
    let scene = load_scene(path)?;
    let text = std::fs::read(path).map_err(io_error(path))?;
    let hash = fnv1a_hex(&text);
    let stem = stem_of(path);
    let exposure = scene.image.exposure;
    let mut cmds = Commands::new(&ctx.device)?;
    let gpu = GpuScene::with_origin(&ctx.device, &mut cmds, &scene, &CellParams::default(), scene.camera.position)?;
    let size = (config.width, config.height);
    let mut bench = Bench { ctx, cmds, gpu, scene, size, shading: config.shading };
    let seed = bench.scene.image.seed;
    let cache = config.out_dir.join("cache");
    if config.shading != SHADING_FULL {
        eprintln!("{stem}: shading variant {}: texture transport alone, no lighting", config.shading);
    }
    std::fs::create_dir_all(&cache).map_err(io_error(&cache))?;

    let key = |spp: u32, offset: f64| ReferenceInfo {
        scene_hash: hash.clone(),
        width: config.width,
        height: config.height,
        spp,
        seed,
        camera_offset: offset,
        shading: config.shading,
        version: env!("CARGO_PKG_VERSION").into(),
        seconds: 0.0,
    };
    let (reference, reference_info) = cached_reference(
        &mut bench,
        &cache.join(format!("{stem}-s{}-reference", config.shading)),
        key(config.reference_spp, 0.0),
    )?;
    let png = config.out_dir.join(format!("{stem}-reference.png"));
    write_png(&reference, exposure, &png).map_err(io_error(&png))?;

    let ladder = spp_ladder(config.max_spp);
    let mut runs = Vec::new();
    for (name, filter) in MODES {
        eprintln!("{stem}: {name}: warming up");
        bench.warm_up(filter)?;
        for (k, &spp) in ladder.iter().enumerate() {
            // A different seed per render: independent noise.
            let out = bench.render(filter, spp, seed.wrapping_add(1 + k as u32), 0.0)?;
            let run = Run {
                mode: name.into(),
                spp,
                seconds: out.seconds,
                flip: flip_mean(&reference, &out, exposure)?,
                relative_mse: relative_mse(&reference, &out)?,
            };
            eprintln!(
                "{stem}: {name:>10} {spp:>5} spp {:>9.3} s  FLIP {:.4}  rel MSE {:.4}",
                run.seconds, run.flip, run.relative_mse
            );
            if k == 0 || spp == config.max_spp {
                let png = config.out_dir.join(format!("{stem}-{name}-{spp}spp.png"));
                write_png(&out, exposure, &png).map_err(io_error(&png))?;
            }
            runs.push(run);
        }
    }

    let none_runs: Vec<&Run> = runs.iter().filter(|r| r.mode == "none").collect();
    let target = none_runs.last().expect("the none mode runs");
    let (target_flip, target_spp, target_seconds) = (target.flip, target.spp, target.seconds);
    let headline = MODES
        .iter()
        .map(|(name, _)| {
            let mine: Vec<&Run> = runs.iter().filter(|r| r.mode == *name).collect();
            let points: Vec<(f64, f64)> = mine.iter().map(|r| (r.seconds, r.flip)).collect();
            let t = time_to_reach(&points, target_flip);
            let best = mine.iter().min_by(|a, b| a.flip.total_cmp(&b.flip)).expect("runs");
            Headline {
                mode: name.to_string(),
                reached_at_first_point: points.first().is_some_and(|&(_, e)| e <= target_flip),
                seconds_to_target: t,
                speedup_over_none: t.map(|t| target_seconds / t),
                best_flip: best.flip,
                best_spp: best.spp,
            }
        })
        .collect();

    let stability =
        if config.frames >= 2 { temporal_stability(&mut bench, config, &stem, &cache, &key)? } else { vec![] };

    let report = SceneReport {
        scene: path.display().to_string(),
        command: config.command.clone(),
        device: ctx.device.name.clone(),
        width: config.width,
        height: config.height,
        reference: reference_info,
        runs,
        target_flip,
        target_spp,
        target_seconds,
        headline,
        stability,
    };
    write_scene_outputs(config, &stem, &report)?;
    Ok(report)
}

/// The pan's frames: camera offsets k · step · distance, k = 0..frames.
fn pan_offsets(scene: &Scene, config: &Config) -> Vec<f64> {
    let distance = (scene.camera.look_at - scene.camera.position).length();
    (0..config.frames).map(|k| k as f64 * config.pan_step * distance).collect()
}

fn temporal_stability(
    bench: &mut Bench<'_>,
    config: &Config,
    stem: &str,
    cache: &Path,
    key: &dyn Fn(u32, f64) -> ReferenceInfo,
) -> Result<Vec<Stability>, BenchError> {
    let exposure = bench.scene.image.exposure;
    let offsets = pan_offsets(&bench.scene, config);
    let mean_change = |frames: &[RenderOutput]| -> Result<f64, BenchError> {
        let mut sum = 0.0;
        for pair in frames.windows(2) {
            sum += mean_display_change(&pair[0], &pair[1], exposure)?;
        }
        Ok(sum / (frames.len() - 1) as f64)
    };
    let mut reference_frames = Vec::new();
    for (k, &offset) in offsets.iter().enumerate() {
        let path = cache.join(format!("{stem}-s{}-pan{k}", config.shading));
        reference_frames.push(cached_reference(bench, &path, key(config.reference_frame_spp, offset))?.0);
    }
    let reference_change = mean_change(&reference_frames)?;
    let mut rows = vec![Stability {
        mode: "reference".into(),
        spp: config.reference_frame_spp,
        mean_change: reference_change,
        ratio_to_reference: 1.0,
        change_error: 0.0,
    }];
    let seed = bench.scene.image.seed;
    for (name, filter) in MODES {
        let mut frames = Vec::new();
        for &offset in &offsets {
            // The same seed every frame, as a viewer re-rendering a moving
            // camera would use.
            frames.push(bench.render(filter, config.frame_spp, seed, offset)?);
        }
        let change = mean_change(&frames)?;
        let mut error = 0.0;
        for k in 1..frames.len() {
            let (a, b) = (&frames[k - 1], &frames[k]);
            error += change_error(a, b, &reference_frames[k - 1], &reference_frames[k], exposure)?;
        }
        error /= (frames.len() - 1) as f64;
        eprintln!(
            "{stem}: pan, {name:>10} {} spp: mean change {change:.4} (reference {reference_change:.4}), change error \
             {error:.4}",
            config.frame_spp
        );
        rows.push(Stability {
            mode: name.into(),
            spp: config.frame_spp,
            mean_change: change,
            ratio_to_reference: change / reference_change.max(1e-12),
            change_error: error,
        });
    }
    Ok(rows)
}

/// The reference for `info`, from `<base>.json` + `<base>.f32` when their
/// settings match, else rendered (filtering `none`) and stored there.
fn cached_reference(
    bench: &mut Bench<'_>,
    base: &Path,
    info: ReferenceInfo,
) -> Result<(RenderOutput, ReferenceInfo), BenchError> {
    let json_path = base.with_extension("json");
    let data_path = base.with_extension("f32");
    if let Ok(text) = std::fs::read_to_string(&json_path) {
        if let Ok(stored) = serde_json::from_str::<ReferenceInfo>(&text) {
            if stored.same_settings(&info) {
                let bytes = std::fs::read(&data_path).map_err(io_error(&data_path))?;
                let n = (info.width * info.height) as usize;
                if bytes.len() != n * 12 {
                    return Err(BenchError::CorruptCache(data_path));
                }
                let floats: Vec<f32> =
                    bytes.chunks_exact(4).map(|c| f32::from_le_bytes([c[0], c[1], c[2], c[3]])).collect();
                let radiance = floats.chunks_exact(3).map(|c| [c[0], c[1], c[2]]).collect();
                eprintln!("{}: cached reference ({} spp)", base.display(), info.spp);
                let mut out = RenderOutput::from_radiance(info.width, info.height, radiance);
                out.spp = info.spp;
                out.seconds = stored.seconds;
                out.render_seconds = stored.seconds;
                return Ok((out, stored));
            }
        }
    }
    eprintln!("{}: rendering the reference ({} spp, filtering none)...", base.display(), info.spp);
    let out = bench.render(FILTER_NONE, info.spp, info.seed, info.camera_offset)?;
    eprintln!("{}: reference took {:.1} s", base.display(), out.seconds);
    let stored = ReferenceInfo { seconds: out.seconds, ..info };
    let bytes: Vec<u8> = out.radiance.iter().flatten().flat_map(|v| v.to_le_bytes()).collect();
    let json = serde_json::to_string_pretty(&stored).expect("serialisable");
    write_all_or_nothing(&[data_path.clone(), json_path], |i, p| {
        if i == 0 {
            std::fs::write(p, &bytes)
        } else {
            std::fs::write(p, &json)
        }
    })
    .map_err(io_error(&data_path))?;
    Ok((out, stored))
}

fn write_scene_outputs(config: &Config, stem: &str, report: &SceneReport) -> Result<(), BenchError> {
    let json_path = config.out_dir.join(format!("{stem}.json"));
    let json = serde_json::to_string_pretty(report).expect("serialisable");
    let md_path = config.out_dir.join(format!("{stem}.md"));
    let md = scene_markdown(report);
    write_all_or_nothing(&[json_path.clone(), md_path], |i, p| std::fs::write(p, if i == 0 { &json } else { &md }))
        .map_err(io_error(&json_path))?;
    for (metric, label, value) in [
        ("flip", "mean FLIP", (|r: &Run| r.flip) as fn(&Run) -> f64),
        ("relmse", "relative MSE", |r: &Run| r.relative_mse),
    ] {
        let series: Vec<Series> = MODES
            .iter()
            .map(|(name, _)| Series {
                label: name.to_string(),
                points: report.runs.iter().filter(|r| r.mode == *name).map(|r| (r.seconds, value(r))).collect(),
            })
            .collect();
        let none_last = report.runs.iter().rfind(|r| r.mode == "none").expect("none runs");
        let hline = HLine { label: format!("none @ {} spp", report.target_spp), y: value(none_last) };
        let path = config.out_dir.join(format!("{stem}-{metric}.png"));
        let title = format!("{stem}: {label} against GPU time ({}x{})", report.width, report.height);
        write_log_log_plot(&path, &title, "GPU seconds", label, &series, &[hline])
            .map_err(|source| BenchError::Plot { path: path.clone(), source })?;
    }
    eprintln!("wrote {}/{stem}.{{json,md}} and {stem}-{{flip,relmse}}.png", config.out_dir.display());
    Ok(())
}

fn fmt_opt(v: Option<f64>, digits: usize) -> String {
    v.map_or_else(|| "not reached".into(), |v| format!("{v:.digits$}"))
}

/// The Markdown report of one scene.
pub fn scene_markdown(r: &SceneReport) -> String {
    let mut s = String::new();
    let _ = writeln!(s, "## {}\n", r.scene);
    let _ = writeln!(
        s,
        "{}x{} on {}; reference: filtering `none`, {} spp ({:.1} s). Command: `{}`\n",
        r.width, r.height, r.device, r.reference.spp, r.reference.seconds, r.command
    );
    let _ = writeln!(s, "| mode | spp | seconds | FLIP mean | relative MSE |\n|---|---:|---:|---:|---:|");
    for run in &r.runs {
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {:.4} | {:.4} |",
            run.mode, run.spp, run.seconds, run.flip, run.relative_mse
        );
    }
    let _ = writeln!(
        s,
        "\nTarget: the FLIP of `none` at {} spp, {:.4} ({:.3} s). Time to reach it: log-log interpolation between the \
         measured points (≤: already reached at 1 spp, an upper bound).\n",
        r.target_spp, r.target_flip, r.target_seconds
    );
    let _ = writeln!(s, "| mode | seconds to target | speed-up over none | best FLIP (spp) |\n|---|---:|---:|---:|");
    for h in &r.headline {
        let (le, ge) = if h.reached_at_first_point { ("≤ ", "≥ ") } else { ("", "") };
        let _ = writeln!(
            s,
            "| {} | {le}{} | {ge}{} | {:.4} ({}) |",
            h.mode,
            fmt_opt(h.seconds_to_target, 3),
            fmt_opt(h.speedup_over_none, 2),
            h.best_flip,
            h.best_spp
        );
    }
    if !r.stability.is_empty() {
        let _ = writeln!(
            s,
            "\nTemporal stability (camera pan): mean frame-to-frame change of the displayed image, its ratio to \
             the reference's, and the change error (the part of the change that the reference's change does not \
             explain: flicker and lost motion; 0 is ideal):\n\n| mode | spp | mean change | ratio to reference | \
             change error |\n|---|---:|---:|---:|---:|"
        );
        for st in &r.stability {
            let _ = writeln!(
                s,
                "| {} | {} | {:.4} | {:.2} | {:.4} |",
                st.mode, st.spp, st.mean_change, st.ratio_to_reference, st.change_error
            );
        }
    }
    s
}

fn summary_markdown(config: &Config, reports: &[SceneReport]) -> String {
    let mut s = String::from("# Prefiltering benchmark\n\n");
    let _ = writeln!(s, "Made by `{}`.\n", config.command);
    let _ = writeln!(
        s,
        "Headline: time to reach the FLIP error of `none` at its largest spp, as a speed-up over `none` (above 1: faster).\n"
    );
    let _ = writeln!(s, "| scene | none | ray-cones | covariance |\n|---|---:|---:|---:|");
    for r in reports {
        let cell = |mode: &str| {
            r.headline.iter().find(|h| h.mode == mode).map_or_else(|| "-".into(), |h| fmt_opt(h.speedup_over_none, 2))
        };
        let _ = writeln!(s, "| {} | {} | {} | {} |", r.scene, cell("none"), cell("ray-cones"), cell("covariance"));
    }
    s.push('\n');
    for r in reports {
        s.push_str(&scene_markdown(r));
        s.push('\n');
    }
    s
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ladder_doubles_up_to_the_maximum() {
        assert_eq!(spp_ladder(64), vec![1, 2, 4, 8, 16, 32, 64]);
        assert_eq!(spp_ladder(48), vec![1, 2, 4, 8, 16, 32, 48]);
        assert_eq!(spp_ladder(1), vec![1]);
    }

    #[test]
    fn time_to_reach_interpolates_in_log_log() {
        // error = 1 / √t: reaching 0.25 takes t = 16.
        let points: Vec<(f64, f64)> = [1.0, 4.0, 64.0].iter().map(|&t: &f64| (t, 1.0 / t.sqrt())).collect();
        assert!((time_to_reach(&points, 0.25).unwrap() - 16.0).abs() < 1e-9);
        assert_eq!(time_to_reach(&points, 2.0), Some(1.0));
        assert_eq!(time_to_reach(&points, 0.01), None);
    }

    #[test]
    fn fnv_is_stable() {
        assert_eq!(fnv1a_hex(b""), "cbf29ce484222325");
        assert_eq!(fnv1a_hex(b"a"), "af63dc4c8601ec8c");
    }

    #[test]
    fn cache_key_ignores_the_time_taken() {
        let a = ReferenceInfo {
            scene_hash: "x".into(),
            width: 2,
            height: 2,
            spp: 4,
            seed: 0,
            camera_offset: 0.0,
            shading: 0,
            version: "1".into(),
            seconds: 3.0,
        };
        assert!(a.same_settings(&ReferenceInfo { seconds: 9.0, ..a.clone() }));
        assert!(!a.same_settings(&ReferenceInfo { spp: 8, ..a.clone() }));
    }
}
