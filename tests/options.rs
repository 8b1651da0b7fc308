//! OpenSubdiv's option set on every technique: the table of docs/options.md, cell by cell.
//!
//! Each column is one option, shown on one of OpenSubdiv's shapes for it (a Catmull-Clark
//! shape and a Loop one) and compared with the same shape without it. Each cell says what a
//! technique does with the option, and the test checks it on the GPU's own output, captured,
//! validation on:
//! - **exact**: every captured vertex is the exact limit of the technique's scheme at its own
//!   domain point (`topology::limit`), within 1e-5 of the diagonal (on the B-spline patches of
//!   the planned techniques; their end caps are reported);
//! - **approximated**: the same comparison, reported and held to the cell's bound;
//! - **ignored**: the capture is bit-identical to the capture without the option;
//! - **refused**: the build fails with the named error.
//!
//! On the columns that make holes every drawn cell also checks that no captured vertex lies in
//! a hole. The docs table is checked against this one, cell kind by cell kind.
mod common;

use common::Gpu;
use tessera::tess::gpu::bindings::ADAPTIVE_KIND_REGULAR;
use tessera::tess::techniques::{self, TechniqueInfo};
use tessera::tess::{BuildOptions, Capturer, Context, FrameParams, TechniqueId};
use tessera::topology::limit::face_domain::LimitEvaluator;
use tessera::topology::mesh::VertexCorner;
use tessera::topology::rules::options::{
    BoundaryInterpolation, CreaseMethod, FVarLinearInterpolation, TriangleSubdivision,
};
use tessera::topology::{load_obj, ControlMesh, Scheme};
use tessera::vk_core::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 64,
    height: 64,
};

/// One option: its name in the table, the shapes showing it, and how to take it away.
struct Column {
    name: &'static str,
    catmark: &'static str,
    loop_: &'static str,
    /// Sets the option where the shape's file does not (applied to both shapes).
    with: fn(&mut ControlMesh, Scheme),
    /// The same shape without the option.
    without: fn(&mut ControlMesh),
    /// The option makes holes (the cells also check that holes are not drawn).
    holes: bool,
    /// The option shapes texture coordinates: the cells compare them, not positions.
    texcoords: bool,
}

fn nothing(_: &mut ControlMesh, _: Scheme) {}

const COLUMNS: [Column; 10] = [
    Column {
        name: "boundary: edges only",
        catmark: "catmark_tent",
        loop_: "loop_saddle_edgeonly",
        with: nothing,
        without: |m| m.options.boundary = BoundaryInterpolation::EdgesAndCorners,
        holes: false,
        texcoords: false,
    },
    Column {
        name: "boundary: edges and corners",
        catmark: "catmark_edgecorner",
        loop_: "loop_saddle_edgecorner",
        with: nothing,
        without: |m| m.options.boundary = BoundaryInterpolation::EdgesOnly,
        holes: false,
        texcoords: false,
    },
    Column {
        name: "boundary: none",
        catmark: "catmark_edgenone",
        loop_: "loop_triangle_edgenone",
        with: nothing,
        without: |m| {
            m.holes.clear();
            m.options.boundary = BoundaryInterpolation::EdgesOnly;
        },
        holes: true,
        texcoords: false,
    },
    Column {
        name: "holes",
        catmark: "catmark_hole_test1",
        loop_: "loop_cube",
        with: |m, scheme| {
            if scheme == Scheme::Loop {
                m.holes = vec![3, 17];
            }
        },
        without: |m| m.holes.clear(),
        holes: true,
        texcoords: false,
    },
    Column {
        name: "semi-sharp creases",
        catmark: "catmark_cube_creases0",
        loop_: "loop_cube_creases0",
        with: nothing,
        without: |m| m.creases.clear(),
        holes: false,
        texcoords: false,
    },
    Column {
        name: "Chaikin creasing",
        catmark: "catmark_chaikin1",
        loop_: "loop_chaikin1",
        with: nothing,
        without: |m| m.options.crease_method = CreaseMethod::Uniform,
        holes: false,
        texcoords: false,
    },
    Column {
        name: "infinitely sharp creases",
        catmark: "catmark_inf_crease0",
        loop_: "loop_cube_creases1",
        with: |m, _| {
            for c in &mut m.creases {
                c.sharpness = 10.0;
            }
        },
        without: |m| m.creases.clear(),
        holes: false,
        texcoords: false,
    },
    Column {
        name: "corners",
        catmark: "catmark_cube_corner1",
        loop_: "loop_cube",
        with: |m, scheme| {
            if scheme == Scheme::Loop {
                m.corners = vec![
                    VertexCorner {
                        vertex: 0,
                        sharpness: 2.0,
                    },
                    VertexCorner {
                        vertex: 5,
                        sharpness: 10.0,
                    },
                ];
            }
        },
        without: |m| m.corners.clear(),
        holes: false,
        texcoords: false,
    },
    Column {
        name: "smooth triangles",
        catmark: "catmark_pyramid",
        loop_: "loop_cube",
        with: |m, _| m.options.triangle_subdivision = TriangleSubdivision::Smooth,
        without: |m| m.options.triangle_subdivision = TriangleSubdivision::Catmark,
        holes: false,
        texcoords: false,
    },
    Column {
        name: "face-varying: none",
        catmark: "catmark_cube",
        loop_: "loop_cube",
        with: |m, _| {
            common::with_curved_layout(m);
            m.options.fvar_interpolation = FVarLinearInterpolation::None;
        },
        without: |m| m.options.fvar_interpolation = FVarLinearInterpolation::All,
        holes: false,
        texcoords: true,
    },
];

/// What a technique does with an option.
#[derive(Clone, Copy, Debug)]
enum Cell {
    Exact,
    /// What it draws instead, and the bound over the diagonal its vertices keep from the
    /// exact limit at their own points.
    Approximated(&'static str, f64),
    /// Why the option does not change what it draws.
    Ignored(&'static str),
    /// A phrase of the named error.
    Refused(&'static str),
}

impl Cell {
    fn kind(self) -> &'static str {
        match self {
            Cell::Exact => "exact",
            Cell::Approximated(..) => "approximated",
            Cell::Ignored(_) => "ignored",
            Cell::Refused(_) => "refused",
        }
    }

    /// What is drawn instead, or why the option changes nothing.
    fn note(self) -> &'static str {
        match self {
            Cell::Approximated(what, _) | Cell::Ignored(what) => what,
            Cell::Exact | Cell::Refused(_) => "",
        }
    }
}

const INTERPOLANT: Cell = Cell::Ignored("interpolates the control mesh: not a subdivision surface");
const CATMARK_RULE: Cell = Cell::Ignored("a Catmull-Clark rule");

const NO_TEXCOORDS: Cell = Cell::Ignored("draws no texture coordinates");

/// The row of technique `id`, one cell per column of [`COLUMNS`].
fn row(id: TechniqueId) -> [Cell; 10] {
    use Cell::*;
    let holes = Exact;
    match id.name() {
        "flat" | "phong" | "pn" => [
            INTERPOLANT,
            INTERPOLANT,
            holes,
            holes,
            INTERPOLANT,
            INTERPOLANT,
            INTERPOLANT,
            INTERPOLANT,
            INTERPOLANT,
            NO_TEXCOORDS,
        ],
        "bft" | "cpu" => [
            Exact,
            Exact,
            Exact,
            Exact,
            Exact,
            Exact,
            Exact,
            Exact,
            CATMARK_RULE,
            NO_TEXCOORDS,
        ],
        "adaptive" => [Exact; 10],
        "cpu-catmark" => [
            Exact,
            Exact,
            Exact,
            Exact,
            Exact,
            Exact,
            Exact,
            Exact,
            Exact,
            NO_TEXCOORDS,
        ],
        // One patch per base face: the bounds are those measured on the column's shape at 4
        // segments, with a margin (docs/options.md has the figures).
        "gregory" | "acc" => [2e-3, 1e-5, 1e-3, 1e-2, 4e-2, 3e-2, 4e-2, 0.15, 1e-2, 2e-2]
            .map(|bound| Approximated("one patch per base face", bound)),
        "doo-sabin" | "cpu-doo-sabin" | "vertex-patches" => [
            Approximated("the refined mesh at depth D", 6e-2),
            Ignored("the boundary is the quadratic B-spline of the boundary polygon"),
            Refused("has no holes"),
            Refused("has no holes"),
            Refused("has no creases"),
            Refused("has no creases"),
            Refused("has no creases"),
            Refused("has no sharp vertices"),
            CATMARK_RULE,
            NO_TEXCOORDS,
        ],
        "doo-sabin-limit" => [
            Exact,
            Ignored("the boundary is the quadratic B-spline of the boundary polygon"),
            Refused("has no holes"),
            Refused("has no holes"),
            Refused("has no creases"),
            Refused("has no creases"),
            Refused("has no creases"),
            Refused("has no sharp vertices"),
            CATMARK_RULE,
            NO_TEXCOORDS,
        ],
        other => panic!("{other}: no row in the option table"),
    }
}

fn shape(name: &str) -> ControlMesh {
    load_obj(common::data(&format!(
        "tests/data/opensubdiv/shapes/{name}.obj"
    )))
    .unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// The column's shape for a technique of `scheme`, with the option and without it.
fn shapes(column: &Column, scheme: Option<Scheme>) -> (ControlMesh, ControlMesh, Scheme) {
    let scheme = scheme.unwrap_or(Scheme::CatmullClark);
    let name = match scheme {
        Scheme::Loop => column.loop_,
        _ => column.catmark,
    };
    let mut with = shape(name);
    (column.with)(&mut with, scheme);
    let mut without = with.clone();
    (column.without)(&mut without);
    assert_ne!(with, without, "{}: the option changes nothing", column.name);
    (with, without, scheme)
}

/// A capture's corners: (position bits, patch, domain bits, flags) for bit comparisons, and
/// the records themselves.
struct Captured {
    soup: tessera::tess::capture::CapturedSoup,
    technique: Box<dyn tessera::tess::Technique>,
}

fn capture(
    ctx: &mut Context,
    capturer: &Capturer,
    info: &TechniqueInfo,
    mesh: &ControlMesh,
) -> Result<Captured, String> {
    let built = techniques::build(
        ctx,
        info.id,
        mesh,
        &BuildOptions {
            name: "option shape".into(),
            tangents: info.features.geometric_normals,
            ..BuildOptions::default()
        },
    )
    .map_err(|e| e.to_string())?;
    let mut technique = built.technique;
    let (soup, _) = capturer
        .capture(ctx, technique.as_mut(), &FrameParams::uniform(4.0), EXTENT)
        .map_err(|e| e.to_string())?;
    Ok(Captured { soup, technique })
}

fn bits(c: &Captured) -> Vec<[u32; 7]> {
    c.soup
        .records
        .iter()
        .map(|r| {
            let p = r.position.map(f32::to_bits);
            let d = r.domain.map(f32::to_bits);
            [p[0], p[1], p[2], d[0], d[1], r.patch, r.flags]
        })
        .collect()
}

/// (worst distance over the diagonal on the vertices held exact, worst elsewhere): what each
/// captured vertex shows against the exact limit of `scheme` at the vertex's own point. The
/// planned techniques hold their B-spline patches exact; the others every vertex.
/// - positions (`texcoords` false): the captured position against `mesh`'s limit;
/// - texture coordinates (`texcoords` true): the coordinate the technique shows there
///   (`Technique::texcoord`, the shaders' evaluation on the host) against the Catmull-Clark
///   limit of the layout taken as positions (mode `none`, the layout's topology the mesh's),
///   over the layout's diagonal.
fn limit_deviation(
    c: &Captured,
    mesh: &ControlMesh,
    scheme: Scheme,
    planned: bool,
    texcoords: bool,
) -> (f64, f64) {
    let (surface, scheme) = if texcoords {
        (common::uvs_as_positions(mesh), Scheme::CatmullClark)
    } else {
        (mesh.clone(), scheme)
    };
    let limit = LimitEvaluator::of_scheme(&surface, scheme).expect("exact limit");
    let diagonal = surface.bbox_diagonal();
    let (mut held, mut elsewhere) = (0.0f64, 0.0f64);
    for r in &c.soup.records {
        let at = c
            .technique
            .face_point(r.patch, r.domain)
            .unwrap_or_else(|| panic!("a vertex of patch {} maps to no base face", r.patch));
        let shown = if texcoords {
            let uv = c
                .technique
                .texcoord(r.patch, r.domain, false)
                .unwrap_or_else(|| panic!("patch {} shows no texture coordinate", r.patch));
            [uv[0], uv[1], 0.0]
        } else {
            r.position.map(f64::from)
        };
        let e = limit
            .evaluate(at.face, at.u as f64, at.v as f64)
            .expect("limit");
        let d = (0..3)
            .map(|k| (shown[k] - e.position[k]).abs())
            .fold(0.0, f64::max)
            / diagonal;
        if !planned || r.flags & 15 == ADAPTIVE_KIND_REGULAR {
            held = held.max(d);
        } else {
            elsewhere = elsewhere.max(d);
        }
    }
    (held, elsewhere)
}

/// No captured vertex lies inside a hole (a vertex on its border belongs to a neighbour too;
/// at four segments every drawn face has vertices inside it). The holes of the option shapes
/// are triangles and quads.
fn holes_not_drawn(c: &Captured, mesh: &ControlMesh) -> Result<(), String> {
    const EPS: f32 = 1e-6;
    for r in &c.soup.records {
        let Some(at) = c.technique.face_point(r.patch, r.domain) else {
            continue;
        };
        if !mesh.holes.contains(&at.face) {
            continue;
        }
        let inside = match mesh.face(at.face as usize).len() {
            3 => at.u > EPS && at.v > EPS && at.u + at.v < 1.0 - EPS,
            4 => [at.u, at.v].iter().all(|&x| EPS < x && x < 1.0 - EPS),
            n => panic!("hole face {} has {n} sides", at.face),
        };
        if inside {
            return Err(format!(
                "a vertex is drawn inside hole face {} at ({}, {})",
                at.face, at.u, at.v
            ));
        }
    }
    Ok(())
}

/// Checks one cell; the figure it measured, for the report.
fn check_cell(
    ctx: &mut Context,
    capturer: &Capturer,
    info: &TechniqueInfo,
    column: &Column,
    cell: Cell,
) -> Result<String, String> {
    let (with, without, scheme) = shapes(column, info.scheme);
    let drawn = capture(ctx, capturer, info, &with);
    let drawn = match (cell, drawn) {
        (Cell::Refused(phrase), Err(e)) if e.contains(phrase) => return Ok(e),
        (Cell::Refused(_), Err(e)) => return Err(format!("refused with another error: {e}")),
        (Cell::Refused(_), Ok(_)) => return Err("drawn, not refused".into()),
        (_, Err(e)) => return Err(format!("refused: {e}")),
        (_, Ok(c)) => c,
    };
    if drawn.soup.records.is_empty() {
        return Err("nothing captured".into());
    }
    if column.holes {
        holes_not_drawn(&drawn, &with)?;
    }
    let planned = info.features.isolation || info.features.single_pass;
    match cell {
        Cell::Ignored(_) => {
            let plain = capture(ctx, capturer, info, &without)?;
            if bits(&drawn) != bits(&plain) {
                return Err("the capture differs from the one without the option".into());
            }
            let shown = |r: &tessera::tess::CaptureRecord| {
                drawn.technique.texcoord(r.patch, r.domain, false).is_some()
            };
            if column.texcoords && drawn.soup.records.iter().any(shown) {
                return Err("it shows texture coordinates".into());
            }
            Ok(format!(
                "{} corners, bit-identical without it",
                drawn.soup.records.len()
            ))
        }
        Cell::Exact if info.scheme.is_none() => {
            let plain = capture(ctx, capturer, info, &without)?;
            if drawn.soup.records.len() >= plain.soup.records.len() {
                return Err("the holes drew as many triangles as the faces".into());
            }
            Ok(format!(
                "{} of {} corners drawn",
                drawn.soup.records.len(),
                plain.soup.records.len()
            ))
        }
        Cell::Exact => {
            let (held, elsewhere) =
                limit_deviation(&drawn, &with, scheme, planned, column.texcoords);
            if held > 1e-5 {
                return Err(format!("{held:.1e} from the exact limit"));
            }
            Ok(if planned {
                format!("B-spline patches {held:.1e}, end caps {elsewhere:.1e}")
            } else {
                format!("{held:.1e}")
            })
        }
        Cell::Approximated(_, bound) => {
            let (held, elsewhere) =
                limit_deviation(&drawn, &with, scheme, planned, column.texcoords);
            let worst = held.max(elsewhere);
            if worst > bound {
                return Err(format!(
                    "{worst:.1e} from the exact limit, over {bound:.0e}"
                ));
            }
            Ok(format!("{worst:.1e}"))
        }
        Cell::Refused(_) => unreachable!("handled above"),
    }
}

#[test]
fn every_cell_of_the_option_table_holds() {
    let gpu = Gpu::new();
    let mut failures = Vec::new();
    {
        let mut ctx = Context::offscreen(gpu.device()).unwrap();
        let capturer = Capturer::new(&ctx).unwrap();
        for info in techniques::registry() {
            let cells = row(info.id);
            for (column, cell) in COLUMNS.iter().zip(cells) {
                let what = format!(
                    "{} × {}: {} {}",
                    info.id,
                    column.name,
                    cell.kind(),
                    cell.note()
                );
                match check_cell(&mut ctx, &capturer, info, column, cell) {
                    Ok(figure) => println!("{what}: {figure}"),
                    Err(e) => failures.push(format!("{what}: {e}")),
                }
            }
        }
    }
    assert!(failures.is_empty(), "{failures:#?}");
    assert!(gpu.errors().is_empty(), "{:#?}", gpu.errors());
}

/// docs/options.md's table has a row per technique with the kind of each cell as above.
#[test]
fn the_docs_table_is_this_table() {
    let doc = std::fs::read_to_string(common::data("docs/options.md")).unwrap();
    let header: Vec<&str> = std::iter::once("technique")
        .chain(COLUMNS.iter().map(|c| c.name))
        .collect();
    let rows: Vec<Vec<String>> = doc
        .lines()
        .filter(|l| l.starts_with('|') && !l.starts_with("|-"))
        .map(|l| {
            l.trim_matches('|')
                .split('|')
                .map(|c| c.trim().to_string())
                .collect()
        })
        .collect();
    let table_header = rows
        .iter()
        .find(|r| r.first().is_some_and(|c| c == "technique"))
        .expect("the table's header");
    assert_eq!(table_header, &header);
    for info in techniques::registry() {
        let name = format!("`{}`", info.id);
        let doc_row = rows
            .iter()
            .find(|r| r.first() == Some(&name))
            .unwrap_or_else(|| panic!("docs/options.md has no row for {name}"));
        for ((column, cell), text) in COLUMNS.iter().zip(row(info.id)).zip(&doc_row[1..]) {
            assert!(
                text.to_lowercase().starts_with(cell.kind()),
                "docs/options.md, {name} × {}: '{text}' should say {}",
                column.name,
                cell.kind()
            );
        }
    }
}
