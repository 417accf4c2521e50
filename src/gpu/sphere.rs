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

/// How the spheres of a view are arranged: `cols` tiles to a row, as many
/// rows as needed, the last row's tiles centred. One row unless a grid makes
/// the spheres at least [`Grid::GRID_GAIN`] times larger: three or four
/// BRDFs side by side stay a row, six on a slide become 3 × 2 (their labels
/// fit), Cook & Torrance's twelve materials 6 × 2
/// (LECTURE.md N5, small multiples). A function of the tile count and the
/// image's aspect only, so the shaders (given `cols`), the CPU reference and
/// the overlays drawn in points agree.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Grid {
    /// Number of spheres.
    pub tiles: usize,
    /// Tiles in a full row.
    pub cols: usize,
}

impl Grid {
    /// A grid is used only when its spheres are this much larger than one
    /// row's: a row reads left to right, and scenes with a few BRDFs keep it.
    pub const GRID_GAIN: f64 = 1.15;

    /// The arrangement of `tiles` spheres in an image of `size`.
    pub fn new(tiles: usize, size: DVec2) -> Self {
        let tiles = tiles.max(1);
        let radius = |cols: usize| {
            let rows = tiles.div_ceil(cols);
            (size.x / cols as f64).min(size.y / rows as f64)
        };
        let best = best_columns(tiles, 1e-9, radius);
        let cols = if radius(best) > Self::GRID_GAIN * radius(tiles) {
            best
        } else {
            tiles
        };
        Self { tiles, cols }
    }

    /// Number of rows.
    pub fn rows(&self) -> usize {
        self.tiles.div_ceil(self.cols)
    }

    /// Width and height of one tile.
    pub fn tile_size(&self, size: DVec2) -> DVec2 {
        DVec2::new(size.x / self.cols as f64, size.y / self.rows() as f64)
    }

    /// Tiles in `row` and the row's left margin (its tiles centred).
    fn row_span(&self, row: usize, size: DVec2) -> (usize, f64) {
        let n = self.cols.min(self.tiles - row * self.cols);
        (n, 0.5 * (self.cols - n) as f64 * self.tile_size(size).x)
    }

    /// The tile whose cell holds `p` (a point in a row's margin or outside
    /// the image goes to the nearest tile of its row).
    pub fn tile_at(&self, p: DVec2, size: DVec2) -> usize {
        // Counted against the same edges as [`Grid::pixels`], so that a
        // pixel centre on an edge goes to the same tile in both.
        let row = (1..self.rows())
            .filter(|&j| p.y >= self.row_edge(j, size))
            .count();
        let (n, _) = self.row_span(row, size);
        let col = (1..n)
            .filter(|&j| p.x >= self.col_edge(row, j, size))
            .count();
        row * self.cols + col
    }

    /// The top of row `j`.
    fn row_edge(&self, j: usize, size: DVec2) -> f64 {
        j as f64 * self.tile_size(size).y
    }

    /// The left edge of tile `j` of `row`.
    fn col_edge(&self, row: usize, j: usize, size: DVec2) -> f64 {
        let (_, off) = self.row_span(row, size);
        off + j as f64 * self.tile_size(size).x
    }

    /// Centre and radius of sphere `k`.
    pub fn circle(&self, k: usize, size: DVec2) -> (DVec2, f64) {
        let t = self.tile_size(size);
        let row = k / self.cols;
        let (_, off) = self.row_span(row.min(self.rows() - 1), size);
        let col = k % self.cols;
        (
            DVec2::new(off + (col as f64 + 0.5) * t.x, (row as f64 + 0.5) * t.y),
            0.5 * FILL * t.x.min(t.y),
        )
    }

    /// The pixels `[x0, x1) × [y0, y1)` of tile `k` in an image `width` ×
    /// `height`: a pixel belongs to the tile of its centre, as in
    /// shaders/common/sphere.wgsl. The tiles cover the image (a row's
    /// margins go to its outer tiles, so that a view that draws a
    /// background under every pixel draws it there too).
    pub fn pixels(&self, k: usize, width: u32, height: u32) -> [u32; 4] {
        let size = DVec2::new(f64::from(width), f64::from(height));
        let row = (k / self.cols).min(self.rows() - 1);
        let (n, _) = self.row_span(row, size);
        let col = (k - row * self.cols).min(n - 1);
        // The first pixel whose centre is at or past `edge`.
        let start = |edge: f64, limit: u32| ((edge - 0.5).ceil().max(0.0) as u32).min(limit);
        let x0 = if col == 0 {
            0
        } else {
            start(self.col_edge(row, col, size), width)
        };
        let x1 = if col + 1 == n {
            width
        } else {
            start(self.col_edge(row, col + 1, size), width)
        };
        let y0 = if row == 0 {
            0
        } else {
            start(self.row_edge(row, size), height)
        };
        let y1 = if row + 1 == self.rows() {
            height
        } else {
            start(self.row_edge(row + 1, size), height)
        };
        [x0, x1, y0, y1]
    }
}

/// How many of `n` panels to put in a row so that `scale(cols)` (the size
/// a panel gets) is largest; on a tie (within `tol`, relative) the fewest
/// empty cells in the last row (3 + 3 rather than 4 + 2), then the fewest
/// rows. The sphere grid and the polar view's small multiples use it.
pub fn best_columns(n: usize, tol: f64, scale: impl Fn(usize) -> f64) -> usize {
    let n = n.max(1);
    let empty = |cols: usize| cols * n.div_ceil(cols) - n;
    let mut best = n;
    for cols in (1..n).rev() {
        let (r, rb) = (scale(cols), scale(best));
        let tie = (r - rb).abs() <= tol * rb;
        if (!tie && r > rb) || (tie && empty(cols) < empty(best)) {
            best = cols;
        }
    }
    best
}

/// The sphere point under position `p` (pixels, y down, pixel centres at +0.5)
/// in an image of `size` with `tiles` spheres arranged by [`Grid::new`];
/// `None` on the background.
pub fn sphere_at(p: DVec2, size: DVec2, tiles: usize) -> Option<SpherePoint> {
    let grid = Grid::new(tiles, size);
    let tile = grid.tile_at(p, size);
    let (c, r) = grid.circle(tile, size);
    let u = (p.x - c.x) / r;
    let v = (c.y - p.y) / r;
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
    let grid = Grid::new(tiles, size);
    let (c, _) = grid.circle(grid.tile_at(p, size), size);
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

    #[test]
    fn a_few_tiles_stay_a_row_and_many_become_a_grid() {
        let slide = DVec2::new(1800.0, 900.0);
        for tiles in 1..=4 {
            assert_eq!(Grid::new(tiles, slide).cols, tiles);
        }
        let g = Grid::new(12, slide);
        assert_eq!((g.cols, g.rows()), (6, 2));
        assert_eq!(Grid::new(6, slide).cols, 3);
        // A tall image stacks them.
        assert_eq!(Grid::new(3, DVec2::new(300.0, 1200.0)).cols, 1);
    }

    #[test]
    fn tiles_partition_the_image_and_hold_their_spheres() {
        for (tiles, w, h) in [
            (1usize, 7u32, 5u32),
            (2, 300, 100),
            (3, 301, 100),
            (5, 97, 90),
            (5, 400, 300),
            (7, 640, 480),
            (12, 1800, 900),
            (12, 1801, 877),
        ] {
            let size = DVec2::new(f64::from(w), f64::from(h));
            let grid = Grid::new(tiles, size);
            let mut owner = vec![usize::MAX; (w * h) as usize];
            for k in 0..tiles {
                let [x0, x1, y0, y1] = grid.pixels(k, w, h);
                for y in y0..y1 {
                    for x in x0..x1 {
                        let i = (y * w + x) as usize;
                        assert_eq!(owner[i], usize::MAX, "pixel {x},{y} in two tiles");
                        owner[i] = k;
                        let p = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
                        assert_eq!(grid.tile_at(p, size), k, "{tiles} tiles {w}×{h}: {x},{y}");
                        if let Some(s) = sphere_at(p, size, tiles) {
                            assert_eq!(s.tile, k);
                        }
                    }
                }
                // The sphere lies inside its tile's pixels.
                let (c, r) = grid.circle(k, size);
                assert!(c.x - r >= f64::from(x0) - 1.0 && c.x + r <= f64::from(x1) + 1.0);
                assert!(c.y - r >= f64::from(y0) - 1.0 && c.y + r <= f64::from(y1) + 1.0);
            }
            assert!(
                owner.iter().all(|&k| k < tiles),
                "{tiles} tiles: a pixel in none"
            );
        }
    }
}
