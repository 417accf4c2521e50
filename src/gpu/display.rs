//! Exposure, tone map and sRGB encoding: the CPU twin of
//! `shaders/common/display.wgsl`, for reference images and tests.

use glam::DVec3;

/// How radiance above 1 (after exposure) is brought into the display range.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum ToneMap {
    /// None: values are clipped at 1.
    #[default]
    None,
    /// Reinhard et al. 2002, eq. 3: `L/(1 + L)` per channel.
    Reinhard,
    /// Narkowicz 2015's fit of the ACES filmic curve.
    Aces,
}

impl ToneMap {
    /// Index the shaders use (`TONE_*` in display.wgsl).
    pub fn index(self) -> u32 {
        match self {
            ToneMap::None => 0,
            ToneMap::Reinhard => 1,
            ToneMap::Aces => 2,
        }
    }

    /// Applies the tone map to exposed linear radiance.
    pub fn apply(self, x: DVec3) -> DVec3 {
        match self {
            ToneMap::None => x,
            ToneMap::Reinhard => x / (DVec3::ONE + x),
            ToneMap::Aces => ((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14))
                .clamp(DVec3::ZERO, DVec3::ONE),
        }
    }
}

/// The sRGB transfer function (IEC 61966-2-1) of a linear value, clamped to [0, 1].
pub fn srgb_encode(c: f64) -> f64 {
    let x = c.clamp(0.0, 1.0);
    if x <= 0.003_130_8 {
        12.92 * x
    } else {
        1.055 * x.powf(1.0 / 2.4) - 0.055
    }
}

/// Largest exposed value tone mapped as it is (`MAX_EXPOSED` of
/// display.wgsl: every tone map shows it as white, and ACES squares its
/// input, which overflows f32 above about 1e19).
pub const MAX_EXPOSED: f64 = 1e6;

/// Linear radiance to the encoded display value (× exposure, tone map, sRGB).
pub fn display(radiance: DVec3, exposure: f64, tone: ToneMap) -> DVec3 {
    let x = (radiance.max(DVec3::ZERO) * exposure).min(DVec3::splat(MAX_EXPOSED));
    let t = tone.apply(x);
    DVec3::new(srgb_encode(t.x), srgb_encode(t.y), srgb_encode(t.z))
}

/// An encoded value in [0, 1] as an 8-bit level (rounded to nearest).
pub fn to_u8(x: f64) -> u8 {
    (x.clamp(0.0, 1.0) * 255.0).round() as u8
}
