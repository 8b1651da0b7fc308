//! Shared by the C ABI's tests: where cargo put the library, how to build C/C++ against it,
//! and the Rust-side reference render the C and C++ images are compared with.
#![allow(dead_code)]
use std::path::{Path, PathBuf};
use std::process::Command;

/// `target/<profile>`: the directory holding this test's `deps/` (and the cdylib).
pub fn profile_dir() -> PathBuf {
    let exe = std::env::current_exe().expect("test executable path");
    exe.parent()
        .and_then(Path::parent)
        .expect("target/<profile>/deps/<test>")
        .to_path_buf()
}

/// The cdylib built by this very `cargo test`: the integration tests depend on the library
/// unit, which cargo compiles once with all of its crate types, so `deps/` holds the cdylib of
/// the same build. (Asking cargo for it again from here resolved the workspace's features
/// without the dev-dependencies and rebuilt half the dependency graph on a cold CI machine:
/// six minutes.)
pub fn library() -> PathBuf {
    let lib = profile_dir().join("deps").join("libtessera_capi.so");
    assert!(
        lib.exists(),
        "{} was not built by this cargo test run",
        lib.display()
    );
    lib
}

pub fn repo() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("../..")
}

/// A fresh directory under the target directory (never the source tree).
pub fn scratch(name: &str) -> PathBuf {
    let d = profile_dir().join("capi-tests").join(name);
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Runs `cmd`, failing the test with its output when it fails.
pub fn run(cmd: &mut Command) -> String {
    let out = cmd
        .output()
        .unwrap_or_else(|e| panic!("{cmd:?}: cannot start: {e}"));
    let text = format!(
        "{}{}",
        String::from_utf8_lossy(&out.stdout),
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(
        out.status.success(),
        "{cmd:?} failed ({}):\n{text}",
        out.status
    );
    text
}

/// The golden tolerance of the root crate's tests/golden.rs: a pixel differs when a channel
/// moves by more than 24/255; images match when at most 0.5% of pixels differ.
pub fn differing_fraction(a: &[u8], b: &[u8], pixels: usize) -> f64 {
    assert_eq!(a.len(), b.len());
    let n = a
        .chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 24))
        .count();
    n as f64 / pixels as f64
}
pub const TOLERANCE: f64 = 0.005;

/// Renders spot (the embedded mesh) with `technique` through tess directly, as `tessera
/// render --method NAME --level 4` does, on a validated device of our own.
pub fn reference(technique: tess::TechniqueId, width: u32, height: u32) -> Vec<u8> {
    use vk_core::{Device, DeviceDesc, Instance, InstanceDesc, Validation};
    let instance = Instance::new(&InstanceDesc {
        app_name: "tessera-capi reference".into(),
        validation: Validation::Synchronization,
        surface_extensions: vec![],
    })
    .expect("Vulkan instance");
    let device = Device::new(&instance, &DeviceDesc::default(), &[]).expect("device");
    let text = std::fs::read_to_string(repo().join("assets/spot_control_mesh.obj")).unwrap();
    let mesh = topology::parse_obj(&text, "spot").unwrap();
    let pixels = {
        let mut ctx = tess::Context::offscreen(&device).unwrap();
        let mut built = tess::build(&mut ctx, technique, &mesh, &tess::BuildOptions::default())
            .unwrap_or_else(|e| panic!("{technique}: {e}"));
        let params = tess::FrameParams::uniform(4.0);
        ctx.render_offscreen(
            built.technique.as_mut(),
            &params,
            vk_core::vk::Extent2D { width, height },
        )
        .unwrap()
        .pixels
    };
    drop(device);
    assert_eq!(
        instance.messages().error_count(),
        0,
        "{:?}",
        instance.messages().error_messages()
    );
    pixels
}

/// The techniques the C++ host draws.
pub const HOST_TECHNIQUES: &[(&str, tess::TechniqueId)] = &[
    ("flat", tess::TechniqueId::FLAT),
    ("phong", tess::TechniqueId::PHONG),
    ("pn", tess::TechniqueId::PN),
    ("bft", tess::TechniqueId::BFT),
    ("adaptive", tess::TechniqueId::ADAPTIVE),
];

/// Every technique of the C ABI (the C program draws them all).
pub const ALL_TECHNIQUES: &[(&str, tess::TechniqueId)] = &[
    ("flat", tess::TechniqueId::FLAT),
    ("phong", tess::TechniqueId::PHONG),
    ("pn", tess::TechniqueId::PN),
    ("bft", tess::TechniqueId::BFT),
    ("adaptive", tess::TechniqueId::ADAPTIVE),
    ("gregory", tess::TechniqueId::GREGORY),
    ("acc", tess::TechniqueId::ACC),
];

/// Each of `techniques`' `<name>.rgba` in `dir` (160×120, written by a C or C++ host) against
/// the Rust-side render of the same view, within [`TOLERANCE`].
pub fn compare_with_rust_render(dir: &Path, techniques: &[(&str, tess::TechniqueId)]) {
    for &(name, id) in techniques {
        let host = std::fs::read(dir.join(format!("{name}.rgba"))).unwrap();
        let d = differing_fraction(&host, &reference(id, 160, 120), 160 * 120);
        eprintln!("{name}: {d:.5} of pixels differ from the Rust-side render");
        assert!(d <= TOLERANCE, "{name}: {d:.5} of pixels differ");
    }
}

/// `tessera_surface_desc_default` with `technique`.
pub fn surface_desc(technique: tessera_capi::TesseraTechnique) -> tessera_capi::TesseraSurfaceDesc {
    let mut d = std::mem::MaybeUninit::uninit();
    // SAFETY: `d` is writable and filled by the call.
    let status = unsafe { tessera_capi::tessera_surface_desc_default(d.as_mut_ptr()) };
    assert_eq!(status, tessera_capi::TesseraStatus::Ok);
    // SAFETY: initialized above.
    let mut d = unsafe { d.assume_init() };
    d.technique = technique;
    d
}

/// `tessera_frame_desc_default` at `width` × `height`.
pub fn frame_desc(width: u32, height: u32) -> tessera_capi::TesseraFrameDesc {
    let mut f = std::mem::MaybeUninit::uninit();
    // SAFETY: `f` is writable and filled by the call.
    let status = unsafe { tessera_capi::tessera_frame_desc_default(f.as_mut_ptr()) };
    assert_eq!(status, tessera_capi::TesseraStatus::Ok);
    // SAFETY: initialized above.
    let mut f = unsafe { f.assume_init() };
    f.width = width;
    f.height = height;
    f
}
