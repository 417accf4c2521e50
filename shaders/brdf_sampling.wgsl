// Importance sampling of the models for the environment renderer.
//
// Every model is sampled with a mixture of (a) cosine-weighted directions and
// (b) one glossy lobe shaped from its parameters: a power-cosine lobe about
// the mirror direction (Phong family, Lafortune) or GGX visible normals
// reflected about h (half-vector models: microfacet, Ward, Ashikhmin-Shirley,
// Blinn-Phong, Disney), with a GGX roughness matched to the model's lobe width.
// A mix picks a component in proportion to its weight. `pdf` is the exact
// solid-angle density of what `sample` draws, so multiple importance sampling
// stays unbiased whatever the match between lobe and model (the sampling
// test checks E[g/pdf] for every model). The cosine part keeps at least 10 %
// so that no direction above the horizon has zero density.
#define_import_path bv::brdf_sampling

#import bv::params::{pf, prgb, pu}
#import bv::layout as L
#import bv::frame::reflect_n
#import bv::sampling::{cosine_hemisphere, cosine_hemisphere_pdf, power_cosine, power_cosine_pdf, sample_ggx_vndf, ggx_vndf_pdf}

const LOBE_NONE: u32 = 0u;
const LOBE_POWER: u32 = 1u;
const LOBE_GGX: u32 = 2u;

// The sampling lobe of one (non-mix) model seen from wo.
struct Lobe {
    kind: u32,
    // Probability of the cosine part.
    p_cos: f32,
    // LOBE_POWER: axis and exponent; LOBE_GGX: roughness (ax, ay).
    axis: vec3<f32>,
    e: f32,
    ax: f32,
    ay: f32,
}

fn mean3(c: vec3<f32>) -> f32 {
    return (c.x + c.y + c.z) / 3.0;
}

// Cosine probability from diffuse and glossy weights, kept in [0.1, 0.9]
// (a lobe always gets some samples: its albedo may exceed these estimates).
fn p_cos_of(d: f32, s: f32) -> f32 {
    if (d + s <= 0.0) {
        return 0.5;
    }
    return clamp(d / (d + s), 0.1, 0.9);
}

// GGX roughness whose lobe is about as wide as a cos^e lobe (α² ≈ 2/(e + 2),
// the Beckmann-Phong correspondence of Walter et al. 2007, §5.2).
fn alpha_of_exponent(e: f32) -> f32 {
    return clamp(sqrt(2.0 / (e + 2.0)), 0.001, 1.0);
}

fn power_lobe(p: f32, axis: vec3<f32>, e: f32) -> Lobe {
    return Lobe(LOBE_POWER, p, axis, e, 0.0, 0.0);
}

fn ggx_lobe(p: f32, ax: f32, ay: f32) -> Lobe {
    return Lobe(LOBE_GGX, p, vec3<f32>(0.0, 0.0, 1.0), 0.0, clamp(ax, 0.001, 1.0), clamp(ay, 0.001, 1.0));
}

fn lobe_of(model: u32, o: u32, wo: vec3<f32>) -> Lobe {
    let none = Lobe(LOBE_NONE, 1.0, vec3<f32>(0.0, 0.0, 1.0), 0.0, 0.0, 0.0);
    switch model {
        case L::MODEL_PHONG: {
            return power_lobe(p_cos_of(3.14159 * mean3(prgb(o + L::PHONG_KD)), mean3(prgb(o + L::PHONG_KS))),
                reflect_n(wo), pf(o + L::PHONG_E));
        }
        case L::MODEL_MODIFIED_PHONG: {
            return power_lobe(p_cos_of(mean3(prgb(o + L::MODIFIED_PHONG_KD)), mean3(prgb(o + L::MODIFIED_PHONG_KS))),
                reflect_n(wo), pf(o + L::MODIFIED_PHONG_E));
        }
        case L::MODEL_BLINN_PHONG: {
            let a = alpha_of_exponent(pf(o + L::BLINN_PHONG_E));
            return ggx_lobe(p_cos_of(3.14159 * mean3(prgb(o + L::BLINN_PHONG_KD)), mean3(prgb(o + L::BLINN_PHONG_KS))), a, a);
        }
        case L::MODEL_WARD: {
            return ggx_lobe(p_cos_of(mean3(prgb(o + L::WARD_KD)), mean3(prgb(o + L::WARD_KS))),
                pf(o + L::WARD_ALPHA_X), pf(o + L::WARD_ALPHA_Y));
        }
        case L::MODEL_ASHIKHMIN_SHIRLEY: {
            let rs = mean3(prgb(o + L::ASHIKHMIN_SHIRLEY_RS));
            return ggx_lobe(p_cos_of(mean3(prgb(o + L::ASHIKHMIN_SHIRLEY_RD)) * (1.0 - rs), max(rs, 0.2)),
                alpha_of_exponent(pf(o + L::ASHIKHMIN_SHIRLEY_NU)), alpha_of_exponent(pf(o + L::ASHIKHMIN_SHIRLEY_NV)));
        }
        case L::MODEL_COOK_TORRANCE: {
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
        case L::MODEL_DISNEY: {
            let aspect = sqrt(1.0 - 0.9 * pf(o + L::DISNEY_ANISOTROPIC));
            let r = pf(o + L::DISNEY_ROUGHNESS);
            let d = (1.0 - pf(o + L::DISNEY_METALLIC)) * mean3(prgb(o + L::DISNEY_BASE_COLOR));
            return ggx_lobe(p_cos_of(d, 1.0), max(r * r / aspect, 0.001), max(r * r * aspect, 0.001));
        }
        case L::MODEL_LAFORTUNE: {
            // The lobe of largest weight, about its axis C wo.
            let count = min(pu(o + L::LAFORTUNE_LOBES), L::LAFORTUNE_LOBES_MAX);
            var best = 0.0;
            var lobe = none;
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
        default: {
            return none;
        }
    }
}

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
