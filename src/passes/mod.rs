//! GPU passes, one a file: the scene upload, the render pass and the probe
//! pass used by tests and benchmarks.

pub mod gpu;
pub mod probe;
pub mod render;
pub mod scene_gpu;

pub use probe::ProbePass;
pub use render::{render, RenderOutput, RenderVariant};
pub use scene_gpu::{GeometryStats, GpuScene};
