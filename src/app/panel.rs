//! The left panel: the list of loaded BRDFs (colour, visible, solo, remove,
//! add, property badges), the preset browser, the light direction (sliders and a hemisphere to drag on) and the
//! selected BRDF's parameters, generated from its model's declaration.

use crate::session::command::Command;
use crate::session::runtime::Runtime;
use crate::session::state::{AppState, Display, Incident};
use crate::views;
use crate::widgets::params_ui::{self, Edit};
use eframe::egui::{
    self, Align2, Color32, FontId, RichText, Role, Sense, Stroke, Ui, Vec2, WidgetInfo,
};

fn labelled(r: &egui::Response, kind: Role, label: String) {
    r.widget_info(move || WidgetInfo::labeled(kind, true, &label));
}

/// The list of loaded BRDFs and the "Add BRDF" menu.
pub fn brdf_list(ui: &mut Ui, state: &AppState, runtime: &Runtime, out: &mut Vec<Command>) {
    ui.horizontal(|ui| {
        ui.heading("BRDFs");
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
            ui.menu_button("Add BRDF", |ui| {
                for m in bv_core::catalogue().iter() {
                    let r = ui.button(m.name).on_hover_text(m.summary);
                    labelled(&r, Role::Button, format!("Add {}", m.name));
                    if r.clicked() {
                        out.push(Command::AddBrdf(m.id.to_string()));
                        ui.close();
                    }
                }
            })
            .response
            .on_hover_text("Add any model of the catalogue");
            super::measured_ui::load_button(ui, out);
        });
    });
    if state.brdfs.is_empty() {
        ui.weak("Nothing loaded: use “Add BRDF”.");
    }
    for e in &state.brdfs {
        let name = crate::session::naming::display_name(state, e);
        let selected = state.selected == Some(e.id);
        ui.horizontal(|ui| {
            let mut c = e.color;
            let r = egui::color_picker::color_edit_button_srgb(ui, &mut c);
            labelled(&r, Role::ColorWell, format!("Colour of {name}"));
            if c != e.color {
                out.push(Command::SetColor(e.id, c));
            }
            let mut v = e.visible;
            let r = ui.checkbox(&mut v, "").on_hover_text("Show or hide");
            let label = format!("Show {name}");
            r.widget_info(|| WidgetInfo::selected(Role::CheckBox, true, v, &label));
            if v != e.visible {
                out.push(Command::SetVisible(e.id, v));
            }
            // Long names (presets, files) are shortened so that "solo" and
            // "remove" keep their place; the full name is in the hover text.
            const LIST_CHARS: usize = 22;
            let shown = if name.chars().count() > LIST_CHARS {
                let head: String = name.chars().take(LIST_CHARS - 1).collect();
                format!("{}…", head.trim_end())
            } else {
                name.clone()
            };
            let mut text = RichText::new(shown);
            if !state.is_drawn(e) {
                text = text.weak();
            }
            let failing = |b: &crate::session::runtime::Built| {
                b.error.is_some() || b.brdf.as_ref().is_some_and(|f| f.health().failed > 0)
            };
            if runtime.get(e.id).is_some_and(failing) {
                text = text.color(ui.visuals().error_fg_color);
            }
            if ui
                .selectable_label(selected, text)
                .on_hover_text(format!("{name}: show its parameters"))
                .clicked()
            {
                out.push(Command::Select(e.id));
            }
            ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
                let r = ui
                    .small_button("remove")
                    .on_hover_text("Remove from the list");
                labelled(&r, Role::Button, format!("Remove {name}"));
                if r.clicked() {
                    out.push(Command::RemoveBrdf(e.id));
                }
                let solo = state.solo == Some(e.id);
                let r = ui
                    .selectable_label(solo, "solo")
                    .on_hover_text("Show only this one");
                labelled(&r, Role::Button, format!("Solo {name}"));
                if r.clicked() {
                    out.push(Command::ToggleSolo(e.id));
                }
            });
        });
        super::badges::row(ui, &name, e.id, runtime);
    }
    super::badges::evidence_window(ui.ctx(), state);
    super::presets_ui::section(ui, out);
}

/// θi and φi sliders and the hemisphere widget.
pub fn light_ui(ui: &mut Ui, state: &AppState, runtime: &Runtime, out: &mut Vec<Command>) {
    ui.heading("Light");
    let inc = state.incident;
    let mut t = inc.theta_deg;
    let mut p = inc.phi_deg;
    // The slider crosses the horizon only where light below the surface
    // means something: a shown model transmits (or a scene put the light
    // there). For reflection-only models it keeps its 0–89.5° range, so its
    // whole length still moves a light they reflect.
    let transmits = state.brdfs.iter().filter(|e| e.visible).any(|e| {
        runtime
            .get(e.id)
            .and_then(|b| b.brdf.as_ref())
            .is_some_and(|b| b.transmits())
    });
    ui.horizontal(|ui| {
        ui.vertical(|ui| {
            ui.spacing_mut().slider_width = 110.0;
            let max_t = if transmits || inc.below() {
                Incident::MAX_THETA_DEG
            } else {
                Incident::MAX_ABOVE_DEG
            };
            ui.horizontal(|ui| {
                let row = params_ui::slider_row(
                    ui,
                    egui::Id::unique("bv light theta"),
                    &mut t,
                    0.0..=max_t,
                    0.0..=max_t,
                    false,
                    "°",
                    "θi",
                );
                if row.reset {
                    t = Incident::default().theta_deg;
                }
                row.track.on_hover_text(
                    "Polar angle of the light from the normal; beyond 90° the light is \
                     below the surface (for a model that transmits)",
                );
            });
            ui.horizontal(|ui| {
                let row = params_ui::slider_row(
                    ui,
                    egui::Id::unique("bv light phi"),
                    &mut p,
                    -180.0..=180.0,
                    -180.0..=180.0,
                    false,
                    "°",
                    "φi",
                );
                if row.reset {
                    p = Incident::default().phi_deg;
                }
                row.track
                    .on_hover_text("Azimuth of the light from the tangent t towards b");
            });
            ui.weak("or drag the light on the disc");
        });
        hemisphere_widget(ui, inc, state.camera.yaw_deg, out);
    });
    if t != inc.theta_deg || p != inc.phi_deg {
        out.push(Command::SetIncident(Incident {
            theta_deg: t,
            phi_deg: p,
        }));
    }
    turn_ui(ui, state, out);
}

/// The surface turned about its normal: the lecture's test of isotropy
/// ("turn the object: does the shading change?").
fn turn_ui(ui: &mut Ui, state: &AppState, out: &mut Vec<Command>) {
    let mut turn = state.display.turn_deg;
    ui.horizontal(|ui| {
        ui.spacing_mut().slider_width = 110.0;
        let row = params_ui::slider_row(
            ui,
            egui::Id::unique("bv surface turn"),
            &mut turn,
            -180.0..=180.0,
            -180.0..=180.0,
            false,
            "°",
            "turn surface",
        );
        if row.reset {
            turn = 0.0;
        }
        row.track.on_hover_text(
            "Turn the surface about its normal (its tangent frame): an anisotropic \
             highlight turns with it, an isotropic one stays",
        );
    });
    if turn != state.display.turn_deg {
        out.push(Command::SetDisplay(Display {
            turn_deg: turn,
            ..state.display
        }));
    }
}

/// Size of the hemisphere widget.
pub const HEMISPHERE_SIZE: f32 = 116.0;

/// The hemisphere seen from above (azimuthal equidistant: the distance from
/// the centre is θ), with the light as a dot; drag or click to move it. It is
/// turned like the lobe view's camera (`yaw_deg`), so that left and right on
/// the disc are left and right in the 3D view.
pub fn hemisphere_widget(
    ui: &mut Ui,
    inc: Incident,
    yaw_deg: f32,
    out: &mut Vec<Command>,
) -> egui::Response {
    let (rect, response) =
        ui.allocate_exact_size(Vec2::splat(HEMISPHERE_SIZE), Sense::click_and_drag());
    labelled(&response, Role::Slider, "Light direction".to_string());
    let dark = ui.visuals().dark_mode;
    let c = rect.center();
    let radius = rect.width() * 0.5 - 12.0;
    // Screen right is the camera's right vector on the ground, screen down
    // points towards the eye (see `views::camera`).
    let yaw = yaw_deg.to_radians();
    let right = Vec2::new(-yaw.sin(), yaw.cos());
    let toward = Vec2::new(yaw.cos(), yaw.sin());
    let ground_to_screen = |g: Vec2| Vec2::new(g.dot(right), g.dot(toward));
    // A light below the surface (issue 33) is drawn where it shows through
    // the disc, at 180° − θ from the centre (the downward normal), and a
    // drag keeps it on its side; the θ slider crosses the horizon.
    let below = inc.below();
    let disc_theta = |theta_deg: f64| {
        if below { 180.0 - theta_deg } else { theta_deg }
    };
    let to_screen = |theta_deg: f64, phi_deg: f64| {
        let r = (disc_theta(theta_deg) / 90.0) as f32 * radius;
        let a = phi_deg.to_radians() as f32;
        c + ground_to_screen(Vec2::new(r * a.cos(), r * a.sin()))
    };
    if (response.dragged() || response.clicked())
        && let Some(pos) = response.interact_pointer_pos()
    {
        let d = pos - c;
        let g = right * d.x + toward * d.y;
        let theta = disc_theta((d.length() / radius * 90.0).min(90.0) as f64);
        let phi = g.y.atan2(g.x).to_degrees() as f64;
        let new = Incident {
            theta_deg: theta,
            phi_deg: phi,
        }
        .clamped();
        if new != inc {
            out.push(Command::SetIncident(new));
        }
    }
    let painter = ui.painter_at(rect.expand(2.0));
    let visuals = ui.visuals();
    let grid = views::grid_color(dark);
    let text = visuals.text_color();
    painter.circle_filled(c, radius, visuals.extreme_bg_color);
    for deg in [30.0f32, 60.0] {
        painter.circle_stroke(c, radius * deg / 90.0, Stroke::new(1.0, grid));
    }
    painter.circle_stroke(
        c,
        radius,
        Stroke::new(1.5, visuals.widgets.noninteractive.fg_stroke.color),
    );
    let tx = ground_to_screen(Vec2::X);
    let by = ground_to_screen(Vec2::Y);
    painter.line_segment([c - tx * radius, c + tx * radius], Stroke::new(1.0, grid));
    painter.line_segment([c - by * radius, c + by * radius], Stroke::new(1.0, grid));
    let font = FontId::proportional(11.0);
    painter.text(
        c + tx * (radius + 7.0),
        Align2::CENTER_CENTER,
        "t",
        font.clone(),
        text,
    );
    painter.text(
        c + by * (radius + 7.0),
        Align2::CENTER_CENTER,
        "b",
        font,
        text,
    );
    let light = views::light_color(dark);
    let p = to_screen(inc.theta_deg, inc.phi_deg);
    // The mirror direction is opposite in azimuth.
    let m = to_screen(inc.theta_deg, inc.phi_deg + 180.0);
    painter.circle_stroke(m, 4.0, Stroke::new(1.5, views::mirror_color(dark)));
    painter.line_segment([c, p], Stroke::new(1.5, light));
    let r_dot = if response.hovered() || response.dragged() {
        7.0
    } else {
        6.0
    };
    if below {
        // Hollow: seen through the surface, from below.
        painter.circle_stroke(p, r_dot, Stroke::new(2.0, light));
        painter.text(
            rect.left_top() + Vec2::new(2.0, 2.0),
            Align2::LEFT_TOP,
            "below",
            FontId::proportional(11.0),
            light,
        );
    } else {
        painter.circle_filled(p, r_dot, light);
        painter.circle_stroke(p, 6.0, Stroke::new(1.0, Color32::BLACK.gamma_multiply(0.6)));
    }
    response.on_hover_text(if below {
        "The light is below the surface (hollow dot, seen through it): drag to move it \
         there; the centre is the downward normal, the rim the horizon. The θi slider \
         brings it back above."
    } else {
        "Drag to move the light: the centre is the normal, the rim the horizon"
    })
}

/// The selected BRDF's description and parameter widgets.
pub fn params_section(ui: &mut Ui, state: &AppState, runtime: &Runtime, out: &mut Vec<Command>) {
    let Some(e) = state.selected_entry() else {
        ui.weak("Select a BRDF to edit its parameters.");
        return;
    };
    // A spec holds its model: no lookup by id, which cannot fail.
    let info = e.spec.model();
    let name = crate::session::naming::display_name(state, e);
    ui.horizontal(|ui| {
        let [r, g, b] = e.color;
        let (swatch, _) = ui.allocate_exact_size(Vec2::splat(14.0), Sense::hover());
        ui.painter()
            .rect_filled(swatch, 2.0, Color32::from_rgb(r, g, b));
        ui.heading(&name);
        ui.with_layout(egui::Layout::right_to_left(egui::Align::Center), |ui| {
            let r = ui
                .small_button("reset all")
                .on_hover_text("All parameters to their defaults");
            labelled(&r, Role::Button, "Reset all parameters".to_string());
            if r.clicked() {
                out.push(Command::ResetAllParams(e.id));
            }
        });
    });
    // The row's name and model: a lecturer names BRDFs for legends and
    // figures, and switches models keeping the parameters both declare.
    ui.horizontal(|ui| {
        ui.label("name");
        let key = egui::Id::unique(("bv rename", e.id));
        let mut text: String = ui
            .data(|d| d.get_temp::<String>(key))
            .unwrap_or_else(|| e.name.clone().unwrap_or_default());
        let r = ui.add(
            egui::TextEdit::singleline(&mut text)
                .hint_text(info.name)
                .desired_width(120.0),
        );
        labelled(&r, Role::TextInput, format!("Name of {name}"));
        if r.changed() {
            ui.data_mut(|d| d.insert_temp(key, text.clone()));
        }
        if r.lost_focus() {
            ui.data_mut(|d| d.remove::<String>(key));
            if Some(text.trim()) != e.name.as_deref() {
                out.push(Command::Rename(e.id, Some(text)));
            }
        }
        egui::ComboBox::from_id_salt(("bv model of", e.id))
            .selected_text(info.name)
            .show_ui(ui, |ui| {
                for m in bv_core::catalogue().iter() {
                    let r = ui
                        .selectable_label(m.id == info.id, m.name)
                        .on_hover_text(m.summary);
                    if r.clicked() && m.id != info.id {
                        out.push(Command::ChangeModel(e.id, m.id.to_string()));
                    }
                }
            })
            .response
            .on_hover_text("Change the model, keeping the parameters both models declare");
    });
    ui.label(RichText::new(info.summary).small());
    ui.label(RichText::new(info.citation).small().weak());
    if let Some(err) = runtime.get(e.id).and_then(|b| b.error.as_ref()) {
        ui.colored_label(ui.visuals().error_fg_color, err);
    }
    // Evaluations that failed or were not finite read as 0 in the views:
    // say so beside the model, with the first reason.
    if let Some(brdf) = runtime.get(e.id).and_then(|b| b.brdf.as_ref()) {
        let health = brdf.health();
        if let Some(err) = health.failure(brdf.id()) {
            ui.colored_label(
                ui.visuals().error_fg_color,
                format!("{err} (the views show them as 0)"),
            );
        }
        if health.non_finite > 0 {
            ui.colored_label(
                ui.visuals().warn_fg_color,
                format!(
                    "{} evaluation{} returned NaN or infinity (the views show them as 0)",
                    health.non_finite,
                    if health.non_finite == 1 { "" } else { "s" }
                ),
            );
        }
    }
    ui.add_space(4.0);
    let edits = params_ui::params_ui(
        ui,
        egui::Id::unique(("bv params", e.id)),
        info.params,
        e.spec.params(),
    );
    for edit in edits {
        out.push(match edit {
            // A file is read in the background first; a file the reader
            // refuses leaves the BRDF as it was (see `loader`).
            Edit::Set(param, bv_core::ParamValue::Text(path))
                if crate::session::command::path_param(&e.spec) == Some(param.as_str())
                    && !path.trim().is_empty() =>
            {
                Command::OpenFile {
                    path,
                    into: Some(e.id),
                }
            }
            Edit::Set(param, value) => Command::SetParam {
                brdf: e.id,
                param,
                value,
            },
            Edit::Reset(param) => Command::ResetParam { brdf: e.id, param },
        });
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::ModelSpec;

    #[test]
    fn duplicate_models_are_numbered() {
        let mut s = AppState::default();
        let a = s.add(ModelSpec::new("lambert").unwrap());
        let b = s.add(ModelSpec::new("lambert").unwrap());
        assert_eq!(
            crate::session::naming::display_name(&s, s.entry(a).unwrap()),
            "Lambert"
        );
        assert_eq!(
            crate::session::naming::display_name(&s, s.entry(b).unwrap()),
            "Lambert 2"
        );
        let mut spec = ModelSpec::new("merl").unwrap();
        spec.set_str("path", "/data/gold-paint.binary").unwrap();
        let m = s.add(spec);
        assert_eq!(
            crate::session::naming::display_name(&s, s.entry(m).unwrap()),
            "gold-paint (MERL)"
        );
        let fresh = s.add(ModelSpec::new("merl").unwrap());
        assert_eq!(
            crate::session::naming::display_name(&s, s.entry(fresh).unwrap()),
            "MERL measured"
        );
    }
}
