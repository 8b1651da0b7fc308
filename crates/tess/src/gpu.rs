//! Rust mirrors of the GPU-side structs in `glsl/include/*.glsl`. `#[repr(C)]` + `Pod`, no
//! `Vec3` (std140/std430 padding); sizes and offsets asserted at compile time, and checked
//! against the compiled SPIR-V by a test.
use bytemuck::{Pod, Zeroable};
use std::mem::{offset_of, size_of};

/// `Frame` uniform block (std140), `glsl/include/frame.glsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Pod, Zeroable)]
pub struct FrameUniforms {
    pub view_proj: [[f32; 4]; 4],
    pub view: [[f32; 4]; 4],
    pub camera_pos: [f32; 4],
    pub light_dir: [f32; 4],
    /// x: outer level, y: inner level, z: Phong shape factor.
    pub tess: [f32; 4],
    pub base_color: [f32; 4],
    pub wire_color: [f32; 4],
    pub viewport: [f32; 4],
}

const _: () = {
    assert!(size_of::<FrameUniforms>() == 224);
    assert!(offset_of!(FrameUniforms, view) == 64);
    assert!(offset_of!(FrameUniforms, camera_pos) == 128);
    assert!(offset_of!(FrameUniforms, light_dir) == 144);
    assert!(offset_of!(FrameUniforms, tess) == 160);
    assert!(offset_of!(FrameUniforms, base_color) == 176);
    assert!(offset_of!(FrameUniforms, wire_color) == 192);
    assert!(offset_of!(FrameUniforms, viewport) == 208);
};

/// Member offsets of `FrameUniforms` in declaration order, for the SPIR-V layout test.
pub const FRAME_UNIFORM_OFFSETS: [u32; 8] = [
    offset_of!(FrameUniforms, view_proj) as u32,
    offset_of!(FrameUniforms, view) as u32,
    offset_of!(FrameUniforms, camera_pos) as u32,
    offset_of!(FrameUniforms, light_dir) as u32,
    offset_of!(FrameUniforms, tess) as u32,
    offset_of!(FrameUniforms, base_color) as u32,
    offset_of!(FrameUniforms, wire_color) as u32,
    offset_of!(FrameUniforms, viewport) as u32,
];

/// `Draw` push constant (std430), `glsl/include/frame.glsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct DrawPush {
    /// 0: shaded, 1: wireframe.
    pub mode: u32,
    /// Patch id of the draw's first patch: `gl_PrimitiveID` restarts at 0 in every draw, and
    /// draws are split on some drivers, so the TES adds this to number patches frame-wide.
    pub first_patch: u32,
}

const _: () = {
    assert!(size_of::<DrawPush>() == 8);
    assert!(offset_of!(DrawPush, first_patch) == 4);
};

/// Member offsets of `DrawPush` in declaration order, for the SPIR-V layout test.
pub const DRAW_PUSH_OFFSETS: [u32; 2] = [
    offset_of!(DrawPush, mode) as u32,
    offset_of!(DrawPush, first_patch) as u32,
];

/// `BftDraw` push constant of every BFT stage, `glsl/include/bft.glsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct BftPush {
    /// 0: shaded, 1: wireframe.
    pub mode: u32,
    /// Patch (level-1 face) index of the draw's first patch.
    pub first_patch: u32,
    /// 0: uniform, 1: screen-space edge length, 2: camera distance.
    pub factor_mode: u32,
    /// Bit 0: geometric normals; 1: patch colours; 2: fractional factors.
    pub options: u32,
    pub uniform_level: f32,
    pub pixels_per_segment: f32,
    pub distance_ref: f32,
    pub max_level: f32,
    /// Compute passes: level-1 vertex count.
    pub count: u32,
}

const _: () = assert!(size_of::<BftPush>() == 36);

/// Interleaved vertex of the mesh vertex buffer (`mesh.vert` locations 0 and 1).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
}

const _: () = assert!(size_of::<Vertex>() == 24);

/// Reads `OpMemberDecorate ... Offset` of the struct named `struct_name` from SPIR-V words:
/// the offsets glslang actually laid out, to compare with the Rust mirror.
pub fn spirv_member_offsets(words: &[u32], struct_name: &str) -> Option<Vec<u32>> {
    const OP_NAME: u32 = 5;
    const OP_MEMBER_DECORATE: u32 = 72;
    const DECORATION_OFFSET: u32 = 35;
    let mut id = None;
    let mut offsets: Vec<(u32, u32)> = Vec::new();
    let mut i = 5;
    let mut pending: Vec<(u32, u32, u32)> = Vec::new();
    while i < words.len() {
        let count = (words[i] >> 16) as usize;
        let op = words[i] & 0xffff;
        if count == 0 || i + count > words.len() {
            return None;
        }
        let ins = &words[i..i + count];
        if op == OP_NAME && count >= 3 {
            let bytes: Vec<u8> = ins[2..].iter().flat_map(|w| w.to_le_bytes()).collect();
            let name: String = bytes
                .iter()
                .take_while(|&&b| b != 0)
                .map(|&b| b as char)
                .collect();
            if name == struct_name {
                id = Some(ins[1]);
            }
        } else if op == OP_MEMBER_DECORATE && count >= 5 && ins[3] == DECORATION_OFFSET {
            pending.push((ins[1], ins[2], ins[4]));
        }
        i += count;
    }
    let id = id?;
    for (target, member, offset) in pending {
        if target == id {
            offsets.push((member, offset));
        }
    }
    offsets.sort();
    Some(offsets.into_iter().map(|(_, o)| o).collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_block_matches_spirv_layout() {
        for (name, words) in [
            ("mesh+frag", crate::shaders::SHADE_FRAG),
            ("tri.tesc", crate::shaders::TRI_TESC),
        ] {
            let offsets = spirv_member_offsets(words, "Frame")
                .unwrap_or_else(|| panic!("{name}: Frame block not found"));
            assert_eq!(
                offsets, FRAME_UNIFORM_OFFSETS,
                "{name}: GLSL and Rust Frame layouts differ"
            );
        }
    }

    #[test]
    fn draw_push_matches_spirv_layout() {
        // Only the capture builds read first_patch (the optimizer drops the block elsewhere).
        for (name, words) in [
            ("flat_tri.tese", crate::shaders::FLAT_TRI_TESE_EQUAL_CAPTURE),
            (
                "flat_quad.tese",
                crate::shaders::FLAT_QUAD_TESE_EQUAL_CAPTURE,
            ),
            (
                "phong.tese",
                crate::shaders::PHONG_TESE_FRACTIONAL_ODD_CAPTURE,
            ),
            ("pn.tese", crate::shaders::PN_TESE_FRACTIONAL_EVEN_CAPTURE),
        ] {
            let offsets = spirv_member_offsets(words, "Draw")
                .unwrap_or_else(|| panic!("{name}: Draw block not found"));
            assert_eq!(
                offsets, DRAW_PUSH_OFFSETS,
                "{name}: GLSL and Rust Draw layouts differ"
            );
        }
    }

    #[test]
    fn spirv_reader_rejects_missing_struct() {
        assert!(spirv_member_offsets(crate::shaders::SHADE_FRAG, "NoSuchBlock").is_none());
    }
}
