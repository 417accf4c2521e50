// Ideal mirror (bv_core::models::mirror): a delta lobe, so f = 0 at every
// finite pair; the environment renderer uses `delta_reflectance` along R(wo)
// (the model's GPU port declares a reflection delta).
#define_import_path bv::models::mirror

#import bv::params::{prgb, pu}
#import bv::fresnel::fresnel
#import bv::layout::{MIRROR_FRESNEL, MIRROR_ETA, MIRROR_K, MIRROR_F0}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(0.0);
}

// Weight F(cosθ) of the delta lobe for light arriving at cosine c.
fn delta_reflectance(o: u32, c: f32) -> vec3<f32> {
    return fresnel(pu(o + MIRROR_FRESNEL), prgb(o + MIRROR_ETA), prgb(o + MIRROR_K), prgb(o + MIRROR_F0), c);
}
