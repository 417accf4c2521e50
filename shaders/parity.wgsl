// Parity compute shader: evaluates one packed model on a batch of direction
// pairs so that tests can compare with bv-core.
#import bv::brdf

struct Job {
    model: u32,
    offset: u32,
    count: u32,
    pad: u32,
}

// Pair i: wi in dirs[2i].xyz, wo in dirs[2i + 1].xyz.
@group(0) @binding(1) var<storage, read> dirs: array<vec4<f32>>;
@group(0) @binding(2) var<storage, read_write> values: array<vec4<f32>>;
@group(0) @binding(3) var<uniform> job: Job;

@compute @workgroup_size(64)
fn main(@builtin(global_invocation_id) id: vec3<u32>) {
    let i = id.x;
    if (i >= job.count) {
        return;
    }
    let wi = dirs[2u * i].xyz;
    let wo = dirs[2u * i + 1u].xyz;
    values[i] = vec4<f32>(brdf::eval(job.model, job.offset, wi, wo), 0.0);
}
