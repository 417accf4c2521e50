//! The spherical-harmonics overlay shared by the 3D lobe and
//! the polar plot: the selected BRDF's lobe at the current incident direction
//! projected onto real SH of order ≤ L ([`bv_core::represent::sh::project`]),
//! drawn as a wireframe surface in the 3D lobe and a dashed curve in the polar
//! plot, with the relative L2 error of the reconstruction. The point it makes
//! in a lecture: a sharp lobe needs L ≳ 1/width, so at low orders its peak is
//! flattened and the reconstruction rings (and goes negative, drawn as 0).
//!
//! The projection costs tens of milliseconds at L = 16, so it runs in the
//! background ([`super::background`]; in steps of a few quadrature rings, so
//! that a browser page keeps drawing), keyed by everything it depends on;
//! both views read the one result.

use super::background::{self, Done};
use super::{Scene, curves};
use crate::session::command::Command;
use crate::session::state::Display;
use bv_core::lobe::{self, LobeMesh, LobeOptions, RadiusScale};
use bv_core::represent::sh::{self, Domain, ShLobe};
use bv_core::{Brdf, Claims, Rgb, frame};
use eframe::egui::{self, Role, Ui, WidgetInfo};
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
    pub plane: Vec<curves::Sample>,
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
    background::run_to_end(|| step(&mut job, brdf, brdf_id, key))
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
    let plane = curves::plane_of_incidence(&view, t, p, PLANE_SAMPLES, false);
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

/// The latest projection of the scene's primary BRDF (starting one in the
/// background if the current key has none), or `None` with the overlay off.
/// The result may be for an older key while the new one is computed.
pub fn request(ctx: &egui::Context, scene: &Scene<'_>) -> Option<ShDone> {
    let (id, key) = key_for(scene)?;
    let b = scene.primary()?;
    let brdf = b.brdf.clone();
    let slots = background::shared::<ShKey, ShOutcome>(ctx, "sh");
    if scene.figure {
        // A figure is drawn once: compute now rather than show "computing…".
        if let Some(d) = slots.latest(id).filter(|d| d.key == key) {
            return Some(d);
        }
        let t0 = crate::session::platform::Instant::now();
        let v = compute(brdf.as_ref(), id, key);
        return Some(slots.insert(id, key, v, t0.elapsed()));
    }
    let ctx2 = ctx.clone();
    let mut job = None;
    slots.request(
        id,
        key,
        move || step(&mut job, brdf.as_ref(), id, key),
        move || ctx2.request_repaint(),
    )
}

/// Whether a projection for the scene's current key is still being computed.
pub fn pending(ctx: &egui::Context, scene: &Scene<'_>) -> bool {
    match key_for(scene) {
        Some((id, key)) => {
            let slots = background::shared::<ShKey, ShOutcome>(ctx, "sh");
            slots.latest(id).is_none_or(|d| d.key != key)
        }
        None => false,
    }
}

/// Waits until no projection is being computed (tests, scripted drivers).
pub fn wait_idle(ctx: &egui::Context) -> bool {
    background::shared::<ShKey, ShOutcome>(ctx, "sh").wait_idle(std::time::Duration::from_secs(60))
}

/// One line about a result: `SH L = 8: L2 error 23.4 %`.
pub fn summary(done: &ShDone, current: bool) -> String {
    let stale = if current { "" } else { " (updating…)" };
    match &done.value {
        Ok(r) => format!(
            "SH L = {}: relative L2 error {}{stale}",
            r.lobe.order,
            percent(r.lobe.rel_l2_error)
        ),
        Err(e) => format!("SH: {e}"),
    }
}

/// A fraction as a percentage with sensible digits.
pub fn percent(x: f64) -> String {
    let p = 100.0 * x;
    if p >= 10.0 {
        format!("{p:.1} %")
    } else if p >= 0.1 {
        format!("{p:.2} %")
    } else {
        format!("{p:.3} %")
    }
}

/// The toolbar control shared by the lobe and polar views: an "SH" toggle and
/// the order L (0–16); with the overlay on, the error of the current result.
pub fn control(ui: &mut Ui, scene: &Scene<'_>, out: &mut Vec<Command>) {
    let d = scene.state.display;
    if super::toolbar_toggle(
        ui,
        d.sh_overlay,
        "SH",
        "Overlay the selected lobe's spherical-harmonics reconstruction of order ≤ L \
         (dashed / wireframe), with its relative L2 error",
    ) {
        out.push(Command::SetDisplay(Display {
            sh_overlay: !d.sh_overlay,
            ..d
        }));
    }
    if d.sh_overlay {
        let mut l = d.sh_order.min(sh::MAX_ORDER as u8);
        let r = ui
            .add(
                egui::DragValue::new(&mut l)
                    .range(0..=sh::MAX_ORDER as u8)
                    .prefix("L = ")
                    .speed(0.1)
                    .update_while_editing(false),
            )
            .on_hover_text("Highest SH order (0–16): (L + 1)² coefficients");
        r.widget_info(|| WidgetInfo::labeled(Role::SpinButton, true, "SH order L"));
        if l != d.sh_order {
            out.push(Command::SetDisplay(Display { sh_order: l, ..d }));
        }
    }
}

/// The error label under a view's toolbar (accessible text: tests read it).
pub fn error_label(ui: &mut Ui, scene: &Scene<'_>, done: Option<&ShDone>) {
    let Some(done) = done else {
        if scene.state.display.sh_overlay && scene.primary().is_some() {
            ui.weak("SH: computing…");
        }
        return;
    };
    let current = key_for(scene).is_some_and(|(_, k)| k == done.key);
    let text = summary(done, current);
    let r = ui.label(&text);
    if let Ok(res) = &done.value {
        r.on_hover_text(format!(
            "‖ĝ − g‖ / ‖g‖ over the {} of {} ({} quadrature rings); projected in {:.0} ms",
            match res.lobe.domain {
                Domain::Hemisphere => "hemisphere",
                Domain::Sphere => "sphere",
            },
            super::value_label(done.key.cosine),
            res.lobe.n_theta,
            done.elapsed.as_secs_f64() * 1e3
        ));
    }
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

    #[test]
    fn percentages() {
        assert_eq!(percent(0.234), "23.4 %");
        assert_eq!(percent(0.0123), "1.23 %");
        assert_eq!(percent(0.00012), "0.012 %");
    }
}
