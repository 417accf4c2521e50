//! Fitting benchmark: Cook-Torrance (GGX) fitted to an isotropic RGB RGL
//! file of the real files' size (8 θi, VNDF 128², values 32²: about 0.66 MB,
//! written by `measured::rgl_write` from a Cook-Torrance with other values),
//! with the default options (Ngan metric, 4 starts), parsing the file
//! included. Two sets of unknowns: kd, ks and α (5 unknowns), and every
//! float and colour parameter that applies (what `bv fit -m cook-torrance
//! -p distribution=ggx --to FILE` frees). The target: ≤ 10 s on 2
//! cores.
//!
//! `cargo bench -p bv-core --bench fit`

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv_core::fit::{self, FitOptions};
use bv_core::measured::rgl::RglMaterial;
use bv_core::measured::rgl_write::{RglWriteOptions, tabulate_rgl};
use bv_core::models::rgl::Rgl;
use bv_core::{Brdf, ModelSpec};
use criterion::{Criterion, criterion_group, criterion_main};
use std::hint::black_box;
use std::sync::Arc;
use std::sync::atomic::AtomicBool;
use std::time::Duration;

fn spec(model: &str, params: &[(&str, &str)]) -> ModelSpec {
    let mut s = ModelSpec::new(model).unwrap();
    for (k, v) in params {
        s.set_str(k, v).unwrap();
    }
    s
}

fn benches(c: &mut Criterion) {
    let source = spec(
        "cook-torrance",
        &[
            ("distribution", "ggx"),
            ("alpha", "0.15"),
            ("ks", "0.6"),
            ("kd", "0.1,0.2,0.3"),
        ],
    )
    .build()
    .unwrap();
    let opts = RglWriteOptions {
        theta_i: 8,
        ..RglWriteOptions::default()
    };
    let bytes = tabulate_rgl(source.as_ref(), &opts).unwrap();
    eprintln!("RGL file: {} bytes", bytes.len());
    let model = spec("cook-torrance", &[("distribution", "ggx")]);
    let all = fit::default_free(&model);
    let mut g = c.benchmark_group("fit");
    g.sample_size(10).measurement_time(Duration::from_secs(20));
    for (name, free) in [
        ("cook_torrance_kd_ks_alpha", vec!["kd", "ks", "alpha"]),
        ("cook_torrance_default_free", all),
    ] {
        g.bench_function(name, |b| {
            b.iter(|| {
                let m = RglMaterial::parse(black_box(bytes.clone()), "bench.bsdf").unwrap();
                let target = Rgl::new(Arc::new(m));
                let r = fit::fit(
                    &model,
                    &free,
                    &target as &dyn Brdf,
                    &FitOptions::default(),
                    &AtomicBool::new(false),
                    &mut |_| {},
                )
                .unwrap();
                black_box(r.error)
            })
        });
    }
    g.finish();
}

criterion_group!(fit_benches, benches);
criterion_main!(fit_benches);
