// Modified Phong (Lafortune & Willems 1994): kd/π + ks (e+2)/(2π) max(0, R(wo)·wi)^e
// (bv_core::models::modified_phong).
#define_import_path bv::models::modified_phong

#import bv::sampling_lobe::{Lobe, LOBE_NONE, mean3, p_cos_of, alpha_of_exponent, none_lobe, power_lobe, ggx_lobe}
#import bv::layout as L

#import bv::params::{pf, prgb}
#import bv::frame::{PI, INV_PI, lobe_pow, reflect_n}
#import bv::layout::{MODIFIED_PHONG_KD, MODIFIED_PHONG_KS, MODIFIED_PHONG_E}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let e = pf(o + MODIFIED_PHONG_E);
    let lobe = lobe_pow(reflect_n(wo), wi, e);
    return prgb(o + MODIFIED_PHONG_KD) * INV_PI
        + prgb(o + MODIFIED_PHONG_KS) * ((e + 2.0) / (2.0 * PI) * lobe);
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    return power_lobe(p_cos_of(mean3(prgb(o + L::MODIFIED_PHONG_KD)), mean3(prgb(o + L::MODIFIED_PHONG_KS))),
        reflect_n(wo), pf(o + L::MODIFIED_PHONG_E));
}
