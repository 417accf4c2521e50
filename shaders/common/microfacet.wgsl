// Microfacet terms shared by the microfacet models (SPEC §2 "Microfacet parts").
// The half-vector algebra lives here; D, Λ and G follow the Rust of
// bv_core::microfacet once the microfacet models are in the catalogue.
#define_import_path bv::microfacet

// cos²φ and sin²φ of a (not necessarily unit) vector; (1, 0) on the normal.
fn cos2_sin2_phi(v: vec3<f32>) -> vec2<f32> {
    let s = v.x * v.x + v.y * v.y;
    if (s <= 0.0) {
        return vec2<f32>(1.0, 0.0);
    }
    return vec2<f32>(v.x * v.x / s, v.y * v.y / s);
}

// tan²θ of a (not necessarily unit) vector, from its components.
fn tan2_of(v: vec3<f32>) -> f32 {
    return (v.x * v.x + v.y * v.y) / (v.z * v.z);
}
