//! File models in bv's catalogue: the id a path gets, registration (a
//! reload replaces the entry under the same id), and the resolver that lets
//! every place taking a model id take a path ending in `.brdf`.

use crate::compile::{self, Compiled};
use crate::cpu;
use crate::error::{Result, UserError};
use crate::port;
use bv_core::model::{Build, GpuPort, ModelInfo};
use std::collections::HashMap;
use std::path::{Path, PathBuf};
use std::sync::{Arc, LazyLock, Mutex};
use std::time::SystemTime;

/// Whether a model name is a file path rather than an id.
pub fn is_file_name(name: &str) -> bool {
    Path::new(name)
        .extension()
        .is_some_and(|e| e.eq_ignore_ascii_case("brdf"))
}

/// FNV-1a of a path: stable across runs and platforms (the std hasher is
/// randomly seeded).
fn fnv1a(bytes: &[u8]) -> u64 {
    bytes.iter().fold(0xcbf2_9ce4_8422_2325, |h, b| {
        (h ^ u64::from(*b)).wrapping_mul(0x0100_0000_01b3)
    })
}

/// The catalogue id of the file at canonical `path`: its stem (lower case,
/// every other character `-`) and 8 hex digits of the path's hash, so that
/// two `phong.brdf` in different folders are two models and one path is
/// always the same one. Two paths can share this id (32 bits collide after
/// some 77,000 paths, or on purpose); [`unique_id`] is what a load uses.
pub fn model_id(path: &Path) -> String {
    id_with_hash(path, false)
}

/// The stem part and the hash of a path: 8 hex digits, or all 16 (`long`).
fn id_with_hash(path: &Path, long: bool) -> String {
    let stem: String = path
        .file_stem()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_default()
        .chars()
        .take(40)
        .map(|c| {
            if c.is_ascii_alphanumeric() {
                c.to_ascii_lowercase()
            } else {
                '-'
            }
        })
        .collect();
    // One `-` between words and none at the ends: the id's WGSL form (`-`
    // becomes `_`) then has no `__`, which shader composition refuses.
    let stem = stem
        .split('-')
        .filter(|w| !w.is_empty())
        .collect::<Vec<_>>()
        .join("-");
    let hash = fnv1a(path.to_string_lossy().as_bytes());
    let stem = if stem.is_empty() { "brdf" } else { &stem };
    if long {
        format!("{stem}-{hash:016x}")
    } else {
        format!("{stem}-{:08x}", hash as u32)
    }
}

/// The ids given out in this process, and the canonical path each belongs
/// to: an id is never handed to a second path.
static IDS: LazyLock<Mutex<HashMap<String, PathBuf>>> =
    LazyLock::new(|| Mutex::new(HashMap::new()));

/// The id of the file at canonical `path`, unique in this process: its
/// [`model_id`], or, if another path already has that, the stem with the
/// whole 64-bit hash; if even that is taken (a collision built on purpose),
/// the file is refused rather than confused with the other.
pub fn unique_id(path: &Path) -> Result<String> {
    let mut ids = IDS.lock().map_err(|_| UserError::Model {
        file: path.display().to_string(),
        reason: "internal: the id registry is poisoned".into(),
    })?;
    for long in [false, true] {
        let id = id_with_hash(path, long);
        match ids.get(&id) {
            Some(owner) if owner != path => continue,
            Some(_) => return Ok(id),
            None => {
                ids.insert(id.clone(), path.to_path_buf());
                return Ok(id);
            }
        }
    }
    let other = ids
        .get(&id_with_hash(path, true))
        .map(|p| p.display().to_string())
        .unwrap_or_default();
    Err(UserError::Model {
        file: path.display().to_string(),
        reason: format!(
            "its path has the same 64-bit hash as `{other}`, loaded before it; rename or move \
             one of them"
        ),
    })
}

fn leak(s: String) -> &'static str {
    Box::leak(s.into_boxed_str())
}

/// The catalogue entry of a compiled file, under `id` (its
/// [`unique_id`]).
pub fn model_info(c: &Compiled, path: &Path, id: String) -> Result<ModelInfo> {
    let file_name = path
        .file_name()
        .map(|s| s.to_string_lossy().into_owned())
        .unwrap_or_else(|| id.clone());
    let module_path = format!("bv::user::m{}", id.replace('-', "_"));
    let source = port::bv_module(&module_path, &c.wgsl, c.decls)?;
    let program = cpu::FileProgram::new(c, &path.display().to_string())?;
    let id: &'static str = leak(id);
    let build = Build::Shared(Arc::new(move |p: &bv_core::Params| {
        program
            .build(id, p)
            .map(|b| Box::new(b) as Box<dyn bv_core::Brdf>)
            .map_err(bv_core::BvError::from)
    }));
    Ok(ModelInfo {
        id,
        name: leak(file_name),
        summary: {
            let kind = match c.file.language {
                bv_core::user::brdf_file::Language::Glsl => {
                    "User BRDF file (BRDF Explorer format, GLSL shader)"
                }
                bv_core::user::brdf_file::Language::Wgsl => "User BRDF file (bv's WGSL variant)",
            };
            match &c.sampler {
                crate::sampler::Sampler::None => kind,
                crate::sampler::Sampler::Ready(_) => {
                    leak(format!("{kind}; samples with its isFunc section"))
                }
                crate::sampler::Sampler::Unused(why) => {
                    leak(format!("{kind}; samples with bv's default sampler: {why}"))
                }
            }
        },
        citation: leak(path.display().to_string()),
        params: c.decls,
        aliases: &[],
        build,
        gpu: Some(GpuPort::new(
            leak(module_path),
            leak(path.display().to_string()),
            leak(source),
        )),
    })
}

/// What was last loaded from a path: its stamp and catalogue entry.
#[derive(Clone, Copy)]
struct Stamp {
    modified: Option<SystemTime>,
    len: u64,
    info: &'static ModelInfo,
}

static LOADED: LazyLock<Mutex<HashMap<PathBuf, Stamp>>> =
    LazyLock::new(|| Mutex::new(HashMap::new()));

fn stamp_of(path: &Path) -> Option<(Option<SystemTime>, u64)> {
    if let Some(p) = bv_core::fsio::provided(path) {
        return Some((Some(p.stamp()), p.bytes.len() as u64));
    }
    let m = std::fs::metadata(path).ok()?;
    Some((m.modified().ok(), m.len()))
}

/// The canonical form of a user-named path (errors name it as given).
pub fn canonical(path: &Path) -> Result<PathBuf> {
    // A file handed in as bytes (a browser page's) is known by its name.
    if bv_core::fsio::provided(path).is_some() {
        return Ok(path.to_path_buf());
    }
    std::fs::canonicalize(path).map_err(|e| UserError::Read {
        file: path.display().to_string(),
        reason: e.to_string(),
    })
}

/// Reads a file, bounded by the container's size limit (a 10 MB shader is
/// refused without being read whole).
pub fn read(path: &Path) -> Result<String> {
    let cap = bv_core::user::brdf_file::MAX_FILE_BYTES as u64;
    let bytes =
        bv_core::fsio::read_capped(path, cap, "BRDF file").map_err(|e| UserError::Read {
            file: path.display().to_string(),
            // The file's name is said once.
            reason: match e {
                bv_core::BvError::File { reason, .. } => reason,
                other => other.to_string(),
            },
        })?;
    String::from_utf8(bytes).map_err(|_| UserError::Read {
        file: path.display().to_string(),
        reason: "the file is not UTF-8 text".into(),
    })
}

/// Compiles the file at `path` and registers it (replacing the entry of an
/// earlier load of the same path). Returns the catalogue entry.
pub fn load(path: &Path) -> Result<&'static ModelInfo> {
    let canon = canonical(path)?;
    let stamp = stamp_of(&canon);
    let text = read(&canon)?;
    let c = compile::compile(&text, &path.display().to_string())?;
    let id = unique_id(&canon)?;
    let info = model_info(&c, &canon, id)?;
    let info = bv_core::register(info).map_err(|e| UserError::Model {
        file: path.display().to_string(),
        reason: e.to_string(),
    })?;
    if let Ok(mut map) = LOADED.lock() {
        map.insert(
            canon,
            Stamp {
                modified: stamp.and_then(|s| s.0),
                len: stamp.map_or(0, |s| s.1),
                info,
            },
        );
    }
    Ok(info)
}

/// The catalogue entry of the file at `path`: the one already registered if
/// the file has not changed since, else a fresh load.
pub fn open(path: &Path) -> Result<&'static ModelInfo> {
    let canon = canonical(path)?;
    let now = stamp_of(&canon);
    let cached = LOADED.lock().ok().and_then(|m| m.get(&canon).copied());
    if let (Some(s), Some((modified, len))) = (cached, now)
        && s.modified == modified
        && s.len == len
    {
        // The current entry of the id (a watcher may have reloaded it).
        return Ok(bv_core::find(s.info.id).unwrap_or(s.info));
    }
    load(path)
}

/// The path a file model was loaded from, if `id` is one.
pub fn path_of(id: &str) -> Option<PathBuf> {
    let map = LOADED.lock().ok()?;
    map.iter()
        .find(|(_, s)| s.info.id == id)
        .map(|(p, _)| p.clone())
}

/// The catalogue resolver (see [`install`]): a name ending in `.brdf` is a
/// file to open.
fn resolve(name: &str) -> bv_core::Result<Option<&'static ModelInfo>> {
    if !is_file_name(name) {
        return Ok(None);
    }
    open(Path::new(name))
        .map(Some)
        .map_err(bv_core::BvError::from)
}

/// Makes every model lookup of bv (`--model`, `bv eval`'s `"model"`, scene
/// files, mixes) accept the path of a `.brdf` file. Call once at start-up;
/// calling again does nothing.
pub fn install() {
    bv_core::registry::set_resolver(resolve);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn ids_are_stable_distinct_and_plain() {
        let a = model_id(Path::new("/a/phong.brdf"));
        let b = model_id(Path::new("/b/phong.brdf"));
        assert_ne!(a, b);
        assert_eq!(a, model_id(Path::new("/a/phong.brdf")));
        assert!(a.starts_with("phong-"), "{a}");
        assert_eq!(
            model_id(Path::new("/x/Cook Torrance.brdf")).len(),
            "cook-torrance-".len() + 8
        );
        assert!(is_file_name("x/y.BRDF"));
        assert!(!is_file_name("lambert"));
        assert!(model_id(Path::new("/x/_a__b-.brdf")).starts_with("a-b-"));
    }

    /// Two paths whose 32-bit ids collide (found by a birthday search)
    /// get two ids, each path always the same one.
    #[test]
    fn colliding_short_ids_are_told_apart() {
        let mut seen: HashMap<String, PathBuf> = HashMap::new();
        let (a, b) = (0..2_000_000u32)
            .find_map(|k| {
                let p = PathBuf::from(format!("/collide/{k:x}/phong.brdf"));
                let id = model_id(&p);
                match seen.get(&id) {
                    Some(q) => Some((q.clone(), p)),
                    None => {
                        seen.insert(id, p);
                        None
                    }
                }
            })
            .expect("a 32-bit collision among 2 million paths");
        assert_eq!(model_id(&a), model_id(&b));
        let ia = unique_id(&a).unwrap();
        let ib = unique_id(&b).unwrap();
        assert_ne!(ia, ib);
        assert_eq!(ia, model_id(&a));
        assert_eq!(ib.len(), "phong-".len() + 16, "{ib}");
        assert_eq!(unique_id(&a).unwrap(), ia);
        assert_eq!(unique_id(&b).unwrap(), ib);
    }
}
