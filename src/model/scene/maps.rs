//! What a scene's textures are to the renderer: which hold colour and which
//! data (that decides their GPU encoding), and the maps derived from them
//! for filtering (LEAN slope moments of normal and displacement maps). CPU
//! work on the scene's assets, done before the upload.

use std::collections::HashMap;

use super::Scene;
use crate::model::texture::encoding::MapContent;
use crate::model::texture::{lean, TextureImage};

/// What each texture of the scene holds: colour if every use of it is as an
/// albedo map or the environment (both sRGB-decoded when read from PNG or
/// JPEG), data otherwise.
pub fn map_contents(scene: &Scene) -> Vec<MapContent> {
    let mut color = vec![false; scene.textures.len()];
    let mut data = vec![false; scene.textures.len()];
    for m in &scene.materials {
        if let Some(i) = m.maps.albedo {
            color[i] = true;
        }
        for i in [m.maps.normal, m.maps.roughness, m.maps.displacement.map(|(i, _)| i)].into_iter().flatten() {
            data[i] = true;
        }
    }
    if let Some(e) = scene.environment {
        color[e.texture] = true;
    }
    color.iter().zip(&data).map(|(&c, &d)| if c && !d { MapContent::Color } else { MapContent::Data }).collect()
}

/// The slope-moment maps of a scene (LEAN filtering, `lean`): one per
/// distinct normal or displacement map, numbered after the scene's own
/// textures, and for each material the index of its normal map's and its
/// displacement map's moments.
#[derive(Clone, Debug, Default, serde::Serialize)]
pub struct SlopeMoments {
    /// The derived maps, texture `scene.textures.len() + i` for the i-th.
    pub textures: Vec<TextureImage>,
    /// Per material: the texture index of its normal map's moments.
    pub normal: Vec<Option<usize>>,
    /// Per material: the texture index of its displacement map's moments.
    pub displacement: Vec<Option<usize>>,
}

/// Derives the slope moments of every normal and displacement map `scene`
/// uses, once per map.
pub fn slope_moments(scene: &Scene) -> SlopeMoments {
    let mut out = SlopeMoments::default();
    let mut index_of: HashMap<(bool, usize), usize> = HashMap::new();
    let mut moments_of = |textures: &mut Vec<TextureImage>, is_normal: bool, map: usize| {
        *index_of.entry((is_normal, map)).or_insert_with(|| {
            let t = &scene.textures[map];
            textures.push(if is_normal { lean::normal_slope_moments(t) } else { lean::height_slope_moments(t) });
            scene.textures.len() + textures.len() - 1
        })
    };
    for m in &scene.materials {
        let normal = m.maps.normal.map(|map| moments_of(&mut out.textures, true, map));
        let displacement = m.maps.displacement.map(|(map, _)| moments_of(&mut out.textures, false, map));
        out.normal.push(normal);
        out.displacement.push(displacement);
    }
    out
}
