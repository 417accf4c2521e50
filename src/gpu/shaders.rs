//! The WGSL shaders of `shaders/`, composed with naga_oil.
//!
//! Why naga_oil 0.23: it is maintained (Bevy's shader composer) and is built on
//! naga 30, the naga of wgpu 30, so the composed `naga::Module` is validated by
//! the same validator that wgpu runs. Composition happens at start-up from the
//! sources embedded in the binary; the result is written back to WGSL for
//! `wgpu::ShaderSource::Wgsl` (no extra wgpu feature needed).
//!
//! Modules (`#define_import_path`) are registered in dependency order; entry
//! shaders (`parity`, `lit_sphere`, `env`) import what they need. The
//! `bv::layout` module is generated from the parameter declarations
//! ([`super::layout`]).

use anyhow::{Context, Result, anyhow};
use naga_oil::compose::{
    ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderLanguage, ShaderType,
};

/// `(path, source)` of a file under `shaders/`, embedded in the binary.
macro_rules! shader {
    ($path:literal) => {
        (
            concat!("shaders/", $path),
            include_str!(concat!("../../shaders/", $path)),
        )
    };
}

/// Composable modules, in dependency order: (path under the crate root, source).
pub const MODULES: &[(&str, &str)] = &[
    shader!("common/params.wgsl"),
    shader!("common/frame.wgsl"),
    shader!("common/fresnel.wgsl"),
    shader!("common/microfacet.wgsl"),
    shader!("common/display.wgsl"),
    shader!("common/sphere.wgsl"),
    shader!("common/torus.wgsl"),
    shader!("common/sampling.wgsl"),
    shader!("common/envmap.wgsl"),
    shader!("models/lambert.wgsl"),
    shader!("models/phong.wgsl"),
    shader!("models/blinn_phong.wgsl"),
    shader!("models/modified_phong.wgsl"),
    shader!("models/ashikhmin_shirley.wgsl"),
    shader!("models/oren_nayar.wgsl"),
    shader!("models/hapke.wgsl"),
    shader!("models/ward.wgsl"),
    shader!("models/lafortune.wgsl"),
    shader!("models/banks.wgsl"),
    shader!("models/cook_torrance.wgsl"),
    shader!("models/disney.wgsl"),
    shader!("models/mirror.wgsl"),
    shader!("models/glass.wgsl"),
    shader!("models/merl.wgsl"),
    shader!("brdf.wgsl"),
    shader!("brdf_sampling.wgsl"),
];

/// Entry shaders (with entry points): (name, (path, source)).
pub const ENTRIES: &[(&str, (&str, &str))] = &[
    ("parity", shader!("parity.wgsl")),
    ("lit_sphere", shader!("lit_sphere.wgsl")),
    ("env", shader!("env.wgsl")),
    ("env_display", shader!("env_display.wgsl")),
];

/// A composer holding every module of `shaders/`.
pub struct ShaderLibrary {
    composer: Composer,
}

impl std::fmt::Debug for ShaderLibrary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShaderLibrary").finish_non_exhaustive()
    }
}

impl ShaderLibrary {
    /// Registers the generated layout and every module.
    pub fn new() -> Result<Self> {
        let mut composer = Composer::default();
        let layout = super::layout::layout_module()?;
        let mut add = |path: &str, source: &str| -> Result<()> {
            let r = composer.add_composable_module(ComposableModuleDescriptor {
                source,
                file_path: path,
                language: ShaderLanguage::Wgsl,
                ..Default::default()
            });
            r.map(|_| ())
                .map_err(|e| anyhow!("{path}: {}", e.emit_to_string(&composer)))
        };
        add("<generated bv::layout>", &layout)?;
        for (path, source) in MODULES {
            add(path, source)?;
        }
        Ok(Self { composer })
    }

    /// The composed, validated naga module of entry shader `name`.
    pub fn module(&mut self, name: &str) -> Result<naga::Module> {
        let (_, (path, source)) = ENTRIES
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| anyhow!("no entry shader `{name}`"))?;
        self.compose_source(path, source)
    }

    /// Composes any WGSL source against the library's modules.
    pub fn compose_source(&mut self, path: &str, source: &str) -> Result<naga::Module> {
        self.composer
            .make_naga_module(NagaModuleDescriptor {
                source,
                file_path: path,
                shader_type: ShaderType::Wgsl,
                ..Default::default()
            })
            .map_err(|e| anyhow!("{path}: {}", e.emit_to_string(&self.composer)))
    }

    /// Entry shader `name` as one self-contained WGSL source (what wgpu gets).
    pub fn wgsl(&mut self, name: &str) -> Result<String> {
        let module = self.module(name)?;
        to_wgsl(&module).with_context(|| format!("writing shader `{name}` as WGSL"))
    }

    /// A wgpu shader module of entry shader `name`.
    pub fn shader_module(
        &mut self,
        device: &wgpu::Device,
        name: &str,
    ) -> Result<wgpu::ShaderModule> {
        let source = self.wgsl(name)?;
        Ok(device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        }))
    }
}

/// Validates a naga module (all checks, default capabilities: what wgpu
/// demands of a downlevel device).
pub fn validate(module: &naga::Module) -> Result<naga::valid::ModuleInfo> {
    naga::valid::Validator::new(
        naga::valid::ValidationFlags::all(),
        naga::valid::Capabilities::default(),
    )
    .validate(module)
    .map_err(|e| anyhow!("naga validation: {}", e.emit_to_string("")))
}

/// Validates and writes a module as WGSL.
pub fn to_wgsl(module: &naga::Module) -> Result<String> {
    let info = validate(module)?;
    naga::back::wgsl::write_string(module, &info, naga::back::wgsl::WriterFlags::empty())
        .map_err(|e| anyhow!("naga WGSL writer: {e}"))
}
