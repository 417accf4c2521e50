//! The hemisphere view's maps (LECTURE.md N4): each drawn BRDF's
//! `f(ωi, ·)` (or × cos θo) on the equal-area disc of the outgoing
//! hemisphere, with its half-maximum contour
//! (`bv_core::analysis::hemi_map`) — a job per BRDF, cached by its
//! revision, the light and the cosine switch.

use super::jobs::{self, Shown, Slots, Waker};
use crate::session::frame::{Scene, SceneBrdf};
use bv_core::analysis::hemi_map::{HemiMap, hemi_map};
use glam::DVec2;
use std::sync::Arc;
use std::time::Duration;

/// Pixels per side of a map (a disc of up to ~600 points on a slide reads
/// smooth with linear filtering; 10⁵ evaluations).
pub const SIZE: usize = 320;
/// The contour's level as a fraction of the peak.
pub const CONTOUR: f64 = 0.5;

/// What a map depends on: the BRDF's revision, θi and φi (bits), × cos θo.
pub type Key = (u64, u64, u64, bool);

/// A finished map and its half-maximum contour.
#[derive(Debug, Clone)]
pub struct Hemi {
    /// The map.
    pub map: HemiMap,
    /// The contour at [`CONTOUR`] × the peak (disc coordinates).
    pub contour: Vec<[DVec2; 2]>,
}

/// The maps of the process (slot: BRDF id).
pub fn slots() -> Arc<Slots<Key, Arc<Hemi>>> {
    jobs::slots("hemisphere map")
}

/// The map of `b` for this frame's light: computed now for a figure, else
/// the latest finished one while a job computes it.
pub fn request(waker: &Waker, scene: &Scene<'_>, b: &SceneBrdf) -> Shown<Key, Arc<Hemi>> {
    let cosine = scene.state.display.cosine;
    let key = (
        b.revision,
        scene.incident.theta_deg.to_bits(),
        scene.incident.phi_deg.to_bits(),
        cosine,
    );
    let brdf = b.brdf.clone();
    let wi = scene.wi();
    slots().for_frame(
        waker,
        b.id,
        key,
        scene.figure,
        Duration::from_millis(50),
        move || {
            let map = hemi_map(brdf.as_ref(), wi, SIZE, cosine);
            let contour = map.contour(CONTOUR * map.peak);
            Some(Arc::new(Hemi { map, contour }))
        },
    )
}
