// Banks 1994 fibre model along t = +x (bv_core::models::banks):
// kd sin αi + ks max(0, sin αi sin αo − cos αi cos αo)^e.
#define_import_path bv::models::banks

#import bv::params::{pf, prgb}
#import bv::frame::log1p
#import bv::layout::{BANKS_KD, BANKS_KS, BANKS_E}

fn eval(o: u32, wi: vec3<f32>, wo: vec3<f32>) -> vec3<f32> {
    if (wi.z <= 0.0 || wo.z <= 0.0) {
        return vec3<f32>(0.0);
    }
    let e = pf(o + BANKS_E);
    let si = min(sqrt(wi.y * wi.y + wi.z * wi.z), 1.0);
    let so = min(sqrt(wo.y * wo.y + wo.z * wo.z), 1.0);
    let base = si * so - wi.x * wo.x;
    var lobe = 0.0;
    if (base > 0.0) {
        if (e == 0.0) {
            lobe = 1.0;
        } else {
            // base = a·b for the unit 2-vectors a = (wi.x, si), b = (−wo.x, so):
            // 1 − base = |a − b|²/2 = (p² + (p q)²)/2 with p = wi.x + wo.x and
            // si − so = (wo.x − wi.x) p/(si + so) = p q: exact near the peak.
            let p = wi.x + wo.x;
            let q = (wo.x - wi.x) / max(si + so, 1e-30);
            let t = clamp(0.5 * p * p * (1.0 + q * q), 0.0, 1.0);
            lobe = exp(e * log1p(-t));
        }
    }
    return prgb(o + BANKS_KD) * si + prgb(o + BANKS_KS) * lobe;
}
