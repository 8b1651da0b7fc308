//! Flat tessellation: each base face subdivided in its own plane (quads kept as quad patches,
//! other polygons fan-triangulated). The baseline every benchmark ratio divides by.
use crate::shaders::Stage;
use crate::technique::{PatchPipeline, PatchType, TechniqueId, VertexInput};
use crate::techniques::face_patches::{FacePatches, FaceStyle, BASE_FACES};
use crate::techniques::{built, no_early_checks, TechniqueInfo};
use crate::tessellator::Domain;

impl TechniqueId {
    pub const FLAT: TechniqueId = TechniqueId::new("flat");
}

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::FLAT,
    help: "flat tessellation of each base face (quads as quad patches)",
    features: BASE_FACES,
    scheme: None,
    default_for_scheme: false,
    shader_folder: "flat",
    abi_code: 1,
    legend: &[],
    build: |ctx, mesh, options| built(Flat::build(ctx, mesh, options)?),
    check_options: no_early_checks,
};

/// See the module docs.
pub struct FlatStyle;

impl FaceStyle for FlatStyle {
    const ID: TechniqueId = TechniqueId::FLAT;
    const QUADS: bool = true;
    fn pipeline(patch: PatchType) -> PatchPipeline {
        let (control, evaluation, control_points) = match patch {
            PatchType::Quad => (Stage::CommonQuadTesc, Stage::FlatQuadTese, 4),
            _ => (Stage::CommonTriTesc, Stage::FlatTriTese, 3),
        };
        PatchPipeline {
            vertex_input: VertexInput::MESH,
            ..PatchPipeline::tessellated(
                Stage::CommonMeshVert,
                control,
                evaluation,
                Stage::CommonShadeFrag,
                control_points,
            )
        }
    }
    fn pattern_stage(domain: Domain) -> Stage {
        match domain {
            Domain::Quad => Stage::FlatPatternQuadVert,
            Domain::Triangle => Stage::FlatPatternTriVert,
        }
    }
}

/// Flat tessellation of a mesh.
pub type Flat = FacePatches<FlatStyle>;
