//! The base faces as patches: what flat, Phong and PN share. One vertex buffer (positions and
//! shading normals, [`RenderMesh`]) and index buffers of triangle and quad patches; the three
//! techniques differ only in which arrays they draw and in their control and evaluation
//! stages, which a [`FaceStyle`] states. [`FacePatches`] implements [`Technique`] once for all.
use crate::capture::{FacePoint, PatchFaceTable};
use crate::error::{Param, ParamError, Result, TessError};
use crate::gpu::DrawPush;
use crate::render_mesh::{PatchOrigin, RenderMesh};
use crate::technique::{
    for_each_draw, number_arrays, DeviceAllocation, DrawCounts, DrawPath, FactorPolicy, Features,
    FrameParams, Pass, PatchArray, PatchPipeline, PatchType, Technique, TechniqueId,
};
use crate::tessellator::{uniform_triangle_count, uniform_vertex_count, MAX_LEVEL};
use topology::ControlMesh;
use vk_core::{vk, Buffer, Device, Encoder};

/// What flat, Phong and PN take: uniform factors in every spacing, on the tessellation path.
pub const BASE_FACES: Features = Features {
    adaptive_factors: false,
    spacings: [true, true, true],
    animation: false,
    patch_colours: false,
    geometric_normals: false,
    phong_alpha: false,
    table_level: false,
    triangles_only: false,
    isolation: false,
    surface: false,
    single_pass: false,
    paths: &[DrawPath::Tessellation],
};

/// What distinguishes flat, Phong and PN.
pub trait FaceStyle: Send + 'static {
    const ID: TechniqueId;
    /// Flat keeps quads as quad patches; the others draw every face's fan triangles.
    const QUADS: bool;
    /// Stages of a patch type (only `Triangle`, and `Quad` when `QUADS`).
    fn pipeline(patch: PatchType) -> PatchPipeline;
}

/// An index buffer of one patch array.
struct IndexArray {
    indices: Buffer,
    control_points: u32,
}

/// See the module docs. Drop order: buffers, device handle.
pub struct FacePatches<S: FaceStyle> {
    vertices: Buffer,
    /// Parallel to `arrays`.
    indices: Vec<IndexArray>,
    arrays: Vec<PatchArray>,
    faces: PatchFaceTable,
    bbox: ([f32; 3], [f32; 3]),
    _style: std::marker::PhantomData<S>,
}

impl<S: FaceStyle> FacePatches<S> {
    /// Builds normals and patch lists of `mesh` (indices checked by [`RenderMesh`], and again
    /// here before upload: the GPU never receives one out of range).
    pub fn new(device: &Device, mesh: &ControlMesh) -> Result<Self> {
        Self::from_render_mesh(device, &RenderMesh::from_control_mesh(mesh)?)
    }

    pub fn from_render_mesh(device: &Device, mesh: &RenderMesh) -> Result<Self> {
        let n = mesh.vertices.len() as u32;
        let flat3 = |l: &[[u32; 3]]| l.iter().flatten().copied().collect::<Vec<u32>>();
        let flat4 = |l: &[[u32; 4]]| l.iter().flatten().copied().collect::<Vec<u32>>();
        let lists: Vec<(PatchType, Vec<u32>, u32, &[PatchOrigin])> = if S::QUADS {
            vec![
                (PatchType::Quad, flat4(&mesh.quads), 4, &mesh.quad_origins),
                (
                    PatchType::Triangle,
                    flat3(&mesh.quad_mode_triangles),
                    3,
                    &mesh.quad_mode_triangle_origins,
                ),
            ]
        } else {
            vec![(
                PatchType::Triangle,
                flat3(&mesh.triangles),
                3,
                &mesh.triangle_origins,
            )]
        };
        if let Some(&bad) = lists.iter().flat_map(|l| &l.1).find(|&&i| i >= n) {
            return Err(TessError::IndexOutOfRange {
                what: "patch index",
                index: bad as u64,
                len: n as u64,
            });
        }
        let vertices = Buffer::with_data(
            device,
            "mesh vertices",
            vk::BufferUsageFlags::VERTEX_BUFFER,
            bytemuck::cast_slice(&mesh.vertices),
        )?;
        let mut indices = Vec::new();
        let mut counts = Vec::new();
        let mut origins = Vec::new();
        for (patch, list, cp, o) in lists {
            if list.is_empty() {
                continue;
            }
            indices.push(IndexArray {
                indices: Buffer::with_data(
                    device,
                    &format!("{} {patch:?} patches", S::ID),
                    vk::BufferUsageFlags::INDEX_BUFFER,
                    bytemuck::cast_slice(&list),
                )?,
                control_points: cp,
            });
            counts.push((patch, list.len() as u32 / cp, cp));
            origins.extend_from_slice(o);
        }
        Ok(Self {
            vertices,
            indices,
            arrays: number_arrays(&counts),
            faces: PatchFaceTable::new(origins),
            bbox: (mesh.bbox_min, mesh.bbox_max),
            _style: std::marker::PhantomData,
        })
    }

    /// Uniform level of `params` (base-face patches take uniform factors only).
    fn level(&self, params: &FrameParams) -> f32 {
        params
            .uniform_segments()
            .unwrap_or(1.0)
            .clamp(1.0, MAX_LEVEL)
    }
}

impl<S: FaceStyle> Technique for FacePatches<S> {
    fn id(&self) -> TechniqueId {
        S::ID
    }

    fn bbox(&self) -> ([f32; 3], [f32; 3]) {
        self.bbox
    }

    fn patch_arrays(&self) -> &[PatchArray] {
        &self.arrays
    }

    fn check(&self, params: &FrameParams) -> Result<()> {
        match params.factors {
            FactorPolicy::Uniform { segments } if (1.0..=MAX_LEVEL).contains(&segments) => Ok(()),
            FactorPolicy::Uniform { segments } => Err(ParamError::refused(
                Param::Segments,
                segments,
                "expected 1..64",
            )),
            _ => Err(TessError::Unsupported {
                technique: S::ID,
                what: "adaptive factors",
            }),
        }
    }

    fn patch_pipeline(&self, patch: PatchType) -> PatchPipeline {
        S::pipeline(patch)
    }

    fn max_vertices_per_patch(&self, params: &FrameParams, array: usize) -> u64 {
        let domain = self.arrays[array].patch.domain();
        uniform_vertex_count(domain, params.spacing, self.level(params))
    }

    fn triangles(&self, params: &FrameParams, array: usize) -> Option<u64> {
        let a = self.arrays.get(array)?;
        Some(
            a.patches as u64
                * uniform_triangle_count(a.patch.domain(), params.spacing, self.level(params)),
        )
    }

    fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        _slot: usize,
        _params: &FrameParams,
        pass: Pass,
        per_draw: u32,
    ) -> Result<DrawCounts> {
        let (a, list) = match (self.arrays.get(array), self.indices.get(array)) {
            (Some(a), Some(l)) => (*a, l),
            _ => return Err(TessError::NoPatchArray { array }),
        };
        enc.bind_vertex_buffer(0, &self.vertices);
        enc.bind_index_buffer_u32(&list.indices);
        let cp = list.control_points;
        for_each_draw(a.patches, per_draw, |first, n| {
            enc.push_constants(&DrawPush {
                mode: pass.mode(),
                first_patch: a.first_patch + first,
            })?;
            enc.draw_indexed(first * cp..(first + n) * cp)?;
            Ok(())
        })
    }

    fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint> {
        self.faces.face_point(patch, domain)
    }

    /// The render mesh's vertex buffer (positions and normals) and the patch index buffers.
    fn device_memory(&self) -> Vec<DeviceAllocation> {
        std::iter::once(&self.vertices)
            .chain(self.indices.iter().map(|a| &a.indices))
            .map(DeviceAllocation::of_buffer)
            .collect()
    }
}
