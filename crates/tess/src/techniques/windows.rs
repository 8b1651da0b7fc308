//! Storage buffers larger than the device's `maxStorageBufferRange`: chunks of work, each bound
//! to a window of every large buffer.
//!
//! Design decisions:
//! - **Windows, not buffer device addresses.** A descriptor may name at most
//!   `maxStorageBufferRange` bytes (128 MiB on lavapipe; a 1M-triangle mesh's BFT patch rings
//!   alone are 190 MB). Buffer device addresses would lift the limit, but a host's device
//!   (the C ABI) may not enable them; windows work on every device with one shader path.
//!   Arrays no window can cut are read by address instead: the planned-patch techniques' draw
//!   (a patch reads three far-apart runs of its vertex buffer, `techniques::planned_patches`),
//!   BFT's basis-function tables (any patch may read any shared table) and Doo-Sabin's deepest
//!   level (`techniques::doo_sabin`). Each technique's work (level-1 vertices
//!   of a compute pre-pass, patches of a draw) is cut into chunks; a chunk gets its own
//!   descriptor set whose bindings are `(offset, range)` windows of the shared buffers, and the
//!   shaders subtract the chunk's base index (push constants) from every index into a
//!   windowed buffer. Data keep their global indices, so nothing is repacked per chunk.
//! - **Index spaces.** Buffers indexed by the same number (level-1 positions, normals, and the
//!   CSR offsets of their rows) share one window and one base: a *space*. A chunk's window in
//!   a space is the interval hull of every index its invocations can form (its footprint,
//!   computed on the CPU from the same tables the shaders read), with the low end rounded down
//!   so every buffer of the space starts at a multiple of `minStorageBufferOffsetAlignment`.
//! - **Greedy, in order.** Chunks grow item by item while every window fits the limit; meshes
//!   from refinement keep neighbours close in index, so a handful of chunks cover a 1M-face
//!   mesh. A single item whose footprint does not fit is a typed error
//!   ([`TessError::StorageWindow`]), never a silent overrun (vk-core refuses such a write too).
//! - **The uncapped small case is today's path**: one chunk, windows `[0, len)`, bases 0.
//! - The limit used is the device's as capped by `DeviceDesc::storage_buffer_range_cap`, so
//!   tests drive the many-chunk path with small meshes.
use crate::error::{Result, TessError};
use std::ops::Range;
use vk_core::{vk, Buffer, DescriptorSet, Device};

/// One buffer of a space: bytes per element, and how many elements past the window's end the
/// shaders read (1 for CSR offsets: row `v` reads `offsets[v + 1]`).
#[derive(Clone, Copy, Debug)]
pub struct Member {
    pub stride: u64,
    pub extra: u32,
}

/// The buffers one base index addresses.
#[derive(Clone, Copy, Debug)]
pub struct Space {
    pub name: &'static str,
    pub members: &'static [Member],
}

/// The device limits a window must respect.
#[derive(Clone, Copy, Debug)]
pub struct Limits {
    /// Largest storage-buffer range, in bytes.
    pub max_range: u64,
    /// Storage-buffer offset alignment, in bytes.
    pub alignment: u64,
}

impl Limits {
    pub fn of(device: &Device) -> Self {
        let caps = &device.info.caps;
        Self {
            max_range: caps.max_storage_buffer_range as u64,
            alignment: caps.min_storage_buffer_offset_alignment.max(1),
        }
    }
}

fn gcd(a: u64, b: u64) -> u64 {
    if b == 0 {
        a
    } else {
        gcd(b, a % b)
    }
}

fn lcm(a: u64, b: u64) -> u64 {
    a / gcd(a, b) * b
}

impl Space {
    /// Element step a window's low end is rounded down to, so every member's offset is aligned.
    fn step(&self, alignment: u64) -> u64 {
        self.members
            .iter()
            .map(|m| alignment / gcd(m.stride, alignment))
            .fold(1, lcm)
    }

    /// Bytes the largest member's window spans.
    fn bytes(&self, w: &Range<u32>) -> u64 {
        self.members
            .iter()
            .map(|m| (w.end as u64 + m.extra as u64 - w.start as u64) * m.stride)
            .max()
            .unwrap_or(0)
    }
}

/// A run of items and its window in each space (low ends aligned; empty when untouched).
#[derive(Clone, Debug, PartialEq, Eq)]
pub struct Chunk<const K: usize> {
    pub items: Range<u32>,
    pub windows: [Range<u32>; K],
}

fn hull(a: &Range<u32>, b: &Range<u32>) -> Range<u32> {
    if a.is_empty() {
        b.clone()
    } else if b.is_empty() {
        a.clone()
    } else {
        a.start.min(b.start)..a.end.max(b.end)
    }
}

/// Cuts items `0..n` into chunks whose windows fit `limits`; `footprint(i)` gives, per space,
/// the indices item `i` can reach (an empty range: none).
pub fn plan<const K: usize>(
    what: &'static str,
    n: u32,
    spaces: &[Space; K],
    limits: Limits,
    mut footprint: impl FnMut(u32) -> [Range<u32>; K],
) -> Result<Vec<Chunk<K>>> {
    let steps: Vec<u64> = spaces.iter().map(|s| s.step(limits.alignment)).collect();
    let aligned = |w: &Range<u32>, k: usize| -> Range<u32> {
        if w.is_empty() {
            0..0
        } else {
            (w.start - (w.start as u64 % steps[k]) as u32)..w.end
        }
    };
    let overflow = |ws: &[Range<u32>; K]| -> Option<usize> {
        (0..K).find(|&k| spaces[k].bytes(&aligned(&ws[k], k)) > limits.max_range)
    };
    let mut chunks = Vec::new();
    let mut start = 0;
    let mut cur: [Range<u32>; K] = std::array::from_fn(|_| 0..0);
    for i in 0..n {
        let fp = footprint(i);
        let trial: [Range<u32>; K] = std::array::from_fn(|k| hull(&cur[k], &fp[k]));
        if overflow(&trial).is_none() {
            cur = trial;
            continue;
        }
        // The item does not fit with the chunk; alone it must.
        if let Some(k) = overflow(&fp) {
            return Err(TessError::StorageWindow {
                what,
                item: i,
                space: spaces[k].name,
                bytes: spaces[k].bytes(&aligned(&fp[k], k)),
                max: limits.max_range,
            });
        }
        chunks.push(Chunk {
            items: start..i,
            windows: std::array::from_fn(|k| aligned(&cur[k], k)),
        });
        start = i;
        cur = fp;
    }
    if n > start || chunks.is_empty() {
        chunks.push(Chunk {
            items: start..n,
            windows: std::array::from_fn(|k| aligned(&cur[k], k)),
        });
    }
    Ok(chunks)
}

/// Writes `binding` of `set` as the window `w` of `buffer` (a member of stride `m.stride`, with
/// `len` elements): bytes `w.start · stride .. (w.end + extra) · stride`, clamped to the
/// buffer. An untouched window binds the buffer's first element (a set must be complete).
pub fn write_window(
    set: &DescriptorSet,
    binding: u32,
    buffer: &Buffer,
    m: Member,
    len: u64,
    w: &Range<u32>,
) -> Result<()> {
    let size = buffer.size();
    let end = ((w.end as u64 + m.extra as u64).min(len) * m.stride).min(size);
    let offset = w.start as u64 * m.stride;
    let (offset, range) = if w.is_empty() || end <= offset {
        (0, size.min(m.stride.max(4)))
    } else {
        (offset, end - offset)
    };
    Ok(set.write_buffer_range(
        binding,
        vk::DescriptorType::STORAGE_BUFFER,
        buffer,
        offset,
        range,
    )?)
}

#[cfg(test)]
// One-buffer plans are written as one-element arrays of windows, as the planner takes them.
#[allow(clippy::single_range_in_vec_init)]
mod tests {
    use super::*;

    const ONE: Space = Space {
        name: "one",
        members: &[Member {
            stride: 16,
            extra: 0,
        }],
    };

    #[test]
    fn one_chunk_when_everything_fits() {
        let limits = Limits {
            max_range: 1 << 20,
            alignment: 64,
        };
        let c = plan("items", 100, &[ONE], limits, |i| [i..i + 1]).unwrap();
        assert_eq!(
            c,
            vec![Chunk {
                items: 0..100,
                windows: [0..100]
            }]
        );
    }

    #[test]
    fn windows_fit_aligned_and_cover_every_footprint() {
        let limits = Limits {
            max_range: 16 * 40,
            alignment: 64,
        };
        // Each item reaches its neighbours up to 5 away.
        let fp = |i: u32| [i.saturating_sub(5)..(i + 6).min(1000)];
        let c = plan("items", 1000, &[ONE], limits, fp).unwrap();
        assert!(c.len() > 30);
        let mut next = 0;
        for ch in &c {
            assert_eq!(ch.items.start, next);
            next = ch.items.end;
            let w = &ch.windows[0];
            assert_eq!((w.start as u64 * 16) % 64, 0);
            assert!((w.end - w.start) as u64 * 16 <= limits.max_range);
            for i in ch.items.clone() {
                let f = fp(i)[0].clone();
                assert!(w.start <= f.start && f.end <= w.end, "{i}: {f:?} in {w:?}");
            }
        }
        assert_eq!(next, 1000);
    }

    #[test]
    fn an_item_larger_than_the_limit_is_an_error() {
        let limits = Limits {
            max_range: 64,
            alignment: 16,
        };
        let e = plan("items", 3, &[ONE], limits, |_| [0..10]).unwrap_err();
        assert!(matches!(e, TessError::StorageWindow { item: 0, .. }), "{e}");
    }

    #[test]
    fn csr_offsets_count_their_extra_element() {
        const CSR: Space = Space {
            name: "csr",
            members: &[Member {
                stride: 4,
                extra: 1,
            }],
        };
        let limits = Limits {
            max_range: 16,
            alignment: 4,
        };
        let c = plan("rows", 8, &[CSR], limits, |i| [i..i + 1]).unwrap();
        let lens: Vec<usize> = c.iter().map(|ch| ch.items.len()).collect();
        assert_eq!(lens, [3, 3, 2]);
    }
}
