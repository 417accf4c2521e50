// Fresnel terms (SPEC §2, "F"). Mirrors the Rust of the models that use them.
#define_import_path bv::fresnel

// Schlick's approximation f0 + (1 − f0)(1 − c)^5 (Schlick 1994, eq. 24).
fn schlick(f0: vec3<f32>, c: f32) -> vec3<f32> {
    let m = clamp(1.0 - c, 0.0, 1.0);
    let m2 = m * m;
    return f0 + (vec3<f32>(1.0) - f0) * (m2 * m2 * m);
}

// The Schlick weight (1 − c)^5 alone (Disney's FH, FL, FV).
fn schlick_weight(c: f32) -> f32 {
    let m = clamp(1.0 - c, 0.0, 1.0);
    let m2 = m * m;
    return m2 * m2 * m;
}
