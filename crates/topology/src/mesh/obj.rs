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
use crate::mesh::input::{read_regular_file, MAX_OBJ_BYTES};
use crate::mesh::scalar_tags::ScalarTag;
use crate::mesh::{ControlMesh, EdgeCrease, VertexCorner};
use crate::rules::options::{
    BoundaryInterpolation, CreaseMethod, FVarLinearInterpolation, SubdivOptions,
    TriangleSubdivision,
};
use std::borrow::Cow;
use std::io::Write;
use std::path::Path;

/// Read and validate an OBJ file. Errors name the file. Only a regular file of at most
/// [`MAX_OBJ_BYTES`] is read ([`crate::mesh::input::read_regular_file`]: a FIFO, a device or a
/// directory is refused unopened); its text is decoded by [`parse_obj_bytes`].
pub fn load_obj(path: impl AsRef<Path>) -> Result<ControlMesh, TopologyError> {
    load_obj_with_lines(path).map(|(mesh, _)| mesh)
}

/// [`load_obj`], with the line of every vertex, face and tag ([`ObjLines`]), so errors found
/// later (refinement, adaptive plans) can name the line at fault too.
pub fn load_obj_with_lines(
    path: impl AsRef<Path>,
) -> Result<(ControlMesh, ObjLines), TopologyError> {
    let path = path.as_ref();
    let name = path.display().to_string();
    let bytes = read_regular_file(path, MAX_OBJ_BYTES, "an OBJ file").map_err(|error| {
        TopologyError::Io {
            file: name.clone(),
            error,
        }
    })?;
    parse_obj_bytes_with_lines(&bytes, &name)
}

/// OBJ bytes as text: UTF-8, a byte-order mark skipped; UTF-16 (little- or big-endian) when it
/// starts with its byte-order mark. A NUL byte is refused, naming its line: text with NULs is
/// UTF-16 without a byte-order mark (every ASCII character then has one) or not text at all.
/// A line with bytes that are not UTF-8 is read with U+FFFD in their place: in a comment or a
/// name nothing changes; in a number, an index or a tag the parser refuses the word, naming
/// the line; a warning names the first such line outside a comment.
fn decode<'a>(bytes: &'a [u8], name: &str) -> Result<Cow<'a, str>, TopologyError> {
    let bytes = bytes.strip_prefix(b"\xEF\xBB\xBF").unwrap_or(bytes);
    let utf16 = |rest: &[u8], unit: fn([u8; 2]) -> u16| -> String {
        let units = rest.chunks_exact(2).map(|c| unit([c[0], c[1]]));
        char::decode_utf16(units)
            .map(|c| c.unwrap_or(char::REPLACEMENT_CHARACTER))
            .collect()
    };
    if let Some(rest) = bytes.strip_prefix(b"\xFF\xFE") {
        return Ok(Cow::Owned(utf16(rest, u16::from_le_bytes)));
    }
    if let Some(rest) = bytes.strip_prefix(b"\xFE\xFF") {
        return Ok(Cow::Owned(utf16(rest, u16::from_be_bytes)));
    }
    if let Some(at) = bytes.iter().position(|&b| b == 0) {
        let line = 1 + bytes[..at].iter().filter(|&&b| b == b'\n').count();
        return Err(TopologyError::Parse {
            file: name.to_string(),
            line,
            kind: ObjSyntax::NulByte,
        });
    }
    if let Ok(text) = std::str::from_utf8(bytes) {
        return Ok(Cow::Borrowed(text));
    }
    let mut text = String::with_capacity(bytes.len());
    let mut warned = false;
    for (i, line) in bytes.split(|&b| b == b'\n').enumerate() {
        if i > 0 {
            text.push('\n');
        }
        match std::str::from_utf8(line) {
            Ok(l) => text.push_str(l),
            Err(e) => {
                let comment = line.iter().position(|&b| b == b'#');
                if !warned && comment.is_none_or(|c| e.valid_up_to() < c) {
                    log::warn!(
                        "{name}:{}: bytes that are not UTF-8 are read as U+FFFD (save the file \
                         as UTF-8)",
                        i + 1
                    );
                    warned = true;
                }
                text.push_str(&String::from_utf8_lossy(line));
            }
        }
    }
    Ok(Cow::Owned(text))
}

/// Parse and validate OBJ bytes ([`parse_obj`] after decoding them as [`load_obj`] does).
pub fn parse_obj_bytes(bytes: &[u8], name: &str) -> Result<ControlMesh, TopologyError> {
    parse_obj_bytes_with_lines(bytes, name).map(|(mesh, _)| mesh)
}

/// [`parse_obj_bytes`] with the lines of its elements.
pub fn parse_obj_bytes_with_lines(
    bytes: &[u8],
    name: &str,
) -> Result<(ControlMesh, ObjLines), TopologyError> {
    parse_obj_with_lines(&decode(bytes, name)?, name)
}

/// One face corner as written in the file: (vertex, uv, normal), already 0-based.
type RawCorner = (i64, Option<i64>, Option<i64>);

/// The line that made each element of a mesh read from OBJ, for locating errors about it:
/// validation's while parsing, and later ones (refinement, plans) through
/// [`ObjLines::locate`].
#[derive(Clone, Debug, Default)]
pub struct ObjLines {
    vertices: Vec<usize>,
    faces: Vec<usize>,
    creases: Vec<usize>,
    corners: Vec<usize>,
    holes: Vec<usize>,
    scalar_tags: Vec<usize>,
}

impl ObjLines {
    /// The line of face `f` (0-based, as the mesh counts it).
    pub fn face(&self, f: usize) -> Option<usize> {
        self.faces.get(f).copied()
    }

    /// The line of vertex `v` (0-based).
    pub fn vertex(&self, v: usize) -> Option<usize> {
        self.vertices.get(v).copied()
    }

    /// The lines of a mesh that keeps, of this one's faces, those of `kept` (per new face, its
    /// old number: [`crate::mesh::weld::weld_vertices`] drops faces). Vertices and tags keep
    /// their lines.
    pub fn for_faces(&self, kept: &[u32]) -> ObjLines {
        ObjLines {
            faces: kept
                .iter()
                .map(|&f| self.faces.get(f as usize).copied().unwrap_or(0))
                .collect(),
            ..self.clone()
        }
    }

    /// `e`, an error about the mesh read from `file` with these lines, in the file's terms
    /// ([`TopologyError::in_file`] with the line at fault when there is one).
    pub fn locate(&self, e: TopologyError, mesh: &ControlMesh, file: &str) -> TopologyError {
        let line = self.line_of(&e, mesh);
        e.in_file(file, line)
    }

    /// The line an error about `mesh` is about: the vertex's `v` line, the face's `f` line
    /// (for an edge, the face that made it non-manifold or flipped it), the tag's `t` line.
    /// Faces of refined levels have no line.
    fn line_of(&self, e: &TopologyError, mesh: &ControlMesh) -> Option<usize> {
        use TopologyError as E;
        let face = |f: usize| self.face(f);
        match *e {
            E::NonFinitePosition { vertex, .. } | E::CoordinateOutOfRange { vertex, .. } => {
                self.vertex(vertex)
            }
            E::NonManifoldVertex { vertex, .. } => self.vertex(vertex as usize),
            E::IndexOutOfRange { face: f, .. }
            | E::DegenerateFace { face: f, .. }
            | E::RepeatedVertex { face: f, .. }
            | E::LoopRequiresTriangles { face: f, .. }
            | E::AdaptiveFaceTooLarge { face: f, .. }
            | E::AdaptivePatch { level: 0, face: f }
            | E::AdaptiveUnbalanced { level: 0, face: f } => face(f),
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
            E::BadEdgeSharpness { v0, v1, .. } | E::DooSabinCrease { v0, v1, .. } => {
                let k = mesh.creases.iter().position(|c| c.vertices == [v0, v1])?;
                self.creases.get(k).copied()
            }
            E::BadVertexSharpness { vertex, .. } | E::DooSabinCorner { vertex, .. } => {
                let k = mesh.corners.iter().position(|c| c.vertex == vertex)?;
                self.corners.get(k).copied()
            }
            E::ScalarTag { vertex, .. } => {
                let k = mesh.scalar_tags.iter().position(|t| t.vertex == vertex)?;
                self.scalar_tags.get(k).copied()
            }
            E::ScalarTagTriangle { face: f } => face(f),
            E::DooSabinHole { face: f } => face(f as usize),
            E::TagOutOfRange { tag, index, .. } => {
                let k = match tag {
                    TagKind::Crease => mesh
                        .creases
                        .iter()
                        .position(|c| c.vertices.contains(&index)),
                    TagKind::Corner => mesh.corners.iter().position(|c| c.vertex == index),
                    TagKind::Hole => mesh.holes.iter().position(|&h| h == index),
                    TagKind::ScalarTag => mesh.scalar_tags.iter().position(|t| t.vertex == index),
                }?;
                match tag {
                    TagKind::Crease => self.creases.get(k),
                    TagKind::Corner => self.corners.get(k),
                    TagKind::Hole => self.holes.get(k),
                    TagKind::ScalarTag => self.scalar_tags.get(k),
                }
                .copied()
            }
            _ => None,
        }
    }
}

/// Parse and validate OBJ text; `name` is used in error messages (usually the file name).
/// A UTF-8 byte-order mark at the start is skipped.
pub fn parse_obj(text: &str, name: &str) -> Result<ControlMesh, TopologyError> {
    parse_obj_with_lines(text, name).map(|(mesh, _)| mesh)
}

/// [`parse_obj`], with the line of every vertex, face and tag.
pub fn parse_obj_with_lines(
    text: &str,
    name: &str,
) -> Result<(ControlMesh, ObjLines), TopologyError> {
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut mesh = ControlMesh::default();
    let mut lines = ObjLines::default();
    let mut uvs: Vec<[f64; 2]> = Vec::new();
    let mut normals: Vec<[f64; 3]> = Vec::new();
    let mut corners: Vec<RawCorner> = Vec::new();
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
                // Range and finiteness are checked by validation (it names the vertex).
                let p = parse_floats(&rest, 3, line, "v", &perr)?;
                mesh.positions.push([p[0], p[1], p[2]]);
                lines.vertices.push(line);
            }
            "vt" => {
                let p = parse_finite(&rest, 1, line, "vt", &perr)?;
                uvs.push([p[0], p.get(1).copied().unwrap_or(0.0)]);
            }
            "vn" => {
                let p = parse_finite(&rest, 3, line, "vn", &perr)?;
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
                lines.faces.push(line);
            }
            "t" => parse_tag(&rest, line, name, &mut mesh, &mut lines, &perr)?,
            "o" | "g" | "s" | "usemtl" | "mtllib" | "l" | "p" | "vp" => {}
            other => log::warn!("{name}:{line}: ignoring unknown OBJ statement '{other}'"),
        }
    }

    resolve_corners(&mut mesh, &lines, &corners, &uvs, &normals, name)?;
    check_tags(&mesh, &lines).map_err(|(e, line)| e.in_file(name, Some(line)))?;
    mesh.validate().map_err(|e| lines.locate(e, &mesh, name))?;
    mesh.apply_boundary_none();
    drop_creases_off_edges(&mut mesh, &mut lines, name);
    Ok((mesh, lines))
}

/// Fills the mesh's face vertices and per-corner attributes from the corners as written.
/// Vertex indices are checked here and by validation (both name the face and its line);
/// every texture and normal index given is checked here, naming the line, also where the
/// mesh keeps no attribute because some corner has none.
fn resolve_corners(
    mesh: &mut ControlMesh,
    lines: &ObjLines,
    corners: &[RawCorner],
    uvs: &[[f64; 2]],
    normals: &[[f64; 3]],
    name: &str,
) -> Result<(), TopologyError> {
    let nv = mesh.positions.len();
    let all_uv = !corners.is_empty() && corners.iter().all(|c| c.1.is_some());
    let all_n = !corners.is_empty() && corners.iter().all(|c| c.2.is_some());
    let mut corner_uvs = Vec::with_capacity(if all_uv { corners.len() } else { 0 });
    let mut corner_uv_indices = Vec::with_capacity(corner_uvs.capacity());
    let mut corner_normals = Vec::with_capacity(if all_n { corners.len() } else { 0 });
    let perr = |line: usize, kind: ObjSyntax| TopologyError::Parse {
        file: name.to_string(),
        line,
        kind,
    };
    for (f, &face_line) in lines.faces.iter().enumerate() {
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
            if let Some(t) = t {
                let uv = usize::try_from(t).ok().and_then(|t| uvs.get(t));
                let uv = *uv.ok_or_else(|| {
                    perr(
                        face_line,
                        ObjSyntax::TextureIndexOutOfRange {
                            index: t + 1,
                            count: uvs.len(),
                        },
                    )
                })?;
                if all_uv {
                    corner_uvs.push(uv);
                    // In range of `uvs`, whose length came from a `Vec` of 16-byte entries
                    // built from a file of at most `MAX_OBJ_BYTES`: it fits u32.
                    corner_uv_indices.push(t as u32);
                }
            }
            if let Some(n) = n {
                let nn = usize::try_from(n).ok().and_then(|n| normals.get(n));
                let nn = *nn.ok_or_else(|| {
                    perr(
                        face_line,
                        ObjSyntax::NormalIndexOutOfRange {
                            index: n + 1,
                            count: normals.len(),
                        },
                    )
                })?;
                if all_n {
                    corner_normals.push(nn);
                }
            }
        }
    }
    if all_uv {
        mesh.uvs = Some(corner_uvs);
        mesh.uv_indices = Some(corner_uv_indices);
    }
    if all_n {
        mesh.normals = Some(corner_normals);
    }
    Ok(())
}

/// Removes crease tags between vertices no face edge joins, warning with the tag's line:
/// OpenSubdiv ignores them, and so would every refinement (each warning without a line).
fn drop_creases_off_edges(mesh: &mut ControlMesh, lines: &mut ObjLines, name: &str) {
    if mesh.creases.is_empty() {
        return;
    }
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let edges: std::collections::HashSet<(u32, u32)> = (0..mesh.num_faces())
        .flat_map(|f| {
            let fv = mesh.face(f);
            (0..fv.len()).map(move |i| key(fv[i], fv[(i + 1) % fv.len()]))
        })
        .collect();
    let mut kept_lines = Vec::with_capacity(lines.creases.len());
    let mut k = 0;
    mesh.creases.retain(|c| {
        let line = lines.creases[k];
        k += 1;
        let [a, b] = c.vertices;
        let on_edge = edges.contains(&key(a, b));
        if on_edge {
            kept_lines.push(line);
        } else {
            log::warn!(
                "{name}:{line}: crease tag on vertices {a} and {b} (tags count from 0), which \
                 no face edge joins: ignored"
            );
        }
        on_edge
    });
    lines.creases = kept_lines;
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
    if parts.next().is_some() {
        return Err(perr(
            line,
            ObjSyntax::CornerTooManyIndices { word: word.into() },
        ));
    }
    Ok((v, t, n))
}

/// The values of one `t` line as its counts announce them.
struct TagValues<'a> {
    tag: &'a str,
    ints: Vec<i64>,
    floats: Vec<f32>,
    strings: &'a [&'a str],
}

impl<'a> TagValues<'a> {
    /// `<name> <nints>/<nfloats>/<nstrings> ints... floats... strings...`: exactly as many
    /// values as the counts announce.
    fn parse<E: Fn(usize, ObjSyntax) -> TopologyError>(
        words: &'a [&'a str],
        line: usize,
        perr: &E,
    ) -> Result<Self, TopologyError> {
        let (Some(&tag), Some(&counts)) = (words.first(), words.get(1)) else {
            return Err(perr(line, ObjSyntax::TagWithoutCounts));
        };
        let bad_counts = || {
            perr(
                line,
                ObjSyntax::BadTagCounts {
                    tag: tag.into(),
                    counts: counts.into(),
                },
            )
        };
        let nums: Vec<usize> = counts
            .split('/')
            .map(|c| c.parse::<usize>())
            .collect::<Result<_, _>>()
            .map_err(|_| bad_counts())?;
        let [n_int, n_float, n_string] = nums[..] else {
            return Err(bad_counts());
        };
        let vals = &words[2..];
        // Checked: counts near usize::MAX would wrap the sum and pass the length test.
        let needed = n_int
            .checked_add(n_float)
            .and_then(|n| n.checked_add(n_string));
        if needed != Some(vals.len()) {
            return Err(perr(
                line,
                ObjSyntax::TagCountMismatch {
                    tag: tag.into(),
                    counts: counts.into(),
                    found: vals.len(),
                },
            ));
        }
        let ints = vals[..n_int]
            .iter()
            .map(|w| {
                w.parse::<i64>().map_err(|_| {
                    perr(
                        line,
                        ObjSyntax::BadTagInteger {
                            tag: tag.into(),
                            word: w.to_string(),
                        },
                    )
                })
            })
            .collect::<Result<_, _>>()?;
        let floats = vals[n_int..n_int + n_float]
            .iter()
            .map(|w| {
                w.parse::<f32>().map_err(|_| {
                    perr(
                        line,
                        ObjSyntax::BadTagFloat {
                            tag: tag.into(),
                            word: w.to_string(),
                        },
                    )
                })
            })
            .collect::<Result<_, _>>()?;
        Ok(TagValues {
            tag,
            ints,
            floats,
            strings: &vals[n_int + n_float..],
        })
    }

    /// The values as written, for a message about an option tag: its integers, else its
    /// strings, quoted.
    fn shown(&self) -> String {
        if !self.ints.is_empty() {
            let ints: Vec<String> = self.ints.iter().map(i64::to_string).collect();
            ints.join(" ")
        } else if !self.strings.is_empty() {
            let strings: Vec<String> = self.strings.iter().map(|s| format!("'{s}'")).collect();
            strings.join(" ")
        } else if !self.floats.is_empty() {
            let floats: Vec<String> = self.floats.iter().map(f32::to_string).collect();
            floats.join(" ")
        } else {
            "no value".into()
        }
    }
}

/// `t <name> <nints>/<nfloats>/<nstrings> ints... floats... strings...`
fn parse_tag<E: Fn(usize, ObjSyntax) -> TopologyError>(
    words: &[&str],
    line: usize,
    file: &str,
    mesh: &mut ControlMesh,
    lines: &mut ObjLines,
    perr: &E,
) -> Result<(), TopologyError> {
    let t = TagValues::parse(words, line, perr)?;
    let tag = t.tag;
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
    let sharp_for = |k: usize, n: usize| tag_sharpness(&t, k, n, line, file, perr);
    match tag {
        "crease" => {
            if t.ints.len() < 2 || t.ints.len() % 2 != 0 {
                return Err(perr(
                    line,
                    ObjSyntax::CreaseNeedsPairs {
                        found: t.ints.len(),
                    },
                ));
            }
            let pairs = t.ints.len() / 2;
            for k in 0..pairs {
                mesh.creases.push(EdgeCrease {
                    vertices: [to_u32(t.ints[2 * k])?, to_u32(t.ints[2 * k + 1])?],
                    sharpness: sharp_for(k, pairs)?,
                });
                lines.creases.push(line);
            }
        }
        "corner" => {
            if t.ints.is_empty() {
                return Err(perr(line, ObjSyntax::CornerNeedsVertices));
            }
            for (k, &v) in t.ints.iter().enumerate() {
                mesh.corners.push(VertexCorner {
                    vertex: to_u32(v)?,
                    sharpness: sharp_for(k, t.ints.len())?,
                });
                lines.corners.push(line);
            }
        }
        "interpolateboundary"
        | "creasemethod"
        | "smoothtriangles"
        | "facevaryinginterpolateboundary" => option_tag(&t, &mut mesh.options, line, perr)?,
        "scalartag" => {
            mesh.scalar_tags.push(scalar_tag(&t, line, perr, to_u32)?);
            lines.scalar_tags.push(line);
        }
        "hole" => {
            if t.ints.is_empty() {
                return Err(perr(line, ObjSyntax::HoleNeedsFaces));
            }
            for &f in &t.ints {
                mesh.holes.push(to_u32(f)?);
                lines.holes.push(line);
            }
        }
        other => log::warn!("{file}:{line}: ignoring unsupported tag '{other}'"),
    }
    Ok(())
}

/// `t scalartag 1/6/0 v Dx Dy Dz tension sharpness bias` (one vertex per line;
/// [`crate::mesh::scalar_tags`]). Value ranges are checked with the mesh
/// ([`crate::mesh::scalar_tags::check`]).
fn scalar_tag<E: Fn(usize, ObjSyntax) -> TopologyError>(
    t: &TagValues<'_>,
    line: usize,
    perr: &E,
    to_u32: impl Fn(i64) -> Result<u32, TopologyError>,
) -> Result<ScalarTag, TopologyError> {
    let (&[v], &[dx, dy, dz, tension, sharpness, bias]) = (t.ints.as_slice(), t.floats.as_slice())
    else {
        return Err(perr(
            line,
            ObjSyntax::ScalarTagShape {
                ints: t.ints.len(),
                floats: t.floats.len(),
            },
        ));
    };
    Ok(ScalarTag {
        vertex: to_u32(v)?,
        deviation: [dx, dy, dz],
        tension,
        sharpness,
        bias,
    })
}

/// The option tags: `interpolateboundary` (one integer), `creasemethod` and `smoothtriangles`
/// (one string; `smoothtriangles` also one integer), `facevaryinginterpolateboundary` (one
/// integer, 0 none … 5 all as OpenSubdiv's `Far` reads it, or USD's token). Anything else is
/// refused with the value as written and what the tag takes.
fn option_tag<E: Fn(usize, ObjSyntax) -> TopologyError>(
    t: &TagValues<'_>,
    options: &mut SubdivOptions,
    line: usize,
    perr: &E,
) -> Result<(), TopologyError> {
    let bad = |expected: &'static str| {
        perr(
            line,
            ObjSyntax::BadOptionValue {
                option: t.tag.into(),
                value: t.shown(),
                expected,
            },
        )
    };
    match t.tag {
        "interpolateboundary" => {
            options.boundary =
                match (&t.ints[..], t.strings.len()) {
                    ([0], 0) => BoundaryInterpolation::None,
                    ([1], 0) => BoundaryInterpolation::EdgesAndCorners,
                    ([2], 0) => BoundaryInterpolation::EdgesOnly,
                    _ => return Err(bad(
                        "one integer: 0 (none), 1 (edges and corners) or 2 (edges only), as in \
                         't interpolateboundary 1/0/0 1'",
                    )),
                }
        }
        "creasemethod" => {
            options.crease_method = match (t.strings, t.ints.len()) {
                (["chaikin"], 0) => CreaseMethod::Chaikin,
                (["normal" | "uniform"], 0) => CreaseMethod::Uniform,
                _ => {
                    return Err(bad(
                        "one string: chaikin, normal or uniform, as in 't creasemethod 0/0/1 \
                         chaikin'",
                    ))
                }
            }
        }
        "facevaryinginterpolateboundary" => {
            options.fvar_interpolation = match (t.strings, &t.ints[..]) {
                ([], &[i]) => FVarLinearInterpolation::from_tag_value(i),
                ([name], []) => FVarLinearInterpolation::from_name(name),
                _ => None,
            }
            .ok_or_else(|| {
                bad(
                    "one integer: 0 (none), 1 (corners only), 2 (corners plus1), 3 (corners \
                     plus2), 4 (boundaries) or 5 (all), as in 't facevaryinginterpolateboundary \
                     1/0/0 1', or USD's name as one string",
                )
            })?
        }
        _ => {
            options.triangle_subdivision = match (t.strings, &t.ints[..]) {
                (["smooth"], []) | ([], [1]) => TriangleSubdivision::Smooth,
                (["catmark"], []) | ([], [0]) => TriangleSubdivision::Catmark,
                _ => {
                    return Err(bad(
                        "one string, smooth or catmark (or one integer, 1 or 0)",
                    ))
                }
            }
        }
    }
    Ok(())
}

/// The sharpness of element `k` of `n` a crease or corner tag names: one float for all
/// elements, or one per element; finite; a negative value is smooth (warned, as OpenSubdiv
/// treats sharpness ≤ 0).
fn tag_sharpness<E: Fn(usize, ObjSyntax) -> TopologyError>(
    t: &TagValues<'_>,
    k: usize,
    n: usize,
    line: usize,
    file: &str,
    perr: &E,
) -> Result<f32, TopologyError> {
    let tag = t.tag;
    let s = match t.floats.len() {
        0 => return Err(perr(line, ObjSyntax::MissingSharpness { tag: tag.into() })),
        1 => t.floats[0],
        m if m == n => t.floats[k],
        _ => {
            return Err(perr(
                line,
                ObjSyntax::SharpnessCount {
                    tag: tag.into(),
                    values: t.floats.len(),
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
    if s < 0.0 {
        log::warn!(
            "{file}:{line}: tag '{tag}': negative sharpness {s} is treated as 0 (smooth), \
             as OpenSubdiv does"
        );
    }
    Ok(s.max(0.0))
}

/// Tags must name existing vertices/faces; the error comes with the tag's line.
fn check_tags(mesh: &ControlMesh, lines: &ObjLines) -> Result<(), (TopologyError, usize)> {
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

    /// A non-manifold mesh loads (the techniques draw it); the manifold-only adjacency refuses
    /// it, located in the file's terms.
    fn manifold_err(text: &str) -> TopologyError {
        let (mesh, lines) = parse_obj_with_lines(text, "t.obj").expect("non-manifold loads");
        let e = crate::mesh::Topology::from_mesh(&mesh).expect_err("not manifold");
        lines.locate(e, &mesh, "t.obj")
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
        let e = manifold_err(&format!("{TRI}# comment\nf 1 2 3\nf 1 2 2\n"));
        assert_eq!(
            e.to_string(),
            "t.obj:6: face 2 uses vertex 2 more than once"
        );
        let e = manifold_err(
            "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 0 -1 0\nv 0 0 1\nf 1 2 3\nf 2 1 4\nf 1 2 5\n",
        );
        assert_eq!(
            e.to_string(),
            "t.obj:8: edge 1-2 is shared by 3 faces (non-manifold edge)"
        );
        let e = manifold_err(
            "v 0 0 0\nv 1 0 0\nv 1 1 0\nv 0 1 0\nv 2 0 0\nv 2 1 0\nf 1 2 3 4\nf 2 3 6 5\n",
        );
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

    /// An option tag's value is shown as written (integers plain, strings quoted, "no value"),
    /// with the values the tag takes.
    #[test]
    fn bad_option_values_are_shown_as_written() {
        let e = err(&format!("{TRI}f 1 2 3\nt interpolateboundary 1/0/0 7\n"));
        assert_eq!(
            e.to_string(),
            "t.obj:5: tag 'interpolateboundary': 7; expected one integer: 0 (none), 1 (edges \
             and corners) or 2 (edges only), as in 't interpolateboundary 1/0/0 1'"
        );
        let e = err(&format!("{TRI}f 1 2 3\nt creasemethod 0/0/1 sharp\n"));
        assert!(
            e.to_string()
                .starts_with("t.obj:5: tag 'creasemethod': 'sharp'; expected one string: chaikin"),
            "{e}"
        );
        let e = err(&format!("{TRI}f 1 2 3\nt smoothtriangles 0/0/0\n"));
        assert!(
            e.to_string()
                .starts_with("t.obj:5: tag 'smoothtriangles': no value; expected one string"),
            "{e}"
        );
        let e = err(&format!(
            "{TRI}f 1 2 3\nt interpolateboundary 0/0/1 edges\n"
        ));
        assert!(
            e.to_string()
                .starts_with("t.obj:5: tag 'interpolateboundary': 'edges'; expected one integer"),
            "{e}"
        );
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
