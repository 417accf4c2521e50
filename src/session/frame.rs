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
}

impl Scene<'_> {
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

/// Builds the frame's scene from the state and the built evaluators.
pub fn build_scene<'a>(state: &'a AppState, runtime: &Runtime, interacting: bool) -> Scene<'a> {
    let brdfs = state
        .brdfs
        .iter()
        .filter(|e| state.is_drawn(e))
        .filter_map(|e| {
            let built = runtime.get(e.id)?;
            let brdf = built.brdf.clone()?;
            Some(SceneBrdf {
                id: e.id,
                label: display_name(state, e),
                rgb: e.color,
                brdf,
                revision: built.revision,
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
    }
}

/// A figure's scene: the state's drawn BRDFs, not interacting.
pub fn figure_scene<'a>(state: &'a AppState, runtime: &Runtime, transparent: bool) -> Scene<'a> {
    let mut scene = build_scene(state, runtime, false);
    scene.figure = true;
    scene.transparent = transparent;
    scene
}
