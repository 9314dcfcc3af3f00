//! Furnace tests of the path tracer: scenes whose every pixel has a known
//! value.
//!
//! - White furnace: diffuse objects of albedo 1 (non-convex ones among them)
//!   under a uniform environment of radiance 1 reflect exactly 1 everywhere,
//!   however many bounces a path takes.
//! - Closed furnace: inside a sphere whose wall emits E and reflects with
//!   albedo ρ, the radiance is E / (1 − ρ) everywhere (E = 0.5, ρ = 0.5: 1).
//!
//! Bounds, at the sample counts used: the image mean within `MEAN_TOLERANCE`
//! of the expected value (its standard error is printed: some 10x smaller);
//! every pixel within `PIXEL_TOLERANCE` (about 3 standard deviations of the
//! noisiest pixels, those deep in the dents of the bumpy sphere); and the mean
//! of every 4x4 block of pixels within `BLOCK_TOLERANCE`, so that a local bias
//! (energy lost at silhouettes or in creases) cannot hide in the noise. No
//! NaN or Inf.

use crate::common;

use glam::{DAffine3, DVec3, Vec3};
use quadray::model::geometry::{FunctionalObject, Quadric};
use quadray::model::scene::Material;
use quadray::passes::RenderOutput;

const MEAN_TOLERANCE: f64 = 0.005;
const PIXEL_TOLERANCE: f64 = 0.1;
const BLOCK_TOLERANCE: f64 = 0.03;

/// Checks every pixel against `expected`; prints the figures.
fn check_uniform(name: &str, out: &RenderOutput, expected: f64) {
    let common::UniformStats { mean, standard_error, worst } = common::UniformStats::of(out, expected);
    let (w, h) = (out.width as usize, out.height as usize);
    let mut worst_block: f64 = 0.0;
    for by in (0..h - h % 4).step_by(4) {
        for bx in (0..w - w % 4).step_by(4) {
            let mut sum = 0.0;
            for y in by..by + 4 {
                for x in bx..bx + 4 {
                    sum += out.radiance[y * w + x].iter().map(|&c| c as f64).sum::<f64>();
                }
            }
            worst_block = worst_block.max((sum / 48.0 - expected).abs());
        }
    }
    println!(
        "{name}: {w}x{h} at {} spp: mean {mean:.5} (expected {expected}, bound ±{MEAN_TOLERANCE}, standard error \
         {:.5}); worst pixel error {worst:.4} (bound {PIXEL_TOLERANCE}); worst 4x4 block error {worst_block:.4} \
         (bound {BLOCK_TOLERANCE})",
        out.spp, standard_error,
    );
    assert!((mean - expected).abs() <= MEAN_TOLERANCE, "{name}: mean {mean}");
    assert!(worst <= PIXEL_TOLERANCE, "{name}: worst pixel error {worst}");
    assert!(worst_block <= BLOCK_TOLERANCE, "{name}: worst block error {worst_block}");
}

#[test]
fn white_furnace_reflects_the_environment_exactly() {
    let mut scene = common::scene_with(common::test_objects());
    scene.materials = vec![Material::diffuse("white", Vec3::ONE)];
    scene.lights.clear();
    scene.background = Vec3::ONE;
    scene.image.width = 48;
    scene.image.height = 36;
    scene.image.spp = 512;
    scene.image.max_depth = 64;
    scene.camera.position = DVec3::new(0.0, 4.0, 9.0);
    check_uniform("white furnace", &common::render_validated(&scene), 1.0);
}

#[test]
fn closed_furnace_converges_to_emission_over_one_minus_albedo() {
    // The camera inside a sphere of radius 5 whose wall emits 0.5 and reflects 0.5.
    let wall = FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::splat(5.0)),
        perturbations: vec![],
        clip: None,
    };
    let mut scene = common::scene_with(vec![common::object("room", wall, DAffine3::IDENTITY)]);
    let mut m = Material::diffuse("wall", Vec3::splat(0.5));
    m.emission = Vec3::splat(0.5);
    scene.materials = vec![m];
    scene.lights.clear();
    scene.background = Vec3::ZERO;
    scene.camera.position = DVec3::new(0.0, 1.0, 2.0);
    scene.image.width = 32;
    scene.image.height = 24;
    scene.image.spp = 512;
    scene.image.max_depth = 64;
    check_uniform("closed furnace", &common::render_validated(&scene), 1.0);
}

/// Directional albedo E(cos θo) of a GGX conductor with F = 1 (single
/// scattering), by Monte Carlo over the CPU twin's visible-normal sampling:
/// E = mean of the sample weights G2/G1.
fn ggx_albedo(roughness: f64, cos_o: f64) -> f64 {
    use quadray::model::sampling::{Conductor, FresnelModel};
    let c = Conductor::new(roughness, FresnelModel::Schlick { f0: DVec3::ONE });
    let wo = DVec3::new((1.0 - cos_o * cos_o).max(0.0).sqrt(), 0.0, cos_o);
    let n = 200;
    let mut sum = 0.0;
    for i in 0..n {
        for j in 0..n {
            let (u1, u2) = ((i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64);
            if let Some(s) = c.sample(wo, u1, u2, 0.5) {
                sum += s.weight.x;
            }
        }
    }
    sum / (n * n) as f64
}

/// A sphere of GGX conductor with F = 1 under a uniform environment of
/// radiance 1: the sphere is convex, so every reflected ray escapes and a
/// pixel reads the directional albedo E(cos θo) of single-scattering GGX,
/// which loses energy at high roughness (no multiple scattering between
/// microfacets). The expected value per pixel comes from the pixel-centre
/// normal (AOV) and a CPU table of E; pixels whose footprint spans a wide
/// range of θo (the silhouette) are skipped.
#[test]
fn ggx_conductor_loses_only_the_single_scattering_energy() {
    use quadray::model::scene::{ConductorFresnel, MaterialKind};
    for roughness in [0.3f32, 0.7, 1.0] {
        let sphere =
            FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE), perturbations: vec![], clip: None };
        let mut scene = common::scene_with(vec![common::object("ball", sphere, DAffine3::IDENTITY)]);
        scene.materials = vec![Material {
            kind: MaterialKind::Conductor { roughness, fresnel: ConductorFresnel::Schlick { f0: Vec3::ONE } },
            ..Material::diffuse("white metal", Vec3::ONE)
        }];
        scene.lights.clear();
        scene.background = Vec3::ONE;
        common::aim(&mut scene, DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO);
        scene.camera.vfov_degrees = 32.0;
        common::set_image(&mut scene, (40, 40), 512, 8);
        let out = common::render_validated(&scene);
        let table: Vec<f64> = (0..=40).map(|k| ggx_albedo(roughness as f64, (k as f64 / 40.0).max(1e-3))).collect();
        let albedo_at = |c: f64| {
            let x = c.clamp(0.0, 1.0) * 40.0;
            let k = (x.floor() as usize).min(39);
            table[k] + (table[k + 1] - table[k]) * (x - k as f64)
        };
        let (mut errors, mut sum_got, mut sum_want) = (Vec::new(), 0.0, 0.0);
        for (i, a) in out.aov.iter().enumerate() {
            if !a.depth.is_finite() {
                continue;
            }
            let n = DVec3::new(a.normal[0] as f64, a.normal[1] as f64, a.normal[2] as f64);
            let view = (scene.camera.position - n).normalize(); // the hit point of a unit sphere is its normal
            let cos_o = n.dot(view);
            if cos_o < 0.3 {
                continue;
            }
            let want = albedo_at(cos_o);
            let got = out.radiance[i][0] as f64;
            errors.push((got - want) / want);
            sum_got += got;
            sum_want += want;
        }
        let n = errors.len() as f64;
        let bias = sum_got / sum_want - 1.0;
        let rms = (errors.iter().map(|e| e * e).sum::<f64>() / n).sqrt();
        println!(
            "GGX roughness {roughness}: E(1) = {:.4} (single scattering, lost {:.1}%), E(0.5) = {:.4}; {} pixels: \
             rendered/expected energy {:+.4} (bound ±0.01), per-pixel RMS {:.4} (bound 0.05)",
            table[40],
            100.0 * (1.0 - table[40]),
            albedo_at(0.5),
            errors.len(),
            bias,
            rms
        );
        assert!(errors.len() > 300);
        assert!(bias.abs() <= 0.01, "roughness {roughness}: energy {bias}");
        assert!(rms <= 0.05, "roughness {roughness}: RMS {rms}");
    }
}
