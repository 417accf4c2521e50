// MERL measured tables (bv_core::measured::merl; Matusik et al. 2003). The tables live in their own storage buffer, `merl_data`: every
// table a frame draws, one after the other, each in its in-memory layout (f32
// values of f with the channel scales applied, channel-major, cell
// (iθh · nθd + iθd) · nφd + iφd). A model's parameter block holds its
// interpolation choice; its GPU port (bv_core::models::merl) declares four
// derived slots after it: nθh, nθd, nφd and the table's first element in
// units of 4 floats (so that every offset stays an exactly representable f32).
#define_import_path bv::models::merl

#import bv::params::{pf, pu}
#import bv::frame::{PI, half_unnormalised}
#import bv::sampling_lobe::{Lobe, p_cos_of, ggx_lobe}
#import bv::layout::{MERL_INTERPOLATION, MERL_INTERPOLATION_NEAREST, MERL_THETA_H_COUNT, MERL_THETA_D_COUNT, MERL_PHI_D_COUNT, MERL_TABLE, MERL_LOBE_ALPHA, MERL_LOBE_DIFFUSE, MERL_LOBE_GLOSSY}

@group(0) @binding(8) var<storage, read> merl_data: array<f32>;

const HALF_PI: f32 = 1.57079632679489661923;

// How close (radians) a folded φd must be to 0 or π to count as on the seam
// and go to cell 0. bv-core uses 1e-9 in f64; an f32 atan2 has an absolute
// error of order 1e-7 there, so in-plane pairs (φd = 0 or π in theory) need a
// wider band to land in cell 0 as consistently as on the CPU. 1e-6 rad is
// 6e-5 of a public-resolution cell.
const PHI_D_SEAM: f32 = 1e-6;

// (θh, θd, φd) of a pair, as bv_core::measured::merl::half_diff_angles:
// rotate wi by −φh about z, then by −θh about y, with the rotations built from
// h's components.
fn half_diff(wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let h = normalize(half_unnormalised(wi, wo));
    let s = sqrt(h.x * h.x + h.y * h.y);
    var cp = 1.0;
    var sp = 0.0;
    if (s > 0.0) {
        cp = h.x / s;
        sp = h.y / s;
    }
    let x1 = cp * wi.x + sp * wi.y;
    let y1 = cp * wi.y - sp * wi.x;
    let x2 = h.z * x1 - s * wi.z;
    let z2 = s * x1 + h.z * wi.z;
    return vec3<f32>(atan2(s, h.z), atan2(sqrt(x2 * x2 + y1 * y1), z2), atan2(y1, x2));
}

// Continuous θh coordinate √(θh/(π/2)) · n in [0, n].
fn theta_h_coord(t: f32, n: u32) -> f32 {
    if (t > 0.0) {
        return sqrt(min(t / HALF_PI, 1.0)) * f32(n);
    }
    return 0.0;
}

// Continuous θd coordinate θd/(π/2) · n in [0, n].
fn theta_d_coord(t: f32, n: u32) -> f32 {
    if (t > 0.0) {
        return min(t / HALF_PI, 1.0) * f32(n);
    }
    return 0.0;
}

// Continuous φd coordinate, φd/π · n reduced into [0, n) (period π).
fn phi_d_coord(p: f32, n: u32) -> f32 {
    let t = p / PI;
    let u = (t - floor(t)) * f32(n);
    if (u >= f32(n)) {
        return 0.0;
    }
    return u;
}

fn clamp_index(u: f32, n: u32) -> u32 {
    if (u > 0.0) {
        return min(u32(u), n - 1u);
    }
    return 0u;
}

// Nearest cell along φd: fold φd < 0 by +π, the seam goes to cell 0.
fn phi_d_index(p: f32, n: u32) -> u32 {
    var q = p;
    if (q < 0.0) {
        q = q + PI;
    }
    if (q > PHI_D_SEAM && q < PI - PHI_D_SEAM) {
        return clamp_index(q / PI * f32(n), n);
    }
    return 0u;
}

// Cells (i0, i1) and the weight of i1 along a clamped axis whose samples sit
// at i + ½.
fn clamped_lerp(u: f32, n: u32) -> vec3<f32> {
    let t = clamp(u - 0.5, 0.0, f32(n - 1u));
    let i0 = min(u32(t), n - 1u);
    let i1 = min(i0 + 1u, n - 1u);
    return vec3<f32>(f32(i0), f32(i1), t - f32(i0));
}

// The same along the periodic φd axis, for u in [0, n): the cell below is
// −1 (wrapped to n − 1) up to n − 1. The wrap is a comparison, not `%` of a
// negative number: with `((i % n) + n) % n`, lavapipe (LLVM 15) on an
// AVX2-only AMD EPYC read the wrong cells for in-plane pairs (φd near 0,
// t < 0; tests/gpu_parity.rs, up to 885× the tolerance), while the same
// shader passed on an AVX-512 Intel machine. The comparison form passes on
// the AVX2 machine.
fn periodic_lerp(u: f32, n: u32) -> vec3<f32> {
    let t = u - 0.5;
    let fl = floor(t);
    let ni = i32(n);
    var i0 = i32(fl);
    if (i0 < 0) {
        i0 = i0 + ni;
    }
    if (i0 >= ni) {
        i0 = i0 - ni;
    }
    var i1 = i0 + 1;
    if (i1 >= ni) {
        i1 = 0;
    }
    return vec3<f32>(f32(i0), f32(i1), t - fl);
}

fn cell_rgb(base: u32, cells: u32, i: u32) -> vec3<f32> {
    return vec3<f32>(merl_data[base + i], merl_data[base + cells + i], merl_data[base + 2u * cells + i]);
}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let nh = pu(o + MERL_THETA_H_COUNT);
    let nd = pu(o + MERL_THETA_D_COUNT);
    let np = pu(o + MERL_PHI_D_COUNT);
    let base = 4u * pu(o + MERL_TABLE);
    let cells = nh * nd * np;
    let a = half_diff(wi, wo);
    if (pu(o + MERL_INTERPOLATION) == MERL_INTERPOLATION_NEAREST) {
        let ih = clamp_index(theta_h_coord(a.x, nh), nh);
        let id = clamp_index(theta_d_coord(a.y, nd), nd);
        let ip = phi_d_index(a.z, np);
        return cell_rgb(base, cells, (ih * nd + id) * np + ip);
    }
    let lh = clamped_lerp(theta_h_coord(a.x, nh), nh);
    let ld = clamped_lerp(theta_d_coord(a.y, nd), nd);
    let lp = periodic_lerp(phi_d_coord(a.z, np), np);
    var out = vec3<f32>(0.0);
    for (var kh = 0u; kh < 2u; kh++) {
        let ih = u32(select(lh.x, lh.y, kh == 1u));
        let fh = select(1.0 - lh.z, lh.z, kh == 1u);
        for (var kd = 0u; kd < 2u; kd++) {
            let id = u32(select(ld.x, ld.y, kd == 1u));
            let fd = select(1.0 - ld.z, ld.z, kd == 1u);
            let row = (ih * nd + id) * np;
            for (var kp = 0u; kp < 2u; kp++) {
                let ip = u32(select(lp.x, lp.y, kp == 1u));
                let fp = select(1.0 - lp.z, lp.z, kp == 1u);
                out += (fh * fd * fp) * cell_rgb(base, cells, row + ip);
            }
        }
    }
    return out;
}

// The proxy lobe the environment renderer samples (bv::sampling_lobe): GGX
// visible normals at the roughness whose D halves where the table's θh
// profile does, and a cosine part in proportion to its floor (bv_core's
// MerlTable::sampling_proxy, computed once per table).
fn sampling_lobe(o: u32, wo: vec3<f32>) -> Lobe {
    let a = pf(o + MERL_LOBE_ALPHA);
    return ggx_lobe(p_cos_of(pf(o + MERL_LOBE_DIFFUSE), pf(o + MERL_LOBE_GLOSSY)), a, a);
}
