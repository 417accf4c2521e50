// eval(model, offset, wi, wo) for every model of the catalogue. `model` is
// the catalogue index (bv_core::params::gpu_model_index) and `offset` the
// first slot of the model's parameter block. The per-model switch is
// generated from the catalogue (bv::dispatch, src/gpu/dispatch.rs); a mix is
// a loop over its flattened components.
#define_import_path bv::brdf

#import bv::params::{pf, pu}
#import bv::layout as L
#import bv::dispatch::eval_leaf

// f(wi, wo) without the cosine, per linear-RGB channel. A mix is a
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
