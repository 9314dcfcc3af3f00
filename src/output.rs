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

fn temporary_path(path: &Path) -> io::Result<PathBuf> {
    let name = path
        .file_name()
        .ok_or_else(|| io::Error::new(io::ErrorKind::InvalidInput, format!("{} has no file name", path.display())))?;
    Ok(path.with_file_name(format!(".{}.tmp-{}", name.to_string_lossy(), std::process::id())))
}

/// Writes several files all or nothing: `write(i, tmp)` fills a temporary
/// file beside `paths[i]`, and only when all are written are they renamed
/// into place. On error every temporary file is removed, and the error names
/// the file that failed.
pub fn write_all_or_nothing(paths: &[PathBuf], write: impl Fn(usize, &Path) -> io::Result<()>) -> io::Result<()> {
    let named = |path: &Path, e: io::Error| io::Error::new(e.kind(), format!("cannot write {}: {e}", path.display()));
    let mut temporaries = Vec::new();
    let result = (|| {
        for (i, path) in paths.iter().enumerate() {
            let tmp = temporary_path(path)?;
            temporaries.push(tmp.clone());
            write(i, &tmp).map_err(|e| named(path, e))?;
        }
        // A destination that cannot be replaced fails the whole set before any
        // file is renamed into place.
        if let Some(dir) = paths.iter().find(|p| p.is_dir()) {
            return Err(named(dir, io::Error::new(io::ErrorKind::IsADirectory, "a directory is in the way")));
        }
        for (path, tmp) in paths.iter().zip(&temporaries) {
            std::fs::rename(tmp, path).map_err(|e| named(path, e))?;
        }
        Ok(())
    })();
    if result.is_err() {
        for tmp in &temporaries {
            let _ = std::fs::remove_file(tmp);
        }
    }
    result
}

/// Writes the render to every file of `files`, all or nothing.
pub fn write_outputs(out: &RenderOutput, files: &[(PathBuf, OutputKind)]) -> io::Result<()> {
    let paths: Vec<PathBuf> = files.iter().map(|(p, _)| p.clone()).collect();
    write_all_or_nothing(&paths, |i, tmp| match files[i].1 {
        OutputKind::Png { exposure } => write_png_to(out, exposure, tmp),
        OutputKind::Exr(precision) => write_exr_to(out, precision, tmp),
    })
}

/// 8-bit sRGB pixels: radiance · 2^exposure, clamped to [0, 1], encoded.
pub fn tone_map(out: &RenderOutput, exposure: f32) -> Vec<u8> {
    let scale = exposure.exp2();
    out.radiance
        .iter()
        .flat_map(|p| p.map(|v| (crate::texture::linear_to_srgb((v * scale).clamp(0.0, 1.0)) * 255.0 + 0.5) as u8))
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

fn write_png_to(out: &RenderOutput, exposure: f32, path: &Path) -> io::Result<()> {
    let pixels = tone_map(out, exposure);
    image::save_buffer_with_format(
        path,
        &pixels,
        out.width,
        out.height,
        image::ColorType::Rgb8,
        image::ImageFormat::Png,
    )
    .map_err(io::Error::other)
}

/// Writes the linear EXR (not atomically): RGB radiance and the AOVs `depth`
/// (distance along the normalised pixel-centre ray, +inf on a miss),
/// `normal.XYZ` (world space, zero on a miss) and `albedo.RGB`, and, when
/// the render has it, the largest-sample AOV `max_sample.Y` (the luminance of
/// the pixel's largest single sample) and `max_sample.index` (which sample
/// it was; always 32-bit).
pub fn write_exr_to(out: &RenderOutput, precision: ExrPrecision, path: &Path) -> io::Result<()> {
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
    let mut channels: SmallVec<[AnyChannel<FlatSamples>; 4]> = EXR_CHANNELS
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
    if !out.max_sample.is_empty() {
        let [y, index] = EXR_MAX_SAMPLE_CHANNELS;
        channels.push(AnyChannel::new(y, FlatSamples::F32(out.max_sample.iter().map(|m| m[0]).collect())));
        channels.push(AnyChannel::new(index, FlatSamples::F32(out.max_sample.iter().map(|m| m[1]).collect())));
    }
    let image = Image::from_channels((out.width as usize, out.height as usize), AnyChannels::sort(channels));
    image.write().to_file(path).map_err(io::Error::other)
}
