//! The colour map of lobe values (viridis: perceptually uniform, readable in
//! grey on a printed handout and by most colour-blind viewers). One table feeds
//! both the shader and the colour bar, so they cannot disagree.

use eframe::egui::Color32;

/// Viridis at t = 0, 0.1, …, 1 (sRGB), from matplotlib's `_viridis_data`.
pub const VIRIDIS: [[u8; 3]; 11] = [
    [0x44, 0x01, 0x54],
    [0x48, 0x24, 0x75],
    [0x41, 0x44, 0x87],
    [0x35, 0x5f, 0x8d],
    [0x2a, 0x78, 0x8e],
    [0x21, 0x91, 0x8c],
    [0x22, 0xa8, 0x84],
    [0x44, 0xbf, 0x70],
    [0x7a, 0xd1, 0x51],
    [0xbd, 0xdf, 0x26],
    [0xfd, 0xe7, 0x25],
];

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

/// The table as a WGSL array literal (`array<vec3<f32>, 11>(…)`) in 0..1 sRGB.
pub fn wgsl_table() -> String {
    let items: Vec<String> = VIRIDIS
        .iter()
        .map(|c| {
            format!(
                "vec3<f32>({:.6}, {:.6}, {:.6})",
                c[0] as f32 / 255.0,
                c[1] as f32 / 255.0,
                c[2] as f32 / 255.0
            )
        })
        .collect();
    format!("array<vec3<f32>, {}>({})", VIRIDIS.len(), items.join(", "))
}

#[cfg(test)]
mod tests {
    use super::*;

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
        assert!(wgsl_table().starts_with("array<vec3<f32>, 11>(vec3<f32>(0.266667"));
    }
}
