//! The feature-adaptive plan against the exact limit ([`topology::limit::eval`]) on every OpenSubdiv
//! `catmark_*` shape in tests/data and on spot: regular patches exact, end caps converging with
//! the isolation level, canonical curves equal to each patch's own edges (transitions
//! included), balance, uniform counts and errors.

use std::collections::HashMap;

use rayon::prelude::*;

use topology::limit::eval::{LimitScheme, LocalMesh};
use topology::mesh::{EdgeCrease, VertexCorner};
use topology::patches::adaptive::{
    plan_adaptive, AdaptiveOptions, AdaptivePlan, EdgeKind, EndCap, PatchKind,
};
use topology::{load_obj, ControlMesh, TopologyError};

const SHAPES: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../tests/data/opensubdiv/shapes/"
);
const SPOT: &str = concat!(
    env!("CARGO_MANIFEST_DIR"),
    "/../../assets/spot_control_mesh.obj"
);

/// Every catmark shape in tests/data (or in the folder `ADAPTIVE_SHAPES_DIR` names, for runs
/// on OpenSubdiv's whole shape set), then spot. Shapes that are not manifold are skipped.
fn shapes() -> Vec<(String, ControlMesh)> {
    let dir = std::env::var("ADAPTIVE_SHAPES_DIR").unwrap_or_else(|_| SHAPES.to_string());
    let mut names: Vec<String> = std::fs::read_dir(&dir)
        .expect("shape folder")
        .filter_map(|e| e.ok())
        .map(|e| e.file_name().to_string_lossy().into_owned())
        .filter(|n| n.starts_with("catmark_") && n.ends_with(".obj"))
        .collect();
    names.sort();
    assert!(names.len() >= 15, "catmark shapes missing: {names:?}");
    let mut out: Vec<(String, ControlMesh)> = names
        .into_iter()
        .filter_map(|n| {
            let mesh = load_obj(format!("{dir}/{n}"));
            if dir == SHAPES {
                Some((n, mesh.expect("shape loads")))
            } else {
                mesh.ok().map(|m| (n, m))
            }
        })
        .collect();
    out.push(("spot".into(), load_obj(SPOT).expect("spot loads")));
    out
}

fn diag(mesh: &ControlMesh) -> f64 {
    mesh.bbox_diagonal()
}

fn dist(a: &[f64; 3], b: &[f64]) -> f64 {
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

/// Largest finite tag sharpness: a patch at a level at or above it sees no semi-sharp feature.
fn max_semi_sharpness(mesh: &ControlMesh) -> f32 {
    mesh.creases
        .iter()
        .map(|c| c.sharpness)
        .chain(mesh.corners.iter().map(|c| c.sharpness))
        .filter(|&s| s < 10.0)
        .fold(0.0, f32::max)
}

fn options(isolation: u32, end_cap: EndCap) -> AdaptiveOptions {
    AdaptiveOptions {
        isolation,
        end_cap,
        sharpness_scale: 1.0,
        follow_semi_sharp: true,
    }
}

/// Exact limit at a patch's `(u, v)`.
fn exact(lm: &LocalMesh, plan: &AdaptivePlan, p: usize, u: f64, v: f64) -> Vec<f64> {
    let pa = &plan.patches[p];
    let (s, t) = (pa.origin[0] + pa.size * u, pa.origin[1] + pa.size * v);
    let face = pa.base_face as usize;
    let sample = if lm.face(face).len() == 4 {
        lm.evaluate(face, s, t)
    } else {
        lm.evaluate_subface(face, pa.sub_face as usize, s, t)
    };
    sample.expect("exact limit").position
}

/// At most `n` patch indices of `kind`, spread over the plan.
fn sample_patches(plan: &AdaptivePlan, kinds: &[PatchKind], n: usize) -> Vec<usize> {
    let all: Vec<usize> = (0..plan.patches.len())
        .filter(|&p| kinds.contains(&plan.patches[p].kind))
        .collect();
    let stride = all.len().div_ceil(n.max(1)).max(1);
    all.into_iter().step_by(stride).collect()
}

const GRID: [f64; 3] = [0.0, 0.37, 1.0];

#[test]
#[ignore = "sweep tier (every shape and isolation level): tools/test.sh sweeps"]
fn regular_patches_are_the_exact_limit() {
    for (name, mesh) in shapes() {
        let lm = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).expect("mesh");
        let d = diag(&mesh);
        let semi = max_semi_sharpness(&mesh);
        for iso in 1..=4 {
            let plan = plan_adaptive(&mesh, &options(iso, EndCap::Bilinear))
                .unwrap_or_else(|e| panic!("{name} iso {iso}: {e}"));
            let verts = plan.apply(&mesh.positions);
            let mut worst = 0.0f64;
            let (mut checked, mut skipped) = (0, 0);
            for p in sample_patches(&plan, &[PatchKind::Regular], 250) {
                let pa = &plan.patches[p];
                // At the isolation level leftover semi-sharpness is treated as infinite.
                if pa.level as u32 == iso && semi > pa.level as f32 {
                    skipped += 1;
                    continue;
                }
                for &u in &GRID {
                    for &v in &GRID {
                        let got = plan.evaluate(&verts, p, u, v).position;
                        let want = exact(&lm, &plan, p, u, v);
                        worst = worst.max(dist(&got, &want));
                    }
                }
                checked += 1;
            }
            assert!(
                worst <= 1e-9 * d,
                "{name} iso {iso}: regular patch off the limit by {worst:e} (diag {d})"
            );
            assert!(
                checked > 0 || skipped > 0 || plan.level_stats.iter().all(|s| s.regular == 0),
                "{name}: no regular patch checked"
            );
        }
    }
}

/// Largest distance of the end caps (and of everything) from the exact limit.
fn deviations(mesh: &ControlMesh, iso: u32, end_cap: EndCap) -> (f64, f64) {
    let lm = LocalMesh::from_control_mesh(mesh, LimitScheme::CatmullClark).expect("mesh");
    let plan = plan_adaptive(mesh, &options(iso, end_cap)).expect("plan");
    let verts = plan.apply(&mesh.positions);
    let grid = [0.0, 0.25, 0.5, 0.75, 1.0];
    let mut caps = 0.0f64;
    for p in sample_patches(&plan, &[PatchKind::Gregory, PatchKind::Bilinear], 400) {
        for &u in &grid {
            for &v in &grid {
                let got = plan.evaluate(&verts, p, u, v).position;
                caps = caps.max(dist(&got, &exact(&lm, &plan, p, u, v)));
            }
        }
    }
    let mut all = caps;
    for p in sample_patches(&plan, &[PatchKind::Regular], 200) {
        let got = plan.evaluate(&verts, p, 0.5, 0.5).position;
        all = all.max(dist(&got, &exact(&lm, &plan, p, 0.5, 0.5)));
    }
    (caps / diag(mesh), all / diag(mesh))
}

#[test]
fn end_caps_converge_with_isolation() {
    for name in ["catmark_cube.obj", "catmark_pyramid.obj", "spot"] {
        let mesh = if name == "spot" {
            load_obj(SPOT).expect("spot")
        } else {
            load_obj(format!("{SHAPES}{name}")).expect("shape")
        };
        for end_cap in [EndCap::Bilinear, EndCap::Gregory] {
            let devs: Vec<(f64, f64)> =
                (1..=4).map(|iso| deviations(&mesh, iso, end_cap)).collect();
            for (iso, (caps, all)) in devs.iter().enumerate() {
                println!(
                    "{name} {end_cap:?} isolation {}: end caps {caps:.3e}, whole surface {all:.3e} of the diagonal",
                    iso + 1
                );
            }
            assert!(
                devs[3].0 < devs[0].0 && devs[3].0 < 0.5 * devs[1].0,
                "{name} {end_cap:?}: end-cap deviation does not shrink: {devs:?}"
            );
        }
    }
}

/// An end cap beside a semi-sharp crease gets the isolation level's smooth steps after the
/// crease decays, as every other end cap does, so its error shrinks with the isolation level.
/// catmark_cube_creases1's sharpness-5 creases meet at valence-3 corners; capped on the level
/// where the creases decay (the former rule), its caps were the same 8.7e-5 of the diagonal at
/// isolation 4 and 5.
#[test]
fn caps_beside_decayed_creases_shrink_with_isolation() {
    let mesh = load_obj(format!("{SHAPES}catmark_cube_creases1.obj")).expect("shape");
    let caps: Vec<f64> = (3..=5)
        .map(|iso| deviations(&mesh, iso, EndCap::Gregory).0)
        .collect();
    println!("catmark_cube_creases1 Gregory caps, isolation 3..5: {caps:?}");
    assert!(caps[1] <= 5e-5, "isolation 4: caps {:.3e}", caps[1]);
    for w in caps.windows(2) {
        assert!(w[1] < 0.5 * w[0], "caps do not shrink: {caps:?}");
    }
}

/// Largest distance of any Gregory end cap from the limit surface (nearest point, 9×9 points a
/// cap), over the bbox diagonal.
fn cap_distance(mesh: &ControlMesh, iso: u32) -> f64 {
    let lm = LocalMesh::from_control_mesh(mesh, LimitScheme::CatmullClark).expect("mesh");
    let plan = plan_adaptive(mesh, &options(iso, EndCap::Gregory)).expect("plan");
    let verts = plan.apply(&mesh.positions);
    let d = diag(mesh);
    // Patches in parallel: one patch's worst prunes its own points.
    (0..plan.patches.len())
        .into_par_iter()
        .filter(|&p| plan.patches[p].kind == PatchKind::Gregory)
        .map(|p| {
            let mut worst = 0.0f64;
            for i in 0..=8 {
                for j in 0..=8 {
                    let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
                    let got = plan.evaluate(&verts, p, u, v).position;
                    // The nearest point is no farther than the same parameter's.
                    if dist(&got, &exact(&lm, &plan, p, u, v)) <= worst * d {
                        continue;
                    }
                    let pa = &plan.patches[p];
                    let st = [pa.origin[0] + pa.size * u, pa.origin[1] + pa.size * v];
                    let face = pa.base_face as usize;
                    let sub = (lm.face(face).len() != 4).then_some(pa.sub_face as usize);
                    let g = lm
                        .nearest_limit_distance(face, sub, st, &got)
                        .expect("exact limit");
                    worst = worst.max(g / d);
                }
            }
            worst
        })
        .reduce(|| 0.0, f64::max)
}

/// End caps at vertices whose caps converge slowly are isolated deeper (`cap_depth` in the
/// plan's levels), so every cap is within 5e-5 of the diagonal of the limit surface at
/// isolation 4. With every vertex capped after four levels they were: catmark_cube_corner4's
/// cone (an infinitely sharp corner on smooth edges) 1.8e-3, catmark_cubes_infsharp's cone and
/// darts 1.1e-3, catmark_inf_crease1's corner of three sharp edges 9.1e-4, catmark_inf_crease0's
/// 3.9e-4, spot's valence-6 vertices 6.8e-5.
#[test]
fn slow_caps_are_isolated_until_they_meet_the_bound() {
    for name in [
        "catmark_cube_corner4.obj",
        "catmark_cubes_infsharp.obj",
        "catmark_inf_crease0.obj",
        "catmark_inf_crease1.obj",
        "spot",
    ] {
        let mesh = if name == "spot" {
            load_obj(SPOT).expect("spot")
        } else {
            load_obj(format!("{SHAPES}{name}")).expect("shape")
        };
        let worst = cap_distance(&mesh, 4);
        println!("{name}: Gregory caps at isolation 4 within {worst:.3e} of the diagonal");
        assert!(
            worst <= 5e-5,
            "{name}: caps {worst:.3e} from the limit surface"
        );
    }
}

/// Every patch corner is its canonical limit point, the exact limit, darts included
/// (catmark_cubes_infsharp's single infinitely sharp edges end in darts, whose limit is not the
/// smooth mask's: 3e-4 of the diagonal at isolation 4 before the dart mask).
#[test]
fn patch_corners_are_the_exact_limit_at_darts() {
    let mesh = load_obj(format!("{SHAPES}catmark_cubes_infsharp.obj")).expect("shape");
    let lm = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).expect("mesh");
    let d = diag(&mesh);
    for iso in [2, 4] {
        for end_cap in [EndCap::Gregory, EndCap::Bilinear] {
            let plan = plan_adaptive(&mesh, &options(iso, end_cap)).expect("plan");
            let verts = plan.apply(&mesh.positions);
            let mut worst = 0.0f64;
            for p in 0..plan.patches.len() {
                for (u, v) in [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)] {
                    let got = plan.evaluate(&verts, p, u, v).position;
                    worst = worst.max(dist(&got, &exact(&lm, &plan, p, u, v)));
                }
            }
            assert!(
                worst <= 1e-9 * d,
                "isolation {iso} {end_cap:?}: a patch corner is {:.3e} off the limit",
                worst / d
            );
        }
    }
}

#[test]
#[ignore = "sweep tier (every shape, isolation level and end cap): tools/test.sh sweeps"]
fn curves_are_each_patch_edge_and_corners_are_shared() {
    for (name, mesh) in shapes() {
        let d = diag(&mesh);
        for iso in 1..=4 {
            for end_cap in [EndCap::Bilinear, EndCap::Gregory] {
                let plan = plan_adaptive(&mesh, &options(iso, end_cap))
                    .unwrap_or_else(|e| panic!("{name} iso {iso}: {e}"));
                check_curves(&name, &plan, &mesh, d);
            }
        }
    }
}

fn check_curves(name: &str, plan: &AdaptivePlan, mesh: &ControlMesh, d: f64) {
    let verts = plan.apply(&mesh.positions);
    let mut refs = vec![0u32; plan.curves.len()];
    let mut levels: Vec<Vec<u8>> = vec![Vec::new(); plan.curves.len()];
    for (p, pa) in plan.patches.iter().enumerate() {
        // Each corner: the end of one edge's curve is the start of the next one's.
        let ends: Vec<(u32, u32)> = pa
            .edges
            .iter()
            .map(|e| {
                let (first, last) = match e.kind {
                    EdgeKind::Coarse => (0, 1),
                    _ => (0, 0),
                };
                let start = |k: usize| {
                    let c = plan.curves[e.curves[k] as usize];
                    if e.reversed[k] {
                        c[3]
                    } else {
                        c[0]
                    }
                };
                let end = |k: usize| {
                    let c = plan.curves[e.curves[k] as usize];
                    if e.reversed[k] {
                        c[0]
                    } else {
                        c[3]
                    }
                };
                (start(first), end(last))
            })
            .collect();
        for k in 0..4 {
            assert_eq!(
                ends[k].1,
                ends[(k + 1) % 4].0,
                "{name}: patch {p} corner {} differs between its edges",
                (k + 1) % 4
            );
        }
        if pa.kind == PatchKind::Bilinear {
            for (cp, end) in pa.control_points.iter().zip(&ends) {
                assert_eq!(*cp, end.0, "{name}: bilinear corner");
            }
        }
        for (k, e) in pa.edges.iter().enumerate() {
            match e.kind {
                EdgeKind::Plain => {
                    assert_eq!(e.curves[0], e.curves[1]);
                    refs[e.curves[0] as usize] += 1;
                }
                EdgeKind::Coarse => {
                    assert!(pa.transition_mask & (1 << k) != 0);
                    assert_ne!(e.curves[0], e.curves[1]);
                    refs[e.curves[0] as usize] += 1;
                    refs[e.curves[1] as usize] += 1;
                }
                EdgeKind::Fine => refs[e.curves[0] as usize] += 1,
            }
            if e.kind != EdgeKind::Coarse {
                assert!(pa.transition_mask & (1 << k) == 0);
            }
            for c in e.curves {
                levels[c as usize].push(pa.level);
            }
            // The curves are the patch's own edge (Coons patches reproduce theirs exactly).
            // A Gregory cap across a transition (next to finer patches that follow a
            // semi-sharp crease, or to a coarser regular patch) takes the regular side's exact
            // boundary instead: no crack, but not its own boundary.
            if pa.kind == PatchKind::Gregory && e.kind != EdgeKind::Plain {
                continue;
            }
            for t in [0.0, 0.2, 0.5, 0.7, 1.0] {
                let (u, v) = match k {
                    0 => (t, 0.0),
                    1 => (1.0, t),
                    2 => (1.0 - t, 1.0),
                    _ => (0.0, 1.0 - t),
                };
                let own = plan.evaluate(&verts, p, u, v).position;
                let (curve, _) = plan.edge_sample(&verts, p, k, t);
                let err = dist(&own, &curve);
                assert!(
                    err <= 1e-9 * d,
                    "{name}: patch {p} ({:?}, level {}) edge {k} ({:?}) at {t}: curve off by {err:e}",
                    pa.kind,
                    pa.level,
                    e.kind
                );
            }
            if e.kind == EdgeKind::Plain {
                let c = plan.curves[e.curves[0] as usize];
                let at = |t: f64| plan.curve_point(&verts, e.curves[0] as usize, t);
                let own =
                    plan.evaluate(&verts, p, [0.5, 1.0, 0.5, 0.0][k], [0.0, 0.5, 1.0, 0.5][k]);
                assert!(dist(&own.position, &at(0.5)) <= 1e-9 * d);
                assert!(c[0] < c[3], "{name}: curve ends not ascending");
            }
        }
    }
    // Every curve is used by one side (boundary) or two sides, within one level.
    let closed = mesh.holes.is_empty()
        && topology::mesh::Topology::from_mesh(mesh)
            .map(|t| (0..t.num_edges()).all(|e| !t.is_boundary_edge(e)))
            .unwrap_or(false);
    for (c, &n) in refs.iter().enumerate() {
        assert!(
            n == 2 || (n == 1 && !closed),
            "{name}: curve {c} used by {n} patch sides"
        );
        let lv = &levels[c];
        let (lo, hi) = (lv.iter().min().unwrap(), lv.iter().max().unwrap());
        assert!(hi - lo <= 1, "{name}: curve {c} joins levels {lo} and {hi}");
    }
    // Distinct canonical corners are distinct limit points (one id per point), except on
    // OpenSubdiv's degenerate valence-2 shapes, where two sheets share their limit points.
    if name.contains("val2") {
        return;
    }
    let mut corner_ids: Vec<u32> = plan.curves.iter().flat_map(|c| [c[0], c[3]]).collect();
    corner_ids.sort_unstable();
    corner_ids.dedup();
    let mut pts: Vec<([f64; 3], u32)> =
        corner_ids.iter().map(|&i| (verts[i as usize], i)).collect();
    pts.sort_by(|a, b| a.0[0].total_cmp(&b.0[0]));
    for i in 0..pts.len() {
        for j in i + 1..pts.len() {
            if pts[j].0[0] - pts[i].0[0] > 1e-12 * d {
                break;
            }
            assert!(
                dist(&pts[i].0, &pts[j].0) > 1e-12 * d,
                "{name}: corner ids {} and {} are the same limit point",
                pts[i].1,
                pts[j].1
            );
        }
    }
}

#[test]
fn blocks_read_only_earlier_vertices() {
    for (name, mesh) in shapes() {
        let plan = plan_adaptive(&mesh, &options(3, EndCap::Gregory)).expect("plan");
        assert_eq!(plan.num_base_vertices as usize, mesh.positions.len());
        let mut next = plan.num_base_vertices;
        for b in plan.steps.iter().chain(std::iter::once(&plan.local_points)) {
            assert_eq!(b.first_vertex, next, "{name}: blocks are contiguous");
            assert!(
                b.table.indices.iter().all(|&i| i < b.first_vertex),
                "{name}: a block reads itself"
            );
            // Every row is an affine combination, non-empty: the GPU sums it as offsets from
            // its first term's vertex.
            for r in 0..b.table.len() {
                let (idx, w) = b.table.stencil(r);
                let sum: f64 = w.iter().sum();
                assert!(
                    !idx.is_empty() && (sum - 1.0).abs() < 1e-9,
                    "{name}: row {r} of the block at {} sums to {sum}",
                    b.first_vertex
                );
            }
            next += b.table.len() as u32;
        }
        // Then the canonical corners of regular patches and the curves' inner points
        // (two per curve in curve order), which no block computes.
        assert_eq!(next, plan.first_regular_corner, "{name}");
        assert_eq!(
            plan.first_corner as usize + plan.corner_owners.len(),
            plan.first_curve_point as usize,
            "{name}: the canonical corners run up to the curve points"
        );
        let regular_from = (plan.first_regular_corner - plan.first_corner) as usize;
        for &[pi, c] in &plan.corner_owners[regular_from..] {
            let pa = &plan.patches[pi as usize];
            assert!(pa.kind == PatchKind::Regular && c < 4, "{name}");
            assert!(pa
                .control_points
                .iter()
                .all(|&v| v < plan.first_regular_corner));
        }
        // Every corner first met on a regular patch is evaluated from it: none of the corners
        // with rows has a regular owner.
        for &[pi, _] in &plan.corner_owners[..regular_from] {
            assert_ne!(
                plan.patches[pi as usize].kind,
                PatchKind::Regular,
                "{name}: a corner of a regular patch has a row"
            );
        }
        let next = plan.first_curve_point;
        for (c, curve) in plan.curves.iter().enumerate() {
            assert_eq!(curve[1], next + 2 * c as u32, "{name}: curve {c}");
            assert_eq!(curve[2], curve[1] + 1, "{name}: curve {c}");
        }
        assert_eq!(next + 2 * plan.curves.len() as u32, plan.num_vertices);
        // Semi-sharp features are followed past the isolation level until they decay, and
        // slowly converging vertices further (at most level 14).
        assert!(
            (3..=14).contains(&plan.steps.len()),
            "{name}: {} steps",
            plan.steps.len()
        );
        for pa in &plan.patches {
            let n = match pa.kind {
                PatchKind::Regular => 16,
                PatchKind::Gregory => 20,
                PatchKind::Bilinear => 4,
                PatchKind::GregoryTriangle => 27,
            };
            assert_eq!(pa.control_points.len(), n);
            assert!(pa.control_points.iter().all(|&i| i < plan.num_vertices));
        }
        for c in &plan.curves {
            assert!(c.iter().all(|&i| i < plan.num_vertices));
        }
    }
}

#[test]
fn patches_tile_each_base_face() {
    // The patches of each (sub)face cover its unit square exactly once.
    for (name, mesh) in shapes() {
        let plan = plan_adaptive(&mesh, &options(4, EndCap::Bilinear)).expect("plan");
        let mut area: HashMap<(u32, u8), f64> = HashMap::new();
        for pa in &plan.patches {
            *area.entry((pa.base_face, pa.sub_face)).or_default() += pa.size * pa.size;
            assert!(pa.origin[0] >= 0.0 && pa.origin[0] + pa.size <= 1.0);
            assert!(pa.origin[1] >= 0.0 && pa.origin[1] + pa.size <= 1.0);
        }
        let holes: Vec<u32> = mesh.holes.clone();
        for f in 0..mesh.num_faces() as u32 {
            if holes.contains(&f) {
                continue;
            }
            let n = mesh.face(f as usize).len();
            let subs = if n == 4 { 1 } else { n };
            for s in 0..subs {
                let a = area.get(&(f, s as u8)).copied().unwrap_or(0.0);
                assert!((a - 1.0).abs() < 1e-12, "{name}: face {f}.{s} covered {a}");
            }
        }
    }
}

#[test]
fn full_isolation_of_the_cube_is_uniform() {
    let mesh = load_obj(format!("{SHAPES}catmark_cube.obj")).expect("cube");
    let plan = plan_adaptive(&mesh, &options(4, EndCap::Bilinear)).expect("plan");
    // Every face of levels 0 and 1 touches a valence-3 vertex, so levels 1 and 2 are uniform.
    for l in 0..=2 {
        let s = plan.level_stats[l];
        assert_eq!(s.faces as u64, s.uniform_faces, "level {l}: {s:?}");
    }
    assert_eq!(plan.level_stats[1].uniform_faces, 24);
    assert_eq!(plan.level_stats[2].uniform_faces, 96);
    assert_eq!(plan.steps[0].table.len(), 26);
    assert_eq!(plan.steps[1].table.len(), 98);
    // Level 3 still holds every face (the corners' one-rings cover the cube), level 4 not.
    assert!((plan.level_stats[4].faces as u64) < plan.level_stats[4].uniform_faces);
    // The cube's regular patches: none at levels 0 and 1 (every face touches a corner).
    assert_eq!(plan.level_stats[0].regular + plan.level_stats[1].regular, 0);
    assert_eq!(plan.level_stats[4].end_caps, 8 * 3);
}

#[test]
fn spot_face_counts_per_level() {
    let mesh = load_obj(SPOT).expect("spot");
    for iso in [4, 6] {
        let t = std::time::Instant::now();
        let plan = plan_adaptive(&mesh, &options(iso, EndCap::Gregory)).expect("plan");
        let ms = t.elapsed().as_secs_f64() * 1e3;
        println!("spot, isolation {iso} ({ms:.1} ms, this build):");
        println!("level  regular  end caps  faces held  uniform faces");
        for (l, s) in plan.level_stats.iter().enumerate() {
            println!(
                "{l:5}  {:7}  {:8}  {:10}  {:13}",
                s.regular, s.end_caps, s.faces, s.uniform_faces
            );
            assert!(s.faces as u64 <= s.uniform_faces);
        }
        // Spot's four valence-6 vertices are isolated by their caps' reach,
        // ⌈iso · ln 2 / −ln λ_6⌉ levels (λ_6 ≈ 0.58): 6 at isolation 4, 8 at isolation 6.
        let reach = if iso == 4 { 6 } else { 8 };
        assert_eq!(plan.level_stats.len(), reach + 1);
        // Transitions exist on both sides, and each coarse edge faces fine ones.
        let count = |k: EdgeKind| {
            plan.patches
                .iter()
                .flat_map(|p| p.edges.iter())
                .filter(|e| e.kind == k)
                .count()
        };
        let (coarse, fine) = (count(EdgeKind::Coarse), count(EdgeKind::Fine));
        println!("{coarse} coarse and {fine} fine transition edges");
        assert!(
            coarse > 0 && fine == 2 * coarse,
            "{coarse} coarse, {fine} fine"
        );
        // Spot has triangles and pentagons: nothing is a patch at level 0 around them, and the
        // end caps sit at the isolation level or deeper.
        assert!(plan.level_stats[..iso as usize]
            .iter()
            .all(|s| s.end_caps == 0));
        assert!(plan.level_stats[iso as usize].end_caps > 0);
    }
}

#[test]
fn a_regular_torus_is_one_level_of_patches() {
    // 6×5 quads on a torus: every vertex has valence 4, nothing to isolate.
    let (n, m) = (6usize, 5usize);
    let mut positions = Vec::new();
    for i in 0..n {
        for j in 0..m {
            let (a, b) = (
                i as f64 * std::f64::consts::TAU / n as f64,
                j as f64 * std::f64::consts::TAU / m as f64,
            );
            let r = 2.0 + 0.7 * b.cos();
            positions.push([r * a.cos(), r * a.sin(), 0.7 * b.sin()]);
        }
    }
    let id = |i: usize, j: usize| ((i % n) * m + (j % m)) as u32;
    let faces: Vec<[u32; 4]> = (0..n)
        .flat_map(|i| (0..m).map(move |j| (i, j)))
        .map(|(i, j)| [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)])
        .collect();
    let mesh = ControlMesh::from_polygons(positions, &faces);
    let plan = plan_adaptive(&mesh, &options(3, EndCap::Gregory)).expect("plan");
    assert_eq!(plan.patches.len(), n * m);
    assert!(plan.patches.iter().all(|p| p.level == 0
        && p.kind == PatchKind::Regular
        && p.edges.iter().all(|e| e.kind == EdgeKind::Plain)));
    assert_eq!(plan.steps.len(), 3);
    assert!(plan.steps.iter().all(|s| s.table.is_empty()));
    // Every patch point is a base vertex; the local points are corners and curve points.
    assert!(plan
        .patches
        .iter()
        .all(|p| p.control_points.iter().all(|&i| i < plan.num_base_vertices)));
    assert_eq!(plan.curves.len(), 2 * n * m);
    let lm = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).expect("mesh");
    let verts = plan.apply(&mesh.positions);
    for p in 0..plan.patches.len() {
        let got = plan.evaluate(&verts, p, 0.25, 0.6).position;
        assert!(dist(&got, &exact(&lm, &plan, p, 0.25, 0.6)) < 1e-12);
    }
    check_curves("torus", &plan, &mesh, diag(&mesh));
}

#[test]
fn holes_make_no_patches() {
    let mut mesh = load_obj(format!("{SHAPES}catmark_cube.obj")).expect("cube");
    mesh.holes = vec![0];
    let lm = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).expect("mesh");
    let d = diag(&mesh);
    for iso in 1..=3 {
        let plan = plan_adaptive(&mesh, &options(iso, EndCap::Gregory)).expect("plan");
        assert!(plan.patches.iter().all(|p| p.base_face != 0));
        assert!(plan.patches.iter().any(|p| p.base_face == 1));
        check_curves("cube with a hole", &plan, &mesh, d);
        let verts = plan.apply(&mesh.positions);
        for p in sample_patches(&plan, &[PatchKind::Regular], 100) {
            let got = plan.evaluate(&verts, p, 0.3, 0.6).position;
            assert!(dist(&got, &exact(&lm, &plan, p, 0.3, 0.6)) <= 1e-9 * d);
        }
    }
    let mut bad = mesh.clone();
    bad.holes = vec![6];
    let e = plan_adaptive(&bad, &AdaptiveOptions::default()).unwrap_err();
    assert!(
        matches!(e.root(), TopologyError::TagOutOfRange { .. }),
        "{e}"
    );
}

#[test]
fn sharpness_scale_changes_the_plan() {
    let mesh = load_obj(format!("{SHAPES}catmark_cube_creases1.obj")).expect("shape");
    let lm_smooth = {
        let mut m = mesh.clone();
        m.creases.clear();
        m.corners.clear();
        m
    };
    let zero = AdaptiveOptions {
        sharpness_scale: 0.0,
        ..options(3, EndCap::Bilinear)
    };
    let a = plan_adaptive(&mesh, &zero).expect("plan");
    let b = plan_adaptive(&lm_smooth, &options(3, EndCap::Bilinear)).expect("plan");
    assert_eq!(a.level_stats, b.level_stats, "scale 0 removes the creases");
    let c = plan_adaptive(&mesh, &options(3, EndCap::Bilinear)).expect("plan");
    assert_ne!(a.level_stats, c.level_stats);
}

/// Infinite tags (≥ 10) are scaled too, as 10: at scale 0 a crease of 10.5 is smooth (it
/// stayed sharp), at 0.5 it is a crease of 5, and any scale ≥ 1 keeps it infinite.
#[test]
fn sharpness_scale_scales_infinite_tags_as_ten() {
    let mesh = load_obj(format!("{SHAPES}catmark_cube_creases1.obj")).expect("shape");
    let with = |s: f32| {
        let mut m = mesh.clone();
        for c in &mut m.creases {
            c.sharpness = s;
        }
        m.corners.clear();
        m
    };
    let plan = |m: &ControlMesh, scale: f32| {
        let o = AdaptiveOptions {
            sharpness_scale: scale,
            ..options(3, EndCap::Bilinear)
        };
        plan_adaptive(m, &o).expect("plan").level_stats
    };
    let infinite = with(10.5);
    assert_eq!(
        plan(&infinite, 0.0),
        plan(&with(0.0), 1.0),
        "scale 0: smooth"
    );
    assert_eq!(
        plan(&infinite, 0.5),
        plan(&with(5.0), 1.0),
        "scale 0.5: sharpness 5"
    );
    assert_eq!(
        plan(&infinite, 2.0),
        plan(&with(10.0), 1.0),
        "scale 2: infinite"
    );
    assert_eq!(
        plan(&with(1e30), 0.25),
        plan(&with(2.5), 1.0),
        "every infinite tag as 10"
    );
    assert_ne!(plan(&infinite, 0.5), plan(&infinite, 1.0));
}

#[test]
fn bad_options_and_meshes_are_named_errors() {
    let mesh = load_obj(format!("{SHAPES}catmark_cube.obj")).expect("cube");
    for iso in [0, 9, 100] {
        let e = plan_adaptive(&mesh, &options(iso, EndCap::Gregory)).unwrap_err();
        assert!(
            matches!(e, TopologyError::IsolationOutOfRange { isolation } if isolation == iso),
            "{e}"
        );
    }
    for scale in [f32::NAN, -1.0, f32::INFINITY] {
        let o = AdaptiveOptions {
            sharpness_scale: scale,
            ..AdaptiveOptions::default()
        };
        let e = plan_adaptive(&mesh, &o).unwrap_err();
        assert!(matches!(e, TopologyError::BadSharpnessScale { .. }), "{e}");
    }
    for s in [f32::NAN, -0.5] {
        let mut m = mesh.clone();
        m.creases.push(EdgeCrease {
            vertices: [0, 1],
            sharpness: s,
        });
        let e = plan_adaptive(&m, &AdaptiveOptions::default()).unwrap_err();
        assert!(
            matches!(e, TopologyError::BadEdgeSharpness { v0: 0, v1: 1, .. }),
            "{e}"
        );
        let mut m = mesh.clone();
        m.corners.push(VertexCorner {
            vertex: 3,
            sharpness: s,
        });
        let e = plan_adaptive(&m, &AdaptiveOptions::default()).unwrap_err();
        assert!(
            matches!(e, TopologyError::BadVertexSharpness { vertex: 3, .. }),
            "{e}"
        );
    }
    // Three quads on one edge.
    let nonmanifold = ControlMesh::from_polygons(
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
    let e = plan_adaptive(&nonmanifold, &AdaptiveOptions::default()).unwrap_err();
    assert!(
        matches!(e.root(), TopologyError::NonManifoldEdge { .. }),
        "{e}"
    );
    // A 300-gon: sub-faces are numbered with 8 bits.
    let n = 300;
    let ring: Vec<[f64; 3]> = (0..n)
        .map(|i| {
            let a = i as f64 * std::f64::consts::TAU / n as f64;
            [a.cos(), a.sin(), 0.0]
        })
        .collect();
    let big = ControlMesh::from_polygons(ring, &[(0..n as u32).collect::<Vec<u32>>()]);
    let e = plan_adaptive(&big, &AdaptiveOptions::default()).unwrap_err();
    assert!(
        matches!(
            e,
            TopologyError::AdaptiveFaceTooLarge { face: 0, size: 300 }
        ),
        "{e}"
    );
    let empty = ControlMesh::default();
    assert!(plan_adaptive(&empty, &AdaptiveOptions::default()).is_err());
}

/// The size bound is checked before each refinement step: the cube (6 quads, every corner
/// extraordinary) at isolation 3 projects 24 children × 3 levels = 72 refined faces at level
/// 0, then 24 + 96 × 2 = 216 at level 1; a bound below either is a named error carrying the
/// mesh size and the isolation, and the default bound plans it.
#[test]
fn a_plan_projected_past_its_bound_is_refused_before_refining() {
    use topology::patches::adaptive::plan_adaptive_within;
    let mesh = load_obj(format!("{SHAPES}catmark_cube.obj")).expect("cube");
    let opts = options(3, EndCap::Gregory);
    for (bound, level, estimate) in [(71, 0, 72), (72, 1, 216)] {
        let e = plan_adaptive_within(&mesh, &opts, bound).unwrap_err();
        println!("{e}");
        assert!(
            matches!(
                e,
                TopologyError::AdaptiveTooLarge { faces: 6, isolation: 3, level: l, estimate: x, bound: b }
                    if l == level && x == estimate && b == bound
            ),
            "{e}"
        );
    }
    let plan = plan_adaptive_within(&mesh, &opts, 216).expect("within 216");
    assert_eq!(plan, plan_adaptive(&mesh, &opts).expect("default bound"));
}
