//! The two path kernels render the same images: every test scene
//! (`scenes/tests/*.toml`: perturbations, glass and metal chains, textures
//! with each filter mode, media, the caustic and volume passes) rendered by
//! the megakernel and by the wavefront pass (ray queries both), with the
//! validation layer on. The wavefront pass runs the megakernel's code on
//! the same random numbers, stage by stage; only the compiler's treatment
//! of the separate kernels may differ, so the images agree to float
//! rounding. Also: the path recorder sees the same events through both,
//! the AOVs and denoiser features are the same, the wavefront output
//! carries its stage profile, and the wavefront pass on the pipeline
//! backend is refused.

use quadray::passes::{GpuScene, PathKernel, RenderVariant, Renderer};
use quadray::vk::Backend;
use quadray::RenderError;

use crate::common;

/// A channel "differs" beyond this, relative to max(1, the megakernel's).
const MAX_CHANNEL_DIFFERENCE: f64 = 1e-5;
/// Measured at 64x48 and 4 spp: every test scene identical to the bit
/// (scalar code in both; the kernels share every function). A bound of
/// zero differing pixels would fail on a compiler that contracts
/// differently per kernel; one pixel in a thousand allows a path whose
/// Russian roulette such rounding flips.
const MAX_DIFFERING_PIXELS: f64 = 0.001;

fn variant(kernel: PathKernel) -> RenderVariant {
    RenderVariant { backend: Some(Backend::RayQuery), kernel: Some(kernel), ..Default::default() }
}

#[test]
fn every_test_scene_renders_the_same_with_both_kernels() {
    println!("{:<22} {}", "scene", common::Agreement::header());
    let mut failures = Vec::new();
    for (name, scene) in common::test_scenes() {
        let mega = common::render_variant_validated(&scene, variant(PathKernel::Megakernel));
        let wave = common::render_variant_validated(&scene, variant(PathKernel::Wavefront));
        // Which kernel ran shows in the profile: two kernels were compared.
        assert!(mega.wave_profile.is_none(), "{name}: the megakernel ran the wavefront pass");
        let profile = wave.wave_profile.unwrap_or_else(|| panic!("{name}: no wavefront profile"));
        assert_eq!(profile.waves, 4, "{name}: one wave per sample of the single tile");
        assert!(profile.iterations >= 4 && profile.trace > 0.0 && profile.shade > 0.0, "{name}: {profile:?}");
        let d = common::Agreement::of(&mega, &wave, MAX_CHANNEL_DIFFERENCE);
        println!("{name:<22} {}", d.row());
        let share = d.differing as f64 / d.pixels as f64;
        failures.extend((share > MAX_DIFFERING_PIXELS).then(|| format!("{name}: {} pixels differ", d.differing)));
        // The AOVs (first sample) and the denoiser's feature sums.
        let aovs_differ =
            mega.aov.iter().zip(&wave.aov).filter(|(a, b)| bytemuck::bytes_of(*a) != bytemuck::bytes_of(*b)).count();
        let aov_share = aovs_differ as f64 / d.pixels as f64;
        failures.extend((aov_share > MAX_DIFFERING_PIXELS).then(|| format!("{name}: {aovs_differ} AOVs differ")));
        assert_eq!(mega.max_sample.len(), wave.max_sample.len());
    }
    assert!(failures.is_empty(), "{failures:?}");
}

#[test]
fn the_path_recorder_sees_the_same_events_through_both_kernels() {
    let mut scene = common::project_scene("tests/glass_metal.toml");
    let depth = scene.image.max_depth;
    common::set_image(&mut scene, (32, 24), 1, depth);
    let (ctx, counters, mut cmds) = common::gpu();
    let gpu = GpuScene::for_render(&ctx.device, &mut cmds, &scene).unwrap();
    let mut recorded = Vec::new();
    for kernel in PathKernel::ALL {
        let v = RenderVariant { record_path: true, ..variant(kernel) };
        let mut recorder = Renderer::new(&ctx.device, &mut cmds, &gpu, &scene, v).unwrap();
        let paths: Vec<_> =
            [(16, 12), (5, 20), (28, 3)].iter().map(|&p| recorder.trace_path(&mut cmds, p, 0).unwrap()).collect();
        recorded.push(paths);
    }
    drop((gpu, cmds));
    drop(ctx);
    common::assert_no_validation_errors(&counters);
    for (mega, wave) in recorded[0].iter().zip(&recorded[1]) {
        assert!(mega.events.len() >= 2, "a path of one event: {:?}", mega.events);
        assert_eq!(mega.events.len(), wave.events.len());
        for (a, b) in mega.events.iter().zip(&wave.events) {
            assert_eq!(bytemuck::bytes_of(a), bytemuck::bytes_of(b), "{a:?} against {b:?}");
        }
    }
}

#[test]
fn the_wavefront_pass_is_refused_on_the_pipeline_backend() {
    let mut scene = common::project_scene("tests/glass_metal.toml");
    common::set_image(&mut scene, (8, 8), 1, 2);
    let (ctx, _counters, mut cmds) = common::gpu();
    if !ctx.device.offers(Backend::Pipeline) {
        println!("no ray-tracing pipelines on this device: nothing to refuse");
        return;
    }
    let gpu = GpuScene::for_render(&ctx.device, &mut cmds, &scene).unwrap();
    let v =
        RenderVariant { backend: Some(Backend::Pipeline), kernel: Some(PathKernel::Wavefront), ..Default::default() };
    let err = Renderer::new(&ctx.device, &mut cmds, &gpu, &scene, v).err().expect("refused");
    assert!(matches!(err, RenderError::WavefrontNeedsRayQueries), "{err}");
    assert!(err.to_string().contains("--backend ray-query"), "{err}");
}
