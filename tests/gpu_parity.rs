//! Parity of the WGSL ports with bv-core, on whatever
//! adapter wgpu finds (lavapipe in CI).
//!
//! Every model of the catalogue is evaluated by the `parity` compute shader on
//! 4,160 direction pairs (uniform, grazing down to cosθ = 1e-6, near the mirror
//! and retro directions, on the normal, below the horizon) for its default,
//! minimum, maximum and mid-range parameter sets, plus one set per option of
//! every choice parameter, and compared with bv-core's f64 `eval` on the same
//! inputs. The test fails when any channel of any pair is off by more than
//! `1e-4 + 1e-3 |f|` (absolute + relative), and prints the worst case per model
//! (`cargo test --test suite gpu_parity:: -- --nocapture`).
//!
//! Inputs: each direction is the f32 vector nearest to unit length near the rounded
//! f64 unit vector (| |w|² − 1 | ~1e-9 instead of ~1e-7), and bv-core gets exactly those f32 values. An f32 cannot hold a unit
//! vector exactly; at an exponent of 10000 a 1e-7 error in `R(wo)·wi` alone
//! moves `(R(wo)·wi)^e` by 1e-3 relative, which would measure the input
//! rounding rather than the port.
//!
//! Handled explicitly: `mix` is evaluated through its flattened component table
//! (a rich mix of every other model is tested besides the declared sets);
//! delta models (`mirror`, `glass`) are 0 at every finite pair on both sides,
//! which the comparison checks like any other value; `merl` reads files, so
//! it has its own test ([`merl_port_matches_bv_core`]) on small tables
//! written for it.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

// The suite's one copy of tests/support/rgl_files.rs.
use super::rgl_files;

use bv::gpu::{GpuEvaluator, gpu_for_test, shaders::ShaderLibrary};
use bv_core::measured::merl;
use bv_core::params::{ParamDecl, ParamKind, ParamValue, Params};
use bv_core::sampling::{rng, uniform2};
use bv_core::{ModelSpec, catalogue, frame};
use glam::DVec3;
use std::f64::consts::PI;

const ABS_TOL: f64 = 1e-4;
const REL_TOL: f64 = 1e-3;

/// Models without a port yet, with the reason.
const NOT_PORTED: &[(&str, &str)] = &[];

/// Models tested by their own test below (they need files).
const OWN_TEST: &[(&str, &str)] = &[
    ("merl", "see merl_port_matches_bv_core"),
    ("rgl", "see rgl_port_matches_bv_core"),
];

/// The f32 vector closest to unit length near `w` rounded: two components
/// move by up to ±2 ulps and the third is re-solved from |w|² = 1 (taking the
/// nearest f32 and its neighbours), accepted when it keeps its sign and moves by
/// less than 1e-5 and 1 % of itself (so grazing cosines stay what they were);
/// the best of the three choices of solved component.
fn unit_f32(w: DVec3) -> [f32; 3] {
    let r = [w.x as f32, w.y as f32, w.z as f32];
    let step = |x: f32, k: i32| -> f32 {
        let mut y = x;
        for _ in 0..k.abs() {
            y = if k > 0 { y.next_up() } else { y.next_down() };
        }
        y
    };
    let norm_err = |v: &[f32; 3]| -> f64 {
        let l2: f64 = v.iter().map(|&x| f64::from(x) * f64::from(x)).sum();
        (l2 - 1.0).abs()
    };
    let mut best = r;
    let mut best_err = norm_err(&r);
    for s in 0..3 {
        let (p, q) = ((s + 1) % 3, (s + 2) % 3);
        let limit = (0.01 * r[s].abs()).min(1e-5);
        for a in -2..=2 {
            for b in -2..=2 {
                let mut v = r;
                v[p] = step(r[p], a);
                v[q] = step(r[q], b);
                let rest = 1.0 - f64::from(v[p]).powi(2) - f64::from(v[q]).powi(2);
                if rest < 0.0 {
                    continue;
                }
                let solved = (rest.sqrt() as f32).copysign(r[s]);
                for k in -1..=1 {
                    v[s] = step(solved, k);
                    let same_sign = (v[s] > 0.0) == (r[s] > 0.0) && (v[s] < 0.0) == (r[s] < 0.0);
                    if !same_sign || (v[s] - r[s]).abs() > limit {
                        continue;
                    }
                    let err = norm_err(&v);
                    if err < best_err {
                        best_err = err;
                        best = v;
                    }
                }
            }
        }
    }
    best
}

fn to_d(v: [f32; 3]) -> DVec3 {
    DVec3::new(v[0].into(), v[1].into(), v[2].into())
}

/// Uniform direction on the upper hemisphere with cosθ ∈ [z0, z1].
fn dir(u: glam::DVec2, z0: f64, z1: f64) -> DVec3 {
    let z = z0 + (z1 - z0) * u.x;
    let r = (1.0 - z * z).max(0.0).sqrt();
    let phi = 2.0 * PI * u.y;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// A direction with log-uniform cosθ in [1e-6, 1e-2] (grazing).
fn grazing(u: glam::DVec2) -> DVec3 {
    let z = 10f64.powf(-6.0 + 4.0 * u.x);
    let r = (1.0 - z * z).sqrt();
    let phi = 2.0 * PI * u.y;
    DVec3::new(r * phi.cos(), r * phi.sin(), z)
}

/// `w` turned by angle `a` about a random axis orthogonal to it.
fn perturb(w: DVec3, a: f64, phi: f64) -> DVec3 {
    let (t, b) = bv_core::sampling::basis(w);
    let axis = t * phi.cos() + b * phi.sin();
    (w * a.cos() + axis * a.sin()).normalize()
}

fn pairs() -> Vec<([f32; 3], [f32; 3])> {
    let mut g = rng(0x5eed_9a71);
    let mut out = Vec::new();
    let mut push = |wi: DVec3, wo: DVec3| out.push((unit_f32(wi), unit_f32(wo)));
    for _ in 0..3072 {
        push(
            dir(uniform2(&mut g), 0.0, 1.0),
            dir(uniform2(&mut g), 0.0, 1.0),
        );
    }
    for k in 0..512 {
        let a = grazing(uniform2(&mut g));
        let b = if k % 2 == 0 {
            grazing(uniform2(&mut g))
        } else {
            dir(uniform2(&mut g), 0.0, 1.0)
        };
        if k % 4 < 2 { push(a, b) } else { push(b, a) }
    }
    for k in 0..256 {
        // Near the mirror direction: the peaks of the glossy lobes.
        let wi = dir(uniform2(&mut g), 0.0, 1.0);
        let u = uniform2(&mut g);
        let wo = perturb(
            frame::reflect(wi),
            10f64.powf(-4.0 + 3.0 * u.x),
            2.0 * PI * u.y,
        );
        if wo.z > 0.0 {
            if k % 2 == 0 {
                push(wi, wo)
            } else {
                push(wo, wi)
            }
        } else {
            push(wi, frame::reflect(wi));
        }
    }
    for _ in 0..128 {
        // Near retro-reflection (Hapke's opposition surge, Oren-Nayar).
        let wi = dir(uniform2(&mut g), 0.0, 1.0);
        let u = uniform2(&mut g);
        let wo = perturb(wi, 10f64.powf(-4.0 + 3.0 * u.x), 2.0 * PI * u.y);
        push(wi, if wo.z > 0.0 { wo } else { wi });
    }
    for k in 0..128 {
        // The normal itself, exact mirror pairs, exact retro pairs.
        let w = dir(uniform2(&mut g), 0.0, 1.0);
        match k % 4 {
            0 => push(DVec3::Z, w),
            1 => push(w, DVec3::Z),
            2 => push(w, frame::reflect(w)),
            _ => push(w, w),
        }
    }
    for k in 0..64 {
        // Below the horizon: reflection models give 0.
        let a = dir(uniform2(&mut g), 0.0, 1.0);
        let b = -dir(uniform2(&mut g), 0.0, 1.0);
        if k % 2 == 0 { push(a, b) } else { push(b, a) }
    }
    out
}

/// For a transmitting model, `pairs` and as many again on the whole sphere:
/// light from either side, viewers on either side, and viewers near the
/// peaks the model names (its refracted direction) and near the mirror
/// direction on the light's side, by 1e-4 to 0.1 rad.
fn sphere_pairs(
    b: &dyn bv_core::Brdf,
    pairs: &[([f32; 3], [f32; 3])],
) -> Vec<([f32; 3], [f32; 3])> {
    let mut g = rng(0x5eed_7a45);
    let mut out = pairs.to_vec();
    let mut push = |wi: DVec3, wo: DVec3| out.push((unit_f32(wi), unit_f32(wo)));
    let flip = |w: DVec3| DVec3::new(w.x, w.y, -w.z);
    for k in 0..2048 {
        let mut wi = dir(uniform2(&mut g), 0.0, 1.0);
        let mut wo = dir(uniform2(&mut g), 0.0, 1.0);
        if k % 2 == 0 {
            wi = flip(wi);
        }
        if k % 4 < 2 {
            wo = flip(wo);
        }
        push(wi, wo);
        let u = uniform2(&mut g);
        let a = 10f64.powf(-4.0 + 3.0 * u.x);
        for p in b.peaks(wi) {
            push(wi, perturb(p, a, 2.0 * PI * u.y));
        }
        push(
            wi,
            perturb(DVec3::new(-wi.x, -wi.y, wi.z), a, 2.0 * PI * u.y),
        );
    }
    out
}

#[derive(Clone, Copy, Debug)]
enum Level {
    Min,
    Mid,
    Max,
}

fn level_value(d: &ParamDecl, level: Level) -> ParamValue {
    match d.kind {
        ParamKind::Float(s) => ParamValue::Float(match level {
            Level::Min => s.min,
            Level::Max => s.max,
            Level::Mid if s.log && s.slider_min > 0.0 => (s.slider_min * s.slider_max).sqrt(),
            Level::Mid => 0.5 * (s.min + s.max),
        }),
        ParamKind::Color(s) => ParamValue::Color(match level {
            Level::Min => [s.min; 3],
            Level::Max => [s.max; 3],
            // Distinct channels, so that a swapped channel shows.
            Level::Mid => [0.25, 0.5, 0.75].map(|t| s.min + t * (s.max - s.min)),
        }),
        ParamKind::Choice { options, .. } => ParamValue::Text(
            match level {
                Level::Min => options[0],
                Level::Mid => options[options.len() / 2],
                Level::Max => options[options.len() - 1],
            }
            .to_string(),
        ),
        ParamKind::Bool { default } => ParamValue::Bool(match level {
            Level::Min => false,
            Level::Max => true,
            Level::Mid => default,
        }),
        ParamKind::List {
            fields,
            min_items,
            max_items,
            default_items,
        } => {
            let n = match level {
                Level::Min => min_items.max(1),
                Level::Mid => default_items.max(1),
                Level::Max => max_items,
            };
            let mut item = Params::default();
            for f in fields {
                item.set_unvalidated(f.id, level_value(f, level));
            }
            ParamValue::List(vec![item; n])
        }
        ParamKind::Path { .. } => d.default_value(),
        ParamKind::Components { weight, .. } => {
            let w = match level {
                Level::Min => weight.min,
                Level::Mid => 0.5 * (weight.min + weight.max),
                Level::Max => weight.max,
            };
            match d.default_value() {
                ParamValue::Components(mut cs) => {
                    for c in &mut cs {
                        c.weight = w;
                    }
                    ParamValue::Components(cs)
                }
                other => other,
            }
        }
    }
}

/// The named parameter sets of one model.
fn param_sets(model: &str) -> Vec<(String, ModelSpec)> {
    let base = ModelSpec::new(model).unwrap();
    let decls = bv_core::find(model).unwrap().params;
    let mut sets = vec![("default".to_string(), base.clone())];
    for (name, level) in [
        ("min", Level::Min),
        ("max", Level::Max),
        ("mid", Level::Mid),
    ] {
        let mut s = base.clone();
        for d in decls {
            s.set(d.id, level_value(d, level))
                .unwrap_or_else(|e| panic!("{model} {name}: {e}"));
        }
        sets.push((name.to_string(), s));
    }
    for d in decls {
        if let ParamKind::Choice { options, .. } = d.kind {
            for o in options {
                let mut s = base.clone();
                s.set(d.id, ParamValue::Text(o.to_string()))
                    .unwrap_or_else(|e| panic!("{model} {}={o}: {e}", d.id));
                sets.push((format!("{}={o}", d.id), s));
            }
        }
    }
    if model == "cook-torrance" {
        // Kulla–Conty's anisotropic table: the azimuthal harmonics the port
        // reads from the table buffer.
        for dist in ["ggx", "beckmann"] {
            let p = serde_json::json!({"kd": 0.1, "ks": 0.8, "distribution": dist,
                "geometry": "smith-correlated", "alpha_x": 0.8, "alpha_y": 0.2,
                "fresnel": "conductor", "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14],
                "multiscatter": "kulla-conty"});
            sets.push((
                format!("kulla-conty {dist} 0.8/0.2"),
                ModelSpec::from_json(model, &p).unwrap(),
            ));
        }
    }
    if model == "mix" {
        // Every other ported model as a component, one nested mix included.
        let comps: Vec<serde_json::Value> = catalogue()
            .iter()
            .filter(|m| {
                m.id != "mix"
                    && !NOT_PORTED.iter().any(|(id, _)| *id == m.id)
                    && !OWN_TEST.iter().any(|(id, _)| *id == m.id)
            })
            .enumerate()
            .map(|(i, m)| serde_json::json!({"weight": 0.2 + 0.1 * i as f64, "model": m.id}))
            .take(7)
            .collect();
        let nested = serde_json::json!({"weight": 1.5, "model": "mix", "params": {"components": [
            {"weight": 0.5, "model": "lambert", "params": {"albedo": [0.9, 0.1, 0.4]}},
            {"weight": 2.0, "model": "modified-phong", "params": {"e": 300.0}}
        ]}});
        let mut all = comps;
        all.push(nested);
        let spec = ModelSpec::from_json("mix", &serde_json::json!({ "components": all })).unwrap();
        sets.push(("all-models".to_string(), spec));
    }
    sets
}

struct Worst {
    ratio: f64,
    what: String,
}

#[test]
fn wgsl_ports_match_bv_core() {
    let Some(gpu) = gpu_for_test() else { return };
    let mut lib = ShaderLibrary::new().unwrap();
    println!("adapter: {}", gpu.describe());
    let eval = GpuEvaluator::new(gpu, &mut lib).unwrap();
    let pairs = pairs();
    assert!(pairs.len() >= 4096);
    let mut failures = Vec::new();
    println!(
        "{:<18} {:>5} {:>12}  worst case (tolerance {ABS_TOL:e} + {REL_TOL:e}·|f|)",
        "model", "sets", "|Δ|/tol"
    );
    for m in catalogue().iter() {
        if let Some((_, why)) = NOT_PORTED.iter().find(|(id, _)| *id == m.id) {
            println!("{:<18} not ported: {why}", m.id);
            continue;
        }
        if let Some((_, why)) = OWN_TEST.iter().find(|(id, _)| *id == m.id) {
            println!("{:<18} {why}", m.id);
            continue;
        }
        let mut worst = Worst {
            ratio: 0.0,
            what: String::new(),
        };
        let sets = param_sets(m.id);
        let mut tested = 0;
        for (set, spec) in &sets {
            let cpu = match spec.build() {
                Ok(b) => b,
                Err(e) if set != "default" => {
                    println!("{:<18} set {set} refused by bv-core ({e}); skipped", m.id);
                    continue;
                }
                Err(e) => panic!("{}: default set does not build: {e}", m.id),
            };
            tested += 1;
            let set_pairs = if cpu.transmits() {
                sphere_pairs(cpu.as_ref(), &pairs)
            } else {
                pairs.clone()
            };
            let gpu_values = eval.eval(spec, &set_pairs).unwrap();
            for ((wi, wo), g) in set_pairs.iter().zip(&gpu_values) {
                let c = cpu.eval(to_d(*wi), to_d(*wo));
                for k in 0..3 {
                    let (gk, ck) = (f64::from(g[k]), c[k]);
                    let ratio = if gk.is_finite() {
                        (gk - ck).abs() / (ABS_TOL + REL_TOL * ck.abs())
                    } else {
                        f64::INFINITY
                    };
                    if ratio > worst.ratio || (ratio.is_nan() && !worst.ratio.is_nan()) {
                        worst = Worst {
                            ratio,
                            what: format!(
                                "set {set}, wi {wi:?}, wo {wo:?}, channel {k}: gpu {gk:e}, bv-core {ck:e}"
                            ),
                        };
                    }
                }
            }
        }
        println!(
            "{:<18} {tested:>5} {:>12.4}  {}",
            m.id, worst.ratio, worst.what
        );
        if worst.ratio.is_nan() || worst.ratio > 1.0 {
            failures.push(format!("{}: {}", m.id, worst.what));
        }
    }
    assert!(
        failures.is_empty(),
        "WGSL ports disagree with bv-core:\n{}",
        failures.join("\n")
    );
}

/// The table cells a nearest lookup at `(wi, wo)` may pick: the cell bv-core
/// picks, plus its neighbour along any axis where the pair lies within
/// `1e-3` of a cell of a cell boundary (the φd seam included). A nearest
/// lookup jumps at a boundary, and there an f32 angle and an f64 angle of the
/// same f32 inputs may fall on either side: both answers are right.
fn nearest_candidates(wi: DVec3, wo: DVec3, dims: merl::MerlDims) -> Vec<(usize, usize, usize)> {
    const EDGE: f64 = 1e-3;
    let Some((th, td, pd)) = merl::half_diff_angles(wi, wo) else {
        return Vec::new();
    };
    let clamped = |u: f64, n: usize, i: usize| {
        let mut c = vec![i];
        let f = u - u.floor();
        if u > EDGE && f < EDGE && i > 0 {
            c.push(i - 1);
        }
        if f > 1.0 - EDGE && i + 1 < n {
            c.push(i + 1);
        }
        c
    };
    let hs = clamped(
        merl::theta_h_coord(th, dims.theta_h),
        dims.theta_h,
        merl::theta_h_index(th, dims.theta_h),
    );
    let ds = clamped(
        merl::theta_d_coord(td, dims.theta_d),
        dims.theta_d,
        merl::theta_d_index(td, dims.theta_d),
    );
    let n = dims.phi_d;
    let u = merl::fold_phi_d(pd) / PI * n as f64;
    let base = (u.floor().max(0.0) as usize).min(n - 1);
    let mut ps = vec![merl::phi_d_index(pd, n), base];
    let f = u - u.floor();
    if f < EDGE {
        ps.push((base + n - 1) % n);
    }
    if f > 1.0 - EDGE {
        ps.push((base + 1) % n);
    }
    if u < EDGE || u > n as f64 - EDGE {
        ps.extend([0, n - 1]);
    }
    let mut out = Vec::new();
    for &h in &hs {
        for &d in &ds {
            for &p in &ps {
                out.push((h, d, p));
            }
        }
    }
    out
}

/// The WGSL port of `merl` (half/difference angles, index mapping with the
/// φd seam rule, nearest and trilinear lookups, table offsets in the shared
/// table buffer) against bv-core's lookup on the same f32 inputs, with the
/// same tolerance as the other models. Tables: a Cook-Torrance lobe tabulated
/// at 12×10×24 (smooth, physically isotropic), pseudo-random values (1 ± 5 %) at 7×9×16
/// (any index slip shows) and at the public 90×90×180 (large offsets), and a
/// mix of them so that one buffer holds several tables.
///
/// Where φd is ill-conditioned (θh or θd within 0.01 rad of 0: exact mirror
/// and retro pairs and their neighbours) the φd of either side is set by
/// rounding noise, so any φd is a right answer: the GPU value must then lie
/// within the range of bv-core's values over all φd at the same θh and θd
/// (± the tolerance). Their count is printed.
#[test]
fn merl_port_matches_bv_core() {
    let Some(gpu) = gpu_for_test() else { return };
    let mut lib = ShaderLibrary::new().unwrap();
    let eval = GpuEvaluator::new(gpu, &mut lib).unwrap();
    let dir = std::env::temp_dir().join(format!("bv-gpu-merl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();

    let ct = ModelSpec::from_json(
        "cook-torrance",
        &serde_json::json!({"kd": [0.1, 0.2, 0.3], "ks": 0.8, "distribution": "ggx", "alpha": 0.3}),
    )
    .unwrap()
    .build()
    .unwrap();
    let smooth = merl::tabulate(ct.as_ref(), merl::MerlDims::new(12, 10, 24).unwrap()).unwrap();
    let noise = |dims: merl::MerlDims, seed: u64| {
        let mut g = rng(seed);
        let v: Vec<f32> = (0..3 * dims.cells())
            // 1 ± 0.05 per cell: any index slip moves the value by ~50
            // tolerances, while the step between neighbours stays small enough
            // that the GPU's f32 angles (Vulkan allows a loose atan2) cannot
            // move a trilinear value by a tolerance.
            .map(|_| (0.95 + 0.1 * uniform2(&mut g).x) as f32)
            .collect();
        merl::MerlTable::from_values(dims, v).unwrap()
    };
    let tables = [
        ("smooth", smooth),
        ("random", noise(merl::MerlDims::new(7, 9, 16).unwrap(), 7)),
        ("public", noise(merl::STANDARD_DIMS, 11)),
    ];
    let mut paths = Vec::new();
    for (name, t) in &tables {
        let p = dir.join(format!("{name}.binary"));
        t.write(&p).unwrap();
        paths.push(p.display().to_string());
    }
    let pairs = pairs();
    let spec = |path: &str, interp: &str| {
        ModelSpec::from_json(
            "merl",
            &serde_json::json!({"path": path, "interpolation": interp}),
        )
        .unwrap()
    };
    // Per set: name, spec, the table of a nearest lookup, and f at given
    // (θh, θd, φd) straight from bv-core's tables (for the φd-free pairs).
    type AtAngles<'a> = Box<dyn Fn(f64, f64, f64) -> DVec3 + 'a>;
    let mut sets: Vec<(String, ModelSpec, Option<usize>, AtAngles<'_>)> = Vec::new();
    let mode = |interp: &str| merl::Interpolation::from_name(interp).unwrap();
    for (k, (name, table)) in tables.iter().enumerate() {
        for interp in ["trilinear", "nearest"] {
            let m = mode(interp);
            sets.push((
                format!("{name} {interp}"),
                spec(&paths[k], interp),
                (interp == "nearest").then_some(k),
                Box::new(move |th, td, pd| table.lookup_angles(th, td, pd, m)),
            ));
        }
    }
    let lambert = ModelSpec::new("lambert")
        .unwrap()
        .build()
        .unwrap()
        .eval(DVec3::Z, DVec3::Z);
    let mix = ModelSpec::from_json(
        "mix",
        &serde_json::json!({"components": [
            {"weight": 0.5, "model": "lambert"},
            {"weight": 1.0, "model": "merl", "params": {"path": paths[0]}},
            {"weight": 0.7, "model": "merl", "params": {"path": paths[2]}},
            {"weight": 0.3, "model": "merl", "params": {"path": paths[1]}},
            {"weight": 0.2, "model": "merl", "params": {"path": paths[0]}}
        ]}),
    )
    .unwrap();
    let tri = merl::Interpolation::Trilinear;
    let tables = &tables;
    sets.push((
        "mix of three tables".into(),
        mix,
        None,
        Box::new(move |th, td, pd| {
            let at = |k: usize| tables[k].1.lookup_angles(th, td, pd, tri);
            0.5 * lambert + 1.2 * at(0) + 0.7 * at(2) + 0.3 * at(1)
        }),
    ));

    let mut failures = Vec::new();
    for (name, spec, nearest, at_angles) in &sets {
        let cpu = spec.build().unwrap();
        let gpu_values = eval.eval(spec, &pairs).unwrap();
        let (mut worst, mut what, mut free, mut edge) = (0.0f64, String::new(), 0, 0);
        for ((wi, wo), g) in pairs.iter().zip(&gpu_values) {
            let (wi, wo) = (to_d(*wi), to_d(*wo));
            // Distance of the GPU value from [lo, hi] per channel, in tolerances.
            let ratio_to = |lo: DVec3, hi: DVec3| {
                (0..3)
                    .map(|k| {
                        let gk = f64::from(g[k]);
                        if !gk.is_finite() {
                            return f64::INFINITY;
                        }
                        let d = (lo[k] - gk).max(gk - hi[k]).max(0.0);
                        d / (ABS_TOL + REL_TOL * hi[k].abs())
                    })
                    .fold(0.0, f64::max)
            };
            let c = cpu.eval(wi, wo);
            let mut ratio = ratio_to(c, c);
            let angles = (wi.z > 0.0 && wo.z > 0.0)
                .then(|| merl::half_diff_angles(wi, wo))
                .flatten();
            if let Some((th, td, _)) = angles
                && (th.sin() < 1e-2 || td.sin() < 1e-2)
            {
                free += 1;
                let (mut lo, mut hi) = (DVec3::splat(f64::INFINITY), DVec3::ZERO);
                for k in 0..720 {
                    let v = at_angles(th, td, PI * f64::from(k) / 720.0);
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                ratio = ratio.min(ratio_to(lo, hi));
            }
            if let Some(k) = nearest
                && ratio > 1.0
                && angles.is_some()
            {
                let t = &tables[*k].1;
                let best = nearest_candidates(wi, wo, t.dims())
                    .into_iter()
                    .map(|(h, d, p)| {
                        let v = t.at(h, d, p);
                        ratio_to(v, v)
                    })
                    .fold(f64::INFINITY, f64::min);
                if best <= 1.0 {
                    edge += 1;
                }
                ratio = ratio.min(best);
            }
            if ratio > worst || ratio.is_nan() {
                worst = ratio;
                what = format!("wi {wi:?}, wo {wo:?}: gpu {g:?}, bv-core {c:?}");
            }
        }
        println!(
            "merl {name:<22} |Δ|/tol {worst:>8.4}  ({free} pairs with φd free, {edge} on a \
             cell edge) {what}"
        );
        if worst.is_nan() || worst > 1.0 {
            failures.push(format!("{name}: {what}"));
        }
    }
    std::fs::remove_dir_all(&dir).unwrap();
    assert!(
        failures.is_empty(),
        "the merl port disagrees with bv-core:\n{}",
        failures.join("\n")
    );
}

/// The RGL port's tolerance on f cos θo, looser than [`ABS_TOL`]/[`REL_TOL`]: its
/// lookup goes through f32 `asin`/`atan2` (which Vulkan allows to be loose:
/// lavapipe's moved f by up to 0.7 % at ordinary pairs) into a warp whose
/// inverse and values are steep where the lobe is.
const RGL_REL_TOL: f64 = 1e-2;
/// Absolute part of the RGL port's tolerance (on f cos θo).
const RGL_ABS_TOL: f64 = 1e-4;
/// How far (radians) the RGL port's f32 arithmetic may turn a direction: a
/// pair over the tolerance passes when the GPU value lies within the CPU's
/// values at both directions turned by this much (see
/// [`rgl_port_matches_bv_core`]). Needed only by the hand-built random files,
/// whose nodes are independent (far steeper than a measurement), at 25 of
/// their 16,640 pairs, all with an elevation beyond 75°; on lavapipe 1e-4 rad
/// left 8 of them over (worst 1.8 tolerances), 1e-3 none (worst 0.97).
const RGL_ANGLE_SLACK: f64 = 1e-3;

/// The RGL files the port is held to: analytic models tabulated by
/// `tabulate_rgl` (isotropic, one φi), and hand-built random files with 9 φi
/// over a full turn, 5 over a half and a quarter turn (folded), and 2 φi
/// (isotropic layout, interpolated over the absolute φi).
fn rgl_parity_files() -> Vec<(String, Vec<u8>)> {
    use bv_core::measured::rgl_write::{RglWriteOptions, tabulate_rgl};
    let models = [
        (
            "lambert",
            serde_json::json!({"albedo": [0.2, 0.5, 0.8]}),
            RglWriteOptions::default(),
        ),
        (
            "cook-torrance",
            serde_json::json!({"kd": [0.1, 0.2, 0.3], "ks": 0.8, "distribution": "ggx", "alpha": 0.3}),
            RglWriteOptions::default(),
        ),
        (
            "cook-torrance",
            serde_json::json!({"distribution": "ggx", "alpha": 0.6}),
            RglWriteOptions {
                theta_i: 5,
                ndf: 20,
                vndf: 24,
                values: 12,
                ..RglWriteOptions::default()
            },
        ),
    ];
    let mut out: Vec<(String, Vec<u8>)> = models
        .iter()
        .map(|(model, params, opts)| {
            let b = ModelSpec::from_json(model, params)
                .unwrap()
                .build()
                .unwrap();
            (
                format!("{model} {params}"),
                tabulate_rgl(b.as_ref(), opts).unwrap(),
            )
        })
        .collect();
    for (seed, nphi, span) in [(3, 9, 2.0 * PI), (1, 5, PI / 2.0), (2, 5, PI), (4, 2, PI)] {
        out.push((
            format!("random, {nphi} φi over {:.0}°", span.to_degrees()),
            rgl_files::random_rgl_file(seed, nphi, span),
        ));
    }
    out
}

/// The RGL port against bv-core's f64 evaluation on every file of
/// [`rgl_parity_files`] (isotropic tabulated models and anisotropic, folded
/// hand-built ones) over the 4,160 pairs of [`pairs`], as `f cos θo` within
/// [`RGL_ABS_TOL`] + [`RGL_REL_TOL`]·|f cos θo|.
#[test]
fn rgl_port_matches_bv_core() {
    let Some(gpu) = gpu_for_test() else { return };
    let mut lib = ShaderLibrary::new().unwrap();
    let eval = GpuEvaluator::new(gpu, &mut lib).unwrap();
    let dir = std::env::temp_dir().join(format!("bv-gpu-rgl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let pairs = pairs();
    let mut failures = Vec::new();
    for (k, (model, bytes)) in rgl_parity_files().into_iter().enumerate() {
        let path = dir.join(format!("m{k}.bsdf"));
        std::fs::write(&path, bytes).unwrap();
        let spec = ModelSpec::from_json(
            "rgl",
            &serde_json::json!({"path": path.display().to_string()}),
        )
        .unwrap();
        let cpu = spec.build().unwrap();
        let gpu_values = eval.eval(&spec, &pairs).unwrap();
        let (mut worst, mut what, mut over, mut grazing) = (0.0f64, String::new(), 0usize, 0usize);
        let mut bracketed = 0usize;
        for ((wi, wo), g) in pairs.iter().zip(&gpu_values) {
            let (wi, wo) = (to_d(*wi), to_d(*wo));
            // Within 0.6° of the horizon the f32 angles of the lookup move
            // a steep grazing lobe by more than the tolerance: there the
            // GPU value need only be finite and non-negative.
            if wo.z < 1e-2 || wi.z < 1e-2 {
                grazing += 1;
                assert!(
                    g.iter().all(|x| x.is_finite() && *x >= 0.0),
                    "{model}: wi {wi} wo {wo}: {g:?}"
                );
                continue;
            }
            // Compared as f cos θo, what the tables resolve.
            let z = wo.z;
            let c = cpu.eval(wi, wo) * z;
            let dist = |lo: DVec3, hi: DVec3| {
                (0..3)
                    .map(|i| {
                        let gi = f64::from(g[i]) * z;
                        if !gi.is_finite() {
                            return f64::INFINITY;
                        }
                        let d = (lo[i] - gi).max(gi - hi[i]).max(0.0);
                        d / (RGL_ABS_TOL + RGL_REL_TOL * lo[i].abs().max(hi[i].abs()))
                    })
                    .fold(0.0, f64::max)
            };
            let mut r = dist(c, c);
            if r > 1.0 {
                // The f32 angles (atan2, asin) and CDFs of the lookup are off
                // by f32 rounding; where the tables are steep (the random
                // files' independent nodes, near grazing) that moves the
                // value by more than the tolerance. Such a pair passes when the GPU
                // value lies within the CPU's range over both directions
                // turned by RGL_ANGLE_SLACK (16 turns), ± the tolerance.
                let (mut lo, mut hi) = (c, c);
                for t in 0..16 {
                    let a = 2.0 * PI * f64::from(t) / 16.0;
                    let (pi, po) = (
                        perturb(wi, RGL_ANGLE_SLACK, a),
                        perturb(wo, RGL_ANGLE_SLACK, a * 3.0 + 1.0),
                    );
                    let v = cpu.eval(pi, po) * po.z.max(0.0);
                    lo = lo.min(v);
                    hi = hi.max(v);
                }
                r = dist(lo, hi);
                bracketed += 1;
            }
            if r > 1.0 {
                over += 1;
            }
            if r > worst {
                worst = r;
                what = format!("wi {wi} wo {wo}: cpu {c} gpu {g:?}");
            }
        }
        println!(
            "rgl {model}: worst {worst:.3} tolerances, {over} of {} over, {bracketed} within \
             the range of directions turned by {RGL_ANGLE_SLACK:e} rad, {grazing} grazing pairs \
             only checked finite",
            pairs.len()
        );
        if worst > 1.0 {
            failures.push(format!("{model}: {worst} at {what} ({over} pairs over)"));
        }
    }
    std::fs::remove_dir_all(&dir).ok();
    assert!(failures.is_empty(), "{}", failures.join("\n"));
}
