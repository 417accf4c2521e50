//! The energy a single-scattering microfacet lobe loses, and Kulla & Conty's
//! compensation for it (Kulla & Conty 2017, "Revisiting Physically Based
//! Shading at Imageworks", SIGGRAPH course notes, §"Multiple scattering
//! microfacet BSDFs"; after Kelemen & Szirmay-Kalos 2001).
//!
//! A microfacet lobe `D G / (4 cosθi cosθo)` with F = 1 reflects only
//! `E(μ) = ∫ D G / (4 μ cosθo) cosθo dωo < 1` of the light arriving at
//! `μ = cosθi`: the rest is light that hits a second facet, which a
//! single-scattering model drops. Kulla & Conty add the lobe
//!
//! `f_ms(μi, μo) = (1 − E(μi)) (1 − E(μo)) / (π (1 − E_avg))`, with
//! `E_avg = 2 ∫₀¹ E(μ) μ dμ`,
//!
//! whose albedo is exactly `1 − E(μi)` (so that single + multiple = 1 with
//! F = 1), symmetric in (μi, μo), and for a Fresnel term F its coloured
//! weight `F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg))` with
//! `F_avg = 2 ∫₀¹ F(μ) μ dμ` (their eq. for the "Fresnel term of multiple
//! scattering": the series `F_avg E_avg Σ (F_avg (1 − E_avg))^k` of the
//! bounces after the first, times the first bounce's `F_avg`).
//!
//! `E(μ)` is tabulated here by bv's own Gauss–Legendre quadrature
//! ([`crate::quadrature`]) for the exact D, G and α of a model, at first use,
//! and cached per (distribution, geometry, roughnesses): about 20 ms for an
//! isotropic lobe, 0.1–0.3 s for a mixture of two scales, 0.2–0.5 s for an
//! anisotropic one (nine azimuths per μ, below; optimised build). The table has [`TABLE_LEN`] entries uniform in
//! `s = √μ` (denser near grazing, where E changes fastest) and is
//! interpolated linearly in μ ([`lookup`]). Accuracy, measured against a
//! brute-force quadrature written in the tests
//! (`crates/bv-core/tests/kulla_conty.rs`): `|E_table − E| < 8e-4` for
//! α ∈ {0.05, 0.3, 0.8, 1} and θ ∈ {0, 30, 60, 75, 89}° for Beckmann and GGX
//! with every geometry. The albedo of the compensated lobe with F = 1 is
//! `1 + (E(μi) − E_table(μi))`: within 8e-4 of 1 for α from 0.05 to 1 and
//! θi up to 89° by that quadrature, and by `bv check`'s Gauss–Kronrod one
//! (GGX, height-correlated Smith, α = 0.8: 1 − 5e-4 … 1 + 5e-5 over
//! θi = 0…89.999°).
//!
//! Anisotropy (αx ≠ αy): E then depends on the azimuth of incidence as well.
//! D is even in x and in y, so E(μ, φ) is even and π-periodic in φ and
//! symmetric about φ = π/2: a cosine series in 2φ. The table keeps its first
//! [`HARMONICS`] terms, `E(μ, φ) = Σ_k c_k(μ) cos 2kφ`, by trigonometric
//! interpolation of E computed at φ = 0, π/16, …, π/2 (each `c_k`
//! interpolated in μ as above), and `E_avg` is the cosine-weighted
//! hemispherical mean of that interpolant (the `cos 2kφ`, k ≥ 1, average to
//! zero over φ, so it is `2 ∫ c_0 μ dμ`). The lobe keeps its form,
//! `(1 − E(ωi)) (1 − E(ωo)) / (π (1 − E_avg))`, reciprocal by construction,
//! and its albedo is still exactly `1 − E(ωi)`, so with F = 1 the
//! compensated albedo is `1 + E(ωi) − E_table(ωi)` at every azimuth: within
//! 1e-3 of 1 at GGX αx = 0.8, αy = 0.4 for θi up to 85° (the five terms
//! leave the azimuthal error far below the μ interpolation's; measured in
//! `tests/kulla_conty.rs`). Before, the table held only the azimuthal
//! mean, and one azimuth was off by up to ±5 % there. The GPU port and the
//! f32 kernel read the mean's loss from the model's slots and the other
//! harmonics from a table blob ([`EnergyTable::gpu_harmonics`]).

use crate::fresnel::Fresnel;
use crate::microfacet::{Distribution, Geometry, Microfacet, Scale};
use crate::model::GpuBlob;
use crate::quadrature::{gauss_legendre, integrate};
use crate::{Rgb, mean_rgb};
use glam::DVec3;
use std::f64::consts::{FRAC_1_PI, FRAC_PI_2, PI};
use std::sync::{Arc, Mutex};

/// Entries of the E table, uniform in `s = √μ` from 0 to 1 (the WGSL port
/// and the f32 kernel read the same table).
pub const TABLE_LEN: usize = 32;

/// Terms of E's cosine series in 2φ kept for an anisotropic lobe (`c_0` the
/// azimuthal mean, then `cos 2φ` … `cos 16φ`; see the module doc). Eight
/// harmonics keep E within 1e-3 at αx/αy = 4 near grazing incidence, where
/// four left 1.5 %.
pub const HARMONICS: usize = 9;

/// The f32 rows `−c_k` (k = 1 … [`HARMONICS`] − 1) of an anisotropic table,
/// [`TABLE_LEN`] entries each, for the GPU's table buffer.
#[derive(Debug, PartialEq)]
pub struct HarmonicRows(Vec<f32>);

impl GpuBlob for HarmonicRows {
    fn gpu_data(&self) -> &[f32] {
        &self.0
    }
}

/// The smallest μ at which E is computed (the table's first node, s = 0,
/// stands for grazing incidence; E is continuous there).
const MU_MIN: f64 = 1e-7;

/// The tabulated directional albedo `E(μ)` of one microfacet lobe with F = 1
/// (for an anisotropic lobe `E(μ, φ)` as a cosine series in 2φ), and its
/// cosine-weighted average `E_avg`.
#[derive(Debug, Clone, PartialEq)]
pub struct EnergyTable {
    /// `c_0`: E itself for an isotropic lobe, else its mean over φ.
    e: [f64; TABLE_LEN],
    /// `c_1 … c_8` of an anisotropic lobe.
    harmonics: Option<Box<[[f64; TABLE_LEN]; HARMONICS - 1]>>,
    e_avg: f64,
    /// The same harmonics as f32 rows of the loss (`−c_k`), shared with the
    /// GPU (one allocation per table, so the packer uploads it once).
    gpu: Option<Arc<HarmonicRows>>,
}

impl EnergyTable {
    /// E (for an anisotropic lobe its mean over the azimuth) at the nodes
    /// `s_j = j / (TABLE_LEN − 1)`, `μ_j = s_j²`.
    pub fn nodes(&self) -> &[f64; TABLE_LEN] {
        &self.e
    }

    /// The harmonics `c_1 … c_8` of an anisotropic lobe at the nodes
    /// (`None` for an isotropic one).
    pub fn harmonics(&self) -> Option<&[[f64; TABLE_LEN]; HARMONICS - 1]> {
        self.harmonics.as_deref()
    }

    /// `E(μ)` by linear interpolation in μ between the nodes (μ clamped to
    /// [0, 1]); for an anisotropic lobe the mean over the azimuth.
    pub fn e(&self, mu: f64) -> f64 {
        lookup(&self.e, mu)
    }

    /// `E(ω)` for light from `w` (above the surface): [`EnergyTable::e`] of
    /// `w.z` plus, for an anisotropic lobe, the harmonics at `w`'s azimuth.
    pub fn e_dir(&self, w: DVec3) -> f64 {
        let mut e = lookup(&self.e, w.z);
        if let Some(h) = &self.harmonics {
            let c2 = cos_2phi(w.x, w.y);
            let (mut t_prev, mut t) = (1.0, c2);
            for row in h.iter() {
                e += lookup(row, w.z) * t;
                (t_prev, t) = (t, 2.0 * c2 * t - t_prev);
            }
        }
        e
    }

    /// A lower bound on E over every direction: the least of `c_0 − Σ |c_k|`
    /// over the nodes (between two nodes that is concave in μ, the `c_k` being
    /// linear there, so its least value is at a node).
    pub fn e_min(&self) -> f64 {
        (0..TABLE_LEN)
            .map(|j| {
                let spread: f64 = self
                    .harmonics
                    .as_ref()
                    .map_or(0.0, |h| h.iter().map(|r| r[j].abs()).sum());
                self.e[j] - spread
            })
            .fold(1.0, f64::min)
    }

    /// `E_avg = (1/π) ∫ E cos θ dω` of the interpolated table: `2 ∫ c_0(μ) μ dμ`
    /// (exactly: the interpolant is piecewise linear in μ, and the
    /// harmonics average to zero over φ).
    pub fn e_avg(&self) -> f64 {
        self.e_avg
    }

    /// The harmonics' loss rows for the GPU's table buffer (`None` for an
    /// isotropic lobe).
    pub fn gpu_harmonics(&self) -> Option<Arc<HarmonicRows>> {
        self.gpu.clone()
    }

    fn from_nodes(
        e: [f64; TABLE_LEN],
        harmonics: Option<[[f64; TABLE_LEN]; HARMONICS - 1]>,
    ) -> Self {
        // 2 ∫₀¹ E(μ) μ dμ, each segment by 2-point Gauss–Legendre (exact
        // for the quadratic E(μ) μ there).
        let gl = gauss_legendre(2);
        let mut sum = 0.0;
        for j in 0..TABLE_LEN - 1 {
            let (m0, m1) = (node_mu(j), node_mu(j + 1));
            for &(x, w) in &gl {
                let t = 0.5 * (x + 1.0);
                let mu = m0 + (m1 - m0) * t;
                let ej = e[j] * (1.0 - t) + e[j + 1] * t;
                sum += w * 0.5 * (m1 - m0) * ej * mu;
            }
        }
        let gpu = harmonics.map(|h| {
            Arc::new(HarmonicRows(
                h.iter().flatten().map(|&c| (-c) as f32).collect(),
            ))
        });
        Self {
            e,
            harmonics: harmonics.map(Box::new),
            e_avg: 2.0 * sum,
            gpu,
        }
    }
}

/// `cos 2φ` of the azimuth of `(x, y)`, 1 at the pole (where every harmonic
/// is zero anyway: E at normal incidence does not depend on φ).
pub fn cos_2phi(x: f64, y: f64) -> f64 {
    let r2 = x * x + y * y;
    if r2 > 0.0 { (x * x - y * y) / r2 } else { 1.0 }
}

/// The loss `1 − E(ω)` in f32 from the mean's loss row and, when
/// `harmonics`, the harmonics' rows `−c_k` (the batch kernel's per-lane
/// arithmetic; the WGSL port's `ms_loss_dir` does the same), never below 0.
pub fn loss_dir_f32(mean: &[f32; TABLE_LEN], harmonics: Option<&[f32]>, w: [f32; 3]) -> f32 {
    let [x, y, z] = w;
    let mut l = lookup_f32(mean, z);
    if let Some(rows) = harmonics {
        let r2 = x * x + y * y;
        let c2 = if r2 > 0.0 { (x * x - y * y) / r2 } else { 1.0 };
        let (mut t_prev, mut t) = (1.0f32, c2);
        for row in rows.chunks_exact(TABLE_LEN) {
            if let Ok(row) = <&[f32; TABLE_LEN]>::try_from(row) {
                l += lookup_f32(row, z) * t;
            }
            (t_prev, t) = (t, 2.0 * c2 * t - t_prev);
        }
    }
    if l > 0.0 { l } else { 0.0 }
}

/// μ of node `j`: `(j / (TABLE_LEN − 1))²`.
fn node_mu(j: usize) -> f64 {
    let s = j as f64 / (TABLE_LEN - 1) as f64;
    s * s
}

/// Linear interpolation in μ of a table of [`TABLE_LEN`] nodes uniform in
/// `√μ` (the same arithmetic as the WGSL port and the f32 kernel): the cell
/// is found in √μ, the weight is linear in μ, because near grazing
/// incidence `1 − E` is linear in μ (for height-correlated Smith,
/// `1 − E ≈ 6 μ` at GGX α = 0.8), which interpolation in √μ got wrong by
/// 1e-3 at θi = 89.99°.
pub fn lookup(e: &[f64; TABLE_LEN], mu: f64) -> f64 {
    let mu = mu.clamp(0.0, 1.0);
    let n = (TABLE_LEN - 1) as f64;
    let i = ((mu.sqrt() * n).floor() as usize).min(TABLE_LEN - 2);
    let (s0, s1) = (i as f64 / n, (i + 1) as f64 / n);
    let t = ((mu - s0 * s0) / (s1 * s1 - s0 * s0)).clamp(0.0, 1.0);
    e[i] * (1.0 - t) + e[i + 1] * t
}

/// [`lookup`] in f32, for the batch kernel (the WGSL port's `ms_e` does the
/// same arithmetic). A NaN μ gives a finite value (the callers mask such
/// lanes out).
pub fn lookup_f32(e: &[f32; TABLE_LEN], mu: f32) -> f32 {
    if mu.is_nan() {
        return e[0];
    }
    let mu = mu.clamp(0.0, 1.0);
    let n = (TABLE_LEN - 1) as f32;
    let i = ((mu.sqrt() * n).floor() as usize).min(TABLE_LEN - 2);
    let (s0, s1) = (i as f32 / n, (i + 1) as f32 / n);
    let t = ((mu - s0 * s0) / (s1 * s1 - s0 * s0)).clamp(0.0, 1.0);
    e[i] * (1.0 - t) + e[i + 1] * t
}

/// Panels of 8 Gauss–Legendre nodes in ψ and in φh ([`albedo_at`]): the
/// integrand has kinks where the mirror direction crosses the horizon, so
/// panels rather than a higher order.
const PANELS: usize = 16;

/// The directional albedo with F = 1 of `D G / (4 cosθi cosθo)` for light
/// from `wi` (`wi.z > 0`), by quadrature over the half vector:
/// `dωo = 4 (wo·h) dω_h` turns it into `∫ D(h) G (wi·h) / cosθi dω_h` over
/// the h with `wi·h > 0` whose mirror direction stays above the horizon.
/// Each scale of a mixture is integrated in its own variable ψ,
/// `tan θh = α tan ψ`, in which D cosθh dω_h is smooth and spread over
/// [0, π/2) (for GGX it is exactly `sin 2ψ dψ dφ/2π`), so the same nodes
/// serve α = 0.001 and α = 2.
fn albedo_at(ndf: &Microfacet, geometry: Geometry, wi: DVec3, symmetric: bool) -> f64 {
    let gl = gauss_legendre(8);
    // G's factor of wi, once per direction rather than per node.
    let lambda_i = ndf.lambda(wi);
    let g = |wo: DVec3, h: DVec3| match geometry {
        Geometry::VGroove => crate::microfacet::v_groove_g(wi, wo, h),
        Geometry::Smith => 1.0 / ((1.0 + lambda_i) * (1.0 + ndf.lambda(wo))),
        Geometry::SmithCorrelated => 1.0 / (1.0 + lambda_i + ndf.lambda(wo)),
    };
    let (phi_hi, phi_factor) = if symmetric {
        (PI, 2.0)
    } else {
        (2.0 * PI, 1.0)
    };
    let mut total = 0.0;
    let scales: [(Scale, f64); 2] = [(ndf.first, 1.0 - ndf.w2), (ndf.second, ndf.w2)];
    for (scale, weight) in scales {
        if weight <= 0.0 {
            continue;
        }
        let a = match scale.dist {
            Distribution::Blinn => scale.ax,
            _ => (scale.ax * scale.ay).sqrt(),
        };
        let inner = |psi: f64| {
            let tp = psi.tan();
            let theta = (a * tp).atan();
            // dθh/dψ = α sec²ψ / (1 + α² tan²ψ).
            let jac = a * (1.0 + tp * tp) / (1.0 + a * a * tp * tp);
            let (st, ct) = theta.sin_cos();
            let ring = |phi: f64| {
                let (sp, cp) = phi.sin_cos();
                let h = DVec3::new(st * cp, st * sp, ct);
                let ih = wi.dot(h);
                if ih <= 0.0 {
                    return 0.0;
                }
                let wo = 2.0 * ih * h - wi;
                if wo.z <= 0.0 {
                    return 0.0;
                }
                let v = scale.d(h) * g(wo, h) * ih / wi.z;
                if v.is_finite() { v } else { 0.0 }
            };
            integrate(ring, 0.0, phi_hi, PANELS, &gl) * phi_factor * st * jac
        };
        total += weight * integrate(inner, 0.0, FRAC_PI_2, PANELS, &gl);
    }
    total
}

/// `E(μ, φ)` for one μ and azimuth of incidence φ.
fn albedo_mu_phi(ndf: &Microfacet, geometry: Geometry, mu: f64, phi: f64) -> f64 {
    let mu = mu.clamp(MU_MIN, 1.0);
    let sin = (1.0 - mu * mu).max(0.0).sqrt();
    if ndf.is_isotropic() {
        // The integrand is then symmetric about the plane of incidence.
        return albedo_at(ndf, geometry, DVec3::new(sin, 0.0, mu), true);
    }
    albedo_at(
        ndf,
        geometry,
        DVec3::new(sin * phi.cos(), sin * phi.sin(), mu),
        false,
    )
}

/// Computes the table for `ndf` and `geometry` (no cache). E above 1 (Blinn's
/// D with Beckmann's Λ, whose albedo exceeds 1 at grazing angles, see
/// `models::cook_torrance`'s claims) is clamped to 1: that lobe loses no
/// energy there, and `1 − E` must not go negative.
///
/// An anisotropic lobe's E is computed at `φ_j = j π/16`, j = 0 … 8 (the
/// quarter [0, π/2] holds every azimuth: D is even in x and y), and its
/// series in `θ = 2φ` is the trigonometric interpolant through them:
/// `E(θ) = Σ″ a_k cos kθ` with `a_k = (2/N) Σ″_j E_j cos(k j π/N)`, N = 8,
/// `Σ″` halving the first and last terms (the discrete cosine transform of
/// type I), so `c_0 = a_0/2`, `c_k = a_k` for 0 < k < N, `c_N = a_N/2`.
pub fn compute_table(ndf: &Microfacet, geometry: Geometry) -> EnergyTable {
    let mut e = [0.0; TABLE_LEN];
    if ndf.is_isotropic() {
        for (j, ej) in e.iter_mut().enumerate() {
            let s = j as f64 / (TABLE_LEN - 1) as f64;
            *ej = albedo_mu_phi(ndf, geometry, s * s, 0.0).clamp(0.0, 1.0);
        }
        return EnergyTable::from_nodes(e, None);
    }
    const N: usize = HARMONICS - 1;
    let mut h = [[0.0; TABLE_LEN]; N];
    for j in 0..TABLE_LEN {
        let s = j as f64 / (TABLE_LEN - 1) as f64;
        let samples: [f64; N + 1] = std::array::from_fn(|i| {
            let phi = i as f64 * FRAC_PI_2 / N as f64;
            albedo_mu_phi(ndf, geometry, s * s, phi).clamp(0.0, 1.0)
        });
        for k in 0..=N {
            let mut a = 0.0;
            for (i, &ei) in samples.iter().enumerate() {
                let end = if i == 0 || i == N { 0.5 } else { 1.0 };
                a += end * ei * (PI * (k * i) as f64 / N as f64).cos();
            }
            a *= 2.0 / N as f64;
            let c = if k == 0 || k == N { 0.5 * a } else { a };
            if k == 0 {
                e[j] = c;
            } else {
                h[k - 1][j] = c;
            }
        }
    }
    EnergyTable::from_nodes(e, Some(h))
}

type Key = (u8, u8, u64, u64, u64, u64);

/// Cached tables, most recent last (a slider drag makes one per value; 64 is
/// plenty for a session and bounds the memory).
static CACHE: Mutex<Vec<(Key, Arc<EnergyTable>)>> = Mutex::new(Vec::new());
const CACHE_LEN: usize = 64;

/// The table for `ndf` and `geometry`, computed at first use and cached per
/// (distribution, geometry, αx, αy, α2, w2).
pub fn table(ndf: &Microfacet, geometry: Geometry) -> Arc<EnergyTable> {
    let s = &ndf.first;
    let blinn = s.dist == Distribution::Blinn;
    let key: Key = (
        s.dist as u8,
        geometry as u8,
        s.ax.to_bits(),
        if blinn { 0 } else { s.ay.to_bits() },
        if ndf.w2 > 0.0 {
            ndf.second.ax.to_bits()
        } else {
            0
        },
        ndf.w2.to_bits(),
    );
    if let Ok(c) = CACHE.lock()
        && let Some((_, t)) = c.iter().find(|(k, _)| *k == key)
    {
        return t.clone();
    }
    let t = Arc::new(compute_table(ndf, geometry));
    if let Ok(mut c) = CACHE.lock() {
        if c.len() >= CACHE_LEN {
            c.remove(0);
        }
        c.push((key, t.clone()));
    }
    t
}

/// `F_avg = 2 ∫₀¹ F(μ) μ dμ`, per channel.
pub fn fresnel_average(fresnel: &Fresnel) -> Rgb {
    let gl = gauss_legendre(8);
    let mut sum = Rgb::ZERO;
    let panels = 8;
    let h = 1.0 / panels as f64;
    for p in 0..panels {
        for &(x, w) in &gl {
            let mu = (p as f64 + 0.5 * (x + 1.0)) * h;
            sum += fresnel.eval(mu) * (w * 0.5 * h * mu);
        }
    }
    2.0 * sum
}

/// Kulla & Conty's compensation lobe for one model: its E table and the
/// constant colour `F_ms / (π (1 − E_avg))` that multiplies
/// `(1 − E(μi)) (1 − E(μo))`.
#[derive(Debug, Clone)]
pub struct KullaConty {
    /// The single-scattering albedo with F = 1.
    pub table: Arc<EnergyTable>,
    /// `F_ms / (π (1 − E_avg))` per channel (0 when E_avg = 1: nothing lost).
    pub scale: Rgb,
    /// `F_ms`, the coloured weight of the multiple bounces.
    pub f_ms: Rgb,
}

impl KullaConty {
    /// The compensation for `ndf`, `geometry` and `fresnel`.
    pub fn new(ndf: &Microfacet, geometry: Geometry, fresnel: &Fresnel) -> Self {
        let table = table(ndf, geometry);
        let e_avg = table.e_avg();
        let f_avg = fresnel_average(fresnel);
        // F_ms = F_avg² E_avg / (1 − F_avg (1 − E_avg)) (Kulla & Conty 2017).
        let f_ms = f_avg * f_avg * e_avg / (Rgb::ONE - f_avg * (1.0 - e_avg));
        let lost = 1.0 - e_avg;
        let scale = if lost > 1e-12 {
            f_ms * (FRAC_1_PI / lost)
        } else {
            Rgb::ZERO
        };
        Self {
            table,
            scale: if scale.is_finite() { scale } else { Rgb::ZERO },
            f_ms,
        }
    }

    /// `F_ms f_ms(ωi, ωo)` (zero below the horizon).
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        let loss = |w: DVec3| (1.0 - self.table.e_dir(w)).max(0.0);
        self.scale * (loss(wi) * loss(wo))
    }

    /// An upper bound on the lobe's albedo, averaged over the channels, for
    /// choosing between sampling strategies: `mean(F_ms) (1 − E_min)`, with
    /// [`EnergyTable::e_min`] a lower bound on E.
    pub fn weight(&self) -> f64 {
        mean_rgb(self.f_ms).max(0.0) * (1.0 - self.table.e_min()).max(0.0)
    }

    /// The loss `1 − E` at the nodes in f32, for the batch kernel and the
    /// GPU: subtracted in f64 here, because a smooth lobe keeps E within
    /// 1e-6 of 1 at most angles while `1/(π (1 − E_avg))` is large, and
    /// `1 − E` formed from an f32 E would lose most of its digits.
    pub fn loss_f32(&self) -> [f32; TABLE_LEN] {
        self.table.nodes().map(|x| (1.0 - x) as f32)
    }

    /// The harmonics' loss rows `−c_k` in f32, [`HARMONICS`] − 1 rows of
    /// [`TABLE_LEN`] (`None` for an isotropic lobe).
    pub fn harmonic_loss_f32(&self) -> Option<Arc<HarmonicRows>> {
        self.table.gpu_harmonics()
    }
}
