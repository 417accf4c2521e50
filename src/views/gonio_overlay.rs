//! The virtual gonioreflectometer's overlay controls (LECTURE.md N8, issue
//! 29), shared by the polar and the 3D lobe views: both draw the same
//! readings (`derive::gonio`) over their own picture of the BRDF.

use super::Scene;
use crate::session::command::Command;
use crate::session::state::PlotSettings;
use eframe::egui::Ui;

/// The *gonio* and *surface* toggles, a note when the selected BRDF names
/// no slopes to simulate, and the measurement's progress.
pub fn control(ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
    let plots = scene.state.plots;
    if super::toolbar_toggle(
        ui,
        plots.gonio,
        "gonio",
        "Virtual gonioreflectometer: photons from the selected BRDF's own sampler, \
         counted by a detector (1.5° aperture) stopping every 5° in the plane of \
         incidence; dots with 2σ error bars over the curve",
    ) {
        out.push(Command::SetPlots(PlotSettings {
            gonio: !plots.gonio,
            ..plots
        }));
    }
    if plots.gonio
        && super::toolbar_toggle(
            ui,
            plots.gonio_surface,
            "surface",
            "Measure a simulated microsurface with the selected BRDF's slopes \
             (Beckmann or GGX, F = 1) instead of the BRDF: filled dots all bounces, \
             hollow dots one bounce, dashed the model's lobe with F = 1",
        )
    {
        out.push(Command::SetPlots(PlotSettings {
            gonio_surface: !plots.gonio_surface,
            ..plots
        }));
    }
    if plots.gonio
        && plots.gonio_surface
        && let Some(b) = scene.primary()
        && crate::derive::gonio::specimen(scene, b.brdf.as_ref()).is_none()
    {
        ui.label(format!(
            "{} names no Beckmann or GGX slopes to simulate",
            b.label
        ));
    }
    if let Some(shown) = crate::derive::gonio::request(&super::waker(ui.ctx()), scene)
        && shown.busy
        && let Some((a, b)) = shown.progress
    {
        ui.label(format!("measuring {a}/{b}"));
    }
}

/// One detector stop as the views draw it: its signed angle in the plane
/// of incidence (radians, positive on the mirror side), the reading and
/// its 2σ bounds in the quantity drawn (f, or f |cos θo|), never negative.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Stop {
    /// Signed θo of the detector (radians).
    pub theta_s: f64,
    /// The reading.
    pub value: f64,
    /// Reading − 2σ.
    pub lo: f64,
    /// Reading + 2σ.
    pub hi: f64,
}

/// The finite readings of a set as [`Stop`]s (`cosine`: the views show
/// f cos θo).
pub fn stops(readings: &[bv_core::analysis::gonio::Reading], cosine: bool) -> Vec<Stop> {
    let shown = |f: f64, theta_s: f64| {
        let v = if cosine { f * theta_s.cos().abs() } else { f };
        v.max(0.0)
    };
    readings
        .iter()
        .filter(|r| r.f.is_finite() && r.sigma.is_finite())
        .map(|r| Stop {
            theta_s: r.theta_s,
            value: shown(r.f, r.theta_s),
            lo: shown(r.f - 2.0 * r.sigma, r.theta_s),
            hi: shown(r.f + 2.0 * r.sigma, r.theta_s),
        })
        .collect()
}

/// The selected BRDF's lobe with F = 1 (`Brdf::furnace`) in the plane of
/// incidence of `setup`, `n` samples of (signed θo, value): what a simulated
/// surface's one-bounce readings follow. `None` for a BRDF without one.
pub fn f1_section(
    scene: &Scene<'_>,
    setup: &bv_core::analysis::gonio::GonioSetup,
    n: usize,
) -> Option<Vec<(f64, f64)>> {
    let f = scene.primary()?.brdf.furnace()?;
    Some(
        crate::derive::slices::plane_of_incidence(
            f.as_ref(),
            setup.theta_i,
            setup.phi_i,
            n,
            scene.state.display.cosine,
        )
        .iter()
        .map(|p| (p.x, p.value))
        .collect(),
    )
}

/// One set of readings as the lobe view draws them: the detector's
/// directions (unit, in the surface frame), each with its reading and 2σ
/// bounds in the quantity drawn (f, or f cos θo).
pub struct Readings3d {
    /// Legend text.
    pub label: String,
    /// Filled dots (all bounces, or a BRDF's own readings) or hollow (one
    /// bounce on a simulated surface).
    pub filled: bool,
    /// (direction, value, low, high) per detector stop.
    pub stops: Vec<(glam::DVec3, f64, f64, f64)>,
}

/// What the lobe view draws of a measurement: the reading sets and, for a
/// simulated surface, the selected BRDF's lobe with F = 1 in the plane of
/// incidence (direction, value), which its one-bounce readings follow.
pub struct Overlay3d {
    /// The reading sets.
    pub sets: Vec<Readings3d>,
    /// The single-scattering reference curve, if any.
    pub reference: Option<Vec<(glam::DVec3, f64)>>,
}

/// The gonioreflectometer's readings for the 3D lobe view; `None` with
/// the overlay off or nothing measured yet.
pub fn readings_3d(scene: &Scene<'_>, waker: &crate::derive::jobs::Waker) -> Option<Overlay3d> {
    let shown = crate::derive::gonio::request(waker, scene)?;
    let done = shown.done?;
    let m = &done.value;
    let cosine = scene.state.display.cosine;
    let dir = |theta_s: f64| crate::derive::slices::plane_direction(theta_s, m.setup.phi_i);
    let set = |label: &str, filled: bool, rs: &[bv_core::analysis::gonio::Reading]| Readings3d {
        label: label.into(),
        filled,
        stops: stops(rs, cosine)
            .iter()
            .map(|s| (dir(s.theta_s), s.value, s.lo, s.hi))
            .collect(),
    };
    let (sets, reference) = match &m.single {
        Some(single) => (
            vec![
                set("simulated surface, all bounces", true, &m.readings),
                set("simulated surface, one bounce", false, single),
            ],
            f1_section(scene, &m.setup, 181)
                .map(|c| c.into_iter().map(|(t, v)| (dir(t), v.max(0.0))).collect()),
        ),
        None => (vec![set("gonioreflectometer", true, &m.readings)], None),
    };
    Some(Overlay3d { sets, reference })
}
