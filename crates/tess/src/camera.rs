//! An orbit camera framed from the mesh's bounding box.
use glam::{Mat4, Vec3};

/// Orbit parameters: angles in degrees, zoom > 1 moves closer.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Camera {
    pub yaw: f32,
    pub pitch: f32,
    pub zoom: f32,
    pub fov_y_degrees: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            yaw: 35.0,
            pitch: 20.0,
            zoom: 1.0,
            fov_y_degrees: 40.0,
        }
    }
}

/// The smallest radius framed: far above f32's smallest normal number (1.2e-38), so the eye's
/// distance and the near plane (a hundredth of it) stay normal numbers.
const MIN_RADIUS: f32 = 1e-33;

/// View, projection and eye position for one frame.
#[derive(Clone, Copy, Debug)]
pub struct CameraMatrices {
    pub view: Mat4,
    pub proj: Mat4,
    pub eye: Vec3,
}

impl Camera {
    /// Places the eye on a sphere around the box centre, far enough that the bounding sphere
    /// fits the vertical field of view (and the horizontal one for narrow images).
    pub fn matrices(&self, bbox_min: [f32; 3], bbox_max: [f32; 3], aspect: f32) -> CameraMatrices {
        let lo = Vec3::from(bbox_min);
        let hi = Vec3::from(bbox_max);
        let center = (lo + hi) * 0.5;
        // A box that is a point (or thinner than f32 resolves at its distance from the origin)
        // would put the eye on the centre after rounding: NaN view. The radius is kept to a
        // few hundred ulps of the centre's largest coordinate, and above f32's smallest normal
        // numbers (a point at the origin). No other floor: a mesh of size 1e-9 or 1e-30 fills
        // the view like one of size 1. Nothing below squares a length of the mesh's size (the
        // box's diagonal is taken scaled, the view direction is the unit `dir`), so nothing
        // underflows.
        let resolution = center.abs().max_element() * 1e-4;
        let half = hi - lo;
        let scale = half.abs().max_element();
        let diagonal = if scale > 0.0 {
            (half / scale).length() * scale
        } else {
            0.0
        };
        let radius = (diagonal * 0.5).max(resolution).max(MIN_RADIUS);
        let fov = self.fov_y_degrees.to_radians();
        let half = (fov * 0.5).tan().min((fov * 0.5).tan() * aspect.max(1e-3));
        let distance = radius / half.atan().sin() / self.zoom.max(1e-3);
        let (yaw, pitch) = (
            self.yaw.to_radians(),
            self.pitch.clamp(-89.0, 89.0).to_radians(),
        );
        let dir = Vec3::new(
            yaw.sin() * pitch.cos(),
            pitch.sin(),
            yaw.cos() * pitch.cos(),
        );
        let eye = center + dir * distance;
        let view = Mat4::look_to_rh(eye, -dir, Vec3::Y);
        let near = (distance - radius * 1.5).max(distance * 0.01);
        let far = distance + radius * 1.5;
        let proj = Mat4::perspective_rh(fov, aspect.max(1e-3), near, far);
        CameraMatrices { view, proj, eye }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn finite(m: &CameraMatrices) -> bool {
        m.view.is_finite() && m.proj.is_finite() && m.eye.is_finite()
    }

    #[test]
    fn degenerate_boxes_give_finite_matrices() {
        let cam = Camera::default();
        for (lo, hi) in [
            ([0.0; 3], [0.0; 3]),
            ([1e6; 3], [1e6; 3]),
            ([1e12, -1e12, 3.0], [1e12, -1e12, 3.0]),
            ([-1e12; 3], [1e12; 3]),
            ([1e-30; 3], [2e-30; 3]),
            ([5e5, 0.0, 0.0], [5e5 + 0.0625, 0.0, 0.0]),
        ] {
            let m = cam.matrices(lo, hi, 4.0 / 3.0);
            assert!(finite(&m), "{lo:?}..{hi:?}: {m:?}");
            assert_ne!(m.eye, Vec3::from(lo), "{lo:?}: eye on the centre");
        }
    }

    /// A small box fills the view as a large one does: its corners project to the same
    /// normalized device coordinates (the eye's distance follows the box, with no absolute
    /// floor; one of 1e-6 kept a 1e-9 cube a thousandth of the picture).
    #[test]
    fn small_boxes_fill_the_view_like_large_ones() {
        let cam = Camera::default();
        let project = |s: f32| {
            let m = cam.matrices([-s; 3], [s; 3], 4.0 / 3.0);
            let p = m.proj * m.view * glam::Vec4::new(s, s, s, 1.0);
            glam::Vec2::new(p.x / p.w, p.y / p.w)
        };
        let unit = project(1.0);
        for s in [1e-3, 1e-6, 1e-9, 1e-12, 1e-20, 1e-30] {
            let q = project(s);
            assert!((q - unit).length() < 1e-3, "{s}: {q} against {unit}");
        }
    }
}
