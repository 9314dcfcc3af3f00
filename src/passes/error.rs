//! The error every GPU pass returns (re-exported as `quadray::RenderError`).

use crate::gpu::shader_interface;
use crate::model::{geometry, texture};
use crate::vk;

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
    Bounds(#[from] super::film::BoundsError),
    /// An accumulation that does not fit the renderer (another image size,
    /// crop or sample target).
    #[error("the accumulation does not fit this render: {0}")]
    Accumulation(String),
    /// The wavefront pass asked for on the pipeline backend.
    #[error("the wavefront pass traces with ray queries; use `--backend ray-query` or `--kernel megakernel`")]
    WavefrontNeedsRayQueries,
}

impl From<ash::vk::Result> for RenderError {
    fn from(e: ash::vk::Result) -> Self {
        Self::Vk(e.into())
    }
}
