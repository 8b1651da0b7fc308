//! `tessera subdivide` and `tessera limit`: the CPU reference, from the command line.
//!
//! Doo-Sabin's points are `(face, corner, u, v)` in a corner's quad
//! ([`topology::limit::doo_sabin_eval`]); a level's vertex limits are
//! [`topology::limit::doo_sabin_eval::vertex_limits`].
//!
//! Options are checked before the mesh is read; errors about the mesh use the OBJ's 1-based
//! numbers ([`topology::TopologyError::in_file`]); nothing non-finite is written or printed.
use crate::cli::{LimitArgs, SubdivideArgs};
use anyhow::{bail, Context, Result};
use topology::limit::doo_sabin_eval::{vertex_limits, DooSabinEvaluator, DooSabinSample};
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
/// would cost 4× per extra level, and sharpness just below 10 needs 9 more. A Doo-Sabin
/// vertex's limit is the limit at the centre of its domain square (`refined`: above level 0,
/// where boundary vertices are boundary points).
fn limit_positions(
    level: &Level,
    base: &ControlMesh,
    scheme: Scheme,
    refined: bool,
) -> Result<Vec<[f64; 3]>> {
    let ls = match scheme {
        Scheme::Bilinear => return Ok(level.positions.clone()),
        Scheme::DooSabin => return Ok(vertex_limits(level, refined)?),
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
        Some(p) => Ok(topology::mesh::usd::load_mesh_file(p)?),
        None => crate::commands::load_mesh_with_lines(None),
    }
}

/// For an output named `.usda`, the `subdivisionScheme` it is written with (`scheme`'s; none
/// for Doo-Sabin, which USD does not name); `None` for OBJ output.
fn usda_token(output: &std::path::Path, scheme: topology::Scheme) -> Result<Option<&'static str>> {
    let usda = output
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("usda"));
    if !usda {
        return Ok(None);
    }
    match topology::mesh::usda::scheme_token(scheme) {
        Some(token) => Ok(Some(token)),
        None => bail!(
            "-o {}: USD has no {scheme} subdivision scheme; write an .obj",
            output.display()
        ),
    }
}

pub fn subdivide(a: SubdivideArgs) -> Result<()> {
    if a.level > 6 {
        bail!(
            "--level {}: give a level from 0 to 6 (meshes grow 4× per level)",
            a.level
        );
    }
    // Before any work: an output USD cannot name every scheme.
    let usda = usda_token(&a.output, a.scheme)?;
    let name = crate::commands::mesh_name(a.input.as_deref());
    let (mesh, lines) = read_mesh(a.input.as_deref())?;
    // A non-manifold mesh is refined through its manifold split, as every subdivision technique
    // draws it: the output has one vertex per copy (coincident where the sheets meet).
    if a.scheme == topology::Scheme::DooSabin {
        topology::refine::check_doo_sabin_tags(&mesh).map_err(|e| lines.locate(e, &mesh, &name))?;
    }
    let split = ManifoldSplit::of(&mesh).map_err(|e| lines.locate(e, &mesh, &name))?;
    if split.report.any() {
        eprintln!("{name}: {}", split.report.summary());
    }
    let mesh = split.mesh;
    let r = refine_uniform(&mesh, a.scheme, a.level).map_err(|e| lines.locate(e, &mesh, &name))?;
    let level = r.level(a.level);
    let positions = if a.limit {
        limit_positions(level, &mesh, a.scheme, a.level > 0)?
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
    match usda {
        Some(token) => tess::output::write_file(&a.output, |w| {
            topology::mesh::usda::write_usda(w, &positions, offsets, verts, token)
        })?,
        None => tess::output::write_file(&a.output, |w| {
            topology::mesh::obj::write_obj(w, &positions, offsets, verts)
        })?,
    }
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
    let bad_scheme = |e: &dyn std::fmt::Display| anyhow::anyhow!("--scheme {}: {e}", a.scheme);
    let scheme: Scheme = a.scheme.parse().map_err(|e| bad_scheme(&e))?;
    if scheme == Scheme::DooSabin {
        return doo_sabin_limit(a);
    }
    let scheme = LimitScheme::try_from(scheme).map_err(|e| bad_scheme(&e))?;
    if let Some(k) = a.corner {
        bail!(
            "--corner {k}: corners are Doo-Sabin's domain; {scheme} takes --face and --uv",
            scheme = scheme.scheme()
        );
    }
    let name = crate::commands::mesh_name(a.input.as_deref());
    let points = match &a.points {
        Some(path) => Some(read_points(path, false)?),
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

/// A point of a `--points` file: its face, its corner (Doo-Sabin's `F C U V`; 0 for `F U V`),
/// both from 0, and its coordinates.
struct PointRow {
    face: u32,
    corner: u32,
    uv: [f64; 2],
}

/// The points of a `--points` file (`F C U V` lines when `corners`) and the 1-based line of
/// each.
fn read_points(path: &std::path::Path, corners: bool) -> Result<(Vec<PointRow>, Vec<usize>)> {
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
        let (f, c, u, v) = match (corners, &w[..]) {
            (false, &[f, u, v]) => (f, "0", u, v),
            (true, &[f, c, u, v]) => (f, c, u, v),
            (false, _) => bail!(
                "{}: expected `F U V` (a face from 0 and its domain coordinates), found {line:?}",
                at()
            ),
            (true, _) => bail!(
                "{}: expected `F C U V` (a face and its corner from 0, and the corner quad's \
                 coordinates), found {line:?}",
                at()
            ),
        };
        let face: u32 = f
            .parse()
            .map_err(|_| anyhow::anyhow!("{}: face {f:?} is not a number from 0", at()))?;
        let corner: u32 = c
            .parse()
            .map_err(|_| anyhow::anyhow!("{}: corner {c:?} is not a number from 0", at()))?;
        let coord = |x: &str| -> Result<f64> {
            x.parse()
                .map_err(|_| anyhow::anyhow!("{}: {x:?} is not a number", at()))
        };
        points.push(PointRow {
            face,
            corner,
            uv: [coord(u)?, coord(v)?],
        });
        lines.push(i + 1);
    }
    if points.is_empty() {
        let form = if corners {
            "`F C U V`"
        } else {
            "`F U V` or `# p F U V`"
        };
        bail!("--points {}: no {form} lines in it", path.display());
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
    (rows, lines): (&[PointRow], &[usize]),
) -> Result<()> {
    let evaluator = topology::limit::face_domain::LimitEvaluator::new(mesh, scheme)
        .map_err(|e| eval_in_file(e, name, mesh, obj_lines))?;
    let points: Vec<FacePoint> = rows.iter().map(|r| (r.face, r.uv)).collect();
    let samples = evaluator.evaluate_many(&points).map_err(|e| {
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
    let values: Vec<Vec<[f64; 3]>> = samples
        .iter()
        .map(|s| {
            let mut values = vec![s.position];
            if a.derivatives {
                values.extend([s.du, s.dv, s.normal]);
            }
            values
        })
        .collect();
    write_points(a, &values, (name, path, lines), scheme.scheme())
}

/// The values of each point (`X Y Z` and, with --derivatives, three more vectors), one line
/// each, to --output or standard output; nothing when any is not finite.
fn write_points(
    a: &LimitArgs,
    rows: &[Vec<[f64; 3]>],
    (name, path, lines): (&str, &std::path::Path, &[usize]),
    scheme: Scheme,
) -> Result<()> {
    let mut text = String::with_capacity(rows.len() * 64);
    for (values, &line) in rows.iter().zip(lines) {
        if non_finite(values).is_some() {
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
                "wrote {}: {} limit points of {name} ({scheme})",
                out.display(),
                rows.len(),
            );
        }
        None => out!("{}", text.trim_end()),
    }
    Ok(())
}

/// `limit --scheme doo-sabin`: at `--face --corner --uv`, or at every `F C U V` of --points.
fn doo_sabin_limit(a: LimitArgs) -> Result<()> {
    let name = crate::commands::mesh_name(a.input.as_deref());
    let points = match &a.points {
        Some(path) => Some((path.as_path(), read_points(path, true)?)),
        None => None,
    };
    let (mesh, lines) = read_mesh(a.input.as_deref())?;
    let ev = DooSabinEvaluator::new(&mesh).map_err(|e| eval_in_file(e, &name, &mesh, &lines))?;
    if let Some((path, (rows, point_lines))) = points {
        return doo_sabin_points(&a, &ev, &name, path, (&rows, &point_lines));
    }
    let (Some(face), Some(uv)) = (a.face, a.uv) else {
        bail!("--face, --corner and --uv, or --points, say where to evaluate");
    };
    let Some(corner) = a.corner else {
        bail!(
            "--scheme doo-sabin needs --corner K: the corner of --face whose quad --uv is in \
             (see `tessera limit --help`)"
        );
    };
    let faces = ev.num_faces();
    if face == 0 || face > faces {
        bail!("--face {face}: {name} has faces 1 to {faces} (numbered as its `f` lines, from 1)");
    }
    let size = ev.face_size(face - 1);
    if corner > size {
        bail!("--corner {corner}: face {face} of {name} has corners 1 to {size}");
    }
    if !(0.0..=1.0).contains(&uv.0) || !(0.0..=1.0).contains(&uv.1) {
        bail!(
            "--uv {},{}: outside the corner's quad (0 to 1 in u and v)",
            topology::error::number(uv.0),
            topology::error::number(uv.1)
        );
    }
    let s = ev
        .evaluate(face - 1, corner - 1, uv.0, uv.1)
        .map_err(|e| eval_in_file(e, &name, &mesh, &lines))?;
    if non_finite(&[s.position]).is_some() {
        bail!("{name}: the limit at face {face} corner {corner} is not finite");
    }
    let v3 = |p: &[f64; 3]| format!("{:.12} {:.12} {:.12}", p[0], p[1], p[2]);
    out!(
        "scheme doo-sabin face {face} corner {corner} uv {} {}",
        topology::error::number(uv.0),
        topology::error::number(uv.1)
    );
    out!("position {}", v3(&s.position));
    match s.derivatives {
        Some((du, dv)) => out!("du {}\ndv {}", v3(&du), v3(&dv)),
        None => out!("du none (the centre of an extraordinary face)\ndv none"),
    }
    match s.normal {
        Some(n) => out!("normal {}", v3(&n)),
        None => out!("normal none (degenerate, or a boundary face's centre)"),
    }
    Ok(())
}

/// `limit --scheme doo-sabin --points`: every `F C U V` of the file, one line each.
fn doo_sabin_points(
    a: &LimitArgs,
    ev: &DooSabinEvaluator,
    name: &str,
    path: &std::path::Path,
    (rows, lines): (&[PointRow], &[usize]),
) -> Result<()> {
    let mut values = Vec::with_capacity(rows.len());
    for (r, &line) in rows.iter().zip(lines) {
        let at = format!("{}:{line}", path.display());
        let s = ev
            .evaluate(r.face as usize, r.corner as usize, r.uv[0], r.uv[1])
            .map_err(|e| doo_sabin_point_error(e, &at, name))?;
        values.push(doo_sabin_values(&s, a.derivatives, &at)?);
    }
    write_points(a, &values, (name, path, lines), Scheme::DooSabin)
}

/// A sample's position and, with `derivatives`, its partials and normal (refused where the
/// limit has none).
fn doo_sabin_values(s: &DooSabinSample, derivatives: bool, at: &str) -> Result<Vec<[f64; 3]>> {
    if !derivatives {
        return Ok(vec![s.position]);
    }
    let Some((du, dv)) = s.derivatives else {
        bail!(
            "{at}: the centre of an extraordinary face has no parametric derivatives; \
             nothing written (drop --derivatives or move off the centre)"
        );
    };
    let Some(normal) = s.normal else {
        bail!("{at}: the limit there has no normal (degenerate); nothing written");
    };
    Ok(vec![s.position, du, dv, normal])
}

/// A Doo-Sabin point's evaluation error, at `at` (file:line), in the points file's terms.
fn doo_sabin_point_error(e: EvalError, at: &str, name: &str) -> anyhow::Error {
    match e {
        EvalError::FaceOutOfRange { face, count } => anyhow::anyhow!(
            "{at}: face {face} out of range: {name} has faces 0 to {} (counted from 0)",
            count.saturating_sub(1)
        ),
        EvalError::CornerOutOfRange { face, corner, size } => anyhow::anyhow!(
            "{at}: corner {corner} out of range: face {face} has corners 0 to {} (counted \
             from 0)",
            size.saturating_sub(1)
        ),
        EvalError::ParamOutOfRange { u, v } => anyhow::anyhow!(
            "{at}: ({u}, {v}) is not in the corner's quad (0 to 1 in u and v; NaN and infinity \
             never are)"
        ),
        other => anyhow::Error::new(other).context(at.to_string()),
    }
}
