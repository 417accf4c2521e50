//! Microfacet theory: normal distributions D,
//! Smith's Λ, the masking-shadowing terms G and the sampling of microfacet
//! normals, shared by `cook-torrance` and `disney`.
//!
//! All of it works in the local frame (normal +z, tangent +x). `alpha_x`,
//! `alpha_y` are the roughnesses along the tangent and the bitangent. Every D is
//! normalised so that `∫ D(h) cosθh dω_h = 1` over the upper hemisphere.

use crate::batch::lanes::{LaneMask, Lanes};
use crate::batch::math;
use crate::quadrature::{gauss_legendre, integrate};
use crate::{BvError, Ndf, Result};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_1_PI, PI};

/// √π.
const SQRT_PI: f64 = 1.772_453_850_905_516;

/// Projected roughness α(w) along the azimuth of `w`:
/// `√(cos²φ αx² + sin²φ αy²)` (Heitz 2014, "Understanding the masking-shadowing
/// function", §5.3: masking is stretch-invariant, so the anisotropic Λ is the
/// isotropic one with this α). On the normal, where φ is undefined, `αx`.
pub fn projected_alpha(w: DVec3, ax: f64, ay: f64) -> f64 {
    let s2 = w.x * w.x + w.y * w.y;
    if s2 <= 0.0 {
        return ax;
    }
    ((w.x * w.x * ax * ax + w.y * w.y * ay * ay) / s2).sqrt()
}

/// `α(w)² tan²θ = (wx² αx² + wy² αy²)/wz²`, the one combination of `w` that
/// Smith's Λ depends on (+∞ at and below the horizon).
#[inline]
fn alpha2_tan2(w: DVec3, ax: f64, ay: f64) -> f64 {
    if w.z <= 0.0 {
        return f64::INFINITY;
    }
    let num = w.x * w.x * ax * ax + w.y * w.y * ay * ay;
    num / (w.z * w.z)
}

/// Anisotropic Beckmann distribution (Walter et al. 2007, eq. 33, with the
/// anisotropic exponent of Ward 1992):
/// `exp(−tan²θh (cos²φh/αx² + sin²φh/αy²)) / (π αx αy cos⁴θh)`, 0 below the horizon.
pub fn beckmann_d(h: DVec3, ax: f64, ay: f64) -> f64 {
    beckmann_d_inv(h, 1.0 / ax, 1.0 / ay)
}

/// [`beckmann_d`] from the reciprocal roughnesses `1/αx`, `1/αy` (precomputed
/// by [`Scale`]): one division where the quotients take four, the same
/// value to rounding.
pub fn beckmann_d_inv(h: DVec3, inv_ax: f64, inv_ay: f64) -> f64 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let z2 = h.z * h.z;
    let (x, y) = (h.x * inv_ax, h.y * inv_ay);
    let q = 1.0 / z2;
    let e = (x * x + y * y) * q;
    if e > 700.0 {
        // exp underflows long before cos⁴ does: avoid 0 · ∞ near the horizon.
        return 0.0;
    }
    (-e).exp() * (inv_ax * inv_ay * FRAC_1_PI) * (q * q)
}

/// Anisotropic GGX / Trowbridge-Reitz distribution (Walter et al. 2007, eq. 33;
/// Burley 2012, GTR2 anisotropic):
/// `1 / (π αx αy cos⁴θh (1 + tan²θh (cos²φh/αx² + sin²φh/αy²))²)`, written as
/// `1 / (π αx αy (hx²/αx² + hy²/αy² + hz²)²)` to stay finite at the horizon.
pub fn ggx_d(h: DVec3, ax: f64, ay: f64) -> f64 {
    ggx_d_inv(h, 1.0 / ax, 1.0 / ay)
}

/// [`ggx_d`] from the reciprocal roughnesses `1/αx`, `1/αy` (precomputed by
/// [`Scale`], which saves the divisions on the evaluation hot path).
#[inline]
pub fn ggx_d_inv(h: DVec3, inv_ax: f64, inv_ay: f64) -> f64 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let (x, y) = (h.x * inv_ax, h.y * inv_ay);
    let t = x * x + y * y + h.z * h.z;
    inv_ax * inv_ay * FRAC_1_PI / (t * t)
}

/// Smith's Λ for Beckmann in terms of `a = 1/(α(w) tanθ)` (Walter et al. 2007,
/// after eq. 27; Heitz 2014 eq. 80): `(erf(a) − 1)/2 + exp(−a²)/(2a√π)`,
/// evaluated as `(exp(−a²)/(a√π) − erfc(a))/2` to avoid `erf(a) − 1`. Λ → ∞ as
/// `a → 0` (grazing) and → 0 as `a → ∞` (normal).
pub fn beckmann_lambda_a(a: f64) -> f64 {
    if a.is_nan() || a <= 0.0 {
        return f64::INFINITY;
    }
    if a > 26.0 {
        // exp(−676) < 1e-293: Λ has underflowed.
        return 0.0;
    }
    let l = 0.5 * ((-a * a).exp() / (a * SQRT_PI) - libm::erfc(a));
    l.max(0.0)
}

/// Smith's Λ of the anisotropic Beckmann distribution for direction `w`
/// (`a = 1/(α(w) tanθ)`); +∞ at and below the horizon, 0 on the normal.
pub fn beckmann_lambda(w: DVec3, ax: f64, ay: f64) -> f64 {
    let t = alpha2_tan2(w, ax, ay);
    if t == 0.0 {
        return 0.0;
    }
    beckmann_lambda_a(1.0 / t.sqrt())
}

/// Smith's Λ of the anisotropic GGX distribution (Walter et al. 2007, eq. 34;
/// Heitz 2014 eq. 86): `(−1 + √(1 + α(w)² tan²θ))/2`, evaluated as
/// `t/(2(1 + √(1 + t)))` to keep its accuracy near the normal.
pub fn ggx_lambda(w: DVec3, ax: f64, ay: f64) -> f64 {
    let t = alpha2_tan2(w, ax, ay);
    if !t.is_finite() {
        return f64::INFINITY;
    }
    t / (2.0 * (1.0 + (1.0 + t).sqrt()))
}

/// Cook & Torrance's v-groove masking-shadowing (Cook & Torrance 1982, eq. in
/// §"Geometrical attenuation"; Blinn 1977):
/// `min(1, 2(n·h)(n·wo)/(wo·h), 2(n·h)(n·wi)/(wo·h))`. 0 when a direction is
/// below the horizon or sees the back of the facet.
pub fn v_groove_g(wi: DVec3, wo: DVec3, h: DVec3) -> f64 {
    let oh = wo.dot(h);
    if wi.z <= 0.0 || wo.z <= 0.0 || oh <= 0.0 || h.z <= 0.0 {
        return 0.0;
    }
    let k = 2.0 * h.z / oh;
    1.0f64.min(k * wo.z).min(k * wi.z)
}

/// One V-groove of the Torrance–Sparrow surface seen in the plane of
/// incidence, for drawing what [`v_groove_g`] counts: the groove whose
/// facets have the half vector of `(wi, wo)` as normal, and how much of that
/// facet (from its rim down) is lit and how much is seen.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VGrooveSection {
    /// The facets' tilt from the normal, radians, signed in the plane:
    /// positive when the reflecting facet faces the light's azimuth (the
    /// facet of the groove that descends towards +u, `u` the plane's unit
    /// horizontal direction towards the light).
    pub tilt: f64,
    /// The lit fraction of the reflecting facet, `min(1, 2(n·h)(n·wi)/(wi·h))`.
    pub lit: f64,
    /// The seen fraction, `min(1, 2(n·h)(n·wo)/(wo·h))`.
    pub seen: f64,
    /// Lit and seen: `min(lit, seen)`, [`v_groove_g`]. Both parts start at
    /// the rim (the other facet hides the bottom of this one), so one holds
    /// the other.
    pub g: f64,
}

/// The V-groove section for `wi`, `wo` (both above the surface) in the plane
/// of incidence whose horizontal direction is `u` (unit, z = 0); `None`
/// when a direction is at or below the horizon or they are opposite.
pub fn v_groove_section(wi: DVec3, wo: DVec3, u: DVec3) -> Option<VGrooveSection> {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return None;
    }
    let h = (wi + wo).try_normalize()?;
    let c = wi.dot(h);
    if c <= 0.0 || h.z <= 0.0 {
        return None;
    }
    let k = 2.0 * h.z / c;
    let (lit, seen) = ((k * wi.z).min(1.0), (k * wo.z).min(1.0));
    Some(VGrooveSection {
        tilt: h.dot(u).atan2(h.z),
        lit,
        seen,
        g: lit.min(seen),
    })
}

/// The kinks of [`v_groove_g`] for light from `wi` (see [`crate::Kink`]):
/// where either shadowing term reaches 1 and where the two swap (`θo = θi`).
///
/// The first two are linear in `h`, so only its direction matters for
/// their sign: they take the unnormalised `wi + wo`, which saves the
/// quadrature a square root and a division per look at them.
pub fn v_groove_kinks(wi: DVec3) -> Vec<crate::Kink<'static>> {
    vec![
        Box::new(move |wo: DVec3| {
            let h = wi + wo;
            2.0 * h.z * wo.z - wo.dot(h)
        }),
        Box::new(move |wo: DVec3| {
            let h = wi + wo;
            2.0 * h.z * wi.z - wo.dot(h)
        }),
        Box::new(move |wo: DVec3| wo.z - wi.z),
    ]
}

/// The constant `c` of Blinn's distribution `c · exp(−(θh/α)²)` such that
/// `∫ D cosθh dω_h = 1`: `1/c = π ∫₀^{π/2} exp(−θ²/α²) sin 2θ dθ`.
///
/// Computed at construction by composite Gauss–Legendre after substituting
/// `θ = α t` (the integrand then has width ~1 for every α); the range is cut at
/// `t = 9`, where `exp(−81) < 1e-35`. Relative accuracy ~1e-15.
pub fn blinn_normalisation(alpha: f64) -> f64 {
    let gl = gauss_legendre(16);
    let t_max = (PI / (2.0 * alpha)).min(9.0);
    let integral = integrate(
        |t| (-t * t).exp() * (2.0 * alpha * t).sin() * alpha,
        0.0,
        t_max,
        32,
        &gl,
    );
    1.0 / (PI * integral)
}

/// Blinn's distribution `c · exp(−(θh/α)²)` with `c` from
/// [`blinn_normalisation`] (Blinn 1977; Cook & Torrance 1982 eq. in §"D").
pub fn blinn_d(h: DVec3, alpha: f64, c: f64) -> f64 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let theta = (h.x * h.x + h.y * h.y).sqrt().atan2(h.z);
    let e = theta / alpha;
    c * (-e * e).exp()
}

/// Microfacet normal drawn from the Beckmann distribution with density
/// `D(h) cosθh` (solid angle): the slopes of a Beckmann surface are Gaussian
/// with standard deviations `αx/√2`, `αy/√2` (Walter et al. 2007, eqs. 28-29),
/// and `D cosθh dω = P22(slope) d(slope)`.
pub fn sample_beckmann(ax: f64, ay: f64, u: DVec2) -> DVec3 {
    let r = (-(1.0 - u.x).ln()).sqrt();
    let (s, c) = (2.0 * PI * u.y).sin_cos();
    let (sx, sy) = (ax * r * c, ay * r * s);
    DVec3::new(-sx, -sy, 1.0).normalize()
}

/// Density of [`sample_beckmann`]: `D(h) cosθh`.
pub fn sample_beckmann_pdf(h: DVec3, ax: f64, ay: f64) -> f64 {
    beckmann_d(h, ax, ay) * h.z.max(0.0)
}

/// A microfacet normal for Blinn's distribution: θh from the truncated
/// Rayleigh density `∝ θ exp(−θ²/α²)` on [0, π/2] (inverted in closed form),
/// φh uniform. Its solid-angle density ([`sample_blinn_pdf`]) differs from
/// `D cosθh` only by the bounded factor `cosθ sinθ/θ`, so importance weights
/// stay bounded (unlike Beckmann's sampler, whose tail near the horizon is far
/// lighter than Blinn's).
pub fn sample_blinn(alpha: f64, u: DVec2) -> DVec3 {
    // 1 − E with E = exp(−(π/2)²/α²), the mass the truncation removes.
    let one_minus_e = -(-(PI * PI) / (4.0 * alpha * alpha)).exp_m1();
    let theta = (alpha * (-(-u.x * one_minus_e).ln_1p()).sqrt()).min(PI / 2.0);
    crate::frame::from_spherical(theta, 2.0 * PI * u.y)
}

/// Density of [`sample_blinn`]: `θ exp(−θ²/α²) / (π α² (1 − E) sinθ)` per
/// steradian (θ/sinθ → 1 on the normal).
pub fn sample_blinn_pdf(h: DVec3, alpha: f64) -> f64 {
    if h.z <= 0.0 {
        return 0.0;
    }
    let s = (h.x * h.x + h.y * h.y).sqrt();
    let theta = s.atan2(h.z);
    let ratio = if s < 1e-8 { 1.0 } else { theta / s };
    let one_minus_e = -(-(PI * PI) / (4.0 * alpha * alpha)).exp_m1();
    let e = theta / alpha;
    ratio * (-e * e).exp() / (PI * alpha * alpha * one_minus_e)
}

/// A GGX microfacet normal drawn from the distribution of normals visible from
/// `w` (Heitz 2018, "Sampling the GGX Distribution of Visible Normals", JCGT 7(4),
/// listing 1). `w.z` must be positive.
pub fn sample_ggx_vndf(w: DVec3, ax: f64, ay: f64, u: DVec2) -> DVec3 {
    // Stretch the view vector to the hemisphere configuration (α = 1).
    let vh = DVec3::new(ax * w.x, ay * w.y, w.z.max(1e-300)).normalize();
    let lensq = vh.x * vh.x + vh.y * vh.y;
    let t1 = if lensq > 0.0 {
        DVec3::new(-vh.y, vh.x, 0.0) / lensq.sqrt()
    } else {
        DVec3::X
    };
    let t2 = vh.cross(t1);
    // Uniform point on the disc, warped onto the projected visible half-disc.
    let r = u.x.sqrt();
    let (sp, cp) = (2.0 * PI * u.y).sin_cos();
    let p1 = r * cp;
    let mut p2 = r * sp;
    let s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * (1.0 - p1 * p1).max(0.0).sqrt() + s * p2;
    let nh = p1 * t1 + p2 * t2 + (1.0 - p1 * p1 - p2 * p2).max(0.0).sqrt() * vh;
    // Unstretch.
    DVec3::new(ax * nh.x, ay * nh.y, nh.z.max(0.0)).normalize()
}

/// Density of [`sample_ggx_vndf`] at `h` (Heitz 2018 eq. 1 / Heitz 2014 eq. 38):
/// `G1(w) max(0, w·h) D(h) / cosθw`.
pub fn ggx_vndf_pdf(w: DVec3, h: DVec3, ax: f64, ay: f64) -> f64 {
    if w.z <= 0.0 {
        return 0.0;
    }
    let wh = w.dot(h);
    if wh <= 0.0 {
        return 0.0;
    }
    let g1 = 1.0 / (1.0 + ggx_lambda(w, ax, ay));
    g1 * wh * ggx_d(h, ax, ay) / w.z
}

/// Which normal distribution D a microfacet model uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Distribution {
    /// Beckmann (Gaussian slopes).
    Beckmann,
    /// Blinn's Gaussian in θh (isotropic), normalised numerically.
    Blinn,
    /// GGX / Trowbridge-Reitz.
    Ggx,
}

/// Names of the distributions, as the `distribution` parameter takes them.
pub const DISTRIBUTION_OPTIONS: &[&str] = &["beckmann", "blinn", "ggx"];

impl Distribution {
    /// The distribution named `name` (one of [`DISTRIBUTION_OPTIONS`]).
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "beckmann" => Ok(Distribution::Beckmann),
            "blinn" => Ok(Distribution::Blinn),
            "ggx" => Ok(Distribution::Ggx),
            other => Err(BvError::BadValue {
                param: "distribution".to_string(),
                reason: format!(
                    "`{other}` is not one of {}",
                    DISTRIBUTION_OPTIONS.join(", ")
                ),
            }),
        }
    }
}

/// Which masking-shadowing term G a microfacet model uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Geometry {
    /// Cook-Torrance v-groove.
    VGroove,
    /// Separable Smith `G1(wi) G1(wo)`.
    Smith,
    /// Height-correlated Smith `1/(1 + Λ(wi) + Λ(wo))`.
    SmithCorrelated,
}

/// Names of the geometry terms, as the `geometry` parameter takes them.
pub const GEOMETRY_OPTIONS: &[&str] = &["v-groove", "smith", "smith-correlated"];

impl Geometry {
    /// The term named `name` (one of [`GEOMETRY_OPTIONS`]).
    pub fn from_name(name: &str) -> Result<Self> {
        match name {
            "v-groove" => Ok(Geometry::VGroove),
            "smith" => Ok(Geometry::Smith),
            "smith-correlated" => Ok(Geometry::SmithCorrelated),
            other => Err(BvError::BadValue {
                param: "geometry".to_string(),
                reason: format!("`{other}` is not one of {}", GEOMETRY_OPTIONS.join(", ")),
            }),
        }
    }
}

/// One roughness scale of a distribution.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Scale {
    /// The distribution family.
    pub dist: Distribution,
    /// Roughness along the tangent (Blinn: its only α).
    pub ax: f64,
    /// Roughness along the bitangent (ignored by Blinn).
    pub ay: f64,
    /// Blinn's normalisation constant (unused by the others).
    blinn_c: f64,
    /// `1/αx` and `1/αy`, for the GGX hot path.
    inv_ax: f64,
    inv_ay: f64,
}

impl Scale {
    /// A scale of `dist` with roughnesses `ax`, `ay` (Blinn uses `ax` only).
    pub fn new(dist: Distribution, ax: f64, ay: f64) -> Self {
        let blinn_c = if dist == Distribution::Blinn {
            blinn_normalisation(ax)
        } else {
            0.0
        };
        Self {
            dist,
            ax,
            ay,
            blinn_c,
            inv_ax: 1.0 / ax,
            inv_ay: 1.0 / ay,
        }
    }

    /// D(h).
    pub fn d(&self, h: DVec3) -> f64 {
        match self.dist {
            Distribution::Beckmann => beckmann_d_inv(h, self.inv_ax, self.inv_ay),
            Distribution::Ggx => ggx_d_inv(h, self.inv_ax, self.inv_ay),
            Distribution::Blinn => blinn_d(h, self.ax, self.blinn_c),
        }
    }

    /// Smith's Λ(w); Blinn uses Beckmann's , which is exact only for
    /// Beckmann's slope distribution.
    pub fn lambda(&self, w: DVec3) -> f64 {
        match self.dist {
            Distribution::Beckmann => beckmann_lambda(w, self.ax, self.ay),
            Distribution::Ggx => ggx_lambda(w, self.ax, self.ay),
            Distribution::Blinn => beckmann_lambda(w, self.ax, self.ax),
        }
    }

    /// A microfacet normal for light from `w` (w.z > 0): GGX visible normals;
    /// Beckmann `D cosθh`; Blinn by [`sample_blinn`].
    pub fn sample_h(&self, w: DVec3, u: DVec2) -> DVec3 {
        match self.dist {
            Distribution::Ggx => sample_ggx_vndf(w, self.ax, self.ay, u),
            Distribution::Beckmann => sample_beckmann(self.ax, self.ay, u),
            Distribution::Blinn => sample_blinn(self.ax, u),
        }
    }

    /// Solid-angle density of [`Scale::sample_h`] at `h`.
    pub fn pdf_h(&self, w: DVec3, h: DVec3) -> f64 {
        match self.dist {
            Distribution::Ggx => ggx_vndf_pdf(w, h, self.ax, self.ay),
            Distribution::Beckmann => sample_beckmann_pdf(h, self.ax, self.ay),
            Distribution::Blinn => sample_blinn_pdf(h, self.ax),
        }
    }

    /// Whether D is invariant under rotation about the normal.
    pub fn is_isotropic(&self) -> bool {
        self.dist == Distribution::Blinn || self.ax == self.ay
    }
}

/// A microfacet distribution: one scale, or the seed's two-scale mixture
/// ("bumps on bumps") `D = (1 − w2) D(α) + w2 D(α2)`.
///
/// Smith's Λ is linear in the slope distribution (Heitz 2014, eq. 72:
/// `Λ(ωo) = (1/μ) ∫_μ^∞ (q − μ) P²(q) dq`, with P² the 1D projection of the
/// slope density P²², itself `D cos⁴θh`), so the mixture's Λ is the same mix of
/// the two Λs. G computed from it keeps the masking relation
/// `∫ D(h) G1(w) ⟨w·h⟩ dω_h = cosθw` exactly.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Microfacet {
    /// Primary scale.
    pub first: Scale,
    /// Secondary scale (isotropic α2), used when `w2 > 0`.
    pub second: Scale,
    /// Weight of the secondary scale, in [0, 1].
    pub w2: f64,
}

impl Microfacet {
    /// A single-scale distribution.
    pub fn new(dist: Distribution, ax: f64, ay: f64) -> Self {
        let first = Scale::new(dist, ax, ay);
        Self {
            first,
            second: first,
            w2: 0.0,
        }
    }

    /// The same with a second, isotropic scale `alpha2` of weight `w2` (clamped
    /// to [0, 1]).
    pub fn with_second_scale(mut self, alpha2: f64, w2: f64) -> Self {
        self.w2 = w2.clamp(0.0, 1.0);
        self.second = Scale::new(self.first.dist, alpha2, alpha2);
        self
    }

    /// D(h) of the mixture.
    pub fn d(&self, h: DVec3) -> f64 {
        if self.w2 <= 0.0 {
            self.first.d(h)
        } else {
            (1.0 - self.w2) * self.first.d(h) + self.w2 * self.second.d(h)
        }
    }

    /// Λ(w) of the mixture (the same weighted mix, see the type's doc).
    pub fn lambda(&self, w: DVec3) -> f64 {
        if self.w2 <= 0.0 {
            self.first.lambda(w)
        } else if self.w2 >= 1.0 {
            self.second.lambda(w)
        } else {
            (1.0 - self.w2) * self.first.lambda(w) + self.w2 * self.second.lambda(w)
        }
    }

    /// Smith's masking `G1(w) = 1/(1 + Λ(w))` (0 at and below the horizon).
    pub fn g1(&self, w: DVec3) -> f64 {
        1.0 / (1.0 + self.lambda(w))
    }

    /// The masking-shadowing term `geometry` for the pair (`h` their half vector).
    pub fn g(&self, geometry: Geometry, wi: DVec3, wo: DVec3, h: DVec3) -> f64 {
        match geometry {
            Geometry::VGroove => v_groove_g(wi, wo, h),
            Geometry::Smith => self.g1(wi) * self.g1(wo),
            Geometry::SmithCorrelated => 1.0 / (1.0 + self.lambda(wi) + self.lambda(wo)),
        }
    }

    /// `G / (4 cos θi cos θo)`, the masking term `geometry` over the
    /// microfacet reflection's denominator (Walter et al. 2007, eq. 20), for
    /// `wi`, `wo` above the surface and `h` their unit half vector: one
    /// division where `g(…) / (4 wi.z wo.z)` takes two or more (V-groove:
    /// `min(1, 2 hz wz/(wo·h))` over the denominator is
    /// `min(wo·h, 2 hz wi.z, 2 hz wo.z) / (4 (wo·h) wi.z wo.z)`). The same
    /// value to rounding; 0 where [`Microfacet::g`] is.
    #[inline]
    pub fn g_over_cosines(&self, geometry: Geometry, wi: DVec3, wo: DVec3, h: DVec3) -> f64 {
        let den = 4.0 * wi.z * wo.z;
        match geometry {
            Geometry::VGroove => {
                let oh = wo.dot(h);
                if wi.z <= 0.0 || wo.z <= 0.0 || oh <= 0.0 || h.z <= 0.0 {
                    return 0.0;
                }
                let k = 2.0 * h.z;
                oh.min(k * wo.z).min(k * wi.z) / (oh * den)
            }
            Geometry::Smith => 1.0 / ((1.0 + self.lambda(wi)) * (1.0 + self.lambda(wo)) * den),
            Geometry::SmithCorrelated => 1.0 / ((1.0 + self.lambda(wi) + self.lambda(wo)) * den),
        }
    }

    /// Draws a microfacet normal for light from `w` (w.z > 0): picks a scale by
    /// its weight, then that scale's sampler.
    pub fn sample_h(&self, w: DVec3, u: DVec2) -> DVec3 {
        if self.w2 <= 0.0 {
            return self.first.sample_h(w, u);
        }
        if u.x < self.w2 {
            let ux = (u.x / self.w2).min(ONE_MINUS_EPS);
            self.second.sample_h(w, DVec2::new(ux, u.y))
        } else {
            let ux = ((u.x - self.w2) / (1.0 - self.w2)).min(ONE_MINUS_EPS);
            self.first.sample_h(w, DVec2::new(ux, u.y))
        }
    }

    /// Solid-angle density of [`Microfacet::sample_h`] at `h`.
    pub fn pdf_h(&self, w: DVec3, h: DVec3) -> f64 {
        if self.w2 <= 0.0 {
            self.first.pdf_h(w, h)
        } else {
            (1.0 - self.w2) * self.first.pdf_h(w, h) + self.w2 * self.second.pdf_h(w, h)
        }
    }

    /// Whether D is invariant under rotation about the normal (the second scale
    /// is always isotropic).
    pub fn is_isotropic(&self) -> bool {
        self.first.is_isotropic()
    }
}

impl Ndf for Microfacet {
    fn d(&self, h: DVec3) -> f64 {
        Microfacet::d(self, h)
    }

    fn slopes(&self) -> Option<(Distribution, f64, f64)> {
        let f = &self.first;
        (self.w2 == 0.0 && matches!(f.dist, Distribution::Beckmann | Distribution::Ggx))
            .then_some((f.dist, f.ax, f.ay))
    }
}

/// Largest f64 below 1, to keep remapped uniform numbers in [0, 1).
pub const ONE_MINUS_EPS: f64 = 1.0 - f64::EPSILON / 2.0;

/// Draws `wo` by reflecting `wi` about a microfacet normal drawn from `ndf`;
/// `None` when the reflected direction falls below the horizon.
pub fn sample_reflection(ndf: &Microfacet, wi: DVec3, u: DVec2) -> Option<DVec3> {
    if wi.z <= 0.0 {
        return None;
    }
    let h = ndf.sample_h(wi, u);
    let wo = crate::frame::reflect_about(wi, h);
    (wo.z > 0.0 && wi.dot(h) > 0.0).then_some(wo)
}

/// Density of [`sample_reflection`] at `wo`: `pdf_h(h) / (4 |wo·h|)` (the
/// Jacobian of reflection, Walter et al. 2007 eq. 14).
pub fn sample_reflection_pdf(ndf: &Microfacet, wi: DVec3, wo: DVec3) -> f64 {
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return 0.0;
    }
    let Some(h) = crate::frame::half_vector(wi, wo) else {
        return 0.0;
    };
    let c = wo.dot(h);
    if c <= 0.0 {
        return 0.0;
    }
    ndf.pdf_h(wi, h) / (4.0 * c)
}

/// One roughness scale in f32 lanes, for the batch kernels (see
/// [`crate::batch`]): [`beckmann_d`], [`ggx_d`], [`beckmann_lambda`] and
/// [`ggx_lambda`] ported to f32, and [`blinn_d`] with Beckmann's Λ of its one
/// α (as [`Scale::lambda`] pairs them), the distribution a const parameter
/// ([`ScaleLanes::BECKMANN`], [`ScaleLanes::GGX`] or [`ScaleLanes::BLINN`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ScaleLanes {
    inv_ax2: f32,
    inv_ay2: f32,
    inv_ax: f32,
    inv_ay: f32,
    ax2: f32,
    ay2: f32,
    /// 1/(π αx αy); Blinn: its normalisation constant `c`.
    norm: f32,
}

impl ScaleLanes {
    /// Beckmann.
    pub const BECKMANN: u8 = 0;
    /// GGX.
    pub const GGX: u8 = 1;

    /// Blinn (`exp(−(θh/α)²)`, with Beckmann's Λ).
    pub const BLINN: u8 = 2;

    /// The lane form of `s`, with its const tag. (`Option` for a distribution
    /// that has no lane form; every one has one today.)
    pub fn new(s: &Scale) -> Option<(u8, Self)> {
        let tag = match s.dist {
            Distribution::Beckmann => Self::BECKMANN,
            Distribution::Ggx => Self::GGX,
            Distribution::Blinn => Self::BLINN,
        };
        // Blinn has one α; its Λ is Beckmann's at αx = αy = α.
        let (ax, ay) = if tag == Self::BLINN {
            (s.ax, s.ax)
        } else {
            (s.ax, s.ay)
        };
        let norm = if tag == Self::BLINN {
            s.blinn_c
        } else {
            FRAC_1_PI / (ax * ay)
        };
        Some((
            tag,
            Self {
                inv_ax2: (1.0 / (ax * ax)) as f32,
                inv_ay2: (1.0 / (ay * ay)) as f32,
                inv_ax: (1.0 / ax) as f32,
                inv_ay: (1.0 / ay) as f32,
                ax2: (ax * ax) as f32,
                ay2: (ay * ay) as f32,
                norm: norm as f32,
            },
        ))
    }

    /// D(h) for a unit `h`: [`ScaleLanes::d_of_sum`] with `|h|² = 1`.
    #[inline(always)]
    pub fn d<const DIST: u8, V: Lanes>(&self, h: [V; 3]) -> V {
        self.d_of_sum::<DIST, V>(h, V::splat(1.0))
    }

    /// D(h) at `h = hu/√l2` from the unnormalised half vector `hu = wi + wo`
    /// and `l2 = |hu|²`, without normalising it: Beckmann's tan²θh and
    /// Blinn's θh do not depend on |hu|, Beckmann's 1/cos⁴θh is
    /// `(l2/huz²)²` and GGX's `1/(h·A⁻²h)²` is `l2²/(hu·A⁻²hu)²` (as in
    /// [`ScaleLanes::ggx_dg`]). One division (Beckmann) or none before the
    /// caller's, where [`ScaleLanes::d`] after a normalisation takes three.
    #[inline(always)]
    pub fn d_of_sum<const DIST: u8, V: Lanes>(&self, hu: [V; 3], l2: V) -> V {
        let [x, y, z] = hu;
        let v = if DIST == Self::GGX {
            let (u, v) = (x * self.inv_ax, y * self.inv_ay);
            let t = u * u + v * v + z * z;
            l2 * l2 * self.norm / (t * t)
        } else if DIST == Self::BLINN {
            // As `blinn_d`: θh = atan2(√(x² + y²), z), e = θh/α.
            let theta = math::atan2_first_quadrant((x * x + y * y).sqrt(), z);
            let e = theta * self.inv_ax;
            math::exp(-e * e) * self.norm
        } else {
            let inv_z2 = V::splat(1.0) / (z * z);
            let e = (x * x * self.inv_ax2 + y * y * self.inv_ay2) * inv_z2;
            let r = l2 * inv_z2;
            // exp underflows (f32: e > 87) long before 1/cos⁴ overflows:
            // 0 there avoids 0 · ∞ at the horizon.
            let d = math::exp(-e) * self.norm * (r * r);
            e.gt(V::splat(87.0)).select(V::splat(0.0), d)
        };
        z.gt(V::splat(0.0)).select(v, V::splat(0.0))
    }

    /// GGX's `D(h) G(wi, wo) / (4 cosθi cosθo)` with separable
    /// (`CORRELATED = false`) or height-correlated Smith G, from the
    /// unnormalised half vector `hu = wi + wo` and `l2 = |hu|²`, with a single
    /// division: with `T = hux²/αx² + huy²/αy² + huz²`, `D = l2² / (π αx αy T²)`
    /// (`h = hu/√l2` in [`ggx_d`]), and with `s = √(z² + wx²αx² + wy²αy²)`,
    /// `1 + Λ(w) = (z + s)/(2z)` ([`ggx_lambda`]), so the cosines cancel:
    /// separable `G/(4 zi zo) = 1/((zi + si)(zo + so))`, correlated
    /// `G/(4 zi zo) = 1/(2 (si zo + so zi))`. Both directions must be above
    /// the horizon (the caller masks the others).
    #[inline(always)]
    pub fn ggx_dg<const CORRELATED: bool, V: Lanes>(
        &self,
        wi: [V; 3],
        wo: [V; 3],
        hu: [V; 3],
        l2: V,
    ) -> V {
        let (u, v) = (hu[0] * self.inv_ax, hu[1] * self.inv_ay);
        let t = u * u + v * v + hu[2] * hu[2];
        let (si, so) = (self.ggx_s(wi), self.ggx_s(wo));
        let g = if CORRELATED {
            (si * wo[2] + so * wi[2]) * 2.0
        } else {
            (wi[2] + si) * (wo[2] + so)
        };
        l2 * l2 * self.norm / (t * t * g)
    }

    /// `s = √(z² + wx²αx² + wy²αy²)` of [`ScaleLanes::ggx_dg`].
    #[inline(always)]
    fn ggx_s<V: Lanes>(&self, w: [V; 3]) -> V {
        (w[2] * w[2] + w[0] * w[0] * self.ax2 + w[1] * w[1] * self.ay2).sqrt()
    }

    /// `1 + Λ(w)` (+∞ at and below the horizon): the form every G needs.
    /// GGX's `1 + (−1 + √(1 + t))/2` is `(1 + √(1 + t))/2`.
    #[inline(always)]
    pub fn one_plus_lambda<const DIST: u8, V: Lanes>(&self, w: [V; 3]) -> V {
        let [x, y, z] = w;
        let t = (x * x * self.ax2 + y * y * self.ay2) / (z * z);
        let v = if DIST == Self::GGX {
            ((t + 1.0).sqrt() + 1.0) * 0.5
        } else {
            // beckmann_lambda_a with a = 1/(α tanθ) = 1/√t.
            let a = V::splat(1.0) / t.sqrt();
            let l = (math::exp(-a * a) / (a * SQRT_PI as f32) - math::erfc(a)) * 0.5;
            let l = a
                .gt(V::splat(26.0))
                .select(V::splat(0.0), l.max(V::splat(0.0)));
            t.eq(V::splat(0.0)).select(V::splat(0.0), l) + 1.0
        };
        (z.gt(V::splat(0.0)) & t.lt(V::splat(f32::INFINITY))).select(v, V::splat(f32::INFINITY))
    }
}

#[cfg(test)]
pub(crate) mod tests {
    use super::*;

    #[test]
    fn v_groove_section_is_what_v_groove_g_counts() {
        // In the plane φ = 0.4: G of the section equals v_groove_g, and the
        // lit and seen fractions are the two terms of its min. At the mirror
        // direction the grooves are flat (tilt 0) and everything is lit and
        // seen; towards the light (wo = wi) the facets turn to face it and
        // the partner facet hides all but 2 cos²θi of each.
        let phi: f64 = 0.4;
        let u = DVec3::new(phi.cos(), phi.sin(), 0.0);
        let dir = |t: f64| (u * t.sin() + DVec3::Z * t.cos()).normalize();
        let ti = 80f64.to_radians();
        for k in -17..=17 {
            let to = (k as f64 * 5.0).to_radians();
            let (wi, wo) = (dir(ti), dir(to));
            let s = v_groove_section(wi, wo, u).unwrap();
            let h = (wi + wo).normalize();
            assert!((s.g - v_groove_g(wi, wo, h)).abs() < 1e-12, "{k}");
            assert!(s.lit <= 1.0 && s.seen <= 1.0 && s.g <= s.lit.min(s.seen) + 1e-15);
            // The tilt is the half vector's angle in the plane.
            assert!((s.tilt - (ti + to) / 2.0).abs() < 1e-12, "{k}: {}", s.tilt);
        }
        let mirror = v_groove_section(dir(ti), dir(-ti), u).unwrap();
        assert!(mirror.tilt.abs() < 1e-12 && mirror.g == 1.0);
        let back = v_groove_section(dir(ti), dir(ti), u).unwrap();
        let want = 2.0 * ti.cos() * ti.cos();
        assert!(
            (back.g - want).abs() < 1e-12 && (back.tilt - ti).abs() < 1e-12,
            "{back:?}"
        );
        assert!(v_groove_section(dir(ti), DVec3::new(0.0, 0.0, -1.0), u).is_none());
    }
    use crate::frame::from_spherical;
    use crate::sampling;

    /// `∫ g(θ, φ) sinθ dθ dφ` over the upper hemisphere: composite Gauss–Legendre
    /// in θ on panels graded geometrically towards θ = 0 (so that lobes as narrow
    /// as α = 0.001 are resolved) and towards θ = π/2 (where Beckmann's
    /// `exp(−tan²θ/α²)` is flat but not analytic), and the trapezoid rule in φ (spectrally
    /// accurate for periodic integrands).
    pub(crate) fn hemisphere_integral(g: impl Fn(DVec3) -> f64, n_phi: usize) -> f64 {
        let gl = gauss_legendre(12);
        let mut edges = vec![0.0];
        for k in (1..24).rev() {
            edges.push(PI / 4.0 * 0.5f64.powi(k));
        }
        for k in 0..24 {
            edges.push(PI / 2.0 - PI / 4.0 * 0.5f64.powi(k));
        }
        edges.push(PI / 2.0);
        let mut sum = 0.0;
        for p in 0..n_phi {
            let phi = 2.0 * PI * (p as f64 + 0.5) / n_phi as f64;
            for win in edges.windows(2) {
                sum += integrate(
                    |t| g(from_spherical(t, phi)) * t.sin(),
                    win[0],
                    win[1],
                    1,
                    &gl,
                );
            }
        }
        sum * 2.0 * PI / n_phi as f64
    }

    #[test]
    fn gauss_legendre_is_exact_for_polynomials() {
        let gl = gauss_legendre(8);
        let s: f64 = gl.iter().map(|&(x, w)| w * x.powi(14)).sum();
        assert!((s - 2.0 / 15.0).abs() < 1e-14);
        let s: f64 = gl.iter().map(|&(_, w)| w).sum();
        assert!((s - 2.0).abs() < 1e-14);
    }

    #[test]
    fn erf_reference_values() {
        // Abramowitz & Stegun table 7.1.
        assert!((libm::erf(1.0) - 0.842_700_792_949_714_9).abs() < 1e-15);
        assert!((libm::erf(0.5) - 0.520_499_877_813_046_5).abs() < 1e-15);
        assert!((libm::erfc(3.0) - 2.209_049_699_858_544e-5).abs() < 1e-19);
    }

    #[test]
    fn d_normalisation_by_quadrature() {
        let cases: Vec<Microfacet> = vec![
            Microfacet::new(Distribution::Beckmann, 0.001, 0.001),
            Microfacet::new(Distribution::Beckmann, 0.05, 0.05),
            Microfacet::new(Distribution::Beckmann, 0.3, 0.3),
            Microfacet::new(Distribution::Beckmann, 1.0, 1.0),
            Microfacet::new(Distribution::Beckmann, 2.0, 2.0),
            Microfacet::new(Distribution::Beckmann, 0.1, 0.6),
            Microfacet::new(Distribution::Ggx, 0.001, 0.001),
            Microfacet::new(Distribution::Ggx, 0.05, 0.05),
            Microfacet::new(Distribution::Ggx, 0.3, 0.3),
            Microfacet::new(Distribution::Ggx, 1.0, 1.0),
            Microfacet::new(Distribution::Ggx, 2.0, 2.0),
            Microfacet::new(Distribution::Ggx, 0.6, 0.1),
            Microfacet::new(Distribution::Blinn, 0.001, 0.001),
            Microfacet::new(Distribution::Blinn, 0.05, 0.05),
            Microfacet::new(Distribution::Blinn, 0.3, 0.3),
            Microfacet::new(Distribution::Blinn, 1.0, 1.0),
            Microfacet::new(Distribution::Blinn, 2.0, 2.0),
            Microfacet::new(Distribution::Beckmann, 0.1, 0.3).with_second_scale(0.8, 0.3),
            Microfacet::new(Distribution::Ggx, 0.2, 0.2).with_second_scale(0.02, 0.5),
            Microfacet::new(Distribution::Blinn, 0.2, 0.2).with_second_scale(1.5, 0.7),
        ];
        for m in cases {
            let s = hemisphere_integral(|h| m.d(h) * h.z, 256);
            assert!((s - 1.0).abs() < 1e-3, "{m:?}: ∫D cos = {s}");
        }
    }

    /// Unit directions above the surface, a spiral from the normal to within
    /// 1e-3 of the horizon.
    fn upper_dirs(n: usize) -> Vec<DVec3> {
        (0..n)
            .map(|k| {
                let z = 1.0 - (1.0 - 1e-3) * k as f64 / (n - 1) as f64;
                let r = (1.0 - z * z).sqrt();
                let phi = 2.399_963 * k as f64;
                DVec3::new(r * phi.cos(), r * phi.sin(), z)
            })
            .collect()
    }

    #[test]
    fn g_over_cosines_is_g_over_the_denominator() {
        // The one-division form against `g(…) / (4 wi.z wo.z)` (each
        // geometry's own formula), every distribution, anisotropic and
        // mixed, over pairs from the normal to near grazing.
        let ndfs = [
            Microfacet::new(Distribution::Beckmann, 0.1, 0.6),
            Microfacet::new(Distribution::Ggx, 0.3, 0.3),
            Microfacet::new(Distribution::Blinn, 0.5, 0.5),
            Microfacet::new(Distribution::Ggx, 0.2, 0.7).with_second_scale(0.05, 0.4),
        ];
        let dirs = upper_dirs(40);
        for m in ndfs {
            for geometry in [
                Geometry::VGroove,
                Geometry::Smith,
                Geometry::SmithCorrelated,
            ] {
                for &wi in &dirs {
                    for &wo in &dirs {
                        let Some(h) = crate::frame::half_vector(wi, wo) else {
                            continue;
                        };
                        let want = m.g(geometry, wi, wo, h) / (4.0 * wi.z * wo.z);
                        let got = m.g_over_cosines(geometry, wi, wo, h);
                        assert!(
                            (got - want).abs() <= 1e-13 * want.abs(),
                            "{m:?} {geometry:?} {wi} {wo}: {got:e} vs {want:e}"
                        );
                    }
                }
            }
        }
        // Zero where G is: a half vector the outgoing direction sees from
        // behind.
        let (wi, wo) = (DVec3::Z, DVec3::new(0.6, 0.0, 0.8));
        let back = DVec3::new(-0.8, 0.0, 0.6);
        let m = Microfacet::new(Distribution::Ggx, 0.3, 0.3);
        assert_eq!(m.g_over_cosines(Geometry::VGroove, wi, wo, back), 0.0);
    }

    #[test]
    fn beckmann_d_from_reciprocals_is_beckmann_d() {
        for (ax, ay) in [(0.3, 0.3), (0.1, 0.6), (1.5, 0.02)] {
            let s = Scale::new(Distribution::Beckmann, ax, ay);
            for h in upper_dirs(200) {
                let (got, want) = (s.d(h), beckmann_d(h, ax, ay));
                // exp(−e) carries e's rounding (a few ulp of e) into its
                // relative error: 1e-13 at e ≈ 430, near the horizon.
                let e = ((h.x / ax).powi(2) + (h.y / ay).powi(2)) / (h.z * h.z);
                assert!(
                    (got - want).abs() <= 1e-15 * (8.0 + 4.0 * e) * want,
                    "α ({ax}, {ay}) h {h}: {got:e} vs {want:e}"
                );
            }
            // At the normal: 1/(π αx αy) (Walter et al. 2007, eq. 25).
            assert!((s.d(DVec3::Z) * PI * ax * ay - 1.0).abs() < 1e-15);
            assert_eq!(s.d(DVec3::new(1.0, 0.0, 0.0)), 0.0);
        }
    }

    #[test]
    fn blinn_constant_small_alpha_series() {
        // 1/c = π ∫ e^{−θ²/α²} sin2θ dθ; expanding sin2θ = 2θ − 4θ³/3 + 4θ⁵/15 − …
        // and ∫₀^∞ θ^{2k+1} e^{−θ²/α²} dθ = k! α^{2k+2}/2 gives
        // 1/c = π (α² − 2α⁴/3 + 4α⁶/15 − …).
        for alpha in [0.1, 0.03, 0.001] {
            let a2: f64 = alpha * alpha;
            let want = 1.0 / (PI * (a2 - 2.0 * a2 * a2 / 3.0 + 4.0 * a2 * a2 * a2 / 15.0));
            let c = blinn_normalisation(alpha);
            assert!((c / want - 1.0).abs() < 1e-7, "α {alpha}: {c} vs {want}");
        }
    }

    #[test]
    fn d_at_normal_is_one_over_pi_alpha2() {
        // tanθh = 0: exp(0)/(π αx αy) for Beckmann, 1/(π αx αy) for GGX.
        assert!((beckmann_d(DVec3::Z, 0.2, 0.5) - 1.0 / (PI * 0.1)).abs() < 1e-12);
        assert!((ggx_d(DVec3::Z, 0.2, 0.5) - 1.0 / (PI * 0.1)).abs() < 1e-12);
        // At θh = 45°, φh = 0 (tan² = 1): Beckmann e^{−1/αx²}/(π αx αy /4),
        // GGX 4/(π αx αy (1 + 1/αx²)²).
        let h = from_spherical(PI / 4.0, 0.0);
        let (ax, ay) = (0.5f64, 0.25f64);
        let b = (-1.0 / (ax * ax)).exp() * 4.0 / (PI * ax * ay);
        assert!((beckmann_d(h, ax, ay) / b - 1.0).abs() < 1e-12);
        let g = 4.0 / (PI * ax * ay * (1.0 + 1.0 / (ax * ax)).powi(2));
        assert!((ggx_d(h, ax, ay) / g - 1.0).abs() < 1e-12);
        // Grazing half vectors stay finite.
        for d in [
            Distribution::Beckmann,
            Distribution::Ggx,
            Distribution::Blinn,
        ] {
            let m = Microfacet::new(d, 0.001, 0.001);
            let v = m.d(DVec3::new(1.0, 0.0, 1e-300).normalize());
            assert!(v.is_finite() && v >= 0.0);
        }
    }

    #[test]
    fn smith_g1_limits() {
        for d in [
            Distribution::Beckmann,
            Distribution::Ggx,
            Distribution::Blinn,
        ] {
            let m = Microfacet::new(d, 0.3, 0.7);
            assert_eq!(m.g1(DVec3::Z), 1.0);
            // G1 = 1/(1 + Λ).
            let w = from_spherical(1.1, 0.4);
            assert!((m.g1(w) - 1.0 / (1.0 + m.lambda(w))).abs() < 1e-15);
            // Grazing: G1 → 0.
            assert!(m.g1(DVec3::new(1.0, 0.0, 1e-9).normalize()) < 1e-6);
            assert_eq!(m.g1(DVec3::new(1.0, 0.0, -0.1).normalize()), 0.0);
        }
        // Beckmann Λ → 0 as a → ∞ (asymptotically e^{−a²}/(4a³√π)).
        for a in [5.0f64, 10.0, 20.0] {
            let l = beckmann_lambda_a(a);
            let asym = (-a * a).exp() / (4.0 * a.powi(3) * SQRT_PI);
            assert!(l >= 0.0 && l < 2.0 * asym, "a {a}: {l}");
        }
        assert_eq!(beckmann_lambda_a(100.0), 0.0);
        // a = 1: (erf 1 − 1)/2 + e^{−1}/(2√π) with erf 1 = 0.8427007929497149.
        let want = (0.842_700_792_949_714_9 - 1.0) / 2.0 + (-1.0f64).exp() / (2.0 * SQRT_PI);
        assert!((beckmann_lambda_a(1.0) - want).abs() < 1e-15);
        // GGX: θ = 45°, α = 1: (−1 + √2)/2.
        let w = from_spherical(PI / 4.0, 0.0);
        assert!((ggx_lambda(w, 1.0, 1.0) - (2f64.sqrt() - 1.0) / 2.0).abs() < 1e-15);
    }

    /// Λ from its definition (Smith 1967; Heitz 2014 eq. 72):
    /// `Λ = (1/μ) ∫_μ^∞ (q − μ) P²(q) dq`, μ = cotθ, with P²(q) the density of
    /// the slope component along w's azimuth, obtained here by integrating the
    /// anisotropic slope density `P²²(x, y) = D(h) cos⁴θh` over the
    /// perpendicular slope numerically (so the projected-α formula is checked
    /// too). Slopes are substituted `q = μ + tan s`, `r = tan t` so that GGX's
    /// heavy tails are integrated exactly.
    fn lambda_from_definition(d: impl Fn(DVec3) -> f64, w: DVec3) -> f64 {
        let s = (w.x * w.x + w.y * w.y).sqrt();
        let mu = w.z / s;
        let (e, p) = (
            DVec3::new(w.x / s, w.y / s, 0.0),
            DVec3::new(-w.y / s, w.x / s, 0.0),
        );
        let p22 = |x: f64, y: f64| {
            // Slope (x, y) ↔ normal (−x, −y, 1)/√(1 + x² + y²); P22 = D cos⁴.
            let n = DVec3::new(-x, -y, 1.0);
            let c = 1.0 / n.length();
            d(n * c) * c.powi(4)
        };
        let gl = gauss_legendre(20);
        let outer = |sv: f64| {
            let q = mu + sv.tan();
            let jq = 1.0 / sv.cos().powi(2);
            let inner = integrate(
                |t| {
                    let r = t.tan();
                    let slope = e * q + p * r;
                    p22(slope.x, slope.y) / t.cos().powi(2)
                },
                -PI / 2.0 + 1e-9,
                PI / 2.0 - 1e-9,
                40,
                &gl,
            );
            (q - mu) * inner * jq
        };
        integrate(outer, 0.0, PI / 2.0 - 1e-9, 40, &gl) / mu
    }

    #[test]
    fn lambda_matches_its_definition() {
        for (ax, ay) in [(0.3, 0.3), (0.2, 0.6), (1.0, 0.5)] {
            for (th, ph) in [(0.5, 0.3), (1.0, 1.2), (1.3, 2.5)] {
                let w = from_spherical(th, ph);
                let b = lambda_from_definition(|h| beckmann_d(h, ax, ay), w);
                let bl = beckmann_lambda(w, ax, ay);
                assert!(
                    (b - bl).abs() < 1e-6 * (1.0 + bl),
                    "B {ax} {ay} {th}: {b} vs {bl}"
                );
                let g = lambda_from_definition(|h| ggx_d(h, ax, ay), w);
                let gl = ggx_lambda(w, ax, ay);
                assert!(
                    (g - gl).abs() < 5e-4 * (1.0 + gl),
                    "G {ax} {ay} {th}: {g} vs {gl}"
                );
            }
        }
    }

    #[test]
    fn masking_relation_holds_for_smith_and_the_mixture() {
        // Projected area (Heitz 2014 eq. 2): ∫ D(h) G1(w) max(0, w·h) dω_h = cosθw.
        let cases = [
            Microfacet::new(Distribution::Beckmann, 0.3, 0.3),
            Microfacet::new(Distribution::Beckmann, 0.2, 0.7),
            Microfacet::new(Distribution::Ggx, 0.5, 0.5),
            Microfacet::new(Distribution::Ggx, 0.6, 0.15),
            Microfacet::new(Distribution::Ggx, 0.1, 0.1).with_second_scale(0.9, 0.4),
            Microfacet::new(Distribution::Beckmann, 0.4, 0.1).with_second_scale(1.2, 0.6),
        ];
        for m in cases {
            for (th, ph) in [(0.0, 0.0), (0.7, 0.5), (1.3, 2.0), (1.5, -1.0)] {
                let w = from_spherical(th, ph);
                let g1 = m.g1(w);
                let s = hemisphere_integral(|h| m.d(h) * w.dot(h).max(0.0), 1024) * g1;
                assert!(
                    (s - w.z).abs() < 2e-3 * w.z.max(0.05),
                    "{m:?} θ {th}: {s} vs {}",
                    w.z
                );
            }
        }
    }

    #[test]
    fn v_cavity_masking_relation_holds_for_every_d() {
        // ∫ D(h) G1v(w, h) ⟨w·h⟩ dω_h = cosθw with G1v = min(1, 2 hz wz/(w·h))
        // (Heitz 2014 §5.2), for each D, anisotropic ones included: the basis of
        // cook-torrance's energy claim with the v-groove G.
        let cases = [
            Microfacet::new(Distribution::Beckmann, 0.5, 0.5),
            Microfacet::new(Distribution::Ggx, 1.0, 0.2),
            Microfacet::new(Distribution::Blinn, 1.0, 1.0),
            Microfacet::new(Distribution::Beckmann, 2.0, 0.3).with_second_scale(0.1, 0.5),
        ];
        for m in cases {
            for (th, ph) in [(0.5, 0.0), (1.3, 0.7), (1.5, 1.2)] {
                let w = from_spherical(th, ph);
                let s = hemisphere_integral(
                    |h| {
                        let wh = w.dot(h);
                        if wh <= 0.0 {
                            0.0
                        } else {
                            m.d(h) * wh * 1f64.min(2.0 * h.z * w.z / wh)
                        }
                    },
                    1024,
                );
                assert!((s / w.z - 1.0).abs() < 1e-4, "{m:?} θ {th}: {}", s / w.z);
            }
        }
        // Blinn's D with Beckmann's Λ (bv's pairing) breaks the Smith relation.
        let m = Microfacet::new(Distribution::Blinn, 1.0, 1.0);
        let w = from_spherical(1.3, 0.0);
        let s = hemisphere_integral(|h| m.d(h) * w.dot(h).max(0.0), 1024) * m.g1(w);
        assert!(s / w.z > 1.03, "{}", s / w.z);
    }

    #[test]
    fn sampled_normals_match_their_pdf() {
        // ∫ pdf_h dω = 1 by quadrature, and E[g(h)/pdf(h)] = ∫ g dω by Monte Carlo
        // for g = D(h) cosθh on the normals facing w (the only ones visible-normal
        // sampling draws), with ∫ g by quadrature.
        let cases = [
            Microfacet::new(Distribution::Beckmann, 0.3, 0.6),
            Microfacet::new(Distribution::Blinn, 0.4, 0.4),
            Microfacet::new(Distribution::Ggx, 0.5, 0.2),
            Microfacet::new(Distribution::Ggx, 0.1, 0.1).with_second_scale(0.9, 0.4),
        ];
        let mut rng = sampling::rng(11);
        for m in cases {
            for th in [0.2, 1.0, 1.45] {
                let w = from_spherical(th, 0.7);
                let total = hemisphere_integral(|h| m.pdf_h(w, h), 256);
                assert!((total - 1.0).abs() < 2e-3, "{m:?} θ {th}: ∫pdf = {total}");
                let g = |h: DVec3| if w.dot(h) > 0.0 { m.d(h) * h.z } else { 0.0 };
                let want = hemisphere_integral(g, 1024);
                let n = 100_000;
                let mut sum = 0.0;
                for _ in 0..n {
                    let h = m.sample_h(w, sampling::uniform2(&mut rng));
                    let p = m.pdf_h(w, h);
                    assert!(p > 0.0 && (h.length() - 1.0).abs() < 1e-12);
                    sum += g(h) / p;
                }
                let est = sum / n as f64;
                assert!(
                    (est - want).abs() < 0.02,
                    "{m:?} θ {th}: E = {est} vs {want}"
                );
            }
        }
    }
}
