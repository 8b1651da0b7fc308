//! Refinement patterns: the base-face techniques (flat, Phong, PN) on the pattern path.
//! - With the device's tessellator, patterns are its own captured output, so both paths emit
//!   the same triangles with the same bits at every domain point, in every spacing.
//! - Without tessellation shaders (the device made without the feature, validation on: any
//!   tessellation pipeline would be an error), every such technique draws through generated
//!   patterns, watertight by bits, each vertex equal to an independent f64 evaluation of its
//!   patch at its own domain point; what has no pattern path is refused by name.
mod common;

use common::Gpu;
use std::collections::{BTreeSet, HashMap};
use tessera::tess::techniques::bft::{layout::GpuBft, DEFAULT_TABLE_LEVEL};
use tessera::tess::techniques::{flat::Flat, phong::Phong, pn::Pn};
use tessera::tess::{
    BuildOptions, CapturedSoup, Capturer, Context, DrawPath, FactorPolicy, FrameParams,
    PipelineChoice, RenderMesh, Spacing, Technique, TechniqueId, TessError,
};
use tessera::topology::limit::eval::{LimitScheme, LocalMesh};
use tessera::topology::patches::bft::prepare_loop_bft;
use tessera::topology::{load_obj, ControlMesh};
use tessera::vk_core::{vk, DeviceDesc};

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 64,
    height: 64,
};

/// The seed's procedural displacement a·sin(f·‖P‖) (§4), at a frequency that ripples the test
/// meshes several times.
const SINE: [f32; 2] = [0.02, 25.0];

const BASE_FACE_TECHNIQUES: [TechniqueId; 3] =
    [TechniqueId::FLAT, TechniqueId::PHONG, TechniqueId::PN];

fn spot() -> ControlMesh {
    load_obj(common::data("assets/spot_control_mesh.obj")).unwrap()
}

fn cube() -> ControlMesh {
    load_obj(common::data("tests/data/meshes/cube.obj")).unwrap()
}

fn build(
    ctx: &mut Context,
    id: TechniqueId,
    mesh: &ControlMesh,
    pipeline: PipelineChoice,
) -> tessera::tess::Result<Box<dyn Technique>> {
    let options = BuildOptions {
        name: "patterns test".into(),
        pipeline,
        ..BuildOptions::default()
    };
    Ok(tessera::tess::build(ctx, id, mesh, &options)?.technique)
}

fn params(level: f32, spacing: Spacing) -> FrameParams {
    FrameParams {
        spacing,
        ..FrameParams::uniform(level)
    }
}

fn capture(ctx: &mut Context, t: &mut dyn Technique, p: &FrameParams) -> CapturedSoup {
    let capturer = Capturer::new(ctx).unwrap();
    capturer.capture(ctx, t, p, EXTENT).expect("capture").0
}

/// Position and normal bits at each (patch, domain bits).
type Samples = HashMap<(u32, [u32; 2]), ([u32; 3], [u32; 3])>;

fn samples(soup: &CapturedSoup) -> Samples {
    let mut out = Samples::new();
    for r in &soup.records {
        let key = (r.patch, r.domain.map(f32::to_bits));
        let value = (r.position.map(f32::to_bits), r.normal.map(f32::to_bits));
        let old = out.insert(key, value);
        assert!(old.is_none() || old == Some(value), "{key:?}: two values");
    }
    out
}

/// Each triangle as its patch and corner domain bits, rotated to start at the least corner
/// (orientation kept).
fn triangles(soup: &CapturedSoup) -> BTreeSet<(u32, [[u32; 2]; 3])> {
    soup.triangles()
        .map(|t| {
            let c = [0, 1, 2].map(|i| t[i].domain.map(f32::to_bits));
            let first = (0..3).min_by_key(|&i| c[i]).unwrap();
            (t[0].patch, [0, 1, 2].map(|i| c[(first + i) % 3]))
        })
        .collect()
}

#[test]
fn with_the_devices_tessellator_both_paths_emit_the_same_triangles_and_bits() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let cases: [(&str, ControlMesh, &[f32]); 2] = [
            ("spot", spot(), &[1.0, 2.0, 3.0, 5.0, 7.5]),
            ("cube", cube(), &[13.0, 31.0, 64.0]),
        ];
        let mut compared = 0;
        for id in BASE_FACE_TECHNIQUES {
            for (name, mesh, levels) in &cases {
                let mut tess = build(&mut ctx, id, mesh, PipelineChoice::Tessellation).unwrap();
                let mut pattern = build(&mut ctx, id, mesh, PipelineChoice::Pattern).unwrap();
                assert!(pattern
                    .patch_arrays()
                    .iter()
                    .all(|a| a.patch.path() == DrawPath::Pattern));
                for &level in *levels {
                    for (spacing, sine) in [
                        (Spacing::Equal, [0.0, 0.0]),
                        (Spacing::FractionalEven, [0.0, 0.0]),
                        (Spacing::FractionalOdd, [0.0, 0.0]),
                        (Spacing::Equal, SINE),
                    ] {
                        let what =
                            format!("{id} on {name}, level {level}, {spacing:?}, sine {sine:?}");
                        let p = FrameParams {
                            displace_sine: sine,
                            ..params(level, spacing)
                        };
                        let a = capture(&mut ctx, tess.as_mut(), &p);
                        let b = capture(&mut ctx, pattern.as_mut(), &p);
                        assert!(a.triangle_count() > 0, "{what}");
                        assert_eq!(a.triangle_count(), b.triangle_count(), "{what}");
                        let (ta, tb) = (triangles(&a), triangles(&b));
                        if ta != tb {
                            let only_a: Vec<_> = ta.difference(&tb).take(4).collect();
                            let only_b: Vec<_> = tb.difference(&ta).take(4).collect();
                            panic!("{what}: triangles differ: tessellation path only {only_a:?}, pattern path only {only_b:?}");
                        }
                        let (sa, sb) = (samples(&a), samples(&b));
                        let differing = sa.iter().filter(|(k, v)| sb.get(k) != Some(v)).count();
                        assert_eq!(differing, 0, "{what}: of {} samples", sa.len());
                        assert_eq!(sa.len(), sb.len(), "{what}");
                        compared += sa.len();
                    }
                }
            }
        }
        println!("{compared} samples bit-identical on both paths");
        assert!(compared > 100_000, "{compared}");
    }
}

/// An f64 evaluation of each base-face technique at a domain point, written from the papers'
/// formulas independently of the shaders.
mod oracle {
    pub type V = [f64; 3];

    fn add(a: V, b: V) -> V {
        [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
    }
    fn sub(a: V, b: V) -> V {
        [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
    }
    fn mul(a: V, s: f64) -> V {
        a.map(|x| x * s)
    }
    fn dot(a: V, b: V) -> f64 {
        a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
    }
    /// The seed's procedural displacement: `p + a·sin(f·|p|)` along the unit normal.
    pub fn displaced(p: V, n: V, [a, f]: [f64; 2]) -> V {
        let h = a * (f * dot(p, p).sqrt()).sin();
        add(p, mul(normalize(n), h))
    }

    pub fn normalize(a: V) -> V {
        let l = dot(a, a).sqrt();
        if l > 0.0 {
            mul(a, 1.0 / l)
        } else {
            a
        }
    }
    fn weighted(points: &[V], w: &[f64]) -> V {
        points
            .iter()
            .zip(w)
            .fold([0.0; 3], |s, (p, &w)| add(s, mul(*p, w)))
    }

    /// Flat: the bilinear quad point (corners at (0,0), (1,0), (1,1), (0,1)) or the
    /// barycentric triangle point; the normal likewise (unnormalised, as drawn).
    pub fn flat(p: &[V], n: &[V], b: [f64; 3]) -> (V, V) {
        let w: Vec<f64> = if p.len() == 4 {
            let (u, v) = (b[0], b[1]);
            vec![(1.0 - u) * (1.0 - v), u * (1.0 - v), u * v, (1.0 - u) * v]
        } else {
            b.to_vec()
        };
        (weighted(p, &w), weighted(n, &w))
    }

    /// Phong tessellation (Boubekeur & Alexa 2008) with shape factor `alpha`.
    pub fn phong(p: &[V], n: &[V], b: [f64; 3], alpha: f64) -> (V, V) {
        let q = weighted(p, &b);
        let projected: Vec<V> = (0..3)
            .map(|i| sub(q, mul(n[i], dot(sub(q, p[i]), n[i]))))
            .collect();
        let phong = weighted(&projected, &b);
        (add(mul(q, 1.0 - alpha), mul(phong, alpha)), weighted(n, &b))
    }

    /// Curved PN triangles with the corrected normal field (Boubekeur & Schlick 2005,
    /// appendix A): cubic position, normalised quadratic normal.
    pub fn pn(p: &[V], n: &[V], b: [f64; 3]) -> (V, V) {
        let edge = |i: usize, j: usize| {
            let s = dot(sub(p[j], p[i]), n[i]);
            mul(sub(add(mul(p[i], 2.0), p[j]), mul(n[i], s)), 1.0 / 3.0)
        };
        let normal = |i: usize, j: usize| {
            let d = sub(p[j], p[i]);
            let s = add(n[i], n[j]);
            let t = 4.0 * dot(d, s) / dot(d, d);
            sub(s, mul(d, t))
        };
        let (b210, b120, b021, b012, b102, b201) = (
            edge(0, 1),
            edge(1, 0),
            edge(1, 2),
            edge(2, 1),
            edge(2, 0),
            edge(0, 2),
        );
        let e = mul(
            [b210, b120, b021, b012, b102, b201]
                .iter()
                .fold([0.0; 3], |s, x| add(s, *x)),
            1.0 / 6.0,
        );
        let v = mul(add(add(p[0], p[1]), p[2]), 1.0 / 3.0);
        let b111 = add(e, mul(sub(e, v), 0.5));
        let [u, v, w] = b;
        let points = [p[0], p[1], p[2], b210, b120, b021, b012, b102, b201, b111];
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
        let normals = [n[0], n[1], n[2], normal(0, 1), normal(1, 2), normal(2, 0)];
        let nw = [u * u, v * v, w * w, u * v, v * w, w * u];
        (
            weighted(&points, &weights),
            normalize(weighted(&normals, &nw)),
        )
    }
}

/// The corners (positions, normals) of each patch in frame-wide patch order, as the base-face
/// techniques number them (flat: quads, then the other faces' fan triangles; Phong and PN:
/// every face's fan triangles).
fn patch_corners(mesh: &ControlMesh, quads: bool) -> Vec<(Vec<oracle::V>, Vec<oracle::V>)> {
    let rm = RenderMesh::from_control_mesh(mesh).unwrap();
    let corner = |i: u32| {
        let v = rm.vertices[i as usize];
        (v.position.map(f64::from), v.normal.map(f64::from))
    };
    let lists: Vec<Vec<u32>> = if quads {
        rm.quads
            .iter()
            .map(|q| q.to_vec())
            .chain(rm.quad_mode_triangles.iter().map(|t| t.to_vec()))
            .collect()
    } else {
        rm.triangles.iter().map(|t| t.to_vec()).collect()
    };
    lists
        .iter()
        .map(|l| l.iter().map(|&i| corner(i)).unzip())
        .collect()
}

/// The largest distance between a captured position (normal) and the oracle's, over `soup`,
/// drawn with the displacement `sine` (amplitude, frequency).
fn oracle_error(
    id: TechniqueId,
    mesh: &ControlMesh,
    soup: &CapturedSoup,
    sine: [f32; 2],
) -> (f64, f64) {
    let corners = patch_corners(mesh, id == TechniqueId::FLAT);
    let (mut dp, mut dn) = (0.0f64, 0.0f64);
    for r in &soup.records {
        let (p, n) = &corners[r.patch as usize];
        let [u, v] = r.domain.map(f64::from);
        let b = [u, v, 1.0 - u - v];
        let (want_p, want_n) = match id {
            TechniqueId::FLAT => oracle::flat(p, n, b),
            TechniqueId::PHONG => oracle::phong(p, n, b, FrameParams::default().phong_alpha as f64),
            _ => oracle::pn(p, n, b),
        };
        let want_p = oracle::displaced(want_p, want_n, sine.map(f64::from));
        let dist = |a: [f32; 3], b: oracle::V| {
            (0..3)
                .map(|i| (a[i] as f64 - b[i]).powi(2))
                .sum::<f64>()
                .sqrt()
        };
        dp = dp.max(dist(r.position, want_p));
        dn = dn.max(dist(r.normal, want_n));
    }
    (dp, dn)
}

#[test]
fn without_tessellation_shaders_the_base_face_techniques_draw_generated_patterns() {
    let gpu = Gpu::with(&DeviceDesc {
        without_tessellation_shader: true,
        ..DeviceDesc::default()
    });
    {
        assert!(!gpu.device().info.caps.tessellation_shader);
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        for (name, mesh) in [("spot", spot()), ("cube", cube())] {
            let diagonal = mesh.bbox_diagonal();
            for id in BASE_FACE_TECHNIQUES {
                let mut t = build(&mut ctx, id, &mesh, PipelineChoice::Auto).unwrap();
                assert!(t
                    .patch_arrays()
                    .iter()
                    .all(|a| a.patch.path() == DrawPath::Pattern));
                let image = ctx
                    .render_offscreen(t.as_mut(), &params(4.0, Spacing::Equal), EXTENT)
                    .expect("render");
                assert!(image
                    .pixels
                    .chunks_exact(4)
                    .any(|p| p[0] != image.pixels[0]));
                for (level, sine) in [
                    (1.0, [0.0, 0.0]),
                    (3.0, [0.0, 0.0]),
                    (7.0, [0.0, 0.0]),
                    (16.0, [0.0, 0.0]),
                    (16.0, SINE),
                ] {
                    let what = format!("{id} on {name}, level {level}, sine {sine:?}");
                    let p = FrameParams {
                        displace_sine: sine,
                        ..params(level, Spacing::Equal)
                    };
                    let soup = capture(&mut ctx, t.as_mut(), &p);
                    assert_eq!(common::cracks(t.as_ref(), &soup, &mesh), (0, 0), "{what}");
                    let (dp, dn) = oracle_error(id, &mesh, &soup, sine);
                    println!("{what}: position error {dp:.2e}, normal error {dn:.2e}");
                    assert!(dp <= 2e-6 * diagonal, "{what}: position off by {dp}");
                    assert!(dn <= 2e-5, "{what}: normal off by {dn}");
                }
                let fractional = ctx.prepare(
                    t.as_mut(),
                    &params(4.0, Spacing::FractionalOdd),
                    &[tessera::tess::Pass::Shaded],
                );
                assert!(
                    matches!(fractional, Err(TessError::PatternSpacing { .. })),
                    "{fractional:?}"
                );
            }
        }
        let cube = cube();
        for (id, choice) in [
            (TechniqueId::FLAT, PipelineChoice::Tessellation),
            (TechniqueId::BFT, PipelineChoice::Tessellation),
            (TechniqueId::ADAPTIVE, PipelineChoice::Tessellation),
        ] {
            match build(&mut ctx, id, &cube, choice) {
                Err(e @ TessError::NoTessellationShader { .. }) => {
                    assert!(e.to_string().contains(id.name()), "{e}")
                }
                Err(e) => panic!("{id}: refused as {e}"),
                Ok(_) => panic!("{id} built without tessellation shaders"),
            }
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

#[test]
fn a_built_surface_keeps_its_path() {
    let gpu = Gpu::new();
    {
        let ctx = Context::offscreen(gpu.device()).unwrap();
        let mesh = cube();
        let flat = Flat::new(ctx.device(), &mesh, DrawPath::Pattern).unwrap();
        let phong = Phong::new(ctx.device(), &mesh, DrawPath::Tessellation).unwrap();
        let pn = Pn::new(ctx.device(), &mesh, DrawPath::Pattern).unwrap();
        assert_eq!(flat.patch_arrays()[0].control_points, 0);
        assert_eq!(phong.patch_arrays()[0].control_points, 3);
        assert!(pn
            .device_memory()
            .iter()
            .any(|m| m.name.contains("pattern corners")));
    }
}

/// BFT on the refinement-pattern path: with the device's tessellator its patterns are the
/// tessellator's, so at every power-of-two level both paths emit the same triangles and bits,
/// also animated; and `auto` keeps BFT on the tessellation stage (docs/benchmarks.md: the
/// pattern path costs more where the device tessellates).
#[test]
fn bft_draws_the_same_bits_through_patterns() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let meshes = [
            ("spot", spot().triangulated().0),
            (
                "loop_xord_boundary",
                load_obj(common::data(
                    "tests/data/opensubdiv/shapes/loop_xord_boundary.obj",
                ))
                .unwrap(),
            ),
        ];
        let mut compared = 0;
        for (name, mesh) in &meshes {
            let auto = build(&mut ctx, TechniqueId::BFT, mesh, PipelineChoice::Auto).unwrap();
            assert_eq!(auto.patch_arrays()[0].patch.path(), DrawPath::Tessellation);
            let mut tess = build(
                &mut ctx,
                TechniqueId::BFT,
                mesh,
                PipelineChoice::Tessellation,
            )
            .unwrap();
            let mut pattern =
                build(&mut ctx, TechniqueId::BFT, mesh, PipelineChoice::Pattern).unwrap();
            assert_eq!(pattern.patch_arrays()[0].patch.path(), DrawPath::Pattern);
            // Uniform levels' triangles are known before any frame (benchmarks choose levels
            // by them), and are the tessellation path's.
            let p4 = params(4.0, Spacing::Equal);
            assert!(pattern.triangles(&p4, 0).is_some_and(|n| n > 0), "{name}");
            assert_eq!(pattern.triangles(&p4, 0), tess.triangles(&p4, 0), "{name}");
            for (segments, time) in [(2.0, None), (4.0, None), (16.0, None), (8.0, Some(0.3))] {
                if let Some(t) = time {
                    use tessera::tess::animation::{base_normals, base_positions, wave};
                    let base = tess.base_mesh().unwrap().clone();
                    let (lo, hi) = tess.bbox();
                    let posed = wave(&base_positions(&base), &base_normals(&base), lo, hi, t);
                    tess.update_base(0, &posed).unwrap();
                    pattern.update_base(0, &posed).unwrap();
                }
                let what = format!("bft on {name}, S = {segments}, animated {time:?}");
                let p = params(segments, Spacing::Equal);
                let a = capture(&mut ctx, tess.as_mut(), &p);
                let b = capture(&mut ctx, pattern.as_mut(), &p);
                assert!(a.triangle_count() > 0, "{what}");
                assert_eq!(triangles(&a), triangles(&b), "{what}");
                let (sa, sb) = (samples(&a), samples(&b));
                let differing = sa.iter().filter(|(k, v)| sb.get(k) != Some(v)).count();
                assert_eq!(differing, 0, "{what}: of {} samples", sa.len());
                // The flags too: exact table point, patch kind.
                let flags = |s: &CapturedSoup| -> HashMap<(u32, [u32; 2]), u32> {
                    s.records
                        .iter()
                        .map(|r| ((r.patch, r.domain.map(f32::to_bits)), r.flags))
                        .collect()
                };
                assert_eq!(flags(&a), flags(&b), "{what}");
                compared += sa.len();
            }
        }
        println!("{compared} BFT samples bit-identical on both paths");
        assert!(compared > 50_000, "{compared}");
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// BFT without tessellation shaders: `auto` draws generated patterns, welded by bits. At every
/// power-of-two level each sample at a domain point the tessellator also emits (edges,
/// corners, shared lattice points) equals, bit for bit, what the tessellation path of a device
/// with a tessellator evaluates there, and every sample is the exact Loop limit at its own
/// domain point (to the tolerance of BFT's own tests).
#[test]
fn without_tessellation_shaders_bft_draws_generated_patterns() {
    let mesh = spot().triangulated().0;
    let levels = [2.0, 8.0, 16.0];
    let reference: Vec<Samples> = {
        let gpu = Gpu::new();
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mut t = build(
            &mut ctx,
            TechniqueId::BFT,
            &mesh,
            PipelineChoice::Tessellation,
        )
        .unwrap();
        let out = levels
            .iter()
            .map(|&s| samples(&capture(&mut ctx, t.as_mut(), &params(s, Spacing::Equal))))
            .collect();
        drop(t);
        drop(ctx);
        assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
        out
    };
    let gpu = Gpu::with(&DeviceDesc {
        without_tessellation_shader: true,
        ..DeviceDesc::default()
    });
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mut t = build(&mut ctx, TechniqueId::BFT, &mesh, PipelineChoice::Auto).unwrap();
        assert_eq!(t.patch_arrays()[0].patch.path(), DrawPath::Pattern);
        let cpu = LocalMesh::from_control_mesh(&mesh, LimitScheme::Loop).unwrap();
        for (&s, want) in levels.iter().zip(&reference) {
            let soup = capture(&mut ctx, t.as_mut(), &params(s, Spacing::Equal));
            assert_eq!(common::cracks(t.as_ref(), &soup, &mesh), (0, 0), "S = {s}");
            let got = samples(&soup);
            let common: Vec<_> = got.keys().filter(|k| want.contains_key(k)).collect();
            let differing = common.iter().filter(|k| got[k] != want[k]).count();
            assert_eq!(differing, 0, "S = {s}: of {} common samples", common.len());
            assert!(
                common.len() * 2 > got.len(),
                "S = {s}: {} of {}",
                common.len(),
                got.len()
            );
            let worst = exact_limit_error(t.as_ref(), &soup, &cpu) / mesh.bbox_diagonal();
            println!(
                "S = {s}: {} samples, {} common, limit error {worst:.2e}",
                got.len(),
                common.len()
            );
            assert!(worst <= 5e-6, "S = {s}: {worst}");
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// The largest distance between a captured vertex of a Loop surface drawn over the triangle
/// mesh `cpu` evaluates and the exact limit at the captured vertex's base-face point.
fn exact_limit_error(t: &dyn Technique, soup: &CapturedSoup, cpu: &LocalMesh) -> f64 {
    let mut worst = 0.0f64;
    for r in &soup.records {
        let p = t.face_point(r.patch, r.domain).expect("a drawn patch");
        // face_point's (u, v) weigh the triangle's corners 0 and 1; evaluate takes 1 and 2.
        let (u, v) = (p.u as f64, p.v as f64);
        let e = cpu
            .evaluate(p.face as usize, v, 1.0 - u - v)
            .expect("exact limit");
        let d = (0..3)
            .map(|k| (r.position[k] as f64 - e.position[k]).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = worst.max(d);
    }
    worst
}

/// Just past a level's doubling: the largest distance, over the diagonal, from a vertex of
/// `after` to the vertex of `before` at its patch and domain point on the 1/16 lattice (levels
/// 4 and, on coarse transition edges, 8; a moved vertex lies next to the even point it left);
/// every vertex of `after` must have one (`what` names the surface).
fn past_doubling_error(
    before: &CapturedSoup,
    after: &CapturedSoup,
    diagonal: f64,
    what: &str,
) -> f64 {
    let key = |patch: u32, d: [f32; 2]| (patch, d.map(|x| (x * 16.0).round() as i32));
    let old: HashMap<_, [f32; 3]> = before
        .records
        .iter()
        .map(|r| (key(r.patch, r.domain), r.position))
        .collect();
    let mut worst = 0.0f64;
    for r in &after.records {
        let q = old
            .get(&key(r.patch, r.domain))
            .unwrap_or_else(|| panic!("{what}: no vertex before at {:?}", r.domain));
        let d = (0..3)
            .map(|i| (r.position[i] as f64 - q[i] as f64).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = worst.max(d / diagonal);
    }
    worst
}

/// The largest distance between a captured BFT vertex and the tables' f32 mirror of the
/// evaluation stage at the vertex's recorded domain point (table points exactly, other points
/// on the level-L virtual mesh), over the level-1 surface of `base`.
fn mirror_error(mirror: &GpuBft, base: &[[f32; 3]], soup: &CapturedSoup) -> f64 {
    let level1 = mirror.subdivide(base);
    let normals = mirror.normals(&level1);
    let mut worst = 0.0f64;
    for r in &soup.records {
        // The capture records two weights; on an edge their sum can round past 1.
        let [x, y] = r.domain;
        let b = [x, y, (1.0 - x - y).max(0.0)];
        let m = mirror.eval_tess(&level1, &normals, r.patch as usize, b, false);
        let d = (0..3)
            .map(|k| (r.position[k] as f64 - m.position[k] as f64).powi(2))
            .sum::<f64>()
            .sqrt();
        worst = worst.max(d);
    }
    worst
}

/// BFT's screen-space and distance factors and its geomorphing on the pattern path. The host
/// chooses each level-1 edge's level from its two endpoints, as the control stage does, so the
/// levels vary over the surface; every capture welds with 0 cracks (also animated and from
/// other views); every vertex is what the tables' f32 mirror evaluates at its recorded domain
/// point, and every table point the exact Loop limit there. Geomorphing (fractional-even
/// spacing) moves the odd vertices off the table points (some vertices are inexact), and just
/// past a level's doubling every vertex is within 1e-4 of the diagonal of a vertex of the frame
/// before: the level of detail does not pop. A uniform level that is not whole welds on the
/// tessellation path too; the same welds on a device without tessellation shaders.
#[test]
fn bft_takes_screen_space_distance_and_geomorphing_through_patterns() {
    use tessera::tess::animation::{base_positions, Wave};
    let mesh = spot().triangulated().0;
    let diagonal = mesh.bbox_diagonal();
    let cpu = LocalMesh::from_control_mesh(&mesh, LimitScheme::Loop).unwrap();
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mut t = build(&mut ctx, TechniqueId::BFT, &mesh, PipelineChoice::Pattern).unwrap();
        let prepared = prepare_loop_bft(t.base_mesh().unwrap(), DEFAULT_TABLE_LEVEL, false);
        let mirror = GpuBft::new(&prepared.unwrap()).unwrap();
        let distance = FactorPolicy::Distance {
            reference: 0.04 * diagonal as f32,
        };
        let (equal, morph) = (Spacing::Equal, Spacing::FractionalEven);
        let frames = [
            (FactorPolicy::Screen { pixels: 6.0 }, equal, 0.0),
            (distance, equal, 0.0),
            (FactorPolicy::Screen { pixels: 3.0 }, equal, 0.37),
            (FactorPolicy::Uniform { segments: 5.3 }, morph, 0.0),
            (FactorPolicy::Screen { pixels: 5.0 }, morph, 0.0),
            (distance, morph, 0.0),
            (FactorPolicy::Screen { pixels: 3.0 }, morph, 0.37),
        ];
        for (k, (factors, spacing, time)) in frames.into_iter().enumerate() {
            let what = format!("bft, {factors}, {spacing:?}, time {time}");
            let base = match time {
                0.0 => base_positions(&mesh),
                _ => Wave::new(&mesh).at(time),
            };
            t.update_base(0, &base).unwrap();
            let view = (k % 3) as f32;
            let p = FrameParams {
                factors,
                spacing,
                camera: tessera::tess::Camera {
                    zoom: 2.0 + view,
                    yaw: 30.0 * view,
                    ..Default::default()
                },
                ..FrameParams::default()
            };
            let soup = capture(&mut ctx, t.as_mut(), &p);
            assert_eq!(common::cracks(t.as_ref(), &soup, &mesh), (0, 0), "{what}");
            if !matches!(factors, FactorPolicy::Uniform { .. }) {
                let mut per_patch: HashMap<u32, usize> = HashMap::new();
                for r in &soup.records {
                    *per_patch.entry(r.patch).or_default() += 1;
                }
                let sizes: BTreeSet<usize> = per_patch.values().copied().collect();
                assert!(sizes.len() > 2, "{what}: every patch drew alike: {sizes:?}");
            }
            let mirrored = mirror_error(&mirror, &base, &soup) / diagonal;
            // Table points where the pattern put them, on the tables' grid (a third of a level-L
            // segment: fans put a vertex at a face's centre); a moved vertex within the
            // evaluation's snapping distance of a table point is evaluated there, and is checked
            // against the mirror alone.
            let grid = 3.0 * (1u32 << DEFAULT_TABLE_LEVEL) as f32;
            let on_lattice = |d: [f32; 2]| {
                d.iter()
                    .all(|&x| (x * grid - (x * grid).round()).abs() < 1e-3)
            };
            let exact = CapturedSoup {
                records: soup
                    .records
                    .iter()
                    .filter(|r| r.flags & 1 == 1 && on_lattice(r.domain))
                    .copied()
                    .collect(),
            };
            let moved = soup.records.iter().filter(|r| r.flags & 1 == 0).count();
            let limit = match time {
                0.0 => exact_limit_error(t.as_ref(), &exact, &cpu) / diagonal,
                _ => 0.0,
            };
            println!(
                "{what}: {} triangles, {moved} vertices moved, {mirrored:.1e} from the mirror, \
                 table points {limit:.1e} from the limit",
                soup.triangle_count()
            );
            assert!(mirrored <= 1e-5, "{what}: {mirrored}");
            assert!(limit <= 5e-6, "{what}: {limit}");
            match spacing {
                Spacing::Equal => assert_eq!(moved, 0, "{what}"),
                _ => assert!(moved > 0, "{what}: nothing moved"),
            }
        }
        t.update_base(0, &base_positions(&mesh)).unwrap();
        let before = capture(&mut ctx, t.as_mut(), &params(8.0, morph));
        let after = capture(&mut ctx, t.as_mut(), &params(8.004, morph));
        assert!(
            after.records.len() > before.records.len(),
            "the level doubled"
        );
        let worst = past_doubling_error(&before, &after, diagonal, "bft");
        println!("bft: past the doubling, every vertex within {worst:.1e} of one before");
        assert!(worst <= 1e-4, "{worst}");
        // A level that is not whole is fractional spacing's on the tessellation path too.
        let mut tess = build(
            &mut ctx,
            TechniqueId::BFT,
            &mesh,
            PipelineChoice::Tessellation,
        )
        .unwrap();
        let soup = capture(&mut ctx, tess.as_mut(), &params(5.3, morph));
        assert!(soup.triangle_count() > 0);
        assert_eq!(
            common::cracks(tess.as_ref(), &soup, &mesh),
            (0, 0),
            "tessellation, 5.3"
        );
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
    drop(gpu);
    let gpu = Gpu::with(&DeviceDesc {
        without_tessellation_shader: true,
        ..DeviceDesc::default()
    });
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mut t = build(&mut ctx, TechniqueId::BFT, &mesh, PipelineChoice::Auto).unwrap();
        for spacing in [Spacing::Equal, Spacing::FractionalEven] {
            let p = FrameParams {
                factors: FactorPolicy::Screen { pixels: 5.0 },
                spacing,
                ..FrameParams::default()
            };
            let soup = capture(&mut ctx, t.as_mut(), &p);
            let what = format!("without tessellation shaders, {spacing:?}");
            assert_eq!(common::cracks(t.as_ref(), &soup, &mesh), (0, 0), "{what}");
            let worst = exact_limit_error(t.as_ref(), &soup, &cpu) / diagonal;
            if spacing == Spacing::Equal {
                assert!(worst <= 5e-6, "{what}: {worst}");
            }
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// The seed's sine displacement on BFT, on both paths: at a uniform level the pattern path
/// has the tessellation path's bits at every sample; both weld with 0 cracks, as do the
/// patterns under screen-space factors (a shared point has its owner's position and normal bits
/// on both faces, so it moves to the same bits); and every vertex is the tables' f32 mirror
/// moved by a·sin(f·‖P‖) along its unit normal, within 1e-5 of the diagonal.
#[test]
fn bft_takes_the_sine_displacement_on_both_paths() {
    let mesh = spot().triangulated().0;
    let diagonal = mesh.bbox_diagonal();
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mut tess = build(
            &mut ctx,
            TechniqueId::BFT,
            &mesh,
            PipelineChoice::Tessellation,
        )
        .unwrap();
        let mut pattern =
            build(&mut ctx, TechniqueId::BFT, &mesh, PipelineChoice::Pattern).unwrap();
        let prepared = prepare_loop_bft(tess.base_mesh().unwrap(), DEFAULT_TABLE_LEVEL, false);
        let mirror = GpuBft::new(&prepared.unwrap()).unwrap();
        let level1 = mirror.subdivide(&tessera::tess::animation::base_positions(&mesh));
        let normals = mirror.normals(&level1);
        let uniform = FrameParams {
            displace_sine: SINE,
            ..params(8.0, Spacing::Equal)
        };
        let a = capture(&mut ctx, tess.as_mut(), &uniform);
        let b = capture(&mut ctx, pattern.as_mut(), &uniform);
        assert_eq!(
            common::cracks(tess.as_ref(), &a, &mesh),
            (0, 0),
            "tessellation"
        );
        assert_eq!(
            common::cracks(pattern.as_ref(), &b, &mesh),
            (0, 0),
            "pattern"
        );
        let (sa, sb) = (samples(&a), samples(&b));
        let differing = sa.iter().filter(|(k, v)| sb.get(k) != Some(v)).count();
        assert_eq!(differing, 0, "of {} samples", sa.len());
        let (mut worst, mut moved) = (0.0f64, 0.0f64);
        for r in &a.records {
            let [x, y] = r.domain;
            let b = [x, y, (1.0 - x - y).max(0.0)];
            let m = mirror.eval_tess(&level1, &normals, r.patch as usize, b, false);
            let p = m.position.map(f64::from);
            let n = m.normal.map(f64::from);
            let len = (n[0] * n[0] + n[1] * n[1] + n[2] * n[2]).sqrt();
            let norm = (p[0] * p[0] + p[1] * p[1] + p[2] * p[2]).sqrt();
            let h = SINE[0] as f64 * (SINE[1] as f64 * norm).sin() / len;
            let d = (0..3)
                .map(|k| (r.position[k] as f64 - (p[k] + h * n[k])).powi(2))
                .sum::<f64>()
                .sqrt();
            worst = worst.max(d / diagonal);
            moved = moved.max((h * len).abs());
        }
        println!(
            "bft with the sine displacement: {} samples bit-identical on both paths, {worst:.1e} \
             of the diagonal from the displaced mirror, largest move {moved:.4}",
            sa.len()
        );
        assert!(worst <= 1e-5, "{worst}");
        assert!(moved > 0.9 * SINE[0] as f64, "{moved}");
        let screen = FrameParams {
            factors: FactorPolicy::Screen { pixels: 5.0 },
            displace_sine: SINE,
            ..FrameParams::default()
        };
        let soup = capture(&mut ctx, pattern.as_mut(), &screen);
        assert_eq!(
            common::cracks(pattern.as_ref(), &soup, &mesh),
            (0, 0),
            "screen-space"
        );
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// The planned surfaces (feature-adaptive Catmull-Clark, Gregory, ACC-1, the Doo-Sabin limit),
/// which evaluate at a patch domain point.
const PLANNED_TECHNIQUES: [TechniqueId; 4] = [
    TechniqueId::ADAPTIVE,
    TechniqueId::GREGORY,
    TechniqueId::ACC,
    TechniqueId::DOO_SABIN_LIMIT,
];

fn build_isolated(
    ctx: &mut Context,
    id: TechniqueId,
    mesh: &ControlMesh,
    pipeline: PipelineChoice,
) -> tessera::tess::Result<Box<dyn Technique>> {
    let options = BuildOptions {
        name: "patterns test".into(),
        pipeline,
        isolation: 2,
        ..BuildOptions::default()
    };
    Ok(tessera::tess::build(ctx, id, mesh, &options)?.technique)
}

/// Samples of `pattern` at the tessellation path's domain points, and how many of them differ
/// in any bit from `tess`'s; every pattern sample must have such a point.
fn compare_samples(tess: &CapturedSoup, pattern: &CapturedSoup, what: &str) -> usize {
    let (a, b) = (samples(tess), samples(pattern));
    let missing: Vec<_> = b.keys().filter(|k| !a.contains_key(k)).take(4).collect();
    assert!(
        missing.is_empty(),
        "{what}: pattern samples at points the tessellator never emits: {missing:?}"
    );
    let differing = b.iter().filter(|(k, v)| a.get(k) != Some(v)).count();
    assert_eq!(differing, 0, "{what}: of {} samples", b.len());
    b.len()
}

/// The planned surfaces on the refinement-pattern path, with the device's tessellator: one
/// pattern per edge-level key (a transition patch's doubled edge has its own), the uniform ones
/// the tessellator's own. Every pattern vertex lies at a domain point the tessellation path
/// also emits and has its bits there (so it is the limit, or the end cap, exactly as that path
/// draws it); the surface is welded by bits with 0 cracks, also animated; fractional-odd
/// spacing is refused there by name, and `auto` keeps the tessellation stage.
#[test]
fn planned_patches_draw_the_tessellation_paths_bits_through_patterns() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mut compared = 0;
        for id in PLANNED_TECHNIQUES {
            for (name, mesh) in [("spot", spot()), ("cube", cube())] {
                let mut tess =
                    build_isolated(&mut ctx, id, &mesh, PipelineChoice::Tessellation).unwrap();
                let mut pattern =
                    build_isolated(&mut ctx, id, &mesh, PipelineChoice::Pattern).unwrap();
                assert!(pattern
                    .patch_arrays()
                    .iter()
                    .all(|a| a.patch.path() == DrawPath::Pattern));
                for (level, time) in [(1.0, 0.0), (2.0, 0.0), (3.0, 0.0), (8.0, 0.0), (4.0, 0.37)] {
                    let what = format!("{id} on {name}, level {level}, time {time}");
                    if time != 0.0 {
                        let moved = tessera::tess::animation::Wave::new(&mesh).at(time);
                        tess.update_base(0, &moved).unwrap();
                        pattern.update_base(0, &moved).unwrap();
                    }
                    let p = params(level, Spacing::Equal);
                    let a = capture(&mut ctx, tess.as_mut(), &p);
                    let b = capture(&mut ctx, pattern.as_mut(), &p);
                    compared += compare_samples(&a, &b, &what);
                    assert_eq!(
                        common::cracks(pattern.as_ref(), &b, &mesh),
                        (0, 0),
                        "{what}"
                    );
                }
                let refused = params(4.0, Spacing::FractionalOdd);
                let e = ctx.prepare(pattern.as_mut(), &refused, &[tessera::tess::Pass::Shaded]);
                let e = e.err().map(|e| e.to_string()).unwrap_or_default();
                assert!(e.contains("--spacing"), "{id}: {e}");
            }
            let auto = build_isolated(&mut ctx, id, &cube(), PipelineChoice::Auto).unwrap();
            assert!(auto
                .patch_arrays()
                .iter()
                .all(|a| a.patch.path() == DrawPath::Tessellation));
        }
        println!("{compared} planned-patch samples bit-identical on both paths");
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// Without tessellation shaders `auto` draws the planned surfaces through generated patterns,
/// welded by bits with 0 cracks; each vertex at a domain point a tessellator's path also
/// emits has that path's bits (the reference drawn on a device with one).
#[test]
fn without_tessellation_shaders_the_planned_patches_draw_generated_patterns() {
    let mesh = spot();
    let level = 4.0;
    let reference: Vec<Samples> = {
        let gpu = Gpu::new();
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let out = PLANNED_TECHNIQUES
            .iter()
            .map(|&id| {
                let mut t =
                    build_isolated(&mut ctx, id, &mesh, PipelineChoice::Tessellation).unwrap();
                samples(&capture(
                    &mut ctx,
                    t.as_mut(),
                    &params(level, Spacing::Equal),
                ))
            })
            .collect();
        drop(ctx);
        assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
        out
    };
    let gpu = Gpu::with(&DeviceDesc {
        without_tessellation_shader: true,
        ..DeviceDesc::default()
    });
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        for (id, want) in PLANNED_TECHNIQUES.into_iter().zip(&reference) {
            let mut t = build_isolated(&mut ctx, id, &mesh, PipelineChoice::Auto).unwrap();
            assert!(t
                .patch_arrays()
                .iter()
                .all(|a| a.patch.path() == DrawPath::Pattern));
            let soup = capture(&mut ctx, t.as_mut(), &params(level, Spacing::Equal));
            assert_eq!(common::cracks(t.as_ref(), &soup, &mesh), (0, 0), "{id}");
            let got = samples(&soup);
            let common = got.keys().filter(|k| want.contains_key(k)).count();
            let differing = got
                .iter()
                .filter(|(k, v)| want.get(k).is_some_and(|w| w != *v))
                .count();
            println!(
                "{id}: {} samples, {common} at the tessellation path's points",
                got.len()
            );
            assert_eq!(differing, 0, "{id}: of {common} common samples");
            assert!(common * 2 > got.len(), "{id}: {common} of {}", got.len());
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// Screen-space and distance factors on the pattern path: the host chooses each patch's edge
/// levels from its canonical curves in the frame's view, so the levels vary over the surface
/// (patches with different triangle counts), every capture welds with 0 cracks, also animated
/// and from a second view, and the exact surfaces' regular patches stay within 1e-5 of the
/// diagonal of the exact limit at every vertex's own domain point.
#[test]
fn planned_patches_take_screen_space_and_distance_factors_through_patterns() {
    use tessera::tess::gpu::bindings::ADAPTIVE_KIND_REGULAR;
    use tessera::topology::limit::face_domain::LimitEvaluator;
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mesh = spot();
        let diagonal = mesh.bbox_diagonal();
        for id in PLANNED_TECHNIQUES {
            let exact = match id {
                TechniqueId::ADAPTIVE => {
                    Some(LimitEvaluator::new(&mesh, LimitScheme::CatmullClark).unwrap())
                }
                TechniqueId::DOO_SABIN_LIMIT => Some(LimitEvaluator::doo_sabin(&mesh).unwrap()),
                _ => None,
            };
            let mut t = build_isolated(&mut ctx, id, &mesh, PipelineChoice::Pattern).unwrap();
            for (k, factors) in [
                FactorPolicy::Screen { pixels: 6.0 },
                FactorPolicy::Distance {
                    reference: 0.04 * diagonal as f32,
                },
                FactorPolicy::Screen { pixels: 3.0 },
            ]
            .into_iter()
            .enumerate()
            {
                let what = format!("{id}, {factors}");
                if k == 2 {
                    let moved = tessera::tess::animation::Wave::new(&mesh).at(0.37);
                    t.update_base(0, &moved).unwrap();
                }
                let p = FrameParams {
                    factors,
                    camera: tessera::tess::Camera {
                        zoom: 2.0 + k as f32,
                        yaw: 30.0 * k as f32,
                        ..Default::default()
                    },
                    ..FrameParams::default()
                };
                let soup = capture(&mut ctx, t.as_mut(), &p);
                assert_eq!(common::cracks(t.as_ref(), &soup, &mesh), (0, 0), "{what}");
                let mut per_patch: HashMap<u32, usize> = HashMap::new();
                for r in &soup.records {
                    *per_patch.entry(r.patch).or_default() += 1;
                }
                let sizes: BTreeSet<usize> = per_patch.values().copied().collect();
                assert!(sizes.len() > 2, "{what}: every patch drew alike: {sizes:?}");
                if let (Some(limit), 0 | 1) = (&exact, k) {
                    let mut worst = 0.0f64;
                    for r in soup
                        .records
                        .iter()
                        .filter(|r| r.flags & 15 == ADAPTIVE_KIND_REGULAR)
                    {
                        let f = t.face_point(r.patch, r.domain).unwrap();
                        let e = limit.evaluate(f.face, f.u as f64, f.v as f64).unwrap();
                        let d = (0..3)
                            .map(|i| (r.position[i] as f64 - e.position[i]).powi(2))
                            .sum::<f64>()
                            .sqrt();
                        worst = worst.max(d / diagonal);
                    }
                    println!(
                        "{what}: {} triangles, regular patches {worst:.1e} from the limit",
                        soup.triangle_count()
                    );
                    assert!(worst <= 1e-5, "{what}: {worst}");
                }
            }
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// The seed's sine displacement on the Catmull-Clark planned surfaces, on both draw paths: the
/// pattern path emits the tessellation path's bits at every sample; both weld with 0 cracks
/// (a boundary point moves along its canonical owner's normal); adaptive's regular patches are
/// the exact limit moved by a·sin(f·‖P‖) along its unit normal, within 1e-5 of the diagonal; the
/// Doo-Sabin limit, which has no owner frames to move along, refuses it by name.
#[test]
fn planned_surfaces_take_the_sine_displacement_on_both_paths() {
    use tessera::tess::gpu::bindings::ADAPTIVE_KIND_REGULAR;
    use tessera::topology::limit::face_domain::LimitEvaluator;
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mesh = spot();
        let diagonal = mesh.bbox_diagonal();
        let limit = LimitEvaluator::new(&mesh, LimitScheme::CatmullClark).unwrap();
        let p = FrameParams {
            displace_sine: SINE,
            ..FrameParams::uniform(4.0)
        };
        for id in [
            TechniqueId::ADAPTIVE,
            TechniqueId::GREGORY,
            TechniqueId::ACC,
        ] {
            let mut soups = Vec::new();
            for path in [PipelineChoice::Tessellation, PipelineChoice::Pattern] {
                let what = format!("{id}, {path:?}");
                let mut t = build_isolated(&mut ctx, id, &mesh, path).unwrap();
                let soup = capture(&mut ctx, t.as_mut(), &p);
                let plain = capture(&mut ctx, t.as_mut(), &FrameParams::uniform(4.0));
                assert_ne!(samples(&soup), samples(&plain), "{what}: the surface moved");
                assert_eq!(common::cracks(t.as_ref(), &soup, &mesh), (0, 0), "{what}");
                if id == TechniqueId::ADAPTIVE {
                    let mut worst = 0.0f64;
                    let regular = soup
                        .records
                        .iter()
                        .filter(|r| r.flags & 15 == ADAPTIVE_KIND_REGULAR);
                    for r in regular {
                        let f = t.face_point(r.patch, r.domain).unwrap();
                        let e = limit.evaluate(f.face, f.u as f64, f.v as f64).unwrap();
                        let want = oracle::displaced(e.position, e.normal, SINE.map(f64::from));
                        let d = (0..3)
                            .map(|i| (r.position[i] as f64 - want[i]).powi(2))
                            .sum::<f64>()
                            .sqrt();
                        worst = worst.max(d / diagonal);
                    }
                    println!("{what}: regular patches {worst:.1e} from the displaced limit");
                    assert!(worst <= 1e-5, "{what}: {worst}");
                }
                soups.push(soup);
            }
            let n = compare_samples(&soups[0], &soups[1], &format!("{id} displaced"));
            println!("{id}: {n} displaced samples, the same bits on both paths");
        }
        let mut t = build_isolated(
            &mut ctx,
            TechniqueId::DOO_SABIN_LIMIT,
            &mesh,
            PipelineChoice::Tessellation,
        )
        .unwrap();
        let e = ctx
            .prepare(t.as_mut(), &p, &[tessera::tess::Pass::Shaded])
            .unwrap_err()
            .to_string();
        assert!(e.contains("sine displacement (--displace-sine)"), "{e}");
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

/// The regular patches' largest distance from the exact limit at each vertex's recorded domain
/// point (where the vertex stage evaluated it), over the diagonal.
fn regular_limit_error(
    t: &dyn Technique,
    soup: &CapturedSoup,
    limit: &tessera::topology::limit::face_domain::LimitEvaluator,
    diagonal: f64,
) -> f64 {
    use tessera::tess::gpu::bindings::ADAPTIVE_KIND_REGULAR;
    let regular = soup
        .records
        .iter()
        .filter(|r| r.flags & 15 == ADAPTIVE_KIND_REGULAR);
    regular.fold(0.0f64, |worst, r| {
        let f = t.face_point(r.patch, r.domain).unwrap();
        let e = limit.evaluate(f.face, f.u as f64, f.v as f64).unwrap();
        let d = (0..3)
            .map(|i| (r.position[i] as f64 - e.position[i]).powi(2))
            .sum::<f64>()
            .sqrt();
        worst.max(d / diagonal)
    })
}

/// Geomorphing on the pattern path (fractional-even spacing there): patterns of power-of-two
/// levels whose odd vertices slide toward the coarser level's by each edge's and the inside's
/// weight. At uniform, screen-space and distance factors, and animated, the surface welds with 0 cracks
/// and every regular-patch vertex is the exact limit at the domain point it was evaluated at;
/// just past a level's doubling (weight 0.001) every vertex is within 1e-4 of the diagonal of a
/// vertex of the frame just before it, where the pattern of half the level was drawn: the
/// level of detail does not pop. The same welds on a device without tessellation shaders.
#[test]
fn planned_patches_geomorph_between_levels_through_patterns() {
    use tessera::topology::limit::face_domain::LimitEvaluator;
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mesh = spot();
        let diagonal = mesh.bbox_diagonal();
        for id in [
            TechniqueId::ADAPTIVE,
            TechniqueId::GREGORY,
            TechniqueId::DOO_SABIN_LIMIT,
        ] {
            let exact = match id {
                TechniqueId::ADAPTIVE => {
                    Some(LimitEvaluator::new(&mesh, LimitScheme::CatmullClark).unwrap())
                }
                TechniqueId::DOO_SABIN_LIMIT => Some(LimitEvaluator::doo_sabin(&mesh).unwrap()),
                _ => None,
            };
            let mut t = build_isolated(&mut ctx, id, &mesh, PipelineChoice::Pattern).unwrap();
            let frames = [
                (FactorPolicy::Uniform { segments: 5.3 }, 0.0),
                (FactorPolicy::Screen { pixels: 5.0 }, 0.0),
                (
                    FactorPolicy::Distance {
                        reference: 0.05 * diagonal as f32,
                    },
                    0.0,
                ),
                (FactorPolicy::Screen { pixels: 3.0 }, 0.37),
            ];
            for (factors, time) in frames {
                let what = format!("{id}, {factors}, geomorphing, time {time}");
                if time != 0.0 {
                    let moved = tessera::tess::animation::Wave::new(&mesh).at(time);
                    t.update_base(0, &moved).unwrap();
                }
                let p = FrameParams {
                    factors,
                    spacing: Spacing::FractionalEven,
                    camera: tessera::tess::Camera {
                        zoom: 2.0,
                        ..Default::default()
                    },
                    ..FrameParams::default()
                };
                let soup = capture(&mut ctx, t.as_mut(), &p);
                assert_eq!(common::cracks(t.as_ref(), &soup, &mesh), (0, 0), "{what}");
                if let (Some(limit), 0.0) = (&exact, time) {
                    let worst = regular_limit_error(t.as_ref(), &soup, limit, diagonal);
                    println!("{what}: regular patches {worst:.1e} from the limit");
                    assert!(worst <= 1e-5, "{what}: {worst}");
                }
            }
            t.update_base(0, &tessera::tess::animation::base_positions(&mesh))
                .unwrap();
            let before = capture(&mut ctx, t.as_mut(), &params(4.0, Spacing::FractionalEven));
            let after = capture(
                &mut ctx,
                t.as_mut(),
                &params(4.002, Spacing::FractionalEven),
            );
            assert!(
                after.records.len() > before.records.len(),
                "{id}: the level doubled"
            );
            let worst = past_doubling_error(&before, &after, diagonal, &id.to_string());
            println!("{id}: past the doubling, every vertex within {worst:.1e} of one before");
            assert!(worst <= 1e-4, "{id}: {worst}");
        }
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
    drop(gpu);
    // The same on a device without tessellation shaders (every pattern generated).
    let gpu = Gpu::with(&DeviceDesc {
        without_tessellation_shader: true,
        ..DeviceDesc::default()
    });
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let mesh = spot();
        let limit = LimitEvaluator::new(&mesh, LimitScheme::CatmullClark).unwrap();
        let mut t =
            build_isolated(&mut ctx, TechniqueId::ADAPTIVE, &mesh, PipelineChoice::Auto).unwrap();
        let p = FrameParams {
            factors: FactorPolicy::Screen { pixels: 5.0 },
            spacing: Spacing::FractionalEven,
            ..FrameParams::default()
        };
        let soup = capture(&mut ctx, t.as_mut(), &p);
        assert_eq!(
            common::cracks(t.as_ref(), &soup, &mesh),
            (0, 0),
            "without tessellation shaders"
        );
        let worst = regular_limit_error(t.as_ref(), &soup, &limit, mesh.bbox_diagonal());
        println!("without tessellation shaders: regular patches {worst:.1e} from the limit");
        assert!(worst <= 1e-5, "without tessellation shaders: {worst}");
    }
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}
