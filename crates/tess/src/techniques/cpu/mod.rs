//! The mesh refined on the CPU and drawn as a static triangle mesh: the seeds' baseline (a
//! CPU application subdividing to M^k and drawing it, the "VBO" of refinement-pattern
//! benchmarks), on the vertex-stage path of the seam.
//!
//! Design decisions:
//! - **`topology` does the maths** ([`topology::limit::limit_mesh`]): uniform refinement to level
//!   k = log2 S with the one refiner, every vertex on the limit surface, angle-weighted normals,
//!   and each vertex's point on the base mesh. This module only uploads and draws.
//! - **One indexed draw**, no tessellation stage (`glsl/cpu/mesh.vert`); the level follows the
//!   frame's uniform segments and is refined in [`Technique::prepare_frame`] when it changes.
//! - **A captured id is a vertex** of the refined mesh (`first_patch + gl_VertexIndex`), and
//!   [`Technique::face_point`] returns where that vertex lies on the base mesh, so capture,
//!   welding and the crack report treat it like every other technique.
//! - **Animation re-refines on the CPU** and uploads the whole refined mesh into the frame
//!   slot's own host-visible vertex buffer: exactly the cost the papers' animated baseline pays.
//! - Loop refines the fan triangulation of polygons (captured points map back into the input's
//!   polygons); Catmull-Clark and bilinear refine the mesh as given, and so does Doo-Sabin
//!   (`cpu-doo-sabin`), whose vertices stay where the refinement puts them (the Doo-Sabin seed's
//!   CPU baseline, the mesh `doo-sabin` refines on the GPU), each mapped to where its limit lies.
use crate::capture::{face_corner_uv, FacePoint};
use crate::context::Context;
use crate::error::{Param, ParamError, Result, TessError};
use crate::gpu::{DrawPush, Vertex};
use crate::shaders::Stage;
use crate::technique::{
    DeviceAllocation, DrawCounts, DrawPath, FactorPolicy, Features, FrameParams, Pass, PatchArray,
    PatchPipeline, PatchType, Technique, TechniqueId, VertexInput,
};
use crate::techniques::{BuildOptions, Built, TechniqueInfo};
use topology::limit::limit_mesh::{
    catmark_level_size, doo_sabin_level_mesh, loop_level_size, uniform_limit_mesh, DomainPoint,
    LimitMesh,
};
use topology::refine::doo_sabin::{first_level_size, level_sizes, LevelSize};
use topology::{ControlMesh, Scheme};
use vk_core::{vk, Buffer, BufferDesc, Device, Encoder, MemoryLocation};

impl TechniqueId {
    pub const CPU: TechniqueId = TechniqueId::new("cpu");
    pub const CPU_CATMARK: TechniqueId = TechniqueId::new("cpu-catmark");
    pub const CPU_DOO_SABIN: TechniqueId = TechniqueId::new("cpu-doo-sabin");
}

/// The registry entry of `--method cpu`: Loop on the CPU (the seeds' Table I baseline).
pub static INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::CPU,
    help: "Loop subdivision on the CPU to level log2 S at the limit, drawn as a static indexed mesh from the vertex stage (the seeds' baseline); polygons fan-triangulated",
    features: Features {
        adaptive_factors: false,
        spacings: [true, false, false],
        animation: true,
        patch_colours: false,
        geometric_normals: false,
        phong_alpha: false,
        table_level: false,
        triangles_only: true,
        isolation: false,
        surface: false,
        single_pass: false,
        sine_displacement: false,
        paths: &[DrawPath::VertexStage],
    },
    scheme: Some(Scheme::Loop),
    default_for_scheme: false,
    shader_folder: "cpu",
    abi_code: 8,
    legend: &[],
    build: |ctx, mesh, options| build(ctx, TechniqueId::CPU, Scheme::Loop, mesh, options),
    check_options: |_, params| check_segments(params),
};

/// The registry entry of `--method cpu-catmark`: Catmull-Clark on the CPU.
pub static CATMARK_INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::CPU_CATMARK,
    help: "Catmull-Clark subdivision on the CPU to level log2 S at the limit, drawn as a static indexed mesh from the vertex stage",
    features: Features {
        triangles_only: false,
        ..INFO.features
    },
    scheme: Some(Scheme::CatmullClark),
    abi_code: 9,
    build: |ctx, mesh, options| {
        build(ctx, TechniqueId::CPU_CATMARK, Scheme::CatmullClark, mesh, options)
    },
    ..INFO
};

/// The registry entry of `--method cpu-doo-sabin`: Doo-Sabin refined on the CPU (the baseline
/// of the Doo-Sabin seed's §3, against `doo-sabin`'s refinement on the GPU).
pub static DOO_SABIN_INFO: TechniqueInfo = TechniqueInfo {
    id: TechniqueId::CPU_DOO_SABIN,
    help: "Doo-Sabin subdivision on the CPU to level log2 S (refined, as doo-sabin draws it), drawn as a static indexed mesh from the vertex stage",
    features: Features {
        triangles_only: false,
        ..INFO.features
    },
    scheme: Some(Scheme::DooSabin),
    abi_code: 11,
    build: |ctx, mesh, options| {
        build(ctx, TechniqueId::CPU_DOO_SABIN, Scheme::DooSabin, mesh, options)
    },
    ..INFO
};

/// Deepest level a frame may ask for: 2^6 = 64 segments per base edge, the tessellator's
/// maximum, so both paths draw the same range of levels.
pub const MAX_LEVEL: u32 = 6;

/// The refined mesh of one level on the device.
struct LevelMesh {
    level: u32,
    /// One buffer while static; one host-visible buffer per frame slot once animated.
    vertices: Vec<Buffer>,
    indices: Buffer,
    index_count: u32,
    /// Per vertex, its point on the base mesh (input face and its domain).
    domains: Vec<Option<FacePoint>>,
}

/// See the module docs. Drop order: the level's buffers, then the device handle.
pub struct CpuMesh {
    id: TechniqueId,
    scheme: Scheme,
    level: Option<LevelMesh>,
    arrays: [PatchArray; 1],
    /// The mesh refined: the input, or (Loop) its fan triangulation, with the base positions
    /// the last animation frame gave.
    refined: ControlMesh,
    /// The input mesh (what animation moves, in its vertex order).
    input: ControlMesh,
    /// Domain point of every face corner of `refined`, in the input's face domains.
    base_corners: Vec<DomainPoint>,
    bbox: ([f32; 3], [f32; 3]),
    max_vertices: u64,
    slots: usize,
    animated: bool,
    device: Device,
    /// Doo-Sabin's level-1 size, from which every level's is counted before refining.
    doo_sabin_first: Option<LevelSize>,
}

impl CpuMesh {
    /// Prepares `mesh` for refinement by `scheme` (nothing is refined before a frame asks for
    /// a level).
    pub fn new(
        ctx: &Context,
        id: TechniqueId,
        scheme: Scheme,
        mesh: &ControlMesh,
        options: &BuildOptions,
    ) -> Result<Self> {
        let (refined, fans) = refined_control_mesh(mesh, scheme);
        let mesh_error = |e: topology::TopologyError| TessError::Mesh {
            name: options.name.clone(),
            source: e.into(),
        };
        let base = topology::refine::Level::from_mesh(&refined, scheme).map_err(mesh_error)?;
        // Doo-Sabin's first step refuses what the dual scheme cannot refine (a vertex of two
        // faces; holes and sharpness tags are refused by the base level), before any frame
        // asks for a level.
        let doo_sabin_first = match scheme {
            Scheme::DooSabin => Some(first_level_size(&base).map_err(mesh_error)?),
            _ => None,
        };
        let base_corners = corner_domains(&refined, &fans);
        let (lo, hi) = mesh.bounding_box();
        Ok(Self {
            id,
            scheme,
            level: None,
            arrays: [PatchArray {
                patch: PatchType::MeshTriangles,
                patches: 0,
                control_points: 0,
                first_patch: 0,
            }],
            refined,
            input: mesh.clone(),
            base_corners,
            bbox: (lo.map(|c| c as f32), hi.map(|c| c as f32)),
            max_vertices: options.max_refined_vertices,
            doo_sabin_first,
            slots: ctx.frames_in_flight(),
            animated: false,
            device: ctx.device().clone(),
        })
    }

    /// The level a frame of `params` draws, or why it cannot.
    fn level_of(&self, params: &FrameParams) -> Result<u32> {
        level_of(self.id, params)
    }

    /// (vertices, triangles) of the refined mesh at `level`; the faces refining a hole are
    /// not drawn.
    fn size_at(&self, level: u32) -> (u64, u64) {
        let level = level as usize;
        let holes: std::collections::BTreeSet<u32> = self.refined.holes.iter().copied().collect();
        let hole_sides = || {
            holes
                .iter()
                .map(|&h| self.refined.face(h as usize).len() as u64)
        };
        if level == 0 {
            let faces: u64 = self.refined.faces().map(|f| f.len() as u64 - 2).sum();
            let in_holes: u64 = hole_sides().map(|n| n - 2).sum();
            return (self.refined.positions.len() as u64, faces - in_holes);
        }
        let quarters = 4u64.pow(level as u32 - 1);
        match self.scheme {
            Scheme::Loop => {
                let (v, _, f) = loop_level_size(&self.refined, level);
                (v, f - 4 * quarters * holes.len() as u64)
            }
            Scheme::DooSabin => match self.doo_sabin_first {
                Some(first) => {
                    let size = level_sizes(first, level as u32)[level - 1];
                    (size.vertices, size.triangles())
                }
                None => (0, 0),
            },
            _ => {
                let (v, _, f) = catmark_level_size(&self.refined, level);
                (v, 2 * (f - quarters * hole_sides().sum::<u64>()))
            }
        }
    }

    /// Refines to `level` on the CPU (the current base positions).
    fn refine(&self, level: u32) -> Result<LimitMesh> {
        let refined = match self.scheme {
            Scheme::DooSabin => doo_sabin_level_mesh(&self.refined, level as usize),
            scheme => uniform_limit_mesh(&self.refined, scheme, level as usize, &self.base_corners),
        };
        refined.map_err(|e| TessError::Mesh {
            name: format!("{} level {level}", self.scheme),
            source: e.into(),
        })
    }

    /// Refines to `level` and uploads the result (vertices device-local while static).
    fn build_level(&mut self, level: u32) -> Result<()> {
        let mesh = self.refine(level)?;
        let vertices = gpu_vertices(&mesh)?;
        let indices: Vec<u32> = mesh.triangles.iter().flatten().copied().collect();
        let n = vertices.len() as u32;
        if let Some(&bad) = indices.iter().find(|&&i| i >= n) {
            return Err(TessError::IndexOutOfRange {
                what: "refined mesh index",
                index: bad as u64,
                len: n as u64,
            });
        }
        let vertex_buffers = if self.animated {
            self.slot_buffers(&vertices)?
        } else {
            vec![Buffer::with_data(
                &self.device,
                "cpu mesh vertices",
                vk::BufferUsageFlags::VERTEX_BUFFER,
                bytemuck::cast_slice(&vertices),
            )?]
        };
        let domains = mesh
            .domains
            .iter()
            .map(|d| {
                d.map(|d| FacePoint {
                    face: d.face,
                    u: d.uv[0] as f32,
                    v: d.uv[1] as f32,
                })
            })
            .collect();
        self.level = Some(LevelMesh {
            level,
            vertices: vertex_buffers,
            indices: Buffer::with_data(
                &self.device,
                "cpu mesh indices",
                vk::BufferUsageFlags::INDEX_BUFFER,
                bytemuck::cast_slice(&indices),
            )?,
            index_count: indices.len() as u32,
            domains,
        });
        self.arrays[0].patches = n;
        Ok(())
    }

    /// One host-visible vertex buffer per frame slot, each holding `vertices`.
    fn slot_buffers(&self, vertices: &[Vertex]) -> Result<Vec<Buffer>> {
        (0..self.slots)
            .map(|slot| {
                let mut b = Buffer::new(
                    &self.device,
                    &BufferDesc {
                        name: &format!("cpu mesh vertices (slot {slot})"),
                        size: std::mem::size_of_val(vertices) as u64,
                        usage: vk::BufferUsageFlags::VERTEX_BUFFER,
                        location: MemoryLocation::CpuToGpu,
                    },
                )?;
                b.write(0, bytemuck::cast_slice(vertices))?;
                Ok(b)
            })
            .collect()
    }
}

/// The level a frame of `params` draws (uniform segments S = 2^level), or why it cannot.
fn level_of(id: TechniqueId, params: &FrameParams) -> Result<u32> {
    let bad = |segments: f32| {
        ParamError::refused(
            Param::Segments,
            segments,
            format!(
                "a mesh refined on the CPU takes a power of two in 1..={} segments per base \
                 edge (each level halves every edge)",
                1 << MAX_LEVEL
            ),
        )
    };
    let segments = match params.factors {
        FactorPolicy::Uniform { segments } => segments,
        _ => {
            return Err(TessError::Unsupported {
                technique: id,
                what: "adaptive factors (a static mesh has one level)",
            })
        }
    };
    if segments.fract() != 0.0 || !(1.0..=(1u32 << MAX_LEVEL) as f32).contains(&segments) {
        return Err(bad(segments));
    }
    let s = segments as u32;
    if !s.is_power_of_two() {
        return Err(bad(segments));
    }
    Ok(s.trailing_zeros())
}

/// What the registry checks before the mesh is built: the segments are a level.
fn check_segments(params: &FrameParams) -> Result<()> {
    level_of(TechniqueId::CPU, params).map(|_| ())
}

/// The mesh `scheme` refines: the input, or for Loop its fan triangulation; and per face of
/// it, its input face, the input face's side count and the fan index.
fn refined_control_mesh(mesh: &ControlMesh, scheme: Scheme) -> (ControlMesh, Vec<(u32, u32, u32)>) {
    let triangulate = scheme == Scheme::Loop && mesh.faces().any(|f| f.len() != 3);
    let (refined, origin) = if triangulate {
        mesh.triangulated()
    } else {
        (mesh.clone(), (0..mesh.num_faces() as u32).collect())
    };
    let mut fans: Vec<(u32, u32, u32)> = Vec::with_capacity(origin.len());
    for &o in &origin {
        let j = match fans.last() {
            Some(&(prev, _, j)) if prev == o => j + 1,
            _ => 0,
        };
        fans.push((o, mesh.face(o as usize).len() as u32, j));
    }
    (refined, fans)
}

/// The domain point of every face corner of `refined` in its input face's domain
/// ([`face_corner_uv`]): a fan triangle's corners are its polygon's corners 0, j + 1, j + 2.
fn corner_domains(refined: &ControlMesh, fans: &[(u32, u32, u32)]) -> Vec<DomainPoint> {
    let mut out = Vec::with_capacity(refined.face_vertices.len());
    for (f, &(face, n, j)) in fans.iter().enumerate() {
        let len = refined.face(f).len() as u32;
        for k in 0..len {
            let corner = if len == 3 && n != 3 {
                [0, j + 1, j + 2][k as usize]
            } else {
                k
            };
            out.push(DomainPoint {
                face,
                uv: face_corner_uv(n, corner),
            });
        }
    }
    out
}

/// The refined mesh as GPU vertices, refusing coordinates f32 cannot hold.
fn gpu_vertices(mesh: &LimitMesh) -> Result<Vec<Vertex>> {
    mesh.positions
        .iter()
        .zip(&mesh.normals)
        .enumerate()
        .map(|(i, (p, n))| {
            let position = p.map(|c| c as f32);
            if position.iter().any(|c| !c.is_finite()) {
                return Err(TessError::NonFiniteVertex { vertex: i });
            }
            Ok(Vertex {
                position,
                normal: n.map(|c| c as f32),
            })
        })
        .collect()
}

impl Technique for CpuMesh {
    fn id(&self) -> TechniqueId {
        self.id
    }

    fn bbox(&self) -> ([f32; 3], [f32; 3]) {
        self.bbox
    }

    fn patch_arrays(&self) -> &[PatchArray] {
        &self.arrays
    }

    fn check(&self, params: &FrameParams) -> Result<()> {
        let level = self.level_of(params)?;
        let (vertices, _) = self.size_at(level);
        if vertices > self.max_vertices {
            return Err(TessError::RefinedTooLarge {
                scheme: self.scheme,
                level: level as usize,
                vertices,
                max: self.max_vertices,
            });
        }
        Ok(())
    }

    fn prepare_frame(&mut self, _ctx: &mut Context, params: &FrameParams) -> Result<()> {
        let level = self.level_of(params)?;
        if self.level.as_ref().map(|l| l.level) != Some(level) {
            self.level = None;
            self.build_level(level)?;
        }
        Ok(())
    }

    fn patch_pipeline(&self, _patch: PatchType) -> PatchPipeline {
        PatchPipeline {
            vertex_input: VertexInput::MESH,
            ..PatchPipeline::triangles(Stage::CpuMeshVert, Stage::CommonShadeFrag)
        }
    }

    fn max_vertices_per_patch(&self, _params: &FrameParams, _array: usize) -> u64 {
        1
    }

    fn triangles(&self, params: &FrameParams, array: usize) -> Option<u64> {
        (array == 0).then_some(())?;
        let level = self.level_of(params).ok()?;
        Some(self.size_at(level).1)
    }

    fn base_mesh(&self) -> Option<&ControlMesh> {
        Some(&self.input)
    }

    /// Moves the base, refines the current level again on the CPU and uploads it into frame
    /// slot `slot`'s vertex buffer (the first call turns the static buffer into per-slot ones).
    fn update_base(&mut self, slot: usize, positions: &[[f32; 3]]) -> Result<()> {
        if positions.len() != self.refined.positions.len() {
            return Err(TessError::BasePositionCount {
                given: positions.len(),
                expected: self.refined.positions.len(),
            });
        }
        if slot >= self.slots {
            return Err(TessError::FrameSlot {
                slot,
                slots: self.slots,
            });
        }
        for (dst, src) in self.refined.positions.iter_mut().zip(positions) {
            *dst = src.map(f64::from);
        }
        let Some(level) = self.level.as_ref().map(|l| l.level) else {
            return Ok(());
        };
        let vertices = gpu_vertices(&self.refine(level)?)?;
        if !self.animated {
            self.animated = true;
            let buffers = self.slot_buffers(&vertices)?;
            if let Some(l) = self.level.as_mut() {
                l.vertices = buffers;
            }
            return Ok(());
        }
        if let Some(l) = self.level.as_mut() {
            l.vertices[slot].write(0, bytemuck::cast_slice(&vertices))?;
        }
        Ok(())
    }

    fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        slot: usize,
        _params: &FrameParams,
        pass: Pass,
        _per_draw: u32,
    ) -> Result<DrawCounts> {
        let (Some(a), Some(level)) = (self.arrays.get(array), self.level.as_ref()) else {
            return Err(TessError::NoPatchArray { array });
        };
        let vertices = level
            .vertices
            .get(slot)
            .or(level.vertices.first())
            .ok_or(TessError::NoPatchArray { array })?;
        enc.push_constants(&DrawPush {
            mode: pass.mode(),
            first_patch: a.first_patch,
        })?;
        enc.bind_vertex_buffer(0, vertices);
        enc.bind_index_buffer_u32(&level.indices);
        enc.draw_indexed(0..level.index_count)?;
        Ok(DrawCounts {
            draws: 1,
            patches: a.patches,
        })
    }

    /// The captured vertex's point on the base mesh (the domain coordinate is unused).
    fn face_point(&self, patch: u32, _domain: [f32; 2]) -> Option<FacePoint> {
        let level = self.level.as_ref()?;
        let v = patch.checked_sub(self.arrays[0].first_patch)?;
        level.domains.get(v as usize).copied().flatten()
    }

    /// The refined mesh's vertex buffers (one per slot once animated) and index buffer.
    fn device_memory(&self) -> Vec<DeviceAllocation> {
        self.level
            .iter()
            .flat_map(|l| l.vertices.iter().chain(std::iter::once(&l.indices)))
            .map(DeviceAllocation::of_buffer)
            .collect()
    }

    fn report_notes(&self) -> Vec<String> {
        self.level
            .iter()
            .map(|l| {
                format!(
                    "{} level {}: {} vertices, {} triangles refined on the CPU",
                    self.scheme,
                    l.level,
                    self.arrays[0].patches,
                    l.index_count / 3
                )
            })
            .collect()
    }
}

/// Builds the technique of registry entry `id` (the scheme is the entry's).
pub fn build(
    ctx: &mut Context,
    id: TechniqueId,
    scheme: Scheme,
    mesh: &ControlMesh,
    options: &BuildOptions,
) -> Result<Built> {
    Ok(Built {
        technique: Box::new(CpuMesh::new(ctx, id, scheme, mesh, options)?),
        notes: Vec::new(),
    })
}
