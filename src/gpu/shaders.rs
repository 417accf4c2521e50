//! The WGSL shaders of `shaders/`, composed with naga_oil.
//!
//! Why naga_oil 0.23: it is maintained (Bevy's shader composer) and is built on
//! naga 30, the naga of wgpu 30, so the composed `naga::Module` is validated by
//! the same validator that wgpu runs. Composition happens at start-up from the
//! sources embedded in the binary; the result is written back to WGSL for
//! `wgpu::ShaderSource::Wgsl` (no extra wgpu feature needed).
//!
//! Modules (`#define_import_path`) are registered in dependency order, and
//! only when an entry shader that imports them (directly or through another
//! module) is first composed: naga_oil parses and validates a module when it
//! is registered, and the lobe's shaders, which need only the colour map,
//! should not wait for every model's port. The modules are: the
//! generated `bv::layout` (parameter offsets, [`super::layout`]), the shared
//! [`COMMON`] modules, every model's own module from its GPU port in the
//! catalogue, the generated `bv::dispatch` ([`super::dispatch`]) and the
//! [`DISPATCHERS`] over it, and the generated `bv::colormap` (the lobe's colour
//! map, [`super::colormap`]). Entry shaders (`parity`, `lit_sphere`, `env`,
//! `env_display`, and the lobe view's `lobe`, `lines` and `blit`) import what
//! they need. A library holds the catalogue as it was when it was
//! made ([`ShaderLibrary::catalogue_revision`]).

use anyhow::{Context, Result, anyhow};
use naga_oil::compose::{
    ComposableModuleDescriptor, Composer, NagaModuleDescriptor, ShaderLanguage, ShaderType,
};
use std::collections::HashSet;

/// `(path, source)` of a file under `shaders/`, embedded in the binary.
macro_rules! shader {
    ($path:literal) => {
        (
            concat!("shaders/", $path),
            include_str!(concat!("../../shaders/", $path)),
        )
    };
}

/// Shared modules the model ports build on, in dependency order: (path under
/// the crate root, source).
pub const COMMON: &[(&str, &str)] = &[
    shader!("common/params.wgsl"),
    shader!("common/frame.wgsl"),
    shader!("common/fresnel.wgsl"),
    shader!("common/microfacet.wgsl"),
    shader!("common/display.wgsl"),
    shader!("common/sphere.wgsl"),
    shader!("common/torus.wgsl"),
    shader!("common/sampling.wgsl"),
    shader!("common/sampling_lobe.wgsl"),
    shader!("common/envmap.wgsl"),
];

/// Modules over the generated dispatch: evaluation with mixes, and sampling.
pub const DISPATCHERS: &[(&str, &str)] = &[shader!("brdf.wgsl"), shader!("brdf_sampling.wgsl")];

/// Entry shaders (with entry points): (name, (path, source)).
pub const ENTRIES: &[(&str, (&str, &str))] = &[
    ("parity", shader!("parity.wgsl")),
    ("lit_sphere", shader!("lit_sphere.wgsl")),
    ("env", shader!("env.wgsl")),
    ("env_display", shader!("env_display.wgsl")),
    ("lobe", shader!("lobe.wgsl")),
    ("lines", shader!("lines.wgsl")),
    ("blit", shader!("blit.wgsl")),
];

/// The line of an entry shader that [`ShaderLibrary::specialised_wgsl`]
/// replaces (its value [`ANY_MODEL`] means: read the model per tile).
pub const FIXED_MODEL_DECLARATION: &str = "const FIXED_MODEL: u32 = 0xffffffffu;";

/// `FIXED_MODEL` of a generic shader.
pub const ANY_MODEL: u32 = 0xffff_ffff;

/// The catalogue at one moment and its revision: what a library, or a
/// pipeline, made from it holds.
#[derive(Debug, Clone)]
pub struct Snapshot {
    /// [`bv_core::registry::revision`] when it was taken.
    pub revision: u64,
    /// The models, by catalogue index.
    pub catalogue: bv_core::registry::Catalogue,
}

impl Snapshot {
    /// The current catalogue.
    pub fn now() -> Self {
        // The revision before the catalogue: a model registered in between
        // makes the snapshot look older than it is, never newer.
        let revision = bv_core::registry::revision();
        Self {
            revision,
            catalogue: bv_core::catalogue(),
        }
    }
}

/// A library shared by everything that compiles for one catalogue.
pub type SharedLibrary = std::sync::Arc<std::sync::Mutex<ShaderLibrary>>;

/// The library of `snapshot`, composed once for all who ask: composing every
/// module takes tens of milliseconds, and after a user's file is saved each
/// renderer compiling its replacement pipelines needs the same one. The
/// library of the latest revision asked for is kept.
pub fn shared(snapshot: &Snapshot) -> Result<SharedLibrary> {
    static LATEST: std::sync::Mutex<Option<(u64, SharedLibrary)>> = std::sync::Mutex::new(None);
    // Nothing is left half-made in the cache by a panic: it only swaps.
    let mut latest = LATEST.lock().unwrap_or_else(|e| e.into_inner());
    if let Some((revision, lib)) = latest.as_ref()
        && *revision == snapshot.revision
    {
        return Ok(lib.clone());
    }
    let lib = std::sync::Arc::new(std::sync::Mutex::new(ShaderLibrary::of(snapshot)?));
    if latest.as_ref().is_none_or(|(r, _)| *r < snapshot.revision) {
        *latest = Some((snapshot.revision, lib.clone()));
    }
    Ok(lib)
}

/// A composer over every module of `shaders/` and of the catalogue's GPU
/// ports, each registered when first needed.
pub struct ShaderLibrary {
    composer: Composer,
    /// Every composable module in registration order, registered or not.
    modules: Vec<Composable>,
    revision: u64,
    /// The catalogue the modules were composed from.
    catalogue: bv_core::registry::Catalogue,
}

impl std::fmt::Debug for ShaderLibrary {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("ShaderLibrary").finish_non_exhaustive()
    }
}

impl ShaderLibrary {
    /// A library of the current catalogue: the generated layout, every shared
    /// module, every model's port and the generated dispatch, registered as
    /// entry shaders need them.
    pub fn new() -> Result<Self> {
        Self::of(&Snapshot::now())
    }

    /// The library of the catalogue `snapshot` holds.
    pub fn of(snapshot: &Snapshot) -> Result<Self> {
        let (revision, catalogue) = (snapshot.revision, snapshot.catalogue.clone());
        let modules = Self::modules_of(&catalogue)?
            .into_iter()
            .map(|(path, source)| Composable::new(path, source))
            .collect();
        Ok(Self {
            composer: Composer::default(),
            modules,
            revision,
            catalogue,
        })
    }

    /// Registers, in registration order, every module that `source` imports
    /// directly or through other modules and that is not registered yet.
    fn register_imports_of(&mut self, source: &str) -> Result<()> {
        let mut wanted = directives(source).1;
        let mut needed: HashSet<usize> = HashSet::new();
        while let Some(import) = wanted.pop() {
            for (i, m) in self.modules.iter().enumerate() {
                if m.provides(&import) && needed.insert(i) {
                    wanted.extend(m.imports.iter().cloned());
                }
            }
        }
        // A module without an import path cannot be named: it is registered
        // with the first shader composed, as every module used to be.
        needed.extend((0..self.modules.len()).filter(|&i| self.modules[i].name.is_none()));
        // In dependency order (naga_oil needs a module's imports registered
        // before it): each round registers the needed modules whose imports
        // are all registered; registration order breaks ties, and a cycle
        // is left to naga_oil to report.
        let mut pending: Vec<usize> = (0..self.modules.len())
            .filter(|i| needed.contains(i) && !self.modules[*i].registered)
            .collect();
        while !pending.is_empty() {
            let ready: Vec<usize> = pending
                .iter()
                .copied()
                .filter(|&i| {
                    self.modules[i].imports.iter().all(|import| {
                        self.modules
                            .iter()
                            .all(|m| m.registered || !m.provides(import))
                    })
                })
                .collect();
            let batch = if ready.is_empty() {
                std::mem::take(&mut pending)
            } else {
                pending.retain(|i| !ready.contains(i));
                ready
            };
            for i in batch {
                let m = &self.modules[i];
                let added = self
                    .composer
                    .add_composable_module(ComposableModuleDescriptor {
                        source: &m.source,
                        file_path: &m.path,
                        language: ShaderLanguage::Wgsl,
                        ..Default::default()
                    });
                if let Err(e) = added {
                    return Err(anyhow!("{}: {}", m.path, e.emit_to_string(&self.composer)));
                }
                self.modules[i].registered = true;
            }
        }
        Ok(())
    }

    /// Every composable module of the current catalogue, generated ones
    /// included, in registration order: (path, source).
    pub fn modules() -> Result<Vec<(String, String)>> {
        Self::modules_of(&bv_core::catalogue())
    }

    fn modules_of(catalogue: &[&'static bv_core::ModelInfo]) -> Result<Vec<(String, String)>> {
        let mut out = vec![
            (
                "<generated bv::layout>".to_string(),
                super::layout::layout_module()?,
            ),
            (
                "<generated bv::colormap>".to_string(),
                super::colormap::colormap_module(),
            ),
        ];
        out.extend(COMMON.iter().map(|(p, s)| (p.to_string(), s.to_string())));
        for (_, m) in super::dispatch::ported(catalogue) {
            if let Some(port) = &m.gpu {
                out.push((port.path.to_string(), port.source.to_string()));
            }
        }
        out.push((
            "<generated bv::dispatch>".to_string(),
            super::dispatch::dispatch_module(catalogue)?,
        ));
        out.extend(
            DISPATCHERS
                .iter()
                .map(|(p, s)| (p.to_string(), s.to_string())),
        );
        Ok(out)
    }

    /// The paths of the modules registered so far, in registration order
    /// (those the shaders composed up to now import).
    pub fn registered(&self) -> impl Iterator<Item = &str> {
        self.modules
            .iter()
            .filter(|m| m.registered)
            .map(|m| m.path.as_str())
    }

    /// The catalogue revision ([`bv_core::registry::revision`]) the library
    /// was made for: a model registered since is not in it.
    pub fn catalogue_revision(&self) -> u64 {
        self.revision
    }

    /// The catalogue the library's modules were composed from (indices are
    /// the models' `MODEL_*` constants).
    pub fn catalogue(&self) -> &[&'static bv_core::ModelInfo] {
        &self.catalogue
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
        self.register_imports_of(source)?;
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

    /// Entry shader `name` specialised for one model (catalogue index
    /// `model`), or generic for `None`: the entry's
    /// [`FIXED_MODEL_DECLARATION`] gets the index, so that the driver's
    /// compiler folds the model dispatch away. Why: a software rasteriser
    /// (lavapipe) runs every branch of the dispatch on every pixel under an
    /// execution mask, so the generic shader costs the sum of all models
    /// (measured: 30 ms against 2–3 ms for a 465×370 lit sphere).
    pub fn specialised_wgsl(&mut self, name: &str, model: Option<u32>) -> Result<String> {
        let (_, (path, source)) = ENTRIES
            .iter()
            .find(|(n, _)| *n == name)
            .ok_or_else(|| anyhow!("no entry shader `{name}`"))?;
        let Some(model) = model else {
            return self.wgsl(name);
        };
        if model == ANY_MODEL || !source.contains(FIXED_MODEL_DECLARATION) {
            return Err(anyhow!(
                "entry shader `{name}` cannot be specialised for model {model}"
            ));
        }
        let source = source.replace(
            FIXED_MODEL_DECLARATION,
            &format!("const FIXED_MODEL: u32 = {model}u;"),
        );
        let module = self.compose_source(path, &source)?;
        to_wgsl(&module).with_context(|| format!("writing shader `{name}` as WGSL"))
    }

    /// A wgpu shader module of [`Self::specialised_wgsl`].
    pub fn specialised_module(
        &mut self,
        device: &wgpu::Device,
        name: &str,
        model: Option<u32>,
    ) -> Result<wgpu::ShaderModule> {
        let source = self.specialised_wgsl(name, model)?;
        Ok(device.create_shader_module(wgpu::ShaderModuleDescriptor {
            label: Some(name),
            source: wgpu::ShaderSource::Wgsl(source.into()),
        }))
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

/// One composable module: its source, the import path it declares and the
/// modules it imports.
struct Composable {
    path: String,
    source: String,
    /// Its `#define_import_path`.
    name: Option<String>,
    /// What its `#import` lines name.
    imports: Vec<String>,
    registered: bool,
}

impl Composable {
    fn new(path: String, source: String) -> Self {
        let (name, imports) = directives(&source);
        Self {
            path,
            source,
            name,
            imports,
            registered: false,
        }
    }

    /// Whether `import` may name this module: `#import a::b::item` names
    /// module `a::b`, and `#import a::{b::item, c}` names `a::b` and `a::c`,
    /// so either may be a prefix of the other. Registering a module not
    /// needed costs time, never a wrong shader.
    fn provides(&self, import: &str) -> bool {
        let prefix = |long: &str, short: &str| {
            long == short
                || long
                    .strip_prefix(short)
                    .is_some_and(|rest| rest.starts_with("::"))
        };
        self.name
            .as_deref()
            .is_some_and(|name| prefix(import, name) || prefix(name, import))
    }
}

/// The import path a module declares (`#define_import_path`) and the paths
/// its `#import` lines name, up to a brace list or an `as`. A line scan:
/// naga_oil's own preprocessor took 11 ms over bv's modules, as long as
/// composing the lobe's three shaders.
fn directives(source: &str) -> (Option<String>, Vec<String>) {
    let path_of = |rest: &str| -> Option<String> {
        let rest = rest.trim_start().trim_start_matches('"');
        let path: String = rest
            .chars()
            .take_while(|c| c.is_alphanumeric() || *c == '_' || *c == ':')
            .collect();
        let path = path.trim_end_matches(':');
        (!path.is_empty()).then(|| path.to_string())
    };
    let mut name = None;
    let mut imports = Vec::new();
    for line in source.lines().map(str::trim_start) {
        if let Some(rest) = line.strip_prefix("#define_import_path") {
            name = path_of(rest);
        } else if let Some(rest) = line.strip_prefix("#import") {
            imports.extend(path_of(rest));
        }
    }
    (name, imports)
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

#[cfg(test)]
mod tests {
    use super::directives;

    #[test]
    fn directives_name_the_module_and_its_imports() {
        let src = "#define_import_path bv::models::ggx\n\
                   // #import not::a::directive\n\
                   #import bv::common::frame::{to_local, Frame}\n\
                   #import bv::common::fresnel as fresnel\n\
                   #import bv::colormap::COLORMAP\n\
                     #import \"quoted::path\"\n\
                   #import bv::{\n    layout::OFFSETS,\n}\n";
        let (name, imports) = directives(src);
        assert_eq!(name.as_deref(), Some("bv::models::ggx"));
        assert_eq!(
            imports,
            [
                "bv::common::frame",
                "bv::common::fresnel",
                "bv::colormap::COLORMAP",
                "quoted::path",
                "bv",
            ]
        );
        assert_eq!(directives("fn f() {}"), (None, vec![]));
    }
}
