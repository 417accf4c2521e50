//! RGL `.bsdf` materials from the outside: `bv tabulate --format rgl`,
//! `bv info` and `bv eval` on the written file, by path as a model name and
//! as `rgl` + `path`; a `.binary` path as a model name too.

// Test code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use serde_json::Value;
use std::f64::consts::PI;
use std::io::Write;
use std::path::PathBuf;
use std::process::{Command, Output, Stdio};

fn bv(args: &[&str], stdin: &str) -> Output {
    let mut child = Command::new(env!("CARGO_BIN_EXE_bv"))
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .expect("bv runs");
    child
        .stdin
        .take()
        .unwrap()
        .write_all(stdin.as_bytes())
        .unwrap();
    child.wait_with_output().unwrap()
}

fn temp_dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-rgl-cli-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d
}

fn text(b: &[u8]) -> String {
    String::from_utf8_lossy(b).into_owned()
}

/// `f` of each JSON line of `bv eval`'s output (or the error).
fn evals(out: &Output) -> Vec<Result<[f64; 3], String>> {
    text(&out.stdout)
        .lines()
        .map(|l| {
            let v: Value = serde_json::from_str(l).unwrap();
            match v.get("f") {
                Some(f) => Ok([0, 1, 2].map(|i| f[i].as_f64().unwrap())),
                None => Err(v["error"].as_str().unwrap_or("").to_string()),
            }
        })
        .collect()
}

#[test]
fn tabulate_info_and_eval_an_rgl_file() {
    let dir = temp_dir("ok");
    let file = dir.join("lambert.bsdf");
    let f = file.to_str().unwrap();
    let out = bv(
        &[
            "tabulate",
            "--model",
            "lambert",
            "--param",
            "albedo=0.5",
            "--format",
            "rgl",
            "--out",
            f,
        ],
        "",
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    assert!(
        text(&out.stdout).contains("RGL material"),
        "{}",
        text(&out.stdout)
    );

    let out = bv(&["info", "--samples", "20000", "--pairs", "2000", f], "");
    assert!(out.status.success(), "{}", text(&out.stderr));
    let report = text(&out.stdout);
    for want in [
        "rgl model",
        "16 θi",
        "isotropic",
        "Jacobian on",
        "ρhd",
        "reciprocity",
    ] {
        assert!(report.contains(want), "missing `{want}` in\n{report}");
    }
    let out = bv(
        &["info", "--json", "--samples", "20000", "--pairs", "2000", f],
        "",
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let j: Value = serde_json::from_slice(&out.stdout).unwrap();
    assert_eq!(j["model"], "rgl");
    // ρhd of the round-tripped Lambert at normal incidence: 0.5 up to the
    // round trip (< 1 %) and the Monte Carlo error.
    let rho = &j["rho_hd"][0];
    let (v, e) = (
        rho["value"][1].as_f64().unwrap(),
        rho["stderr"][1].as_f64().unwrap(),
    );
    assert!((v - 0.5).abs() < 0.005 + 4.0 * e, "{v} ± {e}");

    // By path as the model, and as `rgl` + `path`: the same value, near
    // albedo/π.
    let wi = [0.0, 0.0, 1.0];
    let wo = [0.6, 0.0, 0.8];
    let q = format!(
        "{}\n{}\n",
        serde_json::json!({"model": f, "wi": wi, "wo": wo}),
        serde_json::json!({"model": "rgl", "params": {"path": f}, "wi": wi, "wo": wo})
    );
    let out = bv(&["eval"], &q);
    assert!(out.status.success(), "{}", text(&out.stderr));
    let r = evals(&out);
    let (a, b) = (r[0].clone().unwrap(), r[1].clone().unwrap());
    assert_eq!(a, b);
    assert!((a[1] - 0.5 / PI).abs() < 0.01 * 0.5 / PI, "{a:?}");
    std::fs::remove_dir_all(&dir).ok();
}

#[test]
fn a_binary_path_is_a_model_and_bad_files_are_named() {
    let dir = temp_dir("bin");
    let file = dir.join("lambert.binary");
    let f = file.to_str().unwrap();
    let out = bv(
        &[
            "tabulate",
            "--model",
            "lambert",
            "--param",
            "albedo=0.3",
            "--out",
            f,
            "--dims",
            "8,6,12",
        ],
        "",
    );
    assert!(out.status.success(), "{}", text(&out.stderr));
    let bad = dir.join("bad.bsdf");
    std::fs::write(&bad, b"tensor_filX\0\x01\x00\x00\x00\x00\x00").unwrap();
    let q = format!(
        "{}\n{}\n",
        serde_json::json!({"model": f, "wi": [0.0, 0.0, 1.0], "wo": [0.0, 0.6, 0.8]}),
        serde_json::json!({"model": bad.to_str().unwrap(), "wi": [0.0, 0.0, 1.0], "wo": [0.0, 0.6, 0.8]}),
    );
    let out = bv(&["eval"], &q);
    let r = evals(&out);
    let v = r[0].clone().unwrap();
    assert!((v[0] - 0.3 / PI).abs() < 1e-6, "{v:?}");
    let e = r[1].clone().unwrap_err();
    assert!(
        e.contains("bad.bsdf") && e.contains("not a tensor file"),
        "{e}"
    );
    std::fs::remove_dir_all(&dir).ok();
}
