//! Face-varying texture coordinates: the value mesh of a layout under each of OpenSubdiv's six
//! modes (seams, pinned corners, junctions, darts, linear boundaries), its exact limit, and
//! the face-varying patches of the adaptive and single-pass plans against that limit.
use topology::limit::eval::{LimitScheme, LocalMesh};
use topology::patches::adaptive::single_pass::{plan_single_pass, SinglePassOptions};
use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions, AdaptivePlan, PatchKind};
use topology::patches::fvar::{texcoord_patches, FVarPatches, FVarPlan};
use topology::refine::fvar::{texcoord_mesh, ValueMesh};
use topology::rules::options::FVarLinearInterpolation as Mode;
use topology::rules::{Scheme, SHARPNESS_INFINITE};
use topology::{load_obj, ControlMesh};

fn shape(name: &str) -> ControlMesh {
    load_obj(format!(
        "{}/../../tests/data/opensubdiv/shapes/{name}.obj",
        env!("CARGO_MANIFEST_DIR")
    ))
    .expect("shape")
}

fn with_mode(mut mesh: ControlMesh, mode: Mode) -> ControlMesh {
    mesh.options.fvar_interpolation = mode;
    mesh
}

fn values(mesh: &ControlMesh) -> ValueMesh {
    texcoord_mesh(mesh, Scheme::CatmullClark)
        .expect("smooth texture coordinates")
        .expect("value mesh")
}

/// A layout with the vertex topology: one value per vertex, a function of its position.
fn continuous_layout(mut mesh: ControlMesh) -> ControlMesh {
    let uv_of = |p: [f64; 3]| {
        [
            p[0] + 0.5 * p[1] - 0.1 * p[2],
            0.3 * p[0] - p[1] + 0.7 * p[2],
        ]
    };
    mesh.uvs = Some(
        mesh.face_vertices
            .iter()
            .map(|&v| uv_of(mesh.positions[v as usize]))
            .collect(),
    );
    mesh.uv_indices = Some(mesh.face_vertices.clone());
    mesh
}

/// The mesh with its texture coordinates as positions `(u, v, 0)` (a continuous layout).
fn uvs_as_positions(mesh: &ControlMesh) -> ControlMesh {
    let mut out = mesh.clone();
    let uvs = mesh.uvs.as_ref().expect("uvs");
    for (c, &v) in mesh.face_vertices.iter().enumerate() {
        out.positions[v as usize] = [uvs[c][0], uvs[c][1], 0.0];
    }
    out
}

fn pinned(v: &ValueMesh, vertex: u32) -> bool {
    v.mesh
        .corners
        .iter()
        .any(|c| c.vertex == vertex && c.sharpness >= SHARPNESS_INFINITE)
}

/// The value-mesh vertices of mesh vertex `vertex` whose value is `uv`.
fn values_at(v: &ValueMesh, vertex: u32, uv: [f64; 2]) -> Vec<u32> {
    (0..v.vertex_of.len() as u32)
        .filter(|&i| v.vertex_of[i as usize] == vertex && v.value(i as usize) == uv)
        .collect()
}

/// With the vertex topology the value mesh is the mesh (its vertices in the mesh's order), and
/// only what the mesh itself makes sharp, or a boundary the mode makes linear, is pinned.
#[test]
fn a_continuous_layout_is_the_mesh_in_every_smooth_mode() {
    for name in ["catmark_cube", "catmark_edgecorner", "catmark_edgeonly"] {
        let base = continuous_layout(shape(name));
        let topo = topology::mesh::Topology::from_mesh(&base).expect("topology");
        let nv = base.positions.len() as u32;
        let on_boundary = |v: u32| {
            topo.vertex_edges(v as usize)
                .iter()
                .any(|&e| topo.is_boundary_edge(e as usize))
        };
        let corner = |v: u32| topo.vertex_faces(v as usize).len() == 1;
        for mode in Mode::ALL_MODES {
            let mesh = with_mode(base.clone(), mode);
            let Some(v) = texcoord_mesh(&mesh, Scheme::CatmullClark) else {
                assert_eq!(mode, Mode::All, "{name}: only 'all' is bilinear");
                continue;
            };
            let v = v.expect("value mesh");
            let same = uvs_as_positions(&mesh);
            assert_eq!(v.mesh.face_vertices, same.face_vertices, "{name} {mode}");
            assert_eq!(v.mesh.positions, same.positions, "{name} {mode}");
            let edge_and_corner = name == "catmark_edgecorner";
            let tagged = |i: u32| {
                mesh.corners
                    .iter()
                    .any(|c| c.vertex == i && c.sharpness >= SHARPNESS_INFINITE)
            };
            for i in 0..nv {
                let expected = tagged(i)
                    || match mode {
                        Mode::Boundaries => on_boundary(i),
                        Mode::None => edge_and_corner && corner(i),
                        _ => corner(i),
                    };
                assert_eq!(pinned(&v, i), expected, "{name} {mode}: vertex {i}");
            }
        }
    }
}

#[test]
fn seams_are_boundaries_of_the_value_mesh() {
    let mesh = with_mode(shape("catmark_fvar_bound1"), Mode::None);
    let v = values(&mesh);
    let ix = mesh.uv_indices.as_ref().expect("vt indices");
    let mut pairs: Vec<(u32, u32)> = mesh
        .face_vertices
        .iter()
        .zip(ix)
        .map(|(&a, &b)| (a, b))
        .collect();
    pairs.sort_unstable();
    pairs.dedup();
    assert_eq!(
        v.mesh.positions.len(),
        pairs.len(),
        "one value per (vertex, vt)"
    );
    // Seams between the three regions: two edges up from the bottom, the row of four across,
    // one edge down from the top.
    let topo = topology::mesh::Topology::from_mesh(&v.mesh).expect("valid value mesh");
    let grid = topology::mesh::Topology::from_mesh(&mesh).expect("valid mesh");
    let boundary = |t: &topology::mesh::Topology| {
        (0..t.num_edges())
            .filter(|&e| t.is_boundary_edge(e))
            .count()
    };
    assert_eq!(boundary(&topo), boundary(&grid) + 2 * 7);
}

/// The corner rule of each mode at a layout corner (a value of one face on a seam) and at a
/// junction of three regions, read off the value mesh and checked on its exact limit: a
/// pinned value is its own limit.
#[test]
fn each_mode_pins_its_corners() {
    // catmark_fvar_bound3: six quads around vertex 0 in three regions of two faces.
    // catmark_fvar_bound1: vertex 2 (bottom edge) is two layout corners, vt 31 and vt 32.
    let junction = |mode| {
        let v = values(&with_mode(shape("catmark_fvar_bound3"), mode));
        let at: Vec<u32> = (0..v.vertex_of.len() as u32)
            .filter(|&i| v.vertex_of[i as usize] == 0)
            .collect();
        assert_eq!(at.len(), 3);
        let pins = at.iter().filter(|&&i| pinned(&v, i)).count();
        (v, at, pins)
    };
    let corner = |mode| {
        let v = values(&with_mode(shape("catmark_fvar_bound1"), mode));
        let at = values_at(&v, 2, [0.4, 0.0]);
        assert_eq!(at.len(), 1);
        let p = pinned(&v, at[0]);
        (v, at[0], p)
    };
    let expected = [
        // (mode, junction pinned, layout corner pinned)
        (Mode::None, false, false),
        (Mode::CornersOnly, false, true),
        (Mode::CornersPlus1, true, true),
        (Mode::CornersPlus2, true, true),
        (Mode::Boundaries, true, true),
    ];
    for (mode, j, c) in expected {
        let (v, at, pins) = junction(mode);
        assert_eq!(pins, if j { 3 } else { 0 }, "{mode}: junction");
        check_limit(&v, &at, j, mode);
        let (v, k, p) = corner(mode);
        assert_eq!(p, c, "{mode}: layout corner");
        check_limit(&v, &[k], c, mode);
    }
}

/// A pinned value is its own limit; a smooth one moves (these layouts are not flat there).
fn check_limit(v: &ValueMesh, at: &[u32], pinned: bool, mode: Mode) {
    let exact = LocalMesh::from_control_mesh(&v.mesh, LimitScheme::CatmullClark).expect("exact");
    for &i in at {
        let limit = exact.vertex_limit_exact(i).expect("limit");
        let value = v.value(i as usize);
        let d = (limit[0] - value[0]).hypot(limit[1] - value[1]);
        if pinned {
            assert!(d < 1e-12, "{mode}: pinned value {i} moved by {d:e}");
        } else {
            assert!(d > 1e-4, "{mode}: smooth value {i} stayed put");
        }
    }
}

/// `boundaries`: every seam and boundary is the polyline of its values.
#[test]
fn boundaries_mode_is_linear_along_seams() {
    let mesh = with_mode(shape("catmark_fvar_bound1"), Mode::Boundaries);
    let v = values(&mesh);
    let exact = LocalMesh::from_control_mesh(&v.mesh, LimitScheme::CatmullClark).expect("exact");
    let topo = topology::mesh::Topology::from_mesh(&v.mesh).expect("topology");
    let mut checked = 0;
    for f in 0..v.mesh.num_faces() {
        let fv = v.mesh.face(f);
        for (k, e) in topo.face_edge_list(f).iter().enumerate() {
            if !topo.is_boundary_edge(*e as usize) {
                continue;
            }
            let (a, b) = (fv[k], fv[(k + 1) % 4]);
            let param = [[0.5, 0.0], [1.0, 0.5], [0.5, 1.0], [0.0, 0.5]][k];
            let s = exact.evaluate(f, param[0], param[1]).expect("limit");
            let (pa, pb) = (v.value(a as usize), v.value(b as usize));
            let mid = [0.5 * (pa[0] + pb[0]), 0.5 * (pa[1] + pb[1])];
            let d = (s.position[0] - mid[0]).hypot(s.position[1] - mid[1]);
            assert!(d < 1e-12, "face {f} edge {k}: {d:e} off the segment");
            checked += 1;
        }
    }
    assert_eq!(
        checked, 30,
        "16 boundary edges of the grid and 14 seam sides"
    );
}

#[test]
fn all_is_bilinear_and_has_no_value_mesh() {
    let mesh = shape("catmark_fvar_bound1");
    assert_eq!(mesh.options.fvar_interpolation, Mode::All, "OBJ default");
    assert!(texcoord_mesh(&mesh, Scheme::CatmullClark).is_none());
    let mut bare = with_mode(mesh, Mode::None);
    bare.uvs = None;
    bare.uv_indices = None;
    assert!(texcoord_mesh(&bare, Scheme::CatmullClark).is_none());
}

/// Worst distance between the face-varying patches' look-up and the exact limit of the
/// value mesh at a lattice of every surface patch: (regular leaves, every leaf).
fn patch_deviation(mesh: &ControlMesh, plan: &AdaptivePlan, fvar: &FVarPatches) -> (f64, f64) {
    let v = values(mesh);
    let exact = LocalMesh::from_control_mesh(&v.mesh, LimitScheme::CatmullClark).expect("exact");
    let (mut regular, mut all) = (0.0f64, 0.0f64);
    for p in &plan.patches {
        let root = fvar.root_of(p);
        for i in 0..5 {
            for j in 0..5 {
                let (u, w) = (i as f64 / 4.0, j as f64 / 4.0);
                if p.kind == PatchKind::GregoryTriangle && u + w > 1.0 {
                    continue;
                }
                let (sub, s, t) = p.base_param(u, w);
                let param = if p.kind == PatchKind::GregoryTriangle {
                    [u, w]
                } else {
                    [s, t]
                };
                let got = fvar.texcoord(root, param).expect("covered");
                let face = p.base_face as usize;
                let e = if mesh.face(face).len() == 4 {
                    exact.evaluate(face, s, t)
                } else {
                    exact.evaluate_subface(face, sub as usize, s, t)
                }
                .expect("exact")
                .position;
                let d = (got[0] - e[0]).hypot(got[1] - e[1]);
                all = all.max(d);
                if leaf_is_regular(fvar, root, param) {
                    regular = regular.max(d);
                }
            }
        }
    }
    (regular, all)
}

/// Whether the leaf at `param` is a B-spline patch of the layout's plan.
fn leaf_is_regular(fvar: &FVarPatches, root: u32, param: [f64; 2]) -> bool {
    fvar.leaf_at(root, param)
        .is_some_and(|(leaf, _, _)| leaf.kind == PatchKind::Regular)
}

/// Mode `none` with the vertex topology: the patches' texture coordinates are the exact
/// Catmull-Clark limit of the coordinates taken as positions, to rounding on regular leaves
/// and within the end caps' deviation elsewhere; every smooth mode on the layouts with seams
/// too.
#[test]
fn adaptive_patches_follow_the_exact_limit() {
    let cases = [
        (continuous_layout(shape("catmark_cube")), Mode::None),
        (continuous_layout(shape("catmark_edgecorner")), Mode::None),
        (shape("catmark_fvar_bound1"), Mode::None),
        (shape("catmark_fvar_bound1"), Mode::CornersPlus1),
        (shape("catmark_fvar_bound2"), Mode::CornersOnly),
        (shape("catmark_fvar_bound3"), Mode::CornersPlus2),
        (shape("catmark_fvar_bound4"), Mode::Boundaries),
        (shape("catmark_fvar_project0"), Mode::CornersPlus1),
    ];
    for (mesh, mode) in cases {
        let mesh = with_mode(mesh, mode);
        let opts = AdaptiveOptions::default();
        let plan = plan_adaptive(&mesh, &opts).expect("plan");
        let fvar = texcoord_patches(&mesh, &FVarPlan::Adaptive(opts))
            .expect("smooth")
            .expect("patches");
        let (regular, all) = patch_deviation(&mesh, &plan, &fvar);
        println!("{mode}: regular leaves {regular:.2e}, all {all:.2e}");
        assert!(regular < 1e-12, "{mode}: regular leaves off by {regular:e}");
        assert!(all < 5e-3, "{mode}: end caps off by {all:e}");
    }
}

/// Single-pass plans: every surface patch finds its layout patch, exact where both are
/// regular, Gregory triangles looked up at their own barycentric parameter.
#[test]
fn single_pass_patches_cover_every_surface_patch() {
    for (name, mode) in [
        ("catmark_fvar_bound1", Mode::CornersPlus1),
        ("catmark_fvar_bound3", Mode::None),
        ("catmark_pyramid", Mode::None),
    ] {
        let base = shape(name);
        let mesh = with_mode(
            if base.uvs.is_some() {
                base
            } else {
                continuous_layout(base)
            },
            mode,
        );
        let opts = SinglePassOptions::default();
        let plan = plan_single_pass(&mesh, &opts).expect("plan");
        let fvar = texcoord_patches(&mesh, &FVarPlan::SinglePass(opts))
            .expect("smooth")
            .expect("patches");
        let (regular, all) = patch_deviation(&mesh, &plan, &fvar);
        println!("{name} {mode}: regular leaves {regular:.2e}, all {all:.2e}");
        assert!(regular < 1e-12, "{name}: {regular:e}");
        assert!(all < 0.1, "{name}: {all:e}");
    }
}

/// `t facevaryinginterpolateboundary` takes OpenSubdiv's integer (0 none … 5 all, as `Far`
/// reads it) or USD's name; the `vt` indices are the layout's topology.
#[test]
fn the_obj_tag_sets_the_mode() {
    let quad = "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nvt 0 0\nvt 1 0\nvt 1 1\nvt 0 1\n\
                f 1/1 2/2 3/3 4/4\n";
    let parse = |tag: &str| topology::mesh::obj::parse_obj(&format!("{quad}{tag}\n"), "t.obj");
    for (k, mode) in Mode::ALL_MODES.into_iter().enumerate() {
        let m = parse(&format!("t facevaryinginterpolateboundary 1/0/0 {k}")).expect("int");
        assert_eq!(m.options.fvar_interpolation, mode);
        let m = parse(&format!(
            "t facevaryinginterpolateboundary 0/0/1 {}",
            mode.name()
        ))
        .expect("name");
        assert_eq!(m.options.fvar_interpolation, mode);
    }
    let e = parse("t facevaryinginterpolateboundary 1/0/0 6").expect_err("out of range");
    assert!(
        e.to_string().starts_with(
            "t.obj:10: tag 'facevaryinginterpolateboundary': 6; expected one integer: 0 (none)"
        ),
        "{e}"
    );
    let m = parse("").expect("plain");
    assert_eq!(m.uv_indices, Some(vec![0, 1, 2, 3]));
    assert_eq!(m.options.fvar_interpolation, Mode::All);
}
