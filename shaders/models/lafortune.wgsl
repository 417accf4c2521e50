// Lafortune et al. 1997, eq. 4 (bv_core::models::lafortune):
// kd/π + Σ ks_j (n_j+2)/(2π) max(0, cx wi.x wo.x + cy wi.y wo.y + cz wi.z wo.z)^n_j.
#define_import_path bv::models::lafortune

#import bv::sampling_lobe::{Lobe, LOBE_NONE, mean3, p_cos_of, alpha_of_exponent, none_lobe, power_lobe, ggx_lobe}
#import bv::layout as L

#import bv::params::{pf, prgb, pu}
#import bv::frame::{PI, INV_PI, log1p}
#import bv::layout::{LAFORTUNE_KD, LAFORTUNE_LOBES, LAFORTUNE_LOBES_ITEMS, LAFORTUNE_LOBES_STRIDE, LAFORTUNE_LOBES_MAX, LAFORTUNE_LOBES_CX, LAFORTUNE_LOBES_CY, LAFORTUNE_LOBES_CZ, LAFORTUNE_LOBES_N, LAFORTUNE_LOBES_KS}

// max(0, base)^n with base = v·wo, v = C wi. Near the peak 1 − base is taken
// as (1 − |v|) + |v| |v̂ − wo|²/2 with 1 − |v| = Σ (1 − c_k²) wi_k² / (1 + |v|)
// (|wi| = 1, |c_k| ≤ 1): no cancellation, so sharp lobes keep f32 accuracy.
fn lobe(c: vec3<f32>, n: f32, wi: vec3<f32>, wo: vec3<f32>) -> f32 {
    let v = c * wi;
    let base = dot(v, wo);
    if (base <= 0.0) {
        return 0.0;
    }
    if (n == 0.0) {
        return 1.0;
    }
    let lv = length(v);
    let w2 = wi * wi;
    let one_minus_lv = dot(vec3<f32>(1.0) - c * c, w2) / (1.0 + lv);
    let d = v / lv - wo;
    let t = clamp(one_minus_lv + lv * 0.5 * dot(d, d), 0.0, 1.0);
    return exp(n * log1p(-t));
}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    var f = prgb(o + LAFORTUNE_KD) * INV_PI;
    let count = min(pu(o + LAFORTUNE_LOBES), LAFORTUNE_LOBES_MAX);
    for (var j = 0u; j < count; j++) {
        let l = o + LAFORTUNE_LOBES_ITEMS + j * LAFORTUNE_LOBES_STRIDE;
        let c = vec3<f32>(pf(l + LAFORTUNE_LOBES_CX), pf(l + LAFORTUNE_LOBES_CY), pf(l + LAFORTUNE_LOBES_CZ));
        let n = pf(l + LAFORTUNE_LOBES_N);
        f += prgb(l + LAFORTUNE_LOBES_KS) * ((n + 2.0) / (2.0 * PI) * lobe(c, n, wi, wo));
    }
    return f;
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    // The lobe of largest weight, about its axis C wo.
    let count = min(pu(o + L::LAFORTUNE_LOBES), L::LAFORTUNE_LOBES_MAX);
    var best = 0.0;
    var lobe = none_lobe();
    for (var j = 0u; j < count; j++) {
        let l = o + L::LAFORTUNE_LOBES_ITEMS + j * L::LAFORTUNE_LOBES_STRIDE;
        let c = vec3<f32>(pf(l + L::LAFORTUNE_LOBES_CX), pf(l + L::LAFORTUNE_LOBES_CY), pf(l + L::LAFORTUNE_LOBES_CZ));
        let v = c * wo;
        let w = mean3(prgb(l + L::LAFORTUNE_LOBES_KS)) * length(v);
        if (w > best && length(v) > 0.0) {
            best = w;
            lobe = power_lobe(0.0, normalize(v), pf(l + L::LAFORTUNE_LOBES_N));
        }
    }
    lobe.p_cos = p_cos_of(mean3(prgb(o + L::LAFORTUNE_KD)), best);
    if (lobe.kind == LOBE_NONE) {
        lobe.p_cos = 1.0;
    }
    return lobe;
}
