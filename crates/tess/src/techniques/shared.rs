//! What the techniques with storage-buffer sets and adaptive factors (BFT, adaptive) share:
//! the stages their sets are visible to, static storage buffers, and the factor-policy fields
//! and checks of their push constants.
use crate::error::{Param, ParamError, Result, TessError};
use crate::gpu::bindings::{BFT_FACTORS_DISTANCE, BFT_FACTORS_SCREEN, BFT_FACTORS_UNIFORM};
use crate::shaders::{self, Stage, Variant};
use crate::technique::{FactorPolicy, FrameParams, TechniqueId};
use vk_core::descriptor::BindingDesc;
use vk_core::pipeline::{Pipeline, ShaderStage};
use vk_core::{vk, Buffer, Device};

/// A coordinate as the GPU receives it: f32, with a zero always `+0.0`. A shared edge's points
/// are sums of products of its corners; a sum is `−0.0` only when every term is, so a `−0.0`
/// corner coordinate (`v -0 1 0` in an OBJ, or an f64 too small for f32) makes the edge's point
/// `−0.0` or `+0.0` depending on the third corner, i.e. on the side it is evaluated from: equal
/// values, different bits, a crack for the weld by bits. No `−0.0` in, none on an edge out.
pub fn gpu_coordinate(c: f64) -> f32 {
    canonical_zero(c as f32)
}

/// `x` with `−0.0` replaced by `+0.0` ([`gpu_coordinate`]).
pub fn canonical_zero(x: f32) -> f32 {
    if x == 0.0 {
        0.0
    } else {
        x
    }
}

/// Every stage a technique's set 1 is read from (the compute pre-pass and the draw).
pub const STAGES: vk::ShaderStageFlags = vk::ShaderStageFlags::from_raw(
    vk::ShaderStageFlags::COMPUTE.as_raw()
        | vk::ShaderStageFlags::VERTEX.as_raw()
        | vk::ShaderStageFlags::TESSELLATION_CONTROL.as_raw()
        | vk::ShaderStageFlags::TESSELLATION_EVALUATION.as_raw()
        | vk::ShaderStageFlags::FRAGMENT.as_raw(),
);

/// A storage buffer at `binding`, visible to [`STAGES`].
pub const fn storage_binding(binding: u32) -> BindingDesc {
    BindingDesc {
        binding,
        ty: vk::DescriptorType::STORAGE_BUFFER,
        stages: STAGES,
    }
}

/// A GPU-only storage buffer holding `bytes`; an empty array is padded to one word
/// (zero-length buffers are invalid).
pub fn storage(device: &Device, name: &str, bytes: &[u8]) -> Result<Buffer> {
    let pad = [0u8; 4];
    let data = if bytes.is_empty() { &pad[..] } else { bytes };
    Ok(Buffer::with_data(
        device,
        name,
        vk::BufferUsageFlags::STORAGE_BUFFER,
        data,
    )?)
}

/// The compute pipeline `name` of `stage` (its one build) over the set `layouts`, with
/// `push_bytes` of push constants.
pub fn compute_pipeline(
    device: &Device,
    name: &str,
    stage: Stage,
    layouts: &[vk::DescriptorSetLayout],
    push_bytes: usize,
) -> Result<Pipeline> {
    Ok(Pipeline::compute(
        device,
        name,
        ShaderStage::new(
            vk::ShaderStageFlags::COMPUTE,
            shaders::spirv(stage, Variant::default())?,
        ),
        layouts,
        push_bytes as u32,
    )?)
}

/// The push-constant fields of a factor policy: (`BFT_FACTORS_*` mode, uniform segments,
/// pixels per segment, reference distance), the segments as the policy gives them.
pub fn factor_fields(factors: FactorPolicy) -> (u32, f32, f32, f32) {
    match factors {
        FactorPolicy::Uniform { segments } => (BFT_FACTORS_UNIFORM, segments, 0.0, 0.0),
        FactorPolicy::Screen { pixels } => (BFT_FACTORS_SCREEN, 0.0, pixels.max(0.01), 0.0),
        FactorPolicy::Distance { reference } => {
            (BFT_FACTORS_DISTANCE, 0.0, 0.0, reference.max(1e-6))
        }
    }
}

/// The screen and distance policies' own ranges (techniques check their uniform levels).
pub fn check_adaptive_policy(params: &FrameParams) -> Result<()> {
    match params.factors {
        FactorPolicy::Screen { pixels } if !(pixels.is_finite() && pixels >= 0.5) => {
            Err(ParamError::refused(
                Param::Pixels,
                pixels,
                "expected at least 0.5 pixels per segment",
            ))
        }
        FactorPolicy::Distance { reference } if !(reference.is_finite() && reference > 0.0) => Err(
            ParamError::refused(Param::Distance, reference, "expected a positive distance"),
        ),
        _ => Ok(()),
    }
}

/// Uploads an animated base into frame slot `slot` of `buffers`, the base-position buffers of a
/// technique that refines from them on the GPU (the stencil evaluator's `vec4` vertices):
/// checks the count against `expected`, every coordinate finite and the slot, writes them with
/// negative zeros made positive (both sides of a shared edge start from the same bits), and
/// returns what was written.
pub fn upload_base(
    buffers: &mut [Buffer],
    slot: usize,
    positions: &[[f32; 3]],
    expected: usize,
) -> Result<Vec<[f32; 3]>> {
    if positions.len() != expected {
        return Err(TessError::BasePositionCount {
            given: positions.len(),
            expected,
        });
    }
    if let Some(v) = positions
        .iter()
        .position(|p| p.iter().any(|c| !c.is_finite()))
    {
        return Err(TessError::NonFiniteVertex { vertex: v });
    }
    let slots = buffers.len();
    let buf = buffers
        .get_mut(slot)
        .ok_or(TessError::FrameSlot { slot, slots })?;
    let positions: Vec<[f32; 3]> = positions.iter().map(|p| p.map(canonical_zero)).collect();
    buf.write(
        0,
        bytemuck::cast_slice(&crate::stencil::vertices(&positions)),
    )?;
    Ok(positions)
}

/// Deepest level a frame may ask for: 2^6 = 64 segments per base edge, the tessellator's
/// maximum, as for the other vertex-stage techniques.
pub const MAX_DOO_SABIN_DEPTH: u32 = 6;

/// The depth a frame of `params` draws (uniform segments S = 2^D), or why it cannot (refused
/// for `technique`).
pub fn depth_of(technique: TechniqueId, params: &FrameParams) -> Result<u32> {
    let segments = match params.factors {
        FactorPolicy::Uniform { segments } => segments,
        _ => {
            return Err(TessError::Unsupported {
                technique,
                what: "adaptive factors (a uniform refinement has one level)",
            })
        }
    };
    let ok = segments.fract() == 0.0
        && (2.0..=(1u32 << MAX_DOO_SABIN_DEPTH) as f32).contains(&segments)
        && (segments as u32).is_power_of_two();
    if !ok {
        return Err(ParamError::refused(
            Param::Segments,
            segments,
            format!(
                "Doo-Sabin refines to a level: a power of two in 2..={} segments per base edge \
                 (each level halves every edge)",
                1 << MAX_DOO_SABIN_DEPTH
            ),
        ));
    }
    Ok((segments as u32).trailing_zeros())
}

/// The refinement-vertex budget of a Doo-Sabin uniform refinement (`doo-sabin`,
/// `vertex-patches`): the depth `params` draws, refused by name when the base and every refined
/// level together exceed `max` vertices.
pub fn check_doo_sabin_budget(
    technique: TechniqueId,
    base_vertices: usize,
    first: topology::refine::doo_sabin::LevelSize,
    max: u64,
    params: &FrameParams,
) -> Result<u32> {
    let depth = depth_of(technique, params)?;
    let sizes = topology::refine::doo_sabin::level_sizes(first, depth);
    let vertices = base_vertices as u64 + sizes.iter().map(|s| s.vertices).sum::<u64>();
    if vertices > max {
        return Err(TessError::RefinedTooLarge {
            scheme: topology::Scheme::DooSabin,
            level: depth as usize,
            vertices,
            max,
        });
    }
    Ok(depth)
}

/// Triangles of array 0 of a Doo-Sabin uniform refinement at the depth `params` draws.
pub fn doo_sabin_triangles(
    technique: TechniqueId,
    first: topology::refine::doo_sabin::LevelSize,
    params: &FrameParams,
    array: usize,
) -> Option<u64> {
    (array == 0).then_some(())?;
    let depth = depth_of(technique, params).ok()?;
    topology::refine::doo_sabin::level_sizes(first, depth)
        .last()
        .map(|s| s.triangles())
}
