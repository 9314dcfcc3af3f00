//! Every light type against its analytic irradiance: a diffuse floor of
//! albedo ρ, seen from straight above, lit by one light at a time, with
//! direct lighting only (max_depth 1). The radiance of a floor point x is
//! ρ/π · E(x); the test reconstructs x from the depth AOV of each pixel
//! centre and compares the rendered radiance with the expected one.
//!
//! E(x): point light I cos θ / d²; directional light E_sun cos θ; sphere
//! light π L (r/d)² cos θ (a sphere above the horizon acts as a point source
//! of intensity π r² L); rect light: numerical quadrature (f64, 200 x 200)
//! of L cos θ cos θ_l / d² over its area; uniform environment: π L_env (the
//! floor sees the whole upper hemisphere); environment map: quadrature of
//! L(d) cos θ over its texels.
//!
//! Bounds: the mean signed relative error over the lit pixels (the bias)
//! within `BIAS_BOUND`; no pixel further than `OUTLIER_SIGMAS` times the RMS
//! relative error from its expected value at two seeds (a local bias shows
//! as a repeated outlier; see `check_scene`); the RMS (Monte Carlo noise at 256 spp, plus the jittered pixel footprint
//! against a pixel-centre reference) below `RMS_BOUND`. Pixels where a
//! jittered camera ray can see a sphere light directly are skipped.

use crate::common;

use glam::{DAffine3, DVec3, Vec3};
use quadray::model::geometry::{Aabb, FunctionalObject, Quadric};
use quadray::model::scene::{Light, Material, Scene};
use quadray::passes::render::PIXEL_FILTER_REACH;
use quadray::passes::{RenderVariant, SamplerMode};

const ALBEDO: f64 = 0.7;
const BIAS_BOUND: f64 = 0.01;
const OUTLIER_SIGMAS: f64 = 6.0;
const RMS_BOUND: f64 = 0.1;

fn floor_scene() -> Scene {
    let floor = FunctionalObject {
        base: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
        perturbations: vec![],
        clip: Some(Aabb::new(DVec3::new(-20.0, -0.5, -20.0), DVec3::new(20.0, 0.5, 20.0))),
    };
    let mut scene = common::scene_with(vec![common::object("floor", floor, DAffine3::IDENTITY)]);
    scene.materials = vec![Material::diffuse("floor", Vec3::splat(ALBEDO as f32))];
    scene.camera.position = DVec3::new(0.0, 8.0, 0.0);
    scene.camera.look_at = DVec3::ZERO;
    scene.camera.up = DVec3::new(0.0, 0.0, -1.0);
    scene.camera.vfov_degrees = 60.0;
    scene.image.width = 40;
    scene.image.height = 40;
    scene.image.spp = 256;
    scene.image.max_depth = 1;
    scene.lights.clear();
    scene
}

fn rect_irradiance(x: DVec3, corner: DVec3, eu: DVec3, ev: DVec3, l: f64) -> f64 {
    let n = eu.cross(ev);
    let area = n.length();
    let nl = n / area;
    let k = 200;
    let mut sum = 0.0;
    for i in 0..k {
        for j in 0..k {
            let q = corner + eu * ((i as f64 + 0.5) / k as f64) + ev * ((j as f64 + 0.5) / k as f64);
            let w = q - x;
            let d2 = w.length_squared();
            let wi = w / d2.sqrt();
            let cos_r = wi.y.max(0.0);
            let cos_l = (-nl.dot(wi)).max(0.0);
            sum += l * cos_r * cos_l / d2;
        }
    }
    sum * area / (k * k) as f64
}

fn check(name: &str, light: Option<Light>, background: f64, irradiance: impl Fn(DVec3) -> f64) {
    let mut scene = floor_scene();
    scene.lights.extend(light);
    scene.background = Vec3::splat(background as f32);
    check_scene(name, scene, irradiance);
}

/// The signed relative error of every lit pixel's radiance (`None` for a
/// pixel left out: background, a visible sphere light, or too little light)
/// in a render of `scene` with `sampler`.
fn pixel_errors(scene: &Scene, sampler: SamplerMode, irradiance: &impl Fn(DVec3) -> f64) -> Vec<Option<f64>> {
    let visible_sphere = match scene.lights.first() {
        Some(Light::Sphere { centre, radius, .. }) => Some((*centre, *radius)),
        _ => None,
    };
    let out = common::render_variant_validated(scene, RenderVariant { sampler, ..Default::default() });
    let (w, h) = (out.width as usize, out.height as usize);
    let half = (0.5 * scene.camera.vfov_degrees).to_radians().tan();
    let mut errors = vec![None; w * h];
    for y in 0..h {
        for x in 0..w {
            let i = y * w + x;
            let depth = out.aov[i].depth as f64;
            if !depth.is_finite() {
                continue;
            }
            // Camera basis for a camera looking down -y with up -z: right = +x.
            let nx = 2.0 * (x as f64 + 0.5) / w as f64 - 1.0;
            let ny = 1.0 - 2.0 * (y as f64 + 0.5) / h as f64;
            let dir = DVec3::new(nx * half * w as f64 / h as f64, -1.0, -ny * half).normalize();
            if let Some((c, r)) = visible_sphere {
                // Some camera ray of the pixel can see the light: the
                // jittered rays land up to PIXEL_FILTER_REACH pixels from
                // the pixel's centre, a pixel spans 2·tan(fov/2)/h radians
                // at the image centre (less at its edges), and the light
                // subtends asin(r/|oc|) around its centre: skip.
                let oc = c - scene.camera.position;
                let angle = oc.normalize().dot(dir).clamp(-1.0, 1.0).acos();
                let reach = PIXEL_FILTER_REACH as f64 * 2.0 * half / h as f64;
                if angle < (r / oc.length()).asin() + reach {
                    continue;
                }
            }
            let p = scene.camera.position + depth * dir;
            let expected = ALBEDO / std::f64::consts::PI * irradiance(p);
            if expected < 1e-3 {
                continue;
            }
            errors[i] = Some((out.radiance[i][0] as f64 - expected) / expected);
        }
    }
    errors
}

/// The relative errors of the lit pixels, summed up.
struct ErrorStats {
    /// Lit pixels.
    lit: usize,
    /// Mean signed error.
    bias: f64,
    /// RMS error.
    rms: f64,
    /// Largest error in magnitude.
    worst: f64,
}

fn error_stats(errors: &[Option<f64>]) -> ErrorStats {
    let lit: Vec<f64> = errors.iter().flatten().copied().collect();
    let n = lit.len() as f64;
    ErrorStats {
        lit: lit.len(),
        bias: lit.iter().sum::<f64>() / n,
        rms: (lit.iter().map(|e| e * e).sum::<f64>() / n).sqrt(),
        worst: lit.iter().fold(0.0f64, |m, e| m.max(e.abs())),
    }
}

/// The largest error that two renders repeat at one pixel: for each pixel
/// lit in both, the smaller of its two errors when they share a sign.
fn repeated_error(a: &[Option<f64>], b: &[Option<f64>]) -> f64 {
    a.iter()
        .zip(b)
        .filter_map(|(ea, eb)| match (ea, eb) {
            (Some(ea), Some(eb)) if ea * eb > 0.0 => Some(ea.abs().min(eb.abs())),
            _ => None,
        })
        .fold(0.0f64, f64::max)
}

/// The repeated-error statistic on synthetic errors: noise with the heavy
/// tail of Sobol points (1 pixel in 400 at 16 RMS, elsewhere Gaussian)
/// stays under the bound, and a local bias of 8 RMS at one pixel does not.
#[test]
fn repeated_errors_find_a_local_bias_and_pass_heavy_tailed_noise() {
    use rand::Rng;
    let mut rng = rand_pcg::Pcg64::new(7, 11);
    let rms = 0.01;
    let mut noise = |spike: bool| -> Vec<Option<f64>> {
        (0..1600)
            .map(|i| {
                // Box-Muller.
                let (u, v): (f64, f64) = (rng.gen::<f64>().max(1e-12), rng.gen());
                let g = (-2.0 * u.ln()).sqrt() * (std::f64::consts::TAU * v).cos() * rms;
                Some(if spike && i % 400 == 17 { 16.0 * rms } else { g })
            })
            .collect()
    };
    let (a, b) = (noise(true), noise(false));
    let (c, d) = (noise(false), noise(true));
    assert!(repeated_error(&a, &b) <= OUTLIER_SIGMAS * rms, "noise with spikes at one seed");
    assert!(repeated_error(&c, &d) <= OUTLIER_SIGMAS * rms, "noise with spikes at the other seed");
    let (mut e, mut f) = (noise(false), noise(false));
    e[900] = Some(8.0 * rms + e[900].unwrap());
    f[900] = Some(8.0 * rms + f[900].unwrap());
    assert!(repeated_error(&e, &f) > OUTLIER_SIGMAS * rms, "a local bias of 8 RMS goes unseen");
}

/// Renders `scene` with the renderer's sampler (Owen-scrambled Sobol points)
/// at two seeds and checks the bias, the RMS and the local bias.
///
/// A local bias (a pixel whose expectation is wrong) shows at the same
/// pixel, with the same sign, whatever the seed; noise does not. With
/// independent samples the errors are near Gaussian and one render's worst
/// pixel against its RMS finds a local bias, but Sobol points make the
/// per-pixel error heavy-tailed: most pixels converge much faster than
/// Monte Carlo (their RMS is 5x lower at 256 spp under the rect light)
/// while a few samples' rare events, e.g. a BSDF-sampled ray that finds the
/// light, keep the Monte Carlo rate, so a single pixel can err 16 RMS and
/// the next seed puts that pixel at 1-2 RMS (measured: the rect light's
/// worst pixel, 16.5 RMS at 256 spp, 0.123, falls to 0.037 at 1024 spp and
/// 0.013 at 4096 spp, where other pixels take the lead). So the bound is on
/// what repeats: for each pixel the smaller of its two errors when they
/// share a sign, at most `OUTLIER_SIGMAS` times the larger RMS
/// (`repeated_errors_find_a_local_bias_and_pass_heavy_tailed_noise`).
///
/// The rect light's bias, +0.0025 with both samplers at 256 to 4096 spp, is
/// the reference's: it is each pixel's centre, and the Gaussian pixel
/// filter (σ 0.5 px) averages the convex irradiance around it (quadrature
/// of that average gives +0.0025 over the image).
fn check_scene(name: &str, scene: Scene, irradiance: impl Fn(DVec3) -> f64) -> f64 {
    let mut second = scene.clone();
    second.image.seed = scene.image.seed.wrapping_add(1);
    let a = pixel_errors(&scene, SamplerMode::Sobol, &irradiance);
    let b = pixel_errors(&second, SamplerMode::Sobol, &irradiance);
    let ErrorStats { lit, bias: bias_a, rms: rms_a, worst } = error_stats(&a);
    let ErrorStats { bias: bias_b, rms: rms_b, .. } = error_stats(&b);
    let rms = rms_a.max(rms_b);
    let repeated = repeated_error(&a, &b);
    println!(
        "{name}: {lit} lit pixels, bias {bias_a:+.4} / {bias_b:+.4} (bound ±{BIAS_BOUND}), RMS {rms_a:.4} / \
         {rms_b:.4} (bound {RMS_BOUND}), worst {worst:.4}, worst repeated {repeated:.4} = {:.1} RMS (bound \
         {OUTLIER_SIGMAS})",
        repeated / rms.max(1e-12)
    );
    assert!(lit > 500, "{name}: too few lit pixels");
    for bias in [bias_a, bias_b] {
        assert!(bias.abs() <= BIAS_BOUND, "{name}: bias {bias}");
    }
    assert!(rms <= RMS_BOUND, "{name}: RMS {rms}");
    assert!(repeated <= OUTLIER_SIGMAS * rms.max(1e-4), "{name}: a pixel errs {repeated} at both seeds");
    rms_a
}

/// The same checks with independent samples, whose per-pixel errors are
/// near Gaussian: one render, and its worst pixel against its RMS.
fn check_independent(name: &str, scene: &Scene, irradiance: impl Fn(DVec3) -> f64) -> f64 {
    let errors = pixel_errors(scene, SamplerMode::Independent, &irradiance);
    let ErrorStats { lit, bias, rms, worst } = error_stats(&errors);
    println!(
        "{name}, independent samples: {lit} lit pixels, bias {bias:+.4}, RMS {rms:.4}, worst {worst:.4} = {:.1} RMS",
        worst / rms.max(1e-12)
    );
    assert!(lit > 500, "{name}: too few lit pixels");
    assert!(bias.abs() <= BIAS_BOUND, "{name}: bias {bias}");
    assert!(rms <= RMS_BOUND, "{name}: RMS {rms}");
    assert!(worst <= OUTLIER_SIGMAS * rms.max(1e-4), "{name}: outlier {worst}");
    rms
}

#[test]
fn point_light() {
    let pos = DVec3::new(1.0, 3.0, -0.5);
    let i = 20.0;
    check("point", Some(Light::Point { position: pos, intensity: Vec3::splat(i as f32) }), 0.0, |x| {
        let w = pos - x;
        i * (w.y / w.length()) / w.length_squared()
    });
}

#[test]
fn directional_light() {
    let dir = DVec3::new(0.3, 1.0, 0.2).normalize();
    check("directional", Some(Light::Directional { direction: dir, irradiance: Vec3::splat(2.0) }), 0.0, |_| {
        2.0 * dir.y
    });
}

#[test]
fn sphere_light() {
    let (c, r, l) = (DVec3::new(-1.0, 2.5, 1.0), 0.4, 5.0);
    check("sphere", Some(Light::Sphere { centre: c, radius: r, radiance: Vec3::splat(l as f32) }), 0.0, |x| {
        let w = c - x;
        std::f64::consts::PI * l * r * r / w.length_squared() * (w.y / w.length())
    });
}

/// Also rendered with independent samples: both samplers pass, and the
/// Sobol points' RMS error is the lower.
#[test]
fn rect_light() {
    let (corner, eu, ev, l) = (DVec3::new(-1.5, 2.0, -1.0), DVec3::new(3.0, 0.0, 0.0), DVec3::new(0.0, 0.0, 2.0), 4.0);
    let mut scene = floor_scene();
    scene.lights.push(Light::Rect { corner, edge_u: eu, edge_v: ev, radiance: Vec3::splat(l as f32) });
    let irradiance = |x: DVec3| rect_irradiance(x, corner, eu, ev, l);
    let independent = check_independent("rect", &scene, irradiance);
    let sobol = check_scene("rect", scene, irradiance);
    println!("rect: RMS of Sobol points / independent samples {:.3}", sobol / independent);
    assert!(
        sobol < independent,
        "rect: the Sobol points' RMS {sobol} is not below the independent samples' {independent}"
    );
}

#[test]
fn uniform_environment() {
    check("environment", None, 0.5, |_| std::f64::consts::PI * 0.5);
}

/// An environment map (a procedural sky with a small bright sun) lighting
/// the floor through importance sampling of the map: E = ∫ L(d) cos⁺θ dω,
/// computed by quadrature over the map's texels (piecewise constant).
#[test]
fn environment_map() {
    use quadray::model::sampling::envmap::{procedural_sky, uv_to_direction, EnvironmentMap};
    use quadray::model::scene::EnvironmentMapSettings;
    let sky = procedural_sky(128, 64);
    let map = EnvironmentMap::from_texture(&sky, 0.5);
    let (w, h) = (map.width as usize, map.height as usize);
    let mut e = 0.0;
    let k = 8;
    for j in 0..h {
        for i in 0..w {
            let l = map.texel_radiance(i, j).x;
            for a in 0..k {
                for b in 0..k {
                    let u = (i as f64 + (a as f64 + 0.5) / k as f64) / w as f64;
                    let v = (j as f64 + (b as f64 + 0.5) / k as f64) / h as f64;
                    let d = uv_to_direction(u, v);
                    // dω = 2π² sin θ du dv.
                    let dw =
                        2.0 * std::f64::consts::PI.powi(2) * (std::f64::consts::PI * v).sin() / (w * h * k * k) as f64;
                    e += l * d.y.max(0.0) * dw;
                }
            }
        }
    }
    let mut scene = floor_scene();
    scene.textures.push(sky);
    scene.environment = Some(EnvironmentMapSettings { texture: scene.textures.len() - 1, scale: 0.5 });
    check_scene("environment map", scene, |_| e);
}
