// Fresnel terms, ports of bv_core::fresnel in f32. The choice
// indices are those of bv_core::fresnel::FRESNEL_OPTIONS, taken from the
// generated layout of `cook-torrance` (every model with a Fresnel choice
// declares it through fresnel_param, which a test checks).
#define_import_path bv::fresnel

#import bv::layout::{COOK_TORRANCE_FRESNEL_NONE, COOK_TORRANCE_FRESNEL_DIELECTRIC, COOK_TORRANCE_FRESNEL_CONDUCTOR}

// The Schlick weight (1 − c)^5 (Disney's FH, FL, FV), c clamped to [0, 1].
fn schlick_weight(c: f32) -> f32 {
    let m = clamp(1.0 - c, 0.0, 1.0);
    let m2 = m * m;
    return m2 * m2 * m;
}

// Schlick's approximation f0 + (1 − f0)(1 − c)^5 (Schlick 1994, eq. 24).
fn schlick(f0: vec3<f32>, c: f32) -> vec3<f32> {
    return f0 + (vec3<f32>(1.0) - f0) * schlick_weight(c);
}

// Exact unpolarised dielectric reflectance (r∥² + r⊥²)/2 for relative index
// eta = ηt/ηi seen from the +z side; cos_i < 0 means arriving from inside
// (index 1/eta); 1 under total internal reflection (bv_core::fresnel::dielectric).
fn dielectric(cos_i: f32, eta_in: f32) -> f32 {
    var c = cos_i;
    var eta = eta_in;
    if (cos_i < 0.0) {
        c = -cos_i;
        eta = 1.0 / eta_in;
    }
    c = min(c, 1.0);
    let sin2_i = max(1.0 - c * c, 0.0);
    let sin2_t = sin2_i / (eta * eta);
    if (sin2_t >= 1.0) {
        return 1.0;
    }
    let cos_t = sqrt(1.0 - sin2_t);
    let r_par = (eta * c - cos_t) / (eta * c + cos_t);
    let r_perp = (c - eta * cos_t) / (c + eta * cos_t);
    return 0.5 * (r_par * r_par + r_perp * r_perp);
}

// Exact unpolarised conductor reflectance for the complex index eta + i k
// (bv_core::fresnel::conductor). a² = (|a²+b²| + t0)/2 is taken as
// 2 η² k² / (|a²+b²| − t0) when t0 < 0, where the sum would cancel in f32
// (η = 0.01, k = 20: t0 ≈ −400 and the sum is 2e-4).
fn conductor(cos_i: f32, eta: f32, k: f32) -> f32 {
    let c = min(abs(cos_i), 1.0);
    let cos2 = c * c;
    let sin2 = 1.0 - cos2;
    let eta2 = eta * eta;
    let k2 = k * k;
    let t0 = eta2 - k2 - sin2;
    let a2b2 = sqrt(t0 * t0 + 4.0 * eta2 * k2);
    let t1 = a2b2 + cos2;
    var a2: f32;
    if (t0 >= 0.0) {
        a2 = 0.5 * (a2b2 + t0);
    } else {
        a2 = 2.0 * eta2 * k2 / (a2b2 - t0);
    }
    let a = sqrt(max(a2, 0.0));
    let t2 = 2.0 * c * a;
    if (t1 + t2 <= 0.0) {
        return 1.0;
    }
    let rs = (t1 - t2) / (t1 + t2);
    let t3 = cos2 * a2b2 + sin2 * sin2;
    let t4 = t2 * sin2;
    let rp = rs * (t3 - t4) / (t3 + t4);
    return 0.5 * (rp + rs);
}

// The Fresnel choice of a model (bv_core::fresnel::Fresnel::eval) at cosine c.
fn fresnel(kind: u32, eta: vec3<f32>, k: vec3<f32>, f0: vec3<f32>, c: f32) -> vec3<f32> {
    if (kind == COOK_TORRANCE_FRESNEL_NONE) {
        return vec3<f32>(1.0);
    }
    if (kind == COOK_TORRANCE_FRESNEL_DIELECTRIC) {
        return vec3<f32>(dielectric(c, eta.x), dielectric(c, eta.y), dielectric(c, eta.z));
    }
    if (kind == COOK_TORRANCE_FRESNEL_CONDUCTOR) {
        return vec3<f32>(conductor(c, eta.x, k.x), conductor(c, eta.y, k.y), conductor(c, eta.z, k.z));
    }
    return schlick(f0, abs(c));
}
