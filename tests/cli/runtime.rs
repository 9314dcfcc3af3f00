//! The Vulkan runtime `make setup` fetches (src/vk/runtime.rs,
//! docs/vulkan-runtime.md): quadray restarts itself through it, the test
//! binaries run on it through cargo's runner (`scripts/vulkan-runtime-run`),
//! both choose the driver alike, a child asked for the system's driver gets
//! it, and the system's driver (Debian 12's Mesa 25.0.7) renders the test
//! scenes as the runtime's does.
//!
//! Where no runtime was fetched (setup warns when Debian unstable no longer
//! has the pinned packages), the tests that need one say so and check
//! only what holds without it.

use std::path::{Path, PathBuf};
use std::process::{Command, Output, Stdio};

use quadray::jobs::output::{read_render_exr, METADATA_DRIVER};
use quadray::vk::runtime::{restore_env, Runtime, BUNDLED_RUNTIME};

/// The runtime `make setup` fetched, if it did.
fn bundled() -> Option<Runtime> {
    Runtime::at(BUNDLED_RUNTIME).ok()
}

/// `quadray ARGS` from the user's environment (the test process's, less
/// what its runner set) plus `envs`.
fn quadray(args: &[&str], cwd: &Path, envs: &[(&str, &str)]) -> Output {
    let mut cmd = Command::new(env!("CARGO_BIN_EXE_quadray"));
    restore_env(&mut cmd);
    // The choice is the test's, not the environment the suite runs in.
    cmd.env_remove("QUADRAY_SYSTEM_VULKAN").env_remove("QUADRAY_VULKAN_RUNTIME");
    cmd.args(args).current_dir(cwd).stdin(Stdio::null()).env("RUST_BACKTRACE", "0");
    for (k, v) in envs {
        cmd.env(k, v);
    }
    cmd.output().expect("cannot start quadray")
}

/// The first line of `quadray devices`: which driver it chose.
fn chosen_by_quadray(envs: &[(&str, &str)]) -> String {
    let out = quadray(&["devices"], Path::new("."), envs);
    String::from_utf8_lossy(&out.stdout).lines().next().unwrap_or_default().to_string()
}

/// Whether `scripts/vulkan-runtime-run` puts a program on a runtime with
/// `envs`.
fn runner_chooses_a_runtime(envs: &[(&str, &str)]) -> bool {
    let mut cmd = Command::new(concat!(env!("CARGO_MANIFEST_DIR"), "/scripts/vulkan-runtime-run"));
    restore_env(&mut cmd);
    cmd.env_remove("QUADRAY_SYSTEM_VULKAN").env_remove("QUADRAY_VULKAN_RUNTIME");
    cmd.arg("/usr/bin/env").stdin(Stdio::null());
    for (k, v) in envs {
        cmd.env(k, v);
    }
    let out = cmd.output().expect("cannot start scripts/vulkan-runtime-run");
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    String::from_utf8_lossy(&out.stdout).lines().any(|l| l.starts_with("_QUADRAY_VULKAN_ROOT="))
}

#[test]
fn the_test_binaries_run_on_the_fetched_runtime() {
    let Some(runtime) = bundled() else {
        println!("no Vulkan runtime fetched ({BUNDLED_RUNTIME}): the tests run on the system's driver");
        return;
    };
    let users_choice =
        ["QUADRAY_SYSTEM_VULKAN", "QUADRAY_VULKAN_RUNTIME"].iter().find(|v| std::env::var_os(v).is_some());
    if let Some(v) = users_choice {
        println!("{v} is set: the runner follows it");
        return;
    }
    // Under the runtime's loader, /proc/self/exe is that loader.
    let exe = std::fs::canonicalize("/proc/self/exe").unwrap();
    assert_eq!(exe, std::fs::canonicalize(runtime.loader()).unwrap(), "the test binary was not started by the runner");
    let ctx = quadray::vk::Context::new(false).expect("a Vulkan device");
    println!("this test binary's device: {}, driver {}", ctx.device.name, ctx.device.driver);
    assert!(ctx.device.driver.contains("Mesa 26.") || ctx.device.driver.contains("Mesa 27."), "{}", ctx.device.driver);
}

#[test]
fn quadray_and_the_test_runner_choose_the_same_driver() {
    let root = BUNDLED_RUNTIME;
    let cases: [(&str, Vec<(&str, &str)>); 6] = [
        ("by default", vec![]),
        ("QUADRAY_SYSTEM_VULKAN=1", vec![("QUADRAY_SYSTEM_VULKAN", "1")]),
        ("QUADRAY_SYSTEM_VULKAN=True", vec![("QUADRAY_SYSTEM_VULKAN", "True")]),
        ("a driver named", vec![("VK_DRIVER_FILES", "/nonexistent/icd.json")]),
        ("a driver named the old way", vec![("VK_ICD_FILENAMES", "/nonexistent/icd.json")]),
        ("a runtime named", vec![("QUADRAY_VULKAN_RUNTIME", root), ("VK_DRIVER_FILES", "/nonexistent/icd.json")]),
    ];
    let have = bundled().is_some();
    for (label, envs) in cases {
        if !have && envs.iter().any(|(k, _)| *k == "QUADRAY_VULKAN_RUNTIME") {
            continue;
        }
        let line = chosen_by_quadray(&envs);
        assert!(line.starts_with("Vulkan: "), "{label}: `quadray devices` begins {line:?}");
        let quadray_on_runtime = line.starts_with("Vulkan: the Vulkan runtime at");
        let runner_on_runtime = runner_chooses_a_runtime(&envs);
        println!("{label:<28} quadray: {line}; runner on a runtime: {runner_on_runtime}");
        assert_eq!(quadray_on_runtime, runner_on_runtime, "{label}: {line}");
        let expected = have && (envs.is_empty() || envs[0].0 == "QUADRAY_VULKAN_RUNTIME");
        assert_eq!(quadray_on_runtime, expected, "{label}: {line}");
    }
}

#[test]
fn a_folder_that_is_not_a_runtime_is_refused_with_the_way_out() {
    let dir = tempfile::tempdir().unwrap();
    let root = dir.path().to_str().unwrap();
    let out = quadray(&["render", "-o", "x"], dir.path(), &[("QUADRAY_VULKAN_RUNTIME", root)]);
    let stderr = String::from_utf8_lossy(&out.stderr);
    assert!(!out.status.success());
    assert!(stderr.contains("is not a Vulkan runtime"), "{stderr}");
    assert!(stderr.contains("--system-vulkan"), "{stderr}");
    assert!(!stderr.contains("Stack backtrace"), "{stderr}");
    let names: Vec<_> = std::fs::read_dir(dir.path()).unwrap().collect();
    assert!(names.is_empty(), "nothing written: {names:?}");
}

/// A quadray started by a process on the runtime without `restore_env`
/// (as a script would start it) inherits the runtime's Vulkan environment;
/// asked for the system's driver, it puts the user's back and gets it.
#[test]
fn a_child_asked_for_the_system_driver_gets_it() {
    let Some(_) = bundled() else {
        println!("no Vulkan runtime fetched: nothing to restore");
        return;
    };
    if std::env::var_os("_QUADRAY_VULKAN_SAVED").is_none() {
        println!("this test binary is not on the runtime (the runner followed the user's choice)");
        return;
    }
    let out = Command::new(env!("CARGO_BIN_EXE_quadray"))
        .args(["--system-vulkan", "devices"])
        .env("RUST_BACKTRACE", "0")
        .output()
        .expect("cannot start quadray");
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(out.status.success(), "{}", String::from_utf8_lossy(&out.stderr));
    assert!(stdout.starts_with("Vulkan: the system's Vulkan driver"), "{stdout}");
    assert!(!stdout.contains("Mesa 26."), "the runtime's driver in a child asked for the system's:\n{stdout}");
    // And without the flag, the child restarts into the runtime.
    let out = Command::new(env!("CARGO_BIN_EXE_quadray")).arg("devices").output().unwrap();
    let stdout = String::from_utf8_lossy(&out.stdout);
    assert!(stdout.starts_with("Vulkan: the Vulkan runtime at"), "{stdout}");
}

/// A channel differs between the drivers beyond this, relative to
/// max(1, the runtime's value).
const MAX_CHANNEL_DIFFERENCE: f64 = 1e-4;
/// Share of pixels that may differ (a path whose branch a rounding step
/// flips goes elsewhere), as between the backends (tests/render/backends.rs).
const MAX_DIFFERING_PIXELS: f64 = 0.002;
/// Mean FLIP between the drivers.
const MAX_FLIP: f64 = 0.001;

/// The system's driver renders test scenes as the runtime's does: one with
/// perturbations (the case Mesa 26.1 crashed on, docs/stability.md), glass
/// and metal chains, textures, and a lens in fog (caustic and volume
/// passes); at 64x48, 4 spp, with the validation layer on both.
#[test]
fn the_system_driver_renders_the_test_scenes_as_the_runtime_does() {
    let dir = tempfile::tempdir().unwrap();
    let have = bundled().is_some();
    let mut failures = Vec::new();
    println!("{:<18} {}", "scene", crate::common::Agreement::header());
    for name in ["materials", "glass_metal", "textures", "lens_fog"] {
        let scene: PathBuf = [env!("CARGO_MANIFEST_DIR"), "scenes/tests", &format!("{name}.toml")].iter().collect();
        let render = |label: &str, extra: &[&str]| {
            let out_path = dir.path().join(format!("{name}-{label}.exr"));
            let mut args = vec!["render", scene.to_str().unwrap(), "--width", "64", "--height", "48", "--spp", "4"];
            args.extend_from_slice(&["--validation", "--no-denoise", "-o", out_path.to_str().unwrap()]);
            args.extend_from_slice(extra);
            let out = quadray(&args, dir.path(), &[]);
            assert!(out.status.success(), "{name} ({label}): {}", String::from_utf8_lossy(&out.stderr));
            read_render_exr(&out_path).unwrap()
        };
        let runtime = render("runtime", &[]);
        let system = render("system", &["--system-vulkan"]);
        let driver = |f: &quadray::jobs::output::ExrFile| {
            f.metadata.iter().find(|(k, _)| k == METADATA_DRIVER).map(|(_, v)| v.clone()).unwrap_or_default()
        };
        let (d_runtime, d_system) = (driver(&runtime), driver(&system));
        if have {
            assert_ne!(d_runtime, d_system, "{name}: the same driver twice");
        }
        let d = crate::common::Agreement::of(&runtime.output, &system.output, MAX_CHANNEL_DIFFERENCE);
        let (flip, differing, pixels) = (d.flip, d.differing, d.pixels);
        println!("{name:<18} {}   ({d_runtime} / {d_system})", d.row());
        failures.extend((flip > MAX_FLIP).then(|| format!("{name}: FLIP {flip}")));
        let share = differing as f64 / pixels as f64;
        failures
            .extend((share > MAX_DIFFERING_PIXELS).then(|| format!("{name}: {differing} of {pixels} pixels differ")));
    }
    assert!(failures.is_empty(), "the drivers' images differ: {failures:?}");
}
