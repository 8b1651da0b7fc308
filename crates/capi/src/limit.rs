//! Limit evaluation on the CPU: exact positions, first derivatives and normals of a surface's
//! limit surface at `(face, u, v)` — picking, scattering, collision, baking, placing objects on
//! the surface.
//!
//! # Domain
//! Points are given as `tessera export` and [`crate::tessera_capture_obj`] write them on their
//! `# p F U V` lines (`tess::capture::face_corner_uv`): `F` a face of the control mesh
//! (0-based, in its face order), `(U, V)` in that face's domain — triangles with corners 0,
//! 1, 2 at (1, 0), (0, 1), (0, 0); quads the unit square (0, 0), (1, 0), (1, 1), (0, 1);
//! n-gons the regular n-gon with corner `k` at (½ + ½ cos 2πk/n, ½ + ½ sin 2πk/n). So a
//! captured vertex's `# p` point evaluates to that vertex's position on the exact limit
//! surface. Derivatives are along the domain's `u` and `v`; the normal is their normalized
//! cross product (outward for a consistently oriented mesh). Points up to
//! `topology::limit::face_domain::DOMAIN_TOLERANCE` outside a face's domain (captured values are `float`) are
//! moved onto it.
//!
//! # Scheme
//! A surface's evaluator evaluates the limit surface of its scheme: the one given at creation,
//! else its technique's (adaptive, gregory, acc: Catmull-Clark; bft: Loop), else Catmull-Clark
//! unless every face is a triangle. Loop evaluates the fan triangulation of other faces (what
//! the Loop technique draws); gregory and acc approximate the Catmull-Clark limit this
//! evaluates exactly. Doo-Sabin evaluates its exact limit in the same face domains (each face
//! through the sub-quads of its corners); at the centre of a face that is not a quad, where
//! that limit has no parametric derivatives, `du` and `dv` are zero. Creases and corners count, scaled by the surface's `sharpness_scale`
//! where its technique scales them (adaptive, gregory, acc). Positions are the surface's
//! newest ([`crate::tessera_surface_update_positions`]) when the evaluator is made.
//!
//! # Threads
//! An evaluator is immutable: [`tessera_limit_evaluate`] may run on any number of threads at
//! once with one evaluator, without locks (the handle is looked up under the handle table's lock
//! for an instant). It holds CPU data only and outlives the context and surface it was made
//! from; destroying it while another thread evaluates lets that evaluation finish.
use crate::ffi::{out_write, read_required, read_slice};
use crate::handles::lock;
use crate::status::{Error, Result, TesseraStatus};
use crate::{guard, handle_id, handles, with_surface, TesseraContext, TesseraSurface};
use crate::{TesseraMeshDesc, TesseraScheme};
use topology::limit::eval::EvalError;
use topology::limit::face_domain::{LimitEvaluator, PointError};
use topology::Scheme;

/// An opaque limit evaluator: one surface's (or mesh's) exact limit surface on the CPU.
// Not `repr(C)`: cbindgen then declares it opaque.
pub struct TesseraLimitEvaluator {
    _opaque: (),
}

/// One of a sample's vectors (position, du, dv, normal).
type SampleField = fn(&topology::limit::face_domain::FaceSample) -> [f64; 3];

fn evaluator_ptr(id: u64) -> *mut TesseraLimitEvaluator {
    id as usize as *mut TesseraLimitEvaluator
}

/// The evaluator of `mesh` under `scheme`, with its message for a scheme without one.
pub(crate) fn build(mesh: &topology::ControlMesh, scheme: Scheme) -> Result<LimitEvaluator> {
    LimitEvaluator::of_scheme(mesh, scheme).map_err(|e| match e {
        EvalError::NoLimitEvaluation { .. } => Error::new(
            TesseraStatus::Unsupported,
            format!("limit evaluation of {scheme}: {e}"),
        ),
        e => eval_error(&e, e.to_string()),
    })
}

/// The status of an evaluation error, with `message`.
fn eval_error(e: &EvalError, message: String) -> Error {
    let status = match e {
        EvalError::FaceOutOfRange { .. } => TesseraStatus::IndexOutOfRange,
        EvalError::ParamOutOfRange { u, v } if !(u.is_finite() && v.is_finite()) => {
            TesseraStatus::NonFinite
        }
        EvalError::ParamOutOfRange { .. } => TesseraStatus::InvalidArgument,
        EvalError::NotConverged { .. } => TesseraStatus::Internal,
        _ => TesseraStatus::Mesh,
    };
    Error::new(status, message)
}

fn point_error(e: PointError) -> Error {
    let message = match e.source.as_ref() {
        EvalError::ParamOutOfRange { .. } => format!(
            "{e}: (u, v) must lie in the face's domain (as on the `# p` lines of a capture)"
        ),
        _ => e.to_string(),
    };
    eval_error(&e.source, message)
}

fn with_evaluator(
    ev: *const TesseraLimitEvaluator,
    body: impl FnOnce(&LimitEvaluator) -> Result<()>,
) -> TesseraStatus {
    guard(|| {
        let e = lock(handles())?.evaluator(handle_id(ev))?;
        body(&e)
    })
}

/// Makes an evaluator of the surface's limit surface (its scheme, control mesh, creases and
/// current positions; see the module documentation in crates/capi/src/limit.rs). Thread-safe.
///
/// # Safety
/// `out` points to a writable `TesseraLimitEvaluator*` (set to NULL on failure).
#[no_mangle]
pub unsafe extern "C" fn tessera_limit_evaluator_create(
    ctx: *const TesseraContext,
    surface: *const TesseraSurface,
    out: *mut *mut TesseraLimitEvaluator,
) -> TesseraStatus {
    with_surface(ctx, surface, |_, s| {
        // SAFETY: the caller's contract.
        unsafe { out_write(out, std::ptr::null_mut(), "out") }?;
        let e = build(&s.limit_mesh(), s.scheme)?;
        let id = lock(handles())?.add_evaluator(e);
        // SAFETY: the caller's contract.
        unsafe { out_write(out, evaluator_ptr(id), "out") }
    })
}

/// Makes an evaluator of a control mesh given as arrays, with no context or device:
/// `scheme` is `TESSERA_SCHEME_*` (AUTO: Loop when every face is a triangle, else
/// Catmull-Clark). The mesh is checked as [`crate::tessera_surface_create`] checks it.
/// Thread-safe.
///
/// # Safety
/// `mesh` is readable and its arrays as long as its counts say; `out` points to a writable
/// `TesseraLimitEvaluator*` (set to NULL on failure).
#[no_mangle]
pub unsafe extern "C" fn tessera_limit_evaluator_create_mesh(
    mesh: *const TesseraMeshDesc,
    scheme: TesseraScheme,
    out: *mut *mut TesseraLimitEvaluator,
) -> TesseraStatus {
    guard(|| {
        // SAFETY: the caller's contract.
        unsafe { out_write(out, std::ptr::null_mut(), "out") }?;
        // SAFETY: the caller's contract.
        let m = unsafe { read_required(mesh, "mesh") }?;
        // SAFETY: the caller's contract for the arrays.
        let (mut mesh, _) = unsafe { crate::read_mesh(&m) }?;
        topology::mesh::check_positions(&mesh.positions)?;
        mesh.validate()?;
        mesh.apply_boundary_none();
        let scheme = crate::surface_scheme(scheme, None, &mesh)?;
        let e = build(&mesh, scheme)?;
        let id = lock(handles())?.add_evaluator(e);
        // SAFETY: the caller's contract.
        unsafe { out_write(out, evaluator_ptr(id), "out") }
    })
}

/// Destroys an evaluator (an evaluation running on another thread finishes first). Thread-safe;
/// a second destroy returns DESTROYED_HANDLE.
///
/// # Safety
/// None: the handle is looked up, never dereferenced.
#[no_mangle]
pub unsafe extern "C" fn tessera_limit_evaluator_destroy(
    ev: *mut TesseraLimitEvaluator,
) -> TesseraStatus {
    guard(|| {
        lock(handles())?.remove_evaluator(handle_id(ev))?;
        Ok(())
    })
}

/// The evaluator's face count (points name faces `0..face_count`) and scheme
/// (`TESSERA_SCHEME_CATMULL_CLARK` or `TESSERA_SCHEME_LOOP`). Either output may be NULL.
/// Thread-safe.
///
/// # Safety
/// Each output is NULL or writable.
#[no_mangle]
pub unsafe extern "C" fn tessera_limit_evaluator_info(
    ev: *const TesseraLimitEvaluator,
    face_count: *mut usize,
    scheme: *mut TesseraScheme,
) -> TesseraStatus {
    with_evaluator(ev, |e| {
        let s = match e.scheme() {
            Scheme::Loop => crate::TESSERA_SCHEME_LOOP,
            Scheme::DooSabin => crate::TESSERA_SCHEME_DOO_SABIN,
            _ => crate::TESSERA_SCHEME_CATMULL_CLARK,
        };
        // SAFETY: the caller's contract; NULL outputs are skipped.
        unsafe {
            crate::ffi::out_write_opt(face_count, e.num_faces());
            crate::ffi::out_write_opt(scheme, s);
        }
        Ok(())
    })
}

/// Evaluates `count` points of the limit surface exactly (see the module documentation in
/// crates/capi/src/limit.rs for the domain): point `i` is face `faces[i]` at
/// `(uvs[2i], uvs[2i+1])`. Writes `3 * count` doubles to each output that is not NULL:
/// `positions`, `du`, `dv` (derivatives along u and v) and `normals` (unit, or zero where the
/// derivatives are parallel). Every point is checked before any output is written: a face out
/// of range is INDEX_OUT_OF_RANGE, a NaN or infinite parameter NON_FINITE, a parameter outside
/// the face's domain INVALID_ARGUMENT, each naming the point. Thread-safe and lock-free per
/// evaluator: call it from as many threads as you like.
///
/// # Safety
/// `faces` points to `count` readable `uint32_t`, `uvs` to `2 * count` readable doubles, each
/// output is NULL or points to `3 * count` writable doubles.
#[no_mangle]
pub unsafe extern "C" fn tessera_limit_evaluate(
    ev: *const TesseraLimitEvaluator,
    faces: *const u32,
    uvs: *const f64,
    count: usize,
    positions: *mut f64,
    du: *mut f64,
    dv: *mut f64,
    normals: *mut f64,
) -> TesseraStatus {
    with_evaluator(ev, |e| {
        // SAFETY: the caller's contract.
        let faces = unsafe { read_slice(faces, count, 1, "faces") }?;
        // SAFETY: the caller's contract.
        let uvs = unsafe { read_slice(uvs, count, 2, "uvs") }?;
        let points: Vec<(u32, [f64; 2])> = faces
            .iter()
            .zip(uvs.chunks_exact(2))
            .map(|(&f, uv)| (f, [uv[0], uv[1]]))
            .collect();
        let samples = e.evaluate_many(&points).map_err(point_error)?;
        let outputs: [(*mut f64, SampleField, &str); 4] = [
            (positions, |s| s.position, "positions"),
            (du, |s| s.du, "du"),
            (dv, |s| s.dv, "dv"),
            (normals, |s| s.normal, "normals"),
        ];
        for (ptr, field, what) in outputs {
            if ptr.is_null() {
                continue;
            }
            let values: Vec<f64> = samples.iter().flat_map(field).collect();
            // SAFETY: the caller's contract: `3 * count` writable doubles.
            unsafe { crate::ffi::write_f64s(ptr, &values, what) }?;
        }
        Ok(())
    })
}
