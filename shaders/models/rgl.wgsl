// RGL measured materials (bv_core::measured::rgl; Dupuy & Jakob 2018, as
// Mitsuba 3's `measured`), for files with one φi (the isotropic ones). The
// material's tables sit in the shared table buffer (declared by the MERL
// port) as bv_core's RglMaterial::gpu_slots describes: θi, the VNDF warp's
// normalised values, marginal and conditional CDFs (per θi slice), the RGB
// values on the warped square (slice-major, channel, row, column), the NDF
// and σ. The derived slots hold the sizes and the offsets; nθ = 0 marks a
// file this port does not draw (0).
#define_import_path bv::models::rgl

#import bv::params::pu
#import bv::models::merl::merl_data
#import bv::layout::{RGL_TABLE, RGL_N_THETA, RGL_VNDF_X, RGL_VNDF_Y, RGL_VALUES, RGL_NDF_X, RGL_NDF_Y, RGL_SIGMA_X, RGL_SIGMA_Y, RGL_JACOBIAN, RGL_AT_THETA, RGL_AT_VNDF, RGL_AT_MARGINAL, RGL_AT_CONDITIONAL, RGL_AT_RGB, RGL_AT_NDF}

const RGL_PI: f32 = 3.14159265358979323846;

// Below this cos θo (θo = 87°), f is held at its value there on the same
// azimuth (bv_core GRAZING_COS, `grazing_held`).
const RGL_GRAZING_COS: f32 = 0.052335956;

fn rgl_t(i: u32) -> f32 {
    return merl_data[i];
}

// Angle from +z, stable near the pole (Mitsuba's `elevation`).
fn rgl_elevation(d: vec3<f32>) -> f32 {
    let dist = sqrt(d.x * d.x + d.y * d.y + (d.z - 1.0) * (d.z - 1.0));
    return 2.0 * asin(clamp(0.5 * dist, -1.0, 1.0));
}

// The θi slice below `p` and the weight of the one above (Marginal2D's
// interpolate_weights over one parameter).
fn rgl_theta_weights(at: u32, n: u32, p: f32) -> vec2<f32> {
    if (n < 2u) {
        return vec2<f32>(0.0, 0.0);
    }
    var i = 0u;
    for (var k = 1u; k + 1u < n; k++) {
        if (rgl_t(at + k) < p) {
            i = k;
        }
    }
    let p0 = rgl_t(at + i);
    let p1 = rgl_t(at + i + 1u);
    var w1 = clamp((p - p0) / (p1 - p0), 0.0, 1.0);
    if (w1 != w1) {
        w1 = 0.0;
    }
    return vec2<f32>(f32(i), w1);
}

// table[i0] interpolated over the θi slices (`size` entries per slice).
fn rgl_lookup(i0: u32, size: u32, w: vec2<f32>) -> f32 {
    let a = rgl_t(i0);
    if (w.y == 0.0) {
        return a;
    }
    return (1.0 - w.y) * a + w.y * rgl_t(i0 + size);
}

// Bilinear interpolation of an nx × ny table at `pos` in [0,1]² (offset
// `at` of its slice), interpolated over θi with `w` (slices `size` apart).
fn rgl_bilinear(at: u32, nx: u32, ny: u32, size: u32, pos: vec2<f32>, w: vec2<f32>) -> f32 {
    let px = clamp(pos.x, 0.0, 1.0) * f32(nx - 1u);
    let py = clamp(pos.y, 0.0, 1.0) * f32(ny - 1u);
    let ox = min(u32(px), nx - 2u);
    let oy = min(u32(py), ny - 2u);
    let w1x = px - f32(ox);
    let w1y = py - f32(oy);
    let i = at + ox + oy * nx;
    let v00 = rgl_lookup(i, size, w);
    let v10 = rgl_lookup(i + 1u, size, w);
    let v01 = rgl_lookup(i + nx, size, w);
    let v11 = rgl_lookup(i + nx + 1u, size, w);
    return (1.0 - w1y) * ((1.0 - w1x) * v00 + w1x * v10) + w1y * ((1.0 - w1x) * v01 + w1x * v11);
}

// The uniform point the VNDF warp maps to `pos` (Marginal2D's
// invert_continuous); `base_*` are the θi slice's offsets.
fn rgl_invert(o: u32, base: u32, pos: vec2<f32>, w: vec2<f32>) -> vec2<f32> {
    let nx = pu(o + RGL_VNDF_X);
    let ny = pu(o + RGL_VNDF_Y);
    let size = nx * ny;
    let slice = u32(w.x);
    let data = base + pu(o + RGL_AT_VNDF) + slice * size;
    let cond = base + pu(o + RGL_AT_CONDITIONAL) + slice * size;
    let marg = base + pu(o + RGL_AT_MARGINAL) + slice * ny;
    var s = vec2<f32>(clamp(pos.x, 0.0, 1.0) * f32(nx - 1u), clamp(pos.y, 0.0, 1.0) * f32(ny - 1u));
    let px = min(u32(s.x), nx - 2u);
    let py = min(u32(s.y), ny - 2u);
    s = s - vec2<f32>(f32(px), f32(py));
    let off = px + py * nx;
    let v00 = rgl_lookup(data + off, size, w);
    let v10 = rgl_lookup(data + off + 1u, size, w);
    let v01 = rgl_lookup(data + off + nx, size, w);
    let v11 = rgl_lookup(data + off + nx + 1u, size, w);
    let c0 = (1.0 - s.y) * v00 + s.y * v01;
    let c1 = (1.0 - s.y) * v10 + s.y * v11;
    var x = s.x * (c0 + 0.5 * s.x * (c1 - c0));
    let k0 = rgl_lookup(cond + off, size, w);
    let k1 = rgl_lookup(cond + off + nx, size, w);
    x = x + (1.0 - s.y) * k0 + s.y * k1;
    let row = cond + py * nx;
    let r0 = rgl_lookup(row + nx - 1u, size, w);
    let r1 = rgl_lookup(row + 2u * nx - 1u, size, w);
    let rt = (1.0 - s.y) * r0 + s.y * r1;
    if (rt > 0.0) {
        x = x / rt;
    }
    var y = s.y * (r0 + 0.5 * s.y * (r1 - r0));
    y = y + rgl_lookup(marg + py, ny, w);
    return vec2<f32>(x, y);
}

fn eval(o: u32, wi_in: vec3<f32>, wo_in: vec3<f32>) -> vec3<f32> {
    if (wi_in.z <= 0.0 || wo_in.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    var wo = wo_in;
    if (wo.z < RGL_GRAZING_COS) {
        let l = length(wo.xy);
        let sin_c = sqrt(1.0 - RGL_GRAZING_COS * RGL_GRAZING_COS);
        if (l > 0.0) {
            wo = vec3<f32>(wo.xy / l * sin_c, RGL_GRAZING_COS);
        } else {
            wo = vec3<f32>(0.0, 0.0, 1.0);
        }
    }
    return rgl_eval_cos(o, wi_in, wo) / wo.z;
}

// f cos θo as the file stores it (bv_core `eval_cos`).
fn rgl_eval_cos(o: u32, wi_in: vec3<f32>, wo_in: vec3<f32>) -> vec3<f32> {
    let nt = pu(o + RGL_N_THETA);
    if (wi_in.z <= 0.0 || wo_in.z <= 0.0 || nt == 0u) {
        return vec3<f32>(0.0);
    }
    // Isotropic data (one φi) is not folded (bv_core's `fold`).
    let wi = wi_in;
    let wo = wo_in;
    let hs = wi + wo;
    let hl = length(hs);
    if (hl <= 0.0) {
        return vec3<f32>(0.0);
    }
    let m = hs / hl;
    let base = 4u * pu(o + RGL_TABLE);
    let theta_i = rgl_elevation(wi);
    let phi_i = atan2(wi.y, wi.x);
    let theta_m = rgl_elevation(m);
    let phi_m = atan2(m.y, m.x);
    let u_wi = vec2<f32>(sqrt(max(theta_i * (2.0 / RGL_PI), 0.0)), (phi_i + RGL_PI) / (2.0 * RGL_PI));
    let um_y = (phi_m - phi_i + RGL_PI) / (2.0 * RGL_PI);
    let u_m = vec2<f32>(sqrt(max(theta_m * (2.0 / RGL_PI), 0.0)), um_y - floor(um_y));
    let w = rgl_theta_weights(base + pu(o + RGL_AT_THETA), nt, theta_i);
    let sq = rgl_invert(o, base, u_m, w);
    let n = pu(o + RGL_VALUES);
    let cells = n * n;
    let slice = u32(w.x);
    let rgb_at = base + pu(o + RGL_AT_RGB);
    var v = vec3<f32>(0.0);
    for (var c = 0u; c < 3u; c++) {
        // Channel slices of one θi slice are `cells` apart; θi slices are
        // 3 · cells apart.
        v[c] = rgl_bilinear(rgb_at + (slice * 3u + c) * cells, n, n, 3u * cells, sq, w);
    }
    if (pu(o + RGL_JACOBIAN) != 0u) {
        let nx = pu(o + RGL_NDF_X);
        let ny = pu(o + RGL_NDF_Y);
        let ndf_at = base + pu(o + RGL_AT_NDF);
        let sigma_at = ndf_at + ((nx * ny + 3u) / 4u) * 4u;
        let d = rgl_bilinear(ndf_at, nx, ny, 0u, u_m, vec2<f32>(0.0, 0.0));
        let s = rgl_bilinear(sigma_at, pu(o + RGL_SIGMA_X), pu(o + RGL_SIGMA_Y), 0u, u_wi, vec2<f32>(0.0, 0.0));
        if (s > 0.0) {
            v = v * (d / (4.0 * s));
        } else {
            v = vec3<f32>(0.0);
        }
    }
    return v;
}
