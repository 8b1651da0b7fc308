//! Non-manifold control meshes: OpenSubdiv's non-manifold regression shapes (and small cases
//! of each kind) split into manifold meshes, refined, and joined back into the input's levels
//! (`topology::mesh::manifold`, `topology::refine::joined`).
//!
//! Checked on their own: the split mesh is manifold; the input's counts (vertices + edges +
//! faces of the input's own non-manifold topology) are the joined level's; every copy of a
//! vertex sits where the vertex does at every level and in the limit; the rules the split
//! carries (sharp non-manifold edges, sharpened vertices, crease vertices). Against
//! OpenSubdiv: `refinement_and_limit_match_opensubdiv_far` compares refined and limit points
//! with baselines made by OpenSubdiv's Far (`tools/far-dump`).

use std::collections::{HashMap, HashSet};
use std::path::PathBuf;
use topology::limit::eval::{LimitScheme, LocalMesh};
use topology::mesh::manifold::{EdgeUse, ManifoldSplit};
use topology::mesh::Topology;
use topology::refine::joined::joined_vertices;
use topology::refine::refine_uniform;
use topology::{load_obj, ControlMesh, Scheme};

/// OpenSubdiv's non-manifold shapes, apart from tests/data's manifold `shapes/` (whose
/// whole-set tests hold every shape to manifold rules).
fn shapes_dir() -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/opensubdiv/nonmanifold")
}

/// The non-manifold regression shapes of tests/data.
const SHAPES: [&str; 10] = [
    "catmark_nonman_bareverts",
    "catmark_nonman_edge100",
    "catmark_nonman_edges",
    "catmark_nonman_quadpole8",
    "catmark_nonman_quadpole64",
    "catmark_nonman_verts",
    "catmark_val2_nonman",
    "loop_nonman_edge100",
    "loop_nonman_edges",
    "loop_nonman_verts",
];

fn shape(name: &str) -> (ControlMesh, Scheme) {
    let mesh = load_obj(shapes_dir().join(format!("{name}.obj"))).expect(name);
    (mesh, Scheme::from_shape_name(name).expect("scheme"))
}

/// The input's edges as OpenSubdiv's `Vtr` builds them, face by face: a vertex pair is one
/// edge, except that a vertex to itself is a new edge at each use, and so is a pair whose
/// edge was last used by the same face.
fn input_edges(mesh: &ControlMesh) -> usize {
    let mut latest: HashMap<[u32; 2], usize> = HashMap::new();
    let mut edges = 0;
    for (f, fv) in mesh.faces().enumerate() {
        for i in 0..fv.len() {
            let (a, b) = (fv[i], fv[(i + 1) % fv.len()]);
            let key = [a.min(b), a.max(b)];
            match latest.get_mut(&key) {
                Some(last) if a != b && *last != f => *last = f,
                Some(_) => edges += 1,
                None => {
                    edges += 1;
                    if a != b {
                        latest.insert(key, f);
                    }
                }
            }
        }
    }
    edges
}

#[test]
fn regression_shapes_split_into_manifold_meshes_that_refine_as_the_input() {
    for name in SHAPES {
        let (mesh, scheme) = shape(name);
        let split = ManifoldSplit::of(&mesh).expect(name);
        // Vertices no face uses are not non-manifold: OpenSubdiv keeps them, as this crate does.
        let bare = name.ends_with("bareverts");
        assert_eq!(split.report.any(), !bare, "{name}: {:?}", split.report);
        Topology::from_mesh(&split.mesh).unwrap_or_else(|e| panic!("{name}: split: {e}"));
        assert_eq!(split.mesh.num_faces(), mesh.num_faces(), "{name}");
        assert_eq!(
            split.mesh.positions.len(),
            mesh.positions.len() + split.report.copies,
            "{name}"
        );
        let r = refine_uniform(&split.mesh, scheme, 2).expect(name);
        let (joined, count) = joined_vertices(&r, &split, 1).expect(name);
        // Level 1 of the input: one vertex per vertex, edge and (Catmull-Clark) face.
        let faces = if scheme == Scheme::Loop {
            0
        } else {
            mesh.num_faces()
        };
        assert_eq!(
            count + known_shortfall(name, 1),
            mesh.positions.len() + input_edges(&mesh) + faces,
            "{name}: level 1 vertices"
        );
        assert_eq!(joined.len(), r.level(1).num_vertices(), "{name}");
        for level in 0..=2 {
            let (joined, _) = joined_vertices(&r, &split, level).expect(name);
            assert_copies_coincide(name, &joined, &r.level(level).positions, 1e-12);
        }
    }
}

/// Every group of vertices joined into one sits at one point (within `tol` of the diagonal).
fn assert_copies_coincide(name: &str, joined: &[u32], positions: &[[f64; 3]], tol: f64) {
    let diag = diagonal(positions);
    let mut first: HashMap<u32, [f64; 3]> = HashMap::new();
    for (v, &j) in joined.iter().enumerate() {
        let p = positions[v];
        let q = *first.entry(j).or_insert(p);
        let d = dist(p, q);
        assert!(
            d <= tol * diag,
            "{name}: vertex {v} is {d:e} from its copies"
        );
    }
}

fn dist(a: [f64; 3], b: [f64; 3]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

fn diagonal(points: &[[f64; 3]]) -> f64 {
    let (mut lo, mut hi) = ([f64::MAX; 3], [f64::MIN; 3]);
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    dist(lo, hi).max(f64::MIN_POSITIVE)
}

/// Limit positions of every vertex of a refined level (the exact evaluator's vertex limit);
/// a vertex no face uses keeps its position.
fn limit_of_level(
    level: &topology::refine::Level,
    scheme: Scheme,
    mesh: &ControlMesh,
) -> Vec<[f64; 3]> {
    let ls = LimitScheme::try_from(scheme).expect("limit scheme");
    let lm = LocalMesh::from_refined_level(level, ls, &mesh.options).expect("local mesh");
    (0..lm.num_vertices() as u32)
        .map(|v| {
            if level.topology.vertex_faces(v as usize).is_empty() {
                return level.positions[v as usize];
            }
            let p = lm.vertex_limit_exact(v).expect("limit");
            [p[0], p[1], p[2]]
        })
        .collect()
}

#[test]
fn copies_share_their_limit_points() {
    for name in SHAPES {
        let (mesh, scheme) = shape(name);
        let split = ManifoldSplit::of(&mesh).expect(name);
        let r = refine_uniform(&split.mesh, scheme, 1).expect(name);
        let (joined, _) = joined_vertices(&r, &split, 1).expect(name);
        let limit = limit_of_level(r.level(1), scheme, &mesh);
        assert_copies_coincide(name, &joined, &limit, 1e-12);
    }
}

/// Three quads on one edge: the edge is sharp (its midpoint at every level), its ends are
/// corners (one non-manifold edge each), and the quads' other edges keep the smooth rule.
#[test]
fn an_edge_of_three_faces_is_an_infinitely_sharp_crease() {
    let mesh = ControlMesh::from_polygons(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, -1.0, 0.0],
            [0.0, -1.0, 0.0],
            [1.0, 0.0, 1.0],
            [0.0, 0.0, 1.0],
        ],
        &[[0u32, 1, 2, 3], [1, 0, 5, 4], [0, 1, 6, 7]],
    );
    let split = ManifoldSplit::of(&mesh).expect("split");
    assert_eq!(split.non_manifold_edges, vec![([0, 1], EdgeUse::Shared)]);
    assert_eq!(split.report.shared_edges, 1);
    assert_eq!(split.report.non_manifold_vertices, 2);
    assert_eq!(
        split.report.sharpened, 2,
        "one non-manifold edge each: corners"
    );
    // Three sheets at each end: two copies each.
    assert_eq!(split.copies, vec![0, 0, 1, 1]);
    let r = refine_uniform(&split.mesh, Scheme::CatmullClark, 3).expect("refine");
    let (joined, count) = joined_vertices(&r, &split, 3).expect("joined");
    assert_copies_coincide("fan", &joined, &r.level(3).positions, 0.0);
    // The sharp edge's points lie on the segment (corners stay, midpoints of midpoints).
    let level = r.level(3);
    let on_edge = (0..level.num_vertices())
        .filter(|&v| {
            let p = level.positions[v];
            p[1].abs() < 1e-15 && p[2].abs() < 1e-15
        })
        .map(|v| joined[v])
        .collect::<HashSet<_>>();
    assert_eq!(on_edge.len(), 9, "8 segments of the edge at level 3");
    assert!(count < level.num_vertices());
}

/// Two faces traversing an edge the same way: sharp there, both ends corners; the split mesh
/// is consistently oriented.
#[test]
fn opposite_windings_meet_at_a_sharp_edge() {
    let mesh = ControlMesh::from_polygons(
        vec![
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.0],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, 0.0],
            [1.0, -1.0, 0.0],
            [0.0, -1.0, 0.0],
        ],
        &[[0u32, 1, 2, 3], [0, 1, 4, 5]],
    );
    let split = ManifoldSplit::of(&mesh).expect("split");
    assert_eq!(
        split.non_manifold_edges,
        vec![([0, 1], EdgeUse::OppositeWinding)]
    );
    assert_eq!(split.report.opposite_winding_edges, 1);
    assert_eq!(split.report.sharpened, 2);
    let topology = Topology::from_mesh(&split.mesh).expect("manifold");
    assert!(
        (0..topology.num_edges())
            .filter(|&e| topology.is_boundary_edge(e))
            .count()
            == 8
    );
}

/// A Möbius strip: one edge of the strip's seam meets with the same direction; the rest of
/// the strip is manifold and smooth.
#[test]
fn a_moebius_strip_refines() {
    let n = 8u32;
    let mut positions = Vec::new();
    for i in 0..n {
        let t = i as f64 / n as f64 * std::f64::consts::TAU;
        let w = (t / 2.0).cos() * 0.3;
        let h = (t / 2.0).sin() * 0.3;
        let r = 1.0 + w;
        positions.push([r * t.cos(), r * t.sin(), h]);
        let r = 1.0 - w;
        positions.push([r * t.cos(), r * t.sin(), -h]);
    }
    let mut faces = Vec::new();
    for i in 0..n {
        let (a, b) = (2 * i, 2 * i + 1);
        let (c, d) = if i + 1 < n {
            (2 * i + 2, 2 * i + 3)
        } else {
            (1, 0) // the half twist joins the strip's two sides
        };
        faces.push([a, c, d, b]);
    }
    let mesh = ControlMesh::from_polygons(positions, &faces);
    let split = ManifoldSplit::of(&mesh).expect("split");
    assert_eq!(split.report.opposite_winding_edges, 1);
    assert_eq!(split.report.shared_edges, 0);
    Topology::from_mesh(&split.mesh).expect("manifold");
    let r = refine_uniform(&split.mesh, Scheme::CatmullClark, 2).expect("refine");
    let (joined, _) = joined_vertices(&r, &split, 2).expect("joined");
    assert_copies_coincide("moebius", &joined, &r.level(2).positions, 1e-12);
}

/// Two cubes sharing one corner vertex (a pinch, no non-manifold edge): two fans, the vertex
/// an infinitely sharp corner in both copies; every other vertex as in a lone cube.
#[test]
fn a_pinched_vertex_is_a_corner_of_each_fan() {
    let cube = |o: [f64; 3], s: f64| -> Vec<[f64; 3]> {
        (0..8)
            .map(|i| {
                [
                    o[0] + s * f64::from(i & 1),
                    o[1] + s * f64::from((i >> 1) & 1),
                    o[2] + s * f64::from((i >> 2) & 1),
                ]
            })
            .collect()
    };
    let quads = [
        [0u32, 2, 3, 1],
        [4, 5, 7, 6],
        [0, 1, 5, 4],
        [2, 6, 7, 3],
        [0, 4, 6, 2],
        [1, 3, 7, 5],
    ];
    // Cube A at the origin, cube B sharing A's vertex 7 as its vertex 0.
    let mut positions = cube([0.0; 3], 1.0);
    positions.extend(cube([1.0; 3], 1.0).into_iter().skip(1));
    let b = |v: u32| if v == 0 { 7 } else { 7 + v };
    let mut faces: Vec<[u32; 4]> = quads.to_vec();
    faces.extend(quads.iter().map(|q| q.map(b)));
    let mesh = ControlMesh::from_polygons(positions, &faces);
    let split = ManifoldSplit::of(&mesh).expect("split");
    assert_eq!(split.report.vertices_with_fans, 1);
    assert_eq!(split.report.sharpened, 1);
    assert_eq!(split.copies, vec![7]);
    assert_eq!(split.mesh.corners.len(), 2);
    let r = refine_uniform(&split.mesh, Scheme::CatmullClark, 2).expect("refine");
    assert_eq!(r.level(2).positions[7], [1.0; 3], "the pinch stays put");
    assert_eq!(r.level(2).positions[15], [1.0; 3], "in its copy too");
}

/// Three sheets along a chain of two edges: the middle vertex (two non-manifold edges, more
/// faces than edges) keeps the crease rule in every copy; the chain's ends are corners.
#[test]
fn fins_along_a_chain_keep_the_crease_rule() {
    // The chain 0-1-2 along x; each sheet is two quads over it, at angles 0, 120, 240 degrees.
    let mut positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let mut faces = Vec::new();
    for k in 0..3u32 {
        let a = k as f64 * std::f64::consts::TAU / 3.0;
        let base = positions.len() as u32;
        for x in 0..3 {
            positions.push([x as f64, a.cos(), a.sin() + 0.1 * x as f64]);
        }
        faces.push([0, 1, base + 1, base]);
        faces.push([1, 2, base + 2, base + 1]);
    }
    let mesh = ControlMesh::from_polygons(positions, &faces);
    let split = ManifoldSplit::of(&mesh).expect("split");
    assert_eq!(split.report.shared_edges, 2);
    assert_eq!(split.report.creases, 1, "vertex 1");
    assert_eq!(split.report.sharpened, 2, "vertices 0 and 2");
    assert!(split.report.sharpened_beyond_rule.is_empty());
    let r = refine_uniform(&split.mesh, Scheme::CatmullClark, 1).expect("refine");
    // The crease rule along 0-1-2: (v0 + 6 v1 + v2) / 8 = v1 here, in every copy.
    let copies: Vec<u32> = (0..split.mesh.positions.len() as u32)
        .filter(|&v| split.source(v) == 1)
        .collect();
    assert_eq!(copies.len(), 3);
    for v in copies {
        assert_eq!(r.level(1).positions[v as usize], [1.0, 0.0, 0.0]);
    }
    // Bent chain: the rule moves the vertex off its position, equally in every copy.
    let mut bent = mesh.clone();
    bent.positions[1] = [1.0, 0.0, 0.5];
    let split = ManifoldSplit::of(&bent).expect("split");
    let r = refine_uniform(&split.mesh, Scheme::CatmullClark, 1).expect("refine");
    let expect = [1.0, 0.0, 6.0 * 0.5 / 8.0];
    for v in 0..split.mesh.positions.len() as u32 {
        if split.source(v) == 1 {
            let p = r.level(1).positions[v as usize];
            assert!(dist(p, expect) < 1e-15, "{v}: {p:?}");
        }
    }
}

/// A cone touching a non-manifold crease vertex: its fan does not run between the crease's
/// two edges, so no manifold split gives it the crease rule; the vertex is sharpened in every
/// copy and listed.
#[test]
fn a_cone_on_a_crease_vertex_is_sharpened_and_reported() {
    let mut positions = vec![[0.0, 0.0, 0.0], [1.0, 0.0, 0.0], [2.0, 0.0, 0.0]];
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for k in 0..3u32 {
        let a = k as f64 * std::f64::consts::TAU / 3.0;
        let base = positions.len() as u32;
        for x in 0..3 {
            positions.push([x as f64, a.cos(), a.sin()]);
        }
        faces.push(vec![0, 1, base + 1, base]);
        faces.push(vec![1, 2, base + 2, base + 1]);
    }
    // A closed cone of three triangles below vertex 1 (its own fan there).
    let apex = positions.len() as u32;
    positions.push([1.0, 0.0, -3.0]);
    let ring = apex + 1;
    positions.extend([[0.7, 0.3, -1.0], [1.3, 0.3, -1.0], [1.0, -0.4, -1.0]]);
    for i in 0..3 {
        let (a, b) = (ring + i, ring + (i + 1) % 3);
        faces.push(vec![1, a, b]);
        faces.push(vec![a, apex, b]);
    }
    let mesh = ControlMesh::from_polygons(positions, &faces);
    let split = ManifoldSplit::of(&mesh).expect("split");
    assert_eq!(split.report.sharpened_beyond_rule, vec![1]);
    let r = refine_uniform(&split.mesh, Scheme::CatmullClark, 2).expect("refine");
    let (joined, _) = joined_vertices(&r, &split, 2).expect("joined");
    assert_copies_coincide("cone", &joined, &r.level(2).positions, 1e-12);
}

/// A face naming a vertex twice in a row (a degenerate edge, as in OpenSubdiv's quad poles)
/// splits; a face whose two corners at one vertex are joined around it has no manifold form.
#[test]
fn degenerate_edges_split_and_faces_joined_to_themselves_are_refused() {
    let (mesh, _) = shape("catmark_nonman_quadpole8");
    let split = ManifoldSplit::of(&mesh).expect("quad pole");
    assert_eq!(split.report.sharpened, 1, "the pole");
    assert!(split
        .non_manifold_edges
        .iter()
        .all(|(e, u)| *u == EdgeUse::Degenerate && e[0] == e[1]));
    // A figure-eight face splits: its corners at vertex 0 are in different fans.
    let eight = ControlMesh::from_polygons(
        vec![[0.0; 3], [1.0, 0.0, 0.0], [1.0, 1.0, 0.0], [0.0, 1.0, 0.0]],
        &[[0u32, 1, 2, 0, 3]],
    );
    let split = ManifoldSplit::of(&eight).expect("figure eight");
    assert_eq!(split.copies, vec![0]);
    // Faces around vertex 0 join the face's two corners there into one fan.
    let joined = ControlMesh::from_polygons(
        vec![[0.0; 3]; 6],
        &[vec![0u32, 1, 2, 0, 3, 4], vec![0, 2, 5], vec![0, 5, 1]],
    );
    let e = ManifoldSplit::of(&joined).unwrap_err();
    assert!(
        matches!(
            e,
            topology::TopologyError::RepeatedVertex { face: 0, vertex: 0 }
        ),
        "{e}"
    );
}

/// A manifold mesh comes back as it is.
#[test]
fn a_manifold_mesh_is_its_own_split() {
    let path = PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/opensubdiv/shapes/catmark_cube_creases1.obj");
    let mesh = load_obj(path).expect("cube");
    let split = ManifoldSplit::of(&mesh).expect("cube");
    assert!(split.is_identity());
    assert_eq!(split.mesh, mesh);
    assert!(split.copies.is_empty() && split.non_manifold_edges.is_empty());
}

// ---------------------------------------------------------------------------------------
// OpenSubdiv Far baselines (tests/data/opensubdiv/far_baseline, made by tools/far-dump with
// OpenSubdiv 3.5's Far): `NAME.L2.txt` with, per level k, `level k V F`, then V lines
// `v x y z`; after the last level's points, its limit points (`l x y z`) and faces
// (`f a b c ...`, 0-based).

struct FarDump {
    levels: Vec<Vec<[f64; 3]>>,
    limit: Vec<[f64; 3]>,
    faces: Vec<Vec<u32>>,
}

fn read_dump(path: &std::path::Path) -> FarDump {
    let text = std::fs::read_to_string(path).unwrap_or_else(|e| panic!("{}: {e}", path.display()));
    let mut d = FarDump {
        levels: Vec::new(),
        limit: Vec::new(),
        faces: Vec::new(),
    };
    for line in text.lines() {
        let mut w = line.split_whitespace();
        let word = w.next();
        let nums: Vec<f64> = w.map(|x| x.parse().expect("number")).collect();
        let p = || [nums[0], nums[1], nums[2]];
        match word {
            Some("level") => d.levels.push(Vec::new()),
            Some("v") => d.levels.last_mut().expect("level").push(p()),
            Some("l") => d.limit.push(p()),
            Some("f") => d.faces.push(nums.iter().map(|&x| x as u32).collect()),
            _ => panic!("{}: unexpected line {line:?}", path.display()),
        }
    }
    d
}

/// Largest distance (relative to Far's diagonal) from a point of ours to the nearest of
/// Far's, and from each of Far's to the nearest of ours: the two point sets agree.
fn set_distance(ours: &[[f64; 3]], far: &[[f64; 3]]) -> f64 {
    let diag = diagonal(far);
    let cell = diag / 64.0;
    let key = |p: &[f64; 3]| p.map(|c| (c / cell).floor() as i64);
    let grid_of = |points: &[[f64; 3]]| {
        let mut grid: HashMap<[i64; 3], Vec<[f64; 3]>> = HashMap::new();
        for p in points {
            grid.entry(key(p)).or_default().push(*p);
        }
        grid
    };
    let nearest = |p: &[f64; 3], grid: &HashMap<[i64; 3], Vec<[f64; 3]>>| {
        let k = key(p);
        let mut best = f64::MAX;
        for d in 0..27 {
            let cell = [k[0] + d % 3 - 1, k[1] + (d / 3) % 3 - 1, k[2] + d / 9 - 1];
            for q in grid.get(&cell).into_iter().flatten() {
                best = best.min(dist(*p, *q));
            }
        }
        best / diag
    };
    let (g_ours, g_far) = (grid_of(ours), grid_of(far));
    let a = ours.iter().map(|p| nearest(p, &g_far)).fold(0.0, f64::max);
    let b = far.iter().map(|p| nearest(p, &g_ours)).fold(0.0, f64::max);
    a.max(b)
}

/// One point per joined vertex (its first member's).
fn joined_points(joined: &[u32], count: usize, points: &[[f64; 3]]) -> Vec<[f64; 3]> {
    let mut out = vec![[f64::NAN; 3]; count];
    for (v, &j) in joined.iter().enumerate().rev() {
        out[j as usize] = points[v];
    }
    out
}

/// Far's interior vertices of two faces (two faces, two distinct neighbours along them).
fn far_valence_two(dump: &FarDump) -> HashSet<usize> {
    let mut faces: HashMap<u32, usize> = HashMap::new();
    let mut neighbours: HashMap<u32, HashSet<u32>> = HashMap::new();
    for f in &dump.faces {
        for i in 0..f.len() {
            *faces.entry(f[i]).or_default() += 1;
            let n = neighbours.entry(f[i]).or_default();
            n.insert(f[(i + 1) % f.len()]);
            n.insert(f[(i + f.len() - 1) % f.len()]);
        }
    }
    faces
        .iter()
        .filter(|(v, &n)| n == 2 && neighbours[v].len() == 2)
        .map(|(&v, _)| v as usize)
        .collect()
}

/// How many vertices fewer than Far's a joined level has: in `catmark_nonman_edges` two
/// quads each name vertex 51 twice in a row, and their corners there lie between the same
/// two fans, so the split has one edge (and at level k its 2^k - 1 points) where Far has
/// two coincident ones (`topology::refine::joined`).
fn known_shortfall(name: &str, level: usize) -> usize {
    if name == "catmark_nonman_edges" {
        (1 << level) - 1
    } else {
        0
    }
}

/// The CPU refiner against OpenSubdiv's Far on the non-manifold regression shapes: vertex
/// counts per level, refined points of levels 1 and 2 and limit points of level 2 as point
/// sets, within 1e-9 of the diagonal (the baselines keep 10 digits). Far's limit mask for an
/// interior vertex of two faces is its corner mask (the point itself, `Sdc`'s choice for
/// valence 2); the exact evaluator gives that vertex's true limit, so those vertices (of
/// `catmark_val2_nonman`) are left out of the limit comparison on both sides.
#[test]
fn refinement_and_limit_match_opensubdiv_far() {
    let dir =
        PathBuf::from(env!("CARGO_MANIFEST_DIR")).join("../../tests/data/opensubdiv/far_baseline");
    let mut report = Vec::new();
    for name in SHAPES {
        let far = read_dump(&dir.join(format!("{name}.L2.txt")));
        let (mesh, scheme) = shape(name);
        let split = ManifoldSplit::of(&mesh).expect(name);
        let r = refine_uniform(&split.mesh, scheme, 2).expect(name);
        let mut line = format!("{name}:");
        for (k, points) in far.levels.iter().enumerate() {
            let (joined, count) = joined_vertices(&r, &split, k).expect(name);
            line.push_str(&format!(" L{k} {count}/{}", points.len()));
            assert_eq!(
                count + known_shortfall(name, k),
                points.len(),
                "{name} level {k}"
            );
            let ours = joined_points(&joined, count, &r.level(k).positions);
            let d = set_distance(&ours, points);
            assert!(d <= 1e-9, "{name}: level {k} points {d:.1e} from Far's");
        }
        let (joined, count) = joined_vertices(&r, &split, 2).expect(name);
        let level = r.level(2);
        let limit = limit_of_level(level, scheme, &mesh);
        let ours: Vec<[f64; 3]> = (0..limit.len())
            .filter(|&v| {
                let t = &level.topology;
                !(t.vertex_faces(v).len() == 2 && t.vertex_edges(v).len() == 2)
            })
            .map(|v| (joined[v], limit[v]))
            .collect::<HashMap<u32, [f64; 3]>>()
            .into_values()
            .collect();
        let skip = far_valence_two(&far);
        let theirs: Vec<[f64; 3]> = (0..far.limit.len())
            .filter(|v| !skip.contains(v))
            .map(|v| far.limit[v])
            .collect();
        assert!(count >= ours.len());
        let d = set_distance(&ours, &theirs);
        line.push_str(&format!(
            ", limit {d:.1e} ({} of {} points)",
            theirs.len(),
            far.limit.len()
        ));
        assert!(d <= 1e-9, "{name}: limit points {d:.1e} from Far's");
        report.push(line);
    }
    println!("{}", report.join("\n"));
}

/// Vertices no face uses (OpenSubdiv keeps them) have no surface: the CPU limit mesh keeps
/// their positions instead of failing or making NaN, in both schemes.
#[test]
fn vertices_no_face_uses_keep_their_position_in_the_limit_mesh() {
    use topology::limit::limit_mesh::{uniform_limit_mesh, DomainPoint};
    for name in ["catmark_nonman_bareverts", "loop_nonman_verts"] {
        let (mesh, scheme) = shape(name);
        let split = ManifoldSplit::of(&mesh).expect(name);
        let corners = vec![
            DomainPoint {
                face: 0,
                uv: [0.0, 0.0]
            };
            split.mesh.face_vertices.len()
        ];
        let topology = Topology::from_mesh(&split.mesh).expect(name);
        let bare: Vec<usize> = (0..topology.num_vertices())
            .filter(|&v| topology.vertex_faces(v).is_empty())
            .collect();
        assert!(!bare.is_empty(), "{name} has vertices no face uses");
        for level in 0..3 {
            let lm = uniform_limit_mesh(&split.mesh, scheme, level, &corners).expect(name);
            assert!(
                lm.positions.iter().flatten().all(|c| c.is_finite()),
                "{name} {level}"
            );
            for &v in &bare {
                assert_eq!(lm.positions[v], split.mesh.positions[v], "{name} {level}");
            }
        }
    }
}

mod random_soups {
    use proptest::prelude::*;
    use topology::mesh::manifold::ManifoldSplit;
    use topology::mesh::Topology;
    use topology::refine::refine_uniform;
    use topology::{ControlMesh, Scheme};

    proptest! {
        #![proptest_config(ProptestConfig::with_cases(512))]

        /// Any polygon soup that validation takes either splits into a mesh the manifold
        /// adjacency accepts (every edge one face or two opposite ones, every vertex one fan),
        /// which then refines, or is refused by name (a face joined to itself at a vertex).
        #[test]
        fn every_split_is_manifold_and_refines(
            faces in prop::collection::vec(prop::collection::vec(0u32..9, 3..6), 1..10),
        ) {
            let positions = (0..9)
                .map(|i| [f64::from(i), f64::from(i * i % 7), f64::from(i % 3)])
                .collect();
            let mesh = ControlMesh::from_polygons(positions, &faces);
            prop_assume!(mesh.validate().is_ok());
            match ManifoldSplit::of(&mesh) {
                Ok(split) => {
                    prop_assert_eq!(split.mesh.num_faces(), mesh.num_faces());
                    let t = Topology::from_mesh(&split.mesh);
                    prop_assert!(t.is_ok(), "{:?}: {:?}", faces, t.err());
                    prop_assert!(refine_uniform(&split.mesh, Scheme::CatmullClark, 1).is_ok());
                }
                Err(e) => prop_assert!(
                    matches!(e, topology::TopologyError::RepeatedVertex { .. }),
                    "{e}"
                ),
            }
        }
    }
}

/// catmark_nonman_edges' face 40 names two vertices twice each (`f 67 67 68 68`): its corners
/// lie on one line and every one of its edges is non-manifold (a vertex to itself, or the edge
/// 67–68 that it uses twice and its neighbour once), so every edge is an infinitely sharp
/// crease and its limit surface is the segment between the two vertices: no area. What a
/// capture classifies as open edges inside a face of no area (`tess::capture::
/// OpenEdgeClasses::in_face_of_no_area`) rests on this: the exact limit at every point of the
/// face's domain lies on that segment, and its two partial derivatives are parallel.
#[test]
fn a_quad_naming_two_vertices_twice_each_has_no_area() {
    use topology::limit::face_domain::LimitEvaluator;
    use topology::mesh::manifold::non_manifold_edges;
    let (mesh, _) = shape("catmark_nonman_edges");
    let face = 40;
    assert_eq!(
        mesh.face(face),
        &[66, 66, 67, 67],
        "0-based vertices of face 40"
    );
    let non_manifold: HashSet<[u32; 2]> = non_manifold_edges(&mesh)
        .unwrap()
        .into_iter()
        .map(|(e, _)| e)
        .collect();
    for e in [[66, 66], [66, 67], [67, 67]] {
        assert!(non_manifold.contains(&e), "edge {e:?} is non-manifold");
    }
    let (a, b) = (mesh.positions[66], mesh.positions[67]);
    let d = diagonal(&mesh.positions);
    let lm = LimitEvaluator::new(&mesh, LimitScheme::CatmullClark).unwrap();
    let ab = [b[0] - a[0], b[1] - a[1], b[2] - a[2]];
    let len = dist(a, b);
    let (mut off_line, mut area) = (0.0f64, 0.0f64);
    let cross = |x: [f64; 3], y: [f64; 3]| {
        [
            x[1] * y[2] - x[2] * y[1],
            x[2] * y[0] - x[0] * y[2],
            x[0] * y[1] - x[1] * y[0],
        ]
    };
    let norm = |x: [f64; 3]| (x[0] * x[0] + x[1] * x[1] + x[2] * x[2]).sqrt();
    let mut along = Vec::new();
    for i in 0..=8 {
        for j in 0..=8 {
            let s = lm
                .evaluate(face as u32, i as f64 / 8.0, j as f64 / 8.0)
                .unwrap();
            let p = s.position;
            let ap = [p[0] - a[0], p[1] - a[1], p[2] - a[2]];
            off_line = off_line.max(norm(cross(ab, ap)) / len / d);
            along.push((ap[0] * ab[0] + ap[1] * ab[1] + ap[2] * ab[2]) / (len * len));
            let du = [s.du[0], s.du[1], s.du[2]];
            let dv = [s.dv[0], s.dv[1], s.dv[2]];
            area = area.max(norm(cross(du, dv)) / (d * d));
        }
    }
    let (lo, hi) = along
        .iter()
        .fold((f64::MAX, f64::MIN), |(lo, hi), &t| (lo.min(t), hi.max(t)));
    println!(
        "face 40: limit {off_line:.1e} of the diagonal off the line, |du × dv| {area:.1e}, \
         along the segment from {lo:.3} to {hi:.3}"
    );
    assert!(off_line < 1e-12, "{off_line:e}");
    assert!(area < 1e-12, "{area:e}");
    assert!(lo >= -1e-12 && hi <= 1.0 + 1e-12, "{lo} {hi}");
}
