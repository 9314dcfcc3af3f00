//! Rendered images against analytic values, references and brute force: furnaces, lights, media, caustics, volumes, filtering, textures, convergence and energy.
//!
//! One test binary per theme (each module was a binary of its own), so the
//! suite links a few executables instead of thirty.

#[path = "../common/mod.rs"]
mod common;

mod backends;
mod caustics;
mod convergence;
mod denoise;
mod energy;
mod filtering;
mod footprint;
mod furnace;
mod kernels;
mod lights;
mod loop_budget;
mod media;
mod nested;
mod sync;
mod texfilter_gpu;
mod textures_gpu;
mod transport_extremes;
mod volume;
