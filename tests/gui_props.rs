//! The lecturer's property tools in the window: the panel's property badges
//! (computed in the background: a preview, then `bv check`'s own numbers), their
//! evidence windows, the reciprocity map view, the swap ωi and ωo readout of
//! the polar plot and the preset browser. Driven with egui_kittest by
//! accessible labels; no GPU needed.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::derive::properties::{self as badges, Property};
use bv::session::Command;
use bv::session::state::AppState;
use bv::views::polar::PolarView;
use bv::views::reciprocity::ReciprocityView;
use bv_core::ModelSpec;
use bv_core::analysis::{self, CheckOptions, PropertyReport};
use eframe::egui;
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

fn state_of(models: &[&str]) -> AppState {
    let mut s = AppState::default();
    for m in models {
        s.add(ModelSpec::new(m).unwrap());
    }
    s
}

/// Runs frames until the badges' background work (the previews, then
/// `bv check`'s runs they start) is done and drawn.
fn settle(h: &mut Harness<'_, Viewer>) {
    let t0 = Instant::now();
    // While jobs run the panel keeps repainting (progress), so a frame may
    // not settle within the harness's step limit: that is what this loop
    // waits out, not an error.
    let frame = |h: &mut Harness<'_, Viewer>| {
        let _ = h.try_run();
    };
    loop {
        frame(h);
        if badges::wait_idle(Duration::from_millis(200)) {
            // A finished preview starts `bv check`'s run on the next frame.
            frame(h);
            frame(h);
            if badges::wait_idle(Duration::from_millis(1)) {
                return;
            }
        }
        assert!(
            t0.elapsed() < Duration::from_secs(600),
            "badges still computing after 600 s"
        );
    }
}

/// The verdicts `bv check` prints for a model at its defaults, from the
/// report at `bv check`'s own options.
fn check_verdicts(model: &str, opts: &CheckOptions) -> [bool; 4] {
    let b = ModelSpec::new(model).unwrap().build().unwrap();
    let r = analysis::check(b.as_ref(), opts);
    [
        r.reciprocity.reciprocal,
        r.energy.conserves,
        r.positivity.ok,
        r.isotropy.isotropic,
    ]
}

#[test]
fn panel_verdicts_agree_with_bv_check_for_phong_and_modified_phong() {
    for (model, want) in [
        // Classical Phong (Phong 1975 as a BRDF, 1/cos θi): neither
        // reciprocal nor energy-conserving at grazing (Lewis 1994).
        ("phong", [false, false, true, true]),
        // Modified Phong with kd + ks = 0.8 ≤ 1 (Lafortune & Willems 1994).
        ("modified-phong", [true, true, true, true]),
    ] {
        let t0 = Instant::now();
        let panel = check_verdicts(model, &badges::preview_options());
        let dt = t0.elapsed();
        let full = check_verdicts(model, &CheckOptions::default());
        assert_eq!(
            panel, full,
            "{model}: panel verdicts differ from bv check's"
        );
        assert_eq!(panel, want, "{model}");
        eprintln!("{model}: panel check {:.2} s", dt.as_secs_f64());
    }
    // The defaults of modified Phong do satisfy the lecture's kd + ks ≤ 1.
    let p = ModelSpec::new("modified-phong").unwrap();
    let sum = p.params().color("kd").unwrap() + p.params().color("ks").unwrap();
    assert!(sum.max_element() <= 1.0, "{sum}");
}

#[test]
fn badges_show_the_verdicts_once_computed_and_open_their_evidence() {
    let mut h = viewer(state_of(&["phong", "modified-phong"]));
    settle(&mut h);
    let phong = bv_core::find("phong").unwrap().name;
    let modified = bv_core::find("modified-phong").unwrap().name;
    h.get_by_label_contains(&format!("{phong}: reciprocal ✗"));
    let want = format!("{phong}: energy ✗ ρhd max");
    let energy = format!("{:?}", h.get_by_label_contains(&want));
    assert!(energy.contains("at θi 89."), "{energy}");
    h.get_by_label_contains(&format!("{modified}: reciprocal ✓"));
    h.get_by_label_contains(&format!("{modified}: energy ✓"));
    h.get_by_label_contains(&format!("{modified}: positive ✓"));
    h.get_by_label_contains(&format!("{phong}: isotropic ✓"));
    assert!(h.query_by_label_contains("reciprocal …").is_none());
    // Settled: no badge is still a preview.
    assert_eq!(h.query_all_by_label_contains(" …").count(), 0);

    // The evidence: the worst pair, as `bv check` prints it.
    h.get_by_label_contains(&format!("{phong}: reciprocal ✗"))
        .click();
    h.run();
    h.get_by_label_contains("worst pair: ωi (θ");
    // Settled: `bv check`'s own run, not the preview.
    h.get_by_label_contains("over 20000 pairs");
    h.get_by_label_contains("bv check's own run: 20000 pairs");

    // A parameter change gives a new revision: the badge computes again.
    let id = h.state().state().brdfs[0].id;
    h.state_mut().push(Command::SetParam {
        brdf: id,
        param: "ks".into(),
        value: bv_core::ParamValue::Color([0.0; 3]),
    });
    h.run();
    settle(&mut h);
    // kd alone (0.15, not divided by π) is reciprocal: ρhd = π kd ≈ 0.47.
    h.get_by_label_contains(&format!("{phong}: reciprocal ✓"));
    h.get_by_label_contains(&format!("{phong}: energy ✓"));
}

/// Runs frames until the reciprocity view shows a map of the current key.
fn reciprocity_map(
    h: &mut Harness<'_, Viewer>,
) -> bv_core::analysis::reciprocity_map::ReciprocityMap {
    let t0 = Instant::now();
    loop {
        h.run();
        if let Some((m, false)) = h.state().view::<ReciprocityView>().unwrap().shown.clone() {
            return (*m).clone();
        }
        assert!(t0.elapsed() < Duration::from_secs(60), "no reciprocity map");
        std::thread::sleep(Duration::from_millis(20));
    }
}

/// The relative reciprocity error of `model` at one pair, written out here.
fn rel_err(model: &str, wi: glam::DVec3, wo: glam::DVec3) -> f64 {
    let b = ModelSpec::new(model).unwrap().build().unwrap();
    (b.eval(wi, wo) - b.eval(wo, wi)).abs().max_element()
}

#[test]
fn reciprocity_view_lights_up_for_phong_and_stays_dark_for_modified_phong() {
    let mut s = state_of(&["phong"]);
    s.maximised = Some("reciprocity".into());
    let mut h = viewer(s);
    let m = reciprocity_map(&mut h);
    let v = h.state().view::<ReciprocityView>().unwrap();
    let disc = v.disc_rect.expect("the disc was drawn");
    assert!(disc.width() > 200.0, "{disc:?}");
    let w = m.worst.unwrap();
    assert!(w.value > 0.1, "classical Phong: worst {}", w.value);
    // The worst pixel's value is the model's own relative error there.
    let wi = h.state().state().incident.direction();
    let direct = rel_err("phong", wi, w.wo) / m.max_f;
    assert!((direct - w.value).abs() < 1e-12 * direct.max(1.0));
    let lit = m.values.iter().flatten().filter(|v| **v > 1e-6).count();
    assert!(lit > m.values.len() / 20, "{lit} pixels above 1e-6");

    let id = h.state().state().brdfs[0].id;
    h.state_mut().push(Command::RemoveBrdf(id));
    h.state_mut()
        .push(Command::AddBrdf("modified-phong".into()));
    let m = reciprocity_map(&mut h);
    let w = m.worst.unwrap();
    assert!(w.value < 1e-12, "modified Phong: worst {}", w.value);

    // Moving the light computes a new map for the new ωi.
    h.state_mut()
        .push(Command::SetIncident(bv::session::state::Incident {
            theta_deg: 70.0,
            phi_deg: 30.0,
        }));
    let m = reciprocity_map(&mut h);
    assert!((m.wi - h.state().state().incident.direction()).length() < 1e-12);
}

#[test]
fn polar_readout_compares_both_orders_and_swaps_the_light() {
    let mut s = state_of(&["phong"]);
    s.maximised = Some("polar".into());
    let mut h = viewer(s);
    let rect = h.state().view::<PolarView>().unwrap().plot_rect.unwrap();
    // A point on the mirror side (right of the centre line), above the surface.
    let p = egui::pos2(
        rect.center().x + rect.width() * 0.15,
        rect.center().y - rect.height() * 0.2,
    );
    h.hover_at(p);
    h.run();
    h.run();
    let swap = h
        .state()
        .view::<PolarView>()
        .unwrap()
        .swap
        .clone()
        .expect("swap readout");
    let wi = h.state().state().incident.direction();
    let b = ModelSpec::new("phong").unwrap().build().unwrap();
    assert_eq!(swap.forward, b.eval(wi, swap.wo));
    assert_eq!(swap.swapped, b.eval(swap.wo, wi));
    assert!(
        swap.rel_diff > 1e-3,
        "classical Phong differs: {}",
        swap.rel_diff
    );
    // The pointer leaves the plot for the button; the pinned ωo stays.
    h.get_by_label("swap ωi and ωo").click();
    h.run();
    let inc = h.state().state().incident;
    assert!(
        (inc.direction() - swap.wo).length() < 1e-9,
        "light moved to ωo: {inc:?} vs {:?}",
        swap.wo
    );
}

#[test]
fn a_preset_from_the_browser_adds_a_named_brdf_with_its_parameters() {
    let mut h = viewer(state_of(&["lambert"]));
    h.get_by_label("Presets…").click();
    h.run();
    h.get_by_label("Search presets").click();
    h.run();
    h.get_by_label("Search presets").type_text("gol");
    h.run();
    h.run();
    assert!(
        h.query_by_label("Add preset Copper").is_none(),
        "filtered out"
    );
    h.get_by_label("Add preset Gold").click();
    h.run();
    let gold = bv::cli::params::find_preset("Gold").unwrap();
    let s = h.state().state();
    assert_eq!(s.brdfs.len(), 2);
    let e = s.brdfs.last().unwrap();
    assert_eq!(e.spec, gold.spec);
    assert_eq!(s.selected, Some(e.id));
    assert_eq!(bv::session::naming::display_name(s, e), "Gold");
    // The name survives a save and a reload of the session.
    let again = AppState::from_json_str(&s.to_json_string()).unwrap();
    assert_eq!(again.brdfs.last().unwrap().name.as_deref(), Some("Gold"));
    h.get_by_label_contains("Gold: reciprocal");
}

#[test]
fn badge_time_per_model() {
    // What a badge costs, per model of the catalogue at its defaults (a
    // file-backed model without its file is skipped), printed with
    // `--nocapture`.
    let mut worst = 0.0f64;
    for m in bv_core::catalogue().iter() {
        let Ok(b) = ModelSpec::new(m.id).and_then(|s| s.build()) else {
            continue;
        };
        let t0 = Instant::now();
        let r = analysis::check(b.as_ref(), &badges::preview_options());
        let dt = t0.elapsed().as_secs_f64();
        worst = worst.max(dt);
        let marks: Vec<String> = Property::ALL
            .iter()
            .map(|p| badges::badge(&r, *p).text)
            .collect();
        eprintln!("{:>20}: {dt:6.2} s  {}", m.id, marks.join(" · "));
    }
    eprintln!("slowest: {worst:.2} s");
    // A badge that takes longer than this in a debug build (some 5–10× slower
    // than release) would leave the panel on "…" for too long.
    assert!(worst < 20.0, "slowest badge {worst:.2} s");
}

/// The four verdicts of a report.
fn verdicts(r: &PropertyReport) -> [bool; 4] {
    [
        r.reciprocity.reciprocal,
        r.energy.conserves,
        r.positivity.ok,
        r.isotropy.isotropic,
    ]
}

/// "X ± Y" of the "max ρhd X ± Y at θi …" line `bv check` prints for
/// `report` (its text output is the report's `Display`).
fn printed_max_rho(report: &PropertyReport) -> String {
    let text = format!("{report}");
    let (_, rest) = text
        .split_once("max ρhd ")
        .unwrap_or_else(|| panic!("no max ρhd in {text}"));
    let (number, _) = rest.split_once(" at θi").unwrap();
    number.to_string()
}

#[test]
fn settled_badges_show_bv_checks_numbers_over_the_catalogue_and_a_file() {
    // Every model of the catalogue at its defaults (a file-backed model
    // without its file is skipped) and a user file, in one window.
    bv::session::user_models::install();
    let mut s = AppState::default();
    for m in bv_core::catalogue().iter() {
        if let Ok(spec) = ModelSpec::new(m.id)
            && spec.build().is_ok()
        {
            s.add(spec);
        }
    }
    let file = concat!(env!("CARGO_MANIFEST_DIR"), "/tests/data/brdf/ward.brdf");
    s.add(ModelSpec::from_json(file, &serde_json::json!({})).unwrap());
    let mut h = Harness::builder()
        .with_size([1280.0, 800.0])
        .with_max_steps(12)
        .build_ui_state(|ui, v: &mut Viewer| v.ui(ui), Viewer::new(s));
    settle(&mut h);
    let state = h.state().state().clone();
    let threads = rayon::current_num_threads();
    let mut wrong = Vec::new();
    for e in &state.brdfs {
        let name = bv::session::naming::display_name(&state, e);
        let b = e.spec.build().unwrap();
        let opts = CheckOptions::default();
        if opts
            .estimated_time(b.as_ref(), threads)
            .is_some_and(|t| t > analysis::CHECK_BUDGET)
        {
            // `bv check` refuses it (an unoptimised build's interpreter):
            // the badge keeps its preview and is not marked as pending.
            eprintln!("{name}: too slow for bv check here; preview kept");
            continue;
        }
        // What `bv check` prints, computed here.
        let full = analysis::check(b.as_ref(), &opts);
        let mark = |ok: bool| if ok { "✓" } else { "✗" };
        let energy = format!(
            "{name}: energy {} ρhd max {}",
            mark(full.energy.conserves),
            printed_max_rho(&full)
        );
        if h.query_by_label_contains(&energy).is_none() {
            let shown = badges::latest(e.id).map(|x| badges::badge(&x.report, Property::Energy));
            wrong.push(format!("want `{energy}`, the panel shows {shown:?}"));
        }
        for (p, ok) in [
            (Property::Reciprocal, full.reciprocity.reciprocal),
            (Property::Positive, full.positivity.ok),
            (Property::Isotropic, full.isotropy.isotropic),
        ] {
            let want = format!("{name}: {} {}", p.word(), mark(ok));
            if h.query_by_label_contains(&want).is_none() {
                wrong.push(format!("want `{want}`"));
            }
        }
        // The preview shown before it had the same verdicts: a badge does
        // not flip when `bv check`'s numbers arrive.
        let preview = badges::previews().latest(e.id).unwrap();
        if verdicts(&preview.value) != verdicts(&full) {
            wrong.push(format!(
                "{name}: preview verdicts {:?}, bv check {:?}",
                verdicts(&preview.value),
                verdicts(&full)
            ));
        }
    }
    assert!(wrong.is_empty(), "{wrong:#?}");
    assert_eq!(h.query_all_by_label_contains(" …").count(), 0);
}

#[test]
fn a_preset_name_goes_through_scene_files_and_old_entries_have_none() {
    let gold = bv::cli::params::find_preset("Gold").unwrap();
    let mut s = state_of(&["lambert"]);
    s.add_named(gold.spec.clone(), Some(gold.name.clone()));
    let text = bv::session::scene_file::to_toml(&s).unwrap();
    let back = bv::session::scene_file::from_toml(&text).unwrap();
    assert!(back.warnings.is_empty(), "{:?}", back.warnings);
    let names: Vec<Option<&str>> = back.state.brdfs.iter().map(|b| b.name.as_deref()).collect();
    assert_eq!(names, [None, Some("Gold")]);
    // An entry without a name writes no `name` key: files read by older
    // builds stay as they were.
    let lambert_only = bv::session::scene_file::to_toml(&state_of(&["lambert"])).unwrap();
    assert!(!lambert_only.contains("\nname"), "{lambert_only}");
}
