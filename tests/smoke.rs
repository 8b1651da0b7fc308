mod common;
use tessera::tess::{Context, FrameParams, TechniqueId};
use tessera::vk_core::vk;

#[test]
fn renders_spot_with_each_method() {
    let gpu = Gpu::new();
    let mesh = tessera::topology::load_obj(common::data("assets/spot_control_mesh.obj")).unwrap();
    let mut ctx = Context::offscreen(gpu.device()).unwrap();
    for m in [TechniqueId::FLAT, TechniqueId::PHONG, TechniqueId::PN] {
        let mut t = common::build(&mut ctx, m, &mesh);
        let p = FrameParams {
            wireframe: true,
            ..FrameParams::uniform(6.0)
        };
        let img = ctx
            .render_offscreen(
                t.as_mut(),
                &p,
                vk::Extent2D {
                    width: 320,
                    height: 240,
                },
            )
            .unwrap();
        img.save_png(std::path::Path::new(&format!("/tmp/smoke_{m:?}.png")))
            .unwrap();
    }
}
use common::Gpu;
