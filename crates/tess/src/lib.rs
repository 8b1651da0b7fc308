//! The tessellation techniques: what joins `topology` (CPU truth) to `vk-core` (Vulkan).
//!
//! Every technique implements [`Technique`], the one seam its callers see, on either draw path
//! (patches through the tessellation stage, or triangles from the vertex stage); a [`Context`]
//! owns the pipelines (one cache for all techniques and both paths), the frame uniforms and the
//! recording of a frame; [`capture`] reads back exactly what any technique's last stage before
//! rasterization emitted (transform feedback) and checks it for cracks. Techniques are built by
//! name from [`techniques::registry`], where each declares itself once.
#![forbid(unsafe_code)]
pub mod animation;
pub mod bench;
pub mod camera;
pub mod capture;
pub mod context;
pub mod error;
pub mod framing;
pub mod gpu;
pub mod output;
pub mod pattern;
pub mod render_mesh;
pub mod shaders;
pub mod stencil;
pub mod surface;
pub mod technique;
pub mod techniques;
pub mod tessellator;

pub use camera::Camera;
pub use capture::{CaptureRecord, CapturedSoup, Capturer, WeldedMesh};
pub use context::Context;
pub use error::{Result, TessError};
pub use render_mesh::RenderMesh;
pub use technique::{
    DeviceAllocation, DrawCounts, DrawPath, DrawSplit, FactorPolicy, Features, FrameParams,
    Geometry, Pass, PatchArray, PatchPipeline, PatchType, PipelineChoice, Technique, TechniqueId,
    VertexInput,
};
pub use techniques::{build, registry, BuildOptions};
pub use tessellator::{Domain, Spacing};
