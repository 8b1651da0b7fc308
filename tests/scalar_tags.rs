//! Scalar-tagged PN meshes (ST-meshes, appendix B of the refinement-pattern paper) on both draw
//! paths:
//! - a triangle without a tagged corner is PN's to the bit, and a mesh whose tags are all zero
//!   is PN everywhere;
//! - a tagged mesh (`tests/data/meshes/st_ridge.obj`, a dome with a sharp ridge) is welded by
//!   bits across its crease edges, every captured vertex equals an f64 evaluation of the cubic
//!   with the tags' edge control points at its own domain point, and the ridge is sharp: the
//!   two sides' surface normals at the crease differ.
mod common;

use common::Gpu;
use std::collections::HashMap;
use tessera::tess::capture::classify_open_edges;
use tessera::tess::techniques::pn::scalar_tags::tag_mesh;
use tessera::tess::{
    BuildOptions, CapturedSoup, Capturer, Context, FrameParams, PipelineChoice, RenderMesh,
    Spacing, Technique, TechniqueId,
};
use tessera::topology::mesh::scalar_tags::ScalarTag;
use tessera::topology::{load_obj, ControlMesh};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 64,
    height: 64,
};

const PATHS: [PipelineChoice; 2] = [PipelineChoice::Tessellation, PipelineChoice::Pattern];

fn spot() -> ControlMesh {
    load_obj(common::data("assets/spot_control_mesh.obj")).unwrap()
}

fn ridge() -> ControlMesh {
    load_obj(common::data("tests/data/meshes/st_ridge.obj")).unwrap()
}

fn build(ctx: &mut Context, mesh: &ControlMesh, pipeline: PipelineChoice) -> Box<dyn Technique> {
    let options = BuildOptions {
        name: "scalar tags test".into(),
        pipeline,
        ..BuildOptions::default()
    };
    tessera::tess::build(ctx, TechniqueId::PN, mesh, &options)
        .unwrap()
        .technique
}

fn capture(ctx: &mut Context, t: &mut dyn Technique, p: &FrameParams) -> CapturedSoup {
    let capturer = Capturer::new(ctx).unwrap();
    capturer.capture(ctx, t, p, EXTENT).expect("capture").0
}

fn params(level: f32, spacing: Spacing) -> FrameParams {
    FrameParams {
        spacing,
        ..FrameParams::uniform(level)
    }
}

/// Position and normal bits at each (patch, domain bits).
type Samples = HashMap<(u32, [u32; 2]), ([u32; 3], [u32; 3])>;

fn samples(soup: &CapturedSoup) -> Samples {
    soup.records
        .iter()
        .map(|r| {
            let key = (r.patch, r.domain.map(f32::to_bits));
            (
                key,
                (r.position.map(f32::to_bits), r.normal.map(f32::to_bits)),
            )
        })
        .collect()
}

fn tag(vertex: u32, deviation: [f32; 3], tension: f32) -> ScalarTag {
    ScalarTag {
        vertex,
        deviation,
        tension,
        sharpness: 0.8,
        bias: 0.25,
    }
}

/// The fan triangles (patches, in PN's order) with a corner among `vertices`.
fn patches_touching(mesh: &ControlMesh, vertices: &[u32]) -> Vec<bool> {
    let render = RenderMesh::from_control_mesh(mesh).unwrap();
    render
        .triangle_origins
        .iter()
        .map(|o| {
            let face = mesh.face(o.face as usize);
            o.face_corners()[..3]
                .iter()
                .any(|&c| vertices.contains(&face[c as usize]))
        })
        .collect()
}

#[test]
fn untagged_triangles_are_pn_to_the_bit_on_both_paths() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let plain = spot();
        let zeros = ControlMesh {
            scalar_tags: (0..plain.positions.len() as u32)
                .map(|v| ScalarTag {
                    sharpness: 0.0,
                    bias: 0.0,
                    ..tag(v, [0.0; 3], 0.0)
                })
                .collect(),
            ..plain.clone()
        };
        // A crease through vertices 10 and 11 if they share an edge, a tension at 40.
        let tagged_vertices = [10, 11, 40];
        let some = ControlMesh {
            scalar_tags: vec![
                tag(10, [0.0, 0.3, 0.0], 0.0),
                tag(11, [0.0, 0.3, 0.0], 0.0),
                tag(40, [0.0; 3], 0.5),
            ],
            ..plain.clone()
        };
        let touched = patches_touching(&plain, &tagged_vertices);
        let mut compared = 0;
        for path in PATHS {
            let mut pn = build(&mut ctx, &plain, path);
            let mut zero = build(&mut ctx, &zeros, path);
            let mut partly = build(&mut ctx, &some, path);
            for (level, spacing) in [
                (1.0, Spacing::Equal),
                (5.0, Spacing::Equal),
                (16.0, Spacing::Equal),
            ] {
                let what = format!("{path:?} level {level}");
                let p = params(level, spacing);
                let want = samples(&capture(&mut ctx, pn.as_mut(), &p));
                let got = samples(&capture(&mut ctx, zero.as_mut(), &p));
                assert_eq!(got, want, "{what}: zero tags are not PN's bits");
                let got = samples(&capture(&mut ctx, partly.as_mut(), &p));
                assert_eq!(got.len(), want.len(), "{what}");
                let mut differing_touched = 0;
                for (key, value) in &got {
                    if touched[key.0 as usize] {
                        differing_touched += (want.get(key) != Some(value)) as usize;
                    } else {
                        assert_eq!(want.get(key), Some(value), "{what}: untagged patch {key:?}");
                        compared += 1;
                    }
                }
                assert!(differing_touched > 0, "{what}: the tags changed nothing");
            }
        }
        println!("{compared} samples of untagged patches bit-identical to PN's");
        assert!(compared > 10_000, "{compared}");
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// An f64 evaluation of a curved PN triangle from its corners and its six edge control points
/// (b210, b120, b021, b012, b102, b201), at barycentric `b`.
fn cubic(c: &[[f64; 3]; 3], e: &[[f64; 3]; 6], b: [f64; 3]) -> [f64; 3] {
    let [u, v, w] = b;
    let mut centre = [0.0; 3];
    for k in 0..3 {
        let es: f64 = e.iter().map(|p| p[k]).sum::<f64>() / 6.0;
        let vs: f64 = c.iter().map(|p| p[k]).sum::<f64>() / 3.0;
        centre[k] = es + 0.5 * (es - vs);
    }
    let points = [c[0], c[1], c[2], e[0], e[1], e[2], e[3], e[4], e[5], centre];
    let weights = [
        u * u * u,
        v * v * v,
        w * w * w,
        3.0 * u * u * v,
        3.0 * u * v * v,
        3.0 * v * v * w,
        3.0 * v * w * w,
        3.0 * w * w * u,
        3.0 * w * u * u,
        6.0 * u * v * w,
    ];
    let mut out = [0.0; 3];
    for (p, wt) in points.iter().zip(weights) {
        for k in 0..3 {
            out[k] += p[k] * wt;
        }
    }
    out
}

/// Each patch's corners and edge control points: the tags' where a corner is tagged, PN's
/// `(2 P_i + P_j − ((P_j − P_i)·N_i) N_i) / 3` elsewhere.
/// A patch's corners and its six edge control points.
type PatchPoints = ([[f64; 3]; 3], [[f64; 3]; 6]);

fn tagged_patches(mesh: &ControlMesh) -> Vec<PatchPoints> {
    let render = RenderMesh::from_control_mesh(mesh).unwrap();
    let tagged = tag_mesh(mesh, &render).unwrap();
    let v = |i: usize| tagged.render.vertices[i];
    let pn = |i: usize, j: usize| {
        let (p, n, q) = (v(i).position, v(i).normal, v(j).position);
        let s: f64 = (0..3).map(|k| (q[k] - p[k]) as f64 * n[k] as f64).sum();
        [0, 1, 2].map(|k| (2.0 * p[k] as f64 + q[k] as f64 - s * n[k] as f64) / 3.0)
    };
    (0..tagged.render.triangles.len())
        .map(|t| {
            let c = [0, 1, 2].map(|k| v(3 * t + k).position.map(f64::from));
            let mut e = [[0.0; 3]; 6];
            for k in 0..3 {
                let (i, next, prev) = (3 * t + k, 3 * t + (k + 1) % 3, 3 * t + (k + 2) % 3);
                let corner = tagged.corners[i];
                let (bn, bp) = if corner.b_next[3] != 0.0 {
                    let f = |b: [f32; 4]| [b[0], b[1], b[2]].map(f64::from);
                    (f(corner.b_next), f(corner.b_prev))
                } else {
                    (pn(i, next), pn(i, prev))
                };
                e[2 * k] = bn;
                e[2 * ((k + 2) % 3) + 1] = bp;
            }
            (c, e)
        })
        .collect()
}

/// The ridge is sharp where it is tagged and nowhere else: the points where captured normals
/// disagree by more than 20° (the two sides of the crease) all lie on the tagged row y = 0,
/// and there are some.
fn assert_sharp_along_the_ridge(soup: &CapturedSoup, what: &str) {
    let mut normals: HashMap<[u32; 3], Vec<[f32; 3]>> = HashMap::new();
    for r in &soup.records {
        normals
            .entry(r.position.map(f32::to_bits))
            .or_default()
            .push(r.normal);
    }
    let cos20 = 20f32.to_radians().cos();
    let mut sharp = 0;
    for (p, ns) in &normals {
        let unit = |n: [f32; 3]| {
            let l = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            n.map(|x| x / l)
        };
        let (a, b) = (unit(ns[0]), ns.iter().map(|&n| unit(n)));
        let split = b
            .map(|n| a[0] * n[0] + a[1] * n[1] + a[2] * n[2])
            .any(|c| c < cos20);
        if split {
            let y = f32::from_bits(p[1]);
            assert!(
                y.abs() < 1e-6,
                "{what}: a sharp point off the ridge at y = {y}"
            );
            sharp += 1;
        }
    }
    assert!(sharp > 8, "{what}: only {sharp} sharp points on the ridge");
}

#[test]
fn a_tagged_ridge_is_welded_by_bits_and_follows_its_cubics() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mesh = ridge();
        let diagonal = mesh.bbox_diagonal();
        let patches = tagged_patches(&mesh);
        for path in PATHS {
            let mut t = build(&mut ctx, &mesh, path);
            for (level, spacing) in [
                (3.0, Spacing::Equal),
                (16.0, Spacing::Equal),
                (7.5, Spacing::FractionalOdd),
            ] {
                if path == PipelineChoice::Pattern && spacing != Spacing::Equal {
                    continue;
                }
                let what = format!("{path:?} level {level} {spacing:?}");
                let soup = capture(&mut ctx, t.as_mut(), &params(level, spacing));
                let welded = soup.weld().unwrap();
                let report = welded.open_edges();
                let map = |p: u32, d: [f32; 2]| t.face_point(p, d);
                let c = classify_open_edges(&soup, &welded, &report, &map, &mesh);
                assert_eq!((c.cracks, c.unmapped), (0, 0), "{what}");
                assert!(c.on_base_boundary > 0, "{what}: the dome's rim is open");
                assert_sharp_along_the_ridge(&soup, &what);
                let mut worst = 0.0f64;
                for r in &soup.records {
                    let (corners, edges) = &patches[r.patch as usize];
                    let [u, v] = r.domain.map(f64::from);
                    let want = cubic(corners, edges, [u, v, 1.0 - u - v]);
                    let d = (0..3)
                        .map(|k| (r.position[k] as f64 - want[k]).powi(2))
                        .sum::<f64>()
                        .sqrt();
                    worst = worst.max(d);
                }
                println!("{what}: position error {worst:.2e}");
                assert!(worst <= 2e-6 * diagonal, "{what}: off by {worst}");
            }
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

#[test]
fn without_tessellation_shaders_the_ridge_draws_through_patterns() {
    use tessera::tess::DrawPath;
    let gpu = Gpu::with(&tessera::vk_core::DeviceDesc {
        without_tessellation_shader: true,
        ..Default::default()
    });
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mesh = ridge();
        let mut t = build(&mut ctx, &mesh, PipelineChoice::Auto);
        assert!(t
            .patch_arrays()
            .iter()
            .all(|a| a.patch.path() == DrawPath::Pattern));
        for level in [2.0, 9.0, 100.0] {
            let soup = capture(&mut ctx, t.as_mut(), &params(level, Spacing::Equal));
            let welded = soup.weld().unwrap();
            let report = welded.open_edges();
            let map = |p: u32, d: [f32; 2]| t.face_point(p, d);
            let c = classify_open_edges(&soup, &welded, &report, &map, &mesh);
            assert_eq!((c.cracks, c.unmapped), (0, 0), "level {level}");
            assert_sharp_along_the_ridge(&soup, &format!("generated level {level}"));
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}
