//! `tessera view`: a window with an orbit camera. Drag to orbit, wheel to zoom, 1, 2, 3, ...
//! switch technique in the registry's order (flat, Phong, PN, BFT, adaptive, gregory, acc),
//! +/- raise/lower the level to the next one the technique takes (BFT: the next power of two
//! unless fractional), arrows double/halve it, W toggles the wireframe; where the technique
//! takes them, A toggles the animation, C the patch colours, F fractional factors, G geometric
//! normals, and for the feature-adaptive surface I / Shift+I raise / lower the isolation level,
//! E switches the end caps (Gregory, bilinear), S / Shift+S scale every crease's sharpness up /
//! down (the surface is re-planned on the CPU; the mesh is not reloaded). On the textured
//! Catmull-Clark techniques (adaptive, gregory, acc) R toggles the texture reparameterization,
//! D the displacement, ] / [ scale the displacement by 1.25 up / down (turning it on), and V
//! cycles the view: shading, parameter shift, the Eq. 1 texture error (its lattice is built
//! then, once per surface);
//! without `--displace` D starts at [`DEFAULT_DISPLACE`] of the mesh's bounding-box diagonal.
//! P saves the next frame as `tessera-screenshot-N.png` in the working directory. An OBJ
//! dropped on the window replaces the mesh. Esc quits. The title shows what is drawn and the
//! frame time. `--frames N --screenshot out.png` renders N frames, saves the last and exits.
//!
//! The HUD (crate::hud, drawn through vk-core's overlay) shows the technique, its scheme, the
//! factor policy, the options and the patch-colour legend, the triangles and patches drawn, the
//! GPU time of each pass (timestamp queries, one pool per frame slot, read when the slot comes
//! round again, so never waited for) and a frame-time graph; each key has a control in it. H
//! hides and shows it. Screenshots are of the window as shown: with the HUD when it is shown.
//! It starts hidden with `--no-hud` and in `--screenshot` runs, whose picture is the scene alone
//! (as `tessera render` draws it).
//!
//! What the user does in the window never ends it with an error: a technique that cannot be
//! built for the mesh (after a key) or a dropped file that cannot be read or built is reported
//! on stderr and in the title, and the window goes on with what it drew before. Only the first
//! build, which the command line asked for, fails the command as `render` would. Techniques are built on first use and kept. `--stats` prints the GPU memory
//! allocated and the live Vulkan objects after [`WARM_UP`] frames, every 1,000 frames and at
//! exit (each after an idle wait, so objects retired by finished frames are counted as gone):
//! what a soak run (tools/soak.sh, the window tests) checks stays constant.
//!
//! Teardown: nothing waits for the frames in flight before the technique, context and swapchain
//! drop; vk-core's retire queue destroys each object only after the submissions that could use
//! it completed (the swapchain's own objects after an idle wait in its drop).
use crate::cli::ViewArgs;
use crate::commands::{
    check_drawable, check_validation, in_mesh_file, load_mesh_welded, load_mesh_with_lines,
    mesh_name, open_device, scene_setup,
};
use crate::hud::{Action, Hud, PassTimes, Shown};
use crate::technique::{describe, Setup};
use anyhow::{Context as _, Result};
use raw_window_handle::HasDisplayHandle;
use std::collections::HashMap;
use std::sync::Arc;
use std::time::Instant;
use tess::animation::Wave;
use tess::techniques;
use tess::{Context, FactorPolicy, Spacing, Technique, TechniqueId};
use topology::mesh::obj::ObjLines;
use topology::ControlMesh;
use vk_core::swapchain::{required_surface_extensions, Swapchain, FRAMES_IN_FLIGHT};
use vk_core::target::DEPTH_FORMAT;
use vk_core::{vk, Device, Instance, Overlay, OverlayDesc, QueryPool};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::keyboard::{Key, NamedKey};
use winit::window::{Window, WindowId};

/// Frames after which `--stats` first reports: every frame slot has been used and every
/// per-slot resource made, so later figures must equal this one.
pub const WARM_UP: u32 = 10;

/// A technique built for the window, with its animation wave.
struct Surface {
    technique: Box<dyn Technique>,
    wave: Option<Wave>,
}

/// Timestamps of one frame slot: pre-pass (0, 1), draw (2, 3), HUD (4, 5).
const TIMESTAMPS: u32 = 6;

/// One timestamp pool per frame slot, each read when its slot is acquired again (its previous
/// frame has then completed, so the read does not wait).
struct Timer {
    pools: Vec<QueryPool>,
    /// Whether the slot's pool holds a recorded frame's timestamps.
    written: Vec<bool>,
}

/// GPU state that lives while the window does. Drop order: surfaces, overlay, timer, context,
/// swapchain, then the device and instance; the window itself is dropped after all of them.
struct Gpu {
    surfaces: HashMap<TechniqueId, Surface>,
    overlay: Overlay,
    /// `None` where the queue has no timestamps.
    timer: Option<Timer>,
    context: Context,
    swapchain: Swapchain,
    device: Device,
    instance: Arc<Instance>,
}

struct App {
    args: ViewArgs,
    mesh: ControlMesh,
    /// The line of every element of `mesh` in its file, for errors about it.
    lines: ObjLines,
    setup: Setup,
    /// The setup of the last frame drawn, to go back to when a key asks for a surface that
    /// cannot be built.
    last_good: Option<Setup>,
    /// What the user should know of the last action that failed (shown in the title).
    status: Option<String>,
    /// P was pressed: the next frame is saved.
    shot_requested: bool,
    /// Screenshots saved by P so far (numbers the files).
    shots: u32,
    /// Wave time shown (advances while animating, kept when paused).
    time: f32,
    /// Whether the base has left the rest pose (every frame slot then gets the current pose).
    moved: bool,
    /// A level to snap once the technique switched to is built.
    pending_level: Option<f32>,
    /// The current surface must be built again (isolation, end caps or sharpness changed).
    rebuild: bool,
    /// The displacement scale D turns back on (`params.displace` is 0 while it is off).
    displace_scale: f32,
    gpu: Option<Gpu>,
    window: Option<Arc<Window>>,
    frames_drawn: u32,
    dragging: bool,
    last_cursor: Option<(f64, f64)>,
    last_frame: Instant,
    frame_ms: f64,
    /// When the first frame was drawn (`--stats` reports the time since).
    started: Option<Instant>,
    error: Option<anyhow::Error>,
    hud: Option<Hud>,
    /// Asked for by the HUD during the frame: applied once it is presented.
    actions: Vec<Action>,
    /// The GPU times of the last frame read back.
    pass_times: Option<PassTimes>,
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
        let (instance, device) = open_device(
            &self.args.scene.gpu,
            required_surface_extensions(display)?,
            &[Swapchain::DEVICE_EXTENSION],
        )?;
        let size = window.inner_size();
        let swapchain = Swapchain::for_window(
            &device,
            window.clone(),
            vk::Extent2D {
                width: size.width,
                height: size.height,
            },
        )?;
        let context = Context::new(&device, swapchain.format, DEPTH_FORMAT, FRAMES_IN_FLIGHT)?;
        let overlay = Overlay::new(
            &device,
            &OverlayDesc {
                color_format: swapchain.format,
                depth_format: Some(DEPTH_FORMAT),
                frames_in_flight: FRAMES_IN_FLIGHT,
            },
        )?;
        let timer = if device.info.caps.timestamps {
            let pools = (0..FRAMES_IN_FLIGHT)
                .map(|i| {
                    QueryPool::timestamps(&device, &format!("frame {i} timestamps"), TIMESTAMPS)
                })
                .collect::<vk_core::Result<Vec<_>>>()?;
            Some(Timer {
                written: vec![false; pools.len()],
                pools,
            })
        } else {
            None
        };
        self.hud = Some(Hud::new(
            &window,
            !self.args.no_hud && self.args.screenshot.is_none(),
        ));
        self.gpu = Some(Gpu {
            surfaces: HashMap::new(),
            overlay,
            timer,
            context,
            swapchain,
            device,
            instance,
        });
        self.window = Some(window);
        Ok(())
    }

    /// `setup`'s technique built for `mesh` (with what every key may need, e.g. tangent tables
    /// for geometric normals).
    fn build_surface(
        gpu: &mut Gpu,
        (mesh, lines): (&ControlMesh, &ObjLines),
        setup: &Setup,
    ) -> Result<Surface> {
        let mut build = setup.build.clone();
        build.tangents = techniques::info(setup.technique).features.geometric_normals;
        let built = crate::progress::during(
            format!("building {} for {}", setup.technique, build.name),
            || tess::build(&mut gpu.context, setup.technique, mesh, &build),
        )
        .map_err(|e| in_mesh_file(e, setup.technique, mesh, lines))?;
        for n in &built.notes {
            eprintln!("{n}");
        }
        let wave = built.technique.base_mesh().map(Wave::new);
        Ok(Surface {
            technique: built.technique,
            wave,
        })
    }

    /// The current technique's surface, built on first use.
    fn surface(gpu: &mut Gpu, mesh: (&ControlMesh, &ObjLines), setup: &Setup) -> Result<()> {
        if !gpu.surfaces.contains_key(&setup.technique) {
            let surface = Self::build_surface(gpu, mesh, setup)?;
            gpu.surfaces.insert(setup.technique, surface);
        }
        Ok(())
    }

    /// Reports a failed action (stderr and the title) without ending the window.
    fn report(&mut self, what: String) {
        eprintln!("{what}");
        self.status = Some(what);
    }

    /// Opens the OBJ or USD file dropped on the window: read, built with the current setup and shown in
    /// place of the mesh; on any error the window keeps the mesh it had.
    fn open_dropped(&mut self, path: &std::path::Path) {
        let name = path.display().to_string();
        let loaded = load_mesh_with_lines(Some(path))
            .and_then(|(m, l)| check_drawable(&m, &l, &name, true).map(|()| (m, l)));
        let (mesh, lines) = match loaded {
            Ok(m) => m,
            Err(e) => return self.report(format!("cannot open {name}: {}", crate::message(&e))),
        };
        let Some(gpu) = self.gpu.as_mut() else {
            return;
        };
        let mut setup = self.setup.clone();
        setup.build.name = name.clone();
        match Self::build_surface(gpu, (&mesh, &lines), &setup) {
            Ok(surface) => {
                // Frames in flight keep the old surfaces' buffers alive (vk-core defers
                // destruction).
                gpu.surfaces.clear();
                gpu.surfaces.insert(setup.technique, surface);
                self.mesh = mesh;
                self.lines = lines;
                self.setup = setup;
                self.moved = self.setup.moved();
                self.status = None;
                eprintln!("opened {name}");
            }
            Err(e) => self.report(format!(
                "cannot draw {name} with {}: {}",
                setup.technique,
                crate::message(&e)
            )),
        }
    }

    /// One frame, in steps: the surface (re)built, the HUD laid out, the pass times of the
    /// slot's previous frame read, the frame recorded and presented, then the bookkeeping
    /// (stats, frame time, title, screenshots) and the HUD's actions.
    fn draw(&mut self, event_loop: &ActiveEventLoop) -> Result<()> {
        if !self.ensure_surface()? {
            return Ok(());
        }
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(());
        };
        let Gpu {
            surfaces,
            overlay,
            timer,
            context,
            swapchain,
            device,
            ..
        } = gpu;
        let surface = surfaces
            .get_mut(&self.setup.technique)
            .context("the surface built above")?;
        let params = self.setup.world_params(surface.technique.bbox());
        // Laid out before the frame is acquired: a texture change waits for the device.
        let hud = match (&mut self.hud, &self.window) {
            (Some(hud), Some(window)) => {
                let technique = surface.technique.as_ref();
                let arrays = technique.patch_arrays();
                let shown = Shown {
                    mesh: &self.setup.build.name,
                    technique: self.setup.technique,
                    params: &params,
                    build: &self.setup.build,
                    path: technique.draw_path(),
                    animate: self.setup.animate,
                    displace_scale: self.displace_scale,
                    triangles: (0..arrays.len())
                        .map(|a| technique.triangles(&params, a))
                        .sum(),
                    patches: arrays.iter().map(|a| u64::from(a.patches)).sum(),
                    gpu: self.pass_times,
                    status: self.status.as_deref(),
                };
                lay_out_hud(hud, window, &shown, &mut self.actions, overlay)?
            }
            _ => None,
        };
        let Some(mut frame) = swapchain.acquire()? else {
            return Ok(());
        };
        let (slot, extent) = (frame.slot(), frame.extent());
        if let Some(times) = read_pass_times(timer.as_mut(), slot)? {
            self.pass_times = Some(times);
        }
        let pool = timer.as_ref().map(|t| &t.pools[slot]);
        let dt = self.last_frame.elapsed().as_secs_f32();
        if self.setup.animate {
            self.time += dt;
            self.moved = true;
        }
        if let (true, Some(wave)) = (self.moved, &surface.wave) {
            surface.technique.update_base(slot, &wave.at(self.time))?;
        }
        context.write_frame(slot, surface.technique.bbox(), &params, extent)?;
        context.prepare(
            surface.technique.as_mut(),
            &params,
            Context::frame_passes(&params),
        )?;
        let technique = surface.technique.as_ref();
        let last = self.args.frames.is_some_and(|n| self.frames_drawn + 1 >= n);
        let recorded = Recorded {
            context,
            technique,
            params: &params,
            pool,
            hud: hud.as_ref(),
        };
        record_frame(&mut frame, overlay, &recorded)?;
        let final_shot = last && self.args.screenshot.is_some();
        let asked = std::mem::take(&mut self.shot_requested);
        let shot = frame.present(final_shot || asked)?;
        self.frames_drawn += 1;
        self.last_good = Some(self.setup.clone());
        let started = *self.started.get_or_insert_with(Instant::now);
        let n = self.frames_drawn;
        if self.args.stats && (n == WARM_UP || n.is_multiple_of(1000) || last) {
            device.wait_idle();
            print_stats(&format!("frame {n}"), device, started);
        }
        let now = Instant::now();
        let interval = (now - self.last_frame).as_secs_f64() * 1e3;
        self.frame_ms = 0.9 * self.frame_ms + 0.1 * interval;
        if let Some(hud) = &mut self.hud {
            hud.push_frame_time(interval);
        }
        self.last_frame = now;
        self.set_title(&params);
        if let Some(img) = shot {
            self.save_shots(&img, asked, final_shot, &params)?;
        }
        for action in std::mem::take(&mut self.actions) {
            self.act(action, event_loop);
        }
        if last {
            event_loop.exit();
        }
        Ok(())
    }

    /// Builds the current technique's surface if it is missing or a key asked for a rebuild.
    /// When a key's choice cannot be drawn, goes back to what was drawn and says why (false:
    /// skip this frame); the first build is the command line's and fails the command.
    fn ensure_surface(&mut self) -> Result<bool> {
        let Some(gpu) = self.gpu.as_mut() else {
            return Ok(false);
        };
        if std::mem::take(&mut self.rebuild) {
            // Frames in flight keep their buffers alive (vk-core defers destruction).
            gpu.surfaces.remove(&self.setup.technique);
        }
        if let Err(e) = Self::surface(gpu, (&self.mesh, &self.lines), &self.setup) {
            // A key asked for it: go back to what was drawn. The first build is the command
            // line's: it fails the command.
            let Some(good) = self.last_good.clone() else {
                return Err(e);
            };
            let what = format!(
                "cannot draw {} that way: {}",
                self.setup.technique,
                crate::message(&e)
            );
            self.setup = good;
            self.pending_level = None;
            self.report(what);
            return Ok(false);
        }
        if let Some(l) = self.pending_level.take() {
            self.set_level(l, true);
        }
        Ok(true)
    }

    /// The window title: the technique and its frame, isolation options, animation, the
    /// frame time and the status line.
    fn set_title(&self, params: &tess::FrameParams) {
        if let Some(w) = &self.window {
            w.set_title(&format!(
                "tessera — {}, {} path{}{} — {:.2} ms/frame{}",
                describe(self.setup.technique, params),
                self.gpu_path().unwrap_or(tess::DrawPath::Tessellation),
                if techniques::info(self.setup.technique).features.isolation {
                    let b = &self.setup.build;
                    format!(
                        ", isolation {}, {} end caps, sharpness ×{:.2}",
                        b.isolation,
                        end_cap_name(b.end_cap),
                        b.sharpness_scale
                    )
                } else {
                    String::new()
                },
                if self.setup.animate { ", animated" } else { "" },
                self.frame_ms,
                self.status
                    .as_deref()
                    .map(|s| format!(" — {s}"))
                    .unwrap_or_default()
            ));
        }
    }

    /// Writes the screenshot a key asked for (`P`, numbered) and the command line's final
    /// `--screenshot`, refusing a blank final image.
    fn save_shots(
        &mut self,
        img: &vk_core::target::Rgba8,
        asked: bool,
        final_shot: bool,
        params: &tess::FrameParams,
    ) -> Result<()> {
        if asked {
            self.shots += 1;
            let path = std::path::PathBuf::from(format!("tessera-screenshot-{}.png", self.shots));
            match crate::output::write_png(&path, img) {
                Ok(()) => out!("wrote {} (P)", path.display()),
                Err(e) => self.report(crate::message(&e)),
            }
        }
        if let (true, Some(path)) = (final_shot, &self.args.screenshot) {
            if crate::output::is_blank(img, params.clear_color) {
                anyhow::bail!(
                    "{}: nothing was drawn in frame {} (every pixel is the background); \
                     {} not written",
                    self.setup.build.name,
                    self.frames_drawn,
                    path.display()
                );
            }
            crate::output::write_png(path, img)?;
            out!(
                "wrote {} after {} frame{}",
                path.display(),
                self.frames_drawn,
                if self.frames_drawn == 1 { "" } else { "s" }
            );
        }
        Ok(())
    }

    /// The draw path of the current technique's built surface.
    fn gpu_path(&self) -> Option<tess::DrawPath> {
        let gpu = self.gpu.as_ref()?;
        Some(
            gpu.surfaces
                .get(&self.setup.technique)?
                .technique
                .draw_path(),
        )
    }

    /// Whether the current technique (its surface already built) draws `params`.
    fn accepts(&self, params: &tess::FrameParams) -> bool {
        let Some(gpu) = &self.gpu else {
            return true;
        };
        match gpu.surfaces.get(&self.setup.technique) {
            Some(s) => s.technique.check(params).is_ok(),
            None => true,
        }
    }

    /// Sets the uniform segments per edge, snapped to what the technique takes: the nearest
    /// accepted value from `level` in the direction of the change.
    fn set_level(&mut self, level: f32, up: bool) {
        let FactorPolicy::Uniform { segments } = self.setup.params.factors else {
            return;
        };
        let mut candidate = level.round().clamp(1.0, 64.0);
        for _ in 0..64 {
            let mut p = self.setup.params;
            p.factors = FactorPolicy::Uniform {
                segments: candidate,
            };
            if self.accepts(&p) {
                self.setup.params = p;
                return;
            }
            candidate = if up { candidate + 1.0 } else { candidate - 1.0 };
            if !(1.0..=64.0).contains(&candidate) {
                break;
            }
        }
        self.setup.params.factors = FactorPolicy::Uniform { segments };
    }

    /// Switches technique (keys 1, 2, …, 9, 0: the registry's order), keeping the level where
    /// the new technique takes it.
    fn switch_technique(&mut self, id: TechniqueId) {
        self.setup.technique = id;
        let f = techniques::info(id).features;
        if !f.spacing(self.setup.params.spacing) {
            self.setup.params.spacing = Spacing::Equal;
        }
        if let FactorPolicy::Uniform { segments } = self.setup.params.factors {
            self.pending_level = Some(segments);
        }
    }

    /// The action a key asks for (the HUD's controls ask for the same ones).
    fn key_action(key: &Key) -> Option<Action> {
        Some(match key {
            Key::Character(c) => match c.as_str() {
                d if d.len() == 1 && d.as_bytes()[0].is_ascii_digit() => {
                    // 1..9 then 0, in the keyboard's order: the first ten techniques.
                    let k = (d.as_bytes()[0] - b'0') as usize;
                    let info = techniques::registry().get((k + 9) % 10)?;
                    Action::Technique(info.id)
                }
                "+" | "=" => Action::LevelUp,
                "-" => Action::LevelDown,
                "w" | "W" => Action::Wireframe,
                "p" | "P" => Action::Screenshot,
                "h" | "H" => Action::ToggleHud,
                "a" | "A" => Action::Animate,
                "c" | "C" => Action::PatchColours,
                "f" | "F" => Action::Fractional,
                "g" | "G" => Action::GeometricNormals,
                "i" => Action::IsolationUp,
                "I" => Action::IsolationDown,
                "e" | "E" => Action::EndCaps,
                "s" => Action::SharpnessUp,
                "S" => Action::SharpnessDown,
                "r" | "R" => Action::Reparam,
                "d" | "D" => Action::Displace,
                "]" => Action::DisplaceUp,
                "v" | "V" => Action::Show,
                "t" | "T" => Action::Pipeline,
                "[" => Action::DisplaceDown,
                _ => return None,
            },
            Key::Named(NamedKey::Tab) => Action::NextTechnique,
            Key::Named(NamedKey::ArrowUp) => Action::LevelDouble,
            Key::Named(NamedKey::ArrowDown) => Action::LevelHalve,
            Key::Named(NamedKey::Escape) => Action::Quit,
            _ => return None,
        })
    }

    /// Carries out `action` where the current technique takes it (otherwise nothing happens).
    fn act(&mut self, action: Action, event_loop: &ActiveEventLoop) {
        let features = techniques::info(self.setup.technique).features;
        let level = self.setup.params.uniform_segments().unwrap_or(8.0);
        let p = &mut self.setup.params;
        match action {
            Action::Technique(id) => self.switch_technique(id),
            Action::NextTechnique => self.switch_technique(next_technique(self.setup.technique)),
            Action::LevelUp => self.set_level(level + 1.0, true),
            Action::LevelDown => self.set_level(level - 1.0, false),
            Action::LevelDouble => self.set_level(level * 2.0, true),
            Action::LevelHalve => self.set_level(level * 0.5, false),
            Action::Wireframe => p.wireframe = !p.wireframe,
            Action::Screenshot => self.shot_requested = true,
            Action::ToggleHud => {
                if let Some(hud) = &mut self.hud {
                    hud.visible = !hud.visible;
                }
            }
            Action::Quit => event_loop.exit(),
            Action::Pipeline if features.paths.contains(&tess::DrawPath::Pattern) => {
                self.setup.build.pipeline = match self.gpu_path() {
                    Some(tess::DrawPath::Pattern) => tess::PipelineChoice::Tessellation,
                    _ => tess::PipelineChoice::Pattern,
                };
                self.rebuild = true;
            }
            Action::Animate if features.animation => self.setup.animate = !self.setup.animate,
            Action::PatchColours if features.patch_colours => p.patch_colours = !p.patch_colours,
            Action::Fractional => {
                let next = if p.spacing == Spacing::Equal {
                    Spacing::FractionalEven
                } else {
                    Spacing::Equal
                };
                if features.spacing(next) {
                    p.spacing = next;
                    self.set_level(level, true);
                }
            }
            Action::GeometricNormals if features.geometric_normals => {
                p.geometric_normals = !p.geometric_normals
            }
            Action::IsolationUp | Action::IsolationDown if features.isolation => {
                let b = &mut self.setup.build;
                let next = if action == Action::IsolationUp {
                    (b.isolation + 1).min(8)
                } else {
                    b.isolation.saturating_sub(1).max(1)
                };
                self.rebuild |= next != b.isolation;
                b.isolation = next;
            }
            Action::EndCaps if features.isolation => {
                let b = &mut self.setup.build;
                b.end_cap = match b.end_cap {
                    topology::patches::adaptive::EndCap::Gregory => {
                        topology::patches::adaptive::EndCap::Bilinear
                    }
                    topology::patches::adaptive::EndCap::Bilinear => {
                        topology::patches::adaptive::EndCap::Gregory
                    }
                };
                self.rebuild = true;
            }
            Action::SharpnessUp | Action::SharpnessDown if features.isolation => {
                let b = &mut self.setup.build;
                b.sharpness_scale = if action == Action::SharpnessUp {
                    (b.sharpness_scale * 1.25).min(64.0)
                } else {
                    b.sharpness_scale / 1.25
                };
                self.rebuild = true;
            }
            Action::Reparam | Action::Displace | Action::DisplaceUp | Action::DisplaceDown
                if features.surface =>
            {
                surface_key(p, &mut self.displace_scale, action)
            }
            Action::Show if features.surface => {
                p.show = next_show(p.show);
                // The Eq. 1 lattice is computed when the surface is built, on request.
                if p.show == tess::surface::SurfaceShow::ParamError
                    && !self.setup.build.maps.param_error
                {
                    self.setup.build.maps.param_error = true;
                    self.rebuild = true;
                }
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
        let taken = match (&mut self.hud, &self.window) {
            (Some(hud), Some(window)) => hud.on_event(window, &event),
            _ => false,
        };
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
            WindowEvent::KeyboardInput { event, .. }
                if event.state == ElementState::Pressed && !taken =>
            {
                if let Some(action) = Self::key_action(&event.logical_key) {
                    self.act(action, event_loop);
                }
            }
            WindowEvent::DroppedFile(path) => self.open_dropped(&path),
            WindowEvent::MouseInput {
                state,
                button: MouseButton::Left,
                ..
            } => {
                // A press on the HUD is its own; a release always ends a drag.
                self.dragging = state == ElementState::Pressed && !taken;
                self.last_cursor = None;
            }
            WindowEvent::CursorMoved { position, .. } if self.dragging => {
                if let Some((x, y)) = self.last_cursor {
                    self.setup.params.camera.yaw -= (position.x - x) as f32 * 0.4;
                    self.setup.params.camera.pitch = (self.setup.params.camera.pitch
                        + (position.y - y) as f32 * 0.4)
                        .clamp(-89.0, 89.0);
                }
                self.last_cursor = Some((position.x, position.y));
            }
            WindowEvent::MouseWheel { delta, .. } if !taken => {
                let steps = match delta {
                    MouseScrollDelta::LineDelta(_, y) => y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.setup.params.camera.zoom =
                    (self.setup.params.camera.zoom * 1.1f32.powf(steps)).clamp(0.1, 20.0);
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
    if let Some(p) = &args.screenshot {
        crate::output::check_png_name(p, "--screenshot")?;
    }
    let name = mesh_name(args.scene.mesh.as_deref());
    let (mesh, lines) = load_mesh_welded(
        args.scene.mesh.as_deref(),
        args.scene.surface.weld,
        args.scene.surface.uv_interpolation,
    )?;
    check_drawable(&mesh, &lines, &name, true)?;
    let setup = scene_setup(&args.scene, &name, &mesh)?;
    // winit's OS errors name a source file of winit itself: not for users.
    let event_loop = EventLoop::new().map_err(|e| match e {
        winit::error::EventLoopError::Os(_) => anyhow::anyhow!(
            "no window system (set DISPLAY or WAYLAND_DISPLAY; use `tessera render` headless)"
        ),
        other => anyhow::anyhow!("cannot open the window system: {other}"),
    })?;
    event_loop.set_control_flow(ControlFlow::Poll);
    let displace_scale = initial_displace_scale(setup.params.displace, &mesh);
    let mut app = App {
        displace_scale,
        time: setup.frame.unwrap_or(0.0),
        moved: setup.moved(),
        setup,
        args,
        mesh,
        lines,
        last_good: None,
        status: None,
        shot_requested: false,
        shots: 0,
        pending_level: None,
        rebuild: false,
        gpu: None,
        window: None,
        frames_drawn: 0,
        dragging: false,
        last_cursor: None,
        last_frame: Instant::now(),
        frame_ms: 0.0,
        started: None,
        error: None,
        hud: None,
        actions: Vec::new(),
        pass_times: None,
    };
    event_loop.run_app(&mut app).context("event loop")?;
    let gpu = app.gpu.take();
    let result = match gpu {
        Some(Gpu {
            surfaces,
            overlay,
            timer,
            context,
            swapchain,
            device,
            instance,
        }) => {
            drop((surfaces, overlay, timer, context, swapchain));
            if app.args.stats {
                // Every frame resource is gone; the one-shot command pools the device keeps
                // for reuse go too, so what is counted is what leaked.
                device.wait_idle();
                device.release_idle_command_pools();
                print_stats("exit", &device, app.started.unwrap_or_else(Instant::now));
            }
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

/// The displacement scale D turns on where `--displace` gave none (or 0), as a fraction of the
/// mesh's bounding-box diagonal: a height of 1 lifts the surface by 2% of its size, clearly
/// visible on spot with its height map or the procedural bumps and far from folding it.
pub(crate) const DEFAULT_DISPLACE: f32 = 0.02;

/// Keys ] and [ multiply / divide the displacement scale by this.
const DISPLACE_STEP: f32 = 1.25;

/// The scale magnitudes the keys keep to: `--displace`'s limit above, and well away from 0
/// below (so [ never turns displacement off by underflow).
const DISPLACE_RANGE: (f32, f32) = (1e-6, 1e3);

/// The scale D restores at start: `--displace S` where S is not 0, else [`DEFAULT_DISPLACE`]
/// of `mesh`'s bounding-box diagonal.
fn initial_displace_scale(displace: f32, mesh: &ControlMesh) -> f32 {
    if displace != 0.0 {
        return displace;
    }
    let scale = DEFAULT_DISPLACE * mesh.bbox_diagonal() as f32;
    if scale.is_finite() && scale >= DISPLACE_RANGE.0 {
        scale.min(DISPLACE_RANGE.1)
    } else {
        DISPLACE_RANGE.0.max(DEFAULT_DISPLACE)
    }
}

/// Tab: the registry's technique after `id`, the first after the last.
fn next_technique(id: TechniqueId) -> TechniqueId {
    let all = techniques::registry();
    let at = all.iter().position(|i| i.id == id).unwrap_or(all.len() - 1);
    all[(at + 1) % all.len()].id
}

/// V: shading, then the reparameterization's parameter shift, then the Eq. 1 texture error.
fn next_show(show: tess::surface::SurfaceShow) -> tess::surface::SurfaceShow {
    use tess::surface::SurfaceShow::*;
    match show {
        Shading => ParamShift,
        ParamShift => ParamError,
        ParamError => Shading,
    }
}

/// R, D, ] and [ (techniques with [`tess::Features::surface`]): `scale` is the displacement D
/// turns back on; it equals `params.displace` whenever displacement is on.
fn surface_key(params: &mut tess::FrameParams, scale: &mut f32, action: Action) {
    match action {
        Action::Reparam => params.reparam = !params.reparam,
        Action::Displace if params.displace != 0.0 => {
            *scale = params.displace;
            params.displace = 0.0;
        }
        Action::Displace => params.displace = *scale,
        Action::DisplaceUp | Action::DisplaceDown => {
            let factor = if action == Action::DisplaceUp {
                DISPLACE_STEP
            } else {
                DISPLACE_STEP.recip()
            };
            let next = *scale * factor;
            let (min, max) = DISPLACE_RANGE;
            *scale = next.signum() * next.abs().clamp(min, max);
            params.displace = *scale;
        }
        _ => {}
    }
}

/// The HUD laid out for `shown`: its tessellated primitives and pixels per point, its
/// textures uploaded (None when egui has nothing to draw).
fn lay_out_hud(
    hud: &mut Hud,
    window: &Window,
    shown: &Shown,
    actions: &mut Vec<Action>,
    overlay: &mut Overlay,
) -> Result<Option<(Vec<egui::ClippedPrimitive>, f32)>> {
    let Some(mut out) = hud.run(window, shown, actions) else {
        return Ok(None);
    };
    overlay.update_textures(&mut out.textures_delta)?;
    let ppp = out.pixels_per_point;
    Ok(Some((hud.tessellate(out.shapes, ppp), ppp)))
}

/// The pass times of the slot's previous frame, once written (acquire waited for that frame:
/// no stall).
fn read_pass_times(timer: Option<&mut Timer>, slot: usize) -> Result<Option<PassTimes>> {
    let Some(t) = timer else {
        return Ok(None);
    };
    let mut times = None;
    if t.written[slot] {
        if let [pre_pass, draw, hud] = t.pools[slot].durations_ns()?[..] {
            times = Some(PassTimes {
                pre_pass: pre_pass * 1e-6,
                draw: draw * 1e-6,
                hud: hud * 1e-6,
            });
        }
    }
    t.written[slot] = true;
    Ok(times)
}

/// What a frame records: the technique's passes with `params`, timestamps into `pool`, and the
/// HUD's primitives.
struct Recorded<'a> {
    context: &'a Context,
    technique: &'a dyn Technique,
    params: &'a tess::FrameParams,
    pool: Option<&'a QueryPool>,
    hud: Option<&'a (Vec<egui::ClippedPrimitive>, f32)>,
}

/// Records the pre-pass, the drawn surface and the HUD, each between timestamps.
fn record_frame<'a>(
    frame: &mut vk_core::swapchain::SwapchainFrame<'a>,
    overlay: &'a mut Overlay,
    r: &Recorded<'a>,
) -> Result<()> {
    let (top, bottom) = (
        vk::PipelineStageFlags::TOP_OF_PIPE,
        vk::PipelineStageFlags::BOTTOM_OF_PIPE,
    );
    let slot = frame.slot();
    let extent = frame.extent();
    if let Some(pool) = r.pool {
        frame.encoder().reset_queries(pool);
    }
    stamp(frame.encoder(), r.pool, 0, top)?;
    r.context
        .record_pre_pass(frame.encoder(), r.technique, slot)?;
    stamp(frame.encoder(), r.pool, 1, bottom)?;
    stamp(frame.encoder(), r.pool, 2, top)?;
    frame.begin_frame_rendering(r.params.clear_color);
    r.context
        .record_frame(frame.encoder(), r.technique, slot, r.params)?;
    stamp(frame.encoder(), r.pool, 3, bottom)?;
    stamp(frame.encoder(), r.pool, 4, top)?;
    if let Some((primitives, ppp)) = r.hud {
        overlay.draw(frame.encoder(), extent, *ppp, primitives)?;
    }
    frame.encoder().end_rendering();
    stamp(frame.encoder(), r.pool, 5, bottom)?;
    Ok(())
}

/// Writes timestamp `index` of the frame's pool, where the queue has timestamps.
fn stamp<'a>(
    encoder: &mut vk_core::Encoder<'a>,
    pool: Option<&'a QueryPool>,
    index: u32,
    stage: vk::PipelineStageFlags,
) -> vk_core::Result<()> {
    match pool {
        Some(pool) => encoder.write_timestamp(pool, stage, index),
        None => Ok(()),
    }
}

/// `--end-cap`'s spelling of an end cap.
pub(crate) fn end_cap_name(e: topology::patches::adaptive::EndCap) -> &'static str {
    match e {
        topology::patches::adaptive::EndCap::Gregory => "gregory",
        topology::patches::adaptive::EndCap::Bilinear => "bilinear",
    }
}

/// One `--stats` line: `stats: <when>: <bytes> bytes allocated, <n> live Vulkan objects, <s> s`.
fn print_stats(when: &str, device: &Device, started: Instant) {
    out!(
        "stats: {when}: {} bytes allocated, {} live Vulkan objects, {:.1} s",
        device.allocated_bytes(),
        device.live_objects(),
        started.elapsed().as_secs_f64()
    );
}

#[cfg(test)]
mod tests {
    use super::*;
    use winit::keyboard::SmolStr;

    fn key(c: &str) -> Option<Action> {
        App::key_action(&Key::Character(SmolStr::new(c)))
    }

    fn key_named(k: NamedKey) -> Option<Action> {
        App::key_action(&Key::Named(k))
    }

    #[test]
    fn v_cycles_every_surface_view() {
        use tess::surface::SurfaceShow::*;
        let mut seen = vec![Shading];
        let mut show = Shading;
        for _ in 0..3 {
            show = next_show(show);
            seen.push(show);
        }
        assert_eq!(seen, [Shading, ParamShift, ParamError, Shading]);
    }

    #[test]
    fn keys_map_to_their_actions() {
        // Method keys: the registry's order, 1-9 then 0 (the tenth); more are chosen from the
        // HUD's list.
        let order: Vec<TechniqueId> = techniques::registry().iter().map(|i| i.id).collect();
        for (i, id) in order.iter().enumerate().take(10) {
            assert_eq!(
                key(&((i + 1) % 10).to_string()),
                Some(Action::Technique(*id))
            );
        }
        assert_eq!(
            key("6"),
            Some(Action::Technique("gregory".parse().unwrap()))
        );
        assert_eq!(key("7"), Some(Action::Technique("acc".parse().unwrap())));
        assert_eq!(
            key("5"),
            Some(Action::Technique("adaptive".parse().unwrap()))
        );
        assert_eq!(key_named(NamedKey::Tab), Some(Action::NextTechnique));
        let all = techniques::registry();
        let mut id = all[0].id;
        for step in 1..=all.len() {
            id = next_technique(id);
            assert_eq!(id, all[step % all.len()].id, "Tab {step} times");
        }
        let past = techniques::registry().len() + 1;
        if past <= 10 {
            assert_eq!(key(&(past % 10).to_string()), None);
        }
        for (c, action) in [
            ("r", Action::Reparam),
            ("R", Action::Reparam),
            ("d", Action::Displace),
            ("D", Action::Displace),
            ("]", Action::DisplaceUp),
            ("[", Action::DisplaceDown),
            ("v", Action::Show),
            ("V", Action::Show),
            ("t", Action::Pipeline),
            ("T", Action::Pipeline),
            // The keys that were there before keep their meaning.
            ("w", Action::Wireframe),
            ("s", Action::SharpnessUp),
            ("S", Action::SharpnessDown),
            ("i", Action::IsolationUp),
            ("I", Action::IsolationDown),
            ("e", Action::EndCaps),
            ("+", Action::LevelUp),
            ("-", Action::LevelDown),
        ] {
            assert_eq!(key(c), Some(action), "key {c}");
        }
        assert_eq!(key("x"), None);
        assert_eq!(
            App::key_action(&Key::Named(NamedKey::Escape)),
            Some(Action::Quit)
        );
    }

    #[test]
    fn reparam_key_toggles() {
        let mut p = tess::FrameParams::default();
        let mut scale = 0.5;
        assert!(p.reparam);
        surface_key(&mut p, &mut scale, Action::Reparam);
        assert!(!p.reparam);
        surface_key(&mut p, &mut scale, Action::Reparam);
        assert!(p.reparam);
        assert_eq!(
            (p.displace, scale),
            (0.0, 0.5),
            "R leaves displacement alone"
        );
    }

    #[test]
    fn displacement_keys_toggle_and_scale_keeping_the_scale() {
        let mut p = tess::FrameParams::default();
        let mut scale = 0.04;
        // D on at the remembered scale, off again keeping it.
        surface_key(&mut p, &mut scale, Action::Displace);
        assert_eq!(p.displace, 0.04);
        surface_key(&mut p, &mut scale, Action::Displace);
        assert_eq!((p.displace, scale), (0.0, 0.04));
        // ] while off: on, 1.25 times larger; [ back.
        surface_key(&mut p, &mut scale, Action::DisplaceUp);
        assert!((p.displace - 0.05).abs() < 1e-7 && scale == p.displace);
        surface_key(&mut p, &mut scale, Action::DisplaceDown);
        assert!((p.displace - 0.04).abs() < 1e-7 && scale == p.displace);
        // Off and on again brings the scaled value back.
        surface_key(&mut p, &mut scale, Action::DisplaceDown);
        let scaled = p.displace;
        surface_key(&mut p, &mut scale, Action::Displace);
        surface_key(&mut p, &mut scale, Action::Displace);
        assert_eq!(p.displace, scaled);
        // A --displace given on the command line that differs from the remembered scale is
        // what D keeps.
        p.displace = -0.3;
        surface_key(&mut p, &mut scale, Action::Displace);
        assert_eq!((p.displace, scale), (0.0, -0.3));
        // The sign stays; the magnitude keeps to --displace's range and never reaches 0.
        for _ in 0..100 {
            surface_key(&mut p, &mut scale, Action::DisplaceUp);
        }
        assert_eq!(p.displace, -DISPLACE_RANGE.1);
        for _ in 0..1000 {
            surface_key(&mut p, &mut scale, Action::DisplaceDown);
        }
        assert_eq!(p.displace, -DISPLACE_RANGE.0);
        // Other actions are not this function's.
        let before = p;
        surface_key(&mut p, &mut scale, Action::Wireframe);
        assert_eq!(p, before);
    }

    #[test]
    fn default_displacement_is_a_fraction_of_the_diagonal() {
        let cube = ControlMesh::from_polygons(
            vec![
                [0.0, 0.0, 0.0],
                [2.0, 0.0, 0.0],
                [2.0, 2.0, 0.0],
                [0.0, 2.0, 2.0],
            ],
            &[[0, 1, 2, 3]],
        );
        let diag = 12f32.sqrt();
        assert!((initial_displace_scale(0.0, &cube) - DEFAULT_DISPLACE * diag).abs() < 1e-6);
        // --displace wins.
        assert_eq!(initial_displace_scale(0.25, &cube), 0.25);
        // A mesh without extent still gets a usable scale.
        let point = ControlMesh::from_polygons(vec![[1.0, 1.0, 1.0]; 3], &[[0, 1, 2]]);
        assert!(initial_displace_scale(0.0, &point) > 0.0);
        assert!(initial_displace_scale(0.0, &ControlMesh::default()) > 0.0);
    }
}
