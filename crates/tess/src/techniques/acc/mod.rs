//! `--method acc`: Catmull-Clark approximated by ACC-1 bicubic geometry patches (Loop &
//! Schaefer 2008), one per base face, drawn by the planned-patch machinery as `gregory` is
//! (an ACC-1 net is a Gregory patch whose two interior points per corner coincide).
//!
//! ACC-1 on triangles and outside its scope (boundaries, creases, non-quad neighbourhoods)
//! falls back to Gregory patches; no tangent patches: normals come from the canonical tangents
//! both sides of an edge share.
use crate::context::Context;
use crate::error::Result;
use crate::technique::{Features, TechniqueId};
use crate::techniques::planned_patches::{self, check_frame, PATCH_LEGEND, PLANNED};
use crate::techniques::{BuildOptions, Built, TechniqueInfo};
use topology::patches::adaptive::single_pass::SinglePassPatch;
use topology::ControlMesh;

impl TechniqueId {
    pub const ACC: TechniqueId = TechniqueId::new("acc");
}

/// What ACC-1 takes: the planned surface's options, no isolation.
pub const FEATURES: Features = Features {
    single_pass: true,
    ..PLANNED
};

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::ACC,
    help: "Catmull-Clark approximated by ACC-1 bicubic patches (Loop & Schaefer), Gregory patches where ACC-1 does not apply",
    features: FEATURES,
    scheme: Some(topology::Scheme::CatmullClark),
    default_for_scheme: false,
    shader_folder: "adaptive",
    abi_code: 7,
    legend: PATCH_LEGEND,
    build,
    check_options: |_, params| check_frame(TechniqueId::ACC, None, params),
};

/// The registry's constructor: [`planned_patches::single_pass`] with ACC-1 patches.
fn build(ctx: &mut Context, mesh: &ControlMesh, options: &BuildOptions) -> Result<Built> {
    let surface = planned_patches::single_pass(
        ctx,
        mesh,
        SinglePassPatch::Acc1,
        options.sharpness_scale,
        !options.split_triangles,
        &options.name,
        &options.maps,
    )?;
    Ok(Built {
        notes: surface.param_error_note().into_iter().collect(),
        technique: Box::new(surface),
    })
}
