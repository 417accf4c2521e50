//! Behaviour tests of the viewer window with egui_kittest: widgets are found by
//! their accessible labels (what a screen reader reads), driven with clicks,
//! drags and keys, and the effect is checked on the state and on the data the
//! views draw. They need no window and no GPU.
//!
//! The `snapshot_*` and `headless_*` tests render on the GPU (lavapipe on
//! machines without one) and compare small images with `tests/snapshots/`.
//! Regenerate with `UPDATE_SNAPSHOTS=1 cargo test -p bv --test gui`.

use bv::app::runtime::Runtime;
use bv::app::state::AppState;
use bv::app::viewer::build_scene;
use bv::app::{Command, Viewer};
use bv::views::cartesian::CartesianView;
use bv::views::lobe_gpu::LobeRenderer;
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
    assert_eq!(s.brdfs[1].spec.model, first.id);
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
        .params
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
    assert_eq!(e.spec, bv_core::ModelSpec::new(&e.spec.model).unwrap());
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
    h.key_press(egui::Key::F1);
    h.run();
    assert!(!h.state().help_open());
}

#[test]
fn keyboard_shortcuts_drive_the_views() {
    let mut h = viewer(AppState::first_run());
    h.state_mut()
        .push(Command::SetCamera(bv::app::state::Camera {
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
            s.camera == bv::app::state::Camera::default()
        }),
        (egui::Key::T, |s: &AppState| {
            s.theme == bv::app::state::Theme::Light
        }),
    ] {
        h.key_press(key);
        h.run();
        assert!(check(h.state().state()), "{key:?}");
    }
}

#[test]
fn every_model_gets_widgets_from_its_declaration() {
    for info in bv_core::catalogue() {
        let mut state = AppState::default();
        state.add(bv_core::ModelSpec::new(info.id).unwrap());
        let h = viewer(state);
        for decl in info.params {
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
            let wo = bv::views::curves::plane_direction(s.x, inc.phi_deg.to_radians());
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
        .push(Command::SetIncident(bv::app::state::Incident {
            theta_deg: 12.0,
            phi_deg: 34.0,
        }));
    h.state_mut().push(Command::ToggleLog);
    h.state_mut()
        .push(Command::SetCamera(bv::app::state::Camera {
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
    lobe_snapshot_from(name, model, params, bv::app::state::Camera::default());
}

fn lobe_snapshot_from(
    name: &str,
    model: &str,
    params: serde_json::Value,
    camera: bv::app::state::Camera,
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
        bv::app::state::Camera {
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
    let mut renderer = LobeRenderer::new(&rs.device, Some(&rs.adapter), rs.target_format);
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

/// Timing of the offscreen lobe pass alone (not a pass/fail test: run with
/// `cargo test --release --test gui -- --ignored --nocapture lobe_pass_timing`).
#[test]
#[ignore]
fn lobe_pass_timing() {
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        egui_wgpu_options(),
    );
    let mut renderer = LobeRenderer::new(&rs.device, Some(&rs.adapter), rs.target_format);
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
    assert_eq!(h.state().state().camera, bv::app::state::Camera::default());
}

/// Renders the whole window in a few states into `$BV_RENDER_DIR` (default
/// `out/gui-states`) for a human to look at; not a pass/fail test. Run with
/// `cargo test --test gui -- --ignored render_window_states`.
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
            vec![Command::SetTheme(bv::app::state::Theme::Light)],
        ),
        ("help", vec![Command::ToggleHelp]),
        ("lobe_max", vec![Command::Maximise(Some("lobe".into()))]),
        (
            "theta_h",
            vec![Command::SetCartesianAxis(
                bv::app::state::CartesianAxis::ThetaH,
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
    use bv::views::lobe_gpu::{BLIT_WGSL, LINES_WGSL, lobe_shader_source};
    for (name, src) in [
        ("lobe.wgsl", lobe_shader_source()),
        ("lines.wgsl", LINES_WGSL.to_string()),
        ("blit.wgsl", BLIT_WGSL.to_string()),
    ] {
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
