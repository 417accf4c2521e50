//! MERL table benchmarks: load time of a full-size 90×90×180 file
//! (34,992,012 bytes, written by `tabulate` + `write`, as `bv tabulate` does)
//! and lookup throughput, nearest and trilinear.
//!
//! `cargo bench -p bv-core --bench merl`

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_core::measured::merl::{self, Interpolation, MerlTable, STANDARD_DIMS};
use bv_core::models::lambert::Lambert;
use bv_core::{Rgb, frame, sampling};
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::hint::black_box;
use std::time::Duration;

fn benches(c: &mut Criterion) {
    let dir = std::env::temp_dir().join(format!("bv-merl-bench-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let path = dir.join("full.binary");
    let table = merl::tabulate(&Lambert::new(Rgb::new(0.2, 0.5, 0.8)), STANDARD_DIMS).unwrap();
    table.write(&path).unwrap();
    assert_eq!(std::fs::metadata(&path).unwrap().len(), 34_992_012);

    let mut g = c.benchmark_group("merl");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    g.throughput(Throughput::Bytes(34_992_012));
    g.bench_function("load_full_size", |b| {
        b.iter(|| MerlTable::read(black_box(&path)).unwrap())
    });
    g.finish();

    let mut rng = sampling::rng(5);
    let n = 1 << 16;
    let pairs: Vec<_> = (0..n)
        .map(|_| {
            (
                sampling::cosine_hemisphere(sampling::uniform2(&mut rng)),
                sampling::cosine_hemisphere(sampling::uniform2(&mut rng)),
            )
        })
        .collect();
    let angles: Vec<_> = pairs
        .iter()
        .map(|&(wi, wo)| frame::to_half_diff(wi, wo).unwrap())
        .collect();
    let mut g = c.benchmark_group("merl_lookup");
    g.sample_size(20).measurement_time(Duration::from_secs(3));
    g.throughput(Throughput::Elements(n as u64));
    for mode in [Interpolation::Nearest, Interpolation::Trilinear] {
        g.bench_function(format!("{}_directions", mode.name()), |b| {
            b.iter(|| {
                let mut acc = Rgb::ZERO;
                for &(wi, wo) in &pairs {
                    acc += table.lookup(wi, wo, mode);
                }
                black_box(acc)
            })
        });
        g.bench_function(format!("{}_angles", mode.name()), |b| {
            b.iter(|| {
                let mut acc = Rgb::ZERO;
                for hd in &angles {
                    acc += table.lookup_angles(hd.theta_h, hd.theta_d, hd.phi_d, mode);
                }
                black_box(acc)
            })
        });
    }
    g.finish();
    std::fs::remove_dir_all(&dir).unwrap();
}

criterion_group!(merl_benches, benches);
criterion_main!(merl_benches);
