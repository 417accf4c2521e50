//! A saved user file refreshes every derived result (issue 28, part 4): the
//! views are drawn offscreen for a `.brdf` model, the file is saved with a
//! new constant and reloaded as the window reloads it, and drawing them again
//! computes each derived result once more, for the new model (albedo curve,
//! SH projection, factor overlay, factorisation, factorisation view,
//! sampling histogram, reciprocity map, and the panel's property report).
//! The counts are the process's: this is the only test of its binary.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::derive::jobs::Waker;
use bv::derive::{albedo, factor, properties, reciprocity, sampling, sh};
use bv::export::{Frame, Offscreen, render_view};
use bv::session::reload::{ReloadEvent, Reloader};
use bv::session::runtime;
use bv::session::state::AppState;
use bv::views::REGISTRY;
use std::time::{Duration, Instant};

/// Results computed so far, per kind.
fn computed() -> [u64; 8] {
    [
        albedo::slots().computed(),
        sh::slots().computed(),
        factor::overlays().computed(),
        factor::factorizations().computed(),
        factor::view_slots().computed(),
        sampling::slots().computed(),
        reciprocity::slots().computed(),
        properties::previews().computed(),
    ]
}

/// A grey Lambert-like file: f = scale · k / π, so ρhd = scale · k.
fn lambertish(scale: &str) -> String {
    format!(
        "analytic\n::begin parameters\nfloat k 0 1 0.5\n::end parameters\n::begin shader\nconst float PI = 3.14159265358979323846;\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{{\n    return vec3({scale} * k / PI);\n}}\n::end shader\n"
    )
}

/// Draws every view of `state` offscreen and waits for the property preview
/// of its BRDF; returns that BRDF's ρhd at normal incidence from the
/// albedo curve drawn.
fn draw_all(off: &mut Offscreen, state: &AppState, frame: Frame) -> f64 {
    for e in REGISTRY.iter() {
        render_view(off, state, e, frame).unwrap_or_else(|err| panic!("{}: {err:#}", e.id));
    }
    let id = state.brdfs[0].id;
    let built = {
        let mut rt = runtime::shared();
        rt.sync(state);
        rt.get(id).unwrap().clone()
    };
    let t0 = Instant::now();
    while properties::report(&Waker::none(), id, &built).is_none_or(|s| s.stale) {
        assert!(
            t0.elapsed() < Duration::from_secs(300),
            "no property report"
        );
        std::thread::sleep(Duration::from_millis(10));
    }
    let curve = albedo::slots().latest(id).unwrap();
    curve.value.rho[0].value.x
}

#[test]
fn a_saved_file_refreshes_every_derived_result() {
    let Some(_) = bv::gpu::context::gpu_for_test() else {
        return;
    };
    bv::session::user_models::install();
    let dir = std::env::temp_dir().join(format!("bv-derive-reload-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("saved.brdf");
    std::fs::write(&path, lambertish("1.0")).unwrap();
    let mut s = AppState::default();
    let id = s.add(
        bv_core::ModelSpec::from_json(path.to_str().unwrap(), &serde_json::json!({"k": 0.4}))
            .unwrap(),
    );
    s.selected = Some(id);
    s.display.sh_overlay = true;
    s.display.sh_order = 4;
    s.display.factor_overlay = true;
    let mut off = Offscreen::headless().unwrap();
    let frame = Frame {
        size: eframe::egui::vec2(480.0, 360.0),
        pixels_per_point: 1.0,
        dark: true,
        transparent: false,
    };
    let mut reloader = Reloader::default();
    assert!(
        reloader.update(&mut s).is_empty(),
        "watching starts quietly"
    );

    let before = draw_all(&mut off, &s, frame);
    assert!((before - 0.4).abs() < 1e-3, "ρhd(0) = k = 0.4: {before}");
    assert_eq!(computed(), [1; 8]);

    // Save an edit: twice the value. The window's reloader picks it up.
    std::fs::write(&path, lambertish("2.0")).unwrap();
    let t0 = Instant::now();
    loop {
        let events = reloader.update(&mut s);
        if let Some(e) = events
            .iter()
            .find(|e| matches!(e, ReloadEvent::Failed { .. }))
        {
            panic!("{e:?}");
        }
        if !events.is_empty() {
            break;
        }
        assert!(t0.elapsed() < Duration::from_secs(20), "no reload");
        std::thread::sleep(Duration::from_millis(20));
    }
    let after = draw_all(&mut off, &s, frame);
    assert!((after - 0.8).abs() < 2e-3, "ρhd(0) = 2k = 0.8: {after}");
    // Every derived result was computed again, once, for the new model.
    assert_eq!(computed(), [2; 8]);
    std::fs::remove_dir_all(&dir).unwrap();
}
