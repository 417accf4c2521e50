// Ward 1992, eq. 5 (bv_core::models::ward):
// kd/π + ks exp(−tan²θh (cos²φh/αx² + sin²φh/αy²)) / (4π αx αy √(cosθi cosθo)).
#define_import_path bv::models::ward

#import bv::sampling_lobe::{Lobe, LOBE_NONE, mean3, p_cos_of, alpha_of_exponent, none_lobe, power_lobe, ggx_lobe}
#import bv::layout as L

#import bv::params::{pf, prgb}
#import bv::frame::{PI, INV_PI, COS_FLOOR}
#import bv::layout::{WARD_KD, WARD_KS, WARD_ALPHA_X, WARD_ALPHA_Y}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let ax = pf(o + WARD_ALPHA_X);
    let ay = pf(o + WARD_ALPHA_Y);
    // The exponent from v = wi + wo (any positive multiple of h gives the same ratio).
    let v = wi + wo;
    let s = (v.x / ax) * (v.x / ax) + (v.y / ay) * (v.y / ay);
    var e = 0.0;
    if (s > 0.0) {
        e = s / (v.z * v.z);
    }
    let g = exp(-e);
    let denom = 4.0 * PI * ax * ay * sqrt(max(wi.z, COS_FLOOR)) * sqrt(max(wo.z, COS_FLOOR));
    return prgb(o + WARD_KD) * INV_PI + prgb(o + WARD_KS) * (g / denom);
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    return ggx_lobe(p_cos_of(mean3(prgb(o + L::WARD_KD)), mean3(prgb(o + L::WARD_KS))),
        pf(o + L::WARD_ALPHA_X), pf(o + L::WARD_ALPHA_Y));
}
