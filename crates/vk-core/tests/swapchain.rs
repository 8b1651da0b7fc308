//! Swapchain frames through the encoder, in a window on Xvfb with the validation layer on
//! (synchronization validation included): a
//! rendered frame with a screenshot, objects dropped right after an unwaited present, an
//! abandoned (dropped) frame, and a present refused for an open rendering scope. Skipped where
//! Xvfb is not installed (CI sets TESSERA_REQUIRE_XVFB=1 so a missing Xvfb fails there).
#[path = "../src/tests/spirv.rs"]
#[allow(dead_code)]
mod spirv;

#[path = "../../../tests/support/xvfb.rs"]
mod xvfb;

use std::sync::Arc;
use vk_core::pipeline::{GraphicsPipelineDesc, ShaderStage};
use vk_core::swapchain::{required_surface_extensions, SwapchainFrame};
use vk_core::target::DEPTH_FORMAT;
use vk_core::{
    vk, Buffer, Device, DeviceDesc, Instance, InstanceDesc, Pipeline, RecordingError, Swapchain,
    Validation, VkError,
};
use winit::application::ApplicationHandler;
use winit::event::WindowEvent;
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::platform::x11::EventLoopBuilderExtX11;
use winit::raw_window_handle::HasDisplayHandle;
use winit::window::{Window, WindowId};

/// Acquires a frame (on Xvfb the surface never goes out of date or minimised, so an acquire
/// after a rebuild succeeds at once).
fn acquire(sc: &mut Swapchain) -> Result<SwapchainFrame<'_>, String> {
    sc.acquire()
        .map_err(|e| e.to_string())?
        .ok_or_else(|| "no frame to draw into".to_owned())
}

fn run(window: Arc<Window>) -> Result<(), String> {
    let display = window.display_handle().map_err(|e| e.to_string())?.as_raw();
    let instance = Instance::new(&InstanceDesc {
        app_name: "vk-core-swapchain-test".into(),
        validation: Validation::Synchronization,
        surface_extensions: required_surface_extensions(display).map_err(|e| e.to_string())?,
    })
    .map_err(|e| e.to_string())?;
    if instance.validation() != Validation::Synchronization {
        return Err("the validation layer is not installed".into());
    }
    let device = Device::new(
        &instance,
        &DeviceDesc::default(),
        &[Swapchain::DEVICE_EXTENSION],
    )
    .map_err(|e| e.to_string())?;
    let extent = vk::Extent2D {
        width: 64,
        height: 64,
    };
    let mut sc = Swapchain::for_window(&device, window, extent).map_err(|e| e.to_string())?;
    let e = |e: VkError| e.to_string();

    // A rendered frame; its pipeline and vertex buffer are dropped right after the unwaited
    // present, which the retire queue must survive.
    {
        let mut desc = GraphicsPipelineDesc::new("frame triangle", sc.format, DEPTH_FORMAT);
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
        desc.depth_test = false;
        let pipeline = Pipeline::graphics(&device, &desc).map_err(e)?;
        let positions: [f32; 9] = [-0.9, -0.9, 0.5, 0.9, -0.9, 0.5, 0.0, 0.9, 0.5];
        let vb = Buffer::with_data(
            &device,
            "frame vertices",
            vk::BufferUsageFlags::VERTEX_BUFFER,
            bytemuck::cast_slice(&positions),
        )
        .map_err(e)?;
        let screenshot = sc.supports_screenshots();
        let mut frame = acquire(&mut sc)?;
        frame.begin_frame_rendering([0.0, 0.0, 1.0, 1.0]);
        frame.bind_pipeline(&pipeline);
        frame.bind_vertex_buffer(0, &vb);
        frame.draw(0..3).map_err(e)?;
        frame.end_rendering();
        let shot = frame.present(screenshot).map_err(e)?;
        drop((pipeline, vb));
        if let Some(shot) = shot {
            let px = |x: u32, y: u32| {
                let i = ((y * shot.width + x) * 4) as usize;
                shot.pixels[i..i + 4].to_vec()
            };
            if px(shot.width / 2, shot.height / 2) != [255, 0, 0, 255] {
                return Err(format!("centre is {:?}, not red", px(32, 32)));
            }
            if px(0, 0) != [0, 0, 255, 255] {
                return Err(format!("corner is {:?}, not the blue clear", px(0, 0)));
            }
        } else if screenshot {
            return Err("no screenshot".into());
        }
    }

    // A dropped frame is abandoned; the next one works.
    drop(acquire(&mut sc)?);
    let mut frame = acquire(&mut sc)?;
    frame.begin_frame_rendering([0.0; 4]);
    frame.end_rendering();
    frame.present(false).map_err(e)?;

    // A present with the rendering scope still open is refused, not submitted.
    let mut frame = acquire(&mut sc)?;
    frame.begin_frame_rendering([0.0; 4]);
    match frame.present(false) {
        Err(VkError::Recording {
            problem: RecordingError::Unclosed { .. },
            ..
        }) => {}
        other => return Err(format!("expected Unclosed, got {other:?}")),
    }
    let frame = acquire(&mut sc)?;
    frame.present(false).map_err(e)?;

    drop(sc);
    let leaked = device.allocated_bytes();
    drop(device);
    if leaked != 0 {
        return Err(format!("{leaked} bytes still allocated"));
    }
    let errors = instance.messages().error_messages();
    if !errors.is_empty() {
        return Err(format!("validation errors: {errors:#?}"));
    }
    Ok(())
}

#[derive(Default)]
struct App {
    result: Option<Result<(), String>>,
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.result.is_none() {
            let attrs =
                Window::default_attributes().with_inner_size(winit::dpi::PhysicalSize::new(64, 64));
            self.result = Some(
                event_loop
                    .create_window(attrs)
                    .map_err(|e| e.to_string())
                    .and_then(|w| run(Arc::new(w))),
            );
        }
        event_loop.exit();
    }

    fn window_event(&mut self, _: &ActiveEventLoop, _: WindowId, _: WindowEvent) {}
}

#[test]
fn swapchain_frames_record_through_the_encoder() {
    let Some(server) = xvfb::start_or_skip(140..170) else {
        return;
    };
    std::env::set_var("DISPLAY", &server.display);
    std::env::remove_var("WAYLAND_DISPLAY");
    let event_loop = EventLoop::builder()
        .with_any_thread(true)
        .build()
        .expect("an X11 event loop on Xvfb");
    let mut app = App::default();
    event_loop.run_app(&mut app).expect("the event loop ran");
    app.result.expect("the window was created").unwrap();
}
