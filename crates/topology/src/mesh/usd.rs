//! USD input (`.usda` text, `.usdc` binary crate, `.usdz` package): the Mesh prims of the
//! composed stage as one [`ControlMesh`], read with the pure-Rust `openusd` crate (pinned to
//! 0.6.0: later versions need a newer Rust than this workspace's 1.95).
//!
//! What is mapped, per `UsdGeomMesh`:
//! - every Mesh prim the stage's default traversal reaches (active, defined, not abstract),
//!   except those whose computed `visibility` is `invisible` or whose computed `purpose` is
//!   `guide` or `proxy` (both inherited from ancestors);
//! - `points` (float or double), with the prim's world transform applied: the composed
//!   `xformOpOrder` of the prim and its ancestors (a `!resetXformStack!` stops the walk);
//! - `faceVertexCounts` / `faceVertexIndices`; `orientation = leftHanded` reverses each face's
//!   winding, keeping its first corner ([v0, v1, …, vn] becomes [v0, vn, …, v1]), and so
//!   does a world transform that mirrors (negative determinant); both together cancel;
//! - `subdivisionScheme` → [`ControlMesh::scheme`]: `catmullClark` (the default), `loop`,
//!   `bilinear`, and `none` (a polygonal mesh) as [`Scheme::Bilinear`], whose limit surface is
//!   the polygons themselves where they are planar;
//! - `creaseIndices` / `creaseLengths` / `creaseSharpnesses` (a crease of n points is n − 1
//!   edges; one sharpness per crease or one per edge), `cornerIndices` / `cornerSharpnesses`
//!   and `holeIndices` as the OBJ tags are; sharpness 10 and above is infinitely sharp, as in
//!   USD and OpenSubdiv ([`crate::rules::is_infinite`]); a crease edge that no face has is
//!   dropped with a warning, as the OBJ reader does;
//! - `interpolateBoundary` (`none`, `edgeOnly`, `edgeAndCorner`: USD's default, unlike OBJ's)
//!   and `triangleSubdivisionRule` (`catmullClark`, `smooth`) → [`SubdivOptions`];
//! - `faceVaryingLinearInterpolation` (`cornersPlus1` when unauthored) →
//!   [`SubdivOptions::fvar_interpolation`], how the texture coordinates are interpolated
//!   ([`crate::refine::fvar`]); also kept per prim as its token
//!   ([`UsdMeshPrim::face_varying_linear_interpolation`]);
//! - `primvars:st` (else `primvars:uv`), float or double, with or without `:indices`, of any
//!   interpolation (`faceVarying`, `vertex`, `varying`, `uniform`, `constant`) → one uv per
//!   face corner. The primvar's indices, else its elements' numbers (an unindexed
//!   `faceVarying` primvar gives every corner a value of its own, as USD's face-varying
//!   topology does), are the layout's topology ([`ControlMesh::uv_indices`]). A merged mesh
//!   keeps uvs only if every prim has them.
//!
//! Values are the default value, else the earliest time sample; transforms are composed at the
//! earliest time (an op's default where it has no samples).
//!
//! Several Mesh prims merge into one control mesh: their points are appended in traversal
//! order and each prim's vertex and face indices (faces, tags, holes) are offset by the points
//! and faces before it. They must share the scheme and options (else
//! [`UsdProblem::Mixed`]), but for `faceVaryingLinearInterpolation`: the first prim's applies
//! to the merged mesh, with a warning naming a prim that differs. [`read_usd`] also returns where each prim's points and faces start.
//!
//! What is refused, with [`TopologyError::Usd`] naming the file, the prim's path and the
//! attribute: a file the reader refuses, an unknown token, counts that do not add up to the
//! indices, a negative count, an index out of range, crease lengths that disagree with their
//! indices or sharpnesses, a wrong value type, a stage without a Mesh prim to draw. A prim's
//! mesh that fails validation (a degenerate face, a non-manifold edge, a coordinate out of
//! range) is refused with [`TopologyError::InUsdPrim`], in that prim's 0-based numbers. The
//! reader may panic on a malformed file; the read runs under [`std::panic::catch_unwind`] and
//! a panic becomes [`UsdProblem::ReaderPanicked`]. Normals and other primvars are not read.

use crate::error::{TopologyError, UsdProblem};
use crate::mesh::{ControlMesh, EdgeCrease, VertexCorner};
use crate::rules::options::{
    BoundaryInterpolation, FVarLinearInterpolation, SubdivOptions, TriangleSubdivision,
};
use crate::rules::Scheme;
use openusd::gf;
use openusd::schemas::geom::{self, Imageable, Mesh, Xformable};
use openusd::sdf::Value;
use openusd::usd::{Prim, PrimPredicate, SchemaBase, SchemaKind, Stage, TimeCode};
use std::path::Path;

/// The mesh file at `path`: USD through [`load_usd`] when [`is_usd_path`] says so (no element
/// lines: its errors name the prim and the attribute), else OBJ with OpenSubdiv's tags and the
/// line of every element ([`crate::mesh::obj::load_obj_with_lines`]). The one place a file's
/// format is chosen by its name.
pub fn load_mesh_file(
    path: &Path,
) -> Result<(ControlMesh, crate::mesh::obj::ObjLines), TopologyError> {
    if is_usd_path(path) {
        return Ok((load_usd(path)?, Default::default()));
    }
    crate::mesh::obj::load_obj_with_lines(path)
}

/// The largest USD file [`load_usd`] opens: 1 GiB, as for OBJ.
pub const MAX_USD_BYTES: u64 = crate::mesh::input::MAX_OBJ_BYTES;

/// Whether `path` names a USD file by its extension (`.usda`, `.usdc`, `.usdz`, `.usd`, any
/// case): the loaders of the command line and the C ABI read those with [`load_usd`] and
/// anything else as OBJ.
pub fn is_usd_path(path: &Path) -> bool {
    path.extension()
        .and_then(|e| e.to_str())
        .is_some_and(|e| ["usda", "usdc", "usdz", "usd"].contains(&e.to_ascii_lowercase().as_str()))
}

/// One Mesh prim of a [`UsdMeshes`]: where its points and faces start in the merged mesh.
#[derive(Clone, Debug, PartialEq)]
pub struct UsdMeshPrim {
    /// The prim's path (`/World/Body`).
    pub path: String,
    /// Its first point in the merged mesh's positions.
    pub first_vertex: u32,
    /// Its first face in the merged mesh's faces.
    pub first_face: u32,
    /// Its `faceVaryingLinearInterpolation` token (`cornersPlus1` when unauthored), which
    /// the merged mesh's [`SubdivOptions::fvar_interpolation`] applies.
    pub face_varying_linear_interpolation: String,
}

/// The Mesh prims of a USD stage merged into one control mesh ([`read_usd`]).
#[derive(Clone, Debug, PartialEq)]
pub struct UsdMeshes {
    pub mesh: ControlMesh,
    pub prims: Vec<UsdMeshPrim>,
}

/// Read a USD file's Mesh prims as one validated [`ControlMesh`] (see the module
/// documentation for what is mapped and refused). Errors name the file, the prim and the
/// attribute.
pub fn load_usd(path: impl AsRef<Path>) -> Result<ControlMesh, TopologyError> {
    read_usd(path).map(|m| m.mesh)
}

/// [`load_usd`], with where each prim's points and faces are in the merged mesh.
pub fn read_usd(path: impl AsRef<Path>) -> Result<UsdMeshes, TopologyError> {
    let path = path.as_ref();
    let file = path.display().to_string();
    // A FIFO, a device or a directory is refused unopened; a file beyond the bound by its size.
    crate::mesh::input::check_regular_file(path, MAX_USD_BYTES, "a USD file").map_err(|error| {
        TopologyError::Io {
            file: file.clone(),
            error,
        }
    })?;
    let file_error = |problem| usd_error(&file, "", "", problem);
    let Some(path_text) = path.to_str() else {
        return Err(file_error(UsdProblem::Read(
            "the path is not UTF-8".to_string(),
        )));
    };
    let read = std::panic::catch_unwind(std::panic::AssertUnwindSafe(|| {
        let stage =
            Stage::open(path_text).map_err(|e| file_error(UsdProblem::Read(format!("{e:#}"))))?;
        read_stage(&stage, &file)
    }));
    match read {
        Ok(result) => result,
        Err(panic) => {
            let message = panic
                .downcast_ref::<&str>()
                .map(|s| s.to_string())
                .or_else(|| panic.downcast_ref::<String>().cloned())
                .unwrap_or_else(|| "no message".to_string());
            Err(file_error(UsdProblem::ReaderPanicked(message)))
        }
    }
}

fn usd_error(file: &str, prim: &str, attribute: &str, problem: UsdProblem) -> TopologyError {
    TopologyError::Usd {
        file: file.to_string(),
        prim: prim.to_string(),
        attribute: attribute.to_string(),
        problem: Box::new(problem),
    }
}

/// The drawn Mesh prims of `stage`, merged.
fn read_stage(stage: &Stage, file: &str) -> Result<UsdMeshes, TopologyError> {
    let read_err = |e: anyhow::Error| usd_error(file, "", "", UsdProblem::Read(format!("{e:#}")));
    check_prim_names(stage, file)?;
    let mut paths = Vec::new();
    stage
        .traverse(PrimPredicate::DEFAULT, |p| paths.push(p.clone()))
        .map_err(read_err)?;
    let mut merged = Merge::default();
    let mut skipped = 0;
    for path in paths {
        let Some(mesh) = Mesh::get(stage, path.clone()).map_err(read_err)? else {
            continue;
        };
        let prim = path.as_str().to_string();
        let at = |attribute: &str| {
            let prim = prim.clone();
            let attribute = attribute.to_string();
            move |e: anyhow::Error| {
                usd_error(file, &prim, &attribute, UsdProblem::Read(format!("{e:#}")))
            }
        };
        let hidden =
            mesh.compute_visibility().map_err(at("visibility"))? == geom::Visibility::Invisible;
        let purpose = mesh.compute_purpose().map_err(at("purpose"))?;
        if hidden || matches!(purpose, geom::Purpose::Guide | geom::Purpose::Proxy) {
            skipped += 1;
            continue;
        }
        let prim_mesh = PrimReader {
            mesh: &mesh,
            file,
            prim: &prim,
        }
        .read()?;
        merged.add(prim_mesh, &prim, file)?;
    }
    if merged.prims.is_empty() {
        return Err(usd_error(file, "", "", UsdProblem::NoMesh { skipped }));
    }
    merged.mesh.validate().map_err(|e| e.in_file(file, None))?;
    Ok(UsdMeshes {
        mesh: merged.mesh,
        prims: merged.prims,
    })
}

/// Refuses a prim whose name is not an identifier (a letter or `_`, then letters, digits or
/// `_`; USD's Unicode identifiers included), walking every prim's children by name before
/// anything else reads the stage: openusd 0.6.0 recurses without end on the path of such a
/// prim (a stack overflow, which no `catch_unwind` catches).
fn check_prim_names(stage: &Stage, file: &str) -> Result<(), TopologyError> {
    let identifier = |name: &str| {
        name.chars()
            .next()
            .is_some_and(|c| c.is_alphabetic() || c == '_')
            && name.chars().all(|c| c.is_alphanumeric() || c == '_')
    };
    let mut stack = vec![openusd::sdf::Path::abs_root()];
    while let Some(path) = stack.pop() {
        let names = stage
            .prim(path.clone())
            .child_names()
            .map_err(|e| usd_error(file, path.as_str(), "", UsdProblem::Read(format!("{e:#}"))))?;
        for name in names {
            let name = name.as_str();
            if !identifier(name) {
                let problem = UsdProblem::Read(format!("child prim '{name}': not an identifier"));
                return Err(usd_error(file, path.as_str(), "", problem));
            }
            let child = path.append_path(name).map_err(|e| {
                usd_error(file, path.as_str(), "", UsdProblem::Read(format!("{e:#}")))
            })?;
            stack.push(child);
        }
    }
    Ok(())
}

/// One prim's mesh as read, before merging.
struct PrimMesh {
    mesh: ControlMesh,
    face_varying: String,
}

/// The prims merged so far.
#[derive(Default)]
struct Merge {
    mesh: ControlMesh,
    prims: Vec<UsdMeshPrim>,
    all_uvs: bool,
}

impl Merge {
    fn add(&mut self, part: PrimMesh, prim: &str, file: &str) -> Result<(), TopologyError> {
        let p = part.mesh;
        if let Some(first) = self.prims.first() {
            let mixed = |attribute: &str, value: String, first_value: String| {
                usd_error(
                    file,
                    prim,
                    attribute,
                    UsdProblem::Mixed {
                        value,
                        first_prim: first.path.clone(),
                        first_value,
                    },
                )
            };
            if p.scheme != self.mesh.scheme {
                return Err(mixed(
                    "subdivisionScheme",
                    format!("{:?}", p.scheme),
                    format!("{:?}", self.mesh.scheme),
                ));
            }
            let fvar = self.mesh.options.fvar_interpolation;
            let same_fvar = SubdivOptions {
                fvar_interpolation: fvar,
                ..p.options
            };
            if same_fvar != self.mesh.options {
                return Err(mixed(
                    "interpolateBoundary/triangleSubdivisionRule",
                    format!("{:?}", p.options),
                    format!("{:?}", self.mesh.options),
                ));
            }
            if p.options.fvar_interpolation != fvar {
                log::warn!(
                    "{file}: {prim}: faceVaryingLinearInterpolation {} differs from {}'s {}: \
                     the merged mesh's texture coordinates use {}",
                    p.options.fvar_interpolation,
                    first.path,
                    fvar,
                    fvar
                );
            }
        } else {
            self.mesh.face_offsets.push(0);
            self.mesh.options = p.options;
            self.mesh.scheme = p.scheme;
            self.all_uvs = true;
        }
        let (v0, f0, c0) = (
            self.mesh.positions.len() as u32,
            self.mesh.num_faces() as u32,
            self.mesh.face_vertices.len() as u32,
        );
        self.prims.push(UsdMeshPrim {
            path: prim.to_string(),
            first_vertex: v0,
            first_face: f0,
            face_varying_linear_interpolation: part.face_varying,
        });
        let m = &mut self.mesh;
        m.positions.extend_from_slice(&p.positions);
        m.face_vertices
            .extend(p.face_vertices.iter().map(|v| v + v0));
        m.face_offsets
            .extend(p.face_offsets[1..].iter().map(|o| o + c0));
        m.creases.extend(p.creases.iter().map(|c| EdgeCrease {
            vertices: [c.vertices[0] + v0, c.vertices[1] + v0],
            sharpness: c.sharpness,
        }));
        m.corners.extend(p.corners.iter().map(|c| VertexCorner {
            vertex: c.vertex + v0,
            sharpness: c.sharpness,
        }));
        m.holes.extend(p.holes.iter().map(|h| h + f0));
        let had_uvs = self.all_uvs;
        self.all_uvs &= p.uvs.is_some();
        if let (true, Some(uvs)) = (self.all_uvs, p.uvs) {
            let first = m.uvs.is_none();
            m.uvs.get_or_insert_with(Vec::new).extend(uvs);
            // Keys are compared only among one vertex's corners, so prims need no offset;
            // one prim without indices makes the whole mesh compare values.
            match (p.uv_indices, first) {
                (Some(ix), true) => m.uv_indices = Some(ix),
                (Some(ix), false) => {
                    if let Some(all) = m.uv_indices.as_mut() {
                        all.extend(ix);
                    }
                }
                (None, _) => m.uv_indices = None,
            }
        } else if had_uvs && self.prims.len() > 1 {
            m.uvs = None;
            m.uv_indices = None;
            log::warn!(
                "{file}: {prim} has no primvars:st or primvars:uv, or an earlier prim has none: \
                 the merged mesh keeps no texture coordinates"
            );
        }
        Ok(())
    }
}

/// A schema view of any prim, for its `xformOpOrder` (an ancestor may be an Xform, a Scope or
/// another gprim).
struct AnyXformable(Prim);

impl SchemaBase for AnyXformable {
    const KIND: SchemaKind = SchemaKind::AbstractTyped;
    fn prim(&self) -> &Prim {
        &self.0
    }
}
impl Imageable for AnyXformable {}
impl Xformable for AnyXformable {}

/// Reads one Mesh prim.
struct PrimReader<'a> {
    mesh: &'a Mesh,
    file: &'a str,
    prim: &'a str,
}

/// How a primvar's values are spread over the mesh.
#[derive(Clone, Copy)]
enum Spread {
    Constant,
    Uniform,
    Vertex,
    FaceVarying,
}

impl PrimReader<'_> {
    fn err(&self, attribute: &str, problem: UsdProblem) -> TopologyError {
        usd_error(self.file, self.prim, attribute, problem)
    }

    /// The attribute's value: its default, else its earliest time sample; `None` unauthored.
    fn value(&self, attribute: &str) -> Result<Option<Value>, TopologyError> {
        let attr = self.mesh.attribute(attribute);
        let read = |e: anyhow::Error| self.err(attribute, UsdProblem::Read(format!("{e:#}")));
        if let Some(v) = attr.get::<Value>().map_err(read)? {
            return Ok(Some(v));
        }
        // The sample of the smallest time (openusd keeps samples in the file's order).
        let samples = attr.time_samples().map_err(read)?.unwrap_or_default();
        Ok(samples
            .into_iter()
            .min_by(|a, b| a.0.total_cmp(&b.0))
            .map(|(_, v)| v))
    }

    fn wrong_type(&self, attribute: &str, found: &Value, expected: &'static str) -> TopologyError {
        let found = format!("{found:?}");
        let found = found
            .split('(')
            .next()
            .unwrap_or("another type")
            .to_string();
        self.err(attribute, UsdProblem::WrongType { found, expected })
    }

    fn ints(&self, attribute: &str) -> Result<Option<Vec<i32>>, TopologyError> {
        match self.value(attribute)? {
            None => Ok(None),
            Some(Value::IntVec(v)) => Ok(Some(v)),
            Some(other) => Err(self.wrong_type(attribute, &other, "int[]")),
        }
    }

    fn floats(&self, attribute: &str) -> Result<Option<Vec<f32>>, TopologyError> {
        match self.value(attribute)? {
            None => Ok(None),
            Some(Value::FloatVec(v)) => Ok(Some(v)),
            Some(Value::DoubleVec(v)) => Ok(Some(v.iter().map(|&x| x as f32).collect())),
            Some(other) => Err(self.wrong_type(attribute, &other, "float[]")),
        }
    }

    /// A token attribute's value among `allowed` (its default `allowed[0]` when unauthored).
    fn token(
        &self,
        attribute: &str,
        allowed: &'static [&'static str],
        expected: &'static str,
    ) -> Result<usize, TopologyError> {
        let token = match self.value(attribute)? {
            None => return Ok(0),
            Some(Value::Token(t)) => t.as_str().to_string(),
            Some(Value::String(s)) => s,
            Some(other) => return Err(self.wrong_type(attribute, &other, "token")),
        };
        allowed.iter().position(|&a| a == token).ok_or_else(|| {
            self.err(
                attribute,
                UsdProblem::UnknownToken {
                    value: token,
                    expected,
                },
            )
        })
    }

    /// Checks that every entry of `indices` is below `count`.
    fn check_indices(
        &self,
        attribute: &str,
        indices: &[i32],
        count: usize,
        of: &'static str,
    ) -> Result<Vec<u32>, TopologyError> {
        indices
            .iter()
            .enumerate()
            .map(|(position, &i)| match usize::try_from(i) {
                Ok(u) if u < count => Ok(i as u32),
                _ => Err(self.err(
                    attribute,
                    UsdProblem::IndexOutOfRange {
                        position,
                        index: i.into(),
                        count,
                        of,
                    },
                )),
            })
            .collect()
    }

    fn read(&self) -> Result<PrimMesh, TopologyError> {
        let mut mesh = ControlMesh {
            positions: self.points()?,
            ..ControlMesh::default()
        };
        let (counts, corners) = self.faces(mesh.positions.len())?;
        let mirrored = self.transform_points(&mut mesh.positions)?;
        let left_handed = self.token(
            "orientation",
            &["rightHanded", "leftHanded"],
            "rightHanded, leftHanded",
        )? == 1;
        mesh.face_offsets = std::iter::once(0)
            .chain(counts.iter().scan(0u32, |acc, &n| {
                *acc += n;
                Some(*acc)
            }))
            .collect();
        let reverse = left_handed != mirrored;
        let order = corner_order(&mesh.face_offsets, reverse);
        mesh.face_vertices = order.iter().map(|&c| corners[c]).collect();
        if let Some((uvs, keys)) = self.uvs(&mesh.face_offsets, &corners, mesh.positions.len())? {
            mesh.uvs = Some(order.iter().map(|&c| uvs[c]).collect());
            mesh.uv_indices = Some(order.iter().map(|&c| keys[c]).collect());
        }
        mesh.scheme = Some(self.scheme()?);
        mesh.options = self.options()?;
        self.tags(&mut mesh)?;
        let face_varying = self.token(
            "faceVaryingLinearInterpolation",
            &FACE_VARYING,
            "cornersPlus1, none, cornersOnly, cornersPlus2, boundaries, all",
        )?;
        mesh.options.fvar_interpolation =
            FVarLinearInterpolation::from_name(FACE_VARYING[face_varying]).unwrap_or_default();
        mesh.validate().map_err(|e| TopologyError::InUsdPrim {
            file: self.file.to_string(),
            prim: self.prim.to_string(),
            error: Box::new(e),
        })?;
        mesh.apply_boundary_none();
        drop_creases_off_edges(&mut mesh, self.file, self.prim);
        Ok(PrimMesh {
            mesh,
            face_varying: FACE_VARYING[face_varying].to_string(),
        })
    }

    fn points(&self) -> Result<Vec<[f64; 3]>, TopologyError> {
        let attribute = "points";
        match self.value(attribute)? {
            None => Err(self.err(attribute, UsdProblem::Missing)),
            Some(Value::Vec3fVec(v)) => Ok(v
                .iter()
                .map(|p| [p.x as f64, p.y as f64, p.z as f64])
                .collect()),
            Some(Value::Vec3dVec(v)) => Ok(v.iter().map(|p| [p.x, p.y, p.z]).collect()),
            Some(other) => Err(self.wrong_type(attribute, &other, "point3f[] or point3d[]")),
        }
    }

    /// The face sizes and the corners' points, checked against each other and the points.
    fn faces(&self, points: usize) -> Result<(Vec<u32>, Vec<u32>), TopologyError> {
        let (c_name, i_name) = ("faceVertexCounts", "faceVertexIndices");
        let counts = self
            .ints(c_name)?
            .ok_or_else(|| self.err(c_name, UsdProblem::Missing))?;
        let indices = self
            .ints(i_name)?
            .ok_or_else(|| self.err(i_name, UsdProblem::Missing))?;
        let counts = counts
            .iter()
            .enumerate()
            .map(|(position, &n)| {
                u32::try_from(n).map_err(|_| {
                    self.err(
                        c_name,
                        UsdProblem::NegativeCount {
                            position,
                            value: n.into(),
                        },
                    )
                })
            })
            .collect::<Result<Vec<u32>, _>>()?;
        let sum: u64 = counts.iter().map(|&n| u64::from(n)).sum();
        if sum != indices.len() as u64 {
            return Err(self.err(
                i_name,
                UsdProblem::Length {
                    len: indices.len(),
                    expected: format!("{sum} (the sum of faceVertexCounts)"),
                },
            ));
        }
        let corners = self.check_indices(i_name, &indices, points, "points")?;
        Ok((counts, corners))
    }

    /// Applies the prim's world transform to `points`; whether it mirrors (negative
    /// determinant).
    fn transform_points(&self, points: &mut [[f64; 3]]) -> Result<bool, TopologyError> {
        let m = self.world_transform()?;
        let a = &m.0;
        for p in points.iter_mut() {
            let q = *p;
            // Row vectors (USD's convention): p' = [x y z 1] · M.
            *p = std::array::from_fn(|j| {
                q[0] * a[j] + q[1] * a[4 + j] + q[2] * a[8 + j] + a[12 + j]
            });
        }
        let det = a[0] * (a[5] * a[10] - a[6] * a[9]) - a[1] * (a[4] * a[10] - a[6] * a[8])
            + a[2] * (a[4] * a[9] - a[5] * a[8]);
        Ok(det < 0.0)
    }

    /// The composed local-to-world matrix of the prim at the earliest time.
    fn world_transform(&self) -> Result<gf::Matrix4d, TopologyError> {
        let stage = self.mesh.stage();
        let mut m = gf::Matrix4d::IDENTITY;
        let mut path = Some(self.mesh.path().clone());
        while let Some(p) = path {
            if p.as_str() == "/" || p.as_str().is_empty() {
                break;
            }
            let x = AnyXformable(stage.prim(p.clone()));
            // Errors name the prim whose ops fail (the mesh or an ancestor).
            let at = |problem| usd_error(self.file, p.as_str(), "xformOpOrder", problem);
            let fail = |e: anyhow::Error| at(UsdProblem::Transform(format!("{e:#}")));
            if let Some(bad) = x
                .xform_op_order()
                .map_err(fail)?
                .and_then(|o| bad_op_name(&o))
            {
                return Err(at(UsdProblem::Transform(format!(
                    "'{bad}' is not an xformOp attribute's name (xformOp:<op>[:<suffix>])"
                ))));
            }
            let local = x
                .local_to_parent_transform(TimeCode::EARLIEST)
                .map_err(fail)?;
            m = m * local;
            if x.resets_xform_stack().map_err(fail)? {
                break;
            }
            path = p.parent();
        }
        Ok(m)
    }

    fn scheme(&self) -> Result<Scheme, TopologyError> {
        let k = self.token(
            "subdivisionScheme",
            &["catmullClark", "loop", "bilinear", "none"],
            "catmullClark, loop, bilinear, none",
        )?;
        Ok([
            Scheme::CatmullClark,
            Scheme::Loop,
            Scheme::Bilinear,
            Scheme::Bilinear,
        ][k])
    }

    fn options(&self) -> Result<SubdivOptions, TopologyError> {
        let boundary = self.token(
            "interpolateBoundary",
            &["edgeAndCorner", "edgeOnly", "none"],
            "edgeAndCorner, edgeOnly, none",
        )?;
        let triangles = self.token(
            "triangleSubdivisionRule",
            &["catmullClark", "smooth"],
            "catmullClark, smooth",
        )?;
        Ok(SubdivOptions {
            boundary: [
                BoundaryInterpolation::EdgesAndCorners,
                BoundaryInterpolation::EdgesOnly,
                BoundaryInterpolation::None,
            ][boundary],
            triangle_subdivision: [TriangleSubdivision::Catmark, TriangleSubdivision::Smooth]
                [triangles],
            ..SubdivOptions::default()
        })
    }

    /// Creases, corners and holes.
    fn tags(&self, mesh: &mut ControlMesh) -> Result<(), TopologyError> {
        let nv = mesh.positions.len();
        mesh.creases = self.creases(nv)?;
        let corners = self.ints("cornerIndices")?.unwrap_or_default();
        let corners = self.check_indices("cornerIndices", &corners, nv, "points")?;
        let sharp = self.floats("cornerSharpnesses")?.unwrap_or_default();
        if sharp.len() != corners.len() {
            return Err(self.err(
                "cornerSharpnesses",
                UsdProblem::Length {
                    len: sharp.len(),
                    expected: format!("{} (one per cornerIndices entry)", corners.len()),
                },
            ));
        }
        mesh.corners = corners
            .iter()
            .zip(&sharp)
            .map(|(&vertex, &sharpness)| VertexCorner { vertex, sharpness })
            .collect();
        let holes = self.ints("holeIndices")?.unwrap_or_default();
        mesh.holes = self.check_indices("holeIndices", &holes, mesh.num_faces(), "faces")?;
        Ok(())
    }

    fn creases(&self, points: usize) -> Result<Vec<EdgeCrease>, TopologyError> {
        let indices = self.ints("creaseIndices")?.unwrap_or_default();
        let indices = self.check_indices("creaseIndices", &indices, points, "points")?;
        let lengths = self.ints("creaseLengths")?.unwrap_or_default();
        let sharp = self.floats("creaseSharpnesses")?.unwrap_or_default();
        let mut lens = Vec::with_capacity(lengths.len());
        for (crease, &n) in lengths.iter().enumerate() {
            if n < 2 {
                let problem = UsdProblem::ShortCrease {
                    crease,
                    length: n.into(),
                };
                return Err(self.err("creaseLengths", problem));
            }
            lens.push(n as usize);
        }
        let sum: usize = lens.iter().sum();
        if sum != indices.len() {
            return Err(self.err(
                "creaseIndices",
                UsdProblem::Length {
                    len: indices.len(),
                    expected: format!("{sum} (the sum of creaseLengths)"),
                },
            ));
        }
        let edges = sum - lens.len();
        let per_edge = sharp.len() == edges && sharp.len() != lens.len();
        if sharp.len() != lens.len() && sharp.len() != edges {
            return Err(self.err(
                "creaseSharpnesses",
                UsdProblem::Length {
                    len: sharp.len(),
                    expected: format!(
                        "{} (one per crease) or {edges} (one per crease edge)",
                        lens.len()
                    ),
                },
            ));
        }
        let mut out = Vec::with_capacity(edges);
        let mut start = 0;
        for (crease, &n) in lens.iter().enumerate() {
            for k in 0..n - 1 {
                out.push(EdgeCrease {
                    vertices: [indices[start + k], indices[start + k + 1]],
                    sharpness: if per_edge {
                        sharp[out.len()]
                    } else {
                        sharp[crease]
                    },
                });
            }
            start += n;
        }
        Ok(out)
    }

    /// Per face corner (in the file's order), the texture coordinate of `primvars:st`, else
    /// `primvars:uv`, and its value's number (the primvar's index, else its element's);
    /// `None` without either primvar.
    #[allow(clippy::type_complexity)]
    fn uvs(
        &self,
        offsets: &[u32],
        corners: &[u32],
        points: usize,
    ) -> Result<Option<(Vec<[f64; 2]>, Vec<u32>)>, TopologyError> {
        for name in ["primvars:st", "primvars:uv"] {
            let Some(value) = self.value(name)? else {
                continue;
            };
            let values: Vec<[f64; 2]> = match value {
                Value::Vec2fVec(v) => v.iter().map(|t| [t.x as f64, t.y as f64]).collect(),
                Value::Vec2dVec(v) => v.iter().map(|t| [t.x, t.y]).collect(),
                other => return Err(self.wrong_type(name, &other, "texCoord2f[] or float2[]")),
            };
            let spread = self.spread(name)?;
            let faces = offsets.len() - 1;
            let elements = match spread {
                Spread::Constant => 1,
                Spread::Uniform => faces,
                Spread::Vertex => points,
                Spread::FaceVarying => corners.len(),
            };
            let indices_name = format!("{name}:indices");
            let indices = match self.ints(&indices_name)? {
                Some(ix) => {
                    let ix = self.check_indices(&indices_name, &ix, values.len(), "values")?;
                    self.expect_len(&indices_name, ix.len(), elements, spread)?;
                    Some(ix)
                }
                None => {
                    self.expect_len(name, values.len(), elements, spread)?;
                    None
                }
            };
            let element = |f: usize, c: usize| match spread {
                Spread::Constant => 0,
                Spread::Uniform => f,
                Spread::Vertex => corners[c] as usize,
                Spread::FaceVarying => c,
            };
            let corner_elements: Vec<usize> = (0..faces)
                .flat_map(|f| (offsets[f]..offsets[f + 1]).map(move |c| element(f, c as usize)))
                .collect();
            // The value number of each element: its index, else the element itself (an
            // unindexed primvar's elements are distinct values, as USD's face-varying
            // topology numbers them).
            let value_of: Vec<u32> = indices.unwrap_or_else(|| (0..elements as u32).collect());
            let per_corner = corner_elements
                .iter()
                .map(|&e| values[value_of[e] as usize])
                .collect();
            let keys = corner_elements.iter().map(|&e| value_of[e]).collect();
            return Ok(Some((per_corner, keys)));
        }
        Ok(None)
    }

    fn spread(&self, name: &str) -> Result<Spread, TopologyError> {
        let attr = self.mesh.attribute(name);
        let read = |e: anyhow::Error| self.err(name, UsdProblem::Read(format!("{e:#}")));
        let token = match attr.get_metadata::<Value>("interpolation").map_err(read)? {
            None => return Ok(Spread::Constant),
            Some(Value::Token(t)) => t.as_str().to_string(),
            Some(Value::String(s)) => s,
            Some(other) => return Err(self.wrong_type(name, &other, "an interpolation token")),
        };
        match token.as_str() {
            "constant" => Ok(Spread::Constant),
            "uniform" => Ok(Spread::Uniform),
            "vertex" | "varying" => Ok(Spread::Vertex),
            "faceVarying" => Ok(Spread::FaceVarying),
            _ => Err(self.err(
                &format!("{name} (interpolation)"),
                UsdProblem::UnknownToken {
                    value: token,
                    expected: "constant, uniform, vertex, varying, faceVarying",
                },
            )),
        }
    }

    fn expect_len(
        &self,
        name: &str,
        len: usize,
        elements: usize,
        spread: Spread,
    ) -> Result<(), TopologyError> {
        if len == elements {
            return Ok(());
        }
        let per = match spread {
            Spread::Constant => "one value (constant)",
            Spread::Uniform => "one per face (uniform)",
            Spread::Vertex => "one per point (vertex)",
            Spread::FaceVarying => "one per face corner (faceVarying)",
        };
        Err(self.err(
            name,
            UsdProblem::Length {
                len,
                expected: format!("{elements}: {per}"),
            },
        ))
    }
}

/// The first entry of an `xformOpOrder` that does not name an xformOp attribute: a name that
/// is not `xformOp:` and identifier characters (after an optional `!invert!`), other than
/// `!resetXformStack!`. Checked before openusd composes the ops: it loops forever on a
/// property path it cannot parse.
fn bad_op_name(order: &[String]) -> Option<String> {
    let identifier = |part: &str| {
        part.chars()
            .next()
            .is_some_and(|c| c.is_alphabetic() || c == '_')
            && part.chars().all(|c| c.is_alphanumeric() || c == '_')
    };
    order
        .iter()
        .find(|op| {
            let name = op.strip_prefix("!invert!").unwrap_or(op);
            let valid = name
                .strip_prefix("xformOp:")
                .is_some_and(|rest| rest.split(':').all(identifier));
            !valid && op.as_str() != "!resetXformStack!"
        })
        .cloned()
}

/// USD's `faceVaryingLinearInterpolation` tokens, the default first.
const FACE_VARYING: [&str; 6] = [
    "cornersPlus1",
    "none",
    "cornersOnly",
    "cornersPlus2",
    "boundaries",
    "all",
];

/// Per output corner, the file's corner it takes: the identity, or with each face reversed
/// keeping its first corner.
fn corner_order(offsets: &[u32], reverse: bool) -> Vec<usize> {
    let mut order = Vec::with_capacity(offsets.last().copied().unwrap_or(0) as usize);
    for f in 0..offsets.len() - 1 {
        let (s, e) = (offsets[f] as usize, offsets[f + 1] as usize);
        if reverse && e > s {
            order.push(s);
            order.extend((s + 1..e).rev());
        } else {
            order.extend(s..e);
        }
    }
    order
}

/// Drops crease edges that no face has, with a warning (as the OBJ reader does).
fn drop_creases_off_edges(mesh: &mut ControlMesh, file: &str, prim: &str) {
    if mesh.creases.is_empty() {
        return;
    }
    let key = |a: u32, b: u32| (a.min(b), a.max(b));
    let edges: std::collections::HashSet<(u32, u32)> = mesh
        .faces()
        .flat_map(|fv| (0..fv.len()).map(move |i| key(fv[i], fv[(i + 1) % fv.len()])))
        .collect();
    mesh.creases.retain(|c| {
        let [a, b] = c.vertices;
        let on_edge = edges.contains(&key(a, b));
        if !on_edge {
            log::warn!(
                "{file}: {prim}.creaseIndices: points {a} and {b}, which no face edge joins: \
                 ignored"
            );
        }
        on_edge
    });
}
