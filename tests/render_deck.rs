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

/// A deck file `name` in the fresh folder `out`: the format header, then
/// `scenes` (TOML).
fn deck_file(out: &Path, name: &str, scenes: &str) -> PathBuf {
    std::fs::create_dir_all(out).unwrap();
    let path = out.join(name);
    std::fs::write(
        &path,
        format!("format = \"bv-deck\"\nversion = 1\n{scenes}"),
    )
    .unwrap();
    path
}

fn deck_path() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join(DECK)
}

/// The shipped deck at projector size (1920×1080), every slide numbered,
/// titled and not blank. This is the deck check of CI (.ci/gui-smoke.sh
/// rendered the same deck again at this size). The environment scenes are
/// path traced at `--spp 8` rather than their 64: at 64, on lavapipe in the
/// debug build, eight of them took 330 s of this test's 485 (and the test
/// was the suite's last minutes, alone on one core); `--spp` reaching them is
/// `a_deck_takes_the_sample_count_asked_for`'s check. The slides are left in
/// `target/tmp/lecture-deck/` for a human to look at (the environment scenes
/// grainy: `bv render --deck` without `--spp` draws them as the lecture
/// shows them).
#[test]
fn the_lecture_deck_renders_one_png_per_scene() {
    let loaded = deck::load(&deck_path(), Builds::Required).unwrap();
    assert!(loaded.warnings.is_empty(), "{:?}", loaded.warnings);
    let slides = loaded.deck.slides;
    assert!(slides.len() >= 62, "{} scenes", slides.len());

    let out = Path::new(env!("CARGO_TARGET_TMPDIR")).join("lecture-deck");
    let _ = std::fs::remove_dir_all(&out);
    let dir = format!("{}/", out.display());
    let (w, h) = (1920u32, 1080u32);
    let run = Command::new(bin())
        .args(["render", "--deck"])
        .arg(deck_path())
        .args(["--out", &dir, "--width", &w.to_string(), "--height"])
        .arg(h.to_string())
        .args(["--spp", "8"])
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
        assert_eq!(img.dimensions(), (w, h), "{file}");
        // Not blank: the title band alone has text; the view area (between
        // the band and the strip: the middle quarters of the height) must
        // vary too, and the whole slide must have more than a handful of
        // colours.
        let colours = |ys: std::ops::Range<u32>| {
            let mut c: Vec<[u8; 4]> = ys
                .step_by(3)
                .flat_map(|y| (0..w).step_by(3).map(move |x| (x, y)))
                .map(|(x, y)| img.get_pixel(x, y).0)
                .collect();
            c.sort_unstable();
            c.dedup();
            c.len()
        };
        let view_area = colours(h / 4..h * 5 / 6);
        assert!(
            view_area > 20,
            "{file}: the view area has {view_area} colours"
        );
        let whole = colours(0..h);
        assert!(whole >= 100, "{file}: the slide has {whole} colours");
    }
}

#[test]
fn a_bad_deck_names_the_entry_and_the_key() {
    let out = out_dir("bad");
    let path = deck_file(
        &out,
        "bad.toml",
        "[[scene]]\ntitle = \"Phong\"\ncaption = \"c\"\n\
         view = \"lobe\"\n[scene.state]\nincident = { theta_deg = 190.0, phi_deg = 0.0 }\n",
    );
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

/// Mean absolute difference between horizontally adjacent pixels (all three
/// channels) in the middle of an image: Monte Carlo noise, where the
/// environment view's sphere is.
fn pixel_noise(img: &image::RgbaImage) -> f64 {
    let (w, h) = img.dimensions();
    let (mut sum, mut n) = (0.0, 0u32);
    for y in h * 2 / 5..h * 3 / 5 {
        for x in w * 2 / 5..w * 3 / 5 {
            let a = img.get_pixel(x, y).0;
            let b = img.get_pixel(x + 1, y).0;
            for c in 0..3 {
                sum += (f64::from(a[c]) - f64::from(b[c])).abs();
                n += 1;
            }
        }
    }
    sum / f64::from(n)
}

/// `--spp N` reaches every environment scene of a deck: one sample per
/// pixel leaves the sphere visibly noisy, 64 far less so; and a count out of
/// range is refused before anything is written.
#[test]
fn a_deck_takes_the_sample_count_asked_for() {
    let out = out_dir("spp");
    let path = deck_file(
        &out,
        "env.toml",
        "[[scene]]\ntitle = \"Plastic\"\ncaption = \"c\"\n\
         view = \"environment\"\n[scene.state]\nselected = 1\n[[scene.state.brdfs]]\nid = 1\n\
         color = [78, 151, 234]\nvisible = true\n\
         spec = { model = \"cook-torrance\", params = { alpha = 0.3 } }\n",
    );
    let render = |spp: &str, name: &str| {
        Command::new(bin())
            .args(["render", "--deck"])
            .arg(&path)
            .args(["--width", "480", "--height", "270", "--spp", spp, "--out"])
            .arg(out.join(name))
            .output()
            .unwrap()
    };
    let noise = |spp: &str| {
        let run = render(spp, spp);
        assert!(
            run.status.success(),
            "--spp {spp}: {}",
            String::from_utf8_lossy(&run.stderr)
        );
        let img = image::open(out.join(spp).join("01-plastic.png"))
            .unwrap()
            .to_rgba8();
        pixel_noise(&img)
    };
    let (one, many) = (noise("1"), noise("64"));
    println!("pixel-to-pixel difference: {one:.2} at 1 spp, {many:.2} at 64");
    assert!(
        one > 3.0 * many,
        "1 spp {one:.2} against 64 spp {many:.2}: the count did not reach the scene"
    );

    let bad = render("0", "zero");
    assert!(!bad.status.success());
    let err = String::from_utf8_lossy(&bad.stderr);
    assert!(err.contains("--spp 0"), "{err}");
    assert!(!out.join("zero").exists(), "nothing written");
    let _ = std::fs::remove_dir_all(&out);
}
