// Warps from the unit square to directions (ports of bv_core::sampling and
// bv_core::microfacet's GGX visible-normal sampler), and a hash-based
// random source for the progressive renderers.
#define_import_path bv::sampling

#import bv::frame::{PI, INV_PI, basis}
#import bv::microfacet::{ggx_d, ggx_lambda}

// PCG hash (Jarzynski & Olano 2020, "Hash functions for GPU rendering").
fn pcg(v: u32) -> u32 {
    let state = v * 747796405u + 2891336453u;
    let word = ((state >> ((state >> 28u) + 4u)) ^ state) * 277803737u;
    return (word >> 22u) ^ word;
}

// Uniform in [0, 1) from a running state.
fn rand(state: ptr<function, u32>) -> f32 {
    *state = pcg(*state);
    return f32(*state >> 8u) * (1.0 / 16777216.0);
}

// Shirley-Chiu concentric map of the square onto the unit disc.
fn concentric_disc(u: vec2<f32>) -> vec2<f32> {
    let o = 2.0 * u - vec2<f32>(1.0);
    if (o.x == 0.0 && o.y == 0.0) {
        return vec2<f32>(0.0);
    }
    var r: f32;
    var t: f32;
    if (abs(o.x) > abs(o.y)) {
        r = o.x;
        t = PI / 4.0 * (o.y / o.x);
    } else {
        r = o.y;
        t = PI / 2.0 - PI / 4.0 * (o.x / o.y);
    }
    return r * vec2<f32>(cos(t), sin(t));
}

// Cosine-weighted hemisphere (Malley's method), density cosθ/π.
fn cosine_hemisphere(u: vec2<f32>) -> vec3<f32> {
    let d = concentric_disc(u);
    return vec3<f32>(d, sqrt(max(1.0 - dot(d, d), 0.0)));
}

fn cosine_hemisphere_pdf(w: vec3<f32>) -> f32 {
    return max(w.z, 0.0) * INV_PI;
}

// Direction about `axis` with density (e+1)/(2π) cos^e α over the axis's hemisphere.
fn power_cosine(axis: vec3<f32>, e: f32, u: vec2<f32>) -> vec3<f32> {
    let cos_a = pow(max(u.x, 1e-30), 1.0 / (e + 1.0));
    let sin_a = sqrt(max(1.0 - cos_a * cos_a, 0.0));
    let phi = 2.0 * PI * u.y;
    let tb = basis(axis);
    return normalize(tb[0] * (sin_a * cos(phi)) + tb[1] * (sin_a * sin(phi)) + axis * cos_a);
}

fn power_cosine_pdf(axis: vec3<f32>, e: f32, w: vec3<f32>) -> f32 {
    let c = dot(axis, w);
    if (c <= 0.0) {
        return 0.0;
    }
    return (e + 1.0) / (2.0 * PI) * pow(min(c, 1.0), e);
}

// GGX normal visible from w (Heitz 2018, JCGT 7(4), listing 1), w.z > 0.
fn sample_ggx_vndf(w: vec3<f32>, ax: f32, ay: f32, u: vec2<f32>) -> vec3<f32> {
    let vh = normalize(vec3<f32>(ax * w.x, ay * w.y, max(w.z, 1e-30)));
    let lensq = vh.x * vh.x + vh.y * vh.y;
    var t1 = vec3<f32>(1.0, 0.0, 0.0);
    if (lensq > 0.0) {
        t1 = vec3<f32>(-vh.y, vh.x, 0.0) / sqrt(lensq);
    }
    let t2 = cross(vh, t1);
    let r = sqrt(u.x);
    let phi = 2.0 * PI * u.y;
    let p1 = r * cos(phi);
    var p2 = r * sin(phi);
    let s = 0.5 * (1.0 + vh.z);
    p2 = (1.0 - s) * sqrt(max(1.0 - p1 * p1, 0.0)) + s * p2;
    let nh = p1 * t1 + p2 * t2 + sqrt(max(1.0 - p1 * p1 - p2 * p2, 0.0)) * vh;
    return normalize(vec3<f32>(ax * nh.x, ay * nh.y, max(nh.z, 0.0)));
}

// Density of sample_ggx_vndf at h: G1(w) max(0, w·h) D(h) / cosθw.
fn ggx_vndf_pdf(w: vec3<f32>, h: vec3<f32>, ax: f32, ay: f32) -> f32 {
    let wh = dot(w, h);
    if (w.z <= 0.0 || wh <= 0.0) {
        return 0.0;
    }
    return wh * ggx_d(h, ax, ay) / (w.z * (1.0 + ggx_lambda(w, ax, ay)));
}
