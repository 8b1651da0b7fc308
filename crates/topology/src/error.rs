//! The crate's error types: every failure names the face, edge, vertex or file involved.
//!
//! This module is below every layer (see the crate documentation): each layer reports
//! through it, and it names what went wrong in plain data (numbers, names, the problem
//! kinds of the end caps), importing nothing from the layers themselves.

/// Everything that can go wrong while loading, validating or refining a control mesh.
#[derive(Debug, thiserror::Error)]
pub enum TopologyError {
    /// The OBJ file could not be read. The I/O error is said in the message, not chained
    /// (`error`, not `source`), so `{:#}` chains say it once.
    #[error("{file}: cannot read file: {error}")]
    Io { file: String, error: std::io::Error },
    /// A line of OBJ text could not be understood.
    #[error("{file}:{line}: {kind}")]
    Parse {
        file: String,
        line: usize,
        kind: ObjSyntax,
    },
    /// A validation error found in an OBJ file: shown in the file's own terms (1-based vertex
    /// and face numbers, the line that made the element at fault when there is one), while
    /// `error` keeps the 0-based numbers of the loaded [`crate::mesh::ControlMesh`] for code that
    /// matches on it ([`TopologyError::root`]). Said in the message, not chained.
    #[error("{file}{}: {}", at_line(*.line), ObjTerms(.error))]
    InFile {
        file: String,
        line: Option<usize>,
        error: Box<TopologyError>,
    },
    /// A USD file that cannot be read, or a Mesh prim's attribute that cannot be mapped to a
    /// control mesh ([`crate::mesh::usd`]): the file, the prim's path and the attribute's name
    /// (each left out where the problem is not about one).
    #[error("{file}{}: {problem}", usd_site(prim, attribute))]
    Usd {
        file: String,
        prim: String,
        attribute: String,
        /// Boxed: keeps every `Result<_, TopologyError>` small.
        problem: Box<UsdProblem>,
    },
    /// A validation error about one Mesh prim of a USD file, with the 0-based point and face
    /// numbers of that prim (as USD's arrays count them). Said in the message, not chained.
    #[error("{file}: {prim}: {error}")]
    InUsdPrim {
        file: String,
        prim: String,
        error: Box<TopologyError>,
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
    #[error("vertex {vertex} has a non-finite position ({})", xyz(position))]
    NonFinitePosition { vertex: usize, position: [f64; 3] },
    /// A finite vertex position with a coordinate beyond `bound` (the mesh's
    /// [`MAX_COORDINATE`](crate::mesh::MAX_COORDINATE)), where intermediates of the f32 GPU
    /// path would overflow (see there).
    #[error(
        "vertex {vertex} at ({}) has a coordinate beyond ±{bound:e}, the largest the GPU's f32 \
         arithmetic keeps finite (scale the mesh down)",
        xyz(position)
    )]
    CoordinateOutOfRange {
        vertex: usize,
        position: [f64; 3],
        bound: f64,
    },
    /// Loop subdivision was asked for a mesh with non-triangular faces.
    #[error("Loop subdivision needs triangles, but face {face} has {size} vertices")]
    LoopRequiresTriangles { face: usize, size: usize },
    /// A crease, corner or hole tag naming a vertex or face the mesh does not have.
    #[error("invalid tag: {tag} names {} {index}, mesh has {count} {}", tag.element(), tag.elements())]
    TagOutOfRange {
        tag: TagKind,
        index: u32,
        count: usize,
    },
    /// A scalar tag (an ST-mesh's per-vertex shape parameters) that cannot shape its vertex:
    /// a value out of its range, a second tag on one vertex, or a vertex on two creases.
    #[error("scalar tag of vertex {vertex}: {problem}")]
    ScalarTag { vertex: u32, problem: String },
    /// A fan triangle of a face with three vertices carrying a deviation vector: an ST-mesh
    /// takes at most two per triangle (one crease edge).
    #[error(
        "face {face}: a triangle of it has three vertices with a deviation vector (scalar tags \
         allow two per triangle: a crease crosses a triangle along one edge)"
    )]
    ScalarTagTriangle { face: usize },
    /// A face that is a hole (tagged, or a boundary face under boundary interpolation
    /// `none`) under Doo-Sabin, whose dual refinement has no holes (every face becomes an
    /// f-face of the next level: the hole would be drawn).
    #[error(
        "face {face} is a hole (tagged, or a boundary face under interpolateboundary none): \
         Doo-Sabin's refinement has no holes (it would draw the face)"
    )]
    DooSabinHole { face: u32 },
    /// A crease tag under Doo-Sabin, whose rules have no sharp edges (the edge would be drawn
    /// smooth).
    #[error(
        "the edge {v0}-{v1} has crease sharpness {sharpness}: Doo-Sabin's refinement has no \
         creases (it would draw the edge smooth)"
    )]
    DooSabinCrease { v0: u32, v1: u32, sharpness: f32 },
    /// A corner tag under Doo-Sabin, whose rules have no sharp vertices.
    #[error(
        "vertex {vertex} has corner sharpness {sharpness}: Doo-Sabin's refinement has no sharp \
         vertices (it would draw the vertex smooth)"
    )]
    DooSabinCorner { vertex: u32, sharpness: f32 },
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
    /// An operation the scheme does not support (Doo-Sabin has no sparse refinement); the
    /// scheme by its command-line name (`Scheme::name`).
    #[error("{scheme} does not support {operation}")]
    UnsupportedScheme {
        scheme: &'static str,
        operation: &'static str,
    },
    /// A face index (e.g. in a refinement selection) beyond the level's faces.
    #[error("face {face} out of range (the level has {count} faces)")]
    FaceOutOfRange { face: usize, count: usize },
    /// A Gregory end cap cannot be built on this face ([`crate::patches::gregory::gregory_basis`]).
    #[error("Gregory patch of face {face}: {problem}")]
    GregoryPatch {
        face: usize,
        problem: GregoryProblem,
    },
    /// An ACC-1 patch cannot be built on this face ([`crate::patches::acc::acc1_patch`]).
    #[error("ACC-1 patch of face {face}: {problem}")]
    AccPatch { face: usize, problem: AccProblem },
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
    /// An adaptive plan projected to refine more faces than its bound (checked before each
    /// refinement step, so the plan stops before allocating them).
    #[error("adaptive plan of a {faces}-face mesh at isolation {isolation}: about {estimate} refined faces projected at level {level}, above the bound of {bound} (lower the isolation)")]
    AdaptiveTooLarge {
        faces: usize,
        isolation: u32,
        level: usize,
        estimate: u64,
        bound: u64,
    },
    /// A Doo-Sabin limit plan projected to hold more patch domains (squares) than its bound
    /// (checked before each level is planned, so the plan stops before allocating them).
    #[error("Doo-Sabin limit plan of a {faces}-face mesh at isolation {isolation}: about {estimate} patches projected at level {level}, above the bound of {bound} (lower the isolation)")]
    DooSabinTooLarge {
        faces: usize,
        isolation: u32,
        level: u32,
        estimate: u64,
        bound: u64,
    },
    /// Gregory end caps whose point stencils were projected past their bound (checked before
    /// any is built: each of the 20 points is a row over its corners' one-rings, ~200 terms a
    /// patch, so a mesh made of end caps, such as a triangle mesh under Catmull-Clark, costs
    /// tens of bytes per term at every stage).
    #[error("adaptive plan of a {faces}-face mesh: {patches} Gregory patches project about {estimate} local-point stencil terms, above the bound of {bound} (most faces are end caps, as a triangle mesh's are under Catmull-Clark: draw a triangle mesh as Loop, --method bft; adaptive takes --end-cap bilinear or a lower --isolation)")]
    GregoryTooLarge {
        faces: usize,
        patches: u64,
        estimate: u64,
        bound: u64,
    },
    /// An adaptive patch whose neighbour is more than one level coarser or finer (drawing it
    /// would leave a crack).
    #[error("adaptive plan: face {face} of level {level} borders a face more than one level away")]
    AdaptiveUnbalanced { level: u32, face: usize },
}

/// Why a Gregory patch cannot be built on a face ([`TopologyError::GregoryPatch`]).
#[derive(Clone, Debug, PartialEq, Eq, thiserror::Error)]
pub enum GregoryProblem {
    #[error("the face has {size} corners, a Gregory patch needs a quad")]
    NotQuad { size: usize },
    #[error("the faces around vertex {vertex} do not form one complete fan in this level")]
    IncompleteRing { vertex: u32 },
    #[error("a face around vertex {vertex} is not a quad (refine once first)")]
    NonQuadRing { vertex: u32 },
    #[error("the level's sharpness tables do not match its topology")]
    SharpnessLength,
}

/// Why an ACC-1 patch cannot be built on a face ([`TopologyError::AccPatch`]).
#[derive(Clone, Copy, Debug, PartialEq, Eq, thiserror::Error)]
pub enum AccProblem {
    #[error("the face has {size} corners; ACC-1 patches are quads")]
    NotQuad { size: usize },
    #[error("vertex {vertex} is on a boundary")]
    Boundary { vertex: u32 },
    #[error("vertex {vertex} has a sharp edge or is a tagged corner")]
    Sharp { vertex: u32 },
    #[error("vertex {vertex} has a face that is not a quad")]
    NonQuadNeighbour { vertex: u32 },
}

/// Which OBJ tag a [`TopologyError::TagOutOfRange`] comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TagKind {
    Crease,
    Corner,
    Hole,
    ScalarTag,
}

impl TagKind {
    /// What the tag's indices name.
    pub fn element(self) -> &'static str {
        match self {
            TagKind::Crease | TagKind::Corner | TagKind::ScalarTag => "vertex",
            TagKind::Hole => "face",
        }
    }

    /// [`TagKind::element`] in the plural.
    pub fn elements(self) -> &'static str {
        match self {
            TagKind::Crease | TagKind::Corner | TagKind::ScalarTag => "vertices",
            TagKind::Hole => "faces",
        }
    }
}

impl std::fmt::Display for TagKind {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(match self {
            TagKind::Crease => "crease",
            TagKind::Corner => "corner",
            TagKind::Hole => "hole",
            TagKind::ScalarTag => "scalartag",
        })
    }
}

impl TopologyError {
    /// The underlying error with any file wrapper removed (useful to match on the kind).
    pub fn root(&self) -> &TopologyError {
        match self {
            TopologyError::InFile { error, .. } | TopologyError::InUsdPrim { error, .. } => {
                error.root()
            }
            other => other,
        }
    }

    /// Attach an OBJ file's name (and the line at fault, when known) to an error about a
    /// mesh loaded from it, so its message uses the file's 1-based numbering. Errors that
    /// already name a file are returned as they are. Callers that refine or evaluate a mesh
    /// loaded from OBJ use this to report later errors in the same terms.
    pub fn in_file(self, file: &str, line: Option<usize>) -> TopologyError {
        match self {
            e @ (TopologyError::Io { .. }
            | TopologyError::Parse { .. }
            | TopologyError::Usd { .. }
            | TopologyError::InUsdPrim { .. }
            | TopologyError::InFile { .. }) => e,
            other => TopologyError::InFile {
                file: file.to_string(),
                line,
                error: Box::new(other),
            },
        }
    }
}

/// ` <prim>.<attribute>` of a [`TopologyError::Usd`], as much of it as is known.
fn usd_site(prim: &str, attribute: &str) -> String {
    match (prim.is_empty(), attribute.is_empty()) {
        (true, true) => String::new(),
        (false, true) => format!(": {prim}"),
        (true, false) => format!(": {attribute}"),
        (false, false) => format!(": {prim}.{attribute}"),
    }
}

/// What is wrong with a USD file or one of its Mesh prims' attributes
/// ([`TopologyError::Usd`]).
#[derive(Debug, thiserror::Error)]
pub enum UsdProblem {
    /// The USD reader refused the file (its message).
    #[error("cannot read USD: {0}")]
    Read(String),
    /// The USD reader panicked on the file (a malformed file it does not check); the panic's
    /// message.
    #[error("the USD reader failed on malformed input: {0}")]
    ReaderPanicked(String),
    /// The composed stage has no Mesh prim to draw.
    #[error("no Mesh prim to draw ({skipped} skipped: invisible, guide or proxy)")]
    NoMesh { skipped: usize },
    /// A required attribute is not authored.
    #[error("not authored (a Mesh needs it)")]
    Missing,
    /// The attribute holds another type than the schema's.
    #[error("holds {found}; expected {expected}")]
    WrongType {
        found: String,
        expected: &'static str,
    },
    /// A token outside the attribute's allowed tokens.
    #[error("unknown token '{value}' (expected one of: {expected})")]
    UnknownToken {
        value: String,
        expected: &'static str,
    },
    /// A negative entry in a count array (`faceVertexCounts`).
    #[error("entry {position} is {value}; counts cannot be negative")]
    NegativeCount { position: usize, value: i64 },
    /// An array whose length disagrees with what the other attributes ask for.
    #[error("has {len} entries; expected {expected}")]
    Length { len: usize, expected: String },
    /// An index out of its range.
    #[error("entry {position} is {index}, but there are {count} {of}")]
    IndexOutOfRange {
        position: usize,
        index: i64,
        count: usize,
        of: &'static str,
    },
    /// A crease of fewer than two points (`creaseLengths`).
    #[error("crease {crease} has length {length}; a crease needs at least 2 points")]
    ShortCrease { crease: usize, length: i64 },
    /// Meshes merged into one control mesh must share the scheme and subdivision options.
    #[error("{value} differs from {first_prim}'s {first_value}; meshes merged into one control mesh must share the subdivision scheme and options")]
    Mixed {
        value: String,
        first_prim: String,
        first_value: String,
    },
    /// The prim's transform could not be composed (the reader's message).
    #[error("cannot compose the transform: {0}")]
    Transform(String),
}

fn at_line(line: Option<usize>) -> String {
    line.map(|l| format!(":{l}")).unwrap_or_default()
}

/// A number as a user would write it: shortest round-trip digits, in exponent form when very
/// large or small (3e38 and -1e-300, not 39 or 300 digits).
pub fn number(x: f64) -> String {
    if x != 0.0 && x.is_finite() && !(1e-6..1e16).contains(&x.abs()) {
        format!("{x:e}")
    } else {
        format!("{x}")
    }
}

/// `x, y, z` as [`number`] writes each.
pub(crate) fn xyz(p: &[f64; 3]) -> String {
    format!("{}, {}, {}", number(p[0]), number(p[1]), number(p[2]))
}

/// A [`TopologyError`] about a mesh read from OBJ, worded with the file's 1-based vertex and
/// face numbers (`f 1 2 3` names vertices 1..3; a mesh's arrays count from 0). Tag indices are
/// 0-based in the file already (OpenSubdiv's `t` lines) and are shown as written.
struct ObjTerms<'a>(&'a TopologyError);

impl std::fmt::Display for ObjTerms<'_> {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        use TopologyError as E;
        match self.0 {
            E::IndexOutOfRange { face, index, count } => write!(
                f,
                "face {} names vertex {}, but the file has {count} vertices",
                face + 1,
                index + 1
            ),
            E::DegenerateFace { face, size } => write!(
                f,
                "face {} has {size} vertices; a face needs at least 3",
                face + 1
            ),
            E::RepeatedVertex { face, vertex } => write!(
                f,
                "face {} uses vertex {} more than once",
                face + 1,
                vertex + 1
            ),
            E::NonManifoldEdge { v0, v1, faces } => write!(
                f,
                "edge {}-{} is shared by {faces} faces (non-manifold edge)",
                v0 + 1,
                v1 + 1
            ),
            E::NonManifoldVertex { vertex, fans } => write!(
                f,
                "vertex {}: its faces form {fans} separate fans (non-manifold vertex)",
                vertex + 1
            ),
            E::InconsistentOrientation {
                face0,
                face1,
                v0,
                v1,
            } => write!(
                f,
                "faces {} and {} both traverse edge {}->{} in the same direction \
                 (inconsistent orientation)",
                face0 + 1,
                face1 + 1,
                v0 + 1,
                v1 + 1
            ),
            E::NonFinitePosition { vertex, position } => write!(
                f,
                "vertex {} has a non-finite position ({})",
                vertex + 1,
                xyz(position)
            ),
            E::CoordinateOutOfRange {
                vertex,
                position,
                bound,
            } => write!(
                f,
                "vertex {} at ({}) has a coordinate beyond ±{bound:e}, the largest the GPU's f32 \
                 arithmetic keeps finite (scale the mesh down)",
                vertex + 1,
                xyz(position)
            ),
            E::LoopRequiresTriangles { face, size } => write!(
                f,
                "Loop subdivision needs triangles, but face {} has {size} vertices",
                face + 1
            ),
            E::AdaptiveFaceTooLarge { face, size } => write!(
                f,
                "adaptive plan: face {} has {size} corners (at most 256)",
                face + 1
            ),
            // Level-0 faces are the file's; refined faces have no number in the file, so they
            // keep the refiner's (0-based) one and say which level it is of.
            E::AdaptivePatch { level: 0, face } => write!(
                f,
                "adaptive plan: face {} is not a regular patch",
                face + 1
            ),
            E::AdaptiveUnbalanced { level: 0, face } => write!(
                f,
                "adaptive plan: face {} borders a face more than one level away",
                face + 1
            ),
            E::AdaptivePatch { level, face } => write!(
                f,
                "adaptive plan: refined face {face} (0-based) of level {level} is not a regular patch"
            ),
            E::AdaptiveUnbalanced { level, face } => write!(
                f,
                "adaptive plan: refined face {face} (0-based) of level {level} borders a face \
                 more than one level away"
            ),
            E::TagOutOfRange { tag, index, count } => write!(
                f,
                "invalid tag: {tag} names {} {index} (tags count from 0), the file has {count} {}",
                tag.element(),
                tag.elements()
            ),
            other => std::fmt::Display::fmt(other, f),
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
    #[error("face corner '{word}' has more than three indices (v, v/vt, v//vn or v/vt/vn)")]
    CornerTooManyIndices { word: String },
    #[error("texture coordinate {index} is named, but the file has {count} 'vt' lines")]
    TextureIndexOutOfRange { index: i64, count: usize },
    #[error("normal {index} is named, but the file has {count} 'vn' lines")]
    NormalIndexOutOfRange { index: i64, count: usize },
    #[error("'t' needs a tag name and its counts (t NAME INTS/FLOATS/STRINGS VALUES...)")]
    TagWithoutCounts,
    #[error(
        "tag '{tag}': counts '{counts}' are not three whole numbers INTS/FLOATS/STRINGS \
         (such as 2/1/0)"
    )]
    BadTagCounts { tag: String, counts: String },
    #[error("tag '{tag}': counts '{counts}' do not match the {found} values on the line")]
    TagCountMismatch {
        tag: String,
        counts: String,
        found: usize,
    },
    #[error("tag '{tag}': '{word}' is not an integer")]
    BadTagInteger { tag: String, word: String },
    #[error("tag '{tag}': '{word}' is not a number")]
    BadTagFloat { tag: String, word: String },
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
    #[error("'{statement}': '{word}' is not a finite number")]
    NonFiniteNumber {
        statement: &'static str,
        word: String,
    },
    #[error("tag '{tag}': sharpness {value} is not finite")]
    NonFiniteSharpness { tag: String, value: f32 },
    #[error(
        "tag 'crease' needs vertex pairs (an even number of integers), found {found} integers"
    )]
    CreaseNeedsPairs { found: usize },
    #[error("tag 'corner' needs at least one vertex")]
    CornerNeedsVertices,
    #[error("tag 'hole' needs at least one face")]
    HoleNeedsFaces,
    #[error(
        "tag 'scalartag' takes one vertex and six numbers (1/6/0: v Dx Dy Dz tension sharpness \
         bias), found {ints} integers and {floats} numbers"
    )]
    ScalarTagShape { ints: usize, floats: usize },
    #[error("tag '{option}': {value}; expected {expected}")]
    BadOptionValue {
        option: String,
        value: String,
        expected: &'static str,
    },
    #[error("NUL byte: not UTF-8 text (UTF-16 without a byte-order mark? save the file as UTF-8)")]
    NulByte,
}
