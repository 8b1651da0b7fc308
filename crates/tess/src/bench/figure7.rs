//! The seed's Fig. 7 (Boubekeur & Schlick 2005, §5): coarse triangle meshes refined to S × S
//! segments with flat interpolation and no culling, drawn two ways in the same run:
//! - **VBO**: the seed's static mesh, every coarse triangle's pattern instance evaluated once on
//!   the CPU into one vertex buffer and drawn with one indexed draw;
//! - **pattern**: one refinement pattern instanced over the coarse triangles (flat on the
//!   pattern path), the vertex stage interpolating each instance.
//!
//! Both rows draw the seed's pattern, the barycentric lattice of S segments per edge (on the
//! device, (S + 1)(S + 2) / 2 vertices; the seed counts (S + 1)² for its strips).
//! Both rows of a case are measured by the benchmark's own loop (GPU time between two
//! timestamps, frames interleaved round robin), so their ratio is a ratio within one run.
use super::{run_group, BenchConfig, BenchMesh, Harness, TechniqueRow};
use crate::capture::FacePoint;
use crate::context::Context;
use crate::error::{Result, TessError};
use crate::gpu::{DrawPush, Vertex};
use crate::pattern::RefinementPattern;
use crate::shaders::Stage;
use crate::technique::{
    DeviceAllocation, DrawCounts, DrawPath, FrameParams, Pass, PatchArray, PatchPipeline,
    PatchType, Technique, TechniqueId, VertexInput,
};
use crate::techniques::flat::Flat;
use crate::tessellator::{Domain, Spacing};
use std::sync::Arc;
use topology::ControlMesh;
use vk_core::query::QueryPool;
use vk_core::target::{OffscreenTarget, COLOR_FORMAT, DEPTH_FORMAT};
use vk_core::{vk, Buffer, Device, Encoder};

/// The seed's cases: 10, 100 and 1,000 coarse triangles at 64 × 64 and 128 × 128 segments.
pub const SEED_CASES: [(u32, u32); 6] = [
    (10, 64),
    (100, 64),
    (1000, 64),
    (10, 128),
    (100, 128),
    (1000, 128),
];

/// One case measured both ways.
#[derive(Clone, Debug, PartialEq)]
pub struct Figure7Row {
    pub coarse_triangles: u32,
    pub segments: u32,
    /// Median frame time (ms) of the static mesh and of the pattern.
    pub vbo_ms: f64,
    pub pattern_ms: f64,
    /// Vertices each keeps on the device: the static mesh's, the one pattern's.
    pub vbo_vertices: u64,
    pub pattern_vertices: u64,
}

/// `coarse` triangles in rows of a gently curved sheet (two per grid cell, row by row).
pub fn coarse_sheet(coarse: u32) -> ControlMesh {
    let columns = ((coarse as f64 / 2.0).sqrt().ceil() as u32).max(1);
    let rows = coarse.div_ceil(2 * columns);
    let positions: Vec<[f64; 3]> = (0..=rows)
        .flat_map(|j| {
            (0..=columns).map(move |i| {
                let (x, y) = (i as f64, j as f64);
                [x, y, 0.15 * ((0.7 * x).sin() + (0.9 * y).cos())]
            })
        })
        .collect();
    let at = |i: u32, j: u32| j * (columns + 1) + i;
    let faces: Vec<[u32; 3]> = (0..rows)
        .flat_map(|j| {
            (0..columns).flat_map(move |i| {
                [
                    [at(i, j), at(i + 1, j), at(i + 1, j + 1)],
                    [at(i, j), at(i + 1, j + 1), at(i, j + 1)],
                ]
            })
        })
        .take(coarse as usize)
        .collect();
    ControlMesh::from_polygons(positions, &faces)
}

impl TechniqueId {
    /// The static pre-tessellated mesh of Fig. 7 (a benchmark row, not a registry technique).
    pub const FIGURE7_VBO: TechniqueId = TechniqueId::new("vbo");
}

/// The static mesh: the pattern instanced on the CPU over every coarse triangle.
struct StaticMesh {
    vertices: Buffer,
    indices: Buffer,
    index_count: u32,
    vertex_count: u64,
    arrays: [PatchArray; 1],
    bbox: ([f32; 3], [f32; 3]),
}

impl StaticMesh {
    fn new(device: &Device, mesh: &BenchMesh, pattern: &RefinementPattern) -> Result<Self> {
        let rm = &mesh.render;
        let mut vertices = Vec::with_capacity(rm.triangles.len() * pattern.points.len());
        let mut indices = Vec::with_capacity(rm.triangles.len() * 3 * pattern.triangles.len());
        for t in &rm.triangles {
            let corners = t.map(|i| rm.vertices[i as usize]);
            let first = vertices.len() as u32;
            for b in &pattern.points {
                let at = |f: fn(&Vertex) -> [f32; 3]| {
                    let c = corners.map(|v| f(&v));
                    [0, 1, 2].map(|k| b[0] * c[0][k] + b[1] * c[1][k] + b[2] * c[2][k])
                };
                vertices.push(Vertex {
                    position: at(|v| v.position),
                    normal: at(|v| v.normal),
                });
            }
            indices.extend(pattern.triangles.iter().flatten().map(|&i| first + i));
        }
        let index_count = u32::try_from(indices.len()).map_err(|_| TessError::BenchConfig {
            option: "--figure7".into(),
            reason: format!("{} indices do not fit one draw", indices.len()),
        })?;
        Ok(Self {
            vertices: Buffer::with_data(
                device,
                "figure 7 static vertices",
                vk::BufferUsageFlags::VERTEX_BUFFER,
                bytemuck::cast_slice(&vertices),
            )?,
            indices: Buffer::with_data(
                device,
                "figure 7 static indices",
                vk::BufferUsageFlags::INDEX_BUFFER,
                bytemuck::cast_slice(&indices),
            )?,
            index_count,
            vertex_count: vertices.len() as u64,
            arrays: [PatchArray {
                patch: PatchType::MeshTriangles,
                patches: vertices.len() as u32,
                control_points: 0,
                first_patch: 0,
            }],
            bbox: (rm.bbox_min, rm.bbox_max),
        })
    }
}

impl Technique for StaticMesh {
    fn id(&self) -> TechniqueId {
        TechniqueId::FIGURE7_VBO
    }

    fn bbox(&self) -> ([f32; 3], [f32; 3]) {
        self.bbox
    }

    fn patch_arrays(&self) -> &[PatchArray] {
        &self.arrays
    }

    fn check(&self, _params: &FrameParams) -> Result<()> {
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

    fn triangles(&self, _params: &FrameParams, _array: usize) -> Option<u64> {
        Some(self.index_count as u64 / 3)
    }

    fn record_array<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        _array: usize,
        _slot: usize,
        _params: &FrameParams,
        pass: Pass,
        _per_draw: u32,
    ) -> Result<DrawCounts> {
        enc.bind_vertex_buffer(0, &self.vertices);
        enc.bind_index_buffer_u32(&self.indices);
        enc.push_constants(&DrawPush {
            mode: pass.mode(),
            first_patch: 0,
        })?;
        enc.draw_indexed(0..self.index_count)?;
        Ok(DrawCounts {
            draws: 1,
            patches: self.arrays[0].patches,
        })
    }

    fn face_point(&self, _patch: u32, _domain: [f32; 2]) -> Option<FacePoint> {
        None
    }

    fn device_memory(&self) -> Vec<DeviceAllocation> {
        [&self.vertices, &self.indices]
            .into_iter()
            .map(DeviceAllocation::of_buffer)
            .collect()
    }
}

/// Measures `cases` (coarse triangles, segments) on `device` with `config`'s frames, warm-up,
/// extent and camera.
pub fn run_figure7(
    device: &Device,
    cases: &[(u32, u32)],
    config: &BenchConfig,
) -> Result<Vec<Figure7Row>> {
    let harness = Harness {
        device,
        target: OffscreenTarget::new(device, config.extent)?,
        timestamps: QueryPool::timestamps(device, "figure 7 frame timestamps", 2)?,
        statistics: None,
    };
    cases
        .iter()
        .map(|&(coarse, segments)| run_case(&harness, coarse, segments, config))
        .collect()
}

/// One case: both rows built, measured together.
fn run_case(
    harness: &Harness<'_>,
    coarse: u32,
    segments: u32,
    config: &BenchConfig,
) -> Result<Figure7Row> {
    let device = harness.device;
    let mesh = BenchMesh::new(&format!("{coarse} triangles"), &coarse_sheet(coarse))?;
    // The seed's pattern, the barycentric lattice, in both rows and at every size (not the
    // tessellator's concentric rings).
    let pattern = Arc::new(RefinementPattern::generate(Domain::Triangle, segments)?);
    let mut pattern_ctx = Context::new(device, COLOR_FORMAT, DEPTH_FORMAT, 1)?;
    pattern_ctx.set_refinement_pattern(Spacing::Equal, segments as f32, pattern.clone());
    let vbo = StaticMesh::new(device, &mesh, &pattern)?;
    let vbo_vertices = vbo.vertex_count;
    let flat = Flat::new(device, &mesh.mesh, DrawPath::Pattern)?;
    let vbo_ctx = Context::new(device, COLOR_FORMAT, DEPTH_FORMAT, 1)?;
    let mut rows = [
        TechniqueRow::from_technique("vbo", Box::new(vbo), vbo_ctx, &mesh),
        TechniqueRow::from_technique("pattern", Box::new(flat), pattern_ctx, &mesh),
    ];
    let [a, b] = &mut rows;
    let mut group = [(a, segments), (b, segments)];
    let measured = run_group(harness, &mut group, &mesh, segments, config)?;
    Ok(Figure7Row {
        coarse_triangles: coarse,
        segments,
        vbo_ms: measured[0].total_median_ms,
        pattern_ms: measured[1].total_median_ms,
        vbo_vertices,
        pattern_vertices: pattern.points.len() as u64,
    })
}

/// The rows as the seed's table, in markdown: one line per case, with the run's device and
/// settings above it.
pub fn figure7_markdown(rows: &[Figure7Row], device: &str, settings: &str) -> String {
    let mut out = format!(
        "Device: {device}. {settings}\n\n| coarse triangles | segments | VBO ms | pattern ms | \
         pattern / VBO | VBO vertices | pattern vertices |\n|---:|---:|---:|---:|---:|---:|---:|\n"
    );
    for r in rows {
        out.push_str(&format!(
            "| {} | {}×{} | {:.3} | {:.3} | {:.3} | {} | {} |\n",
            r.coarse_triangles,
            r.segments,
            r.segments,
            r.vbo_ms,
            r.pattern_ms,
            r.pattern_ms / r.vbo_ms,
            r.vbo_vertices,
            r.pattern_vertices
        ));
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_coarse_sheet_has_the_asked_triangles() {
        for n in [1, 2, 10, 100, 1000, 1001] {
            let m = coarse_sheet(n);
            assert_eq!(m.num_faces() as u32, n);
            assert!(m.faces().all(|f| f.len() == 3));
        }
    }
}
