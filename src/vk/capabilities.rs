//! What a Vulkan device offers the renderer, read without creating a device:
//! the ray-tracing extensions and features each way of tracing rays needs,
//! float64, 64-bit atomics and timestamps. Device selection says from it
//! what each device lacks; `quadray devices` prints it.

use std::ffi::CStr;
use std::fmt;
use std::str::FromStr;

use ash::vk;
use serde::Serialize;

/// How rays are traced.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "kebab-case")]
pub enum Backend {
    /// Compute shaders with `VK_KHR_ray_query` (`rayQueryEXT`): the
    /// renderer's backend.
    RayQuery,
    /// Ray-tracing pipelines (`VK_KHR_ray_tracing_pipeline`): ray generation,
    /// intersection and hit shaders. Some GPUs offer only these (NVIDIA GPUs
    /// without RT cores). Every tracing pass (render, G-buffer, caustic
    /// rays, volume, probes) has a ray-generation shader for it.
    Pipeline,
}

impl Backend {
    /// Every backend, in the order `auto` prefers them.
    pub const ALL: [Backend; 2] = [Backend::RayQuery, Backend::Pipeline];

    /// The name used on the command line and in JSON.
    pub fn name(self) -> &'static str {
        match self {
            Backend::RayQuery => "ray-query",
            Backend::Pipeline => "pipeline",
        }
    }
}

impl fmt::Display for Backend {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        f.write_str(self.name())
    }
}

impl FromStr for Backend {
    type Err = String;

    fn from_str(s: &str) -> Result<Self, Self::Err> {
        Backend::ALL
            .into_iter()
            .find(|b| b.name() == s)
            .ok_or_else(|| format!("unknown backend `{s}`: expected `ray-query` or `pipeline`"))
    }
}

/// The ray-tracing-pipeline limits a shader binding table is laid out by.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct PipelineLimits {
    /// `shaderGroupHandleSize`, bytes.
    pub shader_group_handle_size: u32,
    /// `shaderGroupHandleAlignment`, bytes.
    pub shader_group_handle_alignment: u32,
    /// `shaderGroupBaseAlignment`, bytes.
    pub shader_group_base_alignment: u32,
    /// `maxRayRecursionDepth`.
    pub max_ray_recursion_depth: u32,
    /// `maxRayHitAttributeSize`, bytes.
    pub max_ray_hit_attribute_size: u32,
}

/// What one physical device offers; every flag is true only when both the
/// extension (or core version) and the feature are there.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Capabilities {
    /// `deviceName`.
    pub name: String,
    /// Discrete GPU, integrated GPU, virtual GPU, CPU or other.
    pub device_type: String,
    /// The Vulkan version the driver supports, `major.minor.patch`.
    pub api_version: String,
    /// The driver's name (`VkPhysicalDeviceDriverProperties`), e.g. `llvmpipe`.
    pub driver_name: String,
    /// The driver's own version string, e.g. `Mesa 25.0.7 (LLVM 15.0.6)`.
    pub driver_info: String,
    /// Vulkan 1.2 or later.
    pub vulkan_1_2: bool,
    /// A queue family with compute.
    pub compute_queue: bool,
    /// `VK_KHR_acceleration_structure` with `accelerationStructure`.
    pub acceleration_structure: bool,
    /// `VK_KHR_deferred_host_operations` (acceleration structures need it).
    pub deferred_host_operations: bool,
    /// `VK_KHR_ray_query` with `rayQuery`.
    pub ray_query: bool,
    /// `VK_KHR_ray_tracing_pipeline` with `rayTracingPipeline`.
    pub ray_tracing_pipeline: bool,
    /// `bufferDeviceAddress`.
    pub buffer_device_address: bool,
    /// `scalarBlockLayout`.
    pub scalar_block_layout: bool,
    /// `shaderSampledImageArrayNonUniformIndexing`.
    pub non_uniform_indexing: bool,
    /// `shaderFloat64`: the intersection refines roots in f64.
    pub float64: bool,
    /// `shaderInt64`.
    pub int64: bool,
    /// `shaderBufferInt64Atomics`: the caustic maps add in 64-bit fixed point.
    pub int64_atomics: bool,
    /// Timestamps on the compute queue (`timestampValidBits` > 0): GPU
    /// times in benchmarks.
    pub timestamps: bool,
    /// Nanoseconds per timestamp tick.
    pub timestamp_period_ns: f32,
    /// The pipeline limits, when ray-tracing pipelines are offered.
    pub pipeline_limits: Option<PipelineLimits>,
}

fn has_extension(extensions: &[vk::ExtensionProperties], name: &CStr) -> bool {
    extensions.iter().any(|e| e.extension_name_as_c_str() == Ok(name))
}

fn version(v: u32) -> String {
    format!("{}.{}.{}", vk::api_version_major(v), vk::api_version_minor(v), vk::api_version_patch(v))
}

fn c_text(chars: Result<&CStr, std::ffi::FromBytesUntilNulError>) -> String {
    chars.map(|c| c.to_string_lossy().into_owned()).unwrap_or_default()
}

impl Capabilities {
    /// Reads what `physical` offers. Feature structures of an extension are
    /// chained only when the device lists the extension.
    pub fn query(instance: &ash::Instance, physical: vk::PhysicalDevice) -> Self {
        // SAFETY: the callers (`Device::select`, `survey`) pass a `physical` enumerated from `instance`,
        // which is borrowed alive for the call; nothing checks this for other callers of this public
        // function.
        let props = unsafe { instance.get_physical_device_properties(physical) };
        // SAFETY: as above; ash sizes the returned Vec from the reported count.
        let extensions = unsafe { instance.enumerate_device_extension_properties(physical) }.unwrap_or_default();
        let vulkan_1_2 = props.api_version >= vk::API_VERSION_1_2;
        let has = |name: &CStr| has_extension(&extensions, name);
        let (has_as, has_rq, has_rt) = (
            has(ash::khr::acceleration_structure::NAME),
            has(ash::khr::ray_query::NAME),
            has(ash::khr::ray_tracing_pipeline::NAME),
        );

        let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
        let mut fas = vk::PhysicalDeviceAccelerationStructureFeaturesKHR::default();
        let mut frq = vk::PhysicalDeviceRayQueryFeaturesKHR::default();
        let mut frt = vk::PhysicalDeviceRayTracingPipelineFeaturesKHR::default();
        let mut features = vk::PhysicalDeviceFeatures2::default();
        if vulkan_1_2 {
            features = features.push_next(&mut f12);
        }
        if has_as {
            features = features.push_next(&mut fas);
        }
        if has_rq {
            features = features.push_next(&mut frq);
        }
        if has_rt {
            features = features.push_next(&mut frt);
        }
        // SAFETY: `physical` belongs to `instance` (API 1.2, so the command is core); each struct in the
        // chain is a live local, chained only where valid: the Vulkan 1.2 features where the device reports
        // 1.2, an extension's features where the device lists the extension.
        unsafe { instance.get_physical_device_features2(physical, &mut features) };
        let base = features.features;

        let mut driver = vk::PhysicalDeviceDriverProperties::default();
        let mut rt_props = vk::PhysicalDeviceRayTracingPipelinePropertiesKHR::default();
        let mut props2 = vk::PhysicalDeviceProperties2::default();
        if vulkan_1_2 {
            props2 = props2.push_next(&mut driver);
        }
        if has_rt {
            props2 = props2.push_next(&mut rt_props);
        }
        // SAFETY: as for the features: driver properties (core 1.2) only on a 1.2 device,
        // ray-tracing-pipeline properties only where the device lists the extension; both are live locals.
        unsafe { instance.get_physical_device_properties2(physical, &mut props2) };

        // SAFETY: `physical` belongs to the live `instance`, as above.
        let families = unsafe { instance.get_physical_device_queue_family_properties(physical) };
        let compute = families.iter().find(|q| q.queue_flags.contains(vk::QueueFlags::COMPUTE));
        let ray_tracing_pipeline = has_rt && frt.ray_tracing_pipeline == vk::TRUE;
        // QUADRAY_HIDE_RAY_QUERY=1 reports no ray queries (and the device is
        // then created without them): a test of the pipeline backend alone,
        // as on a GPU that offers only pipelines.
        let hidden = |name: &str| std::env::var(name).is_ok_and(|v| v == "1");
        let hide_ray_query = hidden("QUADRAY_HIDE_RAY_QUERY");
        // QUADRAY_HIDE_PIPELINE=1 likewise hides ray-tracing pipelines.
        let ray_tracing_pipeline = ray_tracing_pipeline && !hidden("QUADRAY_HIDE_PIPELINE");
        let on = |flag: vk::Bool32| flag == vk::TRUE;
        Self {
            name: c_text(props.device_name_as_c_str()),
            device_type: match props.device_type {
                vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
                vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
                vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
                vk::PhysicalDeviceType::CPU => "CPU",
                _ => "other",
            }
            .to_string(),
            api_version: version(props.api_version),
            driver_name: c_text(driver.driver_name_as_c_str()),
            driver_info: c_text(driver.driver_info_as_c_str()),
            vulkan_1_2,
            compute_queue: compute.is_some(),
            acceleration_structure: has_as && on(fas.acceleration_structure),
            deferred_host_operations: has(ash::khr::deferred_host_operations::NAME),
            ray_query: has_rq && on(frq.ray_query) && !hide_ray_query,
            ray_tracing_pipeline,
            buffer_device_address: on(f12.buffer_device_address),
            scalar_block_layout: on(f12.scalar_block_layout),
            non_uniform_indexing: on(f12.shader_sampled_image_array_non_uniform_indexing),
            float64: on(base.shader_float64),
            int64: on(base.shader_int64),
            int64_atomics: on(f12.shader_buffer_int64_atomics),
            timestamps: compute.is_some_and(|q| q.timestamp_valid_bits > 0),
            timestamp_period_ns: props.limits.timestamp_period,
            pipeline_limits: ray_tracing_pipeline.then_some(PipelineLimits {
                shader_group_handle_size: rt_props.shader_group_handle_size,
                shader_group_handle_alignment: rt_props.shader_group_handle_alignment,
                shader_group_base_alignment: rt_props.shader_group_base_alignment,
                max_ray_recursion_depth: rt_props.max_ray_recursion_depth,
                max_ray_hit_attribute_size: rt_props.max_ray_hit_attribute_size,
            }),
        }
    }

    /// What the device lacks for `backend`, by the names of the extensions
    /// and features (empty when it has everything).
    pub fn lacks(&self, backend: Backend) -> Vec<&'static str> {
        let tracing = match backend {
            Backend::RayQuery => (self.ray_query, "VK_KHR_ray_query with rayQuery"),
            Backend::Pipeline => (self.ray_tracing_pipeline, "VK_KHR_ray_tracing_pipeline with rayTracingPipeline"),
        };
        let needs = [
            (self.vulkan_1_2, "Vulkan 1.2"),
            (self.compute_queue, "a compute queue"),
            (self.acceleration_structure, "VK_KHR_acceleration_structure with accelerationStructure"),
            (self.deferred_host_operations, "VK_KHR_deferred_host_operations"),
            tracing,
            (self.buffer_device_address, "bufferDeviceAddress"),
            (self.scalar_block_layout, "scalarBlockLayout"),
            (self.non_uniform_indexing, "shaderSampledImageArrayNonUniformIndexing"),
            (self.float64, "shaderFloat64"),
            (self.int64, "shaderInt64"),
            (self.int64_atomics, "shaderBufferInt64Atomics"),
        ];
        needs.into_iter().filter(|(has, _)| !has).map(|(_, name)| name).collect()
    }

    /// The backend `--backend auto` takes: the first of [`Backend::ALL`]
    /// (ray queries, then pipelines) the device has everything for.
    pub fn auto_backend(&self) -> Option<Backend> {
        Backend::ALL.into_iter().find(|&b| self.lacks(b).is_empty())
    }

    /// One line per backend: what the device lacks for it, or that it fits.
    pub fn backend_lines(&self) -> Vec<String> {
        Backend::ALL
            .into_iter()
            .map(|b| {
                let lacks = self.lacks(b);
                if lacks.is_empty() {
                    format!("{b}: supported")
                } else {
                    format!("{b}: lacks {}", lacks.join(", "))
                }
            })
            .collect()
    }
}

/// How much the renderer prefers a device of this type (lower first):
/// discrete GPUs, then integrated, then virtual, then the rest (CPU drivers).
pub fn preference(device_type: vk::PhysicalDeviceType) -> u32 {
    match device_type {
        vk::PhysicalDeviceType::DISCRETE_GPU => 0,
        vk::PhysicalDeviceType::INTEGRATED_GPU => 1,
        vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
        _ => 3,
    }
}

/// Every Vulkan device the loader lists and the one a render takes.
#[derive(Clone, Debug)]
pub struct Survey {
    /// What each device offers, in the order the loader lists them.
    pub devices: Vec<Capabilities>,
    /// The device `auto` takes (its index) and the backend: the most
    /// preferred device type ([`preference`]) with a backend.
    pub auto: Option<(usize, Backend)>,
}

/// Lists the Vulkan devices and what each offers; needs no validation layer.
pub fn survey() -> Result<Survey, super::VkError> {
    let instance = super::Instance::new(false)?;
    // SAFETY: `instance.raw` is the instance created just above, alive until this function returns.
    let physical = unsafe { instance.raw.enumerate_physical_devices() }?;
    let mut devices = Vec::new();
    let mut best: Option<(u32, usize, Backend)> = None;
    for (index, &pd) in physical.iter().enumerate() {
        let caps = Capabilities::query(&instance.raw, pd);
        // SAFETY: `pd` was just enumerated from `instance.raw`, which is alive.
        let rank = preference(unsafe { instance.raw.get_physical_device_properties(pd) }.device_type);
        if let Some(backend) = caps.auto_backend() {
            if best.is_none_or(|(r, _, _)| rank < r) {
                best = Some((rank, index, backend));
            }
        }
        devices.push(caps);
    }
    Ok(Survey { devices, auto: best.map(|(_, index, backend)| (index, backend)) })
}

#[cfg(test)]
mod tests {
    use super::*;

    fn everything() -> Capabilities {
        Capabilities {
            name: "test".into(),
            device_type: "CPU".into(),
            api_version: "1.3.0".into(),
            driver_name: "test".into(),
            driver_info: String::new(),
            vulkan_1_2: true,
            compute_queue: true,
            acceleration_structure: true,
            deferred_host_operations: true,
            ray_query: true,
            ray_tracing_pipeline: true,
            buffer_device_address: true,
            scalar_block_layout: true,
            non_uniform_indexing: true,
            float64: true,
            int64: true,
            int64_atomics: true,
            timestamps: true,
            timestamp_period_ns: 1.0,
            pipeline_limits: None,
        }
    }

    #[test]
    fn a_device_with_everything_lacks_nothing_and_auto_takes_ray_queries() {
        let caps = everything();
        assert!(caps.lacks(Backend::RayQuery).is_empty());
        assert!(caps.lacks(Backend::Pipeline).is_empty());
        assert_eq!(caps.auto_backend(), Some(Backend::RayQuery));
    }

    #[test]
    fn a_pipeline_only_gpu_is_told_apart_from_one_that_lacks_float64() {
        // NVIDIA GPUs without RT cores: pipelines, no ray queries.
        let caps = Capabilities { ray_query: false, ..everything() };
        assert_eq!(caps.lacks(Backend::RayQuery), ["VK_KHR_ray_query with rayQuery"]);
        assert!(caps.lacks(Backend::Pipeline).is_empty());
        assert_eq!(caps.auto_backend(), Some(Backend::Pipeline));
        let lines = caps.backend_lines();
        assert_eq!(lines, ["ray-query: lacks VK_KHR_ray_query with rayQuery", "pipeline: supported"]);
        let neither = Capabilities { ray_query: false, ray_tracing_pipeline: false, ..everything() };
        assert_eq!(neither.auto_backend(), None);
        let no_f64 = Capabilities { float64: false, ray_tracing_pipeline: false, ..everything() };
        assert_eq!(no_f64.lacks(Backend::RayQuery), ["shaderFloat64"]);
        assert_eq!(
            no_f64.lacks(Backend::Pipeline),
            ["VK_KHR_ray_tracing_pipeline with rayTracingPipeline", "shaderFloat64"]
        );
    }

    #[test]
    fn backend_names_round_trip() {
        for b in Backend::ALL {
            assert_eq!(b.name().parse::<Backend>(), Ok(b));
            assert_eq!(serde_json::to_string(&b).unwrap(), format!("\"{}\"", b.name()));
        }
        assert!("rt".parse::<Backend>().unwrap_err().contains("ray-query"));
    }
}
