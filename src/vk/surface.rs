//! A window's Vulkan surface (`VK_KHR_surface`), destroyed on drop.

use std::sync::Arc;

use ash::vk;
use raw_window_handle::{RawDisplayHandle, RawWindowHandle};

use super::{Instance, VkError};

/// The instance extensions a surface on `display` needs (for
/// [`Instance::with_extensions`]).
pub fn surface_extensions(display: RawDisplayHandle) -> Result<Vec<*const std::ffi::c_char>, VkError> {
    Ok(ash_window::enumerate_required_extensions(display)?.to_vec())
}

/// A surface of one window.
pub struct Surface {
    // Held so the instance outlives the surface.
    _instance: Arc<Instance>,
    /// `VK_KHR_surface` entry points.
    pub loader: ash::khr::surface::Instance,
    /// The surface.
    pub raw: vk::SurfaceKHR,
}

impl Surface {
    /// Creates a surface for the window `window` on `display`. The window
    /// must outlive the surface.
    pub fn new(instance: &Arc<Instance>, display: RawDisplayHandle, window: RawWindowHandle) -> Result<Self, VkError> {
        // SAFETY: `instance.entry` and `instance.raw` are alive (the Arc is held, then kept in `Self`); the
        // instance must have been created with `surface_extensions(display)`, as the viewer does. `display`
        // and `window` must be valid handles of a live window that outlives this surface: documented above,
        // but this safe function cannot check it (the viewer drops the surface before the window).
        let raw = unsafe { ash_window::create_surface(&instance.entry, &instance.raw, display, window, None) }?;
        let loader = ash::khr::surface::Instance::new(&instance.entry, &instance.raw);
        Ok(Self { _instance: instance.clone(), loader, raw })
    }

    /// True when queue family `family` of `pd` can present to this surface.
    pub fn supports_presenting(&self, pd: vk::PhysicalDevice, family: u32) -> bool {
        // SAFETY: `self.raw` is alive; the callers pass a `pd` enumerated from the same instance and the
        // index of one of its queue families (`surface_shortcomings`), neither checked here.
        unsafe { self.loader.get_physical_device_surface_support(pd, family, self.raw) }.unwrap_or(false)
    }
}

impl Drop for Surface {
    fn drop(&mut self) {
        // SAFETY: `self.raw` was created in `new` and is destroyed once, here, while `_instance` (a field,
        // dropped after this body) keeps the instance alive. Every swapchain on the surface must be gone
        // first: `Swapchain` does not hold the surface, so this rests on the owner's field order (the
        // viewer's `WindowGpu` drops its swapchain first).
        unsafe { self.loader.destroy_surface(self.raw, None) };
    }
}
