//! `tessera view`: a window with an orbit camera. Drag to orbit, wheel to zoom, 1/2/3/4 switch
//! flat/Phong/PN/BFT, +/- raise/lower the level (BFT: halve/double unless fractional), arrows
//! halve/double it, W toggles the wireframe; for BFT, A toggles the animation, C the patch
//! colours, F fractional factors, G geometric normals. Esc quits. The title shows the frame
//! time. `--frames N --screenshot out.png` renders N frames, saves the last and exits.
use crate::cli::ViewArgs;
use crate::commands::{check_validation, draw_params, load_mesh, mesh_name, open_device};
use crate::technique::{loop_control_mesh, BftSetup, Technique, Wave};
use anyhow::{Context, Result};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use std::sync::Arc;
use std::time::Instant;
use tess::bft::{BftSurface, FactorPolicy};
use tess::renderer::GpuMesh;
use tess::{DrawParams, Method, RenderMesh, Renderer};
use topology::ControlMesh;
use vk_core::swapchain::{required_surface_extensions, Swapchain, FRAMES_IN_FLIGHT};
use vk_core::target::DEPTH_FORMAT;
use vk_core::{vk, Device, Instance};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// GPU state that lives while the window does. Drop order: BFT surface, renderer and mesh,
/// swapchain, then the device and instance; the window itself is dropped after all of them.
struct Gpu {
    bft: Option<BftSurface>,
    renderer: Renderer,
    mesh: GpuMesh,
    swapchain: Swapchain,
    device: Device,
    instance: Arc<Instance>,
}

/// The BFT side of the view: the Loop control mesh, its options and the animation clock.
struct BftView {
    mesh: ControlMesh,
    name: String,
    setup: BftSetup,
    wave: Wave,
    animate: bool,
    /// Wave time shown (advances while animating, kept when paused).
    time: f32,
    /// Whether the base has left the rest pose (every frame slot then gets the current pose).
    moved: bool,
}

struct App {
    args: ViewArgs,
    rm: RenderMesh,
    technique: Technique,
    bft: BftView,
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
            bft: None,
            renderer,
            mesh,
            swapchain,
            device,
            instance,
        });
        self.window = Some(window);
        Ok(())
    }

    /// The BFT surface, built on first use (tangent tables included, so G can toggle).
    fn bft_surface(gpu: &mut Gpu, view: &BftView) -> Result<()> {
        if gpu.bft.is_none() {
            gpu.bft = Some(BftSurface::new(
                &gpu.renderer,
                &view.mesh,
                &view.name,
                view.setup.table_level,
                true,
                FRAMES_IN_FLIGHT,
            )?);
        }
        Ok(())
    }

    fn draw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        if self.technique == Technique::Bft {
            Self::bft_surface(gpu, &self.bft)?;
        }
        let Some(frame) = gpu.swapchain.begin_frame()? else {
            return Ok(());
        };
        let dt = self.last_frame.elapsed().as_secs_f32();
        match (self.technique, gpu.bft.as_mut()) {
            (Technique::Bft, Some(surface)) => {
                let view = &mut self.bft;
                if view.animate {
                    view.time += dt;
                    view.moved = true;
                }
                if view.moved {
                    surface.update_base(frame.slot, &view.wave.at(view.time))?;
                }
                let bbox = (surface.bbox_min, surface.bbox_max);
                gpu.renderer
                    .update_frame(frame.slot, bbox, &self.params, frame.extent)?;
                let params = view.setup.world_params(bbox);
                surface.record_compute(frame.cmd, &gpu.renderer, frame.slot);
                gpu.swapchain
                    .cmd_begin_rendering(&frame, self.params.clear_color)?;
                let split = self.params.split;
                surface.record_draw(frame.cmd, &gpu.renderer, frame.slot, &params, split, false)?;
                if self.params.wireframe {
                    surface.record_draw(
                        frame.cmd,
                        &gpu.renderer,
                        frame.slot,
                        &params,
                        split,
                        true,
                    )?;
                }
            }
            (Technique::Tessellated(m), _) => {
                self.params.method = m;
                gpu.renderer
                    .update_uniforms(frame.slot, &gpu.mesh, &self.params, frame.extent)?;
                gpu.swapchain
                    .cmd_begin_rendering(&frame, self.params.clear_color)?;
                gpu.renderer
                    .record(frame.cmd, frame.slot, &gpu.mesh, &self.params)?;
            }
            (Technique::Bft, None) => unreachable!("built above"),
        }
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
                "tessera — {} — {:.2} ms/frame",
                self.describe(),
                self.frame_ms
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

    fn describe(&self) -> String {
        match self.technique {
            Technique::Tessellated(m) => {
                format!(
                    "{m:?} level {} {:?}",
                    self.params.level, self.params.spacing
                )
            }
            Technique::Bft => {
                let p = &self.bft.setup.params;
                format!(
                    "BFT {:?}{}{}{}{}",
                    p.factors,
                    if p.fractional { " fractional" } else { "" },
                    if p.geometric_normals {
                        " geometric normals"
                    } else {
                        ""
                    },
                    if p.patch_colours {
                        " patch colours"
                    } else {
                        ""
                    },
                    if self.bft.animate { " animated" } else { "" }
                )
            }
        }
    }

    /// Sets the uniform level, for BFT snapped to what its tables take.
    fn set_level(&mut self, level: f32) {
        let max_bft = (2u32 << self.bft.setup.table_level) as f32;
        self.params.level = level.clamp(1.0, 64.0);
        let p = &mut self.bft.setup.params;
        if let FactorPolicy::Uniform { segments } = &mut p.factors {
            let s = level.round().clamp(2.0, max_bft);
            *segments = if p.fractional {
                s as u32
            } else {
                (s as u32).next_power_of_two().min(max_bft as u32)
            };
        }
    }

    fn key(&mut self, key: &Key) {
        let bft = self.technique == Technique::Bft;
        let level = match &self.bft.setup.params.factors {
            FactorPolicy::Uniform { segments } if bft => *segments as f32,
            _ => self.params.level,
        };
        let step_up = if bft && !self.bft.setup.params.fractional {
            level * 2.0
        } else {
            level + 1.0
        };
        let step_down = if bft && !self.bft.setup.params.fractional {
            level * 0.5
        } else {
            level - 1.0
        };
        match key {
            Key::Character(c) => match c.as_str() {
                "1" => self.technique = Technique::Tessellated(Method::Flat),
                "2" => self.technique = Technique::Tessellated(Method::Phong),
                "3" => self.technique = Technique::Tessellated(Method::Pn),
                "4" => {
                    self.technique = Technique::Bft;
                    self.set_level(level);
                }
                "+" | "=" => self.set_level(step_up),
                "-" => self.set_level(step_down),
                "w" | "W" => self.params.wireframe = !self.params.wireframe,
                "a" | "A" => self.bft.animate = !self.bft.animate,
                "c" | "C" => {
                    let p = &mut self.bft.setup.params;
                    p.patch_colours = !p.patch_colours;
                }
                "f" | "F" => {
                    let p = &mut self.bft.setup.params;
                    p.fractional = !p.fractional;
                    self.set_level(level);
                }
                "g" | "G" => {
                    let p = &mut self.bft.setup.params;
                    p.geometric_normals = !p.geometric_normals;
                }
                _ => {}
            },
            Key::Named(NamedKey::ArrowUp) => self.set_level(level * 2.0),
            Key::Named(NamedKey::ArrowDown) => self.set_level(level * 0.5),
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
    let name = mesh_name(args.scene.mesh.as_deref());
    let (params, setup) = draw_params(&args.scene)?;
    let rm = RenderMesh::from_control_mesh(&mesh)?;
    // The BFT options hold even when the view starts on another technique (key 4 switches).
    let setup = match setup {
        Some(s) => s,
        None => {
            let mut surface = args.scene.surface.clone();
            surface.table_level = tess::bft::DEFAULT_TABLE_LEVEL;
            surface
                .setup(Technique::Bft, 16.0, tess::Spacing::Equal, false)?
                .context("bft setup")?
        }
    };
    let (loop_mesh, _, note) = loop_control_mesh(&mesh, &name);
    if let (Some(n), Technique::Bft) = (note, args.scene.method) {
        eprintln!("{n}");
    }
    let bft = BftView {
        wave: Wave::new(&loop_mesh),
        mesh: loop_mesh,
        name,
        animate: args.scene.animate,
        time: setup.frame.unwrap_or(0.0),
        moved: args.scene.animate || setup.frame.is_some(),
        setup,
    };
    let event_loop = EventLoop::new().context(
        "no window system (set DISPLAY or WAYLAND_DISPLAY; use `tessera render` headless)",
    )?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let mut app = App {
        technique: args.scene.method,
        args,
        rm,
        bft,
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
            bft,
            renderer,
            mesh,
            swapchain,
            device,
            instance,
        }) => {
            drop(bft);
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
