//! Fitting (`bv_core::fit`): parameters of a model evaluated with known
//! values are recovered, a model fitted to itself has no error left, a fit
//! never leaves the declared ranges, a cancel stops it within one
//! iteration, and both metrics agree with values computed here without the
//! fit's sample set (a closed form for Lambert against Lambert, brute-force
//! quadrature over (θi, θo, φo) for a lobe against Lambert).

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_core::fit::{self, FitOptions, FitProgress, Metric, SampleOptions};
use bv_core::{Brdf, Claims, ModelSpec, Rgb};
use glam::DVec3;
use std::f64::consts::PI;
use std::sync::atomic::{AtomicBool, Ordering};

fn spec(model: &str, params: &[(&str, &str)]) -> ModelSpec {
    let mut s = ModelSpec::new(model).unwrap();
    for (k, v) in params {
        s.set_str(k, v).unwrap();
    }
    s
}

fn run(model: &ModelSpec, free: &[&str], target: &dyn Brdf, metric: Metric) -> fit::FitResult {
    let opts = FitOptions {
        metric,
        ..FitOptions::default()
    };
    fit::fit(
        model,
        free,
        target,
        &opts,
        &AtomicBool::new(false),
        &mut |_| {},
    )
    .unwrap()
}

fn rel(a: f64, b: f64) -> f64 {
    (a - b).abs() / b.abs()
}

/// Asserts each named float (or colour channel) of `got` within `tol`
/// (relative) of `want`'s.
fn assert_recovered(got: &ModelSpec, want: &ModelSpec, names: &[&str], tol: f64) {
    eprintln!(
        "{}: fitted {}, true {}",
        want.id(),
        got.params().to_json(),
        want.params().to_json()
    );
    for n in names {
        match want.params().get(n).unwrap() {
            bv_core::ParamValue::Float(w) => {
                let g = got.params().float(n).unwrap();
                assert!(rel(g, *w) < tol, "{} {n}: fitted {g}, true {w}", want.id());
            }
            bv_core::ParamValue::Color(w) => {
                let g = got.params().color(n).unwrap();
                for c in 0..3 {
                    assert!(
                        rel(g[c], w[c]) < tol,
                        "{} {n}[{c}]: fitted {}, true {}",
                        want.id(),
                        g[c],
                        w[c]
                    );
                }
            }
            v => panic!("{n}: {v:?}"),
        }
    }
}

#[test]
fn ggx_cook_torrance_alpha_ks_kd_are_recovered() {
    let truth = spec(
        "cook-torrance",
        &[
            ("distribution", "ggx"),
            ("geometry", "smith-correlated"),
            ("alpha", "0.15"),
            ("ks", "0.6"),
            ("kd", "0.2,0.4,0.1"),
        ],
    );
    let start = spec(
        "cook-torrance",
        &[("distribution", "ggx"), ("geometry", "smith-correlated")],
    );
    for metric in Metric::ALL {
        let r = run(
            &start,
            &["kd", "ks", "alpha"],
            truth.build().unwrap().as_ref(),
            metric,
        );
        assert_recovered(&r.spec, &truth, &["alpha_x", "alpha_y", "ks", "kd"], 0.01);
        assert!(
            r.error < 1e-4 * r.initial_error,
            "{metric:?}: {} from {}",
            r.error,
            r.initial_error
        );
    }
}

#[test]
fn anisotropic_alphas_are_recovered_separately() {
    let truth = spec(
        "cook-torrance",
        &[
            ("distribution", "ggx"),
            ("alpha_x", "0.1"),
            ("alpha_y", "0.3"),
            ("ks", "0.5"),
            ("kd", "0.1"),
        ],
    );
    let start = spec("cook-torrance", &[("distribution", "ggx")]);
    let r = run(
        &start,
        &["kd", "ks", "alpha_x", "alpha_y"],
        truth.build().unwrap().as_ref(),
        Metric::Ngan,
    );
    assert_recovered(&r.spec, &truth, &["alpha_x", "alpha_y", "ks", "kd"], 0.01);
}

#[test]
fn ward_alpha_and_blinn_phong_exponent_are_recovered() {
    let truth = spec(
        "ward",
        &[
            ("alpha", "0.08"),
            ("ks", "0.3,0.2,0.1"),
            ("kd", "0.4,0.3,0.2"),
        ],
    );
    let r = run(
        &spec("ward", &[]),
        &["kd", "ks", "alpha"],
        truth.build().unwrap().as_ref(),
        Metric::Ngan,
    );
    assert_recovered(&r.spec, &truth, &["alpha_x", "alpha_y", "ks", "kd"], 0.01);

    let truth = spec(
        "blinn-phong",
        &[("e", "150"), ("ks", "0.5"), ("kd", "0.1,0.2,0.3")],
    );
    let r = run(
        &spec("blinn-phong", &[]),
        &["kd", "ks", "e"],
        truth.build().unwrap().as_ref(),
        Metric::E2,
    );
    assert_recovered(&r.spec, &truth, &["e", "ks", "kd"], 0.01);
}

#[test]
fn a_model_fitted_to_itself_has_no_error_left() {
    // Every float and colour parameter free, from the defaults, to the same
    // model with other values: the error falls to the f32 kernels' noise.
    for (model, params) in [
        ("lambert", vec![("albedo", "0.7,0.2,0.4")]),
        ("ward", vec![("alpha", "0.3"), ("ks", "0.1")]),
        ("blinn-phong", vec![("e", "40")]),
    ] {
        let truth = spec(model, &params);
        let start = ModelSpec::new(model).unwrap();
        let free = fit::default_free(&start);
        let r = run(&start, &free, truth.build().unwrap().as_ref(), Metric::Ngan);
        assert!(
            r.error < 1e-5,
            "{model}: error {} (from {})",
            r.error,
            r.initial_error
        );
        // The evaluation at the true values is exactly 0: same kernel, same pairs.
        let (e, bands) = fit::error(
            truth.build().unwrap().as_ref(),
            truth.build().unwrap().as_ref(),
            &SampleOptions::default(),
            Metric::E2,
        )
        .unwrap();
        assert_eq!(e, 0.0);
        assert!(bands.iter().all(|b| b.error == 0.0));
    }
}

/// A target no model can match: a constant `value` everywhere above the horizon.
#[derive(Debug)]
struct Constant(f64);

impl Brdf for Constant {
    fn id(&self) -> &'static str {
        "constant"
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z > 0.0 && wo.z > 0.0 {
            Rgb::splat(self.0)
        } else {
            Rgb::ZERO
        }
    }
    fn claims(&self) -> Claims {
        Claims {
            reciprocal: true,
            energy_conserving: false,
            isotropic: true,
        }
    }
}

#[test]
fn fits_never_leave_the_declared_ranges() {
    // Far too bright for Lambert (albedo ≤ 1): the fit ends at the bound.
    let r = run(
        &spec("lambert", &[]),
        &["albedo"],
        &Constant(1000.0),
        Metric::Ngan,
    );
    assert_eq!(r.spec.params().color("albedo").unwrap(), DVec3::splat(1.0));
    // Black: the albedo goes to its lower bound (0) or within 1e-4 of it.
    let r = run(
        &spec("lambert", &[]),
        &["albedo"],
        &Constant(0.0),
        Metric::E2,
    );
    assert!(r.spec.params().color("albedo").unwrap().max_element() < 1e-4);
    // A mirror-sharp, huge lobe for Blinn-Phong (e ≤ 10000) and Ward (α ≥ 0.001).
    let sharp = spec(
        "cook-torrance",
        &[
            ("distribution", "ggx"),
            ("alpha", "0.001"),
            ("ks", "1"),
            ("kd", "0"),
        ],
    );
    let target = sharp.build().unwrap();
    for (model, free) in [
        ("blinn-phong", vec!["kd", "ks", "e"]),
        ("ward", vec!["kd", "ks", "alpha_x", "alpha_y"]),
    ] {
        let start = ModelSpec::new(model).unwrap();
        // Every value any start tried was validated by `ModelSpec::set`
        // (an out-of-range value is an error, which would fail the fit).
        let r = run(&start, &free, target.as_ref(), Metric::Ngan);
        for d in start.model().params {
            if let bv_core::ParamKind::Float(f) = d.kind {
                let x = r.spec.params().float(d.id).unwrap();
                assert!((f.min..=f.max).contains(&x), "{model} {} = {x}", d.id);
            }
        }
    }
}

#[test]
fn cancelling_stops_within_one_iteration() {
    let truth = spec(
        "cook-torrance",
        &[("distribution", "ggx"), ("alpha", "0.05")],
    );
    let target = truth.build().unwrap();
    let start = spec("cook-torrance", &[("distribution", "ggx")]);
    let cancel = AtomicBool::new(false);
    let mut seen: Vec<FitProgress> = Vec::new();
    let mut progress = |p: &FitProgress| {
        seen.push(*p);
        if p.iteration >= 2 {
            cancel.store(true, Ordering::Relaxed);
        }
    };
    let opts = FitOptions::default();
    let r = fit::fit(
        &start,
        &["kd", "ks", "alpha"],
        target.as_ref(),
        &opts,
        &cancel,
        &mut progress,
    )
    .unwrap();
    assert!(r.cancelled);
    // The flag went up at iteration 2 of start 0; at most one more began.
    assert!(r.iterations <= 3, "{} iterations", r.iterations);
    assert!(
        seen.iter().all(|p| p.start == 0 && p.iteration <= 3),
        "{seen:?}"
    );
    // The result is the best point so far, inside the ranges, and no worse than the start.
    assert!(r.error <= r.initial_error);

    // Cancelled before it starts: no iteration at all.
    let r = fit::fit(
        &start,
        &["alpha"],
        target.as_ref(),
        &opts,
        &AtomicBool::new(true),
        &mut |_| {},
    )
    .unwrap();
    assert!(r.cancelled && r.iterations == 0);
}

/// The grazing cut of the default sample set, as a cosine.
fn cut() -> f64 {
    SampleOptions::default().max_theta_deg.to_radians().cos()
}

#[test]
fn ngan_metric_matches_a_closed_form_for_two_lamberts() {
    // f = a/π against b/π: ∛(f cos θi) differs by (∛a − ∛b) ∛(μ/π), so with
    // both directions cut at μ ≥ c, E² = (∛a − ∛b)² ∫_c^1 (μ/π)^(2/3) dμ / (1 − c)
    // = (∛a − ∛b)² π^(−2/3) (3/5) (1 − c^(5/3)) / (1 − c). The same number
    // for every channel, so the RMS over channels is it too.
    let (a, b): (f64, f64) = (0.8, 0.2);
    let c = cut();
    let want = (a.cbrt() - b.cbrt())
        * (PI.powf(-2.0 / 3.0) * 0.6 * (1.0 - c.powf(5.0 / 3.0)) / (1.0 - c)).sqrt();
    let m = spec("lambert", &[("albedo", &a.to_string())])
        .build()
        .unwrap();
    let t = spec("lambert", &[("albedo", &b.to_string())])
        .build()
        .unwrap();
    let (got, bands) = fit::error(
        m.as_ref(),
        t.as_ref(),
        &SampleOptions::default(),
        Metric::Ngan,
    )
    .unwrap();
    eprintln!("Ngan, two Lamberts: sample set {got}, closed form {want}");
    assert!(
        rel(got, want) < 1e-3,
        "sample set {got}, closed form {want}"
    );
    // The band errors: the same closed form over μ in each band.
    for band in bands.iter().filter(|b| b.samples > 0) {
        let (lo, hi) = (
            band.theta_i_max.to_radians().cos().max(c),
            band.theta_i_min.to_radians().cos(),
        );
        let want = (a.cbrt() - b.cbrt())
            * (PI.powf(-2.0 / 3.0) * 0.6 * (hi.powf(5.0 / 3.0) - lo.powf(5.0 / 3.0)) / (hi - lo))
                .sqrt();
        assert!(rel(band.error, want) < 0.02, "{band:?}: closed form {want}");
    }
}

/// Brute force over the cut domain: midpoints in (μi, μo, φo) with φi = 0
/// (both models are isotropic, so φi contributes a factor 2π to numerator
/// and denominator alike), dω = dμ dφ.
fn brute_force(m: &dyn Brdf, t: &dyn Brdf, g: impl Fn(f64) -> f64) -> f64 {
    let c = cut();
    let (ni, no, np) = (120, 120, 240);
    let (mut num, mut den) = (0.0, 0.0);
    for i in 0..ni {
        let mu_i = c + (1.0 - c) * (i as f64 + 0.5) / ni as f64;
        let wi = DVec3::new((1.0 - mu_i * mu_i).sqrt(), 0.0, mu_i);
        for o in 0..no {
            let mu_o = c + (1.0 - c) * (o as f64 + 0.5) / no as f64;
            let s = (1.0 - mu_o * mu_o).sqrt();
            for p in 0..np {
                let phi = 2.0 * PI * (p as f64 + 0.5) / np as f64;
                let wo = DVec3::new(s * phi.cos(), s * phi.sin(), mu_o);
                let (fm, ft) = (m.eval(wi, wo), t.eval(wi, wo));
                for ch in 0..3 {
                    num += (g(fm[ch] * mu_i) - g(ft[ch] * mu_i)).powi(2);
                }
                den += 3.0;
            }
        }
    }
    (num / den).sqrt()
}

#[test]
fn both_metrics_match_brute_force_quadrature_for_a_lobe() {
    // A glossy Blinn-Phong against a coloured Lambert: the error lives in the
    // lobe, so this checks the sample set's half/difference weights.
    let m = spec("blinn-phong", &[("e", "30"), ("ks", "0.4"), ("kd", "0.1")])
        .build()
        .unwrap();
    let t = spec("lambert", &[("albedo", "0.5,0.3,0.1")])
        .build()
        .unwrap();
    let bf_ngan = brute_force(m.as_ref(), t.as_ref(), f64::cbrt);
    let bf_e2 = brute_force(m.as_ref(), t.as_ref(), f64::ln_1p);
    let (ngan, _) = fit::error(
        m.as_ref(),
        t.as_ref(),
        &SampleOptions::default(),
        Metric::Ngan,
    )
    .unwrap();
    let (e2, _) = fit::error(
        m.as_ref(),
        t.as_ref(),
        &SampleOptions::default(),
        Metric::E2,
    )
    .unwrap();
    eprintln!("Ngan {ngan} vs brute force {bf_ngan}; E2 {e2} vs {bf_e2}");
    assert!(
        rel(ngan, bf_ngan) < 3e-3,
        "Ngan: sample set {ngan}, brute force {bf_ngan}"
    );
    assert!(
        rel(e2, bf_e2) < 3e-3,
        "E2: sample set {e2}, brute force {bf_e2}"
    );
}
