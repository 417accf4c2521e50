//! Lecture decks: a TOML file listing scenes to step through in presentation
//! mode (`bv --deck FILE`) or to render as numbered slides
//! (`bv render --deck FILE --out DIR/`).
//!
//! ```toml
//! format = "bv-deck"
//! version = 1
//! title = "Reflectance functions"        # optional
//!
//! [[scene]]
//! title = "Lambert: ideal diffuse"       # the slide's title, one line
//! caption = "f = ρ/π in every direction" # one line under it
//! view = "polar"                         # the view shown (maximised)
//! seed = "Ideal Diffuse Reflection"      # optional: the lecture slide(s) it
//!                                        # shows, a heading or a list of them
//! file = "scenes/lambert.toml"           # a scene file, relative to the deck
//!
//! [[scene]]
//! title = "Phong"
//! caption = "…"
//! view = "lobe"
//! [scene.state]                          # or the scene inline: the keys of a
//! incident = { theta_deg = 45.0, phi_deg = 0.0 }   # scene file
//! [[scene.state.brdfs]]
//! id = 1
//! color = [78, 151, 234]
//! visible = true
//! spec = { model = "phong", params = { exponent = 20.0 } }
//! ```
//!
//! Each entry's scene is a scene file's state ([`super::scene_file`]) read
//! by the scene file's own parser, so its keys, ranges and models are
//! checked the same way (an inline table needs neither `format` nor
//! `version`: the deck's header covers them); relative paths in an inline
//! scene are relative to the deck's folder, in a `file` scene to that file's.
//! The deck's own keys are strict: an unknown key, a missing title, a caption
//! of several lines, an unknown view, or an entry with both or neither of
//! `file` and `state` is an error naming the entry (`scene[3] ("Phong")`) and
//! the key. A deck bv wrote ends with [`END_MARKER`] and is refused without it
//! (a truncated save). Saving ([`save`]) writes the deck atomically and, for
//! `file` entries whose scene changed, the scene file too.

use super::scene_file::{self as scene, Builds, SceneError};
use super::state::AppState;
use bv_core::error::quote;
use bv_core::fsio;
use serde::Serialize;
use std::path::{Path, PathBuf};

/// The value of the `format` key.
pub const FORMAT: &str = "bv-deck";

/// The deck format's version.
pub const VERSION: i64 = 1;

/// The last line of every deck bv writes.
pub const END_MARKER: &str = "# end of bv deck";

/// Largest deck file read: a deck of inline scenes is a few kB per scene.
pub const MAX_DECK_BYTES: u64 = 4 * fsio::MAX_SCENE_BYTES;

/// Most scenes in a deck: a long lecture has a few dozen. Every scene's
/// BRDFs are built when the deck loads, so the count bounds the work.
pub const MAX_SLIDES: usize = 200;

/// Longest title or caption, in characters: a few lines' worth on a
/// 1920-pixel slide. Laying text out costs hundreds of bytes per character
/// (a 3 MB caption took 1.3 GB), and a slide's file name is made from its
/// title.
pub const MAX_TEXT_CHARS: usize = 1000;

/// Why a deck could not be read or written.
#[derive(Debug, thiserror::Error)]
pub enum DeckError {
    /// The file could not be read or written.
    #[error(transparent)]
    File(#[from] bv_core::BvError),
    /// The text is not valid TOML.
    #[error("not a valid deck file: {0}")]
    Syntax(String),
    /// A key of the deck's header has a value bv refuses.
    #[error("bad value for `{}`: {reason}", quote(.key))]
    Header {
        /// The key (`format`, `version`, `title`, `scene`).
        key: String,
        /// Why it is refused.
        reason: String,
    },
    /// A key of one entry (or of its scene) has a value bv refuses.
    #[error(
        "scene[{entry}]{}: bad value for `{}`: {reason}",
        titled(.title),
        quote(.key)
    )]
    Entry {
        /// The entry's index (0-based, as `scene[i]` in TOML tools).
        entry: usize,
        /// Its title, when it has one.
        title: Option<String>,
        /// The key: `title`, `view`, `file`, `state.incident.theta_deg` …
        key: String,
        /// Why it is refused.
        reason: String,
    },
    /// A scene file of the deck could not be written.
    #[error("scene[{entry}]: saving {}: {source}", .path.display())]
    SaveScene {
        /// The entry's index.
        entry: usize,
        /// The scene file.
        path: PathBuf,
        /// Why.
        source: SceneError,
    },
    /// The file was cut short.
    #[error(
        "the file is truncated: it names bv as its generator but does not end with the line \
         `{END_MARKER}` that bv writes last"
    )]
    Truncated,
}

fn titled(title: &Option<String>) -> String {
    title
        .as_deref()
        .map(|t| format!(" (\"{}\")", quote(t)))
        .unwrap_or_default()
}

/// Where an entry's scene is kept.
#[derive(Debug, Clone, PartialEq)]
pub enum Source {
    /// In the deck (`[scene.state]`).
    Inline,
    /// In a scene file, as the deck names it (relative to the deck's folder
    /// unless absolute), and the state last read from or written to it.
    File {
        /// The path as written in the deck.
        path: String,
        /// What the file holds (saving rewrites it only when the scene
        /// differs).
        on_disk: Box<AppState>,
    },
}

/// One slide: a scene with its title, caption and view.
#[derive(Debug, Clone, PartialEq)]
pub struct Slide {
    /// The title (one line, drawn large above the view).
    pub title: String,
    /// One line under the title.
    pub caption: String,
    /// The headings of the lecture's slides this scene shows (the deck's
    /// `seed` key: one heading or a list), so that a deck's coverage of its
    /// lecture can be checked; empty when the deck does not say.
    pub seed: Vec<String>,
    /// The id of the view shown (see `session::views`).
    pub view: String,
    /// The scene; its `maximised` is [`Slide::view`].
    pub state: AppState,
    /// Where the scene is kept.
    pub source: Source,
    /// The entry's stand-ins (`[[scene.stand_in]]`) and what they replaced,
    /// so that saving writes the entry back as it was read.
    pub stand_ins: Option<StandIns>,
}

/// A deck entry's stand-ins as written and what they replaced.
#[derive(Debug, Clone, PartialEq)]
pub struct StandIns {
    /// The `[[scene.stand_in]]` array as read.
    pub raw: toml::Value,
    /// The caption as written (without the notes of the stand-ins used).
    pub caption: String,
    /// The caption as shown (with them).
    pub shown: String,
    /// Each BRDF replaced: its id, its spec and name as written, and the
    /// stand-in's spec drawn instead.
    pub replaced: Vec<(u64, bv_core::ModelSpec, Option<String>, bv_core::ModelSpec)>,
}

impl Slide {
    /// The scene as the deck keeps it: the BRDFs a stand-in replaces as
    /// written (unless they were edited since), so that saving loses no
    /// measured file.
    pub fn state_to_save(&self) -> AppState {
        let mut state = self.state.clone();
        if let Some(si) = &self.stand_ins {
            for (id, spec, name, stand) in &si.replaced {
                if let Some(b) = state.brdfs.iter_mut().find(|b| b.id == *id)
                    && b.spec == *stand
                {
                    b.spec = spec.clone();
                    b.name = name.clone();
                }
            }
        }
        state
    }

    /// The caption as the deck keeps it (without stand-ins' notes, unless
    /// it was edited since).
    pub fn caption_to_save(&self) -> &str {
        match &self.stand_ins {
            Some(si) if self.caption == si.shown => &si.caption,
            _ => &self.caption,
        }
    }

    /// A slide whose scene is kept in the deck; `view` must be a view id or
    /// alias.
    pub fn inline(title: &str, caption: &str, view: &str, mut state: AppState) -> Option<Self> {
        let view = super::views::find(view)?.id.to_string();
        state.maximised = Some(view.clone());
        Some(Self {
            title: title.to_string(),
            caption: caption.to_string(),
            seed: Vec::new(),
            view,
            state: state.sanitised(),
            source: Source::Inline,
            stand_ins: None,
        })
    }
}

/// A lecture deck.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Deck {
    /// The lecture's title, if it has one.
    pub title: Option<String>,
    /// The slides, in order (never empty in a loaded deck).
    pub slides: Vec<Slide>,
}

/// A loaded deck and what was odd about it.
#[derive(Debug, Clone, PartialEq)]
pub struct Loaded {
    /// The deck.
    pub deck: Deck,
    /// Non-fatal remarks (unknown keys inside a scene, clamped values), one
    /// line each, naming the entry.
    pub warnings: Vec<String>,
}

/// Reads a deck file (a regular file of at most [`MAX_DECK_BYTES`]); its
/// `file` entries are read relative to its folder.
pub fn load(path: &Path, builds: Builds) -> Result<Loaded, DeckError> {
    let bytes = fsio::read_capped(path, MAX_DECK_BYTES, "a deck file")?;
    let text = super::scene_file::utf8_text(bytes).map_err(DeckError::Syntax)?;
    from_toml_in(&text, path.parent(), builds)
}

const HEADER_KEYS: &[&str] = &["format", "generator", "version", "title", "scene"];
const ENTRY_KEYS: &[&str] = &[
    "title", "caption", "view", "seed", "file", "state", "stand_in",
];

/// Most headings one scene's `seed` names.
pub const MAX_SEED_HEADINGS: usize = 16;

/// Parses deck text; `file` entries and relative paths of inline scenes are
/// taken relative to `base` (the current directory when `None`).
pub fn from_toml_in(text: &str, base: Option<&Path>, builds: Builds) -> Result<Loaded, DeckError> {
    let text = text.trim_start_matches('\u{feff}');
    let table: toml::Table =
        toml::from_str(text).map_err(|e| DeckError::Syntax(e.to_string().trim().to_string()))?;
    let header = |key: &str, reason: String| DeckError::Header {
        key: key.to_string(),
        reason,
    };
    for key in table.keys() {
        if !HEADER_KEYS.contains(&key.as_str()) {
            return Err(header(
                key,
                format!("unknown key (a deck has {})", HEADER_KEYS.join(", ")),
            ));
        }
    }
    match table.get("format") {
        Some(toml::Value::String(f)) if f == FORMAT => {}
        Some(other) => {
            return Err(header(
                "format",
                format!("expected \"{FORMAT}\", found {other} (not a bv deck)"),
            ));
        }
        None => {
            return Err(header(
                "format",
                format!("missing: a deck starts with `format = \"{FORMAT}\"`"),
            ));
        }
    }
    match table.get("version") {
        Some(toml::Value::Integer(v)) if *v == VERSION => {}
        Some(toml::Value::Integer(v)) if *v > VERSION => {
            return Err(header(
                "version",
                format!("deck format version {v} is newer than this bv reads ({VERSION})"),
            ));
        }
        Some(other) => {
            return Err(header(
                "version",
                format!("expected {VERSION}, found {other}"),
            ));
        }
        None => {
            return Err(header(
                "version",
                format!("missing (`version = {VERSION}`)"),
            ));
        }
    }
    if table.contains_key("generator") && !ends_with_marker(text) {
        return Err(DeckError::Truncated);
    }
    let title = match table.get("title") {
        None => None,
        Some(v) => Some(one_line(v).map_err(|r| header("title", r))?),
    };
    let Some(items) = table.get("scene") else {
        return Err(header(
            "scene",
            "missing: a deck lists its slides as [[scene]] tables".into(),
        ));
    };
    let Some(items) = items.as_array().filter(|a| !a.is_empty()) else {
        return Err(header(
            "scene",
            "expected a non-empty array of tables ([[scene]])".into(),
        ));
    };
    if items.len() > MAX_SLIDES {
        return Err(header(
            "scene",
            format!(
                "{} scenes; a deck holds at most {MAX_SLIDES} (split the lecture into \
                 several decks)",
                items.len()
            ),
        ));
    }
    let mut deck = Deck {
        title,
        slides: Vec::with_capacity(items.len()),
    };
    let mut warnings = Vec::new();
    for (i, item) in items.iter().enumerate() {
        deck.slides
            .push(entry(i, item, base, builds, &mut warnings)?);
    }
    Ok(Loaded { deck, warnings })
}

/// One `[[scene]]` entry.
fn entry(
    i: usize,
    item: &toml::Value,
    base: Option<&Path>,
    builds: Builds,
    warnings: &mut Vec<String>,
) -> Result<Slide, DeckError> {
    let title = item
        .get("title")
        .and_then(toml::Value::as_str)
        .map(str::to_string);
    let bad = |key: &str, reason: String| DeckError::Entry {
        entry: i,
        title: title.clone(),
        key: key.to_string(),
        reason,
    };
    let Some(t) = item.as_table() else {
        return Err(bad("scene", "expected a table ([[scene]])".into()));
    };
    for key in t.keys() {
        if !ENTRY_KEYS.contains(&key.as_str()) {
            return Err(bad(
                key,
                format!("unknown key (an entry has {})", ENTRY_KEYS.join(", ")),
            ));
        }
    }
    let text_key = |key: &str| -> Result<String, DeckError> {
        match t.get(key) {
            Some(v) => one_line(v).map_err(|r| bad(key, r)),
            None => Err(bad(key, "missing".into())),
        }
    };
    let title_text = text_key("title")?;
    if title_text.trim().is_empty() {
        return Err(bad("title", "empty: every slide has a title".into()));
    }
    let caption = text_key("caption")?;
    let seed = match t.get("seed") {
        None => Vec::new(),
        Some(v) => seed_headings(v).map_err(|r| bad("seed", r))?,
    };
    let view_name = text_key("view")?;
    let Some(view) = super::views::find(&view_name) else {
        return Err(bad(
            "view",
            format!(
                "no view `{}` in this bv (views: {})",
                quote(&view_name),
                super::views::id_list()
            ),
        ));
    };
    let prefix = format!("scene[{i}] (\"{}\")", quote(&title_text));
    let stand_ins = match t.get("stand_in") {
        None => Vec::new(),
        Some(v) => stand_ins(v).map_err(|r| bad("stand_in", r))?,
    };
    // With stand-ins a BRDF that cannot be built (its file is missing) is
    // replaced below rather than refusing the scene.
    let required = builds == Builds::Required;
    let builds = if stand_ins.is_empty() {
        builds
    } else {
        Builds::Warn
    };
    let (loaded, source) = match (t.get("file"), t.get("state")) {
        (Some(_), Some(_)) => {
            return Err(bad(
                "file",
                "an entry has either `file` or a `[scene.state]` table, not both".into(),
            ));
        }
        (None, None) => {
            return Err(bad(
                "state",
                "missing: give the scene as `file = \"scene.toml\"` or as a \
                 `[scene.state]` table"
                    .into(),
            ));
        }
        (Some(f), None) => {
            let Some(rel) = f.as_str().filter(|s| !s.trim().is_empty()) else {
                return Err(bad(
                    "file",
                    format!("expected a path, found {}", quote(&f.to_string())),
                ));
            };
            let path = resolve(base, rel);
            let loaded = scene::load_with(&path, builds).map_err(|e| match e {
                // The file's own errors name the path already.
                SceneError::File(_) => bad("file", e.to_string()),
                other => bad("file", format!("{}: {other}", path.display())),
            })?;
            (
                loaded,
                Source::File {
                    path: rel.to_string(),
                    on_disk: Box::default(),
                },
            )
        }
        (None, Some(s)) => {
            let Some(s) = s.as_table() else {
                return Err(bad("state", "expected a table ([scene.state])".into()));
            };
            let mut s = s.clone();
            s.entry("format")
                .or_insert_with(|| toml::Value::String(scene::FORMAT.into()));
            s.entry("version")
                .or_insert_with(|| toml::Value::Integer(i64::from(super::state::STATE_VERSION)));
            let text = toml::to_string(&s).map_err(|e| bad("state", e.to_string()))?;
            let loaded = scene::from_toml_in(&text, base, builds).map_err(|e| match e {
                SceneError::BadValue { key, reason } => bad(&format!("state.{key}"), reason),
                other => bad("state", other.to_string()),
            })?;
            (loaded, Source::Inline)
        }
    };
    let mut state = loaded.state;
    let written_caption = caption.clone();
    let mut caption = caption;
    // The BRDFs the scene could not build and a stand-in replaces: the
    // BRDF itself when it builds (its file is there); else the stand-in,
    // named as such, and the slide says why.
    let mut replaced: Vec<&scene::Unbuilt> = Vec::new();
    let mut record = Vec::new();
    for si in &stand_ins {
        let Some(k) = state.brdfs.iter().position(|b| b.id == si.id) else {
            return Err(bad(
                "stand_in",
                format!("no BRDF with id {} in the scene", si.id),
            ));
        };
        let Some(u) = loaded.unbuilt.iter().find(|u| u.id == si.id) else {
            continue;
        };
        record.push((
            si.id,
            state.brdfs[k].spec.clone(),
            state.brdfs[k].name.clone(),
            si.spec.clone(),
        ));
        state.brdfs[k].spec = si.spec.clone();
        state.brdfs[k].name = Some(si.name.clone());
        replaced.push(u);
        caption = format!("{caption} [{}]", si.note);
    }
    if caption.chars().nth(MAX_TEXT_CHARS).is_some() {
        return Err(bad(
            "stand_in",
            format!(
                "the caption with the stand-in's note has {} characters; at most {MAX_TEXT_CHARS}",
                caption.chars().count()
            ),
        ));
    }
    // Any other BRDF that could not be built refuses the scene, as
    // `builds` asked (loading ran leniently only for the stand-ins).
    if required
        && let Some(u) = loaded
            .unbuilt
            .iter()
            .find(|u| !replaced.iter().any(|r| r.id == u.id))
    {
        return Err(bad(&format!("state.{}", u.key), u.reason.clone()));
    }
    // The warning about a BRDF a stand-in replaced is the caption's note.
    let dropped: Vec<String> = replaced.iter().map(|u| u.warning()).collect();
    for w in loaded.warnings {
        if !dropped.contains(&w) {
            warnings.push(format!("{prefix}: {w}"));
        }
    }
    state.maximised = Some(view.id.to_string());
    let mut source = source;
    if let Source::File { on_disk, .. } = &mut source {
        **on_disk = state.clone();
    }
    let stand_ins = t.get("stand_in").map(|raw| StandIns {
        raw: raw.clone(),
        caption: written_caption,
        shown: caption.clone(),
        replaced: record,
    });
    Ok(Slide {
        title: title_text,
        caption,
        seed,
        view: view.id.to_string(),
        state,
        source,
        stand_ins,
    })
}

/// A BRDF of a scene drawn instead when it cannot be built (LECTURE.md N7:
/// a measured file the lecturer supplies, absent): the entry's
/// `[[scene.stand_in]]` with the BRDF's `id`, the stand-in's `name` (its
/// legend entry: say what it is), its `spec`, and the `note` appended to the
/// caption when it is used.
#[derive(Debug, Clone, PartialEq)]
struct StandIn {
    id: u64,
    name: String,
    spec: bv_core::ModelSpec,
    note: String,
}

fn stand_ins(v: &toml::Value) -> Result<Vec<StandIn>, String> {
    let Some(items) = v.as_array() else {
        return Err("expected an array of tables ([[scene.stand_in]])".into());
    };
    items
        .iter()
        .enumerate()
        .map(|(k, item)| {
            let at = |r: String| format!("[{k}]: {r}");
            let t = item
                .as_table()
                .ok_or_else(|| at("expected a table".into()))?;
            for key in t.keys() {
                if !["id", "name", "spec", "note"].contains(&key.as_str()) {
                    return Err(at(format!(
                        "unknown key `{}` (id, name, spec, note)",
                        quote(key)
                    )));
                }
            }
            let id = t
                .get("id")
                .and_then(toml::Value::as_integer)
                .and_then(|i| u64::try_from(i).ok())
                .ok_or_else(|| at("`id`: expected the BRDF's id".into()))?;
            let text = |key: &str| match t.get(key) {
                Some(v) => one_line(v).map_err(|r| at(format!("`{key}`: {r}"))),
                None => Err(at(format!("`{key}`: missing"))),
            };
            let (name, note) = (text("name")?, text("note")?);
            let spec_v = t.get("spec").ok_or_else(|| at("`spec`: missing".into()))?;
            let json = serde_json::to_value(spec_v).map_err(|e| at(e.to_string()))?;
            let model = json
                .get("model")
                .and_then(|m| m.as_str())
                .ok_or_else(|| at("`spec.model`: missing".into()))?;
            let params = json
                .get("params")
                .cloned()
                .unwrap_or_else(|| serde_json::json!({}));
            let spec = bv_core::ModelSpec::from_json(model, &params)
                .map_err(|e| at(format!("`spec`: {e}")))?;
            spec.build()
                .map_err(|e| at(format!("the stand-in cannot be built: {e}")))?;
            Ok(StandIn {
                id,
                name,
                spec,
                note,
            })
        })
        .collect()
}

/// A title or caption: one line of at most [`MAX_TEXT_CHARS`] characters.
fn one_line(v: &toml::Value) -> Result<String, String> {
    match v.as_str() {
        Some(s) if s.contains(['\n', '\r']) => Err("expected one line of text".into()),
        Some(s) if s.chars().nth(MAX_TEXT_CHARS).is_some() => Err(format!(
            "{} characters; at most {MAX_TEXT_CHARS} (a title or caption is a line on a slide)",
            s.chars().count()
        )),
        Some(s) => Ok(s.to_string()),
        None => Err(format!(
            "expected a string, found {}",
            quote(&v.to_string())
        )),
    }
}

/// A `seed` value: one heading, or a non-empty list of at most
/// [`MAX_SEED_HEADINGS`] distinct headings, each one non-empty line.
fn seed_headings(v: &toml::Value) -> Result<Vec<String>, String> {
    let items: Vec<&toml::Value> = match v {
        toml::Value::Array(a) if a.is_empty() => {
            return Err("an empty list (leave `seed` out, or name a heading)".into());
        }
        toml::Value::Array(a) if a.len() > MAX_SEED_HEADINGS => {
            return Err(format!(
                "{} headings; a scene names at most {MAX_SEED_HEADINGS}",
                a.len()
            ));
        }
        toml::Value::Array(a) => a.iter().collect(),
        other => vec![other],
    };
    let mut out: Vec<String> = Vec::with_capacity(items.len());
    for item in items {
        let h = one_line(item)?.trim().to_string();
        if h.is_empty() {
            return Err("an empty heading".into());
        }
        if out.contains(&h) {
            return Err(format!("\"{}\" twice", quote(&h)));
        }
        out.push(h);
    }
    Ok(out)
}

fn resolve(base: Option<&Path>, rel: &str) -> PathBuf {
    let p = Path::new(rel);
    match base {
        Some(b) if !p.is_absolute() && !b.as_os_str().is_empty() => b.join(p),
        _ => p.to_path_buf(),
    }
}

fn ends_with_marker(text: &str) -> bool {
    text.lines()
        .rev()
        .map(str::trim)
        .find(|l| !l.is_empty())
        .is_some_and(|l| l == END_MARKER)
}

#[derive(Serialize)]
struct DeckOut<'a> {
    format: &'a str,
    generator: String,
    version: i64,
    #[serde(skip_serializing_if = "Option::is_none")]
    title: Option<&'a str>,
    scene: Vec<EntryOut<'a>>,
}

#[derive(Serialize)]
struct EntryOut<'a> {
    title: &'a str,
    caption: &'a str,
    view: &'a str,
    #[serde(skip_serializing_if = "Option::is_none")]
    seed: Option<toml::Value>,
    #[serde(skip_serializing_if = "Option::is_none")]
    file: Option<&'a str>,
    #[serde(skip_serializing_if = "Option::is_none")]
    state: Option<toml::Table>,
    #[serde(skip_serializing_if = "Option::is_none")]
    stand_in: Option<&'a toml::Value>,
}

/// The deck as TOML text for a file at `path` (what [`save`] writes): inline
/// scenes as scene files write them, with their paths relative to the deck's
/// folder.
pub fn to_toml_for(path: &Path, deck: &Deck) -> Result<String, DeckError> {
    let mut entries = Vec::with_capacity(deck.slides.len());
    for (i, s) in deck.slides.iter().enumerate() {
        let state = match &s.source {
            Source::File { .. } => None,
            Source::Inline => {
                let text =
                    scene::to_toml_for(path, &s.state_to_save()).map_err(|e| DeckError::Entry {
                        entry: i,
                        title: Some(s.title.clone()),
                        key: "state".into(),
                        reason: e.to_string(),
                    })?;
                let mut t: toml::Table = toml::from_str(&text)
                    .map_err(|e| DeckError::Syntax(e.to_string().trim().to_string()))?;
                // The deck's header says what these say.
                for k in ["format", "generator", "version", "maximised"] {
                    t.remove(k);
                }
                Some(t)
            }
        };
        entries.push(EntryOut {
            title: &s.title,
            caption: s.caption_to_save(),
            view: &s.view,
            seed: match s.seed.as_slice() {
                [] => None,
                [one] => Some(toml::Value::String(one.clone())),
                many => Some(toml::Value::Array(
                    many.iter().cloned().map(toml::Value::String).collect(),
                )),
            },
            file: match &s.source {
                Source::File { path, .. } => Some(path),
                Source::Inline => None,
            },
            state,
            stand_in: s.stand_ins.as_ref().map(|si| &si.raw),
        });
    }
    let out = DeckOut {
        format: FORMAT,
        generator: format!("bv {}", env!("CARGO_PKG_VERSION")),
        version: VERSION,
        title: deck.title.as_deref(),
        scene: entries,
    };
    let body = toml::to_string(&out).map_err(|e| DeckError::Syntax(e.to_string()))?;
    let mut text = String::from(
        "# bv lecture deck: the slides of `bv --deck FILE` (presentation mode) and\n\
         # `bv render --deck FILE --out DIR/`. Each [[scene]] has a title, a caption,\n\
         # the view shown, and its scene (a scene file's keys) inline or in a file.\n",
    );
    text.push_str(&body);
    if !text.ends_with('\n') {
        text.push('\n');
    }
    text.push('\n');
    text.push_str(END_MARKER);
    text.push('\n');
    Ok(text)
}

/// Writes the deck to `path` atomically, after writing each `file` entry's
/// scene whose state changed (atomically, relative to the deck's folder);
/// the entries' `on_disk` copies are updated.
pub fn save(path: &Path, deck: &mut Deck) -> Result<(), DeckError> {
    for (i, s) in deck.slides.iter_mut().enumerate() {
        let keep = s.state_to_save();
        if let Source::File { path: rel, on_disk } = &mut s.source
            && **on_disk != s.state
        {
            let file = resolve(path.parent(), rel);
            scene::save(&file, &keep).map_err(|source| DeckError::SaveScene {
                entry: i,
                path: file.clone(),
                source,
            })?;
            **on_disk = s.state.clone();
        }
    }
    let text = to_toml_for(path, deck)?;
    fsio::write_atomic(path, |f| f.write_all(text.as_bytes()))?;
    Ok(())
}

/// Longest [`slug`], in bytes: slide files are `NNN-slug.png`, and a file
/// name has at most 255 bytes (a title may have [`MAX_TEXT_CHARS`]).
pub const MAX_SLUG_BYTES: usize = 80;

/// A file-name-safe form of a title: lower-case ASCII letters and digits,
/// anything else one `-` ("Cook-Torrance: D" → "cook-torrance-d"), at most
/// [`MAX_SLUG_BYTES`] long (cut at a word's end where there is one).
pub fn slug(title: &str) -> String {
    let mut out = String::new();
    for c in title.chars() {
        if out.len() >= MAX_SLUG_BYTES {
            // One more character says whether the cut falls inside a word.
            if c.is_ascii_alphanumeric()
                && out.ends_with(|c: char| c.is_ascii_alphanumeric())
                && let Some(end) = out.rfind('-')
            {
                out.truncate(end);
            }
            out.truncate(MAX_SLUG_BYTES);
            break;
        }
        if c.is_ascii_alphanumeric() {
            out.push(c.to_ascii_lowercase());
        } else if !out.ends_with('-') && !out.is_empty() {
            out.push('-');
        }
    }
    while out.ends_with('-') {
        out.pop();
    }
    if out.is_empty() {
        out.push_str("scene");
    }
    out
}

#[cfg(test)]
mod tests {
    use super::*;
    use bv_core::ModelSpec;

    fn tmp_dir(name: &str) -> PathBuf {
        let d = std::env::temp_dir().join(format!("bv-deck-{}-{name}", std::process::id()));
        let _ = std::fs::remove_dir_all(&d);
        std::fs::create_dir_all(&d).unwrap();
        d
    }

    /// A scene's BRDF that cannot be built (its file is missing) is drawn
    /// by its stand-in, named as such, with the note in the caption and no
    /// warning; when the file is there, the BRDF itself is drawn.
    #[test]
    fn a_stand_in_replaces_a_missing_file_and_says_so() {
        let dir = tmp_dir("stand-in");
        let deck = r#"
format = "bv-deck"
version = 1
[[scene]]
title = "Measured"
caption = "A measured material"
view = "polar"
[scene.state]
[[scene.state.brdfs]]
id = 7
color = [78, 151, 234]
visible = true
name = "measured"
spec = { model = "merl", params = { path = "table.binary" } }
[[scene.stand_in]]
id = 7
name = "stand-in: Lambert 0.5"
note = "table.binary is missing: a model stands in"
spec = { model = "lambert", params = { albedo = 0.5 } }
"#;
        let path = dir.join("deck.toml");
        std::fs::write(&path, deck).unwrap();
        let l = load(&path, Builds::Required).unwrap();
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        let s = &l.deck.slides[0];
        assert_eq!(s.state.brdfs[0].spec.id(), "lambert");
        assert_eq!(
            s.state.brdfs[0].name.as_deref(),
            Some("stand-in: Lambert 0.5")
        );
        assert!(
            s.caption
                .ends_with("[table.binary is missing: a model stands in]")
        );
        // Saving writes the entry back as it was read: the measured file,
        // the stand-in table, the caption without the note.
        let mut d = l.deck.clone();
        save(&path, &mut d).unwrap();
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.contains("table.binary") && text.contains("[[scene.stand_in]]"),
            "{text}"
        );
        assert!(!text.contains("a model stands in]"), "{text}");
        let again = load(&path, Builds::Required).unwrap();
        assert_eq!(again.deck.slides[0].state, l.deck.slides[0].state);
        assert_eq!(again.deck.slides[0].caption, l.deck.slides[0].caption);
        // With the file next to the deck (a small table), the file is drawn.
        let lambert = ModelSpec::new("lambert").unwrap().build().unwrap();
        let dims = bv_core::measured::merl::MerlDims::new(8, 8, 16).unwrap();
        bv_core::measured::merl::tabulate(lambert.as_ref(), dims)
            .unwrap()
            .write(dir.join("table.binary"))
            .unwrap();
        let l = load(&path, Builds::Required).unwrap();
        assert!(l.warnings.is_empty(), "{:?}", l.warnings);
        let s = &l.deck.slides[0];
        assert_eq!(s.state.brdfs[0].spec.id(), "merl");
        assert_eq!(s.state.brdfs[0].name.as_deref(), Some("measured"));
        assert_eq!(s.caption, "A measured material");
        // A stand-in for no BRDF, or one that cannot be built, is an error.
        let bad = deck.replace("id = 7\nname = \"stand-in", "id = 8\nname = \"stand-in");
        std::fs::write(&path, bad).unwrap();
        assert!(
            load(&path, Builds::Required)
                .unwrap_err()
                .to_string()
                .contains("no BRDF with id 8")
        );
        let bad = deck.replace("albedo = 0.5", "albedo = 7.0");
        std::fs::write(&path, bad).unwrap();
        assert!(load(&path, Builds::Required).is_err());
        let _ = std::fs::remove_dir_all(&dir);
    }

    fn state(model: &str, theta: f64) -> AppState {
        let mut s = AppState::default();
        s.add(ModelSpec::new(model).unwrap());
        s.incident.theta_deg = theta;
        s.sanitised()
    }

    fn sample() -> Deck {
        let mut lambert =
            Slide::inline("Lambert", "f = ρ/π", "polar", state("lambert", 30.0)).unwrap();
        lambert.seed = vec!["Ideal Diffuse Reflection".into()];
        let mut phong =
            Slide::inline("Phong", "a cosine lobe", "lobe3d", state("phong", 60.0)).unwrap();
        phong.seed = vec!["Classical Phong Model".into(), "Reflectance Models".into()];
        Deck {
            title: Some("Reflectance".into()),
            slides: vec![
                lambert,
                phong,
                Slide::inline("Mirror", "δ", "polar", state("mirror", 45.0)).unwrap(),
            ],
        }
    }

    const HEAD: &str = "format = \"bv-deck\"\nversion = 1\n";

    fn parse(text: &str) -> Result<Loaded, DeckError> {
        from_toml_in(text, None, Builds::Required)
    }

    #[test]
    fn round_trip_is_exact() {
        let dir = tmp_dir("round");
        let path = dir.join("deck.toml");
        let mut deck = sample();
        save(&path, &mut deck).unwrap();
        let back = load(&path, Builds::Required).unwrap();
        assert_eq!(back.warnings, Vec::<String>::new());
        assert_eq!(back.deck, deck);
        // Aliases become ids, and the view is the scene's maximised one.
        assert_eq!(back.deck.slides[1].view, "lobe");
        assert_eq!(back.deck.slides[1].state.maximised.as_deref(), Some("lobe"));
        assert_eq!(back.deck.slides[1].state.incident.theta_deg, 60.0);
        // One heading is written as a string, several as a list, none not at all.
        let text = std::fs::read_to_string(&path).unwrap();
        assert!(
            text.contains("seed = \"Ideal Diffuse Reflection\"\n"),
            "{text}"
        );
        assert!(
            text.contains("seed = [\"Classical Phong Model\", \"Reflectance Models\"]"),
            "{text}"
        );
        assert_eq!(text.matches("seed =").count(), 2, "{text}");
        // A file bv wrote is refused when cut short.
        let text = std::fs::read_to_string(&path).unwrap();
        let cut = &text[..text.len() - END_MARKER.len() - 2];
        assert!(matches!(parse(cut), Err(DeckError::Truncated)), "{cut}");
    }

    #[test]
    fn a_minimal_hand_written_deck_loads() {
        let text = format!(
            "{HEAD}[[scene]]\ntitle = \"Diffuse\"\ncaption = \"same radiance everywhere\"\n\
             view = \"polar\"\n[scene.state]\nincident = {{ theta_deg = 20.0, phi_deg = 0.0 }}\n\
             [[scene.state.brdfs]]\nid = 1\ncolor = [1, 2, 3]\nvisible = true\n\
             spec = {{ model = \"lambert\", params = {{ albedo = 0.8 }} }}\n"
        );
        let d = parse(&text).unwrap();
        assert!(d.warnings.is_empty(), "{:?}", d.warnings);
        let s = &d.deck.slides[0];
        assert_eq!(s.title, "Diffuse");
        assert_eq!(s.state.incident.theta_deg, 20.0);
        assert_eq!(s.state.brdfs[0].spec.id(), "lambert");
        assert_eq!(s.state.maximised.as_deref(), Some("polar"));
        assert_eq!(d.deck.title, None);
    }

    fn entry_error(text: &str) -> (usize, Option<String>, String, String) {
        match parse(text) {
            Err(DeckError::Entry {
                entry,
                title,
                key,
                reason,
            }) => (entry, title, key, reason),
            other => panic!("expected an entry error, got {other:?}"),
        }
    }

    #[test]
    fn errors_name_the_entry_and_the_key() {
        let good = "[[scene]]\ntitle = \"A\"\ncaption = \"c\"\nview = \"polar\"\n\
                    [scene.state]\n";
        // The second entry's inline scene has an angle out of range.
        let text = format!(
            "{HEAD}{good}[[scene]]\ntitle = \"Phong\"\ncaption = \"c\"\nview = \"lobe\"\n\
             [scene.state]\nincident = {{ theta_deg = 190.0, phi_deg = 0.0 }}\n"
        );
        let (i, title, key, reason) = entry_error(&text);
        assert_eq!((i, title.as_deref()), (1, Some("Phong")));
        assert_eq!(key, "state.incident.theta_deg");
        assert!(reason.contains("190"), "{reason}");
        let msg = parse(&text).unwrap_err().to_string();
        assert!(
            msg.contains("scene[1] (\"Phong\")") && msg.contains("state.incident.theta_deg"),
            "{msg}"
        );

        let cases = [
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"nope\"\n[scene.state]\n",
                "view",
                "nope",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\n",
                "state",
                "missing",
            ),
            (
                "caption = \"c\"\nview = \"polar\"\n[scene.state]\n",
                "title",
                "missing",
            ),
            (
                "title = \"\"\ncaption = \"c\"\nview = \"polar\"\n[scene.state]\n",
                "title",
                "empty",
            ),
            (
                "title = \"A\"\ncaption = \"two\\nlines\"\nview = \"polar\"\n[scene.state]\n",
                "caption",
                "one line",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\ncolour = 1\n[scene.state]\n",
                "colour",
                "unknown",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\nseed = []\n[scene.state]\n",
                "seed",
                "empty list",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\nseed = 3\n[scene.state]\n",
                "seed",
                "expected a string",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\nseed = [\"X\", \" \"]\n\
                 [scene.state]\n",
                "seed",
                "empty heading",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\nseed = [\"X\", \"X\"]\n\
                 [scene.state]\n",
                "seed",
                "twice",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\nseed = \"a\\nb\"\n\
                 [scene.state]\n",
                "seed",
                "one line",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\nfile = \"x.toml\"\n[scene.state]\n",
                "file",
                "not both",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\nfile = \"no-such-scene.toml\"\n",
                "file",
                "no-such-scene.toml",
            ),
            (
                "title = \"A\"\ncaption = \"c\"\nview = \"polar\"\n[scene.state]\n\
                 [[scene.state.brdfs]]\nid = 1\ncolor = [1, 2, 3]\nvisible = true\n\
                 spec = { model = \"no-such-model\" }\n",
                "state.brdfs[0]",
                "no-such-model",
            ),
        ];
        for (body, want_key, want_reason) in cases {
            let text = format!("{HEAD}{good}[[scene]]\n{body}");
            let (i, _, key, reason) = entry_error(&text);
            assert_eq!(i, 1, "{body}");
            assert!(key.starts_with(want_key), "{body}: key {key}");
            assert!(reason.contains(want_reason), "{body}: {reason}");
        }
    }

    #[test]
    fn header_errors_name_the_key() {
        let header_key = |text: &str| match parse(text) {
            Err(DeckError::Header { key, .. }) => key,
            other => panic!("{text}: {other:?}"),
        };
        assert_eq!(header_key("version = 1\n[[scene]]\n"), "format");
        assert_eq!(header_key("format = \"bv-scene\"\nversion = 1\n"), "format");
        assert_eq!(header_key("format = \"bv-deck\"\n"), "version");
        assert_eq!(header_key("format = \"bv-deck\"\nversion = 9\n"), "version");
        assert_eq!(header_key(HEAD), "scene");
        assert_eq!(header_key(&format!("{HEAD}scene = []\n")), "scene");
        assert_eq!(header_key(&format!("{HEAD}slides = 3\n")), "slides");
        assert!(matches!(parse("format = "), Err(DeckError::Syntax(_))));
    }

    #[test]
    fn file_entries_are_relative_to_the_deck_and_saved_back() {
        let dir = tmp_dir("files");
        std::fs::create_dir_all(dir.join("scenes")).unwrap();
        let scene_path = dir.join("scenes/ward.toml");
        scene::save(&scene_path, &state("lambert", 10.0)).unwrap();
        let deck_path = dir.join("deck.toml");
        std::fs::write(
            &deck_path,
            format!(
                "{HEAD}[[scene]]\ntitle = \"Ward\"\ncaption = \"c\"\nview = \"cartesian\"\n\
                 file = \"scenes/ward.toml\"\n"
            ),
        )
        .unwrap();
        // Loaded from another working directory: the path is the deck's.
        let mut d = load(&deck_path, Builds::Required).unwrap().deck;
        assert_eq!(d.slides[0].state.incident.theta_deg, 10.0);
        assert_eq!(d.slides[0].state.maximised.as_deref(), Some("cartesian"));
        let before = std::fs::read_to_string(&scene_path).unwrap();
        // Saving an unchanged deck leaves the scene file alone.
        save(&deck_path, &mut d).unwrap();
        assert_eq!(std::fs::read_to_string(&scene_path).unwrap(), before);
        // An edit is written back to the scene file, and the deck still
        // names the file.
        d.slides[0].state.incident.theta_deg = 70.0;
        save(&deck_path, &mut d).unwrap();
        let deck_text = std::fs::read_to_string(&deck_path).unwrap();
        assert!(
            deck_text.contains("file = \"scenes/ward.toml\""),
            "{deck_text}"
        );
        assert!(!deck_text.contains("theta_deg"), "{deck_text}");
        let scene_back = scene::load(&scene_path).unwrap().state;
        assert_eq!(scene_back.incident.theta_deg, 70.0);
        let again = load(&deck_path, Builds::Required).unwrap().deck;
        assert_eq!(again.slides[0].state.incident.theta_deg, 70.0);
    }

    #[test]
    fn warnings_name_the_entry() {
        let text = format!(
            "{HEAD}[[scene]]\ntitle = \"A\"\ncaption = \"c\"\nview = \"polar\"\n\
             [scene.state]\nnot_a_key = 1\n"
        );
        let d = parse(&text).unwrap();
        assert_eq!(d.warnings.len(), 1, "{:?}", d.warnings);
        assert!(
            d.warnings[0].starts_with("scene[0] (\"A\")") && d.warnings[0].contains("not_a_key"),
            "{:?}",
            d.warnings
        );
    }

    #[test]
    fn slugs_are_file_names() {
        assert_eq!(slug("Diffuse"), "diffuse");
        assert_eq!(
            slug("Cook-Torrance: D (Beckmann)"),
            "cook-torrance-d-beckmann"
        );
        assert_eq!(slug("Snell & TIR"), "snell-tir");
        assert_eq!(slug("ρ…"), "scene");
        // Long titles: cut at a word's end, never longer than the limit.
        let long = "Anisotropic microfacet reflection ".repeat(10);
        let s = slug(&long);
        assert!(
            s.len() <= MAX_SLUG_BYTES && s.len() > MAX_SLUG_BYTES / 2,
            "{s}"
        );
        assert!(
            long.to_lowercase()
                .replace(' ', "-")
                .starts_with(&format!("{s}-")),
            "{s}"
        );
        assert_eq!(slug(&"x".repeat(300)), "x".repeat(MAX_SLUG_BYTES));
        assert_eq!(slug(&"ab ".repeat(300)), "ab-".repeat(26) + "ab");
    }
}
