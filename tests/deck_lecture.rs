//! The lecture deck against its lecture: every scene names the seed slides it
//! shows (`seed`, checked against the seed's headings), and the scenes whose
//! plan (`LECTURE.md`) gives a number show it, read from the data the view
//! draws and compared with a closed form computed here.

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::derive::albedo::AlbedoData;
use bv::derive::slices::plane_of_incidence;
use bv::session::deck::{self, Slide};
use bv::session::frame::build_scene;
use bv::session::runtime::Runtime;
use bv::session::scene_file::Builds;
use bv::views::snell::{SnellView, snell_figure};
use bv_core::mean_rgb;
use std::collections::BTreeSet;
use std::path::Path;
use std::sync::atomic::{AtomicBool, AtomicUsize};

fn manifest() -> &'static Path {
    Path::new(env!("CARGO_MANIFEST_DIR"))
}

fn slides() -> Vec<Slide> {
    let loaded = deck::load(
        &manifest().join("assets/decks/reflectance.toml"),
        Builds::Required,
    )
    .unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    loaded.deck.slides
}

/// The seed's headings: (to cover, administrative).
fn headings() -> (Vec<String>, Vec<String>) {
    let text = std::fs::read_to_string(manifest().join("tests/data/seed-headings.txt")).unwrap();
    let (mut cover, mut admin) = (Vec::new(), Vec::new());
    for line in text
        .lines()
        .filter(|l| !l.starts_with('#') && !l.is_empty())
    {
        match line.strip_prefix("- ") {
            Some(a) => admin.push(a.to_string()),
            None => cover.push(line.to_string()),
        }
    }
    (cover, admin)
}

fn slide<'a>(slides: &'a [Slide], title: &str) -> &'a Slide {
    slides
        .iter()
        .find(|s| s.title == title)
        .unwrap_or_else(|| panic!("no scene titled {title:?}"))
}

#[test]
fn the_heading_list_is_the_seeds_own() {
    // The list is a copy (the seed is not part of the repository); where the
    // seed is at hand, the copy must still match it.
    let Ok(dir) = std::fs::read_dir(manifest().join("../shared/seed")) else {
        eprintln!("no ../shared/seed here: the copy in tests/data is used as it is");
        return;
    };
    let mut seen = Vec::new();
    for e in dir {
        let text = std::fs::read_to_string(e.unwrap().path()).unwrap();
        for h in text.lines().filter_map(|l| l.strip_prefix("# ")) {
            if !seen.iter().any(|s| s == h) {
                seen.push(h.to_string());
            }
        }
    }
    let (cover, admin) = headings();
    let mut listed: Vec<String> = cover.into_iter().chain(admin).collect();
    listed.sort();
    seen.sort();
    assert_eq!(listed, seen);
}

#[test]
fn every_scene_names_real_seed_slides_and_the_deck_covers_the_lecture() {
    let slides = slides();
    let (cover, admin) = headings();
    let mut covered = BTreeSet::new();
    for (i, s) in slides.iter().enumerate() {
        assert!(
            !s.seed.is_empty(),
            "scene {i} ({:?}) has no `seed`",
            s.title
        );
        for h in &s.seed {
            assert!(
                cover.contains(h),
                "scene {i} ({:?}): {h:?} is not a heading of the seed{}",
                s.title,
                if admin.contains(h) {
                    " a deck covers (it is administrative)"
                } else {
                    ""
                }
            );
            covered.insert(h.clone());
        }
    }
    let missing: Vec<&String> = cover.iter().filter(|h| !covered.contains(*h)).collect();
    let share = covered.len() as f64 / cover.len() as f64;
    eprintln!(
        "{} scenes cover {} of the seed's {} headings ({:.0} %); still to come: {missing:?}",
        slides.len(),
        covered.len(),
        cover.len(),
        100.0 * share
    );
    // What the deck covers today; it only grows (the goal is 90 %).
    assert!(slides.len() >= 82, "{} scenes", slides.len());
    assert!(covered.len() >= 53, "{} headings covered", covered.len());
    // In the seed's order: a scene's first heading never comes before the
    // previous scene's first one, by more than a part of the lecture
    // (the plan shows some ideas early, e.g. Fresnel before Ideal Specular).
    let pos = |h: &str| cover.iter().position(|c| c == h).unwrap();
    let order: Vec<usize> = slides.iter().map(|s| pos(&s.seed[0])).collect();
    let backwards = order.windows(2).filter(|w| w[1] + 8 < w[0]).count();
    assert_eq!(backwards, 0, "scenes out of the seed's order: {order:?}");
}

/// The scene's BRDFs' in-plane curves (the polar view's data): per BRDF, the
/// samples at signed θo.
fn polar_curves(s: &Slide) -> Vec<Vec<(f64, f64)>> {
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let scene = build_scene(&s.state, &rt, false);
    let (ti, pi) = (
        scene.incident.theta_deg.to_radians(),
        scene.incident.phi_deg.to_radians(),
    );
    scene
        .brdfs
        .iter()
        .map(|b| {
            plane_of_incidence(b.brdf.as_ref(), ti, pi, 3600, false)
                .into_iter()
                .map(|p| (p.x.to_degrees(), p.value))
                .collect()
        })
        .collect()
}

fn peak(c: &[(f64, f64)]) -> (f64, f64) {
    c.iter()
        .copied()
        .max_by(|a, b| a.1.total_cmp(&b.1))
        .unwrap()
}

fn value_at(c: &[(f64, f64)], deg: f64) -> f64 {
    c.iter()
        .min_by(|a, b| (a.0 - deg).abs().total_cmp(&(b.0 - deg).abs()))
        .unwrap()
        .1
}

fn albedo_curves(s: &Slide) -> Vec<AlbedoData> {
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let scene = build_scene(&s.state, &rt, false);
    scene
        .brdfs
        .iter()
        .map(|b| {
            AlbedoData::compute(
                b.brdf.as_ref(),
                scene.incident.phi_deg.to_radians(),
                &AtomicUsize::new(0),
                &AtomicBool::new(false),
            )
            .unwrap()
        })
        .collect()
}

fn rho_at(d: &AlbedoData, deg: f64) -> f64 {
    let k = d
        .theta_deg
        .iter()
        .position(|t| (t - deg).abs() < 1e-9)
        .unwrap_or_else(|| panic!("no θi = {deg} in {:?}", d.theta_deg));
    mean_rgb(d.rho[k].value)
}

#[test]
fn classical_phong_peaks_at_ks_over_cos_theta_i_whatever_e() {
    let slides = slides();
    let c = polar_curves(slide(&slides, "Classical Phong"));
    let want = 0.3 / 45f64.to_radians().cos();
    for curve in &c {
        let (at, v) = peak(curve);
        assert!((at - 45.0).abs() <= 0.1, "peak at {at}");
        assert!((v - want).abs() < 1e-3 * want, "{v} vs {want}");
    }
}

#[test]
fn modified_phong_is_taller_when_sharper_by_e_plus_2_over_2_pi() {
    let slides = slides();
    let c = polar_curves(slide(&slides, "Modified Phong: normalised"));
    for (curve, e) in c.iter().zip([10.0f64, 100.0]) {
        let (at, v) = peak(curve);
        let want = (e + 2.0) / (2.0 * std::f64::consts::PI);
        assert!((at - 30.0).abs() <= 0.1, "peak at {at}");
        assert!((v - want).abs() < 1e-3 * want, "{v} vs {want}");
    }
}

#[test]
fn linearity_the_mix_is_the_weighted_sum_of_its_parts() {
    let slides = slides();
    let c = polar_curves(slide(&slides, "Property 1: linearity"));
    for (k, ((a, b), mix)) in c[0].iter().zip(&c[1]).zip(&c[2]).enumerate() {
        let sum = 0.6 * a.1 + 0.4 * b.1;
        assert!((mix.1 - sum).abs() <= 1e-12 * sum.max(1.0), "{k}");
    }
    // Lambert 0.8/π under it everywhere, the glossy lobe above it at +45°.
    assert!((value_at(&c[0], 10.0) - 0.8 / std::f64::consts::PI).abs() < 1e-12);
    assert!(value_at(&c[2], 45.0) > value_at(&c[2], 0.0));
}

#[test]
fn energy_classical_phong_with_kd_0_crosses_1_only_near_grazing() {
    let slides = slides();
    let s = slide(&slides, "Property 4: conservation of energy");
    let phong = s
        .state
        .brdfs
        .iter()
        .position(|b| b.spec.id() == "phong")
        .unwrap();
    let d = &albedo_curves(s)[phong];
    // With kd 0 the excess is the 1/cos θi alone. At normal incidence the
    // lobe is cos^e about the normal: ρhd(0) = ks ∫ cos^e θ cos θ dω =
    // ks 2π/(e+2) (the lecture's Phong has no 1/π).
    let want0 = 0.8 * 2.0 * std::f64::consts::PI / 12.0;
    let r0 = rho_at(d, 0.0);
    assert!(
        (r0 - want0).abs() < 0.01,
        "ρhd(0) = {r0}, closed form {want0}"
    );
    for t in [0.0, 20.0, 40.0, 50.0] {
        assert!((rho_at(d, t) - r0).abs() < 0.01, "{t}: {}", rho_at(d, t));
    }
    assert!(rho_at(d, 84.0) < 1.0 && rho_at(d, 88.0) > 1.0);
    // Every other BRDF of the slide stays at or below 1.
    for (i, other) in albedo_curves(s).iter().enumerate() {
        if i != phong {
            assert!(other.rho.iter().all(|r| mean_rgb(r.value) <= 1.0 + 1e-3));
        }
    }
}

#[test]
fn diffuse_f_without_pi_reflects_pi_times_kd() {
    let slides = slides();
    let d = albedo_curves(slide(&slides, "Diffuse: reciprocal, and f ≤ 1/π"));
    for t in [0.0, 30.0, 60.0, 88.0] {
        assert!((rho_at(&d[0], t) - 1.0).abs() < 1e-3, "{t}");
        assert!(
            (rho_at(&d[1], t) - 0.5 * std::f64::consts::PI).abs() < 2e-3,
            "{t}: {}",
            rho_at(&d[1], t)
        );
    }
}

#[test]
fn blinn_phong_reflects_half_as_much_as_phong_at_70_degrees() {
    let slides = slides();
    let d = albedo_curves(slide(&slides, "Blinn-Phong: the half vector"));
    let (p, b) = (rho_at(&d[0], 70.0), rho_at(&d[1], 70.0));
    assert!(b <= 0.5 * p, "Phong {p}, Blinn {b}");
    // Near-equal at normal incidence (the same highlight in the plane).
    assert!((rho_at(&d[0], 0.0) - rho_at(&d[1], 0.0)).abs() < 0.03);
}

#[test]
fn bsdf_slide_transmits_near_snells_direction() {
    let slides = slides();
    let s = slide(&slides, "BSDF = BRDF + BTDF");
    let c = &polar_curves(s)[0];
    // Transmitted side: θo beyond ±90°. Snell: sin θt = sin 45° / 1.5.
    let theta_t = (45f64.to_radians().sin() / 1.5).asin().to_degrees();
    let below: Vec<(f64, f64)> = c.iter().copied().filter(|p| p.0.abs() > 90.0).collect();
    let (at, _) = peak(&below);
    // Signed angle from +z: the refracted ray is at 180° − θt on the far
    // side of the light. A rough lobe's peak sits near it (within α's blur).
    let from_down = 180.0 - at.abs();
    assert!(
        (from_down - theta_t).abs() < 3.0,
        "peak {from_down}° from −n, Snell {theta_t}°"
    );
    // And the reflected lobe peaks at the mirror direction or a little past
    // it: F and 1/cos θo grow towards grazing (the off-specular peak of a
    // rough surface, Torrance & Sparrow 1967), here at about 50°.
    let above: Vec<(f64, f64)> = c.iter().copied().filter(|p| p.0.abs() < 90.0).collect();
    let p = peak(&above);
    assert!(p.0 > 44.9 && p.0 < 55.0, "reflected peak {p:?}");
}

#[test]
fn snell_slides_show_snells_law_fresnel_and_the_window() {
    let slides = slides();
    // Closed forms written here: Snell and the Fresnel term.
    for (title, eta, below) in [
        ("Snell's law", 1.5, false),
        ("Law of refraction and total internal reflection", 1.5, true),
        ("Optical manhole", 1.333, true),
    ] {
        let s = slide(&slides, title);
        let mut rt = Runtime::default();
        rt.sync(&s.state);
        let scene = build_scene(&s.state, &rt, false);
        let interface = SnellView::default().interface(&scene);
        assert_eq!(interface.from_below, below, "{title}");
        assert!((interface.eta - eta).abs() < 1e-12, "{title}");
        let ti = s.state.incident.theta_deg;
        let fig = snell_figure(ti.to_radians(), &interface, true).unwrap();
        let texts = fig.texts().join(" | ");
        let (ei, et) = if below { (eta, 1.0) } else { (1.0, eta) };
        let tt = (ei / et * ti.to_radians().sin()).asin().to_degrees();
        let r = fresnel_dielectric(ti.to_radians().cos(), ei, et);
        for want in [
            format!("θt = {tt:.1}°"),
            format!("R = {r:.3}"),
            format!("T = {:.3}", 1.0 - r),
        ] {
            assert!(texts.contains(&want), "{title}: {want} not in {texts}");
        }
        if below {
            let c = (1.0 / eta).asin().to_degrees();
            let want = format!("2 × {c:.1}°");
            assert!(texts.contains(&want), "{title}: {want} not in {texts}");
        }
    }
}

/// The unpolarised Fresnel reflectance of a smooth dielectric interface,
/// written here from the Fresnel equations.
fn fresnel_dielectric(cos_i: f64, eta_i: f64, eta_t: f64) -> f64 {
    let sin_t = eta_i / eta_t * (1.0 - cos_i * cos_i).sqrt();
    if sin_t >= 1.0 {
        return 1.0;
    }
    let cos_t = (1.0 - sin_t * sin_t).sqrt();
    let rs = (eta_i * cos_i - eta_t * cos_t) / (eta_i * cos_i + eta_t * cos_t);
    let rp = (eta_t * cos_i - eta_i * cos_t) / (eta_t * cos_i + eta_i * cos_t);
    0.5 * (rs * rs + rp * rp)
}

/// LECTURE.md scene 47 (N9): the facet normals' histogram of the
/// simulated surface lies within 5 % of the model's D wherever D is at
/// least a tenth of its peak, and the model's D is normalised.
#[test]
fn the_facet_normals_follow_d() {
    use bv::derive::jobs::Waker;
    use bv::derive::microsurface;
    let slides = slides();
    let s = slide(&slides, "D is the distribution of the facets' normals");
    assert!(s.state.plots.microsurface.ndf);
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let mut scene = build_scene(&s.state, &rt, false);
    // As a figure: the simulation is computed before it is drawn.
    scene.figure = true;
    let specimen = microsurface::specimen(&scene);
    assert_eq!(specimen.describe(), "Beckmann α 0.30");
    let shown = microsurface::ndf(&Waker::none(), &scene, &specimen);
    let done = shown.done.expect("a figure computes its histogram");
    let h = &done.value;
    // Σ expected (θ bins and the steeper rest) is ∫ D cos θm dω = 1.
    let total: f64 = h.expected.iter().sum();
    assert!((total - 1.0).abs() < 1e-9, "{total}");
    let peak = (0..h.n_theta).map(|t| h.d_values(t).1).fold(0.0, f64::max);
    let mut checked = 0;
    for t in 0..h.n_theta {
        let (measured, model) = h.d_values(t);
        if model >= 0.1 * peak {
            checked += 1;
            assert!(
                (measured - model).abs() <= 0.05 * model,
                "bin {t}: measured D {measured}, model {model}"
            );
        }
    }
    assert!(checked >= 8, "{checked} bins checked");
}

/// Issue 29: the lobe view's gonio overlay draws the surface's readings at
/// the detector's directions in the plane of incidence, the one-bounce
/// readings near the F = 1 model's section, all bounces above them. "Near":
/// within 4σ + 15 % up to 45° from the normal and 4σ + 30 % beyond, since
/// Smith's masking assumes heights and normals uncorrelated, which a
/// generated surface's are not (Heitz 2014, §5): this GGX α 0.6 surface
/// reads 5–10 % above the model near the normal and up to 28 % at 75°.
#[test]
fn the_lobe_overlay_sets_the_surface_against_the_f1_lobe() {
    use bv::derive::jobs::Waker;
    use bv::views::gonio_overlay::readings_3d;
    let slides = slides();
    let s = slide(&slides, "The lost energy, around the whole lobe");
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let mut scene = build_scene(&s.state, &rt, false);
    scene.figure = true;
    let overlay = readings_3d(&scene, &Waker::none()).expect("a figure measures now");
    assert_eq!(overlay.sets.len(), 2);
    let (all, one) = (&overlay.sets[0], &overlay.sets[1]);
    assert!(all.filled && !one.filled);
    let reference = overlay.reference.as_ref().expect("the F = 1 lobe");
    let b = scene.primary().unwrap();
    let furnace = b.brdf.furnace().unwrap();
    let wi = scene.wi();
    let mut checked = 0;
    for (a, o) in all.stops.iter().zip(&one.stops) {
        for &(dir, v, lo, hi) in [a, o] {
            // In the plane of incidence (φi = 0: the x–z plane).
            assert!(
                dir.y.abs() < 1e-9 && (dir.length() - 1.0).abs() < 1e-9,
                "{dir}"
            );
            assert!(lo <= v && v <= hi, "{lo} {v} {hi}");
        }
        let (dir, v, lo, hi) = *o;
        assert_eq!(dir, a.0);
        let sigma = (hi - lo) / 4.0;
        let sigma_all = (a.3 - a.2) / 4.0;
        // All the light is at least the light of one bounce.
        assert!(a.1 >= v - 3.0 * (sigma + sigma_all), "{} < {v}", a.1);
        if dir.z > 0.25 {
            checked += 1;
            let model = mean_rgb(furnace.eval(wi, dir));
            let share = if dir.z >= 45f64.to_radians().cos() {
                0.15
            } else {
                0.30
            };
            assert!(
                (model - v).abs() <= 4.0 * sigma + share * model,
                "at {dir}: one bounce {v} ± {sigma}, the model {model}"
            );
        }
    }
    assert!(checked >= 25, "{checked} stops checked");
    // The dashed section is the F = 1 model's own values.
    for &(dir, v) in reference.iter().step_by(17) {
        if dir.z > 0.0 {
            assert!((mean_rgb(furnace.eval(wi, dir)) - v).abs() < 1e-9);
        }
    }
}

/// LECTURE.md scene 03 with N5: the four classes as small multiples, each
/// panel on its own scale, with the plan's numbers on the curves.
#[test]
fn four_classes_each_on_its_own_scale() {
    use bv::views::polar::{delta_spikes, panel_scales};
    let slides = slides();
    let s = slide(&slides, "Four classes of reflection");
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let scene = build_scene(&s.state, &rt, false);
    assert!(s.state.plots.small_multiples && !s.state.display.log);
    let panels = panel_scales(&scene);
    assert_eq!(panels.len(), 4, "{panels:?}");
    let theta_i = 45f64.to_radians();
    for (ids, outer) in &panels {
        assert_eq!(ids.len(), 1);
        let b = scene.brdfs.iter().find(|b| b.id == ids[0]).unwrap();
        let plane = plane_of_incidence(b.brdf.as_ref(), theta_i, 0.0, 361, false);
        let (at, peak) = plane
            .iter()
            .map(|p| (p.x.to_degrees(), p.value))
            .fold((0.0, 0.0), |m, p| if p.1 > m.1 { p } else { m });
        // The panel's outer ring is its own curve's peak rounded up, not
        // the tallest lobe's (which would leave diffuse a dot).
        if peak > 0.0 {
            assert!(
                *outer >= peak && *outer <= 1.6 * peak,
                "{}: ring {outer}, peak {peak}",
                b.label
            );
        }
        match b.label.as_str() {
            "diffuse" => assert!((peak - 0.8 / std::f64::consts::PI).abs() < 1e-3, "{peak}"),
            // Plan: orange peaks at +45° with f = 7.0 (GGX α 0.15, F = 1).
            // (GGX's lobe leans a little past the mirror direction.)
            "glossy" => {
                let wi = glam::DVec3::new(-theta_i.sin(), 0.0, theta_i.cos());
                let wo = glam::DVec3::new(theta_i.sin(), 0.0, theta_i.cos());
                let f = mean_rgb(b.brdf.eval(wi, wo));
                assert!(
                    (f - 7.0).abs() < 0.05 && (at - 45.0).abs() <= 2.0,
                    "{f} {at} {peak}"
                )
            }
            // Plan: red peaks towards the light, −45°, with f = 0.955.
            "retro-reflective" => {
                assert!(
                    (at + 45.0).abs() <= 1.0 && (peak - 0.955).abs() < 0.01,
                    "{at} {peak}"
                )
            }
            "perfect specular" => {
                let sp = delta_spikes(&scene.only(b.id), *outer);
                assert_eq!(sp.len(), 1);
                assert_eq!(sp[0].text(), "δ 1.000");
            }
            other => panic!("unexpected BRDF {other}"),
        }
    }
}

#[test]
fn delta_spikes_carry_their_weights_and_stay_visible() {
    use bv::views::polar::{MIN_SPIKE, delta_spikes};
    let slides = slides();
    let outer = 1.0;
    let spikes = |title: &str| {
        let s = slide(&slides, title);
        let mut rt = Runtime::default();
        rt.sync(&s.state);
        let scene = build_scene(&s.state, &rt, false);
        delta_spikes(&scene, outer)
    };
    // Smooth glass at 60°: F at +60°, 1 − F refracted at θt from −n.
    let sp = spikes("Ideal specular: reflection and transmission");
    assert_eq!(sp.len(), 2, "{sp:?}");
    let f = fresnel_dielectric(60f64.to_radians().cos(), 1.0, 1.5);
    let theta_t = (60f64.to_radians().sin() / 1.5).asin().to_degrees();
    let angle = |s: &bv::views::polar::Spike| s.tip[0].atan2(s.tip[1]).to_degrees();
    let refl = sp.iter().find(|s| s.tip[1] > 0.0).unwrap();
    let refr = sp.iter().find(|s| s.tip[1] < 0.0).unwrap();
    assert!((refl.weight - f).abs() < 1e-9, "{} vs {f}", refl.weight);
    assert!((refr.weight - (1.0 - f)).abs() < 1e-9);
    assert!((angle(refl) - 60.0).abs() < 1e-9);
    assert!((180.0 - angle(refr).abs() - theta_t).abs() < 1e-9);
    assert_eq!(refl.text(), "δ 0.089");
    // The transmitted lobe's label also gives its radiance factor
    // (ηo/ηi)² (1 − F) = 2.25 × 0.911 (LECTURE.md N3).
    let radiance = 1.5f64.powi(2) * (1.0 - f);
    assert_eq!(refr.text(), format!("δ 0.911, radiance × {radiance:.3}"));
    assert_eq!(refr.text(), "δ 0.911, radiance × 2.049");
    assert!(refr.legend().ends_with("δ transmitted") && refl.legend().ends_with("δ reflected"));
    // The small one is drawn at the shortest length, not as a dot.
    let len = |s: &bv::views::polar::Spike| s.tip[0].hypot(s.tip[1]);
    assert!((len(refl) - MIN_SPIKE * outer).abs() < 1e-12);
    assert!((len(refr) - 0.911 * outer).abs() < 1e-3);
    // A mirror with F = 1: one spike at the mirror direction, weight 1.
    let sp = spikes("Ideal reflection as a delta function");
    assert_eq!(sp.len(), 1);
    assert!((sp[0].weight - 1.0).abs() < 1e-12 && (angle(&sp[0]) - 30.0).abs() < 1e-9);
}

#[test]
fn layered_surfaces_the_coupled_body_darkens_where_the_coat_brightens() {
    let slides = slides();
    let s = slide(&slides, "Layered surfaces: a coat over a body");
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let scene = build_scene(&s.state, &rt, false);
    // Light from the eye: a point whose normal is tilted by θ from the view
    // has ωi = ωo at θ, and the lit sphere shows f cos θ there.
    let radiance = |k: usize, deg: f64| {
        let w = bv_core::frame::from_spherical(deg.to_radians(), 0.0);
        mean_rgb(scene.brdfs[k].brdf.eval(w, w)) * deg.to_radians().cos()
    };
    let (naive80, coupled80) = (radiance(0, 80.0), radiance(1, 80.0));
    assert!(coupled80 * 5.0 <= naive80, "{coupled80} vs {naive80}");
    let (naive30, coupled30) = (radiance(0, 30.0), radiance(1, 30.0));
    assert!(
        (naive30 - coupled30).abs() < 0.1 * naive30,
        "{naive30} vs {coupled30}"
    );

    let d = albedo_curves(slide(&slides, "Layered surfaces: the energy argument"));
    // The naive sum passes 1 towards grazing light; the coupled model never.
    assert!(rho_at(&d[0], 0.0) < 1.0 && rho_at(&d[0], 88.0) > 1.0);
    assert!(d[1].rho.iter().all(|r| mean_rgb(r.value) < 0.85));
    // The layered model (a coat over the same body) stays below 1 too, and
    // its body darkens at the rim like the coupled one.
    assert!(d[2].rho.iter().all(|r| mean_rgb(r.value) < 1.0));
    assert!(radiance(2, 80.0) < 0.5 * naive80, "{}", radiance(2, 80.0));
}

/// The term view's charts for a slide, with the slide's own toggles.
fn term_charts_of(s: &Slide) -> bv::views::terms::TermCharts {
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let scene = build_scene(&s.state, &rt, false);
    bv::views::terms::term_charts(&scene, s.state.plots.terms, true)
}

/// `∫_a^b g` by composite Simpson with `n` (even) intervals.
fn simpson(g: impl Fn(f64) -> f64, a: f64, b: f64, n: usize) -> f64 {
    let h = (b - a) / n as f64;
    let mut s = g(a) + g(b);
    for k in 1..n {
        s += g(a + k as f64 * h) * if k % 2 == 1 { 4.0 } else { 2.0 };
    }
    s * h / 3.0
}

fn at_x(points: &[[f64; 2]], x: f64) -> f64 {
    points
        .iter()
        .min_by(|a, b| (a[0] - x).abs().total_cmp(&(b[0] - x).abs()))
        .unwrap()[1]
}

#[test]
fn d_slides_show_d_alone_normalised() {
    use std::f64::consts::PI;
    let slides = slides();
    // Blinn's Gaussian in angle, c·exp(−(θh/m)²), with c from
    // ∫ D cos θh dω = 1 over the hemisphere (quadrature written here).
    let c = |m: f64| {
        1.0 / simpson(
            |t| (-(t / m).powi(2)).exp() * t.cos() * t.sin() * 2.0 * PI,
            0.0,
            PI / 2.0,
            20_000,
        )
    };
    let ch = term_charts_of(slide(&slides, "D must be normalised"));
    assert!(ch.g.is_none() && ch.f.is_none(), "only D is shown");
    let d = ch.d.unwrap();
    for (s, m) in d.series.iter().zip([0.2, 0.5]) {
        let want = c(m);
        let got = s.points[0][1];
        assert!((got - want).abs() < 1e-3 * want, "m {m}: {got} vs {want}");
    }
    // The narrower one is taller, by about 5.4.
    let ratio = d.series[0].points[0][1] / d.series[1].points[0][1];
    assert!((ratio - 5.4).abs() < 0.1, "{ratio}");

    // Beckmann against Blinn's Gaussian, on the log scale (log10 D).
    let ch = term_charts_of(slide(&slides, "Beckmann against Gaussian"));
    assert!(ch.g.is_none() && ch.f.is_none());
    let d = ch.d.unwrap();
    let beckmann = |m: f64, t: f64| (-(t.tan() / m).powi(2)).exp() / (PI * m * m * t.cos().powi(4));
    for (k, m) in [(0, 0.2), (2, 0.6)] {
        for deg in [0.0f64, 10.0, 20.0, 45.0] {
            let want = beckmann(m, deg.to_radians()).log10();
            let got = at_x(&d.series[k].points, deg);
            assert!(
                (got - want).abs() < 1e-6,
                "m {m} at {deg}°: {got} vs {want}"
            );
        }
    }
    // Small m: the two agree within 5 % up to 20°; large m: far apart at 60°.
    for deg in [0.0, 10.0, 20.0] {
        let r = 10f64.powf(at_x(&d.series[0].points, deg) - at_x(&d.series[1].points, deg));
        assert!((r - 1.0).abs() < 0.05, "{deg}°: ratio {r}");
    }
    let r60 = 10f64.powf(at_x(&d.series[3].points, 60.0) - at_x(&d.series[2].points, 60.0));
    assert!(r60 > 10.0, "Blinn/Beckmann at 60° for m 0.6: {r60}");
}

#[test]
fn the_g_slide_shows_g2_alone_v_groove_against_smith() {
    let slides = slides();
    let ch = term_charts_of(slide(&slides, "G: shadowing and masking"));
    assert!(ch.d.is_none() && ch.f.is_none());
    let g = ch.g.unwrap();
    let g2: Vec<_> = g.series.iter().filter(|s| s.label.contains("G2")).collect();
    assert_eq!(
        g2.len(),
        2,
        "{:?}",
        g.series.iter().map(|s| &s.label).collect::<Vec<_>>()
    );
    assert!(g.series.iter().all(|s| !s.label.contains("G1")));
    // V-groove (Cook & Torrance 1982) in the plane at θi = 80°:
    // G = min(1, 2(n·h)(n·ωo)/(ωo·h), 2(n·h)(n·ωi)/(ωo·h)).
    let vgroove = |theta_o_deg: f64| {
        let ti = 80f64.to_radians();
        let to = theta_o_deg.to_radians();
        let wi = glam::DVec3::new(-ti.sin(), 0.0, ti.cos());
        let wo = glam::DVec3::new(to.sin(), 0.0, to.cos());
        let h = (wi + wo).normalize();
        let (nh, no, ni, oh) = (h.z, wo.z, wi.z, wo.dot(h));
        (2.0 * nh * no / oh).min(2.0 * nh * ni / oh).min(1.0)
    };
    let (v, s) = (&g2[0].points, &g2[1].points);
    assert!((at_x(v, 80.0) - 1.0).abs() < 1e-9, "{}", at_x(v, 80.0));
    assert!((at_x(v, -80.0) - vgroove(-80.0)).abs() < 1e-9);
    assert!((vgroove(-80.0) - 0.06).abs() < 0.005);
    // Height-correlated Smith, 1/(1 + Λ(θi) + Λ(θo)): the same at the
    // mirror direction and in backscatter, and below the v-groove's 1.
    assert!((at_x(s, 80.0) - at_x(s, -80.0)).abs() < 1e-9);
    assert!((at_x(s, 80.0) - 0.56).abs() < 0.01, "{}", at_x(s, 80.0));
    // The v-groove cross-sections (LECTURE.md N9) under the chart, at the
    // mirror direction, the normal and back towards the light: flat
    // grooves all lit and seen; at θo = 0 the facets tilt 40° and the light
    // reaches 2 cos 80° of each; towards the light the grooves are 80°
    // deep and 2 cos² 80° of each facet is both lit and seen. Each panel's
    // G is the curve's value there.
    let sl = slide(&slides, "G: shadowing and masking");
    assert!(sl.state.plots.terms.vgroove);
    let mut rt = Runtime::default();
    rt.sync(&sl.state);
    let scene = build_scene(&sl.state, &rt, false);
    let panels = bv::views::terms::vgroove_sections(&scene);
    let at: Vec<_> = panels.iter().map(|p| p.theta_o_deg).collect();
    assert_eq!(at, vec![80.0, 0.0, -80.0]);
    let c80 = 80f64.to_radians().cos();
    for (p, tilt, lit, seen) in [
        (&panels[0], 0.0, 1.0, 1.0),
        (&panels[1], 40.0, 2.0 * c80, 1.0),
        (&panels[2], 80.0, 2.0 * c80 * c80, 2.0 * c80 * c80),
    ] {
        let s = p.section.unwrap();
        assert!((s.tilt.to_degrees() - tilt).abs() < 1e-9, "{p:?}");
        assert!(
            (s.lit - lit).abs() < 1e-12 && (s.seen - seen).abs() < 1e-12,
            "{p:?}"
        );
        assert!((s.g - at_x(v, p.theta_o_deg)).abs() < 1e-9, "{p:?}");
    }
}

/// `|got − want| ≤ tol · want`, with the scene and quantity in the message.
fn near(got: f64, want: f64, tol: f64, what: &str) {
    assert!(
        (got - want).abs() <= tol * want.abs(),
        "{what}: {got} where the plan reads {want}"
    );
}

/// LECTURE.md scene 11 [bv]: four GGX lobes at θi = 30° peak at the mirror
/// direction, about ten times taller per decade of α².
#[test]
fn property_0_peaks_grow_tenfold_per_decade_of_alpha_squared() {
    let slides = slides();
    let c = polar_curves(slide(&slides, "Property 0: 0 ≤ f ≤ ∞"));
    let want = [1.16, 10.6, 118.0, 1061.0];
    assert_eq!(c.len(), 4);
    for (k, (curve, w)) in c.iter().zip(want).enumerate() {
        let (at, v) = peak(curve);
        // α 0.3's lobe leans off-specular (its 1/cos θo), the sharp ones not.
        let lean = if k == 0 { 4.0 } else { 1.0 };
        assert!((at - 30.0).abs() <= lean, "peak at {at}°");
        // On the 0.05° grid the sharpest lobe's top may fall between samples.
        near(v, w, 0.03, "Property 0 peak");
    }
}

/// LECTURE.md scene 46 [bv, cf]: single-scattering Cook–Torrance with
/// F = 1 keeps ρhd(0°) = 0.988 / 0.688 / 0.307 at α 0.1 / 0.5 / 1.0.
#[test]
fn cook_torrance_loses_energy_with_roughness() {
    let slides = slides();
    let d = albedo_curves(slide(
        &slides,
        "Cook-Torrance: single scattering loses energy",
    ));
    for (data, want) in d.iter().zip([0.988, 0.688, 0.307]) {
        let r = rho_at(data, 0.0);
        assert!((r - want).abs() <= 0.005, "ρhd(0°) {r}, the plan {want}");
        assert!(data.rho.iter().all(|e| mean_rgb(e.value) < 1.0));
    }
}

/// Torrance–Sparrow in the plane of incidence (Cook & Torrance 1982):
/// `F D G / (4 cos θi cos θo)` with Beckmann D of roughness `m`, the v-groove
/// G and glass's exact F, light at θi on the negative side, θo signed.
fn torrance_sparrow(ti: f64, to: f64, m: f64) -> f64 {
    use std::f64::consts::PI;
    let wi = glam::DVec3::new(-ti.sin(), 0.0, ti.cos());
    let wo = glam::DVec3::new(to.sin(), 0.0, to.cos());
    let h = (wi + wo).normalize();
    let t2 = (1.0 - h.z * h.z) / (h.z * h.z);
    let d = (-t2 / (m * m)).exp() / (PI * m * m * h.z.powi(4));
    let oh = wo.dot(h);
    let g = (2.0 * h.z * wo.z / oh).min(2.0 * h.z * wi.z / oh).min(1.0);
    fresnel_dielectric(oh, 1.0, 1.5) * d * g / (4.0 * wi.z * wo.z)
}

/// LECTURE.md scene 53 [bv]: at θi = 75° Blinn-Phong peaks at the mirror
/// direction (1.16) and Torrance–Sparrow at the horizon (21.4, the closed
/// form at 89.95°); from θi = 15° its peak has grown about 560×.
#[test]
fn cook_torrance_moves_off_specular_at_grazing_light() {
    let slides = slides();
    let c = polar_curves(slide(
        &slides,
        "Cook-Torrance against Phong at grazing light",
    ));
    let (at, v) = peak(&c[0]);
    assert!((at - 75.0).abs() <= 1.0, "Blinn-Phong peaks at {at}°");
    near(v, 1.16, 0.02, "Blinn-Phong peak");
    let (at, v) = peak(&c[1]);
    assert!(at >= 85.0, "Cook-Torrance peaks at {at}°");
    let ti = 75f64.to_radians();
    near(
        v,
        torrance_sparrow(ti, at.to_radians(), 0.3),
        1e-6,
        "Cook-Torrance at its peak",
    );
    near(v, 21.4, 0.02, "Cook-Torrance peak");
    let at_15 = (0..900)
        .map(|k| torrance_sparrow(15f64.to_radians(), (f64::from(k) / 10.0).to_radians(), 0.3))
        .fold(0.0, f64::max);
    near(at_15, 0.038, 0.02, "its peak at θi = 15°");
    let growth = v / at_15;
    assert!((500.0..620.0).contains(&growth), "grows {growth}×");
}

/// LECTURE.md scene 56 [cf]: the mix of 0.5 Lambert 0.8, 0.4 GGX α 0.2 and
/// 0.1 mirror: a floor at 0.5 · 0.8/π = 0.127, a lobe to 1.69 at +45° and a
/// spike labelled "δ 0.100".
#[test]
fn a_complex_brdf_is_floor_lobe_and_spike() {
    use bv::views::polar::delta_spikes;
    let slides = slides();
    let s = slide(&slides, "A complex BRDF: diffuse + glossy + specular");
    let c = polar_curves(s);
    // The floor: the curve never dips below the Lambert part, and where the
    // lobe's tail is least it is within 7 % of it.
    let floor = 0.5 * 0.8 / std::f64::consts::PI;
    let least = c[0].iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    assert!(
        least >= floor - 1e-9 && least <= 1.07 * floor,
        "floor {least} vs {floor}"
    );
    // GGX's lobe leans a little past the mirror direction.
    let (at, _) = peak(&c[0]);
    assert!((at - 45.0).abs() <= 3.0, "the lobe peaks at {at}°");
    near(value_at(&c[0], 45.0), 1.69, 0.02, "the lobe at +45°");
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let scene = build_scene(&s.state, &rt, false);
    let sp = delta_spikes(&scene, 1.0);
    assert_eq!(sp.len(), 1);
    assert_eq!(sp[0].text(), "δ 0.100");
}

/// LECTURE.md scene 58 [bv]: Hapke's opposition surge is a cusp at the
/// light's direction, θo = −30°: 0.166 there, 0.148 at −28°, 0.115 at −20°.
#[test]
fn hapke_surges_at_the_lights_direction() {
    let slides = slides();
    let c = polar_curves(slide(
        &slides,
        "BRDF illustrations: Hapke's opposition surge",
    ));
    near(value_at(&c[0], -30.0), 0.166, 0.02, "Hapke at −30°");
    near(value_at(&c[0], -28.0), 0.148, 0.02, "Hapke at −28°");
    near(value_at(&c[0], -20.0), 0.115, 0.02, "Hapke at −20°");
}

/// LECTURE.md scene 43 [bv]: Lafortune's lobes put the mirror side's
/// maximum off-specular, at +63° (0.0623 over 0.0454 at +50°), a retro
/// maximum at −50° (0.0633), over a floor of kd/π = 0.032.
#[test]
fn lafortune_peaks_off_specular_and_backwards() {
    let slides = slides();
    let c = polar_curves(slide(&slides, "Lafortune"));
    let mirror_side: Vec<(f64, f64)> = c[0].iter().copied().filter(|p| p.0 > 0.0).collect();
    let (at, v) = peak(&mirror_side);
    assert!((at - 63.0).abs() <= 2.0, "mirror-side maximum at {at}°");
    near(v, 0.0623, 0.02, "mirror-side maximum");
    near(
        value_at(&c[0], 50.0),
        0.0454,
        0.02,
        "at the mirror direction",
    );
    let retro: Vec<(f64, f64)> = c[0].iter().copied().filter(|p| p.0 < 0.0).collect();
    let (at, v) = peak(&retro);
    assert!((at + 50.0).abs() <= 2.0, "retro maximum at {at}°");
    near(v, 0.0633, 0.02, "retro maximum");
    let floor = c[0].iter().map(|p| p.1).fold(f64::INFINITY, f64::min);
    assert!(floor >= 0.1 / std::f64::consts::PI - 1e-9, "floor {floor}");
}

/// LECTURE.md scene 45 [cf]: GGX α 0.3 with glass's Fresnel at θi = 60°:
/// D(0) = 1/(πα²) = 3.54, F(0) = 0.040 and F(60°) = 0.089 (computed here),
/// and G2 at the mirror direction ≈ 0.89.
#[test]
fn the_ingredients_read_their_closed_forms() {
    let slides = slides();
    let ch = term_charts_of(slide(&slides, "The ingredients: D, G, F"));
    let d = ch.d.expect("D is shown");
    let d0 = d.series[0].points[0];
    assert!(d0[0].abs() < 1e-9);
    near(d0[1], 1.0 / (std::f64::consts::PI * 0.09), 1e-4, "D(0)");
    let f = ch.f.expect("F is shown");
    let fpts = &f.series[0].points;
    near(
        at_x(fpts, 0.0),
        fresnel_dielectric(1.0, 1.0, 1.5),
        1e-3,
        "F(0°)",
    );
    near(
        at_x(fpts, 60.0),
        fresnel_dielectric(60f64.to_radians().cos(), 1.0, 1.5),
        2e-3,
        "F(60°)",
    );
    let g = ch.g.expect("G is shown");
    let g2 = g
        .series
        .iter()
        .find(|s| s.label.contains("G2"))
        .expect("a G2 curve");
    near(at_x(&g2.points, 60.0), 0.89, 0.02, "G2 at ωr (+60°)");
}

/// The Fresnel view's figure of a scene.
fn fresnel_figure_of(s: &Slide) -> bv::views::fresnel::FresnelFigure {
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let scene = build_scene(&s.state, &rt, false);
    bv::views::fresnel::figure_of(&scene, true)
}

/// The points of the series whose label contains every one of `words`.
fn series_with<'a>(c: &'a bv::views::chart::Chart, words: &[&str]) -> &'a [[f64; 2]] {
    let s = c
        .series
        .iter()
        .find(|s| words.iter().all(|w| s.label.contains(w)))
        .unwrap_or_else(|| {
            let labels: Vec<&str> = c.series.iter().map(|s| s.label.as_str()).collect();
            panic!("no series with {words:?} in {labels:?}")
        });
    &s.points
}

/// A conductor's (Rs, Rp) for the complex index n = η + ik, the exact
/// form in complex arithmetic written here (pbrt-v4's FrComplex): cos θt =
/// √(1 − sin²θi / n²), rs = (cos θi − n cos θt)/(cos θi + n cos θt),
/// rp = (n cos θi − cos θt)/(n cos θi + cos θt).
fn fresnel_conductor(cos_i: f64, eta: f64, k: f64) -> (f64, f64) {
    type C = (f64, f64);
    let mul = |a: C, b: C| (a.0 * b.0 - a.1 * b.1, a.0 * b.1 + a.1 * b.0);
    let div = |a: C, b: C| {
        let d = b.0 * b.0 + b.1 * b.1;
        ((a.0 * b.0 + a.1 * b.1) / d, (a.1 * b.0 - a.0 * b.1) / d)
    };
    let sqrt = |a: C| {
        let r = (a.0 * a.0 + a.1 * a.1).sqrt();
        let re = (0.5 * (r + a.0)).sqrt();
        let im = (0.5 * (r - a.0)).sqrt().copysign(a.1);
        (re, im)
    };
    let n: C = (eta, k);
    let sin2: C = (1.0 - cos_i * cos_i, 0.0);
    let s2t = div(sin2, mul(n, n));
    let cos_t = sqrt((1.0 - s2t.0, -s2t.1));
    let ci: C = (cos_i, 0.0);
    let n_ct = mul(n, cos_t);
    let rs = div((ci.0 - n_ct.0, -n_ct.1), (ci.0 + n_ct.0, n_ct.1));
    let n_ci = mul(n, ci);
    let rp = div(
        (n_ci.0 - cos_t.0, n_ci.1 - cos_t.1),
        (n_ci.0 + cos_t.0, n_ci.1 + cos_t.1),
    );
    (rs.0 * rs.0 + rs.1 * rs.1, rp.0 * rp.0 + rp.1 * rp.1)
}

/// LECTURE.md scene 27 [cf]: one F0 = 0.5 read as a conductor with η = 1
/// (k = 2) and as a dielectric with η = 5.83: equal at 0°, 0.700 against
/// 0.443 at 80°; the conductor's Rp dips to 0.335 near 63.3°.
#[test]
fn one_f0_two_readings() {
    let slides = slides();
    let fig = fresnel_figure_of(slide(&slides, "Conductors: one F0, two readings"));
    let c = &fig.chart;
    let blue = series_with(c, &["η = 1, k = 2", "F"]);
    let orange = series_with(c, &["η = 5.83", "F"]);
    near(at_x(blue, 0.0), 0.5, 2e-3, "the conductor's F0");
    near(at_x(orange, 0.0), 0.5, 2e-3, "the dielectric's F0");
    near(at_x(blue, 80.0), 0.700, 5e-3, "the conductor at 80°");
    near(at_x(orange, 80.0), 0.443, 5e-3, "the dielectric at 80°");
    // Closed forms written here for the same two readings.
    let (rs, rp) = fresnel_conductor(80f64.to_radians().cos(), 1.0, 2.0);
    near(
        at_x(blue, 80.0),
        0.5 * (rs + rp),
        2e-3,
        "the conductor at 80° (closed form)",
    );
    near(
        at_x(orange, 80.0),
        fresnel_dielectric(80f64.to_radians().cos(), 1.0, 5.83),
        2e-3,
        "the dielectric at 80° (closed form)",
    );
    let rp = series_with(c, &["Rp"]);
    let (at, min) = rp
        .iter()
        .map(|p| (p[0], p[1]))
        .fold((0.0, f64::INFINITY), |m, p| if p.1 < m.1 { p } else { m });
    assert!((at - 63.3).abs() <= 1.0, "Rp's minimum at {at}°");
    near(min, 0.335, 5e-3, "Rp's minimum");
    // The inverse problem, as the readout under the chart states it.
    assert!(
        fig.readouts
            .iter()
            .any(|r| r.contains("= 2.000, given η = 1.000")),
        "{:?}",
        fig.readouts
    );
}

/// LECTURE.md scene 26 [cf]: glass's F0 0.040 and its Brewster angle
/// atan 1.5 = 56.3° (Rp = 0 there); water's F0 0.020, diamond's 0.172.
#[test]
fn dielectrics_f0_and_brewster() {
    let slides = slides();
    let fig = fresnel_figure_of(slide(&slides, "Fresnel: water, glass and diamond"));
    let c = &fig.chart;
    for (name, eta) in [("water", 1.333f64), ("glass", 1.5), ("diamond", 2.42)] {
        let f = series_with(c, &[name, "F"]);
        near(
            at_x(f, 0.0),
            ((eta - 1.0) / (eta + 1.0)).powi(2),
            1e-3,
            name,
        );
        near(
            at_x(f, 89.0),
            fresnel_dielectric(89f64.to_radians().cos(), 1.0, eta),
            2e-3,
            name,
        );
    }
}

/// LECTURE.md scene 31 [cf]: copper's F0 is red (0.94, 0.63, 0.55) and goes
/// white at grazing; aluminium (mean of channels) dips to 0.865 near 81°;
/// glass starts at 0.040.
#[test]
fn conductor_and_dielectric_read_their_closed_forms() {
    let slides = slides();
    let fig = fresnel_figure_of(slide(&slides, "Conductor and dielectric"));
    let c = &fig.chart;
    let copper = [(0.217, 3.64), (0.958, 2.58), (1.17, 2.39)];
    for (ch, (eta, k)) in ["r", "g", "b"].iter().zip(copper) {
        let f = series_with(c, &["copper", &format!("F {ch}")]);
        let (rs, rp) = fresnel_conductor(1.0, eta, k);
        near(at_x(f, 0.0), 0.5 * (rs + rp), 2e-3, "copper F0");
        let (rs, rp) = fresnel_conductor(89f64.to_radians().cos(), eta, k);
        near(at_x(f, 89.0), 0.5 * (rs + rp), 2e-3, "copper at 89°");
        assert!(
            at_x(f, 89.0) >= 0.95,
            "copper {ch} at 89°: {}",
            at_x(f, 89.0)
        );
    }
    let al = series_with(c, &["aluminium", "F"]);
    let (at, min) = al
        .iter()
        .map(|p| (p[0], p[1]))
        .fold((0.0, f64::INFINITY), |m, p| if p.1 < m.1 { p } else { m });
    assert!((at - 81.0).abs() <= 2.0, "aluminium's minimum at {at}°");
    near(min, 0.865, 5e-3, "aluminium's minimum");
    near(
        at_x(series_with(c, &["glass", "F"]), 0.0),
        0.04,
        1e-3,
        "glass F0",
    );
}

/// Radiance the lit sphere shows, for light from the eye (θi = 0: E = 1
/// along the view), at the sphere point whose normal is `gamma` from the
/// view: f(w, w) cos γ with w at γ from the normal (the shader's formula).
fn lit_from_the_eye(b: &dyn bv_core::Brdf, gamma_deg: f64) -> f64 {
    let g = gamma_deg.to_radians();
    let w = glam::DVec3::new(g.sin(), 0.0, g.cos());
    mean_rgb(b.eval(w, w)) * g.cos()
}

fn scene_brdfs(s: &Slide) -> Vec<std::sync::Arc<dyn bv_core::Brdf>> {
    let mut rt = Runtime::default();
    rt.sync(&s.state);
    let scene = build_scene(&s.state, &rt, false);
    scene.brdfs.iter().map(|b| b.brdf.clone()).collect()
}

/// LECTURE.md scene 06 [cf]: a Lambert sphere of albedo 0.8 lit from the
/// eye: ρ/π = 0.255 at the centre, half of it 60° out, 0 at the limb.
#[test]
fn radiance_is_proportional_to_irradiance() {
    let slides = slides();
    let s = slide(&slides, "Reflected radiance is proportional to irradiance");
    assert_eq!(s.state.incident.theta_deg, 0.0);
    let b = &scene_brdfs(s)[0];
    let centre = lit_from_the_eye(b.as_ref(), 0.0);
    near(centre, 0.8 / std::f64::consts::PI, 1e-9, "the centre");
    near(
        lit_from_the_eye(b.as_ref(), 60.0),
        0.5 * centre,
        1e-9,
        "60° out",
    );
    assert!(lit_from_the_eye(b.as_ref(), 89.9) < 2e-3 * centre);
}

/// LECTURE.md scene 57 [bv]: lit from behind the viewer, the limb (80°)
/// over the centre reads 0.17 for Lambert (cos 80°), 0.58 for Oren-Nayar
/// σ 0.5 and 0.91 for Hapke's regolith: the moon looks flat.
#[test]
fn the_full_moon_is_flat() {
    let slides = slides();
    let s = slide(&slides, "The full moon is a disc, not a ball");
    assert_eq!(s.state.incident.theta_deg, 0.0);
    let b = scene_brdfs(s);
    let ratio =
        |k: usize| lit_from_the_eye(b[k].as_ref(), 80.0) / lit_from_the_eye(b[k].as_ref(), 0.0);
    near(ratio(0), 80f64.to_radians().cos(), 1e-9, "Lambert's limb");
    near(ratio(1), 0.58, 0.02, "Oren-Nayar's limb");
    near(ratio(2), 0.91, 0.02, "Hapke's limb");
}

/// LECTURE.md scene 55 [cf]: Ashikhmin-Shirley's coupled body lit from the
/// eye: 80° from the centre the isotropic one reads 0.0069 against
/// Lambert 0.768's 0.042 (≥ 5× darker); 30° out, 0.229 against 0.212.
#[test]
fn ashikhmin_shirleys_body_darkens_at_grazing() {
    let slides = slides();
    let s = slide(
        &slides,
        "Ashikhmin-Shirley: anisotropic, coupled, plausible",
    );
    assert_eq!(s.state.incident.theta_deg, 0.0);
    let b = scene_brdfs(s);
    let (iso, lambert) = (b[1].as_ref(), b[2].as_ref());
    near(lit_from_the_eye(iso, 80.0), 0.0069, 0.03, "A-S 80° out");
    near(
        lit_from_the_eye(lambert, 80.0),
        0.768 / std::f64::consts::PI * 80f64.to_radians().cos(),
        1e-9,
        "Lambert 80° out",
    );
    near(
        lit_from_the_eye(lambert, 80.0),
        0.042,
        0.02,
        "Lambert 80° out (the plan)",
    );
    assert!(lit_from_the_eye(lambert, 80.0) >= 5.0 * lit_from_the_eye(iso, 80.0));
    near(lit_from_the_eye(iso, 30.0), 0.229, 0.02, "A-S 30° out");
    near(
        lit_from_the_eye(lambert, 30.0),
        0.212,
        0.02,
        "Lambert 30° out",
    );
}

/// The legend names of a slide's BRDFs, in list order.
fn brdf_names(s: &Slide) -> Vec<&str> {
    s.state
        .brdfs
        .iter()
        .filter_map(|b| b.name.as_deref())
        .collect()
}

/// LECTURE.md scene 01 (N7): measured, phenomenological and microfacet,
/// named by class; without MERL's file (not shipped) its stand-in is drawn,
/// named as one, and the caption says so. The plan's "≥ 1 decade apart
/// more than 30° from the mirror direction" needs the real table (there
/// the stand-in's diffuse body, which both fits match, holds them within
/// 0.2 decades); with the stand-in the fits part by at least a factor 2
/// near the horizon, where Blinn-Phong has no Fresnel rise.
#[test]
fn where_reflectance_functions_come_from() {
    let slides = slides();
    let s = slide(&slides, "Where reflectance functions come from");
    let names = brdf_names(s);
    let shipped = manifest().join("assets/decks/blue-acrylic.binary").exists();
    let measured = if shipped { "measured" } else { "stand-in" };
    assert!(names[0].starts_with(measured), "{names:?}");
    assert!(names[1].starts_with("phenomenological") && names[2].starts_with("microfacet"));
    assert_eq!(!shipped, s.caption.contains("stands in"), "{}", s.caption);
    if shipped {
        return;
    }
    let c = polar_curves(s);
    let widest = |a: usize, b: usize| {
        c[a].iter()
            .zip(&c[b])
            .filter(|(p, q)| p.1 > 0.0 && q.1 > 0.0)
            .map(|(p, q)| (p.1 / q.1).log10().abs())
            .fold(0.0f64, f64::max)
    };
    assert!(
        widest(0, 1) >= 0.3,
        "Blinn-Phong against the data: {}",
        widest(0, 1)
    );
    assert!(widest(1, 2) >= 0.3, "the two fits: {}", widest(1, 2));
}

/// LECTURE.md scene 10 [cf]: the slice's display is the slide's own
/// (`plots.slice`, N1), Lambert is one grey, and the microfacet band at
/// θh = 0 brightens about 200× from θd 0° to 80° (F 9.7×, 1/cos²θd 33×,
/// G2 0.66) without being clipped to white below 80°.
#[test]
fn the_parameterisation_slide_shows_the_band_unclipped() {
    use bv::derive::slice::{compute, luminance};
    use bv::views::image_slice::display_color;
    let slides = slides();
    let s = slide(&slides, "Parameterisations: θh, θd");
    let set = s.state.plots.slice;
    assert_eq!(set.phi_d_deg, 90.0);
    let brdfs = scene_brdfs(s);
    let n = 256;
    let hatch = (eframe::egui::Color32::BLACK, eframe::egui::Color32::BLACK);
    let shown = |d: &bv::derive::slice::SliceData, row: usize, col: usize| {
        display_color(d.values[row * n + col], &set, hatch, false)
    };
    // Lambert: one grey over the whole image, neither black nor white.
    let lambert = compute(
        brdfs[0].as_ref(),
        set.phi_d_deg.to_radians(),
        set.sqrt_theta_h,
        n,
    );
    let grey = shown(&lambert, 0, 0);
    assert!((30..225).contains(&grey.r()), "{grey:?}");
    for row in 0..n {
        for col in 0..n {
            assert_eq!(shown(&lambert, row, col), grey);
        }
    }
    // The microfacet lobe at θh ≈ 0 (the first column), against its closed
    // form D(0) F(θd) G2(θd, θd) / (4 cos²θd) with GGX and Smith's
    // height-correlated G2 (Heitz 2014, eq. 99).
    let ggx = compute(
        brdfs[1].as_ref(),
        set.phi_d_deg.to_radians(),
        set.sqrt_theta_h,
        n,
    );
    let alpha: f64 = 0.2;
    let closed = |td: f64| {
        let c = td.cos();
        let lambda = (-1.0 + (1.0 + alpha * alpha * td.tan().powi(2)).sqrt()) / 2.0;
        let g2 = 1.0 / (1.0 + 2.0 * lambda);
        let d0 = 1.0 / (std::f64::consts::PI * alpha * alpha);
        d0 * fresnel_dielectric(c, 1.0, 1.5) * g2 / (4.0 * c * c)
    };
    let row_of = |td_deg: f64| ((1.0 - td_deg / 90.0) * n as f64 - 0.5).round() as usize;
    let td_of = |row: usize| (1.0 - (row as f64 + 0.5) / n as f64) * std::f64::consts::FRAC_PI_2;
    let mut last_level = 0u8;
    for td_deg in [0.2, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 75.0, 80.0] {
        let row = row_of(td_deg);
        let got = luminance(ggx.values[row * n].unwrap());
        let want = closed(td_of(row));
        assert!(
            (got - want).abs() <= 2e-3 * want,
            "θd {td_deg}: {got} vs {want}"
        );
        let level = shown(&ggx, row, 0).r();
        assert!(
            level >= last_level,
            "θd {td_deg}: level {level} after {last_level}"
        );
        last_level = level;
        if td_deg < 80.0 {
            assert!(level < 255, "θd {td_deg}: clipped to white");
        }
        if td_deg < 1.0 {
            assert!(level >= 30, "the band at θd 0 is black: {level}");
        }
    }
    // A gradient up the band that reads from across the room.
    assert!(
        f64::from(last_level) > 4.0 * f64::from(shown(&ggx, row_of(0.2), 0).r()),
        "{last_level}"
    );
    let ratio = closed(80f64.to_radians()) / closed(0.0);
    assert!((150.0..260.0).contains(&ratio), "{ratio}");
    // A band: at θd 30° the first column is brighter than θh = 30°.
    let row = row_of(30.0);
    let col30 =
        (bv::derive::slice::u_of_theta_h(30f64.to_radians(), set.sqrt_theta_h) * n as f64) as usize;
    let (at0, at30) = (shown(&ggx, row, 0).r(), shown(&ggx, row, col30).r());
    assert!(f64::from(at0) > 1.5 * f64::from(at30), "{at0} vs {at30}");
}

/// LECTURE.md scene 58 (N7): lumber and cement are RGL files the lecturer
/// supplies; without them (not shipped) models stand in, named as such,
/// and the caption says so. The lumber's stand-in is anisotropic: the
/// same pair of directions turned 90° about the normal reflects ≥ 3× less
/// near its highlight (Ward's αx 0.05 against αy 0.3).
#[test]
fn lumber_and_cement_are_measured_or_named_stand_ins() {
    let slides = slides();
    let s = slide(&slides, "BRDF illustrations: lumber and cement");
    let dir = manifest().join("assets/decks");
    let names = brdf_names(s);
    for (k, file) in ["lumber.bsdf", "cement.bsdf"].into_iter().enumerate() {
        let shipped = dir.join(file).exists();
        let want = if shipped { "measured" } else { "stand-in" };
        assert!(names[k].starts_with(want), "{names:?}");
        assert_eq!(!shipped, s.caption.contains(file), "{}", s.caption);
    }
    if dir.join("lumber.bsdf").exists() {
        return;
    }
    let brdfs = scene_brdfs(s);
    let wood = brdfs[0].as_ref();
    // Directions 8° either side of the normal's highlight, along x then y.
    let (a, b) = (8f64.to_radians(), 45f64.to_radians());
    let wi = glam::DVec3::new(b.sin(), 0.0, b.cos());
    let along = |u: glam::DVec3| {
        let h = (glam::DVec3::new(0.0, 0.0, 1.0) * a.cos() + u * a.sin()).normalize();
        let wo = 2.0 * wi.dot(h) * h - wi;
        mean_rgb(wood.eval(wi, wo))
    };
    let tilt_x = along(glam::DVec3::X);
    let tilt_y = along(glam::DVec3::Y);
    assert!(tilt_y > 3.0 * tilt_x, "{tilt_x} vs {tilt_y}");
}

/// LECTURE.md scene 59 [cf]: seen along ωr, the anisotropic lobe's
/// cross-section is an ellipse whose long axis is along b, with axis ratio
/// ≥ 3: turning ωo off ωr by δ tilts the half vector by δ/2 in the plane of
/// incidence (along t, Ward's αx) and by about δ/(2 cos θi) across it (along
/// b, αy), so the plan's small-angle ratio is cos θi · αy/αx = 4.2. Read
/// here as the half-maximum widths of f(ωi, ·) about ωr in the two
/// directions, against the same widths of Ward's formula (Ward 1992, eq. 5)
/// written in this test: at the half maximum across, 0.36 rad out, the half
/// vector also tilts along t, which the small-angle ratio leaves out.
#[test]
fn the_anisotropic_lobe_seen_along_the_mirror_direction_is_an_ellipse() {
    let slides = slides();
    let s = slide(&slides, "bv = BRDF viewer: an anisotropic lobe in 3-D");
    let b = &scene_brdfs(s)[0];
    let ti = s.state.incident.theta_deg.to_radians();
    let wi = glam::DVec3::new(ti.sin(), 0.0, ti.cos());
    let wr = glam::DVec3::new(-wi.x, -wi.y, wi.z);
    let (kd, ks, ax, ay) = (0.1, 0.5, 0.05, 0.3);
    let ward = |wo: glam::DVec3| {
        let h = (wi + wo).normalize();
        let t2 = (h.x * h.x / (ax * ax) + h.y * h.y / (ay * ay)) / (h.z * h.z);
        kd / std::f64::consts::PI
            + ks * (-t2).exp() / (4.0 * std::f64::consts::PI * ax * ay * (wi.z * wo.z).sqrt())
    };
    let model = |wo: glam::DVec3| mean_rgb(b.eval(wi, wo));
    // In-plane (towards t) and across (along b), both perpendicular to ωr.
    let in_plane = wr.cross(glam::DVec3::Y).normalize();
    let half_width = |f: &dyn Fn(glam::DVec3) -> f64, axis: glam::DVec3| {
        let peak = f(wr);
        let mut d = 0.0f64;
        while d < 1.0 {
            d += 1e-4;
            if f(wr * d.cos() + axis * d.sin()) < 0.5 * peak {
                return d;
            }
        }
        d
    };
    let ratio =
        |f: &dyn Fn(glam::DVec3) -> f64| half_width(f, glam::DVec3::Y) / half_width(f, in_plane);
    let (got, want) = (ratio(&model), ratio(&ward));
    assert!(got >= 3.0, "axis ratio {got}");
    assert!((got / want - 1.0).abs() < 0.02, "{got} vs {want}");
}
