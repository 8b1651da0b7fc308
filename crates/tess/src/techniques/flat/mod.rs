//! Flat tessellation: each base face subdivided in its own plane (quads kept as quad patches,
//! other polygons fan-triangulated). The baseline every benchmark ratio divides by.
use crate::gpu::DrawPush;
use crate::shaders::{Stage, Variant};
use crate::technique::{PatchPipeline, PatchType, TechniqueId};
use crate::techniques::face_patches::{FacePatches, FaceStyle};

/// See the module docs.
pub struct FlatStyle;

impl FaceStyle for FlatStyle {
    const ID: TechniqueId = TechniqueId::Flat;
    const QUADS: bool = true;
    fn pipeline(patch: PatchType) -> PatchPipeline {
        let (control, evaluation, control_points) = match patch {
            PatchType::Quad => (Stage::CommonQuadTesc, Stage::FlatQuadTese, 4),
            _ => (Stage::CommonTriTesc, Stage::FlatTriTese, 3),
        };
        PatchPipeline {
            vertex: Stage::CommonMeshVert,
            control,
            evaluation,
            fragment: Stage::CommonShadeFrag,
            control_points,
            mesh_vertex_input: true,
            push_constant_bytes: std::mem::size_of::<DrawPush>() as u32,
            axes: Variant::default(),
        }
    }
}

/// Flat tessellation of a mesh.
pub type Flat = FacePatches<FlatStyle>;
