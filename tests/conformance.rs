//! The conformance suite: every technique of the registry, on every draw path it declares, is
//! held to what the seam promises — a technique is tested by being registered. For each, on
//! spot's control mesh (triangles, quads, pentagons) and a cube:
//! - it builds, and its arrays use the geometry of the declared path with stages from its own
//!   shader folder or `glsl/common/`;
//! - a frame renders validation-clean and draws something;
//! - a capture of what the GPU emitted welds by position bits with 0 cracks and 0 unmapped
//!   vertices on these closed meshes, under uniform factors and (on the cube) under every
//!   factor policy and spacing it declares;
//! - if it declares animation, a moved base captures with 0 cracks too, and the surface moved;
//! - each option it declares it does not take is refused by name, and animation is refused
//!   where it is not declared.
mod common;

use common::Gpu;
use tessera::tess::animation::Wave;
use tessera::tess::capture::classify_open_edges;
use tessera::tess::techniques::{self, TechniqueInfo};
use tessera::tess::{
    BuildOptions, Capturer, Context, DrawPath, FactorPolicy, FrameParams, PipelineChoice, Spacing,
    Technique, TessError,
};
use tessera::topology::{load_obj, ControlMesh};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 96,
    height: 96,
};

/// Every technique takes four uniform segments (BFT and the CPU meshes: a power of two;
/// adaptive: whole segments).
const SEGMENTS: f32 = 4.0;

fn meshes() -> Vec<(&'static str, ControlMesh)> {
    vec![
        (
            "spot",
            load_obj(common::data("assets/spot_control_mesh.obj")).unwrap(),
        ),
        (
            "cube",
            load_obj(common::data("tests/data/meshes/cube.obj")).unwrap(),
        ),
    ]
}

/// The `--pipeline` choice that builds `path`.
fn choice(path: DrawPath) -> PipelineChoice {
    match path {
        DrawPath::Tessellation => PipelineChoice::Tessellation,
        DrawPath::Pattern => PipelineChoice::Pattern,
        DrawPath::VertexStage => PipelineChoice::Auto,
    }
}

fn build(
    ctx: &mut Context,
    info: &TechniqueInfo,
    mesh: &ControlMesh,
    path: DrawPath,
) -> Box<dyn Technique> {
    techniques::build(
        ctx,
        info.id,
        mesh,
        &BuildOptions {
            name: "conformance".into(),
            tangents: info.features.geometric_normals,
            pipeline: choice(path),
            ..BuildOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("building {}: {e}", info.id))
    .technique
}

/// The arrays are on the path they were built for, their geometry is that path's, and every
/// stage comes from the technique's shader folder or the common one.
fn check_pipelines(info: &TechniqueInfo, technique: &dyn Technique, path: DrawPath, what: &str) {
    assert!(!technique.patch_arrays().is_empty(), "{what}: no arrays");
    for a in technique.patch_arrays() {
        let pp = technique.patch_pipeline(a.patch);
        assert_eq!(a.patch.path(), path, "{what}: {:?}", a.patch);
        assert!(
            path.draws(pp.geometry),
            "{what}: {:?} is not drawn as its path draws",
            a.patch
        );
        assert_eq!(a.control_points, pp.control_points(), "{what}");
        let mut stages = vec![pp.vertex, pp.fragment];
        if let tessera::tess::Geometry::Tessellated {
            control,
            evaluation,
            ..
        } = pp.geometry
        {
            stages.extend([control, evaluation]);
        }
        for s in stages {
            let path = s.path();
            assert!(
                path.starts_with(&format!("{}/", info.shader_folder))
                    || path.starts_with("common/"),
                "{what}: stage {path} is outside glsl/{}/ and glsl/common/",
                info.shader_folder
            );
        }
    }
}

/// Cracks, unmapped vertices and base-boundary edges of one capture; also its welded
/// positions.
fn capture(
    ctx: &mut Context,
    capturer: &Capturer,
    technique: &mut dyn Technique,
    mesh: &ControlMesh,
    params: &FrameParams,
) -> ((usize, usize, usize), Vec<[f32; 3]>) {
    let (soup, _) = capturer
        .capture(ctx, &mut *technique, params, EXTENT)
        .expect("capture");
    let welded = soup.weld().expect("weld");
    let report = welded.open_edges();
    let map = |p: u32, d: [f32; 2]| technique.face_point(p, d);
    let c = classify_open_edges(&soup, &welded, &report, &map, mesh);
    assert_eq!(
        c.on_base_boundary + c.on_non_manifold_edge + c.cracks,
        report.open.len()
    );
    ((c.cracks, c.unmapped, c.on_base_boundary), welded.positions)
}

/// Renders one frame and returns how many pixels differ from the clear colour.
fn drawn_pixels(ctx: &mut Context, technique: &mut dyn Technique, params: &FrameParams) -> usize {
    let image = ctx
        .render_offscreen(technique, params, EXTENT)
        .expect("render");
    let clear = params.clear_color.map(|c| (c * 255.0).round() as u8);
    image
        .pixels
        .chunks_exact(4)
        .filter(|p| p[..3] != clear[..3])
        .count()
}

#[test]
fn every_technique_draws_captures_and_welds_on_every_declared_path() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        let params = FrameParams::uniform(SEGMENTS);
        let mut policy_captures = 0;
        for info in techniques::registry() {
            assert!(!info.features.paths.is_empty(), "{}: no draw path", info.id);
            for (name, mesh) in meshes() {
                for &path in info.features.paths {
                    let what = format!("{} on {name}, {path} path", info.id);
                    let mut t = build(&mut ctx, info, &mesh, path);
                    assert_eq!(t.id(), info.id, "{what}");
                    check_pipelines(info, t.as_ref(), path, &what);
                    assert!(
                        drawn_pixels(&mut ctx, t.as_mut(), &params) > 100,
                        "{what}: nothing drawn"
                    );
                    let (classes, rest) = capture(&mut ctx, &capturer, t.as_mut(), &mesh, &params);
                    assert_eq!(classes, (0, 0, 0), "{what}: (cracks, unmapped, boundary)");
                    // On the cube: the tessellation path's capture is sized for the largest
                    // level a policy can reach, past the capture budget on spot's patches.
                    let policies = if name == "cube" {
                        policies(info, &mesh)
                    } else {
                        Vec::new()
                    };
                    for (policy, p) in policies {
                        let (classes, _) = capture(&mut ctx, &capturer, t.as_mut(), &mesh, &p);
                        assert_eq!(classes, (0, 0, 0), "{what}, {policy}");
                        policy_captures += 1;
                    }
                    if info.features.animation {
                        let base = t.base_mesh().expect("an animated technique's base").clone();
                        let moved = Wave::new(&base).at(0.37);
                        t.update_base(0, &moved).expect("animated base");
                        let (classes, positions) =
                            capture(&mut ctx, &capturer, t.as_mut(), &mesh, &params);
                        assert_eq!(classes, (0, 0, 0), "{what}, animated");
                        assert_ne!(positions, rest, "{what}: the animated surface moved");
                    }
                    println!("{what}: conforms");
                }
            }
        }
        println!("{policy_captures} captures under other factor policies and spacings");
        assert!(policy_captures >= 30, "{policy_captures}");
    }
}

/// One frame per factor policy and spacing a technique declares beyond uniform factors in
/// equal spacing: screen-space and distance factors, and each other spacing at a level that is
/// not a power of two.
fn policies(info: &TechniqueInfo, mesh: &ControlMesh) -> Vec<(String, FrameParams)> {
    let f = info.features;
    let mut out = Vec::new();
    if f.adaptive_factors {
        let reference = 0.5 * mesh.bbox_diagonal() as f32;
        for factors in [
            FactorPolicy::Screen { pixels: 8.0 },
            FactorPolicy::Distance { reference },
        ] {
            out.push((
                format!("{factors}"),
                FrameParams {
                    factors,
                    ..FrameParams::uniform(SEGMENTS)
                },
            ));
        }
    }
    for spacing in [Spacing::FractionalEven, Spacing::FractionalOdd] {
        if f.spacing(spacing) {
            out.push((
                format!("{spacing:?} spacing"),
                FrameParams {
                    spacing,
                    ..FrameParams::uniform(6.0)
                },
            ));
        }
    }
    out
}

/// One frame per option a technique's features decline, each using that option alone.
fn declined(info: &TechniqueInfo) -> Vec<(&'static str, FrameParams)> {
    let f = info.features;
    let base = FrameParams::uniform(SEGMENTS);
    let mut out = Vec::new();
    if !f.adaptive_factors {
        out.push((
            "screen factors",
            FrameParams {
                factors: FactorPolicy::Screen { pixels: 8.0 },
                ..base
            },
        ));
    }
    for spacing in [
        Spacing::Equal,
        Spacing::FractionalEven,
        Spacing::FractionalOdd,
    ] {
        if !f.spacing(spacing) {
            out.push(("spacing", FrameParams { spacing, ..base }));
        }
    }
    if !f.patch_colours {
        out.push((
            "patch colours",
            FrameParams {
                patch_colours: true,
                ..base
            },
        ));
    }
    if !f.geometric_normals {
        out.push((
            "geometric normals",
            FrameParams {
                geometric_normals: true,
                ..base
            },
        ));
    }
    if !f.surface {
        out.push((
            "displacement",
            FrameParams {
                displace: 0.1,
                ..base
            },
        ));
        out.push((
            "no reparameterization",
            FrameParams {
                reparam: false,
                ..base
            },
        ));
    }
    if !f.sine_displacement {
        out.push((
            "sine displacement",
            FrameParams {
                displace_sine: [0.05, 20.0],
                ..base
            },
        ));
    }
    out
}

#[test]
fn every_technique_refuses_each_option_it_declares_it_does_not_take() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let (_, cube) = meshes().pop().unwrap();
        let mut refusals = 0;
        for info in techniques::registry() {
            for path in [DrawPath::Tessellation, DrawPath::Pattern] {
                if info.features.paths.contains(&path) {
                    continue;
                }
                let options = BuildOptions {
                    pipeline: choice(path),
                    ..BuildOptions::default()
                };
                match techniques::build(&mut ctx, info.id, &cube, &options) {
                    Err(e @ TessError::Unsupported { technique, .. }) => {
                        assert_eq!(technique, info.id, "{e}");
                        assert!(e.to_string().contains("--pipeline"), "{e}");
                    }
                    Err(e) => panic!("{}: --pipeline {path} refused as {e}", info.id),
                    Ok(_) => panic!("{}: --pipeline {path} was not refused", info.id),
                }
                refusals += 1;
            }
            let mut t = build(&mut ctx, info, &cube, info.features.paths[0]);
            for (option, params) in declined(info) {
                match ctx.prepare(t.as_mut(), &params, &[tessera::tess::Pass::Shaded]) {
                    Err(TessError::Unsupported { technique, .. }) => {
                        assert_eq!(technique, info.id, "{option}")
                    }
                    other => panic!("{}: {option} was not refused: {other:?}", info.id),
                }
                refusals += 1;
            }
            if !info.features.animation {
                let rest = vec![[0.0f32; 3]; cube.positions.len()];
                assert!(
                    matches!(t.update_base(0, &rest), Err(TessError::Unsupported { .. })),
                    "{}: animation was not refused",
                    info.id
                );
                refusals += 1;
            }
        }
        // Not vacuous: the base-face techniques alone decline more than a dozen options.
        assert!(refusals > 20, "{refusals} refusals checked");
    }
}

/// On a device without tessellation shaders (lavapipe's, made without the feature, so any
/// tessellation pipeline would be a validation error), `auto` draws every technique (each has a
/// refinement-pattern or a vertex-stage path) validation-clean, capturing with 0 cracks; asked
/// for the tessellation path, each that has one is refused by name.
#[test]
fn without_tessellation_shaders_every_technique_draws_or_is_refused_by_name() {
    let gpu = Gpu::with(&tessera::vk_core::DeviceDesc {
        without_tessellation_shader: true,
        ..Default::default()
    });
    let (mut drawn, mut refused) = (Vec::new(), Vec::new());
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        let params = FrameParams::uniform(SEGMENTS);
        let (_, mesh) = meshes().remove(0);
        for info in techniques::registry() {
            let options = |pipeline| BuildOptions {
                name: "no tessellation".into(),
                pipeline,
                ..BuildOptions::default()
            };
            let mut t = techniques::build(&mut ctx, info.id, &mesh, &options(PipelineChoice::Auto))
                .unwrap_or_else(|e| panic!("{}: {e}", info.id))
                .technique;
            assert!(
                t.patch_arrays()
                    .iter()
                    .all(|a| a.patch.path() != DrawPath::Tessellation),
                "{}",
                info.id
            );
            assert!(
                drawn_pixels(&mut ctx, t.as_mut(), &params) > 100,
                "{}",
                info.id
            );
            let (classes, _) = capture(&mut ctx, &capturer, t.as_mut(), &mesh, &params);
            assert_eq!(
                classes,
                (0, 0, 0),
                "{}: (cracks, unmapped, boundary)",
                info.id
            );
            drawn.push(info.id);
            if info.features.paths.contains(&DrawPath::Tessellation) {
                match techniques::build(
                    &mut ctx,
                    info.id,
                    &mesh,
                    &options(PipelineChoice::Tessellation),
                ) {
                    Err(e @ TessError::NoTessellationShader { .. }) => {
                        assert!(e.to_string().contains(info.id.name()), "{e}");
                        refused.push(info.id);
                    }
                    Err(e) => panic!("{}: refused as {e}", info.id),
                    Ok(_) => panic!(
                        "{} built on the tessellation path without tessellation shaders",
                        info.id
                    ),
                }
            }
        }
    }
    println!("drawn: {drawn:?}; tessellation path refused by name: {refused:?}");
    assert_eq!(drawn.len(), techniques::registry().len(), "{drawn:?}");
    assert!(refused.len() >= 7, "{refused:?}");
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}
