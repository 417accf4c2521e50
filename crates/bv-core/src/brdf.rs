//! The evaluator interface every model implements.

use crate::{Rgb, sampling};
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// What a model claims about itself, for its current parameters. The property
/// tests hold every model to its claims; `bv check` prints them beside the
/// measured numbers.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct Claims {
    /// Helmholtz reciprocity `f(wi, wo) = f(wo, wi)`.
    pub reciprocal: bool,
    /// Directional albedo ρhd ≤ 1 for every incident direction.
    pub energy_conserving: bool,
    /// Invariance under a common rotation of `wi` and `wo` about the normal.
    pub isotropic: bool,
}

/// A function of the outgoing direction whose zero set is a kink of
/// `f(wi, ·)`: where a `min`, `max` or clamp in the model switches branch, so
/// that `f` is continuous but its slope jumps (see [`Brdf::kinks`]). Its sign
/// says which branch applies; only where it changes sign matters.
pub type Kink<'a> = Box<dyn Fn(DVec3) -> f64 + 'a>;

/// A cone of directions about a unit `axis`: the `w` with
/// `w·axis > cos_half` (a half-angle over 90° when `cos_half < 0`; see
/// [`Brdf::transmission_support`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Cone {
    /// The cone's axis (unit).
    pub axis: DVec3,
    /// The cosine of its half-angle.
    pub cos_half: f64,
}

/// Whether a delta lobe reflects or transmits.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum DeltaKind {
    /// Mirror reflection into the upper hemisphere.
    Reflection,
    /// Refraction into the lower hemisphere.
    Transmission,
}

/// A Dirac lobe: all of its energy leaves in one direction. Views draw it as a
/// spike of length `weight`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct DeltaLobe {
    /// Outgoing direction (unit, away from the surface).
    pub direction: DVec3,
    /// Fraction of the incident flux that leaves along `direction`, per channel
    /// (F for reflection, 1 − F for transmission).
    pub weight: Rgb,
    /// Factor applied to radiance along the lobe: equal to `weight` for
    /// reflection, `(ηo/ηi)² (1 − F)` for transmission (radiance is compressed
    /// when entering a denser medium).
    pub radiance_scale: Rgb,
    /// Reflection or transmission.
    pub kind: DeltaKind,
}

/// A microfacet normal distribution, for the D-normalisation check.
pub trait Ndf: Send + Sync {
    /// D(h) for a unit `h` in the upper hemisphere (1/sr).
    fn d(&self, h: DVec3) -> f64;

    /// The family and roughness (αx, αy) when the distribution is one
    /// scale of a family with a slope distribution (Beckmann or GGX), so
    /// that a simulated microsurface can be made with the same slopes
    /// (`microsurface`, issue 29). `None` for mixtures of scales, Blinn's
    /// θh Gaussian and anything else.
    fn slopes(&self) -> Option<(crate::microfacet::Distribution, f64, f64)> {
        None
    }
}

/// A bidirectional scattering distribution function: `wi` towards the light,
/// `wo` towards the viewer, both away from the surface, normal `+z`.
pub trait Brdf: Send + Sync + std::fmt::Debug {
    /// Model id from the catalogue.
    fn id(&self) -> &'static str;

    /// `f(wi, wo)` without the cosine factor, 1/sr, per linear-RGB channel.
    /// Zero when either direction is below the horizon (reflection models) and
    /// at every finite pair for delta models.
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb;

    /// `f(wi, wo)` for a pair both above the surface whose unit half vector
    /// `h = (wi + wo)/|wi + wo|` the caller has already (the albedo
    /// quadrature integrates over `h` and forms `wo` from it): a model whose
    /// `f` is built from `h` (a microfacet lobe's `D(h)`, `F(wi·h)`) may take
    /// it from here instead of normalising `wi + wo` again. It must return
    /// what [`Brdf::eval`] returns, to rounding (`h` may differ from the
    /// normalised sum by a few ulp). Default: [`Brdf::eval`], ignoring `h`.
    fn eval_with_half(&self, wi: DVec3, wo: DVec3, h: DVec3) -> Rgb {
        let _ = h;
        self.eval(wi, wo)
    }

    /// [`Brdf::eval`] at the pairs `(wi, wo[k])` into `out[k]` (the
    /// shorter of `wo` and `out`): the albedo quadrature's nodes of one
    /// panel. The same values as calling [`Brdf::eval`] per pair, bit for
    /// bit; the default does exactly that, and since a provided method is
    /// compiled for each model, the calls inside it are direct, where the
    /// quadrature's calls through `&dyn Brdf` each went through the vtable
    /// and kept the out-of-order core from overlapping one evaluation with
    /// the next (a GGX Cook-Torrance ρhd curve took a sixth less time).
    /// Override only with a form that returns the same values.
    fn eval_many(&self, wi: DVec3, wo: &[DVec3], out: &mut [Rgb]) {
        for (o, &w) in out.iter_mut().zip(wo) {
            *o = self.eval(wi, w);
        }
    }

    /// [`Brdf::eval_with_half`] at the pairs `(wi, wo[k])` with half
    /// vectors `h[k]` into `out[k]` (the shortest of the three), as
    /// [`Brdf::eval_many`] is to [`Brdf::eval`].
    fn eval_many_with_half(&self, wi: DVec3, wo: &[DVec3], h: &[DVec3], out: &mut [Rgb]) {
        for ((o, &w), &hh) in out.iter_mut().zip(wo).zip(h) {
            *o = self.eval_with_half(wi, w, hh);
        }
    }

    /// What the model claims for its current parameters.
    fn claims(&self) -> Claims;

    /// Whether [`Brdf::claims`] are promises the model's author made (every
    /// catalogue formula), rather than what a file's data was observed to do
    /// when it was loaded (a MERL table, a user `.brdf`): a file promises
    /// nothing, so its `claims` only steer the analysis (one azimuth for an
    /// isotropic table) and reports show "no claim" (issue 30). Default: true.
    fn claims_declared(&self) -> bool {
        true
    }

    /// The delta lobes for light arriving from `wi` (empty for non-delta models).
    fn deltas(&self, _wi: DVec3) -> Vec<DeltaLobe> {
        Vec::new()
    }

    /// Whether the model scatters into the lower hemisphere (lobe meshes then
    /// cover the whole sphere).
    fn transmits(&self) -> bool {
        false
    }

    /// For a model of an interface between two media: the relative index
    /// `η_below / η_above` (the `eta` of `glass` and `rough-dielectric`).
    /// Across such an interface a radiance BSDF is not symmetric: it obeys
    /// the generalised reciprocity `f(wi, wo)/ηo² = f(wo, wi)/ηi²`, with ηi
    /// and ηo the indices on the sides of `wi` and `wo` (Veach 1997, §5.2,
    /// eq. 5.14), and the reciprocity check compares that form (see
    /// [`crate::analysis::reciprocity`]). `None` (the default): the same
    /// medium on both sides, where reciprocity is `f(wi, wo) = f(wo, wi)`.
    fn interface_eta(&self) -> Option<f64> {
        None
    }

    /// Draws an outgoing direction for light from `wi`, given a uniform point
    /// `u ∈ [0,1)²`. `None` when no direction could be drawn. Default: cosine
    /// weighted, which suits diffuse-like models.
    fn sample(&self, _wi: DVec3, u: DVec2) -> Option<DVec3> {
        Some(sampling::cosine_hemisphere(u))
    }

    /// Solid-angle density of [`Brdf::sample`] at `wo` (must match it).
    fn pdf(&self, _wi: DVec3, wo: DVec3) -> f64 {
        sampling::cosine_hemisphere_pdf(wo)
    }

    /// Outgoing directions (unit) near which `f(wi, ·)` has a
    /// narrow peak or a cusp *away from the mirror direction*, so that the
    /// albedo quadrature places panel breaks there (a Lafortune lobe about
    /// `C wi`, Hapke's opposition surge at `wi`). The mirror direction is
    /// always treated as a peak. A transmitting model may name directions on
    /// the far side of the surface from `wi` (the refracted direction), about
    /// which the quadrature of the transmitted part is graded. Default: none.
    fn peaks(&self, _wi: DVec3) -> Vec<DVec3> {
        Vec::new()
    }

    /// A unit direction on `wi`'s side of the surface or in its plane about
    /// which `f(wi, ·)` is best integrated in polar coordinates: a point cusp
    /// there, where `f` depends on the angle from it like `|wo − c|` rather
    /// than smoothly (Hapke's opposition surge at `wo = wi`, Hapke 1981
    /// eq. 30 with `tan(g/2)`), or an axis on whose rings `f` is constant
    /// (Banks' fibre, where `f` depends on `wo` through `wo·t` alone). The
    /// albedo quadrature then integrates the part on `wi`'s side about it
    /// instead of over the half vector, where a cusp is a 2-D feature that
    /// both axes must resolve and Banks' cone a ridge across the circles.
    /// Name one only when the model has no narrow lobe about the half vector
    /// (which the half vector serves better); [`Brdf::peaks`] on that side
    /// still break the rings, and [`Brdf::kinks`] the rings and the polar
    /// angle where they cross the great circle through the pole and `wi`.
    /// Default: none.
    fn pole(&self, _wi: DVec3) -> Option<DVec3> {
        None
    }

    /// The kinks of `f(wi, ·)` (see [`Kink`]) over the outgoing directions on
    /// `wi`'s side (and, for a transmitting model, on the other side too),
    /// so that the albedo quadrature breaks its panels where they cross a
    /// circle of integration instead of bisecting towards them: Oren-Nayar's
    /// `max(0, cos Δφ)` and `max(cos θi, cos θo)`, V-groove's `min`, the
    /// rough dielectric's cone past which no facet refracts. A kink left out
    /// costs evaluations, not accuracy (the quadrature verifies its panels);
    /// a function whose sign changes where `f` is smooth costs a break.
    /// Default: none.
    fn kinks(&self, _wi: DVec3) -> Vec<Kink<'_>> {
        Vec::new()
    }

    /// For a transmitting model: cones that hold every direction on the far
    /// side of the surface from `wi` where `f(wi, ·)` may be non-zero
    /// (`f(wi, wo) = 0` for every `wo` with `wo.z · wi.z < 0` that lies
    /// outside any of them, `wo·axis ≤ cos_half`): the rough dielectric's
    /// cone past which no facet refracts and the plane beyond which the
    /// facet that would would face down. The albedo quadrature integrates
    /// the transmitted part only inside them, with breaks where its rings
    /// cross them: rings and arcs outside cost no evaluation (at 45° on the
    /// default rough dielectric, half of the transmitted part's evaluations
    /// were exact zeros out there). A claim, not a hint: a cone narrower
    /// than the model's support loses energy without a sign, so the
    /// catalogue's cones are tested against `eval`. Default: none (the
    /// whole far side).
    fn transmission_support(&self, _wi: DVec3) -> Vec<Cone> {
        Vec::new()
    }

    /// Whether `f` is a closed-form function that a deterministic quadrature
    /// may integrate to its stated accuracy. Tabulated and user-defined models
    /// answer `false`: their albedo is estimated by Monte Carlo.
    fn is_analytic(&self) -> bool {
        self.file_data().is_none()
    }

    /// The microfacet distribution, for models that have one.
    fn ndf(&self) -> Option<&dyn Ndf> {
        None
    }

    /// Evaluates many pairs at once (`out[i] = f(pairs[i])`). Models may override
    /// it with a faster loop; the default calls [`Brdf::eval`].
    fn eval_batch(&self, pairs: &[(DVec3, DVec3)], out: &mut [Rgb]) {
        for (o, &(wi, wo)) in out.iter_mut().zip(pairs) {
            *o = self.eval(wi, wo);
        }
    }

    /// The model's f32 batch kernel, if it has one (see [`crate::batch`]);
    /// callers go through [`crate::batch::eval`], which falls back to
    /// [`Brdf::eval`] lane by lane when this is `None`. Default: none.
    fn batch_kernel(&self) -> Option<&dyn crate::batch::Kernel> {
        None
    }

    /// The data a file-backed model read from its file (a measured table),
    /// for the panel and for GPU views that upload it. `None` for analytic
    /// models.
    fn file_data(&self) -> Option<std::sync::Arc<dyn crate::model::FileData>> {
        None
    }

    /// The model's microfacet terms (D, G1, G2), for plotting them apart.
    /// `None` for models that are not microfacet models.
    fn microfacet_terms(&self) -> Option<MicrofacetTerms> {
        None
    }

    /// The model's microfacet lobe under a white furnace: the same D, G,
    /// roughness and multiple-scattering choice with F = 1, no diffuse base
    /// and full weight, so that its directional albedo `E(μ)` is what the
    /// lobe keeps of the light and `1 − E(μ)` what single scattering loses
    /// (the albedo view's furnace switch; Kulla & Conty 2017). `None` for
    /// models that are not microfacet models.
    fn furnace(&self) -> Option<Box<dyn Brdf>> {
        None
    }

    /// The model's Fresnel term, for the Fresnel view: what multiplies its
    /// specular (or delta) lobe as a function of the angle of incidence.
    /// `None` for models without one.
    fn fresnel_term(&self) -> Option<FresnelTerm> {
        None
    }

    /// `f(wi, wo)`, or why it cannot be computed. The built-in models always
    /// succeed (the default is [`Brdf::eval`]); a user's shader can fail (its
    /// step budget, its memory limit), and that is an error here, where
    /// [`Brdf::eval`] reads it as 0 and counts it in [`Brdf::health`].
    fn try_eval(&self, wi: DVec3, wo: DVec3) -> crate::Result<Rgb> {
        Ok(self.eval(wi, wo))
    }

    /// How [`Brdf::eval`] has gone since the model was built: failed and
    /// non-finite evaluations, which it read as 0. Every analysis reads this
    /// after computing, so that a result built on failures is an error, not
    /// a silent 0. Default: nothing can fail.
    fn health(&self) -> EvalHealth {
        EvalHealth::default()
    }

    /// About how long one evaluation takes, where that can be far more than a
    /// built-in model's fraction of a microsecond (an interpreted shader,
    /// timed when it was built), so that an analysis can refuse a model too
    /// slow for it before it starts. Default: `None` (cheap).
    fn eval_cost(&self) -> Option<std::time::Duration> {
        None
    }

    /// Limits the wall-clock time evaluation may take from now on: past it,
    /// each [`Brdf::eval`] fails at once (counted in [`Brdf::health`]), so an
    /// analysis of a model that turned out too slow ends in bounded time and
    /// reports why. `None` lifts the limit. Default: nothing to limit.
    fn limit_time(&self, _budget: Option<std::time::Duration>) {}
}

/// Failed and non-finite evaluations of a model (see [`Brdf::health`]).
#[derive(Debug, Clone, Default, PartialEq, Eq)]
pub struct EvalHealth {
    /// Evaluations that failed (each read as 0).
    pub failed: u64,
    /// Evaluations whose value had a NaN or infinite channel (read as 0).
    pub non_finite: u64,
    /// Why the first failed evaluation failed, with its directions.
    pub first_failure: Option<String>,
}

impl EvalHealth {
    /// The error for a result computed with failed evaluations of model
    /// `id`, if any failed.
    pub fn failure(&self, id: &str) -> Option<crate::BvError> {
        (self.failed > 0).then(|| {
            crate::BvError::Invalid(format!(
                "{} evaluation{} of model `{id}` failed, so the result would be wrong; the first: {}",
                self.failed,
                if self.failed == 1 { "" } else { "s" },
                self.first_failure.as_deref().unwrap_or("no reason recorded")
            ))
        })
    }
}

/// The microfacet terms of a model, as functions a plot can sample: the
/// distribution D(h), Smith's masking G1(w) and the masking-shadowing term
/// G2(wi, wo) the model uses (Heitz 2014, "Understanding the
/// Masking-Shadowing Function", eqs. 2, 43 and 98), with their names.
#[derive(Clone)]
pub struct MicrofacetTerms {
    /// The distribution's name ("GGX").
    pub distribution: String,
    /// The masking-shadowing term's name ("height-correlated Smith").
    pub geometry: String,
    /// D(h) for a unit `h` in the upper hemisphere (1/sr).
    pub d: Arc<dyn Fn(DVec3) -> f64 + Send + Sync>,
    /// G1(w) of the distribution (Smith masking for `w` at the macro normal's
    /// side; the v-groove G has no separate G1 and reports Smith's).
    pub g1: Arc<dyn Fn(DVec3) -> f64 + Send + Sync>,
    /// G2(wi, wo, h), the term the model multiplies by.
    pub g2: Arc<dyn Fn(DVec3, DVec3, DVec3) -> f64 + Send + Sync>,
}

impl std::fmt::Debug for MicrofacetTerms {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("MicrofacetTerms")
            .field("distribution", &self.distribution)
            .field("geometry", &self.geometry)
            .finish_non_exhaustive()
    }
}

/// A model's Fresnel term and a one-line description of where it comes from
/// (`fresnel = conductor`, "Schlick, F0 from specular, …").
#[derive(Debug, Clone, PartialEq)]
pub struct FresnelTerm {
    /// The term.
    pub fresnel: crate::fresnel::Fresnel,
    /// Where it comes from, in the model's words.
    pub source: String,
}

/// One importance sample of a BRDF: the drawn direction, its weight
/// `f(wi, wo) |cos θo| / pdf(wo)` per channel, and the density.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BrdfSample {
    /// The outgoing direction drawn by [`Brdf::sample`].
    pub wo: DVec3,
    /// `f |cos θo| / pdf`, the Monte Carlo weight of the sample (zero where
    /// the density is zero or not finite).
    pub weight: Rgb,
    /// [`Brdf::pdf`] at `wo`, per steradian.
    pub pdf: f64,
}

/// Draws one sample of `brdf` for light from `wi` with the uniform point
/// `u` (the estimator the albedo's Monte Carlo and renderers build on: the
/// weight of importance sampling, Veach 1997 eq. 2.7); `None` when the
/// model draws no direction. Delta lobes ([`Brdf::deltas`]) are not drawn:
/// `f` is zero at every finite pair of a pure delta model, and their weights
/// are the lobes' own.
pub fn sample_weighted(brdf: &dyn Brdf, wi: DVec3, u: DVec2) -> Option<BrdfSample> {
    let wo = brdf.sample(wi, u)?;
    if !wo.is_finite() {
        return None;
    }
    let pdf = brdf.pdf(wi, wo);
    let f = brdf.eval(wi, wo);
    let weight = if pdf > 0.0 && pdf.is_finite() && f.is_finite() {
        f * (wo.z.abs() / pdf)
    } else {
        Rgb::ZERO
    };
    Some(BrdfSample { wo, weight, pdf })
}
