//! The panel's preset browser: a search field over the shipped material
//! presets (`bv_core::presets`), grouped by category; hovering one shows
//! where its numbers come from, clicking it adds it as a new BRDF named after
//! it.

use crate::session::command::Command;
use bv_core::presets::{self, CATEGORIES, Preset};
use eframe::egui::{self, RichText, Role, Ui, WidgetInfo};

/// The heading of a category.
fn category_title(c: &str) -> &str {
    match c {
        "conductor" => "Conductors",
        "dielectric" => "Dielectrics",
        "cook-torrance-1982" => "Cook & Torrance 1982",
        _ => "Other",
    }
}

/// The hover text of a preset: its source, notes and wavelengths.
fn hover(p: &Preset) -> String {
    let mut t = format!("{} ({})\nsource: {}", p.name, p.spec.model().name, p.source);
    if let Some(w) = p.wavelengths_nm {
        t.push_str(&format!(
            "\nr, g, b sample {} nm, {} nm, {} nm",
            w[0], w[1], w[2]
        ));
    }
    if let Some(n) = &p.notes {
        t.push('\n');
        t.push_str(n);
    }
    t
}

/// The collapsible "Presets" section.
pub fn section(ui: &mut Ui, out: &mut Vec<Command>) {
    let all = bv_core::presets::shipped_presets();
    egui::CollapsingHeader::new("Presets…")
        .id_salt("bv presets")
        .show(ui, |ui| {
            let id = egui::Id::unique("bv preset query");
            let mut query: String = ui.data(|d| d.get_temp(id)).unwrap_or_default();
            let r = ui.add(
                egui::TextEdit::singleline(&mut query)
                    .hint_text("search materials")
                    .desired_width(f32::INFINITY),
            );
            r.widget_info(|| WidgetInfo::labeled(Role::TextInput, true, "Search presets"));
            if r.changed() {
                ui.data_mut(|d| d.insert_temp(id, query.clone()));
            }
            let found = presets::search(all, query.trim());
            if found.is_empty() {
                ui.weak(format!("no preset matches “{}”", query.trim()));
            }
            for cat in CATEGORIES {
                let here: Vec<&Preset> = found
                    .iter()
                    .filter(|p| p.category == *cat)
                    .copied()
                    .collect();
                if here.is_empty() {
                    continue;
                }
                ui.label(RichText::new(category_title(cat)).strong().small());
                ui.horizontal_wrapped(|ui| {
                    for p in here {
                        // The category says "Cook & Torrance 1982" already.
                        let short = p.name.split(" (").next().unwrap_or(&p.name);
                        let r = ui.small_button(short).on_hover_text(hover(p));
                        let label = format!("Add preset {}", p.name);
                        r.widget_info(move || WidgetInfo::labeled(Role::Button, true, &label));
                        if r.clicked() {
                            out.push(Command::AddNamed {
                                name: p.name.clone(),
                                spec: p.spec.clone(),
                            });
                        }
                    }
                });
            }
        });
}
