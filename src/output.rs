//! Image files: tone-mapped sRGB PNG and linear EXR with AOV channels.
//! Every file is written to a temporary name beside its destination and
//! renamed into place, so a failed or interrupted write leaves no partial file.

use std::io;
use std::path::{Path, PathBuf};

use exr::prelude::{f16, AnyChannel, AnyChannels, FlatSamples, Image, SmallVec, WritableImage};

use crate::passes::RenderOutput;

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

/// Writes `path` atomically: `write` fills a temporary file beside it, which
/// is then renamed over `path`; on error the temporary file is removed.
pub fn write_atomically(path: &Path, write: impl FnOnce(&Path) -> io::Result<()>) -> io::Result<()> {
    let name = path.file_name().ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, "no file name"))?;
    let tmp: PathBuf = path.with_file_name(format!(".{}.tmp-{}", name.to_string_lossy(), std::process::id()));
    let result = write(&tmp).and_then(|_| std::fs::rename(&tmp, path));
    if result.is_err() {
        let _ = std::fs::remove_file(&tmp);
    }
    result
}

/// sRGB transfer function of a linear value in [0, 1].
fn srgb_encode(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// 8-bit sRGB pixels: radiance · 2^exposure, clamped to [0, 1], encoded.
pub fn tone_map(out: &RenderOutput, exposure: f32) -> Vec<u8> {
    let scale = exposure.exp2();
    out.radiance
        .iter()
        .flat_map(|p| p.map(|v| (srgb_encode((v * scale).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8))
        .collect()
}

/// Writes the tone-mapped PNG.
pub fn write_png(out: &RenderOutput, exposure: f32, path: &Path) -> io::Result<()> {
    let pixels = tone_map(out, exposure);
    write_atomically(path, |tmp| {
        image::save_buffer_with_format(
            tmp,
            &pixels,
            out.width,
            out.height,
            image::ColorType::Rgb8,
            image::ImageFormat::Png,
        )
        .map_err(io::Error::other)
    })
}

/// Writes the linear EXR: RGB radiance and the AOVs `depth` (distance along
/// the normalised pixel-centre ray, +inf on a miss), `normal.XYZ` (world
/// space, zero on a miss) and `albedo.RGB`.
pub fn write_exr(out: &RenderOutput, precision: ExrPrecision, path: &Path) -> io::Result<()> {
    let columns: [Vec<f32>; 10] = [
        out.radiance.iter().map(|p| p[0]).collect(),
        out.radiance.iter().map(|p| p[1]).collect(),
        out.radiance.iter().map(|p| p[2]).collect(),
        out.aov.iter().map(|a| a.depth).collect(),
        out.aov.iter().map(|a| a.normal[0]).collect(),
        out.aov.iter().map(|a| a.normal[1]).collect(),
        out.aov.iter().map(|a| a.normal[2]).collect(),
        out.aov.iter().map(|a| a.albedo[0]).collect(),
        out.aov.iter().map(|a| a.albedo[1]).collect(),
        out.aov.iter().map(|a| a.albedo[2]).collect(),
    ];
    let channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = EXR_CHANNELS
        .iter()
        .zip(columns)
        .map(|(name, values)| {
            let samples = match precision {
                ExrPrecision::Float => FlatSamples::F32(values),
                ExrPrecision::Half => FlatSamples::F16(values.into_iter().map(f16::from_f32).collect()),
            };
            AnyChannel::new(*name, samples)
        })
        .collect();
    let image = Image::from_channels((out.width as usize, out.height as usize), AnyChannels::sort(channels));
    write_atomically(path, |tmp| image.write().to_file(tmp).map_err(io::Error::other))
}
