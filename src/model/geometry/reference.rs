//! The reference ray intersection in f64: the first root of F' along a ray,
//! found exactly from the piecewise-polynomial structure of F' (`NOTES.md` §1).
//!
//! Along o + t d, F and every Q_i are quadratics in t. The breakpoints where
//! some Q_i changes sign cut the ray into pieces; on each, F' is the
//! polynomial F + Σ_active f_i Q_i³ of degree <= 6, whose first root is
//! isolated by [`poly::first_root`]. This uses all perturbations (no cells), so
//! it also checks the GPU's cell culling. The GPU twin is `glsl/intersection/intersect.glsl`.

use glam::DVec3;

use super::{poly, Aabb, FunctionalObject};

/// A ray hit in the object's frame.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Hit {
    /// Ray parameter of the hit.
    pub t: f64,
    /// Outward unit normal (-∇F' normalised).
    pub normal: DVec3,
}

/// The first hit of o + t d with the object's surface for t in [t_min, t_max].
pub fn intersect(obj: &FunctionalObject, o: DVec3, d: DVec3, t_min: f64, t_max: f64) -> Option<Hit> {
    intersect_within(obj, &obj.bounds().ok()?, o, d, t_min, t_max)
}

/// [`intersect`] with the object's bounds ([`FunctionalObject::bounds`]) given,
/// for callers that trace many rays.
pub fn intersect_within(
    obj: &FunctionalObject,
    bounds: &Aabb,
    o: DVec3,
    d: DVec3,
    t_min: f64,
    t_max: f64,
) -> Option<Hit> {
    // The search runs from the point of the ray nearest the box's centre,
    // s = t - tref, so that a ray from far away (1e7 object sizes) is solved
    // with f64 steps of the object's size rather than of the distance: the
    // re-basing itself rounds once, ~1e-16 of the distance (1e-9 object
    // sizes at 1e7), and F' along the ray no longer cancels terms of the
    // distance's square.
    let tref = (bounds.centre() - o).dot(d) / d.length_squared();
    let tref = if tref.is_finite() { tref } else { 0.0 };
    let hit = intersect_from(obj, bounds, o + tref * d, d, t_min - tref, t_max - tref)?;
    Some(Hit { t: tref + hit.t, ..hit })
}

/// [`intersect_within`] without re-basing.
fn intersect_from(obj: &FunctionalObject, bounds: &Aabb, o: DVec3, d: DVec3, t_min: f64, t_max: f64) -> Option<Hit> {
    let (b0, b1) = bounds.ray_range(o, d);
    let (t0, t1) = (t_min.max(b0), t_max.min(b1));
    if t0.is_nan() || t1.is_nan() || t0 > t1 {
        return None;
    }
    // Only perturbations that are positive somewhere on the segment matter.
    let relevant: Vec<usize> = (0..obj.perturbations.len())
        .filter(|&i| positive_somewhere(obj.perturbations[i].quadric.along_ray(o, d), t0, t1))
        .collect();
    let mut cuts: Vec<f64> = relevant
        .iter()
        .flat_map(|&i| poly::quadratic_roots(obj.perturbations[i].quadric.along_ray(o, d)))
        .filter(|&t| t > t0 && t < t1)
        .collect();
    cuts.push(t1);
    cuts.sort_by(f64::total_cmp);
    let mut a = t0;
    for &b in &cuts {
        if b <= a {
            continue;
        }
        if let Some(t) = first_root_on_piece(obj, &relevant, o, d, a, b) {
            let p = o + t * d;
            return Some(Hit { t, normal: obj.normal(p) });
        }
        a = b;
    }
    None
}

/// True when the quadratic q is positive somewhere in [t0, t1].
fn positive_somewhere(q: [f64; 3], t0: f64, t1: f64) -> bool {
    let at = |t: f64| q[0] + t * (q[1] + t * q[2]);
    if at(t0) > 0.0 || at(t1) > 0.0 {
        return true;
    }
    if q[2] < 0.0 {
        let v = -q[1] / (2.0 * q[2]);
        return v > t0 && v < t1 && at(v) > 0.0;
    }
    false
}

/// The first root of F' on [a, b], a piece on which no Q_i changes sign.
fn first_root_on_piece(obj: &FunctionalObject, relevant: &[usize], o: DVec3, d: DVec3, a: f64, b: f64) -> Option<f64> {
    // Expand around the piece's middle for conditioning: s = t - m.
    let m = 0.5 * (a + b);
    let pm = o + m * d;
    let mut c = [0.0; poly::MAX_DEGREE + 1];
    c[..3].copy_from_slice(&obj.base.along_ray(pm, d));
    for p in relevant.iter().map(|&i| &obj.perturbations[i]) {
        if p.quadric.eval(pm) > 0.0 {
            let q3 = poly::cube(p.quadric.along_ray(pm, d));
            for (ci, qi) in c.iter_mut().zip(q3) {
                *ci += p.form_factor * qi;
            }
        }
    }
    let s = poly::first_root(&c, a - m, b - m)?;
    Some(refine(obj, o, d, m + s, a, b))
}

/// Polishes a root by bisection on F' itself (not its expanded polynomial)
/// inside a bracket around `t`, when one can be found.
fn refine(obj: &FunctionalObject, o: DVec3, d: DVec3, t: f64, a: f64, b: f64) -> f64 {
    let f = |t: f64| obj.eval(o + t * d);
    let h = 1e-9 * (b - a).max(1e-300);
    let (mut lo, mut hi) = ((t - h).max(a), (t + h).min(b));
    let (flo, fhi) = (f(lo), f(hi));
    if flo == 0.0 || (flo < 0.0) == (fhi < 0.0) {
        return t;
    }
    let rising = flo < 0.0;
    for _ in 0..80 {
        let mid = 0.5 * (lo + hi);
        if mid <= lo || mid >= hi {
            break;
        }
        if (f(mid) < 0.0) == rising {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::model::geometry::{Perturbation, Quadric};

    #[test]
    fn unit_sphere_hit_from_outside() {
        let s =
            FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE), perturbations: vec![], clip: None };
        let h = intersect(&s, DVec3::new(0.0, 0.0, -5.0), DVec3::Z, 0.0, f64::INFINITY).unwrap();
        assert!((h.t - 4.0).abs() < 1e-12);
        assert!((h.normal - DVec3::NEG_Z).length() < 1e-12);
    }

    /// The reference must agree with brute-force dense sampling of F'.
    #[test]
    fn agrees_with_dense_sampling_on_a_bumpy_sphere() {
        let mut o =
            FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE), perturbations: vec![], clip: None };
        for i in 0..30 {
            let a = i as f64 * 2.4;
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 30.0;
            let r = (1.0 - z * z).sqrt();
            let c = DVec3::new(r * a.cos(), z, r * a.sin());
            let f = if i % 3 == 0 { -1.5 } else { 1.5 };
            o.perturbations.push(Perturbation { quadric: Quadric::ellipsoid(c, DVec3::splat(0.4)), form_factor: f });
        }
        let mut checked = 0;
        for i in 0..400 {
            let u = (i as f64 * 0.618034) % 1.0 - 0.5;
            let v = (i as f64 * 0.754878) % 1.0 - 0.5;
            let origin = DVec3::new(0.3, -0.2, -4.0);
            let d = (DVec3::new(u * 2.4, v * 2.4, 0.0) - origin).normalize();
            let n = 200_000;
            let dt = 8.0 / n as f64;
            let mut brute = None;
            let mut prev = o.eval(origin);
            for k in 1..=n {
                let v = o.eval(origin + (k as f64 * dt) * d);
                if (v >= 0.0) != (prev >= 0.0) {
                    brute = Some(k as f64 * dt);
                    break;
                }
                prev = v;
            }
            let exact = intersect(&o, origin, d, 0.0, 8.0).map(|h| h.t);
            match (brute, exact) {
                (Some(b), Some(e)) => {
                    assert!((b - e).abs() <= dt, "ray {i}: brute {b} exact {e}");
                    checked += 1;
                }
                (None, None) => {}
                other => panic!("ray {i}: disagreement {other:?}"),
            }
        }
        assert!(checked > 100);
    }
}
