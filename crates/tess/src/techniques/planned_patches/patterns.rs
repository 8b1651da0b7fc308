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
//! 4. **Screen-space and distance factors (per frame, on the host):** there is no control
//!    stage to choose levels, so the host does what it does: each canonical curve's factor
//!    (`curve_factor` of `adaptive.glsl`, from the curve's four points in the frame's view),
//!    each patch edge's level rounded up to a power of two (`edge_level`, a coarse transition
//!    edge twice its halves'), and the patch's key from its four levels. A curve's level is one
//!    number both patches of its edge read, so shared edges still meet point for point. The
//!    patches are grouped by key for the frame (one draw per key, a family of patterns indexed
//!    by the edge levels, made on first use) and their ids written into the command buffer
//!    ahead of the draws. The curve points come from the plan on the host (`AdaptivePlan::apply`,
//!    again only when the base moves), one frame's worth of stencils in `f64`.
//! 5. **Geomorphing (fractional-even spacing, per frame on the host too):** the levels stay
//!    powers of two, always from the generated patterns (their lattices nest level to level),
//!    and each patch instance carries morph weights: each edge's from its curve factor `g`
//!    and level `L` (`(g − L/2) / (L/2)`, the same on both sides of the edge), and the inside's
//!    from the facing edges that set each inner level. The vertex stage slides every odd
//!    vertex toward the even one the half level keeps by `1 − weight` and evaluates the patch
//!    there (`glsl/adaptive/pattern_patch.glsl`); a boundary vertex slides along its canonical
//!    curve, counted in the curve's direction, so both sides slide it to the same bits. Just
//!    past a doubling the surface is the half level's; uniform levels need not be whole.
use crate::error::{Result, TessError};
use crate::gpu::bindings::{
    ADAPTIVE_EDGE_COARSE, ADAPTIVE_EDGE_PLAIN, BFT_FACTORS_SCREEN, BFT_FACTORS_UNIFORM,
};
use crate::gpu::AdaptivePush;
use crate::pattern::{
    group_by_key, instance_buffers, write_instances, PatternBuffers, PatternFamily, PatternKey,
};
use crate::technique::{DrawCounts, PatchArray};
use crate::techniques::host_view::{
    morph_weight, pow2_level, unorm16_pair, HostView, MorphWords, NO_MORPH,
};
use crate::tessellator::{Domain, Spacing};
use std::collections::BTreeMap;
use std::ops::Range;
use vk_core::{Buffer, Encoder};

use super::layout::{GpuPlan, PatchRecord};
use topology::patches::adaptive::AdaptivePlan;

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
    current: PatternFamily,
    /// Under host-chosen levels, the frame's grouping; `None` under uniform factors.
    frame: Option<FrameGroups>,
    /// The frame's patch ids, written by the command buffer (`FrameGroups::ids`).
    frame_ids: Buffer,
}

/// One frame's patches grouped by the keys the host chose for them.
struct FrameGroups {
    /// Frame-wide patch ids and their morph weights, per array, per key.
    ids: Vec<[u32; 4]>,
    /// Per array, each key and its run of `ids`.
    groups: Vec<Vec<(PatternKey, Range<u32>)>>,
}

impl HostView {
    /// The factor a curve of control points `p` asks for (`curve_factor`).
    fn curve_factor(&self, p: [glam::Vec3; 4]) -> f32 {
        if self.mode == BFT_FACTORS_UNIFORM {
            return self.field;
        }
        if self.mode == BFT_FACTORS_SCREEN {
            let c = p.map(|q| self.view_proj * q.extend(1.0));
            if c.iter().map(|c| c.w).fold(f32::INFINITY, f32::min) <= 1e-6 {
                return self.max_level;
            }
            let h = glam::Vec2::from(self.viewport) * 0.5;
            let s = c.map(|c| glam::Vec2::new(c.x, c.y) / c.w * h);
            return (s[0].distance(s[1]) + s[1].distance(s[2]) + s[2].distance(s[3])) / self.field;
        }
        let d = self.eye.distance(0.5 * (p[0] + p[3]));
        self.max_level * self.field / d.max(1e-6)
    }

    /// Every canonical curve's factor, from the plan's vertices `verts`.
    pub fn curve_factors(&self, plan: &AdaptivePlan, verts: &[[f64; 3]]) -> Vec<f32> {
        let point = |id: u32| {
            let v = verts.get(id as usize).copied().unwrap_or_default();
            glam::Vec3::new(v[0] as f32, v[1] as f32, v[2] as f32)
        };
        plan.curves
            .iter()
            .map(|c| self.curve_factor(c.map(point)))
            .collect()
    }

    /// The level of edge `e` of patch `p` (`edge_level` with power-of-two levels, equal
    /// spacing): a plain edge its curve's, a transition edge the larger of its halves', doubled
    /// on the coarse side; and its morph weight (both sides of an edge compute it from the same
    /// curves, so they agree).
    fn edge_level(&self, p: &PatchRecord, e: usize, factors: &[f32]) -> (f32, f32) {
        let kind = (p.edge_info >> (4 * e)) & 3;
        let factor = |h: usize| {
            factors
                .get(p.curves[2 * e + h] as usize)
                .copied()
                .unwrap_or(1.0)
        };
        let pow2 = pow2_level;
        let weight = |g: f32, level: f32| self.weight(g, level);
        let lim = self.max_level;
        if kind == ADAPTIVE_EDGE_PLAIN {
            let g = factor(0).clamp(1.0, lim);
            let level = pow2(g).ceil().min(lim);
            return (level, weight(g, level));
        }
        let half = (lim * 0.5).floor();
        let g = factor(0).max(factor(1)).clamp(1.0, half);
        let f = pow2(g).ceil().min(half);
        let level = if kind == ADAPTIVE_EDGE_COARSE {
            2.0 * f
        } else {
            f
        };
        (level, weight(g, f))
    }

    /// The key of patch `p` on `domain`, and its morph weights: each edge's, and the inside's
    /// from the edge that sets each inner level (the larger continuous factor of the facing
    /// edges, `level / 2 · (1 + weight)`).
    pub fn key(
        &self,
        domain: Domain,
        p: &PatchRecord,
        factors: &[f32],
    ) -> (PatternKey, MorphWords) {
        let e: [(f32, f32); 4] = std::array::from_fn(|i| self.edge_level(p, i, factors));
        let key = key_of_levels(domain, Spacing::Equal, e.map(|(l, _)| l));
        if !self.morph {
            return (key, NO_MORPH);
        }
        let continuous = |(l, w): (f32, f32)| if l <= 1.0 { 1.0 } else { 0.5 * l * (1.0 + w) };
        let inner = |edges: &[usize]| {
            let level = edges.iter().map(|&i| e[i].0).fold(0.0, f32::max);
            let g = edges.iter().map(|&i| continuous(e[i])).fold(0.0, f32::max);
            morph_weight(g, level)
        };
        let (iu, iv) = match domain {
            Domain::Quad => (inner(&[0, 2]), inner(&[1, 3])),
            Domain::Triangle => (inner(&[0, 1, 2]), 1.0),
        };
        let words = [
            unorm16_pair(e[0].1, e[1].1),
            unorm16_pair(e[2].1, e[3].1),
            unorm16_pair(iu, iv),
        ];
        (key.generated(), words)
    }
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
    key_of_levels(domain, spacing, [e(0), e(1), e(2), e(3)])
}

/// The pattern key of a patch whose edges `0..4` (patch order) have levels `levels`, with the
/// control stage's mapping to the tessellator's outer and inner levels.
pub(super) fn key_of_levels(domain: Domain, spacing: Spacing, levels: [f32; 4]) -> PatternKey {
    let [e0, e1, e2, e3] = levels;
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
        let mut ids: Vec<[u32; 4]> = Vec::with_capacity(gpu.patches.len());
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
                let [a, b, c] = NO_MORPH;
                ids.extend(members.into_iter().map(|id| [id, a, b, c]));
                array_groups.push(PatternGroup {
                    kinds,
                    instances: first..ids.len() as u32,
                });
            }
            groups.push(array_groups);
        }
        let (ids, frame_ids) = instance_buffers(device, "adaptive pattern patch ids", ids)?;
        Ok(Self {
            ids,
            groups,
            current: PatternFamily::default(),
            frame: None,
            frame_ids,
        })
    }

    /// Groups the patches of every array by the key `key_of(array, id)` the host chose for the
    /// frame (with each patch's morph weights) and takes their patterns from the context
    /// ([`Self::record_ids`] writes the ids).
    pub fn prepare_host_levels(
        &mut self,
        ctx: &mut crate::context::Context,
        arrays: &[PatchArray],
        key_of: &dyn Fn(usize, u32) -> (PatternKey, MorphWords),
    ) -> Result<()> {
        let mut ids = Vec::new();
        let mut groups = Vec::with_capacity(arrays.len());
        for (i, a) in arrays.iter().enumerate() {
            let instances = (a.first_patch..a.first_patch + a.patches).map(|id| {
                let (key, [m0, m1, m2]) = key_of(i, id);
                (key, [id, m0, m1, m2])
            });
            groups.push(group_by_key(instances, &mut ids));
        }
        let keys: Vec<PatternKey> = groups.iter().flatten().map(|(k, _)| *k).collect();
        self.current.take(ctx, &keys)?;
        self.frame = Some(FrameGroups { ids, groups });
        Ok(())
    }

    /// Back to uniform factors' static groups.
    fn forget_host_levels(&mut self) {
        self.frame = None;
    }

    /// Under host-chosen levels, writes the frame's patch ids ahead of the draws (after the
    /// previous frame's draws read them).
    pub fn record_ids<'a>(&'a self, enc: &mut Encoder<'a>) -> Result<()> {
        match &self.frame {
            Some(f) => write_instances(enc, &self.frame_ids, &f.ids),
            None => Ok(()),
        }
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
        self.forget_host_levels();
        let keys: Vec<PatternKey> = self.keys(key_of).collect();
        self.current.take(ctx, &keys)
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
        if let Some(f) = &self.frame {
            let groups = f
                .groups
                .get(array)
                .ok_or(TessError::NoPatchArray { array })?;
            enc.bind_vertex_buffer(1, &self.frame_ids);
            let mut counts = DrawCounts::default();
            for (key, instances) in groups {
                counts += self.draw_group(enc, array, key, instances.clone(), &mut push)?;
            }
            return Ok(counts);
        }
        let mut counts = DrawCounts::default();
        enc.bind_vertex_buffer(1, &self.ids);
        for g in groups {
            let key = key_of(array, g.kinds);
            counts += self.draw_group(enc, array, &key, g.instances.clone(), &mut push)?;
        }
        Ok(counts)
    }

    /// One instanced draw of `key`'s pattern over the patch ids `instances`.
    fn draw_group<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        array: usize,
        key: &PatternKey,
        instances: Range<u32>,
        push: &mut AdaptivePush,
    ) -> Result<DrawCounts> {
        {
            let p = self.pattern(key, array)?;
            enc.bind_vertex_buffer(0, &p.points);
            enc.bind_index_buffer_u32(&p.indices);
            push.pattern_outer = key.outer();
            enc.push_constants(push)?;
            let indices = 3 * p.pattern.triangles.len() as u32;
            let patches = instances.len() as u32;
            enc.draw_indexed_instanced(0..indices, instances)?;
            Ok(DrawCounts { draws: 1, patches })
        }
    }

    /// Triangles `array` draws with the frame's keys, once they are prepared.
    pub fn triangles(
        &self,
        array: usize,
        key_of: &dyn Fn(usize, u32) -> PatternKey,
    ) -> Option<u64> {
        if let Some(f) = &self.frame {
            return f
                .groups
                .get(array)?
                .iter()
                .try_fold(0u64, |sum, (key, ids)| {
                    let p = self.current.get(key)?;
                    Some(sum + ids.len() as u64 * p.pattern.triangles.len() as u64)
                });
        }
        self.groups.get(array)?.iter().try_fold(0u64, |sum, g| {
            let p = self.current.get(&key_of(array, g.kinds))?;
            Some(sum + g.instances.len() as u64 * p.pattern.triangles.len() as u64)
        })
    }

    /// The most pattern vertices a patch of `array` has with the frame's keys.
    pub fn max_vertices(&self, array: usize, key_of: &dyn Fn(usize, u32) -> PatternKey) -> u64 {
        let keys: Vec<PatternKey> = match &self.frame {
            Some(f) => f
                .groups
                .get(array)
                .map_or(Vec::new(), |g| g.iter().map(|(k, _)| *k).collect()),
            None => self.groups.get(array).map_or(Vec::new(), |g| {
                g.iter().map(|g| key_of(array, g.kinds)).collect()
            }),
        };
        keys.iter()
            .filter_map(|k| self.current.get(k))
            .map(|p| p.pattern.points.len() as u64)
            .max()
            .unwrap_or(0)
    }

    /// The patch ids and the frame's patterns.
    pub fn buffers(&self) -> impl Iterator<Item = &Buffer> {
        std::iter::once(&self.ids).chain(self.current.buffers())
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
