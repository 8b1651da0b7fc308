//! CPU truth for every GPU technique: control meshes, subdivision, stencils, limit evaluation.
#![forbid(unsafe_code)]

pub mod error;
pub mod limit;
pub mod mesh;
pub mod patches;
pub mod refine;
pub mod rules;

pub use error::{ObjSyntax, TagKind, TopologyError};
pub use mesh::obj::{load_obj, parse_obj, write_control_mesh, write_obj};
pub use mesh::{
    check_positions, BoundaryInterpolation, ControlMesh, CreaseMethod, EdgeCrease, SubdivOptions,
    Topology, TriangleSubdivision, VertexCorner, MAX_COORDINATE,
};
pub use patches::adaptive::{
    plan_adaptive, AdaptiveOptions, AdaptivePatch, AdaptivePlan, EdgeKind, EndCap, LevelStats,
    PatchEdge, PatchKind, PatchSample, StencilBlock,
};
pub use refine::stencil::{StencilTable, StencilTableF32};
pub use refine::{
    refine_level, refine_sparse, refine_sparse_region, refine_uniform, uniform_stencils, ChildMaps,
    ChildOrigin, Level, LevelRef, LevelTopology, SparseRefinement, SparseRegion, UniformRefinement,
};
pub use rules::{Rule, Scheme};
