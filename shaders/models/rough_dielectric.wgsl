// Rough dielectric (bv_core::models::rough_dielectric): Walter et al. 2007,
// eq. 20 (reflection) and eq. 21 (transmission) with the exact dielectric
// Fresnel term, GGX or Beckmann D and Smith G (separable, or height
// correlated: 1/(1 + Λi + Λo) in reflection, B(1 + Λi, 1 + Λo) in
// transmission). Either direction may be below the surface; eta is the
// index below over the index above.
#define_import_path bv::models::rough_dielectric

#import bv::params::{pf, prgb, pu}
#import bv::sampling_lobe::{Lobe, ggx_lobe}
#import bv::frame::log1p
#import bv::fresnel::dielectric
#import bv::microfacet::{ggx_d, beckmann_d, ggx_lambda, beckmann_lambda}
#import bv::layout::{ROUGH_DIELECTRIC_DISTRIBUTION, ROUGH_DIELECTRIC_DISTRIBUTION_BECKMANN, ROUGH_DIELECTRIC_ALPHA_X, ROUGH_DIELECTRIC_ALPHA_Y, ROUGH_DIELECTRIC_ETA, ROUGH_DIELECTRIC_GEOMETRY, ROUGH_DIELECTRIC_GEOMETRY_SMITH_CORRELATED, ROUGH_DIELECTRIC_TINT}

// Λ of a direction on either side (its mirror image above the surface).
fn lambda(beckmann: bool, w: vec3<f32>, ax: f32, ay: f32) -> f32 {
    let u = vec3<f32>(w.x, w.y, abs(w.z));
    if (beckmann) {
        return beckmann_lambda(u, ax, ay);
    }
    return ggx_lambda(u, ax, ay);
}

// Lanczos' series for Γ (g = 5, Numerical Recipes' gammln), as
// bv_core's `lanczos_ser`.
fn lanczos_ser(x: f32) -> f32 {
    var s = 1.000000000190015;
    s += 76.18009172947146 / (x + 1.0);
    s += -86.50532032941677 / (x + 2.0);
    s += 24.01409824083091 / (x + 3.0);
    s += -1.231739572450155 / (x + 4.0);
    s += 0.1208650973866179e-2 / (x + 5.0);
    s += -0.5395239384953e-5 / (x + 6.0);
    return s;
}

// B(x, y) for x, y ≥ 1 without cancellation (bv_core's `beta_lanes`).
fn beta(x: f32, y: f32) -> f32 {
    if (!(x < 3.0e38) || !(y < 3.0e38)) {
        return 0.0;
    }
    let s = x + y;
    let t = -(x + 0.5) * log1p(y / (x + 5.5)) - (y + 0.5) * log1p(x / (y + 5.5))
        + 0.5 * log(s + 5.5) - 5.5;
    let r = lanczos_ser(x) * lanczos_ser(y) / lanczos_ser(s) * (s / x) / y * 2.5066282746310005;
    return exp(t) * r;
}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let zi = wi.z;
    let zo = wo.z;
    if (zi == 0.0 || zo == 0.0) {
        return vec3<f32>(0.0);
    }
    let eta = pf(o + ROUGH_DIELECTRIC_ETA);
    let ax = pf(o + ROUGH_DIELECTRIC_ALPHA_X);
    let ay = pf(o + ROUGH_DIELECTRIC_ALPHA_Y);
    let beckmann = pu(o + ROUGH_DIELECTRIC_DISTRIBUTION) == ROUGH_DIELECTRIC_DISTRIBUTION_BECKMANN;
    let correlated = pu(o + ROUGH_DIELECTRIC_GEOMETRY) == ROUGH_DIELECTRIC_GEOMETRY_SMITH_CORRELATED;
    let trans = (zi > 0.0) != (zo > 0.0);
    let ei = select(eta, 1.0, zi > 0.0);
    let eo = select(eta, 1.0, zo > 0.0);
    // Eq. 13 / eq. 16, turned towards +z.
    var hu = wi + wo;
    if (trans) {
        hu = ei * wi + eo * wo;
    }
    let l2 = dot(hu, hu);
    if (!(l2 > 1e-30) || !(l2 < 3.0e38)) {
        return vec3<f32>(0.0);
    }
    var h = hu / sqrt(l2);
    if (h.z < 0.0) {
        h = -h;
    }
    let ci = dot(wi, h);
    let co = dot(wo, h);
    if (h.z <= 0.0 || ci * zi <= 0.0 || co * zo <= 0.0) {
        return vec3<f32>(0.0);
    }
    var d = ggx_d(h, ax, ay);
    if (beckmann) {
        d = beckmann_d(h, ax, ay);
    }
    let li = lambda(beckmann, wi, ax, ay);
    let lo = lambda(beckmann, wo, ax, ay);
    var g = 1.0 / ((1.0 + li) * (1.0 + lo));
    if (correlated) {
        if (trans) {
            g = beta(1.0 + li, 1.0 + lo);
        } else {
            g = 1.0 / (1.0 + li + lo);
        }
    }
    let f = dielectric(ci, eta);
    let zz = abs(zi * zo);
    var v = f * d * g / (4.0 * zz);
    if (trans) {
        // (ηi wi·h + ηo wo·h)² = |ηi wi + ηo wo|².
        v = abs(ci * co) * eo * eo * (1.0 - f) * d * g / (zz * l2);
    }
    if (!(v >= 0.0) || !(v < 3.0e38)) {
        return vec3<f32>(0.0);
    }
    return v * prgb(o + ROUGH_DIELECTRIC_TINT);
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe): GGX
// visible normals reflected about h at the model's roughness, the reflected
// lobe's shape (the transmitted light of the environment below is not
// gathered by that renderer), with the least cosine share.
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    return ggx_lobe(0.1, pf(o + ROUGH_DIELECTRIC_ALPHA_X), pf(o + ROUGH_DIELECTRIC_ALPHA_Y));
}
