//! Tests of the rough dielectric (`quadray::model::sampling::bsdf::RoughDielectric`,
//! Walter et al. 2007 with visible-normal sampling): chi-square tests of its
//! sampler against its density over the whole sphere of directions (both
//! hemispheres: reflection and refraction, from outside and from inside),
//! sample weights against eval · |cos| / pdf, reciprocity, the white-furnace
//! (flux) albedo, and the smooth limit.
//!
//! Every chi-square test prints its χ², degrees of freedom and p-value
//! (`cargo test --test sampling -- dielectric_chi2:: --nocapture`). A test fails when its
//! p-value is below the Šidák-corrected level for a family-wise level of 0.01
//! over the [`CHI2_TESTS`] tests of this file, or when ∫pdf dω differs from the
//! fraction of valid samples by more than 1e-2 (see `sampling::chi2`). The
//! random numbers are seeded, so the figures are reproducible.

use std::f64::consts::{PI, TAU};

use glam::DVec3;
use quadray::model::sampling::bsdf::RoughDielectric;
use quadray::model::sampling::chi2::{self, chi2_test, Chi2Config, Pcg32};
use quadray::model::sampling::*;
use quadray::model::scene::{Material, MaterialKind};

/// GGX α of the chi-square tests.
const ALPHAS: [f64; 3] = [0.1, 0.3, 0.7];
/// Relative indices of the chi-square tests.
const IORS: [f64; 2] = [1.33, 1.5];
/// View directions: (θ from the normal on wo's side in degrees, inside).
/// From inside, 20° is within the critical angle (41.8° for 1.5, 48.8° for
/// 1.33) and 50° beyond it (total internal reflection of the smooth surface;
/// the rough one still transmits a little through tilted microfacets).
const VIEWS: [(f64, bool); 5] = [(0.0, false), (45.0, false), (75.0, false), (20.0, true), (50.0, true)];
/// Chi-square tests of a (α, ior, view): the whole sphere, the reflection
/// lobe and the refraction lobe (either lobe skipped when it gets fewer than
/// 2% of the samples, so this is an upper bound, which keeps the level
/// conservative).
const TESTS_PER_CASE: usize = 3;
/// Chi-square tests in this file (upper bound): 3 α × 2 ior × 5 views × 3,
/// and 3 harness sanity tests that must pass.
const CHI2_TESTS: usize = ALPHAS.len() * IORS.len() * VIEWS.len() * TESTS_PER_CASE + 3;
/// The tests of this file, judged at a family-wise level of 1 %.
const FAMILY: chi2::Family = chi2::Family { alpha: 0.01, tests: CHI2_TESTS };

/// The view direction of a [`VIEWS`] entry (azimuth 0.7).
fn view(deg: f64, inside: bool) -> DVec3 {
    let w = spherical_direction(deg.to_radians(), 0.7);
    if inside {
        DVec3::new(w.x, w.y, -w.z)
    } else {
        w
    }
}

/// n_t / n_i for a ray arriving from wo's side.
fn eta_rel(ior: f64, wo: DVec3) -> f64 {
    if wo.z > 0.0 {
        ior
    } else {
        1.0 / ior
    }
}

fn same_side(wo: DVec3, wi: DVec3) -> bool {
    wo.z * wi.z > 0.0
}

// ---------------------------------------------------------------- harness

/// The harness on the full sphere (the default grid, pole +z, 20 × 40 cells
/// of equal solid angle over cos θ ∈ [−1, 1]): it accepts a correct density
/// that lives on both hemispheres, and it rejects a wrong one whose error is
/// only below the horizon, or which puts the mass on the wrong hemisphere; a
/// cap centred on a direction below the horizon works too.
#[test]
fn chi2_harness_sanity_on_the_full_sphere() {
    let config = Chi2Config { samples: 400_000, seed: 1, ..Chi2Config::default() };
    // Half the samples uniform on the upper hemisphere, half cosine-distributed
    // about −z: the right mixture density passes.
    let mixed = |u: [f64; 3]| {
        if u[2] < 0.5 {
            let w = sample_uniform_sphere(0.5 * u[0], u[1]);
            Some(DVec3::new(w.x, w.y, w.z.abs()))
        } else {
            let w = sample_cosine_hemisphere(u[0], u[1]);
            Some(DVec3::new(w.x, w.y, -w.z))
        }
    };
    let right = |w: DVec3| {
        if w.z > 0.0 {
            0.5 / (2.0 * PI)
        } else {
            0.5 * pdf_cosine_hemisphere(DVec3::new(w.x, w.y, -w.z))
        }
    };
    let r = chi2_test(&config, mixed, right);
    FAMILY.check("harness: uniform up + cosine down (right pdf)", &r);
    assert!(r.pdf_mass > 0.99 && r.valid_fraction == 1.0);

    // Wrong only below the horizon: uniform instead of cosine there.
    let wrong = |_: DVec3| 0.25 / PI;
    let r = chi2_test(&config, mixed, wrong);
    println!("{:<52} {r}", "harness: WRONG pdf below the horizon");
    assert!(r.p_value < 1e-6, "an error confined to z < 0 was not detected: {r}");
    assert!((r.pdf_mass - 1.0).abs() < 1e-6);

    // The mass on the wrong hemisphere: samples below, density above.
    let r = chi2_test(
        &config,
        |u| {
            let w = sample_cosine_hemisphere(u[0], u[1]);
            Some(DVec3::new(w.x, w.y, -w.z))
        },
        pdf_cosine_hemisphere,
    );
    println!("{:<52} {r}", "harness: WRONG hemisphere");
    assert!(!r.passed(FAMILY.level()) && r.zero_expected_hits == 400_000, "{r}");

    // A cap about a direction below the horizon, on a cosine lobe about −z,
    // and the uniform sphere with the default grid.
    let axis = DVec3::new(0.3, 0.2, -1.0).normalize();
    let capped = Chi2Config { axis, cap_cos: 0.5, seed: 2, ..config.clone() };
    let r = chi2_test(
        &capped,
        |u| {
            let w = sample_cosine_hemisphere(u[0], u[1]);
            Some(DVec3::new(w.x, w.y, -w.z))
        },
        |w| pdf_cosine_hemisphere(DVec3::new(w.x, w.y, -w.z)),
    );
    FAMILY.check("harness: cosine about -z, cap about a tilted -z", &r);
    let r = chi2_test(
        &Chi2Config { seed: 3, ..config },
        |u| Some(sample_uniform_sphere(u[0], u[1])),
        |_| pdf_uniform_sphere(),
    );
    FAMILY.check("harness: uniform sphere", &r);
}

/// The tests see the errors a rough dielectric could have: samples drawn with
/// a 3% larger ior, or α 3% too large, or a pdf without the eta² of the
/// refraction Jacobian, are all rejected.
#[test]
fn chi2_detects_wrong_dielectrics() {
    let right = RoughDielectric { alpha: 0.3, ior: 1.5 };
    let wo = view(45.0, false);
    let config = Chi2Config { samples: 400_000, seed: 5, ..Chi2Config::default() };
    for (what, wrong) in [
        ("ior x 1.03", RoughDielectric { ior: 1.5 * 1.03, ..right }),
        ("alpha x 1.03", RoughDielectric { alpha: 0.3 * 1.03, ..right }),
    ] {
        let r = chi2_test(&config, |u| wrong.sample(wo, u[0], u[1], u[2]).map(|s| s.wi), |wi| right.pdf(wo, wi));
        println!("{:<52} {r}", format!("WRONG sampler ({what})"));
        assert!(r.p_value < 1e-6, "{what} was not detected: {r}");
    }
    // Refraction density without the eta² of Walter's eq. 17.
    let eta2 = 1.5 * 1.5;
    let r = chi2_test(
        &config,
        |u| right.sample(wo, u[0], u[1], u[2]).map(|s| s.wi),
        |wi| if same_side(wo, wi) { right.pdf(wo, wi) } else { right.pdf(wo, wi) / eta2 },
    );
    println!("{:<52} {r}", "WRONG pdf (refraction Jacobian without eta²)");
    assert!(!r.passed(FAMILY.level()), "{r}");
}

// ---------------------------------------------------------------- chi-square

/// Axis and cap for a chi-square test of one lobe: from a pilot run with its
/// own seed (so the binning does not depend on the tested samples), the mean
/// direction of the lobe's samples and a cap holding ~97% of them. `None`
/// when the lobe gets fewer than 2% of the samples.
fn lobe_cap(bsdf: &RoughDielectric, wo: DVec3, reflection: bool, seed: u64) -> Option<(DVec3, f64)> {
    let n = 20_000;
    let mut rng = Pcg32::new(seed, 77);
    let mut dirs = Vec::new();
    for _ in 0..n {
        let s = bsdf.sample(wo, rng.next_f64(), rng.next_f64(), rng.next_f64());
        if let Some(s) = s.filter(|s| same_side(wo, s.wi) == reflection) {
            dirs.push(s.wi);
        }
    }
    if dirs.len() < n / 50 {
        return None;
    }
    let axis = dirs.iter().copied().sum::<DVec3>().normalize();
    let mut spread: Vec<f64> = dirs.iter().map(|d| 1.0 - d.dot(axis)).collect();
    spread.sort_by(f64::total_cmp);
    let q = spread[(spread.len() as f64 * 0.97) as usize];
    Some((axis, (1.0 - 1.2 * q).max(-1.0)))
}

/// Chi-square tests of one α and ior over [`VIEWS`]: the whole sphere with
/// the default grid (pole +z, cos θ in 20 bins over [−1, 1], so the horizon
/// is a cell boundary), then each lobe alone on a cap fitted to it (the
/// sampler's directions on the other side count as invalid, the density is
/// restricted to the lobe's side).
fn chi2_rough_dielectric(alpha: f64, ior: f64) {
    let bsdf = RoughDielectric { alpha, ior };
    for (k, (deg, inside)) in VIEWS.into_iter().enumerate() {
        let wo = view(deg, inside);
        let seed = ((alpha * 100.0) as u64 * 1000 + (ior * 100.0) as u64) * 10 + k as u64;
        let name = format!("alpha = {alpha} ior = {ior} {} {deg:>2}°", if inside { "in " } else { "out" });
        let config = Chi2Config { seed, ..Chi2Config::default() };
        let r = chi2_test(&config, |u| bsdf.sample(wo, u[0], u[1], u[2]).map(|s| s.wi), |wi| bsdf.pdf(wo, wi));
        FAMILY.check(&format!("{name} sphere"), &r);
        for reflection in [true, false] {
            let lobe = if reflection { "refl" } else { "refr" };
            let Some((axis, cap_cos)) = lobe_cap(&bsdf, wo, reflection, seed + 7) else {
                println!("{:<52} skipped: under 2% of the samples", format!("{name} {lobe}"));
                continue;
            };
            let config =
                Chi2Config { axis, cap_cos, seed: seed + 1000 * (1 + u64::from(reflection)), ..config.clone() };
            let r = chi2_test(
                &config,
                |u| bsdf.sample(wo, u[0], u[1], u[2]).map(|s| s.wi).filter(|&wi| same_side(wo, wi) == reflection),
                |wi| if same_side(wo, wi) == reflection { bsdf.pdf(wo, wi) } else { 0.0 },
            );
            FAMILY.check(&format!("{name} {lobe} cap {cap_cos:.4}"), &r);
        }
    }
}

#[test]
fn chi2_alpha_0_1_ior_1_33() {
    chi2_rough_dielectric(0.1, 1.33);
}

#[test]
fn chi2_alpha_0_1_ior_1_5() {
    chi2_rough_dielectric(0.1, 1.5);
}

#[test]
fn chi2_alpha_0_3_ior_1_33() {
    chi2_rough_dielectric(0.3, 1.33);
}

#[test]
fn chi2_alpha_0_3_ior_1_5() {
    chi2_rough_dielectric(0.3, 1.5);
}

#[test]
fn chi2_alpha_0_7_ior_1_33() {
    chi2_rough_dielectric(0.7, 1.33);
}

#[test]
fn chi2_alpha_0_7_ior_1_5() {
    chi2_rough_dielectric(0.7, 1.5);
}

// ---------------------------------------------------------------- weights

/// For random wo on the whole sphere, α, ior (also below 1) and u: the
/// sample's pdf is `pdf(wo, wi)` and its weight eval · |wi.z| / pdf, both to
/// 1e-9 relative; the weight is G2/G1 on reflection and G2/(G1 eta²) on
/// refraction; wi is a unit vector on the side its lobe says.
#[test]
fn sample_weights_are_f_cos_over_pdf() {
    let mut rng = Pcg32::new(17, 4);
    let (mut checked, mut refracted, mut worst_w, mut worst_p) = (0usize, 0usize, 0f64, 0f64);
    for alpha in [0.00101, 0.01, 0.1, 0.3, 0.7, 1.0] {
        for ior in [1.33, 1.5, 2.4, 0.8] {
            let bsdf = RoughDielectric { alpha, ior };
            for _ in 0..20_000 {
                let wo = sample_uniform_sphere(rng.next_f64(), rng.next_f64());
                let (u1, u2, u3) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
                let Some(s) = bsdf.sample(wo, u1, u2, u3) else { continue };
                let pdf = s.pdf.expect("not a delta lobe");
                assert!((s.wi.length() - 1.0).abs() < 1e-12 && s.wi.z != 0.0);
                let p = bsdf.pdf(wo, s.wi);
                let ep = (p - pdf).abs() / pdf;
                assert!(ep <= 1e-9, "alpha {alpha} ior {ior}: pdf {pdf} vs {p} for wo {wo}, wi {}", s.wi);
                let want = bsdf.eval(wo, s.wi) * s.wi.z.abs() / pdf;
                let ew = ((s.weight - want).abs() / want).max_element();
                assert!(ew <= 1e-9, "alpha {alpha} ior {ior}: weight {} vs {want} for wo {wo}, wi {}", s.weight, s.wi);
                let wo_up = DVec3::new(wo.x, wo.y, wo.z.abs());
                let g = ggx::g2(alpha, wo, s.wi) / ggx::g1(alpha, wo_up);
                let closed = if same_side(wo, s.wi) {
                    g
                } else {
                    refracted += 1;
                    g / eta_rel(ior, wo).powi(2)
                };
                assert!((s.weight.x - closed).abs() <= 1e-12 * closed);
                worst_w = worst_w.max(ew);
                worst_p = worst_p.max(ep);
                checked += 1;
            }
        }
    }
    println!(
        "weight = f |cos| / pdf: {checked} samples ({refracted} refracted), worst relative error: weight \
         {worst_w:.2e}, pdf {worst_p:.2e}"
    );
    assert!(refracted > checked / 4);
}

/// Scene materials: α = roughness² ≥ 1e-3 (and ior ≠ 1) gives the rough
/// dielectric, anything smoother the smooth one.
#[test]
fn materials_choose_smooth_or_rough() {
    let glass = |roughness: f32, ior: f32| Material {
        kind: MaterialKind::Dielectric { roughness, ior },
        ..Material::diffuse("glass", glam::Vec3::ONE)
    };
    assert_eq!(Bsdf::from_material(&glass(0.0, 1.5)), Bsdf::Dielectric(SmoothDielectric { ior: 1.5 }));
    assert_eq!(Bsdf::from_material(&glass(0.03, 1.5)), Bsdf::Dielectric(SmoothDielectric { ior: 1.5 }));
    assert!(matches!(Bsdf::from_material(&glass(1.0, 1.0)), Bsdf::Dielectric(_)));
    let Bsdf::RoughDielectric(b) = Bsdf::from_material(&glass(0.5, 1.33)) else { panic!("not rough") };
    assert!((b.alpha - 0.25).abs() < 1e-12 && (b.ior - 1.33).abs() < 1e-6);
    let rough = Bsdf::from_material(&glass(0.04, 1.5)); // α = 1.6e-3
    assert!(!rough.is_delta() && matches!(rough, Bsdf::RoughDielectric(_)));
    let s = rough.sample(DVec3::new(0.6, 0.0, 0.8), 0.3, 0.4, 0.9).unwrap();
    assert!(s.pdf.is_some() && s.wi.z < 0.0);
}

// ---------------------------------------------------------------- reciprocity

/// Reflection: f(wo, wi) = f(wi, wo). Refraction (radiance convention):
/// f(wo, wi)/n_wo² = f(wi, wo)/n_wi², n = 1 outside and ior inside.
#[test]
fn reciprocity() {
    let mut rng = Pcg32::new(23, 9);
    let (mut reflections, mut refractions, mut worst) = (0, 0, 0f64);
    for alpha in [0.05, 0.3, 1.0] {
        for ior in [1.33, 1.5, 0.8] {
            let bsdf = RoughDielectric { alpha, ior };
            for _ in 0..20_000 {
                let wo = sample_uniform_sphere(rng.next_f64(), rng.next_f64());
                let wi = sample_uniform_sphere(rng.next_f64(), rng.next_f64());
                let (a, b) = (bsdf.eval(wo, wi).x, bsdf.eval(wi, wo).x);
                let (a, b) = if same_side(wo, wi) {
                    reflections += usize::from(a > 0.0);
                    (a, b)
                } else {
                    refractions += usize::from(a > 0.0);
                    let n2 = |w: DVec3| if w.z > 0.0 { 1.0 } else { ior * ior };
                    (a / n2(wo), b / n2(wi))
                };
                assert_eq!(a > 0.0, b > 0.0, "support: {wo} {wi}");
                // Relative 1e-9, and absolute 1e-12: near a microfacet's
                // critical angle 1 − F has the cancellation of
                // √(1 − sin²θt) (relative 1e-6 seen at f ~ 1e-11).
                assert!((a - b).abs() <= 1e-9 * a.max(b) + 1e-12, "alpha {alpha} ior {ior}: {a} vs {b} for {wo}, {wi}");
                if a > 1e-6 {
                    worst = worst.max((a - b).abs() / a.max(b));
                }
            }
        }
    }
    println!(
        "reciprocity: {reflections} reflections, {refractions} refractions, worst relative error (f > 1e-6) {worst:.2e}"
    );
    assert!(reflections > 10_000 && refractions > 10_000);
}

// ---------------------------------------------------------------- energy

/// ∫ g dω over the sphere in polar coordinates about `axis`, with θ split at
/// `breaks` (ascending, from 0 to π).
fn integrate_about<G: Fn(DVec3) -> f64>(axis: DVec3, breaks: &[f64], g: &G, eps: f64) -> f64 {
    let (tu, tv) = frame_around(axis);
    let f = |theta: f64, phi: f64| {
        let d = theta.sin() * (phi.cos() * tu + phi.sin() * tv) + theta.cos() * axis;
        g(d) * theta.sin()
    };
    breaks.windows(2).map(|w| chi2::integrate_2d(&f, (w[0], w[1]), (0.0, TAU), eps, 4, 16)).sum()
}

/// Polar breakpoints for a lobe of width ~α about its axis.
fn lobe_breaks(alpha: f64) -> Vec<f64> {
    let mut b: Vec<f64> =
        [0.0, 0.5 * alpha, 2.0 * alpha, 6.0 * alpha, 1.0, PI].into_iter().filter(|&t| t <= PI).collect();
    b.sort_by(f64::total_cmp);
    b.dedup();
    if *b.last().unwrap() < PI {
        b.push(PI);
    }
    b
}

/// The flux albedo E = ∫ (f_r + eta² f_t) |cos θi| dωi (the 1/eta² radiance
/// scaling undone) for α from 1.01e-3 to 1, three ways: quadrature of the
/// sampler's expected flux weight over (u1, u2) (u3 summed exactly:
/// F w_r + (1 − F) eta² w_t, m and F from `ggx::sample_vndf`), Monte Carlo
/// with 10⁶ samples, and (α ≥ 0.1) quadrature of `eval` over wi about each
/// lobe's axis. E ≤ 1 + 1e-3, the three agree, and E → 1 as α → 0.
#[test]
fn white_furnace_flux_albedo() {
    let n = 1_000_000;
    println!("rough dielectric: flux albedo E(wo) = ∫ (f_r + eta² f_t) |cos θi| dωi (single scattering)");
    println!(
        "{:>8} {:>5} {:>7} {:>10} {:>10} {:>10} {:>9} {:>10} {:>10} {:>9}",
        "alpha", "ior", "wo", "E (quad u)", "E (quad w)", "E (MC)", "±1σ", "R (quad u)", "T (quad u)", "1 − E"
    );
    let mut worst_small = 0f64;
    for alpha in [0.00101, 0.01, 0.1, 0.3, 0.7, 1.0] {
        for ior in IORS {
            for (deg, inside) in VIEWS {
                let bsdf = RoughDielectric { alpha, ior };
                let wo = view(deg, inside);
                let eta = eta_rel(ior, wo);
                let wo_up = DVec3::new(wo.x, wo.y, wo.z.abs());
                // Expected flux weight over u3, split into reflection and refraction.
                let parts = |u1: f64, u2: f64| {
                    let m = ggx::sample_vndf(alpha, wo_up, u1, u2);
                    let f = fresnel_dielectric(wo_up.dot(m).max(0.0), eta);
                    let r = bsdf.sample(wo, u1, u2, 0.0).filter(|s| same_side(wo, s.wi)).map_or(0.0, |s| s.weight.x);
                    let t = bsdf
                        .sample(wo, u1, u2, 1.0 - f64::EPSILON)
                        .filter(|s| !same_side(wo, s.wi))
                        .map_or(0.0, |s| s.weight.x * eta * eta);
                    (f * r, (1.0 - f) * t)
                };
                let quad = |g: &dyn Fn(f64, f64) -> f64| chi2::integrate_2d(&g, (0.0, 1.0), (0.0, 1.0), 1e-7, 4, 14);
                let refl = quad(&|u1, u2| parts(u1, u2).0);
                let refr = quad(&|u1, u2| parts(u1, u2).1);
                let e_u = refl + refr;

                let mut rng = Pcg32::new(31, (alpha * 1e5) as u64 + (ior * 100.0) as u64 + deg as u64);
                let (mut sum, mut sum2) = (0.0, 0.0);
                for _ in 0..n {
                    if let Some(s) = bsdf.sample(wo, rng.next_f64(), rng.next_f64(), rng.next_f64()) {
                        let w = if same_side(wo, s.wi) { s.weight.x } else { s.weight.x * eta * eta };
                        sum += w;
                        sum2 += w * w;
                    }
                }
                let mc = sum / n as f64;
                let sigma = ((sum2 / n as f64 - mc * mc).max(0.0) / n as f64).sqrt();

                let e_w = (alpha >= 0.1).then(|| {
                    let breaks = lobe_breaks(alpha);
                    let flux = |wi: DVec3| {
                        let c = wi.z.abs() * bsdf.eval(wo, wi).x;
                        if same_side(wo, wi) {
                            c
                        } else {
                            c * eta * eta
                        }
                    };
                    let up = integrate_about(
                        reflect(wo),
                        &breaks,
                        &|wi| if same_side(wo, wi) { flux(wi) } else { 0.0 },
                        1e-8,
                    );
                    let t_axis = refract(wo, eta).unwrap_or(DVec3::new(0.0, 0.0, -wo.z.signum()));
                    let down =
                        integrate_about(t_axis, &breaks, &|wi| if same_side(wo, wi) { 0.0 } else { flux(wi) }, 1e-8);
                    up + down
                });
                println!(
                    "{alpha:>8} {ior:>5} {:>3} {deg:>2}° {e_u:>10.6} {:>10} {mc:>10.6} {sigma:>9.1e} {refl:>10.6} \
                     {refr:>10.6} {:>9.2e}",
                    if inside { "in" } else { "out" },
                    e_w.map_or("-".to_string(), |e| format!("{e:.6}")),
                    1.0 - e_u
                );
                assert!(e_u <= 1.0 + 1e-3 && mc <= 1.0 + 1e-3, "energy gain: {e_u} {mc}");
                assert!((mc - e_u).abs() <= 5.0 * sigma + 1e-4, "MC {mc} ± {sigma} vs quadrature {e_u}");
                if let Some(e_w) = e_w {
                    assert!((e_w - e_u).abs() < 1e-4, "quadrature over wi {e_w} vs over u {e_u}");
                }
                if alpha < 0.002 {
                    worst_small = worst_small.max(1.0 - e_u);
                }
            }
        }
    }
    println!("alpha = 0.00101: largest 1 − E = {worst_small:.2e}");
    assert!(worst_small < 1e-3, "the smooth limit loses energy: {worst_small}");
}

// ---------------------------------------------------------------- smooth limit

/// α = 1.01e-3 (just above the delta threshold): with the same u3 choosing
/// the lobe, the sampled directions are within 1e-2 of the smooth
/// dielectric's (reflection or refraction), and the weights near its 1 and
/// 1/eta². GGX has long tails (P(tan θm > t) ≈ α²/t² for t ≫ α), so this
/// holds for the bulk of the samples, not all: on a grid of u1 ≤ 0.9 (the
/// inner part of the visible-normal disc) every sample, and over random u at
/// least 95%.
#[test]
fn smooth_limit() {
    let alpha = 1.01e-3;
    let mut rng = Pcg32::new(41, 2);
    println!(
        "{:>5} {:>7} {:>10} {:>12} {:>12} {:>14}",
        "ior", "wo", "grid max", "random med.", "random 99%", "within 1e-2"
    );
    for ior in [1.33, 1.5] {
        let (rough, smooth) = (RoughDielectric { alpha, ior }, SmoothDielectric { ior });
        for (deg, inside) in VIEWS.into_iter().chain([(35.0, true), (89.0, false)]) {
            let wo = view(deg, inside);
            let f = fresnel_dielectric(wo.z, ior);
            // Lobe choices away from the Fresnel boundary, on a grid.
            let mut grid_max = 0f64;
            // (Under total internal reflection, f = 1, both choose reflection.)
            for u3 in [0.5 * f, (0.5 * (1.0 + f)).min(0.999)] {
                let want = smooth.sample(wo, 0.5, 0.5, u3).unwrap();
                for i in 0..=30 {
                    for j in 0..30 {
                        let (u1, u2) = (0.9 * i as f64 / 30.0, j as f64 / 30.0);
                        let Some(s) = rough.sample(wo, u1, u2, u3) else { continue };
                        assert_eq!(same_side(wo, s.wi), same_side(wo, want.wi), "{ior} {deg} {u1} {u2} {u3}");
                        grid_max = grid_max.max((s.wi - want.wi).length());
                        let ratio = s.weight.x / want.weight.x;
                        assert!(ratio <= 1.0 + 1e-12 && ratio > 0.99, "weight {} vs {}", s.weight.x, want.weight.x);
                    }
                }
            }
            assert!(grid_max < 1e-2, "ior {ior}, {deg}° inside {inside}: {grid_max}");
            let mut dev = Vec::new();
            for _ in 0..100_000 {
                let (u1, u2, u3) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
                let want = smooth.sample(wo, u1, u2, u3).unwrap();
                if let Some(s) = rough.sample(wo, u1, u2, u3) {
                    dev.push((s.wi - want.wi).length());
                }
            }
            dev.sort_by(f64::total_cmp);
            let within = dev.iter().filter(|&&d| d < 1e-2).count() as f64 / 100_000.0;
            println!(
                "{ior:>5} {:>3} {deg:>2}° {grid_max:>10.2e} {:>12.2e} {:>12.2e} {:>13.3}%",
                if inside { "in" } else { "out" },
                dev[dev.len() / 2],
                dev[dev.len() * 99 / 100],
                100.0 * within
            );
            assert!(within >= 0.95, "ior {ior}, {deg}°: only {within} within 1e-2");
        }
    }
}
