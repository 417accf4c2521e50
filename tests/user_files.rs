//! User BRDF files (`.brdf`) as models: the test files of `tests/data/brdf/`
//! are opened by path, registered, and evaluated by the GPU (through the
//! generated dispatch, as every view does) against closed forms written
//! here, independently of the files' GLSL. Runs in its own process because
//! the catalogue is process-wide.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::eval::GpuEvaluator;
use bv::gpu::shaders::ShaderLibrary;
use bv_core::ModelSpec;
use glam::DVec3;
use std::f64::consts::PI;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("tests/data/brdf")
        .join(name)
}

fn spec(name: &str, params: serde_json::Value) -> ModelSpec {
    bv::session::user_models::install();
    let path = data(name);
    ModelSpec::from_json(path.to_str().unwrap(), &params).unwrap_or_else(|e| panic!("{name}: {e}"))
}

/// Direction pairs above the horizon, away from grazing.
fn pairs() -> Vec<(DVec3, DVec3)> {
    let mut out = Vec::new();
    for i in 0..7 {
        for j in 0..7 {
            let ti = 0.1 + 1.2 * f64::from(i) / 7.0;
            let to = 0.05 + 1.25 * f64::from(j) / 7.0;
            let pi = 0.3 * f64::from(i);
            let po = 2.0 + 0.7 * f64::from(j);
            let wi = DVec3::new(ti.sin() * pi.cos(), ti.sin() * pi.sin(), ti.cos());
            let wo = DVec3::new(to.sin() * po.cos(), to.sin() * po.sin(), to.cos());
            out.push((wi, wo));
            // The mirror direction too, where the highlights are.
            out.push((wi, DVec3::new(-wi.x, -wi.y, wi.z)));
        }
    }
    out
}

fn f32_pairs(p: &[(DVec3, DVec3)]) -> Vec<([f32; 3], [f32; 3])> {
    p.iter()
        .map(|(a, b)| (a.as_vec3().to_array(), b.as_vec3().to_array()))
        .collect()
}

/// Compares the GPU with `want` on [`pairs`]: relative 1e-4 (f32 through
/// transcendental functions) plus a small absolute floor.
fn gpu_matches(
    eval: &GpuEvaluator,
    s: &ModelSpec,
    what: &str,
    want: impl Fn(DVec3, DVec3) -> [f64; 3],
) {
    let p = pairs();
    let got = eval.eval(s, &f32_pairs(&p)).unwrap();
    for ((wi, wo), g) in p.iter().zip(&got) {
        // The closed form gets the f32 directions the GPU got.
        let wi = wi.as_vec3().as_dvec3();
        let wo = wo.as_vec3().as_dvec3();
        let w = want(wi, wo);
        for c in 0..3 {
            let tol = 2e-4 * w[c].abs() + 1e-5;
            assert!(
                (f64::from(g[c]) - w[c]).abs() <= tol,
                "{what}: GPU {g:?} against {w:?} at wi {wi} wo {wo}"
            );
        }
    }
}

fn h(wi: DVec3, wo: DVec3) -> DVec3 {
    (wi + wo).normalize()
}

fn grey(x: f64) -> [f64; 3] {
    [x, x, x]
}

fn gpu() -> Option<(GpuEvaluator, ())> {
    let gpu = bv::gpu::context::gpu_for_test()?;
    let mut lib = ShaderLibrary::new().unwrap();
    Some((GpuEvaluator::new(gpu, &mut lib).unwrap(), ()))
}

#[test]
fn the_gpu_evaluates_every_test_file_as_its_closed_form() {
    // Register every file first: the shader library is built from the
    // catalogue as it is when it is made.
    let lambert = spec(
        "lambert.brdf",
        serde_json::json!({"albedo": [0.2, 0.4, 0.6]}),
    );
    let phong = spec("phong.brdf", serde_json::json!({"e": 20.0}));
    let ct = spec(
        "cooktorrance.brdf",
        serde_json::json!({"m": 0.3, "f0": 0.04}),
    );
    let ward = spec(
        "ward.brdf",
        serde_json::json!({"alpha_x": 0.15, "alpha_y": 0.4}),
    );
    let ggx = spec("ggx.brdf", serde_json::json!({"alpha": 0.25}));
    let ints = spec("lenient_int_literals.brdf", serde_json::json!({}));
    let reflect = spec("lenient_reflect.brdf", serde_json::json!({"n": 10.0}));
    let smooth = spec("lenient_smoothstep.brdf", serde_json::json!({}));
    let globals = spec("lenient_globals.brdf", serde_json::json!({"k": 3.0}));
    let shadow = spec("lenient_shadowing.brdf", serde_json::json!({"m": 0.5}));
    let bools = spec("lenient_bools.brdf", serde_json::json!({}));
    let bools2 = spec(
        "lenient_bools.brdf",
        serde_json::json!({"doubled": true, "red_only": false}),
    );
    let features = spec("features.brdf", serde_json::json!({}));
    let native = spec("native.brdf", serde_json::json!({}));
    let looping = spec("hostile_loop.brdf", serde_json::json!({}));
    let names = spec("names.brdf", serde_json::json!({"Ks": 0.125}));
    let Some((eval, ())) = gpu() else {
        return;
    };
    gpu_matches(&eval, &lambert, "lambert", |_, _| {
        [0.2 / PI, 0.4 / PI, 0.6 / PI]
    });
    gpu_matches(&eval, &phong, "phong", |wi, wo| {
        let r = DVec3::new(-wo.x, -wo.y, wo.z);
        grey(0.15 + 0.3 * r.dot(wi).max(0.0).powf(20.0) / wi.z)
    });
    gpu_matches(&eval, &ct, "cook-torrance", |wi, wo| {
        let h = h(wi, wo);
        let (c, m) = (h.z, 0.3);
        let d = (-(1.0 - c * c) / (c * c) / (m * m)).exp() / (PI * m * m * c.powi(4));
        let vh = wo.dot(h);
        let g = (2.0 * c * wo.z / vh).min(2.0 * c * wi.z / vh).min(1.0);
        let f = 0.04 + 0.96 * (1.0 - wi.dot(h)).powi(5);
        grey(0.3 / PI + 0.7 * d * g * f / (4.0 * wi.z * wo.z))
    });
    gpu_matches(&eval, &ward, "ward", |wi, wo| {
        let hv = wi + wo;
        let e = -((hv.x / 0.15).powi(2) + (hv.y / 0.4).powi(2)) / (hv.z * hv.z);
        grey(0.5 / PI + 0.2 * e.exp() / (4.0 * PI * 0.15 * 0.4 * (wi.z * wo.z).sqrt()))
    });
    gpu_matches(&eval, &ggx, "ggx", |wi, wo| {
        let h = h(wi, wo);
        let a2 = 0.25f64 * 0.25;
        let d = a2 / (PI * (h.z * h.z * (a2 - 1.0) + 1.0).powi(2));
        let vh = wo.dot(h);
        let g = (2.0 * h.z * wo.z / vh).min(2.0 * h.z * wi.z / vh).min(1.0);
        grey(d * g / (4.0 * wi.z * wo.z))
    });
    gpu_matches(&eval, &ints, "int literals", |wi, wo| {
        let u = wi.z;
        [
            0.25 + 0.75 * (1.0 - u).powi(5),
            (1.0 - u).clamp(0.0, 1.0),
            wo.z / 2.0,
        ]
    });
    gpu_matches(&eval, &reflect, "redefined reflect", |wi, wo| {
        // The file's reflect(L, N) = 2 (L·N) N − L: the mirror of L.
        let r = DVec3::new(-wi.x, -wi.y, wi.z);
        grey(r.dot(wo).max(0.0).powf(10.0))
    });
    gpu_matches(&eval, &smooth, "redefined smoothstep", |wi, _| {
        // The file's linear ramp, not GLSL's Hermite smoothstep.
        grey(wi.z)
    });
    gpu_matches(&eval, &globals, "non-const globals", |_, _| {
        grey(3.0 * 2.0 / PI)
    });
    gpu_matches(&eval, &shadow, "shadowing local", |wi, wo| {
        grey(wi.z / (wi.z + 0.5) * wo.z / (wo.z + 0.5))
    });
    gpu_matches(&eval, &bools, "bools (defaults)", |wi, _| [wi.z, 0.0, 0.0]);
    gpu_matches(&eval, &bools2, "bools (set)", |wi, _| grey(2.0 * wi.z));
    gpu_matches(&eval, &features, "features", |wi, wo| {
        let aniso = wi.x * wi.x + 2.0 * wo.y * wo.y;
        let v = (1.5 * wi.z * wo.z + aniso) / PI;
        [0.9 * v, 0.5 * v, 0.25 * v]
    });
    gpu_matches(&eval, &native, "native wgsl", |wi, wo| {
        let lobe = wi.dot(wo).max(0.0).powf(10.0) * 11.0 / (2.0 * PI);
        [0.8 / PI + lobe, 0.6 / PI + lobe, 0.4 / PI + lobe]
    });
    gpu_matches(&eval, &names, "names", |_, _| [0.375, 0.25, 0.125]);
    // An endless loop ends on the GPU (the guard breaks out of it) with a
    // finite value: the guard's count.
    let got = eval.eval(&looping, &f32_pairs(&pairs()[..4])).unwrap();
    for g in got {
        assert!(g.iter().all(|x| x.is_finite()), "{g:?}");
    }
}

/// The parity directions of `tests/gpu_parity.rs` in spirit: uniform pairs
/// over the upper hemisphere, grazing ones, near the mirror and retro
/// directions and on the normal.
fn parity_pairs() -> Vec<(DVec3, DVec3)> {
    let mut out = pairs();
    let d = |t: f64, p: f64| DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    for k in 0..24 {
        let t = 0.05 + 1.5 * f64::from(k) / 24.0;
        let p = 0.37 * f64::from(k);
        let wi = d(t, p);
        out.push((wi, d(t * 0.999, p + PI + 0.01))); // near the mirror
        out.push((wi, d(t * 0.98, p + 0.02))); // near the retro direction
        out.push((wi, DVec3::Z));
        out.push((DVec3::Z, wi));
        out.push((d(1.55, p), d(1.5, p + 2.0))); // grazing
    }
    out
}

#[test]
fn cpu_and_gpu_agree_on_file_models() {
    let names = [
        ("lambert.brdf", serde_json::json!({})),
        ("phong.brdf", serde_json::json!({"e": 50.0})),
        ("cooktorrance.brdf", serde_json::json!({"m": 0.2})),
        (
            "ward.brdf",
            serde_json::json!({"alpha_x": 0.1, "alpha_y": 0.3}),
        ),
        ("ggx.brdf", serde_json::json!({"alpha": 0.4})),
        ("lenient_int_literals.brdf", serde_json::json!({})),
        ("lenient_reflect.brdf", serde_json::json!({})),
        ("lenient_globals.brdf", serde_json::json!({})),
        ("lenient_shadowing.brdf", serde_json::json!({})),
        ("lenient_bools.brdf", serde_json::json!({"doubled": true})),
        ("features.brdf", serde_json::json!({})),
        ("native.brdf", serde_json::json!({})),
        ("retro.brdf", serde_json::json!({"shine": 30.0})),
        ("polyfills.brdf", serde_json::json!({})),
    ];
    let specs: Vec<(&str, ModelSpec)> = names
        .iter()
        .map(|(n, p)| (*n, spec(n, p.clone())))
        .collect();
    let Some((eval, ())) = gpu() else {
        return;
    };
    let p = parity_pairs();
    let fp = f32_pairs(&p);
    let mut worst = 0.0f64;
    for (name, s) in &specs {
        let cpu = s.build().unwrap();
        let got = eval.eval(s, &fp).unwrap();
        for ((wi, wo), g) in fp.iter().zip(&got) {
            // The CPU gets exactly the f32 directions the GPU got.
            let wi = glam::Vec3::from_array(*wi).as_dvec3();
            let wo = glam::Vec3::from_array(*wo).as_dvec3();
            let w = cpu.eval(wi, wo);
            for c in 0..3 {
                let err = (f64::from(g[c]) - w[c]).abs();
                let rel = err / w[c].abs().max(1e-3);
                worst = worst.max(rel);
                assert!(
                    err <= 1e-4 * w[c].abs() + 1e-6,
                    "{name}: GPU {g:?} against CPU {w} at wi {wi} wo {wo}"
                );
            }
        }
    }
    println!("worst CPU/GPU relative difference: {worst:.2e}");
}

/// Runs `bv eval` on JSON lines and returns the `f` of each answer.
fn bv_eval(queries: &[serde_json::Value]) -> Vec<[f64; 3]> {
    use std::io::Write as _;
    let mut child = std::process::Command::new(env!("CARGO_BIN_EXE_bv"))
        .arg("eval")
        .stdin(std::process::Stdio::piped())
        .stdout(std::process::Stdio::piped())
        .spawn()
        .unwrap();
    {
        let mut stdin = child.stdin.take().unwrap();
        for q in queries {
            writeln!(stdin, "{q}").unwrap();
        }
    }
    let out = child.wait_with_output().unwrap();
    String::from_utf8(out.stdout)
        .unwrap()
        .lines()
        .map(|l| {
            let v: serde_json::Value = serde_json::from_str(l).unwrap();
            let f = v.get("f").unwrap_or_else(|| panic!("{l}"));
            let f: Vec<f64> = serde_json::from_value(f.clone()).unwrap();
            [f[0], f[1], f[2]]
        })
        .collect()
}

#[test]
fn bv_eval_of_a_file_agrees_with_the_built_in_model() {
    // (file, its parameters, built-in model, the built-in's parameters).
    let cases = [
        (
            "lambert.brdf",
            serde_json::json!({"albedo": [0.2, 0.5, 0.8]}),
            "lambert",
            serde_json::json!({"albedo": [0.2, 0.5, 0.8]}),
        ),
        (
            "phong.brdf",
            serde_json::json!({"kd": 0.1, "ks": [0.3, 0.2, 0.1], "e": 40}),
            "phong",
            serde_json::json!({"kd": 0.1, "ks": [0.3, 0.2, 0.1], "e": 40}),
        ),
        (
            "cooktorrance.brdf",
            serde_json::json!({"kd": 0.2, "ks": 0.6, "m": 0.25, "f0": 0.1}),
            "cook-torrance",
            serde_json::json!({"kd": 0.2, "ks": 0.6, "distribution": "beckmann",
                "alpha_x": 0.25, "alpha_y": 0.25, "geometry": "v-groove",
                "fresnel": "schlick", "f0": 0.1}),
        ),
        (
            "ward.brdf",
            serde_json::json!({"kd": 0.3, "ks": 0.15, "alpha_x": 0.1, "alpha_y": 0.35}),
            "ward",
            serde_json::json!({"kd": 0.3, "ks": 0.15, "alpha_x": 0.1, "alpha_y": 0.35}),
        ),
        (
            "ggx.brdf",
            serde_json::json!({"alpha": 0.3}),
            "cook-torrance",
            serde_json::json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx",
                "alpha_x": 0.3, "alpha_y": 0.3, "geometry": "v-groove", "fresnel": "none"}),
        ),
    ];
    let dirs = pairs();
    for (file, fp, model, mp) in cases {
        let path = data(file).display().to_string();
        let mut queries = Vec::new();
        for (wi, wo) in &dirs {
            let (wi, wo) = (wi.to_array(), wo.to_array());
            queries.push(serde_json::json!({"model": path, "params": fp, "wi": wi, "wo": wo}));
            queries.push(serde_json::json!({"model": model, "params": mp, "wi": wi, "wo": wo}));
        }
        let f = bv_eval(&queries);
        assert_eq!(f.len(), queries.len(), "{file}: one answer per query");
        let mut worst = 0.0f64;
        for (k, pair) in f.chunks(2).enumerate() {
            for (&a, &b) in pair[0].iter().zip(&pair[1]) {
                let rel = (a - b).abs() / b.abs().max(1e-300);
                worst = worst.max(if b == 0.0 { a.abs() } else { rel });
                assert!(
                    (a - b).abs() <= 1e-5 * b.abs() + 1e-12,
                    "{file} against {model} at {:?}: {a} vs {b}",
                    dirs[k]
                );
            }
        }
        println!("{file} vs {model}: worst relative difference {worst:.2e}");
    }
}

#[test]
fn scene_files_name_a_file_model_by_its_path_and_every_view_draws_it() {
    use bv::session::scene_file;
    use bv::session::state::AppState;
    let s = spec("cooktorrance.brdf", serde_json::json!({"m": 0.2}));
    let mut state = AppState::default();
    let id = state.add(s.clone());
    state.selected = Some(id);
    let text = scene_file::to_toml(&state).unwrap();
    let canon = std::fs::canonicalize(data("cooktorrance.brdf")).unwrap();
    assert!(
        text.contains(&format!("model = \"{}\"", canon.display())),
        "the scene names the file: {text}"
    );
    let back = scene_file::from_toml(&text).unwrap();
    assert_eq!(back.state.brdfs[0].spec, s);

    let Some(_) = bv::gpu::context::gpu_for_test() else {
        return;
    };
    let mut off = bv::export::Offscreen::headless().unwrap();
    let frame = bv::export::Frame {
        size: eframe::egui::Vec2::new(320.0, 240.0),
        pixels_per_point: 1.0,
        dark: true,
        transparent: false,
    };
    for e in bv::views::REGISTRY.iter() {
        let img = bv::export::render_view(&mut off, &state, e, frame)
            .unwrap_or_else(|err| panic!("view {}: {err:#}", e.id));
        assert!(!bv::export::is_blank(&img), "view {} is blank", e.id);
    }
}

/// The `model` of every spec in a scene's TOML (`brdfs[i].spec` and the
/// components of a mix), in order.
fn scene_models(text: &str) -> Vec<String> {
    fn walk(v: &toml::Value, out: &mut Vec<String>) {
        match v {
            toml::Value::Table(t) => {
                if let Some(toml::Value::String(m)) = t.get("model") {
                    out.push(m.clone());
                }
                for (_, x) in t {
                    walk(x, out);
                }
            }
            toml::Value::Array(a) => a.iter().for_each(|x| walk(x, out)),
            _ => {}
        }
    }
    let v: toml::Value = toml::from_str(text).unwrap();
    let mut out = Vec::new();
    walk(&v, &mut out);
    out
}

#[test]
fn scene_files_write_file_models_relative_to_their_folder_and_read_them_from_anywhere() {
    use bv::session::scene_file;
    use bv::session::state::AppState;
    bv::session::user_models::install();
    let root = std::env::temp_dir().join(format!("bv-scene-brdf-{}", std::process::id()));
    let _ = std::fs::remove_dir_all(&root);
    let dir = root.join("scene");
    std::fs::create_dir_all(dir.join("models")).unwrap();
    std::fs::create_dir_all(root.join("elsewhere")).unwrap();
    std::fs::copy(data("phong.brdf"), dir.join("models/phong.brdf")).unwrap();
    std::fs::copy(data("lambert.brdf"), dir.join("lambert.brdf")).unwrap();
    let by_path = |p: &std::path::Path, params: serde_json::Value| {
        ModelSpec::from_json(p.to_str().unwrap(), &params).unwrap()
    };
    let phong = by_path(
        &dir.join("models/phong.brdf"),
        serde_json::json!({"kd": 0.1, "ks": [0.3, 0.2, 0.1], "e": 40}),
    );
    // A file outside the scene's folder is written by its absolute path.
    let outside = data("ggx.brdf");
    let mix = ModelSpec::from_json(
        "mix",
        &serde_json::json!({"components": [
            {"weight": 0.25, "model": dir.join("lambert.brdf").to_str().unwrap(),
             "params": {"albedo": [0.2, 0.5, 0.8]}},
            {"weight": 0.75, "model": outside.to_str().unwrap(), "params": {"alpha": 0.4}},
            {"weight": 0.5, "model": "lambert", "params": {"albedo": 0.3}},
        ]}),
    )
    .unwrap();
    let mut state = AppState::default();
    state.add(phong.clone());
    state.add(mix.clone());
    let scene = dir.join("scene.toml");
    scene_file::save(&scene, &state).unwrap();

    let text = std::fs::read_to_string(&scene).unwrap();
    let canon_outside = std::fs::canonicalize(&outside).unwrap();
    assert_eq!(
        scene_models(&text),
        [
            "models/phong.brdf".to_string(),
            "mix".into(),
            "lambert.brdf".into(),
            canon_outside.display().to_string(),
            "lambert".into(),
        ],
        "{text}"
    );

    // In this process: loading resolves against the scene's folder, and the
    // specs evaluate as the originals.
    let back = scene_file::load(&scene).unwrap();
    let pairs = pairs();
    for (got, want) in back.state.brdfs.iter().zip([&phong, &mix]) {
        let (g, w) = (got.spec.build().unwrap(), want.build().unwrap());
        for &(wi, wo) in &pairs {
            assert_eq!(g.eval(wi, wo), w.eval(wi, wo), "{}", want.id());
        }
    }

    // Another process in another folder: `bv scene print` reads the scene
    // (every model found from its folder, not the current directory) and
    // writes it back as it would save it there, with the same values.
    let out = std::process::Command::new(env!("CARGO_BIN_EXE_bv"))
        .args(["scene", "print", "../scene/scene.toml"])
        .current_dir(root.join("elsewhere"))
        .output()
        .unwrap();
    assert!(
        out.status.success(),
        "{}",
        String::from_utf8_lossy(&out.stderr)
    );
    let printed = String::from_utf8(out.stdout).unwrap();
    assert_eq!(scene_models(&printed), scene_models(&text), "{printed}");
    let params = |t: &str| -> Vec<toml::Value> {
        let v: toml::Value = toml::from_str(t).unwrap();
        v["brdfs"]
            .as_array()
            .unwrap()
            .iter()
            .map(|b| b["spec"]["params"].clone())
            .collect()
    };
    assert_eq!(params(&printed), params(&text));
    let _ = std::fs::remove_dir_all(&root);
}

#[test]
fn the_sampling_views_verdict_passes_a_files_correct_isfunc_and_fails_a_wrong_one() {
    use bv::derive::sampling::{SIGNIFICANCE, options, verdict};
    use bv_core::analysis::sample_histogram::sample_histogram;
    let wi = DVec3::new(0.4, 0.2, 0.8).normalize();
    for (name, params) in [
        ("isfunc_lobe.brdf", serde_json::json!({"n": 12})),
        ("isfunc_mirror.brdf", serde_json::json!({"e": 30})),
    ] {
        let b = spec(name, params).build().unwrap();
        let h = sample_histogram(b.as_ref(), wi, &options()).unwrap();
        assert!(h.chi2.p_value >= SIGNIFICANCE, "{name}: {}", verdict(&h));
    }
    // The mirror lobe at a grazing angle: many draws fall below the horizon,
    // and the density accounts for them.
    let grazing = DVec3::new(0.95, 0.0, 0.312).normalize();
    let b = spec("isfunc_mirror.brdf", serde_json::json!({"e": 5}))
        .build()
        .unwrap();
    let h = sample_histogram(b.as_ref(), grazing, &options()).unwrap();
    assert!(h.failed > 1000, "{}", h.failed);
    assert!(h.chi2.p_value >= SIGNIFICANCE, "{}", verdict(&h));

    let wrong = spec("isfunc_wrong_pdf.brdf", serde_json::json!({"n": 12}))
        .build()
        .unwrap();
    let h = sample_histogram(wrong.as_ref(), wi, &options()).unwrap();
    assert!(h.chi2.p_value < 1e-6, "{}", verdict(&h));
    assert!(verdict(&h).contains("FAILED"));
}
