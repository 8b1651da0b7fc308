//! Textures: upload and mip chain validation-clean, level 0 read back exactly, the last level
//! the average; refused sizes are typed errors; a set written with a texture samples it in a
//! shader and keeps it alive.
use super::{problem, spirv, Gpu};
use crate::descriptor::{BindingDesc, DescriptorPool, DescriptorSetLayout};
use crate::error::{DescriptorError, RecordingError, VkError};
use crate::pipeline::{Pipeline, ShaderStage};
use crate::{Buffer, BufferDesc, Device, Texture, TextureDesc, TextureFormat};
use ash::vk;
use gpu_allocator::MemoryLocation;

const W: u32 = 5;
const H: u32 = 3;

/// A 5×3 RGBA8 gradient, linear in x and y, so any symmetric downsampling (a linear blit
/// samples 2 of 5 columns) keeps the average: (90, 80, 55, 255).
fn gradient() -> Vec<u8> {
    let mut texels = Vec::new();
    for y in 0..H {
        for x in 0..W {
            texels.extend_from_slice(&[
                (40 * x + 10) as u8,
                (60 * y + 20) as u8,
                (10 * x + 30 * y + 5) as u8,
                255,
            ]);
        }
    }
    texels
}

const AVERAGE: [u8; 4] = [90, 80, 55, 255];

fn desc(name: &str, format: TextureFormat, mipmaps: bool) -> TextureDesc<'_> {
    TextureDesc {
        name,
        width: W,
        height: H,
        format,
        mipmaps,
        repeat: false,
    }
}

/// `level` of `texture`, tightly packed, through a host-visible buffer.
fn read_level(device: &Device, texture: &Texture, level: u32) -> crate::Result<Vec<u8>> {
    let extent = texture.level_extent(level);
    let bytes = (extent.width * extent.height * texture.format().bytes_per_texel()) as usize;
    let readback = Buffer::new(
        device,
        &BufferDesc {
            name: "test texture readback",
            size: bytes as u64,
            usage: vk::BufferUsageFlags::TRANSFER_DST,
            location: MemoryLocation::GpuToCpu,
        },
    )?;
    device.submit_once(|enc| enc.read_texture_level(texture, level, &readback))??;
    let mut out = readback.read::<u8>()?;
    out.truncate(bytes);
    Ok(out)
}

#[test]
fn rgba8_texture_uploads_with_mip_chain() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let texels = gradient();
    let texture = Texture::new(
        device,
        &desc("test gradient", TextureFormat::Rgba8Unorm, true),
        &texels,
    )
    .unwrap();
    assert!(gpu.errors().is_empty(), "{:#?}", gpu.errors());
    assert_eq!(texture.levels(), 3, "5×3, 2×1, 1×1");
    assert_eq!(texture.filter(), vk::Filter::LINEAR);
    assert_eq!(
        texture.extent(),
        vk::Extent2D {
            width: W,
            height: H
        }
    );
    assert_eq!(texture.format(), TextureFormat::Rgba8Unorm);
    assert_eq!(read_level(device, &texture, 0).unwrap(), texels);
    let last = read_level(device, &texture, 2).unwrap();
    for (got, want) in last.iter().zip(AVERAGE) {
        assert!(
            got.abs_diff(want) <= 3,
            "1×1 level {last:?}, average {AVERAGE:?}"
        );
    }
    // Reading back returned the levels to their resting layout: reading again works.
    assert_eq!(read_level(device, &texture, 0).unwrap(), texels);
    assert!(gpu.errors().is_empty(), "{:#?}", gpu.errors());
}

#[test]
fn r32_float_texture_round_trips_bit_exactly() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let values: Vec<f32> = (0..W * H)
        .map(|i| i as f32 * 0.37 - 2.0)
        .chain([f32::MAX, -0.0, f32::MIN_POSITIVE / 4.0])
        .skip(3)
        .collect();
    assert_eq!(values.len(), (W * H) as usize);
    let texture = Texture::new(
        device,
        &desc("test height map", TextureFormat::R32Float, true),
        bytemuck::cast_slice(&values),
    )
    .unwrap();
    // A device that cannot filter floats linearly gets one level and NEAREST sampling.
    if texture.filter() == vk::Filter::NEAREST {
        assert_eq!(texture.levels(), 1);
    }
    let back = read_level(device, &texture, 0).unwrap();
    let bits = |v: &[f32]| v.iter().map(|f| f.to_bits()).collect::<Vec<_>>();
    assert_eq!(bits(bytemuck::cast_slice::<u8, f32>(&back)), bits(&values));
}

#[test]
fn refused_textures_are_typed_errors() {
    let gpu = Gpu::new();
    let device = gpu.device();
    device.submit_once(|_| ()).unwrap();
    let start = device.live_objects();
    let e = Texture::new(
        device,
        &desc("test short", TextureFormat::Rgba8Srgb, true),
        &[0; 59],
    )
    .err()
    .unwrap();
    assert!(
        matches!(
            e,
            VkError::PictureSize {
                width: W,
                height: H,
                bytes: 59
            }
        ),
        "{e}"
    );
    let mut empty = desc("test empty", TextureFormat::Rgba8Unorm, false);
    empty.width = 0;
    let e = Texture::new(device, &empty, &[]).err().unwrap();
    assert!(matches!(e, VkError::Extent { width: 0, .. }), "{e}");
    let max = device.info.caps.max_image_dimension_2d;
    let mut huge = desc("test huge", TextureFormat::Rgba8Unorm, false);
    huge.height = max + 1;
    let e = Texture::new(device, &huge, &[]).err().unwrap();
    assert!(
        matches!(e, VkError::Extent { max: m, .. } if m == max),
        "{e}"
    );
    assert_eq!(device.live_objects(), start, "refusals create nothing");

    // Without mipmaps: one level, no transfer-source usage, so no readback.
    let plain = Texture::new(
        device,
        &desc("test plain", TextureFormat::Rgba8Srgb, false),
        &gradient(),
    )
    .unwrap();
    assert_eq!(plain.levels(), 1);
    let e = read_level(device, &plain, 0).unwrap_err();
    assert!(matches!(problem(e), RecordingError::TextureUsage { .. }));
    let mipmapped = Texture::new(
        device,
        &desc("test mipmapped", TextureFormat::Rgba8Srgb, true),
        &gradient(),
    )
    .unwrap();
    let e = read_level(device, &mipmapped, 3).unwrap_err();
    assert!(matches!(
        problem(e),
        RecordingError::MipLevel {
            level: 3,
            levels: 3,
            ..
        }
    ));
    drop((plain, mipmapped));
    assert_eq!(device.live_objects(), start);
}

#[test]
fn descriptor_sets_sample_textures_and_keep_them_alive() {
    let gpu = Gpu::new();
    let device = gpu.device();
    device.submit_once(|_| ()).unwrap();
    let start = device.live_objects();
    let layout = DescriptorSetLayout::new(
        device,
        "test sampling layout",
        &[
            BindingDesc {
                binding: 0,
                ty: vk::DescriptorType::STORAGE_BUFFER,
                stages: vk::ShaderStageFlags::COMPUTE,
            },
            BindingDesc {
                binding: 1,
                ty: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
                stages: vk::ShaderStageFlags::COMPUTE,
            },
        ],
    )
    .unwrap();
    let pool = DescriptorPool::new(device, "test sampling pool", &layout, 1).unwrap();
    let pipeline = Pipeline::compute(
        device,
        "test sampling",
        ShaderStage::new(vk::ShaderStageFlags::COMPUTE, spirv::SAMPLE_COMP),
        &[layout.raw],
        0,
    )
    .unwrap();
    let out = Buffer::new(
        device,
        &BufferDesc {
            name: "test samples",
            size: 32,
            usage: vk::BufferUsageFlags::STORAGE_BUFFER,
            location: MemoryLocation::GpuToCpu,
        },
    )
    .unwrap();
    let set = pool.allocate_set(&layout).unwrap();
    let before_texture = device.live_objects();
    let texture = Texture::new(
        device,
        &desc("test sampled", TextureFormat::Rgba8Unorm, true),
        &gradient(),
    )
    .unwrap();
    let with_texture = device.live_objects();
    assert_eq!(with_texture, before_texture + 3, "image, view, sampler");

    let descriptor_problem = |e: VkError| match e {
        VkError::Descriptor { problem, .. } => problem,
        other => panic!("expected a descriptor error, got {other}"),
    };
    let e = set.write_texture(0, &texture).unwrap_err();
    assert_eq!(
        descriptor_problem(e),
        DescriptorError::Type {
            layout: vk::DescriptorType::STORAGE_BUFFER,
            given: vk::DescriptorType::COMBINED_IMAGE_SAMPLER,
        }
    );
    let e = set.write_texture(7, &texture).unwrap_err();
    assert_eq!(descriptor_problem(e), DescriptorError::NoSuchBinding);
    set.write_buffer(0, vk::DescriptorType::STORAGE_BUFFER, &out)
        .unwrap();
    // The texture binding was never written: the set cannot be bound.
    let e = device
        .submit_once(|enc| {
            enc.bind_pipeline(&pipeline);
            enc.bind_descriptor_sets(0, &[&set])
        })
        .unwrap()
        .unwrap_err();
    assert!(matches!(
        problem(e),
        RecordingError::SetIncomplete { binding: 1, .. }
    ));
    set.write_texture(1, &texture).unwrap();
    // A set bound in a recording not yet submitted cannot be updated.
    let in_use = device
        .submit_once(|enc| {
            enc.bind_pipeline(&pipeline);
            enc.bind_descriptor_sets(0, &[&set]).unwrap();
            set.write_texture(1, &texture)
        })
        .unwrap()
        .unwrap_err();
    assert_eq!(descriptor_problem(in_use), DescriptorError::InUse);

    drop(texture);
    assert_eq!(
        device.live_objects(),
        with_texture,
        "the set keeps it alive"
    );
    device
        .submit_once(|enc| -> crate::Result<()> {
            enc.bind_pipeline(&pipeline);
            enc.bind_descriptor_sets(0, &[&set])?;
            enc.dispatch([1, 1, 1])?;
            enc.memory_barrier(
                (
                    vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::AccessFlags::SHADER_WRITE,
                ),
                (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
            );
            Ok(())
        })
        .unwrap()
        .unwrap();
    let samples: Vec<f32> = out.read().unwrap();
    let texel = [10.0, 20.0, 5.0, 255.0];
    for (i, want) in texel.iter().enumerate() {
        assert!(
            (samples[i] * 255.0 - want).abs() < 1.5,
            "LOD 0 at texel (0, 0): {:?}",
            &samples[..4]
        );
    }
    for (i, want) in AVERAGE.iter().enumerate() {
        assert!(
            (samples[4 + i] * 255.0 - *want as f32).abs() < 3.5,
            "last level: {:?}",
            &samples[4..]
        );
    }
    assert!(gpu.errors().is_empty(), "{:#?}", gpu.errors());

    drop(set);
    assert_eq!(device.live_objects(), before_texture);
    drop((pipeline, pool, layout, out));
    assert_eq!(device.live_objects(), start);
}
