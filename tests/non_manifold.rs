//! Non-manifold control meshes drawn by every technique of the registry: OpenSubdiv's
//! non-manifold regression shapes (edges of three or more faces, faces of opposite winding,
//! vertices whose faces form several fans, quad poles, vertices no face uses).
//! - Every technique builds each shape of its scheme (flat, Phong, PN and Doo-Sabin: every
//!   shape; Doo-Sabin refuses catmark_val2_nonman by name, as it refuses any vertex of two
//!   faces), renders
//!   it validation-clean and draws something; a capture of what the GPU emitted has no crack
//!   and no unmapped vertex: every open edge lies on the shape's boundary or along one of its
//!   non-manifold edges (or inside a face of no area, see [`capture`]), so faces that share a
//!   manifold edge are watertight by bits.
//! - An animated base moves every copy of a split vertex with its source: still no crack.
//! - The meshes refined on the CPU put every captured vertex on the exact limit (the split's)
//!   at its face point.
mod common;

use common::Gpu;
use tessera::tess::animation::Wave;
use tessera::tess::capture::{classify_open_edges, EdgeReport};
use tessera::tess::techniques::{self, TechniqueInfo};
use tessera::tess::{BuildOptions, Capturer, Context, FrameParams, Technique, TechniqueId};
use tessera::topology::limit::eval::LimitScheme;
use tessera::topology::limit::face_domain::LimitEvaluator;
use tessera::topology::{load_obj, ControlMesh, Scheme};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 64,
    height: 64,
};

const SHAPES: [&str; 10] = [
    "catmark_nonman_bareverts",
    "catmark_nonman_edge100",
    "catmark_nonman_edges",
    "catmark_nonman_quadpole8",
    "catmark_nonman_quadpole64",
    "catmark_nonman_verts",
    "catmark_val2_nonman",
    "loop_nonman_edge100",
    "loop_nonman_edges",
    "loop_nonman_verts",
];

fn shape(name: &str) -> (ControlMesh, Scheme) {
    let mesh = load_obj(common::data(&format!(
        "tests/data/opensubdiv/nonmanifold/{name}.obj"
    )))
    .unwrap_or_else(|e| panic!("{name}: {e}"));
    (mesh, Scheme::from_shape_name(name).expect("scheme"))
}

/// The shapes a technique draws: those of its scheme, or all of them (techniques of no
/// scheme, and Doo-Sabin, which OpenSubdiv's shapes are not named for).
fn shapes_for(info: &TechniqueInfo) -> Vec<(&'static str, ControlMesh)> {
    SHAPES
        .iter()
        .map(|&name| (name, shape(name)))
        .filter(|(_, (_, scheme))| {
            info.scheme
                .is_none_or(|s| s == *scheme || s == Scheme::DooSabin)
        })
        .map(|(name, (mesh, _))| (name, mesh))
        .collect()
}

fn build(
    ctx: &mut Context,
    info: &TechniqueInfo,
    mesh: &ControlMesh,
    name: &str,
) -> Box<dyn Technique> {
    techniques::build(
        ctx,
        info.id,
        mesh,
        &BuildOptions {
            name: name.into(),
            tangents: info.features.geometric_normals,
            ..BuildOptions::default()
        },
    )
    .unwrap_or_else(|e| panic!("building {} for {name}: {e}", info.id))
    .technique
}

/// Open edges of one capture by class: (cracks, unmapped, on the boundary, along a
/// non-manifold edge, inside a face of no area); and the welded positions.
///
/// A face of no area (catmark_nonman_edges' face 41 names two vertices twice each: a
/// segment) has no surface to keep closed: its patch's sliver triangles all lie on the
/// segment, and where two of them sample points whose positions round to one float they weld
/// into a fan with open sides. Such an open edge, both ends inside one face whose corners lie
/// on a line, is counted apart, not as a crack.
fn capture(
    ctx: &mut Context,
    capturer: &Capturer,
    technique: &mut dyn Technique,
    mesh: &ControlMesh,
    params: &FrameParams,
) -> ([usize; 5], Vec<[f32; 3]>) {
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
    let mut in_no_area = 0;
    if c.cracks > c.unmapped {
        for e in &report.open {
            let one = EdgeReport {
                open: vec![*e],
                ..EdgeReport::default()
            };
            if classify_open_edges(&soup, &welded, &one, &map, mesh).cracks == 0 {
                continue;
            }
            let t = e.triangle as usize;
            let faces: Vec<Option<u32>> = (0..3)
                .filter(|&i| e.vertices.contains(&welded.triangles[t][i]))
                .map(|i| soup.records[3 * t + i])
                .map(|r| map(r.patch, r.domain).map(|p| p.face))
                .collect();
            if let [Some(a), Some(b)] = faces[..] {
                in_no_area += usize::from(a == b && has_no_area(mesh, a as usize));
            }
        }
    }
    (
        [
            c.cracks - in_no_area,
            c.unmapped,
            c.on_base_boundary,
            c.on_non_manifold_edge,
            in_no_area,
        ],
        welded.positions,
    )
}

/// Whether face `f`'s corners all lie on one line (exactly, in the file's coordinates).
fn has_no_area(mesh: &ControlMesh, f: usize) -> bool {
    let p: Vec<[f64; 3]> = mesh
        .face(f)
        .iter()
        .map(|&v| mesh.positions[v as usize])
        .collect();
    let sub = |a: [f64; 3], b: [f64; 3]| [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
    let Some(&d) = p
        .iter()
        .map(|&q| sub(q, p[0]))
        .find(|d| *d != [0.0; 3])
        .as_ref()
    else {
        return true;
    };
    p.iter().all(|&q| {
        let e = sub(q, p[0]);
        let cross = [
            d[1] * e[2] - d[2] * e[1],
            d[2] * e[0] - d[0] * e[2],
            d[0] * e[1] - d[1] * e[0],
        ];
        cross == [0.0; 3]
    })
}

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
fn every_technique_draws_the_non_manifold_shapes_without_cracks() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        let params = FrameParams::uniform(4.0);
        let mut failures = Vec::new();
        for info in techniques::registry() {
            for (name, mesh) in shapes_for(info) {
                let what = format!("{} on {name}", info.id);
                // Doo-Sabin makes a face of every vertex: a vertex of two faces (valence 2, as
                // catmark_val2_nonman has, manifold or not) would make a face of two corners,
                // which its refiner refuses by name.
                if info.id == TechniqueId::DOO_SABIN && name == "catmark_val2_nonman" {
                    let refused = techniques::build(&mut ctx, info.id, &mesh, &Default::default());
                    let e = refused
                        .err()
                        .expect("Doo-Sabin refuses valence 2")
                        .to_string();
                    assert!(e.contains("a face needs at least 3"), "{what}: {e}");
                    println!("{what}: refused by name: {e}");
                    continue;
                }
                let mut t = build(&mut ctx, info, &mesh, name);
                assert!(
                    drawn_pixels(&mut ctx, t.as_mut(), &params) > 0,
                    "{what}: nothing drawn"
                );
                let (classes, rest) = capture(&mut ctx, &capturer, t.as_mut(), &mesh, &params);
                if classes[..2] != [0, 0] {
                    failures.push(format!("{what}: (cracks, unmapped) {:?}", &classes[..2]));
                }
                if info.features.animation {
                    let base = t.base_mesh().expect("an animated technique's base").clone();
                    assert_eq!(base.positions.len(), mesh.positions.len(), "{what}");
                    let moved = Wave::new(&base).at(0.37);
                    t.update_base(0, &moved).expect("animated base");
                    let (moved_classes, positions) =
                        capture(&mut ctx, &capturer, t.as_mut(), &mesh, &params);
                    if moved_classes[..2] != [0, 0] {
                        failures.push(format!("{what}, animated: {:?}", &moved_classes[..2]));
                    }
                    assert_ne!(positions, rest, "{what}: the animated surface moved");
                }
                println!(
                    "{what}: {} cracks; {} open edges on the boundary, {} along non-manifold \
                     edges, {} inside faces of no area",
                    classes[0], classes[2], classes[3], classes[4]
                );
            }
        }
        assert!(failures.is_empty(), "{failures:#?}");
    }
    assert!(gpu.errors().is_empty(), "{:#?}", gpu.errors());
}

/// The largest distance, over the diagonal, of a captured vertex from the exact limit at its
/// own face point.
fn worst_deviation(
    ctx: &mut Context,
    capturer: &Capturer,
    technique: &mut dyn Technique,
    mesh: &ControlMesh,
    scheme: LimitScheme,
) -> f64 {
    let (soup, _) = capturer
        .capture(ctx, &mut *technique, &FrameParams::uniform(4.0), EXTENT)
        .expect("capture");
    let lm = LimitEvaluator::new(mesh, scheme).expect("evaluator");
    let diagonal = mesh.bbox_diagonal();
    let mut worst = 0.0f64;
    for r in &soup.records {
        let p = technique
            .face_point(r.patch, r.domain)
            .unwrap_or_else(|| panic!("vertex {} maps to no base face", r.patch));
        let e = lm
            .evaluate(p.face, p.u as f64, p.v as f64)
            .expect("exact limit");
        for k in 0..3 {
            worst = worst.max((r.position[k] as f64 - e.position[k]).abs() / diagonal);
        }
    }
    worst
}

#[test]
fn meshes_refined_on_the_cpu_are_the_exact_limit_of_the_split() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for name in SHAPES {
            let (mesh, scheme) = shape(name);
            let (id, limit) = match scheme {
                Scheme::Loop => (TechniqueId::CPU, LimitScheme::Loop),
                _ => (TechniqueId::CPU_CATMARK, LimitScheme::CatmullClark),
            };
            let mut t = build(&mut ctx, techniques::info(id), &mesh, name);
            let worst = worst_deviation(&mut ctx, &capturer, t.as_mut(), &mesh, limit);
            println!("{id} on {name}: {worst:.1e} of the diagonal from the exact limit");
            assert!(worst < 1e-5, "{id} on {name}: {worst:e}");
        }
    }
    assert!(gpu.errors().is_empty(), "{:#?}", gpu.errors());
}
