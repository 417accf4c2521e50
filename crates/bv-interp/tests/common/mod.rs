//! Building programs from WGSL and GLSL sources for the tests.
#![allow(clippy::unwrap_used, clippy::expect_used, dead_code)]

use bv_interp::{Limits, Program, Value};

/// A program from WGSL source (panics with naga's message on a parse error).
pub fn wgsl(src: &str) -> Program {
    let module = naga::front::wgsl::parse_str(src)
        .unwrap_or_else(|e| panic!("WGSL parse error: {}", e.emit_to_string(src)));
    Program::new(module).unwrap_or_else(|e| panic!("Program::new: {e}"))
}

/// A naga module from a GLSL 450 fragment shader source; `void main(){}` is
/// appended (naga's GLSL front end needs an entry point).
pub fn glsl_module(src: &str) -> naga::Module {
    let full = format!("#version 450\n{src}\nvoid main() {{}}\n");
    let mut fe = naga::front::glsl::Frontend::default();
    fe.parse(
        &naga::front::glsl::Options::from(naga::ShaderStage::Fragment),
        &full,
    )
    .unwrap_or_else(|e| panic!("GLSL parse error: {}", e.emit_to_string(&full)))
}

/// A program from GLSL source (see [`glsl_module`]).
pub fn glsl(src: &str) -> Program {
    Program::new(glsl_module(src)).unwrap_or_else(|e| panic!("Program::new: {e}"))
}

/// Calls `name` with the default limits, panicking on an error.
pub fn call(p: &Program, name: &str, args: &[Value]) -> Value {
    p.call(name, args, &Limits::default())
        .unwrap_or_else(|e| panic!("call {name}: {e}"))
}

/// Calls a function returning a float.
pub fn call_f(p: &Program, name: &str, args: &[Value]) -> f64 {
    let v = call(p, name, args);
    v.as_f().unwrap_or_else(|| panic!("{name} returned {v:?}"))
}

/// Relative closeness (absolute below `tol` for values near zero).
pub fn close(a: f64, b: f64, tol: f64) -> bool {
    if a.is_nan() || b.is_nan() {
        return a.is_nan() && b.is_nan();
    }
    if a.is_infinite() || b.is_infinite() {
        return a == b;
    }
    (a - b).abs() <= tol * a.abs().max(b.abs()).max(1.0)
}
