//! Single-pass Catmull-Clark approximations: one patch per base face, no
//! refinement on the device, as real-time engines ship them: Gregory patches (Loop, Schaefer,
//! Ni, Castaño 2009) or ACC-1 geometry patches (Loop & Schaefer 2008), bicubic B-spline
//! patches where the face is regular (exact there).
//!
//! The result is an [`AdaptivePlan`], so the feature-adaptive technique's GPU machinery (one
//! stencil kernel from base positions to control points every frame, canonical corners and
//! curves, transition edges) draws it unchanged and watertight by the same construction.
//!
//! # Design decisions
//! * **Quads away from non-quads: one patch per base face.** Regular faces (the adaptive
//!   plan's regularity, sharp-but-regular boundaries and creases included) are bicubic
//!   B-spline patches; the others Gregory patches built on the base mesh
//!   ([`crate::patches::gregory::gregory_basis`]), or with [`SinglePassPatch::Acc1`] ACC-1 nets where
//!   ACC-1 applies (interior quads with smooth corners and all-quad neighbourhoods,
//!   [`crate::patches::acc`]) and Gregory patches elsewhere. An ACC-1 net is stored as a Gregory patch
//!   whose two interior points per corner coincide (then the Gregory patch is that bicubic
//!   Bézier patch), so the device needs no third patch kind.
//! * **Non-quads and their neighbours: one Catmull-Clark step, on the CPU.** Gregory and ACC-1
//!   patches need quads all around their corners. A face with a corner next to a triangle,
//!   pentagon, ... (the non-quad itself included) is split into its level-1 children (4 per
//!   quad, `n` per `n`-gon), each a B-spline or Gregory patch there. The step is folded into
//!   the local points' stencils only when there is a split face (an all-quad mesh has no
//!   refinement block at all); its rows are one extra dispatch of the same kernel. There is no
//!   Gregory *triangle* patch yet: a triangle is 3 quad patches. A level-0 patch next to a
//!   split face gets a transition edge (two half curves, doubled level) as in the adaptive
//!   plan, so shared edges are still one canonical curve each.
//! * **Semi-sharp creases and corners are rounded** to the nearest rule a single patch
//!   represents: sharpness `< 0.5` smooth, `≥ 0.5` infinitely sharp
//!   ([`SEMI_SHARP_ROUNDING`]); tests/gregory.rs measures what it costs against the exact
//!   limit on OpenSubdiv's crease shapes.
//! * **Exact where regular**: regular faces are the B-spline patch; Gregory patches of faces
//!   whose four corners are regular are too (their face points are the B-spline's).
use super::*;

/// Sharpness at or above which a semi-sharp tag is rounded to infinitely sharp (below: smooth).
pub const SEMI_SHARP_ROUNDING: f32 = 0.5;

/// Which patch the irregular faces get.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum SinglePassPatch {
    /// Gregory patches (20 points).
    #[default]
    Gregory,
    /// ACC-1 geometry patches where ACC-1 applies, Gregory patches elsewhere.
    Acc1,
}

/// Options of [`plan_single_pass`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SinglePassOptions {
    pub patch: SinglePassPatch,
    /// Multiplies every tagged sharpness before the rounding (finite, ≥ 0).
    pub sharpness_scale: f32,
    /// Triangles as one Gregory triangle patch each (default); off, as three quad patches of
    /// their level-1 children.
    pub gregory_triangles: bool,
}

impl Default for SinglePassOptions {
    fn default() -> Self {
        SinglePassOptions {
            patch: SinglePassPatch::Gregory,
            sharpness_scale: 1.0,
            gregory_triangles: true,
        }
    }
}

/// `mesh` with every tag rounded to smooth or infinitely sharp ([`SEMI_SHARP_ROUNDING`]).
pub fn rounded_sharpness(mesh: &ControlMesh, scale: f32) -> Result<ControlMesh, TopologyError> {
    if !scale.is_finite() || scale < 0.0 {
        return Err(TopologyError::BadSharpnessScale { scale });
    }
    let mut out = levels::scaled_mesh(mesh, scale)?;
    let round = |s: f32| {
        if s >= SEMI_SHARP_ROUNDING {
            SHARPNESS_INFINITE
        } else {
            0.0
        }
    };
    out.creases.retain_mut(|c| {
        c.sharpness = round(c.sharpness);
        c.sharpness > 0.0
    });
    out.corners.retain_mut(|c| {
        c.sharpness = round(c.sharpness);
        c.sharpness > 0.0
    });
    Ok(out)
}

/// The single-pass plan of `mesh` (see the module docs). Its `isolation` is 0 when no face was
/// split, else 1.
///
/// ```
/// use topology::patches::adaptive::single_pass::{plan_single_pass, SinglePassOptions};
/// use topology::patches::adaptive::PatchKind;
/// use topology::ControlMesh;
/// let p = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.],
///          [0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]];
/// let faces = [[0u32, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
/// let mesh = ControlMesh::from_polygons(p.to_vec(), &faces);
/// let plan = plan_single_pass(&mesh, &SinglePassOptions::default()).unwrap();
/// assert_eq!(plan.patches.len(), 6); // one Gregory patch per face
/// assert!(plan.patches.iter().all(|p| p.kind == PatchKind::Gregory && p.level == 0));
/// assert!(plan.steps.is_empty());
/// ```
pub fn plan_single_pass(
    mesh: &ControlMesh,
    opts: &SinglePassOptions,
) -> Result<AdaptivePlan, TopologyError> {
    let rounded = rounded_sharpness(mesh, opts.sharpness_scale)?;
    let levels = levels::build_levels(&rounded, 1, false, MAX_REFINED_FACES, true)?;
    let split = levels.len() > 1;
    let adaptive = AdaptiveOptions {
        isolation: 1,
        end_cap: EndCap::Gregory,
        sharpness_scale: 1.0,
        follow_semi_sharp: false,
    };
    let mut plan = assemble::assemble(
        &rounded,
        &adaptive,
        levels,
        0,
        opts.patch == SinglePassPatch::Acc1,
        opts.gregory_triangles,
    )?;
    plan.isolation = u32::from(split);
    Ok(plan)
}
