//! Scalar-tagged PN triangles (ST-meshes; appendix B of the refinement-pattern paper): the
//! tags of [`topology::mesh::scalar_tags`] turned into each tagged corner's edge control points
//! and its side's sharp normal, on the CPU, once per mesh.
//!
//! **The formulas** (corner `j` of edge `{j, k}`, its tags `D`, `θ`, `σ`, `β`, its unit
//! normal `N`; `Π(p, n, q) = −n·(q − p)`):
//! - sharp normals `N'± = (N ± σD) / ‖N ± σD‖`, `+` on the side `D` points to;
//! - edge control point `b = d + e` with `d = P_j + (1 − θ)/3 (P_k − P_j)` and
//!   `e = (1 − δ) Π(P_j, X, d) X + δ Π(P_j, N, d) Y`,
//!   `X = ((1 − σ)N + N') / ‖…‖`, `Y = (N + βD) / ‖…‖`.
//!
//! **δ, the weight our copy of the paper never defines,** is 1 on a crease edge and 0 on every
//! other edge. Why: a crease edge is shared by triangles on the two sides of the crease, and
//! `X` depends on the side (through `N'`) while `Y` does not; only `δ = 1` there gives both
//! triangles the same edge control points, so the crease curve is one curve (watertight), and
//! it lies in the tangent plane of `N` tilted by the bias, as the seed's Fig. 6 creases do.
//! Off the crease, `δ = 0` bends the surface toward the side's sharp normal, which is what
//! makes the crease sharp. With every tag zero the formula is PN's (`X = Y = N`, `d` a third
//! of the edge): `tests/scalar_tags.rs` checks that untagged triangles are PN's to the bit.
//!
//! **Sides.** An edge control point's side is the sign of `D·(P_k − P_j)` (the edge's own
//! direction, so both triangles of an edge agree and the edge is welded by bits); a triangle's
//! corner normal (shading) takes the side of the triangle's centroid. The two sides' normals
//! differ across the crease: that is the crease's shading, not a crack.
//!
//! **On the GPU.** A tagged mesh draws its triangles' corners unshared (each corner carries its
//! side's normal) with a [`TaggedCorner`] each; untagged corners' edge points stay PN's, computed
//! in the shader (`glsl/pn/pn.glsl`, `pn_patch_tagged`).
use crate::error::{Result, TessError};
use crate::gpu::{TaggedCorner, Vertex};
use crate::render_mesh::RenderMesh;
use topology::mesh::scalar_tags::{self, CreaseEdges, ScalarTag};
use topology::{ControlMesh, TopologyError};

type V3 = [f64; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn sub(a: V3, b: V3) -> V3 {
    [a[0] - b[0], a[1] - b[1], a[2] - b[2]]
}
fn scale(a: V3, s: f64) -> V3 {
    [a[0] * s, a[1] * s, a[2] * s]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

/// A unit vector along `a`, or an error naming `vertex` and `what` vanished.
fn unit(a: V3, vertex: u32, what: &str) -> Result<V3> {
    let len = dot(a, a).sqrt();
    if len > 0.0 && len.is_finite() {
        Ok(scale(a, 1.0 / len))
    } else {
        Err(TessError::Topology(TopologyError::ScalarTag {
            vertex,
            problem: format!("{what} is zero (the tags cancel the vertex normal)"),
        }))
    }
}

/// One tagged corner's data in f64.
struct Corner<'a> {
    tag: &'a ScalarTag,
    p: V3,
    n: V3,
}

impl Corner<'_> {
    fn deviation(&self) -> V3 {
        self.tag.deviation.map(f64::from)
    }

    /// `+1` on the side `D` points to from `P` toward `q` (ties go to `+`), else `−1`.
    fn side(&self, q: V3) -> f64 {
        if dot(self.deviation(), sub(q, self.p)) >= 0.0 {
            1.0
        } else {
            -1.0
        }
    }

    /// `N'` on side `s`.
    fn sharp_normal(&self, s: f64) -> Result<V3> {
        let sd = scale(self.deviation(), s * f64::from(self.tag.sharpness));
        unit(add(self.n, sd), self.tag.vertex, "the sharp normal N ± σD")
    }

    /// The edge control point next to this corner on the edge toward `pk`.
    fn edge_point(&self, pk: V3, crease: bool) -> Result<V3> {
        let t = self.tag;
        let d = add(
            self.p,
            scale(sub(pk, self.p), (1.0 - f64::from(t.tension)) / 3.0),
        );
        let along = sub(d, self.p);
        let e = if crease {
            let y = add(self.n, scale(self.deviation(), f64::from(t.bias)));
            let y = unit(y, t.vertex, "the crease normal N + βD")?;
            scale(y, -dot(self.n, along))
        } else {
            let sharp = self.sharp_normal(self.side(pk))?;
            let x = add(scale(self.n, 1.0 - f64::from(t.sharpness)), sharp);
            let x = unit(x, t.vertex, "the blended normal (1 − σ)N + N'")?;
            scale(x, -dot(x, along))
        };
        Ok(add(d, e))
    }
}

/// A tagged mesh as the GPU draws it: unshared corners (three vertices per triangle, in
/// triangle order) and their [`TaggedCorner`]s, parallel.
pub struct TaggedMesh {
    pub render: RenderMesh,
    pub corners: Vec<TaggedCorner>,
}

fn f64s(a: [f32; 3]) -> V3 {
    a.map(f64::from)
}

fn f32s(a: V3) -> [f32; 3] {
    a.map(|x| x as f32)
}

/// Checks `mesh`'s tags ([`scalar_tags::check`]) and shapes the triangles of `render` (made
/// from `mesh`) with them.
pub fn tag_mesh(mesh: &ControlMesh, render: &RenderMesh) -> Result<TaggedMesh> {
    let (tags, creases) = scalar_tags::check(mesh)?;
    let mut vertices = Vec::with_capacity(3 * render.triangles.len());
    let mut corners = Vec::with_capacity(3 * render.triangles.len());
    for (t, tri) in render.triangles.iter().enumerate() {
        let origin = render.triangle_origins[t];
        let face = mesh.face(origin.face as usize);
        let slots = origin.face_corners();
        let base: [u32; 3] = std::array::from_fn(|k| face[slots[k] as usize]);
        let v: [Vertex; 3] = tri.map(|i| render.vertices[i as usize]);
        for k in 0..3 {
            let tag = tags.get(&base[k]).filter(|t| t.shapes());
            let (vertex, corner) = match tag {
                None => (v[k], TaggedCorner::default()),
                Some(tag) => tagged_corner(tag, &v, base, k, &creases)?,
            };
            vertices.push(vertex);
            corners.push(corner);
        }
    }
    let n = vertices.len() as u32;
    Ok(TaggedMesh {
        render: RenderMesh {
            vertices,
            triangles: (0..n / 3).map(|t| [3 * t, 3 * t + 1, 3 * t + 2]).collect(),
            triangle_origins: render.triangle_origins.clone(),
            bbox_min: render.bbox_min,
            bbox_max: render.bbox_max,
            ..RenderMesh::default()
        },
        corners,
    })
}

/// Corner `k` of the triangle `v` (base vertices `base`) under `tag`: its vertex with the
/// side's sharp normal, and its two edge control points.
fn tagged_corner(
    tag: &ScalarTag,
    v: &[Vertex; 3],
    base: [u32; 3],
    k: usize,
    creases: &CreaseEdges,
) -> Result<(Vertex, TaggedCorner)> {
    let (next, prev) = ((k + 1) % 3, (k + 2) % 3);
    let c = Corner {
        tag,
        p: f64s(v[k].position),
        n: f64s(v[k].normal),
    };
    let normal = if tag.has_crease() {
        let centroid = scale(
            add(add(c.p, f64s(v[next].position)), f64s(v[prev].position)),
            1.0 / 3.0,
        );
        f32s(c.sharp_normal(c.side(centroid))?)
    } else {
        v[k].normal
    };
    let point = |j: usize| -> Result<[f32; 4]> {
        let b = c.edge_point(f64s(v[j].position), creases.contains(base[k], base[j]))?;
        let [x, y, z] = f32s(b);
        Ok([x, y, z, 1.0])
    };
    Ok((
        Vertex {
            position: v[k].position,
            normal,
        },
        TaggedCorner {
            b_next: point(next)?,
            b_prev: point(prev)?,
        },
    ))
}

#[cfg(test)]
mod tests {
    use super::*;

    fn corner(tag: &ScalarTag) -> Corner<'_> {
        Corner {
            tag,
            p: [0.0; 3],
            n: [0.0, 0.0, 1.0],
        }
    }

    fn zero() -> ScalarTag {
        ScalarTag {
            vertex: 0,
            deviation: [0.0; 3],
            tension: 0.0,
            sharpness: 0.0,
            bias: 0.0,
        }
    }

    /// PN's `b_ij = (2 P_i + P_j − s_ij N_i) / 3` with `s_ij = (P_j − P_i)·N_i`.
    fn pn_point(pj: V3, nj: V3, pk: V3) -> V3 {
        let s = dot(sub(pk, pj), nj);
        scale(sub(add(scale(pj, 2.0), pk), scale(nj, s)), 1.0 / 3.0)
    }

    fn close(a: V3, b: V3) -> bool {
        (0..3).all(|i| (a[i] - b[i]).abs() < 1e-12)
    }

    #[test]
    fn zero_tags_give_pn_edge_points_on_and_off_creases() {
        let z = zero();
        let c = corner(&z);
        let pk = [1.0, 0.5, 0.3];
        for crease in [false, true] {
            assert!(close(
                c.edge_point(pk, crease).unwrap(),
                pn_point(c.p, c.n, pk)
            ));
        }
    }

    #[test]
    fn full_sharpness_puts_the_tangent_in_the_sides_sharp_plane() {
        // D along +y, σ = 1: the + side's sharp normal is (0, 1, 1)/√2.
        let t = ScalarTag {
            deviation: [0.0, 1.0, 0.0],
            sharpness: 1.0,
            ..zero()
        };
        let c = corner(&t);
        let pk = [0.0, 1.0, 0.0];
        let b = c.edge_point(pk, false).unwrap();
        let sharp = c.sharp_normal(1.0).unwrap();
        assert!(dot(b, sharp).abs() < 1e-12, "{b:?} off the sharp plane");
        // The − side in its own sharp plane: both sides fall away from the crease (a ridge).
        let b_minus = c.edge_point([0.0, -1.0, 0.0], false).unwrap();
        assert!(dot(b_minus, c.sharp_normal(-1.0).unwrap()).abs() < 1e-12);
        assert!(b[2] < -0.16 && b_minus[2] < -0.16, "{b:?} {b_minus:?}");
    }

    #[test]
    fn crease_edges_ignore_the_side_and_follow_the_bias() {
        let t = ScalarTag {
            deviation: [0.0, 1.0, 0.0],
            sharpness: 1.0,
            bias: 0.5,
            ..zero()
        };
        let c = corner(&t);
        let pk = [1.0, 0.0, 0.2];
        let b = c.edge_point(pk, true).unwrap();
        // e = −N·(d − P) Y with Y ∝ N + βD: the offset from d is along (0, 0.5, 1).
        let d = scale(pk, 1.0 / 3.0);
        let e = sub(b, d);
        assert!((e[1] * 2.0 - e[2]).abs() < 1e-12 && e[0] == 0.0, "{e:?}");
        assert!((dot(e, [0.0, 0.5, 1.0]) / 1.25f64.sqrt() + d[2]).abs() < 1e-12);
    }

    #[test]
    fn tension_shortens_the_tangent() {
        let t = ScalarTag {
            tension: 1.0,
            ..zero()
        };
        let b = corner(&t).edge_point([1.0, 0.0, 0.5], false).unwrap();
        assert!(close(b, [0.0; 3]), "{b:?}");
    }

    #[test]
    fn a_cancelled_normal_is_a_named_error() {
        let t = ScalarTag {
            vertex: 7,
            deviation: [0.0, 0.0, -1.0],
            sharpness: 1.0,
            ..zero()
        };
        let e = corner(&t).sharp_normal(1.0).unwrap_err().to_string();
        assert!(e.contains("vertex 7") && e.contains("sharp normal"), "{e}");
    }
}
