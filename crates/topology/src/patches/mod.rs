//! Patches and the plans that draw them.

pub mod acc;
pub mod adaptive;
pub mod bft;
pub mod gregory;
pub mod reparam;
pub mod texcoord;
