//! The viewer's state: everything that is saved between runs (loaded BRDFs and
//! their parameters, incident direction, camera, display options, layout, theme),
//! kept apart from GPU resources and caches.
//!
//! It is serialised to JSON (not eframe's RON) because a BRDF's parameters are
//! stored in their `ModelSpec::to_json` form, the same form scene files and
//! `bv eval` use; a saved BRDF whose model is gone or whose values no longer
//! validate is dropped with a note instead of failing the whole session.

use bv_core::ModelSpec;
use bv_core::microsurface::SlopeDistribution;
use serde::{Deserialize, Deserializer, Serialize, Serializer};
use serde_json::Value;

/// Current layout of the saved state; bump when a field changes meaning.
pub const STATE_VERSION: u32 = 1;

/// Distinct colours for overlaid BRDFs (Tableau 10, reordered so that the first
/// few differ most and read on both dark and light backgrounds).
pub const PALETTE: [[u8; 3]; 10] = [
    [78, 151, 234],  // blue
    [242, 142, 43],  // orange
    [89, 185, 90],   // green
    [225, 87, 89],   // red
    [176, 122, 211], // purple
    [188, 189, 34],  // olive (not the light's sun yellow)
    [118, 183, 178], // teal
    [255, 157, 167], // pink
    [176, 135, 104], // brown
    [186, 176, 172], // grey
];

/// Most BRDFs in one scene. Every view draws every BRDF (the lobe view
/// keeps a mesh per BRDF: a scene of 100 took 1.36 GB to draw at 400×300),
/// the palette has ten colours and a legend room for about as many; a figure
/// with more curves than this cannot be read. Scene files, decks, the
/// command line and the window's "add" all stop here.
pub const MAX_BRDFS: usize = 16;

/// One loaded BRDF.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
pub struct BrdfEntry {
    /// Stable id within this session's list (never reused while the app runs).
    pub id: u64,
    /// Model and parameters.
    #[serde(with = "spec_json")]
    pub spec: ModelSpec,
    /// Display colour (sRGB).
    pub color: [u8; 3],
    /// Whether it is drawn.
    pub visible: bool,
    /// A name chosen for it (a material preset's), shown instead of the
    /// model's; absent in sessions and scene files written before names.
    #[serde(default, skip_serializing_if = "Option::is_none")]
    pub name: Option<String>,
}

/// The incident (light) direction, in degrees because that is what the sliders
/// show and what a lecturer quotes.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
pub struct Incident {
    /// Polar angle from the normal, 0..180°: above 90° the light is below
    /// the surface (inside the medium of a transmitting model), and the
    /// horizon band [`Incident::in_horizon_gap`] is excluded.
    pub theta_deg: f64,
    /// Azimuth from the tangent towards the bitangent, −180..180°.
    pub phi_deg: f64,
}

impl Default for Incident {
    fn default() -> Self {
        Self {
            theta_deg: 45.0,
            phi_deg: 0.0,
        }
    }
}

impl Incident {
    /// Largest polar angle the sliders, drags, scene files and `bv render`
    /// allow: straight from below (issue 33, light inside a transmitting
    /// model's medium).
    pub const MAX_THETA_DEG: f64 = 180.0;

    /// Largest polar angle above the surface: the horizon itself is excluded
    /// because every reflection model is 0 there and a refracted ray is not
    /// defined (the light grazes the interface).
    pub const MAX_ABOVE_DEG: f64 = 89.5;

    /// Smallest polar angle below the surface, the mirror of
    /// [`Self::MAX_ABOVE_DEG`].
    pub const MIN_BELOW_DEG: f64 = 90.5;

    /// Whether `theta_deg` lies in the excluded band around the horizon,
    /// (89.5°, 90.5°).
    pub fn in_horizon_gap(theta_deg: f64) -> bool {
        theta_deg > Self::MAX_ABOVE_DEG && theta_deg < Self::MIN_BELOW_DEG
    }

    /// Why a θ in the horizon band is refused (scene files, decks,
    /// `bv render --theta-i`).
    pub fn horizon_reason(theta_deg: f64) -> String {
        format!(
            "{}° is at the horizon: the light must be above the surface (≤ {}°) or \
             below it (≥ {}°, for a model that transmits)",
            bv_core::error::fmt_num(theta_deg),
            Self::MAX_ABOVE_DEG,
            Self::MIN_BELOW_DEG
        )
    }

    /// Whether the light is below the surface (θi > 90°).
    pub fn below(&self) -> bool {
        self.theta_deg > 90.0
    }

    /// The unit direction towards the light.
    pub fn direction(&self) -> glam::DVec3 {
        bv_core::frame::from_spherical(self.theta_deg.to_radians(), self.phi_deg.to_radians())
    }

    /// The same direction with θ clamped to the slider range and φ wrapped.
    /// A θ in the horizon band goes to the nearer of its edges (exactly 90°
    /// to 89.5°, above the surface, as it always did): a defined light,
    /// never one in the surface.
    pub fn clamped(self) -> Self {
        let theta = if self.theta_deg.is_finite() {
            let t = self.theta_deg.clamp(0.0, Self::MAX_THETA_DEG);
            if Self::in_horizon_gap(t) {
                if t <= 90.0 {
                    Self::MAX_ABOVE_DEG
                } else {
                    Self::MIN_BELOW_DEG
                }
            } else {
                t
            }
        } else {
            0.0
        };
        // Wrapped into (−180°, 180°] in degrees: a value already there is
        // kept exactly (a round trip through radians turns 30° into
        // 29.999999999999993°, which a scene file then reports as changed).
        let phi = if self.phi_deg.is_finite() {
            if self.phi_deg > -180.0 && self.phi_deg <= 180.0 {
                self.phi_deg
            } else {
                let p = (self.phi_deg + 180.0).rem_euclid(360.0) - 180.0;
                if p <= -180.0 { p + 360.0 } else { p }
            }
        } else {
            0.0
        };
        Self {
            theta_deg: theta,
            phi_deg: phi,
        }
    }

    /// The incident direction pointing at `w` (any non-zero vector, above or
    /// below the surface; the horizon band is clamped to its nearer edge).
    pub fn from_direction(w: glam::DVec3) -> Self {
        let (theta, phi) = bv_core::frame::to_spherical(w.normalize_or(glam::DVec3::Z));
        Self {
            theta_deg: theta.to_degrees(),
            phi_deg: phi.to_degrees(),
        }
        .clamped()
    }
}

/// Options shared by every view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Display {
    /// Logarithmic radius / axis.
    pub log: bool,
    /// Show `f · cos θo` instead of `f`.
    pub cosine: bool,
    /// Lobe view: draw the mesh's grid lines instead of a filled surface.
    pub wireframe: bool,
    /// Lobe view: colour the selected lobe by value (otherwise by its own colour).
    pub color_by_value: bool,
    /// Lobe view: scale the scene so that the largest lobe fills the unit
    /// hemisphere; otherwise keep the last scale while parameters change.
    pub auto_scale: bool,
    /// Lobe and polar views: overlay the selected lobe's spherical-harmonics
    /// reconstruction.
    pub sh_overlay: bool,
    /// Its highest order L (0–16).
    pub sh_order: u8,
    /// Lobe and polar views: overlay the selected BRDF rebuilt from the first
    /// K terms of its half/difference-table factorisation.
    pub factor_overlay: bool,
    /// Its number of terms K (1..=[`Display::MAX_FACTOR_TERMS`]).
    pub factor_terms: u8,
    /// The surface turned about its normal by this angle, degrees
    /// (counter-clockwise seen from above, from the tangent towards the
    /// bitangent): "if you turn an object, does its shading change?" An
    /// anisotropic highlight turns with the surface; an isotropic one does
    /// not. Every view draws the turned surface.
    pub turn_deg: f64,
    /// Figures of one view (the export dialog, `bv render --caption`) carry
    /// a caption: each drawn BRDF with its model and parameters, and the
    /// light's direction.
    pub caption: bool,
}

impl Default for Display {
    fn default() -> Self {
        Self {
            log: false,
            cosine: false,
            wireframe: false,
            color_by_value: true,
            auto_scale: true,
            sh_overlay: false,
            sh_order: 4,
            factor_overlay: false,
            factor_terms: 2,
            turn_deg: 0.0,
            caption: false,
        }
    }
}

impl Display {
    /// Most factorisation terms the overlay and the factorisation view use:
    /// past 8 the rebuilt lobes of the catalogue's models no longer differ
    /// visibly from the table.
    pub const MAX_FACTOR_TERMS: u8 = 8;
}

/// The orbit camera of the lobe view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct Camera {
    /// Azimuth of the eye around +z, degrees (90 puts the eye on +y, so that
    /// light at φi = 0 comes from the left and its mirror lobe leans right,
    /// like the polar plot).
    pub yaw_deg: f32,
    /// Elevation of the eye above the ground plane, degrees.
    pub pitch_deg: f32,
    /// Distance from the target in units of the unit hemisphere.
    pub distance: f32,
    /// World units per radius unit when auto-scale is off (1/sr per unit).
    pub fixed_scale: f32,
}

impl Default for Camera {
    fn default() -> Self {
        Self {
            yaw_deg: 90.0,
            pitch_deg: 20.0,
            distance: 4.9,
            fixed_scale: 1.0,
        }
    }
}

impl Camera {
    /// Closest and farthest eye distances.
    pub const DISTANCE_RANGE: (f32, f32) = (1.5, 30.0);
    /// Elevation limits (a little below the ground to look at transmission).
    pub const PITCH_RANGE: (f32, f32) = (-85.0, 89.0);

    /// The same camera with its angles and distance in range.
    pub fn clamped(mut self) -> Self {
        let ok = |x: f32, d: f32| if x.is_finite() { x } else { d };
        let d = Self::default();
        self.yaw_deg = ok(self.yaw_deg, d.yaw_deg).rem_euclid(360.0);
        self.pitch_deg =
            ok(self.pitch_deg, d.pitch_deg).clamp(Self::PITCH_RANGE.0, Self::PITCH_RANGE.1);
        self.distance =
            ok(self.distance, d.distance).clamp(Self::DISTANCE_RANGE.0, Self::DISTANCE_RANGE.1);
        self.fixed_scale = if self.fixed_scale.is_finite() && self.fixed_scale > 0.0 {
            self.fixed_scale
        } else {
            1.0
        };
        self
    }
}

/// What the Cartesian plot's horizontal axis is.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum CartesianAxis {
    /// θo in the plane of incidence, signed (negative on the light's side).
    #[default]
    ThetaO,
    /// θh at a fixed θd (φd = 90°, φh = 0).
    ThetaH,
    /// θd at a fixed θh (φd = 90°, φh = 0).
    ThetaD,
}

/// Plot settings.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct PlotSettings {
    /// The Cartesian plot's horizontal axis.
    pub axis: CartesianAxis,
    /// The fixed θd (for θh curves), degrees.
    pub fixed_theta_d_deg: f64,
    /// The fixed θh (for θd curves), degrees.
    pub fixed_theta_h_deg: f64,
    /// The Snell view's interface.
    pub snell: SnellSettings,
    /// The microfacet term view's charts.
    pub terms: TermToggles,
    /// The albedo view's options.
    pub albedo: AlbedoSettings,
    /// The microsurface view's specimen.
    pub microsurface: MicrosurfaceSettings,
    /// The polar view's *gonio* overlay: a virtual gonioreflectometer's
    /// readings of the primary BRDF, dots with error bars over its curve
    /// (LECTURE.md N8; `derive::gonio`).
    pub gonio: bool,
    /// The gonio overlay measures a simulated microsurface with the
    /// primary BRDF's slopes (F = 1; single and all bounces) instead of
    /// the BRDF itself (issue 29).
    pub gonio_surface: bool,
    /// The polar view as small multiples (LECTURE.md N5): each drawn BRDF
    /// in its own panel, on its own scale, instead of all of them overlaid
    /// on the largest one's.
    pub small_multiples: bool,
    /// The image slice view's display (LECTURE.md N1: the slice's φd and
    /// exposure kept in the scene, so that a slide shows the band it means
    /// rather than one clipped to white).
    pub slice: SliceSettings,
}

/// The image slice view's display settings: saved with the scene.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SliceSettings {
    /// The fixed difference azimuth φd, degrees (0–180).
    pub phi_d_deg: f64,
    /// θh on a √θh axis (as the MERL table's cells) instead of linear.
    pub sqrt_theta_h: bool,
    /// Exposure: `f` is multiplied by `2^ev` before the gamma.
    pub exposure_ev: f64,
    /// Display gamma: the shown level is `(2^ev f)^(1/γ)`.
    pub gamma: f64,
    /// Colour (RGB) or luminance (grey).
    pub chroma: bool,
    /// Every drawn BRDF, or only the selected one.
    pub all: bool,
    /// Residual mode: the relative error against `reference`.
    pub residual: bool,
    /// The BRDF the residuals are taken against (an id of the list); the
    /// first drawn BRDF when it is not set or not drawn.
    pub reference: Option<u64>,
    /// The relative error at either end of the colour map (1 = ±100 %).
    pub residual_range: f64,
}

impl SliceSettings {
    /// Accepted range of φd, degrees.
    pub const PHI_D_RANGE: (f64, f64) = (0.0, 180.0);
    /// Accepted range of the exposure, EV.
    pub const EV_RANGE: (f64, f64) = (-20.0, 20.0);
    /// Accepted range of the display gamma.
    pub const GAMMA_RANGE: (f64, f64) = (1.0, 4.0);
    /// Accepted range of the residual colour map's end (0.01 = ±1 %,
    /// 10 = ±1000 %).
    pub const RESIDUAL_RANGE: (f64, f64) = (0.01, 10.0);
}

impl Default for SliceSettings {
    fn default() -> Self {
        Self {
            phi_d_deg: 90.0,
            sqrt_theta_h: false,
            exposure_ev: 0.0,
            gamma: 2.2,
            chroma: true,
            all: true,
            residual: false,
            reference: None,
            residual_range: 1.0,
        }
    }
}

/// The albedo view's options: saved with the scene, so that a deck's slide
/// can show the white furnace (issue 29).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct AlbedoSettings {
    /// The white furnace: plot each microfacet model's lobe with F = 1,
    /// kd = 0, ks = 1 (`bv_core::Brdf::furnace`), and the energy it loses,
    /// `1 − E(μ)`; other models are left out.
    pub furnace: bool,
    /// Beside each ρhd, dashed, the swapped integral
    /// `ρdh(θ) = ∫ f(ωi, ωo) cos θi dωi` at θo = θ (LECTURE.md N12): equal
    /// to ρhd for a reciprocal BRDF, apart for one that is not.
    pub swapped: bool,
}

impl Default for PlotSettings {
    fn default() -> Self {
        Self {
            axis: CartesianAxis::ThetaO,
            fixed_theta_d_deg: 30.0,
            fixed_theta_h_deg: 0.0,
            snell: SnellSettings::default(),
            terms: TermToggles::default(),
            albedo: AlbedoSettings::default(),
            microsurface: MicrosurfaceSettings::default(),
            gonio: false,
            gonio_surface: false,
            small_multiples: false,
            slice: SliceSettings::default(),
        }
    }
}

/// The microsurface view's specimen (issue 29): saved with the scene, so
/// that a deck's slide shows the surface it means.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct MicrosurfaceSettings {
    /// Generate the surface from the selected BRDF's distribution and
    /// roughness when it names them (`bv_core::Ndf::slopes`); otherwise,
    /// or when it does not, from the two settings below.
    pub from_model: bool,
    /// The specimen's slope distribution when not taken from the model.
    pub distribution: SlopeDistribution,
    /// Its roughness α when not taken from the model.
    pub alpha: f64,
    /// Under the surface, the facet normals' histogram against the model's
    /// D(θm) (LECTURE.md N9: a rough surface and its NDF).
    pub ndf: bool,
}

impl Default for MicrosurfaceSettings {
    fn default() -> Self {
        Self {
            from_model: true,
            distribution: SlopeDistribution::Beckmann,
            alpha: 0.5,
            ndf: false,
        }
    }
}

/// Which charts the microfacet term view draws: saved with the scene, so
/// that a deck's slide can show D alone (LECTURE.md N1) or G2 alone.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize, Deserialize)]
#[serde(default)]
pub struct TermToggles {
    /// D(θh).
    pub d: bool,
    /// D on a logarithmic scale.
    pub log_d: bool,
    /// Smith's masking G1(ωo).
    pub g1: bool,
    /// The model's masking-shadowing G2(ωi, ωo).
    pub g2: bool,
    /// F(θd).
    pub f: bool,
    /// The v-groove cross-sections (Torrance & Sparrow's grooves, lit and
    /// seen parts) at three outgoing directions, under the charts.
    pub vgroove: bool,
}

impl Default for TermToggles {
    fn default() -> Self {
        Self {
            d: true,
            log_d: false,
            g1: true,
            g2: true,
            f: true,
            vgroove: false,
        }
    }
}

/// The Snell view's interface: saved with the scene, so that a deck's slide
/// can show the lecture's "optical manhole" (water seen from below).
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct SnellSettings {
    /// The view's own relative index of the medium below (used when the
    /// selected BRDF has no dielectric Fresnel term, or when `use_own` is set).
    pub eta: f64,
    /// Use `eta` even when the selected BRDF has a dielectric.
    pub use_own: bool,
    /// Light from below (from inside the medium η).
    pub from_below: bool,
}

impl SnellSettings {
    /// Accepted range of the view's own index.
    pub const ETA_RANGE: (f64, f64) = (1.0, 3.0);
}

impl Default for SnellSettings {
    fn default() -> Self {
        Self {
            eta: 1.5,
            use_own: false,
            from_below: false,
        }
    }
}

/// Colour theme.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Theme {
    /// Light text on dark grey.
    #[default]
    Dark,
    /// Dark text on white (projectors in bright rooms).
    Light,
}

/// Everything that persists between runs.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct AppState {
    /// Layout version of this record.
    pub version: u32,
    /// Loaded BRDFs, in list order.
    #[serde(deserialize_with = "lenient_entries")]
    pub brdfs: Vec<BrdfEntry>,
    /// Id of the BRDF whose parameters the panel shows.
    pub selected: Option<u64>,
    /// Id of the BRDF shown alone, if any.
    pub solo: Option<u64>,
    /// Next id to hand out.
    pub next_id: u64,
    /// Light direction.
    pub incident: Incident,
    /// Options shared by all views.
    pub display: Display,
    /// The lobe view's camera.
    pub camera: Camera,
    /// Plot settings.
    pub plots: PlotSettings,
    /// Id of the maximised view (see `views::REGISTRY`), if any.
    pub maximised: Option<String>,
    /// Colour theme.
    pub theme: Theme,
    /// Settings of the lit sphere and environment views.
    pub lighting: super::lighting::Lighting,
}

impl Default for AppState {
    fn default() -> Self {
        Self {
            version: STATE_VERSION,
            brdfs: Vec::new(),
            selected: None,
            solo: None,
            next_id: 1,
            incident: Incident::default(),
            display: Display::default(),
            camera: Camera::default(),
            plots: PlotSettings::default(),
            maximised: None,
            theme: Theme::default(),
            lighting: Default::default(),
        }
    }
}

impl AppState {
    /// The state a first run starts with: the first model of the catalogue
    /// (with its defaults) lit from 45°.
    pub fn first_run() -> Self {
        let mut s = Self::default();
        if let Some(info) = bv_core::catalogue().first()
            && let Ok(spec) = ModelSpec::new(info.id)
        {
            s.add(spec);
        }
        s
    }

    /// Whether the scene holds [`MAX_BRDFS`] BRDFs already (the window
    /// refuses to add another, with [`AppState::full_message`]).
    pub fn is_full(&self) -> bool {
        self.brdfs.len() >= MAX_BRDFS
    }

    /// Why a BRDF cannot be added to a full scene.
    pub fn full_message() -> String {
        format!("a scene holds at most {MAX_BRDFS} BRDFs; remove one before adding another")
    }

    /// Adds a BRDF with the first palette colour not in use; selects it and
    /// returns its id.
    pub fn add(&mut self, spec: ModelSpec) -> u64 {
        self.add_named(spec, None)
    }

    /// [`AppState::add`] with a display name (a preset's); an empty name
    /// counts as none.
    pub fn add_named(&mut self, spec: ModelSpec, name: Option<String>) -> u64 {
        let name = name.map(|n| n.trim().to_string()).filter(|n| !n.is_empty());
        let id = self.next_id.max(1);
        self.next_id = id + 1;
        let color = PALETTE
            .iter()
            .copied()
            .find(|c| !self.brdfs.iter().any(|b| b.color == *c))
            .unwrap_or(PALETTE[self.brdfs.len() % PALETTE.len()]);
        self.brdfs.push(BrdfEntry {
            id,
            spec,
            color,
            visible: true,
            name,
        });
        self.selected = Some(id);
        id
    }

    /// The entry with id `id`.
    pub fn entry(&self, id: u64) -> Option<&BrdfEntry> {
        self.brdfs.iter().find(|b| b.id == id)
    }

    /// The entry with id `id`, mutably.
    pub fn entry_mut(&mut self, id: u64) -> Option<&mut BrdfEntry> {
        self.brdfs.iter_mut().find(|b| b.id == id)
    }

    /// The selected entry, if any.
    pub fn selected_entry(&self) -> Option<&BrdfEntry> {
        self.selected.and_then(|id| self.entry(id))
    }

    /// Whether entry `e` is drawn (its own toggle, and the solo if one is set).
    pub fn is_drawn(&self, e: &BrdfEntry) -> bool {
        match self.solo {
            Some(s) if self.entry(s).is_some() => s == e.id,
            _ => e.visible,
        }
    }

    /// Repairs whatever a hand-edited or old saved state may hold: ids unique,
    /// selection and solo pointing at existing entries, ranges clamped.
    pub fn sanitised(mut self) -> Self {
        let mut seen = std::collections::HashSet::new();
        self.brdfs.retain(|b| seen.insert(b.id));
        // A stored session from before the limit (scene files refuse more).
        self.brdfs.truncate(MAX_BRDFS);
        let max_id = self.brdfs.iter().map(|b| b.id).max().unwrap_or(0);
        self.next_id = self.next_id.max(max_id + 1);
        if self.selected.is_none_or(|id| self.entry(id).is_none()) {
            self.selected = self.brdfs.first().map(|b| b.id);
        }
        if self.solo.is_some_and(|id| self.entry(id).is_none()) {
            self.solo = None;
        }
        self.incident = self.incident.clamped();
        self.camera = self.camera.clamped();
        let p = &mut self.plots;
        p.fixed_theta_d_deg = clamp_deg(p.fixed_theta_d_deg, 0.0, 89.5);
        p.fixed_theta_h_deg = clamp_deg(p.fixed_theta_h_deg, 0.0, 89.5);
        self.lighting = self.lighting.sanitised();
        self.display.sh_order = self
            .display
            .sh_order
            .min(bv_core::represent::sh::MAX_ORDER as u8);
        self.display.factor_terms = self
            .display
            .factor_terms
            .clamp(1, Display::MAX_FACTOR_TERMS);
        self.version = STATE_VERSION;
        self
    }

    /// The state as a JSON string (what is stored).
    pub fn to_json_string(&self) -> String {
        serde_json::to_string(self).unwrap_or_default()
    }

    /// Parses a stored state; `None` when it is not a state at all.
    pub fn from_json_str(text: &str) -> Option<Self> {
        serde_json::from_str::<Self>(text).ok().map(Self::sanitised)
    }
}

fn clamp_deg(x: f64, lo: f64, hi: f64) -> f64 {
    if x.is_finite() { x.clamp(lo, hi) } else { lo }
}

/// Serialises a spec as `{"model": …, "params": {…}}`.
mod spec_json {
    use super::*;

    pub fn serialize<S: Serializer>(spec: &ModelSpec, s: S) -> Result<S::Ok, S::Error> {
        let mut v = spec.to_json();
        // A user file's model (alone or in a mix) is saved by its path.
        crate::session::model_names::model_names_for_save(&mut v);
        v.serialize(s)
    }

    pub fn deserialize<'de, D: Deserializer<'de>>(d: D) -> Result<ModelSpec, D::Error> {
        let mut v = Value::deserialize(d)?;
        crate::session::model_names::model_names_for_load(&mut v);
        spec_from_json(&v).map_err(serde::de::Error::custom)
    }
}

/// A spec from its `{"model", "params"}` JSON form.
pub fn spec_from_json(v: &Value) -> Result<ModelSpec, String> {
    let model = v
        .get("model")
        .and_then(Value::as_str)
        .ok_or_else(|| "no `model` id".to_string())?;
    ModelSpec::from_json(model, v.get("params").unwrap_or(&Value::Null)).map_err(|e| e.to_string())
}

/// Keeps the saved entries that still parse; reports the others on stderr.
fn lenient_entries<'de, D: Deserializer<'de>>(d: D) -> Result<Vec<BrdfEntry>, D::Error> {
    let items = Vec::<Value>::deserialize(d)?;
    Ok(items
        .into_iter()
        .filter_map(|v| match serde_json::from_value::<BrdfEntry>(v) {
            Ok(e) => Some(e),
            Err(e) => {
                eprintln!("bv: dropping a saved BRDF that no longer loads: {e}");
                None
            }
        })
        .collect())
}

#[cfg(test)]
mod tests {
    use super::*;

    /// Azimuths in (−180°, 180°] are kept exactly; others wrap by whole
    /// turns into that range.
    #[test]
    fn azimuths_wrap_in_degrees_and_stay_exact() {
        let phi = |p: f64| {
            Incident {
                theta_deg: 45.0,
                phi_deg: p,
            }
            .clamped()
            .phi_deg
        };
        for k in -1799..=1800 {
            let p = k as f64 * 0.1;
            assert_eq!(phi(p), p, "{p}");
        }
        for p in [30.0, -33.0, 0.1, 179.99, 1.0 / 3.0] {
            assert_eq!(phi(p), p);
        }
        assert_eq!(phi(-180.0), 180.0);
        assert_eq!(phi(540.0), 180.0);
        assert_eq!(phi(190.0), -170.0);
        assert_eq!(phi(-190.0), 170.0);
        assert_eq!(phi(720.0 + 30.0), 30.0);
        assert_eq!(phi(f64::NAN), 0.0);
        assert!(phi(1e12).abs() <= 180.0);
    }

    #[test]
    fn state_round_trips_through_json() {
        let mut s = AppState::first_run();
        s.incident.theta_deg = 12.5;
        s.camera.yaw_deg = 33.0;
        s.display.log = true;
        let text = s.to_json_string();
        let back = AppState::from_json_str(&text).unwrap();
        assert_eq!(back, s);
    }

    #[test]
    fn bad_entries_are_dropped_and_ids_repaired() {
        let text = r#"{"brdfs": [
            {"id": 3, "spec": {"model": "no-such-model", "params": {}}, "color": [1,2,3], "visible": true},
            {"id": 4, "spec": {"model": "lambert", "params": {"albedo": 0.25}}, "color": [1,2,3], "visible": true},
            {"id": 4, "spec": {"model": "lambert", "params": {}}, "color": [1,2,3], "visible": true}
        ], "selected": 99, "solo": 3, "next_id": 0, "incident": {"theta_deg": 120, "phi_deg": 270}}"#;
        let s = AppState::from_json_str(text).unwrap();
        assert_eq!(s.brdfs.len(), 1);
        assert_eq!(s.brdfs[0].id, 4);
        assert_eq!(s.selected, Some(4));
        assert_eq!(s.solo, None);
        assert_eq!(s.next_id, 5);
        // 120° is a light below the surface (issue 33): kept.
        assert_eq!(s.incident.theta_deg, 120.0);
        assert!((s.incident.phi_deg - (-90.0)).abs() < 1e-9);
    }

    #[test]
    fn colours_are_distinct_until_the_palette_runs_out() {
        let mut s = AppState::default();
        for _ in 0..PALETTE.len() {
            s.add(ModelSpec::new("lambert").unwrap());
        }
        let mut colours: Vec<_> = s.brdfs.iter().map(|b| b.color).collect();
        colours.sort();
        colours.dedup();
        assert_eq!(colours.len(), PALETTE.len());
    }

    #[test]
    fn solo_hides_the_others() {
        let mut s = AppState::default();
        let a = s.add(ModelSpec::new("lambert").unwrap());
        let b = s.add(ModelSpec::new("lambert").unwrap());
        s.solo = Some(b);
        assert!(!s.is_drawn(s.entry(a).unwrap()));
        assert!(s.is_drawn(s.entry(b).unwrap()));
    }

    #[test]
    fn incident_from_direction_round_trips() {
        let i = Incident {
            theta_deg: 30.0,
            phi_deg: -45.0,
        };
        let back = Incident::from_direction(i.direction());
        assert!((back.theta_deg - 30.0).abs() < 1e-9);
        assert!((back.phi_deg + 45.0).abs() < 1e-9);
        // Below the surface is a light from below (issue 33).
        let low = Incident::from_direction(glam::DVec3::new(1.0, 0.0, -0.2));
        assert!((low.theta_deg - (90.0 + 0.2f64.atan().to_degrees())).abs() < 1e-9);
        assert!(low.below());
        // The horizon goes to the edge of the excluded band on its side.
        let flat = Incident::from_direction(glam::DVec3::new(1.0, 0.0, 0.0));
        assert_eq!(flat.theta_deg, Incident::MAX_ABOVE_DEG);
        let just_below = Incident::from_direction(glam::DVec3::new(1.0, 0.0, -1e-4));
        assert_eq!(just_below.theta_deg, Incident::MIN_BELOW_DEG);
    }

    #[test]
    fn incident_clamps_to_the_whole_sphere_without_the_horizon() {
        let c = |t: f64| {
            Incident {
                theta_deg: t,
                phi_deg: 0.0,
            }
            .clamped()
            .theta_deg
        };
        assert_eq!(c(-5.0), 0.0);
        assert_eq!(c(45.0), 45.0);
        assert_eq!(c(89.7), 89.5);
        assert_eq!(c(90.0), 89.5);
        assert_eq!(c(90.2), 90.5);
        assert_eq!(c(135.0), 135.0);
        assert_eq!(c(180.0), 180.0);
        assert_eq!(c(400.0), 180.0);
        assert_eq!(c(f64::NAN), 0.0);
        // Every clamped light is a finite unit direction, never in the surface.
        for t in [0.0, 89.5, 90.0, 90.5, 179.9, 180.0] {
            let w = Incident {
                theta_deg: t,
                phi_deg: 30.0,
            }
            .clamped()
            .direction();
            assert!(w.is_finite() && (w.length() - 1.0).abs() < 1e-12 && w.z != 0.0);
        }
    }
}
