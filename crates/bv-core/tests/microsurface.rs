//! The simulated microsurface and the virtual gonioreflectometer (issue 29)
//! against what shares no code with them: the requested slope variance, the
//! model's D integrated over the histogram's bins, Smith's closed-form G1,
//! the masking identity, energy conservation with F = 1, and the analytic
//! single-scattering Cook–Torrance BRDF.
//!
//! Every check is statistical: its tolerance is stated with its reason, and
//! the errors of several seeds are looked at together where one surface's
//! finite size matters.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_core::microfacet::{Distribution, Microfacet};
use bv_core::microsurface::measure::{self, GonioJob, GonioOptions};
use bv_core::microsurface::{SimFresnel, SlopeDistribution, Surface, SurfaceOptions};
use std::sync::Arc;

fn surface(dist: SlopeDistribution, ax: f64, ay: f64, n: usize, seed: u64) -> Surface {
    Surface::generate(&SurfaceOptions::new(dist, ax, ay, n, seed)).unwrap()
}

fn mean_sd(x: &[f64]) -> (f64, f64) {
    let n = x.len() as f64;
    let m = x.iter().sum::<f64>() / n;
    let v = x.iter().map(|v| (v - m).powi(2)).sum::<f64>() / (n - 1.0);
    (m, v.sqrt())
}

/// Beckmann: the triangles' slope variance per axis is αx²/2, αy²/2
/// (anisotropic), their covariance 0. A 256² surface with correlation length
/// 4 cells holds ~(256/4)² independent patches, so one surface's variance
/// scatters by a few per cent; over 8 seeds the mean relative error must be
/// within 3 standard errors of 0 (no bias) and each seed within 10 %.
#[test]
fn beckmann_slope_variance_is_alpha_squared_over_two() {
    let (ax, ay) = (0.3, 0.6);
    let mut ex = Vec::new();
    let mut ey = Vec::new();
    let mut cov = Vec::new();
    for seed in 1..=8 {
        let s = surface(SlopeDistribution::Beckmann, ax, ay, 256, seed);
        let st = measure::slope_stats(&s);
        ex.push(st.var_x / (ax * ax / 2.0) - 1.0);
        ey.push(st.var_y / (ay * ay / 2.0) - 1.0);
        cov.push(st.cov_xy / (ax * ay / 2.0));
    }
    for (name, e) in [("x", &ex), ("y", &ey), ("cov", &cov)] {
        let (m, sd) = mean_sd(e);
        eprintln!("{name}: mean rel error {m:+.4}, sd {sd:.4}, per seed {e:.4?}");
        assert!(
            m.abs() <= 3.0 * sd / (e.len() as f64).sqrt() + 2e-3,
            "{name}: biased, mean {m}"
        );
        assert!(
            e.iter().all(|v| v.abs() < 0.10),
            "{name}: a seed off by more than 10 %: {e:?}"
        );
    }
}

/// The projected-area histogram of facet normals against ∫_bin D cos θ dω,
/// as the L1 distance of the two distributions. For one seed it is the
/// finite-surface fluctuation (a few per cent); averaged over seeds the
/// histogram must come much closer (the fluctuation averages out, a wrong D
/// would not): the averaged distance is at most half the single-seed mean.
#[test]
fn ndf_histograms_match_d() {
    for (dist, ax, ay, n, seeds, single_tol) in [
        (SlopeDistribution::Beckmann, 0.4, 0.4, 256, 6, 0.08),
        (SlopeDistribution::Beckmann, 0.2, 0.5, 256, 6, 0.08),
        // GGX: the roughness scale has ~(512/8)² independent patches.
        (SlopeDistribution::Ggx, 0.3, 0.3, 512, 6, 0.08),
    ] {
        let mut sum: Option<Vec<f64>> = None;
        let mut errs = Vec::new();
        let mut expected = Vec::new();
        for seed in 1..=seeds {
            let s = surface(dist, ax, ay, n, 100 + seed);
            let h = measure::ndf_histogram(&s, 16, 8);
            errs.push(h.rel_error());
            let acc = sum.get_or_insert_with(|| vec![0.0; h.measured.len()]);
            for (a, m) in acc.iter_mut().zip(&h.measured) {
                *a += m;
            }
            expected = h.expected.clone();
        }
        let avg: Vec<f64> = sum.unwrap().iter().map(|v| v / seeds as f64).collect();
        let avg_err: f64 = avg.iter().zip(&expected).map(|(a, e)| (a - e).abs()).sum();
        let (m, _) = mean_sd(&errs);
        eprintln!(
            "{dist:?} α=({ax},{ay}): per-seed L1 {errs:.4?}, averaged histogram L1 {avg_err:.4}"
        );
        assert!(errs.iter().all(|e| *e < single_tol), "{dist:?}: {errs:?}");
        assert!(
            avg_err < 0.5 * m + 0.005,
            "{dist:?}: averaged L1 {avg_err} vs single {m}"
        );
    }
}

/// Masking on a Beckmann surface, α = 0.3 and 0.6, θ ≤ 80°.
///
/// Two checks. (1) The tracer: the escape fraction of rays leaving
/// front-facing points must equal, within 4σ (binomial), the surface's own
/// masking identity cos θ / ⟨⟨ω, m⟩⁺⟩ (Heitz 2014, eq. 2), which holds for
/// any heightfield and is computed from the facets without rays.
/// (2) Against Smith: within 2 % of Smith's closed form or 3σ (the issue's
/// criterion), σ here including the spread of the surfaces (two seeds).
#[test]
fn g1_of_a_beckmann_surface_matches_smith() {
    let thetas: Vec<f64> = [0.0f64, 20.0, 40.0, 60.0, 70.0, 80.0]
        .iter()
        .map(|d| d.to_radians())
        .collect();
    for alpha in [0.3, 0.6] {
        for seed in [7, 8] {
            let s = surface(SlopeDistribution::Beckmann, alpha, alpha, 256, seed);
            let pts = measure::measure_g1(&s, &thetas, 0.3, 40_000, seed).unwrap();
            for p in &pts {
                let th = p.theta.to_degrees();
                eprintln!(
                    "α {alpha} seed {seed} θ {th:4.1}: measured {:.4} ± {:.4}, identity {:.4}, Smith {:.4}, lost {}",
                    p.measured, p.sigma, p.identity, p.smith, p.lost
                );
                assert!(p.lost * 1000 < p.rays, "too many lost rays: {}", p.lost);
                assert!(
                    (p.measured - p.identity).abs() <= 4.0 * p.sigma + 1e-9,
                    "tracer vs identity at θ {th}: {} vs {}",
                    p.measured,
                    p.identity
                );
                let err = (p.measured - p.smith).abs();
                assert!(
                    err <= 0.02 * p.smith || err <= 3.0 * p.sigma,
                    "G1 vs Smith at α {alpha} θ {th}: {} ± {} vs {}",
                    p.measured,
                    p.sigma,
                    p.smith
                );
            }
        }
    }
}

/// Masking on the GGX surface: the tracer must agree with the surface's own
/// masking identity within 4σ at every angle (it holds for any heightfield).
/// Against Smith's GGX G1 the surface is only approximately Smith-like
/// (heights and slopes are correlated through the roughness scale, and its
/// heavy tail is sampled by (256/8)² patches; the surface masks less than
/// Smith predicts): within 4 % for θ ≤ 70°, a bound set from the deviations
/// seen on this surface (up to 2.3 %, at α = 0.8, θ = 70°), not a property
/// of GGX surfaces in general.
#[test]
fn g1_of_a_ggx_surface_matches_its_identity_and_roughly_smith() {
    let thetas: Vec<f64> = [20.0f64, 40.0, 60.0, 70.0, 80.0]
        .iter()
        .map(|d| d.to_radians())
        .collect();
    for alpha in [0.3, 0.8] {
        let s = surface(SlopeDistribution::Ggx, alpha, alpha, 256, 31);
        let pts = measure::measure_g1(&s, &thetas, 0.0, 40_000, 2).unwrap();
        for p in &pts {
            let th = p.theta.to_degrees();
            eprintln!(
                "GGX α {alpha} θ {th:4.1}: measured {:.4} ± {:.4}, identity {:.4}, Smith {:.4}",
                p.measured, p.sigma, p.identity, p.smith
            );
            assert!((p.measured - p.identity).abs() <= 4.0 * p.sigma + 1e-9);
            if th <= 70.0 {
                assert!((p.measured - p.smith).abs() <= 0.04 * p.smith);
            }
        }
    }
}

/// With F = 1 every ray leaves eventually: total ρhd = 1 within 1 % (the
/// bounce cap of 64 and lost rays are what could take energy; both are
/// counted and must be rare).
#[test]
fn furnace_total_albedo_is_one() {
    for (dist, alpha) in [
        (SlopeDistribution::Beckmann, 0.6),
        (SlopeDistribution::Ggx, 0.8),
    ] {
        let s = Arc::new(surface(dist, alpha, alpha, 256, 11));
        for theta in [0.0f64, 45.0, 75.0] {
            let opts = GonioOptions::new(theta.to_radians(), 100_000, 5);
            let g = GonioJob::new(Arc::clone(&s), opts).unwrap().run();
            eprintln!(
                "{dist:?} α {alpha} θi {theta}: single {:.4} multiple {:.4} total {:.5} ± {:.5}, dropped {}, lost {}",
                g.rho_single,
                g.rho_multiple,
                g.rho(),
                g.rho_sigma,
                g.dropped,
                g.lost
            );
            assert!((g.rho() - 1.0).abs() < 0.01, "ρ = {}", g.rho());
            assert!(
                g.rho_multiple > 0.0,
                "rough surface without multiple bounces"
            );
        }
    }
}

/// Single-bounce light against `F D G / (4 cos θi cos θo)` with Smith's
/// height-correlated G, on a Beckmann surface with α = 0.2 at θi = 30°, with
/// a conductor F. Smith is close to exact where masking is small: at α = 0.2
/// and these angles G differs from 1 by a few per cent, so Smith's own
/// approximation is a fraction of that. Per bin (bins holding ≥ 2 % of the
/// peak value) the error bar is the start tiles' spread
/// (`single_sigma_surface`, ray noise and the surface's own NDF fluctuation
/// together; with the ray noise alone the z-scores spread ~4× too wide on
/// 256² surfaces): within 4σ plus 3 % of the value (the systematic part —
/// measured single scattering sat 1.5 % above Smith's on average over the
/// bins of 1024² surfaces at α = 0.2 and 0.5). The z-scores must also look
/// like errors, not noise hidden by a large σ: their RMS within [0.5, 2].
/// The single-bounce ρhd must match the analytic within 1 %.
#[test]
fn single_bounce_brdf_matches_cook_torrance() {
    let s = Arc::new(surface(SlopeDistribution::Beckmann, 0.2, 0.2, 512, 21));
    let mut opts = GonioOptions::new(30f64.to_radians(), 400_000, 3);
    opts.fresnel = SimFresnel::Conductor { eta: 0.2, k: 3.9 };
    opts.n_theta = 12;
    opts.n_phi = 24;
    let g = GonioJob::new(Arc::clone(&s), opts).unwrap().run();
    let mf = Microfacet::new(Distribution::Beckmann, 0.2, 0.2);
    let bins = opts.n_theta * opts.n_phi;
    let analytic: Vec<f64> = (0..bins).map(|b| g.analytic_single(&mf, b)).collect();
    let peak = analytic.iter().cloned().fold(0.0, f64::max);
    let mut checked = 0;
    let mut z2 = 0.0;
    for (b, &a) in analytic.iter().enumerate() {
        if a < 0.02 * peak {
            continue;
        }
        checked += 1;
        let (m, sig) = (g.single[b], g.single_sigma_surface[b]);
        let err = (m - a).abs();
        z2 += ((m - a) / sig).powi(2);
        assert!(err <= 4.0 * sig + 0.03 * a, "bin {b}: {m} ± {sig} vs {a}");
    }
    let z_rms = (z2 / checked as f64).sqrt();
    eprintln!("z RMS over {checked} bins: {z_rms:.2}");
    assert!((0.5..=2.0).contains(&z_rms), "z RMS {z_rms}");
    let rho_a: f64 = (0..bins)
        .map(|b| analytic[b] * opts.bin_cos_integral(b))
        .sum();
    eprintln!(
        "single ρ {:.4} ± {:.4} vs analytic {rho_a:.4}; multiple {:.4}; {checked} bins checked",
        g.rho_single, g.rho_single_sigma, g.rho_multiple
    );
    assert!(checked >= 10);
    assert!((g.rho_single - rho_a).abs() < 0.01 * rho_a);
}

/// The surface-aware error bars are honest: two surfaces of different seeds
/// estimate the same BRDF, so per bin `(m1 − m2)/√(σ1² + σ2²)` must scatter
/// like a unit normal — RMS within [0.7, 1.4] over the bins holding light
/// (the RMS of ~100 such z has a spread of ~0.07; the tiles' σ is itself
/// estimated from 16 values, which widens it). Seed pairs 41/42 … 47/48
/// gave 1.15, 1.13, 1.02, 1.12: the tiles' σ runs ~10 % small (rays cross
/// tile borders, so the tiles are not quite independent). The
/// ray-noise-only σ gave 2.1–2.6: too small for comparing with a model, by
/// design.
#[test]
fn surface_error_bars_cover_the_spread_between_surfaces() {
    let run = |seed: u64| {
        let s = Arc::new(surface(SlopeDistribution::Beckmann, 0.5, 0.5, 256, seed));
        let mut o = GonioOptions::new(45f64.to_radians(), 200_000, seed);
        o.n_theta = 12;
        o.n_phi = 24;
        GonioJob::new(s, o).unwrap().run()
    };
    let (a, b) = (run(41), run(42));
    let (mut z2, mut z2_ray, mut n) = (0.0, 0.0, 0usize);
    let peak = a.single.iter().cloned().fold(0.0, f64::max);
    for k in 0..a.single.len() {
        if a.single[k] < 0.05 * peak {
            continue;
        }
        let d = a.single[k] - b.single[k];
        z2 += d * d / (a.single_sigma_surface[k].powi(2) + b.single_sigma_surface[k].powi(2));
        z2_ray += d * d / (a.single_sigma[k].powi(2) + b.single_sigma[k].powi(2));
        n += 1;
    }
    let rms = (z2 / n as f64).sqrt();
    let rms_ray = (z2_ray / n as f64).sqrt();
    eprintln!("{n} bins: z RMS with the tiles' σ {rms:.2}, with ray noise only {rms_ray:.2}");
    assert!(n >= 50);
    assert!((0.7..=1.4).contains(&rms), "z RMS {rms}");
}

/// The same seed gives the same surface and the same measurement on 1 and
/// 2 threads, and for any step sizes.
#[test]
fn deterministic_across_threads() {
    let run = |threads: usize, step: usize| {
        let pool = rayon::ThreadPoolBuilder::new()
            .num_threads(threads)
            .build()
            .unwrap();
        pool.install(|| {
            let s = Arc::new(surface(SlopeDistribution::Ggx, 0.5, 0.3, 128, 9));
            let mut job = GonioJob::new(Arc::clone(&s), GonioOptions::new(0.7, 30_000, 4)).unwrap();
            let g = loop {
                if let Some(g) = job.step(step) {
                    break g;
                }
            };
            let g1 = measure::measure_g1(&s, &[1.0], 0.0, 20_000, 4).unwrap();
            (s.heights().to_vec(), g, g1)
        })
    };
    let a = run(1, 1);
    let b = run(2, 3);
    assert!(a.0 == b.0, "surfaces differ");
    assert_eq!(a.1, b.1);
    assert_eq!(a.2, b.2);
}

/// Bad input is refused with a reason, never a panic.
#[test]
fn bad_input_is_refused() {
    let ok = SurfaceOptions::new(SlopeDistribution::Beckmann, 0.3, 0.3, 64, 1);
    for bad in [
        SurfaceOptions { alpha_x: 0.0, ..ok },
        SurfaceOptions {
            alpha_y: -1.0,
            ..ok
        },
        SurfaceOptions {
            alpha_x: f64::NAN,
            ..ok
        },
        SurfaceOptions { size: 100, ..ok },
        SurfaceOptions {
            size: 1 << 20,
            ..ok
        },
        SurfaceOptions { size: 8, ..ok },
        SurfaceOptions {
            correlation_cells: 0.5,
            ..ok
        },
    ] {
        assert!(Surface::generate(&bad).is_err(), "{bad:?} accepted");
    }
    let s = Arc::new(Surface::generate(&ok).unwrap());
    for bad in [
        GonioOptions::new(0.1, 0, 1),
        GonioOptions::new(2.0, 10, 1),
        GonioOptions::new(f64::NAN, 10, 1),
        GonioOptions {
            n_theta: 0,
            ..GonioOptions::new(0.1, 10, 1)
        },
        GonioOptions {
            fresnel: SimFresnel::Conductor { eta: -1.0, k: 0.0 },
            ..GonioOptions::new(0.1, 10, 1)
        },
    ] {
        assert!(
            GonioJob::new(Arc::clone(&s), bad).is_err(),
            "{bad:?} accepted"
        );
    }
    assert!(measure::measure_g1(&s, &[1.0], 0.0, 0, 1).is_err());
    assert!(measure::measure_g1(&s, &[2.0], 0.0, 10, 1).is_err());
}

/// Every model that names its slopes (`Ndf::slopes`, what the microsurface
/// view and the gonioreflectometer generate a specimen from) has exactly
/// that D: checked against the closed forms of anisotropic Beckmann and GGX
/// written here, over directions of the upper hemisphere. Blinn's θh
/// Gaussian and a two-scale mixture name none.
#[test]
fn named_slopes_are_the_models_own_distribution() {
    use bv_core::ModelSpec;
    use serde_json::json;
    use std::f64::consts::PI;
    let d_closed = |dist: Distribution, ax: f64, ay: f64, h: glam::DVec3| {
        let (x, y, z) = (h.x / ax, h.y / ay, h.z);
        let c2 = z * z;
        match dist {
            Distribution::Beckmann => (-(x * x + y * y) / c2).exp() / (PI * ax * ay * c2 * c2),
            Distribution::Ggx => 1.0 / (PI * ax * ay * (x * x + y * y + c2).powi(2)),
            Distribution::Blinn => unreachable!(),
        }
    };
    let cases = [
        (
            "cook-torrance",
            json!({"distribution": "ggx", "alpha": 0.3}),
            true,
        ),
        (
            "cook-torrance",
            json!({"distribution": "beckmann", "alpha_x": 0.2, "alpha_y": 0.5}),
            true,
        ),
        (
            "cook-torrance",
            json!({"distribution": "blinn", "alpha": 0.3}),
            false,
        ),
        (
            "disney",
            json!({"roughness": 0.6, "anisotropic": 0.8}),
            true,
        ),
        ("rough-dielectric", json!({"alpha": 0.4}), true),
        ("lambert", json!({}), false),
    ];
    for (id, p, named) in cases {
        let b = ModelSpec::from_json(id, &p).unwrap().build().unwrap();
        let slopes = b.ndf().and_then(|n| n.slopes());
        assert_eq!(slopes.is_some(), named, "{id} {p}");
        let Some((dist, ax, ay)) = slopes else {
            continue;
        };
        let ndf = b.ndf().unwrap();
        for i in 0..200 {
            let t = (i as f64 + 0.5) / 200.0 * 1.4;
            let f = i as f64 * 2.399;
            let h = glam::DVec3::new(t.sin() * f.cos(), t.sin() * f.sin(), t.cos());
            let (a, e) = (ndf.d(h), d_closed(dist, ax, ay, h));
            assert!(
                (a - e).abs() <= 1e-9 * e.max(1e-12),
                "{id} {p} h {h}: {a} vs {e}"
            );
        }
    }
}
