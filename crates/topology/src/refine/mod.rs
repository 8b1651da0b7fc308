//! The crate's one refiner: Catmull-Clark, Loop, bilinear and Doo-Sabin with OpenSubdiv's
//! semi-sharp crease, corner and boundary rules (all taken from [`crate::rules`]), in the spirit of
//! OpenSubdiv's `Vtr::Refinement` (sdc rules → one topology representation → stencil tables).
//!
//! # Levels and steps
//! A level is a [`Topology`] plus per-edge and per-vertex sharpness ([`LevelTopology`], borrowed
//! as [`LevelRef`]); [`Level`] adds 3D positions for the uniform API. A step reads a parent level
//! and produces the child topology, the child sharpness (uniform or Chaikin decay) and one
//! stencil per child vertex over the parent vertices; vertex data of any dimension is refined by
//! applying the stencils, and composing steps gives stencils over the base vertices. The masks
//! (`MaskContext`) are written once and serve both kinds of step.
//!
//! # Uniform and sparse steps
//! * [`refine_level`] / [`refine_uniform`] / [`uniform_stencils`] refine every face. Their child
//!   topology is written directly from the parent's adjacency, in parallel, for speed on large
//!   meshes.
//! * [`refine_sparse`] refines a selection of faces plus the one-ring of the selection (every
//!   face sharing a vertex with a selected face), as OpenSubdiv's `Vtr::SparseSelector` and
//!   `Far::TopologyRefiner::RefineAdaptive` do for feature-adaptive refinement. The one-ring is
//!   what the children need: the limit surface over a face depends on the faces around its
//!   corners, and the children of a face's one-ring contain the one-ring of each of its
//!   children. So if the parent holds the complete one-ring of each selected face, every child
//!   of a selected face has its complete one-ring in the child level, with exactly the uniform
//!   refiner's stencils, and the next step can select those children again (isolating a
//!   feature level by level, or following a point as [`crate::limit::eval`] does). Child vertices on
//!   the border of the refined region are still computed (from what the parent has), but their
//!   masks see only part of their neighbourhood and are not those of a uniform refinement.
//!   The step returns [`ChildMaps`]: parent → child (vertex-, edge-, face-vertex and first child
//!   face per parent component) and child → parent ([`ChildOrigin`] per child vertex, parent
//!   face per child face). Selecting every face of a mesh without isolated vertices reproduces
//!   [`refine_level`] exactly (same numbering, same stencils); isolated vertices belong to no
//!   face, so a sparse step does not carry them.
//!
//! # Numbering of a child level (all schemes but Doo-Sabin)
//! Vertices: first one vertex-vertex per refined parent vertex, then one edge-vertex per refined
//! parent edge, then (Catmull-Clark, bilinear) one face-vertex per refined parent face, each
//! group in ascending parent order. In a uniform step every component is refined, so a
//! vertex-vertex keeps its parent's index (base indices persist), edge `e` gives vertex
//! `nv + e` and face `f` vertex `nv + ne + f`.
//! Faces: the children of each refined parent face, consecutively, parent faces ascending. A
//! Catmull-Clark / bilinear face with `n` corners has `n` quad children, child `i` being
//! `[v_i', e_{i,i+1}, f, e_{i−1,i}]`; a Loop triangle has four, child `j < 3` being
//! `[v_j', e_{j,j+1}, e_{j−1,j}]` and child 3 `[e_01, e_12, e_20]`.
//! Edges: the two halves of each refined parent edge (`2k` at the parent edge's first end,
//! `2k + 1` at its second, `k` its rank among refined edges), then the interior edges of each
//! refined face (one per corner for quads, joining the corner's edge-vertex to the
//! face-vertex; three per triangle for Loop, inner edge `j` joining the edge-vertices at
//! corner `j`).
//!
//! Doo-Sabin makes one child vertex per parent face corner and is uniform only ([`doo_sabin`]:
//! its numbering, faces and boundary rule).

use crate::error::{TagKind, TopologyError};
use crate::mesh::{corner_faces, par_fill_ragged, prefix_sum, ControlMesh, Topology, INVALID};
use crate::refine::stencil::{
    build_rows, compose_rows, entry_key, insertion_sort, RowKind, RowOut, StencilTable,
};
use crate::rules::options::{BoundaryInterpolation, SubdivOptions, TriangleSubdivision};
use crate::rules::{
    boundary_edge_sharpness, boundary_vertex_sharpness, decrement_sharpness, fractional_weight,
    is_sharp, subdivide_edge_sharpness_at_vertex, vertex_rule, Rule, Scheme,
};
use rayon::prelude::*;

pub mod doo_sabin;
pub mod fvar;
pub mod joined;
pub mod stencil;

/// One level of a refinement: topology, positions and (propagated) sharpness.
#[derive(Clone, Debug)]
pub struct Level {
    pub topology: Topology,
    pub positions: Vec<[f64; 3]>,
    /// Per edge (numbered as in `topology`); boundary edges are infinitely sharp.
    pub edge_sharpness: Vec<f32>,
    /// Per vertex; with [`BoundaryInterpolation::EdgesAndCorners`] corners are infinitely sharp.
    pub vertex_sharpness: Vec<f32>,
}

impl Level {
    /// Face offsets (len faces + 1) of this level.
    pub fn face_offsets(&self) -> &[u32] {
        self.topology.face_tables().0
    }
    /// Face corner vertex indices of this level.
    pub fn face_vertices(&self) -> &[u32] {
        self.topology.face_tables().1
    }
    /// Number of faces.
    pub fn num_faces(&self) -> usize {
        self.topology.num_faces()
    }
    /// Number of vertices.
    pub fn num_vertices(&self) -> usize {
        self.topology.num_vertices()
    }

    /// Base level of `mesh`: validated topology plus sharpness from tags and boundary rules.
    pub fn from_mesh(mesh: &ControlMesh, scheme: Scheme) -> Result<Level, TopologyError> {
        let topology = base_topology(mesh, scheme)?;
        let (edge_sharpness, vertex_sharpness) = base_sharpness(mesh, &topology)?;
        Ok(Level {
            topology,
            positions: mesh.positions.clone(),
            edge_sharpness,
            vertex_sharpness,
        })
    }
}

/// Validated base topology; Loop needs triangles.
fn base_topology(mesh: &ControlMesh, scheme: Scheme) -> Result<Topology, TopologyError> {
    let topology = Topology::from_mesh(mesh)?;
    if scheme == Scheme::Loop {
        if let Some(f) = (0..topology.num_faces()).find(|&f| topology.face_vertices(f).len() != 3) {
            return Err(TopologyError::LoopRequiresTriangles {
                face: f,
                size: topology.face_vertices(f).len(),
            });
        }
    }
    Ok(topology)
}

/// Doo-Sabin's rules (the seed's, and the boundary as the polygon's quadratic B-spline) have
/// no sharp edges, sharp vertices or holes: a crease or corner tag with sharpness, or a hole,
/// of the mesh a user gives is refused by name rather than drawn smooth. The front doors
/// apply it to the input (the Doo-Sabin techniques, [`crate::limit::face_domain::LimitEvaluator`],
/// `tessera subdivide`), before a non-manifold mesh's split, whose sharpness tags carry
/// OpenSubdiv's non-manifold rules and which Doo-Sabin's refinement, having none, ignores.
pub fn check_doo_sabin_tags(mesh: &ControlMesh) -> Result<(), TopologyError> {
    if let Some(&face) = mesh.holes.first() {
        return Err(TopologyError::DooSabinHole { face });
    }
    if let Some(c) = mesh.creases.iter().find(|c| c.sharpness > 0.0) {
        let [v0, v1] = c.vertices;
        return Err(TopologyError::DooSabinCrease {
            v0,
            v1,
            sharpness: c.sharpness,
        });
    }
    match mesh.corners.iter().find(|c| c.sharpness > 0.0) {
        Some(c) => Err(TopologyError::DooSabinCorner {
            vertex: c.vertex,
            sharpness: c.sharpness,
        }),
        None => Ok(()),
    }
}

/// Edge and vertex sharpness of the base level from tags and boundary rules.
fn base_sharpness(
    mesh: &ControlMesh,
    topology: &Topology,
) -> Result<(Vec<f32>, Vec<f32>), TopologyError> {
    let nv = topology.num_vertices();
    let mut edge_sharpness = vec![0.0f32; topology.num_edges()];
    for c in &mesh.creases {
        let [a, b] = c.vertices;
        if a as usize >= nv || b as usize >= nv {
            return Err(TopologyError::TagOutOfRange {
                tag: TagKind::Crease,
                index: a.max(b),
                count: nv,
            });
        }
        match topology.find_edge(a, b) {
            Some(e) => edge_sharpness[e as usize] = c.sharpness.max(0.0),
            None => log::warn!("crease tag on {a}-{b}, which is not an edge: ignored"),
        }
    }
    let mut vertex_sharpness = vec![0.0f32; nv];
    for c in &mesh.corners {
        if c.vertex as usize >= nv {
            return Err(TopologyError::TagOutOfRange {
                tag: TagKind::Corner,
                index: c.vertex,
                count: nv,
            });
        }
        vertex_sharpness[c.vertex as usize] = c.sharpness.max(0.0);
    }
    apply_boundary_rules(
        topology,
        mesh.options.boundary,
        &mut edge_sharpness,
        &mut vertex_sharpness,
    );
    Ok((edge_sharpness, vertex_sharpness))
}

/// Boundary edges become infinitely sharp and, with "edges and corners", boundary corners too
/// (the rules are [`crate::rules::boundary_edge_sharpness`] and
/// [`crate::rules::boundary_vertex_sharpness`]). Applied to a base level only: refinement
/// propagates infinite sharpness unchanged.
pub(crate) fn apply_boundary_rules(
    topology: &Topology,
    boundary: BoundaryInterpolation,
    edge_sharpness: &mut [f32],
    vertex_sharpness: &mut [f32],
) {
    for (e, s) in edge_sharpness.iter_mut().enumerate() {
        if topology.is_boundary_edge(e) {
            *s = boundary_edge_sharpness();
        }
    }
    for (v, s) in vertex_sharpness.iter_mut().enumerate() {
        let (faces, edges) = (
            topology.vertex_faces(v).len(),
            topology.vertex_edges(v).len(),
        );
        if let Some(b) = boundary_vertex_sharpness(boundary, faces, edges) {
            *s = b;
        }
    }
}

/// Result of [`refine_uniform`]: every level from the base (index 0) to the requested one,
/// and the per-step stencils.
#[derive(Clone, Debug)]
pub struct UniformRefinement {
    scheme: Scheme,
    options: SubdivOptions,
    levels: Vec<Level>,
    steps: Vec<StencilTable>,
}

impl UniformRefinement {
    /// The scheme used.
    pub fn scheme(&self) -> Scheme {
        self.scheme
    }
    /// The options (boundary rule, crease method, triangle rule) used.
    pub fn options(&self) -> SubdivOptions {
        self.options
    }
    /// The deepest level refined.
    pub fn max_level(&self) -> usize {
        self.levels.len() - 1
    }
    /// Level `k` (0 is the base mesh).
    pub fn level(&self, k: usize) -> &Level {
        &self.levels[k]
    }
    /// All levels, base first.
    pub fn levels(&self) -> &[Level] {
        &self.levels
    }
    /// Stencils of level `k` (k ≥ 1) over the vertices of level `k - 1`.
    pub fn step_stencils(&self, k: usize) -> &StencilTable {
        &self.steps[k - 1]
    }
    /// Stencils of level `k` over the base (control) vertices; level 0 gives the identity.
    pub fn stencils(&self, k: usize) -> StencilTable {
        if k == 0 {
            return StencilTable::identity(self.levels[0].num_vertices());
        }
        let mut table = self.steps[0].clone();
        for step in &self.steps[1..k] {
            table = step.compose(&table);
        }
        table
    }
}

/// Refine `mesh` uniformly `level` times with `scheme`, honouring its creases, corners and
/// options.
pub fn refine_uniform(
    mesh: &ControlMesh,
    scheme: Scheme,
    level: usize,
) -> Result<UniformRefinement, TopologyError> {
    let base = Level::from_mesh(mesh, scheme)?;
    let mut levels = vec![base];
    let mut steps = Vec::with_capacity(level);
    for k in 0..level {
        let parent = levels.last().expect("base level present");
        let (child, step) = if scheme == Scheme::DooSabin {
            check_size(&parent.topology, scheme)?;
            doo_sabin::refine_doo_sabin(parent, k == 0)?
        } else {
            refine_level(parent, scheme, &mesh.options)?
        };
        levels.push(child);
        steps.push(step);
    }
    Ok(UniformRefinement {
        scheme,
        options: mesh.options,
        levels,
        steps,
    })
}

/// Stencils of the level-`level` vertices over the control vertices of `mesh`.
///
/// Only what the stencils need is built: no positions, no topology of the deepest level, no
/// per-step tables. Each level's rows are composed with the previous level's table on the fly.
pub fn uniform_stencils(
    mesh: &ControlMesh,
    scheme: Scheme,
    level: usize,
) -> Result<StencilTable, TopologyError> {
    if scheme == Scheme::DooSabin {
        return Ok(refine_uniform(mesh, scheme, level)?.stencils(level));
    }
    let mut topology = base_topology(mesh, scheme)?;
    let (mut edge_sharpness, mut vertex_sharpness) = base_sharpness(mesh, &topology)?;
    let num_sources = topology.num_vertices();
    let options = &mesh.options;
    let mut table: Option<StencilTable> = None;
    for k in 0..level {
        check_size(&topology, scheme)?;
        let (child_es, child_vs) = child_sharpness(
            &topology,
            &edge_sharpness,
            &vertex_sharpness,
            scheme,
            options,
        );
        let nv = topology.num_vertices();
        let ctx = MaskContext {
            p: &topology,
            es: &edge_sharpness,
            vs: &vertex_sharpness,
            scheme,
            options,
            child_edge_sharpness: &child_es,
            child_vertex_sharpness: &child_vs[..nv],
        };
        let next = compose_rows(
            child_vs.len(),
            table.as_ref(),
            RowKind::Raw,
            num_sources,
            |i, out| ctx.row_merged(i, out),
        );
        table = Some(next);
        if k + 1 < level {
            topology = split(&topology, scheme);
            edge_sharpness = child_es;
            vertex_sharpness = child_vs;
        }
    }
    Ok(table.unwrap_or_else(|| StencilTable::identity(num_sources)))
}

/// Refuse steps whose child indices would overflow 32 bits.
fn check_size(p: &Topology, scheme: Scheme) -> Result<(), TopologyError> {
    let corners = p.face_verts.len();
    let max_children = match scheme {
        Scheme::Loop => p.num_vertices() + p.num_edges() * 4,
        _ => p.num_vertices() + p.num_edges() * 3 + corners * 4,
    };
    if max_children >= (INVALID / 2) as usize {
        return Err(TopologyError::RefinementTooLarge {
            faces: p.num_faces(),
        });
    }
    Ok(())
}

/// Child topology of a Catmull-Clark / bilinear (quad split) or Loop (triangle split) step.
fn split(p: &Topology, scheme: Scheme) -> Topology {
    match scheme {
        Scheme::Loop => split_triangles(p),
        _ => split_quads(p),
    }
}

/// Child edge sharpness (see [`child_edge_sharpness`]) and child vertex sharpness (vertex
/// vertices decay, new vertices are smooth) of a Catmull-Clark, bilinear or Loop step.
fn child_sharpness(
    p: &Topology,
    edge_sharpness: &[f32],
    vertex_sharpness: &[f32],
    scheme: Scheme,
    options: &SubdivOptions,
) -> (Vec<f32>, Vec<f32>) {
    let (nv, ne, nf) = (p.num_vertices(), p.num_edges(), p.num_faces());
    let (extra, child_nv) = match scheme {
        Scheme::Loop => (3 * nf, nv + ne),
        _ => (p.face_verts.len(), nv + ne + nf),
    };
    let es = child_edge_sharpness(p, edge_sharpness, options, extra);
    let mut vs = vec![0.0f32; child_nv];
    for (c, &s) in vs.iter_mut().zip(vertex_sharpness) {
        *c = decrement_sharpness(s);
    }
    (es, vs)
}

/// One uniform refinement step: child level and its stencils over the parent vertices.
///
/// Doo-Sabin takes `parent` as a control mesh (the step that makes the boundary points,
/// [`doo_sabin`]); [`refine_uniform`] takes the later steps, from refined levels.
pub fn refine_level(
    parent: &Level,
    scheme: Scheme,
    options: &SubdivOptions,
) -> Result<(Level, StencilTable), TopologyError> {
    let p = &parent.topology;
    check_size(p, scheme)?;
    if scheme == Scheme::DooSabin {
        return doo_sabin::refine_doo_sabin(parent, true);
    }
    let (edge_sharpness, vertex_sharpness) = child_sharpness(
        p,
        &parent.edge_sharpness,
        &parent.vertex_sharpness,
        scheme,
        options,
    );
    let nv = p.num_vertices();
    let ctx = MaskContext {
        p,
        es: &parent.edge_sharpness,
        vs: &parent.vertex_sharpness,
        scheme,
        options,
        child_edge_sharpness: &edge_sharpness,
        child_vertex_sharpness: &vertex_sharpness[..nv],
    };
    let step = build_rows(vertex_sharpness.len(), nv, |i, out| ctx.row_merged(i, out));
    let topology = split(p, scheme);
    let positions = step.apply(&parent.positions);
    Ok((
        Level {
            topology,
            positions,
            edge_sharpness,
            vertex_sharpness,
        },
        step,
    ))
}

/// Borrowed view of one level: the topology and the sharpness the rules read. Vertex data
/// (positions, or any per-vertex values) stays with the caller and goes through the stencils.
#[derive(Clone, Copy, Debug)]
pub struct LevelRef<'a> {
    pub topology: &'a Topology,
    /// Per edge; boundary edges of a base level are infinitely sharp.
    pub edge_sharpness: &'a [f32],
    /// Per vertex.
    pub vertex_sharpness: &'a [f32],
}

/// Topology and sharpness of one level without vertex data: what [`refine_sparse`] consumes and
/// produces, and the level type of [`crate::limit::eval`] and [`crate::patches::bft`].
#[derive(Clone, Debug, Default)]
pub struct LevelTopology {
    pub topology: Topology,
    pub edge_sharpness: Vec<f32>,
    pub vertex_sharpness: Vec<f32>,
}

impl LevelTopology {
    /// Base level of `mesh`: validated topology plus sharpness from tags and boundary rules
    /// (Loop needs triangles).
    pub fn from_mesh(mesh: &ControlMesh, scheme: Scheme) -> Result<LevelTopology, TopologyError> {
        let topology = base_topology(mesh, scheme)?;
        let (edge_sharpness, vertex_sharpness) = base_sharpness(mesh, &topology)?;
        Ok(LevelTopology {
            topology,
            edge_sharpness,
            vertex_sharpness,
        })
    }

    /// A base level from a validated topology and tagged sharpness; the boundary rules are
    /// applied here (boundary edges infinitely sharp, "edges and corners" corners too).
    pub fn with_boundary_rules(
        topology: Topology,
        mut edge_sharpness: Vec<f32>,
        mut vertex_sharpness: Vec<f32>,
        boundary: BoundaryInterpolation,
    ) -> LevelTopology {
        edge_sharpness.resize(topology.num_edges(), 0.0);
        vertex_sharpness.resize(topology.num_vertices(), 0.0);
        apply_boundary_rules(
            &topology,
            boundary,
            &mut edge_sharpness,
            &mut vertex_sharpness,
        );
        LevelTopology {
            topology,
            edge_sharpness,
            vertex_sharpness,
        }
    }

    /// The borrowed view the refiner reads.
    pub fn view(&self) -> LevelRef<'_> {
        LevelRef {
            topology: &self.topology,
            edge_sharpness: &self.edge_sharpness,
            vertex_sharpness: &self.vertex_sharpness,
        }
    }
}

impl Level {
    /// The borrowed view the refiner reads (positions stay here).
    pub fn view(&self) -> LevelRef<'_> {
        LevelRef {
            topology: &self.topology,
            edge_sharpness: &self.edge_sharpness,
            vertex_sharpness: &self.vertex_sharpness,
        }
    }
}

/// The parent component a child vertex comes from (OpenSubdiv: vertex-vertex, edge-vertex,
/// face-vertex).
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum ChildOrigin {
    Vertex(u32),
    Edge(u32),
    Face(u32),
}

/// Parent → child and child → parent maps of one [`refine_sparse`] step (`INVALID` where a
/// parent component was not refined).
#[derive(Clone, Debug, Default)]
pub struct ChildMaps {
    /// The refined parent faces, ascending: the selection and its one-ring.
    pub refined_faces: Vec<u32>,
    /// Per parent vertex: its vertex-vertex.
    pub vertex_child_vertex: Vec<u32>,
    /// Per parent edge: its edge-vertex.
    pub edge_child_vertex: Vec<u32>,
    /// Per parent face: its face-vertex (quad-splitting schemes only).
    pub face_child_vertex: Vec<u32>,
    /// Per parent face: its first child face; its children are consecutive (see the module
    /// docs for their order; with [`SparseRegion::SelectedCorners`] a one-ring face has only
    /// the children at selected faces' corners, still in corner order).
    pub face_first_child: Vec<u32>,
    /// Per child vertex: the parent component it refines.
    pub child_vertex_origin: Vec<ChildOrigin>,
    /// Per child face: its parent face.
    pub child_face_parent: Vec<u32>,
    /// Per edge-vertex (child vertex `kv + r` has entry `r`, `kv` the vertex-vertices): the
    /// child edges halving its parent edge, at the parent edge's end 0 and end 1 (`INVALID`
    /// where [`SparseRegion::SelectedCorners`] made no child at that end). With
    /// [`SparseRegion::OneRingFaces`] they are always `2r`, `2r + 1`.
    pub edge_child_halves: Vec<[u32; 2]>,
}

impl ChildMaps {
    /// The child faces of parent face `f` (empty if `f` was not refined).
    pub fn child_faces(&self, f: usize) -> std::ops::Range<usize> {
        let first = self.face_first_child.get(f).copied().unwrap_or(INVALID);
        if first == INVALID {
            return 0..0;
        }
        let first = first as usize;
        let count = self.child_face_parent[first..]
            .iter()
            .take_while(|&&p| p as usize == f)
            .count();
        first..first + count
    }
}

/// One [`refine_sparse`] step: the child level, its stencils over the parent vertices (one row
/// per child vertex, in child order) and the maps between the two levels.
#[derive(Clone, Debug)]
pub struct SparseRefinement {
    pub child: LevelTopology,
    pub stencils: StencilTable,
    pub maps: ChildMaps,
}

/// Refine the faces `selected` of `parent` and every face sharing a vertex with one of them
/// (their one-ring), as OpenSubdiv's sparse selection does for feature-adaptive refinement.
///
/// If `parent` holds the complete one-ring of every selected face (all faces around each of
/// their corners, with exact vertex data), the child level holds the complete one-ring of
/// every child of a selected face, and the stencils of those child vertices are exactly the
/// uniform refiner's. Child vertices on the border of the refined region are computed from
/// the neighbourhood the parent has and may differ from a uniform refinement; topological
/// boundaries there are not mesh boundaries. With every face selected (and no isolated
/// vertex) the child is numbered exactly as [`refine_level`] numbers it.
pub fn refine_sparse(
    parent: LevelRef<'_>,
    scheme: Scheme,
    options: &SubdivOptions,
    selected: &[u32],
) -> Result<SparseRefinement, TopologyError> {
    refine_sparse_region(
        parent,
        scheme,
        options,
        selected,
        SparseRegion::OneRingFaces,
    )
}

/// Which children of the one-ring around a selection a [`refine_sparse_region`] step makes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum SparseRegion {
    /// Every child of every face sharing a vertex with a selected face ([`refine_sparse`]).
    #[default]
    OneRingFaces,
    /// Only what the children of the selected faces need for complete one-rings: the children
    /// of one-ring faces at a corner of a selected face, the vertex-vertices of those corners
    /// and the edge-vertices of their edges, as OpenSubdiv's sparse refinement keeps. The rest
    /// of the one-ring's children (about half of a refined level on catmark_car) would only be
    /// refined to be thrown away. Quad-splitting schemes; Loop takes
    /// [`SparseRegion::OneRingFaces`].
    SelectedCorners,
}

/// [`refine_sparse`] with a choice of [`SparseRegion`]. With
/// [`SparseRegion::SelectedCorners`], the children of the selected faces, their one-rings and
/// the stencils of their vertices are those of [`refine_sparse`] (the same rows, bit for bit,
/// under other child numbers); a one-ring face's children are made only at corners of selected
/// faces, so they come in corner order but not always all of them.
///
/// The step: the region (`Region`: the selected faces' one-ring, the vertices and edges
/// whose children are made), the child numbering (`ChildNumbering`), the edge halves'
/// sharpness and the stencil rows, then the child topology (`SparseChild`).
pub fn refine_sparse_region(
    parent: LevelRef<'_>,
    scheme: Scheme,
    options: &SubdivOptions,
    selected: &[u32],
    region: SparseRegion,
) -> Result<SparseRefinement, TopologyError> {
    let p = parent.topology;
    let nf = p.num_faces();
    if scheme == Scheme::DooSabin {
        return Err(TopologyError::UnsupportedScheme {
            scheme: scheme.name(),
            operation: "sparse refinement",
        });
    }
    if let Some(&f) = selected.iter().find(|&&f| f as usize >= nf) {
        return Err(TopologyError::FaceOutOfRange {
            face: f as usize,
            count: nf,
        });
    }
    check_size(p, scheme)?;
    let quads = scheme.splits_into_quads();
    let region = Region::of(p, selected, quads, region)?;
    let numbering = ChildNumbering::of(p, &region, quads);

    let halves = region_half_sharpness(parent, options, &region.verts);
    let decayed: Vec<f32> = parent
        .vertex_sharpness
        .iter()
        .map(|&s| decrement_sharpness(s))
        .collect();
    let ctx = MaskContext {
        p,
        es: parent.edge_sharpness,
        vs: parent.vertex_sharpness,
        scheme,
        options,
        child_edge_sharpness: &halves,
        child_vertex_sharpness: &decayed,
    };
    let stencils = numbering.stencils(&ctx);

    let mut child = SparseChild::new(p, &region, &numbering, quads);
    child.halves(&region.edges, &halves);
    for &f in &region.faces {
        child.children_of(f);
    }
    let face_first_child = std::mem::take(&mut child.face_first_child);
    let child_face_parent = std::mem::take(&mut child.child_face_parent);
    let edge_child_halves = std::mem::take(&mut child.edge_child_halves);
    let child = child.level(&region, &decayed);
    let ChildNumbering {
        vertex_child_vertex,
        edge_child_vertex,
        face_child_vertex,
        origin,
    } = numbering;
    Ok(SparseRefinement {
        child,
        stencils,
        maps: ChildMaps {
            refined_faces: region.faces,
            vertex_child_vertex,
            edge_child_vertex,
            face_child_vertex,
            face_first_child,
            child_vertex_origin: origin,
            child_face_parent,
            edge_child_halves,
        },
    })
}

/// Sharpness of the edge halves in the parent's numbering (2e, 2e + 1), as the masks read
/// it: a vertex-vertex's rule reads the halves of all its edges, also those leaving the
/// region, so every edge at a refined vertex (`verts`) gets its halves.
fn region_half_sharpness(parent: LevelRef<'_>, options: &SubdivOptions, verts: &[u32]) -> Vec<f32> {
    let p = parent.topology;
    let mut halves = vec![0.0f32; 2 * p.num_edges()];
    let mut scratch = Vec::new();
    for &v in verts {
        for &e in p.vertex_edges(v as usize) {
            let e = e as usize;
            // Smooth edges have smooth halves (as the zeroed `halves` has them).
            if is_sharp(parent.edge_sharpness[e]) {
                let pair = half_edge_sharpness(p, parent.edge_sharpness, options, e, &mut scratch);
                halves[2 * e..2 * e + 2].copy_from_slice(&pair);
            }
        }
    }
    halves
}

/// The part of a parent level a sparse step refines: the selected faces and their one-ring,
/// then the vertices and edges whose children are made.
struct Region {
    /// Per parent face, whether it is refined.
    face_mark: Vec<bool>,
    /// Per parent edge, whether it is refined.
    edge_mark: Vec<bool>,
    /// The refined faces, vertices and edges, in parent order.
    faces: Vec<u32>,
    verts: Vec<u32>,
    edges: Vec<u32>,
    /// Only the corners of selected faces get children ([`SparseRegion::SelectedCorners`]).
    corners_only: bool,
}

impl Region {
    fn of(
        p: &Topology,
        selected: &[u32],
        quads: bool,
        region: SparseRegion,
    ) -> Result<Region, TopologyError> {
        // Marks, not sort and dedup: each face is reached once per corner of every selected
        // face around it (about 16 times), and the marks give parent order directly.
        let mut face_mark = vec![false; p.num_faces()];
        for &f in selected {
            for &v in p.face_vertices(f as usize) {
                for &g in p.vertex_faces(v as usize) {
                    face_mark[g as usize] = true;
                }
            }
        }
        let faces = marked(&face_mark);
        if !quads {
            if let Some(&f) = faces
                .iter()
                .find(|&&f| p.face_vertices(f as usize).len() != 3)
            {
                return Err(TopologyError::LoopRequiresTriangles {
                    face: f as usize,
                    size: p.face_vertices(f as usize).len(),
                });
            }
        }
        // Corners whose children are made: every corner of the region (the whole one-ring),
        // or only the corners of selected faces.
        let corners_only = quads && region == SparseRegion::SelectedCorners;
        let mut vert_mark = vec![false; p.num_vertices()];
        let corner_faces: &[u32] = if corners_only { selected } else { &faces };
        for &f in corner_faces {
            for &v in p.face_vertices(f as usize) {
                vert_mark[v as usize] = true;
            }
        }
        // The edges at those corners (every edge of the region when every corner is made).
        let mut edge_mark = vec![false; p.num_edges()];
        for &f in &faces {
            let fv = p.face_vertices(f as usize);
            let n = fv.len();
            for (i, &e) in p.face_edge_list(f as usize).iter().enumerate() {
                if vert_mark[fv[i] as usize] || vert_mark[fv[(i + 1) % n] as usize] {
                    edge_mark[e as usize] = true;
                }
            }
        }
        let verts = marked(&vert_mark);
        let edges = marked(&edge_mark);
        Ok(Region {
            face_mark,
            edge_mark,
            faces,
            verts,
            edges,
            corners_only,
        })
    }
}

/// The child vertices of a sparse step: vertex-vertices, edge-vertices, face-vertices, each
/// in parent order, with the parent → child maps.
struct ChildNumbering {
    vertex_child_vertex: Vec<u32>,
    edge_child_vertex: Vec<u32>,
    face_child_vertex: Vec<u32>,
    origin: Vec<ChildOrigin>,
}

impl ChildNumbering {
    fn of(p: &Topology, region: &Region, quads: bool) -> ChildNumbering {
        let (kv, ke) = (region.verts.len(), region.edges.len());
        let mut vertex_child_vertex = vec![INVALID; p.num_vertices()];
        let mut edge_child_vertex = vec![INVALID; p.num_edges()];
        let mut face_child_vertex = vec![INVALID; p.num_faces()];
        let mut origin = Vec::with_capacity(kv + ke + region.faces.len());
        for (i, &v) in region.verts.iter().enumerate() {
            vertex_child_vertex[v as usize] = i as u32;
            origin.push(ChildOrigin::Vertex(v));
        }
        for (i, &e) in region.edges.iter().enumerate() {
            edge_child_vertex[e as usize] = (kv + i) as u32;
            origin.push(ChildOrigin::Edge(e));
        }
        if quads {
            for (i, &f) in region.faces.iter().enumerate() {
                face_child_vertex[f as usize] = (kv + ke + i) as u32;
                origin.push(ChildOrigin::Face(f));
            }
        }
        ChildNumbering {
            vertex_child_vertex,
            edge_child_vertex,
            face_child_vertex,
            origin,
        }
    }

    /// One stencil row per child vertex, in child order: the uniform refiner's row of the
    /// same parent component.
    fn stencils(&self, ctx: &MaskContext<'_>) -> StencilTable {
        let (nv, ne) = (ctx.p.num_vertices(), ctx.p.num_edges());
        build_rows(self.origin.len(), nv, |i, out| {
            let uniform_index = match self.origin[i] {
                ChildOrigin::Vertex(v) => v as usize,
                ChildOrigin::Edge(e) => nv + e as usize,
                ChildOrigin::Face(f) => nv + ne + f as usize,
            };
            ctx.row_merged(uniform_index, out)
        })
    }
}

/// The child topology of a sparse step as it is made: the two halves of each refined edge,
/// then the children of each refined face with their interior edges (one per corner for
/// quads, three per triangle for Loop).
///
/// Quads: the child's vertex → edge and vertex → face lists are filled as the child edges and
/// faces are made (both in ascending order, so the lists come out as the counting sort of
/// `Topology::from_parts` makes them), into rows counted from the parent: a vertex-vertex has
/// a half of each refined edge and a child of each refined face at its vertex, an
/// edge-vertex its halves and an inner edge per refined face of its edge and a child per made
/// end and face, a face-vertex an inner edge per edge at a made corner and its children.
/// Counts go to slot `c + 2`, so that after the prefix sum slot `c + 1` is the fill cursor of
/// child vertex `c` and ends as its end offset.
struct SparseChild<'a> {
    p: &'a Topology,
    quads: bool,
    /// Child vertices, and the first edge-vertex.
    nc: usize,
    kv: usize,
    vertex_child_vertex: &'a [u32],
    edge_child_vertex: &'a [u32],
    face_child_vertex: &'a [u32],
    /// Quads: the vertex → edge and vertex → face rows (fill cursors until made) and lists.
    edge_rows: Vec<u32>,
    face_rows: Vec<u32>,
    vert_edges: Vec<u32>,
    vert_faces: Vec<u32>,
    /// Each refined edge's halves (`ChildMaps::edge_child_halves`).
    edge_child_halves: Vec<[u32; 2]>,
    edge_verts: Vec<[u32; 2]>,
    edge_sharpness: Vec<f32>,
    /// Quads: each child edge's faces, filled as the faces are made (as `from_parts` does).
    edge_faces: Vec<[u32; 2]>,
    face_first_child: Vec<u32>,
    /// An n-gon's inner edges, reused from face to face.
    inner_at: Vec<u32>,
    child_face_parent: Vec<u32>,
    face_offsets: Vec<u32>,
    face_verts: Vec<u32>,
    face_edges: Vec<u32>,
}

impl<'a> SparseChild<'a> {
    /// Counts the rows and sizes the child's arrays up front (a quad per corner, or four
    /// triangles): growing them copied MBs per level.
    fn new(
        p: &'a Topology,
        region: &Region,
        numbering: &'a ChildNumbering,
        quads: bool,
    ) -> SparseChild<'a> {
        let (kv, ke) = (region.verts.len(), region.edges.len());
        let nc = numbering.origin.len();
        let mut child = SparseChild {
            p,
            quads,
            nc,
            kv,
            vertex_child_vertex: &numbering.vertex_child_vertex,
            edge_child_vertex: &numbering.edge_child_vertex,
            face_child_vertex: &numbering.face_child_vertex,
            edge_rows: Vec::new(),
            face_rows: Vec::new(),
            vert_edges: Vec::new(),
            vert_faces: Vec::new(),
            edge_child_halves: Vec::new(),
            edge_verts: Vec::new(),
            edge_sharpness: Vec::new(),
            edge_faces: Vec::new(),
            face_first_child: Vec::new(),
            inner_at: Vec::new(),
            child_face_parent: Vec::new(),
            face_offsets: Vec::new(),
            face_verts: Vec::new(),
            face_edges: Vec::new(),
        };
        if quads {
            (child.edge_rows, child.face_rows) = (vec![0u32; nc + 2], vec![0u32; nc + 2]);
            child.count_vertex_rows(region);
        }
        let child_faces = child.count_face_rows(region);
        prefix_sum(&mut child.edge_rows);
        prefix_sum(&mut child.face_rows);
        child.vert_edges = vec![0u32; child.edge_rows.last().map_or(0, |&x| x as usize)];
        child.vert_faces = vec![0u32; child.face_rows.last().map_or(0, |&x| x as usize)];
        let corners = if quads { 4 } else { 3 } * child_faces;
        // The halves, then one inner edge per child quad (or three per triangle; with
        // corners_only, one per parent edge at a made corner, at most one per child quad).
        let inner_edges = if quads {
            child_faces
        } else {
            3 * region.faces.len()
        };
        child.edge_child_halves = Vec::with_capacity(ke);
        child.edge_verts = Vec::with_capacity(2 * ke + inner_edges);
        child.edge_sharpness = Vec::with_capacity(child.edge_verts.capacity());
        if quads {
            child.edge_faces = vec![[INVALID; 2]; 2 * ke + inner_edges];
        }
        child.face_first_child = vec![INVALID; p.num_faces()];
        child.child_face_parent = Vec::with_capacity(child_faces);
        child.face_offsets = Vec::with_capacity(child_faces + 1);
        child.face_offsets.push(0u32);
        child.face_verts = Vec::with_capacity(corners);
        child.face_edges = Vec::with_capacity(corners);
        child
    }

    /// The child vertex of parent vertex `v`.
    #[inline(always)]
    fn vc(&self, v: u32) -> u32 {
        self.vertex_child_vertex[v as usize]
    }

    /// The child vertex of parent edge `e`.
    #[inline(always)]
    fn ec(&self, e: u32) -> u32 {
        self.edge_child_vertex[e as usize]
    }

    /// Whether corner vertex `v` has children (every region vertex has, unless corners_only).
    #[inline(always)]
    fn made(&self, v: u32) -> bool {
        self.vertex_child_vertex[v as usize] != INVALID
    }

    /// Child edge `e` into the edge list of child vertex `c`.
    #[inline(always)]
    fn edge_to(&mut self, c: u32, e: u32) {
        let cursor = &mut self.edge_rows[c as usize + 1];
        self.vert_edges[*cursor as usize] = e;
        *cursor += 1;
    }

    /// The half of refined edge `e` at its end `v`.
    #[inline(always)]
    fn half_at(&self, e: u32, v: u32) -> u32 {
        let [a, _] = self.p.edge_verts[e as usize];
        self.edge_child_halves[(self.ec(e) - self.kv as u32) as usize][usize::from(a != v)]
    }

    /// The vertex → edge and vertex → face counts of the vertex- and edge-vertices (quads).
    fn count_vertex_rows(&mut self, region: &Region) {
        let p = self.p;
        let kv = self.kv;
        for (i, &v) in region.verts.iter().enumerate() {
            let (ne_v, nf_v) = if region.corners_only {
                // Every face at a selected face's corner is in the region, and so every edge.
                (
                    p.vertex_edges(v as usize).len(),
                    p.vertex_faces(v as usize).len(),
                )
            } else {
                (
                    p.vertex_edges(v as usize)
                        .iter()
                        .filter(|&&e| region.edge_mark[e as usize])
                        .count(),
                    p.vertex_faces(v as usize)
                        .iter()
                        .filter(|&&g| region.face_mark[g as usize])
                        .count(),
                )
            };
            self.edge_rows[i + 2] = ne_v as u32;
            self.face_rows[i + 2] = nf_v as u32;
        }
        // Whether face `g` is refined.
        let refined = |g: u32| g != INVALID && region.face_mark[g as usize];
        for (r, &e) in region.edges.iter().enumerate() {
            let ends = p.edge_verts[e as usize]
                .iter()
                .filter(|&&v| self.made(v))
                .count() as u32;
            let faces_e = p.edge_faces[e as usize]
                .iter()
                .filter(|&&g| refined(g))
                .count() as u32;
            self.edge_rows[kv + r + 2] = ends + faces_e;
            self.face_rows[kv + r + 2] = ends * faces_e;
        }
    }

    /// The face-vertices' counts (quads) and the number of child faces.
    fn count_face_rows(&mut self, region: &Region) -> usize {
        let base = self.kv + region.edges.len() + 2;
        let mut child_faces = 0usize;
        for (r, &f) in region.faces.iter().enumerate() {
            if self.quads {
                let fv = self.p.face_vertices(f as usize);
                let n = fv.len();
                let (mut corners_made, mut inner) = (0u32, 0u32);
                for i in 0..n {
                    corners_made += u32::from(self.made(fv[i]));
                    inner += u32::from(self.made(fv[i]) || self.made(fv[(i + 1) % n]));
                }
                self.edge_rows[base + r] = inner;
                self.face_rows[base + r] = corners_made;
                child_faces += corners_made as usize;
            } else {
                child_faces += 4;
            }
        }
        child_faces
    }

    /// The halves of each refined edge `edges`: both, unless corners_only leaves an end
    /// without a vertex-vertex, and so without its half; `halves` their sharpness in the
    /// parent's numbering.
    fn halves(&mut self, edges: &[u32], halves: &[f32]) {
        for &e in edges {
            let [a, b] = self.p.edge_verts[e as usize];
            let h = &halves[2 * e as usize..2 * e as usize + 2];
            let mut pair = [INVALID; 2];
            if self.made(a) {
                pair[0] = self.edge_verts.len() as u32;
                self.edge_verts.push([self.vc(a), self.ec(e)]);
                self.edge_sharpness.push(h[0]);
            }
            if self.made(b) {
                pair[1] = self.edge_verts.len() as u32;
                self.edge_verts.push([self.ec(e), self.vc(b)]);
                self.edge_sharpness.push(h[1]);
            }
            if self.quads {
                for x in pair {
                    if x != INVALID {
                        let [u, w] = self.edge_verts[x as usize];
                        self.edge_to(u, x);
                        self.edge_to(w, x);
                    }
                }
            }
            self.edge_child_halves.push(pair);
        }
    }

    /// The children of refined face `f` and their inner edges.
    fn children_of(&mut self, f: u32) {
        let p = self.p;
        let fv = p.face_vertices(f as usize);
        let fe = p.face_edge_list(f as usize);
        self.face_first_child[f as usize] = self.child_face_parent.len() as u32;
        if let (true, Ok(fv), Ok(fe)) = (
            self.quads,
            <&[u32; 4]>::try_from(fv),
            <&[u32; 4]>::try_from(fe),
        ) {
            self.quad_children(f, fv, fe);
        } else if self.quads {
            self.polygon_children(f, fv, fe);
        } else {
            self.triangle_children(f, fv, fe);
        }
    }

    /// A child quad `[v, e, fc, ep]` with edges `qe` of parent face `f`.
    #[inline(always)]
    fn push_quad(&mut self, f: u32, qv: [u32; 4], qe: [u32; 4]) {
        quad_made(
            (
                &mut self.face_rows,
                &mut self.vert_faces,
                &mut self.edge_faces,
            ),
            self.child_face_parent.len() as u32,
            qv,
            qe,
        );
        self.face_verts.extend_from_slice(&qv);
        self.face_edges.extend_from_slice(&qe);
        self.face_offsets.push(self.face_verts.len() as u32);
        self.child_face_parent.push(f);
    }

    /// A quad's children: as [`SparseChild::polygon_children`], unrolled.
    fn quad_children(&mut self, f: u32, fv: &[u32; 4], fe: &[u32; 4]) {
        let fc = self.face_child_vertex[f as usize];
        let corner_made = [
            self.made(fv[0]),
            self.made(fv[1]),
            self.made(fv[2]),
            self.made(fv[3]),
        ];
        let mut inner4 = [INVALID; 4];
        for i in 0..4 {
            if corner_made[i] || corner_made[(i + 1) & 3] {
                let x = self.edge_verts.len() as u32;
                inner4[i] = x;
                self.edge_verts.push([self.ec(fe[i]), fc]);
                self.edge_to(self.ec(fe[i]), x);
                self.edge_to(fc, x);
            }
        }
        for i in 0..4 {
            if !corner_made[i] {
                continue;
            }
            let prev = (i + 3) & 3;
            let (v, e, ep) = (fv[i], fe[i], fe[prev]);
            let qv = [self.vc(v), self.ec(e), fc, self.ec(ep)];
            let qe = [
                self.half_at(e, v),
                inner4[i],
                inner4[prev],
                self.half_at(ep, v),
            ];
            self.push_quad(f, qv, qe);
        }
    }

    /// The children of an n-gon (Catmull-Clark, bilinear): inner edge i (edge i's vertex to
    /// the face's) where corner i or i + 1 is made (all of them unless corners_only, in edge
    /// order either way), then a quad per made corner.
    fn polygon_children(&mut self, f: u32, fv: &[u32], fe: &[u32]) {
        let n = fv.len();
        let fc = self.face_child_vertex[f as usize];
        self.inner_at.clear();
        self.inner_at.resize(n, INVALID);
        for (i, &e) in fe.iter().enumerate() {
            if self.made(fv[i]) || self.made(fv[(i + 1) % n]) {
                let x = self.edge_verts.len() as u32;
                self.inner_at[i] = x;
                self.edge_verts.push([self.ec(e), fc]);
                self.edge_to(self.ec(e), x);
                self.edge_to(fc, x);
            }
        }
        for i in 0..n {
            if !self.made(fv[i]) {
                continue;
            }
            let prev = (i + n - 1) % n;
            let (v, e, ep) = (fv[i], fe[i], fe[prev]);
            let qv = [self.vc(v), self.ec(e), fc, self.ec(ep)];
            let qe = [
                self.half_at(e, v),
                self.inner_at[i],
                self.inner_at[prev],
                self.half_at(ep, v),
            ];
            self.push_quad(f, qv, qe);
        }
    }

    /// A Loop triangle's four children and its three inner edges.
    fn triangle_children(&mut self, f: u32, fv: &[u32], fe: &[u32]) {
        let inner = self.edge_verts.len() as u32;
        for j in 0..3 {
            let prev = (j + 2) % 3;
            // Inner edge j joins the midpoints of the two edges at corner j.
            self.edge_verts.push([self.ec(fe[j]), self.ec(fe[prev])]);
            let corner = [self.vc(fv[j]), self.ec(fe[j]), self.ec(fe[prev])];
            self.face_verts.extend_from_slice(&corner);
            let edges = [
                self.half_at(fe[j], fv[j]),
                inner + j as u32,
                self.half_at(fe[prev], fv[j]),
            ];
            self.face_edges.extend_from_slice(&edges);
            self.face_offsets.push(self.face_verts.len() as u32);
            self.child_face_parent.push(f);
        }
        let centre = [self.ec(fe[0]), self.ec(fe[1]), self.ec(fe[2])];
        self.face_verts.extend_from_slice(&centre);
        self.face_edges
            .extend_from_slice(&[inner + 1, inner + 2, inner]);
        self.face_offsets.push(self.face_verts.len() as u32);
        self.child_face_parent.push(f);
    }

    /// The child level: its topology (quads: the lists filled as it was made; Loop: built
    /// from the faces and edges), the inner edges smooth, and the vertex-vertices' decayed
    /// sharpness.
    fn level(mut self, region: &Region, decayed: &[f32]) -> LevelTopology {
        let nc = self.nc;
        self.edge_sharpness.resize(self.edge_verts.len(), 0.0);
        let mut vertex_sharpness = vec![0.0f32; nc];
        for (slot, &v) in vertex_sharpness.iter_mut().zip(&region.verts) {
            *slot = decayed[v as usize];
        }
        let topology = if self.quads {
            self.edge_faces.truncate(self.edge_verts.len());
            self.edge_rows.pop();
            self.face_rows.pop();
            Topology {
                num_vertices: nc,
                face_offsets: self.face_offsets,
                face_verts: self.face_verts,
                face_edges: self.face_edges,
                edge_verts: self.edge_verts,
                edge_faces: self.edge_faces,
                vert_edge_offsets: self.edge_rows,
                vert_edges: self.vert_edges,
                vert_face_offsets: self.face_rows,
                vert_faces: self.vert_faces,
            }
        } else {
            Topology::from_parts(
                nc,
                self.face_offsets,
                self.face_verts,
                self.face_edges,
                self.edge_verts,
            )
        };
        LevelTopology {
            topology,
            edge_sharpness: self.edge_sharpness,
            vertex_sharpness,
        }
    }
}

/// A child quad `cf` of a sparse step made, with corners `qv` and edges `qe`: its corners'
/// face lists (`rows` are their fill cursors) and its edges' face pairs.
#[inline(always)]
fn quad_made(
    (rows, vert_faces, edge_faces): (&mut [u32], &mut [u32], &mut [[u32; 2]]),
    cf: u32,
    qv: [u32; 4],
    qe: [u32; 4],
) {
    for x in qv {
        let cursor = &mut rows[x as usize + 1];
        vert_faces[*cursor as usize] = cf;
        *cursor += 1;
    }
    for x in qe {
        push_pair(&mut edge_faces[x as usize], cf);
    }
}

/// The indices of the set marks, in order.
fn marked(marks: &[bool]) -> Vec<u32> {
    marks
        .iter()
        .enumerate()
        .filter_map(|(i, &m)| m.then_some(i as u32))
        .collect()
}

/// Child edge index of parent edge `e` at its end vertex `v`.
#[inline]
fn child_edge_at(p: &Topology, e: u32, v: u32) -> u32 {
    2 * e + u32::from(p.edge_verts[e as usize][0] != v)
}

/// Sharpness of the two children of every parent edge (child `2e` at end 0, `2e + 1` at end 1),
/// followed by smooth interior edges (`extra` of them).
fn child_edge_sharpness(
    p: &Topology,
    edge_sharpness: &[f32],
    options: &SubdivOptions,
    extra: usize,
) -> Vec<f32> {
    let mut out = vec![0.0f32; 2 * p.num_edges() + extra];
    out[..2 * p.num_edges()]
        .par_chunks_mut(2)
        .enumerate()
        .with_min_len(4096)
        .for_each(|(e, pair)| {
            if is_sharp(edge_sharpness[e]) {
                let halves = half_edge_sharpness(p, edge_sharpness, options, e, &mut Vec::new());
                pair.copy_from_slice(&halves);
            }
        });
    out
}

/// Sharpness of the two halves of edge `e` (at end 0, at end 1): each decays with the rule of
/// [`subdivide_edge_sharpness_at_vertex`] over the edges incident to its end vertex.
/// `incident` is scratch space.
fn half_edge_sharpness(
    p: &Topology,
    edge_sharpness: &[f32],
    options: &SubdivOptions,
    e: usize,
    incident: &mut Vec<f32>,
) -> [f32; 2] {
    let s = edge_sharpness[e];
    let mut out = [0.0f32; 2];
    if !is_sharp(s) {
        return out;
    }
    for (k, slot) in out.iter_mut().enumerate() {
        let v = p.edge_verts[e][k] as usize;
        incident.clear();
        incident.extend(
            p.vertex_edges(v)
                .iter()
                .map(|&x| edge_sharpness[x as usize]),
        );
        *slot = subdivide_edge_sharpness_at_vertex(options.crease_method, s, incident);
    }
    out
}

/// Position of edge `e` in the edge list of face `f` (corner `i` owns edge `i → i + 1`).
#[inline]
fn edge_slot(p: &Topology, f: u32, e: u32) -> usize {
    p.face_edge_list(f as usize)
        .iter()
        .position(|&x| x == e)
        .expect("edge lists its faces")
}

/// Push `x` into the first free (`INVALID`) slot of a pair.
#[inline]
fn push_pair(pair: &mut [u32; 2], x: u32) {
    if pair[0] == INVALID {
        pair[0] = x;
    } else {
        pair[1] = x;
    }
}

/// Catmull-Clark / bilinear split: face `f` with n corners → n quads (one per corner).
///
/// Child face `c` is the quad at parent corner `c`; child edges are `2e`, `2e + 1` (halves of
/// parent edge `e`) then one interior edge per parent corner. Every adjacency table of the
/// child is written directly from the parent's, in parallel and in the order (ascending
/// indices) a generic counting sort would produce.
fn split_quads(p: &Topology) -> Topology {
    let split = QuadSplit {
        p,
        nv: p.num_vertices(),
        ne: p.num_edges(),
        corner_face: corner_faces(&p.face_offsets, p.face_verts.len()),
    };
    let (edge_verts, edge_faces) = split.edges();
    let (face_verts, face_edges) = split.faces();
    let face_offsets: Vec<u32> = (0..=p.face_verts.len() as u32).map(|i| 4 * i).collect();
    let (vert_edge_offsets, vert_face_offsets) = split.vertex_offsets();
    let vert_edges = split.vertex_edges(&vert_edge_offsets);
    let vert_faces = split.vertex_faces(&vert_face_offsets);
    Topology {
        num_vertices: split.nv + split.ne + p.num_faces(),
        face_offsets,
        face_verts,
        face_edges,
        edge_verts,
        edge_faces,
        vert_edge_offsets,
        vert_edges,
        vert_face_offsets,
        vert_faces,
    }
}

/// A uniform Catmull-Clark / bilinear split of `p` ([`split_quads`]), table by table.
struct QuadSplit<'a> {
    p: &'a Topology,
    nv: usize,
    ne: usize,
    /// The face of each parent corner.
    corner_face: Vec<u32>,
}

/// Parallel chunks of the split's tables.
const SPLIT_MIN_LEN: usize = 4096;

impl QuadSplit<'_> {
    /// The child vertex of parent edge `e`.
    fn vert_e(&self, e: u32) -> u32 {
        (self.nv as u32) + e
    }

    /// The child vertex of parent face `f`.
    fn vert_f(&self, f: u32) -> u32 {
        (self.nv + self.ne) as u32 + f
    }

    /// The interior child edge at parent corner `c`.
    fn face_edge(&self, c: usize) -> u32 {
        (2 * self.ne + c) as u32
    }

    /// The child edges' vertices and faces: the halves of each parent edge, then one interior
    /// edge per parent corner.
    fn edges(&self) -> (Vec<[u32; 2]>, Vec<[u32; 2]>) {
        let (p, ne) = (self.p, self.ne);
        let corners = p.face_verts.len();
        let corner_face = &self.corner_face;
        let mut edge_verts = vec![[0u32; 2]; 2 * ne + corners];
        let mut edge_faces = vec![[INVALID; 2]; 2 * ne + corners];
        let (halves, inner) = edge_verts.split_at_mut(2 * ne);
        halves
            .par_chunks_mut(2)
            .enumerate()
            .with_min_len(SPLIT_MIN_LEN)
            .for_each(|(e, pair)| {
                let [a, b] = p.edge_verts[e];
                pair[0] = [a, self.vert_e(e as u32)];
                pair[1] = [self.vert_e(e as u32), b];
            });
        inner
            .par_iter_mut()
            .enumerate()
            .with_min_len(SPLIT_MIN_LEN)
            .for_each(|(c, slot)| {
                *slot = [self.vert_e(p.face_edges[c]), self.vert_f(corner_face[c])]
            });
        let (halves, inner) = edge_faces.split_at_mut(2 * ne);
        halves
            .par_chunks_mut(2)
            .enumerate()
            .with_min_len(SPLIT_MIN_LEN)
            .for_each(|(e, pair)| {
                for f in p.edge_faces[e] {
                    if f == INVALID {
                        continue;
                    }
                    let s = p.face_offsets[f as usize] as usize;
                    let n = p.face_offsets[f as usize + 1] as usize - s;
                    let i = edge_slot(p, f, e as u32);
                    // The face runs fv[i] → fv[i + 1] along e.
                    let x = (child_edge_at(p, e as u32, p.face_verts[s + i]) & 1) as usize;
                    push_pair(&mut pair[x], (s + i) as u32);
                    push_pair(&mut pair[1 - x], (s + (i + 1) % n) as u32);
                }
                for slot in pair.iter_mut() {
                    if slot[1] != INVALID && slot[0] > slot[1] {
                        slot.swap(0, 1);
                    }
                }
            });
        inner
            .par_iter_mut()
            .enumerate()
            .with_min_len(SPLIT_MIN_LEN)
            .for_each(|(c, slot)| {
                let f = corner_face[c] as usize;
                let s = p.face_offsets[f] as usize;
                let n = p.face_offsets[f + 1] as usize - s;
                let next = (s + (c - s + 1) % n) as u32;
                *slot = [(c as u32).min(next), (c as u32).max(next)];
            });
        (edge_verts, edge_faces)
    }

    /// The child quads' vertices and edges: quad `c` at parent corner `c`.
    fn faces(&self) -> (Vec<u32>, Vec<u32>) {
        let p = self.p;
        let corners = p.face_verts.len();
        let mut face_verts = vec![0u32; 4 * corners];
        let mut face_edges = vec![0u32; 4 * corners];
        face_verts
            .par_chunks_mut(4)
            .zip(face_edges.par_chunks_mut(4))
            .enumerate()
            .with_min_len(SPLIT_MIN_LEN)
            .for_each(|(c, (qv, qe))| {
                let f = self.corner_face[c] as usize;
                let s = p.face_offsets[f] as usize;
                let n = p.face_offsets[f + 1] as usize - s;
                let i = c - s;
                let prev = s + (i + n - 1) % n;
                let v = p.face_verts[c];
                let (e, ep) = (p.face_edges[c], p.face_edges[prev]);
                qv.copy_from_slice(&[v, self.vert_e(e), self.vert_f(f as u32), self.vert_e(ep)]);
                qe.copy_from_slice(&[
                    child_edge_at(p, e, v),
                    self.face_edge(c),
                    self.face_edge(prev),
                    child_edge_at(p, ep, v),
                ]);
            });
        (face_verts, face_edges)
    }

    /// Vertex incidence offsets (edges, faces): vertex-vertices inherit their parent's counts,
    /// edge-vertices have the two halves plus one interior edge per face, face-vertices one
    /// edge and face per corner.
    fn vertex_offsets(&self) -> (Vec<u32>, Vec<u32>) {
        let p = self.p;
        let nc = self.nv + self.ne + p.num_faces();
        let mut vert_edge_offsets = Vec::with_capacity(nc + 1);
        let mut vert_face_offsets = Vec::with_capacity(nc + 1);
        vert_edge_offsets.extend_from_slice(&p.vert_edge_offsets);
        vert_face_offsets.extend_from_slice(&p.vert_face_offsets);
        let (mut oe, mut of) = (p.vert_edges.len() as u32, p.vert_faces.len() as u32);
        for ef in &p.edge_faces {
            let k = 1 + u32::from(ef[1] != INVALID);
            oe += 2 + k;
            of += 2 * k;
            vert_edge_offsets.push(oe);
            vert_face_offsets.push(of);
        }
        for w in p.face_offsets.windows(2) {
            let n = w[1] - w[0];
            oe += n;
            of += n;
            vert_edge_offsets.push(oe);
            vert_face_offsets.push(of);
        }
        (vert_edge_offsets, vert_face_offsets)
    }

    /// Each child vertex's edges, ascending.
    fn vertex_edges(&self, offsets: &[u32]) -> Vec<u32> {
        let (p, nv, ne) = (self.p, self.nv, self.ne);
        let mut vert_edges = vec![0u32; *offsets.last().expect("offsets") as usize];
        par_fill_ragged(offsets, &mut vert_edges, |i, out| {
            if i < nv {
                for (slot, &e) in out.iter_mut().zip(p.vertex_edges(i)) {
                    *slot = child_edge_at(p, e, i as u32);
                }
            } else if i < nv + ne {
                let e = (i - nv) as u32;
                out[0] = 2 * e;
                out[1] = 2 * e + 1;
                let mut k = 2;
                for f in p.edge_faces[e as usize] {
                    if f != INVALID {
                        let c = p.face_offsets[f as usize] as usize + edge_slot(p, f, e);
                        out[k] = self.face_edge(c);
                        k += 1;
                    }
                }
                out[2..].sort_unstable();
            } else {
                let s = p.face_offsets[i - nv - ne] as usize;
                for (k, slot) in out.iter_mut().enumerate() {
                    *slot = self.face_edge(s + k);
                }
            }
        });
        vert_edges
    }

    /// Each child vertex's faces, ascending.
    fn vertex_faces(&self, offsets: &[u32]) -> Vec<u32> {
        let (p, nv, ne) = (self.p, self.nv, self.ne);
        let mut vert_faces = vec![0u32; *offsets.last().expect("offsets") as usize];
        par_fill_ragged(offsets, &mut vert_faces, |i, out| {
            if i < nv {
                for (slot, &f) in out.iter_mut().zip(p.vertex_faces(i)) {
                    let s = p.face_offsets[f as usize] as usize;
                    let k = p
                        .face_vertices(f as usize)
                        .iter()
                        .position(|&x| x as usize == i)
                        .expect("face lists its vertices");
                    *slot = (s + k) as u32;
                }
            } else if i < nv + ne {
                let e = (i - nv) as u32;
                let mut k = 0;
                for f in p.edge_faces[e as usize] {
                    if f != INVALID {
                        let s = p.face_offsets[f as usize] as usize;
                        let n = p.face_offsets[f as usize + 1] as usize - s;
                        let j = edge_slot(p, f, e);
                        out[k] = (s + j) as u32;
                        out[k + 1] = (s + (j + 1) % n) as u32;
                        k += 2;
                    }
                }
                out.sort_unstable();
            } else {
                let s = p.face_offsets[i - nv - ne];
                for (k, slot) in out.iter_mut().enumerate() {
                    *slot = s + k as u32;
                }
            }
        });
        vert_faces
    }
}

/// Loop split: each triangle → three corner triangles and a middle one.
fn split_triangles(p: &Topology) -> Topology {
    let (nv, ne, nf) = (p.num_vertices(), p.num_edges(), p.num_faces());
    let vert_e = |e: u32| (nv as u32) + e;
    let inner = |f: usize, j: usize| (2 * ne + 3 * f + j) as u32;

    let mut edge_verts = Vec::with_capacity(2 * ne + 3 * nf);
    for (e, &[a, b]) in p.edge_verts.iter().enumerate() {
        edge_verts.push([a, vert_e(e as u32)]);
        edge_verts.push([vert_e(e as u32), b]);
    }
    let mut face_verts = vec![0u32; 12 * nf];
    let mut face_edges = vec![0u32; 12 * nf];
    for f in 0..nf {
        let fv = p.face_vertices(f);
        let fe = p.face_edge_list(f);
        for j in 0..3 {
            let prev = (j + 2) % 3;
            // Inner edge j joins the midpoints of the two edges at corner j.
            edge_verts.push([vert_e(fe[j]), vert_e(fe[prev])]);
            let c = 12 * f + 3 * j;
            face_verts[c..c + 3].copy_from_slice(&[fv[j], vert_e(fe[j]), vert_e(fe[prev])]);
            face_edges[c..c + 3].copy_from_slice(&[
                child_edge_at(p, fe[j], fv[j]),
                inner(f, j),
                child_edge_at(p, fe[prev], fv[j]),
            ]);
        }
        let c = 12 * f + 9;
        face_verts[c..c + 3].copy_from_slice(&[vert_e(fe[0]), vert_e(fe[1]), vert_e(fe[2])]);
        face_edges[c..c + 3].copy_from_slice(&[inner(f, 1), inner(f, 2), inner(f, 0)]);
    }
    let face_offsets: Vec<u32> = (0..=4 * nf as u32).map(|i| 3 * i).collect();
    Topology::from_parts(nv + ne, face_offsets, face_verts, face_edges, edge_verts)
}

/// Everything the vertex masks need for one refinement step.
struct MaskContext<'a> {
    /// Parent topology, edge sharpness and vertex sharpness.
    p: &'a Topology,
    es: &'a [f32],
    vs: &'a [f32],
    scheme: Scheme,
    options: &'a SubdivOptions,
    child_edge_sharpness: &'a [f32],
    child_vertex_sharpness: &'a [f32],
}

impl MaskContext<'_> {
    /// Stencil row of child vertex `i` over the parent vertices.
    fn row(&self, i: usize, out: &mut Vec<(u32, f64)>) {
        let p = self.p;
        let (nv, ne) = (p.num_vertices(), p.num_edges());
        if i < nv {
            self.vertex_vertex(i, out);
        } else if i < nv + ne {
            self.edge_vertex(i - nv, out);
        } else {
            self.face_center(i - nv - ne, 1.0, out);
        }
    }

    fn face_center(&self, f: usize, scale: f64, out: &mut Vec<(u32, f64)>) {
        let fv = self.p.face_vertices(f);
        let w = scale / fv.len() as f64;
        out.extend(fv.iter().map(|&v| (v, w)));
    }

    fn edge_vertex(&self, e: usize, out: &mut Vec<(u32, f64)>) {
        let p = self.p;
        let [a, b] = p.edge_verts[e];
        if self.scheme == Scheme::Bilinear {
            out.extend([(a, 0.5), (b, 0.5)]);
            return;
        }
        let s = self.es[e];
        if !is_sharp(s) {
            self.smooth_edge(e, 1.0, out);
            return;
        }
        let child_is_crease = is_sharp(self.child_edge_sharpness[2 * e])
            && is_sharp(self.child_edge_sharpness[2 * e + 1]);
        if child_is_crease {
            out.extend([(a, 0.5), (b, 0.5)]);
            return;
        }
        // Crease → smooth transition: blend by the parent sharpness (as OpenSubdiv does).
        let pw = s as f64;
        self.smooth_edge(e, 1.0 - pw, out);
        out.extend([(a, 0.5 * pw), (b, 0.5 * pw)]);
    }

    fn smooth_edge(&self, e: usize, scale: f64, out: &mut Vec<(u32, f64)>) {
        let p = self.p;
        let [a, b] = p.edge_verts[e];
        let faces = p.edge_face_list(e);
        match self.scheme {
            Scheme::Loop => {
                let (vw, fw) = if faces.len() == 2 {
                    (0.375, 0.125)
                } else {
                    (0.375, 0.25 / faces.len() as f64)
                };
                out.extend([(a, scale * vw), (b, scale * vw)]);
                for &f in faces {
                    if let Some(&o) = p
                        .face_vertices(f as usize)
                        .iter()
                        .find(|&&x| x != a && x != b)
                    {
                        out.push((o, scale * fw));
                    }
                }
            }
            _ => {
                let (vw, fw) = self.catmark_edge_weights(faces);
                out.extend([(a, scale * vw), (b, scale * vw)]);
                for &f in faces {
                    self.face_center(f as usize, scale * fw, out);
                }
            }
        }
    }

    /// Catmull-Clark's smooth edge-point weights (each end, each face's centre) for an edge
    /// between `faces` (one or two).
    fn catmark_edge_weights(&self, faces: &[u32]) -> (f64, f64) {
        let p = self.p;
        let tri = |f: u32| p.face_vertices(f as usize).len() == 3;
        let smooth_tris = self.options.triangle_subdivision == TriangleSubdivision::Smooth
            && faces.len() == 2
            && (tri(faces[0]) || tri(faces[1]));
        if smooth_tris {
            const TRI_EDGE_WEIGHT: f64 = 0.470;
            let f0 = if tri(faces[0]) { TRI_EDGE_WEIGHT } else { 0.25 };
            let f1 = if tri(faces[1]) { TRI_EDGE_WEIGHT } else { 0.25 };
            let fw = 0.5 * (f0 + f1);
            (0.5 * (1.0 - 2.0 * fw), fw)
        } else if faces.len() == 2 {
            (0.25, 0.25)
        } else {
            (0.25, 0.5 / faces.len() as f64)
        }
    }

    /// [`MaskContext::row`], merged (indices ascending and distinct, no zero weight) for the
    /// common Catmull-Clark rules (face points, smooth edge points, smooth vertex points), so
    /// the row builder skips its accumulator; `true` then. Each index's contributions are
    /// added in the order `row` lists them, as the accumulator adds them, so the weights are
    /// bit-identical. Where the one-ring is not what the fast rule reads (a vertex repeated in
    /// a ring, a long ring) the raw row is written instead, and `false` returned.
    fn row_merged(&self, i: usize, out: &mut RowOut) -> bool {
        let p = self.p;
        let (nv, ne) = (p.num_vertices(), p.num_edges());
        let merged = self.scheme == Scheme::CatmullClark
            && if i < nv {
                self.smooth_vertex_merged(i, out)
            } else if i < nv + ne {
                self.smooth_edge_merged(i - nv, out)
            } else {
                face_centre_merged(p.face_vertices(i - nv - ne), out)
            };
        if !merged {
            self.row(i, out.raw);
        }
        merged
    }

    /// The smooth (or dart) vertex point of a Catmull-Clark vertex, merged: the vertex, its
    /// ring neighbours (an edge term, then each face's share) and the other corners of its
    /// faces (one face's share each).
    fn smooth_vertex_merged(&self, v: usize, out: &mut RowOut) -> bool {
        // Longest ring and row taken here (kept short: the arrays are zeroed per row).
        const RING: usize = 11;
        const ROW: usize = 24;
        let p = self.p;
        let edges = p.vertex_edges(v);
        let faces = p.vertex_faces(v);
        let k = edges.len();
        if k == 0 || k > RING || faces.len() > RING {
            return false;
        }
        let sharp_count = edges
            .iter()
            .filter(|&&e| is_sharp(self.es[e as usize]))
            .count();
        if !matches!(
            vertex_rule(self.vs[v], sharp_count),
            Rule::Smooth | Rule::Dart
        ) {
            return false;
        }
        let done = match k {
            3 => quad_vertex_row::<3, 7>(p, v, edges, faces, out),
            4 => quad_vertex_row::<4, 9>(p, v, edges, faces, out),
            5 => quad_vertex_row::<5, 11>(p, v, edges, faces, out),
            _ => false,
        };
        if done {
            return true;
        }
        // As `smooth_vertex(v, 1.0)` computes them. Weight slots: the vertex, each ring
        // neighbour, then each face's share at its far corners.
        let scale = 1.0f64;
        let n = k as f64;
        let ew = 1.0 / (n * n);
        let mut ring = [0u32; RING];
        let mut w = [0.0f64; 1 + 2 * RING];
        let mut keys = [0u64; ROW];
        keys[0] = entry_key(v as u32, 0);
        for (j, &e) in edges.iter().enumerate() {
            ring[j] = other_end(p, e, v);
            w[1 + j] = scale * ew;
            keys[1 + j] = entry_key(ring[j], 1 + j);
        }
        let mut len = 1 + k;
        let ring = &ring[..k];
        let mut centre = scale * (n - 2.0) / n;
        for (s, &f) in (1 + k..).zip(faces) {
            let fv = p.face_vertices(f as usize);
            let m = fv.len();
            if len + m > ROW {
                return false;
            }
            let wf = (scale * ew) / m as f64;
            w[s] = wf;
            let Some(c) = fv.iter().position(|&x| x as usize == v) else {
                return false;
            };
            if let Ok(q) = <&[u32; 4]>::try_from(fv) {
                // A quad: the corner, the ring neighbours either side, the far corner. Each
                // sum takes its terms in face order, as the loop below adds them.
                centre += wf;
                for x in [q[(c + 1) & 3], q[(c + 3) & 3]] {
                    match ring.iter().position(|&r| r == x) {
                        Some(j) => w[1 + j] += wf,
                        None => return false,
                    }
                }
                keys[len] = entry_key(q[(c + 2) & 3], s);
                len += 1;
                continue;
            }
            for (d, &x) in fv.iter().enumerate() {
                // The corner's place after `c` around the face (no division per corner).
                let d = if d >= c { d - c } else { d + m - c };
                if d == 0 {
                    centre += wf;
                } else if d == 1 || d == m - 1 {
                    match ring.iter().position(|&r| r == x) {
                        Some(j) => w[1 + j] += wf,
                        None => return false,
                    }
                } else {
                    keys[len] = entry_key(x, s);
                    len += 1;
                }
            }
        }
        w[0] = centre;
        emit_merged(&mut keys[..len], &w[..1 + k + faces.len()], out)
    }

    /// The smooth edge point of a Catmull-Clark edge, merged: its ends (the edge term, then
    /// each face's share) and the other corners of its faces.
    fn smooth_edge_merged(&self, e: usize, out: &mut RowOut) -> bool {
        let p = self.p;
        if is_sharp(self.es[e]) {
            return false;
        }
        let [a, b] = p.edge_verts[e];
        let pair = p.edge_faces[e];
        if pair[1] != INVALID && quad_edge_row(p, a, b, pair, out) {
            return true;
        }
        let faces = p.edge_face_list(e);
        // As `smooth_edge(e, 1.0)` computes them. Weight slots: the two ends, then each face's
        // share at its other corners.
        let scale = 1.0f64;
        let (vw, fw) = self.catmark_edge_weights(faces);
        let mut w = [scale * vw, scale * vw, 0.0, 0.0];
        // Long enough for two octagons.
        let mut keys = [0u64; 16];
        keys[0] = entry_key(a, 0);
        keys[1] = entry_key(b, 1);
        let mut len = 2;
        for (s, &f) in (2..).zip(faces) {
            let fv = p.face_vertices(f as usize);
            if len + fv.len() > keys.len() {
                return false;
            }
            let wf = (scale * fw) / fv.len() as f64;
            w[s] = wf;
            for &x in fv {
                if x == a {
                    w[0] += wf;
                } else if x == b {
                    w[1] += wf;
                } else {
                    keys[len] = entry_key(x, s);
                    len += 1;
                }
            }
        }
        emit_merged(&mut keys[..len], &w[..2 + faces.len()], out)
    }

    fn vertex_vertex(&self, v: usize, out: &mut Vec<(u32, f64)>) {
        let p = self.p;
        let edges = p.vertex_edges(v);
        if self.scheme == Scheme::Bilinear || edges.is_empty() {
            out.push((v as u32, 1.0));
            return;
        }
        let es = self.es;
        let pvs = self.vs[v];
        let sharp_count = edges.iter().filter(|&&e| is_sharp(es[e as usize])).count();
        let p_rule = vertex_rule(pvs, sharp_count);
        if matches!(p_rule, Rule::Smooth | Rule::Dart) {
            self.smooth_vertex(v, 1.0, out);
            return;
        }
        let parent_edges: Vec<f32> = edges.iter().map(|&e| es[e as usize]).collect();
        let child_edges: Vec<f32> = edges
            .iter()
            .map(|&e| self.child_edge_sharpness[child_edge_at(p, e, v as u32) as usize])
            .collect();
        let cvs = self.child_vertex_sharpness[v];
        let c_rule = vertex_rule(cvs, child_edges.iter().filter(|&&s| is_sharp(s)).count());
        if c_rule == p_rule {
            self.sharp_vertex(v, p_rule, &parent_edges, 1.0, out);
            return;
        }
        let pw = fractional_weight(
            self.options.crease_method,
            pvs,
            cvs,
            &parent_edges,
            &child_edges,
        ) as f64;
        self.sharp_vertex(v, p_rule, &parent_edges, pw, out);
        match c_rule {
            Rule::Smooth | Rule::Dart => self.smooth_vertex(v, 1.0 - pw, out),
            r => self.sharp_vertex(v, r, &child_edges, 1.0 - pw, out),
        }
    }

    /// Crease (3/4, 1/8, 1/8 along the two sharp edges) or corner (the vertex itself).
    fn sharp_vertex(
        &self,
        v: usize,
        rule: Rule,
        sharpness: &[f32],
        scale: f64,
        out: &mut Vec<(u32, f64)>,
    ) {
        if rule == Rule::Crease {
            let p = self.p;
            out.push((v as u32, 0.75 * scale));
            for (k, &e) in p.vertex_edges(v).iter().enumerate() {
                if is_sharp(sharpness[k]) {
                    out.push((other_end(p, e, v), 0.125 * scale));
                }
            }
        } else {
            out.push((v as u32, scale));
        }
    }

    fn smooth_vertex(&self, v: usize, scale: f64, out: &mut Vec<(u32, f64)>) {
        let p = self.p;
        let edges = p.vertex_edges(v);
        let n = edges.len() as f64;
        match self.scheme {
            Scheme::Loop => {
                let (vw, ew) = loop_vertex_weights(edges.len());
                out.push((v as u32, scale * vw));
                for &e in edges {
                    out.push((other_end(p, e, v), scale * ew));
                }
            }
            _ => {
                let ew = 1.0 / (n * n);
                out.push((v as u32, scale * (n - 2.0) / n));
                for &e in edges {
                    out.push((other_end(p, e, v), scale * ew));
                }
                for &f in p.vertex_faces(v) {
                    self.face_center(f as usize, scale * ew, out);
                }
            }
        }
    }
}

/// Loop's smooth vertex weights (vertex, each neighbour) for valence `n`.
pub(crate) fn loop_vertex_weights(n: usize) -> (f64, f64) {
    if n == 6 {
        return (0.625, 0.0625);
    }
    let inv = 1.0 / n as f64;
    let beta = 0.25 * (2.0 * std::f64::consts::PI * inv).cos() + 0.375;
    let ew = (0.625 - beta * beta) * inv;
    (1.0 - ew * n as f64, ew)
}

/// Corners of face `f` when it is a quad (inlined: the row fast paths read two to four).
#[inline(always)]
fn quad_of(p: &Topology, f: u32) -> Option<[u32; 4]> {
    let f = f as usize;
    let &[s, t] = p.face_offsets.get(f..f + 2)? else {
        return None;
    };
    if t.wrapping_sub(s) != 4 {
        return None;
    }
    let s = s as usize;
    <[u32; 4]>::try_from(p.face_verts.get(s..s + 4)?).ok()
}

/// The corners of quad `q` other than its edge `a`-`b` (`a` found first), if `b` is beside `a`.
#[inline(always)]
fn quad_far_side(q: [u32; 4], a: u32, b: u32) -> Option<[u32; 2]> {
    let c = q.iter().position(|&x| x == a)?;
    if q[(c + 1) & 3] == b {
        Some([q[(c + 2) & 3], q[(c + 3) & 3]])
    } else if q[(c + 3) & 3] == b {
        Some([q[(c + 1) & 3], q[(c + 2) & 3]])
    } else {
        None
    }
}

/// The smooth edge point of an edge between two quads, merged, sorted in registers: the ends
/// at 1/4 plus one share of 1/16 per face (3/8, exact in any order), the far corners at 1/16,
/// as [`MaskContext::smooth_edge_merged`]'s general rule sums them. `false` (nothing written)
/// when a face is no quad with the edge as a side or an index repeats.
#[inline(always)]
fn quad_edge_row(p: &Topology, a: u32, b: u32, faces: [u32; 2], out: &mut RowOut) -> bool {
    let (Some(q0), Some(q1)) = (quad_of(p, faces[0]), quad_of(p, faces[1])) else {
        return false;
    };
    let (Some([c0, d0]), Some([c1, d1])) = (quad_far_side(q0, a, b), quad_far_side(q1, a, b))
    else {
        return false;
    };
    // Words (index, end or not), so the weight of a sorted entry is read off its low bit.
    let key = |x: u32| u64::from(x) << 32;
    let mut k = [key(a) | 1, key(b) | 1, key(c0), key(d0), key(c1), key(d1)];
    sort6(&mut k);
    if (1..6).any(|j| k[j - 1] >> 32 == k[j] >> 32) {
        return false;
    }
    let idx: [u32; 6] = std::array::from_fn(|j| (k[j] >> 32) as u32);
    let w: [f64; 6] = std::array::from_fn(|j| if k[j] & 1 != 0 { 0.375 } else { 0.0625 });
    out.idx.extend_from_slice(&idx);
    out.wts.extend_from_slice(&w);
    true
}

/// The smooth vertex point of an interior vertex of valence `K` among `K` quads, merged, with
/// its `N = 2K + 1` entries sorted as words (index, class): the weights are
/// [`MaskContext::smooth_vertex_merged`]'s, computed the same way once per row (the centre,
/// each ring neighbour with its two faces' shares, each far corner with one). `false` (nothing
/// written) when a face is no quad, a ring neighbour is not beside exactly two of the faces,
/// or an index repeats.
#[inline(always)]
fn quad_vertex_row<const K: usize, const N: usize>(
    p: &Topology,
    v: usize,
    edges: &[u32],
    faces: &[u32],
    out: &mut RowOut,
) -> bool {
    let (Ok(edges), Ok(faces)) = (<&[u32; K]>::try_from(edges), <&[u32; K]>::try_from(faces))
    else {
        return false;
    };
    let mut ring = [0u32; K];
    let mut keys = [0u64; N];
    keys[0] = u64::from(v as u32) << 32;
    for j in 0..K {
        ring[j] = other_end(p, edges[j], v);
        keys[1 + j] = (u64::from(ring[j]) << 32) | 1;
    }
    // Ring neighbours beside one face so far, and beside two.
    let (mut once, mut twice) = (0u32, 0u32);
    for j in 0..K {
        let Some(q) = quad_of(p, faces[j]) else {
            return false;
        };
        let Some(c) = q.iter().position(|&x| x as usize == v) else {
            return false;
        };
        for x in [q[(c + 1) & 3], q[(c + 3) & 3]] {
            let Some(r) = ring.iter().position(|&y| y == x) else {
                return false;
            };
            let bits = 1u32 << r;
            if twice & bits != 0 {
                return false;
            }
            twice |= once & bits;
            once |= bits;
        }
        keys[1 + K + j] = (u64::from(q[(c + 2) & 3]) << 32) | 2;
    }
    if twice != (1u32 << K) - 1 {
        return false;
    }
    if let Ok(k) = <&mut [u64; 9]>::try_from(&mut keys[..]) {
        sort9(k);
    } else {
        insertion_sort(&mut keys);
    }
    if (1..N).any(|j| keys[j - 1] >> 32 == keys[j] >> 32) {
        return false;
    }
    // As `smooth_vertex(v, 1.0)` and the general rule compute them.
    let scale = 1.0f64;
    let n = K as f64;
    let ew = 1.0 / (n * n);
    let wf = (scale * ew) / 4.0;
    let mut centre = scale * (n - 2.0) / n;
    for _ in 0..K {
        centre += wf;
    }
    let mut side = scale * ew;
    side += wf;
    side += wf;
    let w = [centre, side, wf, wf];
    let mut idx = [0u32; N];
    let mut wts = [0.0f64; N];
    for j in 0..N {
        idx[j] = (keys[j] >> 32) as u32;
        wts[j] = w[keys[j] as usize & 3];
    }
    out.idx.extend_from_slice(&idx);
    out.wts.extend_from_slice(&wts);
    true
}

/// A face point, merged: each corner once at `1 / n` (as `face_center(f, 1.0)`).
fn face_centre_merged(fv: &[u32], out: &mut RowOut) -> bool {
    let w = 1.0 / fv.len() as f64;
    if let Ok(&q) = <&[u32; 4]>::try_from(fv) {
        let mut q = q;
        sort4(&mut q);
        if q[0] == q[1] || q[1] == q[2] || q[2] == q[3] {
            return false;
        }
        out.idx.extend_from_slice(&q);
        out.wts.extend_from_slice(&[w; 4]);
        return true;
    }
    let mut keys = [0u64; 16];
    if fv.len() > keys.len() {
        return false;
    }
    for (slot, &x) in keys.iter_mut().zip(fv) {
        *slot = entry_key(x, 0);
    }
    emit_merged(&mut keys[..fv.len()], &[w], out)
}

/// Sort `$k` with a comparator network (branch-free compare-exchanges, unrolled).
macro_rules! sort_net {
    ($k:expr; $(($i:literal, $j:literal)),* $(,)?) => {
        $(
            let (a, b) = ($k[$i], $k[$j]);
            $k[$i] = a.min(b);
            $k[$j] = a.max(b);
        )*
    };
}

/// Optimal sorting networks for the common row lengths: a face point of a quad (4), a smooth
/// edge point between quads (6), a smooth valence-4 vertex point among quads (9).
#[inline(always)]
fn sort4<T: Copy + Ord>(k: &mut [T; 4]) {
    sort_net!(k; (0, 1), (2, 3), (0, 2), (1, 3), (1, 2));
}

#[inline(always)]
fn sort6<T: Copy + Ord>(k: &mut [T; 6]) {
    sort_net!(k;
        (0, 5), (1, 3), (2, 4), (1, 2), (3, 4), (0, 3),
        (2, 5), (0, 1), (2, 3), (4, 5), (1, 2), (3, 4),
    );
}

#[inline(always)]
fn sort9<T: Copy + Ord>(k: &mut [T; 9]) {
    sort_net!(k;
        (0, 3), (1, 7), (2, 5), (4, 8), (0, 7), (2, 4), (3, 8), (5, 6), (0, 2),
        (1, 3), (4, 5), (7, 8), (1, 4), (3, 6), (5, 7), (0, 1), (2, 4), (3, 5),
        (6, 8), (2, 3), (4, 5), (6, 7), (1, 2), (3, 4), (5, 6),
    );
}

/// Sort a short row's keys ([`entry_key`]).
#[inline]
fn sort_keys(keys: &mut [u64]) {
    if let Ok(k) = <&mut [u64; 6]>::try_from(&mut *keys) {
        sort6(k);
    } else if let Ok(k) = <&mut [u64; 9]>::try_from(&mut *keys) {
        sort9(k);
    } else {
        insertion_sort(keys);
    }
}

/// Append a merged rule's entries ([`entry_key`]) to `out`: by ascending index, with their slot's
/// weight in `w` (every slot used), exact zeros dropped. `false` (nothing written) if an index
/// repeats: the merged rules do not sum repeats, the caller writes the row raw.
#[inline]
fn emit_merged(keys: &mut [u64], w: &[f64], out: &mut RowOut) -> bool {
    sort_keys(keys);
    if keys.windows(2).any(|pair| pair[0] >> 32 == pair[1] >> 32) {
        return false;
    }
    let weight = |key: u64| w[key as u32 as usize];
    if w.contains(&0.0) {
        for &key in keys.iter().filter(|&&key| weight(key) != 0.0) {
            out.idx.push((key >> 32) as u32);
            out.wts.push(weight(key));
        }
    } else {
        out.idx.extend(keys.iter().map(|&key| (key >> 32) as u32));
        out.wts.extend(keys.iter().map(|&key| weight(key)));
    }
    true
}

#[inline]
fn other_end(p: &Topology, e: u32, v: usize) -> u32 {
    let [a, b] = p.edge_verts[e as usize];
    if a as usize == v {
        b
    } else {
        a
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The raw row merged as the row builder's accumulator does: each index's terms summed in
    /// the order the row lists them, indices ascending, exact zeros dropped.
    fn reference_merge(raw: &[(u32, f64)]) -> Vec<(u32, f64)> {
        let mut sums: Vec<(u32, f64)> = Vec::new();
        for &(j, w) in raw {
            match sums.iter_mut().find(|e| e.0 == j) {
                Some(e) => e.1 += w,
                None => sums.push((j, w)),
            }
        }
        sums.sort_by_key(|e| e.0);
        sums.retain(|e| e.1 != 0.0);
        sums
    }

    /// Every child row of two levels: where `row_merged` answers merged, its row is the raw
    /// row's merge, bit for bit; where it does not, it wrote the raw row. Returns how many
    /// rows took each path.
    fn check_merged_rows(mesh: &ControlMesh) -> (usize, usize) {
        let (mut fast, mut raw) = (0, 0);
        let mut level = Level::from_mesh(mesh, Scheme::CatmullClark).unwrap();
        for _ in 0..2 {
            let p = &level.topology;
            let (edge_sharpness, vertex_sharpness) = child_sharpness(
                p,
                &level.edge_sharpness,
                &level.vertex_sharpness,
                Scheme::CatmullClark,
                &mesh.options,
            );
            let ctx = MaskContext {
                p,
                es: &level.edge_sharpness,
                vs: &level.vertex_sharpness,
                scheme: Scheme::CatmullClark,
                options: &mesh.options,
                child_edge_sharpness: &edge_sharpness,
                child_vertex_sharpness: &vertex_sharpness[..p.num_vertices()],
            };
            let (mut a, mut b) = (Vec::new(), Vec::new());
            let (mut idx, mut wts) = (Vec::new(), Vec::new());
            for i in 0..vertex_sharpness.len() {
                a.clear();
                b.clear();
                idx.clear();
                wts.clear();
                ctx.row(i, &mut b);
                let mut out = RowOut {
                    raw: &mut a,
                    idx: &mut idx,
                    wts: &mut wts,
                };
                if ctx.row_merged(i, &mut out) {
                    assert!(a.is_empty(), "row {i}");
                    let a: Vec<(u32, f64)> = idx.iter().copied().zip(wts.iter().copied()).collect();
                    let want = reference_merge(&b);
                    assert_eq!(a.len(), want.len(), "row {i}");
                    for (x, y) in a.iter().zip(&want) {
                        assert_eq!((x.0, x.1.to_bits()), (y.0, y.1.to_bits()), "row {i}");
                    }
                    fast += 1;
                } else {
                    assert!(idx.is_empty() && wts.is_empty(), "row {i}");
                    assert_eq!(a, b, "row {i}");
                    raw += 1;
                }
            }
            level = refine_level(&level, Scheme::CatmullClark, &mesh.options)
                .unwrap()
                .0;
        }
        (fast, raw)
    }

    /// The networks sort every sequence of zeros and ones, and so every sequence.
    #[test]
    fn sorting_networks_sort() {
        fn check<const N: usize>(sort: fn(&mut [u64; N])) {
            for bits in 0..1u32 << N {
                let mut k: [u64; N] = std::array::from_fn(|i| u64::from(bits >> i & 1));
                sort(&mut k);
                assert!(k.windows(2).all(|p| p[0] <= p[1]), "{N} {bits:b}");
            }
        }
        check(sort4);
        check(sort6);
        check(sort9);
    }

    #[test]
    fn merged_rows_are_the_raw_rows_merged() {
        let dir = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/data/opensubdiv/shapes/"
        );
        let mut fast = 0;
        for name in [
            "catmark_xord_interior",
            "catmark_xord_boundary",
            "catmark_cube_creases1",
            "catmark_dart_edgeonly",
            "catmark_chaikin1",
            "catmark_hole_test2",
            "catmark_pyramid",
            "catmark_tent_creases1",
            "catmark_flap2",
        ] {
            let mesh = crate::mesh::obj::load_obj(format!("{dir}{name}.obj")).unwrap();
            fast += check_merged_rows(&mesh).0;
        }
        assert!(fast > 1000, "the merged rules ran on {fast} rows");
        // Two quads glued along all four edges: each vertex's two faces share its diagonal
        // (a repeated index the merged rules refuse), so those rows take the raw path.
        let pillow = ControlMesh::from_polygons(
            vec![[0., 0., 0.], [1., 0., 0.], [1., 1., 0.], [0., 1., 0.]],
            &[[0u32, 1, 2, 3], [3, 2, 1, 0]],
        );
        let (_, raw) = check_merged_rows(&pillow);
        assert!(raw > 0, "the pillow's vertex rows fall back to the raw row");
    }

    /// The quad steps' directly written child adjacency (edge faces, vertex incidence) is
    /// what [`Topology::from_parts`] derives from the child's faces, list order included:
    /// sparse steps of both regions over three levels, from base and uniformly refined
    /// parents, on meshes with n-gons, boundaries, holes and triangles.
    #[test]
    fn sparse_child_adjacency_is_from_parts() {
        let dir = concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../tests/data/opensubdiv/shapes/"
        );
        let same = |t: &Topology| {
            let g = Topology::from_parts(
                t.num_vertices,
                t.face_offsets.clone(),
                t.face_verts.clone(),
                t.face_edges.clone(),
                t.edge_verts.clone(),
            );
            assert_eq!(t.edge_faces, g.edge_faces);
            assert_eq!(t.vert_edge_offsets, g.vert_edge_offsets);
            assert_eq!(t.vert_edges, g.vert_edges);
            assert_eq!(t.vert_face_offsets, g.vert_face_offsets);
            assert_eq!(t.vert_faces, g.vert_faces);
        };
        for name in [
            "catmark_xord_interior",
            "catmark_xord_boundary",
            "catmark_hole_test2",
            "catmark_pyramid",
            "catmark_flap2",
            "catmark_car",
            "catmark_bishop",
            "catmark_hole_test3",
        ] {
            let mesh = crate::mesh::obj::load_obj(format!("{dir}{name}.obj")).unwrap();
            let base = LevelTopology::from_mesh(&mesh, Scheme::CatmullClark).unwrap();
            let uniform = refine_level(
                &Level::from_mesh(&mesh, Scheme::CatmullClark).unwrap(),
                Scheme::CatmullClark,
                &mesh.options,
            )
            .unwrap()
            .0;
            for region in [SparseRegion::OneRingFaces, SparseRegion::SelectedCorners] {
                for (start, stride) in [(0usize, 7usize), (3, 2), (1, 29)] {
                    let mut level = base.clone();
                    for step in 0..3 {
                        let parent = if step == 0 && start == 3 {
                            uniform.view()
                        } else {
                            level.view()
                        };
                        let selected: Vec<u32> = (start..parent.topology.num_faces())
                            .step_by(stride)
                            .map(|f| f as u32)
                            .collect();
                        let r = refine_sparse_region(
                            parent,
                            Scheme::CatmullClark,
                            &mesh.options,
                            &selected,
                            region,
                        )
                        .unwrap();
                        same(&r.child.topology);
                        level = r.child;
                    }
                }
            }
        }
    }
}
