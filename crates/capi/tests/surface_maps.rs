//! Surface maps and the single-pass techniques through the C ABI: the single-pass techniques (`TESSERA_TECHNIQUE_GREGORY`,
//! `_ACC`), a colour texture and a height map given as arrays, the frame's `no_reparam`,
//! `displace` and `show`. Each must change what is drawn or captured (a texture changes the
//! image, a height map moves the captured positions, a zero height map moves nothing), and
//! every misuse gets its named status and a message naming the field. One validated
//! standalone device, no validation errors at the end.
mod common;
use common::surface_desc;
use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};
use tessera_capi::*;

const W: u32 = 128;
const H: u32 = 96;

/// The calling thread's last error.
fn last_error() -> String {
    let mut buf = vec![0 as c_char; 1024];
    // SAFETY: `buf` holds `buf.len()` writable bytes.
    unsafe { tessera_last_error(null(), buf.as_mut_ptr(), buf.len()) };
    // SAFETY: tessera_last_error NUL-terminates within the buffer.
    unsafe { CStr::from_ptr(buf.as_ptr()) }
        .to_string_lossy()
        .into_owned()
}

#[track_caller]
fn expect(got: TesseraStatus, want: TesseraStatus, needle: &str) {
    let message = last_error();
    assert_eq!(got, want, "message: {message}");
    assert!(
        message.contains(needle),
        "{want:?}: message {message:?} does not mention {needle:?}"
    );
}

fn frame_desc() -> TesseraFrameDesc {
    let mut f = common::frame_desc(W, H);
    f.factor = 3.0;
    f
}

/// The embedded spot mesh (it has `vt` coordinates) built with `desc`.
fn spot(
    ctx: *mut TesseraContext,
    desc: &TesseraSurfaceDesc,
) -> (TesseraStatus, *mut TesseraSurface) {
    let mut s = null_mut();
    // SAFETY: NULL text builds the embedded mesh; the images `desc` points to are live locals
    // of the sizes it states.
    let status = unsafe { tessera_surface_create_obj(ctx, null(), 0, null(), desc, &mut s) };
    (status, s)
}

fn render(
    ctx: *mut TesseraContext,
    s: *mut TesseraSurface,
    f: &TesseraFrameDesc,
) -> (TesseraStatus, Vec<u8>) {
    let mut px = vec![0u8; (f.width * f.height * 4) as usize];
    // SAFETY: `px` holds `px.len()` writable bytes.
    let status = unsafe { tessera_render(ctx, s, f, px.as_mut_ptr(), px.len()) };
    (status, px)
}

/// The captured, welded positions (`v` lines) of one frame of `s`.
fn capture(
    ctx: *mut TesseraContext,
    s: *mut TesseraSurface,
    f: &TesseraFrameDesc,
    name: &str,
) -> Vec<[f32; 3]> {
    let dir = std::env::temp_dir().join(format!("tessera-capi-maps-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join(name);
    let c_path = CString::new(path.to_str().unwrap()).unwrap();
    let mut triangles = 0u64;
    // SAFETY: `f` and `c_path` are live; `triangles` is writable.
    let status = unsafe { tessera_capture_obj(ctx, s, f, c_path.as_ptr(), &mut triangles) };
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    assert!(triangles > 0);
    let text = std::fs::read_to_string(&path).unwrap();
    let _ = std::fs::remove_dir_all(&dir);
    text.lines()
        .filter_map(|l| l.strip_prefix("v "))
        .map(|l| {
            let v: Vec<f32> = l.split_whitespace().map(|x| x.parse().unwrap()).collect();
            [v[0], v[1], v[2]]
        })
        .collect()
}

/// Mean distance of `p` from the centroid of `reference`.
fn mean_radius(p: &[[f32; 3]], reference: &[[f32; 3]]) -> f64 {
    let n = reference.len() as f64;
    let c: Vec<f64> = (0..3)
        .map(|k| reference.iter().map(|v| v[k] as f64).sum::<f64>() / n)
        .collect();
    p.iter()
        .map(|v| {
            (0..3)
                .map(|k| (v[k] as f64 - c[k]).powi(2))
                .sum::<f64>()
                .sqrt()
        })
        .sum::<f64>()
        / p.len() as f64
}

fn differing_pixels(a: &[u8], b: &[u8]) -> usize {
    a.chunks(4)
        .zip(b.chunks(4))
        .filter(|(p, q)| p.iter().zip(q.iter()).any(|(x, y)| x.abs_diff(*y) > 24))
        .count()
}

/// A 32×32 RGBA8 checkerboard of saturated red and blue (sRGB), 4 texels a square.
fn checker_texture() -> Vec<u8> {
    (0..32 * 32)
        .flat_map(|i| {
            let (x, y) = (i % 32, i / 32);
            if (x / 4 + y / 4) % 2 == 0 {
                [230u8, 20, 20, 255]
            } else {
                [20u8, 20, 230, 255]
            }
        })
        .collect()
}

#[test]
fn single_pass_techniques_draw_textures_and_displace_by_the_height_map() {
    let desc = TesseraStandaloneDesc {
        device: null(),
        validation: TESSERA_VALIDATION_SYNCHRONIZATION,
        ..Default::default()
    };
    let mut ctx = null_mut();
    // SAFETY: `desc` and `ctx` are live locals.
    let status = unsafe { tessera_context_create_standalone(&desc, &mut ctx) };
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    let texture = checker_texture();
    let zeros = vec![0.0f32; 16 * 16];
    // Heights from 0.5 to 1: every point moves outward by at least half the scale.
    let heights: Vec<f32> = (0..16 * 16)
        .map(|i| 0.5 + 0.5 * ((i % 16) as f32 / 15.0))
        .collect();

    for technique in [TESSERA_TECHNIQUE_GREGORY, TESSERA_TECHNIQUE_ACC] {
        // Without maps, then with the texture and a height map.
        let plain = surface_desc(technique);
        let (status, bare) = spot(ctx, &plain);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        let mut with_maps = plain;
        with_maps.texture = texture.as_ptr();
        with_maps.texture_width = 32;
        with_maps.texture_height = 32;
        with_maps.height_map = heights.as_ptr();
        with_maps.height_map_width = 16;
        with_maps.height_map_height = 16;
        let (status, mapped) = spot(ctx, &with_maps);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        let mut flat_height = with_maps;
        flat_height.height_map = zeros.as_ptr();
        let (status, zero_height) = spot(ctx, &flat_height);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());

        // The texture changes the image: the checker's red and blue on a lit surface.
        let f = frame_desc();
        let (status, a) = render(ctx, bare, &f);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        let (status, b) = render(ctx, mapped, &f);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        let changed = differing_pixels(&a, &b);
        eprintln!("technique {technique}: the texture changed {changed} pixels");
        assert!(
            changed > (W * H) as usize / 20,
            "technique {technique}: only {changed} pixels changed with the texture"
        );
        // Reddish pixels appear that the untextured (grey) surface lacks.
        let red = |px: &[u8]| {
            px.chunks(4)
                .filter(|p| p[0] as i32 > p[1] as i32 + 60 && p[0] > 80)
                .count()
        };
        assert!(
            red(&b) > red(&a) + 100,
            "technique {technique}: {} red pixels textured, {} plain",
            red(&b),
            red(&a)
        );

        // `show` colours by the reparameterization's shift instead of shading.
        let mut shift = f;
        shift.show = TESSERA_SHOW_PARAM_SHIFT;
        let (status, c) = render(ctx, mapped, &shift);
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        assert!(
            differing_pixels(&b, &c) > (W * H) as usize / 20,
            "technique {technique}: show PARAM_SHIFT draws the shaded image"
        );

        // Displacement moves the captured surface outward by the height map's heights; a
        // zero height map moves nothing (so the map, not a procedural height, is what moves it).
        let mut cap = frame_desc();
        cap.factor = 2.0;
        let rest = capture(ctx, mapped, &cap, "rest.obj");
        let mut displaced_frame = cap;
        displaced_frame.displace = 0.2;
        let displaced = capture(ctx, mapped, &displaced_frame, "displaced.obj");
        let unmoved = capture(ctx, zero_height, &displaced_frame, "zero.obj");
        assert_eq!(displaced.len(), rest.len(), "same tessellation");
        let grown = mean_radius(&displaced, &rest) - mean_radius(&rest, &rest);
        eprintln!("technique {technique}: displace 0.2 grew the mean radius by {grown:.4}");
        assert!(
            grown > 0.05,
            "technique {technique}: displace 0.2 by heights 0.5..1 grew the mean radius by {grown}"
        );
        assert_eq!(unmoved.len(), rest.len());
        let moved = unmoved
            .iter()
            .zip(&rest)
            .map(|(p, q)| (0..3).map(|k| (p[k] - q[k]).abs()).fold(0.0f32, f32::max))
            .fold(0.0f32, f32::max);
        assert!(
            moved < 1e-4,
            "technique {technique}: a zero height map moved a vertex by {moved}"
        );

        // ParamError needs the lattice the surface was not built with: the technique's named
        // refusal, not a draw.
        let mut error_view = f;
        error_view.show = TESSERA_SHOW_PARAM_ERROR;
        let (status, _) = render(ctx, mapped, &error_view);
        expect(status, TesseraStatus::Unsupported, "param-error");

        for s in [bare, mapped, zero_height] {
            // SAFETY: handles issued above.
            let status = unsafe { tessera_surface_destroy(ctx, s) };
            assert_eq!(status, TesseraStatus::Ok);
        }
    }

    let mut errors = 1;
    // SAFETY: `errors` is writable.
    let status = unsafe { tessera_context_validation_errors(ctx, &mut errors) };
    assert_eq!(status, TesseraStatus::Ok);
    assert_eq!(errors, 0, "validation errors");
    // SAFETY: the context issued above.
    assert_eq!(unsafe { tessera_context_destroy(ctx) }, TesseraStatus::Ok);
}

/// A 2×2 grid of quads with texture coordinates (a small surface for the error lattice).
fn grid() -> (Vec<f32>, Vec<u32>, Vec<u32>, Vec<f32>) {
    let mut positions = Vec::new();
    for y in 0..3 {
        for x in 0..3 {
            positions.extend([x as f32, y as f32, ((x + y) % 2) as f32 * 0.3]);
        }
    }
    let mut indices = Vec::new();
    let mut uvs = Vec::new();
    for y in 0..2u32 {
        for x in 0..2u32 {
            for (dx, dy) in [(0, 0), (1, 0), (1, 1), (0, 1)] {
                indices.push((y + dy) * 3 + x + dx);
                uvs.extend([(x + dx) as f32 / 2.0, (y + dy) as f32 / 2.0]);
            }
        }
    }
    (positions, vec![4; 4], indices, uvs)
}

#[test]
fn bad_maps_and_frame_options_get_named_statuses() {
    let desc = TesseraStandaloneDesc {
        device: null(),
        validation: TESSERA_VALIDATION_SYNCHRONIZATION,
        ..Default::default()
    };
    let mut ctx = null_mut();
    // SAFETY: `desc` and `ctx` are live locals.
    let status = unsafe { tessera_context_create_standalone(&desc, &mut ctx) };
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    let (positions, sizes, indices, uvs) = grid();
    let mesh = TesseraMeshDesc {
        name: c"grid".as_ptr(),
        positions: positions.as_ptr(),
        vertex_count: positions.len() / 3,
        face_sizes: sizes.as_ptr(),
        face_count: sizes.len(),
        face_indices: indices.as_ptr(),
        index_count: indices.len(),
        crease_vertices: null(),
        crease_sharpness: null(),
        crease_count: 0,
        corner_vertices: null(),
        corner_sharpness: null(),
        corner_count: 0,
        uvs: uvs.as_ptr(),
        scalar_tag_vertices: null(),
        scalar_tag_values: null(),
        scalar_tag_count: 0,
    };
    let create = |d: &TesseraSurfaceDesc| {
        let mut s = null_mut();
        // SAFETY: every pointer addresses live locals of the sizes the descriptors state.
        let status = unsafe { tessera_surface_create(ctx, &mesh, d, &mut s) };
        (status, s)
    };
    let texture = checker_texture();
    let mut nan_heights = vec![0.25f32; 8 * 8];
    nan_heights[8 * 3 + 5] = f32::NAN;

    // An unknown technique value.
    let (status, s) = create(&surface_desc(99));
    expect(status, TesseraStatus::InvalidArgument, "technique 99");
    assert!(s.is_null());

    // NULL with a size, a size of 0 with a pointer, a side over the limit.
    let mut d = surface_desc(TESSERA_TECHNIQUE_GREGORY);
    d.texture_width = 32;
    d.texture_height = 32;
    expect(create(&d).0, TesseraStatus::NullPointer, "texture is NULL");
    let mut d = surface_desc(TESSERA_TECHNIQUE_GREGORY);
    d.texture = texture.as_ptr();
    d.texture_width = 32;
    expect(
        create(&d).0,
        TesseraStatus::InvalidArgument,
        "texture size 32x0",
    );
    d.texture_height = TESSERA_MAX_IMAGE_SIDE + 1;
    expect(create(&d).0, TesseraStatus::InvalidArgument, "at most");
    let mut d = surface_desc(TESSERA_TECHNIQUE_ACC);
    d.height_map_width = 4;
    d.height_map_height = 4;
    expect(
        create(&d).0,
        TesseraStatus::NullPointer,
        "height_map is NULL",
    );
    let mut d = surface_desc(TESSERA_TECHNIQUE_ACC);
    d.height_map = nan_heights.as_ptr();
    d.height_map_height = 8;
    expect(
        create(&d).0,
        TesseraStatus::InvalidArgument,
        "height_map size 0x8",
    );
    // A non-finite height, named by its texel.
    d.height_map_width = 8;
    expect(
        create(&d).0,
        TesseraStatus::NonFinite,
        "height_map texel (5, 3)",
    );
    // Flags are 0 or 1.
    let mut d = surface_desc(TESSERA_TECHNIQUE_ADAPTIVE);
    d.param_error = 2;
    expect(
        create(&d).0,
        TesseraStatus::InvalidArgument,
        "param_error 2",
    );
    // Maps on a technique without the surface feature, every field named.
    let mut d = surface_desc(TESSERA_TECHNIQUE_PN);
    d.texture = texture.as_ptr();
    d.texture_width = 32;
    d.texture_height = 32;
    d.param_error = 1;
    let (status, s) = create(&d);
    expect(
        status,
        TesseraStatus::Unsupported,
        "texture, param_error only apply to technique adaptive, gregory or acc",
    );
    assert!(s.is_null());

    // A flat surface refuses the frame's surface options; a gregory one built with the error
    // lattice draws PARAM_ERROR and refuses bad values.
    let (status, flat) = create(&surface_desc(TESSERA_TECHNIQUE_FLAT));
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    let mut lattice = surface_desc(TESSERA_TECHNIQUE_GREGORY);
    lattice.param_error = 1;
    let (status, gregory) = create(&lattice);
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    let f = frame_desc();
    let (status, _) = render(ctx, flat, &f);
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    let mut g = f;
    g.displace = 0.5;
    expect(
        render(ctx, flat, &g).0,
        TesseraStatus::Unsupported,
        "displace only applies to technique adaptive, gregory or acc (this surface's technique is flat)",
    );
    let mut g = f;
    g.no_reparam = 1;
    g.show = TESSERA_SHOW_PARAM_SHIFT;
    expect(
        render(ctx, flat, &g).0,
        TesseraStatus::Unsupported,
        "no_reparam, show only apply",
    );
    let mut g = f;
    g.show = TESSERA_SHOW_PARAM_ERROR;
    let (status, error_view) = render(ctx, gregory, &g);
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    g.no_reparam = 1;
    let (status, _) = render(ctx, gregory, &g);
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    let (_, shaded) = render(ctx, gregory, &f);
    assert!(
        differing_pixels(&error_view, &shaded) > 0,
        "PARAM_ERROR draws the shaded image"
    );
    let mut g = f;
    g.no_reparam = 2;
    expect(
        render(ctx, gregory, &g).0,
        TesseraStatus::InvalidArgument,
        "no_reparam 2",
    );
    let mut g = f;
    g.show = 3;
    expect(
        render(ctx, gregory, &g).0,
        TesseraStatus::InvalidArgument,
        "show 3",
    );
    let mut g = f;
    g.displace = f32::NAN;
    expect(
        render(ctx, gregory, &g).0,
        TesseraStatus::NonFinite,
        "non-finite",
    );
    g.displace = -1500.0;
    expect(
        render(ctx, gregory, &g).0,
        TesseraStatus::InvalidArgument,
        "displace -1500",
    );

    let mut errors = 1;
    // SAFETY: `errors` is writable.
    let status = unsafe { tessera_context_validation_errors(ctx, &mut errors) };
    assert_eq!(status, TesseraStatus::Ok);
    assert_eq!(errors, 0, "validation errors");
    // SAFETY: the context issued above (it destroys its surfaces).
    assert_eq!(unsafe { tessera_context_destroy(ctx) }, TesseraStatus::Ok);
}
