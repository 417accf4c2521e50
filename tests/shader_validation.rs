//! naga validation of every shader in `shaders/`: each entry
//! shader composed with naga_oil and validated, written back to WGSL and
//! re-parsed and re-validated (the exact text wgpu receives), and each
//! composable module composed and validated on its own.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use bv::gpu::shaders::{ENTRIES, ShaderLibrary, to_wgsl, validate};

#[test]
fn every_entry_shader_validates_and_round_trips() {
    let mut lib = ShaderLibrary::new().unwrap();
    for (name, _) in ENTRIES {
        let module = lib.module(name).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        validate(&module).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        let text = to_wgsl(&module).unwrap();
        let reparsed = naga::front::wgsl::parse_str(&text)
            .unwrap_or_else(|e| panic!("{name}: written WGSL does not parse: {e}\n{text}"));
        validate(&reparsed).unwrap_or_else(|e| panic!("{name}: written WGSL: {e:#}"));
    }
}

#[test]
fn the_lobe_view_shaders_translate_to_webgl2() {
    // The browser page falls back to WebGL2, whose shaders wgpu writes as
    // GLSL ES 3.00: a construct that lacks (`@interpolate(linear)`) would
    // leave the page's lobe view without lines or without the figure.
    let mut lib = ShaderLibrary::new().unwrap();
    for name in ["lobe", "lines", "blit"] {
        let module = lib.module(name).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        let info = validate(&module).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        assert!(!module.entry_points.is_empty(), "{name}: no entry point");
        for ep in &module.entry_points {
            let options = naga::back::glsl::Options {
                version: naga::back::glsl::Version::Embedded {
                    version: 300,
                    is_webgl: true,
                },
                ..Default::default()
            };
            let pipeline = naga::back::glsl::PipelineOptions {
                shader_stage: ep.stage,
                entry_point: ep.name.clone(),
                multiview: None,
            };
            let mut out = String::new();
            naga::back::glsl::Writer::new(
                &mut out,
                &module,
                &info,
                &options,
                &pipeline,
                naga::proc::BoundsCheckPolicies::default(),
            )
            .and_then(|mut w| w.write())
            .unwrap_or_else(|e| panic!("{name} {}: GLSL ES 3.00: {e}", ep.name));
        }
    }
}

#[test]
fn every_entry_composes_on_a_fresh_library() {
    // Modules are registered as shaders need them: each entry, first on its
    // library, must find everything it imports (directly or not).
    for (name, _) in ENTRIES {
        let mut lib = ShaderLibrary::new().unwrap();
        assert_eq!(lib.registered().count(), 0, "{name}: registered early");
        let module = lib.module(name).unwrap_or_else(|e| panic!("{name}: {e:#}"));
        validate(&module).unwrap_or_else(|e| panic!("{name}: {e:#}"));
    }
}

#[test]
fn the_lobe_shaders_leave_the_model_ports_unregistered() {
    // What the lazy registration is for: the lobe view starts without
    // parsing every model's port.
    let mut lib = ShaderLibrary::new().unwrap();
    for name in ["lobe", "lines", "blit"] {
        lib.module(name).unwrap();
    }
    let registered: Vec<&str> = lib.registered().collect();
    assert!(
        registered.iter().any(|p| p.contains("colormap")),
        "{registered:?}"
    );
    for m in bv_core::catalogue().iter() {
        if let Some(port) = &m.gpu {
            assert!(
                !registered.contains(&port.path),
                "{}: registered for the lobe: {registered:?}",
                m.id
            );
        }
    }
    // The lit sphere imports the dispatch, hence every port.
    lib.module("lit_sphere").unwrap();
    let registered: Vec<&str> = lib.registered().collect();
    for m in bv_core::catalogue().iter() {
        if let Some(port) = &m.gpu {
            assert!(registered.contains(&port.path), "{}", m.id);
        }
    }
}

#[test]
fn every_module_validates_on_its_own() {
    let mut lib = ShaderLibrary::new().unwrap();
    for (path, source) in ShaderLibrary::modules().unwrap() {
        let (path, source) = (path.as_str(), source.as_str());
        // Composed as a top-level shader, every item of the module (not only
        // those some entry point uses) is in the result and gets validated.
        let module = lib
            .compose_source(path, source)
            .unwrap_or_else(|e| panic!("{path}: {e:#}"));
        let items = module.functions.len() + module.constants.len();
        assert!(items > 0, "{path}: composed to an empty module");
        validate(&module).unwrap_or_else(|e| panic!("{path}: {e:#}"));
        if source.contains("\nfn ") {
            assert!(
                !module.functions.is_empty(),
                "{path}: functions were dropped"
            );
        }
    }
}

#[test]
fn every_catalogue_port_is_registered() {
    // The library holds each model's module from its port (the generated
    // dispatch's coverage is tested in gpu::dispatch, the values by the
    // parity test).
    let modules = ShaderLibrary::modules().unwrap();
    for m in bv_core::catalogue().iter() {
        if let Some(port) = &m.gpu {
            assert!(
                modules
                    .iter()
                    .any(|(p, s)| p == port.path && s == port.source),
                "{}: its port is not registered",
                m.id
            );
        }
    }
}
