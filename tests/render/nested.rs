//! Nested dielectrics: a sphere of glass inside a glass sphere of the same
//! index of refraction is an index-matched interface, so it must be
//! invisible. The test renders the glass ball with and without the inner
//! ball (a different material of the same index) and compares: the RMS
//! difference between the two (of 4x4 block means of radiance clamped to 1)
//! must be that of noise alone, measured as the same difference between two
//! renders of the same scene with different seeds (ratio below
//! `NOISE_RATIO`). Without the stack of media, the inner
//! ball would refract with index 1.5 against vacuum and show.

use crate::common;

use glam::{DAffine3, DVec3, Vec3};
use quadray::model::geometry::{FunctionalObject, Quadric};
use quadray::model::scene::{Light, Material, MaterialKind, Scene};
use quadray::passes::RenderOutput;

const NOISE_RATIO: f64 = 1.15;

fn glass(name: &str, ior: f32) -> Material {
    Material { kind: MaterialKind::Dielectric { roughness: 0.0, ior }, ..Material::diffuse(name, Vec3::ONE) }
}

fn scene(inner: bool) -> Scene {
    let ball = |r: f64| FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::splat(r)),
        perturbations: vec![],
        clip: None,
    };
    let floor = FunctionalObject {
        base: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
        perturbations: vec![],
        clip: Some(quadray::model::geometry::Aabb::new(DVec3::new(-5.0, -0.5, -5.0), DVec3::new(5.0, 0.5, 5.0))),
    };
    let mut objects = vec![
        common::object("outer", ball(1.0), DAffine3::from_translation(DVec3::new(0.0, 1.0, 0.0))),
        common::object("floor", floor, DAffine3::IDENTITY),
    ];
    if inner {
        objects.push(common::object("inner", ball(0.5), DAffine3::from_translation(DVec3::new(0.1, 1.1, 0.0))));
    }
    let mut s = common::scene_with(objects);
    s.materials = vec![
        glass("glass", 1.5),
        quadray::model::scene::Material::diffuse("floor", Vec3::splat(0.6)),
        glass("other glass of the same index", 1.5),
    ];
    s.objects[1].material = 1;
    if inner {
        s.objects[2].material = 2;
    }
    // A checkered look through the ball comes from the floor's light and shadow.
    s.lights = vec![Light::Sphere { centre: DVec3::new(2.0, 4.0, 3.0), radius: 0.5, radiance: Vec3::splat(30.0) }];
    s.background = Vec3::new(0.2, 0.25, 0.3);
    common::aim(&mut s, DVec3::new(0.0, 1.5, 4.5), DVec3::new(0.0, 1.0, 0.0));
    common::set_image(&mut s, (48, 36), 256, 12);
    s
}

/// RMS difference of 4x4-pixel block means of radiance clamped to 1 (the
/// caustics through glass make rare, very bright samples whose noise would
/// otherwise swamp the comparison).
fn rmse(a: &RenderOutput, b: &RenderOutput) -> f64 {
    let (w, h) = (a.width as usize, a.height as usize);
    let block = |img: &RenderOutput, bx: usize, by: usize, k: usize| {
        let mut sum = 0.0;
        for y in by * 4..by * 4 + 4 {
            for x in bx * 4..bx * 4 + 4 {
                sum += (img.radiance[y * w + x][k] as f64).min(1.0);
            }
        }
        sum / 16.0
    };
    let mut sum = 0.0;
    let mut n = 0;
    for by in 0..h / 4 {
        for bx in 0..w / 4 {
            for k in 0..3 {
                sum += (block(a, bx, by, k) - block(b, bx, by, k)).powi(2);
                n += 1;
            }
        }
    }
    (sum / n as f64).sqrt()
}

#[test]
fn an_index_matched_inner_ball_is_invisible() {
    let ctx = common::context();
    let counters = ctx.counters();
    let render = |s: &Scene, seed: u32| {
        let mut s = s.clone();
        s.image.seed = seed;
        let out = quadray::render_scene(&ctx, &s, &mut |_, _| {}).unwrap();
        common::assert_finite(&out);
        out
    };
    let (with, without) = (scene(true), scene(false));
    // Several independent renders of each scene, so that the noise estimate
    // is itself steady.
    let with_renders: Vec<RenderOutput> = (1..=3).map(|seed| render(&with, seed)).collect();
    let without_renders: Vec<RenderOutput> = (11..=13).map(|seed| render(&without, seed)).collect();
    let mean = |v: Vec<f64>| v.iter().sum::<f64>() / v.len() as f64;
    let difference = mean(with_renders.iter().flat_map(|a| without_renders.iter().map(move |b| rmse(a, b))).collect());
    let noise = mean(vec![
        rmse(&without_renders[0], &without_renders[1]),
        rmse(&without_renders[0], &without_renders[2]),
        rmse(&without_renders[1], &without_renders[2]),
        rmse(&with_renders[0], &with_renders[1]),
        rmse(&with_renders[0], &with_renders[2]),
        rmse(&with_renders[1], &with_renders[2]),
    ]);
    let b = &without_renders[0];
    // The same inner ball with index 1.33 (water in glass) must show.
    let mut water = with.clone();
    water.materials[2] = glass("water", 1.33);
    let w = render(&water, 1);
    let visible = rmse(&w, b);
    println!(
        "RMS difference with and without the index-matched inner ball {difference:.4}, noise {noise:.4}: ratio \
         {:.3} (bound {NOISE_RATIO}); with a water ball inside instead: ratio {:.3}",
        difference / noise,
        visible / noise
    );
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    assert!(difference / noise <= NOISE_RATIO, "the index-matched ball shows");
    assert!(visible / noise > 1.5, "a water ball inside glass should show");
}
