//! Vulkan plumbing for Tessera: instance, device, memory, buffers, images, pipelines, targets and
//! queries, on `ash` with `gpu-allocator`. It knows nothing of subdivision.
//!
//! Design decisions:
//! - Vulkan is loaded at run time (`ash::Entry::load`), so a missing loader is an error value.
//! - Every resource holds an `Arc<DeviceShared>` and frees itself in `Drop`; the device outlives
//!   all of them and the instance outlives the device. Field order states the drop order.
//! - The validation layer's messages are counted by severity; tests assert no error-severity one.
//! - Rendering uses Vulkan 1.3 dynamic rendering; vk-core makes no render-pass objects, but
//!   pipelines can be made for a host application's render pass subpass
//!   ([`pipeline::Subpass`]) and recorded into its render pass instance
//!   ([`HostScope::Subpass`]).
//! - A UI overlay ([`overlay`], egui through egui-ash-renderer) draws into a frame's scope behind
//!   safe calls, so the window's HUD needs no `unsafe` above vk-core.
//! - Optional features (VK_EXT_transform_feedback, for captures) are detected and enabled when
//!   present; what needs them returns [`VkError::Unsupported`] where they are absent.
//! - Textures ([`texture`]) are sampled 2D images with their own sampler, uploaded and
//!   mip-mapped when made, and resting in SHADER_READ_ONLY_OPTIMAL between recordings.
//! - Draws are direct, instanced or indirect; an indirect draw's buffer knows how far its
//!   commands reach ([`indirect`]), and the encoder checks that against the bound buffers as it
//!   checks a direct draw's ranges.
//! - Driver bugs are worked around through [`workarounds`], a documented list keyed by driver.
//! - Commands are recorded through [`Encoder`], whose module states the `unsafe` contracts once
//!   and why its safe methods uphold them; crates above vk-core need no `unsafe`.
//! - Objects are destroyed through the device's retire queue ([`retire`]): never while a
//!   submission that could use them is pending, so frames need not be waited for.
//! - A host application's instance and device (the C ABI's host-owned mode) are wrapped, not
//!   owned ([`Instance::from_host`], [`Device::from_host`]: loaded through the host's
//!   `vkGetInstanceProcAddr`, never destroyed or waited idle), and [`Encoder::record_into`]
//!   records into the host's command buffers, inside its rendering scope, without submitting.
//! - Every handle vk-core creates is counted where it is created and where it is destroyed
//!   ([`DeviceShared::live_objects`]), next to gpu-allocator's bytes
//!   ([`DeviceShared::allocated_bytes`]): soak runs assert both constant after warm-up.
//! - The `tessera` binary fixes its host heap's mmap threshold ([`host_heap`]) so that freed
//!   preparation blocks leave the process, and keeps the heap's top untrimmed so that
//!   lavapipe's per-draw arrays keep their pages; a library linked into a host leaves its heap
//!   alone.
#![deny(unsafe_op_in_unsafe_fn)]
pub mod buffer;
pub mod command;
pub mod descriptor;
pub mod device;
pub mod encoder;
pub mod error;
pub mod host_heap;
pub mod image;
pub mod indirect;
pub mod instance;
pub mod overlay;
pub mod pipeline;
pub mod pipeline_cache;
pub mod query;
pub mod retire;
pub mod swapchain;
pub mod target;
pub mod texture;
pub mod workarounds;

#[cfg(test)]
mod tests;

pub use ash::vk;
pub use buffer::{Buffer, BufferDesc};
pub use descriptor::{BindingDesc, DescriptorPool, DescriptorSet, DescriptorSetLayout};
pub use device::{AdapterInfo, Device, DeviceDesc, DeviceSelector, DeviceShared, HostDevice};
pub use encoder::{Encoder, HostScope, Submission};
pub use error::{DescriptorError, RecordingError, Result, VkError};
pub use gpu_allocator::MemoryLocation;
pub use image::{Image, ImageDesc};
pub use indirect::{DrawCommand, DrawIndexedCommand, IndirectDraws, IndirectExtent, IndirectKind};
pub use instance::{Instance, InstanceDesc, MessageCounts, Validation};
pub use overlay::{Overlay, OverlayDesc};
pub use pipeline::Pipeline;
pub use query::QueryPool;
pub use swapchain::{Swapchain, SwapchainFrame};
pub use target::OffscreenTarget;
pub use texture::{Texture, TextureDesc, TextureFormat};
