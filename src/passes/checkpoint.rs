//! Checkpoints of a long render (`quadray render --checkpoint`): the
//! accumulation so far, written atomically, from which `--resume` goes on
//! to an image bit-identical to an uninterrupted render's (as RenderMan's
//! `-checkpoint`/`-recover`).
//!
//! A render's result is a function of its scene and settings, and each
//! sample of each pixel has its own random numbers, so the accumulation
//! (the f32 sums in the order they were added, the finite-sample counts,
//! the largest samples, the AOVs) and the place the render stopped (the
//! sample and the tile within it) are all the state there is. The caustic
//! and volume passes are deterministic (their splats add in fixed point)
//! and are run again on resume.
//!
//! File layout, little-endian: the magic `QRAYCKP1`; the key (u64, a hash
//! of the scene and the settings); the target spp, the frame width and
//! height, the bounds (x0, x1, y0, y1), the samples done and the tiles of
//! the next sample done (u32 each); the GPU seconds so far (f64); a
//! description of the render (u32 length, UTF-8); the sums (4 f32 a
//! pixel), the largest samples (2 f32) and the AOVs (`GpuAov`), pixel by
//! pixel over the bounds; then FNV-1a of everything before it (u64), so that
//! a truncated or damaged file is refused rather than resumed.

use std::path::{Path, PathBuf};

use super::film::{Accumulation, PixelBounds};
use super::gpu::GpuAov;
use crate::util::hash::Fnv1a;

const MAGIC: &[u8; 8] = b"QRAYCKP2";

/// A checkpoint file's contents.
#[derive(Clone, Debug, PartialEq)]
pub struct Checkpoint {
    /// Hash of the scene and every setting that changes the image
    /// ([`render_key`]); resuming needs the same.
    pub key: u64,
    /// The samples per pixel the render is for.
    pub target_spp: u32,
    /// What was rendered, for messages (scene, size, spp).
    pub description: String,
    /// The work so far.
    pub accumulation: Accumulation,
}

/// Why a checkpoint cannot be read or used.
#[derive(Debug, thiserror::Error)]
pub enum CheckpointError {
    /// The file cannot be read or written.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// What failed.
        source: std::io::Error,
    },
    /// Not a quadray checkpoint, or a damaged one.
    #[error("{path} is not a quadray checkpoint or is damaged ({why})")]
    Damaged {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        why: &'static str,
    },
    /// A checkpoint of another scene or other settings.
    #[error(
        "{path} is a checkpoint of another render ({found}); this render is {expected}. Resume with the scene \
         file and the flags it was started with, or start afresh without --resume"
    )]
    OtherRender {
        /// The file.
        path: PathBuf,
        /// The checkpoint's description.
        found: String,
        /// This render's description.
        expected: String,
    },
}

/// The version of the key's serialisation: bumped when a change to the
/// scene model or the variant changes the image an unchanged scene file
/// makes (old checkpoints must then not resume), never by a change that
/// leaves the image alone.
pub const KEY_VERSION: u32 = 1;

/// A hash of everything that makes a render's image: the scene (objects,
/// materials, lights, camera, image and quality settings, the seed) and
/// `settings` (the caller's other switches, e.g. the render variant),
/// through a stable serialisation (serde's JSON of their fields, in
/// declaration order; no `Debug` form, no hash-map order), after the key
/// version, streamed (FNV-1a).
pub fn render_key(scene: &impl serde::Serialize, settings: &impl serde::Serialize) -> u64 {
    use std::io::Write as _;
    let mut h = Fnv1a::default();
    write!(h, "quadray render key v{KEY_VERSION}\u{0}").expect("hashing cannot fail");
    serde_json::to_writer(&mut h, scene).expect("the scene serialises");
    h.write_all(&[0]).expect("hashing cannot fail");
    serde_json::to_writer(&mut h, settings).expect("the settings serialise");
    h.finish()
}

impl Checkpoint {
    /// The file's bytes (see the module documentation).
    pub fn to_bytes(&self) -> Vec<u8> {
        let a = &self.accumulation;
        let mut b = Vec::with_capacity(64 + a.sums.len() * (24 + std::mem::size_of::<GpuAov>()));
        b.extend_from_slice(MAGIC);
        b.extend_from_slice(&self.key.to_le_bytes());
        let words = [
            self.target_spp,
            a.frame_size.0,
            a.frame_size.1,
            a.bounds.x0,
            a.bounds.x1,
            a.bounds.y0,
            a.bounds.y1,
            a.samples,
            a.partial_tiles,
        ];
        words.iter().for_each(|w| b.extend_from_slice(&w.to_le_bytes()));
        b.extend_from_slice(&a.render_seconds.to_le_bytes());
        b.extend_from_slice(&(self.description.len() as u32).to_le_bytes());
        b.extend_from_slice(self.description.as_bytes());
        b.extend_from_slice(bytemuck::cast_slice(&a.sums));
        b.extend_from_slice(bytemuck::cast_slice(&a.max_sample));
        b.extend_from_slice(bytemuck::cast_slice(&a.aov));
        let sum = Fnv1a::of(&b);
        b.extend_from_slice(&sum.to_le_bytes());
        b
    }

    /// Parses a file's bytes; `path` names it in errors.
    pub fn from_bytes(bytes: &[u8], path: &Path) -> Result<Self, CheckpointError> {
        let damaged = |why| CheckpointError::Damaged { path: path.into(), why };
        if bytes.starts_with(b"QRAYCKP1") {
            return Err(damaged("an older checkpoint format (1, before the denoiser's features): render afresh"));
        }
        if bytes.len() < MAGIC.len() || &bytes[..MAGIC.len()] != MAGIC {
            return Err(damaged("no checkpoint header"));
        }
        let (body, sum) = bytes.split_at(bytes.len().checked_sub(8).ok_or_else(|| damaged("truncated"))?);
        if Fnv1a::of(body).to_le_bytes() != sum {
            return Err(damaged("checksum mismatch: truncated or changed"));
        }
        let mut at = MAGIC.len();
        let mut take = |n: usize| -> Result<&[u8], CheckpointError> {
            let part = body.get(at..at + n).ok_or_else(|| damaged("truncated"))?;
            at += n;
            Ok(part)
        };
        let key = u64::from_le_bytes(take(8)?.try_into().expect("8 bytes"));
        let mut w = [0u32; 9];
        for v in &mut w {
            *v = u32::from_le_bytes(take(4)?.try_into().expect("4 bytes"));
        }
        let [target_spp, fw, fh, x0, x1, y0, y1, samples, partial_tiles] = w;
        let render_seconds = f64::from_le_bytes(take(8)?.try_into().expect("8 bytes"));
        let len = u32::from_le_bytes(take(4)?.try_into().expect("4 bytes")) as usize;
        let description = String::from_utf8(take(len)?.to_vec()).map_err(|_| damaged("description not UTF-8"))?;
        let bounds = PixelBounds { x0, x1, y0, y1 };
        let bounds = bounds.check(fw, fh).map_err(|_| damaged("bounds outside the frame"))?;
        let n = bounds.pixels();
        let sums = bytemuck::pod_collect_to_vec(take(n * 16)?);
        let max_sample = bytemuck::pod_collect_to_vec(take(n * 8)?);
        let aov = bytemuck::pod_collect_to_vec(take(n * std::mem::size_of::<GpuAov>())?);
        if at != body.len() {
            return Err(damaged("trailing bytes"));
        }
        Ok(Self {
            key,
            target_spp,
            description,
            accumulation: Accumulation {
                frame_size: (fw, fh),
                bounds,
                samples,
                partial_tiles,
                render_seconds,
                sums,
                max_sample,
                aov,
            },
        })
    }

    /// Writes the checkpoint atomically (a temporary file renamed into
    /// place): a render killed while writing leaves the previous one.
    pub fn write(&self, path: &Path) -> Result<(), CheckpointError> {
        let bytes = self.to_bytes();
        crate::util::files::write_file_atomically(path, &bytes)
            .map_err(|source| CheckpointError::Io { path: path.into(), source })
    }

    /// Reads a checkpoint.
    pub fn read(path: &Path) -> Result<Self, CheckpointError> {
        let bytes = std::fs::read(path).map_err(|source| CheckpointError::Io { path: path.into(), source })?;
        Self::from_bytes(&bytes, path)
    }

    /// Reads a checkpoint and checks that it is one of the render with
    /// `key` (see [`render_key`]), described as `description` in the error.
    pub fn read_for(path: &Path, key: u64, description: &str) -> Result<Self, CheckpointError> {
        let c = Self::read(path)?;
        if c.key != key {
            return Err(CheckpointError::OtherRender {
                path: path.into(),
                found: c.description,
                expected: description.into(),
            });
        }
        Ok(c)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sample() -> Checkpoint {
        let bounds = PixelBounds { x0: 1, x1: 3, y0: 0, y1: 2 };
        let aov = GpuAov {
            depth: 2.5,
            normal: [0.0, 1.0, 0.0],
            albedo: [0.5, 0.25, 0.125],
            object: 3,
            denoise_albedo: [1.0, 0.5, 0.25],
            denoise_normal: [0.0, 2.0, 0.0],
        };
        Checkpoint {
            key: 0x1234_5678_9abc_def0,
            target_spp: 64,
            description: "scene.toml 4x2 64 spp".into(),
            accumulation: Accumulation {
                frame_size: (4, 2),
                bounds,
                samples: 7,
                partial_tiles: 0,
                render_seconds: 1.5,
                sums: (0..4).map(|i| [i as f32, 1.0, 2.0, 7.0]).collect(),
                max_sample: vec![[3.0, 2.0]; 4],
                aov: vec![aov; 4],
            },
        }
    }

    #[test]
    fn round_trips_and_refuses_damage() {
        let c = sample();
        let bytes = c.to_bytes();
        let path = Path::new("test.ckpt");
        assert_eq!(Checkpoint::from_bytes(&bytes, path).unwrap(), c);
        for cut in [0, 7, 30, bytes.len() - 1] {
            assert!(Checkpoint::from_bytes(&bytes[..cut], path).is_err(), "truncated at {cut}");
        }
        let mut flipped = bytes.clone();
        flipped[40] ^= 1;
        assert!(matches!(Checkpoint::from_bytes(&flipped, path), Err(CheckpointError::Damaged { .. })));
    }

    #[test]
    fn keys_differ_with_any_setting() {
        assert_eq!(render_key(&("a", 1), &2), render_key(&("a", 1), &2));
        assert_ne!(render_key(&("a", 1), &2), render_key(&("a", 2), &2));
        assert_ne!(render_key(&("a", 1), &2), render_key(&("a", 1), &3));
    }

    #[test]
    fn output_divides_by_each_pixels_count() {
        let out = sample().accumulation.into_output(&[7, 8, 7, 0]);
        assert_eq!(out.radiance[1], [1.0 / 8.0, 1.0 / 8.0, 2.0 / 8.0]);
        assert_eq!(out.radiance[3], [3.0, 1.0, 2.0]);
        // 8 samples, 7 finite: one dropped.
        assert_eq!(out.dropped_samples, 1);
        assert_eq!((out.width, out.height), (2, 2));
        // The denoiser's features too (sums over the samples); the
        // pixel-centre AOVs are kept as they are.
        assert_eq!(
            (out.aov[1].denoise_albedo, out.aov[1].denoise_normal),
            ([0.125, 0.0625, 0.03125], [0.0, 0.25, 0.0])
        );
        assert_eq!((out.aov[1].albedo, out.aov[1].depth), ([0.5, 0.25, 0.125], 2.5));
    }

    #[test]
    fn an_older_format_is_named() {
        let e = Checkpoint::from_bytes(b"QRAYCKP1 and the rest", Path::new("old.ckpt")).unwrap_err().to_string();
        assert!(e.contains("an older checkpoint format"), "{e}");
    }
}
