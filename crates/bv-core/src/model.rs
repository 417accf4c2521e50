//! What a model of the catalogue is: [`ModelInfo`], declared once per model
//! next to its evaluator (as a Mitsuba plugin is one file). Everything bv knows
//! about a model comes from here: its parameters and their aliases, how to
//! build its evaluator (whose [`crate::Brdf`] methods carry its claims,
//! sampling and microfacet/Fresnel terms), its GPU port and, for models read
//! from files, the file format.
//!
//! This module is a leaf: it names the vocabulary (declarations, values, the
//! evaluator interface) and nothing that lists models, so model files import
//! it without an import cycle through the catalogue ([`crate::registry`]).

use crate::params::decl::ParamDecl;
use crate::params::value::{ModelSpec, Params};
use crate::{Brdf, Result};
use std::fmt;
use std::path::Path;
use std::sync::Arc;

/// A parameter name that stands for several declared parameters at once
/// (`alpha` sets `alpha_x` and `alpha_y` of an anisotropic model). Explicit
/// values of the parameters it stands for win over the alias.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Alias {
    /// The accepted name.
    pub name: &'static str,
    /// The declared parameters it sets, all to the same value.
    pub sets: &'static [&'static str],
}

/// The roughness shorthand of the anisotropic microfacet models: `alpha`
/// sets `alpha_x = alpha_y`.
pub const ALPHA_ALIAS: Alias = Alias {
    name: "alpha",
    sets: &["alpha_x", "alpha_y"],
};

/// A run-time model's constructor, with what it captured (a compiled file).
pub type SharedBuild = Arc<dyn Fn(&Params) -> Result<Box<dyn Brdf>> + Send + Sync>;

/// The builder of an evaluator from a complete, validated parameter set.
#[derive(Clone)]
pub enum Build {
    /// A built-in model's constructor.
    Static(fn(&Params) -> Result<Box<dyn Brdf>>),
    /// A model built at run time (a user file).
    Shared(SharedBuild),
}

impl Build {
    /// Builds the evaluator.
    pub fn call(&self, params: &Params) -> Result<Box<dyn Brdf>> {
        match self {
            Build::Static(f) => f(params),
            Build::Shared(f) => f(params),
        }
    }
}

impl fmt::Debug for Build {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        match self {
            Build::Static(_) => f.write_str("Build::Static"),
            Build::Shared(_) => f.write_str("Build::Shared"),
        }
    }
}

/// Data a GPU view uploads beside the parameters (a measured table): stored
/// once per frame's buffer however many models use it.
pub trait GpuBlob: Send + Sync + fmt::Debug {
    /// The floats to upload.
    fn gpu_data(&self) -> &[f32];
}

/// Offsets of blobs in the shared table buffer are multiples of this many
/// floats, so that an offset stored in units of `TABLE_ALIGN` in an `f32`
/// slot stays exact up to 2²⁴ units.
pub const TABLE_ALIGN: usize = 4;

/// Where the packer puts the blobs of one frame.
pub trait GpuTables {
    /// The offset (in floats, a multiple of [`TABLE_ALIGN`]) of `blob` in the
    /// shared table buffer, adding it if new.
    fn offset_of(&mut self, blob: Arc<dyn GpuBlob>) -> usize;
}

/// Computes a model's derived slots (see [`GpuPort::derived`]); `tables`
/// receives the blobs the model's shader reads.
pub type DeriveSlots = fn(&ModelSpec, &mut dyn GpuTables) -> Result<Vec<f32>>;

/// How the environment renderer treats a model's delta lobes.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeltaPort {
    /// A mirror lobe only; the shader module defines
    /// `fn delta_reflectance(o: u32, c: f32) -> vec3<f32>`.
    Reflection,
    /// Mirror reflection and refraction into a dielectric; the module also
    /// defines `fn delta_eta(o: u32) -> f32`.
    Refraction,
}

/// A model's WGSL port: the shader module and what the generated dispatch and
/// parameter layout need to know about it.
#[derive(Debug, Clone)]
pub struct GpuPort {
    /// naga_oil import path of the module (`bv::models::cook_torrance`); it
    /// defines `fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32>`.
    pub module: &'static str,
    /// Where the source comes from, for error messages.
    pub path: &'static str,
    /// The WGSL source.
    pub source: &'static str,
    /// Names of the derived slots stored right after the parameter block, in
    /// order: quantities computed once on the CPU by bv-core's own functions
    /// (a normalisation constant, a table's dimensions), read by the shader
    /// through generated offsets `<MODEL>_<NAME>`.
    pub derived: &'static [&'static str],
    /// Computes the derived slots, in the order of [`GpuPort::derived`].
    pub derive: Option<DeriveSlots>,
    /// Whether the module defines `fn sampling_lobe(o: u32, wo: vec3<f32>) ->
    /// Lobe` (`bv::sampling_lobe`), the proxy lobe the environment renderer
    /// importance-samples; without one it samples the cosine.
    pub sampling_lobe: bool,
    /// Whether the module defines `fn sample_sphere(o: u32, wo: vec3<f32>,
    /// u: vec3<f32>) -> SphereSample` (`bv::sampling_lobe`): its own
    /// sampler on the whole sphere, with the weight f |cos θi| / pdf, so
    /// that the environment renderer follows its transmitted light through
    /// the object (issue 33: frosted glass).
    pub sphere_sampling: bool,
    /// The model's delta lobes, if it has any.
    pub delta: Option<DeltaPort>,
}

impl GpuPort {
    /// A port with no derived slots, no sampling proxy and no delta lobes.
    pub const fn new(module: &'static str, path: &'static str, source: &'static str) -> Self {
        Self {
            module,
            path,
            source,
            derived: &[],
            derive: None,
            sampling_lobe: false,
            sphere_sampling: false,
            delta: None,
        }
    }

    /// The same port with a sampler on the whole sphere.
    pub const fn with_sphere_sampling(mut self) -> Self {
        self.sphere_sampling = true;
        self
    }

    /// The same port with a sampling proxy.
    pub const fn with_sampling_lobe(mut self) -> Self {
        self.sampling_lobe = true;
        self
    }

    /// The same port with delta lobes.
    pub const fn with_delta(mut self, delta: DeltaPort) -> Self {
        self.delta = Some(delta);
        self
    }

    /// The same port with derived slots.
    pub const fn with_derived(
        mut self,
        names: &'static [&'static str],
        derive: DeriveSlots,
    ) -> Self {
        self.derived = names;
        self.derive = Some(derive);
        self
    }
}

/// Reports bytes read so far and the file's size while a file loads.
pub type Progress<'a> = dyn FnMut(u64, u64) + 'a;

/// Data a file-backed model reads from its file (a measured table).
pub trait FileData: GpuBlob {
    /// One-line facts for the panel and `bv info` (size, ranges).
    fn summary(&self) -> Vec<String>;
    /// What the reader noticed and repaired (unmeasured samples, NaNs).
    fn warnings(&self) -> Vec<String>;
}

/// A kind of file a model reads its data from (the `format` of a
/// [`crate::ParamKind::Path`] parameter): how to read one, with progress,
/// through a cache keyed by the file's identity.
pub trait FileFormat: Send + Sync + fmt::Debug {
    /// What the files are ("MERL table").
    fn name(&self) -> &'static str;
    /// A short tag for display names ("MERL").
    fn tag(&self) -> &'static str;
    /// Accepted extensions, lower case, without the dot.
    fn extensions(&self) -> &'static [&'static str];
    /// Reads and validates the file through the cache (path, modification
    /// time and length are the key), reporting progress.
    fn load(&self, path: &Path, progress: &mut Progress<'_>) -> Result<Arc<dyn FileData>>;
    /// Whether the file is already in the cache (a build will not read it).
    fn is_cached(&self, path: &Path) -> bool;
}

/// One model of the catalogue.
#[derive(Debug, Clone)]
pub struct ModelInfo {
    /// Stable id (`cook-torrance`).
    pub id: &'static str,
    /// Display name (`Cook-Torrance`).
    pub name: &'static str,
    /// One-line description.
    pub summary: &'static str,
    /// Where the formula comes from (paper, equation).
    pub citation: &'static str,
    /// The parameter declaration: the one source the CLI, scenes and GUI read.
    pub params: &'static [ParamDecl],
    /// Other names accepted for parameters.
    pub aliases: &'static [Alias],
    /// Builds an evaluator from a complete, validated parameter set.
    pub build: Build,
    /// The WGSL port; `None` for models the GPU views cannot draw.
    pub gpu: Option<GpuPort>,
}

impl ModelInfo {
    /// The declaration of parameter `id`, or an error listing the known ones.
    pub fn param(&self, id: &str) -> Result<&'static ParamDecl> {
        self.params
            .iter()
            .find(|d| d.id == id)
            .ok_or_else(|| crate::BvError::UnknownParam {
                model: self.id.to_string(),
                param: id.to_string(),
                known: self
                    .params
                    .iter()
                    .map(|d| d.id)
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }

    /// The alias named `name`, if the model declares one.
    pub fn alias(&self, name: &str) -> Option<&'static Alias> {
        self.aliases.iter().find(|a| a.name == name)
    }

    /// The model's file parameter and its format, if it reads a file.
    pub fn file_param(&self) -> Option<(&'static ParamDecl, &'static dyn FileFormat)> {
        self.params.iter().find_map(|d| match d.kind {
            crate::ParamKind::Path { format, .. } => Some((d, format)),
            _ => None,
        })
    }
}
