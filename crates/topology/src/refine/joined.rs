//! The levels of a manifold split's refinement joined back into the levels of the input's
//! (the non-manifold mesh OpenSubdiv refines): every copy of a vertex, and what refinement
//! makes of the copies, is one vertex again, numbered as OpenSubdiv's `Vtr` would count it.
//!
//! In a uniform step a vertex-vertex keeps its parent's index, edge `e` makes vertex `nv + e`
//! and face `f` vertex `nv + ne + f`; edge `e` has the halves `2e` (at its first end) and
//! `2e + 1` (at its second), then come the faces' interior edges (module [`crate::refine`]).
//! So identity follows parentage: a vertex-vertex is its parent's joined vertex, an
//! edge-vertex its parent edge's joined edge, a face-vertex its own (faces are never split);
//! a half of an edge is the half of its parent's joined edge at its end's joined vertex, an
//! interior edge is its own.
//!
//! The base level's edges are joined as `Vtr::Level::completeTopologyFromFaceVertices` makes
//! them from the input's faces, in face order: a pair of vertices is one edge, except that a
//! vertex to itself is a new edge at each use, and so is a pair a face uses again when that
//! edge's latest face is the face itself. Where the split has one edge for two of these
//! (two faces' uses of a vertex to itself that lie between the same two fans), the joined
//! levels have one edge, and the points below it, where OpenSubdiv has two coincident ones.
use super::UniformRefinement;
use crate::error::TopologyError;
use crate::mesh::manifold::ManifoldSplit;
use crate::rules::Scheme;
use std::collections::HashMap;

/// Per vertex of level `level` of `r` (a refinement of `split.mesh`), the vertex of the input's
/// refinement it is (numbered as a uniform step numbers them: the parent's vertices, then one
/// per joined parent edge, then one per face); and that level's vertex count. Doo-Sabin's levels are numbered otherwise and are refused.
pub fn joined_vertices(
    r: &UniformRefinement,
    split: &ManifoldSplit,
    level: usize,
) -> Result<(Vec<u32>, usize), TopologyError> {
    if r.scheme() == Scheme::DooSabin {
        return Err(TopologyError::UnsupportedScheme {
            scheme: r.scheme().name(),
            operation: "joining the levels of a manifold split",
        });
    }
    let base = &r.level(0).topology;
    let mut vertices: Vec<u32> = (0..base.num_vertices() as u32)
        .map(|v| split.source(v))
        .collect();
    let mut count = split.input_vertices();
    let (mut edges, mut num_edges) = base_edges(r, split);
    for k in 1..=level.min(r.max_level()) {
        let parent = &r.level(k - 1).topology;
        let child = &r.level(k).topology;
        let (nv, ne) = (parent.num_vertices(), parent.num_edges());
        let mut next = Vec::with_capacity(child.num_vertices());
        next.extend_from_slice(&vertices[..nv]);
        next.extend(edges.iter().map(|&e| (count + e as usize) as u32));
        let faces = child.num_vertices() - nv - ne;
        let first_face = (count + num_edges) as u32;
        next.extend(first_face..first_face + faces as u32);
        let (child_edges, child_count) = child_edges(parent, child, &vertices, &edges);
        count += num_edges + faces;
        vertices = next;
        edges = child_edges;
        num_edges = child_count;
    }
    Ok((vertices, count))
}

/// Per edge of the base level, its edge of the input as `Vtr` builds them (module
/// documentation), and how many the input has.
fn base_edges(r: &UniformRefinement, split: &ManifoldSplit) -> (Vec<u32>, usize) {
    let base = &r.level(0).topology;
    let mut edges = vec![u32::MAX; base.num_edges()];
    // Per vertex pair of the input, its first edge and that edge's latest face.
    let mut first: HashMap<[u32; 2], (u32, usize)> = HashMap::new();
    let mut count = 0u32;
    for f in 0..base.num_faces() {
        let fv = base.face_vertices(f);
        for (i, &e) in base.face_edge_list(f).iter().enumerate() {
            let (a, b) = (split.source(fv[i]), split.source(fv[(i + 1) % fv.len()]));
            let key = [a.min(b), a.max(b)];
            let id = match first.get_mut(&key) {
                Some((id, latest)) if a != b && *latest != f => {
                    *latest = f;
                    *id
                }
                Some(_) => {
                    count += 1;
                    count - 1
                }
                None if a == b => {
                    count += 1;
                    count - 1
                }
                None => {
                    first.insert(key, (count, f));
                    count += 1;
                    count - 1
                }
            };
            // A split edge that two faces use is one input edge (the first use names it).
            if edges[e as usize] == u32::MAX {
                edges[e as usize] = id;
            }
        }
    }
    compact(edges)
}

/// Renumbers `ids` densely in order of first appearance; returns them and their count. Where
/// the split joins two of `Vtr`'s edges into one (two faces' uses of a vertex to itself
/// between the same two fans), the second one's number is dropped: its points coincide
/// with the first's, and the joined level has one vertex fewer there than OpenSubdiv's.
fn compact(mut ids: Vec<u32>) -> (Vec<u32>, usize) {
    let mut renumber: HashMap<u32, u32> = HashMap::new();
    for id in ids.iter_mut() {
        let n = renumber.len() as u32;
        *id = *renumber.entry(*id).or_insert(n);
    }
    let count = renumber.len();
    (ids, count)
}

/// Per edge of `child` (one uniform step below `parent`), its joined edge, and their count:
/// halves of one joined parent edge at one joined end are one; interior edges are their own.
fn child_edges(
    parent: &crate::mesh::Topology,
    child: &crate::mesh::Topology,
    vertices: &[u32],
    edges: &[u32],
) -> (Vec<u32>, usize) {
    let mut halves: HashMap<(u32, u64), u32> = HashMap::new();
    let mut out = Vec::with_capacity(child.num_edges());
    let mut count = 0u32;
    for e in 0..child.num_edges() {
        let id = if e < 2 * parent.num_edges() {
            let p = e / 2;
            let [a, b] = parent.edge_vertices(p).map(|v| vertices[v as usize]);
            let end = if e % 2 == 0 { a } else { b };
            // A parent edge from a vertex to itself has two halves at one joined end.
            let marker = if a == b {
                (1 << 32) | (e % 2) as u64
            } else {
                end as u64
            };
            *halves.entry((edges[p], marker)).or_insert_with(|| {
                count += 1;
                count - 1
            })
        } else {
            count += 1;
            count - 1
        };
        out.push(id);
    }
    (out, count as usize)
}
