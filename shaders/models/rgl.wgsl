// RGL measured materials (bv_core::measured::rgl; Dupuy & Jakob 2018, as
// Mitsuba 3's `measured`), isotropic and anisotropic. The material's tables
// sit in the shared table buffer (declared by the MERL port) as bv_core's
// RglMaterial::gpu_slots describes: θi and φi, the VNDF warp's normalised
// values, marginal and conditional CDFs (per (φi, θi) slice, θi fastest),
// the RGB values on the warped square (φi, θi, channel, row, column), the
// NDF and σ. The derived slots hold the sizes, the offsets, the layout
// (isotropic: half-vector azimuth relative to φi), the fold of anisotropic
// files (Mitsuba's m_reduction) and the sampling proxy.
#define_import_path bv::models::rgl

#import bv::params::{pf, pu}
#import bv::models::merl::merl_data
#import bv::sampling_lobe::{Lobe, p_cos_of, ggx_lobe}
#import bv::layout::{RGL_TABLE, RGL_N_THETA, RGL_VNDF_X, RGL_VNDF_Y, RGL_VALUES, RGL_NDF_X, RGL_NDF_Y, RGL_SIGMA_X, RGL_SIGMA_Y, RGL_JACOBIAN, RGL_AT_THETA, RGL_AT_VNDF, RGL_AT_MARGINAL, RGL_AT_CONDITIONAL, RGL_AT_RGB, RGL_AT_NDF, RGL_N_PHI, RGL_AT_PHI, RGL_ISOTROPIC, RGL_REDUCTION, RGL_LOBE_ALPHA_X, RGL_LOBE_ALPHA_Y, RGL_LOBE_DIFFUSE, RGL_LOBE_GLOSSY}

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

// The slice below `p` among the n increasing nodes at `at` and the weight of
// the one above (Marginal2D's interpolate_weights over one parameter; a
// single node has weight 0 above).
fn rgl_weights(at: u32, n: u32, p: f32) -> vec2<f32> {
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

// Where a point sits among the (φi, θi) slices: base slice indices and the
// weights of the slices above (Marginal2D's weights, φi the outer parameter).
struct RglW {
    i_phi: u32,
    w_phi: f32,
    i_theta: u32,
    w_theta: f32,
}

// table[i0] interpolated over φi and θi, where the next θi slice is `dt`
// floats on and the next φi slice `dp` (Marginal2D's lookup: corners in
// the same order, zero weights skipped so a lone node is never read past).
fn rgl_lookup(i0: u32, dt: u32, dp: u32, w: RglW) -> f32 {
    let w1p = w.w_phi;
    let w0p = 1.0 - w1p;
    let w1t = w.w_theta;
    let w0t = 1.0 - w1t;
    var acc = 0.0;
    if (w0p * w0t != 0.0) {
        acc += w0p * w0t * rgl_t(i0);
    }
    if (w1p * w0t != 0.0) {
        acc += w1p * w0t * rgl_t(i0 + dp);
    }
    if (w0p * w1t != 0.0) {
        acc += w0p * w1t * rgl_t(i0 + dt);
    }
    if (w1p * w1t != 0.0) {
        acc += w1p * w1t * rgl_t(i0 + dp + dt);
    }
    return acc;
}

// Bilinear interpolation of an nx × ny table at `pos` in [0,1]² (offset
// `at` of its base slice), interpolated over the slices with `w`.
fn rgl_bilinear(at: u32, nx: u32, ny: u32, dt: u32, dp: u32, pos: vec2<f32>, w: RglW) -> f32 {
    let px = clamp(pos.x, 0.0, 1.0) * f32(nx - 1u);
    let py = clamp(pos.y, 0.0, 1.0) * f32(ny - 1u);
    let ox = min(u32(px), nx - 2u);
    let oy = min(u32(py), ny - 2u);
    let w1x = px - f32(ox);
    let w1y = py - f32(oy);
    let i = at + ox + oy * nx;
    let v00 = rgl_lookup(i, dt, dp, w);
    let v10 = rgl_lookup(i + 1u, dt, dp, w);
    let v01 = rgl_lookup(i + nx, dt, dp, w);
    let v11 = rgl_lookup(i + nx + 1u, dt, dp, w);
    return (1.0 - w1y) * ((1.0 - w1x) * v00 + w1x * v10) + w1y * ((1.0 - w1x) * v01 + w1x * v11);
}

// A single-slice table's bilinear interpolant (the NDF and σ).
fn rgl_plain(at: u32, nx: u32, ny: u32, pos: vec2<f32>) -> f32 {
    return rgl_bilinear(at, nx, ny, 0u, 0u, pos, RglW(0u, 0.0, 0u, 0.0));
}

// The uniform point the VNDF warp maps to `pos` (Marginal2D's
// invert_continuous), interpolated over the (φi, θi) slices.
fn rgl_invert(o: u32, base: u32, pos: vec2<f32>, w: RglW) -> vec2<f32> {
    let nx = pu(o + RGL_VNDF_X);
    let ny = pu(o + RGL_VNDF_Y);
    let nt = pu(o + RGL_N_THETA);
    let size = nx * ny;
    let slice = w.i_phi * nt + w.i_theta;
    let data = base + pu(o + RGL_AT_VNDF) + slice * size;
    let cond = base + pu(o + RGL_AT_CONDITIONAL) + slice * size;
    let marg = base + pu(o + RGL_AT_MARGINAL) + slice * ny;
    // Next θi and φi slices of the values and CDFs, and of the marginal.
    let dt = size;
    let dp = nt * size;
    var s = vec2<f32>(clamp(pos.x, 0.0, 1.0) * f32(nx - 1u), clamp(pos.y, 0.0, 1.0) * f32(ny - 1u));
    let px = min(u32(s.x), nx - 2u);
    let py = min(u32(s.y), ny - 2u);
    s = s - vec2<f32>(f32(px), f32(py));
    let off = px + py * nx;
    let v00 = rgl_lookup(data + off, dt, dp, w);
    let v10 = rgl_lookup(data + off + 1u, dt, dp, w);
    let v01 = rgl_lookup(data + off + nx, dt, dp, w);
    let v11 = rgl_lookup(data + off + nx + 1u, dt, dp, w);
    let c0 = (1.0 - s.y) * v00 + s.y * v01;
    let c1 = (1.0 - s.y) * v10 + s.y * v11;
    var x = s.x * (c0 + 0.5 * s.x * (c1 - c0));
    let k0 = rgl_lookup(cond + off, dt, dp, w);
    let k1 = rgl_lookup(cond + off + nx, dt, dp, w);
    x = x + (1.0 - s.y) * k0 + s.y * k1;
    let row = cond + py * nx;
    let r0 = rgl_lookup(row + nx - 1u, dt, dp, w);
    let r1 = rgl_lookup(row + 2u * nx - 1u, dt, dp, w);
    let rt = (1.0 - s.y) * r0 + s.y * r1;
    if (rt > 0.0) {
        x = x / rt;
    }
    var y = s.y * (r0 + 0.5 * s.y * (r1 - r0));
    y = y + rgl_lookup(marg + py, ny, nt * ny, w);
    return vec2<f32>(x, y);
}

// atan2 with IEEE 754's values at the origin, as Rust's f64::atan2 (WGSL
// leaves atan2(0, 0) undefined): ±0 for x = +0, ±π for x = −0, the sign of
// y's zero. A direction on the normal (wi, or the half vector of a mirror
// pair) then reads the φ slice the CPU reads, which matters where the
// tables vary with φ there.
fn rgl_atan2(y: f32, x: f32) -> f32 {
    if (x == 0.0 && y == 0.0) {
        var r = 0.0;
        if ((bitcast<u32>(x) & 0x80000000u) != 0u) {
            r = RGL_PI;
        }
        if ((bitcast<u32>(y) & 0x80000000u) != 0u) {
            r = -r;
        }
        return r;
    }
    return atan2(y, x);
}

// x times the negated sign of y, +0 counting as positive (Dr.Jit's
// mulsign_neg, bv_core's `mulsign_neg`): read from the sign bit.
fn rgl_mulsign_neg(x: f32, y: f32) -> f32 {
    if ((bitcast<u32>(y) & 0x80000000u) != 0u) {
        return x;
    }
    return -x;
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
    // Anisotropic files whose φi span a half or a quarter turn are folded by
    // the symmetry Mitsuba assumes (bv_core's `fold`): wi to y ≤ 0 (and
    // x ≤ 0 for a quarter turn), wo with it; isotropic files are not.
    var wi = wi_in;
    var wo = wo_in;
    let reduction = pu(o + RGL_REDUCTION);
    if (reduction >= 2u) {
        let sy = wi.y;
        var sx = sy;
        if (reduction == 4u) {
            sx = wi.x;
        }
        wi = vec3<f32>(rgl_mulsign_neg(wi.x, sx), rgl_mulsign_neg(wi.y, sy), wi.z);
        wo = vec3<f32>(rgl_mulsign_neg(wo.x, sx), rgl_mulsign_neg(wo.y, sy), wo.z);
    }
    let hs = wi + wo;
    let hl = length(hs);
    if (hl <= 0.0) {
        return vec3<f32>(0.0);
    }
    let m = hs / hl;
    let base = 4u * pu(o + RGL_TABLE);
    let theta_i = rgl_elevation(wi);
    let phi_i = rgl_atan2(wi.y, wi.x);
    let theta_m = rgl_elevation(m);
    let phi_m = rgl_atan2(m.y, m.x);
    let u_wi = vec2<f32>(sqrt(max(theta_i * (2.0 / RGL_PI), 0.0)), (phi_i + RGL_PI) / (2.0 * RGL_PI));
    var phi_rel = phi_m;
    if (pu(o + RGL_ISOTROPIC) != 0u) {
        phi_rel = phi_m - phi_i;
    }
    let um_y = (phi_rel + RGL_PI) / (2.0 * RGL_PI);
    let u_m = vec2<f32>(sqrt(max(theta_m * (2.0 / RGL_PI), 0.0)), um_y - floor(um_y));
    let wt = rgl_weights(base + pu(o + RGL_AT_THETA), nt, theta_i);
    let wp = rgl_weights(base + pu(o + RGL_AT_PHI), pu(o + RGL_N_PHI), phi_i);
    let w = RglW(u32(wp.x), wp.y, u32(wt.x), wt.y);
    let sq = rgl_invert(o, base, u_m, w);
    let n = pu(o + RGL_VALUES);
    let cells = n * n;
    let rgb_at = base + pu(o + RGL_AT_RGB) + (w.i_phi * nt + w.i_theta) * 3u * cells;
    var v = vec3<f32>(0.0);
    for (var c = 0u; c < 3u; c++) {
        // Channel slices of one (φi, θi) slice are `cells` apart; θi slices
        // 3 · cells, φi slices nθ · 3 · cells.
        v[c] = rgl_bilinear(rgb_at + c * cells, n, n, 3u * cells, nt * 3u * cells, sq, w);
    }
    if (pu(o + RGL_JACOBIAN) != 0u) {
        let nx = pu(o + RGL_NDF_X);
        let ny = pu(o + RGL_NDF_Y);
        let ndf_at = base + pu(o + RGL_AT_NDF);
        let sigma_at = ndf_at + ((nx * ny + 3u) / 4u) * 4u;
        let d = rgl_plain(ndf_at, nx, ny, u_m);
        let s = rgl_plain(sigma_at, pu(o + RGL_SIGMA_X), pu(o + RGL_SIGMA_Y), u_wi);
        if (s > 0.0) {
            v = v * (d / (4.0 * s));
        } else {
            v = vec3<f32>(0.0);
        }
    }
    return v;
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe): GGX
// visible normals at the roughness whose D at the normal equals the file's
// normalised NDF there (αx : αy from its half-maximum widths for an
// anisotropic file), and a cosine part in proportion to the material's
// diffuse weight (bv_core's RglMaterial::sampling_proxy, computed once).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    let p = p_cos_of(pf(o + RGL_LOBE_DIFFUSE), pf(o + RGL_LOBE_GLOSSY));
    return ggx_lobe(p, pf(o + RGL_LOBE_ALPHA_X), pf(o + RGL_LOBE_ALPHA_Y));
}
