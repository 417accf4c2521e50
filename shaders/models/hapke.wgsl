// Hapke 1981 without macroscopic roughness (bv_core::models::hapke).
#define_import_path bv::models::hapke

#import bv::params::pf
#import bv::frame::PI
#import bv::layout::{HAPKE_W, HAPKE_B0, HAPKE_H, HAPKE_G}

// Henyey-Greenstein in Hapke's normalisation, denominator written without
// cancellation exactly as bv_core::models::hapke::henyey_greenstein.
fn henyey_greenstein(g: f32, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let num = (1.0 - g) * (1.0 + g);
    if (num <= 0.0) {
        return 0.0;
    }
    var a: f32;
    if (g <= 0.0) {
        let d = wi - wo;
        a = (1.0 + g) - g * 0.5 * dot(d, d);
    } else {
        let s = wi + wo;
        a = (1.0 - g) + g * 0.5 * dot(s, s);
    }
    let c = cross(wi, wo);
    let den = a * a + g * g * dot(c, c);
    return num / (den * sqrt(den));
}

// H(x) − 1 for Hapke's H(x) = (1 + 2x)/(1 + 2xγ): 2x(1 − γ)/(1 + 2xγ), so that
// H(μi)H(μo) − 1 = δi + δo + δi δo needs no subtraction of nearly equal
// numbers (in f32, H H − 1 at grazing angles would keep two digits).
// `one_minus_gamma` = 1 − √(1 − w) = w/(1 + √(1 − w)).
fn h_minus_one(x: f32, gamma: f32, one_minus_gamma: f32) -> f32 {
    return 2.0 * x * one_minus_gamma / (1.0 + 2.0 * x * gamma);
}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let w = pf(o + HAPKE_W);
    let b0 = pf(o + HAPKE_B0);
    let width = pf(o + HAPKE_H);
    let g = pf(o + HAPKE_G);
    let gamma = sqrt(max(1.0 - w, 0.0));
    let one_minus_gamma = w / (1.0 + gamma);
    let p = henyey_greenstein(g, wi, wo);
    // Opposition surge b0 h |wi+wo| / (h |wi+wo| + |wi−wo|).
    let hs = width * length(wi + wo);
    let b = b0 * hs / (hs + length(wi - wo));
    let di = h_minus_one(wi.z, gamma, one_minus_gamma);
    let dl = h_minus_one(wo.z, gamma, one_minus_gamma);
    let multiple = di + dl + di * dl;
    let f = w / (4.0 * PI) / (wi.z + wo.z) * ((1.0 + b) * p + max(multiple, 0.0));
    return vec3<f32>(f);
}
