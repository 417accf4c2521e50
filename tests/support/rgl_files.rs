//! RGL test files shared by the GPU tests (`gpu_parity`, `gpu_env`, through
//! the suite's one module) and bv-core's `tests/rgl.rs` (both include this
//! file by path).

// Each test crate that includes this module uses part of it.
#![allow(dead_code)]

use glam::DVec3;
use std::f64::consts::PI;

/// A hand-built RGL file of random positive tables: `nphi` incident azimuths
/// from −π spanning `span` (anisotropic above 2: folded by a half turn for
/// span π, a quarter turn for π/2), 4 θi, NDF and σ varying with φ, the VNDF
/// zero where the normal faces away from the slice's wi, the Jacobian on.
pub fn random_rgl_file(seed: u64, nphi: usize, span: f64) -> Vec<u8> {
    use bv_core::measured::tensor::TensorWriter;
    let mut g = bv_core::sampling::rng(seed);
    let mut r = |n: usize, lo: f32, hi: f32| -> Vec<f32> {
        (0..n)
            .map(|_| lo + (hi - lo) * bv_core::sampling::uniform2(&mut g).x as f32)
            .collect()
    };
    let phi: Vec<f32> = if nphi == 1 {
        vec![0.0]
    } else {
        (0..nphi)
            .map(|k| (-PI + span * k as f64 / (nphi - 1) as f64) as f32)
            .collect()
    };
    let theta: Vec<f32> = (0..4).map(|k| 1.4 * k as f32 / 3.0).collect();
    let sph = |t: f64, p: f64| DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
    let mut vndf = r(nphi * 4 * 192, 0.1, 2.0);
    for (k, v) in vndf.iter_mut().enumerate() {
        let (x, y) = (k % 16, (k / 16) % 12);
        let (t, pi) = ((k / 192) % 4, k / 768);
        let phi_i = if nphi <= 2 { 0.0 } else { f64::from(phi[pi]) };
        let wi = sph(f64::from(theta[t]), phi_i);
        let u = x as f64 / 15.0;
        let tm = u * u * PI / 2.0;
        let m = sph(tm, (2.0 * y as f64 / 11.0 - 1.0) * PI);
        *v *= (wi.dot(m).max(0.0) * u * tm.sin()) as f32;
    }
    let p = nphi as u64;
    let mut w = TensorWriter::new();
    w.u8("description", &[6], b"random")
        .f32("theta_i", &[4], &theta)
        .f32("phi_i", &[p], &phi)
        .f32("ndf", &[8, 16], &r(128, 0.2, 2.0))
        .f32("sigma", &[8, 16], &r(128, 0.5, 1.5))
        .f32("vndf", &[p, 4, 12, 16], &vndf)
        .f32("luminance", &[p, 4, 8, 8], &r(nphi * 4 * 64, 0.1, 2.0))
        .f32("rgb", &[p, 4, 3, 8, 8], &r(nphi * 4 * 192, 0.0, 1.0))
        .u8("jacobian", &[1], &[1]);
    w.to_bytes()
}

/// A sharp conductor-like GGX lobe (Cook-Torrance, no diffuse part, GGX of
/// roughness `alpha`) tabulated as an isotropic RGL file by bv-core's writer.
pub fn tabulated_ggx(alpha: f64) -> Vec<u8> {
    use bv_core::measured::rgl_write::{RglWriteOptions, tabulate_rgl};
    tabulate_rgl(sharp_ggx(alpha).as_ref(), &RglWriteOptions::default()).unwrap()
}

/// The sharp lobe [`tabulated_ggx`] and [`merl_ggx_spec`] tabulate.
fn sharp_ggx(alpha: f64) -> Box<dyn bv_core::Brdf> {
    bv_core::ModelSpec::from_json(
        "cook-torrance",
        &serde_json::json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx", "alpha": alpha, "fresnel": "schlick", "f0": 0.9}),
    )
    .unwrap()
    .build()
    .unwrap()
}

/// A spec of the measured `model` reading the file at `path`.
fn file_spec(model: &str, path: &std::path::Path) -> bv_core::ModelSpec {
    bv_core::ModelSpec::from_json(
        model,
        &serde_json::json!({"path": path.display().to_string()}),
    )
    .unwrap()
}

/// An `rgl` model spec over `bytes`, written as `name` in `dir`.
pub fn rgl_spec(dir: &std::path::Path, name: &str, bytes: &[u8]) -> bv_core::ModelSpec {
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join(name);
    std::fs::write(&path, bytes).unwrap();
    file_spec("rgl", &path)
}

/// A `merl` model spec over the same sharp lobe as [`tabulated_ggx`],
/// tabulated at the public 90 × 90 × 180 resolution into `dir`.
pub fn merl_ggx_spec(dir: &std::path::Path, alpha: f64) -> bv_core::ModelSpec {
    use bv_core::measured::merl::{MerlDims, tabulate};
    std::fs::create_dir_all(dir).unwrap();
    let path = dir.join(format!("ggx-{alpha}.binary"));
    tabulate(
        sharp_ggx(alpha).as_ref(),
        MerlDims::new(90, 90, 180).unwrap(),
    )
    .unwrap()
    .write(&path)
    .unwrap();
    file_spec("merl", &path)
}
