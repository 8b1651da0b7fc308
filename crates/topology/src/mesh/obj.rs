//! OBJ input/output with OpenSubdiv's `t` tag lines (creases, corners, boundary rule, ...).
//!
//! The reader is a small line parser rather than `tobj`: `tobj` re-numbers the vertices of each
//! group in order of first use and stores them as f32, but the `t crease`/`t corner` tags name
//! vertices by their index in the file, and refinement works in f64. Faces keep their size
//! (nothing is triangulated).
//!
//! Errors speak the file's language: a parse error names its line; a validation error found
//! after parsing (an index out of range, a non-manifold edge, a coordinate beyond
//! [`crate::mesh::MAX_COORDINATE`]) is located on the line that made the vertex, face or tag at fault
//! and worded with the file's 1-based numbers ([`TopologyError::InFile`]). The parser keeps the
//! line of every vertex, face and tag for that (a few bytes each).

use crate::error::{ObjSyntax, TagKind, TopologyError};
use crate::mesh::{ControlMesh, EdgeCrease, VertexCorner};
use crate::rules::options::{BoundaryInterpolation, CreaseMethod, TriangleSubdivision};
use std::io::Write;
use std::path::Path;

/// Read and validate an OBJ file. Errors name the file.
pub fn load_obj(path: impl AsRef<Path>) -> Result<ControlMesh, TopologyError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let text = std::fs::read_to_string(path).map_err(|error| TopologyError::Io {
        file: name.clone(),
        error,
    })?;
    parse_obj(&text, &name)
}

/// One face corner as written in the file: (vertex, uv, normal), already 0-based.
type RawCorner = (i64, Option<i64>, Option<i64>);

/// The line that made each element, for locating validation errors.
#[derive(Default)]
struct Lines {
    vertices: Vec<usize>,
    faces: Vec<usize>,
    creases: Vec<usize>,
    corners: Vec<usize>,
    holes: Vec<usize>,
}

impl Lines {
    /// The line a validation error of `mesh` is about: the vertex's `v` line, the face's `f`
    /// line (for an edge, the face that made it non-manifold or flipped it), the tag's `t` line.
    fn locate(&self, e: &TopologyError, mesh: &ControlMesh) -> Option<usize> {
        use TopologyError as E;
        let face = |f: usize| self.faces.get(f).copied();
        match *e {
            E::NonFinitePosition { vertex, .. } | E::CoordinateOutOfRange { vertex, .. } => {
                self.vertices.get(vertex).copied()
            }
            E::NonManifoldVertex { vertex, .. } => self.vertices.get(vertex as usize).copied(),
            E::IndexOutOfRange { face: f, .. }
            | E::DegenerateFace { face: f, .. }
            | E::RepeatedVertex { face: f, .. } => face(f),
            E::InconsistentOrientation { face1, .. } => face(face1),
            E::NonManifoldEdge { v0, v1, .. } => {
                // The third face on the edge (the first two are a manifold edge).
                let on_edge = |fv: &[u32]| {
                    (0..fv.len()).any(|i| {
                        let (a, b) = (fv[i], fv[(i + 1) % fv.len()]);
                        (a, b) == (v0, v1) || (a, b) == (v1, v0)
                    })
                };
                let f = (0..mesh.num_faces())
                    .filter(|&f| on_edge(mesh.face(f)))
                    .nth(2)?;
                face(f)
            }
            _ => None,
        }
    }
}

/// Parse and validate OBJ text; `name` is used in error messages (usually the file name).
/// A UTF-8 byte-order mark at the start is skipped.
pub fn parse_obj(text: &str, name: &str) -> Result<ControlMesh, TopologyError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let perr = |line: usize, kind: ObjSyntax| TopologyError::Parse {
        file: name.to_string(),
        line,
        kind,
    };
    let mut obj = RawObj::default();
    obj.mesh.face_offsets.push(0);
    for (lineno, raw) in text.lines().enumerate() {
        let content = raw.split('#').next().unwrap_or("").trim();
        if !content.is_empty() {
            obj.statement(content, lineno + 1, name, &perr)?;
        }
    }
    let mesh = obj.resolve_corners(name, &perr)?;
    let lines = obj.lines;
    check_tags(&mesh, &lines).map_err(|(e, line)| e.in_file(name, Some(line)))?;
    mesh.validate().map_err(|e| {
        let line = lines.locate(&e, &mesh);
        e.in_file(name, line)
    })?;
    Ok(mesh)
}

/// An OBJ file as its statements are read: the mesh so far, the line of each element, the
/// texture coordinates and normals and the face corners as written.
#[derive(Default)]
struct RawObj {
    mesh: ControlMesh,
    lines: Lines,
    uvs: Vec<[f64; 2]>,
    normals: Vec<[f64; 3]>,
    corners: Vec<RawCorner>,
}

impl RawObj {
    /// One statement (`content`, comment stripped) on line `line`.
    fn statement<E: Fn(usize, ObjSyntax) -> TopologyError>(
        &mut self,
        content: &str,
        line: usize,
        name: &str,
        perr: &E,
    ) -> Result<(), TopologyError> {
        let mut words = content.split_whitespace();
        let keyword = words.next().unwrap_or("");
        let rest: Vec<&str> = words.collect();
        match keyword {
            "v" => {
                // Range and finiteness are checked by validation (it names the vertex).
                let p = parse_floats(&rest, 3, line, "v", perr)?;
                self.mesh.positions.push([p[0], p[1], p[2]]);
                self.lines.vertices.push(line);
            }
            "vt" => {
                let p = parse_finite(&rest, 1, line, "vt", perr)?;
                self.uvs.push([p[0], p.get(1).copied().unwrap_or(0.0)]);
            }
            "vn" => {
                let p = parse_finite(&rest, 3, line, "vn", perr)?;
                self.normals.push([p[0], p[1], p[2]]);
            }
            "f" => {
                if rest.is_empty() {
                    return Err(perr(line, ObjSyntax::FaceWithoutVertices));
                }
                let counts = [
                    self.mesh.positions.len(),
                    self.uvs.len(),
                    self.normals.len(),
                ];
                for word in &rest {
                    self.corners.push(parse_corner(word, counts, line, perr)?);
                }
                self.mesh.face_offsets.push(self.corners.len() as u32);
                self.lines.faces.push(line);
            }
            "t" => parse_tag(&rest, line, name, &mut self.mesh, &mut self.lines, perr)?,
            "o" | "g" | "s" | "usemtl" | "mtllib" | "l" | "p" | "vp" => {}
            other => log::warn!("{name}:{line}: ignoring unknown OBJ statement '{other}'"),
        }
        Ok(())
    }

    /// The mesh with its corners resolved: vertex indices are checked by validation (it names
    /// the face); attribute indices are checked here (they name the line). Texture
    /// coordinates and normals are kept when every corner has one.
    fn resolve_corners<E: Fn(usize, ObjSyntax) -> TopologyError>(
        &mut self,
        name: &str,
        perr: &E,
    ) -> Result<ControlMesh, TopologyError> {
        let mut mesh = std::mem::take(&mut self.mesh);
        let corners = &self.corners;
        let nv = mesh.positions.len();
        let all_uv = !corners.is_empty() && corners.iter().all(|c| c.1.is_some());
        let all_n = !corners.is_empty() && corners.iter().all(|c| c.2.is_some());
        let mut corner_uvs = Vec::with_capacity(if all_uv { corners.len() } else { 0 });
        let mut corner_normals = Vec::with_capacity(if all_n { corners.len() } else { 0 });
        for (f, &face_line) in self.lines.faces.iter().enumerate() {
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
                    .in_file(name, Some(face_line)));
                }
                mesh.face_vertices.push(v as u32);
                if all_uv {
                    let t = t.unwrap_or(-1);
                    let uv = usize::try_from(t).ok().and_then(|t| self.uvs.get(t));
                    corner_uvs.push(*uv.ok_or_else(|| {
                        perr(
                            face_line,
                            ObjSyntax::TextureIndexOutOfRange { index: t + 1 },
                        )
                    })?);
                }
                if all_n {
                    let n = n.unwrap_or(-1);
                    let nn = usize::try_from(n).ok().and_then(|n| self.normals.get(n));
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
        Ok(mesh)
    }
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

/// [`parse_floats`] for attributes, which validation does not see: NaN and infinity are
/// refused here.
fn parse_finite<E: Fn(usize, ObjSyntax) -> TopologyError>(
    words: &[&str],
    min: usize,
    line: usize,
    what: &'static str,
    perr: &E,
) -> Result<Vec<f64>, TopologyError> {
    let p = parse_floats(words, min, line, what, perr)?;
    if let Some(k) = p.iter().position(|x| !x.is_finite()) {
        return Err(perr(
            line,
            ObjSyntax::NonFiniteNumber {
                statement: what,
                word: words[k].to_string(),
            },
        ));
    }
    Ok(p)
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
    lines: &mut Lines,
    perr: &E,
) -> Result<(), TopologyError> {
    let tag = Tag::parse(words, line, file, perr)?;
    match tag.name {
        "crease" => tag.creases(mesh, lines)?,
        "corner" => tag.corners(mesh, lines)?,
        "interpolateboundary" => mesh.options.boundary = tag.boundary_interpolation()?,
        "creasemethod" => mesh.options.crease_method = tag.crease_method()?,
        "smoothtriangles" => mesh.options.triangle_subdivision = tag.triangle_subdivision()?,
        "hole" => {
            for &f in &tag.ints {
                mesh.holes.push(tag.index(f)?);
                lines.holes.push(line);
            }
        }
        other => log::warn!("{file}:{line}: ignoring unsupported tag '{other}'"),
    }
    Ok(())
}

/// One `t` line, its values read: the tag's name, integers, floats and strings, where it is
/// (for errors and warnings) and how a syntax error is made.
struct Tag<'a, E> {
    name: &'a str,
    ints: Vec<i64>,
    floats: Vec<f32>,
    strings: &'a [&'a str],
    line: usize,
    file: &'a str,
    perr: &'a E,
}

impl<'a, E: Fn(usize, ObjSyntax) -> TopologyError> Tag<'a, E> {
    /// The name, the counts `<nints>/<nfloats>/<nstrings>` and as many values of each.
    fn parse(
        words: &'a [&'a str],
        line: usize,
        file: &'a str,
        perr: &'a E,
    ) -> Result<Tag<'a, E>, TopologyError> {
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
        Ok(Tag {
            name: tag,
            ints,
            floats,
            strings,
            line,
            file,
            perr,
        })
    }

    fn err(&self, kind: ObjSyntax) -> TopologyError {
        (self.perr)(self.line, kind)
    }

    /// An integer value as a vertex or face index.
    fn index(&self, i: i64) -> Result<u32, TopologyError> {
        u32::try_from(i).map_err(|_| {
            self.err(ObjSyntax::NegativeTagIndex {
                tag: self.name.into(),
                index: i,
            })
        })
    }

    /// The sharpness of element `k` of `n`: one float for all elements, or one per element.
    fn sharpness(&self, k: usize, n: usize) -> Result<f32, TopologyError> {
        let (tag, floats) = (self.name, &self.floats);
        let s = match floats.len() {
            0 => return Err(self.err(ObjSyntax::MissingSharpness { tag: tag.into() })),
            1 => floats[0],
            m if m == n => floats[k],
            _ => {
                return Err(self.err(ObjSyntax::SharpnessCount {
                    tag: tag.into(),
                    values: floats.len(),
                    elements: n,
                }))
            }
        };
        if !s.is_finite() {
            return Err(self.err(ObjSyntax::NonFiniteSharpness {
                tag: tag.into(),
                value: s,
            }));
        }
        if s < 0.0 {
            // OpenSubdiv treats sharpness ≤ 0 as smooth; say so rather than drop it silently.
            let (file, line) = (self.file, self.line);
            log::warn!(
                "{file}:{line}: tag '{tag}': negative sharpness {s} is treated as 0 (smooth), \
                 as OpenSubdiv does"
            );
        }
        Ok(s.max(0.0))
    }

    /// `crease`: vertex pairs, their sharpness.
    fn creases(&self, mesh: &mut ControlMesh, lines: &mut Lines) -> Result<(), TopologyError> {
        let ints = &self.ints;
        if ints.len() < 2 || ints.len() & 1 != 0 {
            return Err(self.err(ObjSyntax::CreaseNeedsPairs));
        }
        let pairs = ints.len() / 2;
        for k in 0..pairs {
            mesh.creases.push(EdgeCrease {
                vertices: [self.index(ints[2 * k])?, self.index(ints[2 * k + 1])?],
                sharpness: self.sharpness(k, pairs)?,
            });
            lines.creases.push(self.line);
        }
        Ok(())
    }

    /// `corner`: vertices, their sharpness.
    fn corners(&self, mesh: &mut ControlMesh, lines: &mut Lines) -> Result<(), TopologyError> {
        if self.ints.is_empty() {
            return Err(self.err(ObjSyntax::CornerNeedsVertices));
        }
        for (k, &v) in self.ints.iter().enumerate() {
            mesh.corners.push(VertexCorner {
                vertex: self.index(v)?,
                sharpness: self.sharpness(k, self.ints.len())?,
            });
            lines.corners.push(self.line);
        }
        Ok(())
    }

    /// `interpolateboundary`: OpenSubdiv's integer (0 none, 1 edges and corners, 2 edges).
    fn boundary_interpolation(&self) -> Result<BoundaryInterpolation, TopologyError> {
        match self.ints.first() {
            Some(0) => Ok(BoundaryInterpolation::None),
            Some(1) => Ok(BoundaryInterpolation::EdgesAndCorners),
            Some(2) => Ok(BoundaryInterpolation::EdgesOnly),
            other => Err(self.err(ObjSyntax::BadOptionValue {
                option: "interpolateboundary",
                value: other.map_or_else(|| "(none)".into(), |v| v.to_string()),
            })),
        }
    }

    /// `creasemethod`: `chaikin`, or `normal` / `uniform`.
    fn crease_method(&self) -> Result<CreaseMethod, TopologyError> {
        match self.strings.first().copied() {
            Some("chaikin") => Ok(CreaseMethod::Chaikin),
            Some("normal") | Some("uniform") => Ok(CreaseMethod::Uniform),
            other => Err(self.err(ObjSyntax::BadOptionValue {
                option: "creasemethod",
                value: other.unwrap_or("(none)").to_string(),
            })),
        }
    }

    /// `smoothtriangles`: `smooth` or 1, `catmark` or 0.
    fn triangle_subdivision(&self) -> Result<TriangleSubdivision, TopologyError> {
        match (self.strings.first().copied(), self.ints.first()) {
            (Some("smooth"), _) | (None, Some(1)) => Ok(TriangleSubdivision::Smooth),
            (Some("catmark"), _) | (None, Some(0)) => Ok(TriangleSubdivision::Catmark),
            (s, i) => Err(self.err(ObjSyntax::BadOptionValue {
                option: "smoothtriangles",
                value: s
                    .map(str::to_string)
                    .or(i.map(|i| i.to_string()))
                    .unwrap_or_else(|| "(none)".into()),
            })),
        }
    }
}

/// Tags must name existing vertices/faces; the error comes with the tag's line.
fn check_tags(mesh: &ControlMesh, lines: &Lines) -> Result<(), (TopologyError, usize)> {
    let nv = mesh.positions.len() as u32;
    let out_of_range =
        |tag, index, count, line| (TopologyError::TagOutOfRange { tag, index, count }, line);
    for (c, &line) in mesh.creases.iter().zip(&lines.creases) {
        if let Some(&v) = c.vertices.iter().find(|&&v| v >= nv) {
            return Err(out_of_range(TagKind::Crease, v, nv as usize, line));
        }
    }
    for (c, &line) in mesh.corners.iter().zip(&lines.corners) {
        if c.vertex >= nv {
            return Err(out_of_range(TagKind::Corner, c.vertex, nv as usize, line));
        }
    }
    let nf = mesh.num_faces() as u32;
    for (&f, &line) in mesh.holes.iter().zip(&lines.holes) {
        if f >= nf {
            return Err(out_of_range(TagKind::Hole, f, nf as usize, line));
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::mesh::MAX_COORDINATE;
    use std::error::Error as _;

    fn err(text: &str) -> TopologyError {
        parse_obj(text, "t.obj").expect_err("mesh should be rejected")
    }

    const TRI: &str = "v 0 0 0\nv 1 0 0\nv 0 1 0\n";

    /// The repro: a finite coordinate whose f32 intermediates overflow is refused, with
    /// the file, the line and the 1-based vertex number.
    #[test]
    fn coordinates_beyond_the_bound_name_line_and_vertex() {
        let e = err("v 3e38 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nf 1 2 3\nf 2 4 3\n");
        assert!(matches!(
            e.root(),
            TopologyError::CoordinateOutOfRange { vertex: 0, .. }
        ));
        let m = e.to_string();
        assert!(m.starts_with("t.obj:1: vertex 1 at (3e38, 0, 0) "), "{m}");
        assert!(m.contains("1e12"), "{m}");
        // 1e39 overflows f32 but not f64: still refused, on its own line.
        let e = err(&format!("{TRI}v 0 0 1e39\nf 1 2 3\n"));
        assert!(e.to_string().starts_with("t.obj:4: vertex 4 "), "{e}");
        let e = err(&format!("{TRI}v 0 -1.0000001e12 0\nf 1 2 3\n"));
        assert!(matches!(
            e.root(),
            TopologyError::CoordinateOutOfRange { vertex: 3, .. }
        ));
        // NaN keeps its own error, worded in the file's numbers.
        let e = err("v 0 0 0\nv nan 0 0\nv 0 1 0\nf 1 2 3\n");
        assert_eq!(
            e.to_string(),
            "t.obj:2: vertex 2 has a non-finite position (NaN, 0, 0)"
        );
    }

    #[test]
    fn coordinates_at_the_bound_are_accepted() {
        let m = MAX_COORDINATE;
        let text = format!("v {m} {m} {m}\nv -{m} {m} -{m}\nv 0 -{m} {m}\nf 1 2 3\n");
        let mesh = parse_obj(&text, "t.obj").unwrap();
        assert_eq!(mesh.positions[1], [-m, m, -m]);
    }

    #[test]
    fn a_byte_order_mark_is_skipped() {
        let mesh = parse_obj(&format!("\u{feff}{TRI}f 1 2 3\n"), "bom.obj").unwrap();
        assert_eq!(mesh.positions.len(), 3);
        assert_eq!(mesh.positions[0], [0.0, 0.0, 0.0]);
    }

    /// Validation errors speak the file's language: 1-based numbers and the line that made
    /// the element at fault; the root keeps the mesh's 0-based numbers.
    #[test]
    fn validation_errors_use_obj_numbers_and_lines() {
        let e = err(&format!("{TRI}f 1 2 4\n"));
        assert_eq!(
            e.to_string(),
            "t.obj:4: face 1 names vertex 4, but the file has 3 vertices"
        );
        assert!(matches!(
            e.root(),
            TopologyError::IndexOutOfRange {
                face: 0,
                index: 3,
                count: 3
            }
        ));
        let e = err(&format!("{TRI}# comment\nf 1 2 3\nf 1 2 2\n"));
        assert_eq!(
            e.to_string(),
            "t.obj:6: face 2 uses vertex 2 more than once"
        );
        let e = err("v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n");
        assert_eq!(
            e.to_string(),
            "t.obj:8: edge 1-2 is shared by 3 faces (non-manifold edge)"
        );
        let e = err("v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4\nf 2 3 6 5\n");
        assert_eq!(
            e.to_string(),
            "t.obj:8: faces 1 and 2 both traverse edge 2->3 in the same direction \
             (inconsistent orientation)"
        );
        let e = err(&format!("{TRI}f 1 2 3\nt crease 2/1/0 0 7 2\n"));
        assert_eq!(
            e.to_string(),
            "t.obj:5: invalid tag: crease names vertex 7 (tags count from 0), the file has 3 vertices"
        );
        let e = err("v 0 0 0\n");
        assert_eq!(e.to_string(), "t.obj: empty mesh: no faces");
    }

    /// Each cause is said once: file errors embed their cause and do not chain it too.
    #[test]
    fn causes_are_said_once() {
        let e = super::load_obj("/nonexistent/dir/m.obj").unwrap_err();
        assert!(e.source().is_none());
        let m = e.to_string();
        assert_eq!(m.matches("os error").count(), 1, "{m}");
        let e = err("v 0 0 0\n");
        assert!(e.source().is_none(), "{e}");
    }

    #[test]
    fn bad_option_values_are_shown_as_written() {
        let e = err(&format!("{TRI}f 1 2 3\nt interpolateboundary 1/0/0 7\n"));
        assert_eq!(e.to_string(), "t.obj:5: interpolateboundary: bad value 7");
        let e = err(&format!("{TRI}f 1 2 3\nt creasemethod 0/0/1 sharp\n"));
        assert_eq!(e.to_string(), "t.obj:5: creasemethod: bad value sharp");
        let e = err(&format!("{TRI}f 1 2 3\nt smoothtriangles 0/0/0\n"));
        assert_eq!(e.to_string(), "t.obj:5: smoothtriangles: bad value (none)");
    }

    #[test]
    fn non_finite_attributes_name_their_line() {
        let e = err(&format!("{TRI}vn 0 nan 1\nf 1//1 2//1 3//1\n"));
        assert_eq!(e.to_string(), "t.obj:4: 'vn': 'nan' is not a finite number");
    }

    /// Negative sharpness is smooth (OpenSubdiv); the loader keeps it at 0 (and warns).
    #[test]
    fn negative_sharpness_is_smooth() {
        let m = parse_obj(&format!("{TRI}f 1 2 3\nt crease 2/1/0 0 1 -2\n"), "t.obj").unwrap();
        assert_eq!(m.creases[0].sharpness, 0.0);
    }
}
