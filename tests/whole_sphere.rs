//! Views on the whole sphere (issue 33, part 3): the polar view's interface
//! marks (refracted ray, critical angle, Snell's window) checked against
//! Snell's law in closed form, light from below in the state, scene files
//! and `bv render`, the note of views with only reflecting models and the
//! light below, and the albedo curve's ρR and ρT against independent
//! numbers (the smooth interface's Fresnel reflectance, bv-core's Monte
//! Carlo estimator).

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::derive::albedo::AlbedoData;
use bv::session::frame::build_scene;
use bv::session::runtime::Runtime;
use bv::session::state::{AppState, Incident};
use bv::views::polar::{Mark, interface_marks};
use bv_core::mean_rgb;
use std::sync::atomic::{AtomicBool, AtomicUsize};

fn state(model: &str, params: serde_json::Value, theta_deg: f64) -> (AppState, Runtime) {
    let mut s = AppState::default();
    s.add(bv_core::ModelSpec::from_json(model, &params).unwrap());
    s.selected = s.brdfs.first().map(|b| b.id);
    s.incident = Incident {
        theta_deg,
        phi_deg: 20.0,
    };
    let mut rt = Runtime::default();
    rt.sync(&s);
    (s, rt)
}

fn marks(model: &str, params: serde_json::Value, theta_deg: f64) -> Vec<Mark> {
    let (s, rt) = state(model, params, theta_deg);
    let scene = build_scene(&s, &rt, false);
    interface_marks(&scene, 1.0, true)
}

fn texts(m: &[Mark]) -> Vec<String> {
    m.iter()
        .filter_map(|m| match m {
            Mark::Text { text, .. } => Some(text.clone()),
            _ => None,
        })
        .collect()
}

/// The signed in-plane angle (degrees) of the refracted ray's line (the one
/// dashed 9 points long), if drawn.
fn refracted_deg(m: &[Mark]) -> Option<f64> {
    m.iter().find_map(|m| match m {
        Mark::Line {
            points,
            dash: Some(d),
            ..
        } if *d == 9.0 => {
            let p = points[1];
            Some(p[0].atan2(p[1]).to_degrees())
        }
        _ => None,
    })
}

/// The signed angles (degrees) of the dashed critical-angle lines.
fn critical_lines_deg(m: &[Mark]) -> Vec<f64> {
    m.iter()
        .filter_map(|m| match m {
            Mark::Line {
                points,
                dash: Some(d),
                ..
            } if *d == 4.0 => {
                let p = points[1];
                Some(p[0].atan2(p[1]).to_degrees())
            }
            _ => None,
        })
        .collect()
}

fn rd(eta: f64) -> serde_json::Value {
    serde_json::json!({"alpha": 0.2, "eta": eta})
}

#[test]
fn polar_marks_refract_by_snell_and_bound_snells_window_at_the_critical_angle() {
    for eta in [1.333f64, 1.5, 2.42] {
        // Closed forms, computed here: θc = asin(1/η), sin θt = sin θi / η.
        let theta_c = (1.0 / eta).asin().to_degrees();
        for ti in [0.0f64, 30.0, 60.0, 85.0] {
            let m = marks("rough-dielectric", rd(eta), ti);
            let theta_t = (ti.to_radians().sin() / eta).asin().to_degrees();
            // Light above: the refracted ray leaves below, on the mirror
            // side, at 180° − θt from the upward normal.
            let a = refracted_deg(&m).unwrap();
            assert!((a - (180.0 - theta_t)).abs() < 1e-9 || (ti == 0.0 && a.abs() > 179.999));
            let t = texts(&m);
            assert!(
                t.iter().any(|s| s == &format!("ωt θt {theta_t:.1}°")),
                "{eta} {ti}: {t:?}"
            );
            assert!(
                t.iter()
                    .any(|s| s == &format!("Snell's window, θc {theta_c:.1}°")),
                "{t:?}"
            );
            // The window's edges: θc either side of the downward normal.
            let mut c = critical_lines_deg(&m);
            c.sort_by(f64::total_cmp);
            assert_eq!(c.len(), 2);
            assert!((c[0] + (180.0 - theta_c)).abs() < 1e-9, "{c:?}");
            assert!((c[1] - (180.0 - theta_c)).abs() < 1e-9, "{c:?}");
            // Every transmitted direction lies inside the window.
            assert!(180.0 - a.abs() <= theta_c + 1e-9);
        }
    }
}

#[test]
fn light_from_inside_refracts_up_to_the_critical_angle_then_is_totally_reflected() {
    // Glass, light inside at 30° from the downward normal (θi = 150°):
    // sin θt = 1.5 sin 30° = 0.75, leaving above at θt = 48.59°.
    let m = marks("rough-dielectric", rd(1.5), 150.0);
    let want = (1.5 * 30f64.to_radians().sin()).asin().to_degrees();
    let a = refracted_deg(&m).unwrap();
    assert!((a - want).abs() < 1e-9, "{a} vs {want}");
    assert!(!texts(&m).iter().any(|s| s.contains("TIR")));
    // At 45° from the downward normal (θi = 135°) it is beyond θc = 41.8°.
    let m = marks("rough-dielectric", rd(1.5), 135.0);
    assert_eq!(refracted_deg(&m), None);
    assert!(
        texts(&m).iter().any(|s| s.contains("TIR")),
        "{:?}",
        texts(&m)
    );
    // The smooth `glass` model reports its index too and gets the same marks.
    let g = marks("glass", serde_json::json!({"eta": 1.5}), 150.0);
    assert!((refracted_deg(&g).unwrap() - want).abs() < 1e-9);
}

#[test]
fn reflection_only_models_get_no_marks() {
    for (model, params) in [
        ("cook-torrance", serde_json::json!({"alpha": 0.2})),
        ("lambert", serde_json::json!({})),
    ] {
        assert!(marks(model, params.clone(), 30.0).is_empty(), "{model}");
        let (s, rt) = state(model, params, 30.0);
        let svg = bv::views::polar::polar_svg(&build_scene(&s, &rt, false), [800.0, 600.0], true);
        assert!(!svg.contains("θc") && !svg.contains("Snell"), "{model}");
    }
    // The SVG export draws the same marks as the window.
    let (s, rt) = state("rough-dielectric", rd(1.5), 30.0);
    let svg = bv::views::polar::polar_svg(&build_scene(&s, &rt, false), [800.0, 600.0], true);
    for t in ["Snell&apos;s window, θc 41.8°", "ωt θt 19.5°"] {
        assert!(svg.contains(t), "{t}");
    }
}

#[test]
fn the_light_below_with_only_reflecting_models_gives_a_note_not_a_blank() {
    let (s, rt) = state("cook-torrance", serde_json::json!({"alpha": 0.2}), 120.0);
    let scene = build_scene(&s, &rt, false);
    let note = bv::views::light_below_note(&scene).unwrap();
    assert!(
        note.contains("120.0") && note.contains("below") && note.contains("transmits"),
        "{note}"
    );
    // A transmitting model has something to show from below.
    let (s, rt) = state("rough-dielectric", rd(1.5), 120.0);
    assert!(bv::views::light_below_note(&build_scene(&s, &rt, false)).is_none());
    // Above the surface there is no note.
    let (s, rt) = state("cook-torrance", serde_json::json!({"alpha": 0.2}), 60.0);
    assert!(bv::views::light_below_note(&build_scene(&s, &rt, false)).is_none());
}

#[test]
fn the_polar_curve_of_a_light_below_is_finite_everywhere() {
    // Light inside, at the horizon band's edge, straight from below, and
    // beyond the critical angle: every sample of the curve is finite and
    // something is transmitted or reflected.
    for ti in [90.5, 120.0, 150.0, 180.0] {
        let (s, rt) = state("rough-dielectric", rd(1.5), ti);
        let scene = build_scene(&s, &rt, false);
        let b = &scene.brdfs[0];
        let curve = bv::derive::slices::plane_of_incidence(
            b.brdf.as_ref(),
            ti.to_radians(),
            20f64.to_radians(),
            1440,
            false,
        );
        assert!(curve.iter().all(|p| p.value.is_finite() && p.value >= 0.0));
        assert!(curve.iter().any(|p| p.value > 0.0), "{ti}");
        let m = interface_marks(&scene, 1.0, true);
        for mk in &m {
            if let Mark::Line { points, .. } | Mark::Fill { points, .. } = mk {
                assert!(points.iter().flatten().all(|v| v.is_finite()));
            }
        }
    }
}

fn curve(params: serde_json::Value) -> AlbedoData {
    let b = bv_core::ModelSpec::from_json("rough-dielectric", &params)
        .unwrap()
        .build()
        .unwrap();
    AlbedoData::compute(
        b.as_ref(),
        0.0,
        &AtomicUsize::new(0),
        &AtomicBool::new(false),
    )
    .unwrap()
}

#[test]
fn albedo_curve_of_a_dielectric_has_both_sides_and_parts_that_sum() {
    let d = curve(serde_json::json!({"alpha": 0.3, "eta": 1.5}));
    assert!(d.has_parts());
    // 0°, 2°, …, 88° above and 92°, …, 180° below.
    assert_eq!(d.theta_deg.len(), 90);
    assert_eq!(d.theta_deg[0], 0.0);
    assert!((d.theta_deg[44] - 88.0).abs() < 1e-9);
    assert!((d.theta_deg[45] - 92.0).abs() < 1e-9);
    assert!((d.theta_deg[89] - 180.0).abs() < 1e-9);
    for k in 0..d.rho.len() {
        let (r, t, sum) = (
            mean_rgb(d.reflected[k].value),
            mean_rgb(d.transmitted[k].value),
            mean_rgb(d.rho[k].value),
        );
        assert!((r + t - sum).abs() < 1e-9, "{k}: {r} + {t} vs {sum}");
        assert!(r >= 0.0 && t >= 0.0 && r.is_finite() && t.is_finite());
        // Single scattering loses energy, never gains it (white furnace).
        let band = mean_rgb(d.rho[k].allowance(3.0));
        assert!(sum <= 1.0 + band + 1e-3, "{k}: ρR + ρT = {sum}");
    }
    // A rough surface loses most at grazing light (Walter 2007 §5.2 / Heitz
    // 2016: the missing multiple scattering grows with α and θi).
    let at = |deg: f64| {
        let k = d
            .theta_deg
            .iter()
            .position(|t| (t - deg).abs() < 1e-9)
            .unwrap();
        mean_rgb(d.rho[k].value)
    };
    assert!(at(0.0) > at(88.0), "{} vs {}", at(0.0), at(88.0));
}

#[test]
fn albedo_parts_match_bv_cores_monte_carlo_and_smooth_fresnel() {
    // Nearly smooth glass: ρR(θi) is close to the smooth interface's Fresnel
    // reflectance (bv_core::optics, closed form) and ρR + ρT close to 1; from
    // inside beyond the critical angle everything is reflected.
    let d = curve(serde_json::json!({"alpha": 0.02, "eta": 1.5}));
    for (k, &t) in d.theta_deg.iter().enumerate() {
        let (from_normal, ei, et) = if t > 90.0 {
            (180.0 - t, 1.5, 1.0)
        } else {
            (t, 1.0, 1.5)
        };
        if from_normal > 80.0 {
            continue; // grazing: the microfacet lobe spreads past the horizon
        }
        let f = bv_core::optics::dielectric(from_normal.to_radians(), ei, et)
            .unwrap()
            .r;
        let r = mean_rgb(d.reflected[k].value);
        let sum = mean_rgb(d.rho[k].value);
        assert!((sum - 1.0).abs() < 0.01, "θi {t}: ρR + ρT = {sum}");
        // Within a few degrees of the critical angle the rough surface blurs
        // Fresnel's step from total reflection to refraction (measured with
        // α = 0.02: ρR 0.76 at 44° inside, where a smooth one gives 1).
        let theta_c = (1.0f64 / 1.5).asin().to_degrees();
        if t > 90.0 && (from_normal - theta_c).abs() < 5.0 {
            continue;
        }
        assert!((r - f).abs() < 0.015, "θi {t}: ρR {r} vs Fresnel {f}");
    }
    // An independent estimator: bv-core's Monte Carlo parts at a few angles
    // of the rough curve agree with the curve's (quadrature) within bands.
    let params = serde_json::json!({"alpha": 0.3, "eta": 1.5});
    let d = curve(params.clone());
    let b = bv_core::ModelSpec::from_json("rough-dielectric", &params)
        .unwrap()
        .build()
        .unwrap();
    for deg in [20.0f64, 60.0, 150.0] {
        let k = d
            .theta_deg
            .iter()
            .position(|t| (t - deg).abs() < 1e-9)
            .unwrap();
        let wi = bv_core::frame::from_spherical(deg.to_radians(), 0.0);
        let mc = bv_core::analysis::albedo::rho_hd_parts_dir(b.as_ref(), wi, 1 << 16, 7);
        for (name, mine, theirs) in [
            ("ρR", &d.reflected[k], &mc.reflected),
            ("ρT", &d.transmitted[k], &mc.transmitted),
        ] {
            let (a, b) = (mean_rgb(mine.value), mean_rgb(theirs.value));
            let tol = mean_rgb(mine.allowance(3.0)) + mean_rgb(theirs.allowance(3.0)) + 2e-3;
            assert!(
                (a - b).abs() <= tol,
                "θi {deg} {name}: {a} vs MC {b} ± {tol}"
            );
        }
    }
}

#[test]
fn reflection_only_albedo_curves_are_unchanged_in_shape() {
    let b = bv_core::ModelSpec::from_json("lambert", &serde_json::json!({"albedo": 0.5}))
        .unwrap()
        .build()
        .unwrap();
    let d = AlbedoData::compute(
        b.as_ref(),
        0.0,
        &AtomicUsize::new(0),
        &AtomicBool::new(false),
    )
    .unwrap();
    assert!(!d.has_parts());
    assert_eq!(d.theta_deg.len(), 45);
    assert!(d.reflected.is_empty() && d.transmitted.is_empty());
}

fn bv(args: &[&str]) -> std::process::Output {
    std::process::Command::new(env!("CARGO_BIN_EXE_bv"))
        .args(args)
        .output()
        .unwrap()
}

#[test]
fn render_takes_a_light_below_and_refuses_the_horizon() {
    let dir = std::env::temp_dir().join(format!("bv-whole-sphere-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("below.png");
    let png_s = png.to_str().unwrap();
    let common = [
        "render", "--view", "polar", "--width", "320", "--height", "240",
    ];
    // The horizon: a clear error, no image.
    let out = bv(&[
        &common[..],
        &[
            "--model",
            "rough-dielectric",
            "--theta-i",
            "90",
            "--out",
            png_s,
        ],
    ]
    .concat());
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--theta-i 90") && err.contains("horizon"),
        "{err}"
    );
    // Beyond the sphere.
    let out = bv(&[
        &common[..],
        &[
            "--model",
            "rough-dielectric",
            "--theta-i",
            "181",
            "--out",
            png_s,
        ],
    ]
    .concat());
    assert!(!out.status.success());
    // A reflecting model with the light below: why, not a blank figure.
    let out = bv(&[
        &common[..],
        &["--model", "lambert", "--theta-i", "120", "--out", png_s],
    ]
    .concat());
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("below the surface") && err.contains("transmits"),
        "{err}"
    );
    // A transmitting model with the light below draws.
    let out = bv(&[
        &common[..],
        &[
            "--model",
            "rough-dielectric",
            "--param",
            "alpha=0.2",
            "--theta-i",
            "135",
            "--out",
            png_s,
        ],
    ]
    .concat());
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    assert!(png.exists());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn slice_takes_a_light_below_for_a_transmitting_model_only() {
    let out = bv(&[
        "slice",
        "--model",
        "rough-dielectric",
        "--param",
        "alpha=0.2",
        "--theta-i",
        "150",
        "--samples",
        "8",
    ]);
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(!text.contains("NaN") && !text.contains("inf"), "{text}");
    let out = bv(&["slice", "--model", "lambert", "--theta-i", "150"]);
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    assert!(
        err.contains("--theta-i 150") && err.contains("transmits"),
        "{err}"
    );
}

/// Segments of the 3D lobe's guide lines that lie along `dir` (beyond the
/// origin).
fn segments_along(
    model: &str,
    params: serde_json::Value,
    theta_deg: f64,
    dir: glam::DVec3,
) -> usize {
    let (s, rt) = state(model, params, theta_deg);
    let scene = build_scene(&s, &rt, false);
    let mut view = bv::views::lobe3d::Lobe3dView::default();
    let frame = view.frame(
        &scene,
        eframe::egui::vec2(400.0, 300.0),
        [0.0, 0.0, 0.0, 1.0],
        true,
    );
    let d = dir.as_vec3();
    frame
        .lines
        .iter()
        .filter(|l| {
            let (a, b) = (glam::Vec3::from(l.a), glam::Vec3::from(l.b));
            a.length() > 0.01
                && b.length() > 0.01
                && a.cross(d).length() < 1e-4
                && b.cross(d).length() < 1e-4
                && a.dot(d) > 0.0
        })
        .count()
}

#[test]
fn the_3d_lobe_draws_the_refracted_ray_by_snell() {
    // Light from above at 30° into glass and from inside at 30° from −z:
    // the dashed ray lies along Snell's direction, written here from the
    // angles (sin θt = sin θi · ηi/ηt, leaving on the far side, away from
    // the light's azimuth).
    let phi = 20f64.to_radians();
    let snell = |theta_t: f64, down: bool| {
        let (s, c) = theta_t.sin_cos();
        glam::DVec3::new(-s * phi.cos(), -s * phi.sin(), if down { -c } else { c })
    };
    let down = snell((30f64.to_radians().sin() / 1.5).asin(), true);
    assert!(segments_along("rough-dielectric", rd(1.5), 30.0, down) > 2);
    let up = snell((1.5 * 30f64.to_radians().sin()).asin(), false);
    assert!(segments_along("rough-dielectric", rd(1.5), 150.0, up) > 2);
    // Beyond the critical angle from inside no ray: no segment in the
    // refracted ray's colour (dark theme: rgb 110 190 255, opacity 0.95).
    let refr_segments = |model: &str, params: serde_json::Value, ti: f64| {
        let (s, rt) = state(model, params, ti);
        let scene = build_scene(&s, &rt, false);
        let mut view = bv::views::lobe3d::Lobe3dView::default();
        let f = view.frame(
            &scene,
            eframe::egui::vec2(400.0, 300.0),
            [0.0, 0.0, 0.0, 1.0],
            true,
        );
        let want = [110.0 / 255.0, 190.0 / 255.0, 1.0, 0.95];
        f.lines
            .iter()
            .filter(|l| l.color.iter().zip(want).all(|(a, b)| (a - b).abs() < 1e-3))
            .count()
    };
    assert!(refr_segments("rough-dielectric", rd(1.5), 150.0) > 2);
    assert_eq!(refr_segments("rough-dielectric", rd(1.5), 135.0), 0);
    assert_eq!(
        refr_segments("cook-torrance", serde_json::json!({"alpha": 0.2}), 30.0),
        0
    );
    assert_eq!(
        segments_along(
            "cook-torrance",
            serde_json::json!({"alpha": 0.2}),
            30.0,
            down
        ),
        0
    );
}

/// The sampling view's histogram for a scene, computed now (as a figure).
fn histogram(
    model: &str,
    params: serde_json::Value,
    theta_deg: f64,
) -> bv_core::analysis::sample_histogram::SampleHistogram {
    let (s, rt) = state(model, params, theta_deg);
    let mut scene = build_scene(&s, &rt, false);
    scene.figure = true;
    let b = scene.brdfs[0].clone();
    let shown = bv::derive::sampling::histogram(&bv::derive::Waker::none(), &scene, &b);
    let (outcome, _) = shown.value().unwrap();
    outcome.as_ref().clone().unwrap()
}

#[test]
fn the_sampling_histogram_covers_both_hemispheres_of_a_transmitting_model() {
    use bv::derive::sampling::{N_PHI, N_THETA, SIGNIFICANCE};
    // Light above and below: draws on both sides, χ² over the whole sphere
    // passes for the model's own sampler (Walter 2007 §5.3).
    for ti in [30.0, 150.0] {
        let h = histogram(
            "rough-dielectric",
            serde_json::json!({"alpha": 0.3, "eta": 1.5}),
            ti,
        );
        assert!(h.whole_sphere);
        assert_eq!(h.n_theta, 2 * N_THETA);
        assert_eq!(h.observed.len(), 2 * N_THETA * N_PHI);
        let upper: u64 = h.observed[..N_THETA * N_PHI].iter().sum();
        let lower: u64 = h.observed[N_THETA * N_PHI..].iter().sum();
        assert!(upper > 0 && lower > 0, "{ti}: {upper} above, {lower} below");
        assert!(
            h.chi2.p_value >= SIGNIFICANCE,
            "{ti}: p = {}",
            h.chi2.p_value
        );
        assert!(h.points.iter().any(|w| w.z < 0.0) && h.points.iter().any(|w| w.z > 0.0));
    }
    // A reflecting model keeps its hemisphere.
    let h = histogram("cook-torrance", serde_json::json!({"alpha": 0.3}), 30.0);
    assert!(!h.whole_sphere);
    assert_eq!(h.n_theta, N_THETA);
}
