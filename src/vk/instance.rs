//! The Vulkan instance, with the Khronos validation layer and a debug
//! messenger that routes messages to `log` and counts errors.

use std::ffi::{c_void, CStr};
use std::sync::atomic::{AtomicUsize, Ordering};
use std::sync::Arc;

use ash::vk;

use super::VkError;

/// The command that installs a driver with ray queries.
pub const SETUP_HINT: &str =
    "run `make setup` (installs Mesa's lavapipe with VK_KHR_ray_query from bookworm-backports on Debian 12)";

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Counts of validation messages by severity, shared with the messenger
/// callback and readable after the instance is gone (leaks are reported
/// when the device is destroyed).
#[derive(Debug, Default)]
pub struct ValidationCounters {
    errors: AtomicUsize,
    warnings: AtomicUsize,
    hazards: AtomicUsize,
}

impl ValidationCounters {
    /// Messages of error severity seen so far.
    pub fn errors(&self) -> usize {
        self.errors.load(Ordering::SeqCst)
    }

    /// Messages of warning severity seen so far.
    pub fn warnings(&self) -> usize {
        self.warnings.load(Ordering::SeqCst)
    }

    /// Synchronisation hazards (`SYNC-HAZARD-*` messages, also counted as
    /// errors) seen so far.
    pub fn hazards(&self) -> usize {
        self.hazards.load(Ordering::SeqCst)
    }
}

/// A Vulkan instance that owns its debug messenger.
// Release order: `Drop::drop` destroys the messenger and then the instance before any field drops, so `entry`
// (the loaded library) and `counters` (the messenger's user data, also used during vkDestroyInstance) outlive
// both.
pub struct Instance {
    /// The loader entry points.
    pub entry: ash::Entry,
    /// The instance.
    pub raw: ash::Instance,
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    counters: Arc<ValidationCounters>,
    /// The validation layer's Vulkan version (`specVersion`) when it is on:
    /// what it checks depends on it (tests/render/sync.rs).
    pub validation_layer_version: Option<u32>,
}

impl Instance {
    /// Creates a Vulkan 1.2 instance; with `validation`, enables the Khronos
    /// validation layer (failing if it is not installed), its
    /// synchronisation checks (`VK_EXT_validation_features`; they run in the
    /// layer, so on lavapipe too, which would otherwise hide a missing
    /// barrier by running commands one after another) and a messenger.
    pub fn new(validation: bool) -> Result<Self, VkError> {
        Self::with_extensions(validation, &[])
    }

    /// [`Instance::new`] with extra instance extensions (a window surface's).
    pub fn with_extensions(validation: bool, extra: &[*const std::ffi::c_char]) -> Result<Self, VkError> {
        // SAFETY: loads the system Vulkan loader (libvulkan.so.1), trusting its initialisers; the returned
        // `Entry` keeps the library loaded and is stored in `Self::entry`, which drops only after
        // `Drop::drop` has destroyed the instance.
        let entry = unsafe { ash::Entry::load() }.map_err(|e| VkError::Loader(e.to_string()))?;
        let app = vk::ApplicationInfo::default()
            .application_name(c"quadray")
            .engine_name(c"quadray")
            .api_version(vk::API_VERSION_1_2);

        let mut layers = Vec::new();
        let mut extensions = extra.to_vec();
        let mut validation_layer_version = None;
        let mut layer_settings_on = false;
        if validation {
            // SAFETY: a global command of the entry just loaded: it takes no handles, and ash sizes the
            // returned Vec from the count the loader reports.
            let available = unsafe { entry.enumerate_instance_layer_properties() }?;
            let found =
                available.iter().find(|l| l.layer_name_as_c_str().map(|n| n == VALIDATION_LAYER).unwrap_or(false));
            let Some(found) = found else {
                return Err(VkError::MissingValidationLayer);
            };
            validation_layer_version = Some(found.spec_version);
            layers.push(VALIDATION_LAYER.as_ptr());
            extensions.push(ash::ext::debug_utils::NAME.as_ptr());
            // SAFETY: as above; the layer name is a NUL-terminated `&'static CStr` that the loader has just
            // listed.
            let layer_extensions = unsafe { entry.enumerate_instance_extension_properties(Some(VALIDATION_LAYER)) }?;
            let features = ash::ext::validation_features::NAME;
            if !layer_extensions.iter().any(|e| e.extension_name_as_c_str() == Ok(features)) {
                return Err(VkError::MissingValidationLayer);
            }
            extensions.push(features.as_ptr());
            if layer_extensions.iter().any(|e| e.extension_name_as_c_str() == Ok(ash::ext::layer_settings::NAME)) {
                extensions.push(ash::ext::layer_settings::NAME.as_ptr());
                layer_settings_on = true;
            }
        }
        let sync_checks = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut validation_features = vk::ValidationFeaturesEXT::default().enabled_validation_features(&sync_checks);
        // From layer 1.3.292 on, the synchronisation checks ignore what shaders
        // read and write through descriptors unless this setting is on (it
        // is off by default: "can produce false positives"); the older
        // layers always track them and do not know VK_EXT_layer_settings
        // (chaining it there is an error). With it, the 1.4 layer sees a
        // dispatch or a traceRays racing a fill (tests/render/sync.rs).
        let heuristic: vk::Bool32 = vk::TRUE;
        let mut shader_accesses = vk::LayerSettingEXT::default()
            .layer_name(VALIDATION_LAYER)
            .setting_name(c"syncval_shader_accesses_heuristic")
            .ty(vk::LayerSettingTypeEXT::BOOL32);
        // One Bool32 value (ash's `values` takes bytes and would count 4).
        shader_accesses.value_count = 1;
        shader_accesses.p_values = (&heuristic as *const vk::Bool32).cast();
        let settings = [shader_accesses];
        let mut layer_settings = vk::LayerSettingsCreateInfoEXT::default().settings(&settings);

        let counters = Arc::new(ValidationCounters::default());
        let mut messenger_info = vk::DebugUtilsMessengerCreateInfoEXT::default()
            .message_severity(
                vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                    | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING
                    | vk::DebugUtilsMessageSeverityFlagsEXT::INFO,
            )
            .message_type(
                vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                    | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                    | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
            )
            .pfn_user_callback(Some(debug_callback))
            .user_data(Arc::as_ptr(&counters) as *mut c_void);

        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layers)
            .enabled_extension_names(&extensions);
        if validation {
            // Also report problems in vkCreateInstance / vkDestroyInstance.
            info = info.push_next(&mut messenger_info).push_next(&mut validation_features);
        }
        if layer_settings_on {
            info = info.push_next(&mut layer_settings);
        }
        // SAFETY: `info` and everything it points to (`app`, `layers`, `extensions` and, with validation, the
        // chained `messenger_info`, `validation_features` and `layer_settings` (with `settings` and the
        // `heuristic` value it points to), whose extensions are in `extensions`) are locals alive until the
        // call returns. The names are `&'static CStr`s except those in `extra`, which
        // must be valid NUL-terminated strings: this safe function cannot check that (the viewer passes
        // ash-window's static names). The messenger's user data points into `counters`, which `Self` keeps
        // past vkDestroyInstance.
        let raw = match unsafe { entry.create_instance(&info, None) } {
            Ok(raw) => raw,
            Err(e @ (vk::Result::ERROR_INCOMPATIBLE_DRIVER | vk::Result::ERROR_INITIALIZATION_FAILED)) => {
                return Err(VkError::NoSuitableDevice(format!(
                    "the Vulkan loader found no working driver (ICD) ({e}).\nTo fix: {}",
                    SETUP_HINT
                )))
            }
            Err(e) => return Err(e.into()),
        };

        let debug = if validation {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &raw);
            // SAFETY: `loader` was loaded for `raw`, which enabled VK_EXT_debug_utils (pushed when
            // `validation`); `messenger_info` is a live local whose pNext is null (push_next put it at the
            // end of the instance's chain); its user data points into `counters`, which `Self` keeps until
            // after `Drop::drop` destroyed the messenger.
            let messenger = unsafe { loader.create_debug_utils_messenger(&messenger_info, None) }?;
            Some((loader, messenger))
        } else {
            None
        };
        Ok(Self { entry, raw, debug, counters, validation_layer_version })
    }

    /// The validation message counters (shared; outlive the instance).
    pub fn counters(&self) -> Arc<ValidationCounters> {
        self.counters.clone()
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: the messenger and the instance were created in `with_extensions` and are destroyed once,
        // here (`take` leaves `None`), the messenger first since an instance's children must go before it. No
        // device or surface is left: each holds an `Arc<Instance>`, so this runs after they dropped. `entry`
        // and `counters` are fields and drop after this body (see the struct).
        unsafe {
            if let Some((loader, messenger)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(messenger, None);
            }
            self.raw.destroy_instance(None);
        }
    }
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    kind: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    let message = if data.is_null() || (*data).p_message.is_null() {
        std::borrow::Cow::Borrowed("(no message)")
    } else {
        CStr::from_ptr((*data).p_message).to_string_lossy()
    };
    // `user` points into the instance's Arc, which outlives the messenger.
    let counters = (user as *const ValidationCounters).as_ref();
    let id = if data.is_null() || (*data).p_message_id_name.is_null() {
        std::borrow::Cow::Borrowed("")
    } else {
        CStr::from_ptr((*data).p_message_id_name).to_string_lossy()
    };
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        if let Some(c) = counters {
            c.errors.fetch_add(1, Ordering::SeqCst);
            if id.starts_with("SYNC-HAZARD") {
                c.hazards.fetch_add(1, Ordering::SeqCst);
            }
        }
        log::error!(target: "vulkan", "[{kind:?}] {message}");
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        if let Some(c) = counters {
            c.warnings.fetch_add(1, Ordering::SeqCst);
        }
        log::warn!(target: "vulkan", "[{kind:?}] {message}");
    } else {
        log::debug!(target: "vulkan", "[{kind:?}] {message}");
    }
    vk::FALSE
}
