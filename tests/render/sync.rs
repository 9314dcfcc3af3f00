//! The validation layer's synchronisation checks are on in every validated
//! context (`vk::Instance`), and they see what lavapipe hides by running
//! commands one after another: a transfer that fills a buffer, then a pass
//! that writes it with no barrier between them, is reported; the same
//! commands with the barrier the typed layer (`vk::sync`) derives from the
//! pass's backend report nothing, on both backends.
//!
//! What the layers check, measured here: hazards between the commands of
//! one submission, for transfers and compute dispatches; the layer Debian
//! 12 ships (1.3.239) does not track the accesses of `vkCmdTraceRaysKHR` (a
//! fill then a ray-generation shader that writes the same buffer, with no
//! barrier, reports nothing), the one of the Vulkan runtime `make setup`
//! fetches (1.4.363, Debian unstable) does, and there the test asserts that
//! a fill racing a ray-generation shader, and a barrier to the compute stage
//! instead of the ray-tracing stage, are reported. Under the old layer the
//! ray-tracing stage's barriers rest on the typed layer's unit tests
//! (`vk::sync::tests`). Every pass waits on a fence after
//! each submission, and the layer takes that as the end of the work before
//! it: the barriers that open a submission are written for a GPU but not
//! checked by this layer. `docs/stability.md`, "Synchronisation".

use glam::DVec3;
use quadray::model::geometry::CellParams;
use quadray::passes::gpu::GpuRay;
use quadray::passes::{GpuScene, IntersectMode, ProbePass};
use quadray::vk::{Access, Backend, ShaderStage};

use crate::common;

/// Fills the probe pass's hits, then traces into them after a barrier from
/// the fill to `stage` (none without); returns the hazards the layer
/// reported.
fn fill_then_trace(backend: Backend, stage: Option<ShaderStage>) -> usize {
    fill_then_trace_on(backend, stage).0
}

/// [`fill_then_trace`], with the validation layer's version.
fn fill_then_trace_on(backend: Backend, stage: Option<ShaderStage>) -> (usize, u32) {
    let (ctx, counters, mut cmds) = common::gpu();
    let layer = ctx.device.instance.validation_layer_version.expect("validation is on");
    let scene = common::project_scene("tests/one_sphere.toml");
    let gpu = GpuScene::new(&ctx.device, &mut cmds, &scene, &CellParams::default()).unwrap();
    let camera = scene.camera.position;
    let rays: Vec<GpuRay> = (0..256)
        .map(|i| {
            let target = DVec3::new((i % 16) as f64 / 8.0 - 1.0, (i / 16) as f64 / 8.0 - 1.0, 0.0);
            let dir = (target - camera).normalize().as_vec3();
            GpuRay { origin: (camera - gpu.origin).as_vec3().to_array(), tmin: 0.0, dir: dir.to_array(), tmax: 1e30 }
        })
        .collect();
    let probe = ProbePass::with_backend(&ctx.device, &gpu, &rays, IntersectMode::Full, false, backend).unwrap();
    assert_eq!(probe.stage(), ShaderStage::from(backend));
    let before = counters.hazards();
    cmds.run(|rec| {
        probe.hits().fill(rec, 0);
        if let Some(stage) = stage {
            rec.barrier(&[Access::TransferWrite], &[Access::ShaderWrite(stage)]);
        }
        probe.record(rec);
    })
    .unwrap();
    let hazards = counters.hazards() - before;
    let errors = counters.errors();
    drop((probe, gpu, cmds, ctx));
    // Hazards are errors; nothing else may be.
    assert_eq!(counters.errors(), errors);
    assert_eq!(errors, hazards, "validation errors other than hazards (see the log)");
    (hazards, layer)
}

/// The first layer version that tracks `vkCmdTraceRaysKHR`, as far as
/// measured here: 1.3.239 does not, 1.4.363 does.
const TRACES_RAYS_FROM: u32 = quadray::vk::vk::make_api_version(0, 1, 4, 0);

#[test]
fn a_missing_barrier_is_reported_and_the_typed_one_is_not() {
    // The deliberate hazard: the fill and a compute pass that writes the
    // same buffer with no barrier between them.
    let missing = fill_then_trace(Backend::RayQuery, None);
    println!("fill, no barrier, ray-query dispatch: {missing} hazard(s) reported");
    assert!(missing > 0, "the synchronisation checks did not see a fill racing a compute shader");
    // The layer's view of ray-tracing pipelines: it does not track the
    // accesses of vkCmdTraceRaysKHR (measured with 1.3.239: no hazard even
    // without any barrier). Where it does (a newer layer), the barrier that
    // names the compute stage for a ray-generation shader must be reported.
    let (unseen, layer) = fill_then_trace_on(Backend::Pipeline, None);
    let wrong_stage = fill_then_trace(Backend::Pipeline, Some(ShaderStage::Compute));
    let v = |f: fn(u32) -> u32| f(layer);
    println!(
        "validation layer {}.{}.{}: fill, no barrier, traceRays: {unseen} hazard(s); fill, barrier to the compute \
         stage, traceRays: {wrong_stage} hazard(s){}",
        v(quadray::vk::vk::api_version_major),
        v(quadray::vk::vk::api_version_minor),
        v(quadray::vk::vk::api_version_patch),
        if unseen == 0 { " (this layer does not track traceRays)" } else { "" }
    );
    if layer >= TRACES_RAYS_FROM {
        assert!(unseen > 0, "this layer tracks traceRays, but a fill racing a ray-generation shader went unreported");
    }
    if unseen > 0 {
        assert!(wrong_stage > 0, "a barrier that misses the ray-tracing stage went unreported");
    }
    for backend in [Backend::Pipeline, Backend::RayQuery] {
        let typed = fill_then_trace(backend, Some(backend.into()));
        println!("fill, barrier to the {backend} backend's stage, trace: {typed} hazard(s)");
        assert_eq!(typed, 0, "{backend}");
    }
}
