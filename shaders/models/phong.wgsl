// Classical Phong as a BRDF: kd + ks max(0, R(wo)·wi)^e / cosθi
// (bv_core::models::phong; deliberately non-reciprocal).
#define_import_path bv::models::phong

#import bv::sampling_lobe::{Lobe, LOBE_NONE, mean3, p_cos_of, alpha_of_exponent, none_lobe, power_lobe, ggx_lobe}
#import bv::layout as L

#import bv::params::{pf, prgb}
#import bv::frame::{COS_FLOOR, lobe_pow, reflect_n}
#import bv::layout::{PHONG_KD, PHONG_KS, PHONG_E}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let lobe = lobe_pow(reflect_n(wo), wi, pf(o + PHONG_E));
    return prgb(o + PHONG_KD) + prgb(o + PHONG_KS) * (lobe / max(wi.z, COS_FLOOR));
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    return power_lobe(p_cos_of(3.14159 * mean3(prgb(o + L::PHONG_KD)), mean3(prgb(o + L::PHONG_KS))),
        reflect_n(wo), pf(o + L::PHONG_E));
}
