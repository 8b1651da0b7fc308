//! Scalar-tagged meshes (ST-meshes; Boubekeur, Reuter and Schlick, appendix B of the
//! refinement-pattern paper): per-vertex shape parameters that bend curved PN triangles into
//! sharp creases.
//!
//! A tag gives its vertex a **deviation vector** `D` (zero: no crease through the vertex), a
//! **tension** `θ`, a **sharpness** `σ` and a **bias** `β`. In an OBJ it is the tag line
//! `t scalartag 1/6/0 v Dx Dy Dz θ σ β` (OpenSubdiv's tag syntax, so other readers skip it);
//! an untagged vertex has all six zero.
//!
//! The steps this module takes, before a technique shapes anything:
//! 1. **Values** ([`check_values`]): finite; `θ` and `σ` in 0..=1, `β` in −1..=1; one tag per
//!    vertex, naming a vertex of the mesh.
//! 2. **Creases** ([`CreaseEdges::of`]): a *crease edge* is an edge of the control mesh whose
//!    two ends both carry a deviation vector. A vertex takes one crease (the seed's rule): at
//!    most two crease edges, else an error naming it.
//! 3. **Triangles** ([`check_triangles`]): a face's fan triangle holds at most two vertices with
//!    a deviation vector (the seed's rule), else an error naming the face.
//!
//! What the tags do to the surface is the PN technique's (`tess::techniques::pn`).
use crate::error::{TagKind, TopologyError};
use crate::mesh::ControlMesh;
use std::collections::{HashMap, HashSet};

/// One vertex's scalar tags.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct ScalarTag {
    pub vertex: u32,
    /// `D`: the direction the crease tilts the normal to, across the crease; the two sides'
    /// sharp normals are `N ± σ D` normalised, `+` on the side `D` points to. Zero: no crease.
    pub deviation: [f32; 3],
    /// `θ`: 0 is PN's tangent length (a third of the edge), 1 pulls the tangents to the vertex.
    pub tension: f32,
    /// `σ`: how far the surface beside a crease turns to the sharp normal (0: smooth).
    pub sharpness: f32,
    /// `β`: tilts the crease's own tangent plane toward `D` (0: the vertex normal's).
    pub bias: f32,
}

impl ScalarTag {
    /// Whether a crease passes through the vertex (its deviation vector is not zero).
    pub fn has_crease(&self) -> bool {
        self.deviation.iter().any(|&d| d != 0.0)
    }

    /// Whether the tag changes the surface at all: a crease or a tension.
    pub fn shapes(&self) -> bool {
        self.has_crease() || self.tension != 0.0
    }
}

/// A tag per tagged vertex, after [`check_values`].
pub type TagMap = HashMap<u32, ScalarTag>;

/// Step 1: the tags' values and vertices, as a map from vertex to tag.
pub fn check_values(mesh: &ControlMesh) -> Result<TagMap, TopologyError> {
    let mut map = TagMap::new();
    for tag in &mesh.scalar_tags {
        let v = tag.vertex;
        if v as usize >= mesh.positions.len() {
            return Err(TopologyError::TagOutOfRange {
                tag: TagKind::ScalarTag,
                index: v,
                count: mesh.positions.len(),
            });
        }
        check_ranges(tag)?;
        if map.insert(v, *tag).is_some() {
            return Err(problem(v, "the vertex is tagged twice".into()));
        }
    }
    Ok(map)
}

fn problem(vertex: u32, problem: String) -> TopologyError {
    TopologyError::ScalarTag { vertex, problem }
}

fn check_ranges(tag: &ScalarTag) -> Result<(), TopologyError> {
    if let Some(d) = tag.deviation.iter().find(|d| !d.is_finite()) {
        return Err(problem(
            tag.vertex,
            format!("deviation component {d} is not finite"),
        ));
    }
    let ranges = [
        ("tension", tag.tension, 0.0, 1.0),
        ("sharpness", tag.sharpness, 0.0, 1.0),
        ("bias", tag.bias, -1.0, 1.0),
    ];
    for (name, value, lo, hi) in ranges {
        // NaN fails the range test too.
        if !(lo..=hi).contains(&value) {
            return Err(problem(
                tag.vertex,
                format!("{name} {value} is outside {lo}..={hi}"),
            ));
        }
    }
    Ok(())
}

/// Step 2: the crease edges (unordered vertex pairs of control-mesh edges whose ends both
/// carry a deviation vector).
#[derive(Clone, Debug, Default)]
pub struct CreaseEdges {
    edges: HashSet<(u32, u32)>,
}

impl CreaseEdges {
    /// The crease edges of `mesh` under `tags`; a vertex on more than two is an error.
    pub fn of(mesh: &ControlMesh, tags: &TagMap) -> Result<Self, TopologyError> {
        let creased = |v: u32| tags.get(&v).is_some_and(ScalarTag::has_crease);
        let mut edges = HashSet::new();
        for face in mesh.faces() {
            for (i, &a) in face.iter().enumerate() {
                let b = face[(i + 1) % face.len()];
                if a != b && creased(a) && creased(b) {
                    edges.insert((a.min(b), a.max(b)));
                }
            }
        }
        let mut per_vertex: HashMap<u32, usize> = HashMap::new();
        for &(a, b) in &edges {
            *per_vertex.entry(a).or_default() += 1;
            *per_vertex.entry(b).or_default() += 1;
        }
        let mut crowded: Vec<(u32, usize)> = per_vertex.into_iter().filter(|e| e.1 > 2).collect();
        crowded.sort_unstable();
        if let Some(&(v, n)) = crowded.first() {
            return Err(problem(
                v,
                format!(
                    "{n} crease edges meet at it (edges to other vertices with a deviation \
                     vector); a vertex takes one crease, two crease edges"
                ),
            ));
        }
        Ok(Self { edges })
    }

    /// Whether the edge from `a` to `b` is a crease edge.
    pub fn contains(&self, a: u32, b: u32) -> bool {
        self.edges.contains(&(a.min(b), a.max(b)))
    }

    pub fn len(&self) -> usize {
        self.edges.len()
    }

    pub fn is_empty(&self) -> bool {
        self.edges.is_empty()
    }
}

/// Step 3: every fan triangle `(0, k, k + 1)` of every face holds at most two vertices with a
/// deviation vector.
pub fn check_triangles(mesh: &ControlMesh, tags: &TagMap) -> Result<(), TopologyError> {
    let creased = |v: u32| tags.get(&v).is_some_and(ScalarTag::has_crease);
    for (f, face) in mesh.faces().enumerate() {
        for k in 1..face.len().saturating_sub(1) {
            if [face[0], face[k], face[k + 1]].into_iter().all(creased) {
                return Err(TopologyError::ScalarTagTriangle { face: f });
            }
        }
    }
    Ok(())
}

/// The three steps: the tag map and the crease edges of a mesh whose tags can shape it.
pub fn check(mesh: &ControlMesh) -> Result<(TagMap, CreaseEdges), TopologyError> {
    let tags = check_values(mesh)?;
    let creases = CreaseEdges::of(mesh, &tags)?;
    check_triangles(mesh, &tags)?;
    Ok((tags, creases))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn tag(vertex: u32, deviation: [f32; 3]) -> ScalarTag {
        ScalarTag {
            vertex,
            deviation,
            tension: 0.0,
            sharpness: 1.0,
            bias: 0.0,
        }
    }

    /// A 3×2 grid of quads, vertices numbered row by row (4 per row).
    fn grid() -> ControlMesh {
        let positions = (0..12)
            .map(|i| [(i % 4) as f64, (i / 4) as f64, 0.0])
            .collect();
        let quad = |i: u32| [i, i + 1, i + 5, i + 4];
        ControlMesh::from_polygons(
            positions,
            &[quad(0), quad(1), quad(2), quad(4), quad(5), quad(6)],
        )
    }

    #[test]
    fn crease_edges_join_vertices_with_deviation_vectors() {
        let mut mesh = grid();
        mesh.scalar_tags = (4..8).map(|v| tag(v, [0.0, 1.0, 0.0])).collect();
        let (_, creases) = check(&mesh).unwrap();
        assert_eq!(creases.len(), 3);
        assert!(creases.contains(5, 4) && creases.contains(6, 7));
        assert!(!creases.contains(1, 5));
    }

    #[test]
    fn a_vertex_of_two_creases_is_named() {
        let mut mesh = grid();
        // Row 1 and column 1: vertex 5 has four crease edges.
        mesh.scalar_tags = [1, 4, 5, 6, 9]
            .into_iter()
            .map(|v| tag(v, [0.0, 1.0, 0.0]))
            .collect();
        let e = check(&mesh).unwrap_err();
        assert!(
            matches!(e, TopologyError::ScalarTag { vertex: 5, .. }),
            "{e}"
        );
        assert!(e.to_string().contains("4 crease edges"), "{e}");
    }

    #[test]
    fn a_triangle_of_three_creased_vertices_is_named() {
        let mut mesh = grid();
        // Fan triangle (5, 6, 10) of face 4 (5, 6, 10, 9).
        mesh.scalar_tags = [5, 6, 10]
            .into_iter()
            .map(|v| tag(v, [1.0, 0.0, 0.0]))
            .collect();
        let e = check(&mesh).unwrap_err();
        assert!(
            matches!(e, TopologyError::ScalarTagTriangle { face: 4 }),
            "{e}"
        );
    }

    #[test]
    fn values_out_of_range_tagged_twice_or_off_the_mesh_are_named() {
        let mut mesh = grid();
        let bad = [
            (
                ScalarTag {
                    tension: 1.5,
                    ..tag(2, [0.0; 3])
                },
                "tension 1.5",
            ),
            (
                ScalarTag {
                    sharpness: f32::NAN,
                    ..tag(2, [0.0; 3])
                },
                "sharpness NaN",
            ),
            (
                ScalarTag {
                    bias: -2.0,
                    ..tag(2, [0.0; 3])
                },
                "bias -2",
            ),
            (tag(2, [f32::INFINITY, 0.0, 0.0]), "not finite"),
        ];
        for (t, expected) in bad {
            mesh.scalar_tags = vec![t];
            let e = check(&mesh).unwrap_err().to_string();
            assert!(e.contains(expected) && e.contains("vertex 2"), "{e}");
        }
        mesh.scalar_tags = vec![tag(3, [0.0; 3]), tag(3, [0.0; 3])];
        assert!(check(&mesh)
            .unwrap_err()
            .to_string()
            .contains("tagged twice"));
        mesh.scalar_tags = vec![tag(12, [0.0; 3])];
        assert!(matches!(
            check(&mesh).unwrap_err(),
            TopologyError::TagOutOfRange {
                tag: TagKind::ScalarTag,
                index: 12,
                count: 12
            }
        ));
    }
}
