//! Ray-tracing pipelines, the `pipeline` backend: a ray-generation shader,
//! one miss shader and one procedural hit group (the intersection shader
//! that solves the perturbed quadric's first root in a candidate box, and a
//! closest-hit shader), with recursion depth 1 (paths loop in the
//! ray-generation shader), and the shader binding table laid out by the
//! device's handle size and alignments.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::MemoryLocation;

use super::pipeline::PipelineResources;
use super::reflect::ShaderInterface;
use super::{Binding, Buffer, Device, VkError};

/// The SPIR-V of a pipeline's stages.
pub struct RayTracingStages {
    /// The ray-generation shader (one per pass).
    pub raygen: Vec<u32>,
    /// The miss shader.
    pub miss: Vec<u32>,
    /// The intersection shader of the procedural boxes.
    pub intersection: Vec<u32>,
    /// The closest-hit shader.
    pub closest_hit: Vec<u32>,
}

fn align_up(value: u32, alignment: u32) -> u32 {
    value.div_ceil(alignment.max(1)) * alignment.max(1)
}

/// A ray-tracing pipeline with its layout, descriptor set and shader
/// binding table.
pub struct RayTracingPipeline {
    /// The layout, descriptor set and the stages' merged interface.
    pub resources: PipelineResources,
    /// The pipeline.
    pub raw: vk::Pipeline,
    /// The shader binding table the regions point into (kept alive).
    _sbt: Buffer,
    /// Ray generation, miss, hit and (empty) callable regions of the table.
    regions: [vk::StridedDeviceAddressRegionKHR; 4],
}

impl RayTracingPipeline {
    /// Creates the pipeline: the descriptor set layout is the union of the
    /// stages' reflected bindings; `specialization` sets constants by id in
    /// every stage that declares them (an id no stage declares is an
    /// error). Needs a device created with ray-tracing pipelines
    /// ([`Device::ray_tracing`]).
    pub fn new(
        device: &Arc<Device>,
        stages: &RayTracingStages,
        specialization: &[(u32, u32)],
    ) -> Result<Self, VkError> {
        let Some(super::RayTracing { loader: rt, limits }) = device.ray_tracing.as_ref() else {
            return Err(VkError::NoSuitableDevice(format!(
                "{} was not created with VK_KHR_ray_tracing_pipeline (the device lacks it)",
                device.name
            )));
        };
        let code = [&stages.raygen, &stages.miss, &stages.intersection, &stages.closest_hit];
        let mut interface = ShaderInterface::reflect(code[0])?;
        for spirv in &code[1..] {
            interface = interface.merge(ShaderInterface::reflect(spirv)?)?;
        }
        let flags = [
            vk::ShaderStageFlags::RAYGEN_KHR,
            vk::ShaderStageFlags::MISS_KHR,
            vk::ShaderStageFlags::INTERSECTION_KHR,
            vk::ShaderStageFlags::CLOSEST_HIT_KHR,
        ];
        let all = flags.iter().fold(vk::ShaderStageFlags::empty(), |a, &f| a | f);
        let resources = PipelineResources::new(device, interface, all)?;
        let (mut entries, mut values) = (Vec::new(), Vec::new());
        let spec = resources.specialization(specialization, &mut entries, &mut values)?;
        let raw = &device.raw;
        let mut modules = Vec::new();
        for spirv in code {
            // SAFETY: `raw` is the live device; each `spirv` is a `&Vec<u32>` (a byte length that is a
            // multiple of 4) that `ShaderInterface::reflect` parsed above; the create info is a temporary
            // alive for the call.
            match unsafe { raw.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(spirv), None) } {
                Ok(m) => modules.push(m),
                Err(e) => {
                    // SAFETY: the modules created so far belong to no pipeline and are not used after this.
                    modules.iter().for_each(|&m| unsafe { raw.destroy_shader_module(m, None) });
                    return Err(e.into());
                }
            }
        }
        let stage_infos: Vec<_> = modules
            .iter()
            .zip(flags)
            .map(|(&module, stage)| {
                vk::PipelineShaderStageCreateInfo::default()
                    .stage(stage)
                    .module(module)
                    .name(c"main")
                    .specialization_info(&spec)
            })
            .collect();
        let general = |index: u32| {
            vk::RayTracingShaderGroupCreateInfoKHR::default()
                .ty(vk::RayTracingShaderGroupTypeKHR::GENERAL)
                .general_shader(index)
                .closest_hit_shader(vk::SHADER_UNUSED_KHR)
                .any_hit_shader(vk::SHADER_UNUSED_KHR)
                .intersection_shader(vk::SHADER_UNUSED_KHR)
        };
        let groups = [
            general(0),
            general(1),
            vk::RayTracingShaderGroupCreateInfoKHR::default()
                .ty(vk::RayTracingShaderGroupTypeKHR::PROCEDURAL_HIT_GROUP)
                .general_shader(vk::SHADER_UNUSED_KHR)
                .intersection_shader(2)
                .closest_hit_shader(3)
                .any_hit_shader(vk::SHADER_UNUSED_KHR),
        ];
        let info = [vk::RayTracingPipelineCreateInfoKHR::default()
            .stages(&stage_infos)
            .groups(&groups)
            .max_pipeline_ray_recursion_depth(1)
            .layout(resources.layout)];
        // SAFETY: `rt` was loaded for `device.raw`, which enabled VK_KHR_ray_tracing_pipeline and its
        // rayTracingPipeline feature (`device.ray_tracing` is `Some` only then). `info` -> `stage_infos`,
        // `groups`, `spec` -> `entries`/`values` are locals alive until the call returns; the groups name
        // stages 0 to 3 by kind (general: ray generation and miss; procedural hit group: intersection and
        // closest hit); recursion depth 1 is within maxRayRecursionDepth (at least 1); the layout was built
        // from the merged interface of all four stages; no deferred operation or cache is used.
        let created = unsafe {
            rt.create_ray_tracing_pipelines(vk::DeferredOperationKHR::null(), vk::PipelineCache::null(), &info, None)
        };
        // SAFETY: whether or not creation succeeded, no further pipeline is made from the modules; they were
        // created above and are not used after this.
        modules.iter().for_each(|&m| unsafe { raw.destroy_shader_module(m, None) });
        let pipeline = created.map_err(|(_, e)| e)?[0];

        // The shader binding table: one region per group kind, each at the
        // base alignment, handles at the handle alignment.
        let handle_size = limits.shader_group_handle_size;
        let handle_stride = align_up(handle_size, limits.shader_group_handle_alignment);
        let region = align_up(handle_stride, limits.shader_group_base_alignment);
        let group_count = groups.len() as u32;
        // SAFETY: `pipeline` was just created through `rt` on this device; groups 0 to `group_count` - 1
        // exist, and the data size is `group_count` x `handle_size` bytes, as required.
        let handles = match unsafe {
            rt.get_ray_tracing_shader_group_handles(pipeline, 0, group_count, (group_count * handle_size) as usize)
        } {
            Ok(h) => h,
            Err(e) => {
                // SAFETY: `pipeline` was created above, never recorded into a command buffer, and is not used
                // after this.
                unsafe { raw.destroy_pipeline(pipeline, None) };
                return Err(e.into());
            }
        };
        let usage = vk::BufferUsageFlags::SHADER_BINDING_TABLE_KHR | vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;
        // Room to move the table's start up to the base alignment.
        let size = u64::from(region * group_count + limits.shader_group_base_alignment);
        let mut sbt = match Buffer::new(device, "shader binding table", size, usage, MemoryLocation::CpuToGpu) {
            Ok(b) => b,
            Err(e) => {
                // SAFETY: as above: `pipeline` was never recorded and is not used after this.
                unsafe { raw.destroy_pipeline(pipeline, None) };
                return Err(e);
            }
        };
        let start = sbt.device_address();
        let alignment = u64::from(limits.shader_group_base_alignment.max(1));
        let base = start.div_ceil(alignment) * alignment;
        for g in 0..group_count as usize {
            let handle = &handles[g * handle_size as usize..(g + 1) * handle_size as usize];
            sbt.write((base - start) as usize + g * region as usize, handle);
        }
        let region_at = |index: u64, stride: u32| vk::StridedDeviceAddressRegionKHR {
            device_address: base + index * u64::from(region),
            stride: u64::from(stride),
            size: u64::from(region),
        };
        // The ray-generation region's stride must equal its size.
        let regions =
            [region_at(0, region), region_at(1, handle_stride), region_at(2, handle_stride), Default::default()];
        Ok(Self { resources, raw: pipeline, _sbt: sbt, regions })
    }

    /// Points the stages' bindings at resources ([`PipelineResources::bind`]).
    pub fn bind(&self, resources: &[(u32, Binding<'_>)]) -> Result<(), VkError> {
        self.resources.bind(resources)
    }

    /// Records binding the pipeline and set, pushing `constants`, and
    /// tracing `size` = (width, height, depth) ray-generation invocations.
    pub fn trace(&self, cmd: vk::CommandBuffer, constants: &[u8], size: [u32; 3]) {
        let device = self.resources.device();
        let rt = &device.ray_tracing.as_ref().expect("checked in new").loader;
        // SAFETY: `cmd` is a recording command buffer of this device (the callers pass `rec.cmd`; the type
        // cannot check it); `self.raw` is a live ray-tracing pipeline owned by `self`; the compute queue
        // supports the ray-tracing bind point.
        unsafe { device.raw.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::RAY_TRACING_KHR, self.raw) };
        self.resources.record(cmd, vk::PipelineBindPoint::RAY_TRACING_KHR, constants);
        let [raygen, miss, hit, callable] = &self.regions;
        // SAFETY: `rt` was loaded for this device, which enabled the extension (`new` checked `ray_tracing`);
        // the pipeline, set and push constants were bound just above. The regions lie inside `_sbt`, owned by
        // `self` (which the caller keeps alive across `Commands::run`), in host-coherent memory written
        // before any submission: each starts at the base alignment, the ray-generation region's stride equals
        // its size, the other strides are multiples of the handle alignment, and the callable region is
        // empty. A size within maxRayDispatchInvocationCount is the caller's to respect (not checked).
        unsafe { rt.cmd_trace_rays(cmd, raygen, miss, hit, callable, size[0], size[1], size[2]) };
    }
}

impl Drop for RayTracingPipeline {
    fn drop(&mut self) {
        // SAFETY: `self.raw` was created in `new` and is destroyed once, here, before the fields drop, so
        // `resources` (its layout and set) and `_sbt` outlive it; no pending submission uses it, as
        // `Commands::run` waits before returning.
        unsafe { self.resources.device().raw.destroy_pipeline(self.raw, None) };
    }
}
