//! Scene files: the viewer's [`AppState`] as TOML, for slides,
//! papers and `bv render --scene`.
//!
//! A scene file is the same serialisable state eframe persists between runs
//! (one type, [`AppState`]), written as TOML with two header keys:
//!
//! ```toml
//! format = "bv-scene"
//! generator = "bv 0.1.0"
//! version = 1
//! …
//! [incident]
//! theta_deg = 45.0
//! …
//! [[brdfs]]
//! id = 1
//! color = [78, 151, 234]
//! visible = true
//! [brdfs.spec]
//! model = "cook-torrance"
//! [brdfs.spec.params]
//! alpha_x = 0.2
//! …
//! # end of bv scene
//! ```
//!
//! Loading is strict where the persisted session is lenient: a value of the
//! wrong type, an out-of-range angle, a BRDF whose model is unknown or whose
//! parameters do not validate (the core's one declaration checks them, through
//! `ModelSpec::from_json`) is an error naming the key and the reason; an unknown
//! key is a warning (the rest still loads). A file that bv wrote carries
//! `generator` and ends with [`END_MARKER`]; if the marker is missing the file
//! was cut short, and loading it is refused rather than silently filling the
//! lost tail with defaults. A BRDF that cannot be built (a MERL table that is
//! missing) refuses the scene on the command line and is a warning in the
//! window ([`Builds`]); a value that would be clamped into range is a
//! warning. File paths in a scene (MERL tables, the environment map, the
//! `.brdf` files of file models, alone or in a mix) are relative to the
//! scene file's folder: [`load`] resolves them there and [`save`] writes
//! paths inside that folder relative to it, so a folder of a scene and its
//! tables can move as a whole. Reading refuses anything but a
//! regular file of at most 1 MiB ([`fsio::read_capped`]). Saving writes a
//! temporary file beside the target, syncs it and renames it over the target,
//! so a crash or a full disk leaves the old scene intact; FIFOs, devices and
//! read-only files are refused, and a symlink is written through
//! ([`fsio::write_atomic`]).

use super::command::MAX_NAME_CHARS;
use super::model_names::{portable_in, resolve_in};
use super::state::{
    AppState, BrdfEntry, Camera, Display, Incident, MAX_BRDFS, STATE_VERSION, SliceSettings,
    SnellSettings,
};
use bv_core::error::quote;
use bv_core::fsio;

use serde::Deserialize;
use std::fmt::Write as _;
use std::path::{Path, PathBuf};

/// The value of the `format` key.
pub const FORMAT: &str = "bv-scene";

/// The last line of every scene bv writes; its absence in a file that names
/// bv as its `generator` means the file was truncated.
pub const END_MARKER: &str = "# end of bv scene";

/// The usual file extension (without the dot).
pub const EXTENSION: &str = "toml";

/// Why a scene could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum SceneError {
    /// The file could not be read or written (the message names the file
    /// and says why, once).
    #[error(transparent)]
    File(#[from] bv_core::BvError),
    /// The text is not valid TOML, or a value has the wrong type.
    #[error("not a valid scene file: {0}")]
    Syntax(String),
    /// A key has a value bv refuses.
    #[error("bad value for `{}`: {reason}", quote(.key))]
    BadValue {
        /// Dotted path of the key (`incident.theta_deg`, `brdfs[2].spec`).
        key: String,
        /// Why it is refused.
        reason: String,
    },
    /// The file was cut short.
    #[error(
        "the file is truncated: it names bv as its generator but does not end with the line \
         `{END_MARKER}` that bv writes last (was the save interrupted, or the file copied \
         incompletely?)"
    )]
    Truncated,
    /// The file comes from a newer bv.
    #[error(
        "scene format version {found} is newer than this bv reads (up to {STATE_VERSION}); \
         update bv"
    )]
    TooNew {
        /// The version in the file.
        found: i64,
    },
}

/// A loaded scene and what was odd about it.
#[derive(Debug, Clone, PartialEq)]
pub struct Loaded {
    /// The state (sanitised, ready for the viewer).
    pub state: AppState,
    /// Keys that were ignored and other non-fatal remarks, one line each.
    pub warnings: Vec<String>,
    /// The BRDFs that could not be built ([`Builds::Warn`]; each also has
    /// its line in `warnings`), so that a caller can act on them (a deck's
    /// stand-ins) without building them again.
    pub unbuilt: Vec<Unbuilt>,
}

/// A BRDF of a loaded scene that could not be built.
#[derive(Debug, Clone, PartialEq)]
pub struct Unbuilt {
    /// Its id.
    pub id: u64,
    /// Where it is in the file (`brdfs[2]`).
    pub key: String,
    /// Why (`the `merl` BRDF cannot be built: …`).
    pub reason: String,
}

impl Unbuilt {
    /// Its line in [`Loaded::warnings`].
    pub fn warning(&self) -> String {
        format!("`{}`: {}; it draws nothing", self.key, self.reason)
    }
}

/// The scene as TOML text (what [`save`] writes).
pub fn to_toml(state: &AppState) -> Result<String, SceneError> {
    let mut state = state.clone();
    state.version = STATE_VERSION;
    let body = toml::to_string(&state).map_err(|e| SceneError::Syntax(e.to_string()))?;
    let mut out = String::new();
    out.push_str(
        "# bv scene: BRDFs (model, parameters, colour, visibility), light, camera,\n\
         # display options and layout. Open with `bv --scene FILE`, render with\n\
         # `bv render --scene FILE --view …`, check with `bv scene check FILE`.\n",
    );
    let _ = writeln!(out, "format = \"{FORMAT}\"");
    let _ = writeln!(out, "generator = \"bv {}\"", env!("CARGO_PKG_VERSION"));
    out.push_str(&body);
    if !out.ends_with('\n') {
        out.push('\n');
    }
    out.push('\n');
    out.push_str(END_MARKER);
    out.push('\n');
    Ok(out)
}

/// The header keys, read before the state itself.
#[derive(Debug, Default, Deserialize)]
struct Header {
    format: Option<toml::Value>,
    generator: Option<toml::Value>,
    version: Option<toml::Value>,
}

/// Parses scene text (strictly; see the module docs). Relative file paths
/// in it are taken relative to the current directory; [`load`] takes them
/// relative to the scene file's folder.
pub fn from_toml(text: &str) -> Result<Loaded, SceneError> {
    from_toml_in(text, None, Builds::Required)
}

/// What loading does with a BRDF that cannot be built (a MERL table that
/// is missing or unreadable).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Builds {
    /// Refuse the scene (the command line: a figure must show what the file
    /// says, so `bv render` and `bv scene check` exit with status 1).
    Required,
    /// Load it with a warning naming the BRDF and the reason (the window:
    /// the scene opens, and that BRDF's panel shows the error until its file
    /// is found).
    Warn,
}

/// [`from_toml`] for a file in the folder `base`: relative paths (MERL
/// tables, the environment map) are resolved against `base`.
pub fn from_toml_in(text: &str, base: Option<&Path>, builds: Builds) -> Result<Loaded, SceneError> {
    match base {
        // `.brdf` model paths are read relative to the folder too (the
        // specs' serde resolves them: `model_names::with_scene_dir`).
        Some(base) => {
            super::model_names::with_scene_dir(base, || from_toml_in_dir(text, Some(base), builds))
        }
        None => from_toml_in_dir(text, None, builds),
    }
}

fn from_toml_in_dir(text: &str, base: Option<&Path>, builds: Builds) -> Result<Loaded, SceneError> {
    let text = text.trim_start_matches('\u{feff}');
    let mut warnings = Vec::new();
    let table: toml::Table =
        toml::from_str(text).map_err(|e| SceneError::Syntax(e.to_string().trim().to_string()))?;
    let header: Header = toml::Table::try_into(table.clone())
        .map_err(|e| SceneError::Syntax(e.to_string().trim().to_string()))?;

    match &header.format {
        Some(toml::Value::String(f)) if f == FORMAT => {}
        Some(other) => {
            return Err(SceneError::BadValue {
                key: "format".into(),
                reason: format!("expected \"{FORMAT}\", found {other} (not a bv scene file)"),
            });
        }
        None => warnings.push(format!(
            "no `format = \"{FORMAT}\"` line; reading the file as a bv scene anyway"
        )),
    }
    match &header.version {
        Some(toml::Value::Integer(v)) if *v > i64::from(STATE_VERSION) => {
            return Err(SceneError::TooNew { found: *v });
        }
        Some(toml::Value::Integer(v)) if *v >= 1 => {}
        Some(other) => {
            return Err(SceneError::BadValue {
                key: "version".into(),
                reason: format!("expected a format version 1..={STATE_VERSION}, found {other}"),
            });
        }
        // Required, so that a file cut short before bv's header is refused
        // rather than read as an empty scene.
        None => {
            return Err(SceneError::BadValue {
                key: "version".into(),
                reason: format!(
                    "missing: a scene file starts with `format = \"{FORMAT}\"` and \
                     `version = {STATE_VERSION}` (an empty or truncated file?)"
                ),
            });
        }
    }
    if header.generator.is_some() && !ends_with_marker(text) {
        return Err(SceneError::Truncated);
    }

    // BRDF entries one by one, so that an error names the entry (the
    // persisted session drops bad entries instead; a scene refuses them).
    if let Some(items) = table.get("brdfs") {
        let Some(items) = items.as_array() else {
            return Err(SceneError::BadValue {
                key: "brdfs".into(),
                reason: "expected an array of tables ([[brdfs]])".into(),
            });
        };
        // Before any is built: building and drawing cost per BRDF.
        if items.len() > MAX_BRDFS {
            return Err(SceneError::BadValue {
                key: "brdfs".into(),
                reason: format!(
                    "{} BRDFs; a scene holds at most {MAX_BRDFS} (a figure with more \
                     curves cannot be read; split it into several scenes)",
                    items.len()
                ),
            });
        }
        let mut ids = std::collections::HashSet::new();
        for (i, item) in items.iter().enumerate() {
            let key = format!("brdfs[{i}]");
            let json = serde_json::to_value(item).map_err(|e| SceneError::BadValue {
                key: key.clone(),
                reason: e.to_string(),
            })?;
            let mut unknown = Vec::new();
            let entry: BrdfEntry = serde_ignored::deserialize(json.clone(), |p| {
                unknown.push(p.to_string());
            })
            .map_err(|e: serde_json::Error| {
                let model = json
                    .get("spec")
                    .and_then(|s| s.get("model"))
                    .and_then(|m| m.as_str())
                    .map(|m| format!(" (model `{m}`)"))
                    .unwrap_or_default();
                SceneError::BadValue {
                    key: format!("{key}{model}"),
                    reason: e.to_string(),
                }
            })?;
            for u in unknown {
                warnings.push(format!(
                    "unknown key `{}` ignored",
                    quote(&format!("{key}.{u}"))
                ));
            }
            if !ids.insert(entry.id) {
                return Err(SceneError::BadValue {
                    key: format!("{key}.id"),
                    reason: format!("id {} is used by an earlier BRDF", entry.id),
                });
            }
        }
    }

    // The whole state, noting every key serde ignores.
    let mut ignored = Vec::new();
    let de = toml::Deserializer::parse(text)
        .map_err(|e| SceneError::Syntax(e.to_string().trim().to_string()))?;
    let mut state: AppState = serde_ignored::deserialize(de, |path| ignored.push(path.to_string()))
        .map_err(|e| SceneError::Syntax(e.to_string().trim().to_string()))?;
    for key in ignored {
        if key == "format" || key == "generator" {
            continue;
        }
        warnings.push(format!("unknown key `{}` ignored", quote(&key)));
    }

    // A name is a legend entry: one longer than the window lets a user type
    // is cut to that length, with a warning.
    for (i, b) in state.brdfs.iter_mut().enumerate() {
        if let Some(name) = &mut b.name
            && let Some((cut, _)) = name.char_indices().nth(MAX_NAME_CHARS)
        {
            warnings.push(format!(
                "`brdfs[{i}].name` has {} characters; a name has at most {MAX_NAME_CHARS}, \
                 so it is cut to \"{}\"",
                name.chars().count(),
                &name[..cut]
            ));
            name.truncate(cut);
        }
    }
    validate(&state, &mut warnings)?;
    if let Some(base) = base {
        map_paths(&mut state, &|p| resolve_in(base, p));
    }
    // Every BRDF must build: a MERL table that cannot be read would
    // otherwise vanish from the figure without a word.
    let mut unbuilt = Vec::new();
    for (i, b) in state.brdfs.iter().enumerate() {
        if let Err(e) = b.spec.build() {
            let u = Unbuilt {
                id: b.id,
                key: format!("brdfs[{i}]"),
                reason: format!("the `{}` BRDF cannot be built: {e}", b.spec.id()),
            };
            match builds {
                Builds::Required => {
                    return Err(SceneError::BadValue {
                        key: u.key,
                        reason: u.reason,
                    });
                }
                Builds::Warn => {
                    warnings.push(u.warning());
                    unbuilt.push(u);
                }
            }
        }
    }
    let clean = state.clone().sanitised();
    warnings.extend(clamp_warnings(&state, &clean));
    Ok(Loaded {
        state: clean,
        warnings,
        unbuilt,
    })
}

/// One warning per value that sanitising changed (a number out of its range
/// clamped, an angle wrapped): a scene must not be "ok" and then show
/// something else than it says.
fn clamp_warnings(raw: &AppState, clean: &AppState) -> Vec<String> {
    fn walk(key: &str, a: &serde_json::Value, b: &serde_json::Value, out: &mut Vec<String>) {
        use serde_json::Value;
        match (a, b) {
            (Value::Object(x), Value::Object(y)) => {
                for (k, va) in x {
                    if let Some(vb) = y.get(k) {
                        let sub = if key.is_empty() {
                            k.clone()
                        } else {
                            format!("{key}.{k}")
                        };
                        walk(&sub, va, vb, out);
                    }
                }
            }
            (Value::Array(x), Value::Array(y)) if x.len() == y.len() => {
                for (i, (va, vb)) in x.iter().zip(y).enumerate() {
                    walk(&format!("{key}[{i}]"), va, vb, out);
                }
            }
            _ if a != b => out.push(format!("`{key} = {a}` is out of range; using {b}")),
            _ => {}
        }
    }
    let (Ok(mut a), Ok(mut b)) = (serde_json::to_value(raw), serde_json::to_value(clean)) else {
        return Vec::new();
    };
    // Bookkeeping that sanitising fills in, not values the file chose
    // (`selected` and `solo` are reported by `validate`).
    for v in [&mut a, &mut b] {
        if let serde_json::Value::Object(m) = v {
            for k in ["version", "next_id", "selected", "solo"] {
                m.remove(k);
            }
        }
    }
    let mut out = Vec::new();
    walk("", &a, &b, &mut out);
    out
}

/// Applies `f` to every file path of the state: the path parameters of
/// every BRDF (mix components included) and the environment map.
fn map_paths(state: &mut AppState, f: &dyn Fn(&str) -> String) {
    for b in &mut state.brdfs {
        b.spec.map_paths(f);
    }
    if let Some(m) = &mut state.lighting.env.map
        && !m.trim().is_empty()
    {
        *m = f(m);
    }
}

/// The scene text [`save`] writes to `path`: file paths relative to the
/// scene's folder where they lie inside it, absolute otherwise (so that
/// [`load`] finds them whatever the current directory).
pub fn to_toml_for(path: &Path, state: &AppState) -> Result<String, SceneError> {
    let dir = match path.parent() {
        Some(d) if !d.as_os_str().is_empty() => d.to_path_buf(),
        _ => PathBuf::from("."),
    };
    let mut state = state.clone();
    map_paths(&mut state, &|p| portable_in(&dir, p));
    // File models' paths are written by the specs' serde, in the folder.
    super::model_names::with_scene_dir(&dir, || to_toml(&state))
}

fn ends_with_marker(text: &str) -> bool {
    text.lines()
        .rev()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .is_some_and(|l| l == END_MARKER)
}

/// Range checks the persisted session would silently clamp, but a scene file
/// refuses: a figure must show what the file says.
fn validate(s: &AppState, warnings: &mut Vec<String>) -> Result<(), SceneError> {
    let bad = |key: &str, reason: String| {
        Err(SceneError::BadValue {
            key: key.to_string(),
            reason,
        })
    };
    let range = |key: &str, x: f64, lo: f64, hi: f64, unit: &str| {
        if x.is_finite() && (lo..=hi).contains(&x) {
            Ok(())
        } else {
            bad(
                key,
                format!(
                    "{} is outside {lo}..={hi}{unit}",
                    bv_core::error::fmt_num(x)
                ),
            )
        }
    };
    range(
        "incident.theta_deg",
        s.incident.theta_deg,
        0.0,
        Incident::MAX_THETA_DEG,
        "°",
    )?;
    if Incident::in_horizon_gap(s.incident.theta_deg) {
        return bad(
            "incident.theta_deg",
            Incident::horizon_reason(s.incident.theta_deg),
        );
    }
    range("incident.phi_deg", s.incident.phi_deg, -360.0, 360.0, "°")?;
    range("display.turn_deg", s.display.turn_deg, -360.0, 360.0, "°")?;
    range(
        "display.factor_terms",
        f64::from(s.display.factor_terms),
        1.0,
        f64::from(Display::MAX_FACTOR_TERMS),
        " terms",
    )?;
    let c = s.camera;
    if !c.yaw_deg.is_finite() {
        return bad(
            "camera.yaw_deg",
            format!(
                "{} is not a finite angle",
                bv_core::error::fmt_num(f64::from(c.yaw_deg))
            ),
        );
    }
    range(
        "camera.pitch_deg",
        f64::from(c.pitch_deg),
        f64::from(Camera::PITCH_RANGE.0),
        f64::from(Camera::PITCH_RANGE.1),
        "°",
    )?;
    range(
        "camera.distance",
        f64::from(c.distance),
        f64::from(Camera::DISTANCE_RANGE.0),
        f64::from(Camera::DISTANCE_RANGE.1),
        "",
    )?;
    if !(c.fixed_scale.is_finite() && c.fixed_scale > 0.0) {
        return bad(
            "camera.fixed_scale",
            format!(
                "{} is not a positive number",
                bv_core::error::fmt_num(f64::from(c.fixed_scale))
            ),
        );
    }
    range(
        "plots.fixed_theta_d_deg",
        s.plots.fixed_theta_d_deg,
        0.0,
        89.5,
        "°",
    )?;
    range(
        "plots.snell.eta",
        s.plots.snell.eta,
        SnellSettings::ETA_RANGE.0,
        SnellSettings::ETA_RANGE.1,
        "",
    )?;
    range(
        "plots.fixed_theta_h_deg",
        s.plots.fixed_theta_h_deg,
        0.0,
        89.5,
        "°",
    )?;
    let slice = &s.plots.slice;
    for (key, v, (lo, hi), unit) in [
        (
            "plots.slice.phi_d_deg",
            slice.phi_d_deg,
            SliceSettings::PHI_D_RANGE,
            "°",
        ),
        (
            "plots.slice.exposure_ev",
            slice.exposure_ev,
            SliceSettings::EV_RANGE,
            " EV",
        ),
        (
            "plots.slice.gamma",
            slice.gamma,
            SliceSettings::GAMMA_RANGE,
            "",
        ),
        (
            "plots.slice.residual_range",
            slice.residual_range,
            SliceSettings::RESIDUAL_RANGE,
            "",
        ),
    ] {
        range(key, v, lo, hi, unit)?;
    }
    if let Some(v) = &s.maximised
        && super::views::info(v).is_none()
    {
        warnings.push(format!(
            "`maximised = \"{}\"`: no such view in this bv (views: {}); showing all views",
            quote(v),
            super::views::id_list()
        ));
    }
    for (key, id) in [("selected", s.selected), ("solo", s.solo)] {
        if let Some(id) = id
            && s.entry(id).is_none()
        {
            warnings.push(format!("`{key} = {id}`: no BRDF has that id; ignored"));
        }
    }
    Ok(())
}

/// Reads a scene file: a regular file of at most
/// [`fsio::MAX_SCENE_BYTES`] (a FIFO or device is refused, never waited
/// on); relative paths in it are relative to its folder. A BRDF that cannot
/// be built refuses the scene ([`Builds::Required`]).
pub fn load(path: &Path) -> Result<Loaded, SceneError> {
    load_with(path, Builds::Required)
}

/// [`load`] with the given treatment of BRDFs that cannot be built (the
/// window opens such a scene with a warning: [`Builds::Warn`]).
pub fn load_with(path: &Path, builds: Builds) -> Result<Loaded, SceneError> {
    let bytes = fsio::read_capped(path, fsio::MAX_SCENE_BYTES, "a scene file")?;
    let text = utf8_text(bytes).map_err(SceneError::Syntax)?;
    from_toml_in(&text, path.parent(), builds)
}

/// The bytes of a text file (scene, deck) as a string, or why not.
pub fn utf8_text(bytes: Vec<u8>) -> Result<String, String> {
    String::from_utf8(bytes).map_err(|e| {
        format!(
            "the file is not UTF-8 text (invalid byte at offset {})",
            e.utf8_error().valid_up_to()
        )
    })
}

/// Writes a scene file atomically (see [`write_atomic`]), with its file
/// paths as [`to_toml_for`] writes them. In a browser page the file becomes
/// a download named by `path`'s file name.
pub fn save(path: &Path, state: &AppState) -> Result<(), SceneError> {
    let text = to_toml_for(path, state)?;
    #[cfg(target_arch = "wasm32")]
    {
        let name = path
            .file_name()
            .map_or_else(|| "scene.toml".into(), |n| n.to_string_lossy().into_owned());
        super::platform::download(&name, text.as_bytes()).map_err(|reason| {
            SceneError::File(bv_core::BvError::File {
                path: name.clone(),
                reason: format!("the browser refused the download: {reason}"),
            })
        })
    }
    #[cfg(not(target_arch = "wasm32"))]
    write_atomic(path, |f| f.write_all(text.as_bytes()))
}

/// Writes `path` through a temporary file in the same directory, synced and
/// then renamed over `path` (rename is atomic within a file system), so that
/// readers see either the old file or the whole new one. If `write` fails,
/// the temporary file is removed and `path` is untouched. FIFOs, devices,
/// directories and read-only files are refused, a symlink is written
/// through to its target, and an existing file keeps its permissions
/// ([`fsio::write_atomic`]).
pub fn write_atomic(
    path: &Path,
    write: impl FnOnce(&mut dyn std::io::Write) -> std::io::Result<()>,
) -> Result<(), SceneError> {
    Ok(fsio::write_atomic(path, write)?)
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::ModelSpec;

    fn sample() -> AppState {
        let mut s = AppState::default();
        s.add(
            ModelSpec::from_json("lambert", &serde_json::json!({"albedo": [0.2, 0.4, 0.6]}))
                .unwrap(),
        );
        s.add(ModelSpec::new("cook-torrance").unwrap());
        s.brdfs[0].visible = false;
        s.incident = Incident {
            theta_deg: 33.25,
            phi_deg: -20.0,
        };
        s.camera.yaw_deg = 12.5;
        s.display.log = true;
        s.display.turn_deg = 37.5;
        s.maximised = Some("polar".into());
        s.sanitised()
    }

    #[test]
    fn round_trip_is_exact() {
        let s = sample();
        let text = to_toml(&s).unwrap();
        let back = from_toml(&text).unwrap();
        assert_eq!(back.warnings, Vec::<String>::new());
        assert_eq!(back.state, s);
    }

    #[test]
    fn unknown_keys_warn_and_the_rest_loads() {
        let text = to_toml(&sample())
            .unwrap()
            .replace("[incident]", "[incident]\nshininess = 3");
        let back = from_toml(&text).unwrap();
        assert_eq!(back.warnings.len(), 1, "{:?}", back.warnings);
        assert!(back.warnings[0].contains("incident.shininess"));
        assert_eq!(back.state, sample());
    }

    #[test]
    fn file_paths_are_relative_to_the_scene_file() {
        use bv_core::measured::merl::{MerlDims, MerlTable};
        let dir = std::env::temp_dir().join(format!("bv-scene-paths-{}", std::process::id()));
        let sub = dir.join("scenes");
        std::fs::create_dir_all(&sub).unwrap();
        let dims = MerlDims::new(1, 1, 2).unwrap();
        let table = MerlTable::from_values(dims, vec![0.1; 6]).unwrap();
        table.write(sub.join("t.binary")).unwrap();
        table.write(dir.join("outside.binary")).unwrap();
        let merl = |p: &Path| {
            ModelSpec::from_json(
                "merl",
                &serde_json::json!({"path": p.display().to_string()}),
            )
            .unwrap()
        };
        let mut s = AppState::default();
        // Paths as the window holds them: usable from the current directory.
        s.add(merl(&sub.join("t.binary")));
        s.add(merl(&dir.join("outside.binary")));
        s.lighting.env.map = Some(sub.join("env.hdr").display().to_string());
        let file = sub.join("s.toml");
        save(&file, &s).unwrap();
        let text = std::fs::read_to_string(&file).unwrap();
        // Inside the scene's folder: relative; outside: absolute.
        assert!(text.contains("path = \"t.binary\""), "{text}");
        assert!(text.contains("map = \"env.hdr\""), "{text}");
        let abs = std::path::absolute(dir.join("outside.binary")).unwrap();
        assert!(text.contains(&abs.display().to_string()), "{text}");
        // Loading resolves them against the folder again, wherever bv runs.
        let back = load(&file).unwrap();
        let p = back.state.brdfs[0].spec.params().text("path").unwrap();
        assert_eq!(Path::new(&p), sub.join("t.binary"));
        // A table that is not there refuses the scene, or warns in the window.
        std::fs::remove_file(sub.join("t.binary")).unwrap();
        let e = load(&file).unwrap_err().to_string();
        assert!(e.contains("brdfs[0]") && e.contains("t.binary"), "{e}");
        let lenient = load_with(&file, Builds::Warn).unwrap();
        assert_eq!(lenient.state.brdfs.len(), 2);
        assert!(lenient.warnings.iter().any(|w| w.contains("brdfs[0]")));
        std::fs::remove_dir_all(&dir).unwrap();
    }

    #[test]
    fn bad_values_name_the_key() {
        let text = to_toml(&sample()).unwrap();
        let e = from_toml(&text.replace("theta_deg = 33.25", "theta_deg = 190.0")).unwrap_err();
        assert!(e.to_string().contains("incident.theta_deg"), "{e}");
        // The horizon is refused with the reason; a light below loads (issue 33).
        let e = from_toml(&text.replace("theta_deg = 33.25", "theta_deg = 90.0")).unwrap_err();
        let m = e.to_string();
        assert!(
            m.contains("incident.theta_deg") && m.contains("horizon"),
            "{m}"
        );
        let below = from_toml(&text.replace("theta_deg = 33.25", "theta_deg = 120.0")).unwrap();
        assert_eq!(below.state.incident.theta_deg, 120.0);
        let e = from_toml(&text.replace("turn_deg = 37.5", "turn_deg = 1e9")).unwrap_err();
        assert!(e.to_string().contains("display.turn_deg"), "{e}");
        let e = from_toml(&text.replace("factor_terms = 2", "factor_terms = 0")).unwrap_err();
        assert!(e.to_string().contains("display.factor_terms"), "{e}");
        let e = from_toml(&text.replace("factor_terms = 2", "factor_terms = 9")).unwrap_err();
        assert!(e.to_string().contains("display.factor_terms"), "{e}");
        let e = from_toml(&text.replace("albedo = [", "albedo = [7.0, ")).unwrap_err();
        let m = e.to_string();
        assert!(m.contains("brdfs[0]") && m.contains("albedo"), "{m}");
    }
}
