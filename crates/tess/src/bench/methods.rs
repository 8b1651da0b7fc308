//! The techniques as the benchmark drives them, behind one trait, and the registry that builds
//! them by name. A new technique is one [`MethodEntry`] in [`registry`].
use super::{BenchConfig, BenchMesh};
use crate::camera::Camera;
use crate::error::{Result, TessError};
use crate::gpu::Vertex;
use crate::plain::{PlainMesh, PlainRenderer};
use crate::render_mesh::angle_weighted_normals;
use crate::renderer::{DrawParams, DrawSplit, GpuMesh, Method, Renderer};
use crate::tessellator::{uniform_triangle_count, Domain, Spacing, MAX_LEVEL};
use std::time::Instant;
use topology::eval::{LimitScheme, LocalMesh};
use topology::{refine_level, ControlMesh, Level, Scheme};
use vk_core::{vk, Device};

/// What one frame of a row asks for.
#[derive(Clone, Copy, Debug)]
pub struct BenchFrame {
    /// Frame number within the row, warm-up frames included (0 is the first warm-up frame).
    pub index: u32,
    /// A warm-up frame (its times are not in the row).
    pub warmup: bool,
    /// Segments per base edge S (the paper's 4×4, 16×16, 32×32 splits: S = 4, 16, 32).
    pub segments: u32,
    pub extent: vk::Extent2D,
    pub camera: Camera,
}

/// Everything a method may need to build its resources for one mesh.
pub struct MethodContext<'a> {
    pub device: &'a Device,
    pub mesh: &'a BenchMesh,
    pub config: &'a BenchConfig,
    pub color_format: vk::Format,
    pub depth_format: vk::Format,
}

/// One technique as the benchmark drives it. Per frame the runner calls `begin_frame` (host
/// work), then records one command buffer: timestamp, `record_pre_pass` (outside any rendering
/// scope: compute), the rendering scope with `record` (draws), timestamp; it submits and waits.
/// The GPU time is the span between the two timestamps, so a compute pre-pass counts.
pub trait BenchMethod {
    /// The row label, equal to the name it was built by ("flat", "cpu-static", ...).
    fn label(&self) -> &str;

    /// Why this method cannot run at `segments` on its mesh (the row is listed as skipped).
    fn skip_reason(&self, segments: u32) -> Option<String> {
        let _ = segments;
        None
    }

    /// Host work before the frame is recorded: uniforms and, for CPU techniques, the frame's
    /// subdivision. Returns the CPU milliseconds that belong to the frame's cost (`None`: the
    /// method has no per-frame CPU work worth reporting).
    fn begin_frame(&mut self, frame: &BenchFrame) -> Result<Option<f64>>;

    /// Commands recorded before the rendering scope, inside the timed span (a compute pre-pass).
    fn record_pre_pass(&mut self, cmd: vk::CommandBuffer, frame: &BenchFrame) -> Result<()> {
        let _ = (cmd, frame);
        Ok(())
    }

    /// The frame's draws, inside the rendering scope. Returns how many triangles they emit by
    /// the CPU's count (the tessellator's arithmetic for tessellated draws); the runner checks it
    /// against the pipeline-statistics count where the device has one.
    fn record(&mut self, cmd: vk::CommandBuffer, frame: &BenchFrame) -> Result<u64>;

    /// Notes about the row just measured (called once after its last frame).
    fn row_notes(&mut self) -> Vec<String> {
        Vec::new()
    }

    /// Lines for the report header, e.g. the memory of the method's tables.
    fn report_notes(&self) -> Vec<String> {
        Vec::new()
    }

    /// Whether a pipeline-statistics query may wrap this method's frame (a driver workaround
    /// can forbid it; the row then reports the CPU triangle count).
    fn statistics_query_safe(&self) -> bool {
        true
    }
}

/// Builds the rows of one registry entry for one mesh (usually one method).
pub type MethodFactory = fn(&MethodContext<'_>) -> Result<Vec<Box<dyn BenchMethod>>>;

/// A name the command line accepts and what it builds.
pub struct MethodEntry {
    pub name: &'static str,
    pub help: &'static str,
    pub build: MethodFactory,
}

/// Wraps one method as a factory result.
pub fn one<M: BenchMethod + 'static>(method: Result<M>) -> Result<Vec<Box<dyn BenchMethod>>> {
    Ok(vec![Box::new(method?)])
}

/// Every technique the benchmark knows, in table order (Flat first: the ratios divide by it).
/// Adding a technique is one entry here.
pub fn registry() -> Vec<MethodEntry> {
    vec![
        MethodEntry {
            name: "flat",
            help: "flat tessellation at level S (no displacement)",
            build: |c| one(TessMethod::new(c, Method::Flat, "flat")),
        },
        MethodEntry {
            name: "phong",
            help: "Phong tessellation at level S",
            build: |c| one(TessMethod::new(c, Method::Phong, "phong")),
        },
        MethodEntry {
            name: "pn",
            help: "curved PN triangles at level S",
            build: |c| one(TessMethod::new(c, Method::Pn, "pn")),
        },
        MethodEntry {
            name: "bft",
            help: "Loop limit surface from basis-function tables (one GPU subdivision step per \
                   frame, then S/2 segments per level-1 edge): bft (static base) and \
                   bft-animated (the --animate wave uploaded every frame)",
            build: |c| {
                Ok(vec![
                    Box::new(BftMethod::new(c, false)?),
                    Box::new(BftMethod::new(c, true)?),
                ])
            },
        },
        MethodEntry {
            name: "cpu",
            help: "CPU Loop subdivision to level log2 S at the limit, drawn as plain triangles: \
                   cpu-static (drawn only) and cpu-animated (re-subdivided and uploaded every frame)",
            build: |c| {
                Ok(vec![
                    Box::new(CpuLoopMethod::new(c, false)?),
                    Box::new(CpuLoopMethod::new(c, true)?),
                ])
            },
        },
    ]
}

/// The registry's names, for messages.
pub fn method_names() -> Vec<&'static str> {
    registry().iter().map(|e| e.name).collect()
}

/// Builds the methods named in `names` for one mesh, in registry order.
pub fn build_methods(
    names: &[String],
    ctx: &MethodContext<'_>,
) -> Result<Vec<Box<dyn BenchMethod>>> {
    let entries = registry();
    if let Some(bad) = names
        .iter()
        .find(|n| !entries.iter().any(|e| e.name == n.as_str()))
    {
        return Err(TessError::Invalid(format!(
            "unknown bench method '{bad}' (known: {})",
            method_names().join(", ")
        )));
    }
    let mut out = Vec::new();
    for e in entries.iter().filter(|e| names.iter().any(|n| n == e.name)) {
        out.extend((e.build)(ctx)?);
    }
    Ok(out)
}

/// Flat, Phong or PN through [`Renderer`]: the base mesh's triangles as patches at level S.
pub struct TessMethod {
    label: &'static str,
    method: Method,
    renderer: Renderer,
    mesh: GpuMesh,
}

impl TessMethod {
    pub fn new(ctx: &MethodContext<'_>, method: Method, label: &'static str) -> Result<Self> {
        Ok(Self {
            label,
            method,
            renderer: Renderer::new(ctx.device, ctx.color_format, ctx.depth_format, 1)?,
            mesh: GpuMesh::upload(ctx.device, &ctx.mesh.render)?,
        })
    }

    fn params(&self, frame: &BenchFrame) -> DrawParams {
        DrawParams {
            method: self.method,
            spacing: Spacing::Equal,
            level: frame.segments as f32,
            camera: frame.camera,
            ..DrawParams::default()
        }
    }

    /// Triangles the draws emit by the tessellator's arithmetic (same lists as `Renderer`).
    fn expected_triangles(&self, segments: u32) -> u64 {
        let level = segments as f32;
        let count = |l: Option<&crate::renderer::PatchList>, d| {
            l.map(|l| l.patches as u64 * uniform_triangle_count(d, Spacing::Equal, level))
                .unwrap_or(0)
        };
        match self.method {
            Method::Flat => {
                count(self.mesh.quads.as_ref(), Domain::Quad)
                    + count(self.mesh.quad_mode_triangles.as_ref(), Domain::Triangle)
            }
            Method::Phong | Method::Pn => count(self.mesh.triangles.as_ref(), Domain::Triangle),
        }
    }
}

impl BenchMethod for TessMethod {
    fn label(&self) -> &str {
        self.label
    }

    fn skip_reason(&self, segments: u32) -> Option<String> {
        (segments as f32 > MAX_LEVEL)
            .then(|| format!("tessellation level {segments} is above the maximum {MAX_LEVEL}"))
    }

    fn begin_frame(&mut self, frame: &BenchFrame) -> Result<Option<f64>> {
        let params = self.params(frame);
        self.renderer
            .update_uniforms(0, &self.mesh, &params, frame.extent)?;
        Ok(None)
    }

    fn record(&mut self, cmd: vk::CommandBuffer, frame: &BenchFrame) -> Result<u64> {
        let params = self.params(frame);
        self.renderer.record(cmd, 0, &self.mesh, &params)?;
        Ok(self.expected_triangles(frame.segments))
    }
}

/// Loop basis-function tables ([`crate::bft`]): the compute pass (base → level-1 positions and
/// normals) is the pre-pass, inside the timed span; the draw is one patch per level-1 face at
/// `S/2` segments per edge, so it emits as many triangles as Flat at `S`.
pub struct BftMethod {
    label: &'static str,
    mesh_name: String,
    animated: bool,
    renderer: Renderer,
    surface: crate::bft::BftSurface,
    rest: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
}

impl BftMethod {
    pub fn new(ctx: &MethodContext<'_>, animated: bool) -> Result<Self> {
        use crate::bft::{base_normals, BftSurface, DEFAULT_TABLE_LEVEL};
        let renderer = Renderer::new(ctx.device, ctx.color_format, ctx.depth_format, 1)?;
        let surface = BftSurface::new(
            &renderer,
            &ctx.mesh.mesh,
            &ctx.mesh.name,
            DEFAULT_TABLE_LEVEL,
            false,
            1,
        )?;
        Ok(Self {
            label: if animated { "bft-animated" } else { "bft" },
            mesh_name: ctx.mesh.name.clone(),
            animated,
            rest: surface.base_positions.clone(),
            normals: base_normals(&ctx.mesh.mesh),
            renderer,
            surface,
        })
    }

    fn params(segments: u32) -> crate::bft::BftParams {
        crate::bft::BftParams {
            factors: crate::bft::FactorPolicy::Uniform { segments },
            ..Default::default()
        }
    }
}

impl BenchMethod for BftMethod {
    fn label(&self) -> &str {
        self.label
    }

    fn skip_reason(&self, segments: u32) -> Option<String> {
        self.surface
            .check_params(&Self::params(segments))
            .err()
            .map(|e| e.to_string())
    }

    fn begin_frame(&mut self, frame: &BenchFrame) -> Result<Option<f64>> {
        let draw = DrawParams {
            camera: frame.camera,
            ..DrawParams::default()
        };
        let bbox = (self.surface.bbox_min, self.surface.bbox_max);
        self.renderer.update_frame(0, bbox, &draw, frame.extent)?;
        if !self.animated {
            return Ok(None);
        }
        // The viewer's --animate: deform on the CPU, upload only the base positions.
        let start = Instant::now();
        let t = frame.index as f32 / 30.0;
        let moved = crate::bft::wave(&self.rest, &self.normals, bbox.0, bbox.1, t);
        self.surface.update_base(0, &moved)?;
        Ok(Some(start.elapsed().as_secs_f64() * 1e3))
    }

    fn record_pre_pass(&mut self, cmd: vk::CommandBuffer, _frame: &BenchFrame) -> Result<()> {
        self.surface.record_compute(cmd, &self.renderer, 0);
        Ok(())
    }

    fn record(&mut self, cmd: vk::CommandBuffer, frame: &BenchFrame) -> Result<u64> {
        let params = Self::params(frame.segments);
        self.surface
            .record_draw(cmd, &self.renderer, 0, &params, DrawSplit::Auto, false)?;
        Ok(self.surface.patch_count() as u64
            * uniform_triangle_count(
                Domain::Triangle,
                Spacing::Equal,
                frame.segments as f32 * 0.5,
            ))
    }

    fn report_notes(&self) -> Vec<String> {
        let g = &self.surface.gpu;
        let words = |n: usize| 4 * n;
        let stencils =
            words(g.stencil_offsets.len() + g.stencil_indices.len() + g.stencil_weights.len());
        vec![format!(
            "{}: BFT tables {} bytes at level {} (the valences and cases present in the mesh), \
             patch records {} bytes, base-to-level-1 stencils {} bytes",
            self.mesh_name,
            self.surface.table_bytes(),
            g.table_words[0],
            words(g.patches.len()),
            stencils
        )]
    }

    fn statistics_query_safe(&self) -> bool {
        !self
            .renderer
            .device()
            .workarounds
            .has(vk_core::workarounds::WorkaroundId::LavapipeStatisticsQueryPointPatches)
    }
}

/// Loop subdivision level k with 2^k = S, or why there is none.
pub fn loop_level_for(segments: u32) -> std::result::Result<usize, String> {
    if segments == 0 || !segments.is_power_of_two() {
        return Err(format!(
            "S = {segments} is not a power of two (Loop subdivision splits edges in 2^k)"
        ));
    }
    Ok(segments.trailing_zeros() as usize)
}

/// Vertices, edges and faces of a closed or open triangle mesh after `level` Loop steps:
/// V' = V + E, E' = 2E + 3F, F' = 4F. Known before refining, to skip levels that would not fit.
pub fn loop_level_size(mesh: &ControlMesh, level: usize) -> (u64, u64, u64) {
    let mut edges = std::collections::HashSet::new();
    for f in mesh.faces() {
        for i in 0..f.len() {
            let (a, b) = (f[i], f[(i + 1) % f.len()]);
            edges.insert((a.min(b), a.max(b)));
        }
    }
    let (mut v, mut e, mut f) = (
        mesh.positions.len() as u64,
        edges.len() as u64,
        mesh.num_faces() as u64,
    );
    for _ in 0..level {
        (v, e, f) = (v + e, 2 * e + 3 * f, 4 * f);
    }
    (v, e, f)
}

/// The CPU result for one frame: the refined mesh at the limit, ready to draw.
pub struct CpuLimitMesh {
    pub vertices: Vec<Vertex>,
    pub indices: Vec<u32>,
}

/// Uniform Loop subdivision of `mesh` to `level` (topology's refiner, OpenSubdiv's rules),
/// every vertex moved to its limit position by the limit masks, normals angle-weighted over the
/// limit positions: M^k on the limit surface, as a CPU application would produce it.
pub fn cpu_loop_limit_mesh(mesh: &ControlMesh, level: usize) -> Result<CpuLimitMesh> {
    let mut current = Level::from_mesh(mesh, Scheme::Loop)?;
    for _ in 0..level {
        current = refine_level(&current, Scheme::Loop, &mesh.options)?.0;
    }
    let positions = match loop_limit_positions(&current) {
        Some(p) => p,
        None => evaluator_limit_positions(&current, level, &mesh.options)?,
    };
    let normals =
        angle_weighted_normals(&positions, current.face_offsets(), current.face_vertices());
    let vertices = positions
        .iter()
        .zip(&normals)
        .map(|(p, n)| Vertex {
            position: p.map(|c| c as f32),
            normal: n.map(|c| c as f32),
        })
        .collect();
    Ok(CpuLimitMesh {
        vertices,
        indices: current.face_vertices().to_vec(),
    })
}

/// Limit positions of every vertex of a Loop level by the limit masks of
/// [`topology::limit::loop_limit_masks`], read straight off the level's edge lists and
/// sharpness: what a CPU application does, without building an evaluator. `None` when a
/// semi-sharp feature is left (its vertices need more refinement first).
pub fn loop_limit_positions(level: &Level) -> Option<Vec<[f64; 3]>> {
    use topology::limit::{loop_limit_masks, LimitRule, LimitVertex};
    use topology::sdc::{is_infinite, is_semi_sharp as semi};
    let t = &level.topology;
    // Smooth weights (vertex, each neighbour) depend on the valence only.
    let mut smooth: std::collections::HashMap<usize, (f64, f64)> = Default::default();
    let mut out = Vec::with_capacity(level.num_vertices());
    for v in 0..level.num_vertices() {
        let vs = level.vertex_sharpness[v];
        if semi(vs) {
            return None;
        }
        let p = level.positions[v];
        let edges = t.vertex_edges(v);
        let mut sharp = Vec::with_capacity(2);
        for &e in edges {
            let s = level.edge_sharpness[e as usize];
            if semi(s) {
                return None;
            }
            if is_infinite(s) {
                let [a, b] = t.edge_vertices(e as usize);
                sharp.push(if a as usize == v { b } else { a });
            }
        }
        let n = edges.len();
        let q = if is_infinite(vs) || sharp.len() > 2 {
            p
        } else if sharp.len() == 2 {
            // Crease (boundaries included): only the two crease neighbours weigh.
            let m = loop_limit_masks(&LimitVertex {
                valence: 2,
                boundary: false,
                rule: LimitRule::Crease { ends: [0, 1] },
            });
            let w = &m.position;
            let (a, b) = (
                level.positions[sharp[0] as usize],
                level.positions[sharp[1] as usize],
            );
            std::array::from_fn(|k| w.vertex * p[k] + w.edges[0] * a[k] + w.edges[1] * b[k])
        } else {
            let (wv, we) = *smooth.entry(n).or_insert_with(|| {
                let m = loop_limit_masks(&LimitVertex {
                    valence: n,
                    boundary: false,
                    rule: LimitRule::Smooth,
                });
                (
                    m.position.vertex,
                    m.position.edges.first().copied().unwrap_or(0.0),
                )
            });
            let mut q = p.map(|c| wv * c);
            for &e in edges {
                let [a, b] = t.edge_vertices(e as usize);
                let w = level.positions[if a as usize == v { b } else { a } as usize];
                for k in 0..3 {
                    q[k] += we * w[k];
                }
            }
            q
        };
        out.push(q);
    }
    Some(out)
}

/// Limit positions through the general evaluator ([`LocalMesh::vertex_limit_position`]), for
/// levels [`loop_limit_positions`] declines.
fn evaluator_limit_positions(
    current: &Level,
    level: usize,
    options: &topology::SubdivOptions,
) -> Result<Vec<[f64; 3]>> {
    let local = LocalMesh::from_refined_level(current, LimitScheme::Loop, options)
        .map_err(|e| TessError::Invalid(format!("limit masks at level {level}: {e}")))?;
    (0..current.num_vertices())
        .map(|v| {
            let p = local.vertex_limit_position(v as u32).ok_or_else(|| {
                TessError::Invalid(format!(
                    "vertex {v} of level {level} has no limit mask (a semi-sharp crease is \
                     left); bench meshes must be crease-free"
                ))
            })?;
            Ok([p[0], p[1], p[2]])
        })
        .collect()
}

/// The paper's comparison point: subdivision on the CPU, a plain triangle draw on the GPU.
/// Static: subdivided once, uploaded once, only the draw is timed. Animated: every frame the
/// control mesh moves, is subdivided again and uploaded (both timed on the CPU), then drawn.
pub struct CpuLoopMethod {
    animated: bool,
    base: ControlMesh,
    max_vertices: u64,
    renderer: PlainRenderer,
    /// The level-k mesh and its k.
    mesh: Option<(usize, PlainMesh)>,
    subdivide_ms: Vec<f64>,
    upload_ms: Vec<f64>,
    device: Device,
}

impl CpuLoopMethod {
    pub fn new(ctx: &MethodContext<'_>, animated: bool) -> Result<Self> {
        Ok(Self {
            animated,
            base: ctx.mesh.mesh.clone(),
            max_vertices: ctx.config.cpu_max_vertices,
            renderer: PlainRenderer::new(ctx.device, ctx.color_format, ctx.depth_format)?,
            mesh: None,
            subdivide_ms: Vec::new(),
            upload_ms: Vec::new(),
            device: ctx.device.clone(),
        })
    }

    /// The control mesh of frame `index`: a slow breathing scale about the bounding-box centre,
    /// so each frame's subdivision works on new positions (its cost does not depend on them).
    fn animated_base(&self, index: u32) -> ControlMesh {
        let mut m = self.base.clone();
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &m.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let s = 1.0 + 0.02 * (index as f64 * 0.4).sin();
        for p in &mut m.positions {
            for k in 0..3 {
                let c = 0.5 * (lo[k] + hi[k]);
                p[k] = c + (p[k] - c) * s;
            }
        }
        m
    }
}

impl BenchMethod for CpuLoopMethod {
    fn label(&self) -> &str {
        if self.animated {
            "cpu-animated"
        } else {
            "cpu-static"
        }
    }

    fn skip_reason(&self, segments: u32) -> Option<String> {
        let level = match loop_level_for(segments) {
            Ok(l) => l,
            Err(e) => return Some(e),
        };
        let (v, _, f) = loop_level_size(&self.base, level);
        (v > self.max_vertices).then(|| {
            format!(
                "Loop level {level} would have {v} vertices and {f} triangles, above the CPU \
                 baseline's limit of {} vertices (--cpu-max-vertices)",
                self.max_vertices
            )
        })
    }

    fn begin_frame(&mut self, frame: &BenchFrame) -> Result<Option<f64>> {
        let level = loop_level_for(frame.segments).map_err(TessError::Invalid)?;
        if self.mesh.as_ref().map(|(k, _)| *k) != Some(level) {
            // Not timed: the static mesh is built once, and the animated one needs its buffers.
            self.mesh = None;
            let cpu = cpu_loop_limit_mesh(&self.base, level)?;
            let gpu = if self.animated {
                PlainMesh::dynamic(&self.device, &cpu.vertices, &cpu.indices)?
            } else {
                PlainMesh::upload(&self.device, &cpu.vertices, &cpu.indices)?
            };
            self.mesh = Some((level, gpu));
        }
        let cpu_ms = if self.animated {
            let start = Instant::now();
            let base = self.animated_base(frame.index);
            let cpu = cpu_loop_limit_mesh(&base, level)?;
            let subdivided = Instant::now();
            if let Some((_, mesh)) = &mut self.mesh {
                mesh.write_vertices(&cpu.vertices)?;
            }
            let done = Instant::now();
            let sub = (subdivided - start).as_secs_f64() * 1e3;
            let up = (done - subdivided).as_secs_f64() * 1e3;
            if !frame.warmup {
                self.subdivide_ms.push(sub);
                self.upload_ms.push(up);
            }
            Some(sub + up)
        } else {
            None
        };
        if let Some((_, mesh)) = &self.mesh {
            let params = DrawParams {
                camera: frame.camera,
                ..DrawParams::default()
            };
            self.renderer.update_uniforms(mesh, &params, frame.extent)?;
        }
        Ok(cpu_ms)
    }

    fn record(&mut self, cmd: vk::CommandBuffer, _frame: &BenchFrame) -> Result<u64> {
        let (_, mesh) = self
            .mesh
            .as_ref()
            .ok_or_else(|| TessError::Invalid("cpu baseline recorded before begin_frame".into()))?;
        self.renderer.record(cmd, mesh)
    }

    fn row_notes(&mut self) -> Vec<String> {
        let mut notes = Vec::new();
        if let Some((level, mesh)) = &self.mesh {
            notes.push(format!(
                "Loop level {level}: {} vertices, {} KiB of vertices + indices on the GPU",
                mesh.vertex_count,
                (mesh.vertex_count as u64 * std::mem::size_of::<Vertex>() as u64
                    + mesh.index_count as u64 * 4)
                    / 1024
            ));
        }
        if self.animated && !self.subdivide_ms.is_empty() {
            let med = |v: &[f64]| super::stats::median(v).unwrap_or(f64::NAN);
            notes.push(format!(
                "CPU per frame (medians): subdivide + limit + normals {:.2} ms, upload {:.2} ms",
                med(&self.subdivide_ms),
                med(&self.upload_ms)
            ));
        }
        self.subdivide_ms.clear();
        self.upload_ms.clear();
        notes
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3 × 2 grid of quads split into triangles: boundary creases and corners.
    fn open_grid() -> ControlMesh {
        let mut pos = Vec::new();
        for j in 0..3 {
            for i in 0..4 {
                pos.push([i as f64, j as f64, ((i * j) as f64 * 0.7).sin()]);
            }
        }
        let mut faces = Vec::new();
        for j in 0..2u32 {
            for i in 0..3u32 {
                let a = j * 4 + i;
                faces.push([a, a + 1, a + 5]);
                faces.push([a, a + 5, a + 4]);
            }
        }
        ControlMesh::from_polygons(pos, &faces)
    }

    fn tetrahedron() -> ControlMesh {
        ControlMesh::from_polygons(
            vec![
                [1.0, 1.0, 1.0],
                [1.0, -1.0, -1.0],
                [-1.0, 1.0, -1.0],
                [-1.0, -1.0, 1.0],
            ],
            &[[0u32, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
        )
    }

    #[test]
    fn mask_limit_positions_equal_the_evaluator() {
        let mut corners = open_grid();
        corners.options.boundary = topology::BoundaryInterpolation::EdgesAndCorners;
        let mut creased = tetrahedron();
        creased.creases.push(topology::EdgeCrease {
            vertices: [0, 1],
            sharpness: 10.0,
        });
        creased.creases.push(topology::EdgeCrease {
            vertices: [1, 2],
            sharpness: 10.0,
        });
        for (name, mesh) in [
            ("grid", open_grid()),
            ("grid, corners", corners),
            ("tetrahedron", tetrahedron()),
            ("tetrahedron, crease", creased),
        ] {
            let mut level = Level::from_mesh(&mesh, Scheme::Loop).unwrap();
            for k in 0..3 {
                let fast = loop_limit_positions(&level).expect("no semi-sharp features");
                let slow = evaluator_limit_positions(&level, k, &mesh.options).unwrap();
                assert_eq!(fast.len(), slow.len());
                for (v, (a, b)) in fast.iter().zip(&slow).enumerate() {
                    for c in 0..3 {
                        assert!((a[c] - b[c]).abs() < 1e-12, "{name} level {k} vertex {v}");
                    }
                }
                level = refine_level(&level, Scheme::Loop, &mesh.options).unwrap().0;
            }
        }
    }

    #[test]
    fn semi_sharp_creases_are_declined_until_decayed() {
        let mut mesh = tetrahedron();
        mesh.creases.push(topology::EdgeCrease {
            vertices: [0, 1],
            sharpness: 1.5,
        });
        let level = Level::from_mesh(&mesh, Scheme::Loop).unwrap();
        assert!(loop_limit_positions(&level).is_none());
        // One level later it is 0.5: still semi-sharp, a typed error, no panic.
        let e = cpu_loop_limit_mesh(&mesh, 1)
            .err()
            .expect("semi-sharp")
            .to_string();
        assert!(e.contains("semi-sharp"), "{e}");
        // Two levels later the crease has decayed and the masks apply.
        let cpu = cpu_loop_limit_mesh(&mesh, 2).unwrap();
        assert_eq!(cpu.indices.len(), 3 * 4 * 16);
    }
}
