//! The options a control mesh carries into its refinement, named as OpenSubdiv's
//! `Sdc::Options` names them.

/// How boundary vertices are treated (OpenSubdiv `VtxBoundaryInterpolation`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum BoundaryInterpolation {
    /// OBJ tag value 0: the faces around a boundary vertex whose boundary edges are not all
    /// tagged infinitely sharp are holes, as in OpenSubdiv
    /// ([`crate::mesh::ControlMesh::apply_boundary_none`]); what remains refines as under
    /// [`BoundaryInterpolation::EdgesOnly`].
    None,
    /// OBJ tag value 2 (the default): boundary edges are infinitely sharp creases.
    #[default]
    EdgesOnly,
    /// OBJ tag value 1: boundary edges are sharp and corners (vertices with a single face)
    /// are infinitely sharp too, so they stay put.
    EdgesAndCorners,
}

/// How semi-sharp edge sharpness decays per level (OpenSubdiv `CreasingMethod`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CreaseMethod {
    /// Subtract one per level.
    #[default]
    Uniform,
    /// Chaikin: blend with the average sharpness of the other semi-sharp edges at the end vertex.
    Chaikin,
}

/// Catmull-Clark rule for edges next to triangles (OpenSubdiv `TriangleSubdivision`).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum TriangleSubdivision {
    /// The plain Catmull-Clark edge rule.
    #[default]
    Catmark,
    /// OpenSubdiv's "smooth triangle" weights for edges next to triangles.
    Smooth,
}

/// Subdivision options carried by a control mesh (set from OBJ `t` tags or a USD mesh's
/// attributes).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SubdivOptions {
    pub boundary: BoundaryInterpolation,
    pub crease_method: CreaseMethod,
    pub triangle_subdivision: TriangleSubdivision,
    /// How the texture coordinates are interpolated.
    pub fvar_interpolation: FVarLinearInterpolation,
}

/// How face-varying data (texture coordinates) is interpolated (OpenSubdiv's
/// `Sdc::Options::FVarLinearInterpolation`, USD's `faceVaryingLinearInterpolation`), from the
/// smoothest to the most linear. Where the texture coordinates are continuous and the mode
/// smooth, they are subdivided with the vertex rules; where they are discontinuous (a seam,
/// the corners of a `vt` island) the mode pins them in the ways named here. See
/// [`crate::refine::fvar`] for how each rule is applied.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum FVarLinearInterpolation {
    /// Smooth everywhere the mesh is smooth: seams are smooth boundary curves (RenderMan's old
    /// "facevertex").
    None,
    /// Corners of the texture layout (a value with a single face) are pinned.
    CornersOnly,
    /// Corners, and values where three or more texture regions meet, are pinned (USD's
    /// default, `cornersPlus1`).
    CornersPlus1,
    /// [`FVarLinearInterpolation::CornersPlus1`], and darts (a seam ending inside the mesh)
    /// and both values of a seam vertex with a corner on either side are pinned.
    CornersPlus2,
    /// Linear along every seam and boundary, smooth inside each region.
    Boundaries,
    /// Linear everywhere: bilinear on each face (OBJ's default here, OpenSubdiv's default).
    #[default]
    All,
}

impl FVarLinearInterpolation {
    /// Every mode, smoothest first.
    pub const ALL_MODES: [FVarLinearInterpolation; 6] = [
        FVarLinearInterpolation::None,
        FVarLinearInterpolation::CornersOnly,
        FVarLinearInterpolation::CornersPlus1,
        FVarLinearInterpolation::CornersPlus2,
        FVarLinearInterpolation::Boundaries,
        FVarLinearInterpolation::All,
    ];

    /// USD's token (`none`, `cornersOnly`, `cornersPlus1`, `cornersPlus2`, `boundaries`,
    /// `all`), which is also the command line's name.
    pub fn name(self) -> &'static str {
        match self {
            FVarLinearInterpolation::None => "none",
            FVarLinearInterpolation::CornersOnly => "cornersOnly",
            FVarLinearInterpolation::CornersPlus1 => "cornersPlus1",
            FVarLinearInterpolation::CornersPlus2 => "cornersPlus2",
            FVarLinearInterpolation::Boundaries => "boundaries",
            FVarLinearInterpolation::All => "all",
        }
    }

    /// The mode USD's token names (case-sensitive, as USD spells them), or `None`.
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL_MODES.into_iter().find(|m| m.name() == name)
    }

    /// The integer of OpenSubdiv's `t facevaryinginterpolateboundary` tag (the order of
    /// `Sdc::Options::FVarLinearInterpolation`: 0 none … 5 all).
    pub fn tag_value(self) -> i64 {
        Self::ALL_MODES.iter().position(|&m| m == self).unwrap_or(5) as i64
    }

    /// The mode of tag value `value`, or `None` outside 0..=5.
    pub fn from_tag_value(value: i64) -> Option<Self> {
        usize::try_from(value)
            .ok()
            .and_then(|i| Self::ALL_MODES.get(i).copied())
    }

    /// Whether the texture coordinates are bilinear on each face (no face-varying
    /// refinement needed).
    pub fn is_linear(self) -> bool {
        self == FVarLinearInterpolation::All
    }
}

impl std::fmt::Display for FVarLinearInterpolation {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

impl std::str::FromStr for FVarLinearInterpolation {
    type Err = String;
    fn from_str(s: &str) -> Result<Self, String> {
        Self::from_name(s).ok_or_else(|| {
            format!(
                "unknown face-varying interpolation '{s}' (none, cornersOnly, cornersPlus1, \
                 cornersPlus2, boundaries, all)"
            )
        })
    }
}
