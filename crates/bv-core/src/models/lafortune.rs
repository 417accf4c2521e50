//! Lafortune's generalised cosine lobes:
//! `f = kd/π + Σ_j ks_j (n_j+2)/(2π) · max(0, cx wi.x wo.x + cy wi.y wo.y + cz wi.z wo.z)^n_j`.
//!
//! Lafortune, Foo, Torrance & Greenberg 1997, "Non-linear approximation of
//! reflectance functions", eq. 4 (the lobe `(Cx ux vx + Cy uy vy + Cz uz vz)^n`),
//! with each lobe scaled by `ks_j` and the modified-Phong normalisation
//! `(n+2)/(2π)` so that `(−1, −1, 1)` is exactly a `modified-phong` lobe;
//! `(1, 1, 1)` is retro-reflective, `|cz| < |cx|` gives off-specular peaks, and
//! `cx ≠ cy` anisotropy.
//!
//! Coefficient range −1..1 (the paper gives none). The paper's fitted magnitudes
//! are near 1; a lobe `s·(cx, cy, cz)` is the lobe `(cx, cy, cz)` scaled by
//! `s^n`, so a magnitude beyond 1 is a brightness that `ks` (0..10) already
//! provides. Keeping `|c| ≤ 1` bounds the base of the power by 1
//! (Cauchy–Schwarz: `x = (C wi)·wo ≤ |C wi| ≤ max|c|`), so that `x^n` cannot
//! overflow for any exponent up to 10000 (`2^10000` would).

use super::lobes::{Mixture, PowerLobe, clamped_pow};
use crate::batch::{self, Dirs, Isa, Kernel, LaneKernel, LaneMask, Lanes, Out, WideLanes, math};
use crate::model::{Build, GpuPort, ModelInfo};
use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::Params;
use crate::{Brdf, Claims, Result, Rgb, mean_rgb};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_1_PI, PI};

/// Most lobes a Lafortune BRDF may have (the paper fits up to 3 per channel).
pub const MAX_LOBES: usize = 8;

/// Fields of one lobe; defaults make a Phong-like lobe `(−1, −1, 1)`.
pub const LOBE_FIELDS: &[ParamDecl] = &[
    ParamDecl {
        id: "cx",
        label: "Cx",
        doc: "Weight of wi.x·wo.x (−1: mirror-like, +1: retro-reflective)",
        kind: ParamKind::Float(FloatSpec::linear(-1.0, 1.0, -1.0)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "cy",
        label: "Cy",
        doc: "Weight of wi.y·wo.y (Cx ≠ Cy: anisotropic)",
        kind: ParamKind::Float(FloatSpec::linear(-1.0, 1.0, -1.0)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "cz",
        label: "Cz",
        doc: "Weight of wi.z·wo.z (|Cz| < |Cx|: off-specular peak)",
        kind: ParamKind::Float(FloatSpec::linear(-1.0, 1.0, 1.0)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "n",
        label: "n",
        doc: "Lobe exponent",
        kind: ParamKind::Float(FloatSpec::log(0.0, 10000.0, 20.0, 1.0, 1000.0)),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "ks",
        label: "ks",
        doc: "Lobe weight (its albedo at normal incidence for the (−1, −1, 1) lobe)",
        kind: ParamKind::Color(ColorSpec::range(0.0, 10.0, [0.3, 0.3, 0.3])),
        applies: Applies::Always,
    },
];

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "kd",
        label: "kd",
        doc: "Diffuse albedo (the diffuse term is kd/π)",
        kind: ParamKind::Color(ColorSpec::unit_range([0.5, 0.5, 0.5])),
        applies: Applies::Always,
    },
    ParamDecl {
        id: "lobes",
        label: "lobes",
        doc: "Generalised cosine lobes {cx, cy, cz, n, ks}",
        kind: ParamKind::List {
            fields: LOBE_FIELDS,
            min_items: 0,
            max_items: MAX_LOBES,
            default_items: 1,
        },
        applies: Applies::Always,
    },
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "lafortune",
    name: "Lafortune",
    summary: "Sum of generalised cosine lobes: reciprocal, off-specular, retro-reflective or anisotropic",
    citation: "Lafortune, Foo, Torrance & Greenberg 1997, \"Non-linear approximation of reflectance functions\", eq. 4",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::lafortune",
            "shaders/models/lafortune.wgsl",
            include_str!("../../../../shaders/models/lafortune.wgsl"),
        )
        .with_sampling_lobe(),
    ),
};

/// One generalised cosine lobe.
#[derive(Debug, Clone, Copy)]
struct Lobe {
    /// `(cx, cy, cz)`.
    c: DVec3,
    /// Exponent.
    n: f64,
    /// Weight.
    ks: Rgb,
    /// `(n+2)/(2π)`.
    norm: f64,
}

impl Lobe {
    /// `cx wi.x wo.x + cy wi.y wo.y + cz wi.z wo.z`, with the products of
    /// direction components formed first so that it is exactly symmetric in
    /// `wi` and `wo` (reciprocity holds bit for bit).
    #[inline]
    fn base(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.c.x * (wi.x * wo.x) + self.c.y * (wi.y * wo.y) + self.c.z * (wi.z * wo.z)
    }

    /// Upper bound of the lobe's directional albedo, `ks · max|c|^n` (see
    /// [`Lafortune::claims`]).
    fn albedo_bound(&self) -> Rgb {
        self.ks * self.c.abs().max_element().powf(self.n)
    }
}

/// Lafortune BRDF.
#[derive(Debug, Clone)]
pub struct Lafortune {
    kd: Rgb,
    lobes: Vec<Lobe>,
    kernel: LafortuneLanes,
}

/// [`Lafortune`]'s f32 batch kernel: `kd/π + Σ ks norm clamped_pow(C wi · wo,
/// n)` over the first `count` of [`MAX_LOBES`] slots (see [`Lobes`]). Each
/// base is formed in f64 lanes and its power taken from `1 − base`
/// ([`math::pow_1m`]), which keeps large exponents accurate near the peak.
#[derive(Debug, Clone, Copy)]
struct LafortuneLanes {
    diffuse: [f32; 3],
    c: [[f64; 3]; MAX_LOBES],
    n: [f32; MAX_LOBES],
    /// `ks · norm` per lobe and channel.
    scale: [[f32; 3]; MAX_LOBES],
    /// Lobes in use (the first `count` slots).
    count: usize,
}

impl LafortuneLanes {
    fn new(kd: Rgb, lobes: &[Lobe]) -> Self {
        let mut k = Self {
            diffuse: math::rgb(kd * FRAC_1_PI),
            c: [[0.0; 3]; MAX_LOBES],
            n: [0.0; MAX_LOBES],
            scale: [[0.0; 3]; MAX_LOBES],
            count: lobes.len().min(MAX_LOBES),
        };
        for (j, l) in lobes.iter().take(MAX_LOBES).enumerate() {
            k.c[j] = l.c.to_array();
            k.n[j] = l.n as f32;
            k.scale[j] = math::rgb(l.ks * l.norm);
        }
        k
    }
}

impl LafortuneLanes {
    /// One lane with the first `L` lobes (the rest are unused slots).
    #[inline(always)]
    fn lane_with<const L: usize, V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let p: [V::Wide; 3] = math::channels!(|c| wi[c].widen() * wo[c].widen());
        let mut f = math::splat3::<V>(self.diffuse);
        for j in 0..L.min(MAX_LOBES) {
            let c = self.c[j];
            let x = p[0] * c[0] + p[1] * c[1] + p[2] * c[2];
            let lobe = math::pow_1m(V::narrow(x), V::narrow(x.one_minus()), self.n[j]);
            for (k, fk) in f.iter_mut().enumerate() {
                *fk += lobe * self.scale[j][k];
            }
        }
        let above = wi[2].gt(V::splat(0.0)) & wo[2].gt(V::splat(0.0));
        math::channels!(|c| above.select(f[c], V::splat(0.0)))
    }
}

/// [`LafortuneLanes`] compiled for exactly `L` lobes: each power costs an
/// `exp` and a `ln` per lane, so the eight fixed slots of a one-lobe model
/// would cost eight times its work. The lobe count is a const parameter so
/// that the lobe loop has a constant trip count and is unrolled.
#[derive(Debug)]
struct Lobes<const L: usize>(LafortuneLanes);

impl<const L: usize> LaneKernel for Lobes<L> {
    #[inline(always)]
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        self.0.lane_with::<L, V>(wi, wo)
    }
}

impl Kernel for LafortuneLanes {
    fn eval(&self, isa: Isa, dirs: &Dirs<'_>, out: &mut Out<'_>) {
        match self.count {
            0 => batch::run(&Lobes::<0>(*self), isa, dirs, out),
            1 => batch::run(&Lobes::<1>(*self), isa, dirs, out),
            2 => batch::run(&Lobes::<2>(*self), isa, dirs, out),
            3 => batch::run(&Lobes::<3>(*self), isa, dirs, out),
            4 => batch::run(&Lobes::<4>(*self), isa, dirs, out),
            5 => batch::run(&Lobes::<5>(*self), isa, dirs, out),
            6 => batch::run(&Lobes::<6>(*self), isa, dirs, out),
            7 => batch::run(&Lobes::<7>(*self), isa, dirs, out),
            _ => batch::run(&Lobes::<MAX_LOBES>(*self), isa, dirs, out),
        }
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    let lobes = p
        .list("lobes")?
        .iter()
        .map(|l| {
            let n = l.float("n")?;
            Ok(Lobe {
                c: DVec3::new(l.float("cx")?, l.float("cy")?, l.float("cz")?),
                n,
                ks: l.color("ks")?,
                norm: (n + 2.0) / (2.0 * PI),
            })
        })
        .collect::<Result<Vec<_>>>()?;
    let kd = p.color("kd")?;
    Ok(Box::new(Lafortune {
        kd,
        kernel: LafortuneLanes::new(kd, &lobes),
        lobes,
    }))
}

impl Lafortune {
    /// Sampling lobes at `wi`. Lobe `j` is, as a function of `wo`,
    /// `(v·wo)^n` with `v = C wi`: a power-cosine lobe about `v/|v|` scaled by
    /// `|v|^n`. Its selection weight is its albedo bound `ks |v|^n` (mean
    /// channel); a lobe with `v = 0` is identically 0 and gets weight 0.
    fn sampling_lobes(&self, wi: DVec3) -> ([PowerLobe; MAX_LOBES], usize) {
        let mut out = [PowerLobe {
            axis: DVec3::Z,
            e: 0.0,
            weight: 0.0,
        }; MAX_LOBES];
        let mut k = 0;
        for l in self.lobes.iter().take(MAX_LOBES) {
            let v = l.c * wi;
            let len = v.length();
            if len > 0.0 && len.is_finite() {
                out[k] = PowerLobe {
                    axis: v / len,
                    e: l.n,
                    weight: mean_rgb(l.ks) * len.min(1.0).powf(l.n),
                };
                k += 1;
            }
        }
        (out, k)
    }
}

impl Brdf for Lafortune {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        Some(&self.kernel)
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let mut f = self.kd * FRAC_1_PI;
        for l in &self.lobes {
            f += l.ks * (l.norm * clamped_pow(l.base(wi, wo), l.n));
        }
        f
    }

    /// Each lobe `(C wi · wo)^n` peaks at `wo = C wi / |C wi|`.
    fn peaks(&self, wi: DVec3) -> Vec<DVec3> {
        self.lobes
            .iter()
            .filter_map(|l| (l.c * wi).try_normalize())
            .filter(|v| v.z > 0.0)
            .collect()
    }

    /// With one lobe that contributes (`ks ≠ 0`), `f` depends on `wo`
    /// through `C wi · wo` alone, so it is constant on every ring about
    /// `C wi / |C wi|`: the albedo quadrature integrates in polar
    /// coordinates about it when it lies above the horizon (a Phong lobe
    /// `(−1, −1, 1)` about the mirror direction, a retro-reflective one
    /// `(1, 1, 1)` about `wi`). Lobes about different axes have no common
    /// pole.
    fn pole(&self, wi: DVec3) -> Option<DVec3> {
        let mut lit = self.lobes.iter().filter(|l| l.ks.max_element() != 0.0);
        let (Some(l), None) = (lit.next(), lit.next()) else {
            return None;
        };
        (l.c * wi).try_normalize().filter(|v| v.z > 0.0)
    }

    /// Each lobe's clamp `max(0, C wi · wo)` switches branch where the base
    /// turns negative (a kink for exponents near 1 or below).
    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        self.lobes
            .iter()
            .filter(|l| l.ks.max_element() != 0.0)
            .map(|l| -> crate::Kink<'_> {
                let v = l.c * wi;
                Box::new(move |wo: DVec3| v.dot(wo))
            })
            .collect()
    }

    /// Reciprocal: each lobe's base is symmetric in `wi` and `wo`.
    ///
    /// Isotropic when every lobe that contributes (`ks ≠ 0`) has `cx = cy`:
    /// then `cx (wi.x wo.x + wi.y wo.y)` is invariant under a common rotation
    /// about z.
    ///
    /// Energy (a sufficient condition, claimed only when it holds):
    /// `kd + Σ_j ks_j · max(|cx_j|, |cy_j|, |cz_j|)^n_j ≤ 1` per channel.
    /// Proof: with `v = C wi = (cx wi.x, cy wi.y, cz wi.z)`, the lobe is
    /// `(v·wo)₊^n`, and `|v| ≤ max|c| · |wi| = max|c|`. Its albedo is
    /// `ks (n+2)/(2π) |v|^n ∫ (v̂·wo)₊^n cosθo dωo ≤ ks |v|^n ≤ ks max|c|^n`
    /// by the lemma in [`super::lobes`] (`∫ (r·w)₊^n (n·w)₊ dω ≤ 2π/(n+2)` for
    /// any unit `r`); for `v = 0` the lobe is 0. The diffuse albedo is `kd`.
    /// When the condition fails the model may still conserve energy (the bound
    /// is not tight for lobes tilted away from the normal); it is then simply
    /// not claimed.
    fn claims(&self) -> Claims {
        let bound = self
            .lobes
            .iter()
            .fold(self.kd, |acc, l| acc + l.albedo_bound());
        Claims {
            reciprocal: true,
            energy_conserving: bound.max_element() <= 1.0,
            isotropic: self
                .lobes
                .iter()
                .all(|l| l.ks.max_element() == 0.0 || l.c.x == l.c.y),
        }
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z <= 0.0 {
            return None;
        }
        let (lobes, k) = self.sampling_lobes(wi);
        Mixture {
            diffuse: mean_rgb(self.kd),
            lobes: &lobes[..k],
        }
        .sample(u)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 {
            return 0.0;
        }
        let (lobes, k) = self.sampling_lobes(wi);
        Mixture {
            diffuse: mean_rgb(self.kd),
            lobes: &lobes[..k],
        }
        .pdf(wo)
    }
}

#[cfg(test)]
mod tests {
    use super::super::lobes::testing::*;
    use super::*;
    use crate::ModelSpec;
    use crate::frame::{self, from_spherical};
    use proptest::prelude::*;
    use serde_json::{Value, json};

    fn model(kd: f64, lobes: Value) -> Box<dyn Brdf> {
        build_model("lafortune", json!({"kd": kd, "lobes": lobes}))
    }

    #[test]
    fn default_is_one_phong_lobe() {
        let b = build_model("lafortune", json!({}));
        let wi = from_spherical(0.4, 0.0);
        let f = b.eval(wi, frame::reflect(wi)).x;
        let want = 0.5 / PI + 0.3 * 22.0 / (2.0 * PI);
        assert!((f - want).abs() < 1e-13 * want);
        assert!(b.claims().energy_conserving && b.claims().isotropic);
    }

    #[test]
    fn phong_lobe_equals_modified_phong() {
        // (−1, −1, 1): cx wi.x wo.x + … = R(wo)·wi, so the model is
        // modified-phong with e = n, ks = ks.
        let lf = build_model(
            "lafortune",
            json!({"kd": [0.2, 0.3, 0.4], "lobes": [{"cx": -1, "cy": -1, "cz": 1, "n": 33, "ks": [0.5, 0.1, 0.0]}]}),
        );
        let mp = build_model(
            "modified-phong",
            json!({"kd": [0.2, 0.3, 0.4], "ks": [0.5, 0.1, 0.0], "e": 33}),
        );
        let mut rng = crate::sampling::rng(11);
        for _ in 0..1000 {
            let wi = crate::sampling::cosine_hemisphere(crate::sampling::uniform2(&mut rng));
            let wo = crate::sampling::cosine_hemisphere(crate::sampling::uniform2(&mut rng));
            assert!(rel_diff(lf.eval(wi, wo), mp.eval(wi, wo)) < 1e-12);
            assert!((lf.pdf(wi, wo) - mp.pdf(wi, wo)).abs() < 1e-12 * mp.pdf(wi, wo));
        }
    }

    #[test]
    fn retro_reflective_lobe() {
        // (1, 1, 1): the base is wi·wo, 1 at wo = wi (back towards the light),
        // and cos 2θ at the mirror direction.
        let (ks, n) = (0.7, 10.0);
        let b = model(0.0, json!([{"cx": 1, "cy": 1, "cz": 1, "n": n, "ks": ks}]));
        let theta = 0.3f64;
        let wi = from_spherical(theta, 1.0);
        let norm = (n + 2.0) / (2.0 * PI);
        assert!((b.eval(wi, wi).x - ks * norm).abs() < 1e-13);
        let mirror = b.eval(wi, frame::reflect(wi)).x;
        assert!((mirror - ks * norm * (2.0 * theta).cos().powf(n)).abs() < 1e-13);
    }

    #[test]
    fn off_specular_peak() {
        // (−0.5, −0.5, 1) at wi = (sinθ, 0, cosθ): v = C wi = (−0.5 sinθ, 0, cosθ),
        // the lobe (v·wo)^n peaks at wo = v/|v| (closer to the normal than the
        // mirror direction) with value ks (n+2)/(2π) |v|^n.
        let (ks, n, theta) = (2.0, 8.0, 1.0f64);
        let b = model(
            0.0,
            json!([{"cx": -0.5, "cy": -0.5, "cz": 1, "n": n, "ks": ks}]),
        );
        let wi = from_spherical(theta, 0.0);
        let v = DVec3::new(-0.5 * theta.sin(), 0.0, theta.cos());
        let len = (0.25 * theta.sin().powi(2) + theta.cos().powi(2)).sqrt();
        let peak = v / len;
        let want = ks * (n + 2.0) / (2.0 * PI) * len.powf(n);
        assert!((b.eval(wi, peak).x - want).abs() < 1e-12 * want);
        // Peak elevation: tan = 0.5 tanθ, below the mirror's θ.
        assert!((peak.x.atan2(peak.z).abs() - (0.5 * theta.tan()).atan()).abs() < 1e-12);
        for d in [from_spherical(0.05, 0.0), from_spherical(0.05, 1.6)] {
            let nearby = (peak + d - DVec3::Z).normalize();
            assert!(b.eval(wi, nearby).x < want);
        }
    }

    #[test]
    fn lobes_add_up() {
        let a = json!({"cx": -1, "cy": -1, "cz": 1, "n": 5, "ks": 0.4});
        let r = json!({"cx": 0.8, "cy": 0.8, "cz": 0.6, "n": 3, "ks": [1.0, 2.0, 3.0]});
        let both = model(0.25, json!([a.clone(), r.clone()]));
        let only_a = model(0.25, json!([a]));
        let only_r = model(0.0, json!([r]));
        let wi = from_spherical(0.5, 0.2);
        let wo = from_spherical(0.9, 0.7);
        let sum = only_a.eval(wi, wo) + only_r.eval(wi, wo);
        assert!(rel_diff(both.eval(wi, wo), sum) < 1e-14);
        // No lobes: Lambertian kd/π.
        let none = model(0.6, json!([]));
        assert!((none.eval(wi, wo).x - 0.6 / PI).abs() < 1e-15);
    }

    #[test]
    fn anisotropy_claim_and_behaviour() {
        let rz = |w: DVec3, a: f64| {
            let (s, c) = a.sin_cos();
            DVec3::new(c * w.x - s * w.y, s * w.x + c * w.y, w.z)
        };
        let wi = from_spherical(0.6, 0.3);
        let wo = from_spherical(0.8, 2.5);
        let aniso = model(
            0.1,
            json!([{"cx": -1, "cy": -0.3, "cz": 0.8, "n": 6, "ks": 0.5}]),
        );
        assert!(!aniso.claims().isotropic);
        assert!(rel_diff(aniso.eval(rz(wi, 0.9), rz(wo, 0.9)), aniso.eval(wi, wo)) > 0.01);
        let iso = model(
            0.1,
            json!([{"cx": -0.7, "cy": -0.7, "cz": 0.8, "n": 6, "ks": 0.5}]),
        );
        assert!(iso.claims().isotropic);
        assert!(rel_diff(iso.eval(rz(wi, 0.9), rz(wo, 0.9)), iso.eval(wi, wo)) < 1e-12);
        // An anisotropic lobe with ks = 0 contributes nothing.
        let dead = model(
            0.1,
            json!([{"cx": -1, "cy": -0.3, "cz": 0.8, "n": 6, "ks": 0.0}]),
        );
        assert!(dead.claims().isotropic);
    }

    #[test]
    fn energy_claims() {
        let angles = [0.0f64, 30.0, 60.0, 80.0, 88.0];
        // Bound kd + ks = 1 for the Phong lobe: claimed, holds.
        let b = model(
            0.5,
            json!([{"cx": -1, "cy": -1, "cz": 1, "n": 20, "ks": 0.5}]),
        );
        assert!(b.claims().energy_conserving);
        for deg in angles {
            let a = albedo(&*b, from_spherical(deg.to_radians(), 0.0), 1000, 600).x;
            assert!(a <= 1.0 + 1e-3, "θ {deg}: {a}");
        }
        // ks = 2 > 1 but |c| = 0.9: bound 0.3 + 2·0.9^10 = 0.997: claimed, holds.
        let b = model(
            0.3,
            json!([{"cx": -0.9, "cy": -0.9, "cz": 0.9, "n": 10, "ks": 2}]),
        );
        assert!(b.claims().energy_conserving);
        for deg in angles {
            let a = albedo(&*b, from_spherical(deg.to_radians(), 0.0), 1000, 600).x;
            assert!(a <= 1.0 + 1e-3, "θ {deg}: {a}");
        }
        // Bound 1.1: not claimed, and indeed violated at normal incidence
        // (ρhd(0) = kd + ks for the Phong lobe).
        let b = model(
            0.6,
            json!([{"cx": -1, "cy": -1, "cz": 1, "n": 20, "ks": 0.5}]),
        );
        assert!(!b.claims().energy_conserving);
        assert!(albedo(&*b, DVec3::Z, 2000, 8).x > 1.09);
        assert!(b.claims().reciprocal);
    }

    #[test]
    fn lobe_list_is_validated() {
        let lobe = json!({"cx": -1, "cy": -1, "cz": 1, "n": 5, "ks": 0.4});
        let eight: Vec<Value> = vec![lobe.clone(); MAX_LOBES];
        assert!(ModelSpec::from_json("lafortune", &json!({"lobes": eight})).is_ok());
        let nine: Vec<Value> = vec![lobe; MAX_LOBES + 1];
        assert!(ModelSpec::from_json("lafortune", &json!({"lobes": nine})).is_err());
        let err = ModelSpec::from_json("lafortune", &json!({"lobes": [{"cx": 1.5}]})).unwrap_err();
        assert!(err.to_string().contains("lobes[0].cx"), "{err}");
        assert!(ModelSpec::from_json("lafortune", &json!({"lobes": [{"ks": 10.0}]})).is_ok());
        assert!(ModelSpec::from_json("lafortune", &json!({"lobes": [{"ks": 10.5}]})).is_err());
        assert!(ModelSpec::from_json("lafortune", &json!({"lobes": [{"n": -1}]})).is_err());
        assert!(ModelSpec::from_json("lafortune", &json!({"lobes": [{"q": 1}]})).is_err());
        // Omitted fields take the lobe defaults (a Phong lobe).
        let b = model(0.0, json!([{"n": 4, "ks": 1}]));
        let wi = from_spherical(0.7, 0.0);
        assert!((b.eval(wi, frame::reflect(wi)).x - 6.0 / (2.0 * PI)).abs() < 1e-14);
    }

    #[test]
    fn sampling_agrees_with_pdf() {
        let lobes = json!([
            {"cx": -1, "cy": -1, "cz": 1, "n": 30, "ks": 0.4},
            {"cx": 0.9, "cy": 0.9, "cz": 0.9, "n": 5, "ks": 0.5},
            {"cx": -1, "cy": -0.2, "cz": 0.4, "n": 200, "ks": 1.5},
        ]);
        let b = model(0.4, lobes);
        for theta in [0.0, 0.6, 1.3] {
            check_sampling(&*b, from_spherical(theta, 0.3));
        }
    }

    fn lobe_strategy() -> impl Strategy<Value = Value> {
        let c = || prop_oneof![1 => Just(-1.0), 1 => Just(1.0), 1 => Just(0.0), 4 => -1.0..=1.0f64];
        (c(), c(), c(), exponent(), colour(10.0))
            .prop_map(|(cx, cy, cz, n, ks)| json!({"cx": cx, "cy": cy, "cz": cz, "n": n, "ks": ks}))
    }

    proptest! {
        #[test]
        fn finite_nonnegative_and_reciprocal(
            kd in colour(1.0),
            lobes in proptest::collection::vec(lobe_strategy(), 0..=MAX_LOBES),
            wi in direction(), wo in direction(),
        ) {
            let b = build_model("lafortune", json!({"kd": kd, "lobes": lobes}));
            let f = b.eval(wi, wo);
            assert_finite_nonneg(f, "lafortune");
            assert_finite_nonneg(b.eval(wi, wi), "at wi");
            assert_finite_nonneg(b.eval(wi, frame::reflect(wi)), "at mirror");
            prop_assert!(rel_diff(f, b.eval(wo, wi)) < 1e-6);
            let p = b.pdf(wi, wo);
            prop_assert!(p.is_finite() && p >= 0.0);
        }
    }
}
