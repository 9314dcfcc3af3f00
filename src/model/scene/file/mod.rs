//! Reading a [`Scene`] from TOML. The format is documented field by field in
//! `scenes/README.md`.
//!
//! Parsing has two stages, and every error names the file, line, column and
//! field (`scenes/foo.toml:12:10: objects[1].sphere.radius: must be positive
//! (got -1)`), followed by the offending source line:
//!
//! 1. Serde deserializes the text into the private `Raw*` structs. Their leaf
//!    types (`Finite`, `Positive`, `Triple`, `Coefficients`, …) check their own
//!    values inside the TOML deserializer, so a bad value is reported at the
//!    span of its own token; `serde_path_to_error` records the field path on
//!    the way, and `deny_unknown_fields` rejects misspelt keys.
//! 2. Checks that involve more than one value (exactly one shape key per
//!    object, material names, keys that fit a material's or light's `type`,
//!    a conductor's one Fresnel form, a rect light's edges, the camera's
//!    geometry, bounded surfaces, not both `background` and `[environment]`)
//!    run on the raw tree, which keeps `toml::Spanned` wrappers around the
//!    tables and values those checks report on.
//!
//! Array indices in field paths count from 0, as in `objects[0]`.

mod build;
mod schema;
mod source;
#[cfg(test)]
mod tests;
mod textures;
#[macro_use]
mod values;

use std::path::{Path, PathBuf};

use super::{
    Camera, CameraKeyframe, CausticSettings, ConductorFresnel, DenoiseQuality, EnvironmentMapSettings, FilterMode,
    ImageSettings, Light, Material, MaterialKind, MaterialMaps, Medium, Preset, Quality, Scene, SceneObject,
    TextureImage, UvMapping, UvSettings, VolumeSettings,
};

use build::*;
use schema::*;
use source::*;
use textures::*;
use values::*;

/// The file name used in messages about [`DEFAULT_SCENE`].
pub const DEFAULT_SCENE_NAME: &str = "<embedded default scene>";

/// The default showcase scene (`scenes/default.toml`), built into the binary.
pub const DEFAULT_SCENE: &str = include_str!("../../../../scenes/default.toml");

/// Largest accepted image width or height.
pub const MAX_IMAGE_SIZE: i64 = 16384;
/// Largest accepted samples per pixel.
pub const MAX_SPP: i64 = 1 << 20;
pub use super::DEFAULT_MAX_DEPTH;
/// Largest accepted `[image] max_depth`.
pub const MAX_DEPTH: i64 = 64;
/// Largest accepted `[caustics] rays` (per light and light sample).
pub const MAX_CAUSTIC_RAYS: i64 = 1 << 24;
/// Largest accepted `[caustics] light_samples`.
pub const MAX_CAUSTIC_LIGHT_SAMPLES: i64 = 1024;
/// Largest accepted `[volume] samples`.
pub const MAX_VOLUME_SAMPLES: i64 = 65536;
/// Largest accepted `count` of a `[[objects.scatter]]` generator.
pub const MAX_SCATTER_COUNT: i64 = 1_000_000;
/// Name of the built-in material given to objects without a `material` key.
pub const DEFAULT_MATERIAL_NAME: &str = "<default>";
/// Largest accepted `count` of a generated `bumps` texture.
pub const MAX_TEXTURE_BUMPS: i64 = 1_000_000;
/// Largest accepted width of the generated sky (its height is at most half).
pub const MAX_SKY_WIDTH: u32 = 4096;

/// Why a scene could not be loaded. `Display` gives the whole message.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The scene file could not be read.
    #[error("{}: cannot read the scene file", .path.display())]
    Read {
        /// The path that was asked for.
        path: PathBuf,
        /// The I/O error.
        source: std::io::Error,
    },
    /// The text is not valid TOML, or not a valid scene.
    #[error("{}", render_invalid(.file, *.line, *.column, .field, .message, .snippet))]
    Invalid {
        /// File name as given to [`parse_scene`].
        file: String,
        /// Line of the offending text, from 1.
        line: usize,
        /// Column of the offending text in characters, from 1.
        column: usize,
        /// Field path such as `objects[1].sphere.radius` (indices from 0);
        /// empty for TOML syntax errors.
        field: String,
        /// What is wrong.
        message: String,
        /// The offending source line with a caret line under it (may be empty).
        snippet: String,
    },
}

fn render_invalid(file: &str, line: usize, column: usize, field: &str, message: &str, snippet: &str) -> String {
    let mut s = format!("{file}:{line}:{column}: ");
    if !field.is_empty() {
        s.push_str(field);
        s.push_str(": ");
    }
    s.push_str(message);
    s.push_str(snippet);
    s
}

/// Reads and parses the scene file at `path`; messages name the path as given.
pub fn load_scene(path: &Path) -> Result<Scene, SceneError> {
    let text = std::fs::read_to_string(path).map_err(|source| SceneError::Read { path: path.to_path_buf(), source })?;
    parse_scene(&text, &path.display().to_string())
}

/// Parses a scene from TOML text; `file_name` is used in error messages, and
/// relative texture paths are resolved against its parent folder (against the
/// current directory for [`DEFAULT_SCENE_NAME`]).
pub fn parse_scene(source: &str, file_name: &str) -> Result<Scene, SceneError> {
    let dir = if file_name == DEFAULT_SCENE_NAME { None } else { Path::new(file_name).parent() };
    let src = Source { text: source, file: file_name, dir: dir.unwrap_or(Path::new("")) };
    let raw: RawScene =
        serde_path_to_error::deserialize(toml::Deserializer::new(source)).map_err(|e| src.toml_error(e))?;
    build_scene(&src, raw)
}

// ---------------------------------------------------------------------------
// Error locations
// ---------------------------------------------------------------------------
