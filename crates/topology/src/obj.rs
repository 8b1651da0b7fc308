//! OBJ input/output with OpenSubdiv's `t` tag lines (creases, corners, boundary rule, ...).
//!
//! The reader is a small line parser rather than `tobj`: `tobj` re-numbers the vertices of each
//! group in order of first use and stores them as f32, but the `t crease`/`t corner` tags name
//! vertices by their index in the file, and refinement works in f64. Faces keep their size
//! (nothing is triangulated).

use crate::error::{ObjSyntax, TagKind, TopologyError};
use crate::mesh::{
    BoundaryInterpolation, ControlMesh, CreaseMethod, EdgeCrease, TriangleSubdivision, VertexCorner,
};
use std::io::Write;
use std::path::Path;

/// Read and validate an OBJ file. Errors name the file.
pub fn load_obj(path: impl AsRef<Path>) -> Result<ControlMesh, TopologyError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|source| TopologyError::Io {
        file: name.clone(),
        source,
    })?;
    parse_obj(&text, &name)
}

/// One face corner as written in the file: (vertex, uv, normal), already 0-based.
type RawCorner = (i64, Option<i64>, Option<i64>);

/// Parse and validate OBJ text; `name` is used in error messages (usually the file name).
pub fn parse_obj(text: &str, name: &str) -> Result<ControlMesh, TopologyError> {
    let mut mesh = ControlMesh::default();
    let mut uvs: Vec<[f64; 2]> = Vec::new();
    let mut normals: Vec<[f64; 3]> = Vec::new();
    let mut corners: Vec<RawCorner> = Vec::new();
    let mut face_lines: Vec<usize> = Vec::new();
    mesh.face_offsets.push(0);

    let perr = |line: usize, kind: ObjSyntax| TopologyError::Parse {
        file: name.to_string(),
        line,
        kind,
    };

    for (lineno, raw) in text.lines().enumerate() {
        let line = lineno + 1;
        let content = raw.split('#').next().unwrap_or("").trim();
        if content.is_empty() {
            continue;
        }
        let mut words = content.split_whitespace();
        let keyword = words.next().unwrap_or("");
        let rest: Vec<&str> = words.collect();
        match keyword {
            "v" => {
                let p = parse_floats(&rest, 3, line, "v", &perr)?;
                mesh.positions.push([p[0], p[1], p[2]]);
            }
            "vt" => {
                let p = parse_floats(&rest, 1, line, "vt", &perr)?;
                uvs.push([p[0], p.get(1).copied().unwrap_or(0.0)]);
            }
            "vn" => {
                let p = parse_floats(&rest, 3, line, "vn", &perr)?;
                normals.push([p[0], p[1], p[2]]);
            }
            "f" => {
                if rest.is_empty() {
                    return Err(perr(line, ObjSyntax::FaceWithoutVertices));
                }
                for word in &rest {
                    corners.push(parse_corner(
                        word,
                        [mesh.positions.len(), uvs.len(), normals.len()],
                        line,
                        &perr,
                    )?);
                }
                mesh.face_offsets.push(corners.len() as u32);
                face_lines.push(line);
            }
            "t" => parse_tag(&rest, line, name, &mut mesh, &perr)?,
            "o" | "g" | "s" | "usemtl" | "mtllib" | "l" | "p" | "vp" => {}
            other => log::warn!("{name}:{line}: ignoring unknown OBJ statement '{other}'"),
        }
    }

    // Resolve corners: vertex indices are checked by validation (it names the face);
    // attribute indices are checked here (they name the line).
    let nv = mesh.positions.len();
    let all_uv = !corners.is_empty() && corners.iter().all(|c| c.1.is_some());
    let all_n = !corners.is_empty() && corners.iter().all(|c| c.2.is_some());
    let mut corner_uvs = Vec::with_capacity(if all_uv { corners.len() } else { 0 });
    let mut corner_normals = Vec::with_capacity(if all_n { corners.len() } else { 0 });
    for (f, &face_line) in face_lines.iter().enumerate() {
        let (s, e) = (
            mesh.face_offsets[f] as usize,
            mesh.face_offsets[f + 1] as usize,
        );
        for &(v, t, n) in &corners[s..e] {
            if v < 0 || v as usize >= nv {
                return Err(TopologyError::IndexOutOfRange {
                    face: f,
                    index: v,
                    count: nv,
                }
                .in_file(name));
            }
            mesh.face_vertices.push(v as u32);
            if all_uv {
                let t = t.unwrap_or(-1);
                let uv = usize::try_from(t).ok().and_then(|t| uvs.get(t));
                corner_uvs.push(*uv.ok_or_else(|| {
                    perr(
                        face_line,
                        ObjSyntax::TextureIndexOutOfRange { index: t + 1 },
                    )
                })?);
            }
            if all_n {
                let n = n.unwrap_or(-1);
                let nn = usize::try_from(n).ok().and_then(|n| normals.get(n));
                corner_normals.push(*nn.ok_or_else(|| {
                    perr(face_line, ObjSyntax::NormalIndexOutOfRange { index: n + 1 })
                })?);
            }
        }
    }
    if all_uv {
        mesh.uvs = Some(corner_uvs);
    }
    if all_n {
        mesh.normals = Some(corner_normals);
    }
    check_tags(&mesh).map_err(|e| e.in_file(name))?;
    mesh.validate().map_err(|e| e.in_file(name))?;
    Ok(mesh)
}

fn parse_floats<E: Fn(usize, ObjSyntax) -> TopologyError>(
    words: &[&str],
    min: usize,
    line: usize,
    what: &'static str,
    perr: &E,
) -> Result<Vec<f64>, TopologyError> {
    if words.len() < min {
        return Err(perr(
            line,
            ObjSyntax::TooFewNumbers {
                statement: what,
                min,
                found: words.len(),
            },
        ));
    }
    words
        .iter()
        .map(|w| {
            w.parse::<f64>().map_err(|_| {
                perr(
                    line,
                    ObjSyntax::NotANumber {
                        statement: what,
                        word: w.to_string(),
                    },
                )
            })
        })
        .collect()
}

/// Parse `v`, `v/t`, `v//n` or `v/t/n`; negative indices count back from the current end.
fn parse_corner<E: Fn(usize, ObjSyntax) -> TopologyError>(
    word: &str,
    counts: [usize; 3],
    line: usize,
    perr: &E,
) -> Result<RawCorner, TopologyError> {
    let mut parts = word.split('/');
    let mut idx = |k: usize| -> Result<Option<i64>, TopologyError> {
        match parts.next() {
            None | Some("") => Ok(None),
            Some(p) => {
                let i: i64 = p
                    .parse()
                    .map_err(|_| perr(line, ObjSyntax::BadFaceIndex { word: word.into() }))?;
                if i == 0 {
                    return Err(perr(line, ObjSyntax::ZeroFaceIndex { word: word.into() }));
                }
                let r = if i > 0 { i - 1 } else { counts[k] as i64 + i };
                if r < 0 {
                    return Err(perr(
                        line,
                        ObjSyntax::IndexBeforeStart { word: word.into() },
                    ));
                }
                Ok(Some(r))
            }
        }
    };
    let v =
        idx(0)?.ok_or_else(|| perr(line, ObjSyntax::CornerWithoutVertex { word: word.into() }))?;
    let t = idx(1)?;
    let n = idx(2)?;
    Ok((v, t, n))
}

/// `t <name> <nints>/<nfloats>/<nstrings> ints... floats... strings...`
fn parse_tag<E: Fn(usize, ObjSyntax) -> TopologyError>(
    words: &[&str],
    line: usize,
    file: &str,
    mesh: &mut ControlMesh,
    perr: &E,
) -> Result<(), TopologyError> {
    let (Some(&tag), Some(&counts)) = (words.first(), words.get(1)) else {
        return Err(perr(line, ObjSyntax::TagWithoutCounts));
    };
    let nums: Vec<usize> = counts
        .split('/')
        .map(|c| c.parse::<usize>())
        .collect::<Result<_, _>>()
        .map_err(|_| {
            perr(
                line,
                ObjSyntax::BadTagCounts {
                    counts: counts.into(),
                },
            )
        })?;
    // Checked: counts near usize::MAX would wrap the sum and pass the length test.
    let needed = nums.iter().try_fold(2usize, |sum, &n| sum.checked_add(n));
    if nums.len() != 3 || needed.is_none_or(|needed| words.len() < needed) {
        return Err(perr(
            line,
            ObjSyntax::TagCountMismatch {
                tag: tag.into(),
                counts: counts.into(),
            },
        ));
    }
    let vals = &words[2..];
    let ints: Vec<i64> = vals[..nums[0]]
        .iter()
        .map(|w| w.parse::<i64>())
        .collect::<Result<_, _>>()
        .map_err(|_| perr(line, ObjSyntax::BadTagInteger { tag: tag.into() }))?;
    let floats: Vec<f32> = vals[nums[0]..nums[0] + nums[1]]
        .iter()
        .map(|w| w.parse::<f32>())
        .collect::<Result<_, _>>()
        .map_err(|_| perr(line, ObjSyntax::BadTagFloat { tag: tag.into() }))?;
    let strings = &vals[nums[0] + nums[1]..nums[0] + nums[1] + nums[2]];
    let to_u32 = |i: i64| -> Result<u32, TopologyError> {
        u32::try_from(i).map_err(|_| {
            perr(
                line,
                ObjSyntax::NegativeTagIndex {
                    tag: tag.into(),
                    index: i,
                },
            )
        })
    };
    // One float for all elements, or one per element.
    let sharp_for = |k: usize, n: usize| -> Result<f32, TopologyError> {
        let s = match floats.len() {
            0 => return Err(perr(line, ObjSyntax::MissingSharpness { tag: tag.into() })),
            1 => floats[0],
            m if m == n => floats[k],
            _ => {
                return Err(perr(
                    line,
                    ObjSyntax::SharpnessCount {
                        tag: tag.into(),
                        values: floats.len(),
                        elements: n,
                    },
                ))
            }
        };
        if !s.is_finite() {
            return Err(perr(
                line,
                ObjSyntax::NonFiniteSharpness {
                    tag: tag.into(),
                    value: s,
                },
            ));
        }
        Ok(s.max(0.0))
    };
    match tag {
        "crease" => {
            if ints.len() < 2 || ints.len() & 1 != 0 {
                return Err(perr(line, ObjSyntax::CreaseNeedsPairs));
            }
            let pairs = ints.len() / 2;
            for k in 0..pairs {
                mesh.creases.push(EdgeCrease {
                    vertices: [to_u32(ints[2 * k])?, to_u32(ints[2 * k + 1])?],
                    sharpness: sharp_for(k, pairs)?,
                });
            }
        }
        "corner" => {
            if ints.is_empty() {
                return Err(perr(line, ObjSyntax::CornerNeedsVertices));
            }
            for (k, &v) in ints.iter().enumerate() {
                mesh.corners.push(VertexCorner {
                    vertex: to_u32(v)?,
                    sharpness: sharp_for(k, ints.len())?,
                });
            }
        }
        "interpolateboundary" => {
            mesh.options.boundary = match ints.first() {
                Some(0) => BoundaryInterpolation::None,
                Some(1) => BoundaryInterpolation::EdgesAndCorners,
                Some(2) => BoundaryInterpolation::EdgesOnly,
                other => {
                    return Err(perr(
                        line,
                        ObjSyntax::BadOptionValue {
                            option: "interpolateboundary",
                            value: format!("{other:?}"),
                        },
                    ))
                }
            }
        }
        "creasemethod" => {
            mesh.options.crease_method = match strings.first().copied() {
                Some("chaikin") => CreaseMethod::Chaikin,
                Some("normal") | Some("uniform") => CreaseMethod::Uniform,
                other => {
                    return Err(perr(
                        line,
                        ObjSyntax::BadOptionValue {
                            option: "creasemethod",
                            value: format!("{other:?}"),
                        },
                    ))
                }
            }
        }
        "smoothtriangles" => {
            let smooth = match (strings.first().copied(), ints.first()) {
                (Some("smooth"), _) | (None, Some(1)) => true,
                (Some("catmark"), _) | (None, Some(0)) => false,
                other => {
                    return Err(perr(
                        line,
                        ObjSyntax::BadOptionValue {
                            option: "smoothtriangles",
                            value: format!("{other:?}"),
                        },
                    ))
                }
            };
            mesh.options.triangle_subdivision = if smooth {
                TriangleSubdivision::Smooth
            } else {
                TriangleSubdivision::Catmark
            };
        }
        "hole" => {
            for &f in &ints {
                mesh.holes.push(to_u32(f)?);
            }
        }
        other => log::warn!("{file}:{line}: ignoring unsupported tag '{other}'"),
    }
    Ok(())
}

/// Tags must name existing vertices/faces.
fn check_tags(mesh: &ControlMesh) -> Result<(), TopologyError> {
    let nv = mesh.positions.len() as u32;
    for c in &mesh.creases {
        if let Some(&v) = c.vertices.iter().find(|&&v| v >= nv) {
            return Err(TopologyError::TagOutOfRange {
                tag: TagKind::Crease,
                index: v,
                count: nv as usize,
            });
        }
    }
    for c in &mesh.corners {
        if c.vertex >= nv {
            return Err(TopologyError::TagOutOfRange {
                tag: TagKind::Corner,
                index: c.vertex,
                count: nv as usize,
            });
        }
    }
    let nf = mesh.num_faces() as u32;
    if let Some(&f) = mesh.holes.iter().find(|&&f| f >= nf) {
        return Err(TopologyError::TagOutOfRange {
            tag: TagKind::Hole,
            index: f,
            count: nf as usize,
        });
    }
    Ok(())
}

/// Write positions and polygons as OBJ text (`v` and 1-based `f` lines).
pub fn write_obj<W: Write>(
    mut out: W,
    positions: &[[f64; 3]],
    face_offsets: &[u32],
    face_vertices: &[u32],
) -> std::io::Result<()> {
    let mut w = std::io::BufWriter::new(&mut out);
    for p in positions {
        writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
    }
    for f in face_offsets.windows(2) {
        w.write_all(b"f")?;
        for &v in &face_vertices[f[0] as usize..f[1] as usize] {
            write!(w, " {}", v + 1)?;
        }
        w.write_all(b"\n")?;
    }
    w.flush()
}

/// Write a control mesh (positions, faces and its crease/corner tags) as OBJ text.
pub fn write_control_mesh<W: Write>(mut out: W, mesh: &ControlMesh) -> std::io::Result<()> {
    write_obj(
        &mut out,
        &mesh.positions,
        &mesh.face_offsets,
        &mesh.face_vertices,
    )?;
    for c in &mesh.creases {
        writeln!(
            out,
            "t crease 2/1/0 {} {} {}",
            c.vertices[0], c.vertices[1], c.sharpness
        )?;
    }
    for c in &mesh.corners {
        writeln!(out, "t corner 1/1/0 {} {}", c.vertex, c.sharpness)?;
    }
    Ok(())
}
