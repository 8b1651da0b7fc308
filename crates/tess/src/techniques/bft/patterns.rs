//! BFT on the refinement-pattern path ([`crate::pattern`]): triangle patterns instanced over the
//! level-1 faces, each vertex evaluated from the tables in the vertex stage
//! (`glsl/bft/pattern.vert`). Each instance is one face, read from an instance-rate vertex
//! buffer with the face's morph weights.
//!
//! 1. **Uniform factors:** every face draws the pattern of the frame's level; the instances are
//!    the faces in order (a static buffer, instance `f` is face `f`), one draw per drawn run of
//!    each draw chunk.
//! 2. **Screen-space and distance factors (per frame, on the host):** there is no control stage
//!    to choose levels, so the host does what `bft.tesc` does: each level-1 edge's factor from
//!    its two endpoints only, rounded up to a power of two (every pattern vertex stays a table
//!    point); a face's key is its three edge levels and their largest as the inner level (a
//!    family of triangle patterns indexed by edge levels, made on first use). Both faces of an
//!    edge compute its level from the same two points, so they draw the same points on it and
//!    evaluate each in the owner's frame: shared edges keep their bits. The level-1 positions
//!    come from the base → level-1 stencils on the host, again only when the base moves.
//! 3. **Groups:** the faces of each draw chunk (whose descriptor windows hold only its own
//!    faces) are grouped by key, one instanced draw per group with its key's edge levels in the
//!    push constants; the frame's face ids are written into the command buffer ahead of the
//!    draws.
//! 4. **Geomorphing (fractional-even spacing):** the levels stay powers of two, from the
//!    generated patterns (their lattices nest from level to level), and each instance carries
//!    morph weights: each edge's from its factor `g` and level `L` (`(g − L/2) / (L/2)`, the
//!    same on both faces of the edge), and the inside's from the largest factor. The vertex
//!    stage's geomorphing build slides each odd vertex toward the even one the half level
//!    keeps. Uniform levels need not be whole.
use super::{BftPush, SetWindows};
use crate::error::{Result, TessError};
use crate::gpu::bindings::{BFT_FACTORS_DISTANCE, BFT_FACTORS_SCREEN};
use crate::pattern::{group_by_key, instance_buffers, write_instances, PatternFamily, PatternKey};
use crate::stencil::GpuStencils;
use crate::technique::DrawCounts;
use crate::techniques::host_view::{
    morph_weight, pow2_level, unorm16_pair, HostView, MorphWords, NO_MORPH,
};
use crate::tessellator::{Domain, Spacing};
use glam::{Vec2, Vec3};
use std::ops::Range;
use vk_core::{Buffer, DescriptorSet, Encoder};

/// The faces a frame draws under one draw chunk's set: `(chunk, faces)`.
pub(super) type Piece = (usize, Range<u32>);

/// One instanced draw: a key's pattern over a run of instances, under one chunk's set.
struct KeyDraw {
    chunk: usize,
    key: PatternKey,
    instances: Range<u32>,
}

/// The frame's draws, and under host-chosen levels the instances they read (face id and
/// morph weights); `None`: the static instances, face `f` at instance `f`.
struct Frame {
    draws: Vec<KeyDraw>,
    ids: Option<Vec<[u32; 4]>>,
    morph: bool,
}

/// What the host keeps of level 1 to choose levels: the base → level-1 stencils, each face's
/// corners `v0, v1, v2`, and the level-1 positions of the base they were last computed from.
struct HostLevel1 {
    stencils: GpuStencils,
    corners: Vec<[u32; 3]>,
    positions: Option<(Vec<[f32; 3]>, Vec<Vec3>)>,
}

/// BFT's pattern draws.
pub(super) struct BftPatterns {
    /// Every face with no morph, in order: the instances of uniform frames.
    ids: Buffer,
    /// The instances of host-chosen levels (every face at most once), written by the command
    /// buffer.
    frame_ids: Buffer,
    /// The device patterns of the frame's keys.
    patterns: PatternFamily,
    frame: Option<Frame>,
    level1: HostLevel1,
}

impl HostLevel1 {
    /// Recomputes the level-1 positions when `base` moved.
    fn update_positions(&mut self, base: &[[f32; 3]]) {
        if self.positions.as_ref().is_some_and(|(b, _)| b == base) {
            return;
        }
        // The stencil evaluator's own arithmetic: the positions `bft.tesc` measures on the other
        // path, bit for bit.
        let s = &self.stencils;
        let vertex = |i: u32| base.get(i as usize).copied().unwrap_or_default();
        let rows = s.offsets.len().saturating_sub(1) as u32;
        let level1 = (0..rows).map(|r| Vec3::from(s.row_point(r, vertex)));
        self.positions = Some((base.to_vec(), level1.collect()));
    }

    /// The instances (face and morph weights) of every face of `pieces`, keyed in `host`'s view
    /// of the level-1 surface of `base` and grouped by key within each chunk, and their draws.
    fn keyed_draws(
        &mut self,
        host: &HostView,
        base: &[[f32; 3]],
        pieces: &[Piece],
    ) -> Result<(Vec<[u32; 4]>, Vec<KeyDraw>)> {
        self.update_positions(base);
        let pos = self
            .positions
            .as_ref()
            .map_or(&[][..], |(_, p)| p.as_slice());
        let screen: Vec<Option<Vec2>> = match host.mode {
            BFT_FACTORS_SCREEN => pos.iter().map(|&p| host.screen(p)).collect(),
            _ => Vec::new(),
        };
        let factor = |a, b| host.level1_edge_factor(&screen, pos, a, b);
        let (mut ids, mut draws) = (Vec::new(), Vec::new());
        for (chunk, faces) in pieces {
            let instances = faces
                .clone()
                .map(|f| {
                    let c = self
                        .corners
                        .get(f as usize)
                        .ok_or(TessError::IndexOutOfRange {
                            what: "bft pattern face",
                            index: f as u64,
                            len: self.corners.len() as u64,
                        })?;
                    let (key, [m0, m1, m2]) = host.face_key(*c, factor);
                    Ok((key, [f, m0, m1, m2]))
                })
                .collect::<Result<Vec<_>>>()?;
            let groups = group_by_key(instances, &mut ids);
            draws.extend(groups.into_iter().map(|(key, instances)| KeyDraw {
                chunk: *chunk,
                key,
                instances,
            }));
        }
        Ok((ids, draws))
    }
}

impl HostView {
    /// The factor a level-1 edge from `p` to `q` asks for (`edge_factor` of `bft.tesc`):
    /// `screen` holds the level-1 points' screen positions under screen-space factors.
    fn level1_edge_factor(&self, screen: &[Option<Vec2>], pos: &[Vec3], a: u32, b: u32) -> f32 {
        let (lo, hi) = (a.min(b) as usize, a.max(b) as usize);
        let f = match self.mode {
            BFT_FACTORS_SCREEN => match (screen.get(lo), screen.get(hi)) {
                (Some(Some(s)), Some(Some(t))) => s.distance(*t) / self.field,
                _ => self.max_level,
            },
            BFT_FACTORS_DISTANCE => {
                let (p, q) = (pos.get(lo).copied(), pos.get(hi).copied());
                let mid = 0.5 * (p.unwrap_or_default() + q.unwrap_or_default());
                self.max_level * self.field / self.eye.distance(mid).max(1e-6)
            }
            _ => self.field,
        };
        f.clamp(1.0, self.max_level)
    }

    /// The key of a face of corners `c` and its morph weights (bft_locate's edge numbering:
    /// edge `e` runs `v_e → v_(e+1)`), from the edges' `factor`s.
    fn face_key(&self, c: [u32; 3], factor: impl Fn(u32, u32) -> f32) -> (PatternKey, MorphWords) {
        // Edges v0v1, v1v2, v2v0; gl_TessLevelOuter[i] is the edge opposite corner i.
        let g = [factor(c[0], c[1]), factor(c[1], c[2]), factor(c[2], c[0])];
        let level = g.map(|g| pow2_level(g).min(self.max_level));
        let inner = level[0].max(level[1]).max(level[2]);
        let outer = [level[1], level[2], level[0], 0.0];
        let key = PatternKey::with_levels(Domain::Triangle, Spacing::Equal, outer, [inner, 0.0]);
        if !self.morph {
            return (key, NO_MORPH);
        }
        let w = |i: usize| morph_weight(g[i], level[i]);
        let inside = morph_weight(g[0].max(g[1]).max(g[2]), inner);
        let words = [
            unorm16_pair(w(0), w(1)),
            unorm16_pair(w(2), 1.0),
            unorm16_pair(inside, 1.0),
        ];
        (key.generated(), words)
    }
}

impl BftPatterns {
    /// The static instances of `patch_count` faces, and what the host keeps of level 1.
    pub fn new(
        device: &vk_core::Device,
        patch_count: u32,
        stencils: GpuStencils,
        corners: Vec<[u32; 3]>,
    ) -> Result<Self> {
        let [a, b, c] = NO_MORPH;
        let records = (0..patch_count).map(|f| [f, a, b, c]).collect();
        let (ids, frame_ids) = instance_buffers(device, "bft pattern faces", records)?;
        Ok(Self {
            ids,
            frame_ids,
            patterns: PatternFamily::default(),
            frame: None,
            level1: HostLevel1 {
                stencils,
                corners,
                positions: None,
            },
        })
    }

    /// Whether the frame geomorphs (the vertex stage's geomorphing build).
    pub fn morph(&self) -> bool {
        self.frame.as_ref().is_some_and(|f| f.morph)
    }

    /// Uniform factors without geomorphing: one pattern at `level` for every face of `pieces`.
    pub fn prepare_uniform(
        &mut self,
        ctx: &mut crate::context::Context,
        level: f32,
        pieces: &[Piece],
    ) -> Result<()> {
        let key = PatternKey::new(Domain::Triangle, Spacing::Equal, level);
        let draws = pieces
            .iter()
            .map(|(chunk, faces)| KeyDraw {
                chunk: *chunk,
                key,
                instances: faces.clone(),
            })
            .collect();
        self.patterns.take(ctx, &[key])?;
        self.frame = Some(Frame {
            draws,
            ids: None,
            morph: false,
        });
        Ok(())
    }

    /// Host-chosen levels (module docs, steps 2–4): every face of `pieces` keyed from its edges'
    /// factors in `host`'s view of the level-1 surface of `base`, grouped by key within its
    /// chunk.
    pub fn prepare_host_levels(
        &mut self,
        ctx: &mut crate::context::Context,
        host: &HostView,
        base: &[[f32; 3]],
        pieces: &[Piece],
    ) -> Result<()> {
        let (ids, draws) = self.level1.keyed_draws(host, base, pieces)?;
        let keys: Vec<PatternKey> = draws.iter().map(|d| d.key).collect();
        self.patterns.take(ctx, &keys)?;
        self.frame = Some(Frame {
            draws,
            ids: Some(ids),
            morph: host.morph,
        });
        Ok(())
    }

    /// Under host-chosen levels, writes the frame's instances ahead of the draws (after the
    /// previous frame's draws read them).
    pub fn record_ids<'a>(&'a self, enc: &mut Encoder<'a>) -> Result<()> {
        match &self.frame {
            Some(Frame { ids: Some(ids), .. }) => write_instances(enc, &self.frame_ids, ids),
            _ => Ok(()),
        }
    }

    /// The frame's draws: per chunk its set (the context bound the first chunk's) and window
    /// bases, then one instanced draw per key, `push` with its edge levels.
    pub fn record<'a>(
        &'a self,
        enc: &mut Encoder<'a>,
        chunks: &'a [(Range<u32>, SetWindows)],
        sets: &'a [DescriptorSet],
        mut push: BftPush,
    ) -> Result<DrawCounts> {
        let frame = self
            .frame
            .as_ref()
            .ok_or(TessError::NoPatchArray { array: 0 })?;
        let instances = match frame.ids {
            None => &self.ids,
            Some(_) => &self.frame_ids,
        };
        enc.bind_vertex_buffer(1, instances);
        let mut counts = DrawCounts::default();
        let mut bound = None;
        for d in &frame.draws {
            if bound != Some(d.chunk) {
                let (Some((_, w)), Some(set)) = (chunks.get(d.chunk), sets.get(d.chunk)) else {
                    return Err(TessError::NoPatchArray { array: 0 });
                };
                if d.chunk > 0 {
                    enc.bind_descriptor_sets(1, &[set])?;
                }
                w.apply(&mut push);
                bound = Some(d.chunk);
            }
            let p = self
                .patterns
                .get(&d.key)
                .ok_or(TessError::NoPatchArray { array: 0 })?;
            enc.bind_vertex_buffer(0, &p.points);
            enc.bind_index_buffer_u32(&p.indices);
            push.pattern_outer = d.key.outer();
            enc.push_constants(&push)?;
            let indices = 3 * p.pattern.triangles.len() as u32;
            enc.draw_indexed_instanced(0..indices, d.instances.clone())?;
            counts += DrawCounts {
                draws: 1,
                patches: d.instances.len() as u32,
            };
        }
        Ok(counts)
    }

    /// Triangles the frame draws, once prepared.
    pub fn triangles(&self) -> Option<u64> {
        self.frame.as_ref()?.draws.iter().try_fold(0u64, |sum, d| {
            let p = self.patterns.get(&d.key)?;
            Some(sum + d.instances.len() as u64 * p.pattern.triangles.len() as u64)
        })
    }

    /// The most pattern vertices a face has in the frame.
    pub fn max_vertices(&self) -> u64 {
        self.patterns.max_points()
    }

    /// The instances and the frame's patterns.
    pub fn buffers(&self) -> impl Iterator<Item = &Buffer> {
        [&self.ids, &self.frame_ids]
            .into_iter()
            .chain(self.patterns.buffers())
    }
}
