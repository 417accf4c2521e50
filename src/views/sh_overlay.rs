//! The spherical-harmonics overlay's controls, shared by the 3D lobe and the
//! polar plot: the "SH" toggle, the order L and the error line. The
//! projection itself is [`crate::derive::sh`]'s.

use crate::derive::sh::{ShDone, key_for};
use crate::session::command::Command;
use crate::session::frame::Scene;
use crate::session::state::Display;
use bv_core::represent::sh::{self, Domain};
use eframe::egui::{self, Role, Ui, WidgetInfo};

/// One line about a result: `SH L = 8: L2 error 23.4 %`.
pub fn summary(done: &ShDone, current: bool) -> String {
    let stale = if current { "" } else { " (updating…)" };
    match &done.value {
        Ok(r) => format!(
            "SH L = {}: relative L2 error {}{stale}",
            r.lobe.order,
            percent(r.lobe.rel_l2_error)
        ),
        Err(e) => format!("SH: {e}"),
    }
}

/// A fraction as a percentage with sensible digits.
pub fn percent(x: f64) -> String {
    let p = 100.0 * x;
    if p >= 10.0 {
        format!("{p:.1} %")
    } else if p >= 0.1 {
        format!("{p:.2} %")
    } else {
        format!("{p:.3} %")
    }
}

/// The toolbar control shared by the lobe and polar views: an "SH" toggle and
/// the order L (0–16); with the overlay on, the error of the current result.
pub fn control(ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
    let d = scene.state.display;
    if super::toolbar_toggle(
        ui,
        d.sh_overlay,
        "SH",
        "Overlay the selected lobe's spherical-harmonics reconstruction of order ≤ L \
         (dashed / wireframe), with its relative L2 error",
    ) {
        out.push(Command::SetDisplay(Display {
            sh_overlay: !d.sh_overlay,
            ..d
        }));
    }
    if d.sh_overlay {
        let mut l = d.sh_order.min(sh::MAX_ORDER as u8);
        let r = ui
            .add(
                egui::DragValue::new(&mut l)
                    .range(0..=sh::MAX_ORDER as u8)
                    .prefix("L = ")
                    .speed(0.1)
                    .update_while_editing(false),
            )
            .on_hover_text("Highest SH order (0–16): (L + 1)² coefficients");
        r.widget_info(|| WidgetInfo::labeled(Role::SpinButton, true, "SH order L"));
        if l != d.sh_order {
            out.push(Command::SetDisplay(Display { sh_order: l, ..d }));
        }
    }
}

/// The error label under a view's toolbar (accessible text: tests read it).
pub fn error_label(ui: &mut Ui, scene: &Scene<'_>, done: Option<&ShDone>) {
    let Some(done) = done else {
        if scene.state.display.sh_overlay && scene.primary().is_some() {
            ui.weak("SH: computing…");
        }
        return;
    };
    let current = key_for(scene).is_some_and(|(_, k)| k == done.key);
    let text = summary(done, current);
    let r = ui.label(&text);
    if let Ok(res) = &done.value {
        r.on_hover_text(format!(
            "‖ĝ − g‖ / ‖g‖ over the {} of {} ({} quadrature rings); projected in {:.0} ms",
            match res.lobe.domain {
                Domain::Hemisphere => "hemisphere",
                Domain::Sphere => "sphere",
            },
            super::value_label(done.key.cosine),
            res.lobe.n_theta,
            done.elapsed.as_secs_f64() * 1e3
        ));
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn percentages() {
        assert_eq!(percent(0.234), "23.4 %");
        assert_eq!(percent(0.0123), "1.23 %");
        assert_eq!(percent(0.00012), "0.012 %");
    }
}
