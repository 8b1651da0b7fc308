//! The exact Doo-Sabin limit surface as a feature-adaptive [`AdaptivePlan`]: the same stencil
//! blocks, regular B-spline patches, bilinear end caps and canonical boundary curves the
//! Catmull-Clark plan ([`crate::patches::adaptive`]) hands a device, so a device that draws
//! any valid plan watertight draws Doo-Sabin's limit with no new shader.
//!
//! # The domain
//!
//! Patches live on the domain of [`crate::limit::doo_sabin_eval`]: base face `f`, its corner
//! `i` and `(s, t)` in the *corner quad* of that corner (`(0,0)` the corner's vertex, `(1,0)`
//! the midpoint of the edge leaving it, `(1,1)` the face's centre). A patch's `base_face` is
//! `f`, its `sub_face` the corner `i` **on every face, quads included** (a Catmull-Clark plan
//! numbers sub-faces of non-quads only; a quad's corner quads are rotated quarters of its
//! square, which `origin + size·(u, v)` cannot express), and `origin + size·(u, v)` is the
//! patch's square in that corner quad, as [`AdaptivePatch::base_param`] maps it.
//!
//! # The steps
//!
//! 1. **Level 1** is one global Doo-Sabin step ([`refine_dual`], its stencils the first
//!    block). Each corner child `w` (valence 4) owns its corner quad, its *domain square*, whose
//!    corners are the centres of `w`'s four faces (its *ring*: v-face or strip face, e-face of
//!    the leaving edge, f-face, e-face of the entering edge).
//! 2. **Classification.** A square whose ring faces are all quads is *regular*: Doo-Sabin on
//!    quads is the tensor product of Chaikin's rule, so the limit over the square is the
//!    uniform biquadratic B-spline of the ring's 3×3 grid (strip quads completed by point
//!    reflection, as the evaluator does). Otherwise its ring holds an *extraordinary* face:
//!    an f-face of a non-quad base face, a v-face of a vertex of valence ≠ 4, a strip face of a
//!    boundary vertex with other than two faces.
//! 3. **Isolation.** Below the isolation level an irregular square is split: its ring is
//!    refined one step by the refiner's masks ([`corner_weights`]), only the children the four
//!    quadrants' rings need, each shared child one stencil row (keyed by its parent corner),
//!    each level's new rows one block reading only the level above. Quadrant `q` belongs to
//!    `w`'s child in face `q`; its ring is that face's f-face, the e-faces of its two edges at
//!    `w` and `w`'s v-face. The f-face of an extraordinary face is extraordinary, the other
//!    three faces are quads, so from level 2 on an irregular square holds exactly one
//!    extraordinary face and splits into one irregular and three regular quadrants.
//! 4. **Regular patches.** A biquadratic patch is a bicubic polynomial patch, and the four
//!    uniform cubic B-splines restricted to one span are a basis of the cubics: the 3×3 grid
//!    has exactly one 4×4 cubic B-spline net ([`QUADRATIC_TO_CUBIC`] in each direction), which
//!    [`PatchKind::Regular`] evaluates exactly. Its 16 points are rows of the local block.
//! 5. **End caps.** A square still irregular at the isolation level is a
//!    [`PatchKind::Bilinear`] cap, the Coons patch of its four canonical curves. Its corner at
//!    the extraordinary face is that face's limit centre (the centroid; a strip face's is the
//!    midpoint of its boundary edge, on the boundary curve); its curves shared with regular
//!    patches are theirs (exact), and the curves between two caps (those running into the
//!    extraordinary centre) are the straight segments between their canonical corners, which
//!    is what a bilinear owner's curve is ([`AdaptivePlan::curve_inner_point`]).
//! 6. **Canonical corners and curves.** Every patch corner is the centre of a ring face,
//!    keyed by the face that made that centre (a level-1 face, the e-face of an edge, the
//!    v-face of a vertex: an f-face keeps its parent's centre). A corner on some regular patch
//!    is that patch's B-spline corner ([`AdaptivePlan::regular_corner_point`]); the others get
//!    a limit row. A patch edge at level `k` is dual to the level-`k` edge `{w, x}` between the
//!    two ring faces it joins (`x` the neighbour whose square shares it), so each curve is
//!    keyed by that edge's two vertex ids at the finest level it exists. A regular square
//!    beside a split one has an [`EdgeKind::Coarse`] edge (halves dual to the children's edges
//!    `{x_F, w_F}`, `{x_G, w_G}`), the split side's quadrants [`EdgeKind::Fine`] ones; owners
//!    are regular patches before caps, then the lowest patch index, as the Catmull-Clark plan
//!    chooses.
//!
//! # Accuracy
//!
//! Regular patches are the limit to rounding (within 5e-16 of the bounding-box diagonal on
//! the test meshes). End caps converge with the isolation level: about twice closer per level
//! around interior extraordinary faces (the cube's caps: 4.2e-2, 6.6e-3, 2.5e-3, 1.2e-3 of the
//! diagonal at isolation 1 to 4). The strip triangle of a boundary vertex of one face shrinks
//! slower: its real corner's child is `3/4 r + 1/4 q` (`q` the midpoint of its boundary edge;
//! the mode-1 eigenvalue of the 2-gon completion, `7/8 − 1/8`), so its cap shrinks by about
//! `3/4` per level in space while its square halves (a bumped grid's corners: 6.8e-3, 6.4e-3,
//! 5.2e-3 at isolation 2 to 4, then ratios tending to 0.75).
//!
//! Neighbouring squares differ by at most one level by construction: a regular square never
//! shares an edge with a square's quadrant at an extraordinary face (the edge would run into
//! that face's centre, making the square irregular).

use super::adaptive::{
    AdaptivePatch, AdaptivePlan, ControlPoints, CurveOwner, EdgeKind, LevelStats, PatchEdge,
    PatchKind, StencilBlock, MAX_REFINED_FACES,
};
use crate::error::TopologyError;
use crate::mesh::ControlMesh;
use crate::refine::doo_sabin::{
    boundary_vertices, fan, level_sizes, refine_dual, DualVertex, LevelSize,
};
use crate::refine::stencil::StencilTable;
use crate::refine::{check_doo_sabin_tags, Level};
use crate::rules::doo_sabin::{corner_weights, strip_edge};
use crate::rules::Scheme;
use std::collections::{HashMap, HashSet};

/// The uniform cubic B-spline points `c_0..c_3` of one span of a uniform quadratic B-spline
/// with points `p_0, p_1, p_2` (row `j` weighs `p_0..p_2` for `c_j`): the span's polynomial
/// is cubic, and its cubic blossom at the cubic knots `(j−2, j−1, j)` is the mean of the
/// quadratic blossom over the three pairs, which the quadratic points `p_i = f(i−1, i)` give
/// by affine extrapolation.
pub const QUADRATIC_TO_CUBIC: [[f64; 3]; 4] = [
    [11.0 / 6.0, -7.0 / 6.0, 2.0 / 6.0],
    [2.0 / 6.0, 5.0 / 6.0, -1.0 / 6.0],
    [-1.0 / 6.0, 5.0 / 6.0, 2.0 / 6.0],
    [2.0 / 6.0, -7.0 / 6.0, 11.0 / 6.0],
];

/// The corners of a square, in ring order.
const CORNERS: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

/// A linear combination of global vertices.
type Terms = Vec<(u32, f64)>;

/// An edge of a refined level by its two global vertex ids, smaller first: the key of the
/// canonical curve dual to it.
type EdgeKey = (u32, u32);

fn edge_key(a: u32, b: u32) -> EdgeKey {
    (a.min(b), a.max(b))
}

/// What made the centre of a ring face (an f-face keeps its parent's centre).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
enum Centre {
    /// A face of level 1, by its index there.
    First(u32),
    /// The e-face of the edge between two global vertices (smaller first).
    Edge(u32, u32),
    /// The v-face of a global vertex.
    Vertex(u32),
}

/// A face of a ring, listed from the ring's vertex `w` in its orientation.
#[derive(Clone, Debug)]
struct RingFace {
    verts: Vec<u32>,
    centre: Centre,
    /// Whether the face is the e-face of the step that made it.
    e_face: bool,
}

/// The domain square of a real vertex: its ring (face `j` centred on corner `CORNERS[j]`)
/// and where it lies in corner `corner` of base face `face`.
#[derive(Clone, Debug)]
struct Square {
    faces: [RingFace; 4],
    face: u32,
    corner: u8,
    origin: [f64; 2],
    size: f64,
}

impl Square {
    fn w(&self) -> u32 {
        self.faces[0].verts[0]
    }

    /// Ring faces that are not quads.
    fn extraordinary(&self) -> usize {
        self.faces.iter().filter(|f| f.verts.len() != 4).count()
    }
}

/// The stencil blocks as they are made, the boundary points and the shared children.
struct Refinement {
    num_base: u32,
    /// The size of level 1 (for the uniform counts).
    first_size: LevelSize,
    /// Per global vertex (base vertices first): whether it is a boundary point.
    boundary: Vec<bool>,
    steps: Vec<StencilBlock>,
    /// Rows of the level being made.
    rows: Vec<Terms>,
    /// The child of a corner, keyed by the directed edge leaving it in its face.
    children: HashMap<EdgeKey, u32>,
}

impl Refinement {
    fn next_id(&self) -> u32 {
        self.boundary.len() as u32
    }

    /// The child of corner `i` of `face` (global ids in the face's orientation), made once.
    fn child(&mut self, face: &[u32], i: usize) -> Result<u32, TopologyError> {
        let n = face.len();
        let key = (face[i], face[(i + 1) % n]);
        if let Some(&c) = self.children.get(&key) {
            return Ok(c);
        }
        let strip = strip_edge(n, |k| self.boundary[face[k] as usize]).map_err(|_| {
            TopologyError::UnsupportedScheme {
                scheme: "doo-sabin",
                operation:
                    "a refined level whose face holds boundary points that are not one boundary edge",
            }
        })?;
        let mut w = Vec::new();
        corner_weights(n, strip, i, &mut w);
        let terms = (0..n).map(|k| (face[(i + k) % n], w[k])).collect();
        let id = self.next_id();
        self.rows.push(terms);
        self.boundary.push(self.boundary[face[i] as usize]);
        self.children.insert(key, id);
        Ok(id)
    }

    /// Closes the level being made into a block.
    fn close_level(&mut self) {
        let first_vertex = self.next_id() - self.rows.len() as u32;
        let table = table_of(std::mem::take(&mut self.rows), first_vertex as usize);
        self.steps.push(StencilBlock {
            first_vertex,
            table,
        });
    }

    /// The ring of `w`'s child in face `q`, owner of quadrant `q` of `sq`.
    fn quadrant(&mut self, sq: &Square, q: usize) -> Result<Square, TopologyError> {
        let f = &sq.faces;
        let (next, prev, w) = ((q + 1) % 4, (q + 3) % 4, sq.w());
        let fq: Vec<u32> = (0..f[q].verts.len())
            .map(|i| self.child(&f[q].verts, i))
            .collect::<Result<_, _>>()?;
        let mut kid = |j: usize, i: usize| self.child(&f[j].verts, i);
        let (next0, next1) = (kid(next, 0)?, kid(next, 1)?);
        let (prev0, prev_last) = (kid(prev, 0)?, kid(prev, f[prev].verts.len() - 1)?);
        let opposite0 = kid((q + 2) % 4, 0)?;
        let q_last = f[q].verts[f[q].verts.len() - 1];
        let face = |verts: Vec<u32>, centre: Centre, e_face: bool| RingFace {
            verts,
            centre,
            e_face,
        };
        let order = [
            face(fq.clone(), f[q].centre, false),
            face(
                vec![fq[0], fq[fq.len() - 1], next1, next0],
                centre_of_edge(w, q_last),
                true,
            ),
            face(
                vec![fq[0], next0, opposite0, prev0],
                Centre::Vertex(w),
                false,
            ),
            face(
                vec![fq[0], prev0, prev_last, fq[1]],
                centre_of_edge(w, f[q].verts[1]),
                true,
            ),
        ];
        let mut faces = order.clone();
        for (k, ring_face) in order.into_iter().enumerate() {
            faces[(q + k) % 4] = ring_face;
        }
        let size = 0.5 * sq.size;
        Ok(Square {
            faces,
            face: sq.face,
            corner: sq.corner,
            origin: [
                sq.origin[0] + CORNERS[q][0] * size,
                sq.origin[1] + CORNERS[q][1] * size,
            ],
            size,
        })
    }
}

fn centre_of_edge(a: u32, b: u32) -> Centre {
    let (a, b) = edge_key(a, b);
    Centre::Edge(a, b)
}

/// Rows as a table: indices sorted and unique, exact zeros dropped.
fn table_of(rows: Vec<Terms>, num_sources: usize) -> StencilTable {
    let mut table = StencilTable {
        offsets: vec![0],
        num_sources,
        ..StencilTable::default()
    };
    for mut row in rows {
        row.sort_by_key(|t| t.0);
        let mut merged: Terms = Vec::with_capacity(row.len());
        for (i, w) in row {
            match merged.last_mut() {
                Some(last) if last.0 == i => last.1 += w,
                _ => merged.push((i, w)),
            }
        }
        for (i, w) in merged.into_iter().filter(|t| t.1 != 0.0) {
            table.indices.push(i);
            table.weights.push(w);
        }
        table.offsets.push(table.indices.len() as u32);
    }
    table
}

/// Step 1: level 1 globally, and the domain square of every corner child.
fn first_level(mesh: &ControlMesh) -> Result<(Refinement, Vec<Square>), TopologyError> {
    let base = Level::from_mesh(mesh, Scheme::DooSabin)?;
    let step = refine_dual(&base, true)?;
    let num_base = base.positions.len() as u32;
    let t = &step.level.topology;
    let mut boundary = vec![false; num_base as usize];
    boundary.extend(boundary_vertices(t));
    let mut squares = Vec::new();
    for (x, origin) in step.vertices.iter().enumerate() {
        let DualVertex::Corner { face, corner } = *origin else {
            continue;
        };
        let ring = fan(t, x, face);
        if ring.len() != 4 || t.vertex_faces(x).len() != 4 {
            let vertex = base.topology.face_vertices(face as usize)[corner as usize];
            return Err(TopologyError::NonManifoldVertex { vertex, fans: 2 });
        }
        let listed = |g: u32| {
            let fv = t.face_vertices(g as usize);
            let at = fv.iter().position(|&y| y as usize == x).unwrap_or(0);
            RingFace {
                verts: (0..fv.len())
                    .map(|k| num_base + fv[(at + k) % fv.len()])
                    .collect(),
                centre: Centre::First(g),
                e_face: false,
            }
        };
        squares.push(Square {
            faces: std::array::from_fn(|j| listed(ring[(j + 2) % 4])),
            face,
            corner: corner as u8,
            origin: [0.0; 2],
            size: 1.0,
        });
    }
    let steps = vec![StencilBlock {
        first_vertex: num_base,
        table: step.stencils,
    }];
    let refinement = Refinement {
        num_base,
        first_size: LevelSize::of(t),
        boundary,
        steps,
        rows: Vec::new(),
        children: HashMap::new(),
    };
    Ok((refinement, squares))
}

/// One patch edge before numbering: the curve keys it uses and the centres at its ends.
#[derive(Clone, Copy, Debug)]
enum DraftEdge {
    /// Same level or boundary: the curve of the dual edge.
    Plain(EdgeKey),
    /// The neighbour was split: the halves in the edge's direction and the centre between.
    Coarse([EdgeKey; 2], Centre),
    /// The neighbour is a level coarser: this half, the sibling half and the centre of the
    /// coarse edge's midpoint (the e-face's), which is corner `mid_at_end` of this edge.
    Fine {
        own: EdgeKey,
        sibling: EdgeKey,
        mid: Centre,
        mid_at_end: bool,
    },
}

/// A patch before numbering.
#[derive(Clone, Debug)]
struct Draft {
    kind: PatchKind,
    level: u8,
    square: Square,
    edges: [DraftEdge; 4],
    boundary_mask: u8,
    /// Regular patches: the 16 net points.
    net: Vec<Terms>,
}

/// Squares of one level: whether each one's vertex was split.
type Status = HashMap<u32, bool>;

/// The edges of `sq` (a patch at `level`) against its neighbours (`status` of its level).
fn draft_edges(
    r: &Refinement,
    sq: &Square,
    status: &Status,
    level: u32,
) -> Result<([DraftEdge; 4], u8), TopologyError> {
    let w = sq.w();
    let mut boundary_mask = 0;
    let mut edges = [DraftEdge::Plain((0, 0)); 4];
    let missing = || TopologyError::AdaptiveUnbalanced {
        level,
        face: sq.face as usize,
    };
    for (e, edge) in edges.iter_mut().enumerate() {
        let (f, g) = (&sq.faces[e].verts, &sq.faces[(e + 1) % 4].verts);
        let x = f[f.len() - 1];
        *edge = if r.boundary[x as usize] {
            boundary_mask |= 1 << e;
            DraftEdge::Plain(edge_key(w, x))
        } else {
            match status.get(&x) {
                Some(false) => DraftEdge::Plain(edge_key(w, x)),
                Some(true) => {
                    let kid = |a: u32, b: u32| r.children.get(&(a, b)).copied().ok_or(missing());
                    let first = edge_key(kid(x, w)?, kid(w, f[1])?);
                    let second = edge_key(kid(x, g[2])?, kid(w, x)?);
                    DraftEdge::Coarse([first, second], centre_of_edge(w, x))
                }
                None => fine_edge(sq, e, w, x).ok_or(missing())?,
            }
        };
    }
    Ok((edges, boundary_mask))
}

/// Edge `e` of quadrant `sq` against a coarser neighbour: the coarse edge's midpoint is the
/// centre of the e-face among the edge's two ring faces; the sibling half is dual to that
/// e-face's edge between the sibling (its other real neighbour of `w`) and the corner
/// opposite `w`.
fn fine_edge(sq: &Square, e: usize, w: u32, x: u32) -> Option<DraftEdge> {
    let at_end = sq.faces[(e + 1) % 4].e_face;
    let ef = &sq.faces[if at_end { (e + 1) % 4 } else { e }];
    if ef.verts.len() != 4 || !(at_end || ef.e_face) {
        return None;
    }
    let sibling = if ef.verts[1] == x {
        ef.verts[3]
    } else {
        ef.verts[1]
    };
    Some(DraftEdge::Fine {
        own: edge_key(w, x),
        sibling: edge_key(sibling, ef.verts[2]),
        mid: ef.centre,
        mid_at_end: at_end,
    })
}

/// A quad's corner `k` as a combination, a boundary point `b` replaced by `2b − r` (`r` its
/// real neighbour in the quad), as the evaluator completes strip quads.
fn reflected(r: &Refinement, face: &[u32], k: usize) -> Terms {
    let b = face[k];
    if !r.boundary[b as usize] {
        return vec![(b, 1.0)];
    }
    match [face[(k + 1) % 4], face[(k + 3) % 4]]
        .into_iter()
        .find(|&y| !r.boundary[y as usize])
    {
        Some(real) => vec![(b, 2.0), (real, -1.0)],
        None => vec![(b, 1.0)],
    }
}

/// The 16 points of the cubic B-spline net of a regular square (row-major, `u` fastest).
fn regular_net(r: &Refinement, sq: &Square) -> Vec<Terms> {
    let p = |j: usize, k: usize| reflected(r, &sq.faces[j].verts, k);
    // P_ab at a + 3b, a along u (the evaluator's grid).
    let grid = [
        p(0, 2),
        p(0, 3),
        p(1, 2),
        p(0, 1),
        vec![(sq.w(), 1.0)],
        p(1, 3),
        p(3, 2),
        p(2, 3),
        p(2, 2),
    ];
    let mut net = Vec::with_capacity(16);
    for row in QUADRATIC_TO_CUBIC {
        for col in QUADRATIC_TO_CUBIC {
            let mut terms = Terms::new();
            for (b, wb) in row.iter().enumerate() {
                for (a, wa) in col.iter().enumerate() {
                    terms.extend(grid[a + 3 * b].iter().map(|&(i, w)| (i, w * wa * wb)));
                }
            }
            net.push(terms);
        }
    }
    net
}

/// The limit row of a ring face's centre: its centroid, or the midpoint of its boundary
/// edge when it holds boundary points.
fn centre_row(r: &Refinement, verts: &[u32]) -> Result<Terms, TopologyError> {
    let n = verts.len();
    match strip_edge(n, |k| r.boundary[verts[k] as usize]) {
        Ok(None) => Ok(verts.iter().map(|&v| (v, 1.0 / n as f64)).collect()),
        Ok(Some(p)) => Ok(vec![(verts[p], 0.5), (verts[(p + 1) % n], 0.5)]),
        Err(_) => Err(TopologyError::UnsupportedScheme {
            scheme: "doo-sabin",
            operation:
                "a refined level whose face holds boundary points that are not one boundary edge",
        }),
    }
}

/// Steps 2–5 for one level: classify the active squares, refine the split ones (closing the
/// next level's block) and draft the patches; `held` gets the number of distinct faces of
/// the level's rings. Returns the next level's squares.
fn plan_level(
    r: &mut Refinement,
    squares: Vec<Square>,
    level: u32,
    isolation: u32,
    drafts: &mut Vec<Draft>,
    held: &mut Vec<u32>,
) -> Result<Vec<Square>, TopologyError> {
    let split = |sq: &Square| level < isolation && sq.extraordinary() > 0;
    let status: Status = squares.iter().map(|sq| (sq.w(), split(sq))).collect();
    let faces: HashSet<Centre> = squares
        .iter()
        .flat_map(|sq| sq.faces.iter().map(|f| f.centre))
        .collect();
    held.push(faces.len() as u32);
    let mut next = Vec::new();
    for sq in squares.iter().filter(|sq| split(sq)) {
        for q in 0..4 {
            next.push(r.quadrant(sq, q)?);
        }
    }
    if level < isolation {
        r.close_level();
    }
    for sq in squares.into_iter().filter(|sq| !split(sq)) {
        let (edges, boundary_mask) = draft_edges(r, &sq, &status, level)?;
        let regular = sq.extraordinary() == 0;
        drafts.push(Draft {
            kind: if regular {
                PatchKind::Regular
            } else {
                PatchKind::Bilinear
            },
            level: level as u8,
            net: if regular {
                regular_net(r, &sq)
            } else {
                Vec::new()
            },
            square: sq,
            edges,
            boundary_mask,
        });
    }
    Ok(next)
}

/// Plan the exact Doo-Sabin limit surface of `mesh` (module doc), isolating extraordinary
/// faces to level `isolation` (`1..=8`) and capping them there. Refuses by name what
/// Doo-Sabin's rules do not define (holes, crease and corner tags), non-manifold meshes (as
/// the dual refiner names them) and faces of more than 256 corners.
pub fn plan_doo_sabin(mesh: &ControlMesh, isolation: u32) -> Result<AdaptivePlan, TopologyError> {
    plan_doo_sabin_within(mesh, isolation, MAX_REFINED_FACES)
}

/// [`plan_doo_sabin`] under a bound on its patch domains (squares) other than
/// [`MAX_REFINED_FACES`]: a plan projected past it is [`TopologyError::DooSabinTooLarge`],
/// returned before the step that would exceed it. The projection at each level counts the
/// squares planned and held, plus three more for each square split at every level still to
/// come (a split square becomes four, and the squares next to an extraordinary face's centre
/// split again at the next level).
pub fn plan_doo_sabin_within(
    mesh: &ControlMesh,
    isolation: u32,
    max_squares: u64,
) -> Result<AdaptivePlan, TopologyError> {
    if !(1..=8).contains(&isolation) {
        return Err(TopologyError::IsolationOutOfRange { isolation });
    }
    check_doo_sabin_tags(mesh)?;
    // A patch names its base face's corner with 8 bits.
    if let Some((face, f)) = mesh.faces().enumerate().find(|(_, f)| f.len() > 256) {
        return Err(TopologyError::AdaptiveFaceTooLarge {
            face,
            size: f.len(),
        });
    }
    let too_large = |level: u32, estimate: u64| TopologyError::DooSabinTooLarge {
        faces: mesh.num_faces(),
        isolation,
        level,
        estimate,
        bound: max_squares,
    };
    let corners = mesh.face_vertices.len() as u64;
    if corners > max_squares {
        return Err(too_large(0, corners));
    }
    let (mut r, mut squares) = first_level(mesh)?;
    let (mut drafts, mut held) = (Vec::new(), Vec::new());
    for level in 1..=isolation {
        let split = squares
            .iter()
            .filter(|sq| level < isolation && sq.extraordinary() > 0)
            .count() as u64;
        let estimate =
            (drafts.len() + squares.len()) as u64 + 3 * split * (isolation - level) as u64;
        if estimate > max_squares {
            return Err(too_large(level, estimate));
        }
        squares = plan_level(&mut r, squares, level, isolation, &mut drafts, &mut held)?;
    }
    let stats = level_stats(mesh, r.first_size, &drafts, &held);
    assemble(r, drafts, stats, isolation)
}

/// Patch counts per level 0..=isolation; `faces` counts the faces held (level 0's, then the
/// distinct faces of each level's rings, `held`), `uniform_faces` a global refinement's.
fn level_stats(
    mesh: &ControlMesh,
    first: LevelSize,
    drafts: &[Draft],
    held: &[u32],
) -> Vec<LevelStats> {
    let sizes = level_sizes(first, held.len() as u32);
    let mut stats = vec![LevelStats::default(); held.len() + 1];
    stats[0].faces = mesh.num_faces() as u32;
    stats[0].uniform_faces = mesh.num_faces() as u64;
    for d in drafts {
        let s = &mut stats[d.level as usize];
        match d.kind {
            PatchKind::Regular => s.regular += 1,
            _ => s.end_caps += 1,
        }
    }
    for (k, s) in stats.iter_mut().enumerate().skip(1) {
        s.faces = held[k - 1];
        s.uniform_faces = sizes[k - 1].faces;
    }
    stats
}

/// A canonical corner while numbering: its first patch corner, its first regular one, and
/// the limit row of the face it is the centre of.
struct CornerInfo {
    first: [u32; 2],
    regular: Option<[u32; 2]>,
    row: Terms,
}

/// A canonical curve while numbering: its ends and its best owner so far (rank: 0 regular,
/// 1 end cap; then the patch index).
#[derive(Default)]
struct CurveInfo {
    ends: Option<[Centre; 2]>,
    owner: Option<(u8, u32, u8, u8)>,
}

#[derive(Default)]
struct Canonical {
    corners: HashMap<Centre, usize>,
    corner_info: Vec<(Centre, CornerInfo)>,
    curves: HashMap<EdgeKey, usize>,
    curve_info: Vec<CurveInfo>,
}

impl Canonical {
    fn corner(
        &mut self,
        r: &Refinement,
        d: &Draft,
        patch: u32,
        c: usize,
    ) -> Result<(), TopologyError> {
        let face = &d.square.faces[c];
        let corner = [patch, c as u32];
        let k = match self.corners.get(&face.centre) {
            Some(&k) => k,
            None => {
                let row = centre_row(r, &face.verts)?;
                self.corners.insert(face.centre, self.corner_info.len());
                let info = CornerInfo {
                    first: corner,
                    regular: None,
                    row,
                };
                self.corner_info.push((face.centre, info));
                self.corner_info.len() - 1
            }
        };
        let info = &mut self.corner_info[k].1;
        if d.kind == PatchKind::Regular && info.regular.is_none() {
            info.regular = Some(corner);
        }
        Ok(())
    }

    /// Registers curve `key`, with its ends (in the patch's edge direction) and the owner
    /// candidate `(patch, edge, part)` when given.
    fn curve(&mut self, key: EdgeKey, ends: Option<[Centre; 2]>, owner: Option<(u8, u32, u8, u8)>) {
        let next = self.curve_info.len();
        let k = *self.curves.entry(key).or_insert(next);
        if k == next {
            self.curve_info.push(CurveInfo::default());
        }
        let info = &mut self.curve_info[k];
        if info.ends.is_none() {
            info.ends = ends;
        }
        if let Some(o) = owner {
            if info.owner.is_none_or(|b| (o.0, o.1) < (b.0, b.1)) {
                info.owner = Some(o);
            }
        }
    }

    /// The curves of one patch.
    fn patch_curves(&mut self, d: &Draft, patch: u32) {
        let rank = u8::from(d.kind != PatchKind::Regular);
        let centre = |c: usize| d.square.faces[c % 4].centre;
        for (e, edge) in d.edges.iter().enumerate() {
            let (a, b) = (centre(e), centre(e + 1));
            let owner = |part: u8| Some((rank, patch, e as u8, part));
            match *edge {
                DraftEdge::Plain(key) => self.curve(key, Some([a, b]), owner(0)),
                DraftEdge::Coarse([k0, k1], mid) => {
                    self.curve(k0, Some([a, mid]), owner(1));
                    self.curve(k1, Some([mid, b]), owner(2));
                }
                DraftEdge::Fine { own, sibling, .. } => {
                    self.curve(own, Some([a, b]), owner(0));
                    self.curve(sibling, None, None);
                }
            }
        }
    }
}

/// Numbers everything: the local block (regular nets, then the limit rows of corners on no
/// regular patch), the regular corners, the curves' inner points; and builds the patches.
fn assemble(
    r: Refinement,
    drafts: Vec<Draft>,
    level_stats: Vec<LevelStats>,
    isolation: u32,
) -> Result<AdaptivePlan, TopologyError> {
    let mut canon = Canonical::default();
    for (p, d) in drafts.iter().enumerate() {
        for c in 0..4 {
            canon.corner(&r, d, p as u32, c)?;
        }
        canon.patch_curves(d, p as u32);
    }
    let first_local = r.next_id();
    let mut rows: Vec<Terms> = drafts.iter().flat_map(|d| d.net.iter().cloned()).collect();
    let first_corner = first_local + rows.len() as u32;
    // Corner ids: those without a regular patch (limit rows) first, in first-met order.
    let (with_rows, regular): (Vec<usize>, Vec<usize>) =
        (0..canon.corner_info.len()).partition(|&k| canon.corner_info[k].1.regular.is_none());
    let mut corner_id = vec![0u32; canon.corner_info.len()];
    let mut corner_owners = Vec::with_capacity(corner_id.len());
    for (n, &k) in with_rows.iter().chain(&regular).enumerate() {
        corner_id[k] = first_corner + n as u32;
        let info = &canon.corner_info[k].1;
        corner_owners.push(info.regular.unwrap_or(info.first));
    }
    rows.extend(
        with_rows
            .iter()
            .map(|&k| canon.corner_info[k].1.row.clone()),
    );
    let first_regular_corner = first_corner + with_rows.len() as u32;
    let first_curve_point = first_regular_corner + regular.len() as u32;
    let id_of = |c: Centre| corner_id[canon.corners[&c]];
    let local_points = StencilBlock {
        first_vertex: first_local,
        table: table_of(rows, first_local as usize),
    };
    let ends_of = |k: usize| -> Result<[u32; 2], TopologyError> {
        let ends = canon.curve_info[k]
            .ends
            .ok_or(TopologyError::AdaptiveUnbalanced { level: 0, face: 0 })?;
        Ok([id_of(ends[0]), id_of(ends[1])])
    };
    let mut curves = Vec::with_capacity(canon.curve_info.len());
    for k in 0..canon.curve_info.len() {
        let [a, b] = ends_of(k)?;
        let inner = first_curve_point + 2 * k as u32;
        curves.push([a.min(b), inner, inner + 1, a.max(b)]);
    }
    let mut patches = Vec::with_capacity(drafts.len());
    let mut net_at = first_local;
    for d in &drafts {
        let ctx = PatchIds {
            canon: &canon,
            curves: &curves,
            id_of: &id_of,
        };
        patches.push(ctx.patch(d, &mut net_at));
    }
    let curve_owners = curve_owners(&canon, &patches)?;
    Ok(AdaptivePlan {
        num_base_vertices: r.num_base,
        num_vertices: first_curve_point + 2 * curves.len() as u32,
        steps: r.steps,
        local_points,
        patches,
        curves,
        first_curve_point,
        first_regular_corner,
        curve_owners,
        first_corner,
        corner_owners,
        level_stats,
        isolation,
    })
}

/// Curve owners from the best candidates: `forward` when the curve runs with the owner's edge
/// (its part of it).
fn curve_owners(
    canon: &Canonical,
    patches: &[AdaptivePatch],
) -> Result<Vec<CurveOwner>, TopologyError> {
    canon
        .curve_info
        .iter()
        .map(|info| {
            let (_, patch, edge, part) = info
                .owner
                .ok_or(TopologyError::AdaptiveUnbalanced { level: 0, face: 0 })?;
            let pe = &patches[patch as usize].edges[edge as usize];
            Ok(CurveOwner {
                patch,
                edge,
                part,
                forward: !pe.reversed[usize::from(part == 2)],
                triangle: false,
            })
        })
        .collect()
}

/// What numbering a patch reads: curve ids, their points and the corner ids.
struct PatchIds<'a, F: Fn(Centre) -> u32> {
    canon: &'a Canonical,
    curves: &'a [[u32; 4]],
    id_of: &'a F,
}

impl<F: Fn(Centre) -> u32> PatchIds<'_, F> {
    /// The numbered patch of draft `d`; regular nets take ids from `net_at` on.
    fn patch(&self, d: &Draft, net_at: &mut u32) -> AdaptivePatch {
        let corner = |c: usize| (self.id_of)(d.square.faces[c % 4].centre);
        let control_points: ControlPoints = if d.kind == PatchKind::Regular {
            let ids = (*net_at..*net_at + 16).collect();
            *net_at += 16;
            ids
        } else {
            (0..4).map(corner).collect()
        };
        let mut transition_mask = 0;
        let edges = std::array::from_fn(|e| {
            let (a, b) = (corner(e), corner(e + 1));
            let curve = |key: &EdgeKey| self.canon.curves[key] as u32;
            match d.edges[e] {
                DraftEdge::Plain(key) => PatchEdge {
                    kind: EdgeKind::Plain,
                    curves: [curve(&key); 2],
                    reversed: [a > b; 2],
                },
                DraftEdge::Coarse([k0, k1], mid) => {
                    transition_mask |= 1 << e;
                    let m = (self.id_of)(mid);
                    PatchEdge {
                        kind: EdgeKind::Coarse,
                        curves: [curve(&k0), curve(&k1)],
                        reversed: [a > m, m > b],
                    }
                }
                DraftEdge::Fine {
                    own,
                    sibling,
                    mid,
                    mid_at_end,
                } => {
                    let (s, m) = (curve(&sibling), (self.id_of)(mid));
                    let ends = self.curves[s as usize];
                    let far = if ends[0] == m { ends[3] } else { ends[0] };
                    let (start, end) = if mid_at_end { (m, far) } else { (far, m) };
                    PatchEdge {
                        kind: EdgeKind::Fine,
                        curves: [curve(&own), s],
                        reversed: [a > b, start > end],
                    }
                }
            }
        });
        let sq = &d.square;
        AdaptivePatch {
            kind: d.kind,
            level: d.level,
            control_points,
            base_face: sq.face,
            sub_face: sq.corner,
            origin: sq.origin,
            size: sq.size,
            boundary_mask: d.boundary_mask,
            transition_mask,
            edges,
            reparam_valences: [0; 4],
            tangent_valences: [0; 4],
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The quadratic and cubic uniform B-spline bases on one span.
    fn quadratic(s: f64) -> [f64; 3] {
        [0.5 * (1.0 - s) * (1.0 - s), 0.5 + s - s * s, 0.5 * s * s]
    }

    fn cubic(s: f64) -> [f64; 4] {
        let t = 1.0 - s;
        [
            t * t * t / 6.0,
            (3.0 * s * s * s - 6.0 * s * s + 4.0) / 6.0,
            (-3.0 * s * s * s + 3.0 * s * s + 3.0 * s + 1.0) / 6.0,
            s * s * s / 6.0,
        ]
    }

    #[test]
    fn cubic_points_reproduce_each_quadratic_basis_function() {
        for k in 0..=20 {
            let s = k as f64 / 20.0;
            let (q, b) = (quadratic(s), cubic(s));
            for (i, qi) in q.iter().enumerate() {
                let c: f64 = QUADRATIC_TO_CUBIC
                    .iter()
                    .zip(b)
                    .map(|(m, bj)| m[i] * bj)
                    .sum();
                assert!((qi - c).abs() < 1e-15, "basis {i} at {s}: {qi} vs {c}");
            }
        }
        // Affine: each cubic point's weights sum to one.
        for row in QUADRATIC_TO_CUBIC {
            assert!((row.iter().sum::<f64>() - 1.0).abs() < 1e-15);
        }
    }
}
