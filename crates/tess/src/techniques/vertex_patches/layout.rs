//! The host half of the vertex-patch technique, built once per depth: where every patch's
//! array lies at every depth in one buffer, the first step as stencil rows over the base
//! positions, the per-step patch records and point flags of `refine.comp`, the Doo-Sabin
//! weight table, the deepest depth's owned faces as triangle fans and its slots' face corners,
//! and each deepest slot's vertex of the CPU refinement (what capture maps a slot back by).
//!
//! The buffer: the base positions at its head (copied there every frame), then depth 1's
//! arrays (one patch after another, in patch order), depth 2's, …, depth D's.
use crate::gpu::bindings::{
    DOO_SABIN_MAX_CORNERS, VERTEX_PATCHES_MAX_FACE, VERTEX_PATCH_BOUNDARY, VERTEX_PATCH_PRESENT,
};
use crate::gpu::VertexPatchRecord;
use crate::stencil::{GpuStencils, StencilBlock, StencilError};
use topology::mesh::{Topology, INVALID};
use topology::patches::doo_sabin::{vertex_patches, PatchLayout, PointFlags, VertexPatch};
use topology::refine::doo_sabin::refine_dual;
use topology::refine::Level;
use topology::rules::doo_sabin::{corner_weights, strip_edge};
use topology::TopologyError;

/// Everything the GPU needs for one depth.
#[derive(Clone, Debug)]
pub struct PatchesLayout {
    pub depth: u32,
    /// The first step: one row per depth-1 slot over the base positions (an absent slot's row
    /// is empty), one block written from `regions[0]`.
    pub stencils: GpuStencils,
    pub blocks: Vec<StencilBlock>,
    /// Elements of the whole buffer.
    pub num_points: u32,
    /// Where depth `d`'s arrays start (`regions[d − 1]`).
    pub regions: Vec<u32>,
    /// Flag bits per element (`VERTEX_PATCH_PRESENT`, `VERTEX_PATCH_BOUNDARY`).
    pub flags: Vec<u32>,
    /// Per step `d → d + 1`, its records (one per patch) and work items.
    pub steps: Vec<(Vec<VertexPatchRecord>, u32)>,
    /// Corner-size prefix sums, `n + 1` per patch.
    pub sizes: Vec<u32>,
    /// Per face size `m`, `m` full-face weights then `m × m` strip weights (row `r`: the child
    /// of the corner `r` after the strip's boundary edge's start, over the corners from it on).
    pub weights: Vec<f32>,
    /// Where face size `m`'s weights start, `m` in `0..=VERTEX_PATCHES_MAX_FACE`.
    pub weight_starts: Vec<u32>,
    /// The deepest depth's slots.
    pub slots: u32,
    /// Owned faces of the deepest depth as triangle fans (slots).
    pub triangles: Vec<u32>,
    /// Per deepest slot, `DOO_SABIN_MAX_CORNERS` `(next, previous)` slots (the slot itself
    /// where unused).
    pub corners: Vec<[u32; 2]>,
    /// Per deepest slot, the CPU refinement's level-D vertex (`INVALID` where absent).
    pub slot_vertices: Vec<u32>,
    /// Vertices of level D.
    pub level_vertices: u32,
    /// Patches (control vertices with faces).
    pub patches: u32,
}

/// Why a depth cannot be laid out.
#[derive(Debug, thiserror::Error)]
pub enum LayoutError {
    #[error(transparent)]
    Topology(#[from] TopologyError),
    #[error(transparent)]
    Stencil(#[from] StencilError),
    #[error("Doo-Sabin vertex patches: patch of vertex {vertex} has a face of {size} corners, more than the {VERTEX_PATCHES_MAX_FACE} the refinement kernel takes")]
    FaceTooLarge { vertex: u32, size: usize },
    #[error("Doo-Sabin vertex patches: the patch of vertex {vertex} at depth {depth} has a face whose boundary points are not one edge")]
    Strip { vertex: u32, depth: u32 },
    #[error("Doo-Sabin vertex patches: level {level} point {point} lies in {corners} face corners, more than {DOO_SABIN_MAX_CORNERS}")]
    Corners {
        level: u32,
        point: u32,
        corners: u32,
    },
    #[error("Doo-Sabin vertex patches: depth {depth} needs {elements} buffer elements, more than 32-bit indices reach")]
    TooLarge { depth: u32, elements: u64 },
}

fn bits(f: PointFlags) -> u32 {
    (f.present as u32) * VERTEX_PATCH_PRESENT + (f.boundary as u32) * VERTEX_PATCH_BOUNDARY
}

/// The vertex patches of `base` fit the refinement kernel at every depth: no face larger than
/// its local arrays (a v-face of valence over `VERTEX_PATCHES_MAX_FACE`, or a corner face of
/// that many corners). Checked when the technique is built, before any depth is asked for.
pub fn check_patches(base: &Level) -> Result<(), LayoutError> {
    let step = refine_dual(base, true)?;
    check_face_sizes(&vertex_patches(&base.topology, &step)?)
}

/// Lays out depths `1..=depth` of the vertex patches of `base`.
pub fn layout(base: &Level, depth: u32) -> Result<PatchesLayout, LayoutError> {
    let step = refine_dual(base, true)?;
    let patches = vertex_patches(&base.topology, &step)?;
    check_faces(&patches, depth)?;
    let mut levels = Vec::with_capacity(depth as usize);
    let mut last = step.level.clone();
    for _ in 1..depth {
        let next = refine_dual(&last, false)?.level;
        levels.push(std::mem::replace(&mut last, next));
    }
    levels.push(last);
    // Regions and per-patch offsets at every depth.
    let base_len = base.num_vertices() as u64;
    let mut regions = Vec::new();
    let mut offsets: Vec<Vec<u32>> = Vec::new();
    let mut next = base_len;
    for d in 1..=depth {
        regions.push(next as u32);
        let mut at = Vec::with_capacity(patches.len());
        for p in &patches {
            at.push(next as u32);
            next += p.layout().len(d) as u64;
            if next > u32::MAX as u64 {
                return Err(LayoutError::TooLarge {
                    depth,
                    elements: next,
                });
            }
        }
        offsets.push(at);
    }
    let num_points = next as u32;
    let mut flags = vec![0u32; num_points as usize];
    let mut sizes = Vec::new();
    let mut size_starts = Vec::new();
    for (p, patch) in patches.iter().enumerate() {
        for (d, f) in patch.flags_to(depth).iter().enumerate() {
            let at = offsets[d][p] as usize;
            for (i, &x) in f.iter().enumerate() {
                flags[at + i] = bits(x);
            }
        }
        size_starts.push(sizes.len() as u32);
        let mut sum = 0u32;
        sizes.push(0);
        for &m in &patch.corner_sizes {
            sum += m as u32;
            sizes.push(sum);
        }
    }
    let steps = (1..depth)
        .map(|d| step_records(&patches, &size_starts, &offsets, d))
        .collect();
    let (stencils, blocks) = first_step(&patches, &step, regions[0])?;
    let (weights, weight_starts) = weight_table();
    let deepest = deepest(&patches, &levels, &offsets[depth as usize - 1], depth)?;
    Ok(PatchesLayout {
        depth,
        stencils,
        blocks,
        num_points,
        regions: regions.clone(),
        flags,
        steps,
        sizes,
        weights,
        weight_starts,
        slots: num_points - regions[depth as usize - 1],
        triangles: deepest.triangles,
        corners: deepest.corners,
        slot_vertices: deepest.slot_vertices,
        level_vertices: levels[depth as usize - 1].num_vertices() as u32,
        patches: patches.len() as u32,
    })
}

/// Every face the kernel refines fits its local arrays, and every present face with boundary
/// points has them on one edge (the strip the kernel's mask assumes).
fn check_faces(patches: &[VertexPatch], depth: u32) -> Result<(), LayoutError> {
    check_face_sizes(patches)?;
    for patch in patches {
        let layout = patch.layout();
        for (d, flags) in (1..).zip(patch.flags_to(depth)) {
            for face in layout.faces(d) {
                let c = &face.corners;
                if !c.iter().all(|&i| flags[i].present) {
                    continue;
                }
                strip_edge(c.len(), |k| flags[c[k]].boundary).map_err(|_| LayoutError::Strip {
                    vertex: patch.vertex,
                    depth: d,
                })?;
            }
        }
    }
    Ok(())
}

/// Every face the kernel refines fits its local arrays (and the kernel's 32-bit corner masks).
fn check_face_sizes(patches: &[VertexPatch]) -> Result<(), LayoutError> {
    for patch in patches {
        let too_large = patch
            .corner_sizes
            .iter()
            .copied()
            .chain([patch.faces.len()])
            .find(|&m| m > VERTEX_PATCHES_MAX_FACE as usize);
        if let Some(size) = too_large {
            return Err(LayoutError::FaceTooLarge {
                vertex: patch.vertex,
                size,
            });
        }
    }
    Ok(())
}

/// The records of step `d → d + 1`: `L² n + n` items a patch.
fn step_records(
    patches: &[VertexPatch],
    size_starts: &[u32],
    offsets: &[Vec<u32>],
    d: u32,
) -> (Vec<VertexPatchRecord>, u32) {
    let outer = PatchLayout::outer_layer(d) as u32;
    let mut items = 0u32;
    let mut records = Vec::with_capacity(patches.len());
    for (p, patch) in patches.iter().enumerate() {
        let n = patch.faces.len() as u32;
        records.push(VertexPatchRecord {
            valence: n,
            sizes: size_starts[p],
            source: offsets[d as usize - 1][p],
            destination: offsets[d as usize][p],
            first_item: items,
        });
        items += outer * outer * n + n;
    }
    (records, items)
}

/// Depth 1's slots as rows of the first Doo-Sabin step over the base positions.
fn first_step(
    patches: &[VertexPatch],
    step: &topology::refine::doo_sabin::DualStep,
    destination: u32,
) -> Result<(GpuStencils, Vec<StencilBlock>), LayoutError> {
    let mut stencils = GpuStencils::default();
    let table = &step.stencils;
    for patch in patches {
        for &x in &patch.points {
            if x == INVALID {
                stencils.push_row(&[], &[])?;
                continue;
            }
            let (k0, k1) = (
                table.offsets[x as usize] as usize,
                table.offsets[x as usize + 1] as usize,
            );
            stencils.push_row(&table.indices[k0..k1], &table.weights[k0..k1])?;
        }
    }
    let blocks = vec![StencilBlock {
        rows: 0..stencils.rows(),
        destination,
    }];
    Ok((stencils, blocks))
}

/// [`corner_weights`] for every face size up to `VERTEX_PATCHES_MAX_FACE`: full faces, then
/// strips by the child's distance from the boundary edge's start.
fn weight_table() -> (Vec<f32>, Vec<u32>) {
    let mut weights = Vec::new();
    let mut starts = Vec::new();
    let mut w = Vec::new();
    for m in 0..=VERTEX_PATCHES_MAX_FACE as usize {
        starts.push(weights.len() as u32);
        if m < 3 {
            continue;
        }
        corner_weights(m, None, 0, &mut w);
        weights.extend(w.iter().map(|&x| x as f32));
        for r in 0..m {
            corner_weights(m, Some(0), r, &mut w);
            weights.extend(w.iter().map(|&x| x as f32));
        }
    }
    (weights, starts)
}

/// The deepest depth's draw: fans, face corners, slot vertices.
struct Deepest {
    triangles: Vec<u32>,
    corners: Vec<[u32; 2]>,
    slot_vertices: Vec<u32>,
}

fn deepest(
    patches: &[VertexPatch],
    levels: &[Level],
    offsets: &[u32],
    depth: u32,
) -> Result<Deepest, LayoutError> {
    let topologies: Vec<&Topology> = levels.iter().map(|l| &l.topology).collect();
    let first = offsets.first().copied().unwrap_or(0);
    let mut slot_vertices = Vec::new();
    let mut triangles = Vec::new();
    for (p, patch) in patches.iter().enumerate() {
        let local = offsets[p] - first;
        slot_vertices.extend(patch.level_vertices(&topologies, depth)?);
        let flags = patch.flags_to(depth);
        // `flags_to` gives one entry per depth 1..=depth; depth 0 has no faces to draw.
        let Some(flags) = flags.last() else {
            continue;
        };
        for face in patch.layout().faces(depth) {
            if !patch.draws(depth, &face, flags) {
                continue;
            }
            let c = &face.corners;
            for j in 1..c.len() - 1 {
                triangles.extend([c[0], c[j], c[j + 1]].map(|i| local + i as u32));
            }
        }
    }
    let t = &levels[depth as usize - 1].topology;
    let corners = slot_corners(t, &slot_vertices, depth)?;
    Ok(Deepest {
        triangles,
        corners,
        slot_vertices,
    })
}

/// Per slot, its vertex's face corners in `t` as `(next, previous)` slots: each vertex named
/// by its first slot (every copy holds the same bits), unused entries the slot itself.
fn slot_corners(t: &Topology, slots: &[u32], depth: u32) -> Result<Vec<[u32; 2]>, LayoutError> {
    let max = DOO_SABIN_MAX_CORNERS as usize;
    let mut first_slot = vec![INVALID; t.num_vertices()];
    for (s, &v) in slots.iter().enumerate().rev() {
        if v != INVALID {
            first_slot[v as usize] = s as u32;
        }
    }
    let mut by_vertex: Vec<Vec<[u32; 2]>> = vec![Vec::new(); t.num_vertices()];
    for f in 0..t.num_faces() {
        let fv = t.face_vertices(f);
        let len = fv.len();
        for (i, &v) in fv.iter().enumerate() {
            let list = &mut by_vertex[v as usize];
            if list.len() == max {
                return Err(LayoutError::Corners {
                    level: depth,
                    point: v,
                    corners: max as u32 + 1,
                });
            }
            list.push([
                first_slot[fv[(i + 1) % len] as usize],
                first_slot[fv[(i + len - 1) % len] as usize],
            ]);
        }
    }
    let mut out = Vec::with_capacity(slots.len() * max);
    for (s, &v) in slots.iter().enumerate() {
        let s = s as u32;
        let list = if v == INVALID {
            &[][..]
        } else {
            &by_vertex[v as usize][..]
        };
        for k in 0..max {
            out.push(list.get(k).copied().unwrap_or([s, s]));
        }
    }
    Ok(out)
}

#[cfg(test)]
mod tests {
    use super::*;
    use topology::refine::refine_uniform;
    use topology::{load_obj, ControlMesh, Scheme};

    fn mesh(path: &str) -> ControlMesh {
        let root = concat!(env!("CARGO_MANIFEST_DIR"), "/../..");
        load_obj(format!("{root}/{path}")).expect(path)
    }

    /// A host mirror of `refine.comp` on the laid-out records and flags (f64, the CPU layout's
    /// step), run from the first step's rows (f32 weights, so within f32 rounding): every deepest slot holds its level-D vertex's point, every
    /// level-D vertex has a slot, and the fans cover each level-D face's area once.
    #[test]
    fn slots_are_the_refiners_vertices() {
        for name in [
            "tests/data/opensubdiv/shapes/catmark_cube.obj",
            "tests/data/opensubdiv/shapes/catmark_pyramid.obj",
            "tests/data/opensubdiv/shapes/catmark_xord_boundary.obj",
        ] {
            let mesh = mesh(name);
            let base = Level::from_mesh(&mesh, Scheme::DooSabin).expect("base");
            for depth in 1..=3 {
                let l = layout(&base, depth).expect("layout");
                let r = refine_uniform(&mesh, Scheme::DooSabin, depth as usize).expect("refine");
                let want = &r.level(depth as usize);
                assert_eq!(l.level_vertices as usize, want.num_vertices());
                let mut seen = vec![false; want.num_vertices()];
                for &v in l.slot_vertices.iter().filter(|&&v| v != INVALID) {
                    seen[v as usize] = true;
                }
                assert!(
                    seen.iter().all(|&s| s),
                    "{name} depth {depth}: a vertex has no slot"
                );
                let tris = want
                    .topology
                    .face_tables()
                    .1
                    .len()
                    .saturating_sub(2 * want.topology.num_faces());
                assert_eq!(l.triangles.len(), 3 * tris, "{name} depth {depth}");
                for &i in &l.triangles {
                    assert_ne!(
                        l.slot_vertices[i as usize], INVALID,
                        "{name}: absent slot drawn"
                    );
                }
                let buffer = host_refine(&l, &mesh);
                let d0 = l.regions[depth as usize - 1] as usize;
                let diagonal = mesh.bbox_diagonal();
                for (s, &v) in l.slot_vertices.iter().enumerate() {
                    if v == INVALID {
                        continue;
                    }
                    let (got, q) = (buffer[d0 + s], want.positions[v as usize]);
                    for c in 0..3 {
                        assert!((got[c] - q[c]).abs() < 1e-6 * diagonal, "{name} slot {s}");
                    }
                }
            }
        }
    }

    /// The kernel's arithmetic on the host: the layout's records, flags and weight table.
    fn host_refine(l: &PatchesLayout, mesh: &ControlMesh) -> Vec<[f64; 3]> {
        let mut buffer = vec![[0.0; 3]; l.num_points as usize];
        buffer[..mesh.positions.len()].copy_from_slice(&mesh.positions);
        for row in l.blocks[0].rows.clone() {
            let mut p = [0.0; 3];
            for t in l.stencils.row(row) {
                for c in 0..3 {
                    p[c] += t.weight as f64 * buffer[t.index as usize][c];
                }
            }
            buffer[(l.blocks[0].destination + row) as usize] = p;
        }
        for (d, (records, _)) in (1..).zip(&l.steps) {
            for r in records {
                let n = r.valence as usize;
                let s = r.sizes as usize;
                let sizes: Vec<usize> = (0..n)
                    .map(|j| (l.sizes[s + j + 1] - l.sizes[s + j]) as usize)
                    .collect();
                let layout = PatchLayout {
                    valence: n,
                    corner_sizes: &sizes,
                };
                let src = r.source as usize;
                let flags: Vec<PointFlags> = (0..layout.len(d))
                    .map(|i| PointFlags {
                        present: l.flags[src + i] & VERTEX_PATCH_PRESENT != 0,
                        boundary: l.flags[src + i] & VERTEX_PATCH_BOUNDARY != 0,
                    })
                    .collect();
                let points = &buffer[src..src + layout.len(d)];
                let next = layout.refine(d, points, &flags).expect("refine");
                let dst = r.destination as usize;
                for (i, p) in next.into_iter().enumerate() {
                    if l.flags[dst + i] & VERTEX_PATCH_PRESENT != 0 {
                        buffer[dst + i] = p;
                    }
                }
            }
        }
        buffer
    }
}
