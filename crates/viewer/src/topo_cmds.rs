//! `tessera subdivide` and `tessera limit`: the CPU reference, from the command line.
//!
//! Options are checked before the mesh is read; errors about the mesh use the OBJ's 1-based
//! numbers ([`topology::TopologyError::in_file`]); nothing non-finite is written or printed.
use crate::cli::{LimitArgs, SubdivideArgs};
use anyhow::{bail, Context, Result};
use topology::limit::eval::{limit_point, EvalError, LimitScheme, LocalMesh};
use topology::mesh::manifold::ManifoldSplit;
use topology::mesh::obj::ObjLines;
use topology::refine::{refine_uniform, Level};
use topology::{ControlMesh, Scheme};

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
            // A vertex no face uses has no surface: it keeps its position (as in OpenSubdiv).
            if level.topology.vertex_faces(v as usize).is_empty() {
                return Ok(level.positions[v as usize]);
            }
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

/// The OBJ or USD file at `path` as read (an empty mesh included: refining it is not an error here), or the
/// embedded spot control mesh, with the lines of its elements.
fn read_mesh(path: Option<&std::path::Path>) -> Result<(ControlMesh, ObjLines)> {
    match path {
        Some(p) if topology::mesh::usd::is_usd_path(p) => {
            Ok((topology::mesh::usd::load_usd(p)?, ObjLines::default()))
        }
        Some(p) => Ok(topology::mesh::obj::load_obj_with_lines(p)?),
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
    // A non-manifold mesh is refined through its manifold split, as every subdivision technique
    // draws it: the output has one vertex per copy (coincident where the sheets meet).
    let split = ManifoldSplit::of(&mesh).map_err(|e| lines.locate(e, &mesh, &name))?;
    if split.report.any() {
        eprintln!("{name}: {}", split.report.summary());
    }
    let mesh = split.mesh;
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
        topology::mesh::obj::write_obj(w, &positions, offsets, verts)
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
    let points = match &a.points {
        Some(path) => Some(read_points(path)?),
        None => None,
    };
    let (mesh, lines) = read_mesh(a.input.as_deref())?;
    if let Some((points, point_lines)) = points {
        let path = a.points.as_deref().unwrap_or(std::path::Path::new(""));
        return limit_points(
            &a,
            (&mesh, &lines),
            scheme,
            &name,
            path,
            (&points, &point_lines),
        );
    }
    let (Some(face), Some(uv)) = (a.face, a.uv) else {
        bail!("--face and --uv, or --points, say where to evaluate");
    };
    let faces = mesh.num_faces();
    if face == 0 || face > faces {
        bail!("--face {face}: {name} has faces 1 to {faces} (numbered as its `f` lines, from 1)");
    }
    let p = limit_point(&mesh, scheme, face - 1, uv.0, uv.1)
        .map_err(|e| eval_in_file(e, &name, &mesh, &lines))?;
    if non_finite(&[p.position, p.du, p.dv, p.normal]).is_some() {
        bail!(
            "{name}: the limit at face {face} ({}, {}) is not finite",
            topology::error::number(uv.0),
            topology::error::number(uv.1)
        );
    }
    out!("{p}");
    Ok(())
}

/// Statements of an OBJ that a points file skips (so an exported OBJ is a points file).
const OBJ_STATEMENTS: [&str; 10] = ["v", "vn", "vt", "f", "l", "o", "g", "s", "usemtl", "mtllib"];

/// A face (from 0) and its domain coordinates, as on a `# p` line.
type FacePoint = (u32, [f64; 2]);

/// The points of a `--points` file and the 1-based line of each.
fn read_points(path: &std::path::Path) -> Result<(Vec<FacePoint>, Vec<usize>)> {
    let text = std::fs::read_to_string(path)
        .with_context(|| format!("--points {}: cannot read it", path.display()))?;
    let (mut points, mut lines) = (Vec::new(), Vec::new());
    for (i, line) in text.lines().enumerate() {
        let line = line.trim();
        let words = match line.strip_prefix("# p ") {
            Some(rest) => rest,
            None if line.is_empty() || line.starts_with('#') => continue,
            None if line
                .split_whitespace()
                .next()
                .is_some_and(|w| OBJ_STATEMENTS.contains(&w)) =>
            {
                continue
            }
            None => line,
        };
        let at = || format!("{}:{}", path.display(), i + 1);
        let w: Vec<&str> = words.split_whitespace().collect();
        let [f, u, v] = w[..] else {
            bail!(
                "{}: expected `F U V` (a face from 0 and its domain coordinates), found {line:?}",
                at()
            );
        };
        let face: u32 = f
            .parse()
            .map_err(|_| anyhow::anyhow!("{}: face {f:?} is not a number from 0", at()))?;
        let coord = |x: &str| -> Result<f64> {
            x.parse()
                .map_err(|_| anyhow::anyhow!("{}: {x:?} is not a number", at()))
        };
        points.push((face, [coord(u)?, coord(v)?]));
        lines.push(i + 1);
    }
    if points.is_empty() {
        bail!(
            "--points {}: no `F U V` or `# p F U V` lines in it",
            path.display()
        );
    }
    Ok((points, lines))
}

/// `limit --points`: every point of the file, evaluated as one batch, written one per line.
fn limit_points(
    a: &LimitArgs,
    (mesh, obj_lines): (&ControlMesh, &ObjLines),
    scheme: LimitScheme,
    name: &str,
    path: &std::path::Path,
    (points, lines): (&[FacePoint], &[usize]),
) -> Result<()> {
    let evaluator = topology::limit::face_domain::LimitEvaluator::new(mesh, scheme)
        .map_err(|e| eval_in_file(e, name, mesh, obj_lines))?;
    let samples = evaluator.evaluate_many(points).map_err(|e| {
        let at = format!("{}:{}", path.display(), lines[e.point]);
        match *e.source {
            EvalError::FaceOutOfRange { face, count } => anyhow::anyhow!(
                "{at}: face {face} out of range: {name} has faces 0 to {} (counted from 0, as on \
                 `# p` lines)",
                count.saturating_sub(1)
            ),
            EvalError::ParamOutOfRange { u, v } => anyhow::anyhow!(
                "{at}: ({u}, {v}) is not in face {}'s domain (the `# p` convention; NaN and \
                 infinity never are)",
                e.face
            ),
            other => anyhow::Error::new(other).context(at),
        }
    })?;
    let mut text = String::with_capacity(samples.len() * 64);
    for (s, &line) in samples.iter().zip(lines) {
        let mut values = vec![s.position];
        if a.derivatives {
            values.extend([s.du, s.dv, s.normal]);
        }
        if non_finite(&values).is_some() {
            bail!(
                "{}:{line}: the limit there is not finite; nothing written",
                path.display()
            );
        }
        let words: Vec<String> = values.iter().flatten().map(|x| x.to_string()).collect();
        text.push_str(&words.join(" "));
        text.push('\n');
    }
    match &a.output {
        Some(out) => {
            tess::output::write_file(out, |w| w.write_all(text.as_bytes()))?;
            out!(
                "wrote {}: {} limit points of {name} ({})",
                out.display(),
                samples.len(),
                scheme.scheme()
            );
        }
        None => out!("{}", text.trim_end()),
    }
    Ok(())
}
