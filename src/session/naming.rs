//! The names the views, legends and figures show for the loaded BRDFs.

use super::state::{AppState, BrdfEntry};

/// The name shown for an entry: the model's name, numbered when the same
/// model is loaded more than once ("Lambert", "Lambert 2").
pub fn display_name(state: &AppState, e: &BrdfEntry) -> String {
    // A chosen name (a material preset's) wins, numbered like a model's name
    // when two entries carry it ("Gold", "Gold 2").
    if let Some(name) = &e.name {
        let k = state
            .brdfs
            .iter()
            .filter(|b| b.name.as_deref() == Some(name.as_str()))
            .position(|b| b.id == e.id);
        return match k {
            Some(0) | None => name.clone(),
            Some(k) => format!("{name} {}", k + 1),
        };
    }
    // A model read from a file is named after the file, tagged with its
    // format and any choice not at its default ("gold-paint (MERL)", "gold-paint
    // (MERL, nearest)": two lookups of one file side by side).
    let info = e.spec.model();
    if let Some((decl, format)) = info.file_param()
        && let Ok(path) = e.spec.params().text(decl.id)
        && let Some(stem) = std::path::Path::new(path).file_stem()
    {
        let mut kind = format.tag().to_string();
        for d in info.params {
            if let bv_core::ParamKind::Choice { default, .. } = d.kind
                && let Ok(v) = e.spec.params().text(d.id)
                && v != default
            {
                kind.push_str(", ");
                kind.push_str(v);
            }
        }
        return format!("{} ({kind})", stem.to_string_lossy());
    }
    let name = info.name;
    let has_file = |b: &BrdfEntry| {
        super::command::path_param(&b.spec)
            .and_then(|p| b.spec.params().text(p).ok())
            .is_some_and(|p| std::path::Path::new(p).file_stem().is_some())
    };
    let same: Vec<u64> = state
        .brdfs
        .iter()
        .filter(|b| b.spec.id() == e.spec.id() && !has_file(b) && b.name.is_none())
        .map(|b| b.id)
        .collect();
    match same.iter().position(|&id| id == e.id) {
        Some(0) | None => name.to_string(),
        Some(k) => format!("{name} {}", k + 1),
    }
}
