//! Basis-function tables (BFT) for Loop surfaces (Holländer & Boubekeur, section II).
//!
//! After one Loop step every triangle has at most one extraordinary vertex. For each valence
//! `n` and configuration case a table gives, at every dyadic point `(i, j)` of the triangle at
//! a maximum level `L` (`N = 2^L` segments per edge), the exact limit weights (position and the
//! parametric derivatives `du`, `dv`) over the face's ordered control points.
//!
//! # Supported cases ([`BftCase`])
//! * `Interior`: all three corners interior; `v0` has valence `n ≥ 3`, `v1`, `v2` valence 6.
//!   `n + 6` control points. `n = 6` is the regular patch.
//! * `Boundary { fan_position: k }`: `v0` is a boundary vertex with `n ≥ 2` edges (`n − 1`
//!   faces) and the face is face `k` of its fan (CCW from the first boundary edge); `v1`, `v2`
//!   are regular (valence 6 interior, or valence 4 on the boundary where the fan edge is a
//!   boundary edge). `n = 4` covers every face that touches the boundary without an
//!   extraordinary vertex, `n = 2` the corner child of a triangle with two boundary edges.
//!
//! * `Private { face }`: every other face gets a table of its own, exact limit weights over its
//!   one-ring neighbourhood ([`private_table`], [`neighbourhood_vertices`]), built by the same
//!   evaluator. This covers what the shared cases leave out: infinitely sharp and semi-sharp
//!   creases, "edges and corners" corner vertices, faces with two extraordinary vertices and the
//!   centre child of a base triangle with two or three boundary edges.
//!
//! The shared cases cover every face of a once-refined Loop mesh with "edges only" boundaries
//! and no creases except that centre child ([`classify_face`] returns `None` for it and for the
//! other faces above); [`build_patch_records`] gives each such face a `Private` key, so every
//! face of a level-1 Loop mesh is tabulated.
//!
//! # Control-point ordering ([`bft_face_ring`] / [`face_control_ring`]; shaders index by slot)
//! `v0` (the extraordinary vertex, else a boundary vertex, else corner 0), `v1`, `v2` in the
//! face's CCW order, then the one-ring of `v0` CCW starting at `v1`, the one-ring of `v1` CCW
//! starting at `v2`, the one-ring of `v2` CCW starting at `v0`, each vertex kept at its first
//! occurrence. Boundary fans are walked cyclically (past the gap).
//!
//! # Dyadic index mapping
//! Point `(i, j)` (`u = i/N`, `v = j/N`, `i + j ≤ N`) → row `row_map[i·(N+1) + j]` of the
//! table's row map ([`BasisTables::row_map_full`] or, for half tables,
//! [`BasisTables::row_map_half`], which stores only `i ≥ j`).
//!
//! # Mirror symmetry (≈ half the memory)
//! The reflection through `v0`'s bisector swaps `v1 ↔ v2` and `u ↔ v`. Interior tables and the
//! middle boundary fan position are self-symmetric: only rows `i ≥ j` are stored (`half`).
//! Boundary position `k` and `n − 2 − k` are mirror images: only `k ≤ n − 2 − k` is stored and
//! [`BasisTables::lookup`] reports `mirrored` for the other. The read, exactly as
//! [`BasisTables::row`] does it:
//!
//! ```text
//! (a, b, flip) = mirrored ? (j, i, true) : (i, j, false)
//! if half && a < b { swap(a, b); flip = !flip }
//! row  = (half ? row_map_half : row_map_full)[a·(N+1) + b]
//! slot = flip ? mirror_perm[offset_perm + s] : s          // for face slot s
//! pos[s] = weights[offset_position + row·ring_size + slot]
//! du[s], dv[s] = same from offset_du, offset_dv, exchanged when flip
//! ```
//!
//! # Flattened layout
//! [`BasisTables::weights`] concatenates, per stored entry ([`BftEntry`]), a position block and
//! (unless built without tangents) a `du` and a `dv` block, each `rows × ring_size` f32,
//! row-major. The GPU layout of tables and per-face [`PatchRecord`]s is `tess::bft` (tess owns
//! every GPU layout; this crate hands over the plain data).
//!
//! # Bit-identical shared edges
//! A point on an edge (or at a vertex) is never computed from the current face's table: every
//! face edge and corner names an *owner* (the face with the smallest index among the faces
//! that contain it, see [`PatchRecord`]); both neighbours evaluate the owner's row with the
//! owner's control points, summed in the owner's slot order ([`shader_eval`]). The owner's
//! edge rows are nonzero only on control points both faces share (exact zeros are stored as
//! 0.0), so the two invocations perform the same f32 operations on the same operands, and the
//! same holds for normals computed from the owner's `du`, `dv` ([`shader_eval_full`]). The
//! shader must run one code path for this sum (one function; `precise` keeps the compiler from
//! contracting it differently at different call sites). Tests emulate this in f32.

use rayon::prelude::*;
use std::collections::HashMap;

use crate::limit::eval::{EvalError, LimitScheme, LocalMesh};
use crate::rules::options::SubdivOptions;

/// Configuration of a face around its (possibly) extraordinary vertex `v0`.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub enum BftCase {
    Interior,
    Boundary {
        fan_position: u32,
    },
    /// A table private to one level-1 face that no shared case covers (a coarse mesh whose
    /// one-rings overlap, a corner triangle, an "edges and corners" corner, a crease): its
    /// rows are exact limit weights over the face's own neighbourhood ([`private_table`]).
    Private {
        face: u32,
    },
}

/// Table key: valence of `v0` (edge count) and case.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash, PartialOrd, Ord)]
pub struct BftKey {
    pub valence: u32,
    pub case: BftCase,
}

impl BftKey {
    /// The stored table serving this key, and whether the key is that table's mirror image.
    pub fn canonical(self) -> (BftKey, bool) {
        match self.case {
            BftCase::Interior | BftCase::Private { .. } => (self, false),
            BftCase::Boundary { fan_position: k } => {
                let m = self.valence.saturating_sub(2).saturating_sub(k);
                if k <= m {
                    (self, false)
                } else {
                    (
                        BftKey {
                            valence: self.valence,
                            case: BftCase::Boundary { fan_position: m },
                        },
                        true,
                    )
                }
            }
        }
    }

    fn self_symmetric(self) -> bool {
        match self.case {
            BftCase::Interior => true,
            BftCase::Boundary { fan_position: k } => 2 * k + 2 == self.valence,
            BftCase::Private { .. } => false,
        }
    }

    fn valid(self) -> bool {
        match self.case {
            BftCase::Interior => self.valence >= 3,
            BftCase::Private { .. } => false,
            BftCase::Boundary { fan_position } => {
                self.valence >= 2 && fan_position + 2 <= self.valence
            }
        }
    }
}

/// Radius (in lattice rings) of the configuration meshes: 2 covers the face's one-ring.
const RADIUS: u32 = 2;

/// Configuration mesh of a key: `v0` at the centre of `n` (interior) or `n − 1` (boundary)
/// regular lattice sectors. Points are 2D lattice positions lifted to `z = 0` when
/// `identity` is false, else unit vectors (one basis function per vertex). Returns the mesh
/// and the face index.
pub fn configuration_mesh(key: BftKey, identity: bool) -> Result<(LocalMesh, usize), EvalError> {
    if !key.valid() {
        return Err(EvalError::NoBftCase {
            key: format!("{key:?}"),
        });
    }
    let boundary = matches!(key.case, BftCase::Boundary { .. });
    let lattice = FanLattice::new(key.valence, boundary);
    let (sectors, r) = (lattice.sectors, RADIUS);
    let id = |s: u32, i: u32, j: u32| lattice.id(s, i, j);
    let mut fo = vec![0u32];
    let mut fv = Vec::new();
    let mut face = 0;
    for s in 0..sectors {
        for i in 0..r {
            for j in 0..r - i {
                if s == match key.case {
                    BftCase::Boundary { fan_position } => fan_position,
                    _ => 0,
                } && i == 0
                    && j == 0
                {
                    face = fo.len() - 1;
                }
                fv.extend_from_slice(&[id(s, i, j), id(s, i + 1, j), id(s, i, j + 1)]);
                fo.push(fv.len() as u32);
                if i + j + 2 <= r {
                    fv.extend_from_slice(&[id(s, i + 1, j), id(s, i + 1, j + 1), id(s, i, j + 1)]);
                    fo.push(fv.len() as u32);
                }
            }
        }
    }
    let (dim, points) = if identity {
        let nv = lattice.num_vertices();
        let mut p = vec![0.0; nv * nv];
        for v in 0..nv {
            p[v * nv + v] = 1.0;
        }
        (nv, p)
    } else {
        (3, lattice.planar_points())
    };
    let mesh = LocalMesh::from_faces(
        LimitScheme::Loop,
        SubdivOptions::default(),
        dim,
        points,
        fo,
        fv,
    )?;
    Ok((mesh, face))
}

/// The vertices of a configuration mesh: `v0` at the centre of `sectors` regular lattice
/// sectors of radius [`RADIUS`].
struct FanLattice {
    sectors: u32,
    boundary: bool,
    /// A sector's points (i ≥ 1, j ≥ 0, i + j ≤ R), and each one's place among them.
    per: Vec<(u32, u32)>,
    index: HashMap<(u32, u32), u32>,
    /// The first vertex of a boundary fan's closing ray.
    closing: u32,
}

impl FanLattice {
    /// `n` edges at `v0`: `n` sectors, or `n − 1` at a boundary.
    fn new(n: u32, boundary: bool) -> FanLattice {
        let sectors = if boundary { n - 1 } else { n };
        let r = RADIUS;
        // Vertex ids: centre 0; per sector the points (i ≥ 1, j ≥ 0, i + j ≤ R); a boundary fan
        // has one more closing ray (the last sector's (0, j)).
        let per: Vec<(u32, u32)> = (1..=r)
            .flat_map(|i| (0..=r - i).map(move |j| (i, j)))
            .collect();
        let index: HashMap<(u32, u32), u32> = per
            .iter()
            .enumerate()
            .map(|(k, &p)| (p, k as u32))
            .collect();
        let closing = sectors * per.len() as u32 + 1;
        FanLattice {
            sectors,
            boundary,
            per,
            index,
            closing,
        }
    }

    fn num_vertices(&self) -> usize {
        (self.closing + if self.boundary { RADIUS } else { 0 }) as usize
    }

    /// The vertex at lattice point `(i, j)` of sector `s`.
    fn id(&self, s: u32, i: u32, j: u32) -> u32 {
        let per = self.per.len() as u32;
        if i == 0 && j == 0 {
            0
        } else if i == 0 {
            if s + 1 == self.sectors && self.boundary {
                self.closing + j - 1
            } else {
                1 + ((s + 1) % self.sectors) * per + self.index[&(j, 0)]
            }
        } else {
            1 + s * per + self.index[&(i, j)]
        }
    }

    /// A planar fan, `z = 0`: sector s spans angles [s, s+1]·span (boundary fans cover a
    /// half-plane).
    fn planar_points(&self) -> Vec<f64> {
        let (sectors, r) = (self.sectors, RADIUS);
        let span = if self.boundary {
            std::f64::consts::PI / sectors as f64
        } else {
            2.0 * std::f64::consts::PI / sectors as f64
        };
        let mut p = vec![0.0; self.num_vertices() * 3];
        for s in 0..sectors {
            let (a0, a1) = (s as f64 * span, (s + 1) as f64 * span);
            for i in 0..=r {
                for j in 0..=r - i {
                    let v = self.id(s, i, j) as usize;
                    p[v * 3] = i as f64 * a0.cos() + j as f64 * a1.cos();
                    p[v * 3 + 1] = i as f64 * a0.sin() + j as f64 * a1.sin();
                }
            }
        }
        p
    }
}

/// The one-ring of `v` rotated to begin at `start` (no allocation: this runs per face).
fn ring_from(mesh: &LocalMesh, v: u32, start: u32) -> impl Iterator<Item = u32> + '_ {
    let ring = mesh.vertex_ring(v);
    let k = ring.iter().position(|&x| x == start).unwrap_or(0);
    ring[k..].iter().chain(&ring[..k]).copied()
}

/// Ordered control points of triangle `face` with corner `first` as `v0` (see module docs).
pub fn face_control_ring(mesh: &LocalMesh, face: usize, first: usize) -> Vec<u32> {
    let mut out = Vec::with_capacity(16);
    face_control_ring_into(mesh, face, first, &mut out);
    out
}

/// [`face_control_ring`] appended to `out` (the records' rings share one array).
fn face_control_ring_into(mesh: &LocalMesh, face: usize, first: usize, out: &mut Vec<u32>) {
    let f = mesh.face(face);
    let (v0, v1, v2) = (f[first % 3], f[(first + 1) % 3], f[(first + 2) % 3]);
    let start = out.len();
    out.extend([v0, v1, v2]);
    for (c, s) in [(v0, v1), (v1, v2), (v2, v0)] {
        for x in ring_from(mesh, c, s) {
            if !out[start..].contains(&x) {
                out.push(x);
            }
        }
    }
}

/// The table key of a face and its ordered control-vertex indices (rotated so the
/// extraordinary vertex — else a boundary vertex — comes first): the one call the GPU upload
/// needs per face. `None` where no table applies ([`classify_face`]).
pub fn bft_face_ring(mesh: &LocalMesh, face: usize) -> Option<(BftKey, Vec<u32>)> {
    let (key, first) = classify_face(mesh, face)?;
    Some((key, face_control_ring(mesh, face, first)))
}

/// (valence, boundary, fan position if boundary) of each corner starting at `first`.
fn corner_signature(mesh: &LocalMesh, face: usize, first: usize) -> [(usize, bool, usize); 3] {
    let f = mesh.face(face);
    let mut out = [(0, false, 0); 3];
    for (k, o) in out.iter_mut().enumerate() {
        let v = f[(first + k) % 3];
        let b = mesh.is_boundary_vertex(v);
        let pos = if b {
            mesh.vertex_faces(v)
                .position(|g| g == face as u32)
                .unwrap_or(0)
        } else {
            0
        };
        *o = (mesh.vertex_ring(v).len(), b, pos);
    }
    out
}

/// Per table key, what its configuration mesh's face looks like: corner signature and control
/// ring size (`None`: no configuration mesh). Building a configuration mesh per face dominated
/// preparation on large meshes (every face asked again for the same few keys).
type ConfigShapes = HashMap<BftKey, Option<ConfigShape>>;

/// A configuration mesh face's corner signature and its control ring size.
type ConfigShape = ([(usize, bool, usize); 3], usize);

fn config_shape(cache: &mut ConfigShapes, key: BftKey) -> Option<ConfigShape> {
    *cache.entry(key).or_insert_with(|| {
        let (cfg, cf) = configuration_mesh(key, false).ok()?;
        Some((
            corner_signature(&cfg, cf, 0),
            face_control_ring(&cfg, cf, 0).len(),
        ))
    })
}

/// The BFT case of a triangle of a Loop mesh and the corner to use as `v0`, or `None` when the
/// face is not covered by a table (see the module docs).
pub fn classify_face(mesh: &LocalMesh, face: usize) -> Option<(BftKey, usize)> {
    let creases = has_interior_creases(mesh);
    classify_face_cached(
        mesh,
        face,
        &mut ConfigShapes::new(),
        creases,
        &mut Vec::new(),
    )
}

/// Whether any edge that is not a boundary edge has a sharpness: without one, the per-face
/// crease test (an edge search per ring neighbour) cannot fail and is skipped.
fn has_interior_creases(mesh: &LocalMesh) -> bool {
    let t = &mesh.level.topology;
    mesh.level
        .edge_sharpness
        .iter()
        .enumerate()
        .any(|(e, &s)| s > 0.0 && !t.is_boundary_edge(e))
}

/// [`classify_face`] with the configuration shapes cached; the face's control ring is appended
/// to `ring` when a key is found (nothing is appended otherwise).
fn classify_face_cached(
    mesh: &LocalMesh,
    face: usize,
    shapes: &mut ConfigShapes,
    creases: bool,
    ring: &mut Vec<u32>,
) -> Option<(BftKey, usize)> {
    let f = mesh.face(face);
    if f.len() != 3 || mesh.scheme != LimitScheme::Loop {
        return None;
    }
    for &v in f {
        if mesh.vert_sharp(v) > 0.0 {
            return None;
        }
        if !creases {
            continue;
        }
        for &w in mesh.vertex_ring(v) {
            let s = mesh.edge_sharp(v, w);
            if s > 0.0 && !mesh.is_boundary_edge(v, w) {
                return None;
            }
        }
    }
    let sig = corner_signature(mesh, face, 0);
    // Candidate corners for v0 (fixed arrays: this runs per face).
    let pick = |keep: &dyn Fn(usize) -> bool| {
        let mut out = ([0usize; 3], 0usize);
        for k in (0..3).filter(|&k| keep(k)) {
            out.0[out.1] = k;
            out.1 += 1;
        }
        out
    };
    let irregular = pick(&|k| {
        let (n, b, _) = sig[k];
        (b && n != 4) || (!b && n != 6)
    });
    if irregular.1 > 1 {
        return None;
    }
    let mut candidates = irregular;
    if candidates.1 == 0 {
        candidates = pick(&|k| sig[k].1);
        if candidates.1 == 0 {
            candidates = ([0; 3], 1);
        }
    }
    for &c in &candidates.0[..candidates.1] {
        // The signature from corner c: the one above, rotated.
        let s = [sig[c % 3], sig[(c + 1) % 3], sig[(c + 2) % 3]];
        let key = BftKey {
            valence: s[0].0 as u32,
            case: if s[0].1 {
                BftCase::Boundary {
                    fan_position: s[0].2 as u32,
                }
            } else {
                BftCase::Interior
            },
        };
        let Some((cs, ring_len)) = config_shape(shapes, key) else {
            continue;
        };
        let same = (0..3)
            .all(|k| s[k].0 == cs[k].0 && s[k].1 == cs[k].1 && (!s[k].1 || s[k].2 == cs[k].2));
        if !same {
            continue;
        }
        let start = ring.len();
        face_control_ring_into(mesh, face, c, ring);
        if ring.len() - start == ring_len {
            return Some((key, c));
        }
        ring.truncate(start);
    }
    None
}

/// One stored table.
#[derive(Clone, Debug, PartialEq)]
pub struct BftEntry {
    pub key: BftKey,
    /// Number of control points (row stride).
    pub ring_size: u32,
    /// Rows `i ≥ j` only (use [`BasisTables::row_map_half`]).
    pub half: bool,
    pub rows: u32,
    /// Offsets (in f32 units) into [`BasisTables::weights`] of the position, `du` and `dv`
    /// blocks; row `r`, slot `s` is at `offset + r·ring_size + s`.
    pub offset_position: u32,
    pub offset_du: u32,
    pub offset_dv: u32,
    /// Offset into [`BasisTables::mirror_perm`] of this table's `ring_size` slot permutation.
    pub offset_perm: u32,
}

/// GPU-ready flattened tables at one maximum level.
#[derive(Clone, Debug, PartialEq)]
pub struct BasisTables {
    pub level: u32,
    /// Whether the `du`/`dv` blocks are present (else their offsets are `u32::MAX`).
    pub tangents: bool,
    pub weights: Vec<f32>,
    pub mirror_perm: Vec<u32>,
    pub entries: Vec<BftEntry>,
    /// `(N+1)²` entries, `i·(N+1) + j` → row, `u32::MAX` outside the triangle.
    pub row_map_full: Vec<u32>,
    /// Same for half tables (`i ≥ j` only; `u32::MAX` elsewhere).
    pub row_map_half: Vec<u32>,
}

/// Weights of one dyadic point over the face's slots.
#[derive(Clone, Debug, PartialEq)]
pub struct RowWeights {
    pub position: Vec<f32>,
    pub du: Vec<f32>,
    pub dv: Vec<f32>,
}

/// Resolution of the grid every table point lies on: `3·2^level` steps per edge.
pub fn grid_size(level: u32) -> u32 {
    3 << level
}

/// Interior points the triangle tessellator generates for inner level `s` (equal spacing), in
/// units of `1/(3s)`, as `(w1, w2)` (weights of `v1`, `v2`). Ring `r` (`1 ≤ r < s/2`) is the
/// triangle whose corners have barycentric coordinates `(3s − 4r, 2r, 2r)/(3s)` and its
/// permutations — the reference tessellator places inner corners on the lines perpendicular to
/// the outer edges, which is `2/3` of `r/s` in barycentric terms — with `s − 2r` equal
/// segments of length `1/s` per side; an even `s` adds the centre `(s, s, s)/(3s)`.
pub fn tessellator_interior_points(s: u32) -> Vec<(u32, u32)> {
    let mut out = Vec::new();
    let mut r = 1;
    while 2 * r < s {
        let (big, small) = (3 * s - 4 * r, 2 * r);
        let corners = [
            [big, small, small],
            [small, big, small],
            [small, small, big],
        ];
        for (side, &c) in corners.iter().enumerate() {
            let (from, to) = (side, (side + 1) % 3);
            for k in 0..s - 2 * r {
                let mut w = c;
                w[from] -= 3 * k;
                w[to] += 3 * k;
                out.push((w[1], w[2]));
            }
        }
        r += 1;
    }
    if s.is_multiple_of(2) && s >= 2 {
        out.push((s, s));
    }
    out
}

/// Points `(a, b)` of the `1/grid_size(level)` grid that carry a table row, sorted by
/// `(b, a)`: every dyadic point of the level, and the interior tessellator points of every
/// power-of-two inner level `2 ≤ s ≤ 2^level` (all on this grid, see
/// [`tessellator_interior_points`]). With power-of-two factors every vertex the tessellator
/// makes is one of these, so the TES evaluates the exact limit everywhere.
pub fn table_points(level: u32) -> Vec<(u32, u32)> {
    let n = 1u32 << level;
    let mut pts: Vec<(u32, u32)> = Vec::new();
    for j in 0..=n {
        for i in 0..=n - j {
            pts.push((3 * i, 3 * j));
        }
    }
    let mut s = 2;
    while s <= n {
        let scale = n / s;
        pts.extend(
            tessellator_interior_points(s)
                .into_iter()
                .map(|(a, b)| (a * scale, b * scale)),
        );
        s *= 2;
    }
    pts.sort_by_key(|&(a, b)| (b, a));
    pts.dedup();
    pts
}

fn row_maps(level: u32) -> (Vec<u32>, Vec<u32>) {
    let m = grid_size(level);
    let w = (m + 1) as usize;
    let mut full = vec![u32::MAX; w * w];
    let mut half = vec![u32::MAX; w * w];
    let (mut rf, mut rh) = (0u32, 0u32);
    for (a, b) in table_points(level) {
        full[a as usize * w + b as usize] = rf;
        rf += 1;
        if a >= b {
            half[a as usize * w + b as usize] = rh;
            rh += 1;
        }
    }
    (full, half)
}

/// Per row: (position, du, dv) weights over the slots.
pub type Rows = Vec<[Vec<f64>; 3]>;

/// Exact limit weights of one stored table, in f64, and its mirror permutation.
fn table_rows(key: BftKey, level: u32, half: bool) -> Result<(Rows, Vec<u32>), EvalError> {
    let (mesh, face) = configuration_mesh(key, true)?;
    let ring = face_control_ring(&mesh, face, 0);
    // Mirror permutation: the reflected configuration's ring order → this table's slots.
    let mut fo = vec![0u32];
    let mut fvs = Vec::new();
    for f in 0..mesh.num_faces() {
        let fv = mesh.face(f);
        fvs.extend_from_slice(&[fv[0], fv[2], fv[1]]);
        fo.push(fvs.len() as u32);
    }
    let nv = mesh.num_vertices();
    let reflected = LocalMesh::from_faces(
        LimitScheme::Loop,
        SubdivOptions::default(),
        1,
        vec![0.0; nv],
        fo,
        fvs,
    )?;
    let rring = face_control_ring(&reflected, face, 0);
    let perm: Vec<u32> = rring
        .iter()
        .map(|x| ring.iter().position(|y| y == x).unwrap_or(0) as u32)
        .collect();
    let m = grid_size(level) as f64;
    let mut rows = Vec::new();
    for (a, b) in table_points(level) {
        if half && a < b {
            continue;
        }
        let s = mesh.evaluate(face, a as f64 / m, b as f64 / m)?;
        let pick = |x: &[f64]| -> Vec<f64> {
            ring.iter()
                .map(|&v| {
                    let w = x[v as usize];
                    if w.abs() < 1e-13 {
                        0.0
                    } else {
                        w
                    }
                })
                .collect()
        };
        rows.push([pick(&s.position), pick(&s.du), pick(&s.dv)]);
    }
    Ok((rows, perm))
}

impl BasisTables {
    /// Build the tables (positions and tangents) serving `keys` at maximum level `level` (1–6).
    pub fn build(keys: &[BftKey], level: u32) -> Result<BasisTables, EvalError> {
        BasisTables::build_with(keys, level, true)
    }

    /// As [`BasisTables::build`]; `tangents = false` stores position weights only (a third of
    /// the memory, for subdivision shading that reuses the position weights for normals).
    pub fn build_with(
        keys: &[BftKey],
        level: u32,
        tangents: bool,
    ) -> Result<BasisTables, EvalError> {
        if !(1..=6).contains(&level) {
            return Err(EvalError::BftLevel { level });
        }
        let mut stored: Vec<BftKey> = keys
            .iter()
            .filter(|k| !matches!(k.case, BftCase::Private { .. }))
            .map(|k| k.canonical().0)
            .collect();
        stored.sort();
        stored.dedup();
        let (row_map_full, row_map_half) = row_maps(level);
        let mut t = BasisTables {
            level,
            tangents,
            weights: Vec::new(),
            mirror_perm: Vec::new(),
            entries: Vec::new(),
            row_map_full,
            row_map_half,
        };
        for key in stored {
            let half = key.self_symmetric();
            let (rows, perm) = table_rows(key, level, half)?;
            let ring_size = perm.len() as u32;
            let mut offs = [u32::MAX; 3];
            let blocks = if tangents { 3 } else { 1 };
            for (b, off) in offs.iter_mut().enumerate().take(blocks) {
                *off = t.weights.len() as u32;
                for r in &rows {
                    t.weights.extend(r[b].iter().map(|&w| w as f32));
                }
            }
            t.entries.push(BftEntry {
                key,
                ring_size,
                half,
                rows: rows.len() as u32,
                offset_position: offs[0],
                offset_du: offs[1],
                offset_dv: offs[2],
                offset_perm: t.mirror_perm.len() as u32,
            });
            t.mirror_perm.extend_from_slice(&perm);
        }
        Ok(t)
    }

    /// Tables for interior valences `valences` and, if `boundary`, every boundary fan position
    /// of boundary valences `2..=max(valences)`.
    pub fn build_for_valences(
        valences: std::ops::RangeInclusive<u32>,
        boundary: bool,
        level: u32,
    ) -> Result<BasisTables, EvalError> {
        let mut keys: Vec<BftKey> = valences
            .clone()
            .filter(|&n| n >= 3)
            .map(|n| BftKey {
                valence: n,
                case: BftCase::Interior,
            })
            .collect();
        if boundary {
            for n in 2..=*valences.end() {
                for k in 0..n - 1 {
                    keys.push(BftKey {
                        valence: n,
                        case: BftCase::Boundary { fan_position: k },
                    });
                }
            }
        }
        BasisTables::build(&keys, level)
    }

    /// Segments per edge at the maximum level.
    pub fn segments(&self) -> u32 {
        1 << self.level
    }

    /// Steps per edge of the grid that holds every table point ([`grid_size`]).
    pub fn grid(&self) -> u32 {
        grid_size(self.level)
    }

    /// Bytes the GPU needs: weights, permutations, row maps and 8 u32 per entry.
    pub fn memory_bytes(&self) -> usize {
        4 * (self.weights.len()
            + self.mirror_perm.len()
            + self.row_map_full.len()
            + self.row_map_half.len()
            + 8 * self.entries.len())
    }

    /// Entry index serving `key`, and whether the lookup is mirrored.
    pub fn lookup(&self, key: BftKey) -> Option<(usize, bool)> {
        let (canon, mirrored) = key.canonical();
        self.entries
            .iter()
            .position(|e| e.key == canon)
            .map(|i| (i, mirrored))
    }

    /// Weights of dyadic point `(i, j)` over the face's slots (face ring order), exactly as a
    /// shader reads them (`du`/`dv` empty without tangent blocks).
    pub fn row(&self, key: BftKey, i: u32, j: u32) -> Option<RowWeights> {
        if i + j > self.segments() {
            return None;
        }
        self.row_grid(key, 3 * i, 3 * j)
    }

    /// Weights of grid point `(a, b)` (`u = a/grid`, `v = b/grid`, [`table_points`]); `None`
    /// where the grid point carries no row.
    pub fn row_grid(&self, key: BftKey, a: u32, b: u32) -> Option<RowWeights> {
        let (e, mirrored) = self.lookup(key)?;
        let e = &self.entries[e];
        let m = self.grid();
        if a + b > m {
            return None;
        }
        let (mut a, mut b, mut flip) = if mirrored {
            (b, a, true)
        } else {
            (a, b, false)
        };
        if e.half && a < b {
            std::mem::swap(&mut a, &mut b);
            flip = !flip;
        }
        let map = if e.half {
            &self.row_map_half
        } else {
            &self.row_map_full
        };
        let r = map[(a * (m + 1) + b) as usize];
        if r == u32::MAX {
            return None;
        }
        let rs = e.ring_size as usize;
        let slot = |s: usize| {
            if flip {
                self.mirror_perm[e.offset_perm as usize + s] as usize
            } else {
                s
            }
        };
        let read = |off: u32| -> Vec<f32> {
            if off == u32::MAX {
                return Vec::new();
            }
            (0..rs)
                .map(|s| self.weights[off as usize + r as usize * rs + slot(s)])
                .collect()
        };
        let (du, dv) = if flip {
            (read(e.offset_dv), read(e.offset_du))
        } else {
            (read(e.offset_du), read(e.offset_dv))
        };
        Some(RowWeights {
            position: read(e.offset_position),
            du,
            dv,
        })
    }
}

/// Bytes [`BasisTables::build_with`] would use for `keys` at `level` (computed from the table
/// shapes without evaluating anything); with `mirror = false`, the size without the mirror
/// savings (every key stored with all rows), for comparison.
pub fn memory_for(
    keys: &[BftKey],
    level: u32,
    mirror: bool,
    tangents: bool,
) -> Result<usize, EvalError> {
    let mut stored: Vec<(BftKey, bool)> = keys
        .iter()
        .map(|k| {
            if mirror {
                (k.canonical().0, k.canonical().0.self_symmetric())
            } else {
                (*k, false)
            }
        })
        .collect();
    stored.sort();
    stored.dedup();
    let pts = table_points(level);
    let full = pts.len();
    let half = pts.iter().filter(|&&(a, b)| a >= b).count();
    let g = grid_size(level) as usize + 1;
    let maps = 2 * g * g;
    let mut words = maps;
    for (k, h) in stored {
        let (m, f) = configuration_mesh(k, false)?;
        let ring = face_control_ring(&m, f, 0).len();
        let rows = if h { half } else { full };
        let blocks = if tangents { 3 } else { 1 };
        words += blocks * rows * ring + ring + 8;
    }
    Ok(4 * words)
}

/// On-demand tables: built for the valences/cases a mesh actually uses.
#[derive(Clone, Debug)]
pub struct BftCache {
    pub level: u32,
    tables: Option<BasisTables>,
    keys: Vec<BftKey>,
}

impl BftCache {
    pub fn new(level: u32) -> BftCache {
        BftCache {
            level,
            tables: None,
            keys: Vec::new(),
        }
    }

    /// Tables covering `keys` (rebuilt only when a new key appears).
    pub fn tables_for(&mut self, keys: &[BftKey]) -> Result<&BasisTables, EvalError> {
        let mut changed = false;
        for k in keys {
            let c = k.canonical().0;
            if !self.keys.contains(&c) {
                self.keys.push(c);
                changed = true;
            }
        }
        let tables = match self.tables.take() {
            Some(t) if !changed => t,
            _ => BasisTables::build(&self.keys, self.level)?,
        };
        Ok(self.tables.insert(tables))
    }
}

/// A face and one of its local edges or corners (0..3) in one word, `face << 2 | local`: the
/// records of a 1M-triangle mesh hold 24M of them. Ordered as `(face, local)`.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, PartialOrd, Ord, Hash)]
pub struct Owner(u32);

impl Owner {
    /// Faces an owner can name.
    pub const MAX_FACES: usize = 1 << 30;

    /// `face < MAX_FACES` and `local < 4` (checked in debug builds; [`build_patch_records`]
    /// rejects larger meshes).
    pub fn new(face: u32, local: u8) -> Owner {
        debug_assert!((face as usize) < Self::MAX_FACES && local < 4);
        Owner(face << 2 | local as u32)
    }

    pub fn face(self) -> u32 {
        self.0 >> 2
    }

    pub fn local(self) -> u8 {
        (self.0 & 3) as u8
    }
}

/// What the GPU needs per face of the once-refined mesh.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchRecord {
    pub key: BftKey,
    /// The face's global vertex indices in slot order ([`face_control_ring`]) are
    /// `rings[ring_offset..ring_offset + ring_size]` of its [`PatchRecords`].
    pub ring_offset: u32,
    pub ring_size: u32,
    /// Global index of the face's `v0`, `v1`, `v2` (rotated order).
    pub corners: [u32; 3],
    /// For local edge `e` (0: v0→v1 where `j = 0`; 1: v1→v2 where `i + j = N`; 2: v2→v0 where
    /// `i = 0`): the owner face and the edge's index in the owner.
    pub edge_owner: [Owner; 3],
    /// For local corner `c`: the owner face and the corner's index in the owner.
    pub corner_owner: [Owner; 3],
}

/// The patch records of every face with their rings back to back in one array (a `Vec` per
/// face cost a 1M-triangle mesh 4M allocations and ~300 MB at level 1); the GPU's ring
/// buffer is `rings` as it is.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct PatchRecords {
    pub faces: Vec<PatchRecord>,
    pub rings: Vec<u32>,
}

impl PatchRecords {
    pub fn len(&self) -> usize {
        self.faces.len()
    }

    pub fn is_empty(&self) -> bool {
        self.faces.is_empty()
    }

    /// Face `f`'s control ring, in slot order.
    pub fn ring(&self, f: usize) -> &[u32] {
        let r = &self.faces[f];
        &self.rings[r.ring_offset as usize..(r.ring_offset + r.ring_size) as usize]
    }

    pub fn iter(&self) -> std::slice::Iter<'_, PatchRecord> {
        self.faces.iter()
    }
}

impl std::ops::Index<usize> for PatchRecords {
    type Output = PatchRecord;
    fn index(&self, f: usize) -> &PatchRecord {
        &self.faces[f]
    }
}

/// Patch records of every face of a Loop mesh (typically level 1): a shared table key where
/// [`classify_face`] finds one, else a [`BftCase::Private`] key whose ring is the face's
/// neighbourhood. Fails only on a face that is not a triangle.
pub fn build_patch_records(mesh: &LocalMesh) -> Result<PatchRecords, EvalError> {
    let nf = mesh.num_faces();
    if let Some(f) = (0..nf).find(|&f| mesh.face(f).len() != 3) {
        return Err(EvalError::FaceSize {
            face: f,
            size: mesh.face(f).len(),
            scheme: LimitScheme::Loop,
            need: 3,
        });
    }
    if nf > Owner::MAX_FACES {
        return Err(EvalError::TooManyPatches {
            faces: nf,
            max: Owner::MAX_FACES,
        });
    }
    let blocks = classify_blocks(mesh, has_interior_creases(mesh));
    let mut recs = join_blocks(blocks, nf);
    set_owners(mesh, &mut recs);
    Ok(recs)
}

/// The records of a Loop mesh's faces (triangles), classified in parallel blocks: each
/// block's records with its rings in one array, offsets local to the block. `creases`: the
/// mesh has interior creases ([`has_interior_creases`]).
fn classify_blocks(mesh: &LocalMesh, creases: bool) -> Vec<PatchRecords> {
    // Faces are independent: classified in parallel blocks, a shape cache per rayon job, each
    // block's rings in one array (offsets made global when the blocks are joined).
    const BLOCK: usize = 1 << 14;
    let nf = mesh.num_faces();
    (0..nf.div_ceil(BLOCK))
        .into_par_iter()
        .map_init(ConfigShapes::new, |shapes, b| {
            let faces = b * BLOCK..((b + 1) * BLOCK).min(nf);
            let mut out = PatchRecords {
                faces: Vec::with_capacity(faces.len()),
                rings: Vec::with_capacity(12 * faces.len()),
            };
            for f in faces {
                let fv = mesh.face(f);
                let start = out.rings.len();
                let (key, first) =
                    match classify_face_cached(mesh, f, shapes, creases, &mut out.rings) {
                        Some(found) => found,
                        None => {
                            neighbourhood_vertices_into(mesh, f, &mut out.rings);
                            (
                                BftKey {
                                    valence: 0,
                                    case: BftCase::Private { face: f as u32 },
                                },
                                0,
                            )
                        }
                    };
                out.faces.push(PatchRecord {
                    key,
                    ring_offset: start as u32,
                    ring_size: (out.rings.len() - start) as u32,
                    corners: [fv[first], fv[(first + 1) % 3], fv[(first + 2) % 3]],
                    edge_owner: [Owner::default(); 3],
                    corner_owner: [Owner::default(); 3],
                });
            }
            out
        })
        .collect()
}

/// The blocks' records in one table, the ring offsets made global.
fn join_blocks(blocks: Vec<PatchRecords>, nf: usize) -> PatchRecords {
    // Joined block by block, each block freed once copied: the peak is the whole plus one
    // block, not twice the whole.
    let mut recs = PatchRecords {
        faces: Vec::with_capacity(nf),
        rings: Vec::with_capacity(blocks.iter().map(|b| b.rings.len()).sum()),
    };
    for b in blocks {
        let base = recs.rings.len() as u32;
        recs.faces.extend(b.faces.into_iter().map(|r| PatchRecord {
            ring_offset: r.ring_offset + base,
            ..r
        }));
        recs.rings.extend_from_slice(&b.rings);
    }
    recs
}

/// Each record's edge and corner owners.
fn set_owners(mesh: &LocalMesh, recs: &mut PatchRecords) {
    // Owners: the smallest (face, local index) among the faces around the corner (sharing the
    // edge), found from the mesh's vertex-face adjacency instead of global edge maps. A face's
    // rotation (its `v0` among its corners) is all a neighbour needs from its record.
    let first: Vec<u8> = recs
        .faces
        .iter()
        .enumerate()
        .map(|(f, r)| {
            mesh.face(f)
                .iter()
                .position(|&c| c == r.corners[0])
                .unwrap_or(0) as u8
        })
        .collect();
    let local = |g: u32, x: u32| {
        let k = mesh.face(g as usize).iter().position(|&c| c == x)?;
        Some((k + 3 - first[g as usize] as usize) % 3)
    };
    recs.faces.par_iter_mut().enumerate().for_each(|(f, r)| {
        for e in 0..3 {
            let (a, b) = (r.corners[e], r.corners[(e + 1) % 3]);
            let mut edge = Owner::new(f as u32, e as u8);
            let mut corner = edge;
            for g in mesh.vertex_faces(a) {
                let Some(ka) = local(g, a) else { continue };
                corner = corner.min(Owner::new(g, ka as u8));
                if let Some(kb) = local(g, b) {
                    // The edge's index in g: it starts at whichever of a, b the other follows.
                    let k = if (ka + 1) % 3 == kb { ka } else { kb };
                    edge = edge.min(Owner::new(g, k as u8));
                }
            }
            r.edge_owner[e] = edge;
            r.corner_owner[e] = corner;
        }
    });
}

/// The vertices of `face` and of every face touching one of its corners, in the order
/// [`LocalMesh::face_neighbourhood`] numbers them (the face's corners first).
pub fn neighbourhood_vertices(mesh: &LocalMesh, face: usize) -> Vec<u32> {
    let mut out: Vec<u32> = Vec::new();
    neighbourhood_vertices_into(mesh, face, &mut out);
    out
}

/// [`neighbourhood_vertices`] appended to `out`.
fn neighbourhood_vertices_into(mesh: &LocalMesh, face: usize, out: &mut Vec<u32>) {
    let start = out.len();
    for f in mesh.neighbourhood_faces(face) {
        for &v in mesh.face(f as usize) {
            if !out[start..].contains(&v) {
                out.push(v);
            }
        }
    }
}

/// Exact limit weights of one face over its neighbourhood ([`neighbourhood_vertices`]) at every
/// table point: `(rows, ring size)`, rows as `[position, du, dv]`.
pub fn private_table(
    mesh: &LocalMesh,
    face: usize,
    level: u32,
) -> Result<(Rows, usize), EvalError> {
    let nb = mesh.face_neighbourhood(face)?;
    let k = nb.num_vertices();
    let mut pts = vec![0.0; k * k];
    for v in 0..k {
        pts[v * k + v] = 1.0;
    }
    let id = nb.with_points(k, pts)?;
    let m = grid_size(level) as f64;
    let mut rows = Vec::new();
    for (a, b) in table_points(level) {
        let s = id.evaluate(0, a as f64 / m, b as f64 / m)?;
        let clean = |x: &[f64]| -> Vec<f64> {
            x.iter()
                .map(|&w| if w.abs() < 1e-13 { 0.0 } else { w })
                .collect()
        };
        rows.push([clean(&s.position), clean(&s.du), clean(&s.dv)]);
    }
    Ok((rows, k))
}

impl BasisTables {
    /// Appends the private table of `key` (a [`BftCase::Private`] face) from its rows.
    pub fn add_private(&mut self, key: BftKey, rows: &Rows, ring_size: usize) {
        let mut offs = [u32::MAX; 3];
        let blocks = if self.tangents { 3 } else { 1 };
        for (b, off) in offs.iter_mut().enumerate().take(blocks) {
            *off = self.weights.len() as u32;
            for r in rows {
                self.weights.extend(r[b].iter().map(|&w| w as f32));
            }
        }
        self.entries.push(BftEntry {
            key,
            ring_size: ring_size as u32,
            half: false,
            rows: rows.len() as u32,
            offset_position: offs[0],
            offset_du: offs[1],
            offset_dv: offs[2],
            offset_perm: self.mirror_perm.len() as u32,
        });
        self.mirror_perm.extend(0..ring_size as u32);
    }
}

/// Which table row (face, point) a shader uses for dyadic point `(i, j)` of `face`: the face
/// itself for interior points, else the owner of the edge or corner, with the point's
/// coordinates in the owner's parameters.
pub fn resolve_owner(
    recs: &PatchRecords,
    face: usize,
    i: u32,
    j: u32,
    n: u32,
) -> (usize, u32, u32) {
    let r = &recs[face];
    let corner = match (i, j) {
        (0, 0) => Some(0),
        (x, 0) if x == n => Some(1),
        (0, y) if y == n => Some(2),
        _ => None,
    };
    let corner_param = |c: u8| match c {
        0 => (0, 0),
        1 => (n, 0),
        _ => (0, n),
    };
    if let Some(c) = corner {
        let (g, gc) = (r.corner_owner[c].face(), r.corner_owner[c].local());
        let (a, b) = corner_param(gc);
        return (g as usize, a, b);
    }
    // Edge index and position k along it from its start corner.
    let edge = if j == 0 {
        Some((0, i))
    } else if i + j == n {
        Some((1, j))
    } else if i == 0 {
        Some((2, n - j))
    } else {
        None
    };
    match edge {
        None => (face, i, j),
        Some((e, k)) => {
            let (g, ge) = (r.edge_owner[e].face(), r.edge_owner[e].local());
            // The owner walks the edge the other way unless it is this face.
            let kk = if g as usize == face { k } else { n - k };
            let (a, b) = match ge {
                0 => (kk, 0),
                1 => (n - kk, kk),
                _ => (0, n - kk),
            };
            (g as usize, a, b)
        }
    }
}

/// CPU emulation of the shader: f32 position of dyadic point `(i, j)` of `face`, summing
/// `w[s]·p[s]` for `s = 0..ring_size` in slot order (separate multiply and add, as GLSL
/// `precise` guarantees) over the owner's control points.
pub fn shader_eval(
    tables: &BasisTables,
    recs: &PatchRecords,
    points: &[[f32; 3]],
    face: usize,
    i: u32,
    j: u32,
) -> Option<[f32; 3]> {
    shader_eval_full(tables, recs, points, face, i, j).map(|(p, _)| p)
}

fn dot_rows(w: &[f32], ring: &[u32], points: &[[f32; 3]]) -> [f32; 3] {
    let mut acc = [0.0f32; 3];
    for (s, &v) in ring.iter().enumerate() {
        let p = points[v as usize];
        for k in 0..3 {
            let t = w[s] * p[k];
            acc[k] += t;
        }
    }
    acc
}

/// [`shader_eval`] plus the geometric normal `normalize(du × dv)` (zero without tangent
/// tables). Shared points take `du`, `dv` from the owner too, so normals are bit-identical
/// across edges as well; both parameterisations are CCW, so the owner's normal is the face's.
pub fn shader_eval_full(
    tables: &BasisTables,
    recs: &PatchRecords,
    points: &[[f32; 3]],
    face: usize,
    i: u32,
    j: u32,
) -> Option<([f32; 3], [f32; 3])> {
    let n = tables.segments();
    let (g, a, b) = resolve_owner(recs, face, i, j, n);
    let w = tables.row(recs[g].key, a, b)?;
    let ring = recs.ring(g);
    let p = dot_rows(&w.position, ring, points);
    if w.du.is_empty() {
        return Some((p, [0.0; 3]));
    }
    let du = dot_rows(&w.du, ring, points);
    let dv = dot_rows(&w.dv, ring, points);
    let c = [
        du[1] * dv[2] - du[2] * dv[1],
        du[2] * dv[0] - du[0] * dv[2],
        du[0] * dv[1] - du[1] * dv[0],
    ];
    let l = (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt();
    let nrm = if l > 0.0 {
        [c[0] / l, c[1] / l, c[2] / l]
    } else {
        [0.0; 3]
    };
    Some((p, nrm))
}

/// The level-1 limit-tangent stencils as one CSR table (one allocation per array, not three
/// per vertex: a 1M-triangle mesh has 2M level-1 vertices): row `v` is
/// `offsets[v]..offsets[v + 1]` of `indices` (level-1 vertices) and both weight rows.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct TangentStencils {
    pub offsets: Vec<u32>,
    pub indices: Vec<u32>,
    pub t1: Vec<f64>,
    pub t2: Vec<f64>,
}

impl TangentStencils {
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Row `v`: (indices, first tangent weights, second tangent weights).
    pub fn row(&self, v: usize) -> (&[u32], &[f64], &[f64]) {
        let r = self.offsets[v] as usize..self.offsets[v + 1] as usize;
        (&self.indices[r.clone()], &self.t1[r.clone()], &self.t2[r])
    }

    fn append(&mut self, other: TangentStencils) {
        if self.offsets.is_empty() {
            self.offsets.push(0);
        }
        let base = self.indices.len() as u32;
        self.offsets
            .extend(other.offsets.iter().skip(1).map(|&o| base + o));
        self.indices.extend_from_slice(&other.indices);
        self.t1.extend_from_slice(&other.t1);
        self.t2.extend_from_slice(&other.t2);
    }
}

/// Limit-tangent stencils of every level-1 vertex (the normals' pre-pass reads them), in
/// parallel blocks, each row written
/// straight into its block's arrays ([`LocalMesh::loop_tangent_row`]).
pub fn loop_tangent_stencils(level1: &LocalMesh) -> TangentStencils {
    let n = level1.num_vertices();
    let block = 1 << 15;
    let blocks: Vec<TangentStencils> = (0..n.div_ceil(block))
        .into_par_iter()
        .map(|b| {
            let rows = b * block..((b + 1) * block).min(n);
            let mut out = TangentStencils {
                offsets: Vec::with_capacity(rows.len() + 1),
                indices: Vec::with_capacity(8 * rows.len()),
                t1: Vec::with_capacity(8 * rows.len()),
                t2: Vec::with_capacity(8 * rows.len()),
            };
            out.offsets.push(0);
            for v in rows.map(|v| v as u32) {
                if !level1.loop_tangent_row(v, &mut out.indices, &mut out.t1, &mut out.t2) {
                    // No limit mask (e.g. a valence-2 corner under "edges only"): the fan's
                    // chord tangents, first and last ring neighbour, still give the outward
                    // side.
                    let ring = level1.vertex_ring(v);
                    let len = ring.len() + 1;
                    out.indices.push(v);
                    out.indices.extend_from_slice(ring);
                    let (s1, s2) = (out.t1.len(), out.t2.len());
                    out.t1.resize(s1 + len, 0.0);
                    out.t2.resize(s2 + len, 0.0);
                    if len >= 3 {
                        out.t1[s1] = -1.0;
                        out.t1[s1 + 1] = 1.0;
                        out.t2[s2] = -1.0;
                        out.t2[s2 + len - 1] = 1.0;
                    }
                }
                out.offsets.push(out.indices.len() as u32);
            }
            out
        })
        .collect();
    let terms: usize = blocks.iter().map(|b| b.indices.len()).sum();
    let mut all = TangentStencils {
        offsets: Vec::with_capacity(n + 1),
        indices: Vec::with_capacity(terms),
        t1: Vec::with_capacity(terms),
        t2: Vec::with_capacity(terms),
    };
    all.offsets.push(0);
    for b in blocks {
        all.append(b);
    }
    all
}

/// Everything the BFT pipeline needs for a Loop control mesh: the once-refined mesh (its
/// positions are what the shader combines), the base → level-1 stencils that produce them, the
/// level-1 limit-tangent stencils (for the normals subdivision shading starts from), per-face
/// records and the tables at `level`.
#[derive(Clone, Debug)]
pub struct LoopBft {
    pub level1: LocalMesh,
    pub stencils: crate::refine::stencil::StencilTable,
    /// Per level-1 vertex: control indices and the two tangent weight rows.
    pub tangent_stencils: TangentStencils,
    pub records: PatchRecords,
    pub tables: BasisTables,
    pub base_vertices: usize,
    pub base_faces: usize,
}

/// The stages of [`prepare_loop_bft`], for a caller that packs and frees each product before
/// the next is built (a 1M-triangle mesh's level-1 data is ~1.5 GB in f64 and `Vec`s).
///
/// One step of the refiner, taken by value: the level-1 mesh (its topology becomes the local
/// mesh's without a copy) and its stencils over the base vertices (what the GPU's pre-pass
/// applies).
pub fn loop_level1(
    mesh: &crate::mesh::ControlMesh,
) -> Result<(LocalMesh, crate::refine::stencil::StencilTable), EvalError> {
    let (level1, stencils) = {
        let base = crate::refine::Level::from_mesh(mesh, crate::rules::Scheme::Loop)?;
        crate::refine::refine_level(&base, crate::rules::Scheme::Loop, &mesh.options)?
    };
    let crate::refine::Level {
        topology,
        positions,
        edge_sharpness,
        vertex_sharpness,
    } = level1;
    let points: Vec<f64> = positions.iter().flatten().copied().collect();
    drop(positions);
    let level1 = LocalMesh::from_level(
        crate::refine::LevelTopology {
            topology,
            edge_sharpness,
            vertex_sharpness,
        },
        LimitScheme::Loop,
        mesh.options,
        3,
        points,
    )?;
    Ok((level1, stencils))
}

/// The tables at `level` every record of `records` needs: the distinct shared keys, then one
/// private table per face no shared table serves.
pub fn loop_tables(
    level1: &LocalMesh,
    records: &PatchRecords,
    level: u32,
    tangents: bool,
) -> Result<BasisTables, EvalError> {
    // The distinct shared keys (the tables dedup them too, but not 4M of them).
    let keys: Vec<BftKey> = records
        .iter()
        .filter(|r| !matches!(r.key.case, BftCase::Private { .. }))
        .map(|r| r.key.canonical().0)
        .collect::<std::collections::HashSet<_>>()
        .into_iter()
        .collect();
    let mut tables = BasisTables::build_with(&keys, level, tangents)?;
    for (f, r) in records.iter().enumerate() {
        if matches!(r.key.case, BftCase::Private { .. }) {
            let (rows, k) = private_table(level1, f, level)?;
            debug_assert_eq!(k, r.ring_size as usize);
            tables.add_private(r.key, &rows, k);
        }
    }
    Ok(tables)
}

/// The number of f32 weights [`loop_tables`] will store for `records` at `level` (with the
/// `du`/`dv` blocks when `tangents`), counted from the records alone: no table is evaluated.
/// Private tables (one per face next to creases, corners and overlapping rings) cost a full
/// table each, so a mesh with many of them can outgrow what a caller can address or hold; this
/// lets a caller refuse it in milliseconds instead of after minutes of evaluation.
pub fn table_weight_count(records: &PatchRecords, level: u32, tangents: bool) -> u64 {
    let pts = table_points(level);
    let full = pts.len() as u64;
    let half = pts.iter().filter(|&&(a, b)| a >= b).count() as u64;
    let blocks = if tangents { 3 } else { 1 };
    let mut shared: HashMap<BftKey, u64> = HashMap::new();
    let mut private = 0u64;
    for r in records.iter() {
        if matches!(r.key.case, BftCase::Private { .. }) {
            private += full * r.ring_size as u64;
        } else {
            // Mirroring permutes slots, never changes their count.
            shared.insert(r.key.canonical().0, r.ring_size as u64);
        }
    }
    let shared: u64 = shared
        .iter()
        .map(|(k, &ring)| if k.self_symmetric() { half } else { full } * ring)
        .sum();
    blocks * (shared + private)
}

/// Which corner of its level-1 face each record's `v0` is: all [`level1_base_domain`] needs
/// of the records and the level-1 mesh (one byte per face).
pub fn face_rotations(level1: &LocalMesh, records: &PatchRecords) -> Vec<u8> {
    records
        .iter()
        .enumerate()
        .map(|(f, r)| {
            level1
                .face(f)
                .iter()
                .position(|&x| x == r.corners[0])
                .unwrap_or(0) as u8
        })
        .collect()
}

/// Refine `mesh` once (uniform refinement), classify every level-1 face and build the
/// tables it needs.
pub fn prepare_loop_bft(
    mesh: &crate::mesh::ControlMesh,
    level: u32,
    tangents: bool,
) -> Result<LoopBft, EvalError> {
    let (level1, stencils) = loop_level1(mesh)?;
    let records = build_patch_records(&level1)?;
    let tables = loop_tables(&level1, &records, level, tangents)?;
    let tangent_stencils = loop_tangent_stencils(&level1);
    Ok(LoopBft {
        stencils,
        level1,
        tangent_stencils,
        records,
        tables,
        base_vertices: mesh.positions.len(),
        base_faces: mesh.num_faces(),
    })
}

impl LoopBft {
    /// Which corner of level-1 face `face` its record's `v0` is: all [`Self::base_domain`]
    /// needs of the records and the level-1 mesh (what a GPU surface keeps of them).
    pub fn face_rotation(&self, face: usize) -> u8 {
        let v0 = self.records[face].corners[0];
        self.level1
            .face(face)
            .iter()
            .position(|&x| x == v0)
            .unwrap_or(0) as u8
    }

    /// Barycentric weights, in the level-1 face's own corner order, of the point with patch
    /// coordinate `(u, v)` (weights of the record's `v1`, `v2`: the TES's frame).
    pub fn face_barycentric(&self, face: usize, u: f64, v: f64) -> [f64; 3] {
        rotated_barycentric(self.face_rotation(face), u, v)
    }

    /// The base face and its domain coordinate `(U, V)` (weights of the base face's corners 1
    /// and 2) of patch coordinate `(u, v)` on level-1 face `face`.
    pub fn base_domain(&self, face: usize, u: f64, v: f64) -> (usize, f64, f64) {
        level1_base_domain(face, self.face_rotation(face), u, v)
    }
}

/// Barycentric weights in a level-1 face's own corner order of patch coordinate `(u, v)` on a
/// record whose `v0` is corner `first` of the face.
fn rotated_barycentric(first: u8, u: f64, v: f64) -> [f64; 3] {
    let first = first as usize % 3;
    let mut b = [0.0; 3];
    b[first] = 1.0 - u - v;
    b[(first + 1) % 3] = u;
    b[(first + 2) % 3] = v;
    b
}

/// [`LoopBft::base_domain`] from the face's rotation ([`LoopBft::face_rotation`]) alone. Loop's
/// split makes child `4f + j` the triangle at corner `j` of base face `f` and child `4f + 3`
/// the middle one.
pub fn level1_base_domain(face: usize, rotation: u8, u: f64, v: f64) -> (usize, f64, f64) {
    let c = rotated_barycentric(rotation, u, v);
    let (f, j) = (face / 4, face % 4);
    let mut b = [0.0; 3];
    if j < 3 {
        let (next, prev) = ((j + 1) % 3, (j + 2) % 3);
        b[j] += c[0] + 0.5 * (c[1] + c[2]);
        b[next] += 0.5 * c[1];
        b[prev] += 0.5 * c[2];
    } else {
        for k in 0..3 {
            b[k] += 0.5 * c[k];
            b[(k + 1) % 3] += 0.5 * c[k];
        }
    }
    (f, b[1], b[2])
}
