// The dispatcher: eval(model, offset, wi, wo) for every model of the catalogue.
// `model` is the catalogue index (bv_core::params::gpu_model_index) and
// `offset` the first slot of the model's parameter block.
#define_import_path bv::brdf

#import bv::params::{pf, pu}
#import bv::layout as L
#import bv::models::lambert
#import bv::models::phong
#import bv::models::blinn_phong
#import bv::models::modified_phong
#import bv::models::ashikhmin_shirley
#import bv::models::oren_nayar
#import bv::models::hapke
#import bv::models::ward
#import bv::models::lafortune
#import bv::models::banks
#import bv::models::cook_torrance
#import bv::models::disney
#import bv::models::mirror
#import bv::models::glass
#import bv::models::merl

// A model that is not a mix. Unknown indices (a model without a port) give 0,
// which the parity test reports as a failure.
fn eval_leaf(model: u32, o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    switch model {
        case L::MODEL_LAMBERT: { return lambert::eval(o, wi, wo); }
        case L::MODEL_PHONG: { return phong::eval(o, wi, wo); }
        case L::MODEL_BLINN_PHONG: { return blinn_phong::eval(o, wi, wo); }
        case L::MODEL_MODIFIED_PHONG: { return modified_phong::eval(o, wi, wo); }
        case L::MODEL_ASHIKHMIN_SHIRLEY: { return ashikhmin_shirley::eval(o, wi, wo); }
        case L::MODEL_OREN_NAYAR: { return oren_nayar::eval(o, wi, wo); }
        case L::MODEL_HAPKE: { return hapke::eval(o, wi, wo); }
        case L::MODEL_WARD: { return ward::eval(o, wi, wo); }
        case L::MODEL_LAFORTUNE: { return lafortune::eval(o, wi, wo); }
        case L::MODEL_BANKS: { return banks::eval(o, wi, wo); }
        case L::MODEL_COOK_TORRANCE: { return cook_torrance::eval(o, wi, wo); }
        case L::MODEL_DISNEY: { return disney::eval(o, wi, wo); }
        // Delta models: 0 at every finite pair (their lobes are in env.wgsl).
        case L::MODEL_MIRROR: { return mirror::eval(o, wi, wo); }
        case L::MODEL_GLASS: { return glass::eval(o, wi, wo); }
        // Measured: the table is in its own buffer (bv::models::merl).
        case L::MODEL_MERL: { return merl::eval(o, wi, wo); }
        default: { return vec3<f32>(0.0); }
    }
}

// f(wi, wo) without the cosine, per linear-RGB channel (SPEC §1). A mix is a
// loop over its flattened table of (weight, model, offset) entries (nested
// mixes were flattened by the packer: BRDFs are linear).
fn eval(model: u32, o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (model == L::MODEL_MIX) {
        let n = pu(o + L::MIX_COMPONENTS);
        let table = pu(o + L::MIX_COMPONENTS + 1u);
        var sum = vec3<f32>(0.0);
        for (var j = 0u; j < n; j++) {
            let e = table + L::COMPONENT_ENTRY_SLOTS * j;
            sum += pf(e) * eval_leaf(pu(e + 1u), pu(e + 2u), wi, wo);
        }
        return sum;
    }
    return eval_leaf(model, o, wi, wo);
}
