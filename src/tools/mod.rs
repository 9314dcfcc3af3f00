//! Measuring tools beside the renderer: benchmarks of perturbations and
//! presets, throughput of whole processes, texture-filter benchmarks, image
//! metrics (FLIP, relative MSE) and plots.

pub mod bench;
pub mod filter_bench;
pub mod metrics;
pub mod plot;
pub mod throughput;
