// Screen-space thick lines for the lobe view's axes, rays, spikes and grid
//. Each instance is one segment; six vertices make its quad,
// widened in pixels after projection so widths do not depend on the zoom.
//
// The quad is half a pixel wider on each side than the line, and the
// fragment covers the line's share of each pixel across it (analytic
// anti-aliasing): the long sides are smooth with one sample per pixel, where
// the renderer does not multisample (a CPU rasteriser).

struct Globals {
    view_proj: mat4x4<f32>,
    eye: vec4<f32>,
    // xy: target size in pixels.
    viewport: vec4<f32>,
};

@group(0) @binding(0) var<uniform> g: Globals;

struct Seg {
    @location(0) a: vec3<f32>,
    @location(1) b: vec3<f32>,
    // rgb: sRGB colour, a: opacity.
    @location(2) color: vec4<f32>,
    // x: width in pixels.
    @location(3) width: vec4<f32>,
};

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) color: vec4<f32>,
    // Signed distance from the line's centre across it in pixels, times
    // the clip w: divided by the interpolated w it is interpolated linearly
    // in screen space, which the ends of a line at different depths need
    // (WebGL2 has no `@interpolate(linear)`).
    @location(1) across_w: f32,
    @location(2) w: f32,
    // The line's width in pixels.
    @location(3) width: f32,
};

@vertex
fn vs_main(@builtin(vertex_index) vi: u32, seg: Seg) -> VsOut {
    let ca = g.view_proj * vec4<f32>(seg.a, 1.0);
    let cb = g.view_proj * vec4<f32>(seg.b, 1.0);
    let px = g.viewport.xy;
    let sa = ca.xy / max(ca.w, 1e-6) * px;
    let sb = cb.xy / max(cb.w, 1e-6) * px;
    var d = sb - sa;
    if (length(d) < 1e-6) {
        d = vec2<f32>(1.0, 0.0);
    }
    d = normalize(d);
    let nrm = vec2<f32>(-d.y, d.x);
    // Corner table: (t, side) for two triangles.
    var t = array<f32, 6>(0.0, 0.0, 1.0, 0.0, 1.0, 1.0);
    var side = array<f32, 6>(-1.0, 1.0, 1.0, -1.0, 1.0, -1.0);
    let k = t[vi];
    var c = mix(ca, cb, k);
    // Half the width and half a pixel on each side, in NDC units (2 per
    // viewport).
    let half = 0.5 * seg.width.x + 0.5;
    let offset = nrm * side[vi] * 2.0 * half / px;
    c = vec4<f32>(c.xy + offset * c.w, c.zw);
    var o: VsOut;
    o.clip = c;
    o.color = seg.color;
    o.across_w = side[vi] * half * c.w;
    o.w = c.w;
    o.width = seg.width.x;
    return o;
}

@fragment
fn fs_main(v: VsOut) -> @location(0) vec4<f32> {
    // The share of a pixel at this distance the line covers: all of it
    // inside, falling to none half a pixel beyond the edge, and at most the
    // width for a line thinner than a pixel.
    let across = v.across_w / v.w;
    let cover = clamp(min(0.5 * v.width + 0.5 - abs(across), v.width), 0.0, 1.0);
    return vec4<f32>(v.color.rgb, v.color.a * cover);
}
