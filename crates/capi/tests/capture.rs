//! Capture through the C ABI: what the GPU's tessellation emitted for one frame, written as
//! OBJ (as `tessera export` writes it), one face per reported triangle.
mod common;
use common::standalone_context;

use std::ffi::CString;
use std::ptr::{null, null_mut};
use tessera_capi::*;

#[test]
fn capture_writes_the_triangles_the_gpu_drew() {
    let dir = std::env::temp_dir().join(format!("tessera-capi-capture-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("spot_flat.obj");
    let c_path = CString::new(path.to_str().unwrap()).unwrap();
    // SAFETY: every pointer is null or addresses a live local of the type the call reads.
    unsafe {
        let ctx = standalone_context();
        let sdesc = common::surface_desc(TESSERA_TECHNIQUE_FLAT);
        let mut surface = null_mut();
        assert_eq!(
            tessera_surface_create_obj(ctx, null(), 0, null(), &sdesc, &mut surface),
            TesseraStatus::Ok
        );
        let mut frame = common::frame_desc(640, 480);
        frame.factor = 2.0;
        let mut triangles = 0u64;
        let status = tessera_capture_obj(ctx, surface, &frame, c_path.as_ptr(), &mut triangles);
        let mut buf = vec![0 as std::ffi::c_char; 512];
        tessera_last_error(ctx, buf.as_mut_ptr(), buf.len());
        assert_eq!(
            status,
            TesseraStatus::Ok,
            "{:?}",
            std::ffi::CStr::from_ptr(buf.as_ptr())
        );
        let mut vertices = 0usize;
        assert_eq!(
            tessera_surface_info(ctx, surface, &mut vertices, null_mut(), null_mut()),
            TesseraStatus::Ok
        );
        let text = std::fs::read_to_string(&path).unwrap();
        let faces = text.lines().filter(|l| l.starts_with("f ")).count() as u64;
        assert_eq!(faces, triangles, "OBJ faces and the reported count");
        // spot's control mesh is mostly quads (2·2² triangles each at 2 segments), plus a few
        // triangles and fan-triangulated pentagons that add more.
        let text_mesh = std::fs::read_to_string(concat!(
            env!("CARGO_MANIFEST_DIR"),
            "/../../assets/spot_control_mesh.obj"
        ))
        .unwrap();
        let quads = text_mesh
            .lines()
            .filter(|l| l.starts_with("f ") && l.split_whitespace().count() == 5)
            .count() as u64;
        assert!(
            triangles > quads * 8,
            "{triangles} triangles for {quads} quads"
        );
        let mut errors = 1;
        assert_eq!(
            tessera_context_validation_errors(ctx, &mut errors),
            TesseraStatus::Ok
        );
        assert_eq!(errors, 0);
        assert_eq!(tessera_context_destroy(ctx), TesseraStatus::Ok);
    }
    let _ = std::fs::remove_dir_all(&dir);
}

/// `TesseraSurfaceDesc.pipeline`: flat through refinement patterns captures what the
/// tessellation path captures (the same triangle count, bit-identical vertices welded into the
/// same OBJ); a technique without that path, and a value that names no path, are refused.
#[test]
fn the_pipeline_choice_draws_patterns_or_is_refused() {
    let dir = std::env::temp_dir().join(format!("tessera-capi-pipeline-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    // SAFETY: every pointer is null or addresses a live local of the type the call reads.
    unsafe {
        let ctx = standalone_context();
        let mut sdesc = common::surface_desc(TESSERA_TECHNIQUE_AUTO);
        assert_eq!(sdesc.pipeline, TESSERA_PIPELINE_AUTO);
        let mut frame = common::frame_desc(640, 480);
        frame.factor = 3.0;
        let mut objs = Vec::new();
        for (pipeline, name) in [
            (TESSERA_PIPELINE_TESSELLATION, "tessellation.obj"),
            (TESSERA_PIPELINE_PATTERN, "pattern.obj"),
        ] {
            sdesc.technique = TESSERA_TECHNIQUE_PN;
            sdesc.pipeline = pipeline;
            let mut surface = null_mut();
            assert_eq!(
                tessera_surface_create_obj(ctx, null(), 0, null(), &sdesc, &mut surface),
                TesseraStatus::Ok
            );
            let path = dir.join(name);
            let c_path = CString::new(path.to_str().unwrap()).unwrap();
            let mut triangles = 0u64;
            assert_eq!(
                tessera_capture_obj(ctx, surface, &frame, c_path.as_ptr(), &mut triangles),
                TesseraStatus::Ok
            );
            assert!(triangles > 0);
            objs.push(std::fs::read_to_string(&path).unwrap());
            assert_eq!(tessera_surface_destroy(ctx, surface), TesseraStatus::Ok);
        }
        fn vertices(t: &str) -> Vec<&str> {
            let mut v: Vec<&str> = t.lines().filter(|l| l.starts_with("v ")).collect();
            v.sort_unstable();
            v
        }
        assert_eq!(
            vertices(&objs[0]),
            vertices(&objs[1]),
            "the two paths' vertices"
        );
        for (technique, pipeline, status) in [
            (
                TESSERA_TECHNIQUE_CPU_CATMARK,
                TESSERA_PIPELINE_PATTERN,
                TesseraStatus::Unsupported,
            ),
            (TESSERA_TECHNIQUE_FLAT, 7, TesseraStatus::InvalidArgument),
        ] {
            sdesc.technique = technique;
            sdesc.pipeline = pipeline;
            let mut surface = null_mut();
            assert_eq!(
                tessera_surface_create_obj(ctx, null(), 0, null(), &sdesc, &mut surface),
                status
            );
            let mut buf = vec![0 as std::ffi::c_char; 512];
            tessera_last_error(ctx, buf.as_mut_ptr(), buf.len());
            let message = std::ffi::CStr::from_ptr(buf.as_ptr()).to_string_lossy();
            assert!(message.contains("pipeline"), "{message}");
        }
        let mut errors = 1;
        assert_eq!(
            tessera_context_validation_errors(ctx, &mut errors),
            TesseraStatus::Ok
        );
        assert_eq!(errors, 0);
        assert_eq!(tessera_context_destroy(ctx), TesseraStatus::Ok);
    }
    let _ = std::fs::remove_dir_all(&dir);
}
