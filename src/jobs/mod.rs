//! Long renders and their files: progressive jobs with checkpoints,
//! signals, tiles and frames; PNG and EXR output with metadata; merging
//! tiles; Slurm farms; denoising with Intel Open Image Denoise.

pub mod denoise;
pub mod farm;
pub mod job;
pub mod merge;
pub mod output;
