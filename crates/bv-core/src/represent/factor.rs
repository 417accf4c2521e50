//! Factorisation of a tabulated isotropic BRDF (the lecture's
//! "Representations" slide: "into two 2D functions for data reduction, often
//! after reparameterisation").
//!
//! The MERL table `f(θh, θd, φd)` (see [`crate::measured::merl`]) is read as a
//! matrix `M[iθh, (iθd, iφd)]`, one row per θh cell and one column per
//! (θd, φd) cell, per colour channel, and approximated by its truncated SVD,
//! `f_K = Σ_{k ≤ K} g_k(θh) h_k(θd, φd)` (Eckart–Young: the best rank-K
//! approximation in the Frobenius norm). This is the standard teaching
//! baseline for the factored representations of Kautz & McCool 1999
//! ("Interactive rendering with arbitrary BRDFs using separable
//! approximations", which use the SVD) and Lawrence, Rusinkiewicz &
//! Ramamoorthi 2004 ("Efficient BRDF importance sampling using a factored
//! representation", which use a non-negative factorisation in a similar
//! half-angle parameterisation).
//!
//! Choices, and why:
//! - **Per channel**: the three channels are factored separately (three
//!   SVDs), so the reconstruction keeps the material's colour, including a
//!   colour that changes with angle (metals). Factoring the channel mean
//!   would lose that.
//! - **Linear by default**, with an optional log space. In linear space the
//!   truncation is optimal for the relative L2 error that is reported, and
//!   that error is non-increasing in K; but the specular peak dominates the
//!   norm, and a truncated SVD can go negative away from it (rebuilt tables
//!   clamp at 0). In log space (`ln(f + ε)`, as data-driven fits commonly
//!   remap measured BRDFs) the dynamic range is compressed, every cell counts
//!   more evenly and `exp` keeps the reconstruction positive, but the
//!   optimum is then in log space, and the error in `f` need not decrease
//!   monotonically with K. Both errors are reported.
//! - Cells count equally (no solid-angle weight), as in the matrix the
//!   papers factor.
//!
//! The SVD is computed from the Gram matrix `M Mᵀ` (nθh × nθh, 90 × 90 for
//! the public data) with the cyclic Jacobi eigenvalue method, then
//! `h_k = Mᵀ u_k`. Forming `M Mᵀ` squares the condition number, which limits
//! the accuracy of the *small* singular values (to ~1e-8 σ₁), not of the
//! leading vectors; the reported errors are measured on the explicit
//! residual `M − Σ u_k u_kᵀ M`, not derived from the singular values.

use crate::Brdf;
use crate::frame;
use crate::measured::Interpolation;
use crate::measured::merl::{
    MerlDims, MerlTable, phi_d_centre, tabulate, theta_d_centre, theta_h_centre,
};
use crate::models::merl::Merl;
use crate::{BvError, Result};
use std::sync::Arc;

/// The space the table is factored in.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FactorSpace {
    /// `f` itself.
    Linear,
    /// `ln(f + epsilon)` (epsilon > 0 keeps unmeasured zeros finite).
    Log {
        /// Offset added before the logarithm (1/sr).
        epsilon: f64,
    },
    /// `f cos θi cos θo` (each cell's pair, 0 below either horizon), the
    /// reflected light's integrand; the rebuild divides the weight out.
    /// Microfacet models grow like `1/cos θi` towards grazing (in the
    /// mirror configuration θh ≈ 0, θd → 90°, `f ∝ D F / (4 cos² θd)`), so
    /// in linear space a few grazing cells hold most of the table's norm and
    /// the truncated SVD spends its terms on them; weighted, the values are
    /// bounded (`D F G / 4`) and the truncation is optimal for the error
    /// in the light, which is then non-increasing in K.
    Cosine,
}

/// A floor for dividing [`FactorSpace::Cosine`]'s weight out when a rebuilt
/// table is *drawn* (`f = x w / (w² + δ²)`, [`Factorization::table_floored`]):
/// towards the horizon w → 0 and the truncation's residual divided by it
/// spikes, which a lobe drawing shows as needles at the rim. At `w = 10 δ`
/// the rebuild is 1 % low, at `w = δ` half; δ = 0.02 is cos θ = 0.14 (82°)
/// for both directions, or a light at 45° and a view 88° from the normal.
/// The reported errors use the exact division.
pub const COSINE_FLOOR: f64 = 0.02;

/// `cos θi cos θo` of every cell of a `dims` table (index `iθh · nθd nφd +
/// iθd · nφd + iφd`, φh = 0 as tabulated), 0 where either is below the
/// horizon.
pub fn cosine_weights(d: MerlDims) -> Vec<f64> {
    let mut w = Vec::with_capacity(d.cells());
    for ih in 0..d.theta_h {
        for id in 0..d.theta_d {
            for ip in 0..d.phi_d {
                let (wi, wo) = frame::from_half_diff(frame::HalfDiff {
                    theta_h: theta_h_centre(ih, d.theta_h),
                    phi_h: 0.0,
                    theta_d: theta_d_centre(id, d.theta_d),
                    phi_d: phi_d_centre(ip, d.phi_d),
                });
                w.push(if wi.z > 0.0 && wo.z > 0.0 {
                    wi.z * wo.z
                } else {
                    0.0
                });
            }
        }
    }
    w
}

/// Most terms computed.
pub const MAX_TERMS: usize = 64;

/// A truncated SVD of a `rows × cols` matrix: `M ≈ Σ_k sigma_k u_k v_kᵀ`.
#[derive(Debug, Clone, PartialEq)]
pub struct Svd {
    /// Rows of the matrix.
    pub rows: usize,
    /// Columns of the matrix.
    pub cols: usize,
    /// Singular values, non-increasing.
    pub sigma: Vec<f64>,
    /// Left singular vectors (unit, length `rows`).
    pub u: Vec<Vec<f64>>,
    /// Right singular vectors (unit, length `cols`; zero where σ = 0).
    pub v: Vec<Vec<f64>>,
    /// `‖M − M_K‖_F / ‖M‖_F` for K = 1..=terms (index K − 1), from the
    /// explicit residual (0 for a zero matrix).
    pub rel_l2_error: Vec<f64>,
}

/// Eigen-decomposition of a symmetric `n × n` matrix (row-major) by cyclic
/// Jacobi rotations (Golub & Van Loan, *Matrix Computations*, §8.5): returns
/// eigenvalues and eigenvectors (as columns of the returned row-major
/// matrix), unsorted.
fn jacobi_eigen(mut a: Vec<f64>, n: usize) -> (Vec<f64>, Vec<f64>) {
    let mut v = vec![0.0; n * n];
    for i in 0..n {
        v[i * n + i] = 1.0;
    }
    let scale: f64 = a.iter().map(|x| x * x).sum::<f64>().sqrt();
    for _sweep in 0..100 {
        let off: f64 = (0..n)
            .flat_map(|i| (0..n).filter(move |&j| j != i).map(move |j| (i, j)))
            .map(|(i, j)| a[i * n + j] * a[i * n + j])
            .sum::<f64>()
            .sqrt();
        if off <= 1e-15 * scale || scale == 0.0 {
            break;
        }
        for p in 0..n {
            for q in p + 1..n {
                let apq = a[p * n + q];
                if apq == 0.0 {
                    continue;
                }
                let (app, aqq) = (a[p * n + p], a[q * n + q]);
                let theta = (aqq - app) / (2.0 * apq);
                let t = theta.signum() / (theta.abs() + (theta * theta + 1.0).sqrt());
                let t = if theta == 0.0 { 1.0 } else { t };
                let c = 1.0 / (t * t + 1.0).sqrt();
                let s = t * c;
                for k in 0..n {
                    let (akp, akq) = (a[k * n + p], a[k * n + q]);
                    a[k * n + p] = c * akp - s * akq;
                    a[k * n + q] = s * akp + c * akq;
                }
                for k in 0..n {
                    let (apk, aqk) = (a[p * n + k], a[q * n + k]);
                    a[p * n + k] = c * apk - s * aqk;
                    a[q * n + k] = s * apk + c * aqk;
                }
                for k in 0..n {
                    let (vkp, vkq) = (v[k * n + p], v[k * n + q]);
                    v[k * n + p] = c * vkp - s * vkq;
                    v[k * n + q] = s * vkp + c * vkq;
                }
            }
        }
    }
    ((0..n).map(|i| a[i * n + i]).collect(), v)
}

/// The leading `terms` singular triplets of the row-major `rows × cols`
/// matrix `m` (see the module docs for the method), with the relative
/// residual after each.
pub fn truncated_svd(m: &[f64], rows: usize, cols: usize, terms: usize) -> Result<Svd> {
    if rows == 0 || cols == 0 || m.len() != rows * cols {
        return Err(BvError::Invalid(format!(
            "a {rows} × {cols} matrix needs {} values, got {}",
            rows * cols,
            m.len()
        )));
    }
    if m.iter().any(|x| !x.is_finite()) {
        return Err(BvError::Invalid("the matrix has non-finite values".into()));
    }
    let terms = terms.clamp(1, MAX_TERMS).min(rows).min(cols);
    // Gram matrix G = M Mᵀ.
    let mut g = vec![0.0; rows * rows];
    for i in 0..rows {
        let ri = &m[i * cols..(i + 1) * cols];
        for j in i..rows {
            let rj = &m[j * cols..(j + 1) * cols];
            let d: f64 = ri.iter().zip(rj).map(|(a, b)| a * b).sum();
            g[i * rows + j] = d;
            g[j * rows + i] = d;
        }
    }
    let (lambda, vecs) = jacobi_eigen(g, rows);
    let mut order: Vec<usize> = (0..rows).collect();
    order.sort_by(|&a, &b| lambda[b].total_cmp(&lambda[a]));
    let norm2: f64 = m.iter().map(|x| x * x).sum();
    let mut residual = m.to_vec();
    let mut out = Svd {
        rows,
        cols,
        sigma: Vec::with_capacity(terms),
        u: Vec::with_capacity(terms),
        v: Vec::with_capacity(terms),
        rel_l2_error: Vec::with_capacity(terms),
    };
    for &k in order.iter().take(terms) {
        let u: Vec<f64> = (0..rows).map(|i| vecs[i * rows + k]).collect();
        // w = Mᵀ u = σ v.
        let mut w = vec![0.0; cols];
        for (i, &ui) in u.iter().enumerate() {
            for (wj, &mij) in w.iter_mut().zip(&m[i * cols..(i + 1) * cols]) {
                *wj += ui * mij;
            }
        }
        let sigma = w.iter().map(|x| x * x).sum::<f64>().sqrt();
        // Residual −= u wᵀ (uᵀ R = uᵀ M since the u are orthonormal).
        for (i, &ui) in u.iter().enumerate() {
            for (r, &wj) in residual[i * cols..(i + 1) * cols].iter_mut().zip(&w) {
                *r -= ui * wj;
            }
        }
        let v = if sigma > 0.0 {
            w.iter().map(|x| x / sigma).collect()
        } else {
            vec![0.0; cols]
        };
        let err2: f64 = residual.iter().map(|x| x * x).sum();
        out.rel_l2_error.push(if norm2 > 0.0 {
            (err2 / norm2).sqrt()
        } else {
            0.0
        });
        out.sigma.push(sigma);
        out.u.push(u);
        out.v.push(v);
    }
    Ok(out)
}

/// A factored MERL table: per channel, `g_k(θh) = σ_k u_k` over the θh cells
/// and `h_k(θd, φd) = v_k` over the (θd, φd) cells (index
/// `iθd · nφd + iφd`), in [`FactorSpace`].
#[derive(Debug, Clone, PartialEq)]
pub struct Factorization {
    /// Dimensions of the factored table.
    pub dims: MerlDims,
    /// Linear or log.
    pub space: FactorSpace,
    /// One SVD per channel (red, green, blue).
    pub channels: [Svd; 3],
    /// `‖M − M_K‖ / ‖M‖` in the factored space, over the three channels
    /// together, for K = 1..=terms: non-increasing in K.
    pub rel_l2_error: Vec<f64>,
    /// The same for the table of `f` rebuilt from K terms (negative values
    /// clamped at 0, log undone); equal to `rel_l2_error` up to the clamp
    /// in linear space.
    pub rel_l2_error_f: Vec<f64>,
    /// [`cosine_weights`] in [`FactorSpace::Cosine`], empty otherwise.
    pub weights: Vec<f64>,
}

impl Factorization {
    /// Number of terms computed.
    pub fn terms(&self) -> usize {
        self.rel_l2_error.len()
    }

    /// `g_k(θh cell ih)` of channel `c` (0-based k).
    pub fn g(&self, c: usize, k: usize, ih: usize) -> f64 {
        let s = &self.channels[c];
        s.sigma[k] * s.u[k][ih]
    }

    /// `h_k((θd, φd) cell j)` of channel `c` (0-based k, `j = iθd · nφd + iφd`).
    pub fn h(&self, c: usize, k: usize, j: usize) -> f64 {
        self.channels[c].v[k][j]
    }

    /// The value of `f` in cell `(ih, j)` of channel `c` rebuilt from the
    /// first `k` terms (log undone, clamped at 0).
    pub fn value(&self, c: usize, k: usize, ih: usize, j: usize) -> f64 {
        self.value_floored(c, k, ih, j, 0.0)
    }

    /// [`Factorization::value`] with the cosine weight divided out as
    /// `x w / (w² + floor²)` (Tikhonov) in [`FactorSpace::Cosine`]; `floor`
    /// 0 is the exact `x / w`.
    fn value_floored(&self, c: usize, k: usize, ih: usize, j: usize, floor: f64) -> f64 {
        let k = k.min(self.terms());
        let x: f64 = (0..k).map(|t| self.g(c, t, ih) * self.h(c, t, j)).sum();
        let f = match self.space {
            FactorSpace::Linear => x,
            FactorSpace::Log { epsilon } => x.exp() - epsilon,
            FactorSpace::Cosine => {
                let cols = self.dims.theta_d * self.dims.phi_d;
                let w = self.weights.get(ih * cols + j).copied().unwrap_or(0.0);
                if w > 0.0 {
                    x * w / (w * w + floor * floor)
                } else {
                    0.0
                }
            }
        };
        f.max(0.0)
    }

    /// The table rebuilt from the first `k` terms (1..=terms).
    pub fn table(&self, k: usize) -> Result<MerlTable> {
        self.table_floored(k, 0.0)
    }

    /// The table rebuilt from the first `k` terms, dividing the cosine
    /// weight out with a `floor` (see [`COSINE_FLOOR`]); the same as
    /// [`Factorization::table`] outside [`FactorSpace::Cosine`].
    pub fn table_floored(&self, k: usize, floor: f64) -> Result<MerlTable> {
        if k == 0 || k > self.terms() {
            return Err(BvError::Invalid(format!(
                "{k} terms asked for; the factorisation has 1..={}",
                self.terms()
            )));
        }
        let d = self.dims;
        let cols = d.theta_d * d.phi_d;
        let mut data = vec![0f32; 3 * d.cells()];
        for c in 0..3 {
            for ih in 0..d.theta_h {
                for j in 0..cols {
                    data[c * d.cells() + ih * cols + j] =
                        self.value_floored(c, k, ih, j, floor) as f32;
                }
            }
        }
        MerlTable::from_values(d, data)
    }

    /// The reconstruction `f_K` as a model (a measured model over the rebuilt
    /// table, looked up trilinearly), for views to overlay on the original;
    /// in [`FactorSpace::Cosine`] the table drawn is floored
    /// ([`COSINE_FLOOR`]).
    pub fn brdf(&self, k: usize) -> Result<Merl> {
        Ok(Merl::from_table(
            Arc::new(self.table_floored(k, COSINE_FLOOR)?),
            Interpolation::Trilinear,
        ))
    }
}

/// Factors `table` into up to `terms` products per channel in `space`.
pub fn factor(table: &MerlTable, terms: usize, space: FactorSpace) -> Result<Factorization> {
    if let FactorSpace::Log { epsilon } = space
        && !(epsilon.is_finite() && epsilon > 0.0)
    {
        return Err(BvError::BadValue {
            param: "epsilon".into(),
            reason: format!("the log offset must be finite and positive, got {epsilon}"),
        });
    }
    let d = table.dims();
    let cols = d.theta_d * d.phi_d;
    let data = table.data();
    let weights = if space == FactorSpace::Cosine {
        cosine_weights(d)
    } else {
        Vec::new()
    };
    // Value of cell `i` (within a channel) in the factored space.
    let to_space = |f: f64, i: usize| match space {
        FactorSpace::Linear => f,
        FactorSpace::Log { epsilon } => (f.max(0.0) + epsilon).ln(),
        FactorSpace::Cosine => f * weights[i],
    };
    let mut svds = Vec::with_capacity(3);
    for c in 0..3 {
        let m: Vec<f64> = data[c * d.cells()..(c + 1) * d.cells()]
            .iter()
            .enumerate()
            .map(|(i, &x)| to_space(f64::from(x), i))
            .collect();
        svds.push(truncated_svd(&m, d.theta_h, cols, terms)?);
    }
    let channels: [Svd; 3] = svds
        .try_into()
        .map_err(|_| BvError::Invalid("three channels expected".into()))?;
    let n = channels[0].rel_l2_error.len();
    // Combine the channels' errors: ‖R‖² = Σ_c err_c² ‖M_c‖².
    let norms: Vec<f64> = (0..3)
        .map(|c| {
            data[c * d.cells()..(c + 1) * d.cells()]
                .iter()
                .enumerate()
                .map(|(i, &x)| to_space(f64::from(x), i).powi(2))
                .sum()
        })
        .collect();
    let total: f64 = norms.iter().sum();
    let rel_l2_error = (0..n)
        .map(|k| {
            let e2: f64 = (0..3)
                .map(|c| channels[c].rel_l2_error[k].powi(2) * norms[c])
                .sum();
            if total > 0.0 {
                (e2 / total).sqrt()
            } else {
                0.0
            }
        })
        .collect();
    let mut fac = Factorization {
        dims: d,
        space,
        channels,
        rel_l2_error,
        rel_l2_error_f: Vec::new(),
        weights,
    };
    let f_norm2: f64 = data.iter().map(|&x| f64::from(x).powi(2)).sum();
    fac.rel_l2_error_f = (1..=n)
        .map(|k| {
            let mut e2 = 0.0;
            for c in 0..3 {
                for ih in 0..d.theta_h {
                    for j in 0..cols {
                        let f = f64::from(data[c * d.cells() + ih * cols + j]);
                        e2 += (fac.value(c, k, ih, j) - f).powi(2);
                    }
                }
            }
            if f_norm2 > 0.0 {
                (e2 / f_norm2).sqrt()
            } else {
                0.0
            }
        })
        .collect();
    Ok(fac)
}

/// Table dimensions the views factor at: half the public MERL resolution
/// along each angle (45 × 45 × 90 cells, 182 250 per channel, an eighth of
/// MERL's). The θh axis keeps MERL's square-root spacing, which puts half
/// its cells within 22.5° of the normal, so specular peaks stay resolved.
pub const VIEW_DIMS: MerlDims = MerlDims {
    theta_h: 45,
    theta_d: 45,
    phi_d: 90,
};

/// Reports the fraction done (0..=1) of a long computation and answers
/// whether to go on: returning `false` cancels it (a background job whose
/// result is no longer wanted).
pub type Progress<'a> = &'a (dyn Fn(f64) -> bool + Sync);

/// The error a cancelled computation returns.
pub fn cancelled() -> BvError {
    BvError::Invalid("cancelled".into())
}

/// Why a model cannot be factored through the half/difference table, if it
/// cannot: the table has no φh axis, so it holds only isotropic BRDFs (an
/// anisotropic model would be silently averaged to its φh = 0 slice).
pub fn unsupported(brdf: &dyn Brdf) -> Option<String> {
    if !brdf.claims().isotropic {
        return Some(
            "the half/difference table assumes an isotropic BRDF (no φh axis); \
             this model is anisotropic"
                .into(),
        );
    }
    None
}

/// Tabulates an isotropic `brdf` at `dims` (see
/// [`crate::measured::merl::tabulate`]) and factors the table into up to
/// `terms` products per channel in `space`. `progress` is told the fraction
/// done between stages and may cancel (then [`cancelled`] is returned).
pub fn factor_model(
    brdf: &dyn Brdf,
    dims: MerlDims,
    terms: usize,
    space: FactorSpace,
    progress: Progress<'_>,
) -> Result<(MerlTable, Factorization)> {
    if let Some(why) = unsupported(brdf) {
        return Err(BvError::Invalid(why));
    }
    if !progress(0.0) {
        return Err(cancelled());
    }
    let table = tabulate(brdf, dims)?;
    if !progress(0.5) {
        return Err(cancelled());
    }
    let f = factor(&table, terms, space)?;
    if !progress(1.0) {
        return Err(cancelled());
    }
    Ok((table, f))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::frame::{HalfDiff, from_half_diff};
    use serde_json::json;

    const DIMS: MerlDims = MerlDims {
        theta_h: 8,
        theta_d: 6,
        phi_d: 10,
    };

    /// A table from `cell(c, ih, j)`; the test values are small dyadic
    /// rationals, exact in f32, so that the stored table has exactly the
    /// rank it is built with.
    fn table(cell: impl Fn(usize, usize, usize) -> f64) -> MerlTable {
        let cols = DIMS.theta_d * DIMS.phi_d;
        let mut data = Vec::with_capacity(3 * DIMS.cells());
        for c in 0..3 {
            for ih in 0..DIMS.theta_h {
                for j in 0..cols {
                    data.push(cell(c, ih, j) as f32);
                }
            }
        }
        MerlTable::from_values(DIMS, data).unwrap()
    }

    #[test]
    fn separable_table_is_rank_one() {
        let scale = [1.0, 0.5, 0.25];
        let t = table(|c, ih, j| scale[c] * (ih + 1) as f64 * ((j % 7) as f64 + 1.0) * 0.125);
        let f = factor(&t, 4, FactorSpace::Linear).unwrap();
        assert!(f.rel_l2_error[0] < 1e-12, "{:?}", f.rel_l2_error);
        assert!(f.rel_l2_error_f[0] < 1e-12);
        // σ₁ = ‖a‖ ‖b‖ by hand: a = scale (1..8), b = 0.125 (j mod 7 + 1).
        let na: f64 = (1..=8).map(|i| (i * i) as f64).sum::<f64>().sqrt();
        let nb: f64 = (0..60)
            .map(|j| ((j % 7) as f64 + 1.0).powi(2) * 0.015625)
            .sum::<f64>()
            .sqrt();
        assert!((f.channels[0].sigma[0] - na * nb).abs() < 1e-10 * na * nb);
        assert!((f.channels[2].sigma[0] - 0.25 * na * nb).abs() < 1e-10 * na * nb);
        assert!(f.channels[0].sigma[1] < 1e-6 * f.channels[0].sigma[0]);
    }

    #[test]
    fn rank_two_table_hand_error() {
        // M = a1 b1ᵀ + a2 b2ᵀ with a1 = 1, a2 = (−1)^ih (orthogonal over 8
        // rows), b1 = 2, b2 = (−1)^j (orthogonal over 60 columns): σ1 = √8 √240,
        // σ2 = √8 √60, so the one-term error is σ2/√(σ1² + σ2²) = 1/√5, and two
        // terms are exact. Values are 1 or 3, positive as a table must be.
        let sign = |n: usize| if n.is_multiple_of(2) { 1.0 } else { -1.0 };
        let t = table(|c, ih, j| (2.0 + sign(ih) * sign(j)) * [1.0, 0.5, 2.0][c]);
        let f = factor(&t, 5, FactorSpace::Linear).unwrap();
        assert!(
            (f.rel_l2_error[0] - 1.0 / 5f64.sqrt()).abs() < 1e-12,
            "{:?}",
            f.rel_l2_error
        );
        assert!(f.rel_l2_error[1] < 1e-12);
        let s = &f.channels[0].sigma;
        assert!((s[0] - (8.0f64 * 240.0).sqrt()).abs() < 1e-10);
        assert!((s[1] - (8.0f64 * 60.0).sqrt()).abs() < 1e-10);
        // Non-increasing in K.
        for w in f.rel_l2_error.windows(2) {
            assert!(w[1] <= w[0] + 1e-15);
        }
    }

    #[test]
    fn tabulated_model_errors_decrease_and_brdf_matches_table() {
        let ct = ModelSpec::from_json(
            "cook-torrance",
            &json!({"kd": 0.3, "ks": 0.6, "distribution": "ggx", "alpha": 0.2,
                    "geometry": "smith", "fresnel": "schlick", "f0": [0.9, 0.6, 0.3]}),
        )
        .unwrap()
        .build()
        .unwrap();
        let dims = MerlDims {
            theta_h: 16,
            theta_d: 12,
            phi_d: 24,
        };
        let t = tabulate(ct.as_ref(), dims).unwrap();
        for space in [FactorSpace::Linear, FactorSpace::Log { epsilon: 1e-3 }] {
            let f = factor(&t, 8, space).unwrap();
            assert_eq!(f.terms(), 8);
            for w in f.rel_l2_error.windows(2) {
                assert!(w[1] <= w[0] + 1e-12, "{space:?}: {:?}", f.rel_l2_error);
            }
            assert!(f.rel_l2_error[7] < f.rel_l2_error[0]);
            if space == FactorSpace::Linear {
                // Up to the clamp at 0 the two errors are the same number.
                assert!(f.rel_l2_error_f[0] <= f.rel_l2_error[0] + 1e-9);
            }
        }
        // With all 16 terms (full rank) the rebuilt model is the table: at a
        // cell centre the trilinear lookup returns that cell.
        let f = factor(&t, 16, FactorSpace::Linear).unwrap();
        assert!(f.rel_l2_error[15] < 1e-6, "{:?}", f.rel_l2_error);
        let b = f.brdf(16).unwrap();
        let (ih, id, ip) = (3, 4, 5);
        let (wi, wo) = from_half_diff(HalfDiff {
            theta_h: theta_h_centre(ih, 16),
            phi_h: 0.4,
            theta_d: theta_d_centre(id, 12),
            phi_d: phi_d_centre(ip, 24),
        });
        let (got, want) = (b.eval(wi, wo), t.at(ih, id, ip));
        assert!(
            (got - want).abs().max_element() < 1e-5 * want.max_element(),
            "{got} vs {want}"
        );
        assert!(f.table(0).is_err() && f.table(17).is_err());
    }

    #[test]
    fn bad_input_is_refused() {
        assert!(truncated_svd(&[1.0, 2.0], 2, 2, 1).is_err());
        assert!(truncated_svd(&[f64::NAN; 4], 2, 2, 1).is_err());
        let t = table(|_, _, _| 1.0);
        assert!(factor(&t, 2, FactorSpace::Log { epsilon: 0.0 }).is_err());
        // A zero table factors to zero error.
        let z = table(|_, _, _| 0.0);
        assert_eq!(
            factor(&z, 2, FactorSpace::Linear).unwrap().rel_l2_error,
            vec![0.0, 0.0]
        );
    }

    /// Lambert is constant over the cells above both horizons and 0 below:
    /// per channel the table is `ρ/π · mask(θh, θd, φd)`, and the mask is not
    /// a product of a θh row and a (θd, φd) column (the horizon θo = 90°
    /// depends on all three), so it is *not* exactly rank 1. With the view's
    /// own grid the rank-1 error is still small; the channels are exactly
    /// proportional, so each channel's singular values are those of the mask
    /// times ρ_c/π.
    #[test]
    fn lambert_factors_channel_by_channel_in_proportion() {
        let b = ModelSpec::from_json("lambert", &json!({"albedo": [0.8, 0.4, 0.2]}))
            .unwrap()
            .build()
            .unwrap();
        let dims = MerlDims {
            theta_h: 12,
            theta_d: 10,
            phi_d: 20,
        };
        let (t, f) = factor_model(b.as_ref(), dims, 6, FactorSpace::Linear, &|_| true).unwrap();
        assert_eq!(t.dims(), dims);
        let s = |c: usize| f.channels[c].sigma.clone();
        for k in 0..6 {
            assert!((s(1)[k] - 0.5 * s(0)[k]).abs() <= 1e-6 * s(0)[0], "{k}");
            assert!((s(2)[k] - 0.25 * s(0)[k]).abs() <= 1e-6 * s(0)[0], "{k}");
        }
        // The per-channel errors agree (the same mask), and the combined one
        // is non-increasing in K.
        for k in 0..6 {
            let e = &f.channels;
            assert!((e[0].rel_l2_error[k] - e[2].rel_l2_error[k]).abs() < 1e-6);
        }
        for w in f.rel_l2_error.windows(2) {
            assert!(w[1] <= w[0] + 1e-12, "{:?}", f.rel_l2_error);
        }
        // σ₁² + … ≤ ‖M‖² (Frobenius), with ‖M‖² = (ρ/π)² × cells above both
        // horizons, counted here by hand.
        let mut lit = 0usize;
        for ih in 0..dims.theta_h {
            for id in 0..dims.theta_d {
                for ip in 0..dims.phi_d {
                    let (wi, wo) = from_half_diff(HalfDiff {
                        theta_h: theta_h_centre(ih, dims.theta_h),
                        phi_h: 0.0,
                        theta_d: theta_d_centre(id, dims.theta_d),
                        phi_d: phi_d_centre(ip, dims.phi_d),
                    });
                    if wi.z > 0.0 && wo.z > 0.0 {
                        lit += 1;
                    }
                }
            }
        }
        let c = 0.8 / std::f64::consts::PI;
        let norm2 = c * c * lit as f64;
        let s2: f64 = s(0).iter().map(|x| x * x).sum();
        assert!(s2 <= norm2 * (1.0 + 1e-6));
        // The residual after 6 terms is what the singular values leave out.
        let e6 = f.channels[0].rel_l2_error[5];
        assert!(
            ((1.0 - s2 / norm2).max(0.0).sqrt() - e6).abs() < 1e-4,
            "{e6}"
        );
    }

    /// Lambert's table restricted to the cells above both horizons is the
    /// constant ρ/π: exactly rank 1, with σ₁ by hand.
    #[test]
    fn constant_table_is_rank_one() {
        let c = 0.3;
        let dims = MerlDims {
            theta_h: 6,
            theta_d: 5,
            phi_d: 8,
        };
        let cols = dims.theta_d * dims.phi_d;
        let data: Vec<f32> = (0..3 * dims.cells()).map(|_| c as f32).collect();
        let t = MerlTable::from_values(dims, data).unwrap();
        let f = factor(&t, 3, FactorSpace::Linear).unwrap();
        assert!(f.rel_l2_error[0] < 1e-12, "{:?}", f.rel_l2_error);
        // σ₁ of a constant matrix: c √(rows · cols).
        let want = f64::from(c as f32) * ((dims.theta_h * cols) as f64).sqrt();
        assert!((f.channels[0].sigma[0] - want).abs() < 1e-9 * want);
    }

    /// In the cosine space the factored error is the cosine-weighted error
    /// of `f`, computed here by hand from the rebuilt cells; it falls with K,
    /// and the full-rank rebuild divides the weight back out exactly.
    #[test]
    fn cosine_space_is_the_weighted_error_of_f() {
        let ct = ModelSpec::from_json("cook-torrance", &json!({"alpha": 0.2}))
            .unwrap()
            .build()
            .unwrap();
        let dims = MerlDims {
            theta_h: 8,
            theta_d: 6,
            phi_d: 10,
        };
        let (t, f) = factor_model(ct.as_ref(), dims, 8, FactorSpace::Cosine, &|_| true).unwrap();
        let w = cosine_weights(dims);
        let cols = 60;
        for k in [1, 3] {
            let (mut e2, mut n2) = (0.0, 0.0);
            for c in 0..3 {
                for ih in 0..8 {
                    for j in 0..cols {
                        let x = f64::from(t.data()[c * t.dims().cells() + ih * cols + j]);
                        let wc = w[ih * cols + j];
                        e2 += (wc * (f.value(c, k, ih, j) - x)).powi(2);
                        n2 += (wc * x).powi(2);
                    }
                }
            }
            // Equal up to the clamp at 0 (which only lowers the error).
            let hand = (e2 / n2).sqrt();
            let e = f.rel_l2_error[k - 1];
            assert!(hand <= e + 1e-9 && hand > 0.5 * e, "{k}: {hand} vs {e}");
        }
        for win in f.rel_l2_error.windows(2) {
            assert!(win[1] <= win[0] + 1e-12, "{:?}", f.rel_l2_error);
        }
        assert!(f.rel_l2_error[7] < 1e-6, "{:?}", f.rel_l2_error);
        // Cell (2, 3, 4) is above both horizons: full rank gives it back.
        let j = 3 * 10 + 4;
        assert!(w[2 * cols + j] > 0.0);
        let want = t.at(2, 3, 4);
        assert!((f.value(1, 8, 2, j) - want.y).abs() < 1e-5 * want.y.max(1e-3));
        // The floored table is low by w² / (w² + δ²) there.
        let wc = w[2 * cols + j];
        let reg = wc * wc / (wc * wc + COSINE_FLOOR * COSINE_FLOOR);
        let fl = f.table_floored(8, COSINE_FLOOR).unwrap().at(2, 3, 4);
        assert!((fl.y - reg * want.y).abs() < 1e-5 * want.y.max(1e-3));
    }

    #[test]
    fn anisotropic_models_and_cancellation_are_refused() {
        let ward = ModelSpec::from_json("ward", &json!({"alpha_x": 0.1, "alpha_y": 0.4}))
            .unwrap()
            .build()
            .unwrap();
        assert!(unsupported(ward.as_ref()).is_some());
        assert!(factor_model(ward.as_ref(), DIMS, 2, FactorSpace::Linear, &|_| true).is_err());
        let lambert = ModelSpec::new("lambert").unwrap().build().unwrap();
        assert!(unsupported(lambert.as_ref()).is_none());
        let stop = |x: f64| x < 0.25;
        let e = factor_model(lambert.as_ref(), DIMS, 2, FactorSpace::Linear, &stop);
        assert!(e.is_err());
    }
}
