//! CPU truth for every GPU technique: control meshes, subdivision rules, refinement and
//! stencils, limit evaluation, and the patches the techniques draw, handed over as plain Rust
//! data. No GPU, no `unsafe`.
//!
//! # Layers
//!
//! The crate is built in layers, as OpenSubdiv is built of `Sdc`, `Vtr`, `Far` and `Bfr`.
//! Bottom first; each layer imports only the layers before it in this list
//! (`tests/layers.rs` reads the sources and fails on an import that climbs, or on a cycle):
//!
//! | layer | holds | OpenSubdiv |
//! |---|---|---|
//! | [`error`] | the error types every layer reports with ([`TopologyError`], the end caps' problem kinds); imports no layer | — |
//! | [`rules/`](rules) | the schemes ([`Scheme`]), crease sharpness and its decay, the vertex rule, the subdivision options ([`rules::options`]) | `Sdc` (`Sdc::Crease`, `Sdc::Options`) |
//! | [`mesh/`](mesh) | the control mesh as loaded ([`ControlMesh`]), its validated adjacency ([`mesh::Topology`]), OBJ input and output ([`mesh::obj`]), input files read within a bound ([`mesh::input`]) | the base `Vtr::Level`, `Far::TopologyDescriptor` |
//! | [`refine/`](refine) | the one refiner, uniform and sparse, its levels and child maps; stencils and stencil tables ([`refine::stencil`]) | `Vtr` refinement, `Far::TopologyRefiner`, `Far::StencilTable` |
//! | [`limit/`](limit) | limit masks at a vertex ([`limit::masks`]), the regular patches' basis functions ([`limit::basis`]), exact limit evaluation anywhere ([`limit::eval`]) and at points of the face domains ([`limit::face_domain`]), the uniform limit mesh ([`limit::limit_mesh`]) | `Sdc`'s limit masks, `Far`'s patch basis, `Bfr` |
//! | [`patches/`](patches) | patch building: Gregory and ACC-1 patches, basis-function tables, feature-adaptive and single-pass plans, reparameterization, texture coordinates | `Far::PatchTable` and its end caps |
//!
//! One difference from OpenSubdiv's order: exact evaluation (`Bfr` there, built on `Far`'s
//! patches) sits below patch building here, because basis-function tables,
//! reparameterization and texture coordinates are built from exact limit evaluation.
//!
//! The crate root re-exports only what nearly every caller names: [`ControlMesh`],
//! [`load_obj`], [`Scheme`] and the errors. Everything else is named by its layer's path.
#![forbid(unsafe_code)]

pub mod error;
pub mod limit;
pub mod mesh;
pub mod patches;
pub mod refine;
pub mod rules;

pub use error::TopologyError;
pub use limit::eval::EvalError;
pub use mesh::obj::load_obj;
pub use mesh::ControlMesh;
pub use rules::Scheme;
