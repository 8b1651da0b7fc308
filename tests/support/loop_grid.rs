//! The bumpy triangulated grid the BFT tests of topology and tess share (included with
//! `#[path]`).
use topology::ControlMesh;

/// A bumpy triangulated grid with pseudo-random diagonals (interior valences 4–8, boundary
/// valences 2–5); corner quads are split through the corner so no triangle has two boundary
/// edges.
pub fn grid_mesh(m: u32) -> ControlMesh {
    let mut pos = Vec::new();
    for y in 0..=m {
        for x in 0..=m {
            let (fx, fy) = (x as f64, y as f64);
            pos.push([fx, fy, 0.3 * (0.7 * fx).sin() * (0.5 * fy).cos()]);
        }
    }
    let id = |x: u32, y: u32| y * (m + 1) + x;
    let mut faces = Vec::new();
    for y in 0..m {
        for x in 0..m {
            let (a, b, c, d) = (id(x, y), id(x + 1, y), id(x + 1, y + 1), id(x, y + 1));
            let corner_ac = (x == 0 && y == 0) || (x == m - 1 && y == m - 1);
            let corner_bd = (x == m - 1 && y == 0) || (x == 0 && y == m - 1);
            let diag_ac = corner_ac || (!corner_bd && (x * 7 + y * 13 + x * y) % 3 != 0);
            if diag_ac {
                faces.push(vec![a, b, c]);
                faces.push(vec![a, c, d]);
            } else {
                faces.push(vec![a, b, d]);
                faces.push(vec![b, c, d]);
            }
        }
    }
    ControlMesh::from_polygons(pos, &faces)
}
