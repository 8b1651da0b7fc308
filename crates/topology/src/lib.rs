//! CPU truth for every GPU technique: control meshes, subdivision, stencils, limit evaluation.
#![forbid(unsafe_code)]
