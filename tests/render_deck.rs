//! `bv render --deck`: the shipped lecture deck rendered by the binary (on
//! lavapipe where there is no GPU), one numbered PNG per scene, and the
//! errors of a bad deck naming the entry and the key.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::session::deck;
use bv::session::scene_file::Builds;
use std::path::{Path, PathBuf};
use std::process::Command;

const DECK: &str = "assets/decks/reflectance.toml";

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_bv")
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-render-deck-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    d
}

fn deck_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(DECK)
}

#[test]
fn the_lecture_deck_renders_one_png_per_scene() {
    let loaded = deck::load(&deck_path(), Builds::Required).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let slides = loaded.deck.slides;
    assert!(slides.len() >= 62, "{} scenes", slides.len());

    let out = out_dir("lecture");
    let dir = format!("{}/", out.display());
    let run = Command::new(bin())
        .args(["render", "--deck"])
        .arg(deck_path())
        .args(["--out", &dir, "--width", "640", "--height", "360"])
        .output()
        .unwrap();
    assert!(
        run.status.success(),
        "{}",
        String::from_utf8_lossy(&run.stderr)
    );
    let mut files: Vec<String> = std::fs::read_dir(&out)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert_eq!(files.len(), slides.len(), "{files:?}");
    for (i, (file, slide)) in files.iter().zip(&slides).enumerate() {
        assert_eq!(
            file,
            &format!("{:02}-{}.png", i + 1, deck::slug(&slide.title))
        );
        let img = image::open(out.join(file)).unwrap().to_rgba8();
        assert_eq!(img.dimensions(), (640, 360), "{file}");
        // Not blank: the title band alone has text; the view area (between
        // the band and the strip) must vary too.
        let view_area: Vec<[u8; 4]> = (90..300)
            .flat_map(|y| (0..640).step_by(3).map(move |x| (x, y)))
            .map(|(x, y)| img.get_pixel(x, y).0)
            .collect();
        let mut distinct = view_area.clone();
        distinct.sort_unstable();
        distinct.dedup();
        assert!(
            distinct.len() > 20,
            "{file}: the view area has {} colours",
            distinct.len()
        );
    }
    let _ = std::fs::remove_dir_all(&out);
}

#[test]
fn a_bad_deck_names_the_entry_and_the_key() {
    let out = out_dir("bad");
    std::fs::create_dir_all(&out).unwrap();
    let path = out.join("bad.toml");
    std::fs::write(
        &path,
        "format = \"bv-deck\"\nversion = 1\n[[scene]]\ntitle = \"Phong\"\ncaption = \"c\"\n\
         view = \"lobe\"\n[scene.state]\nincident = { theta_deg = 190.0, phi_deg = 0.0 }\n",
    )
    .unwrap();
    let run = Command::new(bin())
        .args(["render", "--deck"])
        .arg(&path)
        .arg("--out")
        .arg(out.join("slides"))
        .output()
        .unwrap();
    assert!(!run.status.success());
    let err = String::from_utf8_lossy(&run.stderr);
    assert!(
        err.contains("scene[0] (\"Phong\")") && err.contains("state.incident.theta_deg"),
        "{err}"
    );
    assert!(!out.join("slides").exists(), "nothing written");
    let _ = std::fs::remove_dir_all(&out);
}
