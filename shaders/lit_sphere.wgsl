// Lit sphere view: each model on an orthographic sphere lit
// by a directional light; radiance f(wi, wo) cosθi E, then exposure, tone map
// and sRGB encoding.
#import bv::brdf
#import bv::display::display
#import bv::sphere::{sphere_at, to_local, turned}

struct View {
    size: vec2<f32>,
    tiles: u32,
    tone: u32,
    // Unit direction towards the light (view space), and its irradiance E at
    // normal incidence in w.
    light: vec4<f32>,
    // Exposure factor 2^EV.
    exposure: f32,
    // Background: 0 flat colour, 1 checkerboard of colour and colour2.
    background: u32,
    checker: f32,
    // The surface turned about its normal (radians).
    turn: f32,
    // Tiles in a full row (src/gpu/sphere.rs, Grid).
    cols: u32,
    pad0: u32,
    pad1: u32,
    pad2: u32,
    color: vec4<f32>,
    color2: vec4<f32>,
}

// The model of every tile when the pipeline is specialised for one model
// (src/gpu/shaders.rs, specialised_wgsl, which replaces this line); the
// generic pipeline reads it per tile.
const FIXED_MODEL: u32 = 0xffffffffu;

@group(0) @binding(1) var<uniform> view: View;
// (model index, parameter offset) of the sphere in each tile.
@group(0) @binding(2) var<storage, read> models: array<vec2<u32>>;

@vertex
fn vs_main(@builtin(vertex_index) i: u32) -> @builtin(position) vec4<f32> {
    // One triangle that covers the viewport.
    let x = f32(i32(i & 1u) * 4 - 1);
    let y = f32(i32(i >> 1u) * 4 - 1);
    return vec4<f32>(x, y, 0.0, 1.0);
}

fn background(p: vec2<f32>) -> vec3<f32> {
    if (view.background == 1u) {
        let c = vec2<i32>(floor(p / view.checker));
        if (((c.x + c.y) & 1) == 1) {
            return view.color2.rgb;
        }
    }
    return view.color.rgb;
}

@fragment
fn fs_main(@builtin(position) pos: vec4<f32>) -> @location(0) vec4<f32> {
    let s = turned(sphere_at(pos.xy, view.size, view.tiles, view.cols), view.turn);
    if (s.tile < 0) {
        return vec4<f32>(background(pos.xy), 1.0);
    }
    let m = models[u32(s.tile)];
    let l = view.light.xyz;
    let wi = to_local(s, l);
    let wo = to_local(s, vec3<f32>(0.0, 0.0, 1.0));
    var radiance = vec3<f32>(0.0);
    if (wi.z > 0.0) {
        let model = select(m.x, FIXED_MODEL, FIXED_MODEL != 0xffffffffu);
        radiance = brdf::eval(model, m.y, wi, wo) * wi.z * view.light.w;
    }
    return vec4<f32>(display(radiance, view.exposure, view.tone), 1.0);
}
