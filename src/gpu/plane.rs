//! The plane object of the environment view (LECTURE.md N13): the Rust twin
//! of `plane_at` in `shaders/env.wgsl`. Each BRDF's tile shows, in the square
//! its sphere would fill, a flat sample of infinite extent seen through a
//! pinhole camera pitched down towards it; the camera has no position
//! because the environment is distant and the plane shadows nothing.

use super::sphere::Grid;
use glam::{DVec2, DVec3};

/// What the ray through pixel position `p` sees.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum PlaneRay {
    /// Outside every tile's square: the view's own background.
    Outside,
    /// Inside tile `tile`'s square, above the horizon: the environment
    /// along `dir` (view space: x right, y up, z towards the viewer).
    Sky {
        /// The tile.
        tile: usize,
        /// The camera ray.
        dir: DVec3,
    },
    /// The plane of tile `tile`, seen along `dir`; its normal is +y.
    Plane {
        /// The tile.
        tile: usize,
        /// The camera ray (pointing away from the eye, `dir.y < 0`).
        dir: DVec3,
    },
}

/// The ray through `p` (pixels, y down) in an image of `size` with `tiles`
/// tiles, for a camera whose vertical half field of view has tangent
/// `fov_tan`, looking down at `elevation` radians below the horizon.
pub fn camera_ray(p: DVec2, size: DVec2, tiles: usize, fov_tan: f64, elevation: f64) -> PlaneRay {
    let grid = Grid::new(tiles, size);
    let tile = grid.tile_at(p, size);
    let (c, r) = grid.circle(tile, size);
    let q = (p - c) / r;
    if q.x.abs() > 1.0 || q.y.abs() > 1.0 {
        return PlaneRay::Outside;
    }
    let (s, co) = elevation.sin_cos();
    let forward = DVec3::new(0.0, -s, -co);
    let up = DVec3::new(0.0, co, -s);
    let dir = (forward + fov_tan * (q.x * DVec3::X - q.y * up)).normalize();
    if dir.y >= 0.0 {
        PlaneRay::Sky { tile, dir }
    } else {
        PlaneRay::Plane { tile, dir }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn straight_down_sees_only_the_plane_and_low_sees_the_horizon() {
        let size = DVec2::new(100.0, 100.0);
        let fov_tan = 30f64.to_radians().tan();
        let centre = DVec2::new(50.0, 50.0);
        match camera_ray(centre, size, 1, fov_tan, 90f64.to_radians()) {
            PlaneRay::Plane { dir, .. } => assert!((dir + DVec3::Y).length() < 1e-12),
            other => panic!("{other:?}"),
        }
        // Every pixel of the square is the plane when looking straight down.
        for y in 6..94 {
            let p = DVec2::new(50.5, f64::from(y) + 0.5);
            assert!(matches!(
                camera_ray(p, size, 1, fov_tan, 90f64.to_radians()),
                PlaneRay::Plane { .. }
            ));
        }
        // At 5° the horizon crosses the square 5° above its centre: the
        // pixel rows above it see the sky.
        let e = 5f64.to_radians();
        let horizon = 50.0 - 45.0 * e.tan() / fov_tan;
        let above = DVec2::new(50.5, horizon - 1.0);
        let below = DVec2::new(50.5, horizon + 1.0);
        assert!(matches!(
            camera_ray(above, size, 1, fov_tan, e),
            PlaneRay::Sky { .. }
        ));
        assert!(matches!(
            camera_ray(below, size, 1, fov_tan, e),
            PlaneRay::Plane { .. }
        ));
        assert_eq!(
            camera_ray(DVec2::new(1.0, 1.0), size, 1, fov_tan, e),
            PlaneRay::Outside
        );
    }
}
