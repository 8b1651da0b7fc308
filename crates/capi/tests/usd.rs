//! Mesh files through the C ABI (`tessera_surface_create_file`): a `.usda` and its OBJ twin
//! (`tests/data/usd/`) build surfaces whose captures are the same OBJ text; a bad USD file and
//! a NULL path are refused by status, the message naming the file, the prim and the attribute.
mod common;
use common::standalone_context;

use std::ffi::{CStr, CString};
use std::ptr::{null, null_mut};
use tessera_capi::*;

fn last_error(ctx: *mut TesseraContext) -> String {
    let mut buf = vec![0 as std::ffi::c_char; 1024];
    // SAFETY: `buf` is writable for its length.
    unsafe {
        tessera_last_error(ctx, buf.as_mut_ptr(), buf.len());
        CStr::from_ptr(buf.as_ptr()).to_string_lossy().into_owned()
    }
}

/// The OBJ text `tessera_capture_obj` writes for the surface built from `mesh`.
fn captured(ctx: *mut TesseraContext, mesh: &std::path::Path, out: &std::path::Path) -> String {
    let c_mesh = CString::new(mesh.to_str().unwrap()).unwrap();
    let c_out = CString::new(out.to_str().unwrap()).unwrap();
    // SAFETY: every pointer is null or addresses a live local of the type the call reads.
    unsafe {
        let sdesc = common::surface_desc(TESSERA_TECHNIQUE_ADAPTIVE);
        let mut surface = null_mut();
        let status = tessera_surface_create_file(ctx, c_mesh.as_ptr(), &sdesc, &mut surface);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
        let mut frame = common::frame_desc(64, 64);
        frame.factor = 2.0;
        let mut triangles = 0u64;
        let status = tessera_capture_obj(ctx, surface, &frame, c_out.as_ptr(), &mut triangles);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
        assert!(triangles > 0);
        assert_eq!(tessera_surface_destroy(ctx, surface), TesseraStatus::Ok);
    }
    std::fs::read_to_string(out).unwrap()
}

#[test]
fn a_usd_file_and_its_obj_twin_capture_the_same() {
    let dir = common::scratch("usd");
    let data = common::repo().join("tests/data/usd");
    let ctx = standalone_context();
    let usd = captured(ctx, &data.join("cube_tags.usda"), &dir.join("usd.obj"));
    let obj = captured(ctx, &data.join("cube_tags.obj"), &dir.join("obj.obj"));
    assert!(
        usd == obj,
        "the captures of cube_tags.usda and cube_tags.obj differ"
    );
    let mut errors = 1;
    // SAFETY: `errors` is a live local; the context is live until destroyed.
    unsafe {
        assert_eq!(
            tessera_context_validation_errors(ctx, &mut errors),
            TesseraStatus::Ok
        );
        assert_eq!(errors, 0);
        assert_eq!(tessera_context_destroy(ctx), TesseraStatus::Ok);
    }
}

#[test]
fn bad_usd_and_null_path_are_refused_by_status() {
    let dir = common::scratch("usd-bad");
    let bad = dir.join("bad.usda");
    std::fs::write(
        &bad,
        "#usda 1.0\ndef Mesh \"M\" {\n int[] faceVertexCounts = [3]\n int[] faceVertexIndices = \
         [0, 1, 5]\n point3f[] points = [(0, 0, 0), (1, 0, 0), (0, 1, 0)]\n}\n",
    )
    .unwrap();
    let c_bad = CString::new(bad.to_str().unwrap()).unwrap();
    let ctx = standalone_context();
    // SAFETY: every pointer is null or addresses a live local of the type the call reads.
    unsafe {
        let mut surface = null_mut();
        let status = tessera_surface_create_file(ctx, c_bad.as_ptr(), null(), &mut surface);
        assert_eq!(status, TesseraStatus::IndexOutOfRange);
        assert!(surface.is_null());
        let message = last_error(ctx);
        assert!(
            message.contains(&format!("{}: /M.faceVertexIndices: ", bad.display())),
            "{message}"
        );
        let status = tessera_surface_create_file(ctx, null(), null(), &mut surface);
        assert_eq!(status, TesseraStatus::InvalidArgument);
        assert_eq!(tessera_context_destroy(ctx), TesseraStatus::Ok);
    }
}
