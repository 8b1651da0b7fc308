use super::*;
use crate::limit::doo_sabin_domain::{DomainPoint, DomainRefinement};
use crate::mesh::obj::parse_obj;
use crate::refine::refine_uniform;

const SHAPES: &str = "../../tests/data/opensubdiv/shapes";

fn shape(name: &str) -> ControlMesh {
    let path = format!("{}/{SHAPES}/{name}.obj", env!("CARGO_MANIFEST_DIR"));
    let text = std::fs::read_to_string(&path).unwrap();
    parse_obj(&text, name).unwrap()
}

fn spot() -> ControlMesh {
    let path = format!(
        "{}/../../assets/spot_control_mesh.obj",
        env!("CARGO_MANIFEST_DIR")
    );
    parse_obj(&std::fs::read_to_string(path).unwrap(), "spot").unwrap()
}

/// A pentagonal prism: two pentagons, five quads, valence-3 vertices.
fn pentagonal_prism() -> ControlMesh {
    let mut positions = Vec::new();
    for z in [0.0, 1.3] {
        for k in 0..5 {
            let a = std::f64::consts::TAU * k as f64 / 5.0;
            positions.push([a.cos() * (1.0 + 0.2 * z), a.sin(), z + 0.1 * k as f64]);
        }
    }
    let mut faces = vec![vec![4, 3, 2, 1, 0], vec![5, 6, 7, 8, 9]];
    for k in 0..5 {
        let j = (k + 1) % 5;
        faces.push(vec![k, j, j + 5, k + 5]);
    }
    ControlMesh::from_polygons(positions, &faces)
}

/// An open disk: a valence-5 interior vertex, a triangle and a pentagon on the boundary.
fn open_fan() -> ControlMesh {
    let mut positions = vec![[0.0, 0.0, 0.3]];
    for k in 0..10 {
        let a = std::f64::consts::TAU * k as f64 / 10.0;
        let r = if k % 2 == 0 { 1.0 } else { 1.2 };
        positions.push([r * a.cos(), r * a.sin(), 0.2 * (3.0 * a).sin()]);
    }
    // Three points outside the rim between ring(1) and ring(2), for a pentagon.
    for (a, r) in [(0.75, 1.7), (0.95, 1.9), (1.15, 1.7)] {
        positions.push([r * f64::cos(a), r * f64::sin(a), 0.15]);
    }
    let ring = |k: u32| 1 + k % 10;
    let mut faces: Vec<Vec<u32>> = (0..5)
        .map(|k| vec![0, ring(2 * k), ring(2 * k + 1), ring(2 * k + 2)])
        .collect();
    // A triangle over the dent at ring(0) (an interior vertex of valence 3 there) and a
    // pentagon on the boundary (ring(1) a boundary vertex of three faces).
    faces.push(vec![ring(0), ring(9), ring(1)]);
    faces.push(vec![ring(1), 11, 12, 13, ring(2)]);
    ControlMesh::from_polygons(positions, &faces)
}

/// A grid of `n × n` vertices at `(a, b, z(a, b))`, quads counter-clockwise.
fn grid(n: usize) -> ControlMesh {
    let positions = (0..n * n)
        .map(|k| {
            let (a, b) = ((k % n) as f64, (k / n) as f64);
            [a, b, height(a, b)]
        })
        .collect();
    let at = |a: usize, b: usize| (a + n * b) as u32;
    let mut faces = Vec::new();
    for b in 0..n - 1 {
        for a in 0..n - 1 {
            faces.push(vec![at(a, b), at(a + 1, b), at(a + 1, b + 1), at(a, b + 1)]);
        }
    }
    ControlMesh::from_polygons(positions, &faces)
}

fn height(a: f64, b: f64) -> f64 {
    (1.3 * a).sin() + 0.4 * (0.7 * b).cos() + 0.05 * a * b
}

/// The centred uniform quadratic B-spline and its derivative.
fn bspline(t: f64) -> (f64, f64) {
    let s = t.abs();
    if s <= 0.5 {
        (0.75 - t * t, -2.0 * t)
    } else if s <= 1.5 {
        (0.5 * (1.5 - s).powi(2), -(1.5 - s) * t.signum())
    } else {
        (0.0, 0.0)
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
    let dot: f64 = (0..3).map(|k| a[k] * b[k]).sum();
    let cross = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    cross.iter().map(|x| x * x).sum::<f64>().sqrt().atan2(dot)
}

const SAMPLES: [f64; 7] = [0.0, 0.1, 0.25, 0.37, 0.5, 0.8, 1.0];

#[test]
fn a_regular_grid_is_the_biquadratic_b_spline_of_its_control_net() {
    let n = 7;
    let mesh = grid(n);
    let ev = DooSabinEvaluator::new(&mesh).unwrap();
    let t = Topology::from_mesh(&mesh).unwrap();
    let interior = |x: u32| {
        let (a, b) = (x as usize % n, x as usize / n);
        (1..n - 1).contains(&a) && (1..n - 1).contains(&b)
    };
    let mut worst = 0.0f64;
    let mut checked = 0;
    for f in 0..mesh.num_faces() {
        let fv = t.face_vertices(f);
        for i in 0..4 {
            if !interior(fv[i]) {
                continue;
            }
            let p = |k: usize| mesh.positions[fv[(i + k) % 4] as usize];
            let (c, next, prev) = (p(0), p(1), p(3));
            for &u in &SAMPLES {
                for &v in &SAMPLES {
                    let x = c[0] + 0.5 * u * (next[0] - c[0]) + 0.5 * v * (prev[0] - c[0]);
                    let y = c[1] + 0.5 * u * (next[1] - c[1]) + 0.5 * v * (prev[1] - c[1]);
                    let (mut z, mut zx, mut zy) = (0.0, 0.0, 0.0);
                    for q in &mesh.positions {
                        let (bx, dx) = bspline(x - q[0]);
                        let (by, dy) = bspline(y - q[1]);
                        z += q[2] * bx * by;
                        zx += q[2] * dx * by;
                        zy += q[2] * bx * dy;
                    }
                    let s = ev.evaluate(f, i, u, v).unwrap();
                    worst = worst.max(dist(s.position, [x, y, z]));
                    let (du, dv) = s.derivatives.unwrap();
                    let (ex, ey) = (
                        [0.5 * (next[0] - c[0]), 0.5 * (next[1] - c[1])],
                        [0.5 * (prev[0] - c[0]), 0.5 * (prev[1] - c[1])],
                    );
                    let du_expected = [ex[0], ex[1], zx * ex[0] + zy * ex[1]];
                    let dv_expected = [ey[0], ey[1], zx * ey[0] + zy * ey[1]];
                    worst = worst.max(dist(du, du_expected)).max(dist(dv, dv_expected));
                    checked += 1;
                }
            }
        }
    }
    assert!(checked > 1000);
    assert!(worst < 1e-13, "worst {worst:e}");
}

/// Every base face's centre is its centroid with `face_limit`'s normal, from all its corners.
fn check_face_centres(mesh: &ControlMesh) {
    let ev = DooSabinEvaluator::new(mesh).unwrap();
    let scale = mesh.bbox_diagonal();
    for f in 0..mesh.num_faces() {
        let corners: Vec<[f64; 3]> = mesh
            .face(f)
            .iter()
            .map(|&x| mesh.positions[x as usize])
            .collect();
        let (c, normal) = face_limit(&corners).unwrap();
        for i in 0..corners.len() {
            let s = ev.evaluate(f, i, 1.0, 1.0).unwrap();
            assert!(dist(s.position, c) < 1e-13 * scale, "face {f} corner {i}");
            let a = angle(s.normal.unwrap(), normal);
            assert!(a < 1e-9, "face {f} corner {i}: normal off by {a:e}");
        }
    }
}

/// A control vertex's limit ([`vertex_limits`] of level 0) is the limit at `(f, i, 0, 0)` from
/// every face `f` around it.
fn check_control_vertices(mesh: &ControlMesh) {
    let ev = DooSabinEvaluator::new(mesh).unwrap();
    let base = Level::from_mesh(mesh, Scheme::DooSabin).unwrap();
    let limits = vertex_limits(&base, false).unwrap();
    for f in 0..mesh.num_faces() {
        for (i, &x) in mesh.face(f).iter().enumerate() {
            let s = ev.evaluate(f, i, 0.0, 0.0).unwrap();
            let d = dist(s.position, limits[x as usize]);
            assert!(
                d < 1e-13 * mesh.bbox_diagonal(),
                "face {f} corner {i}: {d:e}"
            );
        }
    }
}

#[test]
fn face_centres_are_their_centroids() {
    for mesh in [
        shape("catmark_cube"),
        shape("catmark_pyramid"),
        shape("loop_icosahedron"),
        shape("loop_tetrahedron"),
        shape("catmark_xord_interior"),
        shape("catmark_xord_boundary"),
        pentagonal_prism(),
        open_fan(),
        spot(),
    ] {
        check_face_centres(&mesh);
        check_control_vertices(&mesh);
    }
}

/// The other boundary neighbour of boundary vertex `x` than `y`.
fn other_boundary_neighbour(t: &Topology, x: u32, y: u32) -> u32 {
    t.vertex_edges(x as usize)
        .iter()
        .filter(|&&e| t.is_boundary_edge(e as usize))
        .map(|&e| {
            let [a, b] = t.edge_vertices(e as usize);
            if a == x {
                b
            } else {
                a
            }
        })
        .find(|&z| z != y)
        .unwrap()
}

/// On every boundary edge the limit is the uniform quadratic B-spline of the boundary polygon.
fn check_boundary_curve(mesh: &ControlMesh) -> usize {
    let ev = DooSabinEvaluator::new(mesh).unwrap();
    let t = Topology::from_mesh(mesh).unwrap();
    let mut checked = 0;
    for f in 0..mesh.num_faces() {
        let fv = t.face_vertices(f);
        let n = fv.len();
        for i in 0..n {
            let x = fv[i];
            for (leaving, y) in [(true, fv[(i + 1) % n]), (false, fv[(i + n - 1) % n])] {
                let Some(e) = t.find_edge(x, y) else { continue };
                if !t.is_boundary_edge(e as usize) {
                    continue;
                }
                let z = other_boundary_neighbour(&t, x, y);
                let p = |k: u32| mesh.positions[k as usize];
                for &w in &SAMPLES {
                    let (bs, _) = quadratic_basis(0.5 + 0.5 * w);
                    let expected: [f64; 3] = std::array::from_fn(|c| {
                        bs[0] * p(z)[c] + bs[1] * p(x)[c] + bs[2] * p(y)[c]
                    });
                    let (u, v) = if leaving { (w, 0.0) } else { (0.0, w) };
                    let s = ev.evaluate(f, i, u, v).unwrap();
                    let d = dist(s.position, expected);
                    assert!(d < 1e-13, "face {f} corner {i} at ({u}, {v}): {d:e}");
                    checked += 1;
                }
            }
        }
    }
    checked
}

#[test]
fn the_boundary_is_the_quadratic_b_spline_of_the_boundary_polygon() {
    let total: usize = [
        grid(5),
        shape("catmark_xord_boundary"),
        shape("catmark_tent"),
        shape("catmark_flap"),
        open_fan(),
    ]
    .iter()
    .map(check_boundary_curve)
    .sum();
    assert!(total > 300, "{total}");
}

/// How far two samples of one point differ: in position, and in normal (radians; the limit is
/// tangent-plane continuous), where both have one.
fn gap(a: &DooSabinSample, b: &DooSabinSample) -> f64 {
    let turn = match (a.normal, b.normal) {
        (Some(x), Some(y)) => angle(x, y),
        (None, None) => 0.0,
        _ => f64::INFINITY,
    };
    dist(a.position, b.position).max(turn)
}

/// Shared sides of corner quads, evaluated from both owners (positions and normals).
fn check_continuity(mesh: &ControlMesh) -> f64 {
    let ev = DooSabinEvaluator::new(mesh).unwrap();
    let t = Topology::from_mesh(mesh).unwrap();
    let mut worst = 0.0f64;
    for f in 0..mesh.num_faces() {
        let fv = t.face_vertices(f);
        let n = fv.len();
        for i in 0..n {
            // Inside the face: (f, i, 1, s) is (f, i + 1, s, 1).
            // Across the leaving edge: (f, i, s, 0) is (g, j, 0, s).
            let e = t.find_edge(fv[i], fv[(i + 1) % n]).unwrap();
            let across = t
                .edge_faces(e as usize)
                .into_iter()
                .find(|&g| g != f as u32 && g != crate::mesh::INVALID);
            for &s in &SAMPLES {
                let a = ev.evaluate(f, i, 1.0, s).unwrap();
                let b = ev.evaluate(f, (i + 1) % n, s, 1.0).unwrap();
                worst = worst.max(gap(&a, &b));
                if let Some(g) = across {
                    let j = t
                        .face_vertices(g as usize)
                        .iter()
                        .position(|&x| x == fv[i])
                        .unwrap();
                    let a = ev.evaluate(f, i, s, 0.0).unwrap();
                    let b = ev.evaluate(g as usize, j, 0.0, s).unwrap();
                    worst = worst.max(gap(&a, &b));
                }
            }
        }
    }
    worst
}

#[test]
fn owners_of_a_shared_side_agree() {
    for (name, mesh) in [
        ("cube", shape("catmark_cube")),
        ("pyramid", shape("catmark_pyramid")),
        ("icosahedron", shape("loop_icosahedron")),
        ("xord_boundary", shape("catmark_xord_boundary")),
        ("prism", pentagonal_prism()),
        ("open fan", open_fan()),
        ("spot", spot()),
    ] {
        let worst = check_continuity(&mesh);
        eprintln!("{name}: shared sides differ by {worst:.1e}");
        assert!(worst < 1e-12 * mesh.bbox_diagonal(), "{name}: {worst:e}");
    }
}

/// The exact limit at a face's centre: its centroid, or its boundary edge's midpoint.
fn centre_of(level: &Level, boundary: &[bool], g: usize) -> [f64; 3] {
    let fv = level.topology.face_vertices(g);
    let face: Vec<Point> = fv
        .iter()
        .map(|&x| Point {
            p: level.positions[x as usize],
            boundary: boundary[x as usize],
        })
        .collect();
    centre_sample(&face).unwrap().position
}

/// Per level `1..=depth`: the largest distance between a face's exact centre and the evaluation
/// at its domain point, between a vertex's [`vertex_limits`] and the evaluation at its domain
/// point (real vertices and boundary points), and between a real vertex and its limit.
fn track(mesh: &ControlMesh, depth: usize) -> Vec<[f64; 3]> {
    let ev = DooSabinEvaluator::new(mesh).unwrap();
    let domains = DomainRefinement::new(mesh, depth).unwrap();
    let uniform = refine_uniform(mesh, Scheme::DooSabin, depth).unwrap();
    let at = |p: DomainPoint| {
        ev.evaluate(p.face as usize, p.corner as usize, p.uv[0], p.uv[1])
            .unwrap()
            .position
    };
    let mut out = Vec::new();
    for k in 1..=depth {
        let level = domains.level(k);
        // The levels here are refine_uniform's.
        assert_eq!(level.positions, uniform.level(k).positions);
        let boundary = domains.boundary_points(k);
        let mut worst = [0.0f64; 3];
        for g in 0..level.num_faces() {
            let exact = centre_of(level, &boundary, g);
            worst[0] = worst[0].max(dist(at(domains.face_point(k, g).unwrap()), exact));
        }
        let limits = vertex_limits(level, true).unwrap();
        for (x, limit) in limits.iter().enumerate() {
            let p = at(domains.vertex_point(k, x).unwrap());
            worst[1] = worst[1].max(dist(p, *limit));
            if domains.square(k, x).is_some() {
                worst[2] = worst[2].max(dist(p, level.positions[x]));
            }
        }
        out.push(worst);
    }
    out
}

#[test]
fn refined_levels_converge_to_the_evaluation() {
    for (name, mesh, depth) in [
        ("pyramid", shape("catmark_pyramid"), 6),
        ("prism", pentagonal_prism(), 7),
        ("xord_boundary", shape("catmark_xord_boundary"), 5),
        ("open fan", open_fan(), 6),
        ("spot", spot(), 4),
    ] {
        let rows = track(&mesh, depth);
        let scale = mesh.bbox_diagonal();
        for (k, row) in rows.iter().enumerate() {
            eprintln!(
                "{name} level {}: face centres {:.1e}, vertex limits {:.1e}, vertices {:.3e}",
                k + 1,
                row[0] / scale,
                row[1] / scale,
                row[2] / scale
            );
            assert!(row[0] < 1e-12 * scale, "{name} level {}: {row:?}", k + 1);
            assert!(row[1] < 1e-12 * scale, "{name} level {}: {row:?}", k + 1);
        }
        // Vertices approach their limits at O(h) next to an extraordinary face (its nested
        // f-faces shrink by half per level; O(h²) elsewhere), and at (3/4)^k next to a boundary
        // vertex of one face (the strip triangle's real child is 3/4 r + 1/4 of its boundary
        // edge's midpoint).
        for w in rows.windows(2).skip(1) {
            let ratio = w[0][2] / w[1][2];
            assert!(ratio > 1.25, "{name}: vertex distance ratio {ratio}");
        }
    }
}

#[test]
fn points_near_an_extraordinary_centre_approach_it() {
    let mesh = pentagonal_prism();
    let ev = DooSabinEvaluator::new(&mesh).unwrap();
    let centre = ev.evaluate(0, 2, 1.0, 1.0).unwrap();
    assert!(centre.derivatives.is_none());
    let mut last = f64::INFINITY;
    for k in 1..40 {
        let d = 0.5f64.powi(k);
        let s = ev.evaluate(0, 2, 1.0 - d, 1.0 - 0.3 * d).unwrap();
        let gap = dist(s.position, centre.position);
        assert!(gap < last, "{k}");
        last = gap;
        let turn = angle(s.normal.unwrap(), centre.normal.unwrap());
        eprintln!("2^-{k} from the centre: distance {gap:.3e}, normal turned {turn:.3e}");
        // The normal turns by O(d) all the way in: each ring is recentred on its vertex, so
        // rounding stays relative to the ring's size (0.44 d at 2^-1, 0.98 d at 2^-39).
        assert!(turn < 2.0 * d, "2^-{k}: normal turned {turn:e}");
    }
    assert!(last < 1e-10);
    // Within 2^−MAX_DEPTH of a v-face's centre (the prism's vertices have valence 3, their
    // v-faces are triangles at (0, 0)): the centre itself, after MAX_DEPTH steps.
    let vertex = ev.evaluate(0, 2, 0.0, 0.0).unwrap();
    assert!(vertex.derivatives.is_none());
    let s = ev.evaluate(0, 2, 1e-300, 0.0).unwrap();
    assert!(
        dist(s.position, vertex.position) < 1e-15,
        "{s:?} {vertex:?}"
    );
    assert!(s.derivatives.is_none());
    let s = ev.evaluate(0, 2, 2f64.powi(-60), 0.0).unwrap();
    assert!(s.derivatives.is_some());
    assert!(dist(s.position, vertex.position) < 1e-15);
}

#[test]
fn bad_domain_points_are_named() {
    let ev = DooSabinEvaluator::new(&pentagonal_prism()).unwrap();
    assert!(matches!(
        ev.evaluate(7, 0, 0.5, 0.5),
        Err(EvalError::FaceOutOfRange { face: 7, count: 7 })
    ));
    assert!(matches!(
        ev.evaluate(2, 4, 0.5, 0.5),
        Err(EvalError::CornerOutOfRange {
            face: 2,
            corner: 4,
            size: 4
        })
    ));
    for (u, v) in [(1.5, 0.0), (0.0, -0.1), (f64::NAN, 0.5)] {
        assert!(matches!(
            ev.evaluate(0, 0, u, v),
            Err(EvalError::ParamOutOfRange { .. })
        ));
    }
    // An edge of three faces: the dual refiner's named refusal.
    let fin = ControlMesh::from_polygons(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [0.0, 1.0, 0.0],
            [0.0, -1.0, 0.0],
            [0.0, 0.0, 1.0],
        ],
        &[[0u32, 1, 2], [1, 0, 3], [0, 1, 4]],
    );
    assert!(matches!(
        DooSabinEvaluator::new(&fin),
        Err(EvalError::Topology(_))
    ));
}

/// Points approaching a boundary vertex's strip-face centre (a boundary vertex of one face, of
/// three faces) converge to it, at the rate of the strip's real children: (3/4)^k for one
/// face (see the convergence test).
#[test]
fn points_near_a_boundary_centre_approach_it() {
    let mesh = open_fan();
    let ev = DooSabinEvaluator::new(&mesh).unwrap();
    let t = Topology::from_mesh(&mesh).unwrap();
    let boundary = boundary_vertices(&t);
    let mut checked = [0usize; 4];
    for f in 0..mesh.num_faces() {
        for (i, &x) in mesh.face(f).iter().enumerate() {
            let valence = t.vertex_faces(x as usize).len();
            if !boundary[x as usize] || valence == 2 {
                continue;
            }
            let centre = ev.evaluate(f, i, 0.0, 0.0).unwrap();
            assert!(centre.normal.is_none() && centre.derivatives.is_none());
            let mut last = f64::INFINITY;
            for k in 1..=60 {
                let d = 0.5f64.powi(k);
                let s = ev.evaluate(f, i, d, 0.7 * d).unwrap();
                let gap = dist(s.position, centre.position);
                assert!(
                    gap < last || gap < 1e-14,
                    "face {f} corner {i} at 2^-{k}: {gap:e}"
                );
                last = gap;
            }
            eprintln!("boundary vertex {x} of {valence} faces: 2^-60 away, {last:.1e}");
            assert!(last < 1e-6 * mesh.bbox_diagonal());
            checked[valence.min(3)] += 1;
        }
    }
    assert!(checked[1] >= 3 && checked[3] >= 2, "{checked:?}");
}
