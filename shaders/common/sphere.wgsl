// Image-space geometry of the sphere views: N spheres side by side, each in
// its tile, orthographic, seen along −z (viewer direction +z), with a tangent
// frame whose tangent follows the parallels about the vertical axis (the
// direction of increasing longitude), so that anisotropic models show their
// stretched highlights. src/gpu/sphere.rs has the same geometry in Rust.
#define_import_path bv::sphere

// Fraction of the tile's smaller side that the sphere's diameter covers.
const FILL: f32 = 0.9;

struct SpherePoint {
    // Which sphere (tile); -1 for the background.
    tile: i32,
    // Unit normal in view space (x right, y up, z towards the viewer).
    n: vec3<f32>,
    // Unit tangent and bitangent (t along the parallel, b = n × t).
    t: vec3<f32>,
    b: vec3<f32>,
}

// The sphere point under pixel position p (pixel units, y down, centres at +0.5).
fn sphere_at(p: vec2<f32>, size: vec2<f32>, tiles: u32) -> SpherePoint {
    var out: SpherePoint;
    let tile_w = size.x / f32(tiles);
    let tile = min(u32(floor(p.x / tile_w)), tiles - 1u);
    let cx = (f32(tile) + 0.5) * tile_w;
    let cy = 0.5 * size.y;
    let r = 0.5 * FILL * min(tile_w, size.y);
    let u = (p.x - cx) / r;
    let v = (cy - p.y) / r;
    let d2 = u * u + v * v;
    if (d2 >= 1.0) {
        out.tile = -1;
        return out;
    }
    out.tile = i32(tile);
    out.n = vec3<f32>(u, v, sqrt(1.0 - d2));
    // t = normalize(ŷ × n) = (n.z, 0, −n.x)/√(n.x² + n.z²); at the poles
    // (only reachable at the silhouette's top and bottom) fall back to +x.
    let l = sqrt(out.n.x * out.n.x + out.n.z * out.n.z);
    if (l > 0.0) {
        out.t = vec3<f32>(out.n.z, 0.0, -out.n.x) / l;
    } else {
        out.t = vec3<f32>(1.0, 0.0, 0.0);
    }
    out.b = cross(out.n, out.t);
    return out;
}

// The point with its tangent frame turned about the normal by `angle`
// (radians, from t towards b): the surface turned about its normal.
fn turned(s: SpherePoint, angle: f32) -> SpherePoint {
    var out = s;
    let c = cos(angle);
    let sn = sin(angle);
    out.t = c * s.t + sn * s.b;
    out.b = c * s.b - sn * s.t;
    return out;
}

// A view-space direction in the point's local shading frame .
fn to_local(s: SpherePoint, w: vec3<f32>) -> vec3<f32> {
    return vec3<f32>(dot(w, s.t), dot(w, s.b), dot(w, s.n));
}

// A local direction back in view space.
fn to_view(s: SpherePoint, w: vec3<f32>) -> vec3<f32> {
    return w.x * s.t + w.y * s.b + w.z * s.n;
}
