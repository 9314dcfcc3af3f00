//! Geometry at extreme scales and offsets (the stress suite): a sphere with
//! 40 bumps and dents, scaled by s from 1e-4 to 1e4 and moved D from 0 to
//! 1e5 away from the world origin, hit by 2,000 rays from 6 s away, GPU (f32
//! world, object rays re-based in f64 beyond 64 object units) against the
//! f64 reference on the same f32 rays.
//!
//! Two offset strategies. `world`: the GPU's frame is the scene's, so world
//! positions and the instance transform are f32 and the object's placement
//! is only known to ~6e-8 · D, i.e. to ε = 6e-8 · D / s object sizes; the
//! usual bounds hold where ε <= `TRUSTED_EPSILON` and the table shows how
//! the rest degrades (only NaN/Inf are failures there). `relative` (what
//! renders do, centred on the camera): the GPU's frame is centred on the
//! rays' start region in f64 (`GpuScene::with_origin`), so ε = 6e-8 · 6 s / s
//! everywhere and every case is held to the bounds.

mod common;

use glam::{DAffine3, DVec3};
use quadray::geometry::{reference, CellParams, FunctionalObject, Quadric};
use quadray::passes::gpu::GpuRay;
use quadray::passes::{GpuScene, ProbePass};
use quadray::shader_interface::{INTERSECT_FULL, NO_HIT};
use quadray::vk::Commands;
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

const SCALES: [f64; 5] = [1e-4, 1e-2, 1.0, 1e2, 1e4];
const OFFSETS: [f64; 3] = [0.0, 1e3, 1e5];
const RAYS: usize = 2000;
/// Placement uncertainty (object sizes) below which the usual bounds hold.
const TRUSTED_EPSILON: f64 = 1e-4;
/// Relative depth error, plus ε (the placement's own uncertainty).
const MAX_DEPTH_ERROR: f64 = 1e-5;
const MAX_NORMAL_DEGREES: f64 = 0.1;
/// Hits within this angle of grazing (or near the silhouette) are excused.
const SILHOUETTE_DEGREES: f64 = 1.0;

#[test]
fn scales_and_offsets_against_the_f64_reference() {
    let shape = FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE),
        perturbations: common::spread_bumps(40, 1.0, 0.3, 0.5, true),
        clip: None,
    };
    let bounds = shape.bounds().unwrap();
    let ctx = common::context();
    let counters = ctx.counters();
    let mut cmds = Commands::new(&ctx.device).unwrap();
    let mut rng = Pcg64::seed_from_u64(3);
    println!(
        "{:>9} {:>8} {:>8} {:>9} {:>6} {:>6} {:>8} {:>8} {:>11} {:>11} {:>8}",
        "frame",
        "scale",
        "offset",
        "ε (sizes)",
        "hits",
        "agree",
        "excused",
        "failures",
        "max depth",
        "max normal°",
        "bounded"
    );
    let mut violations = Vec::new();
    for relative in [false, true] {
        for &s in &SCALES {
            for &offset in &OFFSETS {
                let centre = DVec3::new(0.6, 0.8, 0.0) * offset;
                let transform = DAffine3::from_scale_rotation_translation(
                    DVec3::splat(s),
                    glam::DQuat::from_rotation_y(0.7),
                    centre,
                );
                let inverse = transform.inverse();
                let object =
                    quadray::scene::SceneObject { transform, ..common::object("ball", shape.clone(), transform) };
                let scene = common::scene_with(vec![object]);
                let origin = if relative { centre + DVec3::new(0.0, 0.0, 6.0 * s) } else { DVec3::ZERO };
                let gpu =
                    GpuScene::with_origin(&ctx.device, &mut cmds, &scene, &CellParams::default(), origin).unwrap();
                let rays: Vec<GpuRay> = (0..RAYS)
                    .map(|_| {
                        let o = centre + 6.0 * s * common::random_unit(&mut rng);
                        let target = centre + 1.3 * s * DVec3::new(rng.gen(), rng.gen(), rng.gen()) - 0.65 * s;
                        let d = (target - o).normalize();
                        let o = o - origin;
                        GpuRay { origin: o.as_vec3().to_array(), tmin: 0.0, dir: d.as_vec3().to_array(), tmax: 1e30 }
                    })
                    .collect();
                let (hits, _) =
                    ProbePass::new(&ctx.device, &gpu, &rays, INTERSECT_FULL, false).unwrap().run(&mut cmds).unwrap();
                drop(gpu);

                let epsilon = 6e-8 * ((centre - origin).length() + 6.0 * s) / s;
                let (mut n_hits, mut agree, mut excused, mut failures) = (0, 0, 0, 0);
                let (mut max_depth, mut max_normal) = (0.0f64, 0.0f64);
                let sil = SILHOUETTE_DEGREES.to_radians().sin();
                for (ray, g) in rays.iter().zip(&hits) {
                    assert!(g.t.is_finite() || g.object == NO_HIT, "non-finite t");
                    assert!(g.normal.iter().all(|v| v.is_finite()), "non-finite normal");
                    let o = origin + DVec3::from_array(ray.origin.map(f64::from));
                    let d = DVec3::from_array(ray.dir.map(f64::from));
                    let (ol, dl) = (inverse.transform_point3(o), inverse.transform_vector3(d));
                    let r = reference::intersect_within(&shape, &bounds, ol, dl, 0.0, f64::INFINITY);
                    let r = r.map(|h| {
                        let n = (inverse.matrix3.transpose() * h.normal).normalize();
                        (h.t, n)
                    });
                    let gn = DVec3::from_array(g.normal.map(f64::from));
                    let near_edge =
                        r.is_some_and(|(_, n)| n.dot(d).abs() < sil) || (g.object != NO_HIT && gn.dot(d).abs() < sil);
                    match (r, g.object != NO_HIT) {
                        (None, false) => agree += 1,
                        (Some((t, n)), true) if ((g.t as f64) - t).abs() < 0.05 * t => {
                            n_hits += 1;
                            if near_edge {
                                excused += 1;
                                continue;
                            }
                            agree += 1;
                            max_depth = max_depth.max(((g.t as f64) - t).abs() / t);
                            max_normal = max_normal.max(gn.dot(n).clamp(-1.0, 1.0).acos().to_degrees());
                        }
                        _ if near_edge => excused += 1,
                        _ => failures += 1,
                    }
                }
                let bounded = epsilon <= TRUSTED_EPSILON;
                let frame = if relative { "relative" } else { "world" };
                println!(
                "{frame:>9} {s:>8.0e} {offset:>8.0e} {epsilon:>9.1e} {n_hits:>6} {agree:>6} {excused:>8} {failures:>8} {max_depth:>11.2e} {max_normal:>11.4} {:>8}",
                if bounded { "yes" } else { "no" }
            );
                if bounded && (failures > 0 || max_depth > MAX_DEPTH_ERROR + epsilon || max_normal > MAX_NORMAL_DEGREES)
                {
                    violations.push(format!("{frame} frame, scale {s:e}, offset {offset:e}"));
                }
            }
        }
    }
    println!(
        "bounds where ε <= {TRUSTED_EPSILON:e}: no unexcused disagreement, depth error <= {MAX_DEPTH_ERROR:e} + ε, normal {MAX_NORMAL_DEGREES}°"
    );
    drop(cmds);
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    assert!(violations.is_empty(), "beyond the bounds: {violations:?}");
}
