//! Rough dielectric interface: microfacet reflection and refraction of
//! Walter, Marschner, Li & Torrance 2007, "Microfacet Models for Refraction
//! through Rough Surfaces" (EGSR), eqs. 20 (reflection) and 21
//! (transmission), with the exact unpolarised dielectric Fresnel term, a GGX
//! or Beckmann distribution and a Smith masking-shadowing term.
//!
//! Conventions (SPEC §1): `wi` towards the light, `wo` towards the viewer,
//! either of them on either side of the surface; `eta` is the index of the
//! medium below (−z) over the one above (+z). `f` is the radiance-carrying
//! BSDF of eq. 21 with `i` the light's side and `o` the viewer's, so across
//! the interface `f(wi, wo)/ηo² = f(wo, wi)/ηi²` (Veach 1997, §5.2) and its
//! α → 0 limit is the `glass` model's ideal refraction, radiance scaled by
//! `(ηo/ηi)² (1 − F)`.
//!
//! With the macro normal `n = +z` and `ηi`, `ηo` the indices on the sides of
//! `wi` and `wo`:
//! - reflection (same side): `h = sign(wi·n) normalize(wi + wo)` (eq. 13),
//!   `f = F(wi·h) D(h) G / (4 |wi·n| |wo·n|)` (eq. 20);
//! - transmission (opposite sides): `h = ±normalize(ηi wi + ηo wo)` with
//!   `h·n > 0` (eq. 16),
//!   `f = |wi·h| |wo·h| ηo² (1 − F(wi·h)) D(h) G / (|wi·n| |wo·n| (ηi wi·h + ηo wo·h)²)`
//!   (eq. 21);
//! - both require the microfacet to face each direction from its own side,
//!   `χ⁺((v·h)/(v·n))` for `v = wi, wo` (eqs. 20-21's G and Heitz 2014 eq. 98).
//!
//! G is Smith's: separable `G1(wi) G1(wo)` (Walter eq. 23), or height
//! correlated, `1/(1 + Λ(wi) + Λ(wo))` for reflection and, for transmission,
//! where the light and the viewer sit on opposite sides of the same heights,
//! `B(1 + Λ(wi), 1 + Λ(wo))` with B Euler's Beta function (Heitz 2014,
//! "Understanding the Masking-Shadowing Function", §6: with
//! `G1(v, height) = C(height)^Λ(v)` seen from above and `(1 − C)^Λ` from
//! below, `∫₀¹ C^a (1 − C)^b dC = B(1 + a, 1 + b)`). Λ of a direction below
//! the surface is Λ of its mirror image above (the microsurface seen from
//! below).
//!
//! Light exactly at the horizon (`wi·n = 0` or `wo·n = 0`) gives `f = 0`
//! (Smith's G1 vanishes there) and no sample. The roughness range
//! (0.001..2) refuses α = 0: the smooth limit is the `glass` model. `eta = 1`
//! is refused (no interface: nothing reflects and the transmitted lobe would
//! be a Dirac δ at `−wi` for every α).

use crate::batch::{self, Dirs, Isa, Kernel, LaneKernel, LaneMask, Lanes, Out, math};
use crate::fresnel::{self, Fresnel};
use crate::microfacet::{Distribution, Microfacet, ScaleLanes};
use crate::model::{ALPHA_ALIAS, Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{
    Brdf, BvError, Claims, FresnelTerm, MicrofacetTerms, Ndf, Result, Rgb, frame, microfacet,
};
use glam::{DVec2, DVec3};
use std::sync::Arc;

/// Roughness range and slider span of `alpha_x`, `alpha_y`.
const ALPHA: FloatSpec = FloatSpec::log(0.001, 2.0, 0.1, 0.005, 1.0);

/// The distributions this model offers.
pub const DISTRIBUTIONS: &[&str] = &["ggx", "beckmann"];
/// The masking-shadowing terms this model offers.
pub const GEOMETRIES: &[&str] = &["smith", "smith-correlated"];

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "distribution",
        label: "D",
        doc: "Microfacet distribution: GGX (Trowbridge-Reitz) or Beckmann",
        kind: ParamKind::Choice {
            options: DISTRIBUTIONS,
            default: "ggx",
        },
        applies: Applies::Always,
    },
    ParamDecl {
        id: "alpha_x",
        label: "α x",
        doc: "Roughness along the tangent (α → 0 is the smooth `glass` interface)",
        kind: ParamKind::Float(ALPHA),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "alpha_y",
        label: "α y",
        doc: "Roughness along the bitangent",
        kind: ParamKind::Float(ALPHA),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "eta",
        label: "η",
        doc: "Relative index ηt/ηi of the medium below the surface (−z) to the one above; ≠ 1",
        kind: ParamKind::Float(FloatSpec::log(0.01, 10.0, 1.5, 0.25, 4.0)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "geometry",
        label: "G",
        doc: "Masking-shadowing: separable Smith, or height-correlated Smith",
        kind: ParamKind::Choice {
            options: GEOMETRIES,
            default: "smith",
        },
        applies: Applies::Always,
    },
    ParamDecl {
        id: "tint",
        label: "tint",
        doc: "Specular tint: multiplies the reflected and the transmitted lobe (white: none)",
        kind: ParamKind::Color(ColorSpec::unit_range([1.0, 1.0, 1.0])),
        applies: Applies::Always,
    },
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "rough-dielectric",
    name: "Rough dielectric",
    summary: "Microfacet reflection and refraction through a rough interface between two dielectrics",
    citation: "Walter, Marschner, Li & Torrance 2007, eqs. 20-21; Heitz 2014 (masking); Heitz 2018 (visible normals)",
    params: PARAMS,
    aliases: &[ALPHA_ALIAS],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::rough_dielectric",
            "shaders/models/rough_dielectric.wgsl",
            include_str!("../../../../shaders/models/rough_dielectric.wgsl"),
        )
        .with_sampling_lobe()
        .with_sphere_sampling(),
    ),
};

/// Which Smith term.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Geometry {
    /// `G1(wi) G1(wo)`.
    Smith,
    /// Height-correlated: `1/(1 + Λi + Λo)` in reflection, `B(1 + Λi, 1 + Λo)`
    /// in transmission.
    SmithCorrelated,
}

/// The rough dielectric interface.
#[derive(Debug, Clone)]
pub struct RoughDielectric {
    ndf: Microfacet,
    eta: f64,
    geometry: Geometry,
    tint: Rgb,
    kernel: Option<RdKernel>,
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    let dist = match p.text("distribution")? {
        "ggx" => Distribution::Ggx,
        "beckmann" => Distribution::Beckmann,
        other => {
            return Err(BvError::BadValue {
                param: "distribution".into(),
                reason: format!("`{other}` is not one of {}", DISTRIBUTIONS.join(", ")),
            });
        }
    };
    let geometry = match p.text("geometry")? {
        "smith" => Geometry::Smith,
        "smith-correlated" => Geometry::SmithCorrelated,
        other => {
            return Err(BvError::BadValue {
                param: "geometry".into(),
                reason: format!("`{other}` is not one of {}", GEOMETRIES.join(", ")),
            });
        }
    };
    Ok(Box::new(RoughDielectric::new(
        dist,
        p.float("alpha_x")?,
        p.float("alpha_y")?,
        p.float("eta")?,
        geometry,
        p.color("tint")?,
    )?))
}

/// `B(x, y) = Γ(x) Γ(y) / Γ(x + y)` for `x, y ≥ 1`, through `ln Γ`
/// (0 when either argument is infinite: Λ at the horizon).
pub fn beta(x: f64, y: f64) -> f64 {
    beta_with(x, libm::lgamma(x), y)
}

/// [`beta`] with `ln Γ(x)` given (the same for every pair that shares ωi).
fn beta_with(x: f64, lgamma_x: f64, y: f64) -> f64 {
    if !(x.is_finite() && y.is_finite()) {
        return 0.0;
    }
    (lgamma_x + libm::lgamma(y) - libm::lgamma(x + y)).exp()
}

/// The microfacet that joins a pair ([`RoughDielectric::facet`]).
struct Facet {
    /// Its normal, towards +z.
    h: DVec3,
    /// Whether the pair lies on opposite sides.
    transmits: bool,
    /// `wi·h`.
    ci: f64,
    /// `wo·h`.
    co: f64,
}

/// What `f(wi, ·)` needs of the incident direction alone: `wi`, its
/// Smith Λ and, for the height-correlated term, `ln Γ(1 + Λ)` (many pairs
/// share one `wi` in the albedo quadrature's panels).
struct Incident {
    wi: DVec3,
    lambda: f64,
    /// `ln Γ(1 + Λ)`, once a transmitted pair with the height-correlated
    /// term has needed it (no other pair does, and it costs more than the
    /// rest of `wi`'s work).
    lgamma: std::cell::OnceCell<f64>,
}

impl RoughDielectric {
    /// What `f(wi, ·)` needs of `wi` alone.
    fn incident(&self, wi: DVec3) -> Incident {
        Incident {
            wi,
            lambda: self.lambda(wi),
            lgamma: std::cell::OnceCell::new(),
        }
    }

    /// [`Brdf::eval_with_half`] at `(inc.wi, wo)` with half vector `h`.
    fn eval_with_half_from(&self, inc: &Incident, wo: DVec3, h: DVec3) -> Rgb {
        if inc.wi.z > 0.0 && wo.z > 0.0 {
            self.tint * self.reflection_from(inc, wo, h)
        } else {
            self.tint * self.eval_from(inc, wo)
        }
    }

    /// An interface with distribution `dist` of roughness (`ax`, `ay`),
    /// relative index `eta` (below over above), Smith term `geometry` and
    /// specular `tint`. Refuses `eta = 1` (no interface), non-positive or
    /// non-finite `eta`, and roughness that is not positive and finite.
    pub fn new(
        dist: Distribution,
        ax: f64,
        ay: f64,
        eta: f64,
        geometry: Geometry,
        tint: Rgb,
    ) -> Result<Self> {
        if !(eta.is_finite() && eta > 0.0) {
            return Err(BvError::BadValue {
                param: "eta".into(),
                reason: format!("the relative index must be positive and finite, got {eta}"),
            });
        }
        if eta == 1.0 {
            return Err(BvError::BadValue {
                param: "eta".into(),
                reason: "eta = 1 means the same medium on both sides: there is no interface to \
                         reflect or refract (choose eta ≠ 1; the light passes straight through)"
                    .into(),
            });
        }
        for (name, a) in [("alpha_x", ax), ("alpha_y", ay)] {
            if !(a.is_finite() && a > 0.0) {
                return Err(BvError::BadValue {
                    param: name.into(),
                    reason: format!(
                        "roughness must be positive and finite, got {a} (α → 0 is the `glass` model)"
                    ),
                });
            }
        }
        if dist == Distribution::Blinn {
            return Err(BvError::BadValue {
                param: "distribution".into(),
                reason: format!("`blinn` is not one of {}", DISTRIBUTIONS.join(", ")),
            });
        }
        let ndf = Microfacet::new(dist, ax, ay);
        let kernel = RdKernel::new(&ndf, eta, geometry, tint);
        Ok(Self {
            ndf,
            eta,
            geometry,
            tint,
            kernel,
        })
    }

    /// Index of the medium on `w`'s side (1 above, `eta` below).
    fn eta_of(&self, w: DVec3) -> f64 {
        if w.z > 0.0 { 1.0 } else { self.eta }
    }

    /// Smith's Λ of a direction on either side: the microsurface seen from
    /// below is the mirror image of the one seen from above.
    fn lambda(&self, w: DVec3) -> f64 {
        self.ndf.lambda(DVec3::new(w.x, w.y, w.z.abs()))
    }

    /// The masking-shadowing term for the pair (`transmits`: opposite sides).
    fn g(&self, wi: DVec3, wo: DVec3, transmits: bool) -> f64 {
        self.g_from(&self.incident(wi), wo, transmits)
    }

    /// [`RoughDielectric::g`] with `wi`'s Λ taken from `inc`.
    fn g_from(&self, inc: &Incident, wo: DVec3, transmits: bool) -> f64 {
        let li = inc.lambda;
        let lo = self.lambda(wo);
        match (self.geometry, transmits) {
            (Geometry::Smith, _) => 1.0 / ((1.0 + li) * (1.0 + lo)),
            (Geometry::SmithCorrelated, false) => 1.0 / (1.0 + li + lo),
            (Geometry::SmithCorrelated, true) => {
                let lgamma_i = *inc.lgamma.get_or_init(|| libm::lgamma(1.0 + li));
                beta_with(1.0 + li, lgamma_i, 1.0 + lo)
            }
        }
    }

    /// The microfacet normal that scatters `wi` into `wo` (pointing to +z),
    /// whether the pair is a transmission, and the cosines `wi·h`, `wo·h`;
    /// `None` when no facet does (a direction at the horizon, a facet seen
    /// from its back side).
    fn facet(&self, wi: DVec3, wo: DVec3) -> Option<Facet> {
        let (zi, zo) = (wi.z, wo.z);
        if zi == 0.0 || zo == 0.0 || !(zi.is_finite() && zo.is_finite()) {
            return None;
        }
        let transmits = (zi > 0.0) != (zo > 0.0);
        // Eq. 13 (reflection) and eq. 16 (transmission), up to sign.
        let hu = if transmits {
            self.eta_of(wi) * wi + self.eta_of(wo) * wo
        } else {
            wi + wo
        };
        let l2 = hu.length_squared();
        if !(l2 > 1e-300 && l2.is_finite()) {
            return None;
        }
        // One division, not three.
        let mut h = hu * (1.0 / l2.sqrt());
        if h.z < 0.0 {
            h = -h;
        }
        // χ⁺: each direction sees the facet from its own side.
        let (ci, co) = (wi.dot(h), wo.dot(h));
        if h.z <= 0.0 || ci * zi <= 0.0 || co * zo <= 0.0 {
            return None;
        }
        Some(Facet {
            h,
            transmits,
            ci,
            co,
        })
    }

    /// `f` without the tint (a scalar: the interface is grey).
    pub fn eval_scalar(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.eval_from(&self.incident(wi), wo)
    }

    /// [`RoughDielectric::eval_scalar`] at `(inc.wi, wo)`, with what
    /// depends on `wi` alone computed once per `inc` (the same values: the
    /// same function of the same `wi`).
    fn eval_from(&self, inc: &Incident, wo: DVec3) -> f64 {
        let wi = inc.wi;
        let Some(Facet {
            h,
            transmits,
            ci,
            co,
        }) = self.facet(wi, wo)
        else {
            return 0.0;
        };
        if !transmits {
            return self.reflection_from(inc, wo, h);
        }
        let d = self.ndf.d(h);
        if d == 0.0 {
            return 0.0;
        }
        let g = self.g_from(inc, wo, transmits);
        // Exact dielectric F for light arriving at the facet from wi's side
        // (a negative cosine: from inside, index 1/eta); 1 under TIR.
        let f = fresnel::dielectric(ci, self.eta);
        // Eq. 21.
        let (ei, eo) = (self.eta_of(wi), self.eta_of(wo));
        let den = ei * ci + eo * co;
        let v = (ci * co).abs() * eo * eo * (1.0 - f) * d * g / ((wi.z * wo.z).abs() * den * den);
        if v.is_finite() { v.max(0.0) } else { 0.0 }
    }

    /// The reflection (eq. 20, without the tint) of a pair on one side whose
    /// microfacet normal `h` (unit, towards +z: `±(wi + wo)/|wi + wo|`) the
    /// caller has: [`RoughDielectric::eval_scalar`]'s reflected branch, and
    /// [`Brdf::eval_with_half`]'s (the albedo quadrature's half vector) for
    /// this model and `coated`'s coat. 0 where a direction sees the facet
    /// from behind (χ⁺).
    pub(crate) fn reflection_at(&self, wi: DVec3, wo: DVec3, h: DVec3) -> f64 {
        self.reflection_from(&self.incident(wi), wo, h)
    }

    /// [`RoughDielectric::reflection_at`] at `(inc.wi, wo)`, as
    /// [`RoughDielectric::eval_from`] is to `eval_scalar`.
    fn reflection_from(&self, inc: &Incident, wo: DVec3, h: DVec3) -> f64 {
        let wi = inc.wi;
        let (ci, co) = (wi.dot(h), wo.dot(h));
        if !(h.z > 0.0 && ci * wi.z > 0.0 && co * wo.z > 0.0) {
            return 0.0;
        }
        let d = self.ndf.d(h);
        if d == 0.0 {
            return 0.0;
        }
        let g = self.g_from(inc, wo, false);
        // Exact dielectric F for light arriving at the facet from wi's side
        // (a negative cosine: from inside, index 1/eta); 1 under TIR.
        let f = fresnel::dielectric(ci, self.eta);
        let v = f * d * g / (4.0 * (wi.z * wo.z).abs());
        if v.is_finite() { v.max(0.0) } else { 0.0 }
    }

    /// Probability of choosing the reflected lobe in [`Brdf::sample`]: the
    /// Fresnel reflectance at the macro normal, kept inside [0.05, 0.95] so
    /// that both lobes are drawn wherever either is non-zero (a rough surface
    /// transmits through tilted facets beyond the critical angle).
    fn p_reflect(&self, wi: DVec3) -> f64 {
        fresnel::dielectric(wi.z, self.eta).clamp(0.05, 0.95)
    }

    /// Density of the microfacet normal sampler for light from `wi`: GGX's
    /// visible normals of `±wi` (Heitz 2018), or Beckmann's `D cosθh`.
    fn pdf_m(&self, wi: DVec3, m: DVec3) -> f64 {
        let w = if wi.z < 0.0 { -wi } else { wi };
        self.ndf.pdf_h(w, m)
    }

    /// The refraction of `wi` through a facet of normal `m` (Snell's law,
    /// indices from each side), or `None` under total internal reflection.
    fn refract_about(&self, wi: DVec3, m: DVec3) -> Option<DVec3> {
        let c = wi.dot(m);
        let (ei, eo) = if wi.z > 0.0 {
            (1.0, self.eta)
        } else {
            (self.eta, 1.0)
        };
        let mu = ei / eo;
        let sin2_t = mu * mu * (1.0 - c * c).max(0.0);
        if sin2_t >= 1.0 {
            return None;
        }
        let cos_t = (1.0 - sin2_t).sqrt();
        Some((-mu * wi + (mu * c - c.signum() * cos_t) * m).normalize())
    }

    /// The distribution, for plots and tests.
    pub fn microfacet(&self) -> &Microfacet {
        &self.ndf
    }

    /// The relative index (below over above).
    pub fn eta(&self) -> f64 {
        self.eta
    }
}

impl Brdf for RoughDielectric {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.tint * self.eval_scalar(wi, wo)
    }

    fn eval_with_half(&self, wi: DVec3, wo: DVec3, h: DVec3) -> Rgb {
        self.eval_with_half_from(&self.incident(wi), wo, h)
    }

    // The albedo quadrature's panels: Λ(wi) (a square root and two
    // divisions) once per panel rather than once per node.
    fn eval_many(&self, wi: DVec3, wo: &[DVec3], out: &mut [Rgb]) {
        let inc = self.incident(wi);
        for (o, &w) in out.iter_mut().zip(wo) {
            *o = self.tint * self.eval_from(&inc, w);
        }
    }

    fn eval_many_with_half(&self, wi: DVec3, wo: &[DVec3], h: &[DVec3], out: &mut [Rgb]) {
        let inc = self.incident(wi);
        for ((o, &w), &hh) in out.iter_mut().zip(wo).zip(h) {
            *o = self.eval_with_half_from(&inc, w, hh);
        }
    }

    fn claims(&self) -> Claims {
        Claims {
            // The generalised reciprocity of a BTDF, f(wi, wo)/ηo² =
            // f(wo, wi)/ηi² (Veach 1997, eq. 5.14), which the check applies
            // through `interface_eta`: eq. 21 divided by ηo² is symmetric
            // in (i, o) (F is the same from both sides, Stokes; G and the
            // denominator are symmetric), and eq. 20 is symmetric outright.
            reciprocal: true,
            // With the Jacobians of eqs. 14 and 17 the albedo becomes an
            // integral over facets: ρR + ρT = ∫ (F + (1 − F)) D G |wi·m| / |wi·n| dm
            // ≤ ∫ D G1(wi) ⟨wi·m⟩ dm / |wi·n| = 1 (Heitz 2014 eq. 2), since
            // every G here is ≤ G1(wi): 1/(1 + Λi + Λo) ≤ 1/(1 + Λi) and
            // B(1 + a, 1 + b) = ∫ C^a (1 − C)^b dC ≤ ∫ C^a dC = 1/(1 + a).
            energy_conserving: self.tint.max_element() <= 1.0,
            isotropic: self.ndf.is_isotropic(),
        }
    }

    fn transmits(&self) -> bool {
        true
    }

    fn interface_eta(&self) -> Option<f64> {
        Some(self.eta)
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z == 0.0 || !wi.is_finite() {
            return None;
        }
        let pr = self.p_reflect(wi);
        let (reflect, ux) = if u.x < pr {
            (true, (u.x / pr).min(microfacet::ONE_MINUS_EPS))
        } else {
            (
                false,
                ((u.x - pr) / (1.0 - pr)).min(microfacet::ONE_MINUS_EPS),
            )
        };
        // Normals visible from wi's side: the sampler of ±wi (above).
        let w = if wi.z < 0.0 { -wi } else { wi };
        let m = self.ndf.sample_h(w, DVec2::new(ux, u.y));
        if m.z.is_nan() || m.z <= 0.0 || wi.dot(m) * wi.z <= 0.0 {
            return None;
        }
        let wo = if reflect {
            frame::reflect_about(wi, m)
        } else {
            self.refract_about(wi, m)?
        };
        // A reflection that leaves through the surface, or a refraction that
        // stays on wi's side, is what another facet's lobe covers: no sample.
        let same = (wo.z > 0.0) == (wi.z > 0.0);
        (wo.z != 0.0 && same == reflect && wo.is_finite()).then_some(wo)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        let Some(Facet {
            h,
            transmits,
            ci,
            co,
        }) = self.facet(wi, wo)
        else {
            return 0.0;
        };
        let pm = self.pdf_m(wi, h);
        let pr = self.p_reflect(wi);
        let p = if transmits {
            // Eq. 17: dωh/dωo = ηo² |wo·h| / (ηi wi·h + ηo wo·h)².
            let (ei, eo) = (self.eta_of(wi), self.eta_of(wo));
            let den = ei * ci + eo * co;
            (1.0 - pr) * pm * eo * eo * co.abs() / (den * den)
        } else {
            // Eq. 14: dωh/dωo = 1 / (4 |wo·h|).
            pr * pm / (4.0 * co.abs())
        };
        if p.is_finite() { p.max(0.0) } else { 0.0 }
    }

    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        // Transmission: the facet that refracts wi into wo has the normal
        // h ∝ ηi wi + ηo wo (eq. 16), which must face both (χ⁺, eq. 21):
        // wi·(ηi wi + ηo wo) = ηi + ηo wi·wo and wo·(ηi wi + ηo wo) =
        // ηi wi·wo + ηo change sign on the cones wi·wo = −ηi/ηo and
        // −ηo/ηi about −wi, of which the one with the ratio below 1 exists.
        // f falls to 0 there (with |wi·h| and 1 − F, or with |wo·h|) and is
        // 0 beyond: a kink across every ring of the transmitted part that
        // the cone cuts (it is a ring itself only at normal incidence).
        let r = self.eta.min(1.0 / self.eta);
        let side = wi.z;
        let mut k: Vec<crate::Kink<'_>> = vec![Box::new(move |wo: DVec3| {
            if wo.z * side > 0.0 {
                1.0
            } else {
                wi.dot(wo) + r
            }
        })];
        // Reflection from the denser side: F's total internal reflection
        // starts at the facet angle sin θc = ηo/ηi, where F (eq. 22) has a
        // square-root kink; with wi·h = √((1 + wi·wo)/2) that is the cone
        // wi·wo = 1 − 2 (ηo/ηi)² about wi.
        let (ei, eo) = (self.eta_of(wi), self.eta_of(-wi));
        if ei > eo {
            let c = 1.0 - 2.0 * (eo / ei) * (eo / ei);
            k.push(Box::new(move |wo: DVec3| {
                if wo.z * side > 0.0 {
                    wi.dot(wo) - c
                } else {
                    1.0
                }
            }));
        }
        k
    }

    fn transmission_support(&self, wi: DVec3) -> Vec<crate::Cone> {
        // χ⁺ (eq. 21) for the facet h = s (ηi wi + ηo wo)/|·| that refracts
        // wi into wo, with σ = sign(wi.z) and k = ηi/ηo: wi·h, wo·h and h.z
        // must have the signs σ, −σ and +. With k < 1, wo·(ηi wi + ηo wo)
        // = ηi wi·wo + ηo > 0 fixes s = −σ; then wi·wo < −k (the cone of
        // `kinks` about −wi) and ηi wi.z + ηo wo.z must have the sign −σ:
        // wo·(−σ z) > k |wi.z|. With k > 1, ηi + ηo wi·wo > 0 fixes s = σ;
        // then wi·wo < −1/k and wo·(σ z) > −k |wi.z| (an obtuse cone about
        // wi's side of the normal). Outside either, f is 0 (facet returns
        // None).
        let (Some(axis), true) = ((-wi).try_normalize(), wi.z != 0.0) else {
            return Vec::new();
        };
        let side = wi.z.signum();
        let k = self.eta_of(wi) / self.eta_of(-wi);
        let plane = if k < 1.0 {
            crate::Cone {
                axis: DVec3::new(0.0, 0.0, -side),
                cos_half: k * wi.z.abs(),
            }
        } else {
            crate::Cone {
                axis: DVec3::new(0.0, 0.0, side),
                cos_half: -k * wi.z.abs(),
            }
        };
        vec![
            crate::Cone {
                axis,
                cos_half: self.eta.min(1.0 / self.eta),
            },
            plane,
        ]
    }

    fn peaks(&self, wi: DVec3) -> Vec<DVec3> {
        // The refracted direction through the macro surface (the transmitted
        // lobe's centre), when Snell's law has a solution.
        frame::refract(wi, self.eta).into_iter().collect()
    }

    /// The interface in a white furnace: the same distribution, roughness,
    /// index and Smith term with a white tint. A dielectric's Fresnel term
    /// only splits the light between reflection and transmission, so the
    /// whole-sphere albedo ρR + ρT of this lobe is what single scattering
    /// keeps, and 1 − (ρR + ρT) what it loses (Walter et al. 2007 §5.2).
    fn furnace(&self) -> Option<Box<dyn Brdf>> {
        let s = &self.ndf.first;
        RoughDielectric::new(s.dist, s.ax, s.ay, self.eta, self.geometry, Rgb::ONE)
            .ok()
            .map(|b| Box::new(b) as Box<dyn Brdf>)
    }

    fn ndf(&self) -> Option<&dyn Ndf> {
        Some(&self.ndf)
    }

    fn microfacet_terms(&self) -> Option<MicrofacetTerms> {
        let ndf = self.ndf;
        let me = self.clone();
        Some(MicrofacetTerms {
            distribution: match ndf.first.dist {
                Distribution::Beckmann => "Beckmann",
                _ => "GGX",
            }
            .to_string(),
            geometry: match self.geometry {
                Geometry::Smith => "separable Smith",
                Geometry::SmithCorrelated => "height-correlated Smith",
            }
            .to_string(),
            d: Arc::new(move |h| ndf.d(h)),
            g1: Arc::new(move |w| if w.z > 0.0 { ndf.g1(w) } else { 0.0 }),
            g2: Arc::new(move |wi, wo, _h| me.g(wi, wo, (wi.z > 0.0) != (wo.z > 0.0))),
        })
    }

    fn fresnel_term(&self) -> Option<FresnelTerm> {
        Some(FresnelTerm {
            fresnel: Fresnel::Dielectric {
                eta: Rgb::splat(self.eta),
            },
            source: "exact dielectric (rough interface)".into(),
        })
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        self.kernel.as_ref().map(|k| k as &dyn Kernel)
    }
}

// ---------------------------------------------------------------------------
// Batch kernel.

/// [`RoughDielectric::eval`] in f32 lanes: both lobes computed for every
/// lane and the one the pair's sides call for selected.
#[derive(Debug, Clone, Copy)]
struct RdKernel {
    tint: [f32; 3],
    dist: u8,
    scale: ScaleLanes,
    eta: f32,
    /// η² and 1/η²: ηrel² for light arriving from above and from below.
    eta2: f32,
    inv_eta2: f32,
    correlated: bool,
    /// The f64 index, for the transmission half vector formed in f64 lanes.
    eta64: f64,
}

impl RdKernel {
    /// The lane form, `None` for a distribution without one (every one this
    /// model offers has one).
    fn new(ndf: &Microfacet, eta: f64, geometry: Geometry, tint: Rgb) -> Option<Self> {
        let (dist, scale) = ScaleLanes::new(&ndf.first)?;
        Some(Self {
            tint: math::rgb(tint),
            dist,
            scale,
            eta: eta as f32,
            eta2: (eta * eta) as f32,
            inv_eta2: (1.0 / (eta * eta)) as f32,
            correlated: geometry == Geometry::SmithCorrelated,
            eta64: eta,
        })
    }
}

/// This interface's reflected lobe (Walter et al. 2007, eq. 20) in f32
/// lanes, for a model that lays the interface over something else (the
/// `coated` model's kernel): the same lane code as this model's own kernel,
/// so the two cannot drift apart.
#[derive(Debug, Clone, Copy)]
pub(crate) struct ReflectionLanes(RdKernel);

impl ReflectionLanes {
    /// The lane form of `rd`'s reflection, `None` when `rd` has no kernel,
    /// is tinted or uses the height-correlated G (a coat is built untinted
    /// with the separable G, which is all this form evaluates).
    pub(crate) fn of(rd: &RoughDielectric) -> Option<Self> {
        rd.kernel
            .filter(|k| !k.correlated && k.tint == [1.0; 3])
            .map(Self)
    }

    /// The distribution's const tag ([`ScaleLanes::BECKMANN`] or
    /// [`ScaleLanes::GGX`]), which [`ReflectionLanes::lane`] must be called with.
    pub(crate) fn dist(&self) -> u8 {
        self.0.dist
    }

    /// `f_r(wi, wo)` (untinted, one value) for lanes with both directions
    /// above the surface; other lanes are the model's value for them.
    #[inline(always)]
    pub(crate) fn lane<const D: u8, V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> V {
        let [r, _, _] = RdLane::<D, false>(&self.0).lane(wi, wo);
        r
    }
}

/// The exact dielectric Fresnel transmittance `1 − F` at `c = |cos θ|`
/// with `g = ηrel cos θt` and `n2 = η²rel`, written out so that it does not
/// cancel near grazing incidence or total internal reflection:
/// `½ [4cg/(c + g)² + 4 n² cg/(n² c + g)²]` (Walter et al. 2007, eq. 22's
/// terms' complements). Shared with the `coated` kernel's macro interface.
#[inline(always)]
pub(crate) fn fresnel_t_lanes<V: Lanes>(c: V, g: V, n2: V) -> V {
    let (s1, s2) = (c + g, n2 * c + g);
    let cg4 = c * g * 4.0;
    (cg4 / (s1 * s1) + cg4 * n2 / (s2 * s2)) * 0.5
}

/// `ln(1 + z)` for `z ≥ 0`, accurate relative to the result for small `z`.
#[inline(always)]
fn ln1p<V: Lanes>(z: V) -> V {
    let one = V::splat(1.0);
    z.lt(V::splat(0.4))
        .select(math::ln_near_one(one + z, -z), math::ln(one + z))
}

/// `ln ser(x)` of Lanczos' series for `Γ` (g = 5, six terms; Press et al.,
/// *Numerical Recipes* 2nd ed. §6.1, `gammln`, relative error < 2e-10):
/// `Γ(x) = √(2π) (x + 4.5)^(x − 0.5) e^−(x + 4.5) ser(x − 1)`, written here
/// for `ser(x)` with `Γ(x) = √(2π) ser(x)/x · (x + 5.5)^(x + 0.5) e^−(x + 5.5)`.
#[inline(always)]
fn lanczos_ser<V: Lanes>(x: V) -> V {
    const C: [f32; 6] = [
        76.180_09,
        -86.505_32,
        24.014_1,
        -1.231_739_6,
        0.001_208_650_9,
        -0.000_005_395_239,
    ];
    let mut s = V::splat(1.000_000_000_19);
    let mut y = x;
    for c in C {
        y += V::splat(1.0);
        s += V::splat(c) / y;
    }
    s
}

/// `B(x, y)` for `x, y ≥ 1` from Lanczos' `Γ`, arranged so that nothing
/// large cancels: with `s = x + y`,
/// `ln B = −(x + ½) ln(1 + y/(x + 5.5)) − (y + ½) ln(1 + x/(y + 5.5)) + ½ ln(s + 5.5) − 5.5
///        + ln(√(2π) ser(x) ser(y) s / (ser(s) x y))`.
/// 0 where either argument is infinite.
#[inline(always)]
fn beta_lanes<V: Lanes>(x: V, y: V) -> V {
    let s = x + y;
    let t = -(x + 0.5) * ln1p(y / (x + 5.5)) - (y + 0.5) * ln1p(x / (y + 5.5))
        + math::ln(s + 5.5) * 0.5
        - 5.5;
    let r = lanczos_ser(x) * lanczos_ser(y) / lanczos_ser(s) * (s / x) / y * 2.506_628_3;
    let v = math::exp(t) * r;
    (x.is_finite() & y.is_finite()).select(v, V::splat(0.0))
}

/// One monomorphised combination of distribution and geometry.
#[derive(Debug)]
struct RdLane<'a, const D: u8, const CORRELATED: bool>(&'a RdKernel);

/// Which lobes a vector of pairs needs ([`RdLane::sides`]): both, only the
/// reflected one (every pair on one side) or only the transmitted one.
const BOTH: u8 = 0;
const REFLECT: u8 = 1;
const TRANSMIT: u8 = 2;

impl<const D: u8, const CORRELATED: bool> LaneKernel for RdLane<'_, D, CORRELATED> {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let zero = V::splat(0.0);
        let (up_i, up_o) = (wi[2].gt(zero), wo[2].gt(zero));
        // Opposite sides: exactly one of the two is above.
        let trans = (up_i & !up_o) | (up_o & !up_i);
        // A lobe mesh's rows lie wholly above or wholly below the surface
        // except near the horizon, so most vectors need one lobe: the
        // other's half vector, Fresnel term and G (for the correlated G of
        // transmission, a Beta function: logarithms, an exponential and
        // eighteen divisions) are skipped there. Each branch computes the
        // same values for its lanes as the general one. The one-lane
        // fallback keeps the general path: LLVM vectorises its loop over
        // pairs only without a branch per pair (with the branch, 51 against
        // 70 M evals/s on one core here).
        if V::LANES == 1 {
            self.sides::<BOTH, V>(wi, wo, up_i, up_o, trans)
        } else if !trans.any() {
            self.sides::<REFLECT, V>(wi, wo, up_i, up_o, trans)
        } else if trans.all() {
            self.sides::<TRANSMIT, V>(wi, wo, up_i, up_o, trans)
        } else {
            self.sides::<BOTH, V>(wi, wo, up_i, up_o, trans)
        }
    }

    // One vector at a time: through `Twice` on AVX2 the 128 × 256 lobe,
    // which a slider drag waits for, took 193–225 µs against 183–203
    // (criterion `lobe/rough-dielectric/128x256/reuse`, 5 interleaved
    // rounds on a Zen 3), though random pairs gained 7 % (`batch/
    // rough-dielectric/avx2x8`, 3.48–3.65 against 3.73–4.02 ms): the
    // lobe's vectors mostly take one side's branch, and at 16 lanes fewer
    // of them are uniform near the horizon.
    const TWICE: bool = false;
}

impl<const D: u8, const CORRELATED: bool> RdLane<'_, D, CORRELATED> {
    /// The lane values for vectors whose pairs need the lobes `S` ([`BOTH`],
    /// [`REFLECT`] or [`TRANSMIT`]); `up_i`, `up_o` and `trans` are the
    /// sides of each pair as [`LaneKernel::lane`] found them.
    #[inline(always)]
    fn sides<const S: u8, V: Lanes>(
        &self,
        wi: [V; 3],
        wo: [V; 3],
        up_i: V::Mask,
        up_o: V::Mask,
        trans: V::Mask,
    ) -> [V; 3] {
        let k = self.0;
        let (zero, one) = (V::splat(0.0), V::splat(1.0));
        let (zi, zo) = (wi[2], wo[2]);
        let off = zi.eq(zero) | zo.eq(zero);
        let eta = V::splat(k.eta);
        let eo = up_o.select(one, eta);
        // The half vector candidates in f64 lanes: reflection wi + wo
        // (eq. 13), transmission ηi wi + ηo wo (eq. 16) with wi above
        // (ηi = 1, ηo = η) or below (ηi = η, ηo = 1). Near the refracted
        // direction the latter's tangential part cancels, and a product
        // rounded to f32 first would leave an error of 1e-7 against a lobe
        // of width α = 0.001. Only the candidates some lane picks are
        // formed; the others stay 0, which no lane selects.
        let [ix, iy, iz] = math::widen3(wi);
        let [ox, oy, oz] = math::widen3(wo);
        let e = k.eta64;
        let need = [
            S != TRANSMIT,
            S != REFLECT && up_i.any(),
            S != REFLECT && !up_i.all(),
        ];
        // For each: |hu|² and the numerator of Fresnel's
        // g² = η²rel − 1 + (wi·h)² (Walter eq. 22, ηrel the index beyond the
        // facet over wi's), g² |hu|² = (η²rel − 1) |hu|² + (wi·hu)², formed
        // in f64 too: near total internal reflection (η²rel < 1) g² is a
        // small difference, and 1 − F ∝ g there.
        let (m_up, m_down) = (e * e - 1.0, 1.0 / (e * e) - 1.0);
        let mut hus = [[zero; 3]; 3];
        let mut l2s = [zero; 3];
        let mut g2s = [[zero; 2]; 3];
        // Reflection above a denser side (every pair of a coat, and the
        // upper rows of this model's lobe at η > 1) needs no f64: wi + wo
        // cancels exactly where it cancels (Sterbenz), and g² |hu|² is a
        // sum of two positive terms there, (η² − 1) |hu|² + (wi·hu)².
        let f32_reflect = S == REFLECT && up_i.all() && e > 1.0;
        if f32_reflect {
            let h = math::channels!(|c| wi[c] + wo[c]);
            let l2 = math::dot(h, h);
            let wih = math::dot(wi, h);
            hus[0] = h;
            l2s[0] = l2;
            g2s[0] = [l2 * (m_up as f32) + wih * wih, zero];
        }
        for j in 0..3 {
            if !need[j] || (j == 0 && f32_reflect) {
                continue;
            }
            let h = match j {
                0 => [ix + ox, iy + oy, iz + oz],
                1 => [ix + ox * e, iy + oy * e, iz + oz * e],
                _ => [ix * e + ox, iy * e + oy, iz * e + oz],
            };
            let l2 = h[0] * h[0] + h[1] * h[1] + h[2] * h[2];
            let wih = ix * h[0] + iy * h[1] + iz * h[2];
            hus[j] = math::channels!(|c| V::narrow(h[c]));
            l2s[j] = V::narrow(l2);
            g2s[j] = [
                V::narrow(l2 * m_up + wih * wih),
                V::narrow(l2 * m_down + wih * wih),
            ];
        }
        let pick = |a: [V; 3]| match S {
            REFLECT => a[0],
            TRANSMIT => up_i.select(a[1], a[2]),
            _ => trans.select(up_i.select(a[1], a[2]), a[0]),
        };
        let hu: [V; 3] = math::channels!(|c| pick([hus[0][c], hus[1][c], hus[2][c]]));
        let l2 = pick(l2s);
        let g2n = up_i.select(
            pick([g2s[0][0], g2s[1][0], g2s[2][0]]),
            pick([g2s[0][1], g2s[1][1], g2s[2][1]]),
        );
        let flip = hu[2].lt(zero).select(-one, one);
        let inv = flip / l2.sqrt();
        let h = math::scale3(hu, inv);
        let (ci, co) = (math::dot(wi, h), math::dot(wo, h));
        let facing = (ci * zi).gt(zero) & (co * zo).gt(zero) & h[2].gt(zero);
        let ok = facing & !off & l2.gt(V::splat(1e-30)) & l2.lt(V::splat(f32::INFINITY));
        let d = k.scale.d::<D, V>(h);
        // 1 + Λ of each direction's mirror image above the surface.
        let opl_i = k.scale.one_plus_lambda::<D, V>([wi[0], wi[1], zi.abs()]);
        let opl_o = k.scale.one_plus_lambda::<D, V>([wo[0], wo[1], zo.abs()]);
        let g = if CORRELATED {
            match S {
                REFLECT => one / (opl_i + opl_o - 1.0),
                TRANSMIT => beta_lanes(opl_i, opl_o),
                _ => trans.select(beta_lanes(opl_i, opl_o), one / (opl_i + opl_o - 1.0)),
            }
        } else {
            one / (opl_i * opl_o)
        };
        // Fresnel at the facet from wi's side in the form of Walter's eq. 22
        // (g = ηrel cosθt): R = ½ [((c − g)/(c + g))² + ((η²rel c − g)/(η²rel c + g))²]
        // and its complement T = 1 − R = ½ [4cg/(c + g)² + 4η²rel cg/(η²rel c + g)²]
        // written out, so neither cancels; R = 1, T = 0 under total
        // internal reflection (g² ≤ 0).
        let n2 = up_i.select(V::splat(k.eta2), V::splat(k.inv_eta2));
        let c = ci.abs();
        let tir = g2n.le(zero);
        let gg = (g2n / l2).max(zero).sqrt();
        let zz = (zi * zo).abs();
        // Eq. 20, and eq. 21 with (ηi wi·h + ηo wo·h)² = |ηi wi + ηo wo|² = l2.
        // (Plain blocks, not closures: a closure the optimiser leaves out of
        // line is compiled without the caller's instruction set, and every
        // vector operation in it becomes a call.)
        let refl = if S == TRANSMIT {
            zero
        } else {
            let (s1, s2) = (c + gg, n2 * c + gg);
            let (rs, rp) = ((c - gg) / s1, (n2 * c - gg) / s2);
            let fr = tir.select(one, (rs * rs + rp * rp) * 0.5);
            fr * d * g / (zz * 4.0)
        };
        let tr = if S == REFLECT {
            zero
        } else {
            let ft = tir.select(zero, fresnel_t_lanes(c, gg, n2));
            (ci * co).abs() * eo * eo * ft * d * g / (zz * l2)
        };
        let v = match S {
            REFLECT => refl,
            TRANSMIT => tr,
            _ => trans.select(tr, refl),
        };
        let v = (ok & v.is_finite()).select(v.max(zero), zero);
        math::channels!(|c| v * k.tint[c])
    }
}

impl Kernel for RdKernel {
    fn eval(&self, isa: Isa, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        match (self.dist, self.correlated) {
            (ScaleLanes::BECKMANN, false) => batch::run(
                &RdLane::<{ ScaleLanes::BECKMANN }, false>(self),
                isa,
                dirs,
                out,
            ),
            (ScaleLanes::BECKMANN, true) => batch::run(
                &RdLane::<{ ScaleLanes::BECKMANN }, true>(self),
                isa,
                dirs,
                out,
            ),
            (_, false) => batch::run(&RdLane::<{ ScaleLanes::GGX }, false>(self), isa, dirs, out),
            (_, true) => batch::run(&RdLane::<{ ScaleLanes::GGX }, true>(self), isa, dirs, out),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::analysis::sample_histogram::{HistogramOptions, sample_histogram};
    use crate::frame::from_spherical;
    use crate::quadrature::{gauss_legendre, integrate};
    use crate::{DeltaKind, sampling};
    use serde_json::{Value, json};
    use std::f64::consts::PI;

    fn model(p: Value) -> Box<dyn Brdf> {
        ModelSpec::from_json("rough-dielectric", &p)
            .unwrap()
            .build()
            .unwrap()
    }

    /// A direction from `cos θ` (either sign) and φ.
    fn dir(z: f64, phi: f64) -> DVec3 {
        let r = (1.0 - z * z).max(0.0).sqrt();
        DVec3::new(r * phi.cos(), r * phi.sin(), z)
    }

    // -----------------------------------------------------------------------
    // Walter et al. 2007 written out again, independently of the model's
    // code: D from θm and φm (eq. 33 for Beckmann, GGX's eq. after 33, with
    // the anisotropic exponent), G1 from Walter's eqs. 25/27 (Beckmann, erf)
    // and 34 (GGX), F from Walter's eq. 22 (Cook & Torrance's form, not the
    // r∥/r⊥ form of `fresnel::dielectric`), h from eqs. 13 and 16, f from
    // eqs. 20 and 21. With `correlated`, Heitz 2014's height-correlated
    // terms instead of G1·G1 (eq. 99 in reflection; in transmission the
    // integral over the height CDF u of u^Λi (1 − u)^Λo, which is
    // B(1 + Λi, 1 + Λo), here from Γ itself rather than the model's ln Γ),
    // with Λ = 1/G1 − 1 from the G1 above.

    struct Walter {
        ggx: bool,
        ax: f64,
        ay: f64,
        eta: f64,
        correlated: bool,
    }

    impl Walter {
        fn d(&self, m: DVec3) -> f64 {
            let c = m.z;
            if c <= 0.0 {
                return 0.0;
            }
            let s = (1.0 - c * c).max(0.0).sqrt();
            let tan2 = (s / c).powi(2);
            let (cp2, sp2) = if s > 0.0 {
                ((m.x / s).powi(2), (m.y / s).powi(2))
            } else {
                (1.0, 0.0)
            };
            let k = cp2 / (self.ax * self.ax) + sp2 / (self.ay * self.ay);
            let c4 = c.powi(4);
            if self.ggx {
                1.0 / (PI * self.ax * self.ay * c4 * (1.0 + tan2 * k).powi(2))
            } else {
                (-tan2 * k).exp() / (PI * self.ax * self.ay * c4)
            }
        }

        fn g1(&self, v: DVec3) -> f64 {
            let z = v.z.abs();
            let s = (1.0 - z * z).max(0.0).sqrt();
            if s == 0.0 {
                return 1.0;
            }
            let (cp, sp) = (v.x / s, v.y / s);
            let alpha = (cp * cp * self.ax * self.ax + sp * sp * self.ay * self.ay).sqrt();
            let tan = s / z;
            if self.ggx {
                2.0 / (1.0 + (1.0 + alpha * alpha * tan * tan).sqrt())
            } else {
                let a = 1.0 / (alpha * tan);
                let lambda = 0.5 * (libm::erf(a) - 1.0) + (-a * a).exp() / (2.0 * a * PI.sqrt());
                1.0 / (1.0 + lambda)
            }
        }

        /// Eq. 22 for light arriving from `i`'s side at a facet `m`.
        fn fresnel(&self, i: DVec3, m: DVec3) -> f64 {
            let (ni, nt) = if i.z > 0.0 {
                (1.0, self.eta)
            } else {
                (self.eta, 1.0)
            };
            let c = i.dot(m).abs();
            let g2 = (nt / ni).powi(2) - 1.0 + c * c;
            if g2 < 0.0 {
                return 1.0;
            }
            let g = g2.sqrt();
            let a = (c * (g + c) - 1.0) / (c * (g - c) + 1.0);
            0.5 * (g - c).powi(2) / (g + c).powi(2) * (1.0 + a * a)
        }

        fn f(&self, i: DVec3, o: DVec3) -> f64 {
            if i.z == 0.0 || o.z == 0.0 {
                return 0.0;
            }
            let side = |w: DVec3| if w.z > 0.0 { 1.0 } else { self.eta };
            let (ni, no) = (side(i), side(o));
            let reflect = i.z * o.z > 0.0;
            let mut m = if reflect {
                (i + o) * i.z.signum()
            } else {
                -(ni * i + no * o)
            }
            .normalize();
            if m.z < 0.0 {
                m = -m;
            }
            if i.dot(m) / i.z <= 0.0 || o.dot(m) / o.z <= 0.0 {
                return 0.0;
            }
            let (gi, go) = (self.g1(i), self.g1(o));
            let g = if !self.correlated {
                gi * go
            } else {
                let (x, y) = (1.0 / gi, 1.0 / go);
                if reflect {
                    1.0 / (x + y - 1.0)
                } else if x + y < 170.0 {
                    libm::tgamma(x) * libm::tgamma(y) / libm::tgamma(x + y)
                } else {
                    // Γ overflows; such grazing pairs are left out.
                    return f64::NAN;
                }
            };
            let (d, f) = (self.d(m), self.fresnel(i, m));
            if reflect {
                f * d * g / (4.0 * i.z.abs() * o.z.abs())
            } else {
                let den = ni * i.dot(m) + no * o.dot(m);
                (i.dot(m) * o.dot(m)).abs() / (i.z * o.z).abs() * no * no * (1.0 - f) * d * g
                    / (den * den)
            }
        }
    }

    /// Random pairs on the whole sphere, half of them near the macro
    /// refraction or mirror direction (where the lobes are).
    fn sphere_pairs(eta: f64, alpha: f64, n: usize, seed: u64) -> Vec<(DVec3, DVec3)> {
        let mut rng = sampling::rng(seed);
        let mut out = Vec::new();
        for k in 0..n {
            let u = sampling::uniform2(&mut rng);
            let wi = dir(2.0 * u.x - 1.0, 2.0 * PI * u.y);
            let v = sampling::uniform2(&mut rng);
            let any = dir(2.0 * v.x - 1.0, 2.0 * PI * v.y);
            let wo = match k % 4 {
                0 | 1 => any,
                2 => frame::refract(wi, eta).map_or(any, |t| (t + any * alpha).normalize()),
                _ => (frame::reflect(wi) + any * alpha).normalize(),
            };
            if wo.z != 0.0 && wi.z != 0.0 {
                out.push((wi, wo));
            }
        }
        out
    }

    #[test]
    fn matches_walters_formulas_on_the_whole_sphere() {
        let mut nonzero = [[0usize; 2]; 2];
        for (ggx, correlated) in [(true, false), (false, false), (true, true), (false, true)] {
            for eta in [1.5, 0.6, 1.01, 2.4, 0.2] {
                for (ax, ay) in [(0.05, 0.05), (0.3, 0.3), (1.2, 1.2), (0.1, 0.6)] {
                    let r = Walter {
                        ggx,
                        ax,
                        ay,
                        eta,
                        correlated,
                    };
                    let geometry = if correlated {
                        "smith-correlated"
                    } else {
                        "smith"
                    };
                    let b = model(json!({"distribution": if ggx {"ggx"} else {"beckmann"},
                        "alpha_x": ax, "alpha_y": ay, "eta": eta, "geometry": geometry}));
                    for (wi, wo) in sphere_pairs(eta, ax, 400, 7) {
                        let want = r.f(wi, wo);
                        if want.is_nan() {
                            continue;
                        }
                        let got = b.eval(wi, wo);
                        assert!(
                            (got.x - want).abs() <= 1e-9 * want.abs() + 1e-300,
                            "ggx {ggx} {geometry} η {eta} α {ax},{ay}: f({wi}, {wo}) = {} vs {want}",
                            got.x
                        );
                        assert_eq!(got.x, got.y);
                        if want > 0.0 {
                            let transmits = (wi.z > 0.0) != (wo.z > 0.0);
                            nonzero[usize::from(correlated)][usize::from(transmits)] += 1;
                        }
                    }
                }
            }
        }
        // Both lobes were really exercised, with each Smith term.
        assert!(nonzero.iter().flatten().all(|&n| n > 2000), "{nonzero:?}");
    }

    #[test]
    fn hand_value_at_normal_incidence() {
        // wi = n from outside, wo = −n: h = n, D = 1/(π α²), G = 1, F(0) =
        // ((η − 1)/(η + 1))², wi·h = 1 and wo·h = −1, so the denominator is
        // (ηi wi·h + ηo wo·h)² = (1 − η)²: f = η² (1 − F0) / (π α² (1 − η)²).
        let (a, eta) = (0.2f64, 1.5f64);
        let b = model(json!({"alpha": a, "eta": eta}));
        let f0 = ((eta - 1.0) / (eta + 1.0)).powi(2);
        let want = eta * eta * (1.0 - f0) / (PI * a * a * (1.0 - eta).powi(2));
        let got = b.eval(DVec3::Z, -DVec3::Z).x;
        assert!((got / want - 1.0).abs() < 1e-14, "{got} vs {want}");
        // The reverse path: ηo = 1, so f/ηo² = f(reverse)/ηi² gives f/η².
        let back = b.eval(-DVec3::Z, DVec3::Z).x;
        assert!((back * eta * eta / want - 1.0).abs() < 1e-14);
        // Reflection at normal incidence: F0 D / 4.
        let refl = b.eval(DVec3::Z, DVec3::Z).x;
        assert!((refl / (f0 / (4.0 * PI * a * a)) - 1.0).abs() < 1e-14);
    }

    /// (η, α, wi, wo, f).
    type MitsubaValue = (f64, f64, [f64; 3], [f64; 3], f64);

    /// Values from Mitsuba 3.9.1 (`pip install mitsuba`, variant `scalar_rgb`,
    /// plugin `roughdielectric` with `int_ior = eta`, `ext_ior = 1`, GGX,
    /// `sample_visible` on), read as `eval(si.wi = wo, wo = wi)[0] / |wi.z|`:
    /// Mitsuba's `si.wi` is our viewer's direction and its value carries the
    /// cosine of its `wo` (our light's side). Its G is separable Smith.
    /// (Mitsuba's Beckmann G1 is Walter's rational approximation of eq. 27,
    /// so only GGX values are kept here.) Over 664 random GGX pairs on both
    /// sides (η 0.6, 1.33, 1.5, 2.4; α 0.05 to 0.8, anisotropic too) the
    /// median relative difference was 2.5e-7 and the 99th percentile 6e-5
    /// (Mitsuba computes in f32); these ten were drawn from them by
    /// configuration: (η, α, wi, wo, f).
    #[rustfmt::skip]
    const MITSUBA: &[MitsubaValue] = &[
        (1.5, 0.8, [0.4908066743048168, -0.8509754501952622, 0.18694809874084428],
          [-0.26511621488361076, 0.6355705316119941, -0.7250955054006571],
          0.4008820976638441),
        (1.5, 0.05, [-0.015631498310215795, 0.9605908966690441, -0.2775261888491598],
          [0.4629205591185119, -0.797400114308951, -0.38711447098432816],
          0.015770726262278746),
        (0.6, 0.3, [-0.9352842006758713, 0.3464630123193372, 0.07215847185679114],
          [0.7882593674729308, -0.44334374077034033, 0.42672414638843237],
          2.2213267549428246),
        (1.33, 0.8, [0.15873643986800068, 0.5517260481067362, 0.8187802577606254],
          [-0.43593553193923223, -0.875874756096527, 0.20689036619839962],
          0.010976400524912406),
        (2.4, 0.8, [0.49402320202180006, 0.6460922931358428, -0.5818125339098463],
          [0.8889611106148754, -0.136167807686221, -0.4372716226378013],
          0.14023213220266464),
        (0.6, 0.8, [0.2457067978498192, 0.643649534063146, 0.7248057993633075],
          [-0.4490286230112005, -0.8031334720541152, -0.3915991851153],
          0.5785326664949336),
        (0.6, 0.05, [-0.06302002422471763, 0.962570273822024, -0.26360376420094966],
          [0.06489909511442261, -0.5886444420854015, 0.8057827425896483],
          74.29134779988757),
        (0.6, 0.3, [-0.6184554145595784, -0.3359189294536654, -0.7104022614242183],
          [0.034430504927699786, -0.1629117056153136, -0.9860397134517114],
          0.010500591239115096),
        (1.33, 0.3, [0.06605538745428913, -0.9795414679199004, -0.19009260483667023],
          [-0.2805201549171522, -0.43853284734720605, -0.8538134365789807],
          0.0015223158585817571),
        (1.33, 0.05, [-0.28218970134587146, -0.26285202442071665, 0.9226471620897443],
          [0.24304869084264244, 0.21554047673344398, -0.9457640492052959],
          26.733180085876658),
    ];

    #[test]
    fn agrees_with_mitsuba_reference_values() {
        for &(eta, a, wi, wo, want) in MITSUBA {
            let b =
                model(json!({"distribution": "ggx", "alpha": a, "eta": eta, "geometry": "smith"}));
            let got = b.eval(DVec3::from(wi), DVec3::from(wo)).x;
            assert!(
                (got - want).abs() <= 1e-4 * want,
                "{wi:?} {wo:?}: {got} vs {want}"
            );
        }
    }

    // -----------------------------------------------------------------------
    // The smooth limit against `glass`.

    /// `∫ g dω` over the cone of half-angle `radius` about `axis`, in polar
    /// coordinates about it: ψ on geometric panels from 1e-7 rad (a lobe of
    /// width 1e-3 is resolved), χ by the trapezoid rule.
    fn cone_integral(g: impl Fn(DVec3) -> f64, axis: DVec3, radius: f64) -> f64 {
        let (t, b) = sampling::basis(axis);
        let gl = gauss_legendre(10);
        let mut edges = vec![0.0];
        let mut e = 1e-7;
        while e < radius {
            edges.push(e);
            e *= 1.5;
        }
        edges.push(radius);
        let n_chi = 256;
        let mut sum = 0.0;
        for k in 0..n_chi {
            let chi = 2.0 * PI * (k as f64 + 0.5) / n_chi as f64;
            let side = t * chi.cos() + b * chi.sin();
            for w in edges.windows(2) {
                sum += integrate(
                    |psi| g((axis * psi.cos() + side * psi.sin()).normalize()) * psi.sin(),
                    w[0],
                    w[1],
                    1,
                    &gl,
                );
            }
        }
        sum * 2.0 * PI / n_chi as f64
    }

    #[test]
    fn smooth_limit_is_the_glass_models_deltas() {
        let a = 1e-3;
        for dist in ["ggx", "beckmann"] {
            for eta in [1.5, 0.7] {
                let b = model(json!({"distribution": dist, "alpha": a, "eta": eta}));
                let glass = crate::models::glass::Glass::new(eta);
                for (z, phi) in [(0.95, 0.3), (0.6, 2.0), (-0.9, -1.0), (-0.5, 0.7)] {
                    let wi = dir(z, phi);
                    for lobe in glass.deltas(wi) {
                        // Flux: ∫ f(wi, wo) |cos θo| dωo about the lobe's
                        // direction is the lobe's weight (F or 1 − F).
                        let flux =
                            cone_integral(|wo| b.eval(wi, wo).x * wo.z.abs(), lobe.direction, 0.2);
                        let tol = if dist == "ggx" { 2e-3 } else { 1e-3 };
                        assert!(
                            (flux - lobe.weight.x).abs() <= tol * lobe.weight.x.max(0.05),
                            "{dist} η {eta} wi {wi} {:?}: {flux} vs {}",
                            lobe.kind,
                            lobe.weight.x
                        );
                        if lobe.kind == DeltaKind::Transmission {
                            // Radiance: with the viewer at wo = T(wi), the
                            // light gathered about wi is scaled by (ηo/ηi)² (1 − F),
                            // the lobe's radiance scale: ∫ f(w, wo) |cos θ| dω.
                            let wo = lobe.direction;
                            let gathered = cone_integral(|w| b.eval(w, wo).x * w.z.abs(), wi, 0.2);
                            let want = lobe.radiance_scale.x;
                            assert!(
                                (gathered - want).abs() <= tol * want.max(0.05),
                                "{dist} η {eta} wi {wi}: radiance {gathered} vs {want}"
                            );
                        }
                    }
                    // Past the critical angle (light from the denser side)
                    // the glass model has no transmitted lobe, and the rough
                    // one transmits nothing to speak of at α = 0.001.
                    if glass.deltas(wi).len() == 1 {
                        let total = cone_integral(
                            |wo| b.eval(wi, wo).x * wo.z.abs(),
                            frame::reflect(wi),
                            0.2,
                        );
                        assert!(
                            (total - 1.0).abs() < 2e-3,
                            "TIR {dist} η {eta} {wi}: {total}"
                        );
                    }
                }
            }
        }
    }

    // -----------------------------------------------------------------------
    // Sampling.

    /// χ² p-values of the sampler over the whole sphere for `seeds` seeds.
    fn p_values(b: &dyn Brdf, wi: DVec3, seeds: u64) -> Vec<f64> {
        (0..seeds)
            .map(|s| {
                let o = HistogramOptions {
                    n_theta: 24,
                    n_phi: 32,
                    samples: 60_000,
                    seed: 500 + s,
                    whole_sphere: true,
                    // The density has kinks inside bins (where a facet turns
                    // away, near the horizon); 6 points per axis misjudge a
                    // bin's mass by up to 4e-3 there, which 60 000 draws see.
                    quadrature_order: 16,
                    ..HistogramOptions::default()
                };
                let h = sample_histogram(b, wi, &o).unwrap();
                assert_eq!(h.chi2.impossible, 0, "{wi}: {:?}", h.chi2);
                assert!(h.pdf_mass <= 1.0 + 1e-3, "{wi}: ∫pdf = {}", h.pdf_mass);
                h.chi2.p_value
            })
            .collect()
    }

    #[test]
    fn sampler_matches_its_pdf_on_the_whole_sphere() {
        // Each configuration's p-values over independent seeds: a correct
        // sampler gives uniform p-values, so none tiny and about half below ½
        // over all of them; a density off by a Jacobian gives p ≈ 0 everywhere.
        let mut all = Vec::new();
        for (p, wis) in [
            (
                json!({"distribution": "ggx", "alpha": 0.3, "eta": 1.5}),
                vec![dir(0.8, 0.4), dir(-0.8, 0.4), dir(-0.4, 2.0), dir(0.1, 1.0)],
            ),
            (
                json!({"distribution": "beckmann", "alpha_x": 0.15, "alpha_y": 0.4, "eta": 1.33}),
                vec![dir(0.6, 0.4), dir(-0.6, -1.0)],
            ),
            (
                json!({"distribution": "ggx", "alpha_x": 0.6, "alpha_y": 0.2, "eta": 0.6,
                       "geometry": "smith-correlated"}),
                vec![dir(0.9, 0.1), dir(-0.3, 0.5)],
            ),
        ] {
            let b = model(p.clone());
            for wi in wis {
                let ps = p_values(b.as_ref(), wi, 8);
                eprintln!("χ² {p} wi {wi}: p = {ps:.3?}");
                assert!(ps.iter().all(|&x| x > 1e-4), "{p} {wi}: {ps:?}");
                all.extend(ps);
            }
        }
        let below = all.iter().filter(|&&x| x < 0.5).count() as f64 / all.len() as f64;
        assert!((0.3..=0.7).contains(&below), "{below}: {all:?}");
        let min = all.iter().copied().fold(1.0, f64::min);
        eprintln!(
            "χ² over {} runs: min p {min:.4}, fraction below ½ {below:.2}",
            all.len()
        );
    }

    #[test]
    fn a_wrong_jacobian_is_caught_by_the_sphere_histogram() {
        // The transmitted density without eq. 17's ηo² (a classic slip).
        #[derive(Debug)]
        struct NoEta2(Box<dyn Brdf>);
        impl Brdf for NoEta2 {
            fn id(&self) -> &'static str {
                "no-eta2"
            }
            fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
                self.0.eval(wi, wo)
            }
            fn claims(&self) -> Claims {
                self.0.claims()
            }
            fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
                self.0.sample(wi, u)
            }
            fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
                let p = self.0.pdf(wi, wo);
                if (wi.z > 0.0) != (wo.z > 0.0) {
                    p / 2.25
                } else {
                    p
                }
            }
        }
        let b = NoEta2(model(json!({"alpha": 0.3, "eta": 1.5})));
        let ps = p_values(&b, dir(0.8, 0.4), 2);
        assert!(ps.iter().all(|&x| x < 1e-6), "{ps:?}");
    }

    #[test]
    fn samples_are_unit_and_their_density_positive() {
        let b =
            model(json!({"alpha_x": 0.05, "alpha_y": 1.5, "eta": 2.4, "distribution": "beckmann"}));
        let mut rng = sampling::rng(3);
        for _ in 0..20_000 {
            let u = sampling::uniform2(&mut rng);
            let v = sampling::uniform2(&mut rng);
            let wi = dir(2.0 * v.x - 1.0, 2.0 * PI * v.y);
            if let Some(wo) = b.sample(wi, u) {
                assert!((wo.length() - 1.0).abs() < 1e-12 && wo.z != 0.0);
                let p = b.pdf(wi, wo);
                assert!(p.is_finite() && p > 0.0, "{wi} {wo}: {p}");
                assert!(b.eval(wi, wo).x > 0.0 || p > 0.0);
            }
        }
    }

    // -----------------------------------------------------------------------
    // Properties.

    #[test]
    fn generalised_reciprocity_holds_and_plain_does_not() {
        let eta: f64 = 1.5;
        for p in [
            json!({"distribution": "ggx", "alpha": 0.3, "eta": eta}),
            json!({"distribution": "beckmann", "alpha_x": 0.1, "alpha_y": 0.5, "eta": eta,
                   "geometry": "smith-correlated"}),
        ] {
            let b = model(p);
            let mut worst_plain = 0.0f64;
            for (wi, wo) in sphere_pairs(eta, 0.3, 2000, 5) {
                let (f, r) = (b.eval(wi, wo).x, b.eval(wo, wi).x);
                let side = |w: DVec3| if w.z > 0.0 { 1.0 } else { eta };
                let (a, c) = (f / side(wo).powi(2), r / side(wi).powi(2));
                assert!((a - c).abs() <= 1e-9 * a.max(c), "{wi} {wo}: {a} vs {c}");
                if f > 1e-3 {
                    worst_plain = worst_plain.max((f - r).abs() / f.max(r));
                }
            }
            // Plain reciprocity fails across the interface by 1 − 1/η².
            assert!(worst_plain > 0.5, "{worst_plain}");
        }
    }

    /// `B(1 + a, 1 + b) = ∫₀¹ C^a (1 − C)^b dC` by quadrature, with
    /// `C = u⁴` on [0, ½] and `1 − C = v⁴` on [½, 1] so that the powers'
    /// singular derivatives at the ends become smooth.
    fn beta_by_quadrature(a: f64, b: f64) -> f64 {
        let gl = gauss_legendre(20);
        let g = |c: f64| c.powf(a) * (1.0 - c).powf(b);
        let h = 0.5f64.powf(0.25);
        integrate(|u| g(u.powi(4)) * 4.0 * u.powi(3), 0.0, h, 100, &gl)
            + integrate(|v| g(1.0 - v.powi(4)) * 4.0 * v.powi(3), 0.0, h, 100, &gl)
    }

    #[test]
    fn height_correlated_transmission_uses_the_beta_function() {
        for (a, b) in [(0.0, 0.0), (0.3, 2.0), (5.0, 0.01), (12.0, 7.5)] {
            let q = beta_by_quadrature(a, b);
            assert!((beta(1.0 + a, 1.0 + b) / q - 1.0).abs() < 1e-8, "{a} {b}");
            // ≤ G1 of either direction: the basis of the energy claim.
            assert!(q <= 1.0 / (1.0 + a) + 1e-12 && q <= 1.0 / (1.0 + b) + 1e-12);
        }
        // The lane form (Lanczos, f32) against the f64 one.
        for (a, b) in [
            (0.0f32, 0.0f32),
            (0.3, 2.0),
            (5.0, 0.01),
            (1e4, 3.0),
            (1e6, 1e6),
        ] {
            let got = beta_lanes(1.0 + a, 1.0 + b) as f64;
            let want = beta(1.0 + a as f64, 1.0 + b as f64);
            assert!(
                (got - want).abs() <= 1e-5 * want + 1e-30,
                "{a} {b}: {got} vs {want} ({:e})",
                got / want - 1.0
            );
        }
        assert_eq!(beta_lanes(f32::INFINITY, 2.0), 0.0);
        assert_eq!(beta(f64::INFINITY, 2.0), 0.0);
    }

    /// `∫ f(wi, wo) |cos θo| dωo` over the hemisphere on `wo`'s `side`
    /// (+1 above, −1 below), by brute force: Gauss–Legendre in θ on 64
    /// panels on each side of `theta_break`, 512 azimuths.
    fn brute_force(b: &dyn Brdf, wi: DVec3, side: f64, theta_break: f64) -> f64 {
        let gl = gauss_legendre(12);
        let n_phi = 512;
        let mut sum = 0.0;
        for k in 0..n_phi {
            let phi = 2.0 * PI * (k as f64 + 0.5) / n_phi as f64;
            let g = |t: f64| {
                let w = from_spherical(t, phi);
                let wo = DVec3::new(w.x, w.y, side * w.z);
                b.eval(wi, wo).x * w.z * t.sin()
            };
            sum += integrate(g, 0.0, theta_break, 64, &gl)
                + integrate(g, theta_break, PI / 2.0, 64, &gl);
        }
        sum * 2.0 * PI / n_phi as f64
    }

    #[test]
    fn reflected_plus_transmitted_albedo_against_brute_force() {
        use crate::analysis::quadrature::{QuadratureOptions, rho_hd_parts_dir};
        for (p, wis) in [
            (
                json!({"distribution": "ggx", "alpha": 0.4, "eta": 1.5}),
                vec![dir(0.9, 0.2), dir(0.2, 0.2), dir(-0.9, 0.3), dir(-0.5, 1.0)],
            ),
            (
                json!({"distribution": "beckmann", "alpha_x": 0.3, "alpha_y": 0.6, "eta": 0.7,
                       "geometry": "smith-correlated"}),
                vec![dir(0.7, 0.5), dir(-0.7, 2.5)],
            ),
        ] {
            let b = model(p.clone());
            let eta = b.interface_eta().unwrap();
            for wi in wis {
                let s = wi.z.signum();
                // Eq. 21 with GGX is discontinuous where the generalised half
                // vector ηi wi + ηo wo turns horizontal (GGX's D does not
                // vanish there, and past it no facet faces both
                // directions): on the circle |cos θo| = ηi |cos θi| / ηo,
                // where the brute force puts a break.
                let (ei, eo) = if s > 0.0 { (1.0, eta) } else { (eta, 1.0) };
                let z_break = (ei * wi.z.abs() / eo).min(1.0);
                let r = brute_force(b.as_ref(), wi, s, PI / 4.0);
                let t = brute_force(
                    b.as_ref(),
                    wi,
                    -s,
                    z_break.acos().clamp(1e-3, PI / 2.0 - 1e-3),
                );
                let q = rho_hd_parts_dir(b.as_ref(), wi, &QuadratureOptions::default());
                eprintln!(
                    "{p} wi {wi}: brute ρR {r:.6} ρT {t:.6} sum {:.6}; quadrature ρR {:.6} ρT {:.6} sum {:.6}",
                    r + t,
                    q.reflected.value.x,
                    q.transmitted.value.x,
                    q.total.value.x
                );
                assert!(
                    (q.reflected.value.x - r).abs() < 1e-4,
                    "ρR {}",
                    q.reflected.value.x
                );
                assert!(
                    (q.transmitted.value.x - t).abs() < 1e-4,
                    "ρT {}",
                    q.transmitted.value.x
                );
                assert!(r + t <= 1.0 + 1e-6 && r + t > 0.5, "{}", r + t);
                // And the Monte Carlo estimate, within 4 standard errors.
                let m = crate::analysis::albedo::rho_hd_parts_dir(b.as_ref(), wi, 32_768, 9);
                for (e, want) in [(m.reflected, r), (m.transmitted, t), (m.total, r + t)] {
                    assert!(
                        (e.value.x - want).abs() <= 4.0 * e.std_error.x + 1e-4,
                        "MC {} ± {} vs {want}",
                        e.value.x,
                        e.std_error.x
                    );
                }
            }
        }
    }

    #[test]
    fn check_reports_a_reciprocal_energy_conserving_model() {
        use crate::analysis::{CheckOptions, check};
        let b = model(json!({"alpha": 0.2, "eta": 1.5}));
        let opts = CheckOptions {
            pairs: 2000,
            theta_count: 12,
            samples_per_angle: 1024,
            hh_samples: 4096,
            ..CheckOptions::default()
        };
        let rep = check(b.as_ref(), &opts);
        assert!(rep.reciprocity.reciprocal, "{rep}");
        assert!(rep.energy.conserves && rep.energy.transmits, "{rep}");
        assert_eq!(rep.energy.below.len(), 1);
        let c = &rep.energy.curves[0];
        assert_eq!(c.reflected.len(), c.rho.len());
        for k in 0..c.rho.len() {
            let sum = c.reflected[k].value.x + c.transmitted[k].value.x;
            assert!((sum - c.rho[k].value.x).abs() < 1e-12);
        }
        assert!(rep.consistent_with_claims(), "{rep}");
        // The table wraps its evidence at 100 columns: read it as words.
        let text = rep
            .to_string()
            .split_whitespace()
            .collect::<Vec<_>>()
            .join(" ");
        assert!(
            text.contains("ρR") && text.contains("light from below"),
            "{text}"
        );
    }

    // -----------------------------------------------------------------------
    // Bad input.

    #[test]
    fn bad_input_is_refused_or_defined() {
        let err = |p: Value| -> String {
            match ModelSpec::from_json("rough-dielectric", &p).and_then(|s| s.build()) {
                Ok(_) => panic!("{p} accepted"),
                Err(e) => e.to_string(),
            }
        };
        let e = err(json!({"eta": 1.0}));
        assert!(e.contains("eta") && e.contains("no interface"), "{e}");
        for eta in [0.0, -1.5] {
            let e = err(json!({"eta": eta}));
            assert!(e.contains("eta"), "{e}");
        }
        // α = 0 is refused (the smooth limit is the `glass` model).
        let e = err(json!({"alpha": 0.0}));
        assert!(e.contains("alpha"), "{e}");
        // And by the constructor itself, whatever the declaration allows.
        let t = Rgb::ONE;
        let g = Geometry::Smith;
        assert!(RoughDielectric::new(Distribution::Ggx, 0.1, 0.1, 1.0, g, t).is_err());
        assert!(RoughDielectric::new(Distribution::Ggx, 0.1, 0.1, 0.0, g, t).is_err());
        assert!(RoughDielectric::new(Distribution::Ggx, 0.1, 0.1, f64::NAN, g, t).is_err());
        assert!(RoughDielectric::new(Distribution::Ggx, 0.0, 0.1, 1.5, g, t).is_err());
        assert!(RoughDielectric::new(Distribution::Blinn, 0.1, 0.1, 1.5, g, t).is_err());
        // Light exactly at 90°: f = 0, no sample, density 0, never NaN.
        for p in [
            json!({"alpha": 0.001, "eta": 1.5}),
            json!({"alpha": 2.0, "eta": 0.01, "distribution": "beckmann",
                   "geometry": "smith-correlated"}),
        ] {
            let b = model(p);
            let horizon = DVec3::new(0.6, 0.8, 0.0);
            for other in [DVec3::Z, -DVec3::Z, dir(0.3, 1.0), dir(-0.3, 1.0), horizon] {
                for (wi, wo) in [(horizon, other), (other, horizon)] {
                    assert_eq!(b.eval(wi, wo), Rgb::ZERO);
                    assert_eq!(b.pdf(wi, wo), 0.0);
                }
            }
            assert!(b.sample(horizon, DVec2::new(0.3, 0.7)).is_none());
            // Nearly grazing: finite and non-negative.
            let g = dir(1e-9, 0.2);
            for other in [dir(0.5, 3.0), dir(-0.5, 3.0), frame::reflect(g), -g] {
                let f = b.eval(g, other);
                assert!(f.is_finite() && f.min_element() >= 0.0, "{f}");
                assert!(b.pdf(g, other).is_finite());
            }
        }
    }

    #[test]
    fn claims_and_terms() {
        let b = model(json!({"alpha_x": 0.2, "alpha_y": 0.3}));
        let c = b.claims();
        assert!(c.reciprocal && c.energy_conserving && !c.isotropic);
        assert!(b.transmits() && b.deltas(DVec3::Z).is_empty());
        assert_eq!(b.interface_eta(), Some(1.5));
        assert!(b.batch_kernel().is_some() && b.ndf().is_some());
        assert!(model(json!({"alpha": 0.2})).claims().isotropic);
        let t = b.microfacet_terms().unwrap();
        assert_eq!(t.distribution, "GGX");
        // Tint scales both lobes.
        let tinted = model(json!({"tint": [0.5, 1.0, 0.25]}));
        let plain = model(json!({}));
        let (wi, wo) = (dir(0.8, 0.1), dir(-0.7, 3.0));
        let (a, p) = (tinted.eval(wi, wo), plain.eval(wi, wo));
        assert!(p.x > 0.0 && (a - p * Rgb::new(0.5, 1.0, 0.25)).abs().max_element() < 1e-15);
    }
}
