mod common;
use tessera::tess::renderer::GpuMesh;
use tessera::tess::{DrawParams, Method, RenderMesh, Renderer};
use tessera::vk_core::vk;

#[test]
fn renders_spot_with_each_method() {
    let gpu = Gpu::new();
    let mesh = tessera::topology::load_obj(common::data("assets/spot_control_mesh.obj")).unwrap();
    let rm = RenderMesh::from_control_mesh(&mesh).unwrap();
    let gm = GpuMesh::upload(gpu.device(), &rm).unwrap();
    let mut r = Renderer::offscreen(gpu.device()).unwrap();
    for m in [Method::Flat, Method::Phong, Method::Pn] {
        let p = DrawParams {
            method: m,
            level: 6.0,
            wireframe: true,
            ..Default::default()
        };
        let img = r
            .render_offscreen(
                &gm,
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
