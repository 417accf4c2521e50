//! The fonts every egui context of bv draws with: egui's own (Ubuntu Light,
//! Hack) and, after them, DejaVu Sans for the glyphs they lack. The lecture's
//! notation needs ∥ ⊥ ∫ ≤ ≠ ≈ ∞ ∇ and more that egui's default fonts have no
//! glyph for (drawn as empty boxes: "r∥²" read "r□²" on the Fresnel slide).
//! DejaVu Sans has them; as a fallback it leaves the look of the text that
//! egui's fonts do cover unchanged.
//!
//! The font is compiled in (`include_bytes!`), so the window, the headless
//! figures (`bv render`) and the web build draw the same glyphs without a
//! file to find at run time. Its licence is `assets/fonts/DejaVuSans-LICENSE.txt`.

use eframe::egui::{self, FontInsert, FontPriority, InsertFontFamily};

/// DejaVu Sans 2.37 (Bitstream Vera licence, which allows bundling).
pub const DEJAVU_SANS: &[u8] = include_bytes!("../../assets/fonts/DejaVuSans.ttf");

/// The name the fallback font is registered under.
pub const FALLBACK_NAME: &str = "DejaVuSans";

/// Adds the fallback font to `ctx` (proportional and monospace text), after
/// egui's fonts. Cheap to call every frame: egui skips a font it already
/// has by name. Takes effect at once where no text was laid out yet in this
/// pass (a fresh context, a test harness's first frame), else from the next.
pub fn install(ctx: &egui::Context) {
    let families = [egui::FontFamily::Proportional, egui::FontFamily::Monospace]
        .into_iter()
        .map(|family| InsertFontFamily {
            family,
            priority: FontPriority::Lowest,
        })
        .collect();
    ctx.add_font(FontInsert::new(
        FALLBACK_NAME,
        egui::FontData::from_static(DEJAVU_SANS),
        families,
    ));
}

/// egui's fonts with DejaVu Sans: after them (their look, DejaVu only for
/// the glyphs they lack) or, for `presenting`, first in proportional text.
/// Projected, Ubuntu Light's ρ reads as a p ("ρhd" as "phd") and its thin
/// strokes wash out; DejaVu Sans's ρ is unmistakable and its strokes
/// heavier. The window keeps egui's look otherwise.
pub fn definitions(presenting: bool) -> egui::FontDefinitions {
    let mut defs = egui::FontDefinitions::default();
    defs.font_data.insert(
        FALLBACK_NAME.to_owned(),
        std::sync::Arc::new(egui::FontData::from_static(DEJAVU_SANS)),
    );
    for (family, first) in [
        (egui::FontFamily::Proportional, presenting),
        (egui::FontFamily::Monospace, false),
    ] {
        let list = defs.families.entry(family).or_default();
        if first {
            list.insert(0, FALLBACK_NAME.to_owned());
        } else {
            list.push(FALLBACK_NAME.to_owned());
        }
    }
    defs
}

/// Sets `ctx`'s fonts to [`definitions`]`(presenting)`. Compares the whole
/// definitions with the current ones (font data included): call it when
/// the mode changes, not every frame.
pub fn set_presenting(ctx: &egui::Context, presenting: bool) {
    ctx.set_fonts(definitions(presenting));
}

/// The characters of `text` that no font of `family` in `ctx` has a glyph
/// for (what would be drawn as an empty box), each once, in order. White
/// space and control characters are not drawn and not reported.
pub fn missing_glyphs(ctx: &egui::Context, family: &egui::FontFamily, text: &str) -> Vec<char> {
    let font = egui::FontId::new(12.0, family.clone());
    let mut out: Vec<char> = Vec::new();
    ctx.fonts_mut(|f| {
        for c in text.chars() {
            if c.is_whitespace() || c.is_control() || out.contains(&c) {
                continue;
            }
            if !f.has_glyph(&font, c) {
                out.push(c);
            }
        }
    });
    out
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn dejavu_comes_first_only_when_presenting() {
        let order = |presenting: bool, family: egui::FontFamily| {
            definitions(presenting)
                .families
                .get(&family)
                .cloned()
                .unwrap_or_default()
        };
        let window = order(false, egui::FontFamily::Proportional);
        assert_eq!(window.first().map(String::as_str), Some("Ubuntu-Light"));
        assert_eq!(window.last().map(String::as_str), Some(FALLBACK_NAME));
        // Presenting: its ρ (Ubuntu Light's reads as a p) and heavier strokes.
        let presented = order(true, egui::FontFamily::Proportional);
        assert_eq!(presented.first().map(String::as_str), Some(FALLBACK_NAME));
        assert!(presented.iter().any(|f| f == "Ubuntu-Light"));
        for presenting in [false, true] {
            let mono = order(presenting, egui::FontFamily::Monospace);
            assert_eq!(mono.last().map(String::as_str), Some(FALLBACK_NAME));
        }
    }
}
