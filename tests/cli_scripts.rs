//! A command line scripts can trust (issue 30, part 3): `bv check --strict`
//! exit statuses, no invented claims for file models, a check table that
//! fits 100 columns, `bv slice` on whole degrees with numbers that read
//! back and a `--json` form, and `-p`/`--param` wherever `--model` is taken.

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use serde_json::Value;
use std::path::{Path, PathBuf};
use std::process::{Command, Output};

const BV: &str = env!("CARGO_BIN_EXE_bv");

fn bv(args: &[&str]) -> Output {
    Command::new(BV).args(args).output().expect("bv starts")
}

fn stdout(o: &Output) -> String {
    String::from_utf8(o.stdout.clone()).unwrap()
}

fn stderr(o: &Output) -> String {
    String::from_utf8(o.stderr.clone()).unwrap()
}

fn data(name: &str) -> String {
    Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/brdf")
        .join(name)
        .to_str()
        .unwrap()
        .to_string()
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-cli-scripts-{tag}-{}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// Every line of a check table within 100 columns.
fn assert_fits(text: &str) {
    for line in text.lines() {
        assert!(
            line.chars().count() <= 100,
            "{} columns: {line}\n{text}",
            line.chars().count()
        );
    }
}

#[test]
fn strict_check_exits_3_on_a_violation_only() {
    // Phong with the seed's normalisation violates energy (ρhd → ∞ at
    // grazing incidence, claimed "no"): 0 without --strict, 3 with it.
    let o = bv(&["check", "-m", "phong"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    assert!(stdout(&o).contains("violates energy"), "{}", stdout(&o));
    let o = bv(&["check", "-m", "phong", "--strict"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    // The report is still printed in full, table or JSON.
    assert!(stdout(&o).contains("violates energy"), "{}", stdout(&o));
    let o = bv(&["check", "-m", "phong", "--strict", "--json"]);
    assert_eq!(o.status.code(), Some(3), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["energy"]["conserves"], false);
    // A model that keeps every promise: 0.
    let o = bv(&["check", "-m", "lambert", "-p", "albedo=0.8", "--strict"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    // Documented where a user looks.
    let help = stdout(&bv(&["check", "--help"]));
    assert!(
        help.contains("--strict") && help.contains("status 3"),
        "{help}"
    );
    let readme =
        std::fs::read_to_string(Path::new(env!("CARGO_MANIFEST_DIR")).join("README.md")).unwrap();
    assert!(
        readme.contains("--strict"),
        "README does not document --strict"
    );
}

#[test]
fn file_models_claim_nothing() {
    let retro = data("retro.brdf");
    let o = bv(&["check", "-m", &retro, "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    for claim in ["reciprocal", "energy_conserving", "isotropic"] {
        assert!(v["claims"][claim].is_null(), "{claim}: {}", v["claims"]);
    }
    let o = bv(&["check", "-m", &retro]);
    let text = stdout(&o);
    assert_fits(&text);
    for property in ["reciprocity", "isotropy", "energy"] {
        let line = text
            .lines()
            .find(|l| l.trim_start().starts_with(property))
            .unwrap_or_else(|| panic!("{property}: {text}"));
        assert!(line.contains(" — "), "{line}");
    }
    assert!(!text.contains("contradicts"), "{text}");

    // A MERL table (tabulated here) claims nothing either.
    let dir = temp_dir("merl");
    let table = dir.join("l.binary");
    let t = table.to_str().unwrap();
    let o = bv(&[
        "tabulate",
        "-m",
        "lambert",
        "-p",
        "albedo=0.5",
        "--dims",
        "4,4,8",
        "--out",
        t,
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    let path = format!("path={t}");
    let o = bv(&["check", "-m", "merl", "-p", &path, "--json"]);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    for claim in ["reciprocal", "energy_conserving", "isotropic"] {
        assert!(v["claims"][claim].is_null(), "{claim}: {}", v["claims"]);
    }
    // A catalogue model still states its claims.
    let o = bv(&["check", "-m", "lambert", "--json"]);
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["claims"]["reciprocal"], true);
    let _ = std::fs::remove_dir_all(&dir);
}

#[test]
fn check_tables_fit_100_columns() {
    // Long evidence: a non-reciprocal model with its worst pair, a
    // transmitting one (ρR + ρT row), a microfacet one (D normalisation).
    for args in [
        &["check", "-m", "phong"][..],
        &["check", "-m", "rough-dielectric"],
        &["check", "-m", "cook-torrance", "-p", "alpha=0.3"],
        &["check", "-m", "lambert", "--albedo", "monte-carlo"],
    ] {
        let o = bv(args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        let text = stdout(&o);
        assert!(text.contains("energy"), "{text}");
        assert_fits(&text);
    }
}

/// The CSV rows of `bv slice args…` (header checked, every cell parsed).
fn csv(args: &[&str]) -> (Vec<String>, Vec<Vec<f64>>, String) {
    let mut a = vec!["slice"];
    a.extend_from_slice(args);
    a.push("--csv");
    let o = bv(&a);
    assert_eq!(o.status.code(), Some(0), "{a:?}: {}", stderr(&o));
    let text = stdout(&o);
    let mut lines = text.lines();
    let header = lines.next().unwrap().split(',').map(String::from).collect();
    let rows = lines
        .map(|l| {
            l.split(',')
                .map(|c| c.parse::<f64>().unwrap_or_else(|e| panic!("{c}: {e}")))
                .collect()
        })
        .collect();
    (header, rows, text)
}

#[test]
fn slice_uses_whole_degrees_and_honours_samples() {
    let (h, rows, text) = csv(&["-m", "lambert"]);
    assert_eq!(h[0], "theta_o_deg");
    let x: Vec<f64> = rows.iter().map(|r| r[0]).collect();
    assert_eq!(x, (-89..=89).map(f64::from).collect::<Vec<_>>());
    // Printed as typed: `30`, never `29.999999999999996`.
    assert!(text.lines().any(|l| l.starts_with("30,")), "{text}");
    assert!(!text.contains("99999999"), "{text}");
    let (_, rows, _) = csv(&["-m", "lambert", "--step", "0.5", "--curve", "theta-h"]);
    assert_eq!(rows.len(), 179);
    assert_eq!(rows[61][0], 30.5);
    // --samples for every curve, albedo included.
    for curve in ["theta-o", "theta-h", "theta-d", "albedo"] {
        let (_, rows, _) = csv(&["-m", "lambert", "--curve", curve, "--samples", "7"]);
        assert_eq!(rows.len(), 8, "{curve}");
    }
    // The albedo curve: ρhd of Lambert is its albedo at every θi, and the
    // default grid is whole degrees 0..89.
    let (h, rows, _) = csv(&[
        "-m",
        "lambert",
        "-p",
        "albedo=0.5",
        "--curve",
        "albedo",
        "--step",
        "10",
    ]);
    assert_eq!(h[0], "theta_i_deg");
    assert_eq!(
        rows.iter().map(|r| r[0]).collect::<Vec<_>>(),
        [0.0, 10.0, 20.0, 30.0, 40.0, 50.0, 60.0, 70.0, 80.0]
    );
    for r in &rows {
        assert!((r[4] - 0.5).abs() <= 1e-5 + 3.0 * r[5], "{r:?}");
    }
}

#[test]
fn slice_numbers_read_back_and_small_ones_are_short() {
    // A sharp lobe far from its peak: values down to ~1e-100 and below.
    let (_, rows, text) = csv(&[
        "-m",
        "cook-torrance",
        "-p",
        "alpha=0.02",
        "-p",
        "kd=0",
        "--theta-i",
        "10",
    ]);
    assert!(rows.iter().any(|r| r[1] > 0.0 && r[1] < 1e-20), "{text}");
    for cell in text.lines().skip(1).flat_map(|l| l.split(',')) {
        assert!(cell.len() <= 24, "{cell}");
        assert!(!cell.contains("00000000"), "{cell}");
        // Shortest round trip: Rust's f64 formatting of the parsed value
        // (plain or scientific) gives the same digits back.
        let v: f64 = cell.parse().unwrap();
        let again = if cell.contains('e') {
            format!("{v:e}")
        } else {
            format!("{v}")
        };
        assert_eq!(again, cell);
    }
}

#[test]
fn slice_json_matches_the_csv() {
    let args = [
        "-m",
        "ward",
        "-p",
        "alpha_x=0.1",
        "--theta-i",
        "30",
        "--step",
        "5",
    ];
    let (h, rows, _) = csv(&args);
    let mut a = vec!["slice"];
    a.extend_from_slice(&args);
    a.push("--json");
    let o = bv(&a);
    assert_eq!(o.status.code(), Some(0), "{}", stderr(&o));
    let v: Value = serde_json::from_str(&stdout(&o)).unwrap();
    assert_eq!(v["model"], "ward");
    assert_eq!(v["curve"], "theta-o");
    assert_eq!(v["params"]["alpha_x"], 0.1);
    let cols: Vec<&str> = v["columns"]
        .as_array()
        .unwrap()
        .iter()
        .map(|c| c.as_str().unwrap())
        .collect();
    assert_eq!(cols, h);
    let jrows = v["rows"].as_array().unwrap();
    assert_eq!(jrows.len(), rows.len());
    for (j, r) in jrows.iter().zip(&rows) {
        let j: Vec<f64> = j
            .as_array()
            .unwrap()
            .iter()
            .map(|x| x.as_f64().unwrap())
            .collect();
        // serde_json's default parser may be an ulp off (no
        // `float_roundtrip` here); what bv prints is ryu's shortest form.
        assert_eq!(j.len(), r.len());
        for (a, b) in j.iter().zip(r) {
            assert!((a - b).abs() <= 4.0 * f64::EPSILON * b.abs(), "{a} vs {b}");
        }
    }
    // --csv and --json together are a usage error.
    let o = bv(&["slice", "-m", "lambert", "--csv", "--json"]);
    assert_eq!(o.status.code(), Some(2));
    // --step and --samples too; a bad step is refused with its name.
    let o = bv(&["slice", "-m", "lambert", "--step", "2", "--samples", "9"]);
    assert_eq!(o.status.code(), Some(2));
    let o = bv(&["slice", "-m", "lambert", "--step", "0"]);
    assert_eq!(o.status.code(), Some(1));
    assert!(stderr(&o).contains("--step 0"), "{}", stderr(&o));
}

/// The sub-commands listed under "Commands:" in a help text.
fn commands(help: &str) -> Vec<String> {
    help.lines()
        .skip_while(|l| !l.starts_with("Commands:"))
        .skip(1)
        .take_while(|l| l.starts_with("  "))
        .filter_map(|l| l.split_whitespace().next())
        .filter(|c| *c != "help")
        .map(String::from)
        .collect()
}

#[test]
fn every_model_option_comes_with_param() {
    let top = stdout(&bv(&["--help"]));
    let mut todo: Vec<Vec<String>> = commands(&top).into_iter().map(|c| vec![c]).collect();
    assert!(todo.len() >= 8, "{top}");
    let mut with_model = Vec::new();
    while let Some(path) = todo.pop() {
        let mut args: Vec<&str> = path.iter().map(String::as_str).collect();
        args.push("--help");
        let o = bv(&args);
        assert_eq!(o.status.code(), Some(0), "{args:?}: {}", stderr(&o));
        let help = stdout(&o);
        for sub in commands(&help) {
            let mut p = path.clone();
            p.push(sub);
            todo.push(p);
        }
        let option = |o: &str| help.lines().any(|l| l.trim_start().starts_with(o));
        if option("-m, --model") || option("--model") {
            assert!(option("-m, --model"), "{args:?}: no -m\n{help}");
            assert!(
                option("-p, --param <NAME=VALUE>"),
                "{args:?}: no -p\n{help}"
            );
            with_model.push(path.join(" "));
        }
    }
    for c in ["check", "bench", "slice", "tabulate", "render", "scene new"] {
        assert!(
            with_model.iter().any(|w| w == c),
            "{c} not found in {with_model:?}"
        );
    }
    // And `-p` works in the one that refused it.
    let dir = temp_dir("tab");
    let out = dir.join("t.binary");
    let o = bv(&[
        "tabulate",
        "-m",
        "lambert",
        "-p",
        "albedo=0.3",
        "--dims",
        "1,1,2",
        "--out",
        out.to_str().unwrap(),
    ]);
    assert!(o.status.success(), "{}", stderr(&o));
    assert!(stdout(&o).contains("0.3"), "{}", stdout(&o));
    let _ = std::fs::remove_dir_all(&dir);
}
