//! GPU view benchmarks: lit-sphere frame time at 1024² and
//! environment samples per second, on whatever adapter wgpu finds (lavapipe on
//! machines without a GPU). `cargo bench --bench gpu`.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::{
    EnvRenderer, EnvSettings, EnvironmentMap, Gpu, LitSphereRenderer, LitSphereSettings,
    shaders::ShaderLibrary,
};
use bv_core::ModelSpec;
use criterion::{Criterion, Throughput, criterion_group, criterion_main};
use std::time::Duration;

fn models() -> Vec<(&'static str, ModelSpec)> {
    vec![
        ("lambert", ModelSpec::new("lambert").unwrap()),
        ("cook-torrance", ModelSpec::new("cook-torrance").unwrap()),
        ("disney", ModelSpec::new("disney").unwrap()),
    ]
}

fn bench(c: &mut Criterion) {
    let gpu = match Gpu::headless() {
        Ok(g) => g,
        Err(e) => {
            eprintln!("no GPU adapter, GPU benchmarks skipped: {e:#}");
            return;
        }
    };
    eprintln!("adapter: {}", gpu.describe());
    let mut lib = ShaderLibrary::new().unwrap();

    let mut lit = LitSphereRenderer::new(gpu.clone(), &mut lib).unwrap();
    let mut g = c.benchmark_group("lit_sphere_1024");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    g.throughput(Throughput::Elements(1024 * 1024));
    for (name, spec) in models() {
        let s = LitSphereSettings::default();
        g.bench_function(name, |b| {
            b.iter(|| {
                lit.render(std::slice::from_ref(&spec), &s, 1024, 1024)
                    .unwrap();
                gpu.wait().unwrap();
            })
        });
    }
    g.finish();

    let studio = EnvironmentMap::studio(256, 128);
    let mut env = EnvRenderer::new(gpu.clone(), &mut lib, &studio).unwrap();
    let (w, h, spp) = (512u32, 512u32, 8u32);
    let mut g = c.benchmark_group("environment_512_8spp");
    g.sample_size(10).measurement_time(Duration::from_secs(5));
    // Elements: samples (one BRDF and one environment sample each) on all
    // pixels, background included (a sphere covers π·0.45² ≈ 64 % of them).
    g.throughput(Throughput::Elements(u64::from(w * h * spp)));
    for (name, spec) in models() {
        let s = EnvSettings::default();
        g.bench_function(name, |b| {
            b.iter(|| {
                env.render(std::slice::from_ref(&spec), &s, w, h, spp)
                    .unwrap();
                gpu.wait().unwrap();
            })
        });
    }
    g.finish();
}

criterion_group!(benches, bench);
criterion_main!(benches);
