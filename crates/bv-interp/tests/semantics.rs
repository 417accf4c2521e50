#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Integer semantics, composites, control flow, calls and module-scope state.

mod common;

use bv_interp::{Kind, Limits, Value, Vector};
use common::*;

fn i(p: &bv_interp::Program, name: &str, args: &[Value]) -> i32 {
    match call(p, name, args) {
        Value::I32(x) => x,
        v => panic!("{name} returned {v:?}"),
    }
}

fn u(p: &bv_interp::Program, name: &str, args: &[Value]) -> u32 {
    match call(p, name, args) {
        Value::U32(x) => x,
        v => panic!("{name} returned {v:?}"),
    }
}

#[test]
fn i32_arithmetic_wraps_and_divides_like_wgsl() {
    let p = wgsl(
        "
        fn add(a: i32, b: i32) -> i32 { return a + b; }
        fn sub(a: i32, b: i32) -> i32 { return a - b; }
        fn mul(a: i32, b: i32) -> i32 { return a * b; }
        fn div(a: i32, b: i32) -> i32 { return a / b; }
        fn rem(a: i32, b: i32) -> i32 { return a % b; }
        fn neg(a: i32) -> i32 { return -a; }
        fn shl(a: i32, b: u32) -> i32 { return a << b; }
        fn shr(a: i32, b: u32) -> i32 { return a >> b; }
        fn band(a: i32, b: i32) -> i32 { return (a & b) | (a ^ b); }
        fn bnot(a: i32) -> i32 { return ~a; }
        fn iabs(a: i32) -> i32 { return abs(a); }
        fn imin(a: i32, b: i32) -> i32 { return min(a, b) + max(a, b) * 0 + clamp(a, -5, 5) * 0; }
        ",
    );
    let vals = [
        i32::MIN,
        i32::MIN + 1,
        -1000,
        -7,
        -1,
        0,
        1,
        3,
        7,
        65536,
        i32::MAX,
    ];
    for &a in &vals {
        let va = Value::I32(a);
        assert_eq!(i(&p, "neg", std::slice::from_ref(&va)), a.wrapping_neg());
        assert_eq!(i(&p, "bnot", std::slice::from_ref(&va)), !a);
        assert_eq!(i(&p, "iabs", std::slice::from_ref(&va)), a.wrapping_abs());
        for &b in &vals {
            let args = [va.clone(), Value::I32(b)];
            assert_eq!(i(&p, "add", &args), a.wrapping_add(b), "{a}+{b}");
            assert_eq!(i(&p, "sub", &args), a.wrapping_sub(b), "{a}-{b}");
            assert_eq!(i(&p, "mul", &args), a.wrapping_mul(b), "{a}*{b}");
            // WGSL: x / 0 == x, MIN / -1 == MIN; x % 0 == 0, MIN % -1 == 0.
            let want_div = if b == 0 || (a == i32::MIN && b == -1) {
                a
            } else {
                a / b
            };
            let want_rem = if b == 0 || (a == i32::MIN && b == -1) {
                0
            } else {
                a % b
            };
            assert_eq!(i(&p, "div", &args), want_div, "{a}/{b}");
            assert_eq!(i(&p, "rem", &args), want_rem, "{a}%{b}");
            assert_eq!(i(&p, "band", &args), (a & b) | (a ^ b));
            assert_eq!(i(&p, "imin", &args), a.min(b));
        }
        for s in [0u32, 1, 5, 31, 32, 33] {
            let args = [va.clone(), Value::U32(s)];
            // Shifts use the low five bits of the amount.
            assert_eq!(i(&p, "shl", &args), a.wrapping_shl(s), "{a}<<{s}");
            assert_eq!(i(&p, "shr", &args), a >> (s % 32), "{a}>>{s}");
        }
    }
    assert_eq!(i(&p, "rem", &[Value::I32(-7), Value::I32(3)]), -1);
}

#[test]
fn u32_arithmetic_and_bits() {
    let p = wgsl(
        "
        fn add(a: u32, b: u32) -> u32 { return a + b; }
        fn sub(a: u32, b: u32) -> u32 { return a - b; }
        fn mul(a: u32, b: u32) -> u32 { return a * b; }
        fn div(a: u32, b: u32) -> u32 { return a / b; }
        fn rem(a: u32, b: u32) -> u32 { return a % b; }
        fn shr(a: u32, b: u32) -> u32 { return a >> b; }
        fn ones(a: u32) -> u32 { return countOneBits(a); }
        fn lz(a: u32) -> u32 { return countLeadingZeros(a); }
        fn tz(a: u32) -> u32 { return countTrailingZeros(a); }
        fn rev(a: u32) -> u32 { return reverseBits(a); }
        fn flb(a: u32) -> u32 { return firstLeadingBit(a); }
        fn ftb(a: u32) -> u32 { return firstTrailingBit(a); }
        fn ext(a: u32, o: u32, c: u32) -> u32 { return extractBits(a, o, c); }
        fn ins(a: u32, b: u32, o: u32, c: u32) -> u32 { return insertBits(a, b, o, c); }
        fn sext(a: i32, o: u32, c: u32) -> i32 { return extractBits(a, o, c); }
        fn sflb(a: i32) -> i32 { return firstLeadingBit(a); }
        ",
    );
    let vals = [
        0u32,
        1,
        2,
        7,
        0x8000_0000,
        0xdead_beef,
        u32::MAX - 1,
        u32::MAX,
    ];
    for &a in &vals {
        let va = Value::U32(a);
        assert_eq!(u(&p, "ones", std::slice::from_ref(&va)), a.count_ones());
        assert_eq!(u(&p, "lz", std::slice::from_ref(&va)), a.leading_zeros());
        assert_eq!(u(&p, "tz", std::slice::from_ref(&va)), a.trailing_zeros());
        assert_eq!(u(&p, "rev", std::slice::from_ref(&va)), a.reverse_bits());
        let flb = if a == 0 {
            u32::MAX
        } else {
            31 - a.leading_zeros()
        };
        assert_eq!(u(&p, "flb", std::slice::from_ref(&va)), flb);
        let ftb = if a == 0 { u32::MAX } else { a.trailing_zeros() };
        assert_eq!(u(&p, "ftb", std::slice::from_ref(&va)), ftb);
        for &b in &vals {
            let args = [va.clone(), Value::U32(b)];
            assert_eq!(u(&p, "add", &args), a.wrapping_add(b));
            assert_eq!(u(&p, "sub", &args), a.wrapping_sub(b));
            assert_eq!(u(&p, "mul", &args), a.wrapping_mul(b));
            assert_eq!(u(&p, "div", &args), a.checked_div(b).unwrap_or(a));
            assert_eq!(u(&p, "rem", &args), if b == 0 { 0 } else { a % b });
            assert_eq!(u(&p, "shr", &args), a >> (b % 32));
        }
    }
    // extractBits / insertBits against bit-by-bit definitions.
    for &(a, o, c) in &[
        (0xdead_beefu32, 4u32, 8u32),
        (0xffff_0000, 12, 8),
        (0x1234_5678, 0, 32),
        (5, 3, 0),
        (0xf0, 28, 10),
    ] {
        let oo = o.min(32);
        let cc = c.min(32 - oo);
        let mut want = 0u32;
        for k in 0..cc {
            want |= ((a >> (oo + k)) & 1) << k;
        }
        assert_eq!(
            u(&p, "ext", &[Value::U32(a), Value::U32(o), Value::U32(c)]),
            want
        );
        let mut sw = want;
        if cc > 0 && cc < 32 && (want >> (cc - 1)) & 1 == 1 {
            for k in cc..32 {
                sw |= 1 << k;
            }
        }
        let got = i(
            &p,
            "sext",
            &[Value::I32(a as i32), Value::U32(o), Value::U32(c)],
        );
        assert_eq!(got, sw as i32, "sext({a:#x},{o},{c})");
        let nb = 0x5555_5555u32;
        let mut wi = a;
        for k in 0..cc {
            let bit = (nb >> k) & 1;
            wi = (wi & !(1 << (oo + k))) | (bit << (oo + k));
        }
        assert_eq!(
            u(
                &p,
                "ins",
                &[Value::U32(a), Value::U32(nb), Value::U32(o), Value::U32(c)]
            ),
            wi
        );
    }
    for (a, want) in [
        (0, -1),
        (-1, -1),
        (1, 0),
        (5, 2),
        (-2, 0),
        (-6, 2),
        (i32::MIN, 30),
    ] {
        assert_eq!(
            i(&p, "sflb", &[Value::I32(a)]),
            want,
            "firstLeadingBit({a})"
        );
    }
}

#[test]
fn conversions_and_bitcasts() {
    let p = wgsl(
        "
        fn f2i(x: f32) -> i32 { return i32(x); }
        fn f2u(x: f32) -> u32 { return u32(x); }
        fn i2f(x: i32) -> f32 { return f32(x); }
        fn u2i(x: u32) -> i32 { return i32(x); }
        fn i2u(x: i32) -> u32 { return u32(x); }
        fn bits(x: f32) -> u32 { return bitcast<u32>(x); }
        fn from_bits(x: u32) -> f32 { return bitcast<f32>(x); }
        fn b2f(b: bool) -> f32 { return f32(b) + 2.0 * f32(!b); }
        fn f2b(x: f32) -> bool { return bool(x); }
        ",
    );
    for (x, want) in [
        (3.7, 3),
        (-3.7, -3),
        (1e20, i32::MAX),
        (-1e20, i32::MIN),
        (f64::NAN, 0),
    ] {
        assert_eq!(i(&p, "f2i", &[Value::f(x)]), want, "i32({x})");
    }
    for (x, want) in [(3.7, 3), (-3.7, 0), (1e20, u32::MAX)] {
        assert_eq!(u(&p, "f2u", &[Value::f(x)]), want, "u32({x})");
    }
    assert_eq!(
        call_f(&p, "i2f", &[Value::I32(-123_456_789)]),
        -123_456_789.0
    );
    assert_eq!(i(&p, "u2i", &[Value::U32(u32::MAX)]), -1);
    assert_eq!(u(&p, "i2u", &[Value::I32(-2)]), u32::MAX - 1);
    assert_eq!(u(&p, "bits", &[Value::f(1.0)]), 0x3f80_0000);
    assert_eq!(u(&p, "bits", &[Value::f(-2.5)]), (-2.5f32).to_bits());
    assert_eq!(
        call_f(&p, "from_bits", &[Value::U32(0x4049_0fdb)]),
        f64::from(f32::from_bits(0x4049_0fdb))
    );
    assert_eq!(call_f(&p, "b2f", &[Value::Bool(true)]), 1.0);
    assert_eq!(call_f(&p, "b2f", &[Value::Bool(false)]), 2.0);
    assert_eq!(call(&p, "f2b", &[Value::f(0.0)]), Value::Bool(false));
    assert_eq!(call(&p, "f2b", &[Value::f(-0.5)]), Value::Bool(true));
}

#[test]
fn swizzles_compose_and_splat() {
    let p = wgsl(
        "
        fn sw(v: vec4<f32>) -> vec4<f32> { return v.wzyx + vec4(v.xy, v.zz) * 10.0; }
        fn sw2(v: vec3<f32>) -> vec2<f32> { return v.zx; }
        fn wr(v: vec3<f32>) -> vec3<f32> { var w = v; w.y = 7.0; w.x += w.z; return w; }
        fn sp(x: f32) -> vec3<f32> { return vec3(x) + vec3<f32>(1.0, 2.0, 3.0); }
        fn iv(a: vec3<i32>) -> vec3<i32> { return a * vec3(2, -1, 3) + 1; }
        fn dyn_idx(v: vec4<f32>, i: u32) -> f32 { return v[i]; }
        fn dyn_store(i: i32) -> vec3<f32> { var v = vec3(1.0, 2.0, 3.0); v[i] = 9.0; return v; }
        ",
    );
    let r = call(&p, "sw", &[Value::vec4(1.0, 2.0, 3.0, 4.0)]);
    assert_eq!(r.as_vec(), Some(&[14.0, 23.0, 32.0, 31.0][..]));
    assert_eq!(
        call(&p, "sw2", &[Value::vec3(1.0, 2.0, 3.0)]).as_vec(),
        Some(&[3.0, 1.0][..])
    );
    assert_eq!(
        call(&p, "wr", &[Value::vec3(1.0, 2.0, 3.0)]).as_vec3(),
        Some([4.0, 7.0, 3.0])
    );
    assert_eq!(
        call(&p, "sp", &[Value::f(0.5)]).as_vec3(),
        Some([1.5, 2.5, 3.5])
    );
    let iv = call(
        &p,
        "iv",
        &[Value::Vec(
            Vector::new(Kind::I32, &[1.0, 2.0, -3.0]).unwrap(),
        )],
    );
    assert_eq!(
        iv,
        Value::Vec(Vector::new(Kind::I32, &[3.0, -1.0, -8.0]).unwrap())
    );
    for k in 0..6u32 {
        let got = call_f(
            &p,
            "dyn_idx",
            &[Value::vec4(1.0, 2.0, 3.0, 4.0), Value::U32(k)],
        );
        // Out-of-range indices are clamped to the last component.
        assert_eq!(got, f64::from(k.min(3) + 1));
    }
    assert_eq!(
        call(&p, "dyn_store", &[Value::I32(1)]).as_vec3(),
        Some([1.0, 9.0, 3.0])
    );
}

#[test]
fn loops_with_continuing_and_break_if() {
    let p = wgsl(
        "
        fn sum_skip3(n: i32) -> i32 {
            var s = 0;
            for (var i = 0; i < n; i++) { if (i == 3) { continue; } s += i; }
            return s;
        }
        fn break_if(n: i32) -> i32 {
            var i = 0; var s = 0;
            loop { s += i; continuing { i += 1; break if i >= n; } }
            return s;
        }
        fn halve(x: f32) -> f32 { var y = x; while (y > 1.0) { y *= 0.5; } return y; }
        fn nested(n: i32) -> i32 {
            var c = 0;
            for (var i = 0; i < n; i++) {
                for (var j = 0; j < n; j++) { if (j > i) { break; } c += 1; }
            }
            return c;
        }
        fn early(n: i32) -> i32 { for (var i = 0; i < 100; i++) { if (i * i >= n) { return i; } } return -1; }
        ",
    );
    for n in 0..10 {
        let want: i32 = (0..n).filter(|&k| k != 3).sum();
        assert_eq!(i(&p, "sum_skip3", &[Value::I32(n)]), want);
        // The body runs before the first break_if check: 0 + 1 + … + (n-1),
        // at least once.
        let want: i32 = (0..n.max(1)).sum();
        assert_eq!(i(&p, "break_if", &[Value::I32(n)]), want);
        assert_eq!(i(&p, "nested", &[Value::I32(n)]), n * (n + 1) / 2);
        let want = (0..100).find(|k| k * k >= n).unwrap_or(-1);
        assert_eq!(i(&p, "early", &[Value::I32(n)]), want);
    }
    assert_eq!(call_f(&p, "halve", &[Value::f(40.0)]), 0.625);
}

#[test]
fn glsl_switch_fallthrough_and_do_while() {
    let p = glsl(
        "
        int sw(int x) {
            int r = 0;
            switch (x) {
                case 0: r += 1;
                case 1: r += 10; break;
                case 2: r += 100;
                default: r += 1000; break;
                case 4: r += 10000;
            }
            return r;
        }
        int dw(int n) { int i = 0; int s = 0; do { s += i; i++; } while (i < n); return s; }
        int loopsw(int n) {
            int s = 0;
            for (int i = 0; i < n; i++) {
                switch (i) { case 2: continue; default: s += i; }
            }
            return s;
        }
        ",
    );
    for (x, want) in [
        (0, 11),
        (1, 10),
        (2, 1100),
        (3, 1000),
        (4, 10000),
        (-7, 1000),
    ] {
        assert_eq!(i(&p, "sw", &[Value::I32(x)]), want, "sw({x})");
    }
    assert_eq!(i(&p, "dw", &[Value::I32(0)]), 0);
    assert_eq!(i(&p, "dw", &[Value::I32(5)]), 10);
    assert_eq!(i(&p, "loopsw", &[Value::I32(6)]), 1 + 3 + 4 + 5);
}

#[test]
fn wgsl_switch_with_default_in_the_middle() {
    let p = wgsl(
        "
        fn sw(x: u32) -> u32 {
            switch x { case 1u, 2u: { return 12u; } default: { return 99u; } case 3u: { return 3u; } }
        }
        ",
    );
    for (x, want) in [(1, 12), (2, 12), (3, 3), (0, 99), (4, 99)] {
        assert_eq!(u(&p, "sw", &[Value::U32(x)]), want);
    }
}

#[test]
fn nested_calls_and_pointer_arguments() {
    let p = wgsl(
        "
        fn sq(x: f32) -> f32 { return x * x; }
        fn hyp(a: f32, b: f32) -> f32 { return sqrt(sq(a) + sq(b)); }
        fn inc(p: ptr<function, f32>) { *p = *p + 1.0; }
        fn twice(x: f32) -> f32 { var y = x; inc(&y); inc(&y); return hyp(y, 4.0); }
        fn set_elem(a: ptr<function, array<f32, 3>>, i: i32, v: f32) { (*a)[i] = v; }
        fn arr(i: i32) -> f32 { var a = array<f32, 3>(1.0, 2.0, 3.0); set_elem(&a, i, 10.0); return a[0] + a[1] + a[2]; }
        ",
    );
    assert_eq!(call_f(&p, "hyp", &[Value::f(3.0), Value::f(4.0)]), 5.0);
    assert_eq!(call_f(&p, "twice", &[Value::f(1.0)]), 5.0);
    assert_eq!(call_f(&p, "arr", &[Value::I32(1)]), 14.0);
    assert_eq!(call_f(&p, "arr", &[Value::I32(2)]), 13.0);
}

#[test]
fn structs_and_arrays() {
    let p = wgsl(
        "
        struct S { a: f32, b: vec3<f32>, c: array<f32, 3>, d: i32 }
        fn st(x: f32) -> f32 {
            var s: S;
            s.a = x;
            s.b = vec3(1.0, 2.0, 3.0) * x;
            s.c[1] = 5.0;
            let t = s;
            s.a = 100.0;
            return t.a + t.b.y + t.c[1] + s.c[0];
        }
        fn mk(x: f32) -> S { return S(x, vec3(x, 2.0 * x, 3.0), array<f32, 3>(1.0, 2.0, x), 7); }
        fn get_b(s: S) -> vec3<f32> { return s.b; }
        fn arr_val(i: i32) -> f32 { let a = array<f32, 4>(1.0, 2.0, 4.0, 8.0); return a[i]; }
        fn arr_var(i: i32) -> f32 { var a = array<f32, 4>(1.0, 2.0, 4.0, 8.0); a[i] *= 3.0; return a[0] + a[1] + a[2] + a[3]; }
        fn nested(i: i32, j: i32) -> f32 {
            var m: array<array<f32, 3>, 2>;
            for (var r = 0; r < 2; r++) { for (var c = 0; c < 3; c++) { m[r][c] = f32(r * 10 + c); } }
            return m[i][j];
        }
        ",
    );
    assert_eq!(call_f(&p, "st", &[Value::f(2.0)]), 2.0 + 4.0 + 5.0 + 0.0);
    let s = call(&p, "mk", &[Value::f(1.5)]);
    let want = Value::Struct(vec![
        Value::f(1.5),
        Value::vec3(1.5, 3.0, 3.0),
        Value::Array(vec![Value::f(1.0), Value::f(2.0), Value::f(1.5)]),
        Value::I32(7),
    ]);
    assert_eq!(s, want);
    assert_eq!(call(&p, "get_b", &[want]).as_vec3(), Some([1.5, 3.0, 3.0]));
    for k in 0..4 {
        assert_eq!(
            call_f(&p, "arr_val", &[Value::I32(k)]),
            [1.0, 2.0, 4.0, 8.0][k as usize]
        );
        assert_eq!(
            call_f(&p, "arr_var", &[Value::I32(k)]),
            15.0 + 2.0 * [1.0, 2.0, 4.0, 8.0][k as usize]
        );
    }
    for r in 0..2 {
        for c in 0..3 {
            assert_eq!(
                call_f(&p, "nested", &[Value::I32(r), Value::I32(c)]),
                f64::from(r * 10 + c)
            );
        }
    }
}

#[test]
fn constants_and_globals() {
    let mut p = wgsl(
        "
        const K: f32 = 0.5;
        const V = vec3<f32>(1.0, 2.0, 3.0);
        const A = array<i32, 3>(4, 5, 6);
        var<private> g: f32 = 2.0;
        var<private> counter: i32 = 0;
        struct P { r: f32, k: vec3<f32> }
        var<private> params: P = P(1.0, vec3(0.0));
        fn f(x: f32) -> f32 { return x * K + V.y + f32(A[1]) + g; }
        fn bump() -> i32 { counter += 1; g = 100.0; return counter; }
        fn pr() -> f32 { return params.r + params.k.z; }
        ",
    );
    assert_eq!(call_f(&p, "f", &[Value::f(2.0)]), 1.0 + 2.0 + 5.0 + 2.0);
    // A call that writes globals does not leak into the next one.
    assert_eq!(i(&p, "bump", &[]), 1);
    assert_eq!(i(&p, "bump", &[]), 1);
    assert_eq!(call_f(&p, "f", &[Value::f(2.0)]), 10.0);
    p.set_global("g", Value::f(-1.0)).unwrap();
    p.set_global("counter", Value::I32(41)).unwrap();
    assert_eq!(call_f(&p, "f", &[Value::f(2.0)]), 7.0);
    assert_eq!(i(&p, "bump", &[]), 42);
    p.set_global(
        "params",
        Value::Struct(vec![Value::f(2.0), Value::vec3(0.0, 0.0, 0.25)]),
    )
    .unwrap();
    assert_eq!(call_f(&p, "pr", &[]), 2.25);
    assert!(p.set_global("g", Value::I32(1)).is_err());
    assert!(p.set_global("nope", Value::f(1.0)).is_err());
    let _ = Limits::default();
}

#[test]
fn glsl_globals_uniform_blocks_and_consts() {
    let mut p = glsl(
        "
        const float K = 0.25;
        float n;
        layout(set = 0, binding = 0) uniform float loose;
        layout(set = 0, binding = 1) uniform Params { float rough; vec3 tint; };
        vec3 f(vec3 x) { return x * n * K + loose + rough * tint; }
        ",
    );
    p.set_global("n", Value::f(4.0)).unwrap();
    p.set_global("loose", Value::f(0.5)).unwrap();
    p.set_global("rough", Value::f(2.0)).unwrap();
    p.set_global("tint", Value::vec3(1.0, 0.0, 0.5)).unwrap();
    let r = call(&p, "f", &[Value::vec3(1.0, 2.0, 3.0)])
        .as_vec3()
        .unwrap();
    assert_eq!(r, [1.0 + 0.5 + 2.0, 2.0 + 0.5, 3.0 + 0.5 + 1.0]);
    assert!(matches!(
        p.set_global("n", Value::vec3(0.0, 0.0, 0.0)),
        Err(bv_interp::InterpError::Type { .. })
    ));
}

#[test]
fn locals_start_at_zero_whatever_earlier_calls_left() {
    // Two programs alternate on one thread, so they share its memory.
    let a = wgsl(
        "fn junk(x: f32) -> f32 {
             var a: array<f32, 64>;
             for (var i = 0; i < 64; i++) { a[i] = x; }
             return a[63];
         }",
    );
    let b = wgsl(
        "fn z(k: i32) -> f32 {
             var a: array<f32, 64>;
             var s = 0.0;
             for (var i = 0; i < 64; i++) { s += a[i]; }
             var v: vec3<f32>;
             return s + v.y + f32(k);
         }",
    );
    for k in 0..5 {
        assert_eq!(
            call_f(&a, "junk", &[Value::f(123.0 + f64::from(k))]),
            123.0 + f64::from(k)
        );
        assert_eq!(call_f(&b, "z", &[Value::I32(k)]), f64::from(k));
    }
}

#[test]
fn negative_zero_constants_keep_their_sign() {
    let p = wgsl("fn nz(x: f32) -> f32 { return x / -0.0; }");
    assert_eq!(call_f(&p, "nz", &[Value::f(1.0)]), f64::NEG_INFINITY);
}

#[test]
fn glsl_out_parameters_implicit_conversions_and_bool_globals() {
    let mut p = glsl(
        "
        const float PI = 3.14159265358979323846;
        bool useHalf;
        vec3 baseColor;
        void split(float x, out float whole, inout float acc) { whole = floor(x); acc += x - whole; }
        float f(float x) {
            float w; float acc = 1;
            split(x, w, acc);
            float g = min(1.0, 2*x / 3);
            if (useHalf) g *= 0.5;
            return w + acc + g + baseColor.g;
        }
        ",
    );
    p.set_global("baseColor", Value::vec3(0.0, 0.25, 0.0))
        .unwrap();
    let want = |x: f64, half: bool| {
        let g = (2.0 * x / 3.0).min(1.0) * if half { 0.5 } else { 1.0 };
        x.floor() + 1.0 + (x - x.floor()) + g + 0.25
    };
    for x in [0.25, 1.75, -2.5] {
        p.set_global("useHalf", Value::Bool(false)).unwrap();
        assert!(close(
            call_f(&p, "f", &[Value::f(x)]),
            want(x, false),
            1e-15
        ));
        p.set_global("useHalf", Value::Bool(true)).unwrap();
        assert!(close(call_f(&p, "f", &[Value::f(x)]), want(x, true), 1e-15));
    }
}

#[test]
fn relational_functions_and_vector_select() {
    let p = glsl(
        "
        bool anynan(vec3 v) { return any(isnan(v)); }
        bool allinf(vec3 v) { return all(isinf(v)); }
        bool below(vec3 a, vec3 b) { return all(lessThan(a, b)); }
        vec3 pick(vec3 a, vec3 b) { return mix(a, b, greaterThan(a, b)); }
        ",
    );
    let inf = f64::INFINITY;
    let b = |v: Value| match v {
        Value::Bool(x) => x,
        v => panic!("{v:?}"),
    };
    assert!(!b(call(&p, "anynan", &[Value::vec3(1.0, inf, 0.0)])));
    assert!(b(call(&p, "anynan", &[Value::vec3(1.0, f64::NAN, 0.0)])));
    assert!(b(call(&p, "allinf", &[Value::vec3(inf, -inf, inf)])));
    assert!(!b(call(&p, "allinf", &[Value::vec3(inf, 1.0, inf)])));
    assert!(b(call(
        &p,
        "below",
        &[Value::vec3(0.0, 1.0, 2.0), Value::vec3(1.0, 2.0, 3.0)]
    )));
    assert!(!b(call(
        &p,
        "below",
        &[Value::vec3(0.0, 2.0, 2.0), Value::vec3(1.0, 2.0, 3.0)]
    )));
    // mix with a boolean vector selects per component (the larger here).
    let m = call(
        &p,
        "pick",
        &[Value::vec3(5.0, 1.0, 3.0), Value::vec3(2.0, 4.0, 3.0)],
    );
    assert_eq!(m.as_vec3(), Some([2.0, 1.0, 3.0]));
    let q = wgsl(
        "fn sel(a: vec3<f32>, b: vec3<f32>, c: vec3<bool>) -> vec3<f32> { return select(a, b, c); }
         struct S { w: f32, v: vec3<f32> }
         fn arr_of_structs(i: i32, x: f32) -> f32 {
             var ss: array<S, 3>;
             ss[i].v.y = x;
             ss[(i + 1) % 3].w = 2.0 * x;
             return ss[i].v.y + ss[0].w + ss[1].w + ss[2].w;
         }",
    );
    let c = Value::Vec(Vector::new(Kind::Bool, &[1.0, 0.0, 1.0]).unwrap());
    let s = call(
        &q,
        "sel",
        &[Value::vec3(1.0, 2.0, 3.0), Value::vec3(4.0, 5.0, 6.0), c],
    );
    assert_eq!(s.as_vec3(), Some([4.0, 2.0, 6.0]));
    for i in 0..3 {
        assert_eq!(
            call_f(&q, "arr_of_structs", &[Value::I32(i), Value::f(1.5)]),
            4.5
        );
    }
}

#[test]
fn overrides_take_their_default_values() {
    let p = wgsl(
        "override k: f32 = 2.5;
         override twice_k = k * 2.0;
         fn f(x: f32) -> f32 { return x * k + twice_k; }",
    );
    assert_eq!(call_f(&p, "f", &[Value::f(2.0)]), 10.0);
    let module =
        naga::front::wgsl::parse_str("override k: f32; fn f(x: f32) -> f32 { return x * k; }")
            .unwrap();
    let e = bv_interp::Program::new(module).err().unwrap();
    assert!(e.to_string().contains("override `k`"), "{e}");
}

#[test]
fn global_arrays_and_pointers_to_globals() {
    let mut p = wgsl(
        "var<private> table: array<f32, 4> = array<f32, 4>(1.0, 2.0, 3.0, 4.0);
         var<private> acc: f32 = 0.0;
         fn add_to(p: ptr<private, f32>, x: f32) { *p += x; }
         fn f(i: i32) -> f32 { add_to(&acc, table[i]); add_to(&acc, table[i]); return acc; }",
    );
    for i in 0..4 {
        assert_eq!(call_f(&p, "f", &[Value::I32(i)]), 2.0 * f64::from(i + 1));
    }
    let t = Value::Array(vec![
        Value::f(0.5),
        Value::f(-1.0),
        Value::f(8.0),
        Value::f(0.0),
    ]);
    p.set_global("table", t).unwrap();
    assert_eq!(call_f(&p, "f", &[Value::I32(2)]), 16.0);
    let short = Value::Array(vec![Value::f(0.5)]);
    assert!(matches!(
        p.set_global("table", short),
        Err(bv_interp::InterpError::Type { .. })
    ));
}

/// Loads that may not read a variable in place: stored again, loaded before
/// its store, stored in a loop, passed by pointer, stored in part.
#[test]
fn loads_see_the_value_at_the_time_of_the_load() {
    let p = wgsl(
        "fn inc(p: ptr<function, f32>) { *p += 1.0; }
         fn twice(x: f32) -> f32 { var y = x; let a = y; y = 5.0; return a + y; }
         fn before(x: f32) -> f32 { var y: f32; let a = y; y = x; return a + y; }
         fn in_loop(n: i32) -> f32 {
             var y: f32; var s = 0.0;
             for (var i = 0; i < n; i++) { let b = y; y = f32(i); s += b; }
             return s;
         }
         fn escaped(x: f32) -> f32 { var y: f32; y = x; let a = y; inc(&y); return a * 10.0 + y; }
         fn partial(x: f32) -> f32 { var v: vec3<f32>; v = vec3(x); let a = v; v.y = 2.0; return a.y + v.y; }
         fn once(x: f32) -> f32 { var y: f32; y = x * 2.0; let a = y; return a + y; }",
    );
    let x = 1.5;
    assert_eq!(call_f(&p, "twice", &[Value::f(x)]), x + 5.0);
    assert_eq!(call_f(&p, "before", &[Value::f(x)]), x);
    // s = 0 + 0 + 1 + … + (n - 2).
    assert_eq!(call_f(&p, "in_loop", &[Value::I32(5)]), 6.0);
    assert_eq!(call_f(&p, "escaped", &[Value::f(x)]), x * 10.0 + x + 1.0);
    assert_eq!(call_f(&p, "partial", &[Value::f(x)]), x + 2.0);
    assert_eq!(call_f(&p, "once", &[Value::f(x)]), 4.0 * x);
    let q = glsl("float f(float x) { float y = x; float a = y; y = 5.0; return a + y; }");
    assert_eq!(call_f(&q, "f", &[Value::f(x)]), x + 5.0);
}
