#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Whole BRDFs: a WGSL Cook–Torrance (GGX) and a GLSL Blinn–Phong in the
//! BRDF Explorer signature, against the formulas written here in f64.
//!
//! Literals are the f32 values naga parsed (`3.14159` is `3.14159f32`), so
//! the references use `f64::from(3.14159f32)`; everything else is f64.

mod common;

use bv_interp::{Program, Value};
use common::*;

const GGX_WGSL: &str = include_str!("../examples/ggx.wgsl");

type V3 = [f64; 3];

fn add(a: V3, b: V3) -> V3 {
    [a[0] + b[0], a[1] + b[1], a[2] + b[2]]
}
fn dot(a: V3, b: V3) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}
fn normalize(a: V3) -> V3 {
    let l = dot(a, a).sqrt();
    [a[0] / l, a[1] / l, a[2] / l]
}
fn dir(theta: f64, phi: f64) -> V3 {
    [
        theta.sin() * phi.cos(),
        theta.sin() * phi.sin(),
        theta.cos(),
    ]
}

/// Cook–Torrance with the GGX distribution, Smith's separable G1 and
/// Schlick's Fresnel (Walter et al. 2007, eqs. 33 and 34; Schlick 1994).
fn ggx_reference(l: V3, v: V3, n: V3, alpha: f64, f0: V3, albedo: V3) -> V3 {
    // The shader's `3.14159265358979` as naga parsed it: the f32 nearest.
    #[allow(clippy::approx_constant)]
    let pi = f64::from(3.141_592_7_f32);
    let nl = dot(n, l).max(0.0);
    let nv = dot(n, v).max(0.0);
    if nl <= 0.0 || nv <= 0.0 {
        return [0.0; 3];
    }
    let h = normalize(add(l, v));
    let nh = dot(n, h).max(0.0);
    let vh = dot(v, h).max(0.0);
    let a2 = alpha * alpha;
    let dd = nh * nh * (a2 - 1.0) + 1.0;
    let d = a2 / (pi * dd * dd);
    let g1 = |x: f64| 2.0 * x / (x + (a2 + (1.0 - a2) * x * x).sqrt());
    let g = g1(nl) * g1(nv);
    let mut out = [0.0; 3];
    for k in 0..3 {
        let f = f0[k] + (1.0 - f0[k]) * (1.0 - vh).powf(5.0);
        out[k] = albedo[k] / pi + f * d * g / (4.0 * nl * nv);
    }
    out
}

fn rel_close(a: f64, b: f64) -> bool {
    a == b || (a - b).abs() <= 1e-12 * a.abs().max(b.abs())
}

#[test]
fn ggx_cook_torrance_wgsl() {
    let mut p = wgsl(GGX_WGSL);
    let n = [0.0, 0.0, 1.0];
    let mut checked = 0;
    for &(alpha, f0, albedo) in &[
        (0.3, [0.04, 0.04, 0.04], [0.5, 0.5, 0.5]),
        (0.05, [0.95, 0.64, 0.54], [0.0, 0.0, 0.0]),
        (0.8, [0.2, 0.3, 0.4], [0.1, 0.7, 0.2]),
    ] {
        p.set_global("alpha", Value::f(alpha)).unwrap();
        p.set_global("f0", Value::vec3(f0[0], f0[1], f0[2]))
            .unwrap();
        p.set_global("albedo", Value::vec3(albedo[0], albedo[1], albedo[2]))
            .unwrap();
        for ti in 0..9 {
            for to in 0..9 {
                for pd in 0..4 {
                    let l = dir(ti as f64 * 0.19, 0.0);
                    let v = dir(to as f64 * 0.19 - 0.1, pd as f64 * 1.1);
                    let got = call(
                        &p,
                        "brdf",
                        &[
                            Value::vec3(l[0], l[1], l[2]),
                            Value::vec3(v[0], v[1], v[2]),
                            Value::vec3(n[0], n[1], n[2]),
                        ],
                    )
                    .as_vec3()
                    .unwrap();
                    let want = ggx_reference(l, v, n, alpha, f0, albedo);
                    for k in 0..3 {
                        assert!(
                            rel_close(got[k], want[k]),
                            "alpha {alpha} l {l:?} v {v:?}: {got:?} vs {want:?}"
                        );
                    }
                    checked += 1;
                }
            }
        }
    }
    assert_eq!(checked, 3 * 81 * 4);
}

const BLINN_GLSL: &str = "
float n;
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)
{
    vec3 H = normalize(L + V);
    float val = pow(max(0.0, dot(N, H)), n);
    val *= (n + 2.0) / (2.0 * 3.14159);
    return vec3(val);
}
";

#[test]
fn blinn_phong_glsl_brdf_explorer_signature() {
    let mut p = glsl(BLINN_GLSL);
    // The shader's literal, deliberately not π.
    #[allow(clippy::approx_constant)]
    let pi = f64::from(3.14159f32);
    let (nrm, x, y) = ([0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]);
    for exponent in [1.0, 10.0, 100.0, 1234.5] {
        p.set_global("n", Value::f(exponent)).unwrap();
        for ti in 0..8 {
            for to in 0..8 {
                let l = dir(ti as f64 * 0.2, 0.3);
                let v = dir(to as f64 * 0.2, 2.0);
                let h = normalize(add(l, v));
                let want = dot(nrm, h).max(0.0).powf(exponent) * ((exponent + 2.0) / (2.0 * pi));
                let got = call(
                    &p,
                    "BRDF",
                    &[
                        Value::vec3(l[0], l[1], l[2]),
                        Value::vec3(v[0], v[1], v[2]),
                        Value::vec3(nrm[0], nrm[1], nrm[2]),
                        Value::vec3(x[0], x[1], x[2]),
                        Value::vec3(y[0], y[1], y[2]),
                    ],
                )
                .as_vec3()
                .unwrap();
                for g in got {
                    assert!(rel_close(g, want), "n {exponent}: {g} vs {want}");
                }
            }
        }
    }
}

/// The evaluation is f64: a value that f32 arithmetic would round differs
/// from the f32 result.
#[test]
fn evaluation_is_f64_not_f32() {
    let p = wgsl("fn f(a: f32, b: f32) -> f32 { return a / b; }");
    let got = call_f(&p, "f", &[Value::f(1.0), Value::f(3.0)]);
    assert_eq!(got, 1.0 / 3.0);
    assert_ne!(got, f64::from(1.0f32 / 3.0f32));
    let _: Option<Program> = None;
}
