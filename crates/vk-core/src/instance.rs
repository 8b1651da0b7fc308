//! The Vulkan instance and the validation-message counter.
use crate::error::{Result, VkContext, VkError};
use ash::vk;
use std::ffi::{c_void, CStr, CString};
use std::sync::atomic::{AtomicU32, Ordering};
use std::sync::{Arc, Mutex};

const VALIDATION_LAYER: &CStr = c"VK_LAYER_KHRONOS_validation";

/// Whether and how the Khronos validation layer runs.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Validation {
    Off,
    /// The layer with its default checks.
    On,
    /// Also synchronization validation (slower; finds missing barriers).
    Synchronization,
}

impl Validation {
    /// Tests and debug builds validate; release builds only when asked.
    pub fn default_for_build() -> Self {
        if cfg!(debug_assertions) {
            Validation::On
        } else {
            Validation::Off
        }
    }
}

#[derive(Clone, Debug)]
pub struct InstanceDesc {
    pub app_name: String,
    pub validation: Validation,
    /// Instance extensions a window surface needs (from `ash-window`).
    pub surface_extensions: Vec<&'static CStr>,
}

impl Default for InstanceDesc {
    fn default() -> Self {
        Self {
            app_name: "tessera".into(),
            validation: Validation::default_for_build(),
            surface_extensions: Vec::new(),
        }
    }
}

/// Debug-utils messages counted by severity; error-severity ones are also kept as text.
#[derive(Default, Debug)]
pub struct MessageCounts {
    pub errors: AtomicU32,
    pub warnings: AtomicU32,
    pub infos: AtomicU32,
    pub error_texts: Mutex<Vec<String>>,
}

impl MessageCounts {
    pub fn error_count(&self) -> u32 {
        self.errors.load(Ordering::SeqCst)
    }
    pub fn warning_count(&self) -> u32 {
        self.warnings.load(Ordering::SeqCst)
    }
    /// The first error-severity messages (at most 16 kept).
    pub fn error_messages(&self) -> Vec<String> {
        self.error_texts
            .lock()
            .map(|v| v.clone())
            .unwrap_or_default()
    }
}

/// Owns the `VkInstance`. Drop order: messenger, then instance, then the loader (`entry`).
pub struct Instance {
    debug: Option<(ash::ext::debug_utils::Instance, vk::DebugUtilsMessengerEXT)>,
    /// Kept alive for the callback's user-data pointer.
    messages: Arc<MessageCounts>,
    validation: Validation,
    pub raw: ash::Instance,
    pub entry: ash::Entry,
    pub api_version: u32,
    pub has_debug_utils: bool,
    /// False for a host application's instance ([`Instance::from_host`]): never destroyed here.
    owned: bool,
}

unsafe extern "system" fn debug_callback(
    severity: vk::DebugUtilsMessageSeverityFlagsEXT,
    _types: vk::DebugUtilsMessageTypeFlagsEXT,
    data: *const vk::DebugUtilsMessengerCallbackDataEXT<'_>,
    user: *mut c_void,
) -> vk::Bool32 {
    // SAFETY: `user` is the `Arc<MessageCounts>` pointer we registered, alive as long as the
    // messenger; `data` is valid for the duration of the callback per the Vulkan spec.
    let (counts, text) = unsafe {
        let counts = &*(user as *const MessageCounts);
        let text = if data.is_null() || (*data).p_message.is_null() {
            String::from("(no message)")
        } else {
            CStr::from_ptr((*data).p_message)
                .to_string_lossy()
                .into_owned()
        };
        (counts, text)
    };
    if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::ERROR) {
        counts.errors.fetch_add(1, Ordering::SeqCst);
        if let Ok(mut v) = counts.error_texts.lock() {
            if v.len() < 16 {
                v.push(text.clone());
            }
        }
        log::error!("[vulkan] {text}");
    } else if severity.contains(vk::DebugUtilsMessageSeverityFlagsEXT::WARNING) {
        counts.warnings.fetch_add(1, Ordering::SeqCst);
        log::warn!("[vulkan] {text}");
    } else {
        counts.infos.fetch_add(1, Ordering::SeqCst);
        log::debug!("[vulkan] {text}");
    }
    vk::FALSE
}

impl Instance {
    pub fn new(desc: &InstanceDesc) -> Result<Arc<Self>> {
        // TESSERA_VULKAN_LIBRARY names a specific loader (e.g. a debug build); default: the system one.
        let entry = match std::env::var_os("TESSERA_VULKAN_LIBRARY") {
            // SAFETY: loading a Vulkan loader; its exported symbols follow the Vulkan ABI.
            Some(path) => unsafe { ash::Entry::load_from(&path) }.map_err(|e| {
                VkError::NoLoader(format!("{}: {e}", std::path::Path::new(&path).display()))
            })?,
            // SAFETY: as above, for the system loader.
            None => unsafe { ash::Entry::load() }.map_err(|e| VkError::NoLoader(e.to_string()))?,
        };
        // SAFETY: entry is a valid loader.
        let api_version = unsafe { entry.try_enumerate_instance_version() }
            .ctx("vkEnumerateInstanceVersion")?
            .unwrap_or(vk::API_VERSION_1_0);
        if api_version < vk::API_VERSION_1_3 {
            return Err(VkError::NoSuitableDevice(format!(
                "the Vulkan loader supports {}.{}, Tessera needs 1.3",
                vk::api_version_major(api_version),
                vk::api_version_minor(api_version)
            )));
        }
        // SAFETY: entry is valid.
        let layers = unsafe { entry.enumerate_instance_layer_properties() }
            .ctx("vkEnumerateInstanceLayerProperties")?;
        // SAFETY: entry is valid.
        let exts = unsafe { entry.enumerate_instance_extension_properties(None) }
            .ctx("vkEnumerateInstanceExtensionProperties")?;
        let has_layer = layers
            .iter()
            .any(|l| l.layer_name_as_c_str() == Ok(VALIDATION_LAYER));
        let has_debug_utils = exts
            .iter()
            .any(|e| e.extension_name_as_c_str() == Ok(ash::ext::debug_utils::NAME));
        let validation = if desc.validation != Validation::Off && !has_layer {
            log::warn!("validation requested but VK_LAYER_KHRONOS_validation is not installed (package vulkan-validationlayers)");
            Validation::Off
        } else {
            desc.validation
        };

        let mut layer_names = Vec::new();
        if validation != Validation::Off {
            layer_names.push(VALIDATION_LAYER.as_ptr());
        }
        let mut ext_names: Vec<*const i8> =
            desc.surface_extensions.iter().map(|e| e.as_ptr()).collect();
        if has_debug_utils {
            ext_names.push(ash::ext::debug_utils::NAME.as_ptr());
        }
        let app_name =
            CString::new(desc.app_name.clone()).unwrap_or_else(|_| c"tessera".to_owned());
        let app = vk::ApplicationInfo::default()
            .application_name(&app_name)
            .engine_name(c"tessera")
            .api_version(vk::API_VERSION_1_3);
        let enables = [vk::ValidationFeatureEnableEXT::SYNCHRONIZATION_VALIDATION];
        let mut features =
            vk::ValidationFeaturesEXT::default().enabled_validation_features(&enables);
        let mut info = vk::InstanceCreateInfo::default()
            .application_info(&app)
            .enabled_layer_names(&layer_names)
            .enabled_extension_names(&ext_names);
        if validation == Validation::Synchronization {
            info = info.push_next(&mut features);
        }
        // SAFETY: all pointers in `info` reference locals that outlive the call.
        let raw = match unsafe { entry.create_instance(&info, None) } {
            Ok(raw) => raw,
            Err(vk::Result::ERROR_INCOMPATIBLE_DRIVER) => {
                return Err(VkError::NoSuitableDevice(
                    "the Vulkan loader found no driver, so no device (install mesa-vulkan-drivers for lavapipe, or a GPU driver)".into(),
                ))
            }
            Err(result) => return Err(VkError::Call { call: "vkCreateInstance", result }),
        };

        let messages = Arc::new(MessageCounts::default());
        let debug = if has_debug_utils {
            let loader = ash::ext::debug_utils::Instance::new(&entry, &raw);
            let mut severity = vk::DebugUtilsMessageSeverityFlagsEXT::ERROR
                | vk::DebugUtilsMessageSeverityFlagsEXT::WARNING;
            if log::log_enabled!(log::Level::Debug) {
                severity |= vk::DebugUtilsMessageSeverityFlagsEXT::INFO;
            }
            let info = vk::DebugUtilsMessengerCreateInfoEXT::default()
                .message_severity(severity)
                .message_type(
                    vk::DebugUtilsMessageTypeFlagsEXT::GENERAL
                        | vk::DebugUtilsMessageTypeFlagsEXT::VALIDATION
                        | vk::DebugUtilsMessageTypeFlagsEXT::PERFORMANCE,
                )
                .pfn_user_callback(Some(debug_callback))
                .user_data(Arc::as_ptr(&messages) as *mut c_void);
            // SAFETY: the callback's user data outlives the messenger (both owned by Self,
            // messenger destroyed first in Drop).
            match unsafe { loader.create_debug_utils_messenger(&info, None) } {
                Ok(m) => Some((loader, m)),
                Err(e) => {
                    log::warn!("debug messenger not created: {e}");
                    None
                }
            }
        } else {
            None
        };
        Ok(Arc::new(Self {
            debug,
            messages,
            validation,
            raw,
            entry,
            api_version,
            has_debug_utils,
            owned: true,
        }))
    }

    /// Wraps a host application's instance (the C ABI's host-owned mode) without taking
    /// ownership: dropping the result destroys nothing. Vulkan is reached through the host's
    /// `vkGetInstanceProcAddr`, so its loader and layers are the host's; validation messages go
    /// to the host's own messenger, and [`Instance::messages`] stays empty.
    ///
    /// # Safety
    /// - `get_instance_proc_addr` is a `vkGetInstanceProcAddr` and `raw` a live instance it
    ///   serves, created for Vulkan 1.3 or later.
    /// - `raw` outlives the returned instance and every device made from it.
    /// - `debug_utils` is true only when VK_EXT_debug_utils was enabled on `raw`.
    pub unsafe fn from_host(
        get_instance_proc_addr: vk::PFN_vkGetInstanceProcAddr,
        raw: vk::Instance,
        debug_utils: bool,
    ) -> Result<Arc<Self>> {
        // SAFETY: the caller's contract: a vkGetInstanceProcAddr with the Vulkan ABI.
        let entry = unsafe {
            ash::Entry::from_static_fn(ash::StaticFn {
                get_instance_proc_addr,
            })
        };
        // SAFETY: the caller's contract: `raw` is a live instance of this entry point.
        let raw = unsafe { ash::Instance::load(entry.static_fn(), raw) };
        // SAFETY: entry is valid.
        let api_version = unsafe { entry.try_enumerate_instance_version() }
            .ctx("vkEnumerateInstanceVersion")?
            .unwrap_or(vk::API_VERSION_1_0);
        Ok(Arc::new(Self {
            debug: None,
            messages: Arc::new(MessageCounts::default()),
            validation: Validation::Off,
            raw,
            entry,
            api_version,
            has_debug_utils: debug_utils,
            owned: false,
        }))
    }

    pub fn messages(&self) -> &Arc<MessageCounts> {
        &self.messages
    }

    pub fn validation(&self) -> Validation {
        self.validation
    }
}

impl Drop for Instance {
    fn drop(&mut self) {
        // SAFETY: every child object (device, surfaces) holds an Arc<Instance> and is gone by now;
        // the messenger is destroyed before the instance that owns it.
        unsafe {
            if let Some((loader, m)) = self.debug.take() {
                loader.destroy_debug_utils_messenger(m, None);
            }
            if self.owned {
                self.raw.destroy_instance(None);
            }
        }
    }
}
