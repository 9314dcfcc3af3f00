//! Texture filtering over ray-cone and covariance footprints (EWA lookups,
//! `--filter ray-cones` and `--filter covariance`; the latter seen through
//! the albedo-only shading variant at the first hit) against the analytic
//! average of a checkerboard: a floor with
//! a fine checker (512 x 512 cells of two colours), seen from far enough that
//! each pixel covers several cells. The albedo AOV (the colour map looked up
//! over the pixel-centre ray's footprint) must be the checker's average
//! (a + b) / 2 within `AVERAGE_TOLERANCE` of the contrast |a - b| at every
//! pixel whose footprint covers at least `MIN_CELLS` cells; without
//! filtering (`none`, one bilinear lookup) the same pixels alias: they read
//! the colour of whatever cell the ray hits.

use crate::common;

use glam::{DAffine3, DVec2, DVec3, Vec3};
use quadray::model::geometry::{Aabb, FunctionalObject, Quadric};
use quadray::model::scene::{FilterMode, ImageSettings, Material, MaterialMaps, Scene, UvMapping, UvSettings};
use quadray::passes::{RenderVariant, ShadingMode};

const A: f32 = 0.9;
const B: f32 = 0.1;
const CELLS: u32 = 512;
const AVERAGE_TOLERANCE: f64 = 0.05;
const MIN_CELLS: f64 = 4.0;

#[test]
fn ewa_over_ray_cones_averages_a_fine_checkerboard() {
    let floor = FunctionalObject {
        base: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
        perturbations: vec![],
        clip: Some(Aabb::new(DVec3::new(-8.0, -0.5, -8.0), DVec3::new(8.0, 0.5, 8.0))),
    };
    let mut objects = vec![common::object("floor", floor, DAffine3::IDENTITY)];
    objects[0].uv = UvSettings {
        mapping: UvMapping::Planar { u_axis: DVec3::X, v_axis: DVec3::Z },
        scale: DVec2::splat(1.0 / 16.0),
        offset: DVec2::splat(0.5),
    };
    let mut scene = common::scene_with(objects);
    let mut m = Material::diffuse("checker", Vec3::ONE);
    m.maps = MaterialMaps { albedo: Some(0), ..Default::default() };
    scene.materials = vec![m];
    scene.textures = vec![quadray::model::texture::checker(1024, CELLS, [A; 3], [B; 3])];
    scene.camera.position = DVec3::new(0.0, 9.0, 9.0);
    scene.camera.look_at = DVec3::ZERO;
    scene.camera.vfov_degrees = 40.0;
    scene.image.width = 64;
    scene.image.height = 48;

    let ctx = common::context();
    let counters = ctx.counters();
    let render = |filter| {
        let s = Scene { image: ImageSettings { filter, ..scene.image.clone() }, ..scene.clone() };
        common::finite(quadray::render_scene(&ctx, &s, &mut |_, _| {}).unwrap())
    };
    let (filtered, unfiltered) = (render(FilterMode::RayCones), render(FilterMode::None));
    // The covariance mode's footprint at the first hit, through the radiance
    // of the albedo-only shading variant.
    let covariance = {
        let s =
            Scene { image: ImageSettings { filter: FilterMode::Covariance, ..scene.image.clone() }, ..scene.clone() };
        let variant = RenderVariant { shading: ShadingMode::Albedo, ..Default::default() };
        common::finite(quadray::render_scene_with(&ctx, &s, variant, &mut |_, _| {}).unwrap())
    };
    drop(ctx);
    common::assert_no_validation_errors(&counters);

    let average = 0.5 * (A + B) as f64;
    let contrast = (A - B) as f64;
    let cell = 16.0 / CELLS as f64;
    let pixel_angle = 2.0 * (20f64).to_radians().tan() / 48.0;
    let (mut count, mut worst_filtered, mut spread_unfiltered, mut worst_covariance) = (0, 0.0f64, 0.0f64, 0.0f64);
    for (i, (f, u)) in filtered.aov.iter().zip(&unfiltered.aov).enumerate() {
        if !f.depth.is_finite() {
            continue;
        }
        // Footprint across the ray, in cells (the smaller extent).
        if pixel_angle * f.depth as f64 / cell < MIN_CELLS {
            continue;
        }
        count += 1;
        worst_filtered = worst_filtered.max((f.albedo[0] as f64 - average).abs() / contrast);
        // The radiance comes from a jittered ray, which may miss past the
        // floor's edge where the pixel centre hits it: skip those.
        let c = covariance.radiance[i][0] as f64;
        if c > 0.0 {
            worst_covariance = worst_covariance.max((c - average).abs() / contrast);
        }
        spread_unfiltered = spread_unfiltered.max((u.albedo[0] as f64 - average).abs() / contrast);
    }
    println!(
        "{count} pixels covering >= {MIN_CELLS} cells: ray-cone albedo within {worst_filtered:.4} of the average, \
         covariance within {worst_covariance:.4} (bound {AVERAGE_TOLERANCE}, in units of the contrast); unfiltered \
         up to {spread_unfiltered:.4}"
    );
    assert!(worst_covariance <= AVERAGE_TOLERANCE, "covariance footprints do not average the checker");
    assert!(count > 1000, "too few pixels");
    assert!(worst_filtered <= AVERAGE_TOLERANCE, "filtered lookups do not average the checker");
    assert!(spread_unfiltered > 0.3, "the unfiltered reference should alias here");
}

/// Relative difference allowed between FLIP(covariance, none) and
/// FLIP(none, none) over independent renders at equal spp: both are the
/// noise of two 16-spp images, which varies by a few percent between seeds.
const NO_BIAS_TOLERANCE: f64 = 0.1;

/// `covariance` (and `ray-cones`) on a scene without textures: no NaN or Inf,
/// and no bias: against an independent `none` render at equal spp, their
/// FLIP is that of another independent `none` render, within
/// `NO_BIAS_TOLERANCE`.
#[test]
fn filtering_adds_no_bias_without_textures() {
    let mut scene = common::project_scene("materials.toml");
    assert!(scene.textures.is_empty(), "the test needs a scene without textures");
    scene.image.width = 96;
    scene.image.height = 72;
    scene.image.spp = 16;
    let exposure = scene.image.exposure;

    let ctx = common::context();
    let counters = ctx.counters();
    let render = |filter: FilterMode, seed: u32| {
        let mut s = scene.clone();
        s.image.seed = seed;
        s.image.filter = filter;
        let out = common::finite(quadray::render_scene(&ctx, &s, &mut |_, _| {}).unwrap());
        assert!(out.radiance.iter().flatten().all(|v| v.is_finite()), "non-finite pixel (filter {filter})");
        out
    };
    let base = render(FilterMode::None, 1);
    let none = render(FilterMode::None, 2);
    let cones = render(FilterMode::RayCones, 3);
    let cov = render(FilterMode::Covariance, 4);
    drop(ctx);
    common::assert_no_validation_errors(&counters);

    let flip = |o| quadray::tools::metrics::flip_mean(&base, o, exposure).unwrap();
    let (noise, f_cones, f_cov) = (flip(&none), flip(&cones), flip(&cov));
    println!(
        "FLIP against an independent none render (16 spp): none {noise:.4}, ray-cones {f_cones:.4}, covariance {f_cov:.4} (allowed ±{:.0}% of none's)",
        100.0 * NO_BIAS_TOLERANCE
    );
    for (name, f) in [("ray-cones", f_cones), ("covariance", f_cov)] {
        assert!((f - noise).abs() <= NO_BIAS_TOLERANCE * noise, "{name}: FLIP {f} vs none's {noise}");
    }
}

/// RMS error allowed, in units of the checker's contrast, of a 1-spp
/// filtered render of a checker seen in a convex mirror against the
/// 1024-spp unfiltered pixel average. Measured: 0.111 for both filtered
/// modes, 0.158 with the curvature term switched off (the mirror's exact
/// curvature widens footprints), 0.22 unfiltered. Not 0: a 1-spp sample's
/// footprint is centred on its jittered position in the pixel, so near the
/// cell edges that the mirror shows large, single samples still differ from
/// the pixel's box average.
const MIRROR_RMS_TOLERANCE: f64 = 0.13;
/// The mirror ball's radius and the checker cells over the 16-unit floor.
const MIRROR_RADIUS: f64 = 0.4;
const MIRROR_CELLS: u32 = 64;
/// Samples per pixel of the mirror test's reference.
const MIRROR_REFERENCE_SPP: u32 = 1024;

/// A checker floor seen in a convex mirror ball: through the
/// curved mirror each pixel covers a wide patch of the floor (the curvature
/// term multiplies the footprint), which 1-spp unfiltered lookups alias and
/// filtered ones must average. Shading variant ShadingMode::MirroredAlbedo (the
/// albedo seen through mirrors, no lighting), so that the reference with
/// many samples is the exact pixel average. Compared over the pixels whose
/// four corners all see the ball. With `QUADRAY_TEST_IMAGES=DIR` the
/// reference and the three 1-spp renders are written to DIR as PNGs.
#[test]
fn footprints_through_a_curved_mirror_average_the_reflected_checker() {
    let floor = FunctionalObject {
        base: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
        perturbations: vec![],
        clip: Some(Aabb::new(DVec3::new(-8.0, -0.5, -8.0), DVec3::new(8.0, 0.5, 8.0))),
    };
    let ball =
        FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE), perturbations: vec![], clip: None };
    let centre = DVec3::new(0.0, 1.2, 0.0);
    let mut objects = vec![
        common::object("floor", floor, DAffine3::IDENTITY),
        common::object("ball", ball, DAffine3::from_translation(centre)),
    ];
    objects[0].uv = UvSettings {
        mapping: UvMapping::Planar { u_axis: DVec3::X, v_axis: DVec3::Z },
        scale: DVec2::splat(1.0 / 16.0),
        offset: DVec2::splat(0.5),
    };
    objects[1].material = 1;
    let mut scene = common::scene_with(objects);
    let mut m = Material::diffuse("checker", Vec3::ONE);
    m.maps = MaterialMaps { albedo: Some(0), ..Default::default() };
    scene.materials = vec![
        m,
        Material { kind: quadray::model::scene::MaterialKind::Mirror, ..Material::diffuse("mirror", Vec3::ONE) },
    ];
    scene.textures = vec![quadray::model::texture::checker(1024, MIRROR_CELLS, [A; 3], [B; 3])];
    scene.camera.position = centre + DVec3::new(0.0, -0.1, 1.6);
    scene.camera.look_at = centre;
    scene.camera.vfov_degrees = 30.0;
    scene.image.width = 96;
    scene.image.height = 72;
    scene.image.max_depth = 4;
    // The sky is the checker's average, so that the floor's far edge, which
    // no texture filter antialiases, shows no contrast once filtered.
    scene.background = Vec3::splat(0.5 * (A + B));

    let ctx = common::context();
    let counters = ctx.counters();
    let render = |filter, spp| {
        let mut s = scene.clone();
        s.image.spp = spp;
        s.image.filter = filter;
        let variant = RenderVariant { shading: ShadingMode::MirroredAlbedo, ..Default::default() };
        common::finite(quadray::render_scene_with(&ctx, &s, variant, &mut |_, _| {}).unwrap())
    };
    let reference = render(FilterMode::None, MIRROR_REFERENCE_SPP);
    let modes = [
        ("none", render(FilterMode::None, 1)),
        ("ray-cones", render(FilterMode::RayCones, 1)),
        ("covariance", render(FilterMode::Covariance, 1)),
    ];
    drop(ctx);
    common::assert_no_validation_errors(&counters);

    // Pixels whose four corners' rays hit the ball.
    let [eye, forward, right, up] = quadray::passes::scene_gpu::camera_basis(&scene, 96, 72);
    let hits_ball = |x: f64, y: f64| {
        let d = (forward + (2.0 * x / 96.0 - 1.0) * right + (1.0 - 2.0 * y / 72.0) * up).normalize();
        let oc = eye - centre;
        let b = oc.dot(d);
        b * b - (oc.length_squared() - MIRROR_RADIUS * MIRROR_RADIUS) > 0.0
    };
    let inside: Vec<usize> = (0..96 * 72)
        .filter(|&i| {
            let (x, y) = ((i % 96) as f64, (i / 96) as f64);
            hits_ball(x, y) && hits_ball(x + 1.0, y) && hits_ball(x, y + 1.0) && hits_ball(x + 1.0, y + 1.0)
        })
        .collect();
    let contrast = (A - B) as f64;
    if let Ok(dir) = std::env::var("QUADRAY_TEST_IMAGES") {
        quadray::jobs::output::write_png(&reference, 0.0, &std::path::Path::new(&dir).join("mirror-reference.png"))
            .unwrap();
        for (name, out) in &modes {
            quadray::jobs::output::write_png(out, 0.0, &std::path::Path::new(&dir).join(format!("mirror-{name}.png")))
                .unwrap();
        }
    }
    let mut errors = Vec::new();
    for (name, out) in &modes {
        let sum: f64 =
            inside.iter().map(|&i| ((out.radiance[i][0] - reference.radiance[i][0]) as f64 / contrast).powi(2)).sum();
        let rms = (sum / inside.len() as f64).sqrt();
        println!(
            "{} mirror pixels, 1 spp against {MIRROR_REFERENCE_SPP} spp: {name:>10} RMS error {rms:.4} of the contrast",
            inside.len()
        );
        errors.push(rms);
    }
    let max_mode_difference = inside
        .iter()
        .map(|&i| (modes[1].1.radiance[i][0] - modes[2].1.radiance[i][0]).abs() as f64 / contrast)
        .fold(0.0, f64::max);
    println!("largest difference between the ray-cone and covariance renders there: {max_mode_difference:.4}");
    assert!(inside.len() > 1000, "too few mirror pixels");
    assert!(errors[0] > 0.2, "the unfiltered 1-spp render should alias in the mirror");
    assert!(errors[1] <= MIRROR_RMS_TOLERANCE, "ray cones through the mirror: {}", errors[1]);
    assert!(errors[2] <= MIRROR_RMS_TOLERANCE, "covariance through the mirror: {}", errors[2]);
}

/// Samples per pixel of each half of the glossy test's reference.
const GLOSSY_REFERENCE_HALF_SPP: u32 = 2048;
/// Independent 16-spp renders averaged per filtered mode in the glossy test.
const GLOSSY_SEEDS: u32 = 16;
/// Standard deviations of the test statistic allowed above its expectation.
const GLOSSY_Z: f64 = 5.0;
/// Each 4x more samples must at least halve the filtered error (an unbiased
/// estimate's error falls 4x; a plateau keeps it).
const GLOSSY_FALL: f64 = 0.5;

/// The prefiltering bias is gone: albedo-only (the albedo seen directly and
/// through a glossy reflector, `ShadingMode::GlossyAlbedo`) on a fine checker
/// wall and a glossy floor (scenes/tests/glossy_reflector.toml). For each
/// filtered mode, the mean of `GLOSSY_SEEDS` independent 16-spp renders
/// equals the unfiltered 4096-spp reference within their noise: the sum over
/// pixels and channels of (mean − reference)² over the sum of its expected
/// value with no bias (the mean's variance, from the seeds, plus the
/// reference's, from its two halves) is at most 1 + `GLOSSY_Z` standard
/// deviations of that ratio. And its relative MSE (the reference's variance
/// subtracted) keeps falling from 16 to 64 to 256 spp, by at least
/// `GLOSSY_FALL` each time.
#[test]
fn filtered_albedo_through_a_glossy_reflector_converges_to_the_reference() {
    let scene = common::project_scene("tests/glossy_reflector.toml");
    let ctx = common::context();
    let counters = ctx.counters();
    let render = |filter: FilterMode, spp: u32, seed: u32| -> Vec<f64> {
        let mut s = scene.clone();
        s.image.spp = spp;
        s.image.seed = seed;
        s.image.filter = filter;
        let variant = RenderVariant { shading: ShadingMode::GlossyAlbedo, ..Default::default() };
        let out = common::finite(quadray::render_scene_with(&ctx, &s, variant, &mut |_, _| {}).unwrap());
        out.radiance.iter().flatten().map(|&v| f64::from(v)).collect()
    };
    let (a, b) = (
        render(FilterMode::None, GLOSSY_REFERENCE_HALF_SPP, 1001),
        render(FilterMode::None, GLOSSY_REFERENCE_HALF_SPP, 1002),
    );
    let reference: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 0.5 * (x + y)).collect();
    let reference_variance: Vec<f64> = a.iter().zip(&b).map(|(x, y)| 0.25 * (x - y).powi(2)).collect();
    let relative_error = |img: &[f64]| -> f64 {
        let sum: f64 = img
            .iter()
            .zip(&reference)
            .zip(&reference_variance)
            .map(|((t, r), v)| ((t - r).powi(2) - v) / (r * r + quadray::tools::metrics::RELATIVE_MSE_EPSILON))
            .sum();
        sum / img.len() as f64
    };
    let mut results = Vec::new();
    for (name, filter) in [("ray-cones", FilterMode::RayCones), ("covariance", FilterMode::Covariance)] {
        let renders: Vec<Vec<f64>> = (0..GLOSSY_SEEDS).map(|k| render(filter, 16, 10 + k)).collect();
        let k = f64::from(GLOSSY_SEEDS);
        let (mut d2, mut expected, mut expected_sq) = (0.0, 0.0, 0.0);
        for i in 0..reference.len() {
            let mean = renders.iter().map(|r| r[i]).sum::<f64>() / k;
            let var = renders.iter().map(|r| (r[i] - mean).powi(2)).sum::<f64>() / (k - 1.0);
            let e = var / k + reference_variance[i];
            d2 += (mean - reference[i]).powi(2);
            expected += e;
            expected_sq += e * e;
        }
        let ratio = d2 / expected;
        // For Gaussian noise (mean − ref)² has variance 2e²: the ratio's σ.
        let sigma = (2.0 * expected_sq).sqrt() / expected;
        let errors: Vec<f64> =
            [16, 64, 256].iter().map(|&spp| relative_error(&render(filter, spp, 500 + spp))).collect();
        println!(
            "{name}: squared bias of the {GLOSSY_SEEDS}-seed mean over its expected noise {ratio:.3} (allowed 1 + \
             {GLOSSY_Z} x {sigma:.3}); relative MSE at 16, 64, 256 spp: {:.2e}, {:.2e}, {:.2e}",
            errors[0], errors[1], errors[2]
        );
        results.push((name, ratio, sigma, errors));
    }
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    for (name, ratio, sigma, errors) in results {
        assert!(ratio <= 1.0 + GLOSSY_Z * sigma, "{name}: the filtered mean is biased ({ratio:.3})");
        assert!(errors[1] <= GLOSSY_FALL * errors[0], "{name}: the error stalls from 16 to 64 spp: {errors:?}");
        assert!(errors[2] <= GLOSSY_FALL * errors[1], "{name}: the error stalls from 64 to 256 spp: {errors:?}");
    }
}
