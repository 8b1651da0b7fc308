//! The base mesh as the GPU techniques upload it, and `--animate`'s deformation of it.
//!
//! Every technique that takes [`crate::technique::Technique::update_base`] uploads f32 base
//! positions ([`base_positions`]: the coordinates the GPU draws, see
//! [`crate::techniques::shared::gpu_coordinate`]); the animation moves them along the base
//! normals by a travelling wave ([`Wave`], the Doo-Sabin paper's §3 wobble), so an animated
//! frame costs one upload of base positions whatever the technique refines from them.
use crate::techniques::shared::gpu_coordinate;
use topology::ControlMesh;

/// The base positions of `mesh` in f32.
pub fn base_positions(mesh: &ControlMesh) -> Vec<[f32; 3]> {
    mesh.positions
        .iter()
        .map(|p| p.map(gpu_coordinate))
        .collect()
}

/// Axis-aligned bounds of points.
pub fn bbox(points: &[[f32; 3]]) -> ([f32; 3], [f32; 3]) {
    let mut lo = [f32::MAX; 3];
    let mut hi = [f32::MIN; 3];
    for p in points {
        for k in 0..3 {
            lo[k] = lo[k].min(p[k]);
            hi[k] = hi[k].max(p[k]);
        }
    }
    if points.is_empty() {
        ([0.0; 3], [0.0; 3])
    } else {
        (lo, hi)
    }
}

/// Per-vertex unit normals of the base mesh (area-weighted face normals), the directions the
/// animation moves vertices along.
pub fn base_normals(mesh: &ControlMesh) -> Vec<[f32; 3]> {
    let mut n = vec![glam::DVec3::ZERO; mesh.positions.len()];
    for f in mesh.faces() {
        let p = |i: usize| glam::DVec3::from(mesh.positions[f[i] as usize]);
        for k in 1..f.len().saturating_sub(1) {
            let c = (p(k) - p(0)).cross(p(k + 1) - p(0));
            for &v in f {
                n[v as usize] += c;
            }
        }
    }
    n.iter()
        .map(|v| v.normalize_or_zero().as_vec3().to_array())
        .collect()
}

/// The `--animate` deformation (a travelling wave along the vertex normals, as in the Doo-Sabin
/// paper's §3): base position + `amplitude · sin(2π(k·p/diag − t))` along the normal. Only these
/// positions are uploaded per frame.
pub fn wave(
    base: &[[f32; 3]],
    normals: &[[f32; 3]],
    bbox_min: [f32; 3],
    bbox_max: [f32; 3],
    time: f32,
) -> Vec<[f32; 3]> {
    let lo = glam::Vec3::from(bbox_min);
    let hi = glam::Vec3::from(bbox_max);
    let diag = (hi - lo).length().max(1e-6);
    let dir = glam::Vec3::new(0.6, 0.8, 0.0);
    let amplitude = 0.03 * diag;
    base.iter()
        .zip(normals)
        .map(|(p, n)| {
            let p = glam::Vec3::from(*p);
            let phase = 2.0 * std::f32::consts::PI * (2.0 * dir.dot(p - lo) / diag - 0.5 * time);
            (p + glam::Vec3::from(*n) * amplitude * phase.sin()).to_array()
        })
        .collect()
}

/// The `--animate` wave at time `t` applied to the rest pose of a mesh: what is uploaded.
/// Works for any technique that takes [`Technique::update_base`](crate::technique::Technique::update_base).
pub struct Wave {
    rest: Vec<[f32; 3]>,
    normals: Vec<[f32; 3]>,
    bbox: ([f32; 3], [f32; 3]),
}

impl Wave {
    pub fn new(mesh: &ControlMesh) -> Self {
        let rest = base_positions(mesh);
        // The amplitude follows the drawn size, not a far vertex no face uses.
        let bbox = crate::framing::drawn_bbox(mesh);
        Self {
            normals: base_normals(mesh),
            rest,
            bbox,
        }
    }

    pub fn at(&self, t: f32) -> Vec<[f32; 3]> {
        wave(&self.rest, &self.normals, self.bbox.0, self.bbox.1, t)
    }
}
