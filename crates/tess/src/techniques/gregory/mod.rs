//! Single-pass Catmull-Clark approximations on the tessellation stage (issue 12):
//! `--method gregory` (Gregory patches, Loop, Schaefer, Ni, Castaño 2009) and `--method acc`
//! (ACC-1 geometry patches, Loop & Schaefer 2008, Gregory where ACC-1 does not apply), one
//! patch per base face, bicubic B-spline where the face is regular.
//!
//! Design decisions:
//! - **The plan is `topology::patches::adaptive::single_pass`'s**, an `AdaptivePlan`, so the adaptive
//!   technique's GPU machinery draws it unchanged ([`Adaptive::from_plan`]): one stencil kernel
//!   turns the base positions into every control point each frame (animation uploads only the
//!   base), canonical corners and curves make shared edges bit-identical under every factor
//!   policy, and the shaders are `glsl/adaptive/`'s (an ACC-1 net is a Gregory patch whose two
//!   interior points per corner coincide).
//! - **Non-quads**: a triangle is one Gregory triangle patch (`triangle.tesc/.tese`, a
//!   triangle domain), unless `split_triangles`; other non-quads, and every face with a corner
//!   next to a non-quad, are split into their level-1 children by one Catmull-Clark step folded
//!   into the stencils. Semi-sharp tags are rounded to smooth (< 0.5) or infinitely sharp.
//! - **ACC-1 on triangles and outside its scope** (boundaries, creases, non-quad
//!   neighbourhoods) falls back to Gregory patches; no tangent patches: normals come from the
//!   geometry patch's derivatives.
use super::adaptive::{Adaptive, AdaptiveBuild};
use crate::context::Context;
use crate::error::{Result, TessError};
use crate::technique::TechniqueId;
use topology::patches::adaptive::single_pass::{
    plan_single_pass, SinglePassOptions, SinglePassPatch,
};
use topology::ControlMesh;

/// Builds `--method gregory` (`patch` Gregory) or `--method acc` (`patch` ACC-1) for `mesh`.
pub fn build(
    ctx: &mut Context,
    mesh: &ControlMesh,
    patch: SinglePassPatch,
    sharpness_scale: f32,
    gregory_triangles: bool,
    name: &str,
    maps: &crate::surface::SurfaceMaps,
) -> Result<Adaptive> {
    crate::techniques::adaptive::check_texcoords(mesh, maps, name)?;
    let plan = plan_single_pass(
        mesh,
        &SinglePassOptions {
            patch,
            sharpness_scale,
            gregory_triangles,
        },
    )
    .map_err(|e| TessError::Mesh {
        name: name.to_string(),
        source: e.into(),
    })?;
    let id = match patch {
        SinglePassPatch::Gregory => TechniqueId::Gregory,
        SinglePassPatch::Acc1 => TechniqueId::Acc,
    };
    Adaptive::from_plan(
        ctx,
        mesh,
        plan,
        &AdaptiveBuild {
            isolation: 1,
            sharpness_scale,
            follow_semi_sharp: false,
            name: name.to_string(),
            maps: maps.clone(),
            ..AdaptiveBuild::default()
        },
        id,
    )
}
