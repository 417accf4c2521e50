#![allow(clippy::unwrap_used, clippy::expect_used)]
//! One program called from many threads at once: the results agree with a
//! sequential run, and a call's writes to module-scope variables stay in
//! that call.

mod common;

use bv_interp::{Limits, Program, Value};
use common::*;
use rayon::prelude::*;

const SRC: &str = "
var<private> scratch: f32 = 0.0;
var<private> alpha: f32 = 0.25;
fn d(nh: f32) -> f32 {
    let a2 = alpha * alpha;
    let t = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (3.14159265 * t * t);
}
fn f(theta: f32, k: i32) -> f32 {
    // Writes a private global: each call must start from its initial value.
    scratch += theta;
    var s = 0.0;
    for (var i = 0; i < k; i++) { s += d(cos(theta * f32(i + 1) * 0.1)); }
    return s + scratch;
}
";

fn inputs() -> Vec<(f64, i32)> {
    (0..4000).map(|i| (f64::from(i) * 1e-3, i % 13)).collect()
}

fn run(p: &Program, (t, k): (f64, i32)) -> f64 {
    p.call("f", &[Value::f(t), Value::I32(k)], &Limits::default())
        .unwrap()
        .as_f()
        .unwrap()
}

#[test]
fn rayon_threads_agree_with_a_sequential_run() {
    let mut p = wgsl(SRC);
    p.set_global("alpha", Value::f(0.4)).unwrap();
    let seq: Vec<f64> = inputs().into_iter().map(|x| run(&p, x)).collect();
    // Spot check against the formula: k = 0 gives just scratch = theta.
    assert_eq!(seq[13], 13.0 * 1e-3);
    let par: Vec<f64> = inputs().into_par_iter().map(|x| run(&p, x)).collect();
    assert_eq!(seq, par);
}

#[test]
fn std_threads_agree() {
    let p = wgsl(SRC);
    let want: Vec<f64> = inputs().into_iter().map(|x| run(&p, x)).collect();
    std::thread::scope(|s| {
        let handles: Vec<_> = (0..4)
            .map(|t| {
                let p = &p;
                s.spawn(move || {
                    // Each thread walks the inputs in a different order.
                    let mut xs = inputs();
                    xs.rotate_left(t * 997);
                    let mut out: Vec<(usize, f64)> = Vec::new();
                    for (j, x) in xs.into_iter().enumerate() {
                        out.push(((j + t * 997) % 4000, run(p, x)));
                    }
                    out
                })
            })
            .collect();
        for h in handles {
            for (i, v) in h.join().unwrap() {
                assert_eq!(v, want[i]);
            }
        }
    });
}

#[test]
fn program_is_send_and_sync() {
    fn check<T: Send + Sync>() {}
    check::<Program>();
}
