//! `Brdf::furnace` (issue 29: the albedo view's furnace switch "for every
//! microfacet model") against what shares no code with the models: the
//! closed forms of anisotropic GGX and its separable Smith term for
//! Disney's specular lobe, the same interface with a white tint for the
//! rough dielectric, and the white furnace's bound ρ ≤ 1 with the lost
//! share growing with roughness.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_core::analysis::quadrature::{QuadratureOptions, rho_hd_dir};
use bv_core::{Brdf, ModelSpec, frame, mean_rgb};
use glam::DVec3;
use serde_json::json;
use std::f64::consts::PI;

fn model(id: &str, p: serde_json::Value) -> Box<dyn Brdf> {
    ModelSpec::from_json(id, &p).unwrap().build().unwrap()
}

/// Disney's furnace lobe is D_GGX(αx, αy) G1(ωi) G1(ωo) / (4 cos θi cos θo)
/// with F = 1 (Burley 2012 B.2; Heitz 2014 eq. 86 for Λ), α = roughness²
/// stretched by √(1 − 0.9 anisotropic).
#[test]
fn disneys_furnace_is_its_specular_lobe_with_f_one() {
    let (rough, aniso) = (0.6f64, 0.5f64);
    let b = model(
        "disney",
        json!({"roughness": rough, "anisotropic": aniso, "metallic": 0.2, "sheen": 0.5,
               "clearcoat": 0.7, "base_color": [0.8, 0.3, 0.1]}),
    );
    let f = b.furnace().expect("Disney has a microfacet lobe");
    let aspect = (1.0 - 0.9 * aniso).sqrt();
    let (ax, ay) = (rough * rough / aspect, rough * rough * aspect);
    let d = |h: DVec3| {
        let (x, y, z) = (h.x / ax, h.y / ay, h.z);
        1.0 / (PI * ax * ay * (x * x + y * y + z * z).powi(2))
    };
    let g1 = |w: DVec3| {
        let t2 = ((w.x * ax).powi(2) + (w.y * ay).powi(2)) / (w.z * w.z);
        2.0 / (1.0 + (1.0 + t2).sqrt())
    };
    for k in 0..300 {
        let wi = frame::from_spherical(1.4 * (k as f64 * 0.618).fract(), k as f64 * 2.4);
        let wo = frame::from_spherical(1.4 * (k as f64 * 0.377).fract(), k as f64 * 1.3);
        let h = (wi + wo).normalize();
        let want = d(h) * g1(wi) * g1(wo) / (4.0 * wi.z * wo.z);
        let got = f.eval(wi, wo);
        for c in [got.x, got.y, got.z] {
            assert!((c - want).abs() <= 1e-9 * want.max(1e-9), "{c} vs {want}");
        }
    }
}

/// The rough dielectric's furnace lobe is the same interface, untinted.
#[test]
fn the_rough_dielectrics_furnace_is_the_untinted_interface() {
    let p = json!({"alpha_x": 0.3, "alpha_y": 0.5, "eta": 1.33, "geometry": "smith-correlated"});
    let mut tinted = p.clone();
    tinted["tint"] = json!([0.2, 0.5, 0.9]);
    let f = model("rough-dielectric", tinted).furnace().unwrap();
    let white = model("rough-dielectric", p);
    for k in 0..200 {
        let wi = frame::from_spherical(3.0 * (k as f64 * 0.618).fract(), k as f64 * 2.4);
        let wo = frame::from_spherical(3.0 * (k as f64 * 0.377).fract(), k as f64 * 1.3);
        assert_eq!(f.eval(wi, wo), white.eval(wi, wo));
    }
}

/// The coated model's furnace lobe is its coat's interface alone: the rough
/// dielectric of the same roughness, distribution and η, untinted.
#[test]
fn the_coated_furnace_is_its_coats_interface() {
    let f = model(
        "coated",
        json!({"alpha": 0.4, "distribution": "ggx", "eta": 1.6, "base": "lambert",
               "base_albedo": [0.8, 0.2, 0.1], "thickness": 1.0, "absorption": 0.5}),
    )
    .furnace()
    .unwrap();
    let interface = model(
        "rough-dielectric",
        json!({"alpha": 0.4, "distribution": "ggx", "eta": 1.6, "geometry": "smith"}),
    );
    for k in 0..200 {
        let wi = frame::from_spherical(3.0 * (k as f64 * 0.618).fract(), k as f64 * 2.4);
        let wo = frame::from_spherical(3.0 * (k as f64 * 0.377).fract(), k as f64 * 1.3);
        let (a, b) = (f.eval(wi, wo), interface.eval(wi, wo));
        assert!(
            (a - b).abs().max_element() <= 1e-12 * (1.0 + b.max_element()),
            "{a:?} {b:?}"
        );
    }
}

/// Every model of the catalogue whose lobe the furnace switch shows keeps
/// at most all of the light, and loses more at high roughness than at low
/// (single scattering drops the light that would bounce again).
#[test]
fn furnace_lobes_keep_at_most_everything_and_lose_more_when_rough() {
    let opts = QuadratureOptions::default();
    let cases = [
        ("cook-torrance", "alpha", 0.1, 0.9),
        ("disney", "roughness", 0.3, 0.95),
        ("rough-dielectric", "alpha", 0.1, 0.9),
        ("coated", "alpha", 0.1, 0.9),
    ];
    for (id, param, smooth, rough) in cases {
        let e = |a: f64| {
            let f = model(id, json!({ param: a })).furnace().unwrap();
            let wi = frame::from_spherical(60f64.to_radians(), 0.0);
            mean_rgb(rho_hd_dir(f.as_ref(), wi, &opts).value)
        };
        let (es, er) = (e(smooth), e(rough));
        assert!(es <= 1.0 + 1e-3 && er <= 1.0 + 1e-3, "{id}: {es} {er}");
        assert!(
            1.0 - er > 1.0 - es + 0.02,
            "{id}: E {es} at {smooth}, {er} at {rough}"
        );
    }
}
