//! CPU truth for every GPU technique: control meshes, subdivision, stencils, limit evaluation.
#![forbid(unsafe_code)]

pub mod acc;
pub mod adaptive;
pub mod bft;
pub mod error;
pub mod eval;
pub mod gregory;
pub mod input;
pub mod limit;
pub mod limit_mesh;
pub mod mesh;
pub mod obj;
pub mod patch;
pub mod refine;
pub mod reparam;
pub mod sdc;
pub mod stencil;
pub mod texcoord;

pub use adaptive::{
    plan_adaptive, AdaptiveOptions, AdaptivePatch, AdaptivePlan, EdgeKind, EndCap, LevelStats,
    PatchEdge, PatchKind, PatchSample, StencilBlock,
};
pub use error::{ObjSyntax, TagKind, TopologyError};
pub use input::{read_regular_file, MAX_OBJ_BYTES};
pub use mesh::{
    check_positions, BoundaryInterpolation, ControlMesh, CreaseMethod, EdgeCrease, SubdivOptions,
    Topology, TriangleSubdivision, VertexCorner, MAX_COORDINATE,
};
pub use obj::{
    load_obj, load_obj_with_lines, parse_obj, parse_obj_bytes, parse_obj_with_lines,
    write_control_mesh, write_obj, ObjLines,
};
pub use refine::{
    refine_level, refine_sparse, refine_sparse_region, refine_uniform, uniform_stencils, ChildMaps,
    ChildOrigin, Level, LevelRef, LevelTopology, SparseRefinement, SparseRegion, UniformRefinement,
};
pub use sdc::{Rule, Scheme};
pub use stencil::{StencilTable, StencilTableF32};
