//! Texture coordinates and curve owners of adaptive and single-pass plans (CPU): each curve's
//! owner evaluates to the curve (what seamless displacement relies on), texture coordinates are
//! continuous inside a base face, and the texture reparameterization of seed 003 lowers the
//! pointwise texture error of Eq. 1 on real meshes (spot and OpenSubdiv's shapes).
use topology::limit::eval::{LimitScheme, LocalMesh};
use topology::patches::adaptive::single_pass::{
    plan_single_pass, SinglePassOptions, SinglePassPatch,
};
use topology::patches::adaptive::{plan_adaptive, AdaptiveOptions, AdaptivePlan, PatchKind};
use topology::patches::texcoord::{has_texcoords, patch_parameter, patch_texcoord};
use topology::{load_obj, ControlMesh};

fn data(rel: &str) -> String {
    format!("{}/../../{rel}", env!("CARGO_MANIFEST_DIR"))
}

fn shapes() -> Vec<(String, ControlMesh)> {
    let dir = data("tests/data/opensubdiv/shapes");
    let mut out: Vec<(String, ControlMesh)> = [
        "catmark_cube",
        "catmark_pawn",
        "catmark_car",
        "catmark_bishop",
        "catmark_cube_creases1",
        "catmark_edgecorner",
    ]
    .iter()
    .filter_map(|n| Some((n.to_string(), load_obj(format!("{dir}/{n}.obj")).ok()?)))
    .collect();
    out.push((
        "spot".into(),
        load_obj(data("assets/spot_control_mesh.obj")).unwrap(),
    ));
    out
}

fn diag(m: &ControlMesh) -> f64 {
    m.bbox_diagonal()
}

fn dist(a: [f64; 3], b: impl AsRef<[f64]>) -> f64 {
    let b = b.as_ref();
    (0..3).map(|k| (a[k] - b[k]).powi(2)).sum::<f64>().sqrt()
}

fn plans(mesh: &ControlMesh) -> Vec<(&'static str, AdaptivePlan)> {
    let single = |patch| {
        plan_single_pass(
            mesh,
            &SinglePassOptions {
                patch,
                ..Default::default()
            },
        )
        .unwrap()
    };
    vec![
        ("gregory", single(SinglePassPatch::Gregory)),
        ("acc", single(SinglePassPatch::Acc1)),
        (
            "adaptive 2",
            plan_adaptive(
                mesh,
                &AdaptiveOptions {
                    isolation: 2,
                    ..Default::default()
                },
            )
            .unwrap(),
        ),
    ]
}

#[test]
fn every_curve_is_its_owners_edge() {
    for (name, mesh) in shapes() {
        let d = diag(&mesh);
        for (method, plan) in plans(&mesh) {
            assert_eq!(
                plan.curve_owners.len(),
                plan.curves.len(),
                "{name} {method}"
            );
            let verts = plan.apply(&mesh.positions);
            // Every curve is exactly its owner's edge (a fine patch owns each half of a
            // transition edge; a triangle patch's boundary is its halves); "half" figures
            // are kept apart to say so.
            let (mut worst, mut worst_half) = (0.0f64, 0.0f64);
            for (c, o) in plan.curves.iter().zip(&plan.curve_owners) {
                let half = o.part != 0 && plan.patches[o.patch as usize].kind != PatchKind::Regular;
                for k in 0..=4 {
                    let s = k as f64 / 4.0;
                    let r = 1.0 - s;
                    let w = [r * r * r, 3.0 * s * r * r, 3.0 * s * s * r, s * s * s];
                    let mut b = [0.0; 3];
                    for (j, &id) in c.iter().enumerate() {
                        for (x, y) in b.iter_mut().zip(verts[id as usize]) {
                            *x += w[j] * y;
                        }
                    }
                    let [u, v] = o.patch_param(s);
                    let p = plan.evaluate(&verts, o.patch as usize, u, v).position;
                    let e = dist(p, b) / d;
                    if half {
                        worst_half = worst_half.max(e);
                    } else {
                        worst = worst.max(e);
                    }
                }
            }
            for (k, &[pi, _]) in plan.corner_owners.iter().enumerate() {
                let [u, v] = plan.corner_owner_param(k);
                let p = plan.evaluate(&verts, pi as usize, u, v).position;
                let corner = verts[plan.first_corner as usize + k];
                worst = worst.max(dist(p, corner) / d);
            }
            assert!(
                worst < 1e-9,
                "{name} {method}: owner off its curve or corner by {worst:e}"
            );
            assert!(
                worst_half < 1e-9,
                "{name} {method}: end cap off its half curve by {worst_half:e}"
            );
        }
    }
}

/// Inside a base face, neighbouring patches show the same texture coordinate on their shared
/// edges (only `vt` seams are seams), with the reparameterization on too: it keeps each edge
/// to the blocks of its two ends.
#[test]
fn texture_coordinates_are_continuous_inside_faces() {
    let mesh = load_obj(data("assets/spot_control_mesh.obj")).unwrap();
    assert!(has_texcoords(&mesh));
    for (method, plan) in plans(&mesh) {
        // Key: (base face, sub-face, base parameter on a lattice of 1/64) -> coordinate.
        let mut seen = std::collections::HashMap::new();
        let mut worst = 0.0f64;
        for (pi, p) in plan.patches.iter().enumerate() {
            for reparam in [false, true] {
                for k in 0..=8 {
                    let t = k as f64 / 8.0;
                    for (u, v) in [(t, 0.0), (1.0, t), (t, 1.0), (0.0, t)] {
                        let uv = patch_texcoord(&mesh, &plan, pi, u, v, reparam).unwrap();
                        let bu = p.origin[0] + p.size * u;
                        let bv = p.origin[1] + p.size * v;
                        let key = (
                            p.base_face,
                            p.sub_face,
                            (bu * 4096.0).round() as i64,
                            (bv * 4096.0).round() as i64,
                            reparam,
                        );
                        if let Some(prev) = seen.insert(key, uv) {
                            let prev: [f64; 2] = prev;
                            worst = worst.max((prev[0] - uv[0]).abs().max((prev[1] - uv[1]).abs()));
                        }
                    }
                }
            }
        }
        // Transition edges meet a coarse patch whose reparameterized edge differs from the
        // two fine halves'; without transitions (single pass) the match is exact.
        let bound = if method.starts_with("adaptive") {
            1e-2
        } else {
            1e-12
        };
        assert!(
            worst < bound,
            "{method}: texture coordinates jump by {worst:e}"
        );
    }
}

/// Eq. 1 on real meshes: the texel a Gregory patch shows at `(u, v)` is the exact limit's at
/// the base parameter of `s(u, v)`; its distance from the Gregory point, RMS over a 17² lattice
/// of every Gregory patch with a reparameterized corner, relative to the bbox diagonal. Prints
/// the table of docs/approximations.md.
#[test]
fn reparameterization_lowers_the_texture_error_on_meshes() {
    println!("| shape | reparameterized Gregory patches | RMS identity | RMS reparameterized | ratio | max identity | max reparameterized |");
    for (name, mesh) in shapes() {
        let plan = plan_single_pass(&mesh, &SinglePassOptions::default()).unwrap();
        let exact = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).unwrap();
        let verts = plan.apply(&mesh.positions);
        let d = diag(&mesh);
        let (mut sq, mut max, mut n, mut patches) = ([0.0f64; 2], [0.0f64; 2], 0usize, 0usize);
        for (pi, p) in plan.patches.iter().enumerate() {
            if p.kind != PatchKind::Gregory || p.reparam_valences.iter().all(|&v| v == 0 || v == 4)
            {
                continue;
            }
            patches += 1;
            let quad = mesh.face(p.base_face as usize).len() == 4;
            for a in 0..17 {
                for b in 0..17 {
                    let (u, v) = (a as f64 / 16.0, b as f64 / 16.0);
                    let g = plan.evaluate(&verts, pi, u, v).position;
                    for (k, reparam) in [false, true].into_iter().enumerate() {
                        let [s, t] = patch_parameter(p, u, v, reparam);
                        let (bs, bt) = (p.origin[0] + p.size * s, p.origin[1] + p.size * t);
                        let e = if quad {
                            exact.evaluate(p.base_face as usize, bs, bt)
                        } else {
                            exact.evaluate_subface(
                                p.base_face as usize,
                                p.sub_face as usize,
                                bs,
                                bt,
                            )
                        }
                        .unwrap()
                        .position;
                        let err = dist(g, e) / d;
                        sq[k] += err * err;
                        max[k] = max[k].max(err);
                    }
                    n += 1;
                }
            }
        }
        if patches == 0 {
            println!("| {name} | 0 | | | | | |");
            continue;
        }
        let rms = sq.map(|s| (s / n as f64).sqrt());
        println!(
            "| {name} | {patches} | {:.2e} | {:.2e} | {:.2} | {:.2e} | {:.2e} |",
            rms[0],
            rms[1],
            rms[1] / rms[0],
            max[0],
            max[1]
        );
        assert!(
            rms[1] < rms[0],
            "{name}: reparameterization raises the RMS texture error ({:e} -> {:e})",
            rms[0],
            rms[1]
        );
    }
}

/// The lattice behind `--show param-error` is Eq. 1's pointwise error: it matches a direct
/// evaluation, is exact (≈ 0) on regular patches of a mesh without semi-sharp tags, and its
/// reparameterized half is lower where the reparameterization applies. Per valence on spot:
/// each Gregory patch grouped by the largest reparameterized corner valence (printed for
/// docs/approximations.md; spot has valences 3, 5 and 6, and each must gain).
#[test]
fn param_error_lattice_is_eq1_pointwise() {
    use topology::patches::texcoord::param_error_lattice;
    let mesh = load_obj(data("assets/spot_control_mesh.obj")).unwrap();
    let plan = plan_single_pass(&mesh, &SinglePassOptions::default()).unwrap();
    let lattice = param_error_lattice(&mesh, &plan, 9).unwrap();
    assert_eq!(lattice.errors.len(), plan.patches.len() * 2 * 81);
    // The summary: RMS and max over all points of each half, and the reparameterized count.
    let summary = lattice.summary();
    let half =
        |r: usize| (0..plan.patches.len()).flat_map(move |p| (0..81).map(move |k| (p, r, k)));
    for r in 0..2 {
        let (mut sq, mut max) = (0.0f64, 0.0f64);
        for (p, _, k) in half(r) {
            let e = lattice.at(p, r == 1, k % 9, k / 9) as f64;
            sq += e * e;
            max = max.max(e);
        }
        let rms = (sq / (81 * plan.patches.len()) as f64).sqrt();
        assert!((summary.rms[r] - rms).abs() <= 1e-12 * rms && summary.max[r] == max);
    }
    assert!(summary.rms[1] < summary.rms[0]);
    let reparameterized = plan
        .patches
        .iter()
        .filter(|p| p.reparam_valences.iter().any(|&v| v != 0 && v != 4))
        .count();
    assert_eq!(lattice.reparameterized, reparameterized);
    let exact = LocalMesh::from_control_mesh(&mesh, LimitScheme::CatmullClark).unwrap();
    let verts = plan.apply(&mesh.positions);
    let d = diag(&mesh);
    // Direct evaluation at a few lattice points of every 7th patch.
    for (pi, p) in plan.patches.iter().enumerate().step_by(7) {
        for (i, j) in [(0, 0), (3, 5), (8, 2), (4, 4)] {
            let (u, v) = (i as f64 / 8.0, j as f64 / 8.0);
            for reparam in [false, true] {
                let [s, t] = patch_parameter(p, u, v, reparam);
                let (bs, bt) = (p.origin[0] + p.size * s, p.origin[1] + p.size * t);
                let face = p.base_face as usize;
                let e = if mesh.face(face).len() == 4 {
                    exact.evaluate(face, bs, bt)
                } else {
                    exact.evaluate_subface(face, p.sub_face as usize, bs, bt)
                }
                .unwrap()
                .position;
                let want = dist(plan.evaluate(&verts, pi, u, v).position, e) / d;
                let got = lattice.at(pi, reparam, i, j) as f64;
                assert!(
                    (got - want).abs() <= 1e-6 * want.max(1e-3),
                    "patch {pi} ({i}, {j}) reparam {reparam}: {got:e} != {want:e}"
                );
            }
        }
    }
    let (mut regular_max, mut sq, mut n) = (0.0f32, [0.0f64; 2], 0usize);
    // Per valence: [sum sq identity, sum sq reparam, max identity, max reparam, points, patches].
    let mut per_valence = std::collections::BTreeMap::<u8, [f64; 6]>::new();
    for (pi, p) in plan.patches.iter().enumerate() {
        if p.kind == PatchKind::Regular {
            regular_max = lattice
                .patch(pi, false)
                .iter()
                .fold(regular_max, |m, &e| m.max(e));
            continue;
        }
        let valence = *p
            .reparam_valences
            .iter()
            .filter(|&&v| v != 4)
            .max()
            .unwrap_or(&0);
        if valence == 0 {
            continue;
        }
        let row = per_valence.entry(valence).or_default();
        row[5] += 1.0;
        for (k, reparam) in [false, true].into_iter().enumerate() {
            for &e in lattice.patch(pi, reparam) {
                let e = e as f64;
                sq[k] += e * e;
                row[k] += e * e;
                row[2 + k] = row[2 + k].max(e);
            }
        }
        n += 81;
        row[4] += 81.0;
    }
    assert!(
        regular_max < 1e-6,
        "regular patches deviate by {regular_max:e}"
    );
    assert!(n > 0 && sq[1] < sq[0], "no gain over the mesh: {sq:?}");
    println!("| valence | patches | RMS identity | RMS reparameterized | ratio | max identity | max reparameterized |");
    for (v, r) in per_valence {
        let (a, b) = ((r[0] / r[4]).sqrt(), (r[1] / r[4]).sqrt());
        println!(
            "| {v} | {} | {a:.2e} | {b:.2e} | {:.2} | {:.2e} | {:.2e} |",
            r[5],
            b / a,
            r[2],
            r[3]
        );
        assert!(
            b < a,
            "valence {v}: reparameterization raises the RMS error"
        );
    }
}

/// A disk around one interior vertex of valence `n`: its `n` quads, a ring of `2n` quads
/// around them (so every other vertex of the first ring is regular and interior), gently
/// curved, with `vt` the planar projection scaled into [0, 1]² (no seams).
fn high_valence_disk(n: usize) -> ControlMesh {
    let tau = std::f64::consts::TAU;
    let at = |r: f64, a: f64| {
        let (x, y) = (r * a.cos(), r * a.sin());
        [x, y, 0.15 * r * r + 0.05 * r * (3.0 * a).cos()]
    };
    let mut pos = vec![[0.0, 0.0, 0.0]];
    // First ring: edge neighbours a_i (index 1 + 2i) and diagonal vertices b_i (2 + 2i).
    for k in 0..2 * n {
        let a = tau * k as f64 / (2 * n) as f64;
        pos.push(at(if k % 2 == 0 { 1.0 } else { 1.3 }, a));
    }
    // Outer ring, one vertex per first-ring vertex.
    for k in 0..2 * n {
        pos.push(at(2.2, tau * k as f64 / (2 * n) as f64));
    }
    let ring = |k: usize| 1 + (k % (2 * n)) as u32;
    let outer = |k: usize| 1 + 2 * n as u32 + (k % (2 * n)) as u32;
    let mut faces = Vec::new();
    for i in 0..n {
        faces.push(vec![0, ring(2 * i), ring(2 * i + 1), ring(2 * i + 2)]);
    }
    for k in 0..2 * n {
        faces.push(vec![ring(k), outer(k), outer(k + 1), ring(k + 1)]);
    }
    let mut mesh = ControlMesh::from_polygons(pos, &faces);
    let uv: Vec<[f64; 2]> = mesh
        .positions
        .iter()
        .map(|p| [0.5 + p[0] / 4.8, 0.5 + p[1] / 4.8])
        .collect();
    mesh.uvs = Some(mesh.face_vertices.iter().map(|&v| uv[v as usize]).collect());
    mesh
}

/// The documented fallback above the table: a Gregory corner of valence 20 (beyond the
/// fitted 3–16) is reparameterized with the valence-16 row (the GPU's row 14), not refused and
/// not the identity. Its texture coordinates with the reparameterization on are finite and stay
/// inside the face's `vt` range (the rational map keeps the unit square), they differ from the
/// identity's, and Eq. 1's texture error on those patches falls, as the characteristic map of
/// valence 20 says it should (docs/approximations.md: RMS 0.10× there).
#[test]
fn corners_above_the_table_reuse_its_last_row() {
    use topology::patches::reparam::{corner_block, TABLE_VALENCES};
    use topology::patches::texcoord::{
        param_error_lattice, reparam_block, reparam_row, subface_corners,
    };
    let n = 20;
    assert!(!TABLE_VALENCES.contains(&(n as u32)) && corner_block(n as u32).is_none());
    assert_eq!(reparam_block(n as u8), corner_block(16));
    assert_eq!(reparam_row(n as u8), reparam_row(16));
    assert_eq!(reparam_row(16), 14);

    let mesh = high_valence_disk(n);
    assert!(has_texcoords(&mesh));
    let plan = plan_single_pass(&mesh, &SinglePassOptions::default()).unwrap();
    let around: Vec<usize> = (0..plan.patches.len())
        .filter(|&i| plan.patches[i].reparam_valences.contains(&(n as u8)))
        .collect();
    assert_eq!(around.len(), n, "one Gregory patch per face at the vertex");
    let mut moved = 0.0f64;
    for &i in &around {
        let p = &plan.patches[i];
        assert_eq!(p.kind, PatchKind::Gregory);
        let c = subface_corners(&mesh, p.base_face as usize, 0).unwrap();
        let lo = [0, 1].map(|k| c.iter().map(|q| q[k]).fold(f64::INFINITY, f64::min));
        let hi = [0, 1].map(|k| c.iter().map(|q| q[k]).fold(f64::NEG_INFINITY, f64::max));
        for a in 0..=16 {
            for b in 0..=16 {
                let (u, v) = (a as f64 / 16.0, b as f64 / 16.0);
                let on = patch_texcoord(&mesh, &plan, i, u, v, true).unwrap();
                let off = patch_texcoord(&mesh, &plan, i, u, v, false).unwrap();
                for k in 0..2 {
                    assert!(on[k].is_finite(), "patch {i} ({u}, {v}): {on:?}");
                    assert!(
                        on[k] >= lo[k] - 1e-12 && on[k] <= hi[k] + 1e-12,
                        "patch {i} ({u}, {v}): {on:?} outside {lo:?}..{hi:?}"
                    );
                    moved = moved.max((on[k] - off[k]).abs());
                }
            }
        }
    }
    // The map moves the texture parameter (the identity would give 0).
    assert!(moved > 1e-3, "largest shift {moved:e}");

    let lattice = param_error_lattice(&mesh, &plan, 9).unwrap();
    let rms = |reparam: bool| {
        let e: Vec<f64> = around
            .iter()
            .flat_map(|&i| lattice.patch(i, reparam).iter().map(|&x| x as f64))
            .collect();
        (e.iter().map(|x| x * x).sum::<f64>() / e.len() as f64).sqrt()
    };
    let (identity, reparameterized) = (rms(false), rms(true));
    println!(
        "valence {n}: Eq. 1 RMS {identity:.2e} identity, {reparameterized:.2e} with the \
         valence-16 row ({:.2}x)",
        reparameterized / identity
    );
    assert!(
        reparameterized.is_finite() && reparameterized < identity,
        "{identity:e} -> {reparameterized:e}"
    );
}
