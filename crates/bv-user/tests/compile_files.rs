//! Every test file of `tests/data/brdf/` through the front end, the GPU port
//! and the CPU evaluator: the good ones compile (every format feature and
//! leniency) and evaluate to their closed forms on the CPU; the broken and
//! hostile ones are refused with a clear message and, where there is one,
//! their place in the file.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_core::{Brdf, ModelSpec};
use glam::DVec3;
use std::path::PathBuf;

fn data(name: &str) -> PathBuf {
    PathBuf::from(env!("CARGO_MANIFEST_DIR"))
        .join("../../tests/data/brdf")
        .join(name)
}

fn compile(name: &str) -> bv_user::Result<bv_user::Compiled> {
    let text = std::fs::read_to_string(data(name)).unwrap();
    bv_user::compile(&text, name)
}

fn error(name: &str) -> bv_user::UserError {
    match compile(name) {
        Ok(_) => panic!("{name} compiled"),
        Err(e) => e,
    }
}

fn built(name: &str, params: serde_json::Value) -> Box<dyn Brdf> {
    let info = bv_user::load(&data(name)).unwrap();
    ModelSpec::from_json(info.id, &params)
        .unwrap()
        .build()
        .unwrap()
}

const GOOD: &[&str] = &[
    "lambert.brdf",
    "phong.brdf",
    "cooktorrance.brdf",
    "ward.brdf",
    "ggx.brdf",
    "lenient_int_literals.brdf",
    "lenient_reflect.brdf",
    "lenient_smoothstep.brdf",
    "lenient_globals.brdf",
    "lenient_shadowing.brdf",
    "lenient_bools.brdf",
    "features.brdf",
    "native.brdf",
    "retro.brdf",
    "polyfills.brdf",
    "hostile_loop.brdf",
];

#[test]
fn the_good_files_compile_with_their_declarations() {
    for name in GOOD {
        let c = compile(name).unwrap_or_else(|e| panic!("{name}: {e}"));
        assert!(c.wgsl.contains("fn bvxbrdf("), "{name}");
    }
    let f = compile("features.brdf").unwrap();
    let ids: Vec<&str> = f.decls.iter().map(|d| d.id).collect();
    assert_eq!(ids, ["gain", "useTint", "tint"]);
    assert_eq!(f.decls[0].doc, "a float with a tooltip");
    assert!(matches!(
        f.decls[1].kind,
        bv_core::ParamKind::Bool { default: true }
    ));
    assert!(f.file.is_func.is_some(), "the isFunc section is kept");
}

/// A broken file, a part of its message, and its line and column if placed.
type Case = (&'static str, &'static str, Option<(usize, usize)>);

#[test]
fn broken_files_are_refused_at_their_place() {
    let cases: &[Case] = &[
        // `    float x = a * ;`: the `;` of file line 8.
        ("broken_syntax.brdf", "Semicolon", Some((8, 19))),
        ("broken_type.brdf", "undefined_thing", Some((6, 17))),
        ("broken_no_brdf.brdf", "defines no `vec3 BRDF(", None),
        ("broken_signature.brdf", "five vec3 arguments", None),
        (
            "broken_kind.brdf",
            "unknown parameter kind `int`",
            Some((3, 1)),
        ),
        ("broken_range.brdf", "MIN 2 is above MAX 1", Some((3, 1))),
        ("broken_wgsl.brdf", "expected expression", Some((4, 24))),
        ("hostile_array.brdf", "an array of 16000000 bytes", None),
        (
            "hostile_recursion.brdf",
            "Unknown function 'f'",
            Some((4, 46)),
        ),
    ];
    for (name, want, place) in cases {
        let e = error(name);
        let text = e.to_string();
        assert!(text.contains(want), "{name}: {text}");
        assert!(
            text.starts_with(name),
            "{name}: the message names the file: {text}"
        );
        match place {
            Some((line, column)) => {
                let p = e
                    .place()
                    .unwrap_or_else(|| panic!("{name}: no place in {text}"));
                assert_eq!((p.line, p.column), (*line, *column), "{name}: {text}");
                assert!(
                    text.starts_with(&format!("{name}:{line}:{column}: ")),
                    "{text}"
                );
            }
            None => assert!(e.place().is_none(), "{name}: {text}"),
        }
    }
}

#[test]
fn a_huge_shader_is_refused_before_it_is_read_whole() {
    let dir = std::env::temp_dir().join(format!("bv-user-huge-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("huge.brdf");
    let mut text = String::from("analytic\n::begin shader\n");
    while text.len() < 10 << 20 {
        text.push_str("// padding padding padding padding padding padding padding\n");
    }
    text.push_str(
        "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(1); }\n::end shader\n",
    );
    std::fs::write(&path, &text).unwrap();
    let e = bv_user::load(&path).unwrap_err().to_string();
    assert!(e.contains("huge.brdf"), "{e}");
    assert!(e.contains("over the 1 MiB limit"), "{e}");
    assert_eq!(e.matches("huge.brdf").count(), 1, "{e}");
    // The same text handed over directly is refused by the container parser.
    assert!(bv_user::compile(&text, "huge.brdf").is_err());
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn an_endless_loop_is_a_build_error_on_the_cpu() {
    let info = bv_user::load(&data("hostile_loop.brdf")).unwrap();
    let t0 = std::time::Instant::now();
    let e = ModelSpec::new(info.id)
        .unwrap()
        .build()
        .unwrap_err()
        .to_string();
    assert!(e.contains("hostile_loop.brdf"), "{e}");
    assert!(e.contains("step"), "{e}");
    assert!(t0.elapsed().as_secs() < 10, "{:?}", t0.elapsed());
}

/// A few direction pairs above the horizon.
fn pairs() -> Vec<(DVec3, DVec3)> {
    let mut out = Vec::new();
    for (ti, pi) in [(0.2, 0.0), (0.7, 1.0), (1.2, 2.5)] {
        for (to, po) in [(0.1, 3.0), (0.9, 4.0), (1.4, 0.5)] {
            let d = |t: f64, p: f64| DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            out.push((d(ti, pi), d(to, po)));
        }
    }
    out
}

fn close(got: DVec3, want: [f64; 3], what: &str) {
    for c in 0..3 {
        let tol = 1e-6 * want[c].abs() + 1e-12;
        assert!(
            (got[c] - want[c]).abs() <= tol,
            "{what}: {got} against {want:?}"
        );
    }
}

#[test]
fn the_cpu_evaluates_the_leniencies_as_their_closed_forms() {
    let ints = built("lenient_int_literals.brdf", serde_json::json!({"f0": 0.25}));
    let reflect = built("lenient_reflect.brdf", serde_json::json!({"n": 10.0}));
    let smooth = built("lenient_smoothstep.brdf", serde_json::json!({}));
    let globals = built("lenient_globals.brdf", serde_json::json!({"k": 3.0}));
    let shadow = built("lenient_shadowing.brdf", serde_json::json!({"m": 0.5}));
    let bools = built("lenient_bools.brdf", serde_json::json!({"doubled": true}));
    let native = built("native.brdf", serde_json::json!({"shine": 20.0}));
    for (wi, wo) in pairs() {
        let u = wi.z;
        close(
            ints.eval(wi, wo),
            [0.25 + 0.75 * (1.0 - u).powi(5), 1.0 - u, wo.z / 2.0],
            "int literals",
        );
        let r = DVec3::new(-wi.x, -wi.y, wi.z);
        let x = r.dot(wo).max(0.0).powf(10.0);
        close(reflect.eval(wi, wo), [x; 3], "reflect");
        close(smooth.eval(wi, wo), [wi.z; 3], "smoothstep");
        // The file's PI is the f32 nearest π (naga keeps GLSL's float type).
        let pi32 = f64::from(std::f32::consts::PI);
        close(globals.eval(wi, wo), [6.0 / pi32; 3], "globals");
        let g = wi.z / (wi.z + 0.5) * wo.z / (wo.z + 0.5);
        close(shadow.eval(wi, wo), [g; 3], "shadowing");
        close(bools.eval(wi, wo), [2.0 * wi.z, 0.0, 0.0], "bools");
        let lobe = wi.dot(wo).max(0.0).powf(20.0) * 21.0 / (2.0 * pi32);
        close(
            native.eval(wi, wo),
            [0.8 / pi32 + lobe, 0.6 / pi32 + lobe, 0.4 / pi32 + lobe],
            "native",
        );
        // Below the horizon: 0, as the built-in models.
        assert_eq!(ints.eval(wi, DVec3::new(wo.x, wo.y, -wo.z)), DVec3::ZERO);
    }
}

#[test]
fn claims_are_what_a_probe_observes() {
    let c = |name: &str, p: serde_json::Value| built(name, p).claims();
    let lambert = c("lambert.brdf", serde_json::json!({}));
    assert!(lambert.reciprocal && lambert.isotropic && !lambert.energy_conserving);
    // Phong's 1/cos θi breaks reciprocity.
    assert!(!c("phong.brdf", serde_json::json!({})).reciprocal);
    let ward = c(
        "ward.brdf",
        serde_json::json!({"alpha_x": 0.1, "alpha_y": 0.4}),
    );
    assert!(ward.reciprocal && !ward.isotropic);
}

fn sampler_of(name: &str) -> bv_user::sampler::Sampler {
    compile(name)
        .unwrap_or_else(|e| panic!("{name}: {e}"))
        .sampler
}

#[test]
fn an_isfunc_section_is_the_models_sampler_when_it_states_its_density() {
    use bv_user::sampler::Sampler;
    assert!(matches!(sampler_of("lambert.brdf"), Sampler::None));
    assert!(matches!(sampler_of("isfunc_lobe.brdf"), Sampler::Ready(_)));
    assert!(matches!(
        sampler_of("isfunc_mirror.brdf"),
        Sampler::Ready(_)
    ));
    // Without pdfBRDF, or without sampleBRDF at all, bv says why it keeps
    // its default sampler.
    for name in ["isfunc_no_pdf.brdf", "features.brdf"] {
        match sampler_of(name) {
            Sampler::Unused(why) => assert!(why.contains("isFunc"), "{name}: {why}"),
            other => panic!("{name}: {other:?}"),
        }
    }
    let info = bv_user::load(&data("isfunc_no_pdf.brdf")).unwrap();
    assert!(info.summary.contains("default sampler"), "{}", info.summary);
    let info = bv_user::load(&data("isfunc_lobe.brdf")).unwrap();
    assert!(info.summary.contains("isFunc"), "{}", info.summary);

    // The file's draws and density against the closed form written here:
    // cos θ = u^(1/(n+1)), φ = 2π v, pdf = (n+1)/(2π) cos^n θ.
    let n = 7.0;
    let b = built("isfunc_lobe.brdf", serde_json::json!({"n": n}));
    let v = DVec3::new(0.3, -0.2, 0.9).normalize();
    for (ux, uy) in [(0.1, 0.2), (0.5, 0.5), (0.93, 0.71), (0.02, 0.99)] {
        let w = b.sample(v, glam::DVec2::new(ux, uy)).unwrap();
        let c = f64::powf(ux, 1.0 / (n + 1.0));
        let s = (1.0 - c * c).sqrt();
        let phi = 2.0 * std::f64::consts::PI * uy;
        let want = DVec3::new(s * phi.cos(), s * phi.sin(), c);
        // The section's arithmetic is f64 but its literals are f32 (π).
        assert!((w - want).length() < 1e-6, "{w} vs {want}");
        let pdf = (n + 1.0) / (2.0 * std::f64::consts::PI) * c.powf(n);
        assert!((b.pdf(v, w) / pdf - 1.0).abs() < 1e-6);
    }
    assert_eq!(b.pdf(v, DVec3::new(0.0, 0.6, -0.8)), 0.0);

    // Without a usable sampler: bv's cosine sampler and its density.
    let d = built("isfunc_no_pdf.brdf", serde_json::json!({}));
    let u = glam::DVec2::new(0.3, 0.6);
    assert_eq!(
        d.sample(v, u),
        Some(bv_core::sampling::cosine_hemisphere(u))
    );
    let w = DVec3::new(0.1, 0.2, 0.9).normalize();
    assert_eq!(d.pdf(v, w), bv_core::sampling::cosine_hemisphere_pdf(w));
}

#[test]
fn a_broken_isfunc_section_is_refused_at_its_place() {
    let e = error("broken_isfunc.brdf");
    let text = e.to_string();
    assert!(text.contains("undefined_thing"), "{text}");
    let p = e.place().unwrap_or_else(|| panic!("no place in {text}"));
    // `    wi = N * undefined_thing;` is file line 11.
    assert_eq!((p.line, p.column), (11, 14), "{text}");
}

/// `inverse` and `determinant` of every size, which the GPU port gets from
/// naga's own WGSL functions, are exact on the CPU: each matrix times its
/// inverse gives the vector back.
#[test]
fn matrix_polyfills_evaluate_to_their_closed_form() {
    let b = built("polyfills.brdf", serde_json::json!({"k": 0.5}));
    let wi = DVec3::new(0.3, -0.2, 0.9).normalize();
    let wo = DVec3::new(-0.5, 0.4, 0.7).normalize();
    let f = b.eval(wi, wo);
    let want = 0.5 * DVec3::new(2.0 + wi.dot(wo), 2.0 + wi.x, 2.0 + wo.z);
    assert!((f - want).abs().max_element() < 1e-9, "{f} vs {want}");
}
