//! A minimal SVG writer: the few primitives bv's plots need (lines,
//! polylines, filled polygons, rectangles, text, clipping), written by hand so
//! that the output is plain SVG 1.1 any editor (Inkscape, Illustrator) and
//! LaTeX toolchain opens. Coordinates are in points, y down, like egui's.

use eframe::egui::Color32;
use std::fmt::Write as _;

/// Horizontal text anchor.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Anchor {
    /// Text starts at the point.
    Start,
    /// Text is centred on the point.
    Middle,
    /// Text ends at the point.
    End,
}

/// Vertical placement of text relative to the point.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Baseline {
    /// The point is on the text's top edge.
    Top,
    /// The point is at mid-height.
    Middle,
    /// The point is on the baseline.
    Bottom,
}

/// An SVG document being written.
#[derive(Debug, Clone)]
pub struct Svg {
    width: f32,
    height: f32,
    defs: String,
    body: String,
    clips: usize,
    open_groups: usize,
}

/// Escapes text for XML content and attribute values.
pub fn escape(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    for c in text.chars() {
        match c {
            '&' => out.push_str("&amp;"),
            '<' => out.push_str("&lt;"),
            '>' => out.push_str("&gt;"),
            '"' => out.push_str("&quot;"),
            '\'' => out.push_str("&apos;"),
            // Control characters are not allowed in XML 1.0.
            c if (c as u32) < 0x20 && c != '\n' && c != '\t' => {}
            c => out.push(c),
        }
    }
    out
}

/// `#rrggbb` and the opacity of a colour.
pub fn paint(c: Color32) -> (String, f32) {
    let [r, g, b, a] = c.to_srgba_unmultiplied();
    (format!("#{r:02x}{g:02x}{b:02x}"), f32::from(a) / 255.0)
}

/// A number with at most two decimals (points; enough for any display).
fn n(x: f32) -> String {
    if !x.is_finite() {
        return "0".into();
    }
    let s = format!("{x:.2}");
    let s = s.trim_end_matches('0').trim_end_matches('.');
    if s == "-0" { "0".into() } else { s.into() }
}

fn stroke_attrs(color: Color32, width: f32, dash: Option<f32>) -> String {
    let (c, a) = paint(color);
    let mut s = format!(r#"stroke="{c}" stroke-width="{}""#, n(width));
    if a < 1.0 {
        let _ = write!(s, r#" stroke-opacity="{}""#, n(a));
    }
    if let Some(d) = dash {
        let _ = write!(s, r#" stroke-dasharray="{} {}""#, n(d), n(d * 0.8));
    }
    s
}

fn fill_attrs(color: Color32) -> String {
    let (c, a) = paint(color);
    if a < 1.0 {
        format!(r#"fill="{c}" fill-opacity="{}""#, n(a))
    } else {
        format!(r#"fill="{c}""#)
    }
}

impl Svg {
    /// An empty document of `width × height` points.
    pub fn new(width: f32, height: f32) -> Self {
        Self {
            width,
            height,
            defs: String::new(),
            body: String::new(),
            clips: 0,
            open_groups: 0,
        }
    }

    /// A filled and/or stroked rectangle.
    pub fn rect(
        &mut self,
        min: [f32; 2],
        size: [f32; 2],
        fill: Option<Color32>,
        stroke: Option<(Color32, f32)>,
    ) {
        let fill = fill.map_or_else(|| r#"fill="none""#.to_string(), fill_attrs);
        let stroke = stroke.map_or_else(String::new, |(c, w)| stroke_attrs(c, w, None));
        let _ = writeln!(
            self.body,
            r#"<rect x="{}" y="{}" width="{}" height="{}" {fill} {stroke}/>"#,
            n(min[0]),
            n(min[1]),
            n(size[0]),
            n(size[1])
        );
    }

    /// A straight segment.
    pub fn line(
        &mut self,
        a: [f32; 2],
        b: [f32; 2],
        color: Color32,
        width: f32,
        dash: Option<f32>,
    ) {
        let _ = writeln!(
            self.body,
            r#"<line x1="{}" y1="{}" x2="{}" y2="{}" {}/>"#,
            n(a[0]),
            n(a[1]),
            n(b[0]),
            n(b[1]),
            stroke_attrs(color, width, dash)
        );
    }

    /// A polyline; non-finite points break it into separate pieces.
    pub fn polyline(&mut self, points: &[[f32; 2]], color: Color32, width: f32, dash: Option<f32>) {
        for piece in points.split(|p| !(p[0].is_finite() && p[1].is_finite())) {
            if piece.len() < 2 {
                continue;
            }
            let mut pts = String::with_capacity(piece.len() * 12);
            for p in piece {
                let _ = write!(pts, "{},{} ", n(p[0]), n(p[1]));
            }
            let _ = writeln!(
                self.body,
                r#"<polyline points="{}" fill="none" stroke-linejoin="round" stroke-linecap="round" {}/>"#,
                pts.trim_end(),
                stroke_attrs(color, width, dash)
            );
        }
    }

    /// A filled polygon (any shape: SVG fills non-convex ones correctly).
    pub fn polygon(&mut self, points: &[[f32; 2]], fill: Color32) {
        if points.len() < 3 {
            return;
        }
        let mut pts = String::new();
        for p in points
            .iter()
            .filter(|p| p[0].is_finite() && p[1].is_finite())
        {
            let _ = write!(pts, "{},{} ", n(p[0]), n(p[1]));
        }
        let _ = writeln!(
            self.body,
            r#"<polygon points="{}" stroke="none" {}/>"#,
            pts.trim_end(),
            fill_attrs(fill)
        );
    }

    /// Text at a point.
    #[allow(clippy::too_many_arguments)]
    pub fn text(
        &mut self,
        at: [f32; 2],
        text: &str,
        size: f32,
        color: Color32,
        anchor: Anchor,
        baseline: Baseline,
        rotate_deg: Option<f32>,
    ) {
        let anchor = match anchor {
            Anchor::Start => "start",
            Anchor::Middle => "middle",
            Anchor::End => "end",
        };
        // dominant-baseline is not honoured everywhere; shift by the font size
        // instead, which every renderer does the same way.
        let dy = match baseline {
            Baseline::Top => size * 0.8,
            Baseline::Middle => size * 0.35,
            Baseline::Bottom => 0.0,
        };
        let transform = rotate_deg.map_or_else(String::new, |r| {
            format!(r#" transform="rotate({} {} {})""#, n(r), n(at[0]), n(at[1]))
        });
        let _ = writeln!(
            self.body,
            r#"<text x="{}" y="{}" font-size="{}" text-anchor="{anchor}" {}{transform}>{}</text>"#,
            n(at[0]),
            n(at[1] + dy),
            n(size),
            fill_attrs(color),
            escape(text)
        );
    }

    /// Starts a group whose contents are shifted by `offset` (end it with
    /// [`Svg::end_group`]): one figure made of several panels.
    pub fn begin_translate(&mut self, offset: [f32; 2]) {
        let _ = writeln!(
            self.body,
            r#"<g transform="translate({} {})">"#,
            n(offset[0]),
            n(offset[1])
        );
        self.open_groups += 1;
    }

    /// Starts a group clipped to a rectangle (end it with [`Svg::end_group`]).
    pub fn begin_clip(&mut self, min: [f32; 2], size: [f32; 2]) {
        self.clips += 1;
        let id = format!("clip{}", self.clips);
        let _ = writeln!(
            self.defs,
            r#"<clipPath id="{id}"><rect x="{}" y="{}" width="{}" height="{}"/></clipPath>"#,
            n(min[0]),
            n(min[1]),
            n(size[0]),
            n(size[1])
        );
        let _ = writeln!(self.body, r#"<g clip-path="url(#{id})">"#);
        self.open_groups += 1;
    }

    /// Ends the last group.
    pub fn end_group(&mut self) {
        if self.open_groups > 0 {
            self.body.push_str("</g>\n");
            self.open_groups -= 1;
        }
    }

    /// A comment (e.g. what the figure shows, for someone reading the file).
    pub fn comment(&mut self, text: &str) {
        let text = text.replace("--", "- -");
        let _ = writeln!(self.body, "<!-- {text} -->");
    }

    /// The finished document.
    pub fn finish(mut self) -> String {
        while self.open_groups > 0 {
            self.end_group();
        }
        let mut out = String::new();
        out.push_str("<?xml version=\"1.0\" encoding=\"UTF-8\"?>\n");
        let _ = writeln!(
            out,
            r#"<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{w}pt" height="{h}pt" viewBox="0 0 {w} {h}" font-family="DejaVu Sans, Helvetica, Arial, sans-serif">"#,
            w = n(self.width),
            h = n(self.height)
        );
        if !self.defs.is_empty() {
            out.push_str("<defs>\n");
            out.push_str(&self.defs);
            out.push_str("</defs>\n");
        }
        out.push_str(&self.body);
        out.push_str("</svg>\n");
        out
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn escapes_markup() {
        assert_eq!(escape("a<b & \"c\""), "a&lt;b &amp; &quot;c&quot;");
        assert_eq!(escape("θ\u{1}"), "θ");
    }

    #[test]
    fn numbers_are_short() {
        assert_eq!(n(1.0), "1");
        assert_eq!(n(1.256), "1.26");
        assert_eq!(n(-0.001), "0");
        assert_eq!(n(f32::NAN), "0");
    }

    #[test]
    fn polylines_break_at_gaps() {
        let mut s = Svg::new(10.0, 10.0);
        s.polyline(
            &[
                [0.0, 0.0],
                [1.0, 1.0],
                [f32::NAN, 0.0],
                [2.0, 2.0],
                [3.0, 3.0],
            ],
            Color32::RED,
            1.0,
            None,
        );
        let doc = s.finish();
        assert_eq!(doc.matches("<polyline").count(), 2);
        assert!(doc.starts_with("<?xml"));
    }
}
