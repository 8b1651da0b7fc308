//! The limit surface.

pub mod basis;
pub mod eval;
pub mod masks;
