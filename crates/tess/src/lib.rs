//! The tessellation techniques: what joins `topology` (CPU truth) to `vk-core` (Vulkan).
//!
//! Every technique draws patches through a real TCS/TES pair; the host side here builds the
//! buffers, chooses the shader variant by a [`renderer::PipelineKey`], sets tessellation factors,
//! and splits draws where a driver needs it ([`vk_core::workarounds`]). [`capture`] reads back
//! exactly what the TES emitted (transform feedback) and checks it for cracks.
pub mod bench;
pub mod bft;
pub mod camera;
pub mod capture;
pub mod error;
pub mod gpu;
pub mod plain;
pub mod render_mesh;
pub mod renderer;
pub mod tessellator;

pub use bft::{BftParams, BftSurface, FactorPolicy};
pub use camera::Camera;
pub use capture::{CaptureRecord, CapturedSoup, Capturer, WeldedMesh};
pub use error::{Result, TessError};
pub use render_mesh::RenderMesh;
pub use renderer::{DrawParams, DrawSplit, Method, Renderer};
pub use tessellator::{Domain, Spacing};

/// SPIR-V of every shader in `glsl/`, compiled by the build script.
pub mod shaders {
    include!(concat!(env!("OUT_DIR"), "/shaders.rs"));
}
