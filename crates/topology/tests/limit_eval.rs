//! Limit masks, regular patch bases and exact limit evaluation, checked against direct spline
//! algebra and against uniform refinement pushed to the limit by masks.

use topology::limit::basis::{
    catmark_regular_weights, loop_regular_weights, CATMARK_CORNER_SLOTS, LOOP_REGULAR_LATTICE,
};
use topology::limit::eval::{limit_point, limit_point_subface, LimitScheme, LocalMesh};
use topology::refine::{refine_uniform, Level};
use topology::{load_obj, ControlMesh, Scheme};

const DATA: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tests/data/opensubdiv/shapes/"
);

#[test]
fn box_spline_partition_of_unity_and_linear_precision() {
    for &(u, v) in &[(0.0, 0.0), (0.25, 0.5), (1.0, 0.0), (0.0, 1.0), (0.3, 0.1)] {
        let w = loop_regular_weights(u, v);
        let sum: f64 = w.point.iter().sum();
        assert!((sum - 1.0).abs() < 1e-14);
        let (mut pu, mut pv, mut du_u, mut dv_v, mut du_v) = (0.0, 0.0, 0.0, 0.0, 0.0);
        for (i, &(a, b)) in LOOP_REGULAR_LATTICE.iter().enumerate() {
            pu += w.point[i] * a as f64;
            pv += w.point[i] * b as f64;
            du_u += w.du[i] * a as f64;
            dv_v += w.dv[i] * b as f64;
            du_v += w.du[i] * b as f64;
        }
        assert!(
            (pu - u).abs() < 1e-14 && (pv - v).abs() < 1e-14,
            "{u} {v}: {pu} {pv}"
        );
        assert!((du_u - 1.0).abs() < 1e-13 && (dv_v - 1.0).abs() < 1e-13 && du_v.abs() < 1e-13);
        // Derivative weights agree with (one-sided at u = 0) differences of the weights.
        let h = 1e-6;
        let wp = loop_regular_weights(u + h, v);
        let wm = loop_regular_weights((u - h).max(0.0), v);
        for i in 0..12 {
            let fd = (wp.point[i] - wm.point[i]) / (u + h - (u - h).max(0.0));
            assert!(
                (fd - w.du[i]).abs() < 1e-5,
                "slot {i} du {fd} vs {}",
                w.du[i]
            );
        }
    }
    // At v0 the box spline equals the valence-6 limit mask (1/2 centre, 1/12 ring).
    let w = loop_regular_weights(0.0, 0.0);
    for (i, &x) in w.point.iter().enumerate() {
        let expect = match i {
            3 => 0.5,
            0 | 1 | 2 | 4 | 6 | 7 => 1.0 / 12.0,
            _ => 0.0,
        };
        assert!((x - expect).abs() < 1e-15, "slot {i}: {x}");
    }
}

#[test]
fn bspline_patch_precision() {
    for &(u, v) in &[(0.0, 0.0), (0.5, 0.25), (1.0, 1.0), (0.1, 0.9)] {
        let w = catmark_regular_weights(u, v);
        let (mut pu, mut pv, mut s, mut duu) = (0.0, 0.0, 0.0, 0.0);
        for r in 0..4 {
            for c in 0..4 {
                let i = 4 * r + c;
                s += w.point[i];
                pu += w.point[i] * (c as f64 - 1.0);
                pv += w.point[i] * (r as f64 - 1.0);
                duu += w.du[i] * (c as f64 - 1.0);
            }
        }
        assert!((s - 1.0).abs() < 1e-14 && (pu - u).abs() < 1e-14 && (pv - v).abs() < 1e-14);
        assert!((duu - 1.0).abs() < 1e-14);
    }
    let w = catmark_regular_weights(0.0, 0.0);
    assert!((w.point[CATMARK_CORNER_SLOTS[0]] - 4.0 / 9.0).abs() < 1e-15);
}

fn local_from_level(level: &Level, scheme: LimitScheme, mesh: &ControlMesh) -> LocalMesh {
    LocalMesh::from_refined_level(level, scheme, &mesh.options).expect("refined level is manifold")
}

fn max_sharpness(mesh: &ControlMesh) -> f32 {
    let e = mesh
        .creases
        .iter()
        .map(|c| c.sharpness)
        .filter(|&s| s < 10.0)
        .fold(0.0, f32::max);
    let v = mesh
        .corners
        .iter()
        .map(|c| c.sharpness)
        .filter(|&s| s < 10.0)
        .fold(0.0, f32::max);
    e.max(v)
}

fn dyadic_params(quad: bool, level: u32) -> Vec<(f64, f64)> {
    let n = 1u32 << level;
    let mut out = Vec::new();
    for i in 0..=n {
        for j in 0..=n {
            if quad || i + j <= n {
                out.push((i as f64 / n as f64, j as f64 / n as f64));
            }
        }
    }
    out
}

/// Every dyadic point of `level` evaluated on every face equals a limit-masked vertex of the
/// uniform refinement (to 1e-12 of the model size).
fn check_shape(name: &str, level: u32) {
    let mesh = load_obj(format!("{DATA}{name}.obj")).expect("shape loads");
    let quad = name.starts_with("catmark");
    let (scheme, refine_scheme) = if quad {
        (LimitScheme::CatmullClark, Scheme::CatmullClark)
    } else {
        (LimitScheme::Loop, Scheme::Loop)
    };
    let extra = max_sharpness(&mesh).ceil() as u32;
    let depth = (level + 1).max(extra + 1);
    let refined = refine_uniform(&mesh, refine_scheme, depth as usize).expect("refines");
    let fine = local_from_level(refined.level(depth as usize), scheme, &mesh);
    let limits: Vec<[f64; 3]> = (0..fine.num_vertices() as u32)
        .filter_map(|v| fine.vertex_limit_position(v).map(|p| [p[0], p[1], p[2]]))
        .collect();
    let base = LocalMesh::from_control_mesh(&mesh, scheme).expect("base mesh");
    let scale = mesh
        .positions
        .iter()
        .map(|p| p.iter().map(|x| x.abs()).fold(0.0, f64::max))
        .fold(0.0, f64::max);
    let mut checked = 0;
    for f in 0..base.num_faces() {
        if base.face(f).len() != if quad { 4 } else { 3 } {
            continue;
        }
        for (u, v) in dyadic_params(quad, level) {
            let s = base.evaluate(f, u, v).expect("evaluates");
            let best = limits
                .iter()
                .map(|q| {
                    (0..3)
                        .map(|k| (q[k] - s.position[k]).abs())
                        .fold(0.0, f64::max)
                })
                .fold(f64::INFINITY, f64::min);
            assert!(
                best <= 1e-12 * scale.max(1.0),
                "{name}: face {f} ({u},{v}) off the refined limit by {best:e}"
            );
            checked += 1;
        }
    }
    assert!(checked > 0);
}

#[test]
fn loop_shapes_match_refined_limit() {
    for name in [
        "loop_icosahedron",
        "loop_cube",
        "loop_cube_creases0",
        "loop_saddle_edgeonly",
        "loop_saddle_edgecorner",
        "loop_triangle_edgeonly",
        "loop_triangle_edgecorner",
    ] {
        check_shape(name, 2);
    }
}

#[test]
fn level3_dyadic_points_match_refined_limit() {
    check_shape("loop_icosahedron", 3);
    check_shape("loop_saddle_edgecorner", 3);
    check_shape("catmark_cube", 3);
    check_shape("catmark_edgecorner", 3);
}

#[test]
fn loop_semi_sharp_shapes_match_refined_limit() {
    for name in ["loop_cube_creases1", "loop_chaikin0", "loop_chaikin1"] {
        check_shape(name, 2);
    }
}

#[test]
fn catmark_shapes_match_refined_limit() {
    for name in [
        "catmark_cube",
        "catmark_edgeonly",
        "catmark_edgecorner",
        "catmark_dart_edgeonly",
        "catmark_dart_edgecorner",
        "catmark_cube_corner0",
        "catmark_cube_corner4",
        "catmark_cube_creases0",
        "catmark_tent",
    ] {
        check_shape(name, 2);
    }
}

/// Darts (an interior vertex with one infinitely sharp edge): the smooth limit mask that
/// OpenSubdiv applies there is not the limit of the refinement (the sharp edge's child is its
/// midpoint), so the limit at level 0 and at level 3 disagreed by 1.3e-2 of the diagonal on
/// catmark_cubes_infsharp; [`topology::limit::masks::dart_position_weights`] is.
#[test]
fn dart_shapes_match_refined_limit() {
    check_shape("catmark_cubes_infsharp", 2);
    check_shape("loop_cubes_infsharp", 2);
}

#[test]
fn catmark_semi_sharp_shapes_match_refined_limit() {
    for name in [
        "catmark_cube_creases1",
        "catmark_chaikin0",
        "catmark_pyramid_creases0",
        "catmark_chaikin1",
        "catmark_pyramid_creases1",
        "catmark_tent_creases1",
        "catmark_cube_corner1",
        "catmark_cube_corner2",
        "catmark_cube_corner3",
        "catmark_flap",
    ] {
        check_shape(name, 2);
    }
}

/// Parametric derivatives agree with central differences of the exact evaluation.
fn check_tangents(name: &str) {
    let mesh = load_obj(format!("{DATA}{name}.obj")).expect("shape loads");
    let quad = name.starts_with("catmark");
    let scheme = if quad {
        LimitScheme::CatmullClark
    } else {
        LimitScheme::Loop
    };
    let base = LocalMesh::from_control_mesh(&mesh, scheme).expect("base");
    let h = 1e-5;
    let params = [(0.3, 0.2), (0.45, 0.35), (0.61, 0.13), (0.2, 0.7)];
    for f in 0..base.num_faces().min(8) {
        if base.face(f).len() != if quad { 4 } else { 3 } {
            continue;
        }
        for &(u, v) in &params {
            if !quad && u + v + h > 1.0 {
                continue;
            }
            let s = base.evaluate(f, u, v).expect("evaluates");
            let pu = base.evaluate(f, u + h, v).expect("u+h");
            let mu = base.evaluate(f, u - h, v).expect("u-h");
            let pv = base.evaluate(f, u, v + h).expect("v+h");
            let mv = base.evaluate(f, u, v - h).expect("v-h");
            for k in 0..3 {
                let fu = (pu.position[k] - mu.position[k]) / (2.0 * h);
                let fv = (pv.position[k] - mv.position[k]) / (2.0 * h);
                let tol = 1e-5 * (1.0 + s.du[k].abs().max(s.dv[k].abs()));
                assert!(
                    (fu - s.du[k]).abs() < tol,
                    "{name} f{f} ({u},{v}) du {fu} vs {}",
                    s.du[k]
                );
                assert!(
                    (fv - s.dv[k]).abs() < tol,
                    "{name} f{f} ({u},{v}) dv {fv} vs {}",
                    s.dv[k]
                );
            }
        }
    }
}

#[test]
fn tangents_match_finite_differences() {
    for name in [
        "loop_icosahedron",
        "loop_saddle_edgecorner",
        "catmark_cube",
        "catmark_edgecorner",
        "catmark_tent",
    ] {
        check_tangents(name);
    }
}

#[test]
fn limit_point_cli_function() {
    let mesh = load_obj(format!("{DATA}catmark_cube.obj")).expect("cube");
    let p = limit_point(&mesh, LimitScheme::CatmullClark, 0, 0.5, 0.5).expect("limit");
    let len = p.normal.iter().map(|x| x * x).sum::<f64>().sqrt();
    assert!((len - 1.0).abs() < 1e-12);
    // The cube's limit surface is symmetric: the face centre lies on a coordinate axis, with
    // the normal along it.
    let axis = (0..3)
        .max_by(|&a, &b| p.position[a].abs().total_cmp(&p.position[b].abs()))
        .unwrap_or(0);
    for k in 0..3 {
        if k != axis {
            assert!(p.position[k].abs() < 1e-12 && p.normal[k].abs() < 1e-12);
        }
    }
    assert!(p.position[axis] * p.normal[axis] > 0.0, "outward normal");
    let text = p.to_string();
    assert!(text.contains("position") && text.contains("normal"));
}

#[test]
fn spot_quads_evaluate_on_refined_limit() {
    let path = concat!(
        env!("CARGO_MANIFEST_DIR"),
        "/../../assets/spot_control_mesh.obj"
    );
    let mesh = load_obj(path).expect("spot");
    let refined = refine_uniform(&mesh, Scheme::CatmullClark, 2).expect("refine");
    let fine = local_from_level(refined.level(2), LimitScheme::CatmullClark, &mesh);
    let base = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).expect("base");
    let mut limits: Vec<[f64; 3]> = (0..fine.num_vertices() as u32)
        .filter_map(|v| fine.vertex_limit_position(v).map(|p| [p[0], p[1], p[2]]))
        .collect();
    limits.sort_by(|a, b| a[0].total_cmp(&b[0]));
    let mut n = 0;
    let mut odd = 0;
    for f in (0..base.num_faces()).step_by(3) {
        let size = base.face(f).len();
        for &(u, v) in &[(0.0, 0.0), (0.5, 0.0), (0.5, 0.5), (1.0, 0.5)] {
            // Quads directly; other faces through their sub-quads (dyadic at level 1 there).
            let s = if size == 4 {
                base.evaluate(f, u, v).expect("eval")
            } else {
                odd += 1;
                base.evaluate_subface(f, f % size, u, v).expect("eval")
            };
            let x = s.position[0];
            let lo = limits.partition_point(|q| q[0] < x - 1e-9);
            let hit = limits[lo..]
                .iter()
                .take_while(|q| q[0] <= x + 1e-9)
                .any(|q| (0..3).all(|k| (q[k] - s.position[k]).abs() < 1e-12));
            assert!(hit, "spot face {f} ({u},{v})");
            n += 1;
        }
    }
    assert!(n > 50 && odd > 0);
    // A quad's sub-quad 0 is its lower-left quadrant.
    let q = (0..base.num_faces())
        .find(|&f| base.face(f).len() == 4)
        .expect("a quad");
    let a = base.evaluate(q, 0.15, 0.35).expect("quad");
    let b = base.evaluate_subface(q, 0, 0.3, 0.7).expect("sub-quad");
    for k in 0..3 {
        assert!((a.position[k] - b.position[k]).abs() < 1e-12);
        assert!((a.du[k] - 2.0 * b.du[k]).abs() < 1e-9);
    }
    let tri = (0..base.num_faces())
        .find(|&f| base.face(f).len() == 3)
        .expect("a triangle");
    let p = limit_point_subface(&mesh, tri, 2, 0.25, 0.5).expect("sub-quad point");
    assert!(p.to_string().contains("subface 2"));
}

/// The nearest-point distance finds a point moved off the surface along the normal (its own
/// offset) and a point on the surface from a wrong starting parameter (0), where the distance
/// at the same parameter would be large.
#[test]
fn nearest_limit_distance_is_geometric() {
    let cases = [
        (
            "catmark_cube.obj",
            LimitScheme::CatmullClark,
            [0.3, 0.6],
            [0.35, 0.55],
        ),
        ("loop_cube.obj", LimitScheme::Loop, [0.2, 0.3], [0.25, 0.25]),
    ];
    for (name, scheme, at, start) in cases {
        let mesh = load_obj(format!("{DATA}{name}")).expect("shape");
        let lm = LocalMesh::from_control_mesh(&mesh, scheme).expect("mesh");
        let e = lm.evaluate(0, at[0], at[1]).expect("limit");
        let cross = [
            e.du[1] * e.dv[2] - e.du[2] * e.dv[1],
            e.du[2] * e.dv[0] - e.du[0] * e.dv[2],
            e.du[0] * e.dv[1] - e.du[1] * e.dv[0],
        ];
        let len = cross.iter().map(|x| x * x).sum::<f64>().sqrt();
        let off = 1e-3;
        let lifted: Vec<f64> = (0..3)
            .map(|k| e.position[k] + off * cross[k] / len)
            .collect();
        let on = lm
            .nearest_limit_distance(0, None, start, &e.position)
            .expect("search");
        let above = lm
            .nearest_limit_distance(0, None, start, &lifted)
            .expect("search");
        let same_param = lm.evaluate(0, start[0], start[1]).expect("limit");
        let param_dist = (0..3)
            .map(|k| (same_param.position[k] - e.position[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        assert!(param_dist > 1e-2, "{name}: start too close ({param_dist})");
        assert!(on < 1e-9, "{name}: on the surface, found {on}");
        assert!(
            (above - off).abs() < 1e-8,
            "{name}: {off} off, found {above}"
        );
    }
}
