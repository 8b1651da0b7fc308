//! Limit masks: weights that push a vertex of any refinement level onto the limit surface,
//! with two limit tangents (OpenSubdiv `Sdc` semantics for smooth, crease/boundary and corner
//! vertices). At a dart Tessera departs from `Sdc`, whose smooth mask is not the limit there:
//! see [`dart_position_weights`].
//!
//! A mask is expressed over the vertex's ordered one-ring:
//! * `vertex`: the vertex itself;
//! * `edges[i]`: the edge-neighbours `e_0 … e_{n−1}` in counter-clockwise order. For a
//!   boundary vertex `e_0` and `e_{n−1}` are the two boundary neighbours (the fan runs CCW from
//!   `e_0` to `e_{n−1}`, so it has `n−1` faces);
//! * `faces[i]` (Catmull-Clark only): the vertex of quad `i` (between `e_i` and `e_{i+1}`)
//!   opposite the centre. Catmull-Clark masks need an all-quad ring, which every vertex has
//!   after one refinement.
//!
//! Tangent magnitudes follow OpenSubdiv (cos/sin masks for smooth vertices, Biermann et al.'s
//! cross-crease masks for Catmull-Clark); they give exact tangent *directions*. Parametric derivatives of a patch are produced by [`crate::limit::basis`]
//! and [`crate::limit::eval`] instead.

use std::f64::consts::PI;

/// Which limit rule applies at a vertex (the refinement rule once sharpness has decayed).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum LimitRule {
    /// Smooth interior vertex.
    Smooth,
    /// Interior vertex with one infinitely sharp edge (`edge`, its index in the ring): the
    /// smooth vertex rule, but the sharp edge's child is its midpoint, so the limit position is
    /// [`dart_position_weights`]'s, not the smooth mask's. Tangents are the smooth masks'.
    Dart { edge: usize },
    /// Two infinitely sharp edges (boundary edges count): `ends` are their indices in the ring,
    /// `ends[0]` the leading edge (CCW start of the span containing the surface).
    Crease { ends: [usize; 2] },
    /// Infinitely sharp vertex (or more than two sharp edges): the vertex stays put.
    Corner,
}

/// A vertex's one-ring shape for mask computation.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LimitVertex {
    /// Number of edge-neighbours.
    pub valence: usize,
    /// Boundary vertex (fan, `valence − 1` faces) or interior (cycle, `valence` faces).
    pub boundary: bool,
    pub rule: LimitRule,
}

/// Weights over (vertex, edge-neighbours, face-opposite vertices).
#[derive(Clone, Debug, PartialEq)]
pub struct Mask {
    pub vertex: f64,
    pub edges: Vec<f64>,
    pub faces: Vec<f64>,
}

impl Mask {
    fn zero(n_edges: usize, n_faces: usize) -> Mask {
        Mask {
            vertex: 0.0,
            edges: vec![0.0; n_edges],
            faces: vec![0.0; n_faces],
        }
    }

    /// Apply to points of any dimension: `edges`/`faces` must match the mask's lengths
    /// (faces may be empty when the mask has no face weights).
    pub fn apply(&self, vertex: &[f64], edges: &[&[f64]], faces: &[&[f64]]) -> Vec<f64> {
        let mut out: Vec<f64> = vertex.iter().map(|x| x * self.vertex).collect();
        for (w, p) in self.edges.iter().zip(edges) {
            for (o, x) in out.iter_mut().zip(p.iter()) {
                *o += w * x;
            }
        }
        for (w, p) in self.faces.iter().zip(faces) {
            for (o, x) in out.iter_mut().zip(p.iter()) {
                *o += w * x;
            }
        }
        out
    }
}

/// Position and tangent masks of one vertex.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitMasks {
    pub position: Mask,
    /// First tangent: along `e_0` for smooth vertices, along the crease for creases.
    pub tangent1: Mask,
    /// Second tangent: 90° CCW of `tangent1` for smooth vertices, across the surface (inward)
    /// for creases; `tangent1 × tangent2` is the outward normal.
    pub tangent2: Mask,
}

fn n_faces(v: &LimitVertex) -> usize {
    if v.boundary {
        v.valence.saturating_sub(1)
    } else {
        v.valence
    }
}

/// Loop limit masks (no face weights).
pub fn loop_limit_masks(v: &LimitVertex) -> LimitMasks {
    let n = v.valence;
    let mut pos = Mask::zero(n, 0);
    let mut t1 = Mask::zero(n, 0);
    let mut t2 = Mask::zero(n, 0);
    match v.rule {
        LimitRule::Smooth | LimitRule::Dart { .. } => {
            let nf = n as f64;
            let beta = 0.25 * (2.0 * PI / nf).cos() + 0.375;
            let gamma = (0.625 - beta * beta) / nf;
            let e = 1.0 / (nf + 3.0 / (8.0 * gamma));
            pos.vertex = 1.0 - e * nf;
            pos.edges.iter_mut().for_each(|w| *w = e);
            for i in 0..n {
                (t1.edges[i], t2.edges[i]) = loop_smooth_tangent_weights(n, i);
            }
            if let LimitRule::Dart { edge } = v.rule {
                set_dart_position(&mut pos, true, n, edge);
            }
        }
        LimitRule::Crease { ends } => {
            pos.vertex = 2.0 / 3.0;
            pos.edges[ends[0]] = 1.0 / 6.0;
            pos.edges[ends[1]] = 1.0 / 6.0;
            t1.edges[ends[0]] = 1.5;
            t1.edges[ends[1]] = -1.5;
            crease_cross_tangent(&mut t2, ends, n, 3.0);
        }
        LimitRule::Corner => {
            pos.vertex = 1.0;
            corner_tangents(&mut t1, &mut t2, v, 3.0);
        }
    }
    LimitMasks {
        position: pos,
        tangent1: t1,
        tangent2: t2,
    }
}

/// Weights of edge-neighbour `i` of a smooth Loop vertex of valence `n` in its two tangent
/// masks (`cos`, `sin` of its angle): one place, so the masks and the allocation-free rows of
/// [`crate::limit::eval::LocalMesh::loop_tangent_row`] agree to the bit.
pub fn loop_smooth_tangent_weights(n: usize, i: usize) -> (f64, f64) {
    let a = 2.0 * PI * i as f64 / n as f64;
    (a.cos(), a.sin())
}

/// Cross-crease tangent over the interior edges strictly between `ends[0]` and `ends[1]`
/// (CCW), pointing into the surface (OpenSubdiv's Loop formulae).
fn crease_cross_tangent(t2: &mut Mask, ends: [usize; 2], n: usize, scale: f64) {
    let interior: Vec<usize> = {
        let mut v = Vec::new();
        let mut i = (ends[0] + 1) % n;
        while i != ends[1] {
            v.push(i);
            i = (i + 1) % n;
        }
        v
    };
    let k = interior.len();
    match k {
        0 => {
            t2.vertex = -2.0 * scale;
            t2.edges[ends[0]] = scale;
            t2.edges[ends[1]] = scale;
        }
        1 => {
            t2.vertex = -scale;
            t2.edges[interior[0]] = scale;
        }
        2 => {
            let r3 = 3f64.sqrt();
            t2.vertex = -r3;
            t2.edges[ends[0]] = -r3 / 2.0;
            t2.edges[ends[1]] = -r3 / 2.0;
            t2.edges[interior[0]] = r3;
            t2.edges[interior[1]] = r3;
        }
        _ => {
            let theta = PI / (k as f64 + 1.0);
            let c = -scale * theta.sin();
            t2.edges[ends[0]] = c;
            t2.edges[ends[1]] = c;
            let e = -scale * 2.0 * (theta.cos() - 1.0);
            for (j, &i) in interior.iter().enumerate() {
                t2.edges[i] = e * ((j + 1) as f64 * theta).sin();
            }
        }
    }
}

fn corner_tangents(t1: &mut Mask, t2: &mut Mask, v: &LimitVertex, scale: f64) {
    let n = v.valence;
    if n == 0 {
        return;
    }
    // Tangents along the first and last edge of the fan (the surface lies between them).
    let last = if v.boundary { n - 1 } else { 1.min(n - 1) };
    t1.vertex = -scale;
    t1.edges[0] = scale;
    t2.vertex = -scale;
    t2.edges[last] += scale;
}

/// Exact limit-position weights of an interior dart of valence `n` (one infinitely sharp edge),
/// over its ring `[v, e_0 … e_{n−1}]` (Loop) or `[v, e_0 … e_{n−1}, f_0 … f_{n−1}]`
/// (Catmull-Clark; `f_i` opposite `v` in the quad between `e_i` and `e_{i+1}`), the sharp edge
/// being `e_0`.
///
/// OpenSubdiv (and this crate before) used the smooth mask at a dart. But the sharp edge's child
/// is its midpoint, so the dart's subdivision matrix `S` differs from the smooth one and so does
/// its left eigenvector for eigenvalue 1, the limit mask: the smooth mask was off by 1.3e-2 of
/// the diagonal on OpenSubdiv's catmark_cubes_infsharp. The ring is closed under refinement, so
/// the mask is `e_v · S^k` as `k → ∞`: the weights of the vertex's level-`k` position over the
/// level-0 ring, iterated until they stop changing (the error shrinks by the subdominant
/// eigenvalue per step).
///
/// Memoized per scheme and valence (the iteration costs about 40,000 instructions and the
/// adaptive plans ask once per dart corner of every end cap): the same bits as iterating anew.
pub fn dart_position_weights(loop_scheme: bool, n: usize) -> Vec<f64> {
    const CACHED: usize = 64;
    static TABLES: [[std::sync::OnceLock<Vec<f64>>; CACHED]; 2] =
        [const { [const { std::sync::OnceLock::new() }; CACHED] }; 2];
    match TABLES[usize::from(loop_scheme)].get(n) {
        Some(cell) => cell
            .get_or_init(|| iterate_dart_position_weights(loop_scheme, n))
            .clone(),
        None => iterate_dart_position_weights(loop_scheme, n),
    }
}

fn iterate_dart_position_weights(loop_scheme: bool, n: usize) -> Vec<f64> {
    let size = if loop_scheme { 1 + n } else { 1 + 2 * n };
    let e = |i: usize| 1 + i % n;
    let f = |i: usize| 1 + n + i % n;
    let mut w = vec![0.0; size];
    w[0] = 1.0;
    let mut next = vec![0.0; size];
    // A face point: a quarter of each corner of quad `i` (Catmull-Clark).
    let face = |next: &mut [f64], i: usize, c: f64| {
        for k in [0, e(i), f(i), e(i + 1)] {
            next[k] += 0.25 * c;
        }
    };
    // Loop's smooth vertex weights at valence n, read once for every step.
    let (loop_vw, loop_ew) = crate::refine::loop_vertex_weights(n);
    for _ in 0..10_000 {
        next.fill(0.0);
        // `next = w · S`: each child's weight spread over the parents its rule reads, with the
        // refiner's smooth rules.
        let c = w[0];
        if loop_scheme {
            next[0] += c * loop_vw;
            for i in 0..n {
                next[e(i)] += c * loop_ew;
            }
        } else {
            let ew = 1.0 / (n * n) as f64;
            next[0] += c * (n as f64 - 2.0) / n as f64;
            for i in 0..n {
                next[e(i)] += c * ew;
                face(&mut next, i, c * ew);
            }
        }
        for i in 0..n {
            let c = w[e(i)];
            if i == 0 {
                // The sharp edge's child: its midpoint.
                next[0] += 0.5 * c;
                next[e(0)] += 0.5 * c;
            } else if loop_scheme {
                next[0] += 0.375 * c;
                next[e(i)] += 0.375 * c;
                next[e(i + n - 1)] += 0.125 * c;
                next[e(i + 1)] += 0.125 * c;
            } else {
                next[0] += 0.25 * c;
                next[e(i)] += 0.25 * c;
                face(&mut next, i + n - 1, 0.25 * c);
                face(&mut next, i, 0.25 * c);
            }
            if !loop_scheme {
                face(&mut next, i, w[f(i)]);
            }
        }
        let change = w
            .iter()
            .zip(&next)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        std::mem::swap(&mut w, &mut next);
        if change < 1e-17 {
            break;
        }
    }
    w
}

/// Replace a smooth position mask with the dart's, its sharp edge at ring index `edge`.
fn set_dart_position(pos: &mut Mask, loop_scheme: bool, n: usize, edge: usize) {
    let w = dart_position_weights(loop_scheme, n);
    pos.vertex = w[0];
    for j in 0..n {
        pos.edges[(edge + j) % n] = w[1 + j];
        if !loop_scheme {
            pos.faces[(edge + j) % n] = w[1 + n + j];
        }
    }
}

/// Weights (vertex, each edge neighbour, each face-opposite vertex) of the smooth interior
/// Catmull-Clark limit position of valence `n`: the position mask of [`catmark_limit_masks`]
/// without its allocations, for callers that need only the position.
pub fn catmark_smooth_position_weights(n: usize) -> [f64; 3] {
    let nf = n as f64;
    let fw = 1.0 / (nf * (nf + 5.0));
    [1.0 - nf * 5.0 * fw, 4.0 * fw, fw]
}

/// Catmull-Clark limit masks. Smooth masks need the all-quad ring (`faces` = opposite vertices).
pub fn catmark_limit_masks(v: &LimitVertex) -> LimitMasks {
    let n = v.valence;
    let nf_count = n_faces(v);
    match v.rule {
        LimitRule::Smooth | LimitRule::Dart { .. } => {
            let nf = n as f64;
            let mut pos = Mask::zero(n, n);
            let [vw, ew, fw] = catmark_smooth_position_weights(n);
            pos.vertex = vw;
            pos.edges.iter_mut().for_each(|w| *w = ew);
            pos.faces.iter_mut().for_each(|w| *w = fw);
            if let LimitRule::Dart { edge } = v.rule {
                set_dart_position(&mut pos, false, n, edge);
            }
            let mut t1 = Mask::zero(n, n);
            let mut t2 = Mask::zero(n, n);
            let c = (2.0 * PI / nf).cos();
            let an = 1.0 + c + (PI / nf).cos() * (2.0 * (9.0 + c)).sqrt();
            for i in 0..n {
                let a0 = 2.0 * PI * i as f64 / nf;
                let a1 = 2.0 * PI * (i + 1) as f64 / nf;
                t1.edges[i] = an * a0.cos();
                t1.faces[i] = a0.cos() + a1.cos();
                t2.edges[i] = an * a0.sin();
                t2.faces[i] = a0.sin() + a1.sin();
            }
            LimitMasks {
                position: pos,
                tangent1: t1,
                tangent2: t2,
            }
        }
        LimitRule::Crease { ends } => {
            let mut pos = Mask::zero(n, nf_count);
            pos.vertex = 2.0 / 3.0;
            pos.edges[ends[0]] = 1.0 / 6.0;
            pos.edges[ends[1]] = 1.0 / 6.0;
            let mut t1 = Mask::zero(n, nf_count);
            t1.edges[ends[0]] = 0.5;
            t1.edges[ends[1]] = -0.5;
            let mut t2 = Mask::zero(n, nf_count);
            catmark_cross_tangent(&mut t2, ends, n);
            LimitMasks {
                position: pos,
                tangent1: t1,
                tangent2: t2,
            }
        }
        LimitRule::Corner => {
            let mut pos = Mask::zero(n, nf_count);
            pos.vertex = 1.0;
            let mut t1 = Mask::zero(n, nf_count);
            let mut t2 = Mask::zero(n, nf_count);
            corner_tangents(&mut t1, &mut t2, v, 1.0);
            LimitMasks {
                position: pos,
                tangent1: t1,
                tangent2: t2,
            }
        }
    }
}

/// Catmull-Clark tangent across a crease, pointing into the span `ends[0] → ends[1]` (CCW):
/// the uniform B-spline cross tangent for one interior edge, Biermann et al.'s eigenvector
/// formula for more, and the average of the two crease edges for a single face. Face `i` is
/// the quad between edges `i` and `i + 1`.
fn catmark_cross_tangent(t2: &mut Mask, ends: [usize; 2], n: usize) {
    t2.vertex = catmark_cross_tangent_into(&mut t2.edges, &mut t2.faces, ends, n);
}

/// [`catmark_cross_tangent`] into zeroed edge and face weights (`edges.len() == n`, one face
/// per ring gap), returning the vertex weight: no [`Mask`] allocated (Gregory end caps).
pub(crate) fn catmark_cross_tangent_into(
    edges: &mut [f64],
    faces: &mut [f64],
    ends: [usize; 2],
    n: usize,
) -> f64 {
    let interior = (ends[1] + n - ends[0]) % n - 1;
    let e = |i: usize| (ends[0] + i) % n;
    let nf = faces.len().max(1);
    let f = |i: usize| (ends[0] + i) % nf;
    match interior {
        0 => {
            edges[ends[0]] = 3.0;
            edges[ends[1]] = 3.0;
            -6.0
        }
        1 => {
            edges[ends[0]] = -1.0 / 6.0;
            edges[e(1)] = 4.0 / 6.0;
            edges[ends[1]] = -1.0 / 6.0;
            faces[f(0)] = 1.0 / 6.0;
            faces[f(1)] = 1.0 / 6.0;
            -4.0 / 6.0
        }
        _ => {
            let k = (interior + 1) as f64;
            let th = PI / k;
            let (c, s) = (th.cos(), th.sin());
            let d = 1.0 / (k * (3.0 + c));
            let r = (c + 1.0) / s;
            edges[ends[0]] = -r * (1.0 + 2.0 * c) * d;
            edges[ends[1]] = -r * (1.0 + 2.0 * c) * d;
            faces[f(0)] = s * d;
            for i in 1..=interior {
                let (si, si1) = ((i as f64 * th).sin(), ((i + 1) as f64 * th).sin());
                edges[e(i)] = 4.0 * si * d;
                faces[f(i)] = (si + si1) * d;
            }
            4.0 * r * (c - 1.0) * d
        }
    }
}

/// Smooth-vertex tangent directed along edge-neighbour `k`, as a weight vector over
/// `(edges, faces)`: the cos/sin masks rotated so the parametric derivative along an edge of a
/// regular vertex comes out exactly (Loop: `(2/n)·Σ cos(θᵢ−θₖ) eᵢ`, which is `1/3` of the mask
/// at valence 6; Catmull-Clark: `1/(3n)` of the Halstead mask, `1/12` at valence 4).
pub fn smooth_directional_tangent(loop_scheme: bool, n: usize, k: usize) -> (Vec<f64>, Vec<f64>) {
    let nf = n as f64;
    let tk = 2.0 * PI * k as f64 / nf;
    if loop_scheme {
        let e = (0..n)
            .map(|i| (2.0 / nf) * (2.0 * PI * i as f64 / nf - tk).cos())
            .collect();
        (e, Vec::new())
    } else {
        let mut e = Vec::with_capacity(n);
        let mut f = Vec::with_capacity(n);
        catmark_directional_tangent_each(n, k, |_, ew, fw| {
            e.push(ew);
            f.push(fw);
        });
        (e, f)
    }
}

/// The Catmull-Clark weights of [`smooth_directional_tangent`], handed to `each(i, edge i,
/// face i)` in ring order instead of collected (same arithmetic, so the same bits).
pub fn catmark_directional_tangent_each(n: usize, k: usize, mut each: impl FnMut(usize, f64, f64)) {
    // Memoized per valence and direction (two cosines per ring entry on every Gregory corner):
    // the same bits as computing them anew.
    if let Some(table) = catmark_directional_tangent_table(n, k) {
        for (i, &(e, f)) in table.iter().enumerate() {
            each(i, e, f);
        }
    } else {
        directional_tangent_weights(n, k, each);
    }
}

/// The memoized `(edge, face)` weights of [`catmark_directional_tangent_each`] for valences
/// below 16 (`None` above, or for `k ≥ n`).
pub(crate) fn catmark_directional_tangent_table(
    n: usize,
    k: usize,
) -> Option<&'static [(f64, f64)]> {
    const CACHED: usize = 16;
    static TABLES: [std::sync::OnceLock<Vec<(f64, f64)>>; CACHED * CACHED] =
        [const { std::sync::OnceLock::new() }; CACHED * CACHED];
    (n < CACHED && k < n).then(|| {
        TABLES[n * CACHED + k]
            .get_or_init(|| {
                let mut t = Vec::with_capacity(n);
                directional_tangent_weights(n, k, |_, e, f| t.push((e, f)));
                t
            })
            .as_slice()
    })
}

fn directional_tangent_weights(n: usize, k: usize, mut each: impl FnMut(usize, f64, f64)) {
    let nf = n as f64;
    let tk = 2.0 * PI * k as f64 / nf;
    let c = (2.0 * PI / nf).cos();
    let an = 1.0 + c + (PI / nf).cos() * (2.0 * (9.0 + c)).sqrt();
    let s = 1.0 / (3.0 * nf);
    for i in 0..n {
        let a0 = 2.0 * PI * i as f64 / nf - tk;
        let a1 = 2.0 * PI * (i + 1) as f64 / nf - tk;
        each(i, s * an * a0.cos(), s * (a0.cos() + a1.cos()));
    }
}
