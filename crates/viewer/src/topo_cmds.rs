//! `tessera subdivide` and `tessera limit`: the CPU reference, from the command line.
//!
//! Options are checked before the mesh is read; errors about the mesh use the OBJ's 1-based
//! numbers ([`topology::TopologyError::in_file`]); nothing non-finite is written or printed.
use crate::cli::{LimitArgs, SubdivideArgs};
use anyhow::{bail, Context, Result};
use topology::eval::{limit_point, EvalError, LimitScheme, LocalMesh};
use topology::{refine_uniform, ControlMesh, Level, ObjLines, Scheme};

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

/// The first vertex (1-based, as in the written OBJ) with a NaN or infinite coordinate.
fn non_finite(positions: &[[f64; 3]]) -> Option<usize> {
    positions
        .iter()
        .position(|p| !p.iter().all(|c| c.is_finite()))
        .map(|i| i + 1)
}

/// The OBJ at `path` as read (an empty mesh included: refining it is not an error here), or the
/// embedded spot control mesh, with the lines of its elements.
fn read_mesh(path: Option<&std::path::Path>) -> Result<(ControlMesh, ObjLines)> {
    match path {
        Some(p) => Ok(topology::load_obj_with_lines(p)?),
        None => crate::commands::load_mesh_with_lines(None),
    }
}

pub fn subdivide(a: SubdivideArgs) -> Result<()> {
    if a.level > 6 {
        bail!(
            "--level {}: give a level from 0 to 6 (meshes grow 4× per level)",
            a.level
        );
    }
    let name = crate::commands::mesh_name(a.input.as_deref());
    let (mesh, lines) = read_mesh(a.input.as_deref())?;
    let r = refine_uniform(&mesh, a.scheme, a.level).map_err(|e| lines.locate(e, &mesh, &name))?;
    let level = r.level(a.level);
    let positions = if a.limit {
        limit_positions(level, &mesh, a.scheme)?
    } else {
        level.positions.clone()
    };
    if let Some(v) = non_finite(&positions) {
        bail!(
            "{name}: level {} vertex {v} is not finite; nothing written",
            a.level
        );
    }
    let (offsets, verts) = level.topology.face_tables();
    tess::output::write_file(&a.output, |w| {
        topology::write_obj(w, &positions, offsets, verts)
    })?;
    out!(
        "wrote {}: {} vertices, {} faces (level {}, {}{})",
        a.output.display(),
        positions.len(),
        level.num_faces(),
        a.level,
        a.scheme,
        if a.limit { ", limit positions" } else { "" }
    );
    Ok(())
}

/// An evaluation error about a mesh read from `name`, in the OBJ's 1-based face numbers (and
/// the line at fault, from `lines`).
fn eval_in_file(e: EvalError, name: &str, mesh: &ControlMesh, lines: &ObjLines) -> anyhow::Error {
    match e {
        EvalError::Topology(t) => lines.locate(t, mesh, name).into(),
        EvalError::ParamOutOfRange { u, v } => anyhow::anyhow!(
            "--uv {},{}: outside the face's domain (a quad's is 0 to 1 in u and v; a \
             triangle's u, v ≥ 0 with u + v ≤ 1)",
            topology::error::number(u),
            topology::error::number(v)
        ),
        EvalError::FaceSize {
            face,
            size,
            scheme,
            need,
        } => anyhow::anyhow!(
            "{name}: face {} has {size} corners; {} evaluation needs {need}",
            face + 1,
            scheme.scheme()
        ),
        other => anyhow::Error::new(other).context(name.to_string()),
    }
}

pub fn limit(a: LimitArgs) -> Result<()> {
    let scheme: LimitScheme = a
        .scheme
        .parse()
        .map_err(|e| anyhow::anyhow!("--scheme {}: {e}", a.scheme))?;
    let name = crate::commands::mesh_name(a.input.as_deref());
    let (mesh, lines) = read_mesh(a.input.as_deref())?;
    let faces = mesh.num_faces();
    if a.face == 0 || a.face > faces {
        bail!(
            "--face {}: {name} has faces 1 to {faces} (numbered as its `f` lines, from 1)",
            a.face
        );
    }
    let p = limit_point(&mesh, scheme, a.face - 1, a.uv.0, a.uv.1)
        .map_err(|e| eval_in_file(e, &name, &mesh, &lines))?;
    if non_finite(&[p.position, p.du, p.dv, p.normal]).is_some() {
        bail!(
            "{name}: the limit at face {} ({}, {}) is not finite",
            a.face,
            topology::error::number(a.uv.0),
            topology::error::number(a.uv.1)
        );
    }
    out!("{p}");
    Ok(())
}
