//! Material presets: readable TOML files, one per material, each naming the
//! source of its numbers (conductors' η and k from published optical
//! constants, dielectrics' indices, and the Cook & Torrance 1982 material
//! list of the lecture as bv parameter sets).
//!
//! # File format
//! ```toml
//! name = "Copper"                 # shown to the user; searched
//! category = "conductor"          # conductor | dielectric | cook-torrance-1982 | other
//! source = "…"                    # where the numbers come from
//! model = "cook-torrance"         # a catalogue model id
//! wavelengths_nm = [650.0, 550.0, 450.0]   # optional: what the RGB channels sample
//! notes = "…"                     # optional
//!
//! [params]                        # bv's parameter names, as `ModelSpec::from_json` takes them
//! fresnel = "conductor"
//! eta = [0.217, 0.958, 1.17]
//! ```
//! Unknown keys are refused (a typo would otherwise drop a value silently),
//! and a preset is valid only if its model builds with its parameters.
//!
//! The presets shipped in the repository's `assets/presets/` are compiled
//! into the library ([`SHIPPED`]), so the binary has them without the folder.

use crate::error::quote;
use crate::{BvError, ModelSpec, Result};
use serde::Deserialize;
use std::path::{Path, PathBuf};
use std::sync::LazyLock;

/// The categories a preset may declare.
pub const CATEGORIES: &[&str] = &["conductor", "dielectric", "cook-torrance-1982", "other"];

/// Largest preset file read (bytes): presets are a few hundred bytes.
pub const MAX_FILE_BYTES: u64 = 1 << 20;

/// A validated material preset.
#[derive(Debug, Clone, PartialEq)]
pub struct Preset {
    /// Display name.
    pub name: String,
    /// One of [`CATEGORIES`].
    pub category: String,
    /// Where the numbers come from.
    pub source: String,
    /// Wavelengths (nm) the red, green and blue channels sample, if stated.
    pub wavelengths_nm: Option<[f64; 3]>,
    /// Free-form remarks.
    pub notes: Option<String>,
    /// The model and its parameters (validated: it builds).
    pub spec: ModelSpec,
}

#[derive(Debug, Deserialize)]
#[serde(deny_unknown_fields)]
struct PresetFile {
    name: String,
    category: String,
    source: String,
    model: String,
    #[serde(default)]
    wavelengths_nm: Option<[f64; 3]>,
    #[serde(default)]
    notes: Option<String>,
    params: toml::Table,
}

/// Parses and validates a preset from TOML text. Errors name the offending
/// key (TOML's messages give the key and line; a bad parameter gives bv's
/// message naming the parameter).
pub fn parse(text: &str) -> Result<Preset> {
    let file: PresetFile =
        toml::from_str(text).map_err(|e| BvError::Invalid(e.to_string().trim().to_string()))?;
    if file.name.trim().is_empty() {
        return Err(BvError::Invalid("`name` must not be empty".into()));
    }
    if file.source.trim().is_empty() {
        return Err(BvError::Invalid(
            "`source` must say where the numbers come from".into(),
        ));
    }
    if !CATEGORIES.contains(&file.category.as_str()) {
        return Err(BvError::Invalid(format!(
            "`category` = \"{}\" is not one of {}",
            file.category,
            CATEGORIES.join(", ")
        )));
    }
    let params = serde_json::to_value(&file.params)
        .map_err(|e| BvError::Invalid(format!("`params`: {e}")))?;
    let spec = ModelSpec::from_json(&file.model, &params)?;
    spec.build()?;
    Ok(Preset {
        name: file.name,
        category: file.category,
        source: file.source,
        wavelengths_nm: file.wavelengths_nm,
        notes: file.notes,
        spec,
    })
}

/// [`parse`], with the error naming `file`.
pub fn parse_named(file: &str, text: &str) -> Result<Preset> {
    parse(text).map_err(|e| BvError::File {
        path: file.to_string(),
        reason: e.to_string(),
    })
}

/// Reads one preset file.
pub fn load_file(path: &Path) -> Result<Preset> {
    let name = path.display().to_string();
    let err = |reason: String| BvError::File {
        path: name.clone(),
        reason,
    };
    let meta = std::fs::metadata(path).map_err(|e| err(e.to_string()))?;
    if !meta.is_file() {
        return Err(err("not a regular file".into()));
    }
    if meta.len() > MAX_FILE_BYTES {
        return Err(err(format!(
            "{} bytes; a preset is at most {MAX_FILE_BYTES}",
            meta.len()
        )));
    }
    let text = std::fs::read_to_string(path).map_err(|e| err(e.to_string()))?;
    parse_named(&name, &text)
}

/// What [`load_dir`] found: the valid presets and one error per bad file.
#[derive(Debug, Clone, Default)]
pub struct Loaded {
    /// Valid presets, in file-name order.
    pub presets: Vec<Preset>,
    /// One error per file that did not load, naming it.
    pub errors: Vec<BvError>,
}

/// Loads every `*.toml` file of `dir`, in file-name order. A bad file does
/// not stop the others; its error (naming it) goes to [`Loaded::errors`].
/// Only an unreadable folder is an error.
pub fn load_dir(dir: &Path) -> Result<Loaded> {
    let entries = std::fs::read_dir(dir).map_err(|e| BvError::File {
        path: dir.display().to_string(),
        reason: e.to_string(),
    })?;
    let mut paths: Vec<PathBuf> = entries
        .filter_map(|e| e.ok().map(|e| e.path()))
        .filter(|p| p.extension().is_some_and(|x| x == "toml"))
        .collect();
    paths.sort();
    let mut out = Loaded::default();
    for p in paths {
        match load_file(&p) {
            Ok(preset) => out.presets.push(preset),
            Err(e) => out.errors.push(e),
        }
    }
    Ok(out)
}

/// Presets whose name contains `query`, ignoring case (all for an empty query).
pub fn search<'a>(presets: &'a [Preset], query: &str) -> Vec<&'a Preset> {
    let q = query.to_lowercase();
    presets
        .iter()
        .filter(|p| p.name.to_lowercase().contains(&q))
        .collect()
}

macro_rules! shipped {
    ($($file:literal),* $(,)?) => {
        /// The presets of `assets/presets/`, compiled in: `(file name, TOML text)`.
        pub const SHIPPED: &[(&str, &str)] = &[
            $(($file, include_str!(concat!("../../../assets/presets/", $file))),)*
        ];
    };
}

shipped![
    "aluminium.toml",
    "calm-water.toml",
    "chromium.toml",
    "copper.toml",
    "ct1982-bronze.toml",
    "ct1982-carbon.toml",
    "ct1982-copper.toml",
    "ct1982-lunar-dust.toml",
    "ct1982-nickel.toml",
    "ct1982-obsidian.toml",
    "ct1982-olive-drab.toml",
    "ct1982-red-rubber.toml",
    "ct1982-rust.toml",
    "ct1982-stainless-steel.toml",
    "ct1982-tin.toml",
    "ct1982-tungsten.toml",
    "diamond.toml",
    "frosted-glass.toml",
    "fused-silica.toml",
    "glass.toml",
    "gold.toml",
    "ice.toml",
    "iridium.toml",
    "iron.toml",
    "mercury.toml",
    "molybdenum.toml",
    "nickel.toml",
    "polished-diamond.toml",
    "sapphire.toml",
    "silver.toml",
    "tantalum.toml",
    "tungsten.toml",
    "water-from-below.toml",
    "water.toml",
    "window-glass.toml",
];

/// The compiled-in presets, parsed (in [`SHIPPED`] order). A shipped preset
/// that fails to parse is a bug the tests catch; it is reported, not hidden.
pub fn shipped() -> Loaded {
    let mut out = Loaded::default();
    for (file, text) in SHIPPED {
        match parse_named(file, text) {
            Ok(p) => out.presets.push(p),
            Err(e) => out.errors.push(e),
        }
    }
    out
}

/// The shipped presets with the file name each came from (without `.toml`).
static SHIPPED_NAMED: LazyLock<Vec<(String, Preset)>> = LazyLock::new(|| {
    SHIPPED
        .iter()
        .filter_map(|(file, text)| {
            let stem = file.strip_suffix(".toml").unwrap_or(file).to_string();
            parse_named(file, text).ok().map(|p| (stem, p))
        })
        .collect()
});

/// The same presets as one slice (what [`search`] takes).
static PRESETS: LazyLock<Vec<Preset>> =
    LazyLock::new(|| SHIPPED_NAMED.iter().map(|(_, p)| p.clone()).collect());

/// The compiled-in presets (those that parse; the core's tests hold all).
pub fn shipped_presets() -> &'static [Preset] {
    &PRESETS
}

/// The shipped preset called `name` (its display name or its file name,
/// ignoring case): what the panel, `--preset` and decks look up. An unknown
/// name is an error listing the close matches.
pub fn find(name: &str) -> Result<&'static Preset> {
    let q = name.trim().to_lowercase();
    if let Some((_, p)) = SHIPPED_NAMED
        .iter()
        .find(|(stem, p)| p.name.to_lowercase() == q || stem.to_lowercase() == q)
    {
        return Ok(p);
    }
    let close = close_matches(&q);
    if close.is_empty() {
        let all: Vec<&str> = SHIPPED_NAMED.iter().map(|(_, p)| p.name.as_str()).collect();
        return Err(BvError::Invalid(format!(
            "unknown preset `{}`; the presets are: {}",
            quote(name),
            all.join(", ")
        )));
    }
    Err(BvError::Invalid(format!(
        "unknown preset `{}`; close matches: {}",
        quote(name),
        close.join(", ")
    )))
}

/// Names of presets that contain the query, or whose name or file name is
/// within a few edits of it (closest first).
fn close_matches(q: &str) -> Vec<String> {
    let mut scored: Vec<(usize, &str)> = SHIPPED_NAMED
        .iter()
        .filter_map(|(stem, p)| {
            let n = p.name.to_lowercase();
            // The bare material word of "Copper (Cook-Torrance 1982)".
            let head = n.split(" (").next().unwrap_or(&n).to_string();
            let d = if !q.is_empty() && (n.contains(q) || stem.contains(q)) {
                0
            } else {
                edit_distance(q, &head)
                    .min(edit_distance(q, &n))
                    .min(edit_distance(q, stem))
            };
            // A third of the query's letters wrong, at least two: a typo,
            // not another word.
            (d <= (q.chars().count() / 3).max(2)).then_some((d, p.name.as_str()))
        })
        .collect();
    scored.sort_by_key(|&(d, n)| (d, n.len()));
    scored
        .into_iter()
        .take(8)
        .map(|(_, n)| n.to_string())
        .collect()
}

/// Levenshtein distance (insertions, deletions, substitutions), by
/// characters.
fn edit_distance(a: &str, b: &str) -> usize {
    let b: Vec<char> = b.chars().collect();
    let mut row: Vec<usize> = (0..=b.len()).collect();
    for (i, ca) in a.chars().enumerate() {
        let mut prev = row[0];
        row[0] = i + 1;
        for (j, &cb) in b.iter().enumerate() {
            let cur = row[j + 1];
            row[j + 1] = (prev + usize::from(ca != cb)).min(row[j] + 1).min(cur + 1);
            prev = cur;
        }
    }
    row[b.len()]
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn edit_distance_by_hand() {
        assert_eq!(edit_distance("", "abc"), 3);
        assert_eq!(edit_distance("kitten", "sitting"), 3);
        assert_eq!(edit_distance("gold", "gold"), 0);
        assert_eq!(edit_distance("gld", "gold"), 1);
    }
    use crate::Rgb;

    #[test]
    fn every_shipped_preset_parses_validates_and_builds() {
        let l = shipped();
        assert!(l.errors.is_empty(), "{:?}", l.errors);
        assert_eq!(l.presets.len(), SHIPPED.len());
        for p in &l.presets {
            p.spec.build().unwrap();
            assert!(!p.source.is_empty());
        }
        // The ten conductors, the dielectrics and the twelve materials of
        // the lecture's Cook-Torrance slide.
        let count = |c: &str| l.presets.iter().filter(|p| p.category == c).count();
        assert!(count("conductor") >= 10);
        assert!(count("dielectric") >= 5);
        assert_eq!(count("cook-torrance-1982"), 12);
        // Names are unique.
        let mut names: Vec<_> = l.presets.iter().map(|p| p.name.to_lowercase()).collect();
        names.sort();
        names.dedup();
        assert_eq!(names.len(), l.presets.len());
    }

    #[test]
    fn rough_dielectric_presets_are_the_issue_33_materials() {
        // (name, η, α): window glass and water nearly smooth, frosted glass
        // rough, diamond's high index.
        let want = [
            ("Window glass", 1.52, 0.02),
            ("Frosted glass", 1.52, 0.3),
            ("Calm water", 1.333, 0.02),
            ("Polished diamond", 2.42, 0.02),
        ];
        let l = shipped();
        for (name, eta, alpha) in want {
            let p = l.presets.iter().find(|p| p.name == name).unwrap();
            assert_eq!(p.category, "dielectric");
            let b = p.spec.build().unwrap();
            assert!(b.transmits(), "{name}");
            assert_eq!(b.interface_eta(), Some(eta), "{name}");
            let a = p.spec.params().float("alpha_x").unwrap();
            assert!((a - alpha).abs() < 1e-12, "{name}: α {a}");
            assert_eq!(p.spec.params().float("alpha_y").unwrap(), a);
        }
    }

    #[test]
    fn the_compiled_list_is_the_folder() {
        let dir = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../assets/presets");
        let l = load_dir(&dir).unwrap();
        assert!(l.errors.is_empty(), "{:?}", l.errors);
        let mut files: Vec<String> = std::fs::read_dir(&dir)
            .unwrap()
            .map(|e| e.unwrap().file_name().to_string_lossy().into_owned())
            .filter(|n| n.ends_with(".toml"))
            .collect();
        files.sort();
        let compiled: Vec<String> = SHIPPED.iter().map(|(f, _)| f.to_string()).collect();
        assert_eq!(files, compiled, "add new preset files to SHIPPED");
        assert_eq!(l.presets, shipped().presets);
    }

    fn f0(eta: f64, k: f64) -> f64 {
        ((eta - 1.0) * (eta - 1.0) + k * k) / ((eta + 1.0) * (eta + 1.0) + k * k)
    }

    #[test]
    fn noble_metal_constants_match_their_source_rows() {
        // Transcription check: normal-incidence reflectance of the presets'
        // η, k against that of the source's own tabulated rows nearest to
        // 650, 550 and 450 nm (Mitsuba 0.5 data/ior, luxpop: rows at
        // 652.5, 551.0 and 450.9 nm), F0 = ((η−1)² + k²)/((η+1)² + k²).
        let rows: [(&str, [(f64, f64); 3]); 3] = [
            ("Gold", [(0.166, 3.15), (0.3455, 2.7306), (1.5021, 1.8759)]),
            (
                "Silver",
                [(0.140, 4.15), (0.1244, 3.3481), (0.1511, 2.4788)],
            ),
            (
                "Copper",
                [(0.214, 3.67), (0.9504, 2.5765), (1.1653, 2.3976)],
            ),
        ];
        let l = shipped();
        for (name, want) in rows {
            let p = l.presets.iter().find(|p| p.name == name).unwrap();
            let eta = p.spec.params().color("eta").unwrap();
            let k = p.spec.params().color("k").unwrap();
            for c in 0..3 {
                let got = f0(eta[c], k[c]);
                let reference = f0(want[c].0, want[c].1);
                assert!(
                    (got - reference).abs() < 0.02,
                    "{name} channel {c}: {got} vs {reference}"
                );
            }
            assert_eq!(p.wavelengths_nm, Some([650.0, 550.0, 450.0]));
        }
        // Gold and copper are coloured (red > blue at normal incidence),
        // silver nearly neutral.
        let refl = |n: &str| {
            let p = l.presets.iter().find(|p| p.name == n).unwrap();
            let (e, k) = (
                p.spec.params().color("eta").unwrap(),
                p.spec.params().color("k").unwrap(),
            );
            Rgb::new(f0(e.x, k.x), f0(e.y, k.y), f0(e.z, k.z))
        };
        assert!(refl("Gold").x - refl("Gold").z > 0.5);
        assert!(refl("Copper").x - refl("Copper").z > 0.3);
        assert!(refl("Silver").x - refl("Silver").z < 0.1);
    }

    #[test]
    fn glass_and_water_numbers() {
        let l = shipped();
        let eta = |n: &str| {
            let p = l.presets.iter().find(|p| p.name == n).unwrap();
            p.spec.params().color("eta").unwrap().x
        };
        assert!((crate::optics::dielectric_f0(eta("Glass")) - 0.04).abs() < 1e-12);
        let w = crate::optics::snell_window_half_angle(eta("Water")).unwrap();
        assert!((w.to_degrees() - 48.6).abs() < 0.05);
    }

    const GOOD: &str = r#"
name = "Test"
category = "other"
source = "a test"
model = "lambert"
[params]
albedo = 0.5
"#;

    #[test]
    fn malformed_files_name_the_key() {
        assert!(parse(GOOD).is_ok());
        let cases = [
            (GOOD.replace("source = \"a test\"\n", ""), "source"),
            (GOOD.replace("name = \"Test\"", "name = 3"), "name"),
            (GOOD.replace("albedo = 0.5", "albedo = 2.0"), "albedo"),
            (GOOD.replace("albedo = 0.5", "albdo = 0.5"), "albdo"),
            (
                GOOD.replace("model = \"lambert\"", "model = \"lambertian\""),
                "lambertian",
            ),
            (
                GOOD.replace("category = \"other\"", "category = \"metal\""),
                "category",
            ),
            (format!("{GOOD}\ncolour = 1\n"), "colour"),
            (GOOD.replace("[params]", "[params\n"), "line"),
        ];
        for (text, key) in cases {
            let e = parse_named("test.toml", &text).unwrap_err().to_string();
            assert!(e.contains(key) && e.starts_with("test.toml"), "{key}: {e}");
        }
    }

    #[test]
    fn search_is_case_insensitive_substring() {
        let l = shipped();
        let hits = search(&l.presets, "COPPER");
        assert_eq!(
            hits.len(),
            2,
            "{:?}",
            hits.iter().map(|p| &p.name).collect::<Vec<_>>()
        );
        assert!(
            search(&l.presets, "water")
                .iter()
                .all(|p| p.name.to_lowercase().contains("water"))
        );
        assert_eq!(search(&l.presets, "").len(), l.presets.len());
        assert!(search(&l.presets, "unobtainium").is_empty());
    }

    #[test]
    fn load_dir_reports_bad_files_by_name() {
        let dir = std::env::temp_dir().join(format!("bv-presets-test-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        std::fs::write(dir.join("b-good.toml"), GOOD).unwrap();
        std::fs::write(dir.join("a-bad.toml"), "name = ").unwrap();
        std::fs::write(dir.join("ignored.txt"), "x").unwrap();
        let l = load_dir(&dir).unwrap();
        std::fs::remove_dir_all(&dir).unwrap();
        assert_eq!(l.presets.len(), 1);
        assert_eq!(l.errors.len(), 1);
        assert!(l.errors[0].to_string().contains("a-bad.toml"));
        assert!(load_dir(Path::new("/nonexistent-bv-presets")).is_err());
    }
}
