//! The subdivision rules every other module calls: scheme names, sharpness tests, decay
//! (uniform and Chaikin), the vertex rule, the fractional weight of a rule transition and the
//! boundary-interpolation corner rule, following OpenSubdiv's `Sdc::Crease` and
//! `Sdc::Options`.
//!
//! Sharpness is kept in `f32` like OpenSubdiv, so decay and rule transitions happen at the same
//! levels as in the reference implementation. Nothing here knows a mesh representation: the
//! refiner ([`crate::refine`]) gathers the incident sharpness values and calls these functions,
//! and the evaluator ([`crate::limit::eval`]) refines through the refiner, so a crease fix is made once.

pub mod doo_sabin;
pub mod options;

use crate::error::TopologyError;
use options::{BoundaryInterpolation, CreaseMethod};

/// The subdivision schemes this crate refines.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Hash)]
pub enum Scheme {
    /// Loop: triangles only, split 1→4; approximating, C2 away from extraordinary vertices.
    Loop,
    /// Catmull-Clark: any polygons, split into quads; bicubic B-spline on regular regions.
    CatmullClark,
    /// Doo-Sabin: the dual quadratic scheme (one vertex per face corner); biquadratic B-spline
    /// on regular regions. Sharpness tags are ignored; the boundary is the quadratic B-spline
    /// of the boundary polygon ([`doo_sabin`]).
    DooSabin,
    /// Bilinear: the same quad split as Catmull-Clark with linear interpolation.
    Bilinear,
}

impl Scheme {
    /// Scheme from an OpenSubdiv shape name: the part before the first `_` (`catmark_cube`,
    /// `loop_saddle_edgecorner`, `bilinear_nonplanar`), read by its [`FromStr`](std::str::FromStr) impl.
    pub fn from_shape_name(name: &str) -> Option<Scheme> {
        name.split('_').next()?.parse().ok()
    }

    /// The canonical command-line name (what its [`FromStr`](std::str::FromStr) impl reads back).
    pub fn name(self) -> &'static str {
        match self {
            Scheme::Loop => "loop",
            Scheme::CatmullClark => "catmull-clark",
            Scheme::DooSabin => "doo-sabin",
            Scheme::Bilinear => "bilinear",
        }
    }

    /// Whether the scheme splits faces into quads around a face point (Catmull-Clark,
    /// bilinear) rather than triangles (Loop).
    pub fn splits_into_quads(self) -> bool {
        matches!(self, Scheme::CatmullClark | Scheme::Bilinear)
    }
}

/// The one scheme parser: `loop`, `catmull-clark` (also `catmark`, OpenSubdiv's name, and
/// `cc`), `doo-sabin`, `bilinear`.
impl std::str::FromStr for Scheme {
    type Err = TopologyError;
    fn from_str(s: &str) -> Result<Scheme, TopologyError> {
        match s {
            "loop" => Ok(Scheme::Loop),
            "catmull-clark" | "catmark" | "cc" => Ok(Scheme::CatmullClark),
            "doo-sabin" => Ok(Scheme::DooSabin),
            "bilinear" => Ok(Scheme::Bilinear),
            _ => Err(TopologyError::UnknownScheme {
                name: s.to_string(),
            }),
        }
    }
}

impl std::fmt::Display for Scheme {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str(self.name())
    }
}

/// Sharpness of a smooth edge or vertex.
pub const SHARPNESS_SMOOTH: f32 = 0.0;
/// Sharpness at or above which an edge or vertex is infinitely sharp.
pub const SHARPNESS_INFINITE: f32 = 10.0;

/// Any positive sharpness.
pub fn is_sharp(s: f32) -> bool {
    s > SHARPNESS_SMOOTH
}
/// Sharpness ≥ 10.
pub fn is_infinite(s: f32) -> bool {
    s >= SHARPNESS_INFINITE
}
/// Sharp but not infinitely so: it decays with refinement.
pub fn is_semi_sharp(s: f32) -> bool {
    SHARPNESS_SMOOTH < s && s < SHARPNESS_INFINITE
}

/// Sharpness a vertex gets from the boundary rule alone: with
/// [`BoundaryInterpolation::EdgesAndCorners`] a boundary corner (a vertex with one face, hence
/// two boundary edges) is infinitely sharp, so it stays put. Boundary *edges* are infinitely
/// sharp under every rule ([`boundary_edge_sharpness`]).
pub fn boundary_vertex_sharpness(
    boundary: BoundaryInterpolation,
    num_faces: usize,
    num_edges: usize,
) -> Option<f32> {
    (boundary == BoundaryInterpolation::EdgesAndCorners && num_faces == 1 && num_edges == 2)
        .then_some(SHARPNESS_INFINITE)
}

/// Sharpness of an edge with a single face: infinite, whatever its tag (OpenSubdiv does this for
/// every boundary rule, so the boundary curve is the B-spline of its control polygon).
pub fn boundary_edge_sharpness() -> f32 {
    SHARPNESS_INFINITE
}

/// The vertex rule chosen from a vertex's sharpness and its sharp incident edges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub enum Rule {
    /// No sharp edges: the scheme's smooth vertex rule.
    Smooth,
    /// One sharp edge: the smooth rule still applies.
    Dart,
    /// Two sharp edges: the cubic B-spline curve rule (1/8, 3/4, 1/8).
    Crease,
    /// A sharp vertex or more than two sharp edges: the vertex stays put.
    Corner,
}

/// OpenSubdiv's `DetermineVertexVertexRule`.
pub fn vertex_rule(vertex_sharpness: f32, sharp_edge_count: usize) -> Rule {
    if is_sharp(vertex_sharpness) {
        return Rule::Corner;
    }
    match sharp_edge_count {
        0 => Rule::Smooth,
        1 => Rule::Dart,
        2 => Rule::Crease,
        _ => Rule::Corner,
    }
}

/// Uniform decay: semi-sharp values lose 1 per level (≤ 1 becomes smooth); infinite stays.
pub fn decrement_sharpness(s: f32) -> f32 {
    if !is_sharp(s) {
        SHARPNESS_SMOOTH
    } else if is_infinite(s) {
        SHARPNESS_INFINITE
    } else if s > 1.0 {
        s - 1.0
    } else {
        SHARPNESS_SMOOTH
    }
}

/// Sharpness of the child of an edge at one of its end vertices, given the sharpness of all
/// edges incident to that vertex (Chaikin blends 3/4 of its own value with 1/4 of the average
/// of the other semi-sharp edges there before decrementing).
pub fn subdivide_edge_sharpness_at_vertex(
    method: CreaseMethod,
    edge_sharpness: f32,
    incident: &[f32],
) -> f32 {
    if method == CreaseMethod::Uniform || incident.len() < 2 {
        return decrement_sharpness(edge_sharpness);
    }
    if !is_sharp(edge_sharpness) {
        return SHARPNESS_SMOOTH;
    }
    if is_infinite(edge_sharpness) {
        return SHARPNESS_INFINITE;
    }
    let (mut sum, mut count) = (0.0f32, 0usize);
    for &s in incident {
        if is_semi_sharp(s) {
            sum += s;
            count += 1;
        }
    }
    let mut s = edge_sharpness;
    if count > 1 {
        let others = (sum - edge_sharpness) / (count - 1) as f32;
        s = 0.75 * edge_sharpness + 0.25 * others;
    }
    s -= 1.0;
    if is_sharp(s) {
        s
    } else {
        SHARPNESS_SMOOTH
    }
}

/// Weight of the parent rule when a vertex's rule changes between levels (OpenSubdiv's
/// `ComputeFractionalWeightAtVertex`): the mean sharpness of what decayed, clamped to 1.
pub fn fractional_weight(
    method: CreaseMethod,
    parent_vertex: f32,
    child_vertex: f32,
    parent_edges: &[f32],
    child_edges: &[f32],
) -> f32 {
    let (mut count, mut sum) = (0usize, 0.0f32);
    if is_sharp(parent_vertex) && !is_sharp(child_vertex) {
        count = 1;
        sum = parent_vertex;
    }
    for (i, &p) in parent_edges.iter().enumerate() {
        let decayed = match method {
            CreaseMethod::Uniform => is_sharp(p) && p <= 1.0,
            CreaseMethod::Chaikin => is_sharp(p) && !is_sharp(child_edges[i]),
        };
        if decayed {
            sum += p;
            count += 1;
        }
    }
    if count == 0 {
        return 0.0;
    }
    (sum / count as f32).min(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rules_follow_sharp_edge_count() {
        assert_eq!(vertex_rule(0.0, 0), Rule::Smooth);
        assert_eq!(vertex_rule(0.0, 1), Rule::Dart);
        assert_eq!(vertex_rule(0.0, 2), Rule::Crease);
        assert_eq!(vertex_rule(0.0, 3), Rule::Corner);
        assert_eq!(vertex_rule(0.5, 0), Rule::Corner);
    }

    #[test]
    fn uniform_decay() {
        assert_eq!(decrement_sharpness(2.5), 1.5);
        assert_eq!(decrement_sharpness(1.0), 0.0);
        assert_eq!(decrement_sharpness(0.3), 0.0);
        assert_eq!(decrement_sharpness(10.0), 10.0);
        assert_eq!(decrement_sharpness(42.0), 10.0);
    }

    #[test]
    fn chaikin_decay_blends_neighbours() {
        // Edge 2 next to a semi-sharp 1 and an infinite boundary: (0.75*2 + 0.25*1) - 1.
        let s = subdivide_edge_sharpness_at_vertex(CreaseMethod::Chaikin, 2.0, &[2.0, 1.0, 10.0]);
        assert!((s - 0.75).abs() < 1e-6);
        // A lone semi-sharp edge decays uniformly.
        let s = subdivide_edge_sharpness_at_vertex(CreaseMethod::Chaikin, 2.0, &[2.0, 0.0, 0.0]);
        assert_eq!(s, 1.0);
    }

    #[test]
    fn fractional_weight_of_decayed_edges() {
        let w = fractional_weight(CreaseMethod::Uniform, 0.0, 0.0, &[0.5, 0.5, 0.0], &[0.0; 3]);
        assert!((w - 0.5).abs() < 1e-6);
        let w = fractional_weight(CreaseMethod::Chaikin, 0.0, 0.0, &[1.5, 0.0], &[0.0, 0.0]);
        assert_eq!(w, 1.0);
    }
}
