// Cook-Torrance (bv_core::models::cook_torrance):
// kd/π + ks F(wi·h) D(h) G(wi, wo) / (4 cosθi cosθo), D, G, F by choice.
// Derived slots after the block (declared and computed with the model in
// bv_core::models::cook_torrance): Blinn's normalisation constants for
// alpha_x and alpha2; Kulla & Conty's (2017) multiple-scattering colour
// ks-free F_ms / (π (1 − E_avg)) (all 0 with multiscatter = none) and the
// table of the loss 1 − E of the directional albedo E of
// bv_core::multiscatter (formed in f64: an f32 E near 1 would lose the
// loss's digits; MS_TABLE_LEN entries
// uniform in √μ, interpolated linearly in μ as bv_core::multiscatter::lookup);
// for an anisotropic lobe, the rows of E's harmonics in cos 2kφ (their loss
// −c_k, MS_TABLE_LEN entries each) in the shared table buffer (declared by
// the MERL port) at 4 × COOK_TORRANCE_MS_HARMONICS, and how many rows
// (COOK_TORRANCE_MS_N_HARMONICS, 0 for an isotropic lobe).
#define_import_path bv::models::cook_torrance

#import bv::sampling_lobe::{Lobe, LOBE_NONE, mean3, p_cos_of, alpha_of_exponent, none_lobe, power_lobe, ggx_lobe}
#import bv::layout as L

#import bv::params::{pf, prgb, pu}
#import bv::models::merl::merl_data
#import bv::frame::INV_PI
#import bv::fresnel::fresnel
#import bv::microfacet::{Scale, mixture_d, mixture_g}
#import bv::layout::{COOK_TORRANCE_KD, COOK_TORRANCE_KS, COOK_TORRANCE_DISTRIBUTION, COOK_TORRANCE_ALPHA_X, COOK_TORRANCE_ALPHA_Y, COOK_TORRANCE_GEOMETRY, COOK_TORRANCE_FRESNEL, COOK_TORRANCE_ETA, COOK_TORRANCE_K, COOK_TORRANCE_F0, COOK_TORRANCE_ALPHA2, COOK_TORRANCE_WEIGHT2, COOK_TORRANCE_BLINN_NORM, COOK_TORRANCE_BLINN_NORM2, COOK_TORRANCE_MS_R, COOK_TORRANCE_MS_G, COOK_TORRANCE_MS_B, COOK_TORRANCE_MS_L0, COOK_TORRANCE_MS_HARMONICS, COOK_TORRANCE_MS_N_HARMONICS}

// bv_core::multiscatter::TABLE_LEN.
const MS_TABLE_LEN: u32 = 32u;

// The cell and weight of μ in a table (bv_core::multiscatter::lookup): the
// cell is found in √μ, the weight is linear in μ.
fn ms_cell(mu_in: f32) -> vec2<f32> {
    let mu = clamp(mu_in, 0.0, 1.0);
    let n = f32(MS_TABLE_LEN - 1u);
    let i = min(u32(floor(sqrt(mu) * n)), MS_TABLE_LEN - 2u);
    let s0 = f32(i) / n;
    let s1 = f32(i + 1u) / n;
    let t = clamp((mu - s0 * s0) / (s1 * s1 - s0 * s0), 0.0, 1.0);
    return vec2<f32>(f32(i), t);
}

// 1 − E(ω) for light from w (bv_core::multiscatter::loss_dir_f32): the
// mean's loss from the slots, plus the harmonics' rows times the Chebyshev
// polynomials T_k(cos 2φ) = cos 2kφ, never below 0.
fn ms_loss(o: u32, w: vec3<f32>) -> f32 {
    let c = ms_cell(w.z);
    let i = u32(c.x);
    let t = c.y;
    var l = pf(o + COOK_TORRANCE_MS_L0 + i) * (1.0 - t) + pf(o + COOK_TORRANCE_MS_L0 + i + 1u) * t;
    let n = pu(o + COOK_TORRANCE_MS_N_HARMONICS);
    if (n > 0u) {
        let base = 4u * pu(o + COOK_TORRANCE_MS_HARMONICS);
        let r2 = w.x * w.x + w.y * w.y;
        var c2 = 1.0;
        if (r2 > 0.0) {
            c2 = (w.x * w.x - w.y * w.y) / r2;
        }
        var t_prev = 1.0;
        var t_k = c2;
        for (var k = 0u; k < n; k++) {
            let row = base + k * MS_TABLE_LEN + i;
            l += (merl_data[row] * (1.0 - t) + merl_data[row + 1u] * t) * t_k;
            let t_next = 2.0 * c2 * t_k - t_prev;
            t_prev = t_k;
            t_k = t_next;
        }
    }
    return max(l, 0.0);
}

// Kulla–Conty's F_ms (1 − E(μi)) (1 − E(μo)) / (π (1 − E_avg)) without ks;
// 0 without multiscatter (its colour slots are 0).
fn multiple(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let c = vec3<f32>(pf(o + COOK_TORRANCE_MS_R), pf(o + COOK_TORRANCE_MS_G), pf(o + COOK_TORRANCE_MS_B));
    if (all(c == vec3<f32>(0.0))) {
        return vec3<f32>(0.0);
    }
    return c * (ms_loss(o, wi) * ms_loss(o, wo));
}

fn first_scale(o: u32) -> Scale {
    return Scale(pu(o + COOK_TORRANCE_DISTRIBUTION), pf(o + COOK_TORRANCE_ALPHA_X),
        pf(o + COOK_TORRANCE_ALPHA_Y), pf(o + COOK_TORRANCE_BLINN_NORM));
}

fn second_scale(o: u32) -> Scale {
    let a2 = pf(o + COOK_TORRANCE_ALPHA2);
    return Scale(pu(o + COOK_TORRANCE_DISTRIBUTION), a2, a2, pf(o + COOK_TORRANCE_BLINN_NORM2));
}

fn weight2(o: u32) -> f32 {
    return clamp(pf(o + COOK_TORRANCE_WEIGHT2), 0.0, 1.0);
}

// The specular factor F D G / (4 cosθi cosθo) without ks (0 where bv-core's is).
fn specular(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let v = wi + wo;
    let l2 = dot(v, v);
    if (l2 <= 1e-24) {
        return vec3<f32>(0.0);
    }
    let h = v / sqrt(l2);
    let first = first_scale(o);
    let second = second_scale(o);
    let w2 = weight2(o);
    let d = mixture_d(first, second, w2, h);
    if (d == 0.0) {
        return vec3<f32>(0.0);
    }
    let g = mixture_g(pu(o + COOK_TORRANCE_GEOMETRY), first, second, w2, wi, wo, h);
    let scalar = d * g / (4.0 * wi.z * wo.z);
    if (!(scalar <= 3.0e38)) {
        return vec3<f32>(0.0);
    }
    let f = fresnel(pu(o + COOK_TORRANCE_FRESNEL), prgb(o + COOK_TORRANCE_ETA),
        prgb(o + COOK_TORRANCE_K), prgb(o + COOK_TORRANCE_F0), dot(wi, h));
    return f * scalar;
}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    return prgb(o + COOK_TORRANCE_KD) * INV_PI
        + pf(o + COOK_TORRANCE_KS) * (specular(o, wi, wo) + multiple(o, wi, wo));
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    var ax = pf(o + L::COOK_TORRANCE_ALPHA_X);
    var ay = pf(o + L::COOK_TORRANCE_ALPHA_Y);
    if (pu(o + L::COOK_TORRANCE_DISTRIBUTION) == L::COOK_TORRANCE_DISTRIBUTION_BLINN) {
        ay = ax;
    }
    if (pf(o + L::COOK_TORRANCE_WEIGHT2) > 0.5) {
        ax = pf(o + L::COOK_TORRANCE_ALPHA2);
        ay = ax;
    }
    return ggx_lobe(p_cos_of(mean3(prgb(o + L::COOK_TORRANCE_KD)), pf(o + L::COOK_TORRANCE_KS)), ax, ay);
}
