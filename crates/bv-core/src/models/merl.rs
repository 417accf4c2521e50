//! `merl`: a measured BRDF from a MERL `.binary` table (Matusik et al.
//! 2003, "A Data-Driven Reflectance Model").

use crate::measured::merl::{self as table, Interpolation, MerlTable};
use crate::model::{
    Build, FileData, FileFormat, GpuPort, GpuTables, ModelInfo, Progress, TABLE_ALIGN,
};
use crate::params::decl::{Applies, ParamDecl, ParamKind};
use crate::params::value::{ModelSpec, Params};
use crate::{Brdf, BvError, Claims, Result, Rgb, sampling};
use glam::{DVec2, DVec3};
use std::f64::consts::{FRAC_PI_2, PI};
use std::path::Path;
use std::sync::Arc;

/// Parameter declaration.
pub const PARAMS: &[ParamDecl] = &[
    ParamDecl {
        id: "path",
        label: "file",
        doc: "MERL .binary file (half/difference-angle table, 90×90×180 in the public set)",
        kind: ParamKind::Path {
            default: "",
            format: &MERL_FILES,
        },
        applies: Applies::Always,
    },
    ParamDecl {
        id: "interpolation",
        label: "interpolation",
        doc: "Lookup between samples: trilinear in (θh index, θd, φd), or the nearest sample as the MERL reference code",
        kind: ParamKind::Choice {
            options: Interpolation::NAMES,
            default: "trilinear",
        },
        applies: Applies::Always,
    },
];

/// Catalogue entry.
pub static INFO: ModelInfo = ModelInfo {
    id: "merl",
    name: "MERL measured",
    summary: "Measured isotropic BRDF, tabulated in half/difference angles",
    citation: "Matusik, Pfister, Brand, McMillan 2003, A Data-Driven Reflectance Model; Rusinkiewicz 1998",
    params: PARAMS,
    aliases: &[],
    build: Build::Static(build),
    gpu: Some(
        GpuPort::new(
            "bv::models::merl",
            "shaders/models/merl.wgsl",
            include_str!("../../../../shaders/models/merl.wgsl"),
        )
        .with_derived(DERIVED_SLOTS, derive_slots)
        .with_sampling_lobe(),
    ),
};

/// MERL `.binary` tables as a file format of bv-core's table reader and
/// cache (`crate::measured::merl`).
#[derive(Debug)]
pub struct MerlFiles;

/// The format of `merl`'s `path` parameter.
pub static MERL_FILES: MerlFiles = MerlFiles;

impl FileFormat for MerlFiles {
    fn name(&self) -> &'static str {
        "MERL table"
    }

    fn tag(&self) -> &'static str {
        "MERL"
    }

    fn extensions(&self) -> &'static [&'static str] {
        &["binary"]
    }

    fn load(&self, path: &Path, progress: &mut Progress<'_>) -> Result<Arc<dyn FileData>> {
        let t = table::read_cached_with_progress(path, &mut |a, b| progress(a, b))?;
        Ok(t)
    }

    fn is_cached(&self, path: &Path) -> bool {
        table::is_cached(path)
    }
}

/// Derived GPU slots of `merl` (read by `shaders/models/merl.wgsl`): the
/// table's dimensions and its offset in the frame's table buffer, in units
/// of [`TABLE_ALIGN`] floats, then the environment renderer's sampling
/// proxy (GGX α, diffuse and glossy weights: [`MerlTable::sampling_proxy`]).
const DERIVED_SLOTS: &[&str] = &[
    "theta_h_count",
    "theta_d_count",
    "phi_d_count",
    "table",
    "lobe_alpha",
    "lobe_diffuse",
    "lobe_glossy",
];

fn derive_slots(spec: &ModelSpec, tables: &mut dyn GpuTables) -> Result<Vec<f32>> {
    // Through the cache: the same table (and so the same upload) as the
    // built model's.
    let t = table::read_cached(spec.params().text("path")?)?;
    let d = t.dims();
    let proxy = t.sampling_proxy();
    let offset = tables.offset_of(t) / TABLE_ALIGN;
    Ok(vec![
        d.theta_h as f32,
        d.theta_d as f32,
        d.phi_d as f32,
        offset as f32,
        proxy.alpha as f32,
        proxy.diffuse as f32,
        proxy.glossy as f32,
    ])
}

/// A measured BRDF: a shared table and how to look it up.
#[derive(Debug, Clone)]
pub struct Merl {
    table: Arc<MerlTable>,
    interpolation: Interpolation,
    /// Cumulative probabilities of the θh cells for half-vector sampling
    /// (`cdf[0] = 0`, `cdf[n] = 1`); empty when the table is all zero.
    cdf: Arc<Vec<f64>>,
}

/// Bounds `(θa, θb)` of θh cell `i` of `n` (the table's `√` mapping).
fn theta_h_cell(i: usize, n: usize) -> (f64, f64) {
    let a = i as f64 / n as f64;
    let b = (i + 1) as f64 / n as f64;
    (FRAC_PI_2 * a * a, FRAC_PI_2 * b * b)
}

/// The θh sampling distribution of a table: cell `i` gets probability
/// `∝ v̄_i ∫ cos θh dω` over the cell, where `v̄_i` is the cell row's mean
/// value over θd, φd and channels: the measured analogue of sampling
/// `D(h) cos θh` (Walter et al. 2007, eq. 35, with a tabulated `D`).
fn theta_h_cdf(table: &MerlTable) -> Vec<f64> {
    let d = table.dims();
    let cells = d.cells();
    let data = table.data();
    let n = d.theta_h;
    let mut w = Vec::with_capacity(n);
    for ih in 0..n {
        let mut sum = 0.0;
        for id in 0..d.theta_d {
            for ip in 0..d.phi_d {
                let k = d.cell(ih, id, ip);
                for c in 0..3 {
                    let v = f64::from(data.get(k + c * cells).copied().unwrap_or(0.0));
                    if v.is_finite() && v > 0.0 {
                        sum += v;
                    }
                }
            }
        }
        let (ta, tb) = theta_h_cell(ih, n);
        // ∫ cos θ sin θ dθ over the cell, times 2π (constant, dropped).
        let area_cos = 0.5 * (ta.cos().powi(2) - tb.cos().powi(2));
        w.push(sum * area_cos);
    }
    let total: f64 = w.iter().sum();
    if !(total > 0.0 && total.is_finite()) {
        return Vec::new();
    }
    let mut cdf = Vec::with_capacity(n + 1);
    let mut acc = 0.0;
    cdf.push(0.0);
    for x in &w {
        acc += x / total;
        cdf.push(acc);
    }
    if let Some(last) = cdf.last_mut() {
        *last = 1.0;
    }
    cdf
}

impl Merl {
    /// A model over an already loaded table (what `bv info` uses).
    pub fn from_table(table: Arc<MerlTable>, interpolation: Interpolation) -> Self {
        let cdf = Arc::new(theta_h_cdf(&table));
        Self {
            table,
            interpolation,
            cdf,
        }
    }

    /// Solid-angle density of the half-vector sampler at `h` (upper hemisphere).
    fn h_density(&self, h: DVec3) -> f64 {
        let n = self.cdf.len().saturating_sub(1);
        if n == 0 || h.z <= 0.0 {
            return 0.0;
        }
        let theta = h.z.clamp(-1.0, 1.0).acos();
        let i = table::theta_h_index(theta, n);
        let (ta, tb) = theta_h_cell(i, n);
        let p = self.cdf[i + 1] - self.cdf[i];
        let omega = 2.0 * PI * (ta.cos() - tb.cos());
        if omega > 0.0 { p / omega } else { 0.0 }
    }

    /// The table.
    pub fn table(&self) -> &Arc<MerlTable> {
        &self.table
    }

    /// The lookup mode.
    pub fn interpolation(&self) -> Interpolation {
        self.interpolation
    }
}

fn build(p: &Params) -> Result<Box<dyn Brdf>> {
    let path = p.text("path")?;
    if path.trim().is_empty() {
        return Err(BvError::BadValue {
            param: "path".into(),
            reason: "no file given: set it to a MERL .binary file".into(),
        });
    }
    let interpolation = Interpolation::from_name(p.text("interpolation")?)?;
    let table = table::read_cached(path)?;
    Ok(Box::new(Merl::from_table(table, interpolation)))
}

impl Brdf for Merl {
    fn id(&self) -> &'static str {
        INFO.id
    }

    fn eval(&self, wi: DVec3, wo: DVec3) -> Rgb {
        self.table.lookup(wi, wo, self.interpolation)
    }

    fn claims(&self) -> Claims {
        Claims {
            // The φd fold makes every lookup reciprocal by construction.
            reciprocal: true,
            // Measured data makes no promise (and real files exceed ρhd = 1 at
            // grazing angles); the analysis reports what it finds.
            energy_conserving: false,
            // The table has no φh axis.
            isotropic: true,
        }
    }

    /// A measured table promises nothing: its claims above are what the
    /// lookup does by construction, used to steer the analysis.
    fn claims_declared(&self) -> bool {
        false
    }

    fn file_data(&self) -> Option<Arc<dyn FileData>> {
        Some(self.table.clone())
    }

    /// Half of the samples cosine-weighted, half through a half vector drawn
    /// from the table's θh profile (cell by [`theta_h_cdf`], then uniform in
    /// solid angle within the cell, φh uniform) and reflected: measured
    /// materials are mostly glossy about the mirror direction, where cosine
    /// sampling alone gives the albedo estimate a heavy tail.
    fn sample(&self, wi: DVec3, u: DVec2) -> Option<DVec3> {
        if wi.z <= 0.0 {
            return None;
        }
        let n = self.cdf.len().saturating_sub(1);
        if u.x < 0.5 || n == 0 {
            let ux = if n == 0 { u.x } else { 2.0 * u.x };
            return Some(sampling::cosine_hemisphere(DVec2::new(
                ux.min(ONE_BELOW),
                u.y,
            )));
        }
        let v = (2.0 * u.x - 1.0).clamp(0.0, ONE_BELOW);
        // The cell whose cumulative interval holds v, and v's place in it.
        let i = self
            .cdf
            .partition_point(|&c| c <= v)
            .saturating_sub(1)
            .min(n - 1);
        let width = self.cdf[i + 1] - self.cdf[i];
        let t = if width > 0.0 {
            ((v - self.cdf[i]) / width).clamp(0.0, 1.0)
        } else {
            0.5
        };
        let (ta, tb) = theta_h_cell(i, n);
        let (ca, cb) = (ta.cos(), tb.cos());
        let cos_h = ca - t * (ca - cb);
        let sin_h = (1.0 - cos_h * cos_h).max(0.0).sqrt();
        let phi = 2.0 * PI * u.y;
        let h = DVec3::new(sin_h * phi.cos(), sin_h * phi.sin(), cos_h);
        let c = wi.dot(h);
        let wo = 2.0 * c * h - wi;
        // Below the horizon the table is zero: such a draw is not returned
        // (and `pdf` is 0 there to match).
        if c <= 0.0 || wo.z <= 0.0 {
            return None;
        }
        Some(wo)
    }

    fn pdf(&self, wi: DVec3, wo: DVec3) -> f64 {
        if wi.z <= 0.0 || wo.z <= 0.0 {
            return 0.0;
        }
        let cosine = sampling::cosine_hemisphere_pdf(wo);
        if self.cdf.len() < 2 {
            return cosine;
        }
        let Some(h) = (wi + wo).try_normalize() else {
            return 0.5 * cosine;
        };
        let c = wo.dot(h);
        let reflected = if c > 0.0 {
            self.h_density(h) / (4.0 * c)
        } else {
            0.0
        };
        0.5 * cosine + 0.5 * reflected
    }
}

/// The largest f64 below 1 (keeps a rescaled uniform in `[0, 1)`).
const ONE_BELOW: f64 = 1.0 - f64::EPSILON / 2.0;
