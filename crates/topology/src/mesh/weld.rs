//! Welding coincident vertices, on request only: a mesh is drawn as given, so two vertices at
//! one position stay two (a seam of the file) unless the caller asks for them to be merged.
//!
//! [`weld_vertices`] merges every group of vertices within a distance of each other (0: the
//! same position exactly, `-0.0` equal to `0.0`); groups are closed under that relation, so a
//! chain of vertices each within the distance of the next is one group. Each group becomes its
//! lowest-numbered vertex; the others stay in the vertex list, used by no face (vertex numbers,
//! and so tag and error lines, keep their meaning). Faces are rewritten: where two consecutive
//! corners become one vertex the edge between them has collapsed and the second corner is
//! removed (with its texture coordinate and normal); a face left with fewer than three
//! corners is dropped. Crease, corner and scalar tags follow their vertices (a group keeps its
//! first scalar tag); a crease whose two ends merged is dropped; holes follow their faces.
use super::ControlMesh;
use std::collections::HashMap;

/// What [`weld_vertices`] merged.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WeldReport {
    /// The distance vertices were merged within (0: identical positions).
    pub tolerance: f64,
    /// Groups of two or more vertices merged into one.
    pub groups: usize,
    /// Vertices merged into another (no face uses them any more).
    pub merged: usize,
    /// Face edges that collapsed (two consecutive corners welded into one).
    pub collapsed_edges: usize,
    /// Faces dropped for having fewer than three corners left, input numbering.
    pub dropped_faces: Vec<u32>,
    /// Crease tags dropped because both their ends merged.
    pub dropped_creases: usize,
}

impl WeldReport {
    /// One sentence for the user.
    pub fn summary(&self) -> String {
        let within = if self.tolerance == 0.0 {
            "at identical positions".to_string()
        } else {
            format!("within {}", self.tolerance)
        };
        let mut s = format!(
            "welded {} vertices {within} into {} ({} removed); {} face edges collapsed",
            self.merged + self.groups,
            self.groups,
            self.merged,
            self.collapsed_edges
        );
        if !self.dropped_faces.is_empty() {
            s.push_str(&format!(
                ", {} faces dropped (fewer than three corners left; first: face {})",
                self.dropped_faces.len(),
                self.dropped_faces[0] + 1
            ));
        }
        if self.dropped_creases > 0 {
            s.push_str(&format!(
                ", {} crease tags dropped (both ends merged)",
                self.dropped_creases
            ));
        }
        s
    }
}

/// Merges the vertices of `mesh` within `tolerance` of each other (module documentation).
/// Returns the welded mesh, per face of it the input face it came from, and the report.
/// `tolerance` must be finite and not negative (callers check options).
pub fn weld_vertices(mesh: &ControlMesh, tolerance: f64) -> (ControlMesh, Vec<u32>, WeldReport) {
    let target = groups(&mesh.positions, tolerance);
    let mut report = WeldReport {
        tolerance,
        ..WeldReport::default()
    };
    let mut sizes: HashMap<u32, usize> = HashMap::new();
    for (v, &t) in target.iter().enumerate() {
        if t as usize != v {
            report.merged += 1;
            *sizes.entry(t).or_default() += 1;
        }
    }
    report.groups = sizes.len();
    let mut out = ControlMesh {
        positions: mesh.positions.clone(),
        face_offsets: vec![0],
        options: mesh.options,
        scheme: mesh.scheme,
        ..ControlMesh::default()
    };
    let mut uvs = mesh.uvs.as_ref().map(|_| Vec::new());
    let mut uv_indices = mesh.uv_indices.as_ref().map(|_| Vec::new());
    let mut normals = mesh.normals.as_ref().map(|_| Vec::new());
    let mut kept: Vec<u32> = Vec::with_capacity(mesh.num_faces());
    let mut new_face: Vec<Option<u32>> = vec![None; mesh.num_faces()];
    for (f, slot) in new_face.iter_mut().enumerate() {
        let start = mesh.face_offsets[f] as usize;
        let corners = welded_corners(mesh.face(f), &target, &mut report);
        if corners.len() < 3 {
            report.dropped_faces.push(f as u32);
            continue;
        }
        *slot = Some(kept.len() as u32);
        kept.push(f as u32);
        for &i in &corners {
            out.face_vertices
                .push(target[mesh.face_vertices[start + i] as usize]);
            if let (Some(dst), Some(src)) = (uvs.as_mut(), mesh.uvs.as_ref()) {
                dst.push(src[start + i]);
            }
            if let (Some(dst), Some(src)) = (uv_indices.as_mut(), mesh.uv_indices.as_ref()) {
                dst.push(src[start + i]);
            }
            if let (Some(dst), Some(src)) = (normals.as_mut(), mesh.normals.as_ref()) {
                dst.push(src[start + i]);
            }
        }
        out.face_offsets.push(out.face_vertices.len() as u32);
    }
    out.uvs = uvs;
    out.uv_indices = uv_indices;
    out.normals = normals;
    let at = |v: u32| target.get(v as usize).copied().unwrap_or(v);
    for c in &mesh.creases {
        let vertices = c.vertices.map(at);
        if vertices[0] == vertices[1] {
            report.dropped_creases += 1;
        } else {
            out.creases.push(super::EdgeCrease { vertices, ..*c });
        }
    }
    out.corners = mesh
        .corners
        .iter()
        .map(|c| super::VertexCorner {
            vertex: at(c.vertex),
            ..*c
        })
        .collect();
    // A welded group keeps the first of its scalar tags (one tag per vertex).
    let mut tagged = std::collections::HashSet::new();
    out.scalar_tags = mesh
        .scalar_tags
        .iter()
        .map(|t| super::scalar_tags::ScalarTag {
            vertex: at(t.vertex),
            ..*t
        })
        .filter(|t| tagged.insert(t.vertex))
        .collect();
    out.holes = mesh
        .holes
        .iter()
        .filter_map(|&h| new_face.get(h as usize).copied().flatten())
        .collect();
    (out, kept, report)
}

/// The corners of `face` kept after welding (their indices in the face): a corner that welds
/// into the previous kept one (or, for the last, into the first) is a collapsed edge.
fn welded_corners(face: &[u32], target: &[u32], report: &mut WeldReport) -> Vec<usize> {
    let mut out: Vec<usize> = Vec::with_capacity(face.len());
    let welded = |i: usize| target[face[i] as usize];
    for i in 0..face.len() {
        if out.last().is_some_and(|&j| welded(j) == welded(i)) {
            report.collapsed_edges += 1;
        } else {
            out.push(i);
        }
    }
    while out.len() > 1 && welded(out[0]) == welded(*out.last().unwrap_or(&0)) {
        out.pop();
        report.collapsed_edges += 1;
    }
    out
}

/// Per vertex, the lowest-numbered vertex of its group (vertices within `tolerance` of each
/// other, closed transitively): a grid of cells `tolerance` wide, each vertex compared with
/// the vertices of its own and the 26 neighbouring cells.
fn groups(positions: &[[f64; 3]], tolerance: f64) -> Vec<u32> {
    let mut parent: Vec<u32> = (0..positions.len() as u32).collect();
    let key = |p: &[f64; 3]| -> [i64; 3] {
        if tolerance > 0.0 {
            p.map(|c| (c / tolerance).floor() as i64)
        } else {
            // Identical positions only: the key is the position (0.0 and -0.0 alike).
            p.map(|c| (c + 0.0).to_bits() as i64)
        }
    };
    let mut cells: HashMap<[i64; 3], Vec<u32>> = HashMap::new();
    for (v, p) in positions.iter().enumerate() {
        cells.entry(key(p)).or_default().push(v as u32);
    }
    let reach = if tolerance > 0.0 { 1 } else { 0 };
    for (v, p) in positions.iter().enumerate() {
        let k = key(p);
        for dx in -reach..=reach {
            for dy in -reach..=reach {
                for dz in -reach..=reach {
                    let cell = [k[0] + dx, k[1] + dy, k[2] + dz];
                    for &w in cells.get(&cell).into_iter().flatten() {
                        if (w as usize) < v && within(p, &positions[w as usize], tolerance) {
                            union(&mut parent, v as u32, w);
                        }
                    }
                }
            }
        }
    }
    (0..positions.len() as u32)
        .map(|v| find(&mut parent, v))
        .collect()
}

fn within(a: &[f64; 3], b: &[f64; 3], tolerance: f64) -> bool {
    let d2: f64 = (0..3).map(|k| (a[k] - b[k]).powi(2)).sum();
    d2 <= tolerance * tolerance
}

fn find(parent: &mut [u32], mut v: u32) -> u32 {
    while parent[v as usize] != v {
        let up = parent[parent[v as usize] as usize];
        parent[v as usize] = up;
        v = up;
    }
    v
}

/// Joins the groups of `a` and `b`; the lower root stays the root (so it is the group's
/// lowest-numbered vertex).
fn union(parent: &mut [u32], a: u32, b: u32) {
    let (ra, rb) = (find(parent, a), find(parent, b));
    if ra != rb {
        parent[ra.max(rb) as usize] = ra.min(rb);
    }
}
