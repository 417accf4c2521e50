// Disney principled BRDF, Burley 2012, with bv's fixed choices (bv_core::models::disney).
#define_import_path bv::models::disney

#import bv::sampling_lobe::{Lobe, LOBE_NONE, mean3, p_cos_of, alpha_of_exponent, none_lobe, power_lobe, ggx_lobe}
#import bv::layout as L

#import bv::params::{pf, prgb}
#import bv::frame::{PI, INV_PI}
#import bv::fresnel::schlick_weight
#import bv::microfacet::{ggx_d, ggx_lambda}
#import bv::layout::{DISNEY_BASE_COLOR, DISNEY_METALLIC, DISNEY_SUBSURFACE, DISNEY_SPECULAR, DISNEY_SPECULAR_TINT, DISNEY_ROUGHNESS, DISNEY_ANISOTROPIC, DISNEY_SHEEN, DISNEY_SHEEN_TINT, DISNEY_CLEARCOAT, DISNEY_CLEARCOAT_GLOSS}

const CLEARCOAT_G_ALPHA: f32 = 0.25;

// GTR1 (Berry) D, (α² − 1)/(π ln α² (1 + (α² − 1) cos²θh)); the bracket is
// written sin²θh + α² cos²θh so that it keeps its digits near the normal.
fn gtr1(h: vec3<f32>, alpha: f32) -> f32 {
    if (alpha >= 1.0) {
        return INV_PI;
    }
    let a2 = alpha * alpha;
    let s2 = h.x * h.x + h.y * h.y;
    let t = s2 + a2 * h.z * h.z;
    return (a2 - 1.0) / (PI * log(a2) * t);
}

// The anisotropic GGX roughness (αx, αy) of `roughness` and `anisotropic`.
fn alphas(o: u32) -> vec2<f32> {
    let aspect = sqrt(1.0 - 0.9 * pf(o + DISNEY_ANISOTROPIC));
    let r = pf(o + DISNEY_ROUGHNESS);
    let r2 = r * r;
    return vec2<f32>(max(r2 / aspect, 0.001), max(r2 * aspect, 0.001));
}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let nl = wi.z;
    let nv = wo.z;
    if (nl <= 0.0 || nv <= 0.0) {
        return vec3<f32>(0.0);
    }
    let v = wi + wo;
    let l2 = dot(v, v);
    if (l2 <= 1e-24) {
        return vec3<f32>(0.0);
    }
    let h = v / sqrt(l2);
    let base = prgb(o + DISNEY_BASE_COLOR);
    let metallic = pf(o + DISNEY_METALLIC);
    let roughness = pf(o + DISNEY_ROUGHNESS);
    let cdlum = 0.3 * base.x + 0.6 * base.y + 0.1 * base.z;
    var ctint = vec3<f32>(1.0);
    if (cdlum > 0.0) {
        ctint = base / cdlum;
    }
    let cspec0 = mix(pf(o + DISNEY_SPECULAR) * 0.08 * mix(vec3<f32>(1.0), ctint, pf(o + DISNEY_SPECULAR_TINT)), base, metallic);
    let csheen = mix(vec3<f32>(1.0), ctint, pf(o + DISNEY_SHEEN_TINT));

    let lh = clamp(dot(wi, h), 0.0, 1.0);
    let fl = schlick_weight(nl);
    let fv = schlick_weight(nv);
    let fh = schlick_weight(lh);
    let fd90 = 0.5 + 2.0 * lh * lh * roughness;
    let fd = mix(1.0, fd90, fl) * mix(1.0, fd90, fv);
    let fss90 = lh * lh * roughness;
    let fss = mix(1.0, fss90, fl) * mix(1.0, fss90, fv);
    let ss = 1.25 * (fss * (1.0 / (nl + nv) - 0.5) + 0.5);
    let fsheen = fh * pf(o + DISNEY_SHEEN) * csheen;
    let diffuse = (INV_PI * mix(fd, ss, pf(o + DISNEY_SUBSURFACE)) * base + fsheen) * (1.0 - metallic);

    let a = alphas(o);
    let ds = ggx_d(h, a.x, a.y);
    let fs = mix(cspec0, vec3<f32>(1.0), fh);
    let gs = 1.0 / ((1.0 + ggx_lambda(wi, a.x, a.y)) * (1.0 + ggx_lambda(wo, a.x, a.y)));
    let spec = fs * (ds * gs / (4.0 * nl * nv));

    var coat = 0.0;
    let clearcoat = pf(o + DISNEY_CLEARCOAT);
    if (clearcoat > 0.0) {
        let dr = gtr1(h, mix(0.1, 0.001, pf(o + DISNEY_CLEARCOAT_GLOSS)));
        let fr = mix(0.04, 1.0, fh);
        let ca = CLEARCOAT_G_ALPHA;
        let gr = 1.0 / ((1.0 + ggx_lambda(wi, ca, ca)) * (1.0 + ggx_lambda(wo, ca, ca)));
        coat = 0.25 * clearcoat * dr * fr * gr / (4.0 * nl * nv);
    }
    let f = diffuse + spec + vec3<f32>(coat);
    if (!(max(f.x, max(f.y, f.z)) <= 3.0e38) || !(min(f.x, min(f.y, f.z)) >= -3.0e38)) {
        return vec3<f32>(0.0);
    }
    return f;
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    let aspect = sqrt(1.0 - 0.9 * pf(o + L::DISNEY_ANISOTROPIC));
    let r = pf(o + L::DISNEY_ROUGHNESS);
    let d = (1.0 - pf(o + L::DISNEY_METALLIC)) * mean3(prgb(o + L::DISNEY_BASE_COLOR));
    return ggx_lobe(p_cos_of(d, 1.0), max(r * r / aspect, 0.001), max(r * r * aspect, 0.001));
}
