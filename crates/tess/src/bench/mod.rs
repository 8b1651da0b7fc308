//! The benchmark behind `tessera bench`, after Table I of Holländer & Boubekeur ("Synthesizing
//! Subdivision Meshes using Real Time Tessellation"): for each mesh, each number of segments per
//! base edge S and each technique, the output triangles and the GPU frame time (median and p90
//! over timed frames after warm-up), offscreen, with the ratio to Flat at the same S.
//!
//! Rows are [`TechniqueRow`]s, one per technique of [`crate::techniques::registry`] named in
//! the configuration (the CPU baselines are techniques too); the runner owns the frame
//! structure (timestamps, pipeline statistics, rendering scope) so every technique is timed the
//! same way, and interleaves the techniques' frames at each mesh and S so that a machine's
//! drift does not bias one of them. Speed is measured here, never asserted by tests.
pub mod figure7;
mod methods;
mod report;
pub mod stats;
pub mod usage;

pub use methods::{build_rows, method_names, parse_method, BenchFrame, RowContext, TechniqueRow};
pub use report::{parse_csv, CSV_HEADER, CSV_HEADER_V1};

use crate::camera::Camera;
use crate::error::{Result, TessError};
use crate::render_mesh::RenderMesh;
use std::time::Instant;
use topology::ControlMesh;
use vk_core::query::QueryPool;
use vk_core::target::{OffscreenTarget, COLOR_FORMAT, DEPTH_FORMAT};
use vk_core::{vk, AdapterInfo, Device};

/// What to measure.
#[derive(Clone, Debug)]
pub struct BenchConfig {
    /// Segments per base edge S (Table I: 4, 16, 32 for levels 2, 4, 5).
    pub segments: Vec<u32>,
    /// Registry names, e.g. `["flat", "phong", "pn", "bft", "cpu"]`.
    pub methods: Vec<String>,
    /// Timed frames per row.
    pub frames: u32,
    /// Untimed frames before them (pipeline creation, caches).
    pub warmup: u32,
    pub extent: vk::Extent2D,
    pub camera: Camera,
    /// When set, a row whose timed frames would take longer than this gets fewer frames
    /// ([`fit_frames`], judged from the last warm-up frame's wall time, or the first timed
    /// frame's without warm-up), never fewer than `min_frames` (nor more than `frames`); the
    /// row says so in its note.
    pub row_budget_s: Option<f64>,
    pub min_frames: u32,
    /// The CPU baseline skips levels with more vertices than this (3 M vertices peak at about
    /// 1.6 GB of host memory).
    pub cpu_max_vertices: u64,
    /// Isolation level of the feature-adaptive rows.
    pub isolation: u32,
    /// Follow semi-sharp creases past it until they decay (and `isolation` levels more at the
    /// irregular vertices beside them).
    pub follow_semi_sharp: bool,
    /// Compare at equal output triangles: at each mesh and S, every method whose triangle
    /// count is known beforehand draws at the whole level (segments per its own edge: per
    /// patch edge for the patch techniques) whose CPU count is nearest Flat's at S
    /// ([`nearest_level`]); Flat keeps S. Needs `flat` among the methods.
    pub equal_triangles: bool,
    /// Colour texture and height map of the techniques that take them
    /// ([`crate::Features::surface`]: adaptive, gregory, acc); the other methods draw without.
    pub maps: crate::surface::SurfaceMaps,
    /// Displacement along the normal by this times the height (the height map's, else the
    /// procedural pattern) for the same techniques; 0: none.
    pub displace: f32,
    /// Their texture coordinates at the reparameterized parameter on Gregory patches (seed 003).
    pub reparam: bool,
    /// The edge factors of every frame: uniform (each row's S), or screen-space or distance
    /// factors for the techniques that take them, whose rows then share one policy and S only
    /// names them.
    pub factors: BenchFactors,
    /// The spacing of every frame of the techniques that take it (fractional-even geomorphs on
    /// the pattern path of BFT and the planned surfaces).
    pub spacing: crate::tessellator::Spacing,
}

/// Edge factors of a benchmark's frames ([`BenchConfig::factors`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum BenchFactors {
    /// Each row's S segments per edge.
    Uniform,
    /// Projected edge length over this many pixels.
    Screen { pixels: f32 },
    /// Halving each time the eye's distance doubles past this many bounding-box diagonals.
    Distance { diagonals: f32 },
}

impl BenchFactors {
    /// The policy at `segments` on a mesh of bounding-box diagonal `diagonal`.
    pub fn policy(self, segments: f32, diagonal: f32) -> crate::FactorPolicy {
        match self {
            Self::Uniform => crate::FactorPolicy::Uniform { segments },
            Self::Screen { pixels } => crate::FactorPolicy::Screen { pixels },
            Self::Distance { diagonals } => crate::FactorPolicy::Distance {
                reference: diagonals * diagonal.max(1e-6),
            },
        }
    }

    /// How the report names it, with `spacing`.
    pub fn describe(self, spacing: crate::tessellator::Spacing) -> String {
        let spacing = format!("{spacing} spacing");
        match self {
            Self::Uniform => format!("uniform factors (S per edge), {spacing}"),
            Self::Screen { pixels } => {
                format!(
                    "screen-space factors ({pixels} px per segment; S names the row), {spacing}"
                )
            }
            Self::Distance { diagonals } => format!(
                "distance factors (the largest level at {diagonals} diagonals; S names the row), \
                 {spacing}"
            ),
        }
    }
}

impl BenchConfig {
    /// What the surface techniques' rows draw beyond plain shading, for their notes and the
    /// report: e.g. "textured (spot_texture.png), displaced by 0.05 × spot_height.png,
    /// reparameterized texture coordinates"; `None` for a plain run.
    pub fn surface_note(&self) -> Option<String> {
        let file = |i: &crate::surface::SurfaceImage| {
            std::path::Path::new(&i.name)
                .file_name()
                .map_or_else(|| i.name.clone(), |f| f.to_string_lossy().into_owned())
        };
        let mut parts = Vec::new();
        if let Some(t) = &self.maps.texture {
            parts.push(format!("textured ({})", file(t)));
        }
        match (&self.maps.height, self.displace != 0.0) {
            (Some(h), true) => parts.push(format!("displaced by {} × {}", self.displace, file(h))),
            (None, true) => parts.push(format!(
                "displaced by {} × the procedural height",
                self.displace
            )),
            (Some(h), false) => parts.push(format!("height map {} (displacement 0)", file(h))),
            (None, false) => {}
        }
        if !self.reparam {
            parts.push("no reparameterization".to_owned());
        } else if !parts.is_empty() {
            parts.push("reparameterized texture coordinates".to_owned());
        }
        (!parts.is_empty()).then(|| parts.join(", "))
    }
}

impl Default for BenchConfig {
    fn default() -> Self {
        Self {
            segments: vec![4, 16, 32],
            methods: ["flat", "phong", "pn", "bft", "cpu"]
                .map(String::from)
                .to_vec(),
            frames: 30,
            warmup: 5,
            extent: vk::Extent2D {
                width: 1280,
                height: 720,
            },
            camera: Camera::default(),
            row_budget_s: None,
            min_frames: 5,
            cpu_max_vertices: 4_000_000,
            isolation: crate::techniques::adaptive::DEFAULT_ISOLATION,
            follow_semi_sharp: true,
            equal_triangles: false,
            maps: Default::default(),
            displace: 0.0,
            reparam: true,
            factors: BenchFactors::Uniform,
            spacing: crate::tessellator::Spacing::Equal,
        }
    }
}

/// A control mesh prepared for every technique: triangles only (Loop and the triangle
/// techniques need them), and its render form.
#[derive(Clone, Debug)]
pub struct BenchMesh {
    pub name: String,
    pub mesh: ControlMesh,
    /// The mesh as loaded: what Catmull-Clark techniques subdivide (a fan triangulation is a
    /// different surface for them).
    pub input: ControlMesh,
    pub render: RenderMesh,
    /// How the mesh was changed on load (fan triangulation), for the report.
    pub notes: Vec<String>,
}

impl BenchMesh {
    /// Fan-triangulates `mesh` (quads and n-gons; the paper's techniques take triangles) and
    /// builds its render form.
    pub fn new(name: &str, mesh: &ControlMesh) -> Result<Self> {
        let (tri, split) = fan_triangulate(mesh)?;
        let mut notes = Vec::new();
        if split.polygons > 0 {
            notes.push(format!(
                "{name}: fan-triangulated on load ({} of {} faces were quads or n-gons; {} triangles)",
                split.polygons,
                mesh.num_faces(),
                tri.num_faces()
            ));
        }
        let render = RenderMesh::from_control_mesh(&tri)?;
        Ok(Self {
            name: name.to_owned(),
            mesh: tri,
            input: mesh.clone(),
            render,
            notes,
        })
    }

    pub fn triangles(&self) -> u64 {
        self.mesh.num_faces() as u64
    }
}

/// How many faces [`fan_triangulate`] split.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TriangulationSummary {
    pub polygons: usize,
}

/// [`ControlMesh::triangulated`] (fans from each face's first corner; corner attributes follow
/// their corners, crease tags keep naming the same edges, holes become all triangles of the
/// holed face), refusing faces of fewer than three corners and counting the faces it split.
pub fn fan_triangulate(mesh: &ControlMesh) -> Result<(ControlMesh, TriangulationSummary)> {
    if let Some(face) = (0..mesh.num_faces()).find(|&f| mesh.face(f).len() < 3) {
        return Err(TessError::Topology(
            topology::TopologyError::DegenerateFace {
                face,
                size: mesh.face(face).len(),
            },
        ));
    }
    let summary = TriangulationSummary {
        polygons: mesh.faces().filter(|f| f.len() > 3).count(),
    };
    Ok((mesh.triangulated().0, summary))
}

/// Where a row's triangle count comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum TriangleSource {
    /// The pipeline-statistics query (clipping invocations) of the first warm-up frame.
    PipelineStatistics,
    /// The CPU count the method reported (no statistics on this device).
    Cpu,
}

impl TriangleSource {
    pub fn as_str(self) -> &'static str {
        match self {
            TriangleSource::PipelineStatistics => "pipeline-statistics",
            TriangleSource::Cpu => "cpu",
        }
    }
}

impl std::str::FromStr for TriangleSource {
    type Err = String;
    fn from_str(s: &str) -> std::result::Result<Self, String> {
        match s {
            "pipeline-statistics" => Ok(TriangleSource::PipelineStatistics),
            "cpu" => Ok(TriangleSource::Cpu),
            _ => Err(format!("unknown triangle source '{s}'")),
        }
    }
}

/// One measured row of the table. Times are milliseconds.
#[derive(Clone, Debug, PartialEq)]
pub struct BenchRow {
    pub mesh: String,
    pub input_triangles: u64,
    pub segments: u32,
    pub method: String,
    /// The level the method drew at: S, or under [`BenchConfig::equal_triangles`] the whole
    /// segments per (patch) edge chosen to match Flat's triangles at S.
    pub level: u32,
    /// Output triangles per frame, as `triangles_source` counted them.
    pub triangles: u64,
    /// The method's own CPU count (the tessellator's arithmetic, or the refined mesh's size).
    pub triangles_expected: u64,
    pub triangles_source: TriangleSource,
    /// Timed frames (after `warmup` untimed ones).
    pub frames: u32,
    pub warmup: u32,
    /// GPU time between the frame's two timestamps (compute + draws).
    pub gpu_median_ms: f64,
    pub gpu_p90_ms: f64,
    /// Per-frame CPU work the method reported (CPU subdivision + upload); `None` when none.
    pub cpu_median_ms: Option<f64>,
    pub cpu_p90_ms: Option<f64>,
    /// Per-frame CPU + GPU time.
    pub total_median_ms: f64,
    pub total_p90_ms: f64,
    /// Host time to record, submit and wait for the frame (a cross-check of the timestamps).
    pub wall_median_ms: f64,
    /// `total_median_ms` over Flat's at the same mesh and S.
    pub ratio_to_flat: Option<f64>,
    /// `triangles` over Flat's at the same mesh and S: how equal "equal triangles" was.
    pub triangle_ratio_to_flat: Option<f64>,
    /// Faces of the control mesh as loaded (before fan triangulation); 0 when unknown (a CSV
    /// written before the column existed).
    pub base_faces: u64,
    /// Bytes of the buffers and textures the method keeps on the device for this mesh
    /// ([`crate::Technique::device_memory`]; the CPU baselines' refined mesh at this level).
    pub device_bytes: Option<u64>,
    pub note: String,
}

impl BenchRow {
    /// `device_bytes` per control-mesh face.
    pub fn bytes_per_base_face(&self) -> Option<f64> {
        match (self.device_bytes, self.base_faces) {
            (Some(b), f) if f > 0 => Some(b as f64 / f as f64),
            _ => None,
        }
    }
}

/// The candidate `(level, triangles)` whose triangle count is nearest `target` (the lower
/// level on a tie), or `None` when there is no candidate.
pub fn nearest_level(
    target: u64,
    candidates: impl IntoIterator<Item = (u32, u64)>,
) -> Option<(u32, u64)> {
    candidates
        .into_iter()
        .min_by_key(|&(level, t)| (t.abs_diff(target), level))
}

/// The highest level the equal-triangle search tries (the tessellator's maximum).
pub const MAX_EQUAL_TRIANGLE_LEVEL: u32 = crate::tessellator::MAX_LEVEL as u32;

/// A row that was not measured, and why.
#[derive(Clone, Debug, PartialEq)]
pub struct SkippedRow {
    pub mesh: String,
    pub segments: u32,
    pub method: String,
    pub reason: String,
}

/// The device, as the report names it.
#[derive(Clone, Debug, PartialEq)]
pub struct DeviceSummary {
    pub name: String,
    pub device_type: String,
    pub driver_name: String,
    pub driver_info: String,
    pub driver_version_raw: u32,
    /// `driver_version` decoded by the vendor's convention.
    pub driver_version: String,
    pub lavapipe: bool,
}

impl DeviceSummary {
    pub fn from_adapter(a: &AdapterInfo) -> Self {
        let v = a.driver_version;
        // NVIDIA packs 10.8.8.6 bits; Mesa and most others use VK_MAKE_VERSION's 10.10.12.
        let driver_version = if a.vendor_id == 0x10de {
            format!(
                "{}.{}.{}.{}",
                v >> 22,
                (v >> 14) & 0xff,
                (v >> 6) & 0xff,
                v & 0x3f
            )
        } else {
            format!("{}.{}.{}", v >> 22, (v >> 12) & 0x3ff, v & 0xfff)
        };
        Self {
            name: a.name.clone(),
            device_type: a.type_name().to_owned(),
            driver_name: a.driver_name.clone(),
            driver_info: a.driver_info.clone(),
            driver_version_raw: v,
            driver_version,
            lavapipe: a.is_lavapipe(),
        }
    }
}

/// Everything one run measured, and how.
#[derive(Clone, Debug)]
pub struct BenchReport {
    pub device: DeviceSummary,
    /// UTC, `YYYY-MM-DD HH:MM`.
    pub date_utc: String,
    /// "release" or "debug" (of the crate that ran the frames).
    pub profile: &'static str,
    pub config: BenchConfig,
    pub rows: Vec<BenchRow>,
    pub skipped: Vec<SkippedRow>,
    /// Per-mesh notes (triangulation).
    pub mesh_notes: Vec<String>,
    /// Lines from the methods for the header (e.g. a technique's table memory).
    pub extra_notes: Vec<String>,
}

/// The build profile of this crate: timings of a debug build say little.
pub fn build_profile() -> &'static str {
    if cfg!(debug_assertions) {
        "debug"
    } else {
        "release"
    }
}

/// `YYYY-MM-DD HH:MM` UTC of a Unix time (the civil-from-days algorithm, no time-zone data).
pub fn utc_date(unix_seconds: u64) -> String {
    let days = (unix_seconds / 86_400) as i64;
    let secs = unix_seconds % 86_400;
    let z = days + 719_468;
    let era = z.div_euclid(146_097);
    let doe = z - era * 146_097;
    let yoe = (doe - doe / 1_460 + doe / 36_524 - doe / 146_096) / 365;
    let doy = doe - (365 * yoe + yoe / 4 - yoe / 100);
    let mp = (5 * doy + 2) / 153;
    let d = doy - (153 * mp + 2) / 5 + 1;
    let m = if mp < 10 { mp + 3 } else { mp - 9 };
    let y = yoe + era * 400 + i64::from(m <= 2);
    format!(
        "{y:04}-{m:02}-{d:02} {:02}:{:02}",
        secs / 3_600,
        (secs / 60) % 60
    )
}

/// Per-frame measurements of one row.
struct FrameTimes {
    gpu_ms: Vec<f64>,
    cpu_ms: Vec<Option<f64>>,
    wall_ms: Vec<f64>,
}

/// Query pools and target shared by every row.
struct Harness<'a> {
    device: &'a Device,
    target: OffscreenTarget,
    timestamps: QueryPool,
    statistics: Option<QueryPool>,
}

impl Harness<'_> {
    /// Records, submits and waits for one frame; returns (GPU ms, wall ms, CPU triangles,
    /// statistics triangles when queried).
    fn frame(
        &self,
        method: &TechniqueRow,
        frame: &BenchFrame,
        query_statistics: bool,
        clear: [f32; 4],
    ) -> Result<(f64, f64, u64, Option<u64>)> {
        let stats = self.statistics.as_ref().filter(|_| query_statistics);
        let device = self.device;
        let start = Instant::now();
        let recorded = device.submit_once(|enc| -> Result<u64> {
            enc.reset_queries(&self.timestamps);
            if let Some(q) = stats {
                enc.reset_queries(q);
            }
            enc.write_timestamp(&self.timestamps, vk::PipelineStageFlags::TOP_OF_PIPE, 0)?;
            if let Some(q) = stats {
                enc.begin_query(q, 0)?;
            }
            let pre = method.record_pre_pass(enc, frame);
            enc.begin_offscreen(&self.target, clear);
            let drawn = pre.and_then(|_| method.record(enc, frame));
            // Ended even when the method failed, so the command buffer stays valid.
            enc.end_rendering();
            if let Some(q) = stats {
                enc.end_query(q, 0)?;
            }
            enc.write_timestamp(&self.timestamps, vk::PipelineStageFlags::BOTTOM_OF_PIPE, 1)?;
            drawn
        })??;
        let wall_ms = start.elapsed().as_secs_f64() * 1e3;
        let gpu_ms = self
            .timestamps
            .durations_ns()?
            .first()
            .copied()
            .ok_or_else(|| TessError::BenchConfig {
                option: "timestamps".into(),
                reason: "no timestamp pair was read back".into(),
            })?
            / 1e6;
        let counted = match stats {
            Some(q) => q
                .statistics_results()?
                .first()
                .map(|s| s.clipping_invocations),
            None => None,
        };
        Ok((gpu_ms, wall_ms, recorded, counted))
    }
}

/// What a benchmark says while it runs, for a progress display: the run is a sequence of
/// groups (one mesh at one S, every method's frames interleaved), each mesh first building its
/// methods (tables, plans: the slow part on large meshes). Only `row` must be written; the
/// library draws nothing itself.
pub trait BenchProgress {
    /// The run starts with `groups` groups to measure.
    fn start(&mut self, groups: usize) {
        let _ = groups;
    }
    /// `mesh`'s methods are being built.
    fn building(&mut self, mesh: &str) {
        let _ = mesh;
    }
    /// The group `mesh` at `segments` is being measured.
    fn measuring(&mut self, mesh: &str, segments: u32) {
        let _ = (mesh, segments);
    }
    /// A measured row, as soon as its group is done.
    fn row(&mut self, row: &BenchRow);
    /// The group last announced by `measuring` is done.
    fn group_done(&mut self) {}
}

/// A row callback as a [`BenchProgress`].
struct RowsOnly<'a>(&'a mut dyn FnMut(&BenchRow));

impl BenchProgress for RowsOnly<'_> {
    fn row(&mut self, row: &BenchRow) {
        (self.0)(row)
    }
}

/// Measures every mesh × S × method of `config` on `device`; `on_row` sees each row as soon as
/// it is measured.
pub fn run_bench(
    device: &Device,
    meshes: &[BenchMesh],
    config: &BenchConfig,
    on_row: &mut dyn FnMut(&BenchRow),
) -> Result<BenchReport> {
    run_bench_with_progress(device, meshes, config, &mut RowsOnly(on_row))
}

/// [`run_bench`], telling `progress` where it is.
pub fn run_bench_with_progress(
    device: &Device,
    meshes: &[BenchMesh],
    config: &BenchConfig,
    progress: &mut dyn BenchProgress,
) -> Result<BenchReport> {
    validate(config, meshes)?;
    progress.start(meshes.len() * config.segments.len());
    let harness = Harness {
        device,
        target: OffscreenTarget::new(device, config.extent)?,
        timestamps: QueryPool::timestamps(device, "bench frame timestamps", 2)?,
        statistics: if device.info.caps.pipeline_statistics_query {
            Some(QueryPool::statistics(device, "bench triangle count", 1)?)
        } else {
            None
        },
    };
    let mut report = BenchReport {
        device: DeviceSummary::from_adapter(&device.info),
        date_utc: utc_date(
            std::time::SystemTime::now()
                .duration_since(std::time::UNIX_EPOCH)
                .map(|d| d.as_secs())
                .unwrap_or(0),
        ),
        profile: build_profile(),
        config: config.clone(),
        rows: Vec::new(),
        skipped: Vec::new(),
        mesh_notes: Vec::new(),
        extra_notes: Vec::new(),
    };
    for mesh in meshes {
        report.mesh_notes.extend(mesh.notes.iter().cloned());
        let ctx = RowContext {
            device,
            mesh,
            config,
            color_format: COLOR_FORMAT,
            depth_format: DEPTH_FORMAT,
        };
        progress.building(&mesh.name);
        let mut methods = build_rows(&config.methods, &ctx)?;
        for &segments in &config.segments {
            progress.measuring(&mesh.name, segments);
            let levels = group_levels(&methods, segments, config, &mesh.name)?;
            let mut runnable = Vec::new();
            for (method, level) in methods.iter_mut().zip(levels) {
                match level {
                    Err(reason) => report.skipped.push(SkippedRow {
                        mesh: mesh.name.clone(),
                        segments,
                        method: method.label().to_owned(),
                        reason,
                    }),
                    Ok(level) => runnable.push((method, level)),
                }
            }
            let mut rows = run_group(&harness, &mut runnable, mesh, segments, config)?;
            let flat = rows
                .iter()
                .find(|r| r.method == "flat")
                .map(|r| (r.total_median_ms, r.triangles));
            for row in &mut rows {
                row.ratio_to_flat = flat.map(|(f, _)| row.total_median_ms / f);
                row.triangle_ratio_to_flat = flat
                    .filter(|&(_, t)| t > 0)
                    .map(|(_, t)| row.triangles as f64 / t as f64);
                progress.row(row);
            }
            progress.group_done();
            report.rows.extend(rows);
        }
        for m in &methods {
            for n in m.report_notes() {
                if !report.extra_notes.contains(&n) {
                    report.extra_notes.push(n);
                }
            }
        }
    }
    Ok(report)
}

/// The level each method draws at in the group at `segments`, or why it is skipped: S (and
/// the method's own skip reason) by default; under [`BenchConfig::equal_triangles`], for each
/// method that knows its triangles beforehand, the whole level in
/// 1..=[`MAX_EQUAL_TRIANGLE_LEVEL`] it accepts whose count is nearest Flat's at S.
fn group_levels(
    methods: &[TechniqueRow],
    segments: u32,
    config: &BenchConfig,
    mesh: &str,
) -> Result<Vec<std::result::Result<u32, String>>> {
    let at_s = |m: &TechniqueRow| match m.skip_reason(segments) {
        Some(reason) => Err(reason),
        None => Ok(segments),
    };
    if !config.equal_triangles {
        return Ok(methods.iter().map(at_s).collect());
    }
    let flat = methods.iter().find(|m| m.label() == "flat");
    let target = flat
        .filter(|f| f.skip_reason(segments).is_none())
        .and_then(|f| f.triangles_at(segments))
        .ok_or_else(|| TessError::BenchConfig {
            option: "--equal-triangles".into(),
            reason: format!("{mesh}: Flat has no triangle count at S = {segments}"),
        })?;
    Ok(methods
        .iter()
        .map(|m| {
            if m.label() == "flat" {
                return at_s(m);
            }
            let candidates = (1..=MAX_EQUAL_TRIANGLE_LEVEL)
                .filter(|&l| m.skip_reason(l).is_none())
                .filter_map(|l| m.triangles_at(l).map(|t| (l, t)));
            match nearest_level(target, candidates) {
                Some((level, _)) => Ok(level),
                // No count known beforehand, or no level accepted (skipped at S with the
                // method's own reason).
                None => at_s(m),
            }
        })
        .collect())
}

fn validate(config: &BenchConfig, meshes: &[BenchMesh]) -> Result<()> {
    let bad = |m: String| {
        Err(TessError::BenchConfig {
            option: "bench".into(),
            reason: m,
        })
    };
    if meshes.is_empty() {
        return bad("no meshes to benchmark".into());
    }
    if config.segments.is_empty() || config.segments.contains(&0) {
        return bad(format!(
            "segments per edge must be at least 1 (got {})",
            config
                .segments
                .iter()
                .map(u32::to_string)
                .collect::<Vec<_>>()
                .join(", ")
        ));
    }
    if config.frames == 0 {
        return bad("at least one timed frame is needed".into());
    }
    // Frame numbers are u32.
    if config.frames.checked_add(config.warmup).is_none() {
        return Err(TessError::BenchConfig {
            option: format!("--frames {} --warmup {}", config.frames, config.warmup),
            reason: format!("a row has at most {} frames in all", u32::MAX),
        });
    }
    if config.methods.is_empty() {
        return bad("no methods to benchmark".into());
    }
    if let Some(b) = config.row_budget_s {
        if !(b > 0.0 && b.is_finite()) {
            return bad(format!("row budget {b} s must be a positive number"));
        }
    }
    for m in &config.methods {
        methods::parse_method(m)?;
    }
    if !config.displace.is_finite() {
        return Err(TessError::BenchConfig {
            option: format!("--displace {}", config.displace),
            reason: "give a finite scale".into(),
        });
    }
    if config.equal_triangles && !config.methods.iter().any(|m| m == "flat") {
        return Err(TessError::BenchConfig {
            option: "--equal-triangles".into(),
            reason: "the triangle counts to match are Flat's: add flat to --methods".into(),
        });
    }
    Ok(())
}

/// The timed frames a row keeps under `--row-budget`: as many frames of `per_frame_s` as fit
/// in `budget_s`, at least `min_frames` (and at least 1) and at most `frames` (a `min_frames`
/// above `frames` is `frames`).
pub fn fit_frames(budget_s: f64, per_frame_s: f64, frames: u32, min_frames: u32) -> u32 {
    let fit = (budget_s / per_frame_s).floor();
    // `as` saturates: NaN gives 0, a huge quotient u32::MAX.
    let fit = if fit.is_nan() { 0 } else { fit as u32 };
    fit.clamp(min_frames.clamp(1, frames.max(1)), frames.max(1))
}

/// One technique's frames within a group.
struct RowState {
    frames: u32,
    times: FrameTimes,
    expected: Option<u64>,
    counted: Option<u64>,
    /// Wall time of the row's last frame (warm-up or timed), seconds.
    last_cost_s: f64,
    notes: Vec<String>,
}

/// Measures every technique at one mesh and S. Frames are interleaved round robin (warm-up
/// frames first, then timed frames), so a slow drift of the machine (another process, clock
/// changes) spreads over all techniques instead of biasing whichever ran during it.
fn run_group(
    harness: &Harness<'_>,
    methods: &mut [(&mut TechniqueRow, u32)],
    mesh: &BenchMesh,
    segments: u32,
    config: &BenchConfig,
) -> Result<Vec<BenchRow>> {
    if methods.is_empty() {
        return Ok(Vec::new());
    }
    let clear = crate::FrameParams::default().clear_color;
    let warmup = config.warmup;
    let mut states: Vec<RowState> = methods
        .iter()
        .map(|_| RowState {
            frames: config.frames,
            times: FrameTimes {
                gpu_ms: Vec::new(),
                cpu_ms: Vec::new(),
                wall_ms: Vec::new(),
            },
            expected: None,
            counted: None,
            last_cost_s: 0.0,
            notes: Vec::new(),
        })
        .collect();
    // The budget is fitted once a frame of each row was measured: after the warm-up, or after
    // the first timed frame without one.
    let fit_at = warmup.max(1);
    let mut index = 0;
    loop {
        let is_warmup = index < warmup;
        let mut any = false;
        for ((method, level), st) in methods.iter_mut().zip(&mut states) {
            if !is_warmup && index - warmup >= st.frames {
                continue;
            }
            any = true;
            let frame = BenchFrame {
                index,
                warmup: is_warmup,
                segments: *level,
                extent: config.extent,
                camera: config.camera,
            };
            let frame_start = Instant::now();
            let cpu = method.begin_frame(&frame)?;
            let query = index == 0 && method.statistics_query_safe();
            let (gpu, wall, cpu_count, stats_count) =
                harness.frame(method, &frame, query, clear)?;
            if index == 0 {
                st.counted = stats_count;
            }
            // Under screen-space and distance factors an animated surface's levels follow it:
            // the row gives its first frame's triangles.
            let fixed = config.factors == BenchFactors::Uniform;
            match st.expected {
                None => st.expected = Some(cpu_count),
                Some(e) if fixed && e != cpu_count => {
                    return Err(TessError::BenchConfig {
                        option: method.label().to_string(),
                        reason: format!("drew {cpu_count} triangles in frame {index}, {e} before"),
                    })
                }
                Some(_) => {}
            }
            st.last_cost_s = frame_start.elapsed().as_secs_f64();
            if !is_warmup {
                st.times.gpu_ms.push(gpu);
                st.times.cpu_ms.push(cpu);
                st.times.wall_ms.push(wall);
            }
        }
        // Every row has its frames (checked before the increment: the last frame number may
        // be u32::MAX - 1).
        if !any && index >= warmup {
            break;
        }
        index += 1;
        // After the warm-up, fit each technique's timed frames into the row budget.
        if index == fit_at {
            if let Some(budget) = config.row_budget_s {
                for st in &mut states {
                    let per_frame = st.last_cost_s.max(1e-9);
                    let reduced = fit_frames(budget, per_frame, st.frames, config.min_frames);
                    if reduced < st.frames {
                        st.notes.push(format!(
                            "frames reduced from {} to {reduced} (row budget {budget} s, \
                             {per_frame:.2} s per frame)",
                            st.frames
                        ));
                        st.frames = reduced;
                    }
                }
            }
        }
    }
    methods
        .iter_mut()
        .zip(states)
        .map(|((method, level), st)| finish_row(method, st, mesh, (segments, *level), warmup))
        .collect()
}

/// The row of one method; `(segments, level)`: the group's S and the level it drew at.
fn finish_row(
    method: &mut TechniqueRow,
    st: RowState,
    mesh: &BenchMesh,
    (segments, level): (u32, u32),
    warmup: u32,
) -> Result<BenchRow> {
    let RowState {
        times,
        expected,
        counted,
        mut notes,
        ..
    } = st;
    let expected = expected.unwrap_or(0);
    let (triangles, triangles_source) = match counted {
        Some(c) => {
            if c != expected {
                notes.push(format!(
                    "pipeline statistics counted {c} triangles, the CPU count is {expected}"
                ));
            }
            (c, TriangleSource::PipelineStatistics)
        }
        None => {
            if expected == 0 {
                notes.push(
                    "triangles not counted: the control stage chooses the levels on the device, \
                     and no pipeline-statistics query counted them"
                        .into(),
                );
            }
            (expected, TriangleSource::Cpu)
        }
    };
    notes.extend(method.row_notes());
    let has_cpu = times.cpu_ms.iter().any(Option::is_some);
    let cpu: Vec<f64> = times.cpu_ms.iter().map(|c| c.unwrap_or(0.0)).collect();
    let total: Vec<f64> = times.gpu_ms.iter().zip(&cpu).map(|(g, c)| g + c).collect();
    let stat = |v: &[f64], f: fn(&[f64]) -> Option<f64>| {
        f(v).ok_or_else(|| TessError::BenchConfig {
            option: "--frames".into(),
            reason: "no frame times to summarise".into(),
        })
    };
    Ok(BenchRow {
        mesh: mesh.name.clone(),
        input_triangles: mesh.triangles(),
        segments,
        method: method.label().to_owned(),
        level,
        triangles,
        triangles_expected: expected,
        triangles_source,
        frames: times.gpu_ms.len() as u32,
        warmup,
        gpu_median_ms: stat(&times.gpu_ms, stats::median)?,
        gpu_p90_ms: stat(&times.gpu_ms, stats::p90)?,
        cpu_median_ms: if has_cpu {
            Some(stat(&cpu, stats::median)?)
        } else {
            None
        },
        cpu_p90_ms: if has_cpu {
            Some(stat(&cpu, stats::p90)?)
        } else {
            None
        },
        total_median_ms: stat(&total, stats::median)?,
        total_p90_ms: stat(&total, stats::p90)?,
        wall_median_ms: stat(&times.wall_ms, stats::median)?,
        ratio_to_flat: None,
        triangle_ratio_to_flat: None,
        base_faces: mesh.input.num_faces() as u64,
        device_bytes: method.device_bytes(),
        note: notes.join("; "),
    })
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Every combination of the budget's inputs gives a frame count in `1..=frames`: a
    /// `min_frames` above `frames` panicked in `clamp` (`--frames 2` with the default
    /// `--min-frames 5`, or `--min-frames 3`).
    #[test]
    fn fit_frames_stays_within_one_and_frames() {
        let cases: [(f64, f64, u32, u32, u32); 10] = [
            (1.5, 0.1, 2, 5, 2),
            (1.5, 0.1, 2, 3, 2),
            (1.0, 0.1, 3000, 5, 10),
            (1.0, 0.5, 3000, 5, 5),
            (1.0, 0.5, 3000, 0, 2),
            (1.0, 1e-9, u32::MAX, 5, 999_999_999),
            (1e12, 1e-9, u32::MAX, 5, u32::MAX),
            (1e-300, 1.0, 30, 0, 1),
            (1.0, 1e-300, 30, 5, 30),
            (f64::MAX, 1e-300, 7, 1, 7),
        ];
        for (budget, per_frame, frames, min_frames, want) in cases {
            assert_eq!(
                fit_frames(budget, per_frame, frames, min_frames),
                want,
                "budget {budget}, {per_frame} s a frame, frames {frames}, min {min_frames}"
            );
        }
    }

    #[test]
    fn nearest_level_picks_the_closest_count_and_the_lower_level_on_ties() {
        let quad = |l: u32| (l, 10 * (l as u64).pow(2));
        // Counts 10, 40, 90, 160: 100 is nearest 90 (level 3), 125 is 35 from 90 and 160.
        assert_eq!(nearest_level(100, (1..=4).map(quad)), Some((3, 90)));
        assert_eq!(nearest_level(125, (1..=4).map(quad)), Some((3, 90)));
        assert_eq!(nearest_level(126, (1..=4).map(quad)), Some((4, 160)));
        assert_eq!(nearest_level(1, (1..=4).map(quad)), Some((1, 10)));
        assert_eq!(nearest_level(10_000, (1..=4).map(quad)), Some((4, 160)));
        assert_eq!(nearest_level(5, std::iter::empty()), None);
    }

    /// The surface techniques' row note: none for a plain run, else what they drew.
    #[test]
    fn surface_notes_say_what_the_surface_rows_drew() {
        let mut c = BenchConfig::default();
        assert_eq!(c.surface_note(), None);
        c.reparam = false;
        assert_eq!(c.surface_note().as_deref(), Some("no reparameterization"));
        c.reparam = true;
        c.displace = 0.25;
        assert_eq!(
            c.surface_note().as_deref(),
            Some("displaced by 0.25 × the procedural height, reparameterized texture coordinates")
        );
        let image = |name: &str| {
            Some(std::sync::Arc::new(crate::surface::SurfaceImage {
                name: name.into(),
                width: 1,
                height: 1,
                format: vk_core::texture::TextureFormat::Rgba8Srgb,
                texels: vec![0; 4],
            }))
        };
        c.maps.texture = image("assets/spot_texture.png");
        c.maps.height = image("/data/spot_height.png");
        c.reparam = false;
        assert_eq!(
            c.surface_note().as_deref(),
            Some(
                "textured (spot_texture.png), displaced by 0.25 × spot_height.png, no \
                 reparameterization"
            )
        );
    }

    #[test]
    fn utc_dates() {
        assert_eq!(utc_date(0), "1970-01-01 00:00");
        assert_eq!(utc_date(951_782_400), "2000-02-29 00:00");
        assert_eq!(utc_date(1_700_000_000), "2023-11-14 22:13");
    }

    #[test]
    fn fan_triangulation_keeps_corner_attributes() {
        let mut mesh = ControlMesh::from_polygons(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
                [2.0, 0.0, 0.0],
            ],
            &[vec![0u32, 1, 2, 3], vec![1, 4, 2]],
        );
        mesh.normals = Some((0..7).map(|i| [i as f64, 0.0, 1.0]).collect());
        mesh.holes = vec![0];
        let (tri, s) = fan_triangulate(&mesh).unwrap();
        assert_eq!(s.polygons, 1);
        assert_eq!(tri.face_vertices, vec![0, 1, 2, 0, 2, 3, 1, 4, 2]);
        assert_eq!(tri.face_offsets, vec![0, 3, 6, 9]);
        let n: Vec<f64> = tri.normals.unwrap().iter().map(|n| n[0]).collect();
        assert_eq!(n, vec![0.0, 1.0, 2.0, 0.0, 2.0, 3.0, 4.0, 5.0, 6.0]);
        assert_eq!(tri.holes, vec![0, 1]);
    }
}
