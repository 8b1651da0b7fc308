//! The planned patches on the refinement-pattern path ([`crate::pattern`]): every patch kind
//! evaluated in the vertex stage at the vertices of a pattern instanced over the patches
//! (`glsl/adaptive/pattern_*.vert`, the evaluation stages' own code).
//!
//! 1. **Groups (once):** the patches of each array are grouped by their edge kinds (plain,
//!    coarse or fine per edge: `edge_info`'s kinds). Under uniform factors every patch of a
//!    group gets the same edge levels, so one pattern serves the group; its frame-wide patch
//!    ids are one run of an instance-rate vertex buffer.
//! 2. **Keys (per frame):** a group's pattern key is the levels the control stage would set
//!    (`glsl/adaptive/tesc_levels.glsl`: a coarse transition edge doubled, inner levels the
//!    larger of each facing pair). Uniform keys are the tessellator's own patterns where the
//!    device has one, so those patches emit the tessellation path's domain points and bits;
//!    keys with a doubled edge are generated ([`crate::pattern::RefinementPattern::generate_edges`]).
//! 3. **Draws:** one instanced indexed draw per group, its key's edge levels in the push
//!    constants: a canonical vertex (on the patch boundary) finds its index along the edge
//!    from them, exactly as the evaluation stage does from `gl_TessLevelOuter`, so both sides
//!    of every edge evaluate the same canonical curve point, transitions included.
use crate::error::{Result, TessError};
use crate::gpu::AdaptivePush;
use crate::pattern::{PatternBuffers, PatternKey};
use crate::technique::{DrawCounts, PatchArray};
use crate::tessellator::{Domain, Spacing};
use std::collections::{BTreeMap, HashMap};
use std::ops::Range;
use vk_core::{vk, Buffer, Encoder};

use super::layout::GpuPlan;

/// The patches of one array sharing their edge kinds.
struct PatternGroup {
    /// `edge_info & 0x3333`: 2 bits of kind at `4 i` per edge `i`.
    kinds: u32,
    /// Their run in the patch-id buffer (the draw's instances).
    instances: Range<u32>,
}

/// The pattern path's draws of a planned surface.
pub(super) struct PatternDraws {
    /// Frame-wide patch ids, per array, per group (the instance-rate vertex buffer).
    ids: Buffer,
    /// Per array, its groups.
    groups: Vec<Vec<PatternGroup>>,
    /// The device patterns of the frame's keys.
    current: HashMap<PatternKey, PatternBuffers>,
}

/// The edge levels of a patch with edge kinds `kinds` as the control stage sets them, as a
/// pattern key: `level(kind)` is one edge's level (`edge_level` in `adaptive.glsl`).
pub(super) fn key_of_kinds(
    domain: Domain,
    spacing: Spacing,
    kinds: u32,
    level: impl Fn(u32) -> f32,
) -> PatternKey {
    let e = |i: u32| level((kinds >> (4 * i)) & 3);
    let (e0, e1, e2, e3) = (e(0), e(1), e(2), e(3));
    match domain {
        // tesc_levels.glsl: outer 0 is the edge u = 0 (patch edge 3), 1 is v = 0 (edge 0), 2 is
        // u = 1 (edge 1), 3 is v = 1 (edge 2).
        Domain::Quad => {
            PatternKey::with_levels(domain, spacing, [e3, e0, e1, e2], [e0.max(e2), e1.max(e3)])
        }
        // A triangle: outer 0 is edge 2, 1 edge 0, 2 edge 1.
        Domain::Triangle => {
            let inner = e0.max(e1).max(e2);
            PatternKey::with_levels(domain, spacing, [e2, e0, e1, 0.0], [inner, 0.0])
        }
    }
}

impl PatternDraws {
    /// Groups every array's patches by their edge kinds and uploads their ids.
    pub fn new(device: &vk_core::Device, arrays: &[PatchArray], gpu: &GpuPlan) -> Result<Self> {
        let mut ids: Vec<u32> = Vec::with_capacity(gpu.patches.len());
        let mut groups = Vec::with_capacity(arrays.len());
        for a in arrays {
            let mut by_kinds: BTreeMap<u32, Vec<u32>> = BTreeMap::new();
            for id in a.first_patch..a.first_patch + a.patches {
                let p = gpu
                    .patches
                    .get(id as usize)
                    .ok_or(TessError::IndexOutOfRange {
                        what: "planned patch id",
                        index: id as u64,
                        len: gpu.patches.len() as u64,
                    })?;
                by_kinds.entry(p.edge_info & 0x3333).or_default().push(id);
            }
            let mut array_groups = Vec::with_capacity(by_kinds.len());
            for (kinds, members) in by_kinds {
                let first = ids.len() as u32;
                ids.extend(members);
                array_groups.push(PatternGroup {
                    kinds,
                    instances: first..ids.len() as u32,
                });
            }
            groups.push(array_groups);
        }
        // An empty plan still binds a buffer (zero-length buffers are invalid); no draw reads it.
        if ids.is_empty() {
            ids.push(0);
        }
        Ok(Self {
            ids: Buffer::with_data(
                device,
                "adaptive pattern patch ids",
                vk::BufferUsageFlags::VERTEX_BUFFER,
                bytemuck::cast_slice(&ids),
            )?,
            groups,
            current: HashMap::new(),
        })
    }

    /// Every key the frame draws, per array and group (`key_of(array, kinds)`).
    fn keys<'a>(
        &'a self,
        key_of: &'a dyn Fn(usize, u32) -> PatternKey,
    ) -> impl Iterator<Item = PatternKey> + 'a {
        self.groups
            .iter()
            .enumerate()
            .flat_map(move |(a, g)| g.iter().map(move |g| key_of(a, g.kinds)))
    }

    /// Takes the frame's patterns from the context and uploads those not on the device yet;
    /// patterns no key uses any more are dropped.
    pub fn prepare(
        &mut self,
        ctx: &mut crate::context::Context,
        key_of: &dyn Fn(usize, u32) -> PatternKey,
    ) -> Result<()> {
        let keys: Vec<PatternKey> = self.keys(key_of).collect();
        self.current.retain(|k, _| keys.contains(k));
        for key in keys {
            if self.current.contains_key(&key) {
                continue;
            }
            let pattern = ctx.refinement_pattern_for(key)?;
            let buffers = PatternBuffers::new(ctx.device(), key, pattern)?;
            self.current.insert(key, buffers);
        }
        Ok(())
    }

    /// The prepared pattern of `key`.
    fn pattern(&self, key: &PatternKey, array: usize) -> Result<&PatternBuffers> {
        self.current
            .get(key)
            .ok_or(TessError::NoPatchArray { array })
    }

    /// One instanced draw per group of `array`, `push` with each group's edge levels.
    pub fn record<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        key_of: &dyn Fn(usize, u32) -> PatternKey,
        mut push: AdaptivePush,
    ) -> Result<DrawCounts> {
        let groups = self
            .groups
            .get(array)
            .ok_or(TessError::NoPatchArray { array })?;
        let mut counts = DrawCounts::default();
        enc.bind_vertex_buffer(1, &self.ids);
        for g in groups {
            let key = key_of(array, g.kinds);
            let p = self.pattern(&key, array)?;
            enc.bind_vertex_buffer(0, &p.points);
            enc.bind_index_buffer_u32(&p.indices);
            push.pattern_outer = key.outer();
            enc.push_constants(&push)?;
            let indices = 3 * p.pattern.triangles.len() as u32;
            enc.draw_indexed_instanced(0..indices, g.instances.clone())?;
            counts += DrawCounts {
                draws: 1,
                patches: g.instances.len() as u32,
            };
        }
        Ok(counts)
    }

    /// Triangles `array` draws with the frame's keys, once they are prepared.
    pub fn triangles(
        &self,
        array: usize,
        key_of: &dyn Fn(usize, u32) -> PatternKey,
    ) -> Option<u64> {
        self.groups.get(array)?.iter().try_fold(0u64, |sum, g| {
            let p = self.current.get(&key_of(array, g.kinds))?;
            Some(sum + g.instances.len() as u64 * p.pattern.triangles.len() as u64)
        })
    }

    /// The most pattern vertices a patch of `array` has with the frame's keys.
    pub fn max_vertices(&self, array: usize, key_of: &dyn Fn(usize, u32) -> PatternKey) -> u64 {
        self.groups.get(array).map_or(0, |groups| {
            groups
                .iter()
                .filter_map(|g| self.current.get(&key_of(array, g.kinds)))
                .map(|p| p.pattern.points.len() as u64)
                .max()
                .unwrap_or(0)
        })
    }

    /// The patch ids and the frame's patterns.
    pub fn buffers(&self) -> impl Iterator<Item = &Buffer> {
        std::iter::once(&self.ids)
            .chain(self.current.values().flat_map(|p| [&p.points, &p.indices]))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::gpu::bindings::{ADAPTIVE_EDGE_COARSE, ADAPTIVE_EDGE_FINE, ADAPTIVE_EDGE_PLAIN};

    fn has_coarse_edge(kinds: u32) -> bool {
        (0..4).any(|i| (kinds >> (4 * i)) & 3 == ADAPTIVE_EDGE_COARSE)
    }

    /// The levels of tesc_levels.glsl: a coarse bottom edge (patch edge 0) is outer level 1
    /// and doubles the inner level along u; a triangle's edges map to outer 1, 2, 0.
    #[test]
    fn keys_follow_the_control_stages_levels() {
        let level = |k: u32| if k == ADAPTIVE_EDGE_COARSE { 8.0 } else { 4.0 };
        let kinds = ADAPTIVE_EDGE_COARSE | (ADAPTIVE_EDGE_FINE << 4) | (ADAPTIVE_EDGE_PLAIN << 8);
        assert!(has_coarse_edge(kinds));
        let k = key_of_kinds(Domain::Quad, Spacing::Equal, kinds, level);
        assert_eq!(k.outer(), [4.0, 8.0, 4.0, 4.0]);
        assert_eq!(k.inner(), [8.0, 4.0]);
        assert_eq!(k.uniform_level(), None);
        let plain = key_of_kinds(Domain::Quad, Spacing::Equal, 0, level);
        assert_eq!(plain.uniform_level(), Some(4.0));
        assert!(!has_coarse_edge(0));
        let coarse_all = ADAPTIVE_EDGE_COARSE * 0x111;
        let t = key_of_kinds(Domain::Triangle, Spacing::Equal, coarse_all, level);
        assert_eq!(t.uniform_level(), Some(8.0));
        let t = key_of_kinds(
            Domain::Triangle,
            Spacing::Equal,
            ADAPTIVE_EDGE_COARSE << 4,
            level,
        );
        assert_eq!(t.outer(), [4.0, 4.0, 8.0, 0.0]);
        assert_eq!(t.inner(), [8.0, 0.0]);
    }
}
