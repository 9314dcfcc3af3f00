//! 2D images with one view, owning their memory.

use std::sync::Arc;

use ash::vk;
use gpu_allocator::vulkan::{Allocation, AllocationCreateDesc, AllocationScheme};
use gpu_allocator::MemoryLocation;

use super::{Access, Buffer, Device, Recording, VkError};

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

/// A 2D, single-layer, optimally tiled image of `levels` mip levels.
fn image_info(
    extent: vk::Extent2D,
    levels: u32,
    format: vk::Format,
    usage: vk::ImageUsageFlags,
) -> vk::ImageCreateInfo<'static> {
    vk::ImageCreateInfo::default()
        .image_type(vk::ImageType::TYPE_2D)
        .format(format)
        .extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 })
        .mip_levels(levels)
        .array_layers(1)
        .samples(vk::SampleCountFlags::TYPE_1)
        .tiling(vk::ImageTiling::OPTIMAL)
        .usage(usage)
        .sharing_mode(vk::SharingMode::EXCLUSIVE)
        .initial_layout(vk::ImageLayout::UNDEFINED)
}

impl Image {
    /// A device-local storage image of `format` that transfers can fill and
    /// read back, in layout UNDEFINED.
    pub fn storage(
        device: &Arc<Device>,
        name: &str,
        extent: vk::Extent2D,
        format: vk::Format,
    ) -> Result<Self, VkError> {
        let usage =
            vk::ImageUsageFlags::STORAGE | vk::ImageUsageFlags::TRANSFER_SRC | vk::ImageUsageFlags::TRANSFER_DST;
        Self::new(device, name, extent, format, usage)
    }

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
        let info = image_info(extent, levels, format, usage);
        // SAFETY: `device.raw` is alive; `info` (from `image_info`, no pNext) is a 2D, single-layer,
        // optimally tiled image in layout UNDEFINED. That `format` supports `usage` at this extent and level
        // count is the caller's choice, not checked here (the scene's textures are checked with
        // `Image::memory_bytes` first).
        let raw = unsafe { device.raw.create_image(&info, None) }?;
        let mut this =
            Self { device: device.clone(), raw, view: vk::ImageView::null(), allocation: None, format, extent, levels };
        // SAFETY: `raw` was just created on this device; `this` owns it from here on and destroys it on every
        // error path.
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
        // SAFETY: `allocation` was made by this device's allocator from `raw`'s own requirements, so memory
        // type, size and offset alignment fit, and `raw` has no memory bound yet.
        unsafe { device.raw.bind_image_memory(raw, allocation.memory(), allocation.offset()) }?;
        this.allocation = Some(allocation);
        let view_info = vk::ImageViewCreateInfo::default()
            .image(raw)
            .view_type(vk::ImageViewType::TYPE_2D)
            .format(format)
            .subresource_range(this.all_levels());
        // SAFETY: `raw` is live and now bound to memory; the view has the image's format and 2D type and
        // covers its `levels` levels and one layer of the COLOR aspect; `view_info` lives until the call
        // returns. On error `this` drops, destroying the image and freeing its memory.
        this.view = unsafe { device.raw.create_image_view(&view_info, None) }?;
        Ok(this)
    }

    fn all_levels(&self) -> vk::ImageSubresourceRange {
        vk::ImageSubresourceRange::default()
            .aspect_mask(vk::ImageAspectFlags::COLOR)
            .level_count(self.levels)
            .layer_count(1)
    }

    /// The device memory an image of this shape would take, without
    /// allocating it; `None` if the device cannot make such an image at all
    /// (beyond the format's largest extent, levels or resource size).
    /// `texel_bytes` is the size of one texel of `format`.
    pub fn memory_bytes(
        device: &Device,
        extent: vk::Extent2D,
        levels: u32,
        format: vk::Format,
        texel_bytes: u64,
        usage: vk::ImageUsageFlags,
    ) -> Result<Option<u64>, VkError> {
        // SAFETY: `device.physical` is the physical device `device.raw` was made on, from the live
        // `device.instance`; the other arguments are plain values.
        let limits = unsafe {
            device.instance.raw.get_physical_device_image_format_properties(
                device.physical,
                format,
                vk::ImageType::TYPE_2D,
                vk::ImageTiling::OPTIMAL,
                usage,
                vk::ImageCreateFlags::empty(),
            )
        };
        let limits = match limits {
            Ok(l) => l,
            Err(vk::Result::ERROR_FORMAT_NOT_SUPPORTED) => return Ok(None),
            Err(e) => return Err(e.into()),
        };
        let level0 = extent.width as u64 * extent.height as u64 * texel_bytes;
        if extent.width > limits.max_extent.width
            || extent.height > limits.max_extent.height
            || levels > limits.max_mip_levels
            || level0 > limits.max_resource_size
        {
            return Ok(None);
        }
        let info = image_info(extent, levels, format, usage);
        // A device that cannot even describe the image (out of memory for
        // its bookkeeping, say) cannot make it: not an error, a "no".
        // SAFETY: as in `with_levels`: a live device and a local create info; the format supports `usage`
        // (the query above succeeded) and the extent and level count are within its limits (checked just
        // above).
        let Ok(raw) = (unsafe { device.raw.create_image(&info, None) }) else { return Ok(None) };
        // SAFETY: `raw` was just created on this device; it is destroyed on the next line.
        let size = unsafe { device.raw.get_image_memory_requirements(raw) }.size;
        // SAFETY: `raw` was never bound to memory nor used by any command, and is not used after this.
        unsafe { device.raw.destroy_image(raw, None) };
        Ok((size <= limits.max_resource_size).then_some(size))
    }

    /// A copy of `rows` rows of mip `level`, from row `first_row` on, packed
    /// tightly in a buffer from byte `buffer_offset`.
    pub fn rows_region(&self, level: u32, first_row: u32, rows: u32, buffer_offset: u64) -> vk::BufferImageCopy {
        let w = (self.extent.width >> level).max(1);
        vk::BufferImageCopy::default()
            .buffer_offset(buffer_offset)
            .image_subresource(
                vk::ImageSubresourceLayers::default()
                    .aspect_mask(vk::ImageAspectFlags::COLOR)
                    .mip_level(level)
                    .layer_count(1),
            )
            .image_offset(vk::Offset3D { x: 0, y: first_row as i32, z: 0 })
            .image_extent(vk::Extent3D { width: w, height: rows, depth: 1 })
    }

    /// Records copying `regions` of `buffer` into the image, which must be in
    /// TRANSFER_DST_OPTIMAL.
    pub fn copy_from_buffer(&self, cmd: vk::CommandBuffer, buffer: &Buffer, regions: &[vk::BufferImageCopy]) {
        // SAFETY: this rests on the caller, as this safe function cannot check it: `cmd` is a command buffer
        // of this device in the recording state (the callers pass `rec.cmd` inside `Commands::run`), the
        // image is in TRANSFER_DST_OPTIMAL with TRANSFER_DST usage, `buffer` has TRANSFER_SRC usage, and the
        // regions lie inside both. Both are borrowed here and kept alive by the caller until `run` has waited
        // for the submission.
        unsafe {
            self.device.raw.cmd_copy_buffer_to_image(
                cmd,
                buffer.raw,
                self.raw,
                vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                regions,
            )
        };
    }

    /// Records a barrier over every level of the image from the accesses
    /// `prev` in layout `from` to the accesses `next` in layout `to` (a
    /// layout transition where they differ).
    pub fn transition(&self, rec: Recording<'_>, from: (&[Access], vk::ImageLayout), to: (&[Access], vk::ImageLayout)) {
        rec.image_barrier(self.raw, self.all_levels(), from, to);
    }

    /// Records clearing the (GENERAL layout) image to zero.
    pub fn clear(&self, cmd: vk::CommandBuffer) {
        let zero = vk::ClearColorValue { float32: [0.0; 4] };
        // SAFETY: `cmd` is a recording command buffer of this device (the callers pass `rec.cmd`; not
        // checked), the image is in GENERAL layout with TRANSFER_DST usage (`Image::storage` gives it), and
        // the range covers exactly its levels and layer; the caller keeps `self` alive until `Commands::run`
        // has waited for the submission.
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
        // SAFETY: as for `copy_from_buffer`, on the caller's word: `cmd` is recording on this device, the
        // image is in `layout` with TRANSFER_SRC usage, `buffer` has TRANSFER_DST usage and room for level 0
        // tightly packed; both stay alive until the submission has finished.
        unsafe { self.device.raw.cmd_copy_image_to_buffer(cmd, self.raw, layout, buffer.raw, &[region]) };
    }
}

impl Drop for Image {
    fn drop(&mut self) {
        // SAFETY: the view and the image were created by `with_levels` on `self.device` and are destroyed
        // once, here, the view before its image (a null view, left by a failed `with_levels`, is skipped); no
        // pending submission uses them, as `Commands::run` waits before returning. The memory is freed after
        // the image is gone, and `self.device` (a field) outlives this body.
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
