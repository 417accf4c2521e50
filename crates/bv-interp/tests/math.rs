#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Each math builtin against a closed form written here in f64, over a grid
//! of inputs that includes edge values (zeros, halves, infinities, NaN).

mod common;

use bv_interp::{Limits, Value, Vector};
use common::*;

const GRID: &[f64] = &[
    -1e30, -10.0, -3.7, -2.5, -1.5, -1.0, -0.75, -0.5, -1e-30, -0.0, 0.0, 1e-30, 0.25, 0.5, 0.75,
    1.0, 1.5, 2.5, 3.0, 3.7, 10.0, 88.0, 1e30,
];
const SPECIAL: &[f64] = &[f64::INFINITY, f64::NEG_INFINITY, f64::NAN];

type F1 = fn(f64) -> f64;

fn sign(x: f64) -> f64 {
    if x > 0.0 {
        1.0
    } else if x < 0.0 {
        -1.0
    } else if x.is_nan() {
        // WGSL leaves sign(NaN) open; the interpreter propagates the NaN.
        x
    } else {
        0.0
    }
}

/// Round half to even, written out rather than taken from std.
fn round_even(x: f64) -> f64 {
    let f = x.floor();
    let d = x - f;
    if d < 0.5 {
        f
    } else if d > 0.5 {
        f + 1.0
    } else if f % 2.0 == 0.0 {
        f
    } else {
        f + 1.0
    }
}

#[test]
fn unary_functions_match_closed_forms() {
    let cases: &[(&str, F1)] = &[
        ("abs", |x| if x < 0.0 { -x } else { x }),
        ("sin", f64::sin),
        ("cos", f64::cos),
        ("tan", f64::tan),
        ("asin", f64::asin),
        ("acos", f64::acos),
        ("atan", f64::atan),
        ("sinh", |x| (x.exp() - (-x).exp()) / 2.0),
        ("cosh", |x| (x.exp() + (-x).exp()) / 2.0),
        ("tanh", f64::tanh),
        ("asinh", f64::asinh),
        ("acosh", |x| (x + (x * x - 1.0).sqrt()).ln()),
        ("atanh", |x| 0.5 * ((1.0 + x) / (1.0 - x)).ln()),
        ("radians", |x| x * std::f64::consts::PI / 180.0),
        ("degrees", |x| x * 180.0 / std::f64::consts::PI),
        ("ceil", f64::ceil),
        ("floor", f64::floor),
        ("round", round_even),
        ("fract", |x| x - x.floor()),
        ("trunc", f64::trunc),
        ("exp", f64::exp),
        ("exp2", |x| 2f64.powf(x)),
        ("log", f64::ln),
        ("log2", f64::log2),
        ("sqrt", f64::sqrt),
        ("inverseSqrt", |x| 1.0 / x.sqrt()),
        ("sign", sign),
        // min/max follow IEEE minNum/maxNum (a NaN operand loses), as GPU
        // min/max do, so saturate(NaN) is 0.
        ("saturate", |x| {
            if x < 0.0 || x.is_nan() {
                0.0
            } else if x > 1.0 {
                1.0
            } else {
                x
            }
        }),
    ];
    let src: String = cases
        .iter()
        .map(|(n, _)| format!("fn t_{n}(x: f32) -> f32 {{ return {n}(x); }}\n"))
        .collect();
    let p = wgsl(&src);
    for (name, f) in cases {
        for &x in GRID.iter().chain(SPECIAL) {
            let got = call_f(&p, &format!("t_{name}"), &[Value::f(x)]);
            let want = f(x);
            // The hyperbolic closed forms lose accuracy to cancellation near
            // zero and overflow at 1e30; compare where they are meaningful.
            let tol = if name.starts_with("a") || name.ends_with('h') {
                1e-9
            } else {
                1e-14
            };
            if name.ends_with('h') && (x.abs() > 700.0 || x.abs() < 1e-10) && !x.is_nan() {
                continue;
            }
            assert!(
                close(got, want, tol),
                "{name}({x}) = {got}, expected {want}"
            );
        }
    }
}

#[test]
fn round_is_ties_to_even_and_sign_is_signed() {
    let p = wgsl("fn r(x: f32) -> f32 { return round(x); }");
    for (x, want) in [
        (0.5, 0.0),
        (1.5, 2.0),
        (2.5, 2.0),
        (-0.5, -0.0),
        (-1.5, -2.0),
        (-2.5, -2.0),
        (2.4, 2.0),
        (2.6, 3.0),
    ] {
        assert_eq!(call_f(&p, "r", &[Value::f(x)]), want, "round({x})");
    }
}

#[test]
fn binary_and_ternary_functions() {
    let src = "
        fn t_min(x: f32, y: f32) -> f32 { return min(x, y); }
        fn t_max(x: f32, y: f32) -> f32 { return max(x, y); }
        fn t_pow(x: f32, y: f32) -> f32 { return pow(x, y); }
        fn t_atan2(y: f32, x: f32) -> f32 { return atan2(y, x); }
        fn t_step(e: f32, x: f32) -> f32 { return step(e, x); }
        fn t_mod(x: f32, y: f32) -> f32 { return x % y; }
        fn t_ldexp(x: f32, e: i32) -> f32 { return ldexp(x, e); }
        fn t_clamp(x: f32, a: f32, b: f32) -> f32 { return clamp(x, a, b); }
        fn t_mix(a: f32, b: f32, t: f32) -> f32 { return mix(a, b, t); }
        fn t_fma(a: f32, b: f32, c: f32) -> f32 { return fma(a, b, c); }
        fn t_smooth(a: f32, b: f32, x: f32) -> f32 { return smoothstep(a, b, x); }
    ";
    let p = wgsl(src);
    let pts = [-2.5, -1.0, -0.25, 0.0, 0.3, 1.0, 2.0, 3.5];
    for &x in &pts {
        for &y in &pts {
            let a = [Value::f(x), Value::f(y)];
            assert_eq!(call_f(&p, "t_min", &a), if x < y { x } else { y });
            assert_eq!(call_f(&p, "t_max", &a), if x > y { x } else { y });
            let pw = call_f(&p, "t_pow", &a);
            assert!(
                close(pw, (y * x.ln()).exp(), 1e-13) || (x <= 0.0),
                "pow({x},{y})={pw}"
            );
            let at = call_f(&p, "t_atan2", &a);
            if y != 0.0 || x != 0.0 {
                // atan2(y = x-arg, x = y-arg): the angle of the point (y, x).
                let (py, px) = (x, y);
                let want = if px > 0.0 {
                    (py / px).atan()
                } else if px < 0.0 && py >= 0.0 {
                    (py / px).atan() + std::f64::consts::PI
                } else if px < 0.0 {
                    (py / px).atan() - std::f64::consts::PI
                } else if py > 0.0 {
                    std::f64::consts::FRAC_PI_2
                } else {
                    -std::f64::consts::FRAC_PI_2
                };
                assert!(close(at, want, 1e-14), "atan2({x},{y})={at} want {want}");
            }
            assert_eq!(call_f(&p, "t_step", &a), if x <= y { 1.0 } else { 0.0 });
            if y != 0.0 {
                let m = call_f(&p, "t_mod", &a);
                // Truncated remainder: x - y * trunc(x / y).
                assert!(close(m, x - y * (x / y).trunc(), 1e-14), "{x} % {y} = {m}");
            }
            for &z in &pts {
                let a3 = [Value::f(x), Value::f(y), Value::f(z)];
                let want_clamp = if x < y { y } else { x };
                let want_clamp = if want_clamp > z { z } else { want_clamp };
                assert_eq!(call_f(&p, "t_clamp", &a3), want_clamp);
                assert!(close(
                    call_f(&p, "t_mix", &a3),
                    x * (1.0 - z) + y * z,
                    1e-15
                ));
                assert!(close(call_f(&p, "t_fma", &a3), x * y + z, 1e-15));
                if x < y {
                    let t = ((z - x) / (y - x)).clamp(0.0, 1.0);
                    let want = t * t * (3.0 - 2.0 * t);
                    assert!(close(call_f(&p, "t_smooth", &a3), want, 1e-15));
                }
            }
        }
        for e in [-1074, -1030, -3, 0, 5, 1023, 1100] {
            let got = call_f(&p, "t_ldexp", &[Value::f(x), Value::I32(e)]);
            let mut want = x;
            // Multiply by two (or a half) e times: exact until over/underflow.
            for _ in 0..e.unsigned_abs() {
                want *= if e > 0 { 2.0 } else { 0.5 };
            }
            assert!(
                close(got, want, 1e-15) || (got == 0.0 && want.abs() < 1e-300),
                "ldexp({x},{e})={got} want {want}"
            );
        }
    }
}

fn v3(v: [f64; 3]) -> Value {
    Value::vec3(v[0], v[1], v[2])
}

fn dot(a: [f64; 3], b: [f64; 3]) -> f64 {
    a[0] * b[0] + a[1] * b[1] + a[2] * b[2]
}

#[test]
fn geometric_functions() {
    let src = "
        fn t_len(v: vec3<f32>) -> f32 { return length(v); }
        fn t_dist(a: vec3<f32>, b: vec3<f32>) -> f32 { return distance(a, b); }
        fn t_norm(v: vec3<f32>) -> vec3<f32> { return normalize(v); }
        fn t_dot(a: vec3<f32>, b: vec3<f32>) -> f32 { return dot(a, b); }
        fn t_cross(a: vec3<f32>, b: vec3<f32>) -> vec3<f32> { return cross(a, b); }
        fn t_reflect(i: vec3<f32>, n: vec3<f32>) -> vec3<f32> { return reflect(i, n); }
        fn t_refract(i: vec3<f32>, n: vec3<f32>, eta: f32) -> vec3<f32> { return refract(i, n, eta); }
        fn t_ff(n: vec3<f32>, i: vec3<f32>, r: vec3<f32>) -> vec3<f32> { return faceForward(n, i, r); }
        fn t_len2(v: vec2<f32>) -> f32 { return length(v); }
        fn t_len1(x: f32) -> f32 { return length(x); }
    ";
    let p = wgsl(src);
    let vs = [
        [1.0, 0.0, 0.0],
        [0.3, -0.4, 0.866],
        [-2.0, 5.0, 0.5],
        [0.0, 0.0, 1.0],
        [1e-3, 2e-3, -4e-3],
    ];
    for a in vs {
        let la = dot(a, a).sqrt();
        assert!(close(call_f(&p, "t_len", &[v3(a)]), la, 1e-15));
        let n = call(&p, "t_norm", &[v3(a)]).as_vec3().unwrap();
        for k in 0..3 {
            assert!(close(n[k], a[k] / la, 1e-15));
        }
        for b in vs {
            let d = [a[0] - b[0], a[1] - b[1], a[2] - b[2]];
            assert!(close(
                call_f(&p, "t_dist", &[v3(a), v3(b)]),
                dot(d, d).sqrt(),
                1e-15
            ));
            assert!(close(
                call_f(&p, "t_dot", &[v3(a), v3(b)]),
                dot(a, b),
                1e-15
            ));
            let c = call(&p, "t_cross", &[v3(a), v3(b)]).as_vec3().unwrap();
            let want = [
                a[1] * b[2] - a[2] * b[1],
                a[2] * b[0] - a[0] * b[2],
                a[0] * b[1] - a[1] * b[0],
            ];
            for k in 0..3 {
                assert!(close(c[k], want[k], 1e-15), "cross");
            }
            let r = call(&p, "t_reflect", &[v3(a), v3(b)]).as_vec3().unwrap();
            let dn = dot(b, a);
            for k in 0..3 {
                assert!(close(r[k], a[k] - 2.0 * dn * b[k], 1e-14), "reflect");
            }
            for eta in [0.5, 1.0 / 1.5, 1.5] {
                let r = call(&p, "t_refract", &[v3(a), v3(b), Value::f(eta)])
                    .as_vec3()
                    .unwrap();
                let k2 = 1.0 - eta * eta * (1.0 - dn * dn);
                for k in 0..3 {
                    let want = if k2 < 0.0 {
                        0.0
                    } else {
                        eta * a[k] - (eta * dn + k2.sqrt()) * b[k]
                    };
                    assert!(close(r[k], want, 1e-14), "refract");
                }
            }
            let f = call(&p, "t_ff", &[v3(a), v3(b), v3(vs[1])])
                .as_vec3()
                .unwrap();
            let s = if dot(vs[1], b) < 0.0 { 1.0 } else { -1.0 };
            for k in 0..3 {
                assert_eq!(f[k], s * a[k]);
            }
        }
    }
    assert_eq!(call_f(&p, "t_len2", &[Value::vec2(3.0, 4.0)]), 5.0);
    assert_eq!(call_f(&p, "t_len1", &[Value::f(-2.5)]), 2.5);
}

#[test]
fn modf_frexp_and_vector_math() {
    let src = "
        fn t_modf_f(x: f32) -> f32 { return modf(x).fract; }
        fn t_modf_w(x: f32) -> f32 { return modf(x).whole; }
        fn t_frexp_f(x: f32) -> f32 { return frexp(x).fract; }
        fn t_frexp_e(x: f32) -> i32 { return frexp(x).exp; }
        fn t_vmix(a: vec3<f32>, b: vec3<f32>, t: f32) -> vec3<f32> { return mix(a, b, vec3(t)); }
        fn t_vclamp(a: vec3<f32>) -> vec3<f32> { return clamp(a, vec3(0.0), vec3(1.0)); }
        fn t_vpow(a: vec3<f32>) -> vec3<f32> { return pow(abs(a), vec3(2.0, 0.5, 3.0)); }
    ";
    let p = wgsl(src);
    for x in [-3.75, -0.5, 0.0, 0.25, 1.0, 2.5, 7.125, 1e10] {
        let fr = call_f(&p, "t_modf_f", &[Value::f(x)]);
        let wh = call_f(&p, "t_modf_w", &[Value::f(x)]);
        assert_eq!(wh, x.trunc());
        assert_eq!(fr, x - x.trunc());
        let f = call_f(&p, "t_frexp_f", &[Value::f(x)]);
        let e = match call(&p, "t_frexp_e", &[Value::f(x)]) {
            Value::I32(e) => e,
            v => panic!("{v:?}"),
        };
        if x == 0.0 {
            assert_eq!((f, e), (0.0, 0));
        } else {
            assert!((0.5..1.0).contains(&f.abs()), "frexp({x}) fraction {f}");
            assert_eq!(f * 2f64.powi(e), x);
        }
    }
    let m = call(
        &p,
        "t_vmix",
        &[
            Value::vec3(0.0, 1.0, 2.0),
            Value::vec3(4.0, 3.0, 2.0),
            Value::f(0.25),
        ],
    );
    assert_eq!(m.as_vec3().unwrap(), [1.0, 1.5, 2.0]);
    let c = call(&p, "t_vclamp", &[Value::vec3(-1.0, 0.5, 3.0)]);
    assert_eq!(c.as_vec3().unwrap(), [0.0, 0.5, 1.0]);
    let w = call(&p, "t_vpow", &[Value::vec3(-3.0, 4.0, 0.5)])
        .as_vec3()
        .unwrap();
    assert!(close(w[0], 9.0, 1e-15) && close(w[1], 2.0, 1e-15) && close(w[2], 0.125, 1e-15));
}

#[test]
fn glsl_builtins_and_broadcasts() {
    let p = glsl(
        "
        float t_mod(float x, float y) { return mod(x, y); }
        float t_atan(float y, float x) { return atan(y, x); }
        vec3 t_clamp(vec3 v) { return clamp(v, 0.0, 1.0); }
        vec3 t_mix(vec3 a, vec3 b, float t) { return mix(a, b, t); }
        vec3 t_smooth(vec3 x) { return smoothstep(0.0, 2.0, x); }
        float t_isqrt(float x) { return inversesqrt(x); }
        vec3 t_step(vec3 x) { return step(0.5, x); }
        float t_sel(float x) { return x > 0.0 ? x : -2.0 * x; }
        ",
    );
    for (x, y) in [(5.5, 2.0), (-5.5, 2.0), (5.5, -2.0), (0.25, 1.0)] {
        // GLSL mod is floored: x - y floor(x / y).
        let got = call_f(&p, "t_mod", &[Value::f(x), Value::f(y)]);
        assert!(
            close(got, x - y * (x / y).floor(), 1e-15),
            "mod({x},{y})={got}"
        );
        let a = call_f(&p, "t_atan", &[Value::f(x), Value::f(y)]);
        assert!(close(a, x.atan2(y), 1e-15));
    }
    let c = call(&p, "t_clamp", &[Value::vec3(-1.0, 0.5, 2.0)]);
    assert_eq!(c.as_vec3().unwrap(), [0.0, 0.5, 1.0]);
    let m = call(
        &p,
        "t_mix",
        &[
            Value::vec3(0.0, 2.0, 4.0),
            Value::vec3(1.0, 2.0, 0.0),
            Value::f(0.5),
        ],
    );
    assert_eq!(m.as_vec3().unwrap(), [0.5, 2.0, 2.0]);
    let s = call(&p, "t_smooth", &[Value::vec3(-1.0, 1.0, 0.5)])
        .as_vec3()
        .unwrap();
    assert_eq!(s, [0.0, 0.5, 0.25 * 0.25 * (3.0 - 0.5)]);
    assert_eq!(call_f(&p, "t_isqrt", &[Value::f(4.0)]), 0.5);
    let st = call(&p, "t_step", &[Value::vec3(0.0, 0.5, 1.0)]);
    assert_eq!(st.as_vec3().unwrap(), [0.0, 1.0, 1.0]);
    assert_eq!(call_f(&p, "t_sel", &[Value::f(3.0)]), 3.0);
    assert_eq!(call_f(&p, "t_sel", &[Value::f(-3.0)]), 6.0);
}

#[test]
fn matrices() {
    let p = wgsl(
        "
        fn mv(m: mat3x3<f32>, v: vec3<f32>) -> vec3<f32> { return m * v; }
        fn vm(v: vec3<f32>, m: mat3x3<f32>) -> vec3<f32> { return v * m; }
        fn mm(a: mat3x3<f32>, b: mat3x3<f32>) -> mat3x3<f32> { return a * b; }
        fn tr(m: mat2x3<f32>) -> mat3x2<f32> { return transpose(m); }
        fn det(m: mat3x3<f32>) -> f32 { return determinant(m); }
        fn det4(m: mat4x4<f32>) -> f32 { return determinant(m); }
        fn col(m: mat3x3<f32>, i: i32) -> vec3<f32> { var mm = m; return mm[i]; }
        fn rect(m: mat2x3<f32>, v: vec2<f32>) -> vec3<f32> { return m * v + m[1] * 2.0; }
        fn scale(m: mat3x3<f32>) -> mat3x3<f32> { return 2.0 * m - m; }
        ",
    );
    let a: Vec<f64> = (0..9).map(|i| ((i * 7 + 3) % 11) as f64 - 4.5).collect();
    let b: Vec<f64> = (0..9).map(|i| ((i * 5 + 1) % 13) as f64 * 0.25).collect();
    let ma = Value::Mat(bv_interp::Matrix::new(3, 3, &a).unwrap());
    let mb = Value::Mat(bv_interp::Matrix::new(3, 3, &b).unwrap());
    let v = [0.5, -1.0, 2.0];
    // Column-major: a[c * 3 + r].
    let got = call(&p, "mv", &[ma.clone(), v3(v)]).as_vec3().unwrap();
    for r in 0..3 {
        let want: f64 = (0..3).map(|c| a[c * 3 + r] * v[c]).sum();
        assert!(close(got[r], want, 1e-15));
    }
    let got = call(&p, "vm", &[v3(v), ma.clone()]).as_vec3().unwrap();
    for c in 0..3 {
        let want: f64 = (0..3).map(|r| v[r] * a[c * 3 + r]).sum();
        assert!(close(got[c], want, 1e-15));
    }
    let Value::Mat(prod) = call(&p, "mm", &[ma.clone(), mb]) else {
        panic!()
    };
    for c in 0..3 {
        for r in 0..3 {
            let want: f64 = (0..3).map(|k| a[k * 3 + r] * b[c * 3 + k]).sum();
            assert!(close(prod.get(c, r).unwrap(), want, 1e-15));
        }
    }
    let m23 = bv_interp::Matrix::new(2, 3, &[1.0, 2.0, 3.0, 4.0, 5.0, 6.0]).unwrap();
    let Value::Mat(t) = call(&p, "tr", &[Value::Mat(m23)]) else {
        panic!()
    };
    assert_eq!((t.columns(), t.rows()), (3, 2));
    for c in 0..2 {
        for r in 0..3 {
            assert_eq!(t.get(r, c), m23.get(c, r));
        }
    }
    let det = a[0] * (a[4] * a[8] - a[7] * a[5]) - a[3] * (a[1] * a[8] - a[7] * a[2])
        + a[6] * (a[1] * a[5] - a[4] * a[2]);
    assert!(close(
        call_f(&p, "det", std::slice::from_ref(&ma)),
        det,
        1e-14
    ));
    // A 4x4 with a known determinant: upper triangular, product of diagonal.
    let mut u = [0.0; 16];
    for c in 0..4 {
        for r in 0..=c {
            u[c * 4 + r] = if r == c { (c + 2) as f64 } else { 1.5 };
        }
    }
    let m4 = Value::Mat(bv_interp::Matrix::new(4, 4, &u).unwrap());
    assert!(close(
        call_f(&p, "det4", &[m4]),
        2.0 * 3.0 * 4.0 * 5.0,
        1e-14
    ));
    for i in 0..3 {
        let c = call(&p, "col", &[ma.clone(), Value::I32(i)])
            .as_vec3()
            .unwrap();
        let i = i as usize;
        assert_eq!(c, [a[i * 3], a[i * 3 + 1], a[i * 3 + 2]]);
    }
    let r = call(&p, "rect", &[Value::Mat(m23), Value::vec2(1.0, -1.0)])
        .as_vec3()
        .unwrap();
    assert_eq!(r, [1.0 - 4.0 + 8.0, 2.0 - 5.0 + 10.0, 3.0 - 6.0 + 12.0]);
    let Value::Mat(s) = call(&p, "scale", &[ma]) else {
        panic!()
    };
    assert_eq!(s.as_slice(), &a[..]);
}

#[test]
fn glsl_inverse_and_outer_product() {
    let p = glsl(
        "
        mat3 inv(mat3 m) { return inverse(m); }
        mat2 inv2(mat2 m) { return inverse(m); }
        mat3 outer(vec3 a, vec3 b) { return outerProduct(a, b); }
        ",
    );
    let a = [2.0, 1.0, 0.5, -1.0, 3.0, 0.25, 0.0, 1.0, 4.0];
    let Value::Mat(inv) = call(
        &p,
        "inv",
        &[Value::Mat(bv_interp::Matrix::new(3, 3, &a).unwrap())],
    ) else {
        panic!()
    };
    // a · inverse(a) is the identity.
    for c in 0..3 {
        for r in 0..3 {
            let s: f64 = (0..3).map(|k| a[k * 3 + r] * inv.get(c, k).unwrap()).sum();
            assert!((s - if r == c { 1.0 } else { 0.0 }).abs() < 1e-14, "{s}");
        }
    }
    let Value::Mat(i2) = call(
        &p,
        "inv2",
        &[Value::Mat(
            bv_interp::Matrix::new(2, 2, &[4.0, 2.0, 7.0, 6.0]).unwrap(),
        )],
    ) else {
        panic!()
    };
    // inverse of [[4 7][2 6]] (columns (4,2), (7,6)) = 1/10 [[6 -7][-2 4]].
    assert_eq!(i2.as_slice(), &[0.6, -0.2, -0.7, 0.4]);
    let Value::Mat(o) = call(
        &p,
        "outer",
        &[Value::vec3(1.0, 2.0, 3.0), Value::vec3(4.0, 5.0, 6.0)],
    ) else {
        panic!()
    };
    for c in 0..3 {
        for r in 0..3 {
            assert_eq!(
                o.get(c, r).unwrap(),
                [1.0, 2.0, 3.0][r] * [4.0, 5.0, 6.0][c]
            );
        }
    }
}

#[test]
fn vectors_of_other_kinds_come_back_typed() {
    let p = wgsl("fn cmp(a: vec3<f32>, b: vec3<f32>) -> vec3<bool> { return a < b; }");
    let v = call(
        &p,
        "cmp",
        &[Value::vec3(1.0, 2.0, 3.0), Value::vec3(2.0, 2.0, 2.0)],
    );
    assert_eq!(
        v,
        Value::Vec(Vector::new(bv_interp::Kind::Bool, &[1.0, 0.0, 0.0]).unwrap())
    );
    let _ = Limits::default();
}
