//! Every block shared with GLSL, held against the compiled SPIR-V: one table of (stage and
//! variant, what to read, what the Rust side says). glslang's optimizer drops blocks a stage
//! does not use, so each row names a build where its block is live; a row whose block is
//! missing fails.
use super::bindings::*;
use super::reflect::Reflection;
use super::{
    AdaptiveArrays, AdaptivePush, BftPush, BftTableArrays, CaptureRecord, DooSabinArrays, DrawPush,
    FrameUniforms, StencilPush, Vertex, VertexPatchArrays, VertexPatchRecord, VertexPatchStep,
};
use crate::shaders::{spirv, Stage, Variant};
use crate::stencil::{StencilTerm, StencilVertex};
use crate::techniques::bft::layout::{
    Level1Point, PatchHeader, TableEntry, TableHeader, TangentTerm, STORAGE_BINDINGS,
};
use crate::techniques::planned_patches::layout::{
    CurveOwner, PatchRecord, PatchSurface, ReparamRow,
};
use crate::tessellator::Spacing;
use std::mem::{offset_of, size_of};
use vk_core::vk;

/// Member offsets of a Rust struct, in declaration order.
macro_rules! offsets {
    ($ty:ty: $($field:ident),+) => {
        vec![$(offset_of!($ty, $field) as u32),+]
    };
}

/// What one row checks.
enum Check {
    /// A uniform or push-constant block, or a struct: member offsets and size.
    Layout {
        name: &'static str,
        offsets: Vec<u32>,
        size: usize,
    },
    /// A storage buffer: set and binding of the block, its members' offsets, and the stride of
    /// the runtime array that ends it.
    Buffer {
        block: &'static str,
        binding: u32,
        members: Vec<u32>,
        stride: usize,
    },
    /// A buffer-reference block (read by device address): no set or binding, its members'
    /// offsets, and the stride of the runtime array that ends it.
    Referenced {
        block: &'static str,
        members: Vec<u32>,
        stride: usize,
    },
    /// An array member of a struct: its stride.
    MemberArray {
        name: &'static str,
        member: u32,
        stride: usize,
    },
    /// A uniform block's set and binding.
    Uniform {
        block: &'static str,
        set: u32,
        binding: u32,
    },
    /// The transform-feedback outputs: (output name, offset), buffer, stride.
    Xfb {
        outputs: Vec<(&'static str, u32)>,
        buffer: u32,
        stride: usize,
    },
    /// A vertex input: (input name, location, byte size) against the attribute with that
    /// location in [`Vertex::ATTRIBUTES`] and the Rust field's offset and size.
    Input {
        name: &'static str,
        offset: usize,
        size: usize,
    },
    /// A refinement-pattern vertex input (`common/pattern_in.glsl`): the attribute at the
    /// input's location in `input` reads 12 bytes from `binding` at `offset`, and the input
    /// is a vec3.
    PatternInput {
        name: &'static str,
        input: crate::technique::VertexInput,
        binding: u32,
        offset: usize,
    },
}

fn variant(spacing: Option<Spacing>, capture: bool) -> Variant {
    Variant {
        spacing,
        capture,
        surface: false,
        patch_block: false,
        scalar_tags: false,
        face_varying: false,
        geomorph: false,
    }
}

const PLAIN: Variant = Variant {
    spacing: None,
    capture: false,
    surface: false,
    patch_block: false,
    scalar_tags: false,
    face_varying: false,
    geomorph: false,
};

/// BFT's patch-block build (its control stage reads the ring and level-1 buffers too).
const BLOCK: Variant = Variant {
    patch_block: true,
    ..PLAIN
};

/// The refinement-pattern vertex stages: the frame block, and every input against
/// [`super::pattern_input`] (the domain point per vertex, each corner's position and normal
/// per instance).
fn pattern_input_rows() -> Vec<(Stage, Variant, Check)> {
    use super::pattern_input::{QUAD, TRIANGLE};
    let corner = size_of::<Vertex>();
    let mut out = Vec::new();
    for (stage, input, corners) in [
        (Stage::FlatPatternTriVert, TRIANGLE, 3),
        (Stage::FlatPatternQuadVert, QUAD, 4),
        (Stage::PhongPatternTriVert, TRIANGLE, 3),
        (Stage::PnPatternTriVert, TRIANGLE, 3),
    ] {
        let frame = Check::Uniform {
            block: "Frame",
            set: FRAME_SET,
            binding: FRAME_UNIFORMS_BINDING,
        };
        out.push((stage, PLAIN, frame));
        let at = |name, binding, offset| Check::PatternInput {
            name,
            input,
            binding,
            offset,
        };
        out.push((stage, PLAIN, at("in_domain", 0, 0)));
        const POSITIONS: [&str; 4] = ["in_p0", "in_p1", "in_p2", "in_p3"];
        const NORMALS: [&str; 4] = ["in_n0", "in_n1", "in_n2", "in_n3"];
        for i in 0..corners {
            out.push((stage, PLAIN, at(POSITIONS[i], 1, i * corner)));
            out.push((stage, PLAIN, at(NORMALS[i], 1, i * corner + 12)));
        }
    }
    out
}

/// The scalar-tagged PN stages' inputs: the pattern vertex stage's tagged corners against
/// [`super::pattern_input::TAGGED_TRIANGLE`] (with the untagged corners still where
/// [`super::pattern_input::TRIANGLE`] has them), and the tessellation path's vertex stage
/// against [`super::TaggedCorner::MESH`].
fn tagged_input_rows() -> Vec<(Stage, Variant, Check)> {
    use super::pattern_input::TAGGED_TRIANGLE;
    let tagged = Variant {
        scalar_tags: true,
        ..PLAIN
    };
    let corner = size_of::<Vertex>();
    let tag = size_of::<super::TaggedCorner>();
    let at = |name, input, binding, offset| Check::PatternInput {
        name,
        input,
        binding,
        offset,
    };
    let stage = Stage::PnPatternTriVert;
    let mut out = vec![(stage, tagged, at("in_domain", TAGGED_TRIANGLE, 0, 0))];
    const NEXT: [&str; 3] = ["in_bn0", "in_bn1", "in_bn2"];
    const PREV: [&str; 3] = ["in_bp0", "in_bp1", "in_bp2"];
    const POSITIONS: [&str; 3] = ["in_p0", "in_p1", "in_p2"];
    for i in 0..3 {
        out.push((
            stage,
            tagged,
            at(POSITIONS[i], TAGGED_TRIANGLE, 1, i * corner),
        ));
        out.push((stage, tagged, at(NEXT[i], TAGGED_TRIANGLE, 2, i * tag)));
        out.push((stage, tagged, at(PREV[i], TAGGED_TRIANGLE, 2, i * tag + 16)));
    }
    let mesh = super::TaggedCorner::MESH;
    let stage = Stage::PnTaggedMeshVert;
    out.push((stage, PLAIN, at("in_position", mesh, 0, 0)));
    out.push((stage, PLAIN, at("in_normal", mesh, 0, 12)));
    out.push((stage, PLAIN, at("in_b_next", mesh, 1, 0)));
    out.push((stage, PLAIN, at("in_b_prev", mesh, 1, 16)));
    out
}

/// The table. Each BFT storage buffer appears with a stage that reads or writes it.
fn rows() -> Vec<(Stage, Variant, Check)> {
    use Check::*;
    let equal = Some(Spacing::Equal);
    let frame = || Layout {
        name: "Frame",
        offsets: offsets!(FrameUniforms: view_proj, view, camera_pos, light_dir, tess, base_color, wire_color, viewport, sine),
        size: size_of::<FrameUniforms>(),
    };
    let draw = || Layout {
        name: "Draw",
        offsets: offsets!(DrawPush: mode, first_patch),
        size: size_of::<DrawPush>(),
    };
    let bft_push = || Layout {
        name: "BftPush",
        offsets: offsets!(BftPush: mode, first_patch, factor_mode, options, uniform_level, pixels_per_segment, distance_ref, max_level, count, first_vertex, patch_base, ring_base, level1_base, tangent_base, pad, pattern_outer),
        size: size_of::<BftPush>(),
    };
    let frame_binding = || Uniform {
        block: "Frame",
        set: FRAME_SET,
        binding: FRAME_UNIFORMS_BINDING,
    };
    let capture = || Xfb {
        outputs: vec![
            ("out_world", offset_of!(CaptureRecord, position) as u32),
            ("out_normal", offset_of!(CaptureRecord, normal) as u32),
            ("out_patch_flags", offset_of!(CaptureRecord, patch) as u32),
            ("out_domain", offset_of!(CaptureRecord, domain) as u32),
        ],
        buffer: CAPTURE_XFB_BUFFER,
        stride: size_of::<CaptureRecord>(),
    };
    let level1 = |block, binding| Buffer {
        block,
        binding,
        members: vec![0],
        stride: size_of::<Level1Point>(),
    };
    let words = |block, binding| Buffer {
        block,
        binding,
        members: vec![0],
        stride: size_of::<u32>(),
    };
    let mut rows = vec![
        (Stage::CommonShadeFrag, PLAIN, frame()),
        (Stage::CommonShadeFrag, PLAIN, frame_binding()),
        (Stage::CommonShadeFrag, PLAIN, draw()),
        (Stage::CommonTriTesc, PLAIN, frame()),
        (Stage::CommonQuadTesc, PLAIN, frame_binding()),
        (Stage::CpuMeshVert, PLAIN, frame()),
        (Stage::BftBftTesc, PLAIN, frame()),
        (Stage::BftBftTesc, PLAIN, frame_binding()),
        (Stage::BftBftTesc, PLAIN, bft_push()),
        (Stage::BftBftTese, variant(equal, false), bft_push()),
        (
            Stage::BftBftTese,
            Variant {
                surface: true,
                ..variant(equal, false)
            },
            bft_push(),
        ),
        (Stage::BftBftFrag, PLAIN, bft_push()),
        (
            Stage::BftBftFrag,
            Variant {
                surface: true,
                ..PLAIN
            },
            bft_push(),
        ),
        (Stage::BftNormalsComp, PLAIN, bft_push()),
        // BFT's refinement-pattern vertex stage: its push constant (the geomorphing build
        // reads the pattern's edge levels), the pattern's domain point and the instance's face
        // and morph weights.
        (Stage::BftPatternVert, PLAIN, bft_push()),
        (
            Stage::BftPatternVert,
            Variant {
                geomorph: true,
                ..PLAIN
            },
            bft_push(),
        ),
        (Stage::BftPatternVert, PLAIN, frame_binding()),
        (
            Stage::BftPatternVert,
            PLAIN,
            PatternInput {
                name: "in_domain",
                input: super::pattern_input::PATCH_IDS,
                binding: 0,
                offset: 0,
            },
        ),
        (
            Stage::BftPatternVert,
            PLAIN,
            PatternInput {
                name: "in_patch",
                input: super::pattern_input::PATCH_IDS,
                binding: 1,
                offset: 0,
            },
        ),
        // Vertex input.
        (
            Stage::CommonMeshVert,
            PLAIN,
            Input {
                name: "in_position",
                offset: offset_of!(Vertex, position),
                size: size_of::<[f32; 3]>(),
            },
        ),
        (
            Stage::CommonMeshVert,
            PLAIN,
            Input {
                name: "in_normal",
                offset: offset_of!(Vertex, normal),
                size: size_of::<[f32; 3]>(),
            },
        ),
        (
            Stage::CpuMeshVert,
            PLAIN,
            Input {
                name: "in_position",
                offset: offset_of!(Vertex, position),
                size: size_of::<[f32; 3]>(),
            },
        ),
        (
            Stage::CpuMeshVert,
            PLAIN,
            Input {
                name: "in_normal",
                offset: offset_of!(Vertex, normal),
                size: size_of::<[f32; 3]>(),
            },
        ),
        // Doo-Sabin's vertex stage: the deepest level's points and their face corners.
        // (The refinement-pattern vertex stages' inputs are appended below.)
        (Stage::DooSabinMeshVert, PLAIN, frame()),
        (
            Stage::DooSabinMeshVert,
            PLAIN,
            Layout {
                name: "DooSabinArrays",
                offsets: offsets!(DooSabinArrays: points, corners),
                size: size_of::<DooSabinArrays>(),
            },
        ),
        (
            Stage::DooSabinMeshVert,
            PLAIN,
            Uniform {
                block: "DooSabinArrays",
                set: DOO_SABIN_SET,
                binding: DOO_SABIN_ARRAYS_BINDING,
            },
        ),
        (
            Stage::DooSabinMeshVert,
            PLAIN,
            Referenced {
                block: "DooSabinPointArray",
                members: vec![0],
                stride: size_of::<StencilVertex>(),
            },
        ),
        (
            Stage::DooSabinMeshVert,
            PLAIN,
            Referenced {
                block: "DooSabinCornerArray",
                members: vec![0],
                stride: size_of::<[u32; 2]>(),
            },
        ),
        // The vertex patches: the refinement kernel's push constant, record and arrays; the
        // vertex stage's addresses, points and face corners.
        (
            Stage::VertexPatchesRefineComp,
            PLAIN,
            Layout {
                name: "VertexPatchStep",
                offsets: offsets!(VertexPatchStep: points, flags, records, sizes, weights, weight_starts, patch_count, items, first_item, depth),
                size: size_of::<VertexPatchStep>(),
            },
        ),
        (
            Stage::VertexPatchesRefineComp,
            PLAIN,
            Layout {
                name: "VertexPatchRecord",
                offsets: offsets!(VertexPatchRecord: valence, sizes, source, destination, first_item),
                size: size_of::<VertexPatchRecord>(),
            },
        ),
        (
            Stage::VertexPatchesRefineComp,
            PLAIN,
            Referenced {
                block: "VertexPatchRecords",
                members: vec![0],
                stride: size_of::<VertexPatchRecord>(),
            },
        ),
        (
            Stage::VertexPatchesRefineComp,
            PLAIN,
            Referenced {
                block: "VertexPatchPoints",
                members: vec![0],
                stride: size_of::<StencilVertex>(),
            },
        ),
        (
            Stage::VertexPatchesRefineComp,
            PLAIN,
            Referenced {
                block: "VertexPatchFlags",
                members: vec![0],
                stride: size_of::<u32>(),
            },
        ),
        (
            Stage::VertexPatchesRefineComp,
            PLAIN,
            Referenced {
                block: "VertexPatchWords",
                members: vec![0],
                stride: size_of::<u32>(),
            },
        ),
        (
            Stage::VertexPatchesRefineComp,
            PLAIN,
            Referenced {
                block: "VertexPatchWeights",
                members: vec![0],
                stride: size_of::<f32>(),
            },
        ),
        (Stage::VertexPatchesMeshVert, PLAIN, frame()),
        (
            Stage::VertexPatchesMeshVert,
            PLAIN,
            Layout {
                name: "VertexPatchArrays",
                offsets: offsets!(VertexPatchArrays: points, corners),
                size: size_of::<VertexPatchArrays>(),
            },
        ),
        (
            Stage::VertexPatchesMeshVert,
            PLAIN,
            Uniform {
                block: "VertexPatchArrays",
                set: VERTEX_PATCHES_SET,
                binding: VERTEX_PATCHES_ARRAYS_BINDING,
            },
        ),
        (
            Stage::VertexPatchesMeshVert,
            PLAIN,
            Referenced {
                block: "VertexPatchPointArray",
                members: vec![0],
                stride: size_of::<StencilVertex>(),
            },
        ),
        (
            Stage::VertexPatchesMeshVert,
            PLAIN,
            Referenced {
                block: "VertexPatchCornerArray",
                members: vec![0],
                stride: size_of::<[u32; 2]>(),
            },
        ),
        // The stencil evaluator: its push constant, its term and its four buffers.
        (
            Stage::StencilEvaluateComp,
            PLAIN,
            Layout {
                name: "StencilPush",
                offsets: offsets!(StencilPush: first_row, count, row_base, term_base, source_base, destination_first),
                size: size_of::<StencilPush>(),
            },
        ),
        (
            Stage::StencilEvaluateComp,
            PLAIN,
            words("StencilOffsets", STENCIL_OFFSETS_BINDING),
        ),
        (
            Stage::StencilEvaluateComp,
            PLAIN,
            Buffer {
                block: "StencilTerms",
                binding: STENCIL_TERMS_BINDING,
                members: vec![0],
                stride: size_of::<StencilTerm>(),
            },
        ),
        (
            Stage::StencilEvaluateComp,
            PLAIN,
            Layout {
                name: "StencilTerm",
                offsets: offsets!(StencilTerm: index, weight),
                size: size_of::<StencilTerm>(),
            },
        ),
        (
            Stage::StencilEvaluateComp,
            PLAIN,
            Buffer {
                block: "StencilSource",
                binding: STENCIL_SOURCE_BINDING,
                members: vec![0],
                stride: size_of::<StencilVertex>(),
            },
        ),
        (
            Stage::StencilEvaluateComp,
            PLAIN,
            Buffer {
                block: "StencilDestination",
                binding: STENCIL_DESTINATION_BINDING,
                members: vec![0],
                stride: size_of::<StencilVertex>(),
            },
        ),
        // BFT storage buffers: the normals pass.
        (
            Stage::BftNormalsComp,
            PLAIN,
            words("TangentOffsets", BFT_TANGENT_OFFSETS_BINDING),
        ),
        (
            Stage::BftNormalsComp,
            PLAIN,
            Buffer {
                block: "TangentTerms",
                binding: BFT_TANGENT_TERMS_BINDING,
                members: vec![0],
                stride: size_of::<TangentTerm>(),
            },
        ),
        (
            Stage::BftNormalsComp,
            PLAIN,
            Layout {
                name: "TangentTerm",
                offsets: offsets!(TangentTerm: index, weight_t1, weight_t2),
                size: size_of::<TangentTerm>(),
            },
        ),
        (
            Stage::BftNormalsComp,
            PLAIN,
            level1("Level1Positions", BFT_LEVEL1_POSITIONS_BINDING),
        ),
        (
            Stage::BftNormalsComp,
            PLAIN,
            level1("Level1Normals", BFT_LEVEL1_NORMALS_BINDING),
        ),
        // BFT storage buffers: the main pass.
        (
            Stage::BftBftTesc,
            PLAIN,
            level1("Level1Positions", BFT_LEVEL1_POSITIONS_BINDING),
        ),
        (
            Stage::BftBftTesc,
            BLOCK,
            level1("Level1Normals", BFT_LEVEL1_NORMALS_BINDING),
        ),
        (
            Stage::BftBftTesc,
            PLAIN,
            words("PatchRings", BFT_PATCH_RINGS_BINDING),
        ),
        (
            Stage::BftBftTese,
            variant(equal, false),
            level1("Level1Normals", BFT_LEVEL1_NORMALS_BINDING),
        ),
    ];
    for (stage, v) in [
        (Stage::BftBftTesc, PLAIN),
        (Stage::BftBftTesc, BLOCK),
        (Stage::BftBftTese, variant(equal, false)),
        (
            Stage::BftBftTese,
            Variant {
                patch_block: true,
                ..variant(equal, false)
            },
        ),
        (
            Stage::BftBftTese,
            variant(Some(Spacing::FractionalEven), true),
        ),
    ] {
        rows.push((
            stage,
            v,
            Buffer {
                block: "PatchHeaders",
                binding: BFT_PATCH_HEADERS_BINDING,
                members: vec![0],
                stride: size_of::<PatchHeader>(),
            },
        ));
        rows.push((
            stage,
            v,
            Layout {
                name: "PatchHeader",
                offsets: offsets!(PatchHeader: ring_offset, ring_size, entry, mirrored, edge_owner, corner_owner),
                size: size_of::<PatchHeader>(),
            },
        ));
        for member in [4, 5] {
            rows.push((
                stage,
                v,
                MemberArray {
                    name: "PatchHeader",
                    member,
                    stride: size_of::<u32>(),
                },
            ));
        }
    }
    for v in [
        variant(equal, false),
        variant(Some(Spacing::FractionalOdd), true),
    ] {
        let tese = Stage::BftBftTese;
        rows.extend([
            (tese, v, words("PatchRings", BFT_PATCH_RINGS_BINDING)),
            (
                tese,
                v,
                Layout {
                    name: "BftTableArrays",
                    offsets: offsets!(BftTableArrays: tables, perms, maps, weights),
                    size: size_of::<BftTableArrays>(),
                },
            ),
            (
                tese,
                v,
                Uniform {
                    block: "BftTableArrays",
                    set: BFT_SET,
                    binding: BFT_TABLE_ARRAYS_BINDING,
                },
            ),
            (
                tese,
                v,
                Referenced {
                    block: "Tables",
                    members: vec![0, size_of::<TableHeader>() as u32],
                    stride: size_of::<TableEntry>(),
                },
            ),
            (
                tese,
                v,
                Layout {
                    name: "TableHeader",
                    offsets: offsets!(TableHeader: level, segments, grid, entry_count, full_map_offset, half_map_offset),
                    size: size_of::<TableHeader>(),
                },
            ),
            (
                tese,
                v,
                Layout {
                    name: "TableEntry",
                    offsets: offsets!(TableEntry: ring_size, half_table, rows, position_offset, du_offset, dv_offset, perm_offset, kind),
                    size: size_of::<TableEntry>(),
                },
            ),
            (
                tese,
                v,
                Referenced {
                    block: "MirrorPerms",
                    members: vec![0],
                    stride: size_of::<u32>(),
                },
            ),
            (
                tese,
                v,
                Referenced {
                    block: "RowMaps",
                    members: vec![0],
                    stride: size_of::<u32>(),
                },
            ),
            (
                tese,
                v,
                Referenced {
                    block: "TableWeights",
                    members: vec![0],
                    stride: size_of::<f32>(),
                },
            ),
            (
                tese,
                v,
                level1("Level1Positions", BFT_LEVEL1_POSITIONS_BINDING),
            ),
        ]);
    }
    // Feature-adaptive Catmull-Clark: push constants, the stencil kernel's buffers, the
    // patch records, control points and curves.
    let adaptive_push = || Layout {
        name: "AdaptivePush",
        offsets: offsets!(AdaptivePush: mode, first_patch, factor_mode, options, uniform_level, pixels_per_segment, distance_ref, max_level, first_item, count, displace_scale, first_corner, pattern_outer),
        size: size_of::<AdaptivePush>(),
    };
    let adaptive_arrays = || Layout {
        name: "AdaptiveArrays",
        offsets: offsets!(AdaptiveArrays: vertices, patches, control_points, curves, surfaces, reparam, curve_owners, corner_owners, param_errors, param_error_count, fvar_count, fvar),
        size: size_of::<AdaptiveArrays>(),
    };
    let adaptive_arrays_binding = || Uniform {
        block: "AdaptiveArrays",
        set: ADAPTIVE_SET,
        binding: ADAPTIVE_ARRAYS_BINDING,
    };
    let referenced = |block, stride| Referenced {
        block,
        members: vec![0],
        stride,
    };
    let surface_tese = Variant {
        surface: true,
        ..variant(equal, false)
    };
    let face_varying_tese = Variant {
        face_varying: true,
        ..surface_tese
    };
    let adaptive_tese = [
        Stage::AdaptiveRegularTese,
        Stage::AdaptiveGregoryTese,
        Stage::AdaptiveBilinearTese,
        Stage::AdaptiveTriangleTese,
    ];
    // The evaluation stages' code as the pattern path's vertex stages.
    let adaptive_pattern = [
        Stage::AdaptivePatternRegularVert,
        Stage::AdaptivePatternGregoryVert,
        Stage::AdaptivePatternBilinearVert,
        Stage::AdaptivePatternTriangleVert,
    ];
    rows.extend([
        (Stage::AdaptiveCanonicalComp, PLAIN, adaptive_push()),
        (Stage::AdaptivePatchVert, PLAIN, adaptive_push()),
        (Stage::AdaptivePatchTesc, PLAIN, adaptive_push()),
        (Stage::AdaptiveRegularTesc, PLAIN, adaptive_push()),
        (Stage::AdaptiveGregoryTesc, PLAIN, adaptive_push()),
        (Stage::AdaptiveTriangleTesc, PLAIN, adaptive_push()),
        (Stage::AdaptiveAdaptiveFrag, PLAIN, adaptive_push()),
        (Stage::AdaptiveCanonicalComp, PLAIN, adaptive_arrays()),
        (
            Stage::AdaptiveCanonicalComp,
            PLAIN,
            adaptive_arrays_binding(),
        ),
        (Stage::AdaptiveRegularTesc, PLAIN, adaptive_arrays()),
        (
            Stage::AdaptiveCanonicalComp,
            PLAIN,
            referenced("VertexArray", size_of::<[f32; 4]>()),
        ),
        (
            Stage::AdaptivePatchTesc,
            PLAIN,
            referenced("VertexArray", size_of::<[f32; 4]>()),
        ),
        (
            Stage::AdaptiveRegularTesc,
            PLAIN,
            referenced("PatchArray", size_of::<PatchRecord>()),
        ),
        (
            Stage::AdaptiveRegularTesc,
            PLAIN,
            Layout {
                name: "AdaptivePatch",
                offsets: offsets!(PatchRecord: cp_offset, info, edge_info, pad, curves),
                size: size_of::<PatchRecord>(),
            },
        ),
        (
            Stage::AdaptiveRegularTesc,
            PLAIN,
            MemberArray {
                name: "AdaptivePatch",
                member: 4,
                stride: size_of::<u32>(),
            },
        ),
        (
            Stage::AdaptiveGregoryTesc,
            PLAIN,
            referenced("ControlPointArray", size_of::<u32>()),
        ),
        (
            Stage::AdaptivePatchTesc,
            PLAIN,
            referenced("CurveArray", size_of::<[u32; 4]>()),
        ),
        (
            Stage::AdaptiveCanonicalComp,
            PLAIN,
            referenced("CurveOwnerArray", size_of::<CurveOwner>()),
        ),
        (
            Stage::AdaptiveCanonicalComp,
            PLAIN,
            referenced("CornerOwnerArray", size_of::<[u32; 2]>()),
        ),
        (
            Stage::AdaptiveRegularTese,
            surface_tese,
            Layout {
                name: "CurveOwner",
                offsets: offsets!(CurveOwner: patch, info),
                size: size_of::<CurveOwner>(),
            },
        ),
        (
            Stage::AdaptiveRegularTese,
            surface_tese,
            referenced("SurfaceArray", size_of::<PatchSurface>()),
        ),
        (
            Stage::AdaptiveRegularTese,
            surface_tese,
            referenced("ReparamArray", size_of::<ReparamRow>()),
        ),
        (
            Stage::AdaptiveRegularTese,
            surface_tese,
            referenced("ParamErrorArray", size_of::<f32>()),
        ),
        (
            Stage::AdaptiveRegularTese,
            face_varying_tese,
            referenced("FVarArray", size_of::<u32>()),
        ),
        (
            Stage::AdaptiveRegularTese,
            surface_tese,
            Layout {
                name: "PatchSurface",
                offsets: offsets!(PatchSurface: uv, reparam_rows, tangent_valences, fvar_root, pad),
                size: size_of::<PatchSurface>(),
            },
        ),
        (Stage::AdaptiveRegularTese, surface_tese, adaptive_arrays()),
        (
            Stage::AdaptiveRegularTese,
            surface_tese,
            adaptive_arrays_binding(),
        ),
    ]);
    for stage in adaptive_tese {
        for spacing in [Spacing::Equal, Spacing::FractionalEven] {
            for surface in [false, true] {
                let v = Variant {
                    surface,
                    ..variant(Some(spacing), false)
                };
                rows.push((stage, v, adaptive_push()));
            }
        }
    }
    // The capture record and the push constant of every capture build (the optimizer keeps
    // `draw` only where the patch id is written).
    for stage in Stage::ALL {
        for &(v, _) in stage.compiled() {
            if v.capture {
                rows.push((stage, v, capture()));
                if adaptive_tese.contains(&stage) || adaptive_pattern.contains(&stage) {
                    rows.push((stage, v, adaptive_push()));
                } else if [Stage::BftBftTese, Stage::BftPatternVert].contains(&stage) {
                    rows.push((stage, v, bft_push()));
                } else {
                    rows.push((stage, v, draw()));
                }
            }
        }
    }
    for stage in adaptive_pattern {
        for surface in [false, true] {
            let v = Variant { surface, ..PLAIN };
            rows.push((stage, v, adaptive_push()));
            rows.push((stage, v, adaptive_arrays_binding()));
        }
        let input = super::pattern_input::PATCH_IDS;
        let at = |name, binding| Check::PatternInput {
            name,
            input,
            binding,
            offset: 0,
        };
        rows.push((stage, PLAIN, at("in_domain", 0)));
        rows.push((stage, PLAIN, at("in_patch", 1)));
    }
    rows.extend(pattern_input_rows());
    rows.extend(tagged_input_rows());
    rows
}

/// The set a stage's storage buffers live in: its technique's, or the stencil evaluator's.
fn technique_set(stage: Stage) -> u32 {
    if stage.path().starts_with("adaptive/") {
        ADAPTIVE_SET
    } else if stage.path().starts_with("stencil/") {
        STENCIL_SET
    } else {
        BFT_SET
    }
}

fn check(stage: Stage, v: Variant, check: &Check) -> Result<(), String> {
    let words = spirv(stage, v).map_err(|e| e.to_string())?;
    let r = Reflection::new(words).map_err(|e| e.to_string())?;
    match check {
        Check::Layout {
            name,
            offsets,
            size,
        } => {
            let found = r.member_offsets(name);
            if found.is_empty() {
                return Err(format!("{name}: no laid-out struct"));
            }
            if found.iter().any(|f| f != offsets) {
                return Err(format!(
                    "{name}: SPIR-V offsets {found:?}, Rust {offsets:?}"
                ));
            }
            match r.struct_size(name) {
                Some(s) if s as usize == *size => Ok(()),
                s => Err(format!("{name}: SPIR-V size {s:?}, Rust {size}")),
            }
        }
        Check::Buffer {
            block,
            binding,
            members,
            stride,
        } => {
            let b = r
                .binding(block)
                .ok_or_else(|| format!("{block}: no bound block"))?;
            let set = technique_set(stage);
            if (b.set, b.binding) != (set, *binding) {
                return Err(format!(
                    "{block}: set {} binding {}, Rust set {set} binding {binding}",
                    b.set, b.binding
                ));
            }
            let found = r.member_offsets(block);
            if found != [members.clone()] {
                return Err(format!(
                    "{block}: member offsets {found:?}, Rust {members:?}"
                ));
            }
            match r.runtime_array_stride(block) {
                Some(s) if s as usize == *stride => Ok(()),
                s => Err(format!("{block}: array stride {s:?}, Rust {stride}")),
            }
        }
        Check::Referenced {
            block,
            members,
            stride,
        } => {
            if let Some(b) = r.binding(block) {
                return Err(format!("{block}: bound at {b:?}, not read by address"));
            }
            let found = r.member_offsets(block);
            if found.is_empty() || found.iter().any(|f| f != members) {
                return Err(format!(
                    "{block}: member offsets {found:?}, Rust {members:?}"
                ));
            }
            match r.runtime_array_stride(block) {
                Some(s) if s as usize == *stride => Ok(()),
                s => Err(format!("{block}: array stride {s:?}, Rust {stride}")),
            }
        }
        Check::MemberArray {
            name,
            member,
            stride,
        } => match r.member_array_stride(name, *member) {
            Some(s) if s as usize == *stride => Ok(()),
            s => Err(format!(
                "{name}.{member}: array stride {s:?}, Rust {stride}"
            )),
        },
        Check::Uniform {
            block,
            set,
            binding,
        } => match r.binding(block) {
            Some(b) if (b.set, b.binding) == (*set, *binding) => Ok(()),
            b => Err(format!("{block}: {b:?}, Rust set {set} binding {binding}")),
        },
        Check::Xfb {
            outputs,
            buffer,
            stride,
        } => {
            let found = r.xfb_outputs();
            let got: Vec<(&str, u32)> = found.iter().map(|o| (o.name.as_str(), o.offset)).collect();
            if got != *outputs {
                return Err(format!("xfb outputs {got:?}, Rust {outputs:?}"));
            }
            if let Some(o) = found
                .iter()
                .find(|o| o.buffer != *buffer || o.stride as usize != *stride)
            {
                return Err(format!(
                    "{}: xfb buffer {} stride {}, Rust buffer {buffer} stride {stride}",
                    o.name, o.buffer, o.stride
                ));
            }
            Ok(())
        }
        Check::Input { name, offset, size } => {
            let (location, bytes) = r.input(name).ok_or_else(|| format!("no input {name}"))?;
            let attr = Vertex::ATTRIBUTES
                .iter()
                .find(|a| a.location == location)
                .ok_or_else(|| format!("{name}: location {location} has no vertex attribute"))?;
            // Every attribute is R32G32B32_SFLOAT: 12 bytes.
            if attr.offset as usize != *offset || bytes as usize != *size || *size != 12 {
                return Err(format!(
                    "{name}: attribute offset {} input {bytes} bytes, Rust field at {offset} of {size} bytes",
                    attr.offset
                ));
            }
            Ok(())
        }
        Check::PatternInput {
            name,
            input,
            binding,
            offset,
        } => {
            let (location, bytes) = r.input(name).ok_or_else(|| format!("no input {name}"))?;
            let attr = input
                .attributes
                .iter()
                .find(|a| a.location == location)
                .ok_or_else(|| format!("{name}: location {location} has no vertex attribute"))?;
            let size = match attr.format {
                vk::Format::R32G32B32A32_SFLOAT | vk::Format::R32G32B32A32_UINT => 16,
                vk::Format::R32_UINT => 4,
                _ => 12,
            };
            if attr.binding != *binding || attr.offset as usize != *offset || bytes != size {
                return Err(format!(
                    "{name}: attribute at binding {} offset {} of {size} bytes, input {bytes} bytes; expected binding {binding} offset {offset}",
                    attr.binding, attr.offset
                ));
            }
            Ok(())
        }
    }
}

#[test]
fn every_gpu_block_matches_its_rust_mirror() {
    let failures: Vec<String> = rows()
        .iter()
        .filter_map(|(stage, v, c)| {
            check(*stage, *v, c)
                .err()
                .map(|e| format!("{} {v:?}: {e}", stage.path()))
        })
        .collect();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn the_table_covers_every_storage_binding_and_capture_build() {
    let rows = rows();
    for binding in STORAGE_BINDINGS {
        assert!(
            rows.iter()
                .any(|(_, _, c)| matches!(c, Check::Buffer { binding: b, .. } if *b == binding)),
            "BFT binding {binding} is not checked"
        );
    }
    for block in ["Tables", "MirrorPerms", "RowMaps", "TableWeights"] {
        assert!(
            rows.iter().any(|(s, _, c)| *s == Stage::BftBftTese
                && matches!(c, Check::Referenced { block: b, .. } if *b == block)),
            "BFT table array {block} is not checked"
        );
    }
    for binding in [
        STENCIL_OFFSETS_BINDING,
        STENCIL_TERMS_BINDING,
        STENCIL_SOURCE_BINDING,
        STENCIL_DESTINATION_BINDING,
    ] {
        assert!(
            rows.iter().any(|(s, _, c)| *s == Stage::StencilEvaluateComp
                && matches!(c, Check::Buffer { binding: b, .. } if *b == binding)),
            "stencil binding {binding} is not checked"
        );
    }
    for block in [
        "VertexArray",
        "PatchArray",
        "ControlPointArray",
        "CurveArray",
        "SurfaceArray",
        "ReparamArray",
        "CurveOwnerArray",
        "CornerOwnerArray",
        "ParamErrorArray",
        "FVarArray",
    ] {
        assert!(
            rows.iter()
                .any(|(s, _, c)| format!("{s:?}").starts_with("Adaptive")
                    && matches!(c, Check::Referenced { block: b, .. } if *b == block)),
            "adaptive array {block} is not checked"
        );
    }
    for block in ["DooSabinPointArray", "DooSabinCornerArray"] {
        assert!(
            rows.iter().any(|(s, _, c)| *s == Stage::DooSabinMeshVert
                && matches!(c, Check::Referenced { block: b, .. } if *b == block)),
            "Doo-Sabin array {block} is not checked"
        );
    }
    let capture_builds = Stage::ALL
        .iter()
        .flat_map(|s| s.compiled())
        .filter(|(v, _)| v.capture)
        .count();
    let xfb_rows = rows
        .iter()
        .filter(|(_, _, c)| matches!(c, Check::Xfb { .. }))
        .count();
    // Nine TESs in three spacings, the four adaptive ones and BFT's also with their surface code,
    // the adaptive ones also in their face-varying build, BFT's also with and without its patch
    // block; the CPU mesh's, Doo-Sabin's and the vertex patches' vertex stages, the four refinement-pattern vertex
    // stages, PN's also in its scalar-tagged build, BFT's with and without its surface code and
    // its geomorphing build, and the four adaptive pattern vertex stages with and without their
    // surface and face-varying code.
    assert_eq!(capture_builds, 100);
    assert_eq!(xfb_rows, capture_builds);
}

/// A row that does not hold is reported: the checker is not vacuous.
#[test]
fn a_wrong_offset_or_binding_is_caught() {
    let wrong = Check::Layout {
        name: "Frame",
        offsets: offsets!(FrameUniforms: view, view_proj, camera_pos, light_dir, tess, base_color, wire_color, viewport),
        size: size_of::<FrameUniforms>(),
    };
    assert!(check(Stage::CommonShadeFrag, PLAIN, &wrong).is_err());
    let wrong = Check::Buffer {
        block: "PatchRings",
        binding: BFT_PATCH_HEADERS_BINDING,
        members: vec![0],
        stride: 4,
    };
    assert!(check(
        Stage::BftBftTese,
        variant(Some(Spacing::Equal), false),
        &wrong
    )
    .is_err());
    let missing = Check::Layout {
        name: "NoSuchBlock",
        offsets: vec![0],
        size: 4,
    };
    assert!(check(Stage::CommonShadeFrag, PLAIN, &missing).is_err());
    let wrong = Check::PatternInput {
        name: "in_n0",
        input: super::pattern_input::TRIANGLE,
        binding: 1,
        offset: 0,
    };
    assert!(check(Stage::PnPatternTriVert, PLAIN, &wrong).is_err());
    // A wrong stride of an array read by address, and a descriptor-bound block taken for one.
    let wrong = Check::Referenced {
        block: "VertexArray",
        members: vec![0],
        stride: 12,
    };
    assert!(check(Stage::AdaptiveCanonicalComp, PLAIN, &wrong).is_err());
    let bound = Check::Referenced {
        block: "AdaptiveArrays",
        members: offsets!(AdaptiveArrays: vertices, patches, control_points, curves, surfaces, reparam, curve_owners, corner_owners, param_errors, param_error_count, fvar_count, fvar),
        stride: 4,
    };
    let e = check(Stage::AdaptiveCanonicalComp, PLAIN, &bound).unwrap_err();
    assert!(e.contains("not read by address"), "{e}");
    let right = Check::Referenced {
        block: "VertexArray",
        members: vec![0],
        stride: 16,
    };
    assert_eq!(check(Stage::AdaptiveCanonicalComp, PLAIN, &right), Ok(()));
}

/// `-DCAPTURE` really changes the build: every capture variant writes transform feedback, and
/// no other build does.
#[test]
fn capture_variants_and_only_they_have_xfb() {
    let mut captures = 0;
    for stage in Stage::ALL {
        for &(v, words) in stage.compiled() {
            let r = Reflection::new(words).expect("SPIR-V");
            assert_eq!(
                r.has_xfb(),
                v.capture,
                "{} {v:?}: XfbBuffer decorations {}",
                stage.path(),
                r.has_xfb()
            );
            captures += v.capture as usize;
        }
    }
    assert_eq!(captures, 100);
}

#[test]
fn reflection_rejects_what_is_not_spirv() {
    assert!(Reflection::new(&[1, 2, 3]).is_err());
    assert!(Reflection::new(&[0x0723_0203, 0, 0, 0, 0, 0x0005_0000]).is_err());
}

/// The plain builds of the adaptive and BFT evaluation stages hand the rasterizer no albedo or
/// texture-coordinate varying (each costs lavapipe on every triangle: docs/benchmarks.md,
/// "varyings are frame time"), and each fragment build reads exactly what the evaluation build
/// of the same `surface` value writes, at the same location and size.
#[test]
fn plain_builds_have_no_surface_varyings() {
    let tese = [
        Stage::AdaptiveRegularTese,
        Stage::AdaptiveGregoryTese,
        Stage::AdaptiveBilinearTese,
        Stage::AdaptiveTriangleTese,
        Stage::BftBftTese,
        Stage::AdaptivePatternRegularVert,
        Stage::AdaptivePatternGregoryVert,
        Stage::AdaptivePatternBilinearVert,
        Stage::AdaptivePatternTriangleVert,
    ];
    let mut checked = 0;
    for stage in tese {
        let frag = if stage == Stage::BftBftTese {
            Stage::BftBftFrag
        } else {
            Stage::AdaptiveAdaptiveFrag
        };
        for &(v, words) in stage.compiled() {
            let r = Reflection::new(words).expect("SPIR-V");
            let f = Reflection::new(spirv(frag, v).expect("fragment build")).expect("SPIR-V");
            for (out, input) in [("out_albedo", "in_albedo"), ("out_texcoord", "in_texcoord")] {
                let written = r.output(out);
                if !v.surface {
                    assert_eq!(written, None, "{} {v:?} writes {out}", stage.path());
                }
                assert_eq!(
                    f.input(input),
                    written,
                    "{} {v:?}: {input} against {out}",
                    stage.path()
                );
            }
            if v.surface {
                assert!(r.output("out_albedo").is_some(), "{} {v:?}", stage.path());
            }
            checked += 1;
        }
    }
    // Four adaptive TESs and BFT's, three spacings, capture or not, plain or surface; the
    // adaptive ones with and without their face-varying look-up, BFT's with and without its
    // patch block; the four adaptive pattern vertex stages, capture or not, plain or surface,
    // with and without the face-varying look-up.
    assert_eq!(checked, 152);
}

/// (NoContraction decorations, GLSL.std.450 FMix calls) in a SPIR-V module.
fn contraction_and_mix(words: &[u32]) -> (usize, usize) {
    const OP_EXT_INST_IMPORT: u32 = 11;
    const OP_EXT_INST: u32 = 12;
    const OP_DECORATE: u32 = 71;
    const NO_CONTRACTION: u32 = 42;
    const GLSL_FMIX: u32 = 46;
    let (mut glsl_set, mut no_contraction, mut fmix) = (None, 0, 0);
    let mut at = 5;
    while at < words.len() {
        let (count, op) = ((words[at] >> 16) as usize, words[at] & 0xffff);
        assert!(count > 0 && at + count <= words.len(), "malformed SPIR-V");
        let ins = &words[at..at + count];
        match op {
            OP_EXT_INST_IMPORT if super::reflect::string(&ins[2..]) == "GLSL.std.450" => {
                glsl_set = Some(ins[1])
            }
            OP_EXT_INST if Some(ins[3]) == glsl_set && ins[4] == GLSL_FMIX => fmix += 1,
            OP_DECORATE if ins[2] == NO_CONTRACTION => no_contraction += 1,
            _ => {}
        }
        at += count;
    }
    (no_contraction, fmix)
}

/// Flat's and Phong's points on a shared edge are sums of corner products that the two patches
/// form in different orders. Only IEEE sums without contraction to fused multiply-adds
/// (`precise`: NoContraction) and without mix() (FMix, whose rounding is the driver's) give
/// both sides the same bits. lavapipe neither fuses nor rewrites mix(), so only a real GPU's
/// capture tests would see a regression (NVIDIA's cracked, docs/benchmarks.md, "Table I on an NVIDIA H100"):
/// this check sees it anywhere.
#[test]
fn corner_sums_are_precise_and_mix_free() {
    for stage in [Stage::FlatTriTese, Stage::FlatQuadTese, Stage::PhongTriTese] {
        for (v, words) in stage.compiled() {
            let (no_contraction, fmix) = contraction_and_mix(words);
            assert!(
                no_contraction >= 10,
                "{} {v:?}: {no_contraction} NoContraction decorations",
                stage.path()
            );
            assert_eq!(fmix, 0, "{} {v:?} calls mix()", stage.path());
        }
    }
}

/// The stencil evaluator sums each row under `precise`: the products and sums of
/// `anchor + Σ w (x − anchor)` are not contracted into fused multiply-adds, so every driver
/// computes what `GpuStencils::row_point` mirrors (BFT's and adaptive's exactness tests, and
/// the evaluator's bit-for-bit test, rely on it where CI has no GPU to see it).
#[test]
fn stencil_rows_are_summed_without_contraction() {
    for (v, words) in Stage::StencilEvaluateComp.compiled() {
        let (no_contraction, fmix) = contraction_and_mix(words);
        println!("{v:?}: {no_contraction} NoContraction decorations");
        assert!(
            no_contraction >= 3,
            "{v:?}: {no_contraction} NoContraction decorations"
        );
        assert_eq!(fmix, 0, "{v:?} calls mix()");
    }
}

/// The vertex-patch kernel sums every child `precise` (no fused products), so each patch that
/// holds a shared face writes its children with the same bits.
#[test]
fn vertex_patch_children_are_summed_without_contraction() {
    for (v, words) in Stage::VertexPatchesRefineComp.compiled() {
        let (no_contraction, fmix) = contraction_and_mix(words);
        assert!(
            no_contraction >= 3,
            "{v:?}: {no_contraction} NoContraction decorations"
        );
        assert_eq!(fmix, 0, "{v:?} calls mix()");
    }
}
