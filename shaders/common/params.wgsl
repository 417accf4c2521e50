// The flat parameter buffer every model reads (layout: bv_core::params::gpu_layout,
// offsets as generated constants in the `bv::layout` module).
#define_import_path bv::params

@group(0) @binding(0) var<storage, read> params: array<f32>;

// One float slot.
fn pf(o: u32) -> f32 {
    return params[o];
}

// A colour: three consecutive slots.
fn prgb(o: u32) -> vec3<f32> {
    return vec3<f32>(params[o], params[o + 1u], params[o + 2u]);
}

// An integer slot (count, choice index, model index, offset): stored as an
// exactly representable f32.
fn pu(o: u32) -> u32 {
    return u32(params[o]);
}
