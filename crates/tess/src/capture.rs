//! Exactly what the GPU's TES produced, captured through transform feedback, and CPU
//! post-processing that never recomputes geometry.
//!
//! # Capture
//! [`Capturer::capture`] records a frame's draws (the same patch lists, draw splits and frame
//! uniforms as [`crate::Renderer`]) with the `-DCAPTURE` TES builds and rasterizer discard. Every
//! emitted triangle corner becomes one [`CaptureRecord`] (the 40-byte contract of
//! `glsl/common/tese_out.glsl`). Each patch list writes its own region of the buffer, sized by
//! the CPU tessellator's exact triangle count; a transform-feedback stream query per list counts
//! primitives written and needed, and if a region overflowed (a TCS that sets other levels than
//! the CPU assumed) a second pass runs with the measured sizes, so no triangle is lost silently.
//! [`CaptureSizing::Measure`] skips the CPU bound: the first pass only measures.
//!
//! # Post-processing
//! - [`CapturedSoup::weld`] merges corners only when the bits of their three position
//!   coordinates are identical (`f32::to_bits`; so `-0.0` and `0.0` stay apart). Two patches
//!   that evaluate a shared edge in a different float order give different bits: that is a real
//!   crack in what the GPU drew, and welding does not hide it.
//! - [`WeldedMesh::open_edges`] counts edges used by exactly one triangle, edges used by three or
//!   more (non-manifold) and zero-area triangles (two identical welded corners; reported, kept in
//!   the mesh, left out of edge use).
//! - [`classify_open_edges`] splits open edges into those on the base mesh's own boundary and
//!   cracks, from the base mesh topology and the captured domain coordinates only.
//!
//! # Patch ids and base faces
//! A captured patch id is the frame-wide patch number of [`crate::renderer::draw_lists`]. A
//! [`PatchToFace`] closure maps (patch id, domain coordinate) to a [`FacePoint`] on the base mesh;
//! [`PatchFaceTable`] is the one for the triangle/quad techniques (identity for triangle meshes;
//! fan triangles of n-gons map into their n-gon), and a technique with its own patches supplies
//! its own. Face domains follow [`face_corner_uv`].
//!
//! # OBJ written by [`WeldedMesh::write_obj`]
//! ```text
//! # tessera capture: V welded vertices, T triangles, corners welded by position bits
//! v X Y Z          one per welded vertex, shortest round-trip f32 text (parses to the same bits)
//! vn X Y Z         its normal (as the TES shaded it, from the first corner welded into it)
//! # p F U V        its base face F (0-based, in the base OBJ's face order) and (U, V) in that
//!                  face's domain (first corner welded into it; a vertex on a shared edge has
//!                  one such line, for one of its faces)
//! f A//A B//B C//C  one per captured triangle, 1-based, zero-area ones included; corners in
//!                  captured order, or reversed with [`Winding::Reversed`]
//! ```
//!
//! Winding: the triangle/quad TESs declare `ccw`, but with Vulkan's upper-left domain origin
//! their triangles come out clockwise seen from the side the base face faces (the captured cube
//! has negative signed volume). Rendering culls nothing, so it does not matter there; an OBJ
//! should wind like its normals, so their export writes [`Winding::Reversed`].
use crate::error::{Result, TessError};
use crate::render_mesh::PatchOrigin;
use crate::renderer::{
    draw_lists, frame_uniforms, patches_per_draw, record_list_draws, set_patch_input,
    technique_stages, DrawCounts, DrawParams, FrameSets, GpuMesh, Method,
};
use crate::tessellator::{uniform_triangle_count, Domain, Spacing};
use std::collections::HashMap;
use std::io::Write as _;
use std::path::Path;
use topology::ControlMesh;
use vk_core::pipeline::{GraphicsPipelineDesc, Pipeline, ShaderStage};
use vk_core::query::{QueryPool, TransformFeedbackCounts};
use vk_core::transform_feedback::TransformFeedbackCommands;
use vk_core::{vk, Buffer, BufferDesc, Device, MemoryLocation};

pub use crate::gpu::{CaptureRecord, CAPTURE_STRIDE};

/// Bytes of one captured triangle.
const TRIANGLE_BYTES: u64 = 3 * CAPTURE_STRIDE;

/// Every corner the TES emitted, three per triangle, in the order the GPU wrote them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CapturedSoup {
    pub records: Vec<CaptureRecord>,
}

/// What one capture did, for tests and reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CaptureStats {
    pub draws: u32,
    pub patches: u32,
    /// Triangles the CPU tessellator predicted (what the first pass was sized for).
    pub expected_triangles: u64,
    /// Summed over the patch lists.
    pub primitives_written: u64,
    pub primitives_needed: u64,
    /// 1, or 2 when the first pass overflowed and was rerun with the measured size.
    pub passes: u32,
}

impl CapturedSoup {
    pub fn triangle_count(&self) -> usize {
        self.records.len() / 3
    }

    /// The captured triangles, three corners each.
    pub fn triangles(&self) -> impl Iterator<Item = &[CaptureRecord]> + '_ {
        self.records.chunks_exact(3)
    }

    /// Merges corners whose position bits are identical into one indexed vertex; triangles keep
    /// their captured order and corner order (triangle `t` is corners `3t..3t + 3`).
    pub fn weld(&self) -> Result<WeldedMesh> {
        if !self.records.chunks_exact(3).remainder().is_empty() {
            return Err(TessError::Invalid(format!(
                "captured soup has {} corners, not whole triangles",
                self.records.len()
            )));
        }
        let mut index: HashMap<[u32; 3], u32> = HashMap::with_capacity(self.records.len() / 4);
        let mut out = WeldedMesh::default();
        let mut corner_vertex = Vec::with_capacity(self.records.len());
        for r in &self.records {
            let key = r.position.map(f32::to_bits);
            let id = *index.entry(key).or_insert_with(|| {
                out.positions.push(r.position);
                out.normals.push(r.normal);
                out.patch.push(r.patch);
                out.domain.push(r.domain);
                out.flags.push(r.flags);
                (out.positions.len() - 1) as u32
            });
            corner_vertex.push(id);
        }
        out.triangles = corner_vertex
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        Ok(out)
    }
}

/// The soup welded by position bits. Per-vertex attributes come from the first corner welded
/// into the vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WeldedMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub patch: Vec<u32>,
    pub domain: Vec<[f32; 2]>,
    pub flags: Vec<u32>,
    pub triangles: Vec<[u32; 3]>,
}

/// An edge used by exactly one triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OpenEdge {
    /// Welded vertex indices, smaller first.
    pub vertices: [u32; 2],
    /// The triangle using it (also its index in the soup: corners `3t..3t + 3`).
    pub triangle: u32,
}

/// Edge use of a welded mesh.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EdgeReport {
    /// Edges used by exactly one triangle, sorted.
    pub open: Vec<OpenEdge>,
    /// Edges used by three or more triangles, sorted.
    pub non_manifold: Vec<[u32; 2]>,
    /// Triangles with two identical welded corners, in order (not counted in edge use).
    pub zero_area: Vec<u32>,
}

impl WeldedMesh {
    /// Counts how many triangles use each edge; see [`EdgeReport`].
    pub fn open_edges(&self) -> EdgeReport {
        let mut uses: HashMap<[u32; 2], (u32, u32)> = HashMap::new();
        let mut report = EdgeReport::default();
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
                report.zero_area.push(t as u32);
                continue;
            }
            for i in 0..3 {
                let (a, b) = (tri[i], tri[(i + 1) % 3]);
                let e = uses.entry([a.min(b), a.max(b)]).or_insert((0, t as u32));
                e.0 += 1;
            }
        }
        for (edge, (count, triangle)) in uses {
            match count {
                1 => report.open.push(OpenEdge {
                    vertices: edge,
                    triangle,
                }),
                2 => {}
                _ => report.non_manifold.push(edge),
            }
        }
        report.open.sort_by_key(|e| e.vertices);
        report.non_manifold.sort();
        report
    }

    /// Writes the mesh as OBJ (format in the module doc); `map` names each vertex's base face.
    pub fn write_obj(&self, path: &Path, map: &PatchToFace<'_>, winding: Winding) -> Result<()> {
        let io = |source| TessError::Io {
            path: path.display().to_string(),
            source,
        };
        let file = std::fs::File::create(path).map_err(io)?;
        let mut w = std::io::BufWriter::new(file);
        self.write_obj_to(&mut w, map, winding)
            .map_err(|e| match e {
                ObjWriteError::Io(source) => io(source),
                ObjWriteError::Unmapped { vertex, patch } => TessError::Invalid(format!(
                    "{}: vertex {vertex} has patch id {patch}, which maps to no base face",
                    path.display()
                )),
            })?;
        w.flush().map_err(io)
    }

    fn write_obj_to(
        &self,
        w: &mut impl std::io::Write,
        map: &PatchToFace<'_>,
        winding: Winding,
    ) -> std::result::Result<(), ObjWriteError> {
        writeln!(
            w,
            "# tessera capture: {} welded vertices, {} triangles, corners welded by position bits",
            self.positions.len(),
            self.triangles.len()
        )?;
        writeln!(
            w,
            "# per vertex: v, vn, then '# p <base face> <u> <v>' (0-based face, its domain)"
        )?;
        for (i, (p, n)) in self.positions.iter().zip(&self.normals).enumerate() {
            let fp = map(self.patch[i], self.domain[i]).ok_or(ObjWriteError::Unmapped {
                vertex: i,
                patch: self.patch[i],
            })?;
            writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
            writeln!(w, "vn {} {} {}", n[0], n[1], n[2])?;
            writeln!(w, "# p {} {} {}", fp.face, fp.u, fp.v)?;
        }
        for t in &self.triangles {
            let [a, b, c] = match winding {
                Winding::AsCaptured => t.map(|i| i + 1),
                Winding::Reversed => [t[0] + 1, t[2] + 1, t[1] + 1],
            };
            writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?;
        }
        Ok(())
    }
}

/// Corner order of the faces [`WeldedMesh::write_obj`] writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Winding {
    /// The order the GPU wrote the corners in.
    #[default]
    AsCaptured,
    /// Second and third corners swapped (see the module doc on winding).
    Reversed,
}

enum ObjWriteError {
    Io(std::io::Error),
    Unmapped { vertex: usize, patch: u32 },
}

impl From<std::io::Error> for ObjWriteError {
    fn from(e: std::io::Error) -> Self {
        ObjWriteError::Io(e)
    }
}

/// A point of the base mesh: face index and its (u, v) in the face's domain ([`face_corner_uv`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacePoint {
    pub face: u32,
    pub u: f32,
    pub v: f32,
}

/// Maps a captured patch id and domain coordinate to the base mesh; `None` for an unknown patch.
pub type PatchToFace<'a> = dyn Fn(u32, [f32; 2]) -> Option<FacePoint> + 'a;

/// Where corner `k` of an `n`-sided face sits in the face's (u, v) domain:
/// - triangles: corner 0 (1, 0), corner 1 (0, 1), corner 2 (0, 0), so (u, v) are the
///   barycentric weights of corners 0 and 1 (= `gl_TessCoord.xy` of a triangle patch);
/// - quads: (0, 0), (1, 0), (1, 1), (0, 1), the bilinear domain of the quad TES;
/// - n-gons, n ≥ 5: the regular n-gon inscribed in the unit square's circle,
///   (½ + ½ cos 2πk/n, ½ + ½ sin 2πk/n); a fan triangle's barycentrics map linearly into it.
pub fn face_corner_uv(n: u32, k: u32) -> [f64; 2] {
    match (n, k % n.max(1)) {
        (3, 0) => [1.0, 0.0],
        (3, 1) => [0.0, 1.0],
        (3, _) => [0.0, 0.0],
        (4, 0) => [0.0, 0.0],
        (4, 1) => [1.0, 0.0],
        (4, 2) => [1.0, 1.0],
        (4, _) => [0.0, 1.0],
        (n, k) => {
            let a = std::f64::consts::TAU * k as f64 / n as f64;
            [0.5 + 0.5 * a.cos(), 0.5 + 0.5 * a.sin()]
        }
    }
}

/// How far (in domain units) a captured coordinate may sit from a face edge and still count as
/// on it: the tessellator's edge coordinates are exact 0 or 1 or i/n with 1 − x − y rounding.
const ON_EDGE: f64 = 1e-5;

/// The face-local edges (edge `k` runs from corner `k` to corner `k + 1`) that `uv` lies on.
pub fn face_edges_at(n: u32, uv: [f32; 2]) -> Vec<u32> {
    let p = [uv[0] as f64, uv[1] as f64];
    (0..n)
        .filter(|&k| {
            let a = face_corner_uv(n, k);
            let b = face_corner_uv(n, k + 1);
            let d = [b[0] - a[0], b[1] - a[1]];
            let len2 = d[0] * d[0] + d[1] * d[1];
            let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0);
            let q = [a[0] + t * d[0] - p[0], a[1] + t * d[1] - p[1]];
            (q[0] * q[0] + q[1] * q[1]).sqrt() <= ON_EDGE
        })
        .collect()
}

/// The patch → base face table of the triangle/quad techniques, indexed by captured patch id
/// (from [`crate::RenderMesh::patch_origins`]).
#[derive(Clone, Debug, Default)]
pub struct PatchFaceTable {
    pub origins: Vec<PatchOrigin>,
}

impl PatchFaceTable {
    pub fn new(origins: Vec<PatchOrigin>) -> Self {
        Self { origins }
    }

    /// A triangle patch spanning a whole triangle face, or a quad patch, is the identity (bit
    /// for bit); a fan triangle of a larger face maps its barycentrics into the face's domain.
    pub fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint> {
        let o = self.origins.get(patch as usize)?;
        let identity = match o.domain {
            Domain::Quad => true,
            Domain::Triangle => o.face_size == 3,
        };
        if identity {
            return Some(FacePoint {
                face: o.face,
                u: domain[0],
                v: domain[1],
            });
        }
        let b = [
            domain[0] as f64,
            domain[1] as f64,
            1.0 - domain[0] as f64 - domain[1] as f64,
        ];
        let corners = o.face_corners();
        let mut uv = [0.0f64; 2];
        for i in 0..3 {
            let c = face_corner_uv(o.face_size, corners[i]);
            uv[0] += b[i] * c[0];
            uv[1] += b[i] * c[1];
        }
        Some(FacePoint {
            face: o.face,
            u: uv[0] as f32,
            v: uv[1] as f32,
        })
    }
}

/// Open edges split by where they lie.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpenEdgeClasses {
    /// Both endpoints lie on one edge of one base face, and that base edge is a boundary edge
    /// of the base mesh (used by one face).
    pub on_base_boundary: usize,
    /// Every other open edge: a gap the GPU left inside the surface.
    pub cracks: usize,
    /// Of the cracks, those whose patch id maps to no base face (a mapping bug, not geometry).
    pub unmapped: usize,
}

/// Classifies `report.open` from the base mesh's topology and the captured patch ids and domain
/// coordinates of each open edge's own triangle (never from positions).
pub fn classify_open_edges(
    soup: &CapturedSoup,
    welded: &WeldedMesh,
    report: &EdgeReport,
    map: &PatchToFace<'_>,
    base: &ControlMesh,
) -> OpenEdgeClasses {
    let mut uses: HashMap<[u32; 2], u32> = HashMap::new();
    for face in base.faces() {
        for k in 0..face.len() {
            let (a, b) = (face[k], face[(k + 1) % face.len()]);
            *uses.entry([a.min(b), a.max(b)]).or_default() += 1;
        }
    }
    let base_boundary = |face: u32, k: u32| -> bool {
        if face as usize >= base.num_faces() {
            return false;
        }
        let f = base.face(face as usize);
        let n = f.len();
        let (a, b) = (f[k as usize % n], f[(k as usize + 1) % n]);
        uses.get(&[a.min(b), a.max(b)]) == Some(&1)
    };
    let mut out = OpenEdgeClasses::default();
    for e in &report.open {
        let t = e.triangle as usize;
        let corner = |v: u32| {
            (0..3)
                .find(|&i| welded.triangles[t][i] == v)
                .map(|i| soup.records[3 * t + i])
        };
        let (Some(ra), Some(rb)) = (corner(e.vertices[0]), corner(e.vertices[1])) else {
            out.cracks += 1;
            continue;
        };
        let (Some(fa), Some(fb)) = (map(ra.patch, ra.domain), map(rb.patch, rb.domain)) else {
            out.cracks += 1;
            out.unmapped += 1;
            continue;
        };
        let on_boundary = fa.face == fb.face && {
            let n = base
                .faces()
                .nth(fa.face as usize)
                .map_or(0, |f| f.len() as u32);
            let ea = face_edges_at(n, [fa.u, fa.v]);
            let eb = face_edges_at(n, [fb.u, fb.v]);
            ea.iter()
                .any(|k| eb.contains(k) && base_boundary(fa.face, *k))
        };
        if on_boundary {
            out.on_base_boundary += 1;
        } else {
            out.cracks += 1;
        }
    }
    out
}

/// Selects one capture pipeline: like [`crate::renderer::PipelineKey`], without wireframe.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct CaptureKey {
    pub method: Method,
    pub domain: Domain,
    pub spacing: Spacing,
}

/// How the first capture pass sizes each patch list's region.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CaptureSizing {
    /// The CPU tessellator's exact count for uniform levels: one pass.
    #[default]
    CpuBound,
    /// One triangle per list, so the first pass only measures (primitives needed) and the second
    /// captures: for TCSs whose levels the CPU cannot predict.
    Measure,
}

/// Largest capture by default (bytes of records): beyond this the caller must raise
/// [`Capturer::max_bytes`] deliberately.
pub const DEFAULT_MAX_CAPTURE_BYTES: u64 = 1 << 30;

/// Owns capture pipelines and the frame uniforms they read. Drop order: pipelines, frame set,
/// device.
pub struct Capturer {
    pipelines: HashMap<CaptureKey, Pipeline>,
    frame: FrameSets,
    /// Captures needing more record bytes than this fail with [`TessError::CaptureTooLarge`].
    pub max_bytes: u64,
    pub sizing: CaptureSizing,
    device: Device,
}

impl Capturer {
    /// A typed error ([`vk_core::VkError::Unsupported`]) on a device without transform feedback.
    pub fn new(device: &Device) -> Result<Self> {
        device.transform_feedback()?;
        QueryPool::transform_feedback_stream(device, "capture query probe", 1)?;
        Ok(Self {
            pipelines: HashMap::new(),
            frame: FrameSets::new(device, "capture", 1)?,
            max_bytes: DEFAULT_MAX_CAPTURE_BYTES,
            sizing: CaptureSizing::default(),
            device: device.clone(),
        })
    }

    fn pipeline(&mut self, key: CaptureKey) -> Result<&Pipeline> {
        if !self.pipelines.contains_key(&key) {
            let (tesc, tese, cp) = technique_stages(key.method, key.domain, key.spacing, true)?;
            let name = format!(
                "capture {:?} {:?} {:?}",
                key.method, key.domain, key.spacing
            );
            // No attachments: the pass renders nothing, it only feeds transform feedback.
            let mut desc =
                GraphicsPipelineDesc::new(&name, vk::Format::UNDEFINED, vk::Format::UNDEFINED);
            desc.stages = vec![
                ShaderStage::new(
                    vk::ShaderStageFlags::VERTEX,
                    crate::shaders::spirv(
                        crate::shaders::Stage::CommonMeshVert,
                        crate::shaders::Variant::default(),
                    )?,
                ),
                ShaderStage::new(vk::ShaderStageFlags::TESSELLATION_CONTROL, tesc),
                ShaderStage::new(vk::ShaderStageFlags::TESSELLATION_EVALUATION, tese),
            ];
            set_patch_input(&mut desc, cp, self.frame.layout());
            desc.rasterizer_discard = true;
            desc.depth_test = false;
            desc.depth_write = false;
            let p = Pipeline::graphics(&self.device, &desc)?;
            self.pipelines.insert(key, p);
        }
        Ok(&self.pipelines[&key])
    }

    /// Captures the triangles one frame of `params` draws for `mesh` (wireframe is ignored:
    /// it draws the same triangles again).
    pub fn capture(&mut self, mesh: &GpuMesh, params: &DrawParams) -> Result<CapturedSoup> {
        Ok(self.capture_with_stats(mesh, params)?.0)
    }

    /// [`Capturer::capture`], with what it took.
    pub fn capture_with_stats(
        &mut self,
        mesh: &GpuMesh,
        params: &DrawParams,
    ) -> Result<(CapturedSoup, CaptureStats)> {
        let u = frame_uniforms(
            mesh,
            params,
            vk::Extent2D {
                width: 1,
                height: 1,
            },
        );
        self.frame.write(0, &u)?;
        let level = params.level.clamp(1.0, crate::tessellator::MAX_LEVEL);
        let lists = draw_lists(mesh, params.method);
        let expected: Vec<u64> = lists
            .iter()
            .map(|l| {
                l.list.patches as u64 * uniform_triangle_count(l.domain, params.spacing, level)
            })
            .collect();
        let mut stats = CaptureStats {
            expected_triangles: expected.iter().sum(),
            ..Default::default()
        };
        let mut capacity = match self.sizing {
            CaptureSizing::CpuBound => expected.clone(),
            CaptureSizing::Measure => vec![1; expected.len()],
        };
        for pass in 1..=2 {
            let (soup, counts, draws) = self.capture_pass(mesh, params, &capacity)?;
            let overflow = counts.iter().zip(&capacity).any(|(c, &cap)| {
                c.primitives_needed > cap || c.primitives_written < c.primitives_needed
            });
            if overflow && pass == 1 {
                log::info!("capture pass 1 overflowed ({counts:?} for {capacity:?}); rerunning");
                capacity = counts
                    .iter()
                    .zip(&capacity)
                    .map(|(c, &cap)| cap.max(c.primitives_needed))
                    .collect();
                continue;
            }
            if overflow {
                return Err(TessError::Invalid(format!(
                    "transform feedback overflowed twice: {counts:?} for capacities {capacity:?}"
                )));
            }
            stats.draws = draws.draws;
            stats.patches = draws.patches;
            stats.primitives_written = counts.iter().map(|c| c.primitives_written).sum();
            stats.primitives_needed = counts.iter().map(|c| c.primitives_needed).sum();
            stats.passes = pass;
            return Ok((soup, stats));
        }
        unreachable!("the loop returns on its second pass")
    }

    /// One capture pass: list `i` writes at most `capacity[i]` triangles into its own region.
    fn capture_pass(
        &mut self,
        mesh: &GpuMesh,
        params: &DrawParams,
        capacity: &[u64],
    ) -> Result<(CapturedSoup, Vec<TransformFeedbackCounts>, DrawCounts)> {
        let device = self.device.clone();
        let xfb = device.transform_feedback()?.clone();
        let triangles: u64 = capacity.iter().sum();
        let bytes = triangles.max(1) * TRIANGLE_BYTES;
        let limit = self
            .max_bytes
            .min(device.info.caps.max_transform_feedback_buffer_size);
        if bytes > limit {
            return Err(TessError::CaptureTooLarge {
                triangles,
                bytes,
                limit,
            });
        }
        let buffer = Buffer::new(
            &device,
            &BufferDesc {
                name: "capture records",
                size: bytes,
                usage: vk::BufferUsageFlags::TRANSFORM_FEEDBACK_BUFFER_EXT,
                location: MemoryLocation::GpuToCpu,
            },
        )?;
        let lists = draw_lists(mesh, params.method);
        if lists.is_empty() {
            // Nothing to draw; a query that is never begun would never become available.
            return Ok((CapturedSoup::default(), Vec::new(), DrawCounts::default()));
        }
        let query = QueryPool::transform_feedback_stream(
            &device,
            "capture primitives",
            lists.len().max(1) as u32,
        )?;
        // Pipelines first: creating them inside the recording closure would borrow self twice.
        let mut pipelines = Vec::new();
        for l in &lists {
            let key = CaptureKey {
                method: params.method,
                domain: l.domain,
                spacing: params.spacing,
            };
            let p = self.pipeline(key)?;
            pipelines.push((p.raw, p.layout));
        }
        let set = self.frame.set(0)?;
        let mut counts = DrawCounts::default();
        let mut failure = None;
        device.one_shot(|cmd| {
            query.cmd_reset(cmd);
            let mut offset = 0u64;
            for (i, (l, &(pipeline, layout))) in lists.iter().zip(&pipelines).enumerate() {
                let size = capacity[i] * TRIANGLE_BYTES;
                // SAFETY: the pipeline, set and buffer are live until one_shot returns (it
                // waits); [offset, offset + size) lies inside the buffer (sizes sum to at most
                // its size).
                unsafe {
                    begin_capture_scope(
                        &device,
                        &xfb,
                        cmd,
                        (pipeline, layout),
                        &[set],
                        (buffer.raw, offset, size.max(4)),
                    )
                };
                if let Err(e) = query.cmd_begin_stream(cmd, i as u32, 0) {
                    failure = Some(e);
                }
                let per_draw = patches_per_draw(&device, params, l.domain, l.list.control_points);
                let c = record_list_draws(&device, cmd, layout, mesh, l, 0, per_draw);
                counts.draws += c.draws;
                counts.patches += c.patches;
                if let Err(e) = query.cmd_end_stream(cmd, i as u32, 0) {
                    failure = Some(e);
                }
                // SAFETY: begun above on this cmd.
                unsafe { end_capture_scope(&device, &xfb, cmd) };
                offset += size;
            }
            // SAFETY: cmd is recording outside a rendering scope.
            unsafe { capture_to_host_barrier(&device, cmd) };
        })?;
        if let Some(e) = failure {
            return Err(e.into());
        }
        let results = query.transform_feedback_results()?;
        let all: Vec<CaptureRecord> = buffer.read()?;
        let mut records = Vec::new();
        let mut offset = 0usize;
        for (i, r) in results.iter().enumerate().take(lists.len()) {
            let written = r.primitives_written.min(capacity[i]) as usize * 3;
            let start = offset / CAPTURE_STRIDE as usize;
            records.extend_from_slice(&all[start..start + written]);
            offset += (capacity[i] * TRIANGLE_BYTES) as usize;
        }
        Ok((CapturedSoup { records }, results, counts))
    }
}

/// Begins a capture scope: an attachment-less 1×1 rendering scope with `pipeline` and `sets`
/// bound and transform feedback writing into `region` (buffer, offset, size).
///
/// # Safety
/// `cmd` is recording outside a rendering scope; the pipeline, sets and buffer outlive the
/// submission; the region lies inside the buffer. Pair with [`end_capture_scope`].
pub(crate) unsafe fn begin_capture_scope(
    device: &Device,
    xfb: &ash::ext::transform_feedback::Device,
    cmd: vk::CommandBuffer,
    (pipeline, layout): (vk::Pipeline, vk::PipelineLayout),
    sets: &[vk::DescriptorSet],
    (buffer, offset, size): (vk::Buffer, u64, u64),
) {
    let area = vk::Rect2D {
        offset: vk::Offset2D { x: 0, y: 0 },
        extent: vk::Extent2D {
            width: 1,
            height: 1,
        },
    };
    let rendering = vk::RenderingInfo::default()
        .render_area(area)
        .layer_count(1);
    let viewport = vk::Viewport {
        x: 0.0,
        y: 0.0,
        width: 1.0,
        height: 1.0,
        min_depth: 0.0,
        max_depth: 1.0,
    };
    // SAFETY: the caller upholds this function's contract.
    unsafe {
        device.raw.cmd_begin_rendering(cmd, &rendering);
        device
            .raw
            .cmd_bind_pipeline(cmd, vk::PipelineBindPoint::GRAPHICS, pipeline);
        device.raw.cmd_bind_descriptor_sets(
            cmd,
            vk::PipelineBindPoint::GRAPHICS,
            layout,
            0,
            sets,
            &[],
        );
        device.raw.cmd_set_viewport(cmd, 0, &[viewport]);
        device.raw.cmd_set_scissor(cmd, 0, &[area]);
        xfb.cmd_bind_transform_feedback_buffer(cmd, 0, buffer, offset, size);
        xfb.cmd_begin_transform_feedback(cmd);
    }
}

/// Ends what [`begin_capture_scope`] began.
///
/// # Safety
/// A capture scope is open on `cmd`.
pub(crate) unsafe fn end_capture_scope(
    device: &Device,
    xfb: &ash::ext::transform_feedback::Device,
    cmd: vk::CommandBuffer,
) {
    // SAFETY: the caller upholds this function's contract.
    unsafe {
        xfb.cmd_end_transform_feedback(cmd);
        device.raw.cmd_end_rendering(cmd);
    }
}

/// Makes transform-feedback writes visible to the host read that follows the submission.
///
/// # Safety
/// `cmd` is recording outside a rendering scope.
pub(crate) unsafe fn capture_to_host_barrier(device: &Device, cmd: vk::CommandBuffer) {
    let barrier = vk::MemoryBarrier::default()
        .src_access_mask(vk::AccessFlags::TRANSFORM_FEEDBACK_WRITE_EXT)
        .dst_access_mask(vk::AccessFlags::HOST_READ);
    // SAFETY: the caller upholds this function's contract.
    unsafe {
        device.raw.cmd_pipeline_barrier(
            cmd,
            vk::PipelineStageFlags::TRANSFORM_FEEDBACK_EXT,
            vk::PipelineStageFlags::HOST,
            vk::DependencyFlags::empty(),
            &[barrier],
            &[],
            &[],
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn rec(p: [f32; 3], patch: u32, d: [f32; 2]) -> CaptureRecord {
        CaptureRecord {
            position: p,
            normal: [0.0, 0.0, 1.0],
            patch,
            flags: 0,
            domain: d,
        }
    }

    /// Two triangles of a unit square, each its own patch, sharing the diagonal.
    fn square(diagonal_b: [f32; 3]) -> CapturedSoup {
        let (a, b, c, d) = (
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        );
        CapturedSoup {
            records: vec![
                rec(a, 0, [1.0, 0.0]),
                rec(b, 0, [0.0, 1.0]),
                rec(c, 0, [0.0, 0.0]),
                rec(a, 1, [1.0, 0.0]),
                rec(diagonal_b, 1, [0.0, 1.0]),
                rec(d, 1, [0.0, 0.0]),
            ],
        }
    }

    #[test]
    fn weld_merges_identical_bits_only() {
        let w = square([1.0, 1.0, 0.0]).weld().unwrap();
        assert_eq!(w.positions.len(), 4);
        assert_eq!(w.triangles, vec![[0, 1, 2], [0, 2, 3]]);
        let r = w.open_edges();
        assert_eq!(r.open.len(), 4, "{r:?}");
        assert!(r.non_manifold.is_empty() && r.zero_area.is_empty());
        // One ulp off on the shared diagonal corner: two vertices, the diagonal opens twice.
        let off = f32::from_bits(1.0f32.to_bits() + 1);
        let w = square([1.0, off, 0.0]).weld().unwrap();
        assert_eq!(w.positions.len(), 5);
        assert_eq!(w.open_edges().open.len(), 6);
        // -0.0 and 0.0 differ in bits: not welded.
        let w = square([1.0, 1.0, -0.0]).weld().unwrap();
        assert_eq!(w.positions.len(), 5);
    }

    #[test]
    fn cracks_are_told_from_base_boundary() {
        // Base: the square as two triangles (0 1 2), (0 2 3): four boundary edges, one inner.
        let base = ControlMesh::from_polygons(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            &[[0u32, 1, 2], [0, 2, 3]],
        );
        let identity = |patch: u32, d: [f32; 2]| {
            Some(FacePoint {
                face: patch,
                u: d[0],
                v: d[1],
            })
        };
        let soup = square([1.0, 1.0, 0.0]);
        let w = soup.weld().unwrap();
        let r = w.open_edges();
        let c = classify_open_edges(&soup, &w, &r, &identity, &base);
        assert_eq!(
            c,
            OpenEdgeClasses {
                on_base_boundary: 4,
                cracks: 0,
                unmapped: 0
            }
        );
        // The one-ulp crack on the inner diagonal: both of its sides are cracks.
        let off = f32::from_bits(1.0f32.to_bits() + 1);
        let soup = square([1.0, off, 0.0]);
        let w = soup.weld().unwrap();
        let r = w.open_edges();
        let c = classify_open_edges(&soup, &w, &r, &identity, &base);
        assert_eq!((c.on_base_boundary, c.cracks), (4, 2), "{r:?}");
        // An unknown patch is a crack, and counted as unmapped.
        let none = |_: u32, _: [f32; 2]| None;
        let c = classify_open_edges(&soup, &w, &r, &none, &base);
        assert_eq!((c.on_base_boundary, c.cracks, c.unmapped), (0, 6, 6));
    }

    #[test]
    fn zero_area_and_non_manifold_are_reported() {
        let p = |x: f32| [x, 0.0, 0.0];
        let q = [0.0, 1.0, 0.0];
        let soup = CapturedSoup {
            records: vec![
                // A zero-area triangle: corners 0 and 1 weld.
                rec(p(0.0), 0, [1.0, 0.0]),
                rec(p(0.0), 0, [0.0, 1.0]),
                rec(q, 0, [0.0, 0.0]),
                // Three triangles on edge (p1, q).
                rec(p(1.0), 1, [1.0, 0.0]),
                rec(q, 1, [0.0, 1.0]),
                rec(p(2.0), 1, [0.0, 0.0]),
                rec(p(1.0), 2, [1.0, 0.0]),
                rec(q, 2, [0.0, 1.0]),
                rec(p(3.0), 2, [0.0, 0.0]),
                rec(p(1.0), 3, [1.0, 0.0]),
                rec(q, 3, [0.0, 1.0]),
                rec(p(4.0), 3, [0.0, 0.0]),
            ],
        };
        let w = soup.weld().unwrap();
        let r = w.open_edges();
        assert_eq!(r.zero_area, vec![0]);
        assert_eq!(r.non_manifold.len(), 1);
        assert_eq!(r.open.len(), 6);
        let broken = CapturedSoup {
            records: soup.records[..4].to_vec(),
        };
        assert!(broken.weld().is_err());
    }

    #[test]
    fn fan_triangles_map_into_their_face() {
        use crate::render_mesh::PatchOrigin;
        let quad = |fan| PatchOrigin {
            face: 7,
            face_size: 4,
            domain: Domain::Triangle,
            fan,
        };
        let t = PatchFaceTable::new(vec![quad(1), quad(2)]);
        // Fan triangle 2 spans corners 0, 2, 3: its corner 1 is the quad's (1, 1).
        let p = t.face_point(1, [0.0, 1.0]).unwrap();
        assert_eq!((p.face, p.u, p.v), (7, 1.0, 1.0));
        let p = t.face_point(0, [0.5, 0.5]).unwrap();
        assert_eq!((p.u, p.v), (0.5, 0.0));
        assert!(t.face_point(2, [0.0, 0.0]).is_none());
        assert_eq!(face_edges_at(4, [0.5, 0.0]), vec![0]);
        assert_eq!(face_edges_at(4, [1.0, 1.0]), vec![1, 2]);
        assert_eq!(face_edges_at(3, [0.25, 0.75]), vec![0]);
        assert!(face_edges_at(5, [0.5, 0.5]).is_empty());
        // Fan triangle 2 of a pentagon spans corners 0, 2, 3: halfway along its corners 1–2
        // is on the pentagon's edge 2; halfway along 0–2 (weights of corners 0 and 2) is on
        // the inner fan diagonal 0–3, on no edge.
        let t = PatchFaceTable::new(vec![PatchOrigin {
            face: 3,
            face_size: 5,
            domain: Domain::Triangle,
            fan: 2,
        }]);
        let p = t.face_point(0, [0.0, 0.5]).unwrap();
        assert_eq!(face_edges_at(5, [p.u, p.v]), vec![2]);
        let p = t.face_point(0, [0.5, 0.0]).unwrap();
        assert!(face_edges_at(5, [p.u, p.v]).is_empty());
        let p = t.face_point(0, [1.0, 0.0]).unwrap();
        assert_eq!(face_edges_at(5, [p.u, p.v]), vec![0, 4], "corner 0");
    }
}
