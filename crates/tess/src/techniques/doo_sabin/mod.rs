//! Doo-Sabin subdivision refined on the GPU every frame to depth D = log2 S and drawn from the
//! vertex stage (`--method doo-sabin`): the seed's refinement of the control mesh's vertex
//! patches, on the stencil evaluator.
//!
//! Design decisions:
//! - **Levels are stencil blocks.** Each Doo-Sabin step is linear in the level before it, so
//!   the refinement is one block of [`crate::stencil`] rows per level
//!   ([`topology::refine::doo_sabin::refine_dual`]'s rows), evaluated in place over one vertex
//!   buffer: the frame slot's base positions copied to its head, then levels 1..D. The first
//!   step (with the boundary's Chaikin points and strip faces) is rows over the base
//!   positions like every other, so an animated frame costs one upload of base positions and
//!   every level is refined on the GPU. The vertex patches of
//!   [`topology::patches::doo_sabin`] partition the same points by the vertex they surround;
//!   the global buffer computes each shared point once, so every shared strip and corner face
//!   is drawn once by construction and every vertex of it welds by bits.
//! - **One indexed draw** of the deepest level's faces as triangle fans
//!   (`glsl/doo_sabin/mesh.vert`), reading the points (level-local numbers from the deepest
//!   level's first point) and the corner table by device address (`GL_EXT_buffer_reference`,
//!   the addresses in the uniform block [`DooSabinArrays`]): no descriptor names them, so
//!   `maxStorageBufferRange` does not limit the level drawn, only device memory does (the
//!   stencil evaluator windows what it binds, `techniques::windows`). An address rather than
//!   windows of the draw: a fan's corners and their neighbours may lie anywhere in the level.
//!   A device without `bufferDeviceAddress` (a host's) is refused by name. The price is
//!   lavapipe's: its address loads run lane by lane, and the level-6 draw is about 1.6–1.9×
//!   the descriptor path's GPU time there (docs/benchmarks.md).
//! - **Normals per point from its face corners**: the sum over the (at most four) faces a
//!   point lies in of `(next − p) × (previous − p)`, in the vertex stage, from a table of the
//!   corners' neighbours; no normal pass. Against the exact limit normal at face centres
//!   ([`topology::limit::doo_sabin::face_limit`]) the corners' mean normal converges about
//!   like the level's edge length (`tests/doo_sabin.rs` measures it).
//! - **A captured id is a point** of the deepest level; [`Technique::face_point`] gives where
//!   that point's limit lies on the base mesh
//!   ([`topology::limit::limit_mesh::doo_sabin_domain_points`], made on the first capture), so
//!   an export's `# p` line evaluates, through the exact Doo-Sabin limit, to the limit of the
//!   point drawn; boundary points map onto their corner's base vertex, which keeps capture's
//!   classification of boundary edges exact.
//! - **The depth follows the frame's segments** (S = 2^D, D in 1..=6, others refused by name)
//!   and its tables are rebuilt in [`Technique::prepare_frame`] when it changes.
pub mod layout;

use crate::capture::FacePoint;
use crate::context::Context;
use crate::error::{Result, TessError};
use crate::gpu::bindings::DOO_SABIN_ARRAYS_BINDING;
use crate::gpu::{DooSabinArrays, DrawPush};
use crate::shaders::Stage;
use crate::stencil::{self, StencilEvaluator, StencilVertex, StencilVertices};
use crate::technique::{
    DeviceAllocation, DrawCounts, DrawPath, Features, FrameParams, Pass, PatchArray, PatchPipeline,
    PatchType, Technique, TechniqueId,
};
use crate::techniques::shared::{
    check_doo_sabin_budget, depth_of, doo_sabin_triangles, upload_base, STAGES,
};
use crate::techniques::{BuildOptions, Built, TechniqueInfo};
use layout::{DepthLayout, LayoutError};
use std::mem::size_of;
use topology::refine::doo_sabin::{first_level_size, LevelSize};
use topology::refine::Level;
use topology::{ControlMesh, Scheme};
use vk_core::descriptor::{BindingDesc, DescriptorPool, DescriptorSetLayout};
use vk_core::{vk, Buffer, BufferDesc, DescriptorSet, Device, Encoder, MemoryLocation};

impl TechniqueId {
    pub const DOO_SABIN: TechniqueId = TechniqueId::new("doo-sabin");
}

/// The registry entry of `--method doo-sabin`.
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::DOO_SABIN,
    help: "Doo-Sabin subdivision refined on the GPU every frame to level log2 S (stencil rows per level from the base positions), drawn from the vertex stage",
    features: Features {
        adaptive_factors: false,
        spacings: [true, false, false],
        animation: true,
        patch_colours: false,
        geometric_normals: false,
        phong_alpha: false,
        table_level: false,
        triangles_only: false,
        isolation: false,
        surface: false,
        single_pass: false,
        sine_displacement: false,
        paths: &[DrawPath::VertexStage],
    },
    scheme: Some(Scheme::DooSabin),
    default_for_scheme: false,
    shader_folder: "doo_sabin",
    abi_code: 10,
    legend: &[],
    build,
    check_options: |_, params| depth_of(TechniqueId::DOO_SABIN, params).map(|_| ()),
};

pub use crate::techniques::shared::MAX_DOO_SABIN_DEPTH as MAX_DEPTH;

/// Set 1: the uniform block of the arrays' addresses.
static SET_BINDINGS: [BindingDesc; 1] = [BindingDesc {
    binding: DOO_SABIN_ARRAYS_BINDING,
    ty: vk::DescriptorType::UNIFORM_BUFFER,
    stages: STAGES,
}];

/// Usage of the buffers the vertex stage reads by address.
const BY_ADDRESS: vk::BufferUsageFlags = vk::BufferUsageFlags::SHADER_DEVICE_ADDRESS;

/// One depth on the device. Drop order: the evaluator, the set (it keeps its pool and
/// buffers alive), the pool, the buffers (the vertex stage reads `vertices` and `corners` at
/// the addresses in `addresses`).
struct DepthMesh {
    layout: DepthLayout,
    evaluator: StencilEvaluator,
    set: DescriptorSet,
    _pool: DescriptorPool,
    vertices: Buffer,
    corners: Buffer,
    addresses: Buffer,
    indices: Buffer,
    /// Per point of the level, where its limit lies on the base mesh (made on the first
    /// [`Technique::face_point`]: captures ask, frames do not).
    face_points: std::sync::OnceLock<Vec<Option<FacePoint>>>,
}

/// See the module docs.
pub struct DooSabin {
    depth: Option<DepthMesh>,
    arrays: [PatchArray; 1],
    mesh: ControlMesh,
    base: Level,
    /// The size of level 1, from which the deeper levels' sizes are counted.
    first_size: LevelSize,
    /// Per frame slot, the base positions the next frame copies to the buffer's head.
    base_buffers: Vec<Buffer>,
    bbox: ([f32; 3], [f32; 3]),
    max_vertices: u64,
    set_layout: DescriptorSetLayout,
    device: Device,
}

impl DooSabin {
    pub fn new(ctx: &mut Context, mesh: &ControlMesh, options: &BuildOptions) -> Result<Self> {
        if !ctx.device().info.caps.buffer_device_address {
            return Err(TessError::Unsupported {
                technique: TechniqueId::DOO_SABIN,
                what: "a device without bufferDeviceAddress enabled (Doo-Sabin's vertex stage \
                       reads its points and corners by address; a host device sets \
                       buffer_device_address)",
            });
        }
        // Refuses holes and sharpness tags by name (Doo-Sabin has neither).
        let base = Level::from_mesh(mesh, Scheme::DooSabin).map_err(|e| TessError::Mesh {
            name: options.name.clone(),
            source: e.into(),
        })?;
        let first_size = first_level_size(&base).map_err(|e| TessError::Mesh {
            name: options.name.clone(),
            source: e.into(),
        })?;
        let device = ctx.device().clone();
        let positions = crate::animation::base_positions(mesh);
        let base_buffers = (0..ctx.frames_in_flight())
            .map(|slot| base_buffer(&device, slot, &positions))
            .collect::<Result<Vec<_>>>()?;
        // The context's layout, which the pipelines are built with: sets are allocated when a
        // depth is laid out (after the build, without the context).
        ctx.ensure_set_layout(TechniqueId::DOO_SABIN, &SET_BINDINGS)?;
        let set_layout = ctx.set_layout(TechniqueId::DOO_SABIN)?.clone();
        Ok(Self {
            depth: None,
            arrays: [PatchArray {
                patch: PatchType::MeshTriangles,
                patches: 0,
                control_points: 0,
                first_patch: 0,
            }],
            mesh: mesh.clone(),
            base,
            first_size,
            base_buffers,
            bbox: crate::animation::bbox(&positions),
            max_vertices: options.max_refined_vertices,
            set_layout,
            device,
        })
    }

    /// Refines the tables of `depth` on the host and puts them on the device.
    fn build_depth(&mut self, depth: u32) -> Result<()> {
        // The deepest level needs no alignment: it is read by address, 16 bytes a point.
        let layout = layout::layout(&self.base, depth, 1).map_err(|e| match e {
            LayoutError::Topology(t) => TessError::Topology(t),
            LayoutError::Stencil(s) => TessError::Stencil(s),
            other => TessError::Mesh {
                name: format!("Doo-Sabin level {depth}"),
                source: Box::new(other),
            },
        })?;
        check_indices(&layout)?;
        self.arrays[0].patches = layout.points;
        self.depth = Some(DepthMesh::new(&self.device, &self.set_layout, layout)?);
        Ok(())
    }
}

/// [`topology::limit::limit_mesh::doo_sabin_domain_points`] of `mesh` at `depth` as capture's
/// face points (none if the refinement fails, which the layout of the same depth already
/// passed).
fn exact_face_points(mesh: &ControlMesh, depth: u32) -> Vec<Option<FacePoint>> {
    let points = topology::limit::limit_mesh::doo_sabin_domain_points(mesh, depth as usize);
    points
        .unwrap_or_default()
        .into_iter()
        .map(|d| {
            d.map(|d| FacePoint {
                face: d.face,
                u: d.uv[0] as f32,
                v: d.uv[1] as f32,
            })
        })
        .collect()
}

impl DepthMesh {
    /// The vertex buffer, the evaluator of `layout`'s blocks over it, the corner table, the
    /// index buffer, and the set of the uniform buffer holding the addresses of the deepest
    /// level's first point and of the corners.
    fn new(device: &Device, set_layout: &DescriptorSetLayout, layout: DepthLayout) -> Result<Self> {
        let vertices = Buffer::new(
            device,
            &BufferDesc {
                name: "doo-sabin vertices",
                size: stencil::vertex_bytes(layout.num_vertices),
                // Storage: the stencil evaluator binds windows of it.
                usage: vk::BufferUsageFlags::STORAGE_BUFFER
                    | vk::BufferUsageFlags::TRANSFER_DST
                    | BY_ADDRESS,
                location: MemoryLocation::GpuOnly,
            },
        )?;
        let evaluator = StencilEvaluator::new(
            device,
            "doo-sabin",
            &layout.stencils,
            &layout.blocks,
            StencilVertices {
                sources: layout.num_vertices,
                destinations: layout.num_vertices,
                in_place: true,
            },
            &[(&vertices, &vertices)],
        )?;
        let corners = Buffer::with_data(
            device,
            "doo-sabin corners",
            BY_ADDRESS,
            bytemuck::cast_slice(&layout.corners),
        )?;
        let arrays = DooSabinArrays {
            points: vertices.device_address()?
                + layout.first_point as u64 * size_of::<StencilVertex>() as u64,
            corners: corners.device_address()?,
        };
        let addresses = Buffer::with_data(
            device,
            "doo-sabin array addresses",
            vk::BufferUsageFlags::UNIFORM_BUFFER,
            bytemuck::bytes_of(&arrays),
        )?;
        let indices = Buffer::with_data(
            device,
            "doo-sabin indices",
            vk::BufferUsageFlags::INDEX_BUFFER,
            bytemuck::cast_slice(&layout.triangles),
        )?;
        let pool = DescriptorPool::new(device, "doo-sabin descriptor pool", set_layout, 1)?;
        let set = pool.allocate_set(set_layout)?;
        set.write_buffer(
            DOO_SABIN_ARRAYS_BINDING,
            vk::DescriptorType::UNIFORM_BUFFER,
            &addresses,
        )?;
        Ok(Self {
            layout,
            evaluator,
            set,
            _pool: pool,
            vertices,
            corners,
            addresses,
            indices,
            face_points: std::sync::OnceLock::new(),
        })
    }
}

/// The vertex stage reads points by the index buffer and the corner table: every index in
/// range of the deepest level.
fn check_indices(layout: &DepthLayout) -> Result<()> {
    let n = layout.points;
    let corners = layout.corners.iter().flatten();
    for (what, &i) in layout
        .triangles
        .iter()
        .map(|i| ("Doo-Sabin triangle index", i))
        .chain(corners.map(|i| ("Doo-Sabin corner neighbour", i)))
    {
        if i >= n {
            return Err(TessError::IndexOutOfRange {
                what,
                index: i as u64,
                len: n as u64,
            });
        }
    }
    Ok(())
}

/// A host-visible buffer of `positions` as the evaluator's vertices, the copy source of frame
/// slot `slot`.
fn base_buffer(device: &Device, slot: usize, positions: &[[f32; 3]]) -> Result<Buffer> {
    let mut b = Buffer::new(
        device,
        &BufferDesc {
            name: &format!("doo-sabin base positions {slot}"),
            size: stencil::vertex_bytes(positions.len() as u32),
            usage: vk::BufferUsageFlags::TRANSFER_SRC,
            location: MemoryLocation::CpuToGpu,
        },
    )?;
    b.write(0, bytemuck::cast_slice(&stencil::vertices(positions)))?;
    Ok(b)
}

impl Technique for DooSabin {
    fn id(&self) -> TechniqueId {
        TechniqueId::DOO_SABIN
    }

    fn bbox(&self) -> ([f32; 3], [f32; 3]) {
        self.bbox
    }

    fn patch_arrays(&self) -> &[PatchArray] {
        &self.arrays
    }

    fn check(&self, params: &FrameParams) -> Result<()> {
        check_doo_sabin_budget(
            TechniqueId::DOO_SABIN,
            self.base.num_vertices(),
            self.first_size,
            self.max_vertices,
            params,
        )
        .map(|_| ())
    }

    fn prepare_frame(&mut self, _ctx: &mut crate::Context, params: &FrameParams) -> Result<()> {
        let depth = depth_of(TechniqueId::DOO_SABIN, params)?;
        if self.depth.as_ref().map(|d| d.layout.depth) != Some(depth) {
            self.depth = None;
            self.arrays[0].patches = 0;
            self.build_depth(depth)?;
        }
        Ok(())
    }

    fn patch_pipeline(&self, _patch: PatchType) -> PatchPipeline {
        PatchPipeline::triangles(Stage::DooSabinMeshVert, Stage::CommonShadeFrag)
    }

    fn set_layout_bindings(&self) -> &'static [BindingDesc] {
        &SET_BINDINGS
    }

    fn descriptor_set(&self, _slot: usize) -> Option<&DescriptorSet> {
        self.depth.as_ref().map(|d| &d.set)
    }

    fn max_vertices_per_patch(&self, _params: &FrameParams, _array: usize) -> u64 {
        1
    }

    fn triangles(&self, params: &FrameParams, array: usize) -> Option<u64> {
        doo_sabin_triangles(TechniqueId::DOO_SABIN, self.first_size, params, array)
    }

    fn base_mesh(&self) -> Option<&ControlMesh> {
        Some(&self.mesh)
    }

    /// Writes the base positions of frame slot `slot`: the one upload an animated frame makes.
    fn update_base(&mut self, slot: usize, positions: &[[f32; 3]]) -> Result<()> {
        upload_base(
            &mut self.base_buffers,
            slot,
            positions,
            self.mesh.positions.len(),
        )?;
        Ok(())
    }

    /// The base copy, then one evaluator block per level, each ordered after the one before;
    /// the previous frame's vertex stage reads the points before they are overwritten.
    fn record_pre_pass<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        _frame_set: &'a DescriptorSet,
        slot: usize,
    ) -> Result<()> {
        let Some(d) = self.depth.as_ref() else {
            return Ok(());
        };
        let slots = self.base_buffers.len();
        let base = self
            .base_buffers
            .get(slot)
            .ok_or(TessError::FrameSlot { slot, slots })?;
        let vertex = vk::PipelineStageFlags::VERTEX_SHADER;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        let transfer = vk::PipelineStageFlags::TRANSFER;
        enc.begin_label("doo-sabin levels");
        enc.memory_barrier(
            (vertex, vk::AccessFlags::SHADER_READ),
            (
                transfer | compute,
                vk::AccessFlags::TRANSFER_WRITE | vk::AccessFlags::SHADER_WRITE,
            ),
        );
        enc.copy_buffer(base, &d.vertices)?;
        enc.memory_barrier(
            (transfer, vk::AccessFlags::TRANSFER_WRITE),
            (
                compute,
                vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
            ),
        );
        d.evaluator.record(enc, 0)?;
        enc.memory_barrier(
            (compute, vk::AccessFlags::SHADER_WRITE),
            (vertex, vk::AccessFlags::SHADER_READ),
        );
        enc.end_label();
        Ok(())
    }

    fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        _slot: usize,
        _params: &FrameParams,
        pass: Pass,
        _per_draw: u32,
    ) -> Result<DrawCounts> {
        let (Some(a), Some(d)) = (self.arrays.get(array), self.depth.as_ref()) else {
            return Err(TessError::NoPatchArray { array });
        };
        enc.push_constants(&DrawPush {
            mode: pass.mode(),
            first_patch: a.first_patch,
        })?;
        enc.bind_index_buffer_u32(&d.indices);
        enc.draw_indexed(0..d.layout.triangles.len() as u32)?;
        Ok(DrawCounts {
            draws: 1,
            patches: a.patches,
        })
    }

    /// Where the captured point's limit lies on the base mesh
    /// ([`topology::limit::limit_mesh::doo_sabin_domain_points`]: boundary points on their
    /// corner's base vertex); the domain is unused.
    fn face_point(&self, patch: u32, _domain: [f32; 2]) -> Option<FacePoint> {
        let d = self.depth.as_ref()?;
        let v = patch.checked_sub(self.arrays[0].first_patch)?;
        let points = d
            .face_points
            .get_or_init(|| exact_face_points(&self.mesh, d.layout.depth));
        points.get(v as usize).copied().flatten()
    }

    fn device_memory(&self) -> Vec<DeviceAllocation> {
        let mut out: Vec<DeviceAllocation> = self
            .base_buffers
            .iter()
            .map(DeviceAllocation::of_buffer)
            .collect();
        if let Some(d) = &self.depth {
            out.extend(
                [&d.vertices, &d.corners, &d.addresses, &d.indices]
                    .into_iter()
                    .chain(d.evaluator.buffers())
                    .map(DeviceAllocation::of_buffer),
            );
        }
        out
    }

    fn report_notes(&self) -> Vec<String> {
        self.depth
            .iter()
            .map(|d| {
                format!(
                    "Doo-Sabin level {}: {} points, {} triangles refined on the GPU from {} stencil rows",
                    d.layout.depth,
                    d.layout.points,
                    d.layout.triangles.len() / 3,
                    d.layout.stencils.rows()
                )
            })
            .collect()
    }
}

/// Builds `--method doo-sabin` for `mesh` (nothing is refined before a frame asks for a level).
pub fn build(ctx: &mut Context, mesh: &ControlMesh, options: &BuildOptions) -> Result<Built> {
    Ok(Built {
        technique: Box::new(DooSabin::new(ctx, mesh, options)?),
        notes: Vec::new(),
    })
}
