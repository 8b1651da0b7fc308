//! Phong tessellation (Boubekeur & Alexa 2008): each point of the flat triangle is projected
//! onto the tangent planes of the corners and blended back by the shape factor α.
use crate::gpu::DrawPush;
use crate::shaders::{Stage, Variant};
use crate::technique::{PatchPipeline, PatchType, TechniqueId};
use crate::techniques::face_patches::{FacePatches, FaceStyle};

/// See the module docs.
pub struct PhongStyle;

impl FaceStyle for PhongStyle {
    const ID: TechniqueId = TechniqueId::Phong;
    const QUADS: bool = false;
    fn pipeline(_patch: PatchType) -> PatchPipeline {
        PatchPipeline {
            vertex: Stage::CommonMeshVert,
            control: Stage::CommonTriTesc,
            evaluation: Stage::PhongTriTese,
            fragment: Stage::CommonShadeFrag,
            control_points: 3,
            mesh_vertex_input: true,
            push_constant_bytes: std::mem::size_of::<DrawPush>() as u32,
            axes: Variant::default(),
        }
    }
}

/// Phong tessellation of a mesh's fan triangles.
pub type Phong = FacePatches<PhongStyle>;
