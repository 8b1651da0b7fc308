//! Sparse (feature-adaptive) refinement against uniform refinement on OpenSubdiv's shapes: the
//! refined region is the selection's one-ring, the children of the selected faces keep complete
//! one-rings, and their positions equal the uniform refiner's (bitwise after one step, to
//! 1e-12 after two).

use topology::mesh::Topology;
use topology::mesh::INVALID;
use topology::refine::{
    refine_sparse, refine_sparse_region, refine_uniform, ChildOrigin, Level, LevelTopology,
    SparseRefinement, SparseRegion,
};
use topology::{load_obj, ControlMesh, Scheme, TopologyError};

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tests/data/opensubdiv/shapes/"
);

/// Creases, semi-sharp corners, boundaries (edges only / edges and corners), Chaikin decay,
/// non-quads and Loop shapes.
const SHAPES: &[&str] = &[
    "catmark_cube_creases1",
    "catmark_cube_corner3",
    "catmark_edgecorner",
    "catmark_dart_edgeonly",
    "catmark_chaikin1",
    "catmark_tent_creases1",
    "catmark_flap",
    "catmark_pyramid_creases1",
    "loop_cube_creases1",
    "loop_saddle_edgecorner",
    "loop_triangle_edgeonly",
    "loop_chaikin1",
    "loop_xord_boundary",
    "bilinear_cube",
];

fn shape(name: &str) -> (ControlMesh, Scheme) {
    let mesh = load_obj(format!("{DATA}{name}.obj")).expect("shape loads");
    let scheme = Scheme::from_shape_name(name).expect("scheme prefix");
    (mesh, scheme)
}

/// A few faces spread over the mesh (first, middle, last).
fn selection(nf: usize) -> Vec<u32> {
    let mut s = vec![0, (nf / 2) as u32, (nf - 1) as u32];
    s.dedup();
    s
}

/// Faces sharing at least one vertex with a selected face, by brute force over all faces.
fn one_ring(t: &Topology, selected: &[u32]) -> Vec<u32> {
    (0..t.num_faces() as u32)
        .filter(|&g| {
            selected.iter().any(|&f| {
                t.face_vertices(f as usize)
                    .iter()
                    .any(|v| t.face_vertices(g as usize).contains(v))
            })
        })
        .collect()
}

/// Index of a parent face's `k`-th child in the uniform refiner's numbering.
fn uniform_child_face(parent: &Topology, scheme: Scheme, f: u32, k: usize) -> usize {
    if scheme == Scheme::Loop {
        4 * f as usize + k
    } else {
        parent.face_tables().0[f as usize] as usize + k
    }
}

/// Where each sparse child vertex sits in the uniform child level, given where each sparse
/// parent vertex, edge and face sits in the uniform parent level.
fn uniform_vertex_map(
    step: &SparseRefinement,
    uniform_parent: &Topology,
    vertex: &dyn Fn(u32) -> usize,
    edge: &dyn Fn(u32) -> usize,
    face: &dyn Fn(u32) -> usize,
) -> Vec<usize> {
    let (nv, ne) = (uniform_parent.num_vertices(), uniform_parent.num_edges());
    step.maps
        .child_vertex_origin
        .iter()
        .map(|o| match *o {
            ChildOrigin::Vertex(v) => vertex(v),
            ChildOrigin::Edge(e) => nv + edge(e),
            ChildOrigin::Face(f) => nv + ne + face(f),
        })
        .collect()
}

fn apply(step: &SparseRefinement, parent: &[[f64; 3]]) -> Vec<[f64; 3]> {
    step.stencils.apply(parent)
}

/// Vertices of every child face touching a corner of a child of a selected face: the one-ring
/// the limit surface over those children needs.
fn needed_vertices(step: &SparseRefinement, selected: &[u32]) -> Vec<u32> {
    let t = &step.child.topology;
    let mut out = Vec::new();
    for &f in selected {
        for c in step.maps.child_faces(f as usize) {
            for &v in t.face_vertices(c) {
                for &g in t.vertex_faces(v as usize) {
                    out.extend_from_slice(t.face_vertices(g as usize));
                }
            }
        }
    }
    out.sort_unstable();
    out.dedup();
    out
}

fn scale(mesh: &ControlMesh) -> f64 {
    mesh.positions
        .iter()
        .flat_map(|p| p.iter().map(|x| x.abs()))
        .fold(1.0, f64::max)
}

#[test]
fn refined_region_is_the_one_ring_of_the_selection() {
    for name in SHAPES {
        let (mesh, scheme) = shape(name);
        let base = Level::from_mesh(&mesh, scheme).expect("base level");
        let t = &base.topology;
        let sel = selection(t.num_faces());
        let step = refine_sparse(base.view(), scheme, &mesh.options, &sel).expect("refines");
        assert_eq!(step.maps.refined_faces, one_ring(t, &sel), "{name}");
        for f in 0..t.num_faces() {
            let refined = step.maps.refined_faces.contains(&(f as u32));
            let children = step.maps.child_faces(f);
            assert_eq!(refined, !children.is_empty(), "{name}: face {f}");
            if refined {
                let expect = if scheme == Scheme::Loop {
                    4
                } else {
                    t.face_vertices(f).len()
                };
                assert_eq!(children.len(), expect, "{name}: face {f}");
                assert!(children
                    .clone()
                    .all(|c| step.maps.child_face_parent[c] == f as u32));
            }
        }
        // Every corner of a selected face's child has all its faces (the uniform valence).
        let uniform = refine_uniform(&mesh, scheme, 1).expect("uniform");
        let u1 = &uniform.level(1).topology;
        let map = uniform_vertex_map(&step, t, &|v| v as usize, &|e| e as usize, &|f| f as usize);
        let c = &step.child.topology;
        for &f in &sel {
            for child in step.maps.child_faces(f as usize) {
                for &v in c.face_vertices(child) {
                    assert_eq!(
                        c.vertex_faces(v as usize).len(),
                        u1.vertex_faces(map[v as usize]).len(),
                        "{name}: child vertex {v} lost faces"
                    );
                    assert_eq!(
                        c.vertex_edges(v as usize).len(),
                        u1.vertex_edges(map[v as usize]).len(),
                        "{name}: child vertex {v} lost edges"
                    );
                }
            }
        }
    }
}

#[test]
fn selected_children_match_uniform_refinement() {
    for name in SHAPES {
        let (mesh, scheme) = shape(name);
        let base = Level::from_mesh(&mesh, scheme).expect("base level");
        let uniform = refine_uniform(&mesh, scheme, 2).expect("uniform");
        let (u0, u1, u2) = (uniform.level(0), uniform.level(1), uniform.level(2));
        let sel = selection(base.num_faces());

        // Step 1, from the complete base: the same stencil rows, so bitwise-equal positions on
        // every child vertex, and the same child faces.
        let s1 = refine_sparse(base.view(), scheme, &mesh.options, &sel).expect("step 1");
        let p1 = apply(&s1, &base.positions);
        let m1 = uniform_vertex_map(&s1, &u0.topology, &|v| v as usize, &|e| e as usize, &|f| {
            f as usize
        });
        for (v, &u) in m1.iter().enumerate() {
            assert_eq!(p1[v], u1.positions[u], "{name}: level 1 vertex {v}");
            assert_eq!(
                s1.child.vertex_sharpness[v], u1.vertex_sharpness[u],
                "{name}: level 1 vertex {v} sharpness"
            );
        }
        let face1 = |f: u32| {
            let parent = s1.maps.child_face_parent[f as usize];
            let k = f as usize - s1.maps.child_faces(parent as usize).start;
            uniform_child_face(&u0.topology, scheme, parent, k)
        };
        for f in 0..s1.child.topology.num_faces() as u32 {
            let ours: Vec<usize> = s1
                .child
                .topology
                .face_vertices(f as usize)
                .iter()
                .map(|&v| m1[v as usize])
                .collect();
            let theirs: Vec<usize> = u1
                .topology
                .face_vertices(face1(f))
                .iter()
                .map(|&v| v as usize)
                .collect();
            assert_eq!(ours, theirs, "{name}: level 1 face {f}");
        }
        let edge1 = |e: u32| {
            let [a, b] = s1.child.topology.edge_vertices(e as usize);
            let ue = u1
                .topology
                .find_edge(m1[a as usize] as u32, m1[b as usize] as u32)
                .expect("edge exists uniformly") as usize;
            assert_eq!(
                s1.child.edge_sharpness[e as usize], u1.edge_sharpness[ue],
                "{name}: level 1 edge {e} sharpness"
            );
            ue
        };

        // Step 2, from the sparse level: select the children of the selected faces.
        let sel2: Vec<u32> = sel
            .iter()
            .flat_map(|&f| s1.maps.child_faces(f as usize))
            .map(|c| c as u32)
            .collect();
        let s2 = refine_sparse(s1.child.view(), scheme, &mesh.options, &sel2).expect("step 2");
        let p2 = apply(&s2, &p1);
        let m2 = uniform_vertex_map(&s2, &u1.topology, &|v| m1[v as usize], &edge1, &|f| {
            face1(f)
        });
        let tol = 1e-12 * scale(&mesh);
        let needed = needed_vertices(&s2, &sel2);
        assert!(!needed.is_empty());
        for &v in &needed {
            let (ours, theirs) = (p2[v as usize], u2.positions[m2[v as usize]]);
            let d = (0..3)
                .map(|k| (ours[k] - theirs[k]).abs())
                .fold(0.0, f64::max);
            assert!(d <= tol, "{name}: level 2 vertex {v} off by {d:e}");
        }
        // The grandchildren of the selection are the uniform ones, corner for corner.
        let face2_parent = |f: usize| s2.maps.child_face_parent[f];
        for &f in &sel2 {
            for g in s2.maps.child_faces(f as usize) {
                let k = g - s2.maps.child_faces(face2_parent(g) as usize).start;
                let ug = uniform_child_face(&u1.topology, scheme, face1(f) as u32, k);
                let ours: Vec<usize> = s2
                    .child
                    .topology
                    .face_vertices(g)
                    .iter()
                    .map(|&v| m2[v as usize])
                    .collect();
                let theirs: Vec<usize> = u2
                    .topology
                    .face_vertices(ug)
                    .iter()
                    .map(|&v| v as usize)
                    .collect();
                assert_eq!(ours, theirs, "{name}: level 2 face {g}");
            }
        }
    }
}

#[test]
fn selecting_every_face_is_uniform_refinement() {
    for name in SHAPES {
        let (mesh, scheme) = shape(name);
        let base = Level::from_mesh(&mesh, scheme).expect("base level");
        let all: Vec<u32> = (0..base.num_faces() as u32).collect();
        let step = refine_sparse(base.view(), scheme, &mesh.options, &all).expect("refines");
        let uniform = refine_uniform(&mesh, scheme, 1).expect("uniform");
        let u1 = uniform.level(1);
        assert_eq!(&step.stencils, uniform.step_stencils(1), "{name}");
        assert_eq!(
            step.child.topology.face_tables(),
            u1.topology.face_tables(),
            "{name}"
        );
        let (s, u) = (&step.child.topology, &u1.topology);
        assert_eq!(s.num_edges(), u.num_edges(), "{name}");
        for e in 0..s.num_edges() {
            assert_eq!(s.edge_vertices(e), u.edge_vertices(e), "{name}: edge {e}");
            assert_eq!(s.edge_faces(e), u.edge_faces(e), "{name}: edge {e}");
        }
        for v in 0..s.num_vertices() {
            assert_eq!(s.vertex_edges(v), u.vertex_edges(v), "{name}: vertex {v}");
            assert_eq!(s.vertex_faces(v), u.vertex_faces(v), "{name}: vertex {v}");
        }
        assert_eq!(step.child.edge_sharpness, u1.edge_sharpness, "{name}");
        assert_eq!(step.child.vertex_sharpness, u1.vertex_sharpness, "{name}");
        assert_eq!(step.stencils.apply(&base.positions), u1.positions, "{name}");
        for f in 0..base.num_faces() {
            assert_ne!(step.maps.face_first_child[f], INVALID);
        }
    }
}

#[test]
fn sparse_refinement_errors_name_what_is_at_fault() {
    let (mesh, scheme) = shape("catmark_cube");
    let base = Level::from_mesh(&mesh, scheme).expect("base level");
    let e = refine_sparse(base.view(), scheme, &mesh.options, &[6]).expect_err("face 6");
    assert!(matches!(
        e,
        TopologyError::FaceOutOfRange { face: 6, count: 6 }
    ));
    let e = refine_sparse(base.view(), Scheme::DooSabin, &mesh.options, &[0]).expect_err("ds");
    assert!(matches!(
        e,
        TopologyError::UnsupportedScheme {
            scheme: "doo-sabin",
            ..
        }
    ));
    let e = refine_sparse(base.view(), Scheme::Loop, &mesh.options, &[0]).expect_err("loop");
    assert!(matches!(
        e,
        TopologyError::LoopRequiresTriangles { size: 4, .. }
    ));
}

/// The child vertex a corner-restricted step made for each component the one-ring step made.
fn same_origin(corners: &SparseRefinement) -> std::collections::HashMap<ChildOrigin, u32> {
    (0..corners.maps.child_vertex_origin.len() as u32)
        .map(|c| (corners.maps.child_vertex_origin[c as usize], c))
        .collect()
}

/// Checks one step: the children of `selected` and the one-rings of their vertices are the
/// one-ring step's (same faces around each vertex, same stencil rows bit for bit, same
/// sharpness), and the step makes no more faces or vertices than it. Returns the corner step
/// and whether it made fewer faces.
fn corners_match_one_ring(
    name: &str,
    parent: &LevelTopology,
    scheme: Scheme,
    mesh: &ControlMesh,
    selected: &[u32],
) -> (SparseRefinement, bool) {
    let full = refine_sparse(parent.view(), scheme, &mesh.options, selected).expect("one ring");
    let part = refine_sparse_region(
        parent.view(),
        scheme,
        &mesh.options,
        selected,
        SparseRegion::SelectedCorners,
    )
    .expect("corners");
    let (ft, pt) = (&full.child.topology, &part.child.topology);
    assert!(pt.num_faces() <= ft.num_faces(), "{name}");
    assert!(pt.num_vertices() <= ft.num_vertices(), "{name}");
    let in_part = same_origin(&part);
    let to_part = |c: u32| in_part[&full.maps.child_vertex_origin[c as usize]];
    for &f in selected {
        let (fc, pc) = (
            full.maps.child_faces(f as usize),
            part.maps.child_faces(f as usize),
        );
        assert_eq!(fc.len(), pc.len(), "{name}: children of face {f}");
        for (a, b) in fc.zip(pc) {
            let fv: Vec<u32> = ft.face_vertices(a).iter().map(|&v| to_part(v)).collect();
            assert_eq!(fv, pt.face_vertices(b), "{name}: child of face {f}");
            for (&v, &w) in ft.face_vertices(a).iter().zip(pt.face_vertices(b)) {
                // The ring: the faces around the vertex, as corner lists, in any order.
                let ring = |t: &Topology, x: u32, map: &dyn Fn(u32) -> u32| {
                    let mut r: Vec<Vec<u32>> = t
                        .vertex_faces(x as usize)
                        .iter()
                        .map(|&g| {
                            t.face_vertices(g as usize)
                                .iter()
                                .map(|&y| map(y))
                                .collect()
                        })
                        .collect();
                    r.sort();
                    r
                };
                assert_eq!(
                    ring(ft, v, &to_part),
                    ring(pt, w, &|y| y),
                    "{name}: ring of child vertex {v}"
                );
                assert_eq!(
                    ft.vertex_edges(v as usize).len(),
                    pt.vertex_edges(w as usize).len(),
                    "{name}: valence of child vertex {v}"
                );
                assert_eq!(
                    full.child.vertex_sharpness[v as usize].to_bits(),
                    part.child.vertex_sharpness[w as usize].to_bits(),
                    "{name}: sharpness of child vertex {v}"
                );
                for &g in ft.vertex_faces(v as usize) {
                    for &y in ft.face_vertices(g as usize) {
                        assert_eq!(
                            full.stencils.stencil(y as usize),
                            part.stencils.stencil(to_part(y) as usize),
                            "{name}: row of child vertex {y}"
                        );
                    }
                }
                for &e in ft.vertex_edges(v as usize) {
                    let [x, y] = ft.edge_vertices(e as usize);
                    let g = pt.find_edge(to_part(x), to_part(y)).expect("edge kept");
                    assert_eq!(
                        full.child.edge_sharpness[e as usize].to_bits(),
                        part.child.edge_sharpness[g as usize].to_bits(),
                        "{name}: sharpness of child edge {e}"
                    );
                }
            }
        }
    }
    // Every half-edge pair names child edges joining its edge-vertex to its ends' children.
    let kv = part
        .maps
        .child_vertex_origin
        .iter()
        .take_while(|o| matches!(o, ChildOrigin::Vertex(_)))
        .count();
    for (r, pair) in part.maps.edge_child_halves.iter().enumerate() {
        let m = (kv + r) as u32;
        let ChildOrigin::Edge(e) = part.maps.child_vertex_origin[m as usize] else {
            panic!("{name}: edge-vertex {m} is not an edge's");
        };
        let ends = parent.topology.edge_vertices(e as usize);
        for (k, &h) in pair.iter().enumerate() {
            let vc = part.maps.vertex_child_vertex[ends[k] as usize];
            if h == INVALID {
                assert_eq!(
                    vc, INVALID,
                    "{name}: edge {e} end {k} has a child but no half"
                );
            } else {
                let mut got = pt.edge_vertices(h as usize);
                got.sort_unstable();
                let mut want = [vc, m];
                want.sort_unstable();
                assert_eq!(got, want, "{name}: half {k} of edge {e}");
            }
        }
    }
    let fewer = pt.num_faces() < ft.num_faces();
    (part, fewer)
}

#[test]
fn corner_region_keeps_the_selected_childrens_rings_and_rows() {
    let mut smaller = 0;
    for name in SHAPES.iter().filter(|n| !n.starts_with("loop")) {
        let (mesh, scheme) = shape(name);
        let base = LevelTopology::from_mesh(&mesh, scheme).expect("base");
        let nf = base.topology.num_faces();
        let sel = selection(nf);
        let (step, fewer) = corners_match_one_ring(name, &base, scheme, &mesh, &sel);
        smaller += usize::from(fewer);
        // A second step from the children of the selection (complete faces).
        let sel2: Vec<u32> = sel
            .iter()
            .flat_map(|&f| step.maps.child_faces(f as usize))
            .map(|c| c as u32)
            .step_by(2)
            .collect();
        corners_match_one_ring(name, &step.child, scheme, &mesh, &sel2);
    }
    assert!(smaller > 0, "the corner region never made fewer faces");
}
