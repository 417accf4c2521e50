//! Reciprocity maps: for the current light direction ωi, the relative
//! reciprocity error `|f(ωi,ωo) − f(ωo,ωi)| / max f` over the outgoing
//! hemisphere (`bv_core::analysis::reciprocity_map`), of the selected BRDF,
//! computed as a job and cached by the BRDF's revision, ωi and the
//! resolution.

use super::jobs::{self, Shown, Slots, Waker};
use crate::session::frame::{Scene, SceneBrdf};
use bv_core::analysis::reciprocity_map::{ReciprocityMap, reciprocity_map};
use std::sync::Arc;
use std::time::Duration;

/// Map resolution in the window (pixels per side): 16 384 pairs, a few
/// milliseconds for an analytic model.
pub const WINDOW_RES: usize = 160;
/// Map resolution of figures.
pub const FIGURE_RES: usize = 320;

/// What a map was computed for: BRDF revision, ωi (θ, φ bits), resolution.
pub type Key = (u64, u64, u64, usize);

/// The maps of the process (slot: BRDF id).
pub fn slots() -> Arc<Slots<Key, Arc<ReciprocityMap>>> {
    jobs::slots("reciprocity map")
}

/// What the map of `b` under the scene's light is keyed by (at the
/// resolution of a figure or of the window).
pub fn key_of(scene: &Scene<'_>, b: &SceneBrdf) -> Key {
    let res = if scene.figure { FIGURE_RES } else { WINDOW_RES };
    (
        b.revision,
        scene.incident.theta_deg.to_bits(),
        scene.incident.phi_deg.to_bits(),
        res,
    )
}

/// The map of `b` for this frame: computed now for a figure, else the latest
/// finished one while a job computes it.
pub fn map(waker: &Waker, scene: &Scene<'_>, b: &SceneBrdf) -> Shown<Key, Arc<ReciprocityMap>> {
    let key = key_of(scene, b);
    let res = key.3;
    let wi = scene.wi();
    let brdf = b.brdf.clone();
    slots().for_frame(
        waker,
        b.id,
        key,
        scene.figure,
        Duration::from_millis(50),
        jobs::once(move || Arc::new(reciprocity_map(brdf.as_ref(), wi, res, res))),
    )
}
