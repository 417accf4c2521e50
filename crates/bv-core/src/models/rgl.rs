//! `rgl`: a measured material of the RGL database (EPFL), read from its
//! `.bsdf` tensor file and evaluated by the adaptive parameterization of
//! Dupuy & Jakob 2018 ([`crate::measured::rgl`]).

use crate::measured::rgl::{self as material, RglMaterial};
use crate::model::{
    Build, FileData, FileFormat, GpuPort, GpuTables, ModelInfo, Progress, TABLE_ALIGN,
};
use crate::params::decl::{Applies, ParamDecl, ParamKind};
use crate::params::value::ModelSpec;
use crate::params::value::Params;
use crate::{Brdf, BvError, Claims, Result, Rgb};
use glam::{DVec2, DVec3};
use std::path::Path;
use std::sync::Arc;

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[ParamDecl {
    id: "path",
    label: "file",
    doc: "RGL material .bsdf file (tensor file of Dupuy & Jakob 2018: VNDF, luminance and RGB or spectral tables)",
    kind: ParamKind::Path {
        default: "",
        format: &RGL_FILES,
    },
    applies: Applies::Always,
}];

/// Catalogue entry. The GPU port draws every file the CPU evaluates
/// (isotropic and anisotropic, every φi and θi slice interpolated as
/// [`RglMaterial::eval`] does), up to [`material::GPU_MAX_FLOATS`] floats of
/// tables; it importance-samples a GGX proxy lobe fitted to the file's NDF
/// ([`RglMaterial::sampling_proxy`]).
pub static INFO: ModelInfo = ModelInfo {
    id: "rgl",
    name: "RGL measured",
    summary: "Measured material of the RGL database: VNDF-warped tables per incident direction",
    citation: "Dupuy & Jakob 2018, An Adaptive Parameterization for Efficient Material Acquisition and Rendering, §4–6; Mitsuba 3 `measured`",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::rgl",
            "shaders/models/rgl.wgsl",
            include_str!("../../../../shaders/models/rgl.wgsl"),
        )
        .with_derived(DERIVED_SLOTS, derive_slots)
        .with_sampling_lobe(),
    ),
};

/// Derived GPU slots of `rgl` (read by `shaders/models/rgl.wgsl`): the
/// blob's offset in the frame's table buffer (units of [`TABLE_ALIGN`]
/// floats), then [`RglMaterial::gpu_slots`], then the sampling proxy's
/// GGX αx and αy, diffuse and glossy weights ([`RglMaterial::sampling_proxy`]).
const DERIVED_SLOTS: &[&str] = &[
    "table",
    "n_theta",
    "vndf_x",
    "vndf_y",
    "values",
    "ndf_x",
    "ndf_y",
    "sigma_x",
    "sigma_y",
    "jacobian",
    "at_theta",
    "at_vndf",
    "at_marginal",
    "at_conditional",
    "at_rgb",
    "at_ndf",
    "n_phi",
    "at_phi",
    "isotropic",
    "reduction",
    "lobe_alpha_x",
    "lobe_alpha_y",
    "lobe_diffuse",
    "lobe_glossy",
];

fn derive_slots(spec: &ModelSpec, tables: &mut dyn GpuTables) -> Result<Vec<f32>> {
    // Through the cache: the same material as the built model's.
    let path = spec.params().text("path")?;
    let m = material::read_cached(path, &mut |_, _| {})?;
    // A file the port cannot draw (tables too large) is refused here rather
    // than packed as zeros: the GPU views then say why instead of drawing
    // it black.
    if let Some(why) = m.gpu_blob_error() {
        return Err(BvError::Invalid(format!(
            "{path}: the GPU views cannot draw this RGL file: {why}; the CPU views \
             (lobe, polar, slices, albedo) draw it"
        )));
    }
    let slots = m.gpu_slots();
    let proxy = m.sampling_proxy();
    let offset = tables.offset_of(m) / TABLE_ALIGN;
    let mut out = vec![offset as f32];
    out.extend_from_slice(&slots);
    out.extend([
        proxy.alpha_x as f32,
        proxy.alpha_y as f32,
        proxy.diffuse as f32,
        proxy.glossy as f32,
    ]);
    Ok(out)
}

/// RGL `.bsdf` files as a file format (reader and cache in
/// [`crate::measured::rgl`]).
#[derive(Debug)]
pub struct RglFiles;

/// The format of `rgl`'s `path` parameter.
pub static RGL_FILES: RglFiles = RglFiles;

impl FileFormat for RglFiles {
    fn name(&self) -> &'static str {
        "RGL material"
    }

    fn tag(&self) -> &'static str {
        "RGL"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["bsdf"]
    }

    fn load(&self, path: &Path, progress: &mut Progress<'_>) -> Result<Arc<dyn FileData>> {
        let m = material::read_cached(path, &mut |a, b| progress(a, b))?;
        Ok(m)
    }

    fn is_cached(&self, path: &Path) -> bool {
        material::is_cached(path)
    }
}

/// A measured RGL material.
#[derive(Debug, Clone)]
pub struct Rgl {
    material: Arc<RglMaterial>,
}

impl Rgl {
    /// A model over an already loaded material.
    pub fn new(material: Arc<RglMaterial>) -> Self {
        Self { material }
    }

    /// The material.
    pub fn material(&self) -> &Arc<RglMaterial> {
        &self.material
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    let path = p.text("path")?;
    if path.trim().is_empty() {
        return Err(BvError::BadValue {
            param: "path".into(),
            reason: "no file given: set it to an RGL .bsdf file".into(),
        });
    }
    let m = material::read_cached(path, &mut |_, _| {})?;
    Ok(Box::new(Rgl::new(m)))
}

impl Brdf for Rgl {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.material.eval(wi, wo)
    }

    fn claims(&self) -> Claims {
        Claims {
            // Each incident direction is its own table: nothing makes the
            // lookup reciprocal; the analysis reports what it finds.
            reciprocal: false,
            // Measured data makes no promise.
            energy_conserving: false,
            // Rotation invariance needs more than the file's "isotropic"
            // layout: σ and the NDF must not vary with φ, and one φi slice.
            isotropic: self.material.is_rotation_invariant(),
        }
    }

    /// A measured file promises nothing: the claims above describe the
    /// lookup, to steer the analysis (`bv check` shows "—").
    fn claims_declared(&self) -> bool {
        false
    }

    fn file_data(&self) -> Option<Arc<dyn FileData>> {
        Some(self.material.clone())
    }

    /// Through the stored luminance and VNDF warps (the paper's sampling,
    /// §6), as Mitsuba's `measured` samples.
    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        self.material.sample(wi, u)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.material.pdf(wi, wo)
    }
}
