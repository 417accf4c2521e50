// Rough dielectric (bv_core::models::rough_dielectric): Walter et al. 2007,
// eq. 20 (reflection) and eq. 21 (transmission) with the exact dielectric
// Fresnel term, GGX or Beckmann D and Smith G (separable, or height
// correlated: 1/(1 + Λi + Λo) in reflection, B(1 + Λi, 1 + Λo) in
// transmission). Either direction may be below the surface; eta is the
// index below over the index above.
#define_import_path bv::models::rough_dielectric

#import bv::params::{pf, prgb, pu}
#import bv::sampling_lobe::{Lobe, ggx_lobe, SphereSample, no_sphere_sample}
#import bv::sampling::sample_ggx_vndf
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

// Draws wi on the whole sphere for the environment renderer's paths through
// the object (Walter et al. 2007, §5.3, with Heitz 2018's visible normals):
// a normal m visible from wo (GGX at the model's roughness, also for a
// Beckmann model), then reflection with probability F(wo·m) and refraction
// otherwise. A draw that lands on the wrong side (reflected through the
// surface, or refracted back out) is no sample: eval would read that pair
// as the other lobe, which the other branch's draws count (as pbrt-v4's
// DielectricBxDF does). The weight f |cos θi| / pdf is taken in closed form,
// the terms of eq. 20/21 over those of the density (eq. 14/17 with the
// visible-normal pdf G1(wo) ⟨wo·m⟩ D_GGX(m) / cos θo):
//   reflection  (D(m) / D_GGX(m)) G(wi, wo) / G1_GGX(wo),
//   refraction  (ηo/ηi)² (D(m) / D_GGX(m)) G(wi, wo) / G1_GGX(wo),
// which is what eval / pdf equals at the same m, without recomputing the
// half vector from wi and wo in f32 (near the critical angle it cancels
// badly, and a 0.05-rough D turns that into fireflies).
fn sample_sphere(o: u32, wo: vec3<f32>, u: vec3<f32>) -> SphereSample {
    let eta = pf(o + ROUGH_DIELECTRIC_ETA);
    let ax = pf(o + ROUGH_DIELECTRIC_ALPHA_X);
    let ay = pf(o + ROUGH_DIELECTRIC_ALPHA_Y);
    let beckmann = pu(o + ROUGH_DIELECTRIC_DISTRIBUTION) == ROUGH_DIELECTRIC_DISTRIBUTION_BECKMANN;
    let correlated = pu(o + ROUGH_DIELECTRIC_GEOMETRY) == ROUGH_DIELECTRIC_GEOMETRY_SMITH_CORRELATED;
    if (wo.z == 0.0) {
        return no_sphere_sample();
    }
    // Work with the viewer above: flip both sides when wo is below.
    let above = wo.z > 0.0;
    let sgn = select(-1.0, 1.0, above);
    let w = wo * sgn;
    let m = sample_ggx_vndf(w, ax, ay, u.xy);
    let wm = dot(w, m);
    if (wm <= 0.0 || m.z <= 0.0) {
        return no_sphere_sample();
    }
    // Index on wo's side over the other's; F from wo's side.
    let eo = select(eta, 1.0, above);
    let et = select(1.0, eta, above);
    let rel = eo / et;
    let sin2_t = rel * rel * max(1.0 - wm * wm, 0.0);
    var f = 1.0;
    if (sin2_t < 1.0) {
        let cos_t = sqrt(1.0 - sin2_t);
        let r_par = (et * wm - eo * cos_t) / (et * wm + eo * cos_t);
        let r_perp = (eo * wm - et * cos_t) / (eo * wm + et * cos_t);
        f = 0.5 * (r_par * r_par + r_perp * r_perp);
    }
    var wi_up: vec3<f32>;
    var scale = 1.0;
    let reflects = u.z < f;
    if (reflects) {
        wi_up = 2.0 * wm * m - w;
        if (wi_up.z <= 0.0) {
            return no_sphere_sample();
        }
    } else {
        let cos_t = sqrt(max(1.0 - sin2_t, 0.0));
        wi_up = normalize(-rel * w + (rel * wm - cos_t) * m);
        if (wi_up.z >= 0.0) {
            return no_sphere_sample();
        }
        scale = rel * rel;
    }
    var dr = 1.0;
    if (beckmann) {
        dr = beckmann_d(m, ax, ay) / ggx_d(m, ax, ay);
    }
    let li = lambda(beckmann, wi_up, ax, ay);
    let lo = lambda(beckmann, w, ax, ay);
    var g = 1.0 / ((1.0 + li) * (1.0 + lo));
    if (correlated) {
        if (reflects) {
            g = 1.0 / (1.0 + li + lo);
        } else {
            g = beta(1.0 + li, 1.0 + lo);
        }
    }
    let g1 = 1.0 / (1.0 + ggx_lambda(w, ax, ay));
    var s: SphereSample;
    s.wi = wi_up * sgn;
    s.weight = scale * dr * g / g1 * prgb(o + ROUGH_DIELECTRIC_TINT);
    if (!all(s.weight >= vec3<f32>(0.0)) || !all(s.weight < vec3<f32>(3.0e38))) {
        return no_sphere_sample();
    }
    return s;
}
