//! Image files: tone-mapped sRGB PNG and linear EXR with AOV channels.
//! Every file is written to a temporary name beside its destination and
//! renamed into place, so a failed or interrupted write leaves no partial file.

use std::io;
use std::path::{Path, PathBuf};

use exr::prelude::{
    f16, AnyChannel, AnyChannels, AttributeValue, Encoding, FlatSamples, Image, IntegerBounds, Layer, LayerAttributes,
    SmallVec, Text, Vec2, WritableImage,
};

use crate::passes::RenderOutput;
pub use crate::util::files::{frame_path, write_all_or_nothing, write_file_atomically};

/// Sample precision of the EXR's channels.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum ExrPrecision {
    /// 16-bit floats.
    Half,
    /// 32-bit floats.
    Float,
}

/// The EXR channel names, in the order they are written.
pub const EXR_CHANNELS: [&str; 10] =
    ["R", "G", "B", "depth", "normal.X", "normal.Y", "normal.Z", "albedo.R", "albedo.G", "albedo.B"];

/// The denoiser's features (`GpuAov::denoise_albedo`, `denoise_normal`:
/// at the first non-specular vertex, averaged over the samples), written
/// with every render that has AOVs; `quadray denoise` reads them.
pub const EXR_DENOISE_CHANNELS: [&str; 6] = [
    "denoise_albedo.R",
    "denoise_albedo.G",
    "denoise_albedo.B",
    "denoise_normal.X",
    "denoise_normal.Y",
    "denoise_normal.Z",
];

/// The raw radiance of a denoised render (its RGB is the denoised image).
pub const EXR_NOISY_CHANNELS: [&str; 3] = ["noisy.R", "noisy.G", "noisy.B"];

/// The largest-sample AOV's EXR channels, written when the render has it:
/// the luminance of the pixel's largest single sample and that sample's
/// index.
pub const EXR_MAX_SAMPLE_CHANNELS: [&str; 2] = ["max_sample.Y", "max_sample.index"];

/// What to write to one output file.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum OutputKind {
    /// Tone-mapped 8-bit sRGB PNG with this exposure (stops).
    Png {
        /// Exposure in stops.
        exposure: f32,
    },
    /// Linear EXR with AOVs.
    Exr(ExrPrecision),
}

/// Writes the render to every file of `files`, all or nothing.
pub fn write_outputs(out: &RenderOutput, files: &[(PathBuf, OutputKind)]) -> io::Result<()> {
    write_outputs_with(out, files, &[])
}

/// [`write_outputs`] with metadata: `(name, value)` pairs written as PNG
/// text chunks and as lines of the EXR attribute
/// [`EXR_METADATA_ATTRIBUTE`] (names as in [`METADATA_SPP`]).
pub fn write_outputs_with(
    out: &RenderOutput,
    files: &[(PathBuf, OutputKind)],
    metadata: &[(String, String)],
) -> io::Result<()> {
    let paths: Vec<PathBuf> = files.iter().map(|(p, _)| p.clone()).collect();
    write_all_or_nothing(&paths, |i, tmp| match files[i].1 {
        OutputKind::Png { exposure } => write_png_to(out, exposure, metadata, tmp),
        OutputKind::Exr(precision) => write_exr_to(out, precision, metadata, tmp),
    })
}

/// The EXR string attribute that holds the metadata, one `name=value`
/// line per entry (PNGs get one text chunk per entry).
pub const EXR_METADATA_ATTRIBUTE: &str = "quadray.metadata";

/// Metadata name: the samples per pixel every pixel has.
pub const METADATA_SPP: &str = "quadray.spp";
/// Metadata name: the samples per pixel the render was asked for.
pub const METADATA_TARGET_SPP: &str = "quadray.target_spp";
/// Metadata name: the exposure (stops) of the PNG.
pub const METADATA_EXPOSURE: &str = "quadray.exposure";
/// Metadata name: the random seed.
pub const METADATA_SEED: &str = "quadray.seed";
/// Metadata name: the frame number (renders of a frame range).
pub const METADATA_FRAME: &str = "quadray.frame";
/// Metadata name: the backend every tracing pass ran on (`ray-query` or
/// `pipeline`).
pub const METADATA_BACKEND: &str = "quadray.backend";
/// Metadata name: the Vulkan device that rendered.
pub const METADATA_DEVICE: &str = "quadray.device";
/// Metadata name: its driver and version ("llvmpipe: Mesa 26.2.6-1 (LLVM
/// 22.1.8)"): which Mesa and LLVM ran.
pub const METADATA_DRIVER: &str = "quadray.driver";
/// Metadata name: how the image was denoised (library, version, quality,
/// time), when it was: its RGB is the denoised image, `noisy.RGB` the raw.
pub const METADATA_DENOISED: &str = "quadray.denoised";
/// Metadata name: the hash of the scene and the settings
/// (`passes::checkpoint::render_key`, 16 hex digits); tiles merge only
/// with tiles of the same.
pub const METADATA_SCENE_KEY: &str = "quadray.scene_key";

/// 8-bit sRGB pixels: radiance (the denoised radiance where the render has
/// it) · 2^exposure, clamped to [0, 1], encoded.
pub fn tone_map(out: &RenderOutput, exposure: f32) -> Vec<u8> {
    let scale = exposure.exp2();
    out.shown()
        .iter()
        .flat_map(|p| {
            p.map(|v| (crate::model::texture::linear_to_srgb((v * scale).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8)
        })
        .collect()
}

/// Writes the tone-mapped PNG atomically.
pub fn write_png(out: &RenderOutput, exposure: f32, path: &Path) -> io::Result<()> {
    write_outputs(out, &[(path.to_path_buf(), OutputKind::Png { exposure })])
}

/// Writes the linear EXR atomically (see [`write_exr_to`] for its channels).
pub fn write_exr(out: &RenderOutput, precision: ExrPrecision, path: &Path) -> io::Result<()> {
    write_outputs(out, &[(path.to_path_buf(), OutputKind::Exr(precision))])
}

fn write_png_to(out: &RenderOutput, exposure: f32, metadata: &[(String, String)], path: &Path) -> io::Result<()> {
    let pixels = tone_map(out, exposure);
    let file = io::BufWriter::new(std::fs::File::create(path)?);
    let mut encoder = png::Encoder::new(file, out.width, out.height);
    encoder.set_color(png::ColorType::Rgb);
    encoder.set_depth(png::BitDepth::Eight);
    for (name, value) in metadata {
        encoder.add_text_chunk(name.clone(), value.clone()).map_err(io::Error::other)?;
    }
    let mut writer = encoder.write_header().map_err(io::Error::other)?;
    writer.write_image_data(&pixels).map_err(io::Error::other)?;
    writer.finish().map_err(io::Error::other)
}

/// Writes the linear EXR (not atomically): RGB radiance (the denoised
/// radiance when the render has it, the raw one then in `noisy.RGB`), the
/// AOVs `depth` (distance along the normalised pixel-centre ray, +inf on a
/// miss), `normal.XYZ` (world space, zero on a miss) and `albedo.RGB`, the
/// denoiser's features `denoise_albedo.RGB` and `denoise_normal.XYZ`, and, when
/// the render has it, the largest-sample AOV `max_sample.Y` (the luminance of
/// the pixel's largest single sample) and `max_sample.index` (which sample
/// it was; always 32-bit). The data window is the render's pixel bounds
/// and the display window the whole frame, so that tools place a crop or
/// tile (OpenImageIO's `oiiotool --paste`, `quadray merge`); `metadata`
/// becomes string attributes.
pub fn write_exr_to(
    out: &RenderOutput,
    precision: ExrPrecision,
    metadata: &[(String, String)],
    path: &Path,
) -> io::Result<()> {
    let shown = out.shown();
    let columns: [Vec<f32>; 10] = [
        shown.iter().map(|p| p[0]).collect(),
        shown.iter().map(|p| p[1]).collect(),
        shown.iter().map(|p| p[2]).collect(),
        out.aov.iter().map(|a| a.depth).collect(),
        out.aov.iter().map(|a| a.normal[0]).collect(),
        out.aov.iter().map(|a| a.normal[1]).collect(),
        out.aov.iter().map(|a| a.normal[2]).collect(),
        out.aov.iter().map(|a| a.albedo[0]).collect(),
        out.aov.iter().map(|a| a.albedo[1]).collect(),
        out.aov.iter().map(|a| a.albedo[2]).collect(),
    ];
    let column = |values: Vec<f32>| match precision {
        ExrPrecision::Float => FlatSamples::F32(values),
        ExrPrecision::Half => FlatSamples::F16(values.into_iter().map(f16::from_f32).collect()),
    };
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> =
        EXR_CHANNELS.iter().zip(columns).map(|(name, values)| AnyChannel::new(*name, column(values))).collect();
    if !out.aov.is_empty() {
        for (k, name) in EXR_DENOISE_CHANNELS.iter().enumerate() {
            let values = out.aov.iter().map(|a| if k < 3 { a.denoise_albedo[k] } else { a.denoise_normal[k - 3] });
            channels.push(AnyChannel::new(*name, column(values.collect())));
        }
    }
    if out.denoised.is_some() {
        for (k, name) in EXR_NOISY_CHANNELS.iter().enumerate() {
            channels.push(AnyChannel::new(*name, column(out.radiance.iter().map(|p| p[k]).collect())));
        }
    }
    if !out.max_sample.is_empty() {
        let [y, index] = EXR_MAX_SAMPLE_CHANNELS;
        channels.push(AnyChannel::new(y, FlatSamples::F32(out.max_sample.iter().map(|m| m[0]).collect())));
        channels.push(AnyChannel::new(index, FlatSamples::F32(out.max_sample.iter().map(|m| m[1]).collect())));
    }
    let mut attributes =
        LayerAttributes { layer_position: Vec2(out.bounds.x0 as i32, out.bounds.y0 as i32), ..Default::default() };
    if !metadata.is_empty() {
        // One attribute: the crate keeps attributes in a hash map, whose
        // order (and so the file's bytes) would change from run to run.
        let lines: String = metadata.iter().map(|(k, v)| format!("{k}={v}\n")).collect();
        let text = Text::new_or_none(&lines).ok_or_else(|| io::Error::other(format!("{lines:?} is not EXR text")))?;
        attributes.other.insert(Text::from(EXR_METADATA_ATTRIBUTE), AttributeValue::Text(text));
    }
    let layer = Layer::new(
        (out.width as usize, out.height as usize),
        attributes,
        Encoding::default(),
        AnyChannels::sort(channels),
    );
    let mut image = Image::from_layer(layer);
    image.attributes.display_window =
        IntegerBounds::new((0, 0), (out.frame_size.0 as usize, out.frame_size.1 as usize));
    // In one thread: parallel compression writes the blocks in the order
    // they finish, so the same image would give different files.
    image.write().non_parallel().to_file(path).map_err(io::Error::other)
}

/// An EXR that [`write_exr_to`] wrote, read back: its channels, data and
/// display windows and string attributes.
pub struct ExrFile {
    /// The render (radiance and, where present, the AOVs), with its pixel
    /// bounds and frame size from the data and display windows.
    pub output: RenderOutput,
    /// The string attributes (metadata).
    pub metadata: Vec<(String, String)>,
}

/// Reads an EXR written by [`write_exr_to`] (RGB and the AOV channels):
/// `radiance` is the raw radiance (`noisy.RGB` of a denoised render, whose
/// RGB becomes `denoised`); the denoiser's features are zero when absent.
pub fn read_render_exr(path: &Path) -> io::Result<ExrFile> {
    use exr::prelude::{read, ReadChannels as _, ReadLayers as _};
    let named = |e: String| io::Error::new(io::ErrorKind::InvalidData, format!("{}: {e}", path.display()));
    let image = read()
        .no_deep_data()
        .largest_resolution_level()
        .all_channels()
        .first_valid_layer()
        .all_attributes()
        .from_file(path)
        .map_err(|e| named(e.to_string()))?;
    let layer = &image.layer_data;
    let (w, h) = (layer.size.0, layer.size.1);
    let channel = |name: &str| -> Option<Vec<f32>> {
        let c = layer.channel_data.list.iter().find(|c| c.name.to_string() == name)?;
        Some(c.sample_data.values_as_f32().collect())
    };
    let required = |name: &str| channel(name).ok_or_else(|| named(format!("no channel {name}")));
    let [r, g, b] = [required("R")?, required("G")?, required("B")?];
    let rgb: Vec<[f32; 3]> = (0..w * h).map(|i| [r[i], g[i], b[i]]).collect();
    // A denoised render's RGB is the denoised image; its radiance is `noisy`.
    let noisy: Option<Vec<Vec<f32>>> = EXR_NOISY_CHANNELS.iter().map(|n| channel(n)).collect();
    let (radiance, denoised) = match noisy {
        Some(c) => ((0..w * h).map(|i| [c[0][i], c[1][i], c[2][i]]).collect(), Some(rgb)),
        None => (rgb, None),
    };
    let aov_channels: Option<Vec<Vec<f32>>> = EXR_CHANNELS[3..].iter().map(|n| channel(n)).collect();
    let features: Option<Vec<Vec<f32>>> = EXR_DENOISE_CHANNELS.iter().map(|n| channel(n)).collect();
    let aov = aov_channels.map_or(Vec::new(), |c| {
        (0..w * h)
            .map(|i| {
                let f = |k: usize| features.as_ref().map_or(0.0, |f| f[k][i]);
                crate::passes::gpu::GpuAov {
                    depth: c[0][i],
                    normal: [c[1][i], c[2][i], c[3][i]],
                    albedo: [c[4][i], c[5][i], c[6][i]],
                    object: 0,
                    denoise_albedo: [f(0), f(1), f(2)],
                    denoise_normal: [f(3), f(4), f(5)],
                }
            })
            .collect()
    });
    let [my, mi] = EXR_MAX_SAMPLE_CHANNELS;
    let max_sample = match (channel(my), channel(mi)) {
        (Some(y), Some(i)) => y.into_iter().zip(i).map(|(y, i)| [y, i]).collect(),
        _ => Vec::new(),
    };
    let display = image.attributes.display_window;
    let position = layer.attributes.layer_position;
    if position.0 < 0 || position.1 < 0 || display.position.0 != 0 || display.position.1 != 0 {
        return Err(named("data or display window not at non-negative pixel coordinates".into()));
    }
    let frame_size = (display.size.0 as u32, display.size.1 as u32);
    let (x0, y0) = (position.0 as u32, position.1 as u32);
    let bounds = crate::passes::PixelBounds { x0, x1: x0 + w as u32, y0, y1: y0 + h as u32 }
        .check(frame_size.0, frame_size.1)
        .map_err(|e| named(e.to_string()))?;
    let metadata: Vec<(String, String)> = match layer.attributes.other.get(&Text::from(EXR_METADATA_ATTRIBUTE)) {
        Some(AttributeValue::Text(t)) => t
            .to_string()
            .lines()
            .filter_map(|l| l.split_once('='))
            .map(|(k, v)| (k.to_string(), v.to_string()))
            .collect(),
        _ => Vec::new(),
    };
    let mut output = RenderOutput::from_radiance(w as u32, h as u32, radiance);
    output.denoised = denoised;
    output.bounds = bounds;
    output.frame_size = frame_size;
    output.aov = aov;
    output.max_sample = max_sample;
    output.spp = metadata.iter().find(|(k, _)| k == METADATA_SPP).and_then(|(_, v)| v.parse().ok()).unwrap_or(0);
    Ok(ExrFile { output, metadata })
}
