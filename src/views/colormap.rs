//! The colour map of lobe values as egui colours (the colour bar, mesh
//! export). The table is [`crate::gpu::colormap::VIRIDIS`], the one the lobe
//! shader gets, so they cannot disagree.

use eframe::egui::Color32;

pub use crate::gpu::colormap::VIRIDIS;

/// The colour of `t ∈ [0, 1]` (clamped), interpolated in sRGB like the shader.
pub fn viridis(t: f32) -> Color32 {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.0
    };
    let x = t * (VIRIDIS.len() - 1) as f32;
    let i = (x.floor() as usize).min(VIRIDIS.len() - 2);
    let f = x - i as f32;
    let a = VIRIDIS[i];
    let b = VIRIDIS[i + 1];
    let mix = |k: usize| (a[k] as f32 + (b[k] as f32 - a[k] as f32) * f).round() as u8;
    Color32::from_rgb(mix(0), mix(1), mix(2))
}

/// Moreland's cool–warm diverging map (K. Moreland, "Diverging Color Maps
/// for Scientific Visualization", ISVC 2009, Table 1's control points as
/// tabulated in sRGB): blue below, light grey at the middle, red above, of
/// equal lightness at equal distances from the middle, so that signed
/// errors of either sign read alike.
pub const COOL_WARM: [[u8; 3]; 9] = [
    [59, 76, 192],
    [98, 130, 234],
    [141, 176, 254],
    [184, 208, 249],
    [221, 221, 221],
    [245, 196, 173],
    [244, 154, 123],
    [222, 96, 77],
    [180, 4, 38],
];

/// The diverging colour of `t ∈ [0, 1]` (clamped; 0.5 is the middle),
/// interpolated in sRGB.
pub fn cool_warm(t: f32) -> Color32 {
    let t = if t.is_finite() {
        t.clamp(0.0, 1.0)
    } else {
        0.5
    };
    let x = t * (COOL_WARM.len() - 1) as f32;
    let i = (x.floor() as usize).min(COOL_WARM.len() - 2);
    let f = x - i as f32;
    let (a, b) = (COOL_WARM[i], COOL_WARM[i + 1]);
    let mix = |k: usize| (a[k] as f32 + (b[k] as f32 - a[k] as f32) * f).round() as u8;
    Color32::from_rgb(mix(0), mix(1), mix(2))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn cool_warm_is_grey_in_the_middle_and_symmetric_in_lightness() {
        assert_eq!(cool_warm(0.5), Color32::from_rgb(221, 221, 221));
        assert_eq!(cool_warm(-1.0), cool_warm(0.0));
        assert_eq!(cool_warm(f32::NAN), cool_warm(0.5));
        let c = cool_warm(0.0);
        assert!(c.b() > c.r(), "blue below");
        let c = cool_warm(1.0);
        assert!(c.r() > c.b(), "red above");
    }

    #[test]
    fn ends_and_monotone_lightness() {
        assert_eq!(viridis(0.0), Color32::from_rgb(0x44, 0x01, 0x54));
        assert_eq!(viridis(1.0), Color32::from_rgb(0xfd, 0xe7, 0x25));
        assert_eq!(viridis(2.0), viridis(1.0));
        assert_eq!(viridis(f32::NAN), viridis(0.0));
        // Viridis gets lighter along t (sum of channels as a crude lightness).
        let l = |t: f32| {
            let c = viridis(t);
            c.r() as u32 + c.g() as u32 + c.b() as u32
        };
        for k in 0..20 {
            assert!(l(k as f32 / 20.0) <= l((k + 1) as f32 / 20.0) + 2);
        }
    }
}
