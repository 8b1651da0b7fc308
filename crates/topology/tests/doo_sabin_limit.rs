//! The Doo-Sabin limit plan ([`topology::patches::doo_sabin_limit`]) against the exact
//! evaluator ([`topology::limit::doo_sabin_eval`]): regular patches exact, bilinear end caps
//! converging with the isolation level, the canonical curves shared bit for bit by both sides
//! of every edge (transitions included), the patch counts per level, and named errors.

use std::collections::HashMap;
use topology::limit::doo_sabin_eval::DooSabinEvaluator;
use topology::mesh::{EdgeCrease, VertexCorner};
use topology::patches::adaptive::{AdaptivePlan, EdgeKind, PatchKind};
use topology::patches::doo_sabin_limit::{plan_doo_sabin, plan_doo_sabin_within};
use topology::refine::doo_sabin::{boundary_vertices, refine_dual};
use topology::refine::Level;
use topology::{load_obj, ControlMesh, Scheme, TopologyError};

const SPOT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../assets/spot_control_mesh.obj"
);

fn cube() -> ControlMesh {
    let p = vec![
        [0., 0., 0.],
        [1., 0., 0.],
        [1., 1., 0.],
        [0., 1., 0.],
        [0., 0., 1.],
        [1., 0., 1.],
        [1., 1., 1.],
        [0., 1., 1.],
    ];
    let faces = [
        [0u32, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ];
    ControlMesh::from_polygons(p, &faces)
}

/// A pentagonal prism whose top is a fan of triangles around a valence-5 vertex: closed, with
/// triangles, a pentagon, and vertices of valence 3, 4 and 5.
fn capped_prism() -> ControlMesh {
    let mut positions = Vec::new();
    for z in [0.0, 1.0] {
        for k in 0..5 {
            let a = std::f64::consts::TAU * k as f64 / 5.0;
            positions.push([a.cos(), a.sin() * (1.0 + 0.2 * z), z + 0.1 * k as f64]);
        }
    }
    positions.push([0.1, 0.0, 1.6]);
    let mut faces: Vec<Vec<u32>> = vec![vec![4, 3, 2, 1, 0]];
    for k in 0..5u32 {
        let k1 = (k + 1) % 5;
        faces.push(vec![k, k1, k1 + 5, k + 5]);
        faces.push(vec![k + 5, k1 + 5, 10]);
    }
    ControlMesh::from_polygons(positions, &faces)
}

/// A 4×4 grid of quads with a bump: a boundary, whose corners are extraordinary (the strip
/// face of a vertex of one face is a triangle).
fn grid() -> ControlMesh {
    let n = 5;
    let mut positions = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let (x, y) = (i as f64, j as f64);
            positions.push([x, y + 0.1 * x, ((x - 2.0) * (y - 1.5)).sin() * 0.4]);
        }
    }
    let mut faces = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = j * n + i;
            faces.push([v, v + 1, v + n + 1, v + n]);
        }
    }
    ControlMesh::from_polygons(positions, &faces)
}

/// An open fan of four quads and a triangle around an interior valence-5 vertex (a boundary
/// with vertices of one and two faces), and a vertex on no face.
fn open_fan() -> ControlMesh {
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

fn meshes() -> Vec<(&'static str, ControlMesh)> {
    vec![
        ("cube", cube()),
        ("capped prism", capped_prism()),
        ("grid", grid()),
        ("open fan", open_fan()),
        ("spot", load_obj(SPOT).expect("spot loads")),
    ]
}

fn dist(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// Largest distance over a 5×5 grid of each patch between the plan and the exact limit at the
/// patch's domain point, over the bounding-box diagonal: (regular patches, end caps).
fn deviations(mesh: &ControlMesh, plan: &AdaptivePlan, ev: &DooSabinEvaluator) -> (f64, f64) {
    let verts = plan.apply(&mesh.positions);
    let d = mesh.bbox_diagonal();
    let (mut regular, mut caps) = (0.0f64, 0.0f64);
    for (p, pa) in plan.patches.iter().enumerate() {
        for (a, b) in (0..25).map(|k| ((k % 5) as f64 / 4.0, (k / 5) as f64 / 4.0)) {
            let (sub, s, t) = pa.base_param(a, b);
            let exact = ev
                .evaluate(pa.base_face as usize, sub as usize, s, t)
                .expect("domain point")
                .position;
            let err = dist(&plan.evaluate(&verts, p, a, b).position, &exact) / d;
            match pa.kind {
                PatchKind::Regular => regular = regular.max(err),
                _ => caps = caps.max(err),
            }
        }
    }
    (regular, caps)
}

#[test]
fn regular_patches_are_the_exact_limit_and_caps_converge() {
    for (name, mesh) in meshes() {
        let ev = DooSabinEvaluator::new(&mesh).expect("evaluator");
        let mut last = f64::INFINITY;
        for iso in 1..=4 {
            let plan = plan_doo_sabin(&mesh, iso).expect("plan");
            let (regular, caps) = deviations(&mesh, &plan, &ev);
            println!("{name}: isolation {iso}: regular {regular:.2e}, end caps {caps:.2e}");
            assert!(
                regular <= 1e-9,
                "{name} iso {iso}: regular off by {regular:e}"
            );
            assert!(
                caps > 0.0 && caps < last,
                "{name} iso {iso}: caps {caps:e} after {last:e}"
            );
            last = caps;
        }
    }
}

/// A point of a patch edge at curve parameter `s` of its part `k` (the curve's own direction):
/// the patch's edge parameter, exact for dyadic `s`.
fn edge_param(kind: EdgeKind, k: usize, reversed: bool, s: f64) -> f64 {
    let local = if reversed { 1.0 - s } else { s };
    match kind {
        EdgeKind::Coarse => 0.5 * (local + k as f64),
        _ => local,
    }
}

/// Every patch edge reads its curves at the same points the curves give (bit for bit, at
/// dyadic parameters), so two sides of one curve coincide; the patch's own edge is its curves
/// (Coons caps exactly, regular patches to rounding); every curve has one side (a boundary)
/// or two, at levels at most one apart; corners meet.
fn check_watertight(name: &str, mesh: &ControlMesh, plan: &AdaptivePlan) {
    let verts = plan.apply(&mesh.positions);
    let d = mesh.bbox_diagonal();
    let mut sides: HashMap<u32, Vec<u8>> = HashMap::new();
    for (p, pa) in plan.patches.iter().enumerate() {
        for (e, edge) in pa.edges.iter().enumerate() {
            let parts = if edge.kind == EdgeKind::Coarse { 2 } else { 1 };
            for k in 0..parts {
                let c = edge.curves[k] as usize;
                sides.entry(c as u32).or_default().push(pa.level);
                for s in (0..=8).map(|i| i as f64 / 8.0) {
                    let t = edge_param(edge.kind, k, edge.reversed[k], s);
                    let (on_edge, _) = plan.edge_sample(&verts, p, e, t);
                    let on_curve = plan.curve_point(&verts, c, s);
                    assert_eq!(
                        on_edge, on_curve,
                        "{name}: patch {p} edge {e} part {k} at {s}"
                    );
                    let [u, v] = topology::patches::adaptive::edge_param(4, e, t);
                    let own = plan.evaluate(&verts, p, u, v).position;
                    let err = dist(&own, &on_curve) / d;
                    assert!(
                        err <= 1e-12,
                        "{name}: patch {p} ({:?}) edge {e}: {err:e}",
                        pa.kind
                    );
                }
            }
            assert_eq!(
                pa.transition_mask & (1 << e) != 0,
                edge.kind == EdgeKind::Coarse,
                "{name}"
            );
        }
        // Consecutive edges meet at one canonical corner.
        let ends: Vec<(u32, u32)> = pa
            .edges
            .iter()
            .map(|e| {
                let last = usize::from(e.kind == EdgeKind::Coarse);
                let point = |k: usize, end: bool| {
                    let c = plan.curves[e.curves[k] as usize];
                    if e.reversed[k] != end {
                        c[3]
                    } else {
                        c[0]
                    }
                };
                (point(0, false), point(last, true))
            })
            .collect();
        for k in 0..4 {
            assert_eq!(ends[k].1, ends[(k + 1) % 4].0, "{name}: patch {p} corner");
        }
        if pa.kind == PatchKind::Bilinear {
            let starts: Vec<u32> = ends.iter().map(|e| e.0).collect();
            assert_eq!(pa.control_points.to_vec(), starts, "{name}: cap corners");
        }
    }
    let closed = {
        let t = topology::mesh::Topology::from_mesh(mesh).unwrap();
        (0..t.num_edges()).all(|e| !t.is_boundary_edge(e))
    };
    assert_eq!(sides.len(), plan.curves.len(), "{name}: an unused curve");
    // Distinct canonical corners are distinct limit points.
    let mut corners: Vec<[f64; 3]> = (plan.first_corner..plan.first_curve_point)
        .map(|c| verts[c as usize])
        .collect();
    corners.sort_by(|a, b| a[0].total_cmp(&b[0]));
    for (i, a) in corners.iter().enumerate() {
        for b in corners[i + 1..]
            .iter()
            .take_while(|b| b[0] - a[0] <= 1e-12 * d)
        {
            assert!(
                dist(a, b) > 1e-12 * d,
                "{name}: two corner ids at one point"
            );
        }
    }
    for (c, levels) in &sides {
        let n = levels.len();
        assert!(
            n == 2 || (n == 1 && !closed),
            "{name}: curve {c} has {n} sides"
        );
        let (lo, hi) = (levels.iter().min().unwrap(), levels.iter().max().unwrap());
        assert!(hi - lo <= 1, "{name}: curve {c} joins levels {lo} and {hi}");
    }
}

#[test]
fn shared_edges_are_bit_identical() {
    for (name, mesh) in meshes() {
        for iso in 1..=4 {
            let plan = plan_doo_sabin(&mesh, iso).expect("plan");
            check_watertight(&format!("{name} iso {iso}"), &mesh, &plan);
        }
    }
}

/// Transitions exist where a regular patch meets a split square, and both sides agree on them.
#[test]
fn transitions_pair_coarse_and_fine_edges() {
    let mesh = capped_prism();
    let plan = plan_doo_sabin(&mesh, 3).expect("plan");
    let count = |kind: EdgeKind| {
        plan.patches
            .iter()
            .flat_map(|p| p.edges.iter())
            .filter(|e| e.kind == kind)
            .count()
    };
    let (coarse, fine) = (count(EdgeKind::Coarse), count(EdgeKind::Fine));
    assert!(coarse > 0, "no transitions");
    assert_eq!(fine, 2 * coarse, "each coarse edge has two fine halves");
    for pa in plan.patches.iter() {
        for e in pa.edges.iter().filter(|e| e.kind == EdgeKind::Fine) {
            assert_ne!(e.curves[0], e.curves[1]);
            // The sibling half continues this one along the coarse edge, in the patch's
            // edge direction.
            let ends = |k: usize| {
                let c = plan.curves[e.curves[k] as usize];
                if e.reversed[k] {
                    (c[3], c[0])
                } else {
                    (c[0], c[3])
                }
            };
            let ((own_start, own_end), (sib_start, sib_end)) = (ends(0), ends(1));
            assert!(sib_start == own_end || sib_end == own_start);
            // The sibling half is a curve some coarse edge holds with this one.
            assert!(plan.patches.iter().any(|q| q
                .edges
                .iter()
                .any(|c| c.kind == EdgeKind::Coarse
                    && c.curves.contains(&e.curves[0])
                    && c.curves.contains(&e.curves[1]))));
        }
    }
}

#[test]
fn blocks_read_only_earlier_vertices_and_patches_tile_the_corner_quads() {
    for (name, mesh) in meshes() {
        let plan = plan_doo_sabin(&mesh, 3).expect("plan");
        let mut next = plan.num_base_vertices;
        assert_eq!(plan.steps.len(), 3, "{name}");
        for b in plan.steps.iter().chain(std::iter::once(&plan.local_points)) {
            assert_eq!(b.first_vertex, next, "{name}: blocks are contiguous");
            for r in 0..b.table.len() {
                let (idx, w) = b.table.stencil(r);
                assert!(
                    idx.iter().all(|&i| i < b.first_vertex),
                    "{name}: reads itself"
                );
                assert!(idx.windows(2).all(|x| x[0] < x[1]), "{name}: unsorted row");
                let sum: f64 = w.iter().sum();
                assert!(
                    !idx.is_empty() && (sum - 1.0).abs() < 1e-12,
                    "{name}: sum {sum}"
                );
            }
            next += b.table.len() as u32;
        }
        assert_eq!(next, plan.first_regular_corner, "{name}");
        let regular_from = (plan.first_regular_corner - plan.first_corner) as usize;
        for (k, &[p, _]) in plan.corner_owners.iter().enumerate() {
            let regular = plan.patches[p as usize].kind == PatchKind::Regular;
            assert_eq!(regular, k >= regular_from, "{name}: corner {k}'s owner");
        }
        assert_eq!(
            plan.first_curve_point,
            plan.first_corner + plan.corner_owners.len() as u32
        );
        for (c, curve) in plan.curves.iter().enumerate() {
            assert_eq!(curve[1], plan.first_curve_point + 2 * c as u32);
            assert!(curve[0] < curve[3], "{name}: curve ends not ascending");
        }
        assert_eq!(
            plan.num_vertices,
            plan.first_curve_point + 2 * plan.curves.len() as u32
        );
        let mut area: HashMap<(u32, u8), f64> = HashMap::new();
        for pa in &plan.patches {
            let n = if pa.kind == PatchKind::Regular { 16 } else { 4 };
            assert_eq!(pa.control_points.len(), n);
            *area.entry((pa.base_face, pa.sub_face)).or_default() += pa.size * pa.size;
        }
        let corners: usize = mesh.faces().map(|f| f.len()).sum();
        assert_eq!(area.len(), corners, "{name}: every corner quad has patches");
        assert!(area.values().all(|a| (a - 1.0).abs() < 1e-12), "{name}");
    }
}

/// The extraordinary faces of level 1 (non-quads), by their real corners (a strip face's
/// boundary points own no square), and the level-1 squares that hold one or two of them.
fn extraordinary(mesh: &ControlMesh) -> (Vec<usize>, usize, usize) {
    let base = Level::from_mesh(mesh, Scheme::DooSabin).unwrap();
    let step = refine_dual(&base, true).unwrap();
    let t = &step.level.topology;
    let boundary = boundary_vertices(t);
    let mut sizes = Vec::new();
    let mut per_vertex = vec![0usize; t.num_vertices()];
    for f in 0..t.num_faces() {
        let fv = t.face_vertices(f);
        if fv.len() == 4 {
            continue;
        }
        let real: Vec<u32> = fv
            .iter()
            .copied()
            .filter(|&v| !boundary[v as usize])
            .collect();
        sizes.push(real.len());
        for v in real {
            per_vertex[v as usize] += 1;
        }
    }
    sizes.sort_unstable();
    let squares = per_vertex.iter().filter(|&&n| n > 0).count();
    let two = per_vertex.iter().filter(|&&n| n == 2).count();
    (sizes, squares, two)
}

/// At isolation `L ≥ 2` every extraordinary face has one end cap per real corner, all around
/// its centre (the one cap corner on no regular patch); a split square gives three regular
/// quadrants from level 3 on, `4 − e` at level 2 (`e` its extraordinary faces).
#[test]
fn end_caps_per_extraordinary_face_and_level_counts() {
    for (name, mesh) in meshes() {
        let (sizes, irregular, doubly) = extraordinary(&mesh);
        let total: usize = sizes.iter().sum();
        let corners: usize = mesh.faces().map(|f| f.len()).sum();
        let one = plan_doo_sabin(&mesh, 1).expect("plan");
        assert_eq!(one.level_stats[1].end_caps as usize, irregular, "{name}");
        assert_eq!(
            one.level_stats[1].regular as usize,
            corners - irregular,
            "{name}"
        );
        for iso in 2..=4 {
            let plan = plan_doo_sabin(&mesh, iso).expect("plan");
            let s = &plan.level_stats;
            println!("{name} iso {iso}: {s:?}");
            assert_eq!(s[1].regular as usize, corners - irregular, "{name}");
            assert_eq!(s[2].regular as usize, 4 * irregular - total, "{name}");
            assert_eq!(total, irregular + doubly);
            for (k, level) in s.iter().enumerate().skip(3) {
                assert_eq!(level.regular as usize, 3 * total, "{name} level {k}");
            }
            assert_eq!(s[iso as usize].end_caps as usize, total, "{name}");
            assert!(s.iter().take(iso as usize).all(|l| l.end_caps == 0));
            assert!(
                s.iter().all(|l| l.faces as u64 <= l.uniform_faces),
                "{name}"
            );
            assert_eq!(
                s.iter().map(|l| l.regular + l.end_caps).sum::<u32>() as usize,
                plan.patches.len()
            );
            // Caps around each centre: the centres are the corners with limit rows.
            let regular_from = plan.first_regular_corner;
            let mut around: HashMap<u32, usize> = HashMap::new();
            for pa in plan
                .patches
                .iter()
                .filter(|p| p.kind == PatchKind::Bilinear)
            {
                let centres: Vec<u32> = pa
                    .control_points
                    .iter()
                    .copied()
                    .filter(|&c| c < regular_from)
                    .collect();
                assert_eq!(centres.len(), 1, "{name}: a cap with {centres:?} centres");
                *around.entry(centres[0]).or_default() += 1;
            }
            let mut counts: Vec<usize> = around.into_values().collect();
            counts.sort_unstable();
            assert_eq!(
                counts, sizes,
                "{name} iso {iso}: caps per extraordinary face"
            );
        }
    }
}

#[test]
fn bad_input_is_a_named_error() {
    let mesh = cube();
    for iso in [0, 9, 100] {
        let e = plan_doo_sabin(&mesh, iso).unwrap_err();
        assert!(
            matches!(e, TopologyError::IsolationOutOfRange { isolation } if isolation == iso),
            "{e}"
        );
    }
    let mut m = mesh.clone();
    m.creases.push(EdgeCrease {
        vertices: [0, 1],
        sharpness: 2.0,
    });
    let e = plan_doo_sabin(&m, 2).unwrap_err();
    assert!(
        matches!(e, TopologyError::DooSabinCrease { v0: 0, v1: 1, .. }),
        "{e}"
    );
    let mut m = mesh.clone();
    m.corners.push(VertexCorner {
        vertex: 3,
        sharpness: 1.0,
    });
    let e = plan_doo_sabin(&m, 2).unwrap_err();
    assert!(
        matches!(e, TopologyError::DooSabinCorner { vertex: 3, .. }),
        "{e}"
    );
    let mut m = mesh.clone();
    m.holes.push(2);
    let e = plan_doo_sabin(&m, 2).unwrap_err();
    assert!(matches!(e, TopologyError::DooSabinHole { face: 2 }), "{e}");
    // Three quads on one edge.
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [1.0, -1.0, 0.0],
        [0.0, -1.0, 0.0],
        [1.0, 0.0, 1.0],
        [0.0, 0.0, 1.0],
    ];
    let three = ControlMesh::from_polygons(p, &[[0u32, 1, 2, 3], [1, 0, 5, 4], [0, 1, 6, 7]]);
    let e = plan_doo_sabin(&three, 2).unwrap_err();
    assert!(
        matches!(e.root(), TopologyError::NonManifoldEdge { .. }),
        "{e}"
    );
    // Two quads sharing only a vertex (a bowtie).
    let p = vec![
        [0.0, 0.0, 0.0],
        [1.0, 0.0, 0.0],
        [1.0, 1.0, 0.0],
        [0.0, 1.0, 0.0],
        [-1.0, 0.0, 0.0],
        [-1.0, -1.0, 0.0],
        [0.0, -1.0, 0.0],
    ];
    let bowtie = ControlMesh::from_polygons(p, &[[0u32, 1, 2, 3], [0, 4, 5, 6]]);
    let e = plan_doo_sabin(&bowtie, 2).unwrap_err();
    assert!(
        matches!(e.root(), TopologyError::NonManifoldVertex { vertex: 0, .. }),
        "{e}"
    );
    // A 300-gon: corners are numbered with 8 bits.
    let ring: Vec<[f64; 3]> = (0..300)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / 300.0;
            [a.cos(), a.sin(), 0.0]
        })
        .collect();
    let big = ControlMesh::from_polygons(ring, &[(0..300u32).collect::<Vec<u32>>()]);
    let e = plan_doo_sabin(&big, 2).unwrap_err();
    assert!(
        matches!(
            e,
            TopologyError::AdaptiveFaceTooLarge { face: 0, size: 300 }
        ),
        "{e}"
    );
    assert!(plan_doo_sabin(&ControlMesh::default(), 2).is_err());
}

/// A plan projected past its bound on patches stops with a named error before the level that
/// would pass it; at the bound of its own size it is planned.
#[test]
fn a_plan_over_its_patch_bound_is_refused_by_name() {
    let mesh = capped_prism();
    let plan = plan_doo_sabin(&mesh, 4).expect("plan");
    let total = plan.patches.len() as u64;
    let within = plan_doo_sabin_within(&mesh, 4, total).expect("at its own size");
    assert_eq!(within.patches.len() as u64, total);
    let e = plan_doo_sabin_within(&mesh, 4, total - 1).unwrap_err();
    match e {
        TopologyError::DooSabinTooLarge {
            faces,
            isolation: 4,
            estimate,
            bound,
            ..
        } => assert!(
            faces == mesh.num_faces() && estimate > bound && bound == total - 1,
            "{e}"
        ),
        _ => panic!("{e}"),
    }
    assert!(e.to_string().contains("lower the isolation"), "{e}");
    let corners = mesh.face_vertices.len() as u64;
    let e = plan_doo_sabin_within(&mesh, 1, corners - 1).unwrap_err();
    let at_first = matches!(e, TopologyError::DooSabinTooLarge { level: 0, estimate, .. }
        if estimate == corners);
    assert!(at_first, "{e}");
}
