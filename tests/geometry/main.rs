//! The exact geometry on the GPU: first roots against f64 CPU twins, offsets, root multiplicity, the stress suite and covariance tracing.
//!
//! One test binary per theme (each module was a binary of its own), so the
//! suite links a few executables instead of thirty.

#[path = "../common/mod.rs"]
mod common;

mod covariance;
mod far_views;
mod geometry_gpu;
mod offsets;
mod parallel_rays;
mod root_multiplicity;
mod stress_geometry;
