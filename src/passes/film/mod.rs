//! The film: what a render accumulates and what it produces, for the pixels
//! of its bounds. `RenderOutput` is the image with its AOVs and reports;
//! `Accumulation` the state between samples that a checkpoint stores and a
//! resumed render goes on from; `PixelBounds` (`bounds.rs`) the part of the
//! frame rendered. The render pass fills them, checkpoints store them and
//! `output` writes them, so none of those needs another.

pub mod bounds;

pub use bounds::{BoundsError, PixelBounds, TileIndex};

use super::gpu::GpuAov;
use crate::vk::Backend;

/// What the caustic passes did, and how long they took (a render's
/// output carries it; `passes::caustics` fills it).
#[derive(Clone, Debug, Default)]
pub struct CausticReport {
    /// Caustic rays traced (all grids).
    pub rays: u64,
    /// Rays that landed on a diffuse receiver after a specular vertex.
    pub landed: u64,
    /// Emission grids (lights × light samples).
    pub grids: usize,
    /// GPU time of the G-buffer pass (s).
    pub gbuffer_seconds: f64,
    /// GPU time of the caustic-ray pass (s).
    pub trace_seconds: f64,
    /// GPU time of the caustic-cell splat pass (s).
    pub splat_seconds: f64,
    /// GPU time of the volumetric-caustic (beam) pass (s); 0 without fog.
    pub beam_seconds: f64,
    /// Caustic irradiance per pixel (W/m², RGB) at the pixel-centre receiver.
    pub irradiance: Vec<[f32; 3]>,
}

impl CausticReport {
    /// Total GPU time of the caustic passes (s).
    pub fn seconds(&self) -> f64 {
        self.gbuffer_seconds + self.trace_seconds + self.splat_seconds + self.beam_seconds
    }
}

/// What a render produces: linear radiance and AOVs, row 0 at the top, for
/// the pixels of `bounds` (the whole frame, or a crop or tile of it).
pub struct RenderOutput {
    /// Width in pixels (of `bounds`).
    pub width: u32,
    /// Height in pixels (of `bounds`).
    pub height: u32,
    /// The part of the frame the image covers.
    pub bounds: PixelBounds,
    /// The whole frame's width and height.
    pub frame_size: (u32, u32),
    /// Mean radiance per pixel (linear RGB).
    pub radiance: Vec<[f32; 3]>,
    /// The radiance denoised (Intel Open Image Denoise, `crate::jobs::denoise`),
    /// when the render was: the PNG and the EXR's RGB show it, and
    /// `radiance` stays beside it as the EXR's `noisy.RGB`.
    pub denoised: Option<Vec<[f32; 3]>>,
    /// Depth, normal, albedo and object per pixel from the pixel-centre ray,
    /// and the denoiser's albedo and normal averaged over the samples.
    pub aov: Vec<GpuAov>,
    /// Samples per pixel taken (every pixel has at least this many; an
    /// interrupted render's pixels in the tiles of its next sample that
    /// finished have one more, see `partial_tiles`).
    pub spp: u32,
    /// Tiles of sample `spp` that were finished when the render stopped
    /// (0 for a render that ran to the end).
    pub partial_tiles: u32,
    /// GPU time of the work in seconds (timestamps), the caustic and volume
    /// passes included.
    pub seconds: f64,
    /// GPU time of the render pass alone (the samples) in seconds.
    pub render_seconds: f64,
    /// What the caustic passes did, when they ran.
    pub caustics: Option<CausticReport>,
    /// GPU time of the volume pass (s), when it ran.
    pub volume_seconds: Option<f64>,
    /// Samples whose radiance came out NaN or infinite, counted as black
    /// (0 in every test; the CLI warns otherwise).
    pub dropped_samples: u64,
    /// The largest single sample per pixel: its luminance (Rec. 709 Y of
    /// the sample's linear radiance) and the sample index that brought it
    /// (empty for an image read from a file). The outlier report compares it
    /// with the bound the scene allows (`passes::outliers`).
    pub max_sample: Vec<[f32; 2]>,
    /// The backend every tracing pass ran on (`None` for an image read from
    /// a file).
    pub backend: Option<Backend>,
    /// Where the wavefront pass's GPU time went, stage by stage (`None`
    /// when the megakernel ran, or for an image read from a file).
    pub wave_profile: Option<crate::passes::wavefront::WaveProfile>,
}

impl RenderOutput {
    /// The image to show: the denoised radiance when there is one, else
    /// the radiance.
    pub fn shown(&self) -> &[[f32; 3]] {
        self.denoised.as_deref().unwrap_or(&self.radiance)
    }

    /// An image without render data (AOVs, times): one read from a file.
    pub fn from_radiance(width: u32, height: u32, radiance: Vec<[f32; 3]>) -> Self {
        Self {
            width,
            height,
            bounds: PixelBounds::full(width, height),
            frame_size: (width, height),
            radiance,
            denoised: None,
            aov: vec![],
            spp: 0,
            partial_tiles: 0,
            seconds: 0.0,
            render_seconds: 0.0,
            caustics: None,
            volume_seconds: None,
            dropped_samples: 0,
            max_sample: vec![],
            backend: None,
            wave_profile: None,
        }
    }
}

/// The state of a render that can go on later: what
/// [`crate::passes::Renderer::accumulation`] reads and [`crate::passes::Renderer::restore`]
/// uploads.
#[derive(Clone, Debug, PartialEq)]
pub struct Accumulation {
    /// The whole frame's width and height.
    pub frame_size: (u32, u32),
    /// The pixels rendered.
    pub bounds: PixelBounds,
    /// Samples per pixel completed.
    pub samples: u32,
    /// Tiles of sample `samples` completed.
    pub partial_tiles: u32,
    /// GPU time of the samples so far (s).
    pub render_seconds: f64,
    /// Per pixel of `bounds`: the radiance sums and the finite-sample count.
    pub sums: Vec<[f32; 4]>,
    /// Per pixel: the largest sample's luminance and index.
    pub max_sample: Vec<[f32; 2]>,
    /// Per pixel: the AOVs of the pixel-centre ray, and the denoiser's
    /// features summed over the samples.
    pub aov: Vec<GpuAov>,
}

/// A sum over `count` samples divided by their count (a pixel without
/// samples keeps its sum, zero).
fn mean_of(sum: [f32; 3], count: u32) -> [f32; 3] {
    let n = count.max(1) as f32;
    sum.map(|v| v / n)
}

impl Accumulation {
    /// The image of the work so far, `counts[i]` samples in pixel i (dropped
    /// samples black); times and pass reports are left empty.
    pub fn into_output(self, counts: &[u32]) -> RenderOutput {
        let radiance = self.sums.iter().zip(counts).map(|(s, &c)| mean_of([s[0], s[1], s[2]], c)).collect();
        // The denoiser's features are sums over the samples on the GPU.
        let aov = self
            .aov
            .iter()
            .zip(counts)
            .map(|(a, &c)| GpuAov {
                denoise_albedo: mean_of(a.denoise_albedo, c),
                denoise_normal: mean_of(a.denoise_normal, c),
                ..*a
            })
            .collect();
        let dropped_samples =
            self.sums.iter().zip(counts).map(|(s, &c)| (c as f64 - s[3] as f64).round().max(0.0) as u64).sum();
        RenderOutput {
            width: self.bounds.width(),
            height: self.bounds.height(),
            bounds: self.bounds,
            frame_size: self.frame_size,
            radiance,
            denoised: None,
            aov,
            spp: self.samples,
            partial_tiles: self.partial_tiles,
            seconds: self.render_seconds,
            render_seconds: self.render_seconds,
            caustics: None,
            volume_seconds: None,
            dropped_samples,
            max_sample: self.max_sample,
            backend: None,
            wave_profile: None,
        }
    }
}
