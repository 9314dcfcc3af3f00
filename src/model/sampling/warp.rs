//! Warps of two uniform random numbers to directions, with their solid-angle
//! densities, and the orthonormal frame built around a direction.
//!
//! Every warp takes its random numbers `u1, u2` in [0, 1) explicitly and is
//! deterministic, so the GLSL version fed the same numbers must agree.

use std::f64::consts::{FRAC_1_PI, PI, TAU};

use glam::DVec3;

/// Cosine-weighted direction on the hemisphere around +z (Malley's method:
/// a uniform point on the unit disc lifted to the hemisphere).
///
/// r = √u1, φ = 2π u2, result (r cos φ, r sin φ, √max(0, 1 − u1)).
/// Density [`pdf_cosine_hemisphere`] = cos θ / π.
pub fn sample_cosine_hemisphere(u1: f64, u2: f64) -> DVec3 {
    let r = u1.sqrt();
    let phi = TAU * u2;
    DVec3::new(r * phi.cos(), r * phi.sin(), (1.0 - u1).max(0.0).sqrt())
}

/// Solid-angle density of [`sample_cosine_hemisphere`]: max(0, w.z) / π.
pub fn pdf_cosine_hemisphere(w: DVec3) -> f64 {
    w.z.max(0.0) * FRAC_1_PI
}

/// Uniform direction on the unit sphere (Archimedes: z uniform in [−1, 1]).
///
/// z = 1 − 2 u1, r = √max(0, 1 − z²), φ = 2π u2, result (r cos φ, r sin φ, z).
/// Density [`pdf_uniform_sphere`] = 1 / (4π).
pub fn sample_uniform_sphere(u1: f64, u2: f64) -> DVec3 {
    let z = 1.0 - 2.0 * u1;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = TAU * u2;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// Solid-angle density of [`sample_uniform_sphere`]: 1 / (4π).
pub fn pdf_uniform_sphere() -> f64 {
    0.25 * FRAC_1_PI
}

/// Uniform direction in the cone of half-angle acos(`cos_max`) around +z.
///
/// cos θ = 1 − u1 (1 − cos_max), sin θ = √max(0, 1 − cos²θ), φ = 2π u2,
/// result (sin θ cos φ, sin θ sin φ, cos θ). Requires `cos_max` < 1.
/// Density [`pdf_uniform_cone`] = 1 / (2π (1 − cos_max)).
pub fn sample_uniform_cone(u1: f64, u2: f64, cos_max: f64) -> DVec3 {
    let cos_t = 1.0 - u1 * (1.0 - cos_max);
    let sin_t = (1.0 - cos_t * cos_t).max(0.0).sqrt();
    let phi = TAU * u2;
    DVec3::new(sin_t * phi.cos(), sin_t * phi.sin(), cos_t)
}

/// Solid-angle density of [`sample_uniform_cone`] at `w`:
/// 1 / (2π (1 − cos_max)) when w.z ≥ cos_max, else 0.
pub fn pdf_uniform_cone(cos_max: f64, w: DVec3) -> f64 {
    if w.z >= cos_max {
        uniform_cone_pdf(1.0 - cos_max)
    } else {
        0.0
    }
}

/// 1 / (2π · `one_minus_cos_max`): the density of a uniform cone given its
/// solid angle over 2π.
pub(crate) fn uniform_cone_pdf(one_minus_cos_max: f64) -> f64 {
    1.0 / (2.0 * PI * one_minus_cos_max)
}

/// The unit direction at polar angle `theta` from +z and azimuth `phi`.
pub fn spherical_direction(theta: f64, phi: f64) -> DVec3 {
    DVec3::new(theta.sin() * phi.cos(), theta.sin() * phi.sin(), theta.cos())
}

/// Two unit tangents (tu, tv) completing the unit `w` to a right-handed
/// orthonormal frame (tu × tv = w), as the renderer builds it:
/// a = |w.x| > 0.9 ? (0, 1, 0) : (1, 0, 0); tu = normalize(a × w); tv = w × tu.
pub fn frame_around(w: DVec3) -> (DVec3, DVec3) {
    let a = if w.x.abs() > 0.9 { DVec3::Y } else { DVec3::X };
    let tu = a.cross(w).normalize();
    let tv = w.cross(tu);
    (tu, tv)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn warps_give_unit_vectors_in_their_domains() {
        for i in 0..50 {
            for j in 0..50 {
                let (u1, u2) = (i as f64 / 50.0, j as f64 / 50.0);
                let c = sample_cosine_hemisphere(u1, u2);
                assert!((c.length() - 1.0).abs() < 1e-12 && c.z > 0.0);
                let s = sample_uniform_sphere(u1, u2);
                assert!((s.length() - 1.0).abs() < 1e-12);
                let k = sample_uniform_cone(u1, u2, 0.3);
                assert!((k.length() - 1.0).abs() < 1e-12 && k.z >= 0.3 - 1e-15);
            }
        }
    }

    #[test]
    fn frame_is_orthonormal_and_right_handed() {
        for w in [DVec3::X, DVec3::Y, DVec3::Z, -DVec3::X, DVec3::new(0.3, -0.5, 0.8).normalize()] {
            let (tu, tv) = frame_around(w);
            assert!((tu.length() - 1.0).abs() < 1e-12 && (tv.length() - 1.0).abs() < 1e-12);
            assert!(tu.dot(w).abs() < 1e-12 && tv.dot(w).abs() < 1e-12 && tu.dot(tv).abs() < 1e-12);
            assert!((tu.cross(tv) - w).length() < 1e-12);
        }
    }
}
