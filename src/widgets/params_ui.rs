//! Parameter widgets generated from a model's own declaration
//! ([`bv_core::ParamDecl`]): no model has UI code of its own. Floats become
//! sliders (logarithmic where declared, with units), colours a level slider, a
//! picker and per-channel fields, choices combo boxes, flags check boxes, lists
//! (Lafortune lobes) and mix components nested groups. A parameter whose
//! declaration says it does not apply to the current choices is not shown.
//! Double-clicking a slider
//! or pressing its "reset" button resets the value to its declared default.
//!
//! Numbers are typed into [`number_field`]s: the text is the user's while the
//! field has the keyboard (nothing is parsed, clamped or applied mid-typing),
//! and it is committed on Enter or when the field loses focus, if it is a
//! number in the accepted range. An entry that is not shows in red with the
//! range beside it; Escape puts the value back.
//!
//! Widgets edit a copy of a parameter's value; the caller turns a changed copy
//! into a command, which the core validates before it is applied.

use bv_core::params::{Component, FloatSpec};
use bv_core::{ModelSpec, ParamDecl, ParamKind, ParamValue, Params};
use eframe::egui::{
    self, Id, Key, Response, RichText, Role, Sense, Slider, SliderClamping, Ui, WidgetInfo,
};
use std::ops::RangeInclusive;

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
        let Ok(current) = params.get(decl.id) else {
            continue;
        };
        // A parameter that does not matter under the current choices (k of
        // a dielectric) is hidden; its value is kept for when it matters.
        if !decl.applies_to(params) {
            continue;
        }
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

/// Width of a number field.
const FIELD_WIDTH: f32 = 58.0;

/// Formats a value for a number field: up to five significant digits, no
/// trailing zeros (`0.3`, `0.001`, `45`, `1.5e-5`).
pub fn format_number(v: f64) -> String {
    if v == 0.0 || !v.is_finite() {
        return if v.is_finite() {
            "0".into()
        } else {
            v.to_string()
        };
    }
    let a = v.abs();
    if !(1e-4..1e6).contains(&a) {
        let s = format!("{v:.4e}");
        let (m, e) = s.split_once('e').unwrap_or((&s, "0"));
        let m = m.trim_end_matches('0').trim_end_matches('.');
        return format!("{m}e{e}");
    }
    let digits = (4 - a.log10().floor() as i32).clamp(0, 9) as usize;
    let s = format!("{v:.digits$}");
    if s.contains('.') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// Reads a typed number: a decimal point or comma, an exponent, spaces
/// around; `None` for anything else (and for infinities and NaN).
pub fn parse_number(text: &str) -> Option<f64> {
    let t = text.trim().replace(',', ".");
    let v: f64 = t.parse().ok()?;
    v.is_finite().then_some(v)
}

/// The text of a field being edited.
#[derive(Debug, Clone, PartialEq)]
struct Draft {
    /// What is typed.
    text: String,
    /// What the field showed when editing began (an unchanged text commits
    /// nothing, so that focusing a field never rounds its value).
    initial: String,
}

/// "0.001 … 1", the range a field accepts.
fn range_text(range: &RangeInclusive<f64>) -> String {
    format!(
        "{} … {}",
        format_number(*range.start()),
        format_number(*range.end())
    )
}

/// A number typed as text (see the module docs). `name` is what a screen
/// reader (and a test) calls it. Returns the field and the committed value,
/// once, on Enter or focus loss, when the text is a number in `range`.
pub fn number_field(
    ui: &mut Ui,
    id: Id,
    value: f64,
    range: RangeInclusive<f64>,
    name: &str,
) -> (Response, Option<f64>) {
    let edit_id = id.with("number field");
    let draft: Option<Draft> = ui.data(|d| d.get_temp(edit_id.with("draft")));
    let shown = format_number(value);
    let mut text = draft
        .as_ref()
        .map_or_else(|| shown.clone(), |d| d.text.clone());
    let accepted = parse_number(&text).filter(|v| range.contains(v));
    let invalid = draft.is_some() && accepted.is_none();
    let mut edit = egui::TextEdit::singleline(&mut text)
        .id(edit_id)
        .desired_width(FIELD_WIDTH)
        .clip_text(false);
    if invalid {
        edit = edit.text_color(ui.visuals().error_fg_color);
    }
    let r = ui.add(edit);
    let info_text = text.clone();
    r.widget_info(|| {
        let mut info = WidgetInfo::text_edit(ui.is_enabled(), &info_text, &info_text, "");
        info.label = Some(name.to_string());
        info
    });
    if r.gained_focus() {
        // Select all, so that typing replaces the value.
        let mut state = egui::TextEdit::load_state(ui.ctx(), edit_id).unwrap_or_default();
        state
            .cursor
            .set_char_range(Some(egui::text::CCursorRange::select_all_str(&text)));
        state.store(ui.ctx(), edit_id);
    }
    let draft_key = edit_id.with("draft");
    if r.has_focus()
        && ui.input(|i| {
            i.events.iter().any(|e| {
                matches!(
                    e,
                    egui::Event::Key { pressed: true, .. }
                        | egui::Event::PointerButton { pressed: true, .. }
                )
            })
        })
    {
        // Tab or a click elsewhere moves the focus at the end of this frame;
        // the field sees that it lost it (and commits) only in the next one,
        // which nothing else may ask for.
        ui.ctx().request_repaint();
    }
    let mut committed = None;
    if r.lost_focus() {
        let (enter, escape) = ui.input(|i| (i.key_pressed(Key::Enter), i.key_pressed(Key::Escape)));
        let initial = draft
            .as_ref()
            .map_or(shown.as_str(), |d| d.initial.as_str());
        let typed = text.trim() != initial.trim();
        if escape || !typed {
            ui.data_mut(|d| d.remove::<Draft>(draft_key));
        } else if let Some(v) = parse_number(&text).filter(|v| range.contains(v)) {
            ui.data_mut(|d| d.remove::<Draft>(draft_key));
            committed = Some(v);
        } else if enter {
            // Not a number in range: keep it, in red, to be fixed.
            ui.data_mut(|d| {
                d.insert_temp(
                    draft_key,
                    Draft {
                        text: text.clone(),
                        initial: initial.to_string(),
                    },
                )
            });
            r.request_focus();
        } else {
            // Clicked away from a bad entry: the value stays as it was.
            ui.data_mut(|d| d.remove::<Draft>(draft_key));
        }
    } else if r.has_focus() {
        let initial = draft.map_or(shown, |d| d.initial);
        ui.data_mut(|d| d.insert_temp(draft_key, Draft { text, initial }));
    } else if draft.is_some() {
        ui.data_mut(|d| d.remove::<Draft>(draft_key));
    }
    let r = if invalid {
        let tip = format!(
            "Not a number in {}: type one and press Enter, or Esc to keep {}",
            range_text(&range),
            format_number(value)
        );
        if r.has_focus() {
            r.show_tooltip_text(RichText::new(&tip).color(ui.visuals().error_fg_color));
            r
        } else {
            r.on_hover_text(tip)
        }
    } else {
        r.on_hover_text(format!(
            "Type a value in {}, then Enter",
            range_text(&range)
        ))
    };
    (r, committed)
}

/// What a slider row reports.
pub struct SliderRow {
    /// The slider track (for hover texts).
    pub track: Response,
    /// The track was double-clicked: reset the value.
    pub reset: bool,
}

/// A slider track over `span` (dragged), a [`number_field`] accepting `range`
/// (typed), the unit and the label. `x` changes while dragging and when a
/// typed value is committed. Double-clicking the track asks for a reset.
#[expect(clippy::too_many_arguments)]
pub fn slider_row(
    ui: &mut Ui,
    id: Id,
    x: &mut f64,
    span: RangeInclusive<f64>,
    range: RangeInclusive<f64>,
    log: bool,
    unit: &str,
    label: &str,
) -> SliderRow {
    let (lo, hi) = (*span.start(), *span.end());
    let mut slider = Slider::new(x, span)
        .logarithmic(log)
        .clamping(SliderClamping::Never)
        .show_value(false);
    if log && lo <= 0.0 {
        // A log slider needs a smallest positive value to start from.
        slider = slider.smallest_positive(hi.min(1.0) * 1e-3);
    }
    // The track senses clicks too: a slider only senses drags, and a
    // double-click is two clicks.
    let track = ui.add(slider).interact(Sense::click());
    let value = *x;
    track.widget_info(|| WidgetInfo::slider(true, value, label));
    let reset = track.double_clicked();
    let (_, typed) = number_field(ui, id, *x, range.clone(), &format!("{label} value"));
    if let Some(v) = typed {
        *x = v;
    }
    if !unit.is_empty() {
        ui.label(unit);
    }
    ui.label(label);
    *x = x.clamp(*range.start(), *range.end());
    SliderRow { track, reset }
}

/// A float slider over the declared slider span with a field for values in
/// the accepted range (which may be wider than the span).
fn float_slider(ui: &mut Ui, id: Id, s: &FloatSpec, x: &mut f64, label: &str) -> SliderRow {
    let lo = s.slider_min.max(s.min);
    let hi = s.slider_max.min(s.max).max(lo);
    if s.unit == "rad" {
        // Angles are declared (and stored, and typed on the command line)
        // in radians, as the formulas use them; people read degrees.
        let shown = x.to_degrees();
        let mut deg = shown;
        let row = slider_row(
            ui,
            id,
            &mut deg,
            lo.to_degrees()..=hi.to_degrees(),
            s.min.to_degrees()..=s.max.to_degrees(),
            s.log,
            "°",
            label,
        );
        // Written back only when the user changed it: a round trip through
        // degrees is not exact, and a value that drifts would be an edit.
        if deg != shown {
            *x = deg.to_radians().clamp(s.min, s.max);
        }
        return row;
    }
    slider_row(ui, id, x, lo..=hi, s.min..=s.max, s.log, s.unit, label)
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
                let row = float_slider(ui, id, &s, x, decl.label);
                with_doc(row.track, decl);
                out.reset |= row.reset;
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
                let levels = s.min.max(0.0)..=s.max;
                let row = slider_row(
                    ui,
                    id.with("level"),
                    &mut new_level,
                    levels.clone(),
                    levels,
                    false,
                    "",
                    decl.label,
                );
                with_doc(row.track, decl);
                out.reset |= row.reset;
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
                    // The picker hands back its colour through an f32 HSV
                    // round trip, a few ulps off the value it was given: only
                    // a real pick replaces the (f64) channels, or a typed 0.2
                    // would become 0.19999998807907104.
                    let picked = (rgba.to_array().iter())
                        .zip(before.to_array())
                        .any(|(a, b)| (a - b).abs() > 1e-5);
                    if picked {
                        c = [rgba.r() as f64, rgba.g() as f64, rgba.b() as f64];
                    }
                }
                out.reset |= reset_button(ui, decl.label, is_default);
            });
            ui.horizontal(|ui| {
                ui.add_space(4.0);
                for (k, ch) in ["R", "G", "B"].iter().enumerate() {
                    ui.label(*ch);
                    let name = format!("{} {ch}", decl.label);
                    let (_, typed) = number_field(ui, id.with(*ch), c[k], s.min..=s.max, &name);
                    if let Some(v) = typed {
                        c[k] = v;
                    }
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
                            if !f.applies_to(item) {
                                continue;
                            }
                            if let Some(v) = item.get_mut(f.id) {
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
                let name = comp.spec.model().name;
                let header = format!("{} {}: {name}", singular(decl.label), i + 1);
                egui::CollapsingHeader::new(&header)
                    .id_salt(id.with(i))
                    .default_open(true)
                    .show(ui, |ui| {
                        ui.horizontal(|ui| {
                            ui.spacing_mut().slider_width = SLIDER_WIDTH;
                            let row = float_slider(
                                ui,
                                id.with(i).with("weight"),
                                &weight,
                                &mut comp.weight,
                                "weight",
                            );
                            if row.reset {
                                comp.weight = weight.default;
                            }
                        });
                        component_model_ui(ui, id.with(i), comp, depth);
                        if depth + 1 < bv_core::params::MAX_NESTING {
                            let info = comp.spec.model();
                            for f in info.params {
                                let Ok(current) = comp.spec.params().get(f.id) else {
                                    continue;
                                };
                                if !f.applies_to(comp.spec.params()) {
                                    continue;
                                }
                                let mut v = current.clone();
                                let r = value_ui(ui, id.with(i).with(f.id), f, &mut v, depth + 1);
                                if r.reset {
                                    v = f.default_value();
                                }
                                // Through the validating setter: a value the
                                // declaration refuses leaves the component as
                                // it was.
                                if comp.spec.params().get(f.id).ok() != Some(&v) {
                                    let _ = comp.spec.set(f.id, v);
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
    let current = comp.spec.id().to_string();
    let name = bv_core::find(&current).map(|m| m.name).unwrap_or("?");
    let mut chosen = current.clone();
    egui::ComboBox::new(id.with("model"), "model")
        .selected_text(name)
        .show_ui(ui, |ui| {
            for m in bv_core::catalogue().iter() {
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
    fn numbers_format_short_and_parse_back() {
        for (v, t) in [
            (0.3, "0.3"),
            (0.001, "0.001"),
            (45.0, "45"),
            (12.5, "12.5"),
            (0.123456, "0.12346"),
            (1.5e-5, "1.5e-5"),
            (2e6, "2e6"),
            (0.0, "0"),
            (-0.25, "-0.25"),
        ] {
            assert_eq!(format_number(v), t, "{v}");
            let back = parse_number(t).unwrap();
            assert!((back - v).abs() <= 1e-4 * v.abs(), "{t} → {back}");
        }
        assert_eq!(parse_number(" 0,4 "), Some(0.4));
        assert_eq!(parse_number("1e-3"), Some(1e-3));
        assert_eq!(parse_number("0.4.00100"), None);
        assert_eq!(parse_number("inf"), None);
        assert_eq!(parse_number(""), None);
    }

    #[test]
    fn singular_labels() {
        assert_eq!(singular("lobes"), "lobe");
        assert_eq!(singular("components"), "component");
        assert_eq!(singular("albedo"), "albedo");
    }
}
