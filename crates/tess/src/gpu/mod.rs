//! Rust mirrors of every block shared with GLSL: uniforms, push constants, the
//! transform-feedback record and the vertex input (the storage buffers' structs live with
//! their users: [`crate::stencil`], [`crate::techniques::bft::layout`],
//! [`crate::techniques::planned_patches::layout`]).
//!
//! Design decisions:
//! - `#[repr(C)]` + `Pod` with named fields, no `Vec3` (std140/std430 would pad it); sizes and
//!   offsets asserted at compile time where GLSL fixes them.
//! - Set, binding and transform-feedback numbers live in [`bindings`], from which the build
//!   script generates the `bindings.glsl` every shader includes.
//! - One table-driven test (`layout_tests`) reads every block, binding, array stride and
//!   transform-feedback decoration back from the compiled SPIR-V ([`reflect`]) and compares
//!   them with `offset_of!` / `size_of` of these structs.
use bytemuck::{Pod, Zeroable};
use std::mem::{offset_of, size_of};
use vk_core::vk;

pub mod bindings;
#[cfg(test)]
mod layout_tests;
pub mod reflect;

/// `Frame` uniform block (std140), `glsl/common/frame.glsl`; set [`bindings::FRAME_SET`],
/// binding [`bindings::FRAME_UNIFORMS_BINDING`].
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
    /// x: amplitude a, y: frequency f of the refinement-pattern seed's procedural displacement
    /// a·sin(f·‖P‖) along the normal (flat, Phong, PN; a = 0: none).
    pub sine: [f32; 4],
}

const _: () = {
    assert!(size_of::<FrameUniforms>() == 240);
    assert!(offset_of!(FrameUniforms, sine) == 224);
    assert!(offset_of!(FrameUniforms, view) == 64);
    assert!(offset_of!(FrameUniforms, camera_pos) == 128);
    assert!(offset_of!(FrameUniforms, light_dir) == 144);
    assert!(offset_of!(FrameUniforms, tess) == 160);
    assert!(offset_of!(FrameUniforms, base_color) == 176);
    assert!(offset_of!(FrameUniforms, wire_color) == 192);
    assert!(offset_of!(FrameUniforms, viewport) == 208);
};

/// `Draw` push constant (std430), `glsl/common/frame.glsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct DrawPush {
    /// [`bindings::DRAW_MODE_SHADED`] or [`bindings::DRAW_MODE_WIREFRAME`].
    pub mode: u32,
    /// Patch id of the draw's first patch: `gl_PrimitiveID` restarts at 0 in every draw, and
    /// draws are split on some drivers, so the TES adds this to number patches frame-wide.
    pub first_patch: u32,
}

const _: () = {
    assert!(size_of::<DrawPush>() == 8);
    assert!(offset_of!(DrawPush, first_patch) == 4);
};

/// `BftPush` push constant of every BFT stage, `glsl/bft/bft.glsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct BftPush {
    /// [`bindings::DRAW_MODE_SHADED`] or [`bindings::DRAW_MODE_WIREFRAME`].
    pub mode: u32,
    /// Patch (level-1 face) index of the draw's first patch.
    pub first_patch: u32,
    /// `BFT_FACTORS_UNIFORM`, `_SCREEN` or `_DISTANCE` ([`bindings`]).
    pub factor_mode: u32,
    /// `BFT_OPTION_*` bits ([`bindings`]): geometric normals, patch colours, fractional factors.
    pub options: u32,
    pub uniform_level: f32,
    pub pixels_per_segment: f32,
    pub distance_ref: f32,
    pub max_level: f32,
    /// Compute passes: level-1 vertex count (of this chunk).
    pub count: u32,
    /// Compute passes: the chunk's first level-1 vertex.
    pub first_vertex: u32,
    /// The chunk's window bases (`techniques::windows`): every index into a windowed buffer
    /// has its space's base subtracted. Patch headers.
    pub patch_base: u32,
    /// Patch rings.
    pub ring_base: u32,
    /// Level-1 positions, normals, and the tangent CSR offsets.
    pub level1_base: u32,
    /// Tangent terms.
    pub tangent_base: u32,
    /// Aligns [`Self::pattern_outer`] to 16 bytes, as the block does.
    pub pad: [u32; 2],
    /// The refinement-pattern path: the drawn pattern's edge levels, in `gl_TessLevelOuter`'s
    /// order (the geomorphing vertex stage reads them; `glsl/bft/pattern.vert`).
    pub pattern_outer: [f32; 4],
}

const _: () = assert!(size_of::<BftPush>() == 80);

/// `AdaptivePush` push constant of every feature-adaptive stage, `glsl/adaptive/adaptive.glsl`.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct AdaptivePush {
    /// [`bindings::DRAW_MODE_SHADED`] or [`bindings::DRAW_MODE_WIREFRAME`]; the canonical
    /// kernel: [`bindings::ADAPTIVE_CANONICAL_MODE_CORNERS`] or
    /// [`bindings::ADAPTIVE_CANONICAL_MODE_CURVES`].
    pub mode: u32,
    /// Frame-wide id of the drawn array's first patch.
    pub first_patch: u32,
    /// `BFT_FACTORS_UNIFORM`, `_SCREEN` or `_DISTANCE` ([`bindings`]).
    pub factor_mode: u32,
    /// `ADAPTIVE_OPTION_*` bits ([`bindings`]).
    pub options: u32,
    /// Segments per patch edge (uniform factors).
    pub uniform_level: f32,
    pub pixels_per_segment: f32,
    pub distance_ref: f32,
    /// The device's maximum tessellation level.
    pub max_level: f32,
    /// Canonical kernel: the dispatch's first regular corner or curve point.
    pub first_item: u32,
    /// Canonical kernel: corners or curve points in the dispatch.
    pub count: u32,
    /// Displacement along the normal per unit of height (`ADAPTIVE_OPTION_DISPLACE`).
    pub displace_scale: f32,
    /// Global id of the first canonical corner (the first of [`AdaptiveArrays::corner_owners`]).
    pub first_corner: u32,
    /// The refinement-pattern path: the drawn pattern's edge levels, in `gl_TessLevelOuter`'s
    /// order (the evaluation stage reads its own; `glsl/adaptive/pattern_patch.glsl`).
    pub pattern_outer: [f32; 4],
}

const _: () = assert!(size_of::<AdaptivePush>() == 64);

/// `AdaptiveArrays` uniform block of every planned-patch stage, `glsl/adaptive/adaptive.glsl`
/// ([`bindings::ADAPTIVE_ARRAYS_BINDING`]): the device address of each array the canonical
/// kernel and the draw read through buffer references (`Buffer::device_address`). A `u64`
/// here is a `uvec2` there, low word first.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct AdaptiveArrays {
    /// `vec4` per global vertex: base, refined levels, local points, canonical points.
    pub vertices: u64,
    /// One patch record per patch, frame-wide order.
    pub patches: u64,
    /// Global vertex indices of every patch's control points, back to back.
    pub control_points: u64,
    /// Canonical boundary curves, four global vertices each.
    pub curves: u64,
    /// Per patch: texture coordinates at its corners and its corners' reparameterization rows.
    pub surfaces: u64,
    /// The texture reparameterization's rows: row 0 the identity, row `v - 2` valence `v`.
    pub reparam: u64,
    /// Per canonical curve: the patch defining its normals and texture coordinates.
    pub curve_owners: u64,
    /// Per canonical corner (global vertex − `first_corner`): `(patch, corner)` of its owner.
    pub corner_owners: u64,
    /// The Eq. 1 error lattice per patch.
    pub param_errors: u64,
    /// Entries of the lattice (0: not built; the view then reads nothing).
    pub param_error_count: u32,
    /// Words of the face-varying array (every read of it is checked against this).
    pub fvar_count: u32,
    /// The face-varying patches (`techniques::planned_patches::layout::fvar_words`).
    pub fvar: u64,
}

const _: () = assert!(size_of::<AdaptiveArrays>() == 88);

/// `BftTableArrays` uniform block of `glsl/bft/bft.glsl`
/// ([`bindings::BFT_TABLE_ARRAYS_BINDING`]): the device addresses of the basis-function tables'
/// arrays, read through buffer references (`Buffer::device_address`). A `u64` here is a
/// `uvec2` there, low word first.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct BftTableArrays {
    /// The table header, then one entry per table.
    pub tables: u64,
    /// Mirror permutations of the tables' ring slots.
    pub perms: u64,
    /// Row maps: grid point → table row, full tables then half tables.
    pub maps: u64,
    /// Basis-function weights of every table.
    pub weights: u64,
}

const _: () = assert!(size_of::<BftTableArrays>() == 32);

/// `DooSabinArrays` uniform block of `glsl/doo_sabin/mesh.vert`
/// ([`bindings::DOO_SABIN_ARRAYS_BINDING`]): the device addresses of the arrays its vertex stage
/// reads through buffer references (`Buffer::device_address`). A `u64` here is a `uvec2`
/// there, low word first.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct DooSabinArrays {
    /// `vec4` per point of the deepest level: the address of its first point in the refined
    /// vertex buffer.
    pub points: u64,
    /// Per point of the deepest level, `DOO_SABIN_MAX_CORNERS` `(next, previous)` neighbours.
    pub corners: u64,
}

const _: () = assert!(size_of::<DooSabinArrays>() == 16);

/// `VertexPatchArrays` uniform block of `glsl/vertex_patches/mesh.vert`
/// ([`bindings::VERTEX_PATCHES_ARRAYS_BINDING`]): device addresses (`uvec2` there, low word
/// first).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct VertexPatchArrays {
    /// `vec4` per slot of the deepest depth: the address of its first slot in the patch buffer.
    pub points: u64,
    /// Per slot of the deepest depth, `DOO_SABIN_MAX_CORNERS` `(next, previous)` slots.
    pub corners: u64,
}

const _: () = assert!(size_of::<VertexPatchArrays>() == 16);

/// `VertexPatchRecord` of `glsl/vertex_patches/refine.comp`: one patch in one step
/// (depth `d` → `d + 1`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct VertexPatchRecord {
    /// `n`, the valence (points per side of layer 0).
    pub valence: u32,
    /// Where its corner faces' size prefix sums start (`n + 1` words: `m_0 + … + m_{j−1}`).
    pub sizes: u32,
    /// Its array at depth `d`: the element of the patch buffer its slot 0 is.
    pub source: u32,
    /// Its array at depth `d + 1`.
    pub destination: u32,
    /// Its first work item in the step (`L² n + n` items a patch).
    pub first_item: u32,
}

const _: () = assert!(size_of::<VertexPatchRecord>() == 20);

/// `VertexPatchStep` push constant of `glsl/vertex_patches/refine.comp`: one dispatch of one
/// step, the arrays' device addresses (`uvec2` there, low word first).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, Pod, Zeroable)]
pub struct VertexPatchStep {
    /// `vec4` per element of the patch buffer (base positions, then every depth's arrays).
    pub points: u64,
    /// Flag bits per element of the patch buffer (`VERTEX_PATCH_PRESENT`, `_BOUNDARY`).
    pub flags: u64,
    /// The step's [`VertexPatchRecord`]s, in work-item order.
    pub records: u64,
    /// Corner-size prefix sums of every patch.
    pub sizes: u64,
    /// Doo-Sabin weights: per face size `m`, `m` full-face weights then `m × m` strip weights.
    pub weights: u64,
    /// Per face size `m` (0..=`VERTEX_PATCHES_MAX_FACE`), where its weights start.
    pub weight_starts: u64,
    /// Records in the step.
    pub patch_count: u32,
    /// Work items of the step.
    pub items: u32,
    /// The dispatch's first work item.
    pub first_item: u32,
    /// The source depth `d` (outer layer `L = 2^(d−1)`).
    pub depth: u32,
}

const _: () = assert!(size_of::<VertexPatchStep>() == 64);

/// `StencilPush` push constant of the stencil evaluator, `glsl/stencil/stencil.glsl`
/// ([`crate::stencil`]): one dispatch, rows `first_row .. first_row + count`, and the window
/// bases of its chunk (`techniques::windows`), subtracted from every index into a windowed
/// buffer.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Pod, Zeroable)]
pub struct StencilPush {
    pub first_row: u32,
    pub count: u32,
    /// The window base of the CSR offsets (row `r` reads `offsets[r − row_base]`).
    pub row_base: u32,
    /// The window base of the terms.
    pub term_base: u32,
    /// The window base of the source vertices (a term reads `source[index − source_base]`).
    pub source_base: u32,
    /// The destination of row `first_row`, in the destination window.
    pub destination_first: u32,
}

const _: () = assert!(size_of::<StencilPush>() == 24);

/// Interleaved vertex of the mesh vertex buffer (`common/mesh.vert` and `plain/plain.vert`
/// locations 0 and 1).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct Vertex {
    pub position: [f32; 3],
    pub normal: [f32; 3],
}

const _: () = assert!(size_of::<Vertex>() == 24);

impl Vertex {
    /// The vertex buffer binding of the interleaved vertices.
    pub const BINDING: vk::VertexInputBindingDescription = vk::VertexInputBindingDescription {
        binding: 0,
        stride: size_of::<Vertex>() as u32,
        input_rate: vk::VertexInputRate::VERTEX,
    };

    /// Position at location 0, normal at 1, at their `offset_of!`.
    pub const ATTRIBUTES: [vk::VertexInputAttributeDescription; 2] = [
        vk::VertexInputAttributeDescription {
            location: 0,
            binding: 0,
            format: vk::Format::R32G32B32_SFLOAT,
            offset: offset_of!(Vertex, position) as u32,
        },
        vk::VertexInputAttributeDescription {
            location: 1,
            binding: 0,
            format: vk::Format::R32G32B32_SFLOAT,
            offset: offset_of!(Vertex, normal) as u32,
        },
    ];
}

/// A scalar-tagged PN triangle's corner beyond its [`Vertex`]: the edge control points its tags
/// make on the edge to the next corner and on the edge to the previous one, `w` 1 where the
/// corner is tagged (else 0, and PN's own points are used; `glsl/pn/pn.glsl`,
/// `pn_patch_tagged`).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct TaggedCorner {
    pub b_next: [f32; 4],
    pub b_prev: [f32; 4],
}

const _: () = assert!(size_of::<TaggedCorner>() == 32);

impl TaggedCorner {
    const MESH_BINDINGS: [vk::VertexInputBindingDescription; 2] = [
        Vertex::BINDING,
        vk::VertexInputBindingDescription {
            binding: 1,
            stride: size_of::<TaggedCorner>() as u32,
            input_rate: vk::VertexInputRate::VERTEX,
        },
    ];
    const MESH_ATTRIBUTES: [vk::VertexInputAttributeDescription; 4] = [
        Vertex::ATTRIBUTES[0],
        Vertex::ATTRIBUTES[1],
        vk::VertexInputAttributeDescription {
            location: 2,
            binding: 1,
            format: vk::Format::R32G32B32A32_SFLOAT,
            offset: offset_of!(TaggedCorner, b_next) as u32,
        },
        vk::VertexInputAttributeDescription {
            location: 3,
            binding: 1,
            format: vk::Format::R32G32B32A32_SFLOAT,
            offset: offset_of!(TaggedCorner, b_prev) as u32,
        },
    ];

    /// The tessellation path's input (`glsl/pn/tagged_mesh.vert`): the corners' [`Vertex`]es
    /// at binding 0 and their tagged corners, parallel, at binding 1 (locations 2 and 3).
    pub const MESH: crate::technique::VertexInput = crate::technique::VertexInput {
        bindings: &Self::MESH_BINDINGS,
        attributes: &Self::MESH_ATTRIBUTES,
    };
}

/// The refinement-pattern path's vertex input (`glsl/common/pattern_in.glsl`): binding 0 per
/// pattern vertex, its domain point (three floats, [`crate::pattern::RefinementPattern`]) at
/// location 0; binding 1 per instance, the patch's corners as [`Vertex`]es, corner `i`'s
/// position at location `1 + 2i` and normal at `2 + 2i`.
pub mod pattern_input {
    use super::{TaggedCorner, Vertex};
    use crate::technique::VertexInput;
    use std::mem::size_of;
    use vk_core::vk;

    const fn bindings(corners: usize) -> [vk::VertexInputBindingDescription; 2] {
        [
            vk::VertexInputBindingDescription {
                binding: 0,
                stride: size_of::<[f32; 3]>() as u32,
                input_rate: vk::VertexInputRate::VERTEX,
            },
            vk::VertexInputBindingDescription {
                binding: 1,
                stride: (corners * size_of::<Vertex>()) as u32,
                input_rate: vk::VertexInputRate::INSTANCE,
            },
        ]
    }

    /// Location 0, then position and normal of each corner.
    const fn attributes<const N: usize>() -> [vk::VertexInputAttributeDescription; N] {
        let float3 = vk::Format::R32G32B32_SFLOAT;
        let mut out = [vk::VertexInputAttributeDescription {
            location: 0,
            binding: 0,
            format: float3,
            offset: 0,
        }; N];
        let mut i = 1;
        while i < N {
            let (corner, normal) = ((i - 1) / 2, (i - 1) % 2);
            out[i] = vk::VertexInputAttributeDescription {
                location: i as u32,
                binding: 1,
                format: float3,
                offset: (corner * size_of::<Vertex>() + normal * size_of::<[f32; 3]>()) as u32,
            };
            i += 1;
        }
        out
    }

    const TRIANGLE_BINDINGS: [vk::VertexInputBindingDescription; 2] = bindings(3);
    const TRIANGLE_ATTRIBUTES: [vk::VertexInputAttributeDescription; 7] = attributes();
    const QUAD_BINDINGS: [vk::VertexInputBindingDescription; 2] = bindings(4);
    const QUAD_ATTRIBUTES: [vk::VertexInputAttributeDescription; 9] = attributes();

    const TAGGED_BINDINGS: [vk::VertexInputBindingDescription; 3] = [
        TRIANGLE_BINDINGS[0],
        TRIANGLE_BINDINGS[1],
        vk::VertexInputBindingDescription {
            binding: 2,
            stride: (3 * size_of::<TaggedCorner>()) as u32,
            input_rate: vk::VertexInputRate::INSTANCE,
        },
    ];

    /// The triangle attributes, then each corner's next and previous tagged edge points.
    const fn tagged_attributes() -> [vk::VertexInputAttributeDescription; 13] {
        let mut out = [TRIANGLE_ATTRIBUTES[0]; 13];
        let mut i = 0;
        while i < 13 {
            out[i] = if i < 7 {
                TRIANGLE_ATTRIBUTES[i]
            } else {
                let (corner, prev) = ((i - 7) / 2, (i - 7) % 2);
                vk::VertexInputAttributeDescription {
                    location: i as u32,
                    binding: 2,
                    format: vk::Format::R32G32B32A32_SFLOAT,
                    offset: (corner * size_of::<TaggedCorner>() + prev * 16) as u32,
                }
            };
            i += 1;
        }
        out
    }
    const TAGGED_ATTRIBUTES: [vk::VertexInputAttributeDescription; 13] = tagged_attributes();

    /// Scalar-tagged PN triangles: [`TRIANGLE`], and per instance at binding 2 the three
    /// corners' [`TaggedCorner`]s (corner `i`'s next point at location `7 + 2i`, previous at
    /// `8 + 2i`).
    pub const TAGGED_TRIANGLE: VertexInput = VertexInput {
        bindings: &TAGGED_BINDINGS,
        attributes: &TAGGED_ATTRIBUTES,
    };
    const POINT_BINDINGS: [vk::VertexInputBindingDescription; 1] = [TRIANGLE_BINDINGS[0]];
    const POINT_ATTRIBUTES: [vk::VertexInputAttributeDescription; 1] = [TRIANGLE_ATTRIBUTES[0]];

    const PATCH_ID_BINDINGS: [vk::VertexInputBindingDescription; 2] = [
        TRIANGLE_BINDINGS[0],
        vk::VertexInputBindingDescription {
            binding: 1,
            stride: size_of::<[u32; 4]>() as u32,
            input_rate: vk::VertexInputRate::INSTANCE,
        },
    ];
    const PATCH_ID_ATTRIBUTES: [vk::VertexInputAttributeDescription; 2] = [
        TRIANGLE_ATTRIBUTES[0],
        vk::VertexInputAttributeDescription {
            location: 1,
            binding: 1,
            format: vk::Format::R32G32B32A32_UINT,
            offset: 0,
        },
    ];

    /// The pattern's domain points (location 0) and, per instance at binding 1, the frame-wide
    /// id of the patch drawn and its morph weights (location 1, `uvec4`: the id, then edges
    /// 0, 1, then 2, 3, then the inside's two directions as unorm16 pairs): techniques whose
    /// instances are not their patches in order (the planned patches draw one pattern per
    /// edge-level key, each over its own list of patches; `glsl/adaptive/pattern_patch.glsl`).
    pub const PATCH_IDS: VertexInput = VertexInput {
        bindings: &PATCH_ID_BINDINGS,
        attributes: &PATCH_ID_ATTRIBUTES,
    };

    /// The pattern's domain points only (location 0): techniques whose vertex stage reads the
    /// patch from its own buffers by the instance (BFT).
    pub const POINTS: VertexInput = VertexInput {
        bindings: &POINT_BINDINGS,
        attributes: &POINT_ATTRIBUTES,
    };
    /// Triangle patches: three corners per instance.
    pub const TRIANGLE: VertexInput = VertexInput {
        bindings: &TRIANGLE_BINDINGS,
        attributes: &TRIANGLE_ATTRIBUTES,
    };
    /// Quad patches: four corners per instance.
    pub const QUAD: VertexInput = VertexInput {
        bindings: &QUAD_BINDINGS,
        attributes: &QUAD_ATTRIBUTES,
    };
}

/// One captured triangle corner: the transform-feedback record of `glsl/common/tese_out.glsl`
/// (buffer [`bindings::CAPTURE_XFB_BUFFER`], stride [`bindings::CAPTURE_XFB_STRIDE`]).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct CaptureRecord {
    /// World position as the TES computed it.
    pub position: [f32; 3],
    /// Normal as shaded.
    pub normal: [f32; 3],
    /// Frame-wide patch id.
    pub patch: u32,
    /// Technique-defined flags (0 for the triangle/quad techniques).
    pub flags: u32,
    /// `gl_TessCoord.xy` as the fixed-function tessellator produced it.
    pub domain: [f32; 2],
}

/// Bytes per record: the `xfb_stride` of `tese_out.glsl`.
pub const CAPTURE_STRIDE: u64 = size_of::<CaptureRecord>() as u64;

// GLSL writes the record from the numbers in `bindings`; the Rust struct must agree with them.
const _: () = {
    assert!(size_of::<CaptureRecord>() == bindings::CAPTURE_XFB_STRIDE as usize);
    assert!(offset_of!(CaptureRecord, position) == bindings::CAPTURE_OFFSET_POSITION as usize);
    assert!(offset_of!(CaptureRecord, normal) == bindings::CAPTURE_OFFSET_NORMAL as usize);
    assert!(offset_of!(CaptureRecord, patch) == bindings::CAPTURE_OFFSET_PATCH as usize);
    // patch and flags are one `uvec2` output.
    assert!(offset_of!(CaptureRecord, flags) == bindings::CAPTURE_OFFSET_PATCH as usize + 4);
    assert!(offset_of!(CaptureRecord, domain) == bindings::CAPTURE_OFFSET_DOMAIN as usize);
};
