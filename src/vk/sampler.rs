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
        let raw = unsafe { device.raw.create_sampler(&info, None) }?;
        Ok(Self { device: device.clone(), raw })
    }
}

impl Drop for Sampler {
    fn drop(&mut self) {
        unsafe { self.device.raw.destroy_sampler(self.raw, None) };
    }
}
