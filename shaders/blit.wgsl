// Copies the lobe view's offscreen image into egui's render pass.
// One triangle covers the viewport egui sets for the paint callback.
//
// `fs_main` copies the image as it stands (a multisampled target, resolved,
// or a frame drawn during a drag). `fs_smooth` copies a one-sample image
// through FXAA (Lottes 2011, "FXAA 3.11", its quality preset 12): where the
// driver pays for every sample (a CPU rasteriser), anti-aliasing the copy
// costs a few texture reads per edge pixel instead of four samples per pixel
// everywhere, and the copy is a pass the figure makes anyway.

@group(0) @binding(0) var src: texture_2d<f32>;
@group(0) @binding(1) var smp: sampler;

struct VsOut {
    @builtin(position) clip: vec4<f32>,
    @location(0) uv: vec2<f32>,
};

@vertex
fn vs_main(@builtin(vertex_index) vi: u32) -> VsOut {
    let x = f32((vi << 1u) & 2u);
    let y = f32(vi & 2u);
    var o: VsOut;
    o.clip = vec4<f32>(x * 2.0 - 1.0, 1.0 - y * 2.0, 0.0, 1.0);
    o.uv = vec2<f32>(x, y);
    return o;
}

@fragment
fn fs_main(v: VsOut) -> @location(0) vec4<f32> {
    return textureSample(src, smp, v.uv);
}

// Local contrast below the larger of these (of the brightest neighbour's
// luma, and absolute) is no edge: the smooth shading inside a lobe and the
// flat background return at the first test, after five reads.
const EDGE_THRESHOLD: f32 = 0.063;
const EDGE_THRESHOLD_MIN: f32 = 0.0312;
// How much of a pixel narrower than the edge search sees (a one-pixel grid
// line) is blended with its neighbours: FXAA's default.
const SUBPIX: f32 = 0.75;

// The image is gamma-encoded, so its green-weighted luma is perceptual as
// FXAA wants it.
fn luma(c: vec4<f32>) -> f32 {
    return dot(c.rgb, vec3<f32>(0.299, 0.587, 0.114));
}

fn at(uv: vec2<f32>) -> vec4<f32> {
    return textureSampleLevel(src, smp, uv, 0.0);
}

// The 3 x 3 neighbourhood is read texel by texel: an unfiltered read costs a
// CPU rasteriser a fraction of a filtered one, and these nine are read for
// every pixel. Only edge pixels go on to filtered reads between texels.
fn texel(p: vec2<i32>, last: vec2<i32>) -> vec4<f32> {
    return textureLoad(src, clamp(p, vec2<i32>(0), last), 0);
}

fn luma_of(p: vec2<i32>, last: vec2<i32>) -> f32 {
    return luma(texel(p, last));
}

@fragment
fn fs_smooth(v: VsOut) -> @location(0) vec4<f32> {
    let size = vec2<i32>(textureDimensions(src));
    let last = size - vec2<i32>(1);
    let px = 1.0 / vec2<f32>(size);
    let uv = v.uv;
    let p = vec2<i32>(floor(uv * vec2<f32>(size)));
    let rgba_m = texel(p, last);
    let m = luma(rgba_m);
    var n = luma_of(p + vec2<i32>(0, -1), last);
    var s = luma_of(p + vec2<i32>(0, 1), last);
    let e = luma_of(p + vec2<i32>(1, 0), last);
    let w = luma_of(p + vec2<i32>(-1, 0), last);
    let hi = max(max(max(n, s), max(e, w)), m);
    let lo = min(min(min(n, s), min(e, w)), m);
    let range = hi - lo;
    if (range < max(EDGE_THRESHOLD_MIN, hi * EDGE_THRESHOLD)) {
        return rgba_m;
    }
    let nw = luma_of(p + vec2<i32>(-1, -1), last);
    let ne = luma_of(p + vec2<i32>(1, -1), last);
    let sw = luma_of(p + vec2<i32>(-1, 1), last);
    let se = luma_of(p + vec2<i32>(1, 1), last);

    // Sub-pixel blend: how far the pixel stands out from its 3 x 3 mean.
    let mean = (2.0 * (n + s + e + w) + (nw + ne + sw + se)) / 12.0;
    let sub_c = clamp(abs(mean - m) / range, 0.0, 1.0);
    let sub_f = (-2.0 * sub_c + 3.0) * sub_c * sub_c;
    let subpix = sub_f * sub_f * SUBPIX;

    // Is the edge horizontal (luma changes along y) or vertical?
    let edge_h = abs(-2.0 * w + nw + sw) + 2.0 * abs(-2.0 * m + n + s) + abs(-2.0 * e + ne + se);
    let edge_v = abs(-2.0 * n + nw + ne) + 2.0 * abs(-2.0 * m + w + e) + abs(-2.0 * s + sw + se);
    let horizontal = edge_h >= edge_v;
    var step_len = select(px.x, px.y, horizontal);
    if (!horizontal) {
        n = w;
        s = e;
    }
    // Which side of the pixel the edge is on: the steeper neighbour.
    let grad_n = n - m;
    let grad_s = s - m;
    let pair_n = abs(grad_n) >= abs(grad_s);
    let gradient = max(abs(grad_n), abs(grad_s));
    if (pair_n) {
        step_len = -step_len;
    }
    let pair_luma = select(s + m, n + m, pair_n) * 0.5;

    // Walk both ways along the edge, half a pixel towards it, until the
    // luma there leaves the pair's mean by a quarter of the gradient.
    var pos = uv;
    if (horizontal) {
        pos.y += step_len * 0.5;
    } else {
        pos.x += step_len * 0.5;
    }
    let along = select(vec2<f32>(0.0, px.y), vec2<f32>(px.x, 0.0), horizontal);
    var pos_n = pos - along;
    var pos_p = pos + along;
    var end_n = luma(at(pos_n)) - pair_luma;
    var end_p = luma(at(pos_p)) - pair_luma;
    let scaled = gradient * 0.25;
    var done_n = abs(end_n) >= scaled;
    var done_p = abs(end_p) >= scaled;
    // Further steps along the edge, in pixels, until its end is found
    // (preset 12); an edge longer than their sum is blended as if it ended
    // there.
    var steps = array<f32, 4>(1.5, 2.0, 4.0, 12.0);
    for (var i = 0; i < 4; i++) {
        if (done_n && done_p) {
            break;
        }
        if (!done_n) {
            pos_n -= along * steps[i];
            end_n = luma(at(pos_n)) - pair_luma;
            done_n = abs(end_n) >= scaled;
        }
        if (!done_p) {
            pos_p += along * steps[i];
            end_p = luma(at(pos_p)) - pair_luma;
            done_p = abs(end_p) >= scaled;
        }
    }
    let dst_n = select(uv.y - pos_n.y, uv.x - pos_n.x, horizontal);
    let dst_p = select(pos_p.y - uv.y, pos_p.x - uv.x, horizontal);
    // The nearer end decides; it counts only where the luma there crosses
    // to the other side of the pair's mean from this pixel's.
    let m_below = m - pair_luma < 0.0;
    let nearer_n = dst_n < dst_p;
    let good = select((end_p < 0.0) != m_below, (end_n < 0.0) != m_below, nearer_n);
    let span = dst_n + dst_p;
    let offset = select(0.0, 0.5 - min(dst_n, dst_p) / span, good);
    let shift = max(offset, subpix) * step_len;
    var out_uv = uv;
    if (horizontal) {
        out_uv.y += shift;
    } else {
        out_uv.x += shift;
    }
    return at(out_uv);
}
