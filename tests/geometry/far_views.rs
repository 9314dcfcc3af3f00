//! Far views of small objects (the stress suite's far-view table): a sphere
//! with 20 bumps and dents, of radius 1e-3 or 1 (in its own frame, or a unit
//! one scaled by 1e-3), seen from D = 1e3 … 1e7 radii, straight down an axis
//! and obliquely, in the frame renders use (`GpuScene::with_origin` at the
//! camera: the object lies D away from the GPU frame's origin). Each of a
//! 48 x 48 grid of rays over the object is traced on the GPU and by the f64
//! reference (which re-bases far rays to their point nearest the object, so
//! that its own error is ~1e-16 of D: 1e-9 radii at 1e7) on the same f32
//! ray, with the object's placement in f64 on both sides.
//!
//! What f32 camera rays themselves limit: a ray's direction is f32, so rays
//! can only be aimed to ~6e-8 rad; seen from 1e7 radii neighbouring
//! directions lie ~0.6 radii apart on the object, and the 48 x 48 grid
//! collapses onto fewer distinct rays (printed as "rays"). The comparison
//! holds per ray, since both sides trace the same f32 ray.
//!
//! Per case: hits, lost hits (the reference hits, the GPU misses), false
//! hits, wrong first roots (both hit, their object-space points more than
//! `WRONG_ROOT` radii apart), rays excused within 1° of grazing (either
//! side), and among agreeing hits the largest point error (radii) and
//! normal error. `QUADRAY_DEBUG_FAILURES=1` prints every lost hit and
//! wrong root. Both backends: ray queries, and the ray-tracing pipeline,
//! whose hardware orders hits by their f32 t.

use crate::common;

use glam::{DAffine3, DQuat, DVec3};
use quadray::gpu::shader_interface::NO_HIT;
use quadray::model::geometry::{reference, CellParams, FunctionalObject, Quadric};
use quadray::passes::gpu::GpuRay;
use quadray::passes::{GpuScene, IntersectMode, ProbePass};
use quadray::vk::Backend;

const DISTANCES: [f64; 5] = [1e3, 1e4, 1e5, 1e6, 1e7];
const GRID: usize = 48;
/// Object-space points farther apart than this (in radii) are different roots.
const WRONG_ROOT: f64 = 1e-3;
const GRAZING_DEGREES: f64 = 1.0;
/// The acceptance bounds: no lost, false or wrong hits up to 1e6 radii;
/// normals within 0.1° up to 1e5 and within 1° at 1e6.
const EXACT_UP_TO: f64 = 1e6;
fn normal_bound(distance: f64) -> Option<f64> {
    if distance <= 1e5 {
        Some(0.1)
    } else if distance <= 1e6 {
        Some(1.0)
    } else {
        None
    }
}

/// One object of the table: its name, shape, placement's scale and its
/// radius in world units.
struct Subject {
    name: &'static str,
    shape: FunctionalObject,
    scale: f64,
    radius: f64,
}

fn bumpy(radius: f64) -> FunctionalObject {
    FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::splat(radius)),
        perturbations: common::spread_bumps(20, radius, 0.35 * radius, 0.5, true),
        clip: None,
    }
}

fn subjects() -> Vec<Subject> {
    vec![
        Subject { name: "r 1e-3", shape: bumpy(1e-3), scale: 1.0, radius: 1e-3 },
        Subject { name: "r 1", shape: bumpy(1.0), scale: 1.0, radius: 1.0 },
        Subject { name: "r 1 scaled 1e-3", shape: bumpy(1.0), scale: 1e-3, radius: 1e-3 },
    ]
}

#[derive(Default)]
struct Tally {
    rays: usize,
    hits: usize,
    lost: usize,
    false_hits: usize,
    wrong: usize,
    excused: usize,
    max_point: f64,
    max_normal: f64,
}

#[test]
fn far_views_against_the_f64_reference() {
    let (ctx, counters, mut cmds) = common::gpu();
    println!(
        "{:>16} {:>6} {:>8} {:>10} {:>6} {:>6} {:>5} {:>6} {:>6} {:>8} {:>11} {:>11} {:>8}",
        "object",
        "D/r",
        "view",
        "backend",
        "rays",
        "hits",
        "lost",
        "false",
        "wrong",
        "excused",
        "max point",
        "max normal°",
        "bounds"
    );
    let mut violations = Vec::new();
    let sil = GRAZING_DEGREES.to_radians().sin();
    for subject in subjects() {
        let bounds = subject.shape.bounds().unwrap();
        // The object somewhere off the scene's origin, turned so that no
        // axis of its frame lines up with the world's in the oblique view.
        let centre = DVec3::new(0.25, -0.5, 0.125);
        for &distance in &DISTANCES {
            for (view, axis, turn) in [
                ("on axis", DVec3::Z, DQuat::IDENTITY),
                ("oblique", DVec3::new(0.48, 0.6, 0.64), DQuat::from_euler(glam::EulerRot::XYZ, 0.3, 0.7, 0.2)),
            ] {
                let transform = DAffine3::from_scale_rotation_translation(DVec3::splat(subject.scale), turn, centre);
                let inverse = transform.inverse();
                let camera = centre + distance * subject.radius * axis;
                let object = common::object("far", subject.shape.clone(), transform);
                let scene = common::scene_with(vec![object]);
                let gpu = GpuScene::with_origin(&ctx.device, &mut cmds, &scene, &CellParams::default(), camera)
                    .expect("the scene uploads");
                assert!(gpu.far_rays(), "{} from {distance:e} radii: the far-ray search is left out", subject.name);
                // A grid over the object's disc, seen from the camera.
                let (e1, e2) = axis.any_orthonormal_pair();
                let rays: Vec<GpuRay> = (0..GRID * GRID)
                    .map(|i| {
                        let u = ((i % GRID) as f64 + 0.5) / GRID as f64 * 2.0 - 1.0;
                        let v = ((i / GRID) as f64 + 0.5) / GRID as f64 * 2.0 - 1.0;
                        let target = centre + 1.3 * subject.radius * (u * e1 + v * e2);
                        let d = (target - camera).normalize().as_vec3();
                        GpuRay { origin: [0.0; 3], tmin: 0.0, dir: d.to_array(), tmax: 1e30 }
                    })
                    .collect();
                let mut distinct: Vec<[u32; 3]> = rays.iter().map(|r| r.dir.map(f32::to_bits)).collect();
                distinct.sort_unstable();
                distinct.dedup();
                // The reference on the same f32 rays, from the f64 camera.
                let references: Vec<Option<(DVec3, DVec3)>> = rays
                    .iter()
                    .map(|r| {
                        let d = DVec3::from_array(r.dir.map(f64::from));
                        let (ol, dl) = (inverse.transform_point3(camera), inverse.transform_vector3(d));
                        reference::intersect_within(&subject.shape, &bounds, ol, dl, 0.0, f64::INFINITY).map(|h| {
                            let n = (inverse.matrix3.transpose() * h.normal).normalize();
                            (ol + h.t * dl, n)
                        })
                    })
                    .collect();
                for backend in [Backend::RayQuery, Backend::Pipeline] {
                    let probe = ProbePass::with_backend(&ctx.device, &gpu, &rays, IntersectMode::Full, false, backend)
                        .expect("the probe pass builds");
                    let (hits, _) = probe.run(&mut cmds).expect("the probe pass runs");
                    let mut t = Tally { rays: distinct.len(), ..Tally::default() };
                    for ((ray, g), r) in rays.iter().zip(&hits).zip(&references) {
                        assert!(g.t.is_finite() || g.object == NO_HIT, "non-finite t");
                        assert!(g.normal.iter().chain(&g.object_point).all(|v| v.is_finite()), "non-finite hit");
                        let d = DVec3::from_array(ray.dir.map(f64::from));
                        let gn = DVec3::from_array(g.normal.map(f64::from));
                        let gpu_hit = g.object != NO_HIT;
                        let grazing =
                            r.is_some_and(|(_, n)| n.dot(d).abs() < sil) || (gpu_hit && gn.dot(d).abs() < sil);
                        match (r, gpu_hit) {
                            (None, false) => {}
                            _ if grazing => t.excused += 1,
                            (Some((p, _)), false) => {
                                if std::env::var_os("QUADRAY_DEBUG_FAILURES").is_some() {
                                    eprintln!("lost: reference point {p}, |p| {}, GPU t {}", p.length(), g.t);
                                }
                                t.lost += 1
                            }
                            (None, true) => t.false_hits += 1,
                            (Some((p, n)), true) => {
                                t.hits += 1;
                                let gp = DVec3::from_array(g.object_point.map(f64::from));
                                // Object units to radii: the shape's own radius.
                                let error = (gp - p).length() / (subject.radius / subject.scale);
                                if error > WRONG_ROOT {
                                    if std::env::var_os("QUADRAY_DEBUG_FAILURES").is_some() {
                                        eprintln!("wrong: reference {p} GPU {gp} GPU t {}", g.t);
                                    }
                                    t.wrong += 1;
                                } else {
                                    t.max_point = t.max_point.max(error);
                                    t.max_normal = t.max_normal.max(gn.dot(*n).clamp(-1.0, 1.0).acos().to_degrees());
                                }
                            }
                        }
                    }
                    let exact = distance <= EXACT_UP_TO;
                    let bounded = normal_bound(distance);
                    println!(
                        "{:>16} {:>6.0e} {:>8} {:>10} {:>6} {:>6} {:>5} {:>6} {:>6} {:>8} {:>11.2e} {:>11.4} {:>8}",
                        subject.name,
                        distance,
                        view,
                        backend.to_string(),
                        t.rays,
                        t.hits,
                        t.lost,
                        t.false_hits,
                        t.wrong,
                        t.excused,
                        t.max_point,
                        t.max_normal,
                        bounded.map_or("measured".to_string(), |b| format!("{b}°"))
                    );
                    let missed = exact && (t.lost > 0 || t.false_hits > 0 || t.wrong > 0);
                    if missed || bounded.is_some_and(|b| t.max_normal > b) {
                        violations.push(format!("{}, {distance:e} radii, {view}, {backend}", subject.name));
                    }
                    assert!(t.hits > GRID * GRID / 4 || distance > EXACT_UP_TO, "too few hits to measure");
                }
            }
        }
    }
    println!(
        "bounds: up to {EXACT_UP_TO:e} radii no lost, false or wrong hits; normals within 0.1° up to 1e5 and 1° at 1e6; 1e7 measured"
    );
    common::finish_bounded(ctx, cmds, &counters, &violations);
}

/// Scenes whose rays all start near their objects (within 90 % of their rebase
/// distance: the project's scenes, the test objects) are specialised without
/// the far-ray search; the same objects seen from afar keep it.
#[test]
fn only_scenes_that_reach_far_keep_the_far_ray_search() {
    let (ctx, counters, mut cmds) = common::gpu();
    for name in ["spheres.toml", "figure1_left.toml", "glass_vessel.toml"] {
        let gpu = GpuScene::for_render(&ctx.device, &mut cmds, &common::project_scene(name)).unwrap();
        assert!(!gpu.far_rays(), "{name} keeps the far-ray search");
    }
    let near = common::scene_with(common::test_objects());
    let gpu = GpuScene::new(&ctx.device, &mut cmds, &near, &CellParams::default()).unwrap();
    assert!(!gpu.far_rays(), "the test objects from the origin keep the far-ray search");
    // The same objects from 1e3 units (their rebase distance is at most 64).
    let far = GpuScene::with_origin(&ctx.device, &mut cmds, &near, &CellParams::default(), DVec3::splat(1e3)).unwrap();
    assert!(far.far_rays(), "the test objects from 1e3 units leave the far-ray search out");
    common::finish_bounded(ctx, cmds, &counters, &[]);
}
