//! Tests of the benchmark's arithmetic: spp ladders, interpolated times, accumulation.

use super::*;
use crate::passes::RenderOutput;
use crate::tools::metrics::RELATIVE_MSE_EPSILON;

#[test]
fn ladder_doubles_up_to_the_maximum() {
    assert_eq!(spp_ladder(64), vec![1, 2, 4, 8, 16, 32, 64]);
    assert_eq!(spp_ladder(48), vec![1, 2, 4, 8, 16, 32, 48]);
    assert_eq!(spp_ladder(1), vec![1]);
}

#[test]
fn time_to_reach_interpolates_in_log_log() {
    // error = 1 / √t: reaching 0.25 takes t = 16.
    let points: Vec<(f64, f64)> = [1.0, 4.0, 64.0].iter().map(|&t: &f64| (t, 1.0 / t.sqrt())).collect();
    assert!((time_to_reach(&points, 0.25).unwrap() - 16.0).abs() < 1e-9);
    assert_eq!(time_to_reach(&points, 2.0), Some(1.0));
    assert_eq!(time_to_reach(&points, 0.01), None);
}

#[test]
fn equal_quality_needs_low_bias_too() {
    // error = 1 / t, bias² 0.1 until t = 8, then 0.
    let points: Vec<(f64, f64, f64)> =
        [1.0, 2.0, 4.0, 8.0, 16.0].iter().map(|&t: &f64| (t, 1.0 / t, if t < 8.0 { 0.1 } else { 0.0 })).collect();
    // Target 0.3: reached at t = 1/0.3 by the error alone, but bias² 0.1 > 0.075 until t = 8.
    assert_eq!(time_to_equal_quality(&points, 0.3, 0.075), Some(8.0));
    // Target 0.3 with bias allowed: interpolated between t = 2 and 4.
    let t = time_to_equal_quality(&points, 0.3, 1.0).unwrap();
    assert!((t - 1.0 / 0.3).abs() < 1e-9, "{t}");
    assert_eq!(time_to_equal_quality(&points, 0.01, 1.0), None);
}

#[test]
fn error_statistics_split_bias_and_variance() {
    // Two pixels' values; reference 1 with no noise; renders 1 + b ± d.
    let r = RenderOutput::from_radiance(2, 1, vec![[1.0; 3]; 2]);
    let reference = Reference::new(&r, &r);
    let mut acc = Accumulation::new(2);
    for d in [-0.2f32, 0.2] {
        acc.add(&RenderOutput::from_radiance(2, 1, vec![[1.1 + d; 3]; 2]));
    }
    let st = reference.stats(&acc, &[0, 1]);
    let w = 1.0 / (1.0 + RELATIVE_MSE_EPSILON);
    // Variance of one render: 2 · 0.2² / (2 − 1) = 0.08; mean squared error 0.1² + 0.2² = 0.05.
    assert!((st.variance - 0.08 * w).abs() < 1e-6, "{st:?}");
    assert!((st.error - 0.05 * w).abs() < 1e-6, "{st:?}");
    assert!((st.bias2 - (0.05 - 0.08) * w).abs() < 1e-6, "{st:?}");
}

#[test]
fn mean_maps_drop_every_map() {
    let mut scene = crate::model::scene::parse_scene(crate::model::scene::DEFAULT_SCENE, "default").unwrap();
    scene.textures = vec![crate::model::texture::checker(4, 2, [1.0; 3], [0.0; 3])];
    scene.materials[0].maps.albedo = Some(0);
    scene.materials[0].albedo = glam::Vec3::ONE;
    let s = with_mean_maps(&scene);
    assert!(s.materials[0].maps.albedo.is_none());
    assert!((s.materials[0].albedo.x - 0.5).abs() < 1e-6);
}

#[test]
fn fnv_is_stable() {
    assert_eq!(fnv1a_hex(b""), "cbf29ce484222325");
    assert_eq!(fnv1a_hex(b"a"), "af63dc4c8601ec8c");
}

#[test]
fn cache_key_ignores_the_time_taken() {
    let a = ReferenceInfo {
        scene_hash: "x".into(),
        width: 2,
        height: 2,
        spp: 4,
        seed: 0,
        camera_offset: 0.0,
        shading: 0,
        pixel_sigma: 0.5,
        version: "1".into(),
        seconds: 3.0,
    };
    assert!(a.same_settings(&ReferenceInfo { seconds: 9.0, ..a.clone() }));
    assert!(!a.same_settings(&ReferenceInfo { spp: 8, ..a.clone() }));
    assert!(!a.same_settings(&ReferenceInfo { pixel_sigma: 0.0, ..a.clone() }));
}
