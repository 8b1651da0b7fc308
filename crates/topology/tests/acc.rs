//! ACC-1 geometry patches against the exact Catmull-Clark limit: exact on regular faces,
//! interpolating limit positions at extraordinary corners, watertight along shared edges, and
//! their deviation (with single-pass Gregory patches beside them) on OpenSubdiv's shapes.
use topology::limit::eval::{LimitScheme, LocalMesh};
use topology::patches::acc::{acc1_patch, evaluate};
use topology::patches::gregory::{gregory_basis, gregory_weights};
use topology::refine::Level;
use topology::{load_obj, ControlMesh, Scheme};

fn shape(name: &str) -> ControlMesh {
    let path = format!(
        "{}/../../tests/data/opensubdiv/shapes/{name}.obj",
        env!("CARGO_MANIFEST_DIR")
    );
    load_obj(&path).unwrap()
}

/// A bumpy 6×6-vertex grid: its 3×3 central quads have interior valence-4 corners.
fn grid() -> ControlMesh {
    let n = 6;
    let mut p = Vec::new();
    for j in 0..n {
        for i in 0..n {
            let z = ((i * 7 + j * 13) % 5) as f64 * 0.1;
            p.push([i as f64, j as f64, z]);
        }
    }
    let mut faces = Vec::new();
    for j in 0..n - 1 {
        for i in 0..n - 1 {
            let v = (j * n + i) as u32;
            faces.push([v, v + 1, v + 1 + n as u32, v + n as u32]);
        }
    }
    ControlMesh::from_polygons(p, &faces)
}

fn dist(a: [f64; 3], b: &[f64]) -> f64 {
    ((a[0] - b[0]).powi(2) + (a[1] - b[1]).powi(2) + (a[2] - b[2]).powi(2)).sqrt()
}

#[test]
fn regular_faces_are_the_exact_bspline_patch() {
    let mesh = grid();
    let level = Level::from_mesh(&mesh, Scheme::CatmullClark).unwrap();
    let exact = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).unwrap();
    let mut built = 0;
    for face in 0..mesh.num_faces() {
        let Ok(net) = acc1_patch(level.view(), face) else {
            continue;
        };
        built += 1;
        for (u, v) in [(0.0, 0.0), (0.3, 0.8), (1.0, 0.5), (0.25, 0.75), (0.9, 0.1)] {
            let [p, du, dv] = evaluate(&net, &level.positions, u, v);
            let s = exact.evaluate(face, u, v).unwrap();
            assert!(dist(p, &s.position) < 1e-12, "face {face} ({u},{v})");
            assert!(dist(du, &s.du) < 1e-11 && dist(dv, &s.dv) < 1e-11);
        }
    }
    assert_eq!(built, 9, "the 3×3 inner quads have interior corners");
}

#[test]
fn refused_faces_name_the_problem() {
    let mesh = grid();
    let level = Level::from_mesh(&mesh, Scheme::CatmullClark).unwrap();
    let e = acc1_patch(level.view(), 0).unwrap_err();
    assert!(e.to_string().contains("on a boundary"), "{e}");
    let e = acc1_patch(level.view(), 99).unwrap_err();
    assert!(e.to_string().contains("out of range"), "{e}");
    let creased = shape("catmark_cube_creases0");
    let level = Level::from_mesh(&creased, Scheme::CatmullClark).unwrap();
    assert!((0..creased.num_faces())
        .any(|f| acc1_patch(level.view(), f).is_err_and(|e| e.to_string().contains("sharp edge"))));
}

#[test]
fn corners_interpolate_the_limit_and_shared_edges_match() {
    for name in ["catmark_cube", "catmark_pawn", "catmark_bishop"] {
        let mesh = shape(name);
        let level = Level::from_mesh(&mesh, Scheme::CatmullClark).unwrap();
        let exact = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).unwrap();
        let nets: Vec<_> = (0..mesh.num_faces())
            .map(|f| acc1_patch(level.view(), f).ok())
            .collect();
        let corners = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
        let mut shared = 0;
        for (f, net) in nets.iter().enumerate() {
            let Some(net) = net else { continue };
            for (c, &(u, v)) in corners.iter().enumerate() {
                let vtx = mesh.face(f)[c] as usize;
                let limit = exact.vertex_limit_exact(vtx as u32).unwrap();
                let p = evaluate(net, &level.positions, u, v)[0];
                assert!(dist(p, &limit) < 1e-12, "{name} face {f} corner {c}");
            }
            // Each edge's curve seen from the neighbour: same points, reversed parameter.
            let fv = mesh.face(f);
            for c in 0..4 {
                let (a, b) = (fv[c], fv[(c + 1) % 4]);
                for (g, other) in nets.iter().enumerate() {
                    let (Some(other), true) = (other, g != f) else {
                        continue;
                    };
                    let gv = mesh.face(g);
                    let Some(k) = (0..4).find(|&k| gv[k] == b && gv[(k + 1) % 4] == a) else {
                        continue;
                    };
                    shared += 1;
                    for t in [0.2, 0.5, 0.7] {
                        let on = |corner: usize, t: f64| {
                            let (u0, v0) = corners[corner];
                            let (u1, v1) = corners[(corner + 1) % 4];
                            (u0 + t * (u1 - u0), v0 + t * (v1 - v0))
                        };
                        let (u, v) = on(c, t);
                        let (x, y) = on(k, 1.0 - t);
                        let p = evaluate(net, &level.positions, u, v)[0];
                        let q = evaluate(other, &level.positions, x, y)[0];
                        assert!(
                            dist(p, &q) < 1e-12,
                            "{name}: crack between faces {f} and {g}"
                        );
                    }
                }
            }
        }
        assert!(shared > 0, "{name}: no shared edge checked");
    }
}

/// Pointwise deviation from the exact limit at the same parameter, relative to the bounding
/// box's diagonal, over a 9×9 lattice of every face both approximations build: ACC-1 and
/// single-pass Gregory patches (no refinement). Printed for docs; asserted exact on regular
/// faces and bounded elsewhere.
#[test]
fn deviation_from_the_exact_limit_on_opensubdiv_shapes() {
    for name in [
        "catmark_cube",
        "catmark_pawn",
        "catmark_bishop",
        "catmark_car",
    ] {
        let mesh = shape(name);
        let level = Level::from_mesh(&mesh, Scheme::CatmullClark).unwrap();
        let exact = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).unwrap();
        let (lo, hi) = mesh
            .positions
            .iter()
            .fold(([f64::MAX; 3], [f64::MIN; 3]), |(lo, hi), p| {
                (
                    [lo[0].min(p[0]), lo[1].min(p[1]), lo[2].min(p[2])],
                    [hi[0].max(p[0]), hi[1].max(p[1]), hi[2].max(p[2])],
                )
            });
        let diag = dist(lo, &hi);
        let (mut acc_max, mut greg_max, mut acc_sq, mut greg_sq, mut count) =
            (0.0f64, 0.0f64, 0.0, 0.0, 0usize);
        let (mut regular, mut irregular) = (0, 0);
        for f in 0..mesh.num_faces() {
            let Ok(net) = acc1_patch(level.view(), f) else {
                continue;
            };
            let Ok(greg) = gregory_basis(level.view(), f, &mesh.options) else {
                continue;
            };
            let greg: Vec<[f64; 3]> = greg.iter().map(|s| s.apply(&level.positions)).collect();
            let is_regular = mesh
                .face(f)
                .iter()
                .all(|&v| level.topology.vertex_edges(v as usize).len() == 4);
            let (mut face_acc, mut face_greg) = (0.0f64, 0.0f64);
            for a in 0..9 {
                for b in 0..9 {
                    let (u, v) = (a as f64 / 8.0, b as f64 / 8.0);
                    let e = exact.evaluate(f, u, v).unwrap().position;
                    let p = evaluate(&net, &level.positions, u, v)[0];
                    let w = gregory_weights(u, v);
                    let mut g = [0.0; 3];
                    for (k, q) in greg.iter().enumerate() {
                        for d in 0..3 {
                            g[d] += w.point[k] * q[d];
                        }
                    }
                    let (da, dg) = (dist(p, &e) / diag, dist(g, &e) / diag);
                    face_acc = face_acc.max(da);
                    face_greg = face_greg.max(dg);
                    acc_sq += da * da;
                    greg_sq += dg * dg;
                    count += 1;
                }
            }
            if is_regular {
                regular += 1;
                assert!(
                    face_acc <= 1e-5 && face_greg <= 1e-5,
                    "{name} regular face {f}"
                );
            } else {
                irregular += 1;
            }
            acc_max = acc_max.max(face_acc);
            greg_max = greg_max.max(face_greg);
        }
        assert!(count > 0, "{name}: no face built");
        let (acc_rms, greg_rms) = (
            (acc_sq / count as f64).sqrt(),
            (greg_sq / count as f64).sqrt(),
        );
        println!(
            "| {name} | {regular} | {irregular} | {acc_max:.2e} | {acc_rms:.2e} | {greg_max:.2e} | {greg_rms:.2e} |"
        );
        // Approximations, not the limit: within 2% of the diagonal on these shapes.
        assert!(
            acc_max < 0.02 && greg_max < 0.02,
            "{name}: {acc_max:e} {greg_max:e}"
        );
    }
}
