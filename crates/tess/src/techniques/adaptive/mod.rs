//! `--method adaptive` (the default for Catmull-Clark meshes): the exact Catmull-Clark limit
//! surface by feature-adaptive refinement (Nießner et al. 2012; the seed's §3–4).
//! `topology::patches::adaptive` isolates extraordinary vertices, non-quads and semi-sharp
//! creases to the isolation level and ends with Gregory or bilinear end caps; the
//! planned-patch machinery ([`planned_patches`]) evaluates the plan's stencils on the GPU
//! every frame and draws its patches, watertight by bits under every factor policy.
use crate::context::Context;
use crate::error::{Result, TessError};
use crate::surface::check_texcoords;
use crate::technique::{Features, TechniqueId};
use crate::techniques::planned_patches::{
    self, check_frame, PlanBuild, PlannedPatches, PATCH_LEGEND, PLANNED,
};
use crate::techniques::{BuildOptions, Built, TechniqueInfo};
use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions};
use topology::patches::fvar::FVarPlan;
use topology::ControlMesh;

pub use planned_patches::DEFAULT_ISOLATION;

impl TechniqueId {
    pub const ADAPTIVE: TechniqueId = TechniqueId::new("adaptive");
}

/// What feature-adaptive Catmull-Clark takes: the planned surface's options and the isolation
/// level.
pub const FEATURES: Features = Features {
    isolation: true,
    ..PLANNED
};

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::ADAPTIVE,
    help: "exact Catmull-Clark limit surface by feature-adaptive refinement (Niessner et al.), Gregory or bilinear end caps",
    features: FEATURES,
    scheme: Some(topology::Scheme::CatmullClark),
    default_for_scheme: true,
    shader_folder: "adaptive",
    abi_code: 5,
    legend: PATCH_LEGEND,
    build: build_registered,
    check_options: |_, params| check_frame(TechniqueId::ADAPTIVE, None, params),
};

/// The registry's constructor: [`new`] with the build options adaptive takes.
fn build_registered(
    ctx: &mut Context,
    mesh: &ControlMesh,
    options: &BuildOptions,
) -> Result<Built> {
    let surface = new(
        ctx,
        mesh,
        &PlanBuild {
            isolation: options.isolation,
            end_cap: options.end_cap,
            sharpness_scale: options.sharpness_scale,
            follow_semi_sharp: options.follow_semi_sharp,
            name: options.name.clone(),
            maps: options.maps.clone(),
            single_pass: false,
            path: planned_patches::resolve_path(
                TechniqueId::ADAPTIVE,
                options.pipeline,
                ctx.device(),
            )?,
            corner_quads: false,
        },
    )?;
    Ok(Built {
        notes: surface.param_error_note().into_iter().collect(),
        technique: Box::new(surface),
    })
}

/// Plans `mesh` (Catmull-Clark, any faces, boundaries, creases) to `options.isolation` and
/// uploads it, with one base-position buffer per frame slot of `ctx`.
pub fn new(ctx: &mut Context, mesh: &ControlMesh, options: &PlanBuild) -> Result<PlannedPatches> {
    check_texcoords(mesh, &options.maps, &options.name)?;
    let plan_options = AdaptiveOptions {
        isolation: options.isolation,
        end_cap: options.end_cap,
        sharpness_scale: options.sharpness_scale,
        follow_semi_sharp: options.follow_semi_sharp,
    };
    let plan = plan_adaptive(mesh, &plan_options).map_err(|e| TessError::Mesh {
        name: options.name.clone(),
        source: e.into(),
    })?;
    let fvar =
        planned_patches::fvar_patches(mesh, &FVarPlan::Adaptive(plan_options), &options.name)?;
    PlannedPatches::from_plan(ctx, mesh, plan, fvar, options, TechniqueId::ADAPTIVE)
}
