//! Feature-adaptive Catmull-Clark on the tessellation stage (Nießner et al. 2012; the seed's
//! §3–4), exact where patches are regular and watertight everywhere:
//!
//! 1. **Plan (CPU, once; again when the sharpness scale changes):** `topology::patches::adaptive`
//!    isolates extraordinary vertices, non-quads and semi-sharp creases level by level with
//!    the crate's one sparse refiner, and flattens the result into stencil blocks (one per
//!    level, then the local points), patches (regular B-spline, Gregory or bilinear end caps)
//!    and canonical boundary curves.
//! 2. **Every frame (GPU):** the stencil kernel (`glsl/adaptive/stencil.comp`) copies the base
//!    positions and applies one block per dispatch (an animated base costs one upload of its
//!    positions), then evaluates the canonical corners of regular patches and each
//!    canonical curve's two inner points from their owner patches' control points (no stencil
//!    rows: a fixed combination per patch kind and corner or edge);
//!    then one draw per patch kind, one control point per patch.
//! 3. **Crack-free by construction:** every edge level comes from the edge's canonical
//!    curve(s) only, a coarse transition edge gets twice its fine halves' level (the seed's
//!    doubled factors: the tessellator makes the missing vertices, no T-junction), and every
//!    boundary vertex is evaluated on its canonical curve at a parameter both sides derive
//!    identically (see `glsl/adaptive/adaptive.glsl`), so shared edges are bit-identical
//!    under every factor policy, across transitions and end caps.
//!
//! 4. **Beyond the storage range:** a block whose stencil terms (or row offsets) exceed
//!    `maxStorageBufferRange` (lavapipe allows 128 MiB; a 1M-quad grid's terms were 264 MB
//!    before its regular corners and curve points were evaluated from their patches)
//!    runs as several dispatches, chunks of rows planned by `techniques::windows`: a row's
//!    terms are one contiguous run of the term buffer, so each chunk binds only its windows of
//!    the offsets and the terms and the kernel subtracts the window bases (push constants).
//!    The vertex buffer, the base positions and the patch buffers (records, control points,
//!    curves) are bound whole: one that exceeds the range is refused with vk-core's typed
//!    range error naming the buffer, never a silent overrun.
//!
//! The GPU data is [`layout`].
pub mod layout;

use super::shared::{
    canonical_zero, check_adaptive_policy, factor_fields, storage, storage_binding,
};
use super::windows::{self, Limits, Member, Space};
use crate::capture::FacePoint;
use crate::context::Context;
use crate::error::{Param, ParamError, Result, TessError};
use crate::gpu::bindings::{
    ADAPTIVE_BASE_POSITIONS_BINDING, ADAPTIVE_CONTROL_POINTS_BINDING, ADAPTIVE_CURVES_BINDING,
    ADAPTIVE_EDGE_COARSE, ADAPTIVE_EDGE_PLAIN, ADAPTIVE_LOCAL_SIZE, ADAPTIVE_OPTION_FRACTIONAL,
    ADAPTIVE_OPTION_PATCH_COLOURS, ADAPTIVE_OPTION_POW2, ADAPTIVE_PATCHES_BINDING,
    ADAPTIVE_STENCIL_OFFSETS_BINDING, ADAPTIVE_STENCIL_TERMS_BINDING, ADAPTIVE_VERTICES_BINDING,
};
use crate::gpu::bindings::{
    ADAPTIVE_CORNER_OWNERS_BINDING, ADAPTIVE_CURVE_OWNERS_BINDING, ADAPTIVE_HEIGHT_BINDING,
    ADAPTIVE_OPTION_CANONICAL_NORMALS, ADAPTIVE_OPTION_DISPLACE, ADAPTIVE_OPTION_HEIGHT_MAP,
    ADAPTIVE_OPTION_REPARAM, ADAPTIVE_OPTION_SHOW_PARAM_ERROR, ADAPTIVE_OPTION_SHOW_PARAM_SHIFT,
    ADAPTIVE_OPTION_TEXTURE, ADAPTIVE_PARAM_ERROR_BINDING, ADAPTIVE_PARAM_ERROR_SIDE,
    ADAPTIVE_REPARAM_BINDING, ADAPTIVE_STENCIL_MODE_BASE, ADAPTIVE_STENCIL_MODE_CORNERS,
    ADAPTIVE_STENCIL_MODE_CURVES, ADAPTIVE_STENCIL_MODE_ROWS, ADAPTIVE_SURFACES_BINDING,
    ADAPTIVE_TEXTURE_BINDING,
};
use crate::gpu::AdaptivePush;
use crate::shaders::{self, Stage, Variant};
use crate::surface::{SurfaceImage, SurfaceMaps, SurfaceShow};
use crate::technique::{
    for_each_draw, number_arrays, DeviceAllocation, DrawCounts, DrawPath, FactorPolicy, Features,
    FrameParams, Pass, PatchArray, PatchPipeline, PatchType, Technique, TechniqueId,
};
use crate::techniques::bft::base_positions;
use crate::techniques::{BuildOptions, Built, LegendEntry, TechniqueInfo};
use crate::tessellator::{
    quad_triangle_count, triangle_triangle_count, uniform_vertex_count, Domain, Spacing,
};
use layout::GpuAdaptive;
use std::ops::Range;
use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions, AdaptivePlan, EndCap};
use topology::ControlMesh;
use vk_core::descriptor::{BindingDesc, DescriptorPool};
use vk_core::pipeline::{Pipeline, ShaderStage};
use vk_core::texture::{Texture, TextureDesc, TextureFormat};
use vk_core::{vk, Buffer, BufferDesc, DescriptorSet, Encoder, MemoryLocation};

/// Default isolation level (OpenSubdiv's and the issue's).
pub const DEFAULT_ISOLATION: u32 = 4;

/// Set 1 of every adaptive pipeline.
static SET_BINDINGS: [BindingDesc; 14] = [
    storage_binding(ADAPTIVE_BASE_POSITIONS_BINDING),
    storage_binding(ADAPTIVE_STENCIL_OFFSETS_BINDING),
    storage_binding(ADAPTIVE_STENCIL_TERMS_BINDING),
    storage_binding(ADAPTIVE_VERTICES_BINDING),
    storage_binding(ADAPTIVE_PATCHES_BINDING),
    storage_binding(ADAPTIVE_CONTROL_POINTS_BINDING),
    storage_binding(ADAPTIVE_CURVES_BINDING),
    storage_binding(ADAPTIVE_SURFACES_BINDING),
    storage_binding(ADAPTIVE_REPARAM_BINDING),
    storage_binding(ADAPTIVE_CURVE_OWNERS_BINDING),
    storage_binding(ADAPTIVE_CORNER_OWNERS_BINDING),
    storage_binding(ADAPTIVE_PARAM_ERROR_BINDING),
    sampler_binding(ADAPTIVE_TEXTURE_BINDING),
    sampler_binding(ADAPTIVE_HEIGHT_BINDING),
];

/// A combined image sampler of the set (the fragment stage reads the texture, the TES both).
const fn sampler_binding(binding: u32) -> BindingDesc {
    BindingDesc {
        binding,
        ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        stages: vk::ShaderStageFlags::from_raw(
            vk::ShaderStageFlags::TESSELLATION_EVALUATION.as_raw()
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

/// A colour texture or height map needs the mesh's `vt` at every face corner: without them
/// each face would show the whole image, which is never what was meant. Checked before the
/// surface is planned. Procedural displacement works without `vt` (the (sub)face parameter
/// stands in).
pub fn check_texcoords(mesh: &ControlMesh, maps: &SurfaceMaps, name: &str) -> Result<()> {
    let wanted = match (&maps.texture, &maps.height) {
        (Some(_), _) => "a colour texture",
        (None, Some(_)) => "a height map",
        (None, None) => return Ok(()),
    };
    if topology::patches::texcoord::has_texcoords(mesh) {
        return Ok(());
    }
    Err(TessError::Mesh {
        name: name.to_string(),
        source: format!(
            "{wanted} was given, but the mesh has no `vt` texture coordinate at every face corner (procedural displacement works without them)"
        )
        .into(),
    })
}

/// Stencil rows: their CSR offsets (row `r` reads `offsets[r + 1]`).
const ROWS: Space = Space {
    name: "stencil row",
    members: &[Member {
        stride: 4,
        extra: 1,
    }],
};
/// Stencil terms.
const TERMS: Space = Space {
    name: "stencil term",
    members: &[Member {
        stride: std::mem::size_of::<layout::StencilTerm>() as u64,
        extra: 0,
    }],
};

/// A set's windows of the stencil offsets (rows) and terms.
type RowWindows = [Range<u32>; 2];

/// One dispatch of the stencil kernel (`mode`: rows, the base copy or curve points; see
/// `ADAPTIVE_STENCIL_MODE_*`), its items and the set whose windows it binds.
#[derive(Clone, Debug, PartialEq, Eq)]
struct Step {
    mode: u32,
    items: Range<u32>,
    /// Index into the slot's sets.
    set: usize,
}

/// The pre-pass: chunks of rows (over every block) whose offset and term windows fit
/// `limits`, one descriptor set each; a block runs as one dispatch per chunk it meets, each at
/// most `max_items` rows (the dispatch's group count). Returns the steps (the base copy
/// first) and each set's windows, `[rows, terms]`.
fn plan_pre_pass(
    g: &GpuAdaptive,
    limits: Limits,
    max_items: u32,
) -> Result<(Vec<Step>, Vec<RowWindows>)> {
    let max_items = max_items.max(1);
    let rows = g.stencil_offsets.len().saturating_sub(1) as u32;
    let chunks = windows::plan("stencil row", rows, &[ROWS, TERMS], limits, |r| {
        let (k0, k1) = (
            g.stencil_offsets[r as usize],
            g.stencil_offsets[r as usize + 1],
        );
        [r..r + 1, k0..k1]
    })?;
    let mut steps = Vec::new();
    let mut split = |mode: u32, items: Range<u32>, set: usize| {
        let mut first = items.start;
        while first < items.end {
            let end = items.end.min(first.saturating_add(max_items));
            steps.push(Step {
                mode,
                items: first..end,
                set,
            });
            first = end;
        }
    };
    // The base copy and the curve points read no stencils: any set serves.
    split(ADAPTIVE_STENCIL_MODE_BASE, 0..g.num_base_vertices, 0);
    for d in &g.dispatches {
        let block = d.first_row..d.first_row + d.rows;
        for (k, c) in chunks.iter().enumerate() {
            split(
                ADAPTIVE_STENCIL_MODE_ROWS,
                block.start.max(c.items.start)..block.end.min(c.items.end),
                k,
            );
        }
    }
    let corners_from = g.first_regular_corner - g.first_corner;
    split(
        ADAPTIVE_STENCIL_MODE_CORNERS,
        corners_from..corners_from + g.regular_corners(),
        0,
    );
    split(ADAPTIVE_STENCIL_MODE_CURVES, 0..g.curve_points(), 0);
    Ok((steps, chunks.into_iter().map(|c| c.windows).collect()))
}

impl TechniqueId {
    pub const ADAPTIVE: TechniqueId = TechniqueId::new("adaptive");
}

/// What feature-adaptive Catmull-Clark takes (the single-pass techniques take it without
/// isolation).
pub const ADAPTIVE_FEATURES: Features = Features {
    adaptive_factors: true,
    spacings: [true, true, false],
    animation: true,
    patch_colours: true,
    geometric_normals: false,
    phong_alpha: false,
    table_level: false,
    triangles_only: false,
    isolation: true,
    surface: true,
    single_pass: false,
    paths: &[DrawPath::Tessellation],
};

/// The patch-colour legend of the planned Catmull-Clark techniques.
pub const PATCH_LEGEND: &[LegendEntry] = &[
    ([0.45, 0.65, 0.95], "B-spline (odd levels lighter)"),
    ([0.95, 0.45, 0.35], "Gregory end cap"),
    ([0.95, 0.8, 0.3], "bilinear end cap"),
    ([0.3, 0.8, 0.35], "boundary / crease (greener)"),
];

/// The registry entry.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::ADAPTIVE,
    help: "exact Catmull-Clark limit surface by feature-adaptive refinement (Niessner et al.), Gregory or bilinear end caps",
    features: ADAPTIVE_FEATURES,
    scheme: Some(topology::Scheme::CatmullClark),
    default_for_scheme: true,
    shader_folder: "adaptive",
    abi_code: 5,
    legend: PATCH_LEGEND,
    build: build_registered,
    check_options: |_, params| check_frame(None, params),
};

/// The registry's constructor: [`Adaptive::new`] with the build options adaptive takes.
fn build_registered(
    ctx: &mut Context,
    mesh: &ControlMesh,
    options: &BuildOptions,
) -> Result<Built> {
    let surface = Adaptive::new(
        ctx,
        mesh,
        &AdaptiveBuild {
            isolation: options.isolation,
            end_cap: options.end_cap,
            sharpness_scale: options.sharpness_scale,
            follow_semi_sharp: options.follow_semi_sharp,
            name: options.name.clone(),
            maps: options.maps.clone(),
        },
    )?;
    Ok(Built {
        notes: surface.param_error_note().into_iter().collect(),
        technique: Box::new(surface),
    })
}

/// How an adaptive surface is built (the per-frame choices are in [`FrameParams`]).
#[derive(Clone, Debug)]
pub struct AdaptiveBuild {
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
}

impl Default for AdaptiveBuild {
    fn default() -> Self {
        Self {
            isolation: DEFAULT_ISOLATION,
            end_cap: EndCap::Gregory,
            sharpness_scale: 1.0,
            follow_semi_sharp: true,
            name: "mesh".into(),
            maps: SurfaceMaps::default(),
        }
    }
}

/// One feature-adaptive Catmull-Clark surface on the GPU. Drop order: pipeline, sets (they
/// keep their pool alive), pool, buffers.
pub struct Adaptive {
    /// Adaptive, or a single-pass technique drawing its plan (`crate::techniques::gregory`).
    id: TechniqueId,
    stencil: Pipeline,
    /// Per frame slot, one set per distinct pre-pass window (slots differ only in the base
    /// positions); the draw binds the slot's first (it reads no stencils).
    sets: Vec<Vec<DescriptorSet>>,
    /// The stencil kernel's dispatches, in order.
    steps: Vec<Step>,
    /// Per set: its windows of the stencil offsets and terms.
    windows: Vec<RowWindows>,
    _pool: DescriptorPool,
    base: Vec<Buffer>,
    _static: Vec<Buffer>,
    _textures: [Texture; 2],
    arrays: Vec<PatchArray>,
    /// Per array: how many patches have each combination of edge kinds (the 2-bit kinds of
    /// `edge_info`), counted once so uniform triangle counts cost a few entries per call.
    edge_kinds: Vec<Vec<(u32, u64)>>,
    pub gpu: GpuAdaptive,
    pub plan: AdaptivePlan,
    pub mesh: ControlMesh,
    pub base_positions: Vec<[f32; 3]>,
    rest_bbox: ([f32; 3], [f32; 3]),
    pub options: AdaptiveBuild,
    max_level: f32,
    /// The Eq. 1 error lattice was built (`SurfaceMaps::param_error`).
    has_param_errors: bool,
    /// Its summary and the patches with a reparameterized corner, when built.
    param_error_summary: Option<(topology::patches::texcoord::ParamErrorSummary, usize)>,
}

impl Adaptive {
    /// Plans `mesh` (Catmull-Clark, any faces, boundaries, creases) and uploads it, with one
    /// base-position buffer per frame slot of `ctx`.
    pub fn new(ctx: &mut Context, mesh: &ControlMesh, options: &AdaptiveBuild) -> Result<Self> {
        check_texcoords(mesh, &options.maps, &options.name)?;
        let plan = plan_adaptive(
            mesh,
            &AdaptiveOptions {
                isolation: options.isolation,
                end_cap: options.end_cap,
                sharpness_scale: options.sharpness_scale,
                follow_semi_sharp: options.follow_semi_sharp,
            },
        )
        .map_err(|e| TessError::Mesh {
            name: options.name.clone(),
            source: e.into(),
        })?;
        Self::from_plan(ctx, mesh, plan, options, TechniqueId::ADAPTIVE)
    }

    /// Uploads an already made plan (the single-pass techniques' too,
    /// `crate::techniques::gregory`), drawn as technique `id`.
    pub fn from_plan(
        ctx: &mut Context,
        mesh: &ControlMesh,
        plan: AdaptivePlan,
        options: &AdaptiveBuild,
        id: TechniqueId,
    ) -> Result<Self> {
        let device = ctx.device().clone();
        let gpu = GpuAdaptive::new(&plan).map_err(|e| TessError::Mesh {
            name: options.name.clone(),
            source: e.into(),
        })?;
        let frames = ctx.frames_in_flight();
        ctx.ensure_set_layout(id, &SET_BINDINGS)?;
        let set_layout = ctx.set_layout(id)?;
        let max_groups = device.info.caps.max_compute_work_group_count[0];
        let (steps, windows) = plan_pre_pass(
            &gpu,
            Limits::of(&device),
            max_groups.saturating_mul(ADAPTIVE_LOCAL_SIZE),
        )?;
        let pool = DescriptorPool::new(
            &device,
            "adaptive descriptor pool",
            set_layout,
            (frames * windows.len()) as u32,
        )?;
        let vertices = Buffer::new(
            &device,
            &BufferDesc {
                name: "adaptive vertices",
                size: gpu.vertex_bytes(),
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        // One 0 stands in when the lattice is not asked for (the view is then refused).
        let mut param_error_summary = None;
        let param_errors = if options.maps.param_error {
            let lattice = topology::patches::texcoord::param_error_lattice(
                mesh,
                &plan,
                ADAPTIVE_PARAM_ERROR_SIDE as usize,
            )
            .map_err(|e| TessError::Mesh {
                name: options.name.clone(),
                source: e.into(),
            })?;
            param_error_summary = Some((lattice.summary(), lattice.reparameterized));
            gpu.param_errors(&lattice)
        } else {
            Vec::new()
        };
        let has_param_errors = !param_errors.is_empty();
        let param_errors = if has_param_errors {
            param_errors
        } else {
            vec![0.0f32]
        };
        let statics = vec![
            (ADAPTIVE_VERTICES_BINDING, vertices),
            (
                ADAPTIVE_STENCIL_OFFSETS_BINDING,
                storage(
                    &device,
                    "adaptive stencil offsets",
                    bytemuck::cast_slice(&gpu.stencil_offsets),
                )?,
            ),
            (
                ADAPTIVE_STENCIL_TERMS_BINDING,
                storage(
                    &device,
                    "adaptive stencil terms",
                    bytemuck::cast_slice(&gpu.stencil_terms),
                )?,
            ),
            (
                ADAPTIVE_PATCHES_BINDING,
                storage(
                    &device,
                    "adaptive patches",
                    bytemuck::cast_slice(&gpu.patches),
                )?,
            ),
            (
                ADAPTIVE_CONTROL_POINTS_BINDING,
                storage(
                    &device,
                    "adaptive control points",
                    bytemuck::cast_slice(&gpu.control_points),
                )?,
            ),
            (
                ADAPTIVE_CURVES_BINDING,
                storage(
                    &device,
                    "adaptive curves",
                    bytemuck::cast_slice(&gpu.curves),
                )?,
            ),
            (
                ADAPTIVE_SURFACES_BINDING,
                storage(
                    &device,
                    "adaptive patch surfaces",
                    bytemuck::cast_slice(&gpu.surfaces(&plan, mesh)),
                )?,
            ),
            (
                ADAPTIVE_REPARAM_BINDING,
                storage(
                    &device,
                    "adaptive reparameterization table",
                    bytemuck::cast_slice(&layout::reparam_rows()),
                )?,
            ),
            (
                ADAPTIVE_CURVE_OWNERS_BINDING,
                storage(
                    &device,
                    "adaptive curve owners",
                    bytemuck::cast_slice(&gpu.curve_owners),
                )?,
            ),
            (
                ADAPTIVE_CORNER_OWNERS_BINDING,
                storage(
                    &device,
                    "adaptive corner owners",
                    bytemuck::cast_slice(&gpu.corner_owners),
                )?,
            ),
            (
                ADAPTIVE_PARAM_ERROR_BINDING,
                storage(
                    &device,
                    "adaptive Eq. 1 error lattice",
                    bytemuck::cast_slice(&param_errors),
                )?,
            ),
        ];
        let textures = surface_textures(&device, &options.maps)?;
        let base_positions = base_positions(mesh);
        let mut base = Vec::new();
        let mut sets = Vec::new();
        for i in 0..frames {
            let mut buf = Buffer::new(
                &device,
                &BufferDesc {
                    name: &format!("adaptive base positions {i}"),
                    size: (12 * base_positions.len().max(1)) as u64,
                    usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                    location: MemoryLocation::CpuToGpu,
                },
            )?;
            buf.write(0, bytemuck::cast_slice(&base_positions))?;
            let mut slot_sets = Vec::with_capacity(windows.len());
            for [rows, terms] in &windows {
                let set = pool.allocate_set(set_layout)?;
                windows::write_whole(&set, ADAPTIVE_BASE_POSITIONS_BINDING, &buf)?;
                for (binding, s) in &statics {
                    match *binding {
                        ADAPTIVE_STENCIL_OFFSETS_BINDING => windows::write_window(
                            &set,
                            *binding,
                            s,
                            ROWS.members[0],
                            gpu.stencil_offsets.len() as u64,
                            rows,
                        )?,
                        ADAPTIVE_STENCIL_TERMS_BINDING => windows::write_window(
                            &set,
                            *binding,
                            s,
                            TERMS.members[0],
                            gpu.stencil_terms.len() as u64,
                            terms,
                        )?,
                        _ => windows::write_whole(&set, *binding, s)?,
                    }
                }
                set.write_texture(ADAPTIVE_TEXTURE_BINDING, &textures[0])?;
                set.write_texture(ADAPTIVE_HEIGHT_BINDING, &textures[1])?;
                slot_sets.push(set);
            }
            base.push(buf);
            sets.push(slot_sets);
        }
        let layouts = [ctx.frame_set_layout().raw, set_layout.raw];
        let stencil = Pipeline::compute(
            &device,
            "adaptive stencils",
            ShaderStage::new(
                vk::ShaderStageFlags::COMPUTE,
                shaders::spirv(Stage::AdaptiveStencilComp, Variant::default())?,
            ),
            &layouts,
            std::mem::size_of::<AdaptivePush>() as u32,
        )?;
        let [regular, gregory, bilinear, triangles] = gpu.counts;
        let arrays = number_arrays(&[
            (PatchType::BSpline, regular, 1),
            (PatchType::Gregory, gregory, 1),
            (PatchType::Bilinear, bilinear, 1),
            (PatchType::GregoryTriangle, triangles, 1),
        ]);
        let edge_kinds = arrays
            .iter()
            .map(|a| {
                let mut counts = std::collections::BTreeMap::new();
                let range = a.first_patch as usize..(a.first_patch + a.patches) as usize;
                for p in &gpu.patches[range] {
                    *counts.entry(p.edge_info & 0x3333).or_insert(0u64) += 1;
                }
                counts.into_iter().collect()
            })
            .collect();
        let max_level = device.info.caps.max_tessellation_generation_level as f32;
        Ok(Self {
            id,
            stencil,
            sets,
            steps,
            windows,
            _pool: pool,
            base,
            _static: statics.into_iter().map(|(_, b)| b).collect(),
            _textures: textures,
            arrays,
            edge_kinds,
            gpu,
            plan,
            mesh: mesh.clone(),
            rest_bbox: crate::framing::drawn_bbox(mesh),
            base_positions,
            options: options.clone(),
            max_level,
            has_param_errors,
            param_error_summary,
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

    /// Stencil-kernel dispatches (the base copy included) and distinct window sets: more than
    /// one set when the stencil tables exceed the storage range.
    pub fn chunk_counts(&self) -> (usize, usize) {
        (self.steps.len(), self.windows.len())
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
        if self.id != TechniqueId::ADAPTIVE {
            options |= ADAPTIVE_OPTION_CANONICAL_NORMALS;
        }
        if fractional {
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
            first_row: 0,
            count: 0,
            base_count: self.gpu.num_base_vertices,
            row_base: 0,
            term_base: 0,
            displace_scale: params.displace,
            first_corner: self.gpu.first_corner,
        }
    }

    /// The level `edge_level` in `adaptive.glsl` gives an edge of kind `kind` under uniform
    /// factors of `segments` per patch edge (mirrored operation for operation).
    fn uniform_edge_level(&self, segments: f32, spacing: Spacing, kind: u32) -> f32 {
        let lim = self.factor_limit();
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

/// What adaptive refuses in `params`: uniform factors are whole segments per patch edge, at most
/// half the device's maximum `factor_limit` (a coarse transition edge doubles them) when it is
/// known; spacing equal or fractional even. Without a device ([`crate::techniques::check_options`])
/// only the bound waits for [`Technique::check`].
pub fn check_frame(factor_limit: Option<f32>, params: &FrameParams) -> Result<()> {
    if params.spacing == Spacing::FractionalOdd {
        return Err(TessError::Unsupported {
            technique: TechniqueId::ADAPTIVE,
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

impl Technique for Adaptive {
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
        check_frame(Some(self.factor_limit()), params)
    }

    fn patch_pipeline(&self, patch: PatchType) -> PatchPipeline {
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
            push_constant_bytes: std::mem::size_of::<AdaptivePush>() as u32,
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

    /// A shown texture, displacement, parameter view or patch colours, or the single-pass
    /// methods' canonical normals (and ACC-1's tangent patches) need the surface build;
    /// adaptive's plain frames do not (and hand the rasterizer no albedo or texture varying).
    fn surface_build(&self, params: &FrameParams) -> bool {
        self.id != TechniqueId::ADAPTIVE
            || params.displace != 0.0
            || params.show != SurfaceShow::Shading
            || params.patch_colours
            || self.options.maps.texture.is_some()
    }

    fn descriptor_set(&self, slot: usize) -> Option<&DescriptorSet> {
        self.sets
            .get(slot.min(self.sets.len().saturating_sub(1)))?
            .first()
    }

    /// At the largest level an edge can get (a coarse transition edge's doubled level).
    fn max_vertices_per_patch(&self, params: &FrameParams, array: usize) -> u64 {
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
        if positions.len() != self.base_positions.len() {
            return Err(TessError::BasePositionCount {
                given: positions.len(),
                expected: self.base_positions.len(),
            });
        }
        if let Some(v) = positions
            .iter()
            .position(|p| p.iter().any(|c| !c.is_finite()))
        {
            return Err(TessError::NonFiniteVertex { vertex: v });
        }
        let slots = self.base.len();
        let buf = self
            .base
            .get_mut(slot)
            .ok_or(TessError::FrameSlot { slot, slots })?;
        let positions: Vec<[f32; 3]> = positions.iter().map(|p| p.map(canonical_zero)).collect();
        buf.write(0, bytemuck::cast_slice(&positions))?;
        self.base_positions = positions;
        Ok(())
    }

    fn record_pre_pass<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        frame_set: &'a DescriptorSet,
        slot: usize,
    ) -> Result<()> {
        let slots = self.sets.len();
        let sets = self
            .sets
            .get(slot.min(slots.saturating_sub(1)))
            .ok_or(TessError::FrameSlot { slot, slots })?;
        let tess_stages = vk::PipelineStageFlags::VERTEX_SHADER
            | vk::PipelineStageFlags::TESSELLATION_CONTROL_SHADER
            | vk::PipelineStageFlags::TESSELLATION_EVALUATION_SHADER;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        enc.begin_label("adaptive subdivision tables");
        // The previous frame's tessellation stages read the vertices before we overwrite them;
        // host writes of the base positions are visible at submit.
        enc.memory_barrier(
            (tess_stages, vk::AccessFlags::SHADER_READ),
            (compute, vk::AccessFlags::SHADER_WRITE),
        );
        enc.bind_pipeline(&self.stencil);
        let n = self.steps.len();
        let mut bound = None;
        for (i, step) in self.steps.iter().enumerate() {
            let [rows, terms] = self
                .windows
                .get(step.set)
                .ok_or(TessError::FrameSlot { slot, slots })?;
            let set = sets
                .get(step.set)
                .ok_or(TessError::FrameSlot { slot, slots })?;
            if bound != Some(step.set) {
                enc.bind_descriptor_sets(0, &[frame_set, set])?;
                bound = Some(step.set);
            }
            let push = AdaptivePush {
                mode: step.mode,
                first_row: step.items.start,
                count: step.items.end - step.items.start,
                base_count: self.gpu.num_base_vertices,
                row_base: rows.start,
                term_base: terms.start,
                first_corner: self.gpu.first_corner,
                ..Default::default()
            };
            enc.push_constants(&push)?;
            enc.dispatch([push.count.div_ceil(ADAPTIVE_LOCAL_SIZE), 1, 1])?;
            // Each block reads the ones before it, and chunks of one block write disjoint
            // vertices of the buffer bound whole (synchronization validation sees the whole
            // range): every dispatch is ordered; the last feeds the tessellation stages.
            let next = if i + 1 == n {
                (tess_stages, vk::AccessFlags::SHADER_READ)
            } else {
                (
                    compute,
                    vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
                )
            };
            enc.memory_barrier((compute, vk::AccessFlags::SHADER_WRITE), next);
        }
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
        enc.push_constants(&push)?;
        for_each_draw(a.patches, per_draw, |first, n| {
            enc.draw(first..first + n)?;
            Ok(())
        })
    }

    /// The patch's point in its base face; a sub-quad of a non-quad maps bilinearly into the
    /// face's domain ([`face_corner_uv`](topology::limit::face_domain::face_corner_uv)): corner, edge
    /// midpoint, centre, edge midpoint.
    fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint> {
        let (face, sub, u, v) = self.base_param(patch, domain[0] as f64, domain[1] as f64)?;
        let n = self.mesh.face(face as usize).len() as u32;
        if n == 4 {
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
        self.base
            .iter()
            .chain(&self._static)
            .map(DeviceAllocation::of_buffer)
            .chain(self._textures.iter().map(DeviceAllocation::of_texture))
            .collect()
    }

    fn report_notes(&self) -> Vec<String> {
        let [r, g, b, t] = self.gpu.counts;
        if self.id != TechniqueId::ADAPTIVE {
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
            "adaptive: isolation {}, {r} regular patches, {g} Gregory and {b} bilinear end caps, \
             {} vertices ({} refined + local), tables {} bytes",
            self.plan.isolation,
            self.gpu.num_vertices,
            self.gpu.num_vertices - self.gpu.num_base_vertices,
            self.gpu.table_bytes()
        )]
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Under a small range and a small group count, the steps run every row exactly once, in
    /// block order (a block's rows read only earlier blocks), each inside its set's windows,
    /// with aligned window starts; the base copy comes first.
    #[test]
    fn pre_pass_chunks_cover_every_row_once_inside_their_windows() {
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
        let g = GpuAdaptive::new(&plan).expect("layout");
        let whole = plan_pre_pass(&g, limits(1 << 30), u32::MAX).expect("whole");
        assert_eq!(whole.1.len(), 1, "everything fits: one set");
        let (steps, sets) = plan_pre_pass(&g, limits(4096), 100).expect("chunked");
        assert!(sets.len() > 3, "{} sets", sets.len());
        assert_eq!(steps[0].mode, ADAPTIVE_STENCIL_MODE_BASE);
        assert_eq!(steps[0].items.start, 0);
        let copied: u32 = steps
            .iter()
            .filter(|s| s.mode == ADAPTIVE_STENCIL_MODE_BASE)
            .map(|s| s.items.len() as u32)
            .sum();
        assert_eq!(copied, g.num_base_vertices);
        let mut next = 0;
        // The curve points come last, in order, after every row.
        let curve_steps: Vec<&Step> = steps
            .iter()
            .filter(|s| s.mode == ADAPTIVE_STENCIL_MODE_CURVES)
            .collect();
        let mut next_point = 0;
        for s in &curve_steps {
            assert_eq!(s.items.start, next_point);
            assert!(s.items.len() <= 100);
            next_point = s.items.end;
        }
        assert_eq!(next_point, g.curve_points());
        assert!(next_point > 0);
        let first_curve_step = steps
            .iter()
            .position(|s| s.mode == ADAPTIVE_STENCIL_MODE_CURVES)
            .expect("curve steps");
        assert!(steps[first_curve_step..]
            .iter()
            .all(|s| s.mode == ADAPTIVE_STENCIL_MODE_CURVES));
        for s in steps
            .iter()
            .filter(|s| s.mode == ADAPTIVE_STENCIL_MODE_ROWS)
        {
            assert_eq!(s.items.start, next, "in order, no gap or overlap");
            assert!(s.items.len() <= 100);
            next = s.items.end;
            let [rows, terms] = &sets[s.set];
            assert_eq!(rows.start % 4, 0, "row window start aligned to 16 bytes");
            assert_eq!(terms.start % 2, 0, "term window start aligned to 16 bytes");
            assert!((rows.end - rows.start + 1) * 4 <= 4096);
            assert!((terms.end - terms.start) * 8 <= 4096);
            for r in s.items.clone() {
                let (k0, k1) = (
                    g.stencil_offsets[r as usize],
                    g.stencil_offsets[r as usize + 1],
                );
                assert!(rows.start <= r && r < rows.end);
                assert!(k0 == k1 || (terms.start <= k0 && k1 <= terms.end));
            }
        }
        assert_eq!(next as usize, g.stencil_offsets.len() - 1);
    }

    fn limits(max_range: u64) -> Limits {
        Limits {
            max_range,
            alignment: 16,
        }
    }
}
