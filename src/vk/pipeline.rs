//! Compute pipelines with one descriptor set and a push-constant block, and
//! the layout and descriptor set every pipeline kind shares.

use std::sync::Arc;

use ash::vk;

use super::reflect::{BindingKind, InterfaceError, ShaderInterface};
use super::{AccelerationStructure, Buffer, Device, Image, Sampler, VkError};

/// A resource bound at one binding.
#[derive(Clone)]
pub enum Binding<'a> {
    /// An acceleration structure.
    AccelerationStructure(&'a AccelerationStructure),
    /// A whole storage buffer.
    Buffer(&'a Buffer),
    /// A storage image in GENERAL layout.
    Image(&'a Image),
    /// Sampled images (one per array element) with one sampler.
    Textures(Vec<&'a Image>, &'a Sampler),
}

impl Binding<'_> {
    /// The descriptor kind this resource fills.
    pub fn kind(&self) -> BindingKind {
        match self {
            Self::AccelerationStructure(_) => BindingKind::AccelerationStructure,
            Self::Buffer(_) => BindingKind::StorageBuffer,
            Self::Image(_) => BindingKind::StorageImage,
            Self::Textures(images, _) => BindingKind::SampledImages(images.len() as u32),
        }
    }
}

/// A pipeline's layout and its one descriptor set, built from the reflected
/// interface of its stages ([`ShaderInterface`]); compute and ray-tracing
/// pipelines share it.
pub struct PipelineResources {
    device: Arc<Device>,
    /// The pipeline layout.
    pub layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    /// The descriptor set.
    pub set: vk::DescriptorSet,
    /// The stages' interface: bindings, spec constants, push constants.
    pub interface: ShaderInterface,
    /// The stages the bindings and push constants are visible to.
    pub stages: vk::ShaderStageFlags,
}

impl PipelineResources {
    /// The device.
    pub fn device(&self) -> &Arc<Device> {
        &self.device
    }

    /// The set layout (every binding visible to `stages`), the push-constant
    /// range and the pipeline layout of `interface`, and its descriptor set.
    pub fn new(
        device: &Arc<Device>,
        interface: ShaderInterface,
        stages: vk::ShaderStageFlags,
    ) -> Result<Self, VkError> {
        let raw = &device.raw;
        let layout_bindings: Vec<_> = interface
            .bindings
            .iter()
            .map(|(&i, b)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i)
                    .descriptor_type(b.kind.descriptor_type())
                    .descriptor_count(b.kind.count())
                    .stage_flags(stages)
            })
            .collect();
        let push_constant_size = interface.push_constant_size;
        let mut this = Self {
            device: device.clone(),
            layout: vk::PipelineLayout::null(),
            set_layout: vk::DescriptorSetLayout::null(),
            pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            interface,
            stages,
        };
        // From here on, `this` owns what is created and Drop cleans up on error.
        // SAFETY: `raw` is the live device; the create info and `layout_bindings` (a local Vec) live until
        // the call returns; binding numbers are distinct (keys of the interface's map) and every descriptor
        // type is one the device supports (acceleration structures: VK_KHR_acceleration_structure is required
        // and enabled).
        this.set_layout = unsafe {
            raw.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings),
                None,
            )
        }?;
        let ranges = [vk::PushConstantRange::default().stage_flags(stages).offset(0).size(push_constant_size)];
        let set_layouts = [this.set_layout];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        if push_constant_size > 0 {
            layout_info = layout_info.push_constant_ranges(&ranges);
        }
        // SAFETY: `set_layouts` holds the set layout just created; the one push-constant range, chained only
        // when nonzero, is at offset 0 with the stages' reflected size; all are locals alive until the call
        // returns.
        this.layout = unsafe { raw.create_pipeline_layout(&layout_info, None) }?;
        let mut sizes: Vec<vk::DescriptorPoolSize> = Vec::new();
        for b in this.interface.bindings.values() {
            let ty = b.kind.descriptor_type();
            match sizes.iter_mut().find(|s| s.ty == ty) {
                Some(s) => s.descriptor_count += b.kind.count(),
                None => sizes.push(vk::DescriptorPoolSize { ty, descriptor_count: b.kind.count() }),
            }
        }
        if !sizes.is_empty() {
            // SAFETY: `sizes` is a local, nonempty list with one entry per descriptor type (counts summed
            // over the bindings), alive for the call; max_sets is 1.
            this.pool = unsafe {
                raw.create_descriptor_pool(
                    &vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes),
                    None,
                )
            }?;
            // SAFETY: `this.pool` was just created with room for exactly one set of `set_layouts[0]`, the
            // layout just created; no other thread has the pool.
            this.set = unsafe {
                raw.allocate_descriptor_sets(
                    &vk::DescriptorSetAllocateInfo::default().descriptor_pool(this.pool).set_layouts(&set_layouts),
                )
            }?[0];
        }
        Ok(this)
    }

    /// The specialisation info of `specialization` (id, value) pairs; an id
    /// no stage declares is an error. `entries` and `values` hold the data.
    pub(super) fn specialization<'a>(
        &self,
        specialization: &[(u32, u32)],
        entries: &'a mut Vec<vk::SpecializationMapEntry>,
        values: &'a mut Vec<u32>,
    ) -> Result<vk::SpecializationInfo<'a>, VkError> {
        self.interface.check_spec_constants(specialization.iter().map(|&(id, _)| id))?;
        *entries = specialization
            .iter()
            .enumerate()
            .map(|(i, &(id, _))| vk::SpecializationMapEntry { constant_id: id, offset: 4 * i as u32, size: 4 })
            .collect();
        *values = specialization.iter().map(|&(_, v)| v).collect();
        Ok(vk::SpecializationInfo::default().map_entries(entries).data(bytemuck::cast_slice(values)))
    }

    /// Records binding the set at `bind_point` and pushing `constants`
    /// (exactly the stages' push-constant block).
    pub(super) fn record(&self, cmd: vk::CommandBuffer, bind_point: vk::PipelineBindPoint, constants: &[u8]) {
        assert_eq!(
            constants.len(),
            self.interface.push_constant_size as usize,
            "{}",
            InterfaceError::PushConstants { host: constants.len() as u32, shader: self.interface.push_constant_size }
        );
        let raw = &self.device.raw;
        // SAFETY: `cmd` is a recording command buffer of this device (the callers pass `rec.cmd`; the type
        // cannot check it); the layout and set are owned by `self` and the set was allocated with the
        // layout's own set layout; `constants` is exactly the push-constant range (asserted above) and
        // `self.stages` are the range's stages. The compute queue supports both bind points.
        unsafe {
            if self.set != vk::DescriptorSet::null() {
                raw.cmd_bind_descriptor_sets(cmd, bind_point, self.layout, 0, &[self.set], &[]);
            }
            if !constants.is_empty() {
                raw.cmd_push_constants(cmd, self.layout, self.stages, 0, constants);
            }
        }
    }

    /// Points the shader's bindings at resources given by binding number
    /// (`BINDING_*` of `shader_interface`). Every binding the shader
    /// declares needs one resource of its kind; resources at numbers the
    /// shader does not declare are left out (passes share the scene's).
    pub fn bind(&self, resources: &[(u32, Binding<'_>)]) -> Result<(), VkError> {
        let kinds: Vec<(u32, BindingKind)> = resources.iter().map(|(n, r)| (*n, r.kind())).collect();
        let unused = self.interface.check_bindings(&kinds)?;
        let resources: Vec<&(u32, Binding<'_>)> = resources.iter().filter(|(n, _)| !unused.contains(n)).collect();
        let mut buffer_infos = Vec::new();
        let mut image_infos = Vec::new();
        let mut as_handles = Vec::new();
        for (_, r) in &resources {
            match r {
                Binding::Buffer(b) => {
                    buffer_infos.push([vk::DescriptorBufferInfo::default().buffer(b.raw).range(vk::WHOLE_SIZE)])
                }
                Binding::Image(i) => image_infos.push(vec![vk::DescriptorImageInfo::default()
                    .image_view(i.view)
                    .image_layout(vk::ImageLayout::GENERAL)]),
                Binding::Textures(images, sampler) => image_infos.push(
                    images
                        .iter()
                        .map(|i| {
                            vk::DescriptorImageInfo::default()
                                .image_view(i.view)
                                .sampler(sampler.raw)
                                .image_layout(vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL)
                        })
                        .collect(),
                ),
                Binding::AccelerationStructure(a) => as_handles.push([a.raw]),
            }
        }
        let mut as_infos: Vec<_> = as_handles
            .iter()
            .map(|h| vk::WriteDescriptorSetAccelerationStructureKHR::default().acceleration_structures(h))
            .collect();
        let mut writes = Vec::new();
        let (mut bi, mut ii) = (0, 0);
        let mut as_iter = as_infos.iter_mut();
        for (n, r) in &resources {
            let base = vk::WriteDescriptorSet::default().dst_set(self.set).dst_binding(*n);
            match r {
                Binding::Buffer(_) => {
                    writes
                        .push(base.descriptor_type(vk::DescriptorType::STORAGE_BUFFER).buffer_info(&buffer_infos[bi]));
                    bi += 1;
                }
                Binding::Textures(..) => {
                    writes.push(
                        base.descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER).image_info(&image_infos[ii]),
                    );
                    ii += 1;
                }
                Binding::Image(_) => {
                    writes.push(base.descriptor_type(vk::DescriptorType::STORAGE_IMAGE).image_info(&image_infos[ii]));
                    ii += 1;
                }
                Binding::AccelerationStructure(_) => {
                    // The count must be explicit: it is not implied by a pNext chain
                    // (lavapipe silently skips the write without it).
                    let info = as_iter.next().expect("one info per acceleration structure");
                    writes.push(
                        base.descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                            .descriptor_count(1)
                            .push_next(info),
                    );
                }
            }
        }
        // SAFETY: `writes` and the arrays they point to (`buffer_infos`, `image_infos`, `as_infos` ->
        // `as_handles`) are locals alive until the call returns; every write targets a binding the shaders
        // declare, with the same descriptor type and count (`check_bindings`), and names live handles
        // borrowed for this call. The set is in no pending submission (`Commands::run` waits before
        // returning). Not checked here: callers keep the resources alive while the set is used, and do not
        // call this while recording a command buffer that bound the set.
        unsafe { self.device.raw.update_descriptor_sets(&writes, &[]) };
        Ok(())
    }
}

impl Drop for PipelineResources {
    fn drop(&mut self) {
        let raw = &self.device.raw;
        // SAFETY: the pool, pipeline layout and set layout were created in `new` on `self.device` (a field,
        // alive here) and are destroyed once, here; any still null after a failed `new` is skipped, as
        // destroying VK_NULL_HANDLE is a no-op. Destroying the pool frees `set`. The owning pipeline's
        // `Drop::drop` has already destroyed the pipeline, and no pending submission uses any of them
        // (`Commands::run` waits).
        unsafe {
            raw.destroy_descriptor_pool(self.pool, None);
            raw.destroy_pipeline_layout(self.layout, None);
            raw.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}

/// A compute pipeline with its layout and one descriptor set, all built
/// from the shader's reflected interface ([`ShaderInterface`]).
pub struct ComputePipeline {
    /// The layout, descriptor set and interface.
    pub resources: PipelineResources,
    /// The pipeline.
    pub raw: vk::Pipeline,
}

impl ComputePipeline {
    /// Creates the pipeline from SPIR-V words: its descriptor set layout and
    /// push-constant range are those the shader declares, and
    /// `specialization` sets constants by their ids (`SPEC_*` of
    /// `shader_interface`); an id the shader lacks is an error.
    pub fn new(device: &Arc<Device>, spirv: &[u32], specialization: &[(u32, u32)]) -> Result<Self, VkError> {
        let interface = ShaderInterface::reflect(spirv)?;
        let resources = PipelineResources::new(device, interface, vk::ShaderStageFlags::COMPUTE)?;
        let (mut entries, mut values) = (Vec::new(), Vec::new());
        let spec = resources.specialization(specialization, &mut entries, &mut values)?;
        let raw = &device.raw;
        // SAFETY: `raw` is the live device; `spirv` is a `&[u32]`, so its byte length is a multiple of 4, and
        // `ShaderInterface::reflect` parsed it above (the words are shaderc's output, compiled at build
        // time); the create info is a temporary alive for the call.
        let module = unsafe { raw.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(spirv), None) }?;
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec);
        let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(resources.layout)];
        // SAFETY: `info` -> `stage` -> `spec` -> `entries`/`values` are locals alive until the call returns;
        // `module` is live and its entry point is `main` (a `&'static CStr`); `resources.layout` was built
        // from this shader's reflected bindings and push constants, and the specialisation ids were checked
        // against the shader's.
        let created = unsafe { raw.create_compute_pipelines(vk::PipelineCache::null(), &info, None) };
        // SAFETY: a shader module may be destroyed once pipelines have been created from it; `module` was
        // created above, never shared, and is not used after this.
        unsafe { raw.destroy_shader_module(module, None) };
        let pipeline = created.map_err(|(_, e)| e)?[0];
        Ok(Self { resources, raw: pipeline })
    }

    /// Points the shader's bindings at resources ([`PipelineResources::bind`]).
    pub fn bind(&self, resources: &[(u32, Binding<'_>)]) -> Result<(), VkError> {
        self.resources.bind(resources)
    }

    /// Records binding the pipeline and set, pushing `constants` (exactly
    /// the shader's push-constant block), and a dispatch.
    pub fn dispatch(&self, cmd: vk::CommandBuffer, constants: &[u8], groups: [u32; 3]) {
        let raw = &self.resources.device.raw;
        // SAFETY: `cmd` is a recording command buffer of this device (the callers pass `rec.cmd`; the type
        // cannot check it); `self.raw` is a live compute pipeline owned by `self`; the queue family has
        // compute.
        unsafe { raw.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.raw) };
        self.resources.record(cmd, vk::PipelineBindPoint::COMPUTE, constants);
        // SAFETY: the pipeline, its descriptor set and push constants were bound just above; the resources
        // the set names are kept alive by the caller until `Commands::run` has waited for the submission.
        // Group counts within maxComputeWorkGroupCount are the caller's to respect (not checked).
        unsafe { raw.cmd_dispatch(cmd, groups[0], groups[1], groups[2]) };
    }

    /// Records binding the pipeline and set, pushing `constants`, and a
    /// dispatch whose workgroup counts the device reads from `args` at byte
    /// `offset` (three `u32`, written by earlier work: the caller's barrier
    /// names [`crate::vk::Access::IndirectRead`]). `args` needs
    /// `INDIRECT_BUFFER` usage.
    pub fn dispatch_indirect(&self, cmd: vk::CommandBuffer, constants: &[u8], args: &super::Buffer, offset: u64) {
        let raw = &self.resources.device.raw;
        // SAFETY: as in `dispatch`: a recording command buffer of this device and a live pipeline.
        unsafe { raw.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.raw) };
        self.resources.record(cmd, vk::PipelineBindPoint::COMPUTE, constants);
        // SAFETY: the pipeline, set and push constants are bound above; `args` is alive until the
        // submission has finished (the caller holds it across `Commands::run`, which waits), has
        // INDIRECT_BUFFER usage (the caller's) and holds three u32 at the 4-aligned `offset`.
        unsafe { raw.cmd_dispatch_indirect(cmd, args.raw, offset) };
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        // SAFETY: `self.raw` was created in `new` on the resources' device and is destroyed once, here,
        // before the `resources` field (with its layout) drops; no pending submission uses it, as
        // `Commands::run` waits before returning.
        unsafe { self.resources.device.raw.destroy_pipeline(self.raw, None) };
    }
}
