//! The Snell, microfacet-term and Fresnel views driven in an egui_kittest
//! harness: each draws a picture, the toolbar's toggles and presets change
//! what it shows, and dragging in the Snell view moves the light.

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::session::frame::{Scene, build_scene};
use bv::session::runtime::Runtime;
use bv::session::state::AppState;
use bv::views::View;
use bv::views::fresnel::FresnelView;
use bv::views::snell::SnellView;
use bv::views::terms::TermsView;
use eframe::egui;
use egui_kittest::Harness;
use egui_kittest::kittest::{Queryable, by};

/// One view over a state, with its toolbar above it; commands are applied
/// at once, as the window does at the start of the next frame.
struct One<V> {
    state: AppState,
    runtime: Runtime,
    view: V,
}

impl<V: View> One<V> {
    fn new(specs: &[(&str, serde_json::Value)], view: V) -> Self {
        let mut state = AppState::default();
        for (model, params) in specs {
            state.add(bv_core::ModelSpec::from_json(model, params).unwrap());
        }
        state.selected = state.brdfs.first().map(|b| b.id);
        let mut runtime = Runtime::default();
        runtime.sync(&state);
        Self {
            state,
            runtime,
            view,
        }
    }

    fn ui(&mut self, ui: &mut egui::Ui) {
        let mut out = Vec::new();
        {
            let scene: Scene<'_> = build_scene(&self.state, &self.runtime, false);
            egui::CentralPanel::default().show(ui, |ui| {
                ui.horizontal(|ui| self.view.toolbar(ui, &scene, &mut out));
                self.view.ui(ui, &scene, &mut out);
            });
        }
        for c in out {
            c.apply(&mut self.state);
        }
        self.runtime.sync(&self.state);
    }
}

fn harness<V: View>(one: One<V>) -> Harness<'static, One<V>> {
    let rs = egui_kittest::wgpu::create_render_state(
        egui_kittest::wgpu::default_wgpu_setup(),
        eframe::egui_wgpu::RendererOptions::PREDICTABLE,
    );
    let mut h = Harness::builder()
        .with_size([900.0, 640.0])
        .with_max_steps(8)
        .renderer(egui_kittest::wgpu::WgpuTestRenderer::from_render_state(rs))
        .build_ui_state(|ui, s: &mut One<V>| s.ui(ui), one);
    h.run();
    h
}

/// Distinct colours of the harness's picture (a blank one has a handful).
fn colours<V: View>(h: &mut Harness<'static, One<V>>) -> usize {
    let img = h.render().expect("render");
    let mut v: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    v.sort_unstable();
    v.dedup();
    v.len()
}

fn snell_texts(h: &Harness<'static, One<SnellView>>) -> Vec<String> {
    h.state()
        .view
        .last
        .as_ref()
        .unwrap()
        .texts()
        .into_iter()
        .map(String::from)
        .collect()
}

fn has(texts: &[String], s: &str) -> bool {
    texts.iter().any(|t| t.contains(s))
}

#[test]
fn snell_view_names_tir_from_the_dense_side_and_follows_drags() {
    let mut h = harness(One::new(
        &[("glass", serde_json::json!({"eta": 1.5}))],
        SnellView::default(),
    ));
    assert!(colours(&mut h) > 50, "the Snell view is blank");
    // Glass's own η, light from above at 45°: refracted, no TIR.
    let t = snell_texts(&h);
    assert!(has(&t, "ηi = 1, ηt = 1.5 (Glass)"), "{t:?}");
    assert!(has(&t, "θt = 28.1°") && !has(&t, "total internal reflection"));
    // From below (inside the glass), 45° > θc = 41.8°: totally reflected.
    h.get_by_label("light from below").click();
    h.run();
    let t = snell_texts(&h);
    assert!(has(&t, "total internal reflection"), "{t:?}");
    assert!(has(&t, "θi > θc = 41.8°") && has(&t, "no refracted ray"));
    // The optical manhole: water, n = 4/3, Snell's window of 2 × 48.6°; at
    // 45° the light still gets out.
    h.get_by_label("optical manhole").click();
    h.run();
    let t = snell_texts(&h);
    assert!(has(&t, "Snell's window 2 × 48.6° = 97.2°"), "{t:?}");
    assert!(!has(&t, "no refracted ray"));
    // The settings are the scene's (saved with it), not the view's.
    let v = h.state().state.plots.snell;
    assert!(
        v.use_own && v.from_below && (v.eta - 4.0 / 3.0).abs() < 1e-15,
        "{v:?}"
    );
    let text = bv::session::scene_file::to_toml(&h.state().state).unwrap();
    let back = bv::session::scene_file::from_toml(&text).unwrap();
    assert_eq!(back.state.plots.snell, v);

    // Dragging from the hit point to 60° below the interface (the light's
    // side) sets θi = 60°: past the window, totally reflected.
    let (_, centre, scale) = h.state().view.last_rect.unwrap();
    let a = 60f32.to_radians();
    let at = centre + egui::vec2(-a.sin(), a.cos()) * 0.8 * scale;
    h.drag_at(at);
    h.run();
    h.drop_at(at);
    h.run();
    let theta = h.state().state.incident.theta_deg;
    assert!((theta - 60.0).abs() < 0.5, "θi = {theta}");
    assert!(has(&snell_texts(&h), "θi = 60"));
    assert!(has(&snell_texts(&h), "total internal reflection"));
}

#[test]
fn snell_view_uses_its_own_eta_for_models_without_a_dielectric() {
    let h = harness(One::new(
        &[("lambert", serde_json::json!({}))],
        SnellView::default(),
    ));
    let t = snell_texts(&h);
    assert!(has(&t, "this view's η"), "{t:?}");
    assert!(h.query_by_label("η of BRDF").is_none());
}

#[test]
fn terms_view_lists_the_terms_and_the_models_without() {
    let mut h = harness(One::new(
        &[
            (
                "cook-torrance",
                serde_json::json!({"distribution": "ggx", "geometry": "smith-correlated"}),
            ),
            (
                "cook-torrance",
                serde_json::json!({"distribution": "beckmann", "geometry": "v-groove"}),
            ),
            ("lambert", serde_json::json!({})),
        ],
        TermsView::default(),
    ));
    assert!(colours(&mut h) > 50, "the term view is blank");
    let c = h.state().view.last.clone().unwrap();
    assert!(c.lines[0].contains("D = GGX") && c.lines[0].contains("height-correlated Smith"));
    assert!(c.lines[1].contains("D = Beckmann") && c.lines[1].contains("v-groove"));
    assert!(c.lines[2].ends_with("no microfacet terms"), "{:?}", c.lines);
    // The lines are on screen.
    assert!(
        h.query_all(by().label_contains("no microfacet terms"))
            .next()
            .is_some()
    );
    // Both Cook-Torrance BRDFs have D, G1, G2 and F curves, Lambert none.
    assert_eq!(c.d.as_ref().unwrap().series.len(), 2);
    assert_eq!(c.g.as_ref().unwrap().series.len(), 4);
    assert_eq!(c.f.as_ref().unwrap().series.len(), 2);
    // Switching D off drops its chart.
    h.get_by_label("D").click();
    h.run();
    let c = h.state().view.last.clone().unwrap();
    assert!(c.d.is_none() && c.g.is_some());
}

#[test]
fn fresnel_view_overlays_every_brdf_with_a_term() {
    let copper = serde_json::json!({"fresnel": "conductor",
        "eta": [0.2, 0.924, 1.102], "k": [3.912, 2.452, 2.142]});
    let mut h = harness(One::new(
        &[
            ("cook-torrance", copper),
            ("glass", serde_json::json!({"eta": 1.5})),
            ("lambert", serde_json::json!({})),
        ],
        FresnelView::default(),
    ));
    assert!(colours(&mut h) > 50, "the Fresnel view is blank");
    let f = h.state().view.last_figure.clone().unwrap();
    let labels: Vec<&str> = f.chart.series.iter().map(|s| s.label.as_str()).collect();
    // The glass's F, then copper in detail: Rs, Rp (green), F and Schlick per
    // channel.
    assert!(
        labels.iter().any(|l| l.starts_with("Glass: F")),
        "{labels:?}"
    );
    assert!(labels.iter().any(|l| l.contains("Rs (g)")), "{labels:?}");
    assert_eq!(
        labels.iter().filter(|l| l.contains("Schlick")).count(),
        3,
        "{labels:?}"
    );
    assert!(f.chart.note.contains("Lambert: no Fresnel term"));
    // The strip: copper's exact and Schlick rows, red at normal incidence,
    // white at grazing.
    assert_eq!(f.strip.len(), 2);
    let first = f.strip[0].linear[0];
    let last = *f.strip[0].linear.last().unwrap();
    assert!(first.x > first.y && first.y > first.z, "{first}");
    assert!(
        (last - bv_core::Rgb::ONE).abs().max_element() < 1e-9,
        "{last}"
    );
    // The readouts give k back from F0 and η: copper's own k.
    assert!(
        f.readouts[1].contains("3.912 / 2.452 / 2.142"),
        "{:?}",
        f.readouts
    );
}
