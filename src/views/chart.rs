//! A 2D chart as data (series, error bands, marker lines, axes, legend), for
//! the vector export of the Cartesian, albedo and Fresnel views: each view
//! builds one from the same numbers it hands egui_plot, and [`Chart::to_svg`]
//! draws it with the GUI's colours, ticks and labels.

use super::svg::{Anchor, Baseline, Svg};
use eframe::egui::Color32;

/// One curve.
#[derive(Debug, Clone)]
pub struct Series {
    /// Legend text (empty: not in the legend).
    pub label: String,
    /// Colour.
    pub color: Color32,
    /// Points in data coordinates (non-finite ones break the line).
    pub points: Vec<[f64; 2]>,
    /// Stroke width in points.
    pub width: f32,
    /// Dash length, if dashed.
    pub dash: Option<f32>,
}

/// A filled band between two curves (an error band).
#[derive(Debug, Clone)]
pub struct Band {
    /// Fill colour (translucent).
    pub color: Color32,
    /// Abscissae.
    pub xs: Vec<f64>,
    /// Lower edge.
    pub lo: Vec<f64>,
    /// Upper edge.
    pub hi: Vec<f64>,
}

/// A vertical or horizontal marker line with a label.
#[derive(Debug, Clone)]
pub struct Marker {
    /// Position (x for vertical, y for horizontal markers).
    pub at: f64,
    /// Colour.
    pub color: Color32,
    /// Dashed.
    pub dashed: bool,
    /// Label drawn beside the line.
    pub label: String,
}

/// A chart.
#[derive(Debug, Clone, Default)]
pub struct Chart {
    /// Title above the plot (optional).
    pub title: String,
    /// Horizontal axis label.
    pub x_label: String,
    /// Vertical axis label.
    pub y_label: String,
    /// Shown x range.
    pub x_range: (f64, f64),
    /// Shown y range.
    pub y_range: (f64, f64),
    /// x ticks with their labels.
    pub x_ticks: Vec<(f64, String)>,
    /// y ticks with their labels.
    pub y_ticks: Vec<(f64, String)>,
    /// Bands, drawn first.
    pub bands: Vec<Band>,
    /// Curves.
    pub series: Vec<Series>,
    /// Vertical markers.
    pub vlines: Vec<Marker>,
    /// Horizontal markers.
    pub hlines: Vec<Marker>,
    /// A note in the plot's top-left corner (e.g. "no Fresnel term").
    pub note: String,
}

/// Colours of a figure's frame.
#[derive(Debug, Clone, Copy)]
pub struct Palette {
    /// Background (None: transparent).
    pub background: Option<Color32>,
    /// Text.
    pub text: Color32,
    /// Weaker text (ticks).
    pub weak: Color32,
    /// Grid lines.
    pub grid: Color32,
    /// Plot frame.
    pub frame: Color32,
}

impl Palette {
    /// The GUI's colours for a theme.
    pub fn new(dark: bool, transparent: bool) -> Self {
        let (bg, text, weak) = if dark {
            (
                Color32::from_gray(27),
                Color32::from_gray(230),
                Color32::from_gray(170),
            )
        } else {
            (
                Color32::from_gray(248),
                Color32::from_gray(20),
                Color32::from_gray(80),
            )
        };
        Self {
            background: (!transparent).then_some(bg),
            text,
            weak,
            grid: super::grid_color(dark),
            frame: weak.gamma_multiply(0.7),
        }
    }
}

/// Round tick positions covering `lo..=hi`, about `target` of them, at steps of
/// 1, 2 or 5 × 10^k.
pub fn nice_ticks(lo: f64, hi: f64, target: usize) -> Vec<f64> {
    if !(lo.is_finite() && hi.is_finite()) || hi <= lo {
        return Vec::new();
    }
    let raw = (hi - lo) / target.max(1) as f64;
    let mag = 10f64.powf(raw.log10().floor());
    let step = [1.0, 2.0, 5.0, 10.0]
        .into_iter()
        .map(|m| m * mag)
        .find(|s| *s >= raw)
        .unwrap_or(10.0 * mag);
    // A little slack, so that 0.3 / 0.1 = 2.9999999999999996 keeps its tick.
    let first = (lo / step - 1e-9).ceil() as i64;
    let last = (hi / step + 1e-9).floor() as i64;
    (first..=last)
        .map(|k| {
            let v = k as f64 * step;
            // Snap the rounding noise of k · step (0.30000000000000004).
            super::curves::round_significant(v, 12)
        })
        .collect()
}

/// Ticks with plain labels (`fmt_tick`).
pub fn labelled(ticks: Vec<f64>) -> Vec<(f64, String)> {
    ticks
        .into_iter()
        .map(|t| (t, super::curves::fmt_tick(t)))
        .collect()
}

/// Angle ticks in degrees at the steps the plots use (15°, 45°, 90°).
pub fn angle_ticks(lo: f64, hi: f64) -> Vec<(f64, String)> {
    let span = hi - lo;
    let step = if span > 200.0 {
        90.0
    } else if span > 100.0 {
        45.0
    } else if span > 50.0 {
        15.0
    } else {
        5.0
    };
    let first = (lo / step).ceil() as i64;
    let last = (hi / step).floor() as i64;
    (first..=last)
        .map(|k| {
            let v = k as f64 * step;
            (v, format!("{v:.0}°"))
        })
        .collect()
}

impl Chart {
    /// The chart as an SVG document of `size` points.
    pub fn to_svg(&self, size: [f32; 2], pal: Palette) -> String {
        let [w, h] = [size[0].max(120.0), size[1].max(90.0)];
        let mut svg = Svg::new(w, h);
        if !self.title.is_empty() {
            svg.comment(&self.title);
        }
        if let Some(bg) = pal.background {
            svg.rect([0.0, 0.0], [w, h], Some(bg), None);
        }
        self.draw(&mut svg, [w, h], pal);
        svg.finish()
    }

    /// The plot's frame inside a chart of `size` points: its top-left corner
    /// and size (the axes' labels lie outside it).
    pub fn plot_area(&self, size: [f32; 2]) -> ([f32; 2], [f32; 2]) {
        let [w, h] = size;
        let top = if self.title.is_empty() { 10.0 } else { 28.0 };
        let (left, bottom, right) = (62.0, 44.0, 14.0);
        (
            [left, top],
            [(w - left - right).max(20.0), (h - top - bottom).max(20.0)],
        )
    }

    /// Draws the chart (without a background) into `svg` over `[0, 0]..size`
    /// of its current coordinates: several charts share one document through
    /// [`Svg::begin_translate`].
    pub fn draw(&self, svg: &mut Svg, size: [f32; 2], pal: Palette) {
        let [w, h] = size;
        let font = 12.0;
        let (pmin, psize) = self.plot_area(size);
        let (x0, x1) = self.x_range;
        let (y0, y1) = self.y_range;
        let sx = |x: f64| pmin[0] + ((x - x0) / (x1 - x0)) as f32 * psize[0];
        let sy = |y: f64| pmin[1] + psize[1] - ((y - y0) / (y1 - y0)) as f32 * psize[1];
        let to = |p: &[f64; 2]| [sx(p[0]), sy(p[1])];

        if !self.title.is_empty() {
            svg.text(
                [w * 0.5, 8.0],
                &self.title,
                font + 1.0,
                pal.text,
                Anchor::Middle,
                Baseline::Top,
                None,
            );
        }
        // Grid and ticks.
        for (x, label) in &self.x_ticks {
            let px = sx(*x);
            svg.line([px, pmin[1]], [px, pmin[1] + psize[1]], pal.grid, 1.0, None);
            svg.text(
                [px, pmin[1] + psize[1] + 4.0],
                label,
                font - 1.0,
                pal.weak,
                Anchor::Middle,
                Baseline::Top,
                None,
            );
        }
        for (y, label) in &self.y_ticks {
            let py = sy(*y);
            svg.line([pmin[0], py], [pmin[0] + psize[0], py], pal.grid, 1.0, None);
            svg.text(
                [pmin[0] - 5.0, py],
                label,
                font - 1.0,
                pal.weak,
                Anchor::End,
                Baseline::Middle,
                None,
            );
        }
        svg.rect(pmin, psize, None, Some((pal.frame, 1.0)));
        svg.text(
            [pmin[0] + psize[0] * 0.5, h - 8.0],
            &self.x_label,
            font,
            pal.text,
            Anchor::Middle,
            Baseline::Bottom,
            None,
        );
        svg.text(
            [14.0, pmin[1] + psize[1] * 0.5],
            &self.y_label,
            font,
            pal.text,
            Anchor::Middle,
            Baseline::Middle,
            Some(-90.0),
        );

        svg.begin_clip(pmin, psize);
        for b in &self.bands {
            let mut pts: Vec<[f32; 2]> =
                b.xs.iter()
                    .zip(&b.hi)
                    .map(|(x, y)| [sx(*x), sy(*y)])
                    .collect();
            pts.extend(b.xs.iter().zip(&b.lo).rev().map(|(x, y)| [sx(*x), sy(*y)]));
            svg.polygon(&pts, b.color);
        }
        for m in &self.hlines {
            let py = sy(m.at);
            svg.line(
                [pmin[0], py],
                [pmin[0] + psize[0], py],
                m.color,
                1.5,
                m.dashed.then_some(6.0),
            );
        }
        for m in &self.vlines {
            let px = sx(m.at);
            svg.line(
                [px, pmin[1]],
                [px, pmin[1] + psize[1]],
                m.color,
                1.5,
                m.dashed.then_some(6.0),
            );
        }
        for s in &self.series {
            let pts: Vec<[f32; 2]> = s.points.iter().map(to).collect();
            svg.polyline(&pts, s.color, s.width, s.dash);
        }
        svg.end_group();
        // Marker labels inside the plot, beside their lines.
        for (k, m) in self.vlines.iter().enumerate() {
            if !m.label.is_empty() {
                svg.text(
                    [sx(m.at) + 3.0, pmin[1] + psize[1] - 4.0 - 14.0 * k as f32],
                    &m.label,
                    font - 1.0,
                    m.color,
                    Anchor::Start,
                    Baseline::Bottom,
                    None,
                );
            }
        }
        for m in &self.hlines {
            if !m.label.is_empty() {
                svg.text(
                    [pmin[0] + 4.0, sy(m.at) - 3.0],
                    &m.label,
                    font - 1.0,
                    m.color,
                    Anchor::Start,
                    Baseline::Bottom,
                    None,
                );
            }
        }
        let mut note_w: f32 = 0.0;
        let mut note_h = 0.0;
        if !self.note.is_empty() {
            for (k, line) in self.note.lines().enumerate() {
                svg.text(
                    [pmin[0] + 8.0, pmin[1] + 8.0 + k as f32 * (font + 4.0)],
                    line,
                    font,
                    pal.text,
                    Anchor::Start,
                    Baseline::Top,
                    None,
                );
                note_w = note_w.max(text_width(line, font));
                note_h = 8.0 + (k + 1) as f32 * (font + 4.0);
            }
        }
        // The legend sits in the top-right corner, or under the note where
        // the two would overlap.
        let top = if note_w + legend_width(&self.series) + 24.0 > psize[0] {
            pmin[1] + note_h
        } else {
            pmin[1]
        };
        legend(svg, &self.series, [pmin[0] + psize[0], top], pal);
    }
}

/// An estimate of a line's width in points (no font metrics here): 0.58 em
/// per character.
fn text_width(text: &str, font: f32) -> f32 {
    text.chars().count() as f32 * font * 0.58
}

/// The legend's font size.
const LEGEND_FONT: f32 = 11.5;

/// The width of [`legend`]'s box for `series` (0 without a labelled one).
fn legend_width(series: &[Series]) -> f32 {
    let text_w = series
        .iter()
        .filter(|s| !s.label.is_empty())
        .map(|s| text_width(&s.label, LEGEND_FONT))
        .fold(None, |m: Option<f32>, w| Some(m.map_or(w, |m| m.max(w))));
    text_w.map_or(0.0, |w| w + 46.0)
}

/// The legend box in the top-right corner at `corner` (the plot's top right).
pub fn legend(svg: &mut Svg, series: &[Series], corner: [f32; 2], pal: Palette) {
    let items: Vec<&Series> = series.iter().filter(|s| !s.label.is_empty()).collect();
    if items.is_empty() {
        return;
    }
    let font = LEGEND_FONT;
    let row = 16.0;
    let box_w = legend_width(series) - 6.0;
    let box_h = items.len() as f32 * row + 8.0;
    let min = [corner[0] - box_w - 6.0, corner[1] + 6.0];
    let fill = pal
        .background
        .map(|c| c.gamma_multiply(0.92))
        .unwrap_or(Color32::TRANSPARENT);
    svg.rect(min, [box_w, box_h], Some(fill), Some((pal.frame, 0.8)));
    for (k, s) in items.iter().enumerate() {
        let y = min[1] + 4.0 + row * (k as f32 + 0.5);
        svg.line(
            [min[0] + 6.0, y],
            [min[0] + 28.0, y],
            s.color,
            s.width.max(2.0),
            s.dash,
        );
        svg.text(
            [min[0] + 34.0, y],
            &s.label,
            font,
            pal.text,
            Anchor::Start,
            Baseline::Middle,
            None,
        );
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ticks_are_round_and_cover_the_range() {
        assert_eq!(nice_ticks(0.0, 1.0, 5), vec![0.0, 0.2, 0.4, 0.6, 0.8, 1.0]);
        assert_eq!(nice_ticks(0.0, 0.3, 3), vec![0.0, 0.1, 0.2, 0.3]);
        assert!(nice_ticks(1.0, 1.0, 5).is_empty());
        let a = angle_ticks(-90.0, 90.0);
        assert_eq!(a.first().unwrap().0, -90.0);
        assert_eq!(a.len(), 5);
    }

    #[test]
    fn svg_has_the_parts_of_a_plot() {
        let c = Chart {
            title: "t".into(),
            x_label: "θ (°)".into(),
            y_label: "F".into(),
            x_range: (0.0, 90.0),
            y_range: (0.0, 1.0),
            x_ticks: angle_ticks(0.0, 90.0),
            y_ticks: labelled(nice_ticks(0.0, 1.0, 5)),
            series: vec![Series {
                label: "a & b".into(),
                color: Color32::RED,
                points: vec![[0.0, 0.0], [90.0, 1.0]],
                width: 2.0,
                dash: None,
            }],
            ..Default::default()
        };
        let svg = c.to_svg([400.0, 300.0], Palette::new(true, false));
        assert!(svg.contains("a &amp; b"));
        assert!(svg.contains("θ (°)"));
        assert!(svg.contains("<polyline"));
    }
}
