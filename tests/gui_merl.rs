//! Measured BRDFs in the viewer window, with
//! egui_kittest: a table dropped on the window is read in the background and
//! appears as a BRDF with its lobe; a bad file shows the reader's message in a
//! dialog and changes nothing; the image slice view draws and follows φd; the
//! SH control adds the reconstruction to the lobe view with its error; a
//! table is compared with the analytic model it was tabulated from.
//!
//! `snapshot_image_slice` renders on the GPU (lavapipe without one) and
//! compares with `tests/snapshots/image_slice_cook_torrance.png`
//! (regenerate with `UPDATE_SNAPSHOTS=1 cargo test --test suite gui_merl::`).

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::session::Command;
use bv::session::build_scene;
use bv::session::runtime::Runtime;
use bv::session::state::AppState;
use bv::views::image_slice::ImageSliceView;
use bv::views::lobe3d::Lobe3dView;
use bv::views::polar::PolarView;
use bv::views::{Scene, View};
use bv_core::ModelSpec;
use bv_core::measured::merl::{MerlDims, tabulate};
use eframe::egui::{self, Role};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::Duration;

const SIZE: [f32; 2] = [1280.0, 800.0];

fn viewer(state: AppState) -> Harness<'static, Viewer> {
    let mut h = Harness::builder()
        .with_size(SIZE)
        .with_max_steps(12)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    h.run();
    h
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-gui-merl-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn cook_torrance() -> ModelSpec {
    ModelSpec::from_json(
        "cook-torrance",
        &serde_json::json!({"kd": [0.1, 0.15, 0.2], "ks": 0.8, "distribution": "ggx", "alpha": 0.3}),
    )
    .unwrap()
}

/// Writes `spec` tabulated at `dims` to `path`.
fn write_table(spec: &ModelSpec, dims: [i64; 3], path: &Path) {
    let d = MerlDims::new(dims[0], dims[1], dims[2]).unwrap();
    tabulate(spec.build().unwrap().as_ref(), d)
        .unwrap()
        .write(path)
        .unwrap();
}

/// A dropped file, as the windowing integration hands it to egui.
#[derive(Debug)]
struct Dropped(PathBuf);

impl egui::DroppedFile for Dropped {
    fn path(&self) -> &Path {
        &self.0
    }
    fn bytes(&self) -> Result<Vec<u8>, String> {
        std::fs::read(&self.0).map_err(|e| e.to_string())
    }
}

/// Drops `path` on the window and lets the background read finish.
fn drop_file(h: &mut Harness<'_, Viewer>, path: &Path) {
    h.input_mut()
        .dropped_files
        .push(Arc::new(Dropped(path.to_path_buf())));
    // One frame takes the drop and starts the read; while it runs the window
    // keeps repainting (the progress bar), so wait rather than `run`.
    h.step();
    assert!(h.state().loader().busy(), "the read started");
    assert!(h.state_mut().wait_for_loads(Duration::from_secs(60)));
    h.run();
}

fn lobe<'a>(h: &'a Harness<'_, Viewer>) -> &'a Lobe3dView {
    h.state().view::<Lobe3dView>().unwrap()
}

#[test]
fn a_dropped_table_becomes_a_merl_brdf_with_its_lobe() {
    let dir = temp_dir("drop");
    let path = dir.join("ct.binary");
    write_table(&cook_torrance(), [16, 16, 32], &path);

    let mut state = AppState::default();
    state.add(cook_torrance());
    let mut h = viewer(state);
    drop_file(&mut h, &path);

    let s = h.state().state();
    assert_eq!(
        s.brdfs.len(),
        2,
        "the analytic model stays, the table is added"
    );
    let e = &s.brdfs[1];
    assert_eq!(e.spec.id(), "merl");
    let canon = std::fs::canonicalize(&path).unwrap();
    assert_eq!(
        e.spec.params().text("path").unwrap(),
        canon.display().to_string()
    );
    assert_eq!(s.selected, Some(e.id));
    let id = e.id;
    // It has a lobe, of the size of the model it came from.
    let m = lobe(&h).mesh(id).expect("lobe mesh of the table");
    let a = lobe(&h).mesh(s.brdfs[0].id).unwrap();
    assert!(m.max_value > 0.0);
    assert!(
        (m.max_value / a.max_value - 1.0).abs() < 0.3,
        "{} vs {}",
        m.max_value,
        a.max_value
    );
    // Named after its file, with its table described in the panel.
    h.get_by_label("Remove ct (MERL)");
    h.get_by_label_contains("16×16×32 cells");
    h.get_by_label_contains("no unmeasured or NaN samples");
    h.get_by_label_contains("read ct.binary");
    assert!(h.state().load_errors().is_empty());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn a_bad_file_shows_the_reader_message_and_keeps_everything() {
    let dir = temp_dir("bad");
    let good = dir.join("good.binary");
    write_table(&cook_torrance(), [8, 8, 16], &good);
    let bad = dir.join("broken.binary");
    // A header promising the public size, and nothing after it.
    let mut bytes = Vec::new();
    for d in [90i32, 90, 180] {
        bytes.extend_from_slice(&d.to_le_bytes());
    }
    std::fs::write(&bad, &bytes).unwrap();

    let mut state = AppState::default();
    state.add(cook_torrance());
    let mut h = viewer(state);
    drop_file(&mut h, &good);
    let before = h.state().state().clone();
    assert_eq!(before.brdfs.len(), 2);
    // The merl BRDF is selected; a dropped file would replace its table only
    // if it had none, so this one is opened as a new BRDF, and refused.
    drop_file(&mut h, &bad);
    assert_eq!(h.state().state(), &before, "nothing changed");
    assert_eq!(h.state().load_errors().len(), 1);
    h.get_by_label("Could not open the file");
    let msg = h.get_by_label_contains("size mismatch");
    let text = format!("{msg:?}");
    assert!(text.contains("90×90×180"), "{text}");
    // Typing the bad path into the table's file field is refused the same way.
    h.get_by_label("OK").click();
    h.run();
    assert!(h.query_by_label("Could not open the file").is_none());
    assert!(h.state().load_errors().is_empty());
    let id = before.brdfs[1].id;
    h.state_mut().push(Command::OpenFile {
        path: bad.display().to_string(),
        into: Some(id),
    });
    h.step();
    assert!(h.state_mut().wait_for_loads(Duration::from_secs(60)));
    h.run();
    assert_eq!(h.state().state(), &before, "the table keeps its file");
    h.get_by_label("Could not open the file");
    // Its lobe is still drawn.
    assert!(lobe(&h).mesh(id).is_some());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn the_load_button_opens_a_file_dialog() {
    // egui_file draws emoji icons that egui's bundled fonts lack (tofu).
    let mut h = Harness::builder()
        .with_size(SIZE)
        .with_max_steps(12)
        .allow_missing_glyphs()
        // egui_file's text fields have no accessible names.
        .with_accessibility_check(false)
        .build_ui_state(
            |ui, v: &mut Viewer| v.ui(ui),
            Viewer::new(AppState::first_run()),
        );
    h.run();
    h.get_by_label("Load MERL…").click();
    h.run();
    assert!(h.state().dialog_open());
    h.get_by_label_contains("Open a MERL table (.binary) or a BRDF file (.brdf)");
    h.key_press(egui::Key::Escape);
    h.run();
    assert!(!h.state().dialog_open());
}

#[test]
fn the_image_slice_follows_phi_d() {
    let mut state = AppState::default();
    state.add(cook_torrance());
    // Maximised: in the default layout the view may be too small to draw.
    state.maximised = Some("slice".into());
    let mut h = viewer(state);
    let id = h.state().state().brdfs[0].id;
    let slice = |h: &Harness<'_, Viewer>| {
        h.state()
            .view::<ImageSliceView>()
            .unwrap()
            .data(id)
            .unwrap()
            .clone()
    };
    let a = slice(&h);
    assert_eq!(a.width, 256);
    // Not blank: the specular peak at θh = 0 is far above the diffuse floor.
    assert!(a.max_luminance() > 10.0 * a.luminance_quantile(0.1));
    // At φd = 90° no direction goes below the horizon.
    assert!(a.values.iter().all(Option::is_some));
    // Drag the φd slider to the left end: φd = 0, where θh + θd > 90° is
    // below the horizon.
    let r = h.get_by_role_and_label(Role::Slider, "φd").rect();
    h.drag_at(r.center());
    h.run();
    h.hover_at(r.left_center() - egui::vec2(40.0, 0.0));
    h.run();
    h.drop_at(r.left_center() - egui::vec2(40.0, 0.0));
    h.run();
    let phi = h
        .state()
        .view::<ImageSliceView>()
        .unwrap()
        .settings
        .phi_d_deg;
    assert_eq!(phi, 0.0);
    // The edit is the scene's (saved with it, undone with it).
    assert_eq!(h.state().state().plots.slice.phi_d_deg, 0.0);
    let b = slice(&h);
    assert_ne!(a.values, b.values);
    let below = b.values.iter().filter(|v| v.is_none()).count();
    assert!(below > 256 * 256 / 3, "{below}");
}

#[test]
fn the_sh_control_overlays_the_reconstruction_with_its_error() {
    let mut state = AppState::default();
    state.add(cook_torrance());
    let mut h = viewer(state);
    let meshes = |h: &Harness<'_, Viewer>| lobe(h).last_frame().unwrap().meshes.len();
    let before = meshes(&h);
    assert!(h.query_by_label("SH order L").is_none());
    h.get_all_by_label("SH").next().unwrap().click();
    h.run();
    assert!(h.state().state().display.sh_overlay);
    assert!(bv::derive::sh::wait_idle());
    h.run();
    h.run();
    let done = lobe(&h).sh_result().expect("SH result");
    let r = done.value.as_ref().unwrap();
    assert_eq!(r.lobe.order, 4);
    let e4 = r.lobe.rel_l2_error;
    assert!(e4 > 0.0 && e4 < 1.0, "{e4}");
    assert_eq!(
        meshes(&h),
        before + 1,
        "the reconstruction is one more mesh"
    );
    assert!(
        h.state()
            .view::<PolarView>()
            .unwrap()
            .sh_curve
            .as_ref()
            .is_some_and(|c| c.len() > 100),
        "the polar plot has the dashed curve"
    );
    // The error is shown as a number (in both views' toolbars).
    let labels = h
        .get_all_by_label_contains("relative L2 error")
        .map(|n| format!("{n:?}"))
        .collect::<Vec<_>>();
    assert_eq!(labels.len(), 2, "{labels:?}");
    assert!(labels[0].contains("SH L = 4"), "{labels:?}");

    // A higher order through the state: a smaller error.
    let d = h.state().state().display;
    h.state_mut()
        .push(Command::SetDisplay(bv::session::state::Display {
            sh_order: 12,
            ..d
        }));
    h.run();
    assert!(bv::derive::sh::wait_idle());
    h.run();
    h.run();
    let r12 = lobe(&h).sh_result().unwrap();
    let e12 = r12.value.as_ref().unwrap().lobe.rel_l2_error;
    assert_eq!(r12.key.order, 12);
    assert!(e12 < e4, "{e12} vs {e4}");
    h.get_all_by_label_contains("SH L = 12").next().unwrap();
}

#[test]
fn a_table_is_compared_with_the_model_it_came_from() {
    let dir = temp_dir("compare");
    let path = dir.join("ct45.binary");
    write_table(&cook_torrance(), [45, 45, 90], &path);
    let mut state = AppState::default();
    state.add(cook_torrance());
    let mut h = viewer(state);
    drop_file(&mut h, &path);
    h.get_by_label("Compare with").click();
    h.run();
    // The option inside the open combo box (the list has an entry of that name too).
    h.get_by_label("Compare with")
        .get_by_label("Cook-Torrance")
        .click();
    h.run();
    assert!(bv::app::measured_ui::wait_compare_idle());
    h.run();
    h.run();
    let shown = |h: &Harness<'_, Viewer>| -> f64 {
        let node = h.get_by_label_contains("relative L2 difference to Cook-Torrance");
        let text = format!("{node:?}");
        text.split("Cook-Torrance: ")
            .nth(1)
            .and_then(|t| t.split(" %").next())
            .and_then(|t| t.trim().parse().ok())
            .unwrap_or_else(|| panic!("no number in {text}"))
    };
    // Of f itself the difference is a few percent, dominated by grazing
    // directions where f is large and the table's last cells blend with the
    // zeros below the horizon (measured 5.5 %)...
    let f = shown(&h);
    assert!(f > 0.5 && f < 10.0, "{f}");
    // ... and of f cos θo, what the reflected light sees, a fraction of a
    // percent (bv-core's own tabulation test measures 0.13 % at θi = 30°).
    h.state_mut().push(Command::ToggleCosine);
    h.run();
    assert!(bv::app::measured_ui::wait_compare_idle());
    h.run();
    h.run();
    let fcos = shown(&h);
    assert!(fcos > 0.0 && fcos < 0.5 && fcos < f, "{fcos} vs {f}");
    std::fs::remove_dir_all(&dir).unwrap();
}

// --- GPU snapshot -----------------------------------------------------------

fn gpu_builder<S>() -> egui_kittest::HarnessBuilder<S> {
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        eframe::egui_wgpu::RendererOptions::PREDICTABLE,
    );
    bv::views::lobe_gpu::install(&rs);
    Harness::builder().renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(rs))
}

/// Just the image slice view over a state.
struct SliceOnly {
    state: AppState,
    runtime: Runtime,
    view: ImageSliceView,
}

impl SliceOnly {
    fn ui(&mut self, ui: &mut egui::Ui) {
        let scene: Scene<'_> = build_scene(&self.state, &self.runtime, false);
        let mut out = Vec::new();
        egui::CentralPanel::default().show(ui, |ui| self.view.ui(ui, &scene, &mut out));
    }
}

#[test]
fn snapshot_image_slice() {
    let mut state = AppState::default();
    state.add(cook_torrance());
    let mut runtime = Runtime::default();
    runtime.sync(&state);
    let mut h = gpu_builder().with_size([360.0, 340.0]).build_ui_state(
        |ui, s: &mut SliceOnly| s.ui(ui),
        SliceOnly {
            state,
            runtime,
            view: ImageSliceView::default(),
        },
    );
    h.run();
    let rect = h.state().view.image_rects[0].1;
    let img = h.render().expect("render");
    // Non-blank: the image area holds many distinct colours.
    let mut colours = std::collections::HashSet::new();
    let ppp = 1.0; // the harness renders at 1 pixel per point
    for y in (rect.min.y as u32 + 2..rect.max.y as u32 - 2).step_by(3) {
        for x in (rect.min.x as u32 + 2..rect.max.x as u32 - 2).step_by(3) {
            let p = img
                .get_pixel((x as f32 * ppp) as u32, (y as f32 * ppp) as u32)
                .0;
            colours.insert(p);
        }
    }
    assert!(colours.len() > 50, "{} colours", colours.len());
    h.snapshot_options(
        "image_slice_cook_torrance",
        &egui_kittest::SnapshotOptions::new()
            .threshold(2.0)
            .max_failed_pixels(200),
    );
    // A different φd gives a different picture.
    h.state_mut().view.settings.phi_d_deg = 20.0;
    h.run();
    let img2 = h.render().unwrap();
    let differ = img
        .pixels()
        .zip(img2.pixels())
        .filter(|(a, b)| a != b)
        .count();
    assert!(differ > 1000, "{differ} pixels changed");
}

/// Timings for the record (not a pass/fail test; machines are noisy):
/// `cargo test --release --test suite gui_merl::timings -- --ignored --nocapture`.
/// A public-size table read through the GUI's background loader, a 256 × 256
/// image slice of the analytic model and of its table, and the SH projection
/// at L = 16 of both.
#[test]
#[ignore]
fn timings() {
    use bv::session::loader::{LoadTarget, Loader};
    use std::time::Instant;
    let dir = temp_dir("timings");
    let path = dir.join("ct.binary");
    let ct = ModelSpec::from_json("cook-torrance", &serde_json::json!({"alpha": 0.2})).unwrap();
    write_table(&ct, [90, 90, 180], &path);
    let mut loader = Loader::default();
    let t0 = Instant::now();
    loader.start(path.clone(), LoadTarget::New);
    let mut last = (0, 0);
    let mut updates = 0;
    while loader.busy() {
        if let Some(j) = loader.jobs().first()
            && j.progress() != last
        {
            updates += 1;
            last = j.progress();
        }
        if !loader.poll().is_empty() {
            break;
        }
        std::thread::sleep(Duration::from_millis(1));
    }
    println!(
        "load 35 MB through the loader: {:.0} ms ({updates} progress values seen, polling every ms)",
        t0.elapsed().as_secs_f64() * 1e3
    );
    let analytic = ct.build().unwrap();
    let merl = ModelSpec::from_json("merl", &serde_json::json!({"path": path.to_str().unwrap()}))
        .unwrap()
        .build()
        .unwrap();
    for (name, b) in [("cook-torrance", &analytic), ("merl table", &merl)] {
        let mut best = f64::INFINITY;
        for _ in 0..5 {
            let d = bv::derive::slice::compute(b.as_ref(), std::f64::consts::FRAC_PI_2, false, 256);
            best = best.min(d.seconds);
        }
        println!(
            "image slice 256×256 of {name}: {:.1} ms (best of 5)",
            best * 1e3
        );
        let key = bv::derive::sh::ShKey {
            revision: 1,
            incident: (45.0, 0.0),
            order: 16,
            cosine: false,
            log: false,
        };
        let t = Instant::now();
        let r = bv::derive::sh::compute(b.as_ref(), 1, key).unwrap();
        println!(
            "SH projection L = 16 of {name} ({} rings, mesh and curve included): {:.0} ms, error {:.1} %",
            r.lobe.n_theta,
            t.elapsed().as_secs_f64() * 1e3,
            100.0 * r.lobe.rel_l2_error
        );
    }
    std::fs::remove_dir_all(&dir).unwrap();
}
