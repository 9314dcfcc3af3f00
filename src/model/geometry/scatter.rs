//! Perturbations spread evenly over an ellipsoid, for scenes and benchmarks
//! that need many of them.

use glam::DVec3;

use super::{Perturbation, Quadric};

/// The golden angle in radians: successive points of a Fibonacci spiral.
const GOLDEN_ANGLE: f64 = 2.399_963_229_728_653;

/// `n` spherical bumps of radius `radius` centred on the ellipsoid of radii
/// `on` (around the origin), placed by a Fibonacci spiral so that they are
/// evenly spread. The form factor is `f`, or alternately `f` and `-f` when
/// `alternate` (bumps and dents).
pub fn spread_bumps(n: usize, on: DVec3, radius: f64, f: f64, alternate: bool) -> Vec<Perturbation> {
    (0..n)
        .map(|i| {
            let z = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
            let rho = (1.0 - z * z).max(0.0).sqrt();
            let a = i as f64 * GOLDEN_ANGLE;
            let centre = on * DVec3::new(rho * a.cos(), z, rho * a.sin());
            let sign = if alternate && i % 2 == 1 { -1.0 } else { 1.0 };
            Perturbation { quadric: Quadric::ellipsoid(centre, DVec3::splat(radius)), form_factor: sign * f }
        })
        .collect()
}
