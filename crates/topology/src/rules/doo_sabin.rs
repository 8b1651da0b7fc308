//! The Doo-Sabin masks: the weights of a child vertex over the corners of its parent face, for
//! every kind of face a Doo-Sabin level has. The refiner ([`crate::refine::doo_sabin`]) takes
//! its weights from here, and so does anything that refines Doo-Sabin levels by other means,
//! so they agree by construction.
//!
//! # The boundary rule
//!
//! The limit surface of a mesh with boundaries is the biquadratic B-spline whose control net is
//! extended past the boundary by point reflection (a phantom point `2b − r` beyond each
//! boundary-row point `r`, `b` on the boundary): its boundary curve is the **uniform quadratic
//! B-spline of the boundary polygon** (Chaikin's curve), which depends on the boundary polygon
//! alone, so two meshes sharing a boundary polygon meet along one curve.
//!
//! A refined level (level 1 and beyond) carries that boundary explicitly: its boundary vertices
//! (*boundary points*, `b`) are the control polygon of the boundary curve, and the faces that
//! hold them (*strip faces*) are the inner halves of the faces the phantom net would have across
//! the boundary. A strip face has two consecutive boundary points, joined by its boundary edge,
//! and a chain of `m ≥ 1` real corners (`[r_0 … r_{m−1}, b_R, b_L]`, `b_L` next to `r_0`,
//! `b_R` next to `r_{m−1}`). Its children:
//!
//! - a boundary point's child is its Chaikin point, `(3 b + b') / 4` with `b'` the other end of
//!   the boundary edge, so the boundary polygons are Chaikin's refinements of each other;
//! - a real corner's child is the Doo-Sabin child of the same corner in the face's phantom
//!   completion: the `2m`-gon `[r_0 … r_{m−1}, p_{m−1} … p_0]` with `p_j = 2 q_j − r_j`,
//!   `q_j` spaced evenly from `b_L` (j = 0) to `b_R` (j = m − 1) (their midpoint when m = 1).
//!   For `m = 2` (the strips along a regular boundary) this is exactly Doo-Sabin on the
//!   reflected net, `3/8 r_0 + 1/8 r_1 + 3/8 b_L + 1/8 b_R`.
//!
//! The level-0 step is where the boundary points are made: every control face keeps Doo-Sabin's
//! mask, each boundary edge gets its two Chaikin points and a strip quad, each boundary vertex
//! a strip face over its faces' corners (see [`crate::refine::doo_sabin`]). Crease and corner
//! tags are not Doo-Sabin rules and are ignored.

use std::f64::consts::TAU;

/// Doo-Sabin's weight at cyclic distance `d` in an `n`-gon: `(n + 5) / 4n` at the corner itself,
/// `(3 + 2 cos(2π d / n)) / 4n` elsewhere.
/// The distance is taken the short way round, so `alpha(n, d) == alpha(n, n − d)` bit for bit.
pub fn alpha(n: usize, d: usize) -> f64 {
    let nf = n as f64;
    let d = (d % n).min(n - d % n);
    if d == 0 {
        (nf + 5.0) / (4.0 * nf)
    } else {
        (3.0 + 2.0 * (TAU * d as f64 / nf).cos()) / (4.0 * nf)
    }
}

/// The weights of the child of corner `i` of an `n`-gon over its corners `i, i+1, …, i−1` (in
/// that order: `out[k]` weighs corner `(i + k) mod n`). `boundary_edge` is `Some(p)` for a strip
/// face whose boundary points are corners `p` (`b_R`) and `p + 1` (`b_L`), `None` for a face
/// without boundary points. Terms that are structurally zero (a Chaikin point's weights over
/// the real corners) are written as 0.
pub fn corner_weights(n: usize, boundary_edge: Option<usize>, i: usize, out: &mut Vec<f64>) {
    out.clear();
    out.resize(n, 0.0);
    let Some(p) = boundary_edge else {
        for (k, w) in out.iter_mut().enumerate() {
            *w = alpha(n, k);
        }
        return;
    };
    let at = |corner: usize| (corner + n - i) % n;
    let (b_right, b_left) = (p % n, (p + 1) % n);
    if i % n == b_right || i % n == b_left {
        let other = if i % n == b_right { b_left } else { b_right };
        out[0] = 0.75;
        out[at(other)] = 0.25;
        return;
    }
    // Real corner r_j of the chain r_0 = p + 2 … r_{m−1} = p − 1.
    let m = n - 2;
    let real = |j: usize| (p + 2 + j) % n;
    let me = (i + n - (p + 2) % n) % n;
    let v = 2 * m;
    let lambda = |j: usize| {
        if m == 1 {
            0.5
        } else {
            j as f64 / (m - 1) as f64
        }
    };
    let dist = |a: usize, b: usize| {
        let d = (a + v - b) % v;
        d.min(v - d)
    };
    for j in 0..m {
        let own = alpha(v, dist(me, j));
        let phantom = alpha(v, dist(me, v - 1 - j));
        out[at(real(j))] += own - phantom;
        // 2 q_j = 2 (1 − λ) b_L + 2 λ b_R.
        out[at(b_left)] += 2.0 * phantom * (1.0 - lambda(j));
        out[at(b_right)] += 2.0 * phantom * lambda(j);
    }
}

/// A face whose boundary points are not the two ends of one of its edges.
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct NotOneBoundaryEdge;

/// The corner `p` that starts the boundary edge of a face whose corners are boundary points
/// where `is_boundary(k)` holds: `Some(p)` when exactly corners `p` and `p + 1` are, `None`
/// when none is, and [`NotOneBoundaryEdge`] for any other pattern (no level of the refiner makes one).
pub fn strip_edge(
    n: usize,
    is_boundary: impl Fn(usize) -> bool,
) -> Result<Option<usize>, NotOneBoundaryEdge> {
    let marked: Vec<usize> = (0..n).filter(|&k| is_boundary(k)).collect();
    match marked[..] {
        [] => Ok(None),
        [a, b] if b == a + 1 => Ok(Some(a)),
        [0, b] if b == n - 1 => Ok(Some(n - 1)),
        _ => Err(NotOneBoundaryEdge),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn sum(w: &[f64]) -> f64 {
        w.iter().sum()
    }

    #[test]
    fn every_mask_is_affine() {
        let mut w = Vec::new();
        for n in 3..9 {
            for i in 0..n {
                corner_weights(n, None, i, &mut w);
                assert!((sum(&w) - 1.0).abs() < 1e-15, "{n} {i}");
                for p in 0..n {
                    corner_weights(n, Some(p), i, &mut w);
                    assert!((sum(&w) - 1.0).abs() < 1e-14, "{n} {p} {i}: {w:?}");
                }
            }
        }
    }

    #[test]
    fn regular_strip_is_doo_sabin_on_the_reflected_net() {
        // [r0, r1, bR, bL]: boundary edge starts at corner 2.
        let mut w = Vec::new();
        corner_weights(4, Some(2), 0, &mut w);
        assert_eq!(w, vec![0.375, 0.125, 0.125, 0.375]);
        corner_weights(4, Some(2), 1, &mut w);
        // Corners 1, 2 (bR), 3 (bL), 0.
        assert_eq!(w, vec![0.375, 0.375, 0.125, 0.125]);
        corner_weights(4, Some(2), 2, &mut w);
        assert_eq!(w, vec![0.75, 0.25, 0.0, 0.0]);
        corner_weights(4, Some(2), 3, &mut w);
        assert_eq!(w, vec![0.75, 0.0, 0.0, 0.25]);
    }

    #[test]
    fn a_strip_triangle_pulls_its_corner_towards_the_boundary_midpoint() {
        // [r0, bR, bL]: 3/4 r0 + 1/8 (bL + bR).
        let mut w = Vec::new();
        corner_weights(3, Some(1), 0, &mut w);
        assert_eq!(w, vec![0.75, 0.125, 0.125]);
    }

    #[test]
    fn strip_edges_are_found_and_other_patterns_refused() {
        assert_eq!(strip_edge(4, |k| k == 2 || k == 3), Ok(Some(2)));
        assert_eq!(strip_edge(4, |k| k == 0 || k == 3), Ok(Some(3)));
        assert_eq!(strip_edge(5, |_| false), Ok(None));
        assert_eq!(strip_edge(4, |k| k == 0 || k == 2), Err(NotOneBoundaryEdge));
        assert_eq!(strip_edge(4, |k| k < 3), Err(NotOneBoundaryEdge));
    }
}
