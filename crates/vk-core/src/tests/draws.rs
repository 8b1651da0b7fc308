//! Instanced and indirect draws: they render as direct draws do, and the encoder checks the
//! instance ranges and the extents indirect commands promise as it checks direct ranges.
use super::{problem, spirv, triangle, Fixture, Gpu};
use crate::error::{RecordingError, VkError};
use crate::indirect::{
    DrawCommand, DrawIndexedCommand, IndirectDraws, IndirectExtent, IndirectKind,
};
use crate::pipeline::{GraphicsPipelineDesc, Pipeline, ShaderStage};
use crate::target::{OffscreenTarget, Rgba8, COLOR_FORMAT, DEPTH_FORMAT};
use crate::Device;
use ash::vk;

const EXTENT: vk::Extent2D = vk::Extent2D {
    width: 32,
    height: 32,
};

fn centre(image: &Rgba8) -> &[u8] {
    let c = ((16 * 32 + 16) * 4) as usize;
    &image.pixels[c..c + 4]
}

/// The fixture's triangle pipeline with its position read per instance (binding 0, input
/// rate INSTANCE): each instance is one point repeated, which is enough to check the ranges.
fn per_instance_pipeline(device: &Device, f: &Fixture) -> Pipeline {
    let mut desc = GraphicsPipelineDesc::new("per-instance test", COLOR_FORMAT, DEPTH_FORMAT);
    desc.stages = vec![
        ShaderStage::new(vk::ShaderStageFlags::VERTEX, spirv::VERT),
        ShaderStage::new(vk::ShaderStageFlags::FRAGMENT, spirv::FRAG),
    ];
    desc.vertex_bindings = vec![vk::VertexInputBindingDescription {
        binding: 0,
        stride: 12,
        input_rate: vk::VertexInputRate::INSTANCE,
    }];
    desc.vertex_attributes = vec![vk::VertexInputAttributeDescription {
        location: 0,
        binding: 0,
        format: vk::Format::R32G32B32_SFLOAT,
        offset: 0,
    }];
    desc.set_layouts = vec![f.layout.raw];
    desc.push_constant_bytes = 16;
    desc.depth_test = false;
    Pipeline::graphics(device, &desc).unwrap()
}

/// How [`render`] draws the fixture's triangle.
enum Draw<'d> {
    IndexedInstanced,
    Instanced,
    Indirect(&'d IndirectDraws),
}

/// Renders the fixture's triangle with one draw of kind `draw`.
fn render(device: &Device, f: &Fixture, draw: Draw<'_>) -> Rgba8 {
    let storage = Fixture::storage(device);
    let set = f.set_with(&storage);
    let (vb, ib) = triangle(device);
    let target = OffscreenTarget::new(device, EXTENT).unwrap();
    let readback = target.readback_buffer(device).unwrap();
    device
        .submit_once(|enc| -> crate::Result<()> {
            enc.begin_offscreen(&target, [0.0, 0.0, 0.0, 1.0]);
            enc.bind_pipeline(&f.graphics);
            enc.bind_descriptor_sets(0, &[&set])?;
            enc.bind_vertex_buffer(0, &vb);
            enc.bind_index_buffer_u32(&ib);
            match draw {
                Draw::IndexedInstanced => enc.draw_indexed_instanced(0..3, 0..2)?,
                Draw::Instanced => enc.draw_instanced(0..3, 0..1)?,
                Draw::Indirect(commands) => enc.draw_indirect(commands)?,
            }
            enc.end_offscreen_and_copy(&target, &readback);
            Ok(())
        })
        .unwrap()
        .unwrap();
    target.read(&readback).unwrap()
}

#[test]
fn instanced_and_indirect_draws_render_like_direct_ones() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let f = Fixture::new(device);
    let indexed = IndirectDraws::host(
        device,
        "indexed commands",
        &[DrawIndexedCommand {
            index_count: 3,
            instance_count: 1,
            ..Default::default()
        }],
    )
    .unwrap();
    let plain = IndirectDraws::host(
        device,
        "commands",
        &[DrawCommand {
            vertex_count: 3,
            instance_count: 1,
            ..Default::default()
        }],
    )
    .unwrap();
    assert_eq!(
        indexed.extent(),
        IndirectExtent {
            vertices: 0,
            indices: 3,
            instances: 1
        }
    );
    assert_eq!(
        plain.extent(),
        IndirectExtent {
            vertices: 3,
            indices: 0,
            instances: 1
        }
    );
    let red = [255, 0, 0, 255];
    let images = [
        render(device, &f, Draw::IndexedInstanced),
        render(device, &f, Draw::Instanced),
        render(device, &f, Draw::Indirect(&indexed)),
        render(device, &f, Draw::Indirect(&plain)),
    ];
    for (i, image) in images.iter().enumerate() {
        assert_eq!(centre(image), red, "draw {i} covers the centre");
        assert_eq!(
            &image.pixels[0..4],
            &[0, 0, 0, 255],
            "draw {i} keeps the corner"
        );
    }
}

#[test]
fn indirect_commands_are_refused_where_they_could_read_out_of_bounds() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let caps = device.info.caps;
    let refused = |e: VkError| matches!(e, VkError::IndirectCommand { .. });
    let offset = DrawIndexedCommand {
        index_count: 3,
        instance_count: 1,
        vertex_offset: 2,
        ..Default::default()
    };
    assert!(refused(
        IndirectDraws::host(device, "offset", &[offset])
            .err()
            .unwrap()
    ));
    let overflow = DrawCommand {
        vertex_count: u32::MAX,
        instance_count: 1,
        first_vertex: 1,
        first_instance: 0,
    };
    assert!(refused(
        IndirectDraws::host(device, "overflow", &[overflow])
            .err()
            .unwrap()
    ));
    let one = DrawCommand {
        vertex_count: 3,
        instance_count: 1,
        ..Default::default()
    };
    let two = IndirectDraws::host(device, "two draws", &[one, one]);
    assert_eq!(
        two.is_ok(),
        caps.multi_draw_indirect,
        "two draws per command"
    );
    let later = DrawCommand {
        first_instance: 1,
        ..one
    };
    let later = IndirectDraws::host(device, "first instance 1", &[later]);
    assert_eq!(later.is_ok(), caps.draw_indirect_first_instance);
    // Rewriting checks the command kind and count.
    let mut draws = IndirectDraws::host(device, "rewritten", &[one]).unwrap();
    assert!(refused(draws.write(&[one, one]).unwrap_err()));
    let indexed = DrawIndexedCommand {
        index_count: 3,
        instance_count: 1,
        ..Default::default()
    };
    assert!(refused(draws.write(&[indexed]).unwrap_err()));
    draws
        .write(&[DrawCommand {
            vertex_count: 6,
            ..one
        }])
        .unwrap();
    assert_eq!(draws.extent().vertices, 6);
}

#[test]
fn instanced_and_indirect_ranges_are_checked_against_bound_buffers() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let f = Fixture::new(device);
    let storage = Fixture::storage(device);
    let set = f.set_with(&storage);
    let (vb, ib) = triangle(device);
    let per_instance = per_instance_pipeline(device, &f);
    let four_vertices = IndirectDraws::host(
        device,
        "four vertices",
        &[DrawCommand {
            vertex_count: 4,
            instance_count: 1,
            ..Default::default()
        }],
    )
    .unwrap();
    let four_indices = IndirectDraws::host(
        device,
        "four indices",
        &[DrawIndexedCommand {
            index_count: 4,
            instance_count: 1,
            ..Default::default()
        }],
    )
    .unwrap();
    // Written by a shader, bounded by its declaration: four instances of a three-point buffer.
    let gpu_written = IndirectDraws::gpu_written(
        device,
        "gpu-written",
        IndirectKind::Draw,
        1,
        IndirectExtent {
            vertices: 3,
            indices: 0,
            instances: 4,
        },
    )
    .unwrap();
    let target = OffscreenTarget::new(device, EXTENT).unwrap();
    let readback = target.readback_buffer(device).unwrap();
    let errors = device
        .submit_once(|enc| {
            let mut seen = Vec::new();
            enc.begin_offscreen(&target, [0.0; 4]);
            enc.bind_pipeline(&f.graphics);
            enc.bind_descriptor_sets(0, &[&set]).unwrap();
            seen.push(enc.draw_indirect(&four_vertices).unwrap_err());
            enc.bind_vertex_buffer(0, &vb);
            seen.push(enc.draw_indirect(&four_vertices).unwrap_err());
            seen.push(enc.draw_indirect(&four_indices).unwrap_err());
            enc.bind_index_buffer_u32(&ib);
            seen.push(enc.draw_indirect(&four_indices).unwrap_err());
            enc.bind_pipeline(&per_instance);
            enc.bind_descriptor_sets(0, &[&set]).unwrap();
            enc.bind_vertex_buffer(0, &vb);
            seen.push(enc.draw_instanced(0..3, 0..4).unwrap_err());
            seen.push(enc.draw_indexed_instanced(0..3, 2..4).unwrap_err());
            seen.push(enc.draw_indirect(&gpu_written).unwrap_err());
            enc.draw_instanced(0..3, 0..3).unwrap();
            enc.end_offscreen_and_copy(&target, &readback);
            seen
        })
        .unwrap();
    let problems: Vec<RecordingError> = errors.into_iter().map(problem).collect();
    assert!(matches!(
        problems[0],
        RecordingError::VertexBufferMissing { .. }
    ));
    assert!(matches!(
        problems[1],
        RecordingError::VertexRange { end: 4, .. }
    ));
    assert!(matches!(problems[2], RecordingError::NoIndexBuffer));
    assert!(matches!(
        problems[3],
        RecordingError::IndexRange {
            end: 4,
            count: 3,
            ..
        }
    ));
    for p in &problems[4..7] {
        assert!(
            matches!(p, RecordingError::InstanceRange { end: 4, .. }),
            "{p}"
        );
    }
}
