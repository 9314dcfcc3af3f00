//! Texture coordinates and colour-map lookups on the GPU against the CPU:
//! objects with a checkerboard colour map under planar, spherical and
//! cylindrical mappings (with scale, offset and object transforms). For
//! every pixel-centre hit, the albedo AOV (material albedo × map) must be
//! the checker colour of the cell that the CPU twin of the mapping
//! (`geometry::uv::object_uv`) gives for the hit point. Pixels within
//! `BORDER` (in cells) of a cell edge are skipped (bilinear filtering blends
//! neighbouring texels there, and f32 hit points differ slightly).

use crate::common;

use glam::{DAffine3, DVec2, DVec3, Vec3};
use quadray::model::geometry::uv::object_uv;
use quadray::model::geometry::{Aabb, FunctionalObject, Quadric};
use quadray::model::scene::{Material, MaterialMaps, UvMapping, UvSettings};

const BORDER: f64 = 0.05;
const CELLS: u32 = 8;
const A: [f32; 3] = [0.9, 0.6, 0.1];
const B: [f32; 3] = [0.1, 0.3, 0.8];

fn checker_colour(uv: DVec2) -> Option<[f32; 3]> {
    let (cu, cv) = ((uv.x.rem_euclid(1.0)) * CELLS as f64, (uv.y.rem_euclid(1.0)) * CELLS as f64);
    let near = |c: f64| (c - c.round()).abs() < BORDER;
    if near(cu) || near(cv) {
        return None;
    }
    Some(if (cu.floor() as i64 + cv.floor() as i64) % 2 == 0 { A } else { B })
}

#[test]
fn colour_maps_follow_the_uv_mappings() {
    let sphere =
        FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE), perturbations: vec![], clip: None };
    let cylinder = FunctionalObject {
        base: Quadric::from_coefficients([-1.0, 0.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.36]),
        perturbations: vec![],
        clip: Some(Aabb::new(DVec3::new(-1.0, -0.8, -1.0), DVec3::new(1.0, 0.8, 1.0))),
    };
    let floor = FunctionalObject {
        base: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
        perturbations: vec![],
        clip: Some(Aabb::new(DVec3::new(-5.0, -0.5, -5.0), DVec3::new(5.0, 0.5, 5.0))),
    };
    let mut objects = vec![
        common::object(
            "sphere",
            sphere,
            common::placement(DVec3::splat(0.9), DVec3::new(20.0, 30.0, 0.0), DVec3::new(-1.3, 1.0, 0.0)),
        ),
        common::object(
            "cylinder",
            cylinder,
            common::placement(DVec3::ONE, DVec3::new(0.0, 0.0, 10.0), DVec3::new(1.3, 0.9, 0.0)),
        ),
        common::object("floor", floor, DAffine3::IDENTITY),
    ];
    objects[0].uv =
        UvSettings { mapping: UvMapping::Spherical, scale: DVec2::new(2.0, 1.0), offset: DVec2::new(0.1, 0.0) };
    objects[1].uv =
        UvSettings { mapping: UvMapping::Cylindrical, scale: DVec2::new(1.0, 0.5), offset: DVec2::new(0.0, 0.3) };
    objects[2].uv = UvSettings {
        mapping: UvMapping::Planar { u_axis: DVec3::new(0.7, 0.0, 0.3), v_axis: DVec3::new(-0.3, 0.0, 0.7) },
        scale: DVec2::splat(0.25),
        offset: DVec2::new(0.05, 0.02),
    };
    let mut scene = common::scene_with(objects);
    let mut m = Material::diffuse("checker", Vec3::ONE);
    m.maps = MaterialMaps { albedo: Some(0), ..Default::default() };
    scene.materials = vec![m];
    scene.textures = vec![quadray::model::texture::checker(256, CELLS, A, B)];
    scene.camera.position = DVec3::new(0.0, 3.0, 6.0);
    scene.camera.look_at = DVec3::new(0.0, 0.6, 0.0);
    scene.image.width = 96;
    scene.image.height = 72;

    let out = common::render_validated(&scene);

    // Reconstruct each pixel-centre hit, find the object it lies on (F' ≈ 0),
    // and compare the albedo AOV with the checker colour there.
    let [eye, forward, right, up] = quadray::passes::scene_gpu::camera_basis(&scene, 96, 72);
    let (mut checked, mut wrong) = (0, Vec::new());
    for y in 0..72 {
        for x in 0..96 {
            let i = y * 96 + x;
            let a = &out.aov[i];
            if !a.depth.is_finite() {
                continue;
            }
            let nx = 2.0 * (x as f64 + 0.5) / 96.0 - 1.0;
            let ny = 1.0 - 2.0 * (y as f64 + 0.5) / 72.0;
            let dir = (forward + nx * right + ny * up).normalize();
            let p = eye + a.depth as f64 * dir;
            let Some(obj) = scene.objects.iter().min_by(|o1, o2| {
                let f = |o: &quadray::model::scene::SceneObject| {
                    o.shape.eval(o.transform.inverse().transform_point3(p)).abs()
                };
                f(o1).total_cmp(&f(o2))
            }) else {
                continue;
            };
            let local = obj.transform.inverse().transform_point3(p);
            let (uv, _, _) = object_uv(&obj.uv, local);
            let Some(want) = checker_colour(uv) else { continue };
            checked += 1;
            let got = a.albedo;
            if (0..3).any(|k| (got[k] - want[k]).abs() > 1e-3) {
                wrong.push(format!("pixel ({x}, {y}) on {}: uv {uv:?}, albedo {got:?}, expected {want:?}", obj.name));
            }
        }
    }
    println!("{checked} pixels checked, {} wrong", wrong.len());
    for w in wrong.iter().take(5) {
        println!("  {w}");
    }
    assert!(checked > 2000, "too few pixels checked");
    assert!(wrong.is_empty());
}
