#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Times the interpreter on a Cook–Torrance (GGX) BRDF and a BRDF Explorer
//! Blinn–Phong on one core and prints evaluations per second.
//!
//! `cargo run --release -p bv-interp --example evals_per_second [EVALS]`
//! (a million evaluations of each by default).

use std::time::Instant;

use bv_interp::{Limits, Program, Value};

fn main() {
    let ggx = naga::front::wgsl::parse_str(include_str!("ggx.wgsl")).unwrap();
    let ggx = Program::new(ggx).unwrap();
    let blinn_src = "#version 450
float n = 40.0;
vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)
{
    vec3 H = normalize(L + V);
    float val = pow(max(0.0, dot(N, H)), n);
    val *= (n + 2.0) / (2.0 * 3.14159);
    return vec3(val);
}
void main() {}
";
    let blinn = naga::front::glsl::Frontend::default()
        .parse(
            &naga::front::glsl::Options::from(naga::ShaderStage::Fragment),
            blinn_src,
        )
        .unwrap();
    let blinn = Program::new(blinn).unwrap();
    let limits = Limits::default();
    let n = Value::vec3(0.0, 0.0, 1.0);
    let dirs: Vec<Value> = (0..1024)
        .map(|i| {
            let t = f64::from(i) / 1024.0 * 1.5;
            let p = f64::from(i) * 0.618;
            Value::vec3(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
        })
        .collect();
    for (name, prog, func, extra) in [
        ("GGX Cook-Torrance (WGSL)", &ggx, "brdf", 0),
        (
            "Blinn-Phong (GLSL, BRDF Explorer signature)",
            &blinn,
            "BRDF",
            2,
        ),
    ] {
        let mut args = vec![dirs[0].clone(), dirs[1].clone(), n.clone()];
        for _ in 0..extra {
            args.push(Value::vec3(1.0, 0.0, 0.0));
        }
        let evals: usize = std::env::args()
            .nth(1)
            .and_then(|a| a.parse().ok())
            .unwrap_or(1_000_000);
        let mut sink = 0.0;
        let t = Instant::now();
        for i in 0..evals {
            args[0] = dirs[i % 1024].clone();
            args[1] = dirs[(i * 7 + 3) % 1024].clone();
            let v = prog.call(func, &args, &limits).unwrap();
            sink += v.as_vec3().unwrap()[0];
        }
        let dt = t.elapsed().as_secs_f64();
        println!(
            "{name}: {:.0} evals/s ({:.2} us each; checksum {sink:.6})",
            evals as f64 / dt,
            dt / evals as f64 * 1e6
        );
    }
}
