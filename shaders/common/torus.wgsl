// The torus of the environment view: one per tile, centred where the sphere
// would be, in units of the sphere's radius, its ring tilted towards the
// viewer so that the hole and the inner side show. Found by sphere tracing of
// its exact distance function (orthographic rays along −z); the shading frame
// has its tangent along the ring (increasing longitude about the torus axis),
// the torus' counterpart of the sphere's parallels, so anisotropic models
// show. src/gpu/torus.rs has the same geometry in Rust.
#define_import_path bv::torus

#import bv::sphere::{SpherePoint, tile_at}

// Radius of the ring's centre line and of its tube (outer radius 0.96 < 1).
const MAJOR: f32 = 0.64;
const MINOR: f32 = 0.32;
// Unit axis of the ring: up, tilted 40° towards the viewer.
const AXIS: vec3<f32> = vec3<f32>(0.0, 0.76604444, 0.64278761);
// Sphere tracing: hit threshold, step limit.
const EPS: f32 = 1e-4;
const STEPS: i32 = 200;
// Bounding sphere radius (rays beyond it cannot hit).
const BOUND: f32 = 1.0;

// Signed distance from p (object space) to the torus' surface.
fn sdf(p: vec3<f32>) -> f32 {
    let h = dot(p, AXIS);
    let q = length(p - h * AXIS) - MAJOR;
    return sqrt(q * q + h * h) - MINOR;
}

// Outward unit normal at (or near) surface point p.
fn normal(p: vec3<f32>) -> vec3<f32> {
    let h = dot(p, AXIS);
    let radial = p - h * AXIS;
    let l = length(radial);
    // The closest point of the centre circle (any point of it on the axis).
    var c = vec3<f32>(MAJOR, 0.0, 0.0);
    if (l > 0.0) {
        c = radial * (MAJOR / l);
    }
    return normalize(p - c);
}

// Shading frame at surface point p: t = AXIS × p normalised (along the ring;
// AXIS × p is orthogonal to n because n lies in the plane of p and AXIS).
fn frame(p: vec3<f32>, tile: i32) -> SpherePoint {
    var s: SpherePoint;
    s.tile = tile;
    s.n = normal(p);
    var t = cross(AXIS, p);
    t = t - dot(t, s.n) * s.n;
    let l = length(t);
    if (l > 0.0) {
        s.t = t / l;
    } else {
        // Only on the axis, which is not on the surface.
        s.t = normalize(cross(vec3<f32>(0.0, 1.0, 0.0), s.n) + vec3<f32>(1e-6, 0.0, 0.0));
    }
    s.b = cross(s.n, s.t);
    return s;
}

// Distance along o + s d (d unit) to the surface, or −1 when the ray leaves
// the bounding sphere (or runs out of steps) first.
fn trace(o: vec3<f32>, d: vec3<f32>) -> f32 {
    var s = 0.0;
    for (var k = 0; k < STEPS; k++) {
        let p = o + s * d;
        let dist = sdf(p);
        if (dist < EPS) {
            return s;
        }
        s += dist;
        let q = o + s * d;
        if (dot(q, q) > BOUND * BOUND && dot(q, d) > 0.0) {
            return -1.0;
        }
    }
    return -1.0;
}

// Whether direction d (unit, object/view space) from surface point p with
// normal n escapes to the environment.
fn unoccluded(p: vec3<f32>, n: vec3<f32>, d: vec3<f32>) -> bool {
    return trace(p + n * (4.0 * EPS), d) < 0.0;
}

// Distance from surface point p (inward normal −n) along d, travelling inside,
// to where the ray leaves the torus; −1 if it does not within the step limit.
fn trace_inside(p: vec3<f32>, n: vec3<f32>, d: vec3<f32>) -> f32 {
    let o = p - n * (4.0 * EPS);
    var s = 0.0;
    for (var k = 0; k < STEPS; k++) {
        let dist = -sdf(o + s * d);
        if (dist < EPS) {
            return s;
        }
        s += dist;
    }
    return -1.0;
}

struct TorusHit {
    // Frame (tile −1: background).
    s: SpherePoint,
    // Object-space position of the hit (units of the tile's radius).
    p: vec3<f32>,
}

// The torus point under pixel position p (the same tiles as sphere_at).
fn torus_at(px: vec2<f32>, size: vec2<f32>, tiles: u32, cols: u32) -> TorusHit {
    var out: TorusHit;
    out.s.tile = -1;
    let cell = tile_at(px, size, tiles, cols);
    let tile = cell.index;
    let cx = cell.centre.x;
    let cy = cell.centre.y;
    let r = cell.r;
    let u = (px.x - cx) / r;
    let v = (cy - px.y) / r;
    let d2 = u * u + v * v;
    if (d2 >= BOUND * BOUND) {
        return out;
    }
    // Start on the bounding sphere, facing −z.
    let o = vec3<f32>(u, v, sqrt(BOUND * BOUND - d2));
    let s = trace(o, vec3<f32>(0.0, 0.0, -1.0));
    if (s < 0.0) {
        return out;
    }
    out.p = o + vec3<f32>(0.0, 0.0, -s);
    out.s = frame(out.p, i32(tile));
    return out;
}
