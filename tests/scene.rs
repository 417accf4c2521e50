//! Scene files: round trips, corrupt and truncated files, atomic
//! saves, unknown keys, and the `bv scene` / `bv --scene` command lines.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::app::viewer::Viewer;
use bv::session::scene_file::{self as scene, END_MARKER, SceneError};
use bv::session::state::{AppState, CartesianAxis, Incident, Theme};
use bv_core::ModelSpec;
use serde_json::json;
use std::path::{Path, PathBuf};
use std::process::Command;

fn tmp(name: &str) -> PathBuf {
    let dir = std::env::temp_dir().join(format!("bv-scene-tests-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    dir.join(name)
}

/// A scene touching every kind of parameter (colour, float, choice, list of
/// records, nested mix) and every section of the state.
fn rich_state() -> AppState {
    let mut s = AppState::default();
    s.add(ModelSpec::from_json("lambert", &json!({"albedo": [0.2, 0.4, 0.6]})).unwrap());
    s.add(
        ModelSpec::from_json(
            "cook-torrance",
            &json!({"distribution": "ggx", "alpha_x": 0.15, "alpha_y": 0.4,
                    "fresnel": "conductor", "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14]}),
        )
        .unwrap(),
    );
    s.add(
        ModelSpec::from_json(
            "lafortune",
            &json!({"kd": 0.1, "lobes": [{"cx": -1.0, "cy": -1.0, "cz": 1.0, "n": 30.0, "ks": 0.5},
                                         {"cx": 1.0, "cy": 1.0, "cz": 1.0, "n": 5.0, "ks": 0.2}]}),
        )
        .unwrap(),
    );
    s.add(
        ModelSpec::from_json(
            "mix",
            &json!({"components": [
                {"weight": 0.3, "model": "lambert", "params": {"albedo": 0.9}},
                {"weight": 0.7, "model": "ward", "params": {"alpha_x": 0.1, "alpha_y": 0.2}}]}),
        )
        .unwrap(),
    );
    s.brdfs[0].visible = false;
    s.brdfs[1].color = [1, 2, 3];
    s.selected = Some(s.brdfs[1].id);
    s.solo = Some(s.brdfs[2].id);
    s.incident = Incident {
        theta_deg: 61.125,
        phi_deg: -33.0,
    };
    s.camera.yaw_deg = 47.5;
    s.camera.pitch_deg = 12.25;
    s.camera.distance = 6.5;
    s.display.log = true;
    s.display.cosine = true;
    s.display.wireframe = true;
    s.plots.axis = CartesianAxis::ThetaH;
    s.plots.fixed_theta_d_deg = 12.5;
    s.plots.slice.phi_d_deg = 33.5;
    s.plots.slice.exposure_ev = -4.5;
    s.plots.slice.gamma = 3.25;
    s.plots.slice.sqrt_theta_h = true;
    s.maximised = Some("polar".into());
    s.theme = Theme::Light;
    s.sanitised()
}

#[test]
fn save_then_load_gives_the_identical_state() {
    let s = rich_state();
    let path = tmp("round-trip.toml");
    scene::save(&path, &s).unwrap();
    let loaded = scene::load(&path).unwrap();
    assert_eq!(loaded.warnings, Vec::<String>::new());
    assert_eq!(loaded.state, s);
    // And saving what was loaded writes the same bytes.
    let again = tmp("round-trip-2.toml");
    scene::save(&again, &loaded.state).unwrap();
    assert_eq!(
        std::fs::read(&path).unwrap(),
        std::fs::read(&again).unwrap()
    );
}

#[test]
fn the_viewer_saves_and_opens_scenes() {
    let mut v = Viewer::new(rich_state());
    let path = tmp("viewer.toml");
    v.save_scene(&path).unwrap();
    let mut w = Viewer::new(AppState::first_run());
    let warnings = w.open_scene(&path).unwrap();
    assert!(warnings.is_empty(), "{warnings:?}");
    // The theme is the window's own choice; everything else comes from the file.
    let mut want = rich_state();
    want.theme = w.state().theme;
    assert_eq!(w.state(), &want);
    assert_eq!(w.export.scene_path.as_deref(), Some(path.as_path()));
}

fn err_of(text: &str) -> String {
    match scene::from_toml(text) {
        Ok(l) => panic!("accepted: {:?}", l.state),
        Err(e) => e.to_string(),
    }
}

#[test]
fn corrupt_files_are_refused_with_a_clear_error() {
    let good = scene::to_toml(&rich_state()).unwrap();
    // Not TOML at all.
    let e = err_of("\u{0}\u{1}PNG garbage ][");
    assert!(e.contains("not a valid scene file"), "{e}");
    // A value of the wrong type: the message points at the line.
    let e = err_of(&good.replace("theta_deg = 61.125", "theta_deg = \"steep\""));
    assert!(e.contains("theta_deg") && e.contains("line"), "{e}");
    // Out of range: the key and the range.
    let e = err_of(&good.replace("theta_deg = 61.125", "theta_deg = 190.0"));
    assert!(e.contains("incident.theta_deg") && e.contains("180"), "{e}");
    // The horizon: the key and both sides' limits (issue 33: the light may
    // be below the surface, but not in it).
    let e = err_of(&good.replace("theta_deg = 61.125", "theta_deg = 90.0"));
    assert!(
        e.contains("incident.theta_deg") && e.contains("89.5") && e.contains("90.5"),
        "{e}"
    );
    // An unknown model, a bad parameter: the entry and the core's reason.
    let e = err_of(&good.replace("model = \"lambert\"\n", "model = \"lamberd\"\n"));
    assert!(e.contains("brdfs[0]") && e.contains("lamberd"), "{e}");
    let e = err_of(&good.replace("alpha_x = 0.15", "alpha_x = -3.0"));
    assert!(e.contains("brdfs[1]") && e.contains("alpha_x"), "{e}");
    // The image slice's display (saved since LECTURE.md N1).
    let e = err_of(&good.replace("gamma = 3.25", "gamma = 0.0"));
    assert!(
        e.contains("plots.slice.gamma") && e.contains("1..=4"),
        "{e}"
    );
    let e = err_of(&good.replace("phi_d_deg = 33.5", "phi_d_deg = nan"));
    assert!(e.contains("plots.slice.phi_d_deg"), "{e}");
    // A colour byte out of range.
    let e = err_of(&good.replace("color = [1, 2, 3]", "color = [1, 2, 300]"));
    assert!(e.contains("300") || e.contains("u8"), "{e}");
    // Another program's file, a newer format.
    let e = err_of(&good.replace("format = \"bv-scene\"", "format = \"blender\""));
    assert!(
        e.contains("`format`") && e.contains("not a bv scene"),
        "{e}"
    );
    let e = err_of(&good.replace("version = 1", "version = 99"));
    assert!(e.contains("99") && e.contains("newer"), "{e}");
    // Two BRDFs with one id.
    let e = err_of(&good.replace("id = 2\n", "id = 1\n"));
    assert!(e.contains("id") && e.contains("earlier"), "{e}");
}

#[test]
fn truncated_files_are_refused() {
    let good = scene::to_toml(&rich_state()).unwrap();
    assert!(good.trim_end().ends_with(END_MARKER));
    // Cut at every line boundary and in the middle of lines: never accepted.
    let cuts: Vec<usize> = good
        .char_indices()
        .filter(|(_, c)| *c == '\n')
        .map(|(i, _)| i + 1)
        .chain(
            (1..good.len())
                .step_by(97)
                .filter(|i| good.is_char_boundary(*i)),
        )
        .filter(|&i| i < good.trim_end().len() - END_MARKER.len())
        .collect();
    assert!(cuts.len() > 50);
    for cut in cuts {
        let e = scene::from_toml(&good[..cut]);
        assert!(e.is_err(), "a file cut at byte {cut} was accepted");
    }
    // The usual case names the problem.
    let half = &good[..good.len() / 2];
    let half = &half[..half.rfind('\n').unwrap() + 1];
    assert!(matches!(scene::from_toml(half), Err(SceneError::Truncated)));
    // An empty file (cut before anything) names the missing version.
    let e = err_of("");
    assert!(e.contains("version") && e.contains("missing"), "{e}");
}

#[test]
fn hand_written_scenes_need_no_marker_and_unknown_keys_warn() {
    let text = r#"
format = "bv-scene"
version = 1
colour_scheme = "viridis"

[incident]
theta_deg = 30
phi_deg = 0
spin = 3

[[brdfs]]
id = 1
color = [200, 100, 50]
visible = true
[brdfs.spec]
model = "phong"
[brdfs.spec.params]
e = 50
"#;
    let l = scene::from_toml(text).unwrap();
    assert_eq!(l.state.brdfs.len(), 1);
    assert_eq!(l.state.brdfs[0].spec.params().float("e").unwrap(), 50.0);
    assert_eq!(l.state.incident.theta_deg, 30.0);
    let w = l.warnings.join("\n");
    assert!(
        w.contains("colour_scheme") && w.contains("incident.spin"),
        "{w}"
    );
}

#[test]
fn an_interrupted_save_leaves_the_old_file_intact() {
    // A folder of its own: the other tests of this binary save in parallel,
    // and a save of theirs in flight is a temporary of this process too.
    let path = tmp("interrupted/interrupted.toml");
    std::fs::create_dir_all(path.parent().unwrap()).unwrap();
    let old = rich_state();
    scene::save(&path, &old).unwrap();
    let before = std::fs::read(&path).unwrap();
    // The writer dies half way (a full disk, a crash): the target is untouched
    // and no temporary file is left behind.
    let r = scene::write_atomic(&path, |f| {
        f.write_all(&before[..before.len() / 2])?;
        Err(std::io::Error::other("simulated crash"))
    });
    assert!(r.is_err());
    assert_eq!(std::fs::read(&path).unwrap(), before);
    assert_eq!(scene::load(&path).unwrap().state, old);
    let dir = path.parent().unwrap();
    let leftovers: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .filter_map(|e| e.ok())
        .filter(|e| {
            // Only this process's temporaries (`.bv-PID-XXXXXXXX.tmp`): the
            // killed-writer test in the same folder, running in parallel,
            // leaves its children's behind by design.
            let n = e.file_name().to_string_lossy().into_owned();
            n.starts_with(&format!(".bv-{}-", std::process::id())) && n.ends_with(".tmp")
        })
        .collect();
    assert!(leftovers.is_empty(), "{leftovers:?}");
    // A save into a folder that does not exist fails cleanly too.
    let r = scene::save(Path::new("/nonexistent-bv-dir/x.toml"), &old);
    assert!(r.unwrap_err().to_string().contains("nonexistent-bv-dir"));
}

#[test]
fn a_killed_writer_process_leaves_the_old_file_intact() {
    // A real crash: a child process writing a large scene through
    // `bv scene new` is killed mid-way, over and over; the old scene must
    // always load. (The rename is the only step that touches the target.)
    let path = tmp("killed.toml");
    let old = rich_state();
    scene::save(&path, &old).unwrap();
    let bin = env!("CARGO_BIN_EXE_bv");
    for k in 0..5u64 {
        let mut child = Command::new(bin)
            .args(["scene", "new", "--model", "lambert", "--out"])
            .arg(&path)
            .spawn()
            .unwrap();
        std::thread::sleep(std::time::Duration::from_millis(2 * k));
        let _ = child.kill();
        let _ = child.wait();
        let l = scene::load(&path).unwrap();
        assert!(
            l.state == old || l.state.brdfs.len() == 1,
            "a half-written scene after kill {k}"
        );
    }
}

#[test]
fn bv_scene_check_print_and_new() {
    let bin = env!("CARGO_BIN_EXE_bv");
    let path = tmp("cli.toml");
    let out = Command::new(bin)
        .args([
            "scene",
            "new",
            "--model",
            "lambert",
            "-p",
            "albedo=0.3",
            "--model",
            "ward",
            "-p",
            "alpha_x=0.1",
            "--theta-i",
            "30",
            "--log",
            "--out",
        ])
        .arg(&path)
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let l = scene::load(&path).unwrap();
    assert_eq!(l.state.brdfs.len(), 2);
    assert_eq!(
        l.state.brdfs[0].spec.params().color("albedo").unwrap().x,
        0.3
    );
    assert_eq!(
        l.state.brdfs[1].spec.params().float("alpha_x").unwrap(),
        0.1
    );
    assert!(l.state.display.log);

    let out = Command::new(bin)
        .args(["scene", "check"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(out.status.success());
    let text = String::from_utf8_lossy(&out.stdout);
    assert!(
        text.contains("ok") && text.contains("lambert, ward"),
        "{text}"
    );

    // Warnings go to stderr; errors fail with the key.
    let text = std::fs::read_to_string(&path)
        .unwrap()
        .replace("[incident]", "[incident]\nwobble = 1");
    std::fs::write(&path, &text).unwrap();
    let out = Command::new(bin)
        .args(["scene", "check"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("incident.wobble"));
    std::fs::write(&path, text.replace("theta_deg = 30.0", "theta_deg = -4.0")).unwrap();
    let out = Command::new(bin)
        .args(["scene", "check"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("incident.theta_deg"));

    // `print` writes a scene that loads back.
    scene::save(&path, &rich_state()).unwrap();
    let out = Command::new(bin)
        .args(["scene", "print"])
        .arg(&path)
        .output()
        .unwrap();
    assert!(out.status.success());
    let printed = String::from_utf8(out.stdout).unwrap();
    assert_eq!(scene::from_toml(&printed).unwrap().state, rich_state());

    // The viewer refuses a bad scene before opening a window.
    std::fs::write(&path, "format = \"bv-scene\"\nversion = \"x\"\n").unwrap();
    let out = Command::new(bin)
        .args(["--scene"])
        .arg(&path)
        .env_remove("DISPLAY")
        .env_remove("WAYLAND_DISPLAY")
        .output()
        .unwrap();
    assert!(!out.status.success());
    assert!(String::from_utf8_lossy(&out.stderr).contains("version"));
}

#[test]
fn unknown_keys_inside_a_brdf_warn() {
    let good = scene::to_toml(&rich_state()).unwrap();
    let text = good.replacen("visible = false", "visible = false\nglossy = true", 1);
    let l = scene::from_toml(&text).unwrap();
    assert_eq!(l.state, rich_state());
    assert!(
        l.warnings.iter().any(|w| w.contains("brdfs[0].glossy")),
        "{:?}",
        l.warnings
    );
}
