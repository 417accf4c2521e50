//! Factorisations of a BRDF: the selected BRDF tabulated in the
//! half/difference layout and factored by a truncated SVD into
//! `Σ_k g_k(θh) h_k(θd, φd)` ([`bv_core::represent::factor`]; Kautz &
//! McCool 1999), once per build revision; the lobe rebuilt from its first K
//! terms, which the 3D lobe and the polar plot overlay (with the relative L2
//! error of the rebuilt lobe); and what the factorisation view draws (the
//! rebuilds' errors against K beside the SH representation's against L, over
//! the same table cells, [`bv_core::represent::sh_table`]). The lecture's
//! point ("Representations"): a few products of 2D functions hold most of a
//! 4D BRDF once it is parameterised by the half vector.
//!
//! Everything here runs as jobs in steps (a browser page draws between
//! them); the factorisation is shared by the overlay and the view.

use super::jobs::{self, Done, Shown, Slots, Waker};
use super::slices;
use crate::session::frame::{Scene, SceneBrdf};
use crate::session::state::Display;
use bv_core::lobe::{self, LobeMesh, LobeOptions, RadiusScale};
use bv_core::measured::merl::MerlTable;
use bv_core::represent::factor::{self, FactorSpace, Factorization};
use bv_core::represent::sh;
use bv_core::represent::sh_table::{self, TableErrors};
use bv_core::{Brdf, frame};
use std::sync::Arc;
use std::time::Duration;

/// A BRDF's table and its factorisation (linear space, the view's grid,
/// [`Display::MAX_FACTOR_TERMS`] terms).
#[derive(Debug)]
pub struct Factored {
    /// The tabulated BRDF.
    pub table: MerlTable,
    /// Its factorisation.
    pub fac: Factorization,
}

/// A factorisation, or why there is none (an anisotropic model).
pub type FactoredOutcome = Result<Arc<Factored>, String>;

/// The process's factorisations (slot: BRDF id, key: build revision).
pub fn factorizations() -> Arc<Slots<u64, FactoredOutcome>> {
    // A factorisation holds a whole table (tens of megabytes): keep few.
    jobs::slots_keeping("factorization", 2)
}

/// The factorisation of `brdf` at `revision`, from `slots` or computed now
/// (on the calling thread: a background job or a figure) and stored there.
pub fn factored(
    slots: &Slots<u64, FactoredOutcome>,
    id: u64,
    revision: u64,
    brdf: &dyn Brdf,
) -> FactoredOutcome {
    let mut table = None;
    jobs::run_to_end(|| factored_step(slots, id, revision, brdf, &mut table))
}

/// One step of [`factored`], for a job that must not block for long (a
/// browser page draws between steps): the tabulation (kept in `table`),
/// then the truncated SVDs ([`factor::factor_model`]'s two halves).
pub fn factored_step(
    slots: &Slots<u64, FactoredOutcome>,
    id: u64,
    revision: u64,
    brdf: &dyn Brdf,
    table: &mut Option<(MerlTable, std::time::Duration)>,
) -> Option<FactoredOutcome> {
    if let Some(d) = slots.latest(id).filter(|d| d.key == revision) {
        return Some(d.value.clone());
    }
    let t0 = crate::session::platform::Instant::now();
    let Some((t, before)) = table.take() else {
        if let Some(why) = factor::unsupported(brdf) {
            return Some(Err(why));
        }
        match bv_core::measured::merl::tabulate(brdf, factor::VIEW_DIMS) {
            Ok(t) => *table = Some((t, t0.elapsed())),
            Err(e) => return Some(Err(e.to_string())),
        }
        return None;
    };
    let v = factor::factor(&t, usize::from(Display::MAX_FACTOR_TERMS), SPACE)
        .map(|fac| Arc::new(Factored { table: t, fac }))
        .map_err(|e| e.to_string());
    slots.insert(id, revision, v.clone(), before + t0.elapsed());
    Some(v)
}

/// The space the views factor in: `f cos θi cos θo`
/// ([`FactorSpace::Cosine`]). In linear space the table's norm is dominated
/// by a few grazing cells, where a microfacet model grows like 1/cos θi
/// (values in the thousands), and the truncated SVD spends its terms there:
/// a rank-8 rebuild of a glossy Cook-Torrance was 1e-3 of `f` away from the
/// peak. In log space the lobe comes back better, but the error is no longer
/// optimal or monotone in K. Weighted by the cosines the values are bounded
/// and the truncation is the best for the error in the reflected light,
/// which is what the view reports.
pub const SPACE: FactorSpace = FactorSpace::Cosine;

/// Samples of the polar plot's dashed curve.
const PLANE_SAMPLES: usize = 360;

/// What an overlay depends on.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FactorKey {
    /// The BRDF's build revision.
    pub revision: u64,
    /// Incident direction (θ, φ) in degrees.
    pub incident: (f64, f64),
    /// Terms K.
    pub terms: usize,
    /// Drawn `f cos θo` instead of `f`.
    pub cosine: bool,
    /// Mesh radius on the log scale.
    pub log: bool,
}

/// A finished overlay and what the views draw of it.
#[derive(Debug)]
pub struct FactorResult {
    /// The factorisation it was rebuilt from.
    pub factored: Arc<Factored>,
    /// Terms used.
    pub terms: usize,
    /// `‖f̂ − f‖ / ‖f‖` of the lobe at ωi over the hemisphere (the sphere for
    /// a transmitting model), on the channel mean: the SH overlay's measure.
    pub lobe_error: f64,
    /// The rebuilt lobe as a mesh.
    pub mesh: Arc<LobeMesh>,
    /// The rebuilt lobe in the plane of incidence (for the polar plot).
    pub plane: Vec<slices::Sample>,
    /// The BRDF it belongs to.
    pub brdf_id: u64,
}

/// The slots' value: a result, or why there is none.
pub type FactorOutcome = Result<FactorResult, String>;

/// A finished overlay with its key.
pub type FactorDone = Arc<Done<FactorKey, FactorOutcome>>;

/// Rebuilds `brdf`'s lobe for `key` from its factorisation (computed, or
/// taken from `slots`) and builds what the views draw.
pub fn compute(
    brdf: &dyn Brdf,
    brdf_id: u64,
    key: FactorKey,
    slots: &Slots<u64, FactoredOutcome>,
) -> FactorOutcome {
    let f = factored(slots, brdf_id, key.revision, brdf)?;
    let terms = key.terms.clamp(1, f.fac.terms());
    let rebuilt = f.fac.brdf(terms).map_err(|e| e.to_string())?;
    let (t, p) = (key.incident.0.to_radians(), key.incident.1.to_radians());
    let wi = frame::from_spherical(t, p);
    let mesh = lobe::build(
        &rebuilt,
        wi,
        &LobeOptions {
            n_theta: super::sh::MESH_GRID.0,
            n_phi: super::sh::MESH_GRID.1,
            cosine: key.cosine,
            scale: if key.log {
                RadiusScale::Log
            } else {
                RadiusScale::Linear
            },
        },
    );
    let plane = slices::plane_of_incidence(&rebuilt, t, p, PLANE_SAMPLES, key.cosine);
    let lobe_error = sh::relative_l2(&rebuilt, brdf, wi, key.cosine, super::sh::RINGS)
        .map_err(|e| e.to_string())?;
    Ok(FactorResult {
        factored: f,
        terms,
        lobe_error,
        mesh: Arc::new(mesh),
        plane,
        brdf_id,
    })
}

/// The key for the scene's primary BRDF, if the overlay is on.
pub fn key_for(scene: &Scene<'_>) -> Option<(u64, FactorKey)> {
    let d = scene.state.display;
    if !d.factor_overlay {
        return None;
    }
    let b = scene.primary()?;
    Some((
        b.id,
        FactorKey {
            revision: b.revision,
            incident: (scene.incident.theta_deg, scene.incident.phi_deg),
            terms: usize::from(d.factor_terms.clamp(1, Display::MAX_FACTOR_TERMS)),
            cosine: d.cosine,
            log: d.log,
        },
    ))
}

/// The process's overlays (slot: BRDF id).
pub fn overlays() -> Arc<Slots<FactorKey, FactorOutcome>> {
    jobs::slots("factor overlay")
}

/// The latest overlay of the scene's primary BRDF (starting one in the
/// background if the current key has none; computed now for a figure), or
/// `None` with the overlay off. The result may be for an older key while the
/// new one is computed.
pub fn request(waker: &Waker, scene: &Scene<'_>) -> Option<FactorDone> {
    let (id, key) = key_for(scene)?;
    let b = scene.primary()?;
    let brdf = b.brdf.clone();
    let tables = factorizations();
    // In steps (a browser page draws between them): the factorisation,
    // unless another view made it, then the rebuilt lobe.
    let mut table = None;
    let mut factored_yet = false;
    let compute = move || {
        if !factored_yet {
            match factored_step(&tables, id, key.revision, brdf.as_ref(), &mut table)? {
                Ok(_) => factored_yet = true,
                Err(e) => return Some(Err(e)),
            }
            return None;
        }
        Some(compute(brdf.as_ref(), id, key, &tables))
    };
    if scene.figure {
        // A figure is drawn once: compute now rather than show "computing…".
        return Some(overlays().now(id, key, compute));
    }
    overlays().request(id, key, compute, waker)
}

/// Whether an overlay for the scene's current key is still being computed.
pub fn pending(scene: &Scene<'_>) -> bool {
    match key_for(scene) {
        Some((id, key)) => overlays().get(id, &key).is_none(),
        None => false,
    }
}

/// Waits until no overlay, factorisation or factorisation view's data is
/// being computed (tests, scripted drivers).
pub fn wait_idle() -> bool {
    let t = Duration::from_secs(120);
    overlays().wait_idle(t) && factorizations().wait_idle(t) && view_slots().wait_idle(t)
}
/// What the view shows of one BRDF.
#[derive(Debug)]
pub struct FactorData {
    /// The table and its factorisation.
    pub factored: Arc<Factored>,
    /// The rebuilt tables' errors for K = 1..=8 (index K − 1).
    pub svd_error: TableErrors,
    /// SH's errors over the same cells for L = 0..=16 (index L).
    pub sh_error: TableErrors,
}

/// The factorisation view's result: its data or why there is none.
pub type ViewOutcome = Arc<Result<FactorData, String>>;

/// What [`step`] has finished so far.
#[derive(Default)]
struct Partial {
    table: Option<(bv_core::measured::merl::MerlTable, Duration)>,
    factored: Option<Arc<Factored>>,
    sh_job: Option<sh_table::ShTableJob>,
    sh_error: Option<TableErrors>,
}

#[cfg(test)]
fn view_compute(
    brdf: &dyn bv_core::Brdf,
    id: u64,
    revision: u64,
    tables: &Slots<u64, FactoredOutcome>,
) -> ViewOutcome {
    let mut partial = Partial::default();
    jobs::run_to_end(|| view_step(&mut partial, brdf, id, revision, tables))
}

/// Quadrature rings, and θh rows of the table, per step of SH's errors: a
/// few per worker thread (one worker in a browser page, where a step must
/// fit in a slice of a frame).
fn sh_step_size() -> (usize, usize) {
    let threads = rayon::current_num_threads();
    (4 * threads, threads)
}

/// One step of the view's computation (so that a browser page draws
/// between them): the factorisation (tabulation, then the SVDs), SH's errors
/// over the table (a few rings of one lobe's projection, or a few rows of
/// the table, a step), then the rank-K rebuilds' errors.
fn view_step(
    partial: &mut Partial,
    brdf: &dyn bv_core::Brdf,
    id: u64,
    revision: u64,
    tables: &Slots<u64, FactoredOutcome>,
) -> Option<ViewOutcome> {
    let fail = |e: String| Some(Arc::new(Err(e)));
    let Some(factored) = partial.factored.clone() else {
        match factored_step(tables, id, revision, brdf, &mut partial.table)? {
            Ok(f) => partial.factored = Some(f),
            Err(e) => return fail(e),
        }
        return None;
    };
    let Some(sh_error) = partial.sh_error.take() else {
        let job = match &mut partial.sh_job {
            Some(j) => j,
            None => match sh_table::ShTableJob::new(
                sh::MAX_ORDER,
                sh_table::VIEW_INCIDENT,
                super::sh::RINGS,
            ) {
                Ok(j) => partial.sh_job.insert(j),
                Err(e) => return fail(e.to_string()),
            },
        };
        let (rings, rows) = sh_step_size();
        match job.step(brdf, &factored.table, rings, rows)? {
            Ok(e) => partial.sh_error = Some(e),
            Err(e) => return fail(e.to_string()),
        }
        return None;
    };
    match sh_table::factor_table_error(&factored.fac, &factored.table) {
        Ok(svd_error) => Some(Arc::new(Ok(FactorData {
            factored,
            svd_error,
            sh_error,
        }))),
        Err(e) => fail(e.to_string()),
    }
}

/// The process's factorisation-view data (slot: BRDF id, key: revision).
pub fn view_slots() -> Arc<Slots<u64, ViewOutcome>> {
    jobs::slots_keeping("factorization view", 2)
}

/// The factorisation view's data of `b` for this frame: computed now for a
/// figure, else the latest finished data while a job computes it.
pub fn view_data(waker: &Waker, scene: &Scene<'_>, b: &SceneBrdf) -> Shown<u64, ViewOutcome> {
    let tables = factorizations();
    let (id, rev) = (b.id, b.revision);
    let brdf = b.brdf.clone();
    let mut partial = Partial::default();
    view_slots().for_frame(
        waker,
        id,
        rev,
        scene.figure,
        Duration::from_millis(100),
        move || view_step(&mut partial, brdf.as_ref(), id, rev, &tables),
    )
}
#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn more_terms_rebuild_a_glossy_lobe_better() {
        let b = bv_core::ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"kd": 0.2, "ks": 0.7, "alpha": 0.3}),
        )
        .unwrap()
        .build()
        .unwrap();
        let slots = Slots::default();
        let key = FactorKey {
            revision: 1,
            incident: (40.0, 0.0),
            terms: 1,
            cosine: false,
            log: false,
        };
        let r1 = compute(b.as_ref(), 3, key, &slots).unwrap();
        let r4 = compute(b.as_ref(), 3, FactorKey { terms: 4, ..key }, &slots).unwrap();
        // The second call reused the first's factorisation.
        assert!(Arc::ptr_eq(&r1.factored, &r4.factored));
        assert_eq!(r4.plane.len(), PLANE_SAMPLES + 1);
        assert!(
            r4.lobe_error < r1.lobe_error,
            "{} {}",
            r4.lobe_error,
            r1.lobe_error
        );
        // Over the table, weighted by cos θi cos θo (what the factorisation
        // minimises, see SPACE).
        let f = &r1.factored;
        let e = bv_core::represent::sh_table::factor_table_error(&f.fac, &f.table).unwrap();
        assert!(e.cosine[3] < e.cosine[0], "{e:?}");
    }

    #[test]
    fn anisotropic_models_say_why() {
        let b = bv_core::ModelSpec::from_json(
            "ward",
            &serde_json::json!({"alpha_x": 0.1, "alpha_y": 0.4}),
        )
        .unwrap()
        .build()
        .unwrap();
        let key = FactorKey {
            revision: 1,
            incident: (40.0, 0.0),
            terms: 2,
            cosine: false,
            log: false,
        };
        let e = compute(b.as_ref(), 3, key, &Slots::default()).unwrap_err();
        assert!(e.contains("isotropic"), "{e}");
    }

    /// A glossy model: the SVD's K = 1 beats SH's L = 0 over the same cells
    /// (a product of two 2D functions holds more of a half-angle lobe than
    /// one constant per θi), both fall with more terms, and the errors of the
    /// cells are the factorisation's own.
    #[test]
    fn errors_for_a_glossy_model() {
        let b = bv_core::ModelSpec::from_json(
            "cook-torrance",
            &serde_json::json!({"kd": 0.1, "ks": 0.8, "alpha": 0.2}),
        )
        .unwrap()
        .build()
        .unwrap();
        let out = view_compute(b.as_ref(), 1, 1, &Slots::default());
        let d = out.as_ref().as_ref().unwrap();
        let sh = &d.sh_error.cosine;
        assert_eq!(sh.len(), sh::MAX_ORDER + 1);
        let svd = &d.svd_error.cosine;
        assert_eq!(svd.len(), usize::from(Display::MAX_FACTOR_TERMS));
        assert!(svd[0] < sh[0], "{svd:?} {sh:?}");
        assert!(svd[7] < svd[0]);
        assert!(sh[16] < sh[0], "{sh:?}");
        for (a, b) in d.svd_error.plain.iter().zip(&d.factored.fac.rel_l2_error_f) {
            assert!((a - b).abs() < 1e-9);
        }
        // The cosine-weighted error of the cells is the factored space's own
        // (up to the clamp at 0, which only lowers it).
        for (a, b) in svd.iter().zip(&d.factored.fac.rel_l2_error) {
            assert!(*a <= b + 1e-9 && *a > 0.5 * b, "{a} vs {b}");
        }
    }
}
