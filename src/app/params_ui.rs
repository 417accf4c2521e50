//! Parameter widgets generated from a model's own declaration
//! ([`bv_core::ParamDecl`]): no model has UI code of its own. Floats become
//! sliders (logarithmic where declared, with units), colours a level slider, a
//! picker and per-channel fields, choices combo boxes, flags check boxes, lists
//! (Lafortune lobes) and mix components nested groups. Double-clicking a slider
//! or pressing its "reset" button resets the value to its declared default.
//!
//! Widgets edit a copy of a parameter's value; the caller turns a changed copy
//! into a command, which the core validates before it is applied.

use bv_core::params::{Component, FloatSpec};
use bv_core::{ModelSpec, ParamDecl, ParamKind, ParamValue, Params};
use eframe::egui::{self, Id, Response, RichText, Role, Slider, SliderClamping, Ui, WidgetInfo};

/// What the user did to one top-level parameter.
#[derive(Debug, Clone, PartialEq)]
pub enum Edit {
    /// Set it to this (whole, possibly nested) value.
    Set(String, ParamValue),
    /// Reset it to its declared default.
    Reset(String),
}

/// Width of a slider's track.
const SLIDER_WIDTH: f32 = 150.0;

/// Draws the widgets of `decls` over `params` and returns what changed.
pub fn params_ui(ui: &mut Ui, salt: Id, decls: &[ParamDecl], params: &Params) -> Vec<Edit> {
    let mut edits = Vec::new();
    for decl in decls {
        let Some(current) = params.0.get(decl.id) else {
            continue;
        };
        let mut value = current.clone();
        let r = value_ui(ui, salt.with(decl.id), decl, &mut value, 0);
        if r.reset {
            edits.push(Edit::Reset(decl.id.to_string()));
        } else if value != *current {
            edits.push(Edit::Set(decl.id.to_string(), value));
        }
    }
    edits
}

/// The outcome of one value widget.
#[derive(Debug, Default, Clone, Copy)]
struct ValueResponse {
    reset: bool,
}

/// A small reset button, shown enabled only when the value is not the default.
fn reset_button(ui: &mut Ui, label: &str, is_default: bool) -> bool {
    let r = ui
        .add_enabled(!is_default, egui::Button::new("reset").small())
        .on_hover_text("Reset to default (or double-click the slider)");
    let name = format!("Reset {label}");
    r.widget_info(|| WidgetInfo::labeled(Role::Button, !is_default, &name));
    r.clicked()
}

fn with_doc(r: Response, decl: &ParamDecl) -> Response {
    let range = decl.range_text();
    let unit = decl.unit();
    let unit = if unit.is_empty() {
        String::new()
    } else {
        format!(" ({unit})")
    };
    r.on_hover_text(format!("{}\n`{}`: {}{}", decl.doc, decl.id, range, unit))
}

/// A float slider over the declared slider span (typing a value outside it is
/// allowed as long as it is in the accepted range).
fn float_slider(ui: &mut Ui, s: &FloatSpec, x: &mut f64, label: &str) -> Response {
    let lo = s.slider_min.max(s.min);
    let hi = s.slider_max.min(s.max).max(lo);
    let mut slider = Slider::new(x, lo..=hi)
        .logarithmic(s.log)
        .clamping(SliderClamping::Never)
        .text(label);
    if s.log && lo <= 0.0 {
        // A log slider needs a smallest positive value to start from.
        slider = slider.smallest_positive(hi.min(1.0) * 1e-3);
    }
    if !s.unit.is_empty() {
        slider = slider.suffix(format!(" {}", s.unit));
    }
    let r = ui.add(slider);
    *x = x.clamp(s.min, s.max);
    r
}

fn value_ui(
    ui: &mut Ui,
    id: Id,
    decl: &ParamDecl,
    value: &mut ParamValue,
    depth: usize,
) -> ValueResponse {
    let mut out = ValueResponse::default();
    let is_default = *value == decl.default_value();
    match (decl.kind, value) {
        (ParamKind::Float(s), ParamValue::Float(x)) => {
            ui.horizontal(|ui| {
                ui.spacing_mut().slider_width = SLIDER_WIDTH;
                let r = with_doc(float_slider(ui, &s, x, decl.label), decl);
                if r.double_clicked() {
                    out.reset = true;
                }
                out.reset |= reset_button(ui, decl.label, is_default);
            });
        }
        (ParamKind::Color(s), v) => {
            let mut c = match v {
                ParamValue::Color(c) => *c,
                ParamValue::Float(x) => [*x; 3],
                _ => s.default,
            };
            ui.horizontal(|ui| {
                ui.spacing_mut().slider_width = SLIDER_WIDTH - 30.0;
                // The level slider scales the colour (its largest channel): one
                // drag dims or brightens it, and a grey stays grey.
                let level = c.iter().copied().fold(0.0, f64::max);
                let mut new_level = level;
                let r = ui.add(
                    Slider::new(&mut new_level, s.min.max(0.0)..=s.max)
                        .clamping(SliderClamping::Always)
                        .text(decl.label),
                );
                let r = with_doc(r, decl);
                if r.double_clicked() {
                    out.reset = true;
                }
                if new_level != level {
                    if level > 0.0 {
                        let k = new_level / level;
                        for ch in &mut c {
                            *ch = (*ch * k).clamp(s.min, s.max);
                        }
                    } else {
                        c = [new_level; 3];
                    }
                }
                if s.is_reflectance() {
                    let mut rgba = egui::Rgba::from_rgb(c[0] as f32, c[1] as f32, c[2] as f32);
                    let before = rgba;
                    let r = egui::color_picker::color_edit_button_rgba(
                        ui,
                        &mut rgba,
                        egui::color_picker::Alpha::Opaque,
                    );
                    let name = format!("{} colour", decl.label);
                    r.widget_info(|| WidgetInfo::labeled(Role::ColorWell, true, &name));
                    if rgba != before {
                        c = [rgba.r() as f64, rgba.g() as f64, rgba.b() as f64];
                    }
                }
                out.reset |= reset_button(ui, decl.label, is_default);
            });
            ui.horizontal(|ui| {
                ui.add_space(4.0);
                for (k, ch) in ["R", "G", "B"].iter().enumerate() {
                    let speed = ((s.max - s.min) / 300.0).max(1e-4);
                    let r = ui.add(
                        egui::DragValue::new(&mut c[k])
                            .range(s.min..=s.max)
                            .speed(speed)
                            .max_decimals(4)
                            .prefix(format!("{ch} ")),
                    );
                    let name = format!("{} {ch}", decl.label);
                    r.widget_info(|| WidgetInfo::labeled(Role::SpinButton, true, &name));
                }
                if !s.unit.is_empty() {
                    ui.weak(s.unit);
                }
            });
            *v = ParamValue::Color(c);
        }
        (ParamKind::Choice { options, .. }, ParamValue::Text(t)) => {
            ui.horizontal(|ui| {
                let r = egui::ComboBox::new(id, decl.label)
                    .selected_text(t.as_str())
                    .show_ui(ui, |ui| {
                        for o in options {
                            ui.selectable_value(t, o.to_string(), *o);
                        }
                    });
                with_doc(r.response, decl);
                out.reset |= reset_button(ui, decl.label, is_default);
            });
        }
        (ParamKind::Bool { .. }, ParamValue::Bool(b)) => {
            ui.horizontal(|ui| {
                with_doc(ui.checkbox(b, decl.label), decl);
                out.reset |= reset_button(ui, decl.label, is_default);
            });
        }
        (ParamKind::Path { .. }, ParamValue::Text(t)) => {
            // Edit a draft; apply on Enter or when the field loses focus, so a
            // half-typed path is not loaded at every keystroke.
            let draft_id = id.with("draft");
            let mut draft: String = ui
                .data(|d| d.get_temp(draft_id))
                .unwrap_or_else(|| t.clone());
            ui.horizontal(|ui| {
                ui.label(decl.label);
                let r = ui.add(
                    egui::TextEdit::singleline(&mut draft)
                        .desired_width(SLIDER_WIDTH)
                        .hint_text("path, or drop a file"),
                );
                let r = with_doc(r, decl);
                if r.lost_focus() {
                    *t = draft.clone();
                    ui.data_mut(|d| d.remove::<String>(draft_id));
                } else if r.has_focus() {
                    ui.data_mut(|d| d.insert_temp(draft_id, draft.clone()));
                } else {
                    ui.data_mut(|d| d.remove::<String>(draft_id));
                }
                out.reset |= reset_button(ui, decl.label, is_default);
            });
        }
        (
            ParamKind::List {
                fields,
                min_items,
                max_items,
                ..
            },
            ParamValue::List(items),
        ) => {
            ui.horizontal(|ui| {
                ui.label(RichText::new(decl.label).strong());
                ui.weak(format!("({} of {min_items}..{max_items})", items.len()));
                out.reset |= reset_button(ui, decl.label, is_default);
            });
            let mut remove = None;
            let can_remove = items.len() > min_items;
            for (i, item) in items.iter_mut().enumerate() {
                let header = format!("{} {}", singular(decl.label), i + 1);
                egui::CollapsingHeader::new(&header)
                    .id_salt(id.with(i))
                    .default_open(i == 0)
                    .show(ui, |ui| {
                        for f in fields {
                            if let Some(v) = item.0.get_mut(f.id) {
                                let r = value_ui(ui, id.with(i).with(f.id), f, v, depth + 1);
                                if r.reset {
                                    *v = f.default_value();
                                }
                            }
                        }
                        if ui
                            .add_enabled(
                                can_remove,
                                egui::Button::new(format!("Remove {header}")).small(),
                            )
                            .clicked()
                        {
                            remove = Some(i);
                        }
                    });
            }
            if let Some(i) = remove
                && items.len() > min_items
            {
                items.remove(i);
            }
            if items.len() < max_items
                && ui
                    .small_button(format!("Add {}", singular(decl.label)))
                    .clicked()
            {
                items.push(Params::defaults(fields));
            }
        }
        (
            ParamKind::Components {
                max_items, weight, ..
            },
            ParamValue::Components(comps),
        ) => {
            ui.horizontal(|ui| {
                ui.label(RichText::new(decl.label).strong());
                out.reset |= reset_button(ui, decl.label, is_default);
            });
            let mut remove = None;
            let can_remove = comps.len() > 1;
            for (i, comp) in comps.iter_mut().enumerate() {
                let name = bv_core::find(&comp.spec.model)
                    .map(|m| m.name)
                    .unwrap_or("?");
                let header = format!("{} {}: {name}", singular(decl.label), i + 1);
                egui::CollapsingHeader::new(&header)
                    .id_salt(id.with(i))
                    .default_open(true)
                    .show(ui, |ui| {
                        ui.horizontal(|ui| {
                            ui.spacing_mut().slider_width = SLIDER_WIDTH;
                            float_slider(ui, &weight, &mut comp.weight, "weight");
                        });
                        component_model_ui(ui, id.with(i), comp, depth);
                        if depth + 1 < bv_core::params::MAX_NESTING {
                            if let Ok(info) = bv_core::find(&comp.spec.model) {
                                for f in info.params {
                                    if let Some(v) = comp.spec.params.0.get_mut(f.id) {
                                        let r =
                                            value_ui(ui, id.with(i).with(f.id), f, v, depth + 1);
                                        if r.reset {
                                            *v = f.default_value();
                                        }
                                    }
                                }
                            }
                        } else {
                            ui.weak("(nested too deeply to edit here)");
                        }
                        if ui
                            .add_enabled(
                                can_remove,
                                egui::Button::new(format!("Remove {header}")).small(),
                            )
                            .clicked()
                        {
                            remove = Some(i);
                        }
                    });
            }
            if let Some(i) = remove
                && comps.len() > 1
            {
                comps.remove(i);
            }
            if comps.len() < max_items
                && ui
                    .small_button(format!("Add {}", singular(decl.label)))
                    .clicked()
                && let Some(first) = bv_core::catalogue().first()
                && let Ok(spec) = ModelSpec::new(first.id)
            {
                comps.push(Component {
                    weight: weight.default,
                    spec,
                });
            }
        }
        (_, v) => {
            // A value whose type does not match its declaration (cannot come
            // from the core's parser); show it rather than hide it.
            ui.label(format!("{}: {}", decl.label, v.to_json()));
        }
    }
    out
}

/// The model of a mix component: any catalogue model.
fn component_model_ui(ui: &mut Ui, id: Id, comp: &mut Component, _depth: usize) {
    let current = comp.spec.model.clone();
    let name = bv_core::find(&current).map(|m| m.name).unwrap_or("?");
    let mut chosen = current.clone();
    egui::ComboBox::new(id.with("model"), "model")
        .selected_text(name)
        .show_ui(ui, |ui| {
            for m in bv_core::catalogue() {
                ui.selectable_value(&mut chosen, m.id.to_string(), m.name);
            }
        });
    if chosen != current
        && let Ok(spec) = ModelSpec::new(&chosen)
    {
        comp.spec = spec;
    }
}

/// "lobes" → "lobe", "components" → "component" (labels of list items).
fn singular(label: &str) -> String {
    label.strip_suffix('s').unwrap_or(label).to_string()
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn singular_labels() {
        assert_eq!(singular("lobes"), "lobe");
        assert_eq!(singular("components"), "component");
        assert_eq!(singular("albedo"), "albedo");
    }
}
