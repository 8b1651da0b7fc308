//! Structured inputs shared by the topology fuzz targets.
//!
//! Raw bytes almost never spell a manifold, consistently oriented mesh, so the topology
//! targets (refine, limit, bft, adaptive) would stop at validation. [`MeshSpec`] is decoded
//! by `arbitrary` into a *template* that is valid by construction (a grid, optionally
//! triangulated and wrapped into a cylinder or torus; a fan around a vertex of any valence;
//! closed solids) followed by *mutations* that keep some inputs valid and push others to
//! the edges of validation (dropped or flipped faces, welded vertices, polygon soups),
//! plus creases, corners, holes, options and coordinates from the bytes.
//!
//! # Bounds (every execution stays small and cannot hang)
//! * at most [`MAX_VERTICES`] vertices and [`MAX_FACES`] faces (grids ≤ 6×6 cells, fans of
//!   valence ≤ 16, soups ≤ 16 vertices × 24 faces of ≤ 8 corners);
//! * coordinates: template positions plus a small jitter, or any `f64` the bytes give;
//!   [`MeshSpec::positions_in_range`] lets the topology targets keep only finite
//!   coordinates within [`MAX_COORD`] (the range the library promises finite output for);
//! * sharpness: half steps 0..=12 (beyond 10 is infinite), or any `f32` (NaN, ∞, negative);
//!   the targets bound refinement levels themselves.

use arbitrary::{Arbitrary, Unstructured};
use topology::mesh::{EdgeCrease, VertexCorner};
use topology::rules::options::{BoundaryInterpolation, CreaseMethod, TriangleSubdivision};
use topology::ControlMesh;

/// Largest coordinate magnitude the topology targets feed in: the library's own bound, within
/// which it promises finite output (`ControlMesh::validate` refuses the rest).
pub const MAX_COORD: f64 = topology::mesh::MAX_COORDINATE;
pub const MAX_VERTICES: usize = 64;
pub const MAX_FACES: usize = 72;

/// A sharpness value: usually a half step in 0..=12, sometimes any `f32`.
#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum Sharp {
    Step(u8),
    Raw(f32),
}

impl Sharp {
    pub fn value(self) -> f32 {
        match self {
            Sharp::Step(k) => (k % 25) as f32 * 0.5,
            Sharp::Raw(s) => s,
        }
    }
}

#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum Solid {
    Tetrahedron,
    Cube,
    Octahedron,
}

#[derive(Arbitrary, Debug, Clone)]
pub enum Shape {
    /// `w × h` cells (1..=6 each); bit `i` of `tri` splits cell `i` into two triangles along
    /// the diagonal chosen by bit `i` of `diag`; `wrap_u` / `wrap_v` glue opposite sides.
    Grid {
        w: u8,
        h: u8,
        tri: u64,
        diag: u64,
        wrap_u: bool,
        wrap_v: bool,
    },
    /// A vertex of valence 3..=16: triangles (closed into a bipyramid if `closed`) or quads.
    Fan {
        n: u8,
        quads: bool,
        closed: bool,
    },
    Solid(Solid),
    /// Any polygons over 3..=16 vertices (mostly invalid: exercises validation).
    Soup {
        vertices: u8,
        faces: Vec<Vec<u8>>,
    },
}

#[derive(Arbitrary, Debug, Clone, Copy)]
pub enum Coord {
    /// Template position plus `jitter / 64`.
    Jitter([i8; 3]),
    /// Any coordinates.
    Raw([f64; 3]),
}

#[derive(Arbitrary, Debug, Clone)]
pub struct MeshSpec {
    pub shape: Shape,
    /// Template positions scaled by `2^(scale_exp / 4)` (−128..=127 → about 2^±32), which
    /// probes degenerate and large geometry without leaving the range.
    pub scale_exp: i8,
    pub coords: Vec<Coord>,
    pub drop_faces: Vec<u8>,
    pub flip_faces: Vec<u8>,
    /// Replace vertex `.0` by vertex `.1` everywhere (non-manifold, repeated corners...).
    pub weld: Option<(u8, u8)>,
    /// Crease on corner `.1` → `.1 + 1` of face `.0` (an edge), or on two vertices if `.2`.
    pub creases: Vec<(u8, u8, bool, Sharp)>,
    pub corners: Vec<(u8, Sharp)>,
    pub holes: Vec<u8>,
    pub boundary: u8,
    pub chaikin: bool,
    pub smooth_triangles: bool,
}

/// Positions (template coordinates) and faces of a shape.
type Template = (Vec<[f64; 3]>, Vec<Vec<u32>>);

fn grid(w: usize, h: usize, tri: u64, diag: u64, wrap_u: bool, wrap_v: bool) -> Template {
    // Wrapping needs at least three cells that way, or faces would repeat a vertex / an edge.
    let wrap_u = wrap_u && w >= 3;
    let wrap_v = wrap_v && h >= 3;
    let cols = if wrap_u { w } else { w + 1 };
    let rows = if wrap_v { h } else { h + 1 };
    let mut pos = Vec::with_capacity(cols * rows);
    for j in 0..rows {
        for i in 0..cols {
            let (a, b) = (i as f64 / w as f64, j as f64 / h as f64);
            pos.push(match (wrap_u, wrap_v) {
                (false, false) => [a, b, 0.0],
                (true, false) => {
                    let t = a * std::f64::consts::TAU;
                    [t.cos(), t.sin(), b]
                }
                (false, true) => {
                    let t = b * std::f64::consts::TAU;
                    [a, t.cos(), t.sin()]
                }
                (true, true) => {
                    let (s, t) = (a * std::f64::consts::TAU, b * std::f64::consts::TAU);
                    let r = 2.0 + t.cos();
                    [r * s.cos(), r * s.sin(), t.sin()]
                }
            });
        }
    }
    let id = |i: usize, j: usize| ((j % rows) * cols + (i % cols)) as u32;
    let mut faces = Vec::new();
    for j in 0..h {
        for i in 0..w {
            let c = j * w + i;
            let q = [id(i, j), id(i + 1, j), id(i + 1, j + 1), id(i, j + 1)];
            if c < 64 && tri >> c & 1 == 1 {
                if diag >> c & 1 == 1 {
                    faces.push(vec![q[0], q[1], q[2]]);
                    faces.push(vec![q[0], q[2], q[3]]);
                } else {
                    faces.push(vec![q[0], q[1], q[3]]);
                    faces.push(vec![q[1], q[2], q[3]]);
                }
            } else {
                faces.push(q.to_vec());
            }
        }
    }
    (pos, faces)
}

fn fan(n: usize, quads: bool, closed: bool) -> Template {
    // Point at angle `half / 2n` of a turn on a circle of radius `r`.
    let ring = |half: usize, r: f64, z: f64| {
        let t = half as f64 / (2 * n) as f64 * std::f64::consts::TAU;
        [r * t.cos(), r * t.sin(), z]
    };
    let mut pos = vec![[0.0, 0.0, 0.5]];
    let mut faces = Vec::new();
    pos.extend((0..n).map(|k| ring(2 * k, 1.0, 0.0)));
    let r = |k: usize| 1 + (k % n) as u32;
    if quads {
        // Outer vertex k sits between ring vertices k and k + 1.
        pos.extend((0..n).map(|k| ring(2 * k + 1, 1.5, 0.0)));
        for k in 0..n {
            faces.push(vec![0, r(k), (1 + n + k) as u32, r(k + 1)]);
        }
    } else {
        for k in 0..n {
            faces.push(vec![0, r(k), r(k + 1)]);
        }
        if closed {
            pos.push([0.0, 0.0, -0.5]);
            let south = pos.len() as u32 - 1;
            for k in 0..n {
                faces.push(vec![south, r(k + 1), r(k)]);
            }
        }
    }
    (pos, faces)
}

fn solid(s: Solid) -> Template {
    match s {
        Solid::Tetrahedron => (
            vec![[1., 1., 1.], [-1., -1., 1.], [-1., 1., -1.], [1., -1., -1.]],
            vec![vec![0, 1, 2], vec![0, 3, 1], vec![0, 2, 3], vec![1, 3, 2]],
        ),
        Solid::Cube => (
            vec![
                [0., 0., 0.],
                [1., 0., 0.],
                [1., 1., 0.],
                [0., 1., 0.],
                [0., 0., 1.],
                [1., 0., 1.],
                [1., 1., 1.],
                [0., 1., 1.],
            ],
            vec![
                vec![0, 3, 2, 1],
                vec![4, 5, 6, 7],
                vec![0, 1, 5, 4],
                vec![1, 2, 6, 5],
                vec![2, 3, 7, 6],
                vec![3, 0, 4, 7],
            ],
        ),
        Solid::Octahedron => (
            vec![
                [1., 0., 0.],
                [-1., 0., 0.],
                [0., 1., 0.],
                [0., -1., 0.],
                [0., 0., 1.],
                [0., 0., -1.],
            ],
            vec![
                vec![4, 0, 2],
                vec![4, 2, 1],
                vec![4, 1, 3],
                vec![4, 3, 0],
                vec![5, 2, 0],
                vec![5, 1, 2],
                vec![5, 3, 1],
                vec![5, 0, 3],
            ],
        ),
    }
}

impl MeshSpec {
    /// Decode from fuzz bytes (`None` when the bytes run out before a shape is read).
    pub fn from_bytes(data: &[u8]) -> Option<MeshSpec> {
        MeshSpec::arbitrary_take_rest(Unstructured::new(data)).ok()
    }

    fn template(&self) -> Template {
        match &self.shape {
            Shape::Grid {
                w,
                h,
                tri,
                diag,
                wrap_u,
                wrap_v,
            } => grid(
                1 + (*w % 6) as usize,
                1 + (*h % 6) as usize,
                *tri,
                *diag,
                *wrap_u,
                *wrap_v,
            ),
            Shape::Fan { n, quads, closed } => fan(3 + (*n % 14) as usize, *quads, *closed),
            Shape::Solid(s) => solid(*s),
            Shape::Soup { vertices, faces } => {
                let nv = 3 + (*vertices % 14) as usize;
                let pos = (0..nv)
                    .map(|k| {
                        let t = k as f64;
                        [t.sin(), t.cos(), (t * 0.37).sin()]
                    })
                    .collect();
                let faces = faces
                    .iter()
                    .take(24)
                    .map(|f| {
                        f.iter()
                            .take(8)
                            .map(|&v| (v as usize % nv) as u32)
                            .collect()
                    })
                    .collect();
                (pos, faces)
            }
        }
    }

    /// The control mesh (not validated: that is the library's job).
    pub fn build(&self) -> ControlMesh {
        let (mut pos, mut faces) = self.template();
        debug_assert!(pos.len() <= MAX_VERTICES && faces.len() <= MAX_FACES);
        let scale = 2f64.powf(self.scale_exp as f64 / 4.0);
        for p in pos.iter_mut() {
            *p = p.map(|c| c * scale);
        }
        for (p, c) in pos.iter_mut().zip(&self.coords) {
            match *c {
                Coord::Jitter(j) => {
                    for k in 0..3 {
                        p[k] += j[k] as f64 / 64.0 * scale;
                    }
                }
                Coord::Raw(r) => *p = r,
            }
        }
        if !faces.is_empty() {
            for &f in &self.flip_faces {
                let n = faces.len();
                faces[f as usize % n].reverse();
            }
            let mut keep = vec![true; faces.len()];
            for &f in &self.drop_faces {
                keep[f as usize % faces.len()] = false;
            }
            let mut k = keep.iter();
            faces.retain(|_| *k.next().unwrap_or(&true));
        }
        let nv = pos.len() as u32;
        if let Some((a, b)) = self.weld {
            let (a, b) = (a as u32 % nv, b as u32 % nv);
            for f in faces.iter_mut() {
                for v in f.iter_mut() {
                    if *v == a {
                        *v = b;
                    }
                }
            }
        }
        let mut mesh = ControlMesh::from_polygons(pos, &faces);
        for &(f, c, pair, s) in &self.creases {
            let vertices = if pair || faces.is_empty() {
                [f as u32 % nv, c as u32 % nv]
            } else {
                let face = &faces[f as usize % faces.len()];
                if face.is_empty() {
                    continue;
                }
                let k = c as usize % face.len();
                [face[k], face[(k + 1) % face.len()]]
            };
            mesh.creases.push(EdgeCrease {
                vertices,
                sharpness: s.value(),
            });
        }
        for &(v, s) in &self.corners {
            mesh.corners.push(VertexCorner {
                vertex: v as u32 % nv,
                sharpness: s.value(),
            });
        }
        let nf = faces.len().max(1) as u32;
        mesh.holes = self.holes.iter().map(|&h| h as u32 % nf).collect();
        mesh.options.boundary = match self.boundary % 3 {
            0 => BoundaryInterpolation::EdgesOnly,
            1 => BoundaryInterpolation::EdgesAndCorners,
            _ => BoundaryInterpolation::None,
        };
        if self.chaikin {
            mesh.options.crease_method = CreaseMethod::Chaikin;
        }
        if self.smooth_triangles {
            mesh.options.triangle_subdivision = TriangleSubdivision::Smooth;
        }
        mesh
    }
}

/// Makes the fuzzing thread rayon's only worker, so the library's parallel iterators run
/// inline instead of handing every call to a pool thread (a cross-thread wake-up per call
/// costs more than these small meshes' whole validation). Call once, from `fuzz_target!`'s
/// `init`.
pub fn single_thread_rayon() {
    // An error means a global pool exists already: fine, it only costs speed.
    let _ = rayon::ThreadPoolBuilder::new()
        .num_threads(1)
        .use_current_thread()
        .build_global();
}

/// Whether every coordinate is finite and within [`MAX_COORD`].
pub fn positions_in_range(mesh: &ControlMesh) -> bool {
    mesh.positions
        .iter()
        .all(|p| p.iter().all(|c| c.is_finite() && c.abs() <= MAX_COORD))
}

/// Whether every value is finite.
pub fn all_finite<'a>(values: impl IntoIterator<Item = &'a f64>) -> bool {
    values.into_iter().all(|x| x.is_finite())
}

/// A parameter in `[0, 1]` from two bytes: exact dyadic corners and midpoints often (where
/// the evaluator takes its mask and regular-patch shortcuts), any fraction otherwise.
pub fn param(u: &mut Unstructured) -> f64 {
    let k: u16 = u.arbitrary().unwrap_or(0);
    match k % 8 {
        0 => 0.0,
        1 => 1.0,
        2 => 0.5,
        3 => (k >> 3) as f64 / 8192.0, // dyadic, k >> 3 < 8192
        _ => (k as f64 / u16::MAX as f64).clamp(0.0, 1.0),
    }
}
