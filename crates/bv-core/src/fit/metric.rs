//! The error metrics a fit minimises, as residual vectors for
//! Levenberg–Marquardt: `error = sqrt(Σ_k r_k²)` with one residual per pair
//! and channel, `r = sqrt(w / W) (g(f_model cos θi) − g(f_target cos θi))`,
//! `w` the pair's share of dωi dωo ([`super::samples`]), `W = 3 Σ w` (three
//! channels). So both errors are weighted RMS differences over the
//! hemisphere of pairs, in the units of `g`.

use serde::{Deserialize, Serialize};

/// Which transform `g` of the cosine-weighted BRDF the error compares.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(rename_all = "lowercase")]
pub enum Metric {
    /// Ngan et al. 2005 ("Experimental Analysis of BRDF Models", EGSR,
    /// their fitting objective): the cube root of the cosine-weighted BRDF,
    /// `E = sqrt(Σ w (∛(f_t cos θi) − ∛(f_m cos θi))² / Σ w)`, `w` the solid
    /// angle weight of each sample. The cube root compresses the specular
    /// peak so that the diffuse part and the lobe's tails still count.
    Ngan,
    /// Löw et al. 2012 ("BRDF Models for Accurate and Efficient Rendering of
    /// Glossy Surfaces", ACM TOG 31(1), the metric they call E2):
    /// `E2 = sqrt(Σ w (ln(1 + f_t cos θi) − ln(1 + f_m cos θi))² / Σ w)`,
    /// relative for large values, absolute for small ones.
    E2,
}

impl Metric {
    /// Every metric, in the order the CLI lists them.
    pub const ALL: [Metric; 2] = [Metric::Ngan, Metric::E2];

    /// The name the CLI and JSON use.
    pub fn name(self) -> &'static str {
        match self {
            Metric::Ngan => "ngan",
            Metric::E2 => "e2",
        }
    }

    /// The metric called `name` (`ngan`, `e2`).
    pub fn from_name(name: &str) -> Option<Self> {
        Self::ALL.into_iter().find(|m| m.name() == name.trim())
    }

    /// `g(f cos θi)`: the transform both sides go through. Negative values
    /// (which no valid BRDF has) are kept negative rather than made NaN, so
    /// that a fit can still move away from them.
    #[inline]
    pub fn transform(self, f_cos: f64) -> f64 {
        match self {
            Metric::Ngan => f_cos.cbrt(),
            Metric::E2 => f_cos.signum() * f_cos.abs().ln_1p(),
        }
    }
}

/// Residuals of model values `model` (channel-major: `model[c][k]`) against
/// transformed target values `target_g[c][k]` into `out` (`3 n` long,
/// channel-major). A non-finite model value gives an infinite residual,
/// which the optimiser rejects.
pub(crate) fn residuals(
    metric: Metric,
    model: &[Vec<f32>; 3],
    target_g: &[Vec<f64>; 3],
    cos_i: &[f64],
    sqrt_w: &[f64],
    out: &mut [f64],
) {
    let n = cos_i.len();
    for c in 0..3 {
        for k in 0..n {
            let f = model[c][k] as f64;
            let r = sqrt_w[k] * (metric.transform(f * cos_i[k]) - target_g[c][k]);
            out[c * n + k] = if r.is_finite() { r } else { f64::INFINITY };
        }
    }
}
