//! Property reports: for a BRDF, whether it is reciprocal,
//! energy-conserving, positive and isotropic, each with the number behind
//! the verdict ("reciprocal ✓ 3e-16", "energy ✗ ρhd max 1.23 ± 0.001 at θi
//! 89.9°"), and the evidence lines behind each. They are
//! `bv_core::analysis::check`'s verdicts, the ones `bv check` prints, as
//! jobs cached by the BRDF's build revision, in two stages:
//! 1. a **preview** with fewer direction pairs and a coarser θi grid (the
//!    near-grazing angles kept: that is where the classical Phong of the
//!    lecture exceeds 1), so that a badge follows a slider within a fraction
//!    of a second;
//! 2. then **`bv check`'s own run** ([`check_options`]), which replaces it:
//!    a settled badge shows the very numbers and errors `bv check` prints.
//!    The preview's largest ρhd is the maximum of noisier estimates, biased
//!    upwards (a user file's 0.71 where `bv check` finds 0.497 ± 0.041), so
//!    it is marked as a preview until the check's run is in.
//!
//! A model that `bv check` would refuse as too slow for its budget
//! ([`bv_core::analysis::CHECK_BUDGET`]) keeps its preview, which says so.

use super::jobs::{self, Slots, Waker};
use crate::session::runtime::Built;
use bv_core::analysis::{
    self, CHECK_BUDGET, CheckOptions, PairSample, PropertyReport, fmt_estimate,
};
use bv_core::text::fmt_duration;
use std::sync::Arc;

/// The preview the panel runs first: `bv check`'s estimators and thresholds
/// with a tenth of its direction pairs, a θi step of 3° instead of 1° (plus
/// the same near-grazing angles) and smaller Monte Carlo and NDF budgets.
pub fn preview_options() -> CheckOptions {
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

/// What `bv check` runs (its default `--albedo auto`), and so what a
/// settled badge shows.
pub fn check_options() -> CheckOptions {
    CheckOptions::default()
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
            let at = if e.conserves {
                String::new()
            } else {
                format!(" at θi {}°", trim_deg(e.argmax_theta_deg))
            };
            (e.conserves, format!("ρhd max {}{at}", fmt_estimate(&e.max)))
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

fn claimed(b: Option<bool>) -> String {
    match b {
        Some(b) => format!("the model claims: {}", if b { "yes" } else { "no" }),
        // A file's data (MERL, user .brdf) promises nothing.
        None => "the model claims nothing (file data)".to_string(),
    }
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
            lines.push(format!(
                "max ρhd = {} at θi = {}°, φi = {}°",
                fmt_estimate(&e.max),
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
            lines.push(format!("ρhh = {}", fmt_estimate(&e.rho_hh)));
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
    lines
}

/// Which run a shown report comes from.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Stage {
    /// The quick run with [`preview_options`].
    Preview,
    /// `bv check`'s own run ([`check_options`]).
    Check,
}

impl Stage {
    /// The options of this run.
    pub fn options(self) -> CheckOptions {
        match self {
            Stage::Preview => preview_options(),
            Stage::Check => check_options(),
        }
    }

    /// The evidence windows' last line: which run the numbers come from.
    pub fn describe(self) -> String {
        let (p, c) = (preview_options(), check_options());
        match self {
            Stage::Preview => format!(
                "preview: {} pairs, {} θi (bv check's own run, {} pairs, {} θi, follows)",
                p.pairs, p.theta_count, c.pairs, c.theta_count
            ),
            Stage::Check => format!(
                "bv check's own run: {} pairs, {} θi; the numbers it prints",
                c.pairs, c.theta_count
            ),
        }
    }
}

/// A report for the panel to show.
#[derive(Debug, Clone)]
pub struct Shown {
    /// The report.
    pub report: Arc<PropertyReport>,
    /// Which run it comes from.
    pub stage: Stage,
    /// It is of an older build of the BRDF (a newer one is computing).
    pub stale: bool,
    /// Why `bv check`'s run will not follow the preview (the model is too
    /// slow for its budget), as a sentence.
    pub no_check: Option<String>,
}

/// The reports of `bv check`'s own runs (slot: BRDF id, key: build
/// revision).
pub fn slots() -> Arc<Slots<u64, Arc<PropertyReport>>> {
    jobs::slots("property report")
}

/// The previews (slot: BRDF id, key: build revision).
pub fn previews() -> Arc<Slots<u64, Arc<PropertyReport>>> {
    jobs::slots("property report preview")
}

/// Why `bv check` would refuse `built`'s model as too slow, if it would.
fn too_slow(built: &Built) -> Option<String> {
    let brdf = built.brdf.as_deref()?;
    let threads = rayon::current_num_threads();
    let t = check_options().estimated_time(brdf, threads)?;
    (t > CHECK_BUDGET).then(|| {
        format!(
            "bv check would refuse this model: about {} of evaluations, over its budget of {}",
            fmt_duration(t),
            fmt_duration(CHECK_BUDGET)
        )
    })
}

/// The report to show for `built` (BRDF `id`): `bv check`'s run of this
/// build when it is in; else this build's preview, starting `bv check`'s
/// run once the preview is in (so that a slider being dragged costs
/// previews only); else the latest report of an older build (`stale`).
/// Starts what is needed; `None` while nothing was ever computed.
pub fn report(waker: &Waker, id: u64, built: &Built) -> Option<Shown> {
    let brdf = built.brdf.clone()?;
    let rev = built.revision;
    if let Some(d) = slots().get(id, &rev) {
        return Some(Shown {
            report: d.value.clone(),
            stage: Stage::Check,
            stale: false,
            no_check: None,
        });
    }
    let b = brdf.clone();
    let preview = previews().request(
        id,
        rev,
        jobs::once(move || Arc::new(analysis::check(b.as_ref(), &preview_options()))),
        waker,
    );
    match preview {
        Some(p) if p.key == rev => {
            let no_check = too_slow(built);
            if no_check.is_none() {
                let checked = slots().request(
                    id,
                    rev,
                    jobs::once(move || Arc::new(analysis::check(brdf.as_ref(), &check_options()))),
                    waker,
                );
                if let Some(d) = checked.filter(|d| d.key == rev) {
                    return Some(Shown {
                        report: d.value.clone(),
                        stage: Stage::Check,
                        stale: false,
                        no_check: None,
                    });
                }
            }
            Some(Shown {
                report: p.value.clone(),
                stage: Stage::Preview,
                stale: false,
                no_check,
            })
        }
        older => {
            // An older build's: `bv check`'s run if there is one, else its
            // preview.
            let (d, stage) = match slots().latest(id) {
                Some(d) => (d, Stage::Check),
                None => (older?, Stage::Preview),
            };
            Some(Shown {
                report: d.value.clone(),
                stage,
                stale: true,
                no_check: None,
            })
        }
    }
}

/// The report last shown for BRDF `id` (for its evidence window), without
/// starting anything: `bv check`'s run of the newest build if it is in,
/// else the newest preview.
pub fn latest(id: u64) -> Option<Shown> {
    let check = slots().latest(id);
    let preview = previews().latest(id);
    let (d, stage) = match (check, preview) {
        (Some(c), Some(p)) if p.key != c.key => (p, Stage::Preview),
        (Some(c), _) => (c, Stage::Check),
        (None, Some(p)) => (p, Stage::Preview),
        (None, None) => return None,
    };
    Some(Shown {
        report: d.value.clone(),
        stage,
        stale: false,
        no_check: None,
    })
}

/// Waits until neither the previews nor `bv check`'s runs have work
/// running or waiting, or `timeout` passes; true when idle. For tests and
/// headless callers: it blocks the thread, which the browser cannot do.
#[cfg(not(target_arch = "wasm32"))]
pub fn wait_idle(timeout: std::time::Duration) -> bool {
    use crate::session::platform::Instant;
    use std::time::Duration;
    let t0 = Instant::now();
    let (a, b) = (previews(), slots());
    loop {
        if a.wait_idle(Duration::ZERO) && b.wait_idle(Duration::ZERO) {
            return true;
        }
        if t0.elapsed() > timeout {
            return false;
        }
        std::thread::sleep(Duration::from_millis(2));
    }
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
        let (p, d) = (preview_options(), check_options());
        assert!(p.pairs < d.pairs && p.theta_count < d.theta_count);
        // The angles where ρhd of a 1/cos θi lobe blows up are kept.
        assert_eq!(p.grazing_deg, d.grazing_deg);
        assert_eq!(
            (p.tolerance, p.energy_sigmas),
            (d.tolerance, d.energy_sigmas)
        );
    }
}
