//! One error type for the crate. Every variant names what failed (the Vulkan call, the object by
//! its debug name, the option or binding) in fields, so a C ABI can map variants to status codes
//! and still print a message that says where the fault lies. `vk::Result` is wrapped with the call
//! that returned it; misuse of an [`crate::Encoder`] is a [`RecordingError`] naming the command;
//! a rejected descriptor write is a [`DescriptorError`] naming the set and binding.
use ash::vk;

pub type Result<T, E = VkError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum VkError {
    #[error(
        "no Vulkan loader found (install libvulkan1 and a driver such as mesa-vulkan-drivers): {0}"
    )]
    NoLoader(String),
    #[error("{call} failed: {result}")]
    Call {
        call: &'static str,
        result: vk::Result,
    },
    #[error("no usable Vulkan device: {0}")]
    NoSuitableDevice(String),
    #[error("device selector {selector:?} matches no device; devices seen:\n{devices}")]
    NoSuchDevice { selector: String, devices: String },
    #[error("device {name} lacks what Tessera needs: {missing}")]
    MissingFeatures { name: String, missing: String },
    /// An optional capability (not needed to render) that one operation needs.
    #[error("device {device} lacks {what}, which this operation needs")]
    Unsupported { device: String, what: &'static str },
    #[error("gpu-allocator: {0}")]
    Allocator(#[from] gpu_allocator::AllocationError),
    /// A lock of the device's shared state was poisoned by a panic on another thread.
    #[error("HUD overlay: {0}")]
    Overlay(#[from] egui_ash_renderer::RendererError),
    #[error("the {what} lock was poisoned by a panic on another thread")]
    LockPoisoned { what: &'static str },
    /// Host access to a buffer whose memory is not host-visible.
    #[error("buffer {buffer} is not host-visible")]
    NotHostVisible { buffer: String },
    /// A byte range outside the object it addresses.
    #[error("{what} [{offset}, {offset}+{len}) lies outside {object} ({size} bytes)")]
    OutOfBounds {
        object: String,
        what: &'static str,
        offset: u64,
        len: u64,
        size: u64,
    },
    /// An image extent outside what the target accepts.
    #[error("{what} size {width}x{height} is outside 1..{max}")]
    Extent {
        what: &'static str,
        width: u32,
        height: u32,
        max: u32,
    },
    /// Pixels whose count does not match the picture's size.
    #[error("picture of {width}x{height} has {bytes} bytes, not width·height·4")]
    PictureSize {
        width: u32,
        height: u32,
        bytes: usize,
    },
    /// An operation on a query pool of another type.
    #[error("{call} on query pool {pool}: it holds {found:?} queries, not {expected:?}")]
    QueryType {
        call: &'static str,
        pool: String,
        expected: vk::QueryType,
        found: vk::QueryType,
    },
    /// A query index outside its pool.
    #[error("{call}: query {index} is outside pool {pool} of {count}")]
    QueryIndex {
        call: &'static str,
        pool: String,
        index: u32,
        count: u32,
    },
    /// An indirect draw command vk-core refused to write (see [`crate::indirect`]).
    #[error("indirect draw {draw}: {problem}")]
    IndirectCommand { draw: usize, problem: String },
    /// A command recorded where Vulkan forbids it, or with arguments vk-core can tell are wrong.
    #[error("{command}: {problem}")]
    Recording {
        command: &'static str,
        problem: RecordingError,
    },
    /// A descriptor write vk-core refused.
    #[error("descriptor set {set}, binding {binding}: {problem}")]
    Descriptor {
        set: String,
        binding: u32,
        problem: DescriptorError,
    },
    #[error("I/O on {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    #[error("image encoding for {path}: {message}")]
    Image { path: String, message: String },
    #[error("window surface: {0}")]
    Surface(String),
}

/// What was wrong with a recorded command (see [`VkError::Recording`] for which command).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum RecordingError {
    #[error("no pipeline is bound")]
    NoPipeline,
    #[error("the bound pipeline {pipeline} is a {bound:?} pipeline, this needs {needed:?}")]
    BindPoint {
        pipeline: String,
        bound: vk::PipelineBindPoint,
        needed: vk::PipelineBindPoint,
    },
    #[error("{bytes} bytes of push constants exceed pipeline {pipeline}'s range of {range}")]
    PushConstantsTooLarge {
        pipeline: String,
        bytes: usize,
        range: u32,
    },
    #[error("{bytes} bytes of push constants: the size must be a non-zero multiple of 4")]
    PushConstantsSize { bytes: usize },
    #[error("sets {first}..{end} exceed pipeline {pipeline}'s {count} set layouts")]
    SetIndex {
        pipeline: String,
        first: u32,
        end: u32,
        count: u32,
    },
    #[error("set {index} ({set}) was not allocated with the layout pipeline {pipeline} expects")]
    SetLayout {
        pipeline: String,
        index: u32,
        set: String,
    },
    #[error("set {index} of pipeline {pipeline} is not bound")]
    SetMissing { pipeline: String, index: u32 },
    #[error("binding {binding} of set {set} was never written")]
    SetIncomplete { set: String, binding: u32 },
    #[error("buffer {buffer} lacks usage {needed:?}")]
    BufferUsage {
        buffer: String,
        needed: vk::BufferUsageFlags,
    },
    #[error("buffer {buffer} of {size} bytes is smaller than the {needed} bytes needed")]
    BufferTooSmall {
        buffer: String,
        needed: u64,
        size: u64,
    },
    #[error("an update of {bytes} bytes at offset {offset}: both must be multiples of 4")]
    UpdateAlignment { offset: u64, bytes: usize },
    #[error("texture {texture} lacks usage {needed:?}")]
    TextureUsage {
        texture: String,
        needed: vk::ImageUsageFlags,
    },
    #[error("mip level {level} is outside texture {texture}'s {levels} levels")]
    MipLevel {
        texture: String,
        level: u32,
        levels: u32,
    },
    #[error("no index buffer is bound")]
    NoIndexBuffer,
    #[error("indices {first}..{end} exceed index buffer {buffer} of {count} indices")]
    IndexRange {
        buffer: String,
        first: u32,
        end: u32,
        count: u64,
    },
    #[error("vertex binding {binding} of pipeline {pipeline} has no buffer bound")]
    VertexBufferMissing { pipeline: String, binding: u32 },
    #[error("vertices up to {end} need {needed} bytes of vertex buffer {buffer} ({size} bytes)")]
    VertexRange {
        buffer: String,
        end: u32,
        needed: u64,
        size: u64,
    },
    #[error("instances up to {end} need {needed} bytes of vertex buffer {buffer} ({size} bytes)")]
    InstanceRange {
        buffer: String,
        end: u32,
        needed: u64,
        size: u64,
    },
    #[error("{groups:?} workgroups exceed the device's maximum {max:?}")]
    WorkgroupCount { groups: [u32; 3], max: [u32; 3] },
    #[error("must be recorded inside a rendering scope")]
    OutsideRendering,
    #[error("must be recorded outside a rendering scope")]
    InsideRendering,
    #[error("the open rendering scope is not the one this command ends")]
    WrongRenderingScope,
    #[error(
        "pipeline {pipeline} renders to {pipeline_formats:?}, the scope has {scope_formats:?}"
    )]
    AttachmentFormats {
        pipeline: String,
        pipeline_formats: [vk::Format; 2],
        scope_formats: [vk::Format; 2],
    },
    #[error(
        "pipeline {pipeline} was made for {pipeline_subpass}, the open scope is {scope_subpass}"
    )]
    Subpass {
        pipeline: String,
        /// "dynamic rendering" or "subpass I of render pass R".
        pipeline_subpass: String,
        scope_subpass: String,
    },
    #[error("query {index} of pool {pool} was not reset earlier in this command buffer")]
    QueryNotReset { pool: String, index: u32 },
    #[error("query {index} of pool {pool} is active")]
    QueryActive { pool: String, index: u32 },
    #[error("query {index} of pool {pool} is not active (or was begun in another scope)")]
    QueryNotActive { pool: String, index: u32 },
    #[error("transform feedback is already active")]
    TransformFeedbackActive,
    #[error("transform feedback is not active")]
    TransformFeedbackInactive,
    #[error("pipeline {pipeline} declares no transform-feedback output (Xfb execution mode)")]
    NoTransformFeedbackOutput { pipeline: String },
    #[error("{count} transform-feedback buffers exceed the device's {max}")]
    TransformFeedbackBuffers { count: usize, max: u32 },
    #[error("the range at {offset} of {size} bytes is not 4-byte aligned or exceeds {max}")]
    TransformFeedbackRange { offset: u64, size: u64, max: u64 },
    #[error("no debug label is open")]
    NoLabel,
    #[error("at submission: {open} is still open")]
    Unclosed { open: &'static str },
    #[error("the encoder was exchanged with another one while recording")]
    Exchanged,
}

/// Why a descriptor write was refused (see [`VkError::Descriptor`] for which set and binding).
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum DescriptorError {
    #[error("the layout has no such binding")]
    NoSuchBinding,
    #[error("the layout declares {layout:?}, the write gives {given:?}")]
    Type {
        layout: vk::DescriptorType,
        given: vk::DescriptorType,
    },
    #[error("{0:?} descriptors cannot be written as whole buffers")]
    UnsupportedType(vk::DescriptorType),
    #[error("buffer {buffer} lacks usage {needed:?}")]
    Usage {
        buffer: String,
        needed: vk::BufferUsageFlags,
    },
    #[error(
        "a range of {size} bytes of buffer {buffer} exceeds the device's limit of {max} bytes"
    )]
    Range { buffer: String, size: u64, max: u64 },
    #[error("offset {offset} into buffer {buffer} is not a multiple of the device's {alignment}")]
    Offset {
        buffer: String,
        offset: u64,
        alignment: u64,
    },
    #[error("the range {offset}..{offset}+{range} lies outside buffer {buffer} of {size} bytes")]
    Window {
        buffer: String,
        offset: u64,
        range: u64,
        size: u64,
    },
    #[error("the set is bound in a command buffer that is still recording")]
    InUse,
}

impl VkError {
    pub(crate) fn recording(command: &'static str, problem: RecordingError) -> Self {
        VkError::Recording { command, problem }
    }
}

/// Wraps a raw `vk::Result` with the name of the call, for messages that say what failed.
pub(crate) trait VkContext<T> {
    fn ctx(self, call: &'static str) -> Result<T>;
}

impl<T> VkContext<T> for std::result::Result<T, vk::Result> {
    fn ctx(self, call: &'static str) -> Result<T> {
        self.map_err(|result| VkError::Call { call, result })
    }
}
