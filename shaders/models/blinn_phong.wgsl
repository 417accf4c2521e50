// Blinn-Phong as a BRDF: kd + ks max(0, h·n)^e / cosθi (bv_core::models::blinn_phong).
#define_import_path bv::models::blinn_phong

#import bv::sampling_lobe::{Lobe, LOBE_NONE, mean3, p_cos_of, alpha_of_exponent, none_lobe, power_lobe, ggx_lobe}
#import bv::layout as L

#import bv::params::{pf, prgb}
#import bv::frame::{COS_FLOOR, pow_from_sin2, sin2_of}
#import bv::layout::{BLINN_PHONG_KD, BLINN_PHONG_KS, BLINN_PHONG_E}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    // h·n = cos θh; its power from sin²θh of wi + wo (h.z > 0 here).
    let lobe = pow_from_sin2(sin2_of(wi + wo), pf(o + BLINN_PHONG_E));
    return prgb(o + BLINN_PHONG_KD) + prgb(o + BLINN_PHONG_KS) * (lobe / max(wi.z, COS_FLOOR));
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    let a = alpha_of_exponent(pf(o + L::BLINN_PHONG_E));
    return ggx_lobe(p_cos_of(3.14159 * mean3(prgb(o + L::BLINN_PHONG_KD)), mean3(prgb(o + L::BLINN_PHONG_KS))), a, a);
}
