//! GPU limits and errors as values: an image larger than one storage binding
//! is accumulated in bands and comes out the same as in one piece; a wgpu
//! validation error (a buffer beyond the device's limit) is an `Err`, not a
//! panic, both inside an error scope and outside one.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::errors;
use bv::gpu::{EnvRenderer, EnvSettings, EnvironmentMap, gpu_for_test, shaders::ShaderLibrary};
use bv_core::ModelSpec;

fn spec() -> ModelSpec {
    ModelSpec::from_json(
        "cook-torrance",
        &serde_json::json!({"alpha_x": 0.3, "alpha_y": 0.3}),
    )
    .unwrap()
}

/// The image is split into bands of a few rows (at most 7 rows of 37
/// pixels, 16 bytes each): every pixel's radiance and the displayed image
/// equal the unsplit render's bit for bit (the sequences are seeded by the
/// whole image's pixel index), rows at band edges included.
#[test]
fn banded_accumulation_equals_one_piece() {
    let Some(gpu) = gpu_for_test() else {
        return;
    };
    let map = EnvironmentMap::studio(64, 32);
    let mut lib = ShaderLibrary::new().unwrap();
    let mut r = EnvRenderer::new(gpu, &mut lib, &map).unwrap();
    let models = [spec(), ModelSpec::new("lambert").unwrap()];
    let s = EnvSettings::default();
    let (w, h) = (37, 29);
    let whole = r.render_radiance(&models, &s, w, h, 4).unwrap();
    let whole_img = r.render_image(&models, &s, w, h, 4).unwrap();
    assert_eq!(r.band_count(), 1);
    r.set_max_band_bytes(Some(16 * 37 * 7));
    let banded = r.render_radiance(&models, &s, w, h, 4).unwrap();
    let banded_img = r.render_image(&models, &s, w, h, 4).unwrap();
    assert_eq!(r.band_count(), 5, "29 rows in bands of 7");
    assert_eq!(whole.len(), (w * h) as usize);
    assert_eq!(banded.len(), whole.len());
    for (i, (a, b)) in whole.iter().zip(&banded).enumerate() {
        assert_eq!(a, b, "pixel ({}, {})", i as u32 % w, i as u32 / w);
    }
    assert!(
        whole.iter().any(|p| p[0] > 0.0),
        "the render is black: the test would prove nothing"
    );
    assert_eq!(whole_img, banded_img);
    // A band of less than one row is refused with the limit named.
    r.set_max_band_bytes(Some(16));
    let e = r.render_radiance(&models, &s, w, h, 1).unwrap_err();
    assert!(format!("{e:#}").contains("per row"), "{e:#}");
}

/// A buffer one byte over the device's limit, made inside the helper's error
/// scopes, is an `Err` naming the work and wgpu's reason.
#[test]
fn validation_errors_in_a_scope_are_errors() {
    let Some(gpu) = gpu_for_test() else {
        return;
    };
    let too_big = gpu.device.limits().max_buffer_size + 1;
    let r = gpu.scoped("an absurd buffer", || {
        Ok(gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("absurd"),
            size: too_big,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        }))
    });
    let e = format!("{:#}", r.unwrap_err());
    assert!(
        e.contains("an absurd buffer") && e.contains("absurd") && e.contains("maximum buffer size"),
        "{e}"
    );
    assert!(!e.contains('\n'), "not one line: {e}");
    // The device still works afterwards.
    let ok = gpu.scoped("a small buffer", || {
        Ok(gpu.device.create_buffer(&wgpu::BufferDescriptor {
            label: Some("small"),
            size: 256,
            usage: wgpu::BufferUsages::STORAGE,
            mapped_at_creation: false,
        }))
    });
    assert!(ok.is_ok());
    // The size check says it before wgpu does, in the user's terms.
    let e = errors::check_buffer(
        &gpu.device,
        "a 9×9 thing",
        too_big,
        false,
        "make it smaller",
    )
    .unwrap_err()
    .to_string();
    assert!(
        e.contains("MiB") && e.contains("at most") && e.contains("make it smaller"),
        "{e}"
    );
    let side = gpu.device.limits().max_texture_dimension_2d + 1;
    let e = errors::check_texture(&gpu.device, "an image", side, 1)
        .unwrap_err()
        .to_string();
    assert!(e.contains(&format!("{side}×1")), "{e}");
}

/// Outside any scope, the handler every bv device gets records the error
/// (wgpu's default would panic), and the log says it arrived.
#[test]
fn uncaptured_errors_are_recorded_not_panics() {
    let Some(gpu) = gpu_for_test() else {
        return;
    };
    let before = gpu.errors.count();
    assert_eq!(gpu.errors.since(before), None);
    let _b = gpu.device.create_buffer(&wgpu::BufferDescriptor {
        label: Some("unscoped absurd"),
        size: gpu.device.limits().max_buffer_size + 1,
        usage: wgpu::BufferUsages::STORAGE,
        mapped_at_creation: false,
    });
    let e = gpu.errors.since(before).expect("the error was recorded");
    assert!(e.contains("unscoped absurd"), "{e}");
    assert_eq!(gpu.errors.count(), before + 1);
}
