//! Texture maps and the environment named in a scene: loaded from files or
//! generated (procedural maps, the sky), cached by description.

use std::ops::Range;
use std::path::{Path, PathBuf};

use toml::Spanned;

use super::{EnvironmentMapSettings, MaterialMaps, TextureImage};
use crate::model::texture::environment::procedural_sky;
use crate::model::texture::{self, TextureKind, TextureUsage};

use super::*;

/// The scene's textures, each loaded or generated once: identical specs
/// (the same resolved path, or the same generator and parameters) read the
/// same way share one entry.
#[derive(Default)]
pub(super) struct TextureCache {
    pub(super) images: Vec<TextureImage>,
    /// Per image: its key, how it was read, and its colour channels.
    pub(super) keys: Vec<(String, TextureUsage, u32)>,
}

/// Where a map's texels come from: a file, or a generator (`Sky` is the
/// environment's [`procedural_sky`]).
pub(super) enum MapSource {
    File { path: PathBuf },
    Checker { size: u32, cells: u32, colors: [[f32; 3]; 2] },
    Heights { size: u32, count: u32, seed: u32 },
    Normals { size: u32, count: u32, seed: u32, strength: f32 },
    Sky { width: u32, height: u32 },
}

impl MapSource {
    /// The dedupe key: equal keys give equal textures.
    pub(super) fn key(&self) -> String {
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
    pub(super) fn get(&mut self, source: &MapSource, kind: TextureKind) -> Result<usize, texture::TextureError> {
        self.get_as(source, kind.usage(), |path, channels| kind.check_channels(path, channels))
    }

    /// The index of the texture for `source` read as `usage`, loading or
    /// generating it on first use; `check` vets a file's colour channels.
    pub(super) fn get_as(
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
pub(super) fn build_maps(
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
pub(super) fn with_article(noun: &str) -> String {
    let article = if noun.starts_with(['a', 'e', 'i', 'o', 'u']) { "an" } else { "a" };
    format!("{article} {noun}")
}

/// One texture map at `field` (e.g. `materials[2].albedo_map`): its texture
/// index, and the height scale of a displacement map.
pub(super) fn build_map(
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
pub(super) fn build_environment(
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
