//! Tessellation techniques.
