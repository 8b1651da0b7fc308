//! `--method acc`: Catmull-Clark approximated by ACC-1 bicubic geometry patches (Loop &
//! Schaefer 2008), one per base face, drawn by the planned-patch machinery as `gregory` is
//! (an ACC-1 net is a Gregory patch whose two interior points per corner coincide).
//!
//! ACC-1 on triangles and outside its scope (boundaries, creases, non-quad neighbourhoods)
//! falls back to Gregory patches; no tangent patches: normals come from the canonical tangents
//! both sides of an edge share.
use crate::technique::TechniqueId;
use crate::techniques::planned_patches::{self, check_frame, PATCH_LEGEND, SINGLE_PASS};
use crate::techniques::TechniqueInfo;
use topology::patches::adaptive::single_pass::SinglePassPatch;

impl TechniqueId {
    pub const ACC: TechniqueId = TechniqueId::new("acc");
}

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::ACC,
    help: "Catmull-Clark approximated by ACC-1 bicubic patches (Loop & Schaefer), Gregory patches where ACC-1 does not apply",
    features: SINGLE_PASS,
    scheme: Some(topology::Scheme::CatmullClark),
    default_for_scheme: false,
    shader_folder: "adaptive",
    abi_code: 7,
    legend: PATCH_LEGEND,
    build: |ctx, mesh, options| {
        planned_patches::build_single_pass(ctx, mesh, options, SinglePassPatch::Acc1)
    },
    check_options: |_, params| check_frame(TechniqueId::ACC, None, params),
};
