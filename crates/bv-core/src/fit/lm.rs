//! A small Levenberg–Marquardt minimiser of `½ Σ r(t)²` over unbounded
//! parameters `t` (the fit maps them into the declared ranges), with a
//! central-difference Jacobian.
//!
//! Why our own rather than a crate: `levenberg-marquardt` (0.14, a port of
//! MINPACK's `lmder`) is well kept but built on `nalgebra` (with its
//! `simba`/`num` tree), which this core does not otherwise use, for a
//! problem of at most a dozen unknowns whose normal equations a 20-line
//! Cholesky solves; it wants an analytic Jacobian (its numeric one is for
//! testing) and has no hook to stop early but a failing residual call.
//! `argmin` (0.10) lists Gauss–Newton (with a line search) but no
//! Levenberg–Marquardt, and needs an `argmin-math` back end (nalgebra or
//! ndarray again). What the fit needs besides — a cancel flag read every
//! step, progress, a Jacobian by differences of f32 batch evaluations — is
//! a few lines here.
//!
//! The method is Marquardt's (1963, "An Algorithm for Least-Squares
//! Estimation of Nonlinear Parameters", SIAM J. Appl. Math. 11(2): the
//! damped normal equations and the λ up/down strategy) with Moré's (1978,
//! "The Levenberg-Marquardt algorithm: implementation and theory") diagonal
//! scaling: solve
//! `(JᵀJ + λ diag(JᵀJ)) δ = −Jᵀr`, accept the step when the cost falls
//! (λ /= 3), otherwise λ ×= 2 and solve again.

use std::sync::atomic::{AtomicBool, Ordering};

/// Stopping rules.
#[derive(Debug, Clone, Copy)]
pub(crate) struct LmOptions {
    /// Jacobian evaluations at most.
    pub max_iterations: usize,
    /// Stop when an accepted step lowers the cost by less than this fraction.
    pub rel_tol: f64,
    /// Central-difference step in `t`.
    pub step: f64,
}

/// Where the minimiser stopped.
#[derive(Debug, Clone)]
pub(crate) struct LmOutcome {
    /// The best parameters found.
    pub t: Vec<f64>,
    /// `½ Σ r²` there.
    pub cost: f64,
    /// Jacobians computed (iterations).
    pub iterations: usize,
    /// Residual evaluations (each one batch over the sample set).
    pub evaluations: usize,
    /// Whether the cancel flag stopped it.
    pub cancelled: bool,
}

/// The residual function: fills `r` at `t`; an `Err` aborts the fit.
pub(crate) type Residuals<'a> = dyn FnMut(&[f64], &mut [f64]) -> crate::Result<()> + 'a;

fn cost_of(r: &[f64]) -> f64 {
    0.5 * r.iter().map(|x| x * x).sum::<f64>()
}

/// Minimises from `t0`. `progress(iteration, cost)` is called after every
/// iteration; `cancel` is read before each Jacobian and each trial step, so a
/// cancel stops the run within one iteration.
pub(crate) fn minimise(
    t0: &[f64],
    m: usize,
    f: &mut Residuals<'_>,
    opts: &LmOptions,
    cancel: &AtomicBool,
    progress: &mut dyn FnMut(usize, f64),
) -> crate::Result<LmOutcome> {
    let p = t0.len();
    let mut t = t0.to_vec();
    let mut r = vec![0.0; m];
    f(&t, &mut r)?;
    let mut out = LmOutcome {
        t: t.clone(),
        cost: cost_of(&r),
        iterations: 0,
        evaluations: 1,
        cancelled: false,
    };
    if p == 0 || !out.cost.is_finite() {
        return Ok(out);
    }
    let mut lambda = 1e-3;
    let mut jac = vec![0.0; m * p]; // column-major: jac[j * m + k]
    let (mut rp, mut rm) = (vec![0.0; m], vec![0.0; m]);
    let mut trial = vec![0.0; m];
    'outer: while out.iterations < opts.max_iterations {
        if cancel.load(Ordering::Relaxed) {
            out.cancelled = true;
            break;
        }
        // Central differences: the residuals come from f32 kernels, so a
        // forward difference's O(h) error would be no smaller than the noise.
        for j in 0..p {
            let tj = t[j];
            t[j] = tj + opts.step;
            f(&t, &mut rp)?;
            t[j] = tj - opts.step;
            f(&t, &mut rm)?;
            t[j] = tj;
            out.evaluations += 2;
            let col = &mut jac[j * m..(j + 1) * m];
            for k in 0..m {
                let d = (rp[k] - rm[k]) / (2.0 * opts.step);
                col[k] = if d.is_finite() { d } else { 0.0 };
            }
        }
        out.iterations += 1;
        let mut a = vec![0.0; p * p];
        let mut g = vec![0.0; p];
        for i in 0..p {
            let ci = &jac[i * m..(i + 1) * m];
            g[i] = ci.iter().zip(&r).map(|(x, y)| x * y).sum();
            for j in 0..=i {
                let cj = &jac[j * m..(j + 1) * m];
                let v: f64 = ci.iter().zip(cj).map(|(x, y)| x * y).sum();
                a[i * p + j] = v;
                a[j * p + i] = v;
            }
        }
        let max_diag = (0..p).map(|i| a[i * p + i]).fold(0.0f64, f64::max);
        if max_diag <= 0.0 {
            // No parameter moves any residual: nothing to do.
            progress(out.iterations, out.cost);
            break;
        }
        loop {
            if cancel.load(Ordering::Relaxed) {
                out.cancelled = true;
                break 'outer;
            }
            let mut damped = a.clone();
            for i in 0..p {
                // A floor on the scaling keeps parameters that do not
                // matter (a zero column) from making the system singular.
                damped[i * p + i] += lambda * a[i * p + i].max(1e-9 * max_diag);
            }
            let neg_g: Vec<f64> = g.iter().map(|x| -x).collect();
            let Some(delta) = cholesky_solve(&mut damped, &neg_g, p) else {
                lambda *= 2.0;
                if lambda > 1e16 {
                    progress(out.iterations, out.cost);
                    break 'outer;
                }
                continue;
            };
            let tn: Vec<f64> = t.iter().zip(&delta).map(|(x, d)| x + d).collect();
            f(&tn, &mut trial)?;
            out.evaluations += 1;
            let cn = cost_of(&trial);
            if cn.is_finite() && cn < out.cost {
                let gain = (out.cost - cn) / out.cost.max(f64::MIN_POSITIVE);
                t = tn;
                std::mem::swap(&mut r, &mut trial);
                out.cost = cn;
                out.t.clone_from(&t);
                lambda = (lambda / 3.0).max(1e-12);
                progress(out.iterations, out.cost);
                if gain < opts.rel_tol || out.cost == 0.0 {
                    break 'outer;
                }
                break;
            }
            lambda *= 2.0;
            if lambda > 1e16 {
                // No step along any damping lowers the cost: a minimum (to
                // the resolution of the differences).
                progress(out.iterations, out.cost);
                break 'outer;
            }
        }
    }
    Ok(out)
}

/// Solves `a x = b` for a symmetric positive definite `a` (p × p, row-major,
/// overwritten by its Cholesky factor); `None` when `a` is not.
fn cholesky_solve(a: &mut [f64], b: &[f64], p: usize) -> Option<Vec<f64>> {
    for j in 0..p {
        let mut d = a[j * p + j];
        for k in 0..j {
            d -= a[j * p + k] * a[j * p + k];
        }
        if d <= 0.0 || !d.is_finite() {
            return None;
        }
        let d = d.sqrt();
        a[j * p + j] = d;
        for i in j + 1..p {
            let mut s = a[i * p + j];
            for k in 0..j {
                s -= a[i * p + k] * a[j * p + k];
            }
            a[i * p + j] = s / d;
        }
    }
    let mut y = b.to_vec();
    for i in 0..p {
        for k in 0..i {
            y[i] -= a[i * p + k] * y[k];
        }
        y[i] /= a[i * p + i];
    }
    for i in (0..p).rev() {
        for k in i + 1..p {
            y[i] -= a[k * p + i] * y[k];
        }
        y[i] /= a[i * p + i];
    }
    y.iter().all(|x| x.is_finite()).then_some(y)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn fits_an_exponential_decay() {
        // r_k = a exp(−b x_k) − y_k with y from a = 2, b = 0.7: a zero-residual problem.
        let xs: Vec<f64> = (0..20).map(|k| k as f64 * 0.25).collect();
        let ys: Vec<f64> = xs.iter().map(|x| 2.0 * (-0.7 * x).exp()).collect();
        let mut f = |t: &[f64], r: &mut [f64]| {
            for (k, x) in xs.iter().enumerate() {
                r[k] = t[0] * (-t[1] * x).exp() - ys[k];
            }
            Ok(())
        };
        let opts = LmOptions {
            max_iterations: 100,
            rel_tol: 1e-15,
            step: 1e-6,
        };
        let out = minimise(
            &[1.0, 0.1],
            20,
            &mut f,
            &opts,
            &AtomicBool::new(false),
            &mut |_, _| {},
        )
        .unwrap();
        assert!(
            (out.t[0] - 2.0).abs() < 1e-6 && (out.t[1] - 0.7).abs() < 1e-6,
            "{:?}",
            out.t
        );
    }

    #[test]
    fn cholesky_solves_and_refuses() {
        let mut a = vec![4.0, 2.0, 2.0, 3.0];
        let x = cholesky_solve(&mut a, &[2.0, 1.0], 2).unwrap();
        // 4x + 2y = 2, 2x + 3y = 1 → x = 0.5, y = 0.
        assert!((x[0] - 0.5).abs() < 1e-12 && x[1].abs() < 1e-12);
        let mut s = vec![1.0, 2.0, 2.0, 1.0];
        assert!(cholesky_solve(&mut s, &[1.0, 1.0], 2).is_none());
    }
}
