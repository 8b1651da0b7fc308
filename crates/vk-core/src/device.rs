//! Physical-device choice (deterministic, overridable) and the logical device with its allocator.
use crate::error::{Result, VkContext, VkError};
use crate::instance::Instance;
use crate::pipeline_cache;
use crate::retire::RetireQueue;
use crate::workarounds::Workarounds;
use ash::vk;
use gpu_allocator::vulkan::{
    Allocation, AllocationCreateDesc, AllocationScheme, Allocator, AllocatorCreateDesc,
};
use gpu_allocator::MemoryLocation;
use std::ffi::CStr;
use std::fmt;
use std::mem::ManuallyDrop;
use std::sync::atomic::{AtomicU64, Ordering};
use std::sync::{Arc, Mutex};

/// Which device to use: the best-scored, or one named by index or name substring (`--device`).
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub enum DeviceSelector {
    #[default]
    Auto,
    Index(usize),
    Name(String),
}

impl std::str::FromStr for DeviceSelector {
    type Err = std::convert::Infallible;
    fn from_str(s: &str) -> std::result::Result<Self, Self::Err> {
        Ok(match s.parse::<usize>() {
            Ok(i) => DeviceSelector::Index(i),
            Err(_) if s.is_empty() || s == "auto" => DeviceSelector::Auto,
            Err(_) => DeviceSelector::Name(s.to_owned()),
        })
    }
}

/// What Tessera needs of a device, one field per feature, gathered in one place.
#[derive(Clone, Copy, Debug, Default)]
pub struct Capabilities {
    pub tessellation_shader: bool,
    pub fill_mode_non_solid: bool,
    pub pipeline_statistics_query: bool,
    pub vertex_pipeline_stores_and_atomics: bool,
    /// `multiDrawIndirect`: one indirect draw command may hold more than one draw.
    pub multi_draw_indirect: bool,
    /// `drawIndirectFirstInstance`: indirect draws may start at an instance other than 0.
    pub draw_indirect_first_instance: bool,
    /// `maxDrawIndirectCount`: the most draws one indirect command may hold.
    pub max_draw_indirect_count: u32,
    pub dynamic_rendering: bool,
    pub timestamps: bool,
    pub max_tessellation_generation_level: u32,
    pub max_tessellation_patch_size: u32,
    pub max_tess_evaluation_output_components: u32,
    pub timestamp_period_ns: f32,
    /// VK_EXT_transform_feedback with its `transformFeedback` feature: optional, needed only to
    /// capture what the TES emitted (`tess::capture`); a device without it still renders.
    pub transform_feedback: bool,
    /// Transform-feedback stream queries (primitives written / needed), used to size captures.
    pub transform_feedback_queries: bool,
    /// Largest transform-feedback buffer binding, in bytes (0 without the extension).
    pub max_transform_feedback_buffer_size: u64,
    /// Largest transform-feedback vertex stride, in bytes (0 without the extension).
    pub max_transform_feedback_stride: u32,
    /// Transform-feedback buffer bindings (0 without the extension).
    pub max_transform_feedback_buffers: u32,
    /// Vertex streams transform feedback can count (0 without the extension).
    pub max_transform_feedback_streams: u32,
    /// Largest uniform-buffer descriptor range, in bytes.
    pub max_uniform_buffer_range: u32,
    /// Largest storage-buffer descriptor range, in bytes: the device's, or less under
    /// [`DeviceDesc::storage_buffer_range_cap`]. Every storage descriptor write is checked
    /// against it, and techniques split their buffers and draws by it.
    pub max_storage_buffer_range: u32,
    /// Alignment of a storage-buffer descriptor's offset, in bytes.
    pub min_storage_buffer_offset_alignment: u64,
    /// Largest dispatch, in workgroups per dimension.
    pub max_compute_work_group_count: [u32; 3],
    /// Timeline semaphores (core in Vulkan 1.2): how vk-core counts submissions.
    pub timeline_semaphore: bool,
    /// Largest width or height of a 2D image, in texels: what textures are checked against.
    pub max_image_dimension_2d: u32,
    /// `maintenance4` (core in Vulkan 1.3), enabled where present: among other things it lets a
    /// stage write an output the next stage does not read (a plain build's TES leaves the
    /// TCS's patch flags unread), which the validation layer otherwise reports every run.
    pub maintenance4: bool,
    /// `bufferDeviceAddress` (required in Vulkan 1.3), enabled where present, and for a host's
    /// device where the host says it enabled it: shaders then read buffers made with
    /// `SHADER_DEVICE_ADDRESS` usage through their addresses ([`crate::Buffer::device_address`]),
    /// which no `maxStorageBufferRange` limits.
    pub buffer_device_address: bool,
}

/// One physical device as seen at start-up: identity, capabilities, and what it lacks.
#[derive(Clone, Debug)]
pub struct AdapterInfo {
    pub index: usize,
    pub name: String,
    pub device_type: vk::PhysicalDeviceType,
    pub driver_id: vk::DriverId,
    pub driver_name: String,
    pub driver_info: String,
    pub driver_version: u32,
    pub api_version: u32,
    pub vendor_id: u32,
    pub device_id: u32,
    /// The driver's `pipelineCacheUUID`: pipeline cache data is only valid for the same one.
    pub pipeline_cache_uuid: [u8; 16],
    pub caps: Capabilities,
    pub queue_family: Option<u32>,
    /// Empty when the device can run Tessera.
    pub missing: Vec<String>,
    pub physical: vk::PhysicalDevice,
}

impl AdapterInfo {
    /// Discrete > integrated > virtual > CPU; unusable devices score 0.
    pub fn score(&self) -> u32 {
        if !self.missing.is_empty() {
            return 0;
        }
        match self.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => 4,
            vk::PhysicalDeviceType::INTEGRATED_GPU => 3,
            vk::PhysicalDeviceType::VIRTUAL_GPU => 2,
            vk::PhysicalDeviceType::CPU => 1,
            _ => 1,
        }
    }

    pub fn type_name(&self) -> &'static str {
        match self.device_type {
            vk::PhysicalDeviceType::DISCRETE_GPU => "discrete GPU",
            vk::PhysicalDeviceType::INTEGRATED_GPU => "integrated GPU",
            vk::PhysicalDeviceType::VIRTUAL_GPU => "virtual GPU",
            vk::PhysicalDeviceType::CPU => "CPU",
            _ => "other",
        }
    }

    pub fn is_lavapipe(&self) -> bool {
        self.driver_id == vk::DriverId::MESA_LLVMPIPE
    }
}

impl fmt::Display for AdapterInfo {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(
            f,
            "[{}] {} ({}, driver {} {}, Vulkan {}.{}.{})",
            self.index,
            self.name,
            self.type_name(),
            self.driver_name,
            self.driver_info,
            vk::api_version_major(self.api_version),
            vk::api_version_minor(self.api_version),
            vk::api_version_patch(self.api_version)
        )?;
        if !self.missing.is_empty() {
            write!(f, " — lacks: {}", self.missing.join(", "))?;
        }
        Ok(())
    }
}

fn cstr_field(chars: &[std::ffi::c_char]) -> String {
    // SAFETY: Vulkan fixed-size string fields are NUL-terminated within their length.
    let bytes: &[u8] = unsafe { std::slice::from_raw_parts(chars.as_ptr().cast(), chars.len()) };
    CStr::from_bytes_until_nul(bytes)
        .map(|c| c.to_string_lossy().into_owned())
        .unwrap_or_default()
}

/// Lists every physical device with what it offers and lacks, in the loader's order.
pub fn enumerate_adapters(instance: &Instance) -> Result<Vec<AdapterInfo>> {
    // SAFETY: instance.raw is a live instance.
    let physicals =
        unsafe { instance.raw.enumerate_physical_devices() }.ctx("vkEnumeratePhysicalDevices")?;
    physicals
        .iter()
        .enumerate()
        .map(|(index, &physical)| adapter_info(instance, index, physical))
        .collect()
}

/// What one physical device reports (properties, features, queue families, extensions),
/// read as [`Capabilities`], and what it lacks.
fn adapter_info(
    instance: &Instance,
    index: usize,
    physical: vk::PhysicalDevice,
) -> Result<AdapterInfo> {
    // SAFETY: physical comes from this instance.
    let extensions = unsafe { instance.raw.enumerate_device_extension_properties(physical) }
        .ctx("vkEnumerateDeviceExtensionProperties")?;
    let has_xfb_extension = extensions
        .iter()
        .any(|e| e.extension_name_as_c_str().ok() == Some(ash::ext::transform_feedback::NAME));
    let mut driver = vk::PhysicalDeviceDriverProperties::default();
    let mut xfb_props = vk::PhysicalDeviceTransformFeedbackPropertiesEXT::default();
    let mut props2 = vk::PhysicalDeviceProperties2::default().push_next(&mut driver);
    if has_xfb_extension {
        props2 = props2.push_next(&mut xfb_props);
    }
    let mut f12 = vk::PhysicalDeviceVulkan12Features::default();
    let mut f13 = vk::PhysicalDeviceVulkan13Features::default();
    let mut xfb_feats = vk::PhysicalDeviceTransformFeedbackFeaturesEXT::default();
    let mut features2 = vk::PhysicalDeviceFeatures2::default()
        .push_next(&mut f12)
        .push_next(&mut f13);
    if has_xfb_extension {
        features2 = features2.push_next(&mut xfb_feats);
    }
    // SAFETY: physical comes from this instance; the out-structs are valid chains (the
    // transform-feedback structs are chained only when the device reports the extension).
    let families = unsafe {
        instance
            .raw
            .get_physical_device_properties2(physical, &mut props2);
        instance
            .raw
            .get_physical_device_features2(physical, &mut features2);
        instance
            .raw
            .get_physical_device_queue_family_properties(physical)
    };
    let props = props2.properties;
    let feats = features2.features;
    let queue_family = families
        .iter()
        .position(|q| {
            q.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
        })
        .map(|i| i as u32);
    let timestamps = queue_family
        .map(|q| families[q as usize].timestamp_valid_bits > 0)
        .unwrap_or(false);
    let reported = Reported {
        props: &props,
        feats: &feats,
        f12: &f12,
        f13: &f13,
        xfb: has_xfb_extension.then_some((&xfb_feats, &xfb_props)),
    };
    let caps = capabilities(&reported, timestamps);
    let missing = missing_requirements(props.api_version, &caps, queue_family);
    Ok(AdapterInfo {
        index,
        name: cstr_field(&props.device_name),
        device_type: props.device_type,
        driver_id: driver.driver_id,
        driver_name: cstr_field(&driver.driver_name),
        driver_info: cstr_field(&driver.driver_info),
        driver_version: props.driver_version,
        api_version: props.api_version,
        vendor_id: props.vendor_id,
        device_id: props.device_id,
        pipeline_cache_uuid: props.pipeline_cache_uuid,
        caps,
        queue_family,
        missing,
        physical,
    })
}

/// What a physical device reports, as [`capabilities`] reads it (the transform-feedback
/// structs only when the device has the extension).
struct Reported<'a> {
    props: &'a vk::PhysicalDeviceProperties,
    feats: &'a vk::PhysicalDeviceFeatures,
    f12: &'a vk::PhysicalDeviceVulkan12Features<'a>,
    f13: &'a vk::PhysicalDeviceVulkan13Features<'a>,
    xfb: Option<(
        &'a vk::PhysicalDeviceTransformFeedbackFeaturesEXT<'a>,
        &'a vk::PhysicalDeviceTransformFeedbackPropertiesEXT<'a>,
    )>,
}

/// The capabilities Tessera reads from what a device reports.
fn capabilities(r: &Reported<'_>, timestamps: bool) -> Capabilities {
    let (props, feats, f12, f13) = (r.props, r.feats, r.f12, r.f13);
    let xfb_feature = r.xfb.is_some_and(|(f, _)| f.transform_feedback == vk::TRUE);
    Capabilities {
        tessellation_shader: feats.tessellation_shader == vk::TRUE,
        fill_mode_non_solid: feats.fill_mode_non_solid == vk::TRUE,
        pipeline_statistics_query: feats.pipeline_statistics_query == vk::TRUE,
        vertex_pipeline_stores_and_atomics: feats.vertex_pipeline_stores_and_atomics == vk::TRUE,
        multi_draw_indirect: feats.multi_draw_indirect == vk::TRUE,
        draw_indirect_first_instance: feats.draw_indirect_first_instance == vk::TRUE,
        max_draw_indirect_count: props.limits.max_draw_indirect_count,
        dynamic_rendering: f13.dynamic_rendering == vk::TRUE,
        maintenance4: f13.maintenance4 == vk::TRUE,
        timestamps,
        max_tessellation_generation_level: props.limits.max_tessellation_generation_level,
        max_tessellation_patch_size: props.limits.max_tessellation_patch_size,
        max_tess_evaluation_output_components: props
            .limits
            .max_tessellation_evaluation_output_components,
        timestamp_period_ns: props.limits.timestamp_period,
        transform_feedback: xfb_feature,
        transform_feedback_queries: xfb_feature
            && r.xfb
                .is_some_and(|(_, p)| p.transform_feedback_queries == vk::TRUE),
        max_transform_feedback_buffer_size: r
            .xfb
            .map_or(0, |(_, p)| p.max_transform_feedback_buffer_size),
        max_transform_feedback_stride: r
            .xfb
            .map_or(0, |(_, p)| p.max_transform_feedback_buffer_data_stride),
        max_transform_feedback_buffers: r.xfb.map_or(0, |(_, p)| p.max_transform_feedback_buffers),
        max_transform_feedback_streams: r.xfb.map_or(0, |(_, p)| p.max_transform_feedback_streams),
        max_uniform_buffer_range: props.limits.max_uniform_buffer_range,
        max_storage_buffer_range: props.limits.max_storage_buffer_range,
        min_storage_buffer_offset_alignment: props
            .limits
            .min_storage_buffer_offset_alignment
            .max(1),
        max_compute_work_group_count: props.limits.max_compute_work_group_count,
        timeline_semaphore: f12.timeline_semaphore == vk::TRUE,
        buffer_device_address: f12.buffer_device_address == vk::TRUE,
        max_image_dimension_2d: props.limits.max_image_dimension2_d,
    }
}

/// What Tessera needs and the device lacks, each named.
fn missing_requirements(
    api_version: u32,
    caps: &Capabilities,
    queue_family: Option<u32>,
) -> Vec<String> {
    let mut missing = Vec::new();
    if api_version < vk::API_VERSION_1_3 {
        missing.push("Vulkan 1.3".to_owned());
    }
    if !caps.fill_mode_non_solid {
        missing.push("fillModeNonSolid".to_owned());
    }
    if !caps.dynamic_rendering {
        missing.push("dynamicRendering".to_owned());
    }
    if !caps.timeline_semaphore {
        missing.push("timelineSemaphore".to_owned());
    }
    if caps.tessellation_shader && caps.max_tessellation_generation_level < 64 {
        missing.push(format!(
            "maxTessellationGenerationLevel ≥ 64 (has {})",
            caps.max_tessellation_generation_level
        ));
    }
    if caps.tessellation_shader && caps.max_tessellation_patch_size < 32 {
        missing.push(format!(
            "maxTessellationPatchSize ≥ 32 (has {})",
            caps.max_tessellation_patch_size
        ));
    }
    if queue_family.is_none() {
        missing.push("a graphics+compute queue".to_owned());
    }
    missing
}

/// Chooses deterministically: highest score, ties broken by the lowest index.
pub fn choose_adapter(adapters: &[AdapterInfo], selector: &DeviceSelector) -> Result<usize> {
    let listing = || {
        adapters
            .iter()
            .map(|a| format!("  {a}"))
            .collect::<Vec<_>>()
            .join("\n")
    };
    let pick = match selector {
        DeviceSelector::Auto => adapters
            .iter()
            .filter(|a| a.score() > 0)
            .max_by_key(|a| (a.score(), std::cmp::Reverse(a.index)))
            .map(|a| a.index),
        DeviceSelector::Index(i) => adapters.iter().find(|a| a.index == *i).map(|a| a.index),
        DeviceSelector::Name(n) => {
            let n = n.to_lowercase();
            adapters
                .iter()
                .find(|a| a.name.to_lowercase().contains(&n))
                .map(|a| a.index)
        }
    };
    match (pick, selector) {
        (None, DeviceSelector::Auto) if adapters.is_empty() => Err(VkError::NoSuitableDevice(
            "the loader reports no Vulkan device (install mesa-vulkan-drivers for lavapipe)".into(),
        )),
        (None, DeviceSelector::Auto) => Err(VkError::NoSuitableDevice(format!(
            "no device has the features Tessera needs; devices seen:\n{}",
            listing()
        ))),
        (None, s) => Err(VkError::NoSuchDevice {
            selector: format!("{s:?}"),
            devices: listing(),
        }),
        (Some(i), _) => {
            let a = &adapters[i];
            if a.missing.is_empty() {
                Ok(i)
            } else {
                Err(VkError::MissingFeatures {
                    name: a.name.clone(),
                    missing: a.missing.join(", "),
                })
            }
        }
    }
}

#[derive(Clone, Debug, Default)]
pub struct DeviceDesc {
    pub selector: DeviceSelector,
    /// The directory the pipeline cache is kept in between runs, one file per device
    /// ([`crate::pipeline_cache`]; [`crate::pipeline_cache::user_dir`] is the user's);
    /// `None` keeps it in memory only.
    pub pipeline_cache_dir: Option<std::path::PathBuf>,
    /// Leaves VK_EXT_transform_feedback off even where the device has it, so the path of devices
    /// without it (typed errors from captures) can be tested on any device.
    pub without_transform_feedback: bool,
    /// Caps the storage-buffer range Tessera uses at `min(device limit, cap)` bytes, so the
    /// paths that split buffers larger than the limit can be tested with small meshes.
    pub storage_buffer_range_cap: Option<u32>,
    /// Leaves `tessellationShader` off even where the device has it, so the path of devices
    /// without tessellation (refinement patterns; any tessellation pipeline is then a
    /// validation error) can be tested on any device.
    pub without_tessellation_shader: bool,
}

/// The state every resource shares. Drop order: idle wait, retired objects, one-shot command
/// pools, timeline semaphore, pipeline cache, allocator (every allocation already handed back),
/// device; then the instance Arc.
pub struct DeviceShared {
    pub(crate) raw: ash::Device,
    pub physical: vk::PhysicalDevice,
    pub queue: vk::Queue,
    pub queue_family: u32,
    pub info: AdapterInfo,
    pub workarounds: Workarounds,
    pub(crate) debug_utils: Option<ash::ext::debug_utils::Device>,
    /// VK_EXT_transform_feedback's commands; `None` when the device lacks the extension or the
    /// feature (see [`DeviceShared::transform_feedback`] for a typed error instead).
    pub(crate) transform_feedback: Option<ash::ext::transform_feedback::Device>,
    pub(crate) allocator: ManuallyDrop<Mutex<Allocator>>,
    /// Command pools (each with its one command buffer) free for one-shot recordings: a pool is
    /// taken for the whole recording, so recordings on several threads never share one.
    pub(crate) once_pools: Mutex<Vec<(vk::CommandPool, vk::CommandBuffer)>>,
    /// Serializes queue access (vkQueueSubmit, vkQueuePresentKHR, vkDeviceWaitIdle).
    pub(crate) queue_lock: Mutex<()>,
    /// Signalled with each submission's serial when it completes (see [`crate::retire`]).
    pub(crate) timeline: vk::Semaphore,
    pub(crate) retired: Mutex<RetireQueue>,
    /// Vulkan handles this device created and has not destroyed yet (see
    /// [`DeviceShared::live_objects`]).
    pub(crate) live: AtomicU64,
    pub(crate) pipeline_cache: vk::PipelineCache,
    /// This device's cache file, and a hash of the data read from it (nothing is written
    /// back when the cache still holds exactly that).
    pub(crate) pipeline_cache_file: Option<(std::path::PathBuf, u64)>,
    /// False for a host application's device ([`Device::from_host`]): never waited idle or
    /// destroyed here.
    pub(crate) owns_device: bool,
    pub instance: Arc<Instance>,
}

/// A raw device and whether vk-core destroys it.
struct Owned {
    raw: ash::Device,
    destroy: bool,
}

/// A host application's device and queue, as [`Device::from_host`] wraps them.
#[derive(Clone, Copy, Debug)]
pub struct HostDevice {
    pub physical: vk::PhysicalDevice,
    pub device: vk::Device,
    pub queue_family: u32,
    pub queue: vk::Queue,
    /// VK_EXT_transform_feedback and its feature were enabled (captures need them).
    pub transform_feedback: bool,
    /// `pipelineStatisticsQuery` was enabled.
    pub pipeline_statistics_query: bool,
    /// `vertexPipelineStoresAndAtomics` was enabled.
    pub vertex_pipeline_stores_and_atomics: bool,
    /// `tessellationShader` was enabled.
    pub tessellation_shader: bool,
    /// `dynamicRendering` was enabled (vk-core's own rendering scopes, such as captures, need
    /// it).
    pub dynamic_rendering: bool,
    /// `bufferDeviceAddress` was enabled: buffers with `SHADER_DEVICE_ADDRESS` usage (read by
    /// address) are refused without it.
    pub buffer_device_address: bool,
}

/// A handle to the logical device; clones share it.
#[derive(Clone)]
pub struct Device {
    pub shared: Arc<DeviceShared>,
}

impl std::ops::Deref for Device {
    type Target = DeviceShared;
    fn deref(&self) -> &DeviceShared {
        &self.shared
    }
}

impl DeviceShared {
    /// Allocates memory for `requirements` and binds it through `bind` (memory, offset). On any
    /// failure the memory is handed back, so the caller only destroys its own handle.
    pub(crate) fn allocate_bound(
        &self,
        name: &str,
        requirements: vk::MemoryRequirements,
        location: MemoryLocation,
        linear: bool,
        bind: impl FnOnce(vk::DeviceMemory, u64) -> Result<()>,
    ) -> Result<Allocation> {
        let allocation = self
            .allocator
            .lock()
            .map_err(|_| VkError::LockPoisoned { what: "allocator" })?
            .allocate(&AllocationCreateDesc {
                name,
                requirements,
                location,
                linear,
                allocation_scheme: AllocationScheme::GpuAllocatorManaged,
            })?;
        // SAFETY: the handle is only passed to `bind`, which binds it while the allocation is
        // alive; the memory was made for these requirements and the offset is aligned to them.
        let memory = unsafe { allocation.memory() };
        if let Err(e) = bind(memory, allocation.offset()) {
            self.free(allocation);
            return Err(e);
        }
        Ok(allocation)
    }

    /// Hands `allocation` back (a poisoned lock leaks it rather than panicking in a drop).
    pub(crate) fn free(&self, allocation: Allocation) {
        if let Ok(mut a) = self.allocator.lock() {
            let _ = a.free(allocation);
        }
    }
}

impl Device {
    pub fn new(
        instance: &Arc<Instance>,
        desc: &DeviceDesc,
        extra_extensions: &[&'static CStr],
    ) -> Result<Self> {
        let adapters = enumerate_adapters(instance)?;
        let chosen = choose_adapter(&adapters, &desc.selector)?;
        let mut info = adapters[chosen].clone();
        if let Some(cap) = desc.storage_buffer_range_cap {
            info.caps.max_storage_buffer_range = info.caps.max_storage_buffer_range.min(cap);
        }
        if desc.without_tessellation_shader {
            info.caps.tessellation_shader = false;
        }
        let physical = info.physical;
        let queue_family = info
            .queue_family
            .ok_or_else(|| VkError::NoSuitableDevice("no queue".into()))?;
        let priorities = [1.0f32];
        let queue_info = [vk::DeviceQueueCreateInfo::default()
            .queue_family_index(queue_family)
            .queue_priorities(&priorities)];
        let features = vk::PhysicalDeviceFeatures::default()
            .tessellation_shader(info.caps.tessellation_shader)
            .fill_mode_non_solid(true)
            .pipeline_statistics_query(info.caps.pipeline_statistics_query)
            .vertex_pipeline_stores_and_atomics(info.caps.vertex_pipeline_stores_and_atomics)
            .multi_draw_indirect(info.caps.multi_draw_indirect)
            .draw_indirect_first_instance(info.caps.draw_indirect_first_instance);
        let mut f12 = vk::PhysicalDeviceVulkan12Features::default()
            .timeline_semaphore(true)
            .buffer_device_address(info.caps.buffer_device_address);
        let mut f13 = vk::PhysicalDeviceVulkan13Features::default()
            .dynamic_rendering(true)
            .maintenance4(info.caps.maintenance4);
        // Transform feedback is enabled whenever the device has it: capture is optional, and
        // enabling it costs nothing when unused.
        let xfb = info.caps.transform_feedback && !desc.without_transform_feedback;
        let mut xfb_feats =
            vk::PhysicalDeviceTransformFeedbackFeaturesEXT::default().transform_feedback(true);
        let mut extensions: Vec<&CStr> = extra_extensions.to_vec();
        if xfb && !extensions.contains(&ash::ext::transform_feedback::NAME) {
            extensions.push(ash::ext::transform_feedback::NAME);
        }
        let ext_names: Vec<*const i8> = extensions.iter().map(|e| e.as_ptr()).collect();
        let mut create = vk::DeviceCreateInfo::default()
            .queue_create_infos(&queue_info)
            .enabled_features(&features)
            .enabled_extension_names(&ext_names)
            .push_next(&mut f12)
            .push_next(&mut f13);
        if xfb {
            create = create.push_next(&mut xfb_feats);
        }
        // SAFETY: physical belongs to instance; create info references live locals.
        let raw =
            unsafe { instance.raw.create_device(physical, &create, None) }.ctx("vkCreateDevice")?;
        // SAFETY: the family/index were requested above.
        let queue = unsafe { raw.get_device_queue(queue_family, 0) };
        let owned = Owned { raw, destroy: true };
        Self::wrap(
            instance,
            info,
            owned,
            queue,
            xfb,
            desc.pipeline_cache_dir.as_deref(),
        )
    }

    /// Wraps a host application's device (the C ABI's host-owned mode) without taking
    /// ownership: dropping the last handle destroys what vk-core created on it (its allocator's
    /// memory, pipeline cache, timeline semaphore, command pools) but neither waits for the
    /// device to be idle nor destroys it; it waits only for vk-core's own submissions.
    ///
    /// vk-core submits to `host.queue` for one-shot work only (uploads of device-local data,
    /// offscreen renders and captures), each submission counted on its own timeline semaphore
    /// and waited for through it, never through `vkDeviceWaitIdle` or `vkQueueWaitIdle`.
    ///
    /// # Safety
    /// - `host.device` is a live device created from `host.physical` of `instance`, with
    ///   `fillModeNonSolid` and `timelineSemaphore` enabled, `tessellationShader` as
    ///   `host.tessellation_shader` says,
    ///   `dynamicRendering` too unless nothing vk-core records on it begins a rendering scope
    ///   of its own or is recorded into a dynamic-rendering scope (a host that draws only into
    ///   render pass subpasses and never captures), and each optional feature `host` claims
    ///   enabled (transform feedback with its extension, pipeline statistics queries,
    ///   vertex-pipeline stores, buffer device addresses) enabled.
    /// - `host.queue` is queue 0 of `host.queue_family`, a family with graphics and compute.
    /// - The device outlives every object made from the result; the host does not use the
    ///   queue on another thread while a vk-core call that submits runs (Vulkan's external
    ///   synchronization of queues).
    ///
    /// `pipeline_cache_dir` is as [`DeviceDesc::pipeline_cache_dir`]: vk-core's own pipeline
    /// cache (never the host's) is read from and saved to this device's file there.
    pub unsafe fn from_host(
        instance: &Arc<Instance>,
        host: &HostDevice,
        pipeline_cache_dir: Option<&std::path::Path>,
    ) -> Result<Self> {
        let adapters = enumerate_adapters(instance)?;
        let Some(mut info) = adapters.into_iter().find(|a| a.physical == host.physical) else {
            return Err(VkError::NoSuchDevice {
                selector: format!("{:?}", host.physical),
                devices: "the host's physical device is not among the instance's".into(),
            });
        };
        if !info.missing.is_empty() {
            return Err(VkError::MissingFeatures {
                name: info.name.clone(),
                missing: info.missing.join(", "),
            });
        }
        // SAFETY: the physical device belongs to the instance (found among its devices).
        let families = unsafe {
            instance
                .raw
                .get_physical_device_queue_family_properties(info.physical)
        };
        let family_ok = families.get(host.queue_family as usize).is_some_and(|q| {
            q.queue_flags
                .contains(vk::QueueFlags::GRAPHICS | vk::QueueFlags::COMPUTE)
        });
        if !family_ok {
            return Err(VkError::MissingFeatures {
                name: info.name.clone(),
                missing: format!(
                    "queue family {} with graphics and compute (the host's queue)",
                    host.queue_family
                ),
            });
        }
        info.queue_family = Some(host.queue_family);
        info.caps.pipeline_statistics_query &= host.pipeline_statistics_query;
        info.caps.vertex_pipeline_stores_and_atomics &= host.vertex_pipeline_stores_and_atomics;
        info.caps.tessellation_shader &= host.tessellation_shader;
        info.caps.dynamic_rendering &= host.dynamic_rendering;
        info.caps.buffer_device_address &= host.buffer_device_address;
        // The host does not say whether it enabled these: indirect draws hold one draw each
        // and start at instance 0 on its device.
        info.caps.multi_draw_indirect = false;
        info.caps.draw_indirect_first_instance = false;
        let xfb = info.caps.transform_feedback && host.transform_feedback;
        info.caps.transform_feedback = xfb;
        // SAFETY: the caller's contract: a live device of this instance.
        let raw = unsafe { ash::Device::load(instance.raw.fp_v1_0(), host.device) };
        let owned = Owned {
            raw,
            destroy: false,
        };
        Self::wrap(instance, info, owned, host.queue, xfb, pipeline_cache_dir)
    }

    /// Everything after the device and its queue exist, for both owners.
    fn wrap(
        instance: &Arc<Instance>,
        info: AdapterInfo,
        owned: Owned,
        queue: vk::Queue,
        xfb: bool,
        pipeline_cache_dir: Option<&std::path::Path>,
    ) -> Result<Self> {
        let Owned { raw, destroy: owns } = owned;
        let physical = info.physical;
        let queue_family = info
            .queue_family
            .ok_or_else(|| VkError::NoSuitableDevice("no queue".into()))?;
        let allocator = Allocator::new(&AllocatorCreateDesc {
            instance: instance.raw.clone(),
            device: raw.clone(),
            physical_device: physical,
            debug_settings: Default::default(),
            buffer_device_address: info.caps.buffer_device_address,
            allocation_sizes: Default::default(),
        });
        let allocator = match allocator {
            Ok(a) => a,
            Err(e) => {
                if owns {
                    // SAFETY: nothing was created on the device yet.
                    unsafe { raw.destroy_device(None) };
                }
                return Err(e.into());
            }
        };
        let mut timeline_info = vk::SemaphoreTypeCreateInfo::default()
            .semaphore_type(vk::SemaphoreType::TIMELINE)
            .initial_value(0);
        let semaphore_info = vk::SemaphoreCreateInfo::default().push_next(&mut timeline_info);
        // SAFETY: raw is a live device with the timelineSemaphore feature enabled above.
        let timeline = match unsafe { raw.create_semaphore(&semaphore_info, None) } {
            Ok(s) => s,
            Err(result) => {
                drop(allocator);
                if owns {
                    // SAFETY: nothing else was created on the device yet.
                    unsafe { raw.destroy_device(None) };
                }
                return Err(VkError::Call {
                    call: "vkCreateSemaphore",
                    result,
                });
            }
        };
        let identity = pipeline_cache::CacheIdentity {
            vendor_id: info.vendor_id,
            device_id: info.device_id,
            pipeline_cache_uuid: info.pipeline_cache_uuid,
        };
        let file = pipeline_cache_dir.map(|d| identity.file_in(d));
        // Only data whose header names this device and driver build (checked in `load`).
        let initial = file
            .as_deref()
            .map(|p| pipeline_cache::load(p, &identity))
            .unwrap_or_default();
        let pipeline_cache_file = file.map(|p| (p, data_hash(&initial)));
        let cache_info = vk::PipelineCacheCreateInfo::default().initial_data(&initial);
        // SAFETY: `initial` is empty or data whose header matches this device; the driver
        // still validates it and ignores what it cannot use.
        let pipeline_cache = match unsafe { raw.create_pipeline_cache(&cache_info, None) } {
            Ok(c) => c,
            Err(_) => {
                // SAFETY: as above, without initial data.
                unsafe { raw.create_pipeline_cache(&vk::PipelineCacheCreateInfo::default(), None) }
                    .ctx("vkCreatePipelineCache")?
            }
        };
        let debug_utils = instance
            .has_debug_utils
            .then(|| ash::ext::debug_utils::Device::new(&instance.raw, &raw));
        let transform_feedback =
            xfb.then(|| ash::ext::transform_feedback::Device::new(&instance.raw, &raw));
        let workarounds = Workarounds::for_adapter(&info);
        for w in workarounds.active() {
            log::info!("driver workaround active on {}: {}", info.name, w.summary);
        }
        let shared = DeviceShared {
            raw,
            physical,
            queue,
            queue_family,
            info,
            workarounds,
            debug_utils,
            transform_feedback,
            allocator: ManuallyDrop::new(Mutex::new(allocator)),
            once_pools: Mutex::new(Vec::new()),
            queue_lock: Mutex::new(()),
            timeline,
            retired: Mutex::new(RetireQueue::default()),
            live: AtomicU64::new(0),
            pipeline_cache,
            pipeline_cache_file,
            owns_device: owns,
            instance: instance.clone(),
        };
        let device = Device {
            shared: Arc::new(shared),
        };
        device.set_name(device.queue, "main queue");
        device.set_name(timeline, "submission timeline");
        Ok(device)
    }

    /// Names a Vulkan object for debug-utils (validation messages and capture tools show it).
    /// Crate-private: naming a handle that is not a live object of this device is invalid.
    pub(crate) fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        self.shared.set_name(handle, name)
    }
}

impl DeviceShared {
    pub(crate) fn set_name<H: vk::Handle>(&self, handle: H, name: &str) {
        let Some(du) = &self.debug_utils else { return };
        let Ok(name) = std::ffi::CString::new(name) else {
            return;
        };
        let info = vk::DebugUtilsObjectNameInfoEXT::default()
            .object_handle(handle)
            .object_name(&name);
        // SAFETY: handle is a live object of this device; naming has no other effect.
        let _ = unsafe { du.set_debug_utils_object_name(&info) };
    }

    /// A typed [`VkError::Unsupported`] unless VK_EXT_transform_feedback is enabled on this
    /// device: what captures check before any work.
    pub fn require_transform_feedback(&self) -> Result<()> {
        self.transform_feedback().map(|_| ())
    }

    /// Whether VK_EXT_transform_feedback is enabled (present, and not turned off by
    /// [`DeviceDesc::without_transform_feedback`]).
    pub fn has_transform_feedback(&self) -> bool {
        self.transform_feedback.is_some()
    }

    pub(crate) fn transform_feedback(&self) -> Result<&ash::ext::transform_feedback::Device> {
        self.transform_feedback
            .as_ref()
            .ok_or_else(|| VkError::Unsupported {
                device: self.info.name.clone(),
                what: "VK_EXT_transform_feedback with the transformFeedback feature",
            })
    }

    /// Bytes still held by the allocator, after destroying what completed submissions freed:
    /// zero once every resource is dropped and the GPU finished with it.
    pub fn allocated_bytes(&self) -> u64 {
        self.collect_retired();
        self.allocator
            .lock()
            .map(|a| a.generate_report().total_allocated_bytes)
            .unwrap_or(0)
    }

    /// Vulkan handles created through this device and not yet destroyed, after destroying what
    /// completed submissions freed: every buffer, image, image view, pipeline, pipeline layout,
    /// shader module, descriptor pool and set layout, query pool, command pool (including idle
    /// one-shot pools kept for reuse), semaphore, fence, swapchain and surface vk-core made
    /// after the device itself (its timeline semaphore and pipeline cache are not counted).
    /// Command buffers and descriptor sets are not counted: they live and die with their pools.
    /// Next to [`DeviceShared::allocated_bytes`], what a soak run watches: both stay constant
    /// once a frame loop has warmed up, unless something leaks.
    pub fn live_objects(&self) -> u64 {
        self.collect_retired();
        self.live.load(Ordering::Relaxed)
    }

    /// Counts `n` handles just created (see [`DeviceShared::live_objects`]).
    pub(crate) fn created(&self, n: u64) {
        self.live.fetch_add(n, Ordering::Relaxed);
    }

    /// Counts `n` handles just destroyed.
    pub(crate) fn destroyed(&self, n: u64) {
        self.live.fetch_sub(n, Ordering::Relaxed);
    }

    /// Waits until the queue is idle, then destroys every retired object.
    pub fn wait_idle(&self) {
        {
            let _q = self.queue_lock.lock();
            // SAFETY: raw is live; queue access is serialized by queue_lock.
            let _ = unsafe { self.raw.device_wait_idle() };
        }
        self.collect_retired();
    }

    /// Destroys the one-shot command pools kept for reuse ([`Device::submit_once`] takes one
    /// and gives it back when its submission completes). Idle pools are the device's cache,
    /// not anything a caller holds: after this, [`DeviceShared::live_objects`] counts only
    /// what callers hold (or leaked). Used before a final count; a later one-shot submission
    /// makes a new pool.
    pub fn release_idle_command_pools(&self) {
        let pools = match self.once_pools.lock() {
            Ok(mut p) => std::mem::take(&mut *p),
            Err(_) => return,
        };
        for (pool, _) in pools {
            // SAFETY: a pool is in `once_pools` only once its command buffer is no longer
            // pending (recycled after its submission completed, or never submitted); it was
            // taken out under the lock, so no other thread uses it.
            unsafe { self.raw.destroy_command_pool(pool, None) };
            self.destroyed(1);
        }
    }

    pub fn pipeline_cache(&self) -> vk::PipelineCache {
        self.pipeline_cache
    }

    /// Writes the pipeline cache to this device's file (when a directory was given and the
    /// cache changed since it was read), atomically; failures only warn.
    pub fn save_pipeline_cache(&self) {
        let Some((path, read_hash)) = &self.pipeline_cache_file else {
            return;
        };
        // SAFETY: the cache belongs to this device.
        match unsafe { self.raw.get_pipeline_cache_data(self.pipeline_cache) } {
            Ok(data) if data_hash(&data) == *read_hash => {}
            Ok(data) => {
                if let Err(e) = pipeline_cache::save(path, &data) {
                    log::warn!("pipeline cache not saved to {}: {e}", path.display());
                }
            }
            Err(e) => log::warn!("pipeline cache data unavailable: {e}"),
        }
    }

    /// This device's pipeline cache file, when it keeps one.
    pub fn pipeline_cache_file(&self) -> Option<&std::path::Path> {
        self.pipeline_cache_file.as_ref().map(|(p, _)| p.as_path())
    }
}

/// A hash of cache data, to tell whether it changed since it was read.
fn data_hash(data: &[u8]) -> u64 {
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    data.hash(&mut h);
    h.finish()
}

impl Drop for DeviceShared {
    fn drop(&mut self) {
        self.save_pipeline_cache();
        // SAFETY: the last Arc is gone, so no resource of this device remains except what waits
        // in the retire queue; after the idle wait no submission is pending, so those and the
        // one-shot pools are unused. Children go before the device, the allocator too.
        unsafe {
            if self.owns_device {
                let _ = self.raw.device_wait_idle();
            } else {
                // A host's device: wait for vk-core's own submissions only; what the host
                // recorded is the host's to have waited for (Encoder::record_into).
                let submitted = self.retired.get_mut().map(|q| q.submitted).unwrap_or(0);
                let _ = self.wait_serial(submitted);
            }
            let waiting = match self.retired.get_mut() {
                Ok(q) => std::mem::take(&mut q.waiting),
                Err(p) => std::mem::take(&mut p.into_inner().waiting),
            };
            for (_, item) in waiting {
                self.destroy_retired(item);
            }
            let pools = match self.once_pools.get_mut() {
                Ok(p) => std::mem::take(p),
                Err(_) => Vec::new(),
            };
            for (pool, _) in pools {
                self.raw.destroy_command_pool(pool, None);
                self.destroyed(1);
            }
            self.raw.destroy_semaphore(self.timeline, None);
            self.raw.destroy_pipeline_cache(self.pipeline_cache, None);
            let live = self.live.load(Ordering::Relaxed);
            if live != 0 {
                log::error!("{live} Vulkan objects of vk-core still live at device drop");
            }
            if let Ok(a) = self.allocator.lock() {
                let report = a.generate_report();
                if !report.allocations.is_empty() {
                    log::error!(
                        "gpu-allocator: {} allocations leaked at device drop",
                        report.allocations.len()
                    );
                }
            }
            ManuallyDrop::drop(&mut self.allocator);
            if self.owns_device {
                self.raw.destroy_device(None);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn adapter(index: usize, ty: vk::PhysicalDeviceType, complete: bool) -> AdapterInfo {
        AdapterInfo {
            index,
            name: format!("device{index}"),
            device_type: ty,
            driver_id: vk::DriverId::default(),
            driver_name: "test".into(),
            driver_info: String::new(),
            driver_version: 0,
            api_version: vk::API_VERSION_1_3,
            vendor_id: 0,
            device_id: 0,
            pipeline_cache_uuid: [0; 16],
            caps: Capabilities {
                tessellation_shader: true,
                fill_mode_non_solid: complete,
                dynamic_rendering: true,
                timeline_semaphore: true,
                ..Default::default()
            },
            queue_family: Some(0),
            missing: if complete {
                vec![]
            } else {
                vec!["fillModeNonSolid".into()]
            },
            physical: vk::PhysicalDevice::null(),
        }
    }

    #[test]
    fn scoring_prefers_discrete_then_lowest_index() {
        use vk::PhysicalDeviceType as T;
        let a = [
            adapter(0, T::CPU, true),
            adapter(1, T::INTEGRATED_GPU, true),
            adapter(2, T::DISCRETE_GPU, true),
            adapter(3, T::DISCRETE_GPU, true),
        ];
        assert_eq!(choose_adapter(&a, &DeviceSelector::Auto).unwrap(), 2);
        assert_eq!(choose_adapter(&a, &DeviceSelector::Index(0)).unwrap(), 0);
        assert_eq!(
            choose_adapter(&a, &DeviceSelector::Name("DEVICE1".into())).unwrap(),
            1
        );
    }

    #[test]
    fn transform_feedback_is_optional() {
        use vk::PhysicalDeviceType as T;
        let mut a = adapter(0, T::CPU, true);
        a.caps.transform_feedback = false;
        assert!(a.score() > 0 && a.missing.is_empty());
        assert_eq!(choose_adapter(&[a], &DeviceSelector::Auto).unwrap(), 0);
    }

    #[test]
    fn tessellation_is_optional() {
        use vk::PhysicalDeviceType as T;
        let mut a = adapter(0, T::CPU, true);
        a.caps.tessellation_shader = false;
        a.missing = missing_requirements(a.api_version, &a.caps, a.queue_family);
        assert!(a.score() > 0 && a.missing.is_empty(), "{:?}", a.missing);
        assert_eq!(choose_adapter(&[a], &DeviceSelector::Auto).unwrap(), 0);
    }

    #[test]
    fn a_missing_feature_is_a_typed_error_listing_devices() {
        use vk::PhysicalDeviceType as T;
        let a = [
            adapter(0, T::DISCRETE_GPU, false),
            adapter(1, T::CPU, false),
        ];
        let e = choose_adapter(&a, &DeviceSelector::Auto).unwrap_err();
        let text = e.to_string();
        assert!(matches!(e, VkError::NoSuitableDevice(_)));
        assert!(
            text.contains("device0")
                && text.contains("device1")
                && text.contains("fillModeNonSolid"),
            "{text}"
        );
        let e = choose_adapter(&a, &DeviceSelector::Index(0)).unwrap_err();
        assert!(matches!(e, VkError::MissingFeatures { .. }), "{e}");
        let e = choose_adapter(&a, &DeviceSelector::Name("nvidia".into())).unwrap_err();
        assert!(matches!(e, VkError::NoSuchDevice { .. }), "{e}");
    }
}
