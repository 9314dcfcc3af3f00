//! `quadray merge`: tiles and crops of one render assembled into the whole
//! frame (as pbrt-v4's `imgtool assemble`). Each tile's EXR places itself
//! (its data window inside the display window); the merge refuses tiles of
//! different renders (scene and settings hash, seed, frame, sample count),
//! tiles that stopped short of their samples, overlaps and gaps.

use std::path::PathBuf;

use crate::jobs::output::{ExrFile, METADATA_SPP, METADATA_TARGET_SPP};
use crate::passes::{PixelBounds, RenderOutput};

/// Why tiles cannot be merged.
#[derive(Debug, thiserror::Error, PartialEq, Eq)]
pub enum MergeError {
    /// Nothing to merge.
    #[error("no tiles given")]
    NoTiles,
    /// Tiles of different renders.
    #[error(
        "{other} is not a tile of the same render as {first}: {what} differs ({first_value:?} against {other_value:?})"
    )]
    Different {
        /// The first tile.
        first: PathBuf,
        /// The tile that differs.
        other: PathBuf,
        /// What differs.
        what: String,
        /// Its value in the first tile.
        first_value: String,
        /// Its value in the other tile.
        other_value: String,
    },
    /// A tile with fewer samples than its render asked for.
    #[error("{path} has {spp} of its {target} spp (an interrupted render: resume it first)")]
    Unfinished {
        /// The tile.
        path: PathBuf,
        /// Samples it has.
        spp: String,
        /// Samples asked for.
        target: String,
    },
    /// Two tiles cover the same pixel.
    #[error("{a} and {b} overlap (both cover pixel {x},{y})")]
    Overlap {
        /// One tile.
        a: PathBuf,
        /// The other.
        b: PathBuf,
        /// Column.
        x: u32,
        /// Row.
        y: u32,
    },
    /// Pixels no tile covers.
    #[error("{missing} pixels of the {width}x{height} frame are in no tile, first at {x},{y} (a missing tile?)")]
    Gap {
        /// How many pixels are missing.
        missing: usize,
        /// Frame width.
        width: u32,
        /// Frame height.
        height: u32,
        /// First missing pixel's column.
        x: u32,
        /// And row.
        y: u32,
    },
}

/// Metadata that may differ between tiles (a farm's nodes may have other
/// devices and drivers; each tile is denoised alone, and dropped); the
/// device and driver are kept in the merged frame where all agree.
const PER_TILE: [&str; 3] = [
    crate::jobs::output::METADATA_DEVICE,
    crate::jobs::output::METADATA_DRIVER,
    crate::jobs::output::METADATA_DENOISED,
];

fn value<'a>(metadata: &'a [(String, String)], name: &str) -> Option<&'a str> {
    metadata.iter().find(|(k, _)| k == name).map(|(_, v)| v.as_str())
}

/// Assembles `tiles` (path, file) into the whole frame; returns the image
/// and the tiles' common metadata. Radiance and the AOVs are copied bit for
/// bit; an AOV is kept only where every tile has it.
pub fn merge(tiles: &[(PathBuf, ExrFile)]) -> Result<(RenderOutput, Vec<(String, String)>), MergeError> {
    let (first_path, first) = tiles.first().ok_or(MergeError::NoTiles)?;
    let (width, height) = first.output.frame_size;
    for (path, tile) in tiles {
        let differs = |what: &str, a: String, b: String| MergeError::Different {
            first: first_path.clone(),
            other: path.clone(),
            what: what.into(),
            first_value: a,
            other_value: b,
        };
        if tile.output.frame_size != first.output.frame_size {
            let size = |s: (u32, u32)| format!("{}x{}", s.0, s.1);
            return Err(differs("the frame size", size(first.output.frame_size), size(tile.output.frame_size)));
        }
        let names: std::collections::BTreeSet<&str> =
            first.metadata.iter().chain(&tile.metadata).map(|(k, _)| k.as_str()).collect();
        for name in names.into_iter().filter(|n| !PER_TILE.contains(n)) {
            let (a, b) = (value(&first.metadata, name), value(&tile.metadata, name));
            if a != b {
                let show = |v: Option<&str>| v.unwrap_or("(none)").to_string();
                return Err(differs(name, show(a), show(b)));
            }
        }
        let (spp, target) = (value(&tile.metadata, METADATA_SPP), value(&tile.metadata, METADATA_TARGET_SPP));
        if spp != target || tile.output.partial_tiles > 0 {
            return Err(MergeError::Unfinished {
                path: path.clone(),
                spp: spp.unwrap_or("?").into(),
                target: target.unwrap_or("?").into(),
            });
        }
    }
    // Which tile covers each pixel: overlaps and gaps.
    let mut owner = vec![usize::MAX; width as usize * height as usize];
    for (i, (path, tile)) in tiles.iter().enumerate() {
        let b = tile.output.bounds;
        for y in b.y0..b.y1 {
            for x in b.x0..b.x1 {
                let o = &mut owner[(y * width + x) as usize];
                if *o != usize::MAX {
                    return Err(MergeError::Overlap { a: tiles[*o].0.clone(), b: path.clone(), x, y });
                }
                *o = i;
            }
        }
    }
    let missing = owner.iter().filter(|&&o| o == usize::MAX).count();
    if let Some(at) = owner.iter().position(|&o| o == usize::MAX) {
        return Err(MergeError::Gap { missing, width, height, x: at as u32 % width, y: at as u32 / width });
    }
    let pixels = width as usize * height as usize;
    let mut out = RenderOutput::from_radiance(width, height, vec![[0.0; 3]; pixels]);
    let full = PixelBounds::full(width, height);
    out.bounds = full;
    out.frame_size = (width, height);
    out.spp = first.output.spp;
    let all_aov = tiles.iter().all(|(_, t)| !t.output.aov.is_empty());
    let all_max = tiles.iter().all(|(_, t)| !t.output.max_sample.is_empty());
    if all_aov {
        out.aov = vec![Default::default(); pixels];
    }
    if all_max {
        out.max_sample = vec![[0.0; 2]; pixels];
    }
    for (_, tile) in tiles {
        let b = tile.output.bounds;
        b.insert(&tile.output.radiance, &mut out.radiance, width);
        if all_aov {
            b.insert(&tile.output.aov, &mut out.aov, width);
        }
        if all_max {
            b.insert(&tile.output.max_sample, &mut out.max_sample, width);
        }
    }
    // The merged frame is the tiles' raw radiance: a tile denoised alone
    // would show its edges (`quadray denoise` of the merged frame denoises
    // it whole).
    // The device and driver are kept where every tile names the same.
    let same_everywhere = |k: &str| tiles.iter().all(|(_, t)| value(&t.metadata, k) == value(&first.metadata, k));
    let metadata = first
        .metadata
        .iter()
        .filter(|(k, _)| k != crate::jobs::output::METADATA_DENOISED)
        .filter(|(k, _)| !PER_TILE.contains(&k.as_str()) || same_everywhere(k))
        .cloned()
        .collect();
    Ok((out, metadata))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tile(bounds: PixelBounds, key: &str, spp: &str) -> (PathBuf, ExrFile) {
        let mut output = RenderOutput::from_radiance(
            bounds.width(),
            bounds.height(),
            (0..bounds.pixels()).map(|i| [i as f32, bounds.y0 as f32, 0.0]).collect(),
        );
        output.bounds = bounds;
        output.frame_size = (4, 6);
        let metadata = vec![
            ("quadray.scene_key".into(), key.into()),
            (METADATA_SPP.into(), spp.into()),
            (METADATA_TARGET_SPP.into(), "8".into()),
        ];
        (PathBuf::from(format!("t{}.exr", bounds.y0)), ExrFile { output, metadata })
    }

    fn band(i: u32, key: &str) -> (PathBuf, ExrFile) {
        tile(PixelBounds::tile(i, 3, 4, 6).unwrap(), key, "8")
    }

    #[test]
    fn merges_bands_into_the_frame() {
        let (out, _) = merge(&[band(2, "k"), band(0, "k"), band(1, "k")]).unwrap();
        assert_eq!((out.width, out.height), (4, 6));
        // Pixel (1, 3) is pixel 5 of band 1 (rows 2..4).
        assert_eq!(out.radiance[3 * 4 + 1], [5.0, 2.0, 0.0]);
    }

    #[test]
    fn refuses_gaps_overlaps_and_other_renders() {
        assert!(matches!(merge(&[band(0, "k"), band(2, "k")]), Err(MergeError::Gap { missing: 8, .. })));
        assert!(matches!(merge(&[band(0, "k"), band(1, "k"), band(1, "k")]), Err(MergeError::Overlap { .. })));
        assert!(matches!(merge(&[band(0, "k"), band(1, "j"), band(2, "k")]), Err(MergeError::Different { .. })));
        let short = tile(PixelBounds::tile(1, 3, 4, 6).unwrap(), "k", "5");
        assert!(matches!(merge(&[band(0, "k"), short, band(2, "k")]), Err(MergeError::Different { .. })));
        let mut unfinished = [band(0, "k"), band(1, "k"), band(2, "k")];
        for (_, t) in &mut unfinished {
            t.metadata[1].1 = "5".into();
        }
        assert!(matches!(merge(&unfinished), Err(MergeError::Unfinished { .. })));
        assert_eq!(merge(&[]).err(), Some(MergeError::NoTiles));
    }
}
