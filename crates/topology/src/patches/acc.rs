//! ACC-1 geometry patches (Loop & Schaefer 2008, "Approximating Catmull-Clark subdivision
//! surfaces with bicubic patches"; seed 002 §2.2): one bicubic Bézier patch per quad, its 16
//! points built from the face's neighbourhood by three fixed masks, no refinement.
//!
//! Design decisions:
//! - **The masks.** For a vertex `v` of valence `n` in a quad `G = (v, e0, f, e1)`, the
//!   *interior point* of `v` in `G` is `(n·v + 2·e0 + 2·e1 + f) / (n + 5)`. A patch's four inner
//!   Bézier points are its own interior points; each *edge point* is the midpoint of the two
//!   interior points (this face's and the neighbour's across the edge) of the edge's end; each
//!   *corner point* is the centroid of the `n` interior points around the vertex, which is the
//!   vertex's Catmull-Clark limit position. Where every corner has valence 4 the 16 points are
//!   the B-spline patch's Bézier points, so the patch is exact there.
//! - **Stencils, not points.** Like [`crate::patches::gregory`], each point is a stencil over the level's
//!   vertices, so it serves any vertex data (animated positions, texture coordinates) and the
//!   GPU builds the points from the same weights.
//! - **Scope.** Interior quads whose corners are smooth (no boundary, crease or corner tag) and
//!   whose corners' faces are all quads: ACC-1's masks are defined for quad neighbourhoods only.
//!   Others are refused with [`AccProblem`] naming the vertex; the technique that draws ACC-1
//!   treats those faces another way (the issue that adds it decides which).
use crate::error::{AccProblem, TopologyError};
use crate::mesh::INVALID;
use crate::refine::stencil::Stencil;
use crate::refine::LevelRef;
use std::collections::BTreeMap;

fn add(acc: &mut BTreeMap<u32, f64>, v: u32, w: f64) {
    *acc.entry(v).or_insert(0.0) += w;
}

fn to_stencil(acc: BTreeMap<u32, f64>) -> Stencil {
    let (indices, weights) = acc.into_iter().filter(|&(_, w)| w != 0.0).unzip();
    Stencil { indices, weights }
}

/// Interior point of `v` in quad `g` (weights added to `acc`, scaled by `scale`).
fn interior(level: &LevelRef<'_>, g: usize, v: u32, scale: f64, acc: &mut BTreeMap<u32, f64>) {
    let t = level.topology;
    let fv = t.face_vertices(g);
    let k = fv.iter().position(|&x| x == v).unwrap_or(0);
    let n = t.vertex_edges(v as usize).len() as f64;
    let s = scale / (n + 5.0);
    add(acc, v, n * s);
    add(acc, fv[(k + 1) % 4], 2.0 * s);
    add(acc, fv[(k + 3) % 4], 2.0 * s);
    add(acc, fv[(k + 2) % 4], s);
}

fn check_corner(level: &LevelRef<'_>, v: u32) -> Result<(), AccProblem> {
    let t = level.topology;
    let edges = t.vertex_edges(v as usize);
    if edges.iter().any(|&e| t.is_boundary_edge(e as usize)) {
        return Err(AccProblem::Boundary { vertex: v });
    }
    if level.vertex_sharpness[v as usize] > 0.0
        || edges
            .iter()
            .any(|&e| level.edge_sharpness[e as usize] > 0.0)
    {
        return Err(AccProblem::Sharp { vertex: v });
    }
    if t.vertex_faces(v as usize)
        .iter()
        .any(|&g| t.face_vertices(g as usize).len() != 4)
    {
        return Err(AccProblem::NonQuadNeighbour { vertex: v });
    }
    Ok(())
}

/// The 16 Bézier points of quad `face`'s ACC-1 geometry patch, `[i][j]` = Bernstein index `i` in
/// `u`, `j` in `v` (corner 0 of the face at `(0,0)`, 1 at `(1,0)`, 2 at `(1,1)`, 3 at `(0,1)`,
/// the domain of [`crate::limit::basis`]), each a stencil over the level's vertices.
pub fn acc1_patch(level: LevelRef<'_>, face: usize) -> Result<[[Stencil; 4]; 4], TopologyError> {
    let t = level.topology;
    if face >= t.num_faces() {
        return Err(TopologyError::FaceOutOfRange {
            face,
            count: t.num_faces(),
        });
    }
    let problem = |problem| TopologyError::AccPatch { face, problem };
    let fv = t.face_vertices(face);
    if fv.len() != 4 {
        return Err(problem(AccProblem::NotQuad { size: fv.len() }));
    }
    for &v in fv {
        check_corner(&level, v).map_err(problem)?;
    }
    let edges = t.face_edge_list(face);
    // Corner `c` of the face sits at Bézier (a, b), its inner point one step inside.
    let corner_ij = [(0usize, 0usize), (3, 0), (3, 3), (0, 3)];
    let inward = |i: usize| if i == 0 { 1 } else { 2 };
    let mut net: [[BTreeMap<u32, f64>; 4]; 4] = Default::default();
    for (c, &v) in fv.iter().enumerate() {
        let (i, j) = corner_ij[c];
        interior(&level, face, v, 1.0, &mut net[inward(i)][inward(j)]);
        let around = t.vertex_faces(v as usize);
        let n = around.len() as f64;
        for &g in around {
            interior(&level, g as usize, v, 1.0 / n, &mut net[i][j]);
        }
        // The two edge points next to this corner: along the edge to corner c+1 and to c−1.
        for (edge, toward) in [(edges[c], (c + 1) % 4), (edges[(c + 3) % 4], (c + 3) % 4)] {
            let [f0, f1] = t.edge_faces(edge as usize);
            let other = if f0 as usize == face { f1 } else { f0 };
            if other == INVALID {
                return Err(problem(AccProblem::Boundary { vertex: v }));
            }
            let (ti, tj) = corner_ij[toward];
            // One third of the way from the corner toward `toward`: index 1 or 2 along the edge.
            let step = |from: usize, to: usize| match (from, to) {
                (0, 3) => 1,
                (3, 0) => 2,
                _ => from,
            };
            let (ei, ej) = (step(i, ti), step(j, tj));
            interior(&level, face, v, 0.5, &mut net[ei][ej]);
            interior(&level, other as usize, v, 0.5, &mut net[ei][ej]);
        }
    }
    Ok(net.map(|row| row.map(to_stencil)))
}

/// Value and derivative weights of the 16 Bézier points at `(u, v)`, in `[i][j]` order.
pub fn bezier_weights(u: f64, v: f64) -> [[[f64; 3]; 4]; 4] {
    let b = crate::limit::basis::bezier_curve_weights;
    let ((bu, du), (bv, dv)) = (b(u), b(v));
    let mut w = [[[0.0; 3]; 4]; 4];
    for i in 0..4 {
        for j in 0..4 {
            w[i][j] = [bu[i] * bv[j], du[i] * bv[j], bu[i] * dv[j]];
        }
    }
    w
}

/// Position and derivatives of an ACC-1 patch at `(u, v)` from its stencils and the level's
/// points.
pub fn evaluate(net: &[[Stencil; 4]; 4], points: &[[f64; 3]], u: f64, v: f64) -> [[f64; 3]; 3] {
    let w = bezier_weights(u, v);
    let mut out = [[0.0; 3]; 3];
    for i in 0..4 {
        for j in 0..4 {
            let p = net[i][j].apply(points);
            for (o, wk) in out.iter_mut().zip(w[i][j]) {
                for d in 0..3 {
                    o[d] += wk * p[d];
                }
            }
        }
    }
    out
}

/// Bernstein values of degree 2 and 3 at `t`.
fn bernstein23(t: f64) -> ([f64; 3], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s, 2.0 * t * s, t * t],
        [s * s * s, 3.0 * t * s * s, 3.0 * t * t * s, t * t * t],
    )
}

/// The shading normal of an ACC-1 patch from its two tangent patches (Loop & Schaefer 2008):
/// the `u`-tangent patch is quadratic in `u`, cubic in `v`, the `v`-tangent patch the
/// transpose, their cross product the normal.
///
/// `points` is the patch in the plan's layout (`AdaptivePatch::tangent_valences`): the 20
/// points of the Gregory form of the Bézier net (per corner `P, Ep, Em, Fp, Fm`), then per
/// corner the limit-tangent points `Ep, Em` of [`crate::patches::gregory`]; `valences` the corners'.
///
/// Construction: start from the geometry patch's derivative. On the patch's own boundary the
/// tangent along the edge becomes the quadratic [corner limit tangent, middle derivative,
/// corner limit tangent], shared by both faces of the edge. Across an edge, ACC-1's inner
/// cross-boundary derivatives of the two faces cancel (an edge point is the midpoint of the
/// two inner points), while at the ends the limit tangents sum to `2 cos(2π/n)` times the edge
/// tangent. Each side adds half of `λ(t)·T(t)`, with `λ` linear from `2 cos(2π/n₀)` to
/// `−2 cos(2π/n₁)` and `T` the edge tangent, so the two cross-boundary derivatives sum to `λ·T`
/// along the whole edge: the normals of both faces agree there. At valence 4 nothing is added
/// and the tangent patches are the geometry patch's derivatives.
pub fn tangent_normal(points: &[[f64; 3]; 28], valences: [u8; 4], u: f64, v: f64) -> [f64; 3] {
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let scale = |a: [f64; 3], s: f64| [a[0] * s, a[1] * s, a[2] * s];
    let add = |a: [f64; 3], b: [f64; 3]| [a[0] + b[0], a[1] + b[1], a[2] + b[2]];
    // Bézier net b[i][j] from the Gregory form (slots as in the plan's assembly).
    const SLOTS: [[(usize, usize); 4]; 4] = [
        [(0, 0), (1, 0), (0, 1), (1, 1)],
        [(3, 0), (3, 1), (2, 0), (2, 1)],
        [(3, 3), (2, 3), (3, 2), (2, 2)],
        [(0, 3), (0, 2), (1, 3), (1, 2)],
    ];
    let mut b = [[[0.0; 3]; 4]; 4];
    for (c, slots) in SLOTS.iter().enumerate() {
        for (k, &(i, j)) in slots.iter().enumerate() {
            b[i][j] = points[5 * c + k];
        }
    }
    // Limit tangents per corner, as derivatives along +u / +v.
    let t = |c: usize, k: usize, sign: f64| {
        scale(sub(points[20 + 2 * c + k], points[5 * c]), 3.0 * sign)
    };
    let (tu00, tv00) = (t(0, 0, 1.0), t(0, 1, 1.0));
    let (tv10, tu10) = (t(1, 0, 1.0), t(1, 1, -1.0));
    let (tu11, tv11) = (t(2, 0, -1.0), t(2, 1, -1.0));
    let (tv01, tu01) = (t(3, 0, -1.0), t(3, 1, 1.0));
    let c = valences.map(|n| {
        if n == 0 {
            0.0
        } else {
            (std::f64::consts::TAU / n as f64).cos()
        }
    });
    let (c00, c10, c11, c01) = (c[0], c[1], c[2], c[3]);
    // Half of λ·T's two inner cubic control vectors, λ from c0 (start) to −c1 (end).
    let half_lambda_t = |t0: [f64; 3], t1: [f64; 3], t2: [f64; 3], c0: f64, c1: f64| {
        (
            scale(add(scale(t0, -c1), scale(t1, 2.0 * c0)), 1.0 / 3.0),
            scale(add(scale(t1, -2.0 * c1), scale(t2, c0)), 1.0 / 3.0),
        )
    };
    // u-tangent patch U[i][j], i = 0..3 (quadratic in u), j = 0..4.
    let mut tu = [[[0.0; 3]; 4]; 3];
    for (i, row) in tu.iter_mut().enumerate() {
        for (j, x) in row.iter_mut().enumerate() {
            *x = scale(sub(b[i + 1][j], b[i][j]), 3.0);
        }
    }
    tu[0][0] = tu00;
    tu[2][0] = tu10;
    tu[0][3] = tu01;
    tu[2][3] = tu11;
    let mid = |a: [f64; 3], b2: [f64; 3]| scale(sub(b2, a), 3.0);
    let (a1, a2) = half_lambda_t(tv00, mid(b[0][1], b[0][2]), tv01, c00, c01);
    tu[0][1] = add(tu[0][1], a1);
    tu[0][2] = add(tu[0][2], a2);
    let (a1, a2) = half_lambda_t(tv10, mid(b[3][1], b[3][2]), tv11, c10, c11);
    tu[2][1] = sub(tu[2][1], a1);
    tu[2][2] = sub(tu[2][2], a2);
    // v-tangent patch V[i][j], i = 0..4, j = 0..3 (quadratic in v).
    let mut tv = [[[0.0; 3]; 3]; 4];
    for (i, col) in tv.iter_mut().enumerate() {
        for (j, x) in col.iter_mut().enumerate() {
            *x = scale(sub(b[i][j + 1], b[i][j]), 3.0);
        }
    }
    tv[0][0] = tv00;
    tv[0][2] = tv01;
    tv[3][0] = tv10;
    tv[3][2] = tv11;
    let (a1, a2) = half_lambda_t(tu00, mid(b[1][0], b[2][0]), tu10, c00, c10);
    tv[1][0] = add(tv[1][0], a1);
    tv[2][0] = add(tv[2][0], a2);
    let (a1, a2) = half_lambda_t(tu01, mid(b[1][3], b[2][3]), tu11, c01, c11);
    tv[1][2] = sub(tv[1][2], a1);
    tv[2][2] = sub(tv[2][2], a2);
    let ((qu, cu), (qv, cv)) = (bernstein23(u), bernstein23(v));
    let (mut du, mut dv) = ([0.0; 3], [0.0; 3]);
    for i in 0..3 {
        for j in 0..4 {
            du = add(du, scale(tu[i][j], qu[i] * cv[j]));
            dv = add(dv, scale(tv[j][i], cu[j] * qv[i]));
        }
    }
    crate::limit::eval::normal_of(&du, &dv)
}
