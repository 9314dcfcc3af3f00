//! Helpers shared by the GPU tests: a validated Vulkan context and
//! scenes built in code.
#![allow(dead_code)]

use std::sync::Arc;

use glam::{DAffine3, DQuat, DVec3, EulerRot, Vec3};
use quadray::model::geometry::{Aabb, FunctionalObject, Perturbation, Quadric};
use quadray::model::scene::{Camera, ImageSettings, Light, Material, Scene, SceneObject};
use quadray::vk::{Commands, Context, ValidationCounters};

/// A headless context with the Khronos validation layer on.
pub fn context() -> Context {
    let _ = env_logger::builder().is_test(true).filter_level(log::LevelFilter::Warn).try_init();
    Context::new(true).expect("a Vulkan device with ray queries and the validation layer (run `make setup`)")
}

/// The scene file `scenes/<relative>` of the project, parsed.
pub fn project_scene(relative: &str) -> Scene {
    let path = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes").join(relative);
    quadray::model::scene::load_scene(&path).unwrap_or_else(|e| panic!("{}: {e}", path.display()))
}

/// Every file under `dir`, in every folder, sorted.
pub fn files_under(dir: &std::path::Path) -> Vec<std::path::PathBuf> {
    let mut out = Vec::new();
    let mut folders = vec![dir.to_path_buf()];
    while let Some(folder) = folders.pop() {
        for entry in std::fs::read_dir(&folder).unwrap() {
            let path = entry.unwrap().path();
            if path.is_dir() {
                folders.push(path);
            } else {
                out.push(path);
            }
        }
    }
    out.sort();
    out
}

/// Every test scene (`scenes/tests/*.toml`) at 64x48 and 4 spp with its own
/// depth, by file name, sorted; at least nine of them.
pub fn test_scenes() -> Vec<(String, Scene)> {
    let dir = std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join("scenes/tests");
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".toml"))
        .collect();
    names.sort();
    assert!(names.len() >= 9, "the test scenes: {names:?}");
    names
        .into_iter()
        .map(|name| {
            let mut scene = project_scene(&format!("tests/{name}"));
            let depth = scene.image.max_depth;
            set_image(&mut scene, (64, 48), 4, depth);
            (name, scene)
        })
        .collect()
}

/// Points the camera of `scene` from `position` at `look_at`.
pub fn aim(scene: &mut Scene, position: DVec3, look_at: DVec3) {
    scene.camera.position = position;
    scene.camera.look_at = look_at;
}

/// Sets the image size, samples per pixel and path depth of `scene`.
pub fn set_image(scene: &mut Scene, (width, height): (u32, u32), spp: u32, max_depth: u32) {
    scene.image.width = width;
    scene.image.height = height;
    scene.image.spp = spp;
    scene.image.max_depth = max_depth;
}

/// A validated context, its validation counters and a command buffer: what
/// the GPU tests that dispatch probes start from.
pub fn gpu() -> (Context, Arc<ValidationCounters>, Commands) {
    let ctx = context();
    let counters = ctx.counters();
    let cmds = Commands::new(&ctx.device).expect("a command pool on the device");
    (ctx, counters, cmds)
}

/// Ends a GPU test that checks a table of bounds: drops the command pool and
/// the device (so that leaks reported at destruction count), fails on any
/// validation error, then on any bound a row of the table broke.
pub fn finish_bounded(ctx: Context, cmds: Commands, counters: &Arc<ValidationCounters>, violations: &[String]) {
    drop(cmds);
    drop(ctx);
    assert_no_validation_errors(counters);
    assert!(violations.is_empty(), "beyond the bounds: {violations:?}");
}

/// Fails when the validation layer reported any error; call after dropping
/// the context so that leaks reported at device destruction count too.
pub fn assert_no_validation_errors(counters: &Arc<ValidationCounters>) {
    assert_eq!(counters.errors(), 0, "the validation layer reported errors (see the log above)");
    println!("validation layer: 0 errors, {} warnings", counters.warnings());
}

/// Renders `scene` on a fresh validated context; fails on any validation
/// error (counted after the device is gone) and on any NaN or Inf pixel.
pub fn render_validated(scene: &Scene) -> quadray::passes::RenderOutput {
    render_variant_validated(scene, Default::default())
}

/// Renders `scene` with `variant` on a fresh validated context; the same
/// checks as [`render_validated`].
pub fn render_variant_validated(
    scene: &Scene,
    variant: quadray::passes::RenderVariant,
) -> quadray::passes::RenderOutput {
    let ctx = context();
    let counters = ctx.counters();
    let out = quadray::render_scene_with(&ctx, scene, variant, &mut |_, _| {}).unwrap();
    drop(ctx);
    assert_no_validation_errors(&counters);
    assert_finite(&out);
    out
}

/// Asserts that no pixel is NaN or infinite and that no sample was (the
/// renderer counts such samples as black and reports them).
pub fn assert_finite(out: &quadray::passes::RenderOutput) {
    assert!(out.radiance.iter().flatten().all(|v| v.is_finite()), "non-finite pixel");
    assert_eq!(out.dropped_samples, 0, "samples came out NaN or infinite");
}

/// `out`, after [`assert_finite`].
pub fn finite(out: quadray::passes::RenderOutput) -> quadray::passes::RenderOutput {
    assert_finite(&out);
    out
}

/// Statistics of every channel of every pixel against a value every pixel
/// should have (furnace tests).
pub struct UniformStats {
    /// Mean over pixels and channels.
    pub mean: f64,
    /// Standard error of that mean (sample standard deviation / √n).
    pub standard_error: f64,
    /// Largest |value − expected|.
    pub worst: f64,
}

impl UniformStats {
    pub fn of(out: &quadray::passes::RenderOutput, expected: f64) -> Self {
        let values: Vec<f64> = out.radiance.iter().flat_map(|p| p.map(f64::from)).collect();
        let n = values.len() as f64;
        let mean = values.iter().sum::<f64>() / n;
        let sigma = (values.iter().map(|v| (v - mean).powi(2)).sum::<f64>() / (n - 1.0)).sqrt();
        let worst = values.iter().map(|v| (v - expected).abs()).fold(0.0, f64::max);
        Self { mean, standard_error: sigma / n.sqrt(), worst }
    }
}

/// A uniformly random unit vector (rejection from the unit ball).
pub fn random_unit(rng: &mut rand_pcg::Pcg64) -> DVec3 {
    use rand::Rng;
    loop {
        let v = DVec3::new(rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0), rng.gen_range(-1.0..1.0));
        let l = v.length_squared();
        if l > 1e-6 && l <= 1.0 {
            return v / l.sqrt();
        }
    }
}

/// `n` bumps spread over a sphere of radius `on` (see `geometry::scatter`).
pub fn spread_bumps(n: usize, on: f64, r: f64, f: f64, alternate: bool) -> Vec<Perturbation> {
    quadray::model::geometry::scatter::spread_bumps(n, DVec3::splat(on), r, f, alternate)
}

/// An object from its parts.
pub fn object(name: &str, shape: FunctionalObject, transform: DAffine3) -> SceneObject {
    SceneObject { name: name.into(), shape, transform, material: 0, uv: Default::default() }
}

/// A transform from scale, Euler XYZ angles in degrees, and translation.
pub fn placement(scale: DVec3, degrees: DVec3, translate: DVec3) -> DAffine3 {
    let r = DQuat::from_euler(EulerRot::XYZ, degrees.x.to_radians(), degrees.y.to_radians(), degrees.z.to_radians());
    DAffine3::from_scale_rotation_translation(scale, r, translate)
}

/// A scene around `objects` with one grey material and one point light.
pub fn scene_with(objects: Vec<SceneObject>) -> Scene {
    Scene {
        image: ImageSettings::minimal(64, 48),
        camera: Camera::still(DVec3::new(0.0, 2.0, 8.0), DVec3::ZERO, DVec3::Y, 40.0),
        background: Vec3::ZERO,
        materials: vec![Material::diffuse("grey", Vec3::splat(0.8))],
        objects,
        lights: vec![Light::Point { position: DVec3::new(3.0, 6.0, 4.0), intensity: Vec3::splat(40.0) }],
        textures: vec![],
        environment: None,
        fog: None,
        caustics: Default::default(),
        volume: Default::default(),
    }
}

/// The five-plus objects of the geometry tests: a sphere with 150 bumps and
/// dents, a clipped one-sheet hyperboloid vessel with bulges, a rotated and
/// non-uniformly scaled ellipsoid with dents, a clipped floor plane, a
/// clipped cone with bumps, and a clipped paraboloid given by its coefficients.
pub fn test_objects() -> Vec<SceneObject> {
    let sphere = FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::ONE),
        perturbations: spread_bumps(150, 1.0, 0.18, 1.5, true),
        clip: None,
    };
    // One sheet: 1 - (x² + z² - (0.8 y)²) / 0.4², clipped to a vessel.
    let r2 = 0.4 * 0.4;
    let hyper = FunctionalObject {
        base: Quadric::from_coefficients([-1.0 / r2, 0.64 / r2, -1.0 / r2, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0]),
        perturbations: (0..20)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 20.0;
                let y = -0.6 + 1.2 * (i % 5) as f64 / 4.0;
                let rr = (r2 + 0.64 * y * y).sqrt();
                let c = DVec3::new(rr * a.cos(), y, rr * a.sin());
                Perturbation { quadric: Quadric::ellipsoid(c, DVec3::splat(0.25)), form_factor: 4.0 }
            })
            .collect(),
        clip: Some(Aabb::new(DVec3::new(-1.5, -0.8, -1.5), DVec3::new(1.5, 0.8, 1.5))),
    };
    let ellipsoid = FunctionalObject {
        base: Quadric::ellipsoid(DVec3::ZERO, DVec3::new(1.0, 0.5, 0.7)),
        perturbations: spread_bumps(12, 0.6, 0.3, -2.0, false),
        clip: None,
    };
    let floor = FunctionalObject {
        base: Quadric::from_coefficients([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0]),
        perturbations: vec![],
        clip: Some(Aabb::new(DVec3::new(-6.0, -0.5, -6.0), DVec3::new(6.0, 0.5, 6.0))),
    };
    // Cone around y with half-angle 25°, apex at the origin, clipped below it.
    let k = 25f64.to_radians().tan().powi(2);
    let cone = FunctionalObject {
        base: Quadric::from_coefficients([-1.0, k, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0]),
        perturbations: (0..8)
            .map(|i| {
                let a = i as f64 * std::f64::consts::TAU / 8.0;
                let y = -0.9;
                let rr = k.sqrt() * 0.9;
                let c = DVec3::new(rr * a.cos(), y, rr * a.sin());
                Perturbation { quadric: Quadric::ellipsoid(c, DVec3::splat(0.15)), form_factor: 3.0 }
            })
            .collect(),
        clip: Some(Aabb::new(DVec3::new(-1.0, -1.2, -1.0), DVec3::new(1.0, -0.05, 1.0))),
    };
    // Paraboloid y = 0.8 (x² + z²), inside above, as general coefficients.
    let paraboloid = FunctionalObject {
        base: Quadric::from_coefficients([-0.8, 0.0, -0.8, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0]),
        perturbations: vec![Perturbation {
            quadric: Quadric::ellipsoid(DVec3::new(0.3, 0.3, 0.0), DVec3::new(0.3, 0.2, 0.3)),
            form_factor: -5.0,
        }],
        clip: Some(Aabb::new(DVec3::new(-1.0, 0.0, -1.0), DVec3::new(1.0, 0.8, 1.0))),
    };
    vec![
        object("bumpy sphere", sphere, placement(DVec3::ONE, DVec3::ZERO, DVec3::new(0.0, 1.0, 0.0))),
        object("vessel", hyper, placement(DVec3::ONE, DVec3::new(0.0, 20.0, 0.0), DVec3::new(2.5, 0.8, -1.0))),
        object(
            "ellipsoid",
            ellipsoid,
            placement(DVec3::new(1.0, 1.5, 0.8), DVec3::new(30.0, 45.0, 10.0), DVec3::new(-2.5, 0.9, 0.5)),
        ),
        object("floor", floor, DAffine3::IDENTITY),
        object("cone", cone, placement(DVec3::ONE, DVec3::new(0.0, 0.0, 180.0), DVec3::new(0.5, 1.3, 2.5))),
        object(
            "paraboloid",
            paraboloid,
            placement(DVec3::splat(1.2), DVec3::new(0.0, 0.0, 0.0), DVec3::new(-1.0, 0.2, -3.0)),
        ),
    ]
}

/// A scene file's render with the caustic and volume passes against the
/// brute-force path tracer (both passes off), at equal GPU time.
pub struct BruteForceComparison {
    /// Brute force at `reference_spp`.
    pub reference: quadray::passes::RenderOutput,
    /// With the passes, at `spp`.
    pub fast: quadray::passes::RenderOutput,
    /// Brute force with EQUAL_TIME_MARGIN times the GPU time of `fast`.
    pub brute: quadray::passes::RenderOutput,
    /// FLIP of `fast` against `reference`.
    pub flip_fast: f64,
    /// FLIP of `brute` against `reference`.
    pub flip_brute: f64,
    /// Relative MSE of `fast` against `reference` (linear radiance).
    pub rel_fast: f64,
    /// Relative MSE of `brute` against `reference`.
    pub rel_brute: f64,
}

impl BruteForceComparison {
    /// Asserts what the passes are for: at equal time (brute force gets
    /// EQUAL_TIME_MARGIN times their GPU time), a smaller relative MSE than
    /// brute force's.
    pub fn assert_passes_win(&self) {
        assert!(
            self.rel_fast < self.rel_brute,
            "passes relMSE {} not below brute force's {} at {:.2}x their GPU time",
            self.rel_fast,
            self.rel_brute,
            self.brute.seconds / self.fast.seconds
        );
    }
}

/// How much more GPU time than the passes' render the brute-force render
/// gets. GPU times on lavapipe vary by 10 - 30 % between runs, so brute
/// force is given half as much time again: a pass that still wins pays
/// whatever the noise did.
pub const EQUAL_TIME_MARGIN: f64 = 1.5;

/// Renders `scenes/tests/{name}.toml` three ways (see
/// [`BruteForceComparison`]): the reference by brute force at
/// `reference_spp`, then as [`equal_time`].
pub fn compare_with_brute_force(name: &str, reference_spp: u32, spp: u32) -> BruteForceComparison {
    use quadray::passes::RenderVariant;
    let mut scene = project_scene(&format!("tests/{name}.toml"));
    let brute_force = RenderVariant { caustics: false, volume: false, ..Default::default() };
    scene.image.spp = reference_spp;
    let reference = render_variant_validated(&scene, brute_force);
    assert!(reference.caustics.is_none() && reference.volume_seconds.is_none());
    // Other random numbers than the reference's (the same seed would make
    // the first `spp` samples of the reference those of `brute`).
    scene.image.seed = scene.image.seed.wrapping_add(1);
    let file = format!("scenes/tests/{name}.toml");
    equal_time(name, &file, &scene, reference, &format!("brute force at {reference_spp} spp"), spp)
}

/// `scene` (from `file`) with the passes at `spp` and by brute force at
/// EQUAL_TIME_MARGIN times their GPU time (measured from a render at
/// `spp`), both against `reference` (`what`: how it was made). With
/// QUADRAY_TEST_IMAGES set to a folder, writes the three images there as
/// `{name}_*.png`; with QUADRAY_EQUAL_TIME set to a JSON file, records the
/// figures there as `{"scene", "brute_relmse", "passes_relmse", "brute_s",
/// "passes_s"}` (replacing the scene's earlier entry; issue 30's
/// `results/caustics/equal_time.json`).
pub fn equal_time(
    name: &str,
    file: &str,
    scene: &quadray::model::scene::Scene,
    reference: quadray::passes::RenderOutput,
    what: &str,
    spp: u32,
) -> BruteForceComparison {
    use quadray::passes::RenderVariant;
    let brute_force = RenderVariant { caustics: false, volume: false, ..Default::default() };
    let mut scene = scene.clone();
    scene.image.spp = spp;
    // Untimed: lavapipe compiles each shader variant at its first dispatch
    // (into its disk cache), and that time would count as GPU time.
    let mut small = scene.clone();
    (small.image.width, small.image.height, small.image.spp) = (8, 8, 1);
    render_variant_validated(&small, RenderVariant::default());
    render_variant_validated(&small, brute_force);
    let fast = render_variant_validated(&scene, RenderVariant::default());
    let probe = render_variant_validated(&scene, brute_force);
    let per_sample = probe.seconds / spp as f64;
    scene.image.spp = ((EQUAL_TIME_MARGIN * fast.seconds / per_sample).ceil() as u32).max(spp);
    let brute = if scene.image.spp == spp { probe } else { render_variant_validated(&scene, brute_force) };
    let flip_fast = quadray::tools::metrics::flip_mean(&reference, &fast, 0.0).unwrap();
    let flip_brute = quadray::tools::metrics::flip_mean(&reference, &brute, 0.0).unwrap();
    let rel_fast = quadray::tools::metrics::relative_mse(&reference, &fast).unwrap();
    let rel_brute = quadray::tools::metrics::relative_mse(&reference, &brute).unwrap();
    println!(
        "{name}: passes at {spp} spp in {:.2} s GPU; brute force at {} spp in {:.2} s ({:.2}x the time); \
         against {what}: relMSE {rel_fast:.5} against {rel_brute:.5} ({:.2}x), FLIP {flip_fast:.4} against \
         {flip_brute:.4}",
        fast.seconds,
        brute.spp,
        brute.seconds,
        brute.seconds / fast.seconds,
        rel_fast / rel_brute
    );
    if let Ok(dir) = std::env::var("QUADRAY_TEST_IMAGES") {
        let dir = std::path::Path::new(&dir);
        for (kind, out) in [("reference", &reference), ("passes", &fast), ("brute", &brute)] {
            quadray::jobs::output::write_png(out, 0.0, &dir.join(format!("{name}_{kind}.png"))).unwrap();
        }
    }
    if let Ok(path) = std::env::var("QUADRAY_EQUAL_TIME") {
        let entry = serde_json::json!({
            "scene": file,
            "size": [scene.image.width, scene.image.height],
            "reference": what,
            "passes_spp": spp,
            "brute_spp": brute.spp,
            "brute_relmse": rel_brute,
            "passes_relmse": rel_fast,
            "brute_s": brute.seconds,
            "passes_s": fast.seconds,
        });
        record_equal_time(std::path::Path::new(&path), entry);
    }
    BruteForceComparison { reference, fast, brute, flip_fast, flip_brute, rel_fast, rel_brute }
}

/// Adds `entry` to the JSON array in `path` (created when missing), in
/// place of an entry of the same scene; tests that run at once take turns.
fn record_equal_time(path: &std::path::Path, entry: serde_json::Value) {
    static LOCK: std::sync::Mutex<()> = std::sync::Mutex::new(());
    let _turn = LOCK.lock().unwrap_or_else(|e| e.into_inner());
    let mut all: Vec<serde_json::Value> = std::fs::read_to_string(path)
        .ok()
        .map(|s| serde_json::from_str(&s).unwrap_or_else(|e| panic!("{}: {e}", path.display())))
        .unwrap_or_default();
    all.retain(|e| e["scene"] != entry["scene"]);
    all.push(entry);
    all.sort_by(|a, b| a["scene"].as_str().cmp(&b["scene"].as_str()));
    std::fs::write(path, serde_json::to_string_pretty(&all).unwrap() + "\n").unwrap();
}

/// How two renders of one scene differ where they should agree to rounding
/// (two backends, two drivers): the largest channel difference relative to
/// max(1, the first's value), mean FLIP, relative MSE, and the pixels with a
/// channel differing by more than `channel_bound` (same measure).
pub struct Agreement {
    pub max_channel: f64,
    pub flip: f64,
    pub relmse: f64,
    pub differing: usize,
    pub pixels: usize,
}

impl Agreement {
    pub fn of(a: &quadray::passes::RenderOutput, b: &quadray::passes::RenderOutput, channel_bound: f64) -> Self {
        let rel = |x: f32, y: f32| f64::from((x - y).abs()) / f64::from(x.abs()).max(1.0);
        let max_channel =
            a.radiance.iter().flatten().zip(b.radiance.iter().flatten()).map(|(&x, &y)| rel(x, y)).fold(0.0, f64::max);
        let differing = a
            .radiance
            .iter()
            .zip(&b.radiance)
            .filter(|(p, q)| p.iter().zip(q.iter()).any(|(&x, &y)| rel(x, y) > channel_bound))
            .count();
        Self {
            max_channel,
            flip: quadray::tools::metrics::flip_mean(a, b, 0.0).unwrap(),
            relmse: quadray::tools::metrics::relative_mse(a, b).unwrap(),
            differing,
            pixels: a.radiance.len(),
        }
    }

    /// The heading of [`Agreement::row`]'s columns.
    pub fn header() -> String {
        format!("{:>12} {:>10} {:>12} {:>14}", "max channel", "FLIP", "relMSE", "pixels differ")
    }

    /// The table row: max channel, FLIP, relMSE, pixels differing.
    pub fn row(&self) -> String {
        format!(
            "{:>12.2e} {:>10.6} {:>12.2e} {:>5} of {}",
            self.max_channel, self.flip, self.relmse, self.differing, self.pixels
        )
    }
}
