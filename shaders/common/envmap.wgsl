// The equirectangular environment: lookup, importance sampling and its
// density. Texels are piecewise constant; texel (i, j) covers azimuths
// φ ∈ [i, i+1)·2π/w − π and polar angles θ ∈ [j, j+1)·π/h from +y (up). It is
// drawn with probability ∝ (its luminance × its solid angle), then uniformly
// in solid angle within the texel, so the density is exact:
// p(ω) = P(texel) / Ω(texel). The CDFs are built by src/gpu/env.rs.
#define_import_path bv::envmap

#import bv::frame::PI

struct EnvInfo {
    width: u32,
    height: u32,
    // 1 when the map has energy to sample.
    sampling: u32,
    // Offsets in env_data of the marginal and the conditional CDFs (the
    // texels, rgb, start at 0).
    marginal: u32,
    conditional: u32,
    // Rotation of the map about +y (radians).
    rotation: f32,
    pad_a: f32,
    pad_b: f32,
}

@group(1) @binding(0) var<uniform> env: EnvInfo;
// One buffer (downlevel devices allow 4 storage buffers per stage): texels
// (3 floats each, row-major), then the marginal CDF over rows (height + 1
// entries, 0 … 1), then each row's conditional CDF (width + 1 entries per row).
@group(1) @binding(1) var<storage, read> env_data: array<f32>;

fn marginal(k: u32) -> f32 {
    return env_data[env.marginal + k];
}

fn conditional(k: u32) -> f32 {
    return env_data[env.conditional + k];
}

// (φ, θ) of a world direction (φ from −z towards +x, measured before rotation).
fn angles(d: vec3<f32>) -> vec2<f32> {
    let phi = atan2(d.x, -d.z) - env.rotation;
    let theta = acos(clamp(d.y, -1.0, 1.0));
    return vec2<f32>(phi, theta);
}

fn texel_of(d: vec3<f32>) -> vec2<u32> {
    let a = angles(d);
    let u = fract((a.x + PI) / (2.0 * PI));
    let v = a.y / PI;
    let i = min(u32(u * f32(env.width)), env.width - 1u);
    let j = min(u32(v * f32(env.height)), env.height - 1u);
    return vec2<u32>(i, j);
}

// Radiance arriving from world direction d.
fn radiance(d: vec3<f32>) -> vec3<f32> {
    let t = texel_of(d);
    let k = 3u * (t.y * env.width + t.x);
    return vec3<f32>(env_data[k], env_data[k + 1u], env_data[k + 2u]);
}

fn texel_solid_angle(j: u32) -> f32 {
    let t0 = f32(j) * PI / f32(env.height);
    let t1 = f32(j + 1u) * PI / f32(env.height);
    return 2.0 * PI / f32(env.width) * (cos(t0) - cos(t1));
}

// Solid-angle density of `sample` at world direction d.
fn pdf(d: vec3<f32>) -> f32 {
    if (env.sampling == 0u) {
        return 0.0;
    }
    let t = texel_of(d);
    let row = marginal(t.y + 1u) - marginal(t.y);
    let base = t.y * (env.width + 1u);
    let col = conditional(base + t.x + 1u) - conditional(base + t.x);
    return row * col / texel_solid_angle(t.y);
}

// Largest k in [0, n) with cdf[offset + k] ≤ u (cdf non-decreasing, cdf[offset] = 0).
fn find_marginal(u: f32) -> u32 {
    var lo = 0u;
    var hi = env.height;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (marginal(mid) <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

fn find_conditional(row: u32, u: f32) -> u32 {
    let base = row * (env.width + 1u);
    var lo = 0u;
    var hi = env.width;
    while (hi - lo > 1u) {
        let mid = (lo + hi) / 2u;
        if (conditional(base + mid) <= u) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    return lo;
}

// A world direction drawn from the map (u in [0, 1)⁴).
fn sample(u: vec4<f32>) -> vec3<f32> {
    let j = find_marginal(u.x);
    let i = find_conditional(j, u.y);
    let phi = (f32(i) + u.z) / f32(env.width) * 2.0 * PI - PI + env.rotation;
    let c0 = cos(f32(j) * PI / f32(env.height));
    let c1 = cos(f32(j + 1u) * PI / f32(env.height));
    let ct = mix(c0, c1, u.w);
    let st = sqrt(max(1.0 - ct * ct, 0.0));
    return vec3<f32>(st * sin(phi), ct, -st * cos(phi));
}
