//! `quadray bench`: the speed/accuracy trade of the quality presets, measured.
//!
//! For each scene, a `reference` render (brute force: 1024 spp, 16 bounces,
//! no prefiltering, no caustic or volume pass; cached) and one render per
//! preset at the same image size. Every render is timed per pass with GPU
//! timestamps, after an untimed warm-up (lavapipe compiles each shader at its
//! first dispatch), and compared with the reference by FLIP and relative
//! MSE. Where Intel Open Image Denoise is installed (`crate::jobs::denoise`), each
//! preset's render is also denoised (high quality, with the albedo and normal
//! features) and compared the same way, at the same spp and at the render's
//! time plus the denoiser's (CPU wall time): denoising is biased, so its
//! error does not fall with more samples the way a raw render's does. The
//! report is written as JSON, Markdown, and a log-log plot of error against
//! time (raw and denoised, one line each per scene), with each render's PNG
//! beside it.

use std::path::{Path, PathBuf};
use std::time::Instant;

use serde::{Deserialize, Serialize};

use crate::jobs::output::{write_outputs, ExrPrecision, OutputKind};
use crate::model::scene::{Preset, Quality, Scene};
use crate::passes::{render, GpuScene, RenderOutput, RenderVariant};
use crate::tools::metrics::{flip_mean, relative_mse, MetricError};
use crate::tools::plot::{write_log_log_plot, PlotError, Series};
use crate::util::progress::ProgressBar;
use crate::vk::{Commands, Context};
use crate::RenderError;

/// Errors of the benchmark.
#[derive(Debug, thiserror::Error)]
pub enum BenchError {
    /// A render failed.
    #[error("{scene}: {source}")]
    Render {
        /// The scene's name.
        scene: String,
        /// What failed.
        source: RenderError,
    },
    /// Comparing images failed.
    #[error(transparent)]
    Metric(#[from] MetricError),
    /// The denoiser failed.
    #[error(transparent)]
    Denoise(#[from] crate::jobs::denoise::DenoiseError),
    /// The plot could not be written.
    #[error(transparent)]
    Plot(#[from] PlotError),
    /// A file could not be written or read.
    #[error("{}: {source}", .path.display())]
    Io {
        /// The file.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
}

/// A scene to measure.
pub struct BenchScene {
    /// Its name in the report (the file stem, or `default`).
    pub name: String,
    /// The scene, as loaded.
    pub scene: Scene,
    /// The scene file's text, part of the reference cache key.
    pub source: String,
}

/// What to measure.
pub struct Config {
    /// The scenes.
    pub scenes: Vec<BenchScene>,
    /// The presets to measure against `reference`.
    pub presets: Vec<Preset>,
    /// Image width and height for every render.
    pub size: (u32, u32),
    /// Samples per pixel of the reference (default: the preset's 1024).
    pub reference_spp: Option<u32>,
    /// Output folder; the references are cached in its `cache/`.
    pub out_dir: PathBuf,
    /// The command line, recorded in the report.
    pub command: String,
    /// Show the progress bar even when stderr is not a terminal.
    pub progress: bool,
}

/// One render's measurements.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Row {
    /// The preset's name.
    pub preset: String,
    /// Its samples per pixel.
    pub spp: u32,
    /// Its path depth.
    pub max_depth: u32,
    /// Its texture filtering.
    pub filter: String,
    /// Caustic rays traced (all lights and light samples; 0 when the passes did not run).
    pub caustic_rays: u64,
    /// Volume-pass camera rays per pixel (0 when the pass did not run).
    pub volume_rays_per_pixel: u32,
    /// GPU time of the render pass (the samples), s.
    pub render_seconds: f64,
    /// GPU time of the caustic passes, s.
    pub caustic_seconds: f64,
    /// GPU time of the volume pass, s.
    pub volume_seconds: f64,
    /// GPU time of all passes, s.
    pub gpu_seconds: f64,
    /// Wall time of the render call (pipeline and buffer creation, passes,
    /// read-back; the scene upload excluded), s.
    pub wall_seconds: f64,
    /// Mean FLIP against the reference (0 for the reference itself).
    pub flip: f64,
    /// Relative MSE against the reference.
    pub relative_mse: f64,
    /// The same render denoised: what it cost and how far it is from the
    /// reference (absent without the denoiser, and for the reference).
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub denoised: Option<Denoised>,
}

/// A render denoised (Intel Open Image Denoise, high quality).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Denoised {
    /// Wall time of the denoiser (on the CPU), s.
    pub seconds: f64,
    /// Mean FLIP against the reference.
    pub flip: f64,
    /// Relative MSE against the reference.
    pub relative_mse: f64,
}

/// One scene's results.
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct SceneReport {
    /// The scene's name.
    pub scene: String,
    /// Image width.
    pub width: u32,
    /// Image height.
    pub height: u32,
    /// The reference's own row (its error is 0 by definition).
    pub reference: Row,
    /// One row per measured preset.
    pub presets: Vec<Row>,
}

/// The whole report (`bench.json`).
#[derive(Clone, Debug, Serialize, Deserialize)]
pub struct Report {
    /// The command that made it.
    pub command: String,
    /// The Vulkan device.
    pub device: String,
    /// True when times are GPU timestamps (not wall clocks).
    pub gpu_timestamps: bool,
    /// Per scene.
    pub scenes: Vec<SceneReport>,
}

/// Runs the benchmark and writes `bench.json`, `bench.md`, `bench.png` and
/// the renders' PNGs into `config.out_dir`.
pub fn run(ctx: &Context, config: &Config) -> Result<Report, BenchError> {
    let io = |path: &Path| {
        let path = path.to_path_buf();
        move |source| BenchError::Io { path: path.clone(), source }
    };
    let cache = config.out_dir.join("cache");
    std::fs::create_dir_all(&cache).map_err(io(&cache))?;
    let device = &ctx.device;
    let mut cmds = Commands::new(device).map_err(|e| render_error("setup", e.into()))?;
    let timestamps = crate::vk::GpuTimer::new(device).map_err(|e| render_error("setup", e.into()))?.is_gpu();

    // Progress in pixel-samples over every render still to do.
    let (w, h) = config.size;
    let mut total = 0u64;
    for s in &config.scenes {
        let reference = reference_scene(&s.scene, config);
        if !cache_path(&cache, s, &reference).exists() {
            total += w as u64 * h as u64 * reference.image.spp as u64;
        }
        for &p in &config.presets {
            total += w as u64 * h as u64 * preset_scene(&s.scene, p, config.size).image.spp as u64;
        }
    }
    let mut denoiser = match crate::jobs::denoise::Denoiser::load() {
        Ok(d) => Some(d),
        Err(e) => {
            log::warn!("{e}: the report has no denoised points");
            None
        }
    };
    let mut bar = ProgressBar::new(config.progress);
    let mut done = 0u64;

    let mut reports = Vec::new();
    for s in &config.scenes {
        let reference_scene = reference_scene(&s.scene, config);
        let gpu = GpuScene::for_render(device, &mut cmds, &s.scene).map_err(|e| render_error(&s.name, e))?;
        let mut measure = |scene: &Scene, label: &str, bar: &mut ProgressBar, done: &mut u64| {
            bar.set_label(format!("{}: {label}", s.name));
            let variant = RenderVariant::default();
            let im = &scene.image;
            // Untimed warm-up: compiles every pipeline this quality uses.
            crate::passes::Renderer::warm_up(device, &mut cmds, &gpu, scene, variant)
                .map_err(|e| render_error(&s.name, e))?;
            let work = im.width as u64 * im.height as u64 * im.spp as u64;
            let start = Instant::now();
            let out = render(device, &mut cmds, &gpu, scene, variant, &mut |d, t| {
                bar.update(*done + work * d / t.max(1), total)
            })
            .map_err(|e| render_error(&s.name, e))?;
            *done += work;
            Ok::<_, BenchError>((out, start.elapsed().as_secs_f64()))
        };

        let reference_file = cache_path(&cache, s, &reference_scene);
        let (reference, reference_row) = match read_cached(&reference_file)? {
            Some(cached) => cached,
            None => {
                let (out, wall) = measure(&reference_scene, "reference", &mut bar, &mut done)?;
                let row = row_of(Preset::Reference, &reference_scene, &out, wall, 0.0, 0.0);
                write_cached(&reference_file, &out, &row)?;
                (out, row)
            }
        };
        let png = |name: &str| config.out_dir.join(format!("{}-{name}.png", s.name));
        let exposure = s.scene.image.exposure;
        write_outputs(&reference, &[(png("reference"), OutputKind::Png { exposure })])
            .map_err(io(&png("reference")))?;

        let mut rows = Vec::new();
        for &preset in &config.presets {
            let scene = preset_scene(&s.scene, preset, config.size);
            let (out, wall) = measure(&scene, preset.name(), &mut bar, &mut done)?;
            let flip = flip_mean(&reference, &out, exposure)?;
            let rel = relative_mse(&reference, &out)?;
            write_outputs(&out, &[(png(preset.name()), OutputKind::Png { exposure })])
                .map_err(io(&png(preset.name())))?;
            let mut row = row_of(preset, &scene, &out, wall, flip, rel);
            if let Some(d) = denoiser.as_mut() {
                let start = Instant::now();
                let image = crate::jobs::denoise::denoise_output(d, &out, crate::jobs::denoise::DenoiseQuality::High)?;
                let seconds = start.elapsed().as_secs_f64();
                let denoised = RenderOutput::from_radiance(out.width, out.height, image);
                let name = format!("{}-denoised", preset.name());
                write_outputs(&denoised, &[(png(&name), OutputKind::Png { exposure })]).map_err(io(&png(&name)))?;
                row.denoised = Some(Denoised {
                    seconds,
                    flip: flip_mean(&reference, &denoised, exposure)?,
                    relative_mse: relative_mse(&reference, &denoised)?,
                });
            }
            rows.push(row);
        }
        reports.push(SceneReport {
            scene: s.name.clone(),
            width: w,
            height: h,
            reference: reference_row,
            presets: rows,
        });
    }
    bar.finish();

    let report = Report {
        command: config.command.clone(),
        device: device.name.clone(),
        gpu_timestamps: timestamps,
        scenes: reports,
    };
    let json = config.out_dir.join("bench.json");
    std::fs::write(&json, serde_json::to_string_pretty(&report).expect("serialisable")).map_err(io(&json))?;
    let md = config.out_dir.join("bench.md");
    std::fs::write(&md, markdown(&report)).map_err(io(&md))?;
    write_plot(&report, &config.out_dir)?;
    Ok(report)
}

/// Draws `bench.png` in `out_dir`: FLIP against GPU time, one line per scene
/// through its presets, and one through the same renders denoised (at
/// their GPU time plus the denoiser's).
pub fn write_plot(report: &Report, out_dir: &Path) -> Result<(), BenchError> {
    let mut series: Vec<Series> = Vec::new();
    for s in &report.scenes {
        series.push(Series {
            label: s.scene.clone(),
            points: s.presets.iter().map(|r| (r.gpu_seconds, r.flip)).collect(),
        });
        let denoised: Vec<(f64, f64)> =
            s.presets.iter().filter_map(|r| r.denoised.as_ref().map(|d| (r.gpu_seconds + d.seconds, d.flip))).collect();
        if !denoised.is_empty() {
            series.push(Series { label: format!("{} denoised", s.scene), points: denoised });
        }
    }
    let first = report.scenes.first();
    let names: Vec<&str> = first.map(|s| s.presets.iter().map(|r| r.preset.as_str()).collect()).unwrap_or_default();
    let (w, h) = first.map_or((0, 0), |s| (s.width, s.height));
    write_log_log_plot(
        &out_dir.join("bench.png"),
        &format!("Presets ({}) against reference, {w}x{h}", names.join(", ")),
        "GPU time (s); denoised lines: plus the denoiser's CPU time",
        "FLIP vs reference",
        &series,
        &[],
    )?;
    Ok(())
}

/// Reads the `bench.json` an earlier run wrote in `out_dir` and draws its
/// `bench.png` again, rendering nothing.
pub fn replot(out_dir: &Path) -> Result<Report, BenchError> {
    let json = out_dir.join("bench.json");
    let io = |source| BenchError::Io { path: json.clone(), source };
    let text = std::fs::read_to_string(&json).map_err(io)?;
    let report: Report = serde_json::from_str(&text).map_err(|e| {
        io(std::io::Error::new(std::io::ErrorKind::InvalidData, format!("not a report of this version: {e}")))
    })?;
    write_plot(&report, out_dir)?;
    Ok(report)
}

fn render_error(scene: &str, source: RenderError) -> BenchError {
    BenchError::Render { scene: scene.to_string(), source }
}

/// `scene` at `preset`'s quality and the benchmark's image size.
fn preset_scene(scene: &Scene, preset: Preset, (width, height): (u32, u32)) -> Scene {
    let mut s = scene.clone();
    s.apply_preset(preset);
    s.image.width = width;
    s.image.height = height;
    s
}

/// The reference: the `reference` preset (with the configured spp) and a
/// seed the presets do not use, so its noise is independent of theirs.
fn reference_scene(scene: &Scene, config: &Config) -> Scene {
    let mut s = preset_scene(scene, Preset::Reference, config.size);
    if let Some(spp) = config.reference_spp {
        s.image.spp = spp;
    }
    s.image.seed = s.image.seed.wrapping_add(0x5eed);
    s
}

fn row_of(preset: Preset, scene: &Scene, out: &RenderOutput, wall: f64, flip: f64, relative_mse: f64) -> Row {
    let Quality { spp, max_depth, filter, .. } = scene.quality();
    Row {
        preset: preset.name().into(),
        spp,
        max_depth,
        filter: filter.name().into(),
        caustic_rays: out.caustics.as_ref().map_or(0, |c| c.rays),
        volume_rays_per_pixel: if out.volume_seconds.is_some() { scene.volume.samples * spp } else { 0 },
        render_seconds: out.render_seconds,
        caustic_seconds: out.caustics.as_ref().map_or(0.0, |c| c.seconds()),
        volume_seconds: out.volume_seconds.unwrap_or(0.0),
        gpu_seconds: out.seconds,
        wall_seconds: wall,
        flip,
        relative_mse,
        denoised: None,
    }
}

/// The reference's cache file: the scene's name and a hash of everything
/// that determines the image (the scene text, size, quality and seed, and
/// the program version).
fn cache_path(cache: &Path, s: &BenchScene, reference: &Scene) -> PathBuf {
    let key = format!(
        "{}|{}|{}x{}|{:?}|{}",
        env!("CARGO_PKG_VERSION"),
        s.source,
        reference.image.width,
        reference.image.height,
        reference.quality(),
        reference.image.seed
    );
    let hash = crate::util::hash::Fnv1a::of(key.as_bytes());
    cache.join(format!("{}-reference-{hash:016x}.exr", s.name))
}

fn read_cached(path: &Path) -> Result<Option<(RenderOutput, Row)>, BenchError> {
    let json = path.with_extension("json");
    let (Ok(text), true) = (std::fs::read_to_string(&json), path.exists()) else {
        return Ok(None);
    };
    let Ok(row) = serde_json::from_str::<Row>(&text) else {
        return Ok(None);
    };
    let Ok((width, height, texels)) = crate::model::texture::read_exr_image(path) else {
        return Ok(None);
    };
    eprintln!("using the cached reference {}", path.display());
    let mut out = RenderOutput::from_radiance(width, height, texels.iter().map(|t| [t[0], t[1], t[2]]).collect());
    out.spp = row.spp;
    out.seconds = row.gpu_seconds;
    out.render_seconds = row.render_seconds;
    Ok(Some((out, row)))
}

fn write_cached(path: &Path, out: &RenderOutput, row: &Row) -> Result<(), BenchError> {
    write_outputs(out, &[(path.to_path_buf(), OutputKind::Exr(ExrPrecision::Float))])
        .map_err(|source| BenchError::Io { path: path.to_path_buf(), source })?;
    let json = path.with_extension("json");
    std::fs::write(&json, serde_json::to_string_pretty(row).expect("serialisable"))
        .map_err(|source| BenchError::Io { path: json, source })
}

/// The report as Markdown: one table per scene.
pub fn markdown(report: &Report) -> String {
    let clock = if report.gpu_timestamps { "GPU timestamps" } else { "wall clock (no GPU timestamps)" };
    let mut s = format!(
        "# Quality presets: time against error\n\nCommand: `{}`\n\nDevice: {}. Times: {clock}, seconds for the \
         whole image; each render after an untimed warm-up. Error: mean FLIP and relative MSE against the scene's \
         `reference` render (rendered with a different seed).\n",
        report.command, report.device
    );
    for sc in &report.scenes {
        let r = &sc.reference;
        s += &format!(
            "\n## {} ({}x{})\n\nReference: {} spp, depth {}, filter {}, brute force: {:.2} s GPU.\n\n",
            sc.scene, sc.width, sc.height, r.spp, r.max_depth, r.filter, r.gpu_seconds
        );
        s +=
            "| preset | spp | depth | filter | caustic rays | volume rays/px | render (s) | caustics (s) | volume (s) \
              | GPU total (s) | wall (s) | time vs reference | FLIP | rel. MSE | denoise (s, CPU) | FLIP denoised \
              | rel. MSE denoised |\n";
        s += "|---|---:|---:|---|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n";
        for row in &sc.presets {
            let denoised = row.denoised.as_ref().map_or("| – | – | – |".to_string(), |d| {
                format!("| {:.3} | {:.4} | {:.4} |", d.seconds, d.flip, d.relative_mse)
            });
            s += &format!(
                "| {} | {} | {} | {} | {} | {} | {:.3} | {:.3} | {:.3} | {:.3} | {:.3} | {:.4} | {:.4} | {:.4} {denoised}\n",
                row.preset,
                row.spp,
                row.max_depth,
                row.filter,
                row.caustic_rays,
                row.volume_rays_per_pixel,
                row.render_seconds,
                row.caustic_seconds,
                row.volume_seconds,
                row.gpu_seconds,
                row.wall_seconds,
                row.gpu_seconds / r.gpu_seconds.max(1e-12),
                row.flip,
                row.relative_mse
            );
        }
    }
    s
}
