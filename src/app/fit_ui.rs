//! The *Fit…* panel: fits a catalogue model to any BRDF of the list (a
//! measured table, a user file, another model) in the background
//! ([`crate::derive::fit`]) and adds the fitted model as a new BRDF beside
//! its target, named after the model, the metric and the error (Ngan et
//! al. 2005; Löw et al. 2012, see [`bv_core::fit::Metric`]).
//!
//! Opened with F or the top bar's *Fit…* button. The fit's key is taken when
//! *Start* is pressed; while it runs, an edit of the target's parameters
//! restarts it for the new values (the running fit is cancelled), and
//! *Cancel* stops it within one Levenberg–Marquardt step.

use crate::derive::fit::{self as fitjob, FitJob, FitKey};
use crate::session::Command;
use crate::session::naming::display_name;
use crate::session::state::AppState;
use bv_core::ModelSpec;
use bv_core::fit::{FitOptions, FitResult, Metric, default_free};
use eframe::egui::{self, RichText, Ui};

/// The panel's settings and its fit.
#[derive(Debug)]
pub struct FitPanel {
    /// Whether the panel is shown.
    pub open: bool,
    /// The BRDF fitted to (an id of the list).
    target: Option<u64>,
    /// The catalogue model fitted.
    model: &'static str,
    /// The model's fittable parameters and whether each is free.
    free: Vec<(&'static str, bool)>,
    /// The error minimised.
    metric: Metric,
    /// The fit.
    job: FitJob,
    /// The key of the fit started here, and the target's id then.
    started: Option<(FitKey, u64)>,
    /// Whether the finished fit of `started` was added to the list.
    added: bool,
    /// Why *Start* refused to start.
    refused: Option<String>,
    /// How the fits run (starts, iterations, samples; the metric is the
    /// panel's).
    pub options: FitOptions,
}

impl Default for FitPanel {
    fn default() -> Self {
        // The first model of the catalogue with something to fit (no view
        // code names a model).
        let cat = bv_core::catalogue();
        let model = cat
            .iter()
            .filter(|m| m.file_param().is_none())
            .find(|m| ModelSpec::new(m.id).is_ok_and(|s| !default_free(&s).is_empty()))
            .map_or("", |m| m.id);
        let mut p = Self {
            open: false,
            target: None,
            model,
            free: Vec::new(),
            metric: Metric::Ngan,
            job: FitJob::default(),
            started: None,
            added: false,
            refused: None,
            options: FitOptions::default(),
        };
        p.set_model(model);
        p
    }
}

/// The name of a catalogue model.
fn model_name(id: &str) -> &'static str {
    bv_core::catalogue()
        .iter()
        .find(|m| m.id == id)
        .map_or("model", |m| m.name)
}

/// The command that adds a finished fit as a BRDF: "Ward fit (ngan 0.031)".
pub fn add_command(r: &FitResult) -> Command {
    Command::AddNamed {
        name: fitjob::fitted_name(model_name(r.spec.id()), r),
        spec: r.spec.clone(),
    }
}

impl FitPanel {
    /// The panel's fit (tests wait for it).
    pub fn job(&self) -> &FitJob {
        &self.job
    }

    /// Chooses the model fitted (a catalogue id; an unknown one changes
    /// nothing); its free parameters become [`default_free`]'s.
    pub fn set_model(&mut self, id: &str) {
        let cat = bv_core::catalogue();
        let Some(id) = cat.iter().find(|m| m.id == id).map(|m| m.id) else {
            return;
        };
        self.model = id;
        self.free = ModelSpec::new(id)
            .map(|s| default_free(&s).into_iter().map(|p| (p, true)).collect())
            .unwrap_or_default();
    }

    /// The key of a fit of the current settings, or why there is none.
    fn key(&self, state: &AppState) -> Result<(FitKey, u64), String> {
        let id = self
            .target
            .or(state.selected)
            .ok_or("choose a BRDF to fit to")?;
        let target = state.entry(id).ok_or("the target BRDF was removed")?;
        let model = ModelSpec::new(self.model).map_err(|e| e.to_string())?;
        let free: Vec<String> = self
            .free
            .iter()
            .filter(|(_, on)| *on)
            .map(|(p, _)| (*p).to_string())
            .collect();
        if free.is_empty() {
            return Err("choose at least one free parameter".into());
        }
        Ok((
            FitKey {
                target: target.spec.clone(),
                model,
                free,
                metric: self.metric,
            },
            id,
        ))
    }

    /// Starts the fit of the current settings (the *Start* button).
    pub fn start(&mut self, state: &AppState, waker: &crate::derive::Waker) -> Result<(), String> {
        let (key, id) = self.key(state)?;
        self.job.start(key.clone(), self.options.clone(), waker);
        self.started = Some((key, id));
        self.added = false;
        Ok(())
    }

    /// Draws the panel when it is open, and pushes the command that adds a
    /// finished fit.
    pub fn window(&mut self, ctx: &egui::Context, state: &AppState, out: &mut Vec<Command>) {
        let waker = crate::views::waker(ctx);
        self.follow_target(state, &waker);
        self.add_finished(out);
        if !self.open {
            return;
        }
        let mut open = self.open;
        egui::Window::new("Fit…")
            .id(egui::Id::unique("bv fit panel"))
            .open(&mut open)
            .collapsible(false)
            .resizable(false)
            .default_pos(egui::pos2(380.0, 80.0))
            .show(ctx, |ui| self.contents(ui, state, &waker));
        self.open = open;
    }

    /// While a fit runs, an edit of its target restarts it for the new
    /// values (the key changed; the running fit is cancelled).
    fn follow_target(&mut self, state: &AppState, waker: &crate::derive::Waker) {
        let Some((key, id)) = &self.started else {
            return;
        };
        if !self.job.status().running {
            return;
        }
        match state.entry(*id) {
            Some(e) if e.spec != key.target => {
                let key = FitKey {
                    target: e.spec.clone(),
                    ..key.clone()
                };
                let id = *id;
                self.job.start(key.clone(), self.options.clone(), waker);
                self.started = Some((key, id));
            }
            Some(_) => {}
            None => {
                self.job.cancel();
                self.started = None;
            }
        }
    }

    /// Adds the finished fit of the key started here, once.
    fn add_finished(&mut self, out: &mut Vec<Command>) {
        let Some((key, _)) = &self.started else {
            return;
        };
        if self.added {
            return;
        }
        let st = self.job.status();
        if st.key.as_ref() != Some(key) {
            return;
        }
        if let Some(Ok(r)) = &st.result {
            out.push(add_command(r));
            self.added = true;
        }
    }

    fn contents(&mut self, ui: &mut Ui, state: &AppState, waker: &crate::derive::Waker) {
        let target = self.target.or(state.selected);
        let target_name = target
            .and_then(|id| state.entry(id))
            .map_or_else(|| "(none)".to_string(), |e| display_name(state, e));
        egui::Grid::new("bv fit grid")
            .num_columns(2)
            .spacing([12.0, 6.0])
            .show(ui, |ui| {
                ui.label("Target");
                egui::ComboBox::from_id_salt("bv fit target")
                    .selected_text(&target_name)
                    .show_ui(ui, |ui| {
                        for e in &state.brdfs {
                            let name = display_name(state, e);
                            if ui.selectable_label(target == Some(e.id), &name).clicked() {
                                self.target = Some(e.id);
                            }
                        }
                    })
                    .response
                    .on_hover_text("The BRDF to fit to: measured data, a file or a model")
                    .widget_info(|| {
                        egui::WidgetInfo::labeled(egui::Role::ComboBox, true, "Fit target")
                    });
                ui.end_row();
                ui.label("Model");
                let mut chosen = None;
                egui::ComboBox::from_id_salt("bv fit model")
                    .selected_text(model_name(self.model))
                    .show_ui(ui, |ui| {
                        for m in bv_core::catalogue().iter() {
                            if m.file_param().is_some() {
                                continue;
                            }
                            let r = ui
                                .selectable_label(m.id == self.model, m.name)
                                .on_hover_text(m.summary);
                            if r.clicked() {
                                chosen = Some(m.id);
                            }
                        }
                    })
                    .response
                    .widget_info(|| {
                        egui::WidgetInfo::labeled(egui::Role::ComboBox, true, "Fit model")
                    });
                if let Some(id) = chosen
                    && id != self.model
                {
                    self.set_model(id);
                }
                ui.end_row();
                ui.label("Free");
                ui.horizontal_wrapped(|ui| {
                    for (p, on) in &mut self.free {
                        let label = format!("Free {p}");
                        let v = *on;
                        ui.checkbox(on, *p)
                            .on_hover_text("Fitted when ticked; kept at its default otherwise")
                            .widget_info(|| {
                                egui::WidgetInfo::selected(egui::Role::CheckBox, true, v, &label)
                            });
                    }
                });
                ui.end_row();
                ui.label("Metric");
                ui.horizontal(|ui| {
                    ui.radio_value(&mut self.metric, Metric::Ngan, "Ngan 2005")
                        .on_hover_text("Cube root of f cos θi (Ngan et al. 2005)");
                    ui.radio_value(&mut self.metric, Metric::E2, "Löw E2")
                        .on_hover_text("ln(1 + f cos θi) (Löw et al. 2012, E2)");
                });
                ui.end_row();
            });
        ui.separator();
        let st = self.job.status();
        let mine = self
            .started
            .as_ref()
            .is_some_and(|(k, _)| st.key.as_ref() == Some(k));
        ui.horizontal(|ui| {
            if st.running {
                if ui.button("Cancel fit").clicked() {
                    self.job.cancel();
                    self.started = None;
                }
            } else if ui
                .button("Start fit")
                .on_hover_text("Fit the model to the target; the result is added as a BRDF")
                .clicked()
            {
                self.refused = self.start(state, waker).err();
            }
            if st.running {
                ui.spinner();
                match st.progress {
                    Some(p) => ui.label(format!(
                        "start {}/{}, iteration {}: error {:.4}",
                        p.start + 1,
                        p.starts,
                        p.iteration,
                        p.error
                    )),
                    None => ui.label("preparing the samples…"),
                };
            }
        });
        if let Some(e) = &self.refused {
            ui.colored_label(ui.visuals().error_fg_color, e);
        }
        if mine && !st.running {
            match &st.result {
                Some(Ok(r)) => {
                    ui.label(
                        RichText::new(fitjob::fitted_name(model_name(r.spec.id()), r)).strong(),
                    );
                    ui.label(format!(
                        "error {:.4} (from {:.4}), {} iterations over {} pairs; added to the list",
                        r.error, r.initial_error, r.iterations, r.pairs
                    ));
                    let worst = r
                        .residuals
                        .iter()
                        .filter(|b| b.samples > 0)
                        .max_by(|a, b| a.error.total_cmp(&b.error));
                    if let Some(b) = worst {
                        ui.weak(format!(
                            "worst band θi {:.0}–{:.0}°: error {:.4}",
                            b.theta_i_min, b.theta_i_max, b.error
                        ));
                    }
                }
                Some(Err(e)) => {
                    ui.colored_label(ui.visuals().error_fg_color, format!("The fit failed: {e}"));
                }
                None => {}
            }
        }
    }
}
