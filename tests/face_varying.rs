//! Smooth (face-varying) texture coordinates on the GPU: the adaptive surface's texture
//! coordinates under OpenSubdiv's face-varying interpolation modes, checked through
//! `tessera export`'s writer (`vt` per triangle corner) against the exact Catmull-Clark limit
//! of the coordinates taken as positions, and through displacement (the TES's own texture
//! coordinate moves each point by the procedural height there) against the host's evaluation.
mod common;

use common::Gpu;
use tessera::tess::capture::{CapturedSoup, Capturer, FacePoint, Winding};
use tessera::tess::surface::SurfaceMaps;
use tessera::tess::techniques::adaptive;
use tessera::tess::techniques::planned_patches::{self, PlanBuild, PlannedPatches};
use tessera::tess::{Context, FrameParams, Technique};
use tessera::topology::limit::eval::LimitScheme;
use tessera::topology::limit::face_domain::LimitEvaluator;
use tessera::topology::patches::adaptive::single_pass::SinglePassPatch;
use tessera::topology::rules::options::FVarLinearInterpolation as Mode;
use tessera::topology::ControlMesh;
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 64,
    height: 64,
};

/// A flat `n` × `n` grid of quads over the unit square with a continuous, curved layout (one
/// value per vertex: its `vt` numbers are its vertex numbers).
fn curved_grid(n: usize, mode: Mode) -> ControlMesh {
    let mut positions = Vec::new();
    for j in 0..=n {
        for i in 0..=n {
            positions.push([i as f64 / n as f64, j as f64 / n as f64, 0.0]);
        }
    }
    let at = |i: usize, j: usize| (i + (n + 1) * j) as u32;
    let faces: Vec<[u32; 4]> = (0..n)
        .flat_map(|j| (0..n).map(move |i| (i, j)))
        .map(|(i, j)| [at(i, j), at(i + 1, j), at(i + 1, j + 1), at(i, j + 1)])
        .collect();
    let mut mesh = ControlMesh::from_polygons(positions, &faces);
    common::with_curved_layout(&mut mesh);
    mesh.options.fvar_interpolation = mode;
    mesh
}

fn surface(ctx: &mut Context, mesh: &ControlMesh, name: &str) -> PlannedPatches {
    adaptive::new(
        ctx,
        mesh,
        &PlanBuild {
            name: name.into(),
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// An exported OBJ read back: per vertex its `# p` point, the `vt` lines, and per triangle
/// corner (vertex, `vt`), 0-based.
struct Exported {
    points: Vec<FacePoint>,
    texcoords: Vec<[f64; 2]>,
    corners: Vec<(usize, usize)>,
}

fn read_export(text: &str) -> Exported {
    let mut out = Exported {
        points: Vec::new(),
        texcoords: Vec::new(),
        corners: Vec::new(),
    };
    let num = |s: &str| s.parse::<f64>().expect("number");
    for line in text.lines() {
        let w: Vec<&str> = line.split_whitespace().collect();
        match w.as_slice() {
            ["#", "p", f, u, v] => out.points.push(FacePoint {
                face: f.parse().expect("face"),
                u: u.parse().expect("u"),
                v: v.parse().expect("v"),
            }),
            ["vt", s, t] => out.texcoords.push([num(s), num(t)]),
            ["f", corners @ ..] => {
                for c in corners {
                    let k: Vec<usize> = c.split('/').map(|x| x.parse().expect("index")).collect();
                    out.corners.push((k[0] - 1, k[1] - 1));
                }
            }
            _ => {}
        }
    }
    out
}

/// Captures `surf` and writes the export (with `vt`) to a file, read back.
fn export(
    ctx: &mut Context,
    capturer: &Capturer,
    surf: &mut PlannedPatches,
    name: &str,
) -> (CapturedSoup, Exported) {
    let params = FrameParams::uniform(4.0);
    let (soup, _) = capturer
        .capture(ctx, surf, &params, EXTENT)
        .unwrap_or_else(|e| panic!("{name}: capture: {e}"));
    let welded = soup.weld().expect("weld");
    let texcoords = welded
        .corner_texcoords(|p, d| surf.texcoord(p, d, params.reparam))
        .expect("every corner has a texture coordinate");
    let map = |patch: u32, domain: [f32; 2]| surf.face_point(patch, domain);
    let path = std::env::temp_dir().join(format!(
        "tessera-face-varying-{}-{name}.obj",
        std::process::id()
    ));
    welded
        .write_obj(&path, &map, Some(&texcoords), Winding::Reversed)
        .expect("write");
    let text = std::fs::read_to_string(&path).expect("read back");
    let _ = std::fs::remove_file(&path);
    (soup, read_export(&text))
}

/// Worst distance, over the layout's range, between each exported corner's `vt` and the exact
/// limit of the coordinates as positions at its vertex's `# p` point.
fn worst_against_limit(mesh: &ControlMesh, e: &Exported) -> f64 {
    let uv_mesh = common::uvs_as_positions(mesh);
    let exact = LimitEvaluator::new(&uv_mesh, LimitScheme::CatmullClark).expect("evaluator");
    let (lo, hi) = uv_mesh.bounding_box();
    let range = (hi[0] - lo[0]).max(hi[1] - lo[1]);
    let mut worst = 0.0f64;
    for &(v, t) in &e.corners {
        let p = e.points[v];
        let s = exact
            .evaluate(p.face, f64::from(p.u), f64::from(p.v))
            .expect("limit");
        let vt = e.texcoords[t];
        worst = worst.max((vt[0] - s.position[0]).hypot(vt[1] - s.position[1]) / range);
    }
    worst
}

/// Mode `none` with the layout's topology the mesh's: every exported `vt` is the exact
/// Catmull-Clark limit of the texture coordinates taken as positions (a regular grid: exact
/// patches everywhere); `all` gives today's bilinear coordinates instead, which differ.
#[test]
fn none_is_the_exact_limit_of_the_coordinates_and_all_is_bilinear() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let smooth = curved_grid(6, Mode::None);
        let mut surf = surface(&mut ctx, &smooth, "grid none");
        assert!(surf.fvar.is_some(), "mode none makes face-varying patches");
        let (_, e) = export(&mut ctx, &capturer, &mut surf, "none");
        assert_eq!(e.corners.len() % 3, 0);
        let worst = worst_against_limit(&smooth, &e);
        println!("grid, none: vt within {worst:.2e} of the layout's range from the exact limit");
        assert!(worst <= 1e-5, "none: {worst:e}");

        let linear = curved_grid(6, Mode::All);
        let mut surf = surface(&mut ctx, &linear, "grid all");
        assert!(surf.fvar.is_none(), "all is bilinear");
        let (_, e) = export(&mut ctx, &capturer, &mut surf, "all");
        let mut worst_bilinear = 0.0f64;
        for &(v, t) in &e.corners {
            let p = e.points[v];
            let want = tessera::topology::patches::texcoord::face_texcoord(
                &linear,
                p.face as usize,
                0,
                f64::from(p.u),
                f64::from(p.v),
            )
            .expect("bilinear");
            let vt = e.texcoords[t];
            worst_bilinear = worst_bilinear.max((vt[0] - want[0]).hypot(vt[1] - want[1]));
        }
        println!("grid, all: vt within {worst_bilinear:.2e} of the face's bilinear blend");
        assert!(worst_bilinear <= 1e-6, "all: {worst_bilinear:e}");
        let off = worst_against_limit(&linear, &e);
        println!("grid, all: {off:.2e} of the range from the smooth limit");
        assert!(
            off > 1e-3,
            "the curved layout's bilinear blend is not its limit"
        );

        // The cube's extraordinary corners: Gregory leaves of the layout there.
        let mut cube = tessera::topology::load_obj(common::data(
            "tests/data/opensubdiv/shapes/catmark_cube.obj",
        ))
        .expect("cube");
        common::with_curved_layout(&mut cube);
        cube.options.fvar_interpolation = Mode::None;
        let mut surf = surface(&mut ctx, &cube, "cube none");
        let (_, e) = export(&mut ctx, &capturer, &mut surf, "cube");
        let worst = worst_against_limit(&cube, &e);
        println!("cube, none: vt within {worst:.2e} of the layout's range from the exact limit");
        assert!(worst <= 5e-3, "cube none: {worst:e}");
    }
}

/// The layout's seams stay seams: under every smooth mode the welded vertices whose corners
/// carry different `vt` are those of mode `all` (the layout's discontinuities), no more, no
/// fewer.
#[test]
fn seams_stay_seams_in_every_mode() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let base = tessera::topology::load_obj(common::data(
            "tests/data/opensubdiv/shapes/catmark_fvar_bound1.obj",
        ))
        .expect("shape");
        let mut seam_vertices = |mode: Mode| {
            let mut mesh = base.clone();
            mesh.options.fvar_interpolation = mode;
            let mut surf = surface(&mut ctx, &mesh, mode.name());
            let (_, e) = export(&mut ctx, &capturer, &mut surf, &format!("seams-{mode}"));
            let mut first: Vec<Option<[f64; 2]>> = vec![None; e.points.len()];
            let mut seam = vec![false; e.points.len()];
            for &(v, t) in &e.corners {
                let vt = e.texcoords[t];
                match first[v] {
                    None => first[v] = Some(vt),
                    Some(f) if (f[0] - vt[0]).hypot(f[1] - vt[1]) > 1e-4 => seam[v] = true,
                    Some(_) => {}
                }
            }
            seam
        };
        let linear = seam_vertices(Mode::All);
        let count = linear.iter().filter(|&&s| s).count();
        assert!(count > 0, "catmark_fvar_bound1 has seams");
        for mode in Mode::ALL_MODES.into_iter().filter(|&m| m != Mode::All) {
            let smooth = seam_vertices(mode);
            assert_eq!(smooth.len(), linear.len(), "{mode}: the same surface");
            let differ = (0..linear.len())
                .filter(|&v| smooth[v] != linear[v])
                .count();
            println!("{mode}: {count} seam vertices under all, {differ} differ");
            assert_eq!(differ, 0, "{mode}: seams moved");
        }
    }
}

/// Displacement reads the TES's own texture coordinate (glsl/adaptive/fvar.glsl): on a flat
/// grid every captured point rises by the procedural height at it, which the host's
/// evaluation of the same patches (`PlannedPatches::texcoord_at`) predicts; for adaptive, for
/// the single-pass gregory and acc, and for gregory on the grid's triangles (Gregory-triangle
/// leaves of the layout).
#[test]
fn the_shaders_texture_coordinates_are_the_hosts() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).expect("context");
        let capturer = Capturer::new(&ctx).expect("capturer");
        let height = |t: [f64; 2]| {
            let w = std::f64::consts::TAU * 8.0;
            0.5 + 0.25 * ((w * t[0]).sin() + (w * t[1]).sin())
        };
        let kinds = ["adaptive", "gregory", "acc", "gregory triangles"];
        for (mode, kind) in [Mode::None, Mode::CornersPlus1, Mode::All]
            .into_iter()
            .flat_map(|m| kinds.map(|k| (m, k)))
        {
            let mut mesh = curved_grid(6, mode);
            if kind == "gregory triangles" {
                mesh = mesh.triangulated().0;
            }
            let mut surf = match kind {
                "adaptive" => surface(&mut ctx, &mesh, mode.name()),
                _ => planned_patches::single_pass(
                    &mut ctx,
                    &mesh,
                    &planned_patches::SinglePassBuild {
                        patch: if kind == "acc" {
                            SinglePassPatch::Acc1
                        } else {
                            SinglePassPatch::Gregory
                        },
                        sharpness_scale: 1.0,
                        gregory_triangles: true,
                        name: mode.name(),
                        maps: &SurfaceMaps::default(),
                        path: tessera::tess::DrawPath::Tessellation,
                    },
                )
                .expect("single-pass surface"),
            };
            assert_eq!(surf.fvar.is_some(), mode != Mode::All, "{kind} {mode}");
            if let (Some(f), "gregory triangles") = (&surf.fvar, kind) {
                assert!(f.patches.iter().all(|p| p.is_triangle()), "triangle leaves");
            }
            let params = FrameParams {
                displace: 1.0,
                ..FrameParams::uniform(4.0)
            };
            let (soup, _) = capturer
                .capture(&mut ctx, &mut surf, &params, EXTENT)
                .expect("capture");
            let mut worst = 0.0f64;
            for r in &soup.records {
                let t = surf
                    .texcoord_at(
                        r.patch,
                        r.domain[0].into(),
                        r.domain[1].into(),
                        params.reparam,
                    )
                    .expect("texture coordinate");
                let want = height(t);
                worst = worst.max((f64::from(r.position[2]).abs() - want).abs());
            }
            println!("{kind} {mode}: displaced heights within {worst:.2e} of the host's");
            assert!(worst < 1e-3, "{kind} {mode}: {worst:e}");
        }
    }
}
