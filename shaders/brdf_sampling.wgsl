// Importance sampling of the models for the environment renderer.
//
// Every model is sampled with a mixture of (a) cosine-weighted directions and
// (b) the glossy proxy lobe its own module declares (`sampling_lobe`, see
// bv::sampling_lobe; models without one are sampled by the cosine alone),
// reached through the generated dispatch (bv::dispatch::lobe_of).
// A mix picks a component in proportion to its weight. `pdf` is the exact
// solid-angle density of what `sample` draws, so multiple importance sampling
// stays unbiased whatever the match between lobe and model (the sampling
// test checks E[g/pdf] for every model). The cosine part keeps at least 10 %
// so that no direction above the horizon has zero density.
#define_import_path bv::brdf_sampling

#import bv::params::{pf, prgb, pu}
#import bv::layout as L
#import bv::sampling_lobe::{LOBE_NONE, LOBE_POWER, LOBE_GGX}
#import bv::dispatch::lobe_of
#import bv::sampling::{cosine_hemisphere, cosine_hemisphere_pdf, power_cosine, power_cosine_pdf, sample_ggx_vndf, ggx_vndf_pdf}

// Draws wi for a (non-mix) model; u in [0, 1)³. Returns (0, 0, 0) when the
// drawn direction is below the horizon (counted as a zero-valued sample).
fn sample_leaf(model: u32, o: u32, wo: vec3<f32>, u: vec3<f32>) -> vec3<f32> {
    let lobe = lobe_of(model, o, wo);
    if (u.z < lobe.p_cos || lobe.kind == LOBE_NONE) {
        return cosine_hemisphere(u.xy);
    }
    var wi: vec3<f32>;
    if (lobe.kind == LOBE_POWER) {
        wi = power_cosine(lobe.axis, lobe.e, u.xy);
    } else {
        let h = sample_ggx_vndf(wo, lobe.ax, lobe.ay, u.xy);
        wi = 2.0 * dot(wo, h) * h - wo;
    }
    if (wi.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    return normalize(wi);
}

// Solid-angle density of sample_leaf at wi.
fn pdf_leaf(model: u32, o: u32, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (wi.z <= 0.0) {
        return 0.0;
    }
    let lobe = lobe_of(model, o, wo);
    var p = lobe.p_cos * cosine_hemisphere_pdf(wi);
    if (lobe.kind == LOBE_POWER) {
        p += (1.0 - lobe.p_cos) * power_cosine_pdf(lobe.axis, lobe.e, wi);
    } else if (lobe.kind == LOBE_GGX) {
        let v = wi + wo;
        let l2 = dot(v, v);
        if (l2 > 1e-24) {
            let h = v / sqrt(l2);
            let oh = dot(wo, h);
            if (oh > 0.0) {
                // dω_h/dω_i = 1/(4 wo·h) (Walter et al. 2007, eq. 14).
                p += (1.0 - lobe.p_cos) * ggx_vndf_pdf(wo, h, lobe.ax, lobe.ay) / (4.0 * oh);
            }
        }
    }
    return p;
}

// Draws wi for any model (a mix picks a component by weight with u.z).
fn sample(model: u32, o: u32, wo: vec3<f32>, u_in: vec3<f32>) -> vec3<f32> {
    if (model != L::MODEL_MIX) {
        return sample_leaf(model, o, wo, u_in);
    }
    let n = pu(o + L::MIX_COMPONENTS);
    let table = pu(o + L::MIX_COMPONENTS + 1u);
    var total = 0.0;
    for (var j = 0u; j < n; j++) {
        total += pf(table + L::COMPONENT_ENTRY_SLOTS * j);
    }
    if (n == 0u || total <= 0.0) {
        return cosine_hemisphere(u_in.xy);
    }
    var t = u_in.z * total;
    for (var j = 0u; j < n; j++) {
        let e = table + L::COMPONENT_ENTRY_SLOTS * j;
        let w = pf(e);
        if (t < w || j + 1u == n) {
            let uz = clamp(t / max(w, 1e-30), 0.0, 0.99999994);
            return sample_leaf(pu(e + 1u), pu(e + 2u), wo, vec3<f32>(u_in.xy, uz));
        }
        t -= w;
    }
    return cosine_hemisphere(u_in.xy);
}

// Density of `sample` at wi.
fn pdf(model: u32, o: u32, wo: vec3<f32>, wi: vec3<f32>) -> f32 {
    if (model != L::MODEL_MIX) {
        return pdf_leaf(model, o, wo, wi);
    }
    let n = pu(o + L::MIX_COMPONENTS);
    let table = pu(o + L::MIX_COMPONENTS + 1u);
    var total = 0.0;
    var p = 0.0;
    for (var j = 0u; j < n; j++) {
        let e = table + L::COMPONENT_ENTRY_SLOTS * j;
        let w = pf(e);
        total += w;
        p += w * pdf_leaf(pu(e + 1u), pu(e + 2u), wo, wi);
    }
    if (n == 0u || total <= 0.0) {
        return cosine_hemisphere_pdf(wi);
    }
    return p / total;
}
