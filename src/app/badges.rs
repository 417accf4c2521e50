//! The property badges of the panel: for every loaded BRDF, whether it is
//! reciprocal, energy-conserving, positive and isotropic, each with the
//! number behind the verdict; clicking a badge opens the numbers behind it.
//! The reports and their words are [`crate::derive::properties`]': a
//! preview first (marked "…"), then `bv check`'s own numbers.

use crate::derive::properties::{self, Badge, Property, Stage, badge, evidence};
use crate::session::runtime::Runtime;
use crate::session::state::AppState;
use eframe::egui::{self, Color32, RichText, Role, Ui, WidgetInfo};

/// One badge: its word, a painted tick or cross (egui's default fonts have
/// no check-mark glyph), and the number; clickable.
fn badge_widget(ui: &mut Ui, b: &Badge, color: Color32, provisional: bool) -> egui::Response {
    let font = egui::TextStyle::Small.resolve(ui.style());
    let word = b.property.word();
    let rest = b
        .text
        .strip_prefix(word)
        .map(|t| t.trim_start_matches([' ', '✓', '✗']))
        .unwrap_or(&b.text);
    let rest = if provisional {
        format!("{rest} …")
    } else {
        rest.to_string()
    };
    let g1 = ui
        .painter()
        .layout_no_wrap(word.to_string(), font.clone(), color);
    let g2 = ui.painter().layout_no_wrap(rest, font, color);
    let h = g1.size().y.max(g2.size().y);
    let mark_w = h;
    let gap = 3.0;
    let size = egui::vec2(g1.size().x + gap + mark_w + gap + g2.size().x, h);
    let (rect, r) = ui.allocate_exact_size(size, egui::Sense::click());
    if ui.is_rect_visible(rect) {
        let p = ui.painter();
        if r.hovered() {
            p.rect_filled(
                rect.expand(1.0),
                2.0,
                ui.visuals().widgets.hovered.weak_bg_fill,
            );
        }
        p.galley(rect.left_top(), g1.clone(), color);
        let m = egui::Rect::from_min_size(
            egui::pos2(rect.left() + g1.size().x + gap, rect.top()),
            egui::vec2(mark_w, h),
        )
        .shrink(h * 0.2);
        let s = egui::Stroke::new(1.6, color);
        if b.ok {
            p.line_segment(
                [
                    m.left_center(),
                    egui::pos2(m.left() + m.width() * 0.4, m.bottom()),
                ],
                s,
            );
            p.line_segment(
                [
                    egui::pos2(m.left() + m.width() * 0.4, m.bottom()),
                    m.right_top(),
                ],
                s,
            );
        } else {
            p.line_segment([m.left_top(), m.right_bottom()], s);
            p.line_segment([m.left_bottom(), m.right_top()], s);
        }
        p.galley(egui::pos2(m.right() + h * 0.2 + gap, rect.top()), g2, color);
    }
    r
}

/// Which badge's evidence window is open: (BRDF id, property).
fn open_id() -> egui::Id {
    egui::Id::unique("bv badge evidence")
}

/// The badge row of BRDF `id` (named `name` for screen readers), under its
/// line in the BRDF list.
pub fn row(ui: &mut Ui, name: &str, id: u64, runtime: &Runtime) {
    let Some(built) = runtime.get(id) else {
        return;
    };
    if built.brdf.is_none() {
        return;
    }
    let got = properties::report(&crate::views::waker(ui.ctx()), id, built);
    let (good, bad) = if ui.visuals().dark_mode {
        (
            Color32::from_rgb(110, 200, 120),
            Color32::from_rgb(255, 120, 100),
        )
    } else {
        (
            Color32::from_rgb(20, 120, 40),
            Color32::from_rgb(190, 40, 30),
        )
    };
    // Two rows of two, whether computed or not: the panel below must not
    // jump when the results arrive (a slider under the pointer would move).
    ui.horizontal(|ui| {
        ui.add_space(18.0);
        egui::Grid::new(("bv badges", id))
            .num_columns(2)
            .spacing([10.0, 1.0])
            .show(ui, |ui| {
                for (k, p) in Property::ALL.into_iter().enumerate() {
                    match &got {
                        None => {
                            let r = ui
                                .label(RichText::new(format!("{} …", p.word())).small().weak())
                                .on_hover_text("computing (a preview: bv check with fewer pairs)");
                            let label = format!("{name}: {} …", p.word());
                            r.widget_info(move || WidgetInfo::labeled(Role::Label, true, &label));
                        }
                        Some(shown) => {
                            let b = badge(&shown.report, p);
                            let color = if b.ok { good } else { bad };
                            // A preview or an older build's report: "…"
                            // until bv check's own run of this build is in
                            // (a preview that stays, for a model too slow
                            // for bv check, says why on hover).
                            let provisional = shown.stale
                                || (shown.stage == Stage::Preview && shown.no_check.is_none());
                            let hover = match (&shown.no_check, shown.stage) {
                                (Some(why), _) => format!("preview only: {why}"),
                                (None, Stage::Preview) => {
                                    "preview; bv check's own numbers follow".to_string()
                                }
                                (None, Stage::Check) => "Show the numbers behind it".to_string(),
                            };
                            let r = badge_widget(ui, &b, color, provisional).on_hover_text(hover);
                            let label = format!(
                                "{name}: {}{}",
                                b.text,
                                if provisional { " …" } else { "" }
                            );
                            r.widget_info(move || WidgetInfo::labeled(Role::Button, true, &label));
                            if r.clicked() {
                                ui.ctx()
                                    .data_mut(|d| d.insert_temp(open_id(), Some((id, p))));
                            }
                        }
                    }
                    if k % 2 == 1 {
                        ui.end_row();
                    }
                }
            });
    });
}

/// The evidence window of the badge last clicked, while it is open.
pub fn evidence_window(ctx: &egui::Context, state: &AppState) {
    let Some((id, property)) = ctx
        .data(|d| d.get_temp::<Option<(u64, Property)>>(open_id()))
        .flatten()
    else {
        return;
    };
    let Some(entry) = state.entry(id) else {
        ctx.data_mut(|d| d.remove::<Option<(u64, Property)>>(open_id()));
        return;
    };
    let name = crate::session::naming::display_name(state, entry);
    let shown = properties::latest(id);
    let mut open = true;
    egui::Window::new(format!("{name}: {}", property.word()))
        .id(egui::Id::unique("bv badge evidence window"))
        .open(&mut open)
        .resizable(false)
        .collapsible(false)
        .default_width(380.0)
        .show(ctx, |ui| match &shown {
            Some(shown) => {
                let b = badge(&shown.report, property);
                let verdict = if b.ok { "holds" } else { "violated" };
                ui.label(RichText::new(format!("{}: {verdict}", property.word())).strong());
                for line in evidence(&shown.report, property) {
                    ui.label(RichText::new(line).small());
                }
                ui.label(RichText::new(shown.stage.describe()).small().weak());
                if let Some(why) = &shown.no_check {
                    ui.label(RichText::new(why).small().weak());
                }
            }
            None => {
                ui.weak("computing…");
            }
        });
    if !open {
        ctx.data_mut(|d| d.remove::<Option<(u64, Property)>>(open_id()));
    }
}
