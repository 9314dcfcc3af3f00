//! Samples that gain energy: no single sample may exceed the bound that the
//! scene's emitters and path depth allow (src/passes/outliers.rs), over
//! more than ten million samples of a stress scene of glass, metal and
//! perturbed objects seen at their silhouettes, with the validation layer
//! on; the largest-sample AOV and the path recorder that find such samples
//! report what the render did; and no handful of pixels dominates the
//! error of a 16-spp render.

use crate::common;

use quadray::model::scene::{parse_scene, Scene, DEFAULT_SCENE, DEFAULT_SCENE_NAME};
use quadray::passes::outliers::{describe_path, largest_sample, luminance, outliers, SampleBound};
use quadray::passes::{GpuScene, RenderOutput, RenderVariant, Renderer};
use quadray::passes::{IntersectMode, LookupMode, SamplerMode, ShadingMode};
use quadray::vk::{Commands, Context};

fn stress_scene() -> Scene {
    common::project_scene("tests/energy_stress.toml")
}

/// The path tracer alone: the bound speaks of its samples.
const BRUTE_FORCE: RenderVariant = RenderVariant {
    intersect: IntersectMode::Full,
    shading: ShadingMode::Full,
    caustics: false,
    volume: false,
    record_path: false,
    lookup: LookupMode::Probes,
    sampler: SamplerMode::Sobol,
    backend: Some(quadray::vk::Backend::RayQuery),
    kernel: None,
};

fn upload(ctx: &Context, cmds: &mut Commands, scene: &Scene) -> GpuScene {
    GpuScene::for_render(&ctx.device, cmds, scene).unwrap()
}

/// Renders `spp` samples of `scene` at `width` x `height` with its seed.
fn render(ctx: &Context, scene: &Scene, (width, height, spp): (u32, u32, u32)) -> RenderOutput {
    let mut cmds = Commands::new(&ctx.device).unwrap();
    let gpu = upload(ctx, &mut cmds, scene);
    let scene = scene.resized(width, height, spp);
    let out = quadray::passes::render(&ctx.device, &mut cmds, &gpu, &scene, BRUTE_FORCE, &mut |_, _| {}).unwrap();
    common::finite(out)
}

#[test]
fn no_sample_exceeds_its_bound_in_the_stress_scene() {
    let mut scene = stress_scene();
    let bound = SampleBound::of(&scene).unwrap();
    let (width, height, spp, seeds) = (128u32, 96u32, 102u32, 8u32);
    let (ctx, counters, mut cmds) = common::gpu();
    let gpu = upload(&ctx, &mut cmds, &scene);
    let sized = scene.resized(width, height, spp);
    let mut renderer = Renderer::new(&ctx.device, &mut cmds, &gpu, &sized, BRUTE_FORCE).unwrap();
    let (mut samples, mut largest, mut over) = (0u64, 0f32, Vec::new());
    for s in 0..seeds {
        scene.image.seed = 1 + 7919 * s;
        renderer.set_camera(&mut cmds, &gpu, &scene).unwrap();
        renderer.add_samples(&mut cmds, spp, &mut |_, _| {}).unwrap();
        let out = common::finite(renderer.output(&mut cmds).unwrap());
        samples += width as u64 * height as u64 * spp as u64;
        let m = largest_sample(&out).unwrap();
        largest = largest.max(m.luminance);
        for o in outliers(&out, bound.luminance) {
            over.push((scene.image.seed, o));
        }
    }
    println!(
        "{samples} samples over {seeds} seeds: largest sample {largest:.4} ({:.3} x the largest emitted luminance \
         {:.4}); bound {:.4}; {} over it",
        largest / bound.emitted,
        bound.emitted,
        bound.luminance,
        over.len()
    );
    // The worst ones, traced again with their random numbers, for the log.
    if !over.is_empty() {
        let record = RenderVariant { record_path: true, ..BRUTE_FORCE };
        let mut recorder =
            Renderer::new(&ctx.device, &mut cmds, &gpu, &scene.resized(width, height, 1), record).unwrap();
        for (seed, o) in over.iter().take(3) {
            scene.image.seed = *seed;
            recorder.set_camera(&mut cmds, &gpu, &scene).unwrap();
            let path = recorder.trace_path(&mut cmds, (o.x, o.y), o.sample).unwrap();
            println!("seed {seed}, pixel ({}, {}), sample {}: {:.4}", o.x, o.y, o.sample, o.luminance);
            print!("{}", describe_path(&scene, &path));
        }
    }
    drop((renderer, gpu, cmds));
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    assert!(samples >= 10_000_000, "{samples} samples");
    assert!(over.is_empty(), "{} samples over the bound {}", over.len(), bound.luminance);
}

/// The largest-sample AOV holds a sample that really was taken: it lies
/// between the pixel's mean and spp times the mean (samples are never
/// negative), and tracing that sample again with the path recorder gives
/// the same radiance, event by event ending in the AOV's value.
#[test]
fn the_largest_sample_aov_is_a_sample_the_recorder_reproduces() {
    let scene = stress_scene();
    let (width, height, spp) = (48u32, 36u32, 8u32);
    let (ctx, counters, mut cmds) = common::gpu();
    let gpu = upload(&ctx, &mut cmds, &scene);
    let out = common::finite(
        quadray::passes::render(
            &ctx.device,
            &mut cmds,
            &gpu,
            &scene.resized(width, height, spp),
            BRUTE_FORCE,
            &mut |_, _| {},
        )
        .unwrap(),
    );
    assert_eq!(out.max_sample.len(), (width * height) as usize);
    for (p, m) in out.radiance.iter().zip(&out.max_sample) {
        let mean = luminance(*p);
        assert!(m[0] >= mean * (1.0 - 1e-5) - 1e-7 && m[0] <= spp as f32 * mean * (1.0 + 1e-5) + 1e-7, "{m:?} {mean}");
        assert!(m[1] < spp as f32 && m[1].fract() == 0.0);
    }
    let record = RenderVariant { record_path: true, ..BRUTE_FORCE };
    let mut recorder = Renderer::new(&ctx.device, &mut cmds, &gpu, &scene.resized(width, height, 1), record).unwrap();
    // The brightest pixels, and some others.
    let mut order: Vec<usize> = (0..out.max_sample.len()).collect();
    order.sort_by(|&a, &b| out.max_sample[b][0].total_cmp(&out.max_sample[a][0]));
    let mut checked = 0;
    for &i in order.iter().take(20).chain(order.iter().step_by(97)) {
        let (x, y) = (i as u32 % width, i as u32 / width);
        let m = out.max_sample[i];
        let path = recorder.trace_path(&mut cmds, (x, y), m[1] as u32).unwrap();
        assert_eq!(path.left_out, 0);
        let end = path.events.last().expect("a recorded path");
        assert_eq!(end.event, quadray::gpu::shader_interface::EVENT_END, "{}", describe_path(&scene, &path));
        let got = luminance(end.radiance);
        assert!((got - m[0]).abs() <= 1e-5 * m[0].max(1.0), "pixel ({x}, {y}): recorded {got}, AOV {}", m[0]);
        checked += 1;
    }
    println!("{checked} recorded paths reproduce their pixel's largest sample");
    drop((recorder, gpu, cmds));
    drop(ctx);
    common::assert_no_validation_errors(&counters);
}

/// Whole-image relative MSE at 16 spp against a converged reference is
/// within 1.5x of the mean of the regions' (the pixels seeing one object,
/// silhouettes left out): no handful of pixels dominates the error.
fn error_is_spread_over_the_image(name: &str, scene: &Scene, size: (u32, u32)) {
    let ctx = common::context();
    let counters = ctx.counters();
    let mut reference_scene = scene.clone();
    reference_scene.image.seed ^= 0x9e37_79b9;
    let reference = render(&ctx, &reference_scene, (size.0, size.1, 1024));
    let test = render(&ctx, scene, (size.0, size.1, 16));
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    let e = quadray::tools::metrics::region_relative_mse(&reference, &test, 2, 64).unwrap();
    let names: Vec<&str> = scene.objects.iter().map(|o| o.name.as_str()).collect();
    for (object, pixels, error) in &e.regions {
        println!(
            "{name}: {:<20} {pixels:>6} pixels  relMSE {error:.5}",
            names.get(*object as usize).unwrap_or(&"background")
        );
    }
    println!(
        "{name}: whole image {:.5}, mean of the regions {:.5}: ratio {:.3} (bound 1.5)",
        e.whole,
        e.mean_of_regions(),
        e.ratio()
    );
    assert!(e.regions.len() >= 3);
    assert!(e.ratio() <= 1.5, "{name}: whole-image relMSE {} is {} x the regions' mean", e.whole, e.ratio());
}

#[test]
fn error_is_spread_over_the_stress_scene() {
    error_is_spread_over_the_image("stress scene", &stress_scene(), (128, 96));
}

#[test]
fn error_is_spread_over_the_default_scene() {
    let scene = parse_scene(DEFAULT_SCENE, DEFAULT_SCENE_NAME).unwrap();
    error_is_spread_over_the_image("default scene", &scene, (128, 96));
}
