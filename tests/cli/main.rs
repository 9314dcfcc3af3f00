//! The `quadray` program as a user runs it: commands, long renders (signals, checkpoints, tiles, frames), Slurm farms and the viewer.
//!
//! One test binary per theme (each module was a binary of its own), so the
//! suite links a few executables instead of thirty.

#[path = "../common/mod.rs"]
mod common;

mod commands;
mod export;
mod farm_slurm;
mod long_renders;
mod runtime;
mod viewer;
