//! The UI overlay: egui's output drawn into an offscreen scope over two frames (both vertex
//! buffer sets, the font atlas uploaded once), validation-clean; a scope of other formats and a
//! draw outside any scope are typed errors, not Vulkan errors.
use super::Gpu;
use crate::error::{RecordingError, VkError};
use crate::overlay::{Overlay, OverlayDesc};
use crate::target::{OffscreenTarget, COLOR_FORMAT, DEPTH_FORMAT};
use ash::vk;

const SIZE: u32 = 64;

/// One egui frame: a red square at (8, 8)–(40, 40) and a line of text (the font atlas).
fn frame(ctx: &egui::Context) -> egui::FullOutput {
    let input = egui::RawInput {
        screen_rect: Some(egui::Rect::from_min_size(
            egui::Pos2::ZERO,
            egui::vec2(SIZE as f32, SIZE as f32),
        )),
        ..Default::default()
    };
    ctx.run_ui(input, |ui| {
        ui.label("HUD");
        ui.painter().rect_filled(
            egui::Rect::from_min_max(egui::pos2(8.0, 8.0), egui::pos2(40.0, 40.0)),
            0.0,
            egui::Color32::from_rgb(255, 0, 0),
        );
    })
}

#[test]
fn overlay_draws_egui_into_a_scope() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let extent = vk::Extent2D {
        width: SIZE,
        height: SIZE,
    };
    let target = OffscreenTarget::new(device, extent).unwrap();
    let readback = target.readback_buffer(device).unwrap();
    let mut overlay = Overlay::new(
        device,
        &OverlayDesc {
            color_format: COLOR_FORMAT,
            depth_format: Some(DEPTH_FORMAT),
            frames_in_flight: 2,
        },
    )
    .unwrap();
    let ctx = egui::Context::default();
    for n in 0..3 {
        let mut out = frame(&ctx);
        assert_eq!(
            out.textures_delta.set.is_empty(),
            n > 0,
            "egui sets its font atlas on the first frame only"
        );
        overlay.update_textures(&mut out.textures_delta).unwrap();
        assert!(out.textures_delta.is_empty(), "the delta is consumed");
        let primitives = ctx.tessellate(out.shapes, out.pixels_per_point);
        device
            .submit_once(|enc| -> crate::Result<()> {
                enc.begin_offscreen(&target, [0.0, 0.0, 0.0, 1.0]);
                overlay.draw(enc, extent, out.pixels_per_point, &primitives)?;
                enc.end_offscreen_and_copy(&target, &readback);
                Ok(())
            })
            .unwrap()
            .unwrap();
        let image = target.read(&readback).unwrap();
        let at = |x: u32, y: u32| {
            let i = ((y * SIZE + x) * 4) as usize;
            [image.pixels[i], image.pixels[i + 1], image.pixels[i + 2]]
        };
        assert_eq!(at(24, 30), [255, 0, 0], "frame {n}: the square");
        assert_eq!(at(60, 60), [0, 0, 0], "frame {n}: the clear outside it");
    }
    drop(overlay);
}

#[test]
fn overlay_refuses_other_formats_and_no_scope() {
    let gpu = Gpu::new();
    let device = gpu.device();
    let extent = vk::Extent2D {
        width: SIZE,
        height: SIZE,
    };
    let target = OffscreenTarget::new(device, extent).unwrap();
    let mut overlay = Overlay::new(
        device,
        &OverlayDesc {
            color_format: vk::Format::B8G8R8A8_UNORM,
            depth_format: None,
            frames_in_flight: 2,
        },
    )
    .unwrap();
    let ctx = egui::Context::default();
    let mut out = frame(&ctx);
    overlay.update_textures(&mut out.textures_delta).unwrap();
    let primitives = ctx.tessellate(out.shapes, out.pixels_per_point);
    let problem = |e: VkError| match e {
        VkError::Recording { problem, .. } => problem,
        other => panic!("not a recording error: {other}"),
    };
    let e = device
        .submit_once(|enc| {
            enc.begin_offscreen(&target, [0.0; 4]);
            let r = overlay.draw(enc, extent, 1.0, &primitives);
            enc.end_rendering();
            r
        })
        .unwrap()
        .unwrap_err();
    assert!(
        matches!(problem(e), RecordingError::AttachmentFormats { .. }),
        "a scope of other formats"
    );
    let e = device
        .submit_once(|enc| overlay.draw(enc, extent, 1.0, &primitives))
        .unwrap()
        .unwrap_err();
    assert!(matches!(problem(e), RecordingError::OutsideRendering));
}
