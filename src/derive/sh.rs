//! The spherical-harmonics projection of a lobe, which the 3D lobe and the
//! polar plot overlay: the selected BRDF's lobe at the current incident
//! direction projected onto real SH of order ≤ L
//! ([`bv_core::represent::sh::project`]), its reconstruction as a mesh and
//! in the plane of incidence, and the relative L2 error.
//!
//! The projection costs tens of milliseconds at L = 16, so it runs as a job
//! (in steps of a few quadrature rings, so that a browser page keeps
//! drawing), keyed by everything it depends on; both views read the one
//! result.

use super::jobs::{self, Done, Slots, Waker};
use super::slices;
use crate::session::frame::Scene;
use bv_core::lobe::{self, LobeMesh, LobeOptions, RadiusScale};
use bv_core::represent::sh::{self, Domain, ShLobe};
use bv_core::{Brdf, Claims, Rgb, frame};
use glam::DVec3;
use std::sync::Arc;

/// Gauss–Legendre rings of the projection's quadrature (twice as many
/// azimuths): 128 × 256 directions resolve lobes down to a couple of degrees
/// wide, and integrate every product of SH up to order 16 exactly.
pub const RINGS: usize = 128;

/// Grid of the reconstruction's wireframe (rings, segments): coarse enough to
/// read as lines over the lobe, fine enough for order-16 ripples (≈ 11°).
pub const MESH_GRID: (usize, usize) = (32, 64);

/// Samples of the polar plot's dashed curve.
const PLANE_SAMPLES: usize = 360;

/// What a projection depends on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ShKey {
    /// The BRDF's build revision.
    pub revision: u64,
    /// Incident direction (θ, φ) in degrees.
    pub incident: (f64, f64),
    /// Order L.
    pub order: usize,
    /// Projected `f cos θo` instead of `f`.
    pub cosine: bool,
    /// Mesh radius on the log scale.
    pub log: bool,
}

/// A finished projection and what the views draw of it.
#[derive(Debug)]
pub struct ShResult {
    /// The coefficients and the relative L2 error.
    pub lobe: ShLobe,
    /// The reconstruction as a lobe mesh (radius clamped at 0).
    pub mesh: Arc<LobeMesh>,
    /// The reconstruction in the plane of incidence (for the polar plot).
    pub plane: Vec<slices::Sample>,
    /// The BRDF it belongs to.
    pub brdf_id: u64,
}

/// The slots' value: a result, or why there is none.
pub type ShOutcome = Result<ShResult, String>;

/// A finished projection with its key.
pub type ShDone = Arc<Done<ShKey, ShOutcome>>;

/// A reconstruction seen as a BRDF, so that the lobe mesh builder and the
/// plane-of-incidence sampler draw it like any model: `eval(wi, wo)` is the
/// SH sum at `wo` (the `wi` of the projection is built in).
#[derive(Debug)]
struct ShBrdf<'a>(&'a ShLobe);

impl Brdf for ShBrdf<'_> {
    fn id(&self) -> &'static str {
        "sh-reconstruction"
    }

    fn eval(&self, _wi: DVec3, wo: DVec3) -> Rgb {
        if self.0.domain == Domain::Hemisphere && wo.z <= 0.0 {
            return Rgb::ZERO;
        }
        self.0.eval(wo)
    }

    fn claims(&self) -> Claims {
        Claims {
            reciprocal: false,
            energy_conserving: false,
            isotropic: false,
        }
    }

    fn transmits(&self) -> bool {
        self.0.domain == Domain::Sphere
    }
}

/// Projects `brdf`'s lobe for `key` and builds what the views draw.
pub fn compute(brdf: &dyn Brdf, brdf_id: u64, key: ShKey) -> ShOutcome {
    let mut job = None;
    jobs::run_to_end(|| step(&mut job, brdf, brdf_id, key))
}

/// Quadrature rings summed per step of the background job: a few per
/// worker thread (one worker in a browser page, where a step must fit in a
/// slice of a frame: 4 rings of 256 directions at L = 16 take a few
/// milliseconds there).
fn rings_per_step() -> usize {
    4 * rayon::current_num_threads()
}

/// One step of [`compute`]: a few quadrature rings of the projection
/// (`job` holds it between steps), and once it is done the mesh and the
/// plane of incidence.
fn step(
    job: &mut Option<sh::ProjectJob>,
    brdf: &dyn Brdf,
    brdf_id: u64,
    key: ShKey,
) -> Option<ShOutcome> {
    let (t, p) = (key.incident.0.to_radians(), key.incident.1.to_radians());
    let wi = frame::from_spherical(t, p);
    let j = match job {
        Some(j) => j,
        None => match sh::ProjectJob::for_brdf(brdf, key.order, RINGS) {
            Ok(j) => job.insert(j),
            Err(e) => return Some(Err(e.to_string())),
        },
    };
    let lobe = j.step(&sh::lobe_fn(brdf, wi, key.cosine), rings_per_step())?;
    let view = ShBrdf(&lobe);
    let mesh = lobe::build(
        &view,
        wi,
        &LobeOptions {
            n_theta: MESH_GRID.0,
            n_phi: MESH_GRID.1,
            // The cosine, if any, is already in the projected function.
            cosine: false,
            scale: if key.log {
                RadiusScale::Log
            } else {
                RadiusScale::Linear
            },
        },
    );
    let plane = slices::plane_of_incidence(&view, t, p, PLANE_SAMPLES, false);
    Some(Ok(ShResult {
        lobe,
        mesh: Arc::new(mesh),
        plane,
        brdf_id,
    }))
}

/// The key for the scene's primary BRDF, if the overlay is on.
pub fn key_for(scene: &Scene<'_>) -> Option<(u64, ShKey)> {
    let d = scene.state.display;
    if !d.sh_overlay {
        return None;
    }
    let b = scene.primary()?;
    Some((
        b.id,
        ShKey {
            revision: b.revision,
            incident: (scene.incident.theta_deg, scene.incident.phi_deg),
            order: usize::from(d.sh_order).min(sh::MAX_ORDER),
            cosine: d.cosine,
            log: d.log,
        },
    ))
}

/// The process's projections (slot: BRDF id).
pub fn slots() -> Arc<Slots<ShKey, ShOutcome>> {
    jobs::slots("sh projection")
}

/// The latest projection of the scene's primary BRDF (starting one in the
/// background if the current key has none; computed now for a figure), or
/// `None` with the overlay off. The result may be for an older key while the
/// new one is computed.
pub fn request(waker: &Waker, scene: &Scene<'_>) -> Option<ShDone> {
    let (id, key) = key_for(scene)?;
    let b = scene.primary()?;
    let brdf = b.brdf.clone();
    let mut job = None;
    let compute = move || step(&mut job, brdf.as_ref(), id, key);
    if scene.figure {
        // A figure is drawn once: compute now rather than show "computing…".
        return Some(slots().now(id, key, compute));
    }
    slots().request(id, key, compute, waker)
}

/// Whether a projection for the scene's current key is still being computed.
pub fn pending(scene: &Scene<'_>) -> bool {
    match key_for(scene) {
        Some((id, key)) => slots().get(id, &key).is_none(),
        None => false,
    }
}

/// Waits until no projection is being computed (tests, scripted drivers).
pub fn wait_idle() -> bool {
    slots().wait_idle(std::time::Duration::from_secs(60))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn lambert_projects_with_a_small_error_and_the_mesh_follows() {
        let b = bv_core::ModelSpec::new("lambert").unwrap().build().unwrap();
        let key = ShKey {
            revision: 1,
            incident: (30.0, 0.0),
            order: 8,
            cosine: false,
            log: false,
        };
        let r = compute(b.as_ref(), 5, key).unwrap();
        assert_eq!(r.brdf_id, 5);
        assert_eq!(r.lobe.coeffs.len(), 81);
        // Lambert extended by 0 below the horizon is not band-limited (the
        // jump at the horizon), but at order 8 most of it is there.
        assert!(r.lobe.rel_l2_error > 0.0 && r.lobe.rel_l2_error < 0.3);
        // Straight up (vertex 0 is the pole) the reconstruction approaches
        // albedo/π = 0.5/π as the order grows (the horizon's jump makes the
        // approach slow: Gibbs).
        let want = 0.5 / std::f64::consts::PI;
        let up = |r: &ShResult| f64::from(r.mesh.positions[0][2]);
        assert!((up(&r) - want).abs() < 0.15 * want, "{}", up(&r));
        assert_eq!(r.plane.len(), PLANE_SAMPLES + 1);
        // Higher order, smaller error.
        let r16 = compute(b.as_ref(), 5, ShKey { order: 16, ..key }).unwrap();
        assert!(r16.lobe.rel_l2_error < r.lobe.rel_l2_error);
        assert!((up(&r16) - want).abs() < (up(&r) - want).abs());
    }
}
