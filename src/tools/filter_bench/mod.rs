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
//!    the GPU; the modes take turns render by render, so that the machine's
//!    drift falls on all alike. The error is the relative MSE of the linear radiance against
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

mod measure;
mod report;
#[cfg(test)]
mod tests;

use std::path::{Path, PathBuf};

use crate::model::scene::FilterMode;
use crate::passes::{LookupMode, ShadingMode};
use crate::tools::metrics::MetricError;
use crate::tools::plot::PlotError;
use crate::vk::Context;
use crate::RenderError;

pub use measure::*;
pub use report::*;

/// The filtering modes, by their CLI names.
pub const MODES: [(&str, FilterMode); 3] =
    [("none", FilterMode::None), ("ray-cones", FilterMode::RayCones), ("covariance", FilterMode::Covariance)];

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
    /// The render shader's shading: `ShadingMode::Full` (the path tracer),
    /// `ShadingMode::MirroredAlbedo` (the albedo seen directly and through
    /// perfect mirrors) or `ShadingMode::GlossyAlbedo` (also through glossy
    /// reflections and refractions); the albedo modes have no lighting.
    pub shading: ShadingMode,
    /// The filtered modes' lookup: `LookupMode::Probes` or `LookupMode::Ewa`.
    pub lookup: LookupMode,
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
            shading: ShadingMode::Full,
            lookup: LookupMode::Probes,
            command: String::new(),
        }
    }
}

/// Why the benchmark stopped.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A scene file could not be loaded.
    #[error("{0}")]
    Scene(#[from] crate::model::scene::SceneError),
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

/// FNV-1a (64 bit) of `bytes`, in hex: a stable cache key.
pub fn fnv1a_hex(bytes: &[u8]) -> String {
    format!("{:016x}", crate::util::hash::Fnv1a::of(bytes))
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
/// (`OUT/<scene>.json`), draws their plots again and writes `summary.md` and
/// `headline.json` over them, rendering nothing: a summary over scenes
/// measured in separate runs.
pub fn summarize(config: &Config) -> Result<Vec<SceneReport>, BenchError> {
    let mut reports = Vec::new();
    for path in &config.scenes {
        let json = config.out_dir.join(format!("{}.json", stem_of(path)));
        let text = std::fs::read_to_string(&json).map_err(io_error(&json))?;
        let report: SceneReport = serde_json::from_str(&text)
            .map_err(|e| BenchError::Settings(format!("{}: not a report of this version: {e}", json.display())))?;
        report::write_plots(&config.out_dir, &stem_of(path), &report)?;
        reports.push(report);
    }
    write_summaries(config, &reports)?;
    Ok(reports)
}
