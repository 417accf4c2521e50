//! Hostile files, names and sizes given to the binary (issue 27's file,
//! scene, deck and environment-map items): each gets a clear error naming
//! the limit and the size found, writes nothing, and echoes no huge input;
//! valid input at the edges (a 255-byte file name, `X.PNG`, a 300-character
//! slide title, a map of enormous values) works. The inputs are built here,
//! in temporary folders.

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BV: &str = env!("CARGO_BIN_EXE_bv");

fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-hostile-files-{}-{tag}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bv(args: &[&str]) -> Output {
    Command::new(BV).args(args).output().expect("bv starts")
}

fn s(p: &Path) -> &str {
    p.to_str().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// Asserts a refusal: exit status 1, no panic, a short message holding every
/// one of `want`.
fn refused(o: &Output, want: &[&str]) -> String {
    let e = stderr(o);
    assert_eq!(o.status.code(), Some(1), "{e}");
    assert!(!e.contains("panicked"), "{e}");
    assert!(
        e.len() < 2000,
        "a message of {} bytes: {}",
        e.len(),
        &e[..2000]
    );
    for w in want {
        assert!(e.contains(w), "no `{w}` in: {e}");
    }
    e
}

fn files_in(d: &Path) -> Vec<String> {
    let mut v: Vec<String> = std::fs::read_dir(d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .collect();
    v.sort();
    v
}

const DECK_HEAD: &str = "format = \"bv-deck\"\nversion = 1\n";

/// A deck entry with an inline scene of one Lambert BRDF.
fn entry(title: &str, caption: &str) -> String {
    format!(
        "[[scene]]\ntitle = \"{title}\"\ncaption = \"{caption}\"\nview = \"polar\"\n\
         [scene.state]\n[[scene.state.brdfs]]\nid = 1\ncolor = [1, 2, 3]\nvisible = true\n\
         spec = {{ model = \"lambert\" }}\n"
    )
}

/// A scene file of `n` Lambert BRDFs (and an environment map, if given).
fn scene_text(n: usize, env_map: Option<&str>) -> String {
    let mut t = String::from("format = \"bv-scene\"\nversion = 1\n");
    if let Some(m) = env_map {
        t.push_str(&format!("[lighting.env]\nmap = \"{m}\"\n"));
    }
    for i in 1..=n {
        t.push_str(&format!(
            "[[brdfs]]\nid = {i}\ncolor = [1, 2, 3]\nvisible = true\n\
             spec = {{ model = \"lambert\" }}\n"
        ));
    }
    t
}

#[test]
fn an_output_name_of_255_bytes_is_written() {
    let d = dir("long-name");
    let name = format!("{}.toml", "n".repeat(250));
    assert_eq!(name.len(), 255);
    let out = d.join(&name);
    for _ in 0..2 {
        let o = bv(&["scene", "new", "--model", "lambert", "--out", s(&out)]);
        assert!(o.status.success(), "{}", stderr(&o));
    }
    let svg = d.join(format!("{}.svg", "s".repeat(251)));
    let o = bv(&["render", "--view", "polar", "--out", s(&svg)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert_eq!(files_in(&d).len(), 2, "{:?}", files_in(&d));
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn upper_case_extensions_name_files_not_folders() {
    let d = dir("upper");
    let png = d.join("FIGURE.PNG");
    let o = bv(&["render", "--view", "all", "--out", s(&png)]);
    refused(&o, &["--out must be a folder", "FIGURE.PNG"]);
    let deck = d.join("deck.toml");
    std::fs::write(&deck, format!("{DECK_HEAD}{}", entry("A", "c"))).unwrap();
    let o = bv(&["render", "--deck", s(&deck), "--out", s(&png)]);
    refused(&o, &["--out must be a folder", "FIGURE.PNG"]);
    assert!(!png.exists());
    // A single view writes the file its extension names, in any case.
    let svg = d.join("PLOT.SVG");
    let o = bv(&["render", "--view", "polar", "--out", s(&svg)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(svg.is_file());
    std::fs::remove_dir_all(&d).unwrap();
}

/// The child of [`a_killed_save_leaves_a_temporary_the_next_save_removes`]:
/// starts replacing the file named by `BV_HOSTILE_WRITER` and waits, half
/// way, to be killed.
#[test]
fn killed_writer_child() {
    let Some(target) = std::env::var_os("BV_HOSTILE_WRITER") else {
        return;
    };
    let target = PathBuf::from(target);
    let _ = bv_core::fsio::write_atomic(&target, |w| {
        // More than the writer's buffer, so the temporary holds bytes.
        w.write_all(&vec![b'x'; 1 << 20])?;
        w.flush()?;
        std::fs::write(target.with_extension("ready"), b"")?;
        loop {
            std::thread::sleep(std::time::Duration::from_secs(1));
        }
    });
}

#[test]
fn a_killed_save_leaves_a_temporary_the_next_save_removes() {
    let d = dir("killed");
    let target = d.join("scene.toml");
    let o = bv(&["scene", "new", "--model", "lambert", "--out", s(&target)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let old = std::fs::read(&target).unwrap();
    // The child test's name as libtest knows it: its module path without
    // the crate's name (`hostile_files::killed_writer_child` in the suite).
    let child_test = match module_path!().split_once("::") {
        Some((_, module)) => format!("{module}::killed_writer_child"),
        None => "killed_writer_child".to_string(),
    };
    let mut child = Command::new(std::env::current_exe().unwrap())
        .args(["--exact", &child_test, "--nocapture"])
        .env("BV_HOSTILE_WRITER", &target)
        .spawn()
        .unwrap();
    let ready = target.with_extension("ready");
    // Not a timing assertion: a bound on waiting for a child that failed.
    for _ in 0..6000 {
        if ready.exists() || child.try_wait().unwrap().is_some() {
            break;
        }
        std::thread::sleep(std::time::Duration::from_millis(10));
    }
    assert!(ready.exists(), "the writer never got half way");
    child.kill().unwrap(); // SIGKILL: no destructor, no clean-up runs.
    child.wait().unwrap();
    std::fs::remove_file(&ready).unwrap();
    assert_eq!(std::fs::read(&target).unwrap(), old, "the old file is kept");
    let temps: Vec<String> = files_in(&d)
        .into_iter()
        .filter(|n| n.starts_with(&format!(".bv-{}-", child.id())) && n.ends_with(".tmp"))
        .collect();
    assert_eq!(temps.len(), 1, "{:?}", files_in(&d));
    let temp = d.join(&temps[0]);
    // A name that fits any target: `.bv-PID-XXXXXXXX.tmp`.
    assert!(temps[0].len() <= 30, "{}", temps[0]);

    // The next save into the folder, while the leftover is fresh, keeps it
    // (a writer in another container could still be busy with it) …
    let other = d.join("other.toml");
    let o = bv(&["scene", "new", "--model", "ward", "--out", s(&other)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(temp.exists());
    // … and once it has not changed for a minute, removes it.
    let minutes_ago = std::time::SystemTime::now() - std::time::Duration::from_secs(120);
    std::fs::File::options()
        .write(true)
        .open(&temp)
        .unwrap()
        .set_modified(minutes_ago)
        .unwrap();
    let o = bv(&["scene", "new", "--model", "ward", "--out", s(&other)]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(!temp.exists(), "{:?}", files_in(&d));
    assert_eq!(files_in(&d), ["other.toml", "scene.toml"]);
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_scene_of_too_many_brdfs_is_refused_naming_the_limit() {
    let d = dir("brdfs");
    let ok = d.join("sixteen.toml");
    std::fs::write(&ok, scene_text(16, None)).unwrap();
    let o = bv(&["scene", "check", s(&ok)]);
    assert!(o.status.success(), "{}", stderr(&o));
    let many = d.join("hundred.toml");
    std::fs::write(&many, scene_text(100, None)).unwrap();
    let o = bv(&["scene", "check", s(&many)]);
    refused(&o, &["100 BRDFs", "at most 16", "brdfs"]);
    let svg = d.join("fig.svg");
    let o = bv(&[
        "render",
        "--scene",
        s(&many),
        "--view",
        "polar",
        "--out",
        s(&svg),
    ]);
    refused(&o, &["100 BRDFs", "at most 16"]);
    assert!(!svg.exists());
    // The command line stops at the same number.
    let mut args = vec!["scene", "new"];
    for _ in 0..17 {
        args.extend(["--model", "lambert"]);
    }
    let out = d.join("new.toml");
    args.extend(["--out", s(&out)]);
    refused(&bv(&args), &["17 BRDFs", "at most 16"]);
    assert!(!out.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn decks_of_too_many_scenes_or_too_much_text_are_refused() {
    let d = dir("deck-limits");
    let slides = d.join("slides");
    let cases = [
        (
            "scenes",
            format!("{DECK_HEAD}{}", entry("A", "c").repeat(201)),
            vec!["201 scenes", "at most 200"],
        ),
        (
            "caption",
            format!("{DECK_HEAD}{}", entry("A", &"c".repeat(3_000_000))),
            vec!["caption", "3000000 characters", "at most 1000"],
        ),
        (
            "title",
            format!("{DECK_HEAD}{}", entry(&"t".repeat(3_000_000), "c")),
            vec!["title", "3000000 characters", "at most 1000", "bytes)"],
        ),
        (
            "deck-title",
            format!(
                "{DECK_HEAD}title = \"{}\"\n{}",
                "t".repeat(5000),
                entry("A", "c")
            ),
            vec!["title", "5000 characters"],
        ),
        (
            "brdfs",
            format!(
                "{DECK_HEAD}[[scene]]\ntitle = \"A\"\ncaption = \"c\"\nview = \"polar\"\n\
                 [scene.state]\n{}",
                scene_text(40, None)
                    .lines()
                    .skip(2)
                    .map(|l| l.replace("[[brdfs]]", "[[scene.state.brdfs]]") + "\n")
                    .collect::<String>()
            ),
            vec!["40 BRDFs", "at most 16"],
        ),
    ];
    for (tag, text, want) in cases {
        let deck = d.join(format!("{tag}.toml"));
        std::fs::write(&deck, text).unwrap();
        let o = bv(&["render", "--deck", s(&deck), "--out", s(&slides)]);
        refused(&o, &want);
        assert!(!slides.exists(), "{tag}: nothing written");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_deck_file_error_names_the_path_once() {
    let d = dir("deck-file");
    let deck = d.join("deck.toml");
    std::fs::write(
        &deck,
        format!(
            "{DECK_HEAD}[[scene]]\ntitle = \"A\"\ncaption = \"c\"\nview = \"polar\"\n\
             file = \"no-such-scene.toml\"\n"
        ),
    )
    .unwrap();
    let o = bv(&["render", "--deck", s(&deck), "--out", s(&d.join("out"))]);
    let e = refused(&o, &["no-such-scene.toml", "scene[0]"]);
    assert_eq!(e.matches("no-such-scene.toml").count(), 1, "{e}");
    assert!(!d.join("out").exists());
    // So do the files named on the command line.
    let missing = d.join("missing.toml");
    for args in [
        vec!["render", "--deck", s(&missing), "--out", "out"],
        vec![
            "render",
            "--scene",
            s(&missing),
            "--view",
            "polar",
            "--out",
            "x.svg",
        ],
        vec!["scene", "check", s(&missing)],
    ] {
        let e = refused(&bv(&args), &["missing.toml"]);
        assert_eq!(e.matches("missing.toml").count(), 1, "{e}");
    }
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_slide_title_of_300_characters_renders() {
    let d = dir("long-title");
    let title = "Anisotropic reflection ".repeat(13) + "x";
    assert!(title.len() >= 300);
    let deck = d.join("deck.toml");
    std::fs::write(&deck, format!("{DECK_HEAD}{}", entry(&title, "c"))).unwrap();
    let out = d.join("slides");
    let o = bv(&[
        "render",
        "--deck",
        s(&deck),
        "--out",
        s(&out),
        "--width",
        "320",
        "--height",
        "180",
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let files = files_in(&out);
    assert_eq!(files.len(), 1, "{files:?}");
    assert!(
        files[0].starts_with("01-anisotropic-reflection-"),
        "{files:?}"
    );
    assert!(files[0].len() <= 100, "{files:?}");
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_huge_param_value_is_not_echoed_whole() {
    let value = format!("albedo={}", "9x".repeat(50_000));
    let o = bv(&["check", "--model", "lambert", "--param", &value]);
    let e = stderr(&o);
    assert!(!o.status.success());
    assert!(e.len() < 1000, "a message of {} bytes", e.len());
    assert!(e.contains("albedo") && e.contains("100007 bytes)"), "{e}");
}

/// An OpenEXR file of `w × h` texels of `value`.
fn exr(w: u32, h: u32, value: f32) -> Vec<u8> {
    let img = image::Rgb32FImage::from_pixel(w, h, image::Rgb([value; 3]));
    let mut bytes = std::io::Cursor::new(Vec::new());
    image::DynamicImage::ImageRgb32F(img)
        .write_to(&mut bytes, image::ImageFormat::OpenExr)
        .unwrap();
    bytes.into_inner()
}

/// A Radiance `.hdr` header claiming `w × h` texels, with no texels after
/// it: what a huge file looks like to a reader of its header.
fn hdr_claiming(w: u32, h: u32) -> Vec<u8> {
    format!("#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y {h} +X {w}\n").into_bytes()
}

/// `bv render` of the environment view of a scene lit by `map` (in `d`).
fn render_env(d: &Path, map: &str, out: &Path) -> Output {
    let scene = d.join(format!("{map}.toml"));
    std::fs::write(&scene, scene_text(1, Some(map))).unwrap();
    bv(&[
        "render",
        "--scene",
        s(&scene),
        "--view",
        "environment",
        "--width",
        "200",
        "--height",
        "150",
        "--spp",
        "4",
        "--out",
        s(out),
    ])
}

#[test]
fn environment_maps_refused_from_the_header_with_one_cause() {
    let d = dir("env-refused");
    std::fs::write(d.join("big.hdr"), hdr_claiming(8192, 4096)).unwrap();
    let png = d.join("fig.png");
    let o = render_env(&d, "big.hdr", &png);
    refused(&o, &["big.hdr", "8192×4096", "8388608 texels"]);
    assert!(!png.exists());
    // A file cut short: the decoder's reason, said once.
    let mut cut = exr(64, 32, 1.0);
    cut.truncate(cut.len() - 64);
    std::fs::write(d.join("cut.exr"), cut).unwrap();
    let o = render_env(&d, "cut.exr", &png);
    let e = refused(&o, &["cut.exr"]);
    for part in e.split(": ").map(str::trim).filter(|p| p.len() > 12) {
        assert_eq!(e.matches(part).count(), 1, "`{part}` twice in: {e}");
    }
    assert!(!png.exists());
    std::fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_map_near_the_largest_float_renders_white_not_black() {
    let d = dir("env-bright");
    std::fs::write(d.join("bright.exr"), exr(64, 32, f32::MAX / 2.0)).unwrap();
    let png = d.join("fig.png");
    let o = render_env(&d, "bright.exr", &png);
    assert!(o.status.success(), "{}", stderr(&o));
    let img = image::open(&png).unwrap().to_rgb8();
    // The background is the map itself, far beyond white at any exposure.
    let white = img
        .pixels()
        .filter(|p| p.0.iter().all(|&c| c >= 250))
        .count();
    let n = img.pixels().count();
    assert!(white * 2 > n, "{white} of {n} pixels white");
    std::fs::remove_dir_all(&d).unwrap();
}
