//! Exactly what the GPU's TES produced, captured through transform feedback, and CPU
//! post-processing that never recomputes geometry.
//!
//! # Capture
//! [`Capturer::capture`] records a frame of any [`crate::Technique`] (its pre-pass, the same
//! patch arrays, draw splits and frame uniforms as a rendered frame, through the same
//! [`crate::Context`]) with the `-DCAPTURE` TES builds and rasterizer discard. Every emitted
//! triangle corner becomes one [`CaptureRecord`] (the 40-byte contract of
//! `glsl/common/tese_out.glsl`). Each patch array writes its own buffer, sized by the CPU
//! tessellator's exact triangle count where the technique knows it; a transform-feedback stream
//! query per array counts
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
//! - [`classify_open_edges`] splits open edges into those on the base mesh's own boundary,
//!   those along its non-manifold edges, and cracks, from the base mesh topology and the
//!   captured domain coordinates only.
//!
//! # Patch ids and base faces
//! A captured patch id is the frame-wide patch number of [`crate::Technique::patch_arrays`];
//! [`crate::Technique::face_point`] maps (patch id, domain coordinate) to a [`FacePoint`] on the
//! base mesh ([`PatchFaceTable`] for the base-face techniques: identity for triangles and quads,
//! fan triangles of n-gons map into their n-gon). Face domains follow [`face_corner_uv`].
//!
//! # OBJ written by [`WeldedMesh::write_obj`]
//! ```text
//! # tessera capture: V welded vertices, T triangles, corners welded by position bits
//! v X Y Z          one per welded vertex, shortest round-trip f32 text (parses to the same bits)
//! vn X Y Z         its normal (as the TES shaded it, from the first corner welded into it)
//! # p F U V        its base face F (0-based, in the base OBJ's face order) and (U, V) in that
//!                  face's domain (first corner welded into it; a vertex on a shared edge has
//!                  one such line, for one of its faces)
//! vt S T           with texture coordinates ([`WeldedMesh::corner_texcoords`]): one per
//!                  distinct (by bits) coordinate of the triangle corners, after every vertex
//! f A//A B//B C//C  one per captured triangle, 1-based, zero-area ones included; corners in
//!                  captured order, or reversed with [`Winding::Reversed`]; `f A/TA/A ...` with
//!                  texture coordinates
//! ```
//!
//! A corner's texture coordinate is the one its own captured (patch id, domain coordinate)
//! shows ([`crate::Technique::texcoord`]: computed on the host from the technique's tables, as
//! its shaders compute it, not read back from the GPU), so a vertex on a `vt` seam has one per
//! side.
//!
//! Winding: the triangle/quad TESs declare `ccw`, but with Vulkan's upper-left domain origin
//! their triangles come out clockwise seen from the side the base face faces (the captured cube
mod domain;
mod soup;

pub use domain::{
    classify_open_edges, face_corner_uv, face_edges_at, FacePoint, OpenEdgeClasses, PatchFaceTable,
    PatchToFace,
};
pub use soup::{
    CaptureRecord, CapturedSoup, EdgeReport, OpenEdge, WeldedMesh, Winding, CAPTURE_STRIDE,
};

use crate::context::Context;
use crate::error::{Result, TessError};
use crate::technique::{DrawCounts, FrameParams, Pass, Technique};
use vk_core::query::{QueryPool, TransformFeedbackCounts};
use vk_core::{vk, Buffer, BufferDesc, MemoryLocation};

/// Bytes of one captured triangle.
const TRIANGLE_BYTES: u64 = 3 * CAPTURE_STRIDE;

/// What one capture did, for tests and reports.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct CaptureStats {
    pub draws: u32,
    pub patches: u32,
    /// Triangles the CPU predicted (what the first pass was sized for); 0 where it cannot
    /// (adaptive factors).
    pub expected_triangles: u64,
    /// Summed over the patch arrays.
    pub primitives_written: u64,
    pub primitives_needed: u64,
    /// 1, or 2 when the first pass overflowed and was rerun with the measured size.
    pub passes: u32,
}

/// How the first capture pass sizes each patch array's region.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum CaptureSizing {
    /// The CPU's exact count where the technique knows it (uniform factors), else a guess of
    /// 16 triangles per patch that the second pass corrects.
    #[default]
    CpuBound,
    /// One triangle per array, so the first pass only measures (primitives needed) and the
    /// second captures: exercises the overflow path.
    Measure,
}

/// Refuses capacities (triangles per patch array) whose records exceed `budget` bytes in all,
/// or `per_buffer` bytes in one array (the device binds each array's buffer on its own).
fn check_capacity(capacity: &[u64], budget: u64, per_buffer: u64) -> Result<()> {
    let triangles: u64 = capacity.iter().sum();
    let bytes = triangles.max(1).saturating_mul(TRIANGLE_BYTES);
    if bytes > budget {
        return Err(TessError::CaptureTooLarge {
            triangles,
            bytes,
            limit: budget,
            bound: "the capture budget (Capturer::max_bytes)",
        });
    }
    if let Some(&largest) = capacity.iter().max() {
        let bytes = largest.max(1).saturating_mul(TRIANGLE_BYTES);
        if bytes > per_buffer {
            return Err(TessError::CaptureTooLarge {
                triangles: largest,
                bytes,
                limit: per_buffer,
                bound: "the device's transform-feedback buffer size for one patch array",
            });
        }
    }
    Ok(())
}

/// Largest capture by default (bytes of records): beyond this the caller must raise
/// [`Capturer::max_bytes`] deliberately.
pub const DEFAULT_MAX_CAPTURE_BYTES: u64 = 1 << 30;

/// Captures what any technique emits from its last stage before rasterization. Holds only its settings: pipelines and frame
/// uniforms are the [`Context`]'s.
#[derive(Clone, Copy, Debug)]
pub struct Capturer {
    /// Captures needing more record bytes than this fail with [`TessError::CaptureTooLarge`].
    pub max_bytes: u64,
    pub sizing: CaptureSizing,
}

impl Default for Capturer {
    fn default() -> Self {
        Self {
            max_bytes: DEFAULT_MAX_CAPTURE_BYTES,
            sizing: CaptureSizing::default(),
        }
    }
}

impl Capturer {
    /// A capturer for `ctx`'s device; a typed error ([`vk_core::VkError`]) on a device
    /// without transform feedback, before any work.
    pub fn new(ctx: &Context) -> Result<Self> {
        ctx.device().require_transform_feedback()?;
        QueryPool::transform_feedback_stream(ctx.device(), "capture query probe", 1)?;
        Ok(Self::default())
    }

    /// Captures the triangles one frame of `params` draws for `technique` (its pre-pass
    /// included; the wireframe overlay is ignored: it draws the same triangles again). `extent`
    /// is the view adaptive factors see.
    pub fn capture(
        &self,
        ctx: &mut Context,
        technique: &mut dyn Technique,
        params: &FrameParams,
        extent: vk::Extent2D,
    ) -> Result<(CapturedSoup, CaptureStats)> {
        ctx.write_frame(0, technique.bbox(), params, extent)?;
        ctx.prepare(technique, params, &[Pass::Capture])?;
        let technique = &*technique;
        let arrays = technique.patch_arrays();
        let known: Vec<Option<u64>> = (0..arrays.len())
            .map(|i| technique.triangles(params, i))
            .collect();
        let mut stats = CaptureStats {
            expected_triangles: known.iter().map(|k| k.unwrap_or(0)).sum(),
            ..Default::default()
        };
        let mut capacity: Vec<u64> = match self.sizing {
            CaptureSizing::CpuBound => known
                .iter()
                .zip(arrays)
                .map(|(k, a)| k.unwrap_or(a.patches as u64 * 16))
                .collect(),
            CaptureSizing::Measure => vec![1; arrays.len()],
        };
        for pass in 1..=2 {
            let (soup, counts, draws) = self.capture_pass(ctx, technique, params, &capacity)?;
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
                return Err(TessError::CaptureOverflow {
                    needed: counts.iter().map(|c| c.primitives_needed).sum(),
                    capacity: capacity.iter().sum(),
                });
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

    /// One capture pass: array `i` writes at most `capacity[i]` triangles into its own buffer,
    /// counted by its own stream query.
    fn capture_pass(
        &self,
        ctx: &Context,
        technique: &dyn Technique,
        params: &FrameParams,
        capacity: &[u64],
    ) -> Result<(CapturedSoup, Vec<TransformFeedbackCounts>, DrawCounts)> {
        let device = ctx.device().clone();
        check_capacity(
            capacity,
            self.max_bytes,
            device.info.caps.max_transform_feedback_buffer_size,
        )?;
        let arrays = technique.patch_arrays().len();
        if arrays == 0 {
            // Nothing to draw; a query that is never begun would never become available.
            return Ok((CapturedSoup::default(), Vec::new(), DrawCounts::default()));
        }
        let buffers = capacity
            .iter()
            .enumerate()
            .map(|(i, &c)| {
                Buffer::new(
                    &device,
                    &BufferDesc {
                        name: &format!("capture records {i}"),
                        size: c.max(1) * TRIANGLE_BYTES,
                        usage: vk::BufferUsageFlags::TRANSFORM_FEEDBACK_BUFFER_EXT,
                        location: MemoryLocation::GpuToCpu,
                    },
                )
            })
            .collect::<std::result::Result<Vec<_>, _>>()?;
        let query =
            QueryPool::transform_feedback_stream(&device, "capture primitives", arrays as u32)?;
        let counts = device.submit_once(|enc| -> Result<DrawCounts> {
            enc.reset_queries(&query);
            ctx.record_pre_pass(enc, technique, 0)?;
            let mut counts = DrawCounts::default();
            for (i, buffer) in buffers.iter().enumerate() {
                enc.begin_rendering_without_attachments(vk::Extent2D {
                    width: 1,
                    height: 1,
                });
                ctx.bind_array(enc, technique, 0, params, Pass::Capture, i)?;
                enc.begin_transform_feedback(&[buffer], &[])?;
                enc.begin_query_stream(&query, i as u32, 0)?;
                counts += ctx.draw_array(enc, technique, 0, params, Pass::Capture, i)?;
                enc.end_query_stream(&query, i as u32, 0)?;
                enc.end_transform_feedback(&[])?;
                enc.end_rendering();
            }
            enc.memory_barrier(
                (
                    vk::PipelineStageFlags::TRANSFORM_FEEDBACK_EXT,
                    vk::AccessFlags::TRANSFORM_FEEDBACK_WRITE_EXT,
                ),
                (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
            );
            Ok(counts)
        })??;
        let results = query.transform_feedback_results()?;
        let mut records = Vec::new();
        for (i, (r, buffer)) in results.iter().zip(&buffers).enumerate() {
            let all: Vec<CaptureRecord> = buffer.read()?;
            let written = (r.primitives_written.min(capacity[i]) as usize * 3).min(all.len());
            records.extend_from_slice(&all[..written]);
        }
        Ok((CapturedSoup { records }, results, counts))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tessellator::Domain;
    use topology::ControlMesh;

    /// Each patch array has a transform-feedback buffer of its own: the device's per-buffer
    /// limit bounds the largest array, the budget the sum; the refusal says which and names
    /// the options that capture fewer triangles.
    #[test]
    fn capture_capacity_is_checked_per_buffer_and_in_all() {
        let t = TRIANGLE_BYTES;
        // Three arrays of 10 triangles: 30 in all over a device buffer limit of 15: fine.
        assert!(check_capacity(&[10, 10, 10], 100 * t, 15 * t).is_ok());
        let e = check_capacity(&[10, 20, 10], 100 * t, 15 * t).unwrap_err();
        assert!(
            matches!(e, TessError::CaptureTooLarge { triangles: 20, .. }),
            "{e}"
        );
        assert!(
            e.to_string().contains("transform-feedback buffer size"),
            "{e}"
        );
        let e = check_capacity(&[10, 10, 10], 25 * t, 15 * t).unwrap_err();
        let text = e.to_string();
        assert!(
            matches!(e, TessError::CaptureTooLarge { triangles: 30, limit, .. } if limit == 25 * t),
            "{text}"
        );
        assert!(text.contains("capture budget"), "{text}");
        assert!(
            text.contains("--segments") && text.contains("--pixels"),
            "{text}"
        );
        assert!(!text.contains("raise the limit"), "{text}");
    }

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
                on_non_manifold_edge: 0,
                in_face_of_no_area: 0,
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

    /// Two triangles walking base edge 0-1 the same way (opposite windings: a non-manifold
    /// edge), drawn as two sheets whose copies of 0 and 1 differ by an ulp: their open sides
    /// along 0-1 are the non-manifold edge, not cracks; the same soup over a manifold base
    /// (the second triangle wound to match) has them as cracks.
    #[test]
    fn open_sides_along_a_non_manifold_edge_are_not_cracks() {
        let positions = vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
        ];
        let base = ControlMesh::from_polygons(positions.clone(), &[[0u32, 1, 2], [0, 1, 3]]);
        let ulp = f32::from_bits(1);
        let corner = |k: u32| face_corner_uv(3, k).map(|c| c as f32);
        let soup = CapturedSoup {
            records: vec![
                rec([0.0, 0.0, 0.0], 0, corner(0)),
                rec([1.0, 0.0, 0.0], 0, corner(1)),
                rec([0.0, 1.0, 0.0], 0, corner(2)),
                rec([0.0, ulp, 0.0], 1, corner(0)),
                rec([1.0, ulp, 0.0], 1, corner(1)),
                rec([0.0, -1.0, 0.0], 1, corner(2)),
            ],
        };
        let identity = |patch: u32, d: [f32; 2]| {
            Some(FacePoint {
                face: patch,
                u: d[0],
                v: d[1],
            })
        };
        let w = soup.weld().unwrap();
        let r = w.open_edges();
        assert_eq!(r.open.len(), 6);
        let c = classify_open_edges(&soup, &w, &r, &identity, &base);
        assert_eq!(
            (c.on_base_boundary, c.on_non_manifold_edge, c.cracks),
            (4, 2, 0)
        );
        let manifold = ControlMesh::from_polygons(positions, &[[0u32, 1, 2], [1, 0, 3]]);
        let soup = CapturedSoup {
            records: vec![
                soup.records[0],
                soup.records[1],
                soup.records[2],
                rec([1.0, ulp, 0.0], 1, corner(0)),
                rec([0.0, ulp, 0.0], 1, corner(1)),
                rec([0.0, -1.0, 0.0], 1, corner(2)),
            ],
        };
        let w = soup.weld().unwrap();
        let r = w.open_edges();
        let c = classify_open_edges(&soup, &w, &r, &identity, &manifold);
        assert_eq!(
            (c.on_base_boundary, c.on_non_manifold_edge, c.cracks),
            (4, 0, 2)
        );
    }

    /// Ends mapped into different faces: a vertex-stage technique maps each vertex into one of
    /// its faces. Ends on one boundary edge (a corner of the other face, a point inside the
    /// edge) are the boundary; ends only on inner edges are a crack.
    #[test]
    fn ends_in_different_faces_are_classified_by_their_base_edges() {
        // Base: the square as two triangles (0 1 2), (0 2 3).
        let base = ControlMesh::from_polygons(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.0, 1.0, 0.0],
                [0.0, 1.0, 0.0],
            ],
            &[[0u32, 1, 2], [0, 2, 3]],
        );
        // One triangle: base vertex 0 named by face 1 (its corner 0), the midpoint of the
        // boundary edge 0-1 named by face 0, and a point inside face 1.
        let soup = CapturedSoup {
            records: vec![
                rec([0.0, 0.0, 0.0], 0, [0.0, 0.0]),
                rec([0.5, 0.0, 0.0], 1, [0.0, 0.0]),
                rec([0.3, 0.6, 0.0], 2, [0.0, 0.0]),
            ],
        };
        let points = [
            FacePoint {
                face: 1,
                u: 1.0,
                v: 0.0,
            },
            FacePoint {
                face: 0,
                u: 0.5,
                v: 0.5,
            },
            FacePoint {
                face: 1,
                u: 0.2,
                v: 0.3,
            },
        ];
        let map = |patch: u32, _: [f32; 2]| points.get(patch as usize).copied();
        let w = soup.weld().unwrap();
        let r = w.open_edges();
        assert_eq!(r.open.len(), 3);
        let c = classify_open_edges(&soup, &w, &r, &map, &base);
        assert_eq!(
            (c.on_base_boundary, c.cracks, c.unmapped),
            (1, 2, 0),
            "{r:?}"
        );
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
