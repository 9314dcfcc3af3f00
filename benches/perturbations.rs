//! Ray throughput against a unit sphere carrying 0, 10, 100 and 1000 small
//! perturbations spread over it, measured in one run on the same device and
//! reported as time ratios to the unperturbed sphere, with the GPU memory
//! each perturbation costs.
//!
//! `cargo bench --bench perturbations` (add `-- --rays N` to change the ray
//! count, `-- --max-per-cell K` to change how finely objects are split into
//! cells). GPU time comes from timestamps around the probe dispatches; the
//! first run of each configuration is discarded (lavapipe compiles the
//! shader at its first dispatch); then every configuration runs once per
//! round, for `RUNS` rounds, and the median is kept, so that the machine's
//! drift over the run affects every configuration alike.

use std::sync::Arc;

use glam::{DAffine3, DVec3, Vec3};
use quadray::gpu::shader_interface::NO_HIT;
use quadray::model::geometry::{scatter::spread_bumps, CellParams, FunctionalObject, Quadric};
use quadray::model::scene::{Camera, ImageSettings, Material, Scene, SceneObject};
use quadray::passes::gpu::GpuRay;
use quadray::passes::IntersectMode;
use quadray::passes::{GpuScene, ProbePass};
use quadray::vk::{Commands, Context};

const COUNTS: [usize; 4] = [0, 10, 100, 1000];
const BUMP_RADIUS: f64 = 0.05;
const FORM_FACTOR: f64 = 0.05;
const RUNS: usize = 9;

fn sphere_scene(n: usize) -> Scene {
    let shape = FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE),
        perturbations: spread_bumps(n, DVec3::ONE, BUMP_RADIUS, FORM_FACTOR, true),
        clip: None,
    };
    Scene {
        image: ImageSettings::minimal(1, 1),
        camera: Camera::still(DVec3::new(0.0, 0.0, 4.0), DVec3::ZERO, DVec3::Y, 40.0),
        background: Vec3::ZERO,
        materials: vec![Material::diffuse("grey", Vec3::splat(0.8))],
        objects: vec![SceneObject {
            name: format!("sphere with {n} bumps"),
            shape,
            transform: DAffine3::IDENTITY,
            material: 0,
            uv: Default::default(),
        }],
        lights: vec![],
        textures: vec![],
        environment: None,
        fog: None,
        caustics: Default::default(),
        volume: Default::default(),
    }
}

/// A `side` x `side` grid of parallel-projection rays over the sphere's
/// silhouette square, from z = 4 toward -z.
fn grid_rays(side: usize) -> Vec<GpuRay> {
    (0..side * side)
        .map(|i| {
            let x = -1.1 + 2.2 * ((i % side) as f32 + 0.5) / side as f32;
            let y = -1.1 + 2.2 * ((i / side) as f32 + 0.5) / side as f32;
            GpuRay { origin: [x, y, 4.0], tmin: 0.0, dir: [0.0, 0.0, -1.0], tmax: 1e30 }
        })
        .collect()
}

fn main() {
    let args: Vec<String> = std::env::args().collect();
    let arg = |name: &str| -> Option<usize> {
        let i = args.iter().position(|a| a == name)?;
        Some(args.get(i + 1).and_then(|v| v.parse().ok()).unwrap_or_else(|| panic!("{name} takes a number")))
    };
    let side = arg("--rays").map_or(1024, |n| (n as f64).sqrt().ceil() as usize);
    let mut params = CellParams::default();
    if let Some(k) = arg("--max-per-cell") {
        params.max_perturbations = k;
    }
    let ctx = Context::new(false).expect("a Vulkan device with ray queries (run `make setup`)");
    let device = Arc::clone(&ctx.device);
    let mut cmds = Commands::new(&device).unwrap();
    let rays = grid_rays(side);
    println!(
        "device: {}; {} rays per run, median of {} rounds (every configuration once a round) after a discarded first run; cells split to <= {} perturbations\n",
        device.name,
        rays.len(),
        RUNS,
        params.max_perturbations
    );
    println!(
        "{:>13} {:>6} {:>6} {:>9} {:>9} {:>7} {:>10} {:>10} {:>12} {:>12}",
        "perturbations",
        "cells",
        "hit %",
        "ms",
        "Mrays/s",
        "ratio",
        "boxes ms",
        "base ms",
        "table B/pert",
        "accel bytes"
    );
    // Every configuration (count and mode) is built and warmed up first,
    // then timed once per round, round after round: the machine's speed
    // drifts by 10 - 30 % over minutes, and interleaving makes every
    // configuration see the same drift, so that the ratios hold.
    let modes = [IntersectMode::Full, IntersectMode::Boxes, IntersectMode::Base];
    let gpus: Vec<GpuScene> =
        COUNTS.iter().map(|&n| GpuScene::new(&device, &mut cmds, &sphere_scene(n), &params).unwrap()).collect();
    let probes: Vec<Vec<ProbePass>> = gpus
        .iter()
        .map(|gpu| modes.iter().map(|&mode| ProbePass::new(&device, gpu, &rays, mode, false).unwrap()).collect())
        .collect();
    // Discarded: each shader variant compiles at its first dispatch.
    let hits: Vec<_> = probes.iter().map(|p| p[0].run(&mut cmds).unwrap().0).collect();
    for p in probes.iter().flatten().skip(1) {
        p.run(&mut cmds).unwrap();
    }
    let mut times = vec![vec![Vec::new(); modes.len()]; COUNTS.len()];
    for _ in 0..RUNS {
        for (i, per_mode) in probes.iter().enumerate() {
            for (m, probe) in per_mode.iter().enumerate() {
                times[i][m].push(probe.run(&mut cmds).unwrap().1 * 1e-6);
            }
        }
    }
    let median = |v: &[f64]| {
        let mut v = v.to_vec();
        v.sort_by(f64::total_cmp);
        v[v.len() / 2]
    };
    let base_ms = median(&times[0][0]);
    let base_table = gpus[0].stats.table_bytes;
    for (i, &n) in COUNTS.iter().enumerate() {
        let [ms, boxes_ms, base_only_ms] = [0, 1, 2].map(|m| median(&times[i][m]));
        let hit_fraction = hits[i].iter().filter(|h| h.object != NO_HIT).count() as f64 / hits[i].len() as f64;
        let stats = gpus[i].stats;
        let per_pert =
            if n > 0 { format!("{:.1}", (stats.table_bytes - base_table) as f64 / n as f64) } else { "-".into() };
        println!(
            "{:>13} {:>6} {:>6.1} {:>9.2} {:>9.2} {:>7.2} {:>10.2} {:>10.2} {:>12} {:>12}",
            n,
            stats.cells,
            100.0 * hit_fraction,
            ms,
            rays.len() as f64 / (ms * 1e3),
            ms / base_ms,
            boxes_ms,
            base_only_ms,
            per_pert,
            stats.accel_bytes
        );
    }
    println!("\nratio: GPU time / GPU time with 0 perturbations (target: <= 3 at 1000).");
    println!("boxes ms: every candidate box is a hit where the ray enters it (traversal cost alone).");
    println!("base ms: perturbations ignored, the base quadric's roots in each box (cells without perturbation work).");
    println!("table B/pert: bytes of perturbation, cell and cell-list tables added per perturbation (target: <= 64),");
    println!("              acceleration structures listed separately.");
}
