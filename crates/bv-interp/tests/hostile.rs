#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Shaders that try to run forever, allocate too much, use what the
//! interpreter cannot do, or are called wrongly: each gets an error, never a
//! panic or a hang.

mod common;

use std::time::{Duration, Instant};

use bv_interp::{InterpError, Limits, Program, Value};
use common::*;

#[test]
fn endless_loops_exhaust_the_step_budget_quickly() {
    let p = wgsl(
        "
        fn spin() -> f32 { loop { } return 1.0; }
        fn count(x: f32) -> f32 { var y = x; loop { y = y + 1.0; } return y; }
        fn nested(x: f32) -> f32 { var y = x; for (var i = 0; i < 1000000; i++) { for (var j = 0; j < 1000000; j++) { y += 1.0; } } return y; }
        ",
    );
    let q = glsl("float spin(float x) { float y = x; while (true) { y += 1.0; } return y; }");
    let limits = Limits::default();
    for (prog, name, args) in [
        (&p, "spin", vec![]),
        (&p, "count", vec![Value::f(0.0)]),
        (&p, "nested", vec![Value::f(0.0)]),
        (&q, "spin", vec![Value::f(0.0)]),
    ] {
        let t = Instant::now();
        let r = prog.call(name, &args, &limits);
        let dt = t.elapsed();
        assert_eq!(
            r,
            Err(InterpError::StepBudget { steps: 1_000_000 }),
            "{name}"
        );
        eprintln!("{name}: step budget of 1e6 exhausted in {dt:?}");
        assert!(dt < Duration::from_millis(500), "{name} took {dt:?}");
    }
    // Copying a large array costs steps by its size, so a loop of copies
    // ends as promptly.
    let copies = wgsl(
        "fn copies() -> f32 {
             var a: array<f32, 200000>;
             var s = 0.0;
             loop { let b = a; s += b[7]; a[7] = s + 1.0; }
             return s;
         }
         fn calls_big(x: f32) -> f32 { var a: array<f32, 200000>; a[3] = x; return take(a); }
         fn take(a: array<f32, 200000>) -> f32 { return a[3]; }
         fn many_calls() -> f32 { var s = 0.0; loop { s += calls_big(s); } return s; }",
    );
    for name in ["copies", "many_calls"] {
        let t = Instant::now();
        let r = copies.call(name, &[], &limits);
        let dt = t.elapsed();
        assert_eq!(
            r,
            Err(InterpError::StepBudget { steps: 1_000_000 }),
            "{name}"
        );
        eprintln!("{name}: step budget exhausted in {dt:?}");
        assert!(dt < Duration::from_millis(500), "{name} took {dt:?}");
    }
    // A small budget stops a finite loop too; a large one lets it finish.
    let small = Limits {
        max_steps: 50,
        ..Limits::default()
    };
    let f =
        wgsl("fn f() -> i32 { var s = 0; for (var i = 0; i < 100; i++) { s += i; } return s; }");
    assert_eq!(
        f.call("f", &[], &small),
        Err(InterpError::StepBudget { steps: 50 })
    );
    assert_eq!(f.call("f", &[], &Limits::default()), Ok(Value::I32(4950)));
}

#[test]
fn huge_local_arrays_are_refused_without_allocating() {
    let p = wgsl(
        "
        fn big(i: i32) -> f32 { var a: array<f32, 100000000>; a[i] = 1.0; return a[i]; }
        fn medium(i: i32) -> f32 { var a: array<f32, 100000>; a[i] = 2.0; return a[i] + a[0]; }
        fn calls_big(i: i32) -> f32 { return big(i) + 1.0; }
        ",
    );
    let r = p.call("big", &[Value::I32(3)], &Limits::default());
    match r {
        Err(InterpError::Memory { bytes, .. }) => assert!(bytes >= 800_000_000, "{bytes}"),
        other => panic!("{other:?}"),
    }
    assert!(matches!(
        p.call("calls_big", &[Value::I32(3)], &Limits::default()),
        Err(InterpError::Memory { .. })
    ));
    // 100 000 cells fit the default 16 MiB but not a 100 kB limit.
    assert_eq!(call_f(&p, "medium", &[Value::I32(5)]), 2.0);
    assert_eq!(call_f(&p, "medium", &[Value::I32(0)]), 4.0);
    let tight = Limits {
        max_memory_bytes: 100_000,
        ..Limits::default()
    };
    assert!(matches!(
        p.call("medium", &[Value::I32(5)], &tight),
        Err(InterpError::Memory { .. })
    ));
}

#[test]
fn call_depth_is_bounded() {
    let p = wgsl(
        "
        fn a(x: f32) -> f32 { return x + 1.0; }
        fn b(x: f32) -> f32 { return a(x) * 2.0; }
        fn c(x: f32) -> f32 { return b(x) * 2.0; }
        fn d(x: f32) -> f32 { return c(x) * 2.0; }
        ",
    );
    assert_eq!(call_f(&p, "d", &[Value::f(1.0)]), 16.0);
    let shallow = Limits {
        max_call_depth: 2,
        ..Limits::default()
    };
    assert_eq!(
        p.call("d", &[Value::f(1.0)], &shallow),
        Err(InterpError::CallDepth { depth: 2 })
    );
    assert!(p.call("b", &[Value::f(1.0)], &shallow).is_ok());
}

fn unsupported_message(src: &str) -> String {
    let module = naga::front::wgsl::parse_str(src).unwrap();
    match Program::new(module) {
        Err(e @ InterpError::Unsupported { .. }) => e.to_string(),
        Err(e) => panic!("expected Unsupported, got {e}"),
        Ok(_) => panic!("expected Unsupported, got a program"),
    }
}

#[test]
fn unsupported_features_are_named() {
    let m = unsupported_message(
        "@group(0) @binding(0) var t: texture_2d<f32>;
         @group(0) @binding(1) var s: sampler;
         fn tex(uv: vec2<f32>) -> vec4<f32> { return textureSampleLevel(t, s, uv, 0.0); }",
    );
    assert!(m.contains("texture sampling") && m.contains("`tex`"), "{m}");
    let m = unsupported_message("fn d(x: f32) -> f32 { return dpdx(x); }");
    assert!(m.contains("derivatives"), "{m}");
    let m = unsupported_message("fn q(x: f32) -> f32 { return quantizeToF16(x); }");
    assert!(m.contains("quantizeToF16"), "{m}");
    let m = unsupported_message("fn p(x: vec4<f32>) -> u32 { return pack4x8unorm(x); }");
    assert!(m.contains("packing"), "{m}");
    let m = unsupported_message(
        "@group(0) @binding(0) var<storage, read_write> buf: array<f32>;
         fn n() -> u32 { return arrayLength(&buf); }",
    );
    assert!(m.contains("storage") || m.contains("runtime-sized"), "{m}");
    let m = unsupported_message(
        "var<workgroup> w: f32;
         fn wg() -> f32 { return w; }",
    );
    assert!(m.contains("workgroup"), "{m}");
    eprintln!("example message: {m}");
}

#[test]
fn discard_is_an_error() {
    let p = glsl("float f(float x) { if (x < 0.0) { discard; } return x; }");
    assert_eq!(call_f(&p, "f", &[Value::f(2.0)]), 2.0);
    assert_eq!(
        p.call("f", &[Value::f(-1.0)], &Limits::default()),
        Err(InterpError::Kill)
    );
}

#[test]
fn wrong_calls_are_errors() {
    let p = wgsl(
        "fn f(a: f32, v: vec3<f32>) -> f32 { return a + v.x; }
         fn g(p: ptr<function, f32>) { *p = 1.0; }",
    );
    let l = Limits::default();
    assert!(matches!(
        p.call("f", &[Value::f(1.0)], &l),
        Err(InterpError::Type { .. })
    ));
    assert!(matches!(
        p.call("f", &[Value::I32(1), Value::vec3(0.0, 0.0, 0.0)], &l),
        Err(InterpError::Type { .. })
    ));
    let e = p
        .call("f", &[Value::f(1.0), Value::vec2(0.0, 0.0)], &l)
        .unwrap_err();
    assert!(e.to_string().contains("vec3<f32>"), "{e}");
    assert_eq!(
        p.call("nope", &[], &l),
        Err(InterpError::UnknownFunction("nope".into()))
    );
    assert!(matches!(
        p.call("g", &[Value::f(0.0)], &l),
        Err(InterpError::Type { .. })
    ));
}

#[test]
fn invalid_modules_are_rejected() {
    // The front ends never produce invalid IR, so build some by hand: a
    // `Load` whose operand is a float literal, not a pointer.
    let mut m = naga::Module::default();
    let f32_ty = m.types.insert(
        naga::Type {
            name: None,
            inner: naga::TypeInner::Scalar(naga::Scalar::F32),
        },
        naga::Span::UNDEFINED,
    );
    let mut f = naga::Function {
        name: Some("bad".into()),
        result: Some(naga::FunctionResult {
            ty: f32_ty,
            binding: None,
        }),
        ..Default::default()
    };
    let lit = f.expressions.append(
        naga::Expression::Literal(naga::Literal::F32(1.0)),
        naga::Span::UNDEFINED,
    );
    let load = f.expressions.append(
        naga::Expression::Load { pointer: lit },
        naga::Span::UNDEFINED,
    );
    f.body.push(
        naga::Statement::Emit(naga::Range::new_from_bounds(load, load)),
        naga::Span::UNDEFINED,
    );
    f.body.push(
        naga::Statement::Return { value: Some(load) },
        naga::Span::UNDEFINED,
    );
    m.functions.append(f, naga::Span::UNDEFINED);
    assert!(matches!(Program::new(m), Err(InterpError::Invalid(_))));
}

/// A tiny expression language rendered to WGSL and evaluated here in f64.
#[derive(Debug, Clone)]
enum E {
    X,
    Y,
    Lit(f64),
    Add(Box<E>, Box<E>),
    Sub(Box<E>, Box<E>),
    Mul(Box<E>, Box<E>),
    Div(Box<E>, Box<E>),
    Min(Box<E>, Box<E>),
    Max(Box<E>, Box<E>),
    Abs(Box<E>),
    Sqrt(Box<E>),
    Sin(Box<E>),
    Sel(Box<E>, Box<E>, Box<E>),
}

struct Lcg(u64);
impl Lcg {
    fn next(&mut self) -> u64 {
        self.0 = self
            .0
            .wrapping_mul(6_364_136_223_846_793_005)
            .wrapping_add(1_442_695_040_888_963_407);
        self.0 >> 33
    }
    fn below(&mut self, n: u64) -> u64 {
        self.next() % n
    }
}

fn random_expr(r: &mut Lcg, depth: u32) -> E {
    let b = |r: &mut Lcg| Box::new(random_expr(r, depth - 1));
    if depth == 0 {
        return match r.below(3) {
            0 => E::X,
            1 => E::Y,
            // Quarters are exact in f32, so the literal rounding is moot.
            _ => E::Lit((r.below(33) as f64 - 16.0) / 4.0),
        };
    }
    match r.below(12) {
        0 => E::Add(b(r), b(r)),
        1 => E::Sub(b(r), b(r)),
        2 => E::Mul(b(r), b(r)),
        3 => E::Div(b(r), b(r)),
        4 => E::Min(b(r), b(r)),
        5 => E::Max(b(r), b(r)),
        6 => E::Abs(b(r)),
        7 => E::Sqrt(b(r)),
        8 => E::Sin(b(r)),
        9 => E::Sel(b(r), b(r), b(r)),
        _ => random_expr(r, 0),
    }
}

fn wgsl_of(e: &E) -> String {
    match e {
        E::X => "x".into(),
        E::Y => "y".into(),
        // Multiplied by the run-time `k = 1` so that no sub-expression is
        // constant: naga's front end folds constant expressions in f32
        // (WGSL's rules), which would round them before the interpreter
        // sees them.
        E::Lit(v) => format!("(k * {v:?})"),
        E::Add(a, b) => format!("({} + {})", wgsl_of(a), wgsl_of(b)),
        E::Sub(a, b) => format!("({} - {})", wgsl_of(a), wgsl_of(b)),
        E::Mul(a, b) => format!("({} * {})", wgsl_of(a), wgsl_of(b)),
        E::Div(a, b) => format!("({} / {})", wgsl_of(a), wgsl_of(b)),
        E::Min(a, b) => format!("min({}, {})", wgsl_of(a), wgsl_of(b)),
        E::Max(a, b) => format!("max({}, {})", wgsl_of(a), wgsl_of(b)),
        E::Abs(a) => format!("abs({})", wgsl_of(a)),
        E::Sqrt(a) => format!("sqrt({})", wgsl_of(a)),
        E::Sin(a) => format!("sin({})", wgsl_of(a)),
        E::Sel(c, a, b) => format!(
            "select({}, {}, {} > 0.0)",
            wgsl_of(b),
            wgsl_of(a),
            wgsl_of(c)
        ),
    }
}

fn eval(e: &E, x: f64, y: f64) -> f64 {
    match e {
        E::X => x,
        E::Y => y,
        E::Lit(v) => *v,
        E::Add(a, b) => eval(a, x, y) + eval(b, x, y),
        E::Sub(a, b) => eval(a, x, y) - eval(b, x, y),
        E::Mul(a, b) => eval(a, x, y) * eval(b, x, y),
        E::Div(a, b) => eval(a, x, y) / eval(b, x, y),
        E::Min(a, b) => eval(a, x, y).min(eval(b, x, y)),
        E::Max(a, b) => eval(a, x, y).max(eval(b, x, y)),
        E::Abs(a) => eval(a, x, y).abs(),
        E::Sqrt(a) => eval(a, x, y).sqrt(),
        E::Sin(a) => eval(a, x, y).sin(),
        E::Sel(c, a, b) => {
            if eval(c, x, y) > 0.0 {
                eval(a, x, y)
            } else {
                eval(b, x, y)
            }
        }
    }
}

#[test]
fn random_programs_agree_with_a_reference_evaluator() {
    let mut r = Lcg(0x5eed);
    let mut compared = 0;
    for _ in 0..300 {
        let depth = 1 + r.below(5) as u32;
        let e = random_expr(&mut r, depth);
        let body = wgsl_of(&e);
        // Wrap in a loop and a helper call so control flow is exercised too.
        let src = format!(
            "fn h(x: f32, y: f32, k: f32) -> f32 {{ return {body}; }}
             fn f(x: f32, y: f32, n: i32) -> f32 {{
                 var s = 0.0;
                 for (var i = 0; i < n; i++) {{ s += h(x + f32(i), y, 1.0); }}
                 return s;
             }}"
        );
        let Ok(module) = naga::front::wgsl::parse_str(&src) else {
            // Constant folding may reject e.g. a constant division by zero.
            continue;
        };
        let p = match Program::new(module) {
            Ok(p) => p,
            Err(InterpError::Invalid(_)) => continue,
            Err(e) => panic!("{e}\n{src}"),
        };
        for (x, y) in [(0.5, -1.25), (-2.0, 3.0), (0.0, 0.0), (7.5, 0.25)] {
            let got = p
                .call(
                    "f",
                    &[Value::f(x), Value::f(y), Value::I32(3)],
                    &Limits::default(),
                )
                .unwrap();
            let want: f64 = (0..3).map(|i| eval(&e, x + i as f64, y)).sum();
            let got = got.as_f().unwrap();
            assert!(
                close(got, want, 1e-12),
                "{src}\nx={x} y={y}: {got} vs {want}"
            );
            compared += 1;
        }
    }
    assert!(compared > 800, "{compared}");
}

#[test]
fn random_statement_soup_never_panics() {
    // Random small programs built from loops, switches, array writes with
    // wild indices and integer arithmetic: any result or error is fine, a
    // panic or hang is not.
    let mut r = Lcg(42);
    let stmts = [
        "a[i] = a[(i * 7) % 5] + f32(i);",
        "i = i * 3 + 1;",
        "i = i / (i - 3);",
        "i = i % 0;",
        "i = i << 31u;",
        "i = -i;",
        "if (a[2] > 3.0) { i += 2; } else { i -= 1; }",
        "switch (i & 3) { case 0: { i += 1; } case 1, 2: { a[0] -= 1.0; } default: { break; } }",
        "for (var j = 0; j < 4; j++) { a[j] *= 2.0; if (j == i) { continue; } }",
        "loop { i += 1; if (i > 5) { break; } }",
        "loop { i += 1; continuing { break if i > 100; } }",
        "a[i] = sqrt(a[i]) / a[i + 1];",
        "i = i32(a[1] * 1e30);",
        "a = array<f32, 5>(1.0, 2.0, 3.0, 4.0, 5.0);",
        "loop { }",
    ];
    for _ in 0..300 {
        let mut body = String::new();
        for _ in 0..1 + r.below(6) {
            body.push_str(stmts[r.below(stmts.len() as u64) as usize]);
            body.push('\n');
        }
        let src = format!(
            "fn f(x: f32, k: i32) -> f32 {{
                 var a: array<f32, 5>;
                 var i = k;
                 a[0] = x;
                 {body}
                 return a[0] + a[4] + f32(i);
             }}"
        );
        let Ok(module) = naga::front::wgsl::parse_str(&src) else {
            continue;
        };
        let Ok(p) = Program::new(module) else {
            continue;
        };
        let limits = Limits {
            max_steps: 20_000,
            ..Limits::default()
        };
        for k in [-3, 0, 1, 7, i32::MAX] {
            let _ = p.call("f", &[Value::f(1.5), Value::I32(k)], &limits);
        }
    }
}
