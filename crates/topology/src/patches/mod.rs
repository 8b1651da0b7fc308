//! Patch building: what the GPU techniques draw, as patches over stencils of control points.
//!
//! - [`gregory`]: Gregory end caps (quads and triangles), 20 (or 15) points as stencils;
//! - [`acc`]: ACC-1 bicubic Bézier patches and their tangent patches;
//! - [`bft`]: Loop basis-function tables and the patch records that index them;
//! - [`doo_sabin`]: Doo-Sabin vertex patches and the index maps of their one-dimensional layout;
//! - [`doo_sabin_limit`]: the exact Doo-Sabin limit surface as a feature-adaptive plan (regular
//!   B-spline patches of the biquadratic pieces, bilinear end caps at extraordinary faces);
//! - [`adaptive`]: the feature-adaptive Catmull-Clark plan (sparse refinement to the isolation
//!   level, regular patches, end caps, stencil blocks, canonical curves) and the single-pass
//!   plan ([`adaptive::single_pass`]);
//! - [`reparam`]: the texture reparameterization of Gregory patches (characteristic maps and
//!   their fitted corner blocks);
//! - [`texcoord`]: texture coordinates of the limit surface at a patch's parameter;
//! - [`fvar`]: face-varying patches, the smooth texture coordinates of a planned surface.
//!
//! The top layer: builds on every layer below it (`rules/`, `mesh/`, `refine/`, `limit/`),
//! as OpenSubdiv's `Far` patch tables build on `Vtr`.

pub mod acc;
pub mod adaptive;
pub mod bft;
pub mod doo_sabin;
pub mod doo_sabin_limit;
pub mod fvar;
pub mod gregory;
pub mod reparam;
pub mod texcoord;
