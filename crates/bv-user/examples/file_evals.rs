#![allow(clippy::unwrap_used, clippy::expect_used)]
//! Times the CPU evaluation of `.brdf` files (the interpreter through
//! `FileBrdf::eval`, as `bv check` calls it) on one core and prints
//! evaluations per second for each file at its default parameters.
//!
//! `cargo run -p bv-user --example file_evals -- F.brdf [G.brdf …]`
//! (200,000 evaluations of each; `BV_EVALS=N` for another count).

use bv_core::ModelSpec;
use glam::DVec3;
use std::time::Instant;

fn main() {
    let evals: usize = std::env::var("BV_EVALS")
        .ok()
        .and_then(|v| v.parse().ok())
        .unwrap_or(200_000);
    // Fixed direction pairs above the horizon (golden-angle spiral).
    let dirs: Vec<DVec3> = (0..1024)
        .map(|i| {
            let t = f64::from(i) / 1024.0 * 1.5;
            let p = f64::from(i) * 2.399_963;
            DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos())
        })
        .collect();
    for path in std::env::args().skip(1) {
        let info = match bv_user::load(std::path::Path::new(&path)) {
            Ok(i) => i,
            Err(e) => {
                println!("{path}: {e}");
                continue;
            }
        };
        let b = ModelSpec::defaults(info).build().unwrap();
        let mut sink = 0.0;
        let t = Instant::now();
        for k in 0..evals {
            let f = b.eval(dirs[k % 1024], dirs[(k * 7 + 3) % 1024]);
            sink += f.x;
        }
        let dt = t.elapsed().as_secs_f64();
        println!(
            "{path}: {:.0} evals/s ({:.2} us each; checksum {sink:.6})",
            evals as f64 / dt,
            dt / evals as f64 * 1e6
        );
    }
}
