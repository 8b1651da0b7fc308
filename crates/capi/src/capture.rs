//! Capture through the C ABI, in both modes: the triangles the GPU's tessellation emitted for
//! one frame (transform feedback), welded by position bits, their open edges classified into
//! the base mesh's boundary and cracks, and written as OBJ — what `tessera export` does, with
//! the same weld, report and file (format: `tess::capture`).
//!
//! # Host-owned contexts
//! A capture records into a command buffer of Tessera's own and submits it to the host's queue
//! (as surface creation's uploads do), waiting for it on Tessera's own timeline semaphore. So
//! the host calls it between frames: the GPU has finished every command buffer the host
//! submitted with this surface's recordings (its fences), none is recorded but not yet
//! submitted, and no other thread uses the queue during the call. The capture writes frame
//! slot 0's uniforms and animated positions; the next [`crate::host::tessera_record_draw`] and
//! [`crate::host::tessera_record_pre_pass`] write their slot's again. The device needs
//! VK_EXT_transform_feedback with its feature (`TesseraHostDesc::transform_feedback`) and
//! `dynamicRendering` (the capture renders into an attachment-less scope of its own).
//!
//! The view is the frame description's standalone camera (`yaw`, `pitch`, `zoom`), as for
//! [`crate::tessera_render`]; [`crate::tessera_surface_camera`] gives its matrices, so a host
//! draws what it captures by drawing with them. Uniform factors do not depend on the view.
use crate::ffi::{out_write_opt, read_required, read_str};
use crate::status::{Error, Result, TesseraStatus};
use crate::{surface_frame_params, with_surface, ContextState, Mode, SurfaceState, TesseraContext};
use crate::{TesseraFrameDesc, TesseraSurface};
use std::ffi::c_char;
use tess::capture::{classify_open_edges, Winding};

/// What a capture found (as `tessera export` reports it).
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub struct TesseraCaptureReport {
    /// Triangles the GPU emitted (zero-area ones included).
    pub triangles: u64,
    /// Welded vertices: corners merged only when the bits of their positions are identical.
    pub vertices: u64,
    /// Edges used by exactly one triangle: `on_base_boundary + cracks`.
    pub open_edges: u64,
    /// Open edges on the control mesh's own boundary, along one of its non-manifold edges
    /// (sheets meeting there without sharing vertices), or inside one of its faces of no area.
    pub on_base_boundary: u64,
    /// Open edges inside the surface: cracks in what the GPU drew.
    pub cracks: u64,
    /// Of the cracks, those on patches with no base face (a technique bug).
    pub unmapped: u64,
    /// Edges used by three or more triangles.
    pub non_manifold_edges: u64,
    /// Triangles with two welded corners alike.
    pub zero_area_triangles: u64,
}

/// Refuses a capture on a host device without `dynamicRendering` (a render-pass host that did
/// not enable it): the capture's own scope would be invalid there.
fn can_capture(c: &ContextState) -> Result<()> {
    match c.mode {
        Mode::Host {
            dynamic_rendering: false,
            ..
        } => Err(Error::new(
            TesseraStatus::Unsupported,
            "a capture renders into an attachment-less dynamic-rendering scope of its own: the \
             host's device needs dynamicRendering enabled (TesseraHostDesc::dynamic_rendering)",
        )),
        _ => Ok(()),
    }
}

/// Captures one frame of `s` and writes the OBJ to `path` when given.
fn capture(
    s: &mut SurfaceState,
    f: &TesseraFrameDesc,
    path: Option<&std::path::Path>,
) -> Result<TesseraCaptureReport> {
    let (params, extent) = surface_frame_params(s, f)?;
    // Slot 0 draws the capture: its animated positions catch up first.
    s.sync_positions(0)?;
    let capturer = tess::Capturer::new(&s.tess)?;
    let (soup, _) = capturer.capture(&mut s.tess, s.technique.as_mut(), &params, extent)?;
    let technique = s.technique.as_ref();
    let welded = soup.weld()?;
    if let Some(i) = welded
        .positions
        .iter()
        .chain(&welded.normals)
        .position(|p| !p.iter().all(|x| x.is_finite()))
    {
        return Err(Error::new(
            TesseraStatus::NonFinite,
            format!(
                "the GPU emitted a non-finite position or normal (captured value {i}); nothing written"
            ),
        ));
    }
    let map = |patch: u32, domain: [f32; 2]| technique.face_point(patch, domain);
    let edges = welded.open_edges();
    let classes = classify_open_edges(&soup, &welded, &edges, &map, &s.mesh);
    if let Some(path) = path {
        let texcoords = welded.corner_texcoords(|p, d| technique.texcoord(p, d, params.reparam));
        welded.write_obj(path, &map, texcoords.as_deref(), Winding::Reversed)?;
    }
    Ok(TesseraCaptureReport {
        triangles: soup.triangle_count() as u64,
        vertices: welded.positions.len() as u64,
        open_edges: edges.open.len() as u64,
        on_base_boundary: (classes.on_base_boundary
            + classes.on_non_manifold_edge
            + classes.in_face_of_no_area) as u64,
        cracks: classes.cracks as u64,
        unmapped: classes.unmapped as u64,
        non_manifold_edges: edges.non_manifold.len() as u64,
        zero_area_triangles: edges.zero_area.len() as u64,
    })
}

/// Captures the triangles the GPU's tessellation emitted for one frame of the surface,
/// welds them, reports open edges and cracks into `report` (may be NULL) and, when `path` is
/// not NULL, writes them as OBJ there (as `tessera export` writes it: `v`, `vn`, a `# p F U V`
/// base-face point per vertex, `f`). Standalone and host-owned contexts alike (see the module
/// documentation in crates/capi/src/capture.rs for what a host must ensure). UNSUPPORTED on a
/// device without VK_EXT_transform_feedback. Thread-safe (serialized per context).
///
/// # Safety
/// `frame` is readable; `path` is NULL or NUL-terminated; `report` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn tessera_capture(
    ctx: *mut TesseraContext,
    surface: *mut TesseraSurface,
    frame: *const TesseraFrameDesc,
    path: *const c_char,
    report: *mut TesseraCaptureReport,
) -> TesseraStatus {
    with_surface(ctx, surface, |c, s| {
        can_capture(c)?;
        // SAFETY: the caller's contract.
        let f = unsafe { read_required(frame, "frame") }?;
        // SAFETY: the caller's contract.
        let path = unsafe { read_str(path, "path") }?;
        let r = capture(s, &f, path.as_deref().map(std::path::Path::new))?;
        // SAFETY: the caller's contract; NULL is skipped.
        unsafe { out_write_opt(report, r) };
        Ok(())
    })
}

/// [`tessera_capture`] writing the OBJ to `path` (required) and the triangle count to
/// `triangles` (may be NULL).
///
/// # Safety
/// `frame` is readable; `path` is NUL-terminated; `triangles` is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn tessera_capture_obj(
    ctx: *mut TesseraContext,
    surface: *mut TesseraSurface,
    frame: *const TesseraFrameDesc,
    path: *const c_char,
    triangles: *mut u64,
) -> TesseraStatus {
    with_surface(ctx, surface, |c, s| {
        can_capture(c)?;
        // SAFETY: the caller's contract.
        let f = unsafe { read_required(frame, "frame") }?;
        // SAFETY: the caller's contract.
        let path = unsafe { read_str(path, "path") }?
            .ok_or_else(|| Error::new(TesseraStatus::NullPointer, "path is NULL"))?;
        let r = capture(s, &f, Some(std::path::Path::new(&path)))?;
        // SAFETY: the caller's contract; NULL is skipped.
        unsafe { out_write_opt(triangles, r.triangles) };
        Ok(())
    })
}
