// Ashikhmin & Shirley 2000, eqs. 4-5 (bv_core::models::ashikhmin_shirley).
#define_import_path bv::models::ashikhmin_shirley

#import bv::sampling_lobe::{Lobe, LOBE_NONE, mean3, p_cos_of, alpha_of_exponent, none_lobe, power_lobe, ggx_lobe}
#import bv::layout as L

#import bv::params::{pf, prgb}
#import bv::frame::{PI, pow_from_sin2}
#import bv::fresnel::schlick
#import bv::layout::{ASHIKHMIN_SHIRLEY_RD, ASHIKHMIN_SHIRLEY_RS, ASHIKHMIN_SHIRLEY_NU, ASHIKHMIN_SHIRLEY_NV}

// 1 − (1 − cosθ/2)^5, the diffuse term's per-direction factor (eq. 5).
fn diffuse_factor(c: f32) -> f32 {
    let m = 1.0 - 0.5 * c;
    let m2 = m * m;
    return 1.0 - m2 * m2 * m;
}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let rd = prgb(o + ASHIKHMIN_SHIRLEY_RD);
    let rs = prgb(o + ASHIKHMIN_SHIRLEY_RS);
    let nu = pf(o + ASHIKHMIN_SHIRLEY_NU);
    let nv = pf(o + ASHIKHMIN_SHIRLEY_NV);
    let diffuse = rd * (vec3<f32>(1.0) - rs) * (28.0 / (23.0 * PI))
        * (diffuse_factor(wi.z) * diffuse_factor(wo.z));
    let s = wi + wo;
    let l2 = dot(s, s);
    if (l2 <= 1e-24) {
        // wi = −wo at the horizon: no finite specular limit (as the Rust).
        return diffuse;
    }
    // E = (nu h.x² + nv h.y²)/(h.x² + h.y²), (nu + nv)/2 on the normal; the
    // ratio is the same for s as for h = s/|s|.
    let x2 = s.x * s.x;
    let y2 = s.y * s.y;
    let t = x2 + y2;
    var e = 0.5 * (nu + nv);
    if (t > 0.0) {
        e = (nu * x2 + nv * y2) / t;
    }
    let hz_e = pow_from_sin2(min(t / l2, 1.0), e);
    // c = h·wi = |wi + wo|/2 for unit directions.
    let c = min(0.5 * sqrt(l2), 1.0);
    let norm = sqrt((nu + 1.0) * (nv + 1.0));
    let spec = norm / (8.0 * PI) * hz_e / (c * max(wi.z, wo.z));
    return diffuse + schlick(rs, c) * spec;
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    let rs = mean3(prgb(o + L::ASHIKHMIN_SHIRLEY_RS));
    return ggx_lobe(p_cos_of(mean3(prgb(o + L::ASHIKHMIN_SHIRLEY_RD)) * (1.0 - rs), max(rs, 0.2)),
        alpha_of_exponent(pf(o + L::ASHIKHMIN_SHIRLEY_NU)), alpha_of_exponent(pf(o + L::ASHIKHMIN_SHIRLEY_NV)));
}
