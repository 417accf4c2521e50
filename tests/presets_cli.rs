//! `--preset NAME` on the command line: `bv check`, `bv render` and the
//! viewer take a material preset's model and parameters; an unknown name is
//! an error listing the close ones. The built binary is run as a user runs it.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use serde_json::Value;
use std::process::{Command, Output};

const BV: &str = env!("CARGO_BIN_EXE_bv");

fn bv(args: &[&str]) -> Output {
    Command::new(BV).args(args).output().expect("bv starts")
}

fn stderr(o: &Output) -> String {
    String::from_utf8_lossy(&o.stderr).into_owned()
}

/// The TOML of a shipped preset, read here from the repository's file.
fn preset_file(name: &str) -> toml::Table {
    let path = format!("{}/assets/presets/{name}.toml", env!("CARGO_MANIFEST_DIR"));
    toml::from_str(&std::fs::read_to_string(path).unwrap()).unwrap()
}

#[test]
fn check_takes_a_preset_and_reports_its_parameters() {
    let out = bv(&["check", "--preset", "Gold", "--json"]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let file = preset_file("gold");
    assert_eq!(v["model"], file["model"].as_str().unwrap());
    // Every parameter the file sets is in the report's parameters.
    let params = file["params"].as_table().unwrap();
    for (k, want) in params {
        // `alpha` is the alias that sets both roughnesses.
        let key = if v["params"].get(k).is_none() && v["params"].get(format!("{k}_x")).is_some() {
            format!("{k}_x")
        } else {
            k.clone()
        };
        let got = &v["params"][&key];
        assert!(!got.is_null(), "{k} missing from {}", v["params"]);
        match want {
            toml::Value::Float(x) => {
                let g = got.as_f64().or_else(|| got[0].as_f64()).unwrap();
                assert!((g - x).abs() < 1e-12, "{k}: {got} vs {want}");
            }
            toml::Value::Array(a) => {
                for (i, x) in a.iter().enumerate() {
                    let x = x.as_float().unwrap();
                    assert!((got[i].as_f64().unwrap() - x).abs() < 1e-12, "{k}: {got}");
                }
            }
            toml::Value::String(s) => assert_eq!(got.as_str(), Some(s.as_str()), "{k}"),
            _ => {}
        }
    }
    // A metal is reciprocal.
    assert_eq!(v["reciprocity"]["reciprocal"], true);

    // --param on top of the preset; the file name works as well.
    let out = bv(&[
        "check",
        "--preset",
        "gold",
        "--param",
        "alpha=0.5",
        "--json",
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(v["params"]["alpha_x"].as_f64(), Some(0.5));
    assert_eq!(v["params"]["alpha_y"].as_f64(), Some(0.5));
}

#[test]
fn an_unknown_preset_lists_close_matches() {
    let out = bv(&["check", "--preset", "Gld"]);
    assert_eq!(out.status.code(), Some(1));
    let e = stderr(&out);
    assert!(
        e.contains("unknown preset `Gld`") && e.contains("Gold"),
        "{e}"
    );
    assert!(!e.contains("panicked"), "{e}");

    let out = bv(&[
        "render", "--preset", "Coper", "--view", "polar", "--out", "x.png",
    ]);
    assert_eq!(out.status.code(), Some(1));
    let e = stderr(&out);
    assert!(e.contains("close matches") && e.contains("Copper"), "{e}");

    // The viewer refuses it before a window opens.
    let out = bv(&["--preset", "Silverr", "--size", "10x10"]);
    assert_ne!(out.status.code(), Some(0));
    let e = stderr(&out);
    assert!(
        e.contains("unknown preset `Silverr`") && e.contains("Silver"),
        "{e}"
    );

    // --model and --preset together are refused.
    let out = bv(&["check", "--preset", "Gold", "--model", "lambert"]);
    assert_eq!(out.status.code(), Some(2), "{}", stderr(&out));
}

#[test]
fn render_draws_a_preset_named_after_it() {
    let dir = std::env::temp_dir().join(format!("bv-presets-cli-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let png = dir.join("r.png");
    let out = bv(&[
        "render",
        "--preset",
        "Copper",
        "--view",
        "reciprocity",
        "--width",
        "400",
        "--height",
        "300",
        "--out",
        png.to_str().unwrap(),
    ]);
    assert!(out.status.success(), "{}", stderr(&out));
    assert!(std::fs::metadata(&png).unwrap().len() > 1000);
    let _ = std::fs::remove_dir_all(&dir);
}
