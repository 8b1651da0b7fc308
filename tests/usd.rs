//! USD input on the GPU: every technique of the registry, on every draw path it declares,
//! captures bit-identical triangles from a `.usda` file and from its hand-written OBJ twin
//! (`tests/data/usd/`: a creased, cornered, holed cube with indexed face-varying st; two
//! transformed meshes merged; a Loop octahedron; a left-handed mesh). A technique that refuses
//! a mesh must refuse both files with the same message.
mod common;

use common::Gpu;
use tessera::tess::techniques::{self, TechniqueInfo};
use tessera::tess::{BuildOptions, Capturer, Context, DrawPath, FrameParams, PipelineChoice};
use tessera::topology::mesh::usd::load_usd;
use tessera::topology::{load_obj, ControlMesh};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 64,
    height: 64,
};

fn choice(path: DrawPath) -> PipelineChoice {
    match path {
        DrawPath::Tessellation => PipelineChoice::Tessellation,
        DrawPath::Pattern => PipelineChoice::Pattern,
        DrawPath::VertexStage => PipelineChoice::Auto,
    }
}

/// The captured corners of `mesh` drawn by `info` on `path` as bits, or the build's error.
fn captured_bits(
    ctx: &mut Context,
    capturer: &Capturer,
    info: &TechniqueInfo,
    mesh: &ControlMesh,
    path: DrawPath,
) -> Result<Vec<[u32; 10]>, String> {
    let options = BuildOptions {
        name: "usd".into(),
        tangents: info.features.geometric_normals,
        pipeline: choice(path),
        ..BuildOptions::default()
    };
    let mut t = techniques::build(ctx, info.id, mesh, &options)
        .map_err(|e| e.to_string())?
        .technique;
    let (soup, _) = capturer
        .capture(ctx, t.as_mut(), &FrameParams::uniform(4.0), EXTENT)
        .expect("capture");
    Ok(soup
        .records
        .iter()
        .map(|r| {
            let f = [
                r.position[0],
                r.position[1],
                r.position[2],
                r.normal[0],
                r.normal[1],
                r.normal[2],
                r.domain[0],
                r.domain[1],
            ];
            let mut bits = [0u32; 10];
            for (b, x) in bits.iter_mut().zip(f) {
                *b = x.to_bits();
            }
            bits[8] = r.patch;
            bits[9] = r.flags;
            bits
        })
        .collect())
}

#[test]
fn every_technique_captures_the_usd_file_as_its_obj_twin() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        let mut compared = 0;
        for stem in ["cube_tags", "two_meshes", "loop_octahedron", "left_handed"] {
            let usd = load_usd(common::data(&format!("tests/data/usd/{stem}.usda"))).unwrap();
            let obj = load_obj(common::data(&format!("tests/data/usd/{stem}.obj"))).unwrap();
            for info in techniques::registry() {
                for &path in info.features.paths {
                    let what = format!("{} on {stem}, {path} path", info.id);
                    let a = captured_bits(&mut ctx, &capturer, info, &usd, path);
                    let b = captured_bits(&mut ctx, &capturer, info, &obj, path);
                    match (a, b) {
                        (Ok(a), Ok(b)) => {
                            assert!(!a.is_empty(), "{what}: nothing captured");
                            assert!(a == b, "{what}: the USD and OBJ captures differ");
                            compared += 1;
                            println!("{what}: {} corners, bit-identical", a.len());
                        }
                        (Err(a), Err(b)) => {
                            assert_eq!(a, b, "{what}: refused differently");
                            println!("{what}: refused both ({a})");
                        }
                        (a, b) => panic!("{what}: USD {:?} vs OBJ {:?}", a.err(), b.err()),
                    }
                }
            }
        }
        assert!(compared > 0);
    }
    assert!(gpu.errors().is_empty(), "{:#?}", gpu.errors());
}

/// Pixar's test files (`tests/data/usd/real/`): every technique draws them (captures
/// triangles) or refuses them by name, validation clean.
#[test]
fn every_technique_draws_pixar_test_files() {
    let gpu = Gpu::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        let mut drawn = 0;
        for name in ["indexedTextureCoordinates.def", "ring"] {
            let path = common::data(&format!("tests/data/usd/real/{name}.usda"));
            let mesh = load_usd(path).unwrap();
            for info in techniques::registry() {
                for &path in info.features.paths {
                    let what = format!("{} on {name}, {path} path", info.id);
                    match captured_bits(&mut ctx, &capturer, info, &mesh, path) {
                        Ok(corners) => {
                            assert!(!corners.is_empty(), "{what}: nothing captured");
                            drawn += 1;
                        }
                        Err(e) => {
                            assert!(!e.is_empty(), "{what}: an unnamed refusal");
                            println!("{what}: refused ({e})");
                        }
                    }
                }
            }
        }
        assert!(drawn > 0);
    }
    assert!(gpu.errors().is_empty(), "{:#?}", gpu.errors());
}
