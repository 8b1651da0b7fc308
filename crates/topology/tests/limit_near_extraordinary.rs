//! Limit derivatives at and next to extraordinary vertices, down to parameters of 1e-300: the
//! normal at `(t, t)` of a face whose corner 0 is the vertex tends to the normal the limit
//! tangent masks give at the vertex, for every valence 3 to 12, Catmull-Clark and Loop,
//! interior and boundary. Before the evaluator kept its points relative to the face it
//! descends into, the derivatives there were differences of points equal to f64 rounding: a
//! cube's corner normal came out 45° off at `t = 1e-20` and 3° off at 1e-12, and Loop's was
//! zero at 1e-17.

use topology::limit::eval::{limit_point, normal_of, LimitScheme, LocalMesh};
use topology::ControlMesh;

/// Where the meshes are put: away from the origin, so the points' coordinates are much larger
/// than their differences near the vertex.
const OFFSET: [f64; 3] = [3.0, -2.0, 5.0];

fn at(r: f64, a: f64) -> [f64; 3] {
    let (x, y) = (r * a.cos(), r * a.sin());
    let z = 0.15 * r * r + 0.05 * r * (3.0 * a).cos();
    [x + OFFSET[0], y + OFFSET[1], z + OFFSET[2]]
}

/// One vertex (0) with `n` faces around it, closed (interior) or spanning 270° (boundary), and
/// a band of faces around them: quads (Catmull-Clark) or triangles (Loop). Face 0 has the
/// vertex at its corner 0.
fn fan(n: usize, quads: bool, boundary: bool) -> ControlMesh {
    let sector = if boundary {
        1.5 * std::f64::consts::PI
    } else {
        std::f64::consts::TAU
    };
    // Ring vertices per face: 2 for quads (edge neighbour, diagonal), 1 for triangles.
    let per = if quads { 2 } else { 1 };
    let m = per * n;
    let count = if boundary { m + 1 } else { m };
    let wrap = |k: usize| if boundary { k } else { k % m };
    let mut p = vec![at(0.0, 0.0)];
    for radii in [[1.0, 1.3], [2.2, 2.2]] {
        for k in 0..count {
            p.push(at(radii[k % 2], sector * k as f64 / m as f64));
        }
    }
    let ring = |k: usize| (1 + wrap(k)) as u32;
    let outer = |k: usize| (1 + count + wrap(k)) as u32;
    let mut faces: Vec<Vec<u32>> = Vec::new();
    for i in 0..n {
        if quads {
            faces.push(vec![0, ring(2 * i), ring(2 * i + 1), ring(2 * i + 2)]);
        } else {
            faces.push(vec![0, ring(i), ring(i + 1)]);
        }
    }
    for k in 0..m {
        if quads {
            faces.push(vec![ring(k), outer(k), outer(k + 1), ring(k + 1)]);
        } else {
            faces.push(vec![ring(k), outer(k), outer(k + 1)]);
            faces.push(vec![ring(k), outer(k + 1), ring(k + 1)]);
        }
    }
    let mesh = ControlMesh::from_polygons(p, &faces);
    mesh.validate().expect("a valid fan");
    mesh
}

/// The angle between two vectors, accurate for small angles too (atan2 of |a × b| and a · b).
fn angle(a: &[f64; 3], b: &[f64; 3]) -> f64 {
    let dot: f64 = a.iter().zip(b).map(|(x, y)| x * y).sum();
    let c = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    (c[0] * c[0] + c[1] * c[1] + c[2] * c[2]).sqrt().atan2(dot)
}

fn unit_normal(s: &topology::limit::eval::LimitSample) -> [f64; 3] {
    normal_of(&[s.du[0], s.du[1], s.du[2]], &[s.dv[0], s.dv[1], s.dv[2]])
}

/// Parameters from the vertex outward.
const PARAMS: [f64; 14] = [
    1e-300, 1e-200, 1e-100, 1e-50, 1e-40, 1e-30, 1e-20, 1e-17, 1e-15, 1e-12, 1e-9, 1e-6, 1e-4, 1e-3,
];

/// Every valence 3 to 12, Catmull-Clark and Loop, interior and boundary: at `(t, t)` on a
/// face whose corner 0 is the vertex, from `t = 1e-3` down to `1e-300`, the normal is a unit
/// vector, and the position ends at the vertex's limit point.
///
/// At an interior vertex the limit masks are exact: the normals approach the masks' normal at
/// the vertex monotonically and are within 1e-9 rad of it from `t = 1e-30` in.
///
/// At a boundary vertex with more than two faces the surface of the standard boundary rules
/// converges slowly and, at high valence, to a normal that depends on the direction it is
/// approached from; the cross-boundary tangent masks (Biermann et al.'s, as OpenSubdiv uses
/// them) are not eigenvectors of those rules, so level 0's miss the tangent plane deeper
/// levels converge to by up to 3°. There the check is that nothing jumps: neighbouring
/// parameters' normals differ by less than 3°, and from `t = 1e-40` in (within 2^-50 of the
/// corner at level 56, where the point is snapped to it) the normal is the deepest level's
/// masks'.
#[test]
fn normals_near_an_extraordinary_vertex_settle_on_the_vertex_normal() {
    let mut failures = Vec::new();
    for (scheme, quads) in [
        (LimitScheme::CatmullClark, true),
        (LimitScheme::Loop, false),
    ] {
        for boundary in [false, true] {
            for valence in 3..=12usize {
                // A boundary vertex of valence k (edges) has k - 1 faces.
                let faces = if boundary { valence - 1 } else { valence };
                let what = format!(
                    "{scheme:?} {} valence {valence}",
                    if boundary { "boundary" } else { "interior" }
                );
                let mesh = fan(faces, quads, boundary);
                failures.extend(settles(&mesh, scheme, !boundary, &what));
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// What is wrong with the normals and positions at `(t, t)` of face 0 of `mesh` as `t` goes
/// down [`PARAMS`] (see the test above); `exact_masks`: the level-0 masks' normal is where the
/// normals must go.
fn settles(mesh: &ControlMesh, scheme: LimitScheme, exact_masks: bool, what: &str) -> Vec<String> {
    let lm = LocalMesh::from_control_mesh(mesh, scheme).expect("local mesh");
    let corner = lm.evaluate(0, 0.0, 0.0).expect("corner");
    let n0 = unit_normal(&corner);
    let samples: Vec<_> = PARAMS
        .iter()
        .map(|&t| (t, lm.evaluate(0, t, t).expect("evaluate")))
        .collect();
    let deepest = unit_normal(&samples[0].1);
    let mut failures = Vec::new();
    let mut previous: Option<[f64; 3]> = None;
    let mut closer_in = 0.0;
    for (t, s) in &samples {
        let n = unit_normal(s);
        if (n.iter().map(|x| x * x).sum::<f64>() - 1.0).abs() > 1e-12 {
            failures.push(format!("{what}, t = {t:e}: normal {n:?}"));
            continue;
        }
        let moved = s
            .position
            .iter()
            .zip(&corner.position)
            .map(|(a, b)| (a - b).abs())
            .fold(0.0, f64::max);
        if *t <= 1e-30 && moved > 1e-12 {
            failures.push(format!(
                "{what}, t = {t:e}: {moved:e} from the vertex's limit point"
            ));
        }
        if exact_masks {
            let off = angle(&n, &n0);
            if off + 1e-12 < closer_in || (*t <= 1e-30 && off > 1e-9) {
                failures.push(format!(
                    "{what}, t = {t:e}: {off:e} rad off the vertex normal ({closer_in:e} closer in)"
                ));
            }
            closer_in = off;
        } else {
            let jump = previous.map_or(0.0, |p| angle(&n, &p));
            if jump > 3f64.to_radians() || (*t <= 1e-40 && angle(&n, &deepest) > 1e-12) {
                failures.push(format!(
                    "{what}, t = {t:e}: {jump:e} rad from the normal closer in, {:e} from the \
                     deepest",
                    angle(&n, &deepest)
                ));
            }
        }
        previous = Some(n);
    }
    failures
}

fn cube() -> ControlMesh {
    let p = vec![
        [-1.0, -1.0, -1.0],
        [1.0, -1.0, -1.0],
        [1.0, 1.0, -1.0],
        [-1.0, 1.0, -1.0],
        [-1.0, -1.0, 1.0],
        [1.0, -1.0, 1.0],
        [1.0, 1.0, 1.0],
        [-1.0, 1.0, 1.0],
    ];
    let faces: [[u32; 4]; 6] = [
        [0, 3, 2, 1],
        [4, 5, 6, 7],
        [0, 1, 5, 4],
        [1, 2, 6, 5],
        [2, 3, 7, 6],
        [3, 0, 4, 7],
    ];
    ControlMesh::from_polygons(p, &faces)
}

/// The probe's cases: the cube's first face near its corner (-1, -1, -1) under Catmull-Clark,
/// and the fan-triangulated cube under Loop, at parameters down to 1e-300.
#[test]
fn cube_corner_normals_hold_to_the_smallest_parameters() {
    let third = (1.0f64 / 3.0).sqrt();
    let outward = [-third, -third, -third];
    let quads = cube();
    let mut tris: Vec<[u32; 3]> = Vec::new();
    for f in 0..quads.num_faces() {
        let v = quads.face(f);
        tris.push([v[0], v[1], v[2]]);
        tris.push([v[0], v[2], v[3]]);
    }
    let tri_cube = ControlMesh::from_polygons(quads.positions.clone(), &tris);
    for (mesh, scheme) in [
        (&quads, LimitScheme::CatmullClark),
        (&tri_cube, LimitScheme::Loop),
    ] {
        let n0 = limit_point(mesh, scheme, 0, 0.0, 0.0)
            .expect("corner")
            .normal;
        if scheme == LimitScheme::CatmullClark {
            // By the cube's symmetry (the triangulation breaks it for Loop).
            assert!(angle(&n0, &outward) < 1e-12, "{n0:?}");
        }
        for &t in &PARAMS[..10] {
            let p = limit_point(mesh, scheme, 0, t, t).expect("limit");
            let off = angle(&p.normal, &n0);
            assert!(
                off < 1e-6,
                "{scheme:?} t = {t:e}: normal {:?}, {off:e} rad off {n0:?}",
                p.normal
            );
        }
    }
}
