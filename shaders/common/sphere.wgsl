// Image-space geometry of the sphere views: N spheres in a grid of tiles
// (`cols` to a row, the last row centred; src/gpu/sphere.rs, Grid, chooses
// `cols`), each in its tile, orthographic, seen along −z (viewer direction +z), with a tangent
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

// Which tile holds pixel position p, its sphere's centre and radius (pixels).
struct Tile {
    index: u32,
    centre: vec2<f32>,
    r: f32,
}

// The tile of p: its row, then its column within the row's centred tiles
// (a point in a row's margin goes to the row's nearest tile).
fn tile_at(p: vec2<f32>, size: vec2<f32>, tiles: u32, cols: u32) -> Tile {
    var out: Tile;
    let rows = (tiles + cols - 1u) / cols;
    let tw = size.x / f32(cols);
    let th = size.y / f32(rows);
    let row = min(u32(max(floor(p.y / th), 0.0)), rows - 1u);
    let n = min(cols, tiles - row * cols);
    let off = 0.5 * f32(cols - n) * tw;
    let col = min(u32(max(floor((p.x - off) / tw), 0.0)), n - 1u);
    out.index = row * cols + col;
    out.centre = vec2<f32>(off + (f32(col) + 0.5) * tw, (f32(row) + 0.5) * th);
    out.r = 0.5 * FILL * min(tw, th);
    return out;
}

// The sphere point under pixel position p (pixel units, y down, centres at +0.5).
fn sphere_at(p: vec2<f32>, size: vec2<f32>, tiles: u32, cols: u32) -> SpherePoint {
    var out: SpherePoint;
    let cell = tile_at(p, size, tiles, cols);
    let tile = cell.index;
    let cx = cell.centre.x;
    let cy = cell.centre.y;
    let r = cell.r;
    let u = (p.x - cx) / r;
    let v = (cy - p.y) / r;
    let d2 = u * u + v * v;
    if (d2 >= 1.0) {
        out.tile = -1;
        return out;
    }
    return frame_at(vec3<f32>(u, v, sqrt(1.0 - d2)), i32(tile));
}

// The sphere's frame at unit normal n (view space): the tangent along the
// parallel about the vertical axis, t = normalize(ŷ × n) = (n.z, 0, −n.x)/
// √(n.x² + n.z²); at the poles (only reachable at the silhouette's top and
// bottom, or from inside the sphere) +x.
fn frame_at(n: vec3<f32>, tile: i32) -> SpherePoint {
    var out: SpherePoint;
    out.tile = tile;
    out.n = n;
    let l = sqrt(n.x * n.x + n.z * n.z);
    if (l > 0.0) {
        out.t = vec3<f32>(n.z, 0.0, -n.x) / l;
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
