//! `--method doo-sabin-limit` (the default for Doo-Sabin meshes): the exact Doo-Sabin limit
//! surface as biquadratic patches, isolated feature-adaptively around the extraordinary points
//! (the centres of non-quad faces).
//!
//! Design decisions:
//! - **The plan is `topology::patches::doo_sabin_limit`'s**, an `AdaptivePlan` drawn by the
//!   planned-patch machinery ([`planned_patches`]): level 1 is one global Doo-Sabin step,
//!   irregular squares are split to the isolation level, every regular square's biquadratic
//!   patch is the exact bicubic B-spline net the regular kind evaluates (no new shader), and a
//!   square still irregular at the isolation level is a bilinear (Coons) end cap on its
//!   canonical curves. So the stencils run on the GPU every frame (an animated base uploads
//!   only its positions), transitions double their coarse edges, and shared edges are
//!   bit-identical under every factor policy, on the tessellation stage and on refinement
//!   patterns alike.
//! - **The domain is the corner quad** (base face, corner, `(s, t)`: the sub-quad of
//!   `topology::limit::face_domain::subface_domain`) on every face, quads included, as the
//!   CPU evaluator (`topology::limit::doo_sabin_eval`) parameterizes the surface; a captured
//!   point maps to its base face through it ([`PlanBuild::corner_quads`]).
//! - **No texture coordinates yet**: the planned surfaces' texture look-up numbers a quad's
//!   patches over the whole face, not its corner quads, so the surface maps are refused by
//!   name (`Features::surface` off).
use crate::context::Context;
use crate::error::{Result, TessError};
use crate::technique::{Features, TechniqueId};
use crate::techniques::planned_patches::{self, check_frame, PlanBuild, PlannedPatches, PLANNED};
use crate::techniques::{BuildOptions, Built, LegendEntry, TechniqueInfo};
use topology::patches::doo_sabin_limit::plan_doo_sabin;
use topology::ControlMesh;

impl TechniqueId {
    pub const DOO_SABIN_LIMIT: TechniqueId = TechniqueId::new("doo-sabin-limit");
}

/// What the Doo-Sabin limit surface takes: the planned surface's options and the isolation
/// level, no surface maps.
pub const FEATURES: Features = Features {
    isolation: true,
    surface: false,
    // The seed's sine moves boundary points along their owner's normal, which the surface
    // build evaluates; the Doo-Sabin limit has no surface build (no texture coordinates).
    sine_displacement: false,
    ..PLANNED
};

/// The patch-colour legend: biquadratic patches drawn as the regular kind, bilinear caps.
const LEGEND: &[LegendEntry] = &[
    ([0.45, 0.65, 0.95], "biquadratic (odd levels lighter)"),
    ([0.95, 0.8, 0.3], "bilinear end cap"),
    ([0.3, 0.8, 0.35], "boundary (greener)"),
];

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::DOO_SABIN_LIMIT,
    help: "exact Doo-Sabin limit surface: biquadratic patches isolated feature-adaptively around the centres of non-quad faces, bilinear end caps",
    features: FEATURES,
    scheme: Some(topology::Scheme::DooSabin),
    default_for_scheme: true,
    shader_folder: "adaptive",
    abi_code: 12,
    legend: LEGEND,
    build: build_registered,
    check_options: |_, params| check_frame(TechniqueId::DOO_SABIN_LIMIT, None, params),
};

/// The registry's constructor: [`new`] with the isolation level and the draw path.
fn build_registered(
    ctx: &mut Context,
    mesh: &ControlMesh,
    options: &BuildOptions,
) -> Result<Built> {
    let path = planned_patches::resolve_path(
        TechniqueId::DOO_SABIN_LIMIT,
        options.pipeline,
        ctx.device(),
    )?;
    // The registry builds through `techniques::split::build_split`, which refused the input's
    // own tags; a non-manifold input arrives as its manifold split, whose tags are OpenSubdiv's
    // sharp rules for the non-manifold parts. Doo-Sabin has no sharp features, and like the
    // other Doo-Sabin techniques this one refines the split without them.
    let mut untagged = mesh.clone();
    untagged.creases.clear();
    untagged.corners.clear();
    let surface = new(
        ctx,
        &untagged,
        &PlanBuild {
            isolation: options.isolation,
            name: options.name.clone(),
            path,
            corner_quads: true,
            ..PlanBuild::default()
        },
    )?;
    Ok(Built {
        notes: Vec::new(),
        technique: Box::new(surface),
    })
}

/// Plans `mesh`'s Doo-Sabin limit to `options.isolation` and uploads it.
pub fn new(ctx: &mut Context, mesh: &ControlMesh, options: &PlanBuild) -> Result<PlannedPatches> {
    let plan = plan_doo_sabin(mesh, options.isolation).map_err(|e| TessError::Mesh {
        name: options.name.clone(),
        source: e.into(),
    })?;
    let options = PlanBuild {
        corner_quads: true,
        ..options.clone()
    };
    PlannedPatches::from_plan(
        ctx,
        mesh,
        plan,
        None,
        &options,
        TechniqueId::DOO_SABIN_LIMIT,
    )
}
