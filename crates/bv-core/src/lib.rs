//! # bv-core
//!
//! All of bv's evaluation: the analytic BRDF models of the lecture, Fresnel
//! terms, microfacet distributions, measured data, lobe meshes and the property
//! analysis (positivity, reciprocity, isotropy, energy). It depends on no GUI
//! crate; the `bv` application, the shaders' parity tests and the command line
//! all call into it.
//!
//! Conventions: local frame with normal `+z`, tangent `+x`; `wi`
//! towards the light and `wo` towards the viewer, both pointing away from the
//! surface; `f(wi, wo)` is returned without the cosine factor, per linear-RGB
//! channel.

pub mod analysis;
pub mod batch;
pub mod brdf;
pub mod error;
pub mod fit;
pub mod frame;
pub mod fresnel;
pub mod fsio;
pub mod lobe;
pub mod measured;
pub mod microfacet;
pub mod microsurface;
pub mod model;
pub mod models;
pub mod multiscatter;
pub mod optics;
pub mod params;
pub mod presets;
pub mod quadrature;
pub mod registry;
pub mod represent;
pub mod rotated;
pub mod sampling;
pub mod swapped;
pub mod text;
pub mod user;

pub use brdf::{
    Brdf, BrdfSample, Claims, Cone, DeltaKind, DeltaLobe, EvalHealth, FresnelTerm, Kink,
    MicrofacetTerms, Ndf, sample_weighted,
};
pub use error::{BvError, Result};
pub use model::ModelInfo;
pub use params::{Applies, ModelSpec, ParamDecl, ParamKind, ParamValue, Params};
pub use registry::{catalogue, find, register};

/// A linear-RGB triple (one value per channel).
pub type Rgb = glam::DVec3;

/// Mean of the three channels: the scalar a lobe's radius and the reports use.
#[inline]
pub fn mean_rgb(c: Rgb) -> f64 {
    (c.x + c.y + c.z) / 3.0
}
