//! Slope moments of normal and displacement maps, for filtering them over a
//! footprint (LEAN mapping: M. Olano, D. Baker, "LEAN Mapping", I3D 2010;
//! the roughness widening of A. Toksvig, "Mipmapping Normal Maps", 2005).
//!
//! A normal map's normals are equivalent to slopes `s = (−n_x/n_z, −n_y/n_z)`
//! of a height field in tangent space. Slopes, unlike normals, average
//! linearly, and so do their squares: the mip chain of the texture
//! `(s_x, s_y, s_x², s_y²)` holds, at every level, the mean slope and the
//! second moments over each texel's area, and filtering it with any linear
//! filter (EWA over a footprint) gives them over the footprint. The mean
//! slope is the filtered normal; the variance
//! `σ² = ½ (E[s_x²] − E[s_x]² + E[s_y²] − E[s_y]²)` (per axis, the two axes
//! averaged: the renderer's GGX lobes are isotropic) is the spread of normals
//! that filtering removed, and goes back into the lobe:
//! [`widened_alpha`]. The cross moment `E[s_x s_y]` is not kept (isotropic
//! lobes cannot use it).
//!
//! A displacement (height) map gets the same treatment with the slopes
//! `(∂h/∂u, ∂h/∂v)` in units of height per unit of u and v (periodic central
//! differences at level 0); the renderer scales them by the material's
//! displacement scale and divides by the lengths of ∂p/∂u and ∂p/∂v.

use super::{from_texels, TextureImage};

/// Smallest |n_z| of a decoded normal: slopes are bounded by 1 / this (a
/// normal within 3° of the tangent plane).
pub const MIN_NORMAL_Z: f64 = 0.05;

/// The slope-moment texture `(s_x, s_y, s_x², s_y²)` of a tangent-space
/// normal map (RGB = (n + 1) / 2), with its mip chain.
pub fn normal_slope_moments(normal_map: &TextureImage) -> TextureImage {
    let texels = normal_map.levels[0]
        .iter()
        .map(|c| {
            let (sx, sy) = slopes_of_encoded_normal(*c);
            moments(sx, sy)
        })
        .collect();
    from_texels(
        format!("slope moments of normal map {}", normal_map.source),
        normal_map.width,
        normal_map.height,
        texels,
    )
}

/// The slope-moment texture `(h_u, h_v, h_u², h_v²)` of a height map (R
/// channel), slopes per unit of u and v by periodic central differences at
/// level 0, with its mip chain.
pub fn height_slope_moments(height_map: &TextureImage) -> TextureImage {
    let (w, h) = (height_map.width as usize, height_map.height as usize);
    let level = &height_map.levels[0];
    let at = |x: usize, y: usize| f64::from(level[y * w + x][0]);
    let texels = (0..w * h)
        .map(|k| {
            let (x, y) = (k % w, k / w);
            let du = (at((x + 1) % w, y) - at((x + w - 1) % w, y)) / 2.0 * w as f64;
            let dv = (at(x, (y + 1) % h) - at(x, (y + h - 1) % h)) / 2.0 * h as f64;
            moments(du, dv)
        })
        .collect();
    from_texels(
        format!("slope moments of height map {}", height_map.source),
        height_map.width,
        height_map.height,
        texels,
    )
}

/// Tangent-space slopes of a normal encoded as (n + 1) / 2; |n_z| is bounded
/// below by [`MIN_NORMAL_Z`] (and a normal pointing into the surface is
/// mirrored to the outside).
pub fn slopes_of_encoded_normal(c: [f32; 4]) -> (f64, f64) {
    let n = [0, 1, 2].map(|i| 2.0 * f64::from(c[i]) - 1.0);
    let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if len == 0.0 {
        return (0.0, 0.0);
    }
    let nz = (n[2] / len).abs().max(MIN_NORMAL_Z);
    (-n[0] / len / nz, -n[1] / len / nz)
}

fn moments(sx: f64, sy: f64) -> [f32; 4] {
    [sx as f32, sy as f32, (sx * sx) as f32, (sy * sy) as f32]
}

/// The per-axis slope variance of a filtered moment texel
/// `(E[s_x], E[s_y], E[s_x²], E[s_y²])`, never negative.
pub fn slope_variance(m: [f32; 4]) -> f64 {
    let (mx, my) = (f64::from(m[0]), f64::from(m[1]));
    let vx = f64::from(m[2]) - mx * mx;
    let vy = f64::from(m[3]) - my * my;
    (0.5 * (vx + vy)).max(0.0)
}

/// The GGX α of a lobe of roughness α on microfacets whose normals spread
/// with per-axis slope variance `σ²`: `√(α² + 2σ²)` (a Beckmann lobe of
/// roughness α has per-axis slope variance α²/2, and variances of independent
/// slopes add; GGX is treated alike, as in LEAN and Toksvig mapping).
pub fn widened_alpha(alpha: f64, slope_variance: f64) -> f64 {
    (alpha * alpha + 2.0 * slope_variance.max(0.0)).sqrt()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::texture::procedural::{bump_heights, normals_from_heights};

    #[test]
    fn flat_normal_map_has_zero_slopes() {
        assert_eq!(slopes_of_encoded_normal([0.5, 0.5, 1.0, 1.0]), (0.0, 0.0));
        let t = normal_slope_moments(&normals_from_heights(&bump_heights(8, 0, 1), 1.0));
        assert!(t.levels.iter().flatten().all(|m| m.iter().all(|v| v.abs() < 1e-6)));
    }

    #[test]
    fn slopes_invert_the_encoding() {
        let (sx, sy) = (0.3, -0.7);
        let len = (sx * sx + sy * sy + 1.0f64).sqrt();
        let c = [-sx / len, -sy / len, 1.0 / len].map(|v| ((v + 1.0) / 2.0) as f32);
        let (a, b) = slopes_of_encoded_normal([c[0], c[1], c[2], 1.0]);
        assert!((a - sx).abs() < 1e-6 && (b - sy).abs() < 1e-6, "{a} {b}");
    }

    #[test]
    fn height_slopes_of_a_sine_wave() {
        // h = sin(2π u): ∂h/∂u = 2π cos(2π u) per unit of u; the mean of its
        // square over a period is 2π², which the 1x1 level holds.
        let n = 256usize;
        let texels = (0..n * n)
            .map(|k| {
                let u = ((k % n) as f64 + 0.5) / n as f64;
                let h = (2.0 * std::f64::consts::PI * u).sin() as f32;
                [h, h, h, 1.0]
            })
            .collect();
        let t = height_slope_moments(&from_texels("wave".into(), n as u32, n as u32, texels));
        let top = t.levels.last().unwrap()[0];
        let expected = 2.0 * std::f64::consts::PI.powi(2);
        assert!(top[0].abs() < 1e-4 && top[1].abs() < 1e-4);
        assert!((f64::from(top[2]) - expected).abs() < 1e-3 * expected, "{top:?}");
        assert!((slope_variance(top) - 0.5 * expected).abs() < 1e-3 * expected);
    }

    #[test]
    fn widening_adds_variances() {
        assert_eq!(widened_alpha(0.3, 0.0), 0.3);
        assert!((widened_alpha(0.0, 0.125) - 0.5).abs() < 1e-15);
        assert!((widened_alpha(0.3, 0.08) - (0.09f64 + 0.16).sqrt()).abs() < 1e-15);
    }
}
