//! The GGX (Trowbridge–Reitz) microfacet distribution, isotropic, in the
//! local shading frame (normal +z), with Smith masking and visible-normal
//! sampling.
//!
//! The roughness parameter α is the perceptual roughness squared
//! ([`alpha_from_roughness`]); lobes with α < [`DELTA_ALPHA`] are treated as
//! perfectly specular (delta) by the BSDFs.

use std::f64::consts::{FRAC_1_PI, TAU};

use glam::DVec3;

/// Below this α a microfacet lobe is a delta (perfect specular) lobe.
pub const DELTA_ALPHA: f64 = 1e-3;

/// GGX α of a perceptual roughness r ∈ [0, 1]: α = r².
pub fn alpha_from_roughness(roughness: f64) -> f64 {
    roughness * roughness
}

/// The GGX normal distribution D(m) for a unit microfacet normal `m`.
///
/// Trowbridge & Reitz 1975; Walter, Marschner, Li & Torrance, "Microfacet
/// Models for Refraction through Rough Surfaces", EGSR 2007, eq. 33:
/// D(m) = α² / (π ((m.z)² (α² − 1) + 1)²) for m.z > 0, else 0.
/// Normalised so that ∫ D(m) m.z dω_m = 1.
///
/// The bracket is evaluated as (m.x² + m.y²) + α² m.z², the same number for a
/// unit m: the written form 1 − m.z² (1 − α²) cancels near the peak
/// (m.z → 1) when α is small, which costs relative precision ~ε/α² (1e-10 in
/// f64 at α = 1e-3, but ~6% in f32).
pub fn d(alpha: f64, m: DVec3) -> f64 {
    if m.z <= 0.0 {
        return 0.0;
    }
    let a2 = alpha * alpha;
    let t = (m.x * m.x + m.y * m.y) + a2 * m.z * m.z;
    a2 * FRAC_1_PI / (t * t)
}

/// Smith's Λ for GGX: Λ(w) = (√(1 + α² (w.x² + w.y²) / w.z²) − 1) / 2
/// (E. Heitz, "Understanding the Masking-Shadowing Function in
/// Microfacet-Based BRDFs", JCGT 3(2), 2014, eq. 72).
///
/// Evaluated as a / (2 (√(1 + a) + 1)) with a = α² tan²θ, which is the same
/// number without the cancellation of √(1 + a) − 1 for small a. Depends on
/// |w.z| only (symmetric in the two hemispheres); +∞ for w.z = 0.
pub fn lambda(alpha: f64, w: DVec3) -> f64 {
    let z2 = w.z * w.z;
    if z2 == 0.0 {
        return f64::INFINITY;
    }
    let a = alpha * alpha * (w.x * w.x + w.y * w.y) / z2;
    a / (2.0 * ((1.0 + a).sqrt() + 1.0))
}

/// Smith masking G1(w) = 1 / (1 + Λ(w)) (Heitz 2014, eq. 43).
pub fn g1(alpha: f64, w: DVec3) -> f64 {
    1.0 / (1.0 + lambda(alpha, w))
}

/// Height-correlated Smith masking-shadowing
/// G2(wo, wi) = 1 / (1 + Λ(wo) + Λ(wi)) (Heitz 2014, eq. 99, for the
/// reflection configuration).
pub fn g2(alpha: f64, wo: DVec3, wi: DVec3) -> f64 {
    1.0 / (1.0 + lambda(alpha, wo) + lambda(alpha, wi))
}

/// A microfacet normal m distributed by the visible-normal density
/// [`pdf_vndf`] for the view direction `wo` (wo.z > 0 required).
///
/// Exactly the algorithm of E. Heitz, "Sampling the GGX Distribution of
/// Visible Normals", JCGT 7(4), 2018 (listing 1), isotropic α:
/// stretch the view, Vh = normalize(α wo.x, α wo.y, wo.z); build
/// T1 = lensq > 0 ? (−Vh.y, Vh.x, 0)/√lensq : (1, 0, 0) with
/// lensq = Vh.x² + Vh.y², T2 = Vh × T1; a uniform point on the disc
/// (t1, t2) = √u1 (cos 2πu2, sin 2πu2), warped to the projected hemisphere,
/// s = (1 + Vh.z)/2, t2 ← (1 − s) √(1 − t1²) + s t2; reproject,
/// Nh = t1 T1 + t2 T2 + √max(0, 1 − t1² − t2²) Vh; unstretch,
/// m = normalize(α Nh.x, α Nh.y, max(0, Nh.z)).
pub fn sample_vndf(alpha: f64, wo: DVec3, u1: f64, u2: f64) -> DVec3 {
    debug_assert!(wo.z > 0.0, "sample_vndf needs wo in the upper hemisphere");
    let vh = DVec3::new(alpha * wo.x, alpha * wo.y, wo.z).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1v = if lensq > 0.0 { DVec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt() } else { DVec3::X };
    let t2v = vh.cross(t1v);
    let r = u1.sqrt();
    let phi = TAU * u2;
    let t1 = r * phi.cos();
    let mut t2 = r * phi.sin();
    let s = 0.5 * (1.0 + vh.z);
    t2 = (1.0 - s) * (1.0 - t1 * t1).sqrt() + s * t2;
    let nh = t1 * t1v + t2 * t2v + (1.0 - t1 * t1 - t2 * t2).max(0.0).sqrt() * vh;
    DVec3::new(alpha * nh.x, alpha * nh.y, nh.z.max(0.0)).normalize()
}

/// Density of [`sample_vndf`] over the solid angle of m, the distribution of
/// visible normals (Heitz 2018, eq. 3; Heitz 2014, eq. 16):
/// D_wo(m) = G1(wo) max(0, wo·m) D(m) / wo.z. Zero for wo.z ≤ 0.
pub fn pdf_vndf(alpha: f64, wo: DVec3, m: DVec3) -> f64 {
    if wo.z <= 0.0 {
        return 0.0;
    }
    g1(alpha, wo) * wo.dot(m).max(0.0) * d(alpha, m) / wo.z
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn d_matches_the_written_formula() {
        for alpha in [0.01, 0.3, 1.0] {
            for z in [0.05f64, 0.4, 0.99, 1.0] {
                let m = DVec3::new(0.0, (1.0 - z * z).sqrt(), z);
                let t = z * z * (alpha * alpha - 1.0) + 1.0;
                let written = alpha * alpha / (std::f64::consts::PI * t * t);
                assert!((d(alpha, m) - written).abs() <= 1e-12 * written, "{alpha} {z}");
            }
        }
        assert_eq!(d(0.5, DVec3::new(1.0, 0.0, 0.0)), 0.0);
    }

    #[test]
    fn lambda_matches_the_direct_formula() {
        for alpha in [0.01, 0.3, 1.0] {
            for z in [0.05f64, 0.4, 0.99] {
                let w = DVec3::new((1.0 - z * z).sqrt(), 0.0, z);
                let direct = ((1.0 + alpha * alpha * (w.x * w.x) / (z * z)).sqrt() - 1.0) / 2.0;
                assert!((lambda(alpha, w) - direct).abs() <= 1e-12 * direct.max(1.0));
            }
        }
        assert_eq!(lambda(0.5, DVec3::Z), 0.0);
        assert_eq!(g1(0.5, DVec3::X), 0.0);
    }

    #[test]
    fn vndf_samples_are_visible_unit_normals() {
        for alpha in [0.002, 0.1, 1.0] {
            for wo in [DVec3::Z, DVec3::new(0.6, 0.0, 0.8), DVec3::new(-0.3, 0.7, 0.1).normalize()] {
                for i in 0..20 {
                    for j in 0..20 {
                        let m = sample_vndf(alpha, wo, i as f64 / 20.0, j as f64 / 20.0);
                        assert!((m.length() - 1.0).abs() < 1e-12);
                        assert!(m.z >= 0.0 && wo.dot(m) >= -1e-12, "{m} for {wo}");
                    }
                }
            }
        }
    }
}
