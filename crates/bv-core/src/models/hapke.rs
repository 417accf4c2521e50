//! Hapke: the planetary-regolith BRDF of Hapke 1981, "Bidirectional reflectance
//! spectroscopy 1. Theory" (J. Geophys. Res. 86), without the macroscopic
//! roughness correction : single scattering with a Henyey-Greenstein
//! phase function and the opposition surge, plus multiple scattering through
//! Hapke's closed-form approximation of Chandrasekhar's H function. The lecture
//! uses it for the Moon's flat, retro-reflective look.

use crate::batch::{Kernel, LaneKernel, LaneMask, Lanes, math};
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, Result, Rgb};
use glam::DVec3;
use std::f64::consts::PI;

/// Parameter declaration (w 0..1, b0 0..10, h 0.001..1, g −1..1).
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "w",
        label: "w",
        doc: "Single-scattering albedo of the particles",
        kind: ParamKind::Float(FloatSpec::linear(0.0, 1.0, 0.6)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "b0",
        label: "B0",
        doc: "Amplitude of the opposition surge (shadow hiding) at zero phase",
        kind: ParamKind::Float(FloatSpec {
            slider_max: 4.0,
            ..FloatSpec::linear(0.0, 10.0, 1.0)
        }),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "h",
        label: "h",
        doc: "Angular width of the opposition surge (regolith compaction)",
        kind: ParamKind::Float(FloatSpec::log(0.001, 1.0, 0.06, 0.001, 1.0)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "g",
        label: "g",
        doc: "Henyey-Greenstein asymmetry: g < 0 scatters back towards the light",
        kind: ParamKind::Float(FloatSpec::linear(-1.0, 1.0, -0.3)),
        applies: Applies::Always,
    },
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "hapke",
    name: "Hapke",
    summary: "Lunar regolith: single scattering with opposition surge plus multiple scattering",
    citation: "Hapke 1981, \"Bidirectional reflectance spectroscopy 1. Theory\" (no macroscopic roughness)",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(GpuPort::new(
        "bv::models::hapke",
        "shaders/models/hapke.wgsl",
        include_str!("../../../../shaders/models/hapke.wgsl"),
    )),
};

/// The Hapke 1981 BRDF (grey: one value for all channels).
#[derive(Debug, Clone)]
pub struct Hapke {
    w: f64,
    b0: f64,
    /// Surge width `h`.
    width: f64,
    /// Henyey-Greenstein asymmetry `g`.
    asym: f64,
    /// `γ = √(1 − w)`, used by H.
    gamma: f64,
    kernel: HapkeLanes,
}

/// [`Hapke`]'s f32 batch kernel: the same expressions as the f64 `eval`
/// (the surge from `|wi ± wo|`, Henyey–Greenstein with its cancellation-free
/// denominator, Hapke's H), written branch-free.
#[derive(Debug, Clone, Copy)]
struct HapkeLanes {
    /// `w / (4π)`.
    w4pi: f32,
    b0: f32,
    width: f32,
    asym: f32,
    gamma: f32,
    one_minus_gamma: f32,
}

impl HapkeLanes {
    /// `H(x) − 1 = 2x (1 − γ)/(1 + 2xγ)`.
    #[inline(always)]
    fn h_minus_1<V: Lanes>(&self, x: V) -> V {
        x * (2.0 * self.one_minus_gamma) / (x * (2.0 * self.gamma) + 1.0)
    }
}

impl LaneKernel for HapkeLanes {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let zero = V::splat(0.0);
        let s = math::add3(wi, wo);
        let d = math::sub3(wi, wo);
        let (s2, d2) = (math::dot(s, s), math::dot(d, d));
        let hs = s2.sqrt() * self.width;
        let bd = hs + d2.sqrt();
        let surge = bd.gt(zero).select(hs * self.b0 / bd, zero);
        let g = self.asym;
        let num = (1.0 - g) * (1.0 + g);
        // A branch on the model's constant, not on a lane.
        let a = if g <= 0.0 {
            -(d2 * (g * 0.5)) + (1.0 + g)
        } else {
            s2 * (g * 0.5) + (1.0 - g)
        };
        let c = math::cross(wi, wo);
        let dd = a * a + math::dot(c, c) * (g * g);
        let phase = if num > 0.0 {
            dd.gt(zero).select(V::splat(num) / (dd * dd.sqrt()), zero)
        } else {
            zero
        };
        // H(μi) H(μo) − 1 as (Hi − 1)(Ho − 1) + (Hi − 1) + (Ho − 1) with
        // H(x) − 1 = 2x (1 − γ)/(1 + 2xγ): near the horizon both H are close
        // to 1 and the direct product minus 1 loses f32's digits, while f
        // divides it by the small cos θi + cos θo.
        let (hi, ho) = (self.h_minus_1(wi[2]), self.h_minus_1(wo[2]));
        let multiple = hi * ho + hi + ho;
        let multiple = multiple.gt(zero).select(multiple, zero);
        let f = V::splat(self.w4pi) / (wi[2] + wo[2]) * ((surge + 1.0) * phase + multiple);
        let v = (wi[2].gt(zero) & wo[2].gt(zero)).select(f, zero);
        [v; 3]
    }
}

impl Hapke {
    /// The model with single-scattering albedo `w`, surge amplitude `b0` and
    /// width `h`, and phase asymmetry `g`.
    pub fn new(w: f64, b0: f64, h: f64, g: f64) -> Self {
        let gamma = (1.0 - w).max(0.0).sqrt();
        Self {
            w,
            b0,
            width: h,
            asym: g,
            gamma,
            kernel: HapkeLanes {
                w4pi: (w / (4.0 * PI)) as f32,
                b0: b0 as f32,
                width: h as f32,
                asym: g as f32,
                gamma: gamma as f32,
                one_minus_gamma: (1.0 - gamma) as f32,
            },
        }
    }

    /// Hapke's approximation `H(x) = (1 + 2x)/(1 + 2x √(1 − w))` of
    /// Chandrasekhar's H function for isotropic scatterers. H(0) = 1, and
    /// H ≥ 1 increasing in x, so H(μi)H(μo) − 1 ≥ 0.
    fn chandrasekhar_h(&self, x: f64) -> f64 {
        (1.0 + 2.0 * x) / (1.0 + 2.0 * x * self.gamma)
    }

    /// Opposition surge `B = b0/(1 + tan(g_ph/2)/h)`. With unit directions
    /// `tan(g_ph/2) = |wi − wo|/|wi + wo|`, so `B = b0 h |wi+wo| / (h |wi+wo| + |wi−wo|)`:
    /// no tangent to overflow, and at g_ph = π (wi = −wo, only reachable at the
    /// horizon) it gives the limit 0 instead of 0/0. The denominator never
    /// vanishes: |wi + wo| and |wi − wo| are not both 0.
    fn surge(&self, wi: DVec3, wo: DVec3) -> f64 {
        let sum = (wi + wo).length();
        let diff = (wi - wo).length();
        let hs = self.width * sum;
        self.b0 * hs / (hs + diff)
    }

    /// Bound on ρhd used by the energy claim (a sufficient condition only):
    /// `ρ(wi) = w/(4π) ∫ cosθo/(cosθi + cosθo) ((1+B)P + H H − 1) dωo
    ///  ≤ w/(4π) ((1 + b0) ∫ P dω + 2π (H(1)² − 1)) = w (1 + b0 + (H(1)² − 1)/2)`,
    /// using cosθo/(cosθi + cosθo) ≤ 1, B ≤ b0, ∫_sphere P dω = 4π and H ≤ H(1).
    fn albedo_bound(&self) -> f64 {
        let h1 = self.chandrasekhar_h(1.0);
        self.w * (1.0 + self.b0 + 0.5 * (h1 * h1 - 1.0))
    }
}

/// Henyey-Greenstein phase function in Hapke's normalisation (∫ P dω = 4π),
/// `P = (1 − g²)/(1 + 2g cos g_ph + g²)^{3/2}` with `cos g_ph = wi·wo`
/// (g < 0 peaks at g_ph = 0, back towards the light).
///
/// The denominator is computed as `(1 + g cos)² + g² sin²` with `1 + g cos` from
/// `|wi ∓ wo|²` so that it never cancels: for |g| < 1 it is ≥ (1 − |g|)² > 0 and P
/// stays finite (≤ 2/(1 − |g|)²). At |g| = 1 the numerator is 0: HG degenerates to
/// a Dirac delta (forward or backward), which no finite value represents, so P = 0
/// everywhere, including the 0/0 point wi = ∓wo itself.
pub fn henyey_greenstein(g: f64, wi: DVec3, wo: DVec3) -> f64 {
    let num = (1.0 - g) * (1.0 + g);
    if num <= 0.0 {
        return 0.0;
    }
    // 1 + g cos = (1 + g) + (−g)(1 − cos) for g ≤ 0, (1 − g) + g (1 + cos) for g > 0:
    // two non-negative terms, with 1 ∓ cos = |wi ∓ wo|²/2.
    let a = if g <= 0.0 {
        (1.0 + g) - g * 0.5 * (wi - wo).length_squared()
    } else {
        (1.0 - g) + g * 0.5 * (wi + wo).length_squared()
    };
    let sin2 = wi.cross(wo).length_squared();
    let d = a * a + g * g * sin2;
    num / (d * d.sqrt())
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    Ok(Box::new(Hapke::new(
        p.float("w")?,
        p.float("b0")?,
        p.float("h")?,
        p.float("g")?,
    )))
}

impl Brdf for Hapke {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        // Hapke 1981's bidirectional reflectance r = w/(4π) μ0/(μ0 + μ) [(1 + B)P
        // + H(μ0)H(μ) − 1] divided by μ0 (BRDF = r/μ0). Every term is ≥ 0 and
        // cos θi + cos θo > 0 here.
        let p = henyey_greenstein(self.asym, wi, wo);
        let b = self.surge(wi, wo);
        let multiple = self.chandrasekhar_h(wi.z) * self.chandrasekhar_h(wo.z) - 1.0;
        let f = self.w / (4.0 * PI) / (wi.z + wo.z) * ((1.0 + b) * p + multiple.max(0.0));
        Rgb::splat(f)
    }

    /// The opposition surge and a backward Henyey–Greenstein lobe peak at
    /// zero phase angle, `wo = wi` (the surge has a cusp there).
    fn peaks(&self, wi: DVec3) -> Vec<DVec3> {
        vec![wi]
    }

    /// The surge `B = b0 h |wi+wo| / (h |wi+wo| + |wi−wo|)` is a cone in
    /// `wo` about `wi` (its slope along any great circle through `wi` jumps
    /// sign there), while every other term is smooth: integrated in polar
    /// coordinates about `wi`, it is a smooth function of the polar angle
    /// alone (`|wi ± wo| = 2 cos, 2 sin` of half of it).
    fn pole(&self, wi: DVec3) -> Option<DVec3> {
        Some(wi)
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        Some(&self.kernel)
    }

    fn claims(&self) -> Claims {
        Claims {
            reciprocal: true,
            // Claimed only when the crude bound of `albedo_bound` proves it: the
            // opposition surge adds energy (b0 up to 10) and Hapke's H is an
            // approximation, so the model is not conserving in general.
            energy_conserving: self.albedo_bound() <= 1.0,
            isotropic: true,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;
    use crate::frame::from_spherical;
    use crate::models::testkit::*;
    use proptest::prelude::*;
    use serde_json::json;

    fn model(p: serde_json::Value) -> Box<dyn Brdf> {
        ModelSpec::from_json("hapke", &p).unwrap().build().unwrap()
    }

    /// `∫ P dω` over the whole sphere around wi = n, as 2π ∫₀^π P sin θ dθ
    /// (midpoint rule).
    fn phase_integral(g: f64, n: usize) -> f64 {
        let dt = PI / n as f64;
        let s: f64 = (0..n)
            .map(|i| {
                let t = (i as f64 + 0.5) * dt;
                henyey_greenstein(g, DVec3::Z, from_spherical(t, 0.0)) * t.sin()
            })
            .sum();
        2.0 * PI * s * dt
    }

    #[test]
    fn zero_albedo_is_black() {
        let m = model(json!({"w": 0.0, "b0": 5.0}));
        for (wi, wo) in [
            (DVec3::Z, DVec3::Z),
            (from_spherical(0.4, 0.0), from_spherical(1.2, 2.0)),
        ] {
            assert_eq!(m.eval(wi, wo), Rgb::ZERO);
        }
        assert!(m.claims().energy_conserving);
    }

    #[test]
    fn phase_function_normalisation_and_values() {
        // ∫ P dω/(4π) = 1 for every |g| < 1.
        for &g in &[-0.99, -0.9, -0.3, 0.0, 0.5, 0.95] {
            let i = phase_integral(g, 200_000) / (4.0 * PI);
            assert!((i - 1.0).abs() < 1e-6, "g = {g}: {i}");
        }
        // At zero phase (wi = wo), P = (1 − g²)/(1 + g)³ = (1 − g)/(1 + g)²: 6 at g = −0.5.
        let w = from_spherical(0.7, 0.2);
        assert!((henyey_greenstein(-0.5, w, w) - 6.0).abs() < 1e-13);
        // At 90° phase, P = (1 − g²)/(1 + g²)^{3/2}.
        let p = henyey_greenstein(0.6, DVec3::Z, DVec3::X);
        assert!((p - 0.64 / 1.36f64.powf(1.5)).abs() < 1e-14);
        // g = 0 is isotropic: P = 1.
        assert_eq!(henyey_greenstein(0.0, DVec3::Z, w), 1.0);
    }

    #[test]
    fn degenerate_phase_functions_are_finite() {
        let w = from_spherical(0.3, 0.1);
        // |g| = 1: a delta, represented by 0 (also at the 0/0 point).
        for g in [-1.0, 1.0] {
            assert_eq!(henyey_greenstein(g, w, w), 0.0);
            assert_eq!(henyey_greenstein(g, w, -w), 0.0);
            assert_eq!(henyey_greenstein(g, w, DVec3::Z), 0.0);
        }
        // |g| just below 1: huge but finite, close to 2/(1 − |g|)² at the peak.
        let g = -(1.0 - 1e-12);
        let p = henyey_greenstein(g, w, w);
        assert!(
            p.is_finite() && (p / (2.0 / 1e-24) - 1.0).abs() < 1e-3,
            "{p}"
        );
        let m = model(json!({"g": -1.0, "w": 1.0, "b0": 10.0, "h": 0.001}));
        let f = m.eval(w, w);
        assert!(finite_nonneg(f), "{f}");
    }

    #[test]
    fn chandrasekhar_h_values() {
        let m = Hapke::new(0.75, 1.0, 0.1, 0.0);
        assert_eq!(m.chandrasekhar_h(0.0), 1.0);
        // √(1 − 0.75) = 1/2: H(1) = 3/2, H(1/2) = 2/1.5.
        assert!((m.chandrasekhar_h(1.0) - 1.5).abs() < 1e-15);
        assert!((m.chandrasekhar_h(0.5) - 2.0 / 1.5).abs() < 1e-15);
        // w = 1 (conservative scattering): H = 1 + 2x.
        assert!((Hapke::new(1.0, 0.0, 0.1, 0.0).chandrasekhar_h(0.25) - 1.5).abs() < 1e-15);
    }

    #[test]
    fn hand_value_at_normal_incidence_and_view() {
        // wi = wo = n: g_ph = 0, B = b0, P = 1 (g = 0), H(1) = 3/2 (w = 3/4):
        // f = w/(4π) · 1/2 · ((1 + b0) + 9/4 − 1) = 0.75 · 3.25/(8π) for b0 = 1.
        let m = model(json!({"w": 0.75, "b0": 1.0, "h": 0.2, "g": 0.0}));
        let f = m.eval(DVec3::Z, DVec3::Z).x;
        assert!((f - 0.75 * 3.25 / (8.0 * PI)).abs() < 1e-15, "{f}");
    }

    #[test]
    fn surge_amplitude_width_and_removal() {
        let m = Hapke::new(0.5, 2.0, 0.05, -0.2);
        let wi = from_spherical(0.5, 0.0);
        // B = b0 at zero phase and b0/2 where tan(g_ph/2) = h.
        assert!((m.surge(wi, wi) - 2.0).abs() < 1e-15);
        let wo = from_spherical(0.5 + 2.0 * 0.05f64.atan(), 0.0);
        assert!((m.surge(wi, wo) - 1.0).abs() < 1e-12, "{}", m.surge(wi, wo));
        // b0 = 0 removes it: f = w/(4π)/(μi + μo) (P + H H − 1) by hand.
        let m0 = Hapke::new(0.5, 0.0, 0.05, -0.2);
        let wo = from_spherical(1.0, 2.0);
        let (mi, mo) = (wi.z, wo.z);
        let gam = 0.5f64.sqrt();
        let hh =
            (1.0 + 2.0 * mi) / (1.0 + 2.0 * mi * gam) * (1.0 + 2.0 * mo) / (1.0 + 2.0 * mo * gam);
        let c = wi.dot(wo);
        let p = (1.0 - 0.04) / (1.0 - 0.4 * c + 0.04f64).powf(1.5);
        let want = 0.5 / (4.0 * PI) / (mi + mo) * (p + hh - 1.0);
        assert!((m0.eval(wi, wo).x - want).abs() < 1e-14 * want);
    }

    #[test]
    fn opposition_peak_at_the_light() {
        // f(wi, ·) is largest at wo = wi (b0 > 0, back-scattering g) and the peak
        // has exactly the surge's height above the b0 = 0 model: w/(4π)/(2μ) b0 P(0).
        let m = Hapke::new(0.4, 1.5, 0.02, -0.3);
        let m0 = Hapke::new(0.4, 0.0, 0.02, -0.3);
        let wi = from_spherical(0.6, 1.0);
        let peak = m.eval(wi, wi).x;
        for k in 0..8 {
            let wo = from_spherical(0.6 + 0.03, 1.0 + k as f64 * 0.8);
            assert!(m.eval(wi, wo).x < peak);
            let wo = from_spherical(0.6 - 0.01 * (k as f64 + 1.0), 1.0);
            assert!(m.eval(wi, wo).x < peak);
        }
        let p0 = 1.3 / 0.49;
        let excess = 0.4 / (4.0 * PI) / (2.0 * wi.z) * 1.5 * p0;
        assert!((peak - m0.eval(wi, wi).x - excess).abs() < 1e-14);
    }

    #[test]
    fn energy_claim_is_a_sufficient_condition() {
        // Claimed: the numeric albedo is below 1 everywhere.
        let dark = model(json!({"w": 0.3, "b0": 1.0, "h": 0.1, "g": -0.3}));
        assert!(dark.claims().energy_conserving);
        for &t in &[0.0, 0.7, 1.2, 1.55] {
            let a = albedo(dark.as_ref(), from_spherical(t, 0.0), 800, 400).x;
            assert!(a < 1.0, "{t}: {a}");
        }
        // Not claimed, and indeed not conserving: a broad strong surge.
        let bright = model(json!({"w": 1.0, "b0": 10.0, "h": 1.0, "g": 0.0}));
        assert!(!bright.claims().energy_conserving);
        let a = albedo(bright.as_ref(), from_spherical(0.5, 0.0), 400, 200).x;
        assert!(a > 1.0, "{a}");
    }

    #[test]
    fn cosine_sampling_matches_pdf() {
        let m = model(json!({}));
        let (est, se) = sampled_integral(
            m.as_ref(),
            from_spherical(0.4, 0.0),
            |w| w.z * (1.0 + 0.5 * w.y),
            100_000,
            9,
        );
        assert!((est - PI).abs() < 5.0 * se + 1e-9, "{est} ± {se}");
    }

    proptest! {
        #[test]
        fn finite_nonneg_and_reciprocal(
            w in 0.0..=1.0f64, b0 in 0.0..=10.0f64, lh in -3.0..=0.0f64,
            g in prop_oneof![-1.0..=1.0f64, Just(-1.0), Just(1.0)],
            wi in upper_dir(), wo in upper_dir(),
        ) {
            let m = Hapke::new(w, b0, 10f64.powf(lh), g);
            let f = m.eval(wi, wo);
            prop_assert!(finite_nonneg(f), "{f}");
            prop_assert!(rel_close(f, m.eval(wo, wi), 1e-6));
            // Also at zero phase, where the surge and a back-scattering P peak.
            prop_assert!(finite_nonneg(m.eval(wi, wi)));
        }
    }
}
