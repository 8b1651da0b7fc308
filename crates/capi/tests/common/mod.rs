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
    let mesh = topology::mesh::obj::parse_obj(&text, "spot").unwrap();
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

/// One of the example C++ hosts under examples/ and the line it prints when all went well.
#[derive(Clone, Copy)]
pub struct Host {
    pub example: &'static str,
    pub done: &'static str,
}

impl Host {
    /// Configures and builds the host against the in-tree CMake package (`Tessera_DIR` and
    /// `TESSERA_LIBRARY`: this test's library) into `target/<profile>/capi-tests/<name>-build`.
    pub fn build_in_tree(&self, name: &str, asan: bool) -> PathBuf {
        let build = profile_dir()
            .join("capi-tests")
            .join(format!("{name}-build"));
        let source = repo().join("examples").join(self.example);
        // A build directory configured from another checkout (a copied target directory)
        // cannot be reconfigured from this one: start it afresh.
        let home = source.canonicalize().unwrap();
        let cache = std::fs::read_to_string(build.join("CMakeCache.txt")).unwrap_or_default();
        let configured_here = cache
            .lines()
            .filter_map(|l| l.strip_prefix("CMAKE_HOME_DIRECTORY:INTERNAL="))
            .any(|d| Path::new(d).canonicalize().ok().as_deref() == Some(home.as_path()));
        if !cache.is_empty() && !configured_here {
            std::fs::remove_dir_all(&build).unwrap();
        }
        run(Command::new("cmake")
            .arg("-S")
            .arg(&source)
            .arg("-B")
            .arg(&build)
            .arg(format!("-DTessera_DIR={}", repo().join("cmake").display()))
            .arg(format!("-DTESSERA_LIBRARY={}", library().display()))
            .arg(format!(
                "-DTESSERA_HOST_ASAN={}",
                if asan { "ON" } else { "OFF" }
            )));
        run(Command::new("cmake").arg("--build").arg(&build));
        build.join(self.example)
    }

    /// Builds the host (as [`Self::build_in_tree`]) and runs it with its misuse checks into a
    /// fresh `capi-tests/<out>` directory, which it returns.
    pub fn run_in_tree(&self, out: &str, asan: bool) -> PathBuf {
        let exe = self.build_in_tree(&format!("{}-{out}", self.example), asan);
        let dir = scratch(out);
        let text = run(Command::new(&exe).arg(&dir).arg("misuse"));
        assert!(text.contains(self.done), "{text}");
        dir
    }
}

/// A standalone context with synchronization validation on (its messages are counted by
/// `tessera_context_validation_errors`, which the tests check).
pub fn standalone_context() -> *mut tessera_capi::TesseraContext {
    use tessera_capi::*;
    let desc = TesseraStandaloneDesc {
        device: std::ptr::null(),
        validation: TESSERA_VALIDATION_SYNCHRONIZATION,
        ..Default::default()
    };
    let mut ctx = std::ptr::null_mut();
    // SAFETY: `desc` and `ctx` are live locals of the types the call reads and writes.
    let status = unsafe { tessera_context_create_standalone(&desc, &mut ctx) };
    assert_eq!(status, TesseraStatus::Ok);
    ctx
}

/// Captures spot drawn by technique `name` on a standalone context through the C ABI, with
/// the surface and frame descriptions the example hosts use (defaults, 160×120, 4 uniform
/// segments), into `dir/<name>.standalone.obj`; returns the file and the report.
pub fn standalone_capture(name: &str, dir: &Path) -> (Vec<u8>, tessera_capi::TesseraCaptureReport) {
    use tessera_capi::*;
    let technique = match name {
        "flat" => TESSERA_TECHNIQUE_FLAT,
        "phong" => TESSERA_TECHNIQUE_PHONG,
        "pn" => TESSERA_TECHNIQUE_PN,
        "bft" => TESSERA_TECHNIQUE_BFT,
        "adaptive" => TESSERA_TECHNIQUE_ADAPTIVE,
        "gregory" => TESSERA_TECHNIQUE_GREGORY,
        "acc" => TESSERA_TECHNIQUE_ACC,
        other => panic!("no technique {other}"),
    };
    let path = dir.join(format!("{name}.standalone.obj"));
    let c_path = std::ffi::CString::new(path.to_str().unwrap()).unwrap();
    let desc = TesseraStandaloneDesc {
        validation: TESSERA_VALIDATION_SYNCHRONIZATION,
        pipeline_cache: TESSERA_PIPELINE_CACHE_OFF,
        ..Default::default()
    };
    let mut frame = frame_desc(160, 120);
    frame.factor = 4.0;
    let sdesc = surface_desc(technique);
    let mut report = tessera_capi::TesseraCaptureReport::default();
    // SAFETY: every pointer addresses a live local of the type the call reads or writes.
    unsafe {
        let mut ctx = std::ptr::null_mut();
        assert_eq!(
            tessera_context_create_standalone(&desc, &mut ctx),
            TesseraStatus::Ok
        );
        let mut surface = std::ptr::null_mut();
        assert_eq!(
            tessera_surface_create_obj(
                ctx,
                std::ptr::null(),
                0,
                std::ptr::null(),
                &sdesc,
                &mut surface
            ),
            TesseraStatus::Ok
        );
        let status = tessera_capture(ctx, surface, &frame, c_path.as_ptr(), &mut report);
        assert_eq!(status, TesseraStatus::Ok, "{name}");
        let mut errors = 1;
        assert_eq!(
            tessera_context_validation_errors(ctx, &mut errors),
            TesseraStatus::Ok
        );
        assert_eq!(errors, 0, "{name}: validation errors");
        assert_eq!(tessera_context_destroy(ctx), TesseraStatus::Ok);
    }
    (std::fs::read(&path).unwrap(), report)
}
