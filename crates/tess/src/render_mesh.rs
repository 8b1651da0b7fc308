//! Renderable form of a control mesh for the triangle/quad techniques: f32 positions with
//! vertex normals, triangle patches (every face fan-triangulated) and quad patches (quads kept
//! for flat quad tessellation, the rest triangulated).
use crate::error::{Result, TessError};
use crate::gpu::Vertex;
use crate::techniques::shared::gpu_coordinate;
use crate::tessellator::Domain;
use topology::ControlMesh;

#[derive(Clone, Debug, Default)]
pub struct RenderMesh {
    pub vertices: Vec<Vertex>,
    /// Every face as triangles (for Phong and PN, and flat triangles).
    pub triangles: Vec<[u32; 3]>,
    /// Quads as quads; other faces go to `quad_mode_triangles`.
    pub quads: Vec<[u32; 4]>,
    pub quad_mode_triangles: Vec<[u32; 3]>,
    /// Where each entry of `triangles`, `quads` and `quad_mode_triangles` came from, in the same
    /// order: vertices were split by normal, so patch indices alone cannot name base corners.
    pub triangle_origins: Vec<PatchOrigin>,
    pub quad_origins: Vec<PatchOrigin>,
    pub quad_mode_triangle_origins: Vec<PatchOrigin>,
    pub bbox_min: [f32; 3],
    pub bbox_max: [f32; 3],
}

/// The base face a patch was made from, and which of the face's corners it spans: a quad patch
/// spans corners 0, 1, 2, 3 of a quad; fan triangle `fan` (1 ≤ fan ≤ n − 2) of an n-gon spans
/// corners 0, fan, fan + 1 (a triangle face is fan triangle 1 of itself).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct PatchOrigin {
    pub face: u32,
    pub face_size: u32,
    pub domain: Domain,
    pub fan: u32,
}

impl PatchOrigin {
    /// The face-local corner slots of the patch's control points, in patch order (3 used for
    /// triangles).
    pub fn face_corners(&self) -> [u32; 4] {
        match self.domain {
            Domain::Quad => [0, 1, 2, 3],
            Domain::Triangle => [0, self.fan, self.fan + 1, 0],
        }
    }
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn normalize(a: [f64; 3]) -> Option<[f64; 3]> {
    let l = dot(a, a).sqrt();
    (l > 0.0 && l.is_finite()).then(|| [a[0] / l, a[1] / l, a[2] / l])
}

impl RenderMesh {
    /// Builds vertex normals (the OBJ's own when every corner has one, else angle-weighted face
    /// normals) and the patch index lists. Indices are checked here, so the GPU never receives
    /// one that reads out of bounds.
    pub fn from_control_mesh(mesh: &ControlMesh) -> Result<Self> {
        let nv = mesh.positions.len();
        if mesh.num_faces() == 0 || nv == 0 {
            return Err(TessError::Topology(topology::TopologyError::EmptyMesh {
                what: "no faces to draw",
            }));
        }
        for (f, face) in mesh.faces().enumerate() {
            if face.len() < 3 {
                return Err(TessError::Topology(
                    topology::TopologyError::DegenerateFace {
                        face: f,
                        size: face.len(),
                    },
                ));
            }
            if let Some(&bad) = face.iter().find(|&&i| i as usize >= nv) {
                return Err(TessError::Topology(
                    topology::TopologyError::IndexOutOfRange {
                        face: f,
                        index: bad as i64,
                        count: nv,
                    },
                ));
            }
        }
        if let Some((v, _)) = mesh
            .positions
            .iter()
            .enumerate()
            .find(|(_, p)| p.iter().any(|c| !c.is_finite()))
        {
            return Err(TessError::NonFiniteVertex { vertex: v });
        }

        // Corner normals from the file are used when complete: vertices are then split by
        // (position, normal) so faces sharing both share the vertex.
        let corner_normals = mesh
            .normals
            .as_ref()
            .filter(|n| n.len() == mesh.face_vertices.len());
        let (positions, corner_index): (Vec<[f64; 3]>, Vec<u32>) = match corner_normals {
            Some(normals) => {
                let mut map = std::collections::HashMap::new();
                let mut pos = Vec::new();
                let mut idx = Vec::with_capacity(mesh.face_vertices.len());
                for (c, &v) in mesh.face_vertices.iter().enumerate() {
                    let n = normals[c];
                    let key = (v, n.map(f64::to_bits));
                    let id = *map.entry(key).or_insert_with(|| {
                        pos.push(mesh.positions[v as usize]);
                        (pos.len() - 1) as u32
                    });
                    idx.push(id);
                }
                (pos, idx)
            }
            None => (mesh.positions.clone(), mesh.face_vertices.clone()),
        };

        let normals: Vec<[f64; 3]> = match corner_normals {
            Some(cn) => {
                let mut n = vec![[0.0; 3]; positions.len()];
                for (c, &id) in corner_index.iter().enumerate() {
                    n[id as usize] = normalize(cn[c]).unwrap_or([0.0, 0.0, 1.0]);
                }
                n
            }
            None => topology::limit::limit_mesh::angle_weighted_normals(
                &positions,
                &mesh.face_offsets,
                &corner_index,
            ),
        };

        let mut out = RenderMesh {
            vertices: positions
                .iter()
                .zip(&normals)
                .map(|(p, n)| Vertex {
                    position: p.map(gpu_coordinate),
                    normal: n.map(gpu_coordinate),
                })
                .collect(),
            ..Default::default()
        };
        // Faces tagged as holes are not drawn (they still shape their neighbours' normals).
        let holes: std::collections::HashSet<u32> = mesh.holes.iter().copied().collect();
        for f in 0..mesh.num_faces() {
            if holes.contains(&(f as u32)) {
                continue;
            }
            let face =
                &corner_index[mesh.face_offsets[f] as usize..mesh.face_offsets[f + 1] as usize];
            let fan = (1..face.len() - 1).map(|i| [face[0], face[i], face[i + 1]]);
            let origin = |domain, fan| PatchOrigin {
                face: f as u32,
                face_size: face.len() as u32,
                domain,
                fan,
            };
            let fan_origins = (1..face.len() - 1).map(|i| origin(Domain::Triangle, i as u32));
            out.triangles.extend(fan.clone());
            out.triangle_origins.extend(fan_origins.clone());
            if face.len() == 4 {
                out.quads.push([face[0], face[1], face[2], face[3]]);
                out.quad_origins.push(origin(Domain::Quad, 0));
            } else {
                out.quad_mode_triangles.extend(fan);
                out.quad_mode_triangle_origins.extend(fan_origins);
            }
        }
        // The vertices the faces use, not every vertex the file has.
        (out.bbox_min, out.bbox_max) = crate::framing::drawn_bbox(mesh);
        Ok(out)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cube_normals_point_along_diagonals() {
        let mesh = topology::mesh::obj::parse_obj(
            include_str!("../../../tests/data/meshes/cube.obj"),
            "cube.obj",
        )
        .unwrap();
        let rm = RenderMesh::from_control_mesh(&mesh).unwrap();
        assert_eq!(rm.quads.len(), 6);
        assert_eq!(rm.triangles.len(), 12);
        for v in &rm.vertices {
            // Equal angles (90°) at each corner: the normal is the corner's diagonal direction.
            let p = v.position;
            let len = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            for (n, c) in v.normal.iter().zip(p) {
                assert!((n - c / len).abs() < 1e-6, "{v:?}");
            }
        }
    }

    #[test]
    fn pentagon_is_fan_triangulated() {
        let mesh = topology::ControlMesh::from_polygons(
            vec![
                [0.0, 0.0, 0.0],
                [1.0, 0.0, 0.0],
                [1.5, 1.0, 0.0],
                [0.5, 1.5, 0.0],
                [-0.5, 1.0, 0.0],
            ],
            &[[0u32, 1, 2, 3, 4]],
        );
        let rm = RenderMesh::from_control_mesh(&mesh).unwrap();
        assert_eq!(rm.triangles, vec![[0, 1, 2], [0, 2, 3], [0, 3, 4]]);
        assert_eq!(rm.quad_mode_triangles.len(), 3);
        let fans: Vec<_> = rm.triangle_origins.iter().map(|o| o.fan).collect();
        assert_eq!(fans, vec![1, 2, 3]);
        assert!(rm.quad_origins.is_empty());
        assert!(rm
            .quad_mode_triangle_origins
            .iter()
            .all(|o| o.face == 0 && o.face_size == 5 && o.domain == Domain::Triangle));
        assert!(rm.vertices.iter().all(|v| (v.normal[2] - 1.0).abs() < 1e-6));
    }

    #[test]
    fn hole_faces_make_no_patches() {
        let mut mesh = topology::mesh::obj::parse_obj(
            include_str!("../../../tests/data/meshes/cube.obj"),
            "cube.obj",
        )
        .unwrap();
        mesh.holes = vec![2];
        let rm = RenderMesh::from_control_mesh(&mesh).unwrap();
        assert_eq!(rm.quads.len(), 5);
        assert_eq!(rm.triangles.len(), 10);
        let origins = rm.quad_origins.iter().chain(&rm.triangle_origins);
        assert!(origins.clone().all(|o| o.face != 2));
        assert_eq!(origins.filter(|o| o.face == 3).count(), 3);
        // The hole still shapes its corners' normals: the cube's corner diagonals, as before.
        let whole = RenderMesh::from_control_mesh(&{
            let mut m = mesh.clone();
            m.holes.clear();
            m
        })
        .unwrap();
        assert_eq!(rm.vertices, whole.vertices);
    }

    #[test]
    fn out_of_range_index_is_an_error() {
        let mesh = topology::ControlMesh::from_polygons(
            vec![[0.0; 3], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]],
            &[[0u32, 1, 7]],
        );
        let e = RenderMesh::from_control_mesh(&mesh)
            .unwrap_err()
            .to_string();
        assert!(e.contains("face 0") && e.contains('7'), "{e}");
    }
}
