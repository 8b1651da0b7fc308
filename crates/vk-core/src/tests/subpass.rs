//! Pipelines made for a host application's render pass subpass, recorded through
//! [`Encoder::record_into`] into a render pass instance the test begins itself through ash, as
//! a host does: the draw lands in the image, and a pipeline of the other kind (dynamic
//! rendering, or another subpass) is refused in either kind of scope.
use super::*;
use crate::encoder::{Encoder, HostScope};
use crate::pipeline::Subpass;

/// A render pass of one subpass: the offscreen colour (cleared, left for a transfer read) and
/// depth formats, with the dependency that makes its writes visible to the copy after it.
fn render_pass(device: &Device) -> vk::RenderPass {
    let attachments = [
        vk::AttachmentDescription::default()
            .format(COLOR_FORMAT)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::STORE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(vk::ImageLayout::TRANSFER_SRC_OPTIMAL),
        vk::AttachmentDescription::default()
            .format(DEPTH_FORMAT)
            .samples(vk::SampleCountFlags::TYPE_1)
            .load_op(vk::AttachmentLoadOp::CLEAR)
            .store_op(vk::AttachmentStoreOp::DONT_CARE)
            .initial_layout(vk::ImageLayout::UNDEFINED)
            .final_layout(vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL),
    ];
    let color = [vk::AttachmentReference {
        attachment: 0,
        layout: vk::ImageLayout::COLOR_ATTACHMENT_OPTIMAL,
    }];
    let depth = vk::AttachmentReference {
        attachment: 1,
        layout: vk::ImageLayout::DEPTH_STENCIL_ATTACHMENT_OPTIMAL,
    };
    let subpasses = [vk::SubpassDescription::default()
        .pipeline_bind_point(vk::PipelineBindPoint::GRAPHICS)
        .color_attachments(&color)
        .depth_stencil_attachment(&depth)];
    let dependencies = [vk::SubpassDependency::default()
        .src_subpass(0)
        .dst_subpass(vk::SUBPASS_EXTERNAL)
        .src_stage_mask(vk::PipelineStageFlags::COLOR_ATTACHMENT_OUTPUT)
        .src_access_mask(vk::AccessFlags::COLOR_ATTACHMENT_WRITE)
        .dst_stage_mask(vk::PipelineStageFlags::TRANSFER)
        .dst_access_mask(vk::AccessFlags::TRANSFER_READ)];
    let info = vk::RenderPassCreateInfo::default()
        .attachments(&attachments)
        .subpasses(&subpasses)
        .dependencies(&dependencies);
    // SAFETY: the device is live; the info references live locals.
    unsafe { device.raw.create_render_pass(&info, None) }.unwrap()
}

/// The fixture's triangle pipeline, made for `subpass`.
fn subpass_pipeline(device: &Device, f: &Fixture, subpass: Subpass) -> Pipeline {
    let mut desc = GraphicsPipelineDesc::new("subpass triangle", COLOR_FORMAT, DEPTH_FORMAT);
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
    desc.set_layouts = vec![f.layout.raw];
    desc.push_constant_bytes = 16;
    desc.depth_test = false;
    desc.subpass = Some(subpass);
    Pipeline::graphics(device, &desc).unwrap()
}

/// Records `record` into a fresh command buffer of the test's own pool (as a host would),
/// submits it and waits for it.
fn host_submit(device: &Device, record: impl FnOnce(vk::CommandBuffer)) {
    let pool_info = vk::CommandPoolCreateInfo::default().queue_family_index(device.queue_family);
    // SAFETY: the device is live; the pool and its one buffer are used on this thread only,
    // the submission is waited for before the pool is destroyed, and the queue is used under
    // the device's queue lock.
    unsafe {
        let pool = device.raw.create_command_pool(&pool_info, None).unwrap();
        let cmd = device
            .raw
            .allocate_command_buffers(
                &vk::CommandBufferAllocateInfo::default()
                    .command_pool(pool)
                    .command_buffer_count(1),
            )
            .unwrap()[0];
        device
            .raw
            .begin_command_buffer(cmd, &vk::CommandBufferBeginInfo::default())
            .unwrap();
        record(cmd);
        device.raw.end_command_buffer(cmd).unwrap();
        let fence = device
            .raw
            .create_fence(&vk::FenceCreateInfo::default(), None)
            .unwrap();
        let cmds = [cmd];
        {
            let _q = device.queue_lock.lock().unwrap();
            device
                .raw
                .queue_submit(
                    device.queue,
                    &[vk::SubmitInfo::default().command_buffers(&cmds)],
                    fence,
                )
                .unwrap();
        }
        device
            .raw
            .wait_for_fences(&[fence], true, u64::MAX)
            .unwrap();
        device.raw.destroy_fence(fence, None);
        device.raw.destroy_command_pool(pool, None);
    }
}

#[test]
fn pipelines_made_for_a_subpass_draw_in_the_hosts_render_pass() {
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
    let pass = render_pass(device);
    let subpass = Subpass {
        render_pass: pass,
        index: 0,
        samples: vk::SampleCountFlags::TYPE_1,
    };
    let pipeline = subpass_pipeline(device, &f, subpass);
    let views = [target.color.view, target.depth.view];
    let fb_info = vk::FramebufferCreateInfo::default()
        .render_pass(pass)
        .attachments(&views)
        .width(extent.width)
        .height(extent.height)
        .layers(1);
    // SAFETY: the render pass and views are live.
    let framebuffer = unsafe { device.raw.create_framebuffer(&fb_info, None) }.unwrap();
    let formats = [COLOR_FORMAT, DEPTH_FORMAT];
    let mut refused = Vec::new();
    host_submit(device, |cmd| {
        let clear = [
            vk::ClearValue {
                color: vk::ClearColorValue {
                    float32: [0.0, 0.0, 0.0, 1.0],
                },
            },
            vk::ClearValue {
                depth_stencil: vk::ClearDepthStencilValue {
                    depth: 1.0,
                    stencil: 0,
                },
            },
        ];
        let begin = vk::RenderPassBeginInfo::default()
            .render_pass(pass)
            .framebuffer(framebuffer)
            .render_area(extent.into())
            .clear_values(&clear);
        // SAFETY: `cmd` is recording outside any scope; the framebuffer matches the pass.
        unsafe {
            device
                .raw
                .cmd_begin_render_pass(cmd, &begin, vk::SubpassContents::INLINE);
            let viewport = vk::Viewport::default()
                .width(32.0)
                .height(32.0)
                .max_depth(1.0);
            device.raw.cmd_set_viewport(cmd, 0, &[viewport]);
            device.raw.cmd_set_scissor(cmd, 0, &[extent.into()]);
        }
        // SAFETY: inside subpass 0 of `pass`, viewport and scissor set; everything recorded
        // outlives the submission, which `host_submit` waits for.
        let mut enc = unsafe {
            Encoder::record_into(device, cmd, Some(HostScope::Subpass { subpass, formats }))
        };
        enc.bind_pipeline(&f.graphics);
        enc.bind_descriptor_sets(0, &[&set]).unwrap();
        enc.push_constants(&[1u32, 2, 3, 4]).unwrap();
        enc.bind_vertex_buffer(0, &vb);
        enc.bind_index_buffer_u32(&ib);
        // The dynamic-rendering pipeline does not belong in a render pass instance.
        refused.push(enc.draw_indexed(0..3).unwrap_err());
        enc.bind_pipeline(&pipeline);
        enc.bind_descriptor_sets(0, &[&set]).unwrap();
        enc.push_constants(&[1u32, 2, 3, 4]).unwrap();
        enc.bind_vertex_buffer(0, &vb);
        enc.bind_index_buffer_u32(&ib);
        enc.draw_indexed(0..3).unwrap();
        enc.finish().unwrap();
        // SAFETY: ends the render pass begun above; the copy reads the colour image in the
        // layout the pass left it in, after the pass's external dependency.
        unsafe {
            device.raw.cmd_end_render_pass(cmd);
            let region = vk::BufferImageCopy::default()
                .image_subresource(vk::ImageSubresourceLayers {
                    aspect_mask: vk::ImageAspectFlags::COLOR,
                    mip_level: 0,
                    base_array_layer: 0,
                    layer_count: 1,
                })
                .image_extent(vk::Extent3D {
                    width: 32,
                    height: 32,
                    depth: 1,
                });
            device.raw.cmd_copy_image_to_buffer(
                cmd,
                target.color.raw,
                vk::ImageLayout::TRANSFER_SRC_OPTIMAL,
                readback.raw,
                &[region],
            );
            let to_host = vk::MemoryBarrier::default()
                .src_access_mask(vk::AccessFlags::TRANSFER_WRITE)
                .dst_access_mask(vk::AccessFlags::HOST_READ);
            device.raw.cmd_pipeline_barrier(
                cmd,
                vk::PipelineStageFlags::TRANSFER,
                vk::PipelineStageFlags::HOST,
                vk::DependencyFlags::empty(),
                &[to_host],
                &[],
                &[],
            );
        }
    });
    // And the subpass pipeline does not belong in a dynamic-rendering scope (checked only:
    // nothing is drawn, so the scope need not exist).
    host_submit(device, |cmd| {
        // SAFETY: nothing is recorded: the draw is refused before reaching the command buffer.
        let mut enc =
            unsafe { Encoder::record_into(device, cmd, Some(HostScope::Rendering(formats))) };
        enc.bind_pipeline(&pipeline);
        enc.bind_descriptor_sets(0, &[&set]).unwrap();
        refused.push(enc.draw(0..3).unwrap_err());
        enc.finish().unwrap();
    });
    for e in refused {
        assert!(
            matches!(problem(e), RecordingError::Subpass { .. }),
            "expected a subpass mismatch"
        );
    }
    let image = target.read(&readback).unwrap();
    let centre = ((16 * 32 + 16) * 4) as usize;
    assert_eq!(&image.pixels[centre..centre + 4], &[255, 0, 0, 255]);
    assert_eq!(
        &image.pixels[0..4],
        &[0, 0, 0, 255],
        "corner keeps the clear"
    );
    drop(pipeline);
    // SAFETY: the submission that used them finished (host_submit waited).
    unsafe {
        device.raw.destroy_framebuffer(framebuffer, None);
        device.raw.destroy_render_pass(pass, None);
    }
}
