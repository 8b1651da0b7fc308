//! A Catmull-Clark patch plan (`topology::patches::adaptive::AdaptivePlan`) on the
//! tessellation stage: what the feature-adaptive technique (`techniques::adaptive`, Nießner et
//! al. 2012) and the single-pass approximations (`techniques::gregory`, `techniques::acc`)
//! share. They differ in how the plan is made (isolation level by level, or one patch per base
//! face) and in [`PlanBuild::single_pass`]; [`PlannedPatches`] implements [`Technique`] once
//! for all three, exact where patches are regular and watertight everywhere:
//!
//! 1. **Plan (CPU, once; again when the sharpness scale changes):** the technique's planner
//!    (`topology::patches::adaptive`, or its `single_pass` module) isolates extraordinary
//!    vertices, non-quads and semi-sharp creases level by level with the crate's one sparse
//!    refiner, and flattens the result into stencil blocks (one per level, then the local
//!    points), patches (regular B-spline, Gregory or bilinear end caps) and canonical boundary
//!    curves.
//! 2. **Every frame (GPU):** the frame slot's base positions are copied into the head of the
//!    global vertex buffer, the stencil evaluator ([`crate::stencil`]) applies the blocks in
//!    place, one pass each (an animated base costs one upload of its positions), then the
//!    canonical kernel (`glsl/adaptive/canonical.comp`) evaluates the canonical corners of
//!    regular patches and each canonical curve's two inner points from their owner patches'
//!    control points (no stencil rows: a fixed combination per patch kind and corner or
//!    edge); then one draw per patch kind, one control point per patch.
//! 3. **Crack-free by construction:** every edge level comes from the edge's canonical
//!    curve(s) only, a coarse transition edge gets twice its fine halves' level (the seed's
//!    doubled factors: the tessellator makes the missing vertices, no T-junction), and every
//!    boundary vertex is evaluated on its canonical curve at a parameter both sides derive
//!    identically (see `glsl/adaptive/adaptive.glsl`), so shared edges are bit-identical
//!    under every factor policy, across transitions and end caps.
//!
//! 4. **Beyond the storage range:** the stencil evaluator windows everything it indexes
//!    (offsets, terms, and the vertex buffer as source and destination), in chunks of rows
//!    (`techniques::windows`; lavapipe allows 128 MiB per descriptor). The base copy is a
//!    transfer, which no range limits. The canonical kernel and the draw read the vertex
//!    buffer and every patch array by device address (`GL_EXT_buffer_reference`, the addresses
//!    in the uniform block [`AdaptiveArrays`]): no descriptor names them, so
//!    `maxStorageBufferRange` does not limit them and a plan is drawn whenever it fits in
//!    device memory (a 12,946-triangle CAD mesh at isolation 4 has 139 MB of vertices). Windows
//!    would not serve here: a patch reads its level's vertices, the canonical corners and the
//!    curve points, three far-apart ranges of one buffer. `bufferDeviceAddress` is required in
//!    Vulkan 1.3 and Tessera enables it; a host's device that did not is refused by name.
//!
//! The GPU data is [`layout`].
pub mod layout;
mod patterns;

use super::shared::{check_adaptive_policy, compute_pipeline, factor_fields, upload_base, STAGES};
use crate::animation::base_positions;
use crate::capture::FacePoint;
use crate::context::Context;
use crate::error::{Param, ParamError, Result, TessError};
use crate::gpu::bindings::{
    ADAPTIVE_ARRAYS_BINDING, ADAPTIVE_CANONICAL_MODE_CORNERS, ADAPTIVE_CANONICAL_MODE_CURVES,
    ADAPTIVE_EDGE_COARSE, ADAPTIVE_EDGE_PLAIN, ADAPTIVE_LOCAL_SIZE, ADAPTIVE_OPTION_FRACTIONAL,
    ADAPTIVE_OPTION_GEOMORPH, ADAPTIVE_OPTION_PATCH_COLOURS, ADAPTIVE_OPTION_POW2,
};
use crate::gpu::bindings::{
    ADAPTIVE_HEIGHT_BINDING, ADAPTIVE_OPTION_CANONICAL_NORMALS, ADAPTIVE_OPTION_DISPLACE,
    ADAPTIVE_OPTION_HEIGHT_MAP, ADAPTIVE_OPTION_REPARAM, ADAPTIVE_OPTION_SHOW_PARAM_ERROR,
    ADAPTIVE_OPTION_SHOW_PARAM_SHIFT, ADAPTIVE_OPTION_TEXTURE, ADAPTIVE_PARAM_ERROR_SIDE,
    ADAPTIVE_TEXTURE_BINDING,
};
use crate::gpu::{AdaptiveArrays, AdaptivePush};
use crate::shaders::Stage;
use crate::stencil::{self, StencilEvaluator, StencilVertices};
use crate::surface::{check_texcoords, SurfaceImage, SurfaceMaps, SurfaceShow};
use crate::technique::{
    for_each_draw, number_arrays, DeviceAllocation, DrawCounts, DrawPath, FactorPolicy, Features,
    FrameParams, Pass, PatchArray, PatchPipeline, PatchType, Technique, TechniqueId,
};
use crate::techniques::host_view::HostView;
use crate::techniques::{BuildOptions, Built, LegendEntry};
use crate::tessellator::{
    quad_triangle_count, triangle_triangle_count, uniform_vertex_count, Domain, Spacing,
};
use layout::GpuPlan;
use patterns::{key_of_kinds, PatternDraws};
use std::ops::Range;
use topology::patches::adaptive::single_pass::{
    plan_single_pass, SinglePassOptions, SinglePassPatch,
};
use topology::patches::adaptive::{AdaptivePlan, EndCap, PatchKind};
use topology::patches::fvar::{FVarPatches, FVarPlan};
use topology::ControlMesh;
use vk_core::descriptor::{BindingDesc, DescriptorPool};
use vk_core::pipeline::Pipeline;
use vk_core::texture::{Texture, TextureDesc, TextureFormat};
use vk_core::{vk, Buffer, BufferDesc, DescriptorSet, Encoder, MemoryLocation};

/// Default isolation level (OpenSubdiv's and the issue's).
pub const DEFAULT_ISOLATION: u32 = 4;

/// Set 1 of every adaptive pipeline: the arrays' addresses, the texture and the height map.
static SET_BINDINGS: [BindingDesc; 3] = [
    BindingDesc {
        binding: ADAPTIVE_ARRAYS_BINDING,
        ty: vk::DescriptorType::UNIFORM_BUFFER,
        stages: STAGES,
    },
    sampler_binding(ADAPTIVE_TEXTURE_BINDING),
    sampler_binding(ADAPTIVE_HEIGHT_BINDING),
];

/// Usage of every array the shaders read by address.
const BY_ADDRESS: vk::BufferUsageFlags = vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;

/// A combined image sampler of the set (the fragment stage reads the texture, the TES or the
/// pattern path's vertex stage both).
const fn sampler_binding(binding: u32) -> BindingDesc {
    BindingDesc {
        binding,
        ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        stages: vk::ShaderStageFlags::from_raw(
            vk::ShaderStageFlags::VERTEX.as_raw()
                | vk::ShaderStageFlags::TESSELLATION_EVALUATION.as_raw()
                | vk::ShaderStageFlags::FRAGMENT.as_raw(),
        ),
    }
}

/// The surface's images as textures: the given ones, or a neutral 1×1 texel (white; height 0).
fn surface_textures(device: &vk_core::Device, maps: &SurfaceMaps) -> Result<[Texture; 2]> {
    let make = |img: Option<&SurfaceImage>, what: &str, fallback: (TextureFormat, [u8; 4])| {
        let (name, w, h, format, texels) = match img {
            Some(i) => (i.name.as_str(), i.width, i.height, i.format, &i.texels[..]),
            None => (what, 1, 1, fallback.0, &fallback.1[..]),
        };
        Texture::new(
            device,
            &TextureDesc {
                name,
                width: w,
                height: h,
                format,
                mipmaps: format != TextureFormat::R32Float,
                repeat: true,
            },
            texels,
        )
    };
    Ok([
        make(
            maps.texture.as_deref(),
            "adaptive texture (none)",
            (TextureFormat::Rgba8Unorm, [255; 4]),
        )?,
        make(
            maps.height.as_deref(),
            "adaptive height map (none)",
            (TextureFormat::R32Float, 0f32.to_le_bytes()),
        )?,
    ])
}

/// One dispatch of the canonical kernel: `mode` (`ADAPTIVE_CANONICAL_MODE_*`) over `items`
/// (regular corners from the first one the kernel evaluates, or curve points).
#[derive(Clone, Debug, PartialEq, Eq)]
struct CanonicalStep {
    mode: u32,
    items: Range<u32>,
}

/// The canonical kernel's dispatches, at most `max_items` items each (the dispatch's group
/// count): the regular corners, then the curves' inner points.
fn plan_canonical(g: &GpuPlan, max_items: u32) -> Vec<CanonicalStep> {
    let max_items = max_items.max(1);
    let corners_from = g.first_regular_corner - g.first_corner;
    let mut steps = Vec::new();
    for (mode, items) in [
        (
            ADAPTIVE_CANONICAL_MODE_CORNERS,
            corners_from..corners_from + g.regular_corners(),
        ),
        (ADAPTIVE_CANONICAL_MODE_CURVES, 0..g.curve_points()),
    ] {
        let mut first = items.start;
        while first < items.end {
            let end = items.end.min(first.saturating_add(max_items));
            steps.push(CanonicalStep {
                mode,
                items: first..end,
            });
            first = end;
        }
    }
    steps
}

/// The Eq. 1 error lattice in array order when `options` ask for it, whether it has any entry,
/// and its summary; one 0 stands in for an empty or absent lattice (the view is then refused).
fn param_errors(
    mesh: &ControlMesh,
    plan: &AdaptivePlan,
    gpu: &GpuPlan,
    options: &PlanBuild,
) -> Result<(Vec<f32>, bool, ParamErrorNote)> {
    if !options.maps.param_error {
        return Ok((vec![0.0], false, None));
    }
    let lattice = topology::patches::texcoord::param_error_lattice(
        mesh,
        plan,
        ADAPTIVE_PARAM_ERROR_SIDE as usize,
    )
    .map_err(|e| TessError::Mesh {
        name: options.name.clone(),
        source: e.into(),
    })?;
    let summary = Some((lattice.summary(), lattice.reparameterized));
    let errors = gpu.param_errors(&lattice);
    if errors.is_empty() {
        return Ok((vec![0.0], false, summary));
    }
    Ok((errors, true, summary))
}

/// The Eq. 1 lattice's summary and the patches with a reparameterized corner, when built.
type ParamErrorNote = Option<(topology::patches::texcoord::ParamErrorSummary, usize)>;

/// The face-varying patches of `mesh`'s texture coordinates for a surface planned as `plan`
/// (`topology::patches::fvar`), or `None` where they are bilinear on each face (the mesh's
/// [`fvar_interpolation`](topology::rules::options::SubdivOptions::fvar_interpolation) is
/// `all`, or it has no texture coordinates).
pub fn fvar_patches(
    mesh: &ControlMesh,
    plan: &FVarPlan,
    name: &str,
) -> Result<Option<FVarPatches>> {
    topology::patches::fvar::texcoord_patches(mesh, plan)
        .transpose()
        .map_err(|e| TessError::Mesh {
            name: name.to_string(),
            source: e.into(),
        })
}

/// The arrays the canonical kernel and the draw read by address besides the vertices, in
/// [`AdaptiveArrays`] order: patch records, control points, curves, patch surfaces, the
/// reparameterization table, curve and corner owners, the error lattice and the face-varying
/// patches.
fn static_buffers(
    device: &vk_core::Device,
    gpu: &GpuPlan,
    plan: &AdaptivePlan,
    mesh: &ControlMesh,
    param_errors: &[f32],
    fvar: &[u32],
    fvar_patches: Option<&FVarPatches>,
) -> Result<[Buffer; 9]> {
    let surfaces = gpu.surfaces(plan, mesh, fvar_patches);
    let reparam = layout::reparam_rows();
    let arrays: [(&str, &[u8]); 9] = [
        ("adaptive patches", bytemuck::cast_slice(&gpu.patches)),
        (
            "adaptive control points",
            bytemuck::cast_slice(&gpu.control_points),
        ),
        ("adaptive curves", bytemuck::cast_slice(&gpu.curves)),
        ("adaptive patch surfaces", bytemuck::cast_slice(&surfaces)),
        (
            "adaptive reparameterization table",
            bytemuck::cast_slice(&reparam),
        ),
        (
            "adaptive curve owners",
            bytemuck::cast_slice(&gpu.curve_owners),
        ),
        (
            "adaptive corner owners",
            bytemuck::cast_slice(&gpu.corner_owners),
        ),
        (
            "adaptive Eq. 1 error lattice",
            bytemuck::cast_slice(param_errors),
        ),
        ("adaptive face-varying patches", bytemuck::cast_slice(fvar)),
    ];
    // An empty array is padded (zero-length buffers are invalid); nothing indexes it.
    let pad = [0u8; 16];
    let [p, c, k, s, r, o, q, e, f] = arrays.map(|(name, bytes)| {
        let data = if bytes.is_empty() { &pad[..] } else { bytes };
        Buffer::with_data(device, name, BY_ADDRESS, data)
    });
    Ok([p?, c?, k?, s?, r?, o?, q?, e?, f?])
}

/// The uniform buffer of [`AdaptiveArrays`]: the address of `vertices` and of each of `statics`.
fn address_table(
    device: &vk_core::Device,
    vertices: &Buffer,
    statics: &[Buffer; 9],
    param_error_count: u32,
    fvar_count: u32,
) -> Result<Buffer> {
    let a = |b: &Buffer| b.device_address();
    let table = AdaptiveArrays {
        vertices: a(vertices)?,
        patches: a(&statics[0])?,
        control_points: a(&statics[1])?,
        curves: a(&statics[2])?,
        surfaces: a(&statics[3])?,
        reparam: a(&statics[4])?,
        curve_owners: a(&statics[5])?,
        corner_owners: a(&statics[6])?,
        param_errors: a(&statics[7])?,
        param_error_count,
        fvar_count,
        fvar: a(&statics[8])?,
    };
    Ok(Buffer::with_data(
        device,
        "adaptive array addresses",
        vk::BufferUsageFlags::UNIFORM_BUFFER,
        bytemuck::bytes_of(&table),
    )?)
}

/// One base-position buffer per frame slot, holding `positions` as the stencil evaluator's
/// vertices (the source of the copy into the vertex buffer's head).
fn base_buffers(
    device: &vk_core::Device,
    frames: usize,
    positions: &[[f32; 3]],
) -> Result<Vec<Buffer>> {
    let vertices = stencil::vertices(positions);
    (0..frames)
        .map(|i| {
            let mut buf = Buffer::new(
                device,
                &BufferDesc {
                    name: &format!("adaptive base positions {i}"),
                    size: stencil::vertex_bytes(positions.len() as u32),
                    usage: vk::BufferUsageFlags::TRANSFER_SRC,
                    location: MemoryLocation::CpuToGpu,
                },
            )?;
            buf.write(0, bytemuck::cast_slice(&vertices))?;
            Ok(buf)
        })
        .collect()
}

/// The plan's arrays, one per patch kind with patches, on `path`: one control point per patch
/// on the tessellation path (it carries the patch), none on the pattern path.
fn patch_arrays(gpu: &GpuPlan, path: DrawPath) -> Vec<PatchArray> {
    let [regular, gregory, bilinear, triangles] = gpu.counts;
    let (types, control_points) = match path {
        DrawPath::Pattern => (
            [
                PatchType::PatternBSpline,
                PatchType::PatternGregory,
                PatchType::PatternBilinear,
                PatchType::PatternGregoryTriangle,
            ],
            0,
        ),
        _ => (
            [
                PatchType::BSpline,
                PatchType::Gregory,
                PatchType::Bilinear,
                PatchType::GregoryTriangle,
            ],
            1,
        ),
    };
    number_arrays(&[
        (types[0], regular, control_points),
        (types[1], gregory, control_points),
        (types[2], bilinear, control_points),
        (types[3], triangles, control_points),
    ])
}

/// Per array, how many of its patches have each combination of edge kinds.
fn edge_kind_counts(arrays: &[PatchArray], gpu: &GpuPlan) -> Vec<Vec<(u32, u64)>> {
    arrays
        .iter()
        .map(|a| {
            let mut counts = std::collections::BTreeMap::new();
            let range = a.first_patch as usize..(a.first_patch + a.patches) as usize;
            for p in &gpu.patches[range] {
                *counts.entry(p.edge_info & 0x3333).or_insert(0u64) += 1;
            }
            counts.into_iter().collect()
        })
        .collect()
}

/// What every planned surface takes; adaptive adds the isolation level, the single-pass
/// techniques their options.
pub const PLANNED: Features = Features {
    adaptive_factors: true,
    spacings: [true, true, false],
    animation: true,
    patch_colours: true,
    geometric_normals: false,
    phong_alpha: false,
    table_level: false,
    triangles_only: false,
    isolation: false,
    surface: true,
    single_pass: false,
    sine_displacement: true,
    paths: &[DrawPath::Tessellation, DrawPath::Pattern],
};

/// What the single-pass techniques (gregory, acc) take: the planned surface's options, no
/// isolation.
pub const SINGLE_PASS: Features = Features {
    single_pass: true,
    ..PLANNED
};

/// The patch-colour legend of the planned Catmull-Clark techniques.
pub const PATCH_LEGEND: &[LegendEntry] = &[
    ([0.45, 0.65, 0.95], "B-spline (odd levels lighter)"),
    ([0.95, 0.45, 0.35], "Gregory end cap"),
    ([0.95, 0.8, 0.3], "bilinear end cap"),
    ([0.3, 0.8, 0.35], "boundary / crease (greener)"),
];

/// How a planned surface is built (the per-frame choices are in [`FrameParams`]).
#[derive(Clone, Debug)]
pub struct PlanBuild {
    /// One patch per base face (gregory, acc): the patches are not C1 across edges, so normals
    /// come from the canonical tangents shared by both sides, and every frame takes the
    /// surface build.
    pub single_pass: bool,
    pub isolation: u32,
    pub end_cap: EndCap,
    /// Multiplies every crease and corner sharpness (the seed's run-time sharpness change).
    pub sharpness_scale: f32,
    /// Follow semi-sharp creases past the isolation level until they decay, then isolate the
    /// irregular vertices beside them `isolation` more levels (exact beside them); off, leftover sharpness is treated as infinite at the isolation level
    /// (OpenSubdiv's behaviour).
    pub follow_semi_sharp: bool,
    /// Name for messages (the mesh's file).
    pub name: String,
    /// Colour texture and height map sampled at the surface's texture coordinates.
    pub maps: SurfaceMaps,
    /// The tessellation stage, or refinement patterns ([`resolve_path`]).
    pub path: DrawPath,
    /// Every patch's `sub_face` is its base face's corner and its square lies in that corner's
    /// quad (`topology::limit::face_domain::subface_domain`), quads included (Doo-Sabin plans);
    /// otherwise a quad's patches lie in the whole face (Catmull-Clark plans).
    pub corner_quads: bool,
}

impl Default for PlanBuild {
    fn default() -> Self {
        Self {
            single_pass: false,
            isolation: DEFAULT_ISOLATION,
            end_cap: EndCap::Gregory,
            sharpness_scale: 1.0,
            follow_semi_sharp: true,
            name: "mesh".into(),
            maps: SurfaceMaps::default(),
            path: DrawPath::Tessellation,
            corner_quads: false,
        }
    }
}

/// A planned surface's draw path for `choice` on `device`. `auto` keeps the tessellation stage
/// wherever the device has one (on lavapipe the pattern path measured slower for these
/// surfaces, whose vertex stage gathers a patch's control points per vertex: docs/patterns.md)
/// and draws patterns where it has none.
pub fn resolve_path(
    technique: TechniqueId,
    choice: crate::technique::PipelineChoice,
    device: &vk_core::Device,
) -> Result<DrawPath> {
    match choice {
        crate::technique::PipelineChoice::Auto if device.info.caps.tessellation_shader => {
            Ok(DrawPath::Tessellation)
        }
        choice => choice.resolve(technique, PLANNED.paths, device),
    }
}

/// The level `edge_level` in `adaptive.glsl` gives an edge of kind `kind` under uniform factors
/// of `segments` per patch edge with the largest level `lim` (mirrored operation for
/// operation).
fn uniform_edge_level(lim: f32, segments: f32, spacing: Spacing, kind: u32) -> f32 {
    let fractional = spacing == Spacing::FractionalEven;
    if kind == ADAPTIVE_EDGE_PLAIN {
        if fractional {
            return segments.clamp(2.0, lim);
        }
        return segments.clamp(1.0, lim).ceil().min(lim);
    }
    let half = (lim * 0.5).floor();
    let f = if fractional {
        2.0 * (segments.clamp(2.0, half) * 0.5).ceil()
    } else {
        segments.clamp(1.0, half).ceil().min(half)
    };
    if kind == ADAPTIVE_EDGE_COARSE {
        2.0 * f
    } else {
        f
    }
}

/// Whether a frame of `params` on the pattern path geomorphs (fractional-even spacing there).
fn geomorphing(params: &FrameParams) -> bool {
    params.spacing == Spacing::FractionalEven
}

/// The base positions a host copy of the plan's vertices was computed from, and those vertices.
type HostVertices = (Vec<[f32; 3]>, Vec<[f64; 3]>);

/// One feature-adaptive Catmull-Clark surface on the GPU. Drop order: pipeline, sets (they
/// keep their pool alive), pool, buffers.
pub struct PlannedPatches {
    /// The technique drawing the plan (its pipelines and set layout are cached under it).
    id: TechniqueId,
    /// The levels and local points, in place in `vertices`.
    evaluator: StencilEvaluator,
    canonical: Pipeline,
    /// The set of the canonical kernel and the draw (every frame slot's: the slots differ
    /// only in the base positions, which are copied).
    set: DescriptorSet,
    /// The canonical kernel's dispatches, in order.
    steps: Vec<CanonicalStep>,
    _pool: DescriptorPool,
    /// Per frame slot, the base positions ([`stencil::StencilVertex`]), copied into the head
    /// of `vertices` every frame.
    base: Vec<Buffer>,
    /// The global vertex buffer.
    vertices: Buffer,
    /// The patch arrays and the uniform buffer of their addresses: the shaders read them (and
    /// `vertices`) by address, so they live as long as the technique.
    _static: Vec<Buffer>,
    _textures: [Texture; 2],
    arrays: Vec<PatchArray>,
    /// Per array: how many patches have each combination of edge kinds (the 2-bit kinds of
    /// `edge_info`), counted once so uniform triangle counts cost a few entries per call.
    edge_kinds: Vec<Vec<(u32, u64)>>,
    /// The refinement-pattern path's draws (`None` on the tessellation path).
    patterns: Option<PatternDraws>,
    /// The pattern path's host copy of the plan's vertices for host-chosen levels.
    host_vertices: Option<HostVertices>,
    pub gpu: GpuPlan,
    pub plan: AdaptivePlan,
    pub mesh: ControlMesh,
    pub base_positions: Vec<[f32; 3]>,
    rest_bbox: ([f32; 3], [f32; 3]),
    pub options: PlanBuild,
    max_level: f32,
    /// The Eq. 1 error lattice was built (`SurfaceMaps::param_error`).
    has_param_errors: bool,
    /// Its summary and the patches with a reparameterized corner, when built.
    param_error_summary: ParamErrorNote,
    /// Smooth texture coordinates (`None`: bilinear on each face), as uploaded.
    pub fvar: Option<FVarPatches>,
}

/// The device arrays of a plan and the descriptor set that binds them: the global vertex
/// buffer, the static arrays (patches, stencils, curves, owners, surfaces, the Eq. 1 lattice,
/// the face-varying patches) with their address table, and the surface textures.
struct PlanArrays {
    vertices: Buffer,
    /// The static arrays, then their address table.
    statics: Vec<Buffer>,
    textures: [Texture; 2],
    set: DescriptorSet,
    pool: DescriptorPool,
    has_param_errors: bool,
    param_error_summary: ParamErrorNote,
}

impl PlanArrays {
    fn new(
        ctx: &Context,
        id: TechniqueId,
        mesh: &ControlMesh,
        plan: &AdaptivePlan,
        gpu: &GpuPlan,
        fvar: Option<&FVarPatches>,
        options: &PlanBuild,
    ) -> Result<Self> {
        let device = ctx.device();
        let set_layout = ctx.set_layout(id)?;
        let pool = DescriptorPool::new(device, "adaptive descriptor pool", set_layout, 1)?;
        let vertices = Buffer::new(
            device,
            &BufferDesc {
                name: "adaptive vertices",
                size: gpu.vertex_bytes(),
                // Storage: the stencil evaluator binds windows of it.
                usage: vk::BufferUsageFlags::STORAGE_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_DST
                    | BY_ADDRESS,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        let (param_errors, has_param_errors, param_error_summary) =
            param_errors(mesh, plan, gpu, options)?;
        let fvar_words = layout::fvar_words(fvar);
        let statics = static_buffers(device, gpu, plan, mesh, &param_errors, &fvar_words, fvar)?;
        let error_count = if has_param_errors {
            param_errors.len() as u32
        } else {
            0
        };
        let fvar_count = u32::try_from(fvar_words.len()).map_err(|_| TessError::Mesh {
            name: options.name.clone(),
            source: format!(
                "face-varying patches of {} words exceed the u32 the shaders index with",
                fvar_words.len()
            )
            .into(),
        })?;
        let addresses = address_table(device, &vertices, &statics, error_count, fvar_count)?;
        let textures = surface_textures(device, &options.maps)?;
        let set = pool.allocate_set(set_layout)?;
        set.write_buffer(
            ADAPTIVE_ARRAYS_BINDING,
            vk::DescriptorType::UNIFORM_BUFFER,
            &addresses,
        )?;
        set.write_texture(ADAPTIVE_TEXTURE_BINDING, &textures[0])?;
        set.write_texture(ADAPTIVE_HEIGHT_BINDING, &textures[1])?;
        Ok(Self {
            vertices,
            statics: statics.into_iter().chain([addresses]).collect(),
            textures,
            set,
            pool,
            has_param_errors,
            param_error_summary,
        })
    }
}

/// The plan's compute work: the stencil evaluator of its levels and local points (in place in
/// `vertices`) and the canonical-curve kernel.
fn plan_kernels(
    ctx: &Context,
    id: TechniqueId,
    gpu: &GpuPlan,
    vertices: &Buffer,
) -> Result<(StencilEvaluator, Pipeline)> {
    let device = ctx.device();
    let evaluator = StencilEvaluator::new(
        device,
        "adaptive",
        &gpu.stencils,
        &gpu.blocks,
        StencilVertices {
            sources: gpu.num_vertices,
            destinations: gpu.num_vertices,
            in_place: true,
        },
        &[(vertices, vertices)],
    )?;
    let canonical = compute_pipeline(
        device,
        "adaptive canonical points",
        Stage::AdaptiveCanonicalComp,
        &[ctx.frame_set_layout().raw, ctx.set_layout(id)?.raw],
        std::mem::size_of::<AdaptivePush>(),
    )?;
    Ok((evaluator, canonical))
}

impl PlannedPatches {
    /// Uploads a plan, drawn as technique `id`, with one base-position buffer per frame slot
    /// of `ctx`, and the face-varying patches `fvar` made for it ([`fvar_patches`]).
    pub fn from_plan(
        ctx: &mut Context,
        mesh: &ControlMesh,
        plan: AdaptivePlan,
        fvar: Option<FVarPatches>,
        options: &PlanBuild,
        id: TechniqueId,
    ) -> Result<Self> {
        let device = ctx.device().clone();
        if !device.info.caps.buffer_device_address {
            return Err(TessError::Unsupported {
                technique: id,
                what: "a device without bufferDeviceAddress enabled (the planned patches read \
                       their arrays by address; a host device sets buffer_device_address)",
            });
        }
        let gpu = GpuPlan::new(&plan).map_err(|e| TessError::Mesh {
            name: options.name.clone(),
            source: e.into(),
        })?;
        ctx.ensure_set_layout(id, &SET_BINDINGS)?;
        let max_groups = device.info.caps.max_compute_work_group_count[0];
        let steps = plan_canonical(&gpu, max_groups.saturating_mul(ADAPTIVE_LOCAL_SIZE));
        let a = PlanArrays::new(ctx, id, mesh, &plan, &gpu, fvar.as_ref(), options)?;
        let (evaluator, canonical) = plan_kernels(ctx, id, &gpu, &a.vertices)?;
        let base_positions = base_positions(mesh);
        let base = base_buffers(&device, ctx.frames_in_flight(), &base_positions)?;
        let arrays = patch_arrays(&gpu, options.path);
        let edge_kinds = edge_kind_counts(&arrays, &gpu);
        let patterns = match options.path {
            DrawPath::Pattern => Some(PatternDraws::new(&device, &arrays, &gpu)?),
            _ => None,
        };
        // The pattern path keeps the tessellator's bound, so both paths give a patch the same
        // edge levels.
        let max_level = match options.path {
            DrawPath::Pattern => crate::tessellator::MAX_LEVEL,
            _ => device.info.caps.max_tessellation_generation_level as f32,
        };
        Ok(Self {
            id,
            evaluator,
            canonical,
            set: a.set,
            steps,
            _pool: a.pool,
            base,
            vertices: a.vertices,
            _static: a.statics,
            _textures: a.textures,
            arrays,
            edge_kinds,
            patterns,
            host_vertices: None,
            gpu,
            plan,
            mesh: mesh.clone(),
            rest_bbox: crate::framing::drawn_bbox(mesh),
            base_positions,
            options: options.clone(),
            max_level,
            has_param_errors: a.has_param_errors,
            param_error_summary: a.param_error_summary,
            fvar,
        })
    }

    /// What the Eq. 1 lattice says over the whole surface, for the command line (`None` when
    /// it was not built).
    pub fn param_error_note(&self) -> Option<String> {
        let (summary, reparameterized) = self.param_error_summary?;
        let ([rms0, rms1], [max0, max1]) = (summary.rms, summary.max);
        Some(format!(
            "{}: Eq. 1 texture error over the bbox diagonal ({}² lattice per patch, rest pose): \
             RMS {rms0:.2e} / max {max0:.2e} without the reparameterization, RMS {rms1:.2e} / \
             max {max1:.2e} with it ({reparameterized} of {} patches have a reparameterized corner)",
            self.options.name,
            ADAPTIVE_PARAM_ERROR_SIDE,
            self.plan.patches.len()
        ))
    }

    /// The stencil evaluator's dispatches and window sets: more than one set when a buffer it
    /// indexes (stencil tables, vertices) exceeds the storage range.
    pub fn chunk_counts(&self) -> (usize, usize) {
        self.evaluator.counts()
    }

    /// Patches of each kind: regular, Gregory, bilinear, Gregory triangle.
    pub fn patch_counts(&self) -> [u32; 4] {
        self.gpu.counts
    }

    /// The largest per-edge level a policy can ask for (transition edges take half of it).
    fn factor_limit(&self) -> f32 {
        self.max_level
    }

    fn push(&self, params: &FrameParams, mode: u32) -> AdaptivePush {
        let (factor_mode, uniform_level, pixels, reference) = factor_fields(params.factors);
        let fractional = params.spacing == Spacing::FractionalEven;
        let adaptive = !matches!(params.factors, FactorPolicy::Uniform { .. });
        let mut options = 0;
        if params.patch_colours {
            options |= ADAPTIVE_OPTION_PATCH_COLOURS;
        }
        let show = params.show;
        if self.options.maps.texture.is_some()
            && !params.patch_colours
            && show == SurfaceShow::Shading
        {
            options |= ADAPTIVE_OPTION_TEXTURE;
        }
        if params.reparam {
            options |= ADAPTIVE_OPTION_REPARAM;
        }
        if params.displace != 0.0 {
            options |= ADAPTIVE_OPTION_DISPLACE;
        }
        if self.options.maps.height.is_some() {
            options |= ADAPTIVE_OPTION_HEIGHT_MAP;
        }
        match show {
            SurfaceShow::Shading => {}
            SurfaceShow::ParamShift => options |= ADAPTIVE_OPTION_SHOW_PARAM_SHIFT,
            SurfaceShow::ParamError => options |= ADAPTIVE_OPTION_SHOW_PARAM_ERROR,
        }
        if self.options.single_pass {
            options |= ADAPTIVE_OPTION_CANONICAL_NORMALS;
        }
        if fractional && self.patterns.is_some() {
            // Patterns keep whole levels: their odd vertices morph instead.
            options |= ADAPTIVE_OPTION_GEOMORPH;
        } else if fractional {
            options |= ADAPTIVE_OPTION_FRACTIONAL;
        } else if adaptive {
            options |= ADAPTIVE_OPTION_POW2;
        }
        AdaptivePush {
            mode,
            first_patch: 0,
            factor_mode,
            options,
            uniform_level,
            pixels_per_segment: pixels,
            distance_ref: reference,
            max_level: self.factor_limit(),
            first_item: 0,
            count: 0,
            displace_scale: params.displace,
            first_corner: self.gpu.first_corner,
            pattern_outer: [0.0; 4],
        }
    }

    /// [`uniform_edge_level`] with the surface's largest level.
    fn uniform_edge_level(&self, segments: f32, spacing: Spacing, kind: u32) -> f32 {
        uniform_edge_level(self.factor_limit(), segments, spacing, kind)
    }

    /// Makes `host_vertices` the plan's vertices from the current base positions, on
    /// the host (again only when the base moved).
    fn update_host_vertices(&mut self) {
        let stale = self
            .host_vertices
            .as_ref()
            .is_none_or(|(base, _)| *base != self.base_positions);
        if stale {
            let base: Vec<[f64; 3]> = self
                .base_positions
                .iter()
                .map(|p| p.map(f64::from))
                .collect();
            let vertices = self.plan.apply(&base);
            self.host_vertices = Some((self.base_positions.clone(), vertices));
        }
    }

    /// The pattern path's key of a group of array `array` with edge kinds `kinds` under
    /// `params` (uniform factors; [`Technique::check`] refuses others there).
    fn pattern_keys(
        &self,
        params: &FrameParams,
    ) -> impl Fn(usize, u32) -> crate::pattern::PatternKey {
        let domains: Vec<Domain> = self.arrays.iter().map(|a| a.patch.domain()).collect();
        let (lim, spacing) = (self.factor_limit(), params.spacing);
        let segments = params.uniform_segments().unwrap_or(1.0);
        move |array, kinds| {
            let domain = domains.get(array).copied().unwrap_or(Domain::Quad);
            key_of_kinds(domain, spacing, kinds, |k| {
                uniform_edge_level(lim, segments, spacing, k)
            })
        }
    }

    /// The texture coordinate patch `patch` (frame-wide id) shows at patch coordinate `(u, v)`,
    /// as the TES computes it (`glsl/adaptive/surface.glsl`'s `texcoord_at`, in `f64`): the
    /// texture parameter (Eq. 3's when `reparam`), then the corners' bilinear blend, then,
    /// with face-varying patches, their look-up at that (sub-)face parameter. `None` for an
    /// unknown patch, a mesh without texture coordinates or a corner-quad plan
    /// ([`PlanBuild::corner_quads`]).
    pub fn texcoord_at(&self, patch: u32, u: f64, v: f64, reparam: bool) -> Option<[f64; 2]> {
        // A corner-quad plan's patches are not numbered over the whole quad the look-up assumes.
        if self.options.corner_quads {
            return None;
        }
        let pi = *self.gpu.order.get(patch as usize)?;
        let p = self.plan.patches.get(pi as usize)?;
        let [s, t] = topology::patches::texcoord::patch_parameter(p, u, v, reparam);
        // As `layout::GpuPlan::surfaces` and the TES: a patch without a root keeps its
        // bilinear corners; a descent that finds no leaf gives the parameter itself.
        let root = self
            .fvar
            .as_ref()
            .map_or(topology::patches::fvar::FVAR_EMPTY, |f| f.root_of(p));
        if let (Some(f), false) = (&self.fvar, root == topology::patches::fvar::FVAR_EMPTY) {
            let param = if p.kind == PatchKind::GregoryTriangle {
                [s, t]
            } else {
                let [u0, v0] = p.origin;
                [u0 + p.size * s, v0 + p.size * t]
            };
            return Some(f.texcoord(root, param).unwrap_or(param));
        }
        let corners = topology::patches::texcoord::patch_corners(&self.mesh, p)?;
        Some(topology::patches::texcoord::bilinear(&corners, s, t))
    }

    /// Where patch `patch` (frame-wide id) at patch coordinate `(u, v)` lies in its base face:
    /// `(base face, sub-face, u, v)` in `topology::limit::eval`'s convention (sub-quads of
    /// non-quads as `LocalMesh::evaluate_subface` numbers them).
    pub fn base_param(&self, patch: u32, u: f64, v: f64) -> Option<(u32, u8, f64, f64)> {
        let pi = *self.gpu.order.get(patch as usize)?;
        let p = self.plan.patches.get(pi as usize)?;
        let (sub, s, t) = p.base_param(u, v);
        Some((p.base_face, sub, s, t))
    }
}

/// How a single-pass surface is built ([`single_pass`]).
pub struct SinglePassBuild<'a> {
    /// Gregory (`--method gregory`) or ACC-1 (`--method acc`).
    pub patch: SinglePassPatch,
    pub sharpness_scale: f32,
    /// One Gregory triangle patch per triangle (else triangles are split once).
    pub gregory_triangles: bool,
    /// Name for messages (the mesh's file).
    pub name: &'a str,
    pub maps: &'a crate::surface::SurfaceMaps,
    pub path: DrawPath,
}

/// Plans `mesh` one patch per base face and uploads it.
pub fn single_pass(
    ctx: &mut Context,
    mesh: &ControlMesh,
    build: &SinglePassBuild,
) -> Result<PlannedPatches> {
    let name = build.name;
    check_texcoords(mesh, build.maps, name)?;
    let plan_options = SinglePassOptions {
        patch: build.patch,
        sharpness_scale: build.sharpness_scale,
        gregory_triangles: build.gregory_triangles,
    };
    let plan = plan_single_pass(mesh, &plan_options).map_err(|e| TessError::Mesh {
        name: name.to_string(),
        source: e.into(),
    })?;
    let fvar = fvar_patches(mesh, &FVarPlan::SinglePass(plan_options), name)?;
    let id = match build.patch {
        SinglePassPatch::Gregory => TechniqueId::GREGORY,
        SinglePassPatch::Acc1 => TechniqueId::ACC,
    };
    PlannedPatches::from_plan(
        ctx,
        mesh,
        plan,
        fvar,
        &PlanBuild {
            single_pass: true,
            isolation: 1,
            sharpness_scale: build.sharpness_scale,
            follow_semi_sharp: false,
            name: name.to_string(),
            maps: build.maps.clone(),
            path: build.path,
            ..PlanBuild::default()
        },
        id,
    )
}

/// The registry constructor of a single-pass technique: [`single_pass`] with `patch` and the
/// build options the single-pass techniques take.
pub fn build_single_pass(
    ctx: &mut Context,
    mesh: &ControlMesh,
    options: &BuildOptions,
    patch: SinglePassPatch,
) -> Result<Built> {
    let id = match patch {
        SinglePassPatch::Gregory => TechniqueId::GREGORY,
        SinglePassPatch::Acc1 => TechniqueId::ACC,
    };
    let surface = single_pass(
        ctx,
        mesh,
        &SinglePassBuild {
            patch,
            sharpness_scale: options.sharpness_scale,
            gregory_triangles: !options.split_triangles,
            name: &options.name,
            maps: &options.maps,
            path: resolve_path(id, options.pipeline, ctx.device())?,
        },
    )?;
    Ok(Built {
        notes: surface.param_error_note().into_iter().collect(),
        technique: Box::new(surface),
    })
}

/// What a planned surface refuses in `params`: uniform factors are whole segments per patch
/// edge, at most half the device's maximum `factor_limit` (a coarse transition edge doubles
/// them) when it is known; spacing equal or fractional even. Without a device ([`crate::techniques::check_options`])
/// only the bound waits for [`Technique::check`].
pub fn check_frame(
    technique: TechniqueId,
    factor_limit: Option<f32>,
    params: &FrameParams,
) -> Result<()> {
    if params.spacing == Spacing::FractionalOdd {
        return Err(TessError::Unsupported {
            technique,
            what: "fractional-odd spacing (transition edges need even levels: use fractional-even spacing)",
        });
    }
    let half = factor_limit.map_or(f32::INFINITY, |l| (l * 0.5).floor());
    if let FactorPolicy::Uniform { segments } = params.factors {
        if segments.fract() != 0.0 || segments < 1.0 || segments > half {
            return Err(ParamError::refused(
                Param::Segments,
                segments,
                "expected whole segments per patch edge, 1 up to half the device's maximum \
                 tessellation level (transition edges double it)",
            ));
        }
    }
    check_adaptive_policy(params)
}

impl Technique for PlannedPatches {
    fn id(&self) -> TechniqueId {
        self.id
    }

    fn bbox(&self) -> ([f32; 3], [f32; 3]) {
        self.rest_bbox
    }

    fn patch_arrays(&self) -> &[PatchArray] {
        &self.arrays
    }

    /// [`check_frame`] with the device's maximum level.
    fn check(&self, params: &FrameParams) -> Result<()> {
        if params.show == SurfaceShow::ParamError && !self.has_param_errors {
            return Err(TessError::Unsupported {
                technique: self.id,
                what: "the param-error view on a surface built without its Eq. 1 error lattice (build with SurfaceMaps::param_error)",
            });
        }
        // On the pattern path fractional-even spacing is geomorphing between power-of-two
        // levels (`patterns` module docs, step 5), which takes any uniform level in range, not
        // only whole ones; `check_frame` refuses fractional-odd.
        match params.factors {
            FactorPolicy::Uniform { segments }
                if self.patterns.is_some() && geomorphing(params) =>
            {
                let whole = FrameParams {
                    factors: FactorPolicy::Uniform {
                        segments: if segments.is_finite() {
                            segments.ceil()
                        } else {
                            segments
                        },
                    },
                    ..*params
                };
                check_frame(self.id, Some(self.factor_limit()), &whole)
            }
            _ => check_frame(self.id, Some(self.factor_limit()), params),
        }
    }

    fn patch_pipeline(&self, patch: PatchType) -> PatchPipeline {
        // The texture look-up of face-varying patches only where there are some (its code
        // costs every vertex on lavapipe).
        let axes = crate::shaders::Variant {
            face_varying: self.fvar.is_some(),
            ..Default::default()
        };
        let push_constant_bytes = std::mem::size_of::<AdaptivePush>() as u32;
        if patch.path() == DrawPath::Pattern {
            let vertex = match patch {
                PatchType::PatternGregory => Stage::AdaptivePatternGregoryVert,
                PatchType::PatternBilinear => Stage::AdaptivePatternBilinearVert,
                PatchType::PatternGregoryTriangle => Stage::AdaptivePatternTriangleVert,
                _ => Stage::AdaptivePatternRegularVert,
            };
            return PatchPipeline {
                push_constant_bytes,
                axes,
                vertex_input: crate::gpu::pattern_input::PATCH_IDS,
                ..PatchPipeline::triangles(vertex, Stage::AdaptiveAdaptiveFrag)
            };
        }
        // Regular and Gregory control stages fetch the patch's points once (Bezier net,
        // Gregory points); the bilinear cap reads only its curves.
        let (control, evaluation) = match patch {
            PatchType::Gregory => (Stage::AdaptiveGregoryTesc, Stage::AdaptiveGregoryTese),
            PatchType::Bilinear => (Stage::AdaptivePatchTesc, Stage::AdaptiveBilinearTese),
            PatchType::GregoryTriangle => {
                (Stage::AdaptiveTriangleTesc, Stage::AdaptiveTriangleTese)
            }
            _ => (Stage::AdaptiveRegularTesc, Stage::AdaptiveRegularTese),
        };
        PatchPipeline {
            push_constant_bytes,
            axes,
            ..PatchPipeline::tessellated(
                Stage::AdaptivePatchVert,
                control,
                evaluation,
                Stage::AdaptiveAdaptiveFrag,
                1,
            )
        }
    }

    fn set_layout_bindings(&self) -> &'static [BindingDesc] {
        &SET_BINDINGS
    }

    /// A shown texture, displacement (height map or sine), parameter view or patch colours, or
    /// the single-pass methods' canonical normals (and ACC-1's tangent patches) need the
    /// surface build; adaptive's plain frames do not (and hand the rasterizer no albedo or
    /// texture varying).
    fn surface_build(&self, params: &FrameParams) -> bool {
        self.options.single_pass
            || params.displace != 0.0
            || params.displace_sine[0] != 0.0
            || params.show != SurfaceShow::Shading
            || params.patch_colours
            || self.options.maps.texture.is_some()
    }

    fn descriptor_set(&self, _slot: usize) -> Option<&DescriptorSet> {
        Some(&self.set)
    }

    /// At the largest level an edge can get (a coarse transition edge's doubled level).
    fn max_vertices_per_patch(&self, params: &FrameParams, array: usize) -> u64 {
        if let Some(p) = &self.patterns {
            return p.max_vertices(array, &self.pattern_keys(params));
        }
        let max = match params.factors {
            FactorPolicy::Uniform { segments } => 2.0 * segments,
            _ => self.factor_limit(),
        };
        let domain = self
            .arrays
            .get(array)
            .map_or(Domain::Quad, |a| a.patch.domain());
        uniform_vertex_count(domain, params.spacing, max.min(self.factor_limit()))
    }

    /// Exact for uniform factors: each patch's edge levels as `patch.tesc` sets them (a
    /// coarse transition edge doubled), counted by the tessellator's arithmetic.
    fn triangles(&self, params: &FrameParams, array: usize) -> Option<u64> {
        if let Some(p) = &self.patterns {
            return p.triangles(array, &self.pattern_keys(params));
        }
        let FactorPolicy::Uniform { segments } = params.factors else {
            return None;
        };
        let triangle = self.arrays.get(array)?.patch.domain() == Domain::Triangle;
        Some(
            self.edge_kinds
                .get(array)?
                .iter()
                .map(|&(kinds, n)| {
                    let e = |k: u32| {
                        self.uniform_edge_level(segments, params.spacing, (kinds >> (4 * k)) & 3)
                    };
                    let (e0, e1, e2, e3) = (e(0), e(1), e(2), e(3));
                    if triangle {
                        // triangle.tesc: outer 0 is edge 2, 1 edge 0, 2 edge 1.
                        return n * triangle_triangle_count(
                            params.spacing,
                            [e2, e0, e1],
                            e0.max(e1).max(e2),
                        );
                    }
                    n * quad_triangle_count(
                        params.spacing,
                        [e3, e0, e1, e2],
                        [e0.max(e2), e1.max(e3)],
                    )
                })
                .sum(),
        )
    }

    fn base_mesh(&self) -> Option<&ControlMesh> {
        Some(&self.mesh)
    }

    fn update_base(&mut self, slot: usize, positions: &[[f32; 3]]) -> Result<()> {
        self.base_positions =
            upload_base(&mut self.base, slot, positions, self.base_positions.len())?;
        Ok(())
    }

    /// On the pattern path, takes the frame's patterns (one per edge-level key) from the
    /// context; under screen-space and distance factors the host chooses each patch's levels
    /// first (`patterns` module docs, step 4).
    fn prepare_frame(&mut self, ctx: &mut Context, params: &FrameParams) -> Result<()> {
        if self.patterns.is_none() {
            return Ok(());
        }
        let morph = geomorphing(params);
        if matches!(params.factors, FactorPolicy::Uniform { .. }) && !morph {
            let keys = self.pattern_keys(params);
            return match &mut self.patterns {
                Some(p) => p.prepare(ctx, &keys),
                None => Ok(()),
            };
        }
        let view = *ctx
            .frame_view()
            .ok_or(TessError::NoFrameView { technique: self.id })?;
        let segments = params.uniform_segments().unwrap_or(1.0);
        let host = HostView::new(&view, params.factors, segments, self.factor_limit(), morph);
        self.update_host_vertices();
        let vertices = self
            .host_vertices
            .as_ref()
            .map_or(&[][..], |(_, v)| v.as_slice());
        let factors = host.curve_factors(&self.plan, vertices);
        let (gpu, arrays) = (&self.gpu, &self.arrays);
        let key_of = |array: usize, id: u32| {
            let domain = arrays.get(array).map_or(Domain::Quad, |a| a.patch.domain());
            match gpu.patches.get(id as usize) {
                Some(p) => host.key(domain, p, &factors),
                None => (
                    crate::pattern::PatternKey::new(domain, Spacing::Equal, 1.0),
                    crate::techniques::host_view::NO_MORPH,
                ),
            }
        };
        match &mut self.patterns {
            Some(p) => p.prepare_host_levels(ctx, arrays, &key_of),
            None => Ok(()),
        }
    }

    /// The base copy, the stencil evaluator's blocks, then the canonical kernel: each step
    /// reads what the steps before it wrote, so each is ordered after them.
    fn record_pre_pass<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        frame_set: &'a DescriptorSet,
        slot: usize,
    ) -> Result<()> {
        let slots = self.base.len();
        let base = self
            .base
            .get(slot)
            .ok_or(TessError::FrameSlot { slot, slots })?;
        // The stages that read the vertices: the pattern path's vertex stage alone (a device
        // without tessellation shaders may name no tessellation stage in a barrier).
        let tess_stages = match self.patterns {
            Some(_) => vk::PipelineStageFlags::VERTEX_SHADER,
            None => {
                vk::PipelineStageFlags::VERTEX_SHADER
                    | vk::PipelineStageFlags::TESSELLATION_CONTROL_SHADER
                    | vk::PipelineStageFlags::TESSELLATION_EVALUATION_SHADER
            }
        };
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        let ordered = (
            compute,
            vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
        );
        enc.begin_label("adaptive subdivision tables");
        if let Some(p) = &self.patterns {
            p.record_ids(enc)?;
        }
        // The previous frame's tessellation stages read the vertices before we overwrite them;
        // host writes of the base positions are visible at submit.
        enc.memory_barrier(
            (tess_stages, vk::AccessFlags::SHADER_READ),
            (
                transfer | compute,
                vk::AccessFlags::TRANSFER_WRITE | vk::AccessFlags::SHADER_WRITE,
            ),
        );
        enc.copy_buffer(base, &self.vertices)?;
        enc.memory_barrier((transfer, vk::AccessFlags::TRANSFER_WRITE), ordered);
        self.evaluator.record(enc, 0)?;
        enc.bind_pipeline(&self.canonical);
        enc.bind_descriptor_sets(0, &[frame_set, &self.set])?;
        for step in &self.steps {
            // Each step reads what the ones before it wrote (the curve points read the corners).
            enc.memory_barrier((compute, vk::AccessFlags::SHADER_WRITE), ordered);
            let push = AdaptivePush {
                mode: step.mode,
                first_item: step.items.start,
                count: step.items.end - step.items.start,
                first_corner: self.gpu.first_corner,
                ..Default::default()
            };
            enc.push_constants(&push)?;
            enc.dispatch([push.count.div_ceil(ADAPTIVE_LOCAL_SIZE), 1, 1])?;
        }
        // The last step (or the copy, for a plan without rows or canonical points) feeds the
        // tessellation stages.
        enc.memory_barrier(
            (
                compute | transfer,
                vk::AccessFlags::SHADER_WRITE | vk::AccessFlags::TRANSFER_WRITE,
            ),
            (tess_stages, vk::AccessFlags::SHADER_READ),
        );
        enc.end_label();
        Ok(())
    }

    fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        _slot: usize,
        params: &FrameParams,
        pass: Pass,
        per_draw: u32,
    ) -> Result<DrawCounts> {
        let a = *self
            .arrays
            .get(array)
            .ok_or(TessError::NoPatchArray { array })?;
        let mut push = self.push(params, pass.mode());
        push.first_patch = a.first_patch;
        if let Some(p) = &self.patterns {
            return p.record(enc, array, &self.pattern_keys(params), push);
        }
        enc.push_constants(&push)?;
        for_each_draw(a.patches, per_draw, |first, n| {
            enc.draw(first..first + n)?;
            Ok(())
        })
    }

    /// The patch's point in its base face; a sub-quad of a non-quad maps bilinearly into the
    /// face's domain ([`face_corner_uv`](topology::limit::face_domain::face_corner_uv)): corner, edge
    /// midpoint, centre, edge midpoint.
    fn texcoord(&self, patch: u32, domain: [f32; 2], reparam: bool) -> Option<[f64; 2]> {
        self.texcoord_at(patch, domain[0] as f64, domain[1] as f64, reparam)
    }

    fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint> {
        let (face, sub, u, v) = self.base_param(patch, domain[0] as f64, domain[1] as f64)?;
        let n = self.mesh.face(face as usize).len() as u32;
        if n == 4 && !self.options.corner_quads {
            return Some(FacePoint {
                face,
                u: u as f32,
                v: v as f32,
            });
        }
        let quad = topology::limit::face_domain::subface_domain(n, sub as u32);
        let uv = topology::limit::face_domain::bilinear(&quad, u, v);
        Some(FacePoint {
            face,
            u: uv[0] as f32,
            v: uv[1] as f32,
        })
    }

    /// Per frame slot, the base positions; the vertex buffer (refined and local points), the
    /// stencils, patch records, control points, curves, patch surfaces, reparameterization
    /// table and curve and corner owners; the colour texture and height map (1×1 when none).
    fn device_memory(&self) -> Vec<DeviceAllocation> {
        let buffers = self
            .base
            .iter()
            .chain([&self.vertices])
            .chain(self.evaluator.buffers())
            .chain(&self._static)
            .chain(self.patterns.iter().flat_map(|p| p.buffers()))
            .map(DeviceAllocation::of_buffer)
            .chain(self._textures.iter().map(DeviceAllocation::of_texture));
        DeviceAllocation::merged(buffers)
    }

    fn report_notes(&self) -> Vec<String> {
        let [r, g, b, t] = self.gpu.counts;
        if self.options.single_pass {
            return vec![format!(
                "{}: {r} B-spline, {g} Gregory/ACC-1 and {t} Gregory triangle patches for {} base faces ({}), {} vertices, tables {} bytes",
                self.id,
                self.mesh.num_faces(),
                if self.plan.isolation == 0 {
                    "one patch per face"
                } else {
                    "faces next to non-quads split by one step"
                },
                self.gpu.num_vertices,
                self.gpu.table_bytes()
            )];
        }
        vec![format!(
            "{}: isolation {}, {r} regular patches, {g} Gregory and {b} bilinear end caps, \
             {} vertices ({} refined + local), tables {} bytes",
            self.id,
            self.plan.isolation,
            self.gpu.num_vertices,
            self.gpu.num_vertices - self.gpu.num_base_vertices,
            self.gpu.table_bytes()
        )]
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;
    use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions};

    /// The layout of `catmark_cube_creases0` at isolation 2 (the stencil evaluator's tests use
    /// it too).
    pub(crate) fn cube_layout() -> GpuPlan {
        let mesh = topology::load_obj(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/data/opensubdiv/shapes/catmark_cube_creases0.obj"
        ))
        .expect("cube");
        let plan = plan_adaptive(
            &mesh,
            &AdaptiveOptions {
                isolation: 2,
                ..Default::default()
            },
        )
        .expect("plan");
        GpuPlan::new(&plan).expect("layout")
    }

    /// A frame writes every vertex once: the base copy `0..num_base_vertices`, then the
    /// evaluator's blocks in order up to the regular corners, then the canonical kernel's
    /// steps, the corners and then the curve points, in order and at most `max_items` each.
    #[test]
    fn the_pre_pass_writes_every_vertex_once_in_order() {
        let g = cube_layout();
        let mut next = g.num_base_vertices;
        for b in &g.blocks {
            assert_eq!(
                b.destination, next,
                "blocks follow the base copy, no gap or overlap"
            );
            assert_eq!(b.rows.start + g.num_base_vertices, b.destination);
            next = b.destinations().end;
        }
        assert_eq!(next, g.first_regular_corner);
        let steps = plan_canonical(&g, 100);
        let split = steps
            .iter()
            .position(|s| s.mode == ADAPTIVE_CANONICAL_MODE_CURVES)
            .expect("curve steps");
        let corners_from = g.first_regular_corner - g.first_corner;
        let mut next_corner = corners_from;
        for s in &steps[..split] {
            assert_eq!(s.mode, ADAPTIVE_CANONICAL_MODE_CORNERS);
            assert_eq!(s.items.start, next_corner);
            assert!(s.items.len() <= 100);
            next_corner = s.items.end;
        }
        assert_eq!(next_corner - corners_from, g.regular_corners());
        assert_eq!(
            g.first_corner + next_corner,
            g.first_curve_point,
            "the corners end where the curve points begin"
        );
        // The curve points come last, in order, after every row.
        let mut next_point = 0;
        for s in &steps[split..] {
            assert_eq!(s.mode, ADAPTIVE_CANONICAL_MODE_CURVES);
            assert_eq!(s.items.start, next_point);
            assert!(s.items.len() <= 100);
            next_point = s.items.end;
        }
        assert_eq!(next_point, g.curve_points());
        assert!(next_point > 0);
        assert_eq!(g.first_curve_point + next_point, g.num_vertices);
        assert_eq!(
            plan_canonical(&g, u32::MAX).len(),
            2,
            "one dispatch per mode"
        );
    }
}
