//! naga validation of every shader in `shaders/` (issue 4, item 2): each entry
//! shader composed with naga_oil and validated, written back to WGSL and
//! re-parsed and re-validated (the exact text wgpu receives), and each
//! composable module composed and validated on its own.

use bv::gpu::shaders::{ENTRIES, MODULES, ShaderLibrary, to_wgsl, validate};

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
fn every_module_validates_on_its_own() {
    let mut lib = ShaderLibrary::new().unwrap();
    for (path, source) in MODULES {
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
fn every_catalogue_model_has_a_port() {
    // The dispatcher must name every model of the catalogue (the parity test
    // then checks the values).
    let brdf = MODULES
        .iter()
        .find(|(p, _)| *p == "shaders/brdf.wgsl")
        .unwrap()
        .1;
    for m in bv_core::catalogue() {
        let name = format!("L::MODEL_{}", bv::gpu::layout::ident(m.id));
        assert!(
            brdf.contains(&name),
            "shaders/brdf.wgsl does not dispatch `{}`",
            m.id
        );
    }
}
