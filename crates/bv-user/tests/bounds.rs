//! The front end's size limits hold the whole pipeline: a file at every
//! limit compiles, is ported to WGSL and is evaluated by the interpreter on
//! a 1 MiB stack (a browser's, and less than a native thread's 2 MiB)
//! without overflowing it, and a file past a limit is refused by name. A
//! property test builds random nested expressions of every depth and checks
//! the same: a result or a refusal, never a crash.

#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_core::Brdf;
use bv_user::bounds::{MAX_NESTING, MAX_OPERATORS};
use proptest::prelude::*;

const STACK: usize = 1 << 20;

fn file(body: &str) -> String {
    format!(
        "analytic\n::begin parameters\nfloat n 0 1 0.5\n::end parameters\n::begin shader\n\
         {body}\n::end shader\n"
    )
}

/// Compiles and evaluates a file on a small stack; the error's text if any
/// step refuses it. A stack overflow aborts the test process.
fn run_small(text: String) -> Result<[f64; 3], String> {
    std::thread::Builder::new()
        .stack_size(STACK)
        .spawn(move || {
            let c = bv_user::compile(&text, "t.brdf").map_err(|e| e.to_string())?;
            let program =
                bv_user::cpu::FileProgram::new(&c, "t.brdf").map_err(|e| e.to_string())?;
            let spec = bv_core::Params::defaults(c.decls);
            let b = program.build("t", &spec).map_err(|e| e.to_string())?;
            let f = b.eval(
                glam::DVec3::new(0.3, 0.2, 0.9).normalize(),
                glam::DVec3::new(-0.1, 0.4, 0.8).normalize(),
            );
            Ok(f.to_array())
        })
        .unwrap()
        .join()
        .unwrap()
}

#[test]
fn files_at_every_limit_compile_and_run_on_a_small_stack() {
    let brdf = |expr: &str| {
        file(&format!(
            "float g(float x) {{ return x * 0.5 + 0.25; }}\n\
             vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ float a = n; return vec3({expr}); }}"
        ))
    };
    // The longest chain of one operator (the `=` of the return and the
    // commas do not count; `a` and `vec3(` add nothing).
    let ops = MAX_OPERATORS - 1;
    let sum = vec!["a"; ops + 1].join("+");
    let f = run_small(brdf(&sum)).unwrap();
    assert!((f[0] - 0.5 * (ops + 1) as f64).abs() < 1e-3, "{f:?}");
    // Alternating operators, right-nested through parentheses as far as the
    // nesting limit allows.
    let depth = MAX_NESTING - 3;
    let nested = format!("{}a{}", "(a*0.5+".repeat(depth), ")".repeat(depth));
    run_small(brdf(&nested)).unwrap();
    // Nested calls.
    let calls = format!("{}a{}", "g(".repeat(depth), ")".repeat(depth));
    let f = run_small(brdf(&calls)).unwrap();
    assert!((f[0] - 0.5).abs() < 1e-6, "g's fixed point is 0.5: {f:?}");
    // A chain of conditionals.
    let ternary = format!("{}a", "a > 2.0 ? 1.0 : ".repeat(ops / 3));
    run_small(brdf(&ternary)).unwrap();
    // Unary minus, a long chain of it.
    let minus = format!("{}a", "- ".repeat(ops));
    run_small(brdf(&minus)).unwrap();
}

#[test]
fn files_past_a_limit_are_refused_by_name() {
    let brdf = |expr: &str| {
        file(&format!(
            "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ float a = n; return vec3({expr}); }}"
        ))
    };
    let e = run_small(brdf(&vec!["a"; 7000].join("+"))).unwrap_err();
    assert!(e.contains("operators") && e.contains("t.brdf:6:"), "{e}");
    let deep = format!("{}a{}", "(".repeat(6000), ")".repeat(6000));
    let e = run_small(brdf(&deep)).unwrap_err();
    assert!(e.contains("nest"), "{e}");
    let stmts = "a = a * 0.5 + 0.25;\n".repeat(20_000);
    let e = run_small(file(&format!(
        "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ float a = n;\n{stmts} return vec3(a); }}"
    )))
    .unwrap_err();
    assert!(e.contains("tokens"), "{e}");
}

/// A random expression over `a` of about `size` nodes: binary and unary
/// operators, parentheses, calls and conditionals, nested at random.
fn expr(size: usize, choices: &[u8]) -> String {
    fn go(size: usize, choices: &[u8], k: &mut usize, out: &mut String) {
        let c = choices[*k % choices.len()];
        *k += 1;
        if size <= 1 {
            out.push_str(if c.is_multiple_of(2) { "a" } else { "0.5" });
            return;
        }
        match c % 6 {
            0 => {
                let left = 1 + (c as usize * 7) % size.max(2);
                let left = left.min(size - 1);
                go(left, choices, k, out);
                out.push_str(["+", "*", "-", "/"][(c as usize / 6) % 4]);
                go(size - left, choices, k, out);
            }
            1 => {
                out.push('(');
                go(size - 1, choices, k, out);
                out.push(')');
            }
            2 => {
                out.push('-');
                go(size - 1, choices, k, out);
            }
            3 => {
                out.push_str("abs(");
                go(size - 1, choices, k, out);
                out.push(')');
            }
            4 => {
                out.push_str("(a > 0.3 ? ");
                go(size / 2, choices, k, out);
                out.push_str(" : ");
                go(size - size / 2, choices, k, out);
                out.push(')');
            }
            _ => {
                out.push_str("max(");
                go(size / 2, choices, k, out);
                out.push_str(", ");
                go((size - size / 2).max(1), choices, k, out);
                out.push(')');
            }
        }
    }
    let mut out = String::new();
    let mut k = 0;
    // The recursion here is the test's own, on the test thread's stack.
    go(size, choices, &mut k, &mut out);
    out
}

proptest! {
    #![proptest_config(ProptestConfig { cases: 64, ..ProptestConfig::default() })]

    #[test]
    fn random_nested_expressions_never_overflow_the_stack(
        size in 1usize..900,
        choices in proptest::collection::vec(any::<u8>(), 1..64),
    ) {
        let e = expr(size, &choices);
        let text = file(&format!(
            "vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) {{ float a = n; return vec3({e}); }}"
        ));
        // Either it runs or it is refused with a message; a crash fails the
        // whole test binary.
        if let Err(msg) = run_small(text) {
            prop_assert!(!msg.is_empty());
        }
    }
}
