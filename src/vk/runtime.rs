//! Which Vulkan driver the process runs on: the system's, or a Vulkan
//! runtime of its own (a current Mesa lavapipe with the glibc, LLVM, loader
//! and validation layer it was built for; `scripts/setup-vulkan-runtime.sh`
//! fetches one, docs/vulkan-runtime.md).
//!
//! A runtime's glibc is newer than the system's, so it cannot be loaded into
//! a process that started on the system's; the process restarts itself
//! through the runtime's own dynamic loader instead (`ld-linux-x86-64.so.2
//! --library-path ... quadray ...`), once, before any Vulkan call: the
//! binary built here runs unchanged. `exec` keeps the process id, so
//! signals, the exit status and a parent's wait pass through.
//!
//! Where the runtime is looked for, in this order:
//! 1. `--system-vulkan` or `QUADRAY_SYSTEM_VULKAN=1`: none, the system's driver;
//! 2. `$QUADRAY_VULKAN_RUNTIME` (a runtime's root folder; only there when set);
//! 3. none where the user chose a driver (`VK_DRIVER_FILES` or
//!    `VK_ICD_FILENAMES` set) or the machine has a GPU (`/dev/dri/renderD*`,
//!    `/dev/nvidiactl`): the runtime holds lavapipe alone, and would hide it;
//! 4. `third_party/vulkan-runtime/root` of the source tree this binary was
//!    built from, where `make setup` puts it;
//! 5. none: the system's driver.
//!
//! `scripts/vulkan-runtime-run` makes the same choice for cargo's test and
//! bench binaries (`tests/cli/runtime.rs` checks that both agree).
//!
//! The runtime's Vulkan environment (`VK_DRIVER_FILES`, `VK_LAYER_PATH`, ...)
//! is set for the restarted process only: the values it replaced travel in
//! [`SAVED_ENV`], and [`enter`] in a child process, or [`restore_env`] on a
//! command about to start another program, puts them back first.

use std::ffi::{OsStr, OsString};
use std::path::{Path, PathBuf};
use std::sync::OnceLock;

/// The environment variable that names a runtime's root folder.
pub const RUNTIME_ENV: &str = "QUADRAY_VULKAN_RUNTIME";
/// The environment variable that keeps the system's driver (`1`, `true`,
/// `yes` or `on`).
pub const SYSTEM_ENV: &str = "QUADRAY_SYSTEM_VULKAN";
/// Where `make setup` puts the runtime, in the source tree the binary was
/// built from.
pub const BUNDLED_RUNTIME: &str = concat!(env!("CARGO_MANIFEST_DIR"), "/third_party/vulkan-runtime/root");

/// Set on the restart (and by `scripts/vulkan-runtime-run`) to the process
/// id that restarts: `exec` keeps it, so the restarted process knows itself
/// and a child, whose id differs, does not mistake an inherited value for
/// its own. The guard against restarting twice.
pub const GUARD_ENV: &str = "_QUADRAY_VULKAN_RESTARTED";
/// The runtime's root folder, beside the guard.
const ROOT_ENV: &str = "_QUADRAY_VULKAN_ROOT";
/// The binary's own path (under the loader, `/proc/self/exe` is the loader).
const EXE_ENV: &str = "_QUADRAY_VULKAN_EXE";
/// The values the runtime's environment replaced: `NAME=value` or `NAME`
/// (it was unset), separated by newlines.
pub const SAVED_ENV: &str = "_QUADRAY_VULKAN_SAVED";
/// The values the runtime set, in the same form: a variable that no longer
/// has it was set on purpose since (a test's `VK_LAYER_PATH`) and is kept.
pub const SET_ENV: &str = "_QUADRAY_VULKAN_SET";

/// The Vulkan loader variables a runtime sets or clears
/// ([`Runtime::vulkan_env`]).
const VULKAN_VARS: [&str; 7] = [
    "VK_DRIVER_FILES",
    "VK_LAYER_PATH",
    "VK_IMPLICIT_LAYER_PATH",
    "VK_ICD_FILENAMES",
    "VK_ADD_DRIVER_FILES",
    "VK_ADD_LAYER_PATH",
    "VK_ADD_IMPLICIT_LAYER_PATH",
];

/// Why the runtime could not be used.
#[derive(Debug, thiserror::Error)]
pub enum RuntimeError {
    /// `$QUADRAY_VULKAN_RUNTIME` names a folder that is not a runtime.
    #[error(
        "{RUNTIME_ENV}={root} is not a Vulkan runtime: {missing} is missing (scripts/setup-vulkan-runtime.sh \
         makes one; unset {RUNTIME_ENV} to use the one `make setup` fetched, or pass --system-vulkan)"
    )]
    NotARuntime {
        /// The folder.
        root: String,
        /// The first file it lacks.
        missing: String,
    },
}

/// A Vulkan runtime: a root folder with Debian's layout (`usr/lib64`,
/// `usr/lib/x86_64-linux-gnu`, `usr/share/vulkan`).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Runtime {
    /// The root folder.
    pub root: PathBuf,
}

impl Runtime {
    /// The runtime at `root`, or the first file it lacks.
    pub fn at(root: impl Into<PathBuf>) -> Result<Self, RuntimeError> {
        let runtime = Self { root: root.into() };
        for file in [runtime.loader(), runtime.driver_manifest(), runtime.library_dir().join("libvulkan.so.1")] {
            if !file.exists() {
                return Err(RuntimeError::NotARuntime {
                    root: runtime.root.display().to_string(),
                    missing: file.display().to_string(),
                });
            }
        }
        Ok(runtime)
    }

    /// The runtime's dynamic loader.
    pub fn loader(&self) -> PathBuf {
        self.root.join("usr/lib64/ld-linux-x86-64.so.2")
    }

    /// The folder of its shared libraries.
    pub fn library_dir(&self) -> PathBuf {
        self.root.join("usr/lib/x86_64-linux-gnu")
    }

    /// lavapipe's driver manifest.
    pub fn driver_manifest(&self) -> PathBuf {
        self.root.join("usr/share/vulkan/icd.d/lvp_icd.json")
    }

    /// The Vulkan environment of a process on this runtime, from the
    /// current one: each of [`VULKAN_VARS`] with its value, `None` to clear
    /// it. The driver is the runtime's lavapipe alone; the layer paths are
    /// the runtime's unless the user set them (their choice is kept, like
    /// the `VK_ADD_*_LAYER_PATH` they set).
    fn vulkan_env(&self) -> [(&'static str, Option<OsString>); 7] {
        let share = self.root.join("usr/share/vulkan");
        let [driver, layers, implicit, icd, add_driver, add_layers, add_implicit] = VULKAN_VARS;
        let users = |name: &str, ours: PathBuf| Some(std::env::var_os(name).unwrap_or_else(|| ours.into()));
        [
            (driver, Some(self.driver_manifest().into())),
            (layers, users(layers, share.join("explicit_layer.d"))),
            (implicit, users(implicit, share.join("implicit_layer.d"))),
            (icd, None),
            (add_driver, None),
            (add_layers, std::env::var_os(add_layers)),
            (add_implicit, std::env::var_os(add_implicit)),
        ]
    }
}

/// Where the process's Vulkan driver comes from, as [`enter`] decided.
#[derive(Clone, Debug, PartialEq, Eq)]
pub enum Driver {
    /// The system's Vulkan loader and drivers.
    System,
    /// A runtime's, through its loader.
    Runtime(Runtime),
}

static DRIVER: OnceLock<Driver> = OnceLock::new();
static EXE: OnceLock<PathBuf> = OnceLock::new();

/// Where this process's Vulkan driver comes from ([`Driver::System`] in a
/// process that did not call [`enter`], such as a test binary started
/// without `scripts/vulkan-runtime-run`).
pub fn driver() -> Driver {
    DRIVER.get().cloned().unwrap_or(Driver::System)
}

/// This binary's path (`std::env::current_exe` names the runtime's loader
/// in a restarted process).
pub fn current_exe() -> std::io::Result<PathBuf> {
    match EXE.get() {
        Some(p) => Ok(p.clone()),
        None => std::env::current_exe(),
    }
}

/// Whether an environment value says yes (`1`, `true`, `yes`, `on`).
fn truthy(v: &OsStr) -> bool {
    matches!(v.to_string_lossy().trim().to_ascii_lowercase().as_str(), "1" | "true" | "yes" | "on")
}

/// The runtime to use, by the order in the module documentation.
pub fn choose(system: bool) -> Result<Option<Runtime>, RuntimeError> {
    if system || std::env::var_os(SYSTEM_ENV).is_some_and(|v| truthy(&v)) {
        return Ok(None);
    }
    if let Some(root) = std::env::var_os(RUNTIME_ENV) {
        return Runtime::at(PathBuf::from(root)).map(Some);
    }
    if chosen_driver().is_some() || gpu_device().is_some() {
        return Ok(None);
    }
    Ok(Runtime::at(BUNDLED_RUNTIME).ok())
}

/// The loader variable by which the user chose a driver, if any.
pub fn chosen_driver() -> Option<&'static str> {
    ["VK_DRIVER_FILES", "VK_ICD_FILENAMES"].into_iter().find(|v| std::env::var_os(v).is_some_and(|s| !s.is_empty()))
}

/// A GPU's device node, if the machine has one.
pub fn gpu_device() -> Option<PathBuf> {
    let nvidia = PathBuf::from("/dev/nvidiactl");
    if nvidia.exists() {
        return Some(nvidia);
    }
    let dri = std::fs::read_dir("/dev/dri").ok()?;
    dri.filter_map(Result::ok)
        .map(|e| e.path())
        .find(|p| p.file_name().is_some_and(|n| n.to_string_lossy().starts_with("renderD")))
}

/// Serialises variables and their values (`None`: unset) in the form of
/// [`SAVED_ENV`] and [`SET_ENV`].
fn serialise<'a>(vars: impl IntoIterator<Item = (&'a str, Option<OsString>)>) -> OsString {
    let mut out = OsString::new();
    for (i, (name, value)) in vars.into_iter().enumerate() {
        if i > 0 {
            out.push("\n");
        }
        out.push(name);
        if let Some(v) = value {
            out.push("=");
            out.push(v);
        }
    }
    out
}

/// The saved values of [`SAVED_ENV`]: each name with its value, `None`
/// where it was unset.
fn saved(text: &OsStr) -> Vec<(String, Option<String>)> {
    text.to_string_lossy()
        .split('\n')
        .filter(|l| !l.is_empty())
        .map(|l| match l.split_once('=') {
            Some((k, v)) => (k.to_string(), Some(v.to_string())),
            None => (l.to_string(), None),
        })
        .collect()
}

/// Puts back, on a command that starts another program from a process on a
/// runtime, the Vulkan environment the runtime replaced, so that the program
/// (an older quadray, a scheduler) sees the user's. A quadray started
/// without it restores it itself.
pub fn restore_env(cmd: &mut std::process::Command) {
    for (name, value) in restorations() {
        match value {
            Some(v) => cmd.env(name, v),
            None => cmd.env_remove(name),
        };
    }
    for name in [SAVED_ENV, SET_ENV, GUARD_ENV, ROOT_ENV, EXE_ENV] {
        cmd.env_remove(name);
    }
}

/// What puts the user's Vulkan environment back: each variable the runtime
/// set that still has the runtime's value, with its value before (`None`:
/// unset). Empty outside a runtime's processes.
fn restorations() -> Vec<(String, Option<String>)> {
    let (Some(saved_text), Some(set_text)) = (std::env::var_os(SAVED_ENV), std::env::var_os(SET_ENV)) else {
        return Vec::new();
    };
    let set = saved(&set_text);
    saved(&saved_text)
        .into_iter()
        .filter(|(name, _)| {
            let now = std::env::var_os(name).map(|v| v.to_string_lossy().into_owned());
            set.iter().any(|(n, v)| n == name && *v == now)
        })
        .collect()
}

/// Decides the driver and, for a runtime, restarts the process through its
/// loader (never returning then). Call it first in `main`, before any other
/// thread exists (it changes the process's environment) and before any
/// Vulkan call. `system`: the command line's `--system-vulkan`, which is
/// passed on to child processes as `QUADRAY_SYSTEM_VULKAN=1`.
///
/// A restart that fails (the loader cannot be executed) is reported as a
/// warning and the process goes on with the system's driver.
pub fn enter(system: bool) -> Result<Driver, RuntimeError> {
    let pid = std::process::id().to_string();
    let guard = std::env::var_os(GUARD_ENV);
    let restarted = guard.as_deref() == Some(OsStr::new(&pid));
    let root = std::env::var_os(ROOT_ENV);
    let exe = std::env::var_os(EXE_ENV);
    // SAFETY (all set_var/remove_var below): called first in main, before
    // any other thread exists.
    for name in [GUARD_ENV, ROOT_ENV, EXE_ENV] {
        std::env::remove_var(name);
    }
    if restarted {
        // This process is the restart: its Vulkan environment is the
        // runtime's, SAVED_ENV and SET_ENV stay for its children.
        let runtime = Runtime { root: root.map(PathBuf::from).unwrap_or_default() };
        if let Some(exe) = exe {
            let _ = EXE.set(PathBuf::from(exe));
        }
        let driver = Driver::Runtime(runtime);
        let _ = DRIVER.set(driver.clone());
        return Ok(driver);
    }
    // A child of a process on a runtime starts from the user's environment.
    for (name, value) in restorations() {
        match value {
            Some(v) => std::env::set_var(name, v),
            None => std::env::remove_var(name),
        }
    }
    std::env::remove_var(SAVED_ENV);
    std::env::remove_var(SET_ENV);
    if system {
        std::env::set_var(SYSTEM_ENV, "1");
    }
    let Some(runtime) = choose(system)? else {
        let _ = DRIVER.set(Driver::System);
        return Ok(Driver::System);
    };
    let err = restart(&runtime, &pid);
    // The logger is not set up yet.
    eprintln!(
        "warning: cannot start through the Vulkan runtime at {} ({err}); using the system's Vulkan driver \
         (--system-vulkan says so without this warning)",
        runtime.root.display()
    );
    let _ = DRIVER.set(Driver::System);
    Ok(Driver::System)
}

/// Replaces the process with itself started through `runtime`'s loader;
/// returns only the error of a failed `exec`.
fn restart(runtime: &Runtime, pid: &str) -> std::io::Error {
    use std::os::unix::process::CommandExt;
    let exe = match std::env::current_exe() {
        Ok(e) => e,
        Err(e) => return e,
    };
    let mut args = std::env::args_os();
    let argv0 = args.next().unwrap_or_else(|| exe.clone().into_os_string());
    let mut cmd = std::process::Command::new(runtime.loader());
    cmd.arg("--argv0").arg(argv0).arg("--library-path").arg(runtime.library_dir()).arg(&exe).args(args);
    cmd.env(SAVED_ENV, serialise(VULKAN_VARS.map(|name| (name, std::env::var_os(name)))));
    let env = runtime.vulkan_env();
    cmd.env(SET_ENV, serialise(env.clone()));
    for (name, value) in env {
        match value {
            Some(v) => cmd.env(name, v),
            None => cmd.env_remove(name),
        };
    }
    cmd.env(GUARD_ENV, pid).env(ROOT_ENV, &runtime.root).env(EXE_ENV, &exe);
    cmd.exec()
}

/// For messages: "the Vulkan runtime at ROOT", or "the system's Vulkan
/// driver" and why.
pub fn describe(driver: &Driver) -> String {
    match driver {
        Driver::System => {
            let why = if std::env::var_os(SYSTEM_ENV).is_some_and(|v| truthy(&v)) {
                " (--system-vulkan)".to_string()
            } else if let Some(v) = chosen_driver() {
                format!(" ({v} names the driver)")
            } else if let Some(gpu) = gpu_device() {
                format!(" (a GPU is present: {})", gpu.display())
            } else if Runtime::at(BUNDLED_RUNTIME).is_err() {
                " (no Vulkan runtime fetched: `make setup` fetches one)".to_string()
            } else {
                String::new()
            };
            format!("the system's Vulkan driver{why}")
        }
        Driver::Runtime(r) => format!("the Vulkan runtime at {}", display_root(&r.root)),
    }
}

/// `root`, shortened to `third_party/...` when it is the bundled one.
fn display_root(root: &Path) -> String {
    let bundled = Path::new(BUNDLED_RUNTIME);
    match root.strip_prefix(env!("CARGO_MANIFEST_DIR")) {
        Ok(rel) if root == bundled => rel.display().to_string(),
        _ => root.display().to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn saved_values_round_trip_set_and_unset() {
        let text = OsString::from("VK_DRIVER_FILES=/a/b.json\nVK_LAYER_PATH\nVK_ADD_LAYER_PATH=x=y");
        assert_eq!(
            saved(&text),
            vec![
                ("VK_DRIVER_FILES".to_string(), Some("/a/b.json".to_string())),
                ("VK_LAYER_PATH".to_string(), None),
                ("VK_ADD_LAYER_PATH".to_string(), Some("x=y".to_string())),
            ]
        );
    }

    #[test]
    fn a_folder_without_a_loader_is_not_a_runtime() {
        let dir = tempfile::tempdir().unwrap();
        let err = Runtime::at(dir.path()).unwrap_err().to_string();
        assert!(err.contains("ld-linux-x86-64.so.2 is missing"), "{err}");
    }

    #[test]
    fn the_runtime_sets_its_driver_and_clears_the_others() {
        let r = Runtime { root: PathBuf::from("/rt") };
        let env = r.vulkan_env();
        assert_eq!(env[0].1.as_deref(), Some(OsStr::new("/rt/usr/share/vulkan/icd.d/lvp_icd.json")));
        assert!(env[3..5].iter().all(|(_, v)| v.is_none()), "{env:?}");
        assert_eq!(env.map(|(n, _)| n), VULKAN_VARS);
    }
}
