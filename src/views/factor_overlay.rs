//! The factorisation overlay's controls, shared by the 3D lobe and the polar
//! plot: the "factor" toggle, the terms K and the error line. The
//! factorisation and the rebuilt lobe are [`crate::derive::factor`]'s.

use crate::derive::factor::{FactorDone, key_for};
use crate::session::command::Command;
use crate::session::frame::Scene;
use crate::session::state::Display;
use eframe::egui::{self, Role, Ui, WidgetInfo};

/// One line about a result:
/// `factor K = 2: lobe L2 error 31 % (table, cos-weighted: 19 %)`.
pub fn summary(done: &FactorDone, current: bool) -> String {
    let stale = if current { "" } else { " (updating…)" };
    match &done.value {
        Ok(r) => format!(
            "factor K = {}: lobe L2 error {} (table, cos-weighted: {}){stale}",
            r.terms,
            super::sh_overlay::percent(r.lobe_error),
            super::sh_overlay::percent(
                r.factored
                    .fac
                    .rel_l2_error
                    .get(r.terms - 1)
                    .copied()
                    .unwrap_or(f64::NAN)
            )
        ),
        Err(e) => format!("factor: {e}"),
    }
}

/// The toolbar control shared by the lobe and polar views: a "factor" toggle
/// and the number of terms K; with the overlay on, the error of the result.
pub fn control(ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
    let d = scene.state.display;
    if super::toolbar_toggle(
        ui,
        d.factor_overlay,
        "factor",
        "Overlay the selected BRDF rebuilt from the first K terms of the SVD of its \
         half/difference table, Σ g_k(θh) h_k(θd, φd) (dashed / wireframe), with its \
         relative L2 error",
    ) {
        out.push(Command::SetDisplay(Display {
            factor_overlay: !d.factor_overlay,
            ..d
        }));
    }
    if d.factor_overlay {
        let mut k = d.factor_terms.clamp(1, Display::MAX_FACTOR_TERMS);
        let r = ui
            .add(
                egui::DragValue::new(&mut k)
                    .range(1..=Display::MAX_FACTOR_TERMS)
                    .prefix("K = ")
                    .speed(0.1)
                    .update_while_editing(false),
            )
            .on_hover_text("Terms of the factorisation (1–8), per colour channel");
        r.widget_info(|| WidgetInfo::labeled(Role::SpinButton, true, "factor terms K"));
        if k != d.factor_terms {
            out.push(Command::SetDisplay(Display {
                factor_terms: k,
                ..d
            }));
        }
    }
}

/// The error label under a view's toolbar (accessible text: tests read it).
pub fn error_label(ui: &mut Ui, scene: &Scene<'_>, done: Option<&FactorDone>) {
    let Some(done) = done else {
        if scene.state.display.factor_overlay && scene.primary().is_some() {
            ui.weak("factor: computing…");
        }
        return;
    };
    let current = key_for(scene).is_some_and(|(_, k)| k == done.key);
    let r = ui.label(summary(done, current));
    if let Ok(res) = &done.value {
        let dims = res.factored.fac.dims;
        r.on_hover_text(format!(
            "|rebuilt − f| / |f| of the lobe at ωi ({}); the table's error is that of \
             f cos θi cos θo over its {dims} cells and three channels (the factored \
             quantity); rebuilt in {:.0} ms",
            super::value_label(done.key.cosine),
            done.elapsed.as_secs_f64() * 1e3
        ));
    }
}
