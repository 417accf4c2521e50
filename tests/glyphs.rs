//! Every character the lecture's text uses has a glyph in the fonts bv
//! loads: the deck's titles and captions, and all the text the views draw
//! for each slide and for every view in presentation mode (legends, axis
//! labels, notes). A character without a glyph is drawn as an empty box
//! (the Fresnel slide's "r∥²" read "r□²" with egui's default fonts alone).

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::Viewer;
use bv::session::deck;
use bv::session::scene_file::Builds;
use bv::session::state::AppState;
use bv_core::ModelSpec;
use eframe::egui;
use egui_kittest::Harness;
use std::collections::BTreeMap;
use std::path::Path;

fn deck_path() -> std::path::PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("assets/decks/reflectance.toml")
}

/// The text of every text shape of the last frame.
fn drawn_text(h: &Harness<'_, Viewer>) -> Vec<String> {
    fn walk(s: &egui::Shape, out: &mut Vec<String>) {
        match s {
            egui::Shape::Text(t) => out.push(t.galley.job.text.clone()),
            egui::Shape::Vec(v) => v.iter().for_each(|s| walk(s, out)),
            _ => {}
        }
    }
    let mut out = Vec::new();
    for c in &h.output().shapes {
        walk(&c.shape, &mut out);
    }
    out
}

/// Adds the characters of `text` that the fonts lack to `missing`, with
/// where they were found.
fn check(h: &Harness<'_, Viewer>, text: &str, at: &str, missing: &mut BTreeMap<char, String>) {
    for c in bv::views::fonts::missing_glyphs(&h.ctx, &egui::FontFamily::Proportional, text) {
        missing
            .entry(c)
            .or_insert_with(|| format!("{at}: {text:?}"));
    }
}

#[test]
fn every_glyph_of_the_deck_and_the_views_is_in_the_fonts() {
    let loaded = deck::load(&deck_path(), Builds::Required).unwrap();
    let d = loaded.deck;
    let mut h = Harness::builder()
        .with_size([1920.0, 1080.0])
        .with_max_steps(12)
        .build_ui_state(
            |ui, v: &mut Viewer| v.ui(ui),
            Viewer::new(AppState::default()),
        );
    h.state_mut().set_deck(d.clone(), None, 0);
    h.run();

    let mut missing = BTreeMap::new();
    let mut texts = 0;
    if let Some(t) = &d.title {
        check(&h, t, "the deck's title", &mut missing);
    }
    for (i, slide) in d.slides.iter().enumerate() {
        let at = format!("scene {} ({})", i + 1, slide.title);
        check(&h, &slide.title, &at, &mut missing);
        check(&h, &slide.caption, &at, &mut missing);
        h.state_mut().set_deck(d.clone(), None, i);
        h.run();
        for t in drawn_text(&h) {
            texts += 1;
            check(&h, &t, &at, &mut missing);
        }
    }
    // The views the deck does not show, with a microfacet model and a
    // dielectric (the terms, the Fresnel and Snell views' notation).
    let mut s = AppState::default();
    s.add(ModelSpec::new("cook-torrance").unwrap());
    s.add(ModelSpec::new("glass").unwrap());
    s.incident.theta_deg = 45.0;
    h.state_mut().set_deck(
        deck::Deck {
            title: None,
            slides: vec![deck::Slide::inline("Views", "every view", "polar", s).unwrap()],
        },
        None,
        0,
    );
    h.run();
    for e in bv::views::REGISTRY.iter() {
        check(&h, e.title, "the view titles", &mut missing);
        h.state_mut()
            .push(bv::session::Command::Maximise(Some(e.id.into())));
        h.run();
        for t in drawn_text(&h) {
            texts += 1;
            check(&h, &t, e.id, &mut missing);
        }
    }
    assert!(texts > 200, "only {texts} texts drawn");
    // The notation the lecture uses, whether or not a view draws it now.
    check(
        &h,
        "ρ θ φ ω η ∥ ⊥ ∫ π ≤ ≥ ≠ ≈ ² ³ · × − ± ∞ ∇ ° → α β κ σ Σ Δ ∂ √ ½ ‖",
        "the lecture's notation",
        &mut missing,
    );
    assert!(
        missing.is_empty(),
        "characters without a glyph (drawn as empty boxes):\n{}",
        missing
            .iter()
            .map(|(c, at)| format!("  {c:?} U+{:04X} in {at}", *c as u32))
            .collect::<Vec<_>>()
            .join("\n")
    );
}
