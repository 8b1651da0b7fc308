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
use super::adaptive::{check_frame, Adaptive, AdaptiveBuild, ADAPTIVE_FEATURES, PATCH_LEGEND};
use crate::context::Context;
use crate::error::{Result, TessError};
use crate::technique::{Features, TechniqueId};
use crate::techniques::{BuildOptions, Built, TechniqueInfo};

impl TechniqueId {
    pub const GREGORY: TechniqueId = TechniqueId::new("gregory");
    pub const ACC: TechniqueId = TechniqueId::new("acc");
}

/// The single-pass approximations: the adaptive machinery without isolation.
pub const SINGLE_PASS: Features = Features {
    isolation: false,
    single_pass: true,
    ..ADAPTIVE_FEATURES
};

/// The registry entry of `--method gregory`.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::GREGORY,
    help: "Catmull-Clark approximated by one Gregory patch per base face, B-spline where regular (Loop, Schaefer, Ni, Castano), Gregory triangle patches on triangles; other faces next to non-quads split once",
    features: SINGLE_PASS,
    scheme: Some(topology::Scheme::CatmullClark),
    default_for_scheme: false,
    shader_folder: "adaptive",
    abi_code: 6,
    legend: PATCH_LEGEND,
    build: |ctx, mesh, options| build_registered(ctx, mesh, options, SinglePassPatch::Gregory),
    check_options: |_, params| check_frame(None, params),
};

/// The registry entry of `--method acc`.
pub static ACC_INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::ACC,
    help: "Catmull-Clark approximated by ACC-1 bicubic patches (Loop & Schaefer), Gregory patches where ACC-1 does not apply",
    abi_code: 7,
    build: |ctx, mesh, options| build_registered(ctx, mesh, options, SinglePassPatch::Acc1),
    ..INFO
};

/// The registry's constructor of both single-pass techniques.
fn build_registered(
    ctx: &mut Context,
    mesh: &ControlMesh,
    options: &BuildOptions,
    patch: SinglePassPatch,
) -> Result<Built> {
    let surface = build(
        ctx,
        mesh,
        patch,
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
        SinglePassPatch::Gregory => TechniqueId::GREGORY,
        SinglePassPatch::Acc1 => TechniqueId::ACC,
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
