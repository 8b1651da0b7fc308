//! The crate's single error type: every failure names the face, edge, vertex or file involved.

/// Everything that can go wrong while loading, validating or refining a control mesh.
#[derive(Debug, thiserror::Error)]
pub enum TopologyError {
    /// The OBJ file could not be read.
    #[error("{file}: cannot read file: {source}")]
    Io {
        file: String,
        #[source]
        source: std::io::Error,
    },
    /// A line of OBJ text could not be understood.
    #[error("{file}:{line}: {kind}")]
    Parse {
        file: String,
        line: usize,
        kind: ObjSyntax,
    },
    /// A validation error found in a named file (the inner error says what and where).
    #[error("{file}: {source}")]
    InFile {
        file: String,
        #[source]
        source: Box<TopologyError>,
    },
    /// The mesh has no faces (or no vertices): there is nothing to subdivide.
    #[error("empty mesh: {what}")]
    EmptyMesh { what: &'static str },
    /// A face refers to a vertex that does not exist.
    #[error("face {face}: vertex index {index} out of range (mesh has {count} vertices)")]
    IndexOutOfRange {
        face: usize,
        index: i64,
        count: usize,
    },
    /// A face with fewer than three corners.
    #[error("face {face} has {size} vertices; a face needs at least 3")]
    DegenerateFace { face: usize, size: usize },
    /// A face that visits the same vertex twice.
    #[error("face {face} uses vertex {vertex} more than once")]
    RepeatedVertex { face: usize, vertex: u32 },
    /// An edge shared by more than two faces.
    #[error("edge {v0}-{v1} is shared by {faces} faces (non-manifold edge)")]
    NonManifoldEdge { v0: u32, v1: u32, faces: usize },
    /// A vertex whose incident faces form more than one fan.
    #[error("vertex {vertex}: its faces form {fans} separate fans (non-manifold vertex)")]
    NonManifoldVertex { vertex: u32, fans: usize },
    /// Two faces traverse a shared edge in the same direction.
    #[error(
        "faces {face0} and {face1} both traverse edge {v0}->{v1} in the same direction (inconsistent orientation)"
    )]
    InconsistentOrientation {
        face0: usize,
        face1: usize,
        v0: u32,
        v1: u32,
    },
    /// A vertex position with NaN or infinite coordinates.
    #[error("vertex {vertex} has a non-finite position {position:?}")]
    NonFinitePosition { vertex: usize, position: [f64; 3] },
    /// Loop subdivision was asked for a mesh with non-triangular faces.
    #[error("Loop subdivision needs triangles, but face {face} has {size} vertices")]
    LoopRequiresTriangles { face: usize, size: usize },
    /// A crease, corner or hole tag naming a vertex or face the mesh does not have.
    #[error("invalid tag: {tag} names {} {index}, mesh has {count} {}s", tag.element(), tag.element())]
    TagOutOfRange {
        tag: TagKind,
        index: u32,
        count: usize,
    },
    /// `face_offsets` does not start at 0, decreases, or does not end at the corner count.
    #[error(
        "malformed face table: face_offsets ({faces} faces) is not a valid prefix table over {corners} face_vertices"
    )]
    MalformedFaceTable { faces: usize, corners: usize },
    /// Per-corner attribute arrays (normals, UVs) whose length does not match the faces.
    #[error("{attribute}: {len} values but the faces have {expected} corners")]
    AttributeLength {
        attribute: &'static str,
        len: usize,
        expected: usize,
    },
    /// The control mesh has too many face corners for 32-bit refinement indices.
    #[error("refinement too large: {corners} face corners")]
    TooManyCorners { corners: usize },
    /// One more refinement step of a level with `faces` faces would overflow 32-bit indices.
    #[error("refinement too large: refining {faces} faces would overflow 32-bit indices")]
    RefinementTooLarge { faces: usize },
    /// A scheme name no parser knows.
    #[error("unknown scheme '{name}' (loop, catmull-clark, doo-sabin, bilinear)")]
    UnknownScheme { name: String },
    /// An operation the scheme does not support (Doo-Sabin has no sparse refinement).
    #[error("{scheme} does not support {operation}")]
    UnsupportedScheme {
        scheme: crate::sdc::Scheme,
        operation: &'static str,
    },
    /// A face index (e.g. in a refinement selection) beyond the level's faces.
    #[error("face {face} out of range (the level has {count} faces)")]
    FaceOutOfRange { face: usize, count: usize },
    /// A Gregory end cap cannot be built on this face ([`crate::gregory::gregory_basis`]).
    #[error("Gregory patch of face {face}: {problem}")]
    GregoryPatch {
        face: usize,
        problem: crate::gregory::GregoryProblem,
    },
    /// An adaptive isolation level outside `1..=8`.
    #[error("isolation level {isolation} is outside 1..=8")]
    IsolationOutOfRange { isolation: u32 },
    /// A sharpness scale that is NaN, infinite or negative.
    #[error("sharpness scale {scale} must be finite and non-negative")]
    BadSharpnessScale { scale: f32 },
    /// A crease tag whose sharpness is NaN or negative.
    #[error("crease {v0}-{v1}: sharpness {sharpness} is NaN or negative")]
    BadEdgeSharpness { v0: u32, v1: u32, sharpness: f32 },
    /// A corner tag whose sharpness is NaN or negative.
    #[error("corner at vertex {vertex}: sharpness {sharpness} is NaN or negative")]
    BadVertexSharpness { vertex: u32, sharpness: f32 },
    /// A face of an adaptive plan that should be a regular patch but is not (its corners do
    /// not form the 4×4 B-spline net).
    #[error("adaptive plan: face {face} of level {level} is not a regular patch")]
    AdaptivePatch { level: u32, face: usize },
    /// A face with more corners than an adaptive patch's 8-bit sub-face number can name.
    #[error("adaptive plan: face {face} has {size} corners (at most 256)")]
    AdaptiveFaceTooLarge { face: usize, size: usize },
    /// An adaptive patch whose neighbour is more than one level coarser or finer (drawing it
    /// would leave a crack).
    #[error("adaptive plan: face {face} of level {level} borders a face more than one level away")]
    AdaptiveUnbalanced { level: u32, face: usize },
}

/// Which OBJ tag a [`TopologyError::TagOutOfRange`] comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TagKind {
    Crease,
    Corner,
    Hole,
}

impl TagKind {
    /// What the tag's indices name.
    pub fn element(self) -> &'static str {
        match self {
            TagKind::Crease | TagKind::Corner => "vertex",
            TagKind::Hole => "face",
        }
    }
}

impl std::fmt::Display for TagKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TagKind::Crease => "crease",
            TagKind::Corner => "corner",
            TagKind::Hole => "hole",
        })
    }
}

impl TopologyError {
    /// The underlying error with any file wrapper removed (useful to match on the kind).
    pub fn root(&self) -> &TopologyError {
        match self {
            TopologyError::InFile { source, .. } => source.root(),
            other => other,
        }
    }

    /// Attach a file name to a validation error, so the user knows which file is broken.
    pub(crate) fn in_file(self, file: &str) -> TopologyError {
        match self {
            e @ (TopologyError::Io { .. }
            | TopologyError::Parse { .. }
            | TopologyError::InFile { .. }) => e,
            other => TopologyError::InFile {
                file: file.to_string(),
                source: Box::new(other),
            },
        }
    }
}

/// What is wrong on an OBJ line ([`TopologyError::Parse`] names the file and line).
#[derive(Clone, Debug, PartialEq, thiserror::Error)]
pub enum ObjSyntax {
    #[error("'{statement}' needs at least {min} numbers, found {found}")]
    TooFewNumbers {
        statement: &'static str,
        min: usize,
        found: usize,
    },
    #[error("'{statement}': '{word}' is not a number")]
    NotANumber {
        statement: &'static str,
        word: String,
    },
    #[error("face without vertices")]
    FaceWithoutVertices,
    #[error("bad face index '{word}'")]
    BadFaceIndex { word: String },
    #[error("face index 0 in '{word}' (OBJ is 1-based)")]
    ZeroFaceIndex { word: String },
    #[error("relative index '{word}' points before the start")]
    IndexBeforeStart { word: String },
    #[error("face corner '{word}' has no vertex")]
    CornerWithoutVertex { word: String },
    #[error("texture index {index} out of range")]
    TextureIndexOutOfRange { index: i64 },
    #[error("normal index {index} out of range")]
    NormalIndexOutOfRange { index: i64 },
    #[error("tag line needs a name and counts")]
    TagWithoutCounts,
    #[error("bad tag counts '{counts}'")]
    BadTagCounts { counts: String },
    #[error("tag '{tag}': counts '{counts}' do not match the values")]
    TagCountMismatch { tag: String, counts: String },
    #[error("tag '{tag}': bad integer")]
    BadTagInteger { tag: String },
    #[error("tag '{tag}': bad float")]
    BadTagFloat { tag: String },
    #[error("tag '{tag}': negative index {index}")]
    NegativeTagIndex { tag: String, index: i64 },
    #[error("tag '{tag}' needs a sharpness value")]
    MissingSharpness { tag: String },
    #[error("tag '{tag}': {values} values for {elements} elements")]
    SharpnessCount {
        tag: String,
        values: usize,
        elements: usize,
    },
    #[error("tag '{tag}': sharpness {value} is not finite")]
    NonFiniteSharpness { tag: String, value: f32 },
    #[error("crease tag needs vertex pairs")]
    CreaseNeedsPairs,
    #[error("corner tag needs vertices")]
    CornerNeedsVertices,
    #[error("{option}: bad value {value}")]
    BadOptionValue { option: &'static str, value: String },
}
