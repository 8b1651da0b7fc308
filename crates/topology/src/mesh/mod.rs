//! Control meshes (plain data as loaded) and their validated edge/vertex adjacency ([`Topology`]).

use crate::error::TopologyError;
use crate::rules::options::SubdivOptions;
use rayon::prelude::*;

pub mod input;
pub mod manifold;
pub mod obj;
pub mod scalar_tags;
pub mod usd;
pub mod usda;
pub mod weld;

/// Sentinel for "no face" / "no edge" in adjacency tables.
pub const INVALID: u32 = u32::MAX;

/// The largest coordinate magnitude a control mesh may have: 10¹² (about 2^39.9).
/// [`ControlMesh::validate`] rejects positions beyond it ([`TopologyError::CoordinateOutOfRange`]),
/// so every intermediate of every technique stays finite in f32 on the GPU and in f64 on the CPU.
///
/// Why this bound, with R the largest |coordinate| and f32's largest value about 2^128:
/// - *Points* (subdivision, limit masks, BFT point weights, B-spline and Bézier patches, the
///   f32 upload): refinement and limit rules of Loop, Catmull-Clark, creases and smooth
///   triangles have non-negative weights, so refined and limit points stay in the control
///   hull (|x| ≤ R); Gregory end caps and Bézier conversions use signed weights whose absolute
///   sum is a small constant (< 2^5). Linear in R: finite while R < 2^123.
/// - *Tangents* (limit tangent masks, BFT tangent tables, patch derivatives): weights summing
///   to zero, with an absolute sum that grows with valence, times up to 2^8 (derivatives with
///   respect to a base face's domain at isolation level 8) times the mesh's diameter 2R. Bounding
///   that factor by 2^20 gives |tangent| ≤ 2^21·R.
/// - *Normals*: `du × dv` has components ≤ 2·|du|·|dv| ≤ 2^43·R², finite while R < 2^42.5
///   (about 6·10¹²). The length of that cross product would square it again (2^86·R⁴, which
///   overflows f32 already for R ≈ 2^10), so the shaders scale a normal by its largest
///   component before normalising (`glsl/common/normals.glsl`) and the CPU works in f64
///   (2^86·R⁴ ≈ 2^246 there, far below f64's 2^1024).
/// - *View transform*: the camera fits the bounding box, whose diagonal length squares
///   coordinates once (12·R² ≈ 2^83.6 for R = 10¹²); the projection and the clip coordinates
///   are linear in R.
///
/// 10¹² leaves a factor of about 2^5 below the tightest of these (the normals), and is far
/// beyond any model's units (10¹² mm is a million km). There is no lower bound: tiny or
/// coincident coordinates give zero-length tangents and normals, which every normalisation
/// (GPU and CPU) turns into a fixed fallback instead of NaN.
pub const MAX_COORDINATE: f64 = 1e12;

/// Checks that every position is finite and within ±[`MAX_COORDINATE`]; the error names the
/// first vertex (0-based) that is not. Part of [`ControlMesh::validate`]; callers that replace
/// positions of a validated mesh (animation, a C ABI's position update) check them with this.
pub fn check_positions(positions: &[[f64; 3]]) -> Result<(), TopologyError> {
    // `!(|c| <= MAX)` is also true for NaN.
    let bad = positions
        .par_iter()
        .enumerate()
        .with_min_len(4096)
        .find_first(|(_, p)| !p.iter().all(|c| c.abs() <= MAX_COORDINATE));
    match bad {
        None => Ok(()),
        Some((vertex, p)) if p.iter().all(|c| c.is_finite()) => {
            Err(TopologyError::CoordinateOutOfRange {
                vertex,
                position: *p,
                bound: MAX_COORDINATE,
            })
        }
        Some((vertex, p)) => Err(TopologyError::NonFinitePosition {
            vertex,
            position: *p,
        }),
    }
}

/// A semi-sharp or infinitely sharp (≥ 10) edge, named by its two vertices.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct EdgeCrease {
    pub vertices: [u32; 2],
    pub sharpness: f32,
}

/// A semi-sharp or infinitely sharp (≥ 10) vertex.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct VertexCorner {
    pub vertex: u32,
    pub sharpness: f32,
}

/// A polygonal control mesh as loaded: plain data, no adjacency.
///
/// Faces are stored flat: face `f` has corners `face_vertices[face_offsets[f]..face_offsets[f + 1]]`.
/// `uvs` and `normals`, when present, have one entry per face corner (aligned with `face_vertices`).
/// `uv_indices`, when present, gives each corner's texture coordinate its index in the file
/// (an OBJ `vt` number, a USD primvar index): it is the texture layout's topology, which
/// face-varying subdivision follows ([`crate::refine::fvar`]).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct ControlMesh {
    pub positions: Vec<[f64; 3]>,
    pub face_offsets: Vec<u32>,
    pub face_vertices: Vec<u32>,
    pub uvs: Option<Vec<[f64; 2]>>,
    /// Per face corner, the index of its texture coordinate as the file numbers them: two
    /// corners at one vertex share a face-varying value when their indices are equal. `None`:
    /// they share it when their `uvs` are bit-equal. Ignored without `uvs`.
    pub uv_indices: Option<Vec<u32>>,
    pub normals: Option<Vec<[f64; 3]>>,
    pub creases: Vec<EdgeCrease>,
    pub corners: Vec<VertexCorner>,
    /// Faces tagged as holes (`t hole`, USD's `holeIndices`). Refinement keeps them (they
    /// shape their neighbours); patch plans and draws leave them out.
    pub holes: Vec<u32>,
    /// Scalar tags of an ST-mesh (`t scalartag`): shape parameters of curved PN triangles
    /// ([`scalar_tags`]); the subdivision schemes ignore them.
    pub scalar_tags: Vec<scalar_tags::ScalarTag>,
    pub options: SubdivOptions,
    /// The subdivision scheme the file names (a USD mesh's `subdivisionScheme`), which
    /// drawing uses when none is asked for; `None` for OBJ, whose scheme is chosen from the
    /// faces (triangles: Loop, else Catmull-Clark).
    pub scheme: Option<crate::rules::Scheme>,
}

impl ControlMesh {
    /// Build a mesh from positions and a list of polygons (no tags, default options).
    pub fn from_polygons<F: AsRef<[u32]>>(positions: Vec<[f64; 3]>, faces: &[F]) -> ControlMesh {
        let mut face_offsets = Vec::with_capacity(faces.len() + 1);
        let mut face_vertices = Vec::new();
        face_offsets.push(0);
        for f in faces {
            face_vertices.extend_from_slice(f.as_ref());
            face_offsets.push(face_vertices.len() as u32);
        }
        ControlMesh {
            positions,
            face_offsets,
            face_vertices,
            ..ControlMesh::default()
        }
    }

    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face_offsets.len().saturating_sub(1)
    }

    /// Axis-aligned bounding box `(min, max)` of the positions; the origin for a mesh without
    /// vertices.
    pub fn bounding_box(&self) -> ([f64; 3], [f64; 3]) {
        if self.positions.is_empty() {
            return ([0.0; 3], [0.0; 3]);
        }
        let (mut lo, mut hi) = ([f64::INFINITY; 3], [f64::NEG_INFINITY; 3]);
        for p in &self.positions {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        (lo, hi)
    }

    /// Length of the bounding box's diagonal: the scale errors and offsets are measured in.
    pub fn bbox_diagonal(&self) -> f64 {
        let (lo, hi) = self.bounding_box();
        (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt()
    }

    /// The vertex indices of face `f`.
    pub fn face(&self, f: usize) -> &[u32] {
        &self.face_vertices[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }

    /// Iterate over the faces as vertex-index slices.
    pub fn faces(&self) -> impl Iterator<Item = &[u32]> + '_ {
        (0..self.num_faces()).map(move |f| self.face(f))
    }

    /// The mesh with every polygon of more than three sides fan-triangulated from its first
    /// corner (Loop needs triangles; the techniques draw triangles). Vertex indices, creases,
    /// corners and options are kept (fans only add diagonals, so crease tags keep naming the
    /// same edges); per-corner uvs, their indices and normals follow their corners (and are dropped if they do
    /// not have one value per corner); a hole tag becomes all triangles of the holed face;
    /// faces of fewer than three corners make no triangle. Also returns, per new face, the
    /// face it came from.
    pub fn triangulated(&self) -> (ControlMesh, Vec<u32>) {
        let mut out = ControlMesh {
            positions: self.positions.clone(),
            face_offsets: vec![0],
            creases: self.creases.clone(),
            corners: self.corners.clone(),
            options: self.options,
            scheme: self.scheme,
            ..ControlMesh::default()
        };
        let corners = self.face_vertices.len();
        let (src_uvs, src_normals) = (
            self.uvs.as_ref().filter(|a| a.len() == corners),
            self.normals.as_ref().filter(|a| a.len() == corners),
        );
        let src_uv_indices = self
            .uv_indices
            .as_ref()
            .filter(|a| a.len() == corners && src_uvs.is_some());
        let mut uvs = src_uvs.map(|_| Vec::new());
        let mut uv_indices = src_uv_indices.map(|_| Vec::new());
        let mut normals = src_normals.map(|_| Vec::new());
        let mut origin = Vec::new();
        let mut first_triangle = Vec::with_capacity(self.num_faces() + 1);
        for f in 0..self.num_faces() {
            let start = self.face_offsets[f] as usize;
            let n = self.face(f).len();
            first_triangle.push(origin.len() as u32);
            for k in 1..n.saturating_sub(1) {
                for c in [start, start + k, start + k + 1] {
                    out.face_vertices.push(self.face_vertices[c]);
                    if let (Some(o), Some(src)) = (uvs.as_mut(), src_uvs) {
                        o.push(src[c]);
                    }
                    if let (Some(o), Some(src)) = (uv_indices.as_mut(), src_uv_indices) {
                        o.push(src[c]);
                    }
                    if let (Some(o), Some(src)) = (normals.as_mut(), src_normals) {
                        o.push(src[c]);
                    }
                }
                out.face_offsets.push(out.face_vertices.len() as u32);
                origin.push(f as u32);
            }
        }
        first_triangle.push(origin.len() as u32);
        for &h in &self.holes {
            if let (Some(&a), Some(&b)) = (
                first_triangle.get(h as usize),
                first_triangle.get(h as usize + 1),
            ) {
                out.holes.extend(a..b);
            }
        }
        out.uvs = uvs;
        out.uv_indices = uv_indices;
        out.normals = normals;
        (out, origin)
    }

    /// Check what every technique relies on: a face table whose faces have three or more
    /// corners naming existing vertices, finite positions within [`MAX_COORDINATE`],
    /// per-corner attributes of the right length. Non-manifold edges and vertices and
    /// opposite windings are not errors: the subdivision techniques refine them as
    /// OpenSubdiv does ([`manifold::ManifoldSplit`]), the others draw the faces as given. A
    /// face visiting a vertex twice is not an error here either (flat shading draws it); the
    /// refiner refuses it. Scalar tags are checked ([`scalar_tags::check`]).
    pub fn validate(&self) -> Result<(), TopologyError> {
        check_faces(self, false)?;
        scalar_tags::check(self).map(|_| ())
    }

    /// The faces OpenSubdiv's boundary interpolation `none` leaves without a surface: every
    /// face around a vertex that ends a boundary edge (an edge of one face) not tagged
    /// infinitely sharp. The remaining faces keep their whole one-ring, so their limit does
    /// not depend on any boundary rule; an explicitly sharpened boundary keeps its faces. Sorted,
    /// whatever the option.
    pub fn boundary_none_faces(&self) -> Vec<u32> {
        let key = |a: u32, b: u32| if a < b { (a, b) } else { (b, a) };
        let mut edge_faces: std::collections::HashMap<(u32, u32), u32> = Default::default();
        for f in self.faces() {
            for (i, &a) in f.iter().enumerate() {
                *edge_faces.entry(key(a, f[(i + 1) % f.len()])).or_default() += 1;
            }
        }
        let sharp: std::collections::HashSet<(u32, u32)> = self
            .creases
            .iter()
            .filter(|c| crate::rules::is_infinite(c.sharpness))
            .map(|c| key(c.vertices[0], c.vertices[1]))
            .collect();
        let mut open = vec![false; self.positions.len()];
        for (&(a, b), &n) in &edge_faces {
            if n == 1 && !sharp.contains(&(a, b)) {
                open[a as usize] = true;
                open[b as usize] = true;
            }
        }
        (0..self.num_faces() as u32)
            .filter(|&f| self.face(f as usize).iter().any(|&v| open[v as usize]))
            .collect()
    }

    /// Applies boundary interpolation `none` as OpenSubdiv does: the faces of
    /// [`ControlMesh::boundary_none_faces`] become holes (appended to [`ControlMesh::holes`]
    /// after the tagged ones, which keep their order). Under the other boundary options, and
    /// for bilinear meshes (whose faces need no neighbourhood), nothing changes. The loaders
    /// (OBJ, USD, the C ABI) call it; a mesh built in code calls it after setting its options.
    /// Idempotent.
    pub fn apply_boundary_none(&mut self) {
        use crate::rules::options::BoundaryInterpolation;
        if self.options.boundary != BoundaryInterpolation::None
            || self.scheme == Some(crate::rules::Scheme::Bilinear)
        {
            return;
        }
        let tagged: std::collections::HashSet<u32> = self.holes.iter().copied().collect();
        let added: Vec<u32> = self
            .boundary_none_faces()
            .into_iter()
            .filter(|f| !tagged.contains(f))
            .collect();
        self.holes.extend(added);
    }
}

/// Validated adjacency of a manifold, consistently oriented polygon mesh.
///
/// Edges are numbered; `face_edges` is aligned with `face_vertices` (corner `i` of a face owns the
/// edge from corner `i` to corner `i + 1`). Vertex incidence lists are unordered.
#[derive(Clone, Debug, Default)]
pub struct Topology {
    pub(crate) num_vertices: usize,
    pub(crate) face_offsets: Vec<u32>,
    pub(crate) face_verts: Vec<u32>,
    pub(crate) face_edges: Vec<u32>,
    pub(crate) edge_verts: Vec<[u32; 2]>,
    pub(crate) edge_faces: Vec<[u32; 2]>,
    pub(crate) vert_edge_offsets: Vec<u32>,
    pub(crate) vert_edges: Vec<u32>,
    pub(crate) vert_face_offsets: Vec<u32>,
    pub(crate) vert_faces: Vec<u32>,
}

impl Topology {
    /// Validate `mesh` and build its adjacency: the mesh must be manifold (split a non-manifold
    /// one first, [`manifold::ManifoldSplit`]).
    pub fn from_mesh(mesh: &ControlMesh) -> Result<Topology, TopologyError> {
        check_faces(mesh, true)?;
        let nv = mesh.positions.len();
        let topo = Topology::build(nv, mesh.face_offsets.clone(), mesh.face_vertices.clone())?;
        topo.check_manifold_vertices()?;
        Ok(topo)
    }

    /// Build edges from faces by sorting half-edges; reports non-manifold edges and
    /// inconsistent orientation.
    fn build(
        num_vertices: usize,
        face_offsets: Vec<u32>,
        face_verts: Vec<u32>,
    ) -> Result<Topology, TopologyError> {
        let corner_face = corner_faces(&face_offsets, face_verts.len());
        let half = sorted_half_edges(num_vertices, &face_offsets, &face_verts, &corner_face);
        let (face_edges, edge_verts, edge_faces) = edges_of(&half, &face_verts, &corner_face)?;
        let mut topo = Topology {
            num_vertices,
            face_offsets,
            face_verts,
            face_edges,
            edge_verts,
            edge_faces,
            ..Topology::default()
        };
        topo.build_vertex_incidence();
        Ok(topo)
    }

    /// Assemble a topology whose faces, face-edges and edge-vertices are already known
    /// (used for refined levels, which are manifold by construction).
    pub(crate) fn from_parts(
        num_vertices: usize,
        face_offsets: Vec<u32>,
        face_verts: Vec<u32>,
        face_edges: Vec<u32>,
        edge_verts: Vec<[u32; 2]>,
    ) -> Topology {
        let mut edge_faces = vec![[INVALID, INVALID]; edge_verts.len()];
        for (f, ends) in face_offsets.windows(2).enumerate() {
            for &e in &face_edges[ends[0] as usize..ends[1] as usize] {
                let slot = &mut edge_faces[e as usize];
                if slot[0] == INVALID {
                    slot[0] = f as u32;
                } else {
                    slot[1] = f as u32;
                }
            }
        }
        let mut topo = Topology {
            num_vertices,
            face_offsets,
            face_verts,
            face_edges,
            edge_verts,
            edge_faces,
            ..Topology::default()
        };
        topo.build_vertex_incidence();
        topo
    }

    /// The sub-mesh made of `faces` (in that order): vertices and edges numbered by first
    /// occurrence, so the first face's corners come first. Vertices on the border of the
    /// selection may have several unconnected fans there; that is a property of the selection,
    /// not an error.
    pub fn sub_topology(&self, faces: &[u32]) -> SubTopology {
        let mut vertex_map: std::collections::HashMap<u32, u32> = Default::default();
        let mut edge_map: std::collections::HashMap<u32, u32> = Default::default();
        let mut vertices = Vec::new();
        let mut edges = Vec::new();
        let mut face_offsets = Vec::with_capacity(faces.len() + 1);
        let mut face_verts = Vec::new();
        let mut face_edges = Vec::new();
        face_offsets.push(0);
        for &f in faces {
            let f = f as usize;
            for (&v, &e) in self.face_vertices(f).iter().zip(self.face_edge_list(f)) {
                let lv = *vertex_map.entry(v).or_insert_with(|| {
                    vertices.push(v);
                    (vertices.len() - 1) as u32
                });
                let le = *edge_map.entry(e).or_insert_with(|| {
                    edges.push(e);
                    (edges.len() - 1) as u32
                });
                face_verts.push(lv);
                face_edges.push(le);
            }
            face_offsets.push(face_verts.len() as u32);
        }
        let edge_verts = edges
            .iter()
            .map(|&e| self.edge_verts[e as usize].map(|v| vertex_map[&v]))
            .collect();
        SubTopology {
            topology: Topology::from_parts(
                vertices.len(),
                face_offsets,
                face_verts,
                face_edges,
                edge_verts,
            ),
            vertices,
            edges,
        }
    }

    /// Counting-sort the vertex→edge and vertex→face incidence lists. The counts go to slot
    /// `v + 2`, so that after the prefix sum slot `v + 1` is vertex `v`'s fill cursor and ends
    /// as its end offset: the offsets come out without a second array.
    fn build_vertex_incidence(&mut self) {
        let nv = self.num_vertices;
        let mut offsets = vec![0u32; nv + 2];
        for ev in &self.edge_verts {
            offsets[ev[0] as usize + 2] += 1;
            offsets[ev[1] as usize + 2] += 1;
        }
        prefix_sum(&mut offsets);
        let mut vert_edges = vec![0u32; 2 * self.edge_verts.len()];
        for (e, ev) in self.edge_verts.iter().enumerate() {
            for &v in ev {
                let cursor = &mut offsets[v as usize + 1];
                vert_edges[*cursor as usize] = e as u32;
                *cursor += 1;
            }
        }
        offsets.pop();
        self.vert_edge_offsets = offsets;
        self.vert_edges = vert_edges;

        let mut offsets = vec![0u32; nv + 2];
        for &v in &self.face_verts {
            offsets[v as usize + 2] += 1;
        }
        prefix_sum(&mut offsets);
        let mut vert_faces = vec![0u32; self.face_verts.len()];
        for (f, ends) in self.face_offsets.windows(2).enumerate() {
            for &v in &self.face_verts[ends[0] as usize..ends[1] as usize] {
                let cursor = &mut offsets[v as usize + 1];
                vert_faces[*cursor as usize] = f as u32;
                *cursor += 1;
            }
        }
        offsets.pop();
        self.vert_face_offsets = offsets;
        self.vert_faces = vert_faces;
    }

    /// Each used vertex must have its faces in a single fan (walk across shared edges).
    fn check_manifold_vertices(&self) -> Result<(), TopologyError> {
        let bad = (0..self.num_vertices).into_par_iter().find_map_first(|v| {
            let faces = self.vertex_faces(v);
            if faces.is_empty() {
                return None; // isolated vertices are allowed and ignored
            }
            let reached = self.fan_size(v as u32, faces[0]);
            if reached == faces.len() {
                None
            } else {
                // Count fans by repeated walks (rare path, only for the error message).
                let mut seen: Vec<u32> = Vec::new();
                let mut fans = 0;
                for &f in faces {
                    if !seen.contains(&f) {
                        fans += 1;
                        seen.extend(self.fan_faces(v as u32, f));
                    }
                }
                Some(TopologyError::NonManifoldVertex {
                    vertex: v as u32,
                    fans,
                })
            }
        });
        match bad {
            Some(e) => Err(e),
            None => Ok(()),
        }
    }

    /// Number of faces in the fan of `v` containing `start` (as [`Self::fan_faces`], without
    /// allocating).
    fn fan_size(&self, v: u32, start: u32) -> usize {
        let limit = self.vertex_faces(v as usize).len();
        let mut count = 1;
        for outgoing in [true, false] {
            let mut f = start;
            while let Some(g) = self.face_across(v, f, outgoing) {
                if g == start || count > limit {
                    return count;
                }
                count += 1;
                f = g;
            }
        }
        count
    }

    /// Faces reachable from `start` by rotating around `v` across its incident edges.
    fn fan_faces(&self, v: u32, start: u32) -> Vec<u32> {
        let limit = self.vertex_faces(v as usize).len();
        let mut out = vec![start];
        for outgoing in [true, false] {
            let mut f = start;
            while let Some(g) = self.face_across(v, f, outgoing) {
                if g == start {
                    return out; // closed fan
                }
                if out.len() > limit {
                    return out;
                }
                out.push(g);
                f = g;
            }
        }
        out
    }

    /// The face across the edge of `f` leaving (`outgoing`) or entering vertex `v`.
    fn face_across(&self, v: u32, f: u32, outgoing: bool) -> Option<u32> {
        let fv = self.face_vertices(f as usize);
        let fe = self.face_edge_list(f as usize);
        let i = fv.iter().position(|&x| x == v)?;
        let e = if outgoing {
            fe[i]
        } else {
            fe[(i + fv.len() - 1) % fv.len()]
        };
        let [a, b] = self.edge_faces[e as usize];
        let g = if a == f { b } else { a };
        (g != INVALID).then_some(g)
    }

    /// Number of vertices (including isolated ones).
    pub fn num_vertices(&self) -> usize {
        self.num_vertices
    }
    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.face_offsets.len() - 1
    }
    /// Number of edges.
    pub fn num_edges(&self) -> usize {
        self.edge_verts.len()
    }
    /// Corners of face `f`.
    pub fn face_vertices(&self, f: usize) -> &[u32] {
        &self.face_verts[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }
    /// Edges of face `f`; entry `i` joins corner `i` and corner `i + 1`.
    pub fn face_edge_list(&self, f: usize) -> &[u32] {
        &self.face_edges[self.face_offsets[f] as usize..self.face_offsets[f + 1] as usize]
    }
    /// The two end vertices of edge `e` (on a validated base mesh, in the direction its first
    /// face traverses it; on refined levels, in no particular direction).
    pub fn edge_vertices(&self, e: usize) -> [u32; 2] {
        self.edge_verts[e]
    }
    /// The one or two faces of edge `e` (`INVALID` in the second slot on a boundary).
    pub fn edge_faces(&self, e: usize) -> [u32; 2] {
        self.edge_faces[e]
    }
    /// The faces of edge `e`: one on a boundary, else two.
    pub fn edge_face_list(&self, e: usize) -> &[u32] {
        let pair = &self.edge_faces[e];
        if pair[1] == INVALID {
            &pair[..1]
        } else {
            &pair[..]
        }
    }
    /// Whether edge `e` has a single face.
    pub fn is_boundary_edge(&self, e: usize) -> bool {
        self.edge_faces[e][1] == INVALID
    }
    /// Edges incident to vertex `v` (unordered); their count is the valence.
    pub fn vertex_edges(&self, v: usize) -> &[u32] {
        &self.vert_edges[self.vert_edge_offsets[v] as usize..self.vert_edge_offsets[v + 1] as usize]
    }
    /// Faces incident to vertex `v` (unordered).
    pub fn vertex_faces(&self, v: usize) -> &[u32] {
        &self.vert_faces[self.vert_face_offsets[v] as usize..self.vert_face_offsets[v + 1] as usize]
    }
    /// Flat face tables: offsets (len faces + 1) and corner vertices.
    pub fn face_tables(&self) -> (&[u32], &[u32]) {
        (&self.face_offsets, &self.face_verts)
    }
    /// Index of the edge joining `a` and `b`, if any.
    pub fn find_edge(&self, a: u32, b: u32) -> Option<u32> {
        if a as usize >= self.num_vertices {
            return None;
        }
        self.vertex_edges(a as usize).iter().copied().find(|&e| {
            let [x, y] = self.edge_verts[e as usize];
            (x == a && y == b) || (x == b && y == a)
        })
    }
}

/// What every technique relies on, manifold or not: vertices and faces, a consistent face table,
/// finite positions within range, per-corner attributes of the corners' length, faces of
/// three or more corners naming existing vertices, indices within 32 bits; and, when
/// `distinct_corners`, no face visiting a vertex twice (the refiner's requirement).
pub(crate) fn check_faces(mesh: &ControlMesh, distinct_corners: bool) -> Result<(), TopologyError> {
    if mesh.positions.is_empty() {
        return Err(TopologyError::EmptyMesh {
            what: "no vertices",
        });
    }
    if mesh.num_faces() == 0 {
        return Err(TopologyError::EmptyMesh { what: "no faces" });
    }
    if mesh.face_offsets.first() != Some(&0)
        || mesh.face_offsets.windows(2).any(|w| w[0] > w[1])
        || *mesh.face_offsets.last().unwrap_or(&0) as usize != mesh.face_vertices.len()
    {
        return Err(TopologyError::MalformedFaceTable {
            faces: mesh.num_faces(),
            corners: mesh.face_vertices.len(),
        });
    }
    check_positions(&mesh.positions)?;
    let corners = mesh.face_vertices.len();
    for (attribute, len) in [
        ("normals", mesh.normals.as_ref().map(Vec::len)),
        ("uvs", mesh.uvs.as_ref().map(Vec::len)),
    ] {
        if let Some(len) = len.filter(|&n| n != corners) {
            return Err(TopologyError::AttributeLength {
                attribute,
                len,
                expected: corners,
            });
        }
    }
    // Without uvs the indices number nothing and are ignored.
    if let (Some(ix), Some(_)) = (&mesh.uv_indices, &mesh.uvs) {
        if ix.len() != corners {
            return Err(TopologyError::AttributeLength {
                attribute: "uv_indices",
                len: ix.len(),
                expected: corners,
            });
        }
    }
    let nv = mesh.positions.len();
    let bad_face = (0..mesh.num_faces())
        .into_par_iter()
        .with_min_len(4096)
        .find_map_first(|face| {
            let fv = mesh.face(face);
            if fv.len() < 3 {
                return Some(TopologyError::DegenerateFace {
                    face,
                    size: fv.len(),
                });
            }
            for (i, &v) in fv.iter().enumerate() {
                if v as usize >= nv {
                    return Some(TopologyError::IndexOutOfRange {
                        face,
                        index: v as i64,
                        count: nv,
                    });
                }
                if distinct_corners && fv[..i].contains(&v) {
                    return Some(TopologyError::RepeatedVertex { face, vertex: v });
                }
            }
            None
        });
    if let Some(e) = bad_face {
        return Err(e);
    }
    if corners >= INVALID as usize / 4 {
        return Err(TopologyError::TooManyCorners { corners });
    }
    Ok(())
}

/// The half-edges of the faces as (min, max, corner) keys, `(min << 32 | max, corner)`,
/// ordered by a counting sort on `min` and a short sort of each bucket (a vertex's valence):
/// the same order as sorting the keys, in linear time. The corner index identifies face +
/// direction.
fn sorted_half_edges(
    num_vertices: usize,
    face_offsets: &[u32],
    face_verts: &[u32],
    corner_face: &[u32],
) -> Vec<(u64, u32)> {
    let corners = face_verts.len();
    let next = |c: usize| {
        let f = corner_face[c] as usize;
        if c + 1 == face_offsets[f + 1] as usize {
            face_offsets[f] as usize
        } else {
            c + 1
        }
    };
    let mut bucket_offsets = vec![0u32; num_vertices + 1];
    for c in 0..corners {
        let (a, b) = (face_verts[c], face_verts[next(c)]);
        bucket_offsets[a.min(b) as usize + 1] += 1;
    }
    prefix_sum(&mut bucket_offsets);
    let mut fill = bucket_offsets.clone();
    // (max, corner), packed so a plain integer sort orders by max then corner.
    let mut buckets = vec![0u64; corners];
    for c in 0..corners {
        let (a, b) = (face_verts[c], face_verts[next(c)]);
        let slot = &mut fill[a.min(b) as usize];
        buckets[*slot as usize] = ((a.max(b) as u64) << 32) | c as u64;
        *slot += 1;
    }
    drop(fill);
    par_fill_ragged(&bucket_offsets, &mut buckets, |_, row| row.sort_unstable());
    (0..num_vertices)
        .flat_map(|v| {
            let r = bucket_offsets[v] as usize..bucket_offsets[v + 1] as usize;
            buckets[r]
                .iter()
                .map(move |&k| (((v as u64) << 32) | (k >> 32), k as u32))
        })
        .collect()
}

/// Per face corner its edge; per edge its vertices and its faces.
type EdgeTables = (Vec<u32>, Vec<[u32; 2]>, Vec<[u32; 2]>);

/// The edges of sorted half-edges `half` (runs of one key): each face corner's edge, each
/// edge's vertices (oriented as its first face traverses it) and faces. An edge of more than
/// two faces, or of two faces that traverse it the same way, is an error.
fn edges_of(
    half: &[(u64, u32)],
    face_verts: &[u32],
    corner_face: &[u32],
) -> Result<EdgeTables, TopologyError> {
    let mut face_edges = vec![INVALID; face_verts.len()];
    let mut edge_verts = Vec::with_capacity(half.len() / 2 + 1);
    let mut edge_faces = Vec::with_capacity(half.len() / 2 + 1);
    let mut i = 0;
    while i < half.len() {
        let key = half[i].0;
        let mut j = i + 1;
        while j < half.len() && half[j].0 == key {
            j += 1;
        }
        let v0 = (key >> 32) as u32;
        let v1 = key as u32;
        if j - i > 2 {
            return Err(TopologyError::NonManifoldEdge {
                v0,
                v1,
                faces: j - i,
            });
        }
        let e = edge_verts.len() as u32;
        let c0 = half[i].1 as usize;
        let f0 = corner_face[c0];
        // Orient the edge as the first face traverses it.
        let a0 = face_verts[c0];
        edge_verts.push(if a0 == v0 { [v0, v1] } else { [v1, v0] });
        face_edges[c0] = e;
        let mut faces = [f0, INVALID];
        if j - i == 2 {
            let c1 = half[i + 1].1 as usize;
            let f1 = corner_face[c1];
            if face_verts[c1] == a0 {
                let (b0, b1) = if a0 == v0 { (v0, v1) } else { (v1, v0) };
                return Err(TopologyError::InconsistentOrientation {
                    face0: f0.min(f1) as usize,
                    face1: f0.max(f1) as usize,
                    v0: b0,
                    v1: b1,
                });
            }
            face_edges[c1] = e;
            faces[1] = f1;
        }
        edge_faces.push(faces);
        i = j;
    }
    Ok((face_edges, edge_verts, edge_faces))
}

/// A sub-mesh cut out of a [`Topology`] ([`Topology::sub_topology`]) and where its parts come
/// from.
#[derive(Clone, Debug)]
pub struct SubTopology {
    pub topology: Topology,
    /// Per sub-mesh vertex: its vertex in the source.
    pub vertices: Vec<u32>,
    /// Per sub-mesh edge: its edge in the source.
    pub edges: Vec<u32>,
}

pub(crate) fn prefix_sum(v: &mut [u32]) {
    for i in 1..v.len() {
        v[i] += v[i - 1];
    }
}

/// Face of every corner, filled in parallel chunks (each chunk finds its first face by binary
/// search, then walks).
pub(crate) fn corner_faces(face_offsets: &[u32], corners: usize) -> Vec<u32> {
    const CHUNK: usize = 1 << 14;
    let mut out = vec![0u32; corners];
    out.par_chunks_mut(CHUNK)
        .enumerate()
        .for_each(|(k, chunk)| {
            let c0 = k * CHUNK;
            // Last face whose offset is <= c0 (skipping empty faces).
            let mut f = face_offsets.partition_point(|&o| o as usize <= c0) - 1;
            for (j, slot) in chunk.iter_mut().enumerate() {
                while face_offsets[f + 1] as usize <= c0 + j {
                    f += 1;
                }
                *slot = f as u32;
            }
        });
    out
}

/// Fill ragged rows in parallel: row `i` is `data[offsets[i]..offsets[i + 1]]`, written by
/// `f(i, row)`. Rows are handed out in contiguous blocks of about `BLOCK` entries.
pub(crate) fn par_fill_ragged<T, F>(offsets: &[u32], data: &mut [T], f: F)
where
    T: Send,
    F: Fn(usize, &mut [T]) + Sync,
{
    const BLOCK: usize = 1 << 15;
    let rows = offsets.len().saturating_sub(1);
    let mut jobs = Vec::new();
    let mut rest = data;
    let mut row = 0;
    while row < rows {
        let start = offsets[row] as usize;
        let end_row =
            (offsets.partition_point(|&o| (o as usize) < start + BLOCK) - 1).clamp(row + 1, rows);
        let len = offsets[end_row] as usize - start;
        let (chunk, tail) = std::mem::take(&mut rest).split_at_mut(len);
        jobs.push((row, end_row, chunk));
        rest = tail;
        row = end_row;
    }
    jobs.into_par_iter().for_each(|(r0, r1, chunk)| {
        let base = offsets[r0] as usize;
        for i in r0..r1 {
            let (s, e) = (offsets[i] as usize - base, offsets[i + 1] as usize - base);
            f(i, &mut chunk[s..e]);
        }
    });
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bounding_box_and_diagonal() {
        let m = ControlMesh::from_polygons(
            vec![[1.0, -2.0, 0.0], [4.0, 2.0, 0.0], [1.0, 2.0, 12.0]],
            &[[0u32, 1, 2]],
        );
        assert_eq!(m.bounding_box(), ([1.0, -2.0, 0.0], [4.0, 2.0, 12.0]));
        assert_eq!(m.bbox_diagonal(), 13.0);
        assert_eq!(ControlMesh::default().bbox_diagonal(), 0.0);
    }
}
