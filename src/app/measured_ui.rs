//! The GUI of measured tables: the "Load MERL…"
//! button (its dialog is [`crate::widgets::files`]), the progress of background reads, the error dialog of a
//! refused file, and the panel section of a `merl` BRDF (its table, the
//! reader's warnings, and the relative L2 difference to another loaded BRDF,
//! e.g. the analytic model a table was tabulated from).

use crate::derive::compare::{self, COMPARE_RINGS, CompareKey};
use crate::session::command::Command;
use crate::session::loader::{self, LoadError, Loader};
use crate::session::runtime::Runtime;
use crate::session::state::{AppState, BrdfEntry};
use crate::views::sh_overlay::percent;
use crate::widgets::files::Filter;
use eframe::egui::{self, RichText, Role, Ui, WidgetInfo};

/// What the "Load MERL…" dialog lists.
pub const MERL_FILES: Filter = Filter {
    name: "MERL table (.binary)",
    extensions: &["binary"],
};

/// What the open dialog offers: measured data (MERL tables, RGL materials)
/// and user BRDF files.
pub const OPENABLE_FILES: Filter = Filter {
    name: "Measured data (.binary, .bsdf) or BRDF file (.brdf)",
    extensions: &["binary", "bsdf", "brdf"],
};

/// Progress bars of the reads in flight (nothing when idle).
pub fn progress_ui(ui: &mut Ui, loader: &Loader) {
    for job in loader.jobs() {
        let (read, total) = job.progress();
        let frac = if total > 0 {
            read as f32 / total as f32
        } else {
            0.0
        };
        ui.horizontal(|ui| {
            ui.spinner();
            ui.label(format!("Loading {}", job.name()));
        });
        let r = ui.add(
            egui::ProgressBar::new(frac)
                .desired_width(ui.available_width().min(300.0))
                .text(loader::progress_text(read, total)),
        );
        let label = format!("Loading {}", job.name());
        r.widget_info(|| WidgetInfo::labeled(Role::ProgressIndicator, true, &label));
    }
}

/// The error dialog of the first refused file; returns whether it was
/// dismissed this frame.
pub fn error_window(ctx: &egui::Context, errors: &[LoadError]) -> bool {
    let Some(e) = errors.first() else {
        return false;
    };
    let mut dismissed = false;
    egui::Window::new("Could not open the file")
        .id(egui::Id::unique("bv load error"))
        .collapsible(false)
        .resizable(false)
        .anchor(egui::Align2::CENTER_CENTER, egui::Vec2::ZERO)
        .show(ctx, |ui| {
            ui.set_max_width(460.0);
            ui.label(RichText::new(&e.path).monospace());
            ui.add_space(4.0);
            ui.colored_label(ui.visuals().error_fg_color, &e.message);
            ui.add_space(4.0);
            ui.weak("Nothing was changed: the BRDFs already loaded are as they were.");
            if errors.len() > 1 {
                ui.weak(format!(
                    "({} more files could not be opened)",
                    errors.len() - 1
                ));
            }
            ui.add_space(6.0);
            if ui.button("OK").clicked() {
                dismissed = true;
            }
        });
    dismissed
}

/// The panel section of a BRDF with a measured table: dimensions, value
/// ranges, the reader's warnings, the last load time, and the comparison
/// with another loaded BRDF.
pub fn measured_section(
    ui: &mut Ui,
    state: &AppState,
    runtime: &Runtime,
    e: &BrdfEntry,
    last_load: Option<&str>,
) {
    let Some(built) = runtime.get(e.id) else {
        return;
    };
    let Some(brdf) = built.brdf.clone() else {
        return;
    };
    let Some(data) = brdf.file_data() else {
        return;
    };
    ui.add_space(4.0);
    let tag = e
        .spec
        .model()
        .file_param()
        .map_or("File", |(_, format)| format.name());
    ui.label(RichText::new(sentence_case(tag)).strong());
    for line in data.summary() {
        ui.label(line);
    }
    let warnings = data.warnings();
    if warnings.is_empty() {
        ui.weak("no unmeasured or NaN samples");
    } else {
        for m in warnings {
            ui.colored_label(ui.visuals().warn_fg_color, format!("⚠ {m}"));
        }
    }
    if let Some(t) = last_load {
        ui.weak(t);
    }

    // Comparison with another BRDF (e.g. the analytic model it was tabulated from).
    let choice_id = egui::Id::unique(("bv compare with", e.id));
    let mut other: Option<u64> = ui.data(|m| m.get_temp::<Option<u64>>(choice_id)).flatten();
    if other.is_some_and(|o| state.entry(o).is_none()) {
        other = None;
    }
    let name_of = |id: u64| {
        state
            .entry(id)
            .map(|x| crate::session::naming::display_name(state, x))
            .unwrap_or_default()
    };
    let before = other;
    ui.horizontal(|ui| {
        ui.label("compare with");
        let r = egui::ComboBox::from_id_salt(("bv compare combo", e.id))
            .selected_text(other.map_or_else(|| "(none)".to_string(), name_of))
            .show_ui(ui, |ui| {
                ui.selectable_value(&mut other, None, "(none)");
                for b in state.brdfs.iter().filter(|b| b.id != e.id) {
                    let n = crate::session::naming::display_name(state, b);
                    ui.selectable_value(&mut other, Some(b.id), n);
                }
            })
            .response
            .on_hover_text(
                "Relative L2 difference ‖f_table − f_other‖ / ‖f_other‖ of the lobes at the \
                 current light direction, over the outgoing hemisphere",
            );
        r.widget_info(|| WidgetInfo::labeled(Role::ComboBox, true, "Compare with"));
    });
    if other != before {
        ui.data_mut(|m| m.insert_temp(choice_id, other));
    }
    let Some(o) = other else {
        return;
    };
    let Some(ob) = runtime.get(o).and_then(|b| b.brdf.clone()) else {
        ui.weak("that BRDF does not build");
        return;
    };
    let key = CompareKey {
        a: built.revision,
        b: runtime.get(o).map_or(0, |b| b.revision),
        incident: (state.incident.theta_deg, state.incident.phi_deg),
        cosine: state.display.cosine,
    };
    let waker = crate::views::waker(ui.ctx());
    let done = compare::request(&waker, e.id, key, brdf, ob, state.incident.direction());
    match done {
        Some(d) => {
            let stale = if d.key == key { "" } else { " (updating…)" };
            let text = match &d.value {
                Ok(x) => format!(
                    "relative L2 difference to {}: {}{stale}",
                    name_of(o),
                    percent(*x)
                ),
                Err(err) => err.clone(),
            };
            ui.label(RichText::new(text).strong())
                .on_hover_text(format!(
                    "At θi = {:.1}°, φi = {:.1}°, on the channel mean of {}; {COMPARE_RINGS} \
                 Gauss–Legendre rings × {} azimuths",
                    d.key.incident.0,
                    d.key.incident.1,
                    crate::views::value_label(d.key.cosine),
                    2 * COMPARE_RINGS
                ));
        }
        None => {
            ui.weak("relative L2 difference: computing…");
        }
    }
}

/// Waits until no comparison is being computed (tests).
pub fn wait_compare_idle() -> bool {
    compare::wait_idle()
}

/// The "Load MERL…" button.
pub fn load_button(ui: &mut Ui, out: &mut Vec<Command>) {
    let r = ui
        .button("Load MERL…")
        .on_hover_text("Open a measured BRDF (.binary); or drop the file on the window");
    if r.clicked() {
        out.push(Command::OpenFileDialog);
    }
}

/// "MERL table" → "MERL table", "user file" → "User file": a heading.
fn sentence_case(text: &str) -> String {
    let mut c = text.chars();
    match c.next() {
        Some(first) => first.to_uppercase().chain(c).collect(),
        None => String::new(),
    }
}
