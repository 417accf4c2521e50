//! Coated surface (the lecture's "Layered Surface"): a rough dielectric coat
//! over a Lambertian or a rough conductor base, with an absorbing layer
//! between them, evaluated with the single-internal-bounce layering of
//! Weidlich & Wilkie 2007, "Arbitrarily Layered Micro-Facet Surfaces"
//! (GRAPHITE), §4 (eqs. 4-7 of that paper: coat reflection plus the base seen
//! through the coat, weighted by the two Fresnel transmittances and the
//! absorption along the refracted path).
//!
//! With `η` the coat's index (relative to the medium above), `wi'`, `wo'`
//! the macro-surface refractions of `wi`, `wo` into the coat (Snell's law,
//! turned to point up, away from the base), `F` the exact dielectric Fresnel
//! reflectance of the macro interface, `σa` the absorption coefficient and
//! `d` the thickness:
//!
//! `f(wi, wo) = f_coat(wi, wo)
//!            + (1 − F(θi)) (1 − F(θo)) / η² · e^(−σa d (1/cos θi' + 1/cos θo')) · f_base(wi', wo')`
//!
//! - `f_coat`: the reflected lobe of the `rough-dielectric` model (Walter et
//!   al. 2007, eq. 20), separable Smith G;
//! - the `1/η²`: radiance gains `η²` entering the coat and loses it leaving,
//!   and the refracted solid angles obey `η² cos θ' dω' = cos θ dω` (Snell; Veach
//!   1997 §5.2), which leaves one `1/η²` when `f_base` is written in the
//!   coat's directions (Weidlich & Wilkie eq. 6 with that Jacobian);
//! - `f_base`: `albedo/π` (Lambert), or Walter's eq. 20 for a conductor of
//!   complex index `(base_eta + i base_k)/η` relative to the coat, roughness
//!   `base_alpha` and the coat's distribution, multiplied by the closed-form
//!   sum of the internal inter-reflections `m = 1/(1 − r̄ K)` per channel, the
//!   geometric series of the light the coat's underside sends back down:
//!   `K = ∫₀¹ F_int(μ) e^(−2σa d/μ) 2μ dμ` (the cosine-weighted internal
//!   Fresnel reflectance, total internal reflection included, with the
//!   absorption of the round trip) and `r̄` the Lambertian base's albedo
//!   (`m = 1` over a conductor: it sends the light back near the mirror
//!   direction, inside the escape cone, where little is trapped). This is the diffuse term of Mitsuba's `plastic` and
//!   `roughplastic` (Jakob 2010, after Weidlich & Wilkie 2007, with the
//!   internal diffuse reflectance `F_dr` of Jensen et al. 2001 §2.2), and
//!   it is exact for a smooth coat over a Lambertian base, absorption
//!   included: the base re-emits a cosine distribution whatever reaches it.
//!
//! Why this approximation rather than albedo scaling (Kulla & Conty 2017,
//! Jakob 2014): it is closed form (no albedo table to build per parameter
//! set, nothing to upload to the GPU port), it is the exact single-bounce
//! result of a smooth coat, and it is reciprocal term by term (every factor is
//! symmetric under `wi ↔ wo`). What it leaves out — light reflected back down
//! at the coat's underside and scattered by the base again, and the rough
//! coat's spreading of the transmitted light — is measured against a
//! position-free random walk through the two interfaces (Guo, Hašan & Zhao
//! 2018) in `tests/coated_random_walk.rs`, per angle of incidence.
//!
//! Reflection only (the base is opaque): `f = 0` when either direction is at
//! or below the horizon.

use crate::batch::{self, Dirs, Isa, Kernel, LaneKernel, LaneMask, Lanes, Out, math};
use crate::fresnel::{self, FresnelLanes};
use crate::microfacet::{self, Distribution, Microfacet, ScaleLanes};
use crate::model::{ALPHA_ALIAS, Build, GpuPort, GpuTables, ModelInfo};
use crate::models::rough_dielectric::{
    Geometry, ReflectionLanes, RoughDielectric, fresnel_t_lanes,
};
use crate::params::decl::{ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::{ModelSpec, Params};
use crate::{Brdf, BvError, Claims, FresnelTerm, Ndf, Result, Rgb, frame, quadrature, sampling};
use glam::{DVec2, DVec3};
use std::f64::consts::FRAC_1_PI;

/// Roughness range and slider span of the coat's `alpha_x`, `alpha_y`.
const ALPHA: FloatSpec = FloatSpec::log(0.001, 2.0, 0.1, 0.005, 1.0);

/// The distributions this model offers (coat and conductor base).
pub const DISTRIBUTIONS: &[&str] = &["ggx", "beckmann"];
/// The bases this model offers.
pub const BASES: &[&str] = &["lambert", "conductor"];

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "distribution",
        label: "D",
        doc: "Microfacet distribution of the coat (and of a conductor base): GGX or Beckmann",
        kind: ParamKind::Choice {
            options: DISTRIBUTIONS,
            default: "ggx",
        },
        applies: crate::params::decl::Applies::Always,
    },
    ParamDecl {
        id: "alpha_x",
        label: "α x",
        doc: "Coat roughness along the tangent",
        kind: ParamKind::Float(ALPHA),
        applies: crate::params::decl::Applies::Always,
    },
    ParamDecl {
        id: "alpha_y",
        label: "α y",
        doc: "Coat roughness along the bitangent",
        kind: ParamKind::Float(ALPHA),
        applies: crate::params::decl::Applies::Always,
    },
    ParamDecl {
        id: "eta",
        label: "η",
        doc: "Index of the coat relative to the medium above (a coat is denser: > 1)",
        kind: ParamKind::Float(FloatSpec::linear(1.01, 4.0, 1.5)),
        applies: crate::params::decl::Applies::Always,
    },
    ParamDecl {
        id: "thickness",
        label: "d",
        doc: "Thickness of the absorbing layer, in units of 1/absorption (optical depth d·σa)",
        kind: ParamKind::Float(FloatSpec::linear(0.0, 10.0, 0.5)),
        applies: crate::params::decl::Applies::Always,
    },
    ParamDecl {
        id: "absorption",
        label: "σa",
        doc: "Absorption coefficient of the layer per unit thickness, per channel (0: clear)",
        kind: ParamKind::Color(ColorSpec::unit_range([0.05, 0.3, 0.8])),
        applies: crate::params::decl::Applies::Always,
    },
    ParamDecl {
        id: "base",
        label: "base",
        doc: "What lies under the coat: a Lambertian diffuser or a rough conductor",
        kind: ParamKind::Choice {
            options: BASES,
            default: "lambert",
        },
        applies: crate::params::decl::Applies::Always,
    },
    ParamDecl {
        id: "base_albedo",
        label: "base ρ",
        doc: "Albedo of the Lambertian base",
        kind: ParamKind::Color(ColorSpec::unit_range([0.8, 0.8, 0.8])),
        applies: crate::params::decl::Applies::Always,
    }
    .applies_when("base", &["lambert"]),
    ParamDecl {
        id: "base_eta",
        label: "base η",
        doc: "Real part of the conductor's index (relative to vacuum; the model divides by the coat's η)",
        kind: ParamKind::Color(ColorSpec::range(0.01, 10.0, [0.2, 0.92, 1.1])),
        applies: crate::params::decl::Applies::Always,
    }
    .applies_when("base", &["conductor"]),
    ParamDecl {
        id: "base_k",
        label: "base k",
        doc: "Extinction coefficient of the conductor, per channel",
        kind: ParamKind::Color(ColorSpec::range(0.0, 20.0, [3.9, 2.45, 2.14])),
        applies: crate::params::decl::Applies::Always,
    }
    .applies_when("base", &["conductor"]),
    ParamDecl {
        id: "base_alpha",
        label: "base α",
        doc: "Roughness of the conductor base (isotropic)",
        kind: ParamKind::Float(FloatSpec::log(0.001, 2.0, 0.3, 0.005, 1.0)),
        applies: crate::params::decl::Applies::Always,
    }
    .applies_when("base", &["conductor"]),
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "coated",
    name: "Coated surface",
    summary: "A rough dielectric coat over a Lambertian or conductor base, with an absorbing layer",
    citation: "Weidlich & Wilkie 2007, §4 (single-bounce layering); Walter et al. 2007, eq. 20 (coat, conductor base)",
    params: PARAMS,
    aliases: &[ALPHA_ALIAS],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::coated",
            "shaders/models/coated.wgsl",
            include_str!("../../../../shaders/models/coated.wgsl"),
        )
        .with_derived(DERIVED_SLOTS, derive_slots)
        .with_sampling_lobe(),
    ),
};

/// The layer under the coat.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Base {
    /// Lambertian, `albedo/π`.
    Lambert {
        /// Directional-hemispherical reflectance.
        albedo: Rgb,
    },
    /// A rough conductor (Walter et al. 2007, eq. 20), its complex index
    /// given relative to vacuum.
    Conductor {
        /// Real part of the index.
        eta: Rgb,
        /// Extinction coefficient.
        k: Rgb,
        /// Isotropic roughness.
        alpha: f64,
    },
}

/// The coated surface.
#[derive(Debug, Clone)]
pub struct Coated {
    /// `1/(1 − r̄ K)` per channel (see the module documentation).
    ms: Rgb,
    coat: RoughDielectric,
    eta: f64,
    /// `σa · d` per channel: the optical depth at normal incidence.
    depth: Rgb,
    base: Base,
    /// The conductor base's distribution (unused for Lambert).
    base_ndf: Microfacet,
    kernel: Option<CoatedKernel>,
}

fn parse_dist(name: &str) -> Result<Distribution> {
    match name {
        "ggx" => Ok(Distribution::Ggx),
        "beckmann" => Ok(Distribution::Beckmann),
        other => Err(BvError::BadValue {
            param: "distribution".into(),
            reason: format!("`{other}` is not one of {}", DISTRIBUTIONS.join(", ")),
        }),
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(coated(p)?))
}

fn coated(p: &Params) -> Result<Coated> {
    let dist = parse_dist(p.text("distribution")?)?;
    let base = match p.text("base")? {
        "lambert" => Base::Lambert {
            albedo: p.color("base_albedo")?,
        },
        "conductor" => Base::Conductor {
            eta: p.color("base_eta")?,
            k: p.color("base_k")?,
            alpha: p.float("base_alpha")?,
        },
        other => {
            return Err(BvError::BadValue {
                param: "base".into(),
                reason: format!("`{other}` is not one of {}", BASES.join(", ")),
            });
        }
    };
    Coated::new(
        dist,
        p.float("alpha_x")?,
        p.float("alpha_y")?,
        p.float("eta")?,
        p.float("thickness")?,
        p.color("absorption")?,
        base,
    )
}

impl Coated {
    /// A coat of distribution `dist`, roughness (`ax`, `ay`) and index `eta`
    /// (> 1) over `base`, with a layer of thickness `thickness` and
    /// absorption coefficient `absorption` (both ≥ 0). Refuses `eta ≤ 1`,
    /// negative or non-finite thickness, absorption or base parameters.
    pub fn new(
        dist: Distribution,
        ax: f64,
        ay: f64,
        eta: f64,
        thickness: f64,
        absorption: Rgb,
        base: Base,
    ) -> Result<Self> {
        if !(eta.is_finite() && eta > 1.0) {
            return Err(BvError::BadValue {
                param: "eta".into(),
                reason: format!("a coat is denser than the medium above: eta > 1, got {eta}"),
            });
        }
        if !(thickness.is_finite() && thickness >= 0.0) {
            return Err(BvError::BadValue {
                param: "thickness".into(),
                reason: format!("must be finite and ≥ 0, got {thickness}"),
            });
        }
        if !(absorption.is_finite() && absorption.min_element() >= 0.0) {
            return Err(BvError::BadValue {
                param: "absorption".into(),
                reason: format!("must be finite and ≥ 0, got {absorption}"),
            });
        }
        let base_ndf = match base {
            Base::Lambert { albedo } => {
                if !(albedo.is_finite() && albedo.min_element() >= 0.0) {
                    return Err(BvError::BadValue {
                        param: "base_albedo".into(),
                        reason: format!("must be finite and ≥ 0, got {albedo}"),
                    });
                }
                Microfacet::new(dist, 1.0, 1.0)
            }
            Base::Conductor { eta: be, k, alpha } => {
                if !(be.is_finite() && be.min_element() > 0.0) {
                    return Err(BvError::BadValue {
                        param: "base_eta".into(),
                        reason: format!("must be positive and finite, got {be}"),
                    });
                }
                if !(k.is_finite() && k.min_element() >= 0.0) {
                    return Err(BvError::BadValue {
                        param: "base_k".into(),
                        reason: format!("must be finite and ≥ 0, got {k}"),
                    });
                }
                if !(alpha.is_finite() && alpha > 0.0) {
                    return Err(BvError::BadValue {
                        param: "base_alpha".into(),
                        reason: format!("must be positive and finite, got {alpha}"),
                    });
                }
                Microfacet::new(dist, alpha, alpha)
            }
        };
        let coat = RoughDielectric::new(dist, ax, ay, eta, Geometry::Smith, Rgb::ONE)?;
        let depth = absorption * thickness;
        let ms = internal_reflections(eta, depth, &base);
        if !ms.is_finite() {
            return Err(BvError::BadValue {
                param: "base".into(),
                reason: format!("the internal reflection series diverges ({ms})"),
            });
        }
        let kernel = CoatedKernel::new(&coat, eta, depth, ms, &base, &base_ndf);
        Ok(Self {
            ms,
            coat,
            eta,
            depth,
            base,
            base_ndf,
            kernel,
        })
    }

    /// `w` (above the surface) refracted into the coat through the macro
    /// normal, turned to point up: `(wx/η, wy/η, cos θ')`.
    fn inside(&self, w: DVec3) -> DVec3 {
        let s = 1.0 / self.eta;
        let z = (1.0 - s * s * (1.0 - w.z * w.z)).max(0.0).sqrt();
        DVec3::new(w.x * s, w.y * s, z)
    }

    /// `w'` inside the coat (pointing up) refracted out, or `None` under
    /// total internal reflection.
    fn outside(&self, w: DVec3) -> Option<DVec3> {
        // `refract` takes the direction pointing away from the surface on
        // the coat's side, −w.
        frame::refract(-w, self.eta)
    }

    /// The base's BRDF for the coat-side directions `wi'`, `wo'`.
    fn f_base(&self, wi: DVec3, wo: DVec3) -> Rgb {
        match self.base {
            Base::Lambert { albedo } => albedo * FRAC_1_PI,
            Base::Conductor { eta, k, .. } => {
                // Walter et al. 2007, eq. 20, separable Smith G.
                let Some(h) = frame::half_vector(wi, wo) else {
                    return Rgb::ZERO;
                };
                let c = wi.dot(h);
                if c <= 0.0 || wo.dot(h) <= 0.0 {
                    return Rgb::ZERO;
                }
                let g = self.base_ndf.g1(wi) * self.base_ndf.g1(wo);
                let s = self.base_ndf.d(h) * g / (4.0 * wi.z * wo.z);
                let fr = |e: f64, kk: f64| fresnel::conductor(c, e / self.eta, kk / self.eta);
                Rgb::new(fr(eta.x, k.x), fr(eta.y, k.y), fr(eta.z, k.z)) * s
            }
        }
    }

    /// The base seen through the coat (the second term of the module's
    /// formula), without the coat's own reflection.
    pub fn eval_through(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let (ti, to) = (self.inside(wi), self.inside(wo));
        if ti.z <= 0.0 || to.z <= 0.0 {
            return Rgb::ZERO;
        }
        let trans = (1.0 - fresnel::dielectric(wi.z, self.eta))
            * (1.0 - fresnel::dielectric(wo.z, self.eta))
            / (self.eta * self.eta);
        let path = 1.0 / ti.z + 1.0 / to.z;
        let absorb = Rgb::new(
            (-self.depth.x * path).exp(),
            (-self.depth.y * path).exp(),
            (-self.depth.z * path).exp(),
        );
        let v = self.f_base(ti, to) * absorb * self.ms * trans;
        if v.is_finite() {
            v.max(Rgb::ZERO)
        } else {
            Rgb::ZERO
        }
    }

    /// The coat's reflection alone (`rough-dielectric`'s eq. 20).
    pub fn eval_coat(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        self.coat.eval_scalar(wi, wo)
    }

    /// Probability of sampling the coat's reflection for light from `wi`:
    /// its Fresnel reflectance, kept inside [0.2, 0.8].
    fn p_coat(&self, wi: DVec3) -> f64 {
        fresnel::dielectric(wi.z, self.eta).clamp(0.2, 0.8)
    }

    /// The coat's index.
    pub fn eta(&self) -> f64 {
        self.eta
    }

    /// The inter-reflection factor `1/(1 − r̄ K)` per channel.
    pub fn internal_reflection_factor(&self) -> Rgb {
        self.ms
    }
}

/// `∫ₐᵇ g(μ) dμ` by 16-point Gauss-Legendre on 8 panels.
fn gl(g: impl Fn(f64) -> f64, a: f64, b: f64) -> f64 {
    thread_local! {
        static NODES: Vec<(f64, f64)> = quadrature::gauss_legendre(16);
    }
    NODES.with(|n| quadrature::integrate(g, a, b, 8, n))
}

/// `1/(1 − r̄ K)` per channel, with `K = ∫₀¹ F_int(μ) e^(−2τ/μ) 2μ dμ`
/// (split at the critical cosine `μc = √(1 − 1/η²)`, below which
/// `F_int = 1`) and `r̄` the base's hemispherical albedo (module docs).
fn internal_reflections(eta: f64, depth: Rgb, base: &Base) -> Rgb {
    let mu_c = (1.0 - 1.0 / (eta * eta)).max(0.0).sqrt();
    let k = |tau: f64| {
        let att = |mu: f64| {
            if mu > 0.0 {
                (-2.0 * tau / mu).exp()
            } else {
                0.0
            }
        };
        // Above μc, μ = μc + (1 − μc) s²: F_int has a square-root cusp at
        // μc, smooth in s.
        let span = 1.0 - mu_c;
        gl(|mu| att(mu) * 2.0 * mu, 0.0, mu_c)
            + gl(
                |t| {
                    let mu = mu_c + span * t * t;
                    fresnel::dielectric(-mu, eta) * att(mu) * 2.0 * mu * 2.0 * span * t
                },
                0.0,
                1.0,
            )
    };
    let rbar = match *base {
        Base::Lambert { albedo } => albedo,
        // A conductor base reflects near the mirror direction, back inside
        // the escape cone where F_int is small: the diffuse series would
        // count light that it does not trap (against the random walk it
        // overestimated copper's ρhd by up to 0.7), so none is added.
        Base::Conductor { .. } => return Rgb::ONE,
    };
    Rgb::new(
        1.0 / (1.0 - rbar.x * k(depth.x)),
        1.0 / (1.0 - rbar.y * k(depth.y)),
        1.0 / (1.0 - rbar.z * k(depth.z)),
    )
}

/// Derived GPU slots (read by `shaders/models/coated.wgsl`): the
/// inter-reflection factor per channel (two quadratures, done once here).
const DERIVED_SLOTS: &[&str] = &["ms_r", "ms_g", "ms_b"];

fn derive_slots(spec: &ModelSpec, _tables: &mut dyn GpuTables) -> Result<Vec<f32>> {
    let c = coated(spec.params())?;
    Ok(c.ms.to_array().iter().map(|&v| v as f32).collect())
}

impl Brdf for Coated {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 || !(wi.is_finite() && wo.is_finite()) {
            return Rgb::ZERO;
        }
        Rgb::splat(self.eval_coat(wi, wo)) + self.eval_through(wi, wo)
    }

    fn eval_with_half(&self, wi: DVec3, wo: DVec3, h: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 || !(wi.is_finite() && wo.is_finite()) {
            return Rgb::ZERO;
        }
        // The coat's reflection from the facet `h` (its eq. 20 in
        // `rough-dielectric`), the base as in `eval`.
        Rgb::splat(self.coat.reflection_at(wi, wo, h)) + self.eval_through(wi, wo)
    }

    fn claims(&self) -> Claims {
        Claims {
            // Every factor is symmetric under wi ↔ wo: eq. 20 of the coat,
            // the product of the two transmittances, the path length, and
            // the base's own BRDF of (wi', wo').
            reciprocal: true,
            // For a smooth coat over a Lambertian base the model is the
            // exact sum of every internal bounce, which conserves energy;
            // over a conductor the base term integrates, by
            // η² cos θ' dω' = cos θ dω, to at most (1 − F(θi)) times the
            // base's albedo. A rough coat reflects F(θi) plus what its
            // tilted facets add, less what masking removes; the unit tests
            // and the catalogue's property test check ρhd ≤ 1 numerically
            // over the parameter ranges.
            energy_conserving: match self.base {
                Base::Lambert { albedo } => albedo.max_element() <= 1.0,
                Base::Conductor { .. } => true,
            },
            isotropic: self.coat.microfacet().is_isotropic(),
        }
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z <= 0.0 || !wi.is_finite() {
            return None;
        }
        let pc = self.p_coat(wi);
        if u.x < pc {
            let ux = (u.x / pc).min(microfacet::ONE_MINUS_EPS);
            return microfacet::sample_reflection(self.coat.microfacet(), wi, DVec2::new(ux, u.y));
        }
        let ux = ((u.x - pc) / (1.0 - pc)).min(microfacet::ONE_MINUS_EPS);
        let u = DVec2::new(ux, u.y);
        match self.base {
            Base::Lambert { .. } => {
                let wo = sampling::cosine_hemisphere(u);
                (wo.z > 0.0).then_some(wo)
            }
            Base::Conductor { .. } => {
                // The base's visible normals for wi', reflected, refracted out.
                let ti = self.inside(wi);
                let to = microfacet::sample_reflection(&self.base_ndf, ti, u)?;
                let wo = self.outside(to)?;
                (wo.z > 0.0 && wo.is_finite()).then_some(wo)
            }
        }
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let pc = self.p_coat(wi);
        let coat = microfacet::sample_reflection_pdf(self.coat.microfacet(), wi, wo);
        let base = match self.base {
            Base::Lambert { .. } => sampling::cosine_hemisphere_pdf(wo),
            Base::Conductor { .. } => {
                let (ti, to) = (self.inside(wi), self.inside(wo));
                // dω'/dω = cos θ / (η² cos θ') (Snell).
                microfacet::sample_reflection_pdf(&self.base_ndf, ti, to) * wo.z
                    / (self.eta * self.eta * to.z)
            }
        };
        let p = pc * coat + (1.0 - pc) * base;
        if p.is_finite() { p.max(0.0) } else { 0.0 }
    }

    fn ndf(&self) -> Option<&dyn Ndf> {
        Some(self.coat.microfacet())
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        self.kernel.as_ref().map(|k| k as &dyn Kernel)
    }

    /// The coat's interface alone, untinted (the rough dielectric's
    /// furnace): with no base to return light, what it reflects and
    /// transmits in one scattering, `ρR + ρT`, is what a single-scattering
    /// interface keeps; the rest is the energy the coat's microfacet model
    /// loses before the base is even reached.
    fn furnace(&self) -> Option<Box<dyn Brdf>> {
        self.coat.furnace()
    }

    fn fresnel_term(&self) -> Option<FresnelTerm> {
        Some(FresnelTerm {
            fresnel: fresnel::Fresnel::Dielectric {
                eta: Rgb::splat(self.eta),
            },
            source: "exact dielectric (the coat)".into(),
        })
    }
}

// ---------------------------------------------------------------------------
// Batch kernel.

/// The base in f32 lanes.
#[derive(Debug, Clone, Copy)]
enum BaseLanes {
    /// `albedo/π` per channel.
    Lambert([f32; 3]),
    /// Walter's eq. 20 with the coat's distribution at the base's roughness
    /// and the conductor's Fresnel relative to the coat (`(η + ik)/η_coat`).
    Conductor(ScaleLanes, FresnelLanes),
}

/// [`Coated::eval`] in f32 lanes: the coat's reflection from the
/// `rough-dielectric` kernel's own lane code, plus the base seen through the
/// coat, term by term as in [`Coated::eval_through`].
#[derive(Debug, Clone, Copy)]
struct CoatedKernel {
    coat: ReflectionLanes,
    /// 1/η and 1/η².
    inv_eta: f32,
    inv_eta2: f32,
    /// η².
    eta2: f32,
    /// `σa d` per channel.
    depth: [f32; 3],
    /// The inter-reflection factor over η² per channel (`ms/η²`).
    gain: [f32; 3],
    base: BaseLanes,
}

impl CoatedKernel {
    fn new(
        coat: &RoughDielectric,
        eta: f64,
        depth: Rgb,
        ms: Rgb,
        base: &Base,
        base_ndf: &Microfacet,
    ) -> Option<Self> {
        let coat = ReflectionLanes::of(coat)?;
        let base = match *base {
            Base::Lambert { albedo } => BaseLanes::Lambert(math::rgb(albedo * FRAC_1_PI)),
            Base::Conductor { eta: be, k, .. } => {
                let (tag, scale) = ScaleLanes::new(&base_ndf.first)?;
                // The base shares the coat's distribution, so one const tag
                // serves both lane calls.
                if tag != coat.dist() {
                    return None;
                }
                let f = fresnel::Fresnel::Conductor {
                    eta: be / eta,
                    k: k / eta,
                };
                BaseLanes::Conductor(scale, FresnelLanes::new(&f))
            }
        };
        Some(Self {
            coat,
            inv_eta: (1.0 / eta) as f32,
            inv_eta2: (1.0 / (eta * eta)) as f32,
            eta2: (eta * eta) as f32,
            depth: math::rgb(depth),
            gain: math::rgb(ms / (eta * eta)),
            base,
        })
    }
}

/// Fresnel transmittance `1 − F` of the coat's macro interface for light
/// from above at `c = cos θ` (> 0): rough-dielectric's lane form with
/// `g = η cos θt = √(η² − 1 + c²)`.
#[inline(always)]
fn transmittance<V: Lanes>(c: V, eta2: f32) -> V {
    let g = (c * c + (eta2 - 1.0)).sqrt();
    fresnel_t_lanes(c, g, V::splat(eta2))
}

/// What a direction `w` above the coat contributes to the base's light
/// (`Coated::inside` and the macro interface's transmittance): a function of
/// `w` alone, so that a lobe, whose pairs share one `wi`, computes `wi`'s
/// once ([`CoatedAtWi`]) rather than in every lane.
#[derive(Debug, Clone, Copy)]
struct Crossing<V> {
    /// `cos θ` of the refracted direction inside the coat.
    t_z: V,
    /// `1/t_z`: the path through the layer per unit depth.
    inv_t_z: V,
    /// `1 − F` of the macro interface at `w`.
    trans: V,
    /// For a conductor base, `1 + Λ` of the refracted direction (its
    /// masking); 0 for a Lambert base.
    opl: V,
}

/// One monomorphised combination of distribution and base
/// (`CONDUCTOR = false`: Lambert).
#[derive(Debug, Clone, Copy)]
struct CoatedLane<'a, const D: u8, const CONDUCTOR: bool>(&'a CoatedKernel);

impl<'a, const D: u8, const CONDUCTOR: bool> CoatedLane<'a, D, CONDUCTOR> {
    /// `w`'s [`Crossing`]. The refracted direction's `sin²θ` is `x² + y²`
    /// over η², which does not cancel near normal incidence.
    #[inline(always)]
    fn crossing<V: Lanes>(&self, w: [V; 3]) -> Crossing<V> {
        let k = self.0;
        let (zero, one) = (V::splat(0.0), V::splat(1.0));
        let sin2 = w[0] * w[0] + w[1] * w[1];
        let t_z = (one - sin2 * V::splat(k.inv_eta2)).max(zero).sqrt();
        let opl = match k.base {
            BaseLanes::Conductor(scale, _) if CONDUCTOR => {
                let s = V::splat(k.inv_eta);
                scale.one_plus_lambda::<D, V>([w[0] * s, w[1] * s, t_z])
            }
            _ => zero,
        };
        Crossing {
            t_z,
            inv_t_z: one / t_z,
            trans: transmittance(w[2], k.eta2),
            opl,
        }
    }

    /// `f(wi, wo)` per channel, given both directions' crossings.
    #[inline(always)]
    fn eval<V: Lanes>(&self, wi: [V; 3], wo: [V; 3], ci: Crossing<V>, co: Crossing<V>) -> [V; 3] {
        let k = self.0;
        let (zero, one) = (V::splat(0.0), V::splat(1.0));
        let above = wi[2].gt(zero) & wo[2].gt(zero);
        let coat = k.coat.lane::<D, V>(wi, wo);
        let trans = ci.trans * co.trans;
        let path = ci.inv_t_z + co.inv_t_z;
        let base: [V; 3] = if CONDUCTOR {
            let BaseLanes::Conductor(scale, fres) = k.base else {
                return [zero; 3];
            };
            let s = V::splat(k.inv_eta);
            let ti = [wi[0] * s, wi[1] * s, ci.t_z];
            // The tangential half vector as (wi + wo)/η, summed before it
            // is scaled: near the mirror pair the sum cancels (exactly, in
            // f32), and two rounded products would leave an error that a
            // base as sharp as α = 0.001 turns into 1e-4 of D.
            let hu = [(wi[0] + wo[0]) * s, (wi[1] + wo[1]) * s, ci.t_z + co.t_z];
            let h = math::scale3(hu, one / math::dot(hu, hu).sqrt());
            let c = math::dot(ti, h);
            let d = scale.d::<D, V>(h);
            let g = one / (ci.opl * co.opl);
            let lobe = d * g / (ci.t_z * co.t_z * 4.0);
            let f = fres.eval::<{ FresnelLanes::CONDUCTOR }, V>(c);
            let ok = c.gt(zero);
            math::channels!(|ch| ok.select(f[ch] * lobe, zero))
        } else {
            let BaseLanes::Lambert(a) = k.base else {
                return [zero; 3];
            };
            math::splat3(a)
        };
        math::channels!(|ch| {
            let through = base[ch] * math::exp(-path * k.depth[ch]) * trans * k.gain[ch];
            let v = coat + through;
            (above & v.is_finite()).select(v.max(zero), zero)
        })
    }

    /// This combination for pairs that share `wi` ([`Kernel::at_wi`]).
    fn at_wi(self, wi: [f32; 3]) -> Box<dyn Kernel + 'a> {
        Box::new(CoatedAtWi {
            lane: self,
            wi,
            ci: self.crossing::<f32>(wi),
        })
    }
}

impl<const D: u8, const CONDUCTOR: bool> LaneKernel for CoatedLane<'_, D, CONDUCTOR> {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        self.eval(wi, wo, self.crossing(wi), self.crossing(wo))
    }
}

/// [`CoatedLane`] for pairs that all share the incident direction `wi`,
/// with `wi`'s [`Crossing`] (two square roots, three divisions and, over a
/// conductor, its masking) computed once in f32 by the same code.
#[derive(Debug)]
struct CoatedAtWi<'a, const D: u8, const CONDUCTOR: bool> {
    lane: CoatedLane<'a, D, CONDUCTOR>,
    wi: [f32; 3],
    ci: Crossing<f32>,
}

impl<const D: u8, const CONDUCTOR: bool> LaneKernel for CoatedAtWi<'_, D, CONDUCTOR> {
    #[inline(always)]
    fn lane<V: Lanes>(&self, _wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let c = self.ci;
        let ci = Crossing {
            t_z: V::splat(c.t_z),
            inv_t_z: V::splat(c.inv_t_z),
            trans: V::splat(c.trans),
            opl: V::splat(c.opl),
        };
        let co = self.lane.crossing(wo);
        self.lane.eval(math::splat3(self.wi), wo, ci, co)
    }
}

/// Evaluates `$body` with `$lane` bound to the [`CoatedLane`] of `$k`'s
/// distribution and base, the one monomorphised combination that serves it
/// (shared by [`Kernel::eval`] and [`Kernel::at_wi`]).
macro_rules! with_lane {
    ($k:expr, |$lane:ident| $body:expr) => {{
        let k: &CoatedKernel = $k;
        let conductor = matches!(k.base, BaseLanes::Conductor(..));
        match (k.coat.dist(), conductor) {
            (ScaleLanes::BECKMANN, false) => {
                let $lane = CoatedLane::<{ ScaleLanes::BECKMANN }, false>(k);
                $body
            }
            (ScaleLanes::BECKMANN, true) => {
                let $lane = CoatedLane::<{ ScaleLanes::BECKMANN }, true>(k);
                $body
            }
            (_, false) => {
                let $lane = CoatedLane::<{ ScaleLanes::GGX }, false>(k);
                $body
            }
            (_, true) => {
                let $lane = CoatedLane::<{ ScaleLanes::GGX }, true>(k);
                $body
            }
        }
    }};
}

impl Kernel for CoatedKernel {
    fn eval(&self, isa: Isa, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        with_lane!(self, |lane| batch::run(&lane, isa, dirs, out))
    }

    fn at_wi(&self, wi: [f32; 3]) -> Option<Box<dyn Kernel + '_>> {
        Some(with_lane!(self, |lane| lane.at_wi(wi)))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use serde_json::{Value, json};

    fn model(p: Value) -> Box<dyn Brdf> {
        ModelSpec::from_json("coated", &p).unwrap().build().unwrap()
    }

    #[test]
    fn refuses_bad_parameters_without_panicking() {
        for p in [
            json!({"eta": 1.0}),
            json!({"thickness": -1.0}),
            json!({"base": "wood"}),
            json!({"base": "conductor", "base_alpha": 0.0}),
        ] {
            let r = ModelSpec::from_json("coated", &p).and_then(|s| s.build());
            assert!(r.is_err(), "{p} accepted");
        }
    }

    #[test]
    fn thick_absorbing_layer_leaves_the_coat_alone() {
        let b = model(json!({"thickness": 10.0, "absorption": 1.0, "alpha": 0.3}));
        let rd = ModelSpec::from_json("rough-dielectric", &json!({"alpha": 0.3}))
            .unwrap()
            .build()
            .unwrap();
        let (wi, wo) = (
            DVec3::new(0.3, 0.1, 0.9).normalize(),
            DVec3::new(-0.5, 0.2, 0.7).normalize(),
        );
        let (f, want) = (b.eval(wi, wo), rd.eval(wi, wo).x);
        assert!((f.x - want).abs() < 1e-8 * want.max(1e-3), "{f} vs {want}");
    }

    #[test]
    fn smooth_limit_normal_incidence_hand_value() {
        // Lambert base, no absorption, wi = wo = n away from the coat's
        // specular peak (α tiny, Beckmann: no tail there):
        // (1 − F(0°)) (1 − F(θo)) ρ/(π η²).
        let b = model(json!({"alpha": 0.001, "distribution": "beckmann",
            "thickness": 0.0, "base_albedo": 0.5}));
        let wo = DVec3::new(0.6, 0.0, 0.8);
        let eta: f64 = 1.5;
        let fi = fresnel::dielectric(1.0, eta);
        let fo = fresnel::dielectric(0.8, eta);
        // F̄_int by the midpoint rule (TIR included), m = 1/(1 − ρ F̄_int).
        let n = 200_000;
        let fbar: f64 = (0..n)
            .map(|j| {
                let mu = (j as f64 + 0.5) / n as f64;
                fresnel::dielectric(-mu, eta) * 2.0 * mu / n as f64
            })
            .sum();
        let want = (1.0 - fi) * (1.0 - fo) * 0.5 * FRAC_1_PI / (eta * eta) / (1.0 - 0.5 * fbar);
        let got = b.eval(DVec3::Z, wo).x;
        assert!((got / want - 1.0).abs() < 1e-7, "{got} vs {want}");
    }

    #[test]
    fn reciprocal_and_below_horizon_zero() {
        for base in ["lambert", "conductor"] {
            let b = model(json!({"base": base, "alpha_x": 0.2, "alpha_y": 0.4, "thickness": 1.0}));
            let wi = DVec3::new(0.3, -0.4, 0.5).normalize();
            let wo = DVec3::new(-0.2, 0.6, 0.4).normalize();
            let (a, r) = (b.eval(wi, wo), b.eval(wo, wi));
            assert!(
                (a - r).abs().max_element() <= 1e-12 * a.max_element(),
                "{a} {r}"
            );
            assert_eq!(b.eval(wi, -wo), Rgb::ZERO);
            assert_eq!(b.eval(-wi, wo), Rgb::ZERO);
        }
    }

    #[test]
    fn albedo_stays_below_one() {
        for p in [
            json!({"base": "lambert", "alpha": 0.3, "base_albedo": 1.0, "thickness": 0.0}),
            json!({"base": "conductor", "alpha": 0.05, "base_alpha": 0.2, "eta": 2.0}),
            json!({"base": "lambert", "alpha": 2.0, "eta": 4.0, "base_albedo": 1.0, "thickness": 0.0}),
            json!({"base": "conductor", "alpha": 1.0, "base_alpha": 0.01, "eta": 1.01,
                   "base_eta": 0.01, "base_k": 20.0, "thickness": 0.0}),
        ] {
            let b = model(p.clone());
            for theta in [0.05f64, 0.8, 1.26, 1.49] {
                let opts = crate::analysis::albedo::AlbedoOptions::default();
                let rho = crate::analysis::albedo::rho_hd_auto(b.as_ref(), theta, 0.3, &opts);
                let m = rho.value.max_element();
                assert!(m <= 1.0, "{p} at θ {theta}: ρ {m}");
            }
        }
    }
}
