//! The `.brdf` front end on arbitrary text: `bv_user::compile` (container,
//! size bounds, naga, safety checks, the WGSL port, the sampler) must return
//! a result or an error, never panic or overflow the stack, and whatever it
//! accepts must build and evaluate within the interpreter's limits.

#![no_main]

use bv_core::Brdf;
use libfuzzer_sys::fuzz_target;

fuzz_target!(|data: &[u8]| {
    let Ok(text) = std::str::from_utf8(data) else {
        return;
    };
    let Ok(c) = bv_user::compile(text, "fuzz.brdf") else {
        return;
    };
    let Ok(program) = bv_user::cpu::FileProgram::new(&c, "fuzz.brdf") else {
        return;
    };
    let params = bv_core::Params::defaults(c.decls);
    let Ok(b) = program.build("fuzz", &params) else {
        return;
    };
    let wi = glam::DVec3::new(0.3, 0.2, 0.9).normalize();
    let wo = glam::DVec3::new(-0.4, 0.1, 0.8).normalize();
    let _ = b.eval(wi, wo);
    let _ = b.try_eval(wo, wi);
});
