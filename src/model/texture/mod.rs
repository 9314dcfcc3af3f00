//! Texture maps on the CPU: loading image files, generating procedural maps,
//! resampling to power-of-two sizes and building mip chains. Every function
//! returns a [`TextureImage`] in linear RGBA with its full mip chain, ready to
//! upload.
//!
//! # Files
//!
//! [`load_texture`] reads PNG and JPEG (8 or 16 bits per channel, through the
//! `image` crate) and OpenEXR (through the `exr` crate), chosen by the file's
//! contents when they are recognisable and by its extension otherwise
//! (`.png`, `.jpg`/`.jpeg`, `.exr`, any case).
//!
//! * **Encoding.** Colour maps ([`TextureUsage::Color`], the albedo) in PNG
//!   and JPEG are sRGB-encoded and are decoded to linear with the exact sRGB
//!   transfer function ([`srgb_to_linear`]). Data maps ([`TextureUsage::Data`]:
//!   normal, roughness, displacement) are taken as stored: 8- and 16-bit values
//!   map linearly to [0, 1]. EXR files hold linear values and are never
//!   decoded, whatever the usage. Alpha is always linear.
//! * **Channels.** A grey image is replicated to RGB; a grey + alpha or RGBA
//!   image keeps its alpha in the fourth component, which is 1 otherwise. An
//!   EXR file is read from its first layer: channels `R`, `G`, `B` (and `A`),
//!   or a single `Y` channel, or any one channel (with an optional `A`). A
//!   normal map needs at least three channels; roughness and displacement maps
//!   use the R channel of whatever is stored (the grey value of a grey image).
//! * **Size.** Each side must be from 1 to [`MAX_TEXTURE_SIZE`] texels; the
//!   size is read from the file's header before the pixels are decoded, so an
//!   oversized file is rejected without allocating it.
//! * **Non-power-of-two sizes** are resampled up to the next power of two on
//!   each axis by bilinear filtering with wrap-around, since textures repeat
//!   ([`resample_to_power_of_two`]): a 3 x 5 image becomes 4 x 8. An axis that
//!   is already a power of two is left alone.
//!
//! # Conventions
//!
//! Row 0 of every level is the top of the image, at v = 0; u grows along a
//! row and v down the rows. A tangent-space normal map stores (n + 1) / 2 in
//! RGB, where n's x component points along +u, y along +v and z out of the
//! surface. Mip levels average texels in linear space, so a normal fetched
//! from a coarse level is shorter than 1 and must be renormalised; filtered
//! lookups of normal and displacement maps go through their slope moments
//! instead ([`lean`]).

pub mod encoding;
pub mod environment;
pub mod lean;
mod procedural;
mod resample;

use std::io;
use std::path::{Path, PathBuf};

pub use procedural::{bump_heights, checker, normals_from_heights};
pub use resample::{build_mips, resample_to_power_of_two};

/// A texture with its mip chain, in linear RGBA (colour maps already
/// sRGB-decoded). Level 0 is `width` x `height` (powers of two); each next
/// level halves both, down to 1 x 1.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct TextureImage {
    /// Where it came from (a path, or a description of a generated texture).
    pub source: String,
    /// Width of level 0.
    pub width: u32,
    /// Height of level 0.
    pub height: u32,
    /// Texels of every level, row 0 at the top (v = 0), row-major.
    pub levels: Vec<Vec<[f32; 4]>>,
}

/// Largest accepted texture width or height, in texels.
pub const MAX_TEXTURE_SIZE: u32 = 16384;

/// How a map's stored values are to be read.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum TextureUsage {
    /// A colour (albedo): PNG and JPEG values are sRGB-decoded to linear.
    Color,
    /// Numbers (normals, roughness, heights): values are taken as stored.
    Data,
}

/// Which material map a texture is loaded for.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum TextureKind {
    /// Colour map multiplying the albedo (sRGB-decoded).
    Albedo,
    /// Tangent-space normal map: needs RGB.
    Normal,
    /// Roughness map: the R channel.
    Roughness,
    /// Height map for bump mapping: the R channel.
    Displacement,
}

impl TextureKind {
    /// How the map's values are read.
    pub fn usage(self) -> TextureUsage {
        match self {
            Self::Albedo => TextureUsage::Color,
            Self::Normal | Self::Roughness | Self::Displacement => TextureUsage::Data,
        }
    }

    /// The map's name in messages.
    pub fn name(self) -> &'static str {
        match self {
            Self::Albedo => "albedo map",
            Self::Normal => "normal map",
            Self::Roughness => "roughness map",
            Self::Displacement => "displacement map",
        }
    }

    /// Checks that a file with `channels` colour channels (alpha not counted)
    /// can serve as this kind of map.
    pub fn check_channels(self, path: &Path, channels: u32) -> Result<(), TextureError> {
        if self == Self::Normal && channels < 3 {
            return Err(TextureError::Channels { path: path.to_path_buf(), kind: self.name(), channels, needed: 3 });
        }
        Ok(())
    }
}

/// Why a texture file could not be loaded. Every message names the path.
#[derive(Debug, thiserror::Error)]
pub enum TextureError {
    /// There is no file at the path.
    #[error("{}: no such file", .path.display())]
    Missing {
        /// The path that was asked for.
        path: PathBuf,
    },
    /// The file exists but cannot be read.
    #[error("{}: cannot read the file: {source}", .path.display())]
    Read {
        /// The path.
        path: PathBuf,
        /// The I/O error.
        source: io::Error,
    },
    /// The file is not a valid image of its format.
    #[error("{}: not a valid {format} image: {message}", .path.display())]
    Corrupt {
        /// The path.
        path: PathBuf,
        /// `PNG`, `JPEG` or `EXR`.
        format: &'static str,
        /// The decoder's message.
        message: String,
    },
    /// An EXR texel is NaN or infinite, which would turn every pixel that
    /// sees it (through filtering, every pixel near it) into NaN.
    #[error("{}: texel ({x}, {y}) holds {value}; texture values must be finite", .path.display())]
    NonFinite {
        /// The path.
        path: PathBuf,
        /// Column of the first such texel.
        x: usize,
        /// Row of the first such texel (row 0 at the top).
        y: usize,
        /// The value found there.
        value: f32,
    },
    /// The file's format is not one of PNG, JPEG and EXR.
    #[error(
        "{}: unsupported texture format {what} (supported: PNG .png, JPEG .jpg/.jpeg, OpenEXR .exr)",
        .path.display()
    )]
    Unsupported {
        /// The path.
        path: PathBuf,
        /// What was found, e.g. "`.bmp`" or "(no extension)".
        what: String,
    },
    /// The EXR file has no channels that can be read as grey or RGB.
    #[error("{}: unsupported EXR channels {channels:?} (expected R, G, B [A], or a single channel such as Y)", .path.display())]
    ExrChannels {
        /// The path.
        path: PathBuf,
        /// The channel names found in the first layer.
        channels: Vec<String>,
    },
    /// The image has too few channels for the map.
    #[error(
        "{}: a {kind} needs {needed} colour channels (RGB) but the image has {channels}",
        .path.display()
    )]
    Channels {
        /// The path.
        path: PathBuf,
        /// The map, e.g. "normal map".
        kind: &'static str,
        /// Colour channels in the file (alpha not counted).
        channels: u32,
        /// Channels needed.
        needed: u32,
    },
    /// The image has no texels.
    #[error("{}: the image is empty ({width} x {height} texels)", .path.display())]
    Empty {
        /// The path.
        path: PathBuf,
        /// Width in the file.
        width: u64,
        /// Height in the file.
        height: u64,
    },
    /// The image is larger than [`MAX_TEXTURE_SIZE`] on a side.
    #[error(
        "{}: the image is {width} x {height} texels; a texture may be at most {MAX_TEXTURE_SIZE} on a side",
        .path.display()
    )]
    TooLarge {
        /// The path.
        path: PathBuf,
        /// Width in the file.
        width: u64,
        /// Height in the file.
        height: u64,
    },
}

/// A texture file as loaded, before any kind-specific check.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct LoadedTexture {
    /// The texture (level 0 resampled to powers of two, with its mips).
    pub image: TextureImage,
    /// Colour channels stored in the file: 1 for grey, 3 for RGB (alpha not
    /// counted).
    pub channels: u32,
    /// Whether the file has an alpha channel.
    pub has_alpha: bool,
}

/// Loads the image file at `path` as a `kind` map: decodes it (sRGB-decoding
/// albedo maps), checks it suits the map, resamples it to powers of two and
/// builds its mips. See the [module documentation](self) for the rules.
pub fn load_texture(path: &Path, kind: TextureKind) -> Result<TextureImage, TextureError> {
    let loaded = load_texture_file(path, kind.usage())?;
    kind.check_channels(path, loaded.channels)?;
    Ok(loaded.image)
}

/// Loads the image file at `path` read as `usage`, without the checks of a
/// particular map kind ([`TextureKind::check_channels`]).
pub fn load_texture_file(path: &Path, usage: TextureUsage) -> Result<LoadedTexture, TextureError> {
    match std::fs::metadata(path) {
        Ok(m) if m.is_file() => {}
        Ok(_) => {
            let source = io::Error::new(io::ErrorKind::InvalidInput, "not a regular file");
            return Err(TextureError::Read { path: path.to_path_buf(), source });
        }
        Err(e) if e.kind() == io::ErrorKind::NotFound => {
            return Err(TextureError::Missing { path: path.to_path_buf() })
        }
        Err(source) => return Err(TextureError::Read { path: path.to_path_buf(), source }),
    }
    let format = detect_format(path)?;
    let (width, height, texels, channels, has_alpha) = match format {
        Format::Png | Format::Jpeg => read_ldr(path, format, usage)?,
        Format::Exr => read_exr(path)?,
    };
    let image = from_texels(path.display().to_string(), width, height, texels);
    Ok(LoadedTexture { image, channels, has_alpha })
}

/// Reads an EXR image as it is (no resampling, no mips): width, height and
/// linear RGBA texels, row 0 at the top. Used to compare renders.
pub fn read_exr_image(path: &Path) -> Result<(u32, u32, Vec<[f32; 4]>), TextureError> {
    let (width, height, texels, _, _) = read_exr(path)?;
    Ok((width, height, texels))
}

/// A texture from level-0 texels in linear RGBA (row-major, row 0 at the
/// top): resamples non-power-of-two sizes up ([`resample_to_power_of_two`])
/// and builds the mip chain ([`build_mips`]).
///
/// # Panics
///
/// If `texels.len() != width * height` or a side is 0.
pub fn from_texels(source: String, width: u32, height: u32, texels: Vec<[f32; 4]>) -> TextureImage {
    let (width, height, texels) = resample_to_power_of_two(width, height, texels);
    TextureImage { source, width, height, levels: build_mips(width, height, texels) }
}

/// The sRGB opto-electronic transfer function: a linear value in [0, 1] to
/// its sRGB encoding.
pub fn linear_to_srgb(v: f32) -> f32 {
    if v <= 0.003_130_8 {
        12.92 * v
    } else {
        1.055 * v.powf(1.0 / 2.4) - 0.055
    }
}

/// The sRGB electro-optical transfer function: an sRGB-encoded value in
/// [0, 1] to linear.
pub fn srgb_to_linear(c: f32) -> f32 {
    let c = f64::from(c);
    let linear = if c <= 0.04045 { c / 12.92 } else { ((c + 0.055) / 1.055).powf(2.4) };
    linear as f32
}

#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
enum Format {
    Png,
    Jpeg,
    Exr,
}

impl Format {
    fn name(self) -> &'static str {
        match self {
            Self::Png => "PNG",
            Self::Jpeg => "JPEG",
            Self::Exr => "EXR",
        }
    }
}

/// The format from the file's first bytes if they are a known signature,
/// else from its extension.
fn detect_format(path: &Path) -> Result<Format, TextureError> {
    use io::Read as _;
    let mut magic = [0u8; 8];
    let mut n = 0;
    let mut file = std::fs::File::open(path).map_err(|source| TextureError::Read { path: path.into(), source })?;
    while n < magic.len() {
        match file.read(&mut magic[n..]) {
            Ok(0) => break,
            Ok(k) => n += k,
            Err(e) if e.kind() == io::ErrorKind::Interrupted => {}
            Err(source) => return Err(TextureError::Read { path: path.into(), source }),
        }
    }
    let magic = &magic[..n];
    let by_extension = match path.extension().and_then(|e| e.to_str()).map(str::to_ascii_lowercase).as_deref() {
        Some("png") => Ok(Format::Png),
        Some("jpg" | "jpeg") => Ok(Format::Jpeg),
        Some("exr") => Ok(Format::Exr),
        Some(other) => Err(format!("`.{other}`")),
        None => Err("(the file name has no extension)".to_owned()),
    };
    if magic.starts_with(b"\x89PNG\r\n\x1a\n") {
        Ok(Format::Png)
    } else if magic.starts_with(&[0xFF, 0xD8, 0xFF]) {
        Ok(Format::Jpeg)
    } else if magic.starts_with(&[0x76, 0x2F, 0x31, 0x01]) {
        Ok(Format::Exr)
    } else {
        by_extension.map_err(|what| TextureError::Unsupported { path: path.to_path_buf(), what })
    }
}

/// Whether an I/O error while decoding an opened file means that its contents
/// are bad (it ends early or holds invalid data) rather than that reading failed.
fn is_format_error(e: &io::Error) -> bool {
    matches!(e.kind(), io::ErrorKind::UnexpectedEof | io::ErrorKind::InvalidData)
}

fn check_size(path: &Path, width: u64, height: u64) -> Result<(), TextureError> {
    if width == 0 || height == 0 {
        return Err(TextureError::Empty { path: path.to_path_buf(), width, height });
    }
    let max = u64::from(MAX_TEXTURE_SIZE);
    if width > max || height > max {
        return Err(TextureError::TooLarge { path: path.to_path_buf(), width, height });
    }
    Ok(())
}

type Decoded = (u32, u32, Vec<[f32; 4]>, u32, bool);

/// PNG or JPEG through the `image` crate.
fn read_ldr(path: &Path, format: Format, usage: TextureUsage) -> Result<Decoded, TextureError> {
    let image_format = if format == Format::Png { image::ImageFormat::Png } else { image::ImageFormat::Jpeg };
    let corrupt = |e: image::ImageError| match e {
        image::ImageError::IoError(source) if !is_format_error(&source) => {
            TextureError::Read { path: path.to_path_buf(), source }
        }
        e => TextureError::Corrupt { path: path.to_path_buf(), format: format.name(), message: e.to_string() },
    };
    let reader = || -> Result<_, TextureError> {
        let file = std::fs::File::open(path).map_err(|source| TextureError::Read { path: path.into(), source })?;
        let mut r = image::ImageReader::with_format(io::BufReader::new(file), image_format);
        r.no_limits();
        Ok(r)
    };
    // The header first, so that an oversized image is never allocated.
    let (width, height) = reader()?.into_dimensions().map_err(corrupt)?;
    check_size(path, width.into(), height.into())?;
    let decoded = reader()?.decode().map_err(corrupt)?;
    let color = decoded.color();
    let has_alpha = color.has_alpha();
    let channels = u32::from(color.channel_count()) - u32::from(has_alpha);
    let mut texels: Vec<[f32; 4]> = decoded.into_rgba32f().pixels().map(|p| p.0).collect();
    if usage == TextureUsage::Color {
        let is_8bit = color.bytes_per_pixel() == color.channel_count();
        let table: Vec<f32> = (0..=255u8).map(|v| srgb_to_linear(f32::from(v) / 255.0)).collect();
        for t in &mut texels {
            for c in &mut t[..3] {
                *c = if is_8bit { table[(*c * 255.0).round() as usize] } else { srgb_to_linear(*c) };
            }
        }
    }
    Ok((width, height, texels, channels, has_alpha))
}

/// An OpenEXR file: the first layer's RGB(A), or one channel (and A).
fn read_exr(path: &Path) -> Result<Decoded, TextureError> {
    let corrupt = |e: exr::error::Error| match e {
        exr::error::Error::Io(source) if !is_format_error(&source) => {
            TextureError::Read { path: path.to_path_buf(), source }
        }
        e => TextureError::Corrupt { path: path.to_path_buf(), format: "EXR", message: e.to_string() },
    };
    // The header first, so that an oversized image is never allocated.
    let meta = exr::meta::MetaData::read_from_file(path, false).map_err(corrupt)?;
    if let Some(h) = meta.headers.iter().find(|h| !h.deep) {
        check_size(path, h.layer_size.x() as u64, h.layer_size.y() as u64)?;
    }
    let image = exr::prelude::read_first_flat_layer_from_file(path).map_err(corrupt)?;
    let layer = &image.layer_data;
    let (width, height) = (layer.size.x(), layer.size.y());
    check_size(path, width as u64, height as u64)?;
    let list = &layer.channel_data.list;
    // The channel's name without any layer prefix ("diffuse.R" -> "R").
    let base_name = |c: &exr::prelude::AnyChannel<exr::prelude::FlatSamples>| {
        let name = c.name.to_string();
        name.rsplit('.').next().unwrap_or_default().to_owned()
    };
    let names: Vec<String> = list.iter().map(base_name).collect();
    let find = |n: &str| names.iter().position(|m| m == n);
    let alpha = find("A");
    let colour: Vec<usize> = match (find("R"), find("G"), find("B"), find("Y")) {
        (Some(r), Some(g), Some(b), _) => vec![r, g, b],
        (_, _, _, Some(y)) => vec![y],
        _ => {
            let others: Vec<usize> = (0..names.len()).filter(|&i| Some(i) != alpha).collect();
            match others.as_slice() {
                [one] => vec![*one],
                _ => {
                    return Err(TextureError::ExrChannels {
                        path: path.to_path_buf(),
                        channels: list.iter().map(|c| c.name.to_string()).collect(),
                    })
                }
            }
        }
    };
    let values = |i: usize| -> Vec<f32> { list[i].sample_data.values_as_f32().collect() };
    let planes: Vec<Vec<f32>> = colour.iter().map(|&i| values(i)).collect();
    let alpha_plane = alpha.map(values);
    let n = width * height;
    let non_finite = planes.iter().chain(&alpha_plane).filter_map(|p| p.iter().position(|v| !v.is_finite())).min();
    if let Some(k) = non_finite {
        let value = planes.iter().chain(&alpha_plane).map(|p| p[k]).find(|v| !v.is_finite()).unwrap_or(f32::NAN);
        return Err(TextureError::NonFinite { path: path.to_path_buf(), x: k % width, y: k / width, value });
    }
    let texels = (0..n)
        .map(|k| {
            let a = alpha_plane.as_ref().map_or(1.0, |p| p[k]);
            match planes.as_slice() {
                [grey] => [grey[k], grey[k], grey[k], a],
                [r, g, b] => [r[k], g[k], b[k], a],
                _ => unreachable!("one or three colour channels"),
            }
        })
        .collect();
    Ok((width as u32, height as u32, texels, colour.len() as u32, alpha.is_some()))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn srgb_known_values() {
        assert_eq!(srgb_to_linear(0.0), 0.0);
        assert!((srgb_to_linear(1.0) - 1.0).abs() < 1e-7);
        assert!((srgb_to_linear(128.0 / 255.0) - 0.215_860_5).abs() < 1e-7);
        // The linear segment.
        assert!((srgb_to_linear(0.04) - 0.04 / 12.92).abs() < 1e-9);
        // Continuous at the joint.
        assert!((srgb_to_linear(0.040_45) - srgb_to_linear(0.040_451)).abs() < 1e-6);
    }

    #[test]
    fn kinds() {
        assert_eq!(TextureKind::Albedo.usage(), TextureUsage::Color);
        for k in [TextureKind::Normal, TextureKind::Roughness, TextureKind::Displacement] {
            assert_eq!(k.usage(), TextureUsage::Data);
            assert!(k.check_channels(Path::new("x"), 3).is_ok());
        }
        let e = TextureKind::Normal.check_channels(Path::new("n.png"), 1).unwrap_err().to_string();
        assert!(e.starts_with("n.png: a normal map needs 3"), "{e}");
        assert!(TextureKind::Roughness.check_channels(Path::new("x"), 1).is_ok());
    }
}
