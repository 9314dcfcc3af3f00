//! Flags and helpers shared by the commands: quality and frame flags, frame
//! ranges, output paths.

use std::path::{Path, PathBuf};

use anyhow::{bail, Result};
use clap::Parser;
use quadray::jobs::output::{ExrPrecision, OutputKind};
use quadray::model::scene::MAX_IMAGE_SIZE;
use quadray::model::scene::{load_scene, parse_scene, FilterMode, Preset, Scene, DEFAULT_SCENE, DEFAULT_SCENE_NAME};

/// Image size and seed overrides of `render` and `outliers`.
#[derive(Parser, Debug, Default, Clone)]
pub(crate) struct FrameArgs {
    /// Image width in pixels (overrides `image.width`).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIZE))]
    pub(crate) width: Option<u32>,
    /// Image height in pixels (overrides `image.height`).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIZE))]
    pub(crate) height: Option<u32>,
    /// Random seed (overrides `image.seed`).
    #[arg(long)]
    pub(crate) seed: Option<u32>,
}

/// `--frames A-B[:STEP]`.
#[derive(Clone, Copy, Debug)]
pub(crate) struct FrameRange {
    pub(crate) first: u32,
    pub(crate) last: u32,
    pub(crate) step: u32,
}

impl FrameRange {
    /// The frames of the range, in order.
    pub(crate) fn frames(self) -> Vec<u32> {
        (self.first..=self.last).step_by(self.step as usize).collect()
    }
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
pub(crate) const EXIT_INTERRUPTED: i32 = 75;

pub(crate) fn positive_seconds(s: &str) -> Result<f64, String> {
    match s.parse::<f64>() {
        Ok(v) if v > 0.0 && v.is_finite() => Ok(v),
        _ => Err(format!("{s:?} is not a positive number of seconds")),
    }
}

/// The files `-o output` asks for, each checked before any work: `output`
/// is not a folder, every folder on the way exists and is one, and a probe
/// file can be created (and is removed) in it. Errors name what is wrong.
pub(crate) fn checked_outputs(output: &Path) -> Result<Vec<PathBuf>> {
    if output.is_dir() || output.as_os_str().to_string_lossy().ends_with(std::path::MAIN_SEPARATOR) {
        bail!("-o {}: give a file name (e.g. {}/render), not a folder", output.display(), output.display());
    }
    let outputs = output_paths(output);
    let dir = match output.parent().filter(|d| !d.as_os_str().is_empty()) {
        Some(d) => d.to_path_buf(),
        None => PathBuf::from("."),
    };
    if !dir.is_dir() {
        // The folder, or the nearest ancestor that exists, says why.
        let existing = dir.ancestors().find(|a| !a.as_os_str().is_empty() && a.exists());
        match existing {
            Some(a) if !a.is_dir() => bail!("-o {}: {} is a file, not a folder", output.display(), a.display()),
            _ => bail!("-o {}: the output folder {} does not exist", output.display(), dir.display()),
        }
    }
    let probe = dir.join(format!(".quadray-write-test-{}", std::process::id()));
    match std::fs::OpenOptions::new().write(true).create_new(true).open(&probe) {
        Ok(_) => {
            let _ = std::fs::remove_file(&probe);
        }
        Err(e) => bail!("-o {}: cannot write in the folder {}: {e}", output.display(), dir.display()),
    }
    Ok(outputs)
}

/// Which files `-o` asks for.
pub(crate) fn output_paths(output: &Path) -> Vec<PathBuf> {
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
pub(crate) fn output_files(paths: &[PathBuf], exposure: f32, half: bool) -> Vec<(PathBuf, OutputKind)> {
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
pub(crate) struct QualityArgs {
    /// Quality preset: `preview`, `interactive`, `final` or `reference`
    /// (docs/presets.md). Replaces all the scene's quality settings (spp,
    /// max_depth, filter, caustic rays and light samples, volume samples,
    /// denoising: `preview` and `interactive` denoise, `final` and
    /// `reference` do not); the flags below override single ones.
    #[arg(long)]
    pub(crate) preset: Option<Preset>,
    /// Samples per pixel (overrides the scene's or preset's `image.spp`).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=quadray::model::scene::MAX_SPP))]
    pub(crate) spp: Option<u32>,
    /// Longest light path in bounces (overrides `image.max_depth`).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=64))]
    pub(crate) max_depth: Option<u32>,
    /// Texture filtering (overrides `image.filter`): `none` (bilinear lookups
    /// of the finest mip level; with many samples per pixel, the reference),
    /// `ray-cones` (prefiltered lookups over ray-cone footprints,
    /// Akenine-Möller et al. 2021) or `covariance` (prefiltered lookups over
    /// covariance footprints carried along the path). The lookups are
    /// trilinear probes along the footprint's major axis (EWA is the
    /// reference lookup of the tests and benchmarks).
    #[arg(long)]
    pub(crate) filter: Option<FilterMode>,
    /// Caustic rays per light and light sample (overrides `caustics.rays`; 0
    /// switches the caustic passes off).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(0..=16_777_216))]
    pub(crate) caustic_rays: Option<u32>,
    /// Points on each sphere light that emit caustic rays (overrides
    /// `caustics.light_samples`).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=1024))]
    pub(crate) caustic_light_samples: Option<u32>,
    /// Camera rays per pixel and render sample of the volume pass (overrides
    /// `volume.samples`; 0 switches the volume pass off).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(0..=65536))]
    pub(crate) volume_samples: Option<u32>,
    /// Denoise the finished image with Intel Open Image Denoise (overrides
    /// `image.denoise`; the `preview` and `interactive` presets denoise).
    /// The PNG and the EXR's RGB show the denoised image; the EXR keeps the
    /// raw radiance as `noisy.RGB`. Needs the library (`make setup`
    /// installs it); without it the command fails before rendering.
    #[arg(long, overrides_with = "no_denoise")]
    pub(crate) denoise: bool,
    /// Do not denoise (overrides `image.denoise` and the preset).
    #[arg(long, overrides_with = "denoise")]
    pub(crate) no_denoise: bool,
    /// The denoiser's quality (overrides `image.denoise_quality`): `fast`,
    /// `balanced` or `high` (the default: the best network, 2-6x the time
    /// of `fast`).
    #[arg(long)]
    pub(crate) denoise_quality: Option<quadray::jobs::denoise::DenoiseQuality>,
}

impl QualityArgs {
    /// Applies the preset, then the single overrides, to `scene`.
    pub(crate) fn apply(&self, scene: &mut Scene) {
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
        q.denoise = (q.denoise || self.denoise) && !self.no_denoise;
        scene.set_quality(q);
        scene.image.denoise_quality = self.denoise_quality.unwrap_or(scene.image.denoise_quality);
    }
}

/// Reads `path` (or the built-in default scene when `None`).
pub(crate) fn read_scene(path: Option<&Path>) -> Result<Scene> {
    Ok(match path {
        Some(path) => load_scene(path)?,
        None => parse_scene(DEFAULT_SCENE, DEFAULT_SCENE_NAME)?,
    })
}

/// `--kernel`: how the render pass runs its paths.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum KernelChoice {
    /// The faster on this backend (docs/benchmarks.md, "Megakernel and
    /// wavefront").
    #[default]
    Auto,
    /// One invocation runs a whole path.
    Megakernel,
    /// Stage kernels over queues of paths (ray queries only).
    Wavefront,
}

impl KernelChoice {
    /// The render variant's kernel (`None`: auto).
    pub(crate) fn kernel(self) -> Option<quadray::passes::PathKernel> {
        use quadray::passes::PathKernel;
        match self {
            KernelChoice::Auto => None,
            KernelChoice::Megakernel => Some(PathKernel::Megakernel),
            KernelChoice::Wavefront => Some(PathKernel::Wavefront),
        }
    }
}

/// `--backend`: how rays are traced.
#[derive(clap::ValueEnum, Clone, Copy, Debug, Default, PartialEq, Eq)]
pub(crate) enum BackendChoice {
    /// Ray queries where the device has them, else a ray-tracing pipeline.
    #[default]
    Auto,
    /// Compute shaders with ray queries (VK_KHR_ray_query).
    RayQuery,
    /// A ray-tracing pipeline with the intersection shader
    /// (VK_KHR_ray_tracing_pipeline) for every tracing pass.
    Pipeline,
}

impl BackendChoice {
    /// The backend on `device`; `pipeline` on a device without ray-tracing
    /// pipelines is an error.
    pub(crate) fn resolve(self, device: &quadray::vk::Device) -> Result<quadray::vk::Backend> {
        use quadray::vk::Backend;
        match self {
            BackendChoice::Auto if device.offers(Backend::RayQuery) => Ok(Backend::RayQuery),
            BackendChoice::Auto => Ok(Backend::Pipeline),
            BackendChoice::RayQuery if device.offers(Backend::RayQuery) => Ok(Backend::RayQuery),
            BackendChoice::RayQuery => anyhow::bail!(
                "{} offers no ray queries (VK_KHR_ray_query); `--backend pipeline` traces through ray-tracing \
                 pipelines instead",
                device.name
            ),
            BackendChoice::Pipeline if device.offers(Backend::Pipeline) => Ok(Backend::Pipeline),
            BackendChoice::Pipeline => anyhow::bail!(
                "{} offers no ray-tracing pipelines (VK_KHR_ray_tracing_pipeline); `quadray devices` lists what \
                 each device offers",
                device.name
            ),
        }
    }
}
