//! Sampling routines: chi-square tests of every sampler (CPU and GPU) and GPU-vs-CPU twins.
//!
//! One test binary per theme (each module was a binary of its own), so the
//! suite links a few executables instead of thirty.

#[path = "../common/mod.rs"]
mod common;

mod dielectric_chi2;
mod envmap_chi2;
mod phase_chi2;
mod sampling_chi2;
mod sampling_gpu;
