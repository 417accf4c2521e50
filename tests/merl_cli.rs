//! `bv tabulate` and `bv info` from the outside.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::path::PathBuf;
use std::process::{Command, Output};

fn bv(args: &[&str]) -> Output {
    Command::new(env!("CARGO_BIN_EXE_bv"))
        .args(args)
        .output()
        .expect("bv runs")
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-merl-cli-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

#[test]
fn tabulate_then_info() {
    let dir = temp_dir("ok");
    let file = dir.join("lambert.binary");
    let f = file.to_str().unwrap();
    let out = bv(&[
        "tabulate",
        "--model",
        "lambert",
        "--param",
        "albedo=0.2,0.5,0.8",
        "--out",
        f,
        "--dims",
        "8,6,12",
    ]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("8×6×12"),
        "{}",
        text(&out.stdout)
    );
    // 12-byte header + 3 channels × 576 cells × 8 bytes.
    assert_eq!(std::fs::metadata(&file).unwrap().len(), 12 + 3 * 576 * 8);

    let out = bv(&["info", f]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report = text(&out.stdout);
    for want in ["θh 8 × θd 6 × φd 12", "576 cells", "ρhd", "reciprocity"] {
        assert!(report.contains(want), "missing `{want}` in\n{report}");
    }

    let out = bv(&["info", "--json", "--samples", "4096", "--pairs", "2000", f]);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let j: serde_json::Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["dims"], serde_json::json!([8, 6, 12]));
    assert_eq!(j["bytes"], 12 + 3 * 576 * 8);
    // Lambert: f = ρ/π in every cell whose centre is above the horizon and 0
    // in the others. A trilinear lookup is a convex combination of cells, so
    // π f ≤ ρ for every sample and ρhd ≤ ρ exactly; it falls short only where
    // a neighbouring cell is below the horizon (wo within about a cell of
    // grazing, little cosine weight), a few percent at this coarse 8×6×12.
    let rho0 = &j["rho_hd"][0];
    assert_eq!(rho0["theta_i_deg"], 0.0);
    for (c, want) in [0.2, 0.5, 0.8].iter().enumerate() {
        let got = rho0["value"][c].as_f64().unwrap();
        assert!(
            got <= want * (1.0 + 1e-6) && got > 0.95 * want,
            "channel {c}: {got}"
        );
        let max = j["channels"][c]["max"].as_f64().unwrap();
        assert!((max - want / std::f64::consts::PI).abs() < 1e-7);
    }
    assert!(j["reciprocity"]["max_rel_error"].as_f64().unwrap() < 1e-6);
    assert_eq!(j["warnings"], serde_json::json!([]));
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn bad_files_and_arguments_fail_with_one_line() {
    let dir = temp_dir("bad");
    let header_only = dir.join("header.binary");
    let mut h = Vec::new();
    for d in [90i32, 90, 180] {
        h.extend_from_slice(&d.to_le_bytes());
    }
    std::fs::write(&header_only, &h).unwrap();
    let negative = dir.join("negative.binary");
    let mut n = Vec::new();
    for d in [90i32, -1, 180] {
        n.extend_from_slice(&d.to_le_bytes());
    }
    std::fs::write(&negative, &n).unwrap();

    let cases: Vec<(Vec<String>, &str)> = vec![
        (
            vec!["info".into(), header_only.display().to_string()],
            "size mismatch",
        ),
        (
            vec!["info".into(), negative.display().to_string()],
            "nθd = -1",
        ),
        (
            vec![
                "info".into(),
                dir.join("missing.binary").display().to_string(),
            ],
            "missing.binary",
        ),
        (
            vec![
                "tabulate".into(),
                "--model".into(),
                "lambert".into(),
                "--out".into(),
                dir.join("x.binary").display().to_string(),
                "--dims".into(),
                "90,0,180".into(),
            ],
            "positive",
        ),
        (
            vec![
                "tabulate".into(),
                "--model".into(),
                "nope".into(),
                "--out".into(),
                dir.join("x.binary").display().to_string(),
            ],
            "unknown model",
        ),
        (
            vec![
                "tabulate".into(),
                "--model".into(),
                "lambert".into(),
                "--param".into(),
                "albedo=2".into(),
                "--out".into(),
                dir.join("x.binary").display().to_string(),
            ],
            "out of range",
        ),
    ];
    for (args, want) in cases {
        let args: Vec<&str> = args.iter().map(String::as_str).collect();
        let out = bv(&args);
        let err = text(&out.stderr);
        assert!(!out.status.success(), "{args:?} succeeded");
        assert!(err.contains(want), "{args:?}: `{err}` lacks `{want}`");
        assert!(!err.contains("panicked"), "{args:?}: {err}");
        assert_eq!(err.trim_end().lines().count(), 1, "{args:?}: {err}");
    }
    assert!(!dir.join("x.binary").exists());
    std::fs::remove_dir_all(&dir).unwrap();
}
