//! Feature-adaptive Catmull-Clark plan (Nießner et al. 2012, OpenSubdiv's `RefineAdaptive` +
//! `PatchTableFactory`): which faces to refine, level by level, the stencils of every refined
//! vertex, the patches that cover the limit surface and the canonical boundary curves that
//! make shared patch edges bit-identical on the GPU. CPU only: indices are `u32`, weights `f64`;
//! packing for a device is the technique's business.
//!
//! # Design decisions
//! * **One refiner.** Level 0 is [`LevelTopology::from_mesh`] with every tagged crease and
//!   corner sharpness multiplied by [`AdaptiveOptions::sharpness_scale`] (infinite tags, ≥ 10,
//!   stay infinite, and boundary edges are infinitely sharp as always). Each step is
//!   [`refine_sparse`] of the selected faces: level L + 1 holds their children and the children
//!   of their one-ring. Only children of selected faces are *complete* (their own one-ring is
//!   present with exact points), so only complete faces are selected again or become patches.
//!   Complete faces partition the surface: a complete face is either selected (its children
//!   cover it) or a patch.
//! * **Irregular vertices** (of a complete face): any incident non-quad face; interior valence
//!   ≠ 4; any positive vertex sharpness or sharp incident edge, except three *regular sharp*
//!   cases the B-spline patch reproduces with phantom points (seed §3.7): (a) a boundary vertex
//!   of valence 3 whose interior edge is smooth, (b) a boundary vertex of valence 2 with
//!   infinite vertex sharpness (the corner rule of "edges and corners"), (c) an interior vertex
//!   of valence 4 with two opposite infinitely sharp edges, the other two smooth, and vertex
//!   sharpness 0 (a regular crease, handled in the patch as a boundary).
//! * **Selection** at level L < isolation: the complete, non-hole faces with an irregular
//!   corner. At level 0 that includes every non-quad face and every face sharing a vertex (so
//!   also an edge) with one, because their corners see a non-quad: the n-gon's level-2
//!   children can therefore never border a level-0 patch. Feature-adaptive isolation of a
//!   vertex feature keeps neighbours within one level by itself (the children of a refined
//!   face along an unrefined neighbour's edge have only regular corners there); the plan still
//!   checks it and returns [`TopologyError::AdaptiveUnbalanced`] instead of emitting a crack.
//! * **Patches.** A complete non-selected face is a Regular patch (16 control points gathered
//!   around its corners, rows across a boundary or infinitely sharp edge replaced by phantom
//!   points `2·P_edge − P_inner`, the corner by `4·P − 2·E₀ − 2·E₁ + F`, as OpenSubdiv does).
//!   At the isolation level an irregular complete face is an end cap: Gregory (the 20 points
//!   of [`crate::gregory::gregory_basis`] on that level, its four `P` replaced by the
//!   canonical corners below, which are the same limit points) or bilinear. Semi-sharp
//!   sharpness still positive at the isolation level is treated as infinite there, for the
//!   classification, the phantoms, the Gregory points and the corner masks alike (as the seed
//!   does): a regular crease becomes a crease patch, anything else an end cap. This is the one
//!   approximation besides the end caps; it vanishes once the isolation level reaches the
//!   sharpness. Holes make no patches and are never selected.
//! * **Parameterisation.** Each patch knows its base face (and sub-quad of a non-quad base
//!   face, numbered as [`crate::eval::LocalMesh::evaluate_subface`] does) and the square
//!   `origin + size·[0,1]²` of that (sub-)face's domain it covers. Its corners are rotated so
//!   that patch corner 0 is the corner at the square's `(0, 0)` and the corners run in the
//!   base face's orientation.
//! * **Transitions.** Each patch edge knows whether the neighbour across it is at the same
//!   level ([`EdgeKind::Plain`]), one level finer ([`EdgeKind::Coarse`]: the neighbour was
//!   refined) or one level coarser ([`EdgeKind::Fine`]: the neighbour's parent is a patch).
//! * **Canonical corners and curves** (what makes shared edges bit-identical on a GPU): every
//!   distinct limit point used as a patch corner is one local point, keyed by the coarsest
//!   vertex-vertex ancestor of the vertex, so a vertex at level L and its child at L + 1 share
//!   it. Its limit stencil is the Catmull-Clark limit mask ([`crate::limit`]) at the first
//!   (coarsest) level where it is a patch corner (where its whole ring is present). Every
//!   distinct patch edge at the finest level where it exists (a transition edge is the union of
//!   its two fine halves) is one cubic Bézier curve `[c0, b1, b2, c3]`, `c0 < c3` the canonical
//!   corner ids; `b1`, `b2` come from one owner patch, chosen Regular before Gregory before
//!   Bilinear, then by lowest patch index (a Regular owner of a half takes it by de Casteljau
//!   from its own edge). A patch's own boundary equals its curves mathematically (a Gregory
//!   edge next to a regular patch has regular ends, where the Gregory boundary is the
//!   B-spline's); a bilinear end cap is the Coons patch of its four curves.
//! * **One global vertex buffer.** Base vertices first, then one [`StencilBlock`] per level (its
//!   rows read only the previous level), then one block of local points (phantoms, Gregory
//!   points, canonical corners, curve points) that reads only refined vertices, so each block
//!   can run as one parallel kernel. Local points are not shared between patches except the
//!   canonical corners and curves (two boundary patches each have their own phantoms).
//! * **Cost.** Faces are drafted in parallel per level, canonical corner and curve stencils in
//!   parallel chunks appended in order, so the plan is the same with any thread count. Most of
//!   the remaining time is the sparse refinement itself and first-touch page faults of the
//!   stencil tables.

use crate::error::TopologyError;
use crate::limit::{catmark_limit_masks, LimitRule, LimitVertex};
use crate::mesh::{ControlMesh, Topology, INVALID};
use crate::patch::catmark_regular_weights;
use crate::refine::{refine_sparse, ChildMaps, ChildOrigin, LevelTopology};
use crate::sdc::{is_infinite, vertex_rule, Rule, Scheme, SHARPNESS_INFINITE};
use crate::stencil::StencilTable;
use rayon::prelude::*;

/// How faces still irregular at the isolation level are drawn.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Hash)]
pub enum EndCap {
    /// Gregory patch (20 points), as OpenSubdiv does by default.
    #[default]
    Gregory,
    /// Coons patch of the four canonical boundary curves (the seed's bilinear choice).
    Bilinear,
}

/// Options of [`plan_adaptive`].
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct AdaptiveOptions {
    /// Deepest refinement level, `1..=8`.
    pub isolation: u32,
    pub end_cap: EndCap,
    /// Multiplies every tagged edge and vertex sharpness before planning (finite, ≥ 0);
    /// infinite tags and boundary edges stay infinitely sharp.
    pub sharpness_scale: f32,
}

impl Default for AdaptiveOptions {
    fn default() -> Self {
        AdaptiveOptions {
            isolation: 4,
            end_cap: EndCap::Gregory,
            sharpness_scale: 1.0,
        }
    }
}

/// Rows computing a contiguous range of global vertices.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StencilBlock {
    /// Row `r` computes global vertex `first_vertex + r`.
    pub first_vertex: u32,
    /// Indices are global vertex ids, all below `first_vertex`.
    pub table: StencilTable,
}

/// Patch counts of one level (the seed's Fig. 5.2).
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct LevelStats {
    pub regular: u32,
    pub end_caps: u32,
    /// Faces held at this level (the selection of the level above and its one-ring).
    pub faces: u32,
    /// Faces of a uniform refinement to this level.
    pub uniform_faces: u64,
}

#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum PatchKind {
    Regular,
    Gregory,
    Bilinear,
}

/// Level of the neighbour across a patch edge.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum EdgeKind {
    /// Same level (or no neighbour).
    Plain,
    /// The neighbour is one level finer: two curves, one per half.
    Coarse,
    /// The neighbour is one level coarser: this edge is half of its edge.
    Fine,
}

/// Curves of one patch edge; see [`EdgeKind`].
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PatchEdge {
    pub kind: EdgeKind,
    /// Plain: both the edge's curve. Coarse: first and second half in the patch's edge
    /// direction. Fine: this edge's curve, then its sibling half.
    pub curves: [u32; 2],
    /// The patch's edge direction runs from the curve's point 3 to its point 0.
    pub reversed: [bool; 2],
}

/// One patch of the plan.
#[derive(Clone, Debug, PartialEq)]
pub struct AdaptivePatch {
    pub kind: PatchKind,
    pub level: u8,
    /// Global vertex ids. Regular: 16, row-major 4×4 as [`crate::patch`] (phantoms
    /// substituted); Gregory: 20, per corner `P, Ep, Em, Fp, Fm`; Bilinear: the 4 canonical
    /// corners.
    pub control_points: Vec<u32>,
    pub base_face: u32,
    /// Sub-quad of a non-quad base face; 0 for quads.
    pub sub_face: u8,
    /// Patch `(u, v)` covers `(sub)face parameter origin + size·(u, v)`.
    pub origin: [f64; 2],
    pub size: f64,
    /// Bit `i`: edge `i` is a boundary or infinitely sharp crease handled in the patch.
    pub boundary_mask: u8,
    /// Bit `i`: the neighbour across edge `i` is one level finer.
    pub transition_mask: u8,
    /// Edge 0: v0→v1 (v = 0), 1: v1→v2 (u = 1), 2: v2→v3 (v = 1), 3: v3→v0 (u = 0).
    pub edges: [PatchEdge; 4],
}

/// Everything a device needs to draw the feature-adaptive limit surface.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct AdaptivePlan {
    /// Global ids `0..num_base_vertices` are the control mesh's vertices.
    pub num_base_vertices: u32,
    /// Size of the global vertex buffer.
    pub num_vertices: u32,
    /// Refinement levels 1..=isolation, in order.
    pub steps: Vec<StencilBlock>,
    /// Phantom points, Gregory points, canonical corners and curve points (the last block).
    pub local_points: StencilBlock,
    pub patches: Vec<AdaptivePatch>,
    /// Canonical boundary curves: cubic Bézier control points (global ids).
    pub curves: Vec<[u32; 4]>,
    /// Per level 0..=isolation.
    pub level_stats: Vec<LevelStats>,
    pub isolation: u32,
}

/// Position and parametric derivatives of a patch.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct PatchSample {
    pub position: [f64; 3],
    pub du: [f64; 3],
    pub dv: [f64; 3],
}

/// Corner positions of the unit square, patch corner order.
const POS: [(i32, i32); 4] = [(0, 0), (1, 0), (1, 1), (0, 1)];
/// Directions around a corner in its local frame (x toward the next corner, y the previous).
const DIR: [(i32, i32); 4] = [(1, 0), (0, 1), (-1, 0), (0, -1)];

#[inline]
fn slot(a: i32, b: i32) -> usize {
    (4 * (b + 1) + (a + 1)) as usize
}

/// Plan the feature-adaptive refinement and patches of `mesh` (Catmull-Clark).
///
/// ```
/// use topology::{plan_adaptive, AdaptiveOptions, ControlMesh, EndCap};
/// // A cube: eight valence-3 vertices, isolated to level 2.
/// let p = [[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.],
///          [0., 0., 1.], [1., 0., 1.], [1., 1., 1.], [0., 1., 1.]];
/// let faces = [[0u32, 3, 2, 1], [4, 5, 6, 7], [0, 1, 5, 4], [1, 2, 6, 5], [2, 3, 7, 6], [3, 0, 4, 7]];
/// let mesh = ControlMesh::from_polygons(p.to_vec(), &faces);
/// let opts = AdaptiveOptions { isolation: 2, end_cap: EndCap::Gregory, sharpness_scale: 1.0 };
/// let plan = plan_adaptive(&mesh, &opts).unwrap();
/// assert_eq!(plan.level_stats[2].end_caps, 24); // three per corner
/// let verts = plan.apply(&mesh.positions);
/// let centre = plan.evaluate(&verts, 0, 0.5, 0.5).position;
/// assert!(centre.iter().all(|x| x.is_finite()));
/// ```
pub fn plan_adaptive(
    mesh: &ControlMesh,
    opts: &AdaptiveOptions,
) -> Result<AdaptivePlan, TopologyError> {
    if !(1..=8).contains(&opts.isolation) {
        return Err(TopologyError::IsolationOutOfRange {
            isolation: opts.isolation,
        });
    }
    let scale = opts.sharpness_scale;
    if !scale.is_finite() || scale < 0.0 {
        return Err(TopologyError::BadSharpnessScale { scale });
    }
    let scaled = scaled_mesh(mesh, scale)?;
    let levels = build_levels(&scaled, opts.isolation as usize)?;
    assemble(&scaled, opts, levels)
}

/// A copy of `mesh` with tag sharpness scaled (infinite tags stay infinite); rejects NaN or
/// negative sharpness.
fn scaled_mesh(mesh: &ControlMesh, scale: f32) -> Result<ControlMesh, TopologyError> {
    let scale_one = |s: f32| {
        if is_infinite(s) {
            s
        } else {
            s * scale
        }
    };
    let mut out = mesh.clone();
    for c in &mut out.creases {
        if c.sharpness.is_nan() || c.sharpness < 0.0 {
            return Err(TopologyError::BadEdgeSharpness {
                v0: c.vertices[0],
                v1: c.vertices[1],
                sharpness: c.sharpness,
            });
        }
        c.sharpness = scale_one(c.sharpness);
    }
    for c in &mut out.corners {
        if c.sharpness.is_nan() || c.sharpness < 0.0 {
            return Err(TopologyError::BadVertexSharpness {
                vertex: c.vertex,
                sharpness: c.sharpness,
            });
        }
        c.sharpness = scale_one(c.sharpness);
    }
    Ok(out)
}

/// One level of the plan.
struct Lvl {
    /// Topology and sharpness; at the isolation level the sharpness is the *effective* one
    /// (every positive value infinite).
    topo: LevelTopology,
    /// Global id of vertex 0 of this level.
    base: u32,
    complete: Vec<bool>,
    hole: Vec<bool>,
    selected: Vec<bool>,
    irregular: Vec<bool>,
    /// Per vertex: global id of its coarsest vertex-vertex ancestor (the canonical key).
    anc: Vec<u32>,
    /// Maps of the step that made this level (none for level 0).
    maps: Option<ChildMaps>,
    /// Stencils of this level's vertices over the parent's (level ≥ 1).
    stencils: Option<StencilTable>,
    /// Number of vertex-vertex children in this level (its edge-vertices follow).
    kv: usize,
}

impl Lvl {
    fn t(&self) -> &Topology {
        &self.topo.topology
    }
    /// Sharp for the patch: positive sharpness or a single face.
    fn sharp_edge(&self, e: usize) -> bool {
        self.topo.edge_sharpness[e] > 0.0 || self.t().is_boundary_edge(e)
    }
}

fn build_levels(mesh: &ControlMesh, iso: usize) -> Result<Vec<Lvl>, TopologyError> {
    let topo = LevelTopology::from_mesh(mesh, Scheme::CatmullClark)?;
    let nf = topo.topology.num_faces();
    let nv = topo.topology.num_vertices();
    let mut hole = vec![false; nf];
    for &h in &mesh.holes {
        match hole.get_mut(h as usize) {
            Some(x) => *x = true,
            None => {
                return Err(TopologyError::TagOutOfRange {
                    tag: crate::error::TagKind::Hole,
                    index: h,
                    count: nf,
                })
            }
        }
    }
    let mut levels = vec![Lvl {
        topo,
        base: 0,
        complete: vec![true; nf],
        hole,
        selected: Vec::new(),
        irregular: Vec::new(),
        anc: (0..nv as u32).collect(),
        maps: None,
        stencils: None,
        kv: 0,
    }];
    for l in 0..=iso {
        let last = l == iso;
        let lvl = levels.last_mut().expect("level present");
        if last {
            for s in lvl
                .topo
                .edge_sharpness
                .iter_mut()
                .chain(lvl.topo.vertex_sharpness.iter_mut())
            {
                if *s > 0.0 {
                    *s = SHARPNESS_INFINITE;
                }
            }
        }
        let irregular: Vec<bool> = (0..lvl.t().num_vertices())
            .into_par_iter()
            .with_min_len(1024)
            .map(|v| vertex_irregular(lvl, v))
            .collect();
        lvl.irregular = irregular;
        let t = &lvl.topo.topology;
        lvl.selected = (0..t.num_faces())
            .map(|f| {
                !last
                    && lvl.complete[f]
                    && !lvl.hole[f]
                    && t.face_vertices(f)
                        .iter()
                        .any(|&v| lvl.irregular[v as usize])
            })
            .collect();
        if last {
            break;
        }
        let selection: Vec<u32> = (0..t.num_faces() as u32)
            .filter(|&f| lvl.selected[f as usize])
            .collect();
        let r = refine_sparse(
            lvl.topo.view(),
            Scheme::CatmullClark,
            &mesh.options,
            &selection,
        )?;
        let base = lvl
            .base
            .checked_add(t.num_vertices() as u32)
            .filter(|b| {
                b.checked_add(r.child.topology.num_vertices() as u32)
                    .is_some()
            })
            .ok_or(TopologyError::RefinementTooLarge {
                faces: t.num_faces(),
            })?;
        let maps = r.maps;
        let complete = maps
            .child_face_parent
            .iter()
            .map(|&p| lvl.selected[p as usize])
            .collect();
        let hole = maps
            .child_face_parent
            .iter()
            .map(|&p| lvl.hole[p as usize])
            .collect();
        let anc = maps
            .child_vertex_origin
            .iter()
            .enumerate()
            .map(|(c, o)| match *o {
                ChildOrigin::Vertex(p) => lvl.anc[p as usize],
                _ => base + c as u32,
            })
            .collect();
        let kv = maps
            .child_vertex_origin
            .iter()
            .take_while(|o| matches!(o, ChildOrigin::Vertex(_)))
            .count();
        levels.push(Lvl {
            topo: r.child,
            base,
            complete,
            hole,
            selected: Vec::new(),
            irregular: Vec::new(),
            anc,
            maps: Some(maps),
            stencils: Some(r.stencils),
            kv,
        });
    }
    Ok(levels)
}

/// Whether vertex `v` (of a complete face) needs isolating: see the module docs.
fn vertex_irregular(lvl: &Lvl, v: usize) -> bool {
    let t = lvl.t();
    let faces = t.vertex_faces(v);
    let edges = t.vertex_edges(v);
    if faces
        .iter()
        .any(|&f| t.face_vertices(f as usize).len() != 4)
    {
        return true;
    }
    let vs = lvl.topo.vertex_sharpness[v];
    let (nf, ne) = (faces.len(), edges.len());
    let sharp = |e: u32| lvl.sharp_edge(e as usize);
    let infinite =
        |e: u32| t.is_boundary_edge(e as usize) || is_infinite(lvl.topo.edge_sharpness[e as usize]);
    if ne == nf {
        if vs > 0.0 || ne != 4 {
            return true;
        }
        let mut sharp_edges = edges.iter().copied().filter(|&e| sharp(e));
        match (sharp_edges.next(), sharp_edges.next(), sharp_edges.next()) {
            (None, _, _) => false,
            (Some(a), Some(b), None) => {
                if !(infinite(a) && infinite(b)) {
                    return true;
                }
                // Consecutive edges share a face; a regular crease runs straight through.
                let fa = t.edge_faces(a as usize);
                let fb = t.edge_faces(b as usize);
                fa.iter().any(|&x| x != INVALID && fb.contains(&x))
            }
            _ => true,
        }
    } else if ne == nf + 1 {
        match nf {
            2 => {
                vs > 0.0
                    || edges.iter().any(|&e| {
                        let boundary = t.is_boundary_edge(e as usize);
                        boundary != sharp(e) || (boundary && !infinite(e))
                    })
            }
            1 => !is_infinite(vs),
            _ => true,
        }
    } else {
        true
    }
}

/// A linear combination of at most four global vertices (a gathered or phantom point).
#[derive(Clone, Copy, Debug, Default)]
struct Combo {
    n: u8,
    idx: [u32; 4],
    w: [f64; 4],
}

impl Combo {
    fn one(i: u32) -> Combo {
        Combo {
            n: 1,
            idx: [i, 0, 0, 0],
            w: [1.0, 0.0, 0.0, 0.0],
        }
    }
    /// `2·a − b`. Phantoms extrapolate gathered points (one term each) or, at a corner,
    /// extrapolated ones (two terms each), so four terms always suffice.
    fn extrapolate(a: &Combo, b: &Combo) -> Combo {
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

/// A patch before local points are numbered.
struct Draft {
    level: u8,
    face: u32,
    shift: u8,
    kind: PatchKind,
    boundary_mask: u8,
    /// Regular: the 16 gathered ids (`INVALID` where a phantom goes).
    grid: Option<[u32; 16]>,
    /// Gregory: 20 stencils over global ids, patch corner order.
    gregory: Option<Vec<Vec<(u32, f64)>>>,
    base_face: u32,
    sub_face: u8,
    origin: [f64; 2],
    size: f64,
}

/// Base face, sub-face, origin, size and corner shift of face `f` of level `l`.
fn frame(levels: &[Lvl], l: usize, f: usize) -> (u32, u8, [f64; 2], f64, u8) {
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

/// The face corners and edges of `f` rotated into patch order.
fn rotated(t: &Topology, f: usize, shift: u8) -> ([u32; 4], [u32; 4]) {
    let fv = t.face_vertices(f);
    let fe = t.face_edge_list(f);
    let s = shift as usize;
    (
        std::array::from_fn(|p| fv[(p + s) % 4]),
        std::array::from_fn(|p| fe[(p + s) % 4]),
    )
}

fn corner_in(t: &Topology, g: u32, v: u32) -> Option<usize> {
    let fv = t.face_vertices(g as usize);
    if fv.len() != 4 {
        return None;
    }
    fv.iter().position(|&x| x == v)
}

/// The 4×4 points of a regular patch (level-local ids) with phantoms for the masked edges.
/// Returns the gathered global ids (`INVALID` where a phantom goes) and the boundary mask;
/// [`phantom_grid`] completes them.
fn gather_regular(lvl: &Lvl, f: usize, shift: u8) -> Option<([u32; 16], u8)> {
    let t = lvl.t();
    let (fv, fe) = rotated(t, f, shift);
    let mut ids = [INVALID; 16];
    let base = lvl.base;
    let set = |a: i32, b: i32, v: u32, grid: &mut [u32; 16]| -> bool {
        let s = slot(a, b);
        if grid[s] != INVALID {
            return grid[s] == base + v;
        }
        grid[s] = base + v;
        true
    };
    for p in 0..4 {
        let (ox, oy) = POS[p];
        if !set(ox, oy, fv[p], &mut ids) {
            return None;
        }
    }
    for p in 0..4 {
        let v = fv[p];
        let (ox, oy) = POS[p];
        let (nx, ny) = POS[(p + 1) % 4];
        let (px, py) = POS[(p + 3) % 4];
        let (xx, xy) = (nx - ox, ny - oy);
        let (yx, yy) = (px - ox, py - oy);
        let at = |d: (i32, i32)| (ox + d.0 * xx + d.1 * yx, oy + d.0 * xy + d.1 * yy);
        let add = |a: (i32, i32), b: (i32, i32)| (a.0 + b.0, a.1 + b.1);
        let start = corner_in(t, f as u32, v)?;
        let mut steps = 0;
        // Forward: across the edge entering v.
        let (mut g, mut k) = (f as u32, start);
        for step in 1..=3usize {
            let e = t.face_edge_list(g as usize)[(k + 3) % 4];
            if lvl.sharp_edge(e as usize) {
                break;
            }
            let [x, y] = t.edge_faces(e as usize);
            let h = if x == g { y } else { x };
            if h == INVALID || h == f as u32 {
                break;
            }
            let kh = corner_in(t, h, v)?;
            let hv = t.face_vertices(h as usize);
            let (d0, d1) = (DIR[step % 4], DIR[(step + 1) % 4]);
            let (a0, a1, a2) = (at(d0), at(add(d0, d1)), at(d1));
            if !(set(a0.0, a0.1, hv[(kh + 1) % 4], &mut ids)
                && set(a1.0, a1.1, hv[(kh + 2) % 4], &mut ids)
                && set(a2.0, a2.1, hv[(kh + 3) % 4], &mut ids))
            {
                return None;
            }
            g = h;
            k = kh;
            steps = step;
        }
        // Backward: across the edge leaving v, for what the forward walk could not reach.
        let (mut g, mut k) = (f as u32, start);
        for step in 1..=(3 - steps) {
            let e = t.face_edge_list(g as usize)[k];
            if lvl.sharp_edge(e as usize) {
                break;
            }
            let [x, y] = t.edge_faces(e as usize);
            let h = if x == g { y } else { x };
            if h == INVALID || h == f as u32 {
                break;
            }
            let kh = corner_in(t, h, v)?;
            let hv = t.face_vertices(h as usize);
            let ds = DIR[(4 - step % 4) % 4];
            let ds1 = DIR[(5 - step % 4) % 4];
            let (a0, a1, a2) = (at(ds1), at(add(ds1, ds)), at(ds));
            if !(set(a0.0, a0.1, hv[(kh + 3) % 4], &mut ids)
                && set(a1.0, a1.1, hv[(kh + 2) % 4], &mut ids)
                && set(a2.0, a2.1, hv[(kh + 1) % 4], &mut ids))
            {
                return None;
            }
            g = h;
            k = kh;
        }
    }
    let mut mask = 0u8;
    for (p, &e) in fe.iter().enumerate() {
        if lvl.sharp_edge(e as usize) {
            mask |= 1 << p;
        }
    }
    phantom_grid(&ids, mask)?;
    Some((ids, mask))
}

/// The 16 points of a regular patch from its gathered ids: rows and columns across the
/// masked edges extrapolated (`2·P_edge − P_inner`), columns (edges 3 and 1) first where
/// their rows exist, then rows (edges 0 and 2), which gives the corner rule where two masked
/// edges meet. `None` if a point is missing.
fn phantom_grid(ids: &[u32; 16], mask: u8) -> Option<[Combo; 16]> {
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

/// Append a stencil row: indices sorted, duplicates merged.
fn push_row(table: &mut StencilTable, terms: &mut [(u32, f64)]) {
    terms.sort_unstable_by_key(|t| t.0);
    let mut last = INVALID;
    for &(i, w) in terms.iter() {
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

/// Weights (vertex, each edge-neighbour, each face-opposite vertex) of the smooth
/// Catmull-Clark limit position mask of valence `n` ([`crate::limit`]), cached per valence.
fn smooth_mask(cache: &mut Vec<Option<[f64; 3]>>, n: usize) -> [f64; 3] {
    if cache.len() <= n {
        cache.resize(n + 1, None);
    }
    *cache[n].get_or_insert_with(|| {
        let m = catmark_limit_masks(&LimitVertex {
            valence: n,
            boundary: false,
            rule: LimitRule::Smooth,
        })
        .position;
        [
            m.vertex,
            m.edges.first().copied().unwrap_or(0.0),
            m.faces.first().copied().unwrap_or(0.0),
        ]
    })
}

/// Limit-position stencil (level-local ids) of vertex `v` of `lvl` (its ring complete).
/// Only positions are needed, and their masks do not depend on the ring's order.
fn limit_stencil(
    lvl: &Lvl,
    v: usize,
    cache: &mut Vec<Option<[f64; 3]>>,
    out: &mut Vec<(u32, f64)>,
) {
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
    match rule {
        Rule::Corner => out.push((v as u32, 1.0)),
        Rule::Crease => {
            out.push((v as u32, 2.0 / 3.0));
            for &e in &sharp {
                out.push((other(e), 1.0 / 6.0));
            }
        }
        Rule::Smooth | Rule::Dart => {
            let [wv, we, wf] = smooth_mask(cache, edges.len());
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

/// Weights over the 16 slots of the Bézier points of regular patch edge `p`, in the edge's
/// direction.
fn regular_edge_bezier(p: usize) -> [[f64; 16]; 4] {
    // The four B-spline points along the edge (limit across it), in edge direction.
    let line: [(i32, i32); 4] = match p {
        0 => [(-1, 0), (0, 0), (1, 0), (2, 0)],
        1 => [(1, -1), (1, 0), (1, 1), (1, 2)],
        2 => [(2, 1), (1, 1), (0, 1), (-1, 1)],
        _ => [(0, 2), (0, 1), (0, 0), (0, -1)],
    };
    let across: (i32, i32) = if p.is_multiple_of(2) { (0, 1) } else { (1, 0) };
    let q: Vec<[f64; 16]> = line
        .iter()
        .map(|&(a, b)| {
            let mut w = [0.0; 16];
            w[slot(a - across.0, b - across.1)] += 1.0 / 6.0;
            w[slot(a, b)] += 4.0 / 6.0;
            w[slot(a + across.0, b + across.1)] += 1.0 / 6.0;
            w
        })
        .collect();
    let mix = |terms: &[(f64, usize)]| {
        let mut w = [0.0; 16];
        for &(s, i) in terms {
            for (o, x) in w.iter_mut().zip(&q[i]) {
                *o += s * x;
            }
        }
        w
    };
    [
        mix(&[(1.0 / 6.0, 0), (4.0 / 6.0, 1), (1.0 / 6.0, 2)]),
        mix(&[(2.0 / 3.0, 1), (1.0 / 3.0, 2)]),
        mix(&[(1.0 / 3.0, 1), (2.0 / 3.0, 2)]),
        mix(&[(1.0 / 6.0, 1), (4.0 / 6.0, 2), (1.0 / 6.0, 3)]),
    ]
}

/// Half `h` (0: first, 1: second) of a Bézier curve by de Casteljau, as weights over the
/// curve's four points.
fn bezier_half(h: usize) -> [[f64; 4]; 4] {
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
/// 1/2 first/second half of a coarse edge).
type Owner = (u8, u32, u8, u8);

fn kind_rank(k: PatchKind) -> u8 {
    match k {
        PatchKind::Regular => 0,
        PatchKind::Gregory => 1,
        PatchKind::Bilinear => 2,
    }
}

/// Rows per parallel chunk of local points.
const CHUNK: usize = 2048;

/// Numbered local points.
struct Locals {
    first: u32,
    table: StencilTable,
}

impl Locals {
    fn push(&mut self, terms: &mut [(u32, f64)]) -> u32 {
        let id = self.first + self.table.len() as u32;
        push_row(&mut self.table, terms);
        id
    }
    /// Append the rows of `table` (built by [`push_row`]); returns the id of its first row.
    fn append(&mut self, table: &StencilTable) -> u32 {
        let id = self.first + self.table.len() as u32;
        let shift = self.table.indices.len() as u32;
        self.table.indices.extend_from_slice(&table.indices);
        self.table.weights.extend_from_slice(&table.weights);
        self.table
            .offsets
            .extend(table.offsets[1..].iter().map(|&o| o + shift));
        id
    }
    /// Expand a global id into refined-vertex terms (local points by their rows).
    fn expand(&self, id: u32, w: f64, out: &mut Vec<(u32, f64)>) {
        if id < self.first {
            out.push((id, w));
        } else {
            let (idx, ws) = self.table.stencil((id - self.first) as usize);
            out.extend(idx.iter().zip(ws).map(|(&i, &x)| (i, w * x)));
        }
    }
}

fn assemble(
    mesh: &ControlMesh,
    opts: &AdaptiveOptions,
    mut levels: Vec<Lvl>,
) -> Result<AdaptivePlan, TopologyError> {
    let iso = opts.isolation as usize;
    let last = levels.last().expect("levels");
    let first_local = last.base + last.t().num_vertices() as u32;
    let mut locals = Locals {
        first: first_local,
        table: StencilTable {
            offsets: vec![0],
            num_sources: first_local as usize,
            ..StencilTable::default()
        },
    };

    // Patches, level by level (faces in parallel).
    let mut drafts: Vec<Draft> = Vec::new();
    for (l, lvl) in levels.iter().enumerate() {
        let is_last = l == iso;
        let candidates: Vec<usize> = (0..lvl.t().num_faces())
            .filter(|&f| lvl.complete[f] && !lvl.hole[f] && !lvl.selected[f])
            .collect();
        // An indexed collect writes the drafts in place (no per-face option, no list merge).
        let found: Vec<Result<Draft, TopologyError>> = candidates
            .into_par_iter()
            .with_min_len(256)
            .map(|f| {
                let irregular = lvl
                    .t()
                    .face_vertices(f)
                    .iter()
                    .any(|&v| lvl.irregular[v as usize]);
                if irregular && !is_last {
                    return Err(TopologyError::AdaptivePatch {
                        level: l as u32,
                        face: f,
                    });
                }
                let (base_face, sub_face, origin, size, shift) = frame(&levels, l, f);
                let mut d = Draft {
                    level: l as u8,
                    face: f as u32,
                    shift,
                    kind: PatchKind::Regular,
                    boundary_mask: 0,
                    grid: None,
                    gregory: None,
                    base_face,
                    sub_face,
                    origin,
                    size,
                };
                if irregular {
                    d.kind = match opts.end_cap {
                        EndCap::Gregory => PatchKind::Gregory,
                        EndCap::Bilinear => PatchKind::Bilinear,
                    };
                    if d.kind == PatchKind::Gregory {
                        d.gregory = Some(gregory_points(mesh, lvl, f, shift)?);
                    }
                } else {
                    let (grid, mask) =
                        gather_regular(lvl, f, shift).ok_or(TopologyError::AdaptivePatch {
                            level: l as u32,
                            face: f,
                        })?;
                    d.grid = Some(grid);
                    d.boundary_mask = mask;
                }
                Ok(d)
            })
            .collect();
        drafts.reserve(found.len());
        for d in found {
            drafts.push(d?);
        }
    }

    // Local points come to about 7 rows of 45 entries per patch on OpenSubdiv's shapes
    // (corners, curve points, phantoms, Gregory points): reserve once instead of regrowing.
    locals.table.offsets.reserve(7 * drafts.len());
    locals.table.indices.reserve(45 * drafts.len());
    locals.table.weights.reserve(45 * drafts.len());
    // Control points (phantoms and Gregory points become local points).
    let mut terms: Vec<(u32, f64)> = Vec::with_capacity(64);
    let mut patches: Vec<AdaptivePatch> = Vec::with_capacity(drafts.len());
    let blank_edge = PatchEdge {
        kind: EdgeKind::Plain,
        curves: [INVALID; 2],
        reversed: [false; 2],
    };
    for d in &drafts {
        let mut cps = Vec::with_capacity(20);
        if let Some(ids) = &d.grid {
            let grid = phantom_grid(ids, d.boundary_mask).ok_or(TopologyError::AdaptivePatch {
                level: d.level as u32,
                face: d.face as usize,
            })?;
            for c in grid.iter() {
                if c.n == 1 && c.w[0] == 1.0 {
                    cps.push(c.idx[0]);
                } else {
                    terms.clear();
                    terms.extend((0..c.n as usize).map(|k| (c.idx[k], c.w[k])));
                    cps.push(locals.push(&mut terms));
                }
            }
        } else if let Some(g) = &d.gregory {
            for (k, row) in g.iter().enumerate() {
                if k % 5 == 0 {
                    // P: the canonical corner, filled below.
                    cps.push(INVALID);
                } else {
                    terms.clear();
                    terms.extend_from_slice(row);
                    cps.push(locals.push(&mut terms));
                }
            }
        } else {
            cps.extend_from_slice(&[INVALID; 4]);
        }
        patches.push(AdaptivePatch {
            kind: d.kind,
            level: d.level,
            control_points: cps,
            base_face: d.base_face,
            sub_face: d.sub_face,
            origin: d.origin,
            size: d.size,
            boundary_mask: d.boundary_mask,
            transition_mask: 0,
            edges: [blank_edge; 4],
        });
    }

    // Canonical corners, at the coarsest level each is a patch corner (drafts are level-ordered).
    // First the numbering (sequential, cheap), then the limit stencils (in parallel chunks,
    // appended in order).
    let mut canon = vec![INVALID; first_local as usize];
    let mut needed: Vec<(u8, u32)> = Vec::new();
    let mut corners: Vec<[u32; 4]> = Vec::with_capacity(drafts.len());
    let first_canon = first_local + locals.table.len() as u32;
    for (d, patch) in drafts.iter().zip(patches.iter_mut()) {
        let lvl = &levels[d.level as usize];
        let (fv, _) = rotated(lvl.t(), d.face as usize, d.shift);
        let mut ids = [0u32; 4];
        for (p, &v) in fv.iter().enumerate() {
            let key = lvl.anc[v as usize] as usize;
            if canon[key] == INVALID {
                canon[key] = first_canon + needed.len() as u32;
                needed.push((d.level, v));
            }
            ids[p] = canon[key];
            match patch.kind {
                PatchKind::Gregory => patch.control_points[5 * p] = ids[p],
                PatchKind::Bilinear => patch.control_points[p] = ids[p],
                PatchKind::Regular => {}
            }
        }
        corners.push(ids);
    }
    let chunks: Vec<StencilTable> = needed
        .par_chunks(CHUNK)
        .map(|chunk| {
            let mut table = StencilTable {
                offsets: vec![0],
                ..StencilTable::default()
            };
            let mut cache = Vec::new();
            let mut terms = Vec::with_capacity(32);
            for &(l, v) in chunk {
                let lvl = &levels[l as usize];
                terms.clear();
                limit_stencil(lvl, v as usize, &mut cache, &mut terms);
                for t in terms.iter_mut() {
                    t.0 += lvl.base;
                }
                push_row(&mut table, &mut terms);
            }
            table
        })
        .collect();
    for c in &chunks {
        locals.append(c);
    }
    let canon_of = |l: usize, v: u32, face: u32| -> Result<u32, TopologyError> {
        let c = canon[levels[l].anc[v as usize] as usize];
        if c == INVALID {
            Err(TopologyError::AdaptiveUnbalanced {
                level: l as u32,
                face: face as usize,
            })
        } else {
            Ok(c)
        }
    };

    // Edges: neighbour levels, balance, curves.
    let mut curve_of: Vec<Vec<u32>> = levels
        .iter()
        .map(|l| vec![INVALID; l.t().num_edges()])
        .collect();
    let mut curves: Vec<[u32; 4]> = Vec::new();
    let mut owners: Vec<Owner> = Vec::new();
    let mut curve_id =
        |l: usize, e: u32, ends: [u32; 2], owner: Owner, curves: &mut Vec<[u32; 4]>| -> u32 {
            let slot = &mut curve_of[l][e as usize];
            if *slot == INVALID {
                *slot = curves.len() as u32;
                let (a, b) = (ends[0].min(ends[1]), ends[0].max(ends[1]));
                curves.push([a, INVALID, INVALID, b]);
                owners.push(owner);
            } else if owner < owners[*slot as usize] {
                owners[*slot as usize] = owner;
            }
            *slot
        };
    for (pi, (d, patch)) in drafts.iter().zip(patches.iter_mut()).enumerate() {
        let l = d.level as usize;
        let lvl = &levels[l];
        let t = lvl.t();
        let (fv, fe) = rotated(t, d.face as usize, d.shift);
        let rank = kind_rank(d.kind);
        let unbalanced = || TopologyError::AdaptiveUnbalanced {
            level: l as u32,
            face: d.face as usize,
        };
        for p in 0..4 {
            let e = fe[p];
            let (a, b) = (fv[p], fv[(p + 1) % 4]);
            let [x, y] = t.edge_faces(e as usize);
            let g = if x == d.face { y } else { x };
            let kind = if g == INVALID || lvl.hole[g as usize] {
                EdgeKind::Plain
            } else if lvl.complete[g as usize] {
                if lvl.selected[g as usize] {
                    EdgeKind::Coarse
                } else {
                    EdgeKind::Plain
                }
            } else {
                let maps = lvl.maps.as_ref().ok_or_else(unbalanced)?;
                let gp = maps.child_face_parent[g as usize] as usize;
                let parent = &levels[l - 1];
                if parent.hole[gp] {
                    EdgeKind::Plain
                } else if parent.complete[gp] && !parent.selected[gp] {
                    EdgeKind::Fine
                } else {
                    return Err(unbalanced());
                }
            };
            let (ca, cb) = (canon_of(l, a, d.face)?, canon_of(l, b, d.face)?);
            let pe = &mut patch.edges[p];
            pe.kind = kind;
            match kind {
                EdgeKind::Plain => {
                    let c = curve_id(l, e, [ca, cb], (rank, pi as u32, p as u8, 0), &mut curves);
                    pe.curves = [c, c];
                    pe.reversed = [ca > cb; 2];
                }
                EdgeKind::Fine => {
                    let c = curve_id(l, e, [ca, cb], (rank, pi as u32, p as u8, 0), &mut curves);
                    let sib = e ^ 1;
                    let [s0, s1] = t.edge_vertices(sib as usize);
                    // The shared end is the midpoint of the coarse edge.
                    let (start, end) = if s0 == a || s1 == a {
                        (if s0 == a { s1 } else { s0 }, a)
                    } else if s0 == b || s1 == b {
                        (b, if s0 == b { s1 } else { s0 })
                    } else {
                        return Err(unbalanced());
                    };
                    let (cs, ce) = (canon_of(l, start, d.face)?, canon_of(l, end, d.face)?);
                    // The sibling's owner is its own fine patch; this one never computes it.
                    let sc = curve_id(l, sib, [cs, ce], (u8::MAX, u32::MAX, 0, 0), &mut curves);
                    pe.curves = [c, sc];
                    pe.reversed = [ca > cb, cs > ce];
                }
                EdgeKind::Coarse => {
                    patch.transition_mask |= 1 << p;
                    let next = &levels[l + 1];
                    let maps = next.maps.as_ref().ok_or_else(unbalanced)?;
                    let m = maps.edge_child_vertex[e as usize];
                    if m == INVALID || (m as usize) < next.kv {
                        return Err(unbalanced());
                    }
                    let r = m - next.kv as u32;
                    let h0 = 2 * r + u32::from(t.edge_vertices(e as usize)[0] != a);
                    let h1 = h0 ^ 1;
                    // Both halves must be patches of level l + 1.
                    for h in [h0, h1] {
                        for cf in next.t().edge_faces(h as usize) {
                            if cf != INVALID
                                && next.complete[cf as usize]
                                && next.selected.get(cf as usize).copied().unwrap_or(false)
                            {
                                return Err(unbalanced());
                            }
                        }
                    }
                    let cm = canon_of(l + 1, m, d.face)?;
                    let c0 = curve_id(
                        l + 1,
                        h0,
                        [ca, cm],
                        (rank, pi as u32, p as u8, 1),
                        &mut curves,
                    );
                    let c1 = curve_id(
                        l + 1,
                        h1,
                        [cm, cb],
                        (rank, pi as u32, p as u8, 2),
                        &mut curves,
                    );
                    pe.curves = [c0, c1];
                    pe.reversed = [ca > cm, cm > cb];
                }
            }
        }
    }

    // Inner Bézier points of each curve from its owner.
    // Per patch edge and part (whole, first half, second half): Bézier weights over the slots.
    let edge_rows: [[[[f64; 16]; 4]; 3]; 4] = std::array::from_fn(|p| {
        let whole = regular_edge_bezier(p);
        std::array::from_fn(|part| {
            if part == 0 {
                return whole;
            }
            let h = bezier_half(part - 1);
            std::array::from_fn(|k| {
                let mut w = [0.0; 16];
                for (j, &s) in h[k].iter().enumerate() {
                    for (o, x) in w.iter_mut().zip(&whole[j]) {
                        *o += s * x;
                    }
                }
                w
            })
        })
    });
    // Curve `c` gets rows `2c` (its point 1) and `2c + 1` (its point 2) of this run of local
    // points, computed in parallel chunks and appended in order.
    if let Some(ci) = owners.iter().position(|o| o.1 == u32::MAX) {
        // A sibling half no patch has as its own edge: a level jump the checks missed.
        return Err(TopologyError::AdaptiveUnbalanced { level: 0, face: ci });
    }
    let first_curve_row = first_local + locals.table.len() as u32;
    let chunks: Vec<StencilTable> = owners
        .par_chunks(CHUNK)
        .enumerate()
        .map(|(chunk_index, chunk)| {
            let mut table = StencilTable {
                offsets: vec![0],
                ..StencilTable::default()
            };
            let mut scratch: Vec<(u32, f64)> = Vec::with_capacity(128);
            for (j, &(_, pi, p, part)) in chunk.iter().enumerate() {
                let ci = chunk_index * CHUNK + j;
                let patch = &patches[pi as usize];
                let (p, part) = (p as usize, part as usize);
                let ids = corners[pi as usize];
                // The segment runs in the patch's edge direction from `start_id`.
                let c = curves[ci];
                let start_id = if part == 2 {
                    // The midpoint: whichever end of the curve is not the patch corner.
                    if c[0] == ids[(p + 1) % 4] {
                        c[3]
                    } else {
                        c[0]
                    }
                } else {
                    ids[p]
                };
                let forward = start_id == c[0];
                for slot in [1usize, 2] {
                    // Curve point `slot` is the segment's Bézier point `k`.
                    let k = if forward { slot } else { 3 - slot };
                    scratch.clear();
                    match patch.kind {
                        PatchKind::Regular => {
                            for (s, &w) in edge_rows[p][part][k].iter().enumerate() {
                                if w != 0.0 {
                                    locals.expand(patch.control_points[s], w, &mut scratch);
                                }
                            }
                        }
                        PatchKind::Gregory => {
                            let cp = &patch.control_points;
                            let id = if k == 1 {
                                cp[5 * p + 1]
                            } else {
                                cp[5 * ((p + 1) % 4) + 2]
                            };
                            locals.expand(id, 1.0, &mut scratch);
                        }
                        PatchKind::Bilinear => {
                            let (c0, c3) = (ids[p], ids[(p + 1) % 4]);
                            let w = if k == 1 { 2.0 / 3.0 } else { 1.0 / 3.0 };
                            locals.expand(c0, w, &mut scratch);
                            locals.expand(c3, 1.0 - w, &mut scratch);
                        }
                    }
                    push_row(&mut table, &mut scratch);
                }
            }
            table
        })
        .collect();
    for c in &chunks {
        locals.append(c);
    }
    for (ci, c) in curves.iter_mut().enumerate() {
        c[1] = first_curve_row + 2 * ci as u32;
        c[2] = c[1] + 1;
    }

    // Statistics.
    let mut level_stats: Vec<LevelStats> = Vec::with_capacity(iso + 1);
    let corners0 = levels[0].t().face_tables().1.len() as u64;
    for (l, lvl) in levels.iter().enumerate() {
        let uniform_faces = if l == 0 {
            levels[0].t().num_faces() as u64
        } else {
            corners0.saturating_mul(4u64.saturating_pow(l as u32 - 1))
        };
        level_stats.push(LevelStats {
            regular: 0,
            end_caps: 0,
            faces: lvl.t().num_faces() as u32,
            uniform_faces,
        });
    }
    for p in &patches {
        let s = &mut level_stats[p.level as usize];
        if p.kind == PatchKind::Regular {
            s.regular += 1;
        } else {
            s.end_caps += 1;
        }
    }

    let bases: Vec<u32> = levels.iter().map(|l| l.base).collect();
    let steps = levels
        .iter_mut()
        .skip(1)
        .zip(bases)
        .map(|(child, parent_base)| {
            let mut table = child.stencils.take().unwrap_or_default();
            for i in table.indices.iter_mut() {
                *i += parent_base;
            }
            table.num_sources = child.base as usize;
            StencilBlock {
                first_vertex: child.base,
                table,
            }
        })
        .collect();
    let num_vertices = first_local + locals.table.len() as u32;
    Ok(AdaptivePlan {
        num_base_vertices: levels[0].t().num_vertices() as u32,
        num_vertices,
        steps,
        local_points: StencilBlock {
            first_vertex: first_local,
            table: locals.table,
        },
        patches,
        curves,
        level_stats,
        isolation: opts.isolation,
    })
}

/// Gregory points of face `f` (global ids, patch corner order).
fn gregory_points(
    mesh: &ControlMesh,
    lvl: &Lvl,
    f: usize,
    shift: u8,
) -> Result<Vec<Vec<(u32, f64)>>, TopologyError> {
    let basis = crate::gregory::gregory_basis(lvl.topo.view(), f, &mesh.options)?;
    let s = shift as usize;
    Ok((0..20)
        .map(|k| {
            let (p, j) = (k / 5, k % 5);
            let st = &basis[5 * ((p + s) % 4) + j];
            st.indices
                .iter()
                .zip(&st.weights)
                .map(|(&i, &w)| (i + lvl.base, w))
                .collect()
        })
        .collect())
}

fn bezier(t: f64) -> ([f64; 4], [f64; 4]) {
    let s = 1.0 - t;
    (
        [s * s * s, 3.0 * s * s * t, 3.0 * s * t * t, t * t * t],
        [
            -3.0 * s * s,
            3.0 * s * s - 6.0 * s * t,
            6.0 * s * t - 3.0 * t * t,
            3.0 * t * t,
        ],
    )
}

fn axpy(out: &mut [f64; 3], w: f64, x: &[f64; 3]) {
    out[0] += w * x[0];
    out[1] += w * x[1];
    out[2] += w * x[2];
}

impl AdaptivePlan {
    /// The whole global vertex buffer from the base positions (`num_base_vertices` of them).
    pub fn apply(&self, base: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let mut verts = Vec::with_capacity(self.num_vertices as usize);
        verts.extend_from_slice(&base[..(self.num_base_vertices as usize).min(base.len())]);
        verts.resize(self.num_base_vertices as usize, [0.0; 3]);
        for block in self.steps.iter().chain(std::iter::once(&self.local_points)) {
            verts.resize(block.first_vertex as usize, [0.0; 3]);
            let rows = block.table.apply(&verts);
            verts.extend_from_slice(&rows);
        }
        verts
    }

    /// Point and derivative of curve `curve` at `t ∈ [0, 1]` (point 0 at `t = 0`).
    pub fn curve_sample(&self, verts: &[[f64; 3]], curve: usize, t: f64) -> ([f64; 3], [f64; 3]) {
        let (w, d) = bezier(t);
        let mut p = [0.0; 3];
        let mut dp = [0.0; 3];
        for (k, &id) in self.curves[curve].iter().enumerate() {
            axpy(&mut p, w[k], &verts[id as usize]);
            axpy(&mut dp, d[k], &verts[id as usize]);
        }
        (p, dp)
    }

    /// Point of curve `curve` at `t ∈ [0, 1]` (point 0 at `t = 0`).
    pub fn curve_point(&self, verts: &[[f64; 3]], curve: usize, t: f64) -> [f64; 3] {
        self.curve_sample(verts, curve, t).0
    }

    /// Point and derivative (with respect to `t`) of edge `edge` of patch `patch` at `t`
    /// along the patch's edge direction, from its curves.
    pub fn edge_sample(
        &self,
        verts: &[[f64; 3]],
        patch: usize,
        edge: usize,
        t: f64,
    ) -> ([f64; 3], [f64; 3]) {
        let e = &self.patches[patch].edges[edge];
        let (k, local, scale) = match e.kind {
            EdgeKind::Coarse if t > 0.5 => (1, 2.0 * t - 1.0, 2.0),
            EdgeKind::Coarse => (0, 2.0 * t, 2.0),
            _ => (0, t, 1.0),
        };
        let (s, sign) = if e.reversed[k] {
            (1.0 - local, -1.0)
        } else {
            (local, 1.0)
        };
        let (p, d) = self.curve_sample(verts, e.curves[k] as usize, s);
        (p, d.map(|x| x * sign * scale))
    }

    /// CPU evaluation of patch `patch` at `(u, v) ∈ [0,1]²` on the global vertex buffer
    /// `verts` (from [`Self::apply`]): bicubic B-spline, Gregory, or the Coons patch of the
    /// four curves of a bilinear end cap.
    pub fn evaluate(&self, verts: &[[f64; 3]], patch: usize, u: f64, v: f64) -> PatchSample {
        let pa = &self.patches[patch];
        let cp = |k: usize| &verts[pa.control_points[k] as usize];
        let mut s = PatchSample {
            position: [0.0; 3],
            du: [0.0; 3],
            dv: [0.0; 3],
        };
        match pa.kind {
            PatchKind::Regular => {
                let w = catmark_regular_weights(u, v);
                for k in 0..16 {
                    axpy(&mut s.position, w.point[k], cp(k));
                    axpy(&mut s.du, w.du[k], cp(k));
                    axpy(&mut s.dv, w.dv[k], cp(k));
                }
            }
            PatchKind::Gregory => {
                let w = crate::gregory::gregory_weights(u, v);
                for k in 0..20 {
                    axpy(&mut s.position, w.point[k], cp(k));
                    axpy(&mut s.du, w.du[k], cp(k));
                    axpy(&mut s.dv, w.dv[k], cp(k));
                }
            }
            PatchKind::Bilinear => {
                let (b, db) = self.edge_sample(verts, patch, 0, u);
                let (r, dr) = self.edge_sample(verts, patch, 1, v);
                let (tp, dtp) = self.edge_sample(verts, patch, 2, 1.0 - u);
                let (lf, dlf) = self.edge_sample(verts, patch, 3, 1.0 - v);
                let (c00, c10, c11, c01) = (cp(0), cp(1), cp(2), cp(3));
                let terms_p: [(f64, &[f64; 3]); 8] = [
                    (1.0 - v, &b),
                    (v, &tp),
                    (1.0 - u, &lf),
                    (u, &r),
                    (-(1.0 - u) * (1.0 - v), c00),
                    (-u * (1.0 - v), c10),
                    (-u * v, c11),
                    (-(1.0 - u) * v, c01),
                ];
                for (w, x) in terms_p {
                    axpy(&mut s.position, w, x);
                }
                let terms_u: [(f64, &[f64; 3]); 8] = [
                    (1.0 - v, &db),
                    (-v, &dtp),
                    (-1.0, &lf),
                    (1.0, &r),
                    (1.0 - v, c00),
                    (-(1.0 - v), c10),
                    (-v, c11),
                    (v, c01),
                ];
                for (w, x) in terms_u {
                    axpy(&mut s.du, w, x);
                }
                let terms_v: [(f64, &[f64; 3]); 8] = [
                    (-1.0, &b),
                    (1.0, &tp),
                    (-(1.0 - u), &dlf),
                    (u, &dr),
                    (1.0 - u, c00),
                    (u, c10),
                    (-u, c11),
                    (-(1.0 - u), c01),
                ];
                for (w, x) in terms_v {
                    axpy(&mut s.dv, w, x);
                }
            }
        }
        s
    }
}
