//! Exact limit evaluation at any `(face, u, v)` of a Loop or Catmull-Clark control mesh.
//!
//! Parametric domains are those of [`crate::limit::basis`] (Loop: `P = v0·(1−u−v) + v1·u + v2·v`;
//! Catmull-Clark: unit square, `v0=(0,0)`, `v1=(1,0)`, `v2=(1,1)`, `v3=(0,1)`).
//!
//! Method (Stam-free, recursion on local neighbourhoods):
//! 1. take the face and every face touching one of its vertices (the one-ring of the face —
//!    exactly the support of the limit surface over the face);
//! 2. if the face is a regular patch (all corners regular smooth, or regular boundary/crease
//!    corners whose missing half is replaced by phantom points, or a Catmull-Clark regular
//!    corner), evaluate the box spline / bicubic B-spline in closed form;
//! 3. if `(u, v)` is exactly a corner, apply the vertex's limit masks ([`crate::limit::masks`]) as soon
//!    as no semi-sharp feature remains there;
//! 4. otherwise refine the face and its one-ring once with the crate's one refiner
//!    ([`crate::refine::refine_sparse`]: OpenSubdiv rules, semi-sharp creases included), pick
//!    the child face containing the point, and repeat on it.
//!
//! This module has no subdivision rule of its own: sharpness tests and rules come from
//! [`crate::rules`], refinement and its masks from [`crate::refine`], and the level type is the
//! refiner's [`LevelTopology`]; [`LocalMesh`] only adds per-vertex data of any dimension (3
//! for geometry, one per basis function for tables) and the ordered vertex fans the limit
//! masks and regular patches read.
//!
//! Because the one-ring of a face refines into a superset of the one-ring of each child face,
//! the local refinement is exact. At dyadic parameters the recursion ends after at most
//! `level + 1` steps on a corner or a regular patch, so results are exact to rounding.
//! Derivatives `du`, `dv` are parametric (exact on regular patches, including regular vertices).
//! Exactly at an extraordinary, crease or corner vertex, where parametric derivatives vanish or
//! diverge, they are built from the limit tangent masks as the tangents toward the face's
//! neighbouring corners (exact directions; `du × dv` is the outward normal; magnitudes are
//! OpenSubdiv's, scaled to match the regular case for smooth vertices).
//!
//! Holes are evaluated like ordinary faces; Loop needs triangles, Catmull-Clark quads (use
//! [`LocalMesh::evaluate_subface`] for other faces).

use std::fmt;

use crate::error::{number, TopologyError};
use crate::limit::basis::{catmark_regular_weights, loop_regular_weights};
use crate::limit::masks::{
    catmark_limit_masks, loop_limit_masks, loop_smooth_tangent_weights, smooth_directional_tangent,
    LimitRule, LimitVertex,
};
use crate::mesh::{ControlMesh, Topology, INVALID};
use crate::refine::{refine_sparse, Level, LevelTopology};
use crate::rules::options::SubdivOptions;
use crate::rules::{is_infinite, is_semi_sharp, is_sharp, vertex_rule, Rule, Scheme};

/// The schemes with a limit surface here: a restricted view of [`Scheme`], parsed by
/// [`Scheme`]'s one parser.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum LimitScheme {
    Loop,
    CatmullClark,
}

impl LimitScheme {
    /// The refinement scheme.
    pub fn scheme(self) -> Scheme {
        match self {
            LimitScheme::Loop => Scheme::Loop,
            LimitScheme::CatmullClark => Scheme::CatmullClark,
        }
    }

    /// Corners of the faces this scheme evaluates directly.
    fn face_size(self) -> usize {
        match self {
            LimitScheme::Loop => 3,
            LimitScheme::CatmullClark => 4,
        }
    }
}

impl TryFrom<Scheme> for LimitScheme {
    type Error = EvalError;
    fn try_from(scheme: Scheme) -> Result<LimitScheme, EvalError> {
        match scheme {
            Scheme::Loop => Ok(LimitScheme::Loop),
            Scheme::CatmullClark => Ok(LimitScheme::CatmullClark),
            other => Err(EvalError::NoLimitEvaluation { scheme: other }),
        }
    }
}

impl std::str::FromStr for LimitScheme {
    type Err = EvalError;
    fn from_str(s: &str) -> Result<Self, EvalError> {
        LimitScheme::try_from(s.parse::<Scheme>()?)
    }
}

/// Why a limit evaluation (or a table built from it) could not be done.
#[derive(Debug, thiserror::Error)]
pub enum EvalError {
    #[error("face {face} out of range (the mesh has {count} faces)")]
    FaceOutOfRange { face: usize, count: usize },
    /// A Doo-Sabin domain point's corner ([`crate::limit::doo_sabin_eval`]).
    #[error("corner {corner} out of range: face {face} has {size} corners")]
    CornerOutOfRange {
        face: usize,
        corner: usize,
        size: usize,
    },
    /// The Doo-Sabin child of a corner without the four faces of a domain square (a
    /// neighbourhood the dual refiner should have refused).
    #[error("the Doo-Sabin child of face {face}'s corner {corner} does not have four faces")]
    NoDomainSquare { face: usize, corner: usize },
    #[error("parameter ({}, {}) outside the face domain", number(*.u), number(*.v))]
    ParamOutOfRange { u: f64, v: f64 },
    #[error("face {face} has {size} corners; {} evaluation needs {need}", scheme.scheme())]
    FaceSize {
        face: usize,
        size: usize,
        scheme: LimitScheme,
        need: usize,
    },
    #[error("sub-face {sub} out of range: face {face} has {size} corners")]
    SubfaceOutOfRange {
        face: usize,
        sub: usize,
        size: usize,
    },
    #[error("sub-faces are a Catmull-Clark parameterisation; {} has none", scheme.scheme())]
    SubfaceNeedsCatmullClark { scheme: LimitScheme },
    #[error("{scheme} has no limit evaluation here (use loop, catmull-clark or doo-sabin)")]
    NoLimitEvaluation { scheme: Scheme },
    #[error("{count} values are not {dim} per vertex for {vertices} vertices")]
    PointCount {
        count: usize,
        dim: usize,
        vertices: usize,
    },
    #[error("vertex {vertex} belongs to no face: it has no limit position")]
    IsolatedVertex { vertex: u32 },
    #[error("evaluation of face {face} at ({}, {}) did not converge", number(*.u), number(*.v))]
    NotConverged { face: usize, u: f64, v: f64 },
    /// A basis-function table key (`patches::bft::BftKey`, in its `Debug` form) that names
    /// no table.
    #[error("no basis-function table case {key}")]
    NoBftCase { key: String },
    #[error("BFT level {level} not in 1..=6")]
    BftLevel { level: u32 },
    /// A characteristic map ([`crate::patches::reparam`]) of a valence below 3.
    #[error("a characteristic map needs valence 3 or more, not {valence}")]
    Valence { valence: u32 },
    /// Patch records name a face and a local index in one word ([`crate::patches::bft::Owner`]).
    #[error("{faces} faces after one refinement step; patch records address at most {max}")]
    TooManyPatches { faces: usize, max: usize },
    /// The mesh or a refinement step failed (names the face, edge or vertex at fault).
    #[error(transparent)]
    Topology(#[from] TopologyError),
}

/// Ordered neighbourhood of one vertex: faces CCW with the vertex's corner index in each, the
/// edge-neighbours `ring[i]` = the vertex after the centre in face `i` (plus the last boundary
/// neighbour for a boundary fan) and the edge to each ring vertex.
#[derive(Clone, Debug, Default)]
struct Fan {
    faces: Vec<(u32, u32)>,
    ring: Vec<u32>,
    edges: Vec<u32>,
    boundary: bool,
    /// All incident faces were reached; false on the border of a refined region, where a
    /// vertex may keep several unconnected fans.
    complete: bool,
}

/// Walks the fan of `v` in `t`: it starts at the face whose edge leaving `v` is a boundary
/// edge, else at the lowest-numbered face, and turns across the edge entering `v` in each face.
/// `visit(face, corner, ring vertex, edge)` runs per face, then once more with face
/// [`INVALID`] for the last neighbour of a fan that ends on a boundary edge. Returns
/// (boundary, complete).
fn walk_fan(t: &Topology, v: u32, mut visit: impl FnMut(u32, u32, u32, u32)) -> (bool, bool) {
    let vf = t.vertex_faces(v as usize);
    let Some(&first) = vf.first() else {
        return (false, true);
    };
    let corner = |g: u32| {
        t.face_vertices(g as usize)
            .iter()
            .position(|&x| x == v)
            .unwrap_or(0)
    };
    let start = vf
        .iter()
        .copied()
        .find(|&g| t.is_boundary_edge(t.face_edge_list(g as usize)[corner(g)] as usize))
        .unwrap_or(first);
    let boundary = t.is_boundary_edge(t.face_edge_list(start as usize)[corner(start)] as usize);
    let mut count = 0;
    let mut g = start;
    loop {
        let c = corner(g);
        let fv = t.face_vertices(g as usize);
        let fe = t.face_edge_list(g as usize);
        let n = fv.len();
        visit(g, c as u32, fv[(c + 1) % n], fe[c]);
        count += 1;
        let entering = fe[(c + n - 1) % n];
        let [a, b] = t.edge_faces(entering as usize);
        let h = if a == g { b } else { a };
        if h == INVALID {
            visit(INVALID, 0, fv[(c + n - 1) % n], entering);
            break;
        }
        if h == start || count >= vf.len() {
            break;
        }
        g = h;
    }
    (boundary, count == vf.len())
}

/// The fan of `v` in `t` ([`walk_fan`]).
fn build_fan(t: &Topology, v: u32) -> Fan {
    let mut fan = Fan::default();
    let (boundary, complete) = walk_fan(t, v, |g, c, w, e| {
        if g != INVALID {
            fan.faces.push((g, c));
        }
        fan.ring.push(w);
        fan.edges.push(e);
    });
    fan.boundary = boundary;
    fan.complete = complete;
    fan
}

/// Every vertex's fan ([`walk_fan`]) flattened: faces and rings in one array each, with offsets
/// (three `Vec`s per vertex cost a 1M-triangle mesh 2M × 3 allocations and ~400 MB at level
/// 1). Corner indices and edges are not stored: [`Fans::fan`] finds them in the topology.
#[derive(Clone, Debug, Default)]
struct Fans {
    /// Faces of `v`: `faces[face_start[v]..face_start[v + 1]]`, CCW.
    face_start: Vec<u32>,
    faces: Vec<u32>,
    /// Edge-neighbours of `v`: `ring[ring_start[v]..ring_start[v + 1]]` (one more than its
    /// faces where the fan ends on a boundary edge).
    ring_start: Vec<u32>,
    ring: Vec<u32>,
    /// Per vertex: bit 0 boundary, bit 1 complete.
    flags: Vec<u8>,
}

const FAN_BOUNDARY: u8 = 1;
const FAN_COMPLETE: u8 = 2;

impl Fans {
    /// The fans of `vertices`, offsets starting at 0 (one past the end at each vertex).
    fn build_range(t: &Topology, vertices: std::ops::Range<usize>) -> Fans {
        let mut out = Fans::default();
        for v in vertices {
            let (faces, ring) = (&mut out.faces, &mut out.ring);
            let (boundary, complete) = walk_fan(t, v as u32, |g, _, w, _| {
                if g != INVALID {
                    faces.push(g);
                }
                ring.push(w);
            });
            out.face_start.push(out.faces.len() as u32);
            out.ring_start.push(out.ring.len() as u32);
            out.flags.push(
                if boundary { FAN_BOUNDARY } else { 0 } | if complete { FAN_COMPLETE } else { 0 },
            );
        }
        out
    }

    /// The fans of every vertex of `t`, in parallel blocks on large levels.
    fn build(t: &Topology) -> Fans {
        const BLOCK: usize = 1 << 15;
        let n = t.num_vertices();
        let blocks: Vec<Fans> = if n <= BLOCK {
            vec![Fans::build_range(t, 0..n)]
        } else {
            use rayon::prelude::*;
            (0..n.div_ceil(BLOCK))
                .into_par_iter()
                .map(|b| Fans::build_range(t, b * BLOCK..((b + 1) * BLOCK).min(n)))
                .collect()
        };
        let faces: usize = blocks.iter().map(|b| b.faces.len()).sum();
        let ring: usize = blocks.iter().map(|b| b.ring.len()).sum();
        let mut all = Fans {
            face_start: Vec::with_capacity(n + 1),
            faces: Vec::with_capacity(faces),
            ring_start: Vec::with_capacity(n + 1),
            ring: Vec::with_capacity(ring),
            flags: Vec::with_capacity(n),
        };
        all.face_start.push(0);
        all.ring_start.push(0);
        for b in blocks {
            let (fb, rb) = (all.faces.len() as u32, all.ring.len() as u32);
            all.face_start.extend(b.face_start.iter().map(|&o| fb + o));
            all.ring_start.extend(b.ring_start.iter().map(|&o| rb + o));
            all.faces.extend_from_slice(&b.faces);
            all.ring.extend_from_slice(&b.ring);
            all.flags.extend_from_slice(&b.flags);
        }
        all
    }

    fn faces(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.faces[self.face_start[v] as usize..self.face_start[v + 1] as usize]
    }

    fn ring(&self, v: u32) -> &[u32] {
        let v = v as usize;
        &self.ring[self.ring_start[v] as usize..self.ring_start[v + 1] as usize]
    }

    fn boundary(&self, v: u32) -> bool {
        self.flags[v as usize] & FAN_BOUNDARY != 0
    }

    fn complete(&self, v: u32) -> bool {
        self.flags[v as usize] & FAN_COMPLETE != 0
    }

    /// The edge from `v` to its ring vertex `i` (the edge leaving `v` in face `i`, or the edge
    /// entering `v` in the last face for the extra neighbour of a boundary fan).
    fn edge(&self, t: &Topology, v: u32, i: usize) -> u32 {
        let faces = self.faces(v);
        let (g, leaving) = match faces.get(i) {
            Some(&g) => (g, true),
            None => (faces[faces.len() - 1], false),
        };
        let fv = t.face_vertices(g as usize);
        let c = fv.iter().position(|&x| x == v).unwrap_or(0);
        let n = fv.len();
        t.face_edge_list(g as usize)[if leaving { c } else { (c + n - 1) % n }]
    }

    /// The fan of `v` as [`build_fan`] makes it.
    fn fan(&self, t: &Topology, v: u32) -> Fan {
        let faces = self.faces(v);
        let ring = self.ring(v);
        Fan {
            faces: faces
                .iter()
                .map(|&g| {
                    let c = t
                        .face_vertices(g as usize)
                        .iter()
                        .position(|&x| x == v)
                        .unwrap_or(0);
                    (g, c as u32)
                })
                .collect(),
            ring: ring.to_vec(),
            edges: (0..ring.len()).map(|i| self.edge(t, v, i)).collect(),
            boundary: self.boundary(v),
            complete: self.complete(v),
        }
    }
}

/// A polygon mesh level with points of any dimension: the working set of the evaluator and of
/// the basis-function-table generator. Topology and sharpness are the refiner's
/// [`LevelTopology`]; this view adds the points and the ordered vertex fans.
#[derive(Clone, Debug)]
pub struct LocalMesh {
    pub scheme: LimitScheme,
    /// Boundary interpolation, crease method and triangle rule the refiner applies.
    pub options: SubdivOptions,
    pub level: LevelTopology,
    /// Dimension of each point (3 for geometry; the number of basis functions for tables).
    pub dim: usize,
    /// `dim` values per vertex.
    pub points: Vec<f64>,
    fans: Fans,
}

/// Limit position and first derivatives (any dimension).
#[derive(Clone, Debug, PartialEq)]
pub struct LimitSample {
    pub position: Vec<f64>,
    pub du: Vec<f64>,
    pub dv: Vec<f64>,
}

fn axpy(out: &mut [f64], w: f64, x: &[f64]) {
    for (o, v) in out.iter_mut().zip(x) {
        *o += w * v;
    }
}

/// `dim` values for each of `vertices` vertices.
fn check_point_count(points: &[f64], dim: usize, vertices: usize) -> Result<(), EvalError> {
    if points.len() == vertices * dim {
        Ok(())
    } else {
        Err(EvalError::PointCount {
            count: points.len(),
            dim,
            vertices,
        })
    }
}

fn flatten(positions: &[[f64; 3]]) -> Vec<f64> {
    positions.iter().flat_map(|p| p.iter().copied()).collect()
}

impl LocalMesh {
    /// A view of `level` with `dim` values per vertex in `points`.
    pub fn from_level(
        level: LevelTopology,
        scheme: LimitScheme,
        options: SubdivOptions,
        dim: usize,
        points: Vec<f64>,
    ) -> Result<LocalMesh, EvalError> {
        let vertices = level.topology.num_vertices();
        check_point_count(&points, dim, vertices)?;
        let fans = Fans::build(&level.topology);
        Ok(LocalMesh {
            scheme,
            options,
            level,
            dim,
            points,
            fans,
        })
    }

    /// An untagged mesh from flat faces and points (validated like any control mesh; boundary
    /// rules from `options`).
    pub fn from_faces(
        scheme: LimitScheme,
        options: SubdivOptions,
        dim: usize,
        points: Vec<f64>,
        face_offsets: Vec<u32>,
        face_verts: Vec<u32>,
    ) -> Result<LocalMesh, EvalError> {
        let vertices = points.len() / dim.max(1);
        let mut mesh = ControlMesh::from_polygons(vec![[0.0; 3]; vertices], &[] as &[[u32; 3]]);
        mesh.face_offsets = face_offsets;
        mesh.face_vertices = face_verts;
        mesh.options = options;
        let level = LevelTopology::from_mesh(&mesh, scheme.scheme())?;
        LocalMesh::from_level(level, scheme, options, dim, points)
    }

    /// The same mesh carrying other per-vertex data (`dim` values per vertex).
    pub fn with_points(&self, dim: usize, points: Vec<f64>) -> Result<LocalMesh, EvalError> {
        check_point_count(&points, dim, self.num_vertices())?;
        Ok(LocalMesh {
            dim,
            points,
            ..self.clone()
        })
    }

    /// Geometry of a [`ControlMesh`] (holes are refined like ordinary faces).
    pub fn from_control_mesh(mesh: &ControlMesh, scheme: LimitScheme) -> Result<Self, EvalError> {
        let level = LevelTopology::from_mesh(mesh, scheme.scheme())?;
        LocalMesh::from_level(level, scheme, mesh.options, 3, flatten(&mesh.positions))
    }

    /// A level of a uniform refinement (e.g. the level-1 mesh the BFT pipeline starts from).
    pub fn from_refined_level(
        level: &Level,
        scheme: LimitScheme,
        options: &SubdivOptions,
    ) -> Result<Self, EvalError> {
        let topology = LevelTopology {
            topology: level.topology.clone(),
            edge_sharpness: level.edge_sharpness.clone(),
            vertex_sharpness: level.vertex_sharpness.clone(),
        };
        LocalMesh::from_level(topology, scheme, *options, 3, flatten(&level.positions))
    }

    pub fn num_vertices(&self) -> usize {
        self.level.topology.num_vertices()
    }

    pub fn num_faces(&self) -> usize {
        self.level.topology.num_faces()
    }

    pub fn face(&self, f: usize) -> &[u32] {
        self.level.topology.face_vertices(f)
    }

    /// Flat face tables: offsets (len faces + 1) and corner vertices.
    pub fn face_tables(&self) -> (&[u32], &[u32]) {
        self.level.topology.face_tables()
    }

    pub fn point(&self, v: u32) -> &[f64] {
        &self.points[v as usize * self.dim..(v as usize + 1) * self.dim]
    }

    /// True if `v` lies on the mesh boundary.
    pub fn is_boundary_vertex(&self, v: u32) -> bool {
        self.fans.boundary(v)
    }

    /// Edge-neighbours of `v` in CCW order (fan order for boundary vertices).
    pub fn vertex_ring(&self, v: u32) -> &[u32] {
        self.fans.ring(v)
    }

    /// Faces around `v` in CCW order.
    pub fn vertex_faces(&self, v: u32) -> impl Iterator<Item = u32> + '_ {
        self.fans.faces(v).iter().copied()
    }

    /// True if edge `a–b` has a face on one side only (or is no edge).
    pub fn is_boundary_edge(&self, a: u32, b: u32) -> bool {
        let t = &self.level.topology;
        t.find_edge(a, b)
            .is_none_or(|e| t.is_boundary_edge(e as usize))
    }

    /// Sharpness of edge `a–b` (boundary edges are infinitely sharp).
    pub fn edge_sharp(&self, a: u32, b: u32) -> f32 {
        match self.level.topology.find_edge(a, b) {
            Some(e) => self.view().edge_sharp(e),
            None => 0.0,
        }
    }

    /// Vertex sharpness, including OpenSubdiv's "edges and corners" boundary corners.
    pub fn vert_sharp(&self, v: u32) -> f32 {
        self.level.vertex_sharpness[v as usize]
    }

    fn view(&self) -> View<'_> {
        View {
            scheme: self.scheme,
            level: &self.level,
            dim: self.dim,
            points: &self.points,
            fans: Some(&self.fans),
        }
    }

    /// The face and every face touching one of its corners: the face first, then each corner's
    /// fan in CCW order, each face once.
    pub fn neighbourhood_faces(&self, face: usize) -> Vec<u32> {
        let mut faces = vec![face as u32];
        for &v in self.face(face) {
            for f in self.vertex_faces(v) {
                if !faces.contains(&f) {
                    faces.push(f);
                }
            }
        }
        faces
    }

    /// The neighbourhood of [`Self::neighbourhood_faces`] as a mesh of its own (vertices
    /// numbered by first occurrence, so the face's corners come first; sharpness carried
    /// over); the face is face 0 there.
    pub fn face_neighbourhood(&self, face: usize) -> Result<LocalMesh, EvalError> {
        let faces = self.neighbourhood_faces(face);
        let sub = self.level.topology.sub_topology(&faces);
        let level = LevelTopology {
            edge_sharpness: sub
                .edges
                .iter()
                .map(|&e| self.view().edge_sharp(e))
                .collect(),
            vertex_sharpness: sub
                .vertices
                .iter()
                .map(|&v| self.level.vertex_sharpness[v as usize])
                .collect(),
            topology: sub.topology,
        };
        let mut points = Vec::with_capacity(sub.vertices.len() * self.dim);
        for &v in &sub.vertices {
            points.extend_from_slice(self.point(v));
        }
        LocalMesh::from_level(level, self.scheme, self.options, self.dim, points)
    }

    /// Limit position of vertex `v` by its limit mask, if no semi-sharp feature remains and (for
    /// Catmull-Clark smooth vertices) all incident faces are quads.
    pub fn vertex_limit_position(&self, v: u32) -> Option<Vec<f64>> {
        let view = self.view();
        view.vertex_limit(v, &view.fan(v), None).map(|(p, _, _)| p)
    }

    /// Exact limit position of vertex `v`: its limit mask where no semi-sharp feature is left
    /// (and its ring allows one), else the exact evaluator at the vertex's corner of its first
    /// face, which refines only that neighbourhood until the sharpness has decayed. A mask
    /// applied where a semi-sharp crease is left (OpenSubdiv's `PrimvarRefiner::Limit`) treats
    /// it as infinitely sharp and misses the limit.
    pub fn vertex_limit_exact(&self, v: u32) -> Result<Vec<f64>, EvalError> {
        if let Some(p) = self.vertex_limit_position(v) {
            return Ok(p);
        }
        const QUAD: [(f64, f64); 4] = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        const TRIANGLE: [(f64, f64); 3] = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];
        let f = self
            .vertex_faces(v)
            .next()
            .ok_or(EvalError::IsolatedVertex { vertex: v })? as usize;
        let corner = self
            .face(f)
            .iter()
            .position(|&w| w == v)
            .ok_or(EvalError::IsolatedVertex { vertex: v })?;
        let sample = match (self.scheme, self.face(f).len()) {
            (LimitScheme::CatmullClark, 4) => {
                let (a, b) = QUAD[corner];
                self.evaluate(f, a, b)
            }
            // Sub-quad `corner` of an n-gon has the vertex at its (0, 0).
            (LimitScheme::CatmullClark, _) => self.evaluate_subface(f, corner, 0.0, 0.0),
            (LimitScheme::Loop, 3) => {
                let (a, b) = TRIANGLE[corner];
                self.evaluate(f, a, b)
            }
            (LimitScheme::Loop, size) => Err(EvalError::FaceSize {
                face: f,
                size,
                scheme: LimitScheme::Loop,
                need: 3,
            }),
        }?;
        Ok(sample.position)
    }

    /// Loop limit tangent masks of vertex `v` as stencils: control indices `[v, ring…]` and the
    /// weights of `tangent1` and `tangent2` over them (`tangent1 × tangent2` points outward).
    /// For the GPU's limit normals of the once-refined mesh. `None` for Catmull-Clark meshes
    /// and where [`Self::vertex_limit_position`] has no mask.
    pub fn loop_tangent_stencils(&self, v: u32) -> Option<(Vec<u32>, Vec<f64>, Vec<f64>)> {
        let (mut idx, mut t1, mut t2) = (Vec::new(), Vec::new(), Vec::new());
        self.loop_tangent_row(v, &mut idx, &mut t1, &mut t2)
            .then_some((idx, t1, t2))
    }

    /// [`Self::loop_tangent_stencils`] appended to `indices`, `t1` and `t2` (nothing appended
    /// and `false` where that returns `None`). Allocation-free at smooth vertices: it runs per
    /// vertex of a level-1 mesh (2M on a 1M-triangle mesh).
    pub fn loop_tangent_row(
        &self,
        v: u32,
        indices: &mut Vec<u32>,
        t1: &mut Vec<f64>,
        t2: &mut Vec<f64>,
    ) -> bool {
        if self.scheme != LimitScheme::Loop {
            return false;
        }
        let ring = self.fans.ring(v);
        if !self.fans.complete(v) || ring.is_empty() {
            return false;
        }
        let t = &self.level.topology;
        let view = self.view();
        let Some(lv) = limit_rule(
            self.level.vertex_sharpness[v as usize],
            self.fans.boundary(v),
            ring.len(),
            (0..ring.len()).map(|i| view.edge_sharp(self.fans.edge(t, v, i))),
            None,
        ) else {
            return false;
        };
        indices.push(v);
        indices.extend_from_slice(ring);
        if lv.rule == LimitRule::Smooth {
            t1.push(0.0);
            t2.push(0.0);
            for i in 0..ring.len() {
                let (c, s) = loop_smooth_tangent_weights(ring.len(), i);
                t1.push(c);
                t2.push(s);
            }
        } else {
            let masks = loop_limit_masks(&lv);
            for (out, m) in [(t1, &masks.tangent1), (t2, &masks.tangent2)] {
                out.push(m.vertex);
                out.extend_from_slice(&m.edges);
            }
        }
        true
    }

    /// Control points of face `f` as a regular patch (ordering of [`crate::limit::basis`]), or `None`.
    pub fn regular_patch(&self, f: usize) -> Option<Vec<Vec<f64>>> {
        self.view().regular_patch(f)
    }

    /// Exact limit position and parametric derivatives at `(face, u, v)`.
    pub fn evaluate(&self, face: usize, u: f64, v: f64) -> Result<LimitSample, EvalError> {
        if face >= self.num_faces() {
            return Err(EvalError::FaceOutOfRange {
                face,
                count: self.num_faces(),
            });
        }
        let quad = self.scheme == LimitScheme::CatmullClark;
        let size = self.face(face).len();
        let need = self.scheme.face_size();
        if size != need {
            return Err(EvalError::FaceSize {
                face,
                size,
                scheme: self.scheme,
                need,
            });
        }
        let bad = !(u.is_finite() && v.is_finite())
            || u < 0.0
            || v < 0.0
            || if quad {
                u > 1.0 || v > 1.0
            } else {
                u + v > 1.0
            };
        if bad {
            return Err(EvalError::ParamOutOfRange { u, v });
        }
        let mesh = self.face_neighbourhood(face)?;
        evaluate_local(&mesh, mesh.level.clone(), mesh.points.clone(), 0, u, v)
    }

    /// Catmull-Clark faces of any size: `(u, v) ∈ [0,1]²` on sub-quad `sub` of `face` after one
    /// refinement (`[v_sub', e_{sub,sub+1}, face point, e_{sub−1,sub}]`, `v_sub'` at `(0,0)`, the
    /// face point at `(1,1)`), as OpenSubdiv parameterises non-quads. Derivatives are with
    /// respect to the sub-quad's parameters.
    pub fn evaluate_subface(
        &self,
        face: usize,
        sub: usize,
        u: f64,
        v: f64,
    ) -> Result<LimitSample, EvalError> {
        if face >= self.num_faces() {
            return Err(EvalError::FaceOutOfRange {
                face,
                count: self.num_faces(),
            });
        }
        let size = self.face(face).len();
        if self.scheme != LimitScheme::CatmullClark {
            return Err(EvalError::SubfaceNeedsCatmullClark {
                scheme: self.scheme,
            });
        }
        if sub >= size {
            return Err(EvalError::SubfaceOutOfRange { face, sub, size });
        }
        if !(u.is_finite() && v.is_finite() && (0.0..=1.0).contains(&u) && (0.0..=1.0).contains(&v))
        {
            return Err(EvalError::ParamOutOfRange { u, v });
        }
        let nb = self.face_neighbourhood(face)?;
        let r = refine_sparse(nb.level.view(), nb.scheme.scheme(), &nb.options, &[0])?;
        let points = r.stencils.apply_flat(&nb.points, nb.dim);
        let child = r.maps.child_faces(0).start + sub;
        evaluate_local(&nb, r.child, points, child, u, v)
    }

    /// Distance from `p` to the limit surface over one face (or sub-quad `sub` of a non-quad
    /// Catmull-Clark face): Gauss-Newton on the face's parameters from `start`, kept inside the
    /// domain, the least distance seen (so at most the distance at `start`). Approximations
    /// (end caps, single-pass patches) parameterize the surface differently near extraordinary
    /// vertices, so this geometric distance, not the one at the same parameter, says how close
    /// their surface is. A local search: `start` should be the approximation's own parameter.
    pub fn nearest_limit_distance(
        &self,
        face: usize,
        sub: Option<usize>,
        start: [f64; 2],
        p: &[f64],
    ) -> Result<f64, EvalError> {
        let triangle = sub.is_none() && self.scheme == LimitScheme::Loop;
        let clamp = |u: f64, v: f64| {
            let (u, v) = (u.clamp(0.0, 1.0), v.clamp(0.0, 1.0));
            if triangle && u + v > 1.0 {
                let excess = 0.5 * (u + v - 1.0);
                ((u - excess).max(0.0), (v - excess).max(0.0))
            } else {
                (u, v)
            }
        };
        let dot = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(x, y)| x * y).sum::<f64>();
        let (mut u, mut v) = clamp(start[0], start[1]);
        let mut best = f64::MAX;
        for _ in 0..20 {
            let e = match sub {
                Some(sub) => self.evaluate_subface(face, sub, u, v)?,
                None => self.evaluate(face, u, v)?,
            };
            let r: Vec<f64> = e.position.iter().zip(p).map(|(a, b)| a - b).collect();
            best = best.min(dot(&r, &r).sqrt());
            let (aa, ab, bb) = (dot(&e.du, &e.du), dot(&e.du, &e.dv), dot(&e.dv, &e.dv));
            let (ar, br) = (dot(&e.du, &r), dot(&e.dv, &r));
            let det = aa * bb - ab * ab;
            if det.abs() < 1e-300 {
                break;
            }
            (u, v) = clamp(u - (bb * ar - ab * br) / det, v - (aa * br - ab * ar) / det);
        }
        Ok(best)
    }

    /// Exact limit at many parameters of one face: [`Self::evaluate`] when `sub` is `None`,
    /// else [`Self::evaluate_subface`]. The face's neighbourhood is gathered (and for a
    /// sub-face refined once) for all of them, which is most of a single evaluation's cost.
    pub fn evaluate_many(
        &self,
        face: usize,
        sub: Option<usize>,
        params: &[[f64; 2]],
    ) -> Result<Vec<LimitSample>, EvalError> {
        let Some(&[u0, v0]) = params.first() else {
            return Ok(Vec::new());
        };
        // The single evaluations check the face, the sub-face and the first parameter.
        match sub {
            None => self.evaluate(face, u0, v0)?,
            Some(s) => self.evaluate_subface(face, s, u0, v0)?,
        };
        let quad = self.scheme == LimitScheme::CatmullClark;
        for &[u, v] in params {
            let inside = u.is_finite()
                && v.is_finite()
                && u >= 0.0
                && v >= 0.0
                && if quad || sub.is_some() {
                    u <= 1.0 && v <= 1.0
                } else {
                    u + v <= 1.0
                };
            if !inside {
                return Err(EvalError::ParamOutOfRange { u, v });
            }
        }
        let nb = self.face_neighbourhood(face)?;
        let (level, points, start) = match sub {
            None => (nb.level.clone(), nb.points.clone(), 0),
            Some(s) => {
                let r = refine_sparse(nb.level.view(), nb.scheme.scheme(), &nb.options, &[0])?;
                let points = r.stencils.apply_flat(&nb.points, nb.dim);
                (r.child, points, r.maps.child_faces(0).start + s)
            }
        };
        params
            .iter()
            .map(|&[u, v]| evaluate_local(&nb, level.clone(), points.clone(), start, u, v))
            .collect()
    }
}

/// What the limit masks and regular patches read at one level: topology, sharpness, points and
/// (when the whole level is a [`LocalMesh`]) its cached fans.
struct View<'a> {
    scheme: LimitScheme,
    level: &'a LevelTopology,
    dim: usize,
    points: &'a [f64],
    fans: Option<&'a Fans>,
}

impl View<'_> {
    fn face(&self, f: usize) -> &[u32] {
        self.level.topology.face_vertices(f)
    }

    fn point(&self, v: u32) -> &[f64] {
        &self.points[v as usize * self.dim..(v as usize + 1) * self.dim]
    }

    fn fan(&self, v: u32) -> Fan {
        match self.fans {
            Some(f) => f.fan(&self.level.topology, v),
            None => build_fan(&self.level.topology, v),
        }
    }

    /// Sharpness of edge `e`; an edge with one face is infinitely sharp.
    fn edge_sharp(&self, e: u32) -> f32 {
        if self.level.topology.is_boundary_edge(e as usize) {
            crate::rules::boundary_edge_sharpness()
        } else {
            self.level.edge_sharpness[e as usize]
        }
    }

    fn incident_sharpness(&self, fan: &Fan) -> Vec<f32> {
        fan.edges.iter().map(|&e| self.edge_sharp(e)).collect()
    }

    /// Limit rule of `v` if no semi-sharp feature is left there (else `None`: refine first).
    /// Crease ends are oriented so the CCW span `ends[0] → ends[1]` contains face `face`.
    fn limit_vertex(&self, v: u32, fan: &Fan, face: Option<u32>) -> Option<LimitVertex> {
        // An isolated vertex (validation allows them) has an empty ring: no limit point, and
        // the masks would divide by its valence 0.
        if !fan.complete || fan.ring.is_empty() {
            return None;
        }
        let j = face.and_then(|f| fan.faces.iter().position(|&(g, _)| g == f));
        limit_rule(
            self.level.vertex_sharpness[v as usize],
            fan.boundary,
            fan.ring.len(),
            fan.edges.iter().map(|&e| self.edge_sharp(e)),
            j,
        )
    }

    /// Limit position and the two mask tangents (see [`crate::limit::masks`]) of vertex `v`.
    fn vertex_limit(
        &self,
        v: u32,
        fan: &Fan,
        face: Option<u32>,
    ) -> Option<(Vec<f64>, Vec<f64>, Vec<f64>)> {
        let lv = self.limit_vertex(v, fan, face)?;
        let quad = self.scheme == LimitScheme::CatmullClark;
        let masks = if quad {
            if lv.rule != LimitRule::Corner
                && fan
                    .faces
                    .iter()
                    .any(|&(f, _)| self.face(f as usize).len() != 4)
            {
                return None;
            }
            catmark_limit_masks(&lv)
        } else {
            loop_limit_masks(&lv)
        };
        let edges: Vec<&[f64]> = fan.ring.iter().map(|&w| self.point(w)).collect();
        let faces: Vec<&[f64]> = if quad {
            fan.faces
                .iter()
                .map(|&(f, c)| {
                    let fv = self.face(f as usize);
                    self.point(fv[(c as usize + 2) % fv.len()])
                })
                .collect()
        } else {
            Vec::new()
        };
        let fcount = masks.position.faces.len();
        let p = masks
            .position
            .apply(self.point(v), &edges, &faces[..fcount]);
        let t1 = masks
            .tangent1
            .apply(self.point(v), &edges, &faces[..masks.tangent1.faces.len()]);
        let t2 = masks
            .tangent2
            .apply(self.point(v), &edges, &faces[..masks.tangent2.faces.len()]);
        Some((p, t1, t2))
    }

    /// Smooth directional tangent of `v` along its ring neighbour index `k`.
    fn directional(&self, fan: &Fan, k: usize) -> Vec<f64> {
        let n = fan.ring.len();
        let quad = self.scheme == LimitScheme::CatmullClark;
        let (ew, fw) = smooth_directional_tangent(!quad, n, k);
        let mut out = vec![0.0; self.dim];
        for (i, &w) in fan.ring.iter().enumerate() {
            axpy(&mut out, ew[i], self.point(w));
        }
        for (i, &(f, c)) in fan.faces.iter().enumerate().take(fw.len()) {
            let fv = self.face(f as usize);
            axpy(&mut out, fw[i], self.point(fv[(c as usize + 2) % fv.len()]));
        }
        out
    }

    /// Limit at corner `c` of face `f`: position and the face-relative tangents. `D(k)` is the
    /// limit tangent toward ring neighbour `k` (smooth: rotated cos masks, exact at regular
    /// vertices; crease: `cos θ·T_along + sin θ·T_across` with `θ` spread over the sector;
    /// corner: `e_k − v`); `du`, `dv` are the combinations a regular patch would give, so
    /// `du × dv` is the outward normal and mirrored faces see swapped `du`/`dv`.
    fn corner_limit(&self, f: usize, c: usize) -> Option<LimitSample> {
        let fv = self.face(f);
        let v = fv[c];
        let fan = self.fan(v);
        let (p, t1, t2) = self.vertex_limit(v, &fan, Some(f as u32))?;
        let lv = self.limit_vertex(v, &fan, Some(f as u32))?;
        let n = fan.ring.len();
        let j = fan.faces.iter().position(|&(g, _)| g == f as u32)?;
        let dir = |k: usize| -> Vec<f64> {
            match lv.rule {
                LimitRule::Smooth | LimitRule::Dart { .. } => self.directional(&fan, k % n),
                LimitRule::Crease { ends } => {
                    let m = ((ends[1] + n - ends[0]) % n).max(1);
                    let th = std::f64::consts::PI * ((k + n - ends[0]) % n) as f64 / m as f64;
                    t1.iter()
                        .zip(&t2)
                        .map(|(a, b)| th.cos() * a + th.sin() * b)
                        .collect()
                }
                LimitRule::Corner => self
                    .point(fan.ring[k % n])
                    .iter()
                    .zip(self.point(v))
                    .map(|(a, b)| a - b)
                    .collect(),
            }
        };
        // Tangents toward the next and previous face vertices.
        let dn = dir(j);
        let dp = dir(j + 1);
        let neg = |x: &[f64]| x.iter().map(|a| -a).collect::<Vec<f64>>();
        let sub = |x: &[f64], y: &[f64]| x.iter().zip(y).map(|(a, b)| a - b).collect::<Vec<f64>>();
        let (du, dv) = if fv.len() == 3 {
            // D(next), D(prev) at v0: (du, dv); at v1: D(v2)=dv−du, D(v0)=−du;
            // at v2: D(v0)=−dv, D(v1)=du−dv, so du = D(v1) − D(v0).
            match c {
                0 => (dn, dp),
                1 => (neg(&dp), sub(&dn, &dp)),
                _ => (sub(&dp, &dn), neg(&dn)),
            }
        } else {
            match c {
                0 => (dn, dp),
                1 => (neg(&dp), dn),
                2 => (neg(&dn), neg(&dp)),
                _ => (dp, neg(&dn)),
            }
        };
        Some(LimitSample {
            position: p,
            du,
            dv,
        })
    }

    /// Sequence of ring positions (Loop: 6 edge-neighbours; Catmull-Clark: 8 interleaved
    /// edge-neighbours and diagonals) around corner `c` of face `f`, starting at the face's
    /// next vertex, with phantoms for regular boundary/crease/corner configurations. `None` if
    /// the corner is not regular.
    fn regular_corner_ring(&self, f: usize, c: usize) -> Option<Vec<Vec<f64>>> {
        let quad = self.scheme == LimitScheme::CatmullClark;
        let fv = self.face(f);
        let v = fv[c];
        let fan = self.fan(v);
        if !fan.complete {
            return None;
        }
        let n = fan.ring.len();
        let vs = self.level.vertex_sharpness[v as usize];
        if is_semi_sharp(vs) {
            return None;
        }
        let inc = self.incident_sharpness(&fan);
        if inc.iter().any(|&s| is_semi_sharp(s)) {
            return None;
        }
        let need = self.scheme.face_size();
        if fan
            .faces
            .iter()
            .any(|&(g, _)| self.face(g as usize).len() != need)
        {
            return None;
        }
        let j = fan.faces.iter().position(|&(g, _)| g == f as u32)?;
        let sharp: Vec<usize> = (0..n).filter(|&i| is_infinite(inc[i])).collect();
        let opp = |i: usize| {
            let (g, cc) = fan.faces[i];
            let gv = self.face(g as usize);
            self.point(gv[(cc as usize + 2) % 4]).to_vec()
        };
        let pt = |w: u32| self.point(w).to_vec();
        let lin = |terms: &[(f64, &[f64])]| {
            let mut o = vec![0.0; self.dim];
            for (w, x) in terms {
                axpy(&mut o, *w, x);
            }
            o
        };
        let center = self.point(v);
        if sharp.is_empty() && !is_sharp(vs) {
            if fan.boundary || n != if quad { 4 } else { 6 } {
                return None;
            }
            let mut seq = Vec::new();
            for k in 0..n {
                let i = (j + k) % n;
                seq.push(pt(fan.ring[i]));
                if quad {
                    seq.push(opp(i));
                }
            }
            return Some(seq);
        }
        if sharp.len() != 2 {
            return None;
        }
        // The sector of faces containing f, bounded by the two sharp edges.
        let nfaces = fan.faces.len();
        let (a, b) = if fan.boundary {
            (0, nfaces)
        } else {
            let (x, y) = (sharp[0], sharp[1]);
            if (j + n - x) % n < (y + n - x) % n {
                (x, y)
            } else {
                (y, x)
            }
        };
        let size = (b + n - a) % n;
        let size = if fan.boundary { nfaces } else { size };
        let ring_at = |i: usize| fan.ring[if fan.boundary { i } else { i % n }];
        let corner_rule = is_sharp(vs);
        let mut seq: Vec<Vec<f64>>;
        if !quad {
            if size != 3 || corner_rule {
                return None;
            }
            let r: Vec<Vec<f64>> = (0..4).map(|k| pt(ring_at(a + k))).collect();
            let p4 = lin(&[(1.0, center), (1.0, &r[3]), (-1.0, &r[2])]);
            let p5 = lin(&[(1.0, center), (1.0, &r[0]), (-1.0, &r[1])]);
            seq = r;
            seq.push(p4);
            seq.push(p5);
        } else if size == 2 && !corner_rule {
            let e0 = pt(ring_at(a));
            let f0 = opp(a % nfaces.max(1));
            let e1 = pt(ring_at(a + 1));
            let f1 = opp((a + 1) % nfaces.max(1));
            let e2 = pt(ring_at(a + 2));
            let p5 = lin(&[(2.0, &e2), (-1.0, &f1)]);
            let p6 = lin(&[(2.0, center), (-1.0, &e1)]);
            let p7 = lin(&[(2.0, &e0), (-1.0, &f0)]);
            seq = vec![e0, f0, e1, f1, e2, p5, p6, p7];
        } else if size == 1 && corner_rule {
            let e0 = pt(ring_at(a));
            let f0 = opp(a % nfaces.max(1));
            let e1 = pt(ring_at(a + 1));
            let p3 = lin(&[(2.0, &e1), (-1.0, &f0)]);
            let p4 = lin(&[(2.0, center), (-1.0, &e0)]);
            let p5 = lin(&[(4.0, center), (-2.0, &e0), (-2.0, &e1), (1.0, &f0)]);
            let p6 = lin(&[(2.0, center), (-1.0, &e1)]);
            let p7 = lin(&[(2.0, &e0), (-1.0, &f0)]);
            seq = vec![e0, f0, e1, p3, p4, p5, p6, p7];
        } else {
            return None;
        }
        // Rotate so the face's next vertex comes first.
        let per = if quad { 2 } else { 1 };
        let shift = ((j + n - a) % n.max(1)) * per;
        let shift = if fan.boundary { (j - a) * per } else { shift };
        let len = seq.len();
        seq.rotate_left(shift % len);
        Some(seq)
    }

    /// Control points of face `f` as a regular patch (ordering of [`crate::limit::basis`]), or `None`.
    fn regular_patch(&self, f: usize) -> Option<Vec<Vec<f64>>> {
        let quad = self.scheme == LimitScheme::CatmullClark;
        let fv = self.face(f);
        let (corner_slots, ring_slots): (&[usize], &[&[usize]]) = if quad {
            if fv.len() != 4 {
                return None;
            }
            (
                &[5, 6, 10, 9],
                &[
                    &[6, 10, 9, 8, 4, 0, 1, 2],
                    &[10, 9, 5, 1, 2, 3, 7, 11],
                    &[9, 5, 6, 7, 11, 15, 14, 13],
                    &[5, 6, 10, 14, 13, 12, 8, 4],
                ],
            )
        } else {
            if fv.len() != 3 {
                return None;
            }
            (
                &[3, 6, 7],
                &[
                    &[6, 7, 4, 1, 0, 2],
                    &[7, 3, 2, 5, 9, 10],
                    &[3, 6, 10, 11, 8, 4],
                ],
            )
        };
        let mut net: Vec<Option<Vec<f64>>> = vec![None; if quad { 16 } else { 12 }];
        for (c, &s) in corner_slots.iter().enumerate() {
            net[s] = Some(self.point(fv[c]).to_vec());
        }
        for (c, slots) in ring_slots.iter().enumerate().take(fv.len()) {
            let seq = self.regular_corner_ring(f, c)?;
            for (k, p) in seq.into_iter().enumerate() {
                let s = slots[k];
                if net[s].is_none() {
                    net[s] = Some(p);
                }
            }
        }
        net.into_iter().collect()
    }
}

/// The limit rule of a vertex of sharpness `vs` with `n` edge-neighbours whose edges have
/// sharpness `inc` (in ring order), or `None` while a semi-sharp feature is left (refine
/// first). Crease ends are oriented so the CCW span `ends[0] → ends[1]` contains fan face `j`
/// (`None`: the span starting at the first sharp edge). Allocation-free: it runs per vertex
/// of a level-1 mesh.
fn limit_rule(
    vs: f32,
    boundary: bool,
    n: usize,
    inc: impl Iterator<Item = f32>,
    j: Option<usize>,
) -> Option<LimitVertex> {
    if is_semi_sharp(vs) {
        return None;
    }
    let mut sharp = [0usize; 2];
    let mut count = 0;
    for (i, s) in inc.enumerate() {
        if is_semi_sharp(s) {
            return None;
        }
        if is_infinite(s) {
            if count < 2 {
                sharp[count] = i;
            }
            count += 1;
        }
    }
    let rule = match vertex_rule(vs, count) {
        Rule::Smooth => LimitRule::Smooth,
        Rule::Dart => LimitRule::Dart { edge: sharp[0] },
        Rule::Crease => {
            let (a, b) = (sharp[0], sharp[1]);
            let ends = if boundary {
                [0, n - 1]
            } else {
                // Face j lies between ring[j] and ring[j+1]: inside the CCW span a → b?
                let j = j.unwrap_or(a);
                if (j + n - a) % n < (b + n - a) % n {
                    [a, b]
                } else {
                    [b, a]
                }
            };
            LimitRule::Crease { ends }
        }
        Rule::Corner => LimitRule::Corner,
    };
    Some(LimitVertex {
        valence: n,
        boundary,
        rule,
    })
}

/// The recursion of [`LocalMesh::evaluate`]: `face` of `level` (whose one-ring is complete,
/// with `points`) holds the point.
fn evaluate_local(
    mesh: &LocalMesh,
    mut level: LevelTopology,
    mut points: Vec<f64>,
    mut face: usize,
    u: f64,
    v: f64,
) -> Result<LimitSample, EvalError> {
    let (scheme, dim) = (mesh.scheme, mesh.dim);
    let quad = scheme == LimitScheme::CatmullClark;
    let (start_face, u0, v0) = (face, u, v);
    let (mut u, mut v) = (u, v);
    let mut jac = [[1.0, 0.0], [0.0, 1.0]];
    // What `points` are relative to (see `recentre`).
    let mut origin = vec![0.0; dim];
    let corners: &[(f64, f64)] = if quad {
        &[(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)]
    } else {
        &[(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)]
    };
    // No f64 parameter needs more than MAX_DEPTH levels (2^-1074 is the smallest; see
    // `snapped`).
    const MAX_DEPTH: usize = 1100;
    for depth in 0..=MAX_DEPTH {
        if depth >= RECENTRE_FROM {
            let v0 = level.topology.face_vertices(face)[0];
            recentre(&mut points, dim, v0, &mut origin);
        }
        (u, v) = snapped(depth, u, v, corners);
        if depth == MAX_DEPTH {
            u = u.round();
            v = v.round();
            if !quad && u + v > 1.0 {
                v = 0.0;
            }
        }
        let view = View {
            scheme,
            level: &level,
            dim,
            points: &points,
            fans: None,
        };
        if let Some(net) = view.regular_patch(face) {
            let (w, wu, wv) = if quad {
                let w = catmark_regular_weights(u, v);
                (w.point.to_vec(), w.du.to_vec(), w.dv.to_vec())
            } else {
                let w = loop_regular_weights(u, v);
                (w.point.to_vec(), w.du.to_vec(), w.dv.to_vec())
            };
            let mut p = vec![0.0; dim];
            let mut du = vec![0.0; dim];
            let mut dv = vec![0.0; dim];
            for (i, x) in net.iter().enumerate() {
                axpy(&mut p, w[i], x);
                axpy(&mut du, wu[i], x);
                axpy(&mut dv, wv[i], x);
            }
            return Ok(chain(shifted(p, &origin), du, dv, &jac));
        }
        if let Some(c) = corners.iter().position(|&(a, b)| a == u && b == v) {
            if let Some(s) = view.corner_limit(face, c) {
                return Ok(chain(shifted(s.position, &origin), s.du, s.dv, &jac));
            }
        }
        let step = refine_sparse(level.view(), scheme.scheme(), &mesh.options, &[face as u32])?;
        let (k, nu, nv, l) = child_of(quad, u, v);
        u = nu;
        v = nv;
        jac = [
            [
                l[0][0] * jac[0][0] + l[0][1] * jac[1][0],
                l[0][0] * jac[0][1] + l[0][1] * jac[1][1],
            ],
            [
                l[1][0] * jac[0][0] + l[1][1] * jac[1][0],
                l[1][0] * jac[0][1] + l[1][1] * jac[1][1],
            ],
        ];
        points = step.stencils.apply_flat(&points, dim);
        face = step.maps.child_faces(face).start + k;
        level = step.child;
    }
    Err(EvalError::NotConverged {
        face: start_face,
        u: u0,
        v: v0,
    })
}

/// The recursion depth from which [`evaluate_local`] keeps its points relative to the face it
/// descends into. Near an extraordinary vertex the points of level `k` lie within about `λ^k`
/// of each other (`λ` the subdominant eigenvalue, 0.4 to 0.9), while their coordinates keep
/// the mesh's magnitude: by level 40 or so their differences, which the tangent masks and the
/// patches' derivative weights take, are below the coordinates' f64 resolution, and the
/// derivatives came out as rounding noise (a normal 45° off at `u = v = 1e-20`, a zero normal
/// further in). Subtracting one point of the face from all of them at each level keeps the
/// differences at full relative precision (every stencil, mask and patch weight sums to 1,
/// their derivative weights to 0, so the shift changes nothing but the rounding). Shallower
/// levels are left alone, so dyadic parameters of the tables' levels evaluate bit for bit as
/// they always did.
const RECENTRE_FROM: usize = 8;

/// `(u, v)` at recursion depth `depth`, snapped to a corner of `corners` when it is there to
/// within what is left of f64's precision. Each level doubles the distance to the corner the
/// point is nearest: from level 56 on, a point within 2^-50 of a corner of its face (2^-106 of
/// the base face's domain) is snapped to it and takes the corner's limit masks; a point further
/// from every corner is followed down until a regular patch holds it (a few levels more).
fn snapped(depth: usize, u: f64, v: f64, corners: &[(f64, f64)]) -> (f64, f64) {
    const SNAP_FROM: usize = 56;
    const SNAP: f64 = 1.0 / (1u64 << 50) as f64;
    if depth < SNAP_FROM {
        return (u, v);
    }
    corners
        .iter()
        .copied()
        .find(|&(a, b)| (u - a).abs() <= SNAP && (v - b).abs() <= SNAP)
        .unwrap_or((u, v))
}

/// Makes `points` (`dim` values each) relative to vertex `v`'s point, adding that point to
/// `origin`, the offset the returned positions get back ([`shifted`]).
fn recentre(points: &mut [f64], dim: usize, v: u32, origin: &mut [f64]) {
    let start = v as usize * dim;
    let Some(centre) = points.get(start..start + dim).map(<[f64]>::to_vec) else {
        return;
    };
    for p in points.chunks_exact_mut(dim) {
        for (x, c) in p.iter_mut().zip(&centre) {
            *x -= c;
        }
    }
    for (o, c) in origin.iter_mut().zip(&centre) {
        *o += c;
    }
}

/// A position of the recentred points, back in the mesh's coordinates.
fn shifted(mut p: Vec<f64>, origin: &[f64]) -> Vec<f64> {
    for (x, o) in p.iter_mut().zip(origin) {
        *x += o;
    }
    p
}

/// Derivatives with respect to the original parameters.
fn chain(p: Vec<f64>, du: Vec<f64>, dv: Vec<f64>, jac: &[[f64; 2]; 2]) -> LimitSample {
    let gu = du
        .iter()
        .zip(&dv)
        .map(|(a, b)| a * jac[0][0] + b * jac[1][0])
        .collect();
    let gv = du
        .iter()
        .zip(&dv)
        .map(|(a, b)| a * jac[0][1] + b * jac[1][1])
        .collect();
    LimitSample {
        position: p,
        du: gu,
        dv: gv,
    }
}

/// Child face (index among the face's children in the refiner's order, see
/// [`crate::refine`]), child parameters and the Jacobian d(u',v')/d(u,v). Catmull-Clark child
/// `i` has its corner 0 at parent corner `i`; Loop child `j < 3` is `[v_j, e_{j,j+1}, e_{j−1,j}]`
/// and child 3 is `[e_01, e_12, e_20]`.
fn child_of(quad: bool, u: f64, v: f64) -> (usize, f64, f64, [[f64; 2]; 2]) {
    if quad {
        if u <= 0.5 && v <= 0.5 {
            (0, 2.0 * u, 2.0 * v, [[2.0, 0.0], [0.0, 2.0]])
        } else if u > 0.5 && v <= 0.5 {
            (1, 2.0 * v, 2.0 * (1.0 - u), [[0.0, 2.0], [-2.0, 0.0]])
        } else if u > 0.5 && v > 0.5 {
            (
                2,
                2.0 * (1.0 - u),
                2.0 * (1.0 - v),
                [[-2.0, 0.0], [0.0, -2.0]],
            )
        } else {
            (3, 2.0 * (1.0 - v), 2.0 * u, [[0.0, -2.0], [2.0, 0.0]])
        }
    } else if u + v <= 0.5 {
        (0, 2.0 * u, 2.0 * v, [[2.0, 0.0], [0.0, 2.0]])
    } else if u >= 0.5 {
        // [v1, e12, e01]: P = v1 + u'·(e12 − v1) + v'·(e01 − v1).
        (1, 2.0 * v, 2.0 * (1.0 - u - v), [[0.0, 2.0], [-2.0, -2.0]])
    } else if v >= 0.5 {
        // [v2, e20, e12].
        (2, 2.0 * (1.0 - u - v), 2.0 * u, [[-2.0, -2.0], [2.0, 0.0]])
    } else {
        // [e01, e12, e20].
        (
            3,
            2.0 * (u + v) - 1.0,
            1.0 - 2.0 * u,
            [[2.0, 2.0], [-2.0, 0.0]],
        )
    }
}

/// Cross product and normalisation (zero if degenerate).
pub fn normal_of(du: &[f64; 3], dv: &[f64; 3]) -> [f64; 3] {
    let n = [
        du[1] * dv[2] - du[2] * dv[1],
        du[2] * dv[0] - du[0] * dv[2],
        du[0] * dv[1] - du[1] * dv[0],
    ];
    let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
    if l > 0.0 {
        [n[0] / l, n[1] / l, n[2] / l]
    } else {
        [0.0; 3]
    }
}

/// A limit point of a 3D surface: what `tessera limit` prints.
#[derive(Clone, Debug, PartialEq)]
pub struct LimitPoint {
    pub scheme: LimitScheme,
    pub face: usize,
    /// Sub-quad of a non-quad Catmull-Clark face (see [`LocalMesh::evaluate_subface`]).
    pub subface: Option<usize>,
    pub u: f64,
    pub v: f64,
    pub position: [f64; 3],
    pub du: [f64; 3],
    pub dv: [f64; 3],
    pub normal: [f64; 3],
}

impl fmt::Display for LimitPoint {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        let v3 = |a: &[f64; 3]| format!("{:.12} {:.12} {:.12}", a[0], a[1], a[2]);
        // 1-based, as the OBJ's `f` lines and every message count faces.
        write!(f, "scheme {} face {}", self.scheme.scheme(), self.face + 1)?;
        if let Some(s) = self.subface {
            write!(f, " subface {s}")?;
        }
        writeln!(f, " uv {} {}", number(self.u), number(self.v))?;
        writeln!(f, "position {}", v3(&self.position))?;
        writeln!(f, "du {}", v3(&self.du))?;
        writeln!(f, "dv {}", v3(&self.dv))?;
        write!(f, "normal {}", v3(&self.normal))
    }
}

fn to3(x: &[f64]) -> [f64; 3] {
    [x[0], x[1], x[2]]
}

/// `tessera limit`: exact limit position, tangents and normal of a control mesh at
/// `(face, u, v)` (face indices of the control mesh itself). Non-quad Catmull-Clark faces need
/// a sub-quad: see [`limit_point_subface`].
pub fn limit_point(
    mesh: &ControlMesh,
    scheme: LimitScheme,
    face: usize,
    u: f64,
    v: f64,
) -> Result<LimitPoint, EvalError> {
    let lm = LocalMesh::from_control_mesh(mesh, scheme)?;
    let s = lm.evaluate(face, u, v)?;
    Ok(to_point(scheme, face, None, u, v, &s))
}

/// [`limit_point`] on sub-quad `sub` of a Catmull-Clark face of any size.
pub fn limit_point_subface(
    mesh: &ControlMesh,
    face: usize,
    sub: usize,
    u: f64,
    v: f64,
) -> Result<LimitPoint, EvalError> {
    let lm = LocalMesh::from_control_mesh(mesh, LimitScheme::CatmullClark)?;
    let s = lm.evaluate_subface(face, sub, u, v)?;
    Ok(to_point(
        LimitScheme::CatmullClark,
        face,
        Some(sub),
        u,
        v,
        &s,
    ))
}

fn to_point(
    scheme: LimitScheme,
    face: usize,
    subface: Option<usize>,
    u: f64,
    v: f64,
    s: &LimitSample,
) -> LimitPoint {
    let (du, dv) = (to3(&s.du), to3(&s.dv));
    LimitPoint {
        scheme,
        face,
        subface,
        u,
        v,
        position: to3(&s.position),
        du,
        dv,
        normal: normal_of(&du, &dv),
    }
}
