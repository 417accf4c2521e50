//! Image-space geometry of the sphere views (the Rust twin of
//! `shaders/common/sphere.wgsl`): where each sphere is, its normal and tangent
//! frame at a pixel, and the inverse a GUI needs to turn a drag into a light
//! direction.

use glam::{DVec2, DVec3};

/// Fraction of the tile's smaller side covered by the sphere's diameter.
pub const FILL: f64 = 0.9;

/// A point on one of the spheres.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SpherePoint {
    /// Which sphere (tile, left to right).
    pub tile: usize,
    /// Unit normal in view space (x right, y up, z towards the viewer).
    pub n: DVec3,
    /// Unit tangent along the parallel (direction of increasing longitude about +y).
    pub t: DVec3,
    /// `n × t`.
    pub b: DVec3,
}

impl SpherePoint {
    /// A view-space direction in the local shading frame.
    pub fn to_local(&self, w: DVec3) -> DVec3 {
        DVec3::new(w.dot(self.t), w.dot(self.b), w.dot(self.n))
    }
}

/// The sphere point under position `p` (pixels, y down, pixel centres at +0.5)
/// in an image of `size` with `tiles` spheres side by side; `None` on the background.
pub fn sphere_at(p: DVec2, size: DVec2, tiles: usize) -> Option<SpherePoint> {
    let tiles = tiles.max(1);
    let tile_w = size.x / tiles as f64;
    let tile = ((p.x / tile_w).floor().max(0.0) as usize).min(tiles - 1);
    let cx = (tile as f64 + 0.5) * tile_w;
    let cy = 0.5 * size.y;
    let r = 0.5 * FILL * tile_w.min(size.y);
    let u = (p.x - cx) / r;
    let v = (cy - p.y) / r;
    let d2 = u * u + v * v;
    if d2 >= 1.0 {
        return None;
    }
    let n = DVec3::new(u, v, (1.0 - d2).sqrt());
    let l = (n.x * n.x + n.z * n.z).sqrt();
    let t = if l > 0.0 {
        DVec3::new(n.z, 0.0, -n.x) / l
    } else {
        DVec3::X
    };
    Some(SpherePoint {
        tile,
        n,
        t,
        b: n.cross(t),
    })
}

/// The light direction a drag at `p` asks for: the normal of the sphere point
/// under it (the light then shines straight onto that point), or, outside the
/// sphere, the direction on its silhouette towards `p`.
pub fn light_from_drag(p: DVec2, size: DVec2, tiles: usize) -> DVec3 {
    if let Some(s) = sphere_at(p, size, tiles) {
        return s.n;
    }
    let tiles = tiles.max(1);
    let tile_w = size.x / tiles as f64;
    let tile = ((p.x / tile_w).floor().max(0.0) as usize).min(tiles - 1);
    let c = DVec2::new((tile as f64 + 0.5) * tile_w, 0.5 * size.y);
    let d = DVec2::new(p.x - c.x, c.y - p.y);
    let d = if d.length_squared() > 0.0 {
        d.normalize()
    } else {
        DVec2::Y
    };
    DVec3::new(d.x, d.y, 0.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn frame_is_orthonormal_and_tangent_follows_parallels() {
        let size = DVec2::new(200.0, 100.0);
        let s = sphere_at(DVec2::new(70.0, 30.0), size, 2).unwrap();
        assert_eq!(s.tile, 0);
        for (a, b) in [(s.n, s.t), (s.n, s.b), (s.t, s.b)] {
            assert!(a.dot(b).abs() < 1e-12);
        }
        assert!((s.n.length() - 1.0).abs() < 1e-12 && (s.t.length() - 1.0).abs() < 1e-12);
        // Tangent is horizontal (a parallel about the vertical axis).
        assert!(s.t.y.abs() < 1e-15);
        // Centre of the second sphere faces the viewer.
        let c = sphere_at(DVec2::new(150.0, 50.0), size, 2).unwrap();
        assert_eq!(c.tile, 1);
        assert!((c.n - DVec3::Z).length() < 1e-12);
        assert!(sphere_at(DVec2::new(1.0, 1.0), size, 2).is_none());
        assert!((light_from_drag(DVec2::new(150.0, 50.0), size, 2) - DVec3::Z).length() < 1e-12);
        let edge = light_from_drag(DVec2::new(199.0, 50.0), size, 2);
        assert!((edge - DVec3::X).length() < 1e-12);
    }
}
