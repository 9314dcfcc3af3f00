//! quadray: a Vulkan path tracer for functionally defined objects
//! (perturbed quadrics), after Vyatkin & Dolgovesov, "Smoothing of
//! functionally defined objects in scenes with global illumination" (2022).
//!
//! Eight modules, bottom up (docs/architecture.md, "Layers"; each uses
//! only its own layer and those below):
//!
//! - [`gpu`]: what the host shares with the shaders: binding numbers,
//!   specialisation constants and enum values, and the compiled SPIR-V.
//! - [`vk`]: Vulkan through `ash`, one concept a file.
//! - [`util`]: leaf libraries: atomic files, a stable hash, progress bars,
//!   Intel Open Image Denoise.
//! - [`model`]: the CPU model: exact f64 geometry, textures, the scene and
//!   its TOML files, the f64 twins of the GPU's sampling code.
//! - [`passes`]: the GPU passes over an uploaded scene (render, caustics,
//!   volume) and the film they fill.
//! - [`jobs`]: long renders (checkpoints, tiles, frames), image files,
//!   merging tiles, Slurm farms.
//! - [`tools`]: benchmarks, metrics, plots.
//! - [`viewer`]: the interactive window (feature `viewer`).

// Every `unsafe` block says why it is sound (clippy runs with -D warnings).
#![warn(clippy::undocumented_unsafe_blocks)]

pub mod gpu;
pub mod jobs;
pub mod model;
pub mod passes;
pub mod tools;
pub mod util;
#[cfg(feature = "viewer")]
pub mod viewer;
pub mod vk;

use model::scene;

pub use passes::RenderError;

/// Uploads `scene` and renders it at its own image settings, reporting
/// progress as (done, total) work units.
pub fn render_scene(
    ctx: &vk::Context,
    scene: &scene::Scene,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<passes::RenderOutput, RenderError> {
    render_scene_with(ctx, scene, Default::default(), progress)
}

/// [`render_scene`] with a variant of the render shader (benchmark
/// breakdowns, brute force, path recording); everything else, the texture
/// filtering included, comes from the scene.
pub fn render_scene_with(
    ctx: &vk::Context,
    scene: &scene::Scene,
    variant: passes::RenderVariant,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<passes::RenderOutput, RenderError> {
    let mut cmds = vk::Commands::new(&ctx.device)?;
    let gpu = passes::GpuScene::for_render(&ctx.device, &mut cmds, scene)?;
    passes::render(&ctx.device, &mut cmds, &gpu, scene, variant, progress)
}
