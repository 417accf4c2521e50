//! The scene of one frame: what every view reads, built from the state and
//! the built evaluators ([`build_scene`]). The window, offscreen figures and
//! `bv render` build it the same way.

use super::naming::display_name;
use super::runtime::Runtime;
use super::state::{AppState, Incident};
use bv_core::Brdf;
use std::sync::Arc;

/// One drawn BRDF, ready to evaluate.
#[derive(Clone)]
pub struct SceneBrdf {
    /// Its id in the state's list.
    pub id: u64,
    /// Display name (model name, numbered when the same model is loaded twice).
    pub label: String,
    /// Display colour (sRGB); views read it as an egui colour through
    /// `views::BrdfColor`.
    pub rgb: [u8; 3],
    /// The evaluator.
    pub brdf: Arc<dyn Brdf>,
    /// Changes whenever its parameters change (cache key).
    pub revision: u64,
    /// Whether it is the selected BRDF.
    pub selected: bool,
}

impl std::fmt::Debug for SceneBrdf {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.debug_struct("SceneBrdf")
            .field("id", &self.id)
            .field("label", &self.label)
            .field("revision", &self.revision)
            .finish_non_exhaustive()
    }
}

/// What every view reads in one frame.
pub struct Scene<'a> {
    /// The whole saved state (display options, camera, plot settings).
    pub state: &'a AppState,
    /// The drawn BRDFs, in list order.
    pub brdfs: Vec<SceneBrdf>,
    /// The light direction.
    pub incident: Incident,
    /// A pointer button is held somewhere (a slider or the light is being
    /// dragged): views may trade resolution for speed.
    pub interacting: bool,
    /// Drawn as a figure (screenshot, `bv render`): no hover hints or
    /// readouts, and slow results (albedo curves) computed before drawing
    /// rather than in the background.
    pub figure: bool,
    /// Figure with a transparent background: views leave their own
    /// backgrounds unfilled.
    pub transparent: bool,
    /// Factor on every stroke width the views draw (1; thicker in
    /// presentation mode, `presentation::LINE_SCALE`): read it through
    /// [`Scene::stroke`].
    pub line_scale: f32,
    /// Shown in presentation mode (a projector, a rendered slide): views
    /// keep every legend and formula (beside the plot where the plot is
    /// short), draw text no smaller than the body size and leave out hover
    /// hints.
    pub presenting: bool,
}

impl<'a> Scene<'a> {
    /// The same frame with only the BRDF `id` drawn, as the selected one
    /// (a panel of small multiples); nothing drawn when it is not here.
    pub fn only(&self, id: u64) -> Scene<'a> {
        Scene {
            state: self.state,
            brdfs: self
                .brdfs
                .iter()
                .filter(|b| b.id == id)
                .map(|b| SceneBrdf {
                    selected: true,
                    ..b.clone()
                })
                .collect(),
            incident: self.incident,
            interacting: self.interacting,
            figure: self.figure,
            transparent: self.transparent,
            line_scale: self.line_scale,
            presenting: self.presenting,
        }
    }

    /// The BRDF drawn opaque and coloured by value in the lobe view: the
    /// selected one if drawn, else the first drawn.
    pub fn primary(&self) -> Option<&SceneBrdf> {
        self.brdfs
            .iter()
            .find(|b| b.selected)
            .or_else(|| self.brdfs.first())
    }

    /// A stroke width of `points` as this frame draws it (thicker when
    /// presenting).
    pub fn stroke(&self, points: f32) -> f32 {
        points * self.line_scale
    }

    /// The unit direction towards the light.
    pub fn wi(&self) -> glam::DVec3 {
        self.incident.direction()
    }
}

/// The evaluator of a surface turned about its normal by `turn_deg`, and a
/// revision for it: the evaluator's own when not turned, else one that
/// differs from every unturned revision (they count up from 0; this one has
/// the top bit set) and from the revisions of other angles, so that views'
/// caches keyed by revision recompute.
fn turned(brdf: Arc<dyn Brdf>, revision: u64, turn_deg: f64) -> (Arc<dyn Brdf>, u64) {
    if turn_deg == 0.0 || !turn_deg.is_finite() {
        return (brdf, revision);
    }
    use std::hash::{Hash, Hasher};
    let mut h = std::collections::hash_map::DefaultHasher::new();
    (revision, turn_deg.to_bits()).hash(&mut h);
    let turned: Arc<dyn Brdf> =
        Arc::new(bv_core::rotated::Rotated::new(brdf, turn_deg.to_radians()));
    (turned, h.finish() | 1 << 63)
}

/// Builds the frame's scene from the state and the built evaluators.
pub fn build_scene<'a>(state: &'a AppState, runtime: &Runtime, interacting: bool) -> Scene<'a> {
    let brdfs = state
        .brdfs
        .iter()
        .filter(|e| state.is_drawn(e))
        .filter_map(|e| {
            let built = runtime.get(e.id)?;
            let (brdf, revision) =
                turned(built.brdf.clone()?, built.revision, state.display.turn_deg);
            Some(SceneBrdf {
                id: e.id,
                label: display_name(state, e),
                rgb: e.color,
                brdf,
                revision,
                selected: state.selected == Some(e.id),
            })
        })
        .collect();
    Scene {
        state,
        brdfs,
        incident: state.incident,
        interacting,
        figure: false,
        transparent: false,
        line_scale: 1.0,
        presenting: false,
    }
}

/// A figure's scene: the state's drawn BRDFs, not interacting.
pub fn figure_scene<'a>(state: &'a AppState, runtime: &Runtime, transparent: bool) -> Scene<'a> {
    let mut scene = build_scene(state, runtime, false);
    scene.figure = true;
    scene.transparent = transparent;
    scene
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::ModelSpec;
    use glam::DVec3;

    /// A turned surface: an anisotropic Ward turned by 90° evaluates as Ward
    /// with its roughnesses swapped (its highlight turned), with a revision
    /// of its own; an isotropic model evaluates as before.
    #[test]
    fn a_turned_surface_turns_anisotropic_models() {
        let ward = |ax: f64, ay: f64| {
            ModelSpec::from_json("ward", &serde_json::json!({"alpha_x": ax, "alpha_y": ay}))
                .unwrap()
        };
        let mut state = AppState::default();
        state.add(ward(0.1, 0.4));
        state.add(ModelSpec::new("blinn-phong").unwrap());
        let mut runtime = Runtime::default();
        runtime.sync(&state);
        let plain = build_scene(&state, &runtime, false);
        let before: Vec<u64> = plain.brdfs.iter().map(|b| b.revision).collect();
        let mut turned_state = state.clone();
        turned_state.display.turn_deg = 90.0;
        let turned = build_scene(&turned_state, &runtime, false);
        let swapped = ward(0.4, 0.1).build().unwrap();
        let wi = DVec3::new(0.5, 0.2, 0.84).normalize();
        let mut max_change = 0.0f64;
        for k in 0..200 {
            let t = 0.05 + 1.4 * (k % 20) as f64 / 20.0;
            let p = 0.3 * k as f64;
            let wo = DVec3::new(t.sin() * p.cos(), t.sin() * p.sin(), t.cos());
            let a = turned.brdfs[0].brdf.eval(wi, wo);
            let b = swapped.eval(wi, wo);
            assert!((a - b).abs().max_element() <= 1e-9 * b.abs().max_element().max(1.0));
            max_change = max_change.max((a - plain.brdfs[0].brdf.eval(wi, wo)).abs().max_element());
            let iso = turned.brdfs[1].brdf.eval(wi, wo) - plain.brdfs[1].brdf.eval(wi, wo);
            assert!(iso.abs().max_element() < 1e-9);
        }
        assert!(
            max_change > 0.1,
            "turning did not change Ward: {max_change}"
        );
        for (b, r) in turned.brdfs.iter().zip(&before) {
            assert_ne!(b.revision, *r);
        }
    }
}
