//! `--method gregory`: Catmull-Clark approximated by one Gregory patch per base face (Loop,
//! Schaefer, Ni, Castaño 2009), bicubic B-spline where the face is regular.
//!
//! Design decisions:
//! - **The plan is `topology::patches::adaptive::single_pass`'s**, an `AdaptivePlan`, drawn by
//!   the planned-patch machinery ([`planned_patches::single_pass`]): the stencil evaluator
//!   turns the base positions into every control point each frame (animation uploads only the
//!   base), canonical corners and curves make shared edges bit-identical under every factor
//!   policy, and the shaders are `glsl/adaptive/`'s.
//! - **Non-quads**: a triangle is one Gregory triangle patch (`triangle.tesc/.tese`, a
//!   triangle domain), unless `split_triangles`; other non-quads, and every face with a corner
//!   next to a non-quad, are split into their level-1 children by one Catmull-Clark step folded
//!   into the stencils. Semi-sharp tags are rounded to smooth (< 0.5) or infinitely sharp.
//! - **Normals** come from the canonical tangents both sides of an edge share (the patches
//!   are not C1 across edges).
use crate::technique::TechniqueId;
use crate::techniques::planned_patches::{self, check_frame, PATCH_LEGEND, SINGLE_PASS};
use crate::techniques::TechniqueInfo;
use topology::patches::adaptive::single_pass::SinglePassPatch;

impl TechniqueId {
    pub const GREGORY: TechniqueId = TechniqueId::new("gregory");
}

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::GREGORY,
    help: "Catmull-Clark approximated by one Gregory patch per base face, B-spline where regular (Loop, Schaefer, Ni, Castano), Gregory triangle patches on triangles; other faces next to non-quads split once",
    features: SINGLE_PASS,
    scheme: Some(topology::Scheme::CatmullClark),
    default_for_scheme: false,
    shader_folder: "adaptive",
    abi_code: 6,
    legend: PATCH_LEGEND,
    build: |ctx, mesh, options| {
        planned_patches::build_single_pass(ctx, mesh, options, SinglePassPatch::Gregory)
    },
    check_options: |_, params| check_frame(TechniqueId::GREGORY, None, params),
};
