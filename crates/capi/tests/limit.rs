//! Limit evaluation through the C ABI: the exact limit surface at `(face, u, v)` in the `# p`
//! domain of a capture. It must be what `tessera limit` prints (`topology::limit::eval::limit_point`)
//! and, for the techniques that draw the limit surface, what the GPU drew at each captured
//! vertex; bad faces and parameters get their codes before any output is written; one
//! evaluator serves many threads at once.
mod common;
use common::{frame_desc, surface_desc};
use std::ffi::{c_char, CStr, CString};
use std::ptr::{null, null_mut};
use tessera_capi::*;
use topology::limit::eval::{limit_point, LimitScheme};

fn last_error() -> String {
    let mut buf = vec![0 as c_char; 1024];
    // SAFETY: `buf` holds `buf.len()` writable bytes; the result is NUL-terminated in it.
    unsafe {
        tessera_last_error(null(), buf.as_mut_ptr(), buf.len());
        CStr::from_ptr(buf.as_ptr()).to_string_lossy().into_owned()
    }
}

struct Standalone {
    ctx: *mut TesseraContext,
}

impl Standalone {
    fn new() -> Self {
        let desc = TesseraStandaloneDesc {
            validation: TESSERA_VALIDATION_SYNCHRONIZATION,
            pipeline_cache: TESSERA_PIPELINE_CACHE_OFF,
            ..Default::default()
        };
        let mut ctx = null_mut();
        // SAFETY: `desc` and `ctx` are live locals.
        let status = unsafe { tessera_context_create_standalone(&desc, &mut ctx) };
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        Self { ctx }
    }

    /// Spot drawn by `technique`.
    fn spot(&self, technique: TesseraTechnique) -> *mut TesseraSurface {
        self.spot_as(technique, TESSERA_SCHEME_AUTO)
    }

    /// Spot drawn by `technique` as `scheme`.
    fn spot_as(&self, technique: TesseraTechnique, scheme: TesseraScheme) -> *mut TesseraSurface {
        let mut d = surface_desc(technique);
        d.scheme = scheme;
        let mut s = null_mut();
        // SAFETY: NULL text builds the embedded mesh; `d` and `s` are live locals.
        let status = unsafe { tessera_surface_create_obj(self.ctx, null(), 0, null(), &d, &mut s) };
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        s
    }

    fn evaluator(&self, s: *mut TesseraSurface) -> Evaluator {
        let mut e = null_mut();
        // SAFETY: `e` is a live local.
        let status = unsafe { tessera_limit_evaluator_create(self.ctx, s, &mut e) };
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        Evaluator(e)
    }
}

impl Drop for Standalone {
    fn drop(&mut self) {
        let mut errors = 1;
        // SAFETY: the context is live until the destroy below.
        unsafe {
            assert_eq!(
                tessera_context_validation_errors(self.ctx, &mut errors),
                TesseraStatus::Ok
            );
            assert_eq!(tessera_context_destroy(self.ctx), TesseraStatus::Ok);
        }
        if !std::thread::panicking() {
            assert_eq!(errors, 0, "validation errors");
        }
    }
}

struct Evaluator(*mut TesseraLimitEvaluator);
// SAFETY: the handle is a number the library looks up; evaluation is thread-safe by contract.
unsafe impl Send for Evaluator {}
// SAFETY: as above.
unsafe impl Sync for Evaluator {}

/// Positions, du, dv and normals of each point (or the status and message).
type Samples = [Vec<[f64; 3]>; 4];

impl Evaluator {
    fn evaluate(&self, points: &[(u32, [f64; 2])]) -> Result<Samples, (TesseraStatus, String)> {
        let faces: Vec<u32> = points.iter().map(|p| p.0).collect();
        let uvs: Vec<f64> = points.iter().flat_map(|p| p.1).collect();
        let n = points.len();
        let mut out = [(); 4].map(|_| vec![[f64::NAN; 3]; n]);
        let [p, du, dv, nn] = &mut out;
        // SAFETY: `faces` holds n indices, `uvs` 2n doubles, each output 3n doubles.
        let status = unsafe {
            tessera_limit_evaluate(
                self.0,
                faces.as_ptr(),
                uvs.as_ptr(),
                n,
                p.as_mut_ptr().cast(),
                du.as_mut_ptr().cast(),
                dv.as_mut_ptr().cast(),
                nn.as_mut_ptr().cast(),
            )
        };
        if status != TesseraStatus::Ok {
            // Nothing was written.
            assert!(out.iter().flatten().flatten().all(|x| x.is_nan()));
            return Err((status, last_error()));
        }
        Ok(out)
    }
}

impl Drop for Evaluator {
    fn drop(&mut self) {
        // SAFETY: the handle is looked up, never dereferenced.
        let status = unsafe { tessera_limit_evaluator_destroy(self.0) };
        assert_eq!(status, TesseraStatus::Ok);
    }
}

fn spot_mesh() -> topology::ControlMesh {
    let text =
        std::fs::read_to_string(common::repo().join("assets/spot_control_mesh.obj")).unwrap();
    topology::mesh::obj::parse_obj(&text, "spot").unwrap()
}

/// A face and its (u, v), as on a `# p` line.
type Point = (u32, [f64; 2]);

/// `v` positions and `# p` points of a captured OBJ, in vertex order.
fn captured(path: &std::path::Path) -> Vec<([f64; 3], Point)> {
    let text = std::fs::read_to_string(path).unwrap();
    let nums = |l: &str, skip: usize| -> Vec<f64> {
        l.split_whitespace()
            .skip(skip)
            .map(|x| x.parse().unwrap())
            .collect()
    };
    let v = text
        .lines()
        .filter(|l| l.starts_with("v "))
        .map(|l| nums(l, 1));
    let p = text
        .lines()
        .filter(|l| l.starts_with("# p "))
        .map(|l| nums(l, 2));
    v.zip(p)
        .map(|(v, p)| ([v[0], v[1], v[2]], (p[0] as u32, [p[1], p[2]])))
        .collect()
}

/// Spot's quads evaluate to `limit_point`'s numbers exactly (the same domain); on Loop, the
/// `# p` triangle (u, v) weigh corners 0 and 1, which `tessera limit --uv` gives as
/// (v, 1 − u − v) on the fan triangle.
#[test]
fn limit_evaluation_is_what_tessera_limit_prints() {
    let ctx = Standalone::new();
    let mesh = spot_mesh();
    let adaptive = ctx.evaluator(ctx.spot(TESSERA_TECHNIQUE_ADAPTIVE));
    let quads: Vec<u32> = (0..mesh.num_faces() as u32)
        .filter(|&f| mesh.face(f as usize).len() == 4)
        .step_by(37)
        .collect();
    let points: Vec<(u32, [f64; 2])> = quads
        .iter()
        .enumerate()
        .map(|(i, &f)| (f, [(i % 7) as f64 / 6.0, (i % 5) as f64 / 4.0]))
        .collect();
    let [pos, du, dv, normal] = adaptive.evaluate(&points).unwrap();
    for (i, &(f, [u, v])) in points.iter().enumerate() {
        let want = limit_point(&mesh, LimitScheme::CatmullClark, f as usize, u, v).unwrap();
        assert_eq!(pos[i], want.position, "face {f} ({u}, {v})");
        assert_eq!((du[i], dv[i]), (want.du, want.dv), "face {f} ({u}, {v})");
        assert_eq!(normal[i], want.normal, "face {f} ({u}, {v})");
    }
    // Loop: spot's fan triangulation, as bft draws it.
    let bft = ctx.evaluator(ctx.spot(TESSERA_TECHNIQUE_BFT));
    let (tri, _) = mesh.triangulated();
    let first = |f: usize| -> usize { (0..f).map(|g| mesh.face(g).len() - 2).sum() };
    let (u, v) = (0.25, 0.5);
    for &f in &quads {
        // Below the quad's diagonal: fan triangle 0 (corners 0, 1, 2); (u, v) = (0.5, 0.25)
        // weighs its corners as (0.5, 0.25, 0.25).
        let [pos, ..] = bft.evaluate(&[(f, [v, u])]).unwrap();
        let want = limit_point(&tri, LimitScheme::Loop, first(f as usize), v - u, u).unwrap();
        for (got, want) in pos[0].iter().zip(want.position) {
            assert!((got - want).abs() < 1e-14, "face {f}");
        }
    }
}

/// What the GPU drew, read back through the capture's `# p` lines: bft's Loop limit at every
/// vertex to float rounding; adaptive's Catmull-Clark limit to float rounding on its regular
/// patches, and close on the Gregory end caps around extraordinary vertices.
#[test]
fn limit_evaluation_is_the_captured_vertices_at_their_points() {
    let ctx = Standalone::new();
    let dir = common::scratch("capi-limit-capture");
    for (technique, scheme, name) in [
        (TESSERA_TECHNIQUE_BFT, TESSERA_SCHEME_AUTO, "bft"),
        (TESSERA_TECHNIQUE_ADAPTIVE, TESSERA_SCHEME_AUTO, "adaptive"),
        (
            TESSERA_TECHNIQUE_DOO_SABIN_LIMIT,
            TESSERA_SCHEME_DOO_SABIN,
            "doo-sabin-limit",
        ),
    ] {
        let s = ctx.spot_as(technique, scheme);
        let path = dir.join(format!("{name}.obj"));
        let c_path = CString::new(path.to_str().unwrap()).unwrap();
        let mut frame = frame_desc(160, 120);
        frame.factor = 4.0;
        let mut report = TesseraCaptureReport::default();
        // SAFETY: live locals of the types the call reads and writes.
        let status = unsafe { tessera_capture(ctx.ctx, s, &frame, c_path.as_ptr(), &mut report) };
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        assert_eq!(report.cracks, 0, "{name}: {report:?}");
        let vertices = captured(&path);
        assert_eq!(vertices.len() as u64, report.vertices);
        let points: Vec<(u32, [f64; 2])> = vertices.iter().map(|v| v.1).collect();
        let [pos, ..] = ctx.evaluator(s).evaluate(&points).unwrap();
        let mut lo = [f64::MAX; 3];
        let mut hi = [f64::MIN; 3];
        for (p, _) in &vertices {
            for k in 0..3 {
                lo[k] = lo[k].min(p[k]);
                hi[k] = hi[k].max(p[k]);
            }
        }
        let diag = (0..3).map(|k| (hi[k] - lo[k]).powi(2)).sum::<f64>().sqrt();
        let mut errors: Vec<f64> = vertices
            .iter()
            .zip(&pos)
            .map(|((v, _), e)| (0..3).map(|k| (v[k] - e[k]).abs()).fold(0.0, f64::max) / diag)
            .collect();
        errors.sort_by(f64::total_cmp);
        let (median, worst) = (errors[errors.len() / 2], errors[errors.len() - 1]);
        eprintln!(
            "{name}: {} vertices, |GPU − limit|/diag median {median:.2e}, worst {worst:.2e}",
            errors.len()
        );
        match name {
            "bft" => assert!(worst < 1e-5, "{name}: {worst:.2e}"),
            _ => {
                assert!(median < 1e-6, "{name}: median {median:.2e}");
                assert!(worst < 2e-3, "{name}: worst {worst:.2e}");
            }
        }
    }
}

/// Bad faces and parameters get their codes, naming the point, and no output is written; so
/// do NULL arrays, and handles that are not evaluators.
#[test]
fn bad_points_and_handles_get_codes() {
    let ctx = Standalone::new();
    let s = ctx.spot(TESSERA_TECHNIQUE_FLAT);
    let e = ctx.evaluator(s);
    let mut faces = 0usize;
    let mut scheme = 0;
    // SAFETY: live locals.
    let status = unsafe { tessera_limit_evaluator_info(e.0, &mut faces, &mut scheme) };
    assert_eq!(status, TesseraStatus::Ok);
    assert_eq!(faces, spot_mesh().num_faces());
    // Spot has quads: flat's scheme defaults to Catmull-Clark.
    assert_eq!(scheme, TESSERA_SCHEME_CATMULL_CLARK);
    let good = (0u32, [0.5, 0.5]);
    for (bad, status, needle) in [
        (
            (faces as u32, [0.5, 0.5]),
            TesseraStatus::IndexOutOfRange,
            "out of range",
        ),
        ((0, [f64::NAN, 0.5]), TesseraStatus::NonFinite, "NaN"),
        ((0, [0.5, f64::INFINITY]), TesseraStatus::NonFinite, "inf"),
        ((0, [1.5, 0.5]), TesseraStatus::InvalidArgument, "domain"),
        ((0, [-0.01, 0.5]), TesseraStatus::InvalidArgument, "domain"),
    ] {
        let (got, message) = e.evaluate(&[good, bad]).unwrap_err();
        assert_eq!(got, status, "{message}");
        assert!(
            message.contains("point 1") && message.contains(needle),
            "{status:?}: {message}"
        );
    }
    let mut out = [0.0f64; 3];
    // SAFETY: NULL arrays with a nonzero count are refused before any read.
    let status = unsafe {
        tessera_limit_evaluate(
            e.0,
            null(),
            null(),
            1,
            out.as_mut_ptr(),
            null_mut(),
            null_mut(),
            null_mut(),
        )
    };
    assert_eq!(status, TesseraStatus::NullPointer);
    // No points: nothing to read or write.
    // SAFETY: count 0 reads and writes nothing.
    let status = unsafe {
        tessera_limit_evaluate(
            e.0,
            null(),
            null(),
            0,
            null_mut(),
            null_mut(),
            null_mut(),
            null_mut(),
        )
    };
    assert_eq!(status, TesseraStatus::Ok);
    // A surface where an evaluator is expected, a null one, a destroyed one.
    let as_evaluator = s.cast::<TesseraLimitEvaluator>();
    // SAFETY: handles are looked up, never dereferenced.
    unsafe {
        assert_eq!(
            tessera_limit_evaluator_info(as_evaluator, null_mut(), null_mut()),
            TesseraStatus::InvalidHandle
        );
        assert_eq!(
            tessera_limit_evaluator_info(null(), null_mut(), null_mut()),
            TesseraStatus::NullHandle
        );
    }
    let gone = ctx.evaluator(s);
    let raw = gone.0;
    drop(gone);
    // SAFETY: as above.
    let status = unsafe { tessera_limit_evaluator_destroy(raw) };
    assert_eq!(status, TesseraStatus::DestroyedHandle);
    assert!(last_error().contains("destroyed"), "{}", last_error());
}

/// One evaluator, eight threads evaluating at once: every thread gets the single-threaded
/// numbers.
#[test]
fn one_evaluator_serves_many_threads() {
    let ctx = Standalone::new();
    let e = ctx.evaluator(ctx.spot(TESSERA_TECHNIQUE_ADAPTIVE));
    let n = spot_mesh().num_faces() as u32;
    let points: Vec<(u32, [f64; 2])> = (0..2000u32)
        .map(|i| (i * 13 % n, [0.5, (i % 9) as f64 / 8.0]))
        .map(|(f, [u, v])| {
            // Inside every face's domain: the centre of triangles and n-gons too.
            if spot_mesh_face_size(f) == 4 {
                (f, [u, v])
            } else {
                (f, [0.45, 0.4])
            }
        })
        .collect();
    let want = e.evaluate(&points).unwrap();
    std::thread::scope(|scope| {
        let handles: Vec<_> = (0..8)
            .map(|_| scope.spawn(|| e.evaluate(&points).unwrap()))
            .collect();
        for h in handles {
            assert!(h.join().unwrap() == want);
        }
    });
}

fn spot_mesh_face_size(f: u32) -> usize {
    static MESH: std::sync::OnceLock<topology::ControlMesh> = std::sync::OnceLock::new();
    MESH.get_or_init(spot_mesh).face(f as usize).len()
}

/// An evaluator made from arrays needs no context; one made from a surface evaluates its
/// newest positions (twice the positions, twice the limit: the limit is linear in them).
#[test]
fn evaluators_of_meshes_and_of_moved_surfaces() {
    let positions: Vec<f32> = (0..8u32)
        .flat_map(|i| [(i & 1) as f32, ((i >> 1) & 1) as f32, ((i >> 2) & 1) as f32])
        .collect();
    let indices = [
        0u32, 2, 3, 1, 4, 5, 7, 6, 0, 1, 5, 4, 2, 6, 7, 3, 0, 4, 6, 2, 1, 3, 7, 5,
    ];
    let sizes = [4u32; 6];
    let mesh = TesseraMeshDesc {
        name: c"cube".as_ptr(),
        positions: positions.as_ptr(),
        vertex_count: 8,
        face_sizes: sizes.as_ptr(),
        face_count: 6,
        face_indices: indices.as_ptr(),
        index_count: 24,
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
    };
    let mut raw = null_mut();
    // SAFETY: `mesh`'s arrays are as long as its counts say.
    let status =
        unsafe { tessera_limit_evaluator_create_mesh(&mesh, TESSERA_SCHEME_AUTO, &mut raw) };
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    let cube = Evaluator(raw);
    let [p, ..] = cube.evaluate(&[(2, [0.5, 0.5])]).unwrap();
    let text = "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n\
                f 1 3 4 2\nf 5 6 8 7\nf 1 2 6 5\nf 3 7 8 4\nf 1 5 7 3\nf 2 4 8 6\n";
    let obj = topology::mesh::obj::parse_obj(text, "cube").unwrap();
    let want = limit_point(&obj, LimitScheme::CatmullClark, 2, 0.5, 0.5).unwrap();
    assert_eq!(p[0], want.position);
    // Loop on quads is refused when asked for strictly, as surfaces refuse it.
    let mut raw = null_mut();
    // SAFETY: as above.
    let status =
        unsafe { tessera_limit_evaluator_create_mesh(&mesh, TESSERA_SCHEME_LOOP, &mut raw) };
    assert_eq!(
        status,
        TesseraStatus::Ok,
        "Loop evaluates the fan triangulation"
    );
    drop(Evaluator(raw));

    let ctx = Standalone::new();
    let s = ctx.spot(TESSERA_TECHNIQUE_BFT);
    let points: Vec<(u32, [f64; 2])> = (0..50).map(|f| (f, [0.3, 0.3])).collect();
    let mut count = 0usize;
    // SAFETY: live local.
    unsafe { tessera_surface_info(ctx.ctx, s, &mut count, null_mut(), null_mut()) };
    let mut rest = vec![0f32; 3 * count];
    // SAFETY: `rest` holds 3 * count floats.
    unsafe { tessera_surface_positions(ctx.ctx, s, rest.as_mut_ptr(), count) };
    let evaluate_at = |p: &[f32]| {
        // SAFETY: `p` holds 3 * count floats.
        let status = unsafe { tessera_surface_update_positions(ctx.ctx, s, p.as_ptr(), count) };
        assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
        let [pos, ..] = ctx.evaluator(s).evaluate(&points).unwrap();
        pos
    };
    // The float positions the surface was given (the OBJ's doubles rounded), then twice them.
    let before = evaluate_at(&rest);
    let after = evaluate_at(&rest.iter().map(|x| 2.0 * x).collect::<Vec<_>>());
    for (a, b) in after.iter().zip(&before) {
        assert_eq!(*a, b.map(|x| 2.0 * x));
    }
}

/// `TESSERA_SCHEME_DOO_SABIN` with `TESSERA_TECHNIQUE_AUTO` builds the Doo-Sabin limit surface
/// (`doo-sabin-limit`), and its limit evaluator evaluates the exact Doo-Sabin limit (topology's, in the same face
/// domains): at every face's centre the face's centroid (the limit there), elsewhere what
/// `topology::limit::face_domain::LimitEvaluator::doo_sabin` gives, bit for bit. The scheme under
/// a technique that draws another is refused.
#[test]
fn doo_sabin_surfaces_build_and_evaluate_the_exact_limit() {
    let c = Standalone::new();
    let mut d = surface_desc(TESSERA_TECHNIQUE_AUTO);
    d.scheme = TESSERA_SCHEME_DOO_SABIN;
    let mut s = null_mut();
    // SAFETY: NULL text builds the embedded mesh; `d` and `s` are live locals.
    let status = unsafe { tessera_surface_create_obj(c.ctx, null(), 0, null(), &d, &mut s) };
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    let mut e = null_mut();
    // SAFETY: `s` is live; `e` is a live local.
    let status = unsafe { tessera_limit_evaluator_create(c.ctx, s, &mut e) };
    assert_eq!(status, TesseraStatus::Ok, "{}", last_error());
    let ev = Evaluator(e);
    let mesh = spot_mesh();
    let cpu = topology::limit::face_domain::LimitEvaluator::doo_sabin(&mesh).unwrap();
    let mut points = Vec::new();
    for f in 0..mesh.num_faces() as u32 {
        let n = mesh.face(f as usize).len() as u32;
        let corners: Vec<[f64; 2]> = (0..n)
            .map(|k| topology::limit::face_domain::face_corner_uv(n, k))
            .collect();
        let centre = corners.iter().fold([0.0; 2], |a, c| {
            [a[0] + c[0] / n as f64, a[1] + c[1] / n as f64]
        });
        points.push((f, centre));
        points.push((
            f,
            [
                0.7 * corners[0][0] + 0.3 * centre[0],
                0.7 * corners[0][1] + 0.3 * centre[1],
            ],
        ));
    }
    let [positions, _, _, normals] = ev.evaluate(&points).unwrap();
    let mut centres = 0;
    for (i, &(f, [u, v])) in points.iter().enumerate() {
        let want = cpu.evaluate(f, u, v).unwrap();
        assert_eq!(positions[i], want.position, "point {i}");
        assert_eq!(normals[i], want.normal, "point {i}");
        if i % 2 == 0 {
            let face = mesh.face(f as usize);
            let centroid: Vec<f64> = (0..3)
                .map(|k| {
                    face.iter()
                        .map(|&x| mesh.positions[x as usize][k])
                        .sum::<f64>()
                        / face.len() as f64
                })
                .collect();
            for k in 0..3 {
                assert!(
                    (positions[i][k] - centroid[k]).abs() < 1e-9,
                    "face {f} centre"
                );
            }
            centres += 1;
        }
    }
    assert_eq!(centres, mesh.num_faces());
    let mut scheme = 0;
    // SAFETY: `e` is live; `scheme` a live local.
    let status = unsafe { tessera_limit_evaluator_info(e, null_mut(), &mut scheme) };
    assert_eq!(
        (status, scheme),
        (TesseraStatus::Ok, TESSERA_SCHEME_DOO_SABIN)
    );
    drop(ev);
    // SAFETY: `s` is live and destroyed once.
    let status = unsafe { tessera_surface_destroy(c.ctx, s) };
    assert_eq!(status, TesseraStatus::Ok);
    let mut d = surface_desc(TESSERA_TECHNIQUE_ADAPTIVE);
    d.scheme = TESSERA_SCHEME_DOO_SABIN;
    let mut s = null_mut();
    // SAFETY: as above.
    let status = unsafe { tessera_surface_create_obj(c.ctx, null(), 0, null(), &d, &mut s) };
    assert_eq!(status, TesseraStatus::Unsupported, "{}", last_error());
    assert!(s.is_null());
}
