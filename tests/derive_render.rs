//! `bv render --view all` computes each derived result once (issue 26): every
//! view drawn offscreen one after another, as `cli/render.rs` does through
//! `export::render_view` and the process's shared runtime. This is the only
//! test of its binary, so the process's counts of computed results are this
//! scene's alone.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::derive::{albedo, factor, hemi, reciprocity, sampling, sh};
use bv::export::{Frame, Offscreen, render_view};
use bv::session::state::AppState;
use bv::views::REGISTRY;

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
        hemi::slots().computed(),
    ]
}

#[test]
fn every_view_rendered_computes_each_derived_result_once() {
    let Some(_) = bv::gpu::context::gpu_for_test() else {
        return;
    };
    let mut s = AppState::default();
    let id = s.add(
        bv_core::ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"alpha": 0.35, "kd": 0.2}),
        )
        .unwrap(),
    );
    s.selected = Some(id);
    // The 3D lobe and the polar plot both draw both overlays; the
    // factorisation view shares the overlay's factorisation.
    s.display.sh_overlay = true;
    s.display.sh_order = 6;
    s.display.factor_overlay = true;
    let mut off = Offscreen::headless().unwrap();
    let frame = Frame {
        size: eframe::egui::vec2(480.0, 360.0),
        pixels_per_point: 1.0,
        dark: true,
        transparent: false,
    };
    assert_eq!(computed(), [0; 8]);
    for e in REGISTRY.iter() {
        render_view(&mut off, &s, e, frame).unwrap_or_else(|err| panic!("{}: {err:#}", e.id));
    }
    // Albedo curve, SH projection, factor overlay, factorisation,
    // factorisation-view data, sampling histogram, reciprocity map,
    // hemisphere map: one each.
    assert_eq!(computed(), [1; 8]);
    // A second `--view all` in the same process computes nothing.
    for e in REGISTRY.iter() {
        render_view(&mut off, &s, e, frame).unwrap();
    }
    assert_eq!(computed(), [1; 8]);
}
