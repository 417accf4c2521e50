// Lambert: f = albedo/π (bv_core::models::lambert).
#define_import_path bv::models::lambert

#import bv::params::prgb
#import bv::frame::INV_PI
#import bv::layout::LAMBERT_ALBEDO

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    return prgb(o + LAMBERT_ALBEDO) * INV_PI;
}
