//! Stencils: each refined vertex as a sparse weighted sum of control (base) vertices, stored
//! flat (CSR) so the GPU can re-evaluate refined points every frame while the base animates.

use rayon::prelude::*;

/// Weights over a level's vertex indices (ascending, no zero weights).
#[derive(Clone, Debug, Default, PartialEq)]
pub struct Stencil {
    pub indices: Vec<u32>,
    pub weights: Vec<f64>,
}

impl Stencil {
    /// Apply to 3D points indexed like the level's vertices.
    pub fn apply(&self, points: &[[f64; 3]]) -> [f64; 3] {
        let mut out = [0.0; 3];
        for (&i, &w) in self.indices.iter().zip(&self.weights) {
            if let Some(p) = points.get(i as usize) {
                for k in 0..3 {
                    out[k] += w * p[k];
                }
            }
        }
        out
    }
}

/// Row-compressed stencils: stencil `i` uses `indices[offsets[i]..offsets[i + 1]]` with the
/// matching `weights`. Indices within a stencil are sorted and unique.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StencilTable {
    /// `len() + 1` entries, starting at 0.
    pub offsets: Vec<u32>,
    pub indices: Vec<u32>,
    pub weights: Vec<f64>,
    /// Number of source (control) vertices the indices refer to.
    pub num_sources: usize,
}

/// The same table with `f32` weights, ready for upload.
#[derive(Clone, Debug, Default, PartialEq)]
pub struct StencilTableF32 {
    pub offsets: Vec<u32>,
    pub indices: Vec<u32>,
    pub weights: Vec<f32>,
    pub num_sources: usize,
}

impl StencilTable {
    /// Identity stencils over `n` vertices.
    pub fn identity(n: usize) -> StencilTable {
        StencilTable {
            offsets: (0..=n as u32).collect(),
            indices: (0..n as u32).collect(),
            weights: vec![1.0; n],
            num_sources: n,
        }
    }

    /// No rows, the storage kept: a table reused as a scratch from chunk to chunk.
    pub fn clear(&mut self) {
        self.offsets.clear();
        self.offsets.push(0);
        self.indices.clear();
        self.weights.clear();
    }

    /// Number of stencils (refined vertices).
    pub fn len(&self) -> usize {
        self.offsets.len().saturating_sub(1)
    }

    /// Whether the table has no stencils.
    pub fn is_empty(&self) -> bool {
        self.len() == 0
    }

    /// Indices and weights of stencil `i`.
    pub fn stencil(&self, i: usize) -> (&[u32], &[f64]) {
        let r = self.offsets[i] as usize..self.offsets[i + 1] as usize;
        (&self.indices[r.clone()], &self.weights[r])
    }

    /// Weights converted to `f32` for the GPU.
    pub fn weights_f32(&self) -> Vec<f32> {
        self.weights.iter().map(|&w| w as f32).collect()
    }

    /// The whole table with `f32` weights.
    pub fn to_f32(&self) -> StencilTableF32 {
        StencilTableF32 {
            offsets: self.offsets.clone(),
            indices: self.indices.clone(),
            weights: self.weights_f32(),
            num_sources: self.num_sources,
        }
    }

    /// Evaluate every stencil on `base` points (e.g. the animated control positions).
    pub fn apply(&self, base: &[[f64; 3]]) -> Vec<[f64; 3]> {
        (0..self.len())
            .into_par_iter()
            .with_min_len(1024)
            .map(|i| {
                let (idx, w) = self.stencil(i);
                let mut p = [0.0f64; 3];
                for (&j, &wj) in idx.iter().zip(w) {
                    let q = base[j as usize];
                    p[0] += wj * q[0];
                    p[1] += wj * q[1];
                    p[2] += wj * q[2];
                }
                p
            })
            .collect()
    }

    /// Evaluate every stencil on flat per-vertex data of any dimension (`dim` values per
    /// source vertex, e.g. one per basis function), serially: for the small levels of local
    /// refinement.
    pub fn apply_flat(&self, data: &[f64], dim: usize) -> Vec<f64> {
        let mut out = vec![0.0; self.len() * dim];
        for (i, row) in out.chunks_exact_mut(dim.max(1)).enumerate() {
            let (idx, w) = self.stencil(i);
            for (&j, &wj) in idx.iter().zip(w) {
                let src = &data[j as usize * dim..(j as usize + 1) * dim];
                for (o, x) in row.iter_mut().zip(src) {
                    *o += wj * x;
                }
            }
        }
        out
    }

    /// Stencils of `self` (over the vertices `parent` produces) re-expressed over `parent`'s
    /// sources: `result_i = Σ_j w_ij · parent_j`.
    pub fn compose(&self, parent: &StencilTable) -> StencilTable {
        compose_rows(
            self.len(),
            Some(parent),
            RowKind::Merged,
            parent.num_sources,
            |i, out| {
                let (idx, w) = self.stencil(i);
                out.idx.extend_from_slice(idx);
                out.wts.extend_from_slice(w);
                true
            },
        )
    }
}

/// Where a row generator writes its row: raw, or merged straight after the rows before it.
pub(crate) struct RowOut<'a> {
    /// The row as written (answer `false`): see [`RowKind`].
    pub(crate) raw: &'a mut Vec<(u32, f64)>,
    /// The row merged (answer `true`): indices ascending and distinct, no zero weight, appended
    /// to the table's arrays (or to the scratch the composition reads), so a merged row is
    /// written once.
    pub(crate) idx: &'a mut Vec<u32>,
    pub(crate) wts: &'a mut Vec<f64>,
}

/// What a row generator writes.
#[derive(Clone, Copy, PartialEq, Eq)]
pub(crate) enum RowKind {
    /// Raw rows' indices may repeat and come in any order (subdivision masks).
    Raw,
    /// Raw rows are merged already (rows of an existing table).
    Merged,
}

/// A dense accumulator over `n` slots with a touched list: O(1) per added entry, no hashing.
/// Slot `k` holds a live value for the current row when its stamp equals the row's tag; stamp
/// and value share a cache line.
struct Dense {
    slots: Vec<(u32, f64)>,
    touched: Vec<u32>,
}

impl Dense {
    fn new(n: usize) -> Dense {
        Dense {
            slots: vec![(0, 0.0); n],
            touched: Vec::with_capacity(64),
        }
    }

    #[inline]
    fn add(&mut self, tag: u32, j: u32, w: f64) {
        let slot = &mut self.slots[j as usize];
        if slot.0 != tag {
            *slot = (tag, w);
            self.touched.push(j);
        } else {
            slot.1 += w;
        }
    }

    /// Sort the touched list (short: insertion sort).
    #[inline]
    fn sort_touched(&mut self) {
        let t = &mut self.touched;
        if t.len() > 32 {
            t.sort_unstable();
        } else {
            insertion_sort(t);
        }
    }
}

/// Insertion sort: for the short rows and lists of the stencil builders, cheaper than the
/// library sort's dispatch.
#[inline]
pub(crate) fn insertion_sort<T: Copy + PartialOrd>(s: &mut [T]) {
    for i in 1..s.len() {
        let x = s[i];
        let mut j = i;
        while j > 0 && s[j - 1] > x {
            s[j] = s[j - 1];
            j -= 1;
        }
        s[j] = x;
    }
}

/// A row entry as one sortable word: its index above `slot` (where its weight is, or its place
/// in the row), so sorting the words sorts the entries by index, ties by slot, and moves a
/// word rather than an (index, weight) pair.
#[inline]
pub(crate) fn entry_key(index: u32, slot: usize) -> u64 {
    (u64::from(index) << 32) | slot as u64
}

/// Per-thread scratch of [`compose_rows`], reused across rounds: the accumulators (merging a
/// raw row; composing with the parent) and the output of the block last computed with it.
struct Scratch {
    /// Sort keys of a raw row being merged ([`merge_raw`]).
    keys: Vec<u64>,
    out: Option<Dense>,
    row: Vec<(u32, f64)>,
    /// A merged row before composing (with a parent).
    merged: (Vec<u32>, Vec<f64>),
    sizes: Vec<u32>,
    idx: Vec<u32>,
    wts: Vec<f64>,
}

impl Scratch {
    /// Empty buffers, and an accumulator over `num_sources` when composing with a parent.
    fn new(composing: bool, num_sources: usize) -> Scratch {
        Scratch {
            keys: Vec::with_capacity(64),
            out: composing.then(|| Dense::new(num_sources)),
            row: Vec::with_capacity(64),
            merged: (Vec::with_capacity(64), Vec::with_capacity(64)),
            sizes: Vec::new(),
            idx: Vec::new(),
            wts: Vec::new(),
        }
    }
}

/// Rows per block of [`compose_rows`].
const BLOCK_ROWS: usize = 8192;

/// Build a table of `n` rows in parallel blocks. `gen` writes row `i` over the "parent"
/// vertices ([`RowOut`]) and answers whether it wrote it merged. Without `parent` those are the
/// sources: raw rows are merged (duplicates added, sorted, exact zeros dropped). With `parent`, each entry `(j, w)` adds `w`
/// times parent row `j` into a dense accumulator over the parent's sources, so the result is the
/// composition without an intermediate table, hashing or per-row allocation.
///
/// On one thread the rows go straight into the final arrays. Otherwise blocks run in rounds of
/// a few per thread; each round's blocks are then appended to the final arrays, so block
/// buffers and accumulators are reused (touched once per thread, not once per row) and the
/// final arrays are written once.
pub(crate) fn compose_rows<G>(
    n: usize,
    parent: Option<&StencilTable>,
    kind: RowKind,
    num_sources: usize,
    gen: G,
) -> StencilTable
where
    G: Fn(usize, &mut RowOut) -> bool + Sync,
{
    assert!(
        n < u32::MAX as usize,
        "too many stencils for 32-bit offsets"
    );
    let threads = rayon::current_num_threads().max(1);
    let merge = kind == RowKind::Raw;
    // Entries per row: ~10 for a composed Catmull-Clark row, fewer for masks. Filled by
    // appending (nothing is zeroed first, which on recycled heap memory wrote every page
    // once more), and trimmed only when the guess was far off (a trim may copy).
    let guess = if parent.is_some() { 12 } else { 8 };
    let mut offsets: Vec<u32> = Vec::with_capacity(n + 1);
    offsets.push(0);
    let mut indices: Vec<u32> = Vec::with_capacity(n * guess);
    let mut weights: Vec<f64> = Vec::with_capacity(n * guess);
    if threads == 1 {
        // One thread: rows go straight into the final arrays (no block buffers to fill and
        // copy; on catmark_car those were 8.6 MB of pages per plan).
        let mut sc = Scratch::new(parent.is_some(), num_sources);
        // Offsets past u32 wrap here; the length check after the loop rejects them.
        fill_rows(
            &mut sc.keys,
            merge,
            &mut sc.out,
            &mut sc.row,
            &mut sc.merged,
            0..n,
            parent,
            &gen,
            &mut indices,
            &mut weights,
            |_, end| offsets.push(end as u32),
        );
    } else {
        let table = (&mut offsets, &mut indices, &mut weights);
        compose_in_rounds(n, parent, merge, num_sources, &gen, table);
    }
    assert!(
        indices.len() < u32::MAX as usize,
        "too many stencil weights for 32-bit offsets"
    );
    if indices.capacity() > indices.len() + indices.len() / 3 {
        indices.shrink_to_fit();
        weights.shrink_to_fit();
    }
    StencilTable {
        offsets,
        indices,
        weights,
        num_sources,
    }
}

/// [`compose_rows`] on more than one thread: blocks of [`BLOCK_ROWS`] rows in rounds of two
/// per thread, each round's blocks appended in order to the table (`offsets`, `indices`,
/// `weights`); the scratch of each block (buffers and accumulator) goes back to a pool for the
/// next round.
fn compose_in_rounds<G>(
    n: usize,
    parent: Option<&StencilTable>,
    merge: bool,
    num_sources: usize,
    gen: &G,
    (offsets, indices, weights): (&mut Vec<u32>, &mut Vec<u32>, &mut Vec<f64>),
) where
    G: Fn(usize, &mut RowOut) -> bool + Sync,
{
    let threads = rayon::current_num_threads().max(1);
    let pool = std::sync::Mutex::new(Vec::<Scratch>::new());
    let blocks = n.div_ceil(BLOCK_ROWS).max(1);
    // Two blocks per thread balance the load (each block in flight holds a scratch
    // accumulator the size of the parent's sources when composing).
    let per_round = threads * 2;
    let mut b0 = 0;
    while b0 < blocks {
        let b1 = (b0 + per_round).min(blocks);
        let done: Vec<Scratch> = (b0..b1)
            .into_par_iter()
            .map(|b| {
                let mut sc = pool
                    .lock()
                    .ok()
                    .and_then(|mut p| p.pop())
                    .unwrap_or_else(|| Scratch::new(parent.is_some(), num_sources));
                let rows = (b * BLOCK_ROWS).min(n)..((b + 1) * BLOCK_ROWS).min(n);
                let Scratch {
                    keys,
                    out,
                    row,
                    merged,
                    sizes,
                    idx,
                    wts,
                } = &mut sc;
                sizes.clear();
                idx.clear();
                wts.clear();
                fill_rows(
                    keys,
                    merge,
                    out,
                    row,
                    merged,
                    rows,
                    parent,
                    gen,
                    idx,
                    wts,
                    |start, end| sizes.push((end - start) as u32),
                );
                sc
            })
            .collect();
        for sc in &done {
            let mut acc = indices.len() as u64;
            offsets.extend(sc.sizes.iter().map(|&s| {
                acc += s as u64;
                acc as u32
            }));
            indices.extend_from_slice(&sc.idx);
            weights.extend_from_slice(&sc.wts);
        }
        if let Ok(mut p) = pool.lock() {
            p.extend(done);
        }
        b0 = b1;
    }
}

/// Compute rows `rows`, appending their entries to `idx` / `wts`; `end_row(start, end)` is told
/// each row's entry range. Raw rows are merged ([`merge_raw`]) when `merge` is set.
#[allow(clippy::too_many_arguments)]
fn fill_rows<G>(
    keys: &mut Vec<u64>,
    merge: bool,
    out: &mut Option<Dense>,
    row: &mut Vec<(u32, f64)>,
    merged: &mut (Vec<u32>, Vec<f64>),
    rows: std::ops::Range<usize>,
    parent: Option<&StencilTable>,
    gen: &G,
    idx: &mut Vec<u32>,
    wts: &mut Vec<f64>,
    mut end_row: impl FnMut(usize, usize),
) where
    G: Fn(usize, &mut RowOut) -> bool + Sync,
{
    for i in rows {
        let tag = i as u32 + 1;
        let before = idx.len();
        row.clear();
        match (parent, out.as_mut()) {
            (Some(p), Some(o)) => {
                // The row over the parent's vertices, merged, then composed.
                let (midx, mwts) = merged;
                midx.clear();
                mwts.clear();
                let mut sink = RowOut {
                    raw: row,
                    idx: midx,
                    wts: mwts,
                };
                if !gen(i, &mut sink) {
                    midx.clear();
                    mwts.clear();
                    merge_raw(keys, merge, row, midx, mwts);
                }
                o.touched.clear();
                for (&j, &wj) in midx.iter().zip(mwts.iter()) {
                    let (pidx, pw) = p.stencil(j as usize);
                    for (&s, &ws) in pidx.iter().zip(pw) {
                        o.add(tag, s, wj * ws);
                    }
                }
                o.sort_touched();
                for &s in &o.touched {
                    let w = o.slots[s as usize].1;
                    if w != 0.0 {
                        idx.push(s);
                        wts.push(w);
                    }
                }
            }
            _ => {
                let mut sink = RowOut { raw: row, idx, wts };
                if !gen(i, &mut sink) {
                    idx.truncate(before);
                    wts.truncate(before);
                    merge_raw(keys, merge, row, idx, wts);
                }
            }
        }
        end_row(before, idx.len());
    }
}

/// Append raw row `row` to `idx` / `wts`: merged when `merge` is set (indices ascending and
/// distinct, exact zeros dropped), else as it is. The merge sorts the row's entries by index,
/// ties in row order, and adds each index's weights in that order, as a dense accumulator
/// would, so the sums are the same bits; an accumulator over every source vertex faulted in
/// up to 117 fresh pages per level on catmark_car for the few raw rows.
fn merge_raw(
    keys: &mut Vec<u64>,
    merge: bool,
    row: &[(u32, f64)],
    idx: &mut Vec<u32>,
    wts: &mut Vec<f64>,
) {
    if !merge {
        idx.extend(row.iter().map(|e| e.0));
        wts.extend(row.iter().map(|e| e.1));
        return;
    }
    keys.clear();
    keys.extend(row.iter().enumerate().map(|(k, e)| entry_key(e.0, k)));
    keys.sort_unstable();
    let mut k = 0;
    while k < keys.len() {
        let j = (keys[k] >> 32) as u32;
        let mut w = row[keys[k] as u32 as usize].1;
        k += 1;
        while k < keys.len() && (keys[k] >> 32) as u32 == j {
            w += row[keys[k] as u32 as usize].1;
            k += 1;
        }
        if w != 0.0 {
            idx.push(j);
            wts.push(w);
        }
    }
}

/// Build a table row by row in parallel. `gen` writes row `i` ([`RowOut`]) and answers whether
/// it wrote it merged; raw rows are sorted, merged and stripped of exact zeros here.
pub(crate) fn build_rows<G>(n: usize, num_sources: usize, gen: G) -> StencilTable
where
    G: Fn(usize, &mut RowOut) -> bool + Sync,
{
    compose_rows(n, None, RowKind::Raw, num_sources, gen)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compose_with_identity_is_unchanged() {
        let t = build_rows(3, 4, |i, out| {
            out.raw.push((i as u32, 0.5));
            out.raw.push((i as u32 + 1, 0.25));
            out.raw.push((i as u32 + 1, 0.25));
            false
        });
        assert_eq!(t.stencil(1), (&[1u32, 2][..], &[0.5, 0.5][..]));
        let c = t.compose(&StencilTable::identity(4));
        assert_eq!(c, t);
        let p = t.apply(&[[0.0; 3], [2.0; 3], [4.0; 3], [6.0; 3]]);
        assert_eq!(p[2], [5.0; 3]);
    }
}
