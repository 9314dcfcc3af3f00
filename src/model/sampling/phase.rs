//! The Henyey–Greenstein phase function (L. G. Henyey, J. L. Greenstein,
//! "Diffuse radiation in the galaxy", ApJ 93, 1941) of homogeneous media:
//! its density and an exact inversion sampler. CPU twin of `glsl/lib/media.glsl`.
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

/// Largest share of the scattered directions that a scattering event in a
/// medium aims past a positional light ([`sample_halo`]) instead of sampling
/// the phase function; the pair is one mixture density ([`scatter_pdf`])
/// whose weight, phase / mixture, is at most 1 / (1 − share). [`halo_share`]
/// takes less where that would lift a path's throughput above 2.
pub const HALO_SHARE: f64 = 0.5;

/// A direction around the unit axis `a` (from a scattering point toward a
/// light's centre) with θ, its angle to `a`, of density ∝ π − θ on [0, π] and
/// φ uniform. Its solid-angle density (π − θ) / (π³ sin θ) has the shape of
/// a small light's halo seen from a point D away in a medium: the single
/// scattering along a ray at angle θ, ∫_0^∞ dt / (D² + t² − 2 D t cos θ) =
/// (π − θ) / (D sin θ) (the "airlight" integral; Sun, Ramamoorthi, Narasimhan,
/// Nayar 2005, "A practical analytic single scattering model"), so a
/// direction that passes close to the light, whose segment's equiangular
/// estimate is large, is sampled as often as it matters. CPU twin of
/// `sampleHalo` in `glsl/lib/media.glsl`.
pub fn sample_halo(a: DVec3, u1: f64, u2: f64) -> DVec3 {
    let theta = PI * (1.0 - (1.0 - u1).max(0.0).sqrt());
    let (sin_theta, cos_theta) = theta.sin_cos();
    let phi = 2.0 * PI * u2;
    let (t, b) = a.any_orthonormal_pair();
    (t * (sin_theta * phi.cos()) + b * (sin_theta * phi.sin()) + a * cos_theta).normalize()
}

/// The solid-angle density of [`sample_halo`] around `a` at `w`.
pub fn halo_pdf(a: DVec3, w: DVec3) -> f64 {
    let sin_theta = a.cross(w).length();
    let theta = sin_theta.atan2(a.dot(w));
    (PI - theta) / (PI * PI * PI * sin_theta.max(1e-12))
}

/// The halo's share of the mixture at a scattering event in a medium, for a
/// path whose throughput (η-corrected, after the event's albedo and Russian
/// roulette; its largest channel) is `throughput`: [`HALO_SHARE`], less
/// where the weight, at most 1 / (1 − share), could lift the throughput above
/// 2, and 0 from 2 on. CPU twin of `haloShare` in `glsl/render/nee.glsl`.
pub fn halo_share(throughput: f64) -> f64 {
    (1.0 - 0.5 * throughput).clamp(0.0, HALO_SHARE)
}

/// The mixture density of a scattered direction in a medium: the phase
/// function (travel direction `d`, anisotropy `g`) with weight 1 − `share`,
/// and the halo around each of `axes` (toward the point and sphere lights,
/// each alike) with `share`. With no axis or no share, the phase function alone.
pub fn scatter_pdf(g: f64, d: DVec3, axes: &[DVec3], share: f64, w: DVec3) -> f64 {
    let phase = hg_pdf(g, d.dot(w));
    if axes.is_empty() || share <= 0.0 {
        return phase;
    }
    let halo = axes.iter().map(|&a| halo_pdf(a, w)).sum::<f64>() / axes.len() as f64;
    (1.0 - share) * phase + share * halo
}

/// A sample of [`scatter_pdf`]: `u[0]` picks the strategy (and, for the
/// halo, which axis), `u[1]` and `u[2]` the direction.
pub fn sample_scatter(g: f64, d: DVec3, axes: &[DVec3], share: f64, u: [f64; 3]) -> DVec3 {
    if axes.is_empty() || u[0] >= share {
        return sample_hg(g, d, u[1], u[2]);
    }
    let which = ((u[0] / share * axes.len() as f64) as usize).min(axes.len() - 1);
    sample_halo(axes[which], u[1], u[2])
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::sampling::chi2::integrate_sphere;

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

    #[test]
    fn halo_density_is_its_sampler_s_and_integrates_to_one() {
        // Over θ about the axis (dω = sin θ dθ dφ cancels the density's
        // 1/sin θ pole), by the midpoint rule: the density times sin θ is
        // 2 (π − θ) / π² per radian once φ is integrated, whose integral is 1.
        let a = DVec3::new(-0.2, 0.7, 0.4).normalize();
        let (t, b) = a.any_orthonormal_pair();
        let n = 20000;
        let mut total = 0.0;
        for i in 0..n {
            let theta = PI * (i as f64 + 0.5) / n as f64;
            let phi = 2.0 * PI * ((i * 7919) % n) as f64 / n as f64;
            let w = (t * phi.cos() + b * phi.sin()) * theta.sin() + a * theta.cos();
            let density = halo_pdf(a, w) * theta.sin() * 2.0 * PI;
            assert!((density - 2.0 * (PI - theta) / (PI * PI)).abs() < 1e-9, "θ {theta}: {density}");
            total += density * PI / n as f64;
        }
        assert!((total - 1.0).abs() < 1e-6, "{total}");
    }

    #[test]
    fn the_mixture_weight_is_at_most_its_bound() {
        // phase / mixture <= 1 / (1 - share) in every direction, and a
        // throughput of at most 2 stays at most 2 (one above 2 does not grow).
        let d = DVec3::new(0.1, 0.2, 0.97).normalize();
        let axes = [DVec3::new(0.5, -0.5, 0.2).normalize()];
        for throughput in [0.1, 0.5, 0.7, 0.95, 1.0, 1.6, 2.0, 2.5] {
            let share = halo_share(throughput);
            for i in 0..2000 {
                let w = sample_hg(0.7, d, (i as f64 + 0.5) / 2000.0, (i as f64 * 0.618).fract());
                let weight = hg_pdf(0.7, d.dot(w)) / scatter_pdf(0.7, d, &axes, share, w);
                assert!(weight <= 1.0 / (1.0 - share) + 1e-12, "{weight}");
                let after = throughput * weight;
                assert!(after <= throughput.max(2.0) + 1e-12, "throughput {throughput}: {after}");
            }
        }
    }
}
