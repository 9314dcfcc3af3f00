//! The Henyey–Greenstein phase function (L. G. Henyey, J. L. Greenstein,
//! "Diffuse radiation in the galaxy", ApJ 93, 1941) of homogeneous media:
//! its density and an exact inversion sampler. CPU twin of `glsl/media.glsl`.
//!
//! Convention: a path travels along `d` (unit) and scatters into `w`; with
//! cos θ = d · w, `g > 0` scatters forward, `g < 0` back, `g = 0` is
//! isotropic. The phase function is a density over the sphere of `w`:
//! p(cos θ) = (1 − g²) / (4π (1 + g² − 2g cos θ)^{3/2}).

use glam::DVec3;
use std::f64::consts::PI;

/// |g| below this is treated as isotropic (the inversion formula divides by g).
pub const ISOTROPIC_G: f64 = 1e-3;

/// Largest |g| accepted (the lobe becomes a delta at ±1).
pub const MAX_G: f64 = 0.99;

/// The phase function's value (= its pdf) for cos θ between the travel
/// direction and the scattered direction.
pub fn hg_pdf(g: f64, cos_theta: f64) -> f64 {
    let g = g.clamp(-MAX_G, MAX_G);
    let denom = 1.0 + g * g - 2.0 * g * cos_theta;
    (1.0 - g * g) / (4.0 * PI * denom * denom.sqrt())
}

/// cos θ of a sample, by inverting the CDF of cos θ with `u` ∈ [0, 1).
pub fn sample_hg_cos(g: f64, u: f64) -> f64 {
    let g = g.clamp(-MAX_G, MAX_G);
    if g.abs() < ISOTROPIC_G {
        return 1.0 - 2.0 * u;
    }
    let s = (1.0 - g * g) / (1.0 - g + 2.0 * g * u);
    ((1.0 + g * g - s * s) / (2.0 * g)).clamp(-1.0, 1.0)
}

/// A scattered direction for a path travelling along `d` (unit).
pub fn sample_hg(g: f64, d: DVec3, u1: f64, u2: f64) -> DVec3 {
    let cos_theta = sample_hg_cos(g, u1);
    let sin_theta = (1.0 - cos_theta * cos_theta).max(0.0).sqrt();
    let phi = 2.0 * PI * u2;
    let (t, b) = d.any_orthonormal_pair();
    (t * (sin_theta * phi.cos()) + b * (sin_theta * phi.sin()) + d * cos_theta).normalize()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::sampling::chi2::integrate_sphere;

    #[test]
    fn density_integrates_to_one() {
        for g in [-0.9, -0.3, 0.0, 0.5, 0.95] {
            let d = DVec3::new(0.3, -0.4, 0.866).normalize();
            let total = integrate_sphere(&|w| hg_pdf(g, d.dot(w)), 1e-7);
            assert!((total - 1.0).abs() < 1e-4, "g = {g}: {total}");
        }
    }

    #[test]
    fn sampler_inverts_the_cdf() {
        // The sampler maps u = 0 to cos θ = −1 and u → 1 to +1, so the
        // density's mass below the sampled cos θ is u.
        for g in [-0.7, 0.2, 0.8] {
            for u in [0.1, 0.37, 0.5, 0.9] {
                let c = sample_hg_cos(g, u);
                let n = 20000;
                let cdf: f64 = (0..n)
                    .map(|i| {
                        let x = -1.0 + (c + 1.0) * (i as f64 + 0.5) / n as f64;
                        2.0 * PI * hg_pdf(g, x) * (c + 1.0) / n as f64
                    })
                    .sum();
                assert!((cdf - u).abs() < 1e-4, "g {g}, u {u}: cdf {cdf}");
            }
        }
    }

    #[test]
    fn mean_cosine_is_g() {
        for g in [-0.5, 0.0, 0.3, 0.9] {
            let n = 200000;
            let mean: f64 = (0..n).map(|i| sample_hg_cos(g, (i as f64 + 0.5) / n as f64)).sum::<f64>() / n as f64;
            assert!((mean - g).abs() < 1e-3, "g {g}: {mean}");
        }
    }
}
