//! The fixed set of (wi, wo) pairs a fit compares model and target on.
//!
//! Stratified in Rusinkiewicz's (1998) half/difference angles, as Ngan et
//! al. (2005) fit on MERL's (θh, θd, φd) table: cell midpoints in
//! `u ∈ (0, 1)` with θh = u² · 90° (MERL's mapping, dense near the specular
//! peak, where lobes are narrow), θd uniform in [0°, 90°), φd uniform in
//! [0°, 180°) (the other half is the same pairs with wi and wo swapped, which
//! a reciprocal BRDF maps to the same values), and φh from a golden-ratio
//! sequence over the cells (so that an anisotropic lobe is seen at every
//! azimuth, while an isotropic one does not care). The set is deterministic:
//! no random numbers, the same pairs on every run and machine.
//!
//! Each pair carries its share of the measure dωi dωo = 4 cos θd dωh dωd
//! (wo is wi reflected about h, and |∂ωo/∂ωh| = 4 (wi·h): Walter et al.
//! 2007, eq. 14; dωd = dωi at fixed h, a rotation), so that a sum over the
//! set approximates an integral over pairs of directions. Pairs with θi or
//! θo beyond [`SampleOptions::max_theta_deg`] (80° by default: Ngan et al. 2005 ignore data beyond 80°, as the later
//! "Addressing grazing angle reflections in Phong models" recalls:
//! grazing data is the least reliable part of a measurement) are dropped.

use crate::batch::PairBuf;
use glam::DVec3;
use std::f64::consts::{FRAC_PI_2, PI};

/// How many cells along each half/difference axis, and the grazing cut.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SampleOptions {
    /// Cells along θh (u² mapping).
    pub theta_h: usize,
    /// Cells along θd.
    pub theta_d: usize,
    /// Cells along φd in [0°, 180°).
    pub phi_d: usize,
    /// Pairs with θi or θo above this many degrees are left out.
    pub max_theta_deg: f64,
}

impl Default for SampleOptions {
    /// 48 × 24 × 24 cells (27 648 before the horizon and grazing cuts, about
    /// 16 000 after): enough that a fitted α moves by far less than 1 % when
    /// the grid is doubled (the fit tests recover parameters to 1 % on it).
    fn default() -> Self {
        Self {
            theta_h: 48,
            theta_d: 24,
            phi_d: 24,
            max_theta_deg: 80.0,
        }
    }
}

/// The pairs, their weights and incident angles.
#[derive(Debug, Clone)]
pub struct SampleSet {
    /// The pairs, as the batch kernels take them.
    pub pairs: PairBuf,
    /// Each pair's share of dωi dωo (sr²).
    pub weight: Vec<f64>,
    /// cos θi of each pair (of the f32-rounded direction the kernels see).
    pub cos_i: Vec<f64>,
}

impl SampleSet {
    /// The set `opts` describes (axes of 0 cells count as 1).
    pub fn new(opts: &SampleOptions) -> Self {
        let (nh, nd, np) = (opts.theta_h.max(1), opts.theta_d.max(1), opts.phi_d.max(1));
        let min_cos = opts
            .max_theta_deg
            .clamp(0.0, 90.0)
            .to_radians()
            .cos()
            .max(1e-6);
        // Golden-ratio increments for φh (Weyl sequence): evenly spread, no seed.
        let golden = (5f64.sqrt() - 1.0) / 2.0;
        let (du, dtd, dpd) = (1.0 / nh as f64, FRAC_PI_2 / nd as f64, PI / np as f64);
        let mut set = SampleSet {
            pairs: PairBuf::default(),
            weight: Vec::new(),
            cos_i: Vec::new(),
        };
        let mut k = 0u64;
        for ih in 0..nh {
            let u = (ih as f64 + 0.5) * du;
            let th = u * u * FRAC_PI_2;
            // dθh/du of the u² mapping.
            let dth = PI * u * du;
            for id in 0..nd {
                let td = (id as f64 + 0.5) * dtd;
                for ip in 0..np {
                    let pd = (ip as f64 + 0.5) * dpd;
                    k += 1;
                    let ph = (k as f64 * golden).fract() * 2.0 * PI;
                    let (wi, wo) = from_half_diff(th, ph, td, pd);
                    let (wi, wo) = (round_f32(wi), round_f32(wo));
                    if wi.z < min_cos || wo.z < min_cos {
                        continue;
                    }
                    // 4 cos θd dωh dωd, dωh = sin θh dθh dφh (φh: one sample
                    // standing for 2π), dωd = sin θd dθd dφd (φd over [0, π)
                    // stands for both halves: ×2).
                    let w = 4.0 * td.cos() * th.sin() * dth * 2.0 * PI * td.sin() * dtd * dpd * 2.0;
                    set.pairs.push(wi, wo);
                    set.weight.push(w);
                    set.cos_i.push(wi.z);
                }
            }
        }
        set
    }

    /// Number of pairs.
    pub fn len(&self) -> usize {
        self.weight.len()
    }

    /// Whether no pair survived the cuts.
    pub fn is_empty(&self) -> bool {
        self.weight.is_empty()
    }

    /// The subset `keep` selects (same order).
    pub(crate) fn retain(&self, keep: &[bool]) -> Self {
        let mut out = SampleSet {
            pairs: PairBuf::default(),
            weight: Vec::new(),
            cos_i: Vec::new(),
        };
        for (i, _) in keep.iter().enumerate().filter(|(_, k)| **k) {
            let (wi, wo) = self.pairs.pair(i);
            out.pairs.push(wi, wo);
            out.weight.push(self.weight[i]);
            out.cos_i.push(self.cos_i[i]);
        }
        out
    }
}

/// (wi, wo) from half/difference angles (Rusinkiewicz 1998): the
/// difference vector rotated from the half vector's frame to the surface's.
pub fn from_half_diff(theta_h: f64, phi_h: f64, theta_d: f64, phi_d: f64) -> (DVec3, DVec3) {
    let d = DVec3::new(
        theta_d.sin() * phi_d.cos(),
        theta_d.sin() * phi_d.sin(),
        theta_d.cos(),
    );
    // R_z(φh) R_y(θh) d.
    let (st, ct) = theta_h.sin_cos();
    let y = DVec3::new(ct * d.x + st * d.z, d.y, -st * d.x + ct * d.z);
    let (sp, cp) = phi_h.sin_cos();
    let wi = DVec3::new(cp * y.x - sp * y.y, sp * y.x + cp * y.y, y.z);
    let h = DVec3::new(st * cp, st * sp, ct);
    let wo = 2.0 * wi.dot(h) * h - wi;
    (wi.normalize(), wo.normalize())
}

/// The direction as the batch kernels see it (f32), so that cos θi and the
/// horizon test agree with what is evaluated.
fn round_f32(v: DVec3) -> DVec3 {
    DVec3::new(v.x as f32 as f64, v.y as f32 as f64, v.z as f32 as f64)
}
