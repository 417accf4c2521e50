//! Commands: what UI code asks for. Widgets never change the state while the
//! frame is being laid out; they push a [`Command`], and the viewer applies the
//! whole list after the frame (so that one frame sees one consistent state, and
//! so that tests and scripted drivers can use the same entry point).

use super::state::{AppState, CartesianAxis, Display, Incident, PlotSettings, Theme};
use bv_core::{ModelSpec, ParamValue};

/// One change to the viewer's state.
#[derive(Debug, Clone, PartialEq)]
pub enum Command {
    /// Adds a BRDF of catalogue model `0` with its defaults, and selects it.
    AddBrdf(String),
    /// Adds a BRDF with the given (validated) parameters, and selects it.
    AddSpec(ModelSpec),
    /// Adds a BRDF with the given parameters under a name (a material
    /// preset's), and selects it.
    AddNamed {
        /// The name shown for it.
        name: String,
        /// Its model and parameters.
        spec: ModelSpec,
    },
    /// Names a BRDF (legends and figures use the name), or gives it back its
    /// model's name with `None` or an empty name.
    Rename(u64, Option<String>),
    /// Changes a BRDF's model, keeping the values of the parameters both
    /// models declare (where the new declaration accepts them) and its
    /// colour, visibility and name.
    ChangeModel(u64, String),
    /// Removes a BRDF.
    RemoveBrdf(u64),
    /// Shows a BRDF's parameters in the panel.
    Select(u64),
    /// Selects the next (+1) or previous (−1) BRDF of the list.
    SelectStep(i32),
    /// Shows or hides a BRDF.
    SetVisible(u64, bool),
    /// Shows a BRDF alone, or ends the solo if it is the soloed one.
    ToggleSolo(u64),
    /// Sets one parameter (validated against the model's declaration).
    SetParam {
        /// BRDF id.
        brdf: u64,
        /// Parameter id.
        param: String,
        /// New value.
        value: ParamValue,
    },
    /// Resets one parameter to its declared default.
    ResetParam {
        /// BRDF id.
        brdf: u64,
        /// Parameter id.
        param: String,
    },
    /// Resets every parameter of a BRDF.
    ResetAllParams(u64),
    /// Replaces the selected BRDF's model by the next (+1) or previous (−1) model
    /// of the catalogue, with its defaults (keeps colour and place).
    StepModel(i32),
    /// Changes a BRDF's display colour.
    SetColor(u64, [u8; 3]),
    /// Moves the light.
    SetIncident(Incident),
    /// Sets the shared display options.
    SetDisplay(Display),
    /// Toggles the logarithmic scale.
    ToggleLog,
    /// Toggles the × cos θo factor.
    ToggleCosine,
    /// Toggles the lobe wireframe.
    ToggleWireframe,
    /// Sets the lobe camera.
    SetCamera(super::state::Camera),
    /// Resets the lobe camera to its default.
    ResetCamera,
    /// Sets the plot settings.
    SetPlots(PlotSettings),
    /// Sets the Cartesian plot's axis.
    SetCartesianAxis(CartesianAxis),
    /// Maximises the view with this registry id, or restores the layout.
    Maximise(Option<String>),
    /// Maximises the view, or restores the layout if it is the maximised one.
    ToggleMaximise(String),
    /// Switches the colour theme.
    SetTheme(Theme),
    /// Reads a measured table (`.binary`) in the background; once it is read
    /// and valid, sets it as the path of BRDF `into` (its path parameter), or
    /// adds a new `merl` BRDF with it. A file the reader refuses changes
    /// nothing and shows the reader's message (see [`super::loader`]).
    OpenFile {
        /// The file.
        path: String,
        /// The BRDF whose file it becomes, or `None` for a new BRDF.
        into: Option<u64>,
    },
    /// Opens the file dialog for measured tables.
    OpenFileDialog,
    /// Opens or closes the keyboard help.
    ToggleHelp,
    /// Sets the lit sphere view's settings.
    SetLitView(super::lighting::LitView),
    /// Sets the environment view's settings.
    SetEnvView(super::lighting::EnvView),
}

/// What applying a command did, beyond changing the state.
#[derive(Debug, Clone, PartialEq, Eq, Default)]
pub struct Applied {
    /// A message for the status line (errors and refusals).
    pub message: Option<String>,
    /// The help overlay should toggle.
    pub toggle_help: bool,
    /// A file to read in the background, and where its table goes.
    pub open: Option<(String, super::loader::LoadTarget)>,
    /// The file dialog should open.
    pub open_dialog: bool,
}

impl Command {
    /// Applies the command to `state`.
    pub fn apply(self, state: &mut AppState) -> Applied {
        let mut out = Applied::default();
        let adds = match &self {
            Command::AddBrdf(_) | Command::AddSpec(_) | Command::AddNamed { .. } => true,
            // A file that becomes a new BRDF (not one BRDF's new table).
            Command::OpenFile { path, into } => {
                super::user_models::is_file(path)
                    || into
                        .and_then(|id| state.entry(id))
                        .and_then(|e| path_param(&e.spec))
                        .is_none()
            }
            _ => false,
        };
        if adds && state.is_full() {
            out.message = Some(AppState::full_message());
            return out;
        }
        match self {
            Command::AddBrdf(model) => match ModelSpec::new(&model) {
                Ok(spec) => {
                    state.add(spec);
                }
                Err(e) => out.message = Some(e.to_string()),
            },
            Command::AddSpec(spec) => {
                state.add(spec);
            }
            Command::AddNamed { name, spec } => {
                state.add_named(spec, Some(name));
            }
            Command::Rename(id, name) => {
                if let Some(e) = state.entry_mut(id) {
                    e.name = name
                        .map(|n| n.trim().chars().take(MAX_NAME_CHARS).collect::<String>())
                        .filter(|n| !n.is_empty());
                }
            }
            Command::ChangeModel(id, model) => match bv_core::find(&model) {
                Ok(info) => {
                    if let Some(e) = state.entry_mut(id)
                        && e.spec.id() != info.id
                    {
                        e.spec = carry_over(&e.spec, info);
                    }
                }
                Err(e) => out.message = Some(e.to_string()),
            },
            Command::RemoveBrdf(id) => {
                let pos = state.brdfs.iter().position(|b| b.id == id);
                if let Some(i) = pos {
                    state.brdfs.remove(i);
                    if state.selected == Some(id) {
                        let j = i.min(state.brdfs.len().saturating_sub(1));
                        state.selected = state.brdfs.get(j).map(|b| b.id);
                    }
                    if state.solo == Some(id) {
                        state.solo = None;
                    }
                }
            }
            Command::Select(id) => {
                if state.entry(id).is_some() {
                    state.selected = Some(id);
                }
            }
            Command::SelectStep(step) => {
                let n = state.brdfs.len() as i64;
                if n > 0 {
                    let cur = state
                        .selected
                        .and_then(|id| state.brdfs.iter().position(|b| b.id == id))
                        .unwrap_or(0) as i64;
                    let next = (cur + step as i64).rem_euclid(n) as usize;
                    state.selected = Some(state.brdfs[next].id);
                }
            }
            Command::SetVisible(id, v) => {
                if let Some(e) = state.entry_mut(id) {
                    e.visible = v;
                }
            }
            Command::ToggleSolo(id) => {
                state.solo = if state.solo == Some(id) {
                    None
                } else if state.entry(id).is_some() {
                    Some(id)
                } else {
                    state.solo
                };
            }
            Command::SetParam { brdf, param, value } => {
                if let Some(e) = state.entry_mut(brdf) {
                    // Validate on a copy: a refused value leaves the spec untouched.
                    let mut spec = e.spec.clone();
                    match spec.set(&param, value) {
                        Ok(()) => e.spec = spec,
                        Err(err) => out.message = Some(err.to_string()),
                    }
                }
            }
            Command::ResetParam { brdf, param } => {
                if let Some(e) = state.entry_mut(brdf)
                    && let Ok(decl) = e.spec.model().param(&param)
                {
                    // A declared default always validates.
                    let _ = e.spec.set(&param, decl.default_value());
                }
            }
            Command::ResetAllParams(id) => {
                if let Some(e) = state.entry_mut(id)
                    && let Ok(spec) = ModelSpec::new(e.spec.id())
                {
                    e.spec = spec;
                }
            }
            Command::StepModel(step) => {
                let cat = bv_core::catalogue();
                if let Some(id) = state.selected
                    && let Some(e) = state.entry_mut(id)
                    && !cat.is_empty()
                {
                    let cur = cat.iter().position(|m| m.id == e.spec.id()).unwrap_or(0) as i64;
                    let next = (cur + step as i64).rem_euclid(cat.len() as i64) as usize;
                    match ModelSpec::new(cat[next].id) {
                        Ok(spec) => e.spec = spec,
                        Err(err) => out.message = Some(err.to_string()),
                    }
                }
            }
            Command::SetColor(id, c) => {
                if let Some(e) = state.entry_mut(id) {
                    e.color = c;
                }
            }
            Command::SetIncident(i) => state.incident = i.clamped(),
            Command::SetDisplay(d) => state.display = d,
            Command::ToggleLog => state.display.log = !state.display.log,
            Command::ToggleCosine => state.display.cosine = !state.display.cosine,
            Command::ToggleWireframe => state.display.wireframe = !state.display.wireframe,
            Command::SetCamera(c) => state.camera = c.clamped(),
            Command::ResetCamera => {
                state.camera = super::state::Camera {
                    fixed_scale: state.camera.fixed_scale,
                    ..Default::default()
                }
            }
            Command::SetPlots(p) => state.plots = p,
            Command::SetCartesianAxis(a) => state.plots.axis = a,
            Command::Maximise(v) => state.maximised = v,
            Command::ToggleMaximise(v) => {
                state.maximised = if state.maximised.as_deref() == Some(v.as_str()) {
                    None
                } else {
                    Some(v)
                };
            }
            Command::SetTheme(t) => state.theme = t,
            Command::ToggleHelp => out.toggle_help = true,
            Command::SetLitView(v) => {
                state.lighting.lit = v;
                state.lighting = std::mem::take(&mut state.lighting).sanitised();
            }
            Command::SetEnvView(v) => {
                state.lighting.env = v;
                state.lighting = std::mem::take(&mut state.lighting).sanitised();
            }
            // A user BRDF file is a model of its own (compiled now, small),
            // not a table for the background loader.
            Command::OpenFile { path, .. } if super::user_models::is_file(&path) => {
                match super::user_models::resolve(&path).map(ModelSpec::defaults) {
                    Ok(spec) => {
                        state.add(spec);
                    }
                    Err(e) => out.message = Some(format!("{e:#}")),
                }
            }
            Command::OpenFile { path, into } => {
                let target = match into.and_then(|id| state.entry(id)) {
                    Some(e) => match path_param(&e.spec) {
                        Some(param) => super::loader::LoadTarget::Into {
                            brdf: e.id,
                            param: param.to_string(),
                        },
                        None => {
                            out.message = Some(format!(
                                "{} takes no file; opening {path} as a new BRDF",
                                e.spec.id()
                            ));
                            super::loader::LoadTarget::New
                        }
                    },
                    None => super::loader::LoadTarget::New,
                };
                out.open = Some((path, target));
            }
            Command::OpenFileDialog => out.open_dialog = true,
        }
        out
    }
}

/// Longest BRDF name kept (a name is a legend entry, not a document).
pub const MAX_NAME_CHARS: usize = 60;

/// A spec of `info` with its defaults, then every value of `old` whose
/// parameter `info` also declares and accepts (same id; e.g. `kd`, `ks`,
/// `alpha_x` between Cook-Torrance and Ward). Values the new declaration
/// refuses (another range, another kind) keep the new model's default.
pub fn carry_over(old: &ModelSpec, info: &'static bv_core::ModelInfo) -> ModelSpec {
    let mut spec = ModelSpec::defaults(info);
    for (id, value) in old.params().iter() {
        if info.param(id).is_ok() {
            let _ = spec.set(id, value.clone());
        }
    }
    spec
}

/// The id of a spec's file parameter, if its model reads a file.
pub fn path_param(spec: &ModelSpec) -> Option<&'static str> {
    spec.model().file_param().map(|(d, _)| d.id)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn changing_the_model_keeps_the_shared_parameters_and_renaming_trims() {
        let mut s = AppState::default();
        let ct = ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"kd": [0.1, 0.2, 0.3], "alpha_x": 0.07, "alpha_y": 0.3, "ks": 0.9}),
        )
        .unwrap();
        let id = s.add(ct);
        Command::ChangeModel(id, "ward".into()).apply(&mut s);
        let e = s.entry(id).unwrap();
        assert_eq!(e.spec.id(), "ward");
        let p = e.spec.params();
        assert_eq!(p.color("kd").unwrap(), glam::DVec3::new(0.1, 0.2, 0.3));
        assert_eq!(p.float("alpha_x").unwrap(), 0.07);
        assert_eq!(p.float("alpha_y").unwrap(), 0.3);
        // Cook-Torrance's scalar ks becomes Ward's grey colour ks; a
        // parameter Ward lacks (distribution) is dropped.
        assert_eq!(p.color("ks").unwrap(), glam::DVec3::splat(0.9));
        assert!(p.get("distribution").is_err());
        // An unknown model changes nothing and says why.
        let before = s.clone();
        let r = Command::ChangeModel(id, "nope".into()).apply(&mut s);
        assert_eq!(s, before);
        assert!(r.message.unwrap().contains("nope"));
        // Names: trimmed, bounded, and empty gives the model's name back.
        Command::Rename(id, Some("  brushed steel  ".into())).apply(&mut s);
        assert_eq!(s.entry(id).unwrap().name.as_deref(), Some("brushed steel"));
        Command::Rename(id, Some("x".repeat(500))).apply(&mut s);
        assert_eq!(
            s.entry(id).unwrap().name.as_ref().unwrap().chars().count(),
            MAX_NAME_CHARS
        );
        Command::Rename(id, Some("   ".into())).apply(&mut s);
        assert_eq!(s.entry(id).unwrap().name, None);
    }

    #[test]
    fn add_select_remove() {
        let mut s = AppState::default();
        Command::AddBrdf("lambert".into()).apply(&mut s);
        Command::AddBrdf("lambert".into()).apply(&mut s);
        let (a, b) = (s.brdfs[0].id, s.brdfs[1].id);
        assert_eq!(s.selected, Some(b));
        Command::RemoveBrdf(b).apply(&mut s);
        assert_eq!(s.selected, Some(a));
        let r = Command::AddBrdf("nope".into()).apply(&mut s);
        assert!(r.message.unwrap().contains("nope"));
        assert_eq!(s.brdfs.len(), 1);
    }

    #[test]
    fn a_full_scene_refuses_another_brdf() {
        use crate::session::state::MAX_BRDFS;
        let mut s = AppState::default();
        for _ in 0..MAX_BRDFS {
            assert_eq!(
                Command::AddBrdf("lambert".into()).apply(&mut s).message,
                None
            );
        }
        let spec = ModelSpec::new("ward").unwrap();
        for c in [
            Command::AddBrdf("lambert".into()),
            Command::AddSpec(spec.clone()),
            Command::AddNamed {
                name: "Gold".into(),
                spec,
            },
            Command::OpenFile {
                path: "table.binary".into(),
                into: None,
            },
        ] {
            let r = c.apply(&mut s);
            let m = r.message.unwrap();
            assert!(m.contains(&format!("at most {MAX_BRDFS} BRDFs")), "{m}");
            assert!(r.open.is_none());
        }
        assert_eq!(s.brdfs.len(), MAX_BRDFS);
        // Removing one makes room again.
        Command::RemoveBrdf(s.brdfs[0].id).apply(&mut s);
        assert_eq!(
            Command::AddBrdf("lambert".into()).apply(&mut s).message,
            None
        );
        assert_eq!(s.brdfs.len(), MAX_BRDFS);
    }

    #[test]
    fn refused_values_leave_the_spec_alone() {
        let mut s = AppState::default();
        Command::AddBrdf("lambert".into()).apply(&mut s);
        let id = s.brdfs[0].id;
        let before = s.brdfs[0].spec.clone();
        let r = Command::SetParam {
            brdf: id,
            param: "albedo".into(),
            value: ParamValue::Color([2.0, 0.0, 0.0]),
        }
        .apply(&mut s);
        assert!(r.message.unwrap().contains("albedo"));
        assert_eq!(s.brdfs[0].spec, before);
        Command::SetParam {
            brdf: id,
            param: "albedo".into(),
            value: ParamValue::Color([0.1, 0.2, 0.3]),
        }
        .apply(&mut s);
        assert_eq!(
            s.brdfs[0].spec.params().color("albedo").unwrap(),
            glam::DVec3::new(0.1, 0.2, 0.3)
        );
        Command::ResetParam {
            brdf: id,
            param: "albedo".into(),
        }
        .apply(&mut s);
        assert_eq!(s.brdfs[0].spec, before);
    }

    #[test]
    fn maximise_toggles() {
        let mut s = AppState::default();
        Command::ToggleMaximise("lobe".into()).apply(&mut s);
        assert_eq!(s.maximised.as_deref(), Some("lobe"));
        Command::ToggleMaximise("lobe".into()).apply(&mut s);
        assert_eq!(s.maximised, None);
    }
}
