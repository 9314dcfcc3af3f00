//! Pearson's chi-square test of a direction sampler against its claimed
//! solid-angle density, in the manner of Mitsuba's `chi2` test suite: draw
//! many samples, histogram them over a grid of equal-area cells on the
//! sphere, integrate the density over every cell numerically for the
//! expected counts, pool the cells with small expected counts, and compute
//! the p-value of the chi-square statistic.
//!
//! Also here, because the tests need them: a small PCG32 generator,
//! adaptive Simpson quadrature in one and two dimensions, the regularised
//! incomplete gamma function Q and log Γ.

use std::f64::consts::{PI, TAU};
use std::fmt;

use glam::DVec3;

use super::warp::frame_around;

/// The PCG32 generator (XSH RR output on a 64-bit LCG), after M. E. O'Neill,
/// "PCG: A Family of Simple Fast Space-Efficient Statistically Good
/// Algorithms for Random Number Generation", HMC-CS-2014-0905, 2014.
#[derive(Clone, Debug)]
pub struct Pcg32(rand_pcg::Pcg32);

impl Pcg32 {
    /// A generator on stream `stream` started from `seed` (the reference
    /// implementation's `pcg32_srandom_r(seed, stream)`).
    pub fn new(seed: u64, stream: u64) -> Self {
        Self(rand_pcg::Pcg32::new(seed, stream))
    }

    /// The next 32 random bits.
    pub fn next_u32(&mut self) -> u32 {
        rand_core::RngCore::next_u32(&mut self.0)
    }

    /// A uniform number in [0, 1) with 53 random bits.
    pub fn next_f64(&mut self) -> f64 {
        let hi = u64::from(self.next_u32()) << 21;
        let lo = u64::from(self.next_u32() >> 11);
        (hi | lo) as f64 * (1.0 / (1u64 << 53) as f64)
    }
}

/// How a chi-square test bins the sphere of directions.
///
/// Cells are taken in a frame whose pole is `axis` (built with
/// [`frame_around`]), over (cos θ, φ): `cos_bins` equal intervals of cos θ
/// over [`cap_cos`, 1] times `phi_bins` equal intervals of φ over [0, 2π)
/// — cells of equal solid angle, dω = d(cos θ) dφ. When `cap_cos` > −1 one
/// more cell holds every direction with cos θ < `cap_cos`, which lets a
/// narrow lobe be resolved by centring a small cap on it.
///
/// With `polar`, each cell's integral is taken over (θ, φ) with dω =
/// sin θ dθ dφ instead: for densities with an integrable 1/sin θ pole at
/// the axis (or its opposite), which the factor sin θ cancels.
#[derive(Clone, Debug)]
pub struct Chi2Config {
    /// Number of samples drawn (valid or not).
    pub samples: usize,
    /// Cells along cos θ.
    pub cos_bins: usize,
    /// Cells along φ.
    pub phi_bins: usize,
    /// The pole of the binning frame (unit).
    pub axis: DVec3,
    /// Lower end of the binned cap in cos θ (−1: the whole sphere).
    pub cap_cos: f64,
    /// Seed of the [`Pcg32`] random numbers fed to the sampler.
    pub seed: u64,
    /// Cells expecting fewer samples than this are pooled.
    pub min_expected: f64,
    /// Integrate the cells over θ rather than cos θ (see above).
    pub polar: bool,
}

impl Default for Chi2Config {
    fn default() -> Self {
        Self {
            samples: 1_000_000,
            cos_bins: 20,
            phi_bins: 40,
            axis: DVec3::Z,
            cap_cos: -1.0,
            seed: 0x5eed,
            min_expected: 5.0,
            polar: false,
        }
    }
}

/// The outcome of [`chi2_test`].
#[derive(Clone, Debug)]
pub struct Chi2Report {
    /// The chi-square statistic Σ (observed − expected)² / expected over the
    /// pooled categories.
    pub chi2: f64,
    /// Degrees of freedom: categories − 1.
    pub dof: usize,
    /// P(χ²_dof ≥ chi2) = Q(dof/2, chi2/2).
    pub p_value: f64,
    /// ∫ pdf dω over the sphere (the sum of the cells' integrals).
    pub pdf_mass: f64,
    /// Fraction of the samples that were valid (the sampler returned a direction).
    pub valid_fraction: f64,
    /// Samples drawn.
    pub samples: usize,
    /// Cells pooled because their expected count was under the minimum.
    pub pooled_cells: usize,
    /// Samples that fell in cells where the density integrates to 0.
    pub zero_expected_hits: u64,
    /// Samples that were not finite unit vectors (|length − 1| > 1e-9).
    pub bad_samples: u64,
}

/// Largest allowed |∫pdf dω − valid fraction|.
pub const MASS_TOLERANCE: f64 = 1e-2;

impl Chi2Report {
    /// Why the test fails at significance `level` (empty when it passes):
    /// p < level, |∫pdf − valid fraction| > [`MASS_TOLERANCE`], bad samples,
    /// more than 1e-5 of the samples in cells of zero density, or no degrees
    /// of freedom.
    pub fn failures(&self, level: f64) -> Vec<String> {
        let mut why = Vec::new();
        if self.p_value.is_nan() || self.p_value < level {
            why.push(format!("p-value {:.3e} < significance level {:.3e}", self.p_value, level));
        }
        let gap = (self.pdf_mass - self.valid_fraction).abs();
        if gap.is_nan() || gap > MASS_TOLERANCE {
            why.push(format!("∫pdf dω = {:.6} but valid fraction {:.6}", self.pdf_mass, self.valid_fraction));
        }
        if self.bad_samples > 0 {
            why.push(format!("{} samples not finite unit vectors", self.bad_samples));
        }
        if self.zero_expected_hits as f64 > 1e-5 * self.samples as f64 {
            why.push(format!("{} samples where the pdf is 0", self.zero_expected_hits));
        }
        if self.dof == 0 {
            why.push("no degrees of freedom".into());
        }
        why
    }

    /// Whether the test passes at significance `level` (see [`Chi2Report::failures`]).
    pub fn passed(&self, level: f64) -> bool {
        self.failures(level).is_empty()
    }

    /// Prints the report under `name` and panics with the reasons when the
    /// test fails at significance `level` (for test suites).
    pub fn assert_passes(&self, name: &str, level: f64) {
        println!("{name:<52} {self}");
        let why = self.failures(level);
        assert!(why.is_empty(), "{name}: {self}\n  fails: {}", why.join("; "));
    }
}

impl fmt::Display for Chi2Report {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "chi2 = {:.1}, dof = {}, p = {}, ∫pdf dω = {:.6}, valid = {:.6}, pooled cells = {}, zero-pdf hits = {}, \
             samples = {}",
            self.chi2,
            self.dof,
            if self.p_value >= 1e-3 { format!("{:.4}", self.p_value) } else { format!("{:.2e}", self.p_value) },
            self.pdf_mass,
            self.valid_fraction,
            self.pooled_cells,
            self.zero_expected_hits,
            self.samples
        )
    }
}

/// A family of chi-square tests judged together: each passes at the Šidák
/// level ([`sidak_level`]) that keeps the family-wise chance of a false
/// alarm at `alpha`.
#[derive(Clone, Copy, Debug)]
pub struct Family {
    /// Family-wise significance level.
    pub alpha: f64,
    /// Tests in the family.
    pub tests: usize,
}

impl Family {
    /// The level each test of the family is judged at.
    pub fn level(&self) -> f64 {
        sidak_level(self.alpha, self.tests)
    }

    /// Prints `report` and asserts that it passes at [`Family::level`].
    pub fn check(&self, name: &str, report: &Chi2Report) {
        report.assert_passes(name, self.level());
    }
}

/// Per-test significance level giving a family-wise level `alpha` over `tests`
/// independent tests (Šidák): 1 − (1 − alpha)^(1/tests) (≈ alpha / tests).
pub fn sidak_level(alpha: f64, tests: usize) -> f64 {
    -((-alpha).ln_1p() / tests as f64).exp_m1()
}

/// The binning of [`Chi2Config`]: maps directions to cells and cells to
/// (cos θ, φ) rectangles.
struct Grid {
    axis: DVec3,
    tu: DVec3,
    tv: DVec3,
    cap: f64,
    nc: usize,
    np: usize,
}

impl Grid {
    fn new(config: &Chi2Config) -> Self {
        let axis = config.axis.normalize();
        let (tu, tv) = frame_around(axis);
        let cap = config.cap_cos.clamp(-1.0, 1.0);
        Self { axis, tu, tv, cap, nc: config.cos_bins.max(1), np: config.phi_bins.max(1) }
    }

    fn has_rest(&self) -> bool {
        self.cap > -1.0
    }

    fn cells(&self) -> usize {
        self.nc * self.np + usize::from(self.has_rest())
    }

    /// The cell of the unit `d`; the rest cell is the last one.
    fn cell(&self, d: DVec3) -> usize {
        let mu = d.dot(self.axis).clamp(-1.0, 1.0);
        if mu < self.cap {
            return self.nc * self.np;
        }
        let i = (((mu - self.cap) / (1.0 - self.cap) * self.nc as f64) as usize).min(self.nc - 1);
        let mut phi = d.dot(self.tv).atan2(d.dot(self.tu));
        if phi < 0.0 {
            phi += TAU;
        }
        let j = ((phi / TAU * self.np as f64) as usize).min(self.np - 1);
        i * self.np + j
    }

    /// The direction at (cos θ, φ) of the frame.
    fn direction(&self, mu: f64, phi: f64) -> DVec3 {
        let s = (1.0 - mu * mu).max(0.0).sqrt();
        s * (phi.cos() * self.tu + phi.sin() * self.tv) + mu * self.axis
    }

    /// The (cos θ, φ) rectangle of a cell.
    fn bounds(&self, cell: usize) -> ((f64, f64), (f64, f64)) {
        if cell == self.nc * self.np {
            return ((-1.0, self.cap), (0.0, TAU));
        }
        let (i, j) = (cell / self.np, cell % self.np);
        let dc = (1.0 - self.cap) / self.nc as f64;
        let dp = TAU / self.np as f64;
        let mu1 = if i + 1 == self.nc { 1.0 } else { self.cap + (i + 1) as f64 * dc };
        ((self.cap + i as f64 * dc, mu1), (j as f64 * dp, (j + 1) as f64 * dp))
    }
}

/// Chi-square test of `sampler` against `pdf`.
///
/// `sampler` gets three uniform numbers in [0, 1) (from [`Pcg32`] seeded by
/// `config.seed`) and returns a unit direction, or `None` for an invalid
/// sample; `pdf` is its solid-angle density (integrating to the probability
/// that a sample is valid). Expected counts are `samples` × ∫ pdf over each
/// cell by [`integrate_2d`] in (cos θ, φ) (to 1e-3 samples, at least 65 × 65
/// points a cell so that a corner of a density's support poking into a cell
/// is not stepped over, at most 2²⁰ panels a side). Cells are sorted by expected count;
/// those below `config.min_expected` are pooled in order until the pool
/// reaches it (a pool left at the end joins the next cell); cells of zero
/// expected count are left out (their samples are counted in
/// [`Chi2Report::zero_expected_hits`]).
pub fn chi2_test<S, P>(config: &Chi2Config, mut sampler: S, pdf: P) -> Chi2Report
where
    S: FnMut([f64; 3]) -> Option<DVec3>,
    P: Fn(DVec3) -> f64,
{
    let grid = Grid::new(config);
    let n = config.samples;
    let mut observed = vec![0u64; grid.cells()];
    let mut rng = Pcg32::new(config.seed, 0x0c4a_2ea5);
    let (mut valid, mut bad) = (0u64, 0u64);
    for _ in 0..n {
        let u = [rng.next_f64(), rng.next_f64(), rng.next_f64()];
        let Some(d) = sampler(u) else { continue };
        valid += 1;
        if !d.is_finite() || (d.length() - 1.0).abs() > 1e-9 {
            bad += 1;
            continue;
        }
        observed[grid.cell(d)] += 1;
    }

    // Integrals of the density over the cells, to 1e-3 expected samples each.
    let eps = 1e-3 / n.max(1) as f64;
    let integrals: Vec<f64> = (0..grid.cells())
        .map(|c| {
            let (mu, phi) = grid.bounds(c);
            let min_depth = if c == grid.nc * grid.np { 6 } else { 4 };
            if config.polar {
                let theta = (mu.1.clamp(-1.0, 1.0).acos(), mu.0.clamp(-1.0, 1.0).acos());
                let f = |t: f64, p: f64| pdf(grid.direction(t.cos(), p)) * t.sin();
                integrate_2d(&f, theta, phi, eps, min_depth, 20)
            } else {
                integrate_2d(&|m, p| pdf(grid.direction(m, p)), mu, phi, eps, min_depth, 20)
            }
        })
        .collect();
    let pdf_mass: f64 = integrals.iter().sum();

    let mut zero_expected_hits = 0u64;
    let mut cells: Vec<(f64, u64)> = Vec::with_capacity(grid.cells());
    for (&i, &o) in integrals.iter().zip(&observed) {
        let e = i * n as f64;
        if e > 0.0 {
            cells.push((e, o));
        } else {
            zero_expected_hits += o;
        }
    }
    cells.sort_by(|a, b| a.0.total_cmp(&b.0));
    let mut categories: Vec<(f64, u64)> = Vec::new();
    let (mut pool_e, mut pool_o, mut pooled) = (0.0, 0u64, 0usize);
    for (e, o) in cells {
        if e < config.min_expected {
            pool_e += e;
            pool_o += o;
            pooled += 1;
            if pool_e >= config.min_expected {
                categories.push((pool_e, pool_o));
                (pool_e, pool_o) = (0.0, 0);
            }
        } else {
            categories.push((e + pool_e, o + pool_o));
            (pool_e, pool_o) = (0.0, 0);
        }
    }
    if pool_e > 0.0 {
        match categories.last_mut() {
            Some(last) => *last = (last.0 + pool_e, last.1 + pool_o),
            None => categories.push((pool_e, pool_o)),
        }
    }
    let chi2: f64 = categories.iter().map(|&(e, o)| (o as f64 - e) * (o as f64 - e) / e).sum();
    let dof = categories.len().saturating_sub(1);
    Chi2Report {
        chi2,
        dof,
        p_value: chi2_p_value(chi2, dof),
        pdf_mass,
        valid_fraction: valid as f64 / n.max(1) as f64,
        samples: n,
        pooled_cells: pooled,
        zero_expected_hits,
        bad_samples: bad,
    }
}

/// P(X ≥ `chi2`) for X chi-square distributed with `dof` degrees of freedom:
/// Q(dof/2, chi2/2). 1 for dof = 0.
pub fn chi2_p_value(chi2: f64, dof: usize) -> f64 {
    if dof == 0 {
        return 1.0;
    }
    gamma_q(0.5 * dof as f64, 0.5 * chi2.max(0.0))
}

/// ln Γ(z) for z > 0 (`statrs`).
pub fn ln_gamma(z: f64) -> f64 {
    assert!(z > 0.0, "ln_gamma needs z > 0, got {z}");
    statrs::function::gamma::ln_gamma(z)
}

/// The regularised upper incomplete gamma function
/// Q(a, x) = Γ(a, x)/Γ(a) = 1 − P(a, x), a > 0, x ≥ 0 (`statrs`).
pub fn gamma_q(a: f64, x: f64) -> f64 {
    assert!(a > 0.0 && x >= 0.0, "gamma_q needs a > 0 and x >= 0, got a = {a}, x = {x}");
    if x == 0.0 {
        return 1.0;
    }
    statrs::function::gamma::gamma_ur(a, x)
}

/// ∫ₐᵇ f by adaptive Simpson quadrature: a panel is split while
/// |S(left) + S(right) − S(whole)| > 15 eps (eps halved at each split), at
/// least to `min_depth` levels (so narrow features are not stepped over) and
/// at most to `max_depth`; each accepted panel adds the Richardson term
/// (S(left) + S(right) − S(whole))/15 (Lyness, "Notes on the adaptive Simpson
/// quadrature routine", J. ACM 16(3), 1969).
pub fn adaptive_simpson<F: Fn(f64) -> f64>(f: &F, a: f64, b: f64, eps: f64, min_depth: u32, max_depth: u32) -> f64 {
    let (fa, fb) = (f(a), f(b));
    let fm = f(0.5 * (a + b));
    let whole = (b - a) / 6.0 * (fa + 4.0 * fm + fb);
    let panel = Panel { a, b, fa, fm, fb, whole };
    simpson_step(f, panel, eps, 0, min_depth, max_depth)
}

#[derive(Clone, Copy)]
struct Panel {
    a: f64,
    b: f64,
    fa: f64,
    fm: f64,
    fb: f64,
    whole: f64,
}

fn simpson_step<F: Fn(f64) -> f64>(f: &F, p: Panel, eps: f64, depth: u32, min_depth: u32, max_depth: u32) -> f64 {
    let m = 0.5 * (p.a + p.b);
    let (flm, frm) = (f(0.5 * (p.a + m)), f(0.5 * (m + p.b)));
    let left = (m - p.a) / 6.0 * (p.fa + 4.0 * flm + p.fm);
    let right = (p.b - m) / 6.0 * (p.fm + 4.0 * frm + p.fb);
    let delta = left + right - p.whole;
    if depth >= max_depth || (depth >= min_depth && delta.abs() <= 15.0 * eps) {
        return left + right + delta / 15.0;
    }
    let l = Panel { a: p.a, b: m, fa: p.fa, fm: flm, fb: p.fm, whole: left };
    let r = Panel { a: m, b: p.b, fa: p.fm, fm: frm, fb: p.fb, whole: right };
    simpson_step(f, l, 0.5 * eps, depth + 1, min_depth, max_depth)
        + simpson_step(f, r, 0.5 * eps, depth + 1, min_depth, max_depth)
}

/// ∫∫ f(x, y) dy dx over [x0, x1] × [y0, y1] by nested [`adaptive_simpson`]
/// (absolute tolerance `eps` overall: eps / (x1 − x0) for each inner integral).
///
/// The integrand is taken as its one-sided limits on the rectangle's edges:
/// points on an edge are moved 1e-14 + 1e-12 × the width inside (far more
/// than the rounding of a direction built from (cos θ, φ), far less than any
/// feature of a density). A density that jumps exactly on a cell boundary
/// (a hemisphere's or a cone's rim, which the chi-square grids put on cell
/// boundaries) then counts only in the cells it covers, instead of adding a
/// spurious h/6 · f(edge) to a neighbour (which the adaptive refinement
/// shrinks but cannot remove).
pub fn integrate_2d<F: Fn(f64, f64) -> f64>(
    f: &F,
    (x0, x1): (f64, f64),
    (y0, y1): (f64, f64),
    eps: f64,
    min_depth: u32,
    max_depth: u32,
) -> f64 {
    if x1 <= x0 || y1 <= y0 {
        return 0.0;
    }
    let inner_eps = eps / (x1 - x0);
    let (dx, dy) = (1e-14 + 1e-12 * (x1 - x0), 1e-14 + 1e-12 * (y1 - y0));
    let g = |x: f64| {
        let x = x.clamp(x0 + dx, x1 - dx);
        adaptive_simpson(&|y: f64| f(x, y.clamp(y0 + dy, y1 - dy)), y0, y1, inner_eps, min_depth, max_depth)
    };
    adaptive_simpson(&g, x0, x1, eps, min_depth, max_depth)
}

/// ∫ f(ω) dω over the whole sphere of directions, by [`integrate_2d`] in
/// (cos θ, φ) about +z, split at cos θ = 0 (so a density confined to a
/// hemisphere has no jump inside a panel).
pub fn integrate_sphere<F: Fn(DVec3) -> f64>(f: &F, eps: f64) -> f64 {
    let dir = |mu: f64, phi: f64| {
        let s = (1.0 - mu * mu).max(0.0).sqrt();
        DVec3::new(s * phi.cos(), s * phi.sin(), mu)
    };
    let g = |mu: f64, phi: f64| f(dir(mu, phi));
    integrate_2d(&g, (-1.0, 0.0), (0.0, TAU), 0.5 * eps, 4, 18)
        + integrate_2d(&g, (0.0, 1.0), (0.0, TAU), 0.5 * eps, 4, 18)
}

/// The density of uniform directions on the hemisphere around +z: 1/(2π)
/// for w.z > 0, else 0 (for testing the tests: cosine samples are not
/// distributed so).
pub fn pdf_uniform_hemisphere(w: DVec3) -> f64 {
    if w.z > 0.0 {
        0.5 / PI
    } else {
        0.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ln_gamma_known_values() {
        assert!((ln_gamma(1.0)).abs() < 1e-14);
        assert!((ln_gamma(5.0) - 24f64.ln()).abs() < 1e-14);
        assert!((ln_gamma(0.5) - PI.sqrt().ln()).abs() < 1e-14);
        // Γ(10.5) = 1133278.3889487855...
        assert!((ln_gamma(10.5) - 1_133_278.388_948_785_5f64.ln()).abs() < 1e-13);
        assert!((ln_gamma(100.0) - 359.134_205_369_575_4).abs() < 1e-11);
    }

    #[test]
    fn chi2_p_values() {
        // Q(1, x) = e^(−x): two degrees of freedom.
        for x in [0.1, 1.0, 3.0, 30.0] {
            assert!((chi2_p_value(x, 2) - (-0.5 * x).exp()).abs() < 1e-14);
        }
        // 95% quantiles of χ² with 1 and 10 dof, and the 99% quantile for 100.
        assert!((chi2_p_value(3.841_458_820_694_124, 1) - 0.05).abs() < 1e-12);
        assert!((chi2_p_value(18.307_038_053_275_146, 10) - 0.05).abs() < 1e-12);
        assert!((chi2_p_value(135.806_723_171_026_8, 100) - 0.01).abs() < 1e-12);
        // Reference values from mpmath (30 digits).
        assert!((chi2_p_value(0.5, 3) - 0.918_891_411_654_675_8).abs() < 1e-13);
        assert!((chi2_p_value(550.5, 601) - 0.930_583_319_639_120_7).abs() < 1e-12);
        assert!((chi2_p_value(900.0, 700) / 4.227_616_740_898_031e-7 - 1.0).abs() < 1e-10);
        assert!(chi2_p_value(5000.0, 100) < 1e-300);
    }

    #[test]
    fn sidak_level_is_close_to_bonferroni() {
        let l = sidak_level(0.01, 30);
        assert!(l > 0.01 / 30.0 && l < 0.0101 / 30.0, "{l}");
    }

    #[test]
    fn pcg32_is_deterministic_and_uniform() {
        let mut a = Pcg32::new(42, 54);
        let mut b = Pcg32::new(42, 54);
        let mut sum = 0.0;
        for _ in 0..10_000 {
            let x = a.next_f64();
            assert_eq!(x, b.next_f64());
            assert!((0.0..1.0).contains(&x));
            sum += x;
        }
        assert!((sum / 10_000.0 - 0.5).abs() < 0.01);
        // The reference output of O'Neill's pcg32 demo (seed 42, stream 54).
        let mut r = Pcg32::new(42, 54);
        let first: Vec<u32> = (0..3).map(|_| r.next_u32()).collect();
        assert_eq!(first, [0xa15c02b7, 0x7b47f409, 0xba1d3330]);
    }

    #[test]
    fn simpson_integrates_smooth_and_jumping_functions() {
        let s = adaptive_simpson(&|x: f64| x.sin(), 0.0, PI, 1e-12, 2, 30);
        assert!((s - 2.0).abs() < 1e-10);
        let j = adaptive_simpson(&|x: f64| if x < 0.3 { 1.0 } else { 0.0 }, 0.0, 1.0, 1e-9, 2, 30);
        assert!((j - 0.3).abs() < 1e-8, "{j}");
        let area = integrate_sphere(&|_| 1.0, 1e-10);
        assert!((area - 4.0 * PI).abs() < 1e-8);
    }
}
