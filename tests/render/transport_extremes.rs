//! Transport at the extremes (the stress suite):
//!
//! - A dielectric furnace: smooth glass and water objects, nested, under a
//!   uniform environment of radiance 1, with paths up to 64 bounces. Smooth
//!   dielectrics neither absorb nor emit, so every pixel is 1 however long
//!   the chains of refractions and total internal reflections inside them
//!   (an ellipsoid traps rays by total internal reflection; a sphere
//!   would not).
//! - Rough dielectrics from roughness 0 to 1 in the same furnace: never
//!   above 1 (single-scattering microfacets lose energy, never gain it).
//! - A very small, very bright sphere light (radius 1e-4, radiance 3.2e9)
//!   over a floor: the irradiance is that of a point light of the same
//!   intensity, I cos³θ / h², and no pixel is NaN or Inf.

use crate::common;

use quadray::model::scene::parse_scene;

/// Image mean within this of 1 (dielectric furnace).
const FURNACE_MEAN_TOLERANCE: f64 = 0.005;
/// Relative error of the floor's radiance under the tiny light.
const TINY_LIGHT_TOLERANCE: f64 = 0.01;

#[test]
fn nested_dielectrics_in_a_furnace_stay_white() {
    let scene = parse_scene(
        "background = [1, 1, 1]\n\
         [image]\nwidth = 64\nheight = 48\nspp = 64\nmax_depth = 64\n\
         [camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfov = 40\n\
         [[materials]]\nname = \"glass\"\ntype = \"dielectric\"\nior = 1.5\n\
         [[materials]]\nname = \"water\"\ntype = \"dielectric\"\nior = 1.33\n\
         [[materials]]\nname = \"diamond\"\ntype = \"dielectric\"\nior = 2.42\n\
         [[objects]]\nmaterial = \"glass\"\nellipsoid = { radii = [1.4, 0.8, 0.9] }\nrotate = [20, 30, 0]\n\
         [[objects]]\nmaterial = \"water\"\nsphere = { radius = 0.5 }\ntranslate = [0.3, 0, 0]\n\
         [[objects]]\nmaterial = \"diamond\"\nellipsoid = { radii = [0.4, 0.25, 0.3] }\ntranslate = [-1.6, 0.9, 0]\n",
        "furnace.toml",
    )
    .unwrap();
    let out = common::render_validated(&scene);
    let common::UniformStats { mean, standard_error, worst } = common::UniformStats::of(&out, 1.0);
    println!(
        "dielectric furnace (glass ⊃ water, diamond; 64 bounces): mean {mean:.5} (expected 1, bound ±{FURNACE_MEAN_TOLERANCE}, \
         standard error {standard_error:.5}); worst pixel off by {worst:.4}"
    );
    assert!((mean - 1.0).abs() < FURNACE_MEAN_TOLERANCE);
}

#[test]
fn a_tiny_bright_light_lights_like_a_point() {
    // Intensity L π r² = 3.2e9 × π × 1e-8 ≈ 100.5 W/sr, 2 units above the floor.
    let (radiance, radius, height) = (3.2e9f64, 1e-4f64, 2.0f64);
    let intensity = radiance * std::f64::consts::PI * radius * radius;
    let scene = parse_scene(
        &format!(
            "background = [0, 0, 0]\n\
             [image]\nwidth = 32\nheight = 32\nspp = 16\nmax_depth = 1\n\
             [camera]\nposition = [0, 1, 0]\nlook_at = [0, 0, 0]\nup = [0, 0, 1]\nfov = 60\n\
             [[materials]]\nname = \"floor\"\nalbedo = [0.5, 0.5, 0.5]\n\
             [[objects]]\nmaterial = \"floor\"\nplane = {{}}\nclip = {{ min = [-4, -0.01, -4], max = [4, 0.01, 4] }}\n\
             [[lights]]\ntype = \"sphere\"\nposition = [0, {height}, 0]\nradius = {radius}\nradiance = [{radiance}, {radiance}, {radiance}]\n"
        ),
        "tiny.toml",
    )
    .unwrap();
    let out = common::render_validated(&scene);
    // The floor point through each pixel centre: the camera looks straight
    // down from height 1, so the point is (x, 0, z) with x, z from the
    // pixel's image-plane position.
    let half = (30.0f64).to_radians().tan();
    let mut worst = 0.0f64;
    for (i, p) in out.radiance.iter().enumerate() {
        let (px, py) = ((i % 32) as f64 + 0.5, (i / 32) as f64 + 0.5);
        let ndc = (2.0 * px / 32.0 - 1.0, 1.0 - 2.0 * py / 32.0);
        let (x, z) = (ndc.0 * half, ndc.1 * half);
        let r2 = x * x + z * z + height * height;
        let cos = height / r2.sqrt();
        let expected = 0.5 / std::f64::consts::PI * intensity * cos / r2;
        worst = worst.max((p[0] as f64 - expected).abs() / expected);
    }
    println!(
        "tiny light (radius {radius:e}, radiance {radiance:e}): worst relative error of the floor's radiance {worst:.5} \
         (bound {TINY_LIGHT_TOLERANCE})"
    );
    assert!(worst < TINY_LIGHT_TOLERANCE);
}

/// Rough dielectrics swept over roughness 0, 0.05, 0.3 and 1 in the same
/// furnace (a glass ball, 64 bounces). Single-scattering microfacet models
/// lose the energy of the light that would scatter again between
/// microfacets (Walter et al. 2007), so a rough dielectric reads below 1; it
/// may never read above it (energy gain), and no pixel may be NaN or Inf. At
/// roughness 0 the ball is smooth and reads 1.
#[test]
fn rough_dielectrics_from_smooth_to_roughness_one_never_gain_energy() {
    println!("| roughness | image mean | standard error | energy lost |");
    println!("|---:|---:|---:|---:|");
    for roughness in [0.0, 0.05, 0.3, 1.0] {
        let scene = parse_scene(
            &format!(
                "background = [1, 1, 1]\n\
                 [image]\nwidth = 48\nheight = 48\nspp = 128\nmax_depth = 64\n\
                 [camera]\nposition = [0, 0, 4]\nlook_at = [0, 0, 0]\nfov = 32\n\
                 [[materials]]\nname = \"glass\"\ntype = \"dielectric\"\nior = 1.5\nroughness = {roughness}\n\
                 [[objects]]\nmaterial = \"glass\"\nsphere = {{ radius = 1 }}\n"
            ),
            "rough_furnace.toml",
        )
        .unwrap();
        let out = common::render_validated(&scene);
        let common::UniformStats { mean, standard_error, .. } = common::UniformStats::of(&out, 1.0);
        println!("| {roughness} | {mean:.5} | {standard_error:.5} | {:.2} % |", 100.0 * (1.0 - mean));
        assert!(mean <= 1.0 + 4.0 * standard_error + 1e-4, "roughness {roughness}: energy gained ({mean})");
        if roughness == 0.0 {
            assert!((mean - 1.0).abs() < FURNACE_MEAN_TOLERANCE, "smooth glass: {mean}");
        }
    }
}
