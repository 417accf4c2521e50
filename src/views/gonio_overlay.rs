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
    let set = |label: String, filled: bool, rs: &[bv_core::analysis::gonio::Reading]| {
        let shown = |f: f64, theta_s: f64| {
            let v = if cosine { f * theta_s.cos().abs() } else { f };
            v.max(0.0)
        };
        Readings3d {
            label,
            filled,
            stops: rs
                .iter()
                .filter(|r| r.f.is_finite() && r.sigma.is_finite())
                .map(|r| {
                    (
                        crate::derive::slices::plane_direction(r.theta_s, m.setup.phi_i),
                        shown(r.f, r.theta_s),
                        shown(r.f - 2.0 * r.sigma, r.theta_s),
                        shown(r.f + 2.0 * r.sigma, r.theta_s),
                    )
                })
                .collect(),
        }
    };
    let mut sets = Vec::new();
    let mut reference = None;
    match &m.single {
        Some(single) => {
            sets.push(set(
                "simulated surface, all bounces".into(),
                true,
                &m.readings,
            ));
            sets.push(set("simulated surface, one bounce".into(), false, single));
            reference = scene.primary().and_then(|b| b.brdf.furnace()).map(|f| {
                crate::derive::slices::plane_of_incidence(
                    f.as_ref(),
                    m.setup.theta_i,
                    m.setup.phi_i,
                    181,
                    cosine,
                )
                .iter()
                .map(|p| {
                    (
                        crate::derive::slices::plane_direction(p.x, m.setup.phi_i),
                        p.value.max(0.0),
                    )
                })
                .collect()
            });
        }
        None => sets.push(set("gonioreflectometer".into(), true, &m.readings)),
    }
    Some(Overlay3d { sets, reference })
}
