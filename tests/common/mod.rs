//! Shared GPU test harness: a device with the validation layer forced on, synchronization
//! validation included (missing barriers between the compute pre-passes, draws, uploads and
//! capture copies are errors too), and a guard that
//! fails the test on any error-severity validation message (checked when the guard drops, after
//! every resource is gone, so leaks reported at device destruction count too).
#![allow(dead_code)]
use std::sync::Arc;
use tessera::vk_core::{Device, DeviceDesc, Instance, InstanceDesc, Validation};

pub struct Gpu {
    pub device: Option<Device>,
    pub instance: Arc<Instance>,
}

impl Gpu {
    pub fn new() -> Gpu {
        Self::with(&DeviceDesc::default())
    }

    /// A device made from `desc` (e.g. with optional features turned off).
    pub fn with(desc: &DeviceDesc) -> Gpu {
        let _ = env_logger_init();
        let instance = Instance::new(&InstanceDesc {
            app_name: "tessera-tests".into(),
            validation: Validation::Synchronization,
            surface_extensions: vec![],
        })
        .expect("Vulkan instance (install mesa-vulkan-drivers and vulkan-validationlayers)");
        assert_eq!(
            instance.validation(),
            Validation::Synchronization,
            "tests need VK_LAYER_KHRONOS_validation (package vulkan-validationlayers)"
        );
        let device = Device::new(&instance, desc, &[]).expect("a Vulkan device with tessellation");
        Gpu {
            device: Some(device),
            instance,
        }
    }

    pub fn device(&self) -> &Device {
        self.device.as_ref().expect("device alive")
    }

    pub fn errors(&self) -> Vec<String> {
        self.instance.messages().error_messages()
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        if let Some(d) = self.device.take() {
            let leaked = d.allocated_bytes();
            drop(d);
            if !std::thread::panicking() {
                assert_eq!(
                    leaked, 0,
                    "gpu-allocator still holds {leaked} bytes at the end of the test"
                );
            }
        }
        let n = self.instance.messages().error_count();
        if !std::thread::panicking() {
            assert_eq!(
                n,
                0,
                "validation errors: {:#?}",
                self.instance.messages().error_messages()
            );
        }
    }
}

fn env_logger_init() -> Result<(), ()> {
    Ok(())
}

pub fn data(path: &str) -> std::path::PathBuf {
    std::path::Path::new(env!("CARGO_MANIFEST_DIR")).join(path)
}

/// The OpenSubdiv shapes a whole-set test takes: those of the folder `var` names (OpenSubdiv's
/// whole set, say), else tests/data's; and whether it is another folder (where shapes may be
/// refused, or too large to capture).
pub fn shapes_dir(var: &str) -> (std::path::PathBuf, bool) {
    match std::env::var_os(var) {
        Some(d) => (d.into(), true),
        None => (data("tests/data/opensubdiv/shapes"), false),
    }
}

/// Stems of the `prefix*.obj` files in `dir`, sorted, hierarchical edits aside (Tessera does
/// not read them).
pub fn shape_names(dir: &std::path::Path, prefix: &str) -> Vec<String> {
    let mut names: Vec<String> = std::fs::read_dir(dir)
        .unwrap_or_else(|e| panic!("shapes in {dir:?}: {e}"))
        .filter_map(|e| {
            let n = e.ok()?.file_name().to_string_lossy().into_owned();
            let stem = n.strip_suffix(".obj")?.to_string();
            (stem.starts_with(prefix) && !stem.contains("hedit")).then_some(stem)
        })
        .collect();
    names.sort();
    names
}

/// (cracks, unmapped) of one capture of `t` drawing `mesh`: its open edges after welding by
/// bits, classified against the base mesh.
pub fn cracks(
    t: &dyn tessera::tess::Technique,
    soup: &tessera::tess::capture::CapturedSoup,
    mesh: &tessera::topology::ControlMesh,
) -> (usize, usize) {
    let welded = soup.weld().expect("weld");
    let report = welded.open_edges();
    let map = |p: u32, d: [f32; 2]| t.face_point(p, d);
    let c = tessera::tess::capture::classify_open_edges(soup, &welded, &report, &map, mesh);
    (c.cracks, c.unmapped)
}

/// Whether `error`, building a Doo-Sabin technique for `mesh`, is the refusal its tags earn:
/// it names sharpness or a hole, and the mesh has crease, corner or hole tags.
pub fn refused_for_doo_sabin_tags(mesh: &tessera::topology::ControlMesh, error: &str) -> bool {
    let tagged = [mesh.creases.len(), mesh.corners.len(), mesh.holes.len()] != [0; 3];
    tagged && ["sharpness", "hole"].iter().any(|w| error.contains(w))
}

/// The verdict of a whole-set test: every refusal is printed, and allowed only in `other`'s
/// folder (a refusal names what it refuses; nothing in tests/data is refused); every failure
/// fails the test.
pub fn whole_set_verdict(refused: &[String], other: bool, failures: &[String]) {
    for r in refused {
        println!("refused: {r}");
        assert!(other, "refused: {r}");
    }
    assert!(failures.is_empty(), "{failures:#?}");
}

/// Builds technique `id` for `mesh` on `ctx` with default options (tangent tables included,
/// so geometric normals can be drawn), on the tessellation path where the technique has one:
/// these tests check what the tessellator emits. The refinement-pattern path emits the same
/// triangles and bits (`tests/patterns.rs`) and has its own tests.
pub fn build(
    ctx: &mut tessera::tess::Context,
    id: tessera::tess::TechniqueId,
    mesh: &tessera::topology::ControlMesh,
) -> Box<dyn tessera::tess::Technique> {
    build_with(ctx, id, mesh, 5, true)
}

/// [`build`] with a table level and tangent choice.
pub fn build_with(
    ctx: &mut tessera::tess::Context,
    id: tessera::tess::TechniqueId,
    mesh: &tessera::topology::ControlMesh,
    table_level: u32,
    tangents: bool,
) -> Box<dyn tessera::tess::Technique> {
    tessera::tess::build(
        ctx,
        id,
        mesh,
        &tessera::tess::BuildOptions {
            name: "test mesh".into(),
            table_level,
            tangents,
            pipeline: tessellation_where_drawn(id),
            ..Default::default()
        },
    )
    .unwrap_or_else(|e| panic!("building {id}: {e}"))
    .technique
}

/// `--pipeline tessellation` for a technique that draws through the tessellation stage, else
/// `auto` (the meshes refined before the draw).
pub fn tessellation_where_drawn(id: tessera::tess::TechniqueId) -> tessera::tess::PipelineChoice {
    let paths = tessera::tess::techniques::info(id).features.paths;
    if paths.contains(&tessera::tess::DrawPath::Tessellation) {
        tessera::tess::PipelineChoice::Tessellation
    } else {
        tessera::tess::PipelineChoice::Auto
    }
}

/// Faces of a strip of `k` quads over `2k + 2` vertices laid out in pairs (bottom, top), or of
/// its `2k` triangles when `triangles`.
pub fn strip_faces(k: u32, triangles: bool) -> Vec<Vec<u32>> {
    let mut faces = Vec::new();
    for i in 0..k {
        let (a, b, c, d) = (2 * i, 2 * i + 2, 2 * i + 3, 2 * i + 1);
        if triangles {
            faces.push(vec![a, b, c]);
            faces.push(vec![a, c, d]);
        } else {
            faces.push(vec![a, b, c, d]);
        }
    }
    faces
}

/// Gives `mesh` a continuous texture layout curved in its positions, one value per vertex (the
/// layout's topology is the mesh's): `(x + 0.3 y², y − 0.2 x² + 0.1 z)`.
pub fn with_curved_layout(mesh: &mut tessera::topology::ControlMesh) {
    let uv = |p: [f64; 3]| {
        [
            p[0] + 0.3 * p[1] * p[1],
            p[1] - 0.2 * p[0] * p[0] + 0.1 * p[2],
        ]
    };
    let uvs = mesh
        .face_vertices
        .iter()
        .map(|&v| uv(mesh.positions[v as usize]));
    mesh.uvs = Some(uvs.collect());
    mesh.uv_indices = Some(mesh.face_vertices.clone());
}

/// The mesh with its (continuous) texture coordinates as positions `(u, v, 0)`: under
/// face-varying mode `none` its limit is the texture coordinates' limit.
pub fn uvs_as_positions(mesh: &tessera::topology::ControlMesh) -> tessera::topology::ControlMesh {
    let mut out = mesh.clone();
    let uvs = mesh.uvs.as_ref().expect("uvs");
    for (c, &v) in mesh.face_vertices.iter().enumerate() {
        out.positions[v as usize] = [uvs[c][0], uvs[c][1], 0.0];
    }
    (out.uvs, out.uv_indices) = (None, None);
    out
}
