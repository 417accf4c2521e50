//! RGL measured materials (Dupuy & Jakob 2018, "An Adaptive Parameterization
//! for Efficient Material Acquisition and Rendering", ACM TOG 37(6)): the
//! `.bsdf` tensor files of the EPFL material database, read and evaluated as
//! Mitsuba 3's `measured` plugin (`src/bsdfs/measured.cpp`) and the RGL
//! loader `powitacq` do.
//!
//! # Fields ([`super::tensor`] container)
//! - `theta_i[nθ]`, `phi_i[nφ]`: the incident directions measured
//!   (radians); `nφ ≤ 2` means isotropic.
//! - `ndf[ny, nx]`, `sigma[ny, nx]`: the microfacet distribution `D` and the
//!   projected area `σ(ω) = ∫ D(m) ⟨ω·m⟩ dm` (Dupuy & Jakob §5, eq. 4), over
//!   the square `(u_θ, u_φ)` with `θ = u_θ² π/2`, `φ = (2u_φ − 1) π`.
//! - `vndf[nφ, nθ, ny, nx]`: the visible normals' distribution per incident
//!   direction, a warp of the square (§4).
//! - `luminance[nφ, nθ, n, n]`: a density on the warped square used only for
//!   sampling; `rgb[nφ, nθ, 3, n, n]` or `spectra[nφ, nθ, nλ, n, n]` with
//!   `wavelengths[nλ]` (nm): the measured values on the warped square.
//! - `jacobian[1]` (`uint8`): when set, the stored values are `f cos θo ·
//!   4σ(ωi)/D(m)` and evaluation multiplies by `D/(4σ)` (§6).
//! - `description` (`uint8` text); optional `valid` (a mask of measured
//!   samples, reported as a fraction) and `version`.
//!
//! # Evaluation (§4–6, `measured.cpp`'s `eval`)
//! `m = normalize(ωi + ωo)`; `(θi, φi)`, `(θm, φm)` to the unit square
//! (`u_θ = √(2θ/π)`, `u_φ = (φ + π)/2π`, with `φm − φi` for isotropic
//! data); the VNDF warp of `(φi, θi)` is inverted at `u_m`
//! ([`Marginal2D::invert`]), giving the point of the square where the
//! values are interpolated (bilinearly, and linearly in θi, φi); then the
//! Jacobian factor `D(u_m) / (4 σ(u_i))` if the file asks for it. The
//! result is `f cos θo` (Mitsuba's `eval` includes the cosine): bv's
//! [`RglMaterial::eval`] divides by `cos θo` to return `f`. Anisotropic
//! files whose `phi_i` covers a half or a quarter turn are folded by the
//! symmetry Mitsuba assumes (`m_reduction`); isotropic files are not folded.
//!
//! # Spectra
//! Spectral files are turned into linear sRGB once, at load: the CIE 1931 2°
//! observer (the multi-lobe fit of Wyman, Sloan & Shirley 2013, "Simple
//! Analytic Approximations to the CIE XYZ Color Matching Functions", JCGT
//! 2(2), eq. 2), trapezoid weights over the file's wavelengths, the XYZ →
//! linear sRGB matrix of IEC 61966-2-1, and **illuminant E as white**: each
//! channel's weights are scaled so that a flat spectrum of value `v` gives
//! `(v, v, v)` (a von Kries adaptation from E in linear sRGB). The
//! conversion is linear, so converting the tables equals converting each
//! interpolated spectrum.

use super::marginal::Marginal2D;
use super::tensor::{Dtype, Field, TensorFile};
use crate::{BvError, Result, Rgb, fsio};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::{Path, PathBuf};
use std::sync::{Arc, Mutex};

/// `cos θo` of the last reliable outgoing elevation (θo = 87°): the tables
/// resolve `f cos θo`, which interpolation does not bring to 0 exactly at
/// the horizon, so `f = (f cos θo) / cos θo` blows up within the last grid
/// cell (a GGX α 0.3 written and read back: within 2 % of the model up to
/// 87°, then 0.25, 0.59 and 1.41 against 0.22 at 89°, 89.9° and the back
/// side at 89.9°). [`RglMaterial::eval`] holds `f` at its value at 87° on
/// the same azimuth beyond it (within 6 % of the model there); `f cos θo`
/// ([`RglMaterial::eval_cos`], Mitsuba's quantity) is left as stored.
pub const GRAZING_COS: f64 = 0.052_335_956_242_943_835;

/// An RGL material in memory, ready to evaluate and sample.
#[derive(Debug, Clone)]
pub struct RglMaterial {
    name: String,
    description: String,
    version: Option<String>,
    theta_i: Vec<f64>,
    phi_i: Vec<f64>,
    ndf: Marginal2D,
    sigma: Marginal2D,
    vndf: Marginal2D,
    luminance: Marginal2D,
    rgb: Marginal2D,
    isotropic: bool,
    phi_free: bool,
    jacobian: bool,
    reduction: i64,
    wavelengths: Option<(usize, f64, f64)>,
    valid: Option<f64>,
    warnings: Vec<String>,
    bytes: usize,
    gpu: Vec<f32>,
    gpu_slots: [f32; GPU_SLOTS],
    proxy: SamplingProxy,
}

/// Number of values [`RglMaterial::gpu_slots`] returns.
pub const GPU_SLOTS: usize = 19;

fn file_err(name: &str, reason: impl Into<String>) -> BvError {
    BvError::File {
        path: name.to_string(),
        reason: reason.into(),
    }
}

/// `u_θ = √(2θ/π)`.
pub fn theta2u(theta: f64) -> f64 {
    (theta * (2.0 / PI)).max(0.0).sqrt()
}

/// `θ = u² π/2`.
pub fn u2theta(u: f64) -> f64 {
    u * u * FRAC_PI_2
}

/// `u_φ = (φ + π)/2π`.
pub fn phi2u(phi: f64) -> f64 {
    (phi + PI) / (2.0 * PI)
}

/// `φ = (2u − 1) π`.
pub fn u2phi(u: f64) -> f64 {
    (2.0 * u - 1.0) * PI
}

/// The angle of `d` from +z, stable near the pole (Mitsuba's `elevation`).
pub fn elevation(d: DVec3) -> f64 {
    let dist = (d.x * d.x + d.y * d.y + (d.z - 1.0) * (d.z - 1.0)).sqrt();
    2.0 * (0.5 * dist).clamp(-1.0, 1.0).asin()
}

/// `x` times the negated sign of `y` (Dr.Jit's `mulsign_neg`: `+0` counts
/// as positive).
fn mulsign_neg(x: f64, y: f64) -> f64 {
    if y.is_sign_negative() { x } else { -x }
}

/// CIE 1931 2° colour matching functions `(x̄, ȳ, z̄)` at `nm`, by Wyman,
/// Sloan & Shirley 2013's multi-lobe piecewise-Gaussian fit (eq. 2).
pub fn cie_xyz(nm: f64) -> DVec3 {
    let g = |mu: f64, s1: f64, s2: f64| {
        let t = (nm - mu) / if nm < mu { s1 } else { s2 };
        (-0.5 * t * t).exp()
    };
    DVec3::new(
        1.056 * g(599.8, 37.9, 31.0) + 0.362 * g(442.0, 16.0, 26.7) - 0.065 * g(501.1, 20.4, 26.2),
        0.821 * g(568.8, 46.9, 40.5) + 0.286 * g(530.9, 16.3, 31.1),
        1.217 * g(437.0, 11.8, 36.0) + 0.681 * g(459.0, 26.0, 13.8),
    )
}

/// XYZ → linear sRGB (IEC 61966-2-1), rows.
const XYZ_TO_SRGB: [[f64; 3]; 3] = [
    [3.240_454_2, -1.537_138_5, -0.498_531_4],
    [-0.969_266_0, 1.876_010_8, 0.041_556_0],
    [0.055_643_4, -0.204_025_9, 1.057_225_2],
];

/// Per-wavelength weights `w[c][k]` that turn a spectrum sampled at `nm`
/// into linear sRGB with illuminant E as white (see the module's notes).
pub fn spectral_weights(nm: &[f64]) -> std::result::Result<[Vec<f64>; 3], String> {
    let n = nm.len();
    let mut w: [Vec<f64>; 3] = [vec![0.0; n], vec![0.0; n], vec![0.0; n]];
    for k in 0..n {
        // Trapezoid weight of sample k.
        let lo = if k > 0 { nm[k - 1] } else { nm[k] };
        let hi = if k + 1 < n { nm[k + 1] } else { nm[k] };
        let dl = 0.5 * (hi - lo);
        let xyz = cie_xyz(nm[k]);
        for (c, row) in XYZ_TO_SRGB.iter().enumerate() {
            w[c][k] = (row[0] * xyz.x + row[1] * xyz.y + row[2] * xyz.z) * dl;
        }
    }
    for (c, wc) in w.iter_mut().enumerate() {
        let s: f64 = wc.iter().sum();
        if s.is_nan() || s <= 1e-6 {
            return Err(format!(
                "the wavelengths ({:.0}–{:.0} nm) do not cover the visible range: channel {c} has no weight",
                nm.first().copied().unwrap_or(0.0),
                nm.last().copied().unwrap_or(0.0)
            ));
        }
        wc.iter_mut().for_each(|x| *x /= s);
    }
    Ok(w)
}

/// What the reader checks a table field against.
struct Expect<'a> {
    tf: &'a TensorFile,
}

impl Expect<'_> {
    fn err(&self, reason: impl Into<String>) -> BvError {
        file_err(self.tf.name(), reason)
    }

    /// A numeric table of the given rank, finite and (with `min`) bounded.
    fn table(&self, name: &str, rank: usize, min: Option<f64>) -> Result<(&Field, Vec<f64>)> {
        let f = self.tf.require(name)?;
        let v = self.tf.finite_values(f, rank, min)?;
        Ok((f, v))
    }

    fn dim(&self, f: &Field, axis: usize) -> usize {
        f.shape.get(axis).copied().unwrap_or(0) as usize
    }

    fn same(&self, a: &Field, ai: usize, b: &Field, bi: usize, what: &str) -> Result<()> {
        if a.shape.get(ai) != b.shape.get(bi) {
            return Err(self.err(format!(
                "shapes disagree: `{}` {} and `{}` {} ({what})",
                a.name,
                a.shape_text(),
                b.name,
                b.shape_text()
            )));
        }
        Ok(())
    }

    fn at_least_2(&self, f: &Field, axes: &[usize]) -> Result<()> {
        for &a in axes {
            if self.dim(f, a) < 2 {
                return Err(self.err(format!(
                    "`{}` {}: the interpolated axes need at least 2 nodes",
                    f.name,
                    f.shape_text()
                )));
            }
        }
        Ok(())
    }
}

fn increasing(tf: &TensorFile, name: &str, v: &[f64]) -> Result<()> {
    if v.is_empty() {
        return Err(file_err(tf.name(), format!("`{name}` is empty")));
    }
    if let Some(w) = v.windows(2).find(|w| w[1] <= w[0]) {
        return Err(file_err(
            tf.name(),
            format!("`{name}` must increase, but {} follows {}", w[1], w[0]),
        ));
    }
    Ok(())
}

impl RglMaterial {
    /// Reads a `.bsdf` file (see [`TensorFile::read`] for the limits).
    pub fn read(path: &Path) -> Result<Self> {
        let tf = TensorFile::read(path)?;
        Self::from_tensor(&tf)
    }

    /// Parses the bytes of a `.bsdf` file (`name` is used in errors).
    pub fn parse(bytes: Vec<u8>, name: &str) -> Result<Self> {
        let tf = TensorFile::parse(bytes, name)?;
        Self::from_tensor(&tf)
    }

    /// The material of a parsed tensor file, every field checked: ranks,
    /// shapes that agree with each other, finite values, non-negative
    /// densities, increasing θi/φi/wavelengths.
    pub fn from_tensor(tf: &TensorFile) -> Result<Self> {
        let x = Expect { tf };
        let name = tf.name();
        let (theta_f, theta_i) = x.table("theta_i", 1, None)?;
        increasing(tf, "theta_i", &theta_i)?;
        if theta_i
            .iter()
            .any(|t| !(0.0..=FRAC_PI_2 + 1e-6).contains(t))
        {
            return Err(x.err(format!(
                "`theta_i` must lie in [0, π/2] radians, found {:?}",
                theta_i
            )));
        }
        let (phi_f, phi_i) = x.table("phi_i", 1, None)?;
        increasing(tf, "phi_i", &phi_i)?;
        let (ndf_f, ndf) = x.table("ndf", 2, Some(0.0))?;
        let (sigma_f, sigma) = x.table("sigma", 2, Some(0.0))?;
        let (vndf_f, vndf) = x.table("vndf", 4, Some(0.0))?;
        let (lum_f, lum) = x.table("luminance", 4, Some(0.0))?;
        x.at_least_2(ndf_f, &[0, 1])?;
        x.at_least_2(sigma_f, &[0, 1])?;
        x.at_least_2(vndf_f, &[2, 3])?;
        x.at_least_2(lum_f, &[2, 3])?;
        for f in [vndf_f, lum_f] {
            x.same(f, 0, phi_f, 0, "one slice per φi")?;
            x.same(f, 1, theta_f, 0, "one slice per θi")?;
        }
        x.same(lum_f, 2, lum_f, 3, "the luminance square is n × n")?;

        let (nphi, ntheta) = (phi_i.len(), theta_i.len());
        let (spec_f, spec, wavelengths) = match tf.field("wavelengths") {
            Some(_) => {
                let (wl_f, wl) = x.table("wavelengths", 1, Some(0.0))?;
                increasing(tf, "wavelengths", &wl)?;
                let (sf, s) = x.table("spectra", 5, None)?;
                x.same(sf, 2, wl_f, 0, "one spectral slice per wavelength")?;
                (sf, s, Some(wl))
            }
            None => {
                let (rf, r) = x.table("rgb", 5, None)?;
                if rf.shape[2] != 3 {
                    return Err(x.err(format!(
                        "`rgb` {}: the third axis holds the 3 channels",
                        rf.shape_text()
                    )));
                }
                (rf, r, None)
            }
        };
        x.same(spec_f, 0, phi_f, 0, "one slice per φi")?;
        x.same(spec_f, 1, theta_f, 0, "one slice per θi")?;
        x.same(spec_f, 3, lum_f, 2, "values and luminance share the square")?;
        x.same(spec_f, 4, lum_f, 3, "values and luminance share the square")?;

        let jac = tf.require("jacobian")?;
        if jac.shape != [1] {
            return Err(x.err(format!(
                "`jacobian` has shape {}, expected [1]",
                jac.shape_text()
            )));
        }
        let jacobian = tf.values(jac)[0] != 0.0;
        let desc = tf.require("description")?;
        if desc.shape.len() != 1 || desc.dtype != Dtype::UInt8 {
            return Err(x.err(format!(
                "`description` is {} {}, expected uint8 text",
                desc.dtype.name(),
                desc.shape_text()
            )));
        }
        let description = String::from_utf8_lossy(tf.raw(desc))
            .trim_end_matches('\0')
            .to_string();
        let version = tf.field("version").map(|f| {
            if f.dtype == Dtype::UInt8 && f.shape.len() == 1 && f.len() > 2 {
                String::from_utf8_lossy(tf.raw(f))
                    .trim_end_matches('\0')
                    .to_string()
            } else {
                let v: Vec<String> = tf.values(f).iter().map(|v| format!("{v}")).collect();
                v.join(".")
            }
        });
        let valid = tf.field("valid").map(|f| {
            let v = tf.values(f);
            if v.is_empty() {
                0.0
            } else {
                v.iter().filter(|x| **x != 0.0).count() as f64 / v.len() as f64
            }
        });

        // Whether the NDF and σ tables are constant along φ: then an
        // isotropic file's evaluation depends on φi − φo only (σ is read at
        // the absolute φi).
        let flat_rows = |v: &[f64], nx: usize| {
            v.chunks(nx.max(1)).all(|r| {
                r.iter()
                    .zip(&v[..nx])
                    .all(|(a, b)| (a - b).abs() <= 1e-6 * b.abs())
            })
        };
        let phi_free = flat_rows(&ndf, x.dim(ndf_f, 1)) && flat_rows(&sigma, x.dim(sigma_f, 1));
        let mut warnings = Vec::new();
        let (ny, nx) = (x.dim(ndf_f, 0), x.dim(ndf_f, 1));
        let ndf = Marginal2D::new(&ndf, nx, ny, vec![], false, false)
            .map_err(|e| x.err(format!("`ndf`: {e}")))?;
        let (sy, sx) = (x.dim(sigma_f, 0), x.dim(sigma_f, 1));
        if jacobian && sigma.iter().any(|s| *s <= 0.0) {
            return Err(x.err("`sigma` must be positive where the Jacobian D/(4σ) divides by it"));
        }
        let sigma = Marginal2D::new(&sigma, sx, sy, vec![], false, false)
            .map_err(|e| x.err(format!("`sigma`: {e}")))?;
        let params = vec![phi_i.clone(), theta_i.clone()];
        let (vy, vx) = (x.dim(vndf_f, 2), x.dim(vndf_f, 3));
        let vndf = Marginal2D::new(&vndf, vx, vy, params.clone(), true, true)
            .map_err(|e| x.err(format!("`vndf`: {e}")))?;
        let n = x.dim(lum_f, 2);
        // A slice of zero luminance (a black measurement) cannot be a
        // density; sampling falls back to the VNDF alone there.
        let mut lum = lum;
        for (s, chunk) in lum.chunks_mut(n * n).enumerate() {
            if chunk.iter().all(|v| *v == 0.0) {
                chunk.iter_mut().for_each(|v| *v = 1.0);
                warnings.push(format!(
                    "luminance slice {s} is all zero: sampling uses the VNDF alone there"
                ));
            }
        }
        let luminance = Marginal2D::new(&lum, n, n, params.clone(), true, true)
            .map_err(|e| x.err(format!("`luminance`: {e}")))?;

        let cells = n * n;
        let (rgb_values, wl_info) = match &wavelengths {
            Some(wl) => {
                let w = spectral_weights(wl).map_err(|e| x.err(e))?;
                let nl = wl.len();
                let mut out = vec![0.0; nphi * ntheta * 3 * cells];
                for s in 0..nphi * ntheta {
                    for (c, wc) in w.iter().enumerate() {
                        let dst = &mut out[(s * 3 + c) * cells..(s * 3 + c + 1) * cells];
                        for (k, wk) in wc.iter().enumerate() {
                            let src = &spec[(s * nl + k) * cells..(s * nl + k + 1) * cells];
                            for (d, v) in dst.iter_mut().zip(src) {
                                *d += wk * v;
                            }
                        }
                    }
                }
                let lo = wl.first().copied().unwrap_or(0.0);
                let hi = wl.last().copied().unwrap_or(0.0);
                (out, Some((nl, lo, hi)))
            }
            None => (spec, None),
        };
        let rgb = Marginal2D::new(
            &rgb_values,
            n,
            n,
            vec![phi_i.clone(), theta_i.clone(), vec![0.0, 1.0, 2.0]],
            false,
            false,
        )
        .map_err(|e| x.err(format!("values: {e}")))?;

        let isotropic = nphi <= 2;
        let reduction = if isotropic {
            // No fold, as the paper and `powitacq`: the reduction describes
            // anisotropic data. (Mitsuba 3.9.1 leaves `m_reduction`
            // uninitialised for isotropic files: measured, the same file
            // folded by a half turn in some runs and not in others. With
            // one φi and NDF and σ constant along φ, as in the files
            // measured and written, the fold changes nothing.)
            0
        } else {
            let span = phi_i[nphi - 1] - phi_i[0];
            (2.0 * PI / span).round() as i64
        };
        let _ = name;
        let (gpu, gpu_slots) = gpu_blob(
            &phi_i, &theta_i, &vndf, &rgb, &ndf, &sigma, jacobian, reduction,
        );
        let mut m = Self {
            name: tf.name().to_string(),
            description,
            version,
            theta_i,
            phi_i,
            ndf,
            sigma,
            vndf,
            luminance,
            rgb,
            isotropic,
            phi_free: isotropic && nphi == 1 && phi_free,
            jacobian,
            reduction,
            wavelengths: wl_info,
            valid,
            warnings,
            bytes: 0,
            gpu,
            gpu_slots,
            proxy: SamplingProxy {
                alpha_x: 1.0,
                alpha_y: 1.0,
                diffuse: 1.0,
                glossy: 0.0,
            },
        };
        m.proxy = m.compute_proxy();
        Ok(m)
    }

    /// The file's name as given.
    pub fn name(&self) -> &str {
        &self.name
    }

    /// The material's description text.
    pub fn description(&self) -> &str {
        &self.description
    }

    /// Incident elevations of the measurement (radians).
    pub fn theta_i(&self) -> &[f64] {
        &self.theta_i
    }

    /// Incident azimuths of the measurement (radians).
    pub fn phi_i(&self) -> &[f64] {
        &self.phi_i
    }

    /// Whether the data is isotropic in the file's sense (at most two
    /// `phi_i`: half-vector azimuths relative to φi).
    pub fn is_isotropic(&self) -> bool {
        self.isotropic
    }

    /// Whether evaluation is invariant under rotations about the normal:
    /// isotropic data with one `phi_i` whose NDF and σ tables do not vary
    /// with φ (σ is read at the absolute φi, and two `phi_i` slices are
    /// interpolated by it).
    pub fn is_rotation_invariant(&self) -> bool {
        self.phi_free
    }

    /// Whether the stored values carry the Jacobian `4σ/D` (§6).
    pub fn jacobian(&self) -> bool {
        self.jacobian
    }

    /// Fraction of samples the `valid` mask marks measured, if it has one.
    pub fn valid_fraction(&self) -> Option<f64> {
        self.valid
    }

    /// Nodes of the VNDF square and of the value square `(nx, ny)`.
    pub fn grids(&self) -> ((usize, usize), (usize, usize)) {
        (self.vndf.size(), self.rgb.size())
    }

    /// Folds `(wi, wo)` by the symmetry of an anisotropic file whose `phi_i`
    /// covers a half or quarter turn (Mitsuba's `m_reduction`:
    /// `wi` is brought to y ≤ 0, and x ≤ 0 for a quarter turn, by flipping
    /// the signs of x and y together or separately); returns the
    /// signs to unfold a sampled direction.
    fn fold(&self, wi: &mut DVec3, wo: Option<&mut DVec3>) -> (f64, f64) {
        if self.reduction < 2 {
            return (-1.0, -1.0);
        }
        let sy = wi.y;
        let sx = if self.reduction == 4 { wi.x } else { sy };
        wi.x = mulsign_neg(wi.x, sx);
        wi.y = mulsign_neg(wi.y, sy);
        if let Some(wo) = wo {
            wo.x = mulsign_neg(wo.x, sx);
            wo.y = mulsign_neg(wo.y, sy);
        }
        (sx, sy)
    }

    /// The half vector's point `u_m` on the square, and the parameters
    /// `(φi, θi)` and `u_i` of `wi` (already folded).
    fn coords(&self, wi: DVec3, m: DVec3) -> ([f64; 2], [f64; 2], [f64; 2]) {
        let theta_i = elevation(wi);
        let phi_i = wi.y.atan2(wi.x);
        let theta_m = elevation(m);
        let phi_m = m.y.atan2(m.x);
        let u_wi = [theta2u(theta_i), phi2u(phi_i)];
        let mut u_m = [
            theta2u(theta_m),
            phi2u(if self.isotropic { phi_m - phi_i } else { phi_m }),
        ];
        u_m[1] -= u_m[1].floor();
        (u_m, [phi_i, theta_i], u_wi)
    }

    /// What the file stores and Mitsuba's `eval` returns: `f(wi, wo) cos θo`
    /// per linear-RGB channel (0 below either horizon).
    pub fn eval_cos(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if !(wi.z > 0.0 && wo.z > 0.0) {
            return Rgb::ZERO;
        }
        let (mut wi, mut wo) = (wi, wo);
        self.fold(&mut wi, Some(&mut wo));
        let Some(m) = (wi + wo).try_normalize() else {
            return Rgb::ZERO;
        };
        let (u_m, params, u_wi) = self.coords(wi, m);
        let (sample, _) = self.vndf.invert(u_m, &params);
        let mut out = [0.0; 3];
        for (c, o) in out.iter_mut().enumerate() {
            *o = self.rgb.eval(sample, &[params[0], params[1], c as f64]);
        }
        let mut v = Rgb::from_array(out);
        if self.jacobian {
            let s = self.sigma.eval(u_wi, &[]);
            v *= if s > 0.0 {
                self.ndf.eval(u_m, &[]) / (4.0 * s)
            } else {
                0.0
            };
        }
        v
    }

    /// `f(wi, wo)` (1/sr): [`Self::eval_cos`] over `cos θo`; beyond the
    /// last reliable elevation ([`GRAZING_COS`]) the value there, on the same
    /// azimuth: dividing the tables' residue at the horizon by a vanishing
    /// cosine would make an unbounded `f` (and rotations of a grazing pair
    /// into large changes).
    pub fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        if !(wi.z > 0.0 && wo.z > 0.0) {
            return Rgb::ZERO;
        }
        let wo = grazing_held(wo);
        self.eval_cos(wi, wo) / wo.z
    }

    /// Draws `wo` for light from `wi` as Mitsuba's `sample` does: the
    /// luminance warp, then the VNDF warp, then reflection about the drawn
    /// normal. `None` below the horizon.
    pub fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z.is_nan() || wi.z <= 0.0 {
            return None;
        }
        let mut wi = wi;
        let (sx, sy) = self.fold(&mut wi, None);
        let theta_i = elevation(wi);
        let phi_i = wi.y.atan2(wi.x);
        let params = [phi_i, theta_i];
        let (s, _) = self.luminance.sample([u.y, u.x], &params);
        let (u_m, _) = self.vndf.sample(s, &params);
        let mut phi_m = u2phi(u_m[1]);
        let theta_m = u2theta(u_m[0]);
        if self.isotropic {
            phi_m += phi_i;
        }
        let (sp, cp) = phi_m.sin_cos();
        let (st, ct) = theta_m.sin_cos();
        let m = DVec3::new(cp * st, sp * st, ct);
        let mut wo = 2.0 * m.dot(wi) * m - wi;
        wo.x = mulsign_neg(wo.x, sx);
        wo.y = mulsign_neg(wo.y, sy);
        (wo.z > 0.0 && m.dot(wi) > 0.0).then_some(wo)
    }

    /// Solid-angle density of [`Self::sample`] at `wo` (Mitsuba's `pdf`).
    pub fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if !(wi.z > 0.0 && wo.z > 0.0) {
            return 0.0;
        }
        let (mut wi, mut wo) = (wi, wo);
        self.fold(&mut wi, Some(&mut wo));
        let Some(m) = (wi + wo).try_normalize() else {
            return 0.0;
        };
        let (u_m, params, _) = self.coords(wi, m);
        let (sample, vndf_pdf) = self.vndf.invert(u_m, &params);
        let lum_pdf = self.luminance.eval(sample, &params);
        let sin_m = (1.0 - m.z * m.z).max(0.0).sqrt();
        // dω_m = 2π² u_θ sin θm du_θ du_φ, and dωo = 4 (wi·m) dω_m.
        let jac = (2.0 * PI * PI * u_m[0] * sin_m).max(1e-6) * 4.0 * wi.dot(m);
        if jac > 0.0 {
            vndf_pdf * lum_pdf / jac
        } else {
            0.0
        }
    }

    /// What the reader noticed and worked around.
    pub fn warnings(&self) -> &[String] {
        &self.warnings
    }

    /// One-line facts for `bv info` and the panel.
    pub fn summary_lines(&self) -> Vec<String> {
        let deg = |v: &[f64]| {
            let parts: Vec<String> = v.iter().map(|t| format!("{:.1}", t.to_degrees())).collect();
            parts.join(", ")
        };
        let ((vx, vy), (nx, ny)) = self.grids();
        let mut out = Vec::new();
        if !self.description.is_empty() {
            out.push(format!("description: {}", self.description));
        }
        out.push(format!(
            "{} θi ({}°), {} φi{}",
            self.theta_i.len(),
            deg(&self.theta_i),
            self.phi_i.len(),
            if self.isotropic {
                ", isotropic".to_string()
            } else {
                format!(" ({}°), anisotropic", deg(&self.phi_i))
            }
        ));
        out.push(format!(
            "VNDF {vy}×{vx}, values {ny}×{nx} per incident direction; {}; Jacobian {}",
            match self.wavelengths {
                Some((n, lo, hi)) => format!(
                    "spectral ({n} wavelengths, {lo:.0}–{hi:.0} nm) to linear sRGB, illuminant E"
                ),
                None => "RGB".to_string(),
            },
            if self.jacobian { "on" } else { "off" }
        ));
        if let Some(v) = self.valid {
            out.push(format!("valid samples: {:.1} %", 100.0 * v));
        }
        if let Some(v) = &self.version {
            out.push(format!("version {v}"));
        }
        if self.bytes > 0 {
            out.push(format!(
                "file size {}",
                fsio::human_bytes(self.bytes as u64)
            ));
        }
        out
    }
}

/// The largest GPU blob, in floats: the port's offsets within the blob travel
/// as `f32` slots, which hold integers exactly up to 2²⁴ (and the blob's own
/// offset, in units of [`crate::model::TABLE_ALIGN`], up to 4 · 2²⁴). A real
/// anisotropic file is a few million floats; beyond this the port refuses it
/// by name ([`RglMaterial::gpu_blob_error`]).
pub const GPU_MAX_FLOATS: usize = 1 << 24;

/// The tables a GPU port reads, in one `f32` vector, and where each starts
/// (see [`RglMaterial::gpu_slots`]): every φi and θi slice, as the CPU
/// evaluation interpolates them. Empty (with zero slots) when the blob would
/// exceed [`GPU_MAX_FLOATS`].
#[allow(clippy::too_many_arguments)]
fn gpu_blob(
    phi_i: &[f64],
    theta_i: &[f64],
    vndf: &Marginal2D,
    rgb: &Marginal2D,
    ndf: &Marginal2D,
    sigma: &Marginal2D,
    jacobian: bool,
    reduction: i64,
) -> (Vec<f32>, [f32; GPU_SLOTS]) {
    let mut slots = [0.0f32; GPU_SLOTS];
    let (vx, vy) = vndf.size();
    let (n, _) = rgb.size();
    let (nx, ny) = ndf.size();
    let (sx, sy) = sigma.size();
    // Each section is padded to TABLE_ALIGN: at most 3 floats each.
    let need = phi_i.len()
        + theta_i.len()
        + vndf.data().len()
        + vndf.marginal().len()
        + vndf.conditional().len()
        + rgb.data().len()
        + ndf.data().len()
        + sigma.data().len()
        + 7 * (crate::model::TABLE_ALIGN - 1);
    if need > GPU_MAX_FLOATS {
        return (Vec::new(), slots);
    }
    let mut out: Vec<f32> = Vec::with_capacity(need);
    let section = |v: &[f64], out: &mut Vec<f32>| -> f32 {
        out.resize(out.len().next_multiple_of(crate::model::TABLE_ALIGN), 0.0);
        let at = out.len();
        out.extend(v.iter().map(|x| *x as f32));
        at as f32
    };
    slots[0] = theta_i.len() as f32;
    slots[1] = vx as f32;
    slots[2] = vy as f32;
    slots[3] = n as f32;
    slots[4] = nx as f32;
    slots[5] = ny as f32;
    slots[6] = sx as f32;
    slots[7] = sy as f32;
    slots[8] = f32::from(u8::from(jacobian));
    slots[9] = section(theta_i, &mut out);
    slots[10] = section(vndf.data(), &mut out);
    slots[11] = section(vndf.marginal(), &mut out);
    slots[12] = section(vndf.conditional(), &mut out);
    // The plain interpolants store values over (nx−1)(ny−1) (Mitsuba's
    // unnormalised Marginal2D); the port reads them as values.
    let values = |m: &Marginal2D| -> Vec<f64> {
        let (x, y) = m.size();
        let k = ((x - 1) * (y - 1)) as f64;
        m.data().iter().map(|v| v * k).collect()
    };
    slots[13] = section(&values(rgb), &mut out);
    let ndf_at = section(&values(ndf), &mut out);
    let sigma_at = section(&values(sigma), &mut out);
    // Both fit one slot: σ directly follows the NDF's rounded-up end.
    slots[14] = ndf_at;
    debug_assert_eq!(
        sigma_at as usize,
        (ndf_at as usize + nx * ny).next_multiple_of(crate::model::TABLE_ALIGN)
    );
    slots[15] = phi_i.len() as f32;
    slots[16] = section(phi_i, &mut out);
    // Isotropic layout (half-vector azimuth relative to φi) for nφ ≤ 2, as
    // in `from_tensor`.
    slots[17] = f32::from(u8::from(phi_i.len() <= 2));
    slots[18] = reduction as f32;
    (out, slots)
}

/// The GGX proxy lobe the environment renderer importance-samples for an
/// RGL material (see [`RglMaterial::sampling_proxy`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SamplingProxy {
    /// GGX roughness along x: with `alpha_y`, `αx αy = 1/(π D(ẑ))` for the
    /// file's normalised `D`, in the ratio of its half-maximum widths along
    /// x and y.
    pub alpha_x: f64,
    /// GGX roughness along y.
    pub alpha_y: f64,
    /// Diffuse weight: π × the 10th percentile of `f` over
    /// cosine-distributed outgoing directions (a glossy lobe covers few of
    /// those, a diffuse floor all of them), at most the albedo.
    pub diffuse: f64,
    /// Glossy weight: the directional albedo less the diffuse weight.
    pub glossy: f64,
}

impl RglMaterial {
    /// What the GPU port reads besides the blob (`shaders/models/rgl.wgsl`,
    /// in this order): nθ, VNDF nx and ny, value nodes n, NDF nx and ny, σ
    /// nx and ny, the Jacobian flag, the offsets in the blob of θi, the
    /// VNDF's values, marginal and conditional CDFs, the RGB values and the
    /// NDF (σ follows it at the next multiple of 4), then nφ, the offset of
    /// φi, the isotropic-layout flag (nφ ≤ 2) and the fold (Mitsuba's
    /// `m_reduction`: 2 a half turn, 4 a quarter turn, below 2 none). All
    /// zero for a file whose tables exceed [`GPU_MAX_FLOATS`].
    pub fn gpu_slots(&self) -> [f32; GPU_SLOTS] {
        self.gpu_slots
    }

    /// Floats in the GPU blob (0 when the tables are too large for the
    /// port: see [`Self::gpu_blob_error`]).
    pub fn gpu_data_len(&self) -> usize {
        self.gpu.len()
    }

    /// Why the GPU port cannot draw this file, if it cannot: its tables
    /// exceed [`GPU_MAX_FLOATS`] floats.
    pub fn gpu_blob_error(&self) -> Option<String> {
        if !self.gpu.is_empty() {
            return None;
        }
        let floats = self.vndf.data().len()
            + self.vndf.conditional().len()
            + self.rgb.data().len()
            + self.ndf.data().len()
            + self.sigma.data().len();
        Some(format!(
            "its tables ({} φi × {} θi) need {:.1} MB as f32, over the GPU port's limit of \
             {:.1} MB (offsets are f32 slots, exact to 2^24 floats)",
            self.phi_i.len(),
            self.theta_i.len(),
            (floats * 4) as f64 / 1e6,
            (GPU_MAX_FLOATS * 4) as f64 / 1e6
        ))
    }

    /// The GGX proxy lobe of the environment renderer's importance sampling
    /// (computed once, at load). Its roughness matches the file's own
    /// microfacet distribution at the normal: with `D` normalised so that
    /// `∫ D(m) cos θm dωm = 1` (the projected-area normalisation of Dupuy &
    /// Jakob 2018, eq. 4, σ(ẑ) = 1; integrated here by the midpoint rule on
    /// the square, whatever scale the file stores `D` at), GGX has
    /// `D(ẑ) = 1/(π αx αy)` (Walter et al. 2007, eq. 33; Heitz 2014, eq. 85
    /// for αx ≠ αy). The peak height is used rather than a second slope
    /// moment because GGX's slope variance is infinite (its tail falls as
    /// tan⁻⁴θ), and the peak is what a sharp highlight's samples must find.
    /// An anisotropic file (more than two φi, whose NDF is over the absolute
    /// azimuth) splits the product in the ratio of the NDF's half-maximum
    /// angles along x (φ = 0, π) and y (φ = ±π/2), each turned into a GGX α
    /// by `D(θ½)/D(0) = ½ ⇔ α² = tan²θ½ / (√2/cos²θ½ − 1)`. The pdf of the
    /// lobe is what the shader draws, so a poor match costs noise, never
    /// bias.
    pub fn sampling_proxy(&self) -> SamplingProxy {
        self.proxy
    }

    fn compute_proxy(&self) -> SamplingProxy {
        // ∫ D cos θm dω over the square: dω = 2π² u sin θ du dv.
        let (nu, nv) = (256usize, 128usize);
        let mut norm = 0.0;
        for i in 0..nu {
            let u = (i as f64 + 0.5) / nu as f64;
            let th = u2theta(u);
            let w = 2.0 * PI * PI * u * th.sin() * th.cos();
            for j in 0..nv {
                let v = (j as f64 + 0.5) / nv as f64;
                norm += w * self.ndf.eval([u, v], &[]);
            }
        }
        norm /= (nu * nv) as f64;
        let d0 = (0..nv)
            .map(|j| self.ndf.eval([0.0, (j as f64 + 0.5) / nv as f64], &[]))
            .sum::<f64>()
            / nv as f64;
        // αx αy from the peak; the ratio from the half-maximum widths.
        let product = if norm > 0.0 && d0 > 0.0 {
            norm / (PI * d0)
        } else {
            1.0
        };
        let ratio = if self.isotropic {
            1.0
        } else {
            let ax = 0.5 * (self.ndf_half_max_alpha(0.0) + self.ndf_half_max_alpha(PI));
            let ay =
                0.5 * (self.ndf_half_max_alpha(FRAC_PI_2) + self.ndf_half_max_alpha(-FRAC_PI_2));
            if ax > 0.0 && ay > 0.0 { ax / ay } else { 1.0 }
        };
        let alpha_x = (product * ratio).sqrt().clamp(1e-3, 1.0);
        let alpha_y = (product / ratio).sqrt().clamp(1e-3, 1.0);
        // Diffuse and glossy weights from light at 30° over four azimuths:
        // the albedo by the file's own sampler (stratified), the diffuse part
        // as π × the 10th percentile of f (mean luminance) over
        // cosine-distributed outgoing directions: the floor that a Lambertian
        // part puts under every direction (the median would count much of
        // a GGX α 0.3 lobe as diffuse).
        let lum = |c: Rgb| (c.x + c.y + c.z) / 3.0;
        let k = 16usize;
        let (mut albedo, mut diffuse) = (0.0, 0.0);
        for q in 0..4 {
            let phi = 0.25 + q as f64 * FRAC_PI_2;
            let th = 30f64.to_radians();
            let wi = DVec3::new(th.sin() * phi.cos(), th.sin() * phi.sin(), th.cos());
            let (mut a, mut fs) = (0.0, Vec::with_capacity(k * k));
            for i in 0..k {
                for j in 0..k {
                    let u = DVec2::new((i as f64 + 0.5) / k as f64, (j as f64 + 0.5) / k as f64);
                    if let Some(wo) = self.sample(wi, u) {
                        let p = self.pdf(wi, wo);
                        if p > 0.0 {
                            a += lum(self.eval_cos(wi, wo)) / p;
                        }
                    }
                    let r = u.x.sqrt();
                    let ph = 2.0 * PI * u.y;
                    let wo = DVec3::new(r * ph.cos(), r * ph.sin(), (1.0 - u.x).max(0.0).sqrt());
                    fs.push(lum(self.eval(wi, wo)));
                }
            }
            fs.sort_by(f64::total_cmp);
            albedo += a / (k * k) as f64 / 4.0;
            diffuse += PI * fs[fs.len() / 10] / 4.0;
        }
        let albedo = if albedo.is_finite() {
            albedo.max(0.0)
        } else {
            0.0
        };
        let diffuse = if diffuse.is_finite() {
            diffuse.clamp(0.0, albedo)
        } else {
            0.0
        };
        SamplingProxy {
            alpha_x,
            alpha_y,
            diffuse,
            glossy: albedo - diffuse,
        }
    }

    /// The GGX α whose `D` falls to half its peak at the same angle as the
    /// file's NDF along azimuth `phi` (0 when it never does).
    fn ndf_half_max_alpha(&self, phi: f64) -> f64 {
        let v = phi2u(phi).clamp(0.0, 1.0);
        let d0 = self.ndf.eval([0.0, v], &[]);
        let steps = 2048;
        let (mut t0, mut v0) = (0.0, d0);
        for k in 1..=steps {
            let u = k as f64 / steps as f64;
            let (t1, v1) = (u2theta(u), self.ndf.eval([u, v], &[]));
            if v1 <= 0.5 * d0 {
                let th = if v0 > v1 {
                    t0 + (t1 - t0) * (v0 - 0.5 * d0) / (v0 - v1)
                } else {
                    t1
                };
                let (c2, t2) = (th.cos().powi(2), th.tan().powi(2));
                let den = std::f64::consts::SQRT_2 / c2 - 1.0;
                return if den > 0.0 { (t2 / den).sqrt() } else { 0.0 };
            }
            (t0, v0) = (t1, v1);
        }
        0.0
    }
}

impl crate::model::GpuBlob for RglMaterial {
    fn gpu_data(&self) -> &[f32] {
        &self.gpu
    }
}

impl crate::model::FileData for RglMaterial {
    fn summary(&self) -> Vec<String> {
        self.summary_lines()
    }

    fn warnings(&self) -> Vec<String> {
        self.warnings.clone()
    }
}

// ---------------------------------------------------------------------------
// Process-wide cache (as the MERL reader's: rebuilding an `rgl` model on every
// parameter change or `bv eval` line must not reread the file).

const CACHE_ENTRIES: usize = 4;

type Key = (PathBuf, Option<std::time::SystemTime>, u64);

static CACHE: Mutex<Vec<(Key, u64, Arc<RglMaterial>)>> = Mutex::new(Vec::new());
static CLOCK: std::sync::atomic::AtomicU64 = std::sync::atomic::AtomicU64::new(0);

fn cache_key(path: &Path) -> Result<Key> {
    if let Some(p) = fsio::provided(path) {
        return Ok((path.to_path_buf(), Some(p.stamp()), p.bytes.len() as u64));
    }
    let name = path.display().to_string();
    let canon = std::fs::canonicalize(path).map_err(|e| file_err(&name, e.to_string()))?;
    let meta = std::fs::metadata(&canon).map_err(|e| file_err(&name, e.to_string()))?;
    Ok((canon, meta.modified().ok(), meta.len()))
}

fn cache_get(key: &Key) -> Option<Arc<RglMaterial>> {
    let mut g = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    let now = CLOCK.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let e = g.iter_mut().find(|(k, _, _)| k == key && key.1.is_some())?;
    e.1 = now;
    Some(e.2.clone())
}

/// Whether [`read_cached`] of `path` would return at once.
pub fn is_cached(path: impl AsRef<Path>) -> bool {
    cache_key(path.as_ref()).is_ok_and(|k| cache_get(&k).is_some())
}

/// Reads `path` through a process-wide cache of 4 materials keyed by the
/// canonical path, modification time and size (a changed file is read
/// again), reporting `progress(bytes, total)`.
pub fn read_cached(
    path: impl AsRef<Path>,
    progress: &mut dyn FnMut(u64, u64),
) -> Result<Arc<RglMaterial>> {
    let path = path.as_ref();
    let key = cache_key(path)?;
    if let Some(m) = cache_get(&key) {
        progress(key.2, key.2);
        return Ok(m);
    }
    progress(0, key.2);
    let mut m = RglMaterial::read(path)?;
    m.bytes = key.2 as usize;
    let m = Arc::new(m);
    progress(key.2, key.2);
    let now = CLOCK.fetch_add(1, std::sync::atomic::Ordering::Relaxed);
    let mut g = CACHE.lock().unwrap_or_else(|e| e.into_inner());
    g.retain(|(k, _, _)| k.0 != key.0);
    if g.len() >= CACHE_ENTRIES
        && let Some(i) = g
            .iter()
            .enumerate()
            .min_by_key(|(_, e)| e.1)
            .map(|(i, _)| i)
    {
        g.swap_remove(i);
    }
    g.push((key, now, m.clone()));
    Ok(m)
}

/// `wo` moved up to the elevation of [`GRAZING_COS`] on its azimuth when
/// it lies below it (the normal's direction when it has no azimuth).
pub fn grazing_held(wo: DVec3) -> DVec3 {
    if wo.z >= GRAZING_COS {
        return wo;
    }
    let sin_c = (1.0 - GRAZING_COS * GRAZING_COS).sqrt();
    let l = wo.x.hypot(wo.y);
    if l > 0.0 {
        DVec3::new(wo.x / l * sin_c, wo.y / l * sin_c, GRAZING_COS)
    } else {
        DVec3::Z
    }
}
