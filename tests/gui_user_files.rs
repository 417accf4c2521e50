//! User BRDF files in the viewer window (egui_kittest): a `.brdf` file
//! dropped on the window becomes a BRDF; saving an edit of an open file
//! reloads it within a second, keeping the parameter values that still
//! exist, and the lobe follows; a broken edit shows the compiler's message
//! with file, line and column and keeps the last working lobe.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::session::state::AppState;
use bv::views::lobe3d::Lobe3dView;
use bv_core::ModelSpec;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::path::{Path, PathBuf};
use std::sync::Arc;
use std::time::{Duration, Instant};

fn viewer(state: AppState) -> Harness<'static, Viewer> {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .with_max_steps(12)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    h.run();
    h
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-gui-user-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// A grey Lambert-like file: f = scale · k / π.
fn lambertish(scale: &str, extra_param: &str) -> String {
    format!(
        "analytic\n::begin parameters\nfloat k 0 1 0.5\n{extra_param}\n::end parameters\n::begin shader\nconst float PI = 3.14159265358979323846;\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{{\n    return vec3({scale} * k / PI);\n}}\n::end shader\n"
    )
}

fn lobe_max(h: &Harness<'_, Viewer>) -> f64 {
    let v = h.state().view::<Lobe3dView>().unwrap();
    let id = h.state().state().brdfs[0].id;
    v.mesh(id).expect("a lobe mesh").max_value
}

/// Steps the window until `done` or `limit` passes; returns the time taken.
fn step_until(
    h: &mut Harness<'_, Viewer>,
    limit: Duration,
    done: impl Fn(&Harness<'_, Viewer>) -> bool,
) -> Duration {
    let t0 = Instant::now();
    while !done(h) {
        assert!(t0.elapsed() < limit, "nothing happened within {limit:?}");
        std::thread::sleep(Duration::from_millis(10));
        let t = Instant::now();
        h.step();
        if std::env::var("BV_TRACE_STEPS").is_ok() {
            println!("step {:?} at {:?}", t.elapsed(), t0.elapsed());
        }
    }
    h.run();
    t0.elapsed()
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

#[test]
fn a_dropped_brdf_file_becomes_a_brdf() {
    bv::session::user_models::install();
    let dir = temp_dir("drop");
    let path = dir.join("dropped.brdf");
    std::fs::write(&path, lambertish("1.0", "")).unwrap();
    let mut state = AppState::default();
    state.add(ModelSpec::new("lambert").unwrap());
    let mut h = viewer(state);
    h.input_mut()
        .dropped_files
        .push(Arc::new(Dropped(path.clone())));
    h.run();
    let s = h.state().state();
    assert_eq!(s.brdfs.len(), 2);
    assert_eq!(s.brdfs[1].spec.model().name, "dropped.brdf");
    assert_eq!(s.brdfs[1].spec.params().float("k").unwrap(), 0.5);
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn saving_an_open_file_reloads_it_and_a_broken_edit_keeps_the_last_lobe() {
    bv::session::user_models::install();
    let dir = temp_dir("reload");
    let path = dir.join("edited.brdf");
    std::fs::write(&path, lambertish("1.0", "")).unwrap();
    let spec =
        ModelSpec::from_json(path.to_str().unwrap(), &serde_json::json!({"k": 0.3})).unwrap();
    let mut state = AppState::default();
    state.add(spec);
    let mut h = viewer(state);
    let before = lobe_max(&h);
    // f = k/π at every pair: the lobe's largest value.
    assert!(
        (before - 0.3 / std::f64::consts::PI).abs() < 1e-6,
        "{before}"
    );

    // Save an edit: twice the value, and a new parameter.
    std::fs::write(&path, lambertish("2.0", "bool extra 1")).unwrap();
    let took = step_until(&mut h, Duration::from_secs(10), |h| {
        h.state().state().brdfs[0]
            .spec
            .params()
            .get("extra")
            .is_ok()
    });
    let redrawn = step_until(&mut h, Duration::from_secs(10), |h| {
        (lobe_max(h) - 2.0 * before).abs() < 1e-6
    });
    println!("reloaded {took:?} after the save, lobe rebuilt {redrawn:?} later");
    // Within a second of saving on an idle machine (the settle time, the
    // compile, and the frame that rebuilds every view's CPU work for the new
    // model); twice that is allowed for a machine busy with other builds.
    assert!(took < Duration::from_secs(2), "the reload took {took:?}");
    let p = h.state().state().brdfs[0].spec.params().clone();
    assert_eq!(p.float("k").unwrap(), 0.3, "the value of k is kept");
    assert!(
        p.bool("extra").unwrap(),
        "the new parameter has its default"
    );
    h.get_by_label_contains("reloaded");

    // A broken edit: the error names the file, line and column, and the
    // lobe stays the last working one.
    let broken = lambertish("2.0 *", "bool extra 1");
    std::fs::write(&path, &broken).unwrap();
    step_until(&mut h, Duration::from_secs(10), |h| {
        !h.state().load_errors().is_empty()
    });
    let e = &h.state().load_errors()[0];
    // The broken line: `    return vec3(2.0 * * k / PI);` is line 10, the second `*` column 23.
    assert!(
        e.message.contains("edited.brdf:10:23:"),
        "the message has file:line:col: {}",
        e.message
    );
    h.get_by_label("Could not open the file");
    assert!((lobe_max(&h) - 2.0 * before).abs() < 1e-6);
    assert_eq!(
        h.state().state().brdfs[0].spec.params().float("k").unwrap(),
        0.3
    );
    std::fs::remove_dir_all(&dir).unwrap();
}

fn viewer_on_gpu(state: AppState) -> Harness<'static, Viewer> {
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        eframe::egui_wgpu::RendererOptions::PREDICTABLE,
    );
    bv::views::lobe_gpu::install(&rs);
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .with_max_steps(8)
        .renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(
            rs.clone(),
        ))
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    bv::views::gpu_image::install(&h.ctx, &rs);
    h.run_steps(2);
    h
}

/// The lit sphere's centre pixel (its red channel).
fn lit_centre(h: &mut Harness<'_, Viewer>) -> Option<u8> {
    use bv::views::lit_sphere::LitSphereView;
    let rect = h.state().view::<LitSphereView>()?.view_rect?;
    let img = h.render().ok()?;
    let c = rect.center();
    Some(img.get_pixel(c.x as u32 - 2, c.y as u32 - 2).0[0])
}

#[test]
fn the_lit_sphere_draws_the_reloaded_shader() {
    bv::session::user_models::install();
    let dir = temp_dir("lit");
    let path = dir.join("lit.brdf");
    std::fs::write(&path, lambertish("1.0", "")).unwrap();
    let mut state = AppState::default();
    state
        .add(ModelSpec::from_json(path.to_str().unwrap(), &serde_json::json!({"k": 0.6})).unwrap());
    state.incident = bv::session::state::Incident {
        theta_deg: 30.0,
        phi_deg: 20.0,
    };
    state.lighting.env.target_spp = 1;
    let mut h = viewer_on_gpu(state);
    // The centre is f·cos θi·E = k/π · cos 30°, in sRGB.
    let want = |scale: f64| {
        bv::gpu::display::to_u8(bv::gpu::display::srgb_encode(
            scale * 0.6 / std::f64::consts::PI * 30f64.to_radians().cos(),
        ))
    };
    let close = |px: Option<u8>, w: u8| px.is_some_and(|p| p.abs_diff(w) <= 2);
    let t0 = Instant::now();
    while !close(lit_centre(&mut h), want(1.0)) {
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "{:?}",
            lit_centre(&mut h)
        );
        std::thread::sleep(Duration::from_millis(20));
        h.run_steps(1);
    }
    // Save a version with 1.5 × the value: the renderer is rebuilt for the
    // new shader and the centre follows.
    std::fs::write(&path, lambertish("1.5", "")).unwrap();
    let t0 = Instant::now();
    while !close(lit_centre(&mut h), want(1.5)) {
        assert!(
            t0.elapsed() < Duration::from_secs(60),
            "centre {:?}, want {}",
            lit_centre(&mut h),
            want(1.5)
        );
        std::thread::sleep(Duration::from_millis(20));
        h.run_steps(1);
    }
    let took = t0.elapsed();
    println!("lit sphere redrawn {took:?} after the save");
    // About a second on an idle machine (the settle time, the compile, one
    // specialised pipeline, and this loop's full-window renders), more while
    // the reloaded model's derived results (its albedo curve, its badges:
    // the shader changed, so they are computed again) share the CPU. A
    // speed target belongs in a benchmark; this bound catches a redraw that
    // never comes or waits for something it should not.
    assert!(took < Duration::from_secs(15), "the redraw took {took:?}");
    std::fs::remove_dir_all(&dir).unwrap();
}
