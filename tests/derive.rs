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
