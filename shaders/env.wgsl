// Environment lighting: spheres under an equirectangular
// environment, one BRDF sample and one environment sample per pixel and pass,
// combined with the power heuristic (Veach & Guibas 1995), accumulated into a
// float buffer across frames. Models with delta lobes (their GPU ports
// declare them: a mirror reflection, or reflection and refraction into a
// dielectric) add their exact specular paths, through the generated dispatch.
#import bv::brdf
#import bv::brdf_sampling
#import bv::envmap
#import bv::params::{pf, pu}
#import bv::layout as L
#import bv::dispatch
#import bv::frame::PI
#import bv::sampling::{pcg, rand}
#import bv::sphere::{sphere_at, tile_at, frame_at, to_local, to_view, turned, SpherePoint}
#import bv::torus

struct Frame {
    size: vec2<f32>,
    tiles: u32,
    // Index of this pass since the last restart (the sampler uses `base`).
    frame: u32,
    // Samples of each strategy per pixel in this pass.
    spp: u32,
    // tan of half the background's field of view.
    fov_tan: f32,
    // 0: spheres, 1: tori (src/gpu/env.rs, Object).
    object: u32,
    // Samples per pixel accumulated before this pass (index of its first
    // sample in each pixel's sequence).
    base: u32,
    // The pixel columns of this dispatch, [x0, x1): one tile, drawn by the
    // pipeline specialised for its model (the dispatch starts at x0).
    x0: u32,
    x1: u32,
    // The rows of this dispatch, [y0, y1): the accumulation buffer bound
    // holds only them (a large image is split into bands that each fit the
    // device's storage binding limit; the dispatch starts at y0).
    y0: u32,
    y1: u32,
    // The surface turned about its normal (radians).
    turn: f32,
    // Tiles in a full row (src/gpu/sphere.rs, Grid).
    cols: u32,
    // The first row of the accumulation buffer bound (its band's; a tile's
    // rows [y0, y1) may start lower in the band).
    band: u32,
    // Object 2, the plane: the eye's elevation above it (radians).
    elevation: f32,
}

// Roberts' R_d low-discrepancy sequences ("The unreasonable effectiveness of
// quasirandom sequences", 2018): point n is fract(shift + n·α) with
// α_i = φ_d^−i, φ_d the positive root of x^(d+1) = x + 1. Kept in 0.32 fixed
// point so that n·α wraps exactly (an f32 product loses the fraction after a
// few thousand samples). Each pixel gets its own random shift (Cranley-
// Patterson rotation), so every sample is still uniform (the estimate stays
// unbiased) while the samples of one pixel are stratified, which takes the
// visible noise down much faster than independent random numbers.
const R3: vec3<u32> = vec3<u32>(3518319155u, 2882110345u, 2360945575u);
const R4: vec4<u32> = vec4<u32>(3679390609u, 3152041523u, 2700274806u, 2313257605u);

fn unit(v: u32) -> f32 {
    return f32(v >> 8u) * (1.0 / 16777216.0);
}

fn r3(shift: vec3<u32>, n: u32) -> vec3<f32> {
    let v = shift + n * R3;
    return vec3<f32>(unit(v.x), unit(v.y), unit(v.z));
}

fn r4(shift: vec4<u32>, n: u32) -> vec4<f32> {
    let v = shift + n * R4;
    return vec4<f32>(unit(v.x), unit(v.y), unit(v.z), unit(v.w));
}

// The model of every tile when the pipeline is specialised for one model
// (src/gpu/shaders.rs, specialised_wgsl, which replaces this line); the
// generic pipeline reads it per tile.
const FIXED_MODEL: u32 = 0xffffffffu;

@group(0) @binding(1) var<uniform> view: Frame;
@group(0) @binding(2) var<storage, read> models: array<vec2<u32>>;
// Running sums of radiance per pixel (rgb) and the number of samples (a).
@group(0) @binding(3) var<storage, read_write> accum: array<vec4<f32>>;

fn balance2(a: f32, b: f32) -> f32 {
    let a2 = a * a;
    return a2 / (a2 + b * b);
}

// Radiance of a refracting (glass) sphere along the view ray entering at normal n (view
// space; sphere of radius 1 at the origin): Fresnel reflection plus the
// refracted path through the ball, with internal reflections (up to 8 exits).
fn glass_path(model: u32, o: u32, n: vec3<f32>) -> vec3<f32> {
    let eta = dispatch::delta_eta(model, o);
    let d = vec3<f32>(0.0, 0.0, -1.0);
    let c = -dot(d, n);
    let f = dispatch::delta_reflectance(model, o, c);
    var l = f * envmap::radiance(reflect(d, n));
    var dir = refract(d, n, 1.0 / eta);
    if (dot(dir, dir) == 0.0) {
        return l;
    }
    var p = n;
    var through = vec3<f32>(1.0) - f;
    for (var k = 0; k < 8; k++) {
        // Next hit of the unit sphere from inside: p + t dir with t = −2 p·dir.
        p = p + (-2.0 * dot(p, dir)) * dir;
        let m = normalize(p);
        let ci = dot(dir, m);
        // From inside: the Fresnel term of the interface seen from −z.
        let fi = dispatch::delta_reflectance(model, o, -ci);
        let out = refract(dir, -m, eta);
        if (dot(out, out) > 0.0) {
            l += through * (1.0 - fi) * envmap::radiance(out);
        }
        through *= fi;
        dir = reflect(dir, -m);
        if (max(through.x, max(through.y, through.z)) < 1e-4) {
            break;
        }
    }
    return l;
}

// The environment mirrored at s about its normal, seen from v (towards the
// eye), weighted by the delta model's reflectance there.
fn mirrored(model: u32, o: u32, s: SpherePoint, v: vec3<f32>) -> vec3<f32> {
    let c = dot(v, s.n);
    return dispatch::delta_reflectance(model, o, c) * envmap::radiance(2.0 * c * s.n - v);
}

// Radiance of the delta parts of a (non-mix) model at sphere point s seen
// from v (towards the eye, view space).
fn delta_leaf(model: u32, o: u32, s: SpherePoint, v: vec3<f32>) -> vec3<f32> {
    let kind = dispatch::delta_kind(model);
    if (kind == dispatch::DELTA_REFLECTION) {
        return mirrored(model, o, s, v);
    }
    if (kind == dispatch::DELTA_REFRACTION) {
        return glass_path(model, o, s.n);
    }
    return vec3<f32>(0.0);
}

// The plane's delta parts: a smooth interface over a dark, opaque floor
// (LECTURE.md N13, "a glass-coated dark floor"): what it reflects, F; what
// it refracts is absorbed below and never comes back.
fn delta_leaf_plane(model: u32, o: u32, s: SpherePoint, v: vec3<f32>) -> vec3<f32> {
    if (dispatch::delta_kind(model) == dispatch::DELTA_NONE) {
        return vec3<f32>(0.0);
    }
    return mirrored(model, o, s, v);
}

// The environment seen from torus point p (normal n) along d: 0 where the
// torus itself is in the way (direct lighting only, no interreflection).
fn torus_radiance(p: vec3<f32>, n: vec3<f32>, d: vec3<f32>) -> vec3<f32> {
    if (torus::unoccluded(p, n, d)) {
        return envmap::radiance(d);
    }
    return vec3<f32>(0.0);
}

// glass_path for the torus: the refracted path is traced through the tube by
// its distance function (up to 8 exits); light leaving the tube is taken from
// the environment even where it would meet the torus again.
fn glass_path_torus(model: u32, o: u32, p0: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let eta = dispatch::delta_eta(model, o);
    let d = vec3<f32>(0.0, 0.0, -1.0);
    let c = -dot(d, n);
    let f = dispatch::delta_reflectance(model, o, c);
    var l = f * torus_radiance(p0, n, reflect(d, n));
    var dir = refract(d, n, 1.0 / eta);
    if (dot(dir, dir) == 0.0) {
        return l;
    }
    var p = p0;
    var m_in = n;
    var through = vec3<f32>(1.0) - f;
    for (var k = 0; k < 8; k++) {
        let t = torus::trace_inside(p, m_in, dir);
        if (t < 0.0) {
            break;
        }
        p = p + t * dir;
        let m = torus::normal(p);
        let ci = dot(dir, m);
        let fi = dispatch::delta_reflectance(model, o, -ci);
        let out = refract(dir, -m, eta);
        if (dot(out, out) > 0.0) {
            l += through * (1.0 - fi) * envmap::radiance(out);
        }
        through *= fi;
        dir = reflect(dir, -m);
        m_in = m;
        if (max(through.x, max(through.y, through.z)) < 1e-4) {
            break;
        }
    }
    return l;
}

fn delta_leaf_torus(model: u32, o: u32, s: SpherePoint, p: vec3<f32>) -> vec3<f32> {
    let kind = dispatch::delta_kind(model);
    if (kind == dispatch::DELTA_REFLECTION) {
        let v = vec3<f32>(0.0, 0.0, 1.0);
        let c = dot(v, s.n);
        return dispatch::delta_reflectance(model, o, c) * torus_radiance(p, s.n, 2.0 * c * s.n - v);
    }
    if (kind == dispatch::DELTA_REFRACTION) {
        return glass_path_torus(model, o, p, s.n);
    }
    return vec3<f32>(0.0);
}

fn delta_any(model: u32, o: u32, s: SpherePoint, p: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    if (view.object == 1u) {
        return delta_leaf_torus(model, o, s, p);
    }
    if (view.object == 2u) {
        return delta_leaf_plane(model, o, s, v);
    }
    return delta_leaf(model, o, s, v);
}

fn delta_radiance(model: u32, o: u32, s: SpherePoint, p: vec3<f32>, v: vec3<f32>) -> vec3<f32> {
    if (model != L::MODEL_MIX) {
        return delta_any(model, o, s, p, v);
    }
    let n = pu(o + L::MIX_COMPONENTS);
    let table = pu(o + L::MIX_COMPONENTS + 1u);
    var sum = vec3<f32>(0.0);
    for (var j = 0u; j < n; j++) {
        let e = table + L::COMPONENT_ENTRY_SLOTS * j;
        sum += pf(e) * delta_any(pu(e + 1u), pu(e + 2u), s, p, v);
    }
    return sum;
}

// Most interfaces a path through a transmitting object crosses or reflects
// off inside it (src/gpu/env.rs, MAX_BOUNCES, which the view shows).
const MAX_BOUNCES: u32 = 16u;

// Radiance of the light that reaches the object's surface point s (position
// x: the unit normal on the sphere, the hit on the torus) from inside, along
// the local direction wi (below the surface), with the weight `thr` of the
// draw so far: the path is followed from interface to interface (reflected
// inside, total internal reflection included, or out to the environment),
// each step drawn by the model's own sampler on the whole sphere, up to
// MAX_BOUNCES (the rest counts as dark). Issue 33: frosted glass.
fn through_object(model: u32, o: u32, s: SpherePoint, x: vec3<f32>, wi: vec3<f32>, thr_in: vec3<f32>, seed: u32) -> vec3<f32> {
    var thr = thr_in;
    var p = x;
    var n_in = s.n;
    var dir = to_view(s, wi);
    var state = seed;
    for (var k = 0u; k < MAX_BOUNCES; k++) {
        var q: vec3<f32>;
        var fr: SpherePoint;
        if (view.object == 1u) {
            let t = torus::trace_inside(p, n_in, dir);
            if (t < 0.0) {
                return vec3<f32>(0.0);
            }
            q = p + t * dir;
            fr = torus::frame(q, 0);
        } else {
            // The unit sphere from inside: p + t dir with t = −2 p·dir.
            q = p + (-2.0 * dot(p, dir)) * dir;
            fr = frame_at(normalize(q), 0);
        }
        fr = turned(fr, view.turn);
        // Towards where the path came from: inside, below this interface.
        let wo = to_local(fr, -dir);
        let u = vec3<f32>(rand(&state), rand(&state), rand(&state));
        let smp = dispatch::sample_sphere(model, o, wo, u);
        if (smp.wi.z == 0.0) {
            return vec3<f32>(0.0);
        }
        thr *= smp.weight;
        let d = to_view(fr, smp.wi);
        if (smp.wi.z > 0.0) {
            // The light comes from outside: the path leaves the object.
            if (view.object == 1u) {
                return thr * torus_radiance(q, fr.n, d);
            }
            return thr * envmap::radiance(d);
        }
        p = q;
        n_in = fr.n;
        dir = d;
    }
    return vec3<f32>(0.0);
}

// A pixel of the plane object (LECTURE.md N13): each tile shows, in the
// square the sphere would fill, a flat sample of infinite extent under
// the environment, seen through a pinhole camera (the background's field of
// view) pitched down by `elevation` towards it. Only directions matter
// (the environment is distant and the plane casts no shadow on itself),
// so the camera has no position.
struct PlaneHit {
    // The floor's frame (tile −1 where the ray misses it or leaves the tile's square).
    s: SpherePoint,
    // Towards the eye (view space).
    v: vec3<f32>,
    // Inside the tile's square: above the horizon the ray sees the sky, −v.
    inside: bool,
}

fn plane_at(p: vec2<f32>) -> PlaneHit {
    var out: PlaneHit;
    out.s.tile = -1;
    out.inside = false;
    let cell = tile_at(p, view.size, view.tiles, view.cols);
    let q = (p - cell.centre) / cell.r;
    if (abs(q.x) > 1.0 || abs(q.y) > 1.0) {
        return out;
    }
    out.inside = true;
    let e = view.elevation;
    // Forward, up and right of the camera (view space: y up, z to the viewer).
    let f = vec3<f32>(0.0, -sin(e), -cos(e));
    let up = vec3<f32>(0.0, cos(e), -sin(e));
    let d = normalize(f + view.fov_tan * (q.x * vec3<f32>(1.0, 0.0, 0.0) - q.y * up));
    out.v = -d;
    if (d.y >= 0.0) {
        return out;
    }
    out.s.tile = i32(cell.index);
    out.s.n = vec3<f32>(0.0, 1.0, 0.0);
    out.s.t = vec3<f32>(1.0, 0.0, 0.0);
    out.s.b = cross(out.s.n, out.s.t);
    return out;
}

@compute @workgroup_size(8, 8)
fn accumulate(@builtin(global_invocation_id) id: vec3<u32>) {
    let w = u32(view.size.x);
    let h = u32(view.size.y);
    let px = id.x + view.x0;
    let py = id.y + view.y0;
    if (px >= min(view.x1, w) || py >= min(view.y1, h)) {
        return;
    }
    // The whole image's pixel index seeds the sequences, so the image does
    // not depend on the split into bands.
    let pixel = py * w + px;
    let p = vec2<f32>(f32(px), f32(py)) + vec2<f32>(0.5);
    let on_torus = view.object == 1u;
    var s: SpherePoint;
    var x = vec3<f32>(0.0);
    // Towards the eye: the orthographic view's +z, or the plane's camera ray.
    var v = vec3<f32>(0.0, 0.0, 1.0);
    var sky = false;
    if (on_torus) {
        let hit = torus::torus_at(p, view.size, view.tiles, view.cols);
        s = hit.s;
        x = hit.p;
    } else if (view.object == 2u) {
        let hit = plane_at(p);
        s = hit.s;
        v = hit.v;
        sky = hit.inside;
    } else {
        s = sphere_at(p, view.size, view.tiles, view.cols);
    }
    s = turned(s, view.turn);
    var sum = vec3<f32>(0.0);
    if (s.tile < 0) {
        // Background: the environment through a pinhole of the given field
        // of view; in the plane's square, through its camera.
        let q = (p - 0.5 * view.size) / (0.5 * view.size.y) * view.fov_tan;
        var dir = normalize(vec3<f32>(q.x, -q.y, -1.0));
        if (sky) {
            dir = -v;
        }
        sum = envmap::radiance(dir) * f32(view.spp);
    } else {
        let m = models[u32(s.tile)];
        let model = select(m.x, FIXED_MODEL, FIXED_MODEL != 0xffffffffu);
        let wo = to_local(s, v);
        // The pixel's shifts: fixed for the whole accumulation (the sequence
        // goes on across passes through view.base).
        let h0 = pcg(pixel * 7919u + 17u);
        let h1 = pcg(h0 ^ 0x9e3779b9u);
        let h2 = pcg(h1 ^ 0x85ebca6bu);
        let h3 = pcg(h2 ^ 0xc2b2ae35u);
        let h4 = pcg(h3 ^ 0x27d4eb2fu);
        let h5 = pcg(h4 ^ 0x165667b1u);
        let h6 = pcg(h5 ^ 0xd3a2646cu);
        let shift_b = vec3<u32>(h0, h1, h2);
        let shift_e = vec4<u32>(h3, h4, h5, h6);
        // A transmitting model: its own draws on the whole sphere, the
        // light that enters followed through the object (on the plane, into
        // a dark floor, where it is lost).
        let through = dispatch::transmits(model);
        for (var k = 0u; through && k < view.spp; k++) {
            let n = view.base + k;
            let smp = dispatch::sample_sphere(model, m.y, wo, r3(shift_b, n));
            let d = to_view(s, smp.wi);
            if (smp.wi.z > 0.0) {
                if (!on_torus || torus::unoccluded(x, s.n, d)) {
                    sum += smp.weight * envmap::radiance(d);
                }
            } else if (smp.wi.z < 0.0 && view.object != 2u) {
                let at = select(s.n, x, on_torus);
                sum += through_object(model, m.y, s, at, smp.wi, smp.weight, pcg(pixel * 9781u + n * 6271u + 1u));
            }
        }
        for (var k = 0u; !through && k < view.spp; k++) {
            let n = view.base + k;
            // BRDF strategy.
            let u = r3(shift_b, n);
            let wi = brdf_sampling::sample(model, m.y, wo, u);
            if (wi.z > 0.0) {
                let pb = brdf_sampling::pdf(model, m.y, wo, wi);
                if (pb > 0.0) {
                    let d = to_view(s, wi);
                    let pe = envmap::pdf(d);
                    let f = brdf::eval(model, m.y, wi, wo);
                    let c = f * wi.z * (balance2(pb, pe) / pb);
                    // Trace the shadow ray only where it matters.
                    if (any(c > vec3<f32>(0.0)) && (!on_torus || torus::unoccluded(x, s.n, d))) {
                        sum += c * envmap::radiance(d);
                    }
                }
            }
            // Environment strategy.
            if (envmap::env.sampling != 0u) {
                let ue = r4(shift_e, n);
                let d = envmap::sample(ue);
                let wi2 = to_local(s, d);
                let pe = envmap::pdf(d);
                if (wi2.z > 0.0 && pe > 0.0) {
                    let pb = brdf_sampling::pdf(model, m.y, wo, wi2);
                    let f = brdf::eval(model, m.y, wi2, wo);
                    let c = f * wi2.z * (balance2(pe, pb) / pe);
                    if (any(c > vec3<f32>(0.0)) && (!on_torus || torus::unoccluded(x, s.n, d))) {
                        sum += c * envmap::radiance(d);
                    }
                }
            }
        }
        sum += delta_radiance(model, m.y, s, x, v) * f32(view.spp);
    }
    accum[(py - view.band) * w + px] += vec4<f32>(sum, f32(view.spp));
}
