// Shows the mean of the environment renderer's accumulated samples.
#import bv::display::display

struct Show {
    size: vec2<f32>,
    exposure: f32,
    tone: u32,
    // First row of the band whose buffer is bound (the pass is scissored
    // to the band's rows).
    y0: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
}

@group(0) @binding(0) var<uniform> show: Show;
@group(0) @binding(1) var<storage, read> accum: array<vec4<f32>>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    let x = f32(i32(i & 1u) * 4 - 1);
    let y = f32(i32(i >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let p = vec2<u32>(pos.xy);
    let a = accum[(p.y - show.y0) * u32(show.size.x) + p.x];
    let mean = a.rgb / max(a.a, 1.0);
    return vec4<f32>(display(mean, show.exposure, show.tone), 1.0);
}
