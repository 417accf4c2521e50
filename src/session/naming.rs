//! The names the views, legends and figures show for the loaded BRDFs.

use super::state::{AppState, BrdfEntry};

/// The name shown for an entry: the model's name, numbered when the same
/// model is loaded more than once ("Lambert", "Lambert 2").
pub fn display_name(state: &AppState, e: &BrdfEntry) -> String {
    // A model read from a file is named after the file ("gold-paint (MERL)").
    if let Some(param) = super::command::path_param(e.spec.id())
        && let Ok(path) = e.spec.params().text(param)
        && let Some(stem) = std::path::Path::new(path).file_stem()
    {
        let kind = if e.spec.id() == "merl" {
            // Nearest and trilinear lookups of one file side by side.
            match e.spec.params().text("interpolation") {
                Ok("nearest") => "MERL, nearest".to_string(),
                _ => "MERL".to_string(),
            }
        } else {
            e.spec.id().to_string()
        };
        return format!("{} ({kind})", stem.to_string_lossy());
    }
    let name = bv_core::find(e.spec.id()).map(|m| m.name).unwrap_or("?");
    let has_file = |b: &BrdfEntry| {
        super::command::path_param(b.spec.id())
            .and_then(|p| b.spec.params().text(p).ok())
            .is_some_and(|p| std::path::Path::new(p).file_stem().is_some())
    };
    let same: Vec<u64> = state
        .brdfs
        .iter()
        .filter(|b| b.spec.id() == e.spec.id() && !has_file(b))
        .map(|b| b.id)
        .collect();
    match same.iter().position(|&id| id == e.id) {
        Some(0) | None => name.to_string(),
        Some(k) => format!("{name} {}", k + 1),
    }
}
