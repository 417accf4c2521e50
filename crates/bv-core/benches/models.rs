//! Speed of every model of the catalogue: evaluations per second on
//! one core, lobe mesh construction, and ρhd curves.
//!
//! Targets reported against (never asserted: machines are noisy): a lobe mesh
//! of 128 × 256 in ≤ 1 ms for every analytic model, Cook-Torrance GGX at
//! ≥ 50 M evaluations/s on one core.
//!
//! Run: `cargo bench -p bv-core -- --quick` (or a filter such as `eval/`).

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_core::analysis::albedo;
use bv_core::lobe::{self, LobeOptions};
use bv_core::params::ParamKind;
use bv_core::{Brdf, ModelInfo, ModelSpec, Rgb, catalogue, frame, sampling};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use glam::DVec3;
use std::hint::black_box;
use std::time::Duration;

/// Pairs per evaluation batch.
const PAIRS: usize = 1_000_000;

/// Fixed-seed pairs of directions drawn uniformly on the upper hemisphere
/// (the same pairs for every model and every run).
fn random_pairs(n: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
    let mut rng = sampling::rng(seed);
    (0..n)
        .map(|_| {
            let wi = sampling::uniform_hemisphere(sampling::uniform2(&mut rng));
            let wo = sampling::uniform_hemisphere(sampling::uniform2(&mut rng));
            (wi, wo)
        })
        .collect()
}

/// Measured models read a file; everything else is analytic.
fn analytic(m: &ModelInfo) -> bool {
    !m.params
        .iter()
        .any(|d| matches!(d.kind, ParamKind::Path { .. }))
}

/// A MERL-format table of the public set's size (90 × 90 × 180)
/// with smooth made-up values, for measured models whose defaults name no
/// file: lookup speed does not depend on the data.
fn synthetic_table() -> String {
    static PATH: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    PATH.get_or_init(write_synthetic_table).clone()
}

/// Writes `bytes` as `name` in the bench's temporary folder, atomically (a
/// concurrent run never reads half a file), and returns its path.
fn bench_file(name: &str, bytes: &[u8]) -> String {
    let path = std::path::PathBuf::from(env!("CARGO_TARGET_TMPDIR")).join(name);
    if let Err(e) = bv_core::fsio::write_atomic(&path, |w| w.write_all(bytes)) {
        eprintln!("cannot write {}: {e}", path.display());
    }
    path.to_string_lossy().into_owned()
}

fn write_synthetic_table() -> String {
    let dims = [90i32, 90, 180];
    let n = (dims[0] * dims[1] * dims[2]) as usize;
    let mut bytes = Vec::with_capacity(12 + 24 * n);
    for d in dims {
        bytes.extend_from_slice(&d.to_le_bytes());
    }
    for c in 0..3 {
        for i in 0..n {
            let v = 100.0 + 50.0 * ((i as f64) * 1e-3 + c as f64).sin();
            bytes.extend_from_slice(&v.to_le_bytes());
        }
    }
    bench_file("bv-bench-90x90x180.binary", &bytes)
}

/// An RGL material of a real file's size (8 θi, 128-node NDF, 32² value
/// squares as the database's isotropic RGB files): a GGX Cook-Torrance
/// written by `bv tabulate --format rgl`'s writer.
fn synthetic_rgl() -> String {
    static PATH: std::sync::OnceLock<String> = std::sync::OnceLock::new();
    PATH.get_or_init(|| {
        use bv_core::measured::rgl_write::{RglWriteOptions, tabulate_rgl};
        let opts = RglWriteOptions {
            theta_i: 8,
            values: 32,
            ..RglWriteOptions::default()
        };
        let written = ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"distribution": "ggx", "alpha": 0.3}),
        )
        .and_then(|s| s.build())
        .and_then(|b| tabulate_rgl(b.as_ref(), &opts));
        let bytes = written.unwrap_or_else(|e| {
            eprintln!("cannot tabulate the RGL bench file: {e}");
            Vec::new()
        });
        bench_file("bv-bench-ggx.bsdf", &bytes)
    })
    .clone()
}

/// Every model of the catalogue with its defaults (a measured model whose
/// defaults name no file reads a synthetic file of its format: a MERL
/// table, an RGL material), plus Cook-Torrance with GGX.
fn models() -> Vec<(String, &'static ModelInfo, Box<dyn Brdf>)> {
    let mut out = Vec::new();
    for &m in catalogue().iter() {
        let built = ModelSpec::new(m.id).and_then(|mut s| {
            if !analytic(m) {
                for d in m.params {
                    if let ParamKind::Path { format, .. } = d.kind {
                        let file = if format.extensions().contains(&"bsdf") {
                            synthetic_rgl()
                        } else {
                            synthetic_table()
                        };
                        s.set_json(d.id, &serde_json::Value::String(file))?;
                    }
                }
            }
            s.build()
        });
        match built {
            Ok(b) => out.push((m.id.to_string(), m, b)),
            Err(e) => eprintln!("skipping `{}`: {e}", m.id),
        }
    }
    if let Ok(m) = bv_core::find("cook-torrance") {
        let spec = ModelSpec::from_json(m.id, &serde_json::json!({"distribution": "ggx"}));
        match spec.and_then(|s| s.build()) {
            Ok(b) => out.push(("cook-torrance-ggx".to_string(), m, b)),
            Err(e) => eprintln!("skipping cook-torrance with GGX: {e}"),
        }
    }
    out
}

fn eval(c: &mut Criterion) {
    let pairs = random_pairs(PAIRS, 0xB5);
    let mut out = vec![Rgb::ZERO; PAIRS];
    let mut g = c.benchmark_group("eval");
    g.throughput(Throughput::Elements(PAIRS as u64));
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(2));
    for (name, _, b) in models() {
        // One core: eval_batch is a plain loop on the calling thread.
        g.bench_function(&name, |bench| {
            bench.iter(|| {
                b.eval_batch(black_box(&pairs), &mut out);
                black_box(&out);
            })
        });
    }
    g.finish();
}

/// The case of `bv bench`'s speed comparison: GGX, separable Smith, α = 0.3,
/// the exact conductor with copper's index.
fn conductor_case() -> Option<(String, Box<dyn Brdf>)> {
    let p = serde_json::json!({"distribution": "ggx", "geometry": "smith", "alpha": 0.3,
        "fresnel": "conductor", "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14]});
    let b = ModelSpec::from_json("cook-torrance", &p).and_then(|s| s.build());
    match b {
        Ok(b) => Some(("cook-torrance-ggx-smith-conductor".to_string(), b)),
        Err(e) => {
            eprintln!("skipping the conductor case: {e}");
            None
        }
    }
}

/// The f32 batch path (`bv_core::batch::eval`) on one core, in chunks of 4096
/// pairs as `bv bench` hands them out, for every model (models without a
/// kernel run their scalar fallback) and the conductor case; the same case
/// through the f64 `eval_batch` for comparison.
fn batch_eval(c: &mut Criterion) {
    use bv_core::batch::{self, Out, PairBuf};
    const CHUNK: usize = 4096;
    let pairs = random_pairs(PAIRS, 0xB5);
    let soa = PairBuf::from_pairs(&pairs);
    let mut rgb = [vec![0f32; CHUNK], vec![0f32; CHUNK], vec![0f32; CHUNK]];
    let mut g = c.benchmark_group("batch");
    g.throughput(Throughput::Elements(PAIRS as u64));
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(500));
    g.measurement_time(Duration::from_secs(2));
    let mut all: Vec<(String, Box<dyn Brdf>)> =
        models().into_iter().map(|(n, _, b)| (n, b)).collect();
    if let Some(case) = conductor_case() {
        let mut out = vec![Rgb::ZERO; PAIRS];
        g.bench_function(format!("{}/f64-scalar", case.0), |bench| {
            bench.iter(|| {
                case.1.eval_batch(black_box(&pairs), &mut out);
                black_box(&out);
            })
        });
        all.push(case);
    }
    // Every instruction set this CPU has, side by side in one run, so that
    // the vector paths' gain over `scalar` is read off one report.
    for (name, b) in all {
        let paths: Vec<Option<batch::Isa>> = if b.batch_kernel().is_some() {
            batch::Isa::available().into_iter().map(Some).collect()
        } else {
            vec![None]
        };
        for isa in paths {
            let path = match isa {
                Some(i) => format!("{i}x{}", i.lanes()),
                None => "fallback".to_string(),
            };
            g.bench_function(format!("{name}/{path}"), |bench| {
                bench.iter(|| {
                    for start in (0..PAIRS).step_by(CHUNK) {
                        let end = (start + CHUNK).min(PAIRS);
                        let [r, gr, bl] = &mut rgb;
                        let mut out = Out {
                            rgb: [&mut r[..], &mut gr[..], &mut bl[..]],
                        };
                        let dirs = soa.dirs(start..end);
                        match isa {
                            Some(i) => batch::eval_with(b.as_ref(), i, &dirs, &mut out),
                            None => batch::eval(b.as_ref(), &dirs, &mut out),
                        };
                        black_box(&rgb);
                    }
                })
            });
        }
    }
    g.finish();
}

fn lobes(c: &mut Criterion) {
    let wi = frame::from_spherical(45f64.to_radians(), 0.3);
    let wi_plane = frame::from_spherical(45f64.to_radians(), 0.0);
    let mut g = c.benchmark_group("lobe");
    g.warm_up_time(Duration::from_millis(300));
    g.measurement_time(Duration::from_secs(1));
    for (name, m, b) in models() {
        if !analytic(m) {
            continue;
        }
        for (n_theta, n_phi) in [(64, 128), (128, 256)] {
            let opts = LobeOptions {
                n_theta,
                n_phi,
                ..LobeOptions::default()
            };
            g.bench_function(format!("{name}/{n_theta}x{n_phi}"), |bench| {
                bench.iter(|| black_box(lobe::build(b.as_ref(), black_box(wi), &opts)))
            });
            // A slider step: the same resolution into the previous mesh's
            // buffers (`lobe::build_into`).
            let mut mesh = lobe::build(b.as_ref(), wi, &opts);
            g.bench_function(format!("{name}/{n_theta}x{n_phi}/reuse"), |bench| {
                bench.iter(|| {
                    lobe::build_into(b.as_ref(), black_box(wi), &opts, &mut mesh);
                    black_box(&mesh);
                })
            });
            // The same with the light in the xz-plane (φi = 0, where the
            // sliders start): an isotropic model's rings are then evaluated
            // half and mirrored (`lobe`'s `mirror_axis`).
            g.bench_function(
                format!("{name}/{n_theta}x{n_phi}/reuse-in-plane"),
                |bench| {
                    bench.iter(|| {
                        lobe::build_into(b.as_ref(), black_box(wi_plane), &opts, &mut mesh);
                        black_box(&mesh);
                    })
                },
            );
        }
    }
    g.finish();
}

fn albedo_curves(c: &mut Criterion) {
    use albedo::{AlbedoMethod, AlbedoOptions};
    let mut g = c.benchmark_group("rho_hd_curve");
    g.sample_size(10);
    g.warm_up_time(Duration::from_millis(300));
    g.measurement_time(Duration::from_secs(1));
    // One core: the target is per core, and the curve is parallel over angles.
    let one = rayon::ThreadPoolBuilder::new().num_threads(1).build();
    let Ok(one) = one else {
        return;
    };
    for (name, _, b) in models() {
        // 90 angles, as `bv check` does by default: quadrature for analytic
        // models, and Monte Carlo with 4096 samples as the cross-check.
        for (label, method) in [
            ("quadrature/90", AlbedoMethod::Quadrature),
            ("monte-carlo/90x4096", AlbedoMethod::MonteCarlo),
        ] {
            let opts = AlbedoOptions {
                method,
                ..AlbedoOptions::default()
            };
            g.bench_function(format!("{name}/{label}/1-core"), |bench| {
                bench.iter(|| {
                    one.install(|| black_box(albedo::rho_hd_curve(b.as_ref(), 0.0, 90, &opts)))
                })
            });
        }
    }
    g.finish();
}

criterion_group!(benches, eval, batch_eval, lobes, albedo_curves);
criterion_main!(benches);
