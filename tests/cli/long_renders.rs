//! Long renders that survive (issue 17): a render stopped by SIGTERM leaves
//! a checkpoint and an image, and resuming it gives files bit-identical to
//! an uninterrupted render's; tiles of a render merge into files
//! bit-identical to the whole render's (AOVs included), each placed by its
//! EXR data window; bad merges and resumes are clear errors that write
//! nothing. Through the CLI, with the validation layer on.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};
use std::time::{Duration, Instant};

fn scene(name: &str) -> String {
    format!("{}/scenes/{name}", env!("CARGO_MANIFEST_DIR"))
}

fn command(args: &[&str], cwd: &Path) -> Command {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_quadray"));
    cmd.args(args).current_dir(cwd).stdin(Stdio::null()).env("RUST_BACKTRACE", "0");
    if args[0] == "render" {
        cmd.arg("--validation");
    }
    cmd
}

#[track_caller]
fn ok(args: &[&str], cwd: &Path) -> String {
    let out = command(args, cwd).output().expect("cannot start quadray");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(out.status.success(), "`quadray {}` failed ({}):\n{stderr}", args.join(" "), out.status);
    stderr
}

#[track_caller]
fn fails(args: &[&str], cwd: &Path) -> String {
    let out: Output = command(args, cwd).output().expect("cannot start quadray");
    let stderr = String::from_utf8_lossy(&out.stderr).into_owned();
    assert!(!out.status.success(), "`quadray {}` should fail:\n{stderr}", args.join(" "));
    stderr
}

fn refs(v: &[String]) -> Vec<&str> {
    v.iter().map(String::as_str).collect()
}

#[track_caller]
fn same_bytes(a: &Path, b: &Path) {
    let (x, y) = (std::fs::read(a).unwrap(), std::fs::read(b).unwrap());
    assert!(x == y, "{} and {} differ", a.display(), b.display());
}

/// Starts a render that checkpoints after every dispatch, sends SIGTERM once
/// the first checkpoint exists, and checks that it stopped with status 75,
/// leaving the checkpoint and an image of fewer samples; then resumes it
/// and compares the files with an uninterrupted render's.
fn interrupt_and_resume(scene_file: &str, size: &[&str], spp: u32, dir: &Path) {
    let spp = spp.to_string();
    let mut base: Vec<&str> = vec!["render", scene_file, "--spp", &spp];
    base.extend_from_slice(size);
    let with = |extra: &[&'static str]| -> Vec<&str> { base.iter().copied().chain(extra.iter().copied()).collect() };
    ok(&with(&["-o", "full"]), dir);

    let mut child = command(&with(&["-o", "part", "--checkpoint", "c.ckpt", "--checkpoint-every", "0.001"]), dir)
        .stderr(Stdio::piped())
        .spawn()
        .expect("cannot start quadray");
    let start = Instant::now();
    while !dir.join("c.ckpt").exists() {
        assert!(start.elapsed() < Duration::from_secs(300), "no checkpoint after 300 s");
        assert!(child.try_wait().unwrap().is_none(), "the render ended before its first checkpoint");
        std::thread::sleep(Duration::from_millis(20));
    }
    // SAFETY: kill(2) with a child's pid.
    assert_eq!(unsafe { libc::kill(child.id() as i32, libc::SIGTERM) }, 0);
    let out = child.wait_with_output().unwrap();
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert_eq!(out.status.code(), Some(75), "status after SIGTERM:\n{stderr}");
    assert!(stderr.contains("interrupted: wrote the image so far"), "{stderr}");
    assert!(dir.join("c.ckpt").exists() && dir.join("part.exr").exists() && dir.join("part.png").exists());
    let part = quadray::jobs::output::read_render_exr(&dir.join("part.exr")).unwrap();
    let reached: u32 = part.output.spp;
    println!("{scene_file}: stopped at {reached} of {spp} spp");
    assert!(reached < spp.parse().unwrap(), "the render finished before the signal: {stderr}");

    // Another seed is another render: refused, nothing written.
    let refused = fails(&with(&["-o", "other", "--resume", "c.ckpt", "--seed", "99"]), dir);
    assert!(refused.contains("is a checkpoint of another render"), "{refused}");
    assert!(!dir.join("other.exr").exists() && dir.join("c.ckpt").exists());

    let stderr = ok(&with(&["-o", "resumed", "--resume", "c.ckpt"]), dir);
    assert!(stderr.contains(&format!("resumed at {reached} of {spp} spp")), "{stderr}");
    same_bytes(&dir.join("full.exr"), &dir.join("resumed.exr"));
    same_bytes(&dir.join("full.png"), &dir.join("resumed.png"));
    assert!(!dir.join("c.ckpt").exists(), "the checkpoint of a completed render is removed");
}

#[test]
fn sigterm_then_resume_is_bit_identical_without_passes() {
    let dir = tempfile::tempdir().unwrap();
    interrupt_and_resume(&scene("default.toml"), &["--width", "48", "--height", "32"], 96, dir.path());
}

#[test]
fn sigterm_then_resume_is_bit_identical_with_caustics_and_fog() {
    let dir = tempfile::tempdir().unwrap();
    let stderr = ok(&["render", &scene("tests/lens_fog.toml"), "--spp", "1", "-o", "probe"], dir.path());
    assert!(stderr.contains("caustics:") && stderr.contains("volume:"), "the passes run: {stderr}");
    interrupt_and_resume(&scene("tests/lens_fog.toml"), &["--width", "48", "--height", "36"], 64, dir.path());
}

#[test]
fn four_tiles_merge_into_the_whole_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    // 300 x 200: the renderer's own 256-pixel dispatch tiles straddle the
    // bands' edges.
    // Raw radiance: tiles merge bit for bit (a denoised tile would show its
    // edges; merge keeps the tiles' raw radiance: `denoised_tiles_merge_into_their_raw_radiance`).
    let base = ["render", "--width", "300", "--height", "200", "--spp", "3", "--no-denoise"];
    let with = |extra: &[&str]| -> Vec<String> { base.iter().chain(extra).map(|s| s.to_string()).collect() };
    ok(&refs(&with(&["-o", "full"])), d);
    let mut tiles = Vec::new();
    for i in 0..4 {
        let name = format!("tile{i}.exr");
        ok(&refs(&with(&["--tile", &format!("{i}/4"), "-o", &name])), d);
        let file = quadray::jobs::output::read_render_exr(&d.join(&name)).unwrap();
        let expected = quadray::passes::PixelBounds::tile(i, 4, 300, 200).unwrap();
        assert_eq!(file.output.bounds, expected, "data window of {name}");
        assert_eq!(file.output.frame_size, (300, 200), "display window of {name}");
        println!("{name}: data window {} of a 300x200 display window", file.output.bounds);
        tiles.push(name);
    }
    // In a shuffled order: each tile places itself.
    ok(&["merge", &tiles[2], &tiles[0], &tiles[3], &tiles[1], "-o", "merged"], d);
    same_bytes(&d.join("full.exr"), &d.join("merged.exr"));
    same_bytes(&d.join("full.png"), &d.join("merged.png"));
    let merged = quadray::jobs::output::read_render_exr(&d.join("merged.exr")).unwrap();
    assert!(!merged.output.aov.is_empty() && !merged.output.max_sample.is_empty(), "AOVs merged");

    // A missing tile, an overlap and a tile of another seed: errors, no files.
    let gap = fails(&["merge", &tiles[0], &tiles[1], &tiles[3], "-o", "bad"], d);
    assert!(gap.contains("in no tile"), "{gap}");
    let overlap = fails(&["merge", &tiles[0], &tiles[1], &tiles[1], &tiles[2], &tiles[3], "-o", "bad"], d);
    assert!(overlap.contains("overlap"), "{overlap}");
    ok(&refs(&with(&["--tile", "2/4", "--seed", "5", "-o", "other.exr"])), d);
    let other = fails(&["merge", &tiles[0], &tiles[1], "other.exr", &tiles[3], "-o", "bad"], d);
    assert!(other.contains("is not a tile of the same render"), "{other}");
    let written: Vec<PathBuf> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.file_name().unwrap().to_string_lossy().contains("bad"))
        .collect();
    assert!(written.is_empty(), "a refused merge wrote {written:?}");
}

#[test]
fn a_crop_is_the_same_pixels_as_the_whole_render() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = ["render", "--width", "90", "--height", "60", "--spp", "2"];
    let full: Vec<&str> = base.iter().copied().chain(["-o", "full.exr"]).collect();
    ok(&full, d);
    let crop: Vec<&str> = base.iter().copied().chain(["--crop", "17,61,5,44", "-o", "crop.exr"]).collect();
    ok(&crop, d);
    let full = quadray::jobs::output::read_render_exr(&d.join("full.exr")).unwrap().output;
    let crop = quadray::jobs::output::read_render_exr(&d.join("crop.exr")).unwrap().output;
    let bounds = quadray::passes::PixelBounds { x0: 17, x1: 61, y0: 5, y1: 44 };
    assert_eq!(crop.bounds, bounds);
    assert_eq!(crop.radiance, bounds.extract(&full.radiance, 90));
    assert_eq!(crop.aov, bounds.extract(&full.aov, 90));
    let outside: Vec<&str> = base.iter().copied().chain(["--crop", "17,91,5,44", "-o", "x.exr"]).collect();
    let err = fails(&outside, d);
    assert!(err.contains("outside the 90x60 frame"), "{err}");
}

#[test]
fn a_frame_range_renders_numbered_frames_equal_to_single_frames() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let scene_file = scene("camera_move.toml");
    let base = ["render", &scene_file, "--width", "64", "--height", "48", "--spp", "2"];
    let range: Vec<&str> = base.iter().copied().chain(["--frames", "0-2", "-o", "move"]).collect();
    let stderr = ok(&range, d);
    assert_eq!(stderr.matches("wrote move.").count(), 3, "{stderr}");
    let single: Vec<&str> = base.iter().copied().chain(["--frame", "2", "-o", "single"]).collect();
    ok(&single, d);
    same_bytes(&d.join("move.0002.exr"), &d.join("single.0002.exr"));
    same_bytes(&d.join("move.0002.png"), &d.join("single.0002.png"));
    // The camera moves: the frames differ, and each says which it is.
    let f0 = quadray::jobs::output::read_render_exr(&d.join("move.0000.exr")).unwrap();
    let f1 = quadray::jobs::output::read_render_exr(&d.join("move.0001.exr")).unwrap();
    assert_ne!(f0.output.radiance, f1.output.radiance);
    assert!(f1.metadata.contains(&("quadray.frame".to_string(), "1".to_string())), "{:?}", f1.metadata);
    let bad: Vec<&str> = base.iter().copied().chain(["--frames", "3-1", "-o", "x"]).collect();
    assert!(fails(&bad, d).contains("a frame range is A-B"));
}

#[test]
fn a_time_limit_writes_what_it_has_and_a_checkpoint_to_resume() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = ["render", "--width", "48", "--height", "32", "--spp", "4000"];
    let limited: Vec<&str> =
        base.iter().copied().chain(["--time-limit", "0.5", "--checkpoint", "t.ckpt", "-o", "part"]).collect();
    let stderr = ok(&limited, d);
    assert!(stderr.contains("time limit reached: wrote the image so far"), "{stderr}");
    let part = quadray::jobs::output::read_render_exr(&d.join("part.exr")).unwrap();
    let meta = |k: &str| part.metadata.iter().find(|(n, _)| n == k).map(|(_, v)| v.clone());
    println!("time limit 0.5 s: {} of 4000 spp", part.output.spp);
    assert!(part.output.spp < 4000);
    assert_eq!(meta("quadray.spp"), Some(part.output.spp.to_string()));
    assert_eq!(meta("quadray.target_spp"), Some("4000".to_string()));
    let checkpoint = quadray::passes::Checkpoint::read(&d.join("t.ckpt")).unwrap();
    assert_eq!(checkpoint.accumulation.samples, part.output.spp);
    assert_eq!(checkpoint.target_spp, 4000);
}

/// The default scene is denoised; its tiles, each denoised alone (in its
/// own time: the metadata differ), merge into their raw radiance, which is
/// the raw whole render's.
#[test]
fn denoised_tiles_merge_into_their_raw_radiance() {
    let dir = tempfile::tempdir().unwrap();
    let d = dir.path();
    let base = ["render", "--width", "64", "--height", "48", "--spp", "2"];
    let with = |extra: &[&str]| -> Vec<String> { base.iter().chain(extra).map(|s| s.to_string()).collect() };
    ok(&refs(&with(&["--no-denoise", "-o", "raw.exr"])), d);
    for i in 0..2 {
        let log = ok(&refs(&with(&["--tile", &format!("{i}/2"), "-o", &format!("t{i}.exr")])), d);
        assert!(log.contains("denoised:"), "{log}");
    }
    let log = ok(&["merge", "t0.exr", "t1.exr", "-o", "merged.exr"], d);
    assert!(log.contains("denoised images are left out"), "{log}");
    let merged = quadray::jobs::output::read_render_exr(&d.join("merged.exr")).unwrap();
    let raw = quadray::jobs::output::read_render_exr(&d.join("raw.exr")).unwrap();
    assert!(merged.output.denoised.is_none());
    assert!(merged.output.radiance == raw.output.radiance, "the merged radiance is not the raw render's");
    assert!(!merged.metadata.iter().any(|(k, _)| k == quadray::jobs::output::METADATA_DENOISED));
}
