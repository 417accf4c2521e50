// Coated surface (bv_core::models::coated): Weidlich & Wilkie 2007 §4,
// f = f_coat(wi, wo) + (1 − F(θi)) (1 − F(θo)) / η² · e^(−σa d (1/cosθi' + 1/cosθo')) · f_base(wi', wo')
// with f_coat Walter et al. 2007 eq. 20 (separable Smith), wi', wo' the
// macro refractions into the coat, f_base Lambert or a rough conductor of
// index (base_eta + i base_k)/η (Walter eq. 20), times the derived
// inter-reflection factor 1/(1 − r̄ K) per channel. Reflection only.
#define_import_path bv::models::coated

#import bv::params::{pf, prgb, pu}
#import bv::sampling_lobe::{Lobe, ggx_lobe}
#import bv::frame::INV_PI
#import bv::fresnel::{dielectric, conductor}
#import bv::microfacet::{ggx_d, beckmann_d, ggx_lambda, beckmann_lambda}
#import bv::layout::{COATED_DISTRIBUTION, COATED_DISTRIBUTION_BECKMANN, COATED_ALPHA_X, COATED_ALPHA_Y, COATED_ETA, COATED_THICKNESS, COATED_ABSORPTION, COATED_BASE, COATED_BASE_CONDUCTOR, COATED_BASE_ALBEDO, COATED_BASE_ETA, COATED_BASE_K, COATED_BASE_ALPHA, COATED_MS_R}

fn d_of(beckmann: bool, h: vec3<f32>, ax: f32, ay: f32) -> f32 {
    if (beckmann) {
        return beckmann_d(h, ax, ay);
    }
    return ggx_d(h, ax, ay);
}

fn g1_of(beckmann: bool, w: vec3<f32>, ax: f32, ay: f32) -> f32 {
    if (beckmann) {
        return 1.0 / (1.0 + beckmann_lambda(w, ax, ay));
    }
    return 1.0 / (1.0 + ggx_lambda(w, ax, ay));
}

// w refracted into the coat, pointing up: (wx/η, wy/η, cosθ').
fn inside(w: vec3<f32>, eta: f32) -> vec3<f32> {
    let s = 1.0 / eta;
    let z = sqrt(max(1.0 - s * s * (1.0 - w.z * w.z), 0.0));
    return vec3<f32>(w.x * s, w.y * s, z);
}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let eta = pf(o + COATED_ETA);
    let ax = pf(o + COATED_ALPHA_X);
    let ay = pf(o + COATED_ALPHA_Y);
    let beckmann = pu(o + COATED_DISTRIBUTION) == COATED_DISTRIBUTION_BECKMANN;
    var v = vec3<f32>(0.0);
    // The coat's reflection (Walter eq. 20).
    let hu = wi + wo;
    let l2 = dot(hu, hu);
    if (l2 > 1e-30) {
        let h = hu / sqrt(l2);
        let ci = dot(wi, h);
        if (h.z > 0.0 && ci > 0.0 && dot(wo, h) > 0.0) {
            let g = g1_of(beckmann, wi, ax, ay) * g1_of(beckmann, wo, ax, ay);
            let c = dielectric(ci, eta) * d_of(beckmann, h, ax, ay) * g / (4.0 * wi.z * wo.z);
            if (c >= 0.0 && c < 3.0e38) {
                v = vec3<f32>(c);
            }
        }
    }
    // The base through the coat.
    let ti = inside(wi, eta);
    let to = inside(wo, eta);
    if (ti.z <= 0.0 || to.z <= 0.0) {
        return v;
    }
    let trans = (1.0 - dielectric(wi.z, eta)) * (1.0 - dielectric(wo.z, eta)) / (eta * eta);
    let path = 1.0 / ti.z + 1.0 / to.z;
    let absorb = exp(-prgb(o + COATED_ABSORPTION) * pf(o + COATED_THICKNESS) * path);
    var base = vec3<f32>(0.0);
    if (pu(o + COATED_BASE) == COATED_BASE_CONDUCTOR) {
        let hb = ti + to;
        let lb = dot(hb, hb);
        if (lb > 1e-30) {
            let h = hb / sqrt(lb);
            let c = dot(ti, h);
            if (c > 0.0 && dot(to, h) > 0.0) {
                let a = pf(o + COATED_BASE_ALPHA);
                let s = d_of(beckmann, h, a, a) * g1_of(beckmann, ti, a, a)
                    * g1_of(beckmann, to, a, a) / (4.0 * ti.z * to.z);
                let e = prgb(o + COATED_BASE_ETA) / eta;
                let k = prgb(o + COATED_BASE_K) / eta;
                base = vec3<f32>(conductor(c, e.x, k.x), conductor(c, e.y, k.y),
                    conductor(c, e.z, k.z)) * s;
            }
        }
    } else {
        base = prgb(o + COATED_BASE_ALBEDO) * INV_PI;
    }
    // The internal inter-reflections 1/(1 − r̄ K), a derived slot per channel.
    let t = base * absorb * prgb(o + COATED_MS_R) * trans;
    if (all(t >= vec3<f32>(0.0)) && all(t < vec3<f32>(3.0e38))) {
        v += t;
    }
    return v;
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe): GGX
// visible normals at the coat's roughness. Over a Lambert base half the
// draws are cosine-weighted (the body), half go to the coat's highlight,
// which is faint in energy (F0 ≈ 4 %) but holds the studio's lamps; over a
// conductor base the light that matters left through the coat from the
// base's lobe, which refraction widens by about η, so the lobe is the wider
// of the two and the cosine keeps its least share.
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    let ax = pf(o + COATED_ALPHA_X);
    let ay = pf(o + COATED_ALPHA_Y);
    if (pu(o + COATED_BASE) == COATED_BASE_CONDUCTOR) {
        let b = min(pf(o + COATED_BASE_ALPHA) * pf(o + COATED_ETA), 1.0);
        return ggx_lobe(0.1, max(ax, b), max(ay, b));
    }
    return ggx_lobe(0.5, ax, ay);
}
