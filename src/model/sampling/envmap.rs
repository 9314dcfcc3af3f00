//! Importance sampling of a latitude-longitude environment map: the f64 CPU
//! twin of the GLSL environment light. The tables it builds (in f32) are what
//! the GPU stores; the sampling and density formulas below are the
//! specification both sides follow.
//!
//! # Directions and texture coordinates
//!
//! World space, y up. A unit direction d ↔ (u, v):
//!
//! - φ = atan2(d.z, d.x) ∈ (−π, π], θ = acos(clamp(d.y, −1, 1)) ∈ [0, π];
//!   u = φ/(2π) + 1/2, v = θ/π ([`direction_to_uv`]). v = 0 is straight up
//!   (+y) and is row 0 of the image, its top; u = 1/2 is +x, u = 3/4 is +z.
//! - Inverse ([`uv_to_direction`]): φ = 2π(u − 1/2), θ = πv,
//!   d = (sin θ cos φ, cos θ, sin θ sin φ).
//! - dω = sin θ dθ dφ = 2π² sin θ du dv.
//!
//! # The radiance
//!
//! The map is W × H texels of linear RGB, row-major, row 0 at the top (level
//! 0 of a [`TextureImage`]; alpha is ignored). Texel (i, j) covers
//! u ∈ [i/W, (i+1)/W), v ∈ [j/H, (j+1)/H); the texel containing (u, v) is
//! i = clamp(⌊u W⌋, 0, W − 1), j = clamp(⌊v H⌋, 0, H − 1) (so u = 1, v = 1 and
//! the seam fall in the last column or row). The radiance arriving from d is
//! that texel's RGB × [`EnvironmentMap::scale`] ([`EnvironmentMap::radiance`]):
//! piecewise constant, nearest texel, never bilinear, so that the density
//! below is exactly proportional to what it integrates.
//!
//! # Importance and tables
//!
//! Weights ([`importance_weights`]): w_ij = Y_ij sin θ_j with
//! θ_j = π (j + 1/2)/H (the row centre) and the luminance
//! Y = 0.2126 R + 0.7152 G + 0.0722 B ([`luminance`]); then every texel with
//! Y > 0 gets w_ij = max(w_ij, 1e-4 · mean(w)) (mean over all W·H texels of
//! the weights before this floor, [`IMPORTANCE_FLOOR`]) so that it keeps a
//! non-zero probability, and every texel with Y ≤ 0 (or not finite) gets 0.
//! If every weight is 0 the map is black: [`EnvironmentMap::sample`] returns
//! `None` and [`EnvironmentMap::pdf`] 0.
//!
//! Tables, computed in f64 and stored as f32 (the GPU buffer,
//! [`EnvironmentMap::cdf_buffer`]):
//!
//! - `marginal[j]`, j = 0..=H: the CDF over rows, marginal[0] = 0,
//!   marginal[H] = 1, marginal[j+1] − marginal[j] = row_sum_j / total
//!   ([`EnvironmentMap::row_pdf`]);
//! - `conditional[j (W+1) + i]`, i = 0..=W: the CDF within row j,
//!   conditional[j (W+1)] = 0, conditional[j (W+1) + W] = 1,
//!   differences w_ij / row_sum_j (uniform, i/W, for an all-zero row).
//!
//! Each CDF is the f64 prefix sum divided by the f64 total, rounded to f32,
//! with the first entry forced to 0.0 and the last to exactly 1.0. Rounding
//! to f32 keeps it monotone but could merge the entries around a texel (or
//! row) whose probability is below an f32 ulp of its CDF value (about 6e-8
//! near 1 — a floored texel next to a bright sun in a large map), which would
//! silently give it probability 0. So the entries are then adjusted by the
//! fewest f32 ulps needed for every texel (row) of non-zero weight to have a
//! strictly positive f32 difference: a forward pass raises entry k + 1 to at
//! least the next f32 above entry k (f32::MIN_POSITIVE above 0, never a
//! subnormal), a backward pass from the final 1.0 lowers entry k to at most
//! the f32 below entry k + 1; zero-weight texels keep a zero difference. The
//! probabilities actually used — by sampling and by the density alike — are
//! the differences of the stored f32 entries, so the density stays exactly
//! normalised and consistent with the sampler whatever the rounding.
//!
//! # Sampling ([`EnvironmentMap::sample`], uniform u1, u2 ∈ [0, 1))
//!
//! 1. Row: j = the largest j ∈ [0, H] with marginal[j] ≤ u1, clamped to
//!    [0, H − 1]. As a binary search: lo = 0, hi = H;
//!    while hi − lo > 1 { mid = (lo + hi)/2; if marginal[mid] ≤ u1 { lo = mid } else { hi = mid } };
//!    j = lo. Rows of zero probability are never chosen (the largest index
//!    of a run of equal entries wins). p_row = marginal[j+1] − marginal[j];
//!    fv = (u1 − marginal[j]) / p_row; v = (j + fv)/H.
//! 2. Column: the same with u2 over row j's W + 1 entries
//!    conditional[j (W+1) ..= j (W+1) + W]: column i, p_col = difference,
//!    fu = (u2 − cdf[i]) / p_col, u = (i + fu)/W.
//! 3. If p_row or p_col is 0 (only for u1 or u2 outside [0, 1)) the sample is
//!    invalid (`None`).
//! 4. d = uv_to_direction(u, v); p_uv = p_row · p_col · W · H (the density
//!    in (u, v)); θ = π v; if sin θ ≤ 0 the sample is invalid (`None`);
//!    otherwise p_ω = p_uv / (2π² sin θ), the solid-angle density.
//! 5. The sample's radiance is texel (i, j)'s RGB × scale (the sampled texel,
//!    not a fetch at d, which at a texel border could round into the
//!    neighbour).
//!
//! # Density ([`EnvironmentMap::pdf`])
//!
//! For a unit d: (u, v) = direction_to_uv(d), (i, j) the texel containing
//! it, sin θ = √(d.x² + d.z²) (which is sin(acos(d.y)) for a unit d, but
//! accurate near the poles, where acos of a rounded d.y is not — in f32
//! badly so); 0 if sin θ ≤ 0 (the poles, a set of measure zero) or the map is
//! black; otherwise
//! p_ω = (marginal[j+1] − marginal[j]) (cond[j (W+1) + i + 1] − cond[j (W+1) + i]) W H / (2π² sin θ).
//! It integrates to 1 over the sphere: Σ_ij P_ij W H ∫∫_texel du dv = Σ P_ij = 1.
//!
//! [`procedural_sky`] (in `texture::environment`, with the lat-long
//! parameterisation) generates a deterministic test environment (a small,
//! very bright sun, a sky gradient with a halo, a dark ground).

use std::f64::consts::PI;

use glam::{DVec2, DVec3};

use super::lights::LightSample;
pub use crate::model::texture::environment::{
    direction_to_uv, procedural_sky, sky_sun_direction, uv_to_direction, SKY_SUN_AZIMUTH_DEG, SKY_SUN_ELEVATION_DEG,
    SKY_SUN_RADIANCE, SKY_SUN_RADIUS_DEG,
};
use crate::model::texture::TextureImage;

/// Rec. 709 luminance weights of linear R, G, B.
pub const LUMINANCE_WEIGHTS: [f64; 3] = [0.2126, 0.7152, 0.0722];

/// The importance floor, as a fraction of the mean weight, that every texel
/// of positive luminance keeps.
pub const IMPORTANCE_FLOOR: f64 = 1e-4;

/// Luminance 0.2126 R + 0.7152 G + 0.0722 B of a linear RGB colour.
pub fn luminance(rgb: [f32; 3]) -> f64 {
    LUMINANCE_WEIGHTS[0] * f64::from(rgb[0])
        + LUMINANCE_WEIGHTS[1] * f64::from(rgb[1])
        + LUMINANCE_WEIGHTS[2] * f64::from(rgb[2])
}

/// The importance weights w_ij (row-major, row 0 at the top) of a W × H map:
/// Y_ij sin(π (j + 1/2)/H), floored at [`IMPORTANCE_FLOOR`] × their mean for
/// texels of positive luminance, 0 for the others (Y ≤ 0 or not finite).
///
/// # Panics
///
/// If a side is 0 or `texels.len() != width * height`.
pub fn importance_weights(width: u32, height: u32, texels: &[[f32; 3]]) -> Vec<f64> {
    let (w, h) = (width as usize, height as usize);
    assert!(w > 0 && h > 0, "an environment map needs at least one texel, got {width} x {height}");
    assert_eq!(texels.len(), w * h, "{width} x {height} environment map with {} texels", texels.len());
    let raw: Vec<f64> = texels
        .iter()
        .enumerate()
        .map(|(k, &t)| {
            let y = luminance(t);
            if y > 0.0 && y.is_finite() {
                y * (PI * ((k / w) as f64 + 0.5) / h as f64).sin()
            } else {
                0.0
            }
        })
        .collect();
    let floor = IMPORTANCE_FLOOR * raw.iter().sum::<f64>() / raw.len() as f64;
    raw.into_iter().map(|x| if x > 0.0 { x.max(floor) } else { 0.0 }).collect()
}

/// The next f32 above `x` ≥ 0, skipping the subnormals.
fn step_up(x: f32) -> f32 {
    if x < f32::MIN_POSITIVE {
        f32::MIN_POSITIVE
    } else {
        x.next_up()
    }
}

/// The next f32 below `x` ≥ 0, skipping the subnormals (0 stays 0).
fn step_down(x: f32) -> f32 {
    if x <= f32::MIN_POSITIVE {
        0.0
    } else {
        x.next_down()
    }
}

/// The f32 CDF (n + 1 entries, 0 to exactly 1) of n weights ≥ 0: f64 prefix
/// sums over the f64 total, rounded, then nudged so that every positive
/// weight has a positive f32 difference (see the module documentation).
/// Uniform (k/n) when every weight is 0.
fn cdf_f32(weights: &[f64]) -> Vec<f32> {
    let n = weights.len();
    let total: f64 = weights.iter().sum();
    let uniform = total.partial_cmp(&0.0) != Some(std::cmp::Ordering::Greater);
    let positive = |k: usize| uniform || weights[k] > 0.0;
    let mut cdf = vec![0.0f32; n + 1];
    let mut acc = 0.0;
    for k in 0..n {
        if uniform {
            cdf[k + 1] = ((k + 1) as f64 / n as f64) as f32;
        } else {
            acc += weights[k];
            cdf[k + 1] = (acc / total) as f32;
        }
    }
    cdf[n] = 1.0;
    for k in 0..n {
        let lower = if positive(k) { step_up(cdf[k]) } else { cdf[k] };
        cdf[k + 1] = cdf[k + 1].max(lower);
    }
    cdf[n] = 1.0;
    for k in (0..n).rev() {
        let upper = if positive(k) { step_down(cdf[k + 1]) } else { cdf[k + 1] };
        cdf[k] = cdf[k].min(upper);
    }
    cdf[0] = 0.0;
    cdf
}

/// Samples a discrete distribution given by its CDF with `x`: the largest k
/// with cdf[k] ≤ x, clamped to [0, n − 1]; returns (k, the fraction of x
/// within the interval, the interval's probability).
fn sample_cdf(cdf: &[f32], x: f64) -> (usize, f64, f64) {
    let n = cdf.len() - 1;
    let k = cdf.partition_point(|&c| f64::from(c) <= x).saturating_sub(1).min(n - 1);
    let (a, b) = (f64::from(cdf[k]), f64::from(cdf[k + 1]));
    let p = b - a;
    (k, if p > 0.0 { (x - a) / p } else { 0.0 }, p)
}

/// An environment map of lat-long texels with its importance-sampling tables
/// (see the module documentation for every formula).
#[derive(Clone, Debug, PartialEq)]
pub struct EnvironmentMap {
    /// Texels per row, W.
    pub width: u32,
    /// Rows, H.
    pub height: u32,
    /// Linear RGB, row-major, row 0 at the top (v = 0, +y).
    pub texels: Vec<[f32; 3]>,
    /// Factor applied to the texels' radiance (not to the sampling).
    pub scale: f32,
    /// CDF over rows, H + 1 entries from 0 to 1.
    pub marginal: Vec<f32>,
    /// CDFs within the rows, H × (W + 1) entries: row j at j (W + 1).
    pub conditional: Vec<f32>,
    black: bool,
}

impl EnvironmentMap {
    /// The map of level 0 of `texture` (RGB; alpha ignored), radiance × `scale`.
    pub fn from_texture(texture: &TextureImage, scale: f32) -> Self {
        Self::from_rgba(texture.width, texture.height, &texture.levels[0], scale)
    }

    /// The map of `width` × `height` RGBA texels (row-major, row 0 at the
    /// top; alpha ignored), radiance × `scale`.
    ///
    /// # Panics
    ///
    /// If a side is 0 or `texels.len() != width * height`.
    pub fn from_rgba(width: u32, height: u32, texels: &[[f32; 4]], scale: f32) -> Self {
        Self::from_rgb(width, height, texels.iter().map(|t| [t[0], t[1], t[2]]).collect(), scale)
    }

    /// The map of `width` × `height` RGB texels (row-major, row 0 at the
    /// top), radiance × `scale`: builds the tables.
    ///
    /// # Panics
    ///
    /// If a side is 0 or `texels.len() != width * height`.
    pub fn from_rgb(width: u32, height: u32, texels: Vec<[f32; 3]>, scale: f32) -> Self {
        let weights = importance_weights(width, height, &texels);
        let w = width as usize;
        let row_sums: Vec<f64> = weights.chunks(w).map(|row| row.iter().sum()).collect();
        let black = !row_sums.iter().any(|&s| s > 0.0);
        let marginal = cdf_f32(&row_sums);
        let conditional = weights.chunks(w).flat_map(cdf_f32).collect();
        Self { width, height, texels, scale, marginal, conditional, black }
    }

    /// Whether every importance weight is 0 (nothing to sample).
    pub fn is_black(&self) -> bool {
        self.black
    }

    /// The probability of row `j`: marginal[j+1] − marginal[j].
    pub fn row_pdf(&self, j: usize) -> f64 {
        f64::from(self.marginal[j + 1]) - f64::from(self.marginal[j])
    }

    /// The probability of column `i` within row `j`: the difference of the
    /// row's conditional CDF.
    pub fn column_pdf(&self, i: usize, j: usize) -> f64 {
        let row = j * (self.width as usize + 1);
        f64::from(self.conditional[row + i + 1]) - f64::from(self.conditional[row + i])
    }

    /// The probability that a sample falls in texel (i, j):
    /// [`row_pdf`](Self::row_pdf)(j) × [`column_pdf`](Self::column_pdf)(i, j)
    /// (0 for every texel of a black map). Its density in (u, v) is this × W H.
    pub fn texel_pdf(&self, i: usize, j: usize) -> f64 {
        if self.black {
            return 0.0;
        }
        self.row_pdf(j) * self.column_pdf(i, j)
    }

    /// The texel (i, j) containing `uv`: i = clamp(⌊u W⌋, 0, W − 1),
    /// j = clamp(⌊v H⌋, 0, H − 1).
    pub fn texel_at(&self, uv: DVec2) -> (usize, usize) {
        let index = |x: f64, n: u32| ((x * f64::from(n)).floor().max(0.0) as usize).min(n as usize - 1);
        (index(uv.x, self.width), index(uv.y, self.height))
    }

    /// Texel (i, j)'s RGB × scale.
    pub fn texel_radiance(&self, i: usize, j: usize) -> DVec3 {
        let t = self.texels[j * self.width as usize + i];
        DVec3::new(f64::from(t[0]), f64::from(t[1]), f64::from(t[2])) * f64::from(self.scale)
    }

    /// The radiance arriving from the unit direction `d`: the RGB of the texel
    /// containing direction_to_uv(d), × scale.
    pub fn radiance(&self, d: DVec3) -> DVec3 {
        let (i, j) = self.texel_at(direction_to_uv(d));
        self.texel_radiance(i, j)
    }

    /// Samples a direction with (u1, u2) ∈ [0, 1)² proportionally to the
    /// importance (see the module documentation): (unit direction,
    /// solid-angle pdf, the sampled texel's radiance). `None` for a black map,
    /// or when the sample lands where sin θ = 0 (a pole; only for u1 = 0 with
    /// a non-zero top row, or u1 → 1 with a non-zero bottom row).
    pub fn sample(&self, u1: f64, u2: f64) -> Option<(DVec3, f64, DVec3)> {
        if self.black {
            return None;
        }
        let (w, h) = (self.width as usize, self.height as usize);
        let (j, fv, p_row) = sample_cdf(&self.marginal, u1);
        let (i, fu, p_col) = sample_cdf(&self.conditional[j * (w + 1)..(j + 1) * (w + 1)], u2);
        if p_row <= 0.0 || p_col <= 0.0 {
            return None;
        }
        let (u, v) = ((i as f64 + fu) / w as f64, (j as f64 + fv) / h as f64);
        let sin_theta = (PI * v).sin();
        if sin_theta <= 0.0 {
            return None;
        }
        let p_uv = p_row * p_col * (w * h) as f64;
        Some((uv_to_direction(u, v), p_uv / (2.0 * PI * PI * sin_theta), self.texel_radiance(i, j)))
    }

    /// [`sample`](Self::sample) as a [`LightSample`] (dist = ∞).
    pub fn sample_light(&self, u1: f64, u2: f64) -> Option<LightSample> {
        let (wi, pdf, emitted) = self.sample(u1, u2)?;
        Some(LightSample { wi, dist: f64::INFINITY, emitted, pdf: Some(pdf) })
    }

    /// The solid-angle density with which [`sample`](Self::sample) produces
    /// the unit direction `d`: the texel's probability × W H / (2π² sin θ),
    /// sin θ = √(d.x² + d.z²); 0 where sin θ = 0 and for a black map.
    pub fn pdf(&self, d: DVec3) -> f64 {
        if self.black {
            return 0.0;
        }
        let sin_theta = (d.x * d.x + d.z * d.z).sqrt();
        if sin_theta <= 0.0 {
            return 0.0;
        }
        let (i, j) = self.texel_at(direction_to_uv(d));
        let texels = f64::from(self.width) * f64::from(self.height);
        self.texel_pdf(i, j) * texels / (2.0 * PI * PI * sin_theta)
    }

    /// The tables as one f32 buffer, the layout the GPU reads: `marginal`
    /// (H + 1 entries) then `conditional` (H (W + 1) entries, row j at
    /// H + 1 + j (W + 1)).
    pub fn cdf_buffer(&self) -> Vec<f32> {
        self.marginal.iter().chain(&self.conditional).copied().collect()
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cdf_is_exact_monotone_and_keeps_tiny_weights() {
        let cdf = cdf_f32(&[1.0, 0.0, 3.0]);
        assert_eq!(cdf, vec![0.0, 0.25, 0.25, 1.0]);
        assert_eq!(cdf_f32(&[0.0; 4]), vec![0.0, 0.25, 0.5, 0.75, 1.0]);
        // Weights far below an f32 ulp next to a huge one keep a positive
        // difference; zero weights keep a zero one.
        let mut weights = vec![1e-12; 50];
        weights[10] = 1.0;
        weights[20] = 0.0;
        weights.push(1e-12);
        let cdf = cdf_f32(&weights);
        assert_eq!((cdf[0], cdf[weights.len()]), (0.0, 1.0));
        for (k, &w) in weights.iter().enumerate() {
            if w > 0.0 {
                assert!(cdf[k + 1] > cdf[k], "entry {k}: {} vs {}", cdf[k + 1], cdf[k]);
            } else {
                assert_eq!(cdf[k + 1], cdf[k]);
            }
        }
        // The big weight still gets (almost) everything.
        assert!(f64::from(cdf[11] - cdf[10]) > 1.0 - 1e-5);
    }

    #[test]
    fn sample_cdf_skips_empty_intervals() {
        let cdf = [0.0, 0.25, 0.25, 1.0];
        assert_eq!(sample_cdf(&cdf, 0.0), (0, 0.0, 0.25));
        assert_eq!(sample_cdf(&cdf, 0.25).0, 2);
        assert_eq!(sample_cdf(&cdf, 0.625), (2, 0.5, 0.75));
        assert_eq!(sample_cdf(&cdf, 0.999_999).0, 2);
    }

    #[test]
    fn black_map_samples_nothing() {
        let map = EnvironmentMap::from_rgb(4, 2, vec![[0.0; 3]; 8], 1.0);
        assert!(map.is_black());
        assert!(map.sample(0.3, 0.7).is_none());
        assert_eq!(map.pdf(DVec3::X), 0.0);
        assert_eq!(map.marginal, vec![0.0, 0.5, 1.0]);
    }

    #[test]
    fn uv_conventions() {
        let close = |a: DVec3, b: DVec3| (a - b).length() < 1e-12;
        assert!(close(uv_to_direction(0.5, 0.5), DVec3::X));
        assert!(close(uv_to_direction(0.75, 0.5), DVec3::Z));
        assert!(close(uv_to_direction(0.3, 0.0), DVec3::Y));
        assert!((direction_to_uv(DVec3::Z) - DVec2::new(0.75, 0.5)).length() < 1e-15);
        assert_eq!(direction_to_uv(-DVec3::Y).y, 1.0);
    }
}
