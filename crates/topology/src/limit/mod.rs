//! The limit surface: where a refinement converges, computed without refining forever.
//!
//! - [`masks`]: limit masks, weights that put a vertex of any level on the limit surface with
//!   two limit tangents (OpenSubdiv's `Sdc` limit masks);
//! - [`basis`]: the basis functions of the regular patches (Loop's quartic box spline,
//!   Catmull-Clark's bicubic B-spline) and the cubic Bézier and B-spline curves, the surface in
//!   closed form where the mesh is regular;
//! - [`doo_sabin`]: the exact Doo-Sabin limit point and normal at the centre of any face;
//! - [`doo_sabin_eval`]: exact Doo-Sabin limit evaluation at any point of a corner quad
//!   (biquadratic patches, local refinement next to extraordinary faces, Chaikin boundaries);
//! - [`doo_sabin_domain`]: the domain points of refined Doo-Sabin levels' vertices and faces;
//! - [`eval`]: exact limit evaluation at any `(face, u, v)` (OpenSubdiv's `Bfr`), refining
//!   locally with the [`refine`](crate::refine) layer until a regular patch or a limit mask
//!   applies;
//! - [`face_domain`]: the face domains points on a base mesh are given in (captures, exports,
//!   the C ABI) and exact evaluation at such points ([`face_domain::LimitEvaluator`]);
//! - [`limit_mesh`]: a control mesh refined uniformly and placed on its limit surface, the
//!   mesh a CPU application would draw, with each vertex's point of the base mesh.
//!
//! Builds on `rules/`, `mesh/` and `refine/`; the `patches/` layer builds on it.

pub mod basis;
pub mod doo_sabin;
pub mod doo_sabin_domain;
pub mod doo_sabin_eval;
pub mod eval;
pub mod face_domain;
pub mod limit_mesh;
pub mod masks;
