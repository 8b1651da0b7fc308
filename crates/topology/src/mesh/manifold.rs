//! Non-manifold control meshes, refined as OpenSubdiv refines them, through a manifold mesh
//! that every refiner, evaluator and patch builder of this crate takes unchanged.
//!
//! # What is non-manifold (OpenSubdiv's `Vtr::Level::completeTopologyFromFaceVertices`)
//! An edge (a pair of vertices) is *manifold* when exactly two faces use it and they traverse it
//! in opposite directions, a *boundary* when one face uses it, and *non-manifold* otherwise:
//! three or more faces on it ([`EdgeUse::Shared`]), or two faces traversing it the same way
//! ([`EdgeUse::OppositeWinding`]: the two faces wind oppositely). A vertex is non-manifold when
//! a non-manifold edge ends at it or when its faces form several *fans* (sets of faces around
//! the vertex joined across manifold edges: two cones touching at their tips, two triangles
//! touching at a corner, a sheet pinched to a point).
//!
//! # OpenSubdiv's rules (`Far::TopologyRefinerFactoryBase::prepareComponentTagsAndSharpness`)
//! - Every non-manifold edge is infinitely sharp.
//! - A non-manifold vertex is infinitely sharp (a corner: it stays put and is its own limit),
//!   except on a *non-manifold crease*: exactly two non-manifold edges, no boundary edge and
//!   more faces than edges (fins along a crease), where its tags decide as usual, so it
//!   follows the crease rule along its two non-manifold edges.
//! - Everything else (manifold edges and vertices, including those next to a non-manifold
//!   feature) keeps the scheme's smooth, crease and boundary rules.
//!
//! # The manifold split ([`ManifoldSplit::of`])
//! Each fan of a vertex becomes a vertex of its own: the first fan keeps the vertex's index and
//! every further fan gets a copy (same position) numbered after the input's vertices, so the
//! faces keep their order and corners and every input vertex keeps its index. Non-manifold
//! edges are cut by construction (their faces lie in different fans at both ends, or share a
//! copy at both ends only where two faces of one sheet meet there, which then is an ordinary
//! interior edge): every edge of the split mesh has one face, or two that traverse it
//! oppositely, and every vertex one fan. The rules carry over as tags of the split mesh:
//! - every piece of a non-manifold edge gets an infinitely sharp crease tag;
//! - every copy of a sharpened vertex gets an infinitely sharp corner tag;
//! - every input crease and corner tag applies to all pieces and copies of its edge or vertex.
//!
//! The split mesh then refines exactly as OpenSubdiv refines the input: sharp edges take the
//! midpoint rule on every sheet, a corner stays put in every copy, and a vertex of a
//! non-manifold crease whose every fan runs from one of its two non-manifold edges to the
//! other is, in every copy, a crease vertex (or boundary vertex) along pieces of the same two
//! edges, so each copy follows the same crease rule to the same point. Copies therefore keep
//! identical positions at every level and in the limit, and the sheets stay joined.
//!
//! One case falls outside what a manifold mesh can express: a non-manifold crease vertex with
//! a fan that does not run between the two non-manifold edges (a cone touching the crease at
//! that vertex, a sheet leaving and returning through the same edge), with another sharp edge
//! (whose tag only one fan would see), or, under "edges and corners" boundaries, with a fan of
//! a single face (the split would make it a boundary corner). Such a vertex is made infinitely
//! sharp in every copy instead of following the crease rule, and is listed in
//! [`NonManifoldReport::sharpened_beyond_rule`].
//!
//! A face that names a vertex twice in a row has a *degenerate* edge from the vertex to itself
//! ([`EdgeUse::Degenerate`], non-manifold like an edge a face uses twice): its two corners
//! there lie in different fans, so the split gives them different copies (at the same
//! position; OpenSubdiv's quad poles are such faces). A face whose two corners at one vertex
//! lie in one fan even so has no manifold form and is refused
//! ([`TopologyError::RepeatedVertex`]).

use super::{check_faces, corner_faces, sorted_half_edges, ControlMesh, EdgeCrease, VertexCorner};
use crate::error::TopologyError;
use crate::rules::options::BoundaryInterpolation;
use crate::rules::SHARPNESS_INFINITE;
use std::collections::HashMap;

/// How the faces of an input edge (a pair of vertices) use it.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum EdgeUse {
    /// One face.
    Boundary,
    /// Two faces traversing it in opposite directions.
    Manifold,
    /// Three or more faces.
    Shared,
    /// Two faces traversing it in the same direction (their windings are opposite).
    OppositeWinding,
    /// A vertex to itself (a face naming a vertex twice in a row), or an edge one face uses
    /// twice: each use is an edge of its own, as in OpenSubdiv.
    Degenerate,
}

impl EdgeUse {
    /// Non-manifold: [`EdgeUse::Shared`] or [`EdgeUse::OppositeWinding`].
    pub fn is_non_manifold(self) -> bool {
        !matches!(self, EdgeUse::Boundary | EdgeUse::Manifold)
    }
}

/// What [`ManifoldSplit::of`] found and did, for reports and notes.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct NonManifoldReport {
    /// Edges of three or more faces.
    pub shared_edges: usize,
    /// Edges of two faces that traverse them in the same direction.
    pub opposite_winding_edges: usize,
    /// Vertices at a non-manifold edge or with several fans.
    pub non_manifold_vertices: usize,
    /// Of those, vertices whose faces form several fans.
    pub vertices_with_fans: usize,
    /// Vertices added: one per fan beyond a vertex's first.
    pub copies: usize,
    /// Non-manifold vertices made infinitely sharp by OpenSubdiv's rule.
    pub sharpened: usize,
    /// Non-manifold crease vertices that keep the crease rule.
    pub creases: usize,
    /// Non-manifold crease vertices made infinitely sharp because the split cannot give each of
    /// their fans the crease rule (see the module documentation), input numbering.
    pub sharpened_beyond_rule: Vec<u32>,
}

impl NonManifoldReport {
    /// Whether the input had anything non-manifold.
    pub fn any(&self) -> bool {
        self.non_manifold_vertices > 0 || self.shared_edges > 0 || self.opposite_winding_edges > 0
    }

    /// One sentence for notes: what was found and how it is drawn.
    pub fn summary(&self) -> String {
        let mut s = format!(
            "non-manifold: {} edges of 3 or more faces, {} edges between faces of opposite \
             winding (both drawn as infinitely sharp creases), {} vertices ({} with several fans \
             of faces; {} sharpened to corners, {} kept on a non-manifold crease)",
            self.shared_edges,
            self.opposite_winding_edges,
            self.non_manifold_vertices,
            self.vertices_with_fans,
            self.sharpened,
            self.creases
        );
        if !self.sharpened_beyond_rule.is_empty() {
            s.push_str(&format!(
                "; {} crease vertices sharpened beyond OpenSubdiv's rule (first: vertex {})",
                self.sharpened_beyond_rule.len(),
                self.sharpened_beyond_rule[0] + 1
            ));
        }
        s
    }
}

/// A control mesh as a manifold mesh that refines as OpenSubdiv refines the input (module
/// documentation).
#[derive(Clone, Debug)]
pub struct ManifoldSplit {
    /// The manifold mesh: the input's faces, corners, attributes, holes and options, over the
    /// input's vertices followed by the copies, with the tags that carry the rules.
    pub mesh: ControlMesh,
    /// Per copy (vertex `input_vertices + i` of [`Self::mesh`]): the input vertex it copies.
    pub copies: Vec<u32>,
    /// Per input edge (as `[smaller, larger]` vertex pair): how its faces use it, for the
    /// non-manifold ones only.
    pub non_manifold_edges: Vec<([u32; 2], EdgeUse)>,
    pub report: NonManifoldReport,
    input_vertices: usize,
}

/// The input's edges: per corner the edge from it to the next corner, per edge its use.
struct Edges {
    corner_edge: Vec<u32>,
    /// Per edge, `(smaller << 32) | larger`, ascending.
    keys: Vec<u64>,
    uses: Vec<EdgeUse>,
    /// Per edge, how many edges OpenSubdiv makes of it (`Vtr` builds edges face by face: a
    /// vertex to itself is a new edge at each use, and so is a pair a face uses again when
    /// the pair's first edge was last used by that same face).
    instances: Vec<u32>,
    /// Per edge, its corners (`corners[offsets[e]..offsets[e + 1]]`).
    offsets: Vec<u32>,
    corners: Vec<u32>,
}

impl Edges {
    fn of(mesh: &ControlMesh, corner_face: &[u32]) -> Edges {
        let next = |c: usize| {
            let f = corner_face[c] as usize;
            if c + 1 == mesh.face_offsets[f + 1] as usize {
                mesh.face_offsets[f] as usize
            } else {
                c + 1
            }
        };
        let half = sorted_half_edges(
            mesh.positions.len(),
            &mesh.face_offsets,
            &mesh.face_vertices,
            corner_face,
        );
        let mut edges = Edges {
            corner_edge: vec![0; mesh.face_vertices.len()],
            keys: Vec::with_capacity(half.len() / 2 + 1),
            uses: Vec::with_capacity(half.len() / 2 + 1),
            instances: Vec::with_capacity(half.len() / 2 + 1),
            offsets: vec![0],
            corners: Vec::with_capacity(half.len()),
        };
        let forward =
            |c: u32| mesh.face_vertices[c as usize] < mesh.face_vertices[next(c as usize)];
        let face = |c: u32| corner_face[c as usize];
        for run in half.chunk_by(|a, b| a.0 == b.0) {
            let e = edges.keys.len() as u32;
            let key = run[0].0;
            edges.keys.push(key);
            edges.uses.push(match run {
                _ if key >> 32 == key & 0xffff_ffff => EdgeUse::Degenerate,
                [_] => EdgeUse::Boundary,
                [(_, a), (_, b)] if face(*a) == face(*b) => EdgeUse::Degenerate,
                [(_, a), (_, b)] if forward(*a) != forward(*b) => EdgeUse::Manifold,
                [_, _] => EdgeUse::OppositeWinding,
                _ => EdgeUse::Shared,
            });
            edges.instances.push(if key >> 32 == key & 0xffff_ffff {
                run.len() as u32
            } else {
                vtr_instances(run.iter().map(|&(_, c)| face(c)))
            });
            for &(_, c) in run {
                edges.corner_edge[c as usize] = e;
                edges.corners.push(c);
            }
            edges.offsets.push(edges.corners.len() as u32);
        }
        edges
    }

    fn corners_of(&self, e: usize) -> &[u32] {
        &self.corners[self.offsets[e] as usize..self.offsets[e + 1] as usize]
    }

    fn find(&self, a: u32, b: u32) -> Option<usize> {
        let key = ((a.min(b) as u64) << 32) | a.max(b) as u64;
        self.keys.binary_search(&key).ok()
    }

    fn ends(&self, e: usize) -> [u32; 2] {
        [(self.keys[e] >> 32) as u32, self.keys[e] as u32]
    }
}

/// How many edges `Vtr` makes of a pair of distinct vertices used by `faces` (in face
/// order): a use by the face that last used the first edge makes a new edge.
fn vtr_instances(mut faces: impl Iterator<Item = u32>) -> u32 {
    let Some(mut latest) = faces.next() else {
        return 0;
    };
    let mut instances = 1;
    for f in faces {
        if f == latest {
            instances += 1;
        } else {
            latest = f;
        }
    }
    instances
}

/// Union-find over face corners.
struct Corners {
    parent: Vec<u32>,
}

impl Corners {
    fn find(&mut self, mut c: u32) -> u32 {
        while self.parent[c as usize] != c {
            let up = self.parent[self.parent[c as usize] as usize];
            self.parent[c as usize] = up;
            c = up;
        }
        c
    }

    fn union(&mut self, a: u32, b: u32) {
        let (ra, rb) = (self.find(a), self.find(b));
        if ra != rb {
            self.parent[ra.max(rb) as usize] = ra.min(rb);
        }
    }
}

/// Per input vertex, what OpenSubdiv's tagging needs.
#[derive(Clone, Copy, Debug, Default)]
struct VertexCounts {
    faces: u32,
    edges: u32,
    boundary_edges: u32,
    non_manifold_edges: u32,
    degenerate_edges: u32,
    fans: u32,
    /// The first copy's index (copies of one vertex are consecutive).
    first_copy: u32,
}

/// How the split treats a vertex.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
enum VertexRule {
    Manifold,
    Sharpened,
    Crease,
    SharpenedBeyondRule,
}

/// The split under construction: corners grouped into fans, the copy each corner uses.
struct Split<'a> {
    mesh: &'a ControlMesh,
    corner_face: Vec<u32>,
    edges: Edges,
    counts: Vec<VertexCounts>,
    /// Per corner, its vertex in the split mesh.
    corner_vertex: Vec<u32>,
    /// Per input vertex, its corners (`vertex_corners[vertex_offsets[v]..]`).
    vertex_offsets: Vec<u32>,
    vertex_corners: Vec<u32>,
    copies: Vec<u32>,
}

impl Split<'_> {
    fn next(&self, c: usize) -> usize {
        let f = self.corner_face[c] as usize;
        if c + 1 == self.mesh.face_offsets[f + 1] as usize {
            self.mesh.face_offsets[f] as usize
        } else {
            c + 1
        }
    }

    fn prev(&self, c: usize) -> usize {
        let f = self.corner_face[c] as usize;
        if c == self.mesh.face_offsets[f] as usize {
            self.mesh.face_offsets[f + 1] as usize - 1
        } else {
            c - 1
        }
    }

    fn corners_at(&self, v: usize) -> &[u32] {
        &self.vertex_corners[self.vertex_offsets[v] as usize..self.vertex_offsets[v + 1] as usize]
    }

    /// Fans: corners joined across manifold edges. Each manifold edge joins, at each of its
    /// ends, the two faces' corners there.
    fn fans(&self) -> Corners {
        let mut uf = Corners {
            parent: (0..self.mesh.face_vertices.len() as u32).collect(),
        };
        for e in 0..self.edges.keys.len() {
            if self.edges.uses[e] == EdgeUse::Manifold {
                let &[c0, c1] = self.edges.corners_of(e) else {
                    continue;
                };
                uf.union(c0, self.next(c1 as usize) as u32);
                uf.union(self.next(c0 as usize) as u32, c1);
            }
        }
        uf
    }

    /// Counts per vertex, fans numbered and copies assigned (each corner's split vertex).
    fn assign(&mut self) {
        let nv = self.mesh.positions.len();
        for e in 0..self.edges.keys.len() {
            let use_ = self.edges.uses[e];
            let instances = self.edges.instances[e];
            for v in self.edges.ends(e) {
                let c = &mut self.counts[v as usize];
                c.edges += instances;
                c.boundary_edges += u32::from(use_ == EdgeUse::Boundary);
                c.non_manifold_edges += instances * u32::from(use_.is_non_manifold());
                c.degenerate_edges += instances * u32::from(use_ == EdgeUse::Degenerate);
            }
        }
        let mut fans = self.fans();
        let mut roots: Vec<u32> = Vec::new();
        for v in 0..nv {
            roots.clear();
            let start = nv as u32 + self.copies.len() as u32;
            for k in self.vertex_offsets[v] as usize..self.vertex_offsets[v + 1] as usize {
                let c = self.vertex_corners[k];
                let root = fans.find(c);
                let fan = match roots.iter().position(|&r| r == root) {
                    Some(i) => i,
                    None => {
                        roots.push(root);
                        roots.len() - 1
                    }
                };
                self.corner_vertex[c as usize] = if fan == 0 {
                    v as u32
                } else {
                    start + fan as u32 - 1
                };
            }
            let counts = &mut self.counts[v];
            counts.faces = self.vertex_offsets[v + 1] - self.vertex_offsets[v];
            counts.fans = roots.len() as u32;
            counts.first_copy = start;
            let extra = roots.len().saturating_sub(1);
            self.copies.extend(std::iter::repeat_n(v as u32, extra));
        }
    }

    /// A face that still visits one vertex twice after the split (its two corners there lie
    /// in one fan) has no manifold form: refused, in the input's numbering.
    fn check_distinct_corners(&self) -> Result<(), TopologyError> {
        for face in 0..self.mesh.num_faces() {
            let range =
                self.mesh.face_offsets[face] as usize..self.mesh.face_offsets[face + 1] as usize;
            let split = &self.corner_vertex[range.clone()];
            for i in 1..split.len() {
                if split[..i].contains(&split[i]) {
                    return Err(TopologyError::RepeatedVertex {
                        face,
                        vertex: self.mesh.face_vertices[range.start + i],
                    });
                }
            }
        }
        Ok(())
    }

    /// OpenSubdiv's decision for vertex `v`, then whether the split can keep a crease.
    fn rule(&self, v: usize, tags: &HashMap<u64, f32>) -> VertexRule {
        let c = self.counts[v];
        if c.non_manifold_edges == 0 && c.fans <= 1 {
            return VertexRule::Manifold;
        }
        let crease = c.non_manifold_edges == 2 && c.boundary_edges == 0 && c.faces > c.edges;
        // A crease along a degenerate edge runs from the vertex to itself: the crease rule
        // and its limit are the vertex itself, as for a corner.
        if !crease || c.degenerate_edges > 0 {
            return VertexRule::Sharpened;
        }
        if self.crease_in_every_fan(v, tags) {
            VertexRule::Crease
        } else {
            VertexRule::SharpenedBeyondRule
        }
    }

    /// Whether every fan of crease vertex `v` sees, as its only sharp edges, one piece of each
    /// of the two non-manifold edges (so each copy takes the same crease rule), and no fan is
    /// a single face under "edges and corners" boundaries.
    fn crease_in_every_fan(&self, v: usize, tags: &HashMap<u64, f32>) -> bool {
        let corners_rule = self.mesh.options.boundary == BoundaryInterpolation::EdgesAndCorners;
        let mut pieces: Vec<(u32, [u32; 2], u32)> = Vec::new(); // (fan vertex, piece, far end)
        let mut faces_per_fan: HashMap<u32, u32> = HashMap::new();
        for &c in self.corners_at(v) {
            let c = c as usize;
            let me = self.corner_vertex[c];
            *faces_per_fan.entry(me).or_default() += 1;
            for (a, b) in [(c, self.next(c)), (self.prev(c), c)] {
                let e = self.edges.corner_edge[a] as usize;
                let far = self.mesh.face_vertices[if a == c { b } else { a }];
                if !self.edges.uses[e].is_non_manifold() {
                    if tags.get(&self.edges.keys[e]).is_some_and(|&s| s > 0.0) {
                        return false;
                    }
                    continue;
                }
                let (x, y) = (self.corner_vertex[a], self.corner_vertex[b]);
                let piece = [x.min(y), x.max(y)];
                if !pieces.iter().any(|p| p.0 == me && p.1 == piece) {
                    pieces.push((me, piece, far));
                }
            }
        }
        faces_per_fan.iter().all(|(&fan, &faces)| {
            let mut far: Vec<u32> = pieces.iter().filter(|p| p.0 == fan).map(|p| p.2).collect();
            far.sort_unstable();
            far.len() == 2 && far[0] != far[1] && !(corners_rule && faces == 1)
        })
    }
}

/// The input's non-manifold edges (vertex pairs, smaller first, ascending) and how their
/// faces use them, without splitting: what a capture needs to tell an open edge along a
/// non-manifold edge from a crack. Refuses what [`ControlMesh::validate`] refuses.
pub fn non_manifold_edges(mesh: &ControlMesh) -> Result<Vec<([u32; 2], EdgeUse)>, TopologyError> {
    check_faces(mesh, false)?;
    let corner_face = corner_faces(&mesh.face_offsets, mesh.face_vertices.len());
    let edges = Edges::of(mesh, &corner_face);
    Ok((0..edges.keys.len())
        .filter(|&e| edges.uses[e].is_non_manifold())
        .map(|e| (edges.ends(e), edges.uses[e]))
        .collect())
}

impl ManifoldSplit {
    /// The manifold split of `mesh` (module documentation). A manifold mesh comes back as it
    /// is, with no copies. Refuses what [`ControlMesh::validate`] refuses, and a face that
    /// visits a vertex twice ([`TopologyError::RepeatedVertex`]).
    pub fn of(mesh: &ControlMesh) -> Result<ManifoldSplit, TopologyError> {
        check_faces(mesh, false)?;
        let nv = mesh.positions.len();
        let corner_face = corner_faces(&mesh.face_offsets, mesh.face_vertices.len());
        let edges = Edges::of(mesh, &corner_face);
        let (vertex_offsets, vertex_corners) = vertex_corners(nv, &mesh.face_vertices);
        let mut split = Split {
            mesh,
            corner_vertex: vec![0; mesh.face_vertices.len()],
            corner_face,
            edges,
            counts: vec![VertexCounts::default(); nv],
            vertex_offsets,
            vertex_corners,
            copies: Vec::new(),
        };
        split.assign();
        let tags: HashMap<u64, f32> = mesh
            .creases
            .iter()
            .map(|c| {
                let [a, b] = c.vertices;
                (((a.min(b) as u64) << 32) | a.max(b) as u64, c.sharpness)
            })
            .collect();
        split.check_distinct_corners()?;
        let rules: Vec<VertexRule> = (0..nv).map(|v| split.rule(v, &tags)).collect();
        Ok(split.finish(&rules))
    }

    /// Number of vertices of the input.
    pub fn input_vertices(&self) -> usize {
        self.input_vertices
    }

    /// Whether the input was manifold (the split mesh is the input).
    pub fn is_identity(&self) -> bool {
        !self.report.any()
    }

    /// The input vertex that vertex `v` of the split mesh is (itself, or the one it copies).
    pub fn source(&self, v: u32) -> u32 {
        match (v as usize).checked_sub(self.input_vertices) {
            Some(i) => self.copies[i],
            None => v,
        }
    }

    /// Per-vertex values of the input (positions, say) for the split mesh's vertices: each
    /// copy takes its source's. `values` has one entry per input vertex.
    pub fn expand<T: Copy>(&self, values: &[T]) -> Vec<T> {
        let mut out = Vec::with_capacity(values.len() + self.copies.len());
        out.extend_from_slice(values);
        out.extend(self.copies.iter().map(|&s| values[s as usize]));
        out
    }
}

impl Split<'_> {
    /// The split mesh with its tags, and the report.
    fn finish(self, rules: &[VertexRule]) -> ManifoldSplit {
        let mesh = self.mesh;
        let nv = mesh.positions.len();
        let mut report = NonManifoldReport {
            copies: self.copies.len(),
            ..Default::default()
        };
        for use_ in &self.edges.uses {
            match use_ {
                EdgeUse::Shared => report.shared_edges += 1,
                EdgeUse::OppositeWinding => report.opposite_winding_edges += 1,
                _ => {}
            }
        }
        for (v, rule) in rules.iter().enumerate() {
            let counted = *rule != VertexRule::Manifold;
            report.non_manifold_vertices += usize::from(counted);
            report.vertices_with_fans += usize::from(counted && self.counts[v].fans > 1);
            match rule {
                VertexRule::Sharpened => report.sharpened += 1,
                VertexRule::Crease => report.creases += 1,
                VertexRule::SharpenedBeyondRule => report.sharpened_beyond_rule.push(v as u32),
                VertexRule::Manifold => {}
            }
        }
        let non_manifold_edges: Vec<([u32; 2], EdgeUse)> = (0..self.edges.keys.len())
            .filter(|&e| self.edges.uses[e].is_non_manifold())
            .map(|e| (self.edges.ends(e), self.edges.uses[e]))
            .collect();
        if !report.any() {
            return ManifoldSplit {
                mesh: mesh.clone(),
                copies: Vec::new(),
                non_manifold_edges,
                report,
                input_vertices: nv,
            };
        }
        let out = ControlMesh {
            positions: {
                let mut p = mesh.positions.clone();
                p.extend(self.copies.iter().map(|&s| mesh.positions[s as usize]));
                p
            },
            face_offsets: mesh.face_offsets.clone(),
            face_vertices: self.corner_vertex.clone(),
            uvs: mesh.uvs.clone(),
            uv_indices: mesh.uv_indices.clone(),
            normals: mesh.normals.clone(),
            creases: self.creases(),
            corners: self.corners(rules),
            holes: mesh.holes.clone(),
            scalar_tags: mesh.scalar_tags.clone(),
            options: mesh.options,
            scheme: mesh.scheme,
        };
        ManifoldSplit {
            mesh: out,
            copies: self.copies,
            non_manifold_edges,
            report,
            input_vertices: nv,
        }
    }

    /// The split vertices of input vertex `v`: itself and its copies.
    fn vertices_of(&self, v: u32) -> impl Iterator<Item = u32> {
        let c = self.counts[v as usize];
        std::iter::once(v).chain(c.first_copy..c.first_copy + c.fans.saturating_sub(1))
    }

    /// The split pieces of input edge `e` (each once), from its faces' corners.
    fn pieces(&self, e: usize) -> Vec<[u32; 2]> {
        let mut out: Vec<[u32; 2]> = Vec::new();
        for &c in self.edges.corners_of(e) {
            let (a, b) = (
                self.corner_vertex[c as usize],
                self.corner_vertex[self.next(c as usize)],
            );
            let piece = [a.min(b), a.max(b)];
            if !out.contains(&piece) {
                out.push(piece);
            }
        }
        out
    }

    /// Input crease tags on every piece of their edge (in tag order, so a later tag still
    /// overrides), then every non-manifold edge's pieces infinitely sharp. A tag on no edge
    /// is kept as given (the refiner ignores it).
    fn creases(&self) -> Vec<EdgeCrease> {
        let mut out = Vec::with_capacity(self.mesh.creases.len());
        for c in &self.mesh.creases {
            let [a, b] = c.vertices;
            match self.edges.find(a, b) {
                Some(e) if !self.edges.uses[e].is_non_manifold() => {
                    out.extend(self.pieces(e).into_iter().map(|vertices| EdgeCrease {
                        vertices,
                        sharpness: c.sharpness,
                    }));
                }
                Some(_) => {}
                None => out.push(*c),
            }
        }
        for e in 0..self.edges.keys.len() {
            if self.edges.uses[e].is_non_manifold() {
                out.extend(self.pieces(e).into_iter().map(|vertices| EdgeCrease {
                    vertices,
                    sharpness: SHARPNESS_INFINITE,
                }));
            }
        }
        out
    }

    /// Input corner tags on every copy of their vertex, then sharpened vertices infinitely
    /// sharp in every copy. A tag on a vertex the mesh does not have is kept as given (the
    /// refiner names it).
    fn corners(&self, rules: &[VertexRule]) -> Vec<VertexCorner> {
        let nv = self.mesh.positions.len();
        let mut out = Vec::with_capacity(self.mesh.corners.len());
        for c in &self.mesh.corners {
            if (c.vertex as usize) < nv {
                out.extend(self.vertices_of(c.vertex).map(|vertex| VertexCorner {
                    vertex,
                    sharpness: c.sharpness,
                }));
            } else {
                out.push(*c);
            }
        }
        for (v, rule) in rules.iter().enumerate() {
            if matches!(
                rule,
                VertexRule::Sharpened | VertexRule::SharpenedBeyondRule
            ) {
                out.extend(self.vertices_of(v as u32).map(|vertex| VertexCorner {
                    vertex,
                    sharpness: SHARPNESS_INFINITE,
                }));
            }
        }
        out
    }
}

/// Per vertex, its corners (counting sort: offsets of `num_vertices + 1`).
fn vertex_corners(num_vertices: usize, face_vertices: &[u32]) -> (Vec<u32>, Vec<u32>) {
    let mut offsets = vec![0u32; num_vertices + 1];
    for &v in face_vertices {
        offsets[v as usize + 1] += 1;
    }
    super::prefix_sum(&mut offsets);
    let mut fill = offsets.clone();
    let mut corners = vec![0u32; face_vertices.len()];
    for (c, &v) in face_vertices.iter().enumerate() {
        corners[fill[v as usize] as usize] = c as u32;
        fill[v as usize] += 1;
    }
    (offsets, corners)
}
