//! Texture sizes at the extremes, in every filtering mode: a 1x1 colour map
//! and a 16384-texel-wide one (the largest side accepted,
//! `MAX_TEXTURE_SIZE`) on a floor seen in perspective, from grazing to
//! steep. For every pixel-centre hit the albedo AOV must be what the map
//! holds at the hit's texture coordinates (from the CPU twin of the
//! mapping):
//!
//! - the 1x1 map is one colour everywhere, whatever the footprint;
//! - the 16k map is a linear ramp in u (texel i holds i / 16383), which
//!   bilinear lookups reproduce exactly and which any footprint symmetric
//!   about its centre averages to the value at the centre, at every mip level.
//!
//! These two maps are f32 on the GPU, so their bounds measure addressing
//! and filtering, not quantisation. A third, 16384 x 16384 map (5.3 GiB of
//! f32 with its mips, more than lavapipe's largest allocation of 2 GiB) is
//! stored in 8-bit sRGB (`texture::encoding`) and must still be read at
//! full resolution: a checker of single texels in its blue channel.

use crate::common;

use glam::{DAffine3, DVec2, DVec3, Vec3};
use quadray::model::geometry::uv::object_uv;
use quadray::model::geometry::{Aabb, FunctionalObject, Quadric};
use quadray::model::scene::{FilterMode, Material, MaterialMaps, Scene, UvMapping, UvSettings};
use quadray::model::texture::encoding::TexelEncoding;
use quadray::model::texture::{from_texels, MAX_TEXTURE_SIZE};
use quadray::passes::RenderVariant;

const SIZE: (u32, u32) = (96, 64);

/// Texture coordinates per world unit on the floor (see `floor_scene`).
const TEXTURE_SCALE: f64 = 0.04;

/// A floor (y = 0, |x|, |z| ≤ 5) with u = 0.04 x + 0.5 (0.3 to 0.7 across
/// it), v = 0.04 z + 0.5, seen from a low camera so that the footprints run
/// from tens of texels to grazing. Maps repeat, and the ramps below do not:
/// a lookup that reaches across a map's edge averages in the far end of
/// the ramp. The floor keeps 0.3 of the map (4915 texels of a 16k map)
/// from every edge, six times the farthest reach of a lookup here (probes
/// at ±2σ of the major axis plus the trilinear tent of the probes' level:
/// about ±0.05 of the map at the grazing end at twice this scale, where
/// the 16k ramp's error grew to 0.024 at the floor's sides; 1.8e-7 at this
/// scale).
fn floor_scene(texture: quadray::model::scene::TextureImage) -> Scene {
    let floor = FunctionalObject {
        base: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
        perturbations: vec![],
        clip: Some(Aabb::new(DVec3::new(-5.0, -0.5, -5.0), DVec3::new(5.0, 0.5, 5.0))),
    };
    let mut object = common::object("floor", floor, DAffine3::IDENTITY);
    object.uv = UvSettings {
        mapping: UvMapping::Planar { u_axis: DVec3::X, v_axis: DVec3::Z },
        scale: DVec2::splat(TEXTURE_SCALE),
        offset: DVec2::splat(0.5),
    };
    let mut scene = common::scene_with(vec![object]);
    let mut m = Material::diffuse("mapped", Vec3::ONE);
    m.maps = MaterialMaps { albedo: Some(0), ..Default::default() };
    scene.materials = vec![m];
    scene.textures = vec![texture];
    scene.camera.position = DVec3::new(0.0, 0.6, 5.5);
    scene.camera.look_at = DVec3::new(0.0, 0.0, 0.0);
    scene.camera.vfov_degrees = 50.0;
    (scene.image.width, scene.image.height) = SIZE;
    scene
}

/// Checks that the largest |albedo AOV − expected(uv)| over the floor's
/// pixels (`expected` may skip a pixel: None) is within `bound`, over more
/// than 2000 pixels; prints it under `what` and returns it.
fn assert_albedo_within(
    scene: &mut Scene,
    filter: FilterMode,
    expected: impl Fn(DVec2) -> Option<[f32; 3]>,
    bound: f64,
    what: &str,
) -> f64 {
    let (worst, checked) = worst_albedo_errors(scene, filter, expected);
    let worst = worst.into_iter().fold(0.0, f64::max);
    println!("{what}, filter {filter}: {checked} pixels, worst albedo error {worst:.2e} (bound {bound:.0e})");
    assert!(checked > 2000);
    assert!(worst <= bound, "{what}, {filter}: {worst}");
    worst
}

/// The largest |albedo AOV − expected(uv)| per channel over the floor's
/// pixels, and how many were checked.
fn worst_albedo_errors(
    scene: &mut Scene,
    filter: FilterMode,
    expected: impl Fn(DVec2) -> Option<[f32; 3]>,
) -> ([f64; 3], usize) {
    // Set in place: the scene's maps are too large to copy (16k x 16k f32).
    scene.image.filter = filter;
    let scene = &*scene;
    let out = common::render_variant_validated(scene, RenderVariant::default());
    let (w, h) = SIZE;
    let [eye, forward, right, up] = quadray::passes::scene_gpu::camera_basis(scene, w, h);
    let (mut worst, mut checked) = ([0.0f64; 3], 0);
    for y in 0..h {
        for x in 0..w {
            let a = &out.aov[(y * w + x) as usize];
            if !a.depth.is_finite() {
                continue;
            }
            let nx = 2.0 * (x as f64 + 0.5) / w as f64 - 1.0;
            let ny = 1.0 - 2.0 * (y as f64 + 0.5) / h as f64;
            let p = eye + a.depth as f64 * (forward + nx * right + ny * up).normalize();
            let (uv, _, _) = object_uv(&scene.objects[0].uv, p);
            let Some(want) = expected(uv) else { continue };
            checked += 1;
            for (c, (got, want)) in a.albedo.iter().zip(want).enumerate() {
                worst[c] = worst[c].max((*got as f64 - want as f64).abs());
            }
        }
    }
    (worst, checked)
}

#[test]
fn a_one_texel_map_is_one_colour_at_every_footprint() {
    const C: [f32; 3] = [0.8, 0.35, 0.05];
    const BOUND: f64 = 1e-5;
    let mut scene = floor_scene(from_texels("1x1".into(), 1, 1, vec![[C[0], C[1], C[2], 1.0]]));
    for filter in FilterMode::ALL {
        assert_albedo_within(&mut scene, filter, |_| Some(C), BOUND, "1x1 map");
    }
}

#[test]
fn a_16k_wide_ramp_is_read_exactly_at_every_footprint() {
    let width = MAX_TEXTURE_SIZE;
    let ramp = |i: u32| i as f32 / (width - 1) as f32;
    let texels: Vec<[f32; 4]> = (0..4).flat_map(|_| (0..width).map(|i| [ramp(i), 1.0 - ramp(i), 0.5, 1.0])).collect();
    let mut scene = floor_scene(from_texels("16k ramp".into(), width, 4, texels));
    assert_eq!(scene.textures[0].width, width, "no resampling of a power-of-two width");
    // Bilinear between texel centres (i + 0.5) / width (u is in [0.3, 0.7]:
    // no lookup reaches the wrap at u = 0 and 1).
    let expected = |uv: DVec2| {
        let x = (uv.x * width as f64 - 0.5) / (width - 1) as f64;
        Some([x as f32, (1.0 - x) as f32, 0.5])
    };
    // One texel of the ramp is 6.1e-5. Bounds: bilinear lookups within 0.16
    // texel (f32 texture coordinates near u = 1 are good to about 2e-3
    // texels); filtered lookups, whose footprints reach hundreds of texels at
    // grazing angles and are truncated to a tap budget, centred within 16
    // texels (0.1 % of the texture's width).
    for (filter, bound) in [(FilterMode::None, 1e-5), (FilterMode::RayCones, 1e-3), (FilterMode::Covariance, 1e-3)] {
        let worst = assert_albedo_within(&mut scene, filter, expected, bound, "16384 x 4 ramp");
        println!("  ({:.2} texels of the ramp)", worst * (width - 1) as f64);
    }
}

#[test]
fn a_16k_square_map_is_stored_in_8_bits_and_read_at_full_resolution() {
    let size = MAX_TEXTURE_SIZE;
    let ramp = |i: u32| i as f32 / (size - 1) as f32;
    let texel = |i: u32, j: u32| [ramp(i), ramp(j), ((i + j) % 2) as f32, 1.0];
    let texels: Vec<[f32; 4]> = (0..size).flat_map(|j| (0..size).map(move |i| texel(i, j))).collect();
    let mut scene = floor_scene(from_texels("16k x 16k".into(), size, size, texels));
    assert_eq!((scene.textures[0].width, scene.textures[0].height), (size, size));

    // Filter `none`: bilinear lookups of level 0 of what was stored, the
    // texels decoded from 8-bit sRGB (exact for the checker's 0 and 1).
    let stored = |i: u32, j: u32| TexelEncoding::Srgb8.round_trip(texel(i % size, j % size));
    let bilinear = |uv: DVec2| {
        let (x, y) = (uv.x * size as f64 - 0.5, uv.y * size as f64 - 0.5);
        let (i, j) = (x.floor(), y.floor());
        let (fx, fy) = (x - i, y - j);
        let wrap = |k: f64| (k as i64).rem_euclid(size as i64) as u32;
        let (i, j) = (wrap(i), wrap(j));
        let [a, b, c, d] = [stored(i, j), stored(i + 1, j), stored(i, j + 1), stored(i + 1, j + 1)];
        let texel = std::array::from_fn(|k| {
            let top = a[k] as f64 * (1.0 - fx) + b[k] as f64 * fx;
            let bottom = c[k] as f64 * (1.0 - fx) + d[k] as f64 * fx;
            (top * (1.0 - fy) + bottom * fy) as f32
        });
        Some(texel)
    };
    let (worst, checked) = worst_albedo_errors(&mut scene, FilterMode::None, bilinear);
    println!(
        "16384 x 16384 map in 8-bit sRGB, filter none: {checked} pixels, worst error of the ramps {:.2e} and {:.2e}, \
         of the single-texel checker {:.2e} (bounds {RAMP:.1e}, {CHECKER:.0e})",
        worst[0], worst[1], worst[2]
    );
    // Bounds. The checker changes by up to 1 a texel, so its error is the
    // addressing error in texels plus the precision of the GPU's bilinear
    // weights (8 bits on many GPUs: 4e-3): it shows the map is read at full
    // resolution. Its 0 and 1 decode exactly; the ramps' codes do not, and
    // Vulkan leaves the precision of sRGB decoding loose: the ramps (6.1e-5
    // a texel, so addressing is no part of their error) are compared with
    // exactly decoded codes and held to 2.2e-3, half the encoding's own
    // worst rounding error (4.5e-3 near 1), so that decoding adds at most
    // half again to it (lavapipe's decoding errs by about 1.2e-3).
    const RAMP: f64 = 2.2e-3;
    const CHECKER: f64 = 1e-2;
    assert!(checked > 2000);
    assert!(worst[0] <= RAMP && worst[1] <= RAMP && worst[2] <= CHECKER, "{worst:?}");

    // Filtered lookups: footprints symmetric about their centre average the
    // ramps to their value there, within the sRGB8 rounding of the stored
    // ramps and its decoding (half a step each: 4.5e-3 together) and the
    // 16-texel centring bound of the ramp test above (1e-3). Every pixel
    // counts (no lookup reaches the map's edges: see floor_scene).
    let centre = |uv: DVec2| {
        let x = (uv.x * size as f64 - 0.5) / (size - 1) as f64;
        let y = (uv.y * size as f64 - 0.5) / (size - 1) as f64;
        Some([x as f32, y as f32, 0.5])
    };
    const BOUND: f64 = 4.5e-3 + 1e-3;
    for filter in [FilterMode::RayCones, FilterMode::Covariance] {
        let (worst, checked) = worst_albedo_errors(&mut scene, filter, centre);
        println!(
            "16384 x 16384 map in 8-bit sRGB, filter {filter}: {checked} pixels, worst error of the ramps {:.2e} and \
             {:.2e} (bound {BOUND:.1e})",
            worst[0], worst[1]
        );
        assert!(checked > 2000);
        assert!(worst[0] <= BOUND && worst[1] <= BOUND, "{filter}: {worst:?}");
    }
}
