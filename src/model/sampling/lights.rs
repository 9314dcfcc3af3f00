//! Light sampling from a shading point, in world space, and the MIS weight.
//!
//! Every sampler returns a [`LightSample`]: the unit direction toward the
//! light, the distance to the point sampled on it, what it emits toward the
//! shading point, and the solid-angle density of the direction (`None` for a
//! delta light). The contribution to the radiance leaving the shading point
//! toward wo is f(wo, wi) · emitted · |cos θi| / pdf for an area or
//! environment light (emitted = radiance), f · emitted · |cos θi| for a delta
//! light (emitted = irradiance on a surface facing the light), once the
//! shadow ray up to `dist` is clear.

use std::f64::consts::TAU;

use glam::DVec3;

use super::warp::{frame_around, pdf_uniform_sphere, sample_uniform_sphere, uniform_cone_pdf};

/// A direction sampled toward a light.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightSample {
    /// Unit direction from the shading point toward the light.
    pub wi: DVec3,
    /// Distance along `wi` to the sampled point of the light
    /// (`f64::INFINITY` for directional and environment lights).
    pub dist: f64,
    /// Radiance arriving along `wi` (area and environment lights), or the
    /// irradiance on a surface facing the light (delta lights).
    pub emitted: DVec3,
    /// Solid-angle density of `wi`; `None` for a delta light.
    pub pdf: Option<f64>,
}

/// The cone a sphere subtends from `x`: (w, cos_max, 1 − cos_max), or `None`
/// when `x` is inside the sphere (or on it).
///
/// cos_max = √max(0, 1 − R²/|c − x|²); 1 − cos_max is computed as
/// sin²max / (1 + cos_max), the same number without cancellation for small
/// or distant spheres.
fn sphere_cone(x: DVec3, centre: DVec3, radius: f64) -> Option<(DVec3, f64, f64)> {
    let to_c = centre - x;
    let d2 = to_c.length_squared();
    if d2 <= radius * radius {
        return None;
    }
    let sin2_max = radius * radius / d2;
    let cos_max = (1.0 - sin2_max).max(0.0).sqrt();
    Some((to_c / d2.sqrt(), cos_max, sin2_max / (1.0 + cos_max)))
}

/// Samples the sphere light (centre, radius, uniform `radiance`) from `x`:
/// uniformly within the cone of directions it subtends.
///
/// cos_max = √max(0, 1 − R²/|c − x|²); cos_a = 1 − u1 (1 − cos_max),
/// sin_a = √max(0, 1 − cos_a²) (computed as √(v (2 − v)), v = u1 (1 − cos_max),
/// the same number), φ = 2π u2; with w = (c − x)/|c − x| and the frame of
/// [`frame_around`]`(w)` = (tu, tv):
/// wi = normalize(cos_a w + sin_a (cos φ tu + sin φ tv)).
/// pdf = 1/(2π (1 − cos_max)); `dist` = the first intersection of the ray
/// with the sphere (with the discriminant clamped at 0, so directions on the
/// cone's rim graze the sphere). `None` when `x` is inside the sphere.
pub fn sample_sphere_light(
    x: DVec3,
    centre: DVec3,
    radius: f64,
    radiance: DVec3,
    u1: f64,
    u2: f64,
) -> Option<LightSample> {
    let (w, _, one_minus_cos_max) = sphere_cone(x, centre, radius)?;
    let v = u1 * one_minus_cos_max;
    let cos_a = 1.0 - v;
    let sin_a = (v * (2.0 - v)).max(0.0).sqrt();
    let phi = TAU * u2;
    let (tu, tv) = frame_around(w);
    let wi = (cos_a * w + sin_a * (phi.cos() * tu + phi.sin() * tv)).normalize();
    let dist = sphere_first_hit(x, wi, centre, radius);
    Some(LightSample { wi, dist, emitted: radiance, pdf: Some(uniform_cone_pdf(one_minus_cos_max)) })
}

/// Distance from `x` (outside the sphere) along the unit `wi` to the first
/// intersection with the sphere, assuming the ray hits it: with oc = x − c,
/// b = oc·wi, c' = |oc|² − R², disc = max(0, b² − c'), the near root
/// −b − √disc, computed as c' / (−b + √disc) (the product of the roots is c').
fn sphere_first_hit(x: DVec3, wi: DVec3, centre: DVec3, radius: f64) -> f64 {
    let oc = x - centre;
    let b = oc.dot(wi);
    let c = oc.length_squared() - radius * radius;
    let disc = (b * b - c).max(0.0);
    c / (-b + disc.sqrt())
}

/// The density with which [`sample_sphere_light`] produces the unit `wi`
/// from `x`: 1/(2π (1 − cos_max)) if wi is inside the cone
/// (wi·w ≥ cos_max), else 0; 0 when `x` is inside the sphere.
pub fn pdf_sphere_light(x: DVec3, centre: DVec3, radius: f64, wi: DVec3) -> f64 {
    match sphere_cone(x, centre, radius) {
        Some((w, cos_max, one_minus_cos_max)) if wi.dot(w) >= cos_max => uniform_cone_pdf(one_minus_cos_max),
        _ => 0.0,
    }
}

/// Samples the one-sided parallelogram light {corner + a edge_u + b edge_v,
/// a, b ∈ [0, 1]}, emitting `radiance` toward n = normalize(edge_u × edge_v),
/// from `x`, uniformly by area.
///
/// p = corner + u1 edge_u + u2 edge_v; wi = normalize(p − x), dist = |p − x|;
/// cos_l = n·(−wi); `None` when cos_l ≤ 0 (the back side: no contribution)
/// or the light is degenerate; pdf = dist² / (area cos_l),
/// area = |edge_u × edge_v|.
pub fn sample_rect_light(
    x: DVec3,
    corner: DVec3,
    edge_u: DVec3,
    edge_v: DVec3,
    radiance: DVec3,
    u1: f64,
    u2: f64,
) -> Option<LightSample> {
    let nu = edge_u.cross(edge_v);
    let area = nu.length();
    if area == 0.0 {
        return None;
    }
    let p = corner + u1 * edge_u + u2 * edge_v;
    let d = p - x;
    let dist2 = d.length_squared();
    let dist = dist2.sqrt();
    if dist == 0.0 {
        return None;
    }
    let wi = d / dist;
    let cos_l = -(nu / area).dot(wi);
    if cos_l <= 0.0 {
        return None;
    }
    Some(LightSample { wi, dist, emitted: radiance, pdf: Some(dist2 / (area * cos_l)) })
}

/// The density with which [`sample_rect_light`] produces the unit `wi` from
/// `x`: intersect the ray x + t wi (t > 0) with the parallelogram's plane,
/// keep it if it arrives on the front side (wi·n < 0) and the hit
/// q = corner + a edge_u + b edge_v has a, b ∈ [0, 1]
/// (a = ((q − corner) × edge_v)·N / |N|², b = (edge_u × (q − corner))·N / |N|²,
/// N = edge_u × edge_v); then pdf = t² / (area cos_l), cos_l = −wi·n; else 0.
pub fn pdf_rect_light(x: DVec3, corner: DVec3, edge_u: DVec3, edge_v: DVec3, wi: DVec3) -> f64 {
    let nu = edge_u.cross(edge_v);
    let area2 = nu.length_squared();
    let denom = wi.dot(nu);
    if area2 == 0.0 || denom >= 0.0 {
        return 0.0;
    }
    let t = (corner - x).dot(nu) / denom;
    if t <= 0.0 {
        return 0.0;
    }
    let q = x + t * wi - corner;
    let a = q.cross(edge_v).dot(nu) / area2;
    let b = edge_u.cross(q).dot(nu) / area2;
    if !(0.0..=1.0).contains(&a) || !(0.0..=1.0).contains(&b) {
        return 0.0;
    }
    let area = area2.sqrt();
    let cos_l = -denom / area;
    t * t / (area * cos_l)
}

/// The directional light (the sun): a delta light, wi = normalize(direction)
/// (from the scene toward the light), emitted = the irradiance on a surface
/// facing it; its contribution is f · irradiance · cos θi.
pub fn sample_directional_light(direction: DVec3, irradiance: DVec3) -> LightSample {
    LightSample { wi: direction.normalize(), dist: f64::INFINITY, emitted: irradiance, pdf: None }
}

/// An isotropic point light of radiant intensity `intensity` (W/sr) at
/// `position`: a delta light, wi = normalize(position − x), dist = |position − x|,
/// emitted = intensity / dist² (the irradiance on a surface facing it).
/// `None` when x is the light's position. (Not in the written conventions;
/// the scene has point lights, and the current renderer treats them so.)
pub fn sample_point_light(x: DVec3, position: DVec3, intensity: DVec3) -> Option<LightSample> {
    let d = position - x;
    let dist2 = d.length_squared();
    if dist2 == 0.0 {
        return None;
    }
    let dist = dist2.sqrt();
    Some(LightSample { wi: d / dist, dist, emitted: intensity / dist2, pdf: None })
}

/// The uniform environment (the scene background: the same `radiance` from
/// every direction), sampled uniformly over the whole sphere of directions
/// with [`sample_uniform_sphere`](u1, u2): pdf = 1/(4π), dist = ∞. Directions
/// below the shading surface are returned too (their cos θi ≤ 0 makes their
/// contribution 0 for reflection).
pub fn sample_uniform_environment(radiance: DVec3, u1: f64, u2: f64) -> LightSample {
    LightSample {
        wi: sample_uniform_sphere(u1, u2),
        dist: f64::INFINITY,
        emitted: radiance,
        pdf: Some(pdf_uniform_sphere()),
    }
}

/// The density of [`sample_uniform_environment`]: 1/(4π) for every direction.
pub fn pdf_uniform_environment() -> f64 {
    pdf_uniform_sphere()
}

/// Veach's power heuristic (β = 2) MIS weight of a sample drawn from the
/// strategy with density `pdf_a` when `pdf_b` is the other strategy's
/// density: a² / (a² + b²) (E. Veach, "Robust Monte Carlo Methods for Light
/// Transport Simulation", PhD thesis, 1997, §9.2.4).
///
/// Evaluated as 1 / (1 + (b/a)²): 0 when a = 0, 1 when a = ∞ (a delta
/// strategy) and b finite, and no overflow of the squares.
pub fn power_heuristic(pdf_a: f64, pdf_b: f64) -> f64 {
    if pdf_a <= 0.0 {
        return 0.0;
    }
    let r = pdf_b / pdf_a;
    1.0 / (1.0 + r * r)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sphere_light_samples_hit_the_sphere_inside_the_cone() {
        let (x, c, r) = (DVec3::new(0.1, -0.2, 0.3), DVec3::new(2.0, 1.0, -1.0), 0.7);
        for i in 0..30 {
            for j in 0..30 {
                let s = sample_sphere_light(x, c, r, DVec3::ONE, i as f64 / 30.0, j as f64 / 30.0).unwrap();
                let hit = x + s.dist * s.wi;
                assert!(((hit - c).length() - r).abs() < 1e-9, "{}", (hit - c).length());
                assert_eq!(pdf_sphere_light(x, c, r, s.wi), s.pdf.unwrap());
            }
        }
        assert!(sample_sphere_light(c, c, r, DVec3::ONE, 0.5, 0.5).is_none());
    }

    #[test]
    fn rect_light_pdf_matches_sample() {
        let (corner, eu, ev) = (DVec3::new(-1.0, 2.0, -1.0), DVec3::new(2.0, 0.0, 0.0), DVec3::new(0.0, 0.0, 1.5));
        // edge_u × edge_v = (0, -3, 0): emits toward −y, so x below it sees the front.
        let x = DVec3::new(0.3, -0.5, 0.2);
        for i in 0..10 {
            for j in 0..10 {
                let s =
                    sample_rect_light(x, corner, eu, ev, DVec3::ONE, i as f64 / 10.0 + 0.05, j as f64 / 10.0).unwrap();
                let pdf = pdf_rect_light(x, corner, eu, ev, s.wi);
                assert!((pdf - s.pdf.unwrap()).abs() < 1e-12 * pdf);
            }
        }
        let behind = DVec3::new(0.0, 3.0, 0.0);
        assert!(sample_rect_light(behind, corner, eu, ev, DVec3::ONE, 0.5, 0.5).is_none());
        assert_eq!(pdf_rect_light(behind, corner, eu, ev, -DVec3::Y), 0.0);
    }

    #[test]
    fn power_heuristic_limits() {
        assert_eq!(power_heuristic(0.0, 0.0), 0.0);
        assert_eq!(power_heuristic(f64::INFINITY, 3.0), 1.0);
        assert!((power_heuristic(1.0, 2.0) - 0.2).abs() < 1e-15);
    }
}
