//! quadray: a Vulkan path tracer for functionally defined objects
//! (perturbed quadrics), after Vyatkin & Dolgovesov, "Smoothing of
//! functionally defined objects in scenes with global illumination" (2022).
//!
//! - [`geometry`]: the surfaces in f64 on the CPU (bounds, cells, the
//!   reference intersection).
//! - [`scene`]: the scene model and its TOML files.
//! - [`vk`]: the Vulkan backend.
//! - [`passes`]: GPU passes.
//! - [`output`]: PNG and EXR files, written atomically.

// Every `unsafe` block says why it is sound (clippy runs with -D warnings).
#![warn(clippy::undocumented_unsafe_blocks)]

pub mod bench;
pub mod covariance;
pub mod denoise;
pub mod farm;
pub mod files;
pub mod filter_bench;
pub mod geometry;
pub mod hash;
pub mod job;
pub mod merge;
pub mod metrics;
pub mod output;
pub mod passes;
pub mod plot;
pub mod progress;
pub mod sampling;
pub mod scene;
pub mod shader_interface;
pub mod shaders;
pub mod texture;
pub mod throughput;
#[cfg(feature = "viewer")]
pub mod viewer;
pub mod vk;

/// Errors of rendering a scene.
#[derive(Debug, thiserror::Error)]
pub enum RenderError {
    /// The Vulkan backend failed.
    #[error(transparent)]
    Vk(#[from] vk::VkError),
    /// The scene uses more texture maps than the shader's texture array holds.
    #[error("the scene uses {0} texture maps; at most {max} are supported", max = shader_interface::MAX_TEXTURES - 1)]
    TooManyTextures(usize),
    /// A texture map is too large for the device in every encoding that
    /// holds its values.
    #[error(transparent)]
    TextureTooLarge(#[from] texture::encoding::TextureTooLarge),
    /// An object cannot be rendered.
    #[error("object `{object}`: {source}")]
    Geometry {
        /// The object's name.
        object: String,
        /// What is wrong.
        source: geometry::GeometryError,
    },
    /// Pixel bounds that are empty or outside the frame.
    #[error(transparent)]
    Bounds(#[from] passes::film::BoundsError),
    /// An accumulation that does not fit the renderer (another image size,
    /// crop or sample target).
    #[error("the accumulation does not fit this render: {0}")]
    Accumulation(String),
}

impl From<ash::vk::Result> for RenderError {
    fn from(e: ash::vk::Result) -> Self {
        Self::Vk(e.into())
    }
}

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
