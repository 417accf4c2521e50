// Oren & Nayar 1994, qualitative model eq. 30 (bv_core::models::oren_nayar).
#define_import_path bv::models::oren_nayar

#import bv::params::{pf, prgb}
#import bv::frame::INV_PI
#import bv::layout::{OREN_NAYAR_ALBEDO, OREN_NAYAR_SIGMA}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let sigma = pf(o + OREN_NAYAR_SIGMA);
    let s2 = sigma * sigma;
    let a = 1.0 - 0.5 * s2 / (s2 + 0.33);
    let b = 0.45 * s2 / (s2 + 0.09);
    // max(0, cos(φi − φo)) sin α tan β = max(0, tangential dot) / max(cosθi, cosθo).
    let tangential = wi.x * wo.x + wi.y * wo.y;
    let t = max(tangential, 0.0) / max(wi.z, wo.z);
    return prgb(o + OREN_NAYAR_ALBEDO) * INV_PI * (a + b * t);
}
