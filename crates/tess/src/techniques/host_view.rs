//! What a technique on the refinement-pattern path reads of a frame to choose its patches'
//! levels on the host, where no control stage chooses them: the view, the factor policy's
//! field and the largest level; and the morph weights of geomorphing between power-of-two
//! levels, which the pattern instances carry. The planned surfaces measure canonical curves
//! with it (`planned_patches::patterns`), BFT its level-1 edges (`bft::patterns`).
use crate::gpu::bindings::{BFT_FACTORS_DISTANCE, BFT_FACTORS_SCREEN, BFT_FACTORS_UNIFORM};
use crate::gpu::FrameUniforms;
use crate::technique::FactorPolicy;

/// The frame as the host's level choice sees it.
pub struct HostView {
    pub view_proj: glam::Mat4,
    pub viewport: [f32; 2],
    pub eye: glam::Vec3,
    /// `BFT_FACTORS_SCREEN`, `BFT_FACTORS_DISTANCE` or `BFT_FACTORS_UNIFORM`.
    pub mode: u32,
    /// The policy's field: the uniform level, pixels per segment or reference distance.
    pub field: f32,
    pub max_level: f32,
    /// Geomorphing: each edge gets the weight of its level ([`morph_weight`]).
    pub morph: bool,
}

/// A patch's morph weights as the instance carries them: three unorm16 pairs (edges and the
/// inside, in the order each technique's vertex stage documents); all 1 (no morph) without
/// geomorphing.
pub type MorphWords = [u32; 3];

/// Morph weights of 1 everywhere: each vertex where its pattern puts it.
pub const NO_MORPH: MorphWords = [u32::MAX; 3];

/// The weight of a level-`level` edge whose continuous factor is `g`: 0 where `g` is half the
/// level (the odd vertices lie on the coarser level's), 1 at the level itself.
pub fn morph_weight(g: f32, level: f32) -> f32 {
    if level <= 1.0 {
        return 1.0;
    }
    ((g - 0.5 * level) / (0.5 * level)).clamp(0.0, 1.0)
}

/// Two weights in `0..=1` as one unorm16 pair (`unpackUnorm2x16`), `a` in the low half.
pub fn unorm16_pair(a: f32, b: f32) -> u32 {
    let q = |x: f32| (x.clamp(0.0, 1.0) * 65535.0).round() as u32;
    q(a) | (q(b) << 16)
}

/// The power of two at or above `f` (`exp2(ceil(log2(f) - 1e-4))`, as the control stages round
/// equal-spacing factors).
pub fn pow2_level(f: f32) -> f32 {
    (f.log2() - 1e-4).ceil().exp2()
}

impl HostView {
    /// The view of `view` under `factors` (`uniform_level`: the level uniform factors ask for,
    /// in the technique's own units), levels up to `max_level`.
    pub fn new(
        view: &FrameUniforms,
        factors: FactorPolicy,
        uniform_level: f32,
        max_level: f32,
        morph: bool,
    ) -> Self {
        let (mode, field) = match factors {
            FactorPolicy::Uniform { .. } => (BFT_FACTORS_UNIFORM, uniform_level),
            FactorPolicy::Screen { pixels } => (BFT_FACTORS_SCREEN, pixels),
            FactorPolicy::Distance { reference } => (BFT_FACTORS_DISTANCE, reference),
        };
        Self {
            view_proj: glam::Mat4::from_cols_array_2d(&view.view_proj),
            viewport: [view.viewport[0], view.viewport[1]],
            eye: glam::Vec3::new(view.camera_pos[0], view.camera_pos[1], view.camera_pos[2]),
            mode,
            field,
            max_level,
            morph,
        }
    }

    /// `p` in pixels from the viewport's centre, or `None` on or behind the eye plane.
    pub fn screen(&self, p: glam::Vec3) -> Option<glam::Vec2> {
        let c = self.view_proj * p.extend(1.0);
        (c.w > 1e-6)
            .then(|| glam::Vec2::new(c.x, c.y) / c.w * glam::Vec2::from(self.viewport) * 0.5)
    }

    /// The weight of `level` at continuous factor `g` when geomorphing, else 1.
    pub fn weight(&self, g: f32, level: f32) -> f32 {
        match self.morph {
            true => morph_weight(g, level),
            false => 1.0,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// The morph weight runs from 0 at half the level to 1 at the level; a level-1 edge has
    /// nothing to morph; the weights travel as unorm16, 1 exactly as 65535.
    #[test]
    fn morph_weights_span_a_doubling() {
        assert_eq!(morph_weight(4.0, 8.0), 0.0);
        assert_eq!(morph_weight(6.0, 8.0), 0.5);
        assert_eq!(morph_weight(8.0, 8.0), 1.0);
        assert_eq!(morph_weight(1.0, 1.0), 1.0);
        assert_eq!(morph_weight(3.9, 8.0), 0.0);
        assert_eq!(unorm16_pair(1.0, 0.0), 0xFFFF);
        assert_eq!(unorm16_pair(0.0, 1.0), 0xFFFF_0000);
        assert_eq!(NO_MORPH, [unorm16_pair(1.0, 1.0); 3]);
    }

    /// Powers of two round up, a power of two stays itself (also just past it, within the
    /// control stages' 1e-4 in log2).
    #[test]
    fn levels_round_up_to_powers_of_two() {
        assert_eq!(pow2_level(1.0), 1.0);
        assert_eq!(pow2_level(4.0), 4.0);
        assert_eq!(pow2_level(4.0001), 4.0);
        assert_eq!(pow2_level(4.1), 8.0);
        assert_eq!(pow2_level(2.65), 4.0);
    }
}
