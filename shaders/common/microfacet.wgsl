// Microfacet terms, ports of bv_core::microfacet
// in f32. Distribution indices are bv_core::microfacet::DISTRIBUTION_OPTIONS
// and GEOMETRY_OPTIONS, from the generated layout of `cook-torrance`.
#define_import_path bv::microfacet

#import bv::frame::PI
#import bv::layout::{COOK_TORRANCE_DISTRIBUTION_BECKMANN, COOK_TORRANCE_DISTRIBUTION_GGX, COOK_TORRANCE_GEOMETRY_V_GROOVE, COOK_TORRANCE_GEOMETRY_SMITH}

const SQRT_PI: f32 = 1.7724538509055160;

// One scale of a (possibly two-scale) distribution.
struct Scale {
    dist: u32,
    ax: f32,
    ay: f32,
    // Blinn's normalisation constant (computed by bv-core, packed as a derived slot).
    blinn_c: f32,
}

// α² tan²θ along w's azimuth, +∞ below the horizon.
fn alpha2_tan2(w: vec3<f32>, ax: f32, ay: f32) -> f32 {
    if (w.z <= 0.0) {
        return 3.0e38;
    }
    let num = w.x * w.x * ax * ax + w.y * w.y * ay * ay;
    return num / (w.z * w.z);
}

// Beckmann D (Walter et al. 2007, eq. 25; bv_core::microfacet::beckmann_d). exp underflows in
// f32 beyond e ≈ 87, where D is far below any value that matters.
fn beckmann_d(h: vec3<f32>, ax: f32, ay: f32) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let z2 = h.z * h.z;
    let e = (h.x * h.x / (ax * ax) + h.y * h.y / (ay * ay)) / z2;
    if (e > 85.0) {
        return 0.0;
    }
    return exp(-e) / (PI * ax * ay * z2 * z2);
}

// GGX / Trowbridge-Reitz D (bv_core::microfacet::ggx_d).
fn ggx_d(h: vec3<f32>, ax: f32, ay: f32) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let t = h.x * h.x / (ax * ax) + h.y * h.y / (ay * ay) + h.z * h.z;
    return 1.0 / (PI * ax * ay * t * t);
}

// Blinn's Gaussian in θh, c · exp(−(θh/α)²) (bv_core::microfacet::blinn_d).
fn blinn_d(h: vec3<f32>, alpha: f32, c: f32) -> f32 {
    if (h.z <= 0.0) {
        return 0.0;
    }
    let theta = atan2(sqrt(h.x * h.x + h.y * h.y), h.z);
    let e = theta / alpha;
    return c * exp(-e * e);
}

// erfc(x) with fractional error below 1.2e-7 (Numerical Recipes' Chebyshev
// fit `erfcc`, Press et al. 1992 §6.2).
fn erfc(x: f32) -> f32 {
    let z = abs(x);
    let t = 1.0 / (1.0 + 0.5 * z);
    let r = t * exp(-z * z - 1.26551223 + t * (1.00002368 + t * (0.37409196 + t * (0.09678418
        + t * (-0.18628806 + t * (0.27886807 + t * (-1.13520398 + t * (1.48851587
        + t * (-0.82215223 + t * 0.17087277)))))))));
    return select(2.0 - r, r, x >= 0.0);
}

// Beckmann's Λ(a) = (erf(a) − 1)/2 + exp(−a²)/(2a√π) (bv_core::microfacet::beckmann_lambda_a).
fn beckmann_lambda_a(a: f32) -> f32 {
    if (!(a > 0.0)) {
        return 3.0e38;
    }
    if (a > 26.0) {
        return 0.0;
    }
    let l = 0.5 * (exp(-a * a) / (a * SQRT_PI) - erfc(a));
    return max(l, 0.0);
}

fn beckmann_lambda(w: vec3<f32>, ax: f32, ay: f32) -> f32 {
    let t = alpha2_tan2(w, ax, ay);
    if (t == 0.0) {
        return 0.0;
    }
    return beckmann_lambda_a(1.0 / sqrt(t));
}

// GGX's Λ = (−1 + √(1 + α² tan²θ))/2, written without cancellation.
fn ggx_lambda(w: vec3<f32>, ax: f32, ay: f32) -> f32 {
    let t = alpha2_tan2(w, ax, ay);
    if (t >= 3.0e38) {
        return 3.0e38;
    }
    return t / (2.0 * (1.0 + sqrt(1.0 + t)));
}

// The Cook-Torrance V-groove G (bv_core::microfacet::v_groove_g).
fn v_groove_g(wi: vec3<f32>, wo: vec3<f32>, h: vec3<f32>) -> f32 {
    let oh = dot(wo, h);
    if (wi.z <= 0.0 || wo.z <= 0.0 || oh <= 0.0 || h.z <= 0.0) {
        return 0.0;
    }
    let k = 2.0 * h.z / oh;
    return min(1.0, min(k * wo.z, k * wi.z));
}

fn scale_d(s: Scale, h: vec3<f32>) -> f32 {
    if (s.dist == COOK_TORRANCE_DISTRIBUTION_BECKMANN) {
        return beckmann_d(h, s.ax, s.ay);
    }
    if (s.dist == COOK_TORRANCE_DISTRIBUTION_GGX) {
        return ggx_d(h, s.ax, s.ay);
    }
    return blinn_d(h, s.ax, s.blinn_c);
}

// Λ of one scale; Blinn uses Beckmann's Λ with α = alpha_x (Walter et al. 2007, eq. 27).
fn scale_lambda(s: Scale, w: vec3<f32>) -> f32 {
    if (s.dist == COOK_TORRANCE_DISTRIBUTION_GGX) {
        return ggx_lambda(w, s.ax, s.ay);
    }
    if (s.dist == COOK_TORRANCE_DISTRIBUTION_BECKMANN) {
        return beckmann_lambda(w, s.ax, s.ay);
    }
    return beckmann_lambda(w, s.ax, s.ax);
}

// D of the two-scale mixture (1 − w2) D1 + w2 D2 (bv_core::microfacet::Microfacet::d).
fn mixture_d(first: Scale, second: Scale, w2: f32, h: vec3<f32>) -> f32 {
    if (w2 <= 0.0) {
        return scale_d(first, h);
    }
    return (1.0 - w2) * scale_d(first, h) + w2 * scale_d(second, h);
}

fn mixture_lambda(first: Scale, second: Scale, w2: f32, w: vec3<f32>) -> f32 {
    if (w2 <= 0.0) {
        return scale_lambda(first, w);
    }
    if (w2 >= 1.0) {
        return scale_lambda(second, w);
    }
    return (1.0 - w2) * scale_lambda(first, w) + w2 * scale_lambda(second, w);
}

// G of the chosen geometry term (bv_core::microfacet::Microfacet::g).
fn mixture_g(geometry: u32, first: Scale, second: Scale, w2: f32, wi: vec3<f32>, wo: vec3<f32>, h: vec3<f32>) -> f32 {
    if (geometry == COOK_TORRANCE_GEOMETRY_V_GROOVE) {
        return v_groove_g(wi, wo, h);
    }
    let li = mixture_lambda(first, second, w2, wi);
    let lo = mixture_lambda(first, second, w2, wo);
    if (geometry == COOK_TORRANCE_GEOMETRY_SMITH) {
        return 1.0 / ((1.0 + li) * (1.0 + lo));
    }
    return 1.0 / (1.0 + li + lo);
}
