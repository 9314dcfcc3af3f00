#![cfg(feature = "viewer")]
//! The viewer (`quadray view`) in a real X11 window under Xvfb, on lavapipe,
//! with the Khronos validation layer on (the command fails on any error,
//! leaks at shutdown included):
//!
//! - it opens, renders the default scene at `interactive` quality, and on
//!   script command saves a screenshot (the frame it presented, PNG + EXR)
//!   and a capture of the window as the X server holds it;
//! - both match an offscreen `quadray render` of the same view (FLIP of the
//!   tone-mapped images, and of the EXR radiance);
//! - at `interactive` quality it shows the denoised image, and the denoise
//!   key switches to the raw samples and back (each matches the offscreen
//!   render with and without `--denoise`);
//! - it is resized (the render follows the window: a screenshot at the new
//!   size matches an offscreen render at that size), minimised and restored,
//!   has its filtering mode, preset and passes switched and its camera
//!   orbited, and closes cleanly.
//!
//! Needs `Xvfb` (package xvfb, installed by `make setup`).

use std::io::{BufRead, BufReader};
use std::path::Path;
use std::process::{Child, Command, Stdio};

/// FLIP allowed between the window and the offscreen render. They run the
/// same samples with the same seeds, so they should agree to the last bit;
/// the bound leaves room only for a driver that rounds differently between
/// two processes.
const FLIP_BOUND: f64 = 0.01;

/// A private X server, killed on drop.
struct Xvfb {
    child: Child,
    display: String,
}

impl Xvfb {
    fn start() -> Self {
        // -displayfd: Xvfb picks a free display and prints its number.
        let mut child = Command::new("Xvfb")
            .args(["-displayfd", "1", "-screen", "0", "1024x768x24", "-nolisten", "tcp"])
            .stdout(Stdio::piped())
            .stderr(Stdio::null())
            .spawn()
            .expect("cannot start Xvfb (package xvfb): run `make setup`");
        let mut line = String::new();
        BufReader::new(child.stdout.take().expect("piped")).read_line(&mut line).expect("Xvfb's display number");
        let number = line.trim();
        assert!(!number.is_empty() && number.bytes().all(|b| b.is_ascii_digit()), "Xvfb printed `{line}`");
        Self { child, display: format!(":{number}") }
    }
}

impl Drop for Xvfb {
    fn drop(&mut self) {
        let _ = self.child.kill();
        let _ = self.child.wait();
    }
}

fn quadray(args: &[&str], display: Option<&str>) -> String {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_quadray"));
    cmd.args(args).env("QUADRAY_VALIDATION", "1").env_remove("WAYLAND_DISPLAY");
    if let Some(d) = display {
        cmd.env("DISPLAY", d);
    }
    let out = cmd.output().expect("run quadray");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "quadray {args:?} failed ({}):\n{stderr}", out.status);
    assert!(!stderr.contains("ERROR"), "quadray {args:?} logged errors:\n{stderr}");
    stderr
}

fn png_flip(reference: &Path, test: &Path) -> f64 {
    let r = image::open(reference).unwrap_or_else(|e| panic!("{}: {e}", reference.display())).to_rgb8();
    let t = image::open(test).unwrap_or_else(|e| panic!("{}: {e}", test.display())).to_rgb8();
    assert_eq!(r.dimensions(), t.dimensions(), "{} and {} differ in size", reference.display(), test.display());
    let (w, h) = r.dimensions();
    let map = nv_flip::flip(
        nv_flip::FlipImageRgb8::with_data(w, h, r.as_raw()),
        nv_flip::FlipImageRgb8::with_data(w, h, t.as_raw()),
        nv_flip::DEFAULT_PIXELS_PER_DEGREE,
    );
    let values = map.to_vec();
    values.iter().map(|&v| f64::from(v)).sum::<f64>() / values.len() as f64
}

fn exr_flip(reference: &Path, test: &Path) -> f64 {
    let read = |p: &Path| {
        let (width, height, texels) =
            quadray::model::texture::read_exr_image(p).unwrap_or_else(|e| panic!("{}: {e}", p.display()));
        quadray::passes::RenderOutput::from_radiance(width, height, texels.iter().map(|t| [t[0], t[1], t[2]]).collect())
    };
    quadray::tools::metrics::flip_mean(&read(reference), &read(test), 0.0).expect("same size")
}

#[test]
fn window_screenshots_match_the_offscreen_render_through_resize_and_close() {
    let x = Xvfb::start();
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let path = |name: &str| d.join(name);
    let dir_arg = d.to_str().unwrap();

    // `interactive` denoises: `key n` shows the raw samples, and again the
    // denoised image.
    let script = "wait 4; screenshot first; key n; frames 1; screenshot raw; key n; frames 2; \
                  capture first-window; \
                  resize 112x80; wait 4; screenshot resized; frames 2; capture resized-window; \
                  minimize; frames 2; restore; frames 2; \
                  key f; key c; key v; orbit 30 10; key 1; wait 1; key 3; frames 1; screenshot last; close";
    let log = quadray(
        &[
            "view",
            "--preset",
            "interactive",
            "--width",
            "128",
            "--height",
            "96",
            "--screenshot-dir",
            dir_arg,
            "--script",
            script,
        ],
        Some(&x.display),
    );
    eprintln!("{log}");
    assert!(log.contains("viewer closed after"), "{log}");

    for (name, (w, h), denoise) in [
        ("first", ("128", "96"), "--denoise"),
        ("raw", ("128", "96"), "--no-denoise"),
        ("resized", ("112", "80"), "--denoise"),
    ] {
        let reference = path(&format!("{name}-offscreen"));
        quadray(
            &[
                "render",
                "--preset",
                "interactive",
                denoise,
                "--width",
                w,
                "--height",
                h,
                "-o",
                reference.to_str().unwrap(),
            ],
            None,
        );
        let offscreen_png = reference.with_extension("png");
        let offscreen_exr = reference.with_extension("exr");
        let shown = png_flip(&offscreen_png, &path(&format!("{name}.png")));
        let window = if name == "raw" { 0.0 } else { png_flip(&offscreen_png, &path(&format!("{name}-window.png"))) };
        let radiance = exr_flip(&offscreen_exr, &path(&format!("{name}.exr")));
        eprintln!(
            "{name} ({w}x{h}, {denoise}): FLIP against the offscreen render: presented frame {shown:.5}, window as \
             the X server shows it {window:.5}, EXR radiance {radiance:.5} (bound {FLIP_BOUND})"
        );
        assert!(shown < FLIP_BOUND && window < FLIP_BOUND && radiance < FLIP_BOUND);
        // The denoised screenshots keep the raw radiance beside the
        // denoised; the raw one has only the raw.
        let file = quadray::jobs::output::read_render_exr(&path(&format!("{name}.exr"))).unwrap();
        assert_eq!(file.output.denoised.is_some(), denoise == "--denoise", "{name}.exr");
    }
    // Denoised and raw differ (the key did something).
    assert!(png_flip(&path("first.png"), &path("raw.png")) > 0.02);
    // The last screenshot: after the toggles, at the `final` preset's first frames.
    let last = image::open(path("last.png")).unwrap().to_rgb8();
    assert_eq!(last.dimensions(), (112, 80));
}

#[test]
fn bad_scripts_are_refused_before_a_window_opens() {
    let out = Command::new(env!("CARGO_BIN_EXE_quadray"))
        .args(["view", "--script", "wait 4; resize big"])
        .env("DISPLAY", ":0")
        .output()
        .expect("run quadray");
    assert!(!out.status.success());
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(stderr.contains("script step 2 (`resize big`)"), "{stderr}");
}
