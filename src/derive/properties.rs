//! Property reports: for a BRDF, whether it is reciprocal,
//! energy-conserving, positive and isotropic, each with the number behind
//! the verdict ("reciprocal ✓ 3e-16", "energy ✗ ρhd max 1.23 at θi 89.9°"),
//! and the evidence lines behind each. They are `bv_core::analysis::check`'s
//! verdicts, the ones `bv check` prints, computed with fewer direction pairs
//! and a coarser θi grid (the near-grazing angles kept: that is where the
//! classical Phong of the lecture exceeds 1), as a job cached by the BRDF's
//! build revision; the panel's badges show them.

use super::jobs::{self, Slots, Waker};
use crate::session::runtime::Built;
use bv_core::analysis::{self, CheckOptions, PairSample, PropertyReport};
use std::sync::Arc;

/// The check the panel runs: `bv check`'s estimators and thresholds with a
/// tenth of its direction pairs, a θi step of 3° instead of 1° (plus the same
/// near-grazing angles) and smaller Monte Carlo and NDF budgets, so that a
/// badge follows a parameter change within a fraction of a second.
pub fn options() -> CheckOptions {
    CheckOptions {
        pairs: 2000,
        theta_count: 30,
        samples_per_angle: 1024,
        anisotropic_azimuths: 2,
        hh_samples: 8192,
        ndf_max_evals: 200_000,
        ..CheckOptions::default()
    }
}

/// One of the four properties a badge shows.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Property {
    /// Helmholtz reciprocity, `f(ωi, ωo) = f(ωo, ωi)`.
    Reciprocal,
    /// `ρhd(θi) ≤ 1` for every θi.
    Energy,
    /// `f ≥ 0` and finite.
    Positive,
    /// Invariance under a common rotation about the normal.
    Isotropic,
}

impl Property {
    /// The four, in the order the panel shows them.
    pub const ALL: [Property; 4] = [
        Property::Reciprocal,
        Property::Energy,
        Property::Positive,
        Property::Isotropic,
    ];

    /// The badge's word.
    pub fn word(self) -> &'static str {
        match self {
            Property::Reciprocal => "reciprocal",
            Property::Energy => "energy",
            Property::Positive => "positive",
            Property::Isotropic => "isotropic",
        }
    }
}

/// A computed badge.
#[derive(Debug, Clone, PartialEq)]
pub struct Badge {
    /// Which property.
    pub property: Property,
    /// The verdict.
    pub ok: bool,
    /// What the badge reads ("reciprocal ✓ 3e-16").
    pub text: String,
}

/// A number in a badge: two significant digits, scientific when small.
fn short(x: f64) -> String {
    if x == 0.0 {
        "0".into()
    } else if !x.is_finite() {
        format!("{x}")
    } else if !(1e-3..1e4).contains(&x.abs()) {
        format!("{x:.0e}")
    } else {
        let digits = (2 - x.abs().log10().floor() as i32).clamp(0, 3) as usize;
        format!("{x:.digits$}")
    }
}

fn mark(ok: bool) -> &'static str {
    if ok { "✓" } else { "✗" }
}

/// The badge of `property` in `report`.
pub fn badge(report: &PropertyReport, property: Property) -> Badge {
    let (ok, measured) = match property {
        Property::Reciprocal => (
            report.reciprocity.reciprocal,
            short(report.reciprocity.max_rel_err),
        ),
        Property::Energy => {
            let e = &report.energy;
            let max = e.max.max_channel().0;
            let at = if e.conserves {
                String::new()
            } else {
                format!(" at θi {}°", trim_deg(e.argmax_theta_deg))
            };
            (e.conserves, format!("ρhd max {}{at}", short(max)))
        }
        Property::Positive => (
            report.positivity.ok,
            format!("min f {}", short(report.positivity.min_f)),
        ),
        Property::Isotropic => (
            report.isotropy.isotropic,
            short(report.isotropy.max_rel_change),
        ),
    };
    Badge {
        property,
        ok,
        text: format!("{} {} {measured}", property.word(), mark(ok)),
    }
}

/// The four badges of `report`.
pub fn badges(report: &PropertyReport) -> [Badge; 4] {
    Property::ALL.map(|p| badge(report, p))
}

use bv_core::text::fmt_deg as trim_deg;

fn pair(w: &PairSample) -> String {
    format!(
        "ωi (θ {}°, φ {}°), ωo (θ {}°, φ {}°): {} vs {} (largest channel)",
        trim_deg(w.wi_deg[0]),
        trim_deg(w.wi_deg[1]),
        trim_deg(w.wo_deg[0]),
        trim_deg(w.wo_deg[1]),
        bv_core::text::fmt_value(w.f.max_element()),
        bv_core::text::fmt_value(w.f_swapped.max_element()),
    )
}

fn claimed(b: bool) -> String {
    format!("the model claims: {}", if b { "yes" } else { "no" })
}

/// The numbers behind a badge, one line each (what `bv check` prints for
/// that property).
pub fn evidence(report: &PropertyReport, property: Property) -> Vec<String> {
    use bv_core::text::fmt_value as v;
    let mut lines = Vec::new();
    match property {
        Property::Reciprocal => {
            let r = &report.reciprocity;
            lines.push(format!(
                "max |f(ωi,ωo) − f(ωo,ωi)| / max f = {} over {} pairs (threshold {})",
                v(r.max_rel_err),
                r.pairs,
                v(r.threshold)
            ));
            lines.push(format!("max f = {} 1/sr", v(r.max_f)));
            if let Some(w) = &r.worst {
                lines.push(format!("worst pair: {}", pair(w)));
            }
            lines.push(claimed(report.claims.reciprocal));
        }
        Property::Energy => {
            let e = &report.energy;
            let (m, err, _) = e.max.max_channel();
            lines.push(format!(
                "max ρhd = {} ± {} at θi = {}°, φi = {}°",
                v(m),
                v(err),
                trim_deg(e.argmax_theta_deg),
                trim_deg(e.argmax_phi_deg)
            ));
            lines.push(format!(
                "{} θi + {} near-grazing θi × {} azimuth(s)",
                e.curves.first().map_or(0, |c| c.rho.len()),
                e.grazing.first().map_or(0, |c| c.rho.len()),
                e.curves.len()
            ));
            let method = if e.method == "quadrature" {
                format!(
                    "Gauss–Kronrod quadrature, ± its error estimate{}",
                    if e.converged {
                        ""
                    } else {
                        " (tolerance not met)"
                    }
                )
            } else {
                format!(
                    "Monte Carlo, {} samples each, ± one standard error; verdict at {}σ",
                    e.curves
                        .first()
                        .and_then(|c| c.rho.first())
                        .map_or(0, |x| x.samples),
                    e.sigmas
                )
            };
            lines.push(method);
            let (hh, hh_err, _) = e.rho_hh.max_channel();
            lines.push(format!("ρhh = {} ± {}", v(hh), v(hh_err)));
            if e.has_deltas {
                lines.push("delta lobes included in ρhd".into());
            }
            if e.transmits {
                lines.push("ρhd integrates over the whole sphere (transmission)".into());
            }
            lines.push(claimed(report.claims.energy_conserving));
        }
        Property::Positive => {
            let p = &report.positivity;
            lines.push(format!(
                "min f = {} over {} evaluations: {} negative, {} non-finite",
                v(p.min_f),
                p.evaluations,
                p.negative,
                p.non_finite
            ));
            if let Some(w) = &p.worst {
                lines.push(format!("lowest at {}", pair(w)));
            }
        }
        Property::Isotropic => {
            let i = &report.isotropy;
            lines.push(format!(
                "max relative change under a rotation about the normal = {} over {} pairs (threshold {})",
                v(i.max_rel_change),
                i.pairs,
                v(i.threshold)
            ));
            if let Some(w) = &i.worst {
                lines.push(format!(
                    "worst: {} after turning both by {}°",
                    pair(w),
                    trim_deg(i.worst_rotation_deg)
                ));
            }
            lines.push(claimed(report.claims.isotropic));
        }
    }
    let o = options();
    lines.push(format!(
        "panel check: {} pairs, {} θi (bv check: {} pairs, {} θi)",
        o.pairs,
        o.theta_count,
        CheckOptions::default().pairs,
        CheckOptions::default().theta_count
    ));
    lines
}

/// The reports of every BRDF (slot: BRDF id, key: its build revision).
pub fn slots() -> Arc<Slots<u64, Arc<PropertyReport>>> {
    jobs::slots("property report")
}

/// The report of `built` for BRDF `id`: the latest finished one (perhaps of
/// an older revision, then `stale`), starting its computation when needed.
pub fn report(waker: &Waker, id: u64, built: &Built) -> Option<(Arc<PropertyReport>, bool)> {
    let brdf = built.brdf.clone()?;
    let done = slots().request(
        id,
        built.revision,
        jobs::once(move || Arc::new(analysis::check(brdf.as_ref(), &options()))),
        waker,
    )?;
    Some((done.value.clone(), done.key != built.revision))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn short_numbers() {
        assert_eq!(short(0.0), "0");
        assert_eq!(short(3.1e-16), "3e-16");
        assert_eq!(short(1.234), "1.23");
        assert_eq!(short(0.5), "0.500");
        assert_eq!(short(12.5), "12.5");
    }

    #[test]
    fn panel_options_are_cheaper_than_bv_check() {
        let (p, d) = (options(), CheckOptions::default());
        assert!(p.pairs < d.pairs && p.theta_count < d.theta_count);
        // The angles where ρhd of a 1/cos θi lobe blows up are kept.
        assert_eq!(p.grazing_deg, d.grazing_deg);
        assert_eq!(
            (p.tolerance, p.energy_sigmas),
            (d.tolerance, d.energy_sigmas)
        );
    }
}
