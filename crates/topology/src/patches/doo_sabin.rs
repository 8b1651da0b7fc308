//! Doo-Sabin vertex patches (Fan and Cheng, "GPU supported patch-based tessellation for dual
//! subdivision", §2): after one Doo-Sabin step of the control mesh
//! ([`crate::refine::doo_sabin::refine_dual`]), each interior control vertex `v` of valence
//! `n` owns a *vertex patch*: its v-face, the `n` e-faces of its edges and the `n` f-faces of
//! its faces. A patch is refined on its own, as a one-dimensional array, and its faces are read
//! back from the array by index arithmetic alone.
//!
//! # The layout (derived here; the seed's formulas are partly misprinted)
//!
//! At depth `d ≥ 1` (the level-`d` mesh of the whole refinement) a patch has `L + 1` *vertex
//! layers*, `L = 2^(d−1)`. Layer `l` holds `(2l + 1) n` points, from `l² n` on (0-based here;
//! the seed counts from 1). It is cut into `n` *sides* of `2l + 1` points; side `j` starts at its
//! *corner point* `C(l, j) = l² n + j (2l + 1)`. Layer 0 is the v-face, in the order of the
//! faces `f_0 … f_{n−1}` around `v` (each the face across the previous one's edge entering `v`),
//! which is the refined mesh's orientation. The faces, corners listed in that orientation:
//!
//! - the **v-face** `[0, 1, …, n − 1]`;
//! - a **regular quad** for each point `i` of layer `l < L` (side `j`, offset `k = i − C(l, j)`):
//!   `[i, i + Δ, i + Δ + 1, next(i)]`, `Δ(l, j) = (2l + 1) n + 2j + 1` (a point's partner one
//!   layer out, same side, one offset further), `next(i)` the following point of layer `l`
//!   (cyclically);
//! - a **corner quad** for each side `j` of layer `l < L − 1`:
//!   `[C(l, j), C(l+1, j) − 1, C(l+1, j), C(l+1, j) + 1]` (`C(l+1, 0) − 1` wraps to the end of
//!   layer `l + 1`);
//! - an **outer corner face** for each side `j`: the f-face that descends from `f_j`, with the
//!   size `m_j` of `f_j` (quads only when `f_j` is). Its points are kept in *corner slots* after
//!   the layers (slot `i` the corner `i` steps after the one at `C(L − 1, j)`), as the seed's
//!   virtual corner faces (§2.2); slots `1` and `m_j − 1` are also the layer points
//!   `C(L, j) − 1` and `C(L, j) + 1`, slot `0` is `C(L − 1, j)`, and slot `2` is `C(L, j)` when
//!   `m_j = 4`. When `m_j ≠ 4`, `C(L, j)` is a *dead* point, never read.
//!
//! One step (depth `d` → `d + 1`) makes the Doo-Sabin children of every face and writes them
//! where they belong at depth `d + 1`; every point of depth `d + 1` is written by exactly one
//! face (its corner slots and their copies by the outer corner face):
//!
//! - the v-face's corner `j` → `j`;
//! - the regular quad at `i = C(l, j) + k` → the regular quad at `i' = C(2l + 1, j) + 2k + 1`
//!   with `Δ' = Δ(2l + 1, j)`: `[i', i' + Δ', i' + Δ' + 1, i' + 1]`. (The seed's step size
//!   `E = i + 1 − C` is written with `C(l+1, j)` in §2.1 and `C(l, j)` in its algorithm, and its
//!   new quad lists `i' + Δ'` twice; counting the points of a side — the corner's child, then two
//!   per regular quad — gives the offset `2k + 1` used here.)
//! - the corner quad at `(l, j)` → the corner quad at `(2l + 1, j)`;
//! - the outer corner face `j` → its corner slots at depth `d + 1`, and the copies above.
//!
//! The *outer face layer* (the regular quads of layer `L − 1` and the outer corner faces) is
//! shared: side `j`'s strip with the patch across the edge from `v` to the corner before `v` in
//! `f_j`, corner face `j` with the patches of all corners of `f_j`. For drawing each is *owned*
//! by one patch ([`VertexPatch::owns_side`], [`VertexPatch::owns_corner`]): a strip by the patch
//! of the smaller vertex, a corner face by the patch of the face's first interior vertex (in its
//! face-vertex order). Inner faces belong to their patch alone.
//!
//! Only interior vertices have patches: a boundary vertex has no v-face (its level-1 face is a
//! strip face, [`crate::rules::doo_sabin`]), and its region is not covered by vertex patches.
//! Faces of an interior vertex's patch never hold boundary points, so every face of a patch is
//! refined with Doo-Sabin's own mask ([`crate::rules::doo_sabin::alpha`]).

use crate::error::TopologyError;
use crate::mesh::{Topology, INVALID};
use crate::refine::doo_sabin::{boundary_vertices, corner_child, fan, DualStep};
use crate::rules::doo_sabin::alpha;

/// The shape of a vertex patch: the valence of its vertex and the sizes of its corner faces.
#[derive(Clone, Copy, Debug)]
pub struct PatchLayout<'a> {
    /// The valence `n` (points per side of layer 0).
    pub valence: usize,
    /// `m_j`, the size of corner face `j`.
    pub corner_sizes: &'a [usize],
}

/// Which face of a patch a [`PatchFace`] is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum PatchFaceKind {
    /// The v-face (layer 0).
    VFace,
    /// The regular quad at point `C(layer, side) + offset` of its inner layer.
    Regular {
        layer: usize,
        side: usize,
        offset: usize,
    },
    /// The corner quad of `side` between layers `layer` and `layer + 1` (not the outer one).
    Corner { layer: usize, side: usize },
    /// The outer corner face of `side` (in corner slots).
    OuterCorner { side: usize },
}

/// One face of a patch at a depth: its corners (indices into the patch array) and, for each
/// corner, where its Doo-Sabin child goes at the next depth (first the child's own place, then
/// its copies).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct PatchFace {
    pub kind: PatchFaceKind,
    pub corners: Vec<usize>,
    pub children: Vec<Vec<usize>>,
}

impl PatchLayout<'_> {
    /// `L = 2^(d−1)`, the outer vertex layer at depth `d ≥ 1`.
    pub fn outer_layer(depth: u32) -> usize {
        1 << (depth - 1)
    }

    /// `C(l, j)`: the corner point of side `j` of layer `l`.
    pub fn corner_point(&self, l: usize, j: usize) -> usize {
        l * l * self.valence + j * (2 * l + 1)
    }

    /// `Δ(l, j)`: from a point of side `j` of layer `l` to its partner in layer `l + 1`.
    pub fn delta(&self, l: usize, j: usize) -> usize {
        (2 * l + 1) * self.valence + 2 * j + 1
    }

    /// The number of layer points at depth `d`, `(L + 1)² n`.
    pub fn layer_points(&self, depth: u32) -> usize {
        let l = Self::outer_layer(depth) + 1;
        l * l * self.valence
    }

    /// The first corner slot of corner face `j` at depth `d`.
    pub fn slot(&self, depth: u32, j: usize) -> usize {
        self.layer_points(depth) + self.corner_sizes[..j].iter().sum::<usize>()
    }

    /// The length of the patch array at depth `d`.
    pub fn len(&self, depth: u32) -> usize {
        self.layer_points(depth) + self.corner_sizes.iter().sum::<usize>()
    }

    /// Whether the array is empty (never: a patch has a v-face).
    pub fn is_empty(&self, depth: u32) -> bool {
        self.len(depth) == 0
    }

    /// Whether point `i` at depth `d` is dead (`C(L, j)` of a corner face that is no quad).
    pub fn is_dead(&self, depth: u32, i: usize) -> bool {
        let outer = Self::outer_layer(depth);
        (0..self.valence).any(|j| self.corner_sizes[j] != 4 && self.corner_point(outer, j) == i)
    }

    /// The point before (`back`) or after point `i` of layer `l`, cyclically.
    fn step(&self, l: usize, i: usize, back: bool) -> usize {
        let start = l * l * self.valence;
        let count = (2 * l + 1) * self.valence;
        let k = i - start;
        start
            + if back {
                (k + count - 1) % count
            } else {
                (k + 1) % count
            }
    }

    /// The corner quad `[C(l, j), C(l+1, j) − 1, C(l+1, j), C(l+1, j) + 1]`.
    fn corner_quad(&self, l: usize, j: usize) -> [usize; 4] {
        let c = self.corner_point(l + 1, j);
        [
            self.corner_point(l, j),
            self.step(l + 1, c, true),
            c,
            self.step(l + 1, c, false),
        ]
    }

    /// Every face of the patch at depth `d`, with where its children go at depth `d + 1`.
    pub fn faces(&self, depth: u32) -> Vec<PatchFace> {
        let n = self.valence;
        let outer = Self::outer_layer(depth);
        let mut out = vec![PatchFace {
            kind: PatchFaceKind::VFace,
            corners: (0..n).collect(),
            children: (0..n).map(|j| vec![j]).collect(),
        }];
        for l in 0..outer {
            for j in 0..n {
                for k in 0..=2 * l {
                    out.push(self.regular(l, j, k));
                }
                if l + 1 < outer {
                    let child = self.corner_quad(2 * l + 1, j);
                    out.push(PatchFace {
                        kind: PatchFaceKind::Corner { layer: l, side: j },
                        corners: self.corner_quad(l, j).to_vec(),
                        children: child.iter().map(|&c| vec![c]).collect(),
                    });
                }
            }
        }
        for j in 0..n {
            out.push(self.outer_corner(depth, j));
        }
        out
    }

    fn regular(&self, l: usize, j: usize, k: usize) -> PatchFace {
        let i = self.corner_point(l, j) + k;
        let d = self.delta(l, j);
        let child = self.corner_point(2 * l + 1, j) + 2 * k + 1;
        let dc = self.delta(2 * l + 1, j);
        PatchFace {
            kind: PatchFaceKind::Regular {
                layer: l,
                side: j,
                offset: k,
            },
            corners: vec![i, i + d, i + d + 1, self.step(l, i, false)],
            children: vec![
                vec![child],
                vec![child + dc],
                vec![child + dc + 1],
                vec![child + 1],
            ],
        }
    }

    fn outer_corner(&self, depth: u32, j: usize) -> PatchFace {
        let m = self.corner_sizes[j];
        let (s, s_next) = (self.slot(depth, j), self.slot(depth + 1, j));
        let outer_next = Self::outer_layer(depth + 1);
        let c = self.corner_point(outer_next, j);
        let mut children: Vec<Vec<usize>> = (0..m).map(|i| vec![s_next + i]).collect();
        children[0].push(self.corner_point(outer_next - 1, j));
        children[1].push(self.step(outer_next, c, true));
        children[m - 1].push(self.step(outer_next, c, false));
        if m == 4 {
            children[2].push(c);
        }
        PatchFace {
            kind: PatchFaceKind::OuterCorner { side: j },
            corners: (s..s + m).collect(),
            children,
        }
    }

    /// One Doo-Sabin step of a patch array from depth `d` to `d + 1` (dead points stay 0).
    pub fn refine(&self, depth: u32, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut out = vec![[0.0; 3]; self.len(depth + 1)];
        for face in self.faces(depth) {
            let m = face.corners.len();
            for (i, targets) in face.children.iter().enumerate() {
                let mut p = [0.0; 3];
                for k in 0..m {
                    let w = alpha(m, k);
                    let q = points[face.corners[(i + k) % m]];
                    for c in 0..3 {
                        p[c] += w * q[c];
                    }
                }
                for &t in targets {
                    out[t] = p;
                }
            }
        }
        out
    }
}

/// The vertex patch of one interior control vertex, at depth 1.
#[derive(Clone, Debug)]
pub struct VertexPatch {
    /// The control vertex.
    pub vertex: u32,
    /// The control faces around it, `f_0 … f_{n−1}` (corner face `j` descends from `f_j`).
    pub faces: Vec<u32>,
    /// `m_j`, the size of `f_j`.
    pub corner_sizes: Vec<usize>,
    /// The patch array at depth 1, as level-1 vertices (`INVALID` at dead points).
    pub points: Vec<u32>,
    /// Whether this patch draws the strip of side `j` of its outer face layer.
    pub owns_side: Vec<bool>,
    /// Whether this patch draws outer corner face `j`.
    pub owns_corner: Vec<bool>,
}

impl VertexPatch {
    /// Its layout.
    pub fn layout(&self) -> PatchLayout<'_> {
        PatchLayout {
            valence: self.faces.len(),
            corner_sizes: &self.corner_sizes,
        }
    }

    /// Whether face `face` of the patch (from [`PatchLayout::faces`] at depth `d`) is drawn by
    /// this patch.
    pub fn draws(&self, depth: u32, face: &PatchFace) -> bool {
        let outer = PatchLayout::outer_layer(depth);
        match face.kind {
            PatchFaceKind::VFace | PatchFaceKind::Corner { .. } => true,
            PatchFaceKind::Regular { layer, side, .. } => layer + 1 < outer || self.owns_side[side],
            PatchFaceKind::OuterCorner { side } => self.owns_corner[side],
        }
    }
}

/// The vertex patches of the interior vertices of control mesh `p`, over `step`, its first
/// Doo-Sabin step ([`crate::refine::doo_sabin::refine_dual`] with `first`).
pub fn vertex_patches(p: &Topology, step: &DualStep) -> Result<Vec<VertexPatch>, TopologyError> {
    let boundary = boundary_vertices(p);
    let interior = |v: u32| !boundary[v as usize] && !p.vertex_faces(v as usize).is_empty();
    let mut out = Vec::new();
    for v in 0..p.num_vertices() {
        if !interior(v as u32) {
            continue;
        }
        let faces = fan(p, v, p.vertex_faces(v)[0]);
        if faces.len() != p.vertex_faces(v).len() || faces.len() < 3 {
            return Err(TopologyError::NonManifoldVertex {
                vertex: v as u32,
                fans: 2,
            });
        }
        out.push(patch_of(p, v as u32, faces, &interior));
    }
    debug_assert!(out.iter().all(|patch| patch
        .points
        .iter()
        .all(|&x| x == INVALID || (x as usize) < step.vertices.len())));
    Ok(out)
}

/// The corners of `f` from `v` on, in the face's order.
fn from_corner(p: &Topology, f: u32, v: u32) -> Vec<u32> {
    let fv = p.face_vertices(f as usize);
    let i = fv.iter().position(|&x| x == v).unwrap_or(0);
    (0..fv.len()).map(|k| fv[(i + k) % fv.len()]).collect()
}

fn patch_of(p: &Topology, v: u32, faces: Vec<u32>, interior: &dyn Fn(u32) -> bool) -> VertexPatch {
    let n = faces.len();
    let corner_sizes: Vec<usize> = faces
        .iter()
        .map(|&f| p.face_vertices(f as usize).len())
        .collect();
    let layout = PatchLayout {
        valence: n,
        corner_sizes: &corner_sizes,
    };
    let mut points = vec![INVALID; layout.len(1)];
    let mut owns_side = Vec::with_capacity(n);
    let mut owns_corner = Vec::with_capacity(n);
    for (j, &f) in faces.iter().enumerate() {
        let ring = from_corner(p, f, v);
        let m = ring.len();
        let (slot, c) = (layout.slot(1, j), layout.corner_point(1, j));
        for (i, &x) in ring.iter().enumerate() {
            points[slot + i] = corner_child(p, f, x);
        }
        points[j] = corner_child(p, f, v);
        points[layout.step(1, c, true)] = corner_child(p, f, ring[1]);
        points[c + 1] = corner_child(p, f, ring[m - 1]);
        if m == 4 {
            points[c] = corner_child(p, f, ring[2]);
        }
        // Side j's strip: the e-face of the edge from v to the corner before it in f_j.
        let u = ring[m - 1];
        points[c + 2] = corner_child(p, faces[(j + 1) % n], u);
        owns_side.push(!interior(u) || v < u);
        let first_interior = p
            .face_vertices(f as usize)
            .iter()
            .copied()
            .find(|&x| interior(x));
        owns_corner.push(first_interior == Some(v));
    }
    VertexPatch {
        vertex: v,
        faces,
        corner_sizes,
        points,
        owns_side,
        owns_corner,
    }
}
