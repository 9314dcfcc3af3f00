//! Texture samplers.

use std::sync::Arc;

use ash::vk;

use super::{Device, VkError};

/// A sampler, destroyed on drop.
pub struct Sampler {
    device: Arc<Device>,
    /// The handle.
    pub raw: vk::Sampler,
}

impl Sampler {
    /// A sampler with linear filtering within and between mip levels and
    /// repeating addressing (shaders pick levels explicitly with textureLod).
    pub fn linear_repeat(device: &Arc<Device>) -> Result<Self, VkError> {
        let info = vk::SamplerCreateInfo::default()
            .mag_filter(vk::Filter::LINEAR)
            .min_filter(vk::Filter::LINEAR)
            .mipmap_mode(vk::SamplerMipmapMode::LINEAR)
            .address_mode_u(vk::SamplerAddressMode::REPEAT)
            .address_mode_v(vk::SamplerAddressMode::REPEAT)
            .address_mode_w(vk::SamplerAddressMode::REPEAT)
            .min_lod(0.0)
            .max_lod(vk::LOD_CLAMP_NONE);
        // SAFETY: `device.raw` is alive; `info` is a local without pNext: linear filtering, repeat
        // addressing, no anisotropy or compare, so it needs no feature.
        let raw = unsafe { device.raw.create_sampler(&info, None) }?;
        Ok(Self { device: device.clone(), raw })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        // SAFETY: `self.raw` was created in `linear_repeat` on `self.device` (a field, so alive here) and is
        // destroyed once, here; no pending submission uses it, as `Commands::run` waits before returning.
        unsafe { self.device.raw.destroy_sampler(self.raw, None) };
    }
}
