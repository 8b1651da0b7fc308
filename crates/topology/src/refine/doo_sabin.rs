//! Doo-Sabin refinement: one child vertex per face corner, and the faces of the dual scheme —
//! an *f-face* per parent face (its corners' children), an *e-face* per interior edge (the four
//! children beside it) and a *v-face* per interior vertex (the children of its corners, in the
//! order of its faces around it).
//!
//! Boundaries follow [`crate::rules::doo_sabin`]'s rule. The step from the control mesh (level 0)
//! adds, after the corners' children, two Chaikin points per boundary edge (`(3a + b) / 4` and
//! `(a + 3b) / 4`), and after the faces above, a strip quad per boundary edge (its face's two
//! children there and its two Chaikin points) and a strip face per boundary vertex (the
//! children of its corners, then the Chaikin points of its last and first boundary edges).
//! Every later step has the topology above (the Chaikin points are the boundary vertices of
//! a refined level, and make no face of their own) and takes each corner's weights from its
//! face's kind, full or strip.
//!
//! [`refine_dual`] also says where each child vertex and face comes from ([`DualVertex`],
//! [`DualFace`]), which is what the vertex patches and the domain points of refined vertices
//! are derived from.
use crate::error::TopologyError;
use crate::mesh::{ControlMesh, Topology, INVALID};
use crate::refine::stencil::{build_rows, StencilTable};
use crate::refine::Level;
use crate::rules::boundary_edge_sharpness;
use crate::rules::doo_sabin::{corner_weights, strip_edge, NotOneBoundaryEdge};

/// Where a child vertex of a Doo-Sabin step comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DualVertex {
    /// The child of corner `corner` of parent face `face`.
    Corner { face: u32, corner: u32 },
    /// A Chaikin point of boundary edge `edge` of the control mesh, next to its end `end`
    /// (`0` or `1`, in [`Topology::edge_vertices`] order): made by the level-0 step only.
    Chaikin { edge: u32, end: u32 },
}

/// Where a child face of a Doo-Sabin step comes from.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum DualFace {
    /// The f-face of a parent face (same corner order).
    Face(u32),
    /// The e-face of an interior parent edge.
    Edge(u32),
    /// The v-face of an interior parent vertex.
    Vertex(u32),
    /// The strip quad of a boundary edge of the control mesh (level-0 step only).
    EdgeStrip(u32),
    /// The strip face of a boundary vertex of the control mesh (level-0 step only).
    VertexStrip(u32),
}

/// One Doo-Sabin step: the child level, its stencils over the parent vertices and the origin
/// of each child vertex and face.
#[derive(Clone, Debug)]
pub struct DualStep {
    pub level: Level,
    pub stencils: StencilTable,
    pub vertices: Vec<DualVertex>,
    pub faces: Vec<DualFace>,
}

/// One Doo-Sabin step of `parent`: from the control mesh when `first` (boundary vertices'
/// faces are halved by the boundary there), else from a refined level (its boundary vertices
/// are the boundary curve's control points).
pub fn refine_dual(parent: &Level, first: bool) -> Result<DualStep, TopologyError> {
    let p = &parent.topology;
    let boundary_points = if first {
        Vec::new()
    } else {
        boundary_vertices(p)
    };
    let (mut faces, mut origins) = interior_faces(p);
    let mut vertices: Vec<DualVertex> = corner_origins(p);
    if first {
        boundary_faces(p, &mut faces, &mut origins, &mut vertices)?;
    }
    let stencils = dual_rows(p, &vertices, &boundary_points)?;
    let positions = stencils.apply(&parent.positions);
    let mesh = ControlMesh::from_polygons(positions.clone(), &faces);
    let topology = Topology::from_mesh(&mesh)?;
    let edge_sharpness = (0..topology.num_edges())
        .map(|e| {
            if topology.is_boundary_edge(e) {
                boundary_edge_sharpness()
            } else {
                0.0
            }
        })
        .collect();
    let vertex_sharpness = vec![0.0; topology.num_vertices()];
    Ok(DualStep {
        level: Level {
            topology,
            positions,
            edge_sharpness,
            vertex_sharpness,
        },
        stencils,
        vertices,
        faces: origins,
    })
}

/// Whether each vertex lies on a boundary edge.
pub fn boundary_vertices(p: &Topology) -> Vec<bool> {
    let mut out = vec![false; p.num_vertices()];
    for e in 0..p.num_edges() {
        if p.is_boundary_edge(e) {
            for v in p.edge_vertices(e) {
                out[v as usize] = true;
            }
        }
    }
    out
}

/// The child vertex of the corner of face `f` at vertex `v` (corners are numbered as the
/// parent's face-vertex table).
pub fn corner_child(p: &Topology, f: u32, v: u32) -> u32 {
    let s = p.face_tables().0[f as usize];
    let i = p
        .face_vertices(f as usize)
        .iter()
        .position(|&x| x == v)
        .unwrap_or(0);
    s + i as u32
}

fn corner_origins(p: &Topology) -> Vec<DualVertex> {
    let mut out = Vec::with_capacity(p.face_tables().1.len());
    for f in 0..p.num_faces() {
        for corner in 0..p.face_vertices(f).len() as u32 {
            out.push(DualVertex::Corner {
                face: f as u32,
                corner,
            });
        }
    }
    out
}

/// The parent face that traverses edge `e` from its first vertex to its second, and the other
/// face (`INVALID` on a boundary).
fn edge_faces_in_order(p: &Topology, e: usize) -> (u32, u32) {
    let [f, g] = p.edge_faces(e);
    let fv = p.face_vertices(f as usize);
    let i = p
        .face_edge_list(f as usize)
        .iter()
        .position(|&x| x == e as u32)
        .unwrap_or(0);
    if fv[i] == p.edge_vertices(e)[0] {
        (f, g)
    } else {
        (g, f)
    }
}

/// The f-faces, the e-faces of interior edges and the v-faces of interior vertices.
fn interior_faces(p: &Topology) -> (Vec<Vec<u32>>, Vec<DualFace>) {
    let (offsets, _) = p.face_tables();
    let mut faces: Vec<Vec<u32>> = Vec::new();
    let mut origins = Vec::new();
    for f in 0..p.num_faces() {
        faces.push((offsets[f]..offsets[f + 1]).collect());
        origins.push(DualFace::Face(f as u32));
    }
    for e in 0..p.num_edges() {
        if p.is_boundary_edge(e) {
            continue;
        }
        let (f, g) = edge_faces_in_order(p, e);
        let [a, b] = p.edge_vertices(e);
        faces.push(vec![
            corner_child(p, f, b),
            corner_child(p, f, a),
            corner_child(p, g, a),
            corner_child(p, g, b),
        ]);
        origins.push(DualFace::Edge(e as u32));
    }
    let boundary = boundary_vertices(p);
    for (v, &on_boundary) in boundary.iter().enumerate() {
        if p.vertex_faces(v).is_empty() || on_boundary {
            continue;
        }
        let ring: Vec<u32> = fan(p, v, p.vertex_faces(v)[0])
            .iter()
            .map(|&f| corner_child(p, f, v as u32))
            .collect();
        faces.push(ring);
        origins.push(DualFace::Vertex(v as u32));
    }
    (faces, origins)
}

/// The faces around `v` from `start`, each the one across the previous face's incoming edge at
/// `v` (the edge from the corner before `v`), until the walk closes or meets a boundary.
pub fn fan(p: &Topology, v: usize, start: u32) -> Vec<u32> {
    let count = p.vertex_faces(v).len();
    let mut out = Vec::with_capacity(count);
    let mut f = start;
    for _ in 0..count {
        out.push(f);
        let fv = p.face_vertices(f as usize);
        let fe = p.face_edge_list(f as usize);
        let i = fv.iter().position(|&x| x == v as u32).unwrap_or(0);
        let e_in = fe[(i + fv.len() - 1) % fv.len()];
        let [x, y] = p.edge_faces(e_in as usize);
        f = if x == f { y } else { x };
        if f == start || f == INVALID {
            break;
        }
    }
    out
}

/// The edge of face `f` leaving its corner at `v` (`outgoing`) or entering it.
fn edge_at(p: &Topology, f: u32, v: u32, outgoing: bool) -> u32 {
    let fv = p.face_vertices(f as usize);
    let fe = p.face_edge_list(f as usize);
    let i = fv.iter().position(|&x| x == v).unwrap_or(0);
    if outgoing {
        fe[i]
    } else {
        fe[(i + fv.len() - 1) % fv.len()]
    }
}

/// The level-0 step's boundary: Chaikin points (appended to `vertices`), strip quads of
/// boundary edges and strip faces of boundary vertices.
fn boundary_faces(
    p: &Topology,
    faces: &mut Vec<Vec<u32>>,
    origins: &mut Vec<DualFace>,
    vertices: &mut Vec<DualVertex>,
) -> Result<(), TopologyError> {
    let mut first_point = vec![INVALID; p.num_edges()];
    for (e, first) in first_point.iter_mut().enumerate() {
        if p.is_boundary_edge(e) {
            *first = vertices.len() as u32;
            for end in 0..2 {
                vertices.push(DualVertex::Chaikin {
                    edge: e as u32,
                    end,
                });
            }
        }
    }
    let point =
        |e: u32, v: u32| first_point[e as usize] + u32::from(p.edge_vertices(e as usize)[1] == v);
    for e in 0..p.num_edges() {
        if !p.is_boundary_edge(e) {
            continue;
        }
        // The face runs along its boundary edge from `a` to `b`.
        let f = p.edge_faces(e)[0];
        let fv = p.face_vertices(f as usize);
        let i = p
            .face_edge_list(f as usize)
            .iter()
            .position(|&x| x == e as u32)
            .unwrap_or(0);
        let (a, b) = (fv[i], fv[(i + 1) % fv.len()]);
        faces.push(vec![
            corner_child(p, f, b),
            corner_child(p, f, a),
            point(e as u32, a),
            point(e as u32, b),
        ]);
        origins.push(DualFace::EdgeStrip(e as u32));
    }
    let boundary = boundary_vertices(p);
    for (v, &on_boundary) in boundary.iter().enumerate() {
        if !on_boundary || p.vertex_faces(v).is_empty() {
            continue;
        }
        let vf = p.vertex_faces(v);
        let Some(&first) = vf
            .iter()
            .find(|&&f| p.is_boundary_edge(edge_at(p, f, v as u32, true) as usize))
        else {
            return Err(TopologyError::NonManifoldVertex {
                vertex: v as u32,
                fans: 2,
            });
        };
        let ring = fan(p, v, first);
        if ring.len() != vf.len() {
            return Err(TopologyError::NonManifoldVertex {
                vertex: v as u32,
                fans: 2,
            });
        }
        let last = *ring.last().unwrap_or(&first);
        let mut strip: Vec<u32> = ring.iter().map(|&f| corner_child(p, f, v as u32)).collect();
        strip.push(point(edge_at(p, last, v as u32, false), v as u32));
        strip.push(point(edge_at(p, first, v as u32, true), v as u32));
        faces.push(strip);
        origins.push(DualFace::VertexStrip(v as u32));
    }
    Ok(())
}

/// The step's stencils: each corner's child by its face's mask (a strip's where the face holds
/// two of `boundary_points`), each Chaikin point from its edge's ends.
fn dual_rows(
    p: &Topology,
    vertices: &[DualVertex],
    boundary_points: &[bool],
) -> Result<StencilTable, TopologyError> {
    let mut strips = vec![None; p.num_faces()];
    if !boundary_points.is_empty() {
        for (f, strip) in strips.iter_mut().enumerate() {
            let fv = p.face_vertices(f);
            *strip = strip_edge(fv.len(), |k| boundary_points[fv[k] as usize])
                .map_err(|NotOneBoundaryEdge| TopologyError::UnsupportedScheme {
                    scheme: "doo-sabin",
                    operation: "a refined level whose face holds boundary points that are not one boundary edge",
                })?;
        }
    }
    Ok(build_rows(vertices.len(), p.num_vertices(), |c, out| {
        let mut w = Vec::new();
        match vertices[c] {
            DualVertex::Corner { face, corner } => {
                let fv = p.face_vertices(face as usize);
                let n = fv.len();
                corner_weights(n, strips[face as usize], corner as usize, &mut w);
                for (k, &wk) in w.iter().enumerate() {
                    out.raw.push((fv[(corner as usize + k) % n], wk));
                }
            }
            DualVertex::Chaikin { edge, end } => {
                let [a, b] = p.edge_vertices(edge as usize);
                let (near, far) = if end == 0 { (a, b) } else { (b, a) };
                out.raw.push((near, 0.75));
                out.raw.push((far, 0.25));
            }
        }
        false
    }))
}

/// [`refine_dual`] as the refiner's uniform step: the level and its stencils.
pub(crate) fn refine_doo_sabin(
    parent: &Level,
    first: bool,
) -> Result<(Level, StencilTable), TopologyError> {
    let step = refine_dual(parent, first)?;
    Ok((step.level, step.stencils))
}

/// Vertices, faces, face corners and boundary edges of one Doo-Sabin level.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct LevelSize {
    pub vertices: u64,
    pub faces: u64,
    pub corners: u64,
    pub boundary_edges: u64,
}

impl LevelSize {
    /// Triangles of the level's faces drawn as fans.
    pub fn triangles(&self) -> u64 {
        self.corners - 2 * self.faces
    }

    /// The next level's size. From level 1 on, every interior point lies in four faces and
    /// every boundary point (a point of the boundary curve's control polygon) in two, every
    /// interior edge makes an e-face (a quad), every interior point a v-face (a quad), every
    /// face an f-face of its own size, and the boundary polygon doubles (Chaikin).
    fn next(&self) -> LevelSize {
        let b = self.boundary_edges;
        let edges = (self.corners + b) / 2;
        let (inner_edges, inner_points) = (edges - b, self.vertices - b);
        LevelSize {
            vertices: self.corners,
            faces: self.faces + inner_edges + inner_points,
            corners: self.corners + 4 * inner_edges + 4 * inner_points,
            boundary_edges: 2 * b,
        }
    }

    /// The size of the level whose topology is `t`.
    pub fn of(t: &Topology) -> LevelSize {
        LevelSize {
            vertices: t.num_vertices() as u64,
            faces: t.num_faces() as u64,
            corners: t.face_tables().1.len() as u64,
            boundary_edges: (0..t.num_edges())
                .filter(|&e| t.is_boundary_edge(e))
                .count() as u64,
        }
    }
}

/// The size of level 1 (one step of the base mesh: made, then counted).
pub fn first_level_size(base: &Level) -> Result<LevelSize, TopologyError> {
    Ok(LevelSize::of(&refine_dual(base, true)?.level.topology))
}

/// Sizes of levels 1..=`depth` from level 1's, the deeper ones counted by the dual scheme's
/// recurrence (every point past level 1 lies in four faces, two on the boundary).
pub fn level_sizes(first: LevelSize, depth: u32) -> Vec<LevelSize> {
    let mut sizes = Vec::with_capacity(depth as usize);
    let mut size = first;
    for _ in 0..depth {
        sizes.push(size);
        size = size.next();
    }
    sizes
}
