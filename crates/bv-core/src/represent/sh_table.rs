//! The spherical-harmonics representation of a whole isotropic BRDF,
//! measured over the cells of a half/difference table, so that its error
//! against the order L can be drawn beside the factorisation's error against
//! the number of terms K ([`super::factor`]) on one chart.
//!
//! SH represent a *lobe* (a function of ωo at one ωi). A 4D BRDF is
//! represented, as in Westin, Arvo & Torrance 1992 ("Predicting reflectance
//! functions from complex surfaces") and Sillion et al. 1991, by one lobe
//! expansion per incident elevation: `n_incident` lobes at θi nodes spaced
//! evenly over [0, π/2) (cell centres; φi = 0, the BRDF being isotropic), each
//! projected onto SH of order ≤ L ([`super::sh::project_fn`], hemisphere
//! domain), and linearly interpolated in θi between the two nearest nodes
//! (held constant beyond the outer ones). A cell of the table gives a pair
//! (ωi, ωo) (with φh = 0, as tabulated); turning both about the normal by −φi
//! brings ωi to its node's plane.
//!
//! The error is the one [`super::factor::Factorization::rel_l2_error_f`]
//! reports: `‖f̂ − f‖ / ‖f‖` over all cells and the three channels, with the
//! reconstruction clamped at 0 (a table of `f` cannot hold a negative value)
//! and cells below either horizon 0 in both. A second error weights each
//! cell by `cos θi cos θo` (the error in `f cos θi cos θo`, the reflected
//! light's integrand): microfacet models grow like `1/cos θi` towards
//! grazing, and a few grazing cells, which SH interpolated in θi cannot
//! follow, would otherwise dominate the plain norm. [`factor_table_error`]
//! measures the factorisation the same two ways. Because the orthonormal
//! projection of order L is the order-Lmax projection truncated to its first
//! `(L + 1)²` coefficients, one projection per node gives every order.

use super::factor::{Factorization, Progress, cancelled};
use super::sh::{self, Domain, MAX_ORDER, ShLobe, eval_basis, num_coeffs};
use crate::measured::merl::{MerlDims, MerlTable, phi_d_centre, theta_d_centre, theta_h_centre};
use crate::{Brdf, BvError, Result, Rgb, frame};
use glam::DVec3;
use rayon::prelude::*;
use std::f64::consts::FRAC_PI_2;

/// Most incident nodes accepted.
pub const MAX_INCIDENT: usize = 256;

/// Incident nodes the views use: 3.75° apart, fine enough that the
/// interpolation in θi adds little to the truncation error of the orders
/// drawn (a lobe moves by twice the node spacing between nodes).
pub const VIEW_INCIDENT: usize = 24;

/// The θi of node `n` of `count` (cell centres over [0, π/2)).
pub fn incident_node(n: usize, count: usize) -> f64 {
    (n as f64 + 0.5) * FRAC_PI_2 / count as f64
}

/// Relative L2 errors of a representation over a table's cells, one per
/// number of terms or order.
#[derive(Debug, Clone, PartialEq)]
pub struct TableErrors {
    /// `‖f̂ − f‖ / ‖f‖`, every cell counting equally.
    pub plain: Vec<f64>,
    /// The same with each cell weighted by `cos θi cos θo` (squared
    /// difference times the weight squared: the error in `f cos θi cos θo`).
    pub cosine: Vec<f64>,
}

/// The (ωi, ωo) pair of cell `(ih, id, ip)` (φh = 0, as tabulated).
fn cell_pair(d: MerlDims, ih: usize, id: usize, ip: usize) -> (DVec3, DVec3) {
    frame::from_half_diff(frame::HalfDiff {
        theta_h: theta_h_centre(ih, d.theta_h),
        phi_h: 0.0,
        theta_d: theta_d_centre(id, d.theta_d),
        phi_d: phi_d_centre(ip, d.phi_d),
    })
}

/// `cos θi cos θo` of a pair, 0 below either horizon.
fn cosine_weight(wi: DVec3, wo: DVec3) -> f64 {
    if wi.z > 0.0 && wo.z > 0.0 {
        wi.z * wo.z
    } else {
        0.0
    }
}

fn relative(e: Vec<f64>, n2: f64) -> Vec<f64> {
    e.into_iter()
        .map(|e| if n2 > 0.0 { (e / n2).sqrt() } else { 0.0 })
        .collect()
}

/// The errors of `fac`'s rebuilt tables (K = 1..=terms, index K − 1; log
/// undone, clamped at 0) against `table`, the table it factored, plain and
/// cosine-weighted ([`TableErrors`]). The plain one is
/// [`Factorization::rel_l2_error_f`], measured again here from the cells.
pub fn factor_table_error(fac: &Factorization, table: &MerlTable) -> Result<TableErrors> {
    let d = table.dims();
    if d != fac.dims {
        return Err(BvError::Invalid(format!(
            "the table is {d}, the factorisation is of a {} table",
            fac.dims
        )));
    }
    let n = fac.terms();
    let ((ep, ec), (np, nc)) = (0..d.theta_h)
        .into_par_iter()
        .map(|ih| {
            let (mut ep, mut ec) = (vec![0.0f64; n], vec![0.0f64; n]);
            let (mut np, mut nc) = (0.0f64, 0.0f64);
            for id in 0..d.theta_d {
                for ip in 0..d.phi_d {
                    let (wi, wo) = cell_pair(d, ih, id, ip);
                    let w2 = cosine_weight(wi, wo).powi(2);
                    let f = table.at(ih, id, ip);
                    np += f.length_squared();
                    nc += w2 * f.length_squared();
                    let j = id * d.phi_d + ip;
                    for k in 1..=n {
                        let e2: f64 = (0..3)
                            .map(|c| (fac.value(c, k, ih, j) - f[c]).powi(2))
                            .sum();
                        ep[k - 1] += e2;
                        ec[k - 1] += w2 * e2;
                    }
                }
            }
            ((ep, ec), (np, nc))
        })
        .reduce(
            || ((vec![0.0; n], vec![0.0; n]), (0.0, 0.0)),
            |((mut a, mut b), (x, y)), ((c, e), (z, w))| {
                a.iter_mut().zip(c).for_each(|(p, q)| *p += q);
                b.iter_mut().zip(e).for_each(|(p, q)| *p += q);
                ((a, b), (x + z, y + w))
            },
        );
    Ok(TableErrors {
        plain: relative(ep, np),
        cosine: relative(ec, nc),
    })
}

/// Relative L2 errors of the SH representation of `brdf` (see the module
/// docs) over the cells of `table` (which must be `brdf` tabulated), for
/// L = 0..=`max_order` (index L), plain and cosine-weighted. The lobes are
/// projected with `n_theta` quadrature rings. `progress` is told the
/// fraction done and may cancel.
pub fn sh_table_error(
    brdf: &dyn Brdf,
    table: &MerlTable,
    max_order: usize,
    n_incident: usize,
    n_theta: usize,
    progress: Progress<'_>,
) -> Result<TableErrors> {
    let mut job = ShTableJob::new(max_order, n_incident, n_theta)?;
    loop {
        if !progress(job.progress()) {
            return Err(cancelled());
        }
        if let Some(r) = job.step(brdf, table, usize::MAX, usize::MAX) {
            if !progress(1.0) {
                return Err(cancelled());
            }
            return r;
        }
    }
}

/// [`sh_table_error`] in steps of bounded work, for a caller that cannot
/// block for the whole computation (a browser page without threads runs a
/// few steps per frame). Stage 1 projects one lobe per incident node, a few
/// quadrature rings a step ([`sh::ProjectJob`]); stage 2 compares a few θh
/// rows of the table a step. The sums of a step are parallel and the steps'
/// sums are added up: the result differs from the one-shot computation only
/// by the order of the additions.
#[derive(Debug, Clone)]
pub struct ShTableJob {
    max_order: usize,
    n_incident: usize,
    n_theta: usize,
    lobes: Vec<ShLobe>,
    current: Option<sh::ProjectJob>,
    rows_done: usize,
    /// The table's θh rows (known at the first step of stage 2).
    rows_total: usize,
    /// Squared errors per order (plain, cosine) and squared norms so far.
    errors: (Vec<f64>, Vec<f64>),
    norms: (f64, f64),
}

impl ShTableJob {
    /// A job for [`sh_table_error`]`(·, ·, max_order, n_incident, n_theta, ·)`;
    /// the order and node count are checked here.
    pub fn new(max_order: usize, n_incident: usize, n_theta: usize) -> Result<Self> {
        if max_order > MAX_ORDER {
            return Err(BvError::Invalid(format!(
                "SH order {max_order} is above the supported {MAX_ORDER}"
            )));
        }
        if n_incident == 0 || n_incident > MAX_INCIDENT {
            return Err(BvError::Invalid(format!(
                "{n_incident} incident directions asked for; 1..={MAX_INCIDENT} accepted"
            )));
        }
        Ok(Self {
            max_order,
            n_incident,
            n_theta,
            lobes: Vec::with_capacity(n_incident),
            current: None,
            rows_done: 0,
            rows_total: 0,
            errors: (vec![0.0; max_order + 1], vec![0.0; max_order + 1]),
            norms: (0.0, 0.0),
        })
    }

    /// The share of the work done, in `[0, 1]` (stage 1 counts for two
    /// thirds), as [`sh_table_error`] reports it.
    pub fn progress(&self) -> f64 {
        let lobes =
            self.lobes.len() as f64 + self.current.as_ref().map_or(0.0, sh::ProjectJob::progress);
        if self.lobes.len() < self.n_incident {
            return lobes / self.n_incident as f64 * 0.67;
        }
        0.67 + 0.33 * self.rows_done as f64 / self.rows_total.max(1) as f64
    }

    /// Does `rings` quadrature rings of the current projection (stage 1) or
    /// `rows` θh rows of the table (stage 2; both at least one) and returns
    /// the errors once everything is done. `brdf` and `table` must be the
    /// same at every step.
    pub fn step(
        &mut self,
        brdf: &dyn Brdf,
        table: &MerlTable,
        rings: usize,
        rows: usize,
    ) -> Option<Result<TableErrors>> {
        if self.lobes.len() < self.n_incident {
            let n = self.lobes.len();
            let job = match &mut self.current {
                Some(j) => j,
                None => match sh::ProjectJob::new(Domain::Hemisphere, self.max_order, self.n_theta)
                {
                    Ok(j) => self.current.insert(j),
                    Err(e) => return Some(Err(e)),
                },
            };
            let wi = frame::from_spherical(incident_node(n, self.n_incident), 0.0);
            let g = |wo: DVec3| {
                if wo.z > 0.0 {
                    brdf.eval(wi, wo)
                } else {
                    Rgb::ZERO
                }
            };
            if let Some(lobe) = job.step(&g, rings) {
                self.lobes.push(lobe);
                self.current = None;
            }
            return None;
        }
        // Stage 2: every cell, every order at once (partial sums by band).
        let d = table.dims();
        let max_order = self.max_order;
        let orders = max_order + 1;
        let step = FRAC_PI_2 / self.n_incident as f64;
        let lobes = &self.lobes;
        let end = self.rows_done.saturating_add(rows.max(1)).min(d.theta_h);
        let ((ep, ec), (np, nc)) = (self.rows_done..end)
            .into_par_iter()
            .map(|ih| {
                let (mut ep, mut ec) = (vec![0.0f64; orders], vec![0.0f64; orders]);
                let (mut np, mut nc) = (0.0f64, 0.0f64);
                let mut y = [0.0f64; num_coeffs(MAX_ORDER)];
                let mut band = vec![Rgb::ZERO; orders];
                for id in 0..d.theta_d {
                    for ip in 0..d.phi_d {
                        let f = table.at(ih, id, ip);
                        let (wi, wo) = cell_pair(d, ih, id, ip);
                        let w2 = cosine_weight(wi, wo).powi(2);
                        np += f.length_squared();
                        nc += w2 * f.length_squared();
                        band.iter_mut().for_each(|b| *b = Rgb::ZERO);
                        if wi.z > 0.0 && wo.z > 0.0 {
                            reconstruct_bands(lobes, step, wi, wo, max_order, &mut y, &mut band);
                        }
                        let mut acc = Rgb::ZERO;
                        for (l, b) in band.iter().enumerate() {
                            acc += *b;
                            let e2 = (acc.max(Rgb::ZERO) - f).length_squared();
                            ep[l] += e2;
                            ec[l] += w2 * e2;
                        }
                    }
                }
                ((ep, ec), (np, nc))
            })
            .reduce(
                || ((vec![0.0; orders], vec![0.0; orders]), (0.0, 0.0)),
                |((mut a, mut b), (x, y)), ((c, e), (z, w))| {
                    a.iter_mut().zip(c).for_each(|(p, q)| *p += q);
                    b.iter_mut().zip(e).for_each(|(p, q)| *p += q);
                    ((a, b), (x + z, y + w))
                },
            );
        self.errors.0.iter_mut().zip(ep).for_each(|(p, q)| *p += q);
        self.errors.1.iter_mut().zip(ec).for_each(|(p, q)| *p += q);
        self.norms.0 += np;
        self.norms.1 += nc;
        self.rows_done = end;
        self.rows_total = d.theta_h;
        if end < d.theta_h {
            return None;
        }
        Some(Ok(TableErrors {
            plain: relative(std::mem::take(&mut self.errors.0), self.norms.0),
            cosine: relative(std::mem::take(&mut self.errors.1), self.norms.1),
        }))
    }
}

/// The contribution of each band l to the interpolated reconstruction at the
/// pair (ωi, ωo), into `band[l]`.
fn reconstruct_bands(
    lobes: &[ShLobe],
    step: f64,
    wi: DVec3,
    wo: DVec3,
    max_order: usize,
    y: &mut [f64],
    band: &mut [Rgb],
) {
    let (theta_i, phi_i) = frame::to_spherical(wi);
    // Turn ωo so that ωi has azimuth 0 (isotropy).
    let (s, c) = (-phi_i).sin_cos();
    let wo = DVec3::new(c * wo.x - s * wo.y, s * wo.x + c * wo.y, wo.z);
    eval_basis(max_order, wo, y);
    // Node positions (n + 0.5) step; linear weights between neighbours.
    let x = (theta_i / step - 0.5).clamp(0.0, (lobes.len() - 1) as f64);
    let n0 = (x.floor() as usize).min(lobes.len() - 1);
    let n1 = (n0 + 1).min(lobes.len() - 1);
    let t = x - n0 as f64;
    for (l, b) in band.iter_mut().enumerate().take(max_order + 1) {
        for (i, &yi) in y.iter().enumerate().take((l + 1) * (l + 1)).skip(l * l) {
            let c = lobes[n0].coeffs[i] * (1.0 - t) + lobes[n1].coeffs[i] * t;
            *b += c * yi;
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::measured::merl::tabulate;
    use crate::represent::factor::{FactorSpace, factor_model};
    use crate::{Claims, ModelSpec};
    use std::f64::consts::PI;

    const DIMS: MerlDims = MerlDims {
        theta_h: 10,
        theta_d: 8,
        phi_d: 16,
    };

    fn go(_: f64) -> bool {
        true
    }

    /// A constant lobe over the hemisphere, `c` for every ωi: the same lobe
    /// at every node, so interpolation adds nothing and the error is the
    /// truncation of the hemisphere's indicator function. Order 0 by hand:
    /// its projection is `c · 2π · Y00 = c √π`, i.e. `c/2` everywhere on the
    /// sphere, so every cell above both horizons is off by exactly `c/2` and
    /// the relative error is exactly 1/2 over those cells.
    #[test]
    fn constant_lobe_order_zero_is_half_off() {
        let b = ModelSpec::new("lambert").unwrap().build().unwrap();
        let t = tabulate(b.as_ref(), DIMS).unwrap();
        let all = sh_table_error(b.as_ref(), &t, 6, 4, 64, &go).unwrap();
        let e = &all.plain;
        assert_eq!(e.len(), 7);
        assert!((e[0] - 0.5).abs() < 1e-6, "{e:?}");
        // The offset is the same in every lit cell, so any weighting gives
        // the same 1/2.
        assert!((all.cosine[0] - 0.5).abs() < 1e-6, "{:?}", all.cosine);
        // Odd bands of the indicator are non-zero, even ones (l ≥ 2) vanish
        // by symmetry: order 1 improves, order 2 adds nothing.
        assert!(e[1] < e[0]);
        assert!((e[2] - e[1]).abs() < 1e-6, "{e:?}");
        assert!(e[3] < e[2], "{e:?}");
    }

    /// A lobe that does depend on θi, `f = cos θi · cos θo / π` (separable,
    /// reciprocal): with the order high enough for `cos θo` on the hemisphere,
    /// what is left is the θi interpolation, which is exact between nodes for
    /// a function linear in θi only approximately; more nodes, less error.
    #[test]
    fn more_incident_nodes_reduce_the_interpolation_error() {
        #[derive(Debug)]
        struct CosCos;
        impl Brdf for CosCos {
            fn id(&self) -> &'static str {
                "cos-cos"
            }
            fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
                Rgb::splat((wi.z * wo.z).max(0.0) / PI)
            }
            fn claims(&self) -> Claims {
                Claims {
                    reciprocal: true,
                    energy_conserving: true,
                    isotropic: true,
                }
            }
        }
        let t = tabulate(&CosCos, DIMS).unwrap();
        let coarse = sh_table_error(&CosCos, &t, 8, 2, 64, &go).unwrap().plain;
        let fine = sh_table_error(&CosCos, &t, 8, 16, 64, &go).unwrap().plain;
        assert!(fine[8] < coarse[8], "{fine:?} vs {coarse:?}");
    }

    /// The plain error measured from the cells is the one the factorisation
    /// computed from its own residual; with every term kept (10 terms of a
    /// table with 10 rows: full rank) both errors vanish.
    #[test]
    fn factor_errors_agree_with_the_factorisation() {
        let ct = ModelSpec::from_json("cook-torrance", &serde_json::json!({"alpha": 0.3}))
            .unwrap()
            .build()
            .unwrap();
        let (t, f) = factor_model(ct.as_ref(), DIMS, 10, FactorSpace::Linear, &go).unwrap();
        let e = factor_table_error(&f, &t).unwrap();
        assert_eq!(e.plain.len(), 10);
        for (a, b) in e.plain.iter().zip(&f.rel_l2_error_f) {
            assert!((a - b).abs() < 1e-9, "{a} vs {b}");
        }
        assert!(e.plain[9] < 1e-5 && e.cosine[9] < 1e-5, "{e:?}");
        assert!(e.cosine[4] < e.cosine[0], "{e:?}");
        let other = tabulate(ct.as_ref(), MerlDims { theta_h: 4, ..DIMS }).unwrap();
        assert!(factor_table_error(&f, &other).is_err());
    }

    /// Brute force, sharing nothing with the interpolation: every cell's
    /// lobe projected at that cell's own ωi and evaluated at its ωo. With
    /// many incident nodes the interpolated representation converges to it.
    #[test]
    fn many_nodes_approach_a_projection_per_cell() {
        let ct = ModelSpec::from_json("cook-torrance", &serde_json::json!({"alpha": 0.4}))
            .unwrap()
            .build()
            .unwrap();
        let t = tabulate(ct.as_ref(), DIMS).unwrap();
        let (order, rings) = (4, 32);
        let (mut e2, mut n2) = (0.0, 0.0);
        for ih in 0..DIMS.theta_h {
            for id in 0..DIMS.theta_d {
                for ip in 0..DIMS.phi_d {
                    let f = t.at(ih, id, ip);
                    n2 += f.length_squared();
                    let (wi, wo) = cell_pair(DIMS, ih, id, ip);
                    let r = if wi.z > 0.0 && wo.z > 0.0 {
                        let l = sh::project(ct.as_ref(), wi, order, false, rings).unwrap();
                        l.eval(wo).max(Rgb::ZERO)
                    } else {
                        Rgb::ZERO
                    };
                    e2 += (r - f).length_squared();
                }
            }
        }
        let brute = (e2 / n2).sqrt();
        let e = sh_table_error(ct.as_ref(), &t, order, 180, rings, &go).unwrap();
        assert!(
            (e.plain[order] - brute).abs() < 0.02 * brute,
            "{} vs {brute}",
            e.plain[order]
        );
    }

    #[test]
    fn cancelled_and_bad_arguments() {
        let b = ModelSpec::new("lambert").unwrap().build().unwrap();
        let t = tabulate(b.as_ref(), DIMS).unwrap();
        let stop = |_: f64| false;
        assert!(sh_table_error(b.as_ref(), &t, 2, 2, 16, &stop).is_err());
        assert!(sh_table_error(b.as_ref(), &t, MAX_ORDER + 1, 2, 16, &go).is_err());
        assert!(sh_table_error(b.as_ref(), &t, 2, 0, 16, &go).is_err());
    }
}
