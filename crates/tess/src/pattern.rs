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

    /// The quad pattern of per-edge levels `outer` (`gl_TessLevelOuter`'s order: the edges
    /// u = 0, v = 0, u = 1, v = 1) and inner levels `inner` (segments along u, along v), whole
    /// segments in equal spacing, each point where `params` puts a level's points: each edge's
    /// at its own level, the inner lattice's at the inner levels, so two patterns sharing an
    /// edge level meet point for point along it. [`LevelParameters::generated`] gives the
    /// uniform levels [`Self::generate`]'s grid. Otherwise the inner lattice (its points
    /// `1..n − 1` per direction) is a grid of cells, and each edge is joined to the lattice side
    /// facing it by a strip zipped along both in step; an inner level of 1 has no lattice in
    /// that direction, and its two edges facing each other are zipped directly (which needs
    /// the edges across them at level 1).
    pub fn generate_edges(
        outer: [u32; 4],
        inner: [u32; 2],
        params: &dyn Fn(u32) -> Result<LevelParameters>,
    ) -> Result<Self> {
        let all = [outer[0], outer[1], outer[2], outer[3], inner[0], inner[1]];
        let refuse = |why| TessError::PatternEdges {
            domain: Domain::Quad,
            outer: outer.map(|l| l as f32).to_vec(),
            inner: inner.map(|l| l as f32).to_vec(),
            why,
        };
        if all
            .iter()
            .any(|&l| !(1..=MAX_GENERATED_SEGMENTS).contains(&l))
        {
            return Err(refuse("expected levels 1..256"));
        }
        let mut levels = HashMap::new();
        for l in all {
            if let std::collections::hash_map::Entry::Vacant(e) = levels.entry(l) {
                e.insert(params(l)?);
            }
        }
        let mut b = Stitch {
            levels,
            ..Stitch::default()
        };
        let [iu, iv] = inner;
        match (iu >= 2, iv >= 2) {
            (true, true) => b.lattice_and_strips(outer, inner),
            (false, false) if all.iter().all(|&l| l == 1) => return Ok(Self::quad_grid(1)),
            (true, false) if outer[0] == 1 && outer[2] == 1 => {
                b.facing_edges((1, outer[1]), (3, outer[3]))
            }
            (false, true) if outer[1] == 1 && outer[3] == 1 => {
                b.facing_edges((2, outer[2]), (0, outer[0]))
            }
            _ => {
                return Err(refuse(
                    "an inner level of 1 needs the two edges across it at level 1",
                ))
            }
        }
        Ok(b.finish())
    }

    /// The triangle pattern of per-edge levels `outer` (`gl_TessLevelOuter`'s order: the edges
    /// u = 0, v = 0, w = 0) and inner level `inner`, whole segments in equal spacing at the
    /// generated parameters of [`Self::generate`]: each edge at its own level, so two patterns
    /// sharing an edge level meet point for point along it. From inner level 3 on, the inner
    /// lattice (the barycentric lattice's points with every index at least 1) is joined to each
    /// edge by a strip zipped along both; below it the boundary is fanned from the centroid.
    /// Uniform levels give [`Self::generate`]'s lattice.
    pub fn generate_triangle_edges(outer: [u32; 3], inner: u32) -> Result<Self> {
        let all = [outer[0], outer[1], outer[2], inner];
        if all
            .iter()
            .any(|&l| !(1..=MAX_GENERATED_SEGMENTS).contains(&l))
        {
            return Err(TessError::PatternEdges {
                domain: Domain::Triangle,
                outer: outer.map(|l| l as f32).to_vec(),
                inner: vec![inner as f32],
                why: "expected levels 1..256",
            });
        }
        if all.iter().all(|&l| l == inner) {
            return Ok(Self::triangle_lattice(inner));
        }
        let mut b = Stitch {
            triangle: true,
            ..Stitch::default()
        };
        if inner >= 3 {
            b.triangle_lattice_and_strips(outer, inner);
        } else {
            b.triangle_fan(outer);
        }
        Ok(b.finish())
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

/// Builds the stitched patterns ([`RefinementPattern::generate_edges`],
/// [`RefinementPattern::generate_triangle_edges`]): points merged by their parameters' bits,
/// triangles counter-clockwise in `(u, v)`.
#[derive(Default)]
struct Stitch {
    /// Triangles (`w = 1 − u − v` per point) or quads.
    triangle: bool,
    /// Where each level used puts its points.
    levels: HashMap<u32, LevelParameters>,
    index: HashMap<[u32; 2], u32>,
    points: Vec<[f32; 3]>,
    triangles: Vec<[u32; 3]>,
}

/// Where the points of one level lie on a quad, as 16.16 numerators in ascending order: on each
/// square edge (`gl_TessLevelOuter`'s order: u = 0, v = 0, u = 1, v = 1; `n + 1` each, ends
/// included) and along u and along v inside (`n + 1` each, 0 and 1 included).
#[derive(Clone, Debug, PartialEq)]
pub struct LevelParameters {
    pub edges: [Vec<u32>; 4],
    pub inner: [Vec<u32>; 2],
}

impl LevelParameters {
    /// The mirrored 16.16 parameters of [`RefinementPattern::generate`].
    pub fn generated(n: u32) -> Self {
        let along: Vec<u32> = (0..=n).map(|k| fixed_parameter(k, n)).collect();
        Self {
            edges: std::array::from_fn(|_| along.clone()),
            inner: [along.clone(), along],
        }
    }

    /// The parameters of the uniform quad pattern `p` of level `n` (a tessellator's): its
    /// points on each edge and the coordinates of its inner lattice. `None` unless every
    /// coordinate is a 16.16 number and each list has `n + 1` entries.
    pub fn of_pattern(p: &RefinementPattern, n: u32) -> Option<Self> {
        let fixed = |x: f32| {
            let f = x as f64 * FIXED_ONE as f64;
            (f.fract() == 0.0 && (0.0..=FIXED_ONE as f64).contains(&f)).then_some(f as u32)
        };
        let sorted = |mut v: Vec<u32>| {
            v.sort_unstable();
            v.dedup();
            (v.len() == n as usize + 1).then_some(v)
        };
        let on = |axis: usize, at: f32| {
            let along = 1 - axis;
            p.points
                .iter()
                .filter(|q| q[axis] == at)
                .map(|q| fixed(q[along]))
                .collect::<Option<Vec<u32>>>()
                .and_then(sorted)
        };
        let inside = |axis: usize| {
            let interior = p
                .points
                .iter()
                .filter(|q| q[..2].iter().all(|&c| c > 0.0 && c < 1.0));
            let mut v: Vec<u32> = interior.map(|q| fixed(q[axis])).collect::<Option<_>>()?;
            v.extend([0, FIXED_ONE]);
            sorted(v)
        };
        Some(Self {
            edges: [on(0, 0.0)?, on(1, 0.0)?, on(0, 1.0)?, on(1, 1.0)?],
            inner: [inside(0)?, inside(1)?],
        })
    }
}

impl Stitch {
    /// The point at fixed-point parameters `(u, v)`.
    fn point(&mut self, u: u32, v: u32) -> u32 {
        let points = &mut self.points;
        let w = if self.triangle {
            to_f32(FIXED_ONE - u - v)
        } else {
            0.0
        };
        *self.index.entry([u, v]).or_insert_with(|| {
            points.push([to_f32(u), to_f32(v), w]);
            points.len() as u32 - 1
        })
    }

    /// The `n + 1` points of square edge `e` (0: u = 0, 1: v = 0, 2: u = 1, 3: v = 1) at level
    /// `n`, in the square's counter-clockwise direction (v = 0 left to right, u = 1 upwards,
    /// v = 1 right to left, u = 0 downwards).
    fn edge(&mut self, e: usize, n: u32) -> Vec<u32> {
        let along = self.levels[&n].edges[e].clone();
        let mut out: Vec<u32> = along
            .iter()
            .map(|&t| match e {
                0 => self.point(0, t),
                1 => self.point(t, 0),
                2 => self.point(FIXED_ONE, t),
                _ => self.point(t, FIXED_ONE),
            })
            .collect();
        // Edges 0 and 3 run against their parameter.
        if e == 0 || e == 3 {
            out.reverse();
        }
        out
    }

    /// Parameter of a point along the direction from `first` to `last` of a polyline (the
    /// coordinate that changes along it).
    fn along(&self, p: u32, first: u32, last: u32) -> f32 {
        let (a, b, q) = (
            self.points[first as usize],
            self.points[last as usize],
            self.points[p as usize],
        );
        let axis = if a[0] != b[0] { 0 } else { 1 };
        let t = (q[axis] - a[axis]) / (b[axis] - a[axis]);
        if t.is_finite() {
            t
        } else {
            0.0
        }
    }

    /// Triangles between `outer` and `inner`, two polylines running the same way with the
    /// region on their left (`outer` on its right side): each step advances the one whose next
    /// point comes first along the way.
    fn zip(&mut self, outer: &[u32], inner: &[u32]) {
        let (mut i, mut j) = (0, 0);
        let (o_first, o_last) = (outer[0], outer[outer.len() - 1]);
        let (i_first, i_last) = (inner[0], inner[inner.len() - 1]);
        while i + 1 < outer.len() || j + 1 < inner.len() {
            let advance_outer = j + 1 == inner.len()
                || (i + 1 < outer.len()
                    && self.along(outer[i + 1], o_first, o_last)
                        <= self.along(inner[j + 1], i_first, i_last));
            if advance_outer {
                self.triangles.push([outer[i], outer[i + 1], inner[j]]);
                i += 1;
            } else {
                self.triangles.push([outer[i], inner[j + 1], inner[j]]);
                j += 1;
            }
        }
    }

    /// Two facing edges `(edge, level)` zipped together (an inner level of 1): `lower` in the
    /// square's direction, `upper` against it, so both run the same way.
    fn facing_edges(&mut self, lower: (usize, u32), upper: (usize, u32)) {
        let lower = self.edge(lower.0, lower.1);
        let mut upper = self.edge(upper.0, upper.1);
        upper.reverse();
        self.zip(&lower, &upper);
    }

    /// The inner lattice's cells, then a strip from each edge to the lattice side facing it.
    fn lattice_and_strips(&mut self, outer: [u32; 4], [iu, iv]: [u32; 2]) {
        let (us, vs) = (
            self.levels[&iu].inner[0].clone(),
            self.levels[&iv].inner[1].clone(),
        );
        let lattice = |s: &mut Self, i: u32, j: u32| s.point(us[i as usize], vs[j as usize]);
        for j in 1..iv - 1 {
            for i in 1..iu - 1 {
                let [a, b, c, d] = [(i, j), (i + 1, j), (i + 1, j + 1), (i, j + 1)]
                    .map(|(x, y)| lattice(self, x, y));
                self.triangles.push([a, b, c]);
                self.triangles.push([a, c, d]);
            }
        }
        // The lattice's sides in the square's counter-clockwise direction, each from the
        // lattice corner its edge starts beside.
        let (hi_u, hi_v) = (iu - 1, iv - 1);
        let sides: [Vec<(u32, u32)>; 4] = [
            (1..=hi_v).rev().map(|j| (1, j)).collect(),
            (1..=hi_u).map(|i| (i, 1)).collect(),
            (1..=hi_v).map(|j| (hi_u, j)).collect(),
            (1..=hi_u).rev().map(|i| (i, hi_v)).collect(),
        ];
        for (e, side) in sides.iter().enumerate() {
            let edge = self.edge(e, outer[e]);
            let inner: Vec<u32> = side.iter().map(|&(i, j)| lattice(self, i, j)).collect();
            self.zip(&edge, &inner);
        }
    }

    fn finish(self) -> RefinementPattern {
        RefinementPattern {
            domain: if self.triangle {
                Domain::Triangle
            } else {
                Domain::Quad
            },
            points: self.points,
            triangles: self.triangles,
        }
    }

    /// The `n + 1` points of triangle edge `e` (0: u = 0, 1: v = 0, 2: w = 0,
    /// `gl_TessLevelOuter`'s order) at level `n`, in the triangle's counter-clockwise direction
    /// (v = 0 from corner (0, 0) to (1, 0), w = 0 on to (0, 1), u = 0 back to (0, 0)).
    fn triangle_edge(&mut self, e: usize, n: u32) -> Vec<u32> {
        (0..=n)
            .map(|k| {
                let t = fixed_parameter(k, n);
                match e {
                    0 => self.point(0, FIXED_ONE - t),
                    1 => self.point(t, 0),
                    _ => self.point(FIXED_ONE - t, t),
                }
            })
            .collect()
    }

    /// The inner lattice of level `n ≥ 3` (its points with every barycentric index ≥ 1), then a
    /// strip from each edge to the lattice side facing it.
    fn triangle_lattice_and_strips(&mut self, outer: [u32; 3], n: u32) {
        let at =
            |s: &mut Self, i: u32, j: u32| s.point(fixed_parameter(i, n), fixed_parameter(j, n));
        for j in 1..n - 1 {
            for i in 1..n - 1 - j {
                let (a, b, c) = (at(self, i, j), at(self, i + 1, j), at(self, i, j + 1));
                self.triangles.push([a, b, c]);
                if i + j + 3 <= n {
                    let d = at(self, i + 1, j + 1);
                    self.triangles.push([b, d, c]);
                }
            }
        }
        let m = n - 2;
        let sides: [Vec<(u32, u32)>; 3] = [
            (1..=m).rev().map(|j| (1, j)).collect(),
            (1..=m).map(|i| (i, 1)).collect(),
            (1..=m).rev().map(|i| (i, n - 1 - i)).collect(),
        ];
        for e in [1, 2, 0] {
            let edge = self.triangle_edge(e, outer[e]);
            let inner: Vec<u32> = sides[e].iter().map(|&(i, j)| at(self, i, j)).collect();
            self.zip(&edge, &inner);
        }
    }

    /// The triangle's boundary points (each edge at its level) fanned from its centroid.
    fn triangle_fan(&mut self, outer: [u32; 3]) {
        let third = fixed_parameter(1, 3);
        let c = self.point(third, third);
        let mut ring = Vec::new();
        for e in [1, 2, 0] {
            let edge = self.triangle_edge(e, outer[e]);
            ring.extend_from_slice(&edge[..edge.len() - 1]);
        }
        for k in 0..ring.len() {
            self.triangles
                .push([ring[k], ring[(k + 1) % ring.len()], c]);
        }
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

/// The device patterns a surface draws in its frames, by key: a family indexed by edge levels,
/// each member made on first use.
#[derive(Default)]
pub(crate) struct PatternFamily {
    current: HashMap<PatternKey, PatternBuffers>,
}

impl PatternFamily {
    /// Takes the patterns of `keys` from the context, uploading those not on the device yet,
    /// and drops the patterns no key uses any more.
    pub fn take(&mut self, ctx: &mut Context, keys: &[PatternKey]) -> Result<()> {
        let wanted: std::collections::HashSet<PatternKey> = keys.iter().copied().collect();
        self.current.retain(|k, _| wanted.contains(k));
        for key in wanted {
            if let std::collections::hash_map::Entry::Vacant(slot) = self.current.entry(key) {
                let pattern = ctx.refinement_pattern_for(key)?;
                slot.insert(PatternBuffers::new(ctx.device(), key, pattern)?);
            }
        }
        Ok(())
    }

    /// The prepared pattern of `key`.
    pub fn get(&self, key: &PatternKey) -> Option<&PatternBuffers> {
        self.current.get(key)
    }

    /// The most points a pattern of the family has.
    pub fn max_points(&self) -> u64 {
        self.current
            .values()
            .map(|p| p.pattern.points.len() as u64)
            .max()
            .unwrap_or(0)
    }

    /// Every pattern's points and indices.
    pub fn buffers(&self) -> impl Iterator<Item = &Buffer> {
        self.current.values().flat_map(|p| [&p.points, &p.indices])
    }
}

/// The instance-rate buffers of a surface drawn through patterns: its static records (each
/// patch with no morph) and, as large, the buffer the frames' host-chosen records are written
/// into ([`write_instances`]); named `name` and "`name` (host-chosen levels)". An empty surface
/// still binds one record (zero-length buffers are invalid); no draw reads it.
pub(crate) fn instance_buffers(
    device: &vk_core::Device,
    name: &str,
    mut records: Vec<[u32; 4]>,
) -> Result<(Buffer, Buffer)> {
    if records.is_empty() {
        records.push([0; 4]);
    }
    let frame = Buffer::new(
        device,
        &vk_core::BufferDesc {
            name: &format!("{name} (host-chosen levels)"),
            size: std::mem::size_of_val(records.as_slice()) as u64,
            usage: vk::BufferUsageFlags::VERTEX_BUFFER | vk::BufferUsageFlags::TRANSFER_DST,
            location: vk_core::MemoryLocation::GpuOnly,
        },
    )?;
    let fixed = Buffer::with_data(
        device,
        name,
        vk::BufferUsageFlags::VERTEX_BUFFER,
        bytemuck::cast_slice(&records),
    )?;
    Ok((fixed, frame))
}

/// Groups a frame's `instances` (each a pattern key and its instance record: a patch id and
/// its morph weights) by key, appending each group to `records` as one run, the groups in the
/// order of their first instance; returns each key and its run (one instanced draw each).
pub(crate) fn group_by_key(
    instances: impl IntoIterator<Item = (PatternKey, [u32; 4])>,
    records: &mut Vec<[u32; 4]>,
) -> Vec<(PatternKey, std::ops::Range<u32>)> {
    let mut order: Vec<PatternKey> = Vec::new();
    let mut by_key: HashMap<PatternKey, Vec<[u32; 4]>> = HashMap::new();
    for (key, record) in instances {
        by_key
            .entry(key)
            .or_insert_with(|| {
                order.push(key);
                Vec::new()
            })
            .push(record);
    }
    order
        .into_iter()
        .map(|key| {
            let first = records.len() as u32;
            records.extend(by_key.remove(&key).unwrap_or_default());
            (key, first..records.len() as u32)
        })
        .collect()
}

/// Writes a frame's instance records (`uvec4`s: a patch id and its morph weights) into
/// `buffer` from the command buffer, after the previous frame's vertex input read them and
/// before this frame's does, so frames in flight never share a host buffer.
pub(crate) fn write_instances<'a>(
    enc: &mut vk_core::Encoder<'a>,
    buffer: &'a Buffer,
    records: &[[u32; 4]],
) -> Result<()> {
    if records.is_empty() {
        return Ok(());
    }
    let input = (
        vk::PipelineStageFlags::VERTEX_INPUT,
        vk::AccessFlags::VERTEX_ATTRIBUTE_READ,
    );
    let transfer = (
        vk::PipelineStageFlags::TRANSFER,
        vk::AccessFlags::TRANSFER_WRITE,
    );
    enc.memory_barrier(input, transfer);
    enc.update_buffer(buffer, 0, bytemuck::cast_slice(records))?;
    enc.memory_barrier(transfer, input);
    Ok(())
}

/// What selects a pattern: domain, spacing and the tessellation levels (their bits: fractional
/// levels are patterns of their own), outer in `gl_TessLevelOuter`'s order and inner in
/// `gl_TessLevelInner`'s; a triangle's fourth outer and second inner level are 0.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub struct PatternKey {
    pub domain: Domain,
    pub spacing: Spacing,
    outer_bits: [u32; 4],
    inner_bits: [u32; 2],
    /// Always the generated patterns, never the tessellator's: their lattices nest from level
    /// to level (each cell split along the same diagonal), which geomorphing needs.
    pub generated: bool,
}

impl PatternKey {
    /// Every level `level`.
    pub fn new(domain: Domain, spacing: Spacing, level: f32) -> Self {
        Self::with_levels(domain, spacing, [level; 4], [level; 2])
    }

    /// Per-edge levels (see the type).
    pub fn with_levels(domain: Domain, spacing: Spacing, outer: [f32; 4], inner: [f32; 2]) -> Self {
        let (outer, inner) = match domain {
            Domain::Quad => (outer, inner),
            Domain::Triangle => ([outer[0], outer[1], outer[2], 0.0], [inner[0], 0.0]),
        };
        Self {
            domain,
            spacing,
            outer_bits: outer.map(f32::to_bits),
            inner_bits: inner.map(f32::to_bits),
            generated: false,
        }
    }

    /// The same levels, from the generated patterns only (see the field).
    pub fn generated(self) -> Self {
        Self {
            generated: true,
            ..self
        }
    }

    pub fn outer(&self) -> [f32; 4] {
        self.outer_bits.map(f32::from_bits)
    }

    pub fn inner(&self) -> [f32; 2] {
        self.inner_bits.map(f32::from_bits)
    }

    /// The levels that mean something on the key's domain: outer, then inner.
    fn levels(&self) -> Vec<f32> {
        let (o, i) = match self.domain {
            Domain::Quad => (4, 2),
            Domain::Triangle => (3, 1),
        };
        self.outer()[..o]
            .iter()
            .chain(&self.inner()[..i])
            .copied()
            .collect()
    }

    /// The level every edge and the inside share, if they do.
    pub fn uniform_level(&self) -> Option<f32> {
        let levels = self.levels();
        let first = levels[0];
        levels
            .iter()
            .all(|l| l.to_bits() == first.to_bits())
            .then_some(first)
    }

    /// The largest level of the key.
    pub fn max_level(&self) -> f32 {
        self.levels().into_iter().fold(0.0, f32::max)
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

/// Makes the pattern of `key` on `ctx`'s device. A uniform key: generated where the key asks
/// for it ([`PatternKey::generated`]), else the tessellator's own where [`from_tessellator`]
/// and the level is within its 64 (one flat patch over the unit domain, drawn through the
/// tessellator and captured), otherwise generated, in equal spacing only.
/// A key with unequal levels (a transition patch's) is generated
/// ([`RefinementPattern::generate_edges`]): its points lie where the tessellator's would, on
/// each edge and inside, so shared edges meet; the triangulation is the pattern's own.
pub fn make(ctx: &mut Context, key: PatternKey) -> Result<RefinementPattern> {
    let Some(level) = key.uniform_level() else {
        return generate_for_edges(ctx, key);
    };
    if key.generated && key.spacing == Spacing::Equal {
        return RefinementPattern::generate(key.domain, generated_segments(level));
    }
    if from_tessellator(ctx.device()) && level <= crate::tessellator::MAX_LEVEL {
        return tessellator_pattern(ctx, key.domain, key.spacing, level);
    }
    if key.spacing != Spacing::Equal {
        return Err(TessError::PatternSpacing {
            spacing: key.spacing,
        });
    }
    RefinementPattern::generate(key.domain, generated_segments(level))
}

/// [`RefinementPattern::generate_edges`] for a key of whole levels in equal spacing, its points
/// where the device's tessellator puts each level's ([`LevelParameters::of_pattern`] of its
/// uniform pattern) when [`from_tessellator`] and the level is within its 64, else at the
/// generated parameters.
fn generate_for_edges(ctx: &mut Context, key: PatternKey) -> Result<RefinementPattern> {
    let refuse = |why| TessError::PatternEdges {
        domain: key.domain,
        outer: key.outer().to_vec(),
        inner: key.inner().to_vec(),
        why,
    };
    if key.spacing != Spacing::Equal {
        return Err(TessError::PatternSpacing {
            spacing: key.spacing,
        });
    }
    let whole = |l: f32| {
        (l.fract() == 0.0 && (1.0..=MAX_GENERATED_SEGMENTS as f32).contains(&l)).then_some(l as u32)
    };
    if key.domain == Domain::Triangle {
        let ([Some(a), Some(b), Some(c), _], [Some(n), _]) =
            (key.outer().map(whole), key.inner().map(whole))
        else {
            return Err(refuse("expected whole levels 1..256"));
        };
        return RefinementPattern::generate_triangle_edges([a, b, c], n);
    }
    let ([Some(a), Some(b), Some(c), Some(d)], [Some(u), Some(v)]) =
        (key.outer().map(whole), key.inner().map(whole))
    else {
        return Err(refuse("expected whole levels 1..256"));
    };
    let mut tessellated = HashMap::new();
    if from_tessellator(ctx.device()) {
        for n in [a, b, c, d, u, v] {
            if n as f32 <= crate::tessellator::MAX_LEVEL && !tessellated.contains_key(&n) {
                let uniform = ctx.refinement_pattern(Domain::Quad, Spacing::Equal, n as f32)?;
                let at = LevelParameters::of_pattern(&uniform, n).ok_or_else(|| {
                    refuse("the tessellator's uniform pattern of a level is not a 16.16 lattice")
                })?;
                tessellated.insert(n, at);
            }
        }
    }
    RefinementPattern::generate_edges([a, b, c, d], [u, v], &|n| {
        Ok(tessellated
            .get(&n)
            .cloned()
            .unwrap_or_else(|| LevelParameters::generated(n)))
    })
}

/// One patch of `key`'s domain over the unit domain, drawn flat through the tessellator at
/// `key`'s level and spacing and captured: the tessellator's points and triangles.
fn tessellator_pattern(
    ctx: &mut Context,
    domain: Domain,
    spacing: Spacing,
    level: f32,
) -> Result<RefinementPattern> {
    let corners: &[[f64; 3]] = match domain {
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
        factors: FactorPolicy::Uniform { segments: level },
        spacing,
        ..FrameParams::default()
    };
    let extent = vk_core::vk::Extent2D {
        width: 1,
        height: 1,
    };
    let (soup, _) = Capturer::new(ctx)?.capture(ctx, &mut patch, &params, extent)?;
    RefinementPattern::from_capture(domain, &soup)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::tessellator::{uniform_triangle_count, uniform_vertex_count, Spacing};

    /// Instances group by key into consecutive runs of the records, in the order of each key's
    /// first instance, each run keeping its instances' order.
    #[test]
    fn instances_group_by_key_in_first_use_order() {
        let (a, b) = (
            PatternKey::new(Domain::Triangle, Spacing::Equal, 2.0),
            PatternKey::new(Domain::Triangle, Spacing::Equal, 4.0),
        );
        let mut records = vec![[9; 4]];
        let groups = group_by_key(
            [(b, [1, 0, 0, 0]), (a, [2, 0, 0, 0]), (b, [3, 0, 0, 0])],
            &mut records,
        );
        assert_eq!(groups, vec![(b, 1..3), (a, 3..4)]);
        let ids: Vec<u32> = records.iter().map(|r| r[0]).collect();
        assert_eq!(ids, vec![9, 1, 3, 2]);
    }

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

    /// Per-edge patterns of the planned patches' transitions (one edge doubled, inner levels
    /// the larger of each facing pair) and others: counter-clockwise, tiling the square, each
    /// edge at its own level, every inner lattice point present.
    #[test]
    fn per_edge_patterns_tile_the_square_with_each_edge_at_its_level() {
        let generated = |n| Ok(LevelParameters::generated(n));
        let cases: [([u32; 4], [u32; 2]); 9] = [
            ([4, 8, 4, 4], [8, 4]),
            ([8, 4, 4, 4], [4, 8]),
            ([8, 8, 4, 4], [8, 8]),
            ([2, 1, 2, 1], [1, 2]),
            ([1, 2, 1, 1], [2, 1]),
            ([1, 1, 2, 1], [1, 2]),
            ([3, 5, 7, 2], [5, 7]),
            ([64, 32, 32, 32], [32, 64]),
            ([6, 6, 6, 6], [6, 6]),
        ];
        for (outer, inner) in cases {
            let p = RefinementPattern::generate_edges(outer, inner, &generated).unwrap();
            let mut area = 0.0;
            for &t in &p.triangles {
                let a = signed_area(&p, t);
                assert!(
                    a > 0.0,
                    "{outer:?} {inner:?}: {t:?} turns clockwise or is degenerate"
                );
                area += a / 2.0;
            }
            assert!(
                (area - 1.0).abs() < 1e-9,
                "{outer:?} {inner:?}: area {area}"
            );
            let on = |e: usize, q: &[f32; 3]| match e {
                0 => q[0] == 0.0,
                1 => q[1] == 0.0,
                2 => q[0] == 1.0,
                _ => q[1] == 1.0,
            };
            for (e, &n) in outer.iter().enumerate() {
                let mut along: Vec<f32> = p
                    .points
                    .iter()
                    .filter(|q| on(e, q))
                    .map(|q| if e % 2 == 0 { q[1] } else { q[0] })
                    .collect();
                along.sort_by(f32::total_cmp);
                let want: Vec<f32> = (0..=n).map(|k| to_f32(fixed_parameter(k, n))).collect();
                assert_eq!(along, want, "{outer:?} {inner:?}: edge {e}");
            }
            let interior = p
                .points
                .iter()
                .filter(|q| !(0..4).any(|e| on(e, q)))
                .count();
            let lattice = if inner.contains(&1) {
                0
            } else {
                (inner[0] - 1) * (inner[1] - 1)
            };
            assert_eq!(interior as u32, lattice, "{outer:?} {inner:?}");
        }
        assert_eq!(
            RefinementPattern::generate_edges([1; 4], [1; 2], &generated).unwrap(),
            RefinementPattern::generate(Domain::Quad, 1).unwrap()
        );
        // A uniform pattern's parameters are read back from it.
        let grid = RefinementPattern::generate(Domain::Quad, 7).unwrap();
        assert_eq!(
            LevelParameters::of_pattern(&grid, 7),
            Some(LevelParameters::generated(7))
        );
        assert_eq!(LevelParameters::of_pattern(&grid, 6), None);
        for (outer, inner) in [
            ([2, 1, 1, 1], [1, 1]),
            ([1, 1, 1, 1], [0, 1]),
            ([300, 1, 1, 1], [2, 2]),
        ] {
            assert!(
                RefinementPattern::generate_edges(outer, inner, &generated).is_err(),
                "{outer:?} {inner:?}"
            );
        }
    }

    /// Per-edge triangle patterns (a Gregory triangle's host-chosen levels): counter-clockwise,
    /// tiling the triangle, each edge at its own level with w exactly 0 on the w = 0 edge.
    #[test]
    fn per_edge_triangle_patterns_tile_the_triangle_with_each_edge_at_its_level() {
        for (outer, inner) in [
            ([4, 8, 2], 8),
            ([1, 2, 1], 2),
            ([1, 1, 2], 2),
            ([3, 3, 1], 3),
            ([16, 64, 32], 64),
            ([5, 5, 5], 5),
        ] {
            let p = RefinementPattern::generate_triangle_edges(outer, inner).unwrap();
            let mut area = 0.0;
            for &t in &p.triangles {
                let a = signed_area(&p, t);
                assert!(
                    a > 0.0,
                    "{outer:?} {inner}: {t:?} turns clockwise or is degenerate"
                );
                area += a / 2.0;
            }
            assert!((area - 0.5).abs() < 1e-9, "{outer:?} {inner}: area {area}");
            for (e, &n) in outer.iter().enumerate() {
                let on = p.points.iter().filter(|q| q[[0, 1, 2][e]] == 0.0).count();
                assert_eq!(on as u32, n + 1, "{outer:?} {inner}: edge {e}");
            }
            for q in &p.points {
                assert_eq!(q[0] + q[1] + q[2], 1.0, "{q:?}");
            }
        }
        assert_eq!(
            RefinementPattern::generate_triangle_edges([6; 3], 6).unwrap(),
            RefinementPattern::generate(Domain::Triangle, 6).unwrap()
        );
        assert!(RefinementPattern::generate_triangle_edges([0, 1, 1], 1).is_err());
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
