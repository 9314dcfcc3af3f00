//! The covariance footprint (glsl/lib/covariance.glsl, path_footprint.glsl) per
//! bounce through curved mirrors and glossy lobes, against a brute-force
//! footprint and against the f64 operators of `src/model/covariance.rs`.
//!
//! The path recorder (`Renderer::trace_path`) gives, at each surface event
//! of a covariance render, the footprint the texture lookups used: its
//! covariance on the surface in the basis (t1, t2) of footprintBasis. The
//! brute force traces, in f64 on the CPU with the exact intersections of
//! `geometry::reference`, many rays of the camera footprint's Gaussian around
//! the recorded path's camera ray through the same surfaces (mirrors
//! reflect; a glossy lobe keeps the recorded path's microfacet normal in the
//! surface's frame, which turns with the normal: what "the lobe is sampled"
//! means for the rays around a sample) and measures the covariance of their
//! hit points on each surface. The f64 operators (travel, rotate, project,
//! mirror, curvature, unproject) are chained along the same mirror path.

use crate::common;

use glam::{DMat2, DMat3, DQuat, DVec2, DVec3};
use quadray::gpu::shader_interface::EVENT_SURFACE;
use quadray::model::covariance::Covariance4;
use quadray::model::geometry::reference;
use quadray::model::scene::{parse_scene, FilterMode, Scene};
use quadray::passes::gpu::GpuPathVertex;
use quadray::passes::variant::RenderVariant;
use quadray::passes::{GpuScene, Renderer};
use rand::{Rng, SeedableRng};
use rand_pcg::Pcg64;

/// Rays of the brute-force footprint per recorded path.
const RAYS: usize = 20_000;
/// The brute force's rays spread over this fraction of the camera
/// footprint's σ, and their covariances are divided by its square: the
/// footprints the renderer carries are first order in the offsets, and
/// a narrower bundle measures the first-order footprint (at the full σ
/// the second-order terms reach 10 % near the cylinder's focus).
const NARROW: f64 = 0.1;
/// |GPU footprint − brute force| / |brute force| (Frobenius norms) allowed
/// at every bounce. The brute force's own sampling error is about
/// √(2 / RAYS) = 1 % per entry; the GPU keeps the footprint in f32.
/// Measured: at most 0.015 through the mirrors, 0.012 through glossy lobes
/// (before the outgoing frame was made orthonormal, glossy samples off the
/// plane of incidence were off by up to 0.70).
const GPU_TOLERANCE: f64 = 0.05;
/// The same for the f64 operators of `src/model/covariance.rs` on mirror paths
/// (measured: at most 0.014; with the paper's curvature operator, which
/// turns the direction by 2 instead of 2 cos θ across the plane of
/// incidence, up to 0.73).
const F64_TOLERANCE: f64 = 0.05;

/// A path is checked when at least this fraction of its brute-force rays
/// meet the same surfaces: elsewhere its footprint straddles an edge, which
/// a Gaussian footprint does not describe (such paths are counted and left
/// out; at least `MIN_PATHS` must remain).
const MIN_FOLLOWED: f64 = 0.999;
/// Paths checked per case, at least.
const MIN_PATHS: usize = 6;

/// A surface hit of the brute force, in world space.
#[derive(Clone, Copy, Debug)]
struct Hit {
    object: usize,
    t: f64,
    point: DVec3,
    /// Outward unit normal.
    normal: DVec3,
}

/// The nearest hit of o + t d (d unit) with the scene's objects, exact.
fn trace(scene: &Scene, o: DVec3, d: DVec3) -> Option<Hit> {
    let mut best: Option<Hit> = None;
    for (i, obj) in scene.objects.iter().enumerate() {
        let inv = obj.transform.inverse();
        let (oo, dd) = (inv.transform_point3(o), inv.transform_vector3(d));
        let t_max = best.map_or(1e30, |b| b.t);
        if let Some(h) = reference::intersect(&obj.shape, oo, dd, 1e-7, t_max) {
            let normal = (inv.matrix3.transpose() * h.normal).normalize();
            best = Some(Hit { object: i, t: h.t, point: o + d * h.t, normal });
        }
    }
    best
}

/// The shape operator of the normal facing `d` at `hit`, in the basis
/// (t1, t2): the facing normal tilts by S u at tangent offset u.
fn shape_operator(scene: &Scene, hit: &Hit, d: DVec3, t1: DVec3, t2: DVec3) -> DMat2 {
    let obj = &scene.objects[hit.object];
    let inv = obj.transform.inverse();
    let p = inv.transform_point3(hit.point);
    let r = obj.transform.matrix3;
    let grad = r * obj.shape.gradient(p);
    let hess: DMat3 = r * obj.shape.hessian(p) * r.transpose();
    // Outward normal n = −∇F / |∇F|: dn = −P H du / |∇F| on tangent vectors.
    let facing = if d.dot(hit.normal) < 0.0 { 1.0 } else { -1.0 };
    let s = |a: DVec3, b: DVec3| -facing * a.dot(hess * b) / grad.length();
    DMat2::from_cols(DVec2::new(s(t1, t1), s(t2, t1)), DVec2::new(s(t1, t2), s(t2, t2)))
}

/// footprintBasis: t1 along the ray's projection on the surface, t2 = n × t1.
fn basis(d: DVec3, n: DVec3) -> (DVec3, DVec3) {
    let t1 = (d - n * n.dot(d)).normalize();
    (t1, n.cross(t1))
}

fn reflect(d: DVec3, n: DVec3) -> DVec3 {
    d - n * (2.0 * d.dot(n))
}

/// The 2 x 2 covariance of points (mean removed).
fn covariance(points: &[DVec2]) -> DMat2 {
    let n = points.len() as f64;
    let mean = points.iter().copied().sum::<DVec2>() / n;
    let (mut xx, mut xy, mut yy) = (0.0, 0.0, 0.0);
    for p in points {
        let q = *p - mean;
        xx += q.x * q.x;
        xy += q.x * q.y;
        yy += q.y * q.y;
    }
    DMat2::from_cols(DVec2::new(xx, xy), DVec2::new(xy, yy)) / (n - 1.0)
}

fn frobenius(m: DMat2) -> f64 {
    m.to_cols_array().iter().map(|v| v * v).sum::<f64>().sqrt()
}

fn relative(a: DMat2, b: DMat2) -> f64 {
    frobenius(a - b) / frobenius(b)
}

/// The recorded surface events of one path: (object, world point, footprint).
fn surface_events(scene: &Scene, events: &[GpuPathVertex]) -> Vec<(usize, DVec3, DMat2)> {
    events
        .iter()
        .filter(|v| v.event == EVENT_SURFACE)
        .map(|v| {
            let p = scene.camera.position + DVec3::from(v.position.map(f64::from));
            let f = v.footprint.map(f64::from);
            (v.object as usize, p, DMat2::from_cols(DVec2::new(f[0], f[1]), DVec2::new(f[1], f[2])))
        })
        .collect()
}

/// The brute-force footprints along a recorded path: the camera ray towards
/// its first hit, its surfaces in order, rays of angular σ `sigma` around it.
/// Each bounce keeps the central path's microfacet normal (the half vector
/// of its recorded directions) in the surface's frame. Returns the central
/// hits and the covariance of the rays' hit points on each surface, in the
/// basis of footprintBasis, and the fraction of rays that followed the
/// central path's surfaces.
fn brute_force(scene: &Scene, path: &[(usize, DVec3, DMat2)], sigma: f64) -> (Vec<Hit>, Vec<DMat2>, f64) {
    let eye = scene.camera.position;
    // The central path, re-traced in f64 with the recorded directions.
    let mut central = Vec::new();
    let mut o = eye;
    for (k, &(object, point, _)) in path.iter().enumerate() {
        let d = (point - o).normalize();
        let h = trace(scene, o, d).expect("the central path hits");
        assert_eq!(h.object, object, "the f64 path meets object {} at bounce {k}, the GPU's {object}", h.object);
        assert!(h.point.distance(point) < 1e-3 * (1.0 + h.t), "bounce {k}: f64 hit {} against {point}", h.point);
        central.push(h);
        o = h.point;
    }
    // Each bounce's microfacet normal in its local frame (from the recorded
    // outgoing direction; for a mirror, the normal itself).
    let mut half = Vec::new();
    let mut d = (central[0].point - eye).normalize();
    for k in 0..central.len() - 1 {
        let out = (central[k + 1].point - central[k].point).normalize();
        let m = (out - d).normalize();
        half.push(m);
        d = out;
    }
    let d0 = (central[0].point - eye).normalize();
    let e1 = d0.cross(scene.camera.up).normalize();
    let e2 = e1.cross(d0);
    let mut rng = Pcg64::seed_from_u64(7);
    let mut offsets: Vec<Vec<DVec2>> = vec![Vec::new(); central.len()];
    let mut followed = 0;
    for _ in 0..RAYS {
        // Box–Muller: two independent standard normals.
        let (u1, u2): (f64, f64) = (1.0 - rng.gen::<f64>(), rng.gen());
        let r = (-2.0 * u1.ln()).sqrt();
        let (a, b) = (r * (std::f64::consts::TAU * u2).cos(), r * (std::f64::consts::TAU * u2).sin());
        let mut d = (d0 + (e1 * a + e2 * b) * sigma).normalize();
        let mut o = eye;
        let mut hits = Vec::new();
        for (k, c) in central.iter().enumerate() {
            let Some(h) = trace(scene, o, d) else { break };
            if h.object != c.object {
                break;
            }
            hits.push(h);
            if k + 1 < central.len() {
                // The microfacet normal turns with the surface normal.
                let m = DQuat::from_rotation_arc(c.normal, h.normal) * half[k];
                d = reflect(d, m).normalize();
                o = h.point;
            }
        }
        if hits.len() < central.len() {
            continue;
        }
        followed += 1;
        let mut din = d0;
        for (k, (h, c)) in hits.iter().zip(&central).enumerate() {
            let (t1, t2) = basis(din, c.normal);
            let u = h.point - c.point;
            offsets[k].push(DVec2::new(u.dot(t1), u.dot(t2)));
            if k + 1 < central.len() {
                din = (central[k + 1].point - c.point).normalize();
            }
        }
    }
    let covs = offsets.iter().map(|o| covariance(o)).collect();
    (central, covs, followed as f64 / RAYS as f64)
}

/// The f64 operators of `src/model/covariance.rs` along a mirror path: the spatial
/// footprint on each surface, in the basis of footprintBasis.
fn f64_operators(scene: &Scene, central: &[Hit], sigma: f64) -> Vec<DMat2> {
    let eye = scene.camera.position;
    let mut c = Covariance4::from_pixel_footprint(sigma, sigma);
    let mut w = (central[0].point - eye).normalize();
    let mut e1 = w.cross(scene.camera.up).normalize();
    let mut e2 = w.cross(e1);
    let mut o = eye;
    let mut out = Vec::new();
    for h in central {
        c = c.travel(h.point.distance(o));
        let n = h.normal;
        let (t1, t2) = basis(w, n);
        // The frame with e1 in the plane of incidence, (e1, e2, w) right-handed.
        let f1 = (t1 - w * w.dot(t1)).normalize();
        let f2 = w.cross(f1);
        let angle = f1.dot(e2).atan2(f1.dot(e1));
        c = c.rotate(angle);
        let cos = w.dot(n).abs();
        let on_surface = c.project(cos);
        // Spatial coordinates: x along t1, y along f2's tangent direction.
        let s2 = f2.dot(t2).signum();
        let fp = on_surface.spatial_footprint();
        let flip = DMat2::from_diagonal(DVec2::new(1.0, s2));
        out.push(flip * fp * flip);
        // Reflection: frame e1' = reflect(f1), e2' = −reflect(f2); the
        // curvature tensor (positive when concave as seen from the ray: the
        // facing normal tilts by −K u) in the outgoing coordinates (x, −y).
        let shape = shape_operator(scene, h, w, t1, t2 * s2);
        let yflip = DMat2::from_diagonal(DVec2::new(1.0, -1.0));
        let k = yflip * (shape * -1.0) * yflip;
        let wo = reflect(w, n);
        c = on_surface.mirror().reflection_curvature(k, cos).unproject(wo.dot(n).abs());
        e1 = reflect(f1, n);
        e2 = reflect(f2, n) * -1.0;
        w = wo;
        o = h.point;
    }
    out
}

/// Renders one sample of each pixel in a column of `scene` with the path
/// recorder, covariance footprints, and returns the recorded surface events
/// of the paths whose surfaces are `objects` (by name), in order.
fn recorded_paths(scene: &Scene, objects: &[&str], pixels: &[(u32, u32)]) -> Vec<Vec<(usize, DVec3, DMat2)>> {
    let wanted: Vec<usize> = objects
        .iter()
        .map(|name| scene.objects.iter().position(|o| o.name == *name).expect("object in the scene"))
        .collect();
    let (ctx, counters, mut cmds) = common::gpu();
    let gpu = GpuScene::for_render(&ctx.device, &mut cmds, scene).unwrap();
    let variant = RenderVariant { record_path: true, ..Default::default() };
    let mut recorder = Renderer::new(&ctx.device, &mut cmds, &gpu, scene, variant).unwrap();
    let mut paths = Vec::new();
    for &(x, y) in pixels {
        let path = recorder.trace_path(&mut cmds, (x, y), 0).unwrap();
        let events = surface_events(scene, &path.events);
        if events.len() >= wanted.len() && events.iter().zip(&wanted).all(|(e, w)| e.0 == *w) {
            paths.push(events[..wanted.len()].to_vec());
        }
    }
    drop((recorder, gpu, cmds));
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    paths
}

/// scenes/curved_mirrors.toml at 128 x 96, 1 spp (the footprint takes the
/// whole pixel filter's share), covariance footprints, with `material`
/// replacing its mirrors' material.
fn curved_mirrors(mirror_material: &str) -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/curved_mirrors.toml");
    let text = std::fs::read_to_string(&path).unwrap();
    let text = text.replace(
        "name = \"mirror\"\ntype = \"mirror\"\nalbedo = [0.92, 0.92, 0.92]",
        &format!("name = \"mirror\"\n{mirror_material}"),
    );
    let mut scene = parse_scene(&text, "curved_mirrors.toml").unwrap();
    common::set_image(&mut scene, (128, 96), 1, 3);
    scene.image.filter = FilterMode::Covariance;
    scene
}

/// Checks every recorded path of `scene` through `objects` bounce by bounce;
/// returns the worst relative differences (GPU, f64 operators).
fn check_paths(name: &str, scene: &Scene, objects: &[&str], pixels: &[(u32, u32)], mirrors: bool) -> (f64, f64) {
    let paths = recorded_paths(scene, objects, pixels);
    let (mut worst_gpu, mut worst_f64, mut checked, mut straddling) = (0.0f64, 0.0f64, 0, 0);
    for path in &paths {
        // The camera footprint's σ from the first hit, where the footprint
        // across the plane of incidence is σ² t² (a pinhole: no spatial
        // extent at the camera).
        let first = path[0];
        let t0 = first.1.distance(scene.camera.position);
        let sigma = first.2.y_axis.y.sqrt() / t0;
        assert!(sigma > 0.0, "{name}: no footprint at the first hit");
        let (central, brute, followed) = brute_force(scene, path, sigma * NARROW);
        let brute: Vec<DMat2> = brute.iter().map(|m| *m / (NARROW * NARROW)).collect();
        if followed < MIN_FOLLOWED {
            // The footprint straddles an edge (a silhouette, the end of a
            // clip box): no first-order footprint describes it.
            println!("{name}: a path where {followed:.3} of the rays follow it: straddles an edge, left out");
            straddling += 1;
            continue;
        }
        checked += 1;
        let f64_chain = if mirrors { Some(f64_operators(scene, &central, sigma)) } else { None };
        for (k, (event, bf)) in path.iter().zip(&brute).enumerate() {
            let gpu = event.2;
            let e_gpu = relative(gpu, *bf);
            worst_gpu = worst_gpu.max(e_gpu);
            let e_f64 = f64_chain.as_ref().map_or(0.0, |c| relative(c[k], *bf));
            worst_f64 = worst_f64.max(e_f64);
            println!(
                "{name}: bounce {k} ({}): brute force [{:.3e} {:.3e} {:.3e}], GPU [{:.3e} {:.3e} {:.3e}] ({e_gpu:.4}){}",
                scene.objects[event.0].name,
                bf.x_axis.x,
                bf.x_axis.y,
                bf.y_axis.y,
                gpu.x_axis.x,
                gpu.x_axis.y,
                gpu.y_axis.y,
                f64_chain.as_ref().map_or(String::new(), |c| format!(
                    ", f64 operators [{:.3e} {:.3e} {:.3e}] ({e_f64:.4})",
                    c[k].x_axis.x, c[k].x_axis.y, c[k].y_axis.y
                ))
            );
        }
    }
    println!(
        "{name}: {checked} paths checked ({straddling} straddling an edge left out), worst relative difference GPU \
         {worst_gpu:.4}, f64 operators {worst_f64:.4}"
    );
    assert!(checked >= MIN_PATHS, "{name}: only {checked} paths through {objects:?} checked");
    (worst_gpu, worst_f64)
}

/// The pixels of the middle column and of a column off the axis (paths
/// there meet the saddle off its symmetry planes).
fn columns() -> Vec<(u32, u32)> {
    [40u32, 64].iter().flat_map(|&x| (4..92).step_by(4).map(move |y| (x, y))).collect()
}

/// Through the mirror saddle, then the mirror cylinder, onto the floor: the
/// covariance footprint on each surface is the brute-force spread of the
/// rays around the path, and the f64 operators agree.
#[test]
fn covariance_footprints_through_two_curved_mirrors_match_brute_force() {
    let scene = curved_mirrors("type = \"mirror\"\nalbedo = [0.92, 0.92, 0.92]");
    for objects in [&["mirror saddle", "mirror cylinder", "floor"][..], &["mirror saddle", "floor"][..]] {
        let (gpu, f64_ops) = check_paths("mirrors", &scene, objects, &columns(), true);
        assert!(gpu <= GPU_TOLERANCE, "GPU footprints off by {gpu:.4} through {objects:?}");
        assert!(f64_ops <= F64_TOLERANCE, "f64 operators off by {f64_ops:.4} through {objects:?}");
    }
}

/// The same through glossy lobes (GGX, roughness 0.3): the rays around a
/// sampled path keep its microfacet normal in the surface's frame, and the
/// GPU turns the sampled direction accordingly (bounceJacobian).
#[test]
fn covariance_footprints_through_glossy_lobes_match_brute_force() {
    let scene = curved_mirrors("type = \"conductor\"\ncolor = [0.92, 0.92, 0.92]\nroughness = 0.3");
    let (gpu, _) = check_paths("glossy", &scene, &["mirror saddle", "floor"], &columns(), false);
    assert!(gpu <= GPU_TOLERANCE, "GPU footprints off by {gpu:.4} through glossy lobes");
}
