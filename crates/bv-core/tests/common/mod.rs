//! Helpers shared by the catalogue-wide tests (`properties.rs`,
//! `batch_parity.rs`).

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_core::params::FloatSpec;
use bv_core::sampling::BvRng;
use rand::Rng;

/// A float from its spec: 5 % exactly `min`, 5 % exactly `max` (the edges are
/// where guards are needed: exponent 0, α = 0.001), otherwise uniform, or
/// log-uniform when the spec says `log` (from `max · 1e-6` when `min` is 0).
pub fn random_float(s: &FloatSpec, rng: &mut BvRng) -> f64 {
    let r: f64 = rng.random();
    if r < 0.05 {
        return s.min;
    }
    if r < 0.10 {
        return s.max;
    }
    let x = if s.log && s.max > 0.0 && s.min >= 0.0 {
        let lo = if s.min > 0.0 { s.min } else { s.max * 1e-6 };
        (rng.random_range(lo.ln()..=s.max.ln())).exp()
    } else {
        rng.random_range(s.min..=s.max)
    };
    x.clamp(s.min, s.max)
}
