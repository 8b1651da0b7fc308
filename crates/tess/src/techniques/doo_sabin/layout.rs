//! The host half of the Doo-Sabin technique: the levels of a uniform Doo-Sabin refinement as
//! stencil rows per level for the GPU evaluator, the deepest level's faces as triangle fans and
//! its points' face corners (what the vertex stage sums a normal from), each point's base face
//! point, and the sizes of the levels counted without refining.
//!
//! Every level is a block of the stencil evaluator over one vertex buffer, in place: the base
//! positions at its head (copied there every frame), then levels 1, 2, ..., each block's rows
//! reading the level before it ([`topology::refine::doo_sabin::refine_dual`]'s rows, their
//! indices moved to where that level lies in the buffer). The deepest level starts at a
//! storage-buffer offset the device can bind, so the vertex stage reads it as a range of its
//! own with level-local numbers.
use crate::gpu::bindings::DOO_SABIN_MAX_CORNERS;
use crate::stencil::{GpuStencils, StencilBlock, StencilError};
use topology::mesh::Topology;
use topology::refine::doo_sabin::refine_dual;
use topology::refine::Level;
use topology::TopologyError;

/// Everything the GPU needs for one depth, built on the host once per depth.
#[derive(Clone, Debug)]
pub struct DepthLayout {
    pub depth: u32,
    /// Rows of every level over the vertex buffer, one block per level.
    pub stencils: GpuStencils,
    pub blocks: Vec<StencilBlock>,
    /// Vertices of the whole buffer (base, every level, the alignment gap).
    pub num_vertices: u32,
    /// Where the deepest level starts in the buffer, and its point count.
    pub first_point: u32,
    pub points: u32,
    /// The deepest level's faces as triangle fans (level-local point numbers).
    pub triangles: Vec<u32>,
    /// Per deepest-level point, [`DOO_SABIN_MAX_CORNERS`] `(next, previous)` neighbour pairs,
    /// unused slots naming the point itself.
    pub corners: Vec<[u32; 2]>,
    /// The deepest level as the CPU refined it (positions of the base it was built from).
    pub level: Level,
}

/// `x` rounded up to a multiple of `step`.
fn align_up(x: u32, step: u32) -> Option<u32> {
    x.checked_next_multiple_of(step.max(1))
}

/// Why a depth cannot be laid out.
#[derive(Debug, thiserror::Error)]
pub enum LayoutError {
    #[error(transparent)]
    Topology(#[from] TopologyError),
    #[error(transparent)]
    Stencil(#[from] StencilError),
    #[error("Doo-Sabin level {level}: point {point} lies in {corners} face corners, more than {DOO_SABIN_MAX_CORNERS}")]
    Corners {
        level: u32,
        point: u32,
        corners: u32,
    },
    #[error("Doo-Sabin level {level}: {vertices} vertices overflow 32-bit indices")]
    TooLarge { level: u32, vertices: u64 },
}

/// Lays out `depth` levels of `base`, the deepest starting at a multiple of `align` vertices.
pub fn layout(base: &Level, depth: u32, align: u32) -> Result<DepthLayout, LayoutError> {
    let mut stencils = GpuStencils::default();
    let mut blocks = Vec::with_capacity(depth as usize);
    let mut level = base.clone();
    let mut source = 0u32;
    let mut next = base.num_vertices() as u32;
    for k in 0..depth {
        let step = refine_dual(&level, k == 0)?;
        let n = step.level.num_vertices() as u32;
        let last = k + 1 == depth;
        let start = if last {
            align_up(next, align)
        } else {
            Some(next)
        };
        let too_large = LayoutError::TooLarge {
            level: k + 1,
            vertices: next as u64 + n as u64,
        };
        let start = start.ok_or(too_large)?;
        start.checked_add(n).ok_or(LayoutError::TooLarge {
            level: k + 1,
            vertices: start as u64 + n as u64,
        })?;
        let table = &step.stencils;
        let first_row = stencils.rows();
        for r in 0..n as usize {
            let (k0, k1) = (table.offsets[r] as usize, table.offsets[r + 1] as usize);
            let indices: Vec<u32> = table.indices[k0..k1].iter().map(|i| i + source).collect();
            stencils.push_row(&indices, &table.weights[k0..k1])?;
        }
        blocks.push(StencilBlock {
            rows: first_row..first_row + n,
            destination: start,
        });
        source = start;
        next = start + n;
        level = step.level;
    }
    let t = &level.topology;
    Ok(DepthLayout {
        depth,
        stencils,
        blocks,
        num_vertices: next,
        first_point: source,
        points: t.num_vertices() as u32,
        triangles: fans(t),
        corners: corners(t, depth)?,
        level,
    })
}

/// The faces of `t` as triangle fans from each face's first corner.
fn fans(t: &Topology) -> Vec<u32> {
    let mut out = Vec::new();
    for f in 0..t.num_faces() {
        let fv = t.face_vertices(f);
        for j in 1..fv.len().saturating_sub(1) {
            out.extend([fv[0], fv[j], fv[j + 1]]);
        }
    }
    out
}

/// Per point of `t`, its face corners as `(next, previous)` pairs, padded with the point.
fn corners(t: &Topology, level: u32) -> Result<Vec<[u32; 2]>, LayoutError> {
    let max = DOO_SABIN_MAX_CORNERS as usize;
    let n = t.num_vertices();
    let mut out: Vec<[u32; 2]> = (0..n as u32).flat_map(|v| [[v, v]; 4]).collect();
    let mut used = vec![0u32; n];
    for f in 0..t.num_faces() {
        let fv = t.face_vertices(f);
        let len = fv.len();
        for (i, &v) in fv.iter().enumerate() {
            let slot = used[v as usize];
            if slot as usize >= max {
                return Err(LayoutError::Corners {
                    level,
                    point: v,
                    corners: slot + 1,
                });
            }
            out[v as usize * max + slot as usize] = [fv[(i + 1) % len], fv[(i + len - 1) % len]];
            used[v as usize] += 1;
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use topology::refine::doo_sabin::{first_level_size, level_sizes, LevelSize};
    use topology::refine::refine_uniform;
    use topology::{load_obj, ControlMesh, Scheme};

    /// A mesh of the repository's test data (`path` from its root).
    fn mesh(path: &str) -> ControlMesh {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
        load_obj(format!("{root}/{path}")).expect(path)
    }

    /// Valence 3 (cube), valence 5 and triangles (icosahedron), triangles around a quad
    /// (pyramid), pentagons (spot), boundaries (edge-corner, extraordinary boundary vertex).
    pub(crate) const SHAPES: [&str; 6] = [
        "tests/data/opensubdiv/shapes/catmark_cube.obj",
        "tests/data/opensubdiv/shapes/loop_icosahedron.obj",
        "tests/data/opensubdiv/shapes/catmark_pyramid.obj",
        "assets/spot_control_mesh.obj",
        "tests/data/opensubdiv/shapes/catmark_edgecorner.obj",
        "tests/data/opensubdiv/shapes/catmark_xord_boundary.obj",
    ];

    /// The counted sizes are the refiner's, level for level, on closed and open meshes with
    /// triangles, pentagons and valences 3 and 5; the layout's rows give the refiner's points.
    #[test]
    fn counted_sizes_and_laid_out_rows_match_the_refiner() {
        for name in SHAPES {
            let mesh = mesh(name);
            let base = Level::from_mesh(&mesh, Scheme::DooSabin).expect("base");
            let r = refine_uniform(&mesh, Scheme::DooSabin, 4).expect("refine");
            let sizes = level_sizes(first_level_size(&base).expect("level 1"), 4);
            for (k, s) in sizes.iter().enumerate() {
                assert_eq!(
                    *s,
                    LevelSize::of(&r.level(k + 1).topology),
                    "{name} level {}",
                    k + 1
                );
            }
            let l = layout(&base, 3, 16).expect("layout");
            assert_eq!(l.first_point % 16, 0);
            assert_eq!(l.points as usize, r.level(3).num_vertices());
            assert_eq!(l.triangles.len() as u64, 3 * sizes[2].triangles());
            let mut buffer = vec![[0f32; 3]; l.num_vertices as usize];
            for (v, p) in mesh.positions.iter().enumerate() {
                buffer[v] = p.map(|c| c as f32);
            }
            for b in &l.blocks {
                for row in b.rows.clone() {
                    let p = l.stencils.row_point(row, |i| buffer[i as usize]);
                    buffer[(b.destination + row - b.rows.start) as usize] = p;
                }
            }
            let diagonal = mesh.bbox_diagonal();
            for (v, want) in r.level(3).positions.iter().enumerate() {
                let got = buffer[l.first_point as usize + v];
                for c in 0..3 {
                    assert!(
                        (got[c] as f64 - want[c]).abs() < 1e-6 * diagonal,
                        "{name} point {v}"
                    );
                }
            }
        }
    }
}
