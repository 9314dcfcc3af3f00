//! Secondary-ray offsets for small objects: a ball of radius r seen from
//! D away, lit by a point light 10 r above it, with a small occluder ball
//! (radius 0.3 r) floating a gap of 0.1 r above its top. Direct light only
//! (max depth 1), black background. Every pixel on the ball must be either
//! the Lambert value of the point light (lit: no self-shadowing acne) or
//! black (inside the occluder's umbra: no light leaking past it because a
//! shadow ray started beyond it). Pixels within 35 % of the occluder's
//! radius of the umbra's edge (about two pixels) are left out.
//!
//! A shadow ray leaves its surface offset along the normal; the offset must
//! exceed the hit point's f32 error (which grows with the distance from the
//! camera-centred origin, and with the object's own size) but stay below the
//! gaps the scene has. The cases run from D/r = 10 to 1e5, and r from 1e-4
//! to 1.

use crate::common;

use glam::{DAffine3, DVec3, Vec3};
use quadray::model::geometry::{FunctionalObject, Quadric};
use quadray::model::scene::{Light, Material, Scene};

const SIZE: u32 = 64;

/// Largest relative deviation of a lit pixel from the Lambert value at its
/// centre: the pixel's mean differs from its centre's value by the
/// curvature of the shading across it (second order, well below 1 %) and by
/// the noise of its 64 sample positions (about 2 % at worst); self-shadowing
/// acne darkens pixels by far more.
const LIT_BOUND: f64 = 0.05;
const SPP: u32 = 64;

fn ball(r: f64) -> FunctionalObject {
    FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::splat(r)), perturbations: vec![], clip: None }
}

struct Case {
    r: f64,
    distance: f64,
}

struct Measured {
    lit: usize,
    worst_lit_error: f64,
    umbra: usize,
    leaking: usize,
}

fn scene(case: &Case) -> (Scene, DVec3, DVec3, f64) {
    let r = case.r;
    // Far from the world origin too: the camera-centred GPU frame must make
    // that harmless.
    let centre = DVec3::new(1.0e3, 0.0, -2.0e3);
    let occluder_centre = centre + DVec3::new(0.0, r + 0.1 * r + 0.3 * r, 0.0);
    let light = centre + DVec3::new(0.0, 10.0 * r, 0.0);
    let mut scene = common::scene_with(vec![
        common::object("ball", ball(r), DAffine3::from_translation(centre)),
        common::object("occluder", ball(0.3 * r), DAffine3::from_translation(occluder_centre)),
    ]);
    scene.materials = vec![Material::diffuse("white", Vec3::ONE)];
    // Irradiance at the ball's top: I / (9 r)²; keep it about 1.
    let intensity = (81.0 * r * r) as f32;
    scene.lights = vec![Light::Point { position: light, intensity: Vec3::splat(intensity) }];
    scene.background = Vec3::ZERO;
    scene.image.max_depth = 1;
    scene.image.spp = SPP;
    (scene.image.width, scene.image.height) = (SIZE, SIZE);
    // Looking down at the ball's top from 40° above its equator.
    let dir = DVec3::new(0.0, 40f64.to_radians().sin(), 40f64.to_radians().cos());
    scene.camera.position = centre + dir * case.distance;
    scene.camera.look_at = centre;
    scene.camera.vfov_degrees = 2.0 * (1.3 * r / case.distance).atan().to_degrees();
    (scene, centre, light, intensity as f64)
}

/// True when the segment from `p` to `light` passes through the occluder
/// with a margin of `margin` (a fraction of its radius).
fn in_umbra(p: DVec3, light: DVec3, occ: DVec3, occ_r: f64, margin: f64) -> bool {
    let d = light - p;
    let t = ((occ - p).dot(d) / d.length_squared()).clamp(0.0, 1.0);
    (p + d * t - occ).length() < occ_r * (1.0 - margin)
}

fn measure(case: &Case) -> Measured {
    let (scene, centre, light, intensity) = scene(case);
    let out = common::render_validated(&scene);
    let r = case.r;
    let occ = centre + DVec3::new(0.0, 1.4 * r, 0.0);
    let [eye, forward, right, up] = quadray::passes::scene_gpu::camera_basis(&scene, SIZE, SIZE);
    let mut m = Measured { lit: 0, worst_lit_error: 0.0, umbra: 0, leaking: 0 };
    for y in 0..SIZE {
        for x in 0..SIZE {
            let i = (y * SIZE + x) as usize;
            let a = &out.aov[i];
            if !a.depth.is_finite() {
                continue;
            }
            let nx = 2.0 * (x as f64 + 0.5) / SIZE as f64 - 1.0;
            let ny = 1.0 - 2.0 * (y as f64 + 0.5) / SIZE as f64;
            let p = eye + a.depth as f64 * (forward + nx * right + ny * up).normalize();
            // Only the ball (the occluder is seen too), away from its
            // terminator and silhouette.
            let n = (p - centre) / r;
            if (n.length() - 1.0).abs() > 0.05 {
                continue;
            }
            let n = n.normalize();
            let to_light = light - p;
            let cos = n.dot(to_light.normalize());
            // Silhouette pixels are partly background.
            let facing = n.dot((scene.camera.position - p).normalize());
            if cos < 0.2 || facing < 0.5 {
                continue;
            }
            let got = out.radiance[i][0] as f64;
            if in_umbra(p, light, occ, 0.3 * r, 0.35) {
                m.umbra += 1;
                if got > 1e-3 {
                    m.leaking += 1;
                }
            } else if !in_umbra(p, light, occ, 0.3 * r, -0.35) {
                let want = intensity * cos / to_light.length_squared() / std::f64::consts::PI;
                m.lit += 1;
                m.worst_lit_error = m.worst_lit_error.max((got - want).abs() / want);
            }
        }
    }
    m
}

#[test]
fn small_far_objects_keep_their_contact_shadows_and_no_acne() {
    let cases = [
        Case { r: 1.0, distance: 10.0 },
        Case { r: 1.0, distance: 1e3 },
        Case { r: 1.0, distance: 1e5 },
        Case { r: 1e-2, distance: 1.0 },
        Case { r: 1e-4, distance: 1e-3 },
        Case { r: 1e-4, distance: 1.0 },
    ];
    let mut failures = Vec::new();
    println!("| r | D | D/r | lit pixels | worst lit deviation (bound 5 %) | umbra pixels | leaking (bound 0) |");
    for c in &cases {
        let m = measure(c);
        println!(
            "| {:.0e} | {:.0e} | {:.0e} | {} | {:.3} % | {} | {} |",
            c.r,
            c.distance,
            c.distance / c.r,
            m.lit,
            100.0 * m.worst_lit_error,
            m.umbra,
            m.leaking
        );
        if m.lit < 100 || m.umbra < 20 || m.worst_lit_error > LIT_BOUND || m.leaking > 0 {
            failures.push(format!("r {} D {}", c.r, c.distance));
        }
    }
    assert!(failures.is_empty(), "failed: {failures:?}");
}
