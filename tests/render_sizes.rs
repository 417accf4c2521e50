//! `bv render` at the sizes people ask for, for every view: never a panic
//! (exit 101), never a success without a picture. A size the device cannot
//! draw must be refused with exit 1 and a message naming the limit; a render
//! whose input fails (a missing MERL file or environment map) must fail
//! without writing a file.
//!
//! Run as a user runs it: the binary, on lavapipe where there is no GPU. The
//! environment view is drawn with `--spp 1` so that the largest size stays
//! within seconds on a software renderer.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::{Path, PathBuf};
use std::process::{Command, Output};
use std::time::Instant;

fn bin() -> &'static str {
    env!("CARGO_BIN_EXE_bv")
}

fn out_dir(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-render-sizes-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn bv(args: &[&str]) -> Output {
    Command::new(bin()).args(args).output().unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The views of this build, from the list `bv render --view nope` prints.
fn view_ids() -> Vec<String> {
    let out = bv(&["render", "--view", "nope", "--out", "x.png"]);
    assert_eq!(out.status.code(), Some(1), "{}", stderr(&out));
    let err = stderr(&out);
    let list = err
        .split("available: ")
        .nth(1)
        .unwrap_or_else(|| panic!("no view list in: {err}"));
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
        .filter(|v| !v.is_empty())
        .collect()
}

/// Distinct colours of an image (a blank render has one), counted up to
/// `enough`: a scan that stops once the picture is plainly not a flat fill.
/// (Sorting every pixel of each 4096×3072 image, in this unoptimised test
/// build, was over a minute of the suite.)
fn colours_up_to(img: &image::RgbaImage, enough: usize) -> usize {
    let mut seen: Vec<[u8; 4]> = Vec::with_capacity(enough);
    for p in img.pixels() {
        if !seen.contains(&p.0) {
            seen.push(p.0);
            if seen.len() >= enough {
                break;
            }
        }
    }
    seen.len()
}

/// Checks one PNG: the asked size, and a picture, not a flat fill.
fn check_png(path: &Path, w: u32, h: u32, what: &str) {
    let img = image::open(path)
        .unwrap_or_else(|e| panic!("{what}: {} unreadable: {e}", path.display()))
        .to_rgba8();
    assert_eq!(img.dimensions(), (w, h), "{what}: {}", path.display());
    let n = colours_up_to(&img, 9);
    assert!(n > 8, "{what}: {} is blank ({n} colours)", path.display());
}

/// What one run ended as.
enum Outcome {
    Drawn,
    Refused(String),
}

/// Runs `bv render` for `view` at `w`×`h` and checks the class of outcomes:
/// exit 0 with every PNG drawn, or exit 1 with a `bv: ` message naming a
/// limit and no PNG; anything else (a panic's 101, a signal) fails.
fn render(view: &str, w: u32, h: u32, dir: &Path, views: &[String]) -> Outcome {
    let all = view == "all";
    let out_path = if all {
        dir.join(format!("all-{w}x{h}"))
    } else {
        dir.join(format!("{view}-{w}x{h}.png"))
    };
    let (ws, hs) = (w.to_string(), h.to_string());
    let out = bv(&[
        "render",
        "--model",
        "cook-torrance",
        "--view",
        view,
        "--width",
        &ws,
        "--height",
        &hs,
        "--spp",
        "1",
        "--out",
        out_path.to_str().unwrap(),
    ]);
    let what = format!("--view {view} at {w}×{h}");
    let err = stderr(&out);
    assert!(
        !err.contains("panicked") && !err.contains("RUST_BACKTRACE"),
        "{what} panicked:\n{err}"
    );
    match out.status.code() {
        Some(0) => {
            if all {
                for v in views.iter().filter(|v| *v != "all" && *v != "window") {
                    check_png(&out_path.join(format!("{v}.png")), w, h, &what);
                }
            } else {
                check_png(&out_path, w, h, &what);
            }
            Outcome::Drawn
        }
        Some(1) => {
            let line = err.trim();
            assert!(
                line.starts_with("bv: ") && line.lines().count() == 1,
                "{what}: the refusal is not one `bv: ` line:\n{err}"
            );
            assert!(
                line.contains("at most") && line.contains("--width"),
                "{what}: the refusal does not name the limit and the option:\n{err}"
            );
            if !all {
                assert!(!out_path.exists(), "{what}: refused but wrote a file");
            }
            Outcome::Refused(line.to_string())
        }
        other => panic!("{what}: exit {other:?}\n{err}"),
    }
}

/// Runs `runs` on two worker threads (each run is a process; lavapipe
/// itself is multi-threaded, so more would only queue) and returns one
/// report line per run, in order.
fn run_all(runs: &[(String, u32, u32)], dir: &Path, views: &[String]) -> Vec<String> {
    let next = std::sync::atomic::AtomicUsize::new(0);
    let report = std::sync::Mutex::new(vec![String::new(); runs.len()]);
    std::thread::scope(|scope| {
        for _ in 0..2 {
            scope.spawn(|| {
                loop {
                    let i = next.fetch_add(1, std::sync::atomic::Ordering::SeqCst);
                    let Some((v, w, h)) = runs.get(i) else {
                        break;
                    };
                    let t = Instant::now();
                    let o = render(v, *w, *h, dir, views);
                    let line = format!(
                        "{v} {w}×{h}: {} in {:.1} s",
                        match &o {
                            Outcome::Drawn => "drawn".to_string(),
                            Outcome::Refused(m) => format!("refused ({m})"),
                        },
                        t.elapsed().as_secs_f64()
                    );
                    // 800×600 and 1600×1200 fit every device wgpu supports
                    // (8192-pixel textures, 128 MiB bindings in bands): they
                    // must be drawn.
                    assert!(*w > 1600 || matches!(o, Outcome::Drawn), "{line}");
                    report.lock().unwrap()[i] = line;
                }
            });
        }
    });
    report.into_inner().unwrap()
}

/// Every view at 800×600 on its own, `all` (every view, through the same
/// drawing code on one device) and the window at 800×600 and 1600×1200; at
/// 4096×3072 the views whose GPU resources grow with the image (the
/// environment's accumulation, the lobe's target) and the
/// window. Every view at 4096×3072 is the test below (about two minutes on
/// lavapipe).
#[test]
fn every_view_at_every_size_draws_or_is_refused_clearly() {
    let views = view_ids();
    for v in ["lobe", "environment", "all", "window"] {
        assert!(views.iter().any(|x| x == v), "{v} missing from {views:?}");
    }
    let dir = out_dir("sizes");
    let t0 = Instant::now();
    let mut runs: Vec<(String, u32, u32)> = Vec::new();
    for v in &views {
        runs.push((v.clone(), 800, 600));
    }
    for v in ["all", "window"] {
        runs.push((v.to_string(), 1600, 1200));
    }
    for v in ["environment", "lobe", "lit_sphere", "window"] {
        runs.push((v.to_string(), 4096, 3072));
    }
    // The slowest first, so the two workers finish together.
    runs.sort_by_key(|(v, w, _)| std::cmp::Reverse((*w, v == "all" || v == "environment")));
    let report = run_all(&runs, &dir, &views);
    eprintln!(
        "{}\ntotal {:.1} s",
        report.join("\n"),
        t0.elapsed().as_secs_f64()
    );
    let _ = std::fs::remove_dir_all(&dir);
}

/// Every view at 4096×3072 (`--view all`, about two minutes on lavapipe).
#[test]
fn every_view_at_4096_by_3072() {
    let views = view_ids();
    let dir = out_dir("all-4096");
    let report = run_all(&[("all".to_string(), 4096, 3072)], &dir, &views);
    eprintln!("{}", report.join("\n"));
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn sizes_beyond_the_device_are_refused_naming_the_limit() {
    let dir = out_dir("huge");
    let png = dir.join("huge.png");
    let out = bv(&[
        "render",
        "--view",
        "polar",
        "--width",
        "100000",
        "--height",
        "600",
        "--out",
        png.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("bv: ") && err.contains("--width") && err.contains("at most"),
        "{err}"
    );
    assert!(!png.exists());
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn failing_inputs_fail_the_render_and_write_nothing() {
    let dir = out_dir("inputs");
    let missing = dir.join("no-such.binary");
    let png = dir.join("merl.png");
    // A MERL file that is not there: no axes-only plot.
    let param = format!("file={}", missing.display());
    let out = bv(&[
        "render",
        "--model",
        "merl",
        "--param",
        &param,
        "--view",
        "polar",
        "--width",
        "400",
        "--height",
        "300",
        "--out",
        png.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("bv: ") && err.contains("no-such.binary"),
        "{err}"
    );
    assert!(!png.exists(), "a failed render wrote {}", png.display());

    // An environment map that is not there, named in a scene: the error is
    // reported, not drawn into the image; an older file is left as it was.
    let scene = dir.join("scene.toml");
    let map = dir.join("no-such.hdr");
    let out = bv(&[
        "scene",
        "new",
        "--model",
        "lambert",
        "--out",
        scene.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let text = std::fs::read_to_string(&scene).unwrap();
    assert!(text.contains("[lighting.env]\n"), "{text}");
    let text = text.replace(
        "[lighting.env]\n",
        &format!("[lighting.env]\nmap = {:?}\n", map.display().to_string()),
    );
    std::fs::write(&scene, text).unwrap();
    let env_png = dir.join("env.png");
    std::fs::write(&env_png, b"old").unwrap();
    let out = bv(&[
        "render",
        "--scene",
        scene.to_str().unwrap(),
        "--view",
        "environment",
        "--width",
        "320",
        "--height",
        "240",
        "--spp",
        "1",
        "--out",
        env_png.to_str().unwrap(),
    ]);
    let err = stderr(&out);
    assert_eq!(out.status.code(), Some(1), "{err}");
    assert!(
        err.starts_with("bv: ") && err.contains("no-such.hdr"),
        "{err}"
    );
    assert_eq!(std::fs::read(&env_png).unwrap(), b"old");
    let _ = std::fs::remove_dir_all(&dir);
}
