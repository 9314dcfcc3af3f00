//! Tests of the CPU sampling twins (`quadray::model::sampling`): chi-square tests of
//! every non-delta sampler against its density (Mitsuba-style, see
//! `sampling::chi2`), exact checks of the delta lobes, Fresnel identities, and
//! GGX normalisation and white-furnace albedo.
//!
//! Every chi-square test prints its χ², degrees of freedom and p-value
//! (`cargo test --test sampling -- sampling_chi2:: --nocapture`). A test fails when its
//! p-value is below the Šidák-corrected level for a family-wise level of 0.01
//! over the [`CHI2_TESTS`] tests of this file, or when ∫pdf dω differs from the
//! fraction of valid samples by more than 1e-2. The random numbers are seeded,
//! so the figures are reproducible.

use std::f64::consts::PI;

use glam::DVec3;
use quadray::model::sampling::chi2::{self, chi2_test, Chi2Config, Pcg32};
use quadray::model::sampling::*;

/// Chi-square tests run by this file (the Šidák correction divides the
/// family-wise level among them): cosine hemisphere 1, uniform sphere 1,
/// uniform cone 2, diffuse BSDF 1, GGX 4 α × 3 wo × (wi, m) = 24, sphere light
/// 2, rect light 2. (The two deliberately wrong tests are not counted: they must fail.)
const CHI2_TESTS: usize = 33;
/// The tests of this file, judged at a family-wise level of 1 %.
const FAMILY: chi2::Family = chi2::Family { alpha: 0.01, tests: CHI2_TESTS };

/// A random unit direction in the upper hemisphere (cos θ uniform in (0, 1]).
fn random_upper(rng: &mut Pcg32) -> DVec3 {
    let w = sample_uniform_sphere(0.5 * rng.next_f64(), rng.next_f64());
    if w.z > 0.0 {
        w
    } else {
        DVec3::Z
    }
}

// ---------------------------------------------------------------- warps

#[test]
fn chi2_cosine_hemisphere() {
    let r = chi2_test(&Chi2Config::default(), |u| Some(sample_cosine_hemisphere(u[0], u[1])), pdf_cosine_hemisphere);
    FAMILY.check("cosine hemisphere", &r);
}

#[test]
fn chi2_uniform_sphere() {
    let r = chi2_test(&Chi2Config::default(), |u| Some(sample_uniform_sphere(u[0], u[1])), |_| pdf_uniform_sphere());
    FAMILY.check("uniform sphere", &r);
}

#[test]
fn chi2_uniform_cone() {
    for cos_max in [0.3, 0.97] {
        // The cap ends at the cone's rim, so the rim is a cell boundary.
        let config = Chi2Config { cap_cos: cos_max, seed: 11 + (cos_max * 100.0) as u64, ..Chi2Config::default() };
        let r =
            chi2_test(&config, |u| Some(sample_uniform_cone(u[0], u[1], cos_max)), |w| pdf_uniform_cone(cos_max, w));
        FAMILY.check(&format!("uniform cone cos_max = {cos_max}"), &r);
    }
}

/// The harness must reject a wrong density: cosine-distributed samples
/// tested against the uniform-hemisphere density (same support, same mass).
#[test]
fn chi2_harness_rejects_a_wrong_pdf() {
    let config = Chi2Config { samples: 200_000, ..Chi2Config::default() };
    let r = chi2_test(&config, |u| Some(sample_cosine_hemisphere(u[0], u[1])), chi2::pdf_uniform_hemisphere);
    println!("{:<44} {r}", "WRONG pdf (cosine vs uniform hemisphere)");
    assert!(r.p_value < 1e-6, "the wrong pdf was not rejected: {r}");
    assert!((r.pdf_mass - 1.0).abs() < 1e-6 && r.valid_fraction == 1.0);
    assert!(!r.passed(FAMILY.level()));
}

/// The harness is sensitive: GGX reflections sampled with α 3% too large
/// (0.206 instead of 0.2) are rejected (p ~ 1e-69; a 2% error is rejected too).
#[test]
fn chi2_harness_detects_a_small_alpha_error() {
    let (alpha, wo) = (0.2, spherical_direction(45f64.to_radians(), 0.7));
    let wrong = Conductor { alpha: alpha * 1.03, fresnel: FresnelModel::Schlick { f0: DVec3::ONE } };
    let right = Conductor { alpha, fresnel: FresnelModel::Schlick { f0: DVec3::ONE } };
    let config = Chi2Config { axis: reflect(wo), cap_cos: 1.0 - 20.0 * alpha * alpha, ..Chi2Config::default() };
    let r = chi2_test(&config, |u| wrong.sample(wo, u[0], u[1], u[2]).map(|s| s.wi), |wi| right.pdf(wo, wi));
    println!("{:<44} {r}", "WRONG alpha (sampled 1.03 alpha)");
    assert!(r.p_value < 1e-6, "a 3% error in alpha was not detected: {r}");
}

// ---------------------------------------------------------------- BSDFs

#[test]
fn chi2_diffuse_bsdf() {
    let bsdf = Diffuse { albedo: DVec3::new(0.8, 0.5, 0.2) };
    let wo = spherical_direction(1.0, 2.0);
    let config = Chi2Config { seed: 21, ..Chi2Config::default() };
    let r = chi2_test(&config, |u| bsdf.sample(wo, u[0], u[1], u[2]).map(|s| s.wi), |wi| bsdf.pdf(wo, wi));
    FAMILY.check("diffuse BSDF", &r);
}

/// View directions of the GGX tests: at the normal (exercising the
/// lensq = 0 branch of the VNDF sampler), at 45° and at grazing 85°.
const GGX_VIEW_DEGREES: [f64; 3] = [0.0, 45.0, 85.0];

/// Chi-square tests of the GGX conductor: the reflected direction wi against
/// `Conductor::pdf`, and the visible normal m against `ggx::pdf_vndf`.
fn chi2_ggx(alpha: f64) {
    let conductor = Conductor { alpha, fresnel: FresnelModel::Schlick { f0: DVec3::ONE } };
    for (k, deg) in GGX_VIEW_DEGREES.into_iter().enumerate() {
        let wo = spherical_direction(deg.to_radians(), 0.7);
        let seed = (alpha * 1e4) as u64 * 10 + k as u64;
        // A cap centred on the mirror direction, sized to the lobe (~2α wide).
        let spread = 20.0 * alpha * alpha;
        let config = Chi2Config {
            axis: reflect(wo),
            cap_cos: if spread < 2.0 { 1.0 - spread } else { -1.0 },
            seed,
            ..Chi2Config::default()
        };
        let r =
            chi2_test(&config, |u| conductor.sample(wo, u[0], u[1], u[2]).map(|s| s.wi), |wi| conductor.pdf(wo, wi));
        FAMILY.check(&format!("GGX wi  alpha = {alpha:<4} theta_o = {deg:>2}°"), &r);

        let config =
            Chi2Config { cap_cos: (1.0 - 10.0 * alpha * alpha).max(0.0), seed: seed + 5, ..Chi2Config::default() };
        let r = chi2_test(&config, |u| Some(ggx::sample_vndf(alpha, wo, u[0], u[1])), |m| ggx::pdf_vndf(alpha, wo, m));
        FAMILY.check(&format!("GGX m   alpha = {alpha:<4} theta_o = {deg:>2}°"), &r);
    }
}

#[test]
fn chi2_ggx_alpha_0_05() {
    chi2_ggx(0.05);
}

#[test]
fn chi2_ggx_alpha_0_2() {
    chi2_ggx(0.2);
}

#[test]
fn chi2_ggx_alpha_0_5() {
    chi2_ggx(0.5);
}

#[test]
fn chi2_ggx_alpha_1() {
    chi2_ggx(1.0);
}

/// For random wo, u: the sample's weight is eval · cos θi / pdf and its pdf
/// is `pdf(wo, wi)`, to 1e-9 relative.
#[test]
fn sample_weights_are_f_cos_over_pdf() {
    let mut rng = Pcg32::new(7, 1);
    let fresnels = [
        FresnelModel::Schlick { f0: DVec3::new(0.95, 0.64, 0.54) },
        FresnelModel::Complex { eta: DVec3::new(0.2, 0.92, 1.1), k: DVec3::new(3.9, 2.45, 2.14) },
    ];
    let mut bsdfs: Vec<Bsdf> = vec![Bsdf::Diffuse(Diffuse { albedo: DVec3::new(0.7, 0.3, 0.1) })];
    for alpha in [0.0011, 0.01, 0.1, 0.4, 1.0] {
        for fresnel in fresnels {
            bsdfs.push(Bsdf::Conductor(Conductor { alpha, fresnel }));
        }
    }
    let mut checked = 0;
    let mut worst = 0.0f64;
    for bsdf in &bsdfs {
        for _ in 0..20_000 {
            let wo = random_upper(&mut rng);
            let (u1, u2, u3) = (rng.next_f64(), rng.next_f64(), rng.next_f64());
            let Some(s) = bsdf.sample(wo, u1, u2, u3) else { continue };
            let pdf = s.pdf.expect("non-delta lobe");
            assert!(s.wi.z > 0.0 && (s.wi.length() - 1.0).abs() < 1e-12);
            let p = bsdf.pdf(wo, s.wi);
            assert!((p - pdf).abs() <= 1e-9 * pdf, "{bsdf:?}: pdf {pdf} vs {p} for wo {wo}, wi {}", s.wi);
            let want = bsdf.eval(wo, s.wi) * s.wi.z / pdf;
            let err = ((s.weight - want).abs() / want.abs().max(DVec3::splat(1e-300))).max_element();
            worst = worst.max(err);
            assert!(err <= 1e-9, "{bsdf:?}: weight {} vs {want} for wo {wo}, wi {}", s.weight, s.wi);
            checked += 1;
        }
    }
    println!("weight = f cos / pdf: {checked} samples, worst relative error {worst:.2e}");
}

/// Delta lobes: conductor with α < 1e-3, mirror.
#[test]
fn delta_reflections_are_exact() {
    let fresnel = FresnelModel::Complex { eta: DVec3::new(0.2, 0.92, 1.1), k: DVec3::new(3.9, 2.45, 2.14) };
    let smooth = Conductor::new(0.03, fresnel); // α = 9e-4 < 1e-3
    assert!(smooth.is_delta());
    let mirror = Mirror { albedo: DVec3::new(0.9, 0.8, 0.7) };
    for (theta, phi) in [(0.0, 0.0), (0.4, 1.0), (1.5, -2.0)] {
        let wo = spherical_direction(theta, phi);
        let s = smooth.sample(wo, 0.3, 0.6, 0.9).unwrap();
        assert_eq!(s.wi, DVec3::new(-wo.x, -wo.y, wo.z));
        assert_eq!(s.weight, fresnel_conductor(wo.z, DVec3::new(0.2, 0.92, 1.1), DVec3::new(3.9, 2.45, 2.14)));
        assert_eq!(s.pdf, None);
        assert_eq!(smooth.eval(wo, s.wi), DVec3::ZERO);
        assert_eq!(smooth.pdf(wo, s.wi), 0.0);
        let m = mirror.sample(wo, 0.1, 0.2, 0.3).unwrap();
        assert_eq!((m.wi, m.weight, m.pdf), (s.wi, mirror.albedo, None));
        // Opaque lobes do not reflect from below.
        assert!(smooth.sample(-wo, 0.3, 0.6, 0.9).is_none() && mirror.sample(-wo, 0.1, 0.2, 0.3).is_none());
    }
}

/// Smooth dielectric: exact reflection and refraction directions from both
/// sides (Snell's law, the plane of incidence, the side).
#[test]
fn dielectric_directions_are_exact() {
    let ior = 1.5;
    let glass = SmoothDielectric { ior };
    for (theta, phi) in [(0.0, 0.0), (0.3, 0.5), (0.7, 2.0), (1.2, -1.0), (2.0, 0.2), (2.9, 3.0), (PI, 0.0)] {
        let wo = spherical_direction(theta, phi);
        let f = fresnel_dielectric(wo.z, ior);
        // u3 below F: reflection.
        if f > 0.0 {
            let r = glass.sample(wo, 0.5, 0.5, 0.0).unwrap();
            assert_eq!((r.wi, r.weight, r.pdf), (DVec3::new(-wo.x, -wo.y, wo.z), DVec3::ONE, None));
        }
        // u3 above F: refraction (unless total internal reflection).
        let t = glass.sample(wo, 0.5, 0.5, 0.999_999_999).unwrap();
        let eta_rel = if wo.z > 0.0 { ior } else { 1.0 / ior };
        let sin_i = (1.0 - wo.z * wo.z).max(0.0).sqrt();
        if sin_i / eta_rel >= 1.0 {
            assert_eq!(t.wi, DVec3::new(-wo.x, -wo.y, wo.z), "total internal reflection");
            continue;
        }
        assert!((t.wi.length() - 1.0).abs() < 1e-15);
        assert!(t.wi.z * wo.z < 0.0, "refraction crosses the surface");
        let sin_t = (1.0 - t.wi.z * t.wi.z).max(0.0).sqrt();
        assert!((eta_rel * sin_t - sin_i).abs() < 1e-14, "Snell: {eta_rel} {sin_t} {sin_i}");
        // In the plane of incidence, on the far side of the normal.
        assert!(wo.cross(t.wi).z.abs() < 1e-15 && wo.x * t.wi.x + wo.y * t.wi.y <= 0.0);
        assert_eq!(t.weight, DVec3::splat(1.0 / (eta_rel * eta_rel)));
        assert_eq!(t.pdf, None);
    }
    assert!(glass.sample(DVec3::X, 0.5, 0.5, 0.5).is_none(), "wo.z = 0 is degenerate");
}

/// Smooth dielectric: reflection is chosen with probability F, and what the
/// weights conserve. With eta_rel = n_t/n_i, refraction weighs 1/eta_rel², so
/// E[weight] = F + (1 − F)/eta_rel² (radiance is compressed entering the
/// denser medium: radiance / n² is the invariant); the power is conserved:
/// E[weight × (eta_rel² if refracted, 1 if reflected)] = F + (1 − F) = 1.
#[test]
fn dielectric_lobe_probabilities_and_energy() {
    let ior = 1.5;
    let glass = SmoothDielectric { ior };
    let n = 200_000;
    let mut rng = Pcg32::new(99, 3);
    println!(
        "{:>8} {:>8} {:>10} {:>10} {:>10} {:>10} {:>10}",
        "cos_o", "F", "P(refl)", "E[w]", "expected", "E[flux]", ""
    );
    for cos_o in [1.0f64, 0.7, 0.3, 0.05, -1.0, -0.9, -0.75, -0.5] {
        let wo = DVec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
        let f = fresnel_dielectric(cos_o, ior);
        let eta_rel = if cos_o > 0.0 { ior } else { 1.0 / ior };
        let (mut reflected, mut sum_w, mut sum_flux) = (0usize, 0.0, 0.0);
        for _ in 0..n {
            let s = glass.sample(wo, 0.5, 0.5, rng.next_f64()).unwrap();
            let w = s.weight.x;
            if s.wi.z * wo.z > 0.0 {
                reflected += 1;
                sum_flux += w;
            } else {
                sum_flux += w * eta_rel * eta_rel;
            }
            sum_w += w;
        }
        let p = reflected as f64 / n as f64;
        let sigma = (f * (1.0 - f) / n as f64).sqrt();
        let expected_w = f + (1.0 - f) / (eta_rel * eta_rel);
        let (mean_w, mean_flux) = (sum_w / n as f64, sum_flux / n as f64);
        println!("{cos_o:>8.3} {f:>8.5} {p:>10.5} {mean_w:>10.5} {expected_w:>10.5} {mean_flux:>10.6}");
        assert!((p - f).abs() <= 5.0 * sigma + 1e-12, "P(reflection) {p} vs F {f}");
        let w_sigma = sigma * (1.0 - 1.0 / (eta_rel * eta_rel)).abs();
        assert!((mean_w - expected_w).abs() <= 5.0 * w_sigma + 1e-12);
        assert!((mean_flux - 1.0).abs() < 1e-12, "flux is conserved sample by sample");
    }
}

// ---------------------------------------------------------------- Fresnel

#[test]
fn fresnel_conductor_without_absorption_is_dielectric() {
    let mut worst = 0.0f64;
    for eta in [1.0001, 1.33, 1.5, 2.42, 0.75, 1.0 / 1.5] {
        for i in 0..=1000 {
            let c = i as f64 / 1000.0;
            let d = fresnel_dielectric(c, eta);
            let k = fresnel_conductor(c, DVec3::splat(eta), DVec3::ZERO);
            worst = worst.max((k - DVec3::splat(d)).abs().max_element());
        }
    }
    println!("max |F_conductor(η, κ = 0) − F_dielectric(η)| = {worst:.2e}");
    assert!(worst < 1e-12);
}

#[test]
fn fresnel_schlick_endpoints() {
    let f0 = DVec3::new(0.04, 0.5, 0.95);
    assert_eq!(fresnel_schlick(1.0, f0), f0);
    assert_eq!(fresnel_schlick(0.0, f0), DVec3::ONE);
    let half = fresnel_schlick(0.5, f0);
    assert!((half - (f0 + (DVec3::ONE - f0) / 32.0)).abs().max_element() < 1e-15);
}

#[test]
fn fresnel_dielectric_total_internal_reflection() {
    let ior: f64 = 1.5;
    // From inside (cos_i < 0), the critical angle has sin θc = 1/ior.
    let cos_c = (1.0 - 1.0 / (ior * ior)).sqrt();
    for cos_i in [0.0, 0.3, 0.6, cos_c - 1e-9] {
        assert_eq!(fresnel_dielectric(-cos_i, ior), 1.0, "beyond the critical angle: cos {cos_i}");
    }
    for cos_i in [cos_c + 1e-6, 0.9, 1.0] {
        assert!(fresnel_dielectric(-cos_i, ior) < 1.0, "within the critical angle: cos {cos_i}");
    }
    // Inside at normal incidence equals outside; never TIR from outside.
    assert!((fresnel_dielectric(-1.0, ior) - 0.04).abs() < 1e-15);
    assert!((0..=100).all(|i| fresnel_dielectric(i as f64 / 100.0, ior) < 1.0 || i == 0));
    // Stokes relation across the interface: F(θi, n) = F(θt, 1/n).
    let cos_i: f64 = 0.6;
    let cos_t = (1.0 - (1.0 - cos_i * cos_i) / (ior * ior)).sqrt();
    assert!((fresnel_dielectric(cos_i, ior) - fresnel_dielectric(-cos_t, ior)).abs() < 1e-15);
}

// ---------------------------------------------------------------- GGX

#[test]
fn ggx_ndf_projected_area_is_one() {
    for alpha in [0.01, 0.05, 0.2, 0.5, 1.0] {
        let total = chi2::integrate_sphere(&|m| ggx::d(alpha, m) * m.z, 1e-9);
        println!("alpha = {alpha:<5} ∫ D(m) m.z dω = {total:.9}");
        assert!((total - 1.0).abs() < 1e-3, "alpha {alpha}: {total}");
    }
}

#[test]
fn ggx_visible_normals_are_normalised() {
    for alpha in [0.05, 0.2, 0.5, 1.0] {
        for deg in [0.0, 30.0, 60.0, 85.0, 89.0] {
            let wo = spherical_direction(f64::to_radians(deg), 0.3);
            let total = chi2::integrate_sphere(&|m| ggx::pdf_vndf(alpha, wo, m), 1e-9);
            println!("alpha = {alpha:<5} theta_o = {deg:>2}°  ∫ D_wo(m) dω = {total:.9}");
            assert!((total - 1.0).abs() < 1e-3, "alpha {alpha}, theta_o {deg}: {total}");
        }
    }
}

/// White-furnace directional albedo of the GGX conductor with F = 1:
/// E(wo) = ∫ f(wo, wi) cos θi dωi, the energy single-scattering GGX keeps
/// (the rest is lost to the multiple scattering it ignores). Three estimates:
/// Monte Carlo with 2·10⁶ VNDF samples (E = mean of the weights G2/G1, 0 for
/// rejected samples); quadrature over the microfacet normal,
/// E = ∫ D(m) G2(wo, wi) max(0, wo·m) / wo.z [wi.z > 0] dm, wi = 2(wo·m)m − wo
/// (dωi = 4 |wo·m| dm); and quadrature of `Conductor::eval` · cos θi over wi.
/// The two quadratures must agree to 1e-6 and Monte Carlo with them to 2e-3.
#[test]
fn ggx_white_furnace_albedo() {
    let n = 2_000_000;
    println!("GGX conductor, F = 1: directional albedo E(wo) = ∫ f cos dωi (single scattering)");
    println!(
        "{:>6} {:>9} {:>6} {:>12} {:>10} {:>12} {:>12} {:>10}",
        "alpha", "roughness", "wo.z", "E (MC)", "±1σ", "E (quad m)", "E (quad wi)", "1 − E"
    );
    for alpha in [0.1, 0.5, 1.0] {
        let conductor = Conductor { alpha, fresnel: FresnelModel::Schlick { f0: DVec3::ONE } };
        for cos_o in [1.0f64, 0.5, 0.1] {
            let wo = DVec3::new((1.0 - cos_o * cos_o).sqrt(), 0.0, cos_o);
            let mut rng = Pcg32::new(1234, (alpha * 100.0) as u64 + (cos_o * 10.0) as u64);
            let (mut sum, mut sum2) = (0.0, 0.0);
            for _ in 0..n {
                let (u1, u2) = (rng.next_f64(), rng.next_f64());
                if let Some(s) = conductor.sample(wo, u1, u2, 0.0) {
                    sum += s.weight.x;
                    sum2 += s.weight.x * s.weight.x;
                }
            }
            let mc = sum / n as f64;
            let sigma = ((sum2 / n as f64 - mc * mc) / n as f64).sqrt();
            let integrand = |mu: f64, phi: f64| {
                let s = (1.0 - mu * mu).max(0.0).sqrt();
                let m = DVec3::new(s * phi.cos(), s * phi.sin(), mu);
                let om = wo.dot(m);
                if om <= 0.0 {
                    return 0.0;
                }
                let wi = 2.0 * om * m - wo;
                if wi.z <= 0.0 {
                    return 0.0;
                }
                ggx::d(alpha, m) * ggx::g2(alpha, wo, wi) * om / wo.z
            };
            let quad = chi2::integrate_2d(&integrand, (0.0, 1.0), (0.0, 2.0 * PI), 1e-8, 4, 18);
            let quad_wi = chi2::integrate_sphere(&|wi: DVec3| conductor.eval(wo, wi).x * wi.z.max(0.0), 1e-8);
            println!(
                "{alpha:>6.2} {:>9.4} {cos_o:>6.2} {mc:>12.6} {sigma:>10.1e} {quad:>12.6} {quad_wi:>12.6} {:>10.6}",
                alpha.sqrt(),
                1.0 - quad
            );
            assert!(quad <= 1.0 + 1e-9 && mc <= 1.0, "energy gain");
            assert!((quad - quad_wi).abs() < 1e-6, "quadrature over m {quad} vs over wi {quad_wi}");
            if alpha == 1.0 && cos_o == 1.0 {
                // Closed form: with α = 1, D = 1/π and G2 = 2 cos θi / (1 + cos θi)
                // at normal view, E = 4 ∫ (μ − 1/(2μ)) dμ over μ = m.z ∈ [1/√2, 1] = 1 − ln 2.
                assert!((quad - (1.0 - 2f64.ln())).abs() < 1e-7, "{quad} vs 1 − ln 2");
            }
            assert!((mc - quad).abs() < 2e-3, "MC {mc} vs quadrature {quad}");
        }
    }
}

// ---------------------------------------------------------------- lights

#[test]
fn chi2_sphere_light() {
    let x = DVec3::new(0.3, -0.2, 0.1);
    for (k, (centre, radius)) in
        [(DVec3::new(1.0, 2.0, 3.0), 0.5), (DVec3::new(0.3, 1.0, 0.6), 1.2)].into_iter().enumerate()
    {
        let to_c = centre - x;
        let cos_max = (1.0 - radius * radius / to_c.length_squared()).sqrt();
        let config =
            Chi2Config { axis: to_c.normalize(), cap_cos: cos_max, seed: 300 + k as u64, ..Chi2Config::default() };
        let r = chi2_test(
            &config,
            |u| sample_sphere_light(x, centre, radius, DVec3::ONE, u[0], u[1]).map(|s| s.wi),
            |wi| pdf_sphere_light(x, centre, radius, wi),
        );
        FAMILY.check(&format!("sphere light cos_max = {cos_max:.4}"), &r);
    }
}

#[test]
fn chi2_rect_light() {
    let corner = DVec3::new(-1.0, 2.0, -0.5);
    let (eu, ev) = (DVec3::new(2.0, 0.3, 0.2), DVec3::new(0.1, 0.2, 1.5));
    let n = eu.cross(ev).normalize();
    let centre = corner + 0.5 * (eu + ev);
    // In front of the light: far and oblique, then close (a wide solid angle).
    for (k, x) in [centre + 4.0 * n + DVec3::new(2.0, 0.0, -1.0), centre + 0.3 * n + 0.2 * eu].into_iter().enumerate() {
        assert!((x - centre).dot(n) > 0.0);
        let axis = (centre - x).normalize();
        let corners = [corner, corner + eu, corner + ev, corner + eu + ev];
        let cap = corners.iter().map(|&c| (c - x).normalize().dot(axis)).fold(1.0, f64::min) - 0.02;
        let config = Chi2Config { axis, cap_cos: cap.max(-1.0), seed: 400 + k as u64, ..Chi2Config::default() };
        let r = chi2_test(
            &config,
            |u| sample_rect_light(x, corner, eu, ev, DVec3::ONE, u[0], u[1]).map(|s| s.wi),
            |wi| pdf_rect_light(x, corner, eu, ev, wi),
        );
        FAMILY.check(&format!("rect light (distance {:.2})", (x - centre).length()), &r);
    }
}

#[test]
fn delta_and_environment_lights() {
    let d = sample_directional_light(DVec3::new(1.0, 2.0, 2.0), DVec3::splat(3.0));
    assert!((d.wi - DVec3::new(1.0, 2.0, 2.0) / 3.0).length() < 1e-15);
    assert_eq!((d.dist, d.emitted, d.pdf), (f64::INFINITY, DVec3::splat(3.0), None));
    let p = sample_point_light(DVec3::ZERO, DVec3::new(0.0, 0.0, 2.0), DVec3::splat(8.0)).unwrap();
    assert_eq!((p.wi, p.dist, p.emitted, p.pdf), (DVec3::Z, 2.0, DVec3::splat(2.0), None));
    let e = sample_uniform_environment(DVec3::ONE, 0.25, 0.5);
    assert_eq!(e.pdf, Some(1.0 / (4.0 * PI)));
    assert_eq!(pdf_uniform_environment(), 1.0 / (4.0 * PI));
    assert!((e.wi - DVec3::new(-(0.75f64).sqrt(), 0.0, 0.5)).length() < 1e-15);
    // A Lambertian surface under a uniform environment of radiance L
    // reflects albedo · L: Σ f L cos / pdf over environment samples.
    let (albedo, mut rng, n) = (0.6, Pcg32::new(5, 5), 400_000);
    let wo = spherical_direction(0.5, 0.0);
    let bsdf = Diffuse { albedo: DVec3::splat(albedo) };
    let mut sum = 0.0;
    for _ in 0..n {
        let s = sample_uniform_environment(DVec3::ONE, rng.next_f64(), rng.next_f64());
        sum += bsdf.eval(wo, s.wi).x * s.wi.z.max(0.0) / s.pdf.unwrap();
    }
    let mean = sum / n as f64;
    assert!((mean - albedo).abs() < 5e-3, "{mean}");
    // MIS weights of two strategies sum to 1.
    for (a, b) in [(0.3, 2.0), (1e-3, 1e3), (5.0, 5.0)] {
        assert!((power_heuristic(a, b) + power_heuristic(b, a) - 1.0).abs() < 1e-15);
    }
}
