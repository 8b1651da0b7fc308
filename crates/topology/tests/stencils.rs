//! Stencils reproduce refined positions; weights sum to 1; affine invariance; refinement keeps
//! closed manifolds closed and manifold with the same Euler characteristic.

use proptest::prelude::*;
use std::path::PathBuf;
use topology::mesh::obj::parse_obj;
use topology::mesh::{EdgeCrease, VertexCorner};
use topology::refine::{refine_uniform, uniform_stencils};
use topology::rules::options::CreaseMethod;
use topology::{load_obj, ControlMesh, Scheme, TopologyError};

fn shape(name: &str) -> ControlMesh {
    let p = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join(format!("../../tests/data/opensubdiv/shapes/{name}.obj"));
    load_obj(p).unwrap()
}

fn max_abs(points: &[[f64; 3]]) -> f64 {
    points.iter().flatten().fold(0.0f64, |m, &x| m.max(x.abs()))
}

fn assert_stencils_reproduce(mesh: &ControlMesh, scheme: Scheme, levels: usize) {
    let r = refine_uniform(mesh, scheme, levels).unwrap();
    for k in 0..=levels {
        let table = r.stencils(k);
        assert_eq!(table.len(), r.level(k).num_vertices());
        assert_eq!(table.num_sources, mesh.positions.len());
        let applied = table.apply(&mesh.positions);
        let want = &r.level(k).positions;
        let scale = max_abs(want).max(1e-300);
        for (a, b) in applied.iter().zip(want) {
            for c in 0..3 {
                assert!(
                    (a[c] - b[c]).abs() <= 1e-12 * scale,
                    "{scheme:?} L{k}: {a:?} vs {b:?}"
                );
            }
        }
    }
}

#[test]
fn stencils_reproduce_refined_positions() {
    for name in [
        "catmark_cube_creases1",
        "catmark_chaikin1",
        "catmark_dart_edgecorner",
        "catmark_flap2",
        "catmark_pyramid_creases1",
        "bilinear_cube",
    ] {
        assert_stencils_reproduce(&shape(name), Scheme::from_shape_name(name).unwrap(), 3);
    }
    for name in [
        "loop_chaikin1",
        "loop_cube_creases1",
        "loop_triangle_edgecorner",
    ] {
        assert_stencils_reproduce(&shape(name), Scheme::Loop, 3);
    }
    for name in ["catmark_cube", "catmark_tent", "catmark_pyramid"] {
        assert_stencils_reproduce(&shape(name), Scheme::DooSabin, 3);
    }
}

#[test]
fn level_one_topology_with_its_stencils() {
    // What the Loop GPU path needs: level-1 faces plus level-1 stencils over the base.
    let mesh = shape("loop_icosahedron");
    let r = refine_uniform(&mesh, Scheme::Loop, 1).unwrap();
    let l1 = r.level(1);
    assert_eq!(l1.num_faces(), 80);
    assert_eq!(l1.face_offsets().len(), 81);
    assert_eq!(l1.face_vertices().len(), 240);
    let table = r.stencils(1);
    assert_eq!(table.len(), 42);
    // Vertex-vertices keep their parent's index: valence-5 Loop weights on the first stencil.
    let (idx, w) = table.stencil(0);
    assert_eq!(idx.len(), 6);
    assert!(idx.contains(&0));
    let wf = table.weights_f32();
    assert_eq!(wf.len(), table.weights.len());
    let t32 = table.to_f32();
    assert_eq!(t32.offsets, table.offsets);
    assert!((t32.weights[0] as f64 - w[0]).abs() < 1e-7);
}

#[test]
fn loop_rejects_non_triangles() {
    let e = refine_uniform(&shape("catmark_cube"), Scheme::Loop, 1).unwrap_err();
    assert!(
        matches!(e, TopologyError::LoopRequiresTriangles { face: 0, size: 4 }),
        "{e}"
    );
}

#[test]
fn doo_sabin_counts_on_a_cube() {
    let r = refine_uniform(&shape("catmark_cube"), Scheme::DooSabin, 2).unwrap();
    // One vertex per corner; faces from 6 faces, 12 edges and 8 vertices.
    assert_eq!(r.level(1).num_vertices(), 24);
    assert_eq!(r.level(1).num_faces(), 26);
    assert_eq!(r.level(2).num_vertices(), 6 * 4 + 12 * 4 + 8 * 3);
    // The refined cube shrinks inside the control hull and stays symmetric.
    let c: [f64; 3] = r
        .level(2)
        .positions
        .iter()
        .fold([0.0; 3], |a, p| [a[0] + p[0], a[1] + p[1], a[2] + p[2]]);
    assert!(c.iter().all(|x| x.abs() < 1e-12));
}

#[test]
fn semi_sharp_crease_interpolates_between_smooth_and_sharp() {
    // A crease across a 3x3 quad patch: the middle point rises with sharpness.
    let mut text = String::new();
    for j in 0..4 {
        for i in 0..4 {
            let z = if i == 1 || i == 2 { 0.0 } else { 1.0 };
            text += &format!("v {i} {j} {z}\n");
        }
    }
    for j in 0..3 {
        for i in 0..3 {
            let a = j * 4 + i + 1;
            text += &format!("f {} {} {} {}\n", a, a + 1, a + 5, a + 4);
        }
    }
    let z_at = |s: f32| {
        let mut m = parse_obj(&text, "patch.obj").unwrap();
        for j in 0..3u32 {
            m.creases.push(EdgeCrease {
                vertices: [j * 4 + 1, j * 4 + 5],
                sharpness: s,
            });
        }
        let r = refine_uniform(&m, Scheme::CatmullClark, 2).unwrap();
        // Vertex 5 keeps its index through the levels.
        r.level(2).positions[5][2]
    };
    let (z0, z05, z1) = (z_at(0.0), z_at(0.5), z_at(1.0));
    assert!(z0 > z05 && z05 > z1 && z1 > 0.0, "{z0} {z05} {z1}");
    // Sharpness above the level count (and infinite) keeps the crease curve: z stays 0.
    assert!(z_at(3.0).abs() < 1e-12 && z_at(10.0).abs() < 1e-12);
}

/// A torus of `m` x `n` quads, or of triangles with random diagonals.
fn torus(m: usize, n: usize, tris: Option<&[bool]>) -> ControlMesh {
    let mut positions = Vec::new();
    for i in 0..m {
        for j in 0..n {
            let (u, v) = (
                i as f64 / m as f64 * std::f64::consts::TAU,
                j as f64 / n as f64 * std::f64::consts::TAU,
            );
            positions.push([
                (2.0 + v.cos()) * u.cos(),
                (2.0 + v.cos()) * u.sin(),
                v.sin(),
            ]);
        }
    }
    let id = |i: usize, j: usize| ((i % m) * n + (j % n)) as u32;
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for i in 0..m {
        for j in 0..n {
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            match tris {
                None => faces.push(q.to_vec()),
                Some(flags) if flags[(i * n + j) % flags.len()] => {
                    faces.push(vec![q[0], q[1], q[2]]);
                    faces.push(vec![q[0], q[2], q[3]]);
                }
                Some(_) => {
                    faces.push(vec![q[0], q[1], q[3]]);
                    faces.push(vec![q[1], q[2], q[3]]);
                }
            }
        }
    }
    ControlMesh::from_polygons(positions, &faces)
}

fn euler(v: usize, e: usize, f: usize) -> i64 {
    v as i64 - e as i64 + f as i64
}

fn arb_mesh() -> impl Strategy<Value = (ControlMesh, Scheme)> {
    (
        3usize..6,
        3usize..6,
        prop::collection::vec(any::<bool>(), 1..12),
        prop::sample::select(vec![
            Scheme::CatmullClark,
            Scheme::Loop,
            Scheme::Bilinear,
            Scheme::DooSabin,
        ]),
        prop::collection::vec((0usize..36, 0.0f32..4.0), 0..6),
        prop::collection::vec((0usize..36, 0.0f32..3.0), 0..3),
        any::<bool>(),
        prop::collection::vec(-0.2f64..0.2, 3),
    )
        .prop_map(|(m, n, flags, scheme, creases, corners, chaikin, jitter)| {
            // Loop needs triangles; the other schemes get mixed meshes half of the time.
            let tris =
                (scheme == Scheme::Loop || (flags[0] && flags.len() > 3)).then_some(&flags[..]);
            let mut mesh = torus(m, n, tris);
            for (i, p) in mesh.positions.iter_mut().enumerate() {
                p[i % 3] += jitter[i % jitter.len()];
            }
            let nf = mesh.num_faces();
            for (k, s) in creases {
                let f = mesh.face(k % nf).to_vec();
                mesh.creases.push(EdgeCrease {
                    vertices: [f[0], f[1]],
                    sharpness: s,
                });
            }
            let nv = mesh.positions.len() as u32;
            for (k, s) in corners {
                mesh.corners.push(VertexCorner {
                    vertex: k as u32 % nv,
                    sharpness: s,
                });
            }
            if chaikin {
                mesh.options.crease_method = CreaseMethod::Chaikin;
            }
            (mesh, scheme)
        })
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 48, ..ProptestConfig::default() })]

    #[test]
    fn stencil_weights_sum_to_one((mesh, scheme) in arb_mesh()) {
        let table = uniform_stencils(&mesh, scheme, 2).unwrap();
        for i in 0..table.len() {
            let s: f64 = table.stencil(i).1.iter().sum();
            prop_assert!((s - 1.0).abs() < 1e-12, "stencil {i} sums to {s}");
        }
    }

    #[test]
    fn refinement_is_affine_invariant((mesh, scheme) in arb_mesh(), a in prop::collection::vec(-2.0f64..2.0, 12)) {
        let map = |p: &[f64; 3]| {
            [
                a[0] * p[0] + a[1] * p[1] + a[2] * p[2] + a[9],
                a[3] * p[0] + a[4] * p[1] + a[5] * p[2] + a[10],
                a[6] * p[0] + a[7] * p[1] + a[8] * p[2] + a[11],
            ]
        };
        let r = refine_uniform(&mesh, scheme, 2).unwrap();
        let mut moved = mesh.clone();
        moved.positions = mesh.positions.iter().map(map).collect();
        let r2 = refine_uniform(&moved, scheme, 2).unwrap();
        let scale = 1.0 + max_abs(&r2.level(2).positions);
        for (p, q) in r.level(2).positions.iter().zip(&r2.level(2).positions) {
            let mp = map(p);
            for c in 0..3 {
                prop_assert!((mp[c] - q[c]).abs() < 1e-12 * scale);
            }
        }
    }

    #[test]
    fn closed_manifold_stays_closed_and_manifold((mesh, scheme) in arb_mesh()) {
        let r = refine_uniform(&mesh, scheme, 2).unwrap();
        let t0 = &r.level(0).topology;
        let chi = euler(t0.num_vertices(), t0.num_edges(), t0.num_faces());
        for level in r.levels() {
            let t = &level.topology;
            prop_assert_eq!(euler(t.num_vertices(), t.num_edges(), t.num_faces()), chi);
            prop_assert!((0..t.num_edges()).all(|e| !t.is_boundary_edge(e)));
            // Re-validate the refined faces from scratch: manifold, oriented, no degenerate faces.
            let as_mesh = ControlMesh {
                positions: level.positions.clone(),
                face_offsets: level.face_offsets().to_vec(),
                face_vertices: level.face_vertices().to_vec(),
                ..ControlMesh::default()
            };
            prop_assert!(as_mesh.validate().is_ok());
        }
    }
}
