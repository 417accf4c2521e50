//! The derive layer seen from its users (issue 26): a derived result the
//! window computed is the very object a figure draws (computed once per
//! process), and headless figures share one runtime and one cache.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::derive::albedo;
use bv::session::state::AppState;
use bv::session::{Scene, build_scene, runtime};
use bv::views::albedo::AlbedoView;
use egui_kittest::Harness;
use std::sync::Arc;

/// A scene of one BRDF with parameters no other test uses (tests of one
/// binary share the process's caches).
fn state(albedo: f64) -> AppState {
    let mut s = AppState::default();
    s.add(
        bv_core::ModelSpec::from_json(
            "oren-nayar",
            &serde_json::json!({ "albedo": albedo, "sigma": 0.3 }),
        )
        .unwrap(),
    );
    s.selected = Some(s.brdfs[0].id);
    s
}

/// The albedo curve of the first BRDF of `state` in the process's cache,
/// under the shared runtime's build of it.
fn cached_curve(state: &AppState) -> Option<Arc<albedo::AlbedoData>> {
    let mut rt = runtime::shared();
    rt.sync(state);
    let scene: Scene<'_> = build_scene(state, &rt, false);
    let b = scene.brdfs.first()?;
    albedo::slots()
        .get(b.id, &albedo::key_of(&scene, b))
        .map(|d| d.value.clone())
}

#[test]
fn a_curve_the_window_computed_is_the_one_the_figure_draws() {
    let s = state(0.4321);
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .with_max_steps(12)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(s.clone()));
    // The window's albedo view starts the job; wait for it to finish.
    let start = std::time::Instant::now();
    loop {
        h.run();
        let v = h.state().view::<AlbedoView>().unwrap();
        if v.progress.is_none() {
            break;
        }
        assert!(start.elapsed().as_secs() < 120, "{:?}", v.progress);
        std::thread::sleep(std::time::Duration::from_millis(20));
    }
    // While the window holds its build, the headless runtime shares it (same
    // revision), so the cache holds the window's curve under the figure's key.
    let window_curve = cached_curve(&s).expect("the window's curve is in the process's cache");
    let computed = albedo::slots().computed();
    let entry = bv::views::entry("albedo").unwrap();
    let svg = bv::export::view_svg(&s, entry, [640.0, 400.0], false).unwrap();
    assert!(svg.contains("ρhh"), "the figure has its legend");
    let after = cached_curve(&s).unwrap();
    assert!(
        Arc::ptr_eq(&window_curve, &after),
        "the figure drew another object than the window's"
    );
    assert_eq!(
        albedo::slots().computed(),
        computed,
        "the figure computed the curve again"
    );
    drop(h);
}

/// `bv render --view all` draws views one after another through the shared
/// runtime: the second figure that needs a result finds the first one's.
#[test]
fn figures_in_a_row_compute_each_result_once() {
    let s = state(0.2345);
    let entry = bv::views::entry("albedo").unwrap();
    let before = albedo::slots().computed();
    bv::export::view_svg(&s, entry, [640.0, 400.0], false).unwrap();
    let first = cached_curve(&s).expect("computed by the first figure");
    // Another view object, as each view of `--view all` is.
    bv::export::view_svg(&s, entry, [800.0, 500.0], true).unwrap();
    let second = cached_curve(&s).unwrap();
    assert!(Arc::ptr_eq(&first, &second));
    // Other tests of this binary may compute curves meanwhile; this scene's
    // adds exactly one, which `cached_curve` found twice as the same object.
    assert!(albedo::slots().computed() > before);
}

/// The microsurface view's specimen follows the selected BRDF when it names
/// its slopes (Beckmann or GGX, anisotropic kept), falls back to the view's
/// own settings for a model without them or with "from model" off, and
/// never hands the generator a roughness out of range or not finite.
#[test]
fn the_microsurface_specimen_comes_from_the_model_or_the_settings() {
    use bv::derive::microsurface::specimen;
    use bv_core::microsurface::SlopeDistribution;
    let mut rt = runtime::shared();
    let with = |model: &str, p: serde_json::Value| {
        let mut s = AppState::default();
        s.add(bv_core::ModelSpec::from_json(model, &p).unwrap());
        s.selected = Some(s.brdfs[0].id);
        s
    };
    let mut s = with(
        "cook-torrance",
        serde_json::json!({"distribution": "ggx", "alpha_x": 0.25, "alpha_y": 0.7}),
    );
    rt.sync(&s);
    let sp = specimen(&build_scene(&s, &rt, false));
    assert_eq!(sp.distribution, SlopeDistribution::Ggx);
    assert_eq!((sp.alpha_x, sp.alpha_y), (0.25, 0.7));
    assert!(sp.from.is_some());
    s.plots.microsurface.from_model = false;
    s.plots.microsurface.alpha = f64::NAN;
    let sp = specimen(&build_scene(&s, &rt, false));
    assert_eq!(sp.distribution, SlopeDistribution::Beckmann);
    assert_eq!((sp.alpha_x, sp.alpha_y, sp.from.clone()), (0.5, 0.5, None));
    let mut s = with("lambert", serde_json::json!({}));
    s.plots.microsurface.distribution = SlopeDistribution::Ggx;
    s.plots.microsurface.alpha = 9.0;
    rt.sync(&s);
    let sp = specimen(&build_scene(&s, &rt, false));
    assert_eq!(sp.distribution, SlopeDistribution::Ggx);
    assert_eq!((sp.alpha_x, sp.from.clone()), (1.5, None));
    // The settings travel in a scene file.
    let text = toml::to_string(&s.plots).unwrap();
    assert!(text.contains("distribution = \"ggx\""), "{text}");
}

/// The polar view's gonio overlay in a figure: one dot per detector stop
/// (35 for a reflection model, 70 round the whole circle for a
/// transmitting one), the grid counter, and nothing with the toggle off.
#[test]
fn the_gonio_overlay_draws_its_readings_in_figures() {
    let entry = bv::views::entry("polar").unwrap();
    for (model, stops) in [("lambert", 35), ("rough-dielectric", 70)] {
        let mut s = AppState::default();
        s.add(bv_core::ModelSpec::from_json(model, &serde_json::json!({})).unwrap());
        s.selected = Some(s.brdfs[0].id);
        let off = bv::export::view_svg(&s, entry, [800.0, 600.0], false).unwrap();
        assert!(!off.contains("detector stops"));
        s.plots.gonio = true;
        let svg = bv::export::view_svg(&s, entry, [800.0, 600.0], false).unwrap();
        assert!(
            svg.contains(&format!("{stops} detector stops")),
            "{model}: no counter"
        );
        assert!(svg.contains("1 458 000 cells"));
        assert!(svg.contains("measured ("), "{model}: no legend entry");
    }
}

/// The gonio overlay on a simulated surface: for a model with slopes the
/// figure has both reading sets and the single-scattering curve; for one
/// without, no readings (and no other specimen measured in its place).
#[test]
fn the_gonio_surface_overlay_measures_only_models_with_slopes() {
    let entry = bv::views::entry("polar").unwrap();
    for (model, params, has) in [
        (
            "cook-torrance",
            serde_json::json!({"distribution": "beckmann", "alpha": 0.45}),
            true,
        ),
        ("lambert", serde_json::json!({}), false),
    ] {
        let mut s = AppState::default();
        s.add(bv_core::ModelSpec::from_json(model, &params).unwrap());
        s.selected = Some(s.brdfs[0].id);
        s.plots.gonio = true;
        s.plots.gonio_surface = true;
        let svg = bv::export::view_svg(&s, entry, [800.0, 600.0], false).unwrap();
        assert_eq!(svg.contains("surface, one bounce"), has, "{model}");
        assert_eq!(svg.contains("F = 1: one bounce"), has, "{model}");
        assert!(!svg.contains("measured ("), "{model}");
    }
}

/// The albedo view's swapped curve (LECTURE N12): for a reciprocal BRDF it
/// is its ρhd within the quadrature's error at every θ; for classical Phong
/// (1/cos θi) it parts from it towards the horizon; the figure draws it only
/// with the switch on.
#[test]
fn the_swapped_albedo_curve_follows_reciprocity() {
    use bv::derive::albedo::{Which, curve_now_of};
    for (model, reciprocal) in [("modified-phong", true), ("phong", false)] {
        let mut s = AppState::default();
        s.add(
            bv_core::ModelSpec::from_json(
                model,
                &serde_json::json!({"kd": 0.0, "ks": 0.8, "e": 21.0}),
            )
            .unwrap(),
        );
        s.selected = Some(s.brdfs[0].id);
        s.plots.albedo.swapped = true;
        let (hd, dh) = {
            // The shared runtime is released before the figures take it.
            let mut rt = runtime::shared();
            rt.sync(&s);
            let scene = build_scene(&s, &rt, false);
            let b = &scene.brdfs[0];
            (
                curve_now_of(&scene, b, Which::Hd),
                curve_now_of(&scene, b, Which::Dh),
            )
        };
        let gap = (0..hd.rho.len())
            .map(|k| (hd.mean_and_band(k).0 - dh.mean_and_band(k).0).abs())
            .fold(0.0, f64::max);
        if reciprocal {
            assert!(gap < 1e-4, "{model}: {gap}");
        } else {
            assert!(gap > 0.05, "{model}: {gap}");
        }
        let entry = bv::views::entry("albedo").unwrap();
        let svg = bv::export::view_svg(&s, entry, [800.0, 500.0], false).unwrap();
        assert!(svg.contains("ρdh"), "{model}");
        s.plots.albedo.swapped = false;
        let svg = bv::export::view_svg(&s, entry, [800.0, 500.0], false).unwrap();
        assert!(!svg.contains("ρdh"), "{model}");
    }
}
