//! `tessera subdivide` and `tessera limit`: the CPU reference, from the command line.
use crate::cli::{LimitArgs, SubdivideArgs};
use anyhow::{bail, Context, Result};
use topology::eval::{limit_point, LimitScheme, LocalMesh};
use topology::{refine_uniform, ControlMesh, Level, Scheme};

/// Clap's value parser for `--scheme`: topology's one scheme parser.
pub fn parse_scheme(s: &str) -> Result<Scheme, String> {
    s.parse::<Scheme>().map_err(|e| e.to_string())
}

/// Limit positions of every vertex of `level` ([`LocalMesh::vertex_limit_exact`]: masks, or
/// the exact evaluator next to semi-sharp features). Refining the whole level further instead
/// would cost 4× per extra level, and sharpness just below 10 needs 9 more.
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
            let p = lm
                .vertex_limit_exact(v)
                .with_context(|| format!("limit position of vertex {v}"))?;
            Ok([p[0], p[1], p[2]])
        })
        .collect()
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
