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

mod common;

use glam::{DAffine3, DVec2, DVec3, Vec3};
use quadray::geometry::{Aabb, FunctionalObject, Quadric};
use quadray::passes::RenderVariant;
use quadray::scene::{Material, MaterialMaps, UvMapping, UvSettings};
use quadray::shader_interface::{FILTER_COVARIANCE, FILTER_NONE, FILTER_RAY_CONES, SHADING_NONE};

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
    scene.textures = vec![quadray::texture::checker(1024, CELLS, [A; 3], [B; 3])];
    scene.camera.position = DVec3::new(0.0, 9.0, 9.0);
    scene.camera.look_at = DVec3::ZERO;
    scene.camera.vfov_degrees = 40.0;
    scene.image.width = 64;
    scene.image.height = 48;

    let ctx = common::context();
    let counters = ctx.counters();
    let render = |filter| {
        let variant = RenderVariant { filter, ..Default::default() };
        quadray::render_scene_with(&ctx, &scene, variant, &mut |_, _| {}).unwrap()
    };
    let (filtered, unfiltered) = (render(FILTER_RAY_CONES), render(FILTER_NONE));
    // The covariance mode's footprint at the first hit, through the radiance
    // of the albedo-only shading variant.
    let covariance = {
        let variant = RenderVariant { filter: FILTER_COVARIANCE, shading: SHADING_NONE, ..Default::default() };
        quadray::render_scene_with(&ctx, &scene, variant, &mut |_, _| {}).unwrap()
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
