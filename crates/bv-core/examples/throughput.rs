//! Throughput of one model the way `bv bench` measures it (a pool of 2²⁰
//! fixed-seed pairs, chunks of 4096 handed to a rayon pool, best of several
//! ≥ 200 ms runs), on both paths side by side: the f64 scalar `eval_batch`
//! over `(DVec3, DVec3)` pairs (what `bv bench` did before the batch
//! evaluator) and the f32 batch path (`bv_core::batch::eval`, what it does
//! now). Without building the whole application in release mode.
//!
//! Run: `cargo run --release -p bv-core --example throughput -- [THREADS…]`.
//! Prints one JSON line per (path, threads).

use bv_core::batch::{self, Out, PairBuf};
use bv_core::{ModelSpec, Rgb, sampling};
use glam::DVec3;
use rayon::prelude::*;
use std::time::{Duration, Instant};

const CHUNK: usize = 4096;
const PAIRS: usize = 1_000_000;

fn main() -> Result<(), Box<dyn std::error::Error>> {
    let threads: Vec<usize> = std::env::args()
        .skip(1)
        .map(|a| a.parse())
        .collect::<Result<_, _>>()?;
    let threads = if threads.is_empty() {
        vec![1, 2]
    } else {
        threads
    };
    let p = serde_json::json!({"distribution": "ggx", "geometry": "smith", "alpha": 0.3,
        "fresnel": "conductor", "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14]});
    let brdf = ModelSpec::from_json("cook-torrance", &p)?.build()?;
    let mut rng = sampling::rng(0x6276_6265_6e63_6801);
    let pairs: Vec<(DVec3, DVec3)> = (0..PAIRS)
        .map(|_| {
            let wi = sampling::uniform_hemisphere(sampling::uniform2(&mut rng));
            let wo = sampling::uniform_hemisphere(sampling::uniform2(&mut rng));
            (wi, wo)
        })
        .collect();
    let soa = PairBuf::from_pairs(&pairs);
    let chunks = PAIRS.div_ceil(CHUNK);
    for &t in &threads {
        let pool = rayon::ThreadPoolBuilder::new().num_threads(t).build()?;
        let scalar = || {
            pool.install(|| {
                (0..chunks).into_par_iter().for_each_init(
                    || vec![Rgb::ZERO; CHUNK],
                    |out, k| {
                        let r = k * CHUNK..((k + 1) * CHUNK).min(PAIRS);
                        let n = r.len();
                        brdf.eval_batch(&pairs[r], &mut out[..n]);
                        std::hint::black_box(&out);
                    },
                )
            })
        };
        let lanes = || {
            pool.install(|| {
                (0..chunks).into_par_iter().for_each_init(
                    || [vec![0f32; CHUNK], vec![0f32; CHUNK], vec![0f32; CHUNK]],
                    |[r, g, b], k| {
                        let range = k * CHUNK..((k + 1) * CHUNK).min(PAIRS);
                        let mut out = Out {
                            rgb: [&mut r[..], &mut g[..], &mut b[..]],
                        };
                        batch::eval(brdf.as_ref(), &soa.dirs(range), &mut out);
                        std::hint::black_box(&out);
                    },
                )
            })
        };
        for (name, f) in [
            ("f64-scalar", &scalar as &dyn Fn()),
            ("f32-batch", &lanes as &dyn Fn()),
        ] {
            f();
            let mut best = 0.0f64;
            for _ in 0..6 {
                let start = Instant::now();
                let mut passes = 0;
                while start.elapsed() < Duration::from_millis(200) {
                    f();
                    passes += 1;
                }
                best = best.max((passes * PAIRS) as f64 / start.elapsed().as_secs_f64());
            }
            let isa = batch::isa();
            let (isa, width) = (isa.name(), isa.lanes());
            println!(
                "{}",
                serde_json::json!({"path": name, "threads": t, "m_evals_per_second": best / 1e6,
                    "isa": if name == "f32-batch" { isa } else { "scalar" },
                    "lanes": if name == "f32-batch" { width } else { 1 }})
            );
        }
    }
    Ok(())
}
