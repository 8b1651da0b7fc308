//! Patch nets: the frame of a face in its base face, the 4×4 regular net with phantoms, limit
//! stencils of corners, Bézier weights of patch edges.

use super::levels::Lvl;
use super::*;

/// Corner positions of the unit square, patch corner order.
pub(super) const POS: [(i32, i32); 4] = [(0, 0), (1, 0), (1, 1), (0, 1)];
/// Directions around a corner in its local frame (x toward the next corner, y the previous).
pub(super) const DIR: [(i32, i32); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

#[inline]
pub(super) const fn slot(a: i32, b: i32) -> usize {
    (4 * (b + 1) + (a + 1)) as usize
}

#[cfg(test)]
/// A linear combination of at most four global vertices (a gathered or phantom point).
#[derive(Clone, Copy, Debug, Default)]
pub(super) struct Combo {
    pub(super) n: u8,
    pub(super) idx: [u32; 4],
    pub(super) w: [f64; 4],
}

#[cfg(test)]
impl Combo {
    pub(super) fn one(i: u32) -> Combo {
        Combo {
            n: 1,
            idx: [i, 0, 0, 0],
            w: [1.0, 0.0, 0.0, 0.0],
        }
    }
    /// `2·a − b`. Phantoms extrapolate gathered points (one term each) or, at a corner,
    /// extrapolated ones (two terms each), so four terms always suffice.
    #[inline]
    pub(super) fn extrapolate(a: &Combo, b: &Combo) -> Combo {
        let mut c = Combo::default();
        let terms = (0..a.n as usize)
            .map(|k| (a.idx[k], 2.0 * a.w[k]))
            .chain((0..b.n as usize).map(|k| (b.idx[k], -b.w[k])));
        for (k, (i, w)) in terms.take(4).enumerate() {
            c.idx[k] = i;
            c.w[k] = w;
            c.n = k as u8 + 1;
        }
        c
    }
}

/// Rows of a patch's points over global ids, flat: one allocation per end cap instead of one
/// per point (thousands of end caps per plan).
#[derive(Clone, Debug, Default)]
pub(super) struct PointRows {
    ends: smallvec::SmallVec<[u32; 28]>,
    terms: Vec<(u32, f64)>,
}

impl PointRows {
    pub(super) fn with_capacity(terms: usize) -> PointRows {
        PointRows {
            ends: smallvec::SmallVec::new(),
            terms: Vec::with_capacity(terms),
        }
    }
    pub(super) fn push(&mut self, terms: impl IntoIterator<Item = (u32, f64)>) {
        self.terms.extend(terms);
        self.ends.push(self.terms.len() as u32);
    }
    pub(super) fn len(&self) -> usize {
        self.ends.len()
    }
    pub(super) fn clear(&mut self) {
        self.ends.clear();
        self.terms.clear();
    }
    pub(super) fn row(&self, k: usize) -> &[(u32, f64)] {
        let start = if k == 0 { 0 } else { self.ends[k - 1] as usize };
        &self.terms[start..self.ends[k] as usize]
    }
    /// Rows from stencils over a level's vertices, shifted to global ids by `base`.
    pub(super) fn from_stencils<'a>(
        base: u32,
        stencils: impl IntoIterator<Item = &'a crate::refine::stencil::Stencil>,
    ) -> PointRows {
        let mut out = PointRows::with_capacity(256);
        for st in stencils {
            out.push(
                st.indices
                    .iter()
                    .zip(&st.weights)
                    .map(|(&i, &w)| (i + base, w)),
            );
        }
        out
    }
}

/// Where a patch's face sits, for the passes after the patch list is made: the face of its
/// level, and the rotation from face corners to patch corners.
#[derive(Clone, Copy)]
pub(super) struct PatchSite {
    pub(super) face: u32,
    pub(super) shift: u8,
}

/// A patch whose face failed: its place in the list until the error is returned.
pub(super) fn placeholder_patch() -> AdaptivePatch {
    AdaptivePatch {
        kind: PatchKind::Bilinear,
        level: 0,
        control_points: ControlPoints::new(),
        base_face: INVALID,
        sub_face: 0,
        origin: [0.0; 2],
        size: 0.0,
        boundary_mask: 0,
        transition_mask: 0,
        edges: [BLANK_EDGE; 4],
        reparam_valences: [0; 4],
        tangent_valences: [0; 4],
    }
}

/// An edge before the edge pass sets its kind and curves.
pub(super) const BLANK_EDGE: PatchEdge = PatchEdge {
    kind: EdgeKind::Plain,
    curves: [INVALID; 2],
    reversed: [false; 2],
};

/// Base face, sub-face, origin, size and corner shift of face `f` of level `l`, by its whole
/// chain of parents (the reference for [`FrameMemo`]).
#[cfg(test)]
pub(super) fn frame(levels: &[Lvl], l: usize, f: usize) -> (u32, u8, [f64; 2], f64, u8) {
    let mut chain = [0u8; 16];
    let mut n = 0;
    let mut g = f;
    for k in (1..=l).rev() {
        let maps = levels[k].maps.as_ref().expect("refined level has maps");
        let p = maps.child_face_parent[g] as usize;
        chain[n] = (g - maps.face_first_child[p] as usize) as u8;
        n += 1;
        g = p;
    }
    let quad = levels[0].t().face_vertices(g).len() == 4;
    let (mut origin, mut size, mut shift, mut sub) = ([0.0, 0.0], 1.0, 0u8, 0u8);
    let mut children = chain[..n].iter().rev();
    if !quad {
        sub = children.next().copied().unwrap_or(0);
    }
    for &c in children {
        let pc = (c + 4 - shift) % 4;
        let (a, b) = POS[pc as usize];
        origin = [
            origin[0] + 0.5 * size * a as f64,
            origin[1] + 0.5 * size * b as f64,
        ];
        size *= 0.5;
        shift = (shift + 4 - c) % 4;
    }
    (g as u32, sub, origin, size, shift)
}

/// A face's frame: base face, sub-face, origin, size and corner shift (and whether the base
/// face is a quad).
#[derive(Clone, Copy, Debug)]
pub(super) struct Frame {
    pub(super) base: u32,
    pub(super) sub: u8,
    pub(super) shift: u8,
    quad: bool,
    pub(super) origin: [f64; 2],
    pub(super) size: f64,
}

/// Per level, the last face whose frame was asked for as a parent, and that frame. A face's
/// frame is its parent's extended by one step (the same arithmetic as a walk down its chain
/// from the base face, so the same bits): the patch pass meets faces in order, siblings
/// together, and finds their parent here instead of walking up to the base face
/// (catmark_car: ~200 → ~50 instructions per patch).
pub(super) struct FrameMemo {
    at: Vec<(u32, Frame)>,
}

impl FrameMemo {
    pub(super) fn new(levels: usize) -> FrameMemo {
        let blank = Frame {
            base: INVALID,
            sub: 0,
            shift: 0,
            quad: true,
            origin: [0.0; 2],
            size: 0.0,
        };
        FrameMemo {
            at: vec![(INVALID, blank); levels],
        }
    }

    /// The frame of face `f` of level `l`.
    pub(super) fn frame(&mut self, levels: &[Lvl], l: usize, f: usize) -> Frame {
        if l == 0 {
            return Frame {
                base: f as u32,
                sub: 0,
                shift: 0,
                quad: levels[0].t().face_vertices(f).len() == 4,
                origin: [0.0, 0.0],
                size: 1.0,
            };
        }
        let maps = levels[l].maps.as_ref().expect("refined level has maps");
        let p = maps.child_face_parent[f];
        let c = (f - maps.face_first_child[p as usize] as usize) as u8;
        let (h, mut fr) = self.at[l - 1];
        if h != p {
            fr = self.frame(levels, l - 1, p as usize);
            self.at[l - 1] = (p, fr);
        }
        if l == 1 && !fr.quad {
            fr.sub = c;
        } else {
            let pc = (c + 4 - fr.shift) % 4;
            let (a, b) = POS[pc as usize];
            fr.origin = [
                fr.origin[0] + 0.5 * fr.size * a as f64,
                fr.origin[1] + 0.5 * fr.size * b as f64,
            ];
            fr.size *= 0.5;
            fr.shift = (fr.shift + 4 - c) % 4;
        }
        fr
    }
}

/// The face corners and edges of `f` rotated into patch order.
pub(super) fn rotated(t: &Topology, f: usize, shift: u8) -> ([u32; 4], [u32; 4]) {
    let fv = t.face_vertices(f);
    let fe = t.face_edge_list(f);
    let s = shift as usize;
    (
        std::array::from_fn(|p| fv[(p + s) % 4]),
        std::array::from_fn(|p| fe[(p + s) % 4]),
    )
}

/// Slots of the three points of the face `step` faces around patch corner `p` (`step` 1 to 3
/// in `[p][step - 1]`), walking forward (across the edge entering the corner, the first table)
/// or backward (across the edge leaving it), in the order of that face's corners after the
/// patch corner: the corner's local frame (x toward the next corner, y toward the previous)
/// mapped into the 4×4 grid once, instead of per gathered point.
const GATHER_SLOTS: [[[[u8; 3]; 3]; 4]; 2] = gather_slots();

const fn gather_slots() -> [[[[u8; 3]; 3]; 4]; 2] {
    let mut out = [[[[0u8; 3]; 3]; 4]; 2];
    let mut p = 0;
    while p < 4 {
        let (ox, oy) = POS[p];
        let (nx, ny) = POS[(p + 1) % 4];
        let (px, py) = POS[(p + 3) % 4];
        let (xx, xy, yx, yy) = (nx - ox, ny - oy, px - ox, py - oy);
        let mut step = 1;
        while step <= 3 {
            let fwd = [
                DIR[step % 4],
                (
                    DIR[step % 4].0 + DIR[(step + 1) % 4].0,
                    DIR[step % 4].1 + DIR[(step + 1) % 4].1,
                ),
                DIR[(step + 1) % 4],
            ];
            let (ds, ds1) = (DIR[(4 - step % 4) % 4], DIR[(5 - step % 4) % 4]);
            let bwd = [ds1, (ds1.0 + ds.0, ds1.1 + ds.1), ds];
            let mut k = 0;
            while k < 3 {
                let (f, b) = (fwd[k], bwd[k]);
                out[0][p][step - 1][k] =
                    slot(ox + f.0 * xx + f.1 * yx, oy + f.0 * xy + f.1 * yy) as u8;
                out[1][p][step - 1][k] =
                    slot(ox + b.0 * xx + b.1 * yx, oy + b.0 * xy + b.1 * yy) as u8;
                k += 1;
            }
            step += 1;
        }
        p += 1;
    }
    out
}

/// One face of a level as the 16-point gather walks it: its corners and, per edge `i`, the
/// face across it, `INVALID` across a boundary or sharp edge (where a walk stops), in one
/// 32-byte record. A step of a walk around a corner then reads one cache line; read from the
/// topology it read four scattered ones (the face's corners, its edges, the edge's faces and
/// the edge's sharpness), and those misses were most of the gather's time on catmark_car.
/// A face that is not a quad has `INVALID` corners, so no walk finds its vertex in it.
#[derive(Clone, Copy, Debug)]
#[repr(C, align(32))]
pub(super) struct QuadRec {
    pub(super) verts: [u32; 4],
    pub(super) across: [u32; 4],
}

/// The [`QuadRec`] of every face of `lvl`, written into `out` (reused from level to level, so
/// its pages are faulted in once per plan, not once per level).
pub(super) fn quad_records(lvl: &Lvl, out: &mut Vec<QuadRec>) {
    const CHUNK: usize = 4096;
    let t = lvl.t();
    let blank = QuadRec {
        verts: [INVALID; 4],
        across: [INVALID; 4],
    };
    out.clear();
    out.resize(t.num_faces(), blank);
    out.par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(c, chunk)| {
            for (k, rec) in chunk.iter_mut().enumerate() {
                let f = c * CHUNK + k;
                let o = t.face_offsets[f] as usize;
                if t.face_offsets[f + 1] as usize != o + 4 {
                    continue;
                }
                for i in 0..4 {
                    rec.verts[i] = t.face_verts[o + i];
                    let e = t.face_edges[o + i] as usize;
                    let [x, y] = t.edge_faces[e];
                    rec.across[i] = if lvl.sharp_edge(e) {
                        INVALID
                    } else if x == f as u32 {
                        y
                    } else {
                        x
                    };
                }
            }
        });
}

/// The 4×4 points of a regular patch (level-local ids) with phantoms for the masked edges.
/// Returns the gathered global ids (`INVALID` where a phantom goes) and the boundary mask;
/// [`phantom_grid`] completes them (or finds a point missing). `quads` are the level's
/// [`quad_records`].
pub(super) fn gather_regular(
    lvl: &Lvl,
    quads: &[QuadRec],
    f: usize,
    shift: u8,
) -> Option<([u32; 16], u8)> {
    let rec = quads.get(f)?;
    if rec.verts[0] == INVALID {
        return None;
    }
    let s = shift as usize;
    if let Some(out) = gather_ring(lvl.base, quads, rec, f as u32, s) {
        return Some(out);
    }
    gather_walk(lvl.base, quads, f, shift)
}

/// [`gather_regular`] by walks around the corners, for any ring.
fn gather_walk(base: u32, quads: &[QuadRec], f: usize, shift: u8) -> Option<([u32; 16], u8)> {
    let rec = quads.get(f)?;
    if rec.verts[0] == INVALID {
        return None;
    }
    let s = shift as usize;
    let fv: [u32; 4] = std::array::from_fn(|p| rec.verts[(p + s) % 4]);
    let mut ids = [INVALID; 16];
    // A slot written twice (the points along an edge, reached from both its corners) must get
    // the same vertex both times; otherwise the ring is not the regular one.
    let set = |s: u8, v: u32, grid: &mut [u32; 16]| -> bool {
        let slot = &mut grid[s as usize];
        if *slot != INVALID {
            return *slot == base + v;
        }
        *slot = base + v;
        true
    };
    for p in 0..4 {
        let (ox, oy) = POS[p];
        if !set(slot(ox, oy) as u8, fv[p], &mut ids) {
            return None;
        }
    }
    for p in 0..4 {
        let v = fv[p];
        let start = rec.verts.iter().position(|&x| x == v)?;
        let mut steps = 0;
        // Forward: across the edge entering v; then backward, across the edge leaving v, for
        // what the forward walk could not reach (a boundary or sharp edge stops a walk).
        for (dir, slots) in GATHER_SLOTS.iter().enumerate() {
            let (mut g, mut k) = (rec, start);
            let last = if dir == 0 { 3 } else { 3 - steps };
            for step in 1..=last {
                let h = g.across[if dir == 0 { (k + 3) % 4 } else { k }];
                if h == INVALID || h == f as u32 {
                    break;
                }
                let hr = quads.get(h as usize)?;
                let hv = hr.verts;
                let kh = hv.iter().position(|&x| x == v)?;
                let [s0, s1, s2] = slots[p][step - 1];
                let (v0, v2) = if dir == 0 {
                    (hv[(kh + 1) % 4], hv[(kh + 3) % 4])
                } else {
                    (hv[(kh + 3) % 4], hv[(kh + 1) % 4])
                };
                if !(set(s0, v0, &mut ids)
                    && set(s1, hv[(kh + 2) % 4], &mut ids)
                    && set(s2, v2, &mut ids))
                {
                    return None;
                }
                g = hr;
                k = kh;
                if dir == 0 {
                    steps = step;
                }
            }
        }
    }
    // `across` is `INVALID` exactly across a sharp or boundary edge (`Lvl::sharp_edge`).
    let mut mask = 0u8;
    for p in 0..4 {
        if rec.across[(p + s) % 4] == INVALID {
            mask |= 1 << p;
        }
    }
    // Whether the phantoms can be completed is checked where they are built (the same error).
    Some((ids, mask))
}

/// Position of `v` among a face's corners (its first), 4 if absent.
#[inline]
fn corner_of(verts: &[u32; 4], v: u32) -> usize {
    let hits = (verts[0] == v) as u32
        | ((verts[1] == v) as u32) << 1
        | ((verts[2] == v) as u32) << 2
        | ((verts[3] == v) as u32) << 3;
    (hits | 16).trailing_zeros() as usize
}

/// Slot of patch corner `p`.
const CORNER_SLOTS: [usize; 4] = [slot(0, 0), slot(1, 0), slot(1, 1), slot(0, 1)];

/// The walks of [`gather_regular`] around the four corners visit each edge neighbour twice
/// (last face around one corner, first around the next) and set the points shared by
/// consecutive faces twice. These are the slot identities that let [`gather_ring`] visit each
/// ring face once and compare once instead.
const fn ring_slots_agree() -> bool {
    let [w, back] = &GATHER_SLOTS;
    let mut p = 0;
    while p < 4 {
        let q = (p + 1) % 4;
        if w[p][2][2] as usize != CORNER_SLOTS[q]
            || w[q][0][0] as usize != CORNER_SLOTS[p]
            || w[q][0][1] != w[p][2][0]
            || w[q][0][2] != w[p][2][1]
            || w[p][1][0] != w[p][0][2]
            || w[p][1][2] != w[p][2][0]
            // A backward walk's first face is the forward walk's last, read the other way.
            || back[p][0][0] != w[p][2][2]
            || back[p][0][1] != w[p][2][1]
            || back[p][0][2] != w[p][2][0]
        {
            return false;
        }
        p += 1;
    }
    // The corners, two points per edge neighbour and one per diagonal face fill the grid.
    let mut seen = 0u32;
    let mut p = 0;
    while p < 4 {
        seen |= 1 << CORNER_SLOTS[p] | 1 << w[p][2][0] | 1 << w[p][2][1] | 1 << w[p][1][1];
        p += 1;
    }
    seen == 0xffff
}
const _: () = assert!(ring_slots_agree());

/// [`gather_regular`] with each ring face visited once: per edge `e` not masked, the neighbour
/// `N_e` across it, and per corner `p` between two such edges the diagonal face `D_p` (across
/// `N_{p-1}`'s edge leaving the corner). `Some` only where the corner walks would visit the
/// same faces, stop at the same masked edges and set every slot consistently, with the same
/// ids; otherwise `None`, and the walks decide (the same outcome, or the error).
#[inline]
fn gather_ring(
    base: u32,
    quads: &[QuadRec],
    rec: &QuadRec,
    f: u32,
    s: usize,
) -> Option<([u32; 16], u8)> {
    let w = &GATHER_SLOTS[0];
    let v: [u32; 4] = std::array::from_fn(|p| rec.verts[(p + s) & 3]);
    // Distinct corners: a walk starts at the corner's own position in the face.
    if v[0] == v[1] || v[0] == v[2] || v[0] == v[3] || v[1] == v[2] || v[1] == v[3] || v[2] == v[3]
    {
        return None;
    }
    let across: [u32; 4] = std::array::from_fn(|e| rec.across[(e + s) & 3]);
    let mut ids = [INVALID; 16];
    let mut mask = 0u8;
    let mut nb = [rec; 4];
    let mut at = [0usize; 4];
    for e in 0..4 {
        ids[CORNER_SLOTS[e]] = base + v[e];
        if across[e] == INVALID {
            mask |= 1 << e;
            continue;
        }
        let r = quads.get(across[e] as usize)?;
        // Edge `e` runs `v[e] → v[e+1]` here and backward in `N_e`: `v[e]` follows `v[e+1]`
        // (which also tells `N_e` from this face, where it leads).
        let a = corner_of(&r.verts, v[e]);
        let b = corner_of(&r.verts, v[(e + 1) & 3]);
        if a > 3 || b != (a + 3) & 3 {
            return None;
        }
        ids[w[e][2][0] as usize] = base + r.verts[(a + 1) & 3];
        ids[w[e][2][1] as usize] = base + r.verts[(a + 2) & 3];
        nb[e] = r;
        at[e] = a;
    }
    for p in 0..4 {
        let q = (p + 3) & 3;
        match (mask >> q & 1 == 0, mask >> p & 1 == 0) {
            (true, true) => {
                let (m, am) = (nb[q], at[q]);
                let d = m.across[(am + 2) & 3];
                if d == f {
                    return None;
                }
                // `INVALID` (a sharp edge past the corner) is past the end.
                let dr = quads.get(d as usize)?;
                let k = corner_of(&dr.verts, v[p]);
                // The walk closes: `D_p`'s next face around the corner is `N_p`.
                if k > 3
                    || dr.across[(k + 3) & 3] != across[p]
                    || dr.verts[(k + 1) & 3] != m.verts[(am + 2) & 3]
                    || dr.verts[(k + 3) & 3] != nb[p].verts[(at[p] + 1) & 3]
                {
                    return None;
                }
                ids[w[p][1][1] as usize] = base + dr.verts[(k + 2) & 3];
            }
            // One masked edge at the corner: the walk from the other one stops at its
            // neighbour (a boundary or crease runs on through the corner).
            (true, false) => {
                if nb[q].across[(at[q] + 2) & 3] != INVALID {
                    return None;
                }
            }
            (false, true) => {
                if nb[p].across[at[p]] != INVALID {
                    return None;
                }
            }
            (false, false) => {}
        }
    }
    Some((ids, mask))
}

/// The 16 points of a regular patch from its gathered ids (the reference for
/// [`phantom_points`]): rows and columns across the
/// masked edges extrapolated (`2·P_edge − P_inner`), columns (edges 3 and 1) first where
/// their rows exist, then rows (edges 0 and 2), which gives the corner rule where two masked
/// edges meet. `None` if a point is missing.
#[cfg(test)]
pub(super) fn phantom_grid(ids: &[u32; 16], mask: u8) -> Option<[Combo; 16]> {
    let mut grid = [Combo::default(); 16];
    let mut known = [false; 16];
    for (s, &id) in ids.iter().enumerate() {
        if id != INVALID {
            grid[s] = Combo::one(id);
            known[s] = true;
        }
    }
    for b in -1..=2 {
        if (b == -1 && mask & 1 != 0) || (b == 2 && mask & 4 != 0) {
            continue;
        }
        for (bit, out, e, i) in [(8u8, -1, 0, 1), (2u8, 2, 1, 0)] {
            if mask & bit != 0 {
                let (se, si) = (slot(e, b), slot(i, b));
                if !(known[se] && known[si]) {
                    return None;
                }
                grid[slot(out, b)] = Combo::extrapolate(&grid[se], &grid[si]);
                known[slot(out, b)] = true;
            }
        }
    }
    for a in -1..=2 {
        for (bit, out, e, i) in [(1u8, -1, 0, 1), (4u8, 2, 1, 0)] {
            if mask & bit != 0 {
                let (se, si) = (slot(a, e), slot(a, i));
                if !(known[se] && known[si]) {
                    return None;
                }
                grid[slot(a, out)] = Combo::extrapolate(&grid[se], &grid[si]);
                known[slot(a, out)] = true;
            }
        }
    }
    known.iter().all(|&k| k).then_some(grid)
}

/// The points of a regular patch from its gathered ids (`INVALID` where none was gathered),
/// as `phantom_grid` makes them, without the grid: rows and columns across the masked edges
/// extrapolated (`2·P_edge − P_inner`), columns (edges 3 and 1) first where their rows
/// exist, then rows (edges 0 and 2). `cps` holds the gathered ids: each phantom's is
/// replaced, in slot order, by the id `row` gives its terms (2, or 4 at a corner where two
/// masked edges meet, in `Combo::extrapolate`'s order). Returns the phantoms' slots, or
/// `None` (and no row made) if a point is missing.
pub(super) fn phantom_points(
    ids: &[u32; 16],
    mask: u8,
    cps: &mut [u32],
    mut row: impl FnMut(&mut [(u32, f64)]) -> u32,
) -> Option<u32> {
    // Grid `(x, y)`, slot `4y + x`: columns 0 and 3 (edges 3 and 1), rows 0 and 3 (edges 0
    // and 2). The column phantoms are in the rows that are not phantoms.
    let col = [mask & 8 != 0, false, false, mask & 2 != 0];
    let rows = if mask & 1 != 0 { 0xf } else { 0 } | if mask & 4 != 0 { 0xf000 } else { 0 };
    let cols = (if col[0] { 0x1111 } else { 0 } | if col[3] { 0x8888 } else { 0 }) & !rows;
    let mut gathered = 0u32;
    for (s, &id) in ids.iter().enumerate() {
        gathered |= ((id != INVALID) as u32) << s;
    }
    // A column phantom extrapolates gathered points of its row; a row phantom, gathered points
    // or column phantoms of its column (rows 1 and 2); every other point is gathered.
    let col_src =
        (cols & 0x1111) << 1 | (cols & 0x1111) << 2 | (cols & 0x8888) >> 1 | (cols & 0x8888) >> 2;
    let row_src = if rows != 0 { 0x0ff0 } else { 0 };
    if col_src & !gathered != 0
        || row_src & !(gathered | cols) != 0
        || gathered | cols | rows != 0xffff
    {
        return None;
    }
    // Column phantom `(x, y)`: `(edge, inner)` ids of its row.
    let column = |x: usize, y: usize| -> [(u32, f64); 2] {
        let (e, i) = if x == 0 { (1, 2) } else { (2, 1) };
        [(ids[4 * y + e], 2.0), (ids[4 * y + i], -1.0)]
    };
    let phantoms = cols | rows;
    let mut m = phantoms;
    while m != 0 {
        let s = m.trailing_zeros() as usize;
        m &= m - 1;
        let (x, y) = (s % 4, s / 4);
        cps[s] = if cols & 1 << s != 0 {
            row(&mut column(x, y))
        } else {
            let (e, i) = if y == 0 { (1, 2) } else { (2, 1) };
            if col[x] {
                let [(e0, a0), (e1, a1)] = column(x, e);
                let [(i0, b0), (i1, b1)] = column(x, i);
                row(&mut [(e0, 2.0 * a0), (e1, 2.0 * a1), (i0, -b0), (i1, -b1)])
            } else {
                row(&mut [(ids[4 * e + x], 2.0), (ids[4 * i + x], -1.0)])
            }
        };
    }
    Some(phantoms)
}

/// Append a stencil row: indices sorted, duplicates merged.
pub(super) fn push_row(table: &mut StencilTable, terms: &mut [(u32, f64)]) {
    if terms.len() <= 4 {
        push_short_row(table, terms);
        return;
    }
    terms.sort_unstable_by_key(|t| t.0);
    push_sorted_row(table, terms);
}

/// [`push_row`] of at most four terms (phantoms' rows: 40k on catmark_car), inlined where the
/// count is known. Insertion sort is stable as the standard sort is on short slices, so
/// duplicates merge in the same order, into the same sums.
#[inline]
pub(super) fn push_short_row(table: &mut StencilTable, terms: &mut [(u32, f64)]) {
    for k in 1..terms.len() {
        let mut j = k;
        while j > 0 && terms[j].0 < terms[j - 1].0 {
            terms.swap(j, j - 1);
            j -= 1;
        }
    }
    push_sorted_row(table, terms);
}

/// Appends terms sorted by index as one row, duplicates summed in order.
#[inline]
fn push_sorted_row(table: &mut StencilTable, terms: &[(u32, f64)]) {
    let mut last = INVALID;
    for &(i, w) in terms {
        if i == last {
            if let Some(x) = table.weights.last_mut() {
                *x += w;
            }
        } else {
            table.indices.push(i);
            table.weights.push(w);
            last = i;
        }
    }
    table.offsets.push(table.indices.len() as u32);
}

/// Limit-position stencil (level-local ids) of vertex `v` of `lvl` (its ring complete).
/// Only positions are needed, and their masks do not depend on the ring's order, except a
/// dart's (walked as a fan from its sharp edge).
pub(super) fn limit_stencil(lvl: &Lvl, v: usize, out: &mut Vec<(u32, f64)>) {
    let t = lvl.t();
    let edges = t.vertex_edges(v);
    let faces = t.vertex_faces(v);
    let other = |e: u32| {
        let [a, b] = t.edge_vertices(e as usize);
        if a as usize == v {
            b
        } else {
            a
        }
    };
    let mut sharp = [0u32; 2];
    let mut count = 0;
    for &e in edges {
        if lvl.sharp_edge(e as usize) {
            if count < 2 {
                sharp[count] = e;
            }
            count += 1;
        }
    }
    let vs = lvl.topo.vertex_sharpness[v];
    let boundary = edges.len() != faces.len();
    let rule = if boundary && count < 2 {
        Rule::Corner
    } else {
        vertex_rule(vs, count)
    };
    let dart_fan = (rule == Rule::Dart)
        .then(|| crate::patches::gregory::build_fan(t, v as u32))
        .flatten();
    match (rule, &dart_fan) {
        (Rule::Corner, _) => out.push((v as u32, 1.0)),
        (Rule::Crease, _) => {
            out.push((v as u32, 2.0 / 3.0));
            for &e in &sharp {
                out.push((other(e), 1.0 / 6.0));
            }
        }
        (Rule::Dart, Some(fan)) => {
            // Its own limit position, over the ring in fan order from the sharp edge.
            let n = fan.ring.len();
            let edge = fan.edges.iter().position(|&e| e == sharp[0]).unwrap_or(0);
            let masks =
                crate::limit::masks::catmark_limit_masks(&crate::limit::masks::LimitVertex {
                    valence: n,
                    boundary: false,
                    rule: crate::limit::masks::LimitRule::Dart { edge },
                });
            let m = &masks.position;
            out.push((v as u32, m.vertex));
            for (i, &x) in fan.ring.iter().enumerate() {
                out.push((x, m.edges[i]));
            }
            for (i, &(g, c)) in fan.faces.iter().enumerate() {
                let fv = t.face_vertices(g as usize);
                out.push((fv[(c + 2) % fv.len()], m.faces[i]));
            }
        }
        // A ring `build_fan` cannot order (none is known: the ring is complete) keeps the
        // smooth mask rather than failing.
        (Rule::Smooth | Rule::Dart, _) => {
            let [wv, we, wf] = catmark_smooth_position_weights(edges.len());
            out.push((v as u32, wv));
            for &e in edges {
                out.push((other(e), we));
            }
            for &f in faces {
                let fv = t.face_vertices(f as usize);
                let c = fv.iter().position(|&x| x as usize == v).unwrap_or(0);
                out.push((fv[(c + 2) % fv.len()], wf));
            }
        }
    }
}

/// Per regular patch edge `p`: the slots of the four B-spline points along it (in the edge's
/// direction) and the slot step across it (the row or column on either side).
/// `glsl/adaptive/stencil.comp` holds the same table.
pub(super) const REGULAR_EDGE_LINES: [([usize; 4], usize); 4] = [
    ([4, 5, 6, 7], 4),
    ([2, 6, 10, 14], 1),
    ([11, 10, 9, 8], 4),
    ([13, 9, 5, 1], 1),
];

/// The Bézier points of regular patch edge `p`, in the edge's direction, from the patch's
/// control point at each slot: the uniform cubic B-spline across the edge (limit across it),
/// then along it converted to Bézier form.
pub(super) fn regular_edge_bezier(p: usize, cp: impl Fn(usize) -> [f64; 3]) -> [[f64; 3]; 4] {
    let (line, step) = REGULAR_EDGE_LINES[p];
    let q: [[f64; 3]; 4] = std::array::from_fn(|i| {
        let (a, b, c) = (cp(line[i] - step), cp(line[i]), cp(line[i] + step));
        std::array::from_fn(|x| (a[x] + 4.0 * b[x] + c[x]) / 6.0)
    });
    let mix = |w: [f64; 4]| -> [f64; 3] {
        std::array::from_fn(|x| w[0] * q[0][x] + w[1] * q[1][x] + w[2] * q[2][x] + w[3] * q[3][x])
    };
    [
        mix([1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0, 0.0]),
        mix([0.0, 2.0 / 3.0, 1.0 / 3.0, 0.0]),
        mix([0.0, 1.0 / 3.0, 2.0 / 3.0, 0.0]),
        mix([0.0, 1.0 / 6.0, 4.0 / 6.0, 1.0 / 6.0]),
    ]
}

/// Half `h` (0: first, 1: second) of a Bézier curve by de Casteljau, as weights over the
/// curve's four points.
pub(super) fn bezier_half(h: usize) -> [[f64; 4]; 4] {
    let first = [
        [1.0, 0.0, 0.0, 0.0],
        [0.5, 0.5, 0.0, 0.0],
        [0.25, 0.5, 0.25, 0.0],
        [0.125, 0.375, 0.375, 0.125],
    ];
    if h == 0 {
        first
    } else {
        // Mirror: the second half read backwards is the first half of the reversed curve.
        let mut out = [[0.0; 4]; 4];
        for (k, row) in first.iter().enumerate() {
            for (j, &w) in row.iter().enumerate() {
                out[3 - k][3 - j] = w;
            }
        }
        out
    }
}

/// Who computes a curve's inner points: (kind rank, patch, patch edge, part: 0 whole edge,
/// 1/2 first/second half of a coarse edge), packed into two words that compare in that order
/// (8 bytes a curve, not 12, aligned as [`crate::patches::adaptive::CurveOwner`], collected in place).
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord)]
pub(super) struct Owner {
    /// Rank, then the patch's high half.
    hi: u32,
    /// The patch's low half, edge, part.
    lo: u32,
}

impl Owner {
    pub(super) fn new(rank: u8, patch: u32, edge: u8, part: u8) -> Owner {
        Owner {
            hi: (rank as u32) << 16 | patch >> 16,
            lo: patch << 16 | (edge as u32) << 8 | part as u32,
        }
    }
    pub(super) fn rank(self) -> u8 {
        (self.hi >> 16) as u8
    }
    pub(super) fn patch(self) -> u32 {
        self.hi << 16 | self.lo >> 16
    }
    pub(super) fn edge(self) -> u8 {
        (self.lo >> 8) as u8
    }
    pub(super) fn part(self) -> u8 {
        self.lo as u8
    }
}

/// Added to a non-regular coarse patch's rank for the halves of its transition edges, so the
/// fine patch on the other side owns them (above every kind's rank, below the placeholder's).
pub(super) const HALF_RANK: u8 = 8;

pub(super) fn kind_rank(k: PatchKind) -> u8 {
    match k {
        PatchKind::Regular => 0,
        PatchKind::Gregory | PatchKind::GregoryTriangle => 1,
        PatchKind::Bilinear => 2,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A 3×3 grid of quads (vertex `4y + x`, face `3j + i`), counter-clockwise.
    fn grid() -> Vec<QuadRec> {
        let face = |i: i32, j: i32| {
            if (0..3).contains(&i) && (0..3).contains(&j) {
                (3 * j + i) as u32
            } else {
                INVALID
            }
        };
        let mut out = Vec::new();
        for j in 0..3 {
            for i in 0..3 {
                let v = |x: i32, y: i32| (4 * (j + y) + i + x) as u32;
                out.push(QuadRec {
                    verts: [v(0, 0), v(1, 0), v(1, 1), v(0, 1)],
                    across: [
                        face(i, j - 1),
                        face(i + 1, j),
                        face(i, j + 1),
                        face(i - 1, j),
                    ],
                });
            }
        }
        out
    }

    /// The phantoms made without the grid are the grid's, term for term, for every mask and
    /// missing points (rows pushed in slot order; `None` where the grid finds a point missing).
    #[test]
    fn phantom_points_match_the_grid() {
        let mut checked = 0;
        for mask in 0..16u8 {
            for holes in 0..(1u32 << 16) {
                // Points missing: any subset of the border slots, and one inner slot.
                let border = holes & 0xf99f;
                if border != holes && holes != 1 << 5 {
                    continue;
                }
                let ids: [u32; 16] = std::array::from_fn(|s| {
                    if holes >> s & 1 != 0 {
                        INVALID
                    } else {
                        100 + (s as u32 * 7) % 16
                    }
                });
                let grid = phantom_grid(&ids, mask);
                let mut cps = ids;
                let mut rows: Vec<Vec<(u32, f64)>> = Vec::new();
                let got = phantom_points(&ids, mask, &mut cps, |t| {
                    rows.push(t.to_vec());
                    1000 + rows.len() as u32 - 1
                });
                let Some(grid) = grid else {
                    assert_eq!(got, None, "mask {mask} holes {holes:x}");
                    assert!(rows.is_empty());
                    continue;
                };
                let mut want = Vec::new();
                let mut slots = 0u32;
                for (s, c) in grid.iter().enumerate() {
                    if c.n == 1 && c.w[0] == 1.0 {
                        assert_eq!(cps[s], c.idx[0]);
                    } else {
                        assert_eq!(cps[s], 1000 + want.len() as u32);
                        want.push((0..c.n as usize).map(|k| (c.idx[k], c.w[k])).collect());
                        slots |= 1 << s;
                    }
                }
                let bits = |r: &Vec<Vec<(u32, f64)>>| -> Vec<Vec<(u32, u64)>> {
                    r.iter()
                        .map(|t| t.iter().map(|&(i, w)| (i, w.to_bits())).collect())
                        .collect()
                };
                assert_eq!(bits(&rows), bits(&want), "mask {mask} holes {holes:x}");
                assert_eq!(got, Some(slots));
                checked += 1;
            }
        }
        assert!(checked > 16);
    }

    /// Short rows merge as the standard sort would: sorted, duplicates summed in order.
    #[test]
    fn short_rows_match_push_row() {
        let cases: [&[(u32, f64)]; 5] = [
            &[(5, 2.0), (3, -1.0)],
            &[(3, 2.0), (5, -1.0)],
            &[(4, 4.0), (4, -2.0), (2, -2.0), (4, 1.0)],
            &[(9, 0.1), (1, 0.2), (9, 0.3), (1, 0.4)],
            &[(7, 1.0)],
        ];
        for terms in cases {
            let mut a = StencilTable {
                offsets: vec![0],
                ..StencilTable::default()
            };
            let mut b = a.clone();
            let mut t = terms.to_vec();
            push_short_row(&mut a, &mut t);
            let mut t = terms.to_vec();
            t.sort_by_key(|x| x.0);
            let mut last = INVALID;
            for &(i, w) in &t {
                if i == last {
                    *b.weights.last_mut().unwrap() += w;
                } else {
                    b.indices.push(i);
                    b.weights.push(w);
                    last = i;
                }
            }
            b.offsets.push(b.indices.len() as u32);
            assert_eq!(a.indices, b.indices);
            assert_eq!(
                a.weights.iter().map(|w| w.to_bits()).collect::<Vec<_>>(),
                b.weights.iter().map(|w| w.to_bits()).collect::<Vec<_>>()
            );
            assert_eq!(a.offsets, b.offsets);
        }
    }

    /// The one-visit gather agrees with the corner walks wherever it answers, and answers on
    /// every face of a plain grid, boundary faces included.
    #[test]
    fn ring_gather_matches_walks() {
        let quads = grid();
        for f in 0..9 {
            for shift in 0..4u8 {
                let ring = gather_ring(7, &quads, &quads[f], f as u32, shift as usize);
                assert!(ring.is_some(), "face {f} shift {shift}");
                assert_eq!(ring, gather_walk(7, &quads, f, shift));
            }
        }
    }

    /// Broken rings around the middle face: the one-visit gather either agrees with the walks
    /// or leaves the answer to them, and a broken ring is never gathered.
    #[test]
    fn broken_rings_left_to_walks() {
        let mut rejected = 0;
        for g in (0..9).filter(|&g| g != 4) {
            for field in 0..8 {
                for value in [99, 4, (g as u32 + 1) % 9, INVALID] {
                    let mut quads = grid();
                    let rec = &mut quads[g];
                    if field < 4 {
                        rec.verts[field] = value;
                    } else {
                        rec.across[field - 4] = value;
                    }
                    for shift in 0..4u8 {
                        let walk = gather_walk(0, &quads, 4, shift);
                        match gather_ring(0, &quads, &quads[4], 4, shift as usize) {
                            Some(ring) => assert_eq!(Some(ring), walk),
                            None => rejected += 1,
                        }
                    }
                }
            }
        }
        assert!(rejected > 0);
        // A diagonal face that does not meet its edge neighbours is an error, not a patch.
        let mut quads = grid();
        quads[0].verts[1] = 99;
        assert_eq!(gather_ring(0, &quads, &quads[4], 4, 0), None);
        assert_eq!(gather_walk(0, &quads, 4, 0), None);
    }
}
