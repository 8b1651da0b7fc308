//! Stencils: each refined vertex as a sparse weighted sum of control (base) vertices, stored
//! flat (CSR) so the GPU can re-evaluate refined points every frame while the base animates.

use rayon::prelude::*;

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

    /// Stencils of `self` (over the vertices `parent` produces) re-expressed over `parent`'s
    /// sources: `result_i = Σ_j w_ij · parent_j`.
    pub fn compose(&self, parent: &StencilTable) -> StencilTable {
        let n_src = parent.num_sources;
        build_rows(
            self.len(),
            n_src,
            || {
                (
                    vec![0.0f64; n_src],
                    vec![u32::MAX; n_src],
                    Vec::<u32>::new(),
                )
            },
            |(acc, stamp, touched), i, out| {
                touched.clear();
                let (idx, w) = self.stencil(i);
                for (&j, &wj) in idx.iter().zip(w) {
                    let (pidx, pw) = parent.stencil(j as usize);
                    for (&b, &wb) in pidx.iter().zip(pw) {
                        let b = b as usize;
                        if stamp[b] != i as u32 {
                            stamp[b] = i as u32;
                            acc[b] = 0.0;
                            touched.push(b as u32);
                        }
                        acc[b] += wj * wb;
                    }
                }
                touched.sort_unstable();
                out.extend(touched.iter().map(|&b| (b, acc[b as usize])));
            },
        )
    }
}

/// Build a table row by row in parallel. `f` writes the (index, weight) pairs of row `i`;
/// they are sorted, merged and stripped of exact zeros here. `init` makes per-block scratch.
pub(crate) fn build_rows<S, I, F>(n: usize, num_sources: usize, init: I, f: F) -> StencilTable
where
    I: Fn() -> S + Sync,
    F: Fn(&mut S, usize, &mut Vec<(u32, f64)>) + Sync,
{
    let threads = rayon::current_num_threads().max(1);
    let blocks = n.div_ceil(2048).clamp(1, threads * 4);
    let block_len = n.div_ceil(blocks).max(1);
    let parts: Vec<(Vec<u32>, Vec<u32>, Vec<f64>)> = (0..blocks)
        .into_par_iter()
        .map(|b| {
            let start = (b * block_len).min(n);
            let end = ((b + 1) * block_len).min(n);
            let mut scratch = init();
            let mut sizes = Vec::with_capacity(end - start);
            let mut idx = Vec::with_capacity((end - start) * 8);
            let mut wts = Vec::with_capacity((end - start) * 8);
            let mut row = Vec::with_capacity(64);
            for i in start..end {
                row.clear();
                f(&mut scratch, i, &mut row);
                merge_row(&mut row);
                sizes.push(row.len() as u32);
                for &(j, w) in &row {
                    idx.push(j);
                    wts.push(w);
                }
            }
            (sizes, idx, wts)
        })
        .collect();
    let total: usize = parts.iter().map(|p| p.1.len()).sum();
    let mut offsets = Vec::with_capacity(n + 1);
    let mut indices = Vec::with_capacity(total);
    let mut weights = Vec::with_capacity(total);
    offsets.push(0u32);
    let mut acc = 0u32;
    for (sizes, idx, wts) in parts {
        for s in sizes {
            acc += s;
            offsets.push(acc);
        }
        indices.extend_from_slice(&idx);
        weights.extend_from_slice(&wts);
    }
    StencilTable {
        offsets,
        indices,
        weights,
        num_sources,
    }
}

/// Sort by index, add duplicates, drop exact zeros.
fn merge_row(row: &mut Vec<(u32, f64)>) {
    if row.len() > 1 {
        row.sort_unstable_by_key(|e| e.0);
        let mut w = 0;
        for r in 1..row.len() {
            if row[r].0 == row[w].0 {
                row[w].1 += row[r].1;
            } else {
                w += 1;
                row[w] = row[r];
            }
        }
        row.truncate(w + 1);
    }
    row.retain(|e| e.1 != 0.0);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn compose_with_identity_is_unchanged() {
        let t = build_rows(
            3,
            4,
            || (),
            |_, i, out| {
                out.push((i as u32, 0.5));
                out.push((i as u32 + 1, 0.25));
                out.push((i as u32 + 1, 0.25));
            },
        );
        assert_eq!(t.stencil(1), (&[1u32, 2][..], &[0.5, 0.5][..]));
        let c = t.compose(&StencilTable::identity(4));
        assert_eq!(c, t);
        let p = t.apply(&[[0.0; 3], [2.0; 3], [4.0; 3], [6.0; 3]]);
        assert_eq!(p[2], [5.0; 3]);
    }
}
