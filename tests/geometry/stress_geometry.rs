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
//!
//! `QUADRAY_DEBUG_FAILURES=1` prints every failure with the first sign
//! change of F' that dense f64 sampling of the ray finds (an arbiter where
//! the GPU and the reference disagree).

use crate::common;

use glam::{DAffine3, DVec3};
use quadray::gpu::shader_interface::NO_HIT;
use quadray::model::geometry::{reference, CellParams, FunctionalObject, Quadric};
use quadray::passes::gpu::GpuRay;
use quadray::passes::IntersectMode;
use quadray::passes::{GpuScene, ProbePass};
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

/// Agreement of the GPU's hits with the f64 reference on one placement.
#[derive(Default)]
struct Agreement {
    hits: usize,
    agree: usize,
    excused: usize,
    failures: usize,
    max_depth: f64,
    max_normal: f64,
}

impl Agreement {
    /// The table columns: hits, agree, excused, failures, max depth, max normal°.
    fn columns(&self) -> String {
        format!(
            "{:>6} {:>6} {:>8} {:>8} {:>11.2e} {:>11.4}",
            self.hits, self.agree, self.excused, self.failures, self.max_depth, self.max_normal
        )
    }
}

/// Traces `rays` rays from 6 `s` away from `centre` toward random points of
/// the box `target_radius` · s around it, on the GPU (frame origin `origin`)
/// and in f64 on the same f32 rays.
#[allow(clippy::too_many_arguments)]
fn measure(
    ctx: &quadray::vk::Context,
    cmds: &mut Commands,
    rng: &mut Pcg64,
    shape: &FunctionalObject,
    transform: DAffine3,
    origin: DVec3,
    s: f64,
    target_radius: f64,
    rays: usize,
) -> Agreement {
    let bounds = shape.bounds().unwrap();
    let centre = transform.translation;
    let inverse = transform.inverse();
    let object = quadray::model::scene::SceneObject { transform, ..common::object("shape", shape.clone(), transform) };
    let scene = common::scene_with(vec![object]);
    let gpu = GpuScene::with_origin(&ctx.device, cmds, &scene, &CellParams::default(), origin).unwrap();
    let rays: Vec<GpuRay> = (0..rays)
        .map(|_| {
            let o = centre + 6.0 * s * common::random_unit(rng);
            let jitter = DVec3::new(rng.gen(), rng.gen(), rng.gen()) * 2.0 - 1.0;
            let target = centre + target_radius * s * jitter;
            let d = (target - o).normalize();
            let o = o - origin;
            GpuRay { origin: o.as_vec3().to_array(), tmin: 0.0, dir: d.as_vec3().to_array(), tmax: 1e30 }
        })
        .collect();
    let (hits, _) = ProbePass::new(&ctx.device, &gpu, &rays, IntersectMode::Full, false).unwrap().run(cmds).unwrap();
    drop(gpu);
    let mut a = Agreement::default();
    let sil = SILHOUETTE_DEGREES.to_radians().sin();
    for (ray, g) in rays.iter().zip(&hits) {
        assert!(g.t.is_finite() || g.object == NO_HIT, "non-finite t");
        assert!(g.normal.iter().all(|v| v.is_finite()), "non-finite normal");
        let o = origin + DVec3::from_array(ray.origin.map(f64::from));
        let d = DVec3::from_array(ray.dir.map(f64::from));
        let (ol, dl) = (inverse.transform_point3(o), inverse.transform_vector3(d));
        let r = reference::intersect_within(shape, &bounds, ol, dl, 0.0, f64::INFINITY);
        let r = r.map(|h| {
            let n = (inverse.matrix3.transpose() * h.normal).normalize();
            (h.t, n)
        });
        let gn = DVec3::from_array(g.normal.map(f64::from));
        // Hits at the rim of a clip box are excused too: the GPU's boxes are
        // the f64 ones rounded outward to f32.
        let on_rim = |t: f64| shape.clip.as_ref().is_some_and(|b| on_box_rim(b, ol + t * dl));
        let near_edge = r.is_some_and(|(t, n)| n.dot(d).abs() < sil || on_rim(t))
            || (g.object != NO_HIT && (gn.dot(d).abs() < sil || on_rim(g.t as f64)));
        match (r, g.object != NO_HIT) {
            (None, false) => a.agree += 1,
            (Some((t, n)), true) if ((g.t as f64) - t).abs() < 0.05 * t => {
                a.hits += 1;
                if near_edge {
                    a.excused += 1;
                    continue;
                }
                a.agree += 1;
                a.max_depth = a.max_depth.max(((g.t as f64) - t).abs() / t);
                a.max_normal = a.max_normal.max(gn.dot(n).clamp(-1.0, 1.0).acos().to_degrees());
            }
            _ if near_edge => a.excused += 1,
            (r, _) => {
                if std::env::var_os("QUADRAY_DEBUG_FAILURES").is_some() {
                    // The first sign change of F' by dense f64 sampling.
                    let n = 400_000;
                    let mut first = None;
                    let mut prev = shape.eval(ol);
                    for i in 1..=n {
                        let t = 12.0 * i as f64 / n as f64;
                        let v = shape.eval(ol + t * dl);
                        if (v >= 0.0) != (prev >= 0.0) {
                            first = Some(t);
                            break;
                        }
                        prev = v;
                    }
                    eprintln!(
                        "failure: reference {:?}, GPU t {} object {}, dense sampling {first:?}, object-frame ray {ol} + t {dl}",
                        r.map(|x| x.0),
                        g.t,
                        g.object
                    );
                }
                a.failures += 1
            }
        }
    }
    a
}

#[test]
fn scales_and_offsets_against_the_f64_reference() {
    let shape = FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE),
        perturbations: common::spread_bumps(40, 1.0, 0.3, 0.5, true),
        clip: None,
    };
    let (ctx, counters, mut cmds) = common::gpu();
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
                let origin = if relative { centre + DVec3::new(0.0, 0.0, 6.0 * s) } else { DVec3::ZERO };
                let a = measure(&ctx, &mut cmds, &mut rng, &shape, transform, origin, s, 0.65, RAYS);
                let epsilon = 6e-8 * ((centre - origin).length() + 6.0 * s) / s;
                let bounded = epsilon <= TRUSTED_EPSILON;
                let frame = if relative { "relative" } else { "world" };
                println!(
                    "{frame:>9} {s:>8.0e} {offset:>8.0e} {epsilon:>9.1e} {} {:>8}",
                    a.columns(),
                    if bounded { "yes" } else { "no" }
                );
                if bounded
                    && (a.failures > 0 || a.max_depth > MAX_DEPTH_ERROR + epsilon || a.max_normal > MAX_NORMAL_DEGREES)
                {
                    violations.push(format!("{frame} frame, scale {s:e}, offset {offset:e}"));
                }
            }
        }
    }
    println!(
        "bounds where ε <= {TRUSTED_EPSILON:e}: no unexcused disagreement, depth error <= {MAX_DEPTH_ERROR:e} + ε, normal {MAX_NORMAL_DEGREES}°"
    );
    common::finish_bounded(ctx, cmds, &counters, &violations);
}

/// Whether `p` lies within 1e-5 of the box's size of one of its faces.
fn on_box_rim(b: &quadray::model::geometry::Aabb, p: DVec3) -> bool {
    let tol = 1e-5 * (b.max - b.min).max_element();
    let inside = p.cmpge(b.min - tol).all() && p.cmple(b.max + tol).all();
    let near_face = (p - b.min).abs().min_element() <= tol || (b.max - p).abs().min_element() <= tol;
    inside && near_face
}

/// One extreme shape of [`shapes_at_the_extremes_against_the_f64_reference`]:
/// its name, the shape, how many rays and how far from its centre they aim,
/// and its bounds on unexcused disagreements (as a fraction of the rays),
/// relative depth error and normal error (degrees).
struct Extreme {
    name: String,
    shape: FunctionalObject,
    rays: usize,
    aim: f64,
    max_failures: f64,
    max_depth: f64,
    max_normal: f64,
}

fn extremes() -> Vec<Extreme> {
    let sphere = |perturbations| FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE),
        perturbations,
        clip: None,
    };
    let mut out = Vec::new();
    // Form factors of 12 alternating bumps and dents (radius 0.4) relative to
    // the unit sphere's, from invisible to walls at the supports' edges,
    // 20,000 rays each (`STRESS_FORM_FACTOR_RAYS` sets another count).
    // Beyond f ~ 1e2 the surface hugs the bumps' support boundaries, where
    // f Q³ has a near-triple root and f32 loses F' to rounding near a
    // piece's ends; the f64 refinement (`refineRoot64`) settles those
    // pieces, but from 1e3 on a pair of roots that both lie where f32 cannot
    // tell F' from 0 is still missed now and then: over 200,000 rays each,
    // 5, 6, 3, 2 and 1 wrong rays at 1e3 … 1e7 (at most 3e-5 of the rays),
    // held here to 1e-4. The walls' normals, from f32 gradients 1e6 times
    // the base's, err by up to 0.58° at 1e6 and 1.85° at 1e7 over those
    // rays (0.26° at 1e5), held to 3°.
    for f in [1e-6, 1e-3, 1.0, 1e3, 1e4, 1e5, 1e6, 1e7] {
        out.push(Extreme {
            name: format!("form factor {f:.0e}"),
            shape: sphere(common::spread_bumps(12, 1.0, 0.4, f, true)),
            rays: std::env::var("STRESS_FORM_FACTOR_RAYS").map_or(20_000, |v| v.parse().expect("a ray count")),
            aim: 1.2,
            max_failures: if f <= 1.0 { 0.0 } else { 1e-4 },
            max_depth: 1e-4,
            max_normal: if f <= 1e5 { 0.5 } else { 3.0 },
        });
    }
    out.push(Extreme {
        name: "300 overlapping bumps".into(),
        shape: sphere(common::spread_bumps(300, 1.0, 0.5, 0.05, true)),
        rays: RAYS,
        aim: 1.0,
        max_failures: 0.0,
        max_depth: 1e-4,
        max_normal: 0.5,
    });
    for (name, radii) in
        [("thin ellipsoid 1e-3", DVec3::new(1.0, 1e-3, 1.0)), ("needle 1e-3", DVec3::new(1e-3, 1.0, 1e-3))]
    {
        out.push(Extreme {
            name: name.into(),
            shape: FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, radii), perturbations: vec![], clip: None },
            rays: RAYS,
            aim: 0.8,
            max_failures: 0.0,
            max_depth: 1e-4,
            max_normal: 0.5,
        });
    }
    // A double cone (inside F = y² − x² − z² ≥ 0) clipped to |p| ≤ 1: rays
    // aimed at its apex.
    out.push(Extreme {
        name: "cone apex".into(),
        shape: FunctionalObject {
            base: Quadric::from_coefficients([-1.0, 1.0, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
            perturbations: vec![],
            clip: Some(quadray::model::geometry::Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0))),
        },
        rays: RAYS,
        aim: 0.05,
        max_failures: 0.0,
        max_depth: 1e-4,
        max_normal: 0.5,
    });
    // Near-planar quadrics: the paraboloid y = ε (x² + z²), clipped to the
    // unit box, whose curvature vanishes next to its linear term.
    for eps in [1e-3, 1e-7] {
        out.push(Extreme {
            name: format!("near-planar {eps:.0e}"),
            shape: FunctionalObject {
                base: Quadric::from_coefficients([eps, 0.0, eps, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
                perturbations: vec![],
                clip: Some(quadray::model::geometry::Aabb::new(DVec3::splat(-1.0), DVec3::splat(1.0))),
            },
            rays: RAYS,
            aim: 0.9,
            max_failures: 0.0,
            max_depth: 1e-4,
            max_normal: 0.5,
        });
    }
    out
}

/// Shapes at the extremes against the f64 reference: perturbation form
/// factors from 1e-6 to 1e7 of the base's, hundreds of overlapping
/// perturbations, nearly degenerate quadrics (thin and needle ellipsoids, a
/// cone's apex, near-planar paraboloids). Each case states its bounds; the table prints the measured
/// figures.
#[test]
fn shapes_at_the_extremes_against_the_f64_reference() {
    let (ctx, counters, mut cmds) = common::gpu();
    let mut rng = Pcg64::seed_from_u64(7);
    println!(
        "{:>22} {:>6} {:>6} {:>8} {:>8} {:>11} {:>11}",
        "shape", "hits", "agree", "excused", "failures", "max depth", "max normal°"
    );
    let mut violations = Vec::new();
    for e in extremes() {
        let transform = DAffine3::from_rotation_y(0.7);
        let origin = DVec3::new(0.0, 0.0, 6.0);
        let a = measure(&ctx, &mut cmds, &mut rng, &e.shape, transform, origin, 1.0, e.aim, e.rays);
        println!(
            "{:>22} {}   bounds: failures {} of {}, depth {:.0e}, normal {}°",
            e.name,
            a.columns(),
            (e.max_failures * e.rays as f64).round(),
            e.rays,
            e.max_depth,
            e.max_normal
        );
        let within = a.failures as f64 <= e.max_failures * e.rays as f64
            && a.max_depth <= e.max_depth
            && a.max_normal <= e.max_normal;
        if !within {
            violations.push(e.name);
        }
    }
    common::finish_bounded(ctx, cmds, &counters, &violations);
}
