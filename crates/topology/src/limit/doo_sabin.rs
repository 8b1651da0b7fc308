//! The exact Doo-Sabin limit at the centre of any face, from the face's corners alone.
//!
//! A face's f-face (its child face) is its corners times the circulant mask
//! [`crate::rules::doo_sabin::alpha`], whose eigenvalues on the face's discrete Fourier modes
//! are `1` (mode 0, the centroid), `1/2` (modes `1` and `n − 1`) and `1/4` (all others). So the
//! nested f-faces keep the centroid, shrink onto it, and their shape tends to the mode-1 ellipse
//! `c + 2^−k (a cos θ_i + b sin θ_i)` with `a = (2/n) Σ p_i cos θ_i`, `b = (2/n) Σ p_i sin θ_i`,
//! `θ_i = 2π i / n`:
//!
//! - the **limit point** of the face's centre is its centroid `c`;
//! - the **limit normal** there is `a × b`, normalized (the mode-1 plane is the tangent plane;
//!   for a quad, the cross product of its diagonals).
//!
//! This is the reference a refined Doo-Sabin mesh's normals are measured against: at every
//! level, every face's centre has an exact limit point and normal. (Faces holding boundary
//! points are refined by the strip mask, whose eigenstructure differs; the formula holds for
//! faces without boundary points.)

use std::f64::consts::TAU;

/// The limit point and unit limit normal at the centre of a face with corners `corners` (in
/// the face's orientation), or `None` when the face is degenerate (its mode-1 vectors are
/// parallel).
pub fn face_limit(corners: &[[f64; 3]]) -> Option<([f64; 3], [f64; 3])> {
    let n = corners.len();
    if n < 3 {
        return None;
    }
    let mut c = [0.0; 3];
    let mut a = [0.0; 3];
    let mut b = [0.0; 3];
    for (i, p) in corners.iter().enumerate() {
        let t = TAU * i as f64 / n as f64;
        for k in 0..3 {
            c[k] += p[k] / n as f64;
            a[k] += p[k] * t.cos();
            b[k] += p[k] * t.sin();
        }
    }
    let normal = [
        a[1] * b[2] - a[2] * b[1],
        a[2] * b[0] - a[0] * b[2],
        a[0] * b[1] - a[1] * b[0],
    ];
    let len = normal.iter().map(|x| x * x).sum::<f64>().sqrt();
    let scale = a.iter().chain(&b).map(|x| x * x).sum::<f64>();
    (len > 1e-12 * scale && len.is_finite()).then(|| (c, normal.map(|x| x / len)))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::rules::doo_sabin::alpha;

    fn f_face(corners: &[[f64; 3]]) -> Vec<[f64; 3]> {
        let n = corners.len();
        (0..n)
            .map(|i| {
                let mut p = [0.0; 3];
                for k in 0..n {
                    for c in 0..3 {
                        p[c] += alpha(n, k) * corners[(i + k) % n][c];
                    }
                }
                p
            })
            .collect()
    }

    fn angle(a: [f64; 3], b: [f64; 3]) -> f64 {
        let dot: f64 = (0..3).map(|k| a[k] * b[k]).sum();
        let cross = [
            a[1] * b[2] - a[2] * b[1],
            a[2] * b[0] - a[0] * b[2],
            a[0] * b[1] - a[1] * b[0],
        ];
        cross.iter().map(|x| x * x).sum::<f64>().sqrt().atan2(dot)
    }

    /// A skew, non-planar face of `n` corners.
    fn skew(n: usize) -> Vec<[f64; 3]> {
        (0..n)
            .map(|i| {
                let t = TAU * i as f64 / n as f64;
                let r = 1.0 + 0.3 * (i as f64 * 1.7).sin();
                [
                    r * t.cos() + 0.2,
                    0.6 * r * t.sin(),
                    0.4 * (2.0 * t).cos() + 0.1 * i as f64,
                ]
            })
            .collect()
    }

    #[test]
    fn nested_f_faces_keep_the_limit_point_and_normal() {
        for n in 3..9 {
            let face = skew(n);
            let (c, normal) = face_limit(&face).unwrap();
            let mut child = face.clone();
            for _ in 0..8 {
                child = f_face(&child);
                let (c2, n2) = face_limit(&child).unwrap();
                for k in 0..3 {
                    assert!((c[k] - c2[k]).abs() < 1e-12, "{n}: centroid moved");
                }
                assert!(angle(normal, n2) < 1e-9, "{n}: normal turned");
            }
            // The f-faces shrink onto the centroid (mode 1 halves each step).
            let radius = child
                .iter()
                .map(|p| (0..3).map(|k| (p[k] - c[k]).powi(2)).sum::<f64>().sqrt())
                .fold(0.0, f64::max);
            assert!(radius < 2.0 / 256.0 + 1e-9, "{n}: radius {radius}");
        }
    }

    #[test]
    fn a_quad_takes_the_normal_of_its_diagonals() {
        let q = [
            [0.0, 0.0, 0.0],
            [1.0, 0.0, 0.2],
            [1.0, 1.0, 0.0],
            [0.0, 1.0, -0.1],
        ];
        let (_, normal) = face_limit(&q).unwrap();
        let d0 = [1.0, 1.0, 0.0];
        let d1 = [-1.0, 1.0, -0.3];
        let x = [
            d0[1] * d1[2] - d0[2] * d1[1],
            d0[2] * d1[0] - d0[0] * d1[2],
            d0[0] * d1[1] - d0[1] * d1[0],
        ];
        let len = x.iter().map(|v| v * v).sum::<f64>().sqrt();
        assert!(angle(normal, x.map(|v| v / len)) < 1e-12);
    }

    #[test]
    fn degenerate_faces_have_no_normal() {
        assert!(face_limit(&[[0.0; 3]; 4]).is_none());
        assert!(face_limit(&[[0.0; 3], [1.0, 0.0, 0.0]]).is_none());
    }
}
