//! Mix: a weighted sum of catalogue models, `f = Σ w_j f_j`. This is the seed's
//! "complex BRDF" (a combination of diffuse and specular parts) and its
//! linearity property of BRDFs (seed, "BRDF Property 1"; Sillion, Arvo, Westin
//! & Greenberg 1991).

use crate::model::{Build, ModelInfo};
use crate::params::MAX_NESTING;
use crate::params::decl::{Applies, FloatSpec, ParamDecl, ParamKind};
use crate::params::value::{Component, ModelSpec, ParamValue, Params};
use crate::{Brdf, BvError, Claims, DeltaLobe, Result, Rgb};
use glam::{DVec2, DVec3};

/// Most components one mix accepts.
pub const MAX_COMPONENTS: usize = 8;

/// Weight range of one component (`mix` weights 0..10).
const WEIGHT: FloatSpec = FloatSpec::linear(0.0, 10.0, 1.0);

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[ParamDecl {
    id: "components",
    label: "components",
    doc: "Weighted models whose BRDFs are summed: [{weight, model, params}, …]",
    kind: ParamKind::Components {
        max_items: MAX_COMPONENTS,
        weight: WEIGHT,
        default: default_components,
    },
    applies: Applies::Always,
}];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "mix",
    name: "Mix",
    summary: "Weighted sum of other models (BRDFs are linear)",
    citation: "Linearity of BRDFs: Sillion, Arvo, Westin & Greenberg 1991; the lecture's complex BRDF",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: None,
};

/// The default component list: the seed's "complex BRDF" as a sum of a
/// diffuse and a glossy part (0.6 · orange Lambert + 0.4 · pure-specular GGX
/// Cook-Torrance), built from the declarations directly so that it cannot fail.
fn default_components() -> Vec<Component> {
    let component = |weight: f64, info: &'static ModelInfo, set: &[(&str, ParamValue)]| {
        let mut params = Params::defaults(info.params);
        for (k, v) in set {
            params.insert((*k).to_string(), v.clone());
        }
        Component {
            weight,
            spec: ModelSpec::from_parts(info, params),
        }
    };
    vec![
        component(
            0.6,
            &super::lambert::INFO,
            &[("albedo", ParamValue::Color([0.8, 0.3, 0.1]))],
        ),
        component(
            0.4,
            &super::cook_torrance::INFO,
            &[
                ("kd", ParamValue::Color([0.0; 3])),
                ("ks", ParamValue::Float(1.0)),
                ("distribution", ParamValue::Text("ggx".into())),
                ("geometry", ParamValue::Text("smith-correlated".into())),
                ("alpha_x", ParamValue::Float(0.2)),
                ("alpha_y", ParamValue::Float(0.2)),
            ],
        ),
    ]
}

/// One weighted, built component.
#[derive(Debug)]
struct Part {
    weight: f64,
    brdf: Box<dyn Brdf>,
}

/// A mix's batch kernel is the weighted sum of its parts' batches (each
/// through its own kernel, or its scalar fallback), accumulated in f32.
impl crate::batch::Kernel for Mix {
    fn eval(
        &self,
        isa: crate::batch::Isa,
        dirs: &crate::batch::Dirs<'_>,
        out: &mut crate::batch::Out<'_>,
    ) {
        let n = dirs.len().min(out.len());
        let mut parts = self.parts.iter();
        let Some(first) = parts.next() else {
            for ch in out.rgb.iter_mut() {
                ch[..n].fill(0.0);
            }
            return;
        };
        // The first part straight into `out`, scaled there; the others
        // through a scratch buffer taken from this thread (taken, not
        // borrowed: a mix inside a mix finds it empty and allocates its
        // own), so that a lobe's many small batches allocate nothing.
        {
            let [r, g, b] = &mut out.rgb;
            let mut head = crate::batch::Out {
                rgb: [&mut r[..n], &mut g[..n], &mut b[..n]],
            };
            crate::batch::eval_with(first.brdf.as_ref(), isa, dirs, &mut head);
        }
        let w = first.weight as f32;
        if w != 1.0 {
            for ch in out.rgb.iter_mut() {
                for d in &mut ch[..n] {
                    *d *= w;
                }
            }
        }
        if parts.len() == 0 {
            return;
        }
        let mut part = MIX_SCRATCH.with_borrow_mut(std::mem::take);
        for ch in &mut part {
            ch.resize(n, 0.0);
        }
        for p in parts {
            {
                let [r, g, b] = &mut part;
                let mut tmp = crate::batch::Out {
                    rgb: [&mut r[..n], &mut g[..n], &mut b[..n]],
                };
                crate::batch::eval_with(p.brdf.as_ref(), isa, dirs, &mut tmp);
            }
            let w = p.weight as f32;
            for (dst, src) in out.rgb.iter_mut().zip(&part) {
                for (d, s) in dst[..n].iter_mut().zip(src) {
                    *d += w * s;
                }
            }
        }
        MIX_SCRATCH.with_borrow_mut(|s| *s = part);
    }
}

thread_local! {
    /// [`Mix`]'s scratch channels for its second and later parts.
    static MIX_SCRATCH: std::cell::RefCell<[Vec<f32>; 3]> = const {
        std::cell::RefCell::new([Vec::new(), Vec::new(), Vec::new()])
    };
}

/// A weighted sum of models.
#[derive(Debug)]
pub struct Mix {
    /// Components of non-zero weight (zero-weight ones contribute nothing and
    /// must not affect the claims).
    parts: Vec<Part>,
    /// Σ of the weights of `parts`.
    total: f64,
}

impl Mix {
    /// A mix of already built models with the given weights (finite, ≥ 0).
    pub fn from_parts(parts: Vec<(f64, Box<dyn Brdf>)>) -> Result<Self> {
        if parts.len() > MAX_COMPONENTS {
            return Err(BvError::BadValue {
                param: "components".to_string(),
                reason: format!(
                    "has {} components; between 1 and {MAX_COMPONENTS} are accepted",
                    parts.len()
                ),
            });
        }
        let mut kept = Vec::with_capacity(parts.len());
        for (i, (weight, brdf)) in parts.into_iter().enumerate() {
            if !(WEIGHT.min..=WEIGHT.max).contains(&weight) {
                return Err(BvError::OutOfRange {
                    param: format!("components[{i}].weight"),
                    value: weight,
                    min: WEIGHT.min,
                    max: WEIGHT.max,
                });
            }
            if weight > 0.0 {
                kept.push(Part { weight, brdf });
            }
        }
        let total = kept.iter().map(|p| p.weight).sum();
        Ok(Self { parts: kept, total })
    }

    /// Probability of drawing from part `j` when sampling: proportional to its
    /// weight (an albedo estimate per part would need wi-dependent quadrature;
    /// weights are cheap, exact to state, and keep `pdf` a plain mixture).
    fn choice_probability(&self, part: &Part) -> f64 {
        part.weight / self.total
    }
}

/// Number of `mix` levels in a parameter set (1 for a mix of plain models),
/// counted without recursion so that a hostile, programmatically built nest
/// cannot overflow the stack before it is refused.
fn nesting_levels(p: &Params) -> usize {
    let mut deepest = 0;
    let mut stack: Vec<(&Params, usize)> = vec![(p, 0)];
    while let Some((params, depth)) = stack.pop() {
        deepest = deepest.max(depth);
        for (_, value) in params.iter() {
            match value {
                ParamValue::Components(cs) => {
                    // Refuse early: nothing deeper needs to be looked at.
                    if depth + 1 > MAX_NESTING {
                        return depth + 1;
                    }
                    for c in cs {
                        stack.push((c.spec.params(), depth + 1));
                    }
                    deepest = deepest.max(depth + 1);
                }
                ParamValue::List(items) => {
                    for item in items {
                        stack.push((item, depth));
                    }
                }
                _ => {}
            }
        }
    }
    deepest
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    // The parser already refuses deep nests from JSON; parameter sets made in
    // code (the GUI) arrive here unparsed, so check again before recursing.
    let levels = nesting_levels(p);
    if levels > MAX_NESTING {
        return Err(BvError::BadValue {
            param: "components".to_string(),
            reason: format!("mixes nest deeper than {MAX_NESTING} levels"),
        });
    }
    let comps = p.components("components")?;
    if comps.is_empty() {
        return Err(BvError::BadValue {
            param: "components".to_string(),
            reason: format!("has 0 components; between 1 and {MAX_COMPONENTS} are accepted"),
        });
    }
    let mut parts = Vec::with_capacity(comps.len());
    for c in comps {
        parts.push((c.weight, c.spec.build()?));
    }
    Ok(Box::new(Mix::from_parts(parts)?))
}

impl Brdf for Mix {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.parts
            .iter()
            .fold(Rgb::ZERO, |acc, p| acc + p.weight * p.brdf.eval(wi, wo))
    }

    /// The sum of the parts' batches, when at least one part has a kernel
    /// (otherwise the whole-mix scalar fallback is as fast).
    fn batch_kernel(&self) -> Option<&dyn crate::batch::Kernel> {
        self.parts
            .iter()
            .any(|p| p.brdf.batch_kernel().is_some())
            .then_some(self as &dyn crate::batch::Kernel)
    }

    fn claims(&self) -> Claims {
        // A sum of reciprocal (isotropic) functions is reciprocal (isotropic). For
        // energy, ρ = Σ w_j ρ_j ≤ Σ w_j max ρ_j ≤ 1 when every part conserves and
        // Σ w_j ≤ 1; otherwise not claimed.
        let all = |f: fn(&Claims) -> bool| self.parts.iter().all(|p| f(&p.brdf.claims()));
        // Across an interface each part obeys f(wi, wo)/ηo² = f(wo, wi)/ηi²
        // with its own η: the sum does with one η only if they agree.
        let mut etas = self.parts.iter().filter_map(|p| p.brdf.interface_eta());
        let one_interface = etas.next().is_none_or(|first| etas.all(|e| e == first));
        Claims {
            reciprocal: one_interface && all(|c| c.reciprocal),
            energy_conserving: self.total <= 1.0 && all(|c| c.energy_conserving),
            isotropic: all(|c| c.isotropic),
        }
    }

    /// The sum's claims are derived from its parts': promises only if every
    /// part's are (a mix with a measured table promises nothing).
    fn claims_declared(&self) -> bool {
        self.parts.iter().all(|p| p.brdf.claims_declared())
    }

    fn deltas(&self, wi: DVec3) -> Vec<DeltaLobe> {
        // Linearity applies to the Dirac parts too: each lobe keeps its direction
        // and kind, with weight and radiance scale multiplied by w_j.
        self.parts
            .iter()
            .flat_map(|p| {
                p.brdf.deltas(wi).into_iter().map(move |d| DeltaLobe {
                    weight: d.weight * p.weight,
                    radiance_scale: d.radiance_scale * p.weight,
                    ..d
                })
            })
            .collect()
    }

    fn transmits(&self) -> bool {
        self.parts.iter().any(|p| p.brdf.transmits())
    }

    /// The interface the parts model, when those that model one agree on
    /// its index (then the generalised reciprocity holds for the sum).
    fn interface_eta(&self) -> Option<f64> {
        let mut etas = self.parts.iter().filter_map(|p| p.brdf.interface_eta());
        let first = etas.next()?;
        etas.all(|e| e == first).then_some(first)
    }

    fn peaks(&self, wi: DVec3) -> Vec<DVec3> {
        self.parts.iter().flat_map(|p| p.brdf.peaks(wi)).collect()
    }

    fn kinks(&self, wi: DVec3) -> Vec<crate::Kink<'_>> {
        self.parts.iter().flat_map(|p| p.brdf.kinks(wi)).collect()
    }

    fn is_analytic(&self) -> bool {
        self.parts.iter().all(|p| p.brdf.is_analytic())
    }

    fn try_eval(&self, wi: DVec3, wo: DVec3) -> crate::Result<Rgb> {
        let mut sum = Rgb::ZERO;
        for p in &self.parts {
            sum += p.weight * p.brdf.try_eval(wi, wo)?;
        }
        Ok(sum)
    }

    /// The parts' failures together (the first reason of the first part
    /// that failed).
    fn health(&self) -> crate::EvalHealth {
        self.parts.iter().map(|p| p.brdf.health()).fold(
            crate::EvalHealth::default(),
            |mut acc, h| {
                acc.failed += h.failed;
                acc.non_finite += h.non_finite;
                acc.first_failure = acc.first_failure.or(h.first_failure);
                acc
            },
        )
    }

    /// An evaluation of the mix evaluates every part.
    fn eval_cost(&self) -> Option<std::time::Duration> {
        self.parts
            .iter()
            .filter_map(|p| p.brdf.eval_cost())
            .reduce(|a, b| a + b)
    }

    fn limit_time(&self, budget: Option<std::time::Duration>) {
        for p in &self.parts {
            p.brdf.limit_time(budget);
        }
    }

    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        // Pick part j with probability w_j / Σw from u.x, rescale u.x within its
        // interval to a fresh uniform, and let the part draw: the density of the
        // result is Σ_j (w_j/Σw) pdf_j, which is what `pdf` returns.
        let mut start = 0.0;
        for (j, p) in self.parts.iter().enumerate() {
            let q = self.choice_probability(p);
            let last = j + 1 == self.parts.len();
            if u.x < start + q || last {
                let ux = ((u.x - start) / q).clamp(0.0, ONE_BELOW);
                return p.brdf.sample(wi, DVec2::new(ux, u.y));
            }
            start += q;
        }
        None
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        self.parts
            .iter()
            .map(|p| self.choice_probability(p) * p.brdf.pdf(wi, wo))
            .sum()
    }

    fn eval_batch(&self, pairs: &[(DVec3, DVec3)], out: &mut [Rgb]) {
        // Part by part, so that each part's own fast batch loop is used.
        out.iter_mut().for_each(|o| *o = Rgb::ZERO);
        let mut tmp = vec![Rgb::ZERO; out.len().min(pairs.len())];
        for p in &self.parts {
            p.brdf.eval_batch(pairs, &mut tmp);
            for (o, t) in out.iter_mut().zip(&tmp) {
                *o += p.weight * *t;
            }
        }
    }
}

/// The largest f64 below 1, to keep rescaled uniforms in [0, 1).
const ONE_BELOW: f64 = 1.0 - f64::EPSILON / 2.0;

#[cfg(test)]
mod tests {
    use super::*;
    use crate::frame::{from_spherical, reflect};
    use crate::models::testkit::*;
    use crate::{DeltaKind, registry};
    use proptest::prelude::*;
    use serde_json::{Value, json};
    use std::f64::consts::PI;

    fn build_json(model: &str, p: Value) -> Box<dyn Brdf> {
        ModelSpec::from_json(model, &p).unwrap().build().unwrap()
    }

    fn mix(components: Value) -> Box<dyn Brdf> {
        build_json("mix", json!({ "components": components }))
    }

    fn pairs() -> Vec<(DVec3, DVec3)> {
        vec![
            (DVec3::Z, DVec3::Z),
            (from_spherical(0.3, 0.2), from_spherical(0.4, 3.0)),
            (from_spherical(1.2, -1.0), from_spherical(0.9, 1.7)),
            (from_spherical(1.5, 0.5), from_spherical(1.56, 0.5 + PI)),
        ]
    }

    const AS: &str = "ashikhmin-shirley";

    #[test]
    fn one_component_of_weight_one_is_the_component() {
        let p = json!({"rd": 0.3, "rs": 0.2, "nu": 40, "nv": 400});
        let single = mix(json!([{"weight": 1.0, "model": AS, "params": p}]));
        let direct = build_json(AS, p.clone());
        for (wi, wo) in pairs() {
            assert_eq!(single.eval(wi, wo), direct.eval(wi, wo));
            assert_eq!(single.pdf(wi, wo), direct.pdf(wi, wo));
        }
        assert_eq!(single.claims(), direct.claims());
        // Weight defaults to 1 when omitted.
        let implicit = mix(json!([{"model": AS, "params": p}]));
        assert_eq!(
            implicit.eval(DVec3::Z, DVec3::Z),
            direct.eval(DVec3::Z, DVec3::Z)
        );
    }

    #[test]
    fn weights_scale_and_add() {
        let a = json!({"albedo": [0.2, 0.4, 0.6], "sigma": 0.4});
        let b = json!({"w": 0.5, "g": -0.4});
        let fa = build_json("oren-nayar", a.clone());
        let fb = build_json("hapke", b.clone());
        let scaled = mix(json!([{"weight": 2.5, "model": "oren-nayar", "params": a}]));
        let sum = mix(json!([
            {"weight": 0.3, "model": "oren-nayar", "params": a},
            {"weight": 0.7, "model": "hapke", "params": b},
        ]));
        for (wi, wo) in pairs() {
            assert!(rel_close(scaled.eval(wi, wo), 2.5 * fa.eval(wi, wo), 1e-15));
            let want = 0.3 * fa.eval(wi, wo) + 0.7 * fb.eval(wi, wo);
            assert!(rel_close(sum.eval(wi, wo), want, 1e-15));
        }
    }

    #[test]
    fn nested_mix_flattens() {
        // 0.5 · (0.4 A + 0.6 B) + 0.5 C = 0.2 A + 0.3 B + 0.5 C.
        let a = json!({"model": "lambert", "params": {"albedo": 0.9}});
        let b = json!({"model": AS, "params": {"nu": 10, "nv": 200}});
        let c = json!({"model": "hapke", "params": {}});
        let with = |w: f64, x: &Value| {
            let mut x = x.clone();
            x["weight"] = json!(w);
            x
        };
        let nested = mix(json!([
            {"weight": 0.5, "model": "mix", "params": {"components": [with(0.4, &a), with(0.6, &b)]}},
            with(0.5, &c),
        ]));
        let flat = mix(json!([with(0.2, &a), with(0.3, &b), with(0.5, &c)]));
        for (wi, wo) in pairs() {
            assert!(rel_close(nested.eval(wi, wo), flat.eval(wi, wo), 1e-14));
            assert!((nested.pdf(wi, wo) - flat.pdf(wi, wo)).abs() <= 1e-14 * flat.pdf(wi, wo));
        }
    }

    /// `levels` mixes, each holding the next one, the innermost holding a Lambert.
    fn nested_json(levels: usize) -> Value {
        let mut inner = json!({"model": "lambert", "params": {"albedo": 0.5}});
        for _ in 0..levels {
            inner = json!({"weight": 1.0, "model": "mix", "params": {"components": [inner]}});
        }
        inner
    }

    #[test]
    fn nesting_depth_is_limited() {
        // MAX_NESTING levels of mix are accepted, one more is refused.
        let ok = nested_json(MAX_NESTING);
        let spec = ModelSpec::from_json("mix", &ok["params"]).unwrap();
        let f = spec.build().unwrap().eval(DVec3::Z, DVec3::Z);
        assert!((f.x - 0.5 / PI).abs() < 1e-15);
        let deep = nested_json(MAX_NESTING + 1);
        let err = ModelSpec::from_json("mix", &deep["params"]).unwrap_err();
        assert!(err.to_string().contains("nest deeper"), "{err}");

        // A nest built inside the crate bypasses the parser; build refuses it too.
        let mut spec = ModelSpec::new("lambert").unwrap();
        for _ in 0..(MAX_NESTING + 1) {
            let mut params = Params::default();
            params.insert(
                "components".into(),
                ParamValue::Components(vec![Component { weight: 1.0, spec }]),
            );
            spec = ModelSpec::from_parts(&INFO, params);
        }
        let err = spec.build().unwrap_err();
        assert!(err.to_string().contains("nest deeper"), "{err}");
        // Far deeper still fails cleanly (no recursion before the check).
        for _ in 0..10_000 {
            let mut params = Params::default();
            params.insert(
                "components".into(),
                ParamValue::Components(vec![Component { weight: 1.0, spec }]),
            );
            spec = ModelSpec::from_parts(&INFO, params);
        }
        assert!(spec.build().is_err());
        // Dropping a 10 000-deep nest recurses in Drop; leak it instead so the
        // test does not depend on the test thread's stack size.
        std::mem::forget(spec);
    }

    #[test]
    fn unknown_model_in_a_component_is_a_clear_error() {
        let err =
            ModelSpec::from_json("mix", &json!({"components": [{"model": "nope"}]})).unwrap_err();
        assert!(
            matches!(&err, BvError::UnknownModel { id, .. } if id == "nope"),
            "{err}"
        );
        assert!(err.to_string().contains("unknown model `nope`"), "{err}");
        // (A spec holds its model, so a component of an unknown model cannot
        // be made in code either.)
        // Other malformed components.
        for bad in [
            json!({"components": []}),
            json!({"components": [{"model": "lambert", "weight": 11.0}]}),
            json!({"components": [{"model": "lambert", "colour": 1.0}]}),
            json!({"components": [{"model": "lambert", "params": {"albedo": 2.0}}]}),
            json!({"components": [{"weight": 1.0}]}),
        ] {
            assert!(ModelSpec::from_json("mix", &bad).is_err(), "{bad}");
        }
    }

    #[test]
    fn default_is_diffuse_plus_glossy_and_round_trips() {
        let spec = ModelSpec::new("mix").unwrap();
        let comps = spec.params().components("components").unwrap();
        assert_eq!(comps.len(), 2);
        assert!(comps.iter().all(|c| registry::find(c.spec.id()).is_ok()));
        let b = spec.build().unwrap();
        // Lambert part 0.6 · (0.8, 0.3, 0.1)/π. At wi = wo = n the GGX part is
        // F(1) D(n) G / 4 with F(1) = ((1.5 − 1)/(1.5 + 1))² = 0.04 (the default
        // dielectric), D(n) = 1/(π α²) = 1/(0.04 π), G = 1: exactly 1/(4π),
        // weighted by 0.4.
        let want = (Rgb::new(0.8, 0.3, 0.1) * 0.6 + Rgb::splat(0.4 / 4.0)) / PI;
        assert!(rel_close(b.eval(DVec3::Z, DVec3::Z), want, 1e-12));
        assert!(b.claims().energy_conserving);
        let back = ModelSpec::from_json("mix", &spec.to_json()["params"]).unwrap();
        assert_eq!(back, spec);
    }

    /// A test double: a non-reciprocal, non-conserving model with one delta lobe.
    #[derive(Debug)]
    struct Odd;
    impl Brdf for Odd {
        fn id(&self) -> &'static str {
            "odd"
        }
        fn eval(&self, wi: DVec3, _wo: DVec3) -> Rgb {
            Rgb::splat(wi.z.max(0.0))
        }
        fn claims(&self) -> Claims {
            Claims {
                reciprocal: false,
                energy_conserving: false,
                isotropic: true,
            }
        }
        fn deltas(&self, wi: DVec3) -> Vec<DeltaLobe> {
            vec![DeltaLobe {
                direction: reflect(wi),
                weight: Rgb::splat(0.5),
                radiance_scale: Rgb::splat(0.5),
                kind: DeltaKind::Reflection,
            }]
        }
    }

    fn lambert(albedo: f64) -> Box<dyn Brdf> {
        build_json("lambert", json!({ "albedo": albedo }))
    }

    #[test]
    fn claims_follow_the_components() {
        let c = |parts: Vec<(f64, Box<dyn Brdf>)>| Mix::from_parts(parts).unwrap().claims();
        assert!(c(vec![(0.5, lambert(1.0)), (0.5, lambert(0.2))]).energy_conserving);
        // Σw > 1 with albedo-1 parts: not claimed.
        assert!(!c(vec![(0.6, lambert(1.0)), (0.6, lambert(1.0))]).energy_conserving);
        // Two interfaces of different η: no single generalised reciprocity.
        let rough = |eta: f64| -> Box<dyn Brdf> {
            ModelSpec::from_json("rough-dielectric", &serde_json::json!({"eta": eta}))
                .unwrap()
                .build()
                .unwrap()
        };
        let same = Mix::from_parts(vec![
            (0.5, rough(1.5)),
            (0.5, rough(1.5)),
            (0.2, lambert(0.5)),
        ])
        .unwrap();
        assert!(same.claims().reciprocal && same.interface_eta() == Some(1.5));
        let two = Mix::from_parts(vec![(0.5, rough(1.5)), (0.5, rough(1.3))]).unwrap();
        assert!(!two.claims().reciprocal && two.interface_eta().is_none());
        let odd = c(vec![(0.5, lambert(1.0)), (0.1, Box::new(Odd))]);
        assert!(!odd.reciprocal && !odd.energy_conserving && odd.isotropic);
        // A zero-weight component does not count.
        let zero = c(vec![(0.5, lambert(1.0)), (0.0, Box::new(Odd))]);
        assert!(zero.reciprocal && zero.energy_conserving);
        let aniso = build_json(AS, json!({"nu": 1, "nv": 100}));
        assert!(!c(vec![(1.0, lambert(0.5)), (1.0, aniso)]).isotropic);
        assert!(Mix::from_parts(vec![(f64::NAN, lambert(0.5))]).is_err());
        assert!(Mix::from_parts(vec![(-1.0, lambert(0.5))]).is_err());
    }

    #[test]
    fn deltas_are_the_weighted_union() {
        let m = Mix::from_parts(vec![
            (2.0, Box::new(Odd)),
            (0.5, lambert(1.0)),
            (0.25, Box::new(Odd)),
        ])
        .unwrap();
        let wi = from_spherical(0.5, 0.3);
        let d = m.deltas(wi);
        assert_eq!(d.len(), 2);
        assert_eq!(d[0].weight, Rgb::splat(1.0));
        assert_eq!(d[1].radiance_scale, Rgb::splat(0.125));
        assert!((d[0].direction - reflect(wi)).length() < 1e-15);
        assert_eq!(d[1].kind, DeltaKind::Reflection);
    }

    #[test]
    fn all_zero_weights_are_black_and_unsampled() {
        let m = Mix::from_parts(vec![(0.0, lambert(1.0))]).unwrap();
        assert_eq!(m.eval(DVec3::Z, DVec3::Z), Rgb::ZERO);
        assert_eq!(m.sample(DVec3::Z, DVec2::new(0.3, 0.3)), None);
        assert_eq!(m.pdf(DVec3::Z, DVec3::Z), 0.0);
    }

    #[test]
    fn sampling_matches_pdf() {
        let m = mix(json!([
            {"weight": 0.3, "model": "lambert"},
            {"weight": 1.2, "model": AS, "params": {"rd": 0.1, "rs": 0.8, "nu": 300, "nv": 30}},
            {"weight": 0.5, "model": "oren-nayar"},
        ]));
        for &t in &[0.2, 1.0, 1.45] {
            let wi = from_spherical(t, 0.9);
            // E[g/pdf] = ∫ cos θo (1 + x/2) dωo = π.
            let (est, se) =
                sampled_integral(m.as_ref(), wi, |w| w.z * (1.0 + 0.5 * w.x), 200_000, 21);
            assert!((est - PI).abs() < 5.0 * se + 1e-9, "θi {t}: {est} ± {se}");
            // ∫ pdf = probability that a draw succeeds (quadrature error ~1e-4,
            // binomial 5σ ≤ 4e-3).
            let i = hemisphere_integral(|wo| m.pdf(wi, wo), 1000, 1000);
            let ok = success_rate(m.as_ref(), wi, 400_000, 4);
            assert!((i - ok).abs() < 4e-3, "θi {t}: ∫pdf {i}, success {ok}");
        }
    }

    proptest! {
        #[test]
        fn finite_nonneg_reciprocal_and_batched(
            w in proptest::collection::vec(0.0..=10.0f64, 4),
            nu in 0.0..=10000.0f64, sigma in 0.0..=1.5f64, g in -1.0..=1.0f64,
            wi in upper_dir(), wo in upper_dir(),
        ) {
            let m = mix(json!([
                {"weight": w[0], "model": "lambert", "params": {"albedo": 1.0}},
                {"weight": w[1], "model": AS, "params": {"nu": nu, "nv": 10000.0 - nu}},
                {"weight": w[2], "model": "oren-nayar", "params": {"sigma": sigma}},
                {"weight": w[3], "model": "hapke", "params": {"g": g, "b0": 10.0, "w": 1.0}},
            ]));
            let f = m.eval(wi, wo);
            prop_assert!(finite_nonneg(f), "{f}");
            prop_assert!(m.claims().reciprocal);
            prop_assert!(rel_close(f, m.eval(wo, wi), 1e-6));
            let mut out = [Rgb::splat(-1.0); 2];
            m.eval_batch(&[(wi, wo), (wo, wi)], &mut out);
            prop_assert!(rel_close(out[0], f, 1e-15) && rel_close(out[1], m.eval(wo, wi), 1e-15));
            let p = m.pdf(wi, wo);
            prop_assert!(p.is_finite() && p >= 0.0);
        }
    }
}
