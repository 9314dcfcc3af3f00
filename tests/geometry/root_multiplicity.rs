//! Rays near roots of multiplicity 2 and 3, on the GPU against exact roots
//! (closed forms evaluated in f64 on the same f32 rays):
//!
//! - **Touching (double root).** Rays across the unit sphere at height
//!   y = 1 − δ: two roots t = z₀ ∓ √(1 − y²) that merge as δ → 0. At a
//!   double root F' has no slope, so an f32 evaluation error e moves the
//!   root by about e / |dF'/dt| = e / (2√(1 − y²)).
//! - **Inflection (near-triple root).** The solid y ≤ −x³ (a plane with a
//!   cubic dent: F = −y, Q = x, f = −1, F' = −y − max(x, 0)³), crossed by
//!   rays at y = −δ along −x: F' = δ − x³ along them, root x = δ^(1/3), where
//!   dF'/dt = 3 δ^(2/3) vanishes as δ → 0 (the three roots of x³ = δ crowd
//!   together), the structure of a surface that hugs a perturbation's
//!   support boundary.
//!
//! Bound: every ray whose root the f32 ray can represent is a hit, and its
//! error is at most `CONDITIONING_FACTOR` times the f32 conditioning limit
//! 2⁻²³ · S / |dF'/dt| (S: the size of F' and its terms on the segment, 1
//! here), plus 2⁻²³ of the distance. The table printed shows where that limit
//! makes the result useless (the error exceeds the gap to the other roots).

use crate::common;

use glam::{DAffine3, DVec3};
use quadray::gpu::shader_interface::NO_HIT;
use quadray::model::geometry::{Aabb, CellParams, FunctionalObject, Perturbation, Quadric};
use quadray::passes::gpu::GpuRay;
use quadray::passes::IntersectMode;
use quadray::passes::{GpuScene, ProbePass};

const F32_EPSILON: f64 = 1.0 / 8_388_608.0;
const CONDITIONING_FACTOR: f64 = 64.0;

struct Probe {
    delta: f64,
    ray: GpuRay,
    /// The exact root on the f32 ray, and |dF'/dt| there.
    exact: (f64, f64),
}

fn trace(shape: FunctionalObject, probes: &[Probe]) -> Vec<quadray::passes::gpu::GpuHit> {
    let (ctx, counters, mut cmds) = common::gpu();
    let scene = common::scene_with(vec![common::object("shape", shape, DAffine3::IDENTITY)]);
    let gpu = GpuScene::with_origin(&ctx.device, &mut cmds, &scene, &CellParams::default(), DVec3::ZERO).unwrap();
    let rays: Vec<GpuRay> = probes.iter().map(|p| p.ray).collect();
    let (hits, _) =
        ProbePass::new(&ctx.device, &gpu, &rays, IntersectMode::Full, false).unwrap().run(&mut cmds).unwrap();
    drop(gpu);
    drop(cmds);
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    hits
}

/// Prints the table and returns the probes that break the bound.
fn report(
    name: &str,
    probes: &[Probe],
    hits: &[quadray::passes::gpu::GpuHit],
    gap: impl Fn(f64) -> f64,
) -> Vec<String> {
    println!("{name}:");
    println!("| δ | exact t | GPU t | error | bound | gap to the next root |");
    println!("|---:|---:|---:|---:|---:|---:|");
    let mut bad = Vec::new();
    for (p, h) in probes.iter().zip(hits) {
        let (t, slope) = p.exact;
        let bound = CONDITIONING_FACTOR * F32_EPSILON * (1.0 / slope + t);
        let got = if h.object == NO_HIT { None } else { Some(h.t as f64) };
        let err = got.map(|g| (g - t).abs());
        println!(
            "| {:.0e} | {t:.9} | {} | {} | {bound:.2e} | {:.2e} |",
            p.delta,
            got.map_or("miss".into(), |g| format!("{g:.9}")),
            err.map_or("-".into(), |e| format!("{e:.2e}")),
            gap(p.delta)
        );
        assert!(got.is_none_or(|g| g.is_finite()), "non-finite t");
        match err {
            Some(e) if e <= bound => {}
            _ => bad.push(format!("{name} δ = {:.0e}", p.delta)),
        }
    }
    bad
}

#[test]
fn double_and_near_triple_roots_against_their_closed_forms() {
    let mut bad = Vec::new();

    // Touching: the unit sphere, rays along +z at height y = 1 − δ.
    let sphere =
        FunctionalObject { base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE), perturbations: vec![], clip: None };
    let probes: Vec<Probe> = (1..=7)
        .map(|k| {
            let delta = 10f64.powi(-k);
            let ray = GpuRay { origin: [0.0, (1.0 - delta) as f32, -3.0], tmin: 0.0, dir: [0.0, 0.0, 1.0], tmax: 1e30 };
            let y = ray.origin[1] as f64;
            let half = (1.0 - y * y).sqrt();
            Probe { delta: 1.0 - y, ray, exact: (3.0 - half, 2.0 * half) }
        })
        .collect();
    let hits = trace(sphere, &probes);
    bad.extend(report("sphere, y = 1 − δ (double root as δ → 0)", &probes, &hits, |d| 2.0 * (2.0 * d).sqrt()));

    // Inflection: y ≤ −x³ within [−1, 1]³, rays along −x at y = −δ from x = 0.9.
    let cubic = FunctionalObject {
        base: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
        perturbations: vec![Perturbation {
            quadric: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0, 0.0]),
            form_factor: -1.0,
        }],
        clip: Some(Aabb::new(DVec3::splat(-1.0), DVec3::ONE)),
    };
    // F' along a ray must be δ − x³ for the closed form: check the quadric's
    // coefficient order on the CPU first.
    assert!((cubic.eval(DVec3::new(0.5, -0.1, 0.0)) - (0.1 - 0.125)).abs() < 1e-12, "F' is not −y − max(x, 0)³");
    let probes: Vec<Probe> = (1..=9)
        .map(|k| {
            let delta = 10f64.powi(-k);
            let ray = GpuRay { origin: [0.9, -delta as f32, 0.0], tmin: 0.0, dir: [-1.0, 0.0, 0.0], tmax: 1e30 };
            let d = -(ray.origin[1] as f64);
            let x = d.cbrt();
            Probe { delta: d, ray, exact: (0.9 - x, 3.0 * x * x) }
        })
        .collect();
    let hits = trace(cubic, &probes);
    // The other two roots of x³ = δ are complex, |x| apart from the real one
    // times √3.
    bad.extend(report("cubic dent, y = −δ (near-triple root as δ → 0)", &probes, &hits, |d| {
        3f64.sqrt() * d.cbrt()
    }));

    assert!(bad.is_empty(), "outside the conditioning bound: {bad:?}");
}
