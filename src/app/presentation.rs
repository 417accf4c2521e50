//! Presentation mode's pieces of UI and bookkeeping: the title band, the
//! strip of view names, the high-contrast look and the open lecture deck.
//! The viewer ([`super::viewer`]) decides when they are drawn.
//!
//! Whether bv is presenting is kept in the viewer, not in the saved state:
//! it is how this window is being used right now (a projector, a deck
//! open), not a property of the scene. A scene saved during a lecture opens
//! normally, and a restart does not come back scaled up with the panel
//! hidden. A rendered slide (`bv render --deck`) sets the same fields on a
//! figure viewer.

use crate::session::deck::Deck;
use crate::session::state::Theme;
use crate::views::REGISTRY;
use eframe::egui::{self, Color32, RichText, Ui};
use std::path::PathBuf;

/// Title size in points (50 pixels at 1080p, with the presentation scale).
pub const TITLE_PT: f32 = 18.0;
/// Caption size in points (32 pixels at 1080p).
pub const CAPTION_PT: f32 = 11.5;
/// Text size of the strip of views in points (26 pixels at 1080p): the
/// presenter's controls, smaller than the slide's text so that they fit one
/// line.
pub const STRIP_PT: f32 = 9.5;

/// The open deck and where in it the viewer is.
#[derive(Debug, Clone)]
pub struct DeckSession {
    /// The slides; the current one's state is the viewer's until it steps
    /// away (then written back here).
    pub deck: Deck,
    /// Its file (where Ctrl+S saves it), if it has one.
    pub path: Option<PathBuf>,
    /// The slide shown.
    pub index: usize,
}

/// What presentation mode keeps between frames.
#[derive(Debug, Clone, Default)]
pub struct Presenter {
    /// Presenting.
    pub on: bool,
    /// The left panel is shown (collapsed by default when presenting).
    pub controls: bool,
    /// The zoom the window had before presenting (restored after).
    pub zoom_before: Option<f32>,
    /// The window size in pixels the zoom was last set for.
    pub zoom_pixels: Option<egui::Vec2>,
    /// The maximised view before presenting (restored after, without a deck).
    pub maximised_before: Option<Option<String>>,
}

/// What the strip asks for.
#[derive(Debug, Clone, PartialEq)]
pub enum StripAction {
    /// Step the deck (or the views) by this many.
    Step(i32),
    /// Show this view.
    View(&'static str),
    /// Show or hide the left panel.
    ToggleControls,
    /// Leave presentation mode.
    Exit,
}

/// The visuals of `theme`, with presentation mode's higher contrast: a
/// black (or white) ground, white (or black) text and firmer outlines, so
/// that a washed-out projector still separates text from background.
pub fn visuals(theme: Theme, presenting: bool) -> egui::Visuals {
    let mut v = match theme {
        Theme::Dark => egui::Visuals::dark(),
        Theme::Light => egui::Visuals::light(),
    };
    if presenting {
        let (ground, ink, weak, line) = match theme {
            Theme::Dark => (
                Color32::BLACK,
                Color32::WHITE,
                Color32::from_gray(200),
                Color32::from_gray(170),
            ),
            Theme::Light => (
                Color32::WHITE,
                Color32::BLACK,
                Color32::from_gray(50),
                Color32::from_gray(60),
            ),
        };
        v.panel_fill = ground;
        v.window_fill = ground;
        v.extreme_bg_color = ground;
        v.faint_bg_color = ground;
        v.override_text_color = Some(ink);
        // Weak text (notes, units) a little lighter than the text, not
        // faded into the ground.
        v.weak_text_color = Some(weak);
        v.widgets.noninteractive.bg_stroke = egui::Stroke::new(1.0, line);
        v.widgets.noninteractive.fg_stroke = egui::Stroke::new(1.0, ink);
    }
    v
}

/// The band at the top: the slide's title and caption (large), and where
/// in the deck it is.
pub fn top_band(ui: &mut Ui, title: &str, caption: &str, position: Option<(usize, usize)>) {
    let frame =
        egui::Frame::side_top_panel(ui.style()).inner_margin(egui::Margin::symmetric(12, 6));
    egui::Panel::top("bv presentation band")
        .frame(frame)
        .resizable(false)
        .show(ui, |ui| {
            ui.horizontal(|ui| {
                ui.label(RichText::new(title).size(TITLE_PT).strong());
                if let Some((i, n)) = position {
                    ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                        ui.label(RichText::new(format!("{} / {n}", i + 1)).size(CAPTION_PT));
                    });
                }
            });
            if !caption.trim().is_empty() {
                ui.label(RichText::new(caption).size(CAPTION_PT));
            }
        });
}

/// A view's short name for the strip ("lit sphere").
fn short_name(id: &str) -> String {
    id.replace('_', " ")
}

/// The strip at the bottom: step buttons (with a deck), the views by name
/// (click one to show it), the panel toggle and the way out.
pub fn bottom_strip(ui: &mut Ui, shown: &str, deck: bool, controls: bool) -> Vec<StripAction> {
    let mut out = Vec::new();
    let frame = egui::Frame::side_top_panel(ui.style()).inner_margin(egui::Margin::symmetric(8, 3));
    egui::Panel::bottom("bv presentation strip")
        .frame(frame)
        .resizable(false)
        .show(ui, |ui| {
            ui.horizontal(|ui| {
                let t = |s: &str| RichText::new(s).size(STRIP_PT);
                let (back, forward) = if deck {
                    ("Previous scene", "Next scene")
                } else {
                    ("Previous view", "Next view")
                };
                if ui.button(t("«")).on_hover_text(back).clicked() {
                    out.push(StripAction::Step(-1));
                }
                if ui.button(t("»")).on_hover_text(forward).clicked() {
                    out.push(StripAction::Step(1));
                }
                // The presenter's controls stay at the right edge; the view
                // names take the width between.
                ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                    if ui
                        .button(t("exit"))
                        .on_hover_text("Leave presentation mode (F5 or Esc)")
                        .clicked()
                    {
                        out.push(StripAction::Exit);
                    }
                    let label = if controls {
                        "hide controls"
                    } else {
                        "controls"
                    };
                    if ui
                        .selectable_label(controls, t(label))
                        .on_hover_text("Show the BRDFs and parameters to edit the scene live")
                        .clicked()
                    {
                        out.push(StripAction::ToggleControls);
                    }
                    ui.separator();
                    ui.with_layout(egui::Layout::left_to_right(egui::Align::Center), |ui| {
                        ui.separator();
                        // Wrapped onto a second row when there are more
                        // views than fit: every name stays one click away.
                        ui.horizontal_wrapped(|ui| {
                            for e in REGISTRY.iter() {
                                if ui
                                    .selectable_label(e.id == shown, t(&short_name(e.id)))
                                    .on_hover_text(e.title)
                                    .clicked()
                                {
                                    out.push(StripAction::View(e.id));
                                }
                            }
                        });
                    });
                });
            });
        });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn presentation_visuals_are_black_on_white_or_white_on_black() {
        let d = visuals(Theme::Dark, true);
        assert_eq!(d.panel_fill, Color32::BLACK);
        assert_eq!(d.text_color(), Color32::WHITE);
        let l = visuals(Theme::Light, true);
        assert_eq!(l.panel_fill, Color32::WHITE);
        assert_eq!(l.text_color(), Color32::BLACK);
        // Outside presentation mode: egui's own themes.
        assert_eq!(visuals(Theme::Dark, false), egui::Visuals::dark());
        assert_eq!(visuals(Theme::Light, false), egui::Visuals::light());
    }
}
