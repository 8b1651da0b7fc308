//! What the GPU wrote (the transform-feedback records), welded by position bits, with edge
//! use and the OBJ writer.
use super::domain::PatchToFace;
use crate::error::{Result, TessError};
pub use crate::gpu::{CaptureRecord, CAPTURE_STRIDE};
use std::collections::HashMap;
use std::path::Path;

/// Every corner the TES emitted, three per triangle, in the order the GPU wrote them.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct CapturedSoup {
    pub records: Vec<CaptureRecord>,
}

impl CapturedSoup {
    pub fn triangle_count(&self) -> usize {
        self.records.len() / 3
    }

    /// The captured triangles, three corners each.
    pub fn triangles(&self) -> impl Iterator<Item = &[CaptureRecord]> + '_ {
        self.records.chunks_exact(3)
    }

    /// Merges corners whose position bits are identical into one indexed vertex; triangles keep
    /// their captured order and corner order (triangle `t` is corners `3t..3t + 3`).
    pub fn weld(&self) -> Result<WeldedMesh> {
        if !self.records.chunks_exact(3).remainder().is_empty() {
            return Err(TessError::PartialTriangle {
                corners: self.records.len(),
            });
        }
        let mut index: HashMap<[u32; 3], u32> = HashMap::with_capacity(self.records.len() / 4);
        let mut out = WeldedMesh::default();
        let mut corner_vertex = Vec::with_capacity(self.records.len());
        out.corner_patch = self.records.iter().map(|r| r.patch).collect();
        out.corner_domain = self.records.iter().map(|r| r.domain).collect();
        for r in &self.records {
            let key = r.position.map(f32::to_bits);
            let id = *index.entry(key).or_insert_with(|| {
                out.positions.push(r.position);
                out.normals.push(r.normal);
                out.patch.push(r.patch);
                out.domain.push(r.domain);
                out.flags.push(r.flags);
                (out.positions.len() - 1) as u32
            });
            corner_vertex.push(id);
        }
        out.triangles = corner_vertex
            .chunks_exact(3)
            .map(|c| [c[0], c[1], c[2]])
            .collect();
        Ok(out)
    }
}

/// The soup welded by position bits. Per-vertex attributes come from the first corner welded
/// into the vertex.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct WeldedMesh {
    pub positions: Vec<[f32; 3]>,
    pub normals: Vec<[f32; 3]>,
    pub patch: Vec<u32>,
    pub domain: Vec<[f32; 2]>,
    pub flags: Vec<u32>,
    pub triangles: Vec<[u32; 3]>,
    /// Per triangle corner (`3t + i`), its own captured patch id and domain coordinate.
    pub corner_patch: Vec<u32>,
    pub corner_domain: Vec<[f32; 2]>,
}

/// An edge used by exactly one triangle.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct OpenEdge {
    /// Welded vertex indices, smaller first.
    pub vertices: [u32; 2],
    /// The triangle using it (also its index in the soup: corners `3t..3t + 3`).
    pub triangle: u32,
}

/// Edge use of a welded mesh.
#[derive(Clone, Debug, Default, PartialEq, Eq)]
pub struct EdgeReport {
    /// Edges used by exactly one triangle, sorted.
    pub open: Vec<OpenEdge>,
    /// Edges used by three or more triangles, sorted.
    pub non_manifold: Vec<[u32; 2]>,
    /// Triangles with two identical welded corners, in order (not counted in edge use).
    pub zero_area: Vec<u32>,
}

impl WeldedMesh {
    /// Counts how many triangles use each edge; see [`EdgeReport`].
    pub fn open_edges(&self) -> EdgeReport {
        let mut uses: HashMap<[u32; 2], (u32, u32)> = HashMap::new();
        let mut report = EdgeReport::default();
        for (t, tri) in self.triangles.iter().enumerate() {
            if tri[0] == tri[1] || tri[1] == tri[2] || tri[2] == tri[0] {
                report.zero_area.push(t as u32);
                continue;
            }
            for i in 0..3 {
                let (a, b) = (tri[i], tri[(i + 1) % 3]);
                let e = uses.entry([a.min(b), a.max(b)]).or_insert((0, t as u32));
                e.0 += 1;
            }
        }
        for (edge, (count, triangle)) in uses {
            match count {
                1 => report.open.push(OpenEdge {
                    vertices: edge,
                    triangle,
                }),
                2 => {}
                _ => report.non_manifold.push(edge),
            }
        }
        report.open.sort_by_key(|e| e.vertices);
        report.non_manifold.sort();
        report
    }

    /// Per triangle corner, the texture coordinate `texcoord` gives its captured (patch id,
    /// domain coordinate) ([`crate::Technique::texcoord`]); `None` if any corner has none.
    pub fn corner_texcoords(
        &self,
        texcoord: impl Fn(u32, [f32; 2]) -> Option<[f64; 2]>,
    ) -> Option<Vec<[f64; 2]>> {
        self.corner_patch
            .iter()
            .zip(&self.corner_domain)
            .map(|(&p, &d)| texcoord(p, d))
            .collect()
    }

    /// Writes the mesh as OBJ (format in the module doc); `map` names each vertex's base face;
    /// `texcoords`, one per triangle corner ([`Self::corner_texcoords`]), add `vt` lines.
    /// Every vertex is mapped before the file is touched; the file is written whole or not at
    /// all ([`crate::output::write_file`]).
    pub fn write_obj(
        &self,
        path: &Path,
        map: &PatchToFace<'_>,
        texcoords: Option<&[[f64; 2]]>,
        winding: Winding,
    ) -> Result<()> {
        if let Some(t) = texcoords.filter(|t| t.len() != 3 * self.triangles.len()) {
            return Err(TessError::Io {
                path: path.display().to_string(),
                source: std::io::Error::other(format!(
                    "{} texture coordinates for {} triangle corners",
                    t.len(),
                    3 * self.triangles.len()
                )),
            });
        }
        for (vertex, (&patch, &domain)) in self.patch.iter().zip(&self.domain).enumerate() {
            if map(patch, domain).is_none() {
                return Err(TessError::UnmappedPatch {
                    path: path.display().to_string(),
                    vertex,
                    patch,
                });
            }
        }
        crate::output::write_file(path, |w| {
            self.write_obj_to(w, map, texcoords, winding)
                .map_err(|e| match e {
                    ObjWriteError::Io(e) => e,
                    ObjWriteError::Unmapped { vertex, patch } => std::io::Error::other(format!(
                        "vertex {vertex} has patch id {patch}, which maps to no base face"
                    )),
                })
        })
    }

    fn write_obj_to(
        &self,
        w: &mut dyn std::io::Write,
        map: &PatchToFace<'_>,
        texcoords: Option<&[[f64; 2]]>,
        winding: Winding,
    ) -> std::result::Result<(), ObjWriteError> {
        writeln!(
            w,
            "# tessera capture: {} welded vertices, {} triangles, corners welded by position bits",
            self.positions.len(),
            self.triangles.len()
        )?;
        writeln!(
            w,
            "# per vertex: v, vn, then '# p <base face> <u> <v>' (0-based face, its domain)"
        )?;
        for (i, (p, n)) in self.positions.iter().zip(&self.normals).enumerate() {
            let fp = map(self.patch[i], self.domain[i]).ok_or(ObjWriteError::Unmapped {
                vertex: i,
                patch: self.patch[i],
            })?;
            writeln!(w, "v {} {} {}", p[0], p[1], p[2])?;
            writeln!(w, "vn {} {} {}", n[0], n[1], n[2])?;
            writeln!(w, "# p {} {} {}", fp.face, fp.u, fp.v)?;
        }
        let corner_vt = texcoords.map(|t| write_texcoords(w, t)).transpose()?;
        let order = match winding {
            Winding::AsCaptured => [0, 1, 2],
            Winding::Reversed => [0, 2, 1],
        };
        for (k, t) in self.triangles.iter().enumerate() {
            let [a, b, c] = order.map(|i| t[i] + 1);
            match &corner_vt {
                Some(vt) => {
                    let [ta, tb, tc] = order.map(|i| vt[3 * k + i] + 1);
                    writeln!(w, "f {a}/{ta}/{a} {b}/{tb}/{b} {c}/{tc}/{c}")?;
                }
                None => writeln!(w, "f {a}//{a} {b}//{b} {c}//{c}")?,
            }
        }
        Ok(())
    }
}

/// Writes one `vt` per distinct (by bits) coordinate of `texcoords` (per triangle corner) and
/// returns each corner's 0-based `vt` number.
fn write_texcoords(
    w: &mut dyn std::io::Write,
    texcoords: &[[f64; 2]],
) -> std::io::Result<Vec<usize>> {
    let mut index: HashMap<[u64; 2], usize> = HashMap::new();
    let mut out = Vec::with_capacity(texcoords.len());
    for t in texcoords {
        let next = index.len();
        let i = *index.entry(t.map(f64::to_bits)).or_insert(next);
        if i == next {
            writeln!(w, "vt {} {}", t[0], t[1])?;
        }
        out.push(i);
    }
    Ok(out)
}

/// Corner order of the faces [`WeldedMesh::write_obj`] writes.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq)]
pub enum Winding {
    /// The order the GPU wrote the corners in.
    #[default]
    AsCaptured,
    /// Second and third corners swapped (see the module doc on winding).
    Reversed,
}

enum ObjWriteError {
    Io(std::io::Error),
    Unmapped { vertex: usize, patch: u32 },
}

impl From<std::io::Error> for ObjWriteError {
    fn from(e: std::io::Error) -> Self {
        ObjWriteError::Io(e)
    }
}
