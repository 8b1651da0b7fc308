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
    /// A frame or build parameter's value the technique does not take (named in the
    /// library's words; each front end rewords it: [`ParamError::worded`]).
    #[error("{0}")]
    Param(ParamError),
    /// A technique asked for something it does not do.
    #[error("{technique} does not support {what}")]
    Unsupported {
        technique: TechniqueId,
        what: &'static str,
    },
    #[error("unknown method '{name}' ({known})")]
    UnknownTechnique { name: String, known: String },
    /// Basis-function tables beyond what their 32-bit weight offsets address, counted from the
    /// patch records before any table is evaluated.
    #[error("{0}")]
    BftTablesTooLarge(TablesTooLarge),
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
    /// windowed (see `techniques::windows`). The message names what makes the reach shorter.
    #[error("{}", storage_window(.what, *.item, .space, *.bytes, *.max, Param::name))]
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
    /// A stencil table that cannot be laid out for the GPU ([`crate::stencil`]).
    #[error(transparent)]
    Stencil(#[from] crate::stencil::StencilError),
    /// A capture larger than the caller's budget ([`crate::capture::Capturer::max_bytes`], for
    /// the whole capture) or one patch array's larger than the device's
    /// `maxTransformFeedbackBufferSize` (each array is captured into a buffer of its own).
    #[error("capturing {triangles} triangles needs {bytes} bytes of transform feedback, over {bound} of {limit} bytes: capture fewer triangles (fewer segments per edge, --segments, or with --factors screen more --pixels per segment)")]
    CaptureTooLarge {
        triangles: u64,
        bytes: u64,
        limit: u64,
        /// Which limit: the capture budget, or the device's per-buffer limit.
        bound: &'static str,
    },
    #[error("transform feedback overflowed twice: {needed} triangles needed, {capacity} captured")]
    CaptureOverflow { needed: u64, capacity: u64 },
    #[error("captured soup has {corners} corners, not whole triangles")]
    PartialTriangle { corners: usize },
    #[error("{technique} on the tessellation path needs tessellation shaders, which this device lacks or --no-tessellation-shader turned off (techniques with a refinement-pattern path draw with --pipeline pattern)")]
    NoTessellationShader { technique: TechniqueId },
    #[error("refinement patterns beyond the tessellator (a device without tessellation shaders or transform feedback, or above 64 segments) are generated in equal spacing only, not {spacing:?} (--spacing equal)")]
    PatternSpacing {
        spacing: crate::tessellator::Spacing,
    },
    #[error("{technique} chooses its pattern levels on the host from the frame's view: write the frame block (Context::write_frame) before Context::prepare")]
    NoFrameView { technique: TechniqueId },
    #[error("a refinement pattern of {segments} segments per edge: expected 1..256")]
    PatternLevel { segments: u32 },
    #[error(
        "a {domain:?} refinement pattern with edge levels {outer:?} and inner levels {inner:?}: \
         {why}"
    )]
    PatternEdges {
        domain: crate::tessellator::Domain,
        outer: Vec<f32>,
        inner: Vec<f32>,
        why: &'static str,
    },
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

/// A parameter of a frame ([`crate::FrameParams`]) or a build ([`crate::BuildOptions`]) that an
/// error names. The library names it by its field ([`Param::name`]); a front end by its own
/// words ([`ParamError::worded`]): the command line by its option, the C ABI by its
/// descriptor's field.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Param {
    /// Uniform segments per edge (`FactorPolicy::Uniform`).
    Segments,
    /// Pixels per segment (`FactorPolicy::Screen`).
    Pixels,
    /// Reference distance (`FactorPolicy::Distance`).
    Distance,
    /// Basis-function table level (`BuildOptions::table_level`).
    TableLevel,
    /// Adaptive's isolation level (`BuildOptions::isolation`).
    Isolation,
}

impl Param {
    /// The library's name: the field of `FrameParams` or `BuildOptions`.
    pub fn name(self) -> &'static str {
        match self {
            Param::Segments => "segments",
            Param::Pixels => "pixels per segment",
            Param::Distance => "reference distance",
            Param::TableLevel => "table level",
            Param::Isolation => "isolation level",
        }
    }
}

/// A parameter's value that is not taken, and why ([`TessError::Param`]).
#[derive(Clone, Debug, PartialEq)]
pub struct ParamError {
    pub param: Param,
    /// The value as given.
    pub value: String,
    /// What is taken instead, in the library's words (no front end's option names).
    pub expected: String,
    /// Another parameter that would let the value be taken ("raise the table level for more").
    pub raise: Option<Param>,
}

impl ParamError {
    pub fn refused(param: Param, value: impl ToString, expected: impl Into<String>) -> TessError {
        TessError::Param(ParamError {
            param,
            value: value.to_string(),
            expected: expected.into(),
            raise: None,
        })
    }

    /// [`Self::refused`], naming the parameter to raise for more.
    pub fn raising(
        param: Param,
        value: impl ToString,
        expected: impl Into<String>,
        raise: Param,
    ) -> TessError {
        TessError::Param(ParamError {
            param,
            value: value.to_string(),
            expected: expected.into(),
            raise: Some(raise),
        })
    }

    /// The message with each parameter named by `name` (the library's [`Param::name`], a
    /// command-line option, a C ABI field).
    pub fn worded(&self, name: impl Fn(Param) -> &'static str) -> String {
        let raise = self
            .raise
            .map(|p| format!("; raise {} for more", name(p)))
            .unwrap_or_default();
        format!(
            "{} {}: {}{raise}",
            name(self.param),
            self.value,
            self.expected
        )
    }
}

/// Basis-function tables beyond what their weight offsets address ([`TessError::BftTablesTooLarge`]).
#[derive(Clone, Debug, PartialEq)]
pub struct TablesTooLarge {
    /// The mesh.
    pub name: String,
    pub level: u32,
    pub bytes: u64,
    /// Level-1 faces whose rings need a table of their own, of `faces`.
    pub private_faces: usize,
    pub faces: usize,
    /// The most bytes the tables' 32-bit weight offsets address.
    pub max: u64,
    /// The highest lower level whose tables fit, and their bytes.
    pub fits: Option<(u32, u64)>,
}

impl TablesTooLarge {
    /// The message with the table-level parameter named by `name`.
    pub fn worded(&self, name: impl Fn(Param) -> &'static str) -> String {
        let hint = match self.fits {
            Some((l, bytes)) => format!(
                "at level {l} they take {bytes} bytes ({} {l}, up to {} segments per base edge)",
                name(Param::TableLevel),
                2u32 << l
            ),
            None => "no table level fits".to_string(),
        };
        format!(
            "{}: basis-function tables at level {} would take {} bytes ({} of {} level-1 faces \
             need a private table: creases, corners or overlapping rings), more than the {} \
             bytes their 32-bit weight offsets address; {hint}",
            self.name, self.level, self.bytes, self.private_faces, self.faces, self.max
        )
    }
}

impl std::fmt::Display for TablesTooLarge {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.worded(Param::name))
    }
}

impl TessError {
    /// The message with every parameter it names worded by `name` (a front end's option or
    /// field names); the library's own words elsewhere.
    pub fn worded(&self, name: impl Fn(Param) -> &'static str) -> String {
        match self {
            TessError::Param(p) => p.worded(name),
            TessError::BftTablesTooLarge(t) => t.worded(name),
            TessError::StorageWindow {
                what,
                item,
                space,
                bytes,
                max,
            } => storage_window(what, *item, space, *bytes, *max, name),
            other => other.to_string(),
        }
    }
}

/// [`TessError::StorageWindow`]'s message, with the parameters that shorten an item's reach
/// named by `name`. An item is bound in one window, so its reach (the hull of the indices it
/// reads: a stencil row's source vertices, a patch's owners' rings) must fit one range; the
/// reach grows with the level's size and with how far apart neighbouring vertices are numbered.
fn storage_window(
    what: &str,
    item: u32,
    space: &str,
    bytes: u64,
    max: u64,
    name: impl Fn(Param) -> &'static str,
) -> String {
    format!(
        "{what} {item} reaches {bytes} bytes of its {space} buffers, more than the device's \
         storage-buffer range of {max} bytes (an item is read through one window); a lower {} \
         (adaptive) or fewer {} (doo-sabin), a smaller mesh, or one whose neighbouring vertices \
         are numbered close together shortens the reach, or a device with a larger range takes it",
        name(Param::Isolation),
        name(Param::Segments)
    )
}

impl std::fmt::Display for ParamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(&self.worded(Param::name))
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The library names parameters by their fields; a front end words them its own way, every
    /// one of them, and other errors are unchanged.
    #[test]
    fn parameters_are_worded_by_each_front_end() {
        let e = ParamError::raising(Param::Segments, 128, "at most 64", Param::TableLevel);
        assert_eq!(
            e.to_string(),
            "segments 128: at most 64; raise table level for more"
        );
        let flag = |p: Param| match p {
            Param::Segments => "--segments",
            Param::TableLevel => "--table-level",
            _ => "--other",
        };
        assert_eq!(
            e.worded(flag),
            "--segments 128: at most 64; raise --table-level for more"
        );
        let tables = TessError::BftTablesTooLarge(TablesTooLarge {
            name: "car".into(),
            level: 5,
            bytes: 10,
            private_faces: 1,
            faces: 2,
            max: 8,
            fits: Some((4, 6)),
        });
        assert!(tables
            .to_string()
            .contains("(table level 4, up to 32 segments"));
        assert!(tables
            .worded(flag)
            .contains("(--table-level 4, up to 32 segments"));
        // A reach beyond the storage range names what shortens it, in each front end's words.
        let window = TessError::StorageWindow {
            what: "stencil row",
            item: 7,
            space: "stencil source vertex",
            bytes: 300,
            max: 256,
        };
        let text = window.to_string();
        assert!(text.contains("stencil row 7 reaches 300 bytes"), "{text}");
        assert!(
            text.contains("a lower isolation level (adaptive) or fewer segments (doo-sabin)"),
            "{text}"
        );
        let flag = |p: Param| match p {
            Param::Isolation => "--isolation",
            Param::Segments => "--segments",
            _ => "--other",
        };
        let text = window.worded(flag);
        assert!(
            text.contains("a lower --isolation (adaptive) or fewer --segments (doo-sabin)"),
            "{text}"
        );
        let other = TessError::NoPatchArray { array: 3 };
        assert_eq!(other.worded(flag), other.to_string());
    }
}
