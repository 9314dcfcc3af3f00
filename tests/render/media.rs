//! Participating media in the path tracer against closed forms:
//!
//! - Absorbing fog (albedo 0) between the camera and an emitter: each pixel
//!   sees the emitter's radiance times the transmittance exp(−σ_t d) along
//!   its ray (Beer–Lambert), d from the analytic ray–wall distance.
//! - A furnace of lights: inside a closed box whose six walls are rect
//!   lights of radiance 1, filled with non-absorbing fog (albedo 1,
//!   anisotropic) around a white diffuse ball, the radiance is 1 everywhere,
//!   however often a path scatters: it tests distance sampling, the phase
//!   function's sampling and next-event estimation through the medium, and
//!   their multiple importance sampling.

use crate::common;

use glam::{DAffine3, DVec3, Vec3};
use quadray::model::geometry::{FunctionalObject, Quadric};
use quadray::model::scene::{Light, Material, Medium};

/// Image mean within this of the expected mean.
const MEAN_TOLERANCE: f64 = 0.005;
/// Every pixel within this (about 4 standard deviations at the spp used).
const PIXEL_TOLERANCE: f64 = 0.15;

/// Six inward-facing rect lights of `radiance` on the cube [−h, h]³.
fn light_box(h: f64, radiance: f32) -> Vec<Light> {
    let (x, y, z) = (DVec3::X * 2.0 * h, DVec3::Y * 2.0 * h, DVec3::Z * 2.0 * h);
    let lo = DVec3::splat(-h);
    let rect = |corner: DVec3, edge_u: DVec3, edge_v: DVec3| Light::Rect {
        corner,
        edge_u,
        edge_v,
        radiance: Vec3::splat(radiance),
    };
    vec![
        rect(lo, y, z),     // x = −h, toward +x
        rect(lo + x, z, y), // x = +h, toward −x
        rect(lo, z, x),     // y = −h, toward +y
        rect(lo + y, x, z), // y = +h, toward −y
        rect(lo, x, y),     // z = −h, toward +z
        rect(lo + z, y, x), // z = +h, toward −z
    ]
}

fn ball(radius: f64, at: DVec3) -> quadray::model::scene::SceneObject {
    let shape = FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::splat(radius)),
        perturbations: vec![],
        clip: None,
    };
    common::object("ball", shape, DAffine3::from_translation(at))
}

#[test]
fn absorbing_fog_transmits_beer_lambert() {
    let h = 2.0;
    let density = 0.6f32;
    // The ball sits behind the camera, out of view.
    let mut scene = common::scene_with(vec![ball(0.2, DVec3::new(0.0, 0.0, 1.9))]);
    scene.lights = light_box(h, 1.0);
    scene.fog = Some(Medium { density, albedo: Vec3::ZERO, anisotropy: 0.0 });
    scene.camera.position = DVec3::new(0.3, -0.2, 1.0);
    scene.camera.look_at = DVec3::new(0.0, 0.1, -2.0);
    scene.image.width = 48;
    scene.image.height = 36;
    scene.image.spp = 256;
    let out = common::render_validated(&scene);

    let (w, hgt) = (48usize, 36usize);
    let [eye, forward, right, up] = quadray::passes::scene_gpu::camera_basis(&scene, w as u32, hgt as u32);
    let (mut sum_got, mut sum_expected, mut worst) = (0.0, 0.0, 0.0f64);
    for y in 0..hgt {
        for x in 0..w {
            let nx = 2.0 * (x as f64 + 0.5) / w as f64 - 1.0;
            let ny = 1.0 - 2.0 * (y as f64 + 0.5) / hgt as f64;
            let d = (forward + nx * right + ny * up).normalize();
            // Distance to the box's wall along d.
            let t = [0, 1, 2]
                .iter()
                .map(|&k| if d[k] > 0.0 { (h - eye[k]) / d[k] } else { (-h - eye[k]) / d[k] })
                .fold(f64::INFINITY, f64::min);
            let expected = (-(density as f64) * t).exp();
            let got = out.radiance[y * w + x][1] as f64;
            sum_got += got;
            sum_expected += expected;
            worst = worst.max((got - expected).abs());
        }
    }
    let n = (w * hgt) as f64;
    let (mean, mean_expected) = (sum_got / n, sum_expected / n);
    println!(
        "absorbing fog (σ_t = {density}): mean {mean:.5}, Beer–Lambert {mean_expected:.5} (bound ±{MEAN_TOLERANCE}); \
         worst pixel off by {worst:.4} (bound {PIXEL_TOLERANCE})"
    );
    assert!((mean - mean_expected).abs() <= MEAN_TOLERANCE);
    assert!(worst <= PIXEL_TOLERANCE);
}

#[test]
fn scattering_fog_in_a_box_of_lights_is_a_furnace() {
    for (density, g) in [(0.8f32, 0.0f32), (1.5, 0.6), (0.5, -0.4)] {
        let mut scene = common::scene_with(vec![ball(0.5, DVec3::ZERO)]);
        scene.materials = vec![Material::diffuse("white", Vec3::ONE)];
        scene.lights = light_box(2.0, 1.0);
        scene.fog = Some(Medium { density, albedo: Vec3::ONE, anisotropy: g });
        common::aim(&mut scene, DVec3::new(0.2, 0.4, 1.7), DVec3::ZERO);
        common::set_image(&mut scene, (32, 24), 256, 256);
        let out = common::render_validated(&scene);
        let common::UniformStats { mean, standard_error, worst } = common::UniformStats::of(&out, 1.0);
        println!(
            "fog furnace (σ_t = {density}, g = {g}): mean {mean:.5} (expected 1, bound ±{MEAN_TOLERANCE}, standard \
             error {standard_error:.5}); worst pixel {worst:.4} (bound {PIXEL_TOLERANCE})"
        );
        assert!((mean - 1.0).abs() <= MEAN_TOLERANCE, "mean {mean}");
        assert!(worst <= PIXEL_TOLERANCE, "worst {worst}");
    }
}
