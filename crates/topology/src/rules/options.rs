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

/// Subdivision options carried by a control mesh (set from OBJ `t` tags).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct SubdivOptions {
    pub boundary: BoundaryInterpolation,
    pub crease_method: CreaseMethod,
    pub triangle_subdivision: TriangleSubdivision,
}
