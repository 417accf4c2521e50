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
    // An endless loop ends on the GPU (the guard breaks out of it) with a
    // finite value: the guard's count.
    let got = eval.eval(&looping, &f32_pairs(&pairs()[..4])).unwrap();
    for g in got {
        assert!(g.iter().all(|x| x.is_finite()), "{g:?}");
    }
}
