//! 2D images with one view, owning their memory.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::{Buffer, Device, VkError};

/// A 2D image (one mip level, one layer) with a view, freed on drop.
pub struct Image {
    device: Arc<Device>,
    /// The image handle.
    pub raw: vk::Image,
    /// A view of the whole image.
    pub view: vk::ImageView,
    allocation: Option<Allocation>,
    /// Pixel format.
    pub format: vk::Format,
    /// Size in pixels of level 0.
    pub extent: vk::Extent2D,
    /// Number of mip levels.
    pub levels: u32,
}

impl Image {
    /// Creates a device-local image of `format` and `usage`, in layout UNDEFINED.
    pub fn new(
        device: &Arc<Device>,
        name: &str,
        extent: vk::Extent2D,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self, VkError> {
        Self::with_levels(device, name, extent, 1, format, usage)
    }

    /// Creates a device-local image with `levels` mip levels, in layout UNDEFINED.
    pub fn with_levels(
        device: &Arc<Device>,
        name: &str,
        extent: vk::Extent2D,
        levels: u32,
        format: vk::Format,
        usage: vk::ImageUsageFlags,
    ) -> Result<Self, VkError> {
        let info = vk::ImageCreateInfo::default()
            .image_type(vk::ImageType::TYPE_2D)
            .format(format)
            .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
            .mip_levels(levels)
            .array_layers(1)
            .samples(vk::SampleCountFlags::TYPE_1)
            .tiling(vk::ImageTiling::OPTIMAL)
            .usage(usage)
            .sharing_mode(vk::SharingMode::EXCLUSIVE)
            .initial_layout(vk::ImageLayout::UNDEFINED);
        let raw = unsafe { device.raw.create_image(&info, None) }?;
        let mut this =
            Self { device: device.clone(), raw, view: vk::ImageView::null(), allocation: None, format, extent, levels };
        let requirements = unsafe { device.raw.get_image_memory_requirements(raw) };
        let allocation = device
            .allocator
            .lock()
            .expect("allocator lock")
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location: MemoryLocation::GpuOnly,
                linear: false,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })
            .map_err(|e| VkError::Allocation(format!("{name}: {e}")))?;
        unsafe { device.raw.bind_image_memory(raw, allocation.memory(), allocation.offset()) }?;
        this.allocation = Some(allocation);
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(this.all_levels());
        this.view = unsafe { device.raw.create_image_view(&view_info, None) }?;
        Ok(this)
    }

    fn all_levels(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .level_count(self.levels)
            .layer_count(1)
    }

    /// Records copying `buffer` into every mip level (tightly packed, level
    /// after level, starting at byte 0) and leaves the image in
    /// SHADER_READ_ONLY_OPTIMAL. `texel_bytes` is the size of one texel.
    pub fn upload_levels(&self, cmd: vk::CommandBuffer, buffer: &Buffer, texel_bytes: u64) {
        self.transition(cmd, vk::ImageLayout::UNDEFINED, vk::ImageLayout::TRANSFER_DST_OPTIMAL);
        let mut offset = 0u64;
        let regions: Vec<vk::BufferImageCopy> = (0..self.levels)
            .map(|level| {
                let w = (self.extent.width >> level).max(1);
                let h = (self.extent.height >> level).max(1);
                let region = vk::BufferImageCopy::default()
                    .buffer_offset(offset)
                    .image_subresource(
                        vk::ImageSubresourceLayers::default()
                            .aspect_mask(vk::ImageAspectFlags::COLOR)
                            .mip_level(level)
                            .layer_count(1),
                    )
                    .image_extent(vk::Extent3D { width: w, height: h, depth: 1 });
                offset += w as u64 * h as u64 * texel_bytes;
                region
            })
            .collect();
        unsafe {
            self.device.raw.cmd_copy_buffer_to_image(
                cmd,
                buffer.raw,
                self.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                &regions,
            )
        };
        self.transition(cmd, vk::ImageLayout::TRANSFER_DST_OPTIMAL, vk::ImageLayout::SHADER_READ_ONLY_OPTIMAL);
    }

    /// Records a transition from `from` to `to`, making all earlier
    /// compute and transfer writes visible to later compute and transfer work.
    pub fn transition(&self, cmd: vk::CommandBuffer, from: vk::ImageLayout, to: vk::ImageLayout) {
        let access = vk::AccessFlags::SHADER_READ
            | vk::AccessFlags::SHADER_WRITE
            | vk::AccessFlags::TRANSFER_READ
            | vk::AccessFlags::TRANSFER_WRITE;
        let barrier = vk::ImageMemoryBarrier::default()
            .src_access_mask(access)
            .dst_access_mask(access)
            .old_layout(from)
            .new_layout(to)
            .src_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .dst_queue_family_index(vk::QUEUE_FAMILY_IGNORED)
            .image(self.raw)
            .subresource_range(self.all_levels());
        let stages = vk::PipelineStageFlags::COMPUTE_SHADER | vk::PipelineStageFlags::TRANSFER;
        unsafe {
            self.device.raw.cmd_pipeline_barrier(
                cmd,
                stages,
                stages,
                vk::DependencyFlags::empty(),
                &[],
                &[],
                &[barrier],
            )
        };
    }

    /// Records clearing the (GENERAL layout) image to zero.
    pub fn clear(&self, cmd: vk::CommandBuffer) {
        let zero = vk::ClearColorValue { float32: [0.0; 4] };
        unsafe {
            self.device.raw.cmd_clear_color_image(cmd, self.raw, vk::ImageLayout::GENERAL, &zero, &[self.all_levels()])
        };
    }

    /// Records copying the image, in `layout` (GENERAL or TRANSFER_SRC_OPTIMAL),
    /// into `buffer`, tightly packed.
    pub fn copy_to_buffer(&self, cmd: vk::CommandBuffer, layout: vk::ImageLayout, buffer: &Buffer) {
        let region = vk::BufferImageCopy::default()
            .image_subresource(
                vk::ImageSubresourceLayers::default().aspect_mask(vk::ImageAspectFlags::COLOR).layer_count(1),
            )
            .image_extent(vk::Extent3D { width: self.extent.width, height: self.extent.height, depth: 1 });
        unsafe { self.device.raw.cmd_copy_image_to_buffer(cmd, self.raw, layout, buffer.raw, &[region]) };
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        unsafe {
            if self.view != vk::ImageView::null() {
                self.device.raw.destroy_image_view(self.view, None);
            }
            self.device.raw.destroy_image(self.raw, None);
        }
        if let Some(a) = self.allocation.take() {
            let _ = self.device.allocator.lock().map(|mut al| al.free(a));
        }
    }
}
