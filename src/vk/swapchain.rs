//! A swapchain presenting 8-bit pixels that the host writes: each frame is
//! copied from a host-visible buffer into the acquired image, then presented.
//!
//! The viewer's frames are tone-mapped on the host (the same code as the PNG
//! output), so the presented pixels and a screenshot's are the same bytes.

use std::sync::Arc;

use ash::vk;

use super::{Access, Buffer, Commands, Device, MemoryLocation, Surface, VkError};

/// What [`Swapchain::present`] found.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PresentResult {
    /// Presented and still matching the window.
    Presented,
    /// The swapchain no longer matches the window (resized): recreate it.
    OutOfDate,
}

/// A swapchain of `TRANSFER_DST` images and a staging buffer for one frame.
pub struct Swapchain {
    device: Arc<Device>,
    loader: ash::khr::swapchain::Device,
    raw: vk::SwapchainKHR,
    images: Vec<vk::Image>,
    /// Image size in pixels.
    pub extent: vk::Extent2D,
    /// Pixel format of the images (8 bits per channel, RGBA or BGRA order).
    pub format: vk::Format,
    staging: Buffer,
    acquired: vk::Fence,
}

impl Swapchain {
    /// Creates a swapchain on `surface` of about `width` x `height` pixels
    /// (the surface's own extent wins when it has one); `None` when the
    /// surface has no area (a minimised window).
    pub fn new(device: &Arc<Device>, surface: &Surface, (width, height): (u32, u32)) -> Result<Option<Self>, VkError> {
        let pd = device.physical;
        // SAFETY: `surface.loader` was loaded for the surface's instance, which enabled VK_KHR_surface;
        // `surface.raw` is alive (borrowed), and `pd` is `device`'s physical device, which must come from
        // that same instance (the viewer makes the device with `Device::for_surface` on it; not checked
        // here).
        let caps = unsafe { surface.loader.get_physical_device_surface_capabilities(pd, surface.raw) }?;
        let extent = if caps.current_extent.width != u32::MAX {
            caps.current_extent
        } else {
            vk::Extent2D {
                width: width.clamp(caps.min_image_extent.width, caps.max_image_extent.width),
                height: height.clamp(caps.min_image_extent.height, caps.max_image_extent.height),
            }
        };
        if extent.width == 0 || extent.height == 0 {
            return Ok(None);
        }
        if !caps.supported_usage_flags.contains(vk::ImageUsageFlags::TRANSFER_DST) {
            return Err(VkError::Vk(vk::Result::ERROR_FEATURE_NOT_PRESENT));
        }
        // SAFETY: as above.
        let formats = unsafe { surface.loader.get_physical_device_surface_formats(pd, surface.raw) }?;
        let byte_formats = [
            vk::Format::B8G8R8A8_UNORM,
            vk::Format::R8G8B8A8_UNORM,
            vk::Format::B8G8R8A8_SRGB,
            vk::Format::R8G8B8A8_SRGB,
        ];
        let chosen = byte_formats
            .iter()
            .find_map(|f| formats.iter().find(|s| s.format == *f))
            .copied()
            .ok_or(VkError::Vk(vk::Result::ERROR_FORMAT_NOT_SUPPORTED))?;
        // SAFETY: as above.
        let modes = unsafe { surface.loader.get_physical_device_surface_present_modes(pd, surface.raw) }?;
        // Mailbox never blocks on a display refresh; FIFO is always there.
        let mode = if modes.contains(&vk::PresentModeKHR::MAILBOX) {
            vk::PresentModeKHR::MAILBOX
        } else {
            vk::PresentModeKHR::FIFO
        };
        let mut count = caps.min_image_count + 1;
        if caps.max_image_count > 0 {
            count = count.min(caps.max_image_count);
        }
        let info = vk::SwapchainCreateInfoKHR::default()
            .surface(surface.raw)
            .min_image_count(count)
            .image_format(chosen.format)
            .image_color_space(chosen.color_space)
            .image_extent(extent)
            .image_array_layers(1)
            .image_usage(vk::ImageUsageFlags::TRANSFER_DST)
            .image_sharing_mode(vk::SharingMode::EXCLUSIVE)
            .pre_transform(caps.current_transform)
            .composite_alpha(vk::CompositeAlphaFlagsKHR::OPAQUE)
            .present_mode(mode)
            .clipped(true);
        let loader = ash::khr::swapchain::Device::new(&device.instance.raw, &device.raw);
        // SAFETY: `loader` was loaded for `device.raw`, which must have enabled VK_KHR_swapchain and be able
        // to present to `surface` from its queue family: `Device::for_surface` ensures both; nothing here
        // checks it for a device from `Device::new`. `info` is a local without pNext: a format and colour
        // space the surface reports, extent and image count within its limits, TRANSFER_DST usage (checked
        // above), FIFO or a reported present mode, the current transform. OPAQUE composite alpha is assumed,
        // not checked against `supported_composite_alpha`.
        let raw = unsafe { loader.create_swapchain(&info, None) }?;
        // SAFETY: `raw` was just created by `loader` and is alive.
        let images = match unsafe { loader.get_swapchain_images(raw) } {
            Ok(i) => i,
            Err(e) => {
                // SAFETY: `raw` was created above, no image of it was acquired, and it is not used after
                // this.
                unsafe { loader.destroy_swapchain(raw, None) };
                return Err(e.into());
            }
        };
        // SAFETY: `device.raw` is alive; the create info is a default one (unsignalled, no pNext), alive for
        // the call.
        let acquired = unsafe { device.raw.create_fence(&vk::FenceCreateInfo::default(), None) };
        let acquired = match acquired {
            Ok(f) => f,
            Err(e) => {
                // SAFETY: as above: no image of `raw` was acquired, and it is not used after this.
                unsafe { loader.destroy_swapchain(raw, None) };
                return Err(e.into());
            }
        };
        let staging = Buffer::new(
            device,
            "swapchain staging",
            extent.width as u64 * extent.height as u64 * 4,
            vk::BufferUsageFlags::TRANSFER_SRC,
            MemoryLocation::CpuToGpu,
        );
        let staging = match staging {
            Ok(b) => b,
            Err(e) => {
                // SAFETY: the fence and the swapchain were created above, never waited on or acquired from,
                // and are not used after this.
                unsafe {
                    device.raw.destroy_fence(acquired, None);
                    loader.destroy_swapchain(raw, None);
                }
                return Err(e);
            }
        };
        log::info!(
            "swapchain: {}x{} {:?}, {:?}, {} images",
            extent.width,
            extent.height,
            chosen.format,
            mode,
            images.len()
        );
        Ok(Some(Self { device: device.clone(), loader, raw, images, extent, format: chosen.format, staging, acquired }))
    }

    /// Presents `rgba` (8-bit sRGB-encoded RGBA, row 0 at the top, exactly
    /// the swapchain's extent) in the next image.
    pub fn present(&mut self, cmds: &mut Commands, rgba: &[u8]) -> Result<PresentResult, VkError> {
        let (w, h) = (self.extent.width as usize, self.extent.height as usize);
        assert_eq!(rgba.len(), w * h * 4, "frame size does not match the swapchain");
        // SAFETY: `self.raw` is owned by `self` and alive; `self.acquired` is unsignalled (created so,
        // and reset after every wait below) and in use by nothing else; a fence without a semaphore is
        // allowed. On success each acquired image is presented below before the next acquire, so at most
        // one is held and the infinite timeout cannot wait forever.
        let acquire =
            unsafe { self.loader.acquire_next_image(self.raw, u64::MAX, vk::Semaphore::null(), self.acquired) };
        let index = match acquire {
            Ok((index, _suboptimal)) => index,
            Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => return Ok(PresentResult::OutOfDate),
            Err(e) => return Err(e.into()),
        };
        // SAFETY: `self.acquired` is the live fence just given to the successful acquire; once waited for it
        // is in use by nothing, so it may be reset, leaving it unsignalled for the next acquire.
        unsafe {
            self.device.raw.wait_for_fences(&[self.acquired], true, u64::MAX)?;
            self.device.raw.reset_fences(&[self.acquired])?;
        }
        if matches!(self.format, vk::Format::B8G8R8A8_UNORM | vk::Format::B8G8R8A8_SRGB) {
            let mut bgra = rgba.to_vec();
            for p in bgra.chunks_exact_mut(4) {
                p.swap(0, 2);
            }
            self.staging.write(0, &bgra);
        } else {
            self.staging.write(0, rgba);
        }
        let image = self.images[index as usize];
        let (staging, extent) = (&self.staging, self.extent);
        let copy = [Access::TransferWrite];
        let whole =
            vk::ImageSubresourceRange::default().aspect_mask(vk::ImageAspectFlags::COLOR).level_count(1).layer_count(1);
        cmds.run(|rec| {
            // Acquired through a fence that was waited on: nothing before
            // the copy touches the image; the presentation engine reads it
            // after the queue has finished (no access to name).
            rec.image_barrier(
                image,
                whole,
                (&[], vk::ImageLayout::UNDEFINED),
                (&copy, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
            );
            let region = vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D { width: extent.width, height: extent.height, depth: 1 });
            // SAFETY: the image is the swapchain's, acquired above; the
            // staging buffer outlives the submission (run waits).
            unsafe {
                rec.device.cmd_copy_buffer_to_image(
                    rec.cmd,
                    staging.raw,
                    image,
                    vk::ImageLayout::TRANSFER_DST_OPTIMAL,
                    &[region],
                )
            };
            rec.image_barrier(
                image,
                whole,
                (&copy, vk::ImageLayout::TRANSFER_DST_OPTIMAL),
                (&[], vk::ImageLayout::PRESENT_SRC_KHR),
            );
        })?;
        // The copy has finished (Commands::run waited): no semaphore needed.
        let swapchains = [self.raw];
        let indices = [index];
        let info = vk::PresentInfoKHR::default().swapchains(&swapchains).image_indices(&indices);
        // SAFETY: `self.device.queue` is from a family that can present to this surface
        // (`Device::for_surface` checked it); image `index` was acquired above and moved to PRESENT_SRC_KHR
        // by the submission that `Commands::run` waited for, so no semaphore is needed; `info` ->
        // `swapchains`, `indices` are locals alive for the call. As for every submission here, no other
        // thread may use the queue meanwhile (nothing locks it).
        match unsafe { self.loader.queue_present(self.device.queue, &info) } {
            Ok(false) => Ok(PresentResult::Presented),
            Ok(true) | Err(vk::Result::ERROR_OUT_OF_DATE_KHR) => Ok(PresentResult::OutOfDate),
            Err(e) => Err(e.into()),
        }
    }
}

impl Drop for Swapchain {
    fn drop(&mut self) {
        // SAFETY: after device_wait_idle nothing uses the fence or the swapchain's images; both were created
        // in `new` on `self.device` (a field, alive here) and are destroyed once, here. The surface is still
        // alive: its owner drops it after the swapchain (see `Surface`'s Drop).
        unsafe {
            let _ = self.device.raw.device_wait_idle();
            self.device.raw.destroy_fence(self.acquired, None);
            self.loader.destroy_swapchain(self.raw, None);
        }
    }
}
