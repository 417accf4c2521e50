//! The GPU lit sphere against the CPU reference rendering from bv-core:
//! same pixels, same geometry (src/gpu/sphere.rs and
//! shaders/common/sphere.wgsl), same display transform.
//!
//! Tolerance: every channel of every pixel within 1 level of 255 (the f32 and
//! f64 values may round to neighbouring levels), except pixels whose centre
//! lies within 1e-5 (in units of the radius²) of the silhouette, where f32 and
//! f64 may disagree on inside/outside; at most 0.1 % of the pixels may be those.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::sphere::{Grid, sphere_at};
use bv::gpu::{
    Background, LitSphereRenderer, LitSphereSettings, ToneMap, gpu_for_test,
    lit_sphere::reference_image, shaders::ShaderLibrary,
};
use bv_core::ModelSpec;
use glam::{DVec2, DVec3};

fn on_silhouette(x: u32, y: u32, w: u32, h: u32, tiles: usize) -> bool {
    let size = DVec2::new(w.into(), h.into());
    let p = DVec2::new(f64::from(x) + 0.5, f64::from(y) + 0.5);
    let grid = Grid::new(tiles, size);
    let (c, r) = grid.circle(grid.tile_at(p, size), size);
    let d2 = ((p - c) / r).length_squared();
    (d2 - 1.0).abs() < 1e-5 || sphere_at(p, size, tiles).is_some() != (d2 < 1.0)
}

fn compare(
    models: &[ModelSpec],
    settings: &LitSphereSettings,
    w: u32,
    h: u32,
    r: &mut LitSphereRenderer,
) {
    let gpu = r.render_image(models, settings, w, h).unwrap();
    if let Ok(dir) = std::env::var("BV_TEST_IMAGES") {
        // For a look by eye: BV_TEST_IMAGES=/tmp cargo test --test suite gpu_lit_sphere::
        let name: Vec<&str> = models.iter().map(|m| m.id()).collect();
        gpu.save(format!("{dir}/lit_sphere_{}_{w}x{h}.png", name.join("+")))
            .unwrap();
    }
    let cpu = reference_image(models, settings, w, h).unwrap();
    let mut worst = 0i32;
    let mut edge = 0usize;
    let mut lit = 0usize;
    for (x, y, g) in gpu.enumerate_pixels() {
        let c = cpu.get_pixel(x, y);
        let d = (0..3)
            .map(|k| (i32::from(g[k]) - i32::from(c[k])).abs())
            .max()
            .unwrap();
        if c[0] > 0 || c[1] > 0 || c[2] > 0 {
            lit += 1;
        }
        if d > 1 {
            assert!(
                on_silhouette(x, y, w, h, models.len()),
                "{:?}: pixel ({x}, {y}) gpu {g:?} cpu {c:?}",
                models.iter().map(|m| m.id()).collect::<Vec<_>>()
            );
            edge += 1;
        }
        worst = worst.max(d);
    }
    assert!(
        edge * 1000 <= (w * h) as usize,
        "{edge} silhouette pixels differ"
    );
    assert!(
        lit > (w * h / 10) as usize,
        "the image is mostly black: {lit} lit pixels"
    );
    println!(
        "{:?} {w}x{h}: worst |Δ| = {worst}/255, {edge} silhouette pixels beyond 1",
        models.iter().map(|m| m.id()).collect::<Vec<_>>()
    );
}

#[test]
fn gpu_lit_sphere_matches_cpu_reference() {
    let Some(gpu) = gpu_for_test() else { return };
    let mut lib = ShaderLibrary::new().unwrap();
    let mut r = LitSphereRenderer::new(gpu, &mut lib).unwrap();
    let lambert =
        ModelSpec::from_json("lambert", &serde_json::json!({"albedo": [0.8, 0.5, 0.2]})).unwrap();
    let ct = ModelSpec::new("cook-torrance").unwrap();
    let aniso = ModelSpec::from_json(
        "cook-torrance",
        &serde_json::json!({"distribution": "ggx", "alpha_x": 0.05, "alpha_y": 0.4, "geometry": "smith", "fresnel": "conductor", "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14]}),
    )
    .unwrap();
    let settings = LitSphereSettings {
        light: DVec3::new(-0.3, 0.4, 0.87),
        ..Default::default()
    };
    compare(std::slice::from_ref(&lambert), &settings, 64, 64, &mut r);
    compare(std::slice::from_ref(&ct), &settings, 64, 64, &mut r);
    // Side by side, a non-square size, exposure, tone map and a checker background.
    let s2 = LitSphereSettings {
        light: DVec3::new(0.6, 0.2, 0.5),
        exposure_ev: 1.5,
        tone_map: ToneMap::Aces,
        background: Background::Checker {
            a: [0.2, 0.2, 0.2],
            b: [0.3, 0.3, 0.3],
            size: 8.0,
        },
        ..Default::default()
    };
    compare(
        &[lambert.clone(), ct.clone(), aniso.clone()],
        &s2,
        150,
        57,
        &mut r,
    );
    // Small multiples: seven spheres in a grid of two rows (4 + 3, the
    // last row centred), every tile drawn by its own model's pipeline.
    let seven: Vec<ModelSpec> = [&lambert, &ct, &aniso, &ct, &lambert, &aniso, &ct]
        .into_iter()
        .cloned()
        .collect();
    assert_eq!(Grid::new(7, DVec2::new(200.0, 120.0)).cols, 4);
    compare(&seven, &s2, 200, 120, &mut r);
    // The surface turned about its normal, at several angles.
    for turn_deg in [30.0f64, 90.0, -135.0] {
        let turned = LitSphereSettings {
            turn: turn_deg.to_radians(),
            ..settings
        };
        compare(&[ct.clone(), aniso.clone()], &turned, 128, 64, &mut r);
    }
}

/// Turning the surface by 90° turns an anisotropic highlight by 90°: an
/// anisotropic GGX with roughness (αx, αy) turned by 90° draws the same
/// pixels as (αy, αx) unturned, while an isotropic model does not change.
#[test]
fn a_turned_surface_turns_only_anisotropic_highlights() {
    let Some(gpu) = gpu_for_test() else { return };
    let mut lib = ShaderLibrary::new().unwrap();
    let mut r = LitSphereRenderer::new(gpu, &mut lib).unwrap();
    let ggx = |ax: f64, ay: f64| {
        ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"distribution": "ggx", "alpha_x": ax, "alpha_y": ay, "geometry": "smith", "fresnel": "none"}),
        )
        .unwrap()
    };
    let plain = LitSphereSettings {
        light: DVec3::new(-0.3, 0.4, 0.87),
        ..Default::default()
    };
    let turned = LitSphereSettings {
        turn: std::f64::consts::FRAC_PI_2,
        ..plain
    };
    let max_diff = |a: &image::RgbaImage, b: &image::RgbaImage| {
        a.pixels()
            .zip(b.pixels())
            .map(|(p, q)| (0..3).map(|k| p[k].abs_diff(q[k])).max().unwrap())
            .max()
            .unwrap()
    };
    let a = r.render_image(&[ggx(0.05, 0.4)], &turned, 96, 96).unwrap();
    let b = r.render_image(&[ggx(0.4, 0.05)], &plain, 96, 96).unwrap();
    let unturned = r.render_image(&[ggx(0.05, 0.4)], &plain, 96, 96).unwrap();
    assert!(
        max_diff(&a, &b) <= 1,
        "turned by 90° differs from swapped roughness"
    );
    if let Ok(dir) = std::env::var("BV_TEST_IMAGES") {
        a.save(format!("{dir}/lit_sphere_turned.png")).unwrap();
        unturned
            .save(format!("{dir}/lit_sphere_unturned.png"))
            .unwrap();
    }
    let moved = max_diff(&a, &unturned);
    assert!(moved > 40, "turning did not move the highlight: {moved}");
    let iso = r.render_image(&[ggx(0.2, 0.2)], &turned, 96, 96).unwrap();
    let iso0 = r.render_image(&[ggx(0.2, 0.2)], &plain, 96, 96).unwrap();
    assert!(
        max_diff(&iso, &iso0) <= 1,
        "an isotropic model changed when turned"
    );
}

/// Measured tables on the lit sphere: a Cook-Torrance lobe tabulated at
/// 45×45×90 next to the model it came from, then (same renderer, so the table
/// buffer must be uploaded again) a Lambert table alone. The GPU reads the
/// tables from their storage buffer; the reference looks them up in bv-core.
#[test]
fn gpu_lit_sphere_draws_merl_tables() {
    use bv_core::measured::merl::{MerlDims, tabulate};
    let Some(gpu) = gpu_for_test() else { return };
    let mut lib = ShaderLibrary::new().unwrap();
    let mut r = LitSphereRenderer::new(gpu, &mut lib).unwrap();
    let dir = std::env::temp_dir().join(format!("bv-lit-merl-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let ct = ModelSpec::from_json(
        "cook-torrance",
        &serde_json::json!({"kd": [0.3, 0.2, 0.1], "distribution": "ggx", "alpha": 0.25}),
    )
    .unwrap();
    let lambert =
        ModelSpec::from_json("lambert", &serde_json::json!({"albedo": [0.2, 0.6, 0.9]})).unwrap();
    let dims = MerlDims::new(45, 45, 90).unwrap();
    let mut merl = Vec::new();
    for (name, spec) in [("ct", &ct), ("lambert", &lambert)] {
        let path = dir.join(format!("{name}.binary"));
        tabulate(spec.build().unwrap().as_ref(), dims)
            .unwrap()
            .write(&path)
            .unwrap();
        merl.push(
            ModelSpec::from_json("merl", &serde_json::json!({"path": path.to_str().unwrap()}))
                .unwrap(),
        );
    }
    let settings = LitSphereSettings {
        light: DVec3::new(-0.3, 0.4, 0.87),
        ..Default::default()
    };
    compare(&[merl[0].clone(), ct], &settings, 128, 64, &mut r);
    compare(std::slice::from_ref(&merl[1]), &settings, 64, 64, &mut r);
    std::fs::remove_dir_all(&dir).unwrap();
}
