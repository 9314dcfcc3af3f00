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

use std::fmt::{self, Write as _};
use std::marker::PhantomData;
use std::ops::Range;
use std::path::{Path, PathBuf};

use glam::{DAffine3, DQuat, DVec2, DVec3, EulerRot, Vec3};
use serde::de::{self, Deserializer, MapAccess, SeqAccess, Visitor};
use serde::Deserialize;
use toml::Spanned;

use crate::hash::hash_unit;

use super::{
    Camera, CameraKeyframe, CausticSettings, ConductorFresnel, EnvironmentMapSettings, FilterMode, ImageSettings,
    Light, Material, MaterialKind, MaterialMaps, Medium, Preset, Quality, Scene, SceneObject, TextureImage, UvMapping,
    UvSettings, VolumeSettings,
};
use crate::geometry::{Aabb, FunctionalObject, GeometryError, Perturbation, Quadric};
use crate::sampling::envmap::procedural_sky;
use crate::texture::{self, TextureKind, TextureUsage, MAX_TEXTURE_SIZE};

/// The file name used in messages about [`DEFAULT_SCENE`].
pub const DEFAULT_SCENE_NAME: &str = "<embedded default scene>";

/// The default showcase scene (`scenes/default.toml`), built into the binary.
pub const DEFAULT_SCENE: &str = include_str!("../../scenes/default.toml");

/// Largest accepted image width or height.
pub const MAX_IMAGE_SIZE: i64 = 16384;
/// Largest accepted samples per pixel.
pub const MAX_SPP: i64 = 1 << 20;
/// Default `[image] max_depth`.
pub const DEFAULT_MAX_DEPTH: u32 = 6;
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

struct Source<'a> {
    text: &'a str,
    file: &'a str,
    /// The folder relative texture paths start from.
    dir: &'a Path,
}

impl Source<'_> {
    /// An error at `span` (byte range into the text; start of file if none).
    fn error(&self, span: Option<Range<usize>>, field: impl Into<String>, message: impl Into<String>) -> SceneError {
        let text = self.text;
        let span = span.unwrap_or(0..0);
        let mut start = span.start.min(text.len());
        while !text.is_char_boundary(start) {
            start -= 1;
        }
        let line_start = text[..start].rfind('\n').map_or(0, |i| i + 1);
        let line_end = text[start..].find('\n').map_or(text.len(), |i| start + i);
        let line = text[..start].matches('\n').count() + 1;
        let column = text[line_start..start].chars().count() + 1;
        let mut end = span.end.clamp(start, line_end);
        while !text.is_char_boundary(end) {
            end -= 1;
        }
        let source_line = text[line_start..line_end].trim_end_matches('\r');
        let snippet = if source_line.trim().is_empty() {
            String::new()
        } else {
            // Keep tabs in the padding so that the caret lines up.
            let pad: String = text[line_start..start].chars().map(|c| if c == '\t' { '\t' } else { ' ' }).collect();
            let width = text[start..end].trim_end_matches('\r').chars().count().max(1);
            let gutter = line.to_string().len();
            format!("\n{line:>gutter$} | {source_line}\n{:>gutter$} | {pad}{}", "", "^".repeat(width))
        };
        SceneError::Invalid {
            file: self.file.to_owned(),
            line,
            column,
            field: field.into(),
            message: message.into(),
            snippet,
        }
    }

    /// The line (from 1) of byte offset `pos`.
    fn line_of(&self, pos: usize) -> usize {
        let mut pos = pos.min(self.text.len());
        while !self.text.is_char_boundary(pos) {
            pos -= 1;
        }
        self.text[..pos].matches('\n').count() + 1
    }

    fn toml_error(&self, e: serde_path_to_error::Error<toml::de::Error>) -> SceneError {
        let mut field = String::new();
        for segment in e.path() {
            match segment {
                serde_path_to_error::Segment::Seq { index } => {
                    let _ = write!(field, "[{index}]");
                }
                serde_path_to_error::Segment::Map { key } | serde_path_to_error::Segment::Enum { variant: key } => {
                    // Skip the private keys of `toml::Spanned`.
                    if !key.starts_with("$__") {
                        if !field.is_empty() {
                            field.push('.');
                        }
                        field.push_str(key);
                    }
                }
                serde_path_to_error::Segment::Unknown => {}
            }
        }
        let inner = e.inner();
        let mut message = inner.message().trim().lines().map(str::trim).collect::<Vec<_>>().join(": ");
        if let Some(missing) = message.strip_prefix("missing field `").and_then(|m| m.strip_suffix('`')) {
            if !field.is_empty() {
                field.push('.');
            }
            field.push_str(missing);
            message = format!("the required key `{missing}` is missing");
        } else if field.is_empty() {
            message = format!("invalid TOML: {message}");
        } else if message == "invalid type: map, expected a sequence" {
            // The table header of the array: the path without its indices.
            let header: String = field.split('[').map(|p| p.split_once(']').map_or(p, |(_, rest)| rest)).collect();
            message.push_str(&format!(" (write [[{header}]] with double brackets for each entry)"));
        } else if message.starts_with("unknown field `background`") && field.contains('.') {
            message.push_str(
                " (top-level keys such as `background` must come before the first [table] header, \
                 or TOML puts them in that table)",
            );
        }
        self.error(inner.span(), field, message)
    }
}

// ---------------------------------------------------------------------------
// Self-checking leaf types
// ---------------------------------------------------------------------------

/// A number type that checks its value while being deserialized, so that a
/// bad value is reported at its own token.
trait Number: Copy {
    /// Accepts `v` (already known to be finite) or says why not.
    fn check(v: f64) -> Result<(), String>;
    fn new(v: f64) -> Self;
    fn get(self) -> f64;

    fn parse(v: f64) -> Result<Self, String> {
        if !v.is_finite() {
            return Err(format!("must be a finite number (got {v})"));
        }
        Self::check(v).map(|()| Self::new(v))
    }
}

struct NumberVisitor<T>(PhantomData<T>);

impl<'de, T: Number> Visitor<'de> for NumberVisitor<T> {
    type Value = T;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<T, E> {
        T::parse(v).map_err(E::custom)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<T, E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<T, E> {
        self.visit_f64(v as f64)
    }
}

/// Largest accepted colour component (they become f32 on the GPU).
const MAX_COLOUR: f64 = 1e30;

macro_rules! number_type {
    ($(#[$meta:meta])* $name:ident, |$v:ident| $check:expr) => {
        $(#[$meta])*
        #[derive(Clone, Copy, Debug)]
        struct $name(f64);

        impl Number for $name {
            fn check($v: f64) -> Result<(), String> {
                $check
            }
            fn new(v: f64) -> Self {
                Self(v)
            }
            fn get(self) -> f64 {
                self.0
            }
        }

        impl<'de> Deserialize<'de> for $name {
            fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
                d.deserialize_any(NumberVisitor::<$name>(PhantomData))
            }
        }
    };
}

fn require(ok: bool, message: impl FnOnce() -> String) -> Result<(), String> {
    if ok {
        Ok(())
    } else {
        Err(message())
    }
}

number_type!(
    /// Any finite number.
    Finite,
    |_v| Ok(())
);
number_type!(
    /// A finite number > 0.
    Positive,
    |v| require(v > 0.0, || format!("must be positive (got {v})"))
);
number_type!(
    /// A finite number != 0.
    NonZero,
    |v| require(v != 0.0, || "must not be zero".to_owned())
);
number_type!(
    /// A colour component: >= 0 and small enough for f32.
    NonNegative,
    |v| {
        require(v >= 0.0, || format!("must not be negative (got {v})"))?;
        require(v <= MAX_COLOUR, || format!("must be at most {MAX_COLOUR:e} (got {v})"))
    }
);
number_type!(
    /// An index of refraction (or its real part): > 0 and small enough for f32.
    Ior,
    |v| {
        require(v > 0.0, || format!("must be positive (got {v})"))?;
        require(v <= MAX_COLOUR, || format!("must be at most {MAX_COLOUR:e} (got {v})"))
    }
);
number_type!(
    /// A Henyey–Greenstein asymmetry, in [−0.99, 0.99].
    Anisotropy,
    |v| require((-0.99..=0.99).contains(&v), || format!("must be between -0.99 and 0.99 (got {v})"))
);
number_type!(
    /// A number in [0, 1].
    UnitInterval,
    |v| require((0.0..=1.0).contains(&v), || format!("must be between 0 and 1 (got {v})"))
);
number_type!(
    /// A vertical field of view in degrees, in (0, 180).
    Fov,
    |v| require(v > 0.0 && v < 180.0, || format!("must be between 0 and 180 degrees, exclusive (got {v})"))
);
number_type!(
    /// A cone's half-angle in degrees, in (0, 90).
    HalfAngle,
    |v| require(v > 0.0 && v < 90.0, || format!("must be between 0 and 90 degrees, exclusive (got {v})"))
);
number_type!(
    /// Exposure in stops.
    Exposure,
    |v| require(v.abs() <= 100.0, || format!("must be between -100 and 100 stops (got {v})"))
);

/// An integer in `LO..=HI`.
#[derive(Clone, Copy, Debug)]
struct Int<const LO: i64, const HI: i64>(i64);

type Dimension = Int<1, MAX_IMAGE_SIZE>;
type Samples = Int<1, MAX_SPP>;
type Seed = Int<0, { u32::MAX as i64 }>;
type Depth = Int<1, MAX_DEPTH>;
type CausticRays = Int<0, MAX_CAUSTIC_RAYS>;
type LightSamples = Int<1, MAX_CAUSTIC_LIGHT_SAMPLES>;
type VolumeSamples = Int<0, MAX_VOLUME_SAMPLES>;
type Count = Int<1, MAX_SCATTER_COUNT>;
type Sheets = Int<1, 2>;

struct IntVisitor<const LO: i64, const HI: i64>;

impl<'de, const LO: i64, const HI: i64> Visitor<'de> for IntVisitor<LO, HI> {
    type Value = Int<LO, HI>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "an integer from {LO} to {HI}")
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        if (LO..=HI).contains(&v) {
            Ok(Int(v))
        } else {
            Err(E::custom(format!("must be an integer from {LO} to {HI} (got {v})")))
        }
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        self.visit_i64(i64::try_from(v).unwrap_or(i64::MAX))
    }
}

impl<'de, const LO: i64, const HI: i64> Deserialize<'de> for Int<LO, HI> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(IntVisitor::<LO, HI>)
    }
}

impl<const LO: i64, const HI: i64> Int<LO, HI> {
    fn get(self) -> i64 {
        self.0
    }
}

/// Reads exactly `N` numbers of type `T` from an array.
fn read_numbers<'de, T, A, const N: usize>(mut seq: A) -> Result<[f64; N], A::Error>
where
    T: Number + Deserialize<'de>,
    A: SeqAccess<'de>,
{
    let mut out = [0.0; N];
    let mut n = 0;
    while let Some(x) = seq.next_element::<T>()? {
        if n < N {
            out[n] = x.get();
        }
        n += 1;
    }
    if n != N {
        return Err(de::Error::custom(format!("must be an array of {N} numbers (got {n})")));
    }
    Ok(out)
}

/// An array of three numbers, each checked as a `T`.
#[derive(Clone, Copy, Debug)]
struct Triple<T>(DVec3, PhantomData<T>);

impl<T> Triple<T> {
    fn get(self) -> DVec3 {
        self.0
    }
}

struct TripleVisitor<T>(PhantomData<T>);

impl<'de, T: Number + Deserialize<'de>> Visitor<'de> for TripleVisitor<T> {
    type Value = Triple<T>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of 3 numbers")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        read_numbers::<T, A, 3>(seq).map(|v| Triple(DVec3::from_array(v), PhantomData))
    }
}

impl<'de, T: Number + Deserialize<'de>> Deserialize<'de> for Triple<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(TripleVisitor::<T>(PhantomData))
    }
}

/// A positive number (the same on every axis) or an array of three.
#[derive(Clone, Copy, Debug)]
struct PositiveVec(DVec3);

struct PositiveVecVisitor;

impl<'de> Visitor<'de> for PositiveVecVisitor {
    type Value = PositiveVec;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a positive number or an array of 3 positive numbers")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<PositiveVec, E> {
        Positive::parse(v).map(|p| PositiveVec(DVec3::splat(p.get()))).map_err(E::custom)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<PositiveVec, E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<PositiveVec, E> {
        self.visit_f64(v as f64)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<PositiveVec, A::Error> {
        read_numbers::<Positive, A, 3>(seq).map(|v| PositiveVec(DVec3::from_array(v)))
    }
}

impl<'de> Deserialize<'de> for PositiveVec {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(PositiveVecVisitor)
    }
}

/// The ten coefficients of a non-degenerate quadric, in the order of
/// [`Quadric::from_coefficients`].
#[derive(Clone, Copy, Debug)]
struct Coefficients(Quadric);

struct CoefficientsVisitor;

impl<'de> Visitor<'de> for CoefficientsVisitor {
    type Value = Coefficients;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of 10 numbers [xx, yy, zz, xy, yz, xz, x, y, z, k]")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Coefficients, A::Error> {
        let k = read_numbers::<Finite, A, 10>(seq)?;
        let q = Quadric::from_coefficients(k);
        if q.is_degenerate() {
            return Err(de::Error::custom(
                "the quadric is degenerate: its quadratic and linear coefficients (the first 9) are all zero, \
                 so it has no surface",
            ));
        }
        Ok(Coefficients(q))
    }
}

impl<'de> Deserialize<'de> for Coefficients {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(CoefficientsVisitor)
    }
}

/// A power of two in `LO..=HI`: the side of a generated texture.
#[derive(Clone, Copy, Debug)]
struct PowerOfTwo<const LO: u32, const HI: u32>(u32);

/// The side of a generated material map.
type TextureSize = PowerOfTwo<1, MAX_TEXTURE_SIZE>;
/// The width of the generated sky.
type SkyWidth = PowerOfTwo<2, MAX_SKY_WIDTH>;
/// The height of the generated sky.
type SkyHeight = PowerOfTwo<1, { MAX_SKY_WIDTH / 2 }>;

struct PowerOfTwoVisitor<const LO: u32, const HI: u32>;

impl<'de, const LO: u32, const HI: u32> Visitor<'de> for PowerOfTwoVisitor<LO, HI> {
    type Value = PowerOfTwo<LO, HI>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        write!(f, "a power of two from {LO} to {HI}")
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<Self::Value, E> {
        match u32::try_from(v) {
            Ok(n) if n.is_power_of_two() && (LO..=HI).contains(&n) => Ok(PowerOfTwo(n)),
            _ => {
                Err(E::custom(format!("must be a power of two from {LO} to {HI}, such as 256, 512 or 1024 (got {v})")))
            }
        }
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<Self::Value, E> {
        self.visit_i64(i64::try_from(v).unwrap_or(i64::MAX))
    }
}

impl<'de, const LO: u32, const HI: u32> Deserialize<'de> for PowerOfTwo<LO, HI> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(PowerOfTwoVisitor::<LO, HI>)
    }
}

/// An array of two numbers, each checked as a `T`.
#[derive(Clone, Copy, Debug)]
struct Pair<T>(DVec2, PhantomData<T>);

struct PairVisitor<T>(PhantomData<T>);

impl<'de, T: Number + Deserialize<'de>> Visitor<'de> for PairVisitor<T> {
    type Value = Pair<T>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of 2 numbers")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<Self::Value, A::Error> {
        read_numbers::<T, A, 2>(seq).map(|v| Pair(DVec2::from_array(v), PhantomData))
    }
}

impl<'de, T: Number + Deserialize<'de>> Deserialize<'de> for Pair<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(PairVisitor::<T>(PhantomData))
    }
}

/// A colour with components in [0, 1], or one number in [0, 1] for a grey.
#[derive(Clone, Copy, Debug)]
struct UnitColour(DVec3);

struct UnitColourVisitor;

impl<'de> Visitor<'de> for UnitColourVisitor {
    type Value = UnitColour;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("a number in [0, 1] or an array of 3 numbers in [0, 1]")
    }

    fn visit_f64<E: de::Error>(self, v: f64) -> Result<UnitColour, E> {
        UnitInterval::parse(v).map(|p| UnitColour(DVec3::splat(p.get()))).map_err(E::custom)
    }

    fn visit_i64<E: de::Error>(self, v: i64) -> Result<UnitColour, E> {
        self.visit_f64(v as f64)
    }

    fn visit_u64<E: de::Error>(self, v: u64) -> Result<UnitColour, E> {
        self.visit_f64(v as f64)
    }

    fn visit_seq<A: SeqAccess<'de>>(self, seq: A) -> Result<UnitColour, A::Error> {
        read_numbers::<UnitInterval, A, 3>(seq).map(|v| UnitColour(DVec3::from_array(v)))
    }
}

impl<'de> Deserialize<'de> for UnitColour {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(UnitColourVisitor)
    }
}

/// Exactly two [`UnitColour`]s: the colours of a checkerboard.
#[derive(Clone, Copy, Debug)]
struct ColourPair([DVec3; 2]);

struct ColourPairVisitor;

impl<'de> Visitor<'de> for ColourPairVisitor {
    type Value = ColourPair;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str("an array of 2 colours, such as [[0.9, 0.9, 0.9], [0.1, 0.1, 0.1]]")
    }

    fn visit_seq<A: SeqAccess<'de>>(self, mut seq: A) -> Result<ColourPair, A::Error> {
        let mut out = [DVec3::ZERO; 2];
        let mut n = 0;
        while let Some(c) = seq.next_element::<UnitColour>()? {
            if n < 2 {
                out[n] = c.0;
            }
            n += 1;
        }
        if n != 2 {
            return Err(de::Error::custom(format!("must be an array of 2 colours (got {n})")));
        }
        Ok(ColourPair(out))
    }
}

impl<'de> Deserialize<'de> for ColourPair {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(ColourPairVisitor)
    }
}

/// The table form of a map, as [`RawMap`] reads it.
trait MapTable {
    /// What the map accepts, for type errors.
    const EXPECTING: &'static str;
}

impl MapTable for RawMapTable {
    const EXPECTING: &'static str =
        "a file path such as \"textures/wood.png\" or a table such as { file = \"wood.png\" }";
}

impl MapTable for RawEnvironmentMapTable {
    const EXPECTING: &'static str =
        "a file path such as \"sky.exr\" or a table such as { sky = { width = 512, height = 256 } }";
}

/// A texture map: a file path, or a table `T` naming a file or a generator.
enum RawMap<T = RawMapTable> {
    Path(String),
    Table(Box<T>),
}

struct RawMapVisitor<T>(PhantomData<T>);

impl<'de, T: MapTable + Deserialize<'de>> Visitor<'de> for RawMapVisitor<T> {
    type Value = RawMap<T>;

    fn expecting(&self, f: &mut fmt::Formatter) -> fmt::Result {
        f.write_str(T::EXPECTING)
    }

    fn visit_str<E: de::Error>(self, v: &str) -> Result<RawMap<T>, E> {
        Ok(RawMap::Path(v.to_owned()))
    }

    fn visit_map<A: MapAccess<'de>>(self, map: A) -> Result<RawMap<T>, A::Error> {
        T::deserialize(de::value::MapAccessDeserializer::new(map)).map(|t| RawMap::Table(Box::new(t)))
    }
}

impl<'de, T: MapTable + Deserialize<'de>> Deserialize<'de> for RawMap<T> {
    fn deserialize<D: Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(RawMapVisitor::<T>(PhantomData))
    }
}

// ---------------------------------------------------------------------------
// The raw tree
// ---------------------------------------------------------------------------

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a scene table")]
struct RawScene {
    background: Option<Spanned<Triple<NonNegative>>>,
    environment: Option<Spanned<RawEnvironment>>,
    fog: Option<Spanned<RawMedium>>,
    caustics: Option<RawCaustics>,
    volume: Option<RawVolume>,
    image: Option<RawImage>,
    camera: Spanned<RawCamera>,
    #[serde(default)]
    materials: Vec<Spanned<RawMaterial>>,
    #[serde(default)]
    objects: Vec<Spanned<RawObject>>,
    #[serde(default)]
    lights: Vec<Spanned<RawLight>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an [image] table")]
struct RawImage {
    width: Option<Dimension>,
    height: Option<Dimension>,
    spp: Option<Samples>,
    seed: Option<Seed>,
    exposure: Option<Exposure>,
    max_depth: Option<Depth>,
    preset: Option<Spanned<String>>,
    filter: Option<Spanned<String>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [volume] table")]
struct RawVolume {
    samples: Option<VolumeSamples>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [caustics] table")]
struct RawCaustics {
    rays: Option<CausticRays>,
    light_samples: Option<LightSamples>,
}

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a medium table such as { density = 0.2, albedo = [0.9, 0.9, 0.9], anisotropy = 0.3 }"
)]
struct RawMedium {
    density: NonNegative,
    albedo: Option<Triple<UnitInterval>>,
    anisotropy: Option<Anisotropy>,
}

impl RawMedium {
    /// The medium; the albedo defaults to 1 (no absorption), the anisotropy to 0.
    fn build(&self) -> Medium {
        Medium {
            density: self.density.get() as f32,
            albedo: self.albedo.map_or(Vec3::ONE, |a| a.get().as_vec3()),
            anisotropy: self.anisotropy.map_or(0.0, |g| g.get() as f32),
        }
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an [environment] table with a map")]
struct RawEnvironment {
    map: Spanned<RawMap<RawEnvironmentMapTable>>,
    scale: Option<NonNegative>,
}

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "an environment map table such as { file = \"sky.exr\" } or { sky = { width = 512, height = 256 } }"
)]
struct RawEnvironmentMapTable {
    file: Option<Spanned<String>>,
    sky: Option<Spanned<RawSky>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { width = 512, height = 256 }")]
struct RawSky {
    width: SkyWidth,
    height: SkyHeight,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [camera] table with position and look_at")]
struct RawCamera {
    position: Triple<Finite>,
    look_at: Spanned<Triple<Finite>>,
    up: Option<Spanned<Triple<Finite>>>,
    fov: Option<Fov>,
    fps: Option<Positive>,
    keyframes: Option<Vec<Spanned<RawKeyframe>>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a [[camera.keyframes]] table with time, position and look_at")]
struct RawKeyframe {
    time: Finite,
    position: Triple<Finite>,
    look_at: Spanned<Triple<Finite>>,
    up: Option<Spanned<Triple<Finite>>>,
    fov: Option<Fov>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Debug)]
#[serde(rename_all = "lowercase")]
enum MaterialType {
    Diffuse,
    Conductor,
    Dielectric,
    Mirror,
}

impl MaterialType {
    fn name(self) -> &'static str {
        match self {
            Self::Diffuse => "diffuse",
            Self::Conductor => "conductor",
            Self::Dielectric => "dielectric",
            Self::Mirror => "mirror",
        }
    }
}

/// The keys each material type accepts, in the order messages list them.
const MATERIAL_KEYS: [(&str, &[&str]); 4] = [
    ("diffuse", &["name", "type", "albedo", "emission", "albedo_map", "normal_map", "displacement_map"]),
    (
        "conductor",
        &[
            "name",
            "type",
            "roughness",
            "color",
            "eta",
            "k",
            "metal",
            "emission",
            "roughness_map",
            "normal_map",
            "displacement_map",
        ],
    ),
    (
        "dielectric",
        &["name", "type", "ior", "roughness", "emission", "roughness_map", "normal_map", "displacement_map", "medium"],
    ),
    ("mirror", &["name", "type", "albedo", "emission", "albedo_map", "normal_map", "displacement_map"]),
];

/// A named conductor whose complex index of refraction is built in.
#[derive(Deserialize, Clone, Copy, PartialEq, Debug)]
#[serde(rename_all = "lowercase")]
enum Metal {
    Gold,
    Silver,
    Copper,
    #[serde(alias = "aluminum")]
    Aluminium,
}

impl Metal {
    /// The complex index of refraction η + iκ at 650, 550 and 450 nm (red,
    /// green, blue), linearly interpolated between neighbouring rows of the
    /// measured tables as published by refractiveindex.info (CC0):
    ///
    /// * gold, silver, copper: P. B. Johnson and R. W. Christy, "Optical
    ///   constants of the noble metals", Phys. Rev. B 6, 4370 (1972);
    /// * aluminium: A. D. Rakić, "Algorithm for the determination of intrinsic
    ///   optical constants of metal films: application to aluminum", Appl.
    ///   Opt. 34, 4755 (1995).
    ///
    /// These are physical constants; their normal-incidence reflectances
    /// ((η−1)² + κ²) / ((η+1)² + κ²) are about gold (0.96, 0.79, 0.41),
    /// silver (0.99, 0.98, 0.98), copper (0.94, 0.62, 0.54) and aluminium
    /// (0.91, 0.92, 0.92).
    fn ior(self) -> (Vec3, Vec3) {
        let (eta, k) = match self {
            Self::Gold => ([0.156, 0.424, 1.383], [3.602, 2.472, 1.915]),
            Self::Silver => ([0.052, 0.060, 0.040], [4.409, 3.597, 2.648]),
            Self::Copper => ([0.238, 1.007, 1.240], [3.626, 2.582, 2.393]),
            Self::Aluminium => ([1.558, 1.015, 0.633], [7.712, 6.627, 5.454]),
        };
        (Vec3::from_array(eta), Vec3::from_array(k))
    }
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a material table with a name")]
struct RawMaterial {
    name: Spanned<String>,
    #[serde(rename = "type")]
    kind: Option<Spanned<MaterialType>>,
    albedo: Option<Spanned<Triple<UnitInterval>>>,
    emission: Option<Spanned<Triple<NonNegative>>>,
    roughness: Option<Spanned<UnitInterval>>,
    color: Option<Spanned<Triple<UnitInterval>>>,
    eta: Option<Spanned<Triple<Ior>>>,
    k: Option<Spanned<Triple<NonNegative>>>,
    metal: Option<Spanned<Metal>>,
    ior: Option<Spanned<Ior>>,
    albedo_map: Option<Spanned<RawMap>>,
    normal_map: Option<Spanned<RawMap>>,
    roughness_map: Option<Spanned<RawMap>>,
    displacement_map: Option<Spanned<RawMap>>,
    medium: Option<Spanned<RawMedium>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a texture map table such as { file = \"wood.png\" }")]
struct RawMapTable {
    file: Option<Spanned<String>>,
    checker: Option<Spanned<RawChecker>>,
    bumps: Option<Spanned<RawBumps>>,
    scale: Option<Spanned<Positive>>,
}

#[derive(Deserialize)]
#[serde(
    deny_unknown_fields,
    expecting = "a table such as { size = 1024, cells = 64, colors = [[0.9, 0.9, 0.9], [0.1, 0.1, 0.1]] }"
)]
struct RawChecker {
    size: TextureSize,
    cells: Spanned<Int<1, { MAX_TEXTURE_SIZE as i64 }>>,
    colors: ColourPair,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { size = 512, count = 200, seed = 3, strength = 4 }")]
struct RawBumps {
    size: TextureSize,
    count: Int<1, MAX_TEXTURE_BUMPS>,
    seed: Option<Seed>,
    strength: Option<Spanned<Positive>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an object table")]
struct RawObject {
    name: Option<String>,
    material: Option<Spanned<String>>,
    sphere: Option<Spanned<RawSphere>>,
    ellipsoid: Option<Spanned<RawEllipsoid>>,
    plane: Option<Spanned<RawPlane>>,
    cylinder: Option<Spanned<RawCylinder>>,
    cone: Option<Spanned<RawCone>>,
    paraboloid: Option<Spanned<RawParaboloid>>,
    hyperboloid: Option<Spanned<RawHyperboloid>>,
    quadric: Option<Spanned<Coefficients>>,
    clip: Option<Spanned<RawClip>>,
    translate: Option<Triple<Finite>>,
    rotate: Option<Triple<Finite>>,
    scale: Option<PositiveVec>,
    #[serde(default)]
    perturbations: Vec<Spanned<RawPerturbation>>,
    #[serde(default)]
    scatter: Vec<Spanned<RawScatter>>,
    uv: Option<Spanned<RawUv>>,
}

#[derive(Deserialize, Clone, Copy, PartialEq, Debug)]
#[serde(rename_all = "lowercase")]
enum MappingName {
    Planar,
    Spherical,
    Cylindrical,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { mapping = \"spherical\", scale = [8, 4] }")]
struct RawUv {
    mapping: Option<MappingName>,
    u_axis: Option<Spanned<Triple<Finite>>>,
    v_axis: Option<Spanned<Triple<Finite>>>,
    scale: Option<Pair<NonZero>>,
    offset: Option<Pair<Finite>>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { radius = 1 }")]
struct RawSphere {
    radius: Positive,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { radii = [1, 0.5, 2] }")]
struct RawEllipsoid {
    radii: Triple<Positive>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "an empty table {}")]
struct RawPlane {}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { radius = 0.5 }")]
struct RawCylinder {
    radius: Positive,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { half_angle = 30 }")]
struct RawCone {
    half_angle: HalfAngle,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { curvature = 1 }")]
struct RawParaboloid {
    curvature: NonZero,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { radius = 0.5, slope = 1, sheets = 1 }")]
struct RawHyperboloid {
    radius: Positive,
    slope: Positive,
    sheets: Option<Sheets>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { min = [-1, -1, -1], max = [1, 1, 1] }")]
struct RawClip {
    min: Triple<Finite>,
    max: Triple<Finite>,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a perturbation table with `f` and one of `bump` or `quadric`")]
struct RawPerturbation {
    bump: Option<RawBump>,
    quadric: Option<Spanned<Coefficients>>,
    f: Finite,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a table such as { centre = [0, 1, 0], radius = 0.2 }")]
struct RawBump {
    #[serde(alias = "center")]
    centre: Triple<Finite>,
    radius: PositiveVec,
}

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a scatter table with count, radius and f")]
struct RawScatter {
    count: Count,
    on_radii: Option<Triple<Positive>>,
    #[serde(alias = "center")]
    centre: Option<Triple<Finite>>,
    radius: PositiveVec,
    f: Finite,
    alternate: Option<bool>,
    seed: Option<Seed>,
    jitter: Option<UnitInterval>,
}

#[derive(Deserialize, Clone, Copy, PartialEq)]
#[serde(rename_all = "lowercase")]
enum LightKind {
    Point,
    Sphere,
    Rect,
    Directional,
}

impl LightKind {
    fn name(self) -> &'static str {
        match self {
            Self::Point => "point",
            Self::Sphere => "sphere",
            Self::Rect => "rect",
            Self::Directional => "directional",
        }
    }
}

/// The keys each light type accepts, in the order messages list them.
const LIGHT_KEYS: [(&str, &[&str]); 4] = [
    ("point", &["type", "position", "intensity"]),
    ("sphere", &["type", "position", "radius", "radiance"]),
    ("rect", &["type", "corner", "edge_u", "edge_v", "radiance"]),
    ("directional", &["type", "direction", "irradiance"]),
];

#[derive(Deserialize)]
#[serde(deny_unknown_fields, expecting = "a light table with a type")]
struct RawLight {
    #[serde(rename = "type")]
    kind: LightKind,
    position: Option<Spanned<Triple<Finite>>>,
    intensity: Option<Spanned<Triple<NonNegative>>>,
    radius: Option<Spanned<Positive>>,
    radiance: Option<Spanned<Triple<NonNegative>>>,
    corner: Option<Spanned<Triple<Finite>>>,
    edge_u: Option<Spanned<Triple<Finite>>>,
    edge_v: Option<Spanned<Triple<Finite>>>,
    direction: Option<Spanned<Triple<Finite>>>,
    irradiance: Option<Spanned<Triple<NonNegative>>>,
}

// ---------------------------------------------------------------------------
// Building the scene
// ---------------------------------------------------------------------------

fn build_scene(src: &Source, raw: RawScene) -> Result<Scene, SceneError> {
    let image = raw.image.as_ref();
    let preset = match image.and_then(|i| i.preset.as_ref()) {
        Some(p) => Some(p.get_ref().parse::<Preset>().map_err(|e| src.error(Some(p.span()), "image.preset", e))?),
        None => None,
    };
    // A preset sets every quality setting; the file's own keys override it.
    let quality = preset.map_or_else(Quality::default, Preset::quality);
    let filter = match image.and_then(|i| i.filter.as_ref()) {
        Some(f) => f.get_ref().parse::<FilterMode>().map_err(|e| src.error(Some(f.span()), "image.filter", e))?,
        None => quality.filter,
    };
    let image = ImageSettings {
        width: image.and_then(|i| i.width).map_or(640, |v| v.get() as u32),
        height: image.and_then(|i| i.height).map_or(480, |v| v.get() as u32),
        spp: image.and_then(|i| i.spp).map_or(quality.spp, |v| v.get() as u32),
        seed: image.and_then(|i| i.seed).map_or(0, |v| v.get() as u32),
        exposure: image.and_then(|i| i.exposure).map_or(0.0, |v| v.get() as f32),
        max_depth: image.and_then(|i| i.max_depth).map_or(quality.max_depth, |v| v.get() as u32),
        filter,
        preset,
    };
    let camera = build_camera(src, &raw.camera)?;
    if let (Some(background), Some(environment)) = (&raw.background, &raw.environment) {
        // Point at whichever comes second in the file.
        let (b, e) = (background.span(), environment.span());
        let ((field, span), (other, first)) = if e.start > b.start {
            (("environment", e), ("background", b))
        } else {
            (("background", b), ("[environment]", e))
        };
        let line = src.line_of(first.start);
        return Err(src.error(
            Some(span),
            field,
            format!(
                "give either background or [environment], not both: the environment map replaces the uniform \
                 background as the light arriving from infinity ({other} is at line {line}); remove one"
            ),
        ));
    }
    let background = raw.background.as_ref().map_or(Vec3::ZERO, |b| b.get_ref().get().as_vec3());

    // Names first, then objects and lights, and only then the materials
    // with their texture maps: an error in an object is reported without
    // first generating or loading maps that can take many seconds.
    let mut names: Vec<&String> = Vec::with_capacity(raw.materials.len());
    let mut material_lines = Vec::with_capacity(raw.materials.len());
    for (i, raw_material) in raw.materials.iter().enumerate() {
        let m = raw_material.get_ref();
        let name = m.name.get_ref();
        if name.is_empty() {
            return Err(src.error(Some(m.name.span()), format!("materials[{i}].name"), "must not be empty"));
        }
        if let Some(first) = names.iter().position(|&n| n == name) {
            let line: usize = material_lines[first];
            return Err(src.error(
                Some(m.name.span()),
                format!("materials[{i}].name"),
                format!("duplicate material name {name:?} (first defined at line {line} as materials[{first}])"),
            ));
        }
        names.push(name);
        material_lines.push(src.line_of(raw_material.span().start));
    }
    let user_materials = names.len();

    let mut needs_default_material = false;
    let mut objects = Vec::with_capacity(raw.objects.len());
    for (i, o) in raw.objects.iter().enumerate() {
        let material = match &o.get_ref().material {
            Some(name) => match names.iter().position(|&n| n == name.get_ref()) {
                Some(k) => k,
                None => {
                    let known: Vec<String> = names.iter().map(|n| format!("{n:?}")).collect();
                    let known = if known.is_empty() {
                        "no [[materials]] are defined".to_owned()
                    } else {
                        format!("defined: {}", known.join(", "))
                    };
                    return Err(src.error(
                        Some(name.span()),
                        format!("objects[{i}].material"),
                        format!("unknown material {:?} ({known})", name.get_ref()),
                    ));
                }
            },
            None => {
                needs_default_material = true;
                user_materials
            }
        };
        objects.push(build_object(src, i, o, material)?);
    }

    let lights = raw.lights.iter().enumerate().map(|(i, l)| build_light(src, i, l)).collect::<Result<Vec<_>, _>>()?;

    let mut textures = TextureCache::default();
    let mut materials: Vec<Material> = Vec::with_capacity(user_materials + 1);
    for (i, raw_material) in raw.materials.iter().enumerate() {
        materials.push(build_material(src, i, raw_material, &mut textures)?);
    }
    if needs_default_material {
        materials.push(Material::diffuse(DEFAULT_MATERIAL_NAME, Vec3::splat(0.8)));
    }

    let environment = match &raw.environment {
        Some(e) => Some(build_environment(src, e.get_ref(), &mut textures)?),
        None => None,
    };

    let fog = raw.fog.as_ref().map(|f| f.get_ref().build());
    let caustics = raw.caustics.as_ref();
    let caustics = CausticSettings {
        rays: caustics.and_then(|c| c.rays).map_or(quality.caustic_rays, |v| v.get() as u32),
        light_samples: caustics.and_then(|c| c.light_samples).map_or(quality.caustic_light_samples, |v| v.get() as u32),
    };
    let volume = VolumeSettings {
        samples: raw.volume.as_ref().and_then(|v| v.samples).map_or(quality.volume_samples, |v| v.get() as u32),
    };
    Ok(Scene {
        volume,
        image,
        camera,
        background,
        materials,
        objects,
        lights,
        environment,
        textures: textures.images,
        fog,
        caustics,
    })
}

fn build_camera(src: &Source, raw: &Spanned<RawCamera>) -> Result<Camera, SceneError> {
    let c = raw.get_ref();
    let (position, look_at, up) = check_view(src, "camera", raw.span(), (c.position.get(), &c.look_at, c.up.as_ref()))?;
    let fov = c.fov.map_or(40.0, |f| f.get());
    let mut keyframes: Vec<CameraKeyframe> = Vec::new();
    for (i, k) in c.keyframes.iter().flatten().enumerate() {
        let name = format!("camera.keyframes[{i}]");
        let r = k.get_ref();
        let (position, look_at, up) = check_view(src, &name, k.span(), (r.position.get(), &r.look_at, r.up.as_ref()))?;
        let time = r.time.get();
        if keyframes.last().is_some_and(|p| p.time >= time) {
            return Err(src.error(Some(k.span()), format!("{name}.time"), "must be later than the keyframe before"));
        }
        // A keyframe's fov defaults to the camera's.
        keyframes.push(CameraKeyframe { time, position, look_at, up, vfov_degrees: r.fov.map_or(fov, |f| f.get()) });
    }
    Ok(Camera { position, look_at, up, vfov_degrees: fov, keyframes, fps: c.fps.map_or(24.0, |f| f.get()) })
}

/// A view as written: position, look_at and up (optional).
type RawView<'a> = (DVec3, &'a Spanned<Triple<Finite>>, Option<&'a Spanned<Triple<Finite>>>);

/// Checks a view (position, look_at, up) of the camera or of a keyframe
/// (`name`: where, in messages) and returns it with the default up.
fn check_view(
    src: &Source,
    name: &str,
    span: std::ops::Range<usize>,
    (position, look_at, up): RawView<'_>,
) -> Result<(DVec3, DVec3, DVec3), SceneError> {
    let c_look_at = look_at;
    let look_at = c_look_at.get_ref().get();
    let up_value = up.map_or(DVec3::Y, |u| u.get_ref().get());
    let view = look_at - position;
    let scale = position.abs().max(look_at.abs()).max_element().max(1.0);
    if view.length() <= 1e-9 * scale {
        return Err(src.error(
            Some(c_look_at.span()),
            format!("{name}.look_at"),
            format!("must differ from {name}.position (the view direction is look_at - position)"),
        ));
    }
    let default_note = format!(" (the default up is [0, 1, 0]; set {name}.up)");
    let (up_span, default_note) = match up {
        Some(u) => (u.span(), ""),
        None => (span, default_note.as_str()),
    };
    let up = up_value;
    if up.length() == 0.0 {
        return Err(src.error(Some(up_span), format!("{name}.up"), "must not be zero"));
    }
    let sin = view.normalize().cross(up.normalize()).length();
    if sin < 1e-6 {
        return Err(src.error(
            Some(up_span),
            format!("{name}.up"),
            format!("must not be parallel to the view direction look_at - position{default_note}"),
        ));
    }
    Ok((position, look_at, up))
}

/// The shape keys of an object, in the order they are listed in messages.
const SHAPE_KEYS: [&str; 8] =
    ["sphere", "ellipsoid", "plane", "cylinder", "cone", "paraboloid", "hyperboloid", "quadric"];

/// The base quadric of an object's one shape key, with that key and the span
/// of its value.
fn base_shape(
    src: &Source,
    i: usize,
    raw: &Spanned<RawObject>,
) -> Result<(Quadric, &'static str, Range<usize>), SceneError> {
    let o = raw.get_ref();
    let present: Vec<(&'static str, Range<usize>)> = [
        o.sphere.as_ref().map(Spanned::span),
        o.ellipsoid.as_ref().map(Spanned::span),
        o.plane.as_ref().map(Spanned::span),
        o.cylinder.as_ref().map(Spanned::span),
        o.cone.as_ref().map(Spanned::span),
        o.paraboloid.as_ref().map(Spanned::span),
        o.hyperboloid.as_ref().map(Spanned::span),
        o.quadric.as_ref().map(Spanned::span),
    ]
    .into_iter()
    .zip(SHAPE_KEYS)
    .filter_map(|(s, k)| s.map(|s| (k, s)))
    .collect();
    let (key, span) = match present.as_slice() {
        [one] => one.clone(),
        [] => {
            return Err(src.error(
                Some(raw.span()),
                format!("objects[{i}]"),
                format!("the object needs exactly one shape key ({}); found none", SHAPE_KEYS.join(", ")),
            ))
        }
        [_, second, ..] => {
            let keys: Vec<&str> = present.iter().map(|(k, _)| *k).collect();
            return Err(src.error(
                Some(second.1.clone()),
                format!("objects[{i}].{}", second.0),
                format!("the object needs exactly one shape key; found {}: {}", keys.len(), keys.join(", ")),
            ));
        }
    };
    let q = |k: [f64; 10]| Quadric::from_coefficients(k);
    let base = if let Some(s) = &o.sphere {
        Quadric::ellipsoid(DVec3::ZERO, DVec3::splat(s.get_ref().radius.get()))
    } else if let Some(e) = &o.ellipsoid {
        Quadric::ellipsoid(DVec3::ZERO, e.get_ref().radii.get())
    } else if o.plane.is_some() {
        q([0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, -1.0, 0.0, 0.0])
    } else if let Some(c) = &o.cylinder {
        let w = 1.0 / c.get_ref().radius.get().powi(2);
        q([-w, 0.0, -w, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 1.0])
    } else if let Some(c) = &o.cone {
        let t = c.get_ref().half_angle.get().to_radians().tan().powi(2);
        q([-1.0, t, -1.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0])
    } else if let Some(p) = &o.paraboloid {
        let k = p.get_ref().curvature.get();
        q([-k, 0.0, -k, 0.0, 0.0, 0.0, 0.0, 1.0, 0.0, 0.0])
    } else if let Some(h) = &o.hyperboloid {
        let h = h.get_ref();
        let w = 1.0 / h.radius.get().powi(2);
        let s = h.slope.get().powi(2) * w;
        let k = if h.sheets.map_or(1, Int::get) == 1 { 1.0 } else { -1.0 };
        q([-w, s, -w, 0.0, 0.0, 0.0, 0.0, 0.0, 0.0, k])
    } else if let Some(c) = &o.quadric {
        c.get_ref().0
    } else {
        unreachable!("exactly one shape key is present")
    };
    Ok((base, key, span))
}

fn build_object(src: &Source, i: usize, raw: &Spanned<RawObject>, material: usize) -> Result<SceneObject, SceneError> {
    let o = raw.get_ref();
    let (base, shape_key, shape_span) = base_shape(src, i, raw)?;

    let clip = match &o.clip {
        Some(c) => {
            let (min, max) = (c.get_ref().min.get(), c.get_ref().max.get());
            if let Some(axis) = (0..3).find(|&k| min[k] >= max[k]) {
                let name = ["x", "y", "z"][axis];
                return Err(src.error(
                    Some(c.span()),
                    format!("objects[{i}].clip"),
                    format!(
                        "clip.min must be less than clip.max on every axis ({name}: min {} >= max {})",
                        min[axis], max[axis]
                    ),
                ));
            }
            Some(Aabb::new(min, max))
        }
        None => None,
    };

    let mut perturbations = Vec::new();
    for (j, p) in o.perturbations.iter().enumerate() {
        let r = p.get_ref();
        let quadric = match (&r.bump, &r.quadric) {
            (Some(b), None) => Quadric::ellipsoid(b.centre.get(), b.radius.0),
            (None, Some(q)) => q.get_ref().0,
            (b, q) => {
                let found = if b.is_some() && q.is_some() { "found both" } else { "found neither" };
                return Err(src.error(
                    Some(p.span()),
                    format!("objects[{i}].perturbations[{j}]"),
                    format!("a perturbation needs exactly one of `bump` and `quadric`; {found}"),
                ));
            }
        };
        perturbations.push(Perturbation { quadric, form_factor: r.f.get() });
    }
    for (j, s) in o.scatter.iter().enumerate() {
        let r = s.get_ref();
        let on_radii = match (&r.on_radii, &o.sphere, &o.ellipsoid) {
            (Some(v), _, _) => v.get(),
            (None, Some(sphere), _) => DVec3::splat(sphere.get_ref().radius.get()),
            (None, None, Some(e)) => e.get_ref().radii.get(),
            (None, None, None) => {
                return Err(src.error(
                    Some(s.span()),
                    format!("objects[{i}].scatter[{j}].on_radii"),
                    "the required key `on_radii` is missing (it defaults to the radii only for spheres and ellipsoids)",
                ));
            }
        };
        perturbations.extend(scatter(ScatterParams {
            count: r.count.get() as usize,
            centre: r.centre.map_or(DVec3::ZERO, Triple::get),
            on_radii,
            radius: r.radius.0,
            form_factor: r.f.get(),
            alternate: r.alternate.unwrap_or(false),
            seed: r.seed.map_or(0, |v| v.get() as u32),
            jitter: r.jitter.map_or(0.0, |v| v.get()),
        }));
    }

    let shape = FunctionalObject { base, perturbations, clip };
    if let Err(e) = shape.bounds() {
        return Err(geometry_error(src, i, raw, shape_key, shape_span, &shape, e));
    }

    let translate = o.translate.map_or(DVec3::ZERO, Triple::get);
    let rotate = o.rotate.map_or(DVec3::ZERO, Triple::get);
    let scale = o.scale.map_or(DVec3::ONE, |s| s.0);
    let rotation =
        DQuat::from_euler(EulerRot::XYZ, rotate.x.to_radians(), rotate.y.to_radians(), rotate.z.to_radians());
    let transform = DAffine3::from_scale_rotation_translation(scale, rotation, translate);

    Ok(SceneObject {
        name: o.name.clone().unwrap_or_else(|| format!("objects[{i}]")),
        shape,
        transform,
        material,
        uv: o.uv.as_ref().map_or(Ok(UvSettings::default()), |uv| build_uv(src, i, uv))?,
    })
}

/// The texture coordinates of objects[i].
fn build_uv(src: &Source, i: usize, raw: &Spanned<RawUv>) -> Result<UvSettings, SceneError> {
    let uv = raw.get_ref();
    let table = format!("objects[{i}].uv");
    let name = uv.mapping.unwrap_or(MappingName::Spherical);
    let axes = [("u_axis", &uv.u_axis), ("v_axis", &uv.v_axis)];
    let mapping = if name == MappingName::Planar {
        let mut vectors: [(DVec3, Range<usize>); 2] = Default::default();
        for ((key, axis), out) in axes.into_iter().zip(&mut vectors) {
            let Some(axis) = axis else {
                return Err(src.error(
                    Some(raw.span()),
                    format!("{table}.{key}"),
                    format!(
                        "the required key `{key}` of a planar mapping is missing; give both axes, e.g. \
                         uv = {{ mapping = \"planar\", u_axis = [1, 0, 0], v_axis = [0, 0, 1] }}"
                    ),
                ));
            };
            let v = axis.get_ref().get();
            if v == DVec3::ZERO {
                return Err(src.error(Some(axis.span()), format!("{table}.{key}"), "must not be zero"));
            }
            *out = (v, axis.span());
        }
        let [(u_axis, _), (v_axis, v_span)] = vectors;
        if u_axis.cross(v_axis).length() <= 1e-6 * u_axis.length() * v_axis.length() {
            return Err(src.error(
                Some(v_span),
                format!("{table}.v_axis"),
                "u_axis and v_axis are parallel, so the planar mapping is degenerate (u and v would vary \
                 together); give two axes that span a plane",
            ));
        }
        UvMapping::Planar { u_axis, v_axis }
    } else {
        if let Some((key, axis)) = axes.into_iter().find_map(|(k, a)| a.as_ref().map(|a| (k, a))) {
            let mapping = if name == MappingName::Spherical { "spherical" } else { "cylindrical" };
            let default_note = if uv.mapping.is_none() { " (the default mapping)" } else { "" };
            return Err(src.error(
                Some(axis.span()),
                format!("{table}.{key}"),
                format!(
                    "`{key}` does not apply to the {mapping} mapping{default_note}; only mapping = \"planar\" \
                     takes u_axis and v_axis"
                ),
            ));
        }
        if name == MappingName::Spherical {
            UvMapping::Spherical
        } else {
            UvMapping::Cylindrical
        }
    };
    Ok(UvSettings {
        mapping,
        scale: uv.scale.map_or(DVec2::ONE, |s| s.0),
        offset: uv.offset.map_or(DVec2::ZERO, |o| o.0),
    })
}

fn geometry_error(
    src: &Source,
    i: usize,
    raw: &Spanned<RawObject>,
    shape_key: &str,
    shape_span: Range<usize>,
    shape: &FunctionalObject,
    e: GeometryError,
) -> SceneError {
    let o = raw.get_ref();
    match e {
        GeometryError::Unbounded(_) if shape.base.support_bounds().is_none() => src.error(
            Some(shape_span),
            format!("objects[{i}].{shape_key}"),
            format!(
                "the {shape_key} surface is unbounded; give the object a clip box, \
                 e.g. clip = {{ min = [-1, -1, -1], max = [1, 1, 1] }}"
            ),
        ),
        GeometryError::Unbounded(_) => {
            let j = o
                .perturbations
                .iter()
                .position(|p| {
                    let r = p.get_ref();
                    r.f.get() > 0.0 && r.quadric.as_ref().is_some_and(|q| q.get_ref().0.support_bounds().is_none())
                })
                .unwrap_or(0);
            let span = o.perturbations.get(j).map_or(raw.span(), Spanned::span);
            src.error(
                Some(span),
                format!("objects[{i}].perturbations[{j}]"),
                "a perturbation with a positive form factor and an unbounded support (its quadric is >= 0 \
                 arbitrarily far away) makes the surface unbounded; give the object a clip box",
            )
        }
        GeometryError::Empty(_) => match &o.clip {
            Some(c) => {
                src.error(Some(c.span()), format!("objects[{i}].clip"), "the surface has no point inside the clip box")
            }
            None => src.error(
                Some(shape_span),
                format!("objects[{i}].{shape_key}"),
                "the surface is empty: the quadric is negative everywhere",
            ),
        },
        e => src.error(Some(raw.span()), format!("objects[{i}]"), e.to_string()),
    }
}

/// The span of an optional spanned value.
fn span_of<T>(value: &Option<Spanned<T>>) -> Option<Range<usize>> {
    value.as_ref().map(Spanned::span)
}

/// Rejects keys that do not apply to the table's type. `table` is the field
/// path of the table (`materials[2]`), `noun` what it is (`material`),
/// `types` the keys each type accepts, `kind` the table's type, `defaulted`
/// whether that type was not written, and `present` the optional keys given,
/// with the spans of their values.
fn check_type_keys(
    src: &Source,
    table: &str,
    noun: &str,
    types: &[(&str, &[&str])],
    kind: &str,
    defaulted: bool,
    present: &[(&str, Option<Range<usize>>)],
) -> Result<(), SceneError> {
    let accepted = types.iter().find(|(t, _)| *t == kind).map_or(&[][..], |(_, keys)| *keys);
    let first_bad = present
        .iter()
        .filter_map(|(key, span)| span.clone().map(|s| (*key, s)))
        .filter(|(key, _)| !accepted.contains(key))
        .min_by_key(|(_, span)| span.start);
    let Some((key, span)) = first_bad else { return Ok(()) };
    let owners: Vec<String> =
        types.iter().filter(|(_, keys)| keys.contains(&key)).map(|(t, _)| format!("type = {t:?}")).collect();
    let default_note = if defaulted { " (the default type)" } else { "" };
    Err(src.error(
        Some(span),
        format!("{table}.{key}"),
        format!(
            "`{key}` does not apply to a {kind} {noun}{default_note}; a {kind} {noun} accepts {}. `{key}` belongs to {}",
            accepted.join(", "),
            owners.join(" or "),
        ),
    ))
}

fn build_material(
    src: &Source,
    i: usize,
    raw: &Spanned<RawMaterial>,
    textures: &mut TextureCache,
) -> Result<Material, SceneError> {
    let m = raw.get_ref();
    let table = format!("materials[{i}]");
    let kind = m.kind.as_ref().map_or(MaterialType::Diffuse, |t| *t.get_ref());
    check_type_keys(
        src,
        &table,
        "material",
        &MATERIAL_KEYS,
        kind.name(),
        m.kind.is_none(),
        &[
            ("albedo", span_of(&m.albedo)),
            ("emission", span_of(&m.emission)),
            ("roughness", span_of(&m.roughness)),
            ("color", span_of(&m.color)),
            ("eta", span_of(&m.eta)),
            ("k", span_of(&m.k)),
            ("metal", span_of(&m.metal)),
            ("ior", span_of(&m.ior)),
            ("albedo_map", span_of(&m.albedo_map)),
            ("normal_map", span_of(&m.normal_map)),
            ("roughness_map", span_of(&m.roughness_map)),
            ("displacement_map", span_of(&m.displacement_map)),
            ("medium", span_of(&m.medium)),
        ],
    )?;
    let albedo = |default: f32| m.albedo.as_ref().map_or(Vec3::splat(default), |a| a.get_ref().get().as_vec3());
    let roughness = |default: f32| m.roughness.as_ref().map_or(default, |r| r.get_ref().get() as f32);
    // Conductors and dielectrics have no albedo; theirs is a neutral 1.
    let (kind, albedo) = match kind {
        // With a colour map the map alone sets the colour unless albedo is given.
        MaterialType::Diffuse => (MaterialKind::Diffuse, albedo(if m.albedo_map.is_some() { 1.0 } else { 0.8 })),
        MaterialType::Mirror => (MaterialKind::Mirror, albedo(1.0)),
        MaterialType::Conductor => (
            MaterialKind::Conductor { roughness: roughness(0.3), fresnel: conductor_fresnel(src, &table, raw)? },
            Vec3::ONE,
        ),
        MaterialType::Dielectric => (
            MaterialKind::Dielectric {
                roughness: roughness(0.0),
                ior: m.ior.as_ref().map_or(1.5, |v| v.get_ref().get() as f32),
            },
            Vec3::ONE,
        ),
    };
    Ok(Material {
        name: m.name.get_ref().clone(),
        kind,
        albedo,
        emission: m.emission.as_ref().map_or(Vec3::ZERO, |e| e.get_ref().get().as_vec3()),
        maps: build_maps(src, &table, m, textures)?,
        medium: m.medium.as_ref().map(|x| x.get_ref().build()),
    })
}

/// The scene's textures, each loaded or generated once: identical specs
/// (the same resolved path, or the same generator and parameters) read the
/// same way share one entry.
#[derive(Default)]
struct TextureCache {
    images: Vec<TextureImage>,
    /// Per image: its key, how it was read, and its colour channels.
    keys: Vec<(String, TextureUsage, u32)>,
}

/// Where a map's texels come from: a file, or a generator (`Sky` is the
/// environment's [`procedural_sky`]).
enum MapSource {
    File { path: PathBuf },
    Checker { size: u32, cells: u32, colors: [[f32; 3]; 2] },
    Heights { size: u32, count: u32, seed: u32 },
    Normals { size: u32, count: u32, seed: u32, strength: f32 },
    Sky { width: u32, height: u32 },
}

impl MapSource {
    /// The dedupe key: equal keys give equal textures.
    fn key(&self) -> String {
        match self {
            Self::File { path } => format!("file {}", path.display()),
            Self::Checker { size, cells, colors } => format!("checker {size} {cells} {colors:?}"),
            Self::Heights { size, count, seed } => format!("heights {size} {count} {seed}"),
            Self::Normals { size, count, seed, strength } => format!("normals {size} {count} {seed} {strength:?}"),
            Self::Sky { width, height } => format!("sky {width} {height}"),
        }
    }
}

impl TextureCache {
    /// The index of the texture for `source` read as a `kind` map, loading
    /// or generating it on first use.
    fn get(&mut self, source: &MapSource, kind: TextureKind) -> Result<usize, texture::TextureError> {
        self.get_as(source, kind.usage(), |path, channels| kind.check_channels(path, channels))
    }

    /// The index of the texture for `source` read as `usage`, loading or
    /// generating it on first use; `check` vets a file's colour channels.
    fn get_as(
        &mut self,
        source: &MapSource,
        usage: TextureUsage,
        check: impl Fn(&Path, u32) -> Result<(), texture::TextureError>,
    ) -> Result<usize, texture::TextureError> {
        let key = source.key();
        if let Some(k) = self.keys.iter().position(|(k, u, _)| *k == key && *u == usage) {
            if let MapSource::File { path } = source {
                check(path, self.keys[k].2)?;
            }
            return Ok(k);
        }
        let (image, channels) = match *source {
            MapSource::File { ref path } => {
                let loaded = texture::load_texture_file(path, usage)?;
                check(path, loaded.channels)?;
                (loaded.image, loaded.channels)
            }
            MapSource::Checker { size, cells, colors: [a, b] } => (texture::checker(size, cells, a, b), 3),
            MapSource::Heights { size, count, seed } => (texture::bump_heights(size, count, seed), 1),
            MapSource::Normals { size, count, seed, strength } => {
                (texture::normals_from_heights(&texture::bump_heights(size, count, seed), strength), 3)
            }
            MapSource::Sky { width, height } => (procedural_sky(width, height), 3),
        };
        self.images.push(image);
        self.keys.push((key, usage, channels));
        Ok(self.images.len() - 1)
    }
}

/// The texture maps of a material (`table` is its field path).
fn build_maps(
    src: &Source,
    table: &str,
    m: &RawMaterial,
    textures: &mut TextureCache,
) -> Result<MaterialMaps, SceneError> {
    let mut maps = MaterialMaps::default();
    let mut one = |key: &str, kind: TextureKind, raw: &Option<Spanned<RawMap>>| match raw {
        Some(raw) => build_map(src, &format!("{table}.{key}"), kind, raw, textures).map(Some),
        None => Ok(None),
    };
    maps.albedo = one("albedo_map", TextureKind::Albedo, &m.albedo_map)?.map(|(k, _)| k);
    maps.normal = one("normal_map", TextureKind::Normal, &m.normal_map)?.map(|(k, _)| k);
    maps.roughness = one("roughness_map", TextureKind::Roughness, &m.roughness_map)?.map(|(k, _)| k);
    maps.displacement = one("displacement_map", TextureKind::Displacement, &m.displacement_map)?
        .map(|(k, scale)| (k, scale.expect("a displacement map has a scale")));
    Ok(maps)
}

/// "a normal map", "an albedo map".
fn with_article(noun: &str) -> String {
    let article = if noun.starts_with(['a', 'e', 'i', 'o', 'u']) { "an" } else { "a" };
    format!("{article} {noun}")
}

/// One texture map at `field` (e.g. `materials[2].albedo_map`): its texture
/// index, and the height scale of a displacement map.
fn build_map(
    src: &Source,
    field: &str,
    kind: TextureKind,
    raw: &Spanned<RawMap>,
    textures: &mut TextureCache,
) -> Result<(usize, Option<f32>), SceneError> {
    let generator = match kind {
        TextureKind::Albedo | TextureKind::Roughness => "checker",
        TextureKind::Normal | TextureKind::Displacement => "bumps",
    };
    let empty_path =
        |span: Range<usize>, field: &str| src.error(Some(span), field, "the texture path must not be empty");
    // (source, span and field path for load errors, height scale)
    let (source, span, source_field, scale) = match raw.get_ref() {
        RawMap::Path(path) => {
            if kind == TextureKind::Displacement {
                return Err(src.error(
                    Some(raw.span()),
                    field,
                    format!(
                        "a displacement map needs a height scale; write a table: \
                         displacement_map = {{ file = {path:?}, scale = 0.02 }}"
                    ),
                ));
            }
            if path.is_empty() {
                return Err(empty_path(raw.span(), field));
            }
            (MapSource::File { path: src.dir.join(path) }, raw.span(), field.to_owned(), None)
        }
        RawMap::Table(t) => {
            let mut present: Vec<(&str, Range<usize>)> = [
                span_of(&t.file).map(|s| ("file", s)),
                span_of(&t.checker).map(|s| ("checker", s)),
                span_of(&t.bumps).map(|s| ("bumps", s)),
            ]
            .into_iter()
            .flatten()
            .collect();
            present.sort_by_key(|(_, span)| span.start);
            if let Some((key, span)) = present.iter().find(|(key, _)| *key != "file" && *key != generator) {
                return Err(src.error(
                    Some(span.clone()),
                    format!("{field}.{key}"),
                    format!(
                        "`{key}` does not apply to {}; it takes `file` or `{generator}`",
                        with_article(kind.name())
                    ),
                ));
            }
            match present.as_slice() {
                [] => {
                    return Err(src.error(
                        Some(raw.span()),
                        field,
                        format!("the {} needs exactly one of `file` and `{generator}`; found neither", kind.name()),
                    ))
                }
                [_, (key, span), ..] => {
                    return Err(src.error(
                        Some(span.clone()),
                        format!("{field}.{key}"),
                        format!("the {} needs exactly one of `file` and `{generator}`; found both", kind.name()),
                    ))
                }
                [_] => {}
            }
            let scale = match (&t.scale, kind) {
                (Some(s), TextureKind::Displacement) => Some(s.get_ref().get() as f32),
                (None, TextureKind::Displacement) => {
                    return Err(src.error(
                        Some(raw.span()),
                        format!("{field}.scale"),
                        "the required key `scale` of a displacement map is missing: the height of a texel \
                         value of 1, in object units, e.g. scale = 0.02",
                    ))
                }
                (Some(s), _) => {
                    return Err(src.error(
                        Some(s.span()),
                        format!("{field}.scale"),
                        format!("`scale` applies only to a displacement map, not to {}", with_article(kind.name())),
                    ))
                }
                (None, _) => None,
            };
            if let Some(file) = &t.file {
                if file.get_ref().is_empty() {
                    return Err(empty_path(file.span(), &format!("{field}.file")));
                }
                (MapSource::File { path: src.dir.join(file.get_ref()) }, file.span(), format!("{field}.file"), scale)
            } else if let Some(c) = &t.checker {
                let c = c.get_ref();
                let (size, cells) = (c.size.0, c.cells.get_ref().get() as u32);
                if cells > size {
                    return Err(src.error(
                        Some(c.cells.span()),
                        format!("{field}.checker.cells"),
                        format!("must be at most the texture size {size} (got {cells})"),
                    ));
                }
                let colors = c.colors.0.map(|v| v.as_vec3().to_array());
                (MapSource::Checker { size, cells, colors }, raw.span(), field.to_owned(), scale)
            } else if let Some(b) = &t.bumps {
                let b = b.get_ref();
                let (size, count, seed) = (b.size.0, b.count.get() as u32, b.seed.map_or(0, |s| s.get() as u32));
                let source = match (kind, &b.strength) {
                    (TextureKind::Normal, strength) => {
                        let strength = strength.as_ref().map_or(1.0, |s| s.get_ref().get() as f32);
                        MapSource::Normals { size, count, seed, strength }
                    }
                    (_, Some(strength)) => {
                        return Err(src.error(
                            Some(strength.span()),
                            format!("{field}.bumps.strength"),
                            "`strength` applies only to the bumps of a normal map; a displacement map's height \
                             is set by its `scale`",
                        ))
                    }
                    (_, None) => MapSource::Heights { size, count, seed },
                };
                (source, raw.span(), field.to_owned(), scale)
            } else {
                unreachable!("exactly one source is present")
            }
        }
    };
    let index = textures
        .get(&source, kind)
        .map_err(|e| src.error(Some(span), source_field, format!("cannot load the {}: {e}", kind.name())))?;
    Ok((index, scale))
}

/// The `[environment]` table: its map (a file read as colour, or the
/// procedural sky) and its radiance scale.
fn build_environment(
    src: &Source,
    raw: &RawEnvironment,
    textures: &mut TextureCache,
) -> Result<EnvironmentMapSettings, SceneError> {
    const FIELD: &str = "environment.map";
    let map = &raw.map;
    let file = |path: &str, span: Range<usize>, field: &str| {
        if path.is_empty() {
            Err(src.error(Some(span), field, "the texture path must not be empty"))
        } else {
            Ok(MapSource::File { path: src.dir.join(path) })
        }
    };
    // (source, span and field path for load errors)
    let (source, span, field) = match map.get_ref() {
        RawMap::Path(path) => (file(path, map.span(), FIELD)?, map.span(), FIELD.to_owned()),
        RawMap::Table(t) => match (&t.file, &t.sky) {
            (Some(f), None) => {
                let field = format!("{FIELD}.file");
                (file(f.get_ref(), f.span(), &field)?, f.span(), field)
            }
            (None, Some(sky)) => {
                let (width, height) = (sky.get_ref().width.0, sky.get_ref().height.0);
                (MapSource::Sky { width, height }, sky.span(), format!("{FIELD}.sky"))
            }
            (None, None) => {
                return Err(src.error(
                    Some(map.span()),
                    FIELD,
                    "the environment map needs exactly one of `file` and `sky`; found neither, e.g. \
                     map = \"sky.exr\" or map = { sky = { width = 512, height = 256 } }",
                ))
            }
            (Some(f), Some(sky)) => {
                let (key, span) =
                    if sky.span().start > f.span().start { ("sky", sky.span()) } else { ("file", f.span()) };
                return Err(src.error(
                    Some(span),
                    format!("{FIELD}.{key}"),
                    "the environment map needs exactly one of `file` and `sky`; found both",
                ));
            }
        },
    };
    // Read like a colour map: PNG and JPEG are sRGB-decoded, EXR is linear;
    // any number of channels will do (grey is replicated to RGB).
    let texture = textures
        .get_as(&source, TextureUsage::Color, |_, _| Ok(()))
        .map_err(|e| src.error(Some(span), field, format!("cannot load the environment map: {e}")))?;
    Ok(EnvironmentMapSettings { texture, scale: raw.scale.map_or(1.0, |s| s.get() as f32) })
}

/// The Fresnel term of a conductor from its one of `color`, `eta` with `k`,
/// and `metal` (Schlick with 0.9 grey when none is given).
fn conductor_fresnel(src: &Source, table: &str, raw: &Spanned<RawMaterial>) -> Result<ConductorFresnel, SceneError> {
    let m = raw.get_ref();
    // The forms given, in source order: (key for the field path, its description, span).
    let complex_key = match (span_of(&m.eta), span_of(&m.k)) {
        (Some(e), Some(k)) if k.start < e.start => Some(("k", k)),
        (Some(e), _) => Some(("eta", e)),
        (None, k) => k.map(|k| ("k", k)),
    };
    let mut forms: Vec<(&str, &str, Range<usize>)> = [
        span_of(&m.color).map(|s| ("color", "`color`", s)),
        complex_key.map(|(key, s)| (key, "`eta`/`k`", s)),
        span_of(&m.metal).map(|s| ("metal", "`metal`", s)),
    ]
    .into_iter()
    .flatten()
    .collect();
    forms.sort_by_key(|(_, _, span)| span.start);
    if let [first, second, ..] = forms.as_slice() {
        return Err(src.error(
            Some(second.2.clone()),
            format!("{table}.{}", second.0),
            format!(
                "a conductor takes one Fresnel form: `color` (Schlick), `eta` with `k` (complex index of \
                 refraction) or `metal` (a named metal); found {} and {}",
                first.1, second.1
            ),
        ));
    }
    let pair_missing = |missing: &str, given: &str, span: Range<usize>| {
        src.error(
            Some(span),
            format!("{table}.{missing}"),
            format!(
                "the required key `{missing}` is missing: `{given}` needs it (`eta` and `k` together give the \
                 complex index of refraction η + iκ)"
            ),
        )
    };
    Ok(match (&m.color, &m.eta, &m.k, &m.metal) {
        (Some(c), ..) => ConductorFresnel::Schlick { f0: c.get_ref().get().as_vec3() },
        (_, Some(eta), Some(k), _) => {
            ConductorFresnel::Complex { eta: eta.get_ref().get().as_vec3(), k: k.get_ref().get().as_vec3() }
        }
        (_, Some(eta), None, _) => return Err(pair_missing("k", "eta", eta.span())),
        (_, None, Some(k), _) => return Err(pair_missing("eta", "k", k.span())),
        (.., Some(metal)) => {
            let (eta, k) = metal.get_ref().ior();
            ConductorFresnel::Complex { eta, k }
        }
        _ => ConductorFresnel::Schlick { f0: Vec3::splat(0.9) },
    })
}

fn build_light(src: &Source, i: usize, raw: &Spanned<RawLight>) -> Result<Light, SceneError> {
    let l = raw.get_ref();
    let table = format!("lights[{i}]");
    let kind = l.kind.name();
    check_type_keys(
        src,
        &table,
        "light",
        &LIGHT_KEYS,
        kind,
        false,
        &[
            ("position", span_of(&l.position)),
            ("intensity", span_of(&l.intensity)),
            ("radius", span_of(&l.radius)),
            ("radiance", span_of(&l.radiance)),
            ("corner", span_of(&l.corner)),
            ("edge_u", span_of(&l.edge_u)),
            ("edge_v", span_of(&l.edge_v)),
            ("direction", span_of(&l.direction)),
            ("irradiance", span_of(&l.irradiance)),
        ],
    )?;
    fn required<'a, T>(
        src: &Source,
        table: &str,
        kind: &str,
        raw: &Spanned<RawLight>,
        key: &str,
        value: &'a Option<Spanned<T>>,
    ) -> Result<&'a Spanned<T>, SceneError> {
        value.as_ref().ok_or_else(|| {
            src.error(
                Some(raw.span()),
                format!("{table}.{key}"),
                format!("the required key `{key}` of a {kind} light is missing"),
            )
        })
    }
    let vector = |key: &str, value: &Option<Spanned<Triple<Finite>>>| {
        required(src, &table, kind, raw, key, value).map(|v| (v.get_ref().get(), v.span()))
    };
    let colour = |key: &str, value: &Option<Spanned<Triple<NonNegative>>>| {
        required(src, &table, kind, raw, key, value).map(|v| v.get_ref().get().as_vec3())
    };
    match l.kind {
        LightKind::Point => Ok(Light::Point {
            position: vector("position", &l.position)?.0,
            intensity: colour("intensity", &l.intensity)?,
        }),
        LightKind::Sphere => {
            let centre = vector("position", &l.position)?.0;
            let radius = required(src, &table, kind, raw, "radius", &l.radius)?.get_ref().get();
            Ok(Light::Sphere { centre, radius, radiance: colour("radiance", &l.radiance)? })
        }
        LightKind::Rect => {
            let corner = vector("corner", &l.corner)?.0;
            let (edge_u, u_span) = vector("edge_u", &l.edge_u)?;
            let (edge_v, v_span) = vector("edge_v", &l.edge_v)?;
            let radiance = colour("radiance", &l.radiance)?;
            for (key, edge, span) in [("edge_u", edge_u, &u_span), ("edge_v", edge_v, &v_span)] {
                if edge.length() == 0.0 {
                    return Err(src.error(Some(span.clone()), format!("{table}.{key}"), "must not be zero"));
                }
            }
            if edge_u.cross(edge_v).length() <= 1e-6 * edge_u.length() * edge_v.length() {
                return Err(src.error(
                    Some(v_span),
                    format!("{table}.edge_v"),
                    "edge_u and edge_v are parallel, so the rect light has no area; \
                     give two edges that span a parallelogram",
                ));
            }
            Ok(Light::Rect { corner, edge_u, edge_v, radiance })
        }
        LightKind::Directional => {
            let (direction, span) = vector("direction", &l.direction)?;
            let Some(direction) = direction.try_normalize() else {
                return Err(src.error(
                    Some(span),
                    format!("{table}.direction"),
                    "must not be zero (it points from the scene toward the light and is normalised on load)",
                ));
            };
            Ok(Light::Directional { direction, irradiance: colour("irradiance", &l.irradiance)? })
        }
    }
}

// ---------------------------------------------------------------------------
// Scattered bumps
// ---------------------------------------------------------------------------

struct ScatterParams {
    count: usize,
    centre: DVec3,
    on_radii: DVec3,
    radius: DVec3,
    form_factor: f64,
    alternate: bool,
    seed: u32,
    jitter: f64,
}

/// `count` ellipsoidal bumps centred on points of the ellipsoid `on_radii`
/// around `centre`, placed by a Fibonacci spiral around the y axis and
/// optionally jittered along the surface by up to `jitter` times the mean
/// spacing.
fn scatter(p: ScatterParams) -> impl Iterator<Item = Perturbation> {
    let n = p.count;
    let golden_angle = std::f64::consts::PI * (3.0 - 5f64.sqrt());
    let spacing = (4.0 * std::f64::consts::PI / n as f64).sqrt();
    (0..n).map(move |i| {
        let y = 1.0 - 2.0 * (i as f64 + 0.5) / n as f64;
        let r = (1.0 - y * y).max(0.0).sqrt();
        let phi = i as f64 * golden_angle;
        let mut u = DVec3::new(r * phi.cos(), y, r * phi.sin());
        if p.jitter > 0.0 {
            let t1 = u.any_orthonormal_vector();
            let t2 = u.cross(t1);
            let a = hash_unit(p.seed, i as u64, 0) - 0.5;
            let b = hash_unit(p.seed, i as u64, 1) - 0.5;
            u = (u + p.jitter * spacing * (a * t1 + b * t2)).normalize();
        }
        let f = if p.alternate && i % 2 == 1 { -p.form_factor } else { p.form_factor };
        Perturbation { quadric: Quadric::ellipsoid(p.centre + p.on_radii * u, p.radius), form_factor: f }
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    const CAMERA: &str = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\n";

    fn parse(body: &str) -> Scene {
        let text = format!("{CAMERA}{body}");
        parse_scene(&text, "test.toml").unwrap_or_else(|e| panic!("{e}"))
    }

    fn one_shape(shape: &str) -> FunctionalObject {
        parse(&format!("[[objects]]\n{shape}\nclip = {{ min = [-3, -3, -3], max = [3, 3, 3] }}\n")).objects[0]
            .shape
            .clone()
    }

    fn near(a: f64, b: f64) -> bool {
        (a - b).abs() < 1e-9
    }

    #[test]
    fn defaults() {
        let s = parse("");
        assert_eq!(
            s.image,
            ImageSettings {
                width: 640,
                height: 480,
                spp: 16,
                seed: 0,
                exposure: 0.0,
                max_depth: 6,
                filter: FilterMode::None,
                preset: None
            }
        );
        assert_eq!(s.camera.up, DVec3::Y);
        assert_eq!(s.camera.vfov_degrees, 40.0);
        assert_eq!(s.background, Vec3::ZERO);
        assert!(s.objects.is_empty() && s.lights.is_empty() && s.materials.is_empty());
    }

    #[test]
    fn presets_set_the_quality_and_the_files_keys_override_them() {
        let s = parse_scene(
            &format!("[image]\npreset = \"final\"\nmax_depth = 10\n[volume]\nsamples = 3\n{CAMERA}"),
            "t.toml",
        )
        .unwrap();
        let q = Preset::Final.quality();
        assert_eq!(s.image.preset, Some(Preset::Final));
        assert_eq!((s.image.spp, s.image.filter, s.caustics.rays), (q.spp, q.filter, q.caustic_rays));
        assert_eq!((s.image.max_depth, s.volume.samples), (10, 3));
        let s = parse_scene(&format!("[image]\nfilter = \"ray-cones\"\n{CAMERA}"), "t.toml").unwrap();
        assert_eq!((s.image.filter, s.image.preset, s.image.spp), (FilterMode::RayCones, None, 16));
    }

    #[test]
    fn unknown_presets_and_filters_are_errors_at_their_line() {
        let e = parse_scene(&format!("[image]\npreset = \"fast\"\n{CAMERA}"), "t.toml").unwrap_err().to_string();
        assert!(e.starts_with("t.toml:2:10: image.preset: unknown preset `fast`"), "{e}");
        let e =
            parse_scene(&format!("[image]\nwidth = 8\nfilter = \"ewa\"\n{CAMERA}"), "t.toml").unwrap_err().to_string();
        assert!(e.starts_with("t.toml:3:10: image.filter: unknown filter `ewa`"), "{e}");
    }

    #[test]
    fn image_and_background() {
        let text = "background = [0.1, 0.2, 0.3]\n[image]\nwidth = 64\nheight = 48\nspp = 3\nseed = 4000000000\nexposure = -1.5\nmax_depth = 12\n";
        let s = parse_scene(&format!("{text}{CAMERA}"), "t.toml").unwrap();
        assert_eq!(
            s.image,
            ImageSettings {
                width: 64,
                height: 48,
                spp: 3,
                seed: 4_000_000_000,
                exposure: -1.5,
                max_depth: 12,
                filter: FilterMode::None,
                preset: None
            }
        );
        assert_eq!(s.background, Vec3::new(0.1, 0.2, 0.3));
    }

    #[test]
    fn sphere_and_ellipsoid() {
        let s = one_shape("sphere = { radius = 2 }");
        assert!(near(s.eval(DVec3::new(2.0, 0.0, 0.0)), 0.0));
        assert!(near(s.eval(DVec3::new(0.0, 0.0, -2.0)), 0.0));
        assert!(s.eval(DVec3::ZERO) > 0.0);
        assert!(s.eval(DVec3::new(0.0, 2.1, 0.0)) < 0.0);
        let e = one_shape("ellipsoid = { radii = [1, 0.5, 2] }");
        for p in [DVec3::X, DVec3::new(0.0, 0.5, 0.0), DVec3::new(0.0, 0.0, -2.0)] {
            assert!(near(e.eval(p), 0.0));
        }
        assert!(e.eval(DVec3::ZERO) > 0.0);
    }

    #[test]
    fn plane_cylinder_cone_paraboloid() {
        let p = one_shape("plane = {}");
        assert!(near(p.eval(DVec3::new(1.0, 0.0, 2.0)), 0.0));
        assert!(p.eval(DVec3::new(0.0, -1.0, 0.0)) > 0.0);
        assert!((p.normal(DVec3::ZERO) - DVec3::Y).length() < 1e-12);
        let c = one_shape("cylinder = { radius = 0.5 }");
        assert!(near(c.eval(DVec3::new(0.5, 7.0, 0.0)), 0.0));
        assert!(near(c.eval(DVec3::new(0.3, -1.0, 0.4)), 0.0));
        assert!(c.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
        let k = one_shape("cone = { half_angle = 30 }");
        let t = 30f64.to_radians().tan();
        assert!(near(k.eval(DVec3::new(t * 2.0, 2.0, 0.0)), 0.0));
        assert!(near(k.eval(DVec3::new(0.0, -1.0, t)), 0.0));
        assert!(k.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
        assert!(k.eval(DVec3::new(1.0, 0.0, 0.0)) < 0.0);
        let q = one_shape("paraboloid = { curvature = 2 }");
        assert!(near(q.eval(DVec3::new(1.0, 2.0, 0.0)), 0.0));
        assert!(q.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
        assert!(q.eval(DVec3::new(0.0, -1.0, 0.0)) < 0.0);
    }

    #[test]
    fn hyperboloids() {
        let h = one_shape("hyperboloid = { radius = 0.5, slope = 2 }");
        assert!(near(h.eval(DVec3::new(0.5, 0.0, 0.0)), 0.0));
        // x² + z² = r² + s² y²
        let r = (0.25f64 + 4.0).sqrt();
        assert!(near(h.eval(DVec3::new(0.0, 1.0, r)), 0.0));
        assert!(h.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
        assert!(h.eval(DVec3::new(1.0, 0.0, 0.0)) < 0.0);
        let h2 = one_shape("hyperboloid = { radius = 0.5, slope = 2, sheets = 2 }");
        // s² y² - (x² + z²) = r²: vertices at y = ±r/s
        assert!(near(h2.eval(DVec3::new(0.0, 0.25, 0.0)), 0.0));
        assert!(near(h2.eval(DVec3::new(0.0, -0.25, 0.0)), 0.0));
        assert!(near(h2.eval(DVec3::new((4.0f64 - 0.25).sqrt(), 1.0, 0.0)), 0.0));
        assert!(h2.eval(DVec3::new(0.0, 1.0, 0.0)) > 0.0);
        assert!(h2.eval(DVec3::ZERO) < 0.0);
    }

    #[test]
    fn general_quadric_and_clip() {
        let s = parse(
            "[[objects]]\nquadric = [1, 2, 3, 4, 5, 6, 7, 8, 9, 10]\nclip = { min = [-1, -2, -3], max = [1, 2, 3] }\n",
        );
        let o = &s.objects[0].shape;
        assert_eq!(o.base.coefficients(), [1.0, 2.0, 3.0, 4.0, 5.0, 6.0, 7.0, 8.0, 9.0, 10.0]);
        assert_eq!(o.clip, Some(Aabb::new(DVec3::new(-1.0, -2.0, -3.0), DVec3::new(1.0, 2.0, 3.0))));
        assert_eq!(one_shape("sphere = { radius = 1 }").clip.unwrap().max, DVec3::splat(3.0));
        assert_eq!(parse("[[objects]]\nsphere = { radius = 1 }\n").objects[0].shape.clip, None);
    }

    #[test]
    fn transforms() {
        let s = parse(
            "[[objects]]\nsphere = { radius = 1 }\ntranslate = [1, 2, 3]\n\
             [[objects]]\nsphere = { radius = 1 }\nrotate = [0, 0, 90]\nscale = 2\n\
             [[objects]]\nsphere = { radius = 1 }\nscale = [1, 2, 3]\n\
             [[objects]]\nsphere = { radius = 1 }\nrotate = [90, 90, 0]\n",
        );
        let t = &s.objects;
        assert_eq!(t[0].transform, DAffine3::from_translation(DVec3::new(1.0, 2.0, 3.0)));
        let p = t[1].transform.transform_point3(DVec3::X);
        assert!((p - DVec3::new(0.0, 2.0, 0.0)).length() < 1e-12, "{p}");
        let p = t[2].transform.transform_point3(DVec3::ONE);
        assert!((p - DVec3::new(1.0, 2.0, 3.0)).length() < 1e-12);
        // Euler XYZ: R = Rx · Ry · Rz, so the vector is turned about z, then y, then x.
        let r = glam::DMat3::from_rotation_x(std::f64::consts::FRAC_PI_2)
            * glam::DMat3::from_rotation_y(std::f64::consts::FRAC_PI_2);
        let v = DVec3::new(0.3, -0.5, 0.7);
        assert!((t[3].transform.transform_vector3(v) - r * v).length() < 1e-12);
        assert_eq!(t[0].name, "objects[0]");
    }

    #[test]
    fn perturbations() {
        let s = parse(
            "[[objects]]\nsphere = { radius = 1 }\n\
             [[objects.perturbations]]\nbump = { centre = [0, 1, 0], radius = 0.2 }\nf = 0.5\n\
             [[objects.perturbations]]\nbump = { center = [1, 0, 0], radius = [0.1, 0.2, 0.3] }\nf = -0.25\n\
             [[objects.perturbations]]\nquadric = [-1, -1, -1, 0, 0, 0, 0, 0, 0, 0.01]\nf = 2\n",
        );
        let p = &s.objects[0].shape.perturbations;
        assert_eq!(p.len(), 3);
        assert_eq!(p[0].quadric, Quadric::ellipsoid(DVec3::Y, DVec3::splat(0.2)));
        assert_eq!(p[0].form_factor, 0.5);
        assert_eq!(p[1].quadric, Quadric::ellipsoid(DVec3::X, DVec3::new(0.1, 0.2, 0.3)));
        assert_eq!(p[1].form_factor, -0.25);
        assert_eq!(p[2].quadric.coefficients()[9], 0.01);
        // The bump raises the surface above the pole.
        assert!(s.objects[0].shape.eval(DVec3::new(0.0, 1.01, 0.0)) > 0.0);
    }

    #[test]
    fn scatter_places_bumps_on_the_ellipsoid() {
        let s = parse(
            "[[objects]]\nsphere = { radius = 2 }\n\
             [[objects.perturbations]]\nbump = { centre = [0, 2, 0], radius = 0.2 }\nf = 0.5\n\
             [[objects.scatter]]\ncount = 1000\nradius = 0.05\nf = 0.8\nalternate = true\n\
             [[objects.scatter]]\ncount = 10\non_radii = [1, 2, 3]\ncentre = [0, 1, 0]\nradius = 0.1\nf = 0.3\njitter = 0.5\nseed = 7\n",
        );
        let p = &s.objects[0].shape.perturbations;
        assert_eq!(p.len(), 1 + 1000 + 10);
        let centre = |q: &Quadric| q.support_bounds().unwrap().unwrap().centre();
        for (k, b) in p[1..1001].iter().enumerate() {
            assert!(near(centre(&b.quadric).length(), 2.0));
            assert_eq!(b.form_factor, if k % 2 == 0 { 0.8 } else { -0.8 });
            assert!(near(b.quadric.support_bounds().unwrap().unwrap().size().x, 0.1));
        }
        for b in &p[1001..] {
            let c = centre(&b.quadric) - DVec3::Y;
            assert!(near((c / DVec3::new(1.0, 2.0, 3.0)).length(), 1.0));
            assert_eq!(b.form_factor, 0.3);
        }
        // Deterministic.
        let again = parse(
            "[[objects]]\nsphere = { radius = 2 }\n\
             [[objects.scatter]]\ncount = 10\non_radii = [1, 2, 3]\ncentre = [0, 1, 0]\nradius = 0.1\nf = 0.3\njitter = 0.5\nseed = 7\n",
        );
        assert_eq!(&again.objects[0].shape.perturbations[..], &p[1001..]);
    }

    #[test]
    fn materials_and_default_material() {
        let s = parse(
            "[[materials]]\nname = \"a\"\nalbedo = [0.1, 0.2, 0.3]\n\
             [[materials]]\nname = \"lamp\"\nemission = [5, 5, 5]\n\
             [[objects]]\nsphere = { radius = 1 }\nmaterial = \"lamp\"\n\
             [[objects]]\nname = \"plain\"\nsphere = { radius = 1 }\n\
             [[objects]]\nsphere = { radius = 1 }\n",
        );
        assert_eq!(s.materials.len(), 3);
        assert_eq!(s.materials[0].albedo, Vec3::new(0.1, 0.2, 0.3));
        assert_eq!(s.materials[0].emission, Vec3::ZERO);
        assert_eq!(s.materials[1].albedo, Vec3::splat(0.8));
        assert_eq!(s.materials[1].emission, Vec3::splat(5.0));
        assert_eq!(s.materials[2].name, DEFAULT_MATERIAL_NAME);
        assert_eq!(s.objects.iter().map(|o| o.material).collect::<Vec<_>>(), [1, 2, 2]);
        assert_eq!(s.objects[1].name, "plain");
        // No default material when every object names one.
        let s = parse("[[materials]]\nname = \"a\"\n[[objects]]\nsphere = { radius = 1 }\nmaterial = \"a\"\n");
        assert_eq!(s.materials.len(), 1);
    }

    #[test]
    fn lights() {
        let s = parse(
            "[[lights]]\ntype = \"point\"\nposition = [1, 2, 3]\nintensity = [10, 10, 10]\n\
             [[lights]]\ntype = \"sphere\"\nposition = [0, 5, 0]\nradius = 0.5\nradiance = [4, 3, 2]\n",
        );
        assert_eq!(
            s.lights,
            [
                Light::Point { position: DVec3::new(1.0, 2.0, 3.0), intensity: Vec3::splat(10.0) },
                Light::Sphere { centre: DVec3::new(0.0, 5.0, 0.0), radius: 0.5, radiance: Vec3::new(4.0, 3.0, 2.0) },
            ]
        );
    }

    #[test]
    fn max_depth_range() {
        for depth in [1, 64] {
            let s = parse_scene(&format!("[image]\nmax_depth = {depth}\n{CAMERA}"), "t.toml").unwrap();
            assert_eq!(s.image.max_depth, depth);
        }
        for depth in ["0", "65", "-1", "2.5"] {
            let e = parse_scene(&format!("[image]\nmax_depth = {depth}\n{CAMERA}"), "t.toml").unwrap_err();
            let SceneError::Invalid { line, ref field, .. } = e else { panic!("{e}") };
            assert_eq!((line, field.as_str()), (2, "image.max_depth"), "{e}");
        }
    }

    fn one_material(body: &str) -> Material {
        let s = parse(&format!("[[materials]]\nname = \"m\"\n{body}"));
        s.materials.into_iter().next().unwrap()
    }

    fn material_error(body: &str) -> String {
        let text = format!("{CAMERA}[[materials]]\nname = \"m\"\n{body}");
        parse_scene(&text, "t.toml").map(|_| ()).unwrap_err().to_string()
    }

    #[test]
    fn material_types_and_defaults() {
        let d = one_material("");
        assert_eq!(d, Material::diffuse("m", Vec3::splat(0.8)));
        assert_eq!(one_material("type = \"diffuse\"\nalbedo = [0.1, 0.2, 0.3]").albedo, Vec3::new(0.1, 0.2, 0.3));

        let m = one_material("type = \"mirror\"");
        assert_eq!((m.kind, m.albedo, m.emission), (MaterialKind::Mirror, Vec3::ONE, Vec3::ZERO));
        assert_eq!(one_material("type = \"mirror\"\nalbedo = [0.9, 0.8, 0.7]").albedo, Vec3::new(0.9, 0.8, 0.7));

        let c = one_material("type = \"conductor\"");
        assert_eq!(
            c.kind,
            MaterialKind::Conductor { roughness: 0.3, fresnel: ConductorFresnel::Schlick { f0: Vec3::splat(0.9) } }
        );
        assert_eq!(c.albedo, Vec3::ONE);
        let c = one_material("type = \"conductor\"\nroughness = 0\nemission = [1, 2, 3]");
        assert!(matches!(c.kind, MaterialKind::Conductor { roughness: 0.0, .. }));
        assert_eq!(c.emission, Vec3::new(1.0, 2.0, 3.0));

        let g = one_material("type = \"dielectric\"");
        assert_eq!((g.kind, g.albedo), (MaterialKind::Dielectric { roughness: 0.0, ior: 1.5 }, Vec3::ONE));
        let w = one_material("type = \"dielectric\"\nior = 1.33\nroughness = 0.25");
        assert_eq!(w.kind, MaterialKind::Dielectric { roughness: 0.25, ior: 1.33 });

        // Emission on every type.
        for ty in ["diffuse", "conductor", "dielectric", "mirror"] {
            let m = one_material(&format!("type = \"{ty}\"\nemission = [4, 5, 6]"));
            assert_eq!(m.emission, Vec3::new(4.0, 5.0, 6.0), "{ty}");
        }
    }

    #[test]
    fn conductor_fresnel_forms() {
        let fresnel = |body: &str| match one_material(&format!("type = \"conductor\"\n{body}")).kind {
            MaterialKind::Conductor { fresnel, .. } => fresnel,
            k => panic!("{k:?}"),
        };
        assert_eq!(
            fresnel("color = [0.95, 0.64, 0.54]"),
            ConductorFresnel::Schlick { f0: Vec3::new(0.95, 0.64, 0.54) }
        );
        assert_eq!(
            fresnel("eta = [0.2, 0.9, 1.1]\nk = [3.9, 2.4, 2.2]"),
            ConductorFresnel::Complex { eta: Vec3::new(0.2, 0.9, 1.1), k: Vec3::new(3.9, 2.4, 2.2) }
        );
        // k = 0 is allowed (a non-absorbing "conductor").
        assert_eq!(
            fresnel("k = [0, 0, 0]\neta = [1.5, 1.5, 1.5]"),
            ConductorFresnel::Complex { eta: Vec3::splat(1.5), k: Vec3::ZERO }
        );
        assert_eq!(fresnel("metal = \"aluminum\""), fresnel("metal = \"aluminium\""));
    }

    #[test]
    fn named_metals_are_complex_iors() {
        /// Reflectance at normal incidence of a conductor in vacuum.
        fn f0(eta: Vec3, k: Vec3) -> Vec3 {
            ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k)
        }
        let mut seen = Vec::new();
        for (metal, preset) in [
            ("gold", Metal::Gold),
            ("silver", Metal::Silver),
            ("copper", Metal::Copper),
            ("aluminium", Metal::Aluminium),
        ] {
            let m = one_material(&format!("type = \"conductor\"\nmetal = \"{metal}\"\nroughness = 0.1"));
            let MaterialKind::Conductor { roughness, fresnel: ConductorFresnel::Complex { eta, k } } = m.kind else {
                panic!("{metal}: {:?}", m.kind)
            };
            assert_eq!(roughness, 0.1);
            assert_eq!((eta, k), preset.ior(), "{metal}");
            assert!(eta.min_element() > 0.0 && k.min_element() > 0.0, "{metal}");
            let r = f0(eta, k);
            assert!(r.min_element() > 0.3 && r.max_element() < 1.0, "{metal}: {r}");
            seen.push(r);
        }
        // Gold and copper are red-yellow: reflectance falls from red to blue;
        // silver and aluminium are nearly neutral and bright.
        for r in &seen[..1] {
            assert!(r.x > r.y && r.y > r.z, "{r}");
        }
        assert!(seen[2].x > seen[2].y && seen[2].x > seen[2].z, "copper {}", seen[2]);
        for r in [seen[1], seen[3]] {
            assert!(r.min_element() > 0.85 && r.max_element() - r.min_element() < 0.05, "{r}");
        }
    }

    #[test]
    fn material_key_errors() {
        let e = material_error("ior = 1.5\n");
        assert!(
            e.starts_with(
                "t.toml:6:7: materials[0].ior: `ior` does not apply to a diffuse material (the default type)"
            ),
            "{e}"
        );
        assert!(e.contains("accepts name, type, albedo, emission") && e.contains("type = \"dielectric\""), "{e}");
        let e = material_error("type = \"conductor\"\nalbedo = [1, 1, 1]\n");
        assert!(e.contains("materials[0].albedo: `albedo` does not apply to a conductor material;"), "{e}");
        assert!(e.contains("type = \"diffuse\" or type = \"mirror\""), "{e}");
        let e = material_error("type = \"glass\"\n");
        assert!(e.contains("materials[0].type") && e.contains("`dielectric`"), "{e}");
        let e = material_error("type = \"conductor\"\nmetal = \"gold\"\ncolor = [1, 1, 1]\n");
        assert!(e.starts_with("t.toml:8:9: materials[0].color:") && e.contains("found `metal` and `color`"), "{e}");
        let e = material_error("type = \"conductor\"\neta = [1, 1, 1]\n");
        assert!(e.starts_with("t.toml:7:7: materials[0].k: the required key `k` is missing"), "{e}");
        let e = material_error("type = \"conductor\"\nk = [1, 1, 1]\n");
        assert!(e.contains("materials[0].eta: the required key `eta` is missing"), "{e}");
        let e = material_error("type = \"conductor\"\nmetal = \"iron\"\n");
        assert!(e.contains("materials[0].metal") && e.contains("unknown variant `iron`"), "{e}");
        let e = material_error("type = \"dielectric\"\nior = 0\n");
        assert!(e.contains("materials[0].ior: must be positive (got 0)"), "{e}");
        let e = material_error("type = \"conductor\"\neta = [1, 0, 1]\nk = [1, 1, 1]\n");
        assert!(e.contains("materials[0].eta[1]: must be positive (got 0)"), "{e}");
    }

    #[test]
    fn rect_and_directional_lights() {
        let s = parse(
            "[[lights]]\ntype = \"rect\"\ncorner = [-1, 2, -1]\nedge_u = [2, 0, 0]\nedge_v = [0, 0, 2]\nradiance = [5, 4, 3]\n\
             [[lights]]\ntype = \"directional\"\ndirection = [0, 3, 4]\nirradiance = [2, 2, 2]\n",
        );
        assert_eq!(
            s.lights[0],
            Light::Rect {
                corner: DVec3::new(-1.0, 2.0, -1.0),
                edge_u: DVec3::new(2.0, 0.0, 0.0),
                edge_v: DVec3::new(0.0, 0.0, 2.0),
                radiance: Vec3::new(5.0, 4.0, 3.0),
            }
        );
        let Light::Directional { direction, irradiance } = s.lights[1] else { panic!("{:?}", s.lights[1]) };
        assert!((direction - DVec3::new(0.0, 0.6, 0.8)).length() < 1e-12, "normalised: {direction}");
        assert_eq!(irradiance, Vec3::splat(2.0));
        // The documented example emits downward.
        let Light::Rect { edge_u, edge_v, .. } = s.lights[0] else { unreachable!() };
        assert_eq!(edge_u.cross(edge_v), DVec3::new(0.0, -4.0, 0.0));
    }

    #[test]
    fn light_errors() {
        let err = |body: &str| parse_scene(&format!("{CAMERA}[[lights]]\n{body}"), "t.toml").unwrap_err().to_string();
        let rect = |u: &str, v: &str| {
            err(&format!("type = \"rect\"\ncorner = [0, 0, 0]\nedge_u = {u}\nedge_v = {v}\nradiance = [1, 1, 1]\n"))
        };
        let e = rect("[1, 0, 0]", "[-2, 0, 0]");
        assert!(e.starts_with("t.toml:8:10: lights[0].edge_v: edge_u and edge_v are parallel"), "{e}");
        let e = rect("[0, 0, 0]", "[0, 0, 1]");
        assert!(e.starts_with("t.toml:7:10: lights[0].edge_u: must not be zero"), "{e}");
        let e = rect("[1, 0, 0]", "[0, 0, 0]");
        assert!(e.starts_with("t.toml:8:10: lights[0].edge_v: must not be zero"), "{e}");
        let e = err("type = \"directional\"\ndirection = [0, 0, 0]\nirradiance = [1, 1, 1]\n");
        assert!(e.starts_with("t.toml:6:13: lights[0].direction: must not be zero"), "{e}");
        let e = err("type = \"rect\"\nposition = [0, 0, 0]\n");
        assert!(e.contains("lights[0].position: `position` does not apply to a rect light;"), "{e}");
        assert!(e.contains("accepts type, corner, edge_u, edge_v, radiance"), "{e}");
        let e = err("type = \"directional\"\ndirection = [0, 1, 0]\n");
        assert!(
            e.starts_with("t.toml:4:1: lights[0].irradiance: the required key `irradiance` of a directional"),
            "{e}"
        );
        let e = err("type = \"sphere\"\nradius = 1\nradiance = [1, 1, 1]\n");
        assert!(e.contains("lights[0].position: the required key `position` of a sphere light is missing"), "{e}");
    }

    #[test]
    fn camera_keyframes_interpolate_and_must_increase() {
        let text = "[camera]\nposition = [0, 0, 5]\nlook_at = [0, 0, 0]\nfps = 2\n\
                    [[camera.keyframes]]\ntime = 0\nposition = [0, 0, 4]\nlook_at = [0, 0, 0]\n\
                    [[camera.keyframes]]\ntime = 1\nposition = [2, 0, 4]\nlook_at = [0, 0, 0]\nfov = 60\n";
        let s = parse_scene(text, "t").unwrap();
        assert_eq!(s.camera.keyframes.len(), 2);
        assert_eq!(s.camera.keyframes[0].vfov_degrees, 40.0);
        // Frame 1 at 2 fps: halfway.
        let c = s.camera.at_frame(1);
        assert_eq!((c.position, c.vfov_degrees), (DVec3::new(1.0, 0.0, 4.0), 50.0));
        assert_eq!(s.camera.at_frame(7).position, DVec3::new(2.0, 0.0, 4.0));
        assert_eq!(s.camera.render_origin(), DVec3::new(0.0, 0.0, 4.0));
        let e = parse_scene(&text.replace("time = 1", "time = 0"), "t").unwrap_err().to_string();
        assert!(e.contains("camera.keyframes[1].time") && e.contains("later"), "{e}");
        let e =
            parse_scene(&text.replace("position = [2, 0, 4]", "position = [0, 0, 0]"), "t").unwrap_err().to_string();
        assert!(e.contains("camera.keyframes[1].look_at"), "{e}");
    }

    #[test]
    fn camera() {
        let s = parse_scene("[camera]\nposition = [1, 2, 3]\nlook_at = [0, 1, 0]\nup = [0, 0, 1]\nfov = 60\n", "t")
            .unwrap();
        assert_eq!(s.camera, Camera::still(DVec3::new(1.0, 2.0, 3.0), DVec3::Y, DVec3::Z, 60.0));
    }

    #[test]
    fn default_scene_parses_and_is_bounded() {
        let s = parse_scene(DEFAULT_SCENE, DEFAULT_SCENE_NAME).unwrap_or_else(|e| panic!("{e}"));
        assert!(s.objects.len() >= 3);
        assert!(!s.lights.is_empty());
        for o in &s.objects {
            assert!(o.shape.bounds().is_ok(), "{}", o.name);
        }
    }

    #[test]
    fn generated_maps_and_deduplication() {
        let s = parse(
            "[[materials]]\nname = \"a\"\nalbedo_map = { checker = { size = 16, cells = 4, colors = [[0.9, 0.9, 0.9], 0.1] } }\n\
             normal_map = { bumps = { size = 32, count = 10, seed = 3, strength = 4.0 } }\n\
             [[materials]]\nname = \"b\"\ntype = \"mirror\"\n\
             albedo_map = { checker = { size = 16, cells = 4, colors = [[0.9, 0.9, 0.9], [0.1, 0.1, 0.1]] } }\n\
             displacement_map = { bumps = { size = 32, count = 10, seed = 3 }, scale = 0.02 }\n\
             [[materials]]\nname = \"c\"\ntype = \"conductor\"\n\
             roughness_map = { checker = { size = 16, cells = 4, colors = [[0.9, 0.9, 0.9], 0.1] } }\n\
             normal_map = { bumps = { size = 32, count = 10, seed = 3, strength = 4 } }\n\
             displacement_map = { bumps = { size = 32, count = 10, seed = 3 }, scale = 0.5 }\n\
             [[materials]]\nname = \"d\"\ntype = \"dielectric\"\n\
             normal_map = { bumps = { size = 32, count = 10, seed = 4 } }\n",
        );
        let maps: Vec<&MaterialMaps> = s.materials.iter().map(|m| &m.maps).collect();
        // a: checker 0, normals 1; b: the same checker, heights 2; c: the
        // checker read as data is another texture (3), the same normals, the
        // same heights with another scale; d: other normals (4).
        assert_eq!(*maps[0], MaterialMaps { albedo: Some(0), normal: Some(1), roughness: None, displacement: None });
        assert_eq!(
            *maps[1],
            MaterialMaps { albedo: Some(0), normal: None, roughness: None, displacement: Some((2, 0.02)) }
        );
        assert_eq!(
            *maps[2],
            MaterialMaps { albedo: None, normal: Some(1), roughness: Some(3), displacement: Some((2, 0.5)) }
        );
        assert_eq!(maps[3].normal, Some(4));
        assert_eq!(s.textures.len(), 5);
        // With a colour map, a diffuse albedo defaults to 1; without, to 0.8.
        assert_eq!(s.materials[0].albedo, Vec3::ONE);
        assert_eq!(
            one_material(
                "albedo_map = { checker = { size = 1, cells = 1, colors = [1, 1] } }\nalbedo = [0.5, 0.5, 0.5]"
            )
            .albedo,
            Vec3::splat(0.5)
        );
        let checker = &s.textures[0];
        assert_eq!((checker.width, checker.height, checker.levels.len()), (16, 16, 5));
        assert_eq!(checker.levels[0][0], [0.9, 0.9, 0.9, 1.0]);
        assert_eq!(checker.levels[0][4], [0.1, 0.1, 0.1, 1.0]);
        assert_eq!(s.textures[3].levels[0], checker.levels[0]);
        assert_eq!(s.textures[1], texture::normals_from_heights(&texture::bump_heights(32, 10, 3), 4.0));
        assert_eq!(s.textures[2], texture::bump_heights(32, 10, 3));
        assert_eq!(s.textures[4], texture::normals_from_heights(&texture::bump_heights(32, 10, 4), 1.0));
        // No maps, no textures.
        assert!(parse("[[materials]]\nname = \"m\"\n").textures.is_empty());
    }

    /// Writes an 8-bit PNG with `channels` channels (1 or 3) of value `v`.
    fn write_png(path: &Path, channels: u8, v: u8) {
        match channels {
            1 => image::GrayImage::from_pixel(2, 2, image::Luma([v])).save(path).unwrap(),
            _ => image::RgbImage::from_pixel(2, 2, image::Rgb([v, v, v])).save(path).unwrap(),
        }
    }

    #[test]
    fn texture_files_are_relative_to_the_scene_and_loaded_once() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("tex")).unwrap();
        write_png(&dir.path().join("tex/grey.png"), 1, 128);
        write_png(&dir.path().join("tex/rgb.png"), 3, 128);
        let text = format!(
            "{CAMERA}[[materials]]\nname = \"a\"\nalbedo_map = \"tex/grey.png\"\nnormal_map = \"tex/rgb.png\"\n\
             [[materials]]\nname = \"b\"\nalbedo_map = {{ file = \"tex/grey.png\" }}\n\
             displacement_map = {{ file = \"tex/rgb.png\", scale = 0.1 }}\n\
             [[materials]]\nname = \"c\"\ntype = \"conductor\"\nroughness_map = \"tex/grey.png\"\n\
             normal_map = \"{}\"\n",
            dir.path().join("tex/rgb.png").display().to_string().replace('\\', "\\\\")
        );
        let scene_file = dir.path().join("scene.toml");
        let s = parse_scene(&text, &scene_file.display().to_string()).unwrap_or_else(|e| panic!("{e}"));
        let maps: Vec<&MaterialMaps> = s.materials.iter().map(|m| &m.maps).collect();
        // grey as colour: 0; rgb as data: 1 (normal, displacement, and by
        // absolute path); grey as data: 2.
        assert_eq!((maps[0].albedo, maps[0].normal), (Some(0), Some(1)));
        assert_eq!((maps[1].albedo, maps[1].displacement), (Some(0), Some((1, 0.1))));
        assert_eq!((maps[2].roughness, maps[2].normal), (Some(2), Some(1)));
        assert_eq!(s.textures.len(), 3);
        assert!((s.textures[0].levels[0][0][0] - 0.215_860_5).abs() < 1e-6, "sRGB-decoded");
        assert!((s.textures[1].levels[0][0][0] - 128.0 / 255.0).abs() < 1e-6, "as stored");
        assert!((s.textures[2].levels[0][0][0] - 128.0 / 255.0).abs() < 1e-6, "as stored");
        assert!(s.textures[0].source.ends_with("grey.png"));

        // A grey image cached for a roughness map is still no normal map.
        let text = format!(
            "{CAMERA}[[materials]]\nname = \"c\"\ntype = \"conductor\"\nroughness_map = \"tex/grey.png\"\n\
             normal_map = \"tex/grey.png\"\n"
        );
        let e = parse_scene(&text, &scene_file.display().to_string()).unwrap_err().to_string();
        assert!(e.contains(":8:14: materials[0].normal_map: cannot load the normal map:"), "{e}");
        assert!(e.contains("grey.png: a normal map needs 3 colour channels (RGB) but the image has 1"), "{e}");

        // A missing file names the resolved path and the field.
        let text = format!("{CAMERA}[[materials]]\nname = \"m\"\nalbedo_map = {{ file = \"tex/nope.png\" }}\n");
        let e = parse_scene(&text, &scene_file.display().to_string()).unwrap_err().to_string();
        let missing = dir.path().join("tex/nope.png").display().to_string();
        assert!(e.contains(":6:23: materials[0].albedo_map.file: cannot load the albedo map: "), "{e}");
        assert!(e.contains(&format!("{missing}: no such file")), "{e}");
    }

    #[test]
    fn objects_are_checked_before_maps_are_loaded() {
        // An unbounded object is reported even though the material's map is
        // missing: maps (which can take seconds to load or generate) come
        // last.
        let text = format!(
            "{CAMERA}[[materials]]\nname = \"m\"\nalbedo_map = \"nope.png\"\n\
             [[objects]]\nname = \"floor\"\nmaterial = \"m\"\nplane = {{}}\n"
        );
        let e = parse_scene(&text, "t.toml").unwrap_err().to_string();
        assert!(e.contains("objects[0].plane: the plane surface is unbounded"), "{e}");
        // A bounded object: now the map is loaded, and its error reported.
        let text = text.replace("plane = {}", "plane = {}\nclip = { min = [-1, -1, -1], max = [1, 1, 1] }");
        let e = parse_scene(&text, "t.toml").unwrap_err().to_string();
        assert!(e.contains("materials[0].albedo_map: cannot load the albedo map"), "{e}");
    }

    #[test]
    fn uv_settings() {
        let s = parse(
            "[[objects]]\nsphere = { radius = 1 }\n\
             [[objects]]\nsphere = { radius = 1 }\nuv = { scale = [8, 4], offset = [0.5, -1] }\n\
             [[objects]]\nsphere = { radius = 1 }\nuv = { mapping = \"planar\", u_axis = [1, 0, 0], v_axis = [0, 0, 2], scale = [2, -2] }\n\
             [[objects]]\nsphere = { radius = 1 }\nuv = { mapping = \"cylindrical\", scale = [4, 1] }\n",
        );
        let uv: Vec<UvSettings> = s.objects.iter().map(|o| o.uv).collect();
        assert_eq!(uv[0], UvSettings::default());
        assert_eq!(uv[0], UvSettings { mapping: UvMapping::Spherical, scale: DVec2::ONE, offset: DVec2::ZERO });
        assert_eq!(
            uv[1],
            UvSettings { mapping: UvMapping::Spherical, scale: DVec2::new(8.0, 4.0), offset: DVec2::new(0.5, -1.0) }
        );
        assert_eq!(uv[2].mapping, UvMapping::Planar { u_axis: DVec3::X, v_axis: DVec3::new(0.0, 0.0, 2.0) });
        assert_eq!(uv[2].scale, DVec2::new(2.0, -2.0));
        assert_eq!((uv[3].mapping, uv[3].scale), (UvMapping::Cylindrical, DVec2::new(4.0, 1.0)));
    }

    #[test]
    fn uv_errors() {
        let err = |uv: &str| {
            let text = format!("{CAMERA}[[objects]]\nsphere = {{ radius = 1 }}\nuv = {uv}\n");
            parse_scene(&text, "t.toml").unwrap_err().to_string()
        };
        let e = err("{ mapping = \"cubic\" }");
        assert!(e.starts_with("t.toml:6:18: objects[0].uv.mapping: unknown variant `cubic`"), "{e}");
        assert!(e.contains("`planar`, `spherical`, `cylindrical`"), "{e}");
        let e = err("{ mapping = \"planar\", u_axis = [1, 0, 0] }");
        assert!(e.starts_with("t.toml:6:6: objects[0].uv.v_axis: the required key `v_axis` of a planar"), "{e}");
        let e = err("{ mapping = \"planar\", u_axis = [1, 0, 0], v_axis = [-2, 0, 0] }");
        assert!(e.starts_with("t.toml:6:57: objects[0].uv.v_axis: u_axis and v_axis are parallel"), "{e}");
        let e = err("{ mapping = \"planar\", u_axis = [0, 0, 0], v_axis = [1, 0, 0] }");
        assert!(e.starts_with("t.toml:6:37: objects[0].uv.u_axis: must not be zero"), "{e}");
        let e = err("{ u_axis = [1, 0, 0] }");
        assert!(
            e.contains("objects[0].uv.u_axis: `u_axis` does not apply to the spherical mapping (the default"),
            "{e}"
        );
        let e = err("{ mapping = \"cylindrical\", v_axis = [1, 0, 0] }");
        assert!(e.contains("objects[0].uv.v_axis: `v_axis` does not apply to the cylindrical mapping;"), "{e}");
        let e = err("{ scale = [1, 0] }");
        assert!(e.starts_with("t.toml:6:20: objects[0].uv.scale[1]: must not be zero"), "{e}");
        let e = err("{ scale = [1, 2, 3] }");
        assert!(e.contains("objects[0].uv.scale: must be an array of 2 numbers (got 3)"), "{e}");
        let e = err("{ offset = [1, 2], scael = [1, 1] }");
        assert!(e.contains("objects[0].uv.scael: unknown field `scael`"), "{e}");
    }

    #[test]
    fn map_errors() {
        let e = material_error("normal_map = { checker = { size = 4, cells = 2, colors = [0, 1] } }\n");
        assert!(e.starts_with("t.toml:6:26: materials[0].normal_map.checker: `checker` does not apply"), "{e}");
        assert!(e.contains("a normal map; it takes `file` or `bumps`"), "{e}");
        let e =
            material_error("albedo_map = { file = \"a.png\", checker = { size = 4, cells = 2, colors = [0, 1] } }\n");
        assert!(
            e.starts_with("t.toml:6:42: materials[0].albedo_map.checker: the albedo map needs exactly one of"),
            "{e}"
        );
        assert!(e.contains("found both"), "{e}");
        let e = material_error("albedo_map = {}\n");
        assert!(e.contains(
            "materials[0].albedo_map: the albedo map needs exactly one of `file` and `checker`; found neither"
        ));
        let e = material_error("albedo_map = { file = \"a.png\", scale = 2 }\n");
        assert!(e.contains("materials[0].albedo_map.scale: `scale` applies only to a displacement map"), "{e}");
        let e = material_error("displacement_map = \"h.png\"\n");
        assert!(e.starts_with("t.toml:6:20: materials[0].displacement_map: a displacement map needs a height"), "{e}");
        let e = material_error("displacement_map = { file = \"h.png\" }\n");
        assert!(e.contains("materials[0].displacement_map.scale: the required key `scale`"), "{e}");
        let e = material_error("displacement_map = { file = \"h.png\", scale = -0.1 }\n");
        assert!(e.contains("materials[0].displacement_map.scale: must be positive (got -0.1)"), "{e}");
        let e = material_error("displacement_map = { bumps = { size = 8, count = 1, strength = 2 }, scale = 1 }\n");
        assert!(e.contains("materials[0].displacement_map.bumps.strength: `strength` applies only"), "{e}");
        let e = material_error("albedo_map = { checker = { size = 100, cells = 2, colors = [0, 1] } }\n");
        assert!(e.contains("materials[0].albedo_map.checker.size: must be a power of two from 1 to 16384"), "{e}");
        let e = material_error("albedo_map = { checker = { size = 4, cells = 8, colors = [0, 1] } }\n");
        assert!(e.contains("materials[0].albedo_map.checker.cells: must be at most the texture size 4 (got 8)"));
        let e = material_error("albedo_map = { checker = { size = 4, cells = 2, colors = [0, 1, 1] } }\n");
        assert!(e.contains("materials[0].albedo_map.checker.colors: must be an array of 2 colours (got 3)"), "{e}");
        let e = material_error("albedo_map = { checker = { size = 4, cells = 2, colors = [0, [1, 2, 0]] } }\n");
        assert!(e.contains("materials[0].albedo_map.checker.colors[1][1]: must be between 0 and 1 (got 2)"), "{e}");
        let e = material_error("normal_map = { bumps = { size = 4, count = 0 } }\n");
        assert!(e.contains("materials[0].normal_map.bumps.count: must be an integer from 1 to"), "{e}");
        let e = material_error("normal_map = 3\n");
        assert!(e.contains("materials[0].normal_map: invalid type: integer `3`, expected a file path"), "{e}");
        let e = material_error("albedo_map = \"\"\n");
        assert!(e.contains("materials[0].albedo_map: the texture path must not be empty"), "{e}");
        let e = material_error("roughness_map = \"r.png\"\n");
        assert!(e.contains("materials[0].roughness_map: `roughness_map` does not apply to a diffuse material"), "{e}");
        assert!(e.contains("belongs to type = \"conductor\" or type = \"dielectric\""), "{e}");
        let e = material_error("type = \"conductor\"\nalbedo_map = \"a.png\"\n");
        assert!(e.contains("`albedo_map` does not apply to a conductor material"), "{e}");
        assert!(e.contains("belongs to type = \"diffuse\" or type = \"mirror\""), "{e}");
    }

    #[test]
    fn environment_sky_and_scale() {
        // No [environment]: none.
        assert_eq!(parse("").environment, None);
        let s = parse("[environment]\nmap = { sky = { width = 16, height = 8 } }\n");
        assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 0, scale: 1.0 }));
        assert_eq!(s.background, Vec3::ZERO);
        assert_eq!(s.textures, [procedural_sky(16, 8)]);
        // After the material maps; the scale is kept; any power-of-two sizes in range.
        let s = parse(
            "[[materials]]\nname = \"a\"\nalbedo_map = { checker = { size = 4, cells = 2, colors = [0, 1] } }\n\
             [environment]\nscale = 0.25\nmap = { sky = { width = 2, height = 1 } }\n",
        );
        assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 1, scale: 0.25 }));
        assert_eq!((s.textures[1].width, s.textures[1].height), (2, 1));
        assert_eq!(s.materials[0].maps.albedo, Some(0));
        let s = parse("[environment]\nmap = { sky = { width = 8, height = 8 } }\nscale = 0\n");
        assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 0, scale: 0.0 }));
        // The largest sky is accepted (read without generating it).
        let largest: RawSky = toml::from_str("width = 4096\nheight = 2048").unwrap();
        assert_eq!((largest.width.0, largest.height.0), (4096, 2048));
        // The inline form, before the first table.
        let s =
            parse_scene(&format!("environment = {{ map = {{ sky = {{ width = 8, height = 4 }} }} }}\n{CAMERA}"), "t")
                .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 0, scale: 1.0 }));
    }

    #[test]
    fn environment_files() {
        let dir = tempfile::tempdir().unwrap();
        std::fs::create_dir(dir.path().join("env")).unwrap();
        write_png(&dir.path().join("env/grey.png"), 1, 128);
        exr::prelude::write_rgb_file(dir.path().join("env/hdr.exr"), 4, 2, |x, _| (5.0f32, 0.5, x as f32)).unwrap();
        let scene_file = dir.path().join("scene.toml").display().to_string();
        let load = |body: &str| parse_scene(&format!("{CAMERA}{body}"), &scene_file);

        // EXR: linear, values above 1 kept; the path is relative to the scene.
        let s = load("[environment]\nmap = \"env/hdr.exr\"\nscale = 2\n").unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 0, scale: 2.0 }));
        let t = &s.textures[0];
        assert_eq!((t.width, t.height), (4, 2));
        assert_eq!(t.levels[0][3], [5.0, 0.5, 3.0, 1.0]);
        assert!(t.source.ends_with("hdr.exr"), "{}", t.source);

        // PNG: sRGB-decoded like a colour map; the table form; shared with
        // an albedo map of the same file, but not with a data map of it.
        let s = load(
            "[[materials]]\nname = \"a\"\ntype = \"conductor\"\nroughness_map = \"env/grey.png\"\n\
             [[materials]]\nname = \"b\"\nalbedo_map = \"env/grey.png\"\n\
             [environment]\nmap = { file = \"env/grey.png\" }\n",
        )
        .unwrap_or_else(|e| panic!("{e}"));
        assert_eq!(s.materials[0].maps.roughness, Some(0));
        assert_eq!(s.materials[1].maps.albedo, Some(1));
        assert_eq!(s.environment, Some(EnvironmentMapSettings { texture: 1, scale: 1.0 }));
        assert_eq!(s.textures.len(), 2);
        assert!((s.textures[1].levels[0][0][0] - 0.215_860_5).abs() < 1e-6, "sRGB-decoded");
        assert!((s.textures[0].levels[0][0][0] - 128.0 / 255.0).abs() < 1e-6, "as stored");

        // A missing file names the field, the scene's line and column and the resolved path.
        let e = load("[environment]\nmap = \"env/nope.exr\"\n").unwrap_err().to_string();
        let missing = dir.path().join("env/nope.exr").display().to_string();
        assert!(e.contains(":5:7: environment.map: cannot load the environment map: "), "{e}");
        assert!(e.contains(&format!("{missing}: no such file")), "{e}");
        let e = load("[environment]\nmap = { file = \"nope.png\" }\n").unwrap_err().to_string();
        assert!(e.contains(":5:16: environment.map.file: cannot load the environment map: "), "{e}");
    }

    #[test]
    fn environment_errors() {
        let err = |body: &str| parse_scene(&format!("{CAMERA}{body}"), "t.toml").unwrap_err().to_string();
        let sky = "map = { sky = { width = 8, height = 4 } }";

        // Both background and [environment]: at the second.
        let e = parse_scene(&format!("background = [1, 1, 1]\n{CAMERA}[environment]\n{sky}\n"), "t.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.toml:5:1: environment: give either background or [environment], not both"), "{e}");
        assert!(e.contains("(background is at line 1)") && e.contains("\n5 | [environment]\n"), "{e}");
        let e = parse_scene(&format!("environment = {{ {sky} }}\nbackground = [0, 0, 0]\n{CAMERA}"), "t.toml")
            .unwrap_err()
            .to_string();
        assert!(e.starts_with("t.toml:2:14: background: give either background or [environment], not both"), "{e}");
        assert!(e.contains("([environment] is at line 1)"), "{e}");

        let e = err("[environment]\nmap = { sky = { width = 500, height = 256 } }\n");
        assert!(e.starts_with("t.toml:5:25: environment.map.sky.width: must be a power of two from 2 to 4096"), "{e}");
        assert!(e.contains("(got 500)"), "{e}");
        let e = err("[environment]\nmap = { sky = { width = 1, height = 1 } }\n");
        assert!(e.contains("environment.map.sky.width: must be a power of two from 2 to 4096"), "{e}");
        let e = err("[environment]\nmap = { sky = { width = 8192, height = 4096 } }\n");
        assert!(e.contains("environment.map.sky.width: must be a power of two from 2 to 4096"), "{e}");
        let e = err("[environment]\nmap = { sky = { width = 8, height = 0 } }\n");
        assert!(
            e.contains("environment.map.sky.height: must be a power of two from 1 to 2048,") && e.contains("(got 0)"),
            "{e}"
        );
        let e = err("[environment]\nmap = { sky = { width = 8 } }\n");
        assert!(e.contains("environment.map.sky.height: the required key `height` is missing"), "{e}");
        let e = err(&format!("[environment]\n{sky}\nscale = -1\n"));
        assert!(e.starts_with("t.toml:6:9: environment.scale: must not be negative (got -1)"), "{e}");
        let e = err(&format!("[environment]\n{sky}\nscale = inf\n"));
        assert!(e.contains("environment.scale: must be a finite number"), "{e}");
        let e = err(&format!("[environment]\n{sky}\nexposure = 1\n"));
        assert!(e.starts_with("t.toml:6:1: environment.exposure: unknown field `exposure`"), "{e}");
        let e = err("[environment]\nmap = { sky = { width = 8, height = 4, sun = 1 } }\n");
        assert!(e.contains("environment.map.sky.sun: unknown field `sun`"), "{e}");
        let e = err("[environment]\nmap = { checker = 1 }\n");
        assert!(e.contains("environment.map.checker: unknown field `checker`, expected `file` or `sky`"), "{e}");
        let e = err("[environment]\nscale = 1\n");
        assert!(e.contains("environment.map: the required key `map` is missing"), "{e}");
        let e = err("[environment]\nmap = {}\n");
        assert!(
            e.starts_with(
                "t.toml:5:7: environment.map: the environment map needs exactly one of `file` and `sky`; found neither"
            ),
            "{e}"
        );
        let e = err("[environment]\nmap = { file = \"a.exr\", sky = { width = 8, height = 4 } }\n");
        assert!(e.starts_with("t.toml:5:31: environment.map.sky: the environment map needs exactly one"), "{e}");
        assert!(e.contains("found both"), "{e}");
        let e = err("[environment]\nmap = \"\"\n");
        assert!(e.contains("environment.map: the texture path must not be empty"), "{e}");
        let e = err("[environment]\nmap = 3\n");
        assert!(
            e.contains("environment.map: invalid type: integer `3`, expected a file path such as \"sky.exr\""),
            "{e}"
        );
        // A background written after [environment] lands in it; the message says so.
        let e = err(&format!("[environment]\n{sky}\nbackground = [0, 0, 0]\n"));
        assert!(e.contains("environment.background: unknown field") && e.contains("must come before"), "{e}");
    }

    #[test]
    fn fog_and_dielectric_media() {
        // Top-level keys come before the first [table].
        let with_fog = |fog: &str| parse_scene(&format!("{fog}\n{CAMERA}"), "t.toml");
        let s = with_fog("fog = { density = 0.2, albedo = [0.9, 0.8, 0.7], anisotropy = 0.3 }").unwrap();
        let fog = s.fog.unwrap();
        assert_eq!((fog.density, fog.albedo, fog.anisotropy), (0.2, Vec3::new(0.9, 0.8, 0.7), 0.3));
        // Defaults: no absorption, isotropic.
        let fog = with_fog("fog = { density = 1 }").unwrap().fog.unwrap();
        assert_eq!((fog.albedo, fog.anisotropy), (Vec3::ONE, 0.0));
        assert!(parse("").fog.is_none());
        let m =
            one_material("type = \"dielectric\"\nior = 1.33\nmedium = { density = 0.5, albedo = [0.4, 0.4, 0.4] }\n");
        assert_eq!(m.medium.unwrap().albedo, Vec3::splat(0.4));

        let err = |fog: &str| with_fog(fog).unwrap_err().to_string();
        let e = err("fog = { density = -1 }");
        assert!(e.contains("fog.density: must not be negative (got -1)"), "{e}");
        let e = err("fog = { density = 1, anisotropy = 1 }");
        assert!(e.contains("fog.anisotropy: must be between -0.99 and 0.99 (got 1)"), "{e}");
        let e = err("fog = { density = 1, colour = [1, 1, 1] }");
        assert!(e.contains("fog.colour: unknown field"), "{e}");
        let e = err("fog = { albedo = [1, 1, 1] }");
        assert!(e.contains("fog.density: the required key `density` is missing"), "{e}");
        let e = parse_scene(&format!("{CAMERA}[[materials]]\nname = \"m\"\nmedium = {{ density = 1 }}\n"), "t.toml")
            .unwrap_err()
            .to_string();
        assert!(e.contains("materials[0].medium") && e.contains("dielectric"), "{e}");
    }

    #[test]
    fn error_location_counts_characters() {
        let e = parse_scene("# é\n[camera]\nposition = [0, 0, 1]\nlook_at = [0, 0, 0]\nfov = 200 # é\n", "x.toml")
            .unwrap_err();
        let SceneError::Invalid { line, column, ref field, .. } = e else { panic!("{e}") };
        assert_eq!((line, column, field.as_str()), (5, 7, "camera.fov"));
        assert!(e.to_string().contains("\n5 | fov = 200 # é\n  |       ^^^"), "{e}");
    }
}
