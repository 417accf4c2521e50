//! `bv render`, `bv slice --csv` and the vector/mesh exports, run as
//! a user runs them: the binary, on lavapipe where there is no GPU.
//!
//! Snapshots: every view of two models at 160 × 120 pixels is compared with
//! `tests/snapshots/render_<model>_<view>.png`. Tolerance: a pixel differs
//! when one of its channels is off by more than [`PIXEL_TOLERANCE`] (of 255),
//! and an image passes when at most [`MAX_DIFFERING`] of its pixels differ
//! (about 2 %, room for another Mesa version's rasterisation and font
//! hinting; a wrong curve, colour or layout changes far more). Regenerate
//! with `UPDATE_SNAPSHOTS=1 cargo test --test suite render::`; a missing or failing
//! snapshot writes `<name>.new.png` beside it.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const WIDTH: u32 = 160;
const HEIGHT: u32 = 120;
/// Largest channel difference (0..255) for two pixels to count as equal.
const PIXEL_TOLERANCE: u8 = 40;
/// Most pixels allowed to differ (of 160 × 120 = 19 200).
const MAX_DIFFERING: usize = 400;

/// The two models every view is drawn for: a glossy microfacet model with a
/// Fresnel term, and an anisotropic one without.
const MODELS: [(&str, &[&str]); 2] = [
    ("cook-torrance", &["alpha_x=0.2", "alpha_y=0.2"]),
    ("ward", &["alpha_x=0.08", "alpha_y=0.3", "ks=0.3"]),
];

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_bv")
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-render-tests-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn run(args: &[&str]) -> Output {
    let out = Command::new(bin()).args(args).output().unwrap();
    if !out.status.success() {
        panic!(
            "bv {} failed:\n{}",
            args.join(" "),
            String::from_utf8_lossy(&out.stderr)
        );
    }
    out
}

fn view_ids() -> Vec<String> {
    // `bv render --view nope` lists the views of this build.
    let out = Command::new(bin())
        .args(["render", "--view", "nope", "--out", "x.png"])
        .output()
        .unwrap();
    assert!(!out.status.success());
    let err = String::from_utf8_lossy(&out.stderr);
    let list = err
        .split("available: ")
        .nth(1)
        .unwrap_or_else(|| panic!("no view list in: {err}"));
    // "lobe (or lobe3d, 3d), polar, …, all": drop the aliases in brackets.
    let mut plain = String::new();
    let mut depth = 0;
    for c in list.trim().chars() {
        match c {
            '(' => depth += 1,
            ')' => depth -= 1,
            c if depth == 0 => plain.push(c),
            _ => {}
        }
    }
    plain
        .split(',')
        .map(|v| v.trim().to_string())
        .filter(|v| !v.is_empty() && v != "all" && v != "window")
        .collect()
}

fn snapshot_dir() -> PathBuf {
    Path::new(env!("CARGO_MANIFEST_DIR")).join("tests/snapshots")
}

/// Compares `img` with the stored snapshot `name` (see the module docs).
fn check_snapshot(name: &str, img: &image::RgbaImage) -> Result<(), String> {
    let path = snapshot_dir().join(format!("{name}.png"));
    let update = std::env::var("UPDATE_SNAPSHOTS").is_ok_and(|v| v != "0");
    let new_path = snapshot_dir().join(format!("{name}.new.png"));
    let stored = match image::open(&path) {
        Ok(s) => s.to_rgba8(),
        Err(_) if update => {
            img.save(&path).unwrap();
            return Ok(());
        }
        Err(e) => {
            img.save(&new_path).unwrap();
            return Err(format!(
                "{name}: no snapshot ({e}); wrote {} (UPDATE_SNAPSHOTS=1 to accept)",
                new_path.display()
            ));
        }
    };
    if stored.dimensions() != img.dimensions() {
        img.save(&new_path).unwrap();
        return Err(format!(
            "{name}: size {:?} differs from the snapshot's {:?}",
            img.dimensions(),
            stored.dimensions()
        ));
    }
    let differing = stored
        .pixels()
        .zip(img.pixels())
        .filter(|(a, b)| (0..4).any(|c| a.0[c].abs_diff(b.0[c]) > PIXEL_TOLERANCE))
        .count();
    if differing > MAX_DIFFERING {
        if update {
            img.save(&path).unwrap();
            return Ok(());
        }
        img.save(&new_path).unwrap();
        return Err(format!(
            "{name}: {differing} pixels differ from the snapshot by more than {PIXEL_TOLERANCE} \
             (at most {MAX_DIFFERING} may); wrote {}",
            new_path.display()
        ));
    }
    Ok(())
}

/// Distinct colours in an image (a blank render has one, a plot dozens).
fn colours(img: &image::RgbaImage) -> usize {
    let mut v: Vec<[u8; 4]> = img.pixels().map(|p| p.0).collect();
    v.sort_unstable();
    v.dedup();
    v.len()
}

#[test]
fn every_view_of_two_models_matches_its_snapshot() {
    let views = view_ids();
    for v in ["lobe", "polar", "cartesian", "albedo", "fresnel"] {
        assert!(
            views.iter().any(|x| x == v),
            "view {v} missing from {views:?}"
        );
    }
    let mut failures = Vec::new();
    for (model, params) in MODELS {
        let dir = out_dir(model);
        let mut args = vec![
            "render",
            "--model",
            model,
            "--view",
            "all",
            "--theta-i",
            "40",
            "--width",
            "160",
            "--height",
            "120",
            "--out",
        ];
        let dir_s = dir.to_string_lossy().to_string();
        args.push(&dir_s);
        for p in params {
            args.push("--param");
            args.push(p);
        }
        let out = run(&args);
        // Progress on stderr: one step per view.
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(
            err.contains(&format!("[{}/{}]", views.len(), views.len())),
            "{err}"
        );
        for v in &views {
            let path = dir.join(format!("{v}.png"));
            let img = image::open(&path)
                .unwrap_or_else(|e| panic!("{}: {e}", path.display()))
                .to_rgba8();
            assert_eq!(img.dimensions(), (WIDTH, HEIGHT), "{model} {v}");
            assert!(colours(&img) > 8, "{model} {v}: blank image");
            if let Err(e) = check_snapshot(&format!("render_{model}_{v}"), &img) {
                failures.push(e);
            }
        }
    }
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}

#[test]
fn sizes_scales_and_transparency() {
    let dir = out_dir("sizes");
    let p = dir.join("lobe.png");
    let ps = p.to_string_lossy().to_string();
    run(&[
        "render",
        "--model",
        "lambert",
        "--view",
        "lobe3d",
        "--width",
        "320",
        "--height",
        "200",
        "--transparent",
        "--out",
        &ps,
    ]);
    let img = image::open(&p).unwrap().to_rgba8();
    assert_eq!(img.dimensions(), (320, 200));
    // The corner is background: transparent; the centre is the lobe: opaque.
    assert_eq!(img.get_pixel(1, 1).0[3], 0, "transparent background");
    assert_eq!(img.get_pixel(160, 100).0[3], 255, "opaque lobe");

    // 2× draws text and lines at twice the resolution, not an upscale: the
    // 2× image is not the 1× image with its pixels doubled.
    let p1 = dir.join("polar1.png");
    let p2 = dir.join("polar2.png");
    for (p, w, h, s) in [(&p1, "300", "200", "1"), (&p2, "600", "400", "2")] {
        run(&[
            "render",
            "--model",
            "phong",
            "--view",
            "polar",
            "--width",
            w,
            "--height",
            h,
            "--scale",
            s,
            "--out",
            &p.to_string_lossy(),
        ]);
    }
    let a = image::open(&p1).unwrap().to_rgba8();
    let b = image::open(&p2).unwrap().to_rgba8();
    assert_eq!(b.dimensions(), (600, 400));
    let up = image::imageops::resize(&a, 600, 400, image::imageops::FilterType::Nearest);
    let same = up.pixels().zip(b.pixels()).filter(|(x, y)| x == y).count();
    assert!(
        same < 600 * 400 * 98 / 100,
        "the 2× image looks like an upscale ({same} equal pixels)"
    );
    assert!(colours(&b) > colours(&a), "more detail at 2×");
}

#[test]
fn bad_requests_fail_with_a_clear_message() {
    let cases: &[(&[&str], &str)] = &[
        (
            &["render", "--view", "lit-sphere-x", "--out", "x.png"],
            "available:",
        ),
        (&["render", "--view", "polar", "--out", "x.jpg"], ".png"),
        (
            &["render", "--view", "lobe", "--out", "x.svg"],
            "no vector form",
        ),
        (&["render", "--view", "polar", "--out", "x.obj"], "lobe"),
        (
            &[
                "render", "--model", "nope", "--view", "polar", "--out", "x.png",
            ],
            "nope",
        ),
        (
            &[
                "render",
                "--view",
                "polar",
                "--theta-i",
                "190",
                "--out",
                "x.png",
            ],
            "--theta-i",
        ),
        (
            &[
                "render", "--view", "polar", "--width", "0", "--out", "x.png",
            ],
            "--width",
        ),
        (
            &[
                "render",
                "--scene",
                "/nonexistent.toml",
                "--view",
                "polar",
                "--out",
                "x.png",
            ],
            "nonexistent",
        ),
    ];
    for (args, want) in cases {
        let out = Command::new(bin()).args(*args).output().unwrap();
        assert!(!out.status.success(), "{args:?} succeeded");
        let err = String::from_utf8_lossy(&out.stderr);
        assert!(err.contains(want), "{args:?}: {err}");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
    }
}

#[test]
fn svg_plots_parse_as_xml_and_carry_the_curves() {
    let dir = out_dir("svg");
    for v in ["polar", "cartesian", "albedo", "fresnel", "snell", "terms"] {
        let p = dir.join(format!("{v}.svg"));
        run(&[
            "render",
            "--model",
            "cook-torrance",
            "--view",
            v,
            "--width",
            "800",
            "--height",
            "600",
            "--light",
            "--out",
            &p.to_string_lossy(),
        ]);
        let text = std::fs::read_to_string(&p).unwrap();
        let doc =
            roxmltree::Document::parse(&text).unwrap_or_else(|e| panic!("{v}.svg is not XML: {e}"));
        let root = doc.root_element();
        assert_eq!(root.tag_name().name(), "svg", "{v}");
        assert_eq!(
            root.tag_name().namespace(),
            Some("http://www.w3.org/2000/svg")
        );
        assert!(root.attribute("viewBox").is_some());
        let count = |tag: &str| doc.descendants().filter(|n| n.has_tag_name(tag)).count();
        assert!(count("polyline") >= 1, "{v}: no curve");
        assert!(count("text") >= 5, "{v}: no labels");
        let texts: String = doc
            .descendants()
            .filter(|n| n.has_tag_name("text"))
            .filter_map(|n| n.text())
            .collect::<Vec<_>>()
            .join("|");
        assert!(
            texts.contains("Cook-Torrance"),
            "{v}: legend missing: {texts}"
        );
    }
    // `--view all --svg` writes one SVG per 2D view besides the PNGs.
    let all = dir.join("all");
    run(&[
        "render",
        "--model",
        "lambert",
        "--view",
        "all",
        "--svg",
        "--width",
        "200",
        "--height",
        "150",
        "--out",
        &all.to_string_lossy(),
    ]);
    for v in ["polar", "cartesian", "albedo", "fresnel", "snell", "terms"] {
        assert!(all.join(format!("{v}.svg")).exists(), "{v}.svg");
    }
    assert!(!all.join("lobe.svg").exists());
}

#[test]
fn slice_csv_has_the_stated_columns() {
    let out = run(&[
        "slice",
        "--model",
        "lambert",
        "--param",
        "albedo=0.5",
        "--theta-i",
        "30",
        "--samples",
        "90",
        "--csv",
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "theta_o_deg,f_r,f_g,f_b,f_mean,f_cos_mean"
    );
    let rows: Vec<Vec<f64>> = lines
        .map(|l| l.split(',').map(|x| x.parse().unwrap()).collect())
        .collect();
    assert_eq!(rows.len(), 91);
    let f = 0.5 / std::f64::consts::PI;
    for r in &rows {
        assert_eq!(r.len(), 6);
        assert!((r[1] - f).abs() < 1e-12 && (r[4] - f).abs() < 1e-12);
        assert!((r[5] - f * r[0].to_radians().cos()).abs() < 1e-9);
    }
    // Reflection curves end a degree short of the horizon (where f is 0 by
    // convention), on whole degrees.
    assert!(rows[0][0] == -89.0 && rows[90][0] == 89.0);

    let out = run(&[
        "slice", "--model", "ward", "--curve", "theta-h", "--fixed", "10", "--csv",
    ]);
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(text.starts_with("theta_h_deg,f_r,f_g,f_b,f_mean,f_cos_mean\n"));

    let out = run(&["slice", "--model", "lambert", "--curve", "albedo", "--csv"]);
    let text = String::from_utf8(out.stdout).unwrap();
    let mut lines = text.lines();
    assert_eq!(
        lines.next().unwrap(),
        "theta_i_deg,rho_r,rho_g,rho_b,rho_mean,std_error_mean"
    );
    for l in lines {
        let r: Vec<f64> = l.split(',').map(|x| x.parse().unwrap()).collect();
        // Lambert's ρhd is its albedo (0.5 by default) at every θi.
        assert!((r[4] - 0.5).abs() < 5.0 * r[5] + 1e-3, "{l}");
    }
}

#[test]
fn lobe_meshes_for_blender() {
    let dir = out_dir("mesh");
    let obj = dir.join("lobe.obj");
    let ply = dir.join("lobe.ply");
    let scene = dir.join("two.toml");
    run(&[
        "scene",
        "new",
        "--model",
        "lambert",
        "--model",
        "phong",
        "--out",
        &scene.to_string_lossy(),
    ]);
    for p in [&obj, &ply] {
        run(&[
            "render",
            "--scene",
            &scene.to_string_lossy(),
            "--view",
            "lobe3d",
            "--out",
            &p.to_string_lossy(),
        ]);
    }
    let text = std::fs::read_to_string(&obj).unwrap();
    assert_eq!(text.lines().filter(|l| l.starts_with("o ")).count(), 2);
    let nv = text.lines().filter(|l| l.starts_with("v ")).count();
    assert!(nv > 1000);
    for l in text.lines().filter(|l| l.starts_with("f ")) {
        for idx in l[2..].split(' ') {
            let i: usize = idx.split("//").next().unwrap().parse().unwrap();
            assert!((1..=nv).contains(&i), "{l}");
        }
    }
    let text = std::fs::read_to_string(&ply).unwrap();
    assert!(text.starts_with("ply\nformat ascii 1.0\n"));
    assert!(text.contains("property uchar red"));
}

/// The terms view's SVG carries the v-groove strip when the scene shows it
/// (`plots.terms.vgroove`): three panels, each with the lit and seen parts
/// and G of Torrance & Sparrow's groove, written here from their closed
/// forms (the light at 80°: towards the normal the partner facet lets
/// 2 cos 80° of each facet be lit; towards the light, 2 cos² 80°).
#[test]
fn terms_svg_draws_the_v_groove_strip() {
    let dir = out_dir("svg-vgroove");
    let scene = dir.join("grooves.toml");
    std::fs::write(
        &scene,
        "format = \"bv-scene\"\nversion = 1\nselected = 1\nmaximised = \"terms\"\n\
         incident = { theta_deg = 80.0, phi_deg = 0.0 }\n\
         plots = { terms = { d = false, g1 = false, f = false, vgroove = true } }\n\
         [[brdfs]]\nid = 1\ncolor = [200, 80, 80]\nvisible = true\nname = \"v-groove\"\n\
         spec = { model = \"cook-torrance\", params = { geometry = \"v-groove\" } }\n",
    )
    .unwrap();
    let p = dir.join("terms.svg");
    run(&[
        "render",
        "--scene",
        &scene.to_string_lossy(),
        "--view",
        "terms",
        "--width",
        "1200",
        "--height",
        "800",
        "--out",
        &p.to_string_lossy(),
    ]);
    let text = std::fs::read_to_string(&p).unwrap();
    let doc = roxmltree::Document::parse(&text).unwrap();
    let texts: Vec<&str> = doc
        .descendants()
        .filter(|n| n.has_tag_name("text"))
        .filter_map(|n| n.text())
        .collect();
    let c = 80f64.to_radians().cos();
    for (title, lit, seen) in [
        ("θo = +80° (ωr)", 1.0, 1.0),
        ("θo = 0° (n)", 2.0 * c, 1.0),
        ("θo = -80° (towards the light)", 2.0 * c * c, 2.0 * c * c),
    ] {
        assert!(texts.contains(&title), "{title} not in {texts:?}");
        let foot = format!(
            "lit {lit:.2} · seen {seen:.2} · G = {:.2}",
            f64::min(lit, seen)
        );
        assert!(texts.contains(&foot.as_str()), "{foot} not in {texts:?}");
    }
    // The grooves are drawn clipped, and the G2 chart is still there.
    assert!(doc.descendants().any(|n| n.has_tag_name("clipPath")));
    assert!(texts.iter().any(|t| t.contains("G2")), "{texts:?}");
}
