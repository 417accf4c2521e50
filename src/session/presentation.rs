//! Presentation mode's sizes: how much the window is scaled and how much
//! thicker plot lines are drawn when bv is projected in a lecture hall.
//!
//! The window and `bv render --deck` both take the scale from here, so a
//! rendered slide has the pixels of the live window at the same size.

/// The window size (in pixels) the presentation sizes are chosen for.
pub const REFERENCE_PIXELS: [f32; 2] = [1920.0, 1080.0];

/// Pixels per point at [`REFERENCE_PIXELS`]. The smallest text the views draw
/// is 11 points (polar angle labels, Fresnel markers, image-slice ticks;
/// egui's default body text, which plot ticks and legends use, is 12.5).
/// At 2.75 pixels per point that is a 30-pixel font, whose digits and
/// capitals (0.7 em in the default font) are 21 pixels tall on a 1080p
/// projector: about the 1/50 of the screen height that is still read from
/// the back of a lecture hall.
pub const REFERENCE_SCALE: f32 = 2.75;

/// How much thicker the views draw their strokes when presenting. The
/// thinnest plot stroke is 1 point (grid lines, reference curves); at
/// [`REFERENCE_SCALE`] that becomes 3.3 pixels, and the plotted BRDF curves
/// (1.8–2.5 points) 6–8 pixels.
pub const LINE_SCALE: f32 = 1.2;

/// Pixels per point for a window of `pixels` (width, height): the
/// [`REFERENCE_SCALE`] scaled with the smaller of the two ratios to
/// [`REFERENCE_PIXELS`] (so a 4K projector gets 5.5, a 1280×720 one 1.83),
/// never below 1 (a small window stays at its native size).
pub fn scale_for(pixels: [f32; 2]) -> f32 {
    let [w, h] = pixels;
    if !(w.is_finite() && h.is_finite() && w > 0.0 && h > 0.0) {
        return 1.0;
    }
    let ratio = (w / REFERENCE_PIXELS[0]).min(h / REFERENCE_PIXELS[1]);
    (REFERENCE_SCALE * ratio).max(1.0)
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn the_scale_follows_the_window() {
        assert_eq!(scale_for([1920.0, 1080.0]), 2.75);
        assert_eq!(scale_for([3840.0, 2160.0]), 5.5);
        // A wide window is limited by its height, a tall one by its width.
        assert_eq!(scale_for([3840.0, 1080.0]), 2.75);
        assert_eq!(scale_for([960.0, 2160.0]), 1.375);
        assert!((scale_for([1280.0, 720.0]) - 2.75 * 2.0 / 3.0).abs() < 1e-6);
        assert_eq!(scale_for([640.0, 360.0]), 1.0);
        assert_eq!(scale_for([320.0, 200.0]), 1.0);
        assert_eq!(scale_for([f32::NAN, 1.0]), 1.0);
        // The smallest view text (11 pt; digits 0.7 em) and stroke (1 pt)
        // at 1080p.
        assert!(0.7 * 11.0 * scale_for([1920.0, 1080.0]) >= 20.0);
        assert!(LINE_SCALE * scale_for([1920.0, 1080.0]) >= 2.5);
    }
}
