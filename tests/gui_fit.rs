//! The *Fit…* panel in the window (egui_kittest, no GPU): opened by its key,
//! driven by its accessible labels, it fits a model to a BRDF of the list and
//! adds the fit as a new BRDF; a refused start says why.

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::app::fit_ui::add_command;
use bv::session::Command;
use bv::session::state::AppState;
use bv_core::ModelSpec;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::time::Duration;

fn ward(alpha: &str) -> ModelSpec {
    let mut s = ModelSpec::new("ward").unwrap();
    s.set_str("alpha", alpha).unwrap();
    s.set_str("ks", "0.3").unwrap();
    s.set_str("kd", "0.4").unwrap();
    s
}

fn viewer(state: AppState) -> Harness<'static, Viewer> {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .with_max_steps(12)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    h.run();
    h
}

#[test]
fn the_panel_fits_the_selected_brdf_and_adds_the_fit() {
    let mut state = AppState::default();
    let truth = ward("0.1");
    state.add(truth.clone());
    let mut h = viewer(state);
    assert!(h.query_by_label("Start fit").is_none(), "closed at first");
    h.key_press(egui::Key::F);
    h.run();
    h.state_mut().fit.set_model("ward");
    h.run();
    h.get_by_label("Start fit").click();
    // A spinner turns while the fit runs: single frames, not `run`.
    h.step();
    assert!(
        h.state().fit.job().wait_idle(Duration::from_secs(300)),
        "the fit did not finish"
    );
    for _ in 0..3 {
        h.run();
    }
    let s = h.state().state();
    assert_eq!(s.brdfs.len(), 2, "the fit is added beside its target");
    let fit = &s.brdfs[1];
    let name = fit.name.clone().unwrap();
    assert!(name.starts_with("Ward fit (Ngan "), "{name}");
    // Ward fitted to Ward from its defaults: the target's α.
    let a = fit.spec.params().float("alpha_x").unwrap();
    assert!((a / 0.1 - 1.0).abs() < 0.01, "alpha {a}");
    assert_eq!(s.selected, Some(fit.id));
    // The list and the panel show it; a later frame adds nothing more.
    assert!(h.get_all_by_label(&name).count() >= 2);
    h.run();
    assert_eq!(h.state().state().brdfs.len(), 2);
}

#[test]
fn a_start_without_free_parameters_is_refused_with_a_reason() {
    let mut state = AppState::default();
    state.add(ward("0.2"));
    let mut h = viewer(state);
    h.state_mut().fit.set_model("ward");
    h.get_by_label("Fit…").click();
    h.run();
    for p in bv_core::fit::default_free(&ward("0.2")) {
        h.get_by_label(&format!("Free {p}")).click();
        h.run();
    }
    h.get_by_label("Start fit").click();
    h.run();
    h.get_by_label("choose at least one free parameter");
    assert!(!h.state().fit.job().status().running);
    assert_eq!(h.state().state().brdfs.len(), 1);
}

#[test]
fn the_add_command_names_the_fit_after_model_metric_and_error() {
    let target = ward("0.15");
    let r = bv_core::fit::fit(
        &ward("0.3"),
        &["alpha"],
        target.build().unwrap().as_ref(),
        &bv_core::fit::FitOptions::default(),
        &std::sync::atomic::AtomicBool::new(false),
        &mut |_| {},
    )
    .unwrap();
    let Command::AddNamed { name, spec } = add_command(&r) else {
        panic!("not an AddNamed");
    };
    assert_eq!(name, format!("Ward fit (Ngan {:.3})", r.error));
    assert_eq!(spec, r.spec);
    let mut s = AppState::default();
    let applied = Command::AddNamed { name, spec }.apply(&mut s);
    assert!(applied.message.is_none());
    assert_eq!(s.brdfs.len(), 1);
}

fn lambert(albedo: &str) -> ModelSpec {
    let mut s = ModelSpec::new("lambert").unwrap();
    s.set_str("albedo", albedo).unwrap();
    s
}

/// The image slice's residual mode, switched on by its toggle: Lambert 0.5
/// against Lambert 0.25 is +100 % everywhere above the horizon; a BRDF
/// against itself, 0.
#[test]
fn the_residual_mode_shows_the_relative_error_against_the_reference() {
    use bv::views::image_slice::ImageSliceView;
    let mut state = AppState::default();
    let quarter = state.add(lambert("0.25"));
    let half = state.add(lambert("0.5"));
    state.maximised = Some("slice".into());
    let mut h = viewer(state);
    h.get_by_label("residual").click();
    h.run();
    let v = h.state().view::<ImageSliceView>().unwrap();
    assert!(v.settings.residual);
    // The reference defaults to the first drawn BRDF, and only the other
    // one is drawn as a residual.
    assert_eq!(v.reference_id, Some(quarter));
    assert_eq!(v.image_rects.len(), 1);
    assert_eq!(v.image_rects[0].0, half);
    let e = v.residual(half, quarter).unwrap();
    let valid: Vec<f64> = e.iter().flatten().copied().collect();
    assert!(valid.len() > 1000);
    assert!(valid.iter().all(|x| (x - 1.0).abs() < 1e-6), "not +100 %");
    let e = v.residual(quarter, quarter).unwrap();
    assert!(e.iter().flatten().all(|x| *x == 0.0));
    // The colour map's range is offered (the legend is painted, not a
    // widget: see the screenshot in the report).
    h.get_by_label("Residual range");
}

/// Just the image slice view (toolbar and image) over a state.
struct SliceOnly {
    state: AppState,
    runtime: bv::session::runtime::Runtime,
    view: bv::views::image_slice::ImageSliceView,
}

impl SliceOnly {
    fn ui(&mut self, ui: &mut egui::Ui) {
        use bv::views::View as _;
        let scene = bv::session::build_scene(&self.state, &self.runtime, false);
        let mut out = Vec::new();
        egui::CentralPanel::default().show(ui, |ui| {
            ui.horizontal(|ui| self.view.toolbar(ui, &scene, &mut out));
            self.view.ui(ui, &scene, &mut out);
        });
    }
}

/// The residual mode drawn (lavapipe where there is no GPU): the deck's
/// two-lobe Lafortune target against its Phong and Ward fits. Each tile
/// shows both signs of error (blue and red pixels) and the hatching below
/// the horizon is absent at φd = 90°. `BV_FIT_RESIDUAL_PNG=path` saves the
/// image.
#[test]
fn headless_residual_tiles_show_both_signs() {
    let json = |m: &str, p: serde_json::Value| ModelSpec::from_json(m, &p).unwrap();
    let mut state = AppState::default();
    let target = state.add(json(
        "lafortune",
        serde_json::json!({"kd": 0.1, "lobes": [
            {"cx": -1.0, "cy": -1.0, "cz": 0.6, "n": 30.0, "ks": 0.6},
            {"cx": 0.9, "cy": 0.9, "cz": 0.9, "n": 12.0, "ks": 0.05}]}),
    ));
    state.add(json(
        "phong",
        serde_json::json!({"kd": 0.0338, "ks": 0.0661, "e": 29.66}),
    ));
    state.add(json(
        "ward",
        serde_json::json!({"kd": 0.1061, "ks": 0.0213, "alpha": 0.2434}),
    ));
    // Residual mode, as a scene saves it (`plots.slice`).
    state.plots.slice.residual = true;
    let mut runtime = bv::session::runtime::Runtime::default();
    runtime.sync(&state);
    let view = bv::views::image_slice::ImageSliceView::default();
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        eframe::egui_wgpu::RendererOptions::PREDICTABLE,
    );
    let mut h = Harness::builder()
        .renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(rs))
        .with_size([900.0, 480.0])
        .build_ui_state(
            |ui, s: &mut SliceOnly| s.ui(ui),
            SliceOnly {
                state,
                runtime,
                view,
            },
        );
    h.run();
    assert_eq!(h.state().view.reference_id, Some(target));
    let rects = h.state().view.image_rects.clone();
    assert_eq!(rects.len(), 2, "one tile per fit, none for the target");
    let img = h.render().expect("render");
    if let Some(path) = std::env::var_os("BV_FIT_RESIDUAL_PNG") {
        img.save(path).unwrap();
    }
    for (_, r) in rects {
        let (mut blue, mut red) = (0, 0);
        for y in (r.min.y as u32 + 2..r.max.y as u32 - 2).step_by(3) {
            for x in (r.min.x as u32 + 2..r.max.x as u32 - 2).step_by(3) {
                let p = img.get_pixel(x, y).0;
                if u16::from(p[2]) > u16::from(p[0]) + 40 {
                    blue += 1;
                }
                if u16::from(p[0]) > u16::from(p[2]) + 40 {
                    red += 1;
                }
            }
        }
        assert!(blue > 50 && red > 50, "blue {blue}, red {red}");
    }
}

/// While a fit runs, an edit of its target restarts it for the new values
/// (the key changed); *Cancel fit* stops it and nothing is added.
#[test]
fn an_edited_target_restarts_the_fit_and_cancel_adds_nothing() {
    let mut target = ModelSpec::new("cook-torrance").unwrap();
    target.set_str("distribution", "ggx").unwrap();
    target.set_str("alpha", "0.05").unwrap();
    let mut state = AppState::default();
    let id = state.add(target.clone());
    let mut h = viewer(state);
    {
        let v = h.state_mut();
        v.fit.set_model("cook-torrance");
        // Far more work than the test waits for: it must be cancelled.
        v.fit.options.starts = 64;
        v.fit.options.max_iterations = 400;
        v.fit.open = true;
    }
    h.run();
    h.get_by_label("Start fit").click();
    h.step();
    let job = h.state().fit.job().clone();
    let t0 = std::time::Instant::now();
    while job.status().progress.is_none() {
        assert!(t0.elapsed() < Duration::from_secs(120), "no progress");
        std::thread::sleep(Duration::from_millis(5));
    }
    assert!(job.status().running);
    h.state_mut().push(Command::SetParam {
        brdf: id,
        param: "alpha".into(),
        value: bv_core::ParamValue::Float(0.3),
    });
    h.step();
    h.step();
    let st = job.status();
    assert!(st.running, "restarted");
    let key = st.key.unwrap();
    assert_eq!(
        key.target.params().float("alpha_x").unwrap(),
        0.3,
        "the new values"
    );
    assert_eq!(key.target, h.state().state().entry(id).unwrap().spec);
    h.get_by_label("Cancel fit").click();
    h.step();
    assert!(
        job.wait_idle(Duration::from_secs(60)),
        "the fit did not stop"
    );
    for _ in 0..3 {
        h.step();
    }
    assert!(!job.status().running);
    assert_eq!(
        h.state().state().brdfs.len(),
        1,
        "a cancelled fit adds nothing"
    );
    h.get_by_label("Start fit");
}
