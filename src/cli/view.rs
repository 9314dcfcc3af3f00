//! `quadray view`: the interactive viewer.

use std::path::PathBuf;

use super::common::*;
use anyhow::{bail, Context as _, Result};
use clap::Parser;
use quadray::model::scene::Preset;
use quadray::model::scene::MAX_IMAGE_SIZE;

#[cfg(feature = "viewer")]
#[derive(Parser, Debug)]
#[command(after_help = concat!("Keys:\n", "mouse: left drag orbits, right drag turns the view, wheel dollies\n",
    "W A S D: fly forward, left, back, right    Q E: down, up    (arrow keys: orbit)\n",
    "F: next filtering mode    P: next preset    1 2 3 4: preview, interactive, final, reference\n",
    "C: caustics on/off    V: volume on/off    N: denoise on/off    R: reset camera\n",
    "F12 or O: screenshot (PNG + EXR)    Esc: close"))]
pub(crate) struct ViewArgs {
    /// Scene file (TOML). Omit it to view the built-in default scene.
    pub(crate) scene: Option<PathBuf>,
    /// Quality preset to start with (default: the scene's, else `interactive`).
    #[command(flatten)]
    pub(crate) quality: QualityArgs,
    /// Initial window width (overrides `image.width`).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIZE))]
    pub(crate) width: Option<u32>,
    /// Initial window height (overrides `image.height`).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=MAX_IMAGE_SIZE))]
    pub(crate) height: Option<u32>,
    /// Samples per pixel to accumulate before the view stops refining
    /// (default: the preset's or scene's spp).
    #[arg(long, allow_negative_numbers = true, value_parser = clap::value_parser!(u32).range(1..=quadray::model::scene::MAX_SPP))]
    pub(crate) max_spp: Option<u32>,
    /// Start with the caustic and volume passes off (brute force).
    #[arg(long)]
    pub(crate) brute_force: bool,
    /// Folder for screenshots.
    #[arg(long, default_value = ".")]
    pub(crate) screenshot_dir: PathBuf,
    /// Steps to run, separated by `;` (for automation and tests): `wait N`
    /// (N spp on screen), `frames N`, `screenshot [NAME]`, `capture NAME`
    /// (the window as the X server shows it), `key K`, `orbit YAW PITCH`,
    /// `resize WxH`, `minimize`, `restore`, `close`. On a machine without a
    /// display: `xvfb-run -a quadray view --script ...`.
    #[arg(long)]
    pub(crate) script: Option<String>,
    /// Enable the Khronos validation layer; the command fails if it reports errors.
    #[arg(long, env = "QUADRAY_VALIDATION", value_parser = clap::builder::BoolishValueParser::new())]
    pub(crate) validation: bool,
}

#[cfg(feature = "viewer")]
pub(crate) fn view(args: ViewArgs) -> Result<()> {
    let mut scene = read_scene(args.scene.as_deref())?;
    if scene.image.preset.is_none() && args.quality.preset.is_none() {
        // A scene without a preset is viewed at `interactive` quality, its
        // own explicit settings aside: the scene's spp is meant for a final
        // render and would make a slow first view.
        let own = scene.quality();
        scene.apply_preset(Preset::Interactive);
        scene.image.max_depth = own.max_depth;
    }
    args.quality.apply(&mut scene);
    if let Some(w) = args.width {
        scene.image.width = w;
    }
    if let Some(h) = args.height {
        scene.image.height = h;
    }
    let script = match &args.script {
        Some(text) => quadray::viewer::actions::parse_script(text)?,
        None => Vec::new(),
    };
    if !args.screenshot_dir.is_dir() {
        bail!("--screenshot-dir {}: no such folder", args.screenshot_dir.display());
    }
    let name = args
        .scene
        .as_ref()
        .and_then(|p| p.file_stem())
        .map_or("default".to_string(), |s| s.to_string_lossy().into_owned());
    let summary = quadray::viewer::run(quadray::viewer::ViewerConfig {
        scene,
        name,
        validation: args.validation,
        max_spp: args.max_spp,
        brute_force: args.brute_force,
        screenshot_dir: args.screenshot_dir.clone(),
        script,
    })
    .context("viewer failed")?;
    eprintln!("viewer closed after {} frames", summary.frames);
    if let Some(c) = summary.counters {
        if c.errors() > 0 {
            bail!("the validation layer reported {} error(s)", c.errors());
        }
    }
    Ok(())
}
