//! Behaviour tests of the viewer window with egui_kittest: widgets are found by
//! their accessible labels (what a screen reader reads), driven with clicks,
//! drags and keys, and the effect is checked on the state and on the data the
//! views draw. They need no window and no GPU.
//!
//! The `snapshot_*` and `headless_*` tests render on the GPU (lavapipe on
//! machines without one) and compare small images with `tests/snapshots/`.
//! Regenerate with `UPDATE_SNAPSHOTS=1 cargo test -p bv --test suite gui::`.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::gpu::lobe::LobeRenderer;
use bv::session::Command;
use bv::session::build_scene;
use bv::session::runtime::Runtime;
use bv::session::state::AppState;
use bv::views::cartesian::CartesianView;
use bv::views::lobe3d::Lobe3dView;
use bv::views::polar::PolarView;
use bv::views::{Scene, View};
use eframe::egui::{self, Role};
use egui_kittest::Harness;
use egui_kittest::kittest::{Queryable, by};
use std::f64::consts::PI;

const SIZE: [f32; 2] = [1280.0, 800.0];

fn viewer(state: AppState) -> Harness<'static, Viewer> {
    let mut h = Harness::builder()
        .with_size(SIZE)
        .with_max_steps(12)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    h.run();
    h
}

fn lobe<'a>(h: &'a Harness<'_, Viewer>) -> &'a Lobe3dView {
    h.state()
        .view::<Lobe3dView>()
        .expect("lobe view registered")
}

fn first_id(h: &Harness<'_, Viewer>) -> u64 {
    h.state().state().brdfs[0].id
}

/// Drags from `from` to `to` in a few moves, like a hand would.
fn drag(h: &mut Harness<'_, Viewer>, from: egui::Pos2, to: egui::Pos2) {
    h.hover_at(from);
    h.run();
    h.drag_at(from);
    h.run();
    for k in 1..=4 {
        h.hover_at(from + (to - from) * (k as f32 / 4.0));
        h.run();
    }
    h.drop_at(to);
    h.run();
}

#[test]
fn add_a_brdf_by_its_label_and_remove_it() {
    let mut h = viewer(AppState::first_run());
    assert_eq!(h.state().state().brdfs.len(), 1);
    let first = bv_core::catalogue()[0];

    h.get_by_label("Add BRDF").click();
    h.run();
    h.get_by_label(&format!("Add {}", first.name)).click();
    h.run();
    let s = h.state().state();
    assert_eq!(s.brdfs.len(), 2);
    assert_eq!(s.brdfs[1].spec.id(), first.id);
    assert_ne!(
        s.brdfs[0].color, s.brdfs[1].color,
        "overlaid BRDFs get distinct colours"
    );
    assert_eq!(s.selected, Some(s.brdfs[1].id), "the new BRDF is selected");
    // Both are drawn in the lobe view, each from its own mesh.
    let ids: Vec<u64> = s.brdfs.iter().map(|b| b.id).collect();
    for id in &ids {
        assert!(lobe(&h).mesh(*id).is_some());
    }

    let second = format!("{} 2", first.name);
    h.get_by_label(&format!("Remove {second}")).click();
    h.run();
    assert_eq!(h.state().state().brdfs.len(), 1);
    assert!(h.query_by_label(&format!("Remove {second}")).is_none());
    assert!(lobe(&h).mesh(ids[1]).is_none(), "its mesh is dropped");

    // Removing the last one leaves an empty, working window.
    h.get_by_label(&format!("Remove {}", first.name)).click();
    h.run();
    assert!(h.state().state().brdfs.is_empty());
    assert_eq!(h.state().state().selected, None);
    h.get_by_label("Add BRDF");
}

#[test]
fn dragging_a_parameter_slider_changes_the_lobe() {
    let mut h = viewer(AppState::first_run());
    let id = first_id(&h);
    let before = lobe(&h).mesh(id).unwrap().max_value;
    // Lambert's albedo defaults to 0.5: its lobe is the hemisphere of radius 0.5/π.
    assert!((before - 0.5 / PI).abs() < 1e-6);

    let slider = h.get_by_role_and_label(Role::Slider, "albedo");
    let r = slider.rect();
    drag(
        &mut h,
        r.center(),
        r.center() - egui::vec2(r.width() * 0.3, 0.0),
    );

    let albedo = h.state().state().brdfs[0]
        .spec
        .params()
        .color("albedo")
        .unwrap();
    assert!(
        albedo.x < 0.45,
        "the slider moved the albedo down: {albedo}"
    );
    assert_eq!(albedo.x, albedo.y, "a grey stays grey");
    let after = lobe(&h).mesh(id).unwrap().max_value;
    assert!(
        (after - albedo.x / PI).abs() < 1e-6,
        "lobe radius {after} follows albedo {albedo}"
    );
}

#[test]
fn a_reset_button_restores_the_default() {
    let mut h = viewer(AppState::first_run());
    let id = first_id(&h);
    h.state_mut().push(Command::SetParam {
        brdf: id,
        param: "albedo".into(),
        value: bv_core::ParamValue::Color([0.1, 0.2, 0.3]),
    });
    h.run();
    h.get_by_label("Reset albedo").click();
    h.run();
    let e = &h.state().state().brdfs[0];
    assert_eq!(e.spec, bv_core::ModelSpec::new(e.spec.id()).unwrap());
}

#[test]
fn log_toggle_changes_the_radius() {
    let mut h = viewer(AppState::first_run());
    let id = first_id(&h);
    // The lobe view's toolbar comes first.
    h.get_all_by_label("log").next().unwrap().click();
    h.run();
    assert!(h.state().state().display.log);
    let m = lobe(&h).mesh(id).unwrap();
    assert!((m.max_radius - (0.5 / PI).ln_1p()).abs() < 1e-6);
    // And the keyboard shortcut turns it off again.
    h.key_press(egui::Key::L);
    h.run();
    assert!(!h.state().state().display.log);
    assert!((lobe(&h).mesh(id).unwrap().max_radius - 0.5 / PI).abs() < 1e-6);
}

#[test]
fn the_light_follows_its_slider_and_the_hemisphere() {
    let mut h = viewer(AppState::first_run());
    let before = h.state().state().incident;
    let builds = lobe(&h).rebuild_count();

    let slider = h.get_by_role_and_label(Role::Slider, "θi");
    let r = slider.rect();
    drag(&mut h, r.center(), r.left_center() + egui::vec2(2.0, 0.0));
    let after = h.state().state().incident;
    assert!(
        after.theta_deg < before.theta_deg - 10.0,
        "{before:?} → {after:?}"
    );
    assert!(
        lobe(&h).rebuild_count() > builds,
        "the lobe is rebuilt for the new light"
    );

    // Clicking the hemisphere's centre puts the light on the normal.
    let disc = h.get_by_label("Light direction").rect();
    h.get_by_label("Light direction").hover();
    h.run();
    h.drag_at(disc.center());
    h.run();
    h.drop_at(disc.center());
    h.run();
    assert!(h.state().state().incident.theta_deg < 1.0);

    // Dragging towards its rim lowers the light.
    drag(
        &mut h,
        disc.center(),
        disc.center() + egui::vec2(0.0, disc.height() * 0.3),
    );
    let low = h.state().state().incident;
    assert!(low.theta_deg > 30.0, "{low:?}");
}

/// The "turn surface" slider turns the surface about its normal: an
/// anisotropic Ward's lobe is rebuilt and its values change.
#[test]
fn the_turn_slider_turns_an_anisotropic_lobe() {
    let mut state = AppState::default();
    state.add(
        bv_core::ModelSpec::from_json(
            "ward",
            &serde_json::json!({"alpha_x": 0.08, "alpha_y": 0.4}),
        )
        .unwrap(),
    );
    let mut h = viewer(state);
    let builds = lobe(&h).rebuild_count();
    let slider = h.get_by_role_and_label(Role::Slider, "turn surface");
    let r = slider.rect();
    drag(
        &mut h,
        r.center(),
        r.center() + egui::vec2(r.width() * 0.25, 0.0),
    );
    let turn = h.state().state().display.turn_deg;
    assert!(turn > 20.0, "turn {turn}");
    assert!(lobe(&h).rebuild_count() > builds, "the lobe is rebuilt");
}

#[test]
fn views_maximise_and_restore() {
    let mut h = viewer(AppState::first_run());
    h.get_by_label("Maximise Plane of incidence (polar)")
        .click();
    h.run();
    assert_eq!(h.state().state().maximised.as_deref(), Some("polar"));
    assert!(
        h.query_by_label("Maximise 3D lobe").is_none(),
        "other views are hidden"
    );
    h.get_by_label("Restore Plane of incidence (polar)").click();
    h.run();
    assert_eq!(h.state().state().maximised, None);
    h.key_press(egui::Key::Num1);
    h.run();
    assert_eq!(h.state().state().maximised.as_deref(), Some("lobe"));
    h.key_press(egui::Key::Escape);
    h.run();
    assert_eq!(h.state().state().maximised, None);
}

#[test]
fn help_overlay_lists_the_shortcuts() {
    let mut h = viewer(AppState::first_run());
    assert!(h.query_by_label("Keyboard shortcuts").is_none());
    h.key_press(egui::Key::F1);
    h.run();
    assert!(h.state().help_open());
    assert!(h.get_all_by_label("Keyboard shortcuts").count() >= 1);
    assert!(h.get_all_by_label("reset the camera").count() >= 1);
    // Each row is drawn from the shortcut's own declaration.
    for sc in bv::app::shortcuts::SHORTCUTS {
        assert!(h.query_all_by_label(sc.help).count() >= 1, "{}", sc.help);
        assert!(
            h.query_all_by_label(&sc.keys_text(&h.ctx)).count() >= 1,
            "{}",
            sc.keys_text(&h.ctx)
        );
    }
    assert!(h.query_by_label("1 … 9").is_some());
    h.key_press(egui::Key::F1);
    h.run();
    assert!(!h.state().help_open());
}

#[test]
fn keyboard_shortcuts_drive_the_views() {
    let mut h = viewer(AppState::first_run());
    h.state_mut()
        .push(Command::SetCamera(bv::session::state::Camera {
            yaw_deg: 10.0,
            ..Default::default()
        }));
    h.run();
    for (key, check) in [
        (
            egui::Key::C,
            (|s: &AppState| s.display.cosine) as fn(&AppState) -> bool,
        ),
        (egui::Key::W, |s: &AppState| s.display.wireframe),
        (egui::Key::R, |s: &AppState| {
            s.camera == bv::session::state::Camera::default()
        }),
        (egui::Key::T, |s: &AppState| {
            s.theme == bv::session::state::Theme::Light
        }),
    ] {
        h.key_press(key);
        h.run();
        assert!(check(h.state().state()), "{key:?}");
    }
}

#[test]
fn every_model_gets_widgets_from_its_declaration() {
    for info in bv_core::catalogue().iter() {
        let mut state = AppState::default();
        state.add(bv_core::ModelSpec::new(info.id).unwrap());
        let h = viewer(state);
        let defaults = bv_core::ModelSpec::new(info.id).unwrap();
        for decl in info
            .params
            .iter()
            .filter(|d| d.applies_to(defaults.params()))
        {
            let found = h.query_all(by().label(decl.label).include_labels()).count();
            assert!(
                found > 0,
                "model {}: no widget labelled `{}`",
                info.id,
                decl.label
            );
        }
    }
}

/// A parameter declared to matter only under some choices (k of a
/// conductor's Fresnel term) has a widget under those choices and none under
/// the others: for every such declaration of every model, its label is found
/// more often with a choice that makes it apply than with one that does not.
#[test]
fn parameters_that_do_not_apply_are_hidden() {
    let mut checked = 0;
    for info in bv_core::catalogue().iter() {
        for decl in info.params {
            let bv_core::Applies::When { param, any_of } = decl.applies else {
                continue;
            };
            let bv_core::ParamKind::Choice { options, .. } = info.param(param).unwrap().kind else {
                panic!(
                    "{}: `{}` depends on `{param}`, which is not a choice",
                    info.id, decl.id
                );
            };
            let Some(off) = options.iter().find(|o| !any_of.contains(o)) else {
                continue;
            };
            let count = |choice: &str| {
                let mut spec = bv_core::ModelSpec::new(info.id).unwrap();
                spec.set_str(param, choice).unwrap();
                let mut state = AppState::default();
                state.add(spec);
                let h = viewer(state);
                h.query_all(by().label(decl.label).include_labels()).count()
            };
            let shown = count(any_of[0]);
            let hidden = count(off);
            assert!(
                shown > hidden,
                "{}: `{}` has {shown} widgets with {param} = {} and {hidden} with {param} = {off}",
                info.id,
                decl.id,
                any_of[0]
            );
            checked += 1;
        }
    }
    assert!(checked >= 3, "only {checked} conditional parameters found");
}

#[test]
fn two_brdfs_overlay_in_all_three_views() {
    let first = bv_core::catalogue()[0];
    let mut state = AppState::default();
    state.add(bv_core::ModelSpec::new(first.id).unwrap());
    let mut spec = bv_core::ModelSpec::new(first.id).unwrap();
    // A different value for the first float or colour parameter, so the two differ.
    if let Some(decl) = first.params.first() {
        let v = match decl.kind {
            bv_core::ParamKind::Color(c) => bv_core::ParamValue::Color([c.max * 0.9; 3]),
            bv_core::ParamKind::Float(f) => bv_core::ParamValue::Float(f.slider_max),
            _ => decl.default_value(),
        };
        spec.set(decl.id, v).unwrap();
    }
    state.add(spec);
    let mut h = viewer(state);
    let ids: Vec<u64> = h.state().state().brdfs.iter().map(|b| b.id).collect();

    // Lobe: one opaque mesh coloured by value, one translucent in its colour.
    let frame = lobe(&h).last_frame().unwrap().clone();
    let styles: Vec<_> = frame
        .meshes
        .iter()
        .filter(|m| ids.contains(&m.key))
        .map(|m| m.style)
        .collect();
    assert_eq!(styles.len(), 2);
    assert_eq!(styles.iter().filter(|s| s.alpha >= 1.0).count(), 1);
    assert_ne!(styles[0].color, styles[1].color);

    // Plots: hovering reads both values, exactly.
    for which in ["polar", "cartesian"] {
        let rect = match which {
            "polar" => h.state().view::<PolarView>().unwrap().plot_rect.unwrap(),
            _ => h
                .state()
                .view::<CartesianView>()
                .unwrap()
                .plot_rect
                .unwrap(),
        };
        // Right of centre and above the surface: θo > 0 in both plots.
        let p = rect.center() + egui::vec2(rect.width() * 0.1, -rect.height() * 0.2);
        h.hover_at(p);
        h.run();
        let readout = match which {
            "polar" => h.state().view::<PolarView>().unwrap().readout.clone(),
            _ => h.state().view::<CartesianView>().unwrap().readout.clone(),
        }
        .unwrap_or_else(|| panic!("{which}: no readout"));
        assert_eq!(readout.values.len(), 2, "{which}");
        assert_ne!(
            readout.values[0].1, readout.values[1].1,
            "{which}: distinct colours"
        );
        let inc = h.state().state().incident;
        let wi = inc.direction();
        for (k, id) in ids.iter().enumerate() {
            let b = h.state().runtime().get(*id).unwrap().brdf.clone().unwrap();
            let s = &readout.values[k].2;
            // Both plots default to θo in the plane of incidence.
            let wo = bv::derive::slices::plane_direction(s.x, inc.phi_deg.to_radians());
            let exact = bv_core::mean_rgb(b.eval(wi, wo));
            assert!(
                (s.value - exact).abs() <= 1e-12 * exact.max(1.0),
                "{which}: {} vs {exact}",
                s.value
            );
        }
    }
    h.remove_cursor();
}

#[test]
fn state_survives_a_restart() {
    let mut h = viewer(AppState::first_run());
    h.state_mut()
        .push(Command::SetIncident(bv::session::state::Incident {
            theta_deg: 12.0,
            phi_deg: 34.0,
        }));
    h.state_mut().push(Command::ToggleLog);
    h.state_mut()
        .push(Command::SetCamera(bv::session::state::Camera {
            yaw_deg: 45.0,
            ..Default::default()
        }));
    h.run();
    let saved = h.state().state().to_json_string();
    let restored = viewer(AppState::from_json_str(&saved).unwrap());
    assert_eq!(restored.state().state(), h.state().state());
}

// ---- Rendering on the GPU (lavapipe where there is none) ----

/// A harness whose renderer has the lobe pipeline installed, like eframe's window.
fn gpu_builder<S>() -> egui_kittest::HarnessBuilder<S> {
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        egui_wgpu_options(),
    );
    bv::views::lobe_gpu::install(&rs);
    Harness::builder().renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(rs))
}

fn egui_wgpu_options() -> eframe::egui_wgpu::RendererOptions {
    eframe::egui_wgpu::RendererOptions::PREDICTABLE
}

/// Just the lobe view over a state.
struct LobeOnly {
    state: AppState,
    runtime: Runtime,
    view: Lobe3dView,
}

impl LobeOnly {
    fn new(model: &str, params: serde_json::Value) -> Self {
        let mut state = AppState::default();
        state.add(bv_core::ModelSpec::from_json(model, &params).unwrap());
        state.incident.theta_deg = 40.0;
        let mut runtime = Runtime::default();
        runtime.sync(&state);
        Self {
            state,
            runtime,
            view: Lobe3dView::new(),
        }
    }

    fn ui(&mut self, ui: &mut egui::Ui) {
        let scene: Scene<'_> = build_scene(&self.state, &self.runtime, false);
        let mut out = Vec::new();
        egui::CentralPanel::default().show(ui, |ui| self.view.ui(ui, &scene, &mut out));
    }
}

fn lobe_snapshot(name: &str, model: &str, params: serde_json::Value) {
    lobe_snapshot_from(name, model, params, bv::session::state::Camera::default());
}

fn lobe_snapshot_from(
    name: &str,
    model: &str,
    params: serde_json::Value,
    camera: bv::session::state::Camera,
) {
    if bv_core::find(model).is_err() {
        eprintln!("skipping snapshot {name}: model `{model}` is not in this build's catalogue");
        return;
    }
    let mut h = gpu_builder().with_size([480.0, 400.0]).build_ui_state(
        |ui, s: &mut LobeOnly| s.ui(ui),
        LobeOnly {
            state: AppState {
                camera,
                ..LobeOnly::new(model, params.clone()).state
            },
            ..LobeOnly::new(model, params)
        },
    );
    h.run();
    let img = h.render().expect("render");
    // The lobe must be there: the centre of the view is not the background.
    let bg = bv::views::lobe3d::background(true);
    let px = img.get_pixel(240, 200).0;
    let bg8 = [
        (bg[0] * 255.0).round() as u8,
        (bg[1] * 255.0).round() as u8,
        (bg[2] * 255.0).round() as u8,
    ];
    let diff: i32 = (0..3).map(|k| (px[k] as i32 - bg8[k] as i32).abs()).sum();
    assert!(
        diff > 30,
        "{name}: centre pixel {px:?} is the background {bg8:?}"
    );
    // lavapipe is deterministic on one machine; a little slack for other Mesa versions.
    h.snapshot_options(
        name,
        &egui_kittest::SnapshotOptions::new()
            .threshold(2.0)
            .max_failed_pixels(400),
    );
}

#[test]
fn snapshot_lobe_lambert() {
    lobe_snapshot(
        "lobe_lambert",
        "lambert",
        serde_json::json!({"albedo": [0.8, 0.8, 0.8]}),
    );
}

#[test]
fn snapshot_lobe_cook_torrance() {
    lobe_snapshot("lobe_cook_torrance", "cook-torrance", serde_json::json!({}));
}

#[test]
fn snapshot_lobe_ward_anisotropic() {
    // Seen from above and aside, so that the lobe's two widths both show.
    lobe_snapshot_from(
        "lobe_ward_anisotropic",
        "ward",
        serde_json::json!({"kd": 0.1, "ks": 0.3, "alpha_x": 0.08, "alpha_y": 0.3}),
        bv::session::state::Camera {
            yaw_deg: 55.0,
            pitch_deg: 40.0,
            ..Default::default()
        },
    );
}

#[test]
fn headless_lobe_render_draws_the_mesh() {
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        egui_wgpu_options(),
    );
    let mut renderer = LobeRenderer::new(&rs.device, Some(&rs.adapter), rs.target_format).unwrap();
    let mut s = LobeOnly::new("lambert", serde_json::json!({"albedo": 1.0}));
    let scene = build_scene(&s.state, &s.runtime, false);
    let bg = bv::views::lobe3d::background(true);
    let frame = s.view.frame(&scene, egui::vec2(200.0, 160.0), bg, true);
    let img = renderer
        .render_to_image(&rs.device, &rs.queue, &frame, 200, 160, 1.0)
        .unwrap();
    assert_eq!(img.dimensions(), (200, 160));
    // Corner: background; centre: the (yellow, top of the colour map) lobe.
    let corner = img.get_pixel(2, 2).0;
    assert!((corner[0] as f32 - bg[0] * 255.0).abs() < 2.0, "{corner:?}");
    let c = img.get_pixel(100, 80).0;
    assert!(
        c[0] > 120 && c[1] > 120 && (c[2] as i32) < c[1] as i32 - 60,
        "centre pixel {c:?} should be lit yellow"
    );
}

#[test]
fn a_slider_step_redraws_the_mesh_as_a_fresh_upload_would() {
    // A new revision with the same connectivity rewrites the vertex buffer in
    // place; what it draws must be what a renderer that never saw the old
    // revision draws. Cook-Torrance, whose lobe follows the light.
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        egui_wgpu_options(),
    );
    let new = || LobeRenderer::new(&rs.device, Some(&rs.adapter), rs.target_format).unwrap();
    let mut s = LobeOnly::new("cook-torrance", serde_json::json!({"alpha": 0.2}));
    let bg = bv::views::lobe3d::background(true);
    let mut frame_at = |theta: f64, interacting: bool| {
        s.state.incident.theta_deg = theta;
        let scene = build_scene(&s.state, &s.runtime, interacting);
        s.view.frame(&scene, egui::vec2(200.0, 160.0), bg, true)
    };
    let (before, after) = (frame_at(20.0, false), frame_at(60.0, false));
    let render = |r: &mut LobeRenderer, f: &bv::gpu::lobe::LobeFrame| {
        r.render_to_image(&rs.device, &rs.queue, f, 200, 160, 1.0)
            .unwrap()
    };
    let mut stepped = new();
    let first = render(&mut stepped, &before);
    let second = render(&mut stepped, &after);
    let fresh = render(&mut new(), &after);
    assert_ne!(first, second, "the light moved but the picture did not");
    assert!(
        second == fresh,
        "a refilled mesh draws differently from a fresh one"
    );

    // A drag frame (copied without FXAA on a software renderer) draws the
    // lobe too.
    let drag = frame_at(40.0, true);
    let img = render(&mut stepped, &drag);
    let differs = img
        .pixels()
        .filter(|p| (p.0[0] as f32 - bg[0] * 255.0).abs() > 8.0)
        .count();
    assert!(
        differs > 500,
        "the drag frame drew {differs} pixels off the background"
    );
}

#[test]
fn priming_the_lobe_pipelines_changes_no_pixel() {
    // `LobeRenderer::prime` draws its empty frame with every pipeline under
    // a view key of its own and removes it: a GPU error there would panic
    // here (wgpu's default handler), and a figure drawn after it must be
    // the one an unprimed renderer draws, view for view.
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        egui_wgpu_options(),
    );
    let new = || LobeRenderer::new(&rs.device, Some(&rs.adapter), rs.target_format).unwrap();
    let mut primed = new();
    primed.prime(&rs.device, &rs.queue);
    let mut s = LobeOnly::new("cook-torrance", serde_json::json!({"alpha": 0.3}));
    let bg = bv::views::lobe3d::background(true);
    let scene = build_scene(&s.state, &s.runtime, false);
    let frame = s.view.frame(&scene, egui::vec2(200.0, 160.0), bg, true);
    let render = |r: &mut LobeRenderer| {
        r.render_to_image(&rs.device, &rs.queue, &frame, 200, 160, 1.0)
            .unwrap()
    };
    let (a, b) = (render(&mut primed), render(&mut new()));
    let off_bg = a
        .pixels()
        .filter(|p| (p.0[0] as f32 - bg[0] * 255.0).abs() > 8.0)
        .count();
    assert!(
        off_bg > 500,
        "the primed renderer drew {off_bg} lobe pixels"
    );
    assert!(a == b, "priming changed the figure");
}

/// Lobe frames of several kinds at `size` points: lobes narrow and wide,
/// above and below the surface, overlaid, seen from the side, from above,
/// and from so close that the lobe leaves the view or lies behind the eye.
fn varied_lobe_frames(size: egui::Vec2) -> Vec<(String, bv::gpu::lobe::LobeFrame)> {
    use serde_json::json;
    // The camera by yaw, pitch and distance (the default is 90°, 20°, 4.9).
    let cam = |yaw_deg, pitch_deg, distance| bv::session::state::Camera {
        yaw_deg,
        pitch_deg,
        distance,
        ..Default::default()
    };
    // (model, parameters, θi, camera, Lambert overlaid as a second lobe).
    #[rustfmt::skip]
    let cases = [
        ("cook-torrance", json!({"alpha": 0.15}), 40.0, cam(90.0, 20.0, 4.9), false),
        ("lambert", json!({}), 0.0, cam(90.0, 20.0, 4.9), false),
        ("rough-dielectric", json!({"alpha": 0.3}), 60.0, cam(90.0, -10.0, 4.9), false),
        ("phong", json!({}), 70.0, cam(10.0, 85.0, 4.9), false),
        ("ward", json!({}), 30.0, cam(90.0, 20.0, 1.6), true),
        ("oren-nayar", json!({}), 20.0, cam(90.0, 20.0, 0.3), false),
    ];
    let bg = bv::views::lobe3d::background(true);
    cases
        .into_iter()
        .filter(|(model, ..)| bv_core::find(model).is_ok())
        .map(|(model, params, theta, camera, overlaid)| {
            let mut s = LobeOnly::new(model, params);
            if overlaid {
                // Two lobes overlaid (the second translucent).
                s.state.add(bv_core::ModelSpec::new("lambert").unwrap());
                s.runtime.sync(&s.state);
            }
            s.state.incident.theta_deg = theta;
            s.state.camera = camera;
            let scene = build_scene(&s.state, &s.runtime, false);
            let mut frame = (*s.view.frame(&scene, size, bg, true)).clone();
            frame.interacting = false;
            let name = format!("{model} at θi {theta}° from {camera:?}");
            (name, frame)
        })
        .collect()
}

#[test]
fn the_content_rectangle_holds_every_pixel_drawn() {
    // FXAA runs only inside `content`'s rectangle: every pixel the lobe's
    // pass draws off the background must lie inside it, with a pixel to
    // spare for FXAA's neighbourhood, for every kind of frame.
    use bv::gpu::lobe::{Content, content};
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        egui_wgpu_options(),
    );
    let (w, h) = (240u32, 180u32);
    let mut bounded = 0;
    for (name, frame) in varied_lobe_frames(egui::vec2(w as f32, h as f32)) {
        // A renderer per frame: the frames come from different views, whose
        // mesh keys and revisions may coincide.
        let mut renderer =
            LobeRenderer::new(&rs.device, Some(&rs.adapter), rs.target_format).unwrap();
        let img = renderer
            .render_to_image(&rs.device, &rs.queue, &frame, w, h, 1.0)
            .unwrap();
        let bg = frame.background.map(|c| (c * 255.0).round());
        let drawn: Vec<(u32, u32)> = img
            .enumerate_pixels()
            .filter(|(_, _, p)| (0..3).any(|c| (f32::from(p.0[c]) - bg[c]).abs() > 1.0))
            .map(|(x, y, _)| (x, y))
            .collect();
        match content(&frame, [w, h], 1.0) {
            Content::Everywhere => {}
            Content::Empty => assert!(drawn.is_empty(), "{name}: drawn, said empty"),
            Content::Within([x, y, cw, ch]) => {
                bounded += 1;
                for &(px, py) in &drawn {
                    assert!(
                        // A pixel to spare, except at the target's edges.
                        (px > x || x == 0)
                            && (py > y || y == 0)
                            && (px + 1 < x + cw || x + cw == w)
                            && (py + 1 < y + ch || y + ch == h),
                        "{name}: pixel ({px}, {py}) drawn outside [{x}, {y}, {cw}, {ch}] less a pixel"
                    );
                }
                if name.starts_with("cook-torrance") {
                    assert!(
                        u64::from(cw) * u64::from(ch) < u64::from(w) * u64::from(h) * 3 / 4,
                        "{name}: the rectangle [{x}, {y}, {cw}, {ch}] spares FXAA little"
                    );
                }
            }
        }
    }
    assert!(bounded >= 3, "only {bounded} frames had a bounded content");
}

#[test]
fn smoothing_only_the_content_changes_no_pixel() {
    // The copy at rest runs FXAA only about what the frame draws, and the
    // plain copy elsewhere: the image must be the one FXAA everywhere gives,
    // for every kind of frame and for a view drawn stretched (odd sizes).
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        egui_wgpu_options(),
    );
    let new = || LobeRenderer::new(&rs.device, Some(&rs.adapter), rs.target_format).unwrap();
    if new().samples() > 1 {
        eprintln!("skipped: this device multisamples the lobe, and its copy has no FXAA");
        return;
    }
    for (w, h) in [(240u32, 180u32), (173, 251)] {
        for (name, frame) in varied_lobe_frames(egui::vec2(w as f32, h as f32)) {
            // A renderer per frame: the frames come from different views,
            // whose mesh keys and revisions may coincide.
            let mut renderer = new();
            let mut copied = |everywhere: bool| {
                renderer.set_smooth_everywhere(everywhere);
                renderer
                    .render_copied(&rs.device, &rs.queue, &frame, w, h, 1.0)
                    .unwrap()
            };
            let (part, all) = (copied(false), copied(true));
            let differ = part
                .pixels()
                .zip(all.pixels())
                .filter(|(a, b)| a != b)
                .count();
            assert_eq!(differ, 0, "{name} at {w}x{h}: {differ} pixels differ");
            // Not vacuous: FXAA changed the image drawn.
            if name.starts_with("cook-torrance") {
                let drawn = renderer
                    .render_to_image(&rs.device, &rs.queue, &frame, w, h, 1.0)
                    .unwrap();
                let smoothed = drawn
                    .pixels()
                    .zip(all.pixels())
                    .filter(|(a, b)| a != b)
                    .count();
                assert!(smoothed > 20, "{name}: FXAA changed {smoothed} pixels");
            }
        }
    }
}

/// Timing of the offscreen lobe pass alone (not a pass/fail test: run with
/// `cargo test --release --test suite -- --ignored --nocapture gui::lobe_pass_timing`).
#[test]
#[ignore]
fn lobe_pass_timing() {
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        egui_wgpu_options(),
    );
    let mut renderer = LobeRenderer::new(&rs.device, Some(&rs.adapter), rs.target_format).unwrap();
    let mut s = LobeOnly::new("lambert", serde_json::json!({}));
    for (w, h) in [(510u32, 680u32), (255, 340)] {
        let mut times = Vec::new();
        for k in 0..30 {
            s.state.incident.theta_deg = 10.0 + k as f64;
            let scene = build_scene(&s.state, &s.runtime, true);
            let frame = s.view.frame(
                &scene,
                egui::vec2(w as f32, h as f32),
                [0.1, 0.1, 0.1, 1.0],
                true,
            );
            let mut f = (*frame).clone();
            f.interacting = false;
            let t = std::time::Instant::now();
            renderer
                .render_to_image(&rs.device, &rs.queue, &f, w, h, 1.0)
                .unwrap();
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "{w}x{h} samples {}: median {:.1} ms",
            renderer.samples(),
            times[times.len() / 2]
        );
    }
}

#[test]
fn shift_drag_on_the_lobe_moves_the_light() {
    let mut h = viewer(AppState::first_run());
    let rect = lobe(&h).view_rect.unwrap();
    let cam = bv::views::camera::CameraMatrices::new(
        &h.state().state().camera,
        rect.width(),
        rect.height(),
    );
    let at = |theta_deg: f64, phi_deg: f64| {
        let w =
            bv_core::frame::from_spherical(theta_deg.to_radians(), phi_deg.to_radians()).as_vec3();
        let s = cam.project(w).unwrap();
        rect.min + egui::vec2(s[0], s[1])
    };
    let (from, to) = (at(20.0, 90.0), at(60.0, 120.0));
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::SHIFT));
    h.hover_at(from);
    h.run();
    h.event(egui::Event::PointerButton {
        pos: from,
        button: egui::PointerButton::Primary,
        pressed: true,
        modifiers: egui::Modifiers::SHIFT,
    });
    h.run();
    for k in 1..=4 {
        h.hover_at(from + (to - from) * (k as f32 / 4.0));
        h.run();
    }
    h.event(egui::Event::PointerButton {
        pos: to,
        button: egui::PointerButton::Primary,
        pressed: false,
        modifiers: egui::Modifiers::SHIFT,
    });
    h.event(egui::Event::ModifiersChanged(egui::Modifiers::NONE));
    h.run();
    let inc = h.state().state().incident;
    assert!(
        (inc.theta_deg - 60.0).abs() < 1.0 && (inc.phi_deg - 120.0).abs() < 1.0,
        "{inc:?}"
    );
    // The camera did not orbit: the drag went to the light.
    assert_eq!(
        h.state().state().camera,
        bv::session::state::Camera::default()
    );
}

/// Renders the whole window in a few states into `$BV_RENDER_DIR` (default
/// `out/gui-states`) for a human to look at; not a pass/fail test. Run with
/// `cargo test --test suite -- --ignored gui::render_window_states`.
#[test]
#[ignore]
fn render_window_states() {
    let dir = std::env::var("BV_RENDER_DIR").unwrap_or_else(|_| "out/gui-states".into());
    std::fs::create_dir_all(&dir).unwrap();
    let models: Vec<&str> = ["cook-torrance", "lambert", "ward"]
        .into_iter()
        .filter(|m| bv_core::find(m).is_ok())
        .collect();
    let mut state = AppState::default();
    for m in &models {
        state.add(bv_core::ModelSpec::new(m).unwrap());
    }
    state.selected = state.brdfs.first().map(|b| b.id);
    let variants: Vec<(&str, Vec<Command>)> = vec![
        ("default", vec![]),
        ("log_cos", vec![Command::ToggleLog, Command::ToggleCosine]),
        ("wireframe", vec![Command::ToggleWireframe]),
        (
            "light",
            vec![Command::SetTheme(bv::session::state::Theme::Light)],
        ),
        ("help", vec![Command::ToggleHelp]),
        ("lobe_max", vec![Command::Maximise(Some("lobe".into()))]),
        (
            "theta_h",
            vec![Command::SetCartesianAxis(
                bv::session::state::CartesianAxis::ThetaH,
            )],
        ),
    ];
    for (name, cmds) in variants {
        let mut h = gpu_builder()
            .with_size(SIZE)
            .with_max_steps(12)
            .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state.clone()));
        for c in cmds {
            h.state_mut().push(c);
        }
        h.run();
        let img = h.render().unwrap();
        img.save(format!("{dir}/{name}.png")).unwrap();
    }
}

#[test]
fn lobe_view_shaders_validate() {
    // The WGSL wgpu gets: composed by the shader library (the colour map
    // table imported from its generated module).
    let mut lib = bv::gpu::shaders::ShaderLibrary::new().unwrap();
    for name in ["lobe", "lines", "blit"] {
        let src = lib.wgsl(name).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        let module = naga::front::wgsl::parse_str(&src)
            .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)));
        naga::valid::Validator::new(
            naga::valid::ValidationFlags::all(),
            naga::valid::Capabilities::default(),
        )
        .validate(&module)
        .unwrap_or_else(|e| panic!("{name}: {}", e.emit_to_string(&src)));
    }
}

// ---- Typing into fields, shortcuts, double-click reset, save dialog, log plot ----

/// The key a character is typed with (as winit reports it), if it has one.
fn key_of(c: char) -> Option<egui::Key> {
    match c {
        '.' => Some(egui::Key::Period),
        '-' => Some(egui::Key::Minus),
        ',' => Some(egui::Key::Comma),
        _ => egui::Key::from_name(&c.to_string()),
    }
}

/// The events of typing `text` on a keyboard: each character's key down,
/// its text, its key up.
fn typing(text: &str) -> Vec<egui::Event> {
    let mut out = Vec::new();
    for c in text.chars() {
        let key = key_of(c);
        let ev = |pressed| egui::Event::Key {
            key: key.unwrap(),
            physical_key: None,
            pressed,
            repeat: false,
            modifiers: egui::Modifiers::NONE,
        };
        if key.is_some() {
            out.push(ev(true));
        }
        out.push(egui::Event::Text(c.to_string()));
        if key.is_some() {
            out.push(ev(false));
        }
    }
    out
}

/// Types `text` one event per frame (a slow typist).
fn type_slowly(h: &mut Harness<'_, Viewer>, text: &str) {
    for e in typing(text) {
        h.event(e);
        h.run();
    }
}

/// Types `text` with all its events in one frame (a fast typist on a slow
/// renderer).
fn type_fast<S>(h: &mut Harness<'_, S>, text: &str) {
    h.input_mut().events.extend(typing(text));
    h.step();
    h.run();
}

fn alpha_x(h: &Harness<'_, Viewer>) -> f64 {
    h.state().state().brdfs[0]
        .spec
        .params()
        .float("alpha_x")
        .unwrap()
}

fn cook_torrance() -> AppState {
    let mut s = AppState::default();
    s.add(bv_core::ModelSpec::new("cook-torrance").unwrap());
    s
}

fn field_text(h: &Harness<'_, Viewer>, label: &str) -> String {
    h.get_by_role_and_label(Role::TextInput, label)
        .value()
        .unwrap_or_default()
}

#[test]
fn a_typed_value_is_not_clamped_until_enter() {
    // α x accepts 0.001 … 2: the "0" typed first is below the minimum, and
    // must not become 0.001 while the user is still typing "0.4".
    for fast in [false, true] {
        let mut h = viewer(cook_torrance());
        assert_eq!(alpha_x(&h), 0.3);
        h.get_by_role_and_label(Role::TextInput, "α x value")
            .click();
        h.run();
        assert!(
            h.get_by_role_and_label(Role::TextInput, "α x value")
                .is_focused()
        );
        if fast {
            type_fast(&mut h, "0.4");
        } else {
            type_slowly(&mut h, "0.4");
        }
        assert_eq!(field_text(&h, "α x value"), "0.4", "fast: {fast}");
        assert_eq!(alpha_x(&h), 0.3, "nothing is applied before Enter");
        h.key_press(egui::Key::Enter);
        h.run();
        assert_eq!(alpha_x(&h), 0.4, "fast: {fast}");
        assert_eq!(field_text(&h, "α x value"), "0.4");
    }
}

#[test]
fn a_bad_entry_stays_red_until_fixed_and_escape_reverts() {
    let mut h = viewer(cook_torrance());
    h.get_by_role_and_label(Role::TextInput, "α x value")
        .click();
    h.run();
    type_slowly(&mut h, "5");
    h.key_press(egui::Key::Enter);
    h.run();
    // 5 is outside 0.001 … 2: refused, kept for fixing, still focused.
    assert_eq!(alpha_x(&h), 0.3);
    let f = h.get_by_role_and_label(Role::TextInput, "α x value");
    assert_eq!(f.value().as_deref(), Some("5"));
    assert!(f.is_focused());
    // The range is said next to it.
    assert!(
        h.query_by_label_contains(
            "Not a number in 0.001 … 2: type one and press Enter, or Esc to keep 0.3"
        )
        .is_some()
    );
    // Escape: the value stays 0.3 and the field shows it again.
    h.key_press(egui::Key::Escape);
    h.run();
    assert_eq!(alpha_x(&h), 0.3);
    assert_eq!(field_text(&h, "α x value"), "0.3");
    assert_eq!(h.state().state().maximised, None, "Esc was the field's");
}

#[test]
fn digits_typed_into_a_field_maximise_no_view() {
    for fast in [false, true] {
        let mut h = viewer(cook_torrance());
        h.get_by_role_and_label(Role::TextInput, "α x value")
            .click();
        h.run();
        if fast {
            type_fast(&mut h, "123456789");
        } else {
            type_slowly(&mut h, "123456789");
        }
        assert_eq!(h.state().state().maximised, None, "fast: {fast}");
        // Letters are the field's too (L would toggle the log scale).
        type_slowly(&mut h, "lctw");
        let s = h.state().state();
        assert!(!s.display.log && !s.display.cosine && !s.display.wireframe);
        assert_eq!(s.theme, AppState::default().theme);
        assert_eq!(field_text(&h, "α x value"), "123456789lctw");
        // Escape gives the keyboard back; then 2 maximises view 2.
        h.key_press(egui::Key::Escape);
        h.run();
        assert_eq!(alpha_x(&h), 0.3);
        h.key_press(egui::Key::Num2);
        h.run();
        assert_eq!(
            h.state().state().maximised.as_deref(),
            Some(bv::views::REGISTRY[1].id)
        );
    }
}

#[test]
fn enter_then_digits_in_one_frame_stay_with_the_field() {
    // A fast typist: "0.5", Enter and "3" arrive in one frame; the 3 must not
    // maximise view 3.
    let mut h = viewer(cook_torrance());
    h.get_by_role_and_label(Role::TextInput, "α x value")
        .click();
    h.run();
    let mut events = typing("0.5");
    events.push(egui::Event::Key {
        key: egui::Key::Enter,
        physical_key: None,
        pressed: true,
        repeat: false,
        modifiers: egui::Modifiers::NONE,
    });
    events.extend(typing("3"));
    h.input_mut().events.extend(events);
    h.step();
    h.run();
    assert_eq!(alpha_x(&h), 0.5);
    assert_eq!(h.state().state().maximised, None);
}

/// Double-clicks at `pos` (the harness's steps must be short enough for
/// egui to see a double click: see `viewer_quick`).
fn double_click(h: &mut Harness<'_, Viewer>, pos: egui::Pos2) {
    // Half a second after any earlier click, so that this one is not
    // counted as the second of a pair.
    h.run_steps(25);
    h.hover_at(pos);
    h.run();
    for pressed in [true, false, true, false] {
        h.event(egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
    }
    h.run();
}

/// A viewer harness whose frames are 20 ms apart (a double click is two
/// clicks within 0.3 s; the default step is 0.25 s).
fn viewer_quick(state: AppState) -> Harness<'static, Viewer> {
    let mut h = Harness::builder()
        .with_size(SIZE)
        .with_max_steps(60)
        .with_step_dt(0.02)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    h.run();
    h
}

#[test]
fn double_clicking_a_slider_resets_it() {
    let mut h = viewer_quick(cook_torrance());
    let id = first_id(&h);
    h.state_mut().push(Command::SetParam {
        brdf: id,
        param: "alpha_x".into(),
        value: bv_core::ParamValue::Float(0.05),
    });
    h.state_mut()
        .push(Command::SetIncident(bv::session::state::Incident {
            theta_deg: 12.0,
            phi_deg: 34.0,
        }));
    h.run();
    assert_eq!(alpha_x(&h), 0.05);
    // Off-centre, so that the click's own move of the slider is not the default.
    let r = h.get_by_role_and_label(Role::Slider, "α x").rect();
    double_click(&mut h, r.left_center() + egui::vec2(r.width() * 0.2, 0.0));
    assert_eq!(alpha_x(&h), 0.3, "α x back to its default");
    // A single click moves it, and does not reset.
    let p = r.left_center() + egui::vec2(r.width() * 0.8, 0.0);
    h.hover_at(p);
    h.run();
    h.drag_at(p);
    h.run();
    h.drop_at(p);
    h.run();
    assert!(alpha_x(&h) > 0.3, "{}", alpha_x(&h));

    // The light's sliders too.
    let r = h.get_by_role_and_label(Role::Slider, "θi").rect();
    double_click(&mut h, r.left_center() + egui::vec2(r.width() * 0.9, 0.0));
    let inc = h.state().state().incident;
    assert_eq!(
        inc.theta_deg,
        bv::session::state::Incident::default().theta_deg
    );
    let r = h.get_by_role_and_label(Role::Slider, "φi").rect();
    double_click(&mut h, r.left_center() + egui::vec2(r.width() * 0.1, 0.0));
    let inc = h.state().state().incident;
    assert_eq!(inc, bv::session::state::Incident::default());
}

/// A save dialog alone, in a folder of its own.
struct SaveDialog {
    files: bv::widgets::files::Files<()>,
    chosen: Option<std::path::PathBuf>,
}

impl SaveDialog {
    fn ui(&mut self, ui: &mut egui::Ui) {
        if let Some(((), p)) = self.files.show(ui.ctx()) {
            self.chosen = Some(p);
        }
    }
}

fn name_field<'a>(h: &'a Harness<'_, SaveDialog>, name: &str) -> egui_kittest::Node<'a> {
    h.query_all(by().role(Role::TextInput))
        .find(|n| n.value().as_deref() == Some(name))
        .unwrap_or_else(|| panic!("no text field holding `{name}`"))
}

#[test]
fn the_save_dialog_types_digits_and_asks_before_replacing() {
    let dir = std::env::temp_dir().join(format!("bv-gui-save-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&dir);
    std::fs::create_dir_all(&dir).unwrap();
    for name in ["1.toml", "12.toml", "2.toml", "scene.toml"] {
        std::fs::write(dir.join(name), format!("# {name}\n")).unwrap();
    }
    let mut files = bv::widgets::files::Files::default();
    files.set_start_dir(&dir);
    // egui_file's text fields have no accessible names; its title starts
    // with an emoji that egui's fonts lack.
    let mut h = Harness::builder()
        .with_size(SIZE)
        .with_accessibility_check(false)
        .build_ui_state(
            |ui, s: &mut SaveDialog| s.ui(ui),
            SaveDialog {
                files,
                chosen: None,
            },
        );
    h.ctx
        .set_missing_glyph_policy(egui::MissingGlyphPolicy::Tofu);
    h.state_mut()
        .files
        .save((), "Save the scene", bv::widgets::files::SCENE, "talk");
    h.run();
    name_field(&h, "talk").click();
    h.run();
    // Typed digits only type: the name reads "talk12", no listed file is
    // picked up as the name.
    type_fast(&mut h, "12");
    name_field(&h, "talk12");
    assert!(h.state().chosen.is_none());
    // Saving under a new name needs no question.
    h.key_press(egui::Key::Enter);
    h.run();
    assert_eq!(
        h.state().chosen.as_deref(),
        Some(dir.join("talk12.toml").as_path())
    );

    // Over an existing file: asked first; Cancel goes back with the name kept.
    h.state_mut().chosen = None;
    h.state_mut()
        .files
        .save((), "Save the scene", bv::widgets::files::SCENE, "");
    h.run();
    name_field(&h, "").click();
    h.run();
    type_fast(&mut h, "12");
    h.key_press(egui::Key::Enter);
    h.run();
    assert!(h.state().chosen.is_none(), "not without asking");
    assert!(h.query_by_label("12.toml exists. Replace?").is_some());
    h.get_by_label("Cancel").click();
    h.run();
    assert!(h.state().chosen.is_none());
    assert!(h.query_by_label("12.toml exists. Replace?").is_none());
    name_field(&h, "12");
    // Asked again, and Replace.
    name_field(&h, "12").click();
    h.run();
    h.key_press(egui::Key::Enter);
    h.run();
    h.get_by_label("Replace").click();
    h.run();
    assert_eq!(
        h.state().chosen.as_deref(),
        Some(dir.join("12.toml").as_path())
    );
    // The dialog writes nothing itself.
    assert_eq!(
        std::fs::read_to_string(dir.join("12.toml")).unwrap(),
        "# 12.toml\n"
    );
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn digits_typed_in_the_viewers_save_dialog_maximise_no_view() {
    // egui_file's text fields have no accessible names; its title starts
    // with an emoji that egui's fonts lack.
    let mut h = Harness::builder()
        .with_size(SIZE)
        .with_max_steps(12)
        .with_accessibility_check(false)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(cook_torrance()));
    h.ctx
        .set_missing_glyph_policy(egui::MissingGlyphPolicy::Tofu);
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    h.run();
    let field = h
        .query_all(by().role(Role::TextInput))
        .find(|n| n.value().as_deref() == Some("scene.toml"))
        .expect("the save dialog's name field");
    field.click();
    h.run();
    type_fast(&mut h, "123");
    type_slowly(&mut h, "45");
    assert_eq!(h.state().state().maximised, None);
    // Before the field is clicked, keys do not reach the views either.
    h.key_press(egui::Key::Escape);
    h.run();
    h.key_press_modifiers(egui::Modifiers::COMMAND, egui::Key::S);
    h.run();
    type_slowly(&mut h, "3l");
    assert_eq!(h.state().state().maximised, None);
    assert!(!h.state().state().display.log);
}

#[test]
fn the_log_plot_reaches_down_to_what_the_data_reach() {
    // A specular lobe alone: far from the mirror direction Beckmann's D
    // falls to ~1e-27 (`bv slice` reads the same numbers).
    let mut state = AppState::default();
    state.add(
        bv_core::ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"kd": 0.0, "alpha_x": 0.1, "alpha_y": 0.1}),
        )
        .unwrap(),
    );
    state.incident.theta_deg = 30.0;
    state.display.log = true;
    let h = viewer(state);
    let v = h.state().view::<CartesianView>().unwrap();
    let (bottom, top) = v.y_bounds.expect("the plot was drawn");
    let b = h
        .state()
        .runtime()
        .get(first_id(&h))
        .unwrap()
        .brdf
        .clone()
        .unwrap();
    let samples =
        bv::derive::slices::plane_of_incidence(b.as_ref(), 30f64.to_radians(), 0.0, 720, false);
    let max = samples.iter().map(|s| s.value).fold(0.0, f64::max);
    let min = samples
        .iter()
        .map(|s| s.value)
        .filter(|v| *v > 0.0)
        .fold(f64::INFINITY, f64::min);
    assert!(min < 1e-20, "the tail is tiny: {min}");
    // Twelve decades below the peak, a whole decade, not the old fixed
    // floor at 1e-5 of the peak.
    assert_eq!(
        bottom,
        (max.log10() - 12.0).floor(),
        "{bottom} for max {max}"
    );
    assert!(bottom < (max * 1e-5).log10() - 6.0);
    assert!(top > max.log10());
    // The chart (the same numbers as the plot, for SVG) draws every sample
    // at its true ordinate: no floor.
    let scene = build_scene(h.state().state(), h.state().runtime(), false);
    let chart = bv::views::cartesian::chart(&scene, true);
    assert_eq!(chart.y_range.0, bottom);
    let ys: Vec<f64> = chart.series[0].points.iter().map(|p| p[1]).collect();
    for (y, s) in ys.iter().zip(&samples) {
        if s.value > 0.0 {
            assert!((y - s.value.log10()).abs() < 1e-9, "{y} vs {}", s.value);
        }
    }
    assert!(
        ys.iter().any(|y| *y < bottom),
        "the tail leaves through the bottom"
    );
    // Decades are labelled as decades.
    for (at, label) in &chart.y_ticks {
        assert_eq!(at.fract(), 0.0);
        assert_eq!(*label, bv::views::decade_label(*at as i32));
    }
}

#[test]
fn tab_and_a_click_elsewhere_commit_a_typed_value() {
    let mut h = viewer(AppState::first_run());
    let albedo = |h: &Harness<'_, Viewer>| {
        h.state().state().brdfs[0]
            .spec
            .params()
            .color("albedo")
            .unwrap()
    };
    h.get_by_role_and_label(Role::TextInput, "albedo R").click();
    h.run();
    type_fast(&mut h, "0.9");
    assert_eq!(albedo(&h).x, 0.5);
    // Tab: committed, the focus on G.
    h.key_press(egui::Key::Tab);
    h.run();
    assert_eq!(albedo(&h).x, 0.9);
    assert!(
        h.get_by_role_and_label(Role::TextInput, "albedo G")
            .is_focused()
    );
    type_fast(&mut h, "0.2");
    // A click on an empty part of the panel, below the parameters.
    let p = egui::pos2(150.0, SIZE[1] - 30.0);
    h.hover_at(p);
    h.drag_at(p);
    h.drop_at(p);
    h.run();
    assert_eq!(albedo(&h).y, 0.2);
}

#[test]
fn a_brdf_is_renamed_its_model_changed_and_angles_read_in_degrees() {
    let mut s = AppState::default();
    let id = s.add(
        bv_core::ModelSpec::from_json("oren-nayar", &serde_json::json!({"sigma": 0.5})).unwrap(),
    );
    s.selected = Some(id);
    let mut h = viewer(s);
    // σ is declared and stored in radians, and read in degrees: 0.5 rad is
    // 28.648°.
    let shown = field_text(&h, "σ value");
    assert!(shown.starts_with("28.6"), "σ shows {shown}");
    // A name typed into the panel becomes the legend's name on Enter.
    h.get_by_role_and_label(Role::TextInput, "Name of Oren-Nayar")
        .click();
    h.run();
    type_fast(&mut h, "rough clay");
    h.key_press(egui::Key::Enter);
    h.run();
    let e = &h.state().state().brdfs[0];
    assert_eq!(e.name.as_deref(), Some("rough clay"));
    assert_eq!(
        bv::session::naming::display_name(h.state().state(), e),
        "rough clay"
    );
    // The model drop-down keeps the shared parameter (albedo) and the name.
    let albedo = e.spec.params().color("albedo").unwrap();
    h.state_mut()
        .push(Command::ChangeModel(id, "lambert".into()));
    h.run();
    let e = &h.state().state().brdfs[0];
    assert_eq!(e.spec.id(), "lambert");
    assert_eq!(e.spec.params().color("albedo").unwrap(), albedo);
    assert_eq!(e.name.as_deref(), Some("rough clay"));
}
