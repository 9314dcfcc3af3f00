//! Environment maps as textures: the lat-long parameterisation of
//! directions that environment maps use (`direction_to_uv`,
//! `uv_to_direction`; `glsl/lib/envmap.glsl` is their GPU side) and a
//! deterministic procedural sky to test them with. Sampling an environment
//! by its luminance is `sampling::envmap`'s.

use std::f64::consts::{PI, TAU};

use glam::{DVec2, DVec3};

use super::TextureImage;

/// The (u, v) of the unit direction `d`: φ = atan2(d.z, d.x),
/// θ = acos(clamp(d.y, −1, 1)), u = φ/(2π) + 1/2, v = θ/π.
pub fn direction_to_uv(d: DVec3) -> DVec2 {
    let phi = d.z.atan2(d.x);
    let theta = d.y.clamp(-1.0, 1.0).acos();
    DVec2::new(phi / TAU + 0.5, theta / PI)
}

/// The unit direction of (u, v): φ = 2π(u − 1/2), θ = πv,
/// d = (sin θ cos φ, cos θ, sin θ sin φ).
pub fn uv_to_direction(u: f64, v: f64) -> DVec3 {
    let (sin_p, cos_p) = (TAU * (u - 0.5)).sin_cos();
    let (sin_t, cos_t) = (PI * v).sin_cos();
    DVec3::new(sin_t * cos_p, cos_t, sin_t * sin_p)
}

/// Elevation of [`procedural_sky`]'s sun above the horizon, in degrees.
pub const SKY_SUN_ELEVATION_DEG: f64 = 35.0;
/// Azimuth φ = atan2(z, x) of [`procedural_sky`]'s sun, in degrees.
pub const SKY_SUN_AZIMUTH_DEG: f64 = 40.0;
/// Angular radius of [`procedural_sky`]'s sun disk, in degrees.
pub const SKY_SUN_RADIUS_DEG: f64 = 2.5;
/// Radiance of [`procedural_sky`]'s sun disk (linear RGB).
pub const SKY_SUN_RADIANCE: [f64; 3] = [2400.0, 2200.0, 1900.0];

/// The unit direction toward the centre of [`procedural_sky`]'s sun.
pub fn sky_sun_direction() -> DVec3 {
    let (e, a) = (SKY_SUN_ELEVATION_DEG.to_radians(), SKY_SUN_AZIMUTH_DEG.to_radians());
    DVec3::new(e.cos() * a.cos(), e.sin(), e.cos() * a.sin())
}

/// The radiance of the procedural sky in the unit direction `d`.
fn sky_radiance(d: DVec3, sun: DVec3) -> [f64; 3] {
    let cos_sun = d.dot(sun);
    if cos_sun >= SKY_SUN_RADIUS_DEG.to_radians().cos() {
        return SKY_SUN_RADIANCE;
    }
    if d.y < 0.0 {
        return [0.03, 0.028, 0.025];
    }
    const HORIZON: [f64; 3] = [0.75, 0.85, 1.0];
    const ZENITH: [f64; 3] = [0.1, 0.25, 0.75];
    const HALO: [f64; 3] = [1.0, 0.8, 0.5];
    let t = d.y.sqrt();
    let halo = 0.8 * (-40.0 * (1.0 - cos_sun)).exp();
    std::array::from_fn(|c| HORIZON[c] + (ZENITH[c] - HORIZON[c]) * t + HALO[c] * halo)
}

/// A deterministic `width` × `height` lat-long test environment with strong
/// structure, alpha 1, with its mip chain:
///
/// - a sun disk of angular radius [`SKY_SUN_RADIUS_DEG`] and radiance
///   [`SKY_SUN_RADIANCE`] toward [`sky_sun_direction`] (elevation
///   [`SKY_SUN_ELEVATION_DEG`], azimuth [`SKY_SUN_AZIMUTH_DEG`]);
/// - above the horizon a sky from (0.75, 0.85, 1.0) at the horizon to
///   (0.1, 0.25, 0.75) at the zenith (linear in √y), plus a halo
///   (1.0, 0.8, 0.5) · 0.8 exp(−40 (1 − cos γ)) around the sun (γ the angle
///   to it);
/// - below the horizon a dark ground (0.03, 0.028, 0.025).
///
/// Each texel is the mean of 4 × 4 point values at evenly spaced (u, v)
/// within it, so the sun, smaller than a texel at low resolution, is
/// anti-aliased.
///
/// # Panics
///
/// If a side is not a power of two from 1 to [`super::MAX_TEXTURE_SIZE`].
pub fn procedural_sky(width: u32, height: u32) -> TextureImage {
    for side in [width, height] {
        assert!(
            side.is_power_of_two() && side <= super::MAX_TEXTURE_SIZE,
            "environment size {width} x {height}: sides must be powers of two up to {}",
            super::MAX_TEXTURE_SIZE
        );
    }
    const SUB: usize = 4;
    let sun = sky_sun_direction();
    let (w, h) = (width as usize, height as usize);
    let texels = (0..w * h)
        .map(|k| {
            let (i, j) = (k % w, k / w);
            let mut sum = [0.0f64; 3];
            for a in 0..SUB {
                for b in 0..SUB {
                    let u = (i as f64 + (a as f64 + 0.5) / SUB as f64) / w as f64;
                    let v = (j as f64 + (b as f64 + 0.5) / SUB as f64) / h as f64;
                    let l = sky_radiance(uv_to_direction(u, v), sun);
                    (0..3).for_each(|c| sum[c] += l[c]);
                }
            }
            let n = (SUB * SUB) as f64;
            [(sum[0] / n) as f32, (sum[1] / n) as f32, (sum[2] / n) as f32, 1.0]
        })
        .collect();
    super::from_texels(format!("procedural_sky({width} x {height})"), width, height, texels)
}
