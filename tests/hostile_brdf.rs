//! Hostile `.brdf` files (the corpus in `tests/data/brdf/hostile/`, one file
//! per class of problem, each saying in its header what it does, plus the
//! large ones this test writes) through the commands a user runs on them:
//! `check`, `eval`, `render --view lit` and a deck that names the file.
//! Each ends with the exit status and the message its class calls for, no
//! crash (a stack overflow aborts with a signal), nothing written on
//! failure, and a peak memory (the child's own, from `wait4`) under 1 GiB.
//! Time is bounded by budgets the code enforces (the step budget, the
//! check's time budget), whose messages are asserted here, not by a timer.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::io::Write;
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};

const BV: &str = env!("CARGO_BIN_EXE_bv");
/// Peak resident memory any one command may reach on a hostile file.
const MAX_RSS_KIB: i64 = 1 << 20;

fn corpus(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/brdf/hostile")
        .join(name)
}

fn scratch(name: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-hostile-brdf-{}-{name}", std::process::id()));
    let _ = std::fs::remove_dir_all(&d);
    std::fs::create_dir_all(&d).unwrap();
    d
}

/// What a finished command left: exit code (None: killed by a signal),
/// stdout, stderr and peak resident memory in KiB.
struct Run {
    code: Option<i32>,
    stdout: String,
    stderr: String,
    max_rss_kib: i64,
}

/// Runs bv with `args` and `stdin`, waiting with `wait4` for its own peak
/// memory (which reaps the child, so `Child::wait` is not called).
#[allow(clippy::zombie_processes)]
fn bv(args: &[&str], stdin: &str) -> Run {
    let mut child = Command::new(BV)
        .args(args)
        .stdin(Stdio::piped())
        .stdout(Stdio::piped())
        .stderr(Stdio::piped())
        .spawn()
        .unwrap();
    let mut input = child.stdin.take().unwrap();
    let text = stdin.to_string();
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(text.as_bytes());
    });
    let out = child.stdout.take().unwrap();
    let err = child.stderr.take().unwrap();
    let read = |mut r: Box<dyn std::io::Read + Send>| {
        std::thread::spawn(move || {
            let mut s = String::new();
            let _ = r.read_to_string(&mut s);
            s
        })
    };
    let (out, err) = (read(Box::new(out)), read(Box::new(err)));
    let pid = i32::try_from(child.id()).unwrap();
    let mut status = 0;
    // SAFETY: an all-zero `rusage` is a valid value, which wait4 fills in.
    let mut usage: libc::rusage = unsafe { std::mem::zeroed() };
    // SAFETY: `pid` is our own child, not yet waited for; the pointers are
    // to live locals.
    let r = unsafe { libc::wait4(pid, &mut status, 0, &mut usage) };
    assert_eq!(r, pid, "wait4 failed");
    writer.join().unwrap();
    let code = libc::WIFEXITED(status).then(|| libc::WEXITSTATUS(status));
    Run {
        code,
        stdout: out.join().unwrap(),
        stderr: err.join().unwrap(),
        max_rss_kib: usage.ru_maxrss,
    }
}

fn check_run(what: &str, r: &Run, code: i32, needle: &str) {
    assert_eq!(
        r.code,
        Some(code),
        "{what}: exit {:?} (None: a signal, e.g. a stack overflow)\nstdout: {}\nstderr: {}",
        r.code,
        r.stdout,
        r.stderr
    );
    let all = format!("{}{}", r.stdout, r.stderr);
    assert!(all.contains(needle), "{what}: no `{needle}` in\n{all}");
    assert!(!all.contains("panicked"), "{what}: a panic\n{all}");
    assert!(
        r.max_rss_kib < MAX_RSS_KIB,
        "{what}: peak memory {} KiB",
        r.max_rss_kib
    );
}

/// The files every command refuses, and what the message must name.
const REFUSED: &[(&str, &str)] = &[
    ("long_sum.brdf", "operators"),
    ("deep_parentheses.brdf", "nest more than"),
    ("doubling_defines.brdf", "operators"),
    ("doubling_statements.brdf", "tokens long"),
    ("doubling_arguments.brdf", "operators"),
    ("empty_macro_bomb.brdf", "macros expand"),
    ("loop_away_from_normal.brdf", "steps"),
    ("arrays_in_total.brdf", "bytes in all"),
    (
        "keyword_parameter.brdf",
        "`mat3` has a name that GLSL reserves",
    ),
    ("include.brdf", "`#include` is not supported"),
    ("sampler.brdf", "`uniform` declarations are not supported"),
    ("no_break_space.brdf", "U+00A0 (a no-break space)"),
    ("nul_byte.brdf", "NUL"),
    ("mutual_recursion.brdf", "call each other"),
    ("derivatives.brdf", "derivatives"),
    ("negative_array.brdf", "cannot be negative"),
];

/// A deck of one slide showing model `model` (a path).
fn deck_naming(dir: &Path, model: &Path) -> PathBuf {
    let deck = dir.join("deck.toml");
    std::fs::write(
        &deck,
        format!(
            "format = \"bv-deck\"\nversion = 1\ntitle = \"t\"\n[[scene]]\ntitle = \"s\"\n\
             caption = \"c\"\nview = \"polar\"\n[scene.state]\nselected = 1\n\
             [[scene.state.brdfs]]\nid = 1\ncolor = [78, 151, 234]\nvisible = true\nspec = {{ model = {:?} }}\n",
            model.display().to_string()
        ),
    )
    .unwrap();
    deck
}

#[test]
fn every_refused_file_is_refused_by_every_command_with_its_cause() {
    let dir = scratch("refused");
    for (name, needle) in REFUSED {
        let path = corpus(name);
        let p = path.to_str().unwrap();
        check_run(
            &format!("check {name}"),
            &bv(&["check", "-m", p], ""),
            1,
            needle,
        );
        let png = dir.join("lit.png");
        let r = bv(
            &[
                "render",
                "-m",
                p,
                "--view",
                "lit",
                "-o",
                png.to_str().unwrap(),
            ],
            "",
        );
        check_run(&format!("render {name}"), &r, 1, needle);
        assert!(!png.exists(), "render {name} wrote a file");
        // eval: the query about this file fails, the good ones around it
        // are answered, in order.
        let good = r#"{"model":"lambert","wi":[0,0,1],"wo":[0,0,1]}"#;
        let bad = format!(r#"{{"model":{p:?},"wi":[0,0,1],"wo":[0,0,1]}}"#);
        let r = bv(&["eval"], &format!("{good}\n{bad}\n{good}\n"));
        check_run(&format!("eval {name}"), &r, 1, needle);
        let lines: Vec<&str> = r.stdout.lines().collect();
        assert_eq!(lines.len(), 3, "eval {name}: {}", r.stdout);
        assert!(lines[0].starts_with(r#"{"f""#) && lines[2].starts_with(r#"{"f""#));
        assert!(lines[1].starts_with(r#"{"error""#), "{}", lines[1]);
        let slides = dir.join("slides");
        let deck = deck_naming(&dir, &path);
        let r = bv(
            &[
                "render",
                "--deck",
                deck.to_str().unwrap(),
                "--out",
                slides.to_str().unwrap(),
            ],
            "",
        );
        check_run(&format!("deck {name}"), &r, 1, needle);
    }
}

#[test]
fn files_too_large_to_compile_quickly_are_refused_by_size() {
    let dir = scratch("large");
    let statements = dir.join("statements.brdf");
    let body = "a = a * 0.5 + 0.25;\n".repeat(40_000);
    std::fs::write(
        &statements,
        format!(
            "analytic\n::begin parameters\nfloat n 0 1 0.5\n::end parameters\n::begin shader\n\
             vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ float a = n;\n{body}return vec3(a); }}\n\
             ::end shader\n"
        ),
    )
    .unwrap();
    let r = bv(&["check", "-m", statements.to_str().unwrap()], "");
    check_run("check 40,000 statements", &r, 1, "tokens long");
    let huge = dir.join("huge.brdf");
    std::fs::write(&huge, format!("analytic\n# {}\n", "x".repeat(2 << 20))).unwrap();
    let r = bv(&["check", "-m", huge.to_str().unwrap()], "");
    check_run("check a 2 MB file", &r, 1, "over the 1 MiB limit");
}

#[test]
fn a_model_too_slow_for_check_is_refused_with_the_numbers() {
    let p = corpus("slow_everywhere.brdf");
    let r = bv(&["check", "-m", p.to_str().unwrap()], "");
    check_run("check slow_everywhere", &r, 1, "too slow for bv check");
    assert!(r.stderr.contains("per evaluation") && r.stderr.contains("budget is 7.0 s"));
    // Evaluating it once is fine.
    let q = format!(
        r#"{{"model":{:?},"wi":[0,0,1],"wo":[0,0,1]}}"#,
        p.to_str().unwrap()
    );
    check_run(
        "eval slow_everywhere",
        &bv(&["eval"], &format!("{q}\n")),
        0,
        "\"f\"",
    );
}

#[test]
fn evaluations_that_fail_are_errors_never_zeros() {
    let p = corpus("loop_in_a_corner.brdf");
    let p = p.to_str().unwrap();
    // At the corner, the query fails with the step budget; elsewhere the
    // value is n = 0.5.
    let corner = format!(r#"{{"model":{p:?},"wi":[0.999,0,0.0447],"wo":[-0.95,0,0.3122]}}"#);
    let fine = format!(r#"{{"model":{p:?},"wi":[0,0,1],"wo":[0,0,1]}}"#);
    let r = bv(&["eval"], &format!("{fine}\n{corner}\n{fine}\n"));
    check_run("eval loop_in_a_corner", &r, 1, "steps");
    let lines: Vec<&str> = r.stdout.lines().collect();
    assert_eq!(lines[0], r#"{"f":[0.5,0.5,0.5]}"#);
    assert!(
        lines[1].contains("error") && lines[1].contains("at L = "),
        "{}",
        lines[1]
    );
    assert_eq!(lines[2], r#"{"f":[0.5,0.5,0.5]}"#);
    // check meets the corner among its pairs: an error naming the failure.
    let r = bv(&["check", "-m", p], "");
    check_run(
        "check loop_in_a_corner",
        &r,
        1,
        "failed, so the result would be wrong",
    );
    // A slice through the corner: at θi = 87°, φi = 0 the light is at
    // L.x = 0.9986, and the plane of incidence sweeps the viewer through
    // V.x < -0.9.
    let r = bv(&["slice", "-m", p, "--theta-i", "87", "--phi-i", "0"], "");
    check_run(
        "slice loop_in_a_corner",
        &r,
        1,
        "failed, so the result would be wrong",
    );
}

#[test]
fn non_finite_values_are_counted_and_reported() {
    let p = corpus("not_finite.brdf");
    let p = p.to_str().unwrap();
    let r = bv(&["check", "-m", p], "");
    check_run("check not_finite", &r, 0, "non-finite");
    assert!(!r.stdout.contains(" 0 non-finite"), "{}", r.stdout);
    assert!(
        r.stderr.contains("returned NaN or infinity"),
        "{}",
        r.stderr
    );
    let q = format!(r#"{{"model":{p:?},"wi":[0,0,1],"wo":[0,0,1]}}"#);
    check_run(
        "eval not_finite",
        &bv(&["eval"], &format!("{q}\n")),
        1,
        "non-finite",
    );
}

#[test]
fn a_byte_order_mark_is_not_part_of_the_file() {
    let p = corpus("byte_order_mark.brdf");
    let q = format!(
        r#"{{"model":{:?},"wi":[0,0,1],"wo":[0,0,1]}}"#,
        p.to_str().unwrap()
    );
    check_run(
        "eval byte_order_mark",
        &bv(&["eval"], &format!("{q}\n")),
        0,
        "[0.5,0.5,0.5]",
    );
}

#[test]
fn two_files_with_one_stem_stay_two_models() {
    let dir = scratch("stems");
    for (sub, value) in [("a", 0.25), ("b", 0.75)] {
        std::fs::create_dir_all(dir.join(sub)).unwrap();
        std::fs::write(
            dir.join(sub).join("same.brdf"),
            format!(
                "analytic\n::begin parameters\nfloat n 0 1 {value}\n::end parameters\n\
                 ::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ return vec3(n); }}\n\
                 ::end shader\n"
            ),
        )
        .unwrap();
    }
    let q = |sub: &str| {
        format!(
            r#"{{"model":{:?},"wi":[0,0,1],"wo":[0,0,1]}}"#,
            dir.join(sub).join("same.brdf").to_str().unwrap()
        )
    };
    let r = bv(&["eval"], &format!("{}\n{}\n{}\n", q("a"), q("b"), q("a")));
    assert_eq!(
        r.stdout, "{\"f\":[0.25,0.25,0.25]}\n{\"f\":[0.75,0.75,0.75]}\n{\"f\":[0.25,0.25,0.25]}\n",
        "{}",
        r.stderr
    );
}
