//! Curved PN triangles with the corrected quadratic normal field of Boubekeur et al. 2005,
//! appendix A (`glsl/pn/tri.tesc` explains the choice of its t).
use crate::gpu::DrawPush;
use crate::shaders::Stage;
use crate::technique::{PatchPipeline, PatchType, TechniqueId};
use crate::techniques::face_patches::{FacePatches, FaceStyle};

/// See the module docs.
pub struct PnStyle;

impl FaceStyle for PnStyle {
    const ID: TechniqueId = TechniqueId::Pn;
    const QUADS: bool = false;
    fn pipeline(_patch: PatchType) -> PatchPipeline {
        PatchPipeline {
            vertex: Stage::CommonMeshVert,
            control: Stage::PnTriTesc,
            evaluation: Stage::PnTriTese,
            fragment: Stage::CommonShadeFrag,
            control_points: 3,
            mesh_vertex_input: true,
            push_constant_bytes: std::mem::size_of::<DrawPush>() as u32,
        }
    }
}

/// Curved PN triangles on a mesh's fan triangles.
pub type Pn = FacePatches<PnStyle>;
