//! `tessera subdivide` and `tessera limit`: the CPU reference, from the command line.
use crate::cli::{LimitArgs, SubdivideArgs};
use anyhow::{bail, Context, Result};
use topology::eval::{limit_point, LimitScheme, LocalMesh};
use topology::{refine_uniform, ControlMesh, Level, Scheme};

/// Clap's value parser for `--scheme`: topology's one scheme parser.
pub fn parse_scheme(s: &str) -> Result<Scheme, String> {
    s.parse::<Scheme>().map_err(|e| e.to_string())
}

/// Limit positions of every vertex of `level`: by the vertex's limit mask where no semi-sharp
/// feature is left there, else by the exact evaluator at the vertex's corner of one of its
/// faces. The evaluator refines only that face's neighbourhood until the sharpness has decayed
/// (a mask applied at this level, as OpenSubdiv's `PrimvarRefiner::Limit` does, treats a
/// semi-sharp crease as infinitely sharp and misses the limit). Refining the whole level
/// instead would cost 4× per extra level, and sharpness just below 10 needs 9 more.
fn limit_positions(level: &Level, base: &ControlMesh, scheme: Scheme) -> Result<Vec<[f64; 3]>> {
    let ls = match scheme {
        Scheme::Bilinear => return Ok(level.positions.clone()),
        Scheme::DooSabin => bail!(
            "--limit is supported for loop and catmull-clark (Doo-Sabin has no limit masks here)"
        ),
        other => LimitScheme::try_from(other)?,
    };
    let lm = LocalMesh::from_refined_level(level, ls, &base.options)?;
    (0..lm.num_vertices() as u32)
        .map(|v| {
            let p = match lm.vertex_limit_position(v) {
                Some(p) => p,
                None => corner_limit(&lm, v)?,
            };
            Ok([p[0], p[1], p[2]])
        })
        .collect()
}

/// The exact limit at vertex `v` of `lm`, evaluated at its corner of its first face.
fn corner_limit(lm: &LocalMesh, v: u32) -> Result<Vec<f64>> {
    const QUAD: [(f64, f64); 4] = [(0.0, 0.0), (1.0, 0.0), (1.0, 1.0), (0.0, 1.0)];
    const TRIANGLE: [(f64, f64); 3] = [(0.0, 0.0), (1.0, 0.0), (0.0, 1.0)];
    let f = lm
        .vertex_faces(v)
        .next()
        .with_context(|| format!("vertex {v} belongs to no face"))? as usize;
    let corners = lm.face(f);
    let corner = corners
        .iter()
        .position(|&w| w == v)
        .with_context(|| format!("vertex {v} is not a corner of face {f}"))?;
    let sample = match (lm.scheme, corners.len()) {
        (LimitScheme::CatmullClark, 4) => {
            let (a, b) = QUAD[corner];
            lm.evaluate(f, a, b)
        }
        // Sub-quad `corner` of an n-gon has the vertex at its (0, 0).
        (LimitScheme::CatmullClark, _) => lm.evaluate_subface(f, corner, 0.0, 0.0),
        (LimitScheme::Loop, 3) => {
            let (a, b) = TRIANGLE[corner];
            lm.evaluate(f, a, b)
        }
        (LimitScheme::Loop, n) => bail!("face {f} has {n} corners: Loop needs triangles"),
    };
    Ok(sample
        .with_context(|| format!("limit position of vertex {v}"))?
        .position)
}

pub fn subdivide(a: SubdivideArgs) -> Result<()> {
    let mesh = topology::load_obj(&a.input)?;
    if a.level > 6 {
        bail!("--level {} is above 6 (meshes grow 4× per level)", a.level);
    }
    let r = refine_uniform(&mesh, a.scheme, a.level)
        .with_context(|| format!("{}", a.input.display()))?;
    let level = r.level(a.level);
    let positions = if a.limit {
        limit_positions(level, &mesh, a.scheme)?
    } else {
        level.positions.clone()
    };
    let (offsets, verts) = level.topology.face_tables();
    let file = std::fs::File::create(&a.output)
        .with_context(|| format!("creating {}", a.output.display()))?;
    topology::write_obj(file, &positions, offsets, verts)
        .with_context(|| format!("writing {}", a.output.display()))?;
    println!(
        "wrote {}: {} vertices, {} faces (level {}, {:?}{})",
        a.output.display(),
        positions.len(),
        level.num_faces(),
        a.level,
        a.scheme,
        if a.limit { ", limit positions" } else { "" }
    );
    Ok(())
}

pub fn limit(a: LimitArgs) -> Result<()> {
    let mesh = topology::load_obj(&a.input)?;
    let scheme: LimitScheme = a.scheme.parse()?;
    let p = limit_point(&mesh, scheme, a.face, a.uv.0, a.uv.1)
        .with_context(|| a.input.display().to_string())?;
    println!("{p}");
    Ok(())
}
