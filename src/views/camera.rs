//! The lobe view's orbit camera: matrices, projection of 3D points to the
//! screen (for labels) and pointer rays (for dragging the light).

use crate::session::state::Camera;
use glam::{Mat4, Vec3, Vec4Swizzles};

/// Vertical field of view, degrees: narrow enough to look like a textbook
/// figure, wide enough to keep some depth cue.
pub const FOV_Y_DEG: f32 = 30.0;

/// The point the camera orbits: a little above the ground, so that a lobe of
/// unit height sits in the middle of the view.
pub const TARGET: Vec3 = Vec3::new(0.0, 0.0, 0.35);

/// The point the camera orbits when the view shows the whole sphere (light
/// from below, or a model that transmits): the origin, so that what lies
/// below the surface is framed as well as what lies above.
pub const WHOLE_TARGET: Vec3 = Vec3::ZERO;

/// How much farther the eye stands when framing the whole sphere: the scene
/// then reaches about 1.2 units below the target as well as above.
pub const WHOLE_ZOOM_OUT: f32 = 1.3;

/// Matrices of one frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CameraMatrices {
    /// World to clip (wgpu convention: depth 0..1).
    pub view_proj: Mat4,
    /// Eye position.
    pub eye: Vec3,
    /// Viewport size in points (for pixel-sized lines).
    pub viewport: [f32; 2],
}

impl CameraMatrices {
    /// Matrices of `cam` for a viewport of `width × height`, framing the
    /// upper hemisphere.
    pub fn new(cam: &Camera, width: f32, height: f32) -> Self {
        Self::framed(cam, width, height, false)
    }

    /// Matrices of `cam` for a viewport of `width × height`; `whole`: frame
    /// the whole sphere (about [`WHOLE_TARGET`], [`WHOLE_ZOOM_OUT`] farther
    /// away) rather than the upper hemisphere.
    pub fn framed(cam: &Camera, width: f32, height: f32, whole: bool) -> Self {
        let (target, eye) = if whole {
            (
                WHOLE_TARGET,
                WHOLE_TARGET + (eye_position(cam) - TARGET) * WHOLE_ZOOM_OUT,
            )
        } else {
            (TARGET, eye_position(cam))
        };
        let view = glam::camera::rh::view::look_at_mat4(eye, target, Vec3::Z);
        let aspect = (width / height.max(1.0)).max(1e-3);
        // In a portrait viewport widen the vertical field so that the
        // horizontal one is a quarter wider than FOV_Y_DEG: the scene (axes and
        // rays reach 1.6 units to the sides, but only about 1.1 above the
        // target) then fits however the view is shaped.
        let half = (FOV_Y_DEG.to_radians() * 0.5).tan();
        let fov_y = if aspect < 1.25 {
            2.0 * (half * 1.25 / aspect).atan()
        } else {
            FOV_Y_DEG.to_radians()
        };
        // wgpu clip space: depth 0..1, y up (the DirectX convention).
        let proj = glam::camera::rh::proj::directx::perspective(fov_y, aspect, 0.05, 200.0);
        Self {
            view_proj: proj * view,
            eye,
            viewport: [width.max(1.0), height.max(1.0)],
        }
    }

    /// Screen position (points, origin top-left of the viewport) of a world
    /// point, and whether it is in front of the camera.
    pub fn project(&self, p: Vec3) -> Option<[f32; 2]> {
        let c = self.view_proj * p.extend(1.0);
        if c.w <= 1e-6 {
            return None;
        }
        let ndc = c.xyz() / c.w;
        Some([
            (ndc.x * 0.5 + 0.5) * self.viewport[0],
            (0.5 - ndc.y * 0.5) * self.viewport[1],
        ])
    }

    /// The world-space ray (origin, unit direction) through a viewport point.
    pub fn ray(&self, x: f32, y: f32) -> (Vec3, Vec3) {
        let inv = self.view_proj.inverse();
        let ndc_x = x / self.viewport[0] * 2.0 - 1.0;
        let ndc_y = 1.0 - y / self.viewport[1] * 2.0;
        let near = inv * glam::Vec4::new(ndc_x, ndc_y, 0.0, 1.0);
        let far = inv * glam::Vec4::new(ndc_x, ndc_y, 1.0, 1.0);
        let near = near.xyz() / near.w;
        let far = far.xyz() / far.w;
        (near, (far - near).normalize_or(Vec3::NEG_Z))
    }
}

/// Eye position of an orbit camera.
pub fn eye_position(cam: &Camera) -> Vec3 {
    let (yaw, pitch) = (cam.yaw_deg.to_radians(), cam.pitch_deg.to_radians());
    TARGET
        + cam.distance
            * Vec3::new(
                pitch.cos() * yaw.cos(),
                pitch.cos() * yaw.sin(),
                pitch.sin(),
            )
}

/// The point of the upper unit hemisphere a ray points at: its hit on the unit
/// sphere (upper half), else the direction of its hit on the ground plane, else
/// `None`. This is what dragging the light on the lobe view uses.
pub fn pick_hemisphere(origin: Vec3, dir: Vec3) -> Option<Vec3> {
    // |o + t d|² = 1 → t² + 2 (o·d) t + |o|² − 1 = 0, nearest root in front.
    let b = origin.dot(dir);
    let c = origin.length_squared() - 1.0;
    let disc = b * b - c;
    if disc >= 0.0 {
        let s = disc.sqrt();
        for t in [-b - s, -b + s] {
            let p = origin + t * dir;
            if t > 0.0 && p.z >= 0.0 {
                return Some(p.normalize());
            }
        }
    }
    if dir.z.abs() > 1e-6 {
        let t = -origin.z / dir.z;
        if t > 0.0 {
            let p = origin + t * dir;
            // Outside the disc: the horizon direction towards that point.
            return Some(Vec3::new(p.x, p.y, 0.0).normalize_or(Vec3::X));
        }
    }
    None
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_whole_sphere_fits_the_view_when_framed_for_it() {
        // The tail of the light's arrow (1.6 units) at θi = 140° and the
        // lobes' unit sphere: outside the upper framing, inside the whole one.
        let (w, h) = (1200.0, 800.0);
        let t = 140f32.to_radians();
        let below = Vec3::new(t.sin(), 0.0, t.cos()) * 1.6;
        let inside = |m: &CameraMatrices, p: Vec3| {
            m.project(p)
                .is_some_and(|s| s[0] >= 0.0 && s[0] <= w && s[1] >= 0.0 && s[1] <= h)
        };
        let upper = CameraMatrices::new(&Camera::default(), w, h);
        let whole = CameraMatrices::framed(&Camera::default(), w, h, true);
        assert!(!inside(&upper, below));
        for p in [
            below,
            Vec3::Z * 1.2,
            Vec3::NEG_Z * 1.2,
            Vec3::X * 1.4,
            Vec3::NEG_X * 1.4,
        ] {
            assert!(inside(&whole, p), "{p}");
        }
    }

    #[test]
    fn target_projects_to_the_centre() {
        let m = CameraMatrices::new(&Camera::default(), 400.0, 300.0);
        let p = m.project(TARGET).unwrap();
        assert!((p[0] - 200.0).abs() < 1e-3 && (p[1] - 150.0).abs() < 1e-3);
        // Up is up on screen.
        let up = m.project(TARGET + Vec3::Z * 0.1).unwrap();
        assert!(up[1] < p[1]);
    }

    #[test]
    fn default_camera_puts_the_light_side_on_the_left() {
        // Light at φi = 0 lies towards +x; the default view shows +x on the left,
        // like the polar plot.
        let m = CameraMatrices::new(&Camera::default(), 400.0, 300.0);
        let px = m.project(Vec3::X).unwrap();
        let nx = m.project(-Vec3::X).unwrap();
        assert!(px[0] < nx[0]);
    }

    #[test]
    fn ray_through_a_projected_point_hits_it() {
        let m = CameraMatrices::new(&Camera::default(), 640.0, 480.0);
        let target = Vec3::new(0.3, 0.5, 0.6).normalize();
        let s = m.project(target).unwrap();
        let (o, d) = m.ray(s[0], s[1]);
        let hit = pick_hemisphere(o, d).unwrap();
        assert!((hit - target).length() < 1e-3, "{hit} vs {target}");
    }
}
