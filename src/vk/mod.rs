//! The Vulkan backend: one concept a file, each object owning its cleanup.
//!
//! `Context` is the entry point: instance (with validation when asked) and a
//! device with ray queries, created headless.

mod accel;
mod buffer;
mod capabilities;
mod commands;
mod device;
mod image;
mod instance;
mod naming;
mod pipeline;
pub mod reflect;
mod rt_pipeline;
pub mod runtime;
mod sampler;
#[cfg(feature = "viewer")]
mod surface;
#[cfg(feature = "viewer")]
mod swapchain;
mod sync;
mod timestamps;

use std::sync::Arc;

pub use accel::{AccelerationStructure, Instance as AsInstance};
pub use ash::vk;
pub use buffer::Buffer;
pub use capabilities::{preference, survey, Backend, Capabilities, PipelineLimits, Survey};
pub use commands::Commands;
pub use device::{Device, RayTracing};
pub use gpu_allocator::MemoryLocation;
pub use image::Image;
pub use instance::{Instance, ValidationCounters, SETUP_HINT};
pub use pipeline::{Binding, ComputePipeline, PipelineResources};
pub use reflect::BindingKind;
pub use rt_pipeline::{RayTracingPipeline, RayTracingStages};
pub use sampler::Sampler;
#[cfg(feature = "viewer")]
pub use surface::{surface_extensions, Surface};
#[cfg(feature = "viewer")]
pub use swapchain::{PresentResult, Swapchain};
pub use sync::{Access, Dependency, Recording, ShaderStage};
pub use timestamps::{GpuTimer, Timestamps};

/// Errors from the Vulkan backend.
#[derive(Debug, thiserror::Error)]
pub enum VkError {
    /// The Vulkan loader library could not be loaded.
    #[error("cannot load the Vulkan loader (libvulkan.so.1): {0}. To fix: {SETUP_HINT}")]
    Loader(String),
    /// Validation was asked for but the layer is not installed.
    #[error("the Khronos validation layer is not installed (package vulkan-validationlayers). To fix: {SETUP_HINT}")]
    MissingValidationLayer,
    /// No device has what the renderer needs.
    #[error("no Vulkan device can trace rays (ray queries or ray-tracing pipelines); {0}")]
    NoSuitableDevice(String),
    /// A pass asked for a backend the device was not created with.
    #[error("{device} was not created with the {backend} backend (`quadray devices` lists what each device offers)")]
    BackendUnavailable {
        /// The device's name.
        device: String,
        /// The backend asked for.
        backend: Backend,
    },
    /// Memory allocation failed.
    #[error("GPU memory allocation failed: {0}")]
    Allocation(String),
    /// A Vulkan call failed.
    #[error("Vulkan call failed: {0}")]
    Vk(#[from] vk::Result),
    /// The host and a shader disagree on their interface.
    #[error("the host and a shader disagree on their interface")]
    Interface(#[from] reflect::InterfaceError),
}

/// An instance and a device, ready for work.
pub struct Context {
    /// The device (holds the instance).
    pub device: Arc<Device>,
    counters: Arc<ValidationCounters>,
}

impl Context {
    /// Creates a headless context. `validation` turns on the Khronos layer.
    pub fn new(validation: bool) -> Result<Self, VkError> {
        let instance = Arc::new(Instance::new(validation)?);
        let counters = instance.counters();
        let device = Device::new(instance)?;
        Ok(Self { device, counters })
    }

    /// Validation message counters; they stay readable after the context
    /// is dropped, when the layer reports leaked objects.
    pub fn counters(&self) -> Arc<ValidationCounters> {
        self.counters.clone()
    }
}
