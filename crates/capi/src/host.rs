//! Host-owned mode: Tessera draws into a C++ host's own Vulkan device and command buffers.
//!
//! # What the host gives and keeps
//! The host passes its `VkInstance`, `VkPhysicalDevice`, `VkDevice`, a queue family and queue,
//! its `vkGetInstanceProcAddr` and where Tessera's draws will be recorded: dynamic-rendering
//! scopes of given colour/depth formats, or a subpass of its `VkRenderPass` (index, sample
//! count and the formats of its colour and depth attachments), for which Tessera builds
//! compatible pipelines (render pass compatibility: the host may begin any render pass
//! compatible with the one it gave). Tessera wraps them (`vk_core::Instance::from_host`,
//! `vk_core::Device::from_host`) and never destroys any of them; it creates and destroys only
//! its own objects (buffers, pipelines, layouts, descriptor pools, its pipeline cache, a
//! timeline semaphore and one-shot command pools).
//!
//! # Recording
//! - [`tessera_record_pre_pass`] records the technique's compute kernels (BFT and adaptive
//!   evaluate their animated bases there; flat, phong and pn record nothing) into a command
//!   buffer the host has begun, **outside** any rendering scope, before the pass. Tessera
//!   records the barriers its own writes need itself: from the previous use of its buffers to
//!   the compute writes, and from the compute writes (shader write) to the vertex, tessellation
//!   control and evaluation stages' reads (shader read) of this frame. The host needs no
//!   barrier for Tessera's resources.
//! - [`tessera_record_draw`] records the draws inside the host's rendering scope (begun by the
//!   host with dynamic rendering and the formats given at creation, or the given subpass of
//!   a render pass instance; viewport and scissor set by the host: Tessera's pipelines take
//!   both as dynamic state). It binds its own pipelines
//!   and sets; after it returns the host must re-bind its own. It writes the colour and depth
//!   attachments the host's scope holds, with depth test and write on (LESS; the wireframe
//!   overlay LESS_OR_EQUAL without writes); ordering those writes against later reads of the
//!   attachments is the host's, as for its own draws.
//! - Tessera never begins, ends, resets or submits a host command buffer, and never waits on
//!   the device or a host queue. The only submissions it makes are its own uploads when a
//!   surface is created (device-local tables) and captures ([`crate::tessera_capture`]), on
//!   the host's queue, each in a command buffer of its own waited for on Tessera's own
//!   timeline semaphore: the host must not use that queue on another thread during
//!   `tessera_surface_create*` and `tessera_capture*` (Vulkan's external synchronization of
//!   queues).
//!
//! # Device features
//! Dynamic rendering needs `dynamicRendering` enabled; a render pass does not, except for
//! captures, which render into an attachment-less dynamic-rendering scope of Tessera's own.
//! The planned-patch techniques (adaptive, gregory, acc), bft and doo-sabin need
//! `bufferDeviceAddress` enabled and `buffer_device_address` set: they read arrays by address
//! (vertex and patch arrays, basis-function tables, the deepest Doo-Sabin level).
//!
//! # Frames in flight
//! The host says how many frames it keeps in flight (`frames_in_flight`); every surface keeps
//! that many copies of its frame uniforms and animated positions. [`tessera_begin_frame`]
//! names the frame about to be recorded: frame `k` writes slot `k % frames_in_flight`, so the
//! host must have waited (its own fences) for the GPU to finish frame `k - frames_in_flight`
//! before calling it for frame `k`, which it does anyway to reuse its command buffers.
//!
//! # Destruction
//! Tessera cannot see the host's submissions, so it keys destruction to the frame index the
//! host advances. `tessera_surface_destroy` invalidates the handle at once but keeps the
//! surface's objects until [`tessera_begin_frame`] names a frame `frames_in_flight` past the
//! frame current at the destruction (which the host calls only once the frames that could have
//! drawn it finished). `tessera_context_destroy` frees everything at once: the host calls it
//! only after the GPU finished every command buffer Tessera recorded into (its frame fences,
//! or `vkDeviceWaitIdle`), as it must before destroying its own device. The host's device,
//! queue and instance are left alive.
use crate::ffi::{out_write, read_required};
use crate::handles::lock;
use crate::status::{Error, Result, TesseraStatus};
use crate::{
    context_ptr, flag, guard, handles, surface_frame_params, with_context, with_surface,
    ContextState, Mode, TesseraContext, TesseraFrameDesc, TesseraSurface,
};
use vk_core::{vk, Device, Encoder, HostDevice, HostScope, Instance};

/// `vkGetInstanceProcAddr` as vulkan.h declares it (the header uses vulkan.h's own type).
#[allow(non_camel_case_types)]
pub type PFN_vkGetInstanceProcAddr = Option<vk::PFN_vkGetInstanceProcAddr>;
/// vulkan.h's handle and enum types (the header uses vulkan.h's own).
pub type VkInstance = vk::Instance;
pub type VkPhysicalDevice = vk::PhysicalDevice;
pub type VkDevice = vk::Device;
pub type VkQueue = vk::Queue;
pub type VkCommandBuffer = vk::CommandBuffer;
pub type VkFormat = vk::Format;
pub type VkRenderPass = vk::RenderPass;

/// The host's Vulkan objects, none of which Tessera ever destroys.
#[repr(C)]
#[derive(Clone, Copy, Debug)]
pub struct TesseraHostDesc {
    pub get_instance_proc_addr: PFN_vkGetInstanceProcAddr,
    /// Created for Vulkan 1.3 or later.
    pub instance: VkInstance,
    pub physical_device: VkPhysicalDevice,
    /// Created from `physical_device` with `fillModeNonSolid` and `timelineSemaphore`
    /// enabled, `tessellationShader` unless `without_tessellation_shader` says otherwise, and
    /// `dynamicRendering` for dynamic-rendering scopes and captures.
    pub device: VkDevice,
    /// A family with graphics and compute; `queue` is its queue 0.
    pub queue_family: u32,
    pub queue: VkQueue,
    /// Formats of the host's attachments Tessera's draws write: of its dynamic-rendering
    /// scopes, or of the colour attachment (the subpass's one) and the depth attachment
    /// (`VK_FORMAT_UNDEFINED`: none) of `subpass` of `render_pass`.
    pub color_format: VkFormat,
    pub depth_format: VkFormat,
    /// 1 or more.
    pub frames_in_flight: u32,
    /// 0 or 1: VK_EXT_debug_utils is enabled on the instance (Tessera then names its objects).
    pub debug_utils: u32,
    /// 0 or 1: VK_EXT_transform_feedback and its feature are enabled on the device.
    pub transform_feedback: u32,
    /// 0 or 1: `pipelineStatisticsQuery` is enabled.
    pub pipeline_statistics_query: u32,
    /// 0 or 1: `vertexPipelineStoresAndAtomics` is enabled.
    pub vertex_pipeline_stores_and_atomics: u32,
    /// VK_NULL_HANDLE: Tessera's draws go into the host's dynamic-rendering scopes. Otherwise
    /// they go into subpass `subpass` of instances of this render pass (or of one compatible
    /// with it): its pipelines are made for that subpass, which must have exactly one colour
    /// attachment (`color_format`) and at most a depth attachment (`depth_format`), all with
    /// `samples` samples. The render pass must outlive the context.
    pub render_pass: VkRenderPass,
    pub subpass: u32,
    /// `VkSampleCountFlagBits` of the subpass's attachments (1, 2, 4, ... 64; 0 means 1).
    /// Render passes only: dynamic rendering takes 0 or 1.
    pub samples: u32,
    /// 0 or 1: `dynamicRendering` is enabled. Dynamic rendering needs it (so it is taken as 1
    /// there); with a render pass only captures do (they render into a scope of their own),
    /// and are UNSUPPORTED without it.
    pub dynamic_rendering: u32,
    /// `TESSERA_PIPELINE_CACHE_*`: Tessera's own pipeline cache (never one of the host's), kept
    /// as [`crate::TesseraStandaloneDesc`] says.
    pub pipeline_cache: crate::TesseraPipelineCache,
    /// NULL (the user's cache directory) or a NUL-terminated directory for it.
    pub pipeline_cache_dir: *const std::ffi::c_char,
    /// 0 or 1: `tessellationShader` is not enabled on the device. Surfaces then draw through
    /// refinement patterns (`TESSERA_PIPELINE_AUTO` picks them; flat, phong, pn), and the
    /// techniques without that path are refused as UNSUPPORTED.
    pub without_tessellation_shader: u32,
    /// 0 or 1: `bufferDeviceAddress` (required in Vulkan 1.3) is enabled. The planned-patch
    /// techniques (`TESSERA_TECHNIQUE_ADAPTIVE`, `_GREGORY`, `_ACC`), `_BFT` and `_DOO_SABIN`
    /// (and whatever `_AUTO` makes of them) read arrays by address (vertex and patch arrays,
    /// basis-function tables, the deepest level), so that no `maxStorageBufferRange` limits
    /// them; with 0 they are UNSUPPORTED.
    pub buffer_device_address: u32,
}

/// The subpass `d` names, checked; `None` for dynamic rendering.
fn host_subpass(d: &TesseraHostDesc) -> Result<Option<vk_core::pipeline::Subpass>> {
    let samples = match d.samples {
        0 => 1,
        s => s,
    };
    if !samples.is_power_of_two() || samples > 64 {
        return Err(Error::new(
            TesseraStatus::InvalidArgument,
            format!(
                "samples {}: expected a VkSampleCountFlagBits (1, 2, 4, ... 64)",
                d.samples
            ),
        ));
    }
    if d.render_pass == vk::RenderPass::null() {
        if d.subpass != 0 || samples != 1 {
            return Err(Error::new(
                TesseraStatus::InvalidArgument,
                format!(
                    "subpass {} and samples {} apply to a render pass, and render_pass is \
                     VK_NULL_HANDLE (dynamic rendering takes subpass 0 and samples 0 or 1)",
                    d.subpass, d.samples
                ),
            ));
        }
        return Ok(None);
    }
    Ok(Some(vk_core::pipeline::Subpass {
        render_pass: d.render_pass,
        index: d.subpass,
        samples: vk::SampleCountFlags::from_raw(samples),
    }))
}

/// Creates a host-owned context on the host's device (see the module documentation in
/// crates/capi/src/host.rs for what Tessera records and never does). Thread-safe.
///
/// # Safety
/// `desc` is readable and its handles are live as [`TesseraHostDesc`] states, and outlive the
/// context; `out` points to a writable `TesseraContext*` (set to NULL on failure).
#[no_mangle]
pub unsafe extern "C" fn tessera_context_create_host(
    desc: *const TesseraHostDesc,
    out: *mut *mut TesseraContext,
) -> TesseraStatus {
    guard(|| {
        // SAFETY: the caller's contract for `out` and `desc`.
        unsafe { out_write(out, std::ptr::null_mut(), "out") }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        let d = unsafe { read_required(desc, "desc") }?;
        let gipa = d.get_instance_proc_addr.ok_or_else(|| {
            Error::new(TesseraStatus::NullPointer, "get_instance_proc_addr is NULL")
        })?;
        for (what, null) in [
            ("instance", d.instance == vk::Instance::null()),
            (
                "physical_device",
                d.physical_device == vk::PhysicalDevice::null(),
            ),
            ("device", d.device == vk::Device::null()),
            ("queue", d.queue == vk::Queue::null()),
        ] {
            if null {
                return Err(Error::new(
                    TesseraStatus::NullHandle,
                    format!("desc.{what} is VK_NULL_HANDLE"),
                ));
            }
        }
        if d.frames_in_flight == 0 || d.frames_in_flight > 16 {
            return Err(Error::new(
                TesseraStatus::InvalidArgument,
                format!("frames_in_flight {}: expected 1..=16", d.frames_in_flight),
            ));
        }
        if d.color_format == vk::Format::UNDEFINED {
            return Err(Error::new(
                TesseraStatus::InvalidArgument,
                "color_format is VK_FORMAT_UNDEFINED: Tessera's draws need a colour attachment",
            ));
        }
        let subpass = host_subpass(&d)?;
        let dynamic_rendering =
            flag(d.dynamic_rendering, "dynamic_rendering")? || subpass.is_none();
        // SAFETY: the caller's contract for `pipeline_cache_dir`.
        let cache = unsafe { crate::pipeline_cache_dir(d.pipeline_cache, d.pipeline_cache_dir) }?;
        // SAFETY: the caller's contract (TesseraHostDesc's documented requirements).
        let instance =
            unsafe { Instance::from_host(gipa, d.instance, flag(d.debug_utils, "debug_utils")?) }?;
        let host = HostDevice {
            physical: d.physical_device,
            device: d.device,
            queue_family: d.queue_family,
            queue: d.queue,
            transform_feedback: flag(d.transform_feedback, "transform_feedback")?,
            pipeline_statistics_query: flag(
                d.pipeline_statistics_query,
                "pipeline_statistics_query",
            )?,
            vertex_pipeline_stores_and_atomics: flag(
                d.vertex_pipeline_stores_and_atomics,
                "vertex_pipeline_stores_and_atomics",
            )?,
            tessellation_shader: !flag(
                d.without_tessellation_shader,
                "without_tessellation_shader",
            )?,
            buffer_device_address: flag(d.buffer_device_address, "buffer_device_address")?,
            dynamic_rendering,
        };
        // SAFETY: as above.
        let device = unsafe { Device::from_host(&instance, &host, cache.as_deref()) }?;
        let id = lock(handles())?.add_context(ContextState {
            graveyard: Vec::new(),
            device,
            instance,
            mode: Mode::Host {
                frames_in_flight: d.frames_in_flight as usize,
                frame: 0,
                formats: [d.color_format, d.depth_format],
                subpass,
                dynamic_rendering,
            },
            last_error: String::new(),
        });
        // SAFETY: as above.
        unsafe { out_write(out, context_ptr(id), "out") }
    })
}

fn host_only(c: &ContextState, call: &str) -> Result<()> {
    match c.mode {
        Mode::Host { .. } => Ok(()),
        Mode::Standalone => Err(Error::new(
            TesseraStatus::WrongMode,
            format!("{call} needs a host-owned context (this one renders standalone)"),
        )),
    }
}

/// Names the frame about to be recorded (host-owned mode). Frame `k` uses slot
/// `k % frames_in_flight`: the GPU must have finished frame `k - frames_in_flight`.
/// Thread-safe (serialized per context).
///
/// # Safety
/// None beyond the handle, which may be anything.
#[no_mangle]
pub unsafe extern "C" fn tessera_begin_frame(
    ctx: *mut TesseraContext,
    frame_index: u64,
) -> TesseraStatus {
    with_context(ctx, |c| {
        host_only(c, "tessera_begin_frame")?;
        if let Mode::Host {
            frame,
            frames_in_flight,
            ..
        } = &mut c.mode
        {
            *frame = frame_index;
            // Frame `frame_index - frames_in_flight` finished, so did every frame before it:
            // surfaces destroyed while one of those was current are no longer drawn.
            let n = *frames_in_flight as u64;
            c.graveyard
                .retain(|(destroyed_in, _)| destroyed_in.saturating_add(n) > frame_index);
        }
        Ok(())
    })
}

/// Sets what the surface's host-owned frames draw: factors, spacing, wireframe, colours, and
/// the viewport size screen-space factors see (`width`, `height`); the camera fields are
/// ignored (the host gives view and projection to [`tessera_record_draw`]). Checked against
/// the technique here, so a refused option fails now rather than while recording.
/// Thread-safe (serialized per context).
///
/// # Safety
/// `frame` is readable.
#[no_mangle]
pub unsafe extern "C" fn tessera_surface_set_frame(
    ctx: *mut TesseraContext,
    surface: *mut TesseraSurface,
    frame: *const TesseraFrameDesc,
) -> TesseraStatus {
    with_surface(ctx, surface, |_, s| {
        // SAFETY: the caller's contract.
        let f = unsafe { read_required(frame, "frame") }?;
        let frame = surface_frame_params(s, &f)?;
        s.technique.check(&frame.0)?;
        s.frame = frame;
        Ok(())
    })
}

/// Records the surface's pre-pass (compute kernels and their barriers; nothing for techniques
/// without one) into `cmd`, which the host has begun and which is outside any rendering scope.
/// Call once per frame per surface, before the scope [`tessera_record_draw`] records into.
/// Thread-safe (serialized per context); `cmd` itself must not be recorded into by another
/// thread during the call.
///
/// # Safety
/// `cmd` is a primary command buffer of the context's device in the recording state, outside
/// a rendering scope; the host submits it before the draws' command buffer (or it is the same
/// one) in the frame named by [`tessera_begin_frame`], and destroys the context only after the
/// GPU finished it.
#[no_mangle]
pub unsafe extern "C" fn tessera_record_pre_pass(
    ctx: *mut TesseraContext,
    surface: *mut TesseraSurface,
    cmd: VkCommandBuffer,
) -> TesseraStatus {
    with_surface(ctx, surface, |c, s| {
        host_only(c, "tessera_record_pre_pass")?;
        no_null_cmd(cmd)?;
        let slot = c.slot();
        s.sync_positions(slot)?;
        // SAFETY: the caller's contract: a recording command buffer of this device outside
        // any scope, whose execution the host waits for before destroying the surface.
        let mut enc = unsafe { Encoder::record_into(&c.device, cmd, None) };
        s.tess
            .record_pre_pass(&mut enc, s.technique.as_ref(), slot)?;
        enc.finish()?;
        Ok(())
    })
}

/// Records the surface's draws (shaded, and the wireframe overlay when the frame asks) into
/// `cmd` inside the host's rendering scope, seen through `view` and `proj` (column-major 4x4,
/// right-handed, depth 0..1 as glam's `perspective_rh`; Tessera's own images flip y with a
/// negative viewport height, so a host matches them by setting its viewport the same way).
/// Writes the frame's uniforms first (slot of [`tessera_begin_frame`]'s frame).
/// Thread-safe (serialized per context); `cmd` itself must not be recorded into by another
/// thread during the call.
///
/// # Safety
/// `cmd` is a primary command buffer of the context's device in the recording state, viewport
/// and scissor set, inside a rendering scope begun with dynamic rendering and the context's
/// formats, or (a context made with a render pass) inside its `subpass` of an instance of that
/// render pass or of one compatible with it, begun with `VK_SUBPASS_CONTENTS_INLINE`; `view` and `proj` point to 16 readable floats each; `cmd` is submitted in the
/// frame named by [`tessera_begin_frame`], and the context is destroyed only after the GPU
/// finished it.
#[no_mangle]
pub unsafe extern "C" fn tessera_record_draw(
    ctx: *mut TesseraContext,
    surface: *mut TesseraSurface,
    cmd: VkCommandBuffer,
    view: *const f32,
    proj: *const f32,
) -> TesseraStatus {
    with_surface(ctx, surface, |c, s| {
        host_only(c, "tessera_record_draw")?;
        no_null_cmd(cmd)?;
        // SAFETY: the caller's contract.
        let view = unsafe { read_required(view.cast::<[f32; 16]>(), "view") }?;
        // SAFETY: the caller's contract (see this function's `# Safety`).
        let proj = unsafe { read_required(proj.cast::<[f32; 16]>(), "proj") }?;
        if let Some(x) = view.iter().chain(&proj).find(|x| !x.is_finite()) {
            return Err(Error::new(
                TesseraStatus::NonFinite,
                format!("view or proj holds a non-finite number ({x})"),
            ));
        }
        let view = glam::Mat4::from_cols_array(&view);
        let proj = glam::Mat4::from_cols_array(&proj);
        if view.determinant() == 0.0 {
            return Err(Error::new(
                TesseraStatus::InvalidArgument,
                "view is not invertible",
            ));
        }
        let Mode::Host {
            formats, subpass, ..
        } = c.mode
        else {
            return Err(Error::new(TesseraStatus::WrongMode, "not host-owned"));
        };
        let scope = match subpass {
            None => HostScope::Rendering(formats),
            Some(subpass) => HostScope::Subpass { subpass, formats },
        };
        let slot = c.slot();
        s.sync_positions(slot)?;
        let (params, extent) = s.frame;
        let eye = view.inverse().w_axis.truncate();
        let m = tess::camera::CameraMatrices { view, proj, eye };
        let uniforms = tess::context::frame_uniforms_with(m, s.technique.bbox(), &params, extent);
        s.tess.write_frame_uniforms(slot, &uniforms)?;
        s.tess.prepare(
            s.technique.as_mut(),
            &params,
            tess::Context::frame_passes(&params),
        )?;
        let technique = s.technique.as_ref();
        // SAFETY: the caller's contract: a recording command buffer of this device inside the
        // host's scope as the context describes it (dynamic rendering of these formats, or
        // the render pass's subpass), whose execution the host waits for before destroying
        // the surface.
        let mut enc = unsafe { Encoder::record_into(&c.device, cmd, Some(scope)) };
        s.tess.record_frame(&mut enc, technique, slot, &params)?;
        enc.finish()?;
        Ok(())
    })
}

fn no_null_cmd(cmd: vk::CommandBuffer) -> Result<()> {
    if cmd == vk::CommandBuffer::null() {
        return Err(Error::new(
            TesseraStatus::NullHandle,
            "cmd is VK_NULL_HANDLE",
        ));
    }
    Ok(())
}
