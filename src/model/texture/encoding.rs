//! How texture maps are stored on the GPU.
//!
//! A map is uploaded as 32-bit floats (exact) whenever its mip chain fits in
//! one device allocation. A map too large for that (a 16384 x 16384 map
//! takes 5.3 GiB as f32; lavapipe allocates at most 2 GiB at once) steps
//! down to the most precise encoding that fits *and* holds its values:
//!
//! | encoding | bytes per texel | holds | error of a stored value |
//! |---|---:|---|---|
//! | [`TexelEncoding::F32`] | 16 | anything | none |
//! | [`TexelEncoding::F16`] | 8 | \|v\| ≤ 65504 | relative 2⁻¹¹ (4.9e-4); absolute 3e-8 below 6.1e-5 |
//! | [`TexelEncoding::Srgb8`] | 4 | colour maps in [0, 1] | half an 8-bit sRGB step: ≤ 4.5e-3 absolute; relative ≤ 3 % above 0.01, ≤ 1.2 % above 0.1 |
//! | [`TexelEncoding::Unorm8`] | 4 | data maps in [0, 1] | 1/510 absolute |
//!
//! 8-bit PNG and JPEG maps lose nothing to the 8-bit encodings beyond the
//! rounding of their resampled and averaged mip texels. When no encoding
//! fits, the render fails with [`TextureTooLarge`], which says what the map
//! would need.

use std::fmt;
use std::sync::OnceLock;

use super::TextureImage;
use crate::model::texture::srgb_to_linear;

/// A GPU storage encoding of RGBA texels.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, serde::Serialize)]
pub enum TexelEncoding {
    /// 32-bit floats: exact.
    F32,
    /// 16-bit floats (IEEE binary16): values up to 65504 in magnitude.
    F16,
    /// 8 bits per channel, colour sRGB-encoded and alpha linear: for colour
    /// maps whose values lie in [0, 1]. The GPU decodes sRGB before filtering.
    Srgb8,
    /// 8 bits per channel, linear: for data maps whose values lie in [0, 1].
    Unorm8,
}

impl TexelEncoding {
    /// Bytes of one RGBA texel.
    pub const fn texel_bytes(self) -> u64 {
        match self {
            Self::F32 => 16,
            Self::F16 => 8,
            Self::Srgb8 | Self::Unorm8 => 4,
        }
    }

    /// Name in messages.
    pub const fn name(self) -> &'static str {
        match self {
            Self::F32 => "32-bit float",
            Self::F16 => "16-bit float",
            Self::Srgb8 => "8-bit sRGB",
            Self::Unorm8 => "8-bit linear",
        }
    }

    /// Writes `texels` encoded into `out`, which must hold exactly
    /// `texels.len() * texel_bytes()` bytes (little-endian, as Vulkan reads
    /// them). Values outside what the encoding holds are clamped to it.
    ///
    /// # Panics
    ///
    /// If `out` has the wrong length.
    pub fn encode(self, texels: &[[f32; 4]], out: &mut [u8]) {
        let bytes = self.texel_bytes() as usize;
        assert_eq!(out.len(), texels.len() * bytes, "encoded size");
        let texel_pairs = texels.iter().zip(out.chunks_exact_mut(bytes));
        match self {
            Self::F32 => out.copy_from_slice(bytemuck::cast_slice(texels)),
            Self::F16 => {
                for (t, o) in texel_pairs {
                    for (c, o) in t.iter().zip(o.chunks_exact_mut(2)) {
                        o.copy_from_slice(&half::f16::from_f32(c.clamp(-F16_MAX, F16_MAX)).to_le_bytes());
                    }
                }
            }
            Self::Srgb8 => {
                let table = srgb8_table();
                for (t, o) in texel_pairs {
                    o.copy_from_slice(&[table.encode(t[0]), table.encode(t[1]), table.encode(t[2]), unorm8(t[3])]);
                }
            }
            Self::Unorm8 => {
                for (t, o) in texel_pairs {
                    o.copy_from_slice(&t.map(unorm8));
                }
            }
        }
    }

    /// The value the GPU reads back for `texel` once stored in this
    /// encoding (before any filtering).
    pub fn round_trip(self, texel: [f32; 4]) -> [f32; 4] {
        let mut bytes = [0u8; 16];
        let n = self.texel_bytes() as usize;
        self.encode(&[texel], &mut bytes[..n]);
        match self {
            Self::F32 => texel,
            Self::F16 => std::array::from_fn(|c| half::f16::from_le_bytes([bytes[2 * c], bytes[2 * c + 1]]).to_f32()),
            Self::Srgb8 => {
                let mut v: [f32; 4] = std::array::from_fn(|c| srgb_to_linear(bytes[c] as f32 / 255.0));
                v[3] = bytes[3] as f32 / 255.0;
                v
            }
            Self::Unorm8 => std::array::from_fn(|c| bytes[c] as f32 / 255.0),
        }
    }
}

impl fmt::Display for TexelEncoding {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

/// The largest finite binary16 value.
const F16_MAX: f32 = 65504.0;

/// What a map's values mean, for choosing an 8-bit encoding.
#[derive(Clone, Copy, Debug, PartialEq, Eq, serde::Serialize)]
pub enum MapContent {
    /// Linear colour (albedo and environment maps): 8-bit storage is
    /// sRGB-encoded.
    Color,
    /// Numbers (normals, heights, roughness, slope moments): 8-bit storage
    /// is linear.
    Data,
}

/// A map that fits in no encoding: even the smallest that holds its values
/// exceeds the device's largest allocation.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
#[error(
    "texture `{source_name}` ({width} x {height}) does not fit on the device: its mip chain takes {} as {smallest} \
     (the most compact encoding that holds its values{why}), and the device allocates at most {} at once. \
     A {fit_width} x {fit_height} map would fit",
    gib(*.bytes),
    gib(*.max_bytes)
)]
pub struct TextureTooLarge {
    /// Where the map came from.
    pub source_name: String,
    /// Width of level 0.
    pub width: u32,
    /// Height of level 0.
    pub height: u32,
    /// The most compact encoding that holds the map's values.
    pub smallest: TexelEncoding,
    /// Its size in bytes.
    pub bytes: u64,
    /// The device's largest allocation in bytes.
    pub max_bytes: u64,
    /// Why no smaller encoding holds the values ("" if none is smaller).
    pub why: &'static str,
    /// Width of the largest map of the same shape, halving the longer side,
    /// that would fit.
    pub fit_width: u32,
    /// Its height.
    pub fit_height: u32,
}

fn gib(bytes: u64) -> String {
    format!("{:.2} GiB", bytes as f64 / (1u64 << 30) as f64)
}

/// The range of a map's values and whether all are finite: its mips
/// average level 0, so level 0 bounds them all. Written so that it
/// vectorises: a 16384 x 16384 map takes a fraction of a second.
fn value_range(t: &TextureImage) -> (f32, f32, bool) {
    const LANES: usize = 16;
    let values: &[f32] = bytemuck::cast_slice(t.levels.first().map_or(&[][..], |l| l.as_slice()));
    let mut lo = [f32::INFINITY; LANES];
    let mut hi = [f32::NEG_INFINITY; LANES];
    let mut nan = [false; LANES];
    let mut chunks = values.chunks_exact(LANES);
    for chunk in &mut chunks {
        for k in 0..LANES {
            let c = chunk[k];
            lo[k] = if c < lo[k] { c } else { lo[k] };
            hi[k] = if c > hi[k] { c } else { hi[k] };
            nan[k] |= c.is_nan();
        }
    }
    let rest = chunks.remainder();
    let lo = lo.iter().chain(rest).fold(f32::INFINITY, |a, &b| a.min(b));
    let hi = hi.iter().chain(rest).fold(f32::NEG_INFINITY, |a, &b| a.max(b));
    let nan = nan.contains(&true) || rest.iter().any(|c| c.is_nan());
    (lo, hi, !nan && lo.is_finite() && hi.is_finite())
}

/// The encodings that hold `t`'s values, most precise first (f32 alone
/// when `f32_fits`, without looking at the values), and why none smaller
/// does.
fn candidates(t: &TextureImage, content: MapContent, f32_fits: bool) -> (Vec<TexelEncoding>, &'static str) {
    let mut list = vec![TexelEncoding::F32];
    if f32_fits {
        return (list, "");
    }
    let (lo, hi, finite) = value_range(t);
    if !finite || lo < -F16_MAX || hi > F16_MAX {
        return (list, ": values beyond ±65504 need 32-bit floats");
    }
    list.push(TexelEncoding::F16);
    if lo < 0.0 || hi > 1.0 {
        return (list, ": values outside [0, 1] rule out 8-bit storage");
    }
    list.push(match content {
        MapContent::Color => TexelEncoding::Srgb8,
        MapContent::Data => TexelEncoding::Unorm8,
    });
    (list, "")
}

/// The most precise encoding of `t` whose mip chain takes at most
/// `max_bytes` on the device, where `bytes(e)` is what it takes in encoding
/// `e`. See the [module documentation](self) for the order.
pub fn choose_encoding(
    t: &TextureImage,
    content: MapContent,
    max_bytes: u64,
    mut bytes: impl FnMut(TexelEncoding) -> u64,
) -> Result<TexelEncoding, TextureTooLarge> {
    let f32_fits = bytes(TexelEncoding::F32) <= max_bytes;
    let (list, why) = candidates(t, content, f32_fits);
    if let Some(e) = list.iter().copied().find(|&e| bytes(e) <= max_bytes) {
        return Ok(e);
    }
    let smallest = *list.last().expect("f32 is always a candidate");
    let need = bytes(smallest);
    // Sizes scale with the texel count: halve the longer side until it fits.
    let (mut fit_width, mut fit_height, mut fit_bytes) = (t.width, t.height, need);
    while fit_bytes > max_bytes && fit_width * fit_height > 1 {
        if fit_width >= fit_height {
            fit_width /= 2;
        } else {
            fit_height /= 2;
        }
        fit_bytes /= 2;
    }
    Err(TextureTooLarge {
        source_name: t.source.clone(),
        width: t.width,
        height: t.height,
        smallest,
        bytes: need,
        max_bytes,
        why,
        fit_width,
        fit_height,
    })
}

/// Texels of a whole mip chain of a `width` x `height` map.
pub fn chain_texels(t: &TextureImage) -> u64 {
    t.levels.iter().map(|l| l.len() as u64).sum()
}

/// Linear [0, 1] to the nearest 8-bit sRGB code: the number of decision
/// thresholds (linear values halfway between adjacent codes, in sRGB
/// space) below `v`. Exact rounding without a `powf` per channel.
#[cfg(test)]
fn srgb8(v: f32) -> u8 {
    srgb8_table().encode(v)
}

/// Buckets of [0, 1] in the sRGB encoder's table: narrower than the
/// narrowest gap between thresholds (3.0e-4, at the dark end), so that a
/// bucket's first code is off by one at most.
const SRGB8_BUCKETS: usize = 4096;

struct Srgb8Table {
    /// The linear values halfway (in sRGB space) between adjacent codes.
    thresholds: [f32; 255],
    /// The code of each bucket's lower end (one more bucket for v = 1).
    first_code: [u8; SRGB8_BUCKETS + 1],
}

impl Srgb8Table {
    /// The code nearest (in sRGB space) to `v`, clamped to [0, 1].
    fn encode(&self, v: f32) -> u8 {
        let v = v.clamp(0.0, 1.0);
        let mut code = self.first_code[(v * SRGB8_BUCKETS as f32) as usize];
        while code < 255 && v >= self.thresholds[code as usize] {
            code += 1;
        }
        code
    }
}

fn srgb8_table() -> &'static Srgb8Table {
    static TABLE: OnceLock<Srgb8Table> = OnceLock::new();
    TABLE.get_or_init(|| {
        let thresholds: [f32; 255] = std::array::from_fn(|k| srgb_to_linear((k as f32 + 0.5) / 255.0));
        let first_code = std::array::from_fn(|b| {
            let v = b as f32 / SRGB8_BUCKETS as f32;
            thresholds.partition_point(|&x| x <= v) as u8
        });
        Srgb8Table { thresholds, first_code }
    })
}

/// Linear [0, 1] to the nearest 8-bit code.
fn unorm8(v: f32) -> u8 {
    (v.clamp(0.0, 1.0) * 255.0).round() as u8
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::texture::from_texels;

    fn map(values: &[f32]) -> TextureImage {
        let texels = values.iter().map(|&v| [v, v, v, 1.0]).collect::<Vec<_>>();
        from_texels("test".into(), values.len() as u32, 1, texels)
    }

    fn per_texel(t: &TextureImage) -> impl Fn(TexelEncoding) -> u64 + '_ {
        move |e| chain_texels(t) * e.texel_bytes()
    }

    #[test]
    fn f32_whenever_it_fits() {
        let t = map(&[0.0, 0.5, 2.0, -1.0]);
        assert_eq!(choose_encoding(&t, MapContent::Data, u64::MAX, per_texel(&t)), Ok(TexelEncoding::F32));
    }

    #[test]
    fn steps_down_to_what_holds_the_values() {
        let texels = chain_texels(&map(&[0.0; 4]));
        let half_budget = texels * 8;
        let byte_budget = texels * 4;
        let unit = map(&[0.0, 0.25, 0.5, 1.0]);
        let hdr = map(&[0.0, 0.5, 2.0, 100.0]);
        let signed = map(&[-0.5, 0.5, 0.0, 0.0]);
        let huge = map(&[0.0, 1e6, 0.0, 0.0]);
        assert_eq!(choose_encoding(&unit, MapContent::Color, half_budget, per_texel(&unit)), Ok(TexelEncoding::F16));
        assert_eq!(choose_encoding(&unit, MapContent::Color, byte_budget, per_texel(&unit)), Ok(TexelEncoding::Srgb8));
        assert_eq!(choose_encoding(&unit, MapContent::Data, byte_budget, per_texel(&unit)), Ok(TexelEncoding::Unorm8));
        let e = choose_encoding(&hdr, MapContent::Color, byte_budget, per_texel(&hdr)).unwrap_err();
        assert_eq!((e.smallest, e.bytes, e.max_bytes), (TexelEncoding::F16, half_budget, byte_budget));
        assert_eq!((e.fit_width, e.fit_height), (2, 1));
        assert!(e.to_string().contains("outside [0, 1]"), "{e}");
        let e = choose_encoding(&signed, MapContent::Data, byte_budget, per_texel(&signed)).unwrap_err();
        assert_eq!(e.smallest, TexelEncoding::F16);
        let e = choose_encoding(&huge, MapContent::Data, half_budget, per_texel(&huge)).unwrap_err();
        assert_eq!(e.smallest, TexelEncoding::F32);
        assert!(e.to_string().contains("65504"), "{e}");
    }

    #[test]
    fn srgb8_table_agrees_with_a_search_of_the_thresholds() {
        let table = srgb8_table();
        for i in 0..=1_000_000 {
            let v = i as f32 / 1_000_000.0;
            assert_eq!(srgb8(v), table.thresholds.partition_point(|&x| x <= v) as u8, "{v}");
        }
        for &x in &table.thresholds {
            for v in [x.next_down(), x, x.next_up()] {
                assert_eq!(srgb8(v), table.thresholds.partition_point(|&t| t <= v) as u8, "{v}");
            }
        }
    }

    #[test]
    fn srgb8_rounds_to_the_nearest_code() {
        for i in 0..=4096 {
            let v = i as f32 / 4096.0;
            let code = srgb8(v);
            let err = |c: u8| (srgb_to_linear(c as f32 / 255.0) - v).abs();
            // Nearest in sRGB space: the decoded neighbours are no closer in
            // the encoded value.
            let encoded = crate::model::texture::linear_to_srgb(v) * 255.0;
            assert!((code as f32 - encoded).abs() <= 0.5 + 1e-3, "{v}: code {code}, exact {encoded}");
            assert!(err(code) <= 4.5e-3, "{v}: {}", err(code));
        }
        assert_eq!((srgb8(0.0), srgb8(1.0), srgb8(-1.0), srgb8(2.0)), (0, 255, 0, 255));
    }

    #[test]
    fn round_trips_stay_within_the_documented_errors() {
        for i in 0..=1000 {
            let v = i as f32 / 1000.0;
            let t = [v, 1.0 - v, v * v, v];
            for (e, bound) in
                [(TexelEncoding::F32, 0.0), (TexelEncoding::F16, 4.9e-4), (TexelEncoding::Unorm8, 1.0 / 510.0)]
            {
                let r = e.round_trip(t);
                for c in 0..4 {
                    assert!((r[c] - t[c]).abs() <= bound * t[c].abs().max(1.0) + 1e-7, "{e}: {t:?} -> {r:?}");
                }
            }
            let r = TexelEncoding::Srgb8.round_trip(t);
            for c in 0..3 {
                let err = (r[c] - t[c]).abs();
                let relative = if t[c] >= 0.1 { 0.012 } else { 0.03 };
                assert!(err <= 4.5e-3 && (t[c] < 0.01 || err <= relative * t[c]), "{t:?} -> {r:?}");
            }
            assert!((r[3] - t[3]).abs() <= 1.0 / 510.0 + 1e-7);
        }
        assert_eq!(TexelEncoding::F16.round_trip([1e9, -1e9, 0.0, 1.0]), [F16_MAX, -F16_MAX, 0.0, 1.0]);
    }
}
