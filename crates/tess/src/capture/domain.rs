//! Base-face domains: where a captured (patch, domain coordinate) lies on the base mesh, and
//! which open edges lie on the base mesh's own boundary.
use super::soup::{CapturedSoup, EdgeReport, WeldedMesh};
use crate::render_mesh::PatchOrigin;
use crate::tessellator::Domain;
use std::collections::HashMap;
use topology::ControlMesh;

/// A point of the base mesh: face index and its (u, v) in the face's domain ([`face_corner_uv`]).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct FacePoint {
    pub face: u32,
    pub u: f32,
    pub v: f32,
}

/// Maps a captured patch id and domain coordinate to the base mesh; `None` for an unknown patch.
pub type PatchToFace<'a> = dyn Fn(u32, [f32; 2]) -> Option<FacePoint> + 'a;

pub use topology::limit::face_domain::face_corner_uv;

/// How far (in domain units) a captured coordinate may sit from a face edge and still count as
/// on it: the tessellator's edge coordinates are exact 0 or 1 or i/n with 1 − x − y rounding.
const ON_EDGE: f64 = 1e-5;

/// The face-local edges (edge `k` runs from corner `k` to corner `k + 1`) that `uv` lies on.
pub fn face_edges_at(n: u32, uv: [f32; 2]) -> Vec<u32> {
    let p = [uv[0] as f64, uv[1] as f64];
    (0..n)
        .filter(|&k| {
            let a = face_corner_uv(n, k);
            let b = face_corner_uv(n, k + 1);
            let d = [b[0] - a[0], b[1] - a[1]];
            let len2 = d[0] * d[0] + d[1] * d[1];
            let t = (((p[0] - a[0]) * d[0] + (p[1] - a[1]) * d[1]) / len2).clamp(0.0, 1.0);
            let q = [a[0] + t * d[0] - p[0], a[1] + t * d[1] - p[1]];
            (q[0] * q[0] + q[1] * q[1]).sqrt() <= ON_EDGE
        })
        .collect()
}

/// The patch → base face table of the triangle/quad techniques, indexed by captured patch id
/// (from [`crate::RenderMesh`]'s origins, in the technique's array order).
#[derive(Clone, Debug, Default)]
pub struct PatchFaceTable {
    pub origins: Vec<PatchOrigin>,
}

impl PatchFaceTable {
    pub fn new(origins: Vec<PatchOrigin>) -> Self {
        Self { origins }
    }

    /// A triangle patch spanning a whole triangle face, or a quad patch, is the identity (bit
    /// for bit); a fan triangle of a larger face maps its barycentrics into the face's domain.
    pub fn face_point(&self, patch: u32, domain: [f32; 2]) -> Option<FacePoint> {
        let o = self.origins.get(patch as usize)?;
        let identity = match o.domain {
            Domain::Quad => true,
            Domain::Triangle => o.face_size == 3,
        };
        if identity {
            return Some(FacePoint {
                face: o.face,
                u: domain[0],
                v: domain[1],
            });
        }
        let b = [
            domain[0] as f64,
            domain[1] as f64,
            1.0 - domain[0] as f64 - domain[1] as f64,
        ];
        let corners = o.face_corners();
        let mut uv = [0.0f64; 2];
        for i in 0..3 {
            let c = face_corner_uv(o.face_size, corners[i]);
            uv[0] += b[i] * c[0];
            uv[1] += b[i] * c[1];
        }
        Some(FacePoint {
            face: o.face,
            u: uv[0] as f32,
            v: uv[1] as f32,
        })
    }
}

/// Open edges split by where they lie.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct OpenEdgeClasses {
    /// Both endpoints lie on one edge of one base face, and that base edge is a boundary edge
    /// of the drawn surface (used by one face that is not a hole).
    pub on_base_boundary: usize,
    /// Both endpoints lie on one base edge that is non-manifold (three or more faces, two
    /// faces of opposite winding, a vertex to itself): where sheets meet along it without
    /// sharing their vertices' bits, each sheet's side is open. Not a crack: OpenSubdiv's rules
    /// draw each sheet to the edge, but nothing joins the sheets there.
    pub on_non_manifold_edge: usize,
    /// Both endpoints inside one base face of no area: its corners lie on one line and every
    /// one of its edges is non-manifold (OpenSubdiv's quad that names two vertices twice each,
    /// catmark_nonman_edges' face 40). Every such edge is an infinitely sharp crease, so the
    /// face's limit surface is the segment its corners span (`crates/topology/tests/
    /// non_manifold.rs` checks it on the exact limit): the tessellation's triangles all lie on
    /// it, and where distinct points of the domain round to one float they weld into fans with
    /// open sides. No surface is there to open, so no crack.
    pub in_face_of_no_area: usize,
    /// Every other open edge: a gap the GPU left inside the surface.
    pub cracks: usize,
    /// Of the cracks, those whose patch id maps to no base face (a mapping bug, not geometry).
    pub unmapped: usize,
}

/// Classifies `report.open` from the base mesh's topology and the captured patch ids and domain
/// coordinates of each open edge's own triangle (never from positions).
///
/// An open edge lies on the base mesh's boundary when both its ends lie on one base edge that
/// is a boundary of the drawn surface. Each end names its base edges through its own face
/// point: the edges of its face it lies on, and at a face corner every base edge of that
/// corner's vertex. So the two ends may name different faces (a technique whose domains are
/// not base faces, or whose vertices are shared by several faces, maps each vertex into one of
/// them), and an edge between two faces' points on one boundary edge is still told apart from
/// a crack.
pub fn classify_open_edges(
    soup: &CapturedSoup,
    welded: &WeldedMesh,
    report: &EdgeReport,
    map: &PatchToFace<'_>,
    base: &ControlMesh,
) -> OpenEdgeClasses {
    let edges = BaseEdges::new(base);
    let mut out = OpenEdgeClasses::default();
    for e in &report.open {
        let t = e.triangle as usize;
        let corner = |v: u32| {
            (0..3)
                .find(|&i| welded.triangles[t][i] == v)
                .map(|i| soup.records[3 * t + i])
        };
        let (Some(ra), Some(rb)) = (corner(e.vertices[0]), corner(e.vertices[1])) else {
            out.cracks += 1;
            continue;
        };
        let (Some(fa), Some(fb)) = (map(ra.patch, ra.domain), map(rb.patch, rb.domain)) else {
            out.cracks += 1;
            out.unmapped += 1;
            continue;
        };
        let (ea, eb) = (edges.at(base, &fa), edges.at(base, &fb));
        let shared =
            |class: &dyn Fn(&[u32; 2]) -> bool| ea.iter().any(|k| eb.contains(k) && class(k));
        if shared(&|k| edges.is_boundary(*k)) {
            out.on_base_boundary += 1;
        } else if shared(&|k| edges.non_manifold.contains(k)) {
            out.on_non_manifold_edge += 1;
        } else if fa.face == fb.face && edges.no_area.contains(&fa.face) {
            out.in_face_of_no_area += 1;
        } else {
            out.cracks += 1;
        }
    }
    out
}

/// Whether the corners `face` names lie on one line, exactly (in the mesh's coordinates).
fn corners_on_a_line(base: &ControlMesh, face: &[u32]) -> bool {
    let p: Vec<[f64; 3]> = face.iter().map(|&v| base.positions[v as usize]).collect();
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let Some(d) = p.iter().map(|&q| sub(q, p[0])).find(|d| *d != [0.0; 3]) else {
        return true;
    };
    p.iter().all(|&q| {
        let e = sub(q, p[0]);
        let cross = [
            d[1] * e[2] - d[2] * e[1],
            d[2] * e[0] - d[0] * e[2],
            d[0] * e[1] - d[1] * e[0],
        ];
        cross == [0.0; 3]
    })
}

/// The base mesh's edges as sorted vertex pairs: how many drawn faces use each (a hole's faces
/// are not drawn: an edge between a hole and a drawn face is the surface's boundary, as an
/// edge with one face is), and the edges at each vertex.
struct BaseEdges {
    uses: HashMap<[u32; 2], u32>,
    at_vertex: HashMap<u32, Vec<[u32; 2]>>,
    /// Non-manifold edges ([`topology::mesh::manifold::non_manifold_edges`]; none for a mesh
    /// that validation refuses).
    non_manifold: std::collections::HashSet<[u32; 2]>,
    /// Faces of no area ([`OpenEdgeClasses::in_face_of_no_area`]).
    no_area: std::collections::HashSet<u32>,
}

impl BaseEdges {
    fn new(base: &ControlMesh) -> Self {
        let holes: std::collections::HashSet<u32> = base.holes.iter().copied().collect();
        let mut uses: HashMap<[u32; 2], u32> = HashMap::new();
        let mut at_vertex: HashMap<u32, Vec<[u32; 2]>> = HashMap::new();
        for (i, face) in base.faces().enumerate() {
            for k in 0..face.len() {
                let (a, b) = (face[k], face[(k + 1) % face.len()]);
                let key = [a.min(b), a.max(b)];
                if !uses.contains_key(&key) {
                    at_vertex.entry(a).or_default().push(key);
                    at_vertex.entry(b).or_default().push(key);
                }
                let u = uses.entry(key).or_default();
                *u += u32::from(!holes.contains(&(i as u32)));
            }
        }
        let non_manifold: std::collections::HashSet<[u32; 2]> =
            topology::mesh::manifold::non_manifold_edges(base)
                .map(|edges| edges.into_iter().map(|(e, _)| e).collect())
                .unwrap_or_default();
        let no_area = (0..base.num_faces())
            .filter(|&f| {
                let face = base.face(f);
                let n = face.len();
                (0..n).all(|k| {
                    let (a, b) = (face[k], face[(k + 1) % n]);
                    non_manifold.contains(&[a.min(b), a.max(b)])
                }) && corners_on_a_line(base, face)
            })
            .map(|f| f as u32)
            .collect();
        Self {
            uses,
            at_vertex,
            non_manifold,
            no_area,
        }
    }

    fn is_boundary(&self, edge: [u32; 2]) -> bool {
        self.uses.get(&edge) == Some(&1)
    }

    /// The base edges `p` lies on: those of its face it lies on, and at a corner of its face
    /// every edge of that corner's vertex.
    fn at(&self, base: &ControlMesh, p: &FacePoint) -> Vec<[u32; 2]> {
        if p.face as usize >= base.num_faces() {
            return Vec::new();
        }
        let f = base.face(p.face as usize);
        let n = f.len();
        let on = face_edges_at(n as u32, [p.u, p.v]);
        let mut out = Vec::new();
        for &k in &on {
            let k = k as usize;
            let (a, b) = (f[k], f[(k + 1) % n]);
            out.push([a.min(b), a.max(b)]);
            if on.contains(&(((k + n - 1) % n) as u32)) {
                out.extend(self.at_vertex.get(&a).into_iter().flatten().copied());
            }
        }
        out
    }
}
