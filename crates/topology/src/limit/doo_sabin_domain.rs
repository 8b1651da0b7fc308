//! Where the vertices and faces of refined Doo-Sabin levels lie in the domain of
//! [`crate::limit::doo_sabin_eval`]: the point `(face, corner, u, v)` whose limit each one
//! converges to, so a refined (or GPU-drawn) level can be compared with the exact limit.
//!
//! Every real vertex `w` of level `k ≥ 1` (a child of a face corner) owns a *domain square*, a
//! dyadic sub-square of side `2^(1−k)` of one corner quad, whose corners are the centres of its
//! four faces (in ring order: `(0,0)`, `(1,0)`, `(1,1)`, `(0,1)` of the square). Level 1's
//! squares are the corner quads themselves; a step gives the child of `w` in its face at corner
//! `q` the quadrant `q` of `w`'s square, with that face's f-face at the quadrant's outer
//! corner, the e-faces of the face's two edges at `w` beside it, and `w`'s v-face at the
//! square's centre (the refiner's [`DualVertex`] and [`DualFace`] origins say which is which).
//!
//! - A real vertex's limit ([`crate::limit::doo_sabin_eval::vertex_limits`]) is the limit at its
//!   square's centre.
//! - A boundary point's is the limit at the midpoint of its real neighbour's square side
//!   between the two faces of their edge (on the boundary curve).
//! - A face's centre is the corner of each of its real corners' squares where the face sits.
//! - At level 0, a control vertex is `(f, i, 0, 0)` of a face around it, a face's centre
//!   `(f, 0, 1, 1)`.

use crate::error::TopologyError;
use crate::limit::eval::EvalError;
use crate::mesh::{ControlMesh, Topology, INVALID};
use crate::refine::doo_sabin::{boundary_vertices, fan, refine_dual, DualFace, DualVertex};
use crate::refine::Level;
use crate::rules::Scheme;

/// A point of the Doo-Sabin domain: base face, its corner, and `(u, v)` in the corner's quad.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DomainPoint {
    pub face: u32,
    pub corner: u32,
    pub uv: [f64; 2],
}

/// The domain square of a real vertex of a refined level: in corner `corner` of base face
/// `face`, from `origin` with side `size`; `faces` are the vertex's four faces of its level, at
/// the square's corners `(0,0)`, `(1,0)`, `(1,1)`, `(0,1)` in that order.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct DomainSquare {
    pub face: u32,
    pub corner: u32,
    pub origin: [f64; 2],
    pub size: f64,
    pub faces: [u32; 4],
}

/// The corners of a square, in ring order.
const CORNERS: [[f64; 2]; 4] = [[0.0, 0.0], [1.0, 0.0], [1.0, 1.0], [0.0, 1.0]];

impl DomainSquare {
    /// The point at `(s, t)` of the square.
    pub fn at(&self, s: f64, t: f64) -> DomainPoint {
        DomainPoint {
            face: self.face,
            corner: self.corner,
            uv: [
                self.origin[0] + s * self.size,
                self.origin[1] + t * self.size,
            ],
        }
    }

    /// Corner `j` of the square (the centre of `faces[j]`).
    pub fn corner_point(&self, j: usize) -> DomainPoint {
        let [s, t] = CORNERS[j % 4];
        self.at(s, t)
    }

    /// The square's centre (its vertex's limit).
    pub fn centre(&self) -> DomainPoint {
        self.at(0.5, 0.5)
    }
}

/// A Doo-Sabin refinement of a control mesh to `depth` levels with the domain square of every
/// real vertex of every level (the global refiner's levels: [`refine_dual`], as
/// [`crate::refine::refine_uniform`] makes them).
#[derive(Clone, Debug)]
pub struct DomainRefinement {
    levels: Vec<Level>,
    /// Per level (level 0 has none), per vertex.
    squares: Vec<Vec<Option<DomainSquare>>>,
}

impl DomainRefinement {
    /// Refines `mesh` `depth` times (names what the dual refiner refuses).
    pub fn new(mesh: &ControlMesh, depth: usize) -> Result<Self, EvalError> {
        let base = Level::from_mesh(mesh, Scheme::DooSabin)?;
        let mut levels = vec![base];
        let mut squares = vec![Vec::new()];
        for k in 0..depth {
            let step = refine_dual(&levels[k], k == 0)?;
            let next = if k == 0 {
                first_squares(&step.level.topology, &step.vertices)?
            } else {
                next_squares(
                    &levels[k].topology,
                    &squares[k],
                    &step.vertices,
                    &step.faces,
                )?
            };
            levels.push(step.level);
            squares.push(next);
        }
        Ok(DomainRefinement { levels, squares })
    }

    /// The deepest level.
    pub fn depth(&self) -> usize {
        self.levels.len() - 1
    }

    /// Level `k`.
    pub fn level(&self, k: usize) -> &Level {
        &self.levels[k]
    }

    /// The domain square of vertex `x` of level `k` (`None` at level 0, for boundary points
    /// and out of range).
    pub fn square(&self, k: usize, x: usize) -> Option<DomainSquare> {
        self.squares.get(k)?.get(x).copied().flatten()
    }

    /// Where vertex `x` of level `k` converges to (module doc); `None` for a vertex of no face.
    pub fn vertex_point(&self, k: usize, x: usize) -> Option<DomainPoint> {
        let t = &self.levels.get(k)?.topology;
        if k == 0 {
            let &f = t.vertex_faces(x).first()?;
            let corner = t
                .face_vertices(f as usize)
                .iter()
                .position(|&y| y as usize == x)?;
            return Some(DomainPoint {
                face: f,
                corner: corner as u32,
                uv: [0.0, 0.0],
            });
        }
        if let Some(sq) = self.square(k, x) {
            return Some(sq.centre());
        }
        self.boundary_point(k, x)
    }

    /// A boundary point's: the midpoint of its real neighbour's square side between the two
    /// faces of their edge.
    fn boundary_point(&self, k: usize, x: usize) -> Option<DomainPoint> {
        let t = &self.levels[k].topology;
        t.vertex_edges(x).iter().find_map(|&e| {
            let [a, b] = t.edge_vertices(e as usize);
            let r = if a as usize == x { b } else { a };
            let sq = self.square(k, r as usize)?;
            let [f, g] = t.edge_faces(e as usize);
            let j = sq.faces.iter().position(|&h| h == f)?;
            let i = sq.faces.iter().position(|&h| h == g)?;
            let (p, q) = (CORNERS[j], CORNERS[i]);
            Some(sq.at(0.5 * (p[0] + q[0]), 0.5 * (p[1] + q[1])))
        })
    }

    /// Where the centre of face `g` of level `k` lies.
    pub fn face_point(&self, k: usize, g: usize) -> Option<DomainPoint> {
        let t = &self.levels.get(k)?.topology;
        if g >= t.num_faces() {
            return None;
        }
        if k == 0 {
            return Some(DomainPoint {
                face: g as u32,
                corner: 0,
                uv: [1.0, 1.0],
            });
        }
        t.face_vertices(g).iter().find_map(|&x| {
            let sq = self.square(k, x as usize)?;
            let j = sq.faces.iter().position(|&h| h as usize == g)?;
            Some(sq.corner_point(j))
        })
    }

    /// Whether each vertex of level `k` is a boundary point.
    pub fn boundary_points(&self, k: usize) -> Vec<bool> {
        boundary_vertices(&self.levels[k].topology)
    }
}

/// A level-1 vertex without the four faces of a domain square (a mesh the refiner should have
/// refused).
fn not_four(face: u32, corner: u32) -> EvalError {
    EvalError::NoDomainSquare {
        face: face as usize,
        corner: corner as usize,
    }
}

/// Level 1: each corner child owns its corner quad; its faces from its fan, which starts at the
/// f-face (`[f, e_in, v, e_out]`), rotated to `[v, e_out, f, e_in]`.
fn first_squares(
    t: &Topology,
    vertices: &[DualVertex],
) -> Result<Vec<Option<DomainSquare>>, EvalError> {
    vertices
        .iter()
        .enumerate()
        .map(|(w, o)| match *o {
            DualVertex::Corner { face, corner } => {
                let ring = fan(t, w, face);
                if ring.len() != 4 {
                    return Err(not_four(face, corner));
                }
                Ok(Some(DomainSquare {
                    face,
                    corner,
                    origin: [0.0; 2],
                    size: 1.0,
                    faces: std::array::from_fn(|j| ring[(j + 2) % 4]),
                }))
            }
            DualVertex::Chaikin { .. } => Ok(None),
        })
        .collect()
}

/// The next level's squares: the child of corner `c` of face `F` (the corner at vertex `x`)
/// owns the quadrant of `x`'s square at `F`, with `[f(F), e(edge entering x), v(x), e(edge
/// leaving x)]` from the quadrant's outer corner on.
fn next_squares(
    p: &Topology,
    squares: &[Option<DomainSquare>],
    vertices: &[DualVertex],
    faces: &[DualFace],
) -> Result<Vec<Option<DomainSquare>>, EvalError> {
    let mut v_face = vec![INVALID; p.num_vertices()];
    let mut e_face = vec![INVALID; p.num_edges()];
    for (k, o) in faces.iter().enumerate() {
        match *o {
            DualFace::Vertex(x) => v_face[x as usize] = k as u32,
            DualFace::Edge(e) => e_face[e as usize] = k as u32,
            _ => {}
        }
    }
    let broken =
        |x: u32| -> EvalError { TopologyError::NonManifoldVertex { vertex: x, fans: 2 }.into() };
    vertices
        .iter()
        .map(|o| {
            let DualVertex::Corner { face, corner } = *o else {
                return Ok(None);
            };
            let fv = p.face_vertices(face as usize);
            let (n, c) = (fv.len(), corner as usize);
            let x = fv[c];
            let Some(sq) = squares[x as usize] else {
                return Ok(None);
            };
            let q = sq.faces.iter().position(|&g| g == face).ok_or(broken(x))?;
            let e_in = p.find_edge(fv[(c + n - 1) % n], x).ok_or(broken(x))?;
            let e_out = p.find_edge(x, fv[(c + 1) % n]).ok_or(broken(x))?;
            let order = [
                face,
                e_face[e_in as usize],
                v_face[x as usize],
                e_face[e_out as usize],
            ];
            let mut ring = [INVALID; 4];
            for (k, g) in order.into_iter().enumerate() {
                ring[(q + k) % 4] = g;
            }
            let size = 0.5 * sq.size;
            Ok(Some(DomainSquare {
                origin: [
                    sq.origin[0] + CORNERS[q][0] * size,
                    sq.origin[1] + CORNERS[q][1] * size,
                ],
                size,
                faces: ring,
                ..sq
            }))
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::limit::doo_sabin_eval::{vertex_limits, DooSabinEvaluator};

    /// An open fan of four quads and a triangle around a valence-5 vertex.
    fn fan_mesh() -> ControlMesh {
        let mut positions = vec![[0.0, 0.0, 0.4]];
        for k in 0..5 {
            let a = std::f64::consts::TAU * k as f64 / 5.0;
            positions.push([a.cos(), a.sin(), 0.1 * k as f64]);
            positions.push([1.6 * (a + 0.6).cos(), 1.6 * (a + 0.6).sin(), 0.0]);
        }
        let ring = |k: u32| 1 + k % 10;
        let mut faces: Vec<Vec<u32>> = (0..4)
            .map(|k| vec![0, ring(2 * k), ring(2 * k + 1), ring(2 * k + 2)])
            .collect();
        faces.push(vec![0, ring(8), ring(0)]);
        ControlMesh::from_polygons(positions, &faces)
    }

    #[test]
    fn level_zero_points_are_corners_and_face_centres() {
        let mesh = fan_mesh();
        let ev = DooSabinEvaluator::new(&mesh).unwrap();
        let domains = DomainRefinement::new(&mesh, 2).unwrap();
        assert_eq!(domains.depth(), 2);
        let base = domains.level(0);
        let limits = vertex_limits(base, false).unwrap();
        let at = |p: DomainPoint| {
            ev.evaluate(p.face as usize, p.corner as usize, p.uv[0], p.uv[1])
                .unwrap()
                .position
        };
        for (x, limit) in limits.iter().enumerate().take(base.num_vertices()) {
            let Some(p) = domains.vertex_point(0, x) else {
                // Vertex 10 is on no face.
                assert_eq!(x, 10);
                continue;
            };
            let q = at(p);
            assert!((0..3).all(|c| (q[c] - limit[c]).abs() < 1e-14), "{x}");
        }
        for g in 0..mesh.num_faces() {
            let q = at(domains.face_point(0, g).unwrap());
            let fv = mesh.face(g);
            for (c, qc) in q.iter().enumerate() {
                let sum: f64 = fv.iter().map(|&x| mesh.positions[x as usize][c]).sum();
                assert!((qc - sum / fv.len() as f64).abs() < 1e-14);
            }
        }
        assert!(domains.square(0, 0).is_none());
        assert!(domains.face_point(1, 1 << 20).is_none());
        assert!(domains.vertex_point(3, 0).is_none());
    }
}
