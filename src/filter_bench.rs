//! The prefiltering benchmark (`quadray filter-bench`): the speed/accuracy
//! trade of the texture-filtering modes, measured against a brute-force
//! reference, as time to equal quality.
//!
//! For each scene:
//! 1. a reference: filtering `none` (bilinear lookups of mip 0) with many
//!    samples per pixel, rendered as two halves with different seeds, so that
//!    its own noise is known per pixel (a quarter of the halves' squared
//!    difference) and subtracted from every error; cached on disk with the
//!    settings that made it;
//! 2. each mode (`none`, `ray-cones`, `covariance`) at 1, 2, 4, … samples per
//!    pixel, `seeds` independent renders per point, after an untimed warm-up
//!    (lavapipe compiles a shader variant at its first dispatch), timed on
//!    the GPU. The error is the relative MSE of the linear radiance against
//!    the reference (its noise subtracted), split into variance (across the
//!    seeds) and bias² (the rest); FLIP is the secondary figure;
//! 3. the texture share at each target spp: 1 − (the error of `none` with
//!    every map replaced by its mean) / (the error of `none`), both measured
//!    as variance across the seeds and relative to the textured reference;
//!    and a texture mask: the pixels where the maps more than double the
//!    variance of `none`;
//! 4. the headline per target (`none`'s error at 16, 64, … spp): the time each
//!    mode takes to reach an error at most the target's with bias² at most
//!    a quarter of it (log-log interpolation between measured points), as a
//!    speed-up over `none`; over the whole image and over the mask; and the
//!    cost per sample of each mode over `none`'s;
//! 5. temporal stability: a short camera pan rendered at low spp in every
//!    mode, and with the reference settings; the mean frame-to-frame change
//!    of each mode against the reference's (the change the motion itself
//!    causes).
//!
//! Outputs per scene, in the output folder: `<scene>.json`, `<scene>.md`,
//! `<scene>-relmse.png`, `<scene>-relmse-mask.png` and `<scene>-flip.png`
//! (error against time, one curve per mode, the targets as lines), and the
//! reference and a few renders as PNG; over all scenes `summary.md` and
//! `headline.json` (entries of scenes measured before are kept).

use std::collections::BTreeMap;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

use glam::DVec3;
use serde::{Deserialize, Serialize};

use crate::geometry::CellParams;
use crate::metrics::{change_error, flip_mean, mean_display_change, MetricError, RELATIVE_MSE_EPSILON};
use crate::output::{write_all_or_nothing, write_png};
use crate::passes::render::PIXEL_FILTER_SIGMA;
use crate::passes::{render, GpuScene, RenderOutput, RenderVariant};
use crate::plot::{write_log_log_plot, HLine, PlotError, Series};
use crate::scene::{load_scene, Scene};
use crate::shader_interface::{FILTER_COVARIANCE, FILTER_NONE, FILTER_RAY_CONES, LOOKUP_PROBES, SHADING_FULL};
use crate::vk::{Commands, Context};
use crate::RenderError;

/// The filtering modes, by their CLI names.
pub const MODES: [(&str, u32); 3] =
    [("none", FILTER_NONE), ("ray-cones", FILTER_RAY_CONES), ("covariance", FILTER_COVARIANCE)];

/// "Equal quality": error at most the target's and bias² at most this
/// fraction of it.
pub const MAX_BIAS_SHARE: f64 = 0.25;

/// A pixel is in the texture mask when the maps multiply `none`'s variance
/// there (3 x 3 box-averaged) by more than this.
pub const MASK_VARIANCE_RATIO: f64 = 2.0;

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
    /// Samples per pixel of the reference (two halves of half as many).
    pub reference_spp: u32,
    /// The modes run at 1, 2, 4, … up to this many samples per pixel.
    pub max_spp: u32,
    /// Independent renders (seeds) per measured point (at least 2).
    pub seeds: u32,
    /// Target spp of `none` (those up to `max_spp` are used).
    pub targets: Vec<u32>,
    /// Frames of the temporal-stability pan (0: skip it).
    pub frames: u32,
    /// Samples per pixel of each mode's pan frames.
    pub frame_spp: u32,
    /// Samples per pixel of the reference pan frames.
    pub reference_frame_spp: u32,
    /// Camera motion per frame, as a fraction of the distance from the
    /// camera to its look-at point, along the camera's right vector.
    pub pan_step: f64,
    /// The render shader's shading: `SHADING_FULL` (the path tracer),
    /// `SHADING_MIRRORED_ALBEDO` (the albedo seen directly and through
    /// perfect mirrors) or `SHADING_GLOSSY_ALBEDO` (also through glossy
    /// reflections and refractions); the albedo modes have no lighting.
    pub shading: u32,
    /// The filtered modes' lookup: `LOOKUP_PROBES` or `LOOKUP_EWA`.
    pub lookup: u32,
    /// The command line, recorded in the reports.
    pub command: String,
}

impl Default for Config {
    fn default() -> Self {
        Self {
            scenes: vec![],
            out_dir: PathBuf::from("results/filtering"),
            width: 256,
            height: 192,
            reference_spp: 2048,
            max_spp: 64,
            seeds: 8,
            targets: vec![16, 64],
            frames: 6,
            frame_spp: 4,
            reference_frame_spp: 256,
            pan_step: 0.004,
            shading: SHADING_FULL,
            lookup: LOOKUP_PROBES,
            command: String::new(),
        }
    }
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
    /// The settings cannot measure what they should.
    #[error("{0}")]
    Settings(String),
}

fn io_error(path: &Path) -> impl FnOnce(std::io::Error) -> BenchError + '_ {
    move |source| BenchError::Io { path: path.to_path_buf(), source }
}

/// Error statistics of one mode at one spp over the seeds, relative to the
/// reference (relative MSE: per pixel and channel over ref² + ε), with the
/// reference's own noise subtracted.
#[derive(Clone, Copy, Debug, Default, Serialize, Deserialize, PartialEq)]
pub struct ErrorStats {
    /// Mean over the seeds of one render's relative MSE: bias² + variance.
    pub error: f64,
    /// The part that does not average away over seeds (may be slightly
    /// negative: an unbiased estimate of a small number).
    pub bias2: f64,
    /// The variance of one render, across the seeds.
    pub variance: f64,
}

/// One measured point: a mode at one spp, over `seeds` renders.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Point {
    /// Filtering mode.
    pub mode: String,
    /// Samples per pixel.
    pub spp: u32,
    /// Mean GPU time of one render, seconds.
    pub seconds: f64,
    /// Over the whole image.
    pub whole: ErrorStats,
    /// Over the texture mask.
    pub masked: ErrorStats,
    /// Mean FLIP of one render against the reference.
    pub flip: f64,
}

/// Time to one target, per mode.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct ModeTime {
    /// Filtering mode.
    pub mode: String,
    /// Seconds to reach the target at equal quality (None: not reached).
    pub seconds_to_target: Option<f64>,
    /// `none`'s time at the target over this mode's time to it.
    pub speedup_over_none: Option<f64>,
    /// True when already reached at the first (1-spp) point: the time is an
    /// upper bound and the speed-up a lower bound.
    pub reached_at_first_point: bool,
}

/// One target: `none`'s error at `spp`.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct Target {
    /// `none@<spp>`.
    pub name: String,
    /// `none`'s spp.
    pub spp: u32,
    /// Over the texture mask (else the whole image).
    pub masked: bool,
    /// `none`'s error there.
    pub error: f64,
    /// `none`'s GPU time there.
    pub seconds: f64,
    /// The texture share at this spp (whole image).
    pub texture_share: f64,
    /// Per mode.
    pub modes: Vec<ModeTime>,
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
    /// Renders per point.
    pub seeds: u32,
    /// The pixel filter's σ in pixels (a Gaussian, every mode).
    pub pixel_sigma: f32,
    /// Reference settings (of its first half).
    pub reference: ReferenceInfo,
    /// The reference's own relative variance (subtracted from every error).
    pub reference_variance: f64,
    /// Share of the pixels in the texture mask.
    pub mask_fraction: f64,
    /// The measured points, by mode then spp.
    pub points: Vec<Point>,
    /// The targets, whole image then masked.
    pub targets: Vec<Target>,
    /// GPU time per sample of each mode over `none`'s (all points).
    pub cost_per_sample: BTreeMap<String, f64>,
    /// Temporal stability (empty when skipped).
    pub stability: Vec<Stability>,
}

/// One entry of `headline.json`: a scene and a target.
#[derive(Clone, Debug, Serialize, Deserialize, PartialEq)]
pub struct HeadlineEntry {
    /// Scene file.
    pub scene: String,
    /// 1 − MSE(maps replaced by their means) / MSE(none) at the target spp.
    pub texture_share: f64,
    /// `none@<spp>`.
    pub target: String,
    /// Time-to-quality speed-up over `none` (whole image; null: not reached).
    pub speedup_vs_none: BTreeMap<String, Option<f64>>,
    /// The same over the texture mask.
    pub speedup_vs_none_masked: BTreeMap<String, Option<f64>>,
    /// True where the mode reached the target at its first (1-spp) point:
    /// its speed-up is then a lower bound (whole image).
    pub speedup_is_lower_bound: BTreeMap<String, bool>,
    /// GPU time per sample over `none`'s.
    pub cost_per_sample: BTreeMap<String, f64>,
    /// Whether the scene counts for the headline (texture share ≥ 0.9).
    pub counts: bool,
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
    /// The pixel filter's σ (0 in caches made with the old box filter).
    #[serde(default)]
    pub pixel_sigma: f32,
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
    format!("{:016x}", crate::hash::Fnv1a::of(bytes))
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

/// Runs the benchmark over every scene; prints progress on stderr. Writes
/// `summary.md` over these scenes and merges their entries into
/// `headline.json` (entries of other scenes are kept).
pub fn run(ctx: &Context, config: &Config) -> Result<Vec<SceneReport>, BenchError> {
    if config.seeds < 2 {
        return Err(BenchError::Settings("--seeds must be at least 2 (variance is measured across seeds)".into()));
    }
    if config.reference_spp < 2 {
        return Err(BenchError::Settings("--reference-spp must be at least 2 (two halves)".into()));
    }
    std::fs::create_dir_all(&config.out_dir).map_err(io_error(&config.out_dir))?;
    let mut reports = Vec::new();
    for path in &config.scenes {
        let report = bench_scene(ctx, config, path)?;
        reports.push(report);
    }
    write_summaries(config, &reports)?;
    Ok(reports)
}

/// Reads the reports that earlier runs wrote for `config.scenes`
/// (`OUT/<scene>.json`) and writes `summary.md` and `headline.json` over
/// them, rendering nothing: a summary over scenes measured in separate runs.
pub fn summarize(config: &Config) -> Result<Vec<SceneReport>, BenchError> {
    let mut reports = Vec::new();
    for path in &config.scenes {
        let json = config.out_dir.join(format!("{}.json", stem_of(path)));
        let text = std::fs::read_to_string(&json).map_err(io_error(&json))?;
        let report: SceneReport = serde_json::from_str(&text)
            .map_err(|e| BenchError::Settings(format!("{}: not a report of this version: {e}", json.display())))?;
        reports.push(report);
    }
    write_summaries(config, &reports)?;
    Ok(reports)
}

/// Writes `summary.md` over `reports` and merges their entries into
/// `headline.json`.
fn write_summaries(config: &Config, reports: &[SceneReport]) -> Result<(), BenchError> {
    let summary = config.out_dir.join("summary.md");
    let text = summary_markdown(config, reports);
    write_all_or_nothing(std::slice::from_ref(&summary), |_, p| std::fs::write(p, &text))
        .map_err(io_error(&summary))?;
    let headline_path = config.out_dir.join("headline.json");
    let mut entries: Vec<HeadlineEntry> =
        std::fs::read_to_string(&headline_path).ok().and_then(|t| serde_json::from_str(&t).ok()).unwrap_or_default();
    entries.retain(|e| !reports.iter().any(|r| r.scene == e.scene));
    entries.extend(reports.iter().flat_map(headline_entries));
    let json = serde_json::to_string_pretty(&entries).expect("serialisable");
    write_all_or_nothing(std::slice::from_ref(&headline_path), |_, p| std::fs::write(p, &json))
        .map_err(io_error(&headline_path))?;
    eprintln!("wrote {} and {}", summary.display(), headline_path.display());
    Ok(())
}

/// The `headline.json` entries of one scene: one per target.
pub fn headline_entries(r: &SceneReport) -> Vec<HeadlineEntry> {
    let per_mode = |t: &Target| -> BTreeMap<String, Option<f64>> {
        t.modes.iter().filter(|m| m.mode != "none").map(|m| (m.mode.clone(), m.speedup_over_none)).collect()
    };
    r.targets
        .iter()
        .filter(|t| !t.masked)
        .map(|t| {
            let masked = r.targets.iter().find(|m| m.masked && m.spp == t.spp);
            HeadlineEntry {
                scene: r.scene.clone(),
                texture_share: t.texture_share,
                target: t.name.clone(),
                speedup_vs_none: per_mode(t),
                speedup_is_lower_bound: t
                    .modes
                    .iter()
                    .filter(|m| m.mode != "none")
                    .map(|m| (m.mode.clone(), m.reached_at_first_point))
                    .collect(),
                speedup_vs_none_masked: masked.map(per_mode).unwrap_or_default(),
                cost_per_sample: r
                    .cost_per_sample
                    .iter()
                    .filter(|(k, _)| *k != "none")
                    .map(|(k, v)| (k.clone(), *v))
                    .collect(),
                counts: t.texture_share >= 0.9,
            }
        })
        .collect()
}

/// The renderer state shared by a scene's renders.
struct Bench<'a> {
    ctx: &'a Context,
    cmds: Commands,
    gpu: GpuScene,
    scene: Scene,
    size: (u32, u32),
    shading: u32,
    lookup: u32,
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

    /// Uploads `scene` in place of the bench's scene, and returns that one.
    fn replace_scene(&mut self, scene: Scene) -> Result<Scene, BenchError> {
        let origin = scene.camera.position;
        self.gpu = GpuScene::with_origin(&self.ctx.device, &mut self.cmds, &scene, &CellParams::default(), origin)?;
        Ok(std::mem::replace(&mut self.scene, scene))
    }

    /// The render shader variant of `filter` with the bench's shading and lookup.
    fn variant(&self, filter: u32) -> RenderVariant {
        RenderVariant { filter, shading: self.shading, lookup: self.lookup, ..Default::default() }
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

/// `scene` with every texture map replaced by its mean: albedo and
/// roughness maps by their mean texel (the coarsest mip level), normal and
/// displacement maps by a flat surface. What `none` renders then is the
/// lighting's own noise, without the textures' detail.
pub fn with_mean_maps(scene: &Scene) -> Scene {
    let mut s = scene.clone();
    let mean = |t: usize| -> [f32; 4] {
        let tex = &scene.textures[t];
        tex.levels.last().and_then(|l| l.first()).copied().unwrap_or([1.0; 4])
    };
    for m in &mut s.materials {
        if let Some(t) = m.maps.albedo.take() {
            let c = mean(t);
            m.albedo *= glam::Vec3::new(c[0], c[1], c[2]);
        }
        if let Some(t) = m.maps.roughness.take() {
            let r = mean(t)[0].clamp(0.0, 1.0);
            match &mut m.kind {
                crate::scene::MaterialKind::Conductor { roughness, .. }
                | crate::scene::MaterialKind::Dielectric { roughness, .. } => *roughness = r,
                _ => {}
            }
        }
        m.maps.normal = None;
        m.maps.displacement = None;
    }
    s
}

/// Per-pixel, per-channel sums over the seeds of one point.
struct Accumulation {
    sum: Vec<f64>,
    sum_sq: Vec<f64>,
    count: u32,
    seconds: f64,
    flip: f64,
}

impl Accumulation {
    fn new(n: usize) -> Self {
        Self { sum: vec![0.0; 3 * n], sum_sq: vec![0.0; 3 * n], count: 0, seconds: 0.0, flip: 0.0 }
    }

    fn add(&mut self, out: &RenderOutput) {
        for (k, v) in out.radiance.iter().flatten().enumerate() {
            let v = f64::from(*v);
            self.sum[k] += v;
            self.sum_sq[k] += v * v;
        }
        self.count += 1;
        self.seconds += out.seconds;
    }

    /// The unbiased variance of one render at value index k.
    fn variance(&self, k: usize) -> f64 {
        let n = f64::from(self.count);
        let mean = self.sum[k] / n;
        ((self.sum_sq[k] - n * mean * mean) / (n - 1.0)).max(0.0)
    }
}

/// The reference: the mean of two halves, and its variance per value.
struct Reference {
    image: RenderOutput,
    values: Vec<f64>,
    variance: Vec<f64>,
}

impl Reference {
    fn new(a: &RenderOutput, b: &RenderOutput) -> Self {
        let values: Vec<f64> =
            a.radiance.iter().flatten().zip(b.radiance.iter().flatten()).map(|(x, y)| 0.5 * f64::from(x + y)).collect();
        let variance = a
            .radiance
            .iter()
            .flatten()
            .zip(b.radiance.iter().flatten())
            .map(|(x, y)| 0.25 * f64::from(x - y).powi(2))
            .collect();
        let radiance = values.chunks_exact(3).map(|c| [c[0] as f32, c[1] as f32, c[2] as f32]).collect();
        let mut image = RenderOutput::from_radiance(a.width, a.height, radiance);
        image.spp = a.spp + b.spp;
        Self { image, values, variance }
    }

    fn weight(&self, k: usize) -> f64 {
        1.0 / (self.values[k] * self.values[k] + RELATIVE_MSE_EPSILON)
    }

    /// The reference's own relative variance over `pixels`.
    fn relative_variance(&self, pixels: &[usize]) -> f64 {
        let sum: f64 = pixels.iter().flat_map(|&p| 3 * p..3 * p + 3).map(|k| self.variance[k] * self.weight(k)).sum();
        sum / (3 * pixels.len().max(1)) as f64
    }

    /// Error statistics of `acc` over `pixels`.
    fn stats(&self, acc: &Accumulation, pixels: &[usize]) -> ErrorStats {
        let n = f64::from(acc.count);
        let (mut error, mut variance) = (0.0, 0.0);
        for k in pixels.iter().flat_map(|&p| 3 * p..3 * p + 3) {
            let r = self.values[k];
            let w = self.weight(k);
            // Mean over the seeds of (x − r)², less the reference's variance.
            let mse = acc.sum_sq[k] / n - 2.0 * r * acc.sum[k] / n + r * r - self.variance[k];
            error += mse * w;
            variance += acc.variance(k) * w;
        }
        let m = (3 * pixels.len().max(1)) as f64;
        ErrorStats { error: error / m, bias2: (error - variance) / m, variance: variance / m }
    }
}

/// A 3 x 3 box average of a per-pixel quantity (edges clamp).
fn box3(values: &[f64], w: usize, h: usize) -> Vec<f64> {
    let mut out = vec![0.0; values.len()];
    for y in 0..h {
        for x in 0..w {
            let (mut sum, mut count) = (0.0, 0.0);
            for yy in y.saturating_sub(1)..(y + 2).min(h) {
                for xx in x.saturating_sub(1)..(x + 2).min(w) {
                    sum += values[yy * w + xx];
                    count += 1.0;
                }
            }
            out[y * w + x] = sum / count;
        }
    }
    out
}

fn bench_scene(ctx: &Context, config: &Config, path: &Path) -> Result<SceneReport, BenchError> {
    let scene = load_scene(path)?;
    let text = std::fs::read(path).map_err(io_error(path))?;
    let hash = fnv1a_hex(&text);
    let stem = stem_of(path);
    let exposure = scene.image.exposure;
    let mut cmds = Commands::new(&ctx.device)?;
    let gpu = GpuScene::for_render(&ctx.device, &mut cmds, &scene)?;
    let size = (config.width, config.height);
    let mut bench = Bench { ctx, cmds, gpu, scene, size, shading: config.shading, lookup: config.lookup };
    let seed = bench.scene.image.seed;
    let cache = config.out_dir.join("cache");
    if config.shading != SHADING_FULL {
        eprintln!("{stem}: shading variant {}: texture transport alone, no lighting", config.shading);
    }
    std::fs::create_dir_all(&cache).map_err(io_error(&cache))?;
    let pixels = (config.width * config.height) as usize;
    let all: Vec<usize> = (0..pixels).collect();

    let key = |spp: u32, seed: u32, offset: f64| ReferenceInfo {
        scene_hash: hash.clone(),
        width: config.width,
        height: config.height,
        spp,
        seed,
        camera_offset: offset,
        shading: config.shading,
        pixel_sigma: PIXEL_FILTER_SIGMA,
        version: env!("CARGO_PKG_VERSION").into(),
        seconds: 0.0,
    };
    let half = config.reference_spp / 2;
    let (a, reference_info) = cached_reference(
        &mut bench,
        &cache.join(format!("{stem}-s{}-reference-a", config.shading)),
        key(half, seed.wrapping_add(1_000_003), 0.0),
    )?;
    let (b, _) = cached_reference(
        &mut bench,
        &cache.join(format!("{stem}-s{}-reference-b", config.shading)),
        key(half, seed.wrapping_add(2_000_003), 0.0),
    )?;
    let reference = Reference::new(&a, &b);
    drop((a, b));
    let png = config.out_dir.join(format!("{stem}-reference.png"));
    write_png(&reference.image, exposure, &png).map_err(io_error(&png))?;

    let ladder = spp_ladder(config.max_spp);
    let targets: Vec<u32> = config.targets.iter().copied().filter(|t| ladder.contains(t)).collect();
    if targets.is_empty() {
        return Err(BenchError::Settings(format!(
            "no target spp ({:?}) is on the ladder 1, 2, 4, … {}",
            config.targets, config.max_spp
        )));
    }
    // Every mode's accumulations, by mode then spp.
    let mut accumulations: Vec<(String, u32, Accumulation)> = Vec::new();
    for (name, filter) in MODES {
        eprintln!("{stem}: {name}: warming up");
        bench.warm_up(filter)?;
        for (k, &spp) in ladder.iter().enumerate() {
            let mut acc = Accumulation::new(pixels);
            for s in 0..config.seeds {
                // A different seed per render: independent noise.
                let out = bench.render(filter, spp, seed.wrapping_add(1 + k as u32 * 1009 + s * 7919), 0.0)?;
                acc.flip += flip_mean(&reference.image, &out, exposure)?;
                acc.add(&out);
                if s == 0 && (k == 0 || spp == config.max_spp) {
                    let png = config.out_dir.join(format!("{stem}-{name}-{spp}spp.png"));
                    write_png(&out, exposure, &png).map_err(io_error(&png))?;
                }
            }
            let st = reference.stats(&acc, &all);
            eprintln!(
                "{stem}: {name:>10} {spp:>5} spp {:>8.3} s  rel MSE {:.5} (bias² {:.5}, variance {:.5})  FLIP {:.4}",
                acc.seconds / f64::from(acc.count),
                st.error,
                st.bias2,
                st.variance,
                acc.flip / f64::from(acc.count)
            );
            accumulations.push((name.to_string(), spp, acc));
        }
    }

    // The maps' share of none's error, and the texture mask, at each target.
    let textured = bench.replace_scene(with_mean_maps(&bench.scene))?;
    bench.warm_up(FILTER_NONE)?;
    let mut shares = Vec::new();
    let mut mask = vec![false; pixels];
    for (i, &t) in targets.iter().enumerate() {
        let mut acc = Accumulation::new(pixels);
        for s in 0..config.seeds {
            acc.add(&bench.render(FILTER_NONE, t, seed.wrapping_add(3_000_017 + s * 7919), 0.0)?);
        }
        let none = &accumulations.iter().find(|(m, spp, _)| m == "none" && *spp == t).expect("none ran").2;
        let lighting: f64 =
            (0..3 * pixels).map(|k| acc.variance(k) * reference.weight(k)).sum::<f64>() / (3 * pixels) as f64;
        let none_error = reference.stats(none, &all).error;
        let share = 1.0 - lighting / none_error.max(1e-30);
        eprintln!(
            "{stem}: texture share at {t} spp: {share:.3} (none's error {none_error:.5}, with mean maps {lighting:.5})"
        );
        shares.push(share);
        if i + 1 == targets.len() {
            let per_pixel = |a: &Accumulation| -> Vec<f64> {
                (0..pixels).map(|p| (3 * p..3 * p + 3).map(|k| a.variance(k) * reference.weight(k)).sum()).collect()
            };
            let (w, h) = (config.width as usize, config.height as usize);
            let (vn, vm) = (box3(&per_pixel(none), w, h), box3(&per_pixel(&acc), w, h));
            for p in 0..pixels {
                mask[p] = vn[p] > MASK_VARIANCE_RATIO * vm[p];
            }
        }
    }
    bench.replace_scene(textured)?;
    let masked: Vec<usize> = (0..pixels).filter(|&p| mask[p]).collect();
    let mask_fraction = masked.len() as f64 / pixels as f64;
    eprintln!("{stem}: texture mask: {:.1} % of the pixels", 100.0 * mask_fraction);

    let points: Vec<Point> = accumulations
        .iter()
        .map(|(mode, spp, acc)| Point {
            mode: mode.clone(),
            spp: *spp,
            seconds: acc.seconds / f64::from(acc.count),
            whole: reference.stats(acc, &all),
            masked: if masked.is_empty() { ErrorStats::default() } else { reference.stats(acc, &masked) },
            flip: acc.flip / f64::from(acc.count),
        })
        .collect();
    let mut target_rows = Vec::new();
    for masked_target in [false, true] {
        if masked_target && masked.is_empty() {
            continue;
        }
        for (i, &t) in targets.iter().enumerate() {
            target_rows.push(target_times(&points, t, masked_target, shares[i]));
        }
    }
    let none_seconds: f64 = points.iter().filter(|p| p.mode == "none").map(|p| p.seconds).sum();
    let cost_per_sample = MODES
        .iter()
        .map(|(name, _)| {
            let s: f64 = points.iter().filter(|p| p.mode == *name).map(|p| p.seconds).sum();
            (name.to_string(), s / none_seconds.max(1e-30))
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
        seeds: config.seeds,
        pixel_sigma: PIXEL_FILTER_SIGMA,
        reference: ReferenceInfo { spp: config.reference_spp, ..reference_info },
        reference_variance: reference.relative_variance(&all),
        mask_fraction,
        points,
        targets: target_rows,
        cost_per_sample,
        stability,
    };
    write_scene_outputs(config, &stem, &report)?;
    Ok(report)
}

/// The time each mode takes to reach `none`'s error at `spp` (over the mask
/// when `masked`) at equal quality: error at most the target and bias² at
/// most [`MAX_BIAS_SHARE`] of it.
pub fn target_times(points: &[Point], spp: u32, masked: bool, texture_share: f64) -> Target {
    let stats = |p: &Point| if masked { p.masked } else { p.whole };
    let none = points.iter().find(|p| p.mode == "none" && p.spp == spp).expect("the target's none point");
    let target = stats(none).error;
    let modes = MODES
        .iter()
        .map(|(name, _)| {
            let curve: Vec<(f64, f64, f64)> = points
                .iter()
                .filter(|p| p.mode == *name)
                .map(|p| (p.seconds, stats(p).error, stats(p).bias2))
                .collect();
            let t = time_to_equal_quality(&curve, target, MAX_BIAS_SHARE * target);
            ModeTime {
                mode: name.to_string(),
                seconds_to_target: t,
                speedup_over_none: t.map(|t| none.seconds / t),
                reached_at_first_point: curve
                    .first()
                    .is_some_and(|&(_, e, b)| e <= target && b <= MAX_BIAS_SHARE * target),
            }
        })
        .collect();
    Target { name: format!("none@{spp}"), spp, masked, error: target, seconds: none.seconds, texture_share, modes }
}

/// The time at which a curve of (seconds, error, bias²) points, in the
/// order of increasing effort, first has error ≤ `target` and bias² ≤
/// `max_bias2`: log-log interpolation of the error between the point before
/// and that point; `None` when no point qualifies.
pub fn time_to_equal_quality(points: &[(f64, f64, f64)], target: f64, max_bias2: f64) -> Option<f64> {
    let first = points.iter().position(|&(_, e, b)| e <= target && b <= max_bias2)?;
    if first == 0 {
        return Some(points[0].0);
    }
    let ((t0, e0, _), (t1, e1, _)) = (points[first - 1], points[first]);
    if e0 <= target {
        // The point before had the error but too much bias.
        return Some(t1);
    }
    time_to_reach(&[(t0, e0), (t1, e1)], target)
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
    key: &dyn Fn(u32, u32, f64) -> ReferenceInfo,
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
        reference_frames
            .push(cached_reference(bench, &path, key(config.reference_frame_spp, bench.scene.image.seed, offset))?.0);
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
    type Value = fn(&Point) -> f64;
    let plots: [(&str, &str, Value, bool); 3] = [
        ("relmse", "relative MSE", |p| p.whole.error, false),
        ("relmse-mask", "relative MSE, texture mask", |p| p.masked.error, true),
        ("flip", "mean FLIP", |p| p.flip, false),
    ];
    for (metric, label, value, masked) in plots {
        if masked && report.mask_fraction == 0.0 {
            continue;
        }
        let series: Vec<Series> = MODES
            .iter()
            .map(|(name, _)| Series {
                label: name.to_string(),
                points: report.points.iter().filter(|p| p.mode == *name).map(|p| (p.seconds, value(p))).collect(),
            })
            .collect();
        let hlines: Vec<HLine> = report
            .targets
            .iter()
            .filter(|t| t.masked == masked)
            .filter_map(|t| {
                let p = report.points.iter().find(|p| p.mode == "none" && p.spp == t.spp)?;
                Some(HLine { label: t.name.clone(), y: value(p) })
            })
            .collect();
        let path = config.out_dir.join(format!("{stem}-{metric}.png"));
        let title =
            format!("{stem}: {label} against GPU time ({}x{}, {} seeds)", report.width, report.height, report.seeds);
        write_log_log_plot(&path, &title, "GPU seconds", label, &series, &hlines)
            .map_err(|source| BenchError::Plot { path: path.clone(), source })?;
    }
    eprintln!("wrote {}/{stem}.{{json,md}} and {stem}-{{relmse,relmse-mask,flip}}.png", config.out_dir.display());
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
        "{}x{} on {}, {} seeds per point, Gaussian pixel filter σ = {} px; reference: filtering `none`, {} spp in two \
         halves ({:.1} s for one), its own relative variance {:.2e} subtracted from every error. Texture mask: {:.1} % \
         of the pixels. Command: `{}`\n",
        r.width,
        r.height,
        r.device,
        r.seeds,
        r.pixel_sigma,
        r.reference.spp,
        r.reference.seconds,
        r.reference_variance,
        100.0 * r.mask_fraction,
        r.command
    );
    let _ = writeln!(
        s,
        "| mode | spp | seconds | rel MSE | bias² | variance | rel MSE (mask) | bias² (mask) | FLIP |\n\
         |---|---:|---:|---:|---:|---:|---:|---:|---:|"
    );
    for p in &r.points {
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {:.5} | {:.5} | {:.5} | {:.5} | {:.5} | {:.4} |",
            p.mode,
            p.spp,
            p.seconds,
            p.whole.error,
            p.whole.bias2,
            p.whole.variance,
            p.masked.error,
            p.masked.bias2,
            p.flip
        );
    }
    let _ = writeln!(
        s,
        "\nTime to equal quality: the relative MSE of `none` at the target spp, reached with bias² at most {:.0} % of \
         it (log-log interpolation between measured points; ≤: already reached at 1 spp, an upper bound). Cost per \
         sample over `none`: {}.\n",
        100.0 * MAX_BIAS_SHARE,
        r.cost_per_sample.iter().map(|(k, v)| format!("{k} {v:.2}")).collect::<Vec<_>>().join(", ")
    );
    let _ = writeln!(
        s,
        "| target | region | texture share | target error | none (s) | ray-cones (s) | speed-up | covariance (s) | speed-up |\n\
         |---|---|---:|---:|---:|---:|---:|---:|---:|"
    );
    for t in &r.targets {
        let cell = |mode: &str| -> (String, String) {
            t.modes.iter().find(|m| m.mode == mode).map_or_else(
                || ("-".into(), "-".into()),
                |m| {
                    let (le, ge) = if m.reached_at_first_point { ("≤ ", "≥ ") } else { ("", "") };
                    (
                        format!("{le}{}", fmt_opt(m.seconds_to_target, 3)),
                        format!("{ge}{}", fmt_opt(m.speedup_over_none, 2)),
                    )
                },
            )
        };
        let (ct, cs) = cell("ray-cones");
        let (vt, vs) = cell("covariance");
        let _ = writeln!(
            s,
            "| {} | {} | {:.3} | {:.5} | {:.3} | {ct} | {cs} | {vt} | {vs} |",
            t.name,
            if t.masked { "mask" } else { "whole" },
            t.texture_share,
            t.error,
            t.seconds
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
        "Headline: time to reach the relative MSE of `none` at the target spp at equal quality (bias² at most {:.0} % \
         of the target), as a speed-up over `none` (above 1: faster), whole image (texture mask).\n",
        100.0 * MAX_BIAS_SHARE
    );
    let _ = writeln!(s, "| scene | texture share | target | ray-cones | covariance |\n|---|---:|---|---:|---:|");
    for r in reports {
        for e in headline_entries(r) {
            let cell = |mode: &str| {
                let w = e.speedup_vs_none.get(mode).copied().flatten();
                let m = e.speedup_vs_none_masked.get(mode).copied().flatten();
                format!("{} ({})", fmt_opt(w, 2), fmt_opt(m, 2))
            };
            let _ = writeln!(
                s,
                "| {} | {:.3} | {} | {} | {} |",
                e.scene,
                e.texture_share,
                e.target,
                cell("ray-cones"),
                cell("covariance")
            );
        }
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
    fn equal_quality_needs_low_bias_too() {
        // error = 1 / t, bias² 0.1 until t = 8, then 0.
        let points: Vec<(f64, f64, f64)> =
            [1.0, 2.0, 4.0, 8.0, 16.0].iter().map(|&t: &f64| (t, 1.0 / t, if t < 8.0 { 0.1 } else { 0.0 })).collect();
        // Target 0.3: reached at t = 1/0.3 by the error alone, but bias² 0.1 > 0.075 until t = 8.
        assert_eq!(time_to_equal_quality(&points, 0.3, 0.075), Some(8.0));
        // Target 0.3 with bias allowed: interpolated between t = 2 and 4.
        let t = time_to_equal_quality(&points, 0.3, 1.0).unwrap();
        assert!((t - 1.0 / 0.3).abs() < 1e-9, "{t}");
        assert_eq!(time_to_equal_quality(&points, 0.01, 1.0), None);
    }

    #[test]
    fn error_statistics_split_bias_and_variance() {
        // Two pixels' values; reference 1 with no noise; renders 1 + b ± d.
        let r = RenderOutput::from_radiance(2, 1, vec![[1.0; 3]; 2]);
        let reference = Reference::new(&r, &r);
        let mut acc = Accumulation::new(2);
        for d in [-0.2f32, 0.2] {
            acc.add(&RenderOutput::from_radiance(2, 1, vec![[1.1 + d; 3]; 2]));
        }
        let st = reference.stats(&acc, &[0, 1]);
        let w = 1.0 / (1.0 + RELATIVE_MSE_EPSILON);
        // Variance of one render: 2 · 0.2² / (2 − 1) = 0.08; mean squared error 0.1² + 0.2² = 0.05.
        assert!((st.variance - 0.08 * w).abs() < 1e-6, "{st:?}");
        assert!((st.error - 0.05 * w).abs() < 1e-6, "{st:?}");
        assert!((st.bias2 - (0.05 - 0.08) * w).abs() < 1e-6, "{st:?}");
    }

    #[test]
    fn mean_maps_drop_every_map() {
        let mut scene = crate::scene::parse_scene(crate::scene::DEFAULT_SCENE, "default").unwrap();
        scene.textures = vec![crate::texture::checker(4, 2, [1.0; 3], [0.0; 3])];
        scene.materials[0].maps.albedo = Some(0);
        scene.materials[0].albedo = glam::Vec3::ONE;
        let s = with_mean_maps(&scene);
        assert!(s.materials[0].maps.albedo.is_none());
        assert!((s.materials[0].albedo.x - 0.5).abs() < 1e-6);
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
            pixel_sigma: 0.5,
            version: "1".into(),
            seconds: 3.0,
        };
        assert!(a.same_settings(&ReferenceInfo { seconds: 9.0, ..a.clone() }));
        assert!(!a.same_settings(&ReferenceInfo { spp: 8, ..a.clone() }));
        assert!(!a.same_settings(&ReferenceInfo { pixel_sigma: 0.0, ..a.clone() }));
    }
}
