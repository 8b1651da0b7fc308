//! `tessera view`: a window with an orbit camera. Drag to orbit, wheel to zoom, 1/2/3 switch
//! flat/Phong/PN, +/- raise/lower the level, W toggles the wireframe, Esc quits. The title shows
//! the frame time. `--frames N --screenshot out.png` renders N frames, saves the last and exits.
use crate::cli::ViewArgs;
use crate::commands::{check_validation, draw_params, load_mesh, open_device};
use anyhow::{Context, Result};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::sync::Arc;
use std::time::Instant;
use tess::renderer::GpuMesh;
use tess::{DrawParams, Method, RenderMesh, Renderer};
use vk_core::swapchain::{required_surface_extensions, Swapchain, FRAMES_IN_FLIGHT};
use vk_core::target::DEPTH_FORMAT;
use vk_core::{vk, Device, Instance};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// GPU state that lives while the window does. Drop order: renderer and mesh, swapchain, then
/// the device and instance; the window itself is dropped after all of them.
struct Gpu {
    renderer: Renderer,
    mesh: GpuMesh,
    swapchain: Swapchain,
    device: Device,
    instance: Arc<Instance>,
}

struct App {
    args: ViewArgs,
    rm: RenderMesh,
    params: DrawParams,
    gpu: Option<Gpu>,
    window: Option<Arc<Window>>,
    frames_drawn: u32,
    dragging: bool,
    last_cursor: Option<(f64, f64)>,
    last_frame: Instant,
    frame_ms: f64,
    error: Option<anyhow::Error>,
}

impl App {
    fn init(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let attrs = Window::default_attributes()
            .with_title("tessera")
            .with_inner_size(winit::dpi::PhysicalSize::new(
                self.args.size.0,
                self.args.size.1,
            ));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .context("creating the window")?,
        );
        let display = window.display_handle().context("display handle")?.as_raw();
        let handle = window.window_handle().context("window handle")?.as_raw();
        let (instance, device) = open_device(
            &self.args.scene.gpu,
            required_surface_extensions(display)?,
            &[Swapchain::DEVICE_EXTENSION],
        )?;
        let size = window.inner_size();
        let swapchain = Swapchain::new(
            &device,
            display,
            handle,
            vk::Extent2D {
                width: size.width,
                height: size.height,
            },
        )?;
        let renderer = Renderer::new(&device, swapchain.format, DEPTH_FORMAT, FRAMES_IN_FLIGHT)?;
        let mesh = GpuMesh::upload(&device, &self.rm)?;
        self.gpu = Some(Gpu {
            renderer,
            mesh,
            swapchain,
            device,
            instance,
        });
        self.window = Some(window);
        Ok(())
    }

    fn draw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        let Some(frame) = gpu.swapchain.begin_frame()? else {
            return Ok(());
        };
        gpu.renderer
            .update_uniforms(frame.slot, &gpu.mesh, &self.params, frame.extent)?;
        gpu.swapchain
            .cmd_begin_rendering(&frame, self.params.clear_color)?;
        gpu.renderer
            .record(frame.cmd, frame.slot, &gpu.mesh, &self.params)?;
        let last = self.args.frames.is_some_and(|n| self.frames_drawn + 1 >= n);
        let shot = gpu
            .swapchain
            .end_frame(frame, last && self.args.screenshot.is_some())?;
        self.frames_drawn += 1;
        let now = Instant::now();
        self.frame_ms = 0.9 * self.frame_ms + 0.1 * (now - self.last_frame).as_secs_f64() * 1e3;
        self.last_frame = now;
        if let Some(w) = &self.window {
            w.set_title(&format!(
                "tessera — {:?} level {} {:?} — {:.2} ms/frame",
                self.params.method, self.params.level, self.params.spacing, self.frame_ms
            ));
        }
        if let (Some(img), Some(path)) = (shot, &self.args.screenshot) {
            img.save_png(path)?;
            println!(
                "wrote {} after {} frames",
                path.display(),
                self.frames_drawn
            );
        }
        if last {
            event_loop.exit();
        }
        Ok(())
    }

    fn key(&mut self, key: &Key) {
        match key {
            Key::Character(c) => match c.as_str() {
                "1" => self.params.method = Method::Flat,
                "2" => self.params.method = Method::Phong,
                "3" => self.params.method = Method::Pn,
                "+" | "=" => self.params.level = (self.params.level + 1.0).min(64.0),
                "-" => self.params.level = (self.params.level - 1.0).max(1.0),
                "w" | "W" => self.params.wireframe = !self.params.wireframe,
                _ => {}
            },
            Key::Named(NamedKey::ArrowUp) => {
                self.params.level = (self.params.level * 2.0).min(64.0)
            }
            Key::Named(NamedKey::ArrowDown) => {
                self.params.level = (self.params.level * 0.5).max(1.0)
            }
            _ => {}
        }
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, e: anyhow::Error) {
        self.error = Some(e);
        event_loop.exit();
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.gpu.is_none() {
            if let Err(e) = self.init(event_loop) {
                self.fail(event_loop, e);
            }
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _id: WindowId, event: WindowEvent) {
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                if let Some(gpu) = self.gpu.as_mut() {
                    gpu.swapchain.resize(vk::Extent2D {
                        width: size.width,
                        height: size.height,
                    });
                }
            }
            WindowEvent::RedrawRequested => {
                if let Err(e) = self.draw(event_loop) {
                    self.fail(event_loop, e);
                }
            }
            WindowEvent::KeyboardInput { event, .. } if event.state == ElementState::Pressed => {
                if event.logical_key == Key::Named(NamedKey::Escape) {
                    event_loop.exit();
                }
                self.key(&event.logical_key);
            }
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                self.dragging = state == ElementState::Pressed;
                self.last_cursor = None;
            }
            WindowEvent::CursorMoved { position, .. } if self.dragging => {
                if let Some((x, y)) = self.last_cursor {
                    self.params.camera.yaw -= (position.x - x) as f32 * 0.4;
                    self.params.camera.pitch = (self.params.camera.pitch
                        + (position.y - y) as f32 * 0.4)
                        .clamp(-89.0, 89.0);
                }
                self.last_cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.params.camera.zoom =
                    (self.params.camera.zoom * 1.1f32.powf(steps)).clamp(0.1, 20.0);
            }
            _ => {}
        }
    }

    fn about_to_wait(&mut self, _event_loop: &ActiveEventLoop) {
        if let Some(w) = &self.window {
            w.request_redraw();
        }
    }
}

pub fn run(args: ViewArgs) -> Result<()> {
    if args.screenshot.is_some() && args.frames.is_none() {
        anyhow::bail!("--screenshot needs --frames N");
    }
    let mesh = load_mesh(args.scene.mesh.as_deref())?;
    let params = draw_params(&args.scene)?;
    let rm = RenderMesh::from_control_mesh(&mesh)?;
    let event_loop = EventLoop::new().context(
        "no window system (set DISPLAY or WAYLAND_DISPLAY; use `tessera render` headless)",
    )?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        args,
        rm,
        params,
        gpu: None,
        window: None,
        frames_drawn: 0,
        dragging: false,
        last_cursor: None,
        last_frame: Instant::now(),
        frame_ms: 0.0,
        error: None,
    };
    event_loop.run_app(&mut app).context("event loop")?;
    let gpu = app.gpu.take();
    let result = match gpu {
        Some(Gpu {
            renderer,
            mesh,
            swapchain,
            device,
            instance,
        }) => {
            drop((renderer, mesh, swapchain));
            drop(device);
            check_validation(&instance)
        }
        None => Ok(()),
    };
    drop(app.window.take());
    if let Some(e) = app.error {
        return Err(e);
    }
    result
}
