//! The caustic passes against closed forms and against the brute-force path
//! tracer:
//!
//! - Energy: a point light above a glass ball over a floor. The caustic map,
//!   integrated over the floor, holds the flux that enters the ball and
//!   leaves it toward the floor, ∫ I (1 − F(θ))² dω over the ball's cone of
//!   directions (both interfaces see the same angle θ in a ball; the
//!   refracting grids), and the flux the ball reflects onto the part of the
//!   floor in view, ∫ I F(θ) dω over the directions whose reflection lands
//!   there (the reflecting grids).
//! - Lens over a plane (`scenes/tests/lens.toml`): the render with the
//!   caustic passes against a long brute-force render (FLIP).
//! - A scene without specular objects runs no caustic pass.

use crate::common;

use quadray::model::sampling::fresnel::fresnel_dielectric;
use quadray::model::scene::parse_scene;
use quadray::passes::RenderVariant;

/// Relative error allowed on the deposited flux: the grid's boundary rays
/// deposit part of their flux (about 1 / (rays across the ball)), and the
/// pixels integrate the map by the midpoint rule.
const FLUX_TOLERANCE: f64 = 0.02;

/// Flux through a ball of radius `r` at distance `d` from a point light of
/// intensity `intensity` after two refractions: ∫ I (1 − F)² dω over the
/// cone, the incidence angle from the impact parameter d sin ψ.
fn predicted_flux(intensity: f64, d: f64, r: f64, eta: f64) -> f64 {
    let psi_max = (r / d).asin();
    let steps = 200_000;
    let h = psi_max / steps as f64;
    (0..steps)
        .map(|k| {
            let psi = (k as f64 + 0.5) * h;
            let sin_i = (d * psi.sin() / r).min(1.0);
            let t = 1.0 - fresnel_dielectric((1.0 - sin_i * sin_i).sqrt(), eta);
            intensity * t * t * 2.0 * std::f64::consts::PI * psi.sin() * h
        })
        .sum()
}

/// Flux that a ball of radius `r` centred `centre_height` above the floor
/// reflects onto the floor square |x|, |z| <= `half` from a point light of
/// intensity `intensity` at `light_height`: ∫ I F(θ) dω over the directions
/// whose mirror reflection off the ball lands there (the floor's top face at
/// y = 0.01; a ray reflected off a ball does not meet it again).
fn predicted_reflected_flux(intensity: f64, light_height: f64, centre_height: f64, r: f64, eta: f64, half: f64) -> f64 {
    use glam::DVec3;
    let d = light_height - centre_height;
    let psi_max = (r / d).asin();
    let (steps, azimuths) = (20_000, 512);
    let h = psi_max / steps as f64;
    let light = DVec3::new(0.0, light_height, 0.0);
    let centre = DVec3::new(0.0, centre_height, 0.0);
    let mut flux = 0.0;
    for k in 0..steps {
        let psi = (k as f64 + 0.5) * h;
        let solid_angle = 2.0 * std::f64::consts::PI * psi.sin() * h / azimuths as f64;
        for j in 0..azimuths {
            let phi = 2.0 * std::f64::consts::PI * (j as f64 + 0.5) / azimuths as f64;
            let dir = DVec3::new(psi.sin() * phi.cos(), -psi.cos(), psi.sin() * phi.sin());
            // First intersection with the ball.
            let oc = light - centre;
            let b = oc.dot(dir);
            let disc = b * b - (oc.length_squared() - r * r);
            if disc < 0.0 {
                continue;
            }
            let p = light + dir * (-b - disc.sqrt());
            let n = (p - centre) / r;
            let cos_i = -dir.dot(n);
            let reflected = dir + 2.0 * cos_i * n;
            if reflected.y >= 0.0 {
                continue;
            }
            let land = p + reflected * ((p.y - 0.01) / -reflected.y);
            if land.x.abs() <= half && land.z.abs() <= half {
                flux += intensity * fresnel_dielectric(cos_i, eta) * solid_angle;
            }
        }
    }
    flux
}

#[test]
fn glass_ball_deposits_the_flux_fresnel_predicts() {
    // The camera looks up at the floor from below: the floor is two-sided,
    // so every pixel's receiver is a floor point, and none is hidden by the
    // ball. Each pixel covers the same floor area (the image plane is
    // parallel to the floor).
    let (height, fov, size) = (3.0, 120.0f64, 320u32);
    let scene = parse_scene(
        &format!(
            "background = [0, 0, 0]\n\
             [image]\nwidth = {size}\nheight = {size}\nspp = 1\nmax_depth = 6\n\
             [caustics]\nrays = 262144\n\
             [camera]\nposition = [0, -{height}, 0]\nlook_at = [0, 0, 0]\nup = [0, 0, 1]\nfov = {fov}\n\
             [[materials]]\nname = \"floor\"\nalbedo = [0.5, 0.5, 0.5]\n\
             [[materials]]\nname = \"glass\"\ntype = \"dielectric\"\nior = 1.5\n\
             [[objects]]\nmaterial = \"floor\"\nplane = {{}}\nclip = {{ min = [-12, -0.01, -12], max = [12, 0.01, 12] }}\n\
             [[objects]]\nmaterial = \"glass\"\nsphere = {{ radius = 0.5 }}\ntranslate = [0, 2, 0]\n\
             [[lights]]\ntype = \"point\"\nposition = [0, 6, 0]\nintensity = [100, 100, 100]\n"
        ),
        "energy.toml",
    )
    .unwrap();
    let out = common::render_variant_validated(&scene, RenderVariant::default());
    let report = out.caustics.as_ref().expect("the caustic passes ran");
    let half = height * (0.5 * fov).to_radians().tan();
    let pixel_area = (2.0 * half / size as f64).powi(2);
    let deposited: f64 = report.irradiance.iter().map(|e| e[0] as f64 * pixel_area).sum();
    let refracted = predicted_flux(100.0, 4.0, 0.5, 1.5);
    let reflected = predicted_reflected_flux(100.0, 6.0, 2.0, 0.5, 1.5, half);
    let predicted = refracted + reflected;
    let error = (deposited - predicted).abs() / predicted;
    println!(
        "glass ball: {} rays, {} landed; deposited flux {deposited:.5} W, predicted {predicted:.5} W \
         ({refracted:.5} refracted, {reflected:.5} reflected), relative error {error:.4} (bound {FLUX_TOLERANCE})",
        report.rays, report.landed
    );
    assert!(error < FLUX_TOLERANCE);
}

/// FLIP between the lens scene with the caustic passes and a long
/// brute-force render.
const LENS_FLIP_BOUND: f64 = 0.05;

#[test]
fn lens_over_plane_matches_the_brute_force_path_tracer() {
    let c = common::compare_with_brute_force("lens", 4096, 64);
    let report = c.fast.caustics.as_ref().expect("the caustic passes ran");
    println!(
        "lens: FLIP against brute force at 4096 spp: caustic passes at 64 spp {:.4} (bound {LENS_FLIP_BOUND}); \
         caustic passes {:.3} s for {} rays",
        c.flip_fast,
        report.seconds(),
        report.rays
    );
    assert!(c.flip_fast < LENS_FLIP_BOUND);
    // What the passes are for: at equal GPU time (brute force gets
    // EQUAL_TIME_MARGIN times as much), a smaller error than brute force's.
    c.assert_passes_win();
}

#[test]
fn scenes_without_specular_objects_run_no_caustic_pass() {
    let scene = common::project_scene("tests/one_sphere.toml");
    assert!(!scene.needs_caustics());
    let out = common::render_variant_validated(&scene, RenderVariant::default());
    assert!(out.caustics.is_none(), "caustic passes ran");
    println!("one_sphere: no caustic pass ran (0 s in caustic passes)");
}

/// FLIP between the lens in fog with the caustic passes (beams included)
/// and a long brute-force render.
const LENS_FOG_FLIP_BOUND: f64 = 0.1;

#[test]
fn lens_in_fog_beams_match_the_brute_force_path_tracer() {
    let c = common::compare_with_brute_force("lens_fog", 2048, 64);
    let report = c.fast.caustics.as_ref().expect("the caustic passes ran");
    assert!(report.beam_seconds > 0.0, "the beam pass ran");
    println!(
        "lens in fog: FLIP against brute force at 2048 spp: passes at 64 spp {:.4} (bound {LENS_FOG_FLIP_BOUND})",
        c.flip_fast
    );
    assert!(c.flip_fast < LENS_FOG_FLIP_BOUND);
    // At equal GPU time (brute force gets EQUAL_TIME_MARGIN times as much)
    // the passes' error is below brute force's since the caustic map also
    // serves the floor seen through the fog and the caustic rays reflect off
    // glass too (issue 30: 0.47x measured at 1.41x the time, against issue
    // 30's 0.5x; before, 0.19 against 0.12).
    c.assert_passes_win();
}

/// The glass vessel of the paper's figure 2 at 256x192: the passes at 64 spp
/// against brute force at equal time, both against the cached reference
/// `results/caustics/vessel_reference.exr` (results/caustics/README.md says
/// how it was made and how far it is from converged). Minutes long, so run
/// on demand: `QUADRAY_EQUAL_TIME=results/caustics/equal_time.json cargo
/// test --release --test render -- --ignored glass_vessel`. It asserts what
/// holds today: the passes' FLIP is below brute force's at equal time (the
/// relative MSE, issue 30's measure, is printed and recorded; its target,
/// 0.2x brute force's, is not met).
#[test]
#[ignore]
fn glass_vessel_at_equal_time() {
    let mut scene = common::project_scene("glass_vessel.toml");
    (scene.image.width, scene.image.height, scene.image.seed) = (256, 192, 1);
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("results/caustics/vessel_reference.exr");
    let reference = quadray::jobs::output::read_render_exr(&path).unwrap().output;
    let what = "results/caustics/vessel_reference.exr (the passes at 2048 spp)";
    let c = common::equal_time("glass_vessel", "scenes/glass_vessel.toml", &scene, reference, what, 64);
    assert!(c.flip_fast < c.flip_brute, "FLIP {} not below brute force's {}", c.flip_fast, c.flip_brute);
}
