//! Scene files and assets: parse errors with file and line, the parser fuzz corpus, textures and their extremes, and the host/shader interface.
//!
//! One test binary per theme (each module was a binary of its own), so the
//! suite links a few executables instead of thirty.

#[path = "../common/mod.rs"]
mod common;

mod docs;
mod interface;
mod layers;
mod parser_fuzz;
mod scene_errors;
mod texture_extremes;
mod textures;
