//! The factorisation overlay shared by the 3D lobe and the polar plot, and
//! the factorisation the factorisation view draws: the selected BRDF
//! tabulated in the half/difference layout and factored by a truncated SVD
//! into `Σ_k g_k(θh) h_k(θd, φd)` ([`bv_core::represent::factor`]), rebuilt
//! from its first K terms and drawn like the SH overlay (a wireframe in the
//! 3D lobe, a dashed curve in the polar plot) with the relative L2 error of
//! the rebuilt lobe. The lecture's point ("Representations"): a few products
//! of 2D functions hold most of a 4D BRDF once it is parameterised by the
//! half vector.
//!
//! The factorisation depends only on the BRDF, so it is computed once per
//! build revision (a background job, shared by both views and the
//! factorisation view); the rebuilt lobe depends on ωi and K as well.

use super::background::{self, Done, Slots};
use super::{Scene, curves};
use crate::session::command::Command;
use crate::session::state::Display;
use bv_core::lobe::{self, LobeMesh, LobeOptions, RadiusScale};
use bv_core::measured::merl::MerlTable;
use bv_core::represent::factor::{self, FactorSpace, Factorization};
use bv_core::represent::sh;
use bv_core::{Brdf, frame};
use eframe::egui::{self, Role, Ui, WidgetInfo};
use std::sync::Arc;

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
pub fn factorizations(ctx: &egui::Context) -> Arc<Slots<u64, FactoredOutcome>> {
    background::shared(ctx, "factorization")
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
    background::run_to_end(|| factored_step(slots, id, revision, brdf, &mut table))
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
    pub plane: Vec<curves::Sample>,
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
            n_theta: super::sh_overlay::MESH_GRID.0,
            n_phi: super::sh_overlay::MESH_GRID.1,
            cosine: key.cosine,
            scale: if key.log {
                RadiusScale::Log
            } else {
                RadiusScale::Linear
            },
        },
    );
    let plane = curves::plane_of_incidence(&rebuilt, t, p, PLANE_SAMPLES, key.cosine);
    let lobe_error = sh::relative_l2(&rebuilt, brdf, wi, key.cosine, super::sh_overlay::RINGS)
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

fn overlays(ctx: &egui::Context) -> Arc<Slots<FactorKey, FactorOutcome>> {
    background::shared(ctx, "factor overlay")
}

/// The latest overlay of the scene's primary BRDF (starting one in the
/// background if the current key has none), or `None` with the overlay off.
/// The result may be for an older key while the new one is computed.
pub fn request(ctx: &egui::Context, scene: &Scene<'_>) -> Option<FactorDone> {
    let (id, key) = key_for(scene)?;
    let b = scene.primary()?;
    let brdf = b.brdf.clone();
    let slots = overlays(ctx);
    let tables = factorizations(ctx);
    if scene.figure {
        // A figure is drawn once: compute now rather than show "computing…".
        if let Some(d) = slots.latest(id).filter(|d| d.key == key) {
            return Some(d);
        }
        let t0 = crate::session::platform::Instant::now();
        let v = compute(brdf.as_ref(), id, key, &tables);
        return Some(slots.insert(id, key, v, t0.elapsed()));
    }
    let ctx2 = ctx.clone();
    // In steps (a browser page draws between them): the factorisation,
    // unless another view made it, then the rebuilt lobe.
    let mut table = None;
    let mut factored_yet = false;
    slots.request(
        id,
        key,
        move || {
            if !factored_yet {
                match factored_step(&tables, id, key.revision, brdf.as_ref(), &mut table)? {
                    Ok(_) => factored_yet = true,
                    Err(e) => return Some(Err(e)),
                }
                return None;
            }
            Some(compute(brdf.as_ref(), id, key, &tables))
        },
        move || ctx2.request_repaint(),
    )
}

/// Whether an overlay for the scene's current key is still being computed.
pub fn pending(ctx: &egui::Context, scene: &Scene<'_>) -> bool {
    match key_for(scene) {
        Some((id, key)) => overlays(ctx).latest(id).is_none_or(|d| d.key != key),
        None => false,
    }
}

/// Waits until no overlay or factorisation is being computed (tests,
/// scripted drivers).
pub fn wait_idle(ctx: &egui::Context) -> bool {
    let t = std::time::Duration::from_secs(60);
    overlays(ctx).wait_idle(t) && factorizations(ctx).wait_idle(t)
}

/// One line about a result:
/// `factor K = 2: lobe L2 error 31 % (table, cos-weighted: 19 %)`.
pub fn summary(done: &FactorDone, current: bool) -> String {
    let stale = if current { "" } else { " (updating…)" };
    match &done.value {
        Ok(r) => format!(
            "factor K = {}: lobe L2 error {} (table, cos-weighted: {}){stale}",
            r.terms,
            super::sh_overlay::percent(r.lobe_error),
            super::sh_overlay::percent(
                r.factored
                    .fac
                    .rel_l2_error
                    .get(r.terms - 1)
                    .copied()
                    .unwrap_or(f64::NAN)
            )
        ),
        Err(e) => format!("factor: {e}"),
    }
}

/// The toolbar control shared by the lobe and polar views: a "factor" toggle
/// and the number of terms K; with the overlay on, the error of the result.
pub fn control(ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
    let d = scene.state.display;
    if super::toolbar_toggle(
        ui,
        d.factor_overlay,
        "factor",
        "Overlay the selected BRDF rebuilt from the first K terms of the SVD of its \
         half/difference table, Σ g_k(θh) h_k(θd, φd) (dashed / wireframe), with its \
         relative L2 error",
    ) {
        out.push(Command::SetDisplay(Display {
            factor_overlay: !d.factor_overlay,
            ..d
        }));
    }
    if d.factor_overlay {
        let mut k = d.factor_terms.clamp(1, Display::MAX_FACTOR_TERMS);
        let r = ui
            .add(
                egui::DragValue::new(&mut k)
                    .range(1..=Display::MAX_FACTOR_TERMS)
                    .prefix("K = ")
                    .speed(0.1)
                    .update_while_editing(false),
            )
            .on_hover_text("Terms of the factorisation (1–8), per colour channel");
        r.widget_info(|| WidgetInfo::labeled(Role::SpinButton, true, "factor terms K"));
        if k != d.factor_terms {
            out.push(Command::SetDisplay(Display {
                factor_terms: k,
                ..d
            }));
        }
    }
}

/// The error label under a view's toolbar (accessible text: tests read it).
pub fn error_label(ui: &mut Ui, scene: &Scene<'_>, done: Option<&FactorDone>) {
    let Some(done) = done else {
        if scene.state.display.factor_overlay && scene.primary().is_some() {
            ui.weak("factor: computing…");
        }
        return;
    };
    let current = key_for(scene).is_some_and(|(_, k)| k == done.key);
    let r = ui.label(summary(done, current));
    if let Ok(res) = &done.value {
        let dims = res.factored.fac.dims;
        r.on_hover_text(format!(
            "|rebuilt − f| / |f| of the lobe at ωi ({}); the table's error is that of \
             f cos θi cos θo over its {dims} cells and three channels (the factored \
             quantity); rebuilt in {:.0} ms",
            super::value_label(done.key.cosine),
            done.elapsed.as_secs_f64() * 1e3
        ));
    }
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
}
