//! One error type for the crate; `vk::Result` is wrapped with the call that failed.
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
    #[error("{0}")]
    Invalid(String),
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

/// Wraps a raw `vk::Result` with the name of the call, for messages that say what failed.
pub(crate) trait VkContext<T> {
    fn ctx(self, call: &'static str) -> Result<T>;
}

impl<T> VkContext<T> for std::result::Result<T, vk::Result> {
    fn ctx(self, call: &'static str) -> Result<T> {
        self.map_err(|result| VkError::Call { call, result })
    }
}
