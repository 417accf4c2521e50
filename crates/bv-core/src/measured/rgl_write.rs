//! Writing any model as an isotropic RGB RGL `.bsdf` file, following the
//! acquisition pipeline of Dupuy & Jakob 2018 §5 with the model standing in
//! for the goniophotometer:
//!
//! 1. **NDF** from the retro-reflection `f(ω, ω)` by power iteration
//!    (Dupuy et al. 2015, "Extracting Microfacet-based BRDF Parameters from
//!    Arbitrary Materials with Power Iterations", eq. 9–10): with Smith's
//!    uncorrelated masking `G1(ω) = cos θ / σ(ω)`, `f(ω, ω) ∝ D(ω) / σ(ω)²`,
//!    so `D ← Y(f(ω, ω)) σ_D(ω)²`, normalised to `∫ D cos θm dωm = 1`, is
//!    iterated to its fixed point (8 steps).
//! 2. **σ** (projected area) `σ(ω) = ∫ D(m) ⟨ω·m⟩ dm` (eq. 4 of the 2018
//!    paper), with the azimuthal integral of `⟨ω·m⟩` in closed form.
//! 3. **VNDF** per incident direction, `D(m) ⟨ωi·m⟩` times the area element
//!    `2π² u_θ sin θm` of the square (so the warp follows the VNDF in solid
//!    angle).
//! 4. **Values** on the VNDF-warped square: node `s` maps through the warp
//!    (exactly as the reader builds it from the `f32` tables) to a normal
//!    `m`, `ωo = reflect(ωi, m)`, and the node stores `f cos θo · 4σ(ωi)/D(m)`
//!    (`jacobian` = 1, §6), with the luminance of that as the sampling
//!    density.
//!
//! Incident elevations are `n` nodes evenly spaced over `[0°, 85°]`
//! ([`RglWriteOptions::theta_max_deg`]); beyond the last, a reader holds the
//! last slice. `phi_i = [0]`: the data is isotropic (an anisotropic model is
//! written as its `φi = 0` slice, relative azimuths kept). `valid` marks the
//! nodes whose `ωo` lies above the horizon.

use super::marginal::Marginal2D;
use super::rgl::{phi2u, theta2u, u2phi, u2theta};
use super::tensor::TensorWriter;
use crate::{Brdf, BvError, Result, Rgb, fsio};
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;

/// Resolutions and labels of a written file.
#[derive(Debug, Clone, PartialEq)]
pub struct RglWriteOptions {
    /// Incident elevations tabulated (at least 2).
    pub theta_i: usize,
    /// Largest incident elevation tabulated, in degrees (below 90).
    pub theta_max_deg: f64,
    /// Nodes of the NDF and σ along `u_θ` (at least 2).
    pub ndf: usize,
    /// Nodes of the VNDF square per side (at least 2).
    pub vndf: usize,
    /// Nodes of the luminance and RGB squares per side (at least 2).
    pub values: usize,
    /// The `description` field.
    pub description: String,
}

impl Default for RglWriteOptions {
    fn default() -> Self {
        Self {
            theta_i: 16,
            theta_max_deg: 85.0,
            ndf: 128,
            vndf: 128,
            values: 32,
            description: String::new(),
        }
    }
}

/// Luminance of linear sRGB (Rec. 709 / sRGB Y row).
fn luminance(c: Rgb) -> f64 {
    0.2126 * c.x + 0.7152 * c.y + 0.0722 * c.z
}

/// `∫₀^{2π} max(0, ω·m) dφm` for `ω` at elevation `θ` and `m` at `θm`.
fn azimuthal_cosine(theta: f64, theta_m: f64) -> f64 {
    let a = theta.cos() * theta_m.cos();
    let b = theta.sin() * theta_m.sin();
    if b <= a.abs() {
        return if a > 0.0 { 2.0 * PI * a } else { 0.0 };
    }
    let phi0 = (-a / b).clamp(-1.0, 1.0).acos();
    2.0 * (a * phi0 + b * phi0.sin())
}

/// A function of `u_θ` given by nodes, linearly interpolated (how the
/// reader's bilinear interpolant reads an isotropic 2-row table).
fn lerp_nodes(nodes: &[f64], u: f64) -> f64 {
    let n = nodes.len();
    let x = u.clamp(0.0, 1.0) * (n - 1) as f64;
    let i = (x as usize).min(n - 2);
    let t = x - i as f64;
    nodes[i] * (1.0 - t) + nodes[i + 1] * t
}

/// The share of the uniform NDF mixed into the extracted one.
const UNIFORM_SHARE: f64 = 0.05;

/// Integration points in `u_θ` (midpoints) for the 1-D integrals over θm.
const QUAD: usize = 4096;

/// `σ(θ) = ∫ D(m) ⟨ω·m⟩ dm` and `∫ D cos θm dm` for a `D` given by nodes.
fn sigma_of(d: &[f64], theta: f64) -> f64 {
    let mut s = 0.0;
    for k in 0..QUAD {
        let u = (k as f64 + 0.5) / QUAD as f64;
        let tm = u2theta(u);
        // dθm = π u du.
        s += lerp_nodes(d, u) * tm.sin() * azimuthal_cosine(theta, tm) * PI * u;
    }
    s / QUAD as f64
}

fn check(opts: &RglWriteOptions) -> Result<()> {
    let bad = |what: &str| Err(BvError::Invalid(format!("RGL writer: {what}")));
    if opts.theta_i < 2 || opts.ndf < 2 || opts.vndf < 2 || opts.values < 2 {
        return bad("every resolution needs at least 2 nodes");
    }
    if opts.theta_i > 90 || opts.ndf > 1024 || opts.vndf > 512 || opts.values > 256 {
        return bad("resolutions are limited to 90 θi, 1024 NDF, 512 VNDF and 256 value nodes");
    }
    if !(opts.theta_max_deg > 0.0 && opts.theta_max_deg < 90.0) {
        return bad("the largest θi must lie in (0°, 90°)");
    }
    Ok(())
}

fn round32(v: &[f64]) -> Vec<f64> {
    v.iter().map(|x| f64::from(*x as f32)).collect()
}

fn to32(v: &[f64]) -> Vec<f32> {
    v.iter().map(|x| *x as f32).collect()
}

/// The bytes of `brdf` as an isotropic RGB RGL file (see the module notes).
/// Refuses a model whose retro-reflection is zero or not finite everywhere
/// (no NDF can be extracted) and non-finite values.
pub fn tabulate_rgl(brdf: &dyn Brdf, opts: &RglWriteOptions) -> Result<Vec<u8>> {
    check(opts)?;
    let nd = opts.ndf;
    // Elevations of the NDF nodes; the last (u = 1, grazing) is evaluated
    // just inside the horizon.
    let node_theta = |j: usize, n: usize| u2theta(j as f64 / (n - 1) as f64).min(FRAC_PI_2 - 1e-3);
    let retro: Vec<f64> = (0..nd)
        .map(|j| {
            let t = node_theta(j, nd);
            let w = DVec3::new(t.sin(), 0.0, t.cos());
            luminance(brdf.eval(w, w)).max(0.0)
        })
        .collect();
    if retro.iter().any(|r| !r.is_finite()) || !retro.iter().any(|r| *r > 0.0) {
        return Err(BvError::Invalid(
            "RGL writer: the model's retro-reflection f(ω, ω) is zero or not finite everywhere, so no NDF can be extracted from it".into(),
        ));
    }
    // Power iteration: D ← retro · σ², normalised.
    let mut d = vec![1.0 / PI; nd];
    let mut sigma = vec![0.0; nd];
    for _ in 0..8 {
        for (j, s) in sigma.iter_mut().enumerate() {
            *s = sigma_of(&d, node_theta(j, nd));
        }
        let mut next: Vec<f64> = retro.iter().zip(&sigma).map(|(r, s)| r * s * s).collect();
        // ∫ D cos θm dωm = 2π ∫ D cos θm sin θm dθm.
        let mut norm = 0.0;
        for k in 0..QUAD {
            let u = (k as f64 + 0.5) / QUAD as f64;
            let tm = u2theta(u);
            norm += lerp_nodes(&next, u) * tm.cos() * tm.sin() * PI * u;
        }
        norm *= 2.0 * PI / QUAD as f64;
        if !(norm > 0.0 && norm.is_finite()) {
            return Err(BvError::Invalid(
                "RGL writer: the NDF iteration did not converge (zero projected area)".into(),
            ));
        }
        next.iter_mut().for_each(|x| *x /= norm);
        d = next;
    }
    // A share of the uniform distribution D = 1/π keeps the VNDF, and so the
    // value grid, away from zero where the retro-reflection says little
    // about the lobe (Phong's lobe follows the mirror direction, not the
    // half vector, and its retro-reflection vanishes beyond 45°); any
    // positive D reproduces the data at the nodes (the Jacobian undoes it).
    d.iter_mut()
        .for_each(|x| *x = (1.0 - UNIFORM_SHARE) * *x + UNIFORM_SHARE / PI);
    let d = round32(&d);
    for (j, s) in sigma.iter_mut().enumerate() {
        *s = sigma_of(&d, node_theta(j, nd));
    }
    let smax = sigma.iter().copied().fold(0.0, f64::max);
    sigma.iter_mut().for_each(|x| *x = x.max(1e-7 * smax));
    let sigma = round32(&sigma);
    // Two identical φ rows: the tables are isotropic.
    let d2: Vec<f64> = d.iter().chain(d.iter()).copied().collect();
    let s2: Vec<f64> = sigma.iter().chain(sigma.iter()).copied().collect();
    let ndf_w = Marginal2D::new(&d2, nd, 2, vec![], false, false).map_err(BvError::Invalid)?;
    let sigma_w = Marginal2D::new(&s2, nd, 2, vec![], false, false).map_err(BvError::Invalid)?;

    let nt = opts.theta_i;
    let theta_i: Vec<f64> = (0..nt)
        .map(|k| f64::from((opts.theta_max_deg.to_radians() * k as f64 / (nt - 1) as f64) as f32))
        .collect();
    let nv = opts.vndf;
    let n = opts.values;
    let mut vndf = Vec::with_capacity(nt * nv * nv);
    let mut lum = Vec::with_capacity(nt * n * n);
    let mut rgb = vec![0.0; nt * 3 * n * n];
    let mut valid = Vec::with_capacity(nt * n * n);
    for (k, &ti) in theta_i.iter().enumerate() {
        let wi = DVec3::new(ti.sin(), 0.0, ti.cos());
        // VNDF slice: rows φ (relative to φi = 0), columns u_θ.
        let mut slice = Vec::with_capacity(nv * nv);
        for y in 0..nv {
            let phi = u2phi(y as f64 / (nv - 1) as f64);
            for x in 0..nv {
                let u = x as f64 / (nv - 1) as f64;
                let tm = u2theta(u);
                let m = DVec3::new(tm.sin() * phi.cos(), tm.sin() * phi.sin(), tm.cos());
                let v = lerp_nodes(&d, u) * wi.dot(m).max(0.0) * 2.0 * PI * PI * u * tm.sin();
                slice.push(f64::from(v as f32));
            }
        }
        // The reader's warp of this slice (phi_i has one value: no φ
        // interpolation).
        let warp = Marginal2D::new(&slice, nv, nv, vec![vec![0.0]], true, true)
            .map_err(|e| BvError::Invalid(format!("RGL writer: VNDF at θi = {ti}: {e}")))?;
        vndf.extend_from_slice(&slice);
        let u_wi = [theta2u(ti), phi2u(0.0)];
        let s = sigma_w.eval(u_wi, &[]);
        for y in 0..n {
            for x in 0..n {
                let sp = [x as f64 / (n - 1) as f64, y as f64 / (n - 1) as f64];
                let (mut u_m, _) = warp.sample(sp, &[0.0]);
                // The first column is the pole of the square (m = the
                // normal, where φm is undefined): the warp's clamped sample
                // lands a little off it, in a direction that depends on the
                // row; store the pole's value in every row, so that a half
                // vector on the normal reads the same whatever its φ.
                if x == 0 {
                    u_m[0] = 0.0;
                }
                let tm = u2theta(u_m[0]);
                let phi = u2phi(u_m[1]);
                let m = DVec3::new(tm.sin() * phi.cos(), tm.sin() * phi.sin(), tm.cos());
                let c = wi.dot(m);
                let wo = 2.0 * c * m - wi;
                let mut v = Rgb::ZERO;
                let ok = c > 0.0 && wo.z > 0.0;
                if ok {
                    let dm = ndf_w.eval(u_m, &[]);
                    v = brdf.eval(wi, wo) * wo.z * 4.0 * s / dm;
                }
                if !v.is_finite() {
                    return Err(BvError::Invalid(format!(
                        "RGL writer: the model is not finite at wi = {wi}, wo = {wo}"
                    )));
                }
                for ch in 0..3 {
                    rgb[((k * 3 + ch) * n + y) * n + x] = v[ch];
                }
                lum.push(luminance(v).max(0.0));
                valid.push(u8::from(ok));
            }
        }
    }
    if lum.chunks(n * n).any(|c| c.iter().all(|v| *v == 0.0)) {
        return Err(BvError::Invalid(
            "RGL writer: the model reflects nothing at some tabulated incident direction".into(),
        ));
    }
    let (nt64, nd64, nv64, n64) = (nt as u64, nd as u64, nv as u64, n as u64);
    let mut w = TensorWriter::new();
    w.u8(
        "description",
        &[opts.description.len() as u64],
        opts.description.as_bytes(),
    )
    .u8("version", &[2], &[1, 0])
    .f32("theta_i", &[nt64], &to32(&theta_i))
    .f32("phi_i", &[1], &[0.0])
    .f32("ndf", &[2, nd64], &to32(&d2))
    .f32("sigma", &[2, nd64], &to32(&s2))
    .f32("vndf", &[1, nt64, nv64, nv64], &to32(&vndf))
    .f32("luminance", &[1, nt64, n64, n64], &to32(&lum))
    .f32("rgb", &[1, nt64, 3, n64, n64], &to32(&rgb))
    .u8("valid", &[1, nt64, n64, n64], &valid)
    .u8("jacobian", &[1], &[1]);
    Ok(w.to_bytes())
}

/// [`tabulate_rgl`] written to `path` atomically (see
/// [`fsio::write_atomic`]).
pub fn write_rgl(brdf: &dyn Brdf, opts: &RglWriteOptions, path: &Path) -> Result<usize> {
    let bytes = tabulate_rgl(brdf, opts)?;
    fsio::write_atomic(path, |w| w.write_all(&bytes))?;
    Ok(bytes.len())
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn azimuthal_cosine_matches_quadrature() {
        for &(t, tm) in &[(0.3, 0.2), (1.2, 0.9), (0.1, 1.5), (1.5, 1.5), (0.0, 0.7)] {
            let n = 200_000;
            let q: f64 = (0..n)
                .map(|k| {
                    let p = 2.0 * PI * (k as f64 + 0.5) / n as f64;
                    let ip = f64::sin(t) * f64::sin(tm) * p.cos() + f64::cos(t) * f64::cos(tm);
                    ip.max(0.0)
                })
                .sum::<f64>()
                * 2.0
                * PI
                / n as f64;
            assert!((q - azimuthal_cosine(t, tm)).abs() < 1e-6, "{t} {tm}");
        }
    }
}
