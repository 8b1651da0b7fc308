//! The window's HUD: an egui panel drawn over the frame through vk-core's overlay.
//!
//! Design decisions:
//! - The HUD emits the same [`Action`]s as the keys (view.rs maps each key to one), so every
//!   binding is reachable from either and both go through one `App::act`. Actions take effect
//!   after the frame is presented, like a key pressed between frames.
//! - egui is laid out every frame the HUD is shown; hidden, it is not laid out nor drawn, and the
//!   input egui collected is discarded each frame so nothing accumulates.
//! - Pointer input over the HUD is egui's (no orbit under a click on a button); keys go to the
//!   window unless a HUD widget takes typed text (none does today).
//! - The patch-colour legend mirrors `KIND_COLOURS` in glsl/bft/bft.tese and
//!   glsl/adaptive/tese_main.glsl (the shaders' colours for each patch kind).
use egui::{Align2, Color32, Stroke};
use std::collections::VecDeque;
use tess::techniques;
use tess::{FactorPolicy, FrameParams, Spacing, TechniqueId};
use winit::window::Window;

/// What a key or a HUD control asks for.
#[derive(Clone, Copy, Debug, PartialEq)]
pub enum Action {
    Technique(TechniqueId),
    /// The registry's next technique, after the last the first (Tab): every technique, the
    /// ones past the ten number keys included.
    NextTechnique,
    LevelUp,
    LevelDown,
    LevelDouble,
    LevelHalve,
    Wireframe,
    Screenshot,
    Animate,
    PatchColours,
    Fractional,
    GeometricNormals,
    IsolationUp,
    IsolationDown,
    EndCaps,
    SharpnessUp,
    SharpnessDown,
    /// Texture reparameterization on/off (R).
    Reparam,
    /// Displacement on/off (D), keeping its scale.
    Displace,
    /// Displacement scale ×1.25 (]) and ÷1.25 ([); either turns displacement on.
    DisplaceUp,
    DisplaceDown,
    /// What the surface is coloured by: shading, parameter shift, Eq. 1 error (V).
    Show,
    /// Draw path: the tessellation stage or refinement patterns (T), where the technique has
    /// both.
    Pipeline,
    ToggleHud,
    Quit,
}

/// GPU time of each pass of one frame, in milliseconds (timestamp queries).
#[derive(Clone, Copy, Debug, Default)]
pub struct PassTimes {
    pub pre_pass: f64,
    pub draw: f64,
    pub hud: f64,
}

/// What the HUD shows of the current frame.
pub struct Shown<'a> {
    pub mesh: &'a str,
    pub technique: TechniqueId,
    /// The frame parameters as drawn (distances in world units).
    pub params: &'a FrameParams,
    pub build: &'a tess::BuildOptions,
    /// The draw path the surface takes.
    pub path: tess::DrawPath,
    pub animate: bool,
    /// The displacement scale D turns on (`params.displace` is 0 while it is off).
    pub displace_scale: f32,
    pub triangles: Option<u64>,
    pub patches: u64,
    /// `None` where the queue has no timestamps.
    pub gpu: Option<PassTimes>,
    pub status: Option<&'a str>,
}

/// Frame times kept for the graph.
const HISTORY: usize = 120;

/// egui's context and input, the HUD's visibility and the frame-time history.
pub struct Hud {
    ctx: egui::Context,
    input: egui_winit::State,
    pub visible: bool,
    frame_ms: VecDeque<f32>,
}

/// The colours and names of the patch-colour legend of `technique` (empty when it
/// has no patch colours): its registry entry's.
fn legend(technique: TechniqueId) -> &'static [([f32; 3], &'static str)] {
    techniques::info(technique).legend
}

fn colour([r, g, b]: [f32; 3]) -> Color32 {
    let c = |v: f32| (v.clamp(0.0, 1.0) * 255.0).round() as u8;
    Color32::from_rgb(c(r), c(g), c(b))
}

impl Hud {
    pub fn new(window: &Window, visible: bool) -> Self {
        let ctx = egui::Context::default();
        // Compact: the whole panel fits a 640x480 window.
        ctx.all_styles_mut(|style| {
            for font in style.text_styles.values_mut() {
                font.size = (font.size * 0.85).round();
            }
            style.spacing.item_spacing = egui::vec2(4.0, 2.0);
            style.spacing.button_padding = egui::vec2(3.0, 0.0);
        });
        let input = egui_winit::State::new(
            ctx.clone(),
            egui::ViewportId::ROOT,
            window,
            Some(window.scale_factor() as f32),
            None,
            None,
        );
        Self {
            ctx,
            input,
            visible,
            frame_ms: VecDeque::with_capacity(HISTORY),
        }
    }

    /// Hands a window event to egui; true when egui takes it (the window must not act on it).
    pub fn on_event(&mut self, window: &Window, event: &winit::event::WindowEvent) -> bool {
        let response = self.input.on_window_event(window, event);
        if !self.visible {
            return false;
        }
        match event {
            winit::event::WindowEvent::KeyboardInput { .. } => self.ctx.egui_wants_keyboard_input(),
            winit::event::WindowEvent::MouseInput { .. }
            | winit::event::WindowEvent::MouseWheel { .. } => {
                response.consumed || self.ctx.is_pointer_over_egui()
            }
            _ => false,
        }
    }

    /// Records a frame interval for the graph.
    pub fn push_frame_time(&mut self, ms: f64) {
        if self.frame_ms.len() == HISTORY {
            self.frame_ms.pop_front();
        }
        self.frame_ms.push_back(ms as f32);
    }

    /// Lays the HUD out for this frame: the actions its controls asked for, and what to draw
    /// (`None` when hidden).
    pub fn run(
        &mut self,
        window: &Window,
        shown: &Shown<'_>,
        actions: &mut Vec<Action>,
    ) -> Option<egui::FullOutput> {
        let raw = self.input.take_egui_input(window);
        if !self.visible {
            return None;
        }
        let history: Vec<f32> = self.frame_ms.iter().copied().collect();
        let output = self.ctx.run_ui(raw, |ui| {
            egui::Window::new("tessera")
                .anchor(Align2::LEFT_TOP, [6.0, 6.0])
                .resizable(false)
                .collapsible(false)
                .default_width(230.0)
                .show(ui.ctx(), |ui| panel(ui, shown, &history, actions));
        });
        self.input
            .handle_platform_output(window, output.platform_output.clone());
        Some(output)
    }

    /// egui's tessellated shapes of `output`, in points, with its pixels per point.
    pub fn tessellate(
        &self,
        shapes: Vec<egui::epaint::ClippedShape>,
        pixels_per_point: f32,
    ) -> Vec<egui::ClippedPrimitive> {
        self.ctx.tessellate(shapes, pixels_per_point)
    }
}

/// A toggle showing its state; `None` disables it (the technique does not take it).
fn toggle(ui: &mut egui::Ui, on: Option<bool>, text: &str) -> bool {
    ui.add_enabled(
        on.is_some(),
        egui::Button::selectable(on.unwrap_or(false), text),
    )
    .clicked()
}

/// The HUD panel, section by section: mesh and technique, factors and level buttons, the
/// isolation options, the toggles, the draw path, the surface options, the patch-colour legend, then what is
/// drawn and the GPU times.
fn panel(ui: &mut egui::Ui, s: &Shown<'_>, history: &[f32], actions: &mut Vec<Action>) {
    let info = techniques::info(s.technique);
    ui.label(format!("mesh: {}", s.mesh));
    if let Some(status) = s.status {
        ui.colored_label(Color32::from_rgb(255, 110, 90), status);
    }
    technique_choice(ui, s, actions);
    ui.label(match info.scheme {
        Some(scheme) => format!("scheme: {scheme}"),
        None => "scheme: none (base faces)".to_owned(),
    });
    ui.label(format!("factors: {}", s.params.factors));
    if let FactorPolicy::Uniform { .. } = s.params.factors {
        level_buttons(ui, actions);
    }
    if info.features.isolation {
        isolation_options(ui, s, actions);
    }
    toggles(ui, s, actions);
    path_choice(ui, s, actions);
    if info.features.surface {
        surface_options(ui, s, actions);
    }
    if s.params.patch_colours {
        patch_legend(ui, s.technique);
    }
    drawn(ui, s, history, actions);
}

/// The technique box (number keys 1..n).
fn technique_choice(ui: &mut egui::Ui, s: &Shown<'_>, actions: &mut Vec<Action>) {
    ui.horizontal(|ui| {
        // Digit keys 1-9 then 0 reach the first ten; Tab and the list reach every technique.
        let n = techniques::registry().len();
        ui.label(match n {
            ..=9 => format!("technique (1-{n}, Tab)"),
            _ => "technique (1-9, 0, Tab)".to_owned(),
        });
        egui::ComboBox::from_id_salt("technique")
            .selected_text(s.technique.name())
            .show_ui(ui, |ui| {
                for (i, t) in techniques::registry().iter().enumerate() {
                    let text = if i < 10 {
                        format!("{} {}", (i + 1) % 10, t.id.name())
                    } else {
                        t.id.name().to_owned()
                    };
                    if ui.selectable_label(t.id == s.technique, text).clicked() {
                        actions.push(Action::Technique(t.id));
                    }
                }
            });
    });
}

/// The draw path, and its switch where the technique has both the tessellation and the
/// pattern path.
fn path_choice(ui: &mut egui::Ui, s: &Shown<'_>, actions: &mut Vec<Action>) {
    let paths = techniques::info(s.technique).features.paths;
    ui.horizontal(|ui| {
        ui.label(format!("draw path: {}", s.path));
        let both = [tess::DrawPath::Tessellation, tess::DrawPath::Pattern]
            .iter()
            .all(|p| paths.contains(p));
        if ui
            .add_enabled(both, egui::Button::new("switch (T)"))
            .clicked()
        {
            actions.push(Action::Pipeline);
        }
    });
}

/// The uniform level's buttons.
fn level_buttons(ui: &mut egui::Ui, actions: &mut Vec<Action>) {
    ui.horizontal(|ui| {
        for (text, action) in [
            ("− (-)", Action::LevelDown),
            ("+ (+)", Action::LevelUp),
            ("÷2 (Down)", Action::LevelHalve),
            ("×2 (Up)", Action::LevelDouble),
        ] {
            if ui.button(text).clicked() {
                actions.push(action);
            }
        }
    });
}

/// Isolation, end caps and sharpness scale.
fn isolation_options(ui: &mut egui::Ui, s: &Shown<'_>, actions: &mut Vec<Action>) {
    let b = s.build;
    ui.horizontal(|ui| {
        ui.label(format!("isolation {}", b.isolation));
        if ui.button("− (Shift+I)").clicked() {
            actions.push(Action::IsolationDown);
        }
        if ui.button("+ (I)").clicked() {
            actions.push(Action::IsolationUp);
        }
    });
    ui.horizontal(|ui| {
        ui.label(format!(
            "end caps: {}",
            crate::view::end_cap_name(b.end_cap)
        ));
        if ui.button("switch (E)").clicked() {
            actions.push(Action::EndCaps);
        }
    });
    ui.horizontal(|ui| {
        ui.label(format!("sharpness ×{:.2}", b.sharpness_scale));
        if ui.button("− (Shift+S)").clicked() {
            actions.push(Action::SharpnessDown);
        }
        if ui.button("+ (S)").clicked() {
            actions.push(Action::SharpnessUp);
        }
    });
}

/// Fractional spacing, wireframe, patch colours, geometric normals and animation, each enabled
/// where the technique takes it.
fn toggles(ui: &mut egui::Ui, s: &Shown<'_>, actions: &mut Vec<Action>) {
    let (f, p) = (techniques::info(s.technique).features, s.params);
    let fractional_ok = f.spacing(Spacing::FractionalEven);
    ui.horizontal_wrapped(|ui| {
        for (on, text, action) in [
            (
                fractional_ok.then_some(p.spacing != Spacing::Equal),
                "fractional (F)",
                Action::Fractional,
            ),
            (Some(p.wireframe), "wireframe (W)", Action::Wireframe),
            (
                f.patch_colours.then_some(p.patch_colours),
                "patch colours (C)",
                Action::PatchColours,
            ),
            (
                f.geometric_normals.then_some(p.geometric_normals),
                "geometric normals (G)",
                Action::GeometricNormals,
            ),
            (
                f.animation.then_some(s.animate),
                "animation (A)",
                Action::Animate,
            ),
        ] {
            if toggle(ui, on, text) {
                actions.push(action);
            }
        }
    });
}

/// Reparameterization, displacement and the parameter views.
fn surface_options(ui: &mut egui::Ui, s: &Shown<'_>, actions: &mut Vec<Action>) {
    let p = s.params;
    ui.horizontal_wrapped(|ui| {
        if toggle(ui, Some(p.reparam), "reparameterization (R)") {
            actions.push(Action::Reparam);
        }
        if toggle(ui, Some(p.displace != 0.0), "displacement (D)") {
            actions.push(Action::Displace);
        }
        if ui
            .button(format!("view: {} (V)", show_name(p.show)))
            .clicked()
        {
            actions.push(Action::Show);
        }
    });
    ui.horizontal(|ui| {
        ui.label(format!(
            "displacement ×{:.4}{}",
            s.displace_scale,
            if p.displace == 0.0 { " (off)" } else { "" }
        ));
        if ui.button("÷1.25 ([)").clicked() {
            actions.push(Action::DisplaceDown);
        }
        if ui.button("×1.25 (])").clicked() {
            actions.push(Action::DisplaceUp);
        }
    });
}

/// The technique's patch-colour legend.
fn patch_legend(ui: &mut egui::Ui, technique: TechniqueId) {
    for &(rgb, name) in legend(technique) {
        ui.horizontal(|ui| {
            let (rect, _) = ui.allocate_exact_size(egui::vec2(12.0, 12.0), egui::Sense::hover());
            ui.painter().rect_filled(rect, 2.0, colour(rgb));
            ui.label(name);
        });
    }
}

/// What is drawn, the GPU times, the frame graph and the window's buttons.
fn drawn(ui: &mut egui::Ui, s: &Shown<'_>, history: &[f32], actions: &mut Vec<Action>) {
    ui.separator();
    ui.label(format!(
        "drawn: {} triangles, {} patches",
        s.triangles
            .map(|t| t.to_string())
            .unwrap_or_else(|| "?".into()),
        s.patches
    ));
    match s.gpu {
        Some(t) => ui.label(format!(
            "GPU ms: pre-pass {:.3}, draw {:.3}, HUD {:.3}",
            t.pre_pass, t.draw, t.hud
        )),
        None => ui.label("GPU: no timestamps on this queue"),
    };
    frame_graph(ui, history);
    ui.horizontal(|ui| {
        for (text, action) in [
            ("screenshot (P)", Action::Screenshot),
            ("hide (H)", Action::ToggleHud),
            ("quit (Esc)", Action::Quit),
        ] {
            if ui.button(text).clicked() {
                actions.push(action);
            }
        }
    });
}

/// The last [`HISTORY`] frame intervals as a line, scaled to the largest.
fn frame_graph(ui: &mut egui::Ui, history: &[f32]) {
    let max = history.iter().copied().fold(1.0f32, f32::max);
    let last = history.last().copied().unwrap_or(0.0);
    ui.label(format!("frame {last:.2} ms (graph top {max:.1} ms)"));
    let (rect, _) = ui.allocate_exact_size(egui::vec2(220.0, 40.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 2.0, Color32::from_gray(24));
    if history.len() < 2 {
        return;
    }
    let dx = rect.width() / (HISTORY - 1) as f32;
    let points = history
        .iter()
        .enumerate()
        .map(|(i, &ms)| {
            egui::pos2(
                rect.left() + i as f32 * dx,
                rect.bottom() - rect.height() * ms / max,
            )
        })
        .collect();
    painter.line(points, Stroke::new(1.0, Color32::from_rgb(120, 200, 120)));
}

/// The HUD's name of a surface view.
pub fn show_name(show: tess::surface::SurfaceShow) -> &'static str {
    match show {
        tess::surface::SurfaceShow::Shading => "shading",
        tess::surface::SurfaceShow::ParamShift => "parameter shift",
        tess::surface::SurfaceShow::ParamError => "Eq. 1 texture error",
    }
}
