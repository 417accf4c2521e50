//! The property badges of the panel: for every loaded BRDF, whether it is
//! reciprocal, energy-conserving, positive and isotropic, each with the
//! number behind the verdict; clicking a badge opens the numbers behind it.
//! The reports and their words are [`crate::derive::properties`]'.

use crate::derive::properties::{self, Badge, Property, badge, evidence};
use crate::session::runtime::Runtime;
use crate::session::state::AppState;
use eframe::egui::{self, Color32, RichText, Role, Ui, WidgetInfo};

/// One badge: its word, a painted tick or cross (egui's default fonts have
/// no check-mark glyph), and the number; clickable.
fn badge_widget(ui: &mut Ui, b: &Badge, color: Color32, stale: bool) -> egui::Response {
    let font = egui::TextStyle::Small.resolve(ui.style());
    let word = b.property.word();
    let rest = b
        .text
        .strip_prefix(word)
        .map(|t| t.trim_start_matches([' ', '✓', '✗']))
        .unwrap_or(&b.text);
    let rest = if stale {
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
                                .on_hover_text("computing (bv check with fewer pairs)");
                            let label = format!("{name}: {} …", p.word());
                            r.widget_info(move || WidgetInfo::labeled(Role::Label, true, &label));
                        }
                        Some((report, stale)) => {
                            let b = badge(report, p);
                            let color = if b.ok { good } else { bad };
                            let r = badge_widget(ui, &b, color, *stale)
                                .on_hover_text("Show the numbers behind it");
                            let label = format!("{name}: {}", b.text);
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
    let report = properties::slots().latest(id).map(|d| d.value.clone());
    let mut open = true;
    egui::Window::new(format!("{name}: {}", property.word()))
        .id(egui::Id::unique("bv badge evidence window"))
        .open(&mut open)
        .resizable(false)
        .collapsible(false)
        .default_width(380.0)
        .show(ctx, |ui| match &report {
            Some(r) => {
                let b = badge(r, property);
                let verdict = if b.ok { "holds" } else { "violated" };
                ui.label(RichText::new(format!("{}: {verdict}", property.word())).strong());
                for line in evidence(r, property) {
                    ui.label(RichText::new(line).small());
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
