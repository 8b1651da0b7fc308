//! What the camera frames and what the GPU's f32 can draw.
//!
//! Every technique frames the box of the vertices its faces use ([`drawn_bbox`]): a vertex no
//! face uses (OBJ files often have them) is not drawn, so a far one must not shrink the
//! picture to a dot.
//!
//! [`check_drawable`] refuses, before anything is built, what f32 positions cannot draw: a face
//! edge whose two ends are distinct in the file but the same f32 point (a mesh far from the
//! origin for its size: at x ≈ 1e12, f32 steps by 65,536; or coordinates below f32's smallest
//! numbers). [`check_shaded`] also refuses a mesh too small to shade: the surface techniques'
//! normals are cross products of tangents of the mesh's size, which underflow f32 below
//! [`MIN_SHADED_EXTENT`] (a cube of 1e-30 is framed, but its limit surface comes out as a
//! flat silhouette). Captures (`tessera export`) need no shading and take such meshes.
use crate::techniques::shared::gpu_coordinate;
use topology::ControlMesh;

/// The smallest diagonal of the drawn faces that is shaded: squares of lengths of the mesh's
/// size (cross products of tangents) stay far above f32's smallest normal number (1.2e-38).
pub const MIN_SHADED_EXTENT: f64 = 1e-15;

/// The vertices of `mesh`'s faces that are not holes, or of every face when all are holes.
fn drawn_vertices(mesh: &ControlMesh) -> Vec<bool> {
    let mut used = vec![false; mesh.positions.len()];
    let holes: std::collections::HashSet<u32> = mesh.holes.iter().copied().collect();
    let all_holes = (0..mesh.num_faces()).all(|f| holes.contains(&(f as u32)));
    for f in 0..mesh.num_faces() {
        if all_holes || !holes.contains(&(f as u32)) {
            for &v in mesh.face(f) {
                if let Some(u) = used.get_mut(v as usize) {
                    *u = true;
                }
            }
        }
    }
    used
}

/// The f32 box of the vertices `mesh`'s drawn faces use (as the GPU receives them); the box of
/// every vertex when no face uses one, `([0; 3], [0; 3])` for no vertex.
pub fn drawn_bbox(mesh: &ControlMesh) -> ([f32; 3], [f32; 3]) {
    let used = drawn_vertices(mesh);
    let any = used.iter().any(|&u| u);
    let mut lo = [f32::MAX; 3];
    let mut hi = [f32::MIN; 3];
    let mut seen = false;
    for (p, &u) in mesh.positions.iter().zip(&used) {
        if any && !u {
            continue;
        }
        seen = true;
        for k in 0..3 {
            let c = gpu_coordinate(p[k]);
            lo[k] = lo[k].min(c);
            hi[k] = hi[k].max(c);
        }
    }
    if seen {
        (lo, hi)
    } else {
        ([0.0; 3], [0.0; 3])
    }
}

/// Why a mesh cannot be drawn in f32 ([`check_drawable`]); vertex and face numbers are the
/// mesh's (0-based).
#[derive(Clone, Debug, PartialEq)]
pub enum Undrawable {
    /// Two ends of an edge of `face`, distinct positions, round to one f32 point.
    Collapsed {
        face: usize,
        vertices: [u32; 2],
        positions: [[f64; 3]; 2],
        f32_point: [f32; 3],
    },
    /// The drawn faces' diagonal is below [`MIN_SHADED_EXTENT`] (and not 0: a mesh all of
    /// whose vertices coincide in the file is the file's own degenerate mesh).
    TooSmallToShade { extent: f64 },
}

impl std::fmt::Display for Undrawable {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        let n = topology::error::number;
        let xyz = |p: &[f64; 3]| format!("{}, {}, {}", n(p[0]), n(p[1]), n(p[2]));
        match self {
            Undrawable::Collapsed {
                face,
                vertices,
                positions,
                f32_point,
            } => write!(
                f,
                "face {}: vertices {} ({}) and {} ({}) are one point in the GPU's f32 \
                 arithmetic ({}): the mesh is too far from the origin for its size (move it \
                 nearer the origin)",
                face + 1,
                vertices[0] + 1,
                xyz(&positions[0]),
                vertices[1] + 1,
                xyz(&positions[1]),
                xyz(&f32_point.map(f64::from))
            ),
            Undrawable::TooSmallToShade { extent } => write!(
                f,
                "the drawn faces span {}, below the {} the GPU's f32 arithmetic shades (normals \
                 underflow; scale the mesh up)",
                n(*extent),
                n(MIN_SHADED_EXTENT)
            ),
        }
    }
}

/// [`check_drawable`], and a drawn box below [`MIN_SHADED_EXTENT`]: what a picture needs.
pub fn check_shaded(mesh: &ControlMesh) -> Result<(), Undrawable> {
    check_drawable(mesh)?;
    let (lo, hi) = drawn_bbox(mesh);
    let extent = (0..3)
        .map(|k| (f64::from(hi[k]) - f64::from(lo[k])).powi(2))
        .sum::<f64>()
        .sqrt();
    if extent > 0.0 && extent < MIN_SHADED_EXTENT {
        return Err(Undrawable::TooSmallToShade { extent });
    }
    Ok(())
}

/// Refuses what the GPU's f32 cannot draw (see the module docs): the first collapsed face
/// edge.
pub fn check_drawable(mesh: &ControlMesh) -> Result<(), Undrawable> {
    for f in 0..mesh.num_faces() {
        let fv = mesh.face(f);
        for i in 0..fv.len() {
            let (a, b) = (fv[i], fv[(i + 1) % fv.len()]);
            let (Some(pa), Some(pb)) = (
                mesh.positions.get(a as usize),
                mesh.positions.get(b as usize),
            ) else {
                continue;
            };
            let (qa, qb) = (pa.map(gpu_coordinate), pb.map(gpu_coordinate));
            if pa != pb && qa == qb {
                return Err(Undrawable::Collapsed {
                    face: f,
                    vertices: [a, b],
                    positions: [*pa, *pb],
                    f32_point: qa,
                });
            }
        }
    }
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::*;

    fn cube(scale: f64, offset: [f64; 3]) -> ControlMesh {
        let mut p = Vec::new();
        for i in 0..8u32 {
            let c = |bit: u32, k: usize| offset[k] + scale * f64::from((i >> bit) & 1);
            p.push([c(0, 0), c(1, 1), c(2, 2)]);
        }
        let faces: [[u32; 4]; 6] = [
            [0, 2, 3, 1],
            [4, 5, 7, 6],
            [0, 1, 5, 4],
            [2, 6, 7, 3],
            [0, 4, 6, 2],
            [1, 3, 7, 5],
        ];
        ControlMesh::from_polygons(p, &faces)
    }

    /// A far vertex no face uses leaves the box of the drawn ones.
    #[test]
    fn unused_vertices_are_not_framed() {
        let mut m = cube(1.0, [0.0; 3]);
        m.positions.push([1e9, 1e9, 1e9]);
        assert_eq!(drawn_bbox(&m), ([0.0; 3], [1.0; 3]));
    }

    /// Accepted: ordinary, tiny, far but resolved, all coincident (the file's own degenerate
    /// mesh). Refused: corners that collapse in f32 (far from the origin for their size, or
    /// below f32's smallest numbers), naming what they are.
    #[test]
    fn what_f32_cannot_draw_is_refused() {
        for ok in [
            cube(1.0, [0.0; 3]),
            cube(1e-9, [0.0; 3]),
            cube(1e-9, [1e-6; 3]),
            cube(1e-30, [0.0; 3]),
            cube(1e6, [1e12; 3]),
            cube(0.0, [5.0; 3]),
        ] {
            check_drawable(&ok).unwrap();
        }
        let e = check_drawable(&cube(1.0, [1e12, 0.0, 0.0])).unwrap_err();
        assert!(
            matches!(
                e,
                Undrawable::Collapsed {
                    face: 0,
                    vertices: [2, 3],
                    ..
                }
            ),
            "{e:?}"
        );
        assert!(
            e.to_string().starts_with(
                "face 1: vertices 3 (1000000000000, 1, 0) and 4 (1000000000001, 1, 0) are one \
                 point in the GPU's f32 arithmetic (999999995904, 1, 0)"
            ),
            "{e}"
        );
        let e = check_drawable(&cube(1e-50, [0.0; 3])).unwrap_err();
        assert!(matches!(e, Undrawable::Collapsed { .. }), "{e:?}");
        // Shaded pictures need more.
        check_shaded(&cube(1e-9, [0.0; 3])).unwrap();
        check_shaded(&cube(0.0, [5.0; 3])).unwrap();
        let e = check_shaded(&cube(1e-30, [0.0; 3])).unwrap_err();
        assert!(matches!(e, Undrawable::TooSmallToShade { .. }), "{e:?}");
        assert!(e.to_string().contains("span 1.7320508"), "{e}");
    }
}
