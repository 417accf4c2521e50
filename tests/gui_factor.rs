//! The factorisation view and the factor overlay of the lobe and polar
//! views, driven with egui_kittest by accessible labels; no GPU needed.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::session::Command;
use bv::session::state::{AppState, Display};
use bv::views::factor::FactorView;
use bv::views::lobe3d::Lobe3dView;
use bv::views::polar::PolarView;
use bv_core::ModelSpec;
use bv_core::frame::{self, HalfDiff};
use bv_core::measured::merl::{phi_d_centre, theta_d_centre, theta_h_centre};
use bv_core::represent::factor::{FactorSpace, VIEW_DIMS, factor_model};
use egui_kittest::Harness;
use egui_kittest::kittest::Queryable;
use std::time::{Duration, Instant};

fn viewer(state: AppState) -> Harness<'static, Viewer> {
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .with_max_steps(12)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(state));
    h.run();
    h
}

fn glossy() -> ModelSpec {
    ModelSpec::from_json(
        "cook-torrance",
        &serde_json::json!({"kd": 0.2, "ks": 0.7, "alpha": 0.25}),
    )
    .unwrap()
}

/// The cosine-weighted relative error of the rank-K rebuild, K = 1..=8,
/// written out here from the factors and the table's cells.
fn weighted_errors(spec: &ModelSpec) -> Vec<f64> {
    let b = spec.build().unwrap();
    let (t, f) = factor_model(b.as_ref(), VIEW_DIMS, 8, FactorSpace::Cosine, &|_| true).unwrap();
    let d = VIEW_DIMS;
    let mut e2 = [0.0; 8];
    let mut n2 = 0.0;
    for ih in 0..d.theta_h {
        for id in 0..d.theta_d {
            for ip in 0..d.phi_d {
                let (wi, wo) = frame::from_half_diff(HalfDiff {
                    theta_h: theta_h_centre(ih, d.theta_h),
                    phi_h: 0.0,
                    theta_d: theta_d_centre(id, d.theta_d),
                    phi_d: phi_d_centre(ip, d.phi_d),
                });
                let w = if wi.z > 0.0 && wo.z > 0.0 {
                    wi.z * wo.z
                } else {
                    0.0
                };
                let x = t.at(ih, id, ip);
                let j = id * d.phi_d + ip;
                for c in 0..3 {
                    n2 += (w * x[c]).powi(2);
                    for (k, e) in e2.iter_mut().enumerate() {
                        // g_k h_k summed by hand, the weight divided out, clamped.
                        let s: f64 = (0..=k).map(|t| f.g(c, t, ih) * f.h(c, t, j)).sum();
                        let rebuilt = if w > 0.0 { (s / w).max(0.0) } else { 0.0 };
                        *e += (w * (rebuilt - x[c])).powi(2);
                    }
                }
            }
        }
    }
    e2.iter().map(|e| (e / n2).sqrt()).collect()
}

#[test]
fn the_view_charts_the_errors_it_computed() {
    let mut s = AppState::default();
    s.add(glossy());
    s.maximised = Some("factor".into());
    let mut h = viewer(s);
    let t0 = Instant::now();
    let chart = loop {
        h.run();
        let v = h.state().view::<FactorView>().unwrap();
        if let Some((o, false)) = &v.shown
            && o.is_ok()
        {
            break v.chart.clone();
        }
        assert!(t0.elapsed() < Duration::from_secs(120), "no factorisation");
        std::thread::sleep(Duration::from_millis(20));
    };
    assert_eq!(chart.len(), 2);
    let (svd, sh) = (&chart[0].1, &chart[1].1);
    assert_eq!(svd.len(), 8);
    assert_eq!(sh.len(), 17);
    assert_eq!((svd[0][0], sh[0][0]), (1.0, 0.0));
    let want = weighted_errors(&glossy());
    for (p, w) in svd.iter().zip(&want) {
        assert!((10f64.powf(p[1]) - w).abs() < 1e-6 * w, "{p:?} vs {w}");
    }
    // Non-increasing: the truncation is optimal in the factored space (a
    // clamp at 0 can only lower an error).
    assert!(want[7] < want[0]);
    // SH of the same lobes over the same cells falls with the order, and a
    // single product holds more of a half-angle lobe than a constant lobe
    // per incident direction.
    assert!(sh[16][1] < sh[0][1]);
    assert!(svd[0][1] < sh[0][1]);
}

#[test]
fn an_anisotropic_model_is_refused_with_the_reason() {
    let mut s = AppState::default();
    s.add(
        ModelSpec::from_json("ward", &serde_json::json!({"alpha_x": 0.1, "alpha_y": 0.4})).unwrap(),
    );
    s.maximised = Some("factor".into());
    let mut h = viewer(s);
    let t0 = Instant::now();
    loop {
        h.run();
        if let Some((o, _)) = &h.state().view::<FactorView>().unwrap().shown {
            let e = o.as_ref().as_ref().unwrap_err();
            assert!(e.contains("isotropic"), "{e}");
            break;
        }
        assert!(t0.elapsed() < Duration::from_secs(60));
        std::thread::sleep(Duration::from_millis(20));
    }
}

fn lobe<'a>(h: &'a Harness<'_, Viewer>) -> &'a Lobe3dView {
    h.state().view::<Lobe3dView>().unwrap()
}

fn settle(h: &mut Harness<'_, Viewer>) {
    h.run();
    assert!(bv::derive::factor::wait_idle());
    h.run();
    h.run();
}

#[test]
fn the_factor_toggle_overlays_the_rebuilt_lobe_with_its_error() {
    let mut state = AppState::default();
    state.add(glossy());
    let mut h = viewer(state);
    let meshes = |h: &Harness<'_, Viewer>| lobe(h).last_frame().unwrap().meshes.len();
    let before = meshes(&h);
    assert!(h.query_by_label("factor terms K").is_none());
    h.get_all_by_label("factor").next().unwrap().click();
    settle(&mut h);
    assert!(h.state().state().display.factor_overlay);
    let done = lobe(&h).factor_result().expect("factor result");
    let r = done.value.as_ref().unwrap();
    assert_eq!(r.terms, 2);
    let e2 = r.lobe_error;
    assert!(e2 > 0.0 && e2 < 1.0, "{e2}");
    assert_eq!(meshes(&h), before + 1, "the rebuild is one more mesh");
    assert!(
        h.state()
            .view::<PolarView>()
            .unwrap()
            .factor_curve
            .as_ref()
            .is_some_and(|c| c.len() > 100),
        "the polar plot has the dashed curve"
    );
    let labels: Vec<String> = h
        .get_all_by_label_contains("factor K = 2: lobe L2 error")
        .map(|n| format!("{n:?}"))
        .collect();
    assert_eq!(labels.len(), 2, "{labels:?}");
    h.get_all_by_label("factor terms K").next().unwrap();

    // More terms through the state: a better rebuild of the same lobe.
    let d = h.state().state().display;
    h.state_mut().push(Command::SetDisplay(Display {
        factor_terms: 8,
        ..d
    }));
    settle(&mut h);
    let r8 = lobe(&h).factor_result().unwrap();
    assert_eq!(r8.key.terms, 8);
    let e8 = r8.value.as_ref().unwrap().lobe_error;
    assert!(e8 < e2, "{e8} vs {e2}");
    h.get_all_by_label_contains("factor K = 8").next().unwrap();

    // Off again: the mesh goes.
    h.get_all_by_label("factor").next().unwrap().click();
    settle(&mut h);
    assert!(!h.state().state().display.factor_overlay);
    assert_eq!(meshes(&h), before);
}
