//! A functional object: F'(p) = F(p) + Σ f_i max(Q_i(p), 0)³ (`NOTES.md` eq. 1–2),
//! with its inside where F' >= 0, and an optional clip box that bounds
//! unbounded surfaces.

use glam::{DMat3, DVec3};
use thiserror::Error;

use super::{Aabb, Quadric};

/// One cubic perturbation f · max(Q, 0)³.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Perturbation {
    /// The perturbing quadric Q; the perturbation acts where Q >= 0.
    pub quadric: Quadric,
    /// Form factor f: positive adds material (a bump), negative removes it.
    pub form_factor: f64,
}

impl Perturbation {
    /// The value f · max(Q(p), 0)³.
    pub fn eval(&self, p: DVec3) -> f64 {
        let q = self.quadric.eval(p).max(0.0);
        self.form_factor * q * q * q
    }

    /// Its gradient 3 f Q² ∇Q (zero where Q <= 0).
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        let q = self.quadric.eval(p);
        if q > 0.0 {
            3.0 * self.form_factor * q * q * self.quadric.gradient(p)
        } else {
            DVec3::ZERO
        }
    }

    /// Its Hessian 3 f Q (2 ∇Q ∇Qᵀ + Q H_Q) (zero where Q <= 0).
    pub fn hessian(&self, p: DVec3) -> DMat3 {
        let q = self.quadric.eval(p);
        if q > 0.0 {
            let g = self.quadric.gradient(p);
            let outer = DMat3::from_cols(g * g.x, g * g.y, g * g.z);
            (outer * 2.0 + self.quadric.hessian() * q) * (3.0 * self.form_factor * q)
        } else {
            DMat3::ZERO
        }
    }
}

/// A base quadric with cubic perturbations, in its own (object) frame.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct FunctionalObject {
    /// The base quadric F.
    pub base: Quadric,
    /// The perturbations, each acting inside its own quadric's support.
    pub perturbations: Vec<Perturbation>,
    /// The surface exists only inside this box, when given. Required when the
    /// surface would otherwise be unbounded.
    pub clip: Option<Aabb>,
}

/// Why an object cannot be rendered.
#[derive(Debug, Error, PartialEq, serde::Serialize)]
pub enum GeometryError {
    /// The surface reaches infinity and no clip box bounds it.
    #[error("the surface is unbounded ({0}); give it a clip box")]
    Unbounded(&'static str),
    /// The surface has no point (inside the clip box).
    #[error("the surface is empty{0}")]
    Empty(&'static str),
    /// A quadric is constant, so it has no surface.
    #[error("the {0} quadric is degenerate (its quadratic and linear parts are zero)")]
    Degenerate(&'static str),
    /// A coefficient is NaN or infinite.
    #[error("the {0} quadric has a non-finite coefficient")]
    NonFinite(&'static str),
}

/// How an object's box is split into cells for the acceleration structure.
#[derive(Clone, Copy, Debug, serde::Serialize)]
pub struct CellParams {
    /// A cell with at most this many perturbations is not split further.
    pub max_perturbations: usize,
    /// Split depth limit (binary splits).
    pub max_depth: u32,
    /// A cell's box is shrunk to the sub-boxes, down to this many halvings,
    /// that may hold surface.
    pub tighten_depth: u32,
    /// Cells are grown by this fraction of the object's box diagonal so that
    /// f32 slab tests on the GPU leave no gap between neighbours.
    pub padding: f64,
}

impl CellParams {
    /// The padding in object units for an object whose box is `bounds`.
    pub fn pad(&self, bounds: &Aabb) -> f64 {
        self.padding * bounds.size().length()
    }
}

impl Default for CellParams {
    fn default() -> Self {
        Self { max_perturbations: 8, max_depth: 18, tighten_depth: 6, padding: 1e-5 }
    }
}

/// A box of an object's surface and the perturbations that can be non-zero in it.
#[derive(Clone, Debug, PartialEq, serde::Serialize)]
pub struct Cell {
    /// The box (already padded).
    pub bounds: Aabb,
    /// Indices into the object's perturbations.
    pub perturbations: Vec<u32>,
}

impl FunctionalObject {
    /// F'(p).
    pub fn eval(&self, p: DVec3) -> f64 {
        self.base.eval(p) + self.perturbations.iter().map(|t| t.eval(p)).sum::<f64>()
    }

    /// ∇F'(p) = ∇F + Σ 3 f_i Q_i² ∇Q_i over the perturbations with Q_i > 0.
    pub fn gradient(&self, p: DVec3) -> DVec3 {
        self.perturbations.iter().fold(self.base.gradient(p), |g, t| g + t.gradient(p))
    }

    /// Hessian of F' at `p`: H_F + Σ 3 f_i Q_i (2 ∇Q_i ∇Q_iᵀ + Q_i H_Qi) over
    /// the perturbations with Q_i > 0 (the second derivative of f q³).
    pub fn hessian(&self, p: DVec3) -> DMat3 {
        self.perturbations.iter().fold(self.base.hessian(), |h, t| h + t.hessian(p))
    }

    /// Mean and Gaussian curvature of the surface F' = 0 at `p`, for the
    /// outward normal n = -∇F'/|∇F'| (positive on a convex bump). The shape
    /// operator is dn/dp on the tangent plane: S = -P H P / |∇F'| with P the
    /// projection onto the tangent plane (a sphere of radius r has S = I/r).
    pub fn curvatures(&self, p: DVec3) -> (f64, f64) {
        let g = self.gradient(p);
        let len = g.length();
        if len == 0.0 {
            return (0.0, 0.0);
        }
        let n = g / len;
        let (t1, t2) = n.any_orthonormal_pair();
        let h = self.hessian(p);
        let s = |a: DVec3, b: DVec3| -a.dot(h * b) / len;
        let (s11, s12, s22) = (s(t1, t1), s(t1, t2), s(t2, t2));
        (0.5 * (s11 + s22), s11 * s22 - s12 * s12)
    }

    /// The outward unit normal at `p` (the inside is F' >= 0).
    pub fn normal(&self, p: DVec3) -> DVec3 {
        (-self.gradient(p)).normalize_or_zero()
    }

    /// Checks that every quadric is finite and non-degenerate.
    pub fn validate(&self) -> Result<(), GeometryError> {
        if !self.base.is_finite() {
            return Err(GeometryError::NonFinite("base"));
        }
        if self.base.is_degenerate() {
            return Err(GeometryError::Degenerate("base"));
        }
        for p in &self.perturbations {
            if !p.quadric.is_finite() || !p.form_factor.is_finite() {
                return Err(GeometryError::NonFinite("perturbation"));
            }
            if p.quadric.is_degenerate() {
                return Err(GeometryError::Degenerate("perturbation"));
            }
        }
        Ok(())
    }

    /// A conservative, tight box around the surface.
    ///
    /// Outside the supports of the positive perturbations F' <= F, so the
    /// surface lies in {F >= 0} ∪ (positive supports), clipped by the clip box.
    pub fn bounds(&self) -> Result<Aabb, GeometryError> {
        self.validate()?;
        let mut unbounded = None;
        let mut acc: Option<Aabb> = None;
        let mut add = |b: Option<Option<Aabb>>, what: &'static str| match b {
            None => unbounded = Some(what),
            Some(Some(b)) => acc = Some(acc.map_or(b, |a| a.union(&b))),
            Some(None) => {}
        };
        add(self.base.support_bounds(), "base quadric");
        for p in self.perturbations.iter().filter(|p| p.form_factor > 0.0) {
            add(p.quadric.support_bounds(), "a positive perturbation with an unbounded support");
        }
        let b = match (unbounded, self.clip, acc) {
            (Some(what), None, _) => return Err(GeometryError::Unbounded(what)),
            (Some(_), Some(clip), _) => clip,
            (None, Some(clip), Some(a)) => a.intersection(&clip),
            (None, None, Some(a)) => a,
            (None, _, None) => return Err(GeometryError::Empty("")),
        };
        if b.is_empty() {
            return Err(GeometryError::Empty(" inside its clip box"));
        }
        Ok(b)
    }

    /// Splits the object's box into cells that may hold surface, each listing
    /// the perturbations that can be non-zero in it, so that a ray pays only
    /// for the perturbations near where it passes.
    ///
    /// A box is dropped when interval arithmetic proves F' has no zero in it;
    /// it is split in half along its longest axis while it holds more than
    /// `max_perturbations` perturbations.
    pub fn cells(&self, params: &CellParams) -> Result<Vec<Cell>, GeometryError> {
        let bounds = self.bounds()?;
        let pad = params.pad(&bounds);
        let all: Vec<u32> = (0..self.perturbations.len() as u32).collect();
        let mut out = Vec::new();
        self.split(bounds, &all, 0, pad, params, &mut out);
        Ok(out)
    }

    /// The perturbations that can be non-zero in `bx` (from `candidates`), or
    /// `None` when interval bounds prove F' has no zero in `bx`.
    fn active_in(&self, bx: &Aabb, candidates: &[u32]) -> Option<Vec<u32>> {
        let mut active = Vec::new();
        let (mut lo, mut hi) = self.base.range_over(bx);
        for &i in candidates {
            let p = &self.perturbations[i as usize];
            let (qlo, qhi) = p.quadric.range_over(bx);
            if qhi <= 0.0 {
                continue;
            }
            active.push(i);
            let (rlo, rhi) = (qlo.max(0.0).powi(3), qhi.powi(3));
            if p.form_factor >= 0.0 {
                lo += p.form_factor * rlo;
                hi += p.form_factor * rhi;
            } else {
                lo += p.form_factor * rhi;
                hi += p.form_factor * rlo;
            }
        }
        (lo <= 0.0 && hi >= 0.0).then_some(active)
    }

    fn split(&self, bx: Aabb, candidates: &[u32], depth: u32, pad: f64, params: &CellParams, out: &mut Vec<Cell>) {
        // The list is taken over the box grown by twice the padding, so that
        // it holds a padding's width beyond the cell (the padded box): a
        // GPU segment that overshoots its cell by f32 rounding (~1e-7 of
        // the object's size in the cell-local search) never meets a
        // perturbation the list lacks.
        let Some(active) = self.active_in(&bx.padded(2.0 * pad), candidates) else { return };
        if active.len() <= params.max_perturbations || depth >= params.max_depth {
            // The list holds for the whole grown box, so also for any box in it.
            if let Some(tight) = self.tighten(bx, &active, params.tighten_depth) {
                out.push(Cell { bounds: tight.padded(pad), perturbations: active });
            }
            return;
        }
        let (left, right) = halves(&bx);
        self.split(left, &active, depth + 1, pad, params, out);
        self.split(right, &active, depth + 1, pad, params, out);
    }

    /// The union of the sub-boxes of `bx`, down to `depth` halvings, that may
    /// hold surface: a tighter box for a cell, so that fewer rays visit it.
    fn tighten(&self, bx: Aabb, active: &[u32], depth: u32) -> Option<Aabb> {
        self.active_in(&bx, active)?;
        if depth == 0 {
            return Some(bx);
        }
        let (left, right) = halves(&bx);
        match (self.tighten(left, active, depth - 1), self.tighten(right, active, depth - 1)) {
            (Some(a), Some(b)) => Some(a.union(&b)),
            (a, b) => a.or(b),
        }
    }
}

/// The two halves of a box, split across its longest axis.
fn halves(bx: &Aabb) -> (Aabb, Aabb) {
    let size = bx.size();
    let axis = if size.x >= size.y && size.x >= size.z {
        0
    } else if size.y >= size.z {
        1
    } else {
        2
    };
    let mid = bx.centre()[axis];
    let (mut left, mut right) = (*bx, *bx);
    left.max[axis] = mid;
    right.min[axis] = mid;
    (left, right)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sphere() -> FunctionalObject {
        FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE), perturbations: vec![], clip: None }
    }

    #[test]
    fn hessian_matches_finite_differences_of_the_gradient() {
        let mut o = sphere();
        for (i, c) in
            [DVec3::new(1.0, 0.0, 0.0), DVec3::new(0.0, 0.8, 0.6), DVec3::new(0.6, 0.0, 0.8)].iter().enumerate()
        {
            let q = Quadric::ellipsoid(*c, DVec3::new(0.5, 0.4, 0.3));
            o.perturbations.push(Perturbation { quadric: q, form_factor: if i == 1 { -0.7 } else { 1.3 } });
        }
        let e = 1e-5;
        let mut checked = 0;
        for p in [DVec3::new(0.9, 0.1, 0.05), DVec3::new(0.1, 0.7, 0.5), DVec3::new(0.5, -0.05, 0.7)] {
            assert!(o.perturbations.iter().any(|t| t.quadric.eval(p) > 0.0));
            let h = o.hessian(p);
            for (k, axis) in [DVec3::X, DVec3::Y, DVec3::Z].into_iter().enumerate() {
                let column = (o.gradient(p + e * axis) - o.gradient(p - e * axis)) / (2.0 * e);
                let err = (column - h.col(k)).abs().max_element();
                assert!(err < 1e-6 * h.col(k).abs().max_element().max(1.0), "column {k} at {p}: {err}");
                checked += 1;
            }
        }
        assert_eq!(checked, 9);
    }

    #[test]
    fn curvatures_of_a_sphere_and_an_ellipsoid_tip_are_the_closed_forms() {
        let s = FunctionalObject {
            base: Quadric::ellipsoid(DVec3::ZERO, DVec3::splat(2.0)),
            perturbations: vec![],
            clip: None,
        };
        let (mean, gauss) = s.curvatures(DVec3::new(0.0, 2.0, 0.0));
        assert!((mean - 0.5).abs() < 1e-12 && (gauss - 0.25).abs() < 1e-12, "{mean} {gauss}");
        // Ellipsoid of radii (a, b, c) at (a, 0, 0): principal curvatures a / b², a / c².
        let (a, b, c) = (3.0, 2.0, 0.5);
        let e = FunctionalObject {
            base: Quadric::ellipsoid(DVec3::ZERO, DVec3::new(a, b, c)),
            perturbations: vec![],
            clip: None,
        };
        let (mean, gauss) = e.curvatures(DVec3::new(a, 0.0, 0.0));
        let (k1, k2) = (a / (b * b), a / (c * c));
        assert!((mean - 0.5 * (k1 + k2)).abs() < 1e-9 * k2, "{mean}");
        assert!((gauss - k1 * k2).abs() < 1e-9 * k1 * k2, "{gauss}");
        // Seen from inside (the inverted quadric), the curvature changes sign.
        let inverted = FunctionalObject { base: Quadric::from_coefficients(e.base.coefficients().map(|v| -v)), ..e };
        let (mean_in, gauss_in) = inverted.curvatures(DVec3::new(a, 0.0, 0.0));
        assert!((mean_in + mean).abs() < 1e-9 * k2 && (gauss_in - gauss).abs() < 1e-9 * k1 * k2);
    }

    #[test]
    fn sphere_bounds_are_tight() {
        let b = sphere().bounds().unwrap();
        assert!((b.min + DVec3::ONE).abs().max_element() < 1e-9);
        assert!((b.max - DVec3::ONE).abs().max_element() < 1e-9);
    }

    #[test]
    fn a_bump_grows_the_bounds_and_a_dent_does_not() {
        let mut o = sphere();
        let bump = Quadric::ellipsoid(DVec3::new(1.0, 0.0, 0.0), DVec3::splat(0.5));
        o.perturbations.push(Perturbation { quadric: bump, form_factor: 1.0 });
        assert!((o.bounds().unwrap().max.x - 1.5).abs() < 1e-9);
        o.perturbations[0].form_factor = -1.0;
        assert!((o.bounds().unwrap().max.x - 1.0).abs() < 1e-9);
    }

    #[test]
    fn unbounded_needs_a_clip_box() {
        let plane = FunctionalObject {
            base: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
            perturbations: vec![],
            clip: None,
        };
        assert!(matches!(plane.bounds(), Err(GeometryError::Unbounded(_))));
        let clipped = FunctionalObject { clip: Some(Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0))), ..plane };
        assert!(clipped.bounds().is_ok());
    }

    #[test]
    fn cells_cover_every_surface_point_with_its_perturbations() {
        let mut o = sphere();
        for i in 0..200 {
            let a = i as f64 * 2.399963;
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / 200.0;
            let r = (1.0 - z * z).sqrt();
            let c = DVec3::new(r * a.cos(), z, r * a.sin());
            let f = if i % 2 == 0 { 2.0 } else { -2.0 };
            o.perturbations.push(Perturbation { quadric: Quadric::ellipsoid(c, DVec3::splat(0.15)), form_factor: f });
        }
        let cells = o.cells(&CellParams::default()).unwrap();
        assert!(cells.len() > 8);
        assert!(cells.iter().all(|c| c.perturbations.len() <= CellParams::default().max_perturbations));
        // Points on the perturbed surface (found along radial rays) must lie
        // in some cell, and that cell must list every perturbation active there.
        for i in 0..2000 {
            let u = (i as f64 * 0.618034) % 1.0;
            let v = (i as f64 * 0.754878) % 1.0;
            let z = 1.0 - 2.0 * u;
            let r = (1.0 - z * z).sqrt();
            let dir = DVec3::new(r * (std::f64::consts::TAU * v).cos(), z, r * (std::f64::consts::TAU * v).sin());
            let (mut a, mut b) = (0.0, 2.0);
            for _ in 0..60 {
                let m = 0.5 * (a + b);
                if o.eval(dir * m) >= 0.0 {
                    a = m
                } else {
                    b = m
                }
            }
            let p = dir * a;
            let active: Vec<u32> = (0..200).filter(|&k| o.perturbations[k as usize].quadric.eval(p) > 0.0).collect();
            let cell = cells.iter().find(|c| c.bounds.contains(p)).expect("surface point outside every cell");
            for k in active {
                assert!(cell.perturbations.contains(&k));
            }
        }
    }

    /// A cell's list holds a padding's width beyond its box (the margin the
    /// GPU's f32 segments may overshoot it by): over every cell's box grown
    /// by the padding, each perturbation off the list is proved non-positive
    /// by interval bounds. The property holds for any padding; a large one
    /// (2 % of the diagonal) makes the margin wide enough that lists taken
    /// over the padded box only (as before issue 20) fail it.
    #[test]
    fn cell_lists_hold_a_padding_beyond_their_boxes() {
        let mut o = sphere();
        o.perturbations = crate::model::geometry::scatter::spread_bumps(60, DVec3::ONE, 0.3, 0.5, true);
        let params = CellParams { padding: 0.02, ..CellParams::default() };
        let pad = params.pad(&o.bounds().unwrap());
        let cells = o.cells(&params).unwrap();
        let mut checked = 0;
        for cell in &cells {
            let grown = cell.bounds.padded(pad);
            for (k, pert) in o.perturbations.iter().enumerate() {
                if !cell.perturbations.contains(&(k as u32)) {
                    checked += 1;
                    let (_, hi) = pert.quadric.range_over(&grown);
                    assert!(
                        hi <= 0.0,
                        "perturbation {k} may be active within a padding of a cell that does not list it"
                    );
                }
            }
        }
        assert!(checked > 1000, "only {checked} unlisted perturbations checked");
    }
}
