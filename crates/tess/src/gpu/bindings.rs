// Numbers the Rust host and the GLSL stages must agree on: descriptor sets and bindings, the
// transform-feedback buffer, and the small enumerations packed into push constants and records.
//
// This file is compiled twice: as `tess::gpu::bindings`, and by the build script, which
// `include!`s it and writes every constant as `#define NAME value` into `$OUT_DIR/bindings.glsl`,
// the include the shaders take them from. So a binding number is written here and nowhere else,
// and the file must stay plain: `u32` literals, no paths into the crate, no inner attributes.
macro_rules! gpu_constants {
    ($($(#[doc = $doc:literal])* $name:ident = $value:literal;)*) => {
        $($(#[doc = $doc])* pub const $name: u32 = $value;)*
        /// Every constant by name, in declaration order: what `bindings.glsl` defines.
        pub const ALL: &[(&str, u32)] = &[$((stringify!($name), $name)),*];
    };
}

gpu_constants! {
    /// Descriptor set of the per-frame uniforms, bound by every technique.
    FRAME_SET = 0;
    /// The `Frame` uniform block ([`crate::gpu::FrameUniforms`]).
    FRAME_UNIFORMS_BINDING = 0;

    /// Descriptor set of one BFT surface's storage buffers (`glsl/bft/bft.glsl`).
    BFT_SET = 1;
    /// CSR offsets of the level-1 limit-tangent stencils.
    BFT_TANGENT_OFFSETS_BINDING = 0;
    /// Level-1 limit-tangent terms ([`crate::techniques::bft::layout::TangentTerm`]).
    BFT_TANGENT_TERMS_BINDING = 1;
    /// Level-1 positions (`vec4`), written by the stencil evaluator ([`crate::stencil`]).
    BFT_LEVEL1_POSITIONS_BINDING = 2;
    /// Level-1 limit normals (`vec4`), written by `normals.comp`.
    BFT_LEVEL1_NORMALS_BINDING = 3;
    /// One [`crate::techniques::bft::layout::PatchHeader`] per level-1 face.
    BFT_PATCH_HEADERS_BINDING = 4;
    /// Every patch's control ring (level-1 vertex indices), back to back.
    BFT_PATCH_RINGS_BINDING = 5;
    /// The uniform block `BftTableArrays` ([`crate::gpu::BftTableArrays`]): the device
    /// addresses of the basis-function tables ([`crate::techniques::bft::layout::TableHeader`],
    /// then one [`crate::techniques::bft::layout::TableEntry`] per table), their mirror
    /// permutations of ring slots, their row maps (grid point → table row, full tables then
    /// half tables) and their weights. Read through buffer references: every patch may read any
    /// table, and no descriptor range limits them.
    BFT_TABLE_ARRAYS_BINDING = 6;
    /// Work-group size of the BFT compute passes.
    BFT_LOCAL_SIZE = 64;

    /// Descriptor set of the stencil evaluator (`glsl/stencil/stencil.glsl`, [`crate::stencil`]):
    /// its own pipeline layout, this set alone.
    STENCIL_SET = 0;
    /// CSR offsets of the stencil rows (rows + 1), windowed.
    STENCIL_OFFSETS_BINDING = 0;
    /// Stencil terms ([`crate::stencil::StencilTerm`]: source vertex, weight), windowed.
    STENCIL_TERMS_BINDING = 1;
    /// The vertices the rows read (`vec4`), windowed.
    STENCIL_SOURCE_BINDING = 2;
    /// The vertices the rows write (`vec4`), windowed; may be the source buffer itself.
    STENCIL_DESTINATION_BINDING = 3;
    /// Work-group size of the stencil evaluator.
    STENCIL_LOCAL_SIZE = 64;

    /// Transform-feedback buffer the capture variants write ([`crate::gpu::CaptureRecord`]).
    CAPTURE_XFB_BUFFER = 0;
    /// Bytes per captured corner: `size_of::<CaptureRecord>()` (asserted in `gpu`).
    CAPTURE_XFB_STRIDE = 40;
    /// Offsets of the record's members (`offset_of!` asserted in `gpu`): world position,
    CAPTURE_OFFSET_POSITION = 0;
    /// normal,
    CAPTURE_OFFSET_NORMAL = 12;
    /// patch id, then flags (one `uvec2` output),
    CAPTURE_OFFSET_PATCH = 24;
    /// domain coordinate.
    CAPTURE_OFFSET_DOMAIN = 32;
    /// Capture flag: the BFT point was a table point (exact limit), not interpolated.
    CAPTURE_FLAG_EXACT = 1;
    /// Capture flags: the BFT patch kind (`BFT_KIND_*`) sits above the exact bit.
    CAPTURE_FLAG_KIND_SHIFT = 1;

    /// `mode` of [`crate::gpu::DrawPush`] and [`crate::gpu::BftPush`]: shaded surface.
    DRAW_MODE_SHADED = 0;
    /// `mode`: the wireframe overlay (flat colour).
    DRAW_MODE_WIREFRAME = 1;

    /// `factor_mode` of [`crate::gpu::BftPush`]: one level everywhere.
    BFT_FACTORS_UNIFORM = 0;
    /// `factor_mode`: projected edge length over pixels per segment.
    BFT_FACTORS_SCREEN = 1;
    /// `factor_mode`: by distance from the eye.
    BFT_FACTORS_DISTANCE = 2;
    /// `options` bit of [`crate::gpu::BftPush`]: normals from the tangent tables (`du × dv`).
    BFT_OPTION_GEOMETRIC_NORMALS = 1;
    /// `options` bit: colour patches by kind.
    BFT_OPTION_PATCH_COLOURS = 2;
    /// `options` bit: fractional factors (no power-of-two rounding).
    BFT_OPTION_FRACTIONAL = 4;

    /// `kind` of a BFT table entry ([`crate::techniques::bft::layout::TableEntry`]): regular interior (valence 6).
    BFT_KIND_REGULAR = 0;
    /// Interior, extraordinary.
    BFT_KIND_EXTRAORDINARY = 1;
    /// On a boundary.
    BFT_KIND_BOUNDARY = 2;
    /// A face-private table (no shared configuration covers it).
    BFT_KIND_PRIVATE = 3;

    /// Patch owners pack `face << BFT_OWNER_SHIFT | local index` ([`crate::techniques::bft::layout::pack_owner`]).
    BFT_OWNER_SHIFT = 2;
    /// Mask of an owner's local edge or corner index.
    BFT_OWNER_LOCAL_MASK = 3;

    /// Descriptor set of one Doo-Sabin surface (`glsl/doo_sabin/mesh.vert`).
    DOO_SABIN_SET = 1;
    /// The uniform block `DooSabinArrays` ([`crate::gpu::DooSabinArrays`]): the device
    /// addresses of the deepest level's points (`vec4`, level-local numbering: where the
    /// stencil evaluator writes that level in the refined vertex buffer, [`crate::stencil`]) and
    /// of its face corners, per point `DOO_SABIN_MAX_CORNERS` `uvec2(next, previous)` neighbours
    /// (an unused slot names the point itself twice, adding nothing): what its normal is summed
    /// from. Read through buffer references, no descriptor range limits them.
    DOO_SABIN_ARRAYS_BINDING = 0;
    /// Face corners a refined Doo-Sabin point lies in at most (one f-face, two e-faces or
    /// boundary strips, one v-face or vertex strip).
    DOO_SABIN_MAX_CORNERS = 4;

    /// Descriptor set of one vertex-patch Doo-Sabin surface (`glsl/vertex_patches/mesh.vert`).
    VERTEX_PATCHES_SET = 1;
    /// The uniform block `VertexPatchArrays` ([`crate::gpu::VertexPatchArrays`]): the device
    /// addresses of the deepest depth's patch arrays (`vec4` per slot, every patch's array one
    /// after another) and of each slot's face corners, `DOO_SABIN_MAX_CORNERS`
    /// `uvec2(next, previous)` slots per slot. Read through buffer references.
    VERTEX_PATCHES_ARRAYS_BINDING = 0;
    /// Invocations per workgroup of `glsl/vertex_patches/refine.comp`.
    VERTEX_PATCHES_LOCAL_SIZE = 64;
    /// The largest face a vertex patch refines (a local array of the kernel): the v-face of a
    /// vertex of valence up to this, or a corner face of up to this many corners.
    VERTEX_PATCHES_MAX_FACE = 32;
    /// A patch point's flag bits ([`topology::patches::doo_sabin::PointFlags`]): a point of the
    /// refined mesh...
    VERTEX_PATCH_PRESENT = 1;
    /// ...and a boundary point (its faces are refined by the strip mask).
    VERTEX_PATCH_BOUNDARY = 2;

    /// Descriptor set of one feature-adaptive Catmull-Clark surface (`glsl/adaptive/adaptive.glsl`).
    ADAPTIVE_SET = 1;
    /// The uniform block `AdaptiveArrays` ([`crate::gpu::AdaptiveArrays`]): the device address of every array the canonical kernel and the draw read (vertices, patch records, control points, curves, patch surfaces, the reparameterization table, curve and corner owners, the Eq. 1 error lattice). Read through buffer references, no descriptor range limits them.
    ADAPTIVE_ARRAYS_BINDING = 0;
    /// Colour texture (combined image sampler; a 1x1 white texel when none is given).
    ADAPTIVE_TEXTURE_BINDING = 1;
    /// Height map (combined image sampler, red channel; a 1x1 texel when none is given).
    ADAPTIVE_HEIGHT_BINDING = 2;
    /// Lattice points per patch side of the Eq. 1 error view.
    ADAPTIVE_PARAM_ERROR_SIDE = 9;
    /// The deepest face-varying descent (`topology::patches::fvar::FVAR_MAX_DEPTH`). Its
    /// leaf and empty entries (`FVAR_LEAF`, `FVAR_EMPTY`, the latter also a patch's "no
    /// face-varying root") need the high bit, which a `#define`d decimal cannot carry:
    /// `glsl/adaptive/fvar.glsl` writes them in hex, checked against `topology` by a test.
    ADAPTIVE_FVAR_MAX_DEPTH = 16;
    /// Work-group size of the adaptive canonical kernel (`canonical.comp`).
    ADAPTIVE_LOCAL_SIZE = 64;
    /// `mode` of the canonical kernel (`AdaptivePush`): evaluate the canonical curves' inner points from their owner patches' control points (two per curve),
    ADAPTIVE_CANONICAL_MODE_CURVES = 2;
    /// evaluate the canonical corners owned by regular patches from their 3x3 points, phantoms included (the B-spline value at the corner).
    ADAPTIVE_CANONICAL_MODE_CORNERS = 3;
    /// Patch kinds (low 4 bits of `AdaptivePatch::info`): bicubic B-spline,
    ADAPTIVE_KIND_REGULAR = 0;
    /// Gregory end cap,
    ADAPTIVE_KIND_GREGORY = 1;
    /// bilinearly blended (Coons) end cap over its four boundary curves,
    ADAPTIVE_KIND_BILINEAR = 2;
    /// Gregory triangle patch (single-pass plans: one per triangle, 15 points, triangle domain).
    ADAPTIVE_KIND_GREGORY_TRIANGLE = 3;
    /// Edge kinds (2 bits per edge in `AdaptivePatch::edge_info`): same level on both sides,
    ADAPTIVE_EDGE_PLAIN = 0;
    /// this patch is the coarse side of a transition (its factor is doubled),
    ADAPTIVE_EDGE_COARSE = 1;
    /// this patch is one fine half of a transition.
    ADAPTIVE_EDGE_FINE = 2;
    /// `options` bit of `AdaptivePush`: colour patches by kind and level.
    ADAPTIVE_OPTION_PATCH_COLOURS = 1;
    /// `options` bit: fractional-even factors (transition edges stay even integers).
    ADAPTIVE_OPTION_FRACTIONAL = 2;
    /// `options` bit: round adaptive factors up to powers of two.
    ADAPTIVE_OPTION_POW2 = 4;
    /// `options` bit: shade with the colour texture at the surface's texture coordinates.
    ADAPTIVE_OPTION_TEXTURE = 8;
    /// `options` bit: texture coordinates at the reparameterized parameter s(u, v) (seed 003, Eq. 3) on Gregory patches.
    ADAPTIVE_OPTION_REPARAM = 16;
    /// `options` bit: displace along the normal by `displace_scale` times the height.
    ADAPTIVE_OPTION_DISPLACE = 32;
    /// `options` bit: the height comes from the height map (else the procedural height).
    ADAPTIVE_OPTION_HEIGHT_MAP = 64;
    /// `options` bit: colour by the parameter shift |s(u, v) - (u, v)| of the reparameterization.
    ADAPTIVE_OPTION_SHOW_PARAM_SHIFT = 128;
    /// `options` bit: colour by the pointwise Eq. 1 texture error (seed 003, Fig. 8).
    ADAPTIVE_OPTION_SHOW_PARAM_ERROR = 256;
    /// `options` bit: a vertex on a patch boundary is shaded with its curve owner's normal
    /// (displaced or not), so both sides of every edge emit the same normal bits (single-pass
    /// methods: their patches are not G1 across transitions and fallbacks).
    ADAPTIVE_OPTION_CANONICAL_NORMALS = 512;
    /// `options` bit, refinement-pattern path: geomorphing between power-of-two levels (fractional-even
    /// spacing there). Each odd pattern vertex slides toward the even one the coarser level
    /// keeps, by its edge's or the inside's morph weight (the instance's, `pattern_patch.glsl`).
    ADAPTIVE_OPTION_GEOMORPH = 1024;
    /// Capture flags of the adaptive TES: patch kind in bits 0..3, level above.
    ADAPTIVE_FLAG_LEVEL_SHIFT = 4;
    /// Capture flag: the point lies on a patch boundary and came from its canonical curve.
    ADAPTIVE_FLAG_CANONICAL = 256;
}
