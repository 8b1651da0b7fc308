//! The mesh refined uniformly on the CPU and placed on its limit (`topology::limit::limit_mesh`): its
//! sizes are known before refining, its limit positions by masks equal the exact evaluator's,
//! and every vertex is the limit surface at the domain point it reports on the base mesh.
use topology::limit::eval::{limit_point, LimitScheme};
use topology::limit::face_domain::{face_corner_uv, LimitEvaluator};
use topology::limit::limit_mesh::{
    catmark_level_size, evaluator_limit_positions, loop_level_size, mask_limit_positions,
    uniform_limit_mesh, DomainPoint,
};
use topology::refine::{refine_level, Level};
use topology::{load_obj, ControlMesh, Scheme};

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tests/data/opensubdiv/shapes/"
);

fn spot() -> ControlMesh {
    load_obj(concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../assets/spot_control_mesh.obj"
    ))
    .unwrap()
}

/// Every face corner at its own face's corner of [`face_corner_uv`].
fn corners(mesh: &ControlMesh) -> Vec<DomainPoint> {
    let mut out = Vec::new();
    for (f, face) in mesh.faces().enumerate() {
        for k in 0..face.len() as u32 {
            out.push(DomainPoint {
                face: f as u32,
                uv: face_corner_uv(face.len() as u32, k),
            });
        }
    }
    out
}

fn octahedron() -> ControlMesh {
    ControlMesh::from_polygons(
        vec![
            [1.0, 0.0, 0.0],
            [-1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
            [0.0, 0.0, -1.0],
        ],
        &[
            [0u32, 2, 4],
            [2, 1, 4],
            [1, 3, 4],
            [3, 0, 4],
            [2, 0, 5],
            [1, 2, 5],
            [3, 1, 5],
            [0, 3, 5],
        ],
    )
}

/// Two quads and two triangles sharing edges: an open mixed mesh.
fn mixed() -> ControlMesh {
    ControlMesh::from_polygons(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.1],
            [2.0, 0.0, 0.0],
            [0.0, 1.0, 0.2],
            [1.0, 1.0, 0.0],
            [2.0, 1.0, 0.3],
            [1.5, 1.8, 0.1],
        ],
        &[
            vec![0u32, 1, 4, 3],
            vec![1, 2, 5, 4],
            vec![4, 5, 6],
            vec![3, 4, 6],
        ],
    )
}

/// A 3 × 2 grid of quads split into triangles: boundary creases and corners.
fn open_grid() -> ControlMesh {
    let mut pos = Vec::new();
    for j in 0..3 {
        for i in 0..4 {
            pos.push([i as f64, j as f64, ((i * j) as f64 * 0.7).sin()]);
        }
    }
    let mut faces = Vec::new();
    for j in 0..2u32 {
        for i in 0..3u32 {
            let a = j * 4 + i;
            faces.push([a, a + 1, a + 5]);
            faces.push([a, a + 5, a + 4]);
        }
    }
    ControlMesh::from_polygons(pos, &faces)
}

fn tetrahedron() -> ControlMesh {
    ControlMesh::from_polygons(
        vec![
            [1.0, 1.0, 1.0],
            [1.0, -1.0, -1.0],
            [-1.0, 1.0, -1.0],
            [-1.0, -1.0, 1.0],
        ],
        &[[0u32, 1, 2], [0, 3, 1], [0, 2, 3], [1, 3, 2]],
    )
}

#[test]
fn loop_sizes_follow_the_recurrence() {
    let mesh = octahedron();
    assert_eq!(loop_level_size(&mesh, 0), (6, 12, 8));
    assert_eq!(loop_level_size(&mesh, 1), (18, 48, 32));
    let cpu = uniform_limit_mesh(&mesh, Scheme::Loop, 2, &corners(&mesh)).unwrap();
    let (v, _, f) = loop_level_size(&mesh, 2);
    assert_eq!(cpu.positions.len() as u64, v);
    assert_eq!(cpu.triangles.len() as u64, f);
}

/// Sizes known before refining; base vertices keep their index and land on the limit.
#[test]
fn catmark_sizes_and_base_vertices_on_the_limit() {
    let mesh = mixed();
    assert_eq!(catmark_level_size(&mesh, 0), (7, 10, 4));
    for level in 0..=3 {
        let cpu = uniform_limit_mesh(&mesh, Scheme::CatmullClark, level, &corners(&mesh)).unwrap();
        let (v, _, f) = catmark_level_size(&mesh, level);
        assert_eq!(cpu.positions.len() as u64, v, "level {level}");
        // Level 0 draws its polygons as fans (2 + 2 + 1 + 1 triangles), then quads.
        let triangles = if level == 0 { 6 } else { 2 * f };
        assert_eq!(cpu.triangles.len() as u64, triangles, "level {level}");
        let want = limit_point(&mesh, LimitScheme::CatmullClark, 0, 1.0, 1.0)
            .unwrap()
            .position;
        for (got, want) in cpu.positions[4].iter().zip(&want) {
            assert!((got - want).abs() < 1e-12, "level {level}");
        }
    }
}

#[test]
fn mask_limit_positions_equal_the_evaluator() {
    let mut corners_grid = open_grid();
    corners_grid.options.boundary =
        topology::rules::options::BoundaryInterpolation::EdgesAndCorners;
    let mut creased = tetrahedron();
    for vertices in [[0, 1], [1, 2]] {
        creased.creases.push(topology::mesh::EdgeCrease {
            vertices,
            sharpness: 10.0,
        });
    }
    for (name, mesh) in [
        ("grid", open_grid()),
        ("grid, corners", corners_grid),
        ("tetrahedron", tetrahedron()),
        ("tetrahedron, crease", creased),
    ] {
        let mut level = Level::from_mesh(&mesh, Scheme::Loop).unwrap();
        for k in 0..3 {
            let fast = mask_limit_positions(&level).expect("no semi-sharp features");
            let slow =
                evaluator_limit_positions(&level, k, &mesh.options, LimitScheme::Loop).unwrap();
            assert_eq!(fast.len(), slow.len());
            for (v, (a, b)) in fast.iter().zip(&slow).enumerate() {
                for c in 0..3 {
                    assert!((a[c] - b[c]).abs() < 1e-12, "{name} level {k} vertex {v}");
                }
            }
            level = refine_level(&level, Scheme::Loop, &mesh.options).unwrap().0;
        }
    }
}

#[test]
fn semi_sharp_creases_are_evaluated_exactly_until_decayed() {
    let mut mesh = tetrahedron();
    mesh.creases.push(topology::mesh::EdgeCrease {
        vertices: [0, 1],
        sharpness: 1.5,
    });
    let level = Level::from_mesh(&mesh, Scheme::Loop).unwrap();
    assert!(mask_limit_positions(&level).is_none());
    // One level later it is 0.5: still semi-sharp, so the masks decline and the exact
    // evaluator places the vertices: base vertex 0 (it keeps its index) lands on the limit
    // the evaluator finds on the control mesh itself, at the vertex's corner of face 0.
    let cpu = uniform_limit_mesh(&mesh, Scheme::Loop, 1, &corners(&mesh)).unwrap();
    let corner = mesh.face(0).iter().position(|&v| v == 0).unwrap();
    let (u, v) = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)][corner];
    let want = limit_point(&mesh, LimitScheme::Loop, 0, u, v)
        .unwrap()
        .position;
    for (got, want) in cpu.positions[0].iter().zip(&want) {
        assert!((got - want).abs() < 1e-12, "{got} vs {want}");
    }
    // Two levels later the crease has decayed and the masks apply.
    let cpu = uniform_limit_mesh(&mesh, Scheme::Loop, 2, &corners(&mesh)).unwrap();
    assert_eq!(cpu.triangles.len(), 4 * 16);
}

/// Every refined vertex is the exact limit at the domain point it reports, on meshes with
/// boundaries, creases, triangles among quads and n-gons (the sub-quad parameterization).
#[test]
fn every_vertex_is_the_limit_at_its_domain_point() {
    let shape = |name: &str| load_obj(format!("{DATA}{name}.obj")).unwrap();
    let cases = [
        ("octahedron", octahedron(), Scheme::Loop, 3),
        ("open grid", open_grid(), Scheme::Loop, 3),
        (
            "loop_xord_boundary",
            shape("loop_xord_boundary"),
            Scheme::Loop,
            2,
        ),
        ("mixed", mixed(), Scheme::CatmullClark, 3),
        (
            "catmark_pyramid",
            shape("catmark_pyramid"),
            Scheme::CatmullClark,
            3,
        ),
        (
            "catmark_tent_creases1",
            shape("catmark_tent_creases1"),
            Scheme::CatmullClark,
            2,
        ),
        (
            "catmark_xord_boundary",
            shape("catmark_xord_boundary"),
            Scheme::CatmullClark,
            2,
        ),
        // Triangles, quads and pentagons.
        ("spot", spot(), Scheme::CatmullClark, 1),
    ];
    for (name, mesh, scheme, level) in cases {
        let cpu = uniform_limit_mesh(&mesh, scheme, level, &corners(&mesh)).unwrap();
        let limit_scheme = match scheme {
            Scheme::Loop => LimitScheme::Loop,
            _ => LimitScheme::CatmullClark,
        };
        let evaluator = LimitEvaluator::new(&mesh, limit_scheme).unwrap();
        let (lo, hi) = mesh.bounding_box();
        let diagonal = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        let mut checked = 0;
        for (v, d) in cpu.domains.iter().enumerate() {
            let Some(d) = d else { continue };
            let e = evaluator
                .evaluate(d.face, d.uv[0], d.uv[1])
                .unwrap_or_else(|e| panic!("{name} vertex {v} at {d:?}: {e}"));
            for k in 0..3 {
                assert!(
                    (cpu.positions[v][k] - e.position[k]).abs() <= 1e-9 * diagonal,
                    "{name} level {level} vertex {v} at {d:?}: {:?} vs {:?}",
                    cpu.positions[v],
                    e.position
                );
            }
            checked += 1;
        }
        assert_eq!(
            checked,
            cpu.positions.len(),
            "{name}: every vertex has a domain"
        );
    }
}

/// The refusals: schemes without a uniform limit mesh here.
#[test]
fn doo_sabin_has_no_uniform_limit_mesh_here() {
    let mesh = mixed();
    assert!(uniform_limit_mesh(&mesh, Scheme::DooSabin, 1, &corners(&mesh)).is_err());
}
