//! What the prefiltering benchmark reports: the statistics per mode, spp
//! and target, and their JSON and Markdown files.

use std::collections::BTreeMap;
use std::fmt::Write as _;

use serde::{Deserialize, Serialize};

use crate::tools::plot::{write_log_log_plot, HLine, Series};
use crate::util::files::{write_all_or_nothing, write_file_atomically};

use super::*;

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
    /// The shading variant (`ShadingMode::constant`, the shader's `SHADING_*`).
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
    pub(super) fn same_settings(&self, other: &Self) -> bool {
        Self { seconds: 0.0, ..self.clone() } == Self { seconds: 0.0, ..other.clone() }
    }
}

/// Writes `summary.md` over `reports` and merges their entries into
/// `headline.json`.
pub(super) fn write_summaries(config: &Config, reports: &[SceneReport]) -> Result<(), BenchError> {
    let summary = config.out_dir.join("summary.md");
    let text = summary_markdown(config, reports);
    write_file_atomically(&summary, text.as_bytes()).map_err(io_error(&summary))?;
    let headline_path = config.out_dir.join("headline.json");
    let mut entries: Vec<HeadlineEntry> =
        std::fs::read_to_string(&headline_path).ok().and_then(|t| serde_json::from_str(&t).ok()).unwrap_or_default();
    entries.retain(|e| !reports.iter().any(|r| r.scene == e.scene));
    entries.extend(reports.iter().flat_map(headline_entries));
    let json = serde_json::to_string_pretty(&entries).expect("serialisable");
    write_file_atomically(&headline_path, json.as_bytes()).map_err(io_error(&headline_path))?;
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

pub(super) fn write_scene_outputs(config: &Config, stem: &str, report: &SceneReport) -> Result<(), BenchError> {
    let json_path = config.out_dir.join(format!("{stem}.json"));
    let json = serde_json::to_string_pretty(report).expect("serialisable");
    let md_path = config.out_dir.join(format!("{stem}.md"));
    let md = scene_markdown(report);
    write_all_or_nothing(&[json_path.clone(), md_path], |i, p| std::fs::write(p, if i == 0 { &json } else { &md }))
        .map_err(io_error(&json_path))?;
    write_plots(&config.out_dir, stem, report)?;
    eprintln!("wrote {}/{stem}.{{json,md}} and {stem}-{{relmse,relmse-mask,flip}}.png", config.out_dir.display());
    Ok(())
}

/// Draws the plots of one scene's report: relative MSE (whole image and
/// texture mask) and FLIP against GPU time, as `OUT/<stem>-<metric>.png`.
pub(super) fn write_plots(out_dir: &Path, stem: &str, report: &SceneReport) -> Result<(), BenchError> {
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
        let path = out_dir.join(format!("{stem}-{metric}.png"));
        let title =
            format!("{stem}: {label} against GPU time ({}x{}, {} seeds)", report.width, report.height, report.seeds);
        write_log_log_plot(&path, &title, "GPU seconds", label, &series, &hlines)
            .map_err(|source| BenchError::Plot { path: path.clone(), source })?;
    }
    Ok(())
}

pub(super) fn fmt_opt(v: Option<f64>, digits: usize) -> String {
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

pub(super) fn summary_markdown(config: &Config, reports: &[SceneReport]) -> String {
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
