//! A user's model saved while the GPU renderers draw it: the renderers adopt
//! the new catalogue in place, compiling again only the pipelines whose code
//! changed (the saved model's, and the mix's, which reads every model through
//! the generic dispatch), and draw the new code, in the lit sphere and in the
//! environment view alike (where the in-place renderer draws what one built
//! from scratch draws).

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::{
    EnvRenderer, EnvSettings, EnvironmentMap, LitSphereRenderer, LitSphereSettings, gpu_for_test,
    shaders::ShaderLibrary,
};
use bv_core::ModelSpec;
use glam::DVec3;
use std::path::PathBuf;
use std::sync::{Mutex, MutexGuard};

/// The catalogue is one per process: the tests here register models and
/// watch its revision, so they take turns.
fn serial() -> MutexGuard<'static, ()> {
    static TURN: Mutex<()> = Mutex::new(());
    TURN.lock().unwrap_or_else(|poisoned| poisoned.into_inner())
}

fn temp_file(tag: &str) -> PathBuf {
    let d = std::env::temp_dir().join(format!("bv-gpu-reload-{}-{tag}", std::process::id()));
    std::fs::create_dir_all(&d).unwrap();
    d.join("grey.brdf")
}

/// f = scale · k / π, grey.
fn greyish(scale: &str) -> String {
    format!(
        "analytic\n::begin parameters\nfloat k 0 1 0.5\n::end parameters\n::begin shader\nconst float PI = 3.14159265358979323846;\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)\n{{\n    return vec3({scale} * k / PI);\n}}\n::end shader\n"
    )
}

/// The three spheres drawn: Lambert, the file model, and a mix of both.
fn models(path: &std::path::Path) -> Vec<ModelSpec> {
    let p = path.to_str().unwrap();
    let lambert =
        ModelSpec::from_json("lambert", &serde_json::json!({"albedo": [0.5, 0.5, 0.5]})).unwrap();
    let file = ModelSpec::from_json(p, &serde_json::json!({"k": 0.5})).unwrap();
    let mix = ModelSpec::from_json(
        "mix",
        &serde_json::json!({"components": [
            {"weight": 0.5, "model": "lambert", "params": {"albedo": [0.5, 0.5, 0.5]}},
            {"weight": 0.5, "model": p, "params": {"k": 0.5}},
        ]}),
    )
    .unwrap();
    vec![lambert, file, mix]
}

/// Polls `poll` (a renderer's `poll_pipelines`) until no pipeline is
/// compiling; whether any arrived.
fn settle(mut poll: impl FnMut() -> (bool, bool)) -> bool {
    let t0 = std::time::Instant::now();
    let mut any = false;
    loop {
        let (arrived, waiting) = poll();
        any |= arrived;
        if !waiting {
            return any;
        }
        assert!(t0.elapsed().as_secs() < 60, "the pipelines never arrived");
        std::thread::sleep(std::time::Duration::from_millis(2));
    }
}

/// The red channel at the centre of each of `n` spheres side by side.
fn centres(img: &image::RgbaImage, n: u32) -> Vec<u8> {
    let (w, h) = img.dimensions();
    (0..n)
        .map(|k| img.get_pixel((2 * k + 1) * w / (2 * n), h / 2).0[0])
        .collect()
}

/// A lit-sphere renderer, and the three models of a fresh file `tag` at
/// scale 1 (`None` without a GPU).
fn lit_sphere(tag: &str) -> Option<(PathBuf, Vec<ModelSpec>, LitSphereRenderer)> {
    let gpu = gpu_for_test()?;
    bv::session::user_models::install();
    let path = temp_file(tag);
    std::fs::write(&path, greyish("1.0")).unwrap();
    let models = models(&path);
    let r = LitSphereRenderer::new(gpu, &mut ShaderLibrary::new().unwrap()).unwrap();
    Some((path, models, r))
}

/// A light straight above: a sphere's centre shows f · 1.
fn head_on() -> LitSphereSettings {
    LitSphereSettings {
        light: DVec3::new(0.0, 0.0, 1.0),
        ..Default::default()
    }
}

/// The display value of a grey f = scale · 0.5 / π lit head-on.
fn shown(scale: f64) -> u8 {
    bv::gpu::display::to_u8(bv::gpu::display::srgb_encode(
        scale * 0.5 / std::f64::consts::PI,
    ))
}

#[test]
fn a_saved_model_is_drawn_anew_by_compiling_only_what_changed() {
    let _turn = serial();
    let Some((path, models, mut r)) = lit_sphere("lit") else {
        return;
    };
    let settings = head_on();
    let before = centres(&r.render_image(&models, &settings, 192, 64).unwrap(), 3);
    // The same f everywhere: three equal centres.
    assert!(
        before.iter().all(|c| c.abs_diff(before[0]) <= 1),
        "{before:?}"
    );
    let compiled = r.pipelines_compiled();
    assert_eq!(compiled, 3, "one specialised pipeline per model");
    assert!(!r.follow_catalogue().changed(), "nothing changed yet");

    // Save the file with twice the value and load it as the watcher would.
    std::fs::write(&path, greyish("2.0")).unwrap();
    bv_user::load(&path).unwrap();
    let followed = r.follow_catalogue();
    assert!(
        followed.compiling && !followed.redraw,
        "replacements compile, the stale pipelines draw what was drawn: {followed:?}"
    );
    // The draw after the change still shows the last version (the
    // replacements compile on the compile thread), then the new one.
    let meanwhile = centres(&r.render_image(&models, &settings, 192, 64).unwrap(), 3);
    assert_eq!(meanwhile, before, "the stale pipelines draw meanwhile");
    assert!(settle(|| r.poll_pipelines()), "the replacements arrive");
    let after = centres(&r.render_image(&models, &settings, 192, 64).unwrap(), 3);
    // Lambert unchanged; the file at 2×; the mix at 1.5× (linear values,
    // so compare through the display transform).
    let want = [shown(1.0), shown(2.0), shown(1.5)];
    for (k, (got, want)) in after.iter().zip(want).enumerate() {
        assert!(
            got.abs_diff(want) <= 1,
            "sphere {k}: {after:?}, want {want:?}"
        );
    }
    assert_eq!(
        r.pipelines_compiled() - compiled,
        2,
        "only the saved model's and the mix's pipelines are compiled again"
    );
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}

#[test]
fn the_environment_view_restarts_its_samples_for_a_saved_model() {
    let _turn = serial();
    let Some(gpu) = gpu_for_test() else { return };
    bv::session::user_models::install();
    let path = temp_file("env");
    std::fs::write(&path, greyish("1.0")).unwrap();
    let models = models(&path)[1..2].to_vec();
    let mut lib = ShaderLibrary::new().unwrap();
    let map = EnvironmentMap::constant([1.0; 3]);
    let mut r = EnvRenderer::new(gpu, &mut lib, &map).unwrap();
    let settings = EnvSettings::default();
    let centre = |img: &image::RgbaImage| {
        let (w, h) = img.dimensions();
        img.get_pixel(w / 2, h / 2).0[0]
    };
    assert!(!r.follow_catalogue().changed(), "nothing changed yet");
    let before = centre(&r.render_image(&models, &settings, 64, 64, 16).unwrap());
    assert_eq!(r.samples_per_pixel(), 16);
    std::fs::write(&path, greyish("0.25")).unwrap();
    bv_user::load(&path).unwrap();
    assert!(r.follow_catalogue().compiling);
    r.render_image(&models, &settings, 64, 64, 16).unwrap();
    assert!(settle(|| r.poll_pipelines()), "the replacement arrives");
    let after = centre(&r.render_image(&models, &settings, 64, 64, 16).unwrap());
    assert_eq!(r.samples_per_pixel(), 16, "the samples restarted");
    // What a renderer built from scratch for the new catalogue draws (the
    // same samples: the estimate is deterministic per frame).
    let mut fresh = EnvRenderer::new(
        gpu_for_test().unwrap(),
        &mut ShaderLibrary::new().unwrap(),
        &map,
    )
    .unwrap();
    let want = centre(&fresh.render_image(&models, &settings, 64, 64, 16).unwrap());
    assert!(
        before.abs_diff(want) > 40,
        "the save changed f: {before} → {want}"
    );
    assert_eq!(after, want, "in place as from scratch");
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}

/// A model first drawn after it was saved but before the renderer followed
/// the catalogue is drawn from the renderer's own (older) shaders; following
/// then still compiles it again.
#[test]
fn a_pipeline_built_from_older_shaders_is_compiled_again_when_followed() {
    let _turn = serial();
    let Some((path, models, mut r)) = lit_sphere("late") else {
        return;
    };
    let settings = head_on();
    r.render_image(&models[..1], &settings, 64, 64).unwrap();
    std::fs::write(&path, greyish("2.0")).unwrap();
    bv_user::load(&path).unwrap();
    // Not followed yet: the file's sphere shows the version the renderer's
    // shaders hold.
    let stale = centres(
        &r.render_image(&models[1..2], &settings, 64, 64).unwrap(),
        1,
    );
    assert!(stale[0].abs_diff(shown(1.0)) <= 1, "{stale:?}");
    assert!(r.follow_catalogue().compiling);
    r.render_image(&models[1..2], &settings, 64, 64).unwrap();
    assert!(settle(|| r.poll_pipelines()));
    let fresh = centres(
        &r.render_image(&models[1..2], &settings, 64, 64).unwrap(),
        1,
    );
    assert!(
        fresh[0].abs_diff(shown(2.0)) <= 1,
        "{fresh:?}, want {}",
        shown(2.0)
    );
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}

/// Every renderer compiling for one catalogue shares one composition of the
/// shaders; a changed catalogue gets a new one.
#[test]
fn one_catalogue_is_composed_once() {
    use bv::gpu::shaders::{Snapshot, shared};
    let _turn = serial();
    bv::session::user_models::install();
    let path = temp_file("shared");
    std::fs::write(&path, greyish("1.0")).unwrap();
    bv_user::load(&path).unwrap();
    let snapshot = Snapshot::now();
    let a = shared(&snapshot).unwrap();
    let b = shared(&Snapshot::now()).unwrap();
    assert!(std::sync::Arc::ptr_eq(&a, &b), "composed once");
    std::fs::write(&path, greyish("2.0")).unwrap();
    bv_user::load(&path).unwrap();
    let c = shared(&Snapshot::now()).unwrap();
    assert!(
        !std::sync::Arc::ptr_eq(&a, &c),
        "a new catalogue, a new library"
    );
    assert_eq!(
        c.lock().unwrap().catalogue_revision(),
        bv_core::registry::revision()
    );
    // The older snapshot still gets its own catalogue's library.
    let old = shared(&snapshot).unwrap();
    assert_eq!(old.lock().unwrap().catalogue_revision(), snapshot.revision);
    std::fs::remove_dir_all(path.parent().unwrap()).unwrap();
}
