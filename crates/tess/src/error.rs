//! The crate's error type. Each variant is one class of failure a caller (the CLI, a C ABI)
//! can map to a status code, with fields naming the option, technique, file or index at fault.
use crate::shaders::{Stage, Variant};
use crate::technique::{Pass, TechniqueId};

pub type Result<T, E = TessError> = std::result::Result<T, E>;

#[derive(Debug, thiserror::Error)]
pub enum TessError {
    #[error(transparent)]
    Vulkan(#[from] vk_core::VkError),
    #[error(transparent)]
    Topology(#[from] topology::TopologyError),
    /// The mesh `name` could not be prepared (its topology error says where).
    #[error("{name}: {source}")]
    Mesh {
        name: String,
        source: Box<dyn std::error::Error + Send + Sync>,
    },
    /// An image (texture or height map) that could not be read.
    #[error("{file}: {message}")]
    Image { file: String, message: String },
    /// An option's value outside what it accepts.
    #[error("{option} {value}: expected {range}")]
    OutOfRange {
        option: &'static str,
        value: String,
        range: &'static str,
    },
    /// A technique asked for something it does not do.
    #[error("{technique} does not support {what}")]
    Unsupported {
        technique: TechniqueId,
        what: &'static str,
    },
    #[error("unknown method '{name}' ({known})")]
    UnknownTechnique { name: String, known: String },
    /// Basis-function tables reach `2^(L+1)` segments per base edge.
    #[error(
        "--segments {segments}: BFT takes a power of two in 2..={max} segments per base edge \
         (tables at level {table_level}; raise --table-level for more)"
    )]
    BftSegments {
        segments: f32,
        max: u32,
        table_level: u32,
    },
    #[error(
        "--table-level {level}: tables must be at level 1..6 and need tessellation level 2^level \
         (the device allows {max_tessellation_level})"
    )]
    TableLevel {
        level: u32,
        max_tessellation_level: u32,
    },
    /// Basis-function tables that cannot be bound in one storage-buffer range, counted from
    /// the patch records before any table is evaluated.
    #[error(
        "{name}: basis-function tables at level {level} would take {bytes} bytes \
         ({private_faces} of {faces} level-1 faces need a private table: creases, corners or \
         overlapping rings), more than the device's storage-buffer range of {max} bytes; {hint}"
    )]
    BftTablesTooLarge {
        name: String,
        level: u32,
        bytes: u64,
        private_faces: usize,
        faces: usize,
        max: u64,
        hint: String,
    },
    /// A mesh refined on the CPU halves every edge per level.
    #[error(
        "--segments {segments}: a mesh refined on the CPU takes a power of two in 1..={max} \
         segments per base edge (each level halves every edge)"
    )]
    RefinedSegments { segments: f32, max: u32 },
    /// A CPU refinement too large to hold.
    #[error(
        "{scheme} level {level} would have {vertices} vertices, more than the limit of {max} \
         for a mesh refined on the CPU"
    )]
    RefinedTooLarge {
        scheme: topology::Scheme,
        level: usize,
        vertices: u64,
        max: u64,
    },
    #[error("geometric normals need the tangent tables (this surface was built without them)")]
    NeedsTangentTables,
    /// One item's reach in a buffer exceeds the device's storage-buffer range: it cannot be
    /// windowed (see `techniques::windows`).
    #[error(
        "{what} {item} reaches {bytes} bytes of its {space} buffers, more than the device's \
         storage-buffer range of {max} bytes"
    )]
    StorageWindow {
        what: &'static str,
        item: u32,
        space: &'static str,
        bytes: u64,
        max: u64,
    },
    #[error("{given} base positions given, the mesh has {expected}")]
    BasePositionCount { given: usize, expected: usize },
    #[error("no frame slot {slot} (the context has {slots})")]
    FrameSlot { slot: usize, slots: usize },
    #[error("no patch array {array}")]
    NoPatchArray { array: usize },
    #[error("{what} {index} is out of range of {len}")]
    IndexOutOfRange {
        what: &'static str,
        index: u64,
        len: u64,
    },
    #[error("vertex {vertex} has a NaN or infinite coordinate")]
    NonFiniteVertex { vertex: usize },
    /// Recording before [`crate::Context::prepare`] built the pass's pipelines.
    #[error("{technique}: no {pass:?} pipeline was prepared before recording")]
    PipelineNotPrepared { technique: TechniqueId, pass: Pass },
    /// A shader variant `glsl/manifest.toml` does not declare.
    #[error("shader {} has no variant {variant:?} (see glsl/manifest.toml)", stage.path())]
    ShaderVariant { stage: Stage, variant: Variant },
    /// BFT data that cannot be laid out for the GPU.
    #[error(transparent)]
    BftLayout(#[from] crate::techniques::bft::layout::LayoutError),
    /// A capture larger than the transform-feedback buffer limit or the caller's budget.
    #[error("capturing {triangles} triangles needs {bytes} bytes of transform feedback, over the limit of {limit} bytes (lower the level or raise the limit)")]
    CaptureTooLarge {
        triangles: u64,
        bytes: u64,
        limit: u64,
    },
    #[error("transform feedback overflowed twice: {needed} triangles needed, {capacity} captured")]
    CaptureOverflow { needed: u64, capacity: u64 },
    #[error("captured soup has {corners} corners, not whole triangles")]
    PartialTriangle { corners: usize },
    #[error("{path}: vertex {vertex} has patch id {patch}, which maps to no base face")]
    UnmappedPatch {
        path: String,
        vertex: usize,
        patch: u32,
    },
    /// A benchmark setting that cannot run (the message names the option).
    #[error("{option}: {reason}")]
    BenchConfig { option: String, reason: String },
    #[error("CSV line {line}: bad {column} '{value}'")]
    Csv {
        line: usize,
        column: String,
        value: String,
    },
    #[error("I/O on {path}: {source}")]
    Io {
        path: String,
        source: std::io::Error,
    },
    /// A file Tessera writes could not be written whole ([`crate::output::write_file`]): the
    /// operating system's reason is said in the message, not chained.
    #[error("cannot write {path}: {error}")]
    Write { path: String, error: std::io::Error },
}
