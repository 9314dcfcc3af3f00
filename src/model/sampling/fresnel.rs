//! Fresnel reflectance: dielectric interfaces, conductors (complex index of
//! refraction) and Schlick's approximation.

use glam::DVec3;

/// Unpolarised Fresnel reflectance of a smooth dielectric interface.
///
/// `eta` = n_inside / n_outside; `cos_i` is the cosine between the incident
/// direction (pointing away from the surface) and the normal, which points
/// outside. A negative `cos_i` means the ray arrives from inside: then
/// eta' = 1/eta and cos_i' = −cos_i are used. With sin²θt = (1 − cos²θi)/eta²,
/// sin²θt ≥ 1 is total internal reflection (returns 1); otherwise, with
/// cos θt = √(1 − sin²θt),
/// r∥ = (eta cos θi − cos θt)/(eta cos θi + cos θt),
/// r⊥ = (cos θi − eta cos θt)/(cos θi + eta cos θt), F = (r∥² + r⊥²)/2
/// (the Fresnel equations, e.g. Born & Wolf, "Principles of Optics", §1.5.2;
/// Walter et al. 2007, eq. 22, is the same quantity).
pub fn fresnel_dielectric(cos_i: f64, eta: f64) -> f64 {
    let (cos_i, eta) = if cos_i < 0.0 { (-cos_i, 1.0 / eta) } else { (cos_i, eta) };
    let cos_i = cos_i.min(1.0);
    let sin2_t = (1.0 - cos_i * cos_i) / (eta * eta);
    if sin2_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin2_t).sqrt();
    let r_par = (eta * cos_i - cos_t) / (eta * cos_i + cos_t);
    let r_perp = (cos_i - eta * cos_t) / (cos_i + eta * cos_t);
    0.5 * (r_par * r_par + r_perp * r_perp)
}

/// Unpolarised Fresnel reflectance of a conductor of complex relative index
/// of refraction η + iκ (per RGB channel), for `cos_i` ∈ [0, 1] (clamped).
///
/// The exact equations for an absorbing medium (Born & Wolf §14.2; in this
/// form e.g. S. Lagarde, "Memo on Fresnel equations", 2013, and Pharr, Jakob &
/// Humphreys, "Physically Based Rendering", 3rd ed., §8.2.1): with
/// s² = 1 − cos²θ, t0 = η² − κ² − s²,
/// a² + b² = √(t0² + 4η²κ²), a = √((a² + b² + t0)/2),
/// Rs = (a² + b² − 2a cos θ + cos²θ) / (a² + b² + 2a cos θ + cos²θ),
/// Rp = Rs (cos²θ (a² + b²) − 2a cos θ s² + s⁴) / (cos²θ (a² + b²) + 2a cos θ s² + s⁴),
/// F = (Rs + Rp)/2. For κ = 0 this is [`fresnel_dielectric`] (a = η cos θt
/// below the critical angle, a = 0 and F = 1 beyond it).
pub fn fresnel_conductor(cos_i: f64, eta: DVec3, k: DVec3) -> DVec3 {
    DVec3::new(
        conductor_channel(cos_i, eta.x, k.x),
        conductor_channel(cos_i, eta.y, k.y),
        conductor_channel(cos_i, eta.z, k.z),
    )
}

fn conductor_channel(cos_i: f64, eta: f64, k: f64) -> f64 {
    let c = cos_i.clamp(0.0, 1.0);
    let c2 = c * c;
    let s2 = 1.0 - c2;
    let t0 = eta * eta - k * k - s2;
    let a2b2 = (t0 * t0 + 4.0 * eta * eta * k * k).sqrt();
    let a = (0.5 * (a2b2 + t0)).max(0.0).sqrt();
    let t1 = a2b2 + c2;
    let t2 = 2.0 * a * c;
    if t1 + t2 <= 0.0 {
        // Only for η = 1, κ = 0 at grazing incidence: the limit is 1.
        return 1.0;
    }
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = c2 * a2b2 + s2 * s2;
    let t4 = t2 * s2;
    if t3 + t4 <= 0.0 {
        return rs;
    }
    let rp = rs * (t3 - t4) / (t3 + t4);
    0.5 * (rs + rp)
}

/// Schlick's approximation F = f0 + (1 − f0)(1 − cos θ)⁵, `cos_i` clamped to
/// [0, 1] (C. Schlick, "An Inexpensive BRDF Model for Physically-based
/// Rendering", Computer Graphics Forum 13(3), 1994, eq. 15).
pub fn fresnel_schlick(cos_i: f64, f0: DVec3) -> DVec3 {
    let m = 1.0 - cos_i.clamp(0.0, 1.0);
    let m2 = m * m;
    f0 + (DVec3::ONE - f0) * (m2 * m2 * m)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn normal_incidence_values() {
        let eta = 1.5;
        let f = fresnel_dielectric(1.0, eta);
        assert!((f - ((eta - 1.0) / (eta + 1.0)).powi(2)).abs() < 1e-15);
        // The same from inside.
        assert!((fresnel_dielectric(-1.0, eta) - f).abs() < 1e-15);
        let (n, k) = (0.2, 3.0);
        let want = ((n - 1.0) * (n - 1.0) + k * k) / ((n + 1.0) * (n + 1.0) + k * k);
        let got = fresnel_conductor(1.0, DVec3::splat(n), DVec3::splat(k));
        assert!((got - DVec3::splat(want)).abs().max_element() < 1e-14);
    }

    #[test]
    fn grazing_incidence_reflects_everything() {
        assert_eq!(fresnel_dielectric(0.0, 1.5), 1.0);
        assert!((fresnel_conductor(0.0, DVec3::splat(0.2), DVec3::splat(3.0)) - DVec3::ONE).length() < 1e-14);
        assert_eq!(fresnel_schlick(0.0, DVec3::splat(0.04)), DVec3::ONE);
    }
}
