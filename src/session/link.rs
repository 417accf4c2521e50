//! The scene as a link: the scene file's text ([`scene_file::to_toml`]),
//! deflated and written in URL-safe base64, after `#scene=1.` in a URL's
//! fragment (`1` is this encoding's version). The fragment never reaches a
//! server, so a link carries the whole scene without one.
//!
//! Opening a link runs the same strict checks as opening a scene file
//! ([`scene_file::from_toml_in`]), after refusing, with a message that says
//! which, a fragment that is too long, of an unknown version, not base64, not
//! deflate data, inflating past the scene files' 1 MiB cap, or not UTF-8.
//! The caller then shows the message and starts from the default scene.

use super::scene_file::{self, Builds, Loaded, SceneError};
use super::state::AppState;
use base64::Engine as _;

/// The fragment's key for a scene.
pub const KEY: &str = "scene";

/// The version of the encoding after the key (`#scene=1.…`).
pub const VERSION: &str = "1";

/// The longest encoded scene a link may carry, in characters. Browsers keep
/// URLs of a few megabytes, but a scene of a dozen BRDFs deflates to well
/// under a kilobyte; anything longer is not a link bv wrote.
pub const MAX_ENCODED: usize = 64 * 1024;

/// The most a link's scene may inflate to: the cap scene files are read with.
pub const MAX_TEXT: usize = 1 << 20;

/// Why a link's scene could not be opened.
#[derive(Debug, thiserror::Error)]
pub enum LinkError {
    /// The fragment has no `scene=` entry.
    #[error("the link holds no scene")]
    NoScene,
    /// The encoded scene is longer than [`MAX_ENCODED`].
    #[error("the link's scene is {0} characters long; bv's links hold at most {MAX_ENCODED}")]
    TooLong(usize),
    /// The version before the dot is not [`VERSION`].
    #[error("the link's scene is of version `{0}`; this bv reads version {VERSION}")]
    Version(String),
    /// Not URL-safe base64.
    #[error("the link's scene is not valid base64 ({0})")]
    Base64(String),
    /// Not deflate data, or it inflates past [`MAX_TEXT`].
    #[error("the link's scene is not a compressed scene ({0})")]
    Inflate(String),
    /// The inflated bytes are not UTF-8 text.
    #[error("the link's scene is not text")]
    NotText,
    /// The text is not a scene bv accepts.
    #[error("the link's scene is refused: {0}")]
    Scene(#[from] SceneError),
}

/// The fragment (without `#`) that carries `state`.
pub fn encode(state: &AppState) -> Result<String, SceneError> {
    let text = scene_file::to_toml(state)?;
    // Level 9: links are made once and read by people pasting them.
    let packed = miniz_oxide::deflate::compress_to_vec(text.as_bytes(), 9);
    let b64 = base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(packed);
    Ok(format!("{KEY}={VERSION}.{b64}"))
}

/// `url` (whatever fragment it had dropped) with `state` in its fragment.
pub fn url_with(url: &str, state: &AppState) -> Result<String, SceneError> {
    let base = url.split('#').next().unwrap_or(url);
    Ok(format!("{base}#{}", encode(state)?))
}

/// The scene of a URL fragment (with or without its `#`; other `&`-separated
/// entries are ignored). File paths in it (MERL tables, environment maps) are
/// kept; a BRDF whose table cannot be read is a warning, as in the window.
pub fn decode(fragment: &str) -> Result<Loaded, LinkError> {
    let fragment = fragment.strip_prefix('#').unwrap_or(fragment);
    let value = fragment
        .split('&')
        .find_map(|kv| kv.strip_prefix(KEY)?.strip_prefix('='))
        .ok_or(LinkError::NoScene)?;
    if value.len() > MAX_ENCODED {
        return Err(LinkError::TooLong(value.len()));
    }
    let (version, b64) = value
        .split_once('.')
        .ok_or_else(|| LinkError::Version(String::new()))?;
    if version != VERSION {
        // Quoted in the message: keep only a short, printable prefix.
        let shown: String = version
            .chars()
            .take(16)
            .filter(|c| !c.is_control())
            .collect();
        return Err(LinkError::Version(shown));
    }
    let packed = base64::engine::general_purpose::URL_SAFE_NO_PAD
        .decode(b64.trim_end_matches('='))
        .map_err(|e| LinkError::Base64(e.to_string()))?;
    let bytes =
        miniz_oxide::inflate::decompress_to_vec_with_limit(&packed, MAX_TEXT).map_err(|e| {
            LinkError::Inflate(match e.status {
                miniz_oxide::inflate::TINFLStatus::HasMoreOutput => {
                    format!("it inflates past {} MiB", MAX_TEXT >> 20)
                }
                s => format!("{s:?}"),
            })
        })?;
    let text = String::from_utf8(bytes).map_err(|_| LinkError::NotText)?;
    Ok(scene_file::from_toml_in(&text, None, Builds::Warn)?)
}

/// Whether a URL fragment (with or without its `#`) carries a scene at all:
/// a page without one starts from the saved session instead.
pub fn has_scene(fragment: &str) -> bool {
    let fragment = fragment.strip_prefix('#').unwrap_or(fragment);
    fragment.split('&').any(|kv| kv.starts_with("scene="))
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::session::lighting::{BackgroundChoice, EnvObject, Tone};
    use crate::session::state::{CartesianAxis, Incident, Theme};
    use bv_core::ModelSpec;

    /// A state in which every section differs from the default (checked by
    /// `the_sample_changes_every_section`).
    fn sample() -> AppState {
        let mut s = AppState::default();
        s.add(
            ModelSpec::from_json("lambert", &serde_json::json!({"albedo": [0.2, 0.4, 0.6]}))
                .unwrap(),
        );
        s.add_named(
            ModelSpec::from_json("cook-torrance", &serde_json::json!({"alpha_x": 0.37})).unwrap(),
            Some("rough gold".into()),
        );
        s.add(ModelSpec::new("oren-nayar").unwrap());
        s.brdfs[0].visible = false;
        s.brdfs[1].color = [12, 200, 7];
        s.selected = Some(s.brdfs[1].id);
        s.solo = Some(s.brdfs[2].id);
        s.incident = Incident {
            theta_deg: 33.25,
            phi_deg: -20.0,
        };
        s.display.log = true;
        s.display.cosine = true;
        s.display.wireframe = true;
        s.display.sh_order = 6;
        s.camera.yaw_deg = 12.5;
        s.camera.pitch_deg = -7.25;
        s.camera.distance = 3.5;
        s.plots.axis = CartesianAxis::ThetaD;
        s.plots.fixed_theta_h_deg = 17.5;
        s.maximised = Some("polar".into());
        s.theme = Theme::Light;
        s.lighting.lit.exposure_ev = -1.5;
        s.lighting.lit.tone_map = Tone::Reinhard;
        s.lighting.lit.background = BackgroundChoice::Checker;
        s.lighting.lit.side_by_side = true;
        s.lighting.env.exposure_ev = 0.75;
        s.lighting.env.tone_map = Tone::None;
        s.lighting.env.object = EnvObject::Torus;
        s.lighting.env.rotation_deg = 123.0;
        s.lighting.env.target_spp = 96;
        s.sanitised()
    }

    #[test]
    fn the_sample_changes_every_section() {
        // A round trip only proves what the sample sets: every top-level
        // field (but the format version) must differ from the default.
        let a = serde_json::to_value(sample()).unwrap();
        let d = serde_json::to_value(AppState::default()).unwrap();
        let fields = a.as_object().unwrap();
        assert!(fields.len() >= 10, "{fields:?}");
        for (k, v) in fields {
            if k != "version" {
                assert_ne!(Some(v), d.get(k), "the sample leaves `{k}` at its default");
            }
        }
        assert_ne!(a["lighting"]["lit"], d["lighting"]["lit"]);
        assert_ne!(a["lighting"]["env"], d["lighting"]["env"]);
    }

    #[test]
    fn every_field_survives_a_round_trip() {
        let s = sample();
        let fragment = encode(&s).unwrap();
        assert!(fragment.starts_with("scene=1."), "{fragment}");
        // Only characters a fragment keeps as they are.
        assert!(
            fragment["scene=1.".len()..]
                .bytes()
                .all(|b| b.is_ascii_alphanumeric() || b == b'-' || b == b'_'),
            "{fragment}"
        );
        for f in [
            fragment.clone(),
            format!("#{fragment}"),
            format!("x=2&{fragment}&y"),
        ] {
            let back = decode(&f).unwrap();
            assert_eq!(back.warnings, Vec::<String>::new());
            assert_eq!(back.state, s);
        }
        // The scene compresses: the link is shorter than the scene file.
        let text = scene_file::to_toml(&s).unwrap();
        assert!(
            fragment.len() < text.len(),
            "{} vs {}",
            fragment.len(),
            text.len()
        );
    }

    #[test]
    fn a_url_keeps_its_address_and_replaces_its_fragment() {
        let s = sample();
        let u = url_with("http://localhost:8080/index.html#scene=1.old", &s).unwrap();
        assert!(
            u.starts_with("http://localhost:8080/index.html#scene=1."),
            "{u}"
        );
        assert!(!u.contains("old"));
        let (_, fragment) = u.split_once('#').unwrap();
        assert_eq!(decode(fragment).unwrap().state, s);
        assert!(has_scene(fragment) && has_scene(&format!("#{fragment}")));
        assert!(!has_scene("") && !has_scene("#view=polar"));
    }

    fn b64(bytes: &[u8]) -> String {
        base64::engine::general_purpose::URL_SAFE_NO_PAD.encode(bytes)
    }

    #[test]
    fn hostile_fragments_are_refused_with_a_reason() {
        let good = encode(&sample()).unwrap();
        let payload = good.strip_prefix("scene=1.").unwrap();
        let cases: Vec<(String, &str)> = vec![
            (String::new(), "holds no scene"),
            ("#".into(), "holds no scene"),
            ("garbage".into(), "holds no scene"),
            ("scene=".into(), "version ``"),
            ("scene=1".into(), "version ``"),
            (format!("scene=2.{payload}"), "version `2`"),
            (format!("scene=\u{7}9.{payload}"), "version `9`"),
            ("scene=1.!!!not*base64".into(), "not valid base64"),
            (
                format!("scene=1.{}", b64(b"hello, not deflate at all")),
                "not a compressed scene",
            ),
            ("scene=1.".into(), "not a compressed scene"),
            (
                format!("scene=1.{}", "A".repeat(MAX_ENCODED + 1)),
                "at most",
            ),
        ];
        for (f, want) in &cases {
            let e = decode(f).unwrap_err().to_string();
            assert!(e.contains(want), "{f:.40}: {e}");
        }
        // Valid deflate of something that is not a scene, not text, or not
        // a scene bv accepts.
        let pack = |b: &[u8]| {
            format!(
                "scene=1.{}",
                b64(&miniz_oxide::deflate::compress_to_vec(b, 6))
            )
        };
        let e = decode(&pack(&[0xff, 0xfe, 0x00, 0x80])).unwrap_err();
        assert!(matches!(e, LinkError::NotText), "{e}");
        let e = decode(&pack(b"this is = not [ toml")).unwrap_err();
        assert!(matches!(e, LinkError::Scene(_)), "{e}");
        let text = scene_file::to_toml(&sample()).unwrap();
        let e = decode(&pack(
            text.replace("theta_deg = 33.25", "theta_deg = 1e300")
                .as_bytes(),
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("incident.theta_deg"), "{e}");
        let e = decode(&pack(
            text.replace("cook-torrance", "no-such-model").as_bytes(),
        ))
        .unwrap_err()
        .to_string();
        assert!(e.contains("brdfs[1]"), "{e}");
        // A cut-off link: the end marker is missing or the stream is short.
        let e = decode(&good[..good.len() - 12]).unwrap_err();
        assert!(
            matches!(
                e,
                LinkError::Base64(_) | LinkError::Inflate(_) | LinkError::Scene(_)
            ),
            "{e}"
        );
    }

    #[test]
    fn a_decompression_bomb_stops_at_the_cap() {
        // 16 MiB of spaces deflate to 16 KiB: small enough to pass the
        // length check, far too big once inflated.
        let bomb = miniz_oxide::deflate::compress_to_vec(&vec![b' '; 16 << 20], 9);
        let f = format!("scene=1.{}", b64(&bomb));
        assert!(f.len() < MAX_ENCODED, "{}", f.len());
        let e = decode(&f).unwrap_err().to_string();
        assert!(e.contains("inflates past 1 MiB"), "{e}");
    }
}
