//! The techniques as the benchmark drives them, behind one trait, and the registry that builds
//! them by name. A new technique is one [`MethodEntry`] in [`registry`].
use super::{BenchConfig, BenchMesh};
use crate::camera::Camera;
use crate::context::{statistics_query_safe, Context};
use crate::error::{Result, TessError};
use crate::gpu::Vertex;
use crate::plain::{PlainMesh, PlainRenderer};
use crate::render_mesh::angle_weighted_normals;
use crate::technique::{FrameParams, Technique};
use crate::techniques::bft::Wave;
use crate::techniques::{self, BuildOptions, TechniqueInfo};
use std::time::Instant;
use topology::limit::eval::{LimitScheme, LocalMesh};
use topology::refine::{refine_level, Level};
use topology::{ControlMesh, Scheme};
use vk_core::{vk, Device, Encoder};

/// What one frame of a row asks for.
#[derive(Clone, Copy, Debug)]
pub struct BenchFrame {
    /// Frame number within the row, warm-up frames included (0 is the first warm-up frame).
    pub index: u32,
    /// A warm-up frame (its times are not in the row).
    pub warmup: bool,
    /// The level this method draws at: segments per base edge S (the paper's 4×4, 16×16,
    /// 32×32 splits: S = 4, 16, 32), or under [`super::BenchConfig::equal_triangles`] the
    /// segments per patch edge chosen to match Flat's triangles at S.
    pub segments: u32,
    pub extent: vk::Extent2D,
    pub camera: Camera,
}

/// Everything a method may need to build its resources for one mesh.
#[derive(Clone, Copy)]
pub struct MethodContext<'a> {
    pub device: &'a Device,
    /// The technique a technique row is built for (None for other rows).
    pub technique: Option<&'static TechniqueInfo>,
    pub mesh: &'a BenchMesh,
    pub config: &'a BenchConfig,
    pub color_format: vk::Format,
    pub depth_format: vk::Format,
}

/// One row source as the benchmark drives it: every [`Technique`] (through
/// [`TechniqueMethod`]) and the CPU baseline. Per frame the runner calls `begin_frame` (host
/// work, `&mut self`), then records one command buffer: timestamp, `record_pre_pass` (outside
/// any rendering scope: compute), the rendering scope with `record` (draws), timestamp; it
/// submits and waits. The GPU time is the span between the two timestamps, so a compute
/// pre-pass counts. Recording borrows the method for the encoder's lifetime.
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
    fn record_pre_pass<'a>(&'a self, enc: &mut Encoder<'a>, frame: &BenchFrame) -> Result<()> {
        let _ = (enc, frame);
        Ok(())
    }

    /// The frame's draws, inside the rendering scope. Returns how many triangles they emit by
    /// the CPU's count (the tessellator's arithmetic for tessellated draws); the runner checks it
    /// against the pipeline-statistics count where the device has one.
    fn record<'a>(&'a self, enc: &mut Encoder<'a>, frame: &BenchFrame) -> Result<u64>;

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

    /// Triangles a frame at `segments` would draw, by the same CPU count `record` returns,
    /// known without drawing; `None` where the method cannot tell beforehand (the CPU
    /// baselines) or does not draw at that level. The equal-triangle choice searches it.
    fn triangles_at(&self, segments: u32) -> Option<u64> {
        let _ = segments;
        None
    }

    /// Bytes the method keeps on the device for its mesh (buffers and textures as created),
    /// called after the row's frames; `None` when unknown.
    fn device_bytes(&self) -> Option<u64> {
        None
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

/// Every technique the benchmark knows, in table order (Flat first: the ratios divide by it):
/// each technique of [`techniques::registry`] (plus an `-animated` row for those that animate),
/// then the CPU baseline. A new technique needs no entry here.
pub fn registry() -> Vec<MethodEntry> {
    let mut out: Vec<MethodEntry> = techniques::registry()
        .iter()
        .map(|info| MethodEntry {
            name: info.id.name(),
            help: info.help,
            build: technique_rows,
        })
        .collect();
    out.push(MethodEntry {
        name: "cpu",
        help: "CPU Loop subdivision to level log2 S at the limit, drawn as plain triangles: \
               cpu-static (drawn only) and cpu-animated (re-subdivided and uploaded every frame)",
        build: |c| {
            Ok(vec![
                Box::new(CpuLoopMethod::new(c, false, Scheme::Loop)?),
                Box::new(CpuLoopMethod::new(c, true, Scheme::Loop)?),
            ])
        },
    });
    out.push(MethodEntry {
        name: "cpu-catmark",
        help: "CPU Catmull-Clark subdivision of the mesh as loaded to level log2 S at the limit, \
               drawn as plain triangles: cpu-catmark-static and cpu-catmark-animated",
        build: |c| {
            Ok(vec![
                Box::new(CpuLoopMethod::new(c, false, Scheme::CatmullClark)?),
                Box::new(CpuLoopMethod::new(c, true, Scheme::CatmullClark)?),
            ])
        },
    });
    out
}

/// The rows of the technique named `name`: static, and animated when it animates.
fn technique_rows_named(
    ctx: &MethodContext<'_>,
    info: &'static TechniqueInfo,
) -> Result<Vec<Box<dyn BenchMethod>>> {
    let mut rows: Vec<Box<dyn BenchMethod>> =
        vec![Box::new(TechniqueMethod::new(ctx, info, false)?)];
    if info.features.animation {
        rows.push(Box::new(TechniqueMethod::new(ctx, info, true)?));
    }
    Ok(rows)
}

/// [`MethodFactory`] of the technique rows; the entry's name picks the technique.
fn technique_rows(ctx: &MethodContext<'_>) -> Result<Vec<Box<dyn BenchMethod>>> {
    let info = ctx.technique.ok_or_else(|| TessError::BenchConfig {
        option: "--methods".into(),
        reason: "a technique row was built without its technique".into(),
    })?;
    technique_rows_named(ctx, info)
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
        return Err(TessError::BenchConfig {
            option: "--methods".into(),
            reason: format!(
                "unknown bench method '{bad}' (known: {})",
                method_names().join(", ")
            ),
        });
    }
    let mut out = Vec::new();
    for e in entries.iter().filter(|e| names.iter().any(|n| n == e.name)) {
        let ctx = MethodContext {
            technique: techniques::registry()
                .iter()
                .find(|i| i.id.name() == e.name),
            ..*ctx
        };
        out.extend((e.build)(&ctx)?);
    }
    Ok(out)
}

/// Any technique through a [`Context`] of its own: uniform factors of S segments per base
/// edge, the pre-pass (if any) inside the timed span; the `-animated` row uploads the
/// `--animate` wave every frame, its CPU time reported.
pub struct TechniqueMethod {
    label: String,
    mesh_name: String,
    animated: bool,
    technique: Box<dyn Technique>,
    wave: Option<Wave>,
    context: Context,
    /// Faces of the control mesh as loaded (the memory note's denominator).
    base_faces: usize,
    /// Displacement scale and reparameterization of every frame: the config's for techniques
    /// that take surface maps, else none and the default.
    displace: f32,
    reparam: bool,
    /// What the row draws beyond plain shading ([`BenchConfig::surface_note`]), for its note.
    surface_note: Option<String>,
}

impl TechniqueMethod {
    pub fn new(ctx: &MethodContext<'_>, info: &TechniqueInfo, animated: bool) -> Result<Self> {
        let mut context = Context::new(ctx.device, ctx.color_format, ctx.depth_format, 1)?;
        // Catmull-Clark techniques take the mesh as loaded; the others its fan triangulation
        // (the paper's Table I).
        let mesh = if info.scheme == Some(topology::Scheme::CatmullClark) {
            &ctx.mesh.input
        } else {
            &ctx.mesh.mesh
        };
        // Textures, displacement and the reparameterization apply to the techniques that take
        // them (`Features::surface`); the others draw as always.
        let surface = info.features.surface;
        let built = techniques::build(
            &mut context,
            info.id,
            mesh,
            &BuildOptions {
                name: ctx.mesh.name.clone(),
                isolation: ctx.config.isolation,
                follow_semi_sharp: ctx.config.follow_semi_sharp,
                maps: if surface {
                    ctx.config.maps.clone()
                } else {
                    Default::default()
                },
                ..BuildOptions::default()
            },
        )?;
        let wave = match (animated, built.technique.base_mesh()) {
            (true, Some(m)) => Some(Wave::new(m)),
            _ => None,
        };
        Ok(Self {
            label: if animated {
                format!("{}-animated", info.id)
            } else {
                info.id.name().to_string()
            },
            mesh_name: ctx.mesh.name.clone(),
            animated,
            technique: built.technique,
            wave,
            context,
            base_faces: ctx.mesh.input.num_faces(),
            displace: if surface { ctx.config.displace } else { 0.0 },
            reparam: !surface || ctx.config.reparam,
            surface_note: if surface {
                ctx.config.surface_note()
            } else {
                None
            },
        })
    }

    fn params(&self, segments: u32, camera: Camera) -> FrameParams {
        FrameParams {
            camera,
            displace: self.displace,
            reparam: self.reparam,
            ..FrameParams::uniform(segments as f32)
        }
    }
}

impl BenchMethod for TechniqueMethod {
    fn label(&self) -> &str {
        &self.label
    }

    fn skip_reason(&self, segments: u32) -> Option<String> {
        self.technique
            .check(&self.params(segments, Camera::default()))
            .err()
            .map(|e| e.to_string())
    }

    fn begin_frame(&mut self, frame: &BenchFrame) -> Result<Option<f64>> {
        let params = self.params(frame.segments, frame.camera);
        self.context
            .prepare(self.technique.as_ref(), &params, &[crate::Pass::Shaded])?;
        let cpu = match (&self.wave, self.animated) {
            (Some(wave), true) => {
                // The viewer's --animate: deform on the CPU, upload only the base positions.
                let start = Instant::now();
                let moved = wave.at(frame.index as f32 / 30.0);
                self.technique.update_base(0, &moved)?;
                Some(start.elapsed().as_secs_f64() * 1e3)
            }
            _ => None,
        };
        self.context
            .write_frame(0, self.technique.bbox(), &params, frame.extent)?;
        Ok(cpu)
    }

    fn record_pre_pass<'a>(&'a self, enc: &mut Encoder<'a>, _frame: &BenchFrame) -> Result<()> {
        self.context
            .record_pre_pass(enc, self.technique.as_ref(), 0)
    }

    fn record<'a>(&'a self, enc: &mut Encoder<'a>, frame: &BenchFrame) -> Result<u64> {
        let params = self.params(frame.segments, frame.camera);
        let t = self.technique.as_ref();
        self.context
            .record_pass(enc, t, 0, &params, crate::Pass::Shaded)?;
        Ok((0..t.patch_arrays().len())
            .map(|i| t.triangles(&params, i).unwrap_or(0))
            .sum())
    }

    fn row_notes(&mut self) -> Vec<String> {
        self.surface_note.iter().cloned().collect()
    }

    fn report_notes(&self) -> Vec<String> {
        if self.animated {
            return Vec::new();
        }
        let memory = self.technique.device_memory();
        let parts: Vec<String> = memory
            .iter()
            .map(|a| format!("{} {}", a.name, a.bytes))
            .collect();
        self.technique
            .report_notes()
            .into_iter()
            .chain(std::iter::once(format!(
                "{} device memory {} bytes for {} base faces: {}",
                self.technique.id(),
                memory.iter().map(|a| a.bytes).sum::<u64>(),
                self.base_faces,
                parts.join(", ")
            )))
            .map(|n| format!("{}: {n}", self.mesh_name))
            .collect()
    }

    fn statistics_query_safe(&self) -> bool {
        statistics_query_safe(self.context.device(), self.technique.as_ref())
    }

    fn triangles_at(&self, segments: u32) -> Option<u64> {
        let params = self.params(segments, Camera::default());
        let t = self.technique.as_ref();
        t.check(&params).ok()?;
        (0..t.patch_arrays().len())
            .map(|i| t.triangles(&params, i))
            .sum()
    }

    fn device_bytes(&self) -> Option<u64> {
        Some(self.technique.device_memory().iter().map(|a| a.bytes).sum())
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

/// Vertices, edges and faces after `level` Catmull-Clark steps: V' = V + E + F,
/// E' = 2E + (face corners), F' = face corners (every face splits into one quad per corner).
pub fn catmark_level_size(mesh: &ControlMesh, level: usize) -> (u64, u64, u64) {
    let (v, e, _) = loop_level_size(mesh, 0);
    let (mut v, mut e, mut f) = (v, e, mesh.num_faces() as u64);
    let mut corners = mesh.faces().map(|f| f.len() as u64).sum::<u64>();
    for _ in 0..level {
        (v, e, f) = (v + e + f, 2 * e + corners, corners);
        corners = 4 * f;
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
    cpu_limit_mesh(mesh, Scheme::Loop, level)
}

/// [`cpu_loop_limit_mesh`] for Loop or Catmull-Clark; Catmull-Clark quads (and the base
/// polygons at level 0) are drawn as fan triangles.
pub fn cpu_limit_mesh(mesh: &ControlMesh, scheme: Scheme, level: usize) -> Result<CpuLimitMesh> {
    let mut current = Level::from_mesh(mesh, scheme)?;
    for _ in 0..level {
        current = refine_level(&current, scheme, &mesh.options)?.0;
    }
    let limit_scheme = if scheme == Scheme::Loop {
        LimitScheme::Loop
    } else {
        LimitScheme::CatmullClark
    };
    let positions = match (scheme == Scheme::Loop)
        .then(|| loop_limit_positions(&current))
        .flatten()
    {
        Some(p) => p,
        None => evaluator_limit_positions(&current, level, &mesh.options, limit_scheme)?,
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
    let indices = if scheme == Scheme::Loop {
        current.face_vertices().to_vec()
    } else {
        let (offsets, verts) = current.topology.face_tables();
        let mut out = Vec::with_capacity(verts.len() * 3 / 2);
        for w in offsets.windows(2) {
            let f = &verts[w[0] as usize..w[1] as usize];
            for k in 1..f.len().saturating_sub(1) {
                out.extend_from_slice(&[f[0], f[k], f[k + 1]]);
            }
        }
        out
    };
    Ok(CpuLimitMesh { vertices, indices })
}

/// The edge-neighbours of interior vertex `v` in cyclic order (either way round) from `first`,
/// walking its triangles; `None` if they do not close into one cycle.
fn cyclic_ring(t: &topology::mesh::Topology, v: usize, first: u32) -> Option<Vec<u32>> {
    let faces = t.vertex_faces(v);
    let (vv, mut prev) = (v as u32, u32::MAX);
    let mut ring = vec![first];
    loop {
        let cur = *ring.last()?;
        let f = faces.iter().copied().find(|&f| {
            let fv = t.face_vertices(f as usize);
            f != prev && fv.contains(&vv) && fv.contains(&cur)
        })?;
        let next = t
            .face_vertices(f as usize)
            .iter()
            .copied()
            .find(|&x| x != vv && x != cur)?;
        prev = f;
        if next == first {
            break;
        }
        ring.push(next);
        if ring.len() > faces.len() {
            return None;
        }
    }
    (ring.len() == t.vertex_edges(v).len() && ring.len() == faces.len()).then_some(ring)
}

/// Limit positions of every vertex of a Loop level by the limit masks of
/// [`topology::limit::masks::loop_limit_masks`], read straight off the level's edge lists and
/// sharpness: what a CPU application does, without building an evaluator. `None` when a
/// semi-sharp feature is left (its vertices need more refinement first).
pub fn loop_limit_positions(level: &Level) -> Option<Vec<[f64; 3]>> {
    use topology::limit::masks::{loop_limit_masks, LimitRule, LimitVertex};
    use topology::rules::{is_infinite, is_semi_sharp as semi};
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
        } else if sharp.len() == 1 {
            // A dart: its own mask ([`topology::limit::masks::dart_position_weights`]) over the ring
            // in cyclic order from the sharp edge; a ring that cannot be walked takes the
            // evaluator's path.
            let ring = cyclic_ring(t, v, sharp[0])?;
            let w = topology::limit::masks::dart_position_weights(true, ring.len());
            let mut q = p.map(|c| w[0] * c);
            for (j, &x) in ring.iter().enumerate() {
                let r = level.positions[x as usize];
                for k in 0..3 {
                    q[k] += w[1 + j] * r[k];
                }
            }
            q
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

/// Limit positions through the general evaluator ([`LocalMesh::vertex_limit_exact`]: masks,
/// or exact evaluation next to semi-sharp features), for levels [`loop_limit_positions`]
/// declines.
fn evaluator_limit_positions(
    current: &Level,
    level: usize,
    options: &topology::rules::options::SubdivOptions,
    scheme: LimitScheme,
) -> Result<Vec<[f64; 3]>> {
    let scheme_name = match scheme {
        LimitScheme::Loop => "loop",
        LimitScheme::CatmullClark => "catmull-clark",
    };
    let local =
        LocalMesh::from_refined_level(current, scheme, options).map_err(|e| TessError::Mesh {
            name: format!("{scheme_name} level {level}"),
            source: e.into(),
        })?;
    (0..current.num_vertices())
        .map(|v| {
            let p = local
                .vertex_limit_exact(v as u32)
                .map_err(|e| TessError::Mesh {
                    name: format!("{scheme_name} level {level}, vertex {v}"),
                    source: e.into(),
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
    scheme: Scheme,
    base: ControlMesh,
    max_vertices: u64,
    renderer: PlainRenderer,
    context: Context,
    /// The level-k mesh and its k.
    mesh: Option<(usize, PlainMesh)>,
    subdivide_ms: Vec<f64>,
    upload_ms: Vec<f64>,
    device: Device,
}

impl CpuLoopMethod {
    /// Loop subdivides the fan-triangulated mesh (Table I); Catmull-Clark the mesh as loaded.
    pub fn new(ctx: &MethodContext<'_>, animated: bool, scheme: Scheme) -> Result<Self> {
        let context = Context::new(ctx.device, ctx.color_format, ctx.depth_format, 1)?;
        Ok(Self {
            animated,
            scheme,
            base: if scheme == Scheme::Loop {
                ctx.mesh.mesh.clone()
            } else {
                ctx.mesh.input.clone()
            },
            max_vertices: ctx.config.cpu_max_vertices,
            renderer: PlainRenderer::new(&context)?,
            context,
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
        let (lo, hi) = m.bounding_box();
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
        match (self.scheme, self.animated) {
            (Scheme::Loop, true) => "cpu-animated",
            (Scheme::Loop, false) => "cpu-static",
            (_, true) => "cpu-catmark-animated",
            (_, false) => "cpu-catmark-static",
        }
    }

    fn skip_reason(&self, segments: u32) -> Option<String> {
        let level = match loop_level_for(segments) {
            Ok(l) => l,
            Err(e) => return Some(e),
        };
        let (v, _, f) = if self.scheme == Scheme::Loop {
            loop_level_size(&self.base, level)
        } else {
            catmark_level_size(&self.base, level)
        };
        (v > self.max_vertices).then(|| {
            format!(
                "{} level {level} would have {v} vertices and {f} faces, above the CPU \
                 baseline's limit of {} vertices (--cpu-max-vertices)",
                self.scheme, self.max_vertices
            )
        })
    }

    fn begin_frame(&mut self, frame: &BenchFrame) -> Result<Option<f64>> {
        let level = loop_level_for(frame.segments).map_err(|reason| TessError::BenchConfig {
            option: "--segments".into(),
            reason,
        })?;
        if self.mesh.as_ref().map(|(k, _)| *k) != Some(level) {
            // Not timed: the static mesh is built once, and the animated one needs its buffers.
            self.mesh = None;
            let cpu = cpu_limit_mesh(&self.base, self.scheme, level)?;
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
            let cpu = cpu_limit_mesh(&base, self.scheme, level)?;
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
            let params = FrameParams {
                camera: frame.camera,
                ..FrameParams::default()
            };
            self.context
                .write_frame(0, (mesh.bbox_min, mesh.bbox_max), &params, frame.extent)?;
        }
        Ok(cpu_ms)
    }

    fn record<'a>(&'a self, enc: &mut Encoder<'a>, _frame: &BenchFrame) -> Result<u64> {
        let (_, mesh) = self.mesh.as_ref().ok_or_else(|| TessError::BenchConfig {
            option: "cpu".into(),
            reason: "the CPU baseline was recorded before begin_frame".into(),
        })?;
        self.renderer.record(enc, &self.context, 0, mesh)
    }

    /// The refined mesh's vertex and index buffers at the level last drawn.
    fn device_bytes(&self) -> Option<u64> {
        self.mesh
            .as_ref()
            .map(|(_, m)| m.vertices.size() + m.indices.size())
    }

    fn row_notes(&mut self) -> Vec<String> {
        let mut notes = Vec::new();
        if let Some((level, mesh)) = &self.mesh {
            notes.push(format!(
                "{} level {level}: {} vertices, {} KiB of vertices + indices on the GPU",
                self.scheme,
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
        corners.options.boundary = topology::rules::options::BoundaryInterpolation::EdgesAndCorners;
        let mut creased = tetrahedron();
        creased.creases.push(topology::mesh::EdgeCrease {
            vertices: [0, 1],
            sharpness: 10.0,
        });
        creased.creases.push(topology::mesh::EdgeCrease {
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
                let slow =
                    evaluator_limit_positions(&level, k, &mesh.options, LimitScheme::Loop).unwrap();
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
    fn semi_sharp_creases_are_evaluated_exactly_until_decayed() {
        let mut mesh = tetrahedron();
        mesh.creases.push(topology::mesh::EdgeCrease {
            vertices: [0, 1],
            sharpness: 1.5,
        });
        let level = Level::from_mesh(&mesh, Scheme::Loop).unwrap();
        assert!(loop_limit_positions(&level).is_none());
        // One level later it is 0.5: still semi-sharp, so the masks decline and the exact
        // evaluator places the vertices: base vertex 0 (it keeps its index) lands on the limit
        // the evaluator finds on the control mesh itself, at the vertex's corner of face 0.
        let cpu = cpu_loop_limit_mesh(&mesh, 1).expect("exact beside the crease");
        let corner = mesh.face(0).iter().position(|&v| v == 0).unwrap();
        let (u, v) = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][corner];
        let want = topology::limit::eval::limit_point(&mesh, LimitScheme::Loop, 0, u, v)
            .unwrap()
            .position;
        for (got, want) in cpu.vertices[0].position.iter().zip(&want) {
            assert!((*got as f64 - want).abs() < 1e-6, "{got} vs {want}");
        }
        // Two levels later the crease has decayed and the masks apply.
        let cpu = cpu_loop_limit_mesh(&mesh, 2).unwrap();
        assert_eq!(cpu.indices.len(), 3 * 4 * 16);
    }
}
