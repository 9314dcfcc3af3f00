//! Compute pipelines with one descriptor set and a push-constant block.

use std::sync::Arc;

use ash::vk;

use super::{AccelerationStructure, Buffer, Device, Image, Sampler, VkError};

/// What a descriptor binding holds.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum BindingKind {
    /// A top-level acceleration structure.
    AccelerationStructure,
    /// A storage buffer.
    StorageBuffer,
    /// A storage image (GENERAL layout).
    StorageImage,
    /// An array of this many combined image samplers (SHADER_READ_ONLY_OPTIMAL).
    SampledImages(u32),
}

impl BindingKind {
    fn descriptor_type(self) -> vk::DescriptorType {
        match self {
            Self::AccelerationStructure => vk::DescriptorType::ACCELERATION_STRUCTURE_KHR,
            Self::StorageBuffer => vk::DescriptorType::STORAGE_BUFFER,
            Self::StorageImage => vk::DescriptorType::STORAGE_IMAGE,
            Self::SampledImages(_) => vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        }
    }

    fn count(self) -> u32 {
        match self {
            Self::SampledImages(n) => n,
            _ => 1,
        }
    }
}

/// A resource bound at one binding.
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

/// A compute pipeline, its layout, and one descriptor set.
pub struct ComputePipeline {
    device: Arc<Device>,
    /// The pipeline.
    pub raw: vk::Pipeline,
    /// The pipeline layout.
    pub layout: vk::PipelineLayout,
    set_layout: vk::DescriptorSetLayout,
    pool: vk::DescriptorPool,
    /// The descriptor set (binding i holds `bindings[i]`).
    pub set: vk::DescriptorSet,
    bindings: Vec<BindingKind>,
}

impl ComputePipeline {
    /// Creates the pipeline from SPIR-V words, with descriptor bindings
    /// `0..bindings.len()` of the given kinds and `push_constant_size` bytes
    /// of push constants.
    pub fn new(
        device: &Arc<Device>,
        spirv: &[u32],
        bindings: &[BindingKind],
        push_constant_size: u32,
        specialization: &[u32],
    ) -> Result<Self, VkError> {
        let raw = &device.raw;
        let layout_bindings: Vec<_> = bindings
            .iter()
            .enumerate()
            .map(|(i, k)| {
                vk::DescriptorSetLayoutBinding::default()
                    .binding(i as u32)
                    .descriptor_type(k.descriptor_type())
                    .descriptor_count(k.count())
                    .stage_flags(vk::ShaderStageFlags::COMPUTE)
            })
            .collect();
        let mut this = Self {
            device: device.clone(),
            raw: vk::Pipeline::null(),
            layout: vk::PipelineLayout::null(),
            set_layout: vk::DescriptorSetLayout::null(),
            pool: vk::DescriptorPool::null(),
            set: vk::DescriptorSet::null(),
            bindings: bindings.to_vec(),
        };
        // From here on, `this` owns what is created and Drop cleans up on error.
        this.set_layout = unsafe {
            raw.create_descriptor_set_layout(
                &vk::DescriptorSetLayoutCreateInfo::default().bindings(&layout_bindings),
                None,
            )
        }?;
        let ranges = [vk::PushConstantRange::default()
            .stage_flags(vk::ShaderStageFlags::COMPUTE)
            .offset(0)
            .size(push_constant_size)];
        let set_layouts = [this.set_layout];
        let mut layout_info = vk::PipelineLayoutCreateInfo::default().set_layouts(&set_layouts);
        if push_constant_size > 0 {
            layout_info = layout_info.push_constant_ranges(&ranges);
        }
        this.layout = unsafe { raw.create_pipeline_layout(&layout_info, None) }?;

        let module = unsafe { raw.create_shader_module(&vk::ShaderModuleCreateInfo::default().code(spirv), None) }?;
        let entries: Vec<_> = (0..specialization.len())
            .map(|i| vk::SpecializationMapEntry { constant_id: i as u32, offset: 4 * i as u32, size: 4 })
            .collect();
        let spec_data: &[u8] = bytemuck::cast_slice(specialization);
        let spec = vk::SpecializationInfo::default().map_entries(&entries).data(spec_data);
        let stage = vk::PipelineShaderStageCreateInfo::default()
            .stage(vk::ShaderStageFlags::COMPUTE)
            .module(module)
            .name(c"main")
            .specialization_info(&spec);
        let info = [vk::ComputePipelineCreateInfo::default().stage(stage).layout(this.layout)];
        let created = unsafe { raw.create_compute_pipelines(vk::PipelineCache::null(), &info, None) };
        unsafe { raw.destroy_shader_module(module, None) };
        this.raw = created.map_err(|(_, e)| e)?[0];

        let mut sizes: Vec<vk::DescriptorPoolSize> = Vec::new();
        for k in bindings {
            let ty = k.descriptor_type();
            match sizes.iter_mut().find(|s| s.ty == ty) {
                Some(s) => s.descriptor_count += k.count(),
                None => sizes.push(vk::DescriptorPoolSize { ty, descriptor_count: k.count() }),
            }
        }
        this.pool = unsafe {
            raw.create_descriptor_pool(&vk::DescriptorPoolCreateInfo::default().max_sets(1).pool_sizes(&sizes), None)
        }?;
        this.set = unsafe {
            raw.allocate_descriptor_sets(
                &vk::DescriptorSetAllocateInfo::default().descriptor_pool(this.pool).set_layouts(&set_layouts),
            )
        }?[0];
        Ok(this)
    }

    /// Points every binding at its resource (`resources[i]` for binding i).
    pub fn bind(&self, resources: &[Binding<'_>]) {
        assert_eq!(resources.len(), self.bindings.len(), "one resource per binding");
        let mut buffer_infos = Vec::new();
        let mut image_infos = Vec::new();
        let mut as_handles = Vec::new();
        for r in resources {
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
        let (mut bi, mut ii, mut ai) = (0, 0, 0);
        let mut as_iter = as_infos.iter_mut();
        for (i, r) in resources.iter().enumerate() {
            let base = vk::WriteDescriptorSet::default().dst_set(self.set).dst_binding(i as u32);
            match (r, self.bindings[i]) {
                (Binding::Buffer(_), BindingKind::StorageBuffer) => {
                    writes
                        .push(base.descriptor_type(vk::DescriptorType::STORAGE_BUFFER).buffer_info(&buffer_infos[bi]));
                    bi += 1;
                }
                (Binding::Textures(images, _), BindingKind::SampledImages(n)) => {
                    assert_eq!(images.len(), n as usize, "binding {i}: one image per array element");
                    writes.push(
                        base.descriptor_type(vk::DescriptorType::COMBINED_IMAGE_SAMPLER).image_info(&image_infos[ii]),
                    );
                    ii += 1;
                }
                (Binding::Image(_), BindingKind::StorageImage) => {
                    writes.push(base.descriptor_type(vk::DescriptorType::STORAGE_IMAGE).image_info(&image_infos[ii]));
                    ii += 1;
                }
                (Binding::AccelerationStructure(_), BindingKind::AccelerationStructure) => {
                    // The count must be explicit: it is not implied by a pNext chain
                    // (lavapipe silently skips the write without it).
                    let info = as_iter.next().expect("one info per acceleration structure");
                    writes.push(
                        base.descriptor_type(vk::DescriptorType::ACCELERATION_STRUCTURE_KHR)
                            .descriptor_count(1)
                            .push_next(info),
                    );
                    ai += 1;
                }
                _ => panic!("binding {i}: resource kind does not match the layout"),
            }
        }
        debug_assert_eq!(ai, as_handles.len());
        unsafe { self.device.raw.update_descriptor_sets(&writes, &[]) };
    }

    /// Records binding the pipeline and set, pushing `constants`, and a dispatch.
    pub fn dispatch(&self, cmd: vk::CommandBuffer, constants: &[u8], groups: [u32; 3]) {
        let raw = &self.device.raw;
        unsafe {
            raw.cmd_bind_pipeline(cmd, vk::PipelineBindPoint::COMPUTE, self.raw);
            raw.cmd_bind_descriptor_sets(cmd, vk::PipelineBindPoint::COMPUTE, self.layout, 0, &[self.set], &[]);
            if !constants.is_empty() {
                raw.cmd_push_constants(cmd, self.layout, vk::ShaderStageFlags::COMPUTE, 0, constants);
            }
            raw.cmd_dispatch(cmd, groups[0], groups[1], groups[2]);
        }
    }
}

impl Drop for ComputePipeline {
    fn drop(&mut self) {
        let raw = &self.device.raw;
        unsafe {
            raw.destroy_descriptor_pool(self.pool, None);
            raw.destroy_pipeline(self.raw, None);
            raw.destroy_pipeline_layout(self.layout, None);
            raw.destroy_descriptor_set_layout(self.set_layout, None);
        }
    }
}
