//! Status codes and the mapping from every Rust error type to them. One code per class of
//! failure a host can act on differently; the message (the error's `Display`, which names the
//! face, edge, option or Vulkan call at fault) goes to the last-error strings.
use tess::TessError;
use topology::TopologyError;
use vk_core::VkError;

/// What a call did. `TESSERA_STATUS_OK` is zero; every other value is a failure whose message
/// [`crate::tessera_last_error`] returns.
#[repr(C)]
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TesseraStatus {
    Ok = 0,
    /// A null `TesseraContext*` or `TesseraSurface*`.
    NullHandle = 1,
    /// A handle this library never issued (or a surface where a context is expected).
    InvalidHandle = 2,
    /// A handle that was valid and has been destroyed (double destroy, use after destroy).
    DestroyedHandle = 3,
    /// A required pointer argument (descriptor, output, array) is null.
    NullPointer = 4,
    /// An enum value, option or number outside what it accepts (the message names it).
    InvalidArgument = 5,
    /// A length that does not match: positions, pixel buffer, face sizes against indices.
    WrongSize = 6,
    /// An index outside what it indexes (a face's vertex, a crease's vertex, a frame slot).
    IndexOutOfRange = 7,
    /// A standalone-only call on a host-owned context, or the reverse.
    WrongMode = 8,
    /// A surface passed with a context it was not created on.
    WrongContext = 9,
    /// OBJ text that does not parse (the message names the line).
    Parse = 10,
    /// A mesh Tessera cannot subdivide: non-manifold, degenerate, Loop on non-triangles, ...
    Mesh = 11,
    /// A NaN or infinite coordinate, given or emitted.
    NonFinite = 12,
    /// A technique (or the device) does not support an option or operation.
    Unsupported = 13,
    /// No Vulkan loader could be loaded.
    NoLoader = 14,
    /// No device, or none matching the selector.
    NoDevice = 15,
    /// The chosen device lacks what Tessera needs (the message lists it).
    MissingFeatures = 16,
    /// A Vulkan call failed (the message names the call and its `VkResult`).
    Vulkan = 17,
    /// Device memory could not be allocated.
    OutOfMemory = 18,
    /// vk-core refused a command as recorded (a scope, a format, a binding).
    Recording = 19,
    /// A capture too large, or one that overflowed.
    Capture = 20,
    /// A file could not be read or written.
    Io = 21,
    /// A panic inside Tessera was caught at the boundary (a bug: please report the message).
    Panic = 22,
    /// An internal invariant failed (a poisoned lock, a missing pipeline): a bug.
    Internal = 23,
}

impl TesseraStatus {
    /// Static, NUL-terminated name of the code.
    pub(crate) fn name(self) -> &'static std::ffi::CStr {
        match self {
            TesseraStatus::Ok => c"ok",
            TesseraStatus::NullHandle => c"null handle",
            TesseraStatus::InvalidHandle => c"invalid handle",
            TesseraStatus::DestroyedHandle => c"destroyed handle",
            TesseraStatus::NullPointer => c"null pointer",
            TesseraStatus::InvalidArgument => c"invalid argument",
            TesseraStatus::WrongSize => c"wrong size",
            TesseraStatus::IndexOutOfRange => c"index out of range",
            TesseraStatus::WrongMode => c"wrong mode",
            TesseraStatus::WrongContext => c"wrong context",
            TesseraStatus::Parse => c"parse error",
            TesseraStatus::Mesh => c"invalid mesh",
            TesseraStatus::NonFinite => c"non-finite number",
            TesseraStatus::Unsupported => c"unsupported",
            TesseraStatus::NoLoader => c"no Vulkan loader",
            TesseraStatus::NoDevice => c"no device",
            TesseraStatus::MissingFeatures => c"missing device features",
            TesseraStatus::Vulkan => c"Vulkan call failed",
            TesseraStatus::OutOfMemory => c"out of device memory",
            TesseraStatus::Recording => c"recording refused",
            TesseraStatus::Capture => c"capture failed",
            TesseraStatus::Io => c"I/O error",
            TesseraStatus::Panic => c"panic",
            TesseraStatus::Internal => c"internal error",
        }
    }
}

/// A failure on its way to the boundary: the code and the message.
#[derive(Debug)]
pub(crate) struct Error {
    pub status: TesseraStatus,
    pub message: String,
}

impl Error {
    pub fn new(status: TesseraStatus, message: impl Into<String>) -> Self {
        Self {
            status,
            message: message.into(),
        }
    }
}

pub(crate) type Result<T> = std::result::Result<T, Error>;

pub(crate) fn topology_status(e: &TopologyError) -> TesseraStatus {
    use TopologyError as T;
    match e {
        T::Io { .. } => TesseraStatus::Io,
        T::Parse { .. } => TesseraStatus::Parse,
        T::InFile { error, .. } | T::InUsdPrim { error, .. } => topology_status(error),
        T::Usd { problem, .. } => usd_status(problem),
        T::IndexOutOfRange { .. } | T::TagOutOfRange { .. } | T::FaceOutOfRange { .. } => {
            TesseraStatus::IndexOutOfRange
        }
        T::NonFinitePosition { .. } | T::CoordinateOutOfRange { .. } => TesseraStatus::NonFinite,
        T::MalformedFaceTable { .. } | T::AttributeLength { .. } => TesseraStatus::WrongSize,
        T::UnknownScheme { .. } | T::IsolationOutOfRange { .. } | T::BadSharpnessScale { .. } => {
            TesseraStatus::InvalidArgument
        }
        _ => TesseraStatus::Mesh,
    }
}

fn usd_status(p: &topology::error::UsdProblem) -> TesseraStatus {
    use topology::error::UsdProblem as U;
    match p {
        U::IndexOutOfRange { .. } => TesseraStatus::IndexOutOfRange,
        U::Length { .. } | U::NegativeCount { .. } | U::ShortCrease { .. } => {
            TesseraStatus::WrongSize
        }
        U::NoMesh { .. } | U::Mixed { .. } => TesseraStatus::Mesh,
        U::Read(_)
        | U::ReaderPanicked(_)
        | U::Missing
        | U::WrongType { .. }
        | U::UnknownToken { .. }
        | U::Transform(_) => TesseraStatus::Parse,
    }
}

pub(crate) fn vk_status(e: &VkError) -> TesseraStatus {
    use VkError as V;
    match e {
        V::NoLoader(_) => TesseraStatus::NoLoader,
        V::Call { result, .. }
            if *result == vk_core::vk::Result::ERROR_OUT_OF_DEVICE_MEMORY
                || *result == vk_core::vk::Result::ERROR_OUT_OF_HOST_MEMORY =>
        {
            TesseraStatus::OutOfMemory
        }
        // The viewer's HUD overlay: not reachable through the C ABI, a Vulkan failure if it were.
        V::Call { .. } | V::Surface(_) | V::Overlay(_) => TesseraStatus::Vulkan,
        V::NoSuitableDevice(_) | V::NoSuchDevice { .. } => TesseraStatus::NoDevice,
        V::MissingFeatures { .. } => TesseraStatus::MissingFeatures,
        V::Unsupported { .. } => TesseraStatus::Unsupported,
        V::Allocator(_) => TesseraStatus::OutOfMemory,
        V::LockPoisoned { .. } => TesseraStatus::Internal,
        V::NotHostVisible { .. }
        | V::QueryType { .. }
        | V::QueryIndex { .. }
        | V::OutOfBounds { .. } => TesseraStatus::Internal,
        V::Extent { .. } => TesseraStatus::InvalidArgument,
        V::PictureSize { .. } => TesseraStatus::WrongSize,
        V::Recording { .. } | V::Descriptor { .. } | V::IndirectCommand { .. } => {
            TesseraStatus::Recording
        }
        V::Io { .. } | V::Image { .. } => TesseraStatus::Io,
    }
}

pub(crate) fn tess_status(e: &TessError) -> TesseraStatus {
    use TessError as E;
    match e {
        E::Vulkan(v) => vk_status(v),
        E::Topology(t) => topology_status(t),
        E::Mesh { source, .. } => match source.downcast_ref::<TopologyError>() {
            Some(t) => topology_status(t),
            None => TesseraStatus::Mesh,
        },
        E::Param(_) | E::UnknownTechnique { .. } | E::BenchConfig { .. } | E::Csv { .. } => {
            TesseraStatus::InvalidArgument
        }
        E::Unsupported { .. }
        | E::NoTessellationShader { .. }
        | E::PatternSpacing { .. }
        | E::NeedsTangentTables
        | E::StorageWindow { .. }
        | E::BftTablesTooLarge(_)
        | E::RefinedTooLarge { .. } => TesseraStatus::Unsupported,
        E::BasePositionCount { .. } => TesseraStatus::WrongSize,
        E::FrameSlot { .. } | E::IndexOutOfRange { .. } => TesseraStatus::IndexOutOfRange,
        E::NonFiniteVertex { .. } => TesseraStatus::NonFinite,
        E::NoPatchArray { .. }
        | E::PipelineNotPrepared { .. }
        | E::ShaderVariant { .. }
        | E::BftLayout(_)
        | E::PatternLevel { .. }
        | E::PatternEdges { .. }
        | E::NoFrameView { .. }
        | E::Stencil(_)
        | E::UnmappedPatch { .. } => TesseraStatus::Internal,
        E::CaptureTooLarge { .. } | E::CaptureOverflow { .. } | E::PartialTriangle { .. } => {
            TesseraStatus::Capture
        }
        E::Io { .. } | E::Write { .. } | E::Image { .. } => TesseraStatus::Io,
    }
}

impl From<TessError> for Error {
    fn from(e: TessError) -> Self {
        let message = e.worded(descriptor_field);
        Error::new(tess_status(&e), message)
    }
}

/// Where a parameter the library names lives in the C ABI's descriptors.
fn descriptor_field(p: tess::error::Param) -> &'static str {
    use tess::error::Param;
    match p {
        Param::Segments => "TesseraFrameDesc.factor (segments)",
        Param::Pixels => "TesseraFrameDesc.factor (pixels per segment)",
        Param::Distance => "TesseraFrameDesc.factor (distance)",
        Param::TableLevel => "TesseraSurfaceDesc.table_level",
        Param::Isolation => "TesseraSurfaceDesc.isolation",
    }
}

impl From<VkError> for Error {
    fn from(e: VkError) -> Self {
        Error::new(vk_status(&e), e.to_string())
    }
}

impl From<TopologyError> for Error {
    fn from(e: TopologyError) -> Self {
        Error::new(topology_status(&e), e.to_string())
    }
}
