// Smooth dielectric (bv_core::models::glass): delta reflection and
// transmission, so f = 0 at every finite pair; the environment renderer uses
// `delta_reflectance` and `delta_eta` (the model's GPU port declares a
// refraction delta).
#define_import_path bv::models::glass

#import bv::params::pf
#import bv::fresnel::dielectric
#import bv::layout::GLASS_ETA

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(0.0);
}

// Relative index ηt/ηi below the surface.
fn delta_eta(o: u32) -> f32 {
    return pf(o + GLASS_ETA);
}

// Exact dielectric F for light arriving at cosine c (negative: from inside).
fn delta_reflectance(o: u32, c: f32) -> vec3<f32> {
    return vec3<f32>(dielectric(c, pf(o + GLASS_ETA)));
}
