//! Polynomials in one variable (coefficients lowest degree first) and an
//! exact first-root search by root isolation.
//!
//! The isolation follows C. Yuksel, "High-Performance Polynomial Root Finding
//! for Graphics" (HPG 2022): the roots of p' split [lo, hi] into intervals on
//! which p is monotonic, so each holds at most one root, found by a
//! Newton iteration safeguarded by bisection. The derivatives' roots are
//! found the same way, from the highest derivative down. The GPU
//! (`glsl/intersection/roots.glsl`) isolates roots by Bernstein subdivision instead, so
//! the reference and the GPU check each other with different methods.

/// Highest supported degree: a cubed quadric.
pub const MAX_DEGREE: usize = 6;

/// A polynomial of degree at most [`MAX_DEGREE`].
pub type Poly = [f64; MAX_DEGREE + 1];

/// Evaluates the `k`-th derivative of `c` at `x` (Horner's scheme).
pub fn eval_derivative(c: &Poly, k: usize, x: f64) -> f64 {
    let mut v = 0.0;
    for j in (k..=MAX_DEGREE).rev() {
        v = v * x + c[j] * falling(j, k);
    }
    v
}

/// j! / (j - k)!
fn falling(j: usize, k: usize) -> f64 {
    ((j - k + 1)..=j).map(|v| v as f64).product()
}

/// The degree of `c`: the index of its last non-zero coefficient.
pub fn degree(c: &Poly) -> usize {
    (0..=MAX_DEGREE).rev().find(|&j| c[j] != 0.0).unwrap_or(0)
}

/// `q³` for a quadratic `q`.
pub fn cube(q: [f64; 3]) -> Poly {
    let sq = [q[0] * q[0], 2.0 * q[0] * q[1], q[1] * q[1] + 2.0 * q[0] * q[2], 2.0 * q[1] * q[2], q[2] * q[2]];
    let mut out = [0.0; MAX_DEGREE + 1];
    for (i, s) in sq.iter().enumerate() {
        for (j, v) in q.iter().enumerate() {
            out[i + j] += s * v;
        }
    }
    out
}

/// All roots of the `k`-th derivative of `c` in [lo, hi], sorted, given the
/// sorted roots `splits` of the (k+1)-th derivative in that interval.
fn roots_between(c: &Poly, k: usize, lo: f64, hi: f64, splits: &[f64], out: &mut Vec<f64>) {
    out.clear();
    let mut x0 = lo;
    let mut v0 = eval_derivative(c, k, x0);
    if v0 == 0.0 {
        out.push(x0);
    }
    for &x1 in splits.iter().chain(std::iter::once(&hi)) {
        let v1 = eval_derivative(c, k, x1);
        if v1 == 0.0 {
            if out.last() != Some(&x1) {
                out.push(x1);
            }
        } else if v0 != 0.0 && (v0 < 0.0) != (v1 < 0.0) {
            out.push(solve_bracket(c, k, x0, x1, v0));
        }
        x0 = x1;
        v0 = v1;
    }
}

/// The root of the `k`-th derivative of `c` in [x0, x1], where it is
/// monotonic and changes sign; `v0` is its value at x0.
fn solve_bracket(c: &Poly, k: usize, mut x0: f64, mut x1: f64, v0: f64) -> f64 {
    let rising = v0 < 0.0;
    let mut x = 0.5 * (x0 + x1);
    for _ in 0..100 {
        let v = eval_derivative(c, k, x);
        if v == 0.0 {
            return x;
        }
        if (v < 0.0) == rising {
            x0 = x;
        } else {
            x1 = x;
        }
        let slope = eval_derivative(c, k + 1, x);
        let newton = x - v / slope;
        x = if slope != 0.0 && newton > x0 && newton < x1 { newton } else { 0.5 * (x0 + x1) };
        let width = x1 - x0;
        if width <= 4.0 * f64::EPSILON * x.abs().max(x1.abs()).max(f64::MIN_POSITIVE) {
            break;
        }
    }
    x
}

/// All the real roots of `c` in [lo, hi], sorted.
pub fn all_roots(c: &Poly, lo: f64, hi: f64) -> Vec<f64> {
    let n = degree(c);
    let mut splits = Vec::new();
    let mut next = Vec::new();
    for k in (0..n).rev() {
        roots_between(c, k, lo, hi, &splits, &mut next);
        std::mem::swap(&mut splits, &mut next);
    }
    if n == 0 {
        return if c[0] == 0.0 { vec![lo] } else { vec![] };
    }
    splits
}

/// The smallest root of `c` in [lo, hi] at which it is zero or changes sign.
pub fn first_root(c: &Poly, lo: f64, hi: f64) -> Option<f64> {
    all_roots(c, lo, hi).first().copied()
}

/// Real roots of the quadratic `q` (lowest degree first), sorted; computed
/// without cancellation.
pub fn quadratic_roots(q: [f64; 3]) -> Vec<f64> {
    let [c, b, a] = q;
    if a == 0.0 {
        return if b != 0.0 { vec![-c / b] } else { vec![] };
    }
    let disc = b * b - 4.0 * a * c;
    if disc < 0.0 {
        return vec![];
    }
    let s = -0.5 * (b + b.signum() * disc.sqrt());
    let (r0, r1) = if s != 0.0 { (s / a, c / s) } else { (0.0, 0.0) };
    if r0 <= r1 {
        vec![r0, r1]
    } else {
        vec![r1, r0]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn from_roots(roots: &[f64]) -> Poly {
        let mut c = [0.0; MAX_DEGREE + 1];
        c[0] = 1.0;
        for &r in roots {
            let prev = c;
            c = [0.0; MAX_DEGREE + 1];
            for j in 0..MAX_DEGREE {
                c[j + 1] += prev[j];
                c[j] -= r * prev[j];
            }
        }
        c
    }

    #[test]
    fn finds_all_simple_roots_of_a_sextic() {
        let roots = [-2.5, -1.0, -0.1, 0.3, 1.7, 2.2];
        let found = all_roots(&from_roots(&roots), -3.0, 3.0);
        assert_eq!(found.len(), 6, "{found:?}");
        for (a, b) in found.iter().zip(roots) {
            assert!((a - b).abs() < 1e-10, "{a} vs {b}");
        }
    }

    #[test]
    fn first_root_respects_the_interval() {
        let c = from_roots(&[-1.0, 0.5, 2.0]);
        assert!((first_root(&c, 0.0, 3.0).unwrap() - 0.5).abs() < 1e-12);
        assert!((first_root(&c, 0.6, 3.0).unwrap() - 2.0).abs() < 1e-12);
        assert!(first_root(&c, 0.6, 1.9).is_none());
    }

    #[test]
    fn cube_matches_evaluation() {
        let q = [0.3, -1.2, 0.7];
        let c = cube(q);
        for x in [-2.0, -0.3, 0.0, 0.4, 1.5] {
            let v = q[0] + q[1] * x + q[2] * x * x;
            assert!((eval_derivative(&c, 0, x) - v * v * v).abs() < 1e-12);
        }
    }

    #[test]
    fn quadratic_roots_are_accurate_without_cancellation() {
        let r = quadratic_roots([1.0, -1e8, 1.0]);
        assert!((r[0] - 1e-8).abs() < 1e-20 && (r[1] - 1e8).abs() < 1e-6);
    }
}
