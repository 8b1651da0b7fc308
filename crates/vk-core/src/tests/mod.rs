//! GPU tests of the encoder, descriptor sets and deferred destruction, on whatever device the
//! loader offers (lavapipe in CI) with the validation layer on, synchronization validation
//! included. Every test fails on any
//! error-severity validation message and on memory still allocated at its end.
mod draws;
mod overlay;
mod pipeline_cache;
mod spirv;
mod subpass;
mod texture;

use crate::descriptor::{BindingDesc, DescriptorPool, DescriptorSet, DescriptorSetLayout};
use crate::error::{DescriptorError, RecordingError, VkError};
use crate::pipeline::{GraphicsPipelineDesc, Pipeline, ShaderStage};
use crate::query::QueryPool;
use crate::target::{OffscreenTarget, COLOR_FORMAT, DEPTH_FORMAT};
use crate::{Buffer, BufferDesc, Device, DeviceDesc, Instance, InstanceDesc, Validation};
use ash::vk;
use gpu_allocator::MemoryLocation;
use std::sync::Arc;

struct Gpu {
    device: Option<Device>,
    instance: Arc<Instance>,
}

impl Gpu {
    fn new() -> Gpu {
        let instance = Instance::new(&InstanceDesc {
            app_name: "vk-core-tests".into(),
            validation: Validation::Synchronization,
            surface_extensions: vec![],
        })
        .expect("Vulkan instance (install mesa-vulkan-drivers and vulkan-validationlayers)");
        assert_eq!(
            instance.validation(),
            Validation::Synchronization,
            "tests need VK_LAYER_KHRONOS_validation (package vulkan-validationlayers)"
        );
        let device = Device::new(&instance, &DeviceDesc::default(), &[]).expect("a device");
        Gpu {
            device: Some(device),
            instance,
        }
    }

    fn device(&self) -> &Device {
        self.device.as_ref().expect("device alive")
    }

    fn errors(&self) -> Vec<String> {
        self.instance.messages().error_messages()
    }
}

impl Drop for Gpu {
    fn drop(&mut self) {
        if let Some(d) = self.device.take() {
            let leaked = d.allocated_bytes();
            drop(d);
            if !std::thread::panicking() {
                assert_eq!(leaked, 0, "gpu-allocator still holds {leaked} bytes");
            }
        }
        if !std::thread::panicking() {
            assert_eq!(
                self.instance.messages().error_count(),
                0,
                "validation errors: {:#?}",
                self.errors()
            );
        }
    }
}

/// A storage-buffer set layout, a graphics pipeline drawing vec3 positions into the offscreen
/// formats (16 bytes of push constants) and a compute pipeline writing 7 into word 0 of set 0.
struct Fixture {
    layout: DescriptorSetLayout,
    pool: DescriptorPool,
    graphics: Pipeline,
    compute: Pipeline,
}

impl Fixture {
    fn new(device: &Device) -> Fixture {
        let layout = DescriptorSetLayout::new(
            device,
            "test layout",
            &[BindingDesc {
                binding: 0,
                ty: vk::DescriptorType::STORAGE_BUFFER,
                stages: vk::ShaderStageFlags::COMPUTE | vk::ShaderStageFlags::FRAGMENT,
            }],
        )
        .unwrap();
        let pool = DescriptorPool::new(device, "test pool", &layout, 4).unwrap();
        let mut desc = GraphicsPipelineDesc::new("test triangle", COLOR_FORMAT, DEPTH_FORMAT);
        desc.stages = vec![
            ShaderStage::new(vk::ShaderStageFlags::VERTEX, spirv::VERT),
            ShaderStage::new(vk::ShaderStageFlags::FRAGMENT, spirv::FRAG),
        ];
        desc.vertex_bindings = vec![vk::VertexInputBindingDescription {
            binding: 0,
            stride: 12,
            input_rate: vk::VertexInputRate::VERTEX,
        }];
        desc.vertex_attributes = vec![vk::VertexInputAttributeDescription {
            location: 0,
            binding: 0,
            format: vk::Format::R32G32B32_SFLOAT,
            offset: 0,
        }];
        desc.set_layouts = vec![layout.raw];
        desc.push_constant_bytes = 16;
        desc.depth_test = false;
        let graphics = Pipeline::graphics(device, &desc).unwrap();
        let compute = Pipeline::compute(
            device,
            "test compute",
            ShaderStage::new(vk::ShaderStageFlags::COMPUTE, spirv::COMP),
            &[layout.raw],
            0,
        )
        .unwrap();
        Fixture {
            layout,
            pool,
            graphics,
            compute,
        }
    }

    fn storage(device: &Device) -> Buffer {
        Buffer::new(
            device,
            &BufferDesc {
                name: "test storage",
                size: 16,
                usage: vk::BufferUsageFlags::STORAGE_BUFFER,
                location: MemoryLocation::GpuToCpu,
            },
        )
        .unwrap()
    }

    fn set_with(&self, buffer: &Buffer) -> DescriptorSet {
        let set = self.pool.allocate_set(&self.layout).unwrap();
        set.write_buffer(0, vk::DescriptorType::STORAGE_BUFFER, buffer)
            .unwrap();
        set
    }
}

/// A triangle covering the centre of the target, and its indices.
fn triangle(device: &Device) -> (Buffer, Buffer) {
    let positions: [f32; 9] = [-0.9, -0.9, 0.5, 0.9, -0.9, 0.5, 0.0, 0.9, 0.5];
    let vb = Buffer::with_data(
        device,
        "test vertices",
        vk::BufferUsageFlags::VERTEX_BUFFER,
        bytemuck::cast_slice(&positions),
    )
    .unwrap();
    let ib = Buffer::with_data(
        device,
        "test indices",
        vk::BufferUsageFlags::INDEX_BUFFER,
        bytemuck::cast_slice(&[0u32, 1, 2]),
    )
    .unwrap();
    (vb, ib)
}

fn problem(e: VkError) -> RecordingError {
    match e {
        VkError::Recording { problem, .. } => problem,
        other => panic!("expected a recording error, got {other}"),
    }
}

/// A one-shot submission leaves its command pool cached for the next (counted live); releasing
/// the idle pools brings the count back to what callers hold, and a later submission works.
#[test]
fn idle_one_shot_pools_are_released_on_request() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let start = device.live_objects();
    device.submit_once(|_| ()).unwrap();
    device.wait_idle();
    assert_eq!(device.live_objects(), start + 1, "the idle pool is cached");
    device.release_idle_command_pools();
    assert_eq!(device.live_objects(), start);
    device.submit_once(|_| ()).unwrap();
    device.wait_idle();
    device.release_idle_command_pools();
    assert_eq!(device.live_objects(), start);
    assert!(gpu.errors().is_empty(), "{:?}", gpu.errors());
}

#[test]
fn encoder_renders_and_dispatches() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let f = Fixture::new(device);
    let storage = Fixture::storage(device);
    let set = f.set_with(&storage);
    let (vb, ib) = triangle(device);
    let extent = vk::Extent2D {
        width: 32,
        height: 32,
    };
    let target = OffscreenTarget::new(device, extent).unwrap();
    let readback = target.readback_buffer(device).unwrap();
    device
        .submit_once(|enc| -> crate::Result<()> {
            enc.begin_label("test frame");
            enc.bind_pipeline(&f.compute);
            enc.bind_descriptor_sets(0, &[&set])?;
            enc.dispatch([1, 1, 1])?;
            enc.memory_barrier(
                (
                    vk::PipelineStageFlags::COMPUTE_SHADER,
                    vk::AccessFlags::SHADER_WRITE,
                ),
                (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
            );
            enc.begin_offscreen(&target, [0.0, 0.0, 0.0, 1.0]);
            enc.bind_pipeline(&f.graphics);
            enc.bind_descriptor_sets(0, &[&set])?;
            enc.push_constants(&[1u32, 2, 3, 4])?;
            enc.bind_vertex_buffer(0, &vb);
            enc.bind_index_buffer_u32(&ib);
            enc.draw_indexed(0..3)?;
            enc.end_offscreen_and_copy(&target, &readback);
            enc.end_label();
            Ok(())
        })
        .unwrap()
        .unwrap();
    assert_eq!(storage.read::<u32>().unwrap()[0], 7);
    let image = target.read(&readback).unwrap();
    let centre = ((16 * 32 + 16) * 4) as usize;
    assert_eq!(&image.pixels[centre..centre + 4], &[255, 0, 0, 255]);
    assert_eq!(
        &image.pixels[0..4],
        &[0, 0, 0, 255],
        "corner keeps the clear"
    );
}

#[test]
fn encoder_refuses_commands_vulkan_forbids() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let f = Fixture::new(device);
    let storage = Fixture::storage(device);
    let set = f.set_with(&storage);
    let (vb, ib) = triangle(device);
    let target = OffscreenTarget::new(
        device,
        vk::Extent2D {
            width: 8,
            height: 8,
        },
    )
    .unwrap();
    let readback = target.readback_buffer(device).unwrap();
    let errors = device
        .submit_once(|enc| {
            let mut seen = Vec::new();
            seen.push(enc.draw(0..3).unwrap_err());
            seen.push(enc.push_constants(&[0u32; 4]).unwrap_err());
            enc.bind_pipeline(&f.graphics);
            seen.push(enc.push_constants(&[0u32; 8]).unwrap_err());
            seen.push(enc.draw(0..3).unwrap_err());
            enc.begin_offscreen(&target, [0.0; 4]);
            seen.push(enc.draw(0..3).unwrap_err());
            enc.bind_descriptor_sets(0, &[&set]).unwrap();
            seen.push(enc.bind_descriptor_sets(1, &[&set]).unwrap_err());
            seen.push(enc.draw_indexed(0..3).unwrap_err());
            enc.bind_vertex_buffer(0, &vb);
            enc.bind_index_buffer_u32(&ib);
            seen.push(enc.draw_indexed(0..4).unwrap_err());
            seen.push(enc.draw(0..4).unwrap_err());
            seen.push(enc.dispatch([1, 1, 1]).unwrap_err());
            enc.draw_indexed(0..3).unwrap();
            enc.end_offscreen_and_copy(&target, &readback);
            seen
        })
        .unwrap();
    let problems: Vec<RecordingError> = errors.into_iter().map(problem).collect();
    assert!(matches!(problems[0], RecordingError::NoPipeline));
    assert!(matches!(problems[1], RecordingError::NoPipeline));
    assert!(matches!(
        problems[2],
        RecordingError::PushConstantsTooLarge {
            bytes: 32,
            range: 16,
            ..
        }
    ));
    assert!(matches!(problems[3], RecordingError::OutsideRendering));
    assert!(matches!(
        problems[4],
        RecordingError::SetMissing { index: 0, .. }
    ));
    assert!(matches!(
        problems[5],
        RecordingError::SetIndex { first: 1, .. }
    ));
    assert!(matches!(
        problems[6],
        RecordingError::VertexBufferMissing { .. }
    ));
    assert!(matches!(
        problems[7],
        RecordingError::IndexRange {
            first: 0,
            end: 4,
            count: 3,
            ..
        }
    ));
    assert!(matches!(
        problems[8],
        RecordingError::VertexRange { end: 4, .. }
    ));
    assert!(matches!(problems[9], RecordingError::BindPoint { .. }));
}

#[test]
fn invalid_recordings_are_not_submitted() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let target = OffscreenTarget::new(
        device,
        vk::Extent2D {
            width: 8,
            height: 8,
        },
    )
    .unwrap();
    // A barrier inside a rendering scope cannot be refused at once (it returns nothing): the
    // submission returns it instead of submitting.
    let e = device
        .submit_once(|enc| {
            enc.begin_offscreen(&target, [0.0; 4]);
            enc.memory_barrier(
                (
                    vk::PipelineStageFlags::ALL_COMMANDS,
                    vk::AccessFlags::MEMORY_WRITE,
                ),
                (
                    vk::PipelineStageFlags::ALL_COMMANDS,
                    vk::AccessFlags::MEMORY_READ,
                ),
            );
            enc.end_rendering();
        })
        .unwrap_err();
    assert!(matches!(problem(e), RecordingError::InsideRendering));
    let e = device
        .submit_once(|enc| enc.begin_offscreen(&target, [0.0; 4]))
        .unwrap_err();
    assert!(matches!(problem(e), RecordingError::Unclosed { .. }));
    let e = device.submit_once(|enc| enc.end_label()).unwrap_err();
    assert!(matches!(problem(e), RecordingError::NoLabel));
    // Exchanging the encoders of two recordings abandons both.
    let inner = device
        .submit_once(|outer| device.submit_once(|inner| std::mem::swap(outer, inner)))
        .unwrap_err();
    assert!(matches!(problem(inner), RecordingError::Exchanged));
    // The device still works afterwards.
    device.submit_once(|_| ()).unwrap();
}

#[test]
fn write_buffer_checks_binding_type_usage_and_use() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let f = Fixture::new(device);
    let storage = Fixture::storage(device);
    let uniform = Buffer::new(
        device,
        &BufferDesc {
            name: "test uniform",
            size: 16,
            usage: vk::BufferUsageFlags::UNIFORM_BUFFER,
            location: MemoryLocation::CpuToGpu,
        },
    )
    .unwrap();
    let set = f.pool.allocate_set(&f.layout).unwrap();
    let descriptor_problem = |e: VkError| match e {
        VkError::Descriptor { problem, .. } => problem,
        other => panic!("expected a descriptor error, got {other}"),
    };
    let e = set
        .write_buffer(5, vk::DescriptorType::STORAGE_BUFFER, &storage)
        .unwrap_err();
    assert_eq!(descriptor_problem(e), DescriptorError::NoSuchBinding);
    let e = set
        .write_buffer(0, vk::DescriptorType::UNIFORM_BUFFER, &uniform)
        .unwrap_err();
    assert!(matches!(
        descriptor_problem(e),
        DescriptorError::Type { .. }
    ));
    let e = set
        .write_buffer(0, vk::DescriptorType::STORAGE_BUFFER, &uniform)
        .unwrap_err();
    assert!(matches!(
        descriptor_problem(e),
        DescriptorError::Usage { .. }
    ));
    // An unwritten set cannot be bound.
    let e = device
        .submit_once(|enc| {
            enc.bind_pipeline(&f.compute);
            enc.bind_descriptor_sets(0, &[&set])
        })
        .unwrap()
        .unwrap_err();
    assert!(matches!(
        problem(e),
        RecordingError::SetIncomplete { binding: 0, .. }
    ));
    set.write_buffer(0, vk::DescriptorType::STORAGE_BUFFER, &storage)
        .unwrap();
    // A set bound in a recording that was not submitted yet cannot be updated.
    let in_use = device
        .submit_once(|enc| {
            enc.bind_pipeline(&f.compute);
            enc.bind_descriptor_sets(0, &[&set]).unwrap();
            set.write_buffer(0, vk::DescriptorType::STORAGE_BUFFER, &storage)
        })
        .unwrap()
        .unwrap_err();
    assert_eq!(descriptor_problem(in_use), DescriptorError::InUse);
    set.write_buffer(0, vk::DescriptorType::STORAGE_BUFFER, &storage)
        .unwrap();
}

#[test]
fn queries_are_checked() {
    let gpu = Gpu::new();
    let device = gpu.device();
    if !device.info.caps.timestamps {
        return;
    }
    let pool = QueryPool::timestamps(device, "test timestamps", 2).unwrap();
    let results = device
        .submit_once(|enc| {
            let before_reset = enc.write_timestamp(&pool, vk::PipelineStageFlags::TOP_OF_PIPE, 0);
            enc.reset_queries(&pool);
            let outside = enc.write_timestamp(&pool, vk::PipelineStageFlags::TOP_OF_PIPE, 2);
            let wrong_type = enc.begin_query(&pool, 0);
            enc.write_timestamp(&pool, vk::PipelineStageFlags::TOP_OF_PIPE, 0)
                .unwrap();
            let twice = enc.write_timestamp(&pool, vk::PipelineStageFlags::TOP_OF_PIPE, 0);
            enc.write_timestamp(&pool, vk::PipelineStageFlags::BOTTOM_OF_PIPE, 1)
                .unwrap();
            [before_reset, outside, wrong_type, twice]
        })
        .unwrap();
    let [before_reset, outside, wrong_type, twice] = results;
    assert!(matches!(
        problem(before_reset.unwrap_err()),
        RecordingError::QueryNotReset { index: 0, .. }
    ));
    assert!(matches!(
        outside.unwrap_err(),
        VkError::QueryIndex {
            index: 2,
            count: 2,
            ..
        }
    ));
    assert!(matches!(wrong_type.unwrap_err(), VkError::QueryType { .. }));
    assert!(matches!(
        problem(twice.unwrap_err()),
        RecordingError::QueryNotReset { index: 0, .. }
    ));
    assert_eq!(pool.durations_ns().unwrap().len(), 1);
}

/// A timeline semaphore a submission waits on (value 1) until the host opens it. Opened when
/// dropped too, so a failing test does not leave the device waiting forever.
struct Gate {
    device: Device,
    raw: vk::Semaphore,
}

impl Gate {
    fn new(device: &Device) -> Gate {
        let mut timeline_info = vk::SemaphoreTypeCreateInfo::default()
            .semaphore_type(vk::SemaphoreType::TIMELINE)
            .initial_value(0);
        let info = vk::SemaphoreCreateInfo::default().push_next(&mut timeline_info);
        // SAFETY: the device is live; the gate is destroyed in Drop after an idle wait.
        let raw = unsafe { device.raw.create_semaphore(&info, None) }.unwrap();
        Gate {
            device: device.clone(),
            raw,
        }
    }

    fn open(&self) {
        // SAFETY: a live timeline semaphore.
        let value = unsafe { self.device.raw.get_semaphore_counter_value(self.raw) }.unwrap();
        if value == 0 {
            let signal = vk::SemaphoreSignalInfo::default()
                .semaphore(self.raw)
                .value(1);
            // SAFETY: a live timeline semaphore at 0, signalled to a greater value.
            unsafe { self.device.raw.signal_semaphore(&signal) }.unwrap();
        }
    }
}

impl Drop for Gate {
    fn drop(&mut self) {
        self.open();
        self.device.wait_idle();
        // SAFETY: the device is idle, so nothing waits on the gate.
        unsafe { self.device.raw.destroy_semaphore(self.raw, None) };
    }
}

/// A defect once shipped: objects dropped right after a submission that is not waited for (a
/// frame) were destroyed while the GPU still used them. A timeline "gate" the host signals last
/// holds the submission back, so the drops certainly happen while it is pending.
#[test]
fn objects_dropped_after_an_unwaited_submission_outlive_it() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let baseline = device.allocated_bytes();
    let gate = Gate::new(device);

    let f = Fixture::new(device);
    let storage = Fixture::storage(device);
    let set = f.set_with(&storage);
    let Fixture {
        layout,
        pool,
        compute,
        graphics,
    } = f;
    let mut enc = device.encoder().unwrap();
    enc.bind_pipeline(&compute);
    enc.bind_descriptor_sets(0, &[&set]).unwrap();
    enc.dispatch([1, 1, 1]).unwrap();
    let cmd = enc.raw_cmd();
    // SAFETY: the gate is a timeline semaphore waited for at value 1, which the host signals
    // below; no fence. The command pool is retired with the serial, as Encoder::submit does.
    let (serial, origin) = unsafe {
        enc.submit_with(
            &[(gate.raw, vk::PipelineStageFlags::ALL_COMMANDS, 1)],
            &[],
            vk::Fence::null(),
        )
    }
    .unwrap();
    if let crate::encoder::Origin::Unwaited { pool } = origin {
        device.retire(crate::retire::Retired::CommandPool { pool, cmd });
    }
    drop((compute, graphics, set, pool, layout, storage));
    assert!(
        device.completed_serial() < serial,
        "the gate holds the submission"
    );
    assert!(
        device.allocated_bytes() > baseline,
        "the buffer must outlive the submission"
    );
    assert!(device.retired.lock().unwrap().waiting.len() >= 4);
    assert!(gpu.errors().is_empty(), "{:#?}", gpu.errors());

    gate.open();
    device.wait_serial(serial).unwrap();
    device.collect_retired();
    assert_eq!(device.allocated_bytes(), baseline);
    assert!(device.retired.lock().unwrap().waiting.is_empty());
    drop(gate);

    // The public path: Encoder::submit does not wait; Submission::wait does.
    let f = Fixture::new(device);
    let storage = Fixture::storage(device);
    let set = f.set_with(&storage);
    let mut enc = device.encoder().unwrap();
    enc.bind_pipeline(&f.compute);
    enc.bind_descriptor_sets(0, &[&set]).unwrap();
    enc.dispatch([1, 1, 1]).unwrap();
    let submission = enc.submit().unwrap();
    drop((f, set, storage));
    submission.wait().unwrap();
    assert!(submission.is_complete());
    assert_eq!(device.allocated_bytes(), baseline);
}

/// The capture pattern (today's tess/src/capture.rs): an attachment-less scope, transform
/// feedback into a region of a buffer, a stream query counting what was written, and the
/// barrier that makes the writes visible to the host.
#[test]
fn transform_feedback_captures_through_the_encoder() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let (vb, _ib) = triangle(device);
    let Ok(query) = QueryPool::transform_feedback_stream(device, "test captured", 1) else {
        // Without the extension the encoder's commands are typed errors.
        let e = device
            .submit_once(|enc| enc.begin_transform_feedback(&[&vb], &[]))
            .unwrap()
            .unwrap_err();
        assert!(matches!(e, VkError::Unsupported { .. }), "{e}");
        return;
    };
    let mut desc =
        GraphicsPipelineDesc::new("test capture", vk::Format::UNDEFINED, vk::Format::UNDEFINED);
    desc.stages = vec![ShaderStage::new(
        vk::ShaderStageFlags::VERTEX,
        spirv::XFB_VERT,
    )];
    desc.vertex_bindings = vec![vk::VertexInputBindingDescription {
        binding: 0,
        stride: 12,
        input_rate: vk::VertexInputRate::VERTEX,
    }];
    desc.vertex_attributes = vec![vk::VertexInputAttributeDescription {
        location: 0,
        binding: 0,
        format: vk::Format::R32G32B32_SFLOAT,
        offset: 0,
    }];
    desc.rasterizer_discard = true;
    desc.depth_test = false;
    desc.depth_write = false;
    let pipeline = Pipeline::graphics(device, &desc).unwrap();
    let plain = Fixture::new(device);
    let captured = Buffer::new(
        device,
        &BufferDesc {
            name: "test capture",
            size: 64 + 48,
            usage: vk::BufferUsageFlags::TRANSFORM_FEEDBACK_BUFFER_EXT,
            location: MemoryLocation::GpuToCpu,
        },
    )
    .unwrap();
    let one_pixel = vk::Extent2D {
        width: 1,
        height: 1,
    };
    let refused = device
        .submit_once(|enc| {
            enc.begin_rendering_without_attachments(one_pixel);
            enc.bind_pipeline(&plain.graphics);
            let wrong_pipeline = enc.begin_transform_feedback(&[&captured], &[]);
            enc.bind_pipeline(&pipeline);
            enc.bind_vertex_buffer(0, &vb);
            let misaligned = enc.begin_transform_feedback_ranges(&[(&captured, 2, 48)], &[]);
            let past_end = enc.begin_transform_feedback_ranges(&[(&captured, 64, 64)], &[]);
            enc.end_rendering();
            [wrong_pipeline, misaligned, past_end]
        })
        .unwrap();
    let [wrong_pipeline, misaligned, past_end] = refused.map(|r| problem(r.unwrap_err()));
    assert!(matches!(
        wrong_pipeline,
        RecordingError::AttachmentFormats { .. }
    ));
    assert!(matches!(
        misaligned,
        RecordingError::TransformFeedbackRange { offset: 2, .. }
    ));
    assert!(matches!(
        past_end,
        RecordingError::TransformFeedbackRange { offset: 64, .. }
    ));
    device
        .submit_once(|enc| -> crate::Result<()> {
            enc.reset_queries(&query);
            enc.begin_rendering_without_attachments(one_pixel);
            enc.bind_pipeline(&pipeline);
            enc.bind_vertex_buffer(0, &vb);
            enc.begin_transform_feedback_ranges(&[(&captured, 64, 48)], &[])?;
            enc.begin_query_stream(&query, 0, 0)?;
            enc.draw(0..3)?;
            enc.end_query_stream(&query, 0, 0)?;
            enc.end_transform_feedback(&[])?;
            enc.end_rendering();
            enc.memory_barrier(
                (
                    vk::PipelineStageFlags::TRANSFORM_FEEDBACK_EXT,
                    vk::AccessFlags::TRANSFORM_FEEDBACK_WRITE_EXT,
                ),
                (vk::PipelineStageFlags::HOST, vk::AccessFlags::HOST_READ),
            );
            Ok(())
        })
        .unwrap()
        .unwrap();
    let counts = query.transform_feedback_results().unwrap();
    assert_eq!(counts[0].primitives_written, 1);
    let words: Vec<f32> = captured.read().unwrap();
    assert_eq!(&words[16..20], &[-0.9, -0.9, 0.5, 1.0]);
    assert_eq!(&words[24..28], &[0.0, 0.9, 0.5, 1.0]);
}

/// `live_objects` counts every handle vk-core makes and comes back to where it was once they
/// are dropped and their submissions completed; one-shot command pools are kept for reuse, so
/// a second round of the same work adds nothing (what the soak test relies on).
#[test]
fn live_objects_count_every_handle_and_return_after_drops() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let round = || {
        let f = Fixture::new(device);
        let storage = Fixture::storage(device);
        let set = f.set_with(&storage);
        let target = OffscreenTarget::new(
            device,
            vk::Extent2D {
                width: 16,
                height: 16,
            },
        )
        .unwrap();
        let query = QueryPool::timestamps(device, "live-object query", 2).unwrap();
        let mut enc = device.encoder().unwrap();
        enc.bind_pipeline(&f.compute);
        enc.bind_descriptor_sets(0, &[&set]).unwrap();
        enc.dispatch([1, 1, 1]).unwrap();
        let submission = enc.submit().unwrap();
        drop((f, set, storage, target, query));
        submission
    };
    let start = device.live_objects();
    let f = Fixture::new(device);
    // The set layout, the pool, and each pipeline with its layout (shader modules are gone).
    assert_eq!(device.live_objects(), start + 6);
    let storage = Fixture::storage(device);
    assert_eq!(device.live_objects(), start + 7);
    drop((f, storage));
    assert_eq!(device.live_objects(), start);

    let first = round();
    first.wait().unwrap();
    let warm = device.live_objects();
    let bytes = device.allocated_bytes();
    for _ in 0..3 {
        let s = round();
        s.wait().unwrap();
        assert_eq!(device.live_objects(), warm);
        assert_eq!(device.allocated_bytes(), bytes);
    }
}
