//! Rays against the heightfield: a 2D DDA over the grid's cells (Amanatides &
//! Woo 1987) with the two triangles of each cell, periodic in x and y, and the
//! specular random walk of a ray that bounces until it leaves.
//!
//! Why a DDA on the CPU: the heightfield is its own acceleration structure
//! (a cell is skipped with one comparison against its highest corner), the
//! traversal needs no build step, and rayon over ray batches keeps the result
//! independent of the thread count. A BVH would pay a build over 2 N²
//! triangles for every new surface, and wgpu compute would make the core
//! depend on a GPU, which bv-core must not.

use super::surface::Surface;
use glam::DVec3;

/// Most cells one traversal may visit before the ray is declared lost (a ray
/// that is numerically trapped below the surface, never a legitimate one:
/// a ray crossing the whole tile at the horizon visits ~2N cells per tile).
const MAX_CELLS: usize = 1 << 22;

/// A triangle's address: cell (i, j) and triangle 0 or 1.
pub type FacetId = (usize, usize, usize);

/// Where a traversal ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Hit {
    /// The ray hit the front face of a triangle.
    Facet {
        /// The triangle.
        id: FacetId,
        /// The hit point (world units, x and y unwrapped).
        point: DVec3,
        /// The triangle's unit normal.
        normal: DVec3,
    },
    /// The ray rose above the highest point: it left the surface.
    Escaped,
    /// The ray went below the lowest point or ran past the cell budget
    /// (numerical failure; counted, never binned).
    Lost,
}

/// The first triangle the ray `origin + t dir` (t > 0) hits from its front,
/// ignoring `skip` (the triangle the ray starts on).
pub fn trace(s: &Surface, origin: DVec3, dir: DVec3, skip: Option<FacetId>) -> Hit {
    let n = s.size();
    let (dx, dy) = s.cell();
    let (hmin, hmax) = s.height_range();
    if dir.z > 0.0 && origin.z > hmax {
        return Hit::Escaped;
    }
    let eps_t = 1e-9 * (dx.max(dy) + (hmax - hmin));
    let nm = n as i64;
    let z_at = |t: f64| {
        if t.is_finite() {
            origin.z + t * dir.z
        } else if dir.z > 0.0 {
            f64::INFINITY
        } else if dir.z < 0.0 {
            f64::NEG_INFINITY
        } else {
            origin.z
        }
    };
    let mut ci = (origin.x / dx).floor() as i64;
    let mut cj = (origin.y / dy).floor() as i64;
    let (step_x, mut tmx, tdx) = axis(origin.x, dir.x, ci, dx);
    let (step_y, mut tmy, tdy) = axis(origin.y, dir.y, cj, dy);
    let mut t_enter = 0.0f64;
    'cells: for _ in 0..MAX_CELLS {
        // Skip whole blocks the ray passes above (coarsest first): the
        // segment's lowest point is at one of its ends.
        for (b, maxima) in s.blocks() {
            let b = *b as i64;
            let nb = nm / b;
            let (bi, bj) = (ci.div_euclid(b), cj.div_euclid(b));
            let bmax = maxima[(bj.rem_euclid(nb) * nb + bi.rem_euclid(nb)) as usize];
            let tbx = boundary(origin.x, dir.x, bi * b, b, dx);
            let tby = boundary(origin.y, dir.y, bj * b, b, dy);
            let tb = tbx.min(tby);
            if z_at(t_enter).min(z_at(tb)) <= bmax + eps_t {
                continue;
            }
            if dir.z > 0.0 && z_at(tb) > hmax {
                return Hit::Escaped;
            }
            if !tb.is_finite() {
                return Hit::Lost;
            }
            // Into the next block: the axis (or axes) whose boundary comes
            // first steps across it; the other takes the cell at that point.
            t_enter = tb;
            let p = origin + tb * dir;
            ci = if tbx <= tby {
                if step_x > 0 { (bi + 1) * b } else { bi * b - 1 }
            } else {
                (p.x / dx).floor() as i64
            };
            cj = if tby <= tbx {
                if step_y > 0 { (bj + 1) * b } else { bj * b - 1 }
            } else {
                (p.y / dy).floor() as i64
            };
            tmx = axis(origin.x, dir.x, ci, dx).1;
            tmy = axis(origin.y, dir.y, cj, dy).1;
            continue 'cells;
        }
        let t_exit = tmx.min(tmy);
        let (i, j) = (ci.rem_euclid(nm) as usize, cj.rem_euclid(nm) as usize);
        let z0 = z_at(t_enter);
        let z1 = z_at(t_exit);
        let cell_max = s
            .height(i, j)
            .max(s.height(i + 1, j))
            .max(s.height(i, j + 1))
            .max(s.height(i + 1, j + 1));
        if z0.min(z1) <= cell_max + eps_t {
            let ou = origin.x - ci as f64 * dx;
            let ov = origin.y - cj as f64 * dy;
            let mut best: Option<(f64, usize)> = None;
            for t in 0..2 {
                if skip == Some((i, j, t)) {
                    continue;
                }
                let f = s.facet(i, j, t);
                // Plane z = a + sx u + sy v: the ray meets it where
                // oz + τ dz = a + sx (ou + τ du) + sy (ov + τ dv).
                let denom = dir.z - f.sx * dir.x - f.sy * dir.y;
                if denom >= 0.0 {
                    continue; // parallel, or reaching the back face
                }
                let tt = (f.a + f.sx * ou + f.sy * ov - origin.z) / denom;
                if !(tt > eps_t && tt >= t_enter - eps_t && tt <= t_exit + eps_t) {
                    continue;
                }
                let a = ((ou + tt * dir.x) / dx).clamp(0.0, 1.0);
                let b = ((ov + tt * dir.y) / dy).clamp(0.0, 1.0);
                if Surface::triangle_at(i, j, a, b) != t {
                    continue;
                }
                if best.is_none_or(|(bt, _)| tt < bt) {
                    best = Some((tt, t));
                }
            }
            if let Some((tt, t)) = best {
                let f = s.facet(i, j, t);
                return Hit::Facet {
                    id: (i, j, t),
                    point: origin + tt * dir,
                    normal: f.normal(),
                };
            }
        }
        if dir.z > 0.0 && z1 > hmax {
            return Hit::Escaped;
        }
        if !t_exit.is_finite() || (dir.z <= 0.0 && z1 < hmin - eps_t) {
            return Hit::Lost;
        }
        if tmx < tmy {
            ci += step_x;
            t_enter = tmx;
            tmx += tdx;
        } else {
            cj += step_y;
            t_enter = tmy;
            tmy += tdy;
        }
    }
    Hit::Lost
}

/// Parameter where the ray leaves the block starting at cell `c0` (side
/// `b` cells of size `size`) along one axis; infinite if it does not move.
fn boundary(o: f64, d: f64, c0: i64, b: i64, size: f64) -> f64 {
    if d > 0.0 {
        ((c0 + b) as f64 * size - o) / d
    } else if d < 0.0 {
        (c0 as f64 * size - o) / d
    } else {
        f64::INFINITY
    }
}

/// DDA set-up along one axis: step, parameter of the first cell boundary,
/// parameter per cell.
fn axis(o: f64, d: f64, c: i64, size: f64) -> (i64, f64, f64) {
    if d > 0.0 {
        (1, ((c + 1) as f64 * size - o) / d, size / d)
    } else if d < 0.0 {
        (-1, (c as f64 * size - o) / d, -size / d)
    } else {
        (0, f64::INFINITY, f64::INFINITY)
    }
}

/// The Fresnel factor applied at each bounce.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum SimFresnel {
    /// F = 1 (every ray keeps its energy: the furnace test).
    None,
    /// A conductor of complex index η + ik (`fresnel::conductor`, exact
    /// unpolarised).
    Conductor {
        /// Real part of the index.
        eta: f64,
        /// Imaginary part (extinction).
        k: f64,
    },
}

impl SimFresnel {
    /// F at the cosine between the incoming ray and the facet normal.
    #[inline]
    pub fn eval(&self, cos: f64) -> f64 {
        match *self {
            SimFresnel::None => 1.0,
            SimFresnel::Conductor { eta, k } => crate::fresnel::conductor(cos, eta, k),
        }
    }
}

/// How a ray's walk on the surface ended.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Walk {
    /// It left the surface in `dir` after `bounces` reflections carrying
    /// `weight` (the product of the Fresnel factors).
    Left {
        /// Outgoing direction (unit, upwards).
        dir: DVec3,
        /// Reflections before it left (≥ 1 for a ray from above).
        bounces: u32,
        /// Product of the Fresnel factors.
        weight: f64,
    },
    /// Still on the surface after the bounce cap: dropped, counted.
    Dropped,
    /// Lost to a numerical failure of the traversal (counted).
    Lost,
}

/// Wraps x and y into the first tile (keeps coordinates small so the
/// traversal keeps its precision over many bounces).
fn wrap(s: &Surface, p: DVec3) -> DVec3 {
    let (dx, dy) = s.cell();
    let (wx, wy) = (dx * s.size() as f64, dy * s.size() as f64);
    DVec3::new(p.x.rem_euclid(wx), p.y.rem_euclid(wy), p.z)
}

/// A ray from `origin` in `dir` reflecting specularly (`d' = d − 2(d·m)m`,
/// the mirror law about the facet normal m) until it leaves, at most
/// `max_bounces` times. `start` is the triangle it starts on, if any (not
/// hit again at t = 0). `path`, when given, receives the points it visits.
pub fn walk(
    s: &Surface,
    origin: DVec3,
    dir: DVec3,
    start: Option<FacetId>,
    fresnel: SimFresnel,
    max_bounces: u32,
    mut path: Option<&mut Vec<DVec3>>,
) -> Walk {
    let mut o = wrap(s, origin);
    let mut d = dir;
    let mut skip = start;
    let mut weight = 1.0;
    if let Some(p) = path.as_deref_mut() {
        p.push(o);
    }
    for bounces in 0..=max_bounces {
        match trace(s, o, d, skip) {
            Hit::Escaped => {
                return Walk::Left {
                    dir: d,
                    bounces,
                    weight,
                };
            }
            Hit::Lost => return Walk::Lost,
            Hit::Facet { id, point, normal } => {
                if bounces == max_bounces {
                    return Walk::Dropped;
                }
                let c = -d.dot(normal);
                weight *= fresnel.eval(c);
                d = (d + 2.0 * c * normal).normalize();
                if let Some(p) = path.as_deref_mut() {
                    p.push(point);
                }
                o = wrap(s, point);
                skip = Some(id);
            }
        }
    }
    Walk::Dropped
}
