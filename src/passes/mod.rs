//! GPU passes, one a file: the scene upload, the render pass, and the probe
//! passes (rays, texture lookups) used by tests and benchmarks.

pub mod caustics;
pub mod checkpoint;
pub mod config;
pub mod error;
pub mod film;
pub mod gpu;
pub mod outliers;
pub mod probe;
pub mod render;
pub mod scene_gpu;
pub mod testing;
pub mod tracer;
pub mod variant;
pub mod volume;
pub mod wavefront;

pub use caustics::{CausticMap, CausticReport};
pub use checkpoint::Checkpoint;
pub use config::{filter_constant, RenderConfig};
pub use error::RenderError;
pub use film::{Accumulation, PixelBounds, RenderOutput, TileIndex};
pub use probe::ProbePass;
pub use render::{render, RecordedPath, Renderer};
pub use scene_gpu::{GeometryStats, GpuScene, LoopBudget, LOOP_LIMIT};
pub use testing::texprobe::TexProbePass;
pub use tracer::Tracer;
pub use variant::{IntersectMode, LookupMode, PathKernel, RenderVariant, SamplerMode, ShadingMode};
pub use volume::VolumeLight;
