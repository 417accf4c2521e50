//! Image slices in half/difference angles (Rusinkiewicz 1998): `f` over θh
//! (columns, 0–90°, optionally on a √θh axis) and θd (rows, 90° at the top)
//! at a chosen φd, φh = 0, evaluated through the model's f32 batch kernel,
//! and cached process-wide by (build revision, φd, axis, resolution): the
//! image slice view, figures and scripts share one evaluation.

use super::jobs::{self, Slots};
use crate::session::platform::Instant;
use bv_core::{Brdf, Rgb, batch, frame};
use rayon::prelude::*;
use std::f64::consts::FRAC_PI_2;
use std::sync::Arc;

/// The values of one slice: `f` per pixel, row 0 at θd = 90° (the top).
#[derive(Debug, Clone, PartialEq)]
pub struct SliceData {
    /// Columns (θh).
    pub width: usize,
    /// Rows (θd).
    pub height: usize,
    /// `f` per pixel (row-major); `None` below the horizon.
    pub values: Vec<Option<[f32; 3]>>,
    /// Seconds the evaluation took.
    pub seconds: f64,
}

impl SliceData {
    /// Largest luminance over the slice (0 if none).
    pub fn max_luminance(&self) -> f64 {
        self.values
            .iter()
            .flatten()
            .map(|v| luminance(*v))
            .fold(0.0, f64::max)
    }

    /// The luminance below which a fraction `q` of the valid pixels lie.
    pub fn luminance_quantile(&self, q: f64) -> f64 {
        let mut v: Vec<f64> = self
            .values
            .iter()
            .flatten()
            .map(|v| luminance(*v))
            .collect();
        if v.is_empty() {
            return 0.0;
        }
        v.sort_by(f64::total_cmp);
        let i = ((q.clamp(0.0, 1.0) * (v.len() - 1) as f64).round() as usize).min(v.len() - 1);
        v[i]
    }
}

/// Rec. 709 luminance of a linear RGB value.
pub fn luminance(c: [f32; 3]) -> f64 {
    0.2126 * f64::from(c[0]) + 0.7152 * f64::from(c[1]) + 0.0722 * f64::from(c[2])
}

/// θh (radians) at horizontal position `u ∈ [0, 1]`.
pub fn theta_h_at(u: f64, sqrt_axis: bool) -> f64 {
    let u = u.clamp(0.0, 1.0);
    if sqrt_axis {
        u * u * FRAC_PI_2
    } else {
        u * FRAC_PI_2
    }
}

/// Horizontal position of θh (inverse of [`theta_h_at`]).
pub fn u_of_theta_h(theta_h: f64, sqrt_axis: bool) -> f64 {
    let t = (theta_h / FRAC_PI_2).clamp(0.0, 1.0);
    if sqrt_axis { t.sqrt() } else { t }
}

/// θd (radians) at vertical position `v ∈ [0, 1]` from the top.
pub fn theta_d_at(v: f64) -> f64 {
    (1.0 - v.clamp(0.0, 1.0)) * FRAC_PI_2
}

/// `f` at half/difference angles (φh = 0), or `None` when a direction is
/// below the horizon.
pub fn value_at(brdf: &dyn Brdf, theta_h: f64, theta_d: f64, phi_d: f64) -> Option<Rgb> {
    let (wi, wo) = frame::from_half_diff(frame::HalfDiff {
        theta_h,
        phi_h: 0.0,
        theta_d,
        phi_d,
    });
    if wi.z <= 0.0 || wo.z <= 0.0 {
        return None;
    }
    let f = brdf.eval(wi, wo);
    Some(if f.is_finite() { f } else { Rgb::ZERO })
}

/// Evaluates a `n × n` slice at pixel centres, a row per batch through the
/// model's f32 SIMD kernel where it has one (`bv_core::batch::eval`; the
/// display needs f32 only), rows in parallel.
pub fn compute(brdf: &dyn Brdf, phi_d: f64, sqrt_axis: bool, n: usize) -> SliceData {
    let t0 = Instant::now();
    let n = n.max(2);
    let mut values = vec![None; n * n];
    values.par_chunks_mut(n).enumerate().for_each(|(row, out)| {
        let theta_d = theta_d_at((row as f64 + 0.5) / n as f64);
        let mut pairs = batch::PairBuf::default();
        let mut above = Vec::with_capacity(n);
        for col in 0..n {
            let theta_h = theta_h_at((col as f64 + 0.5) / n as f64, sqrt_axis);
            let (wi, wo) = frame::from_half_diff(frame::HalfDiff {
                theta_h,
                phi_h: 0.0,
                theta_d,
                phi_d,
            });
            let ok = wi.z > 0.0 && wo.z > 0.0;
            above.push(ok);
            // Pixels below the horizon are evaluated too (the kernel gives 0
            // there) so that the lanes stay in step with the columns.
            pairs.push(wi, wo);
        }
        let mut rgb = [vec![0f32; n], vec![0f32; n], vec![0f32; n]];
        {
            let [r, g, b] = &mut rgb;
            batch::eval(
                brdf,
                &pairs.dirs(0..n),
                &mut batch::Out {
                    rgb: [&mut r[..], &mut g[..], &mut b[..]],
                },
            );
        }
        for (col, o) in out.iter_mut().enumerate() {
            let f = [rgb[0][col], rgb[1][col], rgb[2][col]];
            *o = above[col].then(|| {
                if f.iter().all(|v| v.is_finite()) {
                    f
                } else {
                    [0.0; 3]
                }
            });
        }
    });
    SliceData {
        width: n,
        height: n,
        values,
        seconds: t0.elapsed().as_secs_f64(),
    }
}

/// What a slice depends on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SliceKey {
    /// The BRDF's build revision.
    pub revision: u64,
    /// φd in degrees.
    pub phi_d_deg: f64,
    /// Columns on a √θh axis.
    pub sqrt: bool,
    /// Pixels per side.
    pub resolution: usize,
}

/// The slices of the process (slot: BRDF id).
pub fn slots() -> Arc<Slots<SliceKey, Arc<SliceData>>> {
    jobs::slots("half/difference slice")
}

/// The slice of `brdf` (BRDF `id`) for `key`, evaluated now unless cached:
/// a slice takes milliseconds, so a frame evaluates at most one per BRDF
/// and only when its key changed.
pub fn slice_now(id: u64, key: SliceKey, brdf: &Arc<dyn Brdf>) -> Arc<SliceData> {
    let brdf = brdf.clone();
    let done = slots().now(
        id,
        key,
        jobs::once(move || {
            Arc::new(compute(
                brdf.as_ref(),
                key.phi_d_deg.to_radians(),
                key.sqrt,
                key.resolution,
            ))
        }),
    );
    done.value.clone()
}

/// The relative error `(f − f_ref) / f_ref` of slice `fit` against slice
/// `reference` (the same grid), per pixel, of the Rec. 709 luminances: the
/// residual of a fit over θh × θd (Ngan et al. 2005 show fits this way,
/// their Fig. 4). `None` below the horizon (in either slice); where the
/// reference is 0, 0 if `fit` is too and +∞ otherwise. Slices of different
/// sizes give no values at all.
pub fn relative_error(fit: &SliceData, reference: &SliceData) -> Vec<Option<f64>> {
    if fit.width != reference.width || fit.height != reference.height {
        return Vec::new();
    }
    fit.values
        .iter()
        .zip(&reference.values)
        .map(|(f, r)| {
            let (f, r) = (luminance((*f)?), luminance((*r)?));
            Some(if r > 0.0 {
                (f - r) / r
            } else if f > 0.0 {
                f64::INFINITY
            } else {
                0.0
            })
        })
        .collect()
}

#[cfg(test)]
mod tests {
    use super::*;
    use std::f64::consts::PI;

    fn lambert(albedo: f64) -> Box<dyn Brdf> {
        bv_core::ModelSpec::from_json("lambert", &serde_json::json!({ "albedo": albedo }))
            .unwrap()
            .build()
            .unwrap()
    }

    #[test]
    fn relative_error_of_lamberts_is_their_ratio_minus_one() {
        let (a, b) = (lambert(0.5), lambert(0.25));
        let (sa, sb) = (
            compute(a.as_ref(), 0.0, false, 32),
            compute(b.as_ref(), 0.0, false, 32),
        );
        // Against itself: 0 wherever both are above the horizon.
        let e = relative_error(&sa, &sa);
        assert_eq!(e.len(), 32 * 32);
        assert!(e.iter().flatten().all(|x| *x == 0.0));
        // 0.5/π against 0.25/π: +1; the other way: −1/2.
        for (e, want) in [
            (relative_error(&sa, &sb), 1.0),
            (relative_error(&sb, &sa), -0.5),
        ] {
            let valid: Vec<f64> = e.iter().flatten().copied().collect();
            assert!(valid.len() > 400, "{}", valid.len());
            for x in valid {
                assert!((x - want).abs() < 1e-6, "{x} vs {want}");
            }
            // Below the horizon (φd = 0, θh + θd > 90°) stays marked.
            assert_eq!(
                e.iter().filter(|x| x.is_none()).count(),
                sa.values.iter().filter(|x| x.is_none()).count()
            );
        }
        // A zero reference: 0 against 0, +∞ against anything more.
        let zero = lambert(0.0);
        let sz = compute(zero.as_ref(), 0.0, false, 8);
        let sa8 = compute(a.as_ref(), 0.0, false, 8);
        assert!(relative_error(&sz, &sz).iter().flatten().all(|x| *x == 0.0));
        assert!(
            relative_error(&sa8, &sz)
                .iter()
                .flatten()
                .all(|x| *x == f64::INFINITY)
        );
        // Grids that differ: nothing.
        assert!(relative_error(&sa8, &sa).is_empty());
    }

    #[test]
    fn lambert_slice_is_flat_and_the_horizon_is_marked() {
        let b = bv_core::ModelSpec::from_json(
            "lambert",
            &serde_json::json!({"albedo": [0.2, 0.4, 0.6]}),
        )
        .unwrap()
        .build()
        .unwrap();
        let d = compute(b.as_ref(), 0.0, false, 16);
        let want = [0.2 / PI, 0.4 / PI, 0.6 / PI];
        let mut below = 0;
        for row in 0..16 {
            for col in 0..16 {
                let th = theta_h_at((col as f64 + 0.5) / 16.0, false);
                let td = theta_d_at((row as f64 + 0.5) / 16.0);
                match d.values[row * 16 + col] {
                    Some(v) => {
                        for k in 0..3 {
                            assert!((f64::from(v[k]) - want[k]).abs() < 1e-6);
                        }
                        // At φd = 0 the pair stays above the horizon while θh + θd < 90°.
                        assert!(th + td < FRAC_PI_2 + 1e-9);
                    }
                    None => {
                        below += 1;
                        assert!(th + td > FRAC_PI_2 - 1e-9);
                    }
                }
            }
        }
        assert!(below > 50, "{below}");
        // At φd = 90° both directions stay above the horizon everywhere.
        let d90 = compute(b.as_ref(), FRAC_PI_2, false, 16);
        assert!(d90.values.iter().all(Option::is_some));
    }

    #[test]
    fn batched_slice_equals_the_f64_model_pixel_by_pixel() {
        // The rows go through the f32 kernels; `value_at` is the f64 `eval`.
        for (id, p) in [
            (
                "cook-torrance",
                serde_json::json!({"distribution": "ggx", "alpha": 0.2, "fresnel": "conductor",
                    "eta": [0.2, 0.92, 1.1], "k": [3.9, 2.45, 2.14]}),
            ),
            (
                "cook-torrance",
                serde_json::json!({"distribution": "blinn", "alpha": 0.3}),
            ),
            ("ward", serde_json::json!({"alpha_x": 0.1, "alpha_y": 0.3})),
            ("disney", serde_json::Value::Null),
        ] {
            let b = bv_core::ModelSpec::from_json(id, &p)
                .unwrap()
                .build()
                .unwrap();
            for (phi_d, sqrt_axis) in [(0.0, true), (1.0, false), (FRAC_PI_2, true)] {
                let n = 24;
                let d = compute(b.as_ref(), phi_d, sqrt_axis, n);
                for row in 0..n {
                    let td = theta_d_at((row as f64 + 0.5) / n as f64);
                    for col in 0..n {
                        let th = theta_h_at((col as f64 + 0.5) / n as f64, sqrt_axis);
                        let want = value_at(b.as_ref(), th, td, phi_d);
                        let got = d.values[row * n + col];
                        assert_eq!(got.is_some(), want.is_some(), "{id} ({row}, {col})");
                        if let (Some(g), Some(w)) = (got, want) {
                            for (c, w) in [w.x, w.y, w.z].into_iter().enumerate() {
                                let err = (f64::from(g[c]) - w).abs();
                                assert!(
                                    err <= 1e-4 * w.abs() + 1e-6,
                                    "{id} {p} ({row}, {col}) channel {c}: {} vs {w}",
                                    g[c]
                                );
                            }
                        }
                    }
                }
            }
        }
    }
}
