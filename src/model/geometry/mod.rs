//! Functionally defined objects on the CPU, in f64: the perturbed quadrics of
//! `NOTES.md` §1, their bounds, their split into cells for the acceleration
//! structure, and the reference ray intersection that the GPU is tested
//! against.

pub mod mesh;
pub mod object;
pub mod poly;
pub mod quadric;
pub mod reference;
pub mod scatter;
pub mod uv;

pub use object::{Cell, CellParams, FunctionalObject, GeometryError, Perturbation};
pub use quadric::Quadric;

use glam::DVec3;

/// An axis-aligned box.
#[derive(Clone, Copy, Debug, PartialEq, serde::Serialize)]
pub struct Aabb {
    /// Smallest corner.
    pub min: DVec3,
    /// Largest corner.
    pub max: DVec3,
}

impl Aabb {
    /// The box between two corners.
    pub fn new(min: DVec3, max: DVec3) -> Self {
        Self { min, max }
    }

    /// True when the box holds no point.
    pub fn is_empty(&self) -> bool {
        self.min.cmpgt(self.max).any()
    }

    /// The smallest box holding both.
    pub fn union(&self, o: &Aabb) -> Aabb {
        Aabb::new(self.min.min(o.min), self.max.max(o.max))
    }

    /// The common part (possibly empty).
    pub fn intersection(&self, o: &Aabb) -> Aabb {
        Aabb::new(self.min.max(o.min), self.max.min(o.max))
    }

    /// True when the boxes share a point.
    pub fn overlaps(&self, o: &Aabb) -> bool {
        !self.intersection(o).is_empty()
    }

    /// Edge lengths.
    pub fn size(&self) -> DVec3 {
        self.max - self.min
    }

    /// Centre point.
    pub fn centre(&self) -> DVec3 {
        0.5 * (self.min + self.max)
    }

    /// The box grown by `d` on every side.
    pub fn padded(&self, d: f64) -> Aabb {
        Aabb::new(self.min - DVec3::splat(d), self.max + DVec3::splat(d))
    }

    /// True when `p` is inside or on the boundary.
    pub fn contains(&self, p: DVec3) -> bool {
        p.cmpge(self.min).all() && p.cmple(self.max).all()
    }

    /// The parameter range [t0, t1] in which o + t d is inside the box
    /// (the slab method); empty when t0 > t1.
    pub fn ray_range(&self, o: DVec3, d: DVec3) -> (f64, f64) {
        let inv = DVec3::ONE / d;
        let a = (self.min - o) * inv;
        let b = (self.max - o) * inv;
        let lo = a.min(b);
        let hi = a.max(b);
        // 0 * inf gives NaN when the origin lies on a slab of a parallel ray:
        // max/min with NaN keep the other operand, which is the right answer.
        (lo.max_element(), hi.min_element())
    }

    /// Distance from `p` to the box's surface (0 on it, positive elsewhere).
    pub fn distance_to_boundary(&self, p: DVec3) -> f64 {
        if self.contains(p) {
            (p - self.min).min(self.max - p).min_element()
        } else {
            (self.min - p).max(p - self.max).max(DVec3::ZERO).length()
        }
    }
}
