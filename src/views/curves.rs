//! Plot axes: log ranges, tick marks and their labels shared by the 2D
//! plots (the data they draw are [`crate::derive::slices`]').

/// How many decades below the largest value a log plot reaches at most: a
/// BRDF's tail can fall to 1e-27 and below, which would squash the lobe into
/// the top of the plot; twelve decades show any tail worth reading.
pub const LOG_DECADES: f64 = 12.0;

/// Where a value that a log axis cannot show (zero or negative) is drawn:
/// far below any plot's range, so that its line leaves the plot through the
/// bottom edge (where it is clipped) instead of standing on a made-up floor.
pub const LOG_ZERO: f64 = -1000.0;

/// The vertical range of a log plot, in decades (log10 of the value).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct LogRange {
    /// The bottom of the axis: a whole decade.
    pub bottom: f64,
    /// The top of the axis: the largest value's decade plus headroom for the
    /// legend and markers.
    pub top: f64,
}

impl LogRange {
    /// Headroom above the largest value, in decades.
    pub const HEADROOM: f64 = 0.4;

    /// The range that shows `values`: from the decade of the smallest
    /// positive value (but at most [`LOG_DECADES`] below the largest) to the
    /// largest. At least one decade lies below the largest value, so a
    /// constant (Lambert) is a line inside the plot rather than on its floor.
    /// Without a positive value: 1e-5 to 1.
    pub fn of(values: impl IntoIterator<Item = f64>) -> Self {
        let (mut lo, mut hi) = (f64::INFINITY, 0.0f64);
        for v in values {
            if v > 0.0 && v.is_finite() {
                lo = lo.min(v);
                hi = hi.max(v);
            }
        }
        if hi <= 0.0 {
            return Self {
                bottom: -5.0,
                top: Self::HEADROOM,
            };
        }
        let top = hi.log10();
        let bottom = lo
            .log10()
            .floor()
            .min(top.ceil() - 1.0)
            .max((top - LOG_DECADES).floor());
        Self {
            bottom,
            top: top + Self::HEADROOM,
        }
    }

    /// The lowest value on the axis.
    pub fn floor_value(&self) -> f64 {
        10f64.powf(self.bottom)
    }

    /// The whole decades on the axis, bottom to top.
    pub fn decades(&self) -> impl Iterator<Item = i32> {
        (self.bottom.ceil() as i32)..=(self.top.floor() as i32)
    }
}

/// The plotted ordinate of a value on a log axis: its true log10, with no
/// floor (the plot clips what lies below its range); zero and negative
/// values go to [`LOG_ZERO`].
pub fn log_ordinate(v: f64) -> f64 {
    if v > 0.0 && v.is_finite() {
        v.log10()
    } else {
        LOG_ZERO
    }
}

/// Grid marks of a linear value axis over `bounds`: labelled lines at a
/// 1-2-5 step giving about ten labels at most and at least five minimum steps
/// apart (`min_step` is egui_plot's `GridInput::base_step_size`, about 6
/// points), and thin unlabelled lines at a fifth of it where they are not
/// crowded. egui_plot labels a mark when its `step_size` spans enough points,
/// so the thin lines carry the minimum step as theirs: a maximised plot of a
/// flat Lambert lobe reads 0, 0.05, 0.1, … rather than every 0.01.
pub fn linear_grid_marks(bounds: (f64, f64), min_step: f64) -> Vec<egui_plot::GridMark> {
    let (lo, hi) = bounds;
    if !(lo.is_finite() && hi.is_finite() && min_step.is_finite()) || hi <= lo || min_step <= 0.0 {
        return Vec::new();
    }
    let want = ((hi - lo) / 10.0).max(5.0 * min_step);
    let decade = 10f64.powf(want.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * decade)
        .find(|&s| s >= want * (1.0 - 1e-9))
        .unwrap_or(10.0 * decade);
    let minor = step / 5.0;
    let fine = minor >= 1.5 * min_step;
    // Values as integers of a tenth of the decade, divided once (15 / 100 is
    // 0.15; 3 × 0.05 is 0.15000000000000002).
    let tenth = decade / 10.0;
    let value = |units: i64| {
        if tenth < 1.0 {
            units as f64 / (1.0 / tenth).round()
        } else {
            units as f64 * tenth
        }
    };
    let step_units = (step / tenth).round() as i64;
    let unit_units = if fine { step_units / 5 } else { step_units };
    let first = (lo / (unit_units as f64 * tenth)).ceil() as i64;
    let last = (hi / (unit_units as f64 * tenth)).floor() as i64;
    if last - first > 10_000 || unit_units <= 0 {
        return Vec::new();
    }
    (first..=last)
        .map(|i| {
            let units = i * unit_units;
            let major = units.rem_euclid(step_units) == 0;
            egui_plot::GridMark {
                value: value(units),
                step_size: if major { step } else { min_step },
            }
        })
        .collect()
}

/// The label of a linear axis mark: as many decimals as its step needs
/// (0.05 → "0.05"; egui_plot's default rounds the decimals of a 0.05 step
/// to one and prints "0.1").
pub fn linear_mark_label(value: f64, step: f64) -> String {
    let decimals = if step > 0.0 && step.is_finite() {
        (-step.log10() - 1e-9).ceil().clamp(0.0, 12.0) as usize
    } else {
        0
    };
    let v = if value == 0.0 { 0.0 } else { value };
    format!("{v:.decimals$}")
}

/// `plot` with its y axis marked by [`linear_grid_marks`] and labelled by
/// [`linear_mark_label`].
pub fn with_linear_y(plot: egui_plot::Plot<'_>) -> egui_plot::Plot<'_> {
    plot.y_grid_spacer(|input| linear_grid_marks(input.bounds, input.base_step_size))
        .y_axis_formatter(|mark, _| linear_mark_label(mark.value, mark.step_size))
}

/// Grid marks of a log axis over `bounds` (in decades): a line at every
/// decade, labelled every `k` decades (1, 2, 5, 10, … so that labels do not
/// crowd: `min_step` is the plot's smallest readable step, egui_plot's
/// `GridInput::base_step_size`), and thin lines at 2…9 × 10^k where decades
/// are tall enough. Only whole decades carry labels (see
/// [`decade_mark_label`]).
pub fn log_grid_marks(bounds: (f64, f64), min_step: f64) -> Vec<egui_plot::GridMark> {
    let (lo, hi) = bounds;
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return Vec::new();
    }
    let lo_d = lo.floor() as i64;
    let hi_d = hi.ceil() as i64;
    if hi_d - lo_d > 10_000 {
        return Vec::new();
    }
    // A label is about three minimum steps tall.
    let want = (min_step * 3.0).max(1.0);
    let k = [1i64, 2, 5, 10, 20, 50, 100, 200, 500, 1000]
        .into_iter()
        .find(|&k| k as f64 >= want)
        .unwrap_or(1000);
    let minor = min_step <= 0.15 && hi_d - lo_d <= 40;
    let mut marks = Vec::new();
    for d in lo_d..=hi_d {
        let dv = d as f64;
        if (lo..=hi).contains(&dv) {
            marks.push(egui_plot::GridMark {
                value: dv,
                // Decades between the labelled ones: thinner, unlabelled.
                step_size: if d.rem_euclid(k) == 0 { k as f64 } else { 0.5 },
            });
        }
        if minor {
            for m in 2..=9 {
                let v = dv + f64::from(m).log10();
                if (lo..=hi).contains(&v) {
                    marks.push(egui_plot::GridMark {
                        value: v,
                        step_size: 0.1,
                    });
                }
            }
        }
    }
    marks
}

/// The decade a log axis mark labels: whole decades of step 1 or more (the
/// labelled ones of [`log_grid_marks`]); `None` for the lines between.
pub fn decade_mark_label(value: f64, step_size: f64) -> Option<i32> {
    let k = value.round();
    ((value - k).abs() < 1e-9 && step_size >= 1.0).then_some(k as i32)
}

/// "Nice" round number ≥ `x` (1, 1.2, 1.5, 2, 2.5, 3, 4, 5, 6, 8 × 10^k), for
/// plot rings: fine enough that a curve fills most of the plot.
pub fn nice_ceil(x: f64) -> f64 {
    if x.is_nan() || x <= 0.0 || x.is_infinite() {
        return 1.0;
    }
    let e = x.log10().floor() as i32;
    // Divide for negative exponents, so that 0.3 is the double nearest 0.3.
    let scaled = |m: f64| {
        if e >= 0 {
            m * 10f64.powi(e)
        } else {
            m / 10f64.powi(-e)
        }
    };
    for m in [1.0, 1.2, 1.5, 2.0, 2.5, 3.0, 4.0, 5.0, 6.0, 8.0, 10.0] {
        if scaled(m) >= x * (1.0 - 1e-9) {
            return scaled(m);
        }
    }
    scaled(10.0)
}

pub use bv_core::text::fmt_value;

/// `v` rounded to `digits` significant digits.
pub fn round_significant(v: f64, digits: i32) -> f64 {
    if v == 0.0 || !v.is_finite() {
        return v;
    }
    let e = v.abs().log10().floor() as i32 - (digits - 1);
    if e >= 0 {
        let p = 10f64.powi(e);
        (v / p).round() * p
    } else {
        let p = 10f64.powi(-e);
        (v * p).round() / p
    }
}

/// A compact tick label: at most four significant digits, no trailing zeros
/// (`0.2`, `0.05`, `150`).
pub fn fmt_tick(v: f64) -> String {
    let s = fmt_value(v);
    let trim = |m: &str| m.trim_end_matches('0').trim_end_matches('.').to_string();
    match s.split_once('e') {
        Some((mantissa, exp)) if mantissa.contains('.') => format!("{}e{exp}", trim(mantissa)),
        Some(_) => s,
        None if s.contains('.') => trim(&s),
        None => s,
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Labelled marks (those whose step spans the label spacing) of a linear
    /// axis: a 1-2-5 step, exact multiples, about ten at most.
    #[test]
    fn linear_marks_label_a_readable_step() {
        let labelled = |b: (f64, f64), min: f64| {
            let marks = linear_grid_marks(b, min);
            let step = marks.iter().map(|m| m.step_size).fold(0.0, f64::max);
            let v: Vec<f64> = marks
                .iter()
                .filter(|m| m.step_size == step)
                .map(|m| m.value)
                .collect();
            (step, v, marks.len())
        };
        // A maximised flat Lambert plot: 800 points over 0.23, 6-point base.
        let (step, v, all) = labelled((-0.01, 0.22), 0.23 / 800.0 * 6.0);
        assert_eq!(step, 0.05);
        assert_eq!(v, vec![0.0, 0.05, 0.1, 0.15, 0.2]);
        assert!(all > v.len(), "thin lines between the labels");
        // A small cell: the minimum step wins, no thin lines.
        let (step, v, all) = labelled((0.0, 1.1), 0.08);
        assert_eq!(step, 0.5);
        assert_eq!(v, vec![0.0, 0.5, 1.0]);
        assert_eq!(all, 3);
        // Negative ranges, exact multiples.
        let (step, v, _) = labelled((-3.0, 3.0), 0.01);
        assert_eq!(step, 1.0);
        assert_eq!(v, vec![-3.0, -2.0, -1.0, 0.0, 1.0, 2.0, 3.0]);
        let (_, v, _) = labelled((0.0, 0.7), 0.001);
        assert!(v.contains(&0.3), "{v:?}");
        assert!(v.len() <= 11);
        // Degenerate input.
        assert!(linear_grid_marks((1.0, 1.0), 0.1).is_empty());
        assert!(linear_grid_marks((0.0, f64::NAN), 0.1).is_empty());
        assert!(linear_grid_marks((0.0, 1.0), 0.0).is_empty());
    }

    #[test]
    fn nice_numbers() {
        assert_eq!(nice_ceil(0.159), 0.2);
        assert_eq!(nice_ceil(0.2513), 0.3);
        assert_eq!(nice_ceil(3.0), 3.0);
        assert_eq!(nice_ceil(5.0), 5.0);
        assert_eq!(nice_ceil(51.0), 60.0);
        assert_eq!(nice_ceil(81.0), 100.0);
        assert_eq!(nice_ceil(0.0), 1.0);
        assert_eq!(fmt_value(0.159154), "0.1592");
        assert_eq!(fmt_value(12.5), "12.50");
        assert_eq!(fmt_value(0.0), "0");
        assert_eq!(fmt_value(2.5e-5), "2.500e-5");
        assert_eq!(fmt_tick(0.2), "0.2");
        assert_eq!(round_significant(0.13314, 2), 0.13);
        assert_eq!(round_significant(648.7, 2), 650.0);
        assert_eq!(fmt_tick(150.0), "150");
        assert_eq!(fmt_tick(0.05), "0.05");
        assert_eq!(fmt_tick(1e5), "1e5");
        assert_eq!(fmt_tick(2.5e5), "2.5e5");
        assert_eq!(fmt_tick(2e-5), "2e-5");
    }

    #[test]
    fn log_ordinates_are_true_values() {
        assert!((log_ordinate(100.0) - 2.0).abs() < 1e-12);
        assert!((log_ordinate(3e-27) + 26.522878745280337).abs() < 1e-9);
        assert_eq!(log_ordinate(0.0), LOG_ZERO);
        assert_eq!(log_ordinate(-1.0), LOG_ZERO);
        assert_eq!(log_ordinate(f64::NAN), LOG_ZERO);
    }

    #[test]
    fn log_range_comes_from_the_data() {
        // A specular lobe whose tail falls to 3e-27: twelve decades below
        // its peak of 1.7, not a fixed floor at 1.7e-5.
        let r = LogRange::of([1.7, 0.2, 3e-6, 1e-9, 3e-27, 0.0]);
        assert_eq!(r.bottom, -12.0);
        assert!((r.top - (1.7f64.log10() + LogRange::HEADROOM)).abs() < 1e-12);
        // A tail that stops above that: the range ends at its decade.
        let r = LogRange::of([1.7, 2.5e-4]);
        assert_eq!(r.bottom, -4.0);
        // A constant keeps a decade below it.
        assert_eq!(LogRange::of([0.159]).bottom, -1.0);
        assert_eq!(LogRange::of([0.1]).bottom, -2.0);
        assert_eq!(LogRange::of([100.0, 100.0]).bottom, 1.0);
        // Nothing positive: a default range.
        assert_eq!(LogRange::of([0.0, f64::NAN]).bottom, -5.0);
        let r = LogRange::of([1.0, 1e-3]);
        assert_eq!(r.decades().collect::<Vec<_>>(), vec![-3, -2, -1, 0]);
        assert_eq!(r.floor_value(), 1e-3);
    }

    #[test]
    fn log_grid_marks_label_whole_decades() {
        // Tall decades: every decade strong, minor lines at 2..9.
        let m = log_grid_marks((-3.0, 0.5), 0.05);
        let labelled: Vec<i32> = m
            .iter()
            .filter_map(|g| decade_mark_label(g.value, g.step_size))
            .collect();
        assert_eq!(labelled, vec![-3, -2, -1, 0]);
        assert!(m.iter().any(|g| (g.value - 2f64.log10()).abs() < 1e-12));
        // Many short decades: labels every 5th, no minor lines.
        let m = log_grid_marks((-27.0, 0.5), 1.2);
        let labelled: Vec<i32> = m
            .iter()
            .filter_map(|g| decade_mark_label(g.value, g.step_size))
            .collect();
        assert_eq!(labelled, vec![-25, -20, -15, -10, -5, 0]);
        assert!(m.iter().all(|g| g.value.fract() == 0.0));
        assert!(log_grid_marks((1.0, 1.0), 0.1).is_empty());
    }
}
