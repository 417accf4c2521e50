//! Ashikhmin-Shirley: the anisotropic Phong BRDF of Ashikhmin & Shirley 2000,
//! "An anisotropic Phong BRDF model" (J. Graphics Tools 5(2)), eqs. 4–5 for the
//! value and eqs. 9–10 for importance sampling. bv fixes the seed's typos
//! (`cos²φ` written twice in D, the missing `/2` in the diffuse term).

use crate::batch::{Kernel, LaneKernel, LaneMask, Lanes, math};
use crate::frame::half_vector;
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, FresnelTerm, Result, Rgb, mean_rgb, sampling};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_2, PI};

/// Parameter declaration (colours 0..1, exponents 0..10000).
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "rd",
        label: "Rd",
        doc: "Diffuse reflectance (scaled by 1 − Rs so that the sum stays plausible)",
        kind: ParamKind::Color(ColorSpec::unit_range([0.5, 0.5, 0.5])),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "rs",
        label: "Rs",
        doc: "Specular reflectance at normal incidence (Schlick's F0)",
        kind: ParamKind::Color(ColorSpec::unit_range([0.05, 0.05, 0.05])),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "nu",
        label: "nu",
        doc: "Phong exponent along the tangent u = +x (sharper lobe when larger)",
        kind: ParamKind::Float(FloatSpec::log(0.0, 10000.0, 100.0, 1.0, 10000.0)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "nv",
        label: "nv",
        doc: "Phong exponent along the bitangent v = +y",
        kind: ParamKind::Float(FloatSpec::log(0.0, 10000.0, 100.0, 1.0, 10000.0)),
        applies: Applies::Always,
    },
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "ashikhmin-shirley",
    name: "Ashikhmin-Shirley",
    summary: "Anisotropic Phong: Schlick-Fresnel specular lobe over a coupled diffuse term",
    citation: "Ashikhmin & Shirley 2000, \"An anisotropic Phong BRDF model\", eqs. 4-5, 9-10",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::ashikhmin_shirley",
            "shaders/models/ashikhmin_shirley.wgsl",
            include_str!("../../../../shaders/models/ashikhmin_shirley.wgsl"),
        )
        .with_sampling_lobe(),
    ),
};

/// The Ashikhmin-Shirley BRDF.
#[derive(Debug, Clone)]
pub struct AshikhminShirley {
    rd: Rgb,
    rs: Rgb,
    nu: f64,
    nv: f64,
    /// `√((nu+1)(nv+1))`, the normalisation of the half-vector density.
    norm: f64,
    /// `28 rd (1 − rs) / (23π)`, the diffuse term's constant (eq. 5).
    diffuse_scale: Rgb,
    kernel: AsLanes,
}

/// [`AshikhminShirley`]'s f32 batch kernel: eq. 4 and 5 as in `eval`, with
/// the half vector's `1 − h·n` taken from `v = wi + wo` as
/// `(vx² + vy²)/(|v| (|v| + vz))` (exact algebra) so that exponents up to
/// 10⁴ stay accurate, and `E(h)` from `v` directly (it is scale-free).
#[derive(Debug, Clone, Copy)]
struct AsLanes {
    rs: [f32; 3],
    diffuse_scale: [f32; 3],
    nu: f32,
    nv: f32,
    /// `√((nu+1)(nv+1)) / (8π)`.
    spec_scale: f32,
}

impl LaneKernel for AsLanes {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let (zero, one) = (V::splat(0.0), V::splat(1.0));
        let v = math::add3(wi, wo);
        let (x2, y2) = (v[0] * v[0], v[1] * v[1]);
        let t2 = x2 + y2;
        let l = (t2 + v[2] * v[2]).sqrt();
        let hz = v[2] / l;
        let one_minus = t2 / (l * (l + v[2]));
        let e = t2.gt(zero).select(
            (x2 * self.nu + y2 * self.nv) / t2,
            V::splat(0.5 * (self.nu + self.nv)),
        );
        let lobe = math::pow_1m_lanes(hz, one_minus, e);
        let c = (l * 0.5).min(one);
        let spec = lobe * self.spec_scale / (c * wi[2].max(wo[2]));
        // Schlick's (1 − c)⁵ and the diffuse factors 1 − (1 − cos/2)⁵.
        let fw = math::pow5(one - c);
        let d = (one - math::pow5(one - wi[2] * 0.5)) * (one - math::pow5(one - wo[2] * 0.5));
        let above = wi[2].gt(zero) & wo[2].gt(zero) & l.gt(zero);
        math::channels!(|k| {
            let f = fw * (1.0 - self.rs[k]) + self.rs[k];
            above.select(d * self.diffuse_scale[k] + f * spec, zero)
        })
    }
}

impl AshikhminShirley {
    /// A model with the given reflectances and exponents (`nu`, `nv` ≥ 0).
    pub fn new(rd: Rgb, rs: Rgb, nu: f64, nv: f64) -> Self {
        let norm = ((nu + 1.0) * (nv + 1.0)).sqrt();
        let diffuse_scale = rd * (Rgb::ONE - rs) * (28.0 / (23.0 * PI));
        Self {
            rd,
            rs,
            nu,
            nv,
            norm,
            diffuse_scale,
            kernel: AsLanes {
                rs: math::rgb(rs),
                diffuse_scale: math::rgb(diffuse_scale),
                nu: nu as f32,
                nv: nv as f32,
                spec_scale: (norm / (8.0 * PI)) as f32,
            },
        }
    }

    /// Exponent `E = (nu h.x² + nv h.y²)/(1 − h.z²)` of eq. 4, with `h.x² + h.y²`
    /// in the denominator (equal for a unit h, but exact near the normal), and
    /// `(nu + nv)/2` at h = n where the azimuth is undefined (there `h.z^E = 1`
    /// whatever E is, so the choice only has to be finite).
    fn exponent(&self, h: DVec3) -> f64 {
        let (x2, y2) = (h.x * h.x, h.y * h.y);
        let s2 = x2 + y2;
        if s2 > 0.0 {
            (self.nu * x2 + self.nv * y2) / s2
        } else {
            0.5 * (self.nu + self.nv)
        }
    }

    /// Half-vector density `p(h) = √((nu+1)(nv+1))/(2π) · (h.z)^E` (eq. 9–10's
    /// target). It integrates to exactly 1 over the hemisphere (not cos-weighted):
    /// `∫ cos^E θ dω = ∫ dφ/(E(φ)+1)` and `∫₀^{2π} dφ/((nu+1)cos²φ + (nv+1)sin²φ)
    /// = 2π/√((nu+1)(nv+1))`.
    fn half_density(&self, h: DVec3) -> f64 {
        if h.z <= 0.0 {
            return 0.0;
        }
        // powf(0 < z ≤ 1, E ≥ 0) is finite; E = 0 gives 1.
        self.norm / (2.0 * PI) * h.z.powf(self.exponent(h))
    }

    /// Probability of drawing from the specular lobe rather than the cosine
    /// lobe: the ratio of rough albedo estimates (Schlick F at θi versus the
    /// diffuse reflectance), kept in [0.1, 0.9] so that neither strategy is
    /// ever starved (the other covers the tails).
    fn specular_probability(&self, wi: DVec3) -> f64 {
        let ws = mean_rgb(schlick(self.rs, wi.z.clamp(0.0, 1.0)));
        let wd = mean_rgb(self.rd * (Rgb::ONE - self.rs));
        let total = ws + wd;
        if total > 0.0 {
            (ws / total).clamp(0.1, 0.9)
        } else {
            0.5
        }
    }

    /// Draws a half vector from `p(h)` (eqs. 9–10): φ from the first-quadrant
    /// warp `atan(√((nu+1)/(nv+1)) tan(πξ/2))` mirrored into the quadrant chosen
    /// by `u.x`, then `cos θh = (1 − ξ₂)^{1/(E(φ)+1)}` (we use ξ₂ itself, which has
    /// the same distribution).
    fn sample_half(&self, u: DVec2) -> DVec3 {
        let quadrant = |x: f64| -> f64 {
            if self.nu == self.nv {
                FRAC_PI_2 * x
            } else {
                (((self.nu + 1.0) / (self.nv + 1.0)).sqrt() * (FRAC_PI_2 * x).tan()).atan()
            }
        };
        let x = u.x;
        let phi = if x < 0.25 {
            quadrant(4.0 * x)
        } else if x < 0.5 {
            PI - quadrant(4.0 * (0.5 - x))
        } else if x < 0.75 {
            PI + quadrant(4.0 * (x - 0.5))
        } else {
            2.0 * PI - quadrant(4.0 * (1.0 - x))
        };
        let (sp, cp) = phi.sin_cos();
        let e = self.nu * cp * cp + self.nv * sp * sp;
        // cos θ = ξ^{1/(E+1)} as exp(ln ξ/(E+1)); sin²θ = −expm1(2 ln ξ/(E+1))
        // keeps sin θ accurate for sharp lobes (cos θ ≈ 1).
        let l = u.y.ln() / (e + 1.0);
        let cos_t = l.exp();
        let sin_t = (-(2.0 * l).exp_m1()).max(0.0).sqrt();
        DVec3::new(sin_t * cp, sin_t * sp, cos_t)
    }
}

/// Schlick's Fresnel approximation `rs + (1 − rs)(1 − c)^5` (eq. 5's F).
fn schlick(rs: Rgb, c: f64) -> Rgb {
    rs + (Rgb::ONE - rs) * (1.0 - c).powi(5)
}

/// `1 − (1 − cos θ/2)^5`, the diffuse term's per-direction factor (eq. 5).
fn diffuse_factor(cos_t: f64) -> f64 {
    1.0 - (1.0 - 0.5 * cos_t).powi(5)
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(AshikhminShirley::new(
        p.color("rd")?,
        p.color("rs")?,
        p.float("nu")?,
        p.float("nv")?,
    )))
}

impl Brdf for AshikhminShirley {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        Some(&self.kernel)
    }

    fn fresnel_term(&self) -> Option<FresnelTerm> {
        Some(FresnelTerm {
            fresnel: crate::fresnel::Fresnel::Schlick { f0: self.rs },
            source: "Schlick with F0 = rs (Ashikhmin & Shirley 2000, eq. 5)".into(),
        })
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        // Eq. 5: the diffuse term.
        let diffuse = self.diffuse_scale * (diffuse_factor(wi.z) * diffuse_factor(wo.z));
        // Eq. 4: the specular term. `c = h·wi = |wi + wo|/2` for unit directions:
        // symmetric in (wi, wo) to the last bit and accurate when wi ≈ −wo.
        let s = wi + wo;
        let Some(h) = half_vector(wi, wo) else {
            // wi = −wo to 1e-12: only possible with both at the horizon, where
            // 1/(c · max cos) has no finite limit; we keep the diffuse part.
            return diffuse;
        };
        let c = (0.5 * s.length()).min(1.0);
        let spec = self.norm / (8.0 * PI) * h.z.powf(self.exponent(h)) / (c * wi.z.max(wo.z));
        diffuse + schlick(self.rs, c) * spec
    }

    /// The specular term's `max(cos θi, cos θo)` (Ashikhmin & Shirley 2000,
    /// eq. 4) switches branch where `θo = θi`.
    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        let cz = wi.z;
        vec![Box::new(move |wo: DVec3| wo.z - cz)]
    }

    fn claims(&self) -> Claims {
        // Energy. Proven here only for the specular term alone: with dωo = 4c dωh,
        // ρs(wi) = ∫ p(h) F(c) cosθo / max(cosθi, cosθo) dωh ≤ max F · ∫ p(h) dωh
        // ≤ 1, since ∫ p dωh = 1 exactly (see `half_density`) and F ≤ 1 for rs ≤ 1.
        // The diffuse albedo is rd (1 − rs)(1 − (1 − cosθi/2)^5) (the 28/23 makes
        // ∫ (1 − (1 − cosθo/2)^5) cosθo dωo = 23π/28 exact). The paper argues the
        // sum stays ≤ 1 because the diffuse part takes the (1 − rs) share; that is
        // exact only in the mirror limit (ρs → F(cosθi)), and off-specular half
        // vectors have F(c) > F(cosθi), so we do not claim it: the claim is true
        // only where no channel has a diffuse term (rd (1 − rs) = 0). (A numeric
        // scan with rd = 1, rs ∈ 0..0.3, nu, nv ∈ 0..1000 found at most ρ ≈ 0.98,
        // at normal incidence: evidence, not a proof.)
        let diffuse_free = (self.rd * (Rgb::ONE - self.rs)).max_element() <= 0.0;
        Claims {
            reciprocal: true,
            energy_conserving: diffuse_free && self.rs.max_element() <= 1.0,
            isotropic: self.nu == self.nv,
        }
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z <= 0.0 {
            return None;
        }
        let ps = self.specular_probability(wi);
        if u.x < ps {
            // Reuse u.x rescaled to [0, 1): one uniform per decision.
            let ux = (u.x / ps).min(ONE_BELOW);
            let h = self.sample_half(DVec2::new(ux, u.y));
            let wo = 2.0 * wi.dot(h) * h - wi;
            // Half vectors whose mirror falls below the horizon (wi·h < 0 included)
            // are lost: the pdf then integrates to less than 1, the deficit being
            // the probability of `None`.
            (wo.z > 0.0).then(|| wo.normalize())
        } else {
            let ux = ((u.x - ps) / (1.0 - ps)).min(ONE_BELOW);
            Some(sampling::cosine_hemisphere(DVec2::new(ux, u.y)))
        }
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let ps = self.specular_probability(wi);
        // Reflection about h maps dωh to dωo with Jacobian 1/(4 wo·h) (the paper's
        // eq. 8 with k1 = wi, k2 = wo); wo·h = wi·h = |wi + wo|/2.
        let spec = match half_vector(wi, wo) {
            Some(h) => {
                let c = 0.5 * (wi + wo).length();
                if c > 0.0 {
                    self.half_density(h) / (4.0 * c)
                } else {
                    0.0
                }
            }
            None => 0.0,
        };
        ps * spec + (1.0 - ps) * sampling::cosine_hemisphere_pdf(wo)
    }
}

/// The largest f64 below 1, to keep rescaled uniforms in [0, 1).
const ONE_BELOW: f64 = 1.0 - f64::EPSILON / 2.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::frame::from_spherical;
    use crate::models::testkit::*;
    use proptest::prelude::*;
    use serde_json::json;

    fn model(p: serde_json::Value) -> Box<dyn Brdf> {
        ModelSpec::from_json("ashikhmin-shirley", &p)
            .unwrap()
            .build()
            .unwrap()
    }

    #[test]
    fn normal_incidence_and_view() {
        // wi = wo = n: h = n, c = 1, h.z^E = 1, max cos = 1, F = rs. With
        // nu = 3, nv = 15 the constant is √(4·16)/(8π) = 1/π, so the specular
        // term is rs/π; the diffuse term is 28 rd (1 − rs)/(23π) · (31/32)².
        let b = model(json!({"rd": 0.5, "rs": 0.25, "nu": 3, "nv": 15}));
        let f = b.eval(DVec3::Z, DVec3::Z);
        let want = 0.25 / PI + 28.0 * 0.5 * 0.75 / (23.0 * PI) * (31.0f64 / 32.0).powi(2);
        assert!((f.x - want).abs() < 1e-14 * want, "{} {want}", f.x);
    }

    #[test]
    fn off_specular_value_in_the_tangent_plane() {
        // wi = n, wo at 60° in the x-z plane: h at 30° along x, so E = nu exactly.
        // c = cos 30° = √3/2, max(cos θi, cos θo) = 1, cos θo = 1/2.
        // rs = 0: F = (1 − √3/2)^5. nu = 2, nv = 8: √(3·9) = 3√3.
        let b = model(json!({"rd": 0.4, "rs": 0.0, "nu": 2, "nv": 8}));
        let wo = DVec3::new(3f64.sqrt() / 2.0, 0.0, 0.5);
        let f = b.eval(DVec3::Z, wo).x;
        let c = 3f64.sqrt() / 2.0;
        let spec = 3.0 * 3f64.sqrt() / (8.0 * PI) * 0.75 / c * (1.0 - c).powi(5);
        let diff = 28.0 * 0.4 / (23.0 * PI) * (31.0 / 32.0) * (1.0 - 0.75f64.powi(5));
        assert!((f - (spec + diff)).abs() < 1e-14, "{f} {}", spec + diff);
        // The same pair turned by 90° about z puts h along y: E = nv = 8.
        let wo_y = DVec3::new(0.0, 3f64.sqrt() / 2.0, 0.5);
        let fy = b.eval(DVec3::Z, wo_y).x;
        let spec_y = 3.0 * 3f64.sqrt() / (8.0 * PI) * 0.75f64.powi(4) / c * (1.0 - c).powi(5);
        assert!(
            (fy - (spec_y + diff)).abs() < 1e-14,
            "{fy} {}",
            spec_y + diff
        );
    }

    #[test]
    fn swapping_exponents_is_a_quarter_turn() {
        let a = model(json!({"nu": 10, "nv": 300}));
        let b = model(json!({"nu": 300, "nv": 10}));
        let rot = |w: DVec3| DVec3::new(-w.y, w.x, w.z);
        for &(wi, wo) in &[
            (from_spherical(0.3, 0.2), from_spherical(0.5, 2.9)),
            (from_spherical(1.2, -1.0), from_spherical(0.9, 1.7)),
        ] {
            let fa = a.eval(wi, wo);
            let fb = b.eval(rot(wi), rot(wo));
            assert!(rel_close(fa, fb, 1e-12), "{fa} {fb}");
        }
        assert!(!a.claims().isotropic);
        assert!(model(json!({"nu": 7, "nv": 7})).claims().isotropic);
    }

    #[test]
    fn half_density_integrates_to_one() {
        // ∫ p(h) dωh = 1 exactly, anisotropic included (the proof is in
        // `half_density`); midpoint quadrature with a fine grid.
        for &(nu, nv) in &[(0.0, 0.0), (10.0, 100.0), (50.0, 3.0)] {
            let m = AshikhminShirley::new(Rgb::ZERO, Rgb::ONE, nu, nv);
            let i = hemisphere_integral(|h| m.half_density(h), 800, 800);
            assert!((i - 1.0).abs() < 1e-3, "{nu} {nv}: {i}");
        }
    }

    #[test]
    fn diffuse_albedo_closed_form() {
        // The diffuse term is linear in rd, so f(rd) − f(rd = 0) is the diffuse
        // term alone; its albedo is rd (1 − rs)(1 − (1 − cos θi/2)^5) because
        // 2π ∫₀¹ (1 − (1 − μ/2)^5) μ dμ = 2π (1/2 − 5/56) = 23π/28.
        let with = model(json!({"rd": 0.8, "rs": 0.3, "nu": 20, "nv": 20}));
        let without = model(json!({"rd": 0.0, "rs": 0.3, "nu": 20, "nv": 20}));
        for &t in &[0.0, 0.7, 1.4] {
            let wi = from_spherical(t, 0.3);
            let i = hemisphere_integral(
                |wo| (with.eval(wi, wo).x - without.eval(wi, wo).x) * wo.z,
                400,
                400,
            );
            let want = 0.8 * 0.7 * (1.0 - (1.0 - 0.5 * t.cos()).powi(5));
            assert!((i - want).abs() < 1e-4, "{t}: {i} {want}");
        }
    }

    #[test]
    fn specular_albedo_is_at_most_one() {
        // rd = 0, rs = 1 (F = 1): ρ = ∫ p(h) cos θo / max(cos θi, cos θo) dωh ≤ 1,
        // and the claim says so.
        let b = model(json!({"rd": 0.0, "rs": 1.0, "nu": 5, "nv": 40}));
        assert!(b.claims().energy_conserving);
        for &t in &[0.0, 0.8, 1.3, 1.55] {
            let a = albedo(b.as_ref(), from_spherical(t, 0.4), 600, 600).x;
            assert!(a <= 1.0 + 1e-3, "{t}: {a}");
        }
        assert!(!model(json!({"rd": 0.5})).claims().energy_conserving);
    }

    #[test]
    fn grazing_and_degenerate_pairs_are_finite() {
        let b = model(json!({"nu": 10000, "nv": 0, "rs": 0.5, "rd": 1.0}));
        let cases = [
            (DVec3::Z, DVec3::Z),
            (dir_grazing(6.0, 0.0), dir_grazing(6.0, PI)),
            (dir_grazing(6.0, 0.0), dir_grazing(6.0, 0.0)),
            (dir_grazing(6.0, 1.0), DVec3::Z),
            (DVec3::new(1.0, 0.0, 1e-300), DVec3::new(-1.0, 0.0, 1e-300)),
        ];
        for (wi, wo) in cases {
            let f = b.eval(wi, wo);
            assert!(finite_nonneg(f), "{wi} {wo}: {f}");
            let p = b.pdf(wi, wo);
            assert!(p.is_finite() && p >= 0.0, "{p}");
        }
    }

    #[test]
    fn pdf_integrates_to_success_probability() {
        // ∫ pdf dωo over the hemisphere = P(sample returns a direction).
        let b = model(json!({"rd": 0.3, "rs": 0.4, "nu": 8, "nv": 60}));
        for &t in &[0.2, 1.0, 1.45] {
            let wi = from_spherical(t, 0.7);
            let i = hemisphere_integral(|wo| b.pdf(wi, wo), 1000, 1000);
            let ok = success_rate(b.as_ref(), wi, 400_000, 3);
            // Quadrature error ~1e-4; binomial standard error ≤ 8e-4 (5σ < 4e-3).
            assert!((i - ok).abs() < 4e-3, "{t}: ∫pdf {i}, success {ok}");
        }
    }

    #[test]
    fn sampling_matches_pdf_monte_carlo() {
        // E[g/pdf] = ∫ g dωo with g = cos θo (1 + x/2): exact value π (the x term
        // is odd). Bounded ratio because the cosine lobe has probability ≥ 0.1.
        for p in [
            json!({"rd": 0.3, "rs": 0.4, "nu": 8, "nv": 60}),
            json!({"rd": 0.0, "rs": 0.9, "nu": 1000, "nv": 100}),
            json!({"rd": 0.9, "rs": 0.0, "nu": 0, "nv": 0}),
        ] {
            let b = model(p.clone());
            for &t in &[0.1, 0.9, 1.5] {
                let wi = from_spherical(t, -0.4);
                let (est, se) =
                    sampled_integral(b.as_ref(), wi, |w| w.z * (1.0 + 0.5 * w.x), 200_000, 11);
                assert!(
                    (est - PI).abs() < 5.0 * se + 1e-9,
                    "{p} θi {t}: {est} ± {se}"
                );
                assert!(se < 0.05, "{se}");
            }
        }
    }

    proptest! {
        #[test]
        fn finite_nonneg_and_reciprocal(
            rd in 0.0..=1.0f64, rs in 0.0..=1.0f64,
            lnu in 0.0..=4.0f64, lnv in 0.0..=4.0f64, zero in 0..4u8,
            wi in upper_dir(), wo in upper_dir(),
        ) {
            // Exponents log-uniform over 1..10000, and exactly 0 sometimes.
            let nu = if zero == 1 { 0.0 } else { 10f64.powf(lnu) };
            let nv = if zero == 2 { 0.0 } else { 10f64.powf(lnv) };
            let b = AshikhminShirley::new(Rgb::splat(rd), Rgb::splat(rs), nu, nv);
            let f = b.eval(wi, wo);
            prop_assert!(finite_nonneg(f), "{f}");
            prop_assert!(rel_close(f, b.eval(wo, wi), 1e-6));
            let p = b.pdf(wi, wo);
            prop_assert!(p.is_finite() && p > 0.0);
        }
    }
}
