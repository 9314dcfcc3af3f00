//! Quadrics: q(p) = pᵀ A p + b·p + c with A symmetric.
//!
//! Sign convention (the paper leaves it open, `NOTES.md` §5): a functional
//! object's *inside* is where its function is `>= 0`. A perturbation's support
//! is where its quadric is `>= 0`, so a positive form factor adds material
//! (a bump) and a negative one removes it (a dent).

use glam::{DAffine3, DMat3, DVec3};

use super::Aabb;

/// A quadric function of position, q(p) = pᵀ A p + b·p + c.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Quadric {
    /// Symmetric quadratic part.
    pub a: DMat3,
    /// Linear part.
    pub b: DVec3,
    /// Constant part.
    pub c: f64,
}

/// Coefficients of q(o + t d) = c0 + c1 t + c2 t², lowest degree first.
pub type Quadratic = [f64; 3];

impl Quadric {
    /// From the ten coefficients of
    /// `xx x² + yy y² + zz z² + xy xy + yz yz + xz xz + x x + y y + z z + k`,
    /// in that order: `[xx, yy, zz, xy, yz, xz, x, y, z, k]`.
    pub fn from_coefficients(k: [f64; 10]) -> Self {
        let a = DMat3::from_cols(
            DVec3::new(k[0], 0.5 * k[3], 0.5 * k[5]),
            DVec3::new(0.5 * k[3], k[1], 0.5 * k[4]),
            DVec3::new(0.5 * k[5], 0.5 * k[4], k[2]),
        );
        Self { a, b: DVec3::new(k[6], k[7], k[8]), c: k[9] }
    }

    /// The ten coefficients in the order of [`Quadric::from_coefficients`].
    pub fn coefficients(&self) -> [f64; 10] {
        let a = &self.a;
        [
            a.x_axis.x,
            a.y_axis.y,
            a.z_axis.z,
            2.0 * a.y_axis.x,
            2.0 * a.z_axis.y,
            2.0 * a.z_axis.x,
            self.b.x,
            self.b.y,
            self.b.z,
            self.c,
        ]
    }

    /// `1 - Σ ((p - centre)_k / radii_k)²`: positive inside an ellipsoid.
    pub fn ellipsoid(centre: DVec3, radii: DVec3) -> Self {
        let inv2 = DVec3::ONE / (radii * radii);
        let a = DMat3::from_diagonal(-inv2);
        let b = 2.0 * inv2 * centre;
        let c = 1.0 - (centre * centre * inv2).element_sum();
        Self { a, b, c }
    }

    /// Value at `p`.
    pub fn eval(&self, p: DVec3) -> f64 {
        p.dot(self.a * p) + self.b.dot(p) + self.c
    }

    /// Gradient at `p`: 2 A p + b.
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        2.0 * (self.a * p) + self.b
    }

    /// Hessian (constant): 2 A.
    pub fn hessian(&self) -> DMat3 {
        2.0 * self.a
    }

    /// The restriction to the ray o + t d, as a quadratic in t.
    pub fn along_ray(&self, o: DVec3, d: DVec3) -> Quadratic {
        let ad = self.a * d;
        [self.eval(o), 2.0 * o.dot(ad) + self.b.dot(d), d.dot(ad)]
    }

    /// This quadric expressed in the coordinates `p' = m p`: q'(p') = q(m⁻¹ p').
    pub fn transformed(&self, m: &DAffine3) -> Self {
        let inv = m.inverse();
        let l = inv.matrix3;
        let t = inv.translation;
        let a = l.transpose() * self.a * l;
        let b = l.transpose() * (2.0 * (self.a * t) + self.b);
        let c = self.eval(t);
        Self { a, b, c }
    }

    /// True when every coefficient is finite.
    pub fn is_finite(&self) -> bool {
        self.coefficients().iter().all(|v| v.is_finite())
    }

    /// True when the function is constant (no quadratic and no linear part):
    /// its zero set is empty or everything.
    pub fn is_degenerate(&self) -> bool {
        let k = self.coefficients();
        let scale = k.iter().fold(0.0f64, |m, v| m.max(v.abs()));
        scale == 0.0 || k[..9].iter().all(|v| v.abs() <= 1e-12 * scale)
    }

    /// When A is negative definite, `{q >= 0}` is the ellipsoid
    /// (p - m)ᵀ(-A)(p - m) <= q(m) around m = -A⁻¹b/2: `Some(Some(..))`, or
    /// `Some(None)` when q(m) < 0 (the set is empty). `None` when A is not
    /// negative definite (the set is unbounded or degenerate).
    fn ellipsoid_support(&self) -> Option<Option<EllipsoidSupport>> {
        let neg = -self.a;
        if !is_positive_definite(&neg) {
            return None;
        }
        let inverse = neg.inverse();
        let centre = 0.5 * (inverse * self.b);
        let top = self.eval(centre);
        Some((top >= 0.0).then_some(EllipsoidSupport { inverse, centre, top }))
    }

    /// Bounding box of `{q >= 0}` when that set is bounded: `Some(None)` when
    /// it is empty, `Some(Some(box))` when bounded, `None` when unbounded.
    ///
    /// `{q >= 0}` is bounded only when A is negative definite; then it is the
    /// ellipsoid (p - m)ᵀ(-A)(p - m) <= q(m) around m = -A⁻¹b/2, whose box
    /// half-extents are sqrt(q(m) · ((-A)⁻¹)_kk).
    pub fn support_bounds(&self) -> Option<Option<Aabb>> {
        let Some(EllipsoidSupport { inverse: inv, centre, top }) = self.ellipsoid_support()? else { return Some(None) };
        let half = DVec3::new(
            (top * inv.x_axis.x).max(0.0).sqrt(),
            (top * inv.y_axis.y).max(0.0).sqrt(),
            (top * inv.z_axis.z).max(0.0).sqrt(),
        );
        // Widen by a few ulps so that the box is conservative after rounding.
        let pad = (half + centre.abs()) * 1e-12;
        Some(Some(Aabb::new(centre - half - pad, centre + half + pad)))
    }

    /// A sphere (centre, radius) holding `{q >= 0}` when that set is bounded
    /// and not empty. The radius is sqrt(q(m) · λ_max((-A)⁻¹)), with the
    /// eigenvalue found by power iteration and rounded up.
    pub fn support_sphere(&self) -> Option<(DVec3, f64)> {
        let EllipsoidSupport { inverse: inv, centre, top } = self.ellipsoid_support()??;
        let mut v = DVec3::new(1.0, 0.7, 0.3);
        let mut lambda = 0.0;
        for _ in 0..100 {
            let w = inv * v;
            let l = w.length();
            if l == 0.0 {
                break;
            }
            lambda = l / v.length();
            v = w / l;
        }
        // Power iteration approaches λ_max from below: bound it by the largest
        // diagonal-dominance (Gershgorin) estimate when that is smaller.
        let gershgorin = (0..3).map(|i| (0..3).map(|j| inv.col(j)[i].abs()).sum::<f64>()).fold(0.0f64, f64::max);
        let lambda = (lambda * (1.0 + 1e-6)).min(gershgorin).max(lambda);
        let radius = (top * lambda).sqrt() * (1.0 + 1e-6) + 1e-12 * centre.length();
        Some((centre, radius))
    }

    /// A conservative range of values over `bx`.
    ///
    /// Centred form around the box's middle m, with g = ∇q(m) and |h_i| <= e_i:
    /// q(m + h) = q(m) + Σ_i (g_i h_i + A_ii h_i²) + Σ_{i<j} 2 A_ij h_i h_j.
    /// Each one-axis term is bounded exactly; each cross term by
    /// 2 |A_ij| e_i e_j. The range is exact for quadrics without cross terms
    /// (ellipsoids, spheres, axis-aligned cylinders, planes), and far tighter
    /// than interval arithmetic on the expanded form for boxes away from the
    /// origin.
    pub fn range_over(&self, bx: &Aabb) -> (f64, f64) {
        let m = bx.centre();
        let e = 0.5 * bx.size();
        let g = self.gradient(m);
        let a = &self.a;
        let diag = [a.x_axis.x, a.y_axis.y, a.z_axis.z];
        let mut lo = self.eval(m);
        let mut hi = lo;
        for i in 0..3 {
            let (l, h) = quadratic_range(g[i], diag[i], e[i]);
            lo += l;
            hi += h;
        }
        let cross = 2.0 * (a.y_axis.x.abs() * e.x * e.y + a.z_axis.y.abs() * e.y * e.z + a.z_axis.x.abs() * e.x * e.z);
        (lo - cross, hi + cross)
    }
}

/// Exact range of g h + a h² for h in [-e, e].
fn quadratic_range(g: f64, a: f64, e: f64) -> (f64, f64) {
    let v = |h: f64| h * (g + a * h);
    let (v0, v1) = (v(-e), v(e));
    let (mut lo, mut hi) = (v0.min(v1), v0.max(v1));
    if a != 0.0 {
        let h = -g / (2.0 * a);
        if h.abs() < e {
            lo = lo.min(v(h));
            hi = hi.max(v(h));
        }
    }
    (lo, hi)
}

/// The ellipsoid {q >= 0} of a quadric with negative definite A.
struct EllipsoidSupport {
    /// (-A)⁻¹.
    inverse: DMat3,
    /// Its centre m = -A⁻¹b/2.
    centre: DVec3,
    /// q(m) >= 0.
    top: f64,
}

fn is_positive_definite(m: &DMat3) -> bool {
    // Sylvester's criterion on the leading principal minors.
    let m1 = m.x_axis.x;
    let m2 = m.x_axis.x * m.y_axis.y - m.y_axis.x * m.x_axis.y;
    m1 > 0.0 && m2 > 0.0 && m.determinant() > 0.0
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn coefficients_round_trip() {
        let k = [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0];
        assert_eq!(Quadric::from_coefficients(k).coefficients(), k);
    }

    #[test]
    fn transform_moves_the_zero_set() {
        let q = Quadric::ellipsoid(DVec3::ZERO, DVec3::new(1.0, 2.0, 3.0));
        let m = DAffine3::from_scale_rotation_translation(
            DVec3::new(2.0, 1.0, 0.5),
            glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.3, -0.7, 1.1),
            DVec3::new(5.0, -3.0, 2.0),
        );
        let t = q.transformed(&m);
        for p in [DVec3::new(0.2, 0.4, -1.0), DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 2.0, 0.0)] {
            assert!((t.eval(m.transform_point3(p)) - q.eval(p)).abs() < 1e-12);
        }
    }

    #[test]
    fn ellipsoid_support_box_is_exact() {
        let q = Quadric::ellipsoid(DVec3::new(1.0, 2.0, 3.0), DVec3::new(0.5, 1.5, 2.5));
        let b = q.support_bounds().unwrap().unwrap();
        assert!((b.min - DVec3::new(0.5, 0.5, 0.5)).abs().max_element() < 1e-9);
        assert!((b.max - DVec3::new(1.5, 3.5, 5.5)).abs().max_element() < 1e-9);
    }

    #[test]
    fn support_sphere_bounds_a_rotated_ellipsoid() {
        let e = Quadric::ellipsoid(DVec3::new(0.5, -1.0, 2.0), DVec3::new(0.3, 0.8, 0.5));
        let m = DAffine3::from_rotation_translation(
            glam::DQuat::from_euler(glam::EulerRot::XYZ, 0.4, 1.0, -0.3),
            DVec3::new(1.0, 2.0, 3.0),
        );
        let q = e.transformed(&m);
        let (c, r) = q.support_sphere().unwrap();
        assert!((r - 0.8).abs() < 1e-5, "radius {r}");
        assert!((c - m.transform_point3(DVec3::new(0.5, -1.0, 2.0))).length() < 1e-9);
        assert!(Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
            .support_sphere()
            .is_none());
    }

    #[test]
    fn interval_range_contains_samples() {
        let q = Quadric::from_coefficients([1.0, -2.0, 0.5, 0.3, -0.7, 1.1, 0.2, -0.4, 0.9, -0.3]);
        let bx = Aabb::new(DVec3::new(-1.0, 0.5, -2.0), DVec3::new(0.5, 2.0, 1.0));
        let (lo, hi) = q.range_over(&bx);
        for i in 0..1000 {
            let f = |k: u32| ((i * 7919 + k * 104729) % 1000) as f64 / 999.0;
            let p = bx.min + (bx.max - bx.min) * DVec3::new(f(1), f(2), f(3));
            let v = q.eval(p);
            assert!(v >= lo - 1e-12 && v <= hi + 1e-12);
        }
    }
}
