// Cook–Torrance with the GGX distribution (Walter et al. 2007, eq. 33),
// Smith's separable masking (eq. 34) and Schlick's Fresnel (1994): a BRDF of
// the size bv's users write, for the interpreter's tests and timing.
const PI: f32 = 3.14159265358979;

var<private> alpha: f32 = 0.3;
var<private> f0: vec3<f32> = vec3(0.04);
var<private> albedo: vec3<f32> = vec3(0.5);

fn d_ggx(nh: f32, a: f32) -> f32 {
    let a2 = a * a;
    let d = nh * nh * (a2 - 1.0) + 1.0;
    return a2 / (PI * d * d);
}

fn g1(nx: f32, a: f32) -> f32 {
    let a2 = a * a;
    return 2.0 * nx / (nx + sqrt(a2 + (1.0 - a2) * nx * nx));
}

fn fresnel(f: vec3<f32>, vh: f32) -> vec3<f32> {
    return f + (vec3(1.0) - f) * pow(1.0 - vh, 5.0);
}

fn brdf(l: vec3<f32>, v: vec3<f32>, n: vec3<f32>) -> vec3<f32> {
    let nl = max(dot(n, l), 0.0);
    let nv = max(dot(n, v), 0.0);
    if (nl <= 0.0 || nv <= 0.0) {
        return vec3(0.0);
    }
    let h = normalize(l + v);
    let nh = max(dot(n, h), 0.0);
    let vh = max(dot(v, h), 0.0);
    let spec = fresnel(f0, vh) * d_ggx(nh, alpha) * g1(nl, alpha) * g1(nv, alpha) / (4.0 * nl * nv);
    return albedo / PI + spec;
}

@fragment
fn main() -> @location(0) vec4<f32> {
    return vec4(brdf(vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 1.0)), 1.0);
}
