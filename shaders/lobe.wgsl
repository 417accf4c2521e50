// Lobe surfaces of the 3D view.
//
// Positions arrive in radius units (1/sr, or ln(1 + f) on the log scale) and
// are scaled to the view's world units here, so a scale change needs no
// re-upload. Colours are handled in linear RGB and written gamma-encoded to an
// Rgba8Unorm target, which egui then copies as it stands (egui-wgpu draws in
// gamma space to a non-sRGB framebuffer, so this keeps both consistent).

#import bv::colormap::COLORMAP

struct Globals {
    view_proj: mat4x4<f32>,
    // xyz: eye position.
    eye: vec4<f32>,
    // xy: target size in pixels.
    viewport: vec4<f32>,
};

struct Style {
    // rgb: solid colour (sRGB), a: opacity.
    color: vec4<f32>,
    // x: 1 = colour by value, y: largest value, z: 1 = log scale, w: world scale.
    params: vec4<f32>,
    // x: 1 = unlit (flat colour).
    extra: vec4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;
@group(1) @binding(0) var<uniform> s: Style;


struct VsIn {
    @location(0) pos: vec3<f32>,
    @location(1) normal: vec3<f32>,
    @location(2) value: f32,
};

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) world: vec3<f32>,
    @location(1) normal: vec3<f32>,
    // The base colour in linear RGB, looked up per vertex: the colour map and
    // its sRGB decode (three pow) are then paid 33 k times per mesh instead of
    // once per covered pixel, which on a CPU rasteriser is most of the
    // fragment cost. Across one cell of the 128 x 256 grid the value, and so
    // the interpolated colour, differs from a per-pixel lookup by at most a
    // few 8-bit steps. An unlit surface (the ground disc) is written as its
    // colour stands, so it gets the sRGB colour and skips the decode and the
    // fragment's re-encode.
    @location(2) base: vec3<f32>,
};

@vertex
fn vs_main(v: VsIn) -> VsOut {
    var o: VsOut;
    let world = v.pos * s.params.w;
    o.clip = g.view_proj * vec4<f32>(world, 1.0);
    o.world = world;
    o.normal = v.normal;
    let base = base_color(v.value);
    o.base = select(srgb_to_linear(base), base, s.extra.x > 0.5);
    return o;
}

fn colormap(t_in: f32) -> vec3<f32> {
    let t = clamp(t_in, 0.0, 1.0) * 10.0;
    let i = min(u32(floor(t)), 9u);
    let f = t - f32(i);
    return mix(COLORMAP[i], COLORMAP[i + 1u], f);
}

fn srgb_to_linear(c: vec3<f32>) -> vec3<f32> {
    let lo = c / 12.92;
    let hi = pow((c + 0.055) / 1.055, vec3<f32>(2.4));
    return select(hi, lo, c <= vec3<f32>(0.04045));
}

fn linear_to_srgb(c: vec3<f32>) -> vec3<f32> {
    let lo = c * 12.92;
    let hi = 1.055 * pow(c, vec3<f32>(1.0 / 2.4)) - 0.055;
    return select(hi, lo, c <= vec3<f32>(0.0031308));
}

fn base_color(value: f32) -> vec3<f32> {
    if (s.params.x > 0.5) {
        let vmax = max(s.params.y, 1e-30);
        var t = value / vmax;
        if (s.params.z > 0.5) {
            t = log(1.0 + max(value, 0.0)) / log(1.0 + vmax);
        }
        return colormap(t);
    }
    return s.color.rgb;
}

@fragment
fn fs_main(v: VsOut) -> @location(0) vec4<f32> {
    if (s.extra.x > 0.5) {
        return vec4<f32>(v.base, s.color.a);
    }
    let to_eye = normalize(g.eye.xyz - v.world);
    var n = normalize(v.normal);
    // Two-sided: the inside of a lobe is seen through its opening.
    if (dot(n, to_eye) < 0.0) {
        n = -n;
    }
    // A key light above and to the side of the eye, and a softer fill from the
    // eye itself, so the silhouette and the ridges both read.
    let key = normalize(to_eye + vec3<f32>(0.0, 0.0, 1.2));
    let diffuse = max(dot(n, key), 0.0);
    let fill = max(dot(n, to_eye), 0.0);
    let h = normalize(key + to_eye);
    // (n.h)^48 by squaring (48 = 32 + 16): exact to rounding, and a handful of
    // multiplies where pow is a log2 and an exp2 per pixel.
    let c1 = max(dot(n, h), 0.0);
    let c2 = c1 * c1;
    let c4 = c2 * c2;
    let c8 = c4 * c4;
    let c16 = c8 * c8;
    let spec = c16 * c16 * c16 * 0.25;
    let lit = v.base * (0.28 + 0.55 * diffuse + 0.25 * fill) + vec3<f32>(spec);
    return vec4<f32>(linear_to_srgb(lit), s.color.a);
}
