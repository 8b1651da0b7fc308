//! Curved PN triangles (Vlachos et al. 2001) with the corrected quadratic normal field of
//! Boubekeur et al. 2005, appendix A (`glsl/pn/pn.glsl` explains the choice of its t).
//!
//! Watertight by canonical edges: a tess coordinate on a patch edge is evaluated from that
//! edge's two corners and two edge control points only, starting from the corner with the
//! lower position (then normal) bits, with `precise` arithmetic; corners are the control points
//! themselves. Both patches of a shared edge thus emit the same position and normal bits
//! (`tests/watertight.rs`), without vertex indices: repeated vertices with equal data weld too.
use crate::gpu::DrawPush;
use crate::shaders::{Stage, Variant};
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
            axes: Variant::default(),
        }
    }
}

/// Curved PN triangles on a mesh's fan triangles.
pub type Pn = FacePatches<PnStyle>;
