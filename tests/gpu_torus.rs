//! The torus of the environment view (shaders/common/torus.wgsl): the white
//! furnace tells the geometry and the self-shadowing apart.
//!
//! Under a constant environment of radiance 1, a Lambertian surface of albedo
//! 1 reflects exactly the fraction of its cosine-weighted hemisphere that sees
//! the environment: 1 where nothing of the torus is above its tangent plane,
//! less where the ring hides part of the sky, never more.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::env::Object;
use bv::gpu::sphere::FILL;
use bv::gpu::{EnvRenderer, EnvSettings, EnvironmentMap, gpu_for_test, shaders::ShaderLibrary};
use bv_core::ModelSpec;

/// Major and minor radii and axis of the torus, as in torus.wgsl.
const MAJOR: f64 = 0.64;
const MINOR: f64 = 0.32;

#[test]
fn torus_white_furnace_shows_shadowing_and_no_gain() {
    let Some(gpu) = gpu_for_test() else {
        return;
    };
    let mut lib = ShaderLibrary::new().unwrap();
    let mut r = EnvRenderer::new(gpu, &mut lib, &EnvironmentMap::constant([1.0; 3])).unwrap();
    r.set_object(Object::Torus);
    let spec = ModelSpec::from_json("lambert", &serde_json::json!({"albedo": 1.0})).unwrap();
    let (w, h) = (64u32, 64u32);
    let img = r
        .render_radiance(
            std::slice::from_ref(&spec),
            &EnvSettings::default(),
            w,
            h,
            2048,
        )
        .unwrap();
    let at = |x: u32, y: u32| img[(y * w + x) as usize][0];
    let radius = 0.5 * FILL * f64::from(w.min(h));
    let (cx, cy) = (f64::from(w) * 0.5, f64::from(h) * 0.5);
    // Pixel (column) of a point at horizontal offset u (units of the radius).
    let col = |u: f64| (cx + u * radius - 0.5).round() as u32;
    let row = cy as u32;

    // No gain anywhere (the estimate is ≤ 1 up to its noise).
    let max = img.iter().map(|c| c[0]).fold(0.0f32, f32::max);
    assert!(max < 1.01, "a pixel reflects {max} > 1");
    // The hole shows the environment itself.
    assert!(
        (at(cx as u32, row) - 1.0).abs() < 1e-6,
        "hole: {}",
        at(cx as u32, row)
    );
    // The outermost points of the ring (x = ±(R + r), a supporting plane of
    // the torus): unshadowed, so 1.
    for u in [-(MAJOR + MINOR) + 0.06, MAJOR + MINOR - 0.06] {
        let v = at(col(u), row);
        assert!((v - 1.0).abs() < 0.02, "outer rim at u = {u}: {v}");
    }
    // The inner side of the ring sees the ring's other side: clearly darker
    // somewhere (the far part's inner side, seen through the hole's top).
    let inner = img.iter().map(|c| c[0]).fold(1.0f32, f32::min);
    assert!(inner < 0.75, "nothing is shadowed: darkest pixel {inner}");
    let column: Vec<f32> = (0..h).map(|y| at(cx as u32, y)).collect();
    let darkest = column.iter().cloned().fold(1.0f32, f32::min);
    assert!(darkest < 0.75, "the vertical through the hole: {column:?}");
    println!("torus furnace: max {max:.4}, inner side {inner:.3}");
}
