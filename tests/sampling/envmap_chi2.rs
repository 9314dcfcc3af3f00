//! Tests of the environment-map importance sampling (`quadray::model::sampling::envmap`):
//! chi-square tests of `EnvironmentMap::sample` against `EnvironmentMap::pdf`
//! (see `sampling::chi2`) for a procedural sky, a random map and a map that
//! is black but for one texel; the normalisation of the density; the
//! agreement of each sample's pdf and radiance with `pdf(dir)` and
//! `radiance(dir)`; the (u, v) ↔ direction round trip; the tables; that a
//! wrong density is rejected; and an unbiased Monte Carlo estimate of the
//! irradiance ∫ L(d) cos⁺(d·n) dω against quadrature over the texels.
//!
//! Every chi-square test prints its χ², degrees of freedom and p-value
//! (`cargo test --test sampling -- envmap_chi2:: --nocapture`). A test fails when its
//! p-value is below the Šidák-corrected level for a family-wise level of 0.01
//! over the [`CHI2_TESTS`] tests of this file, or when ∫pdf dω differs from the
//! fraction of valid samples by more than 1e-2. The random numbers are seeded,
//! so the figures are reproducible.

use std::f64::consts::PI;

use glam::{DVec2, DVec3};
use quadray::model::sampling::chi2::{self, chi2_test, Chi2Config, Chi2Report, Pcg32};
use quadray::model::sampling::envmap::{importance_weights, luminance, sky_sun_direction};
use quadray::model::sampling::{direction_to_uv, procedural_sky, uv_to_direction, EnvironmentMap};

/// Chi-square tests run by this file (the Šidák correction divides the
/// family-wise level among them): sky 2 (whole sphere, cap on the sun),
/// random map 2 (two binning axes), single texel 2 (whole sphere, cap on the
/// texel). (The deliberately wrong tests are not counted: they must fail.)
const CHI2_TESTS: usize = 6;
/// Family-wise significance level.
const FAMILY_LEVEL: f64 = 0.01;

fn level() -> f64 {
    chi2::sidak_level(FAMILY_LEVEL, CHI2_TESTS)
}

/// Asserts that the test passes, and that the density integrates to 1
/// within 1e-3 (the harness's own tolerance is 1e-2).
fn check(name: &str, report: &Chi2Report) {
    report.assert_passes(name, level());
    assert!((report.pdf_mass - 1.0).abs() < 1e-3, "{name}: ∫pdf dω = {}", report.pdf_mass);
}

/// Poles of the binning frames of the whole-sphere tests.
///
/// The density is unbounded near the poles ±y (∝ 1/sin θ, integrably), so
/// the grids are tilted to put ±y inside cells, away from cell edges and
/// corners. With the default +z pole, ±y sit on cell corners, the harness's
/// quadrature evaluates the density within 1e-13 of the singularity and
/// overestimates those cells (∫pdf dω comes out 1.09 for the random map);
/// even inside a cell, a quadrature node can land close to a pole, so these
/// axes were checked to give ∫pdf dω = 1 within 1e-5 for all three maps.
const AXES: [DVec3; 3] = [DVec3::new(0.6, 0.5, -0.3), DVec3::new(-0.7, 0.35, 0.45), DVec3::new(0.2, -0.25, 0.9)];

fn axis(k: usize) -> DVec3 {
    AXES[k].normalize()
}

/// The procedural sky at 64 × 32.
fn sky() -> EnvironmentMap {
    let texture = procedural_sky(64, 32);
    assert_eq!((texture.width, texture.height, texture.levels[0].len()), (64, 32, 64 * 32));
    EnvironmentMap::from_texture(&texture, 1.0)
}

/// A 16 × 8 map of random colours over a dynamic range of e⁶ ≈ 400, about
/// 15 % of the texels black, and row 3 entirely black.
fn random_map() -> EnvironmentMap {
    let (w, h) = (16, 8);
    let mut rng = Pcg32::new(2024, 7);
    let texels = (0..w * h)
        .map(|k| {
            let black = rng.next_f64() < 0.15 || k / w == 3;
            let level = (6.0 * rng.next_f64() - 3.0).exp();
            let c = [rng.next_f64(), rng.next_f64(), rng.next_f64()].map(|x| (level * (0.2 + x)) as f32);
            if black {
                [0.0; 4]
            } else {
                [c[0], c[1], c[2], 1.0]
            }
        })
        .collect::<Vec<_>>();
    EnvironmentMap::from_rgba(w as u32, h as u32, &texels, 1.0)
}

/// The texel that is lit in [`single_texel_map`].
const LIT: (usize, usize) = (11, 2);

/// A 16 × 8 map, black but for texel [`LIT`].
fn single_texel_map() -> EnvironmentMap {
    let mut texels = vec![[0.0f32; 3]; 16 * 8];
    texels[LIT.1 * 16 + LIT.0] = [5.0, 4.0, 3.0];
    EnvironmentMap::from_rgb(16, 8, texels, 1.0)
}

fn sampler(map: &EnvironmentMap) -> impl FnMut([f64; 3]) -> Option<DVec3> + '_ {
    |u| map.sample(u[0], u[1]).map(|s| s.0)
}

/// The chi-square test of `map`'s sampling against its own pdf, checked
/// (passes at the level, ∫pdf dω = 1) under `name`.
fn chi2_of_map(map: &EnvironmentMap, config: &Chi2Config, name: &str) -> Chi2Report {
    let r = chi2_test(config, sampler(map), |d| map.pdf(d));
    check(name, &r);
    r
}

/// The smallest cos of the angle between `axis` and the corners and edge
/// midpoints of texel (i, j) (a cap around `axis` down to it holds the texel
/// when the texel is small and away from the poles).
fn cap_cos_around_texel(map: &EnvironmentMap, axis: DVec3, i: usize, j: usize) -> f64 {
    let (w, h) = (f64::from(map.width), f64::from(map.height));
    let mut c = 1.0f64;
    for a in 0..=4 {
        for b in 0..=4 {
            let d = uv_to_direction((i as f64 + a as f64 / 4.0) / w, (j as f64 + b as f64 / 4.0) / h);
            c = c.min(d.dot(axis));
        }
    }
    c
}

// ---------------------------------------------------------------- chi-square

#[test]
fn chi2_procedural_sky() {
    let map = sky();
    let config = Chi2Config { axis: axis(0), seed: 101, ..Chi2Config::default() };
    chi2_of_map(&map, &config, "sky 64x32, whole sphere");
}

/// The sun, finely binned: a 9.5° cap around it (the 2.5° disk and the four
/// texels it covers, 82 % of the probability, whose farthest corner is 8.7°
/// away) in 20 × 40 cells, the rest of the sphere in one cell.
///
/// The map is the sky with its top and bottom rows made black: the rest cell
/// holds both poles, near which the density of a lit pole row is unbounded
/// (∝ 1/sin θ), and the harness's quadrature of one cell that large around
/// them is unreliable (∫pdf dω comes out 1.35 with the full sky). The pole
/// rows are tested by the whole-sphere test. 5·10⁵ samples: the quadrature
/// of the rest cell to 1e-3 / 10⁶ takes 20 times as long.
#[test]
fn chi2_procedural_sky_sun_cap() {
    let texture = procedural_sky(64, 32);
    let mut texels = texture.levels[0].clone();
    let n = texels.len();
    texels[..64].fill([0.0; 4]);
    texels[n - 64..].fill([0.0; 4]);
    let map = EnvironmentMap::from_rgba(64, 32, &texels, 1.0);
    let sun = sky_sun_direction();
    let config = Chi2Config {
        samples: 500_000,
        axis: sun,
        cap_cos: 9.5f64.to_radians().cos(),
        seed: 102,
        ..Chi2Config::default()
    };
    chi2_of_map(&map, &config, "sky 64x32 (pole rows black), 9.5° sun cap");
}

#[test]
fn chi2_random_map() {
    let map = random_map();
    for k in 0..2 {
        let config = Chi2Config { axis: axis(k), seed: 201 + k as u64, ..Chi2Config::default() };
        chi2_of_map(&map, &config, &format!("random 16x8, axis {:.2}", axis(k)));
    }
}

#[test]
fn chi2_single_texel() {
    let map = single_texel_map();
    let config = Chi2Config { axis: axis(1), seed: 301, ..Chi2Config::default() };
    chi2_of_map(&map, &config, "single texel 16x8, whole sphere");
    let (w, h) = (f64::from(map.width), f64::from(map.height));
    let axis = uv_to_direction((LIT.0 as f64 + 0.5) / w, (LIT.1 as f64 + 0.5) / h);
    let cap = cap_cos_around_texel(&map, axis, LIT.0, LIT.1) - 0.01;
    let config = Chi2Config { axis, cap_cos: cap, seed: 302, ..Chi2Config::default() };
    let r = chi2_of_map(&map, &config, "single texel 16x8, cap on the texel");
    assert_eq!(r.zero_expected_hits, 0);
}

/// The harness must reject wrong densities of the right mass: samples of the
/// random map tested against (a) the density with sin θ frozen at the row
/// centre within each texel, (b) the density ignoring sin θ altogether,
/// renormalised (p_uv / (2π² K), K = Σ_j row_pdf_j × the mean of sin θ over
/// row j).
#[test]
fn chi2_rejects_wrong_densities() {
    let map = random_map();
    let (w, h) = (f64::from(map.width), f64::from(map.height));
    let p_uv = |d: DVec3| {
        let (i, j) = map.texel_at(direction_to_uv(d));
        (map.texel_pdf(i, j) * w * h, j)
    };
    let row_centre = |d: DVec3| {
        let (p, j) = p_uv(d);
        p / (2.0 * PI * PI * (PI * (j as f64 + 0.5) / h).sin())
    };
    let k: f64 = (0..map.height as usize)
        .map(|j| map.row_pdf(j) * ((PI * j as f64 / h).cos() - (PI * (j + 1) as f64 / h).cos()) / (PI / h))
        .sum();
    let no_sine = |d: DVec3| p_uv(d).0 / (2.0 * PI * PI * k);
    for (name, wrong) in [("sin θ at the row centre", &row_centre as &dyn Fn(DVec3) -> f64), ("no sin θ", &no_sine)] {
        let config = Chi2Config { axis: axis(0), seed: 401, ..Chi2Config::default() };
        let r = chi2_test(&config, sampler(&map), wrong);
        println!("{:<44} {r}", format!("WRONG pdf ({name})"));
        assert!((r.pdf_mass - 1.0).abs() < 1e-2, "{name}: the wrong pdf should still be normalised: {r}");
        assert!(r.p_value < 1e-6, "{name}: the wrong pdf was not rejected: {r}");
        assert!(!r.passed(level()));
    }
}

// ---------------------------------------------------------------- density

/// ∫ pdf dω over the sphere by quadrature, independently of the chi-square
/// harness: [`chi2::integrate_2d`] over 16 × 32 (cos θ, φ) cells about the
/// third axis of [`AXES`] (to 1e-8 a cell, at least 17 × 17 points a cell).
#[test]
fn pdf_integrates_to_one() {
    let pole = axis(2);
    let (tu, tv) = quadray::model::sampling::frame_around(pole);
    let (nc, np) = (16, 32);
    for (name, map) in [("sky 64x32", sky()), ("random 16x8", random_map()), ("single texel 16x8", single_texel_map())]
    {
        let f = |mu: f64, phi: f64| {
            let s = (1.0 - mu * mu).max(0.0).sqrt();
            map.pdf(s * (phi.cos() * tu + phi.sin() * tv) + mu * pole)
        };
        let mut mass = 0.0;
        for a in 0..nc {
            for b in 0..np {
                let mu = (-1.0 + 2.0 * a as f64 / nc as f64, -1.0 + 2.0 * (a + 1) as f64 / nc as f64);
                let phi = (2.0 * PI * b as f64 / np as f64, 2.0 * PI * (b + 1) as f64 / np as f64);
                mass += chi2::integrate_2d(&f, mu, phi, 1e-8, 4, 20);
            }
        }
        println!("{name:<20} ∫ pdf dω = {mass:.9}");
        assert!((mass - 1.0).abs() < 1e-3, "{name}: {mass}");
        // The discrete probabilities of the texels sum to 1 (up to f64 rounding).
        let (w, h) = (map.width as usize, map.height as usize);
        let sum: f64 = (0..w * h).map(|k| map.texel_pdf(k % w, k / w)).sum();
        assert!((sum - 1.0).abs() < 1e-12, "{name}: Σ texel probabilities = {sum}");
    }
}

/// Distance from `x` to the nearest multiple of 1/`n`, in texels.
fn border_distance(x: f64, n: u32) -> f64 {
    let t = x * f64::from(n);
    (t - t.round()).abs()
}

#[test]
fn sample_pdf_and_radiance_agree_with_lookups() {
    for (name, map) in [("sky 64x32", sky()), ("random 16x8", random_map()), ("single texel 16x8", single_texel_map())]
    {
        let mut rng = Pcg32::new(77, 1);
        let (mut checked, mut border, mut invalid, mut worst) = (0usize, 0usize, 0usize, 0.0f64);
        let mut us: Vec<(f64, f64)> = (0..200_000).map(|_| (rng.next_f64(), rng.next_f64())).collect();
        // The ends of the unit interval too (25 pairs: u = 0 lands on a texel
        // border, u1 = 0 at the pole when the top row is lit).
        let ends = [0.0, 1e-12, 0.5, 1.0 - 1e-12, 1.0 - f64::EPSILON / 2.0];
        us.extend(ends.iter().flat_map(|&a| ends.iter().map(move |&b| (a, b))));
        for (u1, u2) in us {
            let Some((d, pdf, radiance)) = map.sample(u1, u2) else {
                invalid += 1;
                continue;
            };
            assert!((d.length() - 1.0).abs() < 1e-12 && pdf > 0.0 && pdf.is_finite(), "{name}: {d} {pdf}");
            let uv = direction_to_uv(d);
            if border_distance(uv.x, map.width) < 1e-9 || border_distance(uv.y, map.height) < 1e-9 {
                border += 1;
                continue;
            }
            let p = map.pdf(d);
            let rel = (p - pdf).abs() / pdf;
            worst = worst.max(rel);
            assert!(rel < 1e-6, "{name}: sample pdf {pdf} vs pdf(dir) {p} at uv {uv}");
            assert_eq!(map.radiance(d), radiance, "{name}: radiance at uv {uv}");
            checked += 1;
        }
        println!(
            "{name:<20} {checked} samples: worst relative pdf difference {worst:.2e}; {border} at texel borders, \
             {invalid} invalid"
        );
        assert!(border <= 25 + 5 && invalid <= 5, "{name}: {border} border samples, {invalid} invalid");
    }
}

#[test]
fn tables_match_the_importance() {
    for (name, map) in [("sky 64x32", sky()), ("random 16x8", random_map()), ("single texel 16x8", single_texel_map())]
    {
        let (w, h) = (map.width as usize, map.height as usize);
        assert_eq!((map.marginal.len(), map.conditional.len()), (h + 1, h * (w + 1)));
        assert_eq!((map.marginal[0], map.marginal[h]), (0.0, 1.0));
        assert!(map.marginal.windows(2).all(|p| p[0] <= p[1]));
        for row in map.conditional.chunks(w + 1) {
            assert_eq!((row[0], row[w]), (0.0, 1.0));
            assert!(row.windows(2).all(|p| p[0] <= p[1]));
        }
        assert_eq!(map.cdf_buffer().len(), h + 1 + h * (w + 1));
        let weights = importance_weights(map.width, map.height, &map.texels);
        let total: f64 = weights.iter().sum();
        let mut worst = 0.0f64;
        for j in 0..h {
            for i in 0..w {
                let (p, want) = (map.texel_pdf(i, j), weights[j * w + i] / total);
                assert_eq!(p > 0.0, luminance(map.texels[j * w + i]) > 0.0, "{name}: texel ({i}, {j})");
                worst = worst.max((p - want).abs());
                assert!((p - want).abs() <= 3e-7 + 1e-6 * want, "{name}: texel ({i}, {j}): {p} vs {want}");
            }
        }
        println!("{name:<20} max |texel probability − w/Σw| = {worst:.2e}");
    }
    // The single lit texel takes every sample.
    let map = single_texel_map();
    assert_eq!(map.texel_pdf(LIT.0, LIT.1), 1.0);
    // Row 3 of the random map is black: never sampled.
    assert_eq!(random_map().row_pdf(3), 0.0);
}

#[test]
fn uv_round_trip() {
    let n = 101;
    let mut worst = 0.0f64;
    for a in 0..n {
        for b in 0..n {
            let (u, v) = ((a as f64 + 0.5) / n as f64, (b as f64 + 0.5) / n as f64);
            let d = uv_to_direction(u, v);
            assert!((d.length() - 1.0).abs() < 1e-15);
            let back = direction_to_uv(d);
            worst = worst.max((back - DVec2::new(u, v)).abs().max_element());
            assert!((back - DVec2::new(u, v)).abs().max_element() < 1e-12, "({u}, {v}) -> {d} -> {back}");
        }
    }
    let mut rng = Pcg32::new(5, 9);
    for _ in 0..10_000 {
        let d = quadray::model::sampling::sample_uniform_sphere(rng.next_f64(), rng.next_f64());
        let uv = direction_to_uv(d);
        assert!((0.0..=1.0).contains(&uv.x) && (0.0..=1.0).contains(&uv.y));
        assert!((uv_to_direction(uv.x, uv.y) - d).length() < 1e-12);
    }
    println!("(u, v) -> direction -> (u, v): worst error {worst:.2e}");
    // The conventions: +y up at v = 0, u = 1/2 toward +x, u = 3/4 toward +z.
    assert!((uv_to_direction(0.5, 0.5) - DVec3::X).length() < 1e-15);
    assert!((uv_to_direction(0.75, 0.5) - DVec3::Z).length() < 1e-15);
    assert!((uv_to_direction(0.1, 0.0) - DVec3::Y).length() < 1e-15);
}

#[test]
fn black_map_and_scale() {
    let black = EnvironmentMap::from_rgb(8, 4, vec![[0.0; 3]; 32], 1.0);
    assert!(black.is_black() && black.sample(0.5, 0.5).is_none() && black.pdf(DVec3::X) == 0.0);
    let map = single_texel_map();
    let mut scaled = map.clone();
    scaled.scale = 2.5;
    let (d, p, l) = map.sample(0.3, 0.6).unwrap();
    let (ds, ps, ls) = scaled.sample(0.3, 0.6).unwrap();
    assert_eq!((d, p), (ds, ps));
    assert_eq!(ls, 2.5 * l);
    assert_eq!(l, DVec3::new(5.0, 4.0, 3.0));
    let light = scaled.sample_light(0.3, 0.6).unwrap();
    assert_eq!((light.wi, light.dist, light.emitted, light.pdf), (d, f64::INFINITY, ls, Some(p)));
}

// ---------------------------------------------------------------- estimator

/// ∫ max(0, d·n) dω over texel (i, j), by quadrature in (u, v).
fn texel_cosine_integral(map: &EnvironmentMap, i: usize, j: usize, n: DVec3) -> f64 {
    let (w, h) = (f64::from(map.width), f64::from(map.height));
    let f = |u: f64, v: f64| uv_to_direction(u, v).dot(n).max(0.0) * 2.0 * PI * PI * (PI * v).sin();
    let (u0, v0) = (i as f64 / w, j as f64 / h);
    chi2::integrate_2d(&f, (u0, u0 + 1.0 / w), (v0, v0 + 1.0 / h), 1e-12, 2, 20)
}

/// The Monte Carlo estimate of the irradiance E(n) = ∫ L(d) cos⁺(d·n) dω with
/// environment importance sampling (mean of L cos⁺ / pdf, invalid samples
/// counting 0) equals the quadrature Σ_texels L_ij ∫_texel cos⁺ dω within 3σ,
/// per RGB channel.
#[test]
fn irradiance_estimate_matches_quadrature() {
    let samples = 1_000_000;
    let sun = sky_sun_direction();
    let cases = [
        ("sky 64x32", sky(), vec![DVec3::Y, sun, DVec3::new(1.0, 0.2, -0.5).normalize(), -DVec3::Y]),
        ("random 16x8", random_map(), vec![DVec3::Y, DVec3::new(-0.3, -0.4, 0.8).normalize()]),
    ];
    println!("{:<12} {:>22} {:>10} {:>10} {:>10} {:>7}", "map", "n", "channel", "MC", "quadrature", "z");
    for (name, map, normals) in cases {
        for (k, n) in normals.into_iter().enumerate() {
            let (w, h) = (map.width as usize, map.height as usize);
            let mut quad = DVec3::ZERO;
            for j in 0..h {
                for i in 0..w {
                    let l = map.texel_radiance(i, j);
                    if l != DVec3::ZERO {
                        quad += l * texel_cosine_integral(&map, i, j, n);
                    }
                }
            }
            let mut rng = Pcg32::new(900 + k as u64, 3);
            let (mut sum, mut sum2) = (DVec3::ZERO, DVec3::ZERO);
            for _ in 0..samples {
                if let Some((d, pdf, l)) = map.sample(rng.next_f64(), rng.next_f64()) {
                    let x = l * d.dot(n).max(0.0) / pdf;
                    sum += x;
                    sum2 += x * x;
                }
            }
            let count = samples as f64;
            let mean = sum / count;
            let var = ((sum2 / count - mean * mean) / count).max(DVec3::ZERO);
            let sigma = DVec3::new(var.x.sqrt(), var.y.sqrt(), var.z.sqrt());
            for c in 0..3 {
                let z = (mean[c] - quad[c]) / sigma[c];
                println!(
                    "{name:<12} {:>22} {:>10} {:>10.6} {:>10.6} {z:>7.2}",
                    format!("{n:.2}"),
                    ["R", "G", "B"][c],
                    mean[c],
                    quad[c]
                );
                assert!(
                    z.abs() <= 3.0,
                    "{name}, n = {n}, channel {c}: MC {} ± {} vs quadrature {}",
                    mean[c],
                    sigma[c],
                    quad[c]
                );
            }
        }
    }
}
