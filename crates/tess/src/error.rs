//! The crate's error type: Vulkan, topology (with file/face/edge) and parameter errors.
pub type Result<T, E = TessError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum TessError {
    #[error(transparent)]
    Vulkan(#[from] vk_core::VkError),
    #[error(transparent)]
    Topology(#[from] topology::TopologyError),
    #[error("{0}")]
    Invalid(String),
}
