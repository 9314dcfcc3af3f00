//! The volume pass against the brute-force path tracer on a fog-with-shadow
//! scene (`scenes/tests/fog_shadow.toml`: a sphere light behind a ball in
//! haze), and its absence where there is no fog.

use crate::common;

use quadray::passes::RenderVariant;

/// FLIP between the scene with the volume pass and a long brute-force render.
const FOG_FLIP_BOUND: f64 = 0.1;

#[test]
fn fog_with_shadow_matches_the_brute_force_path_tracer() {
    let c = common::compare_with_brute_force("fog_shadow", 2048, 64);
    let seconds = c.fast.volume_seconds.expect("the volume pass ran");
    println!(
        "fog_shadow: FLIP against brute force at 2048 spp: volume pass at 64 spp {:.4} (bound {FOG_FLIP_BOUND}); \
         volume pass {seconds:.3} s",
        c.flip_fast
    );
    // At equal GPU time brute force's error is still below the pass's here
    // (relMSE 0.0106 against 0.0142 when measured after issue 30's light
    // maps and halo sampling; 0.021 against 0.041 before): the volume pass
    // takes single scattering on the camera ray's first segment, now 0.2 s
    // of 1.4 s, but most of the error left is multiple scattering, which the
    // path tracer estimates in both renders. So this test bounds the pass's
    // error only (issue 30's note).
    assert!(c.flip_fast < FOG_FLIP_BOUND);
}

#[test]
fn scenes_without_fog_run_no_volume_pass() {
    let scene = common::project_scene("tests/lens.toml");
    assert!(!scene.needs_volume());
    let out = common::render_variant_validated(&scene, RenderVariant::default());
    assert!(out.volume_seconds.is_none(), "the volume pass ran");
    println!("lens (no fog): no volume pass ran (0 s in the volume pass)");
}
