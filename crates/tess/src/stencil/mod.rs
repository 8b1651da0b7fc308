//! The GPU stencil evaluator: one kernel (`glsl/stencil/evaluate.comp`), one term layout
//! ([`StencilTerm`], `glsl/stencil/stencil.glsl`) and one window, descriptor-set and pipeline
//! setup, fed by every refinement scheme that turns control vertices into refined ones by
//! stencil rows (OpenSubdiv's stencil evaluators: a source and a destination buffer
//! descriptor, the rows' sizes, offsets, indices and weights, one evaluator per back-end).
//! Loop's initial subdivision step (`techniques::bft`) and the Catmull-Clark plans' levels and
//! local points (`techniques::planned_patches`: adaptive, and the single-pass Gregory and ACC
//! plans) use it. A per-level Doo-Sabin refinement would be a third user with nothing new: its
//! table (one CSR row per refined vertex, over the level before it) and one block per level,
//! in place over one vertex buffer or between a source and a destination buffer per level.
//!
//! Design decisions:
//! - **Rows, blocks, buffers.** A table ([`GpuStencils`]) is CSR: row `r`'s terms are
//!   `terms[offsets[r]..offsets[r + 1]]`, each a source vertex and an f32 weight. A
//!   [`StencilBlock`] is a run of rows written to a run of destination vertices; blocks run in
//!   order, one pass each (a block may read what earlier blocks wrote, never its own
//!   destinations). The source and destination are buffers of vertices, either two buffers
//!   (BFT: the frame slot's base positions → level-1 positions) or one, in place (adaptive:
//!   the global vertex buffer, whose levels read the levels before them): the indices of the
//!   terms and the blocks' destinations are element indices of the whole buffers.
//! - **One vertex format: `vec4`** ([`StencilVertex`], `w = 1`), read and written whole. The
//!   tessellation stages fetch a point with one 16-byte load, and a fixed format keeps one
//!   kernel. Base positions are converted on the host when uploaded ([`vertices`]): BFT's
//!   evaluator reads them where they are; adaptive copies them into the head of its vertex
//!   buffer (`vkCmdCopyBuffer`) before the first block.
//! - **Summation: anchored, `precise`.** Rows are affine (their weights sum to 1), so a row is
//!   summed as offsets from its first term's vertex, `anchor + Σ w (x − anchor)`, in table
//!   order, with no fused multiply-add. The f32 rounding is then relative to the row's spread,
//!   not to the coordinates' magnitude (absolute sums put the deep levels around a
//!   valence-360 pole 1.4e-5 of the diagonal off the CPU plan). A row with no term writes the
//!   origin. [`GpuStencils::row_point`] is the kernel's f32 mirror, operation for operation.
//!   This was adaptive's convention; BFT's initial step summed absolutely before and keeps its
//!   exactness tolerances, its bit-welded watertightness and its golden images unchanged.
//! - **Windows for everything the kernel indexes.** A device binds at most
//!   `maxStorageBufferRange` bytes per descriptor, so the rows are cut into chunks
//!   ([`crate::techniques::windows`]) whose windows of the offsets, the terms, the source
//!   vertices (the hull of the rows' term indices) and the destination vertices all fit; each
//!   chunk has its own descriptor set and the kernel subtracts the window bases (push
//!   constants, [`crate::gpu::StencilPush`]). An in-place evaluator binds its one buffer twice,
//!   as two windows. A mesh whose tables fit is one chunk with bases 0 (or the hulls' aligned
//!   starts); a row whose own reach does not fit is a typed error naming it and what shortens
//!   the reach ([`crate::TessError::StorageWindow`]).
//! - **Checked before upload**: every term reads an existing source vertex, every block
//!   writes existing destination vertices, and in place no row reads its own block's
//!   destinations ([`StencilError`]), so the GPU never indexes out of bounds or races.
//! - **Its own set and pipeline.** The evaluator's pipeline layout is its one set
//!   ([`crate::gpu::bindings::STENCIL_SET`]), so it binds nothing of the technique that owns
//!   it; each evaluator holds its table's buffers, one descriptor set per (target, chunk) and
//!   its pipeline.
//! - **Dispatch order.** One dispatch per (block, chunk) pair, at most `maxComputeWorkGroupCount`
//!   groups each, every one ordered after the one before by a barrier (windows of neighbouring
//!   chunks can overlap by their alignment, and synchronization validation sees whole ranges).
//!   The caller orders the first after the previous frame's readers and the last before its
//!   own readers.
use crate::error::Result;
use crate::gpu::bindings::{
    STENCIL_DESTINATION_BINDING, STENCIL_LOCAL_SIZE, STENCIL_OFFSETS_BINDING,
    STENCIL_SOURCE_BINDING, STENCIL_TERMS_BINDING,
};
use crate::gpu::StencilPush;
use crate::shaders::Stage;
use crate::techniques::shared::{compute_pipeline, storage};
use crate::techniques::windows::{self, Limits, Member, Space};
use bytemuck::{Pod, Zeroable};
use std::mem::size_of;
use std::ops::Range;
use vk_core::descriptor::{BindingDesc, DescriptorPool, DescriptorSetLayout};
use vk_core::pipeline::Pipeline;
use vk_core::{vk, Buffer, DescriptorSet, Device, Encoder};

/// `StencilTerm` of `stencil.glsl`: one term of a stencil row.
#[repr(C)]
#[derive(Clone, Copy, Debug, Default, PartialEq, Pod, Zeroable)]
pub struct StencilTerm {
    /// Source vertex (an element of the whole source buffer).
    pub index: u32,
    pub weight: f32,
}

/// A vertex as the evaluator reads and writes it (`vec4`): the position, then `w = 1`.
pub type StencilVertex = [f32; 4];

const _: () = assert!(size_of::<StencilTerm>() == 8);

/// Positions as the evaluator's vertices (`w = 1`): what a base-position buffer holds.
pub fn vertices(positions: &[[f32; 3]]) -> Vec<StencilVertex> {
    positions.iter().map(|&[x, y, z]| [x, y, z, 1.0]).collect()
}

/// Bytes of `n` vertices in a buffer (one vertex when `n` is 0: buffers are never empty).
pub fn vertex_bytes(n: u32) -> u64 {
    n.max(1) as u64 * size_of::<StencilVertex>() as u64
}

/// Why a stencil table cannot go to the GPU.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum StencilError {
    #[error("stencil table: {what} {index} is out of range of {len}")]
    Index {
        what: &'static str,
        index: u64,
        len: u64,
    },
    #[error("stencil table: the CSR offsets are not a run from 0 to the term count (row {row})")]
    Offsets { row: u32 },
    #[error("stencil table: {what} ({value}) does not fit the GPU layout")]
    TooLarge { what: &'static str, value: u64 },
    #[error(
        "stencil table: row {row} reads vertex {reads}, which its own block ({block:?}) writes"
    )]
    ReadsOwnBlock {
        row: u32,
        reads: u32,
        block: Range<u32>,
    },
    #[error("stencil table: the blocks do not tile the rows in order (block {block} starts at row {start}, expected {expected})")]
    Blocks {
        block: usize,
        start: u32,
        expected: u32,
    },
    #[error("stencil table: the blocks cover rows 0..{covered} of its {rows}")]
    Uncovered { covered: u32, rows: u32 },
    #[error(
        "stencil evaluator: buffer {buffer} holds {bytes} bytes, its {what} vertices need {needed}"
    )]
    TargetSize {
        buffer: String,
        what: &'static str,
        bytes: u64,
        needed: u64,
    },
    /// The same buffer as source and destination of a table planned between two, or the
    /// other way round.
    #[error(
        "stencil evaluator: destination {buffer} {} the source, but the table was planned {}",
        if *in_place { "is not" } else { "is" },
        if *in_place { "in place" } else { "between two buffers" }
    )]
    Aliasing { buffer: String, in_place: bool },
}

fn check(what: &'static str, index: u64, len: u64) -> Result<(), StencilError> {
    if index < len {
        Ok(())
    } else {
        Err(StencilError::Index { what, index, len })
    }
}

/// A stencil table as the GPU holds it: CSR offsets (one per row, plus one) and f32 terms.
#[derive(Clone, Debug, PartialEq)]
pub struct GpuStencils {
    pub offsets: Vec<u32>,
    pub terms: Vec<StencilTerm>,
}

impl Default for GpuStencils {
    fn default() -> Self {
        Self {
            offsets: vec![0],
            terms: Vec::new(),
        }
    }
}

impl GpuStencils {
    /// Packs `table` (its f64 weights as f32), taking it: the offsets are moved, not copied.
    pub fn from_table(table: topology::refine::stencil::StencilTable) -> Self {
        let terms = table
            .indices
            .iter()
            .zip(&table.weights)
            .map(|(&index, &w)| StencilTerm {
                index,
                weight: w as f32,
            })
            .collect();
        let offsets = if table.offsets.is_empty() {
            vec![0]
        } else {
            table.offsets
        };
        Self { offsets, terms }
    }

    /// Appends one row.
    pub fn push_row(&mut self, indices: &[u32], weights: &[f64]) -> Result<(), StencilError> {
        self.terms
            .extend(indices.iter().zip(weights).map(|(&index, &w)| StencilTerm {
                index,
                weight: w as f32,
            }));
        let len = u32::try_from(self.terms.len()).map_err(|_| StencilError::TooLarge {
            what: "stencil terms",
            value: self.terms.len() as u64,
        })?;
        self.offsets.push(len);
        Ok(())
    }

    /// Rows in the table.
    pub fn rows(&self) -> u32 {
        self.offsets.len().saturating_sub(1) as u32
    }

    /// The terms of row `r`.
    pub fn row(&self, r: u32) -> &[StencilTerm] {
        let (k0, k1) = (self.offsets[r as usize], self.offsets[r as usize + 1]);
        &self.terms[k0 as usize..k1 as usize]
    }

    /// Bytes of the offsets and terms on the GPU.
    pub fn bytes(&self) -> u64 {
        (4 * self.offsets.len() + size_of::<StencilTerm>() * self.terms.len()) as u64
    }

    /// `rows` rows whose offsets run from 0 to the term count without going back, every term
    /// reading one of `sources` vertices.
    pub fn validate(&self, rows: u32, sources: u32) -> Result<(), StencilError> {
        if self.offsets.len() != rows as usize + 1 {
            return Err(StencilError::Index {
                what: "stencil offsets",
                index: self.offsets.len() as u64,
                len: rows as u64 + 1,
            });
        }
        if self.offsets[0] != 0 || self.offsets[rows as usize] as usize != self.terms.len() {
            return Err(StencilError::Offsets { row: 0 });
        }
        if let Some(r) = self.offsets.windows(2).position(|w| w[0] > w[1]) {
            return Err(StencilError::Offsets { row: r as u32 });
        }
        for t in &self.terms {
            check("stencil source vertex", t.index as u64, sources as u64)?;
        }
        Ok(())
    }

    /// Row `r`'s point as the kernel sums it, operation for operation (its f32 mirror):
    /// `anchor + Σ w (x − anchor)` in table order, anchored at the first term's vertex, no
    /// fused products; the origin for a row without terms.
    pub fn row_point(&self, r: u32, vertex: impl Fn(u32) -> [f32; 3]) -> [f32; 3] {
        let terms = self.row(r);
        let Some(first) = terms.first() else {
            return [0.0; 3];
        };
        let anchor = vertex(first.index);
        let mut d = [0f32; 3];
        for t in terms {
            let x = vertex(t.index);
            for c in 0..3 {
                d[c] += t.weight * (x[c] - anchor[c]);
            }
        }
        [anchor[0] + d[0], anchor[1] + d[1], anchor[2] + d[2]]
    }
}

/// Rows `rows` of a table, row `r` written to destination vertex `destination + r −
/// rows.start`: one pass of the evaluator.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StencilBlock {
    pub rows: Range<u32>,
    pub destination: u32,
}

impl StencilBlock {
    /// The destination vertices the block writes.
    pub fn destinations(&self) -> Range<u32> {
        self.destination..self.destination.saturating_add(self.rows.len() as u32)
    }
}

/// Where the rows read and write: vertex counts of the source and destination buffers, and
/// whether they are one buffer (in place).
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct StencilVertices {
    pub sources: u32,
    pub destinations: u32,
    pub in_place: bool,
}

const fn member(stride: usize, extra: u32) -> Member {
    Member {
        stride: stride as u64,
        extra,
    }
}

/// The spaces a chunk windows: rows (CSR offsets: row `r` reads `offsets[r + 1]`), terms, and
/// the source and destination vertices.
const SPACES: [Space; 4] = [
    Space {
        name: "stencil row",
        members: &[member(4, 1)],
    },
    Space {
        name: "stencil term",
        members: &[member(size_of::<StencilTerm>(), 0)],
    },
    Space {
        name: "stencil source vertex",
        members: &[member(size_of::<StencilVertex>(), 0)],
    },
    Space {
        name: "stencil destination vertex",
        members: &[member(size_of::<StencilVertex>(), 0)],
    },
];

/// A chunk's windows of the rows, terms, source and destination vertices.
pub type StencilWindows = [Range<u32>; 4];

/// One dispatch: `rows`, written from destination vertex `destination`, bound to the windows
/// of chunk `chunk`.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StencilDispatch {
    pub rows: Range<u32>,
    pub destination: u32,
    pub chunk: usize,
}

impl StencilDispatch {
    /// The push constants of the dispatch under its chunk's windows `w`.
    pub fn push(&self, w: &StencilWindows) -> StencilPush {
        StencilPush {
            first_row: self.rows.start,
            count: self.rows.end - self.rows.start,
            row_base: w[0].start,
            term_base: w[1].start,
            source_base: w[2].start,
            destination_first: self.destination - w[3].start,
        }
    }
}

/// The evaluator's work: its dispatches in order and each chunk's windows.
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct StencilPlan {
    pub dispatches: Vec<StencilDispatch>,
    pub windows: Vec<StencilWindows>,
}

/// Validates `blocks` of `stencils` against `vertices` (they tile the rows in order, write
/// existing destinations and, in place, never read their own) and cuts them into dispatches of
/// at most `max_rows` rows whose windows fit `limits`.
pub fn plan(
    stencils: &GpuStencils,
    blocks: &[StencilBlock],
    vertices: StencilVertices,
    limits: Limits,
    max_rows: u32,
) -> Result<StencilPlan> {
    let rows = stencils.rows();
    stencils.validate(rows, vertices.sources)?;
    // Per row, its destination vertex (the blocks tile the rows in order).
    let mut destination = Vec::with_capacity(rows as usize);
    for (b, block) in blocks.iter().enumerate() {
        if block.rows.start != destination.len() as u32 || block.rows.end < block.rows.start {
            return Err(StencilError::Blocks {
                block: b,
                start: block.rows.start,
                expected: destination.len() as u32,
            }
            .into());
        }
        let end = block.destination as u64 + block.rows.len() as u64;
        if end > block.destination as u64 {
            check(
                "stencil destination vertex",
                end - 1,
                vertices.destinations as u64,
            )?;
        }
        let writes = block.destinations();
        for r in block.rows.clone() {
            if vertices.in_place {
                if let Some(t) = stencils.row(r).iter().find(|t| writes.contains(&t.index)) {
                    return Err(StencilError::ReadsOwnBlock {
                        row: r,
                        reads: t.index,
                        block: writes,
                    }
                    .into());
                }
            }
            destination.push(writes.start + (r - block.rows.start));
        }
    }
    if destination.len() as u32 != rows {
        return Err(StencilError::Uncovered {
            covered: destination.len() as u32,
            rows,
        }
        .into());
    }
    let chunks = windows::plan("stencil row", rows, &SPACES, limits, |r| {
        let terms = stencils.row(r);
        let (lo, hi) = terms.iter().fold((u32::MAX, 0), |(lo, hi), t| {
            (lo.min(t.index), hi.max(t.index + 1))
        });
        let d = destination[r as usize];
        let k0 = stencils.offsets[r as usize];
        [
            r..r + 1,
            k0..k0 + terms.len() as u32,
            if terms.is_empty() { 0..0 } else { lo..hi },
            d..d + 1,
        ]
    })?;
    let max_rows = max_rows.max(1);
    let mut dispatches = Vec::new();
    for block in blocks {
        for (chunk, c) in chunks.iter().enumerate() {
            let mut first = block.rows.start.max(c.items.start);
            let end = block.rows.end.min(c.items.end);
            while first < end {
                let last = end.min(first.saturating_add(max_rows));
                dispatches.push(StencilDispatch {
                    rows: first..last,
                    destination: block.destination + (first - block.rows.start),
                    chunk,
                });
                first = last;
            }
        }
    }
    Ok(StencilPlan {
        dispatches,
        windows: chunks.into_iter().map(|c| c.windows).collect(),
    })
}

/// The evaluator's set: a storage buffer per binding, read by the compute stage only.
const fn binding(binding: u32) -> BindingDesc {
    BindingDesc {
        binding,
        ty: vk::DescriptorType::STORAGE_BUFFER,
        stages: vk::ShaderStageFlags::COMPUTE,
    }
}

static SET_BINDINGS: [BindingDesc; 4] = [
    binding(STENCIL_OFFSETS_BINDING),
    binding(STENCIL_TERMS_BINDING),
    binding(STENCIL_SOURCE_BINDING),
    binding(STENCIL_DESTINATION_BINDING),
];

/// A stencil table on the GPU, planned against its source and destination buffers: the
/// pipeline, the table's buffers, and per target (a source and destination pair, e.g. per
/// frame slot) one descriptor set per chunk. Drop order: pipeline, sets (they keep their pool
/// and buffers alive), pool, layout, buffers.
pub struct StencilEvaluator {
    pipeline: Pipeline,
    sets: Vec<Vec<DescriptorSet>>,
    plan: StencilPlan,
    _pool: DescriptorPool,
    _layout: DescriptorSetLayout,
    tables: [Buffer; 2],
}

impl StencilEvaluator {
    /// Uploads `stencils` (buffers named after `name`), plans `blocks` against `vertices`
    /// under the device's limits, and binds each of `targets` (source, destination buffers;
    /// the same buffer twice when in place, each holding its vertex count of
    /// [`StencilVertex`]).
    pub fn new(
        device: &Device,
        name: &str,
        stencils: &GpuStencils,
        blocks: &[StencilBlock],
        vertices: StencilVertices,
        targets: &[(&Buffer, &Buffer)],
    ) -> Result<Self> {
        for (source, destination) in targets {
            if std::ptr::eq(*source, *destination) != vertices.in_place {
                return Err(StencilError::Aliasing {
                    buffer: destination.name().to_owned(),
                    in_place: vertices.in_place,
                }
                .into());
            }
            for (buffer, what, n) in [
                (source, "source", vertices.sources),
                (destination, "destination", vertices.destinations),
            ] {
                if buffer.size() < vertex_bytes(n) {
                    return Err(StencilError::TargetSize {
                        buffer: buffer.name().to_owned(),
                        what,
                        bytes: buffer.size(),
                        needed: vertex_bytes(n),
                    }
                    .into());
                }
            }
        }
        let max_groups = device.info.caps.max_compute_work_group_count[0];
        let plan = plan(
            stencils,
            blocks,
            vertices,
            Limits::of(device),
            max_groups.saturating_mul(STENCIL_LOCAL_SIZE),
        )?;
        let tables = [
            storage(
                device,
                &format!("{name} stencil offsets"),
                bytemuck::cast_slice(&stencils.offsets),
            )?,
            storage(
                device,
                &format!("{name} stencil terms"),
                bytemuck::cast_slice(&stencils.terms),
            )?,
        ];
        let layout =
            DescriptorSetLayout::new(device, &format!("{name} stencil set layout"), &SET_BINDINGS)?;
        let pool = DescriptorPool::new(
            device,
            &format!("{name} stencil descriptor pool"),
            &layout,
            (targets.len() * plan.windows.len()).max(1) as u32,
        )?;
        let lens = [
            stencils.offsets.len() as u64,
            stencils.terms.len() as u64,
            vertices.sources as u64,
            vertices.destinations as u64,
        ];
        let mut sets = Vec::with_capacity(targets.len());
        for (source, destination) in targets {
            let buffers = [&tables[0], &tables[1], *source, *destination];
            let mut target_sets = Vec::with_capacity(plan.windows.len());
            for w in &plan.windows {
                let set = pool.allocate_set(&layout)?;
                for (k, b) in SET_BINDINGS.iter().enumerate() {
                    windows::write_window(
                        &set,
                        b.binding,
                        buffers[k],
                        SPACES[k].members[0],
                        lens[k],
                        &w[k],
                    )?;
                }
                target_sets.push(set);
            }
            sets.push(target_sets);
        }
        let pipeline = compute_pipeline(
            device,
            &format!("{name} stencils"),
            Stage::StencilEvaluateComp,
            &[layout.raw],
            size_of::<StencilPush>(),
        )?;
        Ok(Self {
            pipeline,
            sets,
            plan,
            _pool: pool,
            _layout: layout,
            tables,
        })
    }

    /// Records every dispatch for `target`, each ordered after the one before; the caller
    /// orders the first after the destination's previous readers and the last before its
    /// next ones.
    pub fn record<'a>(&'a self, enc: &mut Encoder<'a>, target: usize) -> Result<()> {
        let slots = self.sets.len();
        let sets = self.sets.get(target).ok_or(crate::TessError::FrameSlot {
            slot: target,
            slots,
        })?;
        let compute = vk::PipelineStageFlags::COMPUTE_SHADER;
        enc.bind_pipeline(&self.pipeline);
        let mut bound = None;
        for (i, d) in self.plan.dispatches.iter().enumerate() {
            if i > 0 {
                enc.memory_barrier(
                    (compute, vk::AccessFlags::SHADER_WRITE),
                    (
                        compute,
                        vk::AccessFlags::SHADER_READ | vk::AccessFlags::SHADER_WRITE,
                    ),
                );
            }
            if bound != Some(d.chunk) {
                enc.bind_descriptor_sets(0, &[&sets[d.chunk]])?;
                bound = Some(d.chunk);
            }
            let push = d.push(&self.plan.windows[d.chunk]);
            enc.push_constants(&push)?;
            enc.dispatch([push.count.div_ceil(STENCIL_LOCAL_SIZE), 1, 1])?;
        }
        Ok(())
    }

    /// Dispatches per evaluation and chunks (window sets per target): more than one chunk
    /// when a buffer the kernel indexes exceeds the storage range.
    pub fn counts(&self) -> (usize, usize) {
        (self.plan.dispatches.len(), self.plan.windows.len())
    }

    /// The table's buffers (offsets, terms), for the technique's device-memory report.
    pub fn buffers(&self) -> &[Buffer] {
        &self.tables
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::techniques::planned_patches::layout::GpuPlan;
    use crate::TessError;

    /// The cube's adaptive layout: levels and local points, in place.
    fn cube() -> GpuPlan {
        crate::techniques::planned_patches::tests::cube_layout()
    }

    fn in_place(n: u32) -> StencilVertices {
        StencilVertices {
            sources: n,
            destinations: n,
            in_place: true,
        }
    }

    fn limits(max_range: u64) -> Limits {
        Limits {
            max_range,
            alignment: 16,
        }
    }

    /// Under a small range and a small group count, the dispatches run every row exactly once,
    /// in block order (a block's rows read only earlier blocks), each inside its chunk's
    /// windows of the offsets, terms, source and destination vertices, with aligned window
    /// starts and every window within the range; uncapped, one chunk.
    #[test]
    fn dispatches_cover_every_row_once_inside_their_windows() {
        let g = cube();
        let v = in_place(g.num_vertices);
        let whole = plan(&g.stencils, &g.blocks, v, limits(1 << 30), u32::MAX).expect("whole");
        assert_eq!(whole.windows.len(), 1, "everything fits: one chunk");
        assert_eq!(
            whole.dispatches.len(),
            g.blocks.len(),
            "one dispatch per block"
        );
        let range = 4096;
        let p = plan(&g.stencils, &g.blocks, v, limits(range), 100).expect("chunked");
        assert!(p.windows.len() > 3, "{} chunks", p.windows.len());
        assert!(
            g.vertex_bytes() > 4 * range,
            "the vertices need windows too"
        );
        let mut next = 0;
        let mut block = 0;
        for d in &p.dispatches {
            assert_eq!(d.rows.start, next, "in order, no gap or overlap");
            assert!(d.rows.len() <= 100);
            next = d.rows.end;
            while g.blocks[block].rows.end <= d.rows.start {
                block += 1;
            }
            let b = &g.blocks[block];
            assert!(d.rows.end <= b.rows.end, "a dispatch stays in its block");
            assert_eq!(d.destination, b.destination + d.rows.start - b.rows.start);
            let [rows, terms, source, destination] = &p.windows[d.chunk];
            assert_eq!(rows.start % 4, 0, "row window start aligned to 16 bytes");
            assert_eq!(terms.start % 2, 0, "term window start aligned to 16 bytes");
            assert!((rows.end - rows.start + 1) as u64 * 4 <= range);
            assert!((terms.end - terms.start) as u64 * 8 <= range);
            for w in [source, destination] {
                assert!((w.end - w.start) as u64 * 16 <= range);
            }
            let push = d.push(&p.windows[d.chunk]);
            for r in d.rows.clone() {
                let (k0, k1) = (
                    g.stencils.offsets[r as usize],
                    g.stencils.offsets[r as usize + 1],
                );
                assert!(rows.start <= r && r < rows.end);
                assert!(k0 == k1 || (terms.start <= k0 && k1 <= terms.end));
                for t in g.stencils.row(r) {
                    assert!(source.contains(&t.index), "{} in {source:?}", t.index);
                    assert!(t.index >= push.source_base);
                }
                let written = push.destination_first + (r - d.rows.start);
                assert_eq!(written + destination.start, g.num_base_vertices + r);
                assert!(destination.contains(&(g.num_base_vertices + r)));
            }
        }
        assert_eq!(next, g.stencils.rows());
    }

    /// What the kernel must never receive is refused, by name: a term past the source, a block
    /// past the destination, a row reading its own block in place, blocks that do not tile.
    #[test]
    fn bad_tables_and_blocks_are_refused() {
        let g = cube();
        let n = g.num_vertices;
        let lim = limits(1 << 30);
        let stencil_error = |r: Result<StencilPlan>| match r {
            Err(TessError::Stencil(e)) => e,
            other => panic!("expected a stencil error, got {other:?}"),
        };
        let mut bad = g.stencils.clone();
        bad.terms[3].index = n;
        let e = stencil_error(plan(&bad, &g.blocks, in_place(n), lim, 64));
        assert!(
            matches!(e, StencilError::Index { index, len, .. } if index == n as u64 && len == n as u64),
            "{e}"
        );
        let written = g.blocks.last().expect("blocks").destinations().end;
        let short = StencilVertices {
            sources: n,
            destinations: written - 1,
            in_place: false,
        };
        let e = stencil_error(plan(&g.stencils, &g.blocks, short, lim, 64));
        assert!(
            matches!(
                e,
                StencilError::Index {
                    what: "stencil destination vertex",
                    ..
                }
            ),
            "{e}"
        );
        // The last block moved onto the rows it reads.
        let mut blocks = g.blocks.clone();
        let last = blocks.last_mut().expect("blocks");
        let reads = g.stencils.row(last.rows.start)[0].index;
        last.destination = reads;
        let e = stencil_error(plan(&g.stencils, &blocks, in_place(n), lim, 64));
        assert!(matches!(e, StencilError::ReadsOwnBlock { .. }), "{e}");
        // Separate buffers may overlap in index: no race.
        let separate = StencilVertices {
            in_place: false,
            ..in_place(n)
        };
        plan(&g.stencils, &blocks, separate, lim, 64).expect("separate buffers");
        let e = stencil_error(plan(&g.stencils, &g.blocks[1..], in_place(n), lim, 64));
        assert!(matches!(e, StencilError::Blocks { block: 0, .. }), "{e}");
        let e = stencil_error(plan(&g.stencils, &g.blocks[..1], in_place(n), lim, 64));
        let covered = g.blocks[0].rows.end;
        assert_eq!(
            e,
            StencilError::Uncovered {
                covered,
                rows: g.stencils.rows()
            }
        );
        // A block past the end of the index space is a named error, not an overflow.
        let mut far = g.blocks.clone();
        far.last_mut().expect("blocks").destination = u32::MAX - 1;
        let e = stencil_error(plan(&g.stencils, &far, in_place(n), lim, 64));
        assert!(
            matches!(
                e,
                StencilError::Index {
                    what: "stencil destination vertex",
                    ..
                }
            ),
            "{e}"
        );
        let mut offsets = g.stencils.clone();
        offsets.offsets.swap(1, 2);
        let e = stencil_error(plan(&offsets, &g.blocks, in_place(n), lim, 64));
        assert!(matches!(e, StencilError::Offsets { .. }), "{e}");
    }

    /// Anchored sums keep f32 rounding relative to the row's spread: far from the origin, an
    /// affine row of close points lands within a few ulps of the spread of the exact (f64)
    /// combination, where absolute sums lose the offsets to the coordinates' magnitude.
    #[test]
    fn anchored_rows_keep_their_precision_far_from_the_origin() {
        let far = 3.0e4f32;
        let points: Vec<[f32; 3]> = (0..7)
            .map(|k| {
                let t = k as f32 * 0.001;
                [far + t, far - 2.0 * t, far + 0.5 * t]
            })
            .collect();
        let weights = [0.1, 0.25, 0.05, 0.2, 0.15, 0.125, 0.125];
        let mut table = GpuStencils::default();
        table
            .push_row(&[0, 1, 2, 3, 4, 5, 6], &weights)
            .expect("row");
        table.push_row(&[], &[]).expect("empty row");
        let anchored = table.row_point(0, |i| points[i as usize]);
        let exact: Vec<f64> = (0..3)
            .map(|c| {
                weights
                    .iter()
                    .zip(&points)
                    .map(|(w, p)| w * p[c] as f64)
                    .sum()
            })
            .collect();
        let mut absolute = [0f32; 3];
        for (w, p) in weights.iter().zip(&points) {
            for c in 0..3 {
                absolute[c] += *w as f32 * p[c];
            }
        }
        let err = |p: [f32; 3]| {
            (0..3)
                .map(|c| (p[c] as f64 - exact[c]).abs())
                .fold(0.0, f64::max)
        };
        let ulp = (far as f64) * f64::from(f32::EPSILON);
        assert!(
            err(anchored) <= ulp,
            "anchored {:e} over one ulp {ulp:e}",
            err(anchored)
        );
        assert!(
            err(absolute) >= err(anchored),
            "absolute {:e}",
            err(absolute)
        );
        assert_eq!(
            table.row_point(1, |i| points[i as usize]),
            [0.0; 3],
            "no term: the origin"
        );
        table.validate(2, 7).expect("valid");
        assert!(table.validate(2, 6).is_err());
        assert!(table.validate(3, 7).is_err());
    }
}
