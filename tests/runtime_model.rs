//! A model built at run time (as a user's file will be) joins the catalogue
//! and is then available to everything that takes a catalogue model: lookup
//! by id, specs and scene files, evaluation, `check`'s analysis, the GPU
//! (through the generated dispatch) and every view. It runs in its own test
//! process because the catalogue is process-wide.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::export::{self, Frame, Offscreen};
use bv::gpu::eval::GpuEvaluator;
use bv::gpu::shaders::ShaderLibrary;
use bv::session::scene_file;
use bv::session::state::AppState;
use bv::views::REGISTRY;
use bv_core::model::{Build, GpuPort, ModelInfo};
use bv_core::params::{Applies, ColorSpec, ParamDecl, ParamKind, Params};
use bv_core::{Brdf, Claims, ModelSpec, Rgb};
use eframe::egui::Vec2;
use glam::DVec3;
use std::f64::consts::PI;
use std::sync::{Arc, OnceLock};

const ID: &str = "test-warm-lambert";

/// f = albedo/π · (½ + cos θi cos θo): reciprocal, isotropic, and with
/// ρhd(θi) = albedo (½ + ⅔ cos θi) in closed form (∫ cos θo dω = π,
/// ∫ cos² θo dω = 2π/3).
#[derive(Debug)]
struct WarmLambert {
    albedo: Rgb,
}

impl Brdf for WarmLambert {
    fn id(&self) -> &'static str {
        ID
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.albedo / PI * (0.5 + wi.z * wo.z)
    }

    fn claims(&self) -> Claims {
        Claims {
            reciprocal: true,
            energy_conserving: self.albedo.max_element() * (0.5 + 2.0 / 3.0) <= 1.0,
            isotropic: true,
        }
    }
}

static PARAMS: &[ParamDecl] = &[ParamDecl {
    id: "albedo",
    label: "albedo",
    doc: "Reflectance scale",
    kind: ParamKind::Color(ColorSpec::unit_range([0.6, 0.5, 0.4])),
    applies: Applies::Always,
}];

const WGSL: &str = "\
#define_import_path bv::test::warm_lambert
#import bv::params::prgb
#import bv::frame::INV_PI
#import bv::layout::TEST_WARM_LAMBERT_ALBEDO

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    return prgb(o + TEST_WARM_LAMBERT_ALBEDO) * INV_PI * (0.5 + wi.z * wo.z);
}
";

/// Registers the model once per process, with a builder that captures data
/// (what a compiled user file does).
fn model() -> &'static ModelInfo {
    static INFO: OnceLock<&'static ModelInfo> = OnceLock::new();
    INFO.get_or_init(|| {
        let scale = Arc::new(1.0f64);
        let build = Build::Shared(Arc::new(move |p: &Params| {
            Ok(Box::new(WarmLambert {
                albedo: p.color("albedo")? * *scale,
            }) as Box<dyn Brdf>)
        }));
        bv_core::register(ModelInfo {
            id: ID,
            name: "Warm Lambert (test)",
            summary: "A run-time model of the catalogue test",
            citation: "none",
            params: PARAMS,
            aliases: &[],
            build,
            gpu: Some(GpuPort::new("bv::test::warm_lambert", "<test>", WGSL)),
        })
        .unwrap()
    })
}

fn spec() -> ModelSpec {
    model();
    ModelSpec::new(ID).unwrap()
}

#[test]
fn the_catalogue_finds_it_and_built_ins_cannot_be_replaced() {
    let before = bv_core::registry::revision();
    let m = model();
    assert!(std::ptr::eq(bv_core::find(ID).unwrap(), m));
    assert!(bv_core::catalogue().iter().any(|x| x.id == ID));
    assert!(bv_core::registry::revision() >= before);
    // A built-in id is refused.
    let mut lambert = bv_core::find("lambert").unwrap().clone();
    lambert.gpu = None;
    assert!(bv_core::register(lambert).is_err());
}

#[test]
fn specs_eval_and_scene_files_work_on_it() {
    let s = ModelSpec::from_json(ID, &serde_json::json!({"albedo": 0.3})).unwrap();
    let b = s.build().unwrap();
    let wi = DVec3::new(0.6, 0.0, 0.8);
    let wo = DVec3::new(0.0, 0.6, 0.8);
    let want = 0.3 / PI * (0.5 + 0.64);
    assert!((b.eval(wi, wo).x - want).abs() < 1e-15);
    assert!(ModelSpec::from_json(ID, &serde_json::json!({"albedo": 2.0})).is_err());
    // Through a scene file and back.
    let mut state = AppState::default();
    state.add(s.clone());
    let text = scene_file::to_toml(&state).unwrap();
    let back = scene_file::from_toml(&text).unwrap();
    assert_eq!(back.state.brdfs[0].spec, s);
}

#[test]
fn check_measures_it_against_its_closed_form() {
    let b = spec().build().unwrap();
    let report = bv_core::analysis::check(b.as_ref(), &bv_core::analysis::CheckOptions::default());
    assert!(report.positivity.ok);
    assert!(report.reciprocity.reciprocal);
    assert!(report.isotropy.isotropic);
    assert!(report.energy.conserves);
    // max ρhd is at normal incidence: albedo (½ + ⅔) for the red channel.
    let want = 0.6 * (0.5 + 2.0 / 3.0);
    let est = report.energy.max;
    let err = (est.value.x - want).abs();
    assert!(
        err <= est.allowance(5.0).x.max(1e-9),
        "ρhd max {} against {want}: error {err} beyond its allowance",
        est.value.x
    );
    assert!(report.consistent_with_claims());
}

#[test]
fn the_gpu_evaluates_it_through_the_generated_dispatch() {
    let s = spec();
    let Some(gpu) = bv::gpu::context::gpu_for_test() else {
        return;
    };
    let mut lib = ShaderLibrary::new().unwrap();
    let eval = GpuEvaluator::new(gpu, &mut lib).unwrap();
    let b = s.build().unwrap();
    let mut pairs = Vec::new();
    for i in 0..8 {
        for j in 0..8 {
            let ti = 0.1 + 1.3 * i as f64 / 8.0;
            let to = 0.1 + 1.3 * j as f64 / 8.0;
            let wi = DVec3::new(ti.sin(), 0.0, ti.cos());
            let wo = DVec3::new(-to.sin() * 0.6, to.sin() * 0.8, to.cos());
            pairs.push((wi, wo));
        }
    }
    let f32_pairs: Vec<_> = pairs
        .iter()
        .map(|(a, b)| (a.as_vec3().to_array(), b.as_vec3().to_array()))
        .collect();
    let got = eval.eval(&s, &f32_pairs).unwrap();
    for ((wi, wo), g) in pairs.iter().zip(&got) {
        let want = b.eval(*wi, *wo);
        for c in 0..3 {
            let w = want[c];
            assert!(
                (f64::from(g[c]) - w).abs() <= 1e-4 * w.abs() + 1e-6,
                "GPU {g:?} against CPU {want} at {wi} {wo}"
            );
        }
    }
}

#[test]
fn every_view_draws_it() {
    let s = spec();
    let Some(_) = bv::gpu::context::gpu_for_test() else {
        return;
    };
    let mut state = AppState::default();
    let id = state.add(s);
    state.selected = Some(id);
    let mut off = Offscreen::headless().unwrap();
    let frame = Frame {
        size: Vec2::new(360.0, 270.0),
        pixels_per_point: 1.0,
        dark: true,
        transparent: false,
    };
    for e in REGISTRY.iter() {
        let img = export::render_view(&mut off, &state, e, frame)
            .unwrap_or_else(|err| panic!("view {}: {err:#}", e.id));
        assert!(!export::is_blank(&img), "view {} is blank", e.id);
    }
}
