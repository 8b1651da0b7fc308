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
    /// A capture larger than the transform-feedback buffer limit or the caller's budget.
    #[error("capturing {triangles} triangles needs {bytes} bytes of transform feedback, over the limit of {limit} bytes (lower the level or raise the limit)")]
    CaptureTooLarge {
        triangles: u64,
        bytes: u64,
        limit: u64,
    },
    /// A shader variant `glsl/manifest.toml` does not declare.
    #[error("shader {} has no variant {variant:?} (see glsl/manifest.toml)", stage.path())]
    ShaderVariant {
        stage: crate::shaders::Stage,
        variant: crate::shaders::Variant,
    },
    /// BFT data that cannot be laid out for the GPU.
    #[error(transparent)]
    BftLayout(#[from] crate::bft::LayoutError),
    #[error("I/O on {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
}
