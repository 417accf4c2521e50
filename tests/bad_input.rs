//! Bad input never crashes, hangs, grows without bound or loses a file: the
//! built binary is run on FIFOs, devices, symlinks, read-only and huge files,
//! full output streams, absurd counts and odd command lines. Every run has a
//! deadline (a regression that blocks fails instead of hanging the suite),
//! and every case checks the exit status, the message, that nothing
//! panicked, and what is left on disk.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]
#![cfg(unix)]

use std::fs::{self, File};
use std::io::{Read, Write};
use std::os::unix::fs::{FileTypeExt, PermissionsExt, symlink};
use std::path::{Path, PathBuf};
use std::process::{Command, Stdio};
use std::time::{Duration, Instant};

const BV: &str = env!("CARGO_BIN_EXE_bv");

/// Longest any one run may take (the slowest case here takes well under a
/// second in a debug build).
const DEADLINE: Duration = Duration::from_secs(20);

/// Where a standard stream of the child goes.
#[derive(Clone, Copy, PartialEq)]
enum Sink {
    /// A pipe the test reads.
    Pipe,
    /// `/dev/full`: every write fails with ENOSPC.
    Full,
}

/// One finished run.
#[derive(Debug)]
struct Run {
    code: Option<i32>,
    stdout: String,
    stderr: String,
}

impl Run {
    /// Exited with `code`, with no panic (`panicked`, exit status 101).
    fn expect(&self, code: i32) -> &Self {
        assert!(
            !self.stderr.contains("panicked") && !self.stderr.contains("RUST_BACKTRACE"),
            "panic: {self:?}"
        );
        assert_ne!(self.code, Some(101), "panic: {self:?}");
        assert_eq!(self.code, Some(code), "{self:?}");
        self
    }

    /// The message names each of `words`.
    fn says(&self, words: &[&str]) -> &Self {
        for w in words {
            assert!(
                self.stderr.contains(w),
                "stderr lacks `{w}`: {}",
                self.stderr
            );
        }
        self
    }

    /// `bad` appears nowhere in stderr.
    fn never(&self, bad: &str) -> &Self {
        assert!(
            !self.stderr.contains(bad),
            "stderr has `{bad}`: {}",
            self.stderr
        );
        self
    }
}

/// Runs `bv args…` in `dir` with `stdin` bytes, stdout and stderr to the
/// given sinks, killing it at [`DEADLINE`].
fn run_in(dir: &Path, args: &[&str], stdin: &[u8], out: Sink, err: Sink) -> Run {
    let full = || Stdio::from(File::options().write(true).open("/dev/full").unwrap());
    let sink = |s: Sink| {
        if s == Sink::Full {
            full()
        } else {
            Stdio::piped()
        }
    };
    let mut child = Command::new(BV)
        .args(args)
        .current_dir(dir)
        .stdin(Stdio::piped())
        .stdout(sink(out))
        .stderr(sink(err))
        .spawn()
        .expect("bv starts");
    let mut input = child.stdin.take().unwrap();
    let bytes = stdin.to_vec();
    // A child that exits without reading gives EPIPE here; that is its right.
    let writer = std::thread::spawn(move || {
        let _ = input.write_all(&bytes);
    });
    let reader = |r: Option<Box<dyn Read + Send>>| {
        std::thread::spawn(move || {
            let mut s = Vec::new();
            if let Some(mut r) = r {
                let _ = r.read_to_end(&mut s);
            }
            String::from_utf8_lossy(&s).into_owned()
        })
    };
    let so = reader(child.stdout.take().map(|x| Box::new(x) as _));
    let se = reader(child.stderr.take().map(|x| Box::new(x) as _));
    let start = Instant::now();
    let status = loop {
        if let Some(s) = child.try_wait().unwrap() {
            break s;
        }
        if start.elapsed() > DEADLINE {
            let _ = child.kill();
            let _ = child.wait();
            panic!("bv {args:?} still running after {DEADLINE:?}: killed");
        }
        std::thread::sleep(Duration::from_millis(5));
    };
    writer.join().unwrap();
    Run {
        code: status.code(),
        stdout: so.join().unwrap(),
        stderr: se.join().unwrap(),
    }
}

fn run(dir: &Path, args: &[&str]) -> Run {
    run_in(dir, args, b"", Sink::Pipe, Sink::Pipe)
}

/// A fresh folder for one test.
fn dir(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-bad-input-{tag}-{}", std::process::id()));
    let _ = fs::remove_dir_all(&d);
    fs::create_dir_all(&d).unwrap();
    d
}

fn mkfifo(path: &Path) {
    let ok = Command::new("mkfifo").arg(path).status().unwrap().success();
    assert!(ok, "mkfifo {}", path.display());
}

fn is_fifo(path: &Path) -> bool {
    fs::symlink_metadata(path).is_ok_and(|m| m.file_type().is_fifo())
}

fn mode(path: &Path) -> u32 {
    fs::metadata(path).unwrap().permissions().mode() & 0o7777
}

/// A valid 1×1×2 MERL table whose every value is `v` (stored, unscaled).
fn merl_bytes(v: f64) -> Vec<u8> {
    let mut b = Vec::new();
    for n in [1i32, 1, 2] {
        b.extend_from_slice(&n.to_le_bytes());
    }
    for _ in 0..6 {
        b.extend_from_slice(&v.to_le_bytes());
    }
    b
}

/// A hand-written scene with one BRDF of `model` and `params` (TOML lines).
fn scene_text(model: &str, params: &str, extra: &str) -> String {
    format!(
        "format = \"bv-scene\"\nversion = 1\n{extra}\n[[brdfs]]\nid = 1\ncolor = [1, 2, 3]\n\
         visible = true\n[brdfs.spec]\nmodel = \"{model}\"\n[brdfs.spec.params]\n{params}\n"
    )
}

/// What every writer must do with every kind of target, for one command
/// that writes `--out TARGET` (`args` with `{}` for the target; targets end
/// in `ext`, which the command may need to pick a format).
fn check_writer(tag: &str, args: &[&str], ext: &str) {
    let d = dir(tag);
    let go = |target: &str| {
        let a: Vec<String> = args.iter().map(|a| a.replace("{}", target)).collect();
        let a: Vec<&str> = a.iter().map(String::as_str).collect();
        run(&d, &a)
    };
    let name = |stem: &str| format!("{stem}{ext}");

    // A FIFO stays a FIFO, and nothing blocks on it.
    let fifo = d.join(name("fifo"));
    mkfifo(&fifo);
    go(&name("fifo"))
        .expect(1)
        .says(&[&name("fifo"), "FIFO", "not a regular file"]);
    assert!(is_fifo(&fifo), "{tag}: the FIFO was replaced");

    // A device stays a device, named directly or through a link.
    symlink("/dev/null", d.join(name("null"))).unwrap();
    go(&name("null"))
        .expect(1)
        .says(&[&name("null"), "character device"]);
    if ext.is_empty() {
        go("/dev/null")
            .expect(1)
            .says(&["/dev/null", "character device"]);
    }
    assert!(
        fs::metadata("/dev/null")
            .unwrap()
            .file_type()
            .is_char_device()
    );

    // A directory, also spelt with a trailing slash (no "Not a directory").
    fs::create_dir(d.join(name("sub"))).unwrap();
    go(&name("sub"))
        .expect(1)
        .says(&[&name("sub"), "a directory"]);
    go(&format!("{}/", name("sub")))
        .expect(1)
        .says(&["names a folder"])
        .never("Not a directory");
    assert!(d.join(name("sub")).is_dir());

    // A read-only file keeps its bytes and its mode (root could write it,
    // so the check is on what is left, not on EACCES).
    let ro = d.join(name("ro"));
    fs::write(&ro, b"precious").unwrap();
    fs::set_permissions(&ro, fs::Permissions::from_mode(0o444)).unwrap();
    go(&name("ro"))
        .expect(1)
        .says(&[&name("ro"), "read-only", "0444"]);
    assert_eq!(fs::read(&ro).unwrap(), b"precious");
    assert_eq!(mode(&ro), 0o444);

    // A symlink is written through: still a link, its target has the new
    // contents and keeps its mode.
    let real = d.join(name("real"));
    fs::write(&real, b"old").unwrap();
    fs::set_permissions(&real, fs::Permissions::from_mode(0o640)).unwrap();
    symlink(name("real"), d.join(name("link"))).unwrap();
    go(&name("link")).expect(0);
    assert!(
        fs::symlink_metadata(d.join(name("link")))
            .unwrap()
            .file_type()
            .is_symlink()
    );
    assert_ne!(fs::read(&real).unwrap(), b"old");
    assert_eq!(mode(&real), 0o640);

    // A dangling symlink is refused and nothing is created at its target.
    symlink(name("nowhere"), d.join(name("dangling"))).unwrap();
    go(&name("dangling"))
        .expect(1)
        .says(&[&name("dangling"), "does not exist"]);
    assert!(!d.join(name("nowhere")).exists());

    // A plain new file is written, and no temporary file is left behind by
    // any of the refusals.
    go(&name("new")).expect(0);
    assert!(d.join(name("new")).is_file());
    let left: Vec<String> = fs::read_dir(&d)
        .unwrap()
        .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
        .filter(|n| n.ends_with(".tmp"))
        .collect();
    assert!(left.is_empty(), "{tag}: {left:?}");
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn scene_new_never_replaces_what_it_must_not() {
    check_writer(
        "scene-new",
        &["scene", "new", "--model", "lambert", "--out", "{}"],
        "",
    );
}

#[test]
fn tabulate_never_replaces_what_it_must_not() {
    check_writer(
        "tabulate",
        &[
            "tabulate", "--model", "lambert", "--dims", "1,1,2", "--out", "{}",
        ],
        "",
    );
}

#[test]
fn fit_scene_never_replaces_what_it_must_not() {
    check_writer(
        "fit",
        &[
            "fit", "-m", "lambert", "--to", "lambert", "--starts", "1", "--out", "{}",
        ],
        ".toml",
    );
}

#[test]
fn render_svg_never_replaces_what_it_must_not() {
    // A 2D plot as SVG needs no GPU; it goes through the same writer as
    // every figure.
    check_writer(
        "render",
        &[
            "render", "--model", "lambert", "--view", "polar", "--out", "{}",
        ],
        ".svg",
    );
}

#[test]
fn reads_refuse_fifos_devices_directories_and_huge_files_at_once() {
    let d = dir("reads");
    mkfifo(&d.join("fifo"));
    fs::create_dir(d.join("folder.toml")).unwrap();
    // 100 MB, sparse: costs no disk.
    let huge = File::create(d.join("huge.toml")).unwrap();
    huge.set_len(100_000_000).unwrap();
    let huge_merl = File::create(d.join("huge.binary")).unwrap();
    huge_merl.set_len(1 << 30).unwrap();
    symlink("missing.toml", d.join("dangling.toml")).unwrap();

    for cmd in [&["scene", "check"][..], &["scene", "print"], &["info"]] {
        let go = |path: &str| {
            let mut a = cmd.to_vec();
            a.push(path);
            run(&d, &a)
        };
        go("fifo")
            .expect(1)
            .says(&["fifo", "FIFO", "not a regular file"]);
        go("/dev/zero")
            .expect(1)
            .says(&["/dev/zero", "character device"]);
        go("/dev/null")
            .expect(1)
            .says(&["/dev/null", "character device"]);
        go("folder.toml")
            .expect(1)
            .says(&["folder.toml", "a directory"]);
        go("dangling.toml")
            .expect(1)
            .says(&["dangling.toml", "missing.toml", "does not exist"]);
    }
    run(&d, &["scene", "check", "huge.toml"]).expect(1).says(&[
        "huge.toml",
        "100000000 bytes",
        "over the 1 MiB limit",
    ]);
    run(&d, &["info", "huge.binary"]).expect(1).says(&[
        "huge.binary",
        "over the",
        "limit for a MERL",
    ]);
    assert!(is_fifo(&d.join("fifo")));
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_symlink_to_a_scene_reads_like_the_scene() {
    let d = dir("read-link");
    run(
        &d,
        &["scene", "new", "--model", "lambert", "--out", "s.toml"],
    )
    .expect(0);
    symlink("s.toml", d.join("l.toml")).unwrap();
    let r = run(&d, &["scene", "check", "l.toml"]);
    r.expect(0);
    assert!(r.stdout.contains("ok (0 warnings)"), "{r:?}");
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_full_stdout_is_an_error_not_a_panic() {
    let d = dir("full-out");
    fs::write(d.join("t.binary"), merl_bytes(1.0)).unwrap();
    run(
        &d,
        &["scene", "new", "--model", "lambert", "--out", "s.toml"],
    )
    .expect(0);
    let cases: [&[&str]; 7] = [
        &["info", "t.binary"],
        &["info", "t.binary", "--json"],
        &[
            "tabulate", "--model", "lambert", "--dims", "1,1,2", "--out", "o.binary",
        ],
        &["models"],
        &["check", "--model", "lambert"],
        &["scene", "print", "s.toml"],
        &["slice", "--model", "lambert"],
    ];
    for args in cases {
        run_in(&d, args, b"", Sink::Full, Sink::Pipe)
            .expect(1)
            .says(&["bv: cannot write to stdout: No space left on device"]);
    }
    let q = br#"{"model":"lambert","wi":[0,0,1],"wo":[0,0,1]}
"#;
    run_in(&d, &["eval"], q, Sink::Full, Sink::Pipe)
        .expect(1)
        .says(&["cannot write to stdout"]);
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_full_stderr_never_panics() {
    let d = dir("full-err");
    // The failed query's summary and the error message both go to a full
    // stderr; the status still tells.
    let r = run_in(&d, &["eval"], b"[1]\n", Sink::Pipe, Sink::Full);
    r.expect(1);
    assert!(r.stdout.contains("must be a JSON object"), "{r:?}");
    run_in(
        &d,
        &["scene", "check", "missing.toml"],
        b"",
        Sink::Pipe,
        Sink::Full,
    )
    .expect(1);
    run_in(
        &d,
        &["info", "x", "--pairs", "0"],
        b"",
        Sink::Pipe,
        Sink::Full,
    )
    .expect(2);
    // Both streams full.
    run_in(&d, &["models"], b"", Sink::Full, Sink::Full).expect(1);
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn counts_are_capped_and_the_cap_is_stated() {
    let d = dir("counts");
    fs::write(d.join("t.binary"), merl_bytes(1.0)).unwrap();
    run(&d, &["info", "t.binary", "--pairs", "99999999999"])
        .expect(2)
        .says(&["--pairs", "1..=2000000"]);
    run(&d, &["info", "t.binary", "--samples", "1e12"])
        .expect(2)
        .says(&["--samples", "1..=10000000"]);
    run(&d, &["bench", "--model", "lambert", "--pairs", "1e9"])
        .expect(2)
        .says(&["1..=50000000"]);
    run(
        &d,
        &["slice", "--model", "lambert", "--samples", "99999999999"],
    )
    .expect(1)
    .says(&["--samples", "2..=1000000"]);
    run(
        &d,
        &[
            "tabulate",
            "--model",
            "lambert",
            "--dims",
            "5000,5000,5000",
            "--out",
            "x.binary",
        ],
    )
    .expect(1)
    .says(&["cap"]);
    assert!(!d.join("x.binary").exists());
    // Within the caps all is well.
    run(
        &d,
        &["info", "t.binary", "--pairs", "10", "--samples", "16"],
    )
    .expect(0);
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_scene_finds_its_tables_beside_it_and_never_drops_a_brdf() {
    let d = dir("relative");
    fs::create_dir(d.join("scenes")).unwrap();
    fs::write(d.join("scenes/t.binary"), merl_bytes(1.0)).unwrap();
    fs::write(
        d.join("scenes/s.toml"),
        scene_text("merl", "path = \"t.binary\"", ""),
    )
    .unwrap();
    // Run from the parent folder: the path is the scene's, not the cwd's.
    let r = run(&d, &["scene", "check", "scenes/s.toml"]);
    r.expect(0);
    assert!(r.stdout.contains("1 BRDF: merl"), "{r:?}");
    // `scene print` writes it back relative to the scene's folder.
    let r = run(&d, &["scene", "print", "scenes/s.toml"]);
    r.expect(0);
    assert!(r.stdout.contains("path = \"t.binary\""), "{}", r.stdout);

    // A table that is not there is an error naming the BRDF and the file.
    fs::write(
        d.join("scenes/gone.toml"),
        scene_text("merl", "path = \"gone.binary\"", ""),
    )
    .unwrap();
    run(&d, &["scene", "check", "scenes/gone.toml"])
        .expect(1)
        .says(&["brdfs[0]", "merl", "gone.binary"]);
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn every_clamped_value_is_a_warning() {
    let d = dir("clamps");
    let extra = "[display]\nsh_order = 200\n[lighting.lit]\nexposure_ev = 99.0\n\
                 [lighting.env]\ntarget_spp = 0\n";
    fs::write(
        d.join("c.toml"),
        scene_text("lambert", "albedo = 0.5", extra),
    )
    .unwrap();
    let r = run(&d, &["scene", "check", "c.toml"]);
    r.expect(0).says(&[
        "display.sh_order = 200",
        "lighting.lit.exposure_ev = 99.0",
        "lighting.env.target_spp = 0",
    ]);
    assert!(r.stdout.contains("ok (3 warnings)"), "{r:?}");
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn duplicate_json_keys_are_refused_per_line() {
    let d = dir("dup");
    let input = br#"{"model":"lambert","wi":[0,0,1],"wo":[0,0,1],"wo":[1,0,0]}
{"model":"lambert","wi":[0,0,1],"wo":[0,0,1]}
"#;
    let r = run_in(&d, &["eval"], input, Sink::Pipe, Sink::Pipe);
    r.expect(1);
    let lines: Vec<&str> = r.stdout.lines().collect();
    assert_eq!(lines.len(), 2, "{r:?}");
    assert!(lines[0].contains("duplicate key `wo`"), "{}", lines[0]);
    assert!(lines[1].contains("\"f\""), "{}", lines[1]);
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn an_all_nan_table_says_it_has_no_valid_sample() {
    let d = dir("nan");
    fs::write(d.join("nan.binary"), merl_bytes(f64::NAN)).unwrap();
    let r = run(&d, &["info", "nan.binary"]);
    r.expect(0);
    assert!(
        r.stdout
            .contains("no valid sample at all in channels red, green, blue"),
        "{}",
        r.stdout
    );
    let r = run(&d, &["info", "nan.binary", "--json"]);
    r.expect(0);
    let v: serde_json::Value = serde_json::from_str(&r.stdout).unwrap();
    assert!(v["channels"][0]["mean"].is_null(), "{v}");
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn a_param_before_any_model_is_refused() {
    let d = dir("param-first");
    run(
        &d,
        &[
            "scene",
            "new",
            "-p",
            "albedo=0.2",
            "--model",
            "lambert",
            "--out",
            "s.toml",
        ],
    )
    .expect(1)
    .says(&["-p albedo=0.2", "before any --model"]);
    assert!(!d.join("s.toml").exists());
    fs::remove_dir_all(&d).unwrap();
}

#[test]
fn messages_say_each_thing_once_and_truly() {
    let d = dir("messages");
    fs::create_dir(d.join("dir.toml")).unwrap();
    let r = run(&d, &["scene", "check", "dir.toml"]);
    r.expect(1);
    assert_eq!(r.stderr.matches("dir.toml").count(), 1, "{}", r.stderr);
    assert_eq!(r.stderr.lines().count(), 1, "{}", r.stderr);
    let r = run(&d, &["scene", "check", "missing.toml"]);
    r.expect(1);
    assert_eq!(r.stderr.matches("missing.toml").count(), 1, "{}", r.stderr);
    assert_eq!(r.stderr.matches("os error 2").count(), 1, "{}", r.stderr);

    // `alpha` names what was typed and lists the model's parameters.
    run(&d, &["check", "--model", "lambert", "-p", "alpha=0.1"])
        .expect(1)
        .says(&["no parameter `alpha`", "albedo"])
        .never("alpha_x");

    // Huge numbers print short.
    for args in [
        &["check", "--model", "lambert", "-p", "albedo=1e300"][..],
        &["slice", "--model", "lambert", "--theta-i", "1e300"],
        &[
            "scene",
            "new",
            "--model",
            "lambert",
            "--theta-i",
            "1e300",
            "--out",
            "x.toml",
        ],
    ] {
        let r = run(&d, args);
        r.expect(1).says(&["1e300"]);
        assert!(!r.stderr.contains("0000000000"), "{}", r.stderr);
    }
    let q = br#"{"model":"lambert","wi":[1e300,0,0],"wo":[0,0,1]}
"#;
    let r = run_in(&d, &["eval"], q, Sink::Pipe, Sink::Pipe);
    r.expect(1);
    assert!(!r.stdout.contains("0000000000"), "{}", r.stdout);
    fs::remove_dir_all(&d).unwrap();
}
