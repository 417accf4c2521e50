//! `bv simulate` end to end: the JSON a script reads, the table, and the
//! refusals (exit status 2, a message, no panic).

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use serde_json::Value;
use std::process::{Command, Output};

const BV: &str = env!("CARGO_BIN_EXE_bv");

fn bv(args: &[&str]) -> Output {
    Command::new(BV).args(args).output().expect("bv starts")
}

/// The JSON has the keys, G1 rows against Smith, ρ with F = 1 that
/// adds up to 1, and one BRDF row per bin; G1 at 0° is 1 and at 80° is below
/// 1 and within 3σ + 2 % of Smith (a small Beckmann surface).
#[test]
fn json_has_the_measurements() {
    let out = bv(&[
        "simulate",
        "--distribution",
        "beckmann",
        "--alpha",
        "0.5",
        "--theta-i",
        "40",
        "--size",
        "128",
        "--rays",
        "40000",
        "--seed",
        "3",
        "--json",
    ]);
    assert_eq!(
        out.status.code(),
        Some(0),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let v: Value = serde_json::from_slice(&out.stdout).unwrap();
    let g1 = v["g1"].as_array().unwrap();
    assert!(g1.len() >= 9);
    for row in g1 {
        for k in ["theta_deg", "measured", "sigma", "smith"] {
            assert!(row[k].is_number(), "g1 row lacks {k}: {row}");
        }
    }
    assert_eq!(g1[0]["measured"].as_f64(), Some(1.0));
    let r80 = g1
        .iter()
        .find(|r| r["theta_deg"].as_f64() == Some(80.0))
        .unwrap();
    let (m, s, smith) = (
        r80["measured"].as_f64().unwrap(),
        r80["sigma"].as_f64().unwrap(),
        r80["smith"].as_f64().unwrap(),
    );
    assert!(
        m < 0.95 && (m - smith).abs() <= 3.0 * s + 0.02 * smith,
        "{r80}"
    );
    assert!(v["ndf_rel_error"].as_f64().unwrap() < 0.2);
    let rho = &v["rho"];
    let total = rho["single"].as_f64().unwrap() + rho["multiple"].as_f64().unwrap();
    assert!((total - 1.0).abs() < 1e-3, "{rho}");
    assert!(rho["sigma"].is_number());
    assert_eq!(v["brdf"].as_array().unwrap().len(), 18 * 36);
}

#[test]
fn table_without_json() {
    let out = bv(&[
        "simulate", "--alpha", "0.3", "--size", "64", "--rays", "5000",
    ]);
    assert_eq!(out.status.code(), Some(0));
    let text = String::from_utf8(out.stdout).unwrap();
    assert!(
        text.contains("masking G1") && text.contains("ρhd"),
        "{text}"
    );
}

#[test]
fn bad_input_exits_2_with_a_reason() {
    for (args, needle) in [
        (vec!["--alpha", "0"], "roughness"),
        (vec!["--alpha=-0.3"], "roughness"),
        (vec!["--alpha", "0.3", "--size", "1000"], "power of two"),
        (vec!["--alpha", "0.3", "--size", "65536"], "power of two"),
        (vec!["--alpha", "0.3", "--rays", "0"], "--rays"),
        (vec!["--alpha", "0.3", "--rays", "99999999999"], "--rays"),
        (vec!["--alpha", "0.3", "--theta-i", "95"], "--theta-i"),
        (vec!["--alpha", "0.3", "--fresnel", "conductor"], "eta"),
        (
            vec!["--alpha", "0.3", "--fresnel", "conductor", "-p", "eta=abc"],
            "not a number",
        ),
        (vec!["--alpha", "0.3", "-p", "q=1"], "unknown parameter"),
    ] {
        let mut a = vec!["simulate"];
        if !args.contains(&"--size") {
            a.extend(["--size", "64"]);
        }
        a.extend(args.iter().copied());
        let out = bv(&a);
        let err = String::from_utf8_lossy(&out.stderr);
        assert_eq!(out.status.code(), Some(2), "{a:?}: {err}");
        assert!(err.contains(needle), "{a:?}: {err}");
        assert!(!err.contains("panicked"), "{a:?}: {err}");
    }
}
