//! Tessera: subdivision surfaces rendered on the GPU's tessellation stage through Vulkan.
//!
//! This root crate re-exports the layers so that integration tests and embedders see one name:
//! [`topology`] (CPU truth, no Vulkan), [`vk_core`] (Vulkan plumbing, no subdivision) and
//! [`tess`] (the techniques that join them).
pub use tess;
pub use topology;
pub use vk_core;
