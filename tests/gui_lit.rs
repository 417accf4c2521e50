//! The rendered views in the viewer (kittest on the GPU; lavapipe
//! on machines without one): the lit sphere follows the sliders and the light
//! drag, the environment view accumulates samples across frames and restarts
//! on a change, errors show in the view, and small snapshots of both.
//! Regenerate the snapshots with `UPDATE_SNAPSHOTS=1 cargo test --test suite gui_lit::`.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::session::Command;
use bv::session::lighting::{EnvObject, Lighting};
use bv::session::state::{AppState, Incident};
use bv::views::environment::EnvironmentView;
use bv::views::lit_sphere::LitSphereView;
use bv_core::{ModelSpec, ParamValue};
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;

/// egui's render state on the test device, with the lobe pipeline installed.
fn render_state() -> eframe::egui_wgpu::RenderState {
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        eframe::egui_wgpu::RendererOptions::PREDICTABLE,
    );
    bv::views::lobe_gpu::install(&rs);
    rs
}

/// The whole viewer on the GPU, with the rendered views' device installed.
fn viewer_on_gpu(state: AppState, size: [f32; 2]) -> Harness<'static, Viewer> {
    let rs = render_state();
    let mut h = Harness::builder()
        .with_size(size)
        .with_max_steps(8)
        .renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(
            rs.clone(),
        ))
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    bv::views::gpu_image::install(&h.ctx, &rs);
    // The renderers are built on worker threads: wait for them.
    wait_until(&mut h, |h| {
        let v = h.state();
        let lit_ok = v
            .view::<LitSphereView>()
            .is_none_or(|l| l.ready() || l.view_rect.is_none());
        let env_ok = v
            .view::<EnvironmentView>()
            .is_none_or(|e| e.ready() || e.view_rect.is_none());
        lit_ok && env_ok
    });
    h.run_steps(2);
    h
}

/// Steps `h` (sleeping a little between frames) until `done`, for at most a minute.
fn wait_until<S>(h: &mut Harness<'_, S>, done: impl Fn(&Harness<'_, S>) -> bool) {
    let t0 = std::time::Instant::now();
    h.run_steps(1);
    while !done(h) {
        assert!(
            t0.elapsed().as_secs() < 60,
            "the renderers were not built in a minute"
        );
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
}

fn state_with(models: &[(&str, serde_json::Value)]) -> AppState {
    let mut s = AppState::default();
    for (m, p) in models {
        s.add(ModelSpec::from_json(m, p).unwrap());
    }
    s.selected = s.brdfs.first().map(|b| b.id);
    s.incident = Incident {
        theta_deg: 30.0,
        phi_deg: 20.0,
    };
    // The environment view stops asking for frames after one sample, so that
    // `run()` settles in tests that are not about it.
    s.lighting.env.target_spp = 1;
    s
}

fn lit<'a>(h: &'a Harness<'_, Viewer>) -> &'a LitSphereView {
    h.state().view::<LitSphereView>().expect("lit sphere view")
}

fn env<'a>(h: &'a Harness<'_, Viewer>) -> &'a EnvironmentView {
    h.state()
        .view::<EnvironmentView>()
        .expect("environment view")
}

/// The part of a rendered window under `rect` (points, pixels_per_point 1).
fn crop(img: &image::RgbaImage, rect: egui::Rect) -> image::RgbaImage {
    let r = rect.shrink(2.0);
    image::imageops::crop_imm(
        img,
        r.min.x as u32,
        r.min.y as u32,
        r.width() as u32,
        r.height() as u32,
    )
    .to_image()
}

/// Mean absolute difference per channel of two equal-size images (0..255).
fn mean_diff(a: &image::RgbaImage, b: &image::RgbaImage) -> f64 {
    assert_eq!(a.dimensions(), b.dimensions());
    let sum: u64 = a
        .pixels()
        .zip(b.pixels())
        .map(|(p, q)| (0..3).map(|k| p[k].abs_diff(q[k]) as u64).sum::<u64>())
        .sum();
    sum as f64 / (3 * a.width() * a.height()) as f64
}

/// How many pixels differ from the most common colour (the background) by
/// more than a few levels.
fn non_background(img: &image::RgbaImage) -> usize {
    let mut counts = std::collections::HashMap::new();
    for p in img.pixels() {
        *counts.entry(p.0).or_insert(0usize) += 1;
    }
    let bg = counts
        .iter()
        .max_by_key(|(_, n)| **n)
        .map(|(c, _)| *c)
        .unwrap();
    img.pixels()
        .filter(|p| (0..3).any(|k| p[k].abs_diff(bg[k]) > 6))
        .count()
}

/// Checks the lit sphere of Lambert with albedo 0.8 lit at θi = 30° in `img`
/// (the view `rect` cropped): it covers a fifth of the view, and its centre
/// shows f·cos θi·E = 0.8/π · cos 30° = 0.2205 → sRGB 0.510 → 130. Returns
/// the centre pixel.
fn lambert_08_sphere(img: &image::RgbaImage, rect: egui::Rect) -> [u8; 4] {
    let lit_pixels = non_background(img);
    assert!(
        lit_pixels > (img.width() * img.height() / 5) as usize,
        "the sphere is missing: {lit_pixels} pixels differ from the background"
    );
    let c = rect.center() - rect.min;
    let px = img.get_pixel(c.x as u32 - 2, c.y as u32 - 2).0;
    let expected = bv::gpu::display::to_u8(bv::gpu::display::srgb_encode(
        0.8 / std::f64::consts::PI * 30f64.to_radians().cos(),
    ));
    for k in 0..3 {
        assert!(
            px[k].abs_diff(expected) <= 2,
            "centre pixel {px:?}, expected {expected}"
        );
    }
    px
}

#[test]
fn lit_sphere_renders_and_follows_a_slider_and_the_light_drag() {
    let mut h = viewer_on_gpu(
        state_with(&[("lambert", serde_json::json!({"albedo": 0.8}))]),
        [1280.0, 800.0],
    );
    let rect = lit(&h).view_rect.expect("lit sphere laid out");
    assert!(lit(&h).error().is_none(), "{:?}", lit(&h).error());
    let img0 = crop(&h.render().unwrap(), rect);
    let px = lambert_08_sphere(&img0, rect);
    let c = rect.center() - rect.min;
    let renders = lit(&h).render_count();
    // An idle frame renders nothing new.
    h.run();
    assert_eq!(lit(&h).render_count(), renders, "idle frames re-render");

    // A slider: the albedo down by dragging its slider.
    let slider = h.get_by_role_and_label(egui::accesskit::Role::Slider, "albedo");
    let r = slider.rect();
    let from = r.center();
    let to = from - egui::vec2(r.width() * 0.3, 0.0);
    h.hover_at(from);
    h.run();
    h.drag_at(from);
    h.run();
    h.hover_at(to);
    h.run();
    h.drop_at(to);
    h.run();
    assert!(lit(&h).render_count() > renders);
    let img1 = crop(&h.render().unwrap(), rect);
    let d = mean_diff(&img0, &img1);
    assert!(d > 2.0, "the slider did not change the sphere ({d})");
    let px1 = img1.get_pixel(c.x as u32 - 2, c.y as u32 - 2).0;
    assert!(px1[0] + 10 < px[0], "darker albedo: {px1:?} vs {px:?}");

    // The light drag: onto the upper left of the sphere.
    let (centre, radius) = bv::views::gpu_image::sphere_circle(rect, 1)(0);
    let target = centre + egui::vec2(-0.5, -0.5) * radius;
    h.hover_at(centre);
    h.run();
    h.drag_at(centre);
    h.run();
    h.hover_at(target);
    h.run();
    h.drop_at(target);
    h.run();
    let inc = h.state().state().incident;
    // n at (−0.5, 0.5) in view space (y up): θ = acos(√0.5) = 45°; the
    // sphere's frame has t to the left and b down at its centre, so the
    // local direction is (0.5, −0.5): φ = −45°.
    assert!(
        (inc.theta_deg - 45.0).abs() < 1.0 && (inc.phi_deg + 45.0).abs() < 1.0,
        "{inc:?}"
    );
    let img2 = crop(&h.render().unwrap(), rect);
    assert!(
        mean_diff(&img1, &img2) > 2.0,
        "moving the light did not change the sphere"
    );
}

#[test]
fn lit_sphere_settings_change_the_image_and_a_measured_brdf_is_drawn() {
    let mut state = state_with(&[
        ("cook-torrance", serde_json::json!({})),
        ("ward", serde_json::json!({"alpha_x": 0.05, "alpha_y": 0.3})),
    ]);
    state.maximised = Some("lit_sphere".into());
    let mut h = viewer_on_gpu(state, [900.0, 600.0]);
    let rect = lit(&h).view_rect.unwrap();
    assert_eq!(lit(&h).tiles, 2, "side by side");
    let a = crop(&h.render().unwrap(), rect);
    let mut l: Lighting = h.state().state().lighting.clone();
    l.lit.exposure_ev = 2.0;
    h.state_mut().push(Command::SetLitView(l.lit));
    h.run();
    let b = crop(&h.render().unwrap(), rect);
    assert!(mean_diff(&a, &b) > 1.0, "exposure did nothing");
    l.lit.side_by_side = false;
    h.state_mut().push(Command::SetLitView(l.lit));
    h.run();
    assert_eq!(lit(&h).tiles, 1, "one at a time");

    // A measured (merl) BRDF: drawn from its table, uploaded to the GPU.
    let dir = std::env::temp_dir().join(format!("bv-gui-lit-merl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("grey.binary");
    let dims = bv_core::measured::MerlDims::new(4, 4, 8).unwrap();
    bv_core::measured::MerlTable::from_values(dims, vec![0.1; 3 * 4 * 4 * 8])
        .unwrap()
        .write(&path)
        .unwrap();
    let mut merl = ModelSpec::new("merl").unwrap();
    merl.set("path", ParamValue::Text(path.display().to_string()))
        .unwrap();
    let mut state = h.state().state().clone();
    state.add(merl);
    state.lighting.lit.side_by_side = true;
    state.maximised = None;
    let mut h = viewer_on_gpu(state, [1280.0, 800.0]);
    assert_eq!(h.state().state().brdfs.len(), 3);
    assert!(
        h.state()
            .runtime()
            .get(h.state().state().brdfs[2].id)
            .unwrap()
            .brdf
            .is_some(),
        "the table loads on the CPU"
    );
    h.run();
    assert_eq!(lit(&h).tiles, 3, "the measured BRDF has its sphere");
    assert!(lit(&h).messages().is_empty(), "{:?}", lit(&h).messages());
    assert!(env(&h).messages().is_empty(), "{:?}", env(&h).messages());
    // Its sphere is lit: constant f = 0.1 → the centre shows 0.1·cos θi
    // (× 2^EV, EV = 2 from above).
    let rect = lit(&h).view_rect.unwrap();
    let img = crop(&h.render().unwrap(), rect);
    let (c, _) = bv::views::gpu_image::sphere_circle(rect, 3)(2);
    let c = c - rect.min;
    let px = img.get_pixel(c.x as u32 - 2, c.y as u32 - 2).0;
    let expected = bv::gpu::display::to_u8(bv::gpu::display::srgb_encode(
        0.1 * 30f64.to_radians().cos() * 4.0,
    ));
    assert!(
        (0..3).all(|k| px[k].abs_diff(expected) <= 3),
        "merl sphere centre {px:?}, expected {expected}"
    );
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn environment_accumulates_and_restarts_on_changes() {
    let mut state = state_with(&[("cook-torrance", serde_json::json!({}))]);
    state.maximised = Some("environment".into());
    state.lighting.env.target_spp = 1024;
    let mut h = viewer_on_gpu(state, [720.0, 480.0]);
    assert!(env(&h).error().is_none(), "{:?}", env(&h).error());
    let s0 = env(&h).samples_per_pixel();
    assert!(s0 >= 1);
    h.run_steps(3);
    let s1 = env(&h).samples_per_pixel();
    assert!(s1 > s0, "no new samples: {s0} then {s1}");
    let restarts = env(&h).restart_count();

    // A click that changes nothing (on the view itself) keeps the samples.
    let rect = env(&h).view_rect.unwrap();
    for pressed in [true, false] {
        h.event(egui::Event::PointerButton {
            pos: rect.center(),
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        });
        h.run_steps(1);
    }
    assert_eq!(env(&h).restart_count(), restarts, "a click restarted");
    assert!(env(&h).samples_per_pixel() > s1);

    // A parameter change restarts.
    let id = h.state().state().brdfs[0].id;
    h.state_mut().push(Command::SetParam {
        brdf: id,
        param: "ks".into(),
        value: ParamValue::Float(0.2),
    });
    h.run_steps(1);
    assert_eq!(env(&h).restart_count(), restarts + 1);
    assert!(env(&h).samples_per_pixel() < s1);

    // So do the light-independent settings: object, rotation, map.
    let mut e = h.state().state().lighting.env.clone();
    for change in 0..3 {
        match change {
            0 => e.object = EnvObject::Torus,
            1 => e.rotation_deg = 40.0,
            _ => e.map = Some("/no/such/map.hdr".into()),
        }
        let before = env(&h).restart_count();
        h.state_mut().push(Command::SetEnvView(e.clone()));
        h.run_steps(2);
        if change < 2 {
            assert_eq!(env(&h).restart_count(), before + 1, "change {change}");
        }
    }
    // The bad map: an error in the view, the studio stays, no restart loop.
    for _ in 0..50 {
        if !env(&h).loading() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
    let err = env(&h).error().expect("a missing file is reported");
    assert!(err.contains("map.hdr"), "{err}");
    assert_eq!(env(&h).map_in_use(), None);
    assert!(err.contains("still showing"), "{err}");

    // Exposure only re-displays: no restart.
    let before = (env(&h).restart_count(), env(&h).samples_per_pixel());
    e.exposure_ev = 1.0;
    h.state_mut().push(Command::SetEnvView(e.clone()));
    h.run_steps(1);
    assert_eq!(env(&h).restart_count(), before.0);
    assert!(env(&h).samples_per_pixel() >= before.1);

    // It stops at the target.
    e.target_spp = 8;
    h.state_mut().push(Command::SetEnvView(e.clone()));
    h.run_steps(1);
    e.rotation_deg = 0.0;
    h.state_mut().push(Command::SetEnvView(e));
    for _ in 0..12 {
        h.run_steps(1);
    }
    assert_eq!(env(&h).samples_per_pixel(), 8);
    assert!(env(&h).converged_after().is_some());
}

#[test]
fn an_environment_file_can_be_loaded_by_path() {
    let dir = std::env::temp_dir().join(format!("bv-gui-lit-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("grey.hdr");
    bv::gpu::EnvironmentMap::constant([0.5; 3])
        .save_hdr(&path)
        .unwrap();
    let mut state = state_with(&[("lambert", serde_json::json!({"albedo": 1.0}))]);
    state.maximised = Some("environment".into());
    state.lighting.env.map = Some(path.display().to_string());
    let mut h = viewer_on_gpu(state, [720.0, 480.0]);
    for _ in 0..100 {
        if env(&h).map_in_use().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(20));
        h.run_steps(1);
    }
    assert_eq!(
        env(&h).map_in_use(),
        Some(path.display().to_string().as_str())
    );
    assert!(env(&h).error().is_none(), "{:?}", env(&h).error());
    std::fs::remove_dir_all(&dir).ok();
}

/// One view alone over a state (for the snapshots: no panels around it).
struct ViewOnly<V> {
    state: AppState,
    runtime: bv::session::runtime::Runtime,
    view: V,
    /// Passed to the scene (a pointer button held).
    interacting: bool,
}

impl<V: bv::views::View> ViewOnly<V> {
    fn new(state: AppState, view: V) -> Self {
        let mut runtime = bv::session::runtime::Runtime::default();
        runtime.sync(&state);
        Self {
            state,
            runtime,
            view,
            interacting: false,
        }
    }

    fn ui(&mut self, ui: &mut egui::Ui) {
        let scene = bv::session::build_scene(&self.state, &self.runtime, self.interacting);
        let mut out = Vec::new();
        egui::CentralPanel::default()
            .frame(egui::Frame::NONE)
            .show(ui, |ui| self.view.ui(ui, &scene, &mut out));
    }
}

fn view_only<V: bv::views::View + 'static>(
    state: AppState,
    view: V,
    size: [f32; 2],
    ready: impl Fn(&V) -> bool,
) -> Harness<'static, ViewOnly<V>> {
    let rs = render_state();
    let mut h = Harness::builder()
        .with_size(size)
        .with_max_steps(8)
        .renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(
            rs.clone(),
        ))
        .build_ui_state(
            |ui, s: &mut ViewOnly<V>| s.ui(ui),
            ViewOnly::new(state, view),
        );
    bv::views::gpu_image::install(&h.ctx, &rs);
    wait_until(&mut h, |h| ready(&h.state().view));
    h.run_steps(2);
    h
}

#[test]
fn snapshot_lit_sphere() {
    let state = state_with(&[
        (
            "ward",
            serde_json::json!({"kd": 0.2, "ks": 0.4, "alpha_x": 0.06, "alpha_y": 0.3}),
        ),
        ("lambert", serde_json::json!({"albedo": [0.8, 0.45, 0.2]})),
    ]);
    let mut h = view_only(
        state,
        LitSphereView::new(),
        [300.0, 170.0],
        LitSphereView::ready,
    );
    h.run_ok();
    assert_eq!(h.state().view.tiles, 2);
    h.snapshot_options(
        "gui_lit_sphere",
        &egui_kittest::SnapshotOptions::new()
            .threshold(2.0)
            .max_failed_pixels(200),
    );
}

#[test]
fn snapshot_environment() {
    // A fixed sample count (not a time) so that the image is reproducible.
    let mut state = state_with(&[(
        "cook-torrance",
        serde_json::json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx", "alpha_x": 0.3, "alpha_y": 0.3,
            "fresnel": "conductor", "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14]}),
    )]);
    state.lighting.env.target_spp = 64;
    let mut h = view_only(
        state,
        EnvironmentView::new(),
        [200.0, 150.0],
        EnvironmentView::ready,
    );
    for _ in 0..200 {
        if h.state().view.samples_per_pixel() >= 64 {
            break;
        }
        h.run_steps(1);
    }
    assert_eq!(h.state().view.samples_per_pixel(), 64);
    h.run_ok();
    // Monte Carlo noise at 64 spp: a little more slack than for the
    // deterministic lit sphere.
    h.snapshot_options(
        "gui_environment",
        &egui_kittest::SnapshotOptions::new()
            .threshold(4.0)
            .max_failed_pixels(600),
    );
}

/// Throughput of the renderers at GUI sizes on this machine's adapter (not a
/// pass/fail test: `cargo test --test suite -- --ignored --nocapture gui_lit::timing`;
/// the GPU work is the driver's, so a debug build measures the same).
#[test]
#[ignore]
fn timing() {
    use bv::gpu::{EnvRenderer, EnvSettings, EnvironmentMap, Gpu, LitSphereRenderer};
    let gpu = Gpu::headless().unwrap();
    println!("adapter: {}", gpu.describe());
    let mut lib = bv::gpu::shaders::ShaderLibrary::new().unwrap();
    let studio = EnvironmentMap::builtin_studio().unwrap();
    let mut env = EnvRenderer::new(gpu.clone(), &mut lib, &studio).unwrap();
    let (w, h) = (420, 360);
    for (m, p) in [
        ("lambert", serde_json::json!({})),
        ("cook-torrance", serde_json::json!({})),
        ("disney", serde_json::json!({})),
    ] {
        let spec = ModelSpec::from_json(m, &p).unwrap();
        for object in [bv::gpu::env::Object::Sphere, bv::gpu::env::Object::Torus] {
            env.set_object(object);
            let settings = EnvSettings {
                rotation: 0.1,
                ..Default::default()
            };
            // Restart, then passes of 8.
            let t0 = std::time::Instant::now();
            let mut marks = vec![16u64, 64, 256, 1024];
            let mut out = Vec::new();
            let mut first = true;
            while !marks.is_empty() {
                let pass = if first { 1 } else { 8 };
                first = false;
                env.render(std::slice::from_ref(&spec), &settings, w, h, pass)
                    .unwrap();
                gpu.wait().unwrap();
                let spp = env.samples_per_pixel();
                if spp >= marks[0] {
                    out.push(format!("{spp}: {:.1} s", t0.elapsed().as_secs_f64()));
                    marks.remove(0);
                }
            }
            println!("environment {w}x{h} {m} {object:?}: {}", out.join(", "));
        }
    }
    let mut lit = LitSphereRenderer::new(gpu.clone(), &mut lib).unwrap();
    let spec = ModelSpec::new("cook-torrance").unwrap();
    for (w, h) in [(500u32, 420u32), (1024, 1024)] {
        let mut times = Vec::new();
        for k in 0..15 {
            let settings = bv::gpu::LitSphereSettings {
                light: glam::DVec3::new(0.1 * k as f64, 0.3, 0.8),
                ..Default::default()
            };
            let t = std::time::Instant::now();
            lit.render(std::slice::from_ref(&spec), &settings, w, h)
                .unwrap();
            gpu.wait().unwrap();
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "lit sphere {w}x{h} cook-torrance: median {:.1} ms",
            times[times.len() / 2]
        );
    }
}

/// Saves the environment view's image at a few sample counts to
/// `$BV_TEST_IMAGES` (default /tmp) for a look by eye (not a pass/fail test).
#[test]
#[ignore]
fn environment_progression_images() {
    use bv::gpu::{EnvRenderer, EnvSettings, EnvironmentMap, Gpu};
    let dir = std::env::var("BV_TEST_IMAGES").unwrap_or_else(|_| "/tmp".into());
    let gpu = Gpu::headless().unwrap();
    let mut lib = bv::gpu::shaders::ShaderLibrary::new().unwrap();
    let studio = EnvironmentMap::builtin_studio().unwrap();
    let mut env = EnvRenderer::new(gpu.clone(), &mut lib, &studio).unwrap();
    // BV_SPECS="ward={\"alpha_x\":0.05};mirror={}" picks the models.
    let specs: Vec<ModelSpec> = match std::env::var("BV_SPECS") {
        Ok(list) => list
            .split(';')
            .map(|item| {
                let (m, p) = item.split_once('=').unwrap_or((item, "{}"));
                ModelSpec::from_json(m, &serde_json::from_str(p).unwrap()).unwrap()
            })
            .collect(),
        Err(_) => vec![
            ModelSpec::new("cook-torrance").unwrap(),
            ModelSpec::from_json("lambert", &serde_json::json!({"albedo": [0.8, 0.45, 0.2]}))
                .unwrap(),
        ],
    };
    let object = match std::env::var("BV_OBJECT").as_deref() {
        Ok("torus") => bv::gpu::env::Object::Torus,
        _ => bv::gpu::env::Object::Sphere,
    };
    env.set_object(object);
    let (w, h) = (180 * specs.len() as u32, 180);
    let t0 = std::time::Instant::now();
    for spp in [4u32, 16, 64, 256] {
        let img = env
            .render_image(&specs, &EnvSettings::default(), w, h, spp)
            .unwrap();
        println!("{spp} spp after {:.1} s", t0.elapsed().as_secs_f64());
        img.save(format!("{dir}/env_{object:?}_{spp}.png")).unwrap();
    }
}

/// RMS error of the environment estimate against a long reference at a few
/// sample counts (not a pass/fail test; shows the convergence rate).
#[test]
#[ignore]
fn environment_error_rate() {
    use bv::gpu::{EnvRenderer, EnvSettings, EnvironmentMap, Gpu};
    let gpu = Gpu::headless().unwrap();
    let mut lib = bv::gpu::shaders::ShaderLibrary::new().unwrap();
    let studio = EnvironmentMap::builtin_studio().unwrap();
    let mut env = EnvRenderer::new(gpu.clone(), &mut lib, &studio).unwrap();
    let model = std::env::var("BV_MODEL").unwrap_or_else(|_| "lambert".into());
    let specs = [ModelSpec::new(&model).unwrap()];
    let (w, h) = (96, 96);
    let reference = env
        .render_radiance(&specs, &EnvSettings::default(), w, h, 8192)
        .unwrap();
    for spp in [4u32, 16, 64, 256] {
        let other = EnvSettings {
            rotation: 1e-9,
            ..Default::default()
        };
        // Restart (a different key), then back to the same settings.
        env.render_radiance(&specs, &other, w, h, 1).unwrap();
        let img = env
            .render_radiance(&specs, &EnvSettings::default(), w, h, spp)
            .unwrap();
        let (mut e2, mut r2) = (0.0f64, 0.0f64);
        for (a, b) in img.iter().zip(&reference) {
            for k in 0..3 {
                e2 += f64::from(a[k] - b[k]).powi(2);
                r2 += f64::from(b[k]).powi(2);
            }
        }
        println!(
            "{model} {spp} spp: relative RMS error {:.4}",
            (e2 / r2).sqrt()
        );
        if let Ok(dir) = std::env::var("BV_TEST_IMAGES") {
            let mut map = image::RgbImage::new(w, h);
            for (i, (a, b)) in img.iter().zip(&reference).enumerate() {
                let e = (0..3).map(|k| (a[k] - b[k]).abs()).sum::<f32>() / 3.0;
                let v = (e / 0.1 * 255.0).min(255.0) as u8;
                map.put_pixel(i as u32 % w, i as u32 / w, image::Rgb([v, v, v]));
            }
            map.save(format!("{dir}/err_{model}_{spp}.png")).unwrap();
        }
    }
}

/// Lit sphere render time per model at a GUI size (not a pass/fail test).
#[test]
#[ignore]
fn lit_timing() {
    use bv::gpu::{Gpu, LitSphereRenderer};
    let gpu = Gpu::headless().unwrap();
    let mut lib = bv::gpu::shaders::ShaderLibrary::new().unwrap();
    let mut lit = LitSphereRenderer::new(gpu.clone(), &mut lib).unwrap();
    let (w, h) = (465u32, 370u32);
    for m in ["lambert", "cook-torrance", "ward", "disney"] {
        let spec = ModelSpec::new(m).unwrap();
        let mut times = Vec::new();
        for k in 0..12 {
            let settings = bv::gpu::LitSphereSettings {
                light: glam::DVec3::new(0.05 * k as f64, 0.3, 0.8),
                ..Default::default()
            };
            let t = std::time::Instant::now();
            lit.render(std::slice::from_ref(&spec), &settings, w, h)
                .unwrap();
            gpu.wait().unwrap();
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        let first = times[0];
        times.sort_by(f64::total_cmp);
        println!(
            "lit sphere {w}x{h} {m}: median {:.1} ms (first, with the pipeline build: {first:.0} ms)",
            times[times.len() / 2]
        );
    }
}

/// Cost of a full-screen pass that does almost nothing (the environment
/// view's display pass) at the lit sphere's size, for comparison.
#[test]
#[ignore]
fn display_pass_timing() {
    use bv::gpu::{EnvRenderer, EnvSettings, EnvironmentMap, Gpu};
    let gpu = Gpu::headless().unwrap();
    let mut lib = bv::gpu::shaders::ShaderLibrary::new().unwrap();
    let mut env =
        EnvRenderer::new(gpu.clone(), &mut lib, &EnvironmentMap::constant([1.0; 3])).unwrap();
    let (w, h) = (465u32, 370u32);
    let spec = ModelSpec::new("lambert").unwrap();
    env.render(
        std::slice::from_ref(&spec),
        &EnvSettings::default(),
        w,
        h,
        1,
    )
    .unwrap();
    gpu.wait().unwrap();
    let mut times = Vec::new();
    for k in 0..12 {
        let s = EnvSettings {
            exposure_ev: 0.1 * k as f64,
            ..Default::default()
        };
        let t = std::time::Instant::now();
        env.display(&s, w, h).unwrap();
        gpu.wait().unwrap();
        times.push(t.elapsed().as_secs_f64() * 1e3);
    }
    times.sort_by(f64::total_cmp);
    println!(
        "display pass {w}x{h}: median {:.1} ms",
        times[times.len() / 2]
    );
}

/// The lit sphere view's frame in a harness while a parameter changes every
/// frame (not a pass/fail test): ui + render of the window image.
#[test]
#[ignore]
fn lit_view_frame_timing() {
    let state = state_with(&[("cook-torrance", serde_json::json!({}))]);
    for interacting in [true, false] {
        let mut h = view_only(
            state.clone(),
            LitSphereView::new(),
            [930.0, 740.0],
            LitSphereView::ready,
        );
        h.state_mut().interacting = interacting;
        let mut times = Vec::new();
        for k in 0..15 {
            let id = h.state().state.brdfs[0].id;
            let e = h.state_mut().state.entry_mut(id).unwrap();
            e.spec
                .set("alpha_x", ParamValue::Float(0.1 + 0.02 * k as f64))
                .unwrap();
            let s = h.state().state.clone();
            h.state_mut().runtime.sync(&s);
            let t = std::time::Instant::now();
            h.run_steps(1);
            let _ = h.render().unwrap();
            times.push(t.elapsed().as_secs_f64() * 1e3);
        }
        times.sort_by(f64::total_cmp);
        println!(
            "lit sphere view 930x740 (interacting {interacting}): median frame {:.1} ms, renders {}",
            times[times.len() / 2],
            h.state().view.render_count()
        );
    }
}

/// A device with WebGL2's limits (no storage buffers, as a browser without
/// WebGPU gives): the lit sphere is drawn on the CPU, the same picture.
#[test]
fn without_storage_buffers_the_lit_sphere_is_drawn_on_the_cpu() {
    let mut setup = egui_kittest::wgpu::default_wgpu_setup();
    if let eframe::egui_wgpu::WgpuSetup::CreateNew(new) = &mut setup {
        new.device_descriptor =
            std::sync::Arc::new(
                |adapter: &eframe::wgpu::Adapter| eframe::wgpu::DeviceDescriptor {
                    label: Some("webgl2-like"),
                    required_limits: eframe::wgpu::Limits::downlevel_webgl2_defaults()
                        .using_resolution(adapter.limits()),
                    ..Default::default()
                },
            );
    }
    let rs = egui_kittest::wgpu::create_render_state(
        setup,
        eframe::egui_wgpu::RendererOptions::PREDICTABLE,
    );
    assert_eq!(rs.device.limits().max_storage_buffers_per_shader_stage, 0);
    let mut state = state_with(&[("lambert", serde_json::json!({"albedo": 0.8}))]);
    state.maximised = Some("lit_sphere".into());
    let mut h = Harness::builder()
        .with_size([900.0, 600.0])
        .with_max_steps(8)
        .renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(
            rs.clone(),
        ))
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    bv::views::gpu_image::install(&h.ctx, &rs);
    h.run_steps(3);
    assert!(bv::views::gpu_image::lacks_storage_buffers(&h.ctx));
    let rect = lit(&h).view_rect.expect("lit sphere laid out");
    assert!(lit(&h).error().is_none(), "{:?}", lit(&h).error());
    assert!(!lit(&h).ready(), "no GPU renderer is built for it");
    let img = crop(&h.render().unwrap(), rect);
    // The same picture as on the GPU.
    let px = lambert_08_sphere(&img, rect);
    let c = rect.center() - rect.min;
    // A slider still changes it.
    let brdf = h.state().state().brdfs[0].id;
    h.state_mut().push(Command::SetParam {
        brdf,
        param: "albedo".into(),
        value: ParamValue::Float(0.4),
    });
    h.run_steps(2);
    let img2 = crop(&h.render().unwrap(), rect);
    let px2 = img2.get_pixel(c.x as u32 - 2, c.y as u32 - 2).0;
    assert!(px2[0] + 10 < px[0], "darker albedo: {px2:?} vs {px:?}");
}
