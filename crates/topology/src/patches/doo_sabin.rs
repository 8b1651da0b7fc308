//! Doo-Sabin vertex patches (Fan and Cheng, "GPU supported patch-based tessellation for dual
//! subdivision", §2): after one Doo-Sabin step of the control mesh
//! ([`crate::refine::doo_sabin::refine_dual`]), each control vertex `v` of valence
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
//! Every face but the v-face and the outer corner faces is found from one inner point `i`
//! (`i < L² n`), as in the seed's algorithm: its layer is `⌊√⌊i / n⌋⌋`, and it starts its
//! regular quad, and its corner quad when it is a corner point ([`PatchLayout::faces_at_point`]),
//! so a step runs one thread per point with index arithmetic alone.
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
//! of the smaller vertex, a corner face by the patch of the face's first vertex (in its
//! face-vertex order). Inner faces belong to their patch alone.
//!
//! A boundary vertex's patch has its strip face ([`crate::rules::doo_sabin`]'s boundary rule)
//! for a v-face, and a wedge of *absent* points and faces beyond its boundary edge
//! ([`vertex_patches`]). Which points are present and which are boundary points is carried
//! from depth to depth ([`PointFlags`], [`PatchLayout::next_flags`]): a face is present when
//! its corners are, and a face holding boundary points is refined by the strip mask, as the
//! refiner does. Faces of an interior vertex's patch never hold boundary points.

use crate::error::TopologyError;
use crate::mesh::{Topology, INVALID};
use crate::refine::doo_sabin::{boundary_vertices, corner_child, fan, DualStep, DualVertex};
use crate::rules::doo_sabin::{corner_weights, strip_edge};
use std::collections::HashMap;

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
        for i in 0..outer * outer * n {
            out.extend(self.faces_at_point(depth, i));
        }
        for j in (0..n).filter(|&j| self.corner_sizes[j] > 0) {
            out.push(self.outer_corner(depth, j));
        }
        out
    }

    /// `(l, j, k)`: the layer, side and offset of point `i` (`l = ⌊√⌊i / n⌋⌋`, since layer `l`
    /// starts at `l² n`).
    pub fn point_position(&self, i: usize) -> (usize, usize, usize) {
        let l = (i / self.valence).isqrt();
        let r = i - l * l * self.valence;
        (l, r / (2 * l + 1), r % (2 * l + 1))
    }

    /// The faces point `i` of an inner layer (`i < L² n`) starts at depth `d`, as in the seed's
    /// algorithm (one thread per point): its regular quad, and its corner quad when it is a
    /// corner point below layer `L − 1`.
    pub fn faces_at_point(&self, depth: u32, i: usize) -> Vec<PatchFace> {
        let (l, j, k) = self.point_position(i);
        let mut out = vec![self.regular(l, j, k)];
        if k == 0 && l + 1 < Self::outer_layer(depth) {
            let child = self.corner_quad(2 * l + 1, j);
            out.push(PatchFace {
                kind: PatchFaceKind::Corner { layer: l, side: j },
                corners: self.corner_quad(l, j).to_vec(),
                children: child.iter().map(|&c| vec![c]).collect(),
            });
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

    /// The flags of every point at depth `d + 1` from those at depth `d`: a face is present when
    /// all its corners are, and its children are present and on the boundary when their parent
    /// corners are.
    pub fn next_flags(&self, depth: u32, flags: &[PointFlags]) -> Vec<PointFlags> {
        let mut out = vec![PointFlags::ABSENT; self.len(depth + 1)];
        for face in self.faces(depth) {
            if !face.corners.iter().all(|&c| flags[c].present) {
                continue;
            }
            for (&c, targets) in face.corners.iter().zip(&face.children) {
                for &t in targets {
                    out[t] = PointFlags {
                        present: true,
                        boundary: flags[c].boundary,
                    };
                }
            }
        }
        out
    }

    /// One Doo-Sabin step of a patch array from depth `d` to `d + 1` (the seed's "no numerical
    /// roundoff gaps": every copy of a shared point is computed by the same sum), each present
    /// face by its mask ([`corner_weights`]: a strip face's where it holds boundary points); points no
    /// present face writes stay 0.
    pub fn refine(
        &self,
        depth: u32,
        points: &[[f64; 3]],
        flags: &[PointFlags],
    ) -> Result<Vec<[f64; 3]>, TopologyError> {
        let mut out = vec![[0.0; 3]; self.len(depth + 1)];
        let mut w = Vec::new();
        for face in self.faces(depth) {
            if !face.corners.iter().all(|&c| flags[c].present) {
                continue;
            }
            let m = face.corners.len();
            let strip = strip_edge(m, |k| flags[face.corners[k]].boundary).map_err(|_| {
                TopologyError::UnsupportedScheme {
                    scheme: "doo-sabin",
                    operation: "a vertex patch face whose boundary points are not one edge",
                }
            })?;
            for (i, targets) in face.children.iter().enumerate() {
                corner_weights(m, strip, i, &mut w);
                // From the child's own corner on, in face order: the same sum in every patch
                // that holds the face (patches list a shared face from different corners, in
                // the same orientation), so all copies of a shared point have the same bits.
                let mut p = [0.0; 3];
                for (k, &wk) in w.iter().enumerate() {
                    let q = points[face.corners[(i + k) % m]];
                    for c in 0..3 {
                        p[c] += wk * q[c];
                    }
                }
                for &t in targets {
                    out[t] = p;
                }
            }
        }
        Ok(out)
    }
}

/// What a point of a patch array is.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PointFlags {
    /// Whether the point is a vertex of the refined mesh (not dead, not beyond the boundary).
    pub present: bool,
    /// Whether it is a boundary point (on the boundary polygon of its level).
    pub boundary: bool,
}

impl PointFlags {
    pub const ABSENT: PointFlags = PointFlags {
        present: false,
        boundary: false,
    };
    const INNER: PointFlags = PointFlags {
        present: true,
        boundary: false,
    };
    const BOUNDARY: PointFlags = PointFlags {
        present: true,
        boundary: true,
    };
}

/// The vertex patch of one control vertex, at depth 1.
#[derive(Clone, Debug)]
pub struct VertexPatch {
    /// The control vertex.
    pub vertex: u32,
    /// The control faces around it, `f_0 … f_{n−1}` (corner face `j` descends from `f_j`);
    /// `INVALID` for the two sides a boundary vertex has beyond its boundary edges.
    pub faces: Vec<u32>,
    /// `m_j`, the size of `f_j` (0 where there is no face).
    pub corner_sizes: Vec<usize>,
    /// The patch array at depth 1, as level-1 vertices (`INVALID` where no point is).
    pub points: Vec<u32>,
    /// The flags of the points at depth 1.
    pub flags: Vec<PointFlags>,
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

    /// The flags of its points at depths `1..=depth`.
    pub fn flags_to(&self, depth: u32) -> Vec<Vec<PointFlags>> {
        let layout = self.layout();
        let mut out = vec![self.flags.clone()];
        for d in 1..depth {
            let next = layout.next_flags(d, out.last().expect("depth 1 present"));
            out.push(next);
        }
        out
    }

    /// Whether face `face` of the patch (from [`PatchLayout::faces`] at depth `d`, `flags` its
    /// points' flags there) is drawn by this patch: present, and owned where shared.
    pub fn draws(&self, depth: u32, face: &PatchFace, flags: &[PointFlags]) -> bool {
        if !face.corners.iter().all(|&c| flags[c].present) {
            return false;
        }
        let outer = PatchLayout::outer_layer(depth);
        match face.kind {
            PatchFaceKind::VFace | PatchFaceKind::Corner { .. } => true,
            PatchFaceKind::Regular { layer, side, .. } => layer + 1 < outer || self.owns_side[side],
            PatchFaceKind::OuterCorner { side } => self.owns_corner[side],
        }
    }
}

impl VertexPatch {
    /// The patch array at depth `depth` as the refiner's level-`depth` vertex numbers
    /// (`INVALID` where no point is): the layout's maps run on level-`d` vertex numbers from
    /// depth 1 ([`VertexPatch::points`]) on, each present face found in `levels[d − 1]` (the
    /// topology of level `d`, as [`crate::refine::doo_sabin::refine_dual`] numbers it: the child
    /// of corner `k` of face `f` is vertex `face_offset(f) + k` of level `d + 1`). What a draw of
    /// the patch arrays maps its points back to the refined mesh by.
    pub fn level_vertices(
        &self,
        levels: &[&Topology],
        depth: u32,
    ) -> Result<Vec<u32>, TopologyError> {
        let layout = self.layout();
        let mut ids = self.points.clone();
        for d in 1..depth {
            let t = levels
                .get(d as usize - 1)
                .ok_or(TopologyError::UnsupportedScheme {
                    scheme: "doo-sabin",
                    operation: "vertex patch numbers without the refined level",
                })?;
            let mut next = vec![INVALID; layout.len(d + 1)];
            for face in layout.faces(d) {
                let corners: Vec<u32> = face.corners.iter().map(|&i| ids[i]).collect();
                if corners.contains(&INVALID) {
                    continue;
                }
                let f = level_face(t, &corners).ok_or(TopologyError::UnsupportedScheme {
                    scheme: "doo-sabin",
                    operation: "a vertex patch face that is no face of the refined level",
                })?;
                let offset = t.face_tables().0[f];
                let fv = t.face_vertices(f);
                for (&c, targets) in corners.iter().zip(&face.children) {
                    let k = fv.iter().position(|&x| x == c).unwrap_or(0) as u32;
                    for &target in targets {
                        next[target] = offset + k;
                    }
                }
            }
            ids = next;
        }
        Ok(ids)
    }
}

/// The face of `t` whose corners are `corners` (same cyclic order and orientation).
fn level_face(t: &Topology, corners: &[u32]) -> Option<usize> {
    t.vertex_faces(corners[0] as usize)
        .iter()
        .map(|&f| f as usize)
        .find(|&f| {
            let fv = t.face_vertices(f);
            let start = fv.iter().position(|&x| x == corners[0]).unwrap_or(0);
            fv.len() == corners.len()
                && (0..fv.len()).all(|k| fv[(start + k) % fv.len()] == corners[k])
        })
}

/// The vertex patches of control mesh `p` (one per vertex with faces, in vertex order), over
/// `step`, its first Doo-Sabin step ([`crate::refine::doo_sabin::refine_dual`] with `first`).
///
/// A boundary vertex with `k` faces has a patch of valence `k + 2`: its layer 0 is its strip
/// face (the children of its corners, then the Chaikin points of its last and first boundary
/// edges), sides `k − 1` and `k + 1` hold the strip quads of those edges, and side `k` (across
/// its boundary edge) and the corner faces of sides `k` and `k + 1` are absent.
pub fn vertex_patches(p: &Topology, step: &DualStep) -> Result<Vec<VertexPatch>, TopologyError> {
    let boundary = boundary_vertices(p);
    let chaikin = chaikin_points(p, step);
    let mut out = Vec::new();
    for (v, &on_boundary) in boundary.iter().enumerate() {
        let vf = p.vertex_faces(v);
        if vf.is_empty() {
            continue;
        }
        let non_manifold = || TopologyError::NonManifoldVertex {
            vertex: v as u32,
            fans: 2,
        };
        let start = if on_boundary {
            let first = vf.iter().copied().find(|&f| {
                let ring = from_corner(p, f, v as u32);
                edge_between(p, f, v as u32, ring[1]).is_some_and(|e| p.is_boundary_edge(e))
            });
            first.ok_or_else(non_manifold)?
        } else {
            vf[0]
        };
        let faces = fan(p, v, start);
        if faces.len() != vf.len() || (!on_boundary && faces.len() < 3) {
            return Err(non_manifold());
        }
        out.push(if on_boundary {
            boundary_patch(p, v as u32, faces, &chaikin)?
        } else {
            interior_patch(p, v as u32, faces)
        });
    }
    debug_assert!(out.iter().all(|patch| patch
        .points
        .iter()
        .all(|&x| x == INVALID || (x as usize) < step.vertices.len())));
    Ok(out)
}

/// The Chaikin point of boundary edge `e` next to its end `x`, by `(e, x)`.
fn chaikin_points(p: &Topology, step: &DualStep) -> HashMap<(u32, u32), u32> {
    let mut out = HashMap::new();
    for (i, origin) in step.vertices.iter().enumerate() {
        if let DualVertex::Chaikin { edge, end } = *origin {
            let x = p.edge_vertices(edge as usize)[end as usize];
            out.insert((edge, x), i as u32);
        }
    }
    out
}

/// The edge of face `f` joining `a` and `b`.
fn edge_between(p: &Topology, f: u32, a: u32, b: u32) -> Option<usize> {
    p.face_edge_list(f as usize)
        .iter()
        .map(|&e| e as usize)
        .find(|&e| {
            let [x, y] = p.edge_vertices(e);
            (x, y) == (a, b) || (x, y) == (b, a)
        })
}

/// The corners of `f` from `v` on, in the face's order.
fn from_corner(p: &Topology, f: u32, v: u32) -> Vec<u32> {
    let fv = p.face_vertices(f as usize);
    let i = fv.iter().position(|&x| x == v).unwrap_or(0);
    (0..fv.len()).map(|k| fv[(i + k) % fv.len()]).collect()
}

/// A patch at depth 1 with its points unset, `faces` padded to the valence.
fn empty_patch(v: u32, faces: Vec<u32>, sizes: Vec<usize>) -> VertexPatch {
    let n = faces.len();
    let len = PatchLayout {
        valence: n,
        corner_sizes: &sizes,
    }
    .len(1);
    VertexPatch {
        vertex: v,
        faces,
        corner_sizes: sizes,
        points: vec![INVALID; len],
        flags: vec![PointFlags::ABSENT; len],
        owns_side: vec![false; n],
        owns_corner: vec![false; n],
    }
}

impl VertexPatch {
    fn set(&mut self, i: usize, id: u32, flags: PointFlags) {
        self.points[i] = id;
        self.flags[i] = flags;
    }

    /// Corner face `j` (control face `f`, corners `ring` from the patch's vertex): its slots,
    /// its layer-0 point, the layer-1 points it shares with the layout, and its owner.
    fn set_corner_face(&mut self, p: &Topology, j: usize, f: u32, ring: &[u32]) {
        let layout = self.layout();
        let (slot, c) = (layout.slot(1, j), layout.corner_point(1, j));
        let before = layout.step(1, c, true);
        let m = ring.len();
        for (i, &x) in ring.iter().enumerate() {
            self.set(slot + i, corner_child(p, f, x), PointFlags::INNER);
        }
        self.set(j, corner_child(p, f, ring[0]), PointFlags::INNER);
        self.set(before, corner_child(p, f, ring[1]), PointFlags::INNER);
        self.set(c + 1, corner_child(p, f, ring[m - 1]), PointFlags::INNER);
        if m == 4 {
            self.set(c, corner_child(p, f, ring[2]), PointFlags::INNER);
        }
        self.owns_corner[j] = p.face_vertices(f as usize)[0] == ring[0];
    }
}

fn interior_patch(p: &Topology, v: u32, faces: Vec<u32>) -> VertexPatch {
    let n = faces.len();
    let sizes = faces
        .iter()
        .map(|&f| p.face_vertices(f as usize).len())
        .collect();
    let mut patch = empty_patch(v, faces.clone(), sizes);
    for (j, &f) in faces.iter().enumerate() {
        let ring = from_corner(p, f, v);
        patch.set_corner_face(p, j, f, &ring);
        // Side j's strip: the e-face of the edge from v to the corner before it in f_j.
        let u = ring[ring.len() - 1];
        let c = patch.layout().corner_point(1, j);
        patch.set(
            c + 2,
            corner_child(p, faces[(j + 1) % n], u),
            PointFlags::INNER,
        );
        patch.owns_side[j] = v < u;
    }
    patch
}

fn boundary_patch(
    p: &Topology,
    v: u32,
    faces: Vec<u32>,
    chaikin: &HashMap<(u32, u32), u32>,
) -> Result<VertexPatch, TopologyError> {
    let k = faces.len();
    let mut padded = faces.clone();
    padded.extend([INVALID, INVALID]);
    let mut sizes: Vec<usize> = faces
        .iter()
        .map(|&f| p.face_vertices(f as usize).len())
        .collect();
    sizes.extend([0, 0]);
    let mut patch = empty_patch(v, padded, sizes);
    let first_ring = from_corner(p, faces[0], v);
    let last_ring = from_corner(p, faces[k - 1], v);
    let (w, u) = (first_ring[1], last_ring[last_ring.len() - 1]);
    let e_first = edge_between(p, faces[0], v, w).unwrap_or(0) as u32;
    let e_last = edge_between(p, faces[k - 1], u, v).unwrap_or(0) as u32;
    let point = |e: u32, x: u32| {
        chaikin
            .get(&(e, x))
            .copied()
            .ok_or(TopologyError::UnsupportedScheme {
                scheme: "doo-sabin",
                operation: "vertex patches over a step without the control mesh's Chaikin points",
            })
    };
    for (j, &f) in faces.iter().enumerate() {
        let ring = from_corner(p, f, v);
        patch.set_corner_face(p, j, f, &ring);
        let u_j = ring[ring.len() - 1];
        if j + 1 < k {
            let c = patch.layout().corner_point(1, j);
            patch.set(c + 2, corner_child(p, faces[j + 1], u_j), PointFlags::INNER);
        }
        patch.owns_side[j] = v < u_j;
    }
    let layout = patch.layout();
    let (c_last, c_first) = (layout.corner_point(1, k - 1), layout.corner_point(1, k + 1));
    patch.set(k, point(e_last, v)?, PointFlags::BOUNDARY);
    patch.set(k + 1, point(e_first, v)?, PointFlags::BOUNDARY);
    patch.set(c_last + 2, point(e_last, u)?, PointFlags::BOUNDARY);
    patch.set(c_first + 1, point(e_first, w)?, PointFlags::BOUNDARY);
    patch.owns_side[k + 1] = v < w;
    Ok(patch)
}
