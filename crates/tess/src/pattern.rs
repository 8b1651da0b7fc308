//! Refinement patterns (Boubekeur & Schlick 2005, §3.2): a tessellated domain stored once on the
//! device and drawn instanced over the coarse patches, the vertex stage evaluating each patch at
//! each pattern vertex. This module makes the patterns; the techniques draw them
//! ([`crate::technique::DrawPath::Pattern`]).
//!
//! Design decisions:
//! - **A vertex is its domain point**, as in the seed (which encodes `{w, u, v}` as the vertex
//!   position): three floats, `(u, v, w)` barycentric on triangles (the weights of corners 0, 1,
//!   2, as `gl_TessCoord`), `(u, v, 0)` on quads (the bilinear parameter, as `gl_TessCoord.xy`).
//! - **Two sources, one type.** Where the device has a tessellator, a pattern is the
//!   tessellator's own output for that domain, spacing and level, captured once
//!   ([`RefinementPattern::from_capture`]): its points and its triangles, so both draw paths
//!   evaluate the same domain points and rasterize the same triangles on any device. Without a
//!   tessellator, [`RefinementPattern::generate`] makes the equal-spacing lattice itself.
//! - **Generated coordinates are mirrored 16.16 fixed point** (the precision Vulkan's
//!   tessellators work in): point k of n segments is `round(k / n · 2^16) / 2^16` for k ≤ n / 2
//!   and `1 − (point n − k)` beyond, so `1 − x` is exact in `f32` and the two patches of a shared
//!   edge, which walk it in opposite directions, meet the same parameters. On a triangle
//!   `w = 1 − u − v`, exact for the same reason, so the weight opposite an edge is exactly 0
//!   there (the techniques' canonical-edge evaluation keys on that).
//! - **Counter-clockwise in the domain**: triangles turn counter-clockwise in `(u, v)` (`u`
//!   right, `v` up), which maps to the base face's own winding on both domains.
use crate::capture::{CapturedSoup, Capturer};
use crate::context::Context;
use crate::error::{Result, TessError};
use crate::technique::{DrawPath, FactorPolicy, FrameParams};
use crate::techniques::flat::Flat;
use crate::tessellator::{Domain, Spacing};
use std::collections::HashMap;
use std::sync::Arc;
use topology::ControlMesh;
use vk_core::{vk, Buffer};

/// Fixed-point denominator of generated coordinates.
const FIXED_ONE: u32 = 1 << 16;

/// The most segments per edge a generated pattern has: beyond the tessellator's 64, the pattern
/// path refines further (the seed's Fig. 7 goes to 128 × 128).
pub const MAX_GENERATED_SEGMENTS: u32 = 256;

/// One refinement pattern: domain points and the triangles over them.
#[derive(Clone, Debug, PartialEq)]
pub struct RefinementPattern {
    pub domain: Domain,
    /// `(u, v, w)` per vertex (`w = 0` on quads).
    pub points: Vec<[f32; 3]>,
    /// Counter-clockwise in `(u, v)`; every index is below `points.len()`.
    pub triangles: Vec<[u32; 3]>,
}

/// Parameter of point `k` of an edge of `n` equal segments, mirrored 16.16 fixed point (see
/// the module docs), as its numerator over 2^16.
fn fixed_parameter(k: u32, n: u32) -> u32 {
    if 2 * k > n {
        return FIXED_ONE - fixed_parameter(n - k, n);
    }
    ((k as u64 * FIXED_ONE as u64 * 2 + n as u64) / (2 * n as u64)) as u32
}

fn to_f32(fixed: u32) -> f32 {
    fixed as f32 / FIXED_ONE as f32
}

impl RefinementPattern {
    /// The equal-spacing pattern of `segments` segments per edge (1..=
    /// [`MAX_GENERATED_SEGMENTS`]; see the module docs).
    pub fn generate(domain: Domain, segments: u32) -> Result<Self> {
        if !(1..=MAX_GENERATED_SEGMENTS).contains(&segments) {
            return Err(TessError::PatternLevel { segments });
        }
        Ok(match domain {
            Domain::Quad => Self::quad_grid(segments),
            Domain::Triangle => Self::triangle_lattice(segments),
        })
    }

    /// (n + 1)² points, 2n² triangles: each cell split along its (i, j)–(i + 1, j + 1) diagonal.
    fn quad_grid(n: u32) -> Self {
        let at = |i: u32, j: u32| j * (n + 1) + i;
        let mut points = Vec::with_capacity(((n + 1) * (n + 1)) as usize);
        for j in 0..=n {
            for i in 0..=n {
                let (u, v) = (fixed_parameter(i, n), fixed_parameter(j, n));
                points.push([to_f32(u), to_f32(v), 0.0]);
            }
        }
        let mut triangles = Vec::with_capacity((2 * n * n) as usize);
        for j in 0..n {
            for i in 0..n {
                triangles.push([at(i, j), at(i + 1, j), at(i + 1, j + 1)]);
                triangles.push([at(i, j), at(i + 1, j + 1), at(i, j + 1)]);
            }
        }
        Self {
            domain: Domain::Quad,
            points,
            triangles,
        }
    }

    /// (n + 1)(n + 2) / 2 points (i, j) with i + j ≤ n at (u, v) = (x_i, x_j), w = 1 − u − v;
    /// n² triangles, n(n + 1) / 2 pointing up and n(n − 1) / 2 down.
    fn triangle_lattice(n: u32) -> Self {
        let mut index = HashMap::new();
        let mut points = Vec::new();
        for j in 0..=n {
            for i in 0..=n - j {
                let (u, v) = (fixed_parameter(i, n), fixed_parameter(j, n));
                index.insert((i, j), points.len() as u32);
                points.push([to_f32(u), to_f32(v), to_f32(FIXED_ONE - u - v)]);
            }
        }
        let at = |i: u32, j: u32| index[&(i, j)];
        let mut triangles = Vec::with_capacity((n * n) as usize);
        for j in 0..n {
            for i in 0..n - j {
                triangles.push([at(i, j), at(i + 1, j), at(i, j + 1)]);
                if i + j + 1 < n {
                    triangles.push([at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)]);
                }
            }
        }
        Self {
            domain: Domain::Triangle,
            points,
            triangles,
        }
    }

    /// The pattern a tessellator drew: the records of one captured patch (three per triangle,
    /// in the order the tessellator emitted them), whose domain coordinates are its
    /// `gl_TessCoord.xy`. Points are merged by their coordinate bits; on triangles
    /// `w = 1 − u − v`.
    pub fn from_capture(domain: Domain, soup: &CapturedSoup) -> Result<Self> {
        if soup.records.is_empty() || !soup.records.len().is_multiple_of(3) {
            return Err(TessError::PartialTriangle {
                corners: soup.records.len(),
            });
        }
        let mut index: HashMap<[u32; 2], u32> = HashMap::new();
        let mut points = Vec::new();
        let mut corners = Vec::with_capacity(soup.records.len());
        for r in &soup.records {
            let [u, v] = r.domain;
            let id = *index.entry([u.to_bits(), v.to_bits()]).or_insert_with(|| {
                let w = match domain {
                    Domain::Triangle => 1.0 - u - v,
                    Domain::Quad => 0.0,
                };
                points.push([u, v, w]);
                points.len() as u32 - 1
            });
            corners.push(id);
        }
        let triangles = corners
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        Ok(Self {
            domain,
            points,
            triangles,
        })
    }

    /// Triangle corners as one index list.
    pub fn indices(&self) -> Vec<u32> {
        self.triangles.iter().flatten().copied().collect()
    }
}

/// A refinement pattern on the device.
pub(crate) struct PatternBuffers {
    pub key: PatternKey,
    pub pattern: Arc<RefinementPattern>,
    pub points: Buffer,
    pub indices: Buffer,
}

impl PatternBuffers {
    pub fn new(
        device: &vk_core::Device,
        key: PatternKey,
        pattern: Arc<RefinementPattern>,
    ) -> Result<Self> {
        let n = pattern.points.len() as u32;
        let indices = pattern.indices();
        if let Some(&bad) = indices.iter().find(|&&i| i >= n) {
            return Err(TessError::IndexOutOfRange {
                what: "refinement pattern index",
                index: bad as u64,
                len: n as u64,
            });
        }
        let name = format!("refinement pattern {:?}", pattern.domain);
        Ok(Self {
            points: Buffer::with_data(
                device,
                &format!("{name} points"),
                vk::BufferUsageFlags::VERTEX_BUFFER,
                bytemuck::cast_slice(&pattern.points),
            )?,
            indices: Buffer::with_data(
                device,
                &format!("{name} indices"),
                vk::BufferUsageFlags::INDEX_BUFFER,
                bytemuck::cast_slice(&indices),
            )?,
            key,
            pattern,
        })
    }
}

/// What selects a pattern: domain, spacing and the uniform level (its bits: fractional levels
/// are patterns of their own).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PatternKey {
    pub domain: Domain,
    pub spacing: Spacing,
    level_bits: u32,
}

impl PatternKey {
    pub fn new(domain: Domain, spacing: Spacing, level: f32) -> Self {
        Self {
            domain,
            spacing,
            level_bits: level.to_bits(),
        }
    }

    pub fn level(&self) -> f32 {
        f32::from_bits(self.level_bits)
    }
}

/// The patterns a context made, by key.
#[derive(Default)]
pub struct PatternCache {
    made: HashMap<PatternKey, Arc<RefinementPattern>>,
}

impl PatternCache {
    pub fn cached(&self, key: PatternKey) -> Option<Arc<RefinementPattern>> {
        self.made.get(&key).cloned()
    }

    pub fn insert(&mut self, key: PatternKey, pattern: Arc<RefinementPattern>) {
        self.made.insert(key, pattern);
    }
}

/// Triangles of the pattern [`make`] generates for `domain` at `level` (equal spacing: whole
/// segments, rounded up).
pub fn generated_triangle_count(domain: Domain, level: f32) -> u64 {
    let n = generated_segments(level) as u64;
    match domain {
        Domain::Quad => 2 * n * n,
        Domain::Triangle => n * n,
    }
}

/// Whole segments of a generated pattern at `level`, as the tessellator rounds equal spacing.
fn generated_segments(level: f32) -> u32 {
    level.ceil().clamp(1.0, MAX_GENERATED_SEGMENTS as f32) as u32
}

/// Whether `device`'s patterns are its tessellator's own: it has tessellation shaders, and can
/// capture them in a rendering scope of its own (transform feedback, dynamic rendering).
pub fn from_tessellator(device: &vk_core::Device) -> bool {
    let caps = &device.info.caps;
    caps.tessellation_shader
        && caps.dynamic_rendering
        && device.require_transform_feedback().is_ok()
}

/// Makes the pattern of `key` on `ctx`'s device: the tessellator's own where
/// [`from_tessellator`] and the level is within its 64 (one flat patch over the unit domain,
/// drawn through the tessellator and captured); otherwise
/// generated, in equal spacing only.
pub fn make(ctx: &mut Context, key: PatternKey) -> Result<RefinementPattern> {
    if from_tessellator(ctx.device()) && key.level() <= crate::tessellator::MAX_LEVEL {
        return tessellator_pattern(ctx, key);
    }
    if key.spacing != Spacing::Equal {
        return Err(TessError::PatternSpacing {
            spacing: key.spacing,
        });
    }
    RefinementPattern::generate(key.domain, generated_segments(key.level()))
}

/// One patch of `key`'s domain over the unit domain, drawn flat through the tessellator at
/// `key`'s level and spacing and captured: the tessellator's points and triangles.
fn tessellator_pattern(ctx: &mut Context, key: PatternKey) -> Result<RefinementPattern> {
    let corners: &[[f64; 3]] = match key.domain {
        Domain::Quad => &[
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
        ],
        Domain::Triangle => &[[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
    };
    let face: Vec<u32> = (0..corners.len() as u32).collect();
    let mesh = ControlMesh::from_polygons(corners.to_vec(), &[face]);
    let mut patch = Flat::new(ctx.device(), &mesh, DrawPath::Tessellation)?;
    let params = FrameParams {
        factors: FactorPolicy::Uniform {
            segments: key.level(),
        },
        spacing: key.spacing,
        ..FrameParams::default()
    };
    let extent = vk_core::vk::Extent2D {
        width: 1,
        height: 1,
    };
    let (soup, _) = Capturer::new(ctx)?.capture(ctx, &mut patch, &params, extent)?;
    RefinementPattern::from_capture(key.domain, &soup)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tessellator::{uniform_triangle_count, uniform_vertex_count, Spacing};

    fn signed_area(p: &RefinementPattern, t: [u32; 3]) -> f64 {
        let [a, b, c] = t.map(|i| p.points[i as usize]);
        let (ab, ac) = (
            [(b[0] - a[0]) as f64, (b[1] - a[1]) as f64],
            [(c[0] - a[0]) as f64, (c[1] - a[1]) as f64],
        );
        ab[0] * ac[1] - ab[1] * ac[0]
    }

    #[test]
    fn quad_counts_equal_the_tessellators_and_triangles_are_the_lattice() {
        for n in 1..=64 {
            let q = RefinementPattern::generate(Domain::Quad, n).unwrap();
            let level = n as f32;
            assert_eq!(
                q.points.len() as u64,
                uniform_vertex_count(Domain::Quad, Spacing::Equal, level),
                "{n}"
            );
            assert_eq!(
                q.triangles.len() as u64,
                uniform_triangle_count(Domain::Quad, Spacing::Equal, level),
                "{n}"
            );
            // The tessellator's triangles are concentric rings (a centre point at even levels);
            // the generated triangle pattern is the barycentric lattice.
            let t = RefinementPattern::generate(Domain::Triangle, n).unwrap();
            assert_eq!(t.points.len() as u32, (n + 1) * (n + 2) / 2, "{n}");
            assert_eq!(t.triangles.len() as u32, n * n, "{n}");
        }
    }

    #[test]
    fn triangles_are_counter_clockwise_and_tile_the_domain() {
        for domain in [Domain::Triangle, Domain::Quad] {
            for n in [1, 2, 3, 7, 64] {
                let p = RefinementPattern::generate(domain, n).unwrap();
                let mut area = 0.0;
                for &t in &p.triangles {
                    assert!(t.iter().all(|&i| (i as usize) < p.points.len()));
                    let a = signed_area(&p, t);
                    assert!(a > 0.0, "{domain:?} {n}: {t:?} turns clockwise");
                    area += a / 2.0;
                }
                let want = if domain == Domain::Quad { 1.0 } else { 0.5 };
                assert!((area - want).abs() < 1e-9, "{domain:?} {n}: area {area}");
            }
        }
    }

    #[test]
    fn parameters_mirror_exactly_and_weights_vanish_on_edges() {
        for n in 1..=64 {
            for k in 0..=n {
                let x = to_f32(fixed_parameter(k, n));
                let y = to_f32(fixed_parameter(n - k, n));
                assert_eq!((1.0 - x).to_bits(), y.to_bits(), "{k}/{n}");
                assert!((x as f64 - k as f64 / n as f64).abs() <= 0.5 / 65536.0);
            }
            let p = RefinementPattern::generate(Domain::Triangle, n).unwrap();
            for q in &p.points {
                let sum = q[0] + q[1] + q[2];
                assert_eq!(sum, 1.0, "{q:?}");
                assert!(q.iter().all(|&c| (0.0..=1.0).contains(&c)));
            }
            // The lattice has exactly 3n points on its boundary.
            let boundary = p.points.iter().filter(|q| q.contains(&0.0)).count();
            assert_eq!(boundary as u32, 3 * n, "{n}");
        }
    }

    #[test]
    fn levels_outside_the_tessellators_range_are_refused_by_name() {
        for n in [0, MAX_GENERATED_SEGMENTS + 1] {
            let e = RefinementPattern::generate(Domain::Quad, n).unwrap_err();
            assert!(e.to_string().contains(&n.to_string()), "{e}");
        }
    }

    #[test]
    fn a_captured_pattern_keeps_the_tessellators_triangles() {
        use crate::gpu::CaptureRecord;
        let rec = |u: f32, v: f32| CaptureRecord {
            domain: [u, v],
            ..Default::default()
        };
        let soup = CapturedSoup {
            records: vec![
                rec(0.0, 0.0),
                rec(1.0, 0.0),
                rec(0.0, 1.0),
                rec(1.0, 0.0),
                rec(0.5, 0.5),
                rec(0.0, 1.0),
            ],
        };
        let p = RefinementPattern::from_capture(Domain::Triangle, &soup).unwrap();
        assert_eq!(p.points.len(), 4);
        assert_eq!(p.triangles, vec![[0, 1, 2], [1, 3, 2]]);
        assert_eq!(p.points[3], [0.5, 0.5, 0.0]);
        let partial = CapturedSoup {
            records: soup.records[..4].to_vec(),
        };
        assert!(RefinementPattern::from_capture(Domain::Quad, &partial).is_err());
    }
}
