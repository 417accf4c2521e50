//! Cook-Torrance: a Lambertian base plus a microfacet specular lobe,
//! `f = kd/π + ks · F(wi·h) D(h) G(wi, wo) / (4 cosθi cosθo)` (Cook & Torrance
//! 1982, eq. in §"The reflectance model"; Walter et al. 2007, eq. 20), with the
//! choices of D, G and F of `crate::microfacet` and `crate::fresnel`, and
//! optionally Kulla & Conty's (2017) compensation for the energy the
//! single-scattering lobe loses (`multiscatter = kulla-conty`,
//! `crate::multiscatter`): `+ ks F_ms (1 − E(μi)) (1 − E(μo)) / (π (1 − E_avg))`.

use crate::batch::{self, Dirs, Isa, Kernel, LaneMask, Lanes, Out, math};
use crate::fresnel::{self, Fresnel, FresnelLanes};
use crate::microfacet::{
    self, DISTRIBUTION_OPTIONS, Distribution, GEOMETRY_OPTIONS, Geometry, Microfacet, ScaleLanes,
};
use crate::model::{ALPHA_ALIAS, Build, GpuBlob, GpuPort, GpuTables, ModelInfo, TABLE_ALIGN};
use crate::multiscatter::{self, HARMONICS, HarmonicRows, KullaConty, TABLE_LEN};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::{ModelSpec, Params};
use crate::{Brdf, Claims, FresnelTerm, MicrofacetTerms, Ndf, Result, Rgb, mean_rgb, sampling};
use glam::{DVec2, DVec3};
use std::f64::consts::FRAC_1_PI;
use std::sync::Arc;

/// Roughness range and slider span shared by `alpha_x`, `alpha_y`, `alpha2`.
const ALPHA: FloatSpec = FloatSpec::log(0.001, 2.0, 0.3, 0.005, 1.0);

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "kd",
        label: "kd",
        doc: "Diffuse reflectance (Lambertian base kd/π)",
        kind: ParamKind::Color(ColorSpec::unit_range([0.3, 0.3, 0.3])),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "ks",
        label: "ks",
        doc: "Weight of the specular microfacet lobe",
        kind: ParamKind::Float(FloatSpec::linear(0.0, 1.0, 0.7)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "distribution",
        label: "D",
        doc: "Microfacet distribution: Beckmann, Blinn (Gaussian in θh, isotropic) or GGX",
        kind: ParamKind::Choice {
            options: DISTRIBUTION_OPTIONS,
            default: "beckmann",
        },
        applies: Applies::Always,
    },
    ParamDecl {
        id: "alpha_x",
        label: "α x",
        doc: "Roughness along the tangent (RMS slope for Beckmann; Blinn's only width)",
        kind: ParamKind::Float(ALPHA),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "alpha_y",
        label: "α y",
        doc: "Roughness along the bitangent (ignored by Blinn)",
        kind: ParamKind::Float(ALPHA),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "geometry",
        label: "G",
        doc: "Masking-shadowing: Cook-Torrance v-groove, separable Smith, height-correlated Smith",
        kind: ParamKind::Choice {
            options: GEOMETRY_OPTIONS,
            default: "v-groove",
        },
        applies: Applies::Always,
    },
    fresnel::fresnel_param("dielectric"),
    fresnel::ETA,
    fresnel::K,
    fresnel::F0,
    ParamDecl {
        id: "alpha2",
        label: "α2",
        doc: "Roughness of the second (isotropic) scale of the multiscale mixture",
        kind: ParamKind::Float(FloatSpec::log(0.001, 2.0, 0.05, 0.005, 1.0)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "weight2",
        label: "w2",
        doc: "Weight of the second scale: D = (1 − w2) D(α) + w2 D(α2); 0 = off",
        kind: ParamKind::Float(FloatSpec::linear(0.0, 1.0, 0.0)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "multiscatter",
        label: "multiple scattering",
        doc: "Energy lost to light bouncing between facets: none (single scattering, \
              darker at high α) or Kulla & Conty 2017's compensation lobe",
        kind: ParamKind::Choice {
            options: MULTISCATTER_OPTIONS,
            default: "none",
        },
        applies: Applies::Positive { param: "ks" },
    },
];

/// The choices of `multiscatter`.
pub const MULTISCATTER_OPTIONS: &[&str] = &["none", "kulla-conty"];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "cook-torrance",
    name: "Cook-Torrance",
    summary: "Microfacet specular (choice of D, G, F) over a Lambertian base",
    citation: "Cook & Torrance 1982; Walter et al. 2007 (GGX, Smith G); Heitz 2014 (masking)",
    params: PARAMS,
    aliases: &[ALPHA_ALIAS],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::cook_torrance",
            "shaders/models/cook_torrance.wgsl",
            include_str!("../../../../shaders/models/cook_torrance.wgsl"),
        )
        .with_sampling_lobe()
        .with_derived(DERIVED_SLOTS, derive_slots),
    ),
};

/// Derived GPU slots (read by `shaders/models/cook_torrance.wgsl`): Blinn's
/// normalisation constant for `alpha_x` and for `alpha2`, 0 unless the
/// distribution is `blinn` (each costs a quadrature, done once here rather
/// than per shaded pixel); then Kulla–Conty's colour `F_ms / (π (1 − E_avg))`
/// (0 with `multiscatter = none`) and its table of the loss 1 − E
/// ([`TABLE_LEN`] entries uniform in √μ, `crate::multiscatter`); then, for
/// an anisotropic lobe, where its azimuthal harmonics' rows sit in the table
/// buffer (in units of [`TABLE_ALIGN`] floats) and how many there are (0:
/// none, the lobe is isotropic).
const DERIVED_SLOTS: &[&str] = &[
    "blinn_norm",
    "blinn_norm2",
    "ms_r",
    "ms_g",
    "ms_b",
    "ms_l0",
    "ms_l1",
    "ms_l2",
    "ms_l3",
    "ms_l4",
    "ms_l5",
    "ms_l6",
    "ms_l7",
    "ms_l8",
    "ms_l9",
    "ms_l10",
    "ms_l11",
    "ms_l12",
    "ms_l13",
    "ms_l14",
    "ms_l15",
    "ms_l16",
    "ms_l17",
    "ms_l18",
    "ms_l19",
    "ms_l20",
    "ms_l21",
    "ms_l22",
    "ms_l23",
    "ms_l24",
    "ms_l25",
    "ms_l26",
    "ms_l27",
    "ms_l28",
    "ms_l29",
    "ms_l30",
    "ms_l31",
    "ms_harmonics",
    "ms_n_harmonics",
];

// The slot list spells the table out: keep it the table's length.
const _: () = assert!(DERIVED_SLOTS.len() == 7 + TABLE_LEN);

fn derive_slots(spec: &ModelSpec, tables: &mut dyn GpuTables) -> Result<Vec<f32>> {
    let p = spec.params();
    let mut v = if p.text("distribution")? == "blinn" {
        vec![
            microfacet::blinn_normalisation(p.float("alpha_x")?) as f32,
            microfacet::blinn_normalisation(p.float("alpha2")?) as f32,
        ]
    } else {
        vec![0.0, 0.0]
    };
    let parts = Parts::from_params(p)?;
    // The same (cached) table as the built model's.
    match parts.multiscatter() {
        Some(ms) => {
            v.extend([ms.scale.x as f32, ms.scale.y as f32, ms.scale.z as f32]);
            v.extend(ms.loss_f32());
            match ms.harmonic_loss_f32() {
                Some(rows) => {
                    let blob: Arc<dyn GpuBlob> = rows;
                    let at = tables.offset_of(blob) / TABLE_ALIGN;
                    v.extend([at as f32, (HARMONICS - 1) as f32]);
                }
                None => v.extend([0.0, 0.0]),
            }
        }
        None => v.extend([0.0; 5 + TABLE_LEN]),
    }
    Ok(v)
}

/// The choices a Cook-Torrance model is built from (shared by [`build`] and
/// the GPU port's derived slots, so that both see the same table).
struct Parts {
    kd: Rgb,
    ks: f64,
    ndf: Microfacet,
    geometry: Geometry,
    fresnel: Fresnel,
    kulla_conty: bool,
}

impl Parts {
    fn from_params(p: &Params) -> Result<Self> {
        let dist = Distribution::from_name(p.text("distribution")?)?;
        let ndf = Microfacet::new(dist, p.float("alpha_x")?, p.float("alpha_y")?)
            .with_second_scale(p.float("alpha2")?, p.float("weight2")?);
        Ok(Self {
            kd: p.color("kd")?,
            ks: p.float("ks")?,
            ndf,
            geometry: Geometry::from_name(p.text("geometry")?)?,
            fresnel: Fresnel::from_params(p)?,
            kulla_conty: match p.text("multiscatter")? {
                "kulla-conty" => true,
                "none" => false,
                other => {
                    return Err(crate::BvError::BadValue {
                        param: "multiscatter".to_string(),
                        reason: format!(
                            "`{other}` is not one of {}",
                            MULTISCATTER_OPTIONS.join(", ")
                        ),
                    });
                }
            },
        })
    }

    /// The compensation lobe, when chosen and the specular lobe has weight.
    fn multiscatter(&self) -> Option<KullaConty> {
        (self.kulla_conty && self.ks > 0.0)
            .then(|| KullaConty::new(&self.ndf, self.geometry, &self.fresnel))
    }
}

/// The Cook-Torrance model with its D, G and F.
#[derive(Debug, Clone)]
pub struct CookTorrance {
    /// kd/π.
    diffuse: Rgb,
    kd: Rgb,
    ks: f64,
    ndf: Microfacet,
    geometry: Geometry,
    fresnel: Fresnel,
    /// Kulla & Conty's multiple-scattering lobe, when chosen (and ks > 0).
    multiscatter: Option<KullaConty>,
    /// Probability of drawing the cosine lobe (diffuse and multiple
    /// scattering) in [`Brdf::sample`].
    p_diffuse: f64,
    /// The f32 batch kernel.
    kernel: Option<CtKernel>,
}

impl CookTorrance {
    /// A Cook-Torrance model from its parts (single scattering).
    pub fn new(kd: Rgb, ks: f64, ndf: Microfacet, geometry: Geometry, fresnel: Fresnel) -> Self {
        Self::from_parts(Parts {
            kd,
            ks,
            ndf,
            geometry,
            fresnel,
            kulla_conty: false,
        })
    }

    fn from_parts(parts: Parts) -> Self {
        let multiscatter = parts.multiscatter();
        let Parts {
            kd,
            ks,
            ndf,
            geometry,
            fresnel,
            ..
        } = parts;
        // Sample the lobes in proportion to their (upper bounds on) albedo;
        // the multiple-scattering lobe is cosine-like (its μo dependence is
        // 1 − E(μo), flat but for grazing angles), so the cosine strategy
        // draws it with the diffuse part.
        let wd = mean_rgb(kd).max(0.0);
        let wd = match &multiscatter {
            Some(ms) => wd + ks * ms.weight(),
            None => wd,
        };
        let ws = ks.max(0.0);
        let p_diffuse = if wd + ws > 0.0 { wd / (wd + ws) } else { 1.0 };
        Self {
            diffuse: kd * FRAC_1_PI,
            kd,
            ks,
            ndf,
            geometry,
            fresnel,
            kernel: CtKernel::new(
                kd * FRAC_1_PI,
                ks,
                &ndf,
                geometry,
                &fresnel,
                multiscatter.as_ref(),
            ),
            multiscatter,
            p_diffuse,
        }
    }

    /// Kulla & Conty's compensation term `F_ms f_ms(μi, μo)` (without ks),
    /// zero without `multiscatter = kulla-conty`.
    pub fn multiple(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.multiscatter
            .as_ref()
            .map_or(Rgb::ZERO, |ms| ms.eval(wi, wo))
    }

    /// The specular term alone, `F D G / (4 cosθi cosθo)` (without ks).
    pub fn specular(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let Some(h) = crate::frame::half_vector(wi, wo) else {
            return Rgb::ZERO;
        };
        self.specular_at(wi, wo, h)
    }

    /// [`CookTorrance::specular`] given the unit half vector `h` of the pair
    /// (both above the surface): the one formula of the lobe, which
    /// [`Brdf::eval_with_half`] reaches without normalising `wi + wo` again.
    #[inline]
    fn specular_at(&self, wi: DVec3, wo: DVec3, h: DVec3) -> Rgb {
        let d = self.ndf.d(h);
        if d == 0.0 {
            return Rgb::ZERO;
        }
        let scalar = d * self.ndf.g_over_cosines(self.geometry, wi, wo, h);
        if !scalar.is_finite() {
            return Rgb::ZERO;
        }
        self.fresnel.eval(wi.dot(h)) * scalar
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(CookTorrance::from_parts(Parts::from_params(p)?)))
}

impl Brdf for CookTorrance {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn microfacet_terms(&self) -> Option<MicrofacetTerms> {
        let (ndf, geometry) = (self.ndf, self.geometry);
        Some(MicrofacetTerms {
            distribution: match ndf.first.dist {
                Distribution::Beckmann => "Beckmann",
                Distribution::Blinn => "Blinn",
                Distribution::Ggx => "GGX",
            }
            .to_string()
                + if ndf.w2 > 0.0 { " (two scales)" } else { "" },
            geometry: match geometry {
                Geometry::VGroove => "v-groove (Cook & Torrance 1982)",
                Geometry::Smith => "separable Smith",
                Geometry::SmithCorrelated => "height-correlated Smith",
            }
            .to_string(),
            d: Arc::new(move |h| ndf.d(h)),
            g1: Arc::new(move |w| if w.z > 0.0 { ndf.g1(w) } else { 0.0 }),
            g2: Arc::new(move |wi, wo, h| ndf.g(geometry, wi, wo, h)),
        })
    }

    fn fresnel_term(&self) -> Option<FresnelTerm> {
        Some(FresnelTerm {
            fresnel: self.fresnel,
            source: format!("fresnel = {}", self.fresnel.kind_name()),
        })
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        match &self.multiscatter {
            None => self.diffuse + self.ks * self.specular(wi, wo),
            Some(ms) => self.diffuse + self.ks * (self.specular(wi, wo) + ms.eval(wi, wo)),
        }
    }

    fn eval_with_half(&self, wi: DVec3, wo: DVec3, h: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let specular = self.specular_at(wi, wo, h);
        match &self.multiscatter {
            None => self.diffuse + self.ks * specular,
            Some(ms) => self.diffuse + self.ks * (specular + ms.eval(wi, wo)),
        }
    }

    fn furnace(&self) -> Option<Box<dyn Brdf>> {
        // The white furnace: the same D, G, roughness and multiple-scattering
        // choice, F = 1, no diffuse base, full weight.
        Some(Box::new(Self::from_parts(Parts {
            kd: Rgb::ZERO,
            ks: 1.0,
            ndf: self.ndf,
            geometry: self.geometry,
            fresnel: Fresnel::None,
            kulla_conty: self.multiscatter.is_some(),
        })))
    }

    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        if self.geometry == Geometry::VGroove && self.ks != 0.0 {
            crate::microfacet::v_groove_kinks(wi)
        } else {
            Vec::new()
        }
    }

    fn claims(&self) -> Claims {
        // Energy. Changing variables dωo = 4 (wo·h) dω_h, the specular albedo is
        // ρs(wi) = ∫ F D G (wi·h)/cosθi dω_h (over the h that reflect wi above the
        // horizon). If G ≤ G1(wi) for a G1 obeying the masking relation
        // ∫ D(h) G1(wi, h) ⟨wi·h⟩ dω_h = cosθi (Heitz 2014, eq. 2), then ρs ≤ 1
        // because F ≤ 1 for every Fresnel choice; the diffuse albedo is kd, so
        // ρ ≤ max(kd) + ks.
        // - smith, smith-correlated with Beckmann or GGX (and their mixtures, Λ
        //   being linear in D): Λ is the exact Smith Λ of D, which satisfies the
        //   masking relation (Heitz 2014, §4), and 1/(1 + Λi + Λo) ≤ G1(wi).
        // - v-groove, any of the three D: G = min(G1v(wi), G1v(wo)) with
        //   G1v(w) = min(1, 2 hz wz/(w·h)) (wi·h = wo·h). Writing
        //   min(w·h, 2 hz wz) = w·h − max(0, −w·h*) with h* = (−hx, −hy, hz) and
        //   using D(h*) = D(h) (true of all three D), the masking integral becomes
        //   ∫ D (w·h) dω_h = wz: the V-cavity G1 satisfies the relation exactly for
        //   every D (Heitz 2014, §5.2: "the V-cavity masking function is exact";
        //   checked by quadrature in `microfacet::tests`).
        // - blinn with smith or smith-correlated: bv pairs Blinn's D with
        //   Beckmann's Λ, which is the Λ of Beckmann's slopes, not Blinn's; the
        //   masking relation fails (∫ D G1 ⟨wi·h⟩ exceeds cosθi by up to ~6 % at
        //   α = 1) and the albedo does exceed 1 (test below), so no claim.
        // - multiscatter = kulla-conty adds ks F_ms (1 − E(μi)) (1 − E(μo)) /
        //   (π (1 − E_avg)), whose albedo is ks F_ms (1 − E(μi)) exactly (the
        //   μo integral of 1 − E is π (1 − E_avg)). The specular albedo becomes
        //   E_F(μi) + F_ms (1 − E(μi)) ≤ E(μi) + (1 − E(μi)) = 1, as
        //   E_F ≤ E (F ≤ 1) and F_ms ≤ 1 (F_avg² E_avg ≤ 1 − F_avg (1 − E_avg)
        //   for F_avg, E_avg in [0, 1]); with F = 1 it is 1 at every θi (up
        //   to the table's accuracy, 1e-3; `crate::multiscatter`). E is
        //   clamped to ≤ 1, so Blinn with Smith (E > 1 at grazing) stays
        //   without a claim as before. With αx ≠ αy the table holds E's
        //   cosine series in 2φ (`crate::multiscatter`): within 1e-3 at
        //   αx/αy up to 4 (`tests/kulla_conty.rs`), but the range allows
        //   αx/αy = 2000, where eight harmonics cannot follow E's azimuthal
        //   spike: no claim for an anisotropic lobe. The table's error (below
        //   1e-3, `crate::multiscatter`) can put ρhd a few 1e-4 above 1 at
        //   ks = 1, F = 1, so the claim keeps that margin: kd + ks (1 + 1e-3) ≤ 1.
        let blinn_smith = self.ndf.first.dist == Distribution::Blinn
            && matches!(self.geometry, Geometry::Smith | Geometry::SmithCorrelated);
        let azimuth_mean = self.multiscatter.is_some() && !self.ndf.is_isotropic();
        let provable = !blinn_smith && !azimuth_mean;
        Claims {
            // D, G (both Smith forms, and v-groove with wi·h = wo·h), F(wi·h) and
            // the cosines are all symmetric in (wi, wo).
            reciprocal: true,
            energy_conserving: provable
                && self.kd.max_element()
                    + self.ks
                        * if self.multiscatter.is_some() {
                            1.0 + 1e-3
                        } else {
                            1.0
                        }
                    <= 1.0,
            isotropic: self.ndf.is_isotropic(),
        }
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z <= 0.0 {
            return None;
        }
        if u.x < self.p_diffuse {
            let ux = (u.x / self.p_diffuse).min(microfacet::ONE_MINUS_EPS);
            Some(sampling::cosine_hemisphere(DVec2::new(ux, u.y)))
        } else {
            let ux =
                ((u.x - self.p_diffuse) / (1.0 - self.p_diffuse)).min(microfacet::ONE_MINUS_EPS);
            microfacet::sample_reflection(&self.ndf, wi, DVec2::new(ux, u.y))
        }
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let mut p = self.p_diffuse * sampling::cosine_hemisphere_pdf(wo);
        if self.p_diffuse < 1.0 {
            p += (1.0 - self.p_diffuse) * microfacet::sample_reflection_pdf(&self.ndf, wi, wo);
        }
        p
    }

    fn ndf(&self) -> Option<&dyn Ndf> {
        Some(&self.ndf)
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        self.kernel.as_ref().map(|k| k as &dyn Kernel)
    }
}

/// [`CookTorrance::eval`] in f32 lanes: the same `kd/π + ks F D G / (4 cosθi
/// cosθo)` with the lane forms of D, Λ and F. Each combination of D (Beckmann,
/// GGX), G, F and mixture on/off is its own monomorphised loop ([`CtLane`]),
/// so the lane code has no branch on the model's choices. The 90 loops are
/// five kernel types, one per Fresnel term, each in a module of its own
/// (`fresnel_kernels!`).
#[derive(Debug, Clone)]
struct CtKernel {
    diffuse: [f32; 3],
    ks: f32,
    dist: u8,
    first: ScaleLanes,
    second: ScaleLanes,
    /// Weight of the second scale, strictly inside (0, 1) when `mix`.
    w2: f32,
    mix: bool,
    geometry: u8,
    fresnel: FresnelLanes,
    /// Kulla–Conty, when chosen: `ks F_ms / (π (1 − E_avg))` per channel,
    /// the table of the mean loss 1 − E and, for an anisotropic lobe, its
    /// harmonics' rows (`crate::multiscatter`).
    multiscatter: Option<MsLanes>,
}

/// Kulla–Conty in the kernel: the colour, the mean loss table and the
/// harmonics' rows (see [`CtKernel::multiscatter`]).
type MsLanes = ([f32; 3], [f32; TABLE_LEN], Option<Arc<HarmonicRows>>);

const VGROOVE: u8 = 0;
const SMITH: u8 = 1;
const CORRELATED: u8 = 2;

impl CtKernel {
    fn new(
        diffuse: Rgb,
        ks: f64,
        ndf: &Microfacet,
        geometry: Geometry,
        fresnel: &Fresnel,
        multiscatter: Option<&KullaConty>,
    ) -> Option<Self> {
        let (dist, first) = ScaleLanes::new(&ndf.first)?;
        let (_, second) = ScaleLanes::new(&ndf.second)?;
        // w2 = 1 is the second scale alone (as `Microfacet::lambda` treats it):
        // a mixture weight of exactly 0 would multiply the first scale's
        // infinite Λ at the horizon into NaN.
        let (first, mix) = if ndf.w2 >= 1.0 {
            (second, false)
        } else {
            (first, ndf.w2 > 0.0)
        };
        Some(Self {
            diffuse: [diffuse.x as f32, diffuse.y as f32, diffuse.z as f32],
            ks: ks as f32,
            dist,
            first,
            second,
            w2: ndf.w2 as f32,
            mix,
            geometry: match geometry {
                Geometry::VGroove => VGROOVE,
                Geometry::Smith => SMITH,
                Geometry::SmithCorrelated => CORRELATED,
            },
            fresnel: FresnelLanes::new(fresnel),
            multiscatter: multiscatter.map(|ms| {
                let c = ms.scale * ks;
                (
                    [c.x as f32, c.y as f32, c.z as f32],
                    ms.loss_f32(),
                    ms.harmonic_loss_f32(),
                )
            }),
        })
    }
}

/// `1 − E(ω)` per lane from the loss tables (`multiscatter::loss_dir_f32`,
/// the WGSL port's arithmetic): lanes have no gather, so through a scalar
/// loop over the stored lanes.
#[inline(always)]
fn loss_lanes<V: Lanes>(mean: &[f32; TABLE_LEN], harmonics: Option<&[f32]>, w: [V; 3]) -> V {
    const MAX_LANES: usize = 64;
    let n = V::LANES.min(MAX_LANES);
    let mut buf = [[0.0f32; MAX_LANES]; 3];
    for (b, c) in buf.iter_mut().zip(w) {
        c.store(&mut b[..n]);
    }
    let mut out = [0.0f32; MAX_LANES];
    for (i, o) in out[..n].iter_mut().enumerate() {
        *o = multiscatter::loss_dir_f32(mean, harmonics, [buf[0][i], buf[1][i], buf[2][i]]);
    }
    V::load(&out[..n])
}

/// One monomorphised combination of [`CtKernel`]'s choices.
#[derive(Debug)]
struct CtLane<'a, const D: u8, const G: u8, const F: u8, const MIX: bool>(&'a CtKernel);

impl<const D: u8, const G: u8, const F: u8, const MIX: bool> CtLane<'_, D, G, F, MIX> {
    /// `1 + Λ(w)` of the distribution, or of the mixture of two scales.
    #[inline(always)]
    fn one_plus_lambda<V: Lanes>(&self, w: [V; 3]) -> V {
        let k = self.0;
        if MIX {
            k.first.one_plus_lambda::<D, V>(w) * (1.0 - k.w2)
                + k.second.one_plus_lambda::<D, V>(w) * k.w2
        } else {
            k.first.one_plus_lambda::<D, V>(w)
        }
    }
}

impl<const D: u8, const G: u8, const F: u8, const MIX: bool> CtLane<'_, D, G, F, MIX> {
    /// [`crate::batch::LaneKernel::lane`] of this combination.
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let k = self.0;
        let zero = V::splat(0.0);
        let above = wi[2].gt(zero) & wo[2].gt(zero);
        // The unnormalised half vector wi + wo and its squared length.
        let hu = math::add3(wi, wo);
        let l2 = math::dot(hu, hu);
        let finite_h = l2.gt(V::splat(1e-24)) & l2.lt(V::splat(f32::INFINITY));
        let (scalar, cos_d) = if D == ScaleLanes::GGX && !MIX && G != VGROOVE {
            // The common GGX-Smith case with one division for D G/(4 cos cos),
            // which needs only wi + wo, not the unit half vector. Fresnel's
            // cos θd = wi·h = (1 + wi·wo)/|wi + wo| is |wi + wo|/2 for unit
            // wi and wo (|wi + wo|² = 2 + 2 wi·wo): one square root and no
            // division, where normalising h took a square root, a division
            // and a dot product.
            let dg = if G == CORRELATED {
                k.first.ggx_dg::<true, V>(wi, wo, hu, l2)
            } else {
                k.first.ggx_dg::<false, V>(wi, wo, hu, l2)
            };
            (dg, l2.sqrt() * 0.5)
        } else {
            // No unit half vector either: D from wi + wo itself
            // (`ScaleLanes::d_of_sum`), V-groove's `2 (n·h)(n·w)/(wo·h)` as
            // `2 huz w.z / (wo·hu)`, its `min(1, ·)` taken over `wo·hu` and
            // divided out with the cosines, and Fresnel's cos θd as
            // wi·hu/|hu|: one square root and two or three divisions, where
            // normalising h and the separate quotients of D, G and the
            // cosines took a square root and five. (|hu|/2, as above, moves
            // F by 1e-4 near wo = −wi with a large η, where f32's |w|² ≠ 1
            // is a percent of the small l2.)
            let w1 = 1.0 - k.w2;
            let d = if MIX {
                k.first.d_of_sum::<D, V>(hu, l2) * w1 + k.second.d_of_sum::<D, V>(hu, l2) * k.w2
            } else {
                k.first.d_of_sum::<D, V>(hu, l2)
            };
            let cosines = wi[2] * wo[2] * 4.0;
            let scalar = match G {
                VGROOVE => {
                    // wo·hu, not l2/2 (equal for unit vectors): near
                    // wo = −wi, where l2 is small, f32's |w|² ≠ 1 would
                    // move l2/2 by a percent.
                    let ohu = math::dot(wo, hu);
                    let t = hu[2] * 2.0;
                    let g_ohu = ohu.min(t * wo[2]).min(t * wi[2]);
                    (ohu.gt(zero) & hu[2].gt(zero)).select(d * g_ohu / (ohu * cosines), zero)
                }
                SMITH => d / (self.one_plus_lambda(wi) * self.one_plus_lambda(wo) * cosines),
                _ => d / ((self.one_plus_lambda(wi) + self.one_plus_lambda(wo) - 1.0) * cosines),
            };
            (scalar, math::dot(wi, hu) / l2.sqrt())
        };
        let ok = above & finite_h & scalar.is_finite();
        let scalar = ok.select(scalar * k.ks, zero);
        let fr = k.fresnel.eval::<F, V>(cos_d);
        match &k.multiscatter {
            // Kulla–Conty's lobe (see `crate::multiscatter`): a branch on the
            // model's choice, the same for every lane.
            Some((c, loss, harmonics)) => {
                let h = harmonics.as_deref().map(GpuBlob::gpu_data);
                let m = loss_lanes(loss, h, wi) * loss_lanes(loss, h, wo);
                math::channels!(|ch| above.select(fr[ch] * scalar + k.diffuse[ch] + m * c[ch], zero))
            }
            None => math::channels!(|c| above.select(fr[c] * scalar + k.diffuse[c], zero)),
        }
    }
}

/// The kernel types of [`CtLane`]: one per Fresnel term, each in a module
/// of its own, generic over D, G and the mixture. rustc puts a kernel's
/// instruction-set loops (`batch`'s `IsaLoops`) in the codegen unit of its
/// type's module, so the 90 combinations are five units that LLVM optimises
/// side by side; as one type they were one unit, the longest of the core's
/// build, on one core. The code is the same.
macro_rules! fresnel_kernels {
    ($($m:ident: $f:ident,)*) => {$(
        mod $m {
            use super::{CtKernel, CtLane};
            use crate::batch::{LaneKernel, Lanes};
            use crate::fresnel::FresnelLanes;

            /// [`CtLane`] with this module's Fresnel term.
            #[derive(Debug)]
            pub(super) struct Lane<'a, const D: u8, const G: u8, const MIX: bool>(
                pub(super) &'a CtKernel,
            );

            impl<const D: u8, const G: u8, const MIX: bool> LaneKernel for Lane<'_, D, G, MIX> {
                #[inline(always)]
                fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
                    CtLane::<D, G, { FresnelLanes::$f }, MIX>(self.0).lane(wi, wo)
                }
            }
        }
    )*};
}

fresnel_kernels! {
    f_none: NONE,
    f_dielectric: DIELECTRIC,
    f_dielectric_grey: DIELECTRIC_GREY,
    f_conductor: CONDUCTOR,
    f_schlick: SCHLICK,
}

impl Kernel for CtKernel {
    fn eval(&self, isa: Isa, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        macro_rules! go {
            ($d:expr, $g:expr, $f:ident) => {
                if self.mix {
                    batch::run(&$f::Lane::<$d, $g, true>(self), isa, dirs, out)
                } else {
                    batch::run(&$f::Lane::<$d, $g, false>(self), isa, dirs, out)
                }
            };
            ($d:expr, $g:expr) => {
                match self.fresnel.kind {
                    FresnelLanes::DIELECTRIC => go!($d, $g, f_dielectric),
                    FresnelLanes::DIELECTRIC_GREY => go!($d, $g, f_dielectric_grey),
                    FresnelLanes::CONDUCTOR => go!($d, $g, f_conductor),
                    FresnelLanes::SCHLICK => go!($d, $g, f_schlick),
                    _ => go!($d, $g, f_none),
                }
            };
            ($d:expr) => {
                match self.geometry {
                    VGROOVE => go!($d, VGROOVE),
                    SMITH => go!($d, SMITH),
                    _ => go!($d, CORRELATED),
                }
            };
        }
        match self.dist {
            ScaleLanes::GGX => go!({ ScaleLanes::GGX }),
            ScaleLanes::BLINN => go!({ ScaleLanes::BLINN }),
            _ => go!({ ScaleLanes::BECKMANN }),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;

    #[test]
    fn eval_with_half_is_eval() {
        // The albedo quadrature's path (h given, wo = 2 (wi·h) h − wi, not
        // normalised) against `eval` of the same pair, for every D, G and
        // F and with the multiple-scattering lobe.
        let specs = [
            json!({}),
            json!({"distribution": "ggx", "geometry": "smith", "fresnel": "conductor",
                    "alpha_x": 0.2, "alpha_y": 0.5}),
            json!({"distribution": "blinn", "geometry": "smith-correlated", "fresnel": "schlick"}),
            json!({"distribution": "beckmann", "multiscatter": "kulla-conty", "weight2": 0.3}),
        ];
        for spec in specs {
            let b = ModelSpec::from_json("cook-torrance", &spec)
                .unwrap()
                .build()
                .unwrap();
            let mut checked = 0;
            for i in 0..12 {
                let wi = from_spherical(0.05 + 1.5 * i as f64 / 12.0, 0.3);
                for k in 0..400 {
                    let th = 1.5 * (k / 20) as f64 / 20.0;
                    let ph = 0.3 + std::f64::consts::TAU * (k % 20) as f64 / 20.0;
                    let h = from_spherical(th, ph);
                    let wo = 2.0 * wi.dot(h) * h - wi;
                    if wo.z <= 0.0 || wi.dot(h) <= 0.0 {
                        continue;
                    }
                    let (got, want) = (b.eval_with_half(wi, wo, h), b.eval(wi, wo));
                    let scale = want.abs().max_element();
                    assert!(
                        (got - want).abs().max_element() <= 1e-12 * scale,
                        "{spec}: wi {wi} wo {wo}: {got} vs {want}"
                    );
                    checked += 1;
                }
            }
            assert!(checked > 2000, "{checked}");
            // Below the horizon: 0, as `eval`.
            let (wi, wo) = (from_spherical(0.3, 0.0), DVec3::new(0.6, 0.0, -0.8));
            let h = (wi + wo).normalize();
            assert_eq!(b.eval_with_half(wi, wo, h), Rgb::ZERO);
        }
    }

    #[test]
    fn microfacet_terms_are_the_models_own() {
        let a = 0.3;
        let b = ModelSpec::from_json(
            "cook-torrance",
            &json!({"alpha": a, "distribution": "ggx", "geometry": "smith-correlated",
                    "fresnel": "none", "kd": 0.0, "ks": 1.0}),
        )
        .unwrap()
        .build()
        .unwrap();
        let t = b.microfacet_terms().unwrap();
        assert_eq!(t.distribution, "GGX");
        assert_eq!(t.geometry, "height-correlated Smith");
        // GGX at the normal: D = 1/(π α²) (Walter et al. 2007, eq. 33).
        assert!(((t.d)(DVec3::Z) - 1.0 / (PI * a * a)).abs() < 1e-12);
        // No masking seen straight down; none below the horizon.
        assert!(((t.g1)(DVec3::Z) - 1.0).abs() < 1e-15);
        assert_eq!((t.g1)(DVec3::new(1.0, 0.0, -0.1).normalize()), 0.0);
        // f = D G2 / (4 cos θi cos θo) with F = 1 and ks = 1 (Walter eq. 20).
        let wi = from_spherical(0.7, 0.3);
        let wo = from_spherical(0.4, 2.9);
        let h = (wi + wo).normalize();
        let want = (t.d)(h) * (t.g2)(wi, wo, h) / (4.0 * wi.z * wo.z);
        assert!((b.eval(wi, wo).x - want).abs() < 1e-12 * want.max(1.0));
        // Models that are not microfacet models have none.
        let l = ModelSpec::new("lambert").unwrap().build().unwrap();
        assert!(l.microfacet_terms().is_none());
    }
    use crate::frame::from_spherical;
    use crate::microfacet::tests::hemisphere_integral;
    use proptest::prelude::*;
    use serde_json::{Value, json};
    use std::f64::consts::PI;

    fn model(params: Value) -> Box<dyn Brdf> {
        ModelSpec::from_json("cook-torrance", &params)
            .unwrap()
            .build()
            .unwrap()
    }

    #[test]
    fn furnace_is_the_lobe_with_f_one_and_no_diffuse() {
        // The hook the albedo view's furnace switch calls: the same D, G, α
        // and multiple-scattering choice, F = 1, kd = 0, ks = 1.
        for ms in MULTISCATTER_OPTIONS {
            let b = model(
                json!({"kd": [0.3, 0.2, 0.1], "ks": 0.6, "distribution": "ggx",
                "alpha_x": 0.5, "alpha_y": 0.5, "geometry": "smith", "fresnel": "conductor",
                "multiscatter": ms}),
            );
            let want = model(json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx",
                "alpha_x": 0.5, "alpha_y": 0.5, "geometry": "smith", "fresnel": "none",
                "multiscatter": ms}));
            let f = b.furnace().unwrap();
            for (wi, wo) in [
                (from_spherical(0.2, 0.1), from_spherical(1.1, 2.9)),
                (from_spherical(1.4, -0.4), from_spherical(0.6, 1.7)),
            ] {
                assert_eq!(f.eval(wi, wo), want.eval(wi, wo), "{ms}");
            }
            assert_eq!(f.pdf(DVec3::Z, DVec3::Z), want.pdf(DVec3::Z, DVec3::Z));
        }
        let l = ModelSpec::new("lambert").unwrap().build().unwrap();
        assert!(l.furnace().is_none());
    }

    #[test]
    fn multiscatter_none_is_the_default_and_applies_only_with_ks() {
        let d = ModelSpec::new("cook-torrance").unwrap();
        assert_eq!(d.params().text("multiscatter").unwrap(), "none");
        let decl = INFO.param("multiscatter").unwrap();
        assert!(decl.applies_to(d.params()));
        let mut off = d.clone();
        off.set("ks", crate::ParamValue::Float(0.0)).unwrap();
        assert!(!decl.applies_to(off.params()));
        assert_eq!(decl.applies_text().unwrap(), "ks > 0");
    }

    #[test]
    fn normal_incidence_hand_value() {
        // wi = wo = n: h = n, D = 1/(π αx αy) (Beckmann and GGX), F = F(0),
        // G = 1 for every geometry; f = kd/π + ks F(0) / (4π αx αy).
        for dist in ["beckmann", "ggx"] {
            for geo in ["v-groove", "smith", "smith-correlated"] {
                let b = model(json!({"kd": 0.2, "ks": 0.5, "distribution": dist,
                    "alpha_x": 0.2, "alpha_y": 0.4, "geometry": geo,
                    "fresnel": "dielectric", "eta": 1.5}));
                let want = 0.2 / PI + 0.5 * 0.04 / (4.0 * PI * 0.08);
                let f = b.eval(DVec3::Z, DVec3::Z);
                assert!((f.x - want).abs() < 1e-13, "{dist} {geo}: {f} vs {want}");
            }
        }
    }

    #[test]
    fn off_normal_hand_value_ggx_smith() {
        // wi, wo at θ = 45° in the xz plane, mirror pair: h = n, D = 1/(π α²),
        // GGX Λ(45°) = (−1 + √(1 + α²))/2, F none.
        let a: f64 = 0.5;
        let b = model(json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx",
            "alpha": a, "geometry": "smith", "fresnel": "none"}));
        let wi = from_spherical(PI / 4.0, 0.0);
        let wo = from_spherical(PI / 4.0, PI);
        let lambda = (-1.0 + (1.0 + a * a).sqrt()) / 2.0;
        let g = 1.0 / (1.0 + lambda).powi(2);
        let want = g / (PI * a * a) / (4.0 * 0.5);
        let f = b.eval(wi, wo);
        assert!((f.x / want - 1.0).abs() < 1e-13, "{f} vs {want}");
        // The height-correlated form at the same pair: 1/(1 + 2Λ).
        let b = model(json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx",
            "alpha": a, "geometry": "smith-correlated", "fresnel": "none"}));
        let want = 1.0 / (1.0 + 2.0 * lambda) / (PI * a * a) / 2.0;
        assert!((b.eval(wi, wo).x / want - 1.0).abs() < 1e-13);
        // V-groove at the mirror pair: h = n, wo·h = cos 45°, so the ratios are 2 ⇒ G = 1.
        let b = model(json!({"kd": 0.0, "ks": 1.0, "distribution": "ggx",
            "alpha": a, "geometry": "v-groove", "fresnel": "none"}));
        let want = 1.0 / (PI * a * a) / 2.0;
        assert!((b.eval(wi, wo).x / want - 1.0).abs() < 1e-13);
    }

    #[test]
    fn v_groove_hand_value() {
        // wi = n, wo at 60° (φ = 0): h at 30°, n·h = cos30°, wo·h = cos30°,
        // G = min(1, 2 cos30° · cos60° / cos30°, 2 cos30° · 1 / cos30°) = min(1, 1, 2) = 1.
        // wo at 80°: h at 40°, G = 2 cos40° cos80°/cos40° = 2 cos 80°.
        let wo = from_spherical(80f64.to_radians(), 0.0);
        let h = crate::frame::half_vector(DVec3::Z, wo).unwrap();
        let g = microfacet::v_groove_g(DVec3::Z, wo, h);
        assert!((g - 2.0 * 80f64.to_radians().cos()).abs() < 1e-14);
    }

    #[test]
    fn mixture_is_the_weighted_sum() {
        // f_spec is linear in D, and the Smith G uses the mixed Λ.
        let wi = from_spherical(0.4, 0.3);
        let wo = from_spherical(0.9, 2.5);
        let mix = model(json!({"kd": 0.0, "ks": 1.0, "distribution": "beckmann",
            "alpha": 0.3, "alpha2": 0.05, "weight2": 0.25, "geometry": "v-groove",
            "fresnel": "none"}));
        let one = model(json!({"kd": 0.0, "ks": 1.0, "distribution": "beckmann",
            "alpha": 0.3, "geometry": "v-groove", "fresnel": "none"}));
        let two = model(json!({"kd": 0.0, "ks": 1.0, "distribution": "beckmann",
            "alpha": 0.05, "geometry": "v-groove", "fresnel": "none"}));
        let want = 0.75 * one.eval(wi, wo).x + 0.25 * two.eval(wi, wo).x;
        assert!((mix.eval(wi, wo).x / want - 1.0).abs() < 1e-12);
    }

    /// Directional albedo ρ(wi) = ∫ f cosθo dωo by quadrature.
    fn albedo(b: &dyn Brdf, wi: DVec3) -> f64 {
        hemisphere_integral(|wo| b.eval(wi, wo).x * wo.z, 256)
    }

    #[test]
    fn smith_albedo_is_at_most_one_and_claims_follow() {
        // Where the claim is made, check it numerically at rough settings and
        // grazing incidence.
        for dist in ["beckmann", "ggx"] {
            for geo in ["smith", "smith-correlated"] {
                let b = model(json!({"kd": 0.0, "ks": 1.0, "distribution": dist,
                    "alpha_x": 1.0, "alpha_y": 0.6, "geometry": geo, "fresnel": "none"}));
                assert!(b.claims().energy_conserving);
                for th in [0.0, 1.0, 1.5] {
                    let r = albedo(b.as_ref(), from_spherical(th, 0.3));
                    assert!(r <= 1.0 + 1e-3 && r > 0.3, "{dist} {geo} θ {th}: {r}");
                }
            }
        }
        let claims = |p: Value| model(p).claims();
        assert!(claims(json!({"geometry": "v-groove", "distribution": "blinn"})).energy_conserving);
        assert!(!claims(json!({"geometry": "smith", "distribution": "blinn"})).energy_conserving);
        assert!(!claims(json!({"geometry": "smith", "kd": 0.5, "ks": 0.6})).energy_conserving);
        assert!(claims(json!({"geometry": "smith", "kd": 0.4, "ks": 0.6})).energy_conserving);
        assert!(claims(json!({"alpha": 0.4})).isotropic);
        assert!(!claims(json!({"alpha_x": 0.4, "alpha_y": 0.2})).isotropic);
        assert!(claims(json!({"alpha_x": 0.4, "alpha_y": 0.2, "distribution": "blinn"})).isotropic);
    }

    #[test]
    fn v_groove_albedo_is_at_most_one_and_blinn_smith_exceeds_it() {
        // The v-groove claim (see `claims`): ρ ≤ 1 for each D, rough and grazing.
        for dist in ["beckmann", "ggx", "blinn"] {
            let b = model(json!({"kd": 0.0, "ks": 1.0, "distribution": dist,
                "alpha": 1.0, "geometry": "v-groove", "fresnel": "none"}));
            assert!(b.claims().energy_conserving);
            for th in [0.0, 1.0, 1.5, 1.56] {
                let r = albedo(b.as_ref(), from_spherical(th, 0.3));
                assert!(r <= 1.0 + 1e-3 && r > 0.3, "{dist} θ {th}: {r}");
            }
        }
        // Blinn's D with Beckmann's Λ: the albedo exceeds 1, hence no claim.
        let b = model(json!({"kd": 0.0, "ks": 1.0, "distribution": "blinn",
            "alpha": 1.0, "geometry": "smith-correlated", "fresnel": "none"}));
        assert!(!b.claims().energy_conserving);
        let r = albedo(b.as_ref(), from_spherical(1.565, 0.0));
        assert!(r > 1.02, "{r}");
    }

    #[test]
    fn ndf_is_exposed_and_normalised() {
        let b = model(
            json!({"distribution": "ggx", "alpha_x": 0.3, "alpha_y": 0.1,
            "alpha2": 0.8, "weight2": 0.5}),
        );
        let d = b.ndf().unwrap();
        let s = hemisphere_integral(|h| d.d(h) * h.z, 256);
        assert!((s - 1.0).abs() < 1e-3, "{s}");
    }

    #[test]
    fn sampling_matches_pdf() {
        // E[g(wo)/pdf(wo)] over samples (a failed sample contributes 0) equals
        // ∫ g dωo for the smooth g = cos²θo (integral 2π/3), and ∫ pdf = the
        // fraction of samples that succeed.
        let mut rng = sampling::rng(5);
        for (dist, a, ms) in [
            ("beckmann", 0.3, "none"),
            ("ggx", 0.2, "none"),
            ("blinn", 0.5, "none"),
            ("ggx", 1.5, "none"),
            // The multiple-scattering lobe drawn with the diffuse part.
            ("ggx", 1.0, "kulla-conty"),
            ("beckmann", 0.6, "kulla-conty"),
        ] {
            let b = model(json!({"kd": 0.3, "ks": 0.7, "distribution": dist,
                "alpha_x": a, "alpha_y": a * 0.7, "alpha2": 0.9, "weight2": 0.3,
                "multiscatter": ms}));
            for th in [0.3, 1.2] {
                let wi = from_spherical(th, 0.4);
                let n = 200_000;
                let (mut sum, mut ok) = (0.0, 0usize);
                for _ in 0..n {
                    if let Some(wo) = b.sample(wi, sampling::uniform2(&mut rng)) {
                        let p = b.pdf(wi, wo);
                        assert!(p > 0.0 && wo.z > 0.0);
                        sum += wo.z * wo.z / p;
                        ok += 1;
                    }
                }
                let est = sum / n as f64;
                assert!((est - 2.0 * PI / 3.0).abs() < 0.03, "{dist} θ {th}: {est}");
                let total = hemisphere_integral(|wo| b.pdf(wi, wo), 512);
                let frac = ok as f64 / n as f64;
                assert!(
                    (total - frac).abs() < 0.01,
                    "{dist} θ {th}: {total} vs {frac}"
                );
            }
        }
    }

    fn all_variants() -> Vec<Value> {
        let mut v = Vec::new();
        for dist in DISTRIBUTION_OPTIONS {
            for geo in GEOMETRY_OPTIONS {
                for fr in fresnel::FRESNEL_OPTIONS {
                    v.push(json!({"distribution": dist, "geometry": geo, "fresnel": fr,
                        "eta": [0.2, 1.5, 3.0], "k": [3.9, 0.0, 1.0], "f0": [0.9, 0.04, 0.5]}));
                }
            }
        }
        v
    }

    #[test]
    fn every_d_g_f_combination_is_reciprocal() {
        // Deterministic sweep over all 36 variants (the proptest samples them).
        let pairs = [
            (dir(0.2, 0.1), dir(1.1, 2.9)),
            (dir(1.5, -0.4), dir(0.6, 1.7)),
            (dir(1e-6f64.acos(), 0.3), dir(0.9, -2.0)),
            (dir(1.3, 1.0), dir(1.3, 1.0 + PI)),
        ];
        for mut p in all_variants() {
            p["alpha_x"] = json!(0.25);
            p["alpha_y"] = json!(0.6);
            p["alpha2"] = json!(0.05);
            p["weight2"] = json!(0.3);
            let b = model(p.clone());
            for (wi, wo) in pairs {
                let (f, r) = (b.eval(wi, wo), b.eval(wo, wi));
                let scale = f.max_element().max(r.max_element());
                assert!(scale > 0.0 && f.is_finite());
                assert!(
                    (f - r).abs().max_element() <= 1e-6 * scale,
                    "{p}: {f} vs {r}"
                );
            }
        }
    }

    fn dir(theta: f64, phi: f64) -> DVec3 {
        from_spherical(theta, phi)
    }

    proptest! {
        #[test]
        fn finite_nonnegative_and_reciprocal(
            variant in 0usize..36,
            ax in 0.001f64..2.0, ay in 0.001f64..2.0, a2 in 0.001f64..2.0, w2 in 0.0f64..1.0,
            kd in 0.0f64..1.0, ks in 0.0f64..1.0,
            zi in prop_oneof![1e-6f64..1e-3, 1e-3f64..1.0], pi in -PI..PI,
            zo in prop_oneof![1e-6f64..1e-3, 1e-3f64..1.0], po in -PI..PI,
        ) {
            let mut p = all_variants()[variant].clone();
            let m = p.as_object_mut().unwrap();
            for (k, x) in [("alpha_x", ax), ("alpha_y", ay), ("alpha2", a2), ("weight2", w2),
                           ("kd", kd), ("ks", ks)] {
                m.insert(k.into(), json!(x));
            }
            let b = model(p);
            let wi = dir(zi.acos(), pi);
            let wo = dir(zo.acos(), po);
            let f = b.eval(wi, wo);
            let r = b.eval(wo, wi);
            prop_assert!(f.is_finite() && f.min_element() >= 0.0, "{f}");
            let scale = f.max_element().max(r.max_element());
            prop_assert!((f - r).abs().max_element() <= 1e-6 * scale, "{f} vs {r}");
            prop_assert!(b.claims().reciprocal);
            let pdf = b.pdf(wi, wo);
            prop_assert!(pdf.is_finite() && pdf >= 0.0);
        }
    }
}
