//! Curved PN triangles (Vlachos et al. 2001) with the corrected quadratic normal field of
//! Boubekeur et al. 2005, appendix A (`glsl/pn/pn.glsl` explains the choice of its t).
//!
//! Watertight by canonical edges: a tess coordinate on a patch edge is evaluated from that
//! edge's two corners and two edge control points only, starting from the corner with the
//! lower position (then normal) bits, with `precise` arithmetic; corners are the control points
//! themselves. Both patches of a shared edge thus emit the same position and normal bits
//! (`tests/watertight.rs`), without vertex indices: repeated vertices with equal data weld too.
//!
//! A mesh with scalar tags (`t scalartag`) is drawn as an ST-mesh ([`scalar_tags`]): tagged
//! corners bring their own edge control points and sides' normals, on both draw paths.
pub mod scalar_tags;
use crate::shaders::Stage;
use crate::shaders::Variant;
use crate::technique::{DrawPath, PatchPipeline, PatchType, TechniqueId, VertexInput};
use crate::techniques::face_patches::{FacePatches, FaceStyle, BASE_FACES};
use crate::techniques::{built, no_early_checks, TechniqueInfo};
use crate::tessellator::Domain;

impl TechniqueId {
    pub const PN: TechniqueId = TechniqueId::new("pn");
}

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::PN,
    help: "curved PN triangles with the corrected normal field",
    features: BASE_FACES,
    scheme: None,
    default_for_scheme: false,
    shader_folder: "pn",
    abi_code: 3,
    legend: &[],
    build: |ctx, mesh, options| built(Pn::build(ctx, mesh, options)?),
    check_options: no_early_checks,
};

/// See the module docs.
pub struct PnStyle;

impl FaceStyle for PnStyle {
    const SCALAR_TAGS: bool = true;
    fn tagged_pipeline(patch: PatchType) -> Option<PatchPipeline> {
        Some(Self::tagged(patch))
    }
    fn pattern_stage(_domain: Domain) -> Stage {
        Stage::PnPatternTriVert
    }
    const ID: TechniqueId = TechniqueId::PN;
    const QUADS: bool = false;
    fn pipeline(_patch: PatchType) -> PatchPipeline {
        PatchPipeline {
            vertex_input: VertexInput::MESH,
            ..PatchPipeline::tessellated(
                Stage::CommonMeshVert,
                Stage::PnTriTesc,
                Stage::PnTriTese,
                Stage::CommonShadeFrag,
                3,
            )
        }
    }
}

impl PnStyle {
    /// The scalar-tagged build of `patch`'s pipeline ([`scalar_tags`]).
    fn tagged(patch: PatchType) -> PatchPipeline {
        let axes = Variant {
            scalar_tags: true,
            ..Variant::default()
        };
        match patch.path() {
            DrawPath::Pattern => PatchPipeline {
                vertex_input: crate::gpu::pattern_input::TAGGED_TRIANGLE,
                axes,
                ..PatchPipeline::triangles(Stage::PnPatternTriVert, Stage::CommonShadeFrag)
            },
            _ => PatchPipeline {
                vertex_input: crate::gpu::TaggedCorner::MESH,
                vertex: Stage::PnTaggedMeshVert,
                axes,
                ..Self::pipeline(patch)
            },
        }
    }
}

/// Curved PN triangles on a mesh's fan triangles.
pub type Pn = FacePatches<PnStyle>;
