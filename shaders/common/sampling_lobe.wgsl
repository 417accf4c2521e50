// The proxy lobe the environment renderer importance-samples for a model:
// a mixture of (a) cosine-weighted directions and (b) one glossy lobe shaped
// from the model's parameters, either a power-cosine lobe about an axis
// (Phong family, Lafortune) or GGX visible normals reflected about h
// (half-vector models), with a GGX roughness matched to the model's lobe
// width. Each model's module defines `fn sampling_lobe(o: u32, wo:
// vec3<f32>) -> Lobe` with these helpers; bv::brdf_sampling draws from it.
#define_import_path bv::sampling_lobe

const LOBE_NONE: u32 = 0u;
const LOBE_POWER: u32 = 1u;
const LOBE_GGX: u32 = 2u;

// The sampling lobe of one (non-mix) model seen from wo.
struct Lobe {
    kind: u32,
    // Probability of the cosine part.
    p_cos: f32,
    // LOBE_POWER: axis and exponent; LOBE_GGX: roughness (ax, ay).
    axis: vec3<f32>,
    e: f32,
    ax: f32,
    ay: f32,
}

fn mean3(c: vec3<f32>) -> f32 {
    return (c.x + c.y + c.z) / 3.0;
}

// Cosine probability from diffuse and glossy weights, kept in [0.1, 0.9]
// (a lobe always gets some samples: its albedo may exceed these estimates).
fn p_cos_of(d: f32, s: f32) -> f32 {
    if (d + s <= 0.0) {
        return 0.5;
    }
    return clamp(d / (d + s), 0.1, 0.9);
}

// GGX roughness whose lobe is about as wide as a cos^e lobe (α² ≈ 2/(e + 2),
// the Beckmann-Phong correspondence of Walter et al. 2007, §5.2).
fn alpha_of_exponent(e: f32) -> f32 {
    return clamp(sqrt(2.0 / (e + 2.0)), 0.001, 1.0);
}

// Cosine sampling only.
fn none_lobe() -> Lobe {
    return Lobe(LOBE_NONE, 1.0, vec3<f32>(0.0, 0.0, 1.0), 0.0, 0.0, 0.0);
}

fn power_lobe(p: f32, axis: vec3<f32>, e: f32) -> Lobe {
    return Lobe(LOBE_POWER, p, axis, e, 0.0, 0.0);
}

fn ggx_lobe(p: f32, ax: f32, ay: f32) -> Lobe {
    return Lobe(LOBE_GGX, p, vec3<f32>(0.0, 0.0, 1.0), 0.0, clamp(ax, 0.001, 1.0), clamp(ay, 0.001, 1.0));
}

// A direction drawn on the whole sphere by a transmitting model's own
// sampler (`fn sample_sphere(o, wo, u) -> SphereSample` in its module): the
// environment renderer follows such a model's light through the object.
struct SphereSample {
    // Towards the light, either side of the surface (0 when nothing was drawn).
    wi: vec3<f32>,
    // f(wi, wo) |cos θi| / pdf(wi).
    weight: vec3<f32>,
}

fn no_sphere_sample() -> SphereSample {
    var s: SphereSample;
    s.wi = vec3<f32>(0.0);
    s.weight = vec3<f32>(0.0);
    return s;
}
