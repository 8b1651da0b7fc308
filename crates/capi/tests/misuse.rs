//! Misuse of the C ABI through its exported functions: null, forged, destroyed and
//! wrong-kind handles, null pointers, wrong sizes, bad indices, out-of-range options, Loop on
//! quads, a surface of another context, calls of the other mode. Each gets its code and a
//! message naming what is at fault, never undefined behaviour; and animation (per-frame
//! positions) changes what a surface draws. Every context it creates has the validation layer
//! on, and none may report an error.
mod common;
use common::surface_desc;
use std::ffi::{c_char, CStr};
use std::ptr::{null, null_mut};
use tessera_capi::host::*;
use tessera_capi::*;

const W: u32 = 96;
const H: u32 = 72;

/// The calling thread's last error (or `ctx`'s).
fn last_error(ctx: *const TesseraContext) -> String {
    let mut buf = vec![0 as c_char; 1024];
    // SAFETY: `buf` holds `buf.len()` writable bytes.
    let n = unsafe { tessera_last_error(ctx, buf.as_mut_ptr(), buf.len()) };
    // SAFETY: tessera_last_error NUL-terminates within the buffer.
    let s = unsafe { CStr::from_ptr(buf.as_ptr()) }
        .to_string_lossy()
        .into_owned();
    assert_eq!(n, s.len(), "length returned for {s:?}");
    s
}

#[track_caller]
fn expect(got: TesseraStatus, want: TesseraStatus, needle: &str) {
    let message = last_error(null());
    assert_eq!(got, want, "message: {message}");
    assert!(
        message.contains(needle),
        "{want:?}: message {message:?} does not mention {needle:?}"
    );
}

/// A unit cube of 6 quads (outward-facing), as arrays.
struct Cube {
    positions: Vec<f32>,
    sizes: Vec<u32>,
    indices: Vec<u32>,
}

fn cube() -> Cube {
    let mut positions = Vec::new();
    for i in 0..8u32 {
        positions.extend([(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32]);
    }
    let indices = vec![
        0, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5,
    ];
    Cube {
        positions,
        sizes: vec![4; 6],
        indices,
    }
}

fn mesh_desc(c: &Cube) -> TesseraMeshDesc {
    TesseraMeshDesc {
        name: c"cube".as_ptr(),
        positions: c.positions.as_ptr(),
        vertex_count: c.positions.len() / 3,
        face_sizes: c.sizes.as_ptr(),
        face_count: c.sizes.len(),
        face_indices: c.indices.as_ptr(),
        index_count: c.indices.len(),
        crease_vertices: null(),
        crease_sharpness: null(),
        crease_count: 0,
        corner_vertices: null(),
        corner_sharpness: null(),
        corner_count: 0,
        uvs: null(),
        scalar_tag_vertices: null(),
        scalar_tag_values: null(),
        scalar_tag_count: 0,
    }
}

fn frame_desc() -> TesseraFrameDesc {
    common::frame_desc(W, H)
}

fn create_surface(
    ctx: *mut TesseraContext,
    mesh: &TesseraMeshDesc,
    desc: &TesseraSurfaceDesc,
) -> (TesseraStatus, *mut TesseraSurface) {
    let mut s = null_mut();
    // SAFETY: every pointer addresses live locals of the sizes the descriptors state.
    let status = unsafe { tessera_surface_create(ctx, mesh, desc, &mut s) };
    (status, s)
}

fn render(ctx: *mut TesseraContext, s: *mut TesseraSurface) -> Vec<u8> {
    let f = frame_desc();
    let mut px = vec![0u8; (W * H * 4) as usize];
    // SAFETY: `px` holds `px.len()` writable bytes.
    let status = unsafe { tessera_render(ctx, s, &f, px.as_mut_ptr(), px.len()) };
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
    px
}

#[test]
fn misuse_gets_codes_and_messages_never_undefined_behaviour() {
    // SAFETY: every call below passes null pointers, forged handles (looked up, never
    // dereferenced), or pointers to live locals of the sizes passed.
    unsafe {
        // Handles before any context exists.
        expect(
            tessera_context_destroy(null_mut()),
            TesseraStatus::NullHandle,
            "null",
        );
        expect(
            tessera_context_destroy(0x1230 as *mut TesseraContext),
            TesseraStatus::InvalidHandle,
            "not a context handle",
        );
        expect(
            tessera_context_create_standalone(null(), null_mut()),
            TesseraStatus::NullPointer,
            "out is NULL",
        );
        let bad_validation = TesseraStandaloneDesc {
            device: null(),
            validation: 7,
            ..Default::default()
        };
        let mut ctx = null_mut();
        expect(
            tessera_context_create_standalone(&bad_validation, &mut ctx),
            TesseraStatus::InvalidArgument,
            "validation 7",
        );
        assert!(ctx.is_null());
        let no_device = TesseraStandaloneDesc {
            device: c"no such device name".as_ptr(),
            validation: TESSERA_VALIDATION_OFF,
            ..Default::default()
        };
        expect(
            tessera_context_create_standalone(&no_device, &mut ctx),
            TesseraStatus::NoDevice,
            "no such device name",
        );
        let cdesc = TesseraStandaloneDesc {
            device: null(),
            validation: TESSERA_VALIDATION_SYNCHRONIZATION,
            ..Default::default()
        };
        assert_eq!(
            tessera_context_create_standalone(&cdesc, &mut ctx),
            TesseraStatus::Ok
        );

        // Meshes.
        let c = cube();
        let flat = surface_desc(TESSERA_TECHNIQUE_FLAT);
        let mut m = mesh_desc(&c);
        m.index_count -= 1;
        expect(
            create_surface(ctx, &m, &flat).0,
            TesseraStatus::WrongSize,
            "face_sizes add up to 24 corners, index_count is 23",
        );
        let mut bad = cube();
        bad.indices[9] = 99;
        expect(
            create_surface(ctx, &mesh_desc(&bad), &flat).0,
            TesseraStatus::IndexOutOfRange,
            "face 2: vertex index 99",
        );
        assert!(
            last_error(ctx).contains("face 2"),
            "the context keeps its message"
        );
        let mut m = mesh_desc(&c);
        m.face_indices = null();
        expect(
            create_surface(ctx, &m, &flat).0,
            TesseraStatus::NullPointer,
            "face_indices is NULL",
        );
        let crease = [0u32, 77];
        let sharp = [2.0f32];
        let mut m = mesh_desc(&c);
        m.crease_vertices = crease.as_ptr();
        m.crease_sharpness = sharp.as_ptr();
        m.crease_count = 1;
        expect(
            create_surface(ctx, &m, &flat).0,
            TesseraStatus::IndexOutOfRange,
            "crease 0: vertex index 77",
        );
        // Scalar tags: an index out of range, a value out of its range, then a crease along the
        // edge from vertex 0 to 1 that PN draws (and that changes its picture).
        let tag_vertices = [0u32, 77];
        let tag_values = [[0.0f32, -1.0, -1.0, 0.0, 1.0, 0.0]; 2];
        let mut m = mesh_desc(&c);
        m.scalar_tag_vertices = tag_vertices.as_ptr();
        m.scalar_tag_values = tag_values.as_ptr().cast();
        m.scalar_tag_count = 2;
        expect(
            create_surface(ctx, &m, &flat).0,
            TesseraStatus::IndexOutOfRange,
            "scalar tag 1: vertex index 77",
        );
        let crease = [0u32, 1];
        m.scalar_tag_vertices = crease.as_ptr();
        let too_sharp = [[0.0f32, -1.0, -1.0, 0.0, 2.0, 0.0]; 2];
        m.scalar_tag_values = too_sharp.as_ptr().cast();
        expect(
            create_surface(ctx, &m, &flat).0,
            TesseraStatus::Mesh,
            "vertex 0: sharpness 2",
        );
        m.scalar_tag_values = tag_values.as_ptr().cast();
        let pn = surface_desc(TESSERA_TECHNIQUE_PN);
        let (status, tagged) = create_surface(ctx, &m, &pn);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
        let (status, smooth) = create_surface(ctx, &mesh_desc(&c), &pn);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
        assert_ne!(
            render(ctx, tagged),
            render(ctx, smooth),
            "the tags changed nothing"
        );
        assert_eq!(tessera_surface_destroy(ctx, tagged), TesseraStatus::Ok);
        assert_eq!(tessera_surface_destroy(ctx, smooth), TesseraStatus::Ok);
        let mut nan = cube();
        nan.positions[4] = f32::NAN;
        expect(
            create_surface(ctx, &mesh_desc(&nan), &flat).0,
            TesseraStatus::NonFinite,
            "vertex 1",
        );
        let mut loop_on_quads = surface_desc(TESSERA_TECHNIQUE_BFT);
        loop_on_quads.scheme = TESSERA_SCHEME_LOOP;
        expect(
            create_surface(ctx, &mesh_desc(&c), &loop_on_quads).0,
            TesseraStatus::Mesh,
            "triangles",
        );
        let mut cc_bft = surface_desc(TESSERA_TECHNIQUE_BFT);
        cc_bft.scheme = TESSERA_SCHEME_CATMULL_CLARK;
        expect(
            create_surface(ctx, &mesh_desc(&c), &cc_bft).0,
            TesseraStatus::Unsupported,
            "bft draws the Loop limit surface",
        );
        expect(
            create_surface(ctx, &mesh_desc(&c), &surface_desc(99)).0,
            TesseraStatus::InvalidArgument,
            "technique 99",
        );
        let mut tangents = flat;
        tangents.tangents = 2;
        expect(
            create_surface(ctx, &mesh_desc(&c), &tangents).0,
            TesseraStatus::InvalidArgument,
            "tangents 2",
        );
        let mut split = flat;
        split.split_triangles = 1;
        expect(
            create_surface(ctx, &mesh_desc(&c), &split).0,
            TesseraStatus::InvalidArgument,
            "split_triangles: flat",
        );
        split.split_triangles = 3;
        expect(
            create_surface(ctx, &mesh_desc(&c), &split).0,
            TesseraStatus::InvalidArgument,
            "split_triangles 3",
        );
        let mut uv_mode = surface_desc(TESSERA_TECHNIQUE_ADAPTIVE);
        assert_eq!(uv_mode.uv_interpolation, TESSERA_UV_INTERPOLATION_MESH);
        uv_mode.uv_interpolation = 7;
        expect(
            create_surface(ctx, &mesh_desc(&c), &uv_mode).0,
            TesseraStatus::InvalidArgument,
            "uv_interpolation 7",
        );
        uv_mode.uv_interpolation = TESSERA_UV_INTERPOLATION_NONE;
        let (status, u) = create_surface(ctx, &mesh_desc(&c), &uv_mode);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
        expect(tessera_surface_destroy(ctx, u), TesseraStatus::Ok, "");
        let mut gregory_split = surface_desc(TESSERA_TECHNIQUE_GREGORY);
        gregory_split.split_triangles = 1;
        let (status, g) = create_surface(ctx, &mesh_desc(&c), &gregory_split);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
        expect(tessera_surface_destroy(ctx, g), TesseraStatus::Ok, "");
        let text = b"v 0 0 0\nv 1 0 0\nf 1 2 3\n";
        let mut s = null_mut();
        let status = tessera_surface_create_obj(
            ctx,
            text.as_ptr().cast(),
            text.len(),
            c"bad.obj".as_ptr(),
            null(),
            &mut s,
        );
        assert!(
            matches!(
                status,
                TesseraStatus::IndexOutOfRange | TesseraStatus::Parse
            ),
            "{status:?}"
        );
        assert!(last_error(ctx).contains("bad.obj"), "{}", last_error(ctx));

        // Optional UVs: one (u, v) per face corner.
        let uvs: Vec<f32> = (0..c.indices.len() * 2).map(|i| (i % 2) as f32).collect();
        let mut with_uvs = mesh_desc(&c);
        with_uvs.uvs = uvs.as_ptr();
        let (status, textured) = create_surface(ctx, &with_uvs, &flat);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
        assert_eq!(tessera_surface_destroy(ctx, textured), TesseraStatus::Ok);

        // A flat cube: frames, sizes, animation refused.
        let (status, flat_cube) = create_surface(ctx, &mesh_desc(&c), &flat);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
        let f = frame_desc();
        let mut px = vec![0u8; (W * H * 4) as usize];
        expect(
            tessera_render(ctx, flat_cube, &f, px.as_mut_ptr(), px.len() + 4),
            TesseraStatus::WrongSize,
            "needs 27648 bytes",
        );
        expect(
            tessera_render(ctx, flat_cube, null(), px.as_mut_ptr(), px.len()),
            TesseraStatus::NullPointer,
            "frame is NULL",
        );
        let mut zero = f;
        zero.width = 0;
        expect(
            tessera_render(ctx, flat_cube, &zero, px.as_mut_ptr(), 0),
            TesseraStatus::InvalidArgument,
            "frame size 0x72",
        );
        let mut policy = f;
        policy.factor_policy = 9;
        expect(
            tessera_render(ctx, flat_cube, &policy, px.as_mut_ptr(), px.len()),
            TesseraStatus::InvalidArgument,
            "factor_policy 9",
        );
        let mut screen = f;
        screen.factor_policy = TESSERA_FACTORS_SCREEN;
        expect(
            tessera_render(ctx, flat_cube, &screen, px.as_mut_ptr(), px.len()),
            TesseraStatus::Unsupported,
            "flat",
        );
        expect(
            tessera_surface_update_positions(ctx, flat_cube, c.positions.as_ptr(), 8),
            TesseraStatus::Unsupported,
            "animated base positions",
        );
        expect(
            tessera_begin_frame(ctx, 3),
            TesseraStatus::WrongMode,
            "host-owned",
        );
        expect(
            tessera_record_draw(
                ctx,
                flat_cube,
                vk_core::vk::CommandBuffer::null(),
                null(),
                null(),
            ),
            TesseraStatus::WrongMode,
            "host-owned",
        );
        expect(
            tessera_surface_destroy(flat_cube.cast(), null_mut()),
            TesseraStatus::InvalidHandle,
            "is a surface handle, not a context handle",
        );

        // Animation: an adaptive cube moved by update_positions draws differently.
        let (status, smooth) = create_surface(
            ctx,
            &mesh_desc(&c),
            &surface_desc(TESSERA_TECHNIQUE_ADAPTIVE),
        );
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error(ctx));
        let before = render(ctx, smooth);
        expect(
            tessera_surface_update_positions(ctx, smooth, c.positions.as_ptr(), 7),
            TesseraStatus::WrongSize,
            "7 positions given, the surface has 8 vertices",
        );
        let moved: Vec<f32> = c.positions.iter().map(|x| x * 0.6).collect();
        assert_eq!(
            tessera_surface_update_positions(ctx, smooth, moved.as_ptr(), 8),
            TesseraStatus::Ok,
            "{}",
            last_error(ctx)
        );
        let after = render(ctx, smooth);
        let changed = before
            .chunks(4)
            .zip(after.chunks(4))
            .filter(|(a, b)| a != b)
            .count();
        assert!(
            changed > (W * H / 20) as usize,
            "moving the base changed only {changed} pixels"
        );
        let mut n = 0usize;
        assert_eq!(
            tessera_surface_info(ctx, smooth, &mut n, null_mut(), null_mut()),
            TesseraStatus::Ok
        );
        assert_eq!(n, 8);

        // Another context's surface, destroyed handles.
        let mut other = null_mut();
        let validated = TesseraStandaloneDesc {
            device: null(),
            validation: TESSERA_VALIDATION_SYNCHRONIZATION,
            ..Default::default()
        };
        assert_eq!(
            tessera_context_create_standalone(&validated, &mut other),
            TesseraStatus::Ok
        );
        expect(
            tessera_surface_destroy(other, smooth),
            TesseraStatus::WrongContext,
            "belongs to context",
        );
        let mut other_errors = 1;
        assert_eq!(
            tessera_context_validation_errors(other, &mut other_errors),
            TesseraStatus::Ok
        );
        assert_eq!(other_errors, 0, "validation errors on the other context");
        assert_eq!(tessera_context_destroy(other), TesseraStatus::Ok);
        assert_eq!(tessera_surface_destroy(ctx, flat_cube), TesseraStatus::Ok);
        expect(
            tessera_surface_destroy(ctx, flat_cube),
            TesseraStatus::DestroyedHandle,
            "was destroyed",
        );
        expect(
            tessera_render(ctx, flat_cube, &f, px.as_mut_ptr(), px.len()),
            TesseraStatus::DestroyedHandle,
            "use after destroy",
        );

        // The per-context message is the context's; another thread's is its own.
        let message = last_error(ctx);
        assert!(message.contains("destroyed"), "{message}");
        let ctx_id = ctx as usize;
        let other_thread = std::thread::spawn(move || {
            (
                last_error(null()),
                last_error(ctx_id as *const TesseraContext),
            )
        })
        .join()
        .unwrap();
        assert_eq!(other_thread, (String::new(), message));

        let mut errors = 1;
        assert_eq!(
            tessera_context_validation_errors(ctx, &mut errors),
            TesseraStatus::Ok
        );
        assert_eq!(errors, 0, "validation errors on the C ABI's context");
        // Destroying the context destroys the surface still on it.
        assert_eq!(tessera_context_destroy(ctx), TesseraStatus::Ok);
        expect(
            tessera_surface_destroy(ctx, smooth),
            TesseraStatus::DestroyedHandle,
            "context handle",
        );
        expect(
            tessera_context_destroy(ctx),
            TesseraStatus::DestroyedHandle,
            "double destroy",
        );
        assert_eq!(
            CStr::from_ptr(tessera_status_name(999)).to_str().unwrap(),
            "unknown status"
        );
        assert_eq!(
            CStr::from_ptr(tessera_status_name(TesseraStatus::WrongSize as u32))
                .to_str()
                .unwrap(),
            "wrong size"
        );
    }
}
