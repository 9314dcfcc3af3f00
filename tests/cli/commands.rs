//! The `quadray` binary end to end, always with the Khronos validation layer
//! (the command fails if the layer reports an error):
//!
//! - a unit sphere seen from (0, 0, 5): the EXR's AOVs match the analytic
//!   ray-sphere intersection of every pixel-centre ray (depth, world-space
//!   normal, albedo; +inf, 0, 0 on a miss), the radiance is finite, equals
//!   the background on misses, albedo · background (the uniform environment
//!   seen by a convex object) on the side facing away from the point light
//!   and that plus the Lambert value on the lit side; the PNG has the scene's
//!   size and the tone-mapped background;
//! - `--half` writes half-float channels, `-o NAME.exr` / `-o NAME.png` only
//!   that file, the size flags override the scene, `QUADRAY_VALIDATION=1`
//!   turns the layer on;
//! - bad scene files, a missing scene file, a missing output directory and an
//!   output that cannot be renamed into place fail with a message naming the
//!   file (and line) and leave nothing behind, not even a temporary file.
//!
//! Without a Vulkan device with ray queries these tests fail with the
//! binary's message (run `make setup`).

use std::ffi::OsStr;
use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use exr::prelude::{read_all_flat_layers_from_file, AnyChannels, FlatSamples, Layer};

/// A unit sphere at the origin, the camera on +z looking at it.
const SPHERE_SCENE: &str = r#"# A unit sphere for tests/cli/commands.rs; the test computes every pixel analytically.
background = [0.1, 0.2, 0.3]

[image]
width = 40
height = 30
spp = 25656
seed = 3
exposure = 1.0

[camera]
position = [0, 0, 5]
look_at = [0, 0, 0]
fov = 30

[[materials]]
name = "paint"
albedo = [0.6, 0.4, 0.2]

[[objects]]
name = "ball"
material = "paint"
sphere = { radius = 1 }

[[lights]]
type = "point"
position = [4, 2, 2]
intensity = [20, 20, 20]
"#;

const WIDTH: usize = 40;
const HEIGHT: usize = 30;
const EYE: [f64; 3] = [0.0, 0.0, 5.0];
const FOV_DEGREES: f64 = 30.0;
const ALBEDO: [f32; 3] = [0.6, 0.4, 0.2];
const BACKGROUND: [f32; 3] = [0.1, 0.2, 0.3];
const EXPOSURE: f32 = 1.0;
const LIGHT: [f64; 3] = [4.0, 2.0, 2.0];
const INTENSITY: f64 = 20.0;

/// Command-line arguments from strings and paths, as `&[OsString]`.
macro_rules! args {
    ($($a:expr),* $(,)?) => {
        &[$(std::ffi::OsString::from($a)),*][..]
    };
}

/// Runs the binary in `cwd` with a clean environment for its error output.
fn quadray<S: AsRef<OsStr>>(args: &[S], cwd: &Path, envs: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_quadray"));
    cmd.args(args)
        .current_dir(cwd)
        .stdin(Stdio::null())
        .env("RUST_BACKTRACE", "0")
        .env_remove("RUST_LIB_BACKTRACE")
        .env_remove("QUADRAY_VALIDATION");
    for (k, v) in envs {
        cmd.env(k, v);
    }
    cmd.output().expect("cannot start the quadray binary")
}

fn describe<S: AsRef<OsStr>>(args: &[S]) -> String {
    args.iter().map(|a| a.as_ref().to_string_lossy().into_owned()).collect::<Vec<_>>().join(" ")
}

/// Runs the binary and fails the test with its stderr unless it succeeds.
#[track_caller]
fn render_ok<S: AsRef<OsStr>>(args: &[S], cwd: &Path, envs: &[(&str, &str)]) -> String {
    let out = quadray(args, cwd, envs);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(
        out.status.success(),
        "`quadray {}` failed ({}); a Vulkan device with ray queries and the validation layer are needed \
         (run `make setup`):\n{stderr}",
        describe(args),
        out.status
    );
    stderr
}

/// Runs the binary, expects it to fail and returns its stderr.
#[track_caller]
fn render_fails<S: AsRef<OsStr>>(args: &[S], cwd: &Path) -> String {
    let out = quadray(args, cwd, &[]);
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "`quadray {}` should have failed; stderr:\n{stderr}", describe(args));
    assert!(!stderr.contains("panicked"), "a panic instead of an error message:\n{stderr}");
    stderr
}

/// Sorted names of the entries of `dir` (hidden ones included).
fn entries(dir: &Path) -> Vec<String> {
    let mut names: Vec<String> =
        std::fs::read_dir(dir).unwrap().map(|e| e.unwrap().file_name().to_string_lossy().into_owned()).collect();
    names.sort();
    names
}

fn write_scene(dir: &Path, name: &str, text: &str) -> PathBuf {
    let path = dir.join(name);
    std::fs::write(&path, text).unwrap();
    path
}

/// The only layer of an EXR file, with its channels by name.
struct Exr {
    layer: Layer<AnyChannels<FlatSamples>>,
}

impl Exr {
    fn read(path: &Path) -> Self {
        let image = read_all_flat_layers_from_file(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
        assert_eq!(image.layer_data.len(), 1, "one layer");
        Self { layer: image.layer_data.into_iter().next().unwrap() }
    }

    fn size(&self) -> (usize, usize) {
        (self.layer.size.x(), self.layer.size.y())
    }

    fn names(&self) -> Vec<String> {
        let mut n: Vec<String> = self.layer.channel_data.list.iter().map(|c| c.name.to_string()).collect();
        n.sort();
        n
    }

    fn samples(&self, name: &str) -> &FlatSamples {
        &self
            .layer
            .channel_data
            .list
            .iter()
            .find(|c| c.name.eq(name))
            .unwrap_or_else(|| panic!("no channel {name}"))
            .sample_data
    }

    /// A channel as f32, row 0 at the top.
    fn channel(&self, name: &str) -> Vec<f32> {
        self.samples(name).values_as_f32().collect()
    }

    fn vec3(&self, names: [&str; 3]) -> Vec<[f32; 3]> {
        let [a, b, c] = names.map(|n| self.channel(n));
        (0..a.len()).map(|i| [a[i], b[i], c[i]]).collect()
    }
}

fn sub(a: [f64; 3], b: [f64; 3]) -> [f64; 3] {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

fn normalize(a: [f64; 3]) -> [f64; 3] {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}

/// What the pixel-centre ray of pixel (x, y) sees in `SPHERE_SCENE`,
/// computed in f64 from the camera model of docs/outputs.md: forward (0, 0, -1),
/// right (1, 0, 0) scaled by tan(fov/2)·aspect, up (0, 1, 0) scaled by
/// tan(fov/2), pixel centres at i + ½, row 0 at the top.
struct Expected {
    /// Distance from the ray to the sphere's centre (1 = grazing).
    miss_distance: f64,
    /// Distance along the unit ray to the first hit.
    hit: Option<(f64, [f64; 3])>,
}

fn expected(x: usize, y: usize, width: usize, height: usize) -> Expected {
    let half = (0.5 * FOV_DEGREES).to_radians().tan();
    let aspect = width as f64 / height as f64;
    let ndc_x = 2.0 * (x as f64 + 0.5) / width as f64 - 1.0;
    let ndc_y = 1.0 - 2.0 * (y as f64 + 0.5) / height as f64;
    let d = normalize([ndc_x * half * aspect, ndc_y * half, -1.0]);
    // |eye + s d|² = 1  <=>  s² + 2 b s + |eye|² - 1 = 0 with b = eye · d.
    let b = dot(EYE, d);
    let c = dot(EYE, EYE) - 1.0;
    let miss_distance = (dot(EYE, EYE) - b * b).max(0.0).sqrt();
    let disc = b * b - c;
    let hit = (disc >= 0.0).then(|| {
        let s = -b - disc.sqrt();
        let p = [EYE[0] + s * d[0], EYE[1] + s * d[1], EYE[2] + s * d[2]];
        (s, p) // on the unit sphere the point is its own outward normal
    });
    Expected { miss_distance, hit }
}

fn srgb8(v: f32) -> u8 {
    let v = v.clamp(0.0, 1.0);
    let e = if v <= 0.003_130_8 { 12.92 * v } else { 1.055 * v.powf(1.0 / 2.4) - 0.055 };
    (e * 255.0 + 0.5) as u8
}

#[test]
fn sphere_aovs_radiance_and_png_match_the_analytic_scene() {
    let input = tempfile::tempdir().unwrap();
    let outdir = tempfile::tempdir().unwrap();
    let scene = write_scene(input.path(), "sphere.toml", SPHERE_SCENE);
    let base = outdir.path().join("out");
    let stderr = render_ok(args!["render", &scene, "-o", &base, "--validation"], outdir.path(), &[]);
    assert!(stderr.contains("wrote"), "{stderr}");
    assert_eq!(entries(outdir.path()), ["out.exr", "out.png"]);

    let exr = Exr::read(&outdir.path().join("out.exr"));
    assert_eq!(exr.size(), (WIDTH, HEIGHT));
    let mut want = quadray::jobs::output::EXR_CHANNELS.map(String::from).to_vec();
    want.extend(quadray::jobs::output::EXR_MAX_SAMPLE_CHANNELS.map(String::from));
    want.extend(quadray::jobs::output::EXR_DENOISE_CHANNELS.map(String::from));
    want.sort();
    assert_eq!(exr.names(), want);
    for name in quadray::jobs::output::EXR_CHANNELS
        .iter()
        .chain(&quadray::jobs::output::EXR_MAX_SAMPLE_CHANNELS)
        .chain(&quadray::jobs::output::EXR_DENOISE_CHANNELS)
    {
        assert!(matches!(exr.samples(name), FlatSamples::F32(_)), "{name} should hold 32-bit floats");
    }
    let depth = exr.channel("depth");
    // The largest-sample AOV: between the pixel's mean luminance and spp
    // times it (samples are never negative), a whole sample index below
    // spp; on pixels that see only the background every sample is the
    // background.
    let spp = 25656.0;
    let (largest, index) = (exr.channel("max_sample.Y"), exr.channel("max_sample.index"));
    let luminance = |c: [f32; 3]| 0.2126 * c[0] + 0.7152 * c[1] + 0.0722 * c[2];
    let normal = exr.vec3(["normal.X", "normal.Y", "normal.Z"]);
    let albedo = exr.vec3(["albedo.R", "albedo.G", "albedo.B"]);
    let rgb = exr.vec3(["R", "G", "B"]);
    let [da, db, dc, dx, dy, dz] = quadray::jobs::output::EXR_DENOISE_CHANNELS;
    let feature_albedo = exr.vec3([da, db, dc]);
    let feature_normal = exr.vec3([dx, dy, dz]);
    let mut max_feature_error = 0f64;

    // A pixel covers about 2·tan(15°)·5/30 ≈ 0.09 at the sphere; radiance
    // (jittered over the pixel filter) is checked only where the pixel's
    // neighbourhood agrees, the AOVs (pixel centre) wherever the ray is not grazing.
    let pixel = 2.0 * (0.5 * FOV_DEGREES).to_radians().tan() * EYE[2] / HEIGHT as f64;
    let (mut hits, mut misses, mut lit, mut dark) = (0, 0, 0, 0);
    let mut max_depth_error = 0f64;
    let mut max_normal_error = 0f64;
    let mut max_lit_error = 0f64;
    let mut max_dark_error = 0f64;
    for y in 0..HEIGHT {
        for x in 0..WIDTH {
            let i = y * WIDTH + x;
            let at = format!("pixel ({x}, {y})");
            assert!(rgb[i].iter().all(|v| v.is_finite() && *v >= 0.0), "{at}: radiance {:?}", rgb[i]);
            let mean = luminance(rgb[i]);
            assert!(
                largest[i] >= mean * (1.0 - 1e-4) && largest[i] <= spp * mean * (1.0 + 1e-4),
                "{at}: largest sample {}",
                largest[i]
            );
            assert!(index[i] >= 0.0 && index[i] < spp && index[i].fract() == 0.0, "{at}: sample {}", index[i]);
            let e = expected(x, y, WIDTH, HEIGHT);
            if (e.miss_distance - 1.0).abs() < 1e-3 {
                continue; // grazing: either answer is right
            }
            match e.hit {
                None => {
                    misses += 1;
                    assert_eq!(depth[i], f32::INFINITY, "{at}: depth of a miss");
                    assert_eq!(normal[i], [0.0; 3], "{at}: normal of a miss");
                    assert_eq!(albedo[i], [0.0; 3], "{at}: albedo of a miss");
                    // Camera rays are jittered with the Gaussian pixel
                    // filter (σ = 0.5 px) from 24-bit uniform numbers: at
                    // most σ·√(−2 ln 2⁻²⁴) = 2.89 px from the pixel's centre.
                    if e.miss_distance > 1.0 + 3.0 * pixel {
                        let b = luminance(BACKGROUND);
                        assert!(
                            (largest[i] - b).abs() < 1e-6,
                            "{at}: largest sample {} of the background {b}",
                            largest[i]
                        );
                        for k in 0..3 {
                            // f32 accumulation of 256 samples rounds at ~1e-4 relative.
                            assert!((rgb[i][k] - BACKGROUND[k]).abs() < 2e-4, "{at}: background {:?}", rgb[i]);
                            // The denoiser's features of the environment:
                            // its colour (below 1), no normal.
                            assert!(
                                (feature_albedo[i][k] - BACKGROUND[k]).abs() < 2e-4,
                                "{at}: {:?}",
                                feature_albedo[i]
                            );
                        }
                        assert_eq!(feature_normal[i], [0.0; 3], "{at}: the denoiser's normal of the environment");
                    }
                }
                Some((t, n)) => {
                    hits += 1;
                    let err = (depth[i] as f64 - t).abs();
                    max_depth_error = max_depth_error.max(err);
                    assert!(err < 1e-5 * t, "{at}: depth {} expected {t}", depth[i]);
                    let got = normal[i].map(|v| v as f64);
                    let nerr = sub(got, n).iter().fold(0f64, |m, v| m.max(v.abs()));
                    max_normal_error = max_normal_error.max(nerr);
                    assert!(nerr < 1e-4, "{at}: normal {got:?} expected {n:?}");
                    for k in 0..3 {
                        assert!((albedo[i][k] - ALBEDO[k]).abs() < 1e-6, "{at}: albedo {:?}", albedo[i]);
                    }
                    // The denoiser's features: averages over the jittered
                    // samples. Where every sample hits the sphere (3 px
                    // inside its silhouette), the albedo; the mean of the
                    // normals over the Gaussian jitter (σ = 0.5 px) is the
                    // centre's to second order: the normal's z bends by
                    // 1 / (1 − d²)^{3/2} ≤ 4.7 per unit² up to d = 0.8, which
                    // moves the mean by ½ · 4.7 · (0.5 px · 0.089)² < 0.005.
                    if e.miss_distance < 1.0 - 3.0 * pixel {
                        for k in 0..3 {
                            let err = (feature_albedo[i][k] - ALBEDO[k]).abs();
                            assert!(err < 2e-4, "{at}: the denoiser's albedo {:?}", feature_albedo[i]);
                        }
                    }
                    if e.miss_distance < 0.8 {
                        let got = feature_normal[i].map(|v| v as f64);
                        let ferr = sub(got, n).iter().fold(0f64, |m, v| m.max(v.abs()));
                        max_feature_error = max_feature_error.max(ferr);
                        assert!(ferr < 0.01, "{at}: the denoiser's normal {got:?}, expected {n:?}");
                    }
                    // Lambert: albedo / π · I cos θ / r² from the point light,
                    // where the whole pixel sees the sphere's front, plus the
                    // uniform environment (the background), which a convex
                    // object sees over its whole hemisphere: albedo · background.
                    let to_light = sub(LIGHT, n);
                    let r2 = dot(to_light, to_light);
                    let cos = dot(n, normalize(to_light));
                    let environment = |k: usize| ALBEDO[k] as f64 * BACKGROUND[k] as f64;
                    // A pixel's radiance is checked where its centre and
                    // the pixel centres 2 px away in x and y fall in the same
                    // class: the Gaussian jitter (σ = 0.5 px) takes a sample
                    // beyond 2 px with probability e⁻⁸ = 0.03 %, which moves
                    // a pixel by under 1 % even at a 20:1 contrast (the
                    // bounds below are 15 % and 25 %).
                    let class = |x: usize, y: usize| -> Option<i32> {
                        let (n, cos) = match expected(x, y, WIDTH, HEIGHT).hit {
                            Some((_, n)) => (n, dot(n, normalize(sub(LIGHT, n)))),
                            None => return None,
                        };
                        if n[2] > 0.5 && cos > 0.5 {
                            Some(1)
                        } else if n[2] > 0.5 && cos < -0.2 {
                            Some(-1)
                        } else {
                            Some(0)
                        }
                    };
                    let near: Vec<Option<i32>> = [(0i64, 0i64), (-2, 0), (2, 0), (0, -2), (0, 2)]
                        .iter()
                        .map(|&(dx, dy)| {
                            let (nx, ny) = (x as i64 + dx, y as i64 + dy);
                            if nx < 0 || ny < 0 || nx >= WIDTH as i64 || ny >= HEIGHT as i64 {
                                None
                            } else {
                                class(nx as usize, ny as usize)
                            }
                        })
                        .collect();
                    let agrees = near.iter().all(|c| *c == near[0]);
                    if agrees && n[2] > 0.5 && cos > 0.5 {
                        lit += 1;
                        for k in 0..3 {
                            let want = ALBEDO[k] as f64 / std::f64::consts::PI * INTENSITY * cos / r2 + environment(k);
                            let rel = (rgb[i][k] as f64 - want).abs() / want;
                            max_lit_error = max_lit_error.max(rel);
                            assert!(rel < 0.15, "{at}: radiance {:?}, Lambert gives {want} in channel {k}", rgb[i]);
                        }
                    } else if agrees && n[2] > 0.5 && cos < -0.2 {
                        dark += 1;
                        for k in 0..3 {
                            let rel = (rgb[i][k] as f64 - environment(k)).abs() / environment(k);
                            max_dark_error = max_dark_error.max(rel);
                            assert!(rel < 0.25, "{at}: radiance {:?} facing away from the point light", rgb[i]);
                        }
                    }
                }
            }
        }
    }
    println!(
        "{hits} hits ({lit} lit, {dark} dark), {misses} misses; max depth error {max_depth_error:.2e}, \
         max normal error {max_normal_error:.2e} (the denoiser's mean normal {max_feature_error:.2e}), \
         max Lambert error {:.1}% (lit), {:.1}% (environment only)",
        100.0 * max_lit_error,
        100.0 * max_dark_error
    );
    // Coverage, not accuracy: the 2-px neighbourhoods above leave 28 lit and
    // 14 dark pixels at this image size.
    assert!(hits > 200 && misses > 200 && lit > 20 && dark > 10, "the scene should show all cases");

    // The first pixel-centre ray near the image centre (the width and the
    // height are even, so no ray is on the axis).
    let e = expected(WIDTH / 2, HEIGHT / 2, WIDTH, HEIGHT);
    let (t, _) = e.hit.unwrap();
    assert!((t - 4.0).abs() < 0.01, "near-axis depth {t}");
    assert!((depth[HEIGHT / 2 * WIDTH + WIDTH / 2] as f64 - t).abs() < 1e-4);

    // The PNG: the scene's size, the background tone-mapped with the
    // scene's exposure of 1 stop.
    let png = image::open(outdir.path().join("out.png")).unwrap();
    assert_eq!((png.width(), png.height()), (WIDTH as u32, HEIGHT as u32));
    let png = png.to_rgb8();
    let corner = png.get_pixel(0, 0).0;
    let want = BACKGROUND.map(|v| srgb8(v * EXPOSURE.exp2()));
    for k in 0..3 {
        assert!(corner[k].abs_diff(want[k]) <= 1, "PNG corner {corner:?}, expected {want:?}");
    }
}

#[test]
fn half_exr_only_with_size_overrides_and_validation_from_the_environment() {
    let input = tempfile::tempdir().unwrap();
    let outdir = tempfile::tempdir().unwrap();
    let scene = write_scene(input.path(), "sphere.toml", SPHERE_SCENE);
    let out = outdir.path().join("half.exr");
    let (w, h) = (20, 16);
    render_ok(
        args![
            "render", &scene, "--output", &out, "--half", "--width", "20", "--height", "16", "--spp", "1", "--seed",
            "9"
        ],
        outdir.path(),
        &[("QUADRAY_VALIDATION", "1")],
    );
    assert_eq!(entries(outdir.path()), ["half.exr"]);
    let exr = Exr::read(&out);
    assert_eq!(exr.size(), (w, h));
    for name in quadray::jobs::output::EXR_CHANNELS {
        assert!(matches!(exr.samples(name), FlatSamples::F16(_)), "{name} should hold half floats");
    }
    // Sample indices need more than f16's 11 bits: these stay 32-bit.
    for name in quadray::jobs::output::EXR_MAX_SAMPLE_CHANNELS {
        assert!(matches!(exr.samples(name), FlatSamples::F32(_)), "{name} should hold 32-bit floats");
    }
    let depth = exr.channel("depth");
    assert_eq!(depth[0], f32::INFINITY, "corner pixel misses");
    let (cx, cy) = (w / 2, h / 2);
    let (t, n) = expected(cx, cy, w, h).hit.unwrap();
    let i = cy * w + cx;
    assert!((depth[i] as f64 - t).abs() < 4e-3, "depth {} expected {t}", depth[i]);
    assert!((exr.channel("normal.Z")[i] as f64 - n[2]).abs() < 2e-3);
    assert!((exr.channel("albedo.R")[i] - ALBEDO[0]).abs() < 1e-3);
    for name in ["R", "G", "B"] {
        assert!(exr.channel(name).iter().all(|v| v.is_finite() && *v >= 0.0), "{name} has NaN, Inf or negatives");
    }
}

#[test]
fn png_only_of_the_default_scene() {
    let outdir = tempfile::tempdir().unwrap();
    let out = outdir.path().join("only.PNG");
    // No scene argument: the built-in default scene, made small.
    render_ok(
        &["render", "-o", out.to_str().unwrap(), "--width", "24", "--height", "18", "--spp", "1", "--validation"],
        outdir.path(),
        &[],
    );
    assert_eq!(entries(outdir.path()), ["only.PNG"]);
    let png = image::open(&out).unwrap();
    assert_eq!((png.width(), png.height()), (24, 18));
}

/// Writes `text` as `name`, renders it into an empty directory and checks
/// the error names the file and `line` and contains every needle, and that
/// the directory stays empty.
#[track_caller]
fn bad_scene(name: &str, text: &str, line: usize, needles: &[&str]) {
    let input = tempfile::tempdir().unwrap();
    let outdir = tempfile::tempdir().unwrap();
    let scene = write_scene(input.path(), name, text);
    let base = outdir.path().join("out");
    let stderr = render_fails(args!["render", &scene, "-o", &base, "--validation"], outdir.path());
    let location = format!("{}:{line}:", scene.display());
    assert!(stderr.contains(&location), "expected `{location}` in\n{stderr}");
    for n in needles {
        assert!(stderr.contains(n), "expected `{n}` in\n{stderr}");
    }
    assert!(entries(outdir.path()).is_empty(), "files left behind: {:?}", entries(outdir.path()));
}

#[test]
fn bad_scene_files_fail_with_file_line_and_reason_and_write_nothing() {
    let camera = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n";
    bad_scene(
        "negative_radius.toml",
        &format!("{camera}\n[[objects]]\nsphere = {{ radius = -1 }}\n"),
        6,
        &["objects[0].sphere.radius", "must be positive (got -1)"],
    );
    bad_scene(
        "unknown_key.toml",
        &format!("{camera}[image]\nwidht = 5\n"),
        5,
        &["image.widht", "unknown field `widht`"],
    );
    bad_scene(
        "unbounded.toml",
        &format!("{camera}[[objects]]\nplane = {{}}\n"),
        5,
        &["objects[0].plane", "unbounded", "clip"],
    );
}

#[test]
fn a_missing_scene_file_is_named() {
    let input = tempfile::tempdir().unwrap();
    let outdir = tempfile::tempdir().unwrap();
    let scene = input.path().join("no_such_scene.toml");
    let base = outdir.path().join("out");
    let stderr = render_fails(args!["render", &scene, "-o", &base], outdir.path());
    assert!(stderr.contains(&scene.display().to_string()), "{stderr}");
    assert!(stderr.contains("cannot read"), "{stderr}");
    assert!(entries(outdir.path()).is_empty());
}

#[test]
fn a_missing_output_directory_is_an_error() {
    let input = tempfile::tempdir().unwrap();
    let outdir = tempfile::tempdir().unwrap();
    let scene = write_scene(input.path(), "sphere.toml", SPHERE_SCENE);
    let missing = outdir.path().join("missing").join("sub");
    let base = missing.join("out");
    let stderr = render_fails(args!["render", &scene, "-o", &base, "--validation"], outdir.path());
    assert!(stderr.contains(&format!("the output folder {} does not exist", missing.display())), "{stderr}");
    assert!(entries(outdir.path()).is_empty(), "files left behind: {:?}", entries(outdir.path()));
}

#[test]
fn a_failed_write_leaves_no_file_at_all() {
    // out.exr is a directory, so the EXR cannot be put in place after the
    // render: neither the PNG nor any temporary file may be left.
    let input = tempfile::tempdir().unwrap();
    let outdir = tempfile::tempdir().unwrap();
    let scene = write_scene(input.path(), "sphere.toml", SPHERE_SCENE);
    let taken = outdir.path().join("out.exr");
    std::fs::create_dir(&taken).unwrap();
    let base = outdir.path().join("out");
    let stderr = render_fails(
        args!["render", &scene, "-o", &base, "--width", "8", "--height", "6", "--validation"],
        outdir.path(),
    );
    assert!(stderr.contains(&format!("cannot write {}", taken.display())), "{stderr}");
    assert_eq!(entries(outdir.path()), ["out.exr"]);
    assert!(entries(&taken).is_empty());
}

#[test]
fn an_output_directory_instead_of_a_name_is_an_error() {
    let input = tempfile::tempdir().unwrap();
    let outdir = tempfile::tempdir().unwrap();
    let scene = write_scene(input.path(), "sphere.toml", SPHERE_SCENE);
    let stderr = render_fails(args!["render", &scene, "-o", outdir.path(), "--validation"], outdir.path());
    assert!(stderr.contains("give a file name"), "{stderr}");
    assert!(entries(outdir.path()).is_empty(), "files left behind: {:?}", entries(outdir.path()));
}

#[test]
fn without_a_vulkan_driver_the_error_says_how_to_install_one() {
    let outdir = tempfile::tempdir().unwrap();
    let out = quadray(&["render", "-o", "x"], outdir.path(), &[("VK_ICD_FILENAMES", "/nonexistent/icd.json")]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("no Vulkan device can trace rays"), "{stderr}");
    assert!(stderr.contains("make setup"), "{stderr}");
    assert!(entries(outdir.path()).is_empty());
}

#[test]
fn quadray_validation_in_the_environment_asks_for_the_layer() {
    // With no layer on the search path, asking for validation must fail
    // before anything is rendered; QUADRAY_VALIDATION=0 does not ask.
    let layers = tempfile::tempdir().unwrap();
    let outdir = tempfile::tempdir().unwrap();
    let no_layers = layers.path().to_str().unwrap();
    let args = ["render", "-o", "out", "--width", "8", "--height", "6", "--spp", "1"];
    let out = quadray(&args, outdir.path(), &[("QUADRAY_VALIDATION", "1"), ("VK_LAYER_PATH", no_layers)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "validation was not asked for:\n{stderr}");
    assert!(stderr.contains("validation layer is not installed"), "{stderr}");
    assert!(entries(outdir.path()).is_empty());
    render_ok(&args, outdir.path(), &[("QUADRAY_VALIDATION", "0"), ("VK_LAYER_PATH", no_layers)]);
    assert_eq!(entries(outdir.path()), ["out.exr", "out.png"]);
}

#[test]
fn presets_apply_and_single_flags_override_them() {
    let outdir = tempfile::tempdir().unwrap();
    let dir = outdir.path();
    let scene = write_scene(dir, "s.toml", &SPHERE_SCENE.replace("spp = 25656", "preset = \"final\"\nspp = 5"));
    let out = dir.join("a.exr");
    // The file's preset (final, 64 spp) is replaced by --preset preview
    // (1 spp), whose spp --spp overrides.
    let log = render_ok(
        &["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--preset", "preview", "--spp", "3"],
        dir,
        &[("QUADRAY_VALIDATION", "1")],
    );
    assert!(log.contains("(40x30, 3 spp,"), "{log}");
    // The file's own spp overrides the file's preset.
    let log = render_ok(
        &["render", scene.to_str().unwrap(), "-o", out.to_str().unwrap(), "--filter", "covariance"],
        dir,
        &[],
    );
    assert!(log.contains("(40x30, 5 spp,"), "{log}");
    let err = render_fails(&["render", scene.to_str().unwrap(), "--preset", "fast"], dir);
    assert!(err.contains("unknown preset `fast`; expected one of: preview, interactive, final, reference"), "{err}");
}

/// `quadray bench` on a tiny image: the report has a row per preset with
/// finite, positive GPU times per pass and errors, and the plot, Markdown and
/// images are written; a second run reuses the cached reference.
#[test]
fn bench_writes_its_report_and_caches_the_reference() {
    let outdir = tempfile::tempdir().unwrap();
    let dir = outdir.path();
    let scene = write_scene(dir, "ball.toml", SPHERE_SCENE);
    let out = dir.join("bench");
    let args = [
        "bench",
        scene.to_str().unwrap(),
        "--presets",
        "preview,final",
        "--width",
        "24",
        "--height",
        "16",
        "--reference-spp",
        "64",
        "-o",
        out.to_str().unwrap(),
        "--validation",
    ];
    render_ok(&args, dir, &[]);
    let report: serde_json::Value =
        serde_json::from_str(&std::fs::read_to_string(out.join("bench.json")).unwrap()).unwrap();
    let rows = report["scenes"][0]["presets"].as_array().unwrap();
    assert_eq!(rows.iter().map(|r| r["preset"].as_str().unwrap()).collect::<Vec<_>>(), ["preview", "final"]);
    for r in rows {
        for key in ["render_seconds", "gpu_seconds", "flip", "relative_mse"] {
            let v = r[key].as_f64().unwrap();
            assert!(v.is_finite() && v > 0.0, "{key} = {v} in {r}");
        }
    }
    // More samples, less error against the reference.
    assert!(rows[1]["flip"].as_f64() < rows[0]["flip"].as_f64(), "{rows:?}");
    assert_eq!(report["scenes"][0]["reference"]["spp"], 64);
    for f in ["bench.md", "bench.png", "ball-reference.png", "ball-preview.png", "ball-final.png"] {
        assert!(out.join(f).is_file(), "{f} missing");
    }
    let log = render_ok(&args, dir, &[]);
    assert!(log.contains("using the cached reference"), "{log}");
}

/// `quadray devices` lists lavapipe with what the renderer uses (Mesa 25
/// offers both ray queries and ray-tracing pipelines, float64, 64-bit
/// atomics and timestamps) and says a render takes it with ray queries.
#[test]
fn devices_lists_the_drivers_capabilities_and_the_backend_auto_takes() {
    let dir = tempfile::tempdir().unwrap();
    let out = quadray(&["devices", "--json"], dir.path(), &[]);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    let report: serde_json::Value = serde_json::from_slice(&out.stdout).expect("JSON");
    let devices = report["devices"].as_array().expect("a device list");
    let lavapipe = devices.iter().find(|d| d["driver_name"] == "llvmpipe").expect("lavapipe is listed");
    for flag in
        ["ray_query", "ray_tracing_pipeline", "acceleration_structure", "float64", "int64_atomics", "timestamps"]
    {
        assert_eq!(lavapipe[flag], true, "lavapipe's {flag}");
    }
    let limits = &lavapipe["pipeline_limits"];
    assert!(limits["shader_group_handle_size"].as_u64().unwrap() >= 16, "{limits}");
    assert!(limits["max_ray_recursion_depth"].as_u64().unwrap() >= 1, "{limits}");
    assert_eq!(lavapipe["lacks"]["ray-query"], serde_json::json!([]));
    assert_eq!(lavapipe["auto_backend"], "ray-query");
    assert_eq!(report["auto"]["backend"], "ray-query");
    let index = report["auto"]["index"].as_u64().unwrap() as usize;
    assert_eq!(devices[index]["ray_query"], true);
    println!("auto: {} with {}", report["auto"]["device"], report["auto"]["backend"]);

    let text = quadray(&["devices"], dir.path(), &[]);
    assert!(text.status.success());
    let text = String::from_utf8_lossy(&text.stdout);
    assert!(text.contains("backend ray-query: supported"), "{text}");
    assert!(text.contains("auto: device "), "{text}");
    assert!(entries(dir.path()).is_empty(), "devices writes nothing");
}

/// A device without ray queries (simulated: `QUADRAY_HIDE_RAY_QUERY=1`
/// creates lavapipe without them, as a GPU that offers only ray-tracing
/// pipelines) renders every pass through the pipeline, under the validation
/// layer, to the same image as the ray-query backend; `--backend ray-query`
/// is then refused with a message that names the way out.
#[test]
fn without_ray_queries_every_pass_runs_through_the_pipeline() {
    let dir = tempfile::tempdir().unwrap();
    let scene = concat!(env!("CARGO_MANIFEST_DIR"), "/scenes/tests/lens_fog.toml");
    let size = ["--width", "48", "--height", "36", "--spp", "2", "--validation"];
    let hidden = [("QUADRAY_HIDE_RAY_QUERY", "1")];
    let devices = quadray(&["devices"], dir.path(), &hidden);
    let text = String::from_utf8_lossy(&devices.stdout);
    assert!(text.contains("backend ray-query: lacks VK_KHR_ray_query"), "{text}");
    assert!(text.contains("with the pipeline backend"), "{text}");
    let pipeline: Vec<&str> = ["render", scene, "-o", "pipeline.exr"].into_iter().chain(size).collect();
    let stderr = render_ok(&pipeline, dir.path(), &hidden);
    assert!(stderr.contains("caustics:") && stderr.contains("volume:"), "the caustic and volume passes ran: {stderr}");
    let reference: Vec<&str> =
        ["render", scene, "-o", "rq.exr", "--backend", "ray-query"].into_iter().chain(size).collect();
    render_ok(&reference, dir.path(), &[]);
    let file = |name: &str| quadray::jobs::output::read_render_exr(&dir.path().join(name)).unwrap();
    let (rq, pipe) = (file("rq.exr"), file("pipeline.exr"));
    // The images say which backend made them.
    let backend = |f: &quadray::jobs::output::ExrFile| {
        f.metadata.iter().find(|(k, _)| k == quadray::jobs::output::METADATA_BACKEND).map(|(_, v)| v.clone())
    };
    assert_eq!(backend(&rq).as_deref(), Some("ray-query"));
    assert_eq!(backend(&pipe).as_deref(), Some("pipeline"));
    let (a, b) = (rq.output, pipe.output);
    let flip = quadray::tools::metrics::flip_mean(&a, &b, 0.0).unwrap();
    println!("lens_fog without ray queries against ray queries: FLIP {flip:.6}");
    assert!(flip <= 0.001, "FLIP {flip}");
    let refused: Vec<&str> =
        ["render", scene, "-o", "no.exr", "--backend", "ray-query"].into_iter().chain(size).collect();
    let out = quadray(&refused, dir.path(), &hidden);
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success() && message.contains("offers no ray queries"), "{message}");
    assert!(!dir.path().join("no.exr").exists());
}

/// A device with neither ray queries nor ray-tracing pipelines (both masked:
/// `QUADRAY_HIDE_RAY_QUERY=1 QUADRAY_HIDE_PIPELINE=1`) is refused: the
/// error lists every device with what it lacks per backend and the setup
/// command, and writes nothing; `devices` says no device fits.
#[test]
fn a_device_with_neither_extension_is_refused_with_what_it_lacks() {
    let dir = tempfile::tempdir().unwrap();
    let masked = [("QUADRAY_HIDE_RAY_QUERY", "1"), ("QUADRAY_HIDE_PIPELINE", "1")];
    let out = quadray(&["render", "-o", "none.png"], dir.path(), &masked);
    let message = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success(), "{message}");
    for needle in [
        "no Vulkan device can trace rays",
        "llvmpipe",
        "ray-query: lacks VK_KHR_ray_query with rayQuery",
        "pipeline: lacks VK_KHR_ray_tracing_pipeline with rayTracingPipeline",
        "make setup",
    ] {
        assert!(message.contains(needle), "`{needle}` missing from:\n{message}");
    }
    println!("{message}");
    assert!(entries(dir.path()).is_empty(), "nothing is written");
    let devices = quadray(&["devices"], dir.path(), &masked);
    assert!(devices.status.success());
    let text = String::from_utf8_lossy(&devices.stdout);
    assert!(text.contains("auto: no device fits"), "{text}");
}

/// `--denoise`: the PNG and the EXR's RGB are the denoised image, the EXR
/// keeps the raw radiance as `noisy.RGB` beside the denoiser's features and
/// says how it was denoised; `quadray denoise` of that EXR gives the same
/// image again. Without the library (`QUADRAY_OIDN_LIB` naming a file that
/// is not there) `render --denoise`, a denoising preset and `quadray
/// denoise` fail before any work, say how to get it, and write nothing.
#[test]
fn denoise_keeps_the_raw_image_and_without_the_library_writes_nothing() {
    let outdir = tempfile::tempdir().unwrap();
    let dir = outdir.path();
    let out = dir.join("d");
    let small = ["--width", "48", "--height", "36", "--spp", "2"];
    let mut args = vec!["render", "-o", out.to_str().unwrap(), "--denoise", "--validation"];
    args.extend(small);
    let log = render_ok(&args, dir, &[]);
    assert!(
        log.contains("denoised: Intel Open Image Denoise 2.5.1, high quality, with the albedo and normal images"),
        "{log}"
    );
    assert_eq!(entries(dir), ["d.exr", "d.png"]);
    let exr = Exr::read(&dir.join("d.exr"));
    for name in quadray::jobs::output::EXR_NOISY_CHANNELS.iter().chain(&quadray::jobs::output::EXR_DENOISE_CHANNELS) {
        assert!(exr.names().iter().any(|n| n == name), "{name} missing from {:?}", exr.names());
    }
    let file = quadray::jobs::output::read_render_exr(&dir.join("d.exr")).unwrap();
    let denoised = file.output.denoised.as_ref().expect("the denoised image");
    assert_ne!(denoised, &file.output.radiance, "the denoised image is the raw one");
    assert_eq!(file.output.radiance, exr.vec3(quadray::jobs::output::EXR_NOISY_CHANNELS), "the raw radiance is kept");
    assert!(file.metadata.iter().any(|(k, v)| k == quadray::jobs::output::METADATA_DENOISED && v.contains("2.5.1")));
    // The PNG shows the denoised image.
    let png = image::open(dir.join("d.png")).unwrap().to_rgb8();
    let i = 18 * 48 + 24;
    for (k, v) in denoised[i].iter().enumerate() {
        assert!(png.as_raw()[3 * i + k].abs_diff(srgb8(*v)) <= 1, "PNG pixel {i}");
    }
    // Denoised again from the file: the same image.
    let again = dir.join("again.exr");
    let log = render_ok(&["denoise", dir.join("d.exr").to_str().unwrap(), "-o", again.to_str().unwrap()], dir, &[]);
    assert!(log.contains("denoised: Intel Open Image Denoise"), "{log}");
    let twice = quadray::jobs::output::read_render_exr(&again).unwrap().output;
    assert_eq!(twice.radiance, file.output.radiance);
    let most = denoised.iter().flatten().zip(twice.denoised.as_ref().unwrap().iter().flatten());
    for (a, b) in most {
        assert!((a - b).abs() <= 1e-4 * a.abs().max(1e-3), "denoised {a} then {b}");
    }

    // Without the library.
    let empty = tempfile::tempdir().unwrap();
    let e = empty.path();
    let missing = [("QUADRAY_OIDN_LIB", "/nonexistent/libOpenImageDenoise.so.2")];
    let x = e.join("x");
    for extra in [&["--denoise"][..], &["--preset", "preview"][..]] {
        let mut args = vec!["render", "-o", x.to_str().unwrap()];
        args.extend(small);
        args.extend(extra);
        let o = quadray(&args, e, &missing);
        let stderr = String::from_utf8_lossy(&o.stderr);
        assert!(!o.status.success(), "{stderr}");
        assert!(
            stderr.contains("Intel Open Image Denoise is not installed")
                && stderr.contains("/nonexistent/libOpenImageDenoise.so.2")
                && stderr.contains("make setup")
                && stderr.contains("--no-denoise"),
            "{stderr}"
        );
        assert!(!stderr.contains("panicked"), "{stderr}");
        assert!(entries(e).is_empty(), "wrote {:?}", entries(e));
    }
    let o = quadray(&["denoise", dir.join("d.exr").to_str().unwrap(), "-o", x.to_str().unwrap()], e, &missing);
    assert!(!o.status.success() && String::from_utf8_lossy(&o.stderr).contains("not installed"));
    assert!(entries(e).is_empty(), "wrote {:?}", entries(e));
    // The same preset renders without it when told not to denoise.
    let mut args = vec!["render", "-o", x.to_str().unwrap(), "--preset", "preview", "--no-denoise"];
    args.extend(small);
    render_ok(&args, e, &missing);
}

#[test]
fn quadray_alone_prints_the_usage_and_exits_0() {
    let dir = tempfile::tempdir().unwrap();
    let out = quadray::<&str>(&[], dir.path(), &[]);
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.contains("Usage: quadray"), "{stdout}");
    assert!(stdout.contains("quadray render"), "the usage shows a first command:\n{stdout}");
    assert!(entries(dir.path()).is_empty(), "bare quadray renders nothing");
}

#[test]
fn the_default_render_is_denoised_with_the_raw_radiance_kept() {
    let dir = tempfile::tempdir().unwrap();
    let stderr = render_ok(&["render", "--width", "32", "--height", "24", "--spp", "2"], dir.path(), &[]);
    assert!(stderr.contains("denoised: Intel Open Image Denoise"), "{stderr}");
    assert_eq!(entries(dir.path()), ["render.exr", "render.png"]);
    let exr = quadray::jobs::output::read_render_exr(&dir.path().join("render.exr")).unwrap();
    assert!(exr.output.denoised.is_some(), "the EXR's RGB is the denoised image, noisy.RGB the raw");
    assert!(exr.metadata.iter().any(|(k, _)| k == quadray::jobs::output::METADATA_DENOISED));
    // --no-denoise: the raw image alone.
    render_ok(
        &["render", "--width", "32", "--height", "24", "--spp", "2", "--no-denoise", "-o", "raw"],
        dir.path(),
        &[],
    );
    let raw = quadray::jobs::output::read_render_exr(&dir.path().join("raw.exr")).unwrap();
    assert!(raw.output.denoised.is_none());
}

#[test]
fn an_unwritable_output_fails_before_any_gpu_work_and_writes_nothing() {
    let dir = tempfile::tempdir().unwrap();
    // A folder nobody may write in (even root: sysfs), and a path through a file.
    let stderr = render_fails(&["render", "-o", "/sys/out"], dir.path());
    assert!(stderr.contains("-o /sys/out: cannot write in the folder /sys"), "{stderr}");
    assert!(!stderr.contains("wrote") && !stderr.contains("spp"), "it rendered first:\n{stderr}");
    assert!(!std::path::Path::new("/sys/out.png").exists());
    std::fs::write(dir.path().join("afile"), b"x").unwrap();
    let stderr = render_fails(&["render", "-o", "afile/out"], dir.path());
    assert!(stderr.contains("afile is a file, not a folder"), "{stderr}");
    assert_eq!(entries(dir.path()), ["afile"], "no probe or output left");
}

#[test]
fn messages_for_common_mistakes_say_what_to_do() {
    let dir = tempfile::tempdir().unwrap();
    // A negative sample count is a bad value, not an unknown argument.
    let stderr = render_fails(&["render", "--spp", "-4"], dir.path());
    assert!(stderr.contains("-4 is not in 1..=1048576"), "{stderr}");
    assert!(!stderr.contains("'-- -4'"), "{stderr}");
    // denoise reads EXRs; a PNG is named as such.
    std::fs::write(dir.path().join("x.png"), b"\x89PNG\r\n\x1a\n0000").unwrap();
    let stderr = render_fails(&["denoise", "x.png"], dir.path());
    assert!(stderr.contains("x.png is a PNG image") && stderr.contains("render's EXR"), "{stderr}");
    assert!(!stderr.contains("file identifier missing"), "{stderr}");
    // A user's mistake shows no backtrace, even when RUST_BACKTRACE asks.
    let out = quadray(&["render", "-o", "/sys/out"], dir.path(), &[("RUST_BACKTRACE", "1")]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(!stderr.contains("Stack backtrace") && !stderr.contains("__libc_start"), "{stderr}");
    // The viewer without a display names the way out, not winit's source.
    #[cfg(feature = "viewer")]
    {
        let out = Command::new(env!("CARGO_BIN_EXE_quadray"))
            .args(["view", "--width", "8", "--height", "8"])
            .current_dir(dir.path())
            .env_remove("DISPLAY")
            .env_remove("WAYLAND_DISPLAY")
            .env_remove("WAYLAND_SOCKET")
            .env("RUST_BACKTRACE", "0")
            .stdin(Stdio::null())
            .output()
            .unwrap();
        let stderr = String::from_utf8_lossy(&out.stderr);
        assert!(!out.status.success());
        assert!(stderr.contains("xvfb-run -a quadray view"), "{stderr}");
        assert!(!stderr.contains(".rs:"), "a source path in the message:\n{stderr}");
    }
}

#[test]
fn denoise_without_an_output_name_writes_beside_its_input() {
    let dir = tempfile::tempdir().unwrap();
    render_ok(
        &["render", "--width", "16", "--height", "12", "--spp", "1", "--no-denoise", "-o", "a.exr"],
        dir.path(),
        &[],
    );
    render_ok(&["denoise", "a.exr"], dir.path(), &[]);
    assert_eq!(entries(dir.path()), ["a-denoised.exr", "a-denoised.png", "a.exr"]);
}
