//! The f32 batch kernels against the f64 scalar reference, over the whole
//! catalogue: for every model with a kernel, random parameter sets drawn from
//! its own declaration (edges included, as `properties.rs` draws them) and
//! direction pairs that are uniform, grazing (cos θ down to 1e-6), at the
//! normal and at and near the mirror direction (where sharp lobes peak). Each
//! value must be within 1e-4 relative or 1e-6 absolute of `Brdf::eval` at the
//! same (f32) directions.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

mod common;
use bv_core::batch::{
    self, Dirs, Isa, Kernel, LaneKernel, LaneMask, LaneTask, Lanes, Out, PairBuf,
};
use bv_core::lobe::{self, LobeMesh, LobeOptions, RadiusScale};
use bv_core::params::{ParamDecl, ParamKind, ParamValue, Params};
use bv_core::sampling::{self, BvRng};
use bv_core::{Brdf, Claims, ModelSpec, Rgb, catalogue};
use common::random_float;
use glam::{DVec3, Vec3};
use rand::Rng;
use std::f64::consts::PI;

const REL: f64 = 1e-4;
const ABS: f64 = 1e-6;
const SETS: u64 = 48;

/// Random values for the declared floats, colours, choices, flags and lists
/// (1 to 3 items of random fields); `None` for a model with components or
/// files (neither has a kernel).
fn random_params(decls: &[ParamDecl], rng: &mut BvRng) -> Option<Params> {
    let mut p = Params::default();
    for d in decls {
        let v = match d.kind {
            ParamKind::Float(s) => ParamValue::Float(random_float(&s, rng)),
            ParamKind::Color(s) => {
                let r: f64 = rng.random();
                ParamValue::Color(if r < 0.05 {
                    [s.min; 3]
                } else if r < 0.10 {
                    [s.max; 3]
                } else if r < 0.2 {
                    [rng.random_range(s.min..=s.max); 3]
                } else {
                    std::array::from_fn(|_| rng.random_range(s.min..=s.max))
                })
            }
            ParamKind::Choice { options, .. } => {
                ParamValue::Text(options[rng.random_range(0..options.len())].to_string())
            }
            ParamKind::Bool { .. } => ParamValue::Bool(rng.random()),
            ParamKind::List {
                fields,
                min_items,
                max_items,
                ..
            } => {
                let n = rng.random_range(min_items.max(1)..=max_items.min(3).max(min_items.max(1)));
                let items = (0..n)
                    .map(|_| random_params(fields, rng))
                    .collect::<Option<Vec<_>>>()?;
                ParamValue::List(items)
            }
            _ => return None,
        };
        p.set_unvalidated(d.id, v);
    }
    Some(p)
}

/// A direction at polar angle `theta`, azimuth `phi`.
fn dir(theta: f64, phi: f64) -> DVec3 {
    bv_core::frame::from_spherical(theta, phi)
}

/// A direction with `cos θ` log-uniform in [1e-6, 1] (grazing ones common).
fn grazing(rng: &mut BvRng) -> DVec3 {
    let z: f64 = (rng.random_range(1e-6f64.ln()..=0.0)).exp();
    let phi = rng.random_range(0.0..2.0 * PI);
    let s = (1.0 - z * z).max(0.0).sqrt();
    DVec3::new(s * phi.cos(), s * phi.sin(), z)
}

/// The test's direction pairs.
fn pairs(seed: u64) -> PairBuf {
    let mut rng = sampling::rng(seed);
    let mut out = Vec::new();
    for _ in 0..400 {
        let wi = sampling::uniform_hemisphere(sampling::uniform2(&mut rng));
        let wo = sampling::uniform_hemisphere(sampling::uniform2(&mut rng));
        out.push((wi, wo));
        out.push((grazing(&mut rng), wo));
        out.push((wi, grazing(&mut rng)));
        out.push((grazing(&mut rng), grazing(&mut rng)));
        // At and near the mirror direction, by up to ~0.001 to 0.1 rad.
        let m = DVec3::new(-wi.x, -wi.y, wi.z);
        out.push((wi, m));
        let d: f64 = (rng.random_range(1e-3f64.ln()..=0.1f64.ln())).exp();
        let t = DVec3::new(rng.random_range(-d..d), rng.random_range(-d..d), 0.0);
        let n = (m + t).normalize();
        if n.z > 0.0 {
            out.push((wi, n));
        }
    }
    for th in [0.0, 0.3, 1.0, 1.5, PI / 2.0 - 1e-6] {
        out.push((DVec3::Z, dir(th, 0.7)));
        out.push((dir(th, 0.7), DVec3::Z));
    }
    // Below the horizon: 0 on both paths.
    out.push((DVec3::new(0.6, 0.0, -0.8), DVec3::Z));
    out.push((DVec3::Z, DVec3::new(0.0, 0.6, -0.8)));
    out.push((DVec3::new(1.0, 0.0, 0.0), DVec3::Z));
    PairBuf::from_pairs(&out)
}

/// The test's pairs for a transmitting model: [`pairs`], then the same
/// kinds of pairs on the whole sphere: light from below, viewers across the
/// surface and below it, grazing on either side, and near the model's peaks
/// (the refracted direction, [`Brdf::peaks`]) and mirror directions on
/// either side, by up to ~0.001 to 0.1 rad.
fn sphere_pairs(brdf: &dyn Brdf, seed: u64) -> PairBuf {
    let mut out = pairs(seed);
    let mut rng = sampling::rng(seed ^ 0x5_9E7E);
    let flip = |w: DVec3| DVec3::new(w.x, w.y, -w.z);
    let uniform = |rng: &mut BvRng| {
        let u = sampling::uniform2(rng);
        let z = 2.0 * u.x - 1.0;
        let s = (1.0 - z * z).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        DVec3::new(s * phi.cos(), s * phi.sin(), z)
    };
    for k in 0..1600 {
        let wi = uniform(&mut rng);
        let wo = uniform(&mut rng);
        out.push(wi, wo);
        let g = if k % 2 == 0 {
            grazing(&mut rng)
        } else {
            flip(grazing(&mut rng))
        };
        out.push(g, wo);
        out.push(wi, g);
        let d: f64 = (rng.random_range(1e-3f64.ln()..=0.1f64.ln())).exp();
        let t = DVec3::new(
            rng.random_range(-d..d),
            rng.random_range(-d..d),
            rng.random_range(-d..d),
        );
        let mirror = DVec3::new(-wi.x, -wi.y, wi.z);
        out.push(wi, mirror);
        out.push(wi, (mirror + t).normalize());
        for p in brdf.peaks(wi) {
            out.push(wi, p);
            out.push(wi, (p + t).normalize());
        }
    }
    for w in [DVec3::Z, -DVec3::Z] {
        for th in [
            0.0,
            0.3,
            1.0,
            1.5,
            PI / 2.0 - 1e-6,
            PI / 2.0 + 1e-6,
            2.0,
            PI,
        ] {
            out.push(w, dir(th, 0.7));
            out.push(dir(th, 0.7), w);
        }
    }
    out
}

/// The first lane where the kernel and `eval` disagree beyond the tolerance,
/// on any instruction set this CPU has (each path's own compiled copy of the
/// kernel; the vector paths also see lane counts that leave a remainder).
fn first_mismatch(brdf: &dyn Brdf, dirs: &PairBuf) -> Option<String> {
    let available = Isa::available();
    assert!(available.contains(&Isa::Scalar));
    let reference = Reference::new(brdf, dirs);
    for isa in available {
        if let Some(e) = first_mismatch_on(brdf, &reference, isa) {
            return Some(format!("[{isa}] {e}"));
        }
    }
    None
}

/// What every instruction set is held to, evaluated once: `eval` at every
/// pair of `dirs`, and where the kernel has a form for pairs that share `wi`
/// ([`Kernel::at_wi`]), that form with `eval` at every outgoing direction of
/// `dirs` with each of a few of its incident ones (grazing and below the
/// surface among them). The f64 evaluations are most of this test's work,
/// and under qemu (.ci/simd.sh) most of its minutes: each path compares with
/// the same values rather than computing them again.
struct Reference<'a> {
    dirs: &'a PairBuf,
    want: Vec<Rgb>,
    /// A kernel for one shared incident direction, its pairs and their values.
    at_wi: Vec<(Box<dyn Kernel + 'a>, PairBuf, Vec<Rgb>)>,
}

impl<'a> Reference<'a> {
    fn new(brdf: &'a dyn Brdf, dirs: &'a PairBuf) -> Self {
        let eval_all = |d: &PairBuf| -> Vec<Rgb> {
            (0..d.len())
                .map(|i| {
                    let (wi, wo) = d.pair(i);
                    brdf.eval(wi, wo)
                })
                .collect()
        };
        let n = dirs.len();
        let mut at_wi = Vec::new();
        if let Some(kernel) = brdf.batch_kernel() {
            // The pairs' first, grazing and below-the-surface incident
            // directions (see `pairs`), and a few from the rest.
            for i in [0, 1, n - 1, n - 3, n / 3, n / 2, 2 * n / 3] {
                let wi = [dirs.wi[0][i], dirs.wi[1][i], dirs.wi[2][i]];
                let Some(k) = kernel.at_wi(wi) else {
                    break;
                };
                let mut shared = dirs.clone();
                for (c, &w) in wi.iter().enumerate() {
                    shared.wi[c].fill(w);
                }
                let want = eval_all(&shared);
                at_wi.push((k, shared, want));
            }
        }
        Reference {
            dirs,
            want: eval_all(dirs),
            at_wi,
        }
    }
}

/// [`first_mismatch`] on one instruction set: the kernel, and its forms for
/// a shared `wi`, against `reference`.
fn first_mismatch_on(brdf: &dyn Brdf, reference: &Reference<'_>, isa: Isa) -> Option<String> {
    let dirs = reference.dirs;
    let n = dirs.len();
    let mut rgb = [vec![f32::NAN; n], vec![f32::NAN; n], vec![f32::NAN; n]];
    let [r, g, b] = &mut rgb;
    let d = batch::eval_with(
        brdf,
        isa,
        &dirs.dirs(0..n),
        &mut Out {
            rgb: [&mut r[..], &mut g[..], &mut b[..]],
        },
    );
    assert!(d.kernel);
    assert_eq!((d.isa, d.lanes), (isa.name(), isa.lanes()));
    if let Some(e) = mismatch_in(dirs, &reference.want, &rgb) {
        return Some(e);
    }
    for (k, shared, want) in &reference.at_wi {
        let mut rgb = [vec![f32::NAN; n], vec![f32::NAN; n], vec![f32::NAN; n]];
        let [r, g, b] = &mut rgb;
        k.eval(
            isa,
            &shared.dirs(0..n),
            &mut Out {
                rgb: [&mut r[..], &mut g[..], &mut b[..]],
            },
        );
        if let Some(e) = mismatch_in(shared, want, &rgb) {
            return Some(format!("at_wi: {e}"));
        }
    }
    None
}

/// The first lane of `rgb` (a batch's values at `dirs`) that is not within
/// [`REL`] or [`ABS`] of `want` (`eval` there).
fn mismatch_in(dirs: &PairBuf, want: &[Rgb], rgb: &[Vec<f32>; 3]) -> Option<String> {
    #[allow(clippy::needless_range_loop)] // lane i of four arrays
    for i in 0..dirs.len() {
        let want = want[i];
        for c in 0..3 {
            let got = rgb[c][i] as f64;
            let tol = (REL * want[c].abs()).max(ABS);
            // NaN fails too.
            let close = (got - want[c]).abs() <= tol;
            if !close {
                let (wi, wo) = dirs.pair(i);
                return Some(format!(
                    "lane {i} channel {c}: wi {wi} wo {wo}: batch {got:e} vs eval {:e}",
                    want[c]
                ));
            }
        }
    }
    None
}

/// `id`'s kernel against its f64 `eval` on [`SETS`] random parameter sets
/// (every set must have a kernel), on every instruction set this machine
/// has.
fn check_kernel(id: &str, seeds: std::ops::Range<u64>) {
    let models = catalogue();
    let m = models
        .iter()
        .find(|m| m.id == id)
        .unwrap_or_else(|| panic!("{id} is not in the catalogue"));
    let dirs = pairs(7);
    let mut sets = 0;
    for seed in seeds {
        let mut rng = sampling::rng(1000 + seed);
        let Some(params) = random_params(m.params, &mut rng) else {
            break;
        };
        let spec = ModelSpec::from_json(m.id, &params.to_json())
            .unwrap_or_else(|e| panic!("{}: generated parameters refused: {e}", m.id));
        let brdf = spec.build().unwrap();
        assert!(brdf.batch_kernel().is_some(), "{} lost its kernel", m.id);
        let dirs = if brdf.transmits() {
            sphere_pairs(brdf.as_ref(), 7)
        } else {
            dirs.clone()
        };
        if let Some(e) = first_mismatch(brdf.as_ref(), &dirs) {
            panic!("{} {}: {e}", m.id, spec.to_json());
        }
        sets += 1;
    }
    assert!(sets > 0, "{id} was never checked");
    // .ci/simd.sh reads this line to see which instruction sets ran.
    eprintln!(
        "kernels checked on {}: {id} ({sets} sets)",
        Isa::available()
            .iter()
            .map(|i| i.name())
            .collect::<Vec<_>>()
            .join(", "),
    );
}

/// Two tests per model with a kernel (the first and second half of its
/// [`SETS`] parameter sets), so that the harness runs them side by side: as
/// one test, the whole catalogue was one thread for minutes under qemu
/// (.ci/simd.sh) while the machine's other cores waited; one test per model
/// still left Cook-Torrance's (the slowest, over five minutes there) alone
/// at the end.
macro_rules! kernel_tests {
    ($($name:ident: $id:literal,)*) => {
        /// The models that must have a kernel for every parameter set.
        const WITH_KERNEL: &[&str] = &[$($id),*];

        mod every_kernel_matches_the_scalar_reference {
            $(
                mod $name {
                    use super::super::{SETS, check_kernel};

                    #[test]
                    fn first_half() {
                        check_kernel($id, 0..SETS / 2);
                    }

                    #[test]
                    fn second_half() {
                        check_kernel($id, SETS / 2..SETS);
                    }
                }
            )*
        }
    };
}

kernel_tests! {
    cook_torrance: "cook-torrance",
    lambert: "lambert",
    phong: "phong",
    blinn_phong: "blinn-phong",
    modified_phong: "modified-phong",
    ward: "ward",
    oren_nayar: "oren-nayar",
    hapke: "hapke",
    disney: "disney",
    ashikhmin_shirley: "ashikhmin-shirley",
    banks: "banks",
    lafortune: "lafortune",
    mirror: "mirror",
    glass: "glass",
    rough_dielectric: "rough-dielectric",
    coated: "coated",
}

/// A model that gains a kernel must gain its test above: no model outside
/// [`WITH_KERNEL`] has a kernel for any of its random parameter sets.
#[test]
fn every_model_with_a_kernel_has_its_test() {
    for m in catalogue().iter().filter(|m| !WITH_KERNEL.contains(&m.id)) {
        for seed in 0..SETS {
            let mut rng = sampling::rng(1000 + seed);
            let Some(params) = random_params(m.params, &mut rng) else {
                break;
            };
            let Ok(brdf) = ModelSpec::from_json(m.id, &params.to_json()).and_then(|s| s.build())
            else {
                continue;
            };
            assert!(
                brdf.batch_kernel().is_none(),
                "{} has a kernel but no test: add it to kernel_tests!",
                m.id
            );
        }
    }
}

#[test]
fn mixes_sum_their_parts_batches() {
    let dirs = pairs(8);
    for components in [
        // The default: Lambert + GGX Cook-Torrance, both with kernels.
        serde_json::Value::Null,
        // Nested mixes and every microfacet distribution.
        serde_json::json!({"components": [
            {"weight": 0.3, "model": "cook-torrance", "params": {"distribution": "blinn"}},
            {"weight": 0.5, "model": "ward", "params": {"alpha_x": 0.05, "alpha_y": 0.4}},
            {"weight": 0.2, "model": "mix", "params": {"components": [
                {"weight": 1.0, "model": "blinn-phong", "params": {"e": 5000.0}}]}}
        ]}),
    ] {
        let spec = ModelSpec::from_json("mix", &components).unwrap();
        let b = spec.build().unwrap();
        assert!(b.batch_kernel().is_some(), "{}", spec.to_json());
        if let Some(e) = first_mismatch(b.as_ref(), &dirs) {
            panic!("{}: {e}", spec.to_json());
        }
    }
}

#[test]
fn every_cook_torrance_combination_is_checked() {
    // The random draw above may miss a combination; this covers all of them
    // at a sharp, a medium and a very rough α, with a mixture.
    let dirs = pairs(8);
    for dist in ["beckmann", "ggx", "blinn"] {
        for geo in ["v-groove", "smith", "smith-correlated"] {
            // The dielectric with one index per channel and with one for all
            // (its own kernel), above and below 1 (η = 0.195: the critical
            // angle near grazing).
            let cases = [
                ("none", 0.0),
                ("schlick", 0.0),
                ("dielectric", 0.0),
                ("dielectric", 1.5),
                ("dielectric", 0.195),
                ("conductor", 0.0),
            ];
            for (fresnel, grey) in cases {
                let eta = if grey > 0.0 {
                    serde_json::json!(grey)
                } else {
                    serde_json::json!([0.2, 0.92, 1.1])
                };
                for (ax, ay, w2) in [(0.001, 0.001, 0.0), (0.3, 0.1, 0.0), (2.0, 2.0, 0.3)] {
                    let p = serde_json::json!({"kd": [0.2, 0.1, 0.0], "ks": 0.8,
                        "distribution": dist, "geometry": geo, "fresnel": fresnel,
                        "alpha_x": ax, "alpha_y": ay, "alpha2": 0.05, "weight2": w2,
                        "eta": eta, "k": [3.9, 2.45, 2.14], "f0": 0.04});
                    let b = ModelSpec::from_json("cook-torrance", &p)
                        .unwrap()
                        .build()
                        .unwrap();
                    if let Some(e) = first_mismatch(b.as_ref(), &dirs) {
                        panic!("{p}: {e}");
                    }
                }
            }
        }
    }
}

#[test]
fn anisotropic_kulla_conty_is_checked() {
    // The compensation's azimuthal harmonics (`multiscatter`), read by the
    // kernel per lane: both distributions and Smith forms, with a Fresnel
    // colour, and an isotropic lobe beside them.
    let dirs = pairs(10);
    for dist in ["beckmann", "ggx"] {
        for geo in ["smith", "smith-correlated"] {
            for (ax, ay) in [(0.8, 0.2), (0.1, 0.5), (0.4, 0.4)] {
                let p = serde_json::json!({"kd": 0.1, "ks": 0.8, "distribution": dist,
                    "geometry": geo, "fresnel": "conductor", "alpha_x": ax, "alpha_y": ay,
                    "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14],
                    "multiscatter": "kulla-conty"});
                let b = ModelSpec::from_json("cook-torrance", &p)
                    .unwrap()
                    .build()
                    .unwrap();
                if let Some(e) = first_mismatch(b.as_ref(), &dirs) {
                    panic!("{p}: {e}");
                }
            }
        }
    }
}

#[test]
fn every_rough_dielectric_combination_is_checked() {
    // Both distributions and geometries, sharp to very rough, indices on
    // both sides of 1 and at the ends of the range, on the whole sphere.
    for dist in ["ggx", "beckmann"] {
        for geo in ["smith", "smith-correlated"] {
            for (ax, ay) in [(0.001, 0.001), (0.3, 0.1), (2.0, 2.0)] {
                for eta in [1.5, 0.6, 1.01, 10.0, 0.01] {
                    let p = serde_json::json!({"distribution": dist, "geometry": geo,
                        "alpha_x": ax, "alpha_y": ay, "eta": eta, "tint": [1.0, 0.5, 0.25]});
                    let b = ModelSpec::from_json("rough-dielectric", &p)
                        .unwrap()
                        .build()
                        .unwrap();
                    let dirs = sphere_pairs(b.as_ref(), 12);
                    // Mixed vectors take the kernel's general branch; the
                    // same pairs sorted by sides fill whole vectors with one
                    // case (reflection above or below, transmission from
                    // above or below), which take the branches that skip
                    // the other lobe.
                    for dirs in [by_sides(&dirs), dirs] {
                        if let Some(e) = first_mismatch(b.as_ref(), &dirs) {
                            panic!("{p}: {e}");
                        }
                    }
                }
            }
        }
    }
}

/// `dirs` sorted (stably) by the sides of each pair: both above, both
/// below, wi above and wo below, wi below and wo above, then the rest (a
/// direction in the plane of the surface).
fn by_sides(dirs: &PairBuf) -> PairBuf {
    let key = |i: usize| match (dirs.wi[2][i], dirs.wo[2][i]) {
        (zi, zo) if zi > 0.0 && zo > 0.0 => 0,
        (zi, zo) if zi < 0.0 && zo < 0.0 => 1,
        (zi, zo) if zi > 0.0 && zo < 0.0 => 2,
        (zi, zo) if zi < 0.0 && zo > 0.0 => 3,
        _ => 4,
    };
    let mut order: Vec<usize> = (0..dirs.len()).collect();
    order.sort_by_key(|&i| key(i));
    let mut out = PairBuf::default();
    for i in order {
        for c in 0..3 {
            out.wi[c].push(dirs.wi[c][i]);
            out.wo[c].push(dirs.wo[c][i]);
        }
    }
    out
}

/// Writes, for each lane, whether any and whether every lane of its vector
/// has `wi.x > 0` (1 or 0); `TWICE` as the kernel's
/// [`LaneKernel::TWICE`].
#[derive(Debug)]
struct MaskProbe<const TWICE: bool>;
impl<const TWICE: bool> LaneKernel for MaskProbe<TWICE> {
    fn lane<V: Lanes>(&self, wi: [V; 3], _wo: [V; 3]) -> [V; 3] {
        let m = wi[0].gt(V::splat(0.0));
        let bit = |b: bool| V::splat(if b { 1.0 } else { 0.0 });
        [bit(m.any()), bit(m.all()), V::splat(0.0)]
    }
    const TWICE: bool = TWICE;
}

#[test]
fn any_and_all_see_every_lane_on_every_path() {
    // Vectors of every pattern that matters: none, one lane (each position
    // in turn), all but one, all. The probe's pairs start at 0 and fill
    // whole vectors of each width (32 is a multiple of 1, 4, 8 and 16, and
    // of two vectors of 8 or of 16).
    const N: usize = 32;
    let mut patterns: Vec<Vec<bool>> = vec![vec![false; N], vec![true; N]];
    for k in 0..N {
        patterns.push((0..N).map(|i| i == k).collect());
        patterns.push((0..N).map(|i| i != k).collect());
    }
    for (isa, twice) in Isa::available()
        .into_iter()
        .flat_map(|isa| [(isa, false), (isa, true)])
    {
        // A kernel's vector: two of the path's where it runs `Twice`.
        let w = isa.lanes() * if twice && isa.twice() { 2 } else { 1 };
        for pattern in &patterns {
            let mut dirs = PairBuf::default();
            for &on in pattern {
                let x = if on { 0.5 } else { -0.5 };
                dirs.push(DVec3::new(x, 0.0, 0.8), DVec3::Z);
            }
            let n = dirs.len();
            let (mut any, mut all, mut z) = (vec![-1f32; n], vec![-1f32; n], vec![-1f32; n]);
            let probe: &dyn Kernel = if twice {
                &MaskProbe::<true>
            } else {
                &MaskProbe::<false>
            };
            probe.eval(
                isa,
                &dirs.dirs(0..n),
                &mut Out {
                    rgb: [&mut any[..], &mut all[..], &mut z[..]],
                },
            );
            for (v, chunk) in pattern.chunks(w).enumerate() {
                let want = (chunk.iter().any(|&b| b), chunk.iter().all(|&b| b));
                for i in v * w..(v + 1) * w {
                    let got = (any[i] == 1.0, all[i] == 1.0);
                    assert_eq!(got, want, "[{isa}, twice {twice}] {pattern:?}, lane {i}");
                }
            }
        }
    }
}

/// `out[k] = [a[k], b[k], c[k]]` through [`Lanes::store3`] and
/// `inv[k] = a[k].rsqrt()`, whole vectors of the path's width (the arrays
/// are a multiple of 16 long).
struct StoreAndRsqrt<'a> {
    a: [&'a [f32]; 3],
    out: &'a mut [[f32; 3]],
    inv: &'a mut [f32],
}
impl LaneTask for StoreAndRsqrt<'_> {
    type Output = ();
    fn run<V: Lanes>(self) {
        let mut k = 0;
        while k < self.out.len() {
            let [a, b, c] = self.a.map(|x| V::load(&x[k..]));
            V::store3(a, b, c, &mut self.out[k..]);
            a.rsqrt().store(&mut self.inv[k..]);
            k += V::LANES;
        }
    }
}

#[test]
fn interleaving_stores_and_reciprocal_roots_hold_on_every_path() {
    // Every lane of every vector distinct, so a lane landing in the wrong
    // place shows; the guard cells after the arrays' end must stay as
    // they are. The roots cover f32's normal range, from MIN_POSITIVE to
    // MAX, in steps that change the exponent and the mantissa.
    let n = 48 * 16;
    let mut rng = sampling::rng(7);
    let mut a: Vec<f32> = (0..n)
        .map(|k| {
            let t = k as f64 / (n - 1) as f64;
            let e = -126.0 + t * 252.9;
            (2f64.powf(e) * (1.0 + 0.5 * rng.random::<f64>())) as f32
        })
        .collect();
    a[0] = f32::MIN_POSITIVE;
    a[n - 1] = f32::MAX;
    let b: Vec<f32> = (0..n).map(|k| -(k as f32) - 0.25).collect();
    let c: Vec<f32> = (0..n).map(|k| k as f32 * 3.0 + 0.5).collect();
    for isa in Isa::available() {
        let guard = [-7.0f32; 3];
        let mut out = vec![guard; n + 1];
        let mut inv = vec![-7.0f32; n + 1];
        batch::run_task(
            isa,
            StoreAndRsqrt {
                a: [&a, &b, &c],
                out: &mut out[..n],
                inv: &mut inv[..n],
            },
        );
        for k in 0..n {
            assert_eq!(out[k], [a[k], b[k], c[k]], "[{isa}] store3, place {k}");
            let want = 1.0 / (a[k] as f64).sqrt();
            let rel = (inv[k] as f64 - want).abs() / want;
            assert!(
                rel <= 2f64.powi(-21),
                "[{isa}] rsqrt({}) = {} against {want}: {rel:e}",
                a[k],
                inv[k]
            );
        }
        assert_eq!(out[n], guard, "[{isa}] store3 wrote past the end");
        assert_eq!(inv[n], -7.0, "[{isa}] rsqrt's store wrote past the end");
    }
}

#[test]
fn every_coated_combination_is_checked() {
    // Both distributions and bases, a sharp, a medium and a very rough
    // coat, a thin and an absorbing layer, indices near 1 and high, and a
    // base conductor whose index is below the coat's (total internal
    // reflection inside the base's Fresnel is then possible).
    let dirs = pairs(9);
    for dist in ["ggx", "beckmann"] {
        for base in ["lambert", "conductor"] {
            for (ax, ay) in [(0.001, 0.001), (0.3, 0.1), (2.0, 2.0)] {
                for eta in [1.01, 1.5, 4.0] {
                    for (thickness, absorption) in [
                        (0.0, [0.0; 3]),
                        (2.0, [0.1, 0.5, 1.0]),
                        (10.0, [0.02, 0.2, 1.0]),
                    ] {
                        let p = serde_json::json!({"distribution": dist, "base": base,
                            "alpha_x": ax, "alpha_y": ay, "eta": eta,
                            "thickness": thickness, "absorption": absorption,
                            "base_albedo": [0.9, 0.5, 0.1], "base_alpha": ax,
                            "base_eta": [0.2, 0.92, 1.1], "base_k": [3.9, 2.45, 2.14]});
                        let b = ModelSpec::from_json("coated", &p).unwrap().build().unwrap();
                        assert!(b.batch_kernel().is_some(), "{p}");
                        if let Some(e) = first_mismatch(b.as_ref(), &dirs) {
                            panic!("{p}: {e}");
                        }
                    }
                }
            }
        }
    }
}

/// Lambert with a kernel that is off by 2e-4: the check must catch it.
#[derive(Debug)]
struct Wrong(Box<dyn Brdf>, WrongKernel);
#[derive(Debug)]
struct WrongKernel;
impl LaneKernel for WrongKernel {
    fn lane<V: Lanes>(&self, wi: [V; 3], wo: [V; 3]) -> [V; 3] {
        let v = V::splat((0.5 / PI * (1.0 + 2e-4)) as f32);
        let above = wi[2].gt(V::splat(0.0)) & wo[2].gt(V::splat(0.0));
        [above.select(v, V::splat(0.0)); 3]
    }
}
impl Brdf for Wrong {
    fn id(&self) -> &'static str {
        "wrong"
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.0.eval(wi, wo)
    }
    fn claims(&self) -> Claims {
        self.0.claims()
    }
    fn batch_kernel(&self) -> Option<&dyn Kernel> {
        Some(&self.1)
    }
}

#[test]
fn a_wrong_kernel_is_caught() {
    let lambert = ModelSpec::from_json("lambert", &serde_json::json!({"albedo": 0.5}))
        .unwrap()
        .build()
        .unwrap();
    let dirs = pairs(9);
    assert!(first_mismatch(lambert.as_ref(), &dirs).is_none());
    let wrong = Wrong(lambert, WrongKernel);
    let reference = Reference::new(&wrong, &dirs);
    for isa in Isa::available() {
        assert!(
            first_mismatch_on(&wrong, &reference, isa).is_some(),
            "{isa}"
        );
    }
}

#[test]
fn every_length_fills_exactly_its_lanes() {
    // Whole vectors and every remainder, through each step of the loops:
    // two vectors at a time (32 lanes on AVX-512), then one, then the padded
    // rest (lengths up to 80 reach two pair steps, a single vector after
    // them and every remainder on every path). Lanes
    // 0..n hold the scalar path's values, lanes n.. are untouched.
    let b = ModelSpec::from_json("cook-torrance", &serde_json::json!({}))
        .unwrap()
        .build()
        .unwrap();
    let dirs = pairs(11);
    let m = 80;
    let mut want = [vec![0f32; m], vec![0f32; m], vec![0f32; m]];
    {
        let [r, g, bl] = &mut want;
        batch::eval_with(
            b.as_ref(),
            Isa::Scalar,
            &dirs.dirs(0..m),
            &mut Out {
                rgb: [&mut r[..], &mut g[..], &mut bl[..]],
            },
        );
    }
    for isa in Isa::available() {
        for n in 0..=m {
            let mut rgb = [vec![-7f32; m], vec![-7f32; m], vec![-7f32; m]];
            let [r, g, bl] = &mut rgb;
            batch::eval_with(
                b.as_ref(),
                isa,
                &dirs.dirs(0..n),
                &mut Out {
                    rgb: [&mut r[..], &mut g[..], &mut bl[..]],
                },
            );
            for c in 0..3 {
                for i in 0..m {
                    let got = rgb[c][i];
                    if i < n {
                        let w = want[c][i];
                        assert!(
                            (got - w).abs() <= 1e-5 * w.abs().max(1e-2),
                            "{isa} n {n} lane {i}: {got} vs {w}"
                        );
                    } else {
                        assert_eq!(got, -7.0, "{isa} n {n}: lane {i} was written");
                    }
                }
            }
        }
    }
}

/// A model without a kernel: Lambert's `eval` alone.
#[derive(Debug)]
struct NoKernel(Box<dyn Brdf>);
impl Brdf for NoKernel {
    fn id(&self) -> &'static str {
        "no-kernel"
    }
    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.0.eval(wi, wo)
    }
    fn claims(&self) -> Claims {
        self.0.claims()
    }
}

#[test]
fn models_without_a_kernel_fall_back_to_eval() {
    // Measured and user-file models have no lane form: the batch path is then
    // `eval` itself.
    let b = NoKernel(
        ModelSpec::from_json("lambert", &serde_json::json!({"albedo": [0.2, 0.5, 0.7]}))
            .unwrap()
            .build()
            .unwrap(),
    );
    assert!(b.batch_kernel().is_none());
    let dirs = pairs(10);
    let n = dirs.len();
    let mut rgb = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
    let [r, g, bl] = &mut rgb;
    let d = batch::eval(
        &b,
        &dirs.dirs(0..n),
        &mut Out {
            rgb: [&mut r[..], &mut g[..], &mut bl[..]],
        },
    );
    assert_eq!((d.kernel, d.isa, d.lanes), (false, "scalar", 1));
    for (i, &red) in rgb[0].iter().enumerate() {
        let (wi, wo) = dirs.pair(i);
        assert_eq!(red, b.eval(wi, wo).x as f32);
    }
}

#[test]
fn dirs_len_is_the_shortest_array() {
    let a = [1f32; 4];
    let b = [1f32; 3];
    let d = Dirs {
        wi: [&a, &a, &a],
        wo: [&a, &b, &a],
    };
    assert_eq!(d.len(), 3);
}

/// Which function [`MathLanes`] computes.
#[derive(Debug, Clone, Copy)]
enum MathFn {
    Exp,
    Ln,
    Erfc,
    Atan2,
    Pow1m,
}

/// One of `batch::math`'s functions as a kernel: red = f(wi.x, wi.y) on
/// every lane, so that the function runs in each instruction set's code.
#[derive(Debug)]
struct MathLanes(MathFn);

impl LaneKernel for MathLanes {
    fn lane<V: Lanes>(&self, wi: [V; 3], _wo: [V; 3]) -> [V; 3] {
        use bv_core::batch::math;
        let (x, y) = (wi[0], wi[1]);
        let v = match self.0 {
            MathFn::Exp => math::exp(x),
            MathFn::Ln => math::ln(x),
            MathFn::Erfc => math::erfc(x),
            MathFn::Atan2 => math::atan2_first_quadrant(y, x),
            // x^400 from x and 1 − x (the sharp Phong lobe's case).
            MathFn::Pow1m => math::pow_1m(x, y, 400.0),
        };
        [v, V::splat(0.0), V::splat(0.0)]
    }
}

#[test]
fn lane_math_matches_f64_on_every_path() {
    // (function, inputs (x, y), the f64 reference, relative tolerance, and
    // an absolute floor).
    type Case = (MathFn, Vec<(f32, f32)>, fn(f64, f64) -> f64, f64, f64);
    let grid = |lo: f32, hi: f32, n: usize| -> Vec<(f32, f32)> {
        (0..=n)
            .map(|i| (lo + (hi - lo) * i as f32 / n as f32, 0.0))
            .collect()
    };
    let near_one: Vec<(f32, f32)> = (0..2000)
        .map(|i| {
            let y = 1e-7f64 * 1.01f64.powi(i);
            ((1.0 - y) as f32, y as f32)
        })
        .filter(|&(x, _)| x > 0.0)
        .collect();
    let angles: Vec<(f32, f32)> = (0..=4000)
        .map(|i| {
            let a = std::f64::consts::FRAC_PI_2 * i as f64 / 4000.0;
            (a.cos() as f32, a.sin() as f32)
        })
        .collect();
    let cases: Vec<Case> = vec![
        (
            MathFn::Exp,
            grid(-87.0, 88.0, 20_000),
            |x, _| x.exp(),
            3e-7,
            0.0,
        ),
        (
            MathFn::Ln,
            grid(1e-3, 4.0, 20_000),
            |x, _| x.ln(),
            3e-7,
            1e-7,
        ),
        (
            MathFn::Erfc,
            grid(-5.0, 9.0, 20_000),
            |x, _| libm::erfc(x),
            5e-7 * 82.0,
            4e-7,
        ),
        (MathFn::Atan2, angles, |x, y| y.atan2(x), 3e-7, 1e-30),
        // From 1 − x (exact in f64 from the f32 inputs' own values).
        (
            MathFn::Pow1m,
            near_one,
            // Below y = 0.29 from y (as `ln_near_one`), above from x.
            |x, y| {
                if y < 0.29 {
                    (400.0 * (-y).ln_1p()).exp()
                } else {
                    x.powf(400.0)
                }
            },
            2e-5,
            1e-30,
        ),
    ];
    for isa in Isa::available() {
        for (f, inputs, reference, rel, abs) in &cases {
            let n = inputs.len();
            let xs: Vec<f32> = inputs.iter().map(|p| p.0).collect();
            let ys: Vec<f32> = inputs.iter().map(|p| p.1).collect();
            let zs = vec![1f32; n];
            let mut out = [vec![f32::NAN; n], vec![0f32; n], vec![0f32; n]];
            let [r, g, b] = &mut out;
            batch::run(
                &MathLanes(*f),
                isa,
                &Dirs {
                    wi: [&xs, &ys, &zs],
                    wo: [&xs, &ys, &zs],
                },
                &mut Out {
                    rgb: [&mut r[..], &mut g[..], &mut b[..]],
                },
            );
            for (i, &(x, y)) in inputs.iter().enumerate() {
                let want = reference(x as f64, y as f64);
                let got = out[0][i] as f64;
                let tol = (rel * want.abs()).max(*abs);
                assert!(
                    (got - want).abs() <= tol,
                    "[{isa}] {f:?}({x}, {y}) = {got:e}, want {want:e}"
                );
            }
        }
    }
}

// ---------------------------------------------------------------------------
// Lobe meshes: the vector passes after evaluation (`lobe`'s `LaneTask`s) on
// every instruction set, here so that the NEON and wasm runs of this test
// hold them too.

/// `f` with non-finite values in places (NaN for x > 0.5, +∞ in green
/// for y > 0.6) and a smooth lobe elsewhere.
#[derive(Debug)]
struct Poisoned;

impl Brdf for Poisoned {
    fn id(&self) -> &'static str {
        "poisoned"
    }
    fn eval(&self, _wi: DVec3, wo: DVec3) -> Rgb {
        if wo.x > 0.5 {
            return Rgb::splat(f64::NAN);
        }
        let v = (1.0 + wo.x) * (1.0 + wo.z * wo.z);
        Rgb::new(v, if wo.y > 0.6 { f64::INFINITY } else { 2.0 * v }, -v)
    }
    fn claims(&self) -> Claims {
        Claims {
            reciprocal: false,
            energy_conserving: false,
            isotropic: false,
        }
    }
}

#[test]
fn lobe_meshes_of_every_instruction_set_follow_the_formulas() {
    // Every path's vector passes (values to radii and positions, then the
    // normals) against the per-vertex formulas written out here in f64:
    // value f·|cos θo| or f, 0 where any channel is not finite, radius the
    // clamped channel mean (or ln(1 + mean)), position radius · direction,
    // normal the normalised (down − up) × (right − left) of the positions.
    // Sizes cover remainders of every vector width, the one-task and the
    // parallel builds; light directions where an isotropic model's rings
    // are mirrored (φi = 0, π, odd and even multiples of π / n_phi,
    // normal incidence) and where they are not.
    let ward = ModelSpec::from_json("ward", &serde_json::json!({"alpha_x": 0.1, "alpha_y": 0.4}))
        .unwrap()
        .build()
        .unwrap();
    let ct = ModelSpec::new("cook-torrance").unwrap().build().unwrap();
    let dielectric = ModelSpec::new("rough-dielectric").unwrap().build().unwrap();
    let models: [(&str, &dyn Brdf); 4] = [
        ("cook-torrance", ct.as_ref()),
        ("rough-dielectric", dielectric.as_ref()),
        ("anisotropic ward", ward.as_ref()),
        ("poisoned", &Poisoned),
    ];
    // `available` ends with the scalar path.
    for isa in Isa::available() {
        for (name, b) in models {
            for (n_theta, n_phi, cosine, scale) in [
                (2, 3, false, RadiusScale::Linear),
                (7, 21, true, RadiusScale::Linear),
                (9, 37, false, RadiusScale::Log),
                (40, 133, true, RadiusScale::Linear),
                (33, 256, false, RadiusScale::Log),
            ] {
                let opts = LobeOptions {
                    n_theta,
                    n_phi,
                    cosine,
                    scale,
                };
                let step = PI / n_phi as f64;
                for phi_i in [0.3, 0.0, PI, 3.0 * step, -4.0 * step] {
                    for wi in [bv_core::frame::from_spherical(0.6, phi_i), DVec3::Z] {
                        let mut m = LobeMesh::default();
                        lobe::build_with(b, wi, &opts, &mut m, isa);
                        let at = format!(
                            "{name} {n_theta}×{n_phi} {isa:?} cosine {cosine} {scale:?} wi {wi}"
                        );
                        check_against_formulas(b, wi, &opts, &m, &at);
                    }
                }
            }
        }
    }
}

fn check_against_formulas(b: &dyn Brdf, wi: DVec3, opts: &LobeOptions, m: &LobeMesh, at: &str) {
    let (n_theta, n_phi) = (opts.n_theta, opts.n_phi);
    let wi32 = wi.as_vec3().as_dvec3();
    let close = |got: f64, want: f64, rel: f64| (got - want).abs() <= (rel * want.abs()).max(1e-6);
    let mut max_mean = 0f64;
    for i in 0..=n_theta {
        for j in 0..n_phi {
            let k = i * n_phi + j;
            let d = m.direction(i, j).as_vec3().as_dvec3();
            let mut f = b.eval(wi32, d);
            if opts.cosine {
                f *= d.z.abs();
            }
            if !(0..3).all(|c| f[c].is_finite()) {
                f = Rgb::splat(0.0);
            }
            let v = m.values[k];
            for c in 0..3 {
                assert!(
                    close(v[c] as f64, f[c], 1e-4),
                    "{at}: value {k} {v:?} vs {f}"
                );
            }
            let mean = ((f[0] + f[1] + f[2]) / 3.0).max(0.0);
            max_mean = max_mean.max(mean);
            let r = match opts.scale {
                RadiusScale::Linear => mean,
                RadiusScale::Log => mean.ln_1p(),
            };
            assert!(
                close(m.radii[k] as f64, r, 1e-4),
                "{at}: radius {k}: {} vs {r}",
                m.radii[k]
            );
            let p = m.positions[k];
            for c in 0..3 {
                let want = d[c] * r;
                assert!(
                    (p[c] as f64 - want).abs() <= 1e-4 * r.abs() + 1e-6,
                    "{at}: position {k} {p:?} vs {}",
                    d * r
                );
            }
        }
    }
    assert!(
        close(m.max_value, max_mean, 1e-4),
        "{at}: max {} vs {max_mean}",
        m.max_value
    );
    // Normals from the mesh's own positions, away from the poles (their
    // fans are tested elsewhere).
    let p = |i: usize, j: usize| Vec3::from_array(m.positions[i * n_phi + j]).as_dvec3();
    for i in 1..n_theta {
        for j in 0..n_phi {
            let (l, r) = ((j + n_phi - 1) % n_phi, (j + 1) % n_phi);
            let n = (p(i + 1, j) - p(i - 1, j)).cross(p(i, r) - p(i, l));
            let got = Vec3::from_array(m.normals[i * n_phi + j]).as_dvec3();
            let want = if n.length() > 1e-12 {
                n.normalize()
            } else if n.length() > 1e-20 {
                continue; // too short to compare in f32
            } else {
                m.direction(i, j)
            };
            assert!(
                (got - want).length() < 1e-3,
                "{at}: normal ({i}, {j}) {got} vs {want}"
            );
        }
    }
}
