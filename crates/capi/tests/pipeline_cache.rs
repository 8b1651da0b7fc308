//! The pipeline cache of C ABI contexts: kept in the directory the descriptor names (one file
//! per device and driver build, whose header names that device), not written when it is off,
//! and bad settings refused with their codes.
mod common;
use std::ffi::CString;
use std::ptr::{null, null_mut};
use tessera_capi::*;

/// Creates a standalone context with `desc`, builds and renders one surface, destroys it all.
fn render_once(desc: &TesseraStandaloneDesc) {
    let sdesc = common::surface_desc(TESSERA_TECHNIQUE_ADAPTIVE);
    let frame = common::frame_desc(32, 24);
    let mut pixels = vec![0u8; 32 * 24 * 4];
    // SAFETY: every pointer addresses a live local of the type the call reads or writes.
    unsafe {
        let mut ctx = null_mut();
        assert_eq!(
            tessera_context_create_standalone(desc, &mut ctx),
            TesseraStatus::Ok
        );
        let mut s = null_mut();
        assert_eq!(
            tessera_surface_create_obj(ctx, null(), 0, null(), &sdesc, &mut s),
            TesseraStatus::Ok
        );
        assert_eq!(
            tessera_render(ctx, s, &frame, pixels.as_mut_ptr(), pixels.len()),
            TesseraStatus::Ok
        );
        assert_eq!(tessera_context_destroy(ctx), TesseraStatus::Ok);
    }
}

#[test]
fn contexts_keep_their_pipeline_cache_where_they_are_told() {
    let dir = common::scratch("capi-pipeline-cache");
    let c_dir = CString::new(dir.to_str().unwrap()).unwrap();
    let desc = TesseraStandaloneDesc {
        validation: TESSERA_VALIDATION_SYNCHRONIZATION,
        pipeline_cache_dir: c_dir.as_ptr(),
        ..Default::default()
    };
    render_once(&desc);
    let files: Vec<_> = std::fs::read_dir(&dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    assert_eq!(files.len(), 1, "{files:?}");
    let data = std::fs::read(&files[0]).unwrap();
    // VkPipelineCacheHeaderVersionOne: 32 bytes, version 1, then vendor and device ids, which
    // the file name repeats.
    assert!(data.len() >= 32);
    assert_eq!(u32::from_le_bytes(data[4..8].try_into().unwrap()), 1);
    let vendor = u32::from_le_bytes(data[8..12].try_into().unwrap());
    let device = u32::from_le_bytes(data[12..16].try_into().unwrap());
    let name = files[0].file_name().unwrap().to_str().unwrap().to_owned();
    assert!(
        name.starts_with(&format!("{vendor:04x}-{device:04x}-")),
        "{name}"
    );
    // A second run reads it (and leaves one file).
    render_once(&desc);
    assert_eq!(std::fs::read_dir(&dir).unwrap().count(), 1);

    // Off: nothing written.
    let off = common::scratch("capi-pipeline-cache-off");
    let c_off = CString::new(off.to_str().unwrap()).unwrap();
    render_once(&TesseraStandaloneDesc {
        pipeline_cache: TESSERA_PIPELINE_CACHE_OFF,
        pipeline_cache_dir: c_off.as_ptr(),
        ..desc
    });
    assert_eq!(std::fs::read_dir(&off).unwrap().count(), 0);
}

#[test]
fn bad_pipeline_cache_settings_are_refused() {
    let empty = CString::new("").unwrap();
    for (desc, needle) in [
        (
            TesseraStandaloneDesc {
                pipeline_cache: 7,
                ..Default::default()
            },
            "pipeline_cache 7",
        ),
        (
            TesseraStandaloneDesc {
                pipeline_cache_dir: empty.as_ptr(),
                ..Default::default()
            },
            "pipeline_cache_dir is empty",
        ),
    ] {
        let mut ctx = null_mut();
        // SAFETY: `desc` and `ctx` are live locals.
        let status = unsafe { tessera_context_create_standalone(&desc, &mut ctx) };
        assert_eq!(status, TesseraStatus::InvalidArgument);
        assert!(ctx.is_null());
        let mut buf = vec![0 as std::ffi::c_char; 512];
        // SAFETY: `buf` holds 512 writable bytes.
        unsafe { tessera_last_error(null(), buf.as_mut_ptr(), buf.len()) };
        // SAFETY: NUL-terminated by the call.
        let message = unsafe { std::ffi::CStr::from_ptr(buf.as_ptr()) }.to_string_lossy();
        assert!(message.contains(needle), "{message}");
    }
}
