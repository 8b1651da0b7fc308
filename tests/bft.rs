//! Loop BFT on the tessellation stage: renders, factors, draw split, animation.
mod common;
use common::Gpu;
use tessera::tess::{BftParams, BftSurface, DrawParams, FactorPolicy, Renderer};
use tessera::topology;
use tessera::vk_core::vk;

pub fn spot() -> topology::ControlMesh {
    let m = topology::load_obj(common::data("assets/spot_control_mesh.obj")).expect("spot");
    m.triangulated().0
}

#[test]
fn bft_renders_spot() {
    let gpu = Gpu::new();
    {
        let mut renderer = Renderer::offscreen(gpu.device()).expect("renderer");
        let mesh = spot();
        let mut surf = BftSurface::new(&renderer, &mesh, "spot", 5, false, 1).expect("surface");
        let draw = DrawParams {
            wireframe: std::env::var("WIRE").is_ok(),
            ..Default::default()
        };
        let params = BftParams {
            factors: FactorPolicy::Uniform { segments: 4 },
            patch_colours: true,
            ..Default::default()
        };
        let extent = vk::Extent2D {
            width: 640,
            height: 480,
        };
        let (img, stats, counts) = surf
            .render_offscreen(&mut renderer, &draw, &params, extent, false)
            .expect("render");
        println!("{counts:?} {stats:?}");
        assert_eq!(counts.patches, surf.patch_count());
    }
}

#[test]
fn bft_compute_only() {
    let gpu = Gpu::new();
    {
        let renderer = Renderer::offscreen(gpu.device()).expect("renderer");
        let mesh = spot();
        let surf = BftSurface::new(&renderer, &mesh, "spot", 5, false, 1).expect("surface");
        gpu.device()
            .one_shot(|cmd| surf.record_compute(cmd, &renderer, 0))
            .expect("compute");
    }
}
