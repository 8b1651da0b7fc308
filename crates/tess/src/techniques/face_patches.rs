//! The base faces as patches: what flat, Phong and PN share, on both of their draw paths. The
//! three techniques differ only in which arrays they draw and in their stages, which a
//! [`FaceStyle`] states; [`FacePatches`] implements [`Technique`] once for all.
//!
//! - **Tessellation path:** one vertex buffer (positions and shading normals, [`RenderMesh`])
//!   and index buffers of triangle and quad patches, through the control and evaluation stages.
//! - **Refinement-pattern path** ([`crate::pattern`]): per array, one buffer of its patches'
//!   corners (read per instance), and the pattern of the frame's domain, spacing and level
//!   (the [`Context`]'s, made once); one instanced indexed draw per array, the vertex stage
//!   evaluating the patch with the same shader functions as the evaluation stage.
//! - **Scalar-tagged meshes** (PN only, [`FaceStyle::SCALAR_TAGS`]): the corners come unshared
//!   with a [`TaggedCorner`] each (`techniques::pn::scalar_tags`), in a second vertex buffer on
//!   the tessellation path and a second per-instance buffer on the pattern path, drawn with
//!   the style's [`FaceStyle::tagged_pipeline`].
use crate::capture::{FacePoint, PatchFaceTable};
use crate::context::Context;
use crate::error::{Param, ParamError, Result, TessError};
use crate::gpu::{pattern_input, DrawPush, TaggedCorner, Vertex};
use crate::pattern::{PatternBuffers, PatternKey};
use crate::render_mesh::{PatchOrigin, RenderMesh};
use crate::shaders::Stage;
use crate::technique::{
    for_each_draw, number_arrays, DeviceAllocation, DrawCounts, DrawPath, FactorPolicy, Features,
    FrameParams, Pass, PatchArray, PatchPipeline, PatchType, Technique, TechniqueId,
};
use crate::techniques::BuildOptions;
use crate::tessellator::{uniform_triangle_count, uniform_vertex_count, Domain, MAX_LEVEL};
use std::sync::Arc;
use topology::ControlMesh;
use vk_core::{vk, Buffer, Device, Encoder};

/// What flat, Phong and PN take: uniform factors in every spacing, on the tessellation and
/// refinement-pattern paths.
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
    sine_displacement: true,
    paths: &[DrawPath::Tessellation, DrawPath::Pattern],
};

/// What distinguishes flat, Phong and PN.
pub trait FaceStyle: Send + 'static {
    const ID: TechniqueId;
    /// Flat keeps quads as quad patches; the others draw every face's fan triangles.
    const QUADS: bool;
    /// Stages of a patch type on the tessellation path (only `Triangle`, and `Quad` when
    /// `QUADS`).
    fn pipeline(patch: PatchType) -> PatchPipeline;
    /// The vertex stage evaluating a patch of `domain` at a pattern vertex.
    fn pattern_stage(domain: Domain) -> Stage;
    /// Whether the style draws a mesh's scalar tags (`t scalartag`); the others draw the
    /// faces untagged.
    const SCALAR_TAGS: bool = false;
    /// The pipeline of `patch` (either path) for a scalar-tagged mesh.
    fn tagged_pipeline(_patch: PatchType) -> Option<PatchPipeline> {
        None
    }
}

/// An index buffer of one patch array.
struct IndexArray {
    indices: Buffer,
    control_points: u32,
}

/// What one path keeps on the device.
enum Draws {
    Tessellated {
        vertices: Buffer,
        /// A scalar-tagged mesh's [`TaggedCorner`]s, parallel to `vertices`.
        tagged: Option<Buffer>,
        /// Parallel to the arrays.
        indices: Vec<IndexArray>,
    },
    Patterns {
        /// Per array, each patch's corners (per-instance data), parallel to the arrays.
        corners: Vec<Buffer>,
        /// A scalar-tagged mesh's per-array [`TaggedCorner`]s of each patch's corners.
        tagged: Option<Vec<Buffer>>,
        /// The frame's patterns, per domain (triangle, quad).
        current: [Option<PatternBuffers>; 2],
        /// Whether the device's patterns are its tessellator's
        /// ([`crate::pattern::from_tessellator`]), so a pattern not yet made has the
        /// tessellator's triangle count.
        from_tessellator: bool,
    },
}

fn domain_slot(domain: Domain) -> usize {
    match domain {
        Domain::Triangle => 0,
        Domain::Quad => 1,
    }
}

/// See the module docs. Drop order: buffers, device handle.
pub struct FacePatches<S: FaceStyle> {
    draws: Draws,
    arrays: Vec<PatchArray>,
    faces: PatchFaceTable,
    bbox: ([f32; 3], [f32; 3]),
    _style: std::marker::PhantomData<S>,
}

/// One patch array's input: its type on the tessellation path, its corner indices (a flat
/// list), corners per patch, and each patch's origin.
type PatchList<'a> = (PatchType, Vec<u32>, u32, &'a [PatchOrigin]);

impl<S: FaceStyle> FacePatches<S> {
    /// Builds `mesh` for the draw path `options.pipeline` chooses on `ctx`'s device.
    pub fn build(ctx: &Context, mesh: &ControlMesh, options: &BuildOptions) -> Result<Self> {
        let path = options
            .pipeline
            .resolve(S::ID, BASE_FACES.paths, ctx.device())?;
        Self::new(ctx.device(), mesh, path)
    }

    /// Builds normals and patch lists of `mesh` for `path` (indices checked by [`RenderMesh`],
    /// and again here before upload: the GPU never receives one out of range).
    /// A mesh with scalar tags is drawn as an ST-mesh where the style takes tags.
    pub fn new(device: &Device, mesh: &ControlMesh, path: DrawPath) -> Result<Self> {
        let render = RenderMesh::from_control_mesh(mesh)?;
        if S::SCALAR_TAGS && !mesh.scalar_tags.is_empty() {
            let tagged = crate::techniques::pn::scalar_tags::tag_mesh(mesh, &render)?;
            return Self::from_parts(device, &tagged.render, Some(&tagged.corners), path);
        }
        Self::from_render_mesh(device, &render, path)
    }

    pub fn from_render_mesh(device: &Device, mesh: &RenderMesh, path: DrawPath) -> Result<Self> {
        Self::from_parts(device, mesh, None, path)
    }

    /// `mesh`'s patches, with `tagged` parallel to its vertices for a scalar-tagged mesh.
    fn from_parts(
        device: &Device,
        mesh: &RenderMesh,
        tagged: Option<&[TaggedCorner]>,
        path: DrawPath,
    ) -> Result<Self> {
        let lists = Self::patch_lists(mesh);
        let n = mesh.vertices.len() as u32;
        if let Some(&bad) = lists.iter().flat_map(|l| &l.1).find(|&&i| i >= n) {
            return Err(TessError::IndexOutOfRange {
                what: "patch index",
                index: bad as u64,
                len: n as u64,
            });
        }
        let lists: Vec<PatchList<'_>> = lists.into_iter().filter(|l| !l.1.is_empty()).collect();
        let mut counts = Vec::new();
        let mut origins = Vec::new();
        for (patch, list, cp, o) in &lists {
            counts.push(match path {
                DrawPath::Pattern => (pattern_type(*patch), list.len() as u32 / cp, 0),
                _ => (*patch, list.len() as u32 / cp, *cp),
            });
            origins.extend_from_slice(o);
        }
        let draws = match path {
            DrawPath::Pattern => Self::pattern_draws(device, mesh, tagged, &lists)?,
            _ => Self::tessellated_draws(device, mesh, tagged, &lists)?,
        };
        Ok(Self {
            draws,
            arrays: number_arrays(&counts),
            faces: PatchFaceTable::new(origins),
            bbox: (mesh.bbox_min, mesh.bbox_max),
            _style: std::marker::PhantomData,
        })
    }

    /// The style's patch lists: quads and the other faces' fan triangles, or every face's
    /// fan triangles.
    fn patch_lists(mesh: &RenderMesh) -> Vec<PatchList<'_>> {
        let flat3 = |l: &[[u32; 3]]| l.iter().flatten().copied().collect::<Vec<u32>>();
        let flat4 = |l: &[[u32; 4]]| l.iter().flatten().copied().collect::<Vec<u32>>();
        if S::QUADS {
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
        }
    }

    /// The tessellation path's vertex buffer and per-array index buffers.
    fn tessellated_draws(
        device: &Device,
        mesh: &RenderMesh,
        tagged: Option<&[TaggedCorner]>,
        lists: &[PatchList<'_>],
    ) -> Result<Draws> {
        let vertices = Buffer::with_data(
            device,
            "mesh vertices",
            vk::BufferUsageFlags::VERTEX_BUFFER,
            bytemuck::cast_slice(&mesh.vertices),
        )?;
        let tagged = tagged
            .map(|t| {
                Buffer::with_data(
                    device,
                    "scalar-tagged corners",
                    vk::BufferUsageFlags::VERTEX_BUFFER,
                    bytemuck::cast_slice(t),
                )
            })
            .transpose()?;
        let indices = lists
            .iter()
            .map(|(patch, list, cp, _)| {
                Ok(IndexArray {
                    indices: Buffer::with_data(
                        device,
                        &format!("{} {patch:?} patches", S::ID),
                        vk::BufferUsageFlags::INDEX_BUFFER,
                        bytemuck::cast_slice(list),
                    )?,
                    control_points: *cp,
                })
            })
            .collect::<Result<_>>()?;
        Ok(Draws::Tessellated {
            vertices,
            tagged,
            indices,
        })
    }

    /// The pattern path's per-array corner buffers (each patch's corners, read per instance);
    /// the patterns come with the first frame.
    fn pattern_draws(
        device: &Device,
        mesh: &RenderMesh,
        tagged: Option<&[TaggedCorner]>,
        lists: &[PatchList<'_>],
    ) -> Result<Draws> {
        let tagged = tagged
            .map(|t| {
                lists
                    .iter()
                    .map(|(patch, list, _, _)| {
                        let corners: Vec<TaggedCorner> =
                            list.iter().map(|&i| t[i as usize]).collect();
                        Ok(Buffer::with_data(
                            device,
                            &format!("{} {patch:?} pattern tagged corners", S::ID),
                            vk::BufferUsageFlags::VERTEX_BUFFER,
                            bytemuck::cast_slice(&corners),
                        )?)
                    })
                    .collect::<Result<Vec<_>>>()
            })
            .transpose()?;
        let corners = lists
            .iter()
            .map(|(patch, list, _, _)| {
                let corners: Vec<Vertex> =
                    list.iter().map(|&i| mesh.vertices[i as usize]).collect();
                Ok(Buffer::with_data(
                    device,
                    &format!("{} {patch:?} pattern corners", S::ID),
                    vk::BufferUsageFlags::VERTEX_BUFFER,
                    bytemuck::cast_slice(&corners),
                )?)
            })
            .collect::<Result<_>>()?;
        Ok(Draws::Patterns {
            corners,
            tagged,
            current: [None, None],
            from_tessellator: crate::pattern::from_tessellator(device),
        })
    }

    /// Whether the mesh is drawn with its scalar tags.
    fn is_tagged(&self) -> bool {
        match &self.draws {
            Draws::Tessellated { tagged, .. } => tagged.is_some(),
            Draws::Patterns { tagged, .. } => tagged.is_some(),
        }
    }

    /// Uniform level of `params` (base-face patches take uniform factors only).
    fn level(&self, params: &FrameParams) -> f32 {
        params
            .uniform_segments()
            .unwrap_or(1.0)
            .clamp(1.0, self.max_level())
    }

    /// The tessellator's 64; on the pattern path, what generated patterns reach beyond it.
    fn max_level(&self) -> f32 {
        match self.draws {
            Draws::Tessellated { .. } => MAX_LEVEL,
            Draws::Patterns { .. } => crate::pattern::MAX_GENERATED_SEGMENTS as f32,
        }
    }

    /// The frame's pattern of `array`'s domain, once [`Technique::prepare_frame`] made it.
    fn pattern(&self, array: usize) -> Option<&PatternBuffers> {
        let Draws::Patterns { current, .. } = &self.draws else {
            return None;
        };
        let domain = self.arrays.get(array)?.patch.domain();
        current[domain_slot(domain)].as_ref()
    }

    /// Records the pattern path's one instanced draw of `array`.
    fn record_patterns<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        pass: Pass,
    ) -> Result<DrawCounts> {
        let (
            Some(a),
            Draws::Patterns {
                corners, tagged, ..
            },
        ) = (self.arrays.get(array), &self.draws)
        else {
            return Err(TessError::NoPatchArray { array });
        };
        let (Some(corners), Some(p)) = (corners.get(array), self.pattern(array)) else {
            return Err(TessError::NoPatchArray { array });
        };
        enc.bind_vertex_buffer(0, &p.points);
        enc.bind_vertex_buffer(1, corners);
        if let Some(t) = tagged {
            let t = t.get(array).ok_or(TessError::NoPatchArray { array })?;
            enc.bind_vertex_buffer(2, t);
        }
        enc.bind_index_buffer_u32(&p.indices);
        enc.push_constants(&DrawPush {
            mode: pass.mode(),
            first_patch: a.first_patch,
        })?;
        enc.draw_indexed_instanced(0..3 * p.pattern.triangles.len() as u32, 0..a.patches)?;
        Ok(DrawCounts {
            draws: 1,
            patches: a.patches,
        })
    }
}

/// The refinement-pattern path's patch type of a tessellation-path one.
fn pattern_type(patch: PatchType) -> PatchType {
    match patch.domain() {
        Domain::Quad => PatchType::PatternQuad,
        Domain::Triangle => PatchType::PatternTriangle,
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
        let patterns = matches!(self.draws, Draws::Patterns { .. });
        match params.factors {
            FactorPolicy::Uniform { segments } if (1.0..=self.max_level()).contains(&segments) => {
                Ok(())
            }
            FactorPolicy::Uniform { segments } => Err(ParamError::refused(
                Param::Segments,
                segments,
                if patterns {
                    "expected 1..256 on the pattern path"
                } else {
                    "expected 1..64"
                },
            )),
            _ => Err(TessError::Unsupported {
                technique: S::ID,
                what: "adaptive factors",
            }),
        }
    }

    fn patch_pipeline(&self, patch: PatchType) -> PatchPipeline {
        if let Some(p) = self
            .is_tagged()
            .then(|| S::tagged_pipeline(patch))
            .flatten()
        {
            return p;
        }
        if patch.path() != DrawPath::Pattern {
            return S::pipeline(patch);
        }
        let vertex_input = match patch.domain() {
            Domain::Triangle => pattern_input::TRIANGLE,
            Domain::Quad => pattern_input::QUAD,
        };
        PatchPipeline {
            vertex_input,
            ..PatchPipeline::triangles(S::pattern_stage(patch.domain()), Stage::CommonShadeFrag)
        }
    }

    /// On the pattern path, takes the frame's patterns from the context (made once per
    /// domain, spacing and level) and uploads those that changed.
    fn prepare_frame(&mut self, ctx: &mut Context, params: &FrameParams) -> Result<()> {
        let level = self.level(params);
        let domains: Vec<Domain> = self.arrays.iter().map(|a| a.patch.domain()).collect();
        let Draws::Patterns { current, .. } = &mut self.draws else {
            return Ok(());
        };
        for domain in domains {
            let pattern = ctx.refinement_pattern(domain, params.spacing, level)?;
            let slot = &mut current[domain_slot(domain)];
            if !slot
                .as_ref()
                .is_some_and(|p| Arc::ptr_eq(&p.pattern, &pattern))
            {
                let key = PatternKey::new(domain, params.spacing, level);
                *slot = Some(PatternBuffers::new(ctx.device(), key, pattern)?);
            }
        }
        Ok(())
    }

    fn max_vertices_per_patch(&self, params: &FrameParams, array: usize) -> u64 {
        if let Some(p) = self.pattern(array) {
            return p.pattern.points.len() as u64;
        }
        let domain = self.arrays[array].patch.domain();
        uniform_vertex_count(domain, params.spacing, self.level(params))
    }

    fn triangles(&self, params: &FrameParams, array: usize) -> Option<u64> {
        let a = self.arrays.get(array)?;
        if let Draws::Patterns {
            from_tessellator, ..
        } = self.draws
        {
            let level = self.level(params);
            let per_patch = match self.pattern(array) {
                Some(p) if p.key == PatternKey::new(a.patch.domain(), params.spacing, level) => {
                    p.pattern.triangles.len() as u64
                }
                _ if from_tessellator && level <= MAX_LEVEL => {
                    uniform_triangle_count(a.patch.domain(), params.spacing, level)
                }
                _ => crate::pattern::generated_triangle_count(a.patch.domain(), level),
            };
            return Some(a.patches as u64 * per_patch);
        }
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
        let Draws::Tessellated {
            vertices,
            tagged,
            indices,
        } = &self.draws
        else {
            return self.record_patterns(enc, array, pass);
        };
        let (a, list) = match (self.arrays.get(array), indices.get(array)) {
            (Some(a), Some(l)) => (*a, l),
            _ => return Err(TessError::NoPatchArray { array }),
        };
        enc.bind_vertex_buffer(0, vertices);
        if let Some(t) = tagged {
            enc.bind_vertex_buffer(1, t);
        }
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

    /// The render mesh's vertex buffer (positions and normals) and the patch index buffers; on
    /// the pattern path, the patches' corners and the frame's patterns.
    fn device_memory(&self) -> Vec<DeviceAllocation> {
        let buffers: Vec<&Buffer> = match &self.draws {
            Draws::Tessellated {
                vertices,
                tagged,
                indices,
            } => std::iter::once(vertices)
                .chain(tagged)
                .chain(indices.iter().map(|a| &a.indices))
                .collect(),
            Draws::Patterns {
                corners,
                tagged,
                current,
                ..
            } => corners
                .iter()
                .chain(tagged.iter().flatten())
                .chain(
                    current
                        .iter()
                        .flatten()
                        .flat_map(|p| [&p.points, &p.indices]),
                )
                .collect(),
        };
        buffers
            .into_iter()
            .map(DeviceAllocation::of_buffer)
            .collect()
    }
}
