//! Saved settings of the two rendered views: the lit sphere
//! (`views::lit_sphere`) and the environment-lit object
//! (`views::environment`). They live in [`super::state::AppState::lighting`]
//! and change through [`super::Command::SetLitView`] and
//! [`super::Command::SetEnvView`], like every other part of the state.

use serde::{Deserialize, Serialize};

/// Exposure range of the EV controls, in stops.
pub const EV_RANGE: (f64, f64) = (-12.0, 12.0);

/// Tone map choice (a serialisable mirror of the renderers' tone map).
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum Tone {
    /// None: exposed radiance is clipped at 1 (what a reading of values wants).
    #[default]
    None,
    /// Reinhard et al. 2002, eq. 3.
    Reinhard,
    /// Narkowicz's ACES filmic fit.
    Aces,
}

impl Tone {
    /// Every choice, in menu order.
    pub const ALL: [Tone; 3] = [Tone::None, Tone::Reinhard, Tone::Aces];

    /// Menu label.
    pub fn label(self) -> &'static str {
        match self {
            Tone::None => "no tone map (clip)",
            Tone::Reinhard => "Reinhard",
            Tone::Aces => "ACES filmic",
        }
    }
}

/// What is behind the lit spheres.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum BackgroundChoice {
    /// The views' own background colour of the current theme.
    #[default]
    Theme,
    /// Black.
    Black,
    /// 18 % grey (sRGB 118).
    Grey,
    /// White.
    White,
    /// A grey checkerboard (shows the silhouette of dark and bright materials).
    Checker,
}

impl BackgroundChoice {
    /// Every choice, in menu order.
    pub const ALL: [BackgroundChoice; 5] = [
        BackgroundChoice::Theme,
        BackgroundChoice::Black,
        BackgroundChoice::Grey,
        BackgroundChoice::White,
        BackgroundChoice::Checker,
    ];

    /// Menu label.
    pub fn label(self) -> &'static str {
        match self {
            BackgroundChoice::Theme => "theme",
            BackgroundChoice::Black => "black",
            BackgroundChoice::Grey => "18% grey",
            BackgroundChoice::White => "white",
            BackgroundChoice::Checker => "checker",
        }
    }
}

/// The object under the environment.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default, Serialize, Deserialize)]
pub enum EnvObject {
    /// A sphere per BRDF.
    #[default]
    Sphere,
    /// A torus per BRDF (tangent along the ring, so anisotropy shows; with
    /// self-shadowing).
    Torus,
    /// A flat sample per BRDF, seen from [`EnvView::elevation_deg`] above
    /// (LECTURE.md N13).
    Plane,
}

impl EnvObject {
    /// Every choice, in menu order.
    pub const ALL: [EnvObject; 3] = [EnvObject::Sphere, EnvObject::Torus, EnvObject::Plane];

    /// Menu label.
    pub fn label(self) -> &'static str {
        match self {
            EnvObject::Sphere => "sphere",
            EnvObject::Torus => "torus",
            EnvObject::Plane => "plane",
        }
    }
}

/// Settings of the lit sphere view.
#[derive(Debug, Clone, Copy, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct LitView {
    /// Exposure in stops (radiance × 2^EV).
    pub exposure_ev: f64,
    /// Tone map after exposure.
    pub tone_map: Tone,
    /// Background.
    pub background: BackgroundChoice,
    /// Every drawn BRDF side by side (else only the selected one).
    pub side_by_side: bool,
}

impl Default for LitView {
    fn default() -> Self {
        Self {
            exposure_ev: 0.0,
            tone_map: Tone::None,
            background: BackgroundChoice::Theme,
            side_by_side: true,
        }
    }
}

/// Settings of the environment view.
#[derive(Debug, Clone, PartialEq, Serialize, Deserialize)]
#[serde(default)]
pub struct EnvView {
    /// Exposure in stops.
    pub exposure_ev: f64,
    /// Tone map after exposure.
    pub tone_map: Tone,
    /// Every drawn BRDF side by side (else only the selected one).
    pub side_by_side: bool,
    /// The object.
    pub object: EnvObject,
    /// Rotation of the environment about the vertical axis, degrees.
    pub rotation_deg: f64,
    /// The environment file (`.hdr` or `.exr`); `None` is the built-in studio
    /// (`assets/studio.hdr`, compiled into the binary).
    pub map: Option<String>,
    /// Samples per pixel after which accumulation stops (saves the CPU once
    /// the image is clean).
    pub target_spp: u32,
    /// Samples per pixel of a figure as asked for (`bv render --spp`):
    /// honoured exactly, on a software renderer too. `None`: the figure
    /// takes `target_spp`, within a software renderer's sample budget.
    /// Not saved: it belongs to one command.
    #[serde(skip)]
    pub figure_spp: Option<u32>,
    /// The plane object: the eye's elevation above the sample, degrees (90:
    /// looking straight down, normal incidence; 5: grazing).
    pub elevation_deg: f64,
}

/// The range of [`EnvView::elevation_deg`]: from grazing (the sample is a
/// sliver at the horizon below 2°) to straight down.
pub const ELEVATION_RANGE: (f64, f64) = (2.0, 90.0);

/// Largest accepted target sample count.
pub const MAX_TARGET_SPP: u32 = 1 << 16;

impl Default for EnvView {
    fn default() -> Self {
        Self {
            exposure_ev: 0.0,
            tone_map: Tone::Aces,
            side_by_side: true,
            object: EnvObject::Sphere,
            rotation_deg: 0.0,
            map: None,
            target_spp: 1024,
            figure_spp: None,
            elevation_deg: 30.0,
        }
    }
}

/// Both views' settings (one field of the saved state).
#[derive(Debug, Clone, PartialEq, Default, Serialize, Deserialize)]
#[serde(default)]
pub struct Lighting {
    /// The lit sphere view.
    pub lit: LitView,
    /// The environment view.
    pub env: EnvView,
}

impl Lighting {
    /// The same settings with every number in range (hand-edited files).
    pub fn sanitised(mut self) -> Self {
        let ev = |x: f64| {
            if x.is_finite() {
                x.clamp(EV_RANGE.0, EV_RANGE.1)
            } else {
                0.0
            }
        };
        self.lit.exposure_ev = ev(self.lit.exposure_ev);
        self.env.exposure_ev = ev(self.env.exposure_ev);
        self.env.rotation_deg = if self.env.rotation_deg.is_finite() {
            (self.env.rotation_deg + 180.0).rem_euclid(360.0) - 180.0
        } else {
            0.0
        };
        self.env.target_spp = self.env.target_spp.clamp(1, MAX_TARGET_SPP);
        self.env.figure_spp = self.env.figure_spp.map(|n| n.clamp(1, MAX_TARGET_SPP));
        self.env.elevation_deg = if self.env.elevation_deg.is_finite() {
            self.env
                .elevation_deg
                .clamp(ELEVATION_RANGE.0, ELEVATION_RANGE.1)
        } else {
            EnvView::default().elevation_deg
        };
        if self.env.map.as_deref().is_some_and(|m| m.trim().is_empty()) {
            self.env.map = None;
        }
        self
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn sanitising_clamps_and_wraps() {
        let mut l = Lighting::default();
        l.lit.exposure_ev = f64::NAN;
        l.env.exposure_ev = 99.0;
        l.env.rotation_deg = 270.0;
        l.env.target_spp = 0;
        l.env.map = Some("  ".into());
        let s = l.sanitised();
        assert_eq!(s.lit.exposure_ev, 0.0);
        assert_eq!(s.env.exposure_ev, EV_RANGE.1);
        assert!((s.env.rotation_deg + 90.0).abs() < 1e-12);
        assert_eq!(s.env.target_spp, 1);
        assert_eq!(s.env.map, None);
    }

    #[test]
    fn old_saved_states_get_the_defaults() {
        let l: Lighting = serde_json::from_str(r#"{"lit": {"exposure_ev": 1.5}}"#).unwrap();
        assert_eq!(l.lit.exposure_ev, 1.5);
        assert_eq!(l.lit.tone_map, Tone::None);
        assert_eq!(l.env, EnvView::default());
    }
}
