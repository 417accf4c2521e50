//! Comparisons of two BRDFs: the relative L2 difference of their lobes at
//! the current light (e.g. a measured table against the analytic model it
//! was tabulated from), over the hemisphere by Gauss–Legendre rings
//! ([`bv_core::represent::sh::relative_l2`]), as a job cached by both build
//! revisions, the light and the cosine.

use super::jobs::{self, Done, Slots, Waker};
use bv_core::Brdf;
use glam::DVec3;
use std::sync::Arc;

/// What a comparison depends on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CompareKey {
    /// Build revision of the first BRDF.
    pub a: u64,
    /// Build revision of the second BRDF.
    pub b: u64,
    /// The light (θ, φ) in degrees.
    pub incident: (f64, f64),
    /// Compared `f cos θo` instead of `f`.
    pub cosine: bool,
}

/// A comparison's result: the relative L2 difference, or why there is none.
pub type CompareOutcome = Result<f64, String>;

/// A finished comparison with its key.
pub type CompareDone = Arc<Done<CompareKey, CompareOutcome>>;

/// Quadrature rings of the comparison (the same as bv-core's tabulation test).
pub const COMPARE_RINGS: usize = 96;

/// The comparisons of the process (slot: the first BRDF's id).
pub fn slots() -> Arc<Slots<CompareKey, CompareOutcome>> {
    jobs::slots("compare")
}

/// The latest comparison in `slot` (perhaps of an older key), starting the
/// one of `key` when needed; `wi` is the light of `key`.
pub fn request(
    waker: &Waker,
    slot: u64,
    key: CompareKey,
    a: Arc<dyn Brdf>,
    b: Arc<dyn Brdf>,
    wi: DVec3,
) -> Option<CompareDone> {
    slots().request(
        slot,
        key,
        jobs::once(move || {
            bv_core::represent::sh::relative_l2(
                a.as_ref(),
                b.as_ref(),
                wi,
                key.cosine,
                COMPARE_RINGS,
            )
            .map_err(|e| e.to_string())
        }),
        waker,
    )
}

/// Waits until no comparison is being computed (tests).
pub fn wait_idle() -> bool {
    slots().wait_idle(std::time::Duration::from_secs(60))
}
