//! A 2D distribution on the unit square that interpolates a table bilinearly,
//! with a marginal-then-conditional inversion warp, optionally conditioned on
//! further parameters: the `Marginal2D<Dimension, Continuous = true>` of
//! Mitsuba (`include/mitsuba/core/distr_2d.h`) and of the RGL loader
//! `powitacq`, which the RGL material format is defined by (Dupuy & Jakob
//! 2018, §4: the VNDF and luminance warps, and the plain interpolants of the
//! NDF, σ and the spectra).
//!
//! The table of each slice has `nx × ny` nodes at `(i/(nx−1), j/(ny−1))`;
//! its density is the bilinear interpolant. Parameters (θi, φi, a channel)
//! select slices, between which every stored quantity (values and CDFs) is
//! interpolated linearly, as Mitsuba does. The arithmetic here is `f64`
//! where Mitsuba's is `f32`; the construction follows it step by step so
//! that the two agree to `f32` rounding.

/// A bilinear 2D distribution over `[0,1]²`, conditioned on parameters.
#[derive(Debug, Clone)]
pub struct Marginal2D {
    nx: usize,
    ny: usize,
    params: Vec<Vec<f64>>,
    strides: Vec<usize>,
    slices: usize,
    data: Vec<f64>,
    marginal: Vec<f64>,
    conditional: Vec<f64>,
}

/// The largest `i` in `[0, size−2]` with `pred(i)` true (0 if none),
/// by bisection: Mitsuba's `math::find_interval`.
pub fn find_interval(size: usize, pred: impl Fn(usize) -> bool) -> usize {
    let mut first: isize = 1;
    let mut len = size as isize - 2;
    while len > 0 {
        let half = len >> 1;
        let middle = first + half;
        if pred(middle as usize) {
            first = middle + 1;
            len -= half + 1;
        } else {
            len = half;
        }
    }
    (first - 1).clamp(0, (size as isize - 2).max(0)) as usize
}

/// Interpolation weights and the base slice of a parameter point.
struct Weights {
    slice: usize,
    w: Vec<(f64, f64)>,
}

impl Marginal2D {
    /// A distribution over `data` (`slices × ny × nx`, x fastest), whose
    /// slices are the grid `params[0] × params[1] × …` (the last varying
    /// fastest). `normalize` scales each slice to integrate to 1;
    /// `build_cdf` (which implies it) prepares [`Self::sample`] and
    /// [`Self::invert`]. Errors say what is wrong (sizes, a slice that
    /// integrates to 0 when a CDF is asked for).
    pub fn new(
        data: &[f64],
        nx: usize,
        ny: usize,
        params: Vec<Vec<f64>>,
        normalize: bool,
        build_cdf: bool,
    ) -> Result<Self, String> {
        if nx < 2 || ny < 2 {
            return Err(format!(
                "a table of {ny}×{nx} nodes: each side needs at least 2"
            ));
        }
        if build_cdf && !normalize {
            return Err("a CDF implies normalisation".into());
        }
        let mut strides = vec![0; params.len()];
        let mut slices = 1usize;
        for (i, p) in params.iter().enumerate().rev() {
            if p.is_empty() {
                return Err(format!("parameter {i} has no values"));
            }
            strides[i] = if p.len() > 1 { slices } else { 0 };
            slices = slices.saturating_mul(p.len());
        }
        let n = nx * ny;
        if data.len() != slices.saturating_mul(n) {
            return Err(format!(
                "{} values for {slices} slices of {ny}×{nx}",
                data.len()
            ));
        }
        let inv_patch = ((nx - 1) * (ny - 1)) as f64;
        let mut out = Vec::with_capacity(data.len());
        let mut marginal = Vec::new();
        let mut conditional = Vec::new();
        if build_cdf {
            marginal.reserve(slices * ny);
            conditional.reserve(slices * n);
            for s in 0..slices {
                let d = &data[s * n..(s + 1) * n];
                let mut cond = vec![0.0; n];
                for y in 0..ny {
                    let mut sum = 0.0;
                    for x in 0..nx - 1 {
                        let i = y * nx + x;
                        sum += 0.5 * (d[i] + d[i + 1]);
                        cond[i + 1] = sum;
                    }
                }
                let mut marg = vec![0.0; ny];
                let mut sum = 0.0;
                for y in 0..ny - 1 {
                    sum += 0.5 * (cond[(y + 1) * nx - 1] + cond[(y + 2) * nx - 1]);
                    marg[y + 1] = sum;
                }
                let total = marg[ny - 1];
                if !(total > 0.0 && total.is_finite()) {
                    return Err(format!("slice {s} integrates to {total}"));
                }
                let norm = 1.0 / total;
                conditional.extend(cond.iter().map(|c| c * norm));
                marginal.extend(marg.iter().map(|c| c * norm));
                out.extend(d.iter().map(|v| v * norm));
            }
        } else {
            for s in 0..slices {
                let d = &data[s * n..(s + 1) * n];
                let mut norm = 1.0 / inv_patch;
                if normalize {
                    let mut sum = 0.0;
                    for y in 0..ny - 1 {
                        for x in 0..nx - 1 {
                            let i = y * nx + x;
                            sum += 0.25 * (d[i] + d[i + 1] + d[i + nx] + d[i + nx + 1]);
                        }
                    }
                    if !(sum > 0.0 && sum.is_finite()) {
                        return Err(format!("slice {s} integrates to {sum}"));
                    }
                    norm = 1.0 / sum;
                }
                out.extend(d.iter().map(|v| v * norm));
            }
        }
        Ok(Self {
            nx,
            ny,
            params,
            strides,
            slices,
            data: out,
            marginal,
            conditional,
        })
    }

    /// Nodes along x and y.
    pub fn size(&self) -> (usize, usize) {
        (self.nx, self.ny)
    }

    /// Number of slices.
    pub fn slices(&self) -> usize {
        self.slices
    }

    /// The (normalised) node values, slice after slice.
    pub fn data(&self) -> &[f64] {
        &self.data
    }

    /// The marginal CDFs over rows, `ny` per slice (empty without a CDF).
    pub fn marginal(&self) -> &[f64] {
        &self.marginal
    }

    /// The conditional CDFs along each row, `nx · ny` per slice (empty
    /// without a CDF).
    pub fn conditional(&self) -> &[f64] {
        &self.conditional
    }

    fn weights(&self, param: &[f64]) -> Weights {
        let mut slice = 0;
        let mut w = Vec::with_capacity(self.params.len());
        for (dim, values) in self.params.iter().enumerate() {
            if values.len() == 1 {
                w.push((1.0, 0.0));
                continue;
            }
            let p = param.get(dim).copied().unwrap_or(0.0);
            let i = find_interval(values.len(), |k| values[k] < p);
            let (p0, p1) = (values[i], values[i + 1]);
            let w1 = ((p - p0) / (p1 - p0)).clamp(0.0, 1.0);
            // A NaN parameter gives weight 0 to the upper slice.
            let w1 = if w1.is_nan() { 0.0 } else { w1 };
            w.push((1.0 - w1, w1));
            slice += self.strides[dim] * i;
        }
        Weights { slice, w }
    }

    /// `table[i0 + …]` interpolated over the parameters, where `size` is the
    /// number of entries per slice of `table`.
    fn lookup(&self, table: &[f64], i0: usize, size: usize, w: &Weights) -> f64 {
        let d = w.w.len();
        let mut acc = 0.0;
        for corner in 0..(1usize << d) {
            let mut weight = 1.0;
            let mut off = 0;
            for (dim, &(w0, w1)) in w.w.iter().enumerate() {
                if corner >> dim & 1 == 1 {
                    weight *= w1;
                    off += self.strides[dim] * size;
                } else {
                    weight *= w0;
                }
            }
            if weight != 0.0 {
                acc += weight * table.get(i0 + off).copied().unwrap_or(0.0);
            }
        }
        acc
    }

    /// The density (or, unnormalised, the interpolated value) at `pos`.
    pub fn eval(&self, pos: [f64; 2], param: &[f64]) -> f64 {
        let w = self.weights(param);
        let (nx, ny) = (self.nx, self.ny);
        let px = pos[0].clamp(0.0, 1.0) * (nx - 1) as f64;
        let py = pos[1].clamp(0.0, 1.0) * (ny - 1) as f64;
        let ox = (px as usize).min(nx - 2);
        let oy = (py as usize).min(ny - 2);
        let (w1x, w1y) = (px - ox as f64, py - oy as f64);
        let (w0x, w0y) = (1.0 - w1x, 1.0 - w1y);
        let size = nx * ny;
        let i = ox + oy * nx + w.slice * size;
        let v00 = self.lookup(&self.data, i, size, &w);
        let v10 = self.lookup(&self.data, i + 1, size, &w);
        let v01 = self.lookup(&self.data, i + nx, size, &w);
        let v11 = self.lookup(&self.data, i + nx + 1, size, &w);
        (w0y * (w0x * v00 + w1x * v10) + w1y * (w0x * v01 + w1x * v11))
            * ((nx - 1) * (ny - 1)) as f64
    }

    /// Maps a uniform point to the distribution: returns the point and the
    /// density there (Mitsuba's `sample_continuous`). Needs `build_cdf`.
    pub fn sample(&self, sample: [f64; 2], param: &[f64]) -> ([f64; 2], f64) {
        let w = self.weights(param);
        let (nx, ny) = (self.nx, self.ny);
        let eps = f64::from(f32::EPSILON) / 2.0;
        let mut s = [
            sample[0].clamp(eps, 1.0 - eps),
            sample[1].clamp(eps, 1.0 - eps),
        ];
        let row_offset = w.slice * ny;
        let fetch_marginal = |i: usize| self.lookup(&self.marginal, row_offset + i, ny, &w);
        let row = find_interval(ny, |i| fetch_marginal(i) < s[1]);
        s[1] -= fetch_marginal(row);
        let size = nx * ny;
        let mut col_offset = row * nx + w.slice * size;
        let r0 = self.lookup(&self.conditional, col_offset + nx - 1, size, &w);
        let r1 = self.lookup(&self.conditional, col_offset + 2 * nx - 1, size, &w);
        let is_const = (r0 - r1).abs() < 1e-4 * (r0 + r1);
        s[1] = if is_const {
            2.0 * s[1] / (r0 + r1)
        } else {
            (r0 - (r0 * r0 - 2.0 * s[1] * (r0 - r1)).max(0.0).sqrt()) / (r0 - r1)
        };
        s[0] *= (1.0 - s[1]) * r0 + s[1] * r1;
        let sy = s[1];
        let fetch_conditional = |i: usize| {
            let v0 = self.lookup(&self.conditional, col_offset + i, size, &w);
            let v1 = self.lookup(&self.conditional, col_offset + i + nx, size, &w);
            (1.0 - sy) * v0 + sy * v1
        };
        let col = find_interval(nx, |i| fetch_conditional(i) < s[0]);
        s[0] -= fetch_conditional(col);
        col_offset += col;
        let v00 = self.lookup(&self.data, col_offset, size, &w);
        let v10 = self.lookup(&self.data, col_offset + 1, size, &w);
        let v01 = self.lookup(&self.data, col_offset + nx, size, &w);
        let v11 = self.lookup(&self.data, col_offset + nx + 1, size, &w);
        let c0 = (1.0 - s[1]) * v00 + s[1] * v01;
        let c1 = (1.0 - s[1]) * v10 + s[1] * v11;
        let is_const = (c0 - c1).abs() < 1e-4 * (c0 + c1);
        let (num, div) = if is_const {
            (2.0 * s[0], c0 + c1)
        } else {
            (
                c0 - (c0 * c0 - 2.0 * s[0] * (c0 - c1)).max(0.0).sqrt(),
                c0 - c1,
            )
        };
        s[0] = if div != 0.0 { num / div } else { num };
        let pdf = ((1.0 - s[0]) * c0 + s[0] * c1) * ((nx - 1) * (ny - 1)) as f64;
        (
            [
                (col as f64 + s[0]) / (nx - 1) as f64,
                (row as f64 + s[1]) / (ny - 1) as f64,
            ],
            pdf,
        )
    }

    /// The inverse of [`Self::sample`]: the uniform point that maps to
    /// `pos`, and the density at `pos` (Mitsuba's `invert_continuous`).
    pub fn invert(&self, pos: [f64; 2], param: &[f64]) -> ([f64; 2], f64) {
        let w = self.weights(param);
        let (nx, ny) = (self.nx, self.ny);
        let mut s = [
            pos[0].clamp(0.0, 1.0) * (nx - 1) as f64,
            pos[1].clamp(0.0, 1.0) * (ny - 1) as f64,
        ];
        let px = (s[0] as usize).min(nx - 2);
        let py = (s[1] as usize).min(ny - 2);
        s[0] -= px as f64;
        s[1] -= py as f64;
        let size = nx * ny;
        let offset = px + py * nx + w.slice * size;
        let v00 = self.lookup(&self.data, offset, size, &w);
        let v10 = self.lookup(&self.data, offset + 1, size, &w);
        let v01 = self.lookup(&self.data, offset + nx, size, &w);
        let v11 = self.lookup(&self.data, offset + nx + 1, size, &w);
        let (w1x, w1y) = (s[0], s[1]);
        let c0 = (1.0 - w1y) * v00 + w1y * v01;
        let c1 = (1.0 - w1y) * v10 + w1y * v11;
        let pdf = (1.0 - w1x) * c0 + w1x * c1;
        s[0] *= c0 + 0.5 * s[0] * (c1 - c0);
        let v0 = self.lookup(&self.conditional, offset, size, &w);
        let v1 = self.lookup(&self.conditional, offset + nx, size, &w);
        s[0] += (1.0 - s[1]) * v0 + s[1] * v1;
        let row = py * nx + w.slice * size;
        let r0 = self.lookup(&self.conditional, row + nx - 1, size, &w);
        let r1 = self.lookup(&self.conditional, row + 2 * nx - 1, size, &w);
        let rt = (1.0 - s[1]) * r0 + s[1] * r1;
        if rt > 0.0 {
            s[0] /= rt;
        }
        s[1] *= r0 + 0.5 * s[1] * (r1 - r0);
        s[1] += self.lookup(&self.marginal, py + w.slice * ny, ny, &w);
        (s, pdf * ((nx - 1) * (ny - 1)) as f64)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn table() -> Marginal2D {
        // A 2×(5×4) table with one parameter; values bumpy and positive.
        let mut d = Vec::new();
        for s in 0..2 {
            for y in 0..4 {
                for x in 0..5 {
                    d.push(1.0 + (x * 3 + y * 7 + s * 5) as f64 % 4.0);
                }
            }
        }
        Marginal2D::new(&d, 5, 4, vec![vec![0.0, 1.0]], true, true).unwrap()
    }

    #[test]
    fn invert_undoes_sample_and_densities_agree() {
        let m = table();
        for &p in &[0.0, 0.3, 1.0] {
            for i in 1..20 {
                for j in 1..20 {
                    let u = [i as f64 / 20.0, j as f64 / 20.0];
                    let (x, pdf) = m.sample(u, &[p]);
                    let (back, pdf2) = m.invert(x, &[p]);
                    assert!((back[0] - u[0]).abs() < 1e-9, "{u:?} {back:?}");
                    assert!((back[1] - u[1]).abs() < 1e-9, "{u:?} {back:?}");
                    assert!((pdf - pdf2).abs() < 1e-9 * pdf);
                    assert!((m.eval(x, &[p]) - pdf).abs() < 1e-9 * pdf);
                }
            }
        }
    }

    #[test]
    fn density_integrates_to_one() {
        // Midpoint rule on a fine grid: the bilinear density integrates to 1
        // on every slice (and so on any interpolation of slices).
        let m = table();
        let n = 400;
        let mut sum = 0.0;
        for i in 0..n {
            for j in 0..n {
                let p = [(i as f64 + 0.5) / n as f64, (j as f64 + 0.5) / n as f64];
                sum += m.eval(p, &[0.4]);
            }
        }
        assert!((sum / (n * n) as f64 - 1.0).abs() < 1e-4, "{sum}");
    }

    #[test]
    fn find_interval_clamps() {
        let v = [0.0, 1.0, 2.0, 3.0];
        assert_eq!(find_interval(4, |i| v[i] < -1.0), 0);
        assert_eq!(find_interval(4, |i| v[i] < 1.5), 1);
        assert_eq!(find_interval(4, |i| v[i] < 9.0), 2);
    }
}
