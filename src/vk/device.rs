//! Physical-device choice and the logical device, with its queue, memory
//! allocator and the ray-query extensions.

use std::ffi::CStr;
use std::mem::ManuallyDrop;
use std::sync::{Arc, Mutex};

use ash::vk;
use gpu_allocator::vulkan::{Allocator, AllocatorCreateDesc};

use super::capabilities::{preference, Capabilities, PipelineLimits};
use super::{Instance, VkError, SETUP_HINT};

/// The device extensions the renderer cannot work without; it also needs
/// ray queries or ray-tracing pipelines (or both), enabled where offered.
const REQUIRED_EXTENSIONS: [&CStr; 2] =
    [ash::khr::acceleration_structure::NAME, ash::khr::deferred_host_operations::NAME];

/// A logical device with one compute queue and a memory allocator.
// Release order: `Drop::drop` waits for idle, drops the `ManuallyDrop` allocator and destroys the device, all
// before any field drops; `instance` (an Arc) is therefore released only after the device is gone.
pub struct Device {
    /// The instance (kept alive as long as the device).
    pub instance: Arc<Instance>,
    /// The physical device.
    pub physical: vk::PhysicalDevice,
    /// The logical device.
    pub raw: ash::Device,
    /// Queue family of [`Device::queue`].
    pub queue_family: u32,
    /// A queue with compute support.
    pub queue: vk::Queue,
    /// VK_KHR_acceleration_structure entry points.
    pub accel: ash::khr::acceleration_structure::Device,
    /// Device properties.
    pub properties: vk::PhysicalDeviceProperties,
    /// Acceleration-structure limits.
    pub accel_properties: AccelProperties,
    /// The largest single memory allocation the device promises
    /// (`maxMemoryAllocationSize`, Vulkan 1.1): 2 GiB on lavapipe.
    pub max_allocation_bytes: u64,
    /// Device name, for messages.
    pub name: String,
    /// The driver's name and version (`VkPhysicalDeviceDriverProperties`:
    /// "llvmpipe: Mesa 26.2.6-1 (LLVM 22.1.8)" on lavapipe).
    pub driver: String,
    /// Ray-tracing pipelines, when the device offers them (enabled then,
    /// for the pipeline backend).
    pub ray_tracing: Option<RayTracing>,
    /// Whether ray queries are enabled (the `ray-query` backend).
    pub ray_query: bool,
    /// The memory allocator (dropped before the device).
    pub allocator: ManuallyDrop<Mutex<Allocator>>,
}

/// VK_KHR_ray_tracing_pipeline on a device: its entry points and limits.
pub struct RayTracing {
    /// The entry points.
    pub loader: ash::khr::ray_tracing_pipeline::Device,
    /// The limits a shader binding table is laid out by.
    pub limits: PipelineLimits,
}

/// The acceleration-structure limits the renderer uses.
#[derive(Clone, Copy, Debug)]
pub struct AccelProperties {
    /// Alignment of scratch buffer addresses.
    pub min_scratch_offset_alignment: u32,
}

/// What one physical device lacks to present to `surface` from its first
/// compute queue family (the one [`Device`] uses).
#[cfg(feature = "viewer")]
fn surface_shortcomings(instance: &ash::Instance, pd: vk::PhysicalDevice, surface: &super::Surface) -> Vec<String> {
    let mut missing = Vec::new();
    // SAFETY: `pd` was enumerated from `instance` by `Device::select`, and `instance` is borrowed alive for
    // the call; ash sizes the returned Vec from the reported count.
    let exts = unsafe { instance.enumerate_device_extension_properties(pd) }.unwrap_or_default();
    if !exts.iter().any(|e| e.extension_name_as_c_str().map(|n| n == ash::khr::swapchain::NAME).unwrap_or(false)) {
        missing.push("VK_KHR_swapchain".to_string());
    }
    // SAFETY: as above, `pd` is a physical device of the live `instance`.
    let family = unsafe { instance.get_physical_device_queue_family_properties(pd) }
        .iter()
        .position(|q| q.queue_flags.contains(vk::QueueFlags::COMPUTE));
    let presents = family.is_some_and(|f| surface.supports_presenting(pd, f as u32));
    if !presents {
        missing.push("presenting to the window from its compute queue".to_string());
    }
    missing
}

fn device_name(props: &vk::PhysicalDeviceProperties) -> String {
    props.device_name_as_c_str().map(|c| c.to_string_lossy().into_owned()).unwrap_or_else(|_| "?".into())
}

impl Device {
    /// Picks the first physical device with ray queries or ray-tracing
    /// pipelines (preferring discrete GPUs, then integrated, then software)
    /// and creates a logical device with what it offers of both.
    /// When none fits, the error lists every device seen and what it lacks.
    pub fn new(instance: Arc<Instance>) -> Result<Arc<Self>, VkError> {
        Self::select(instance, &|_, _| Vec::new(), false)
    }

    /// [`Device::new`] for presenting to `surface`: the device must also
    /// support the swapchain extension and presenting to the surface from
    /// its compute queue.
    #[cfg(feature = "viewer")]
    pub fn for_surface(instance: Arc<Instance>, surface: &super::Surface) -> Result<Arc<Self>, VkError> {
        Self::select(instance, &|raw, pd| surface_shortcomings(raw, pd, surface), true)
    }

    /// The device that fits best: it has a backend and `more` lacks nothing;
    /// `swapchain` enables VK_KHR_swapchain.
    fn select(
        instance: Arc<Instance>,
        more: &dyn Fn(&ash::Instance, vk::PhysicalDevice) -> Vec<String>,
        swapchain: bool,
    ) -> Result<Arc<Self>, VkError> {
        let raw_instance = &instance.raw;
        // SAFETY: `raw_instance` is the live instance owned by `instance`, an Arc held for the whole
        // function.
        let devices = unsafe { raw_instance.enumerate_physical_devices() }.map_err(|e| {
            VkError::NoSuitableDevice(format!("the Vulkan driver lists no devices ({e}).\nTo fix: {SETUP_HINT}"))
        })?;
        let mut report = Vec::new();
        let mut fits = Vec::new();
        for &pd in &devices {
            // SAFETY: `pd` was just enumerated from `raw_instance`.
            let props = unsafe { raw_instance.get_physical_device_properties(pd) };
            let caps = Capabilities::query(raw_instance, pd);
            let extra = more(raw_instance, pd);
            match caps.auto_backend() {
                Some(backend) if extra.is_empty() => {
                    fits.push((preference(props.device_type), pd, caps.clone()));
                    report.push(format!("  {}: suitable ({backend} backend)", caps.name));
                }
                Some(_) => report.push(format!("  {}: lacks {}", caps.name, extra.join(", "))),
                // Per backend: what the device lacks for each.
                None => report.push(format!(
                    "  {} ({}):\n    {}",
                    caps.name,
                    caps.device_type,
                    caps.backend_lines().join("\n    ")
                )),
            }
        }
        let Some((_, physical, caps)) = fits.into_iter().min_by_key(|(rank, ..)| *rank) else {
            let seen = if report.is_empty() { "  (no Vulkan devices)".to_string() } else { report.join("\n") };
            return Err(VkError::NoSuitableDevice(format!("devices seen:\n{seen}\nTo fix: {SETUP_HINT}")));
        };
        Self::create(instance.clone(), physical, &caps, swapchain)
    }

    /// The logical device on `physical`, whose capabilities `caps` are, with
    /// each of ray queries and ray-tracing pipelines that it offers.
    fn create(
        instance: Arc<Instance>,
        physical: vk::PhysicalDevice,
        caps: &Capabilities,
        swapchain: bool,
    ) -> Result<Arc<Self>, VkError> {
        let raw_instance = &instance.raw;
        // SAFETY: `physical` was enumerated from `raw_instance` in `select`; `instance` keeps the instance
        // alive.
        let properties = unsafe { raw_instance.get_physical_device_properties(physical) };
        // SAFETY: as above.
        let queue_family = unsafe { raw_instance.get_physical_device_queue_family_properties(physical) }
            .iter()
            .position(|q| q.queue_flags.contains(vk::QueueFlags::COMPUTE))
            .expect("checked in shortcomings") as u32;
        let priorities = [1.0f32];
        let queue_info =
            [vk::DeviceQueueCreateInfo::default().queue_family_index(queue_family).queue_priorities(&priorities)];
        let mut ext_names: Vec<_> = REQUIRED_EXTENSIONS.iter().map(|e| e.as_ptr()).collect();
        if swapchain {
            ext_names.push(ash::khr::swapchain::NAME.as_ptr());
        }
        // Ray queries and ray-tracing pipelines where offered: the backends.
        if caps.ray_query {
            ext_names.push(ash::khr::ray_query::NAME.as_ptr());
        }
        if caps.ray_tracing_pipeline {
            ext_names.push(ash::khr::ray_tracing_pipeline::NAME.as_ptr());
        }

        let mut supported12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut supported = vk::PhysicalDeviceFeatures2::default().push_next(&mut supported12);
        // SAFETY: `physical` belongs to `raw_instance` (API 1.2, so the command is core); the chain holds
        // only `supported12`, a live local, and the device reports Vulkan 1.2 (`select` takes only devices
        // with a backend, and every backend needs 1.2).
        unsafe { raw_instance.get_physical_device_features2(physical, &mut supported) };
        let base_features = vk::PhysicalDeviceFeatures::default().shader_float64(true).shader_int64(true);

        let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
            .buffer_device_address(true)
            .scalar_block_layout(true)
            .shader_sampled_image_array_non_uniform_indexing(true)
            .host_query_reset(supported12.host_query_reset == vk::TRUE)
            .shader_buffer_int64_atomics(true);
        let mut fas = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default().acceleration_structure(true);
        let mut frq = vk::PhysicalDeviceRayQueryFeaturesKHR::default().ray_query(true);
        let mut frt = vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default().ray_tracing_pipeline(true);
        let mut features =
            vk::PhysicalDeviceFeatures2::default().features(base_features).push_next(&mut f12).push_next(&mut fas);
        if caps.ray_query {
            features = features.push_next(&mut frq);
        }
        if caps.ray_tracing_pipeline {
            features = features.push_next(&mut frt);
        }
        let info = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_extension_names(&ext_names)
            .push_next(&mut features);
        // SAFETY: `info` and what it points to (`queue_info` with `priorities`, `ext_names`, the chain
        // `features` -> `f12`, `fas`, `frq`, `frt`) are locals alive until the call returns, and the names
        // are `&'static CStr`s. Every extension is one the device lists and every feature one it supports:
        // `select` took a device whose `Capabilities` lack nothing for a backend (acceleration structures,
        // deferred host operations, bufferDeviceAddress, scalarBlockLayout, non-uniform indexing, float64,
        // int64, int64 atomics); ray queries and pipelines are chained only where `caps` found them;
        // host_query_reset is copied from the device; the swapchain extension is asked for only by
        // `for_surface`, whose check requires it.
        let raw = unsafe { raw_instance.create_device(physical, &info, None) }?;
        // SAFETY: `raw` was just created with one queue (index 0) of `queue_family`, as `queue_info` asked.
        let queue = unsafe { raw.get_device_queue(queue_family, 0) };
        let accel = ash::khr::acceleration_structure::Device::new(raw_instance, &raw);
        let ray_tracing = caps.pipeline_limits.map(|limits| RayTracing {
            loader: ash::khr::ray_tracing_pipeline::Device::new(raw_instance, &raw),
            limits,
        });

        let mut as_props = vk::PhysicalDeviceAccelerationStructurePropertiesKHR::default();
        let mut maintenance3 = vk::PhysicalDeviceMaintenance3Properties::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut as_props).push_next(&mut maintenance3);
        // SAFETY: `physical` belongs to `raw_instance`; the chain holds two live locals:
        // acceleration-structure properties (the device lists and enabled VK_KHR_acceleration_structure) and
        // maintenance-3 properties (core since Vulkan 1.1).
        unsafe { raw_instance.get_physical_device_properties2(physical, &mut props2) };
        let accel_properties = AccelProperties {
            min_scratch_offset_alignment: as_props.min_acceleration_structure_scratch_offset_alignment,
        };

        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: raw_instance.clone(),
            device: raw.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: true,
            allocation_sizes: Default::default(),
        })
        .map_err(|e| VkError::Allocation(e.to_string()))?;

        let name = device_name(&properties);
        log::info!("Vulkan device: {name}");
        Ok(Arc::new(Self {
            instance,
            physical,
            raw,
            queue_family,
            queue,
            accel,
            properties,
            accel_properties,
            max_allocation_bytes: maintenance3.max_memory_allocation_size,
            name,
            driver: format!("{}: {}", caps.driver_name, caps.driver_info),
            ray_tracing,
            ray_query: caps.ray_query,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
        }))
    }

    /// The backend for a pass that asks for `requested`: that one if the
    /// device was created with it (an error if not: a backend asked for is
    /// never silently replaced), the device's preferred one when `None`
    /// (ray queries where offered, else the pipeline).
    pub fn backend_for(&self, requested: Option<super::Backend>) -> Result<super::Backend, VkError> {
        use super::Backend;
        match requested {
            Some(b) if self.offers(b) => Ok(b),
            Some(b) => Err(VkError::BackendUnavailable { device: self.name.clone(), backend: b }),
            None if self.offers(Backend::RayQuery) => Ok(Backend::RayQuery),
            None => Ok(Backend::Pipeline),
        }
    }

    /// Whether the device was created with what `backend` needs.
    pub fn offers(&self, backend: super::Backend) -> bool {
        match backend {
            super::Backend::RayQuery => self.ray_query,
            super::Backend::Pipeline => self.ray_tracing.is_some(),
        }
    }

    /// The shader stages that passes on this device can run in: compute
    /// always, the ray-tracing stages where the device was created with
    /// ray-tracing pipelines (only then may a barrier name them).
    pub fn shader_stages(&self) -> &'static [super::ShaderStage] {
        if self.offers(super::Backend::Pipeline) {
            &[super::ShaderStage::Compute, super::ShaderStage::RayTracing]
        } else {
            &[super::ShaderStage::Compute]
        }
    }

    /// `access` in every shader stage this device runs passes in (see
    /// [`Device::shader_stages`]): what a barrier names for a resource any
    /// pass may touch.
    pub fn in_every_stage(&self, access: fn(super::ShaderStage) -> super::Access) -> Vec<super::Access> {
        self.shader_stages().iter().map(|&s| access(s)).collect()
    }

    /// Nanoseconds per timestamp tick.
    pub fn timestamp_period_ns(&self) -> f64 {
        self.properties.limits.timestamp_period as f64
    }
}

impl Drop for Device {
    fn drop(&mut self) {
        // SAFETY: every object made from this device holds an `Arc<Device>`, so all of them are destroyed and
        // no other thread can use the device or its queue; after the wait no submission is pending. The
        // allocator frees its memory blocks when dropped, so it goes first, exactly once and is never touched
        // again; then the device is destroyed once. `instance` (a field) drops after this body.
        unsafe {
            let _ = self.raw.device_wait_idle();
            ManuallyDrop::drop(&mut self.allocator);
            self.raw.destroy_device(None);
        }
    }
}
