//! Phong tessellation (Boubekeur & Alexa 2008): each point of the flat triangle is projected
//! onto the tangent planes of the corners and blended back by the shape factor α.
use crate::shaders::Stage;
use crate::technique::Features;
use crate::technique::{PatchPipeline, PatchType, TechniqueId, VertexInput};
use crate::techniques::face_patches::{FacePatches, FaceStyle, BASE_FACES};
use crate::techniques::{built, no_early_checks, TechniqueInfo};
use crate::tessellator::Domain;

impl TechniqueId {
    pub const PHONG: TechniqueId = TechniqueId::new("phong");
}

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::PHONG,
    help: "Phong tessellation (Boubekeur & Alexa 2008) of the fan triangles",
    features: Features {
        phong_alpha: true,
        ..BASE_FACES
    },
    scheme: None,
    default_for_scheme: false,
    shader_folder: "phong",
    abi_code: 2,
    legend: &[],
    build: |ctx, mesh, options| built(Phong::build(ctx, mesh, options)?),
    check_options: no_early_checks,
};

/// See the module docs.
pub struct PhongStyle;

impl FaceStyle for PhongStyle {
    fn pattern_stage(_domain: Domain) -> Stage {
        Stage::PhongPatternTriVert
    }
    const ID: TechniqueId = TechniqueId::PHONG;
    const QUADS: bool = false;
    fn pipeline(_patch: PatchType) -> PatchPipeline {
        PatchPipeline {
            vertex_input: VertexInput::MESH,
            ..PatchPipeline::tessellated(
                Stage::CommonMeshVert,
                Stage::CommonTriTesc,
                Stage::PhongTriTese,
                Stage::CommonShadeFrag,
                3,
            )
        }
    }
}

/// Phong tessellation of a mesh's fan triangles.
pub type Phong = FacePatches<PhongStyle>;
