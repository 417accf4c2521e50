// The local shading frame (n = +z, t = +x) and the f32 direction
// algebra the model ports share. Mirrors bv_core::frame and
// bv_core::models::lobes; formulations are chosen so that f32 keeps the
// relative accuracy the parity test demands (see `pow_from_sin2`).
#define_import_path bv::frame

const PI: f32 = 3.14159265358979323846;
const INV_PI: f32 = 0.31830988618379067154;

// Smallest cosine a model divides by (bv-core uses 1e-150 in f64; f32's
// normal range ends near 1e-38, and 1/1e-30 times any coefficient stays finite).
const COS_FLOOR: f32 = 1e-30;

// Mirror direction about the normal, R(w) = 2 (w·n) n − w.
fn reflect_n(w: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(-w.x, -w.y, w.z);
}

// ln(1 + x) for x in (−1, ∞), accurate to a few ulps relative also where
// |x| is small (WGSL has no log1p, and log(1 + x) loses x's low bits):
// ln(1 + x) = 2 atanh(s), s = x/(2 + x), summed as an odd series for |s| ≤ 1/7.
fn log1p(x: f32) -> f32 {
    if (abs(x) > 0.25) {
        return log(1.0 + x);
    }
    let s = x / (2.0 + x);
    let s2 = s * s;
    // 2 (s + s³/3 + … + s¹³/13): the next term is below 1e-12 relative.
    let p = 1.0 + s2 * (1.0 / 3.0 + s2 * (1.0 / 5.0 + s2 * (1.0 / 7.0 + s2 * (1.0 / 9.0
        + s2 * (1.0 / 11.0 + s2 * (1.0 / 13.0))))));
    return 2.0 * s * p;
}

// (1 − s2)^(e/2), i.e. cos^e θ given sin²θ = s2 ∈ [0, 1]: the power of a lobe
// computed from the sine, so that cos θ ≈ 1 (where sharp lobes live) loses
// nothing to rounding. e = 0 gives 1 (the lobe's open hemisphere is the
// caller's test).
fn pow_from_sin2(s2: f32, e: f32) -> f32 {
    if (e == 0.0) {
        return 1.0;
    }
    if (s2 >= 1.0) {
        return 0.0;
    }
    return exp(0.5 * e * log1p(-s2));
}

// max(0, a·b)^e for unit a, b (bv_core::models::lobes::clamped_pow of a dot
// product): 0 where a·b ≤ 0 (also for e = 0), else (1 − |a − b|²/2)^e with
// 1 − a·b = |a − b|²/2 taken from the difference, exact near the peak.
fn lobe_pow(a: vec3<f32>, b: vec3<f32>, e: f32) -> f32 {
    let c = dot(a, b);
    if (c <= 0.0) {
        return 0.0;
    }
    if (e == 0.0) {
        return 1.0;
    }
    let d = a - b;
    let t = min(0.5 * dot(d, d), 1.0);
    return exp(e * log1p(-t));
}

// wi + wo scaled so that its largest component is ±1 (no underflow near
// opposite grazing directions); +z when it is exactly 0.
fn half_unnormalised(wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    let v = wi + wo;
    let m = max(abs(v.x), max(abs(v.y), abs(v.z)));
    if (m > 0.0) {
        return v / m;
    }
    return vec3<f32>(0.0, 0.0, 1.0);
}

// sin²θ of the direction of a (not necessarily unit) vector v.
fn sin2_of(v: vec3<f32>) -> f32 {
    let t = v.x * v.x + v.y * v.y;
    let l2 = t + v.z * v.z;
    if (l2 <= 0.0) {
        return 0.0;
    }
    return min(t / l2, 1.0);
}

// Orthonormal basis (t, b) around a unit n (Duff et al. 2017), as
// bv_core::sampling::basis.
fn basis(n: vec3<f32>) -> mat2x3<f32> {
    let sgn = select(-1.0, 1.0, n.z >= 0.0);
    let a = -1.0 / (sgn + n.z);
    let b = n.x * n.y * a;
    return mat2x3<f32>(
        vec3<f32>(1.0 + sgn * n.x * n.x * a, sgn * b, -sgn * n.x),
        vec3<f32>(b, sgn + n.y * n.y * a, -n.y),
    );
}
