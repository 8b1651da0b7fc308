//! Gregory end caps for Catmull-Clark (Loop, Schaefer, Ni, Castaño 2009, "Approximating
//! subdivision surfaces with Gregory patches for hardware tessellation"): the 20 control points
//! of a quad that is still irregular at the last isolation level, as stencils over that level's
//! vertices, and the rational basis that evaluates them.
//!
//! # Control points and their order
//!
//! Face corners `i = 0..3` follow the face's vertex order: corner 0 at `(u,v) = (0,0)`, 1 at
//! `(1,0)`, 2 at `(1,1)`, 3 at `(0,1)` (the domain of [`crate::limit::basis`]). Each corner owns five
//! points, slot `5·i + s`:
//!
//! | s | name   | meaning                                                               |
//! |---|--------|-----------------------------------------------------------------------|
//! | 0 | `P_i`  | limit position of the corner vertex                                   |
//! | 1 | `Ep_i` | edge point on the edge toward corner `i+1`: `P_i + T_i(i+1) / 3`       |
//! | 2 | `Em_i` | edge point on the edge toward corner `i−1`: `P_i + T_i(i−1) / 3`       |
//! | 3 | `Fp_i` | interior (face) point paired with `Ep_i`                              |
//! | 4 | `Fm_i` | interior (face) point paired with `Em_i`                              |
//!
//! `T_i(w)` is the limit tangent of the corner vertex toward its edge-neighbour `w`, scaled as a
//! parametric derivative (exactly the B-spline derivative at a regular vertex):
//! * smooth vertex (also a dart) of valence `n`:
//!   [`smooth_directional_tangent`](crate::limit::masks::smooth_directional_tangent) (Halstead's
//!   eigenvector masks rotated onto edge `k`, `1/(3n)` of the mask);
//! * crease (two sharp edges, boundary edges count), sector of `m` faces between the sharp
//!   edges `a` and `b` (CCW, the face inside): `T(k) = cos θ·T_along + sin θ·T_across`,
//!   `θ = π·(k−a)/m`, with `T_along = (e_a − e_b)/2` and the cross tangent of
//!   [`catmark_limit_masks`](crate::limit::masks::catmark_limit_masks); along the sharp edges
//!   themselves `T = ±T_along` exactly;
//! * corner (sharp vertex or more than two sharp edges), sector of `m` faces between sharp
//!   edges `a` and `b`: the vertex stays, `T(a) = e_a − v`, `T(b) = e_b − v`, interior edges
//!   `T(k) = sin((m−t)φ)·T(a) + sin(tφ)·T(b)`, `t = k−a`, `φ = π/(2m)`.
//!
//! Each of `P`, `Ep`, `Em` depends only on the vertex's one-ring and the edge, never on the
//! face asking, and is accumulated in the same order for every face: two patches sharing an
//! edge get bit-identical stencils for the boundary curve `P_i, Ep_i, Em_{i+1}, P_{i+1}`
//! (watertight end caps).
//!
//! Face points (Loop et al.'s formula; `c` = cosine of the corner's characteristic angle per
//! face: `cos(2π/n)` smooth, `cos(π/m)` crease sector, `cos(π/(2m))` corner sector, 0 where
//! the vertex is regular). For `Fp_i` on the edge from `v_i` to `v_{i+1}`, with `x_in`/`x_out`
//! the edge-neighbours of `v_i` next to that edge inside/outside the face and `d_in`/`d_out`
//! the diagonal vertices of the two faces on the edge:
//!
//! ```text
//! Fp_i = c_{i+1}/3 · P_i + (3 − 2c_i − c_{i+1})/3 · Ep_i + 2c_i/3 · Em_{i+1}
//!        + (x_in − x_out)/9 + (d_in − d_out)/18
//! ```
//!
//! and symmetrically `Fm_i` with `Em_i`, `Ep_{i−1}`, `c_{i−1}`. Where both corners of the edge
//! are regular (valence-4 smooth, crease sector of 2 faces, corner sector of 1 face) the point
//! is the B-spline's Bézier interior point `(4v_i + 2v_{i+1} + 2v_{i−1} + v_{i+2})/9`, so
//! regular, boundary and corner patches are exactly their bicubic B-splines. On a sharp edge
//! (no continuity to keep across it) the face point copies the corner's other face point
//! (the face mask if both edges are sharp).
//!
//! # Evaluation ([`gregory_weights`]), written to be ported line by line
//!
//! Cubic Bernstein `B0 = (1−t)³, B1 = 3t(1−t)², B2 = 3t²(1−t), B3 = t³` and derivatives
//! `B0' = −3(1−t)², B1' = 3(1−t)(1−3t), B2' = 3t(2−3t), B3' = 3t²`. The patch is the bicubic
//! Bézier `Σ Bj(u)·Bk(v)·b[j][k]` (`j` along `u`) with
//!
//! ```text
//! b00 = P0   b10 = Ep0  b01 = Em0     b30 = P1   b31 = Ep1  b20 = Em1
//! b33 = P2   b23 = Ep2  b32 = Em2     b03 = P3   b02 = Ep3  b13 = Em3
//! b11 = gp0·Fp0 + gm0·Fm0   b21 = gp1·Fp1 + gm1·Fm1
//! b22 = gp2·Fp2 + gm2·Fm2   b12 = gp3·Fp3 + gm3·Fm3
//! ```
//!
//! At corner `i`, `dp` is the distance to the edge holding `Ep_i` and `dm` to the edge holding
//! `Em_i`; `Fp_i` is weighted by `dm`, so it alone counts on its own edge:
//!
//! ```text
//! corner 0: dp = v,    dm = u      gp0 = u/(u+v)            gm0 = v/(u+v)
//! corner 1: dp = 1−u,  dm = v      gp1 = v/(1−u+v)          gm1 = (1−u)/(1−u+v)
//! corner 2: dp = 1−v,  dm = 1−u    gp2 = (1−u)/(2−u−v)      gm2 = (1−v)/(2−u−v)
//! corner 3: dp = u,    dm = 1−v    gp3 = (1−v)/(1+u−v)      gm3 = u/(1+u−v)
//! gp = dm/D, gm = dp/D, D = dp + dm; where D = 0 (the corner itself) gp = gm = 1/2.
//! ```
//!
//! Derivatives are exact (quotient rule, not the Bézier approximation): with `B = Bj(u)Bk(v)`
//! the interior point's Bernstein product, `∂gp/∂t = (dp·∂dm/∂t − dm·∂dp/∂t)/D²` and
//! `∂gm/∂t = −∂gp/∂t`. The product `B·∂gp/∂t` stays bounded at the corner because
//! `B = 9·dp·dm·h` (`h = (1−u)²(1−v)²`, `u²(1−v)²`, `u²v²`, `(1−u)²v²` at corners 0..3), so the
//! code computes it as `9·h·gp·gm·(dp·∂dm/∂t − dm·∂dp/∂t)` — no division by a vanishing `D²`,
//! no NaN anywhere on `[0,1]²`:
//!
//! ```text
//! w(Fp) = B·gp                 w(Fm) = B·gm
//! ∂w(Fp)/∂t = ∂B/∂t·gp + G_t   ∂w(Fm)/∂t = ∂B/∂t·gm − G_t
//! G_t = 9·h·gp·gm·(dp·∂dm/∂t − dm·∂dp/∂t)
//! ```
//!
//! # Not exact / not handled
//! * Tangent magnitudes at extraordinary vertices are a choice (the directional masks'); the
//!   tangent *plane* is exact for smooth and crease vertices. At a corner vertex whose sector
//!   has 3 or more faces the interior edges' tangent directions are interpolated between the
//!   two sharp edges (in the exact tangent plane, direction approximate). A sharp vertex with
//!   fewer than two sharp edges (a cone) and an interior vertex of valence 2 get the edge
//!   vectors `e_k − v` as tangents and `c = 0`.
//! * Semi-sharp edges and vertices are treated as infinitely sharp (this is the last level).
//! * Every face around each of the four corners must be a quad (true from level 1 on).

use crate::error::{GregoryProblem, TopologyError};
use crate::limit::basis::PatchWeights;
use crate::limit::masks::{
    catmark_cross_tangent_into, catmark_directional_tangent_each,
    catmark_directional_tangent_table, catmark_smooth_position_weights, dart_position_weights,
};
use crate::mesh::{Topology, INVALID};
use crate::refine::stencil::Stencil;
use crate::refine::LevelRef;
use crate::rules::options::SubdivOptions;
use crate::rules::{
    boundary_edge_sharpness, boundary_vertex_sharpness, is_sharp, vertex_rule, Rule,
};

use smallvec::SmallVec;
use std::f64::consts::PI;

/// Sparse row under construction. Entries keep their first-insertion order until
/// [`Row::into_stencil`], so equal inputs built in the same order give bit-equal sums.
#[derive(Clone, Debug, Default)]
struct Row(SmallVec<[(u32, f64); 24]>);

impl Row {
    fn add(&mut self, i: u32, w: f64) {
        match self.0.iter_mut().find(|e| e.0 == i) {
            Some(e) => e.1 += w,
            None => self.0.push((i, w)),
        }
    }

    fn add_row(&mut self, r: &Row, s: f64) {
        for &(i, w) in &r.0 {
            self.add(i, s * w);
        }
    }

    /// Zero weights dropped, indices ascending: the form of a [`Stencil`].
    fn finished(mut self) -> Row {
        self.0.retain(|e| e.1 != 0.0);
        self.0.sort_by_key(|e| e.0);
        self
    }

    fn into_stencil(self) -> Stencil {
        let r = self.finished();
        Stencil {
            indices: r.0.iter().map(|e| e.0).collect(),
            weights: r.0.iter().map(|e| e.1).collect(),
        }
    }
}

/// Ordered one-ring of a vertex: `faces[i] = (face, corner of v in it)`, `ring[i]` the vertex
/// after `v` in face `i` (plus the last neighbour of a boundary fan), `edges[i]` the edge to
/// `ring[i]`. Starts at the face whose leaving edge is a boundary edge, else at the first face
/// the topology lists, so the order is a property of the vertex alone.
pub(crate) struct Fan {
    pub(crate) faces: SmallVec<[(u32, usize); 8]>,
    pub(crate) ring: SmallVec<[u32; 9]>,
    pub(crate) edges: SmallVec<[u32; 9]>,
    pub(crate) boundary: bool,
}

pub(crate) fn build_fan(t: &Topology, v: u32) -> Option<Fan> {
    // The face and edge tables read directly: this runs for every corner of every end cap.
    let (offsets, face_verts, face_edges) = (&t.face_offsets, &t.face_verts, &t.face_edges);
    let span = |g: u32| offsets[g as usize] as usize..offsets[g as usize + 1] as usize;
    let boundary_edge = |e: u32| t.edge_faces[e as usize][1] == INVALID;
    let vf = t.vertex_faces(v as usize);
    let corner = |g: u32| face_verts[span(g)].iter().position(|&x| x == v);
    let leaving_boundary = |g: u32| -> Option<bool> {
        let c = corner(g)?;
        Some(boundary_edge(*face_edges[span(g)].get(c)?))
    };
    let mut start = *vf.first()?;
    let mut boundary = false;
    for &g in vf {
        if leaving_boundary(g)? {
            (start, boundary) = (g, true);
            break;
        }
    }
    let mut fan = Fan {
        faces: SmallVec::with_capacity(vf.len()),
        ring: SmallVec::with_capacity(vf.len() + 1),
        edges: SmallVec::with_capacity(vf.len() + 1),
        boundary,
    };
    let mut g = start;
    loop {
        let fv = &face_verts[span(g)];
        let fe = &face_edges[span(g)];
        let c = fv.iter().position(|&x| x == v)?;
        let n = fv.len();
        fan.faces.push((g, c));
        fan.ring.push(fv[(c + 1) % n]);
        fan.edges.push(fe[c]);
        let entering = fe[(c + n - 1) % n];
        let [a, b] = t.edge_faces[entering as usize];
        let h = if a == g { b } else { a };
        if boundary_edge(entering) {
            fan.ring.push(fv[(c + n - 1) % n]);
            fan.edges.push(entering);
            break;
        }
        if h == start || fan.faces.len() > vf.len() {
            break;
        }
        g = h;
    }
    (fan.faces.len() == vf.len()).then_some(fan)
}

/// The limit rule of a corner vertex as seen from the face (sector of the face for creases
/// and corners).
#[derive(Clone, Copy, Debug, Default, PartialEq)]
enum Kind {
    #[default]
    Smooth,
    /// Sharp edges `a`, `b` (ring indices) bound the face's sector of `m` faces, CCW a → b.
    Crease {
        a: usize,
        b: usize,
        m: usize,
    },
    Corner {
        a: usize,
        b: usize,
        m: usize,
    },
    /// Sharp vertex without a sector, or interior valence 2: edge vectors as tangents.
    Cone,
}

/// One corner of the patch: its vertex's rule and limit constants, with the vertex, its ring
/// and the diagonal of each fan face (level vertex ids from [`build_corner`], then slots of the
/// cap's [`CapRows`]).
#[derive(Default)]
struct Corner {
    /// Position of the patch face in the fan.
    j: usize,
    boundary: bool,
    sharp: SmallVec<[bool; 9]>,
    kind: Kind,
    regular: bool,
    c: f64,
    /// The vertex, its `n` ring neighbours, the diagonals of its `nf` fan faces.
    verts: SmallVec<[usize; 20]>,
    n: usize,
    nf: usize,
}

/// The cap's rows, dense over its vertices (ascending): row `r` is `w[r·l..(r+1)·l]`.
///
/// Each row receives the same additions in the same order as a sparse [`Row`] would, one per
/// slot per `add_row` (a slot a source lacks adds `s·0`, which changes no nonzero sum), so
/// after dropping zeros the sums are bit-equal; no lookups, no copies of sparse rows.
struct CapRows<'a> {
    l: usize,
    w: &'a mut [f64],
}

/// Rows 0..20 are the points (`5·corner + {P, Ep, Em, Fp, Fm}`), then each corner's cross
/// tangent (crease sectors) and two scratch rows.
const ACROSS: usize = 20;
const TANGENT: usize = 24;
const SCRATCH: usize = 25;
const CAP_ROWS: usize = 26;

/// Rows up to this many slots live on the stack.
const CAP_SLOTS: usize = 32;

impl CapRows<'_> {
    fn row(&self, r: usize) -> &[f64] {
        &self.w[r * self.l..(r + 1) * self.l]
    }

    fn clear(&mut self, r: usize) {
        let l = self.l;
        self.w[r * l..(r + 1) * l].fill(0.0);
    }

    fn add(&mut self, r: usize, slot: usize, w: f64) {
        self.w[r * self.l + slot] += w;
    }

    /// Rows `dst` and `src` (distinct) as one mutable and one shared slice.
    fn pair(&mut self, dst: usize, src: usize) -> (&mut [f64], &[f64]) {
        let l = self.l;
        if dst < src {
            let (a, b) = self.w.split_at_mut(src * l);
            (&mut a[dst * l..(dst + 1) * l], &b[..l])
        } else {
            let (a, b) = self.w.split_at_mut(dst * l);
            (&mut b[..l], &a[src * l..(src + 1) * l])
        }
    }

    fn copy(&mut self, dst: usize, src: usize) {
        let (d, s) = self.pair(dst, src);
        d.copy_from_slice(s);
    }

    fn add_row(&mut self, dst: usize, src: usize, s: f64) {
        let (d, r) = self.pair(dst, src);
        for (d, &r) in d.iter_mut().zip(r) {
            *d += s * r;
        }
    }

    /// Row `dst` (distinct from the sources) as one mutable slice and the rows before and
    /// after it.
    fn split(&mut self, dst: usize) -> (&[f64], &mut [f64], &[f64]) {
        let l = self.l;
        let (before, rest) = self.w.split_at_mut(dst * l);
        let (d, after) = rest.split_at_mut(l);
        (before, d, after)
    }

    /// `dst = src + s·add` in one pass: what copying `src` and then adding `s·add` gives.
    fn copy_add(&mut self, dst: usize, src: usize, add: usize, s: f64) {
        let l = self.l;
        let (before, d, after) = self.split(dst);
        let (p, t) = (
            other_row(before, after, dst, src, l),
            other_row(before, after, dst, add, l),
        );
        let (p, t) = (&p[..d.len()], &t[..d.len()]);
        for k in 0..d.len() {
            d[k] = p[k] + s * t[k];
        }
    }

    /// `dst = a·ra + b·rb + c·rc` in one pass: what adding the three scaled rows to a cleared
    /// `dst` in that order gives (`0 + x` is `x`; a zero's sign is dropped with it).
    fn combine3(&mut self, dst: usize, [(ra, a), (rb, b), (rc, c)]: [(usize, f64); 3]) {
        let l = self.l;
        let (before, d, after) = self.split(dst);
        let x = &other_row(before, after, dst, ra, l)[..d.len()];
        let y = &other_row(before, after, dst, rb, l)[..d.len()];
        let z = &other_row(before, after, dst, rc, l)[..d.len()];
        for k in 0..d.len() {
            d[k] = a * x[k] + b * y[k] + c * z[k];
        }
    }
}

/// Row `r` (not `dst`) of the rows split around `dst` by [`CapRows::split`].
fn other_row<'a>(before: &'a [f64], after: &'a [f64], dst: usize, r: usize, l: usize) -> &'a [f64] {
    if r < dst {
        &before[r * l..(r + 1) * l]
    } else {
        &after[(r - dst - 1) * l..(r - dst) * l]
    }
}

impl Corner {
    fn n(&self) -> usize {
        self.n
    }

    fn v(&self) -> usize {
        self.verts[0]
    }

    fn ring(&self, k: usize) -> usize {
        self.verts[1 + k]
    }

    /// Diagonal vertex of fan face `i` (wrapping, as a boundary ring has one more entry:
    /// `i ≤ nf`, so one subtraction instead of a division).
    fn diag(&self, i: usize) -> usize {
        let i = if i >= self.nf { i - self.nf } else { i };
        self.verts[1 + self.n + i]
    }

    /// `e_k − v` into the cleared row `r`.
    fn edge_vector(&self, rows: &mut CapRows<'_>, r: usize, k: usize) {
        rows.add(r, self.ring(k), 1.0);
        rows.add(r, self.v(), -1.0);
    }

    /// Crease tangent along the sharp edges, toward `toward` (one of the two ends), built in
    /// ascending ring order so both sectors produce the same row; into the cleared row `r`.
    fn along(&self, rows: &mut CapRows<'_>, r: usize, a: usize, b: usize, toward: usize) {
        let (lo, hi) = (a.min(b), a.max(b));
        rows.add(r, self.ring(lo), if toward == lo { 0.5 } else { -0.5 });
        rows.add(r, self.ring(hi), if toward == hi { 0.5 } else { -0.5 });
    }

    /// The limit position into row `5·i` and, for a crease, the cross tangent into
    /// `ACROSS + i` (rows cleared).
    fn limit_rows(&self, rows: &mut CapRows<'_>, i: usize) {
        let p = 5 * i;
        let n = self.n();
        rows.clear(p);
        match self.kind {
            Kind::Smooth if self.sharp.iter().filter(|&&x| x).count() == 1 && !self.boundary => {
                // A dart: the smooth tangents, but its own limit position.
                // `catmark_limit_masks`' dart position, added as `mask_row` would (vertex,
                // edges, faces in ring order), without its tangent masks.
                let edge = self.sharp.iter().position(|&x| x).unwrap_or(0);
                let w = dart_position_weights(false, n);
                rows.add(p, self.v(), w[0]);
                for k in 0..n {
                    rows.add(p, self.ring(k), w[1 + (k + n - edge) % n]);
                }
                for k in 0..n.min(self.nf) {
                    rows.add(p, self.diag(k), w[1 + n + (k + n - edge) % n]);
                }
            }
            Kind::Smooth => {
                // Only the position: the tangents come from `Corner::tangent`.
                let [vw, ew, fw] = catmark_smooth_position_weights(n);
                rows.add(p, self.v(), vw);
                for &x in &self.verts[1..1 + n] {
                    rows.add(p, x, ew);
                }
                for &d in &self.verts[1 + n..] {
                    rows.add(p, d, fw);
                }
            }
            Kind::Crease { a, b, .. } => {
                // `catmark_limit_masks`' crease position and cross tangent, added as
                // `mask_row` would (vertex, edges, faces; zero weights change no sum).
                rows.add(p, self.v(), 2.0 / 3.0);
                rows.add(p, self.ring(a.min(b)), 1.0 / 6.0);
                rows.add(p, self.ring(a.max(b)), 1.0 / 6.0);
                let nf = if self.boundary {
                    n.saturating_sub(1)
                } else {
                    n
                };
                let mut edges: SmallVec<[f64; 16]> = SmallVec::from_elem(0.0, n);
                let mut faces: SmallVec<[f64; 16]> = SmallVec::from_elem(0.0, nf);
                let vertex = catmark_cross_tangent_into(&mut edges, &mut faces, [a, b], n);
                let r = ACROSS + i;
                rows.clear(r);
                rows.add(r, self.v(), vertex);
                for (k, &w) in edges.iter().enumerate() {
                    if w != 0.0 {
                        rows.add(r, self.ring(k), w);
                    }
                }
                for (k, &w) in faces.iter().enumerate().take(self.nf) {
                    if w != 0.0 {
                        rows.add(r, self.diag(k), w);
                    }
                }
            }
            Kind::Corner { .. } | Kind::Cone => rows.add(p, self.v(), 1.0),
        }
    }

    /// Parametric limit tangent toward ring neighbour `k` (see the module docs) of corner `i`,
    /// into row [`TANGENT`] (cleared here; [`SCRATCH`] is used too).
    fn tangent(&self, rows: &mut CapRows<'_>, i: usize, k: usize) {
        let n = self.n();
        let r = TANGENT;
        rows.clear(r);
        match self.kind {
            Kind::Smooth => {
                // Edge weights first, then face weights, as the rows were always summed.
                let l = rows.l;
                let t = &mut rows.w[r * l..(r + 1) * l];
                if let Some(table) = catmark_directional_tangent_table(n, k) {
                    for (&x, &(e, _)) in self.verts[1..].iter().zip(table) {
                        t[x] += e;
                    }
                    for (i, &(_, f)) in table.iter().enumerate() {
                        t[self.diag(i)] += f;
                    }
                    return;
                }
                let mut fw: SmallVec<[f64; 16]> = SmallVec::new();
                catmark_directional_tangent_each(n, k, |i, e, f| {
                    t[self.ring(i)] += e;
                    fw.push(f);
                });
                for (i, &w) in fw.iter().enumerate() {
                    t[self.diag(i)] += w;
                }
            }
            Kind::Crease { a, b, m } => {
                if k == a || k == b {
                    return self.along(rows, r, a, b, k);
                }
                let s = (k + n - a) % n;
                if 2 * s == m {
                    return rows.copy(r, ACROSS + i);
                }
                rows.clear(SCRATCH);
                self.along(rows, SCRATCH, a, b, a);
                let th = PI * s as f64 / m as f64;
                rows.add_row(r, SCRATCH, th.cos());
                rows.add_row(r, ACROSS + i, th.sin());
            }
            Kind::Corner { a, b, m } => {
                if k == a || k == b {
                    return self.edge_vector(rows, r, k);
                }
                let s = (k + n - a) % n;
                let phi = PI / (2.0 * m as f64);
                rows.clear(SCRATCH);
                self.edge_vector(rows, SCRATCH, a);
                rows.add_row(r, SCRATCH, ((m - s) as f64 * phi).sin());
                rows.clear(SCRATCH);
                self.edge_vector(rows, SCRATCH, b);
                rows.add_row(r, SCRATCH, (s as f64 * phi).sin());
            }
            Kind::Cone => self.edge_vector(rows, r, k),
        }
    }
}

/// Sharpness of edge `e` at the last level: boundary edges are infinitely sharp.
fn edge_sharp(level: &LevelRef<'_>, e: u32) -> f32 {
    if level.topology.is_boundary_edge(e as usize) {
        boundary_edge_sharpness()
    } else {
        level.edge_sharpness[e as usize]
    }
}

/// The sector of fan face `j` between the nearest sharp edges (ring indices) before and after
/// it, CCW; `None` with fewer than two sharp edges.
fn sector(sharp: &[bool], j: usize, boundary: bool) -> Option<(usize, usize, usize)> {
    let n = sharp.len();
    if sharp.iter().filter(|&&s| s).count() < 2 {
        return None;
    }
    let a = (0..n).map(|d| (j + n - d) % n).find(|&k| sharp[k])?;
    let b = (0..n).map(|d| (j + 1 + d) % n).find(|&k| sharp[k])?;
    let m = if boundary { b - a } else { (b + n - a) % n };
    (m > 0).then_some((a, b, m))
}

/// The fan of `v` as [`build_fan`] orders it, straight into `out` (`verts`: the vertex, its
/// ring, the diagonals; `sharp`: the edges' sharpness), its position `j` of `face` and whether
/// it is a boundary fan. `None` where the ring is not one complete fan of quads containing
/// `face` (then [`build_corner`] takes [`build_fan`]'s way, which says why).
fn walk_fan(level: &LevelRef<'_>, face: usize, v: u32, out: &mut Corner) -> Option<(usize, bool)> {
    let t = level.topology;
    let (offsets, face_verts, face_edges) = (&t.face_offsets, &t.face_verts, &t.face_edges);
    let quad = |g: u32| -> Option<(&[u32], &[u32], usize)> {
        let (s, e) = (
            offsets[g as usize] as usize,
            offsets[g as usize + 1] as usize,
        );
        let fv: &[u32; 4] = face_verts.get(s..e)?.try_into().ok()?;
        let fe: &[u32; 4] = face_edges.get(s..e)?.try_into().ok()?;
        let c = fv.iter().position(|&x| x == v)?;
        Some((fv, fe, c))
    };
    let boundary_edge = |e: u32| t.edge_faces[e as usize][1] == INVALID;
    let vf = t.vertex_faces(v as usize);
    let nf = vf.len();
    let mut start = *vf.first()?;
    let mut boundary = false;
    for &g in vf {
        let (_, fe, c) = quad(g)?;
        if boundary_edge(fe[c]) {
            (start, boundary) = (g, true);
            break;
        }
    }
    let n = nf + boundary as usize;
    // Sized from zeroed inline buffers where they fit (`resize` costs more).
    let len = 1 + n + nf;
    if len <= 20 {
        out.verts = SmallVec::from_buf_and_len([0; 20], len);
    } else {
        out.verts.clear();
        out.verts.resize(len, 0);
    }
    out.verts[0] = v as usize;
    if n <= 9 {
        out.sharp = SmallVec::from_buf_and_len([false; 9], n);
    } else {
        out.sharp.clear();
        out.sharp.resize(n, false);
    }
    let (ring, diag) = out.verts[1..].split_at_mut(n);
    let mut j = None;
    let mut g = start;
    for i in 0..nf {
        let (fv, fe, c) = quad(g)?;
        if j.is_none() && g as usize == face {
            j = Some(i);
        }
        ring[i] = fv[(c + 1) % 4] as usize;
        diag[i] = fv[(c + 2) % 4] as usize;
        out.sharp[i] = is_sharp(edge_sharp(level, fe[c]));
        let entering = fe[(c + 3) % 4];
        if boundary_edge(entering) {
            // Only the last face of a boundary fan may end it.
            if !boundary || i + 1 != nf {
                return None;
            }
            ring[nf] = fv[(c + 3) % 4] as usize;
            out.sharp[nf] = is_sharp(edge_sharp(level, entering));
            return Some((j?, true));
        }
        let [x, y] = t.edge_faces[entering as usize];
        let h = if x == g { y } else { x };
        if h == start {
            return (!boundary && i + 1 == nf).then_some((j?, false));
        }
        g = h;
    }
    None
}

/// Corner `v` of `face` into `out` (its vectors reused).
fn build_corner(
    level: &LevelRef<'_>,
    options: &SubdivOptions,
    face: usize,
    v: u32,
    out: &mut Corner,
) -> Result<(), TopologyError> {
    let t = level.topology;
    let (j, boundary) = match walk_fan(level, face, v, out) {
        Some(fan) => fan,
        None => build_corner_fan(level, face, v, out)?,
    };
    let n = out.verts.len() - 1 - t.vertex_faces(v as usize).len();
    let sharp = &out.sharp;
    let mut vs = level.vertex_sharpness[v as usize];
    if let Some(s) = boundary_vertex_sharpness(
        options.boundary,
        t.vertex_faces(v as usize).len(),
        t.vertex_edges(v as usize).len(),
    ) {
        vs = vs.max(s);
    }
    let sharp_count = sharp.iter().filter(|&&s| s).count();
    let kind = match vertex_rule(vs, sharp_count) {
        Rule::Smooth | Rule::Dart if n >= 3 => Kind::Smooth,
        Rule::Smooth | Rule::Dart => Kind::Cone,
        Rule::Crease => match sector(sharp, j, boundary) {
            Some((a, b, m)) => Kind::Crease { a, b, m },
            None => Kind::Cone,
        },
        Rule::Corner => match sector(sharp, j, boundary) {
            Some((a, b, m)) => Kind::Corner { a, b, m },
            None => Kind::Cone,
        },
    };
    let (regular, c) = match kind {
        Kind::Smooth => (
            n == 4 && sharp_count == 0,
            if n == 4 {
                0.0
            } else {
                (2.0 * PI / n as f64).cos()
            },
        ),
        Kind::Crease { m, .. } => (m == 2, if m == 2 { 0.0 } else { (PI / m as f64).cos() }),
        Kind::Corner { m, .. } => (
            m == 1,
            if m == 1 {
                0.0
            } else {
                (PI / (2.0 * m as f64)).cos()
            },
        ),
        Kind::Cone => (false, 0.0),
    };
    out.j = j;
    out.boundary = boundary;
    out.kind = kind;
    out.regular = regular;
    out.c = c;
    out.n = n;
    out.nf = out.verts.len() - 1 - n;
    Ok(())
}

/// [`walk_fan`] through [`build_fan`], for the rings it leaves (the errors come from here).
fn build_corner_fan(
    level: &LevelRef<'_>,
    face: usize,
    v: u32,
    out: &mut Corner,
) -> Result<(usize, bool), TopologyError> {
    let t = level.topology;
    let problem = |problem| TopologyError::GregoryPatch { face, problem };
    let fan =
        build_fan(t, v).ok_or_else(|| problem(GregoryProblem::IncompleteRing { vertex: v }))?;
    if fan
        .faces
        .iter()
        .any(|&(g, _)| t.face_vertices(g as usize).len() != 4)
    {
        return Err(problem(GregoryProblem::NonQuadRing { vertex: v }));
    }
    let j = fan
        .faces
        .iter()
        .position(|&(g, _)| g as usize == face)
        .ok_or_else(|| problem(GregoryProblem::IncompleteRing { vertex: v }))?;
    out.sharp.clear();
    out.sharp
        .extend(fan.edges.iter().map(|&e| is_sharp(edge_sharp(level, e))));
    out.verts.clear();
    out.verts.push(v as usize);
    out.verts.extend(fan.ring.iter().map(|&x| x as usize));
    for &(g, c) in &fan.faces {
        out.verts
            .push(t.face_vertices(g as usize)[(c + 2) % 4] as usize);
    }
    Ok((j, fan.boundary))
}

/// The Bézier interior point of a regular patch, `(4v_i + 2v_{i+1} + 2v_{i−1} + v_{i+2})/9`,
/// into row `r` (`fv`: the corners' slots).
fn face_mask(rows: &mut CapRows<'_>, r: usize, fv: [usize; 4], i: usize) {
    rows.clear(r);
    rows.add(r, fv[i], 4.0 / 9.0);
    rows.add(r, fv[(i + 1) % 4], 2.0 / 9.0);
    rows.add(r, fv[(i + 3) % 4], 2.0 / 9.0);
    rows.add(r, fv[(i + 2) % 4], 1.0 / 9.0);
}

/// Face point `Fp_i` (`plus`) or `Fm_i` into its row, from the finished `P`, `Ep` and `Em`
/// rows.
fn face_point(rows: &mut CapRows<'_>, corners: &[Corner], i: usize, plus: bool) {
    let dst = 5 * i + if plus { 3 } else { 4 };
    let fv = [
        corners[0].v(),
        corners[1].v(),
        corners[2].v(),
        corners[3].v(),
    ];
    let near = &corners[i];
    let n = near.n();
    let j = near.j;
    let (k, other, far_i) = if plus {
        (j, (j + 1) % n, (i + 1) % 4)
    } else {
        ((j + 1) % n, j, (i + 3) % 4)
    };
    let far = &corners[far_i];
    if near.regular && far.regular {
        return face_mask(rows, dst, fv, i);
    }
    let formula = |rows: &mut CapRows<'_>, k: usize, far_i: usize, plus: bool| {
        let far = &corners[far_i];
        let (e_near, e_far) = if plus {
            (5 * i + 1, 5 * far_i + 2)
        } else {
            (5 * i + 2, 5 * far_i + 1)
        };
        let (cn, cf) = (near.c, far.c);
        rows.combine3(
            dst,
            [
                (5 * i, cf / 3.0),
                (e_near, (3.0 - 2.0 * cn - cf) / 3.0),
                (e_far, 2.0 * cn / 3.0),
            ],
        );
        // Ring neighbours and diagonals on either side of edge k (inside: our face j).
        let (x_in, x_out, d_out) = if plus {
            (
                near.ring((k + 1) % n),
                near.ring((k + n - 1) % n),
                (k + n - 1) % n,
            )
        } else {
            (near.ring((k + n - 1) % n), near.ring((k + 1) % n), k)
        };
        rows.add(dst, x_in, 1.0 / 9.0);
        rows.add(dst, x_out, -1.0 / 9.0);
        rows.add(dst, near.diag(j), 1.0 / 18.0);
        rows.add(dst, near.diag(d_out), -1.0 / 18.0);
    };
    if !near.sharp[k] {
        return formula(rows, k, far_i, plus);
    }
    // Sharp edge: nothing to match across it; take the corner's other face point.
    if near.sharp[other] {
        return face_mask(rows, dst, fv, i);
    }
    let other_far = if plus { (i + 3) % 4 } else { (i + 1) % 4 };
    if near.regular && corners[other_far].regular {
        return face_mask(rows, dst, fv, i);
    }
    formula(rows, other, other_far, !plus)
}

/// The 20 Gregory control points of quad `face` of `level` as stencils over the level's vertex
/// indices, in the order of the module docs (`5·corner + {P, Ep, Em, Fp, Fm}`).
///
/// The face needs its complete one-ring in `level` (every face around each of its corners, all
/// quads), which [`crate::refine::refine_sparse`] guarantees for the children of selected faces.
/// Semi-sharp creases are treated as infinitely sharp: this is meant for the last level.
///
/// ```
/// use topology::patches::gregory::{gregory_basis, gregory_weights};
/// use topology::refine::refine_uniform;
/// use topology::{ControlMesh, Scheme};
/// let mesh = ControlMesh::from_polygons(
///     vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
///     &[[0u32, 1, 2, 3]],
/// );
/// let r = refine_uniform(&mesh, Scheme::CatmullClark, 1).unwrap();
/// let level = r.level(1);
/// let cps = gregory_basis(level.view(), 0, &mesh.options).unwrap();
/// let w = gregory_weights(0.5, 0.5);
/// let p: f64 = (0..20).map(|i| w.point[i] * cps[i].apply(&level.positions)[2]).sum();
/// assert!(p.abs() < 1e-12);
/// ```
pub fn gregory_basis(
    level: LevelRef<'_>,
    face: usize,
    options: &SubdivOptions,
) -> Result<[Stencil; 20], TopologyError> {
    let mut out: [Stencil; 20] = Default::default();
    gregory_basis_each(level, face, options, |k, terms| {
        out[k] = Stencil {
            indices: terms.iter().map(|e| e.0).collect(),
            weights: terms.iter().map(|e| e.1).collect(),
        };
    })?;
    Ok(out)
}

/// [`gregory_basis`] handing each point `k` to `each(k, terms)` as sorted `(index, weight)`
/// terms instead of allocating 20 stencils (the adaptive plan builds thousands of end caps).
pub(crate) fn gregory_basis_each(
    level: LevelRef<'_>,
    face: usize,
    options: &SubdivOptions,
    mut each: impl FnMut(usize, &[(u32, f64)]),
) -> Result<(), TopologyError> {
    let t = level.topology;
    if face >= t.num_faces() {
        return Err(TopologyError::FaceOutOfRange {
            face,
            count: t.num_faces(),
        });
    }
    if level.edge_sharpness.len() != t.num_edges()
        || level.vertex_sharpness.len() != t.num_vertices()
    {
        return Err(TopologyError::GregoryPatch {
            face,
            problem: GregoryProblem::SharpnessLength,
        });
    }
    let fv = t.face_vertices(face);
    if fv.len() != 4 {
        return Err(TopologyError::GregoryPatch {
            face,
            problem: GregoryProblem::NotQuad { size: fv.len() },
        });
    }
    let mut corners: [Corner; 4] = Default::default();
    for (c, &v) in corners.iter_mut().zip(fv) {
        build_corner(&level, options, face, v, c)?;
    }
    // The cap's vertices become slots of its dense rows, numbered as first seen through a
    // small open-addressing table.
    let refs: usize = corners.iter().map(|c| c.verts.len()).sum();
    let bits = (2 * refs).next_power_of_two().max(64).trailing_zeros();
    let mask = (1usize << bits) - 1;
    let mut table_inline = [(u32::MAX, 0u32); 128];
    let mut table_heap = Vec::new();
    let table: &mut [(u32, u32)] = if mask < 128 {
        &mut table_inline[..mask + 1]
    } else {
        table_heap.resize(mask + 1, (u32::MAX, 0));
        &mut table_heap
    };
    let mut ids: SmallVec<[u32; 32]> = SmallVec::new();
    for x in corners.iter_mut().flat_map(|c| &mut c.verts) {
        let id = *x as u32;
        let mut h = (id.wrapping_mul(0x9E37_79B9) >> (32 - bits)) as usize;
        loop {
            let e = &mut table[h];
            if e.0 == id {
                *x = e.1 as usize;
                break;
            }
            if e.0 == u32::MAX {
                *e = (id, ids.len() as u32);
                *x = ids.len();
                ids.push(id);
                break;
            }
            h = (h + 1) & mask;
        }
    }
    // Renumbered in ascending id order, so each row comes out as a stencil's sorted indices.
    let l = ids.len();
    let mut order: SmallVec<[u64; 32]> = ids
        .iter()
        .enumerate()
        .map(|(s, &x)| (x as u64) << 32 | s as u64)
        .collect();
    order.sort_unstable();
    let mut rank: SmallVec<[usize; 32]> = SmallVec::from_elem(0, l);
    for (new, &key) in order.iter().enumerate() {
        rank[key as u32 as usize] = new;
        ids[new] = (key >> 32) as u32;
    }
    for x in corners.iter_mut().flat_map(|c| &mut c.verts) {
        *x = rank[*x];
    }
    // The rows live in a per-thread buffer (no allocation per cap); every row is written
    // before it is read, so what an earlier cap left there never counts.
    thread_local! {
        static ROWS: std::cell::RefCell<Vec<f64>> = const { std::cell::RefCell::new(Vec::new()) };
    }
    ROWS.with(|cell| match cell.try_borrow_mut() {
        Ok(mut w) => cap_rows(&corners, &ids, &mut w, &mut each),
        Err(_) => cap_rows(&corners, &ids, &mut Vec::new(), &mut each),
    });
    Ok(())
}

/// The 20 points of the cap with `corners` (slots into `ids`, the cap's vertices ascending)
/// to `each`, `w` the rows' storage.
fn cap_rows(
    corners: &[Corner; 4],
    ids: &[u32],
    w: &mut Vec<f64>,
    each: &mut impl FnMut(usize, &[(u32, f64)]),
) {
    let l = ids.len();
    if w.len() < l * CAP_ROWS {
        w.resize(l * CAP_ROWS, 0.0);
    }
    let mut rows = CapRows {
        l,
        w: &mut w[..l * CAP_ROWS],
    };
    for (i, c) in corners.iter().enumerate() {
        c.limit_rows(&mut rows, i);
    }
    // Edge points: index k of the ring is the edge toward the face's next (j) or previous
    // (j + 1) corner; `P + T/3` in one pass.
    for (i, c) in corners.iter().enumerate() {
        let n = c.n();
        c.tangent(&mut rows, i, c.j);
        rows.copy_add(5 * i + 1, 5 * i, TANGENT, 1.0 / 3.0);
        c.tangent(&mut rows, i, (c.j + 1) % n);
        rows.copy_add(5 * i + 2, 5 * i, TANGENT, 1.0 / 3.0);
    }
    for i in 0..4 {
        face_point(&mut rows, corners, i, true);
        face_point(&mut rows, corners, i, false);
    }
    // Zero weights dropped (indices already ascending): the form of a [`Stencil`].
    let mut terms_inline = [(0u32, 0.0f64); CAP_SLOTS];
    let mut terms_heap = Vec::new();
    let terms: &mut [(u32, f64)] = if l <= CAP_SLOTS {
        &mut terms_inline[..l]
    } else {
        terms_heap.resize(l, (0, 0.0));
        &mut terms_heap
    };
    for k in 0..20 {
        let row = rows.row(k);
        let mut m = 0;
        for (&x, &w) in ids.iter().zip(row) {
            if w != 0.0 {
                terms[m] = (x, w);
                m += 1;
            }
        }
        each(k, &terms[..m]);
    }
}

/// One corner's interior point in [`gregory_weights`]: Bézier indices `(j, k)`, then `dp` and
/// `dm` each as `[value, ∂/∂u, ∂/∂v]`, then `h` (the Bernstein product is `9·dp·dm·h`).
type InteriorBlend = (usize, usize, [f64; 3], [f64; 3], f64);

/// Value and parametric derivative weights of the 20 Gregory points at `(u, v) ∈ [0,1]²`
/// (formulas in the module docs; finite everywhere on the square, corners included).
pub fn gregory_weights(u: f64, v: f64) -> PatchWeights<20> {
    let (bu, dbu) = crate::limit::basis::bezier_curve_weights(u);
    let (bv, dbv) = crate::limit::basis::bezier_curve_weights(v);
    let mut w = PatchWeights {
        point: [0.0; 20],
        du: [0.0; 20],
        dv: [0.0; 20],
    };
    // (slot, j, k): P, Ep, Em of each corner at Bézier point b[j][k].
    const BOUNDARY: [(usize, usize, usize); 12] = [
        (0, 0, 0),
        (1, 1, 0),
        (2, 0, 1),
        (5, 3, 0),
        (6, 3, 1),
        (7, 2, 0),
        (10, 3, 3),
        (11, 2, 3),
        (12, 3, 2),
        (15, 0, 3),
        (16, 0, 2),
        (17, 1, 3),
    ];
    for &(s, j, k) in &BOUNDARY {
        w.point[s] = bu[j] * bv[k];
        w.du[s] = dbu[j] * bv[k];
        w.dv[s] = bu[j] * dbv[k];
    }
    let (iu, iv) = (1.0 - u, 1.0 - v);
    // Per corner: Bézier interior (j, k); dp, ∂dp/∂u, ∂dp/∂v; dm, ∂dm/∂u, ∂dm/∂v; h.
    let interior: [InteriorBlend; 4] = [
        (1, 1, [v, 0.0, 1.0], [u, 1.0, 0.0], iu * iu * iv * iv),
        (2, 1, [iu, -1.0, 0.0], [v, 0.0, 1.0], u * u * iv * iv),
        (2, 2, [iv, 0.0, -1.0], [iu, -1.0, 0.0], u * u * v * v),
        (1, 2, [u, 1.0, 0.0], [iv, 0.0, -1.0], iu * iu * v * v),
    ];
    for (i, &(j, k, dp, dm, h)) in interior.iter().enumerate() {
        let d = dp[0] + dm[0];
        let (gp, gm) = if d > 0.0 {
            (dm[0] / d, dp[0] / d)
        } else {
            (0.5, 0.5)
        };
        let b = bu[j] * bv[k];
        let b_u = dbu[j] * bv[k];
        let b_v = bu[j] * dbv[k];
        let q = 9.0 * h * gp * gm;
        let g_u = q * (dp[0] * dm[1] - dm[0] * dp[1]);
        let g_v = q * (dp[0] * dm[2] - dm[0] * dp[2]);
        let (fp, fm) = (5 * i + 3, 5 * i + 4);
        w.point[fp] = b * gp;
        w.point[fm] = b * gm;
        w.du[fp] = b_u * gp + g_u;
        w.du[fm] = b_u * gm - g_u;
        w.dv[fp] = b_v * gp + g_v;
        w.dv[fm] = b_v * gm - g_v;
    }
    w
}

/// Exponents `(i, j, k)` of a quartic Bernstein polynomial `λ0^i λ1^j λ2^k`.
type Ijk = (usize, usize, usize);

/// Gregory *triangle* patches (Loop, Schaefer, Ni, Castaño 2009, §4; OpenSubdiv's
/// `GREGORY_TRIANGLE` layout): 15 points, per corner `i = 0..2` (corner 0 at `(u, v) = (0, 0)`,
/// 1 at `(1, 0)`, 2 at `(0, 1)`; barycentric `λ = (1 − u − v, u, v)`) the slots `5·i + s` as for
/// quads: `P_i`, `Ep_i` (cubic edge point toward corner `i+1`), `Em_i` (toward `i−1`), `Fp_i`,
/// `Fm_i`.
///
/// The patch is a quartic triangular Bézier patch whose boundary is the cubic
/// `[P_i, Ep_i, Em_{i+1}, P_{i+1}]` degree-elevated (so a shared edge is the same cubic curve as
/// a neighbour's) and whose three interior points are rational blends, each the right face
/// point on the edge it controls the cross derivative of:
///
/// ```text
/// b211 = (λ1·Fp0 + λ2·Fm0) / (λ1 + λ2)    (Fp0 on edge 0: λ2 = 0; Fm0 on edge 2: λ1 = 0)
/// b121 = (λ2·Fp1 + λ0·Fm1) / (λ2 + λ0)
/// b112 = (λ0·Fp2 + λ1·Fm2) / (λ0 + λ1)
/// ```
///
/// Derivatives are exact (quotient rule); where a blend's denominator vanishes (its corner,
/// where its Bernstein weight vanishes quadratically) the blend is the mean and its derivative
/// term 0.
pub fn gregory_triangle_weights(u: f64, v: f64) -> PatchWeights<15> {
    let l = [1.0 - u - v, u, v];
    // ∂λ/∂u, ∂λ/∂v.
    const DL: [[f64; 2]; 3] = [[-1.0, -1.0], [1.0, 0.0], [0.0, 1.0]];
    let pw = |x: f64, n: i32| if n < 0 { 0.0 } else { x.powi(n) };
    let fact = |n: usize| [1.0, 1.0, 2.0, 6.0, 24.0][n];
    // Quartic Bernstein B_{ijk} and its derivatives.
    let bern = |i: usize, j: usize, k: usize| -> [f64; 3] {
        let c = 24.0 / (fact(i) * fact(j) * fact(k));
        let (i, j, k) = (i as i32, j as i32, k as i32);
        let b = c * pw(l[0], i) * pw(l[1], j) * pw(l[2], k);
        let d0 = c * i as f64 * pw(l[0], i - 1) * pw(l[1], j) * pw(l[2], k);
        let d1 = c * j as f64 * pw(l[0], i) * pw(l[1], j - 1) * pw(l[2], k);
        let d2 = c * k as f64 * pw(l[0], i) * pw(l[1], j) * pw(l[2], k - 1);
        [
            b,
            d0 * DL[0][0] + d1 * DL[1][0] + d2 * DL[2][0],
            d0 * DL[0][1] + d1 * DL[1][1] + d2 * DL[2][1],
        ]
    };
    let mut w = PatchWeights {
        point: [0.0; 15],
        du: [0.0; 15],
        dv: [0.0; 15],
    };
    let mut add = |slot: usize, coef: f64, b: [f64; 3]| {
        w.point[slot] += coef * b[0];
        w.du[slot] += coef * b[1];
        w.dv[slot] += coef * b[2];
    };
    // Boundary Bézier points (i, j, k) as combinations of P, Ep, Em.
    const BOUNDARY: [(Ijk, [(usize, f64); 2]); 12] = [
        ((4, 0, 0), [(0, 1.0), (0, 0.0)]),
        ((0, 4, 0), [(5, 1.0), (5, 0.0)]),
        ((0, 0, 4), [(10, 1.0), (10, 0.0)]),
        ((3, 1, 0), [(0, 0.25), (1, 0.75)]),
        ((2, 2, 0), [(1, 0.5), (7, 0.5)]),
        ((1, 3, 0), [(7, 0.75), (5, 0.25)]),
        ((0, 3, 1), [(5, 0.25), (6, 0.75)]),
        ((0, 2, 2), [(6, 0.5), (12, 0.5)]),
        ((0, 1, 3), [(12, 0.75), (10, 0.25)]),
        ((1, 0, 3), [(10, 0.25), (11, 0.75)]),
        ((2, 0, 2), [(11, 0.5), (2, 0.5)]),
        ((3, 0, 1), [(2, 0.75), (0, 0.25)]),
    ];
    for &((i, j, k), terms) in &BOUNDARY {
        let b = bern(i, j, k);
        for (slot, c) in terms {
            if c != 0.0 {
                add(slot, c, b);
            }
        }
    }
    // Interior: (i, j, k), Fp slot, its weight's λ index, Fm's λ index.
    const INTERIOR: [(Ijk, usize, usize, usize); 3] = [
        ((2, 1, 1), 3, 1, 2),
        ((1, 2, 1), 8, 2, 0),
        ((1, 1, 2), 13, 0, 1),
    ];
    for &((i, j, k), fp, a, b) in &INTERIOR {
        let bb = bern(i, j, k);
        let d = l[a] + l[b];
        let (gp, gu, gv) = if d > 1e-300 {
            // gp = λa / (λa + λb); ∂gp = (λb ∂λa − λa ∂λb) / d².
            let q = 1.0 / (d * d);
            (
                l[a] / d,
                (l[b] * DL[a][0] - l[a] * DL[b][0]) * q,
                (l[b] * DL[a][1] - l[a] * DL[b][1]) * q,
            )
        } else {
            (0.5, 0.0, 0.0)
        };
        let fm = fp + 1;
        w.point[fp] += bb[0] * gp;
        w.point[fm] += bb[0] * (1.0 - gp);
        w.du[fp] += bb[1] * gp + bb[0] * gu;
        w.du[fm] += bb[1] * (1.0 - gp) - bb[0] * gu;
        w.dv[fp] += bb[2] * gp + bb[0] * gv;
        w.dv[fm] += bb[2] * (1.0 - gp) - bb[0] * gv;
    }
    w
}

/// The 15 points of the Gregory triangle patch of a triangle face, from the Gregory points of
/// its three level-1 children (`children[i]`: the child quad at triangle corner `i`, whose
/// corner 0 is the corner's vertex child, corner 1 on the edge toward triangle corner `i+1`;
/// each its 20 stencils of [`gregory_basis`]).
///
/// Each triangle corner keeps its child's limit position and tangents (doubled: the child
/// covers half of each edge) and its twist: with the triangle's local coordinates
/// `(a, b) = (s, t)/2 − s·t/6` of the child's `(s, t)` (the bilinear map of the child onto the
/// corner's third of the triangle, [`crate::patches::adaptive::AdaptivePatch::base_param`]), matching
/// `∂²/∂a∂b` of the quartic at the corner with the child's gives
///
/// ```text
/// Ep = 2·Ep' − P,  Em = 2·Em' − P,  F = 3·F' − 7/6·(Ep' + Em') + P/3   (F = Fp, Fm)
/// ```
///
/// So the corner is exact to first order wherever the child's is, and the boundary is the cubic
/// through the two corners' limit points along their limit tangents.
pub fn gregory_triangle_from_children(children: [&[Stencil; 20]; 3]) -> [Stencil; 15] {
    let mut out: [Stencil; 15] = Default::default();
    for (i, basis) in children.iter().enumerate() {
        let row = |k: usize| {
            let mut r = Row::default();
            for (&x, &w) in basis[k].indices.iter().zip(&basis[k].weights) {
                r.add(x, w);
            }
            r
        };
        let (p, ep, em) = (row(0), row(1), row(2));
        let edge = |e: &Row| {
            let mut r = Row::default();
            r.add_row(e, 2.0);
            r.add_row(&p, -1.0);
            r.into_stencil()
        };
        let face = |f: &Row| {
            let mut r = Row::default();
            r.add_row(f, 3.0);
            r.add_row(&ep, -7.0 / 6.0);
            r.add_row(&em, -7.0 / 6.0);
            r.add_row(&p, 1.0 / 3.0);
            r.into_stencil()
        };
        out[5 * i] = p.clone().into_stencil();
        out[5 * i + 1] = edge(&ep);
        out[5 * i + 2] = edge(&em);
        out[5 * i + 3] = face(&row(3));
        out[5 * i + 4] = face(&row(4));
    }
    out
}

/// Moves the six face points of a Gregory triangle patch by one common vector so the patch
/// passes through `centre` (weights over the same vertices) at the domain's centroid, where
/// the three interior Bézier points carry 4/9 of the weight. Corner positions, tangents and
/// the boundary stay.
///
/// `mids[p]`: the limit point of edge `p`'s midpoint. The patch's boundary correction
/// ([`crate::patches::adaptive::AdaptivePlan::evaluate`]) puts its edges through them, which moves the centroid
/// by `4/9` of each midpoint's distance from the patch's own cubic there; that is accounted
/// for, so the corrected patch passes through `centre`.
pub fn gregory_triangle_through_centre(
    points: &mut [Stencil; 15],
    centre: &[(u32, f64)],
    mids: [&[(u32, f64)]; 3],
) {
    let w = gregory_triangle_weights(1.0 / 3.0, 1.0 / 3.0);
    let mut delta = Row::default();
    for &(i, x) in centre {
        delta.add(i, x * 9.0 / 4.0);
    }
    for (k, st) in points.iter().enumerate() {
        for (&i, &x) in st.indices.iter().zip(&st.weights) {
            delta.add(i, -w.point[k] * x * 9.0 / 4.0);
        }
    }
    // − 9/4 · 4/9 · (M_p − B_p(1/2)), B_p(1/2) = (P_p + 3 Ep_p + 3 Em_p+1 + P_p+1) / 8.
    for (p, mid) in mids.iter().enumerate() {
        let q = (p + 1) % 3;
        for &(i, x) in mid.iter() {
            delta.add(i, -x);
        }
        for (k, c) in [
            (5 * p, 1.0),
            (5 * p + 1, 3.0),
            (5 * q + 2, 3.0),
            (5 * q, 1.0),
        ] {
            let st = &points[k];
            for (&i, &x) in st.indices.iter().zip(&st.weights) {
                delta.add(i, c / 8.0 * x);
            }
        }
    }
    for corner in 0..3 {
        for slot in [3, 4] {
            let st = &points[5 * corner + slot];
            let mut r = Row::default();
            for (&i, &x) in st.indices.iter().zip(&st.weights) {
                r.add(i, x);
            }
            r.add_row(&delta, 1.0);
            points[5 * corner + slot] = r.into_stencil();
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn weights_sum_to_one_and_derivatives_to_zero() {
        for a in 0..=10 {
            for b in 0..=10 {
                let w = gregory_weights(a as f64 / 10.0, b as f64 / 10.0);
                let s: f64 = w.point.iter().sum();
                let su: f64 = w.du.iter().sum();
                let sv: f64 = w.dv.iter().sum();
                assert!((s - 1.0).abs() < 1e-14 && su.abs() < 1e-13 && sv.abs() < 1e-13);
            }
        }
    }

    #[test]
    fn triangle_weights_are_a_partition_of_unity_with_exact_derivatives() {
        let h = 1e-6;
        for a in 0..=10 {
            for b in 0..=(10 - a) {
                let (u, v) = (a as f64 / 10.0, b as f64 / 10.0);
                let w = gregory_triangle_weights(u, v);
                let s: f64 = w.point.iter().sum();
                assert!((s - 1.0).abs() < 1e-14);
                assert!(w.du.iter().sum::<f64>().abs() < 1e-12);
                assert!(w.dv.iter().sum::<f64>().abs() < 1e-12);
                // Interior points: the derivatives are those of the point weights.
                if a > 0 && b > 0 && a + b < 10 {
                    let (pu, mu) = (
                        gregory_triangle_weights(u + h, v),
                        gregory_triangle_weights(u - h, v),
                    );
                    let (pv, mv) = (
                        gregory_triangle_weights(u, v + h),
                        gregory_triangle_weights(u, v - h),
                    );
                    for k in 0..15 {
                        let du = (pu.point[k] - mu.point[k]) / (2.0 * h);
                        let dv = (pv.point[k] - mv.point[k]) / (2.0 * h);
                        assert!((du - w.du[k]).abs() < 1e-7, "du {k} at {u} {v}");
                        assert!((dv - w.dv[k]).abs() < 1e-7, "dv {k} at {u} {v}");
                    }
                }
            }
        }
        // On edge 0 (v = 0) only that edge's cubic counts: P0, Ep0, Em1, P1.
        let w = gregory_triangle_weights(0.3, 0.0);
        for (k, &x) in w.point.iter().enumerate() {
            assert_eq!(x != 0.0, [0, 1, 5, 7].contains(&k), "slot {k}");
        }
    }

    #[test]
    fn sector_bounds() {
        // Interior vertex, sharp edges 1 and 4 of 6; face 2 lies in 1..4.
        let sharp = [false, true, false, false, true, false];
        assert_eq!(sector(&sharp, 2, false), Some((1, 4, 3)));
        assert_eq!(sector(&sharp, 5, false), Some((4, 1, 3)));
        assert_eq!(sector(&sharp, 1, false), Some((1, 4, 3)));
        // Boundary fan of 3 faces: edges 0 and 3 are the boundary.
        let sharp = [true, false, false, true];
        assert_eq!(sector(&sharp, 1, true), Some((0, 3, 3)));
    }
}
