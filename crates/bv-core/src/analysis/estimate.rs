//! An estimated number with its error and how it was computed: what every
//! albedo method (Monte Carlo in `albedo`, quadrature in `quadrature`)
//! returns.

use crate::Rgb;
use serde::Serialize;

/// How an [`Estimate`] was computed, and so what its error means.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(tag = "kind", rename_all = "kebab-case")]
pub enum Method {
    /// Monte Carlo: `std_error` is a standard error (one σ).
    MonteCarlo {
        /// Independent replicas behind the standard error.
        replicas: usize,
    },
    /// Deterministic Gauss–Kronrod quadrature: `std_error` is the error
    /// estimate `|K15 − G7|` summed over panels (a bound-like estimate).
    Quadrature {
        /// Whether the tolerance was met within the panel budget.
        converged: bool,
    },
}

impl Method {
    /// A short name for reports: `quadrature` or `monte carlo`.
    pub fn name(&self) -> &'static str {
        match self {
            Method::MonteCarlo { .. } => "monte carlo",
            Method::Quadrature { .. } => "quadrature",
        }
    }
}

/// An estimate with its error (per linear-RGB channel).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct Estimate {
    /// The estimate.
    pub value: Rgb,
    /// Its error: the standard error (one σ) for Monte Carlo, the error
    /// estimate for quadrature (see [`Estimate::method`]).
    pub std_error: Rgb,
    /// Samples (`f` evaluations) it used.
    pub samples: usize,
    /// Samples discarded because `f` or the density was NaN or infinite (a
    /// model bug: positivity reports it too).
    pub rejected: usize,
    /// How it was computed.
    pub method: Method,
}

impl Estimate {
    /// The error allowance of a verdict: `sigmas` standard errors for Monte
    /// Carlo, the error estimate itself for quadrature (per channel).
    pub fn allowance(&self, sigmas: f64) -> Rgb {
        match self.method {
            Method::MonteCarlo { .. } => self.std_error * sigmas,
            Method::Quadrature { .. } => self.std_error,
        }
    }

    /// The largest channel: `(value, its std_error, channel index)`.
    pub fn max_channel(&self) -> (f64, f64, usize) {
        let v = self.value.to_array();
        let e = self.std_error.to_array();
        let mut c = 0;
        for i in 1..3 {
            if v[i] > v[c] {
                c = i;
            }
        }
        (v[c], e[c], c)
    }
}

/// A directional albedo split by where the light leaves: `reflected` (ρR,
/// back to the side it came from) and `transmitted` (ρT, through the
/// surface; 0 for a reflection model), each with its own error, and their
/// sum `total` (ρhd = ρR + ρT, which energy conservation bounds by 1).
#[derive(Debug, Clone, Copy, PartialEq, Serialize)]
pub struct AlbedoParts {
    /// ρhd = ρR + ρT.
    pub total: Estimate,
    /// ρR.
    pub reflected: Estimate,
    /// ρT.
    pub transmitted: Estimate,
}

impl AlbedoParts {
    /// The parts of a deterministic (quadrature) estimate: the total's error
    /// is the sum of the parts' error bounds.
    pub fn new(reflected: Estimate, transmitted: Estimate) -> Self {
        let method = match (reflected.method, transmitted.method) {
            (Method::Quadrature { converged: a }, Method::Quadrature { converged: b }) => {
                Method::Quadrature { converged: a && b }
            }
            (m, _) => m,
        };
        Self {
            total: Estimate {
                value: reflected.value + transmitted.value,
                std_error: reflected.std_error + transmitted.std_error,
                samples: reflected.samples + transmitted.samples,
                rejected: reflected.rejected + transmitted.rejected,
                method,
            },
            reflected,
            transmitted,
        }
    }
}
