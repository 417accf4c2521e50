// From linear radiance to display values: exposure, optional tone map, sRGB
// encoding. src/gpu/display.rs holds the same functions in Rust for the CPU
// reference images.
#define_import_path bv::display

// Tone maps (indices of src/gpu/display.rs's ToneMap).
const TONE_NONE: u32 = 0u;
const TONE_REINHARD: u32 = 1u;
const TONE_ACES: u32 = 2u;

// Tone map of one linear value already scaled by the exposure.
fn tone_map(x: vec3<f32>, kind: u32) -> vec3<f32> {
    if (kind == TONE_REINHARD) {
        // Reinhard et al. 2002, eq. 3: L/(1 + L), per channel.
        return x / (vec3<f32>(1.0) + x);
    }
    if (kind == TONE_ACES) {
        // Narkowicz 2015's fit of the ACES filmic curve.
        return clamp((x * (2.51 * x + 0.03)) / (x * (2.43 * x + 0.59) + 0.14), vec3<f32>(0.0), vec3<f32>(1.0));
    }
    return x;
}

// The sRGB transfer function (IEC 61966-2-1) of a linear value in [0, 1].
fn srgb_encode(c: vec3<f32>) -> vec3<f32> {
    let x = clamp(c, vec3<f32>(0.0), vec3<f32>(1.0));
    let lo = 12.92 * x;
    let hi = 1.055 * pow(x, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, x <= vec3<f32>(0.0031308));
}

// Largest exposed value tone mapped as it is: every tone map shows it as
// white already, and ACES squares its input, which overflows f32 (to
// infinity, then NaN, drawn black) above about 1e19.
const MAX_EXPOSED: f32 = 1e6;

// Linear radiance to the encoded display value: × exposure, tone map, sRGB.
fn display(radiance: vec3<f32>, exposure: f32, kind: u32) -> vec3<f32> {
    let x = min(max(radiance, vec3<f32>(0.0)) * exposure, vec3<f32>(MAX_EXPOSED));
    return srgb_encode(tone_map(x, kind));
}
