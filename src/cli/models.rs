//! `bv models`: the model catalogue with each parameter's kind, range, default,
//! unit, slider scale and description, as a readable listing or as JSON.

use super::output::{json_f64, print};
use bv_core::params::{Applies, ParamDecl, ParamKind};
use bv_core::{ModelInfo, catalogue};
use serde_json::{Value, json};
use std::fmt::Write as _;

/// Options of `bv models`.
#[derive(Debug, Clone, clap::Args)]
pub struct ModelsArgs {
    /// Print JSON (an array of models) instead of the readable listing.
    #[arg(long)]
    pub json: bool,
    /// List only the model of this `.brdf` file (compiled, with its
    /// parameters as bv declares them).
    #[arg(long, value_name = "FILE")]
    pub file: Option<std::path::PathBuf>,
}

/// Runs `bv models`.
pub fn run(args: &ModelsArgs) -> anyhow::Result<()> {
    if let Some(path) = &args.file {
        let m = crate::session::user_models::resolve(&path.to_string_lossy())?;
        if args.json {
            let mut text = serde_json::to_string_pretty(&model_json(m))?;
            text.push('\n');
            return print(&text);
        }
        let mut s = String::new();
        model_text(&mut s, m);
        return print(&s);
    }
    if args.json {
        let mut text = serde_json::to_string_pretty(&catalogue_json())?;
        text.push('\n');
        print(&text)
    } else {
        print(&catalogue_text())
    }
}

/// Every model of the catalogue as JSON: `[{id, name, summary, citation,
/// params: [{id, label, kind, range, default, unit, log, doc, …}]}]`.
pub fn catalogue_json() -> Value {
    Value::Array(catalogue().iter().map(|m| model_json(m)).collect())
}

fn model_json(m: &ModelInfo) -> Value {
    json!({
        "id": m.id,
        "name": m.name,
        "summary": m.summary,
        "citation": m.citation,
        "params": m.params.iter().map(param_json).collect::<Vec<_>>(),
    })
}

/// One parameter declaration as JSON. Always present: `id`, `label`, `kind`,
/// `range` (human text), `default`, `unit`, `log`, `doc`, `applies_when`
/// (`null`, or the choice parameter and values under which it matters); numeric kinds add
/// `min`/`max` (and the slider span), choices their `options`, lists their
/// item `fields`.
pub fn param_json(d: &ParamDecl) -> Value {
    let mut v = json!({
        "id": d.id,
        "label": d.label,
        "kind": kind_name(&d.kind),
        "range": d.range_text(),
        "default": d.default_value().to_json(),
        "unit": d.unit(),
        "log": matches!(d.kind, ParamKind::Float(s) if s.log),
        "doc": d.doc,
        "applies_when": match d.applies {
            Applies::Always => Value::Null,
            Applies::When { param, any_of } => json!({ "param": param, "any_of": any_of }),
            Applies::Positive { param } => json!({ "param": param, "above": 0.0 }),
        },
    });
    let extra = match d.kind {
        ParamKind::Float(s) => json!({
            "min": json_f64(s.min),
            "max": json_f64(s.max),
            "slider_min": json_f64(s.slider_min),
            "slider_max": json_f64(s.slider_max),
        }),
        ParamKind::Color(s) => json!({ "min": json_f64(s.min), "max": json_f64(s.max) }),
        ParamKind::Choice { options, .. } => json!({ "options": options }),
        ParamKind::List {
            fields,
            min_items,
            max_items,
            ..
        } => json!({
            "min_items": min_items,
            "max_items": max_items,
            "fields": fields.iter().map(param_json).collect::<Vec<_>>(),
        }),
        ParamKind::Components {
            max_items, weight, ..
        } => json!({
            "min_items": 1,
            "max_items": max_items,
            "weight_min": json_f64(weight.min),
            "weight_max": json_f64(weight.max),
        }),
        ParamKind::Bool { .. } | ParamKind::Path { .. } => json!({}),
    };
    if let (Value::Object(base), Value::Object(more)) = (&mut v, extra) {
        base.extend(more);
    }
    v
}

/// Short name of a parameter kind (`float`, `color`, …).
pub fn kind_name(k: &ParamKind) -> &'static str {
    match k {
        ParamKind::Float(_) => "float",
        ParamKind::Color(_) => "color",
        ParamKind::Choice { .. } => "choice",
        ParamKind::Bool { .. } => "bool",
        ParamKind::List { .. } => "list",
        ParamKind::Path { .. } => "path",
        ParamKind::Components { .. } => "components",
    }
}

/// The readable listing: per model a heading, its summary and source, then a
/// table of its parameters.
pub fn catalogue_text() -> String {
    let mut s = String::new();
    let models = catalogue();
    let _ = writeln!(
        s,
        "{} model{}. f(wi, wo) is without the cosine factor, in 1/sr per RGB channel.\n\
         Set parameters with `--param NAME=VALUE` (a colour as r,g,b or one grey number),\n\
         or as JSON in `bv eval` queries.",
        models.len(),
        if models.len() == 1 { "" } else { "s" }
    );
    for m in models.iter() {
        s.push('\n');
        model_text(&mut s, m);
    }
    s
}

/// One model's entry of the listing.
fn model_text(s: &mut String, m: &ModelInfo) {
    let _ = writeln!(s, "{}  ({})", m.id, m.name);
    let _ = writeln!(s, "  {}", m.summary);
    let _ = writeln!(s, "  source: {}", m.citation);
    if m.params.is_empty() {
        let _ = writeln!(s, "  (no parameters)");
        return;
    }
    param_table(s, m.params, "  ");
}

/// Appends an aligned table of `decls` to `s`, each line prefixed by `indent`;
/// list-valued parameters get their item fields in a nested table.
fn param_table(s: &mut String, decls: &[ParamDecl], indent: &str) {
    let header = ["param", "kind", "range", "default", "unit", "scale"];
    let rows: Vec<[String; 6]> = decls
        .iter()
        .map(|d| {
            [
                d.id.to_string(),
                kind_name(&d.kind).to_string(),
                match d.applies_text() {
                    Some(when) => format!("{} (if {when})", d.range_text()),
                    None => d.range_text(),
                },
                default_text(d),
                d.unit().to_string(),
                match d.kind {
                    ParamKind::Float(f) if f.log => "log".to_string(),
                    ParamKind::Float(_) | ParamKind::Color(_) => "linear".to_string(),
                    _ => String::new(),
                },
            ]
        })
        .collect();
    let mut width = header.map(str::len);
    for r in &rows {
        for (w, c) in width.iter_mut().zip(r) {
            *w = (*w).max(c.chars().count());
        }
    }
    let line = |s: &mut String, cells: &[&str], doc: &str| {
        let mut l = String::from(indent);
        for (c, w) in cells.iter().zip(width) {
            let pad = w.saturating_sub(c.chars().count());
            let _ = write!(l, "{c}{}  ", " ".repeat(pad));
        }
        l.push_str(doc);
        let _ = writeln!(s, "{}", l.trim_end());
    };
    line(s, &header, "description");
    for (d, r) in decls.iter().zip(&rows) {
        let cells: Vec<&str> = r.iter().map(String::as_str).collect();
        line(s, &cells, d.doc);
        if is_list(d) {
            let _ = writeln!(s, "{indent}    default: {}", d.default_value().to_json());
        }
        if let ParamKind::List { fields, .. } = d.kind {
            let _ = writeln!(s, "{indent}    each item of `{}`:", d.id);
            param_table(s, fields, &format!("{indent}      "));
        }
    }
}

/// Whether a parameter takes a list (its default is printed below its row,
/// as it would not fit in the table).
fn is_list(d: &ParamDecl) -> bool {
    matches!(
        d.kind,
        ParamKind::List { .. } | ParamKind::Components { .. }
    )
}

/// A default value as short text: `0.5` for a grey colour, `0.1,0.2,0.3`
/// otherwise, the item count for lists.
fn default_text(d: &ParamDecl) -> String {
    let json = d.default_value().to_json();
    if is_list(d) {
        let n = json.as_array().map_or(0, Vec::len);
        return format!("{n} item{}", if n == 1 { "" } else { "s" });
    }
    match json {
        Value::Array(a) if matches!(d.kind, ParamKind::Color(_)) => {
            if a.windows(2).all(|w| w[0] == w[1]) && !a.is_empty() {
                a[0].to_string()
            } else {
                a.iter().map(Value::to_string).collect::<Vec<_>>().join(",")
            }
        }
        Value::String(t) if t.is_empty() => "(none)".to_string(),
        Value::String(t) => t,
        other => other.to_string(),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn json_lists_every_model_and_parameter() {
        let v = catalogue_json();
        let arr = v.as_array().unwrap();
        assert_eq!(arr.len(), catalogue().len());
        for (j, m) in arr.iter().zip(catalogue().iter()) {
            assert_eq!(j["id"], m.id);
            let ps = j["params"].as_array().unwrap();
            assert_eq!(ps.len(), m.params.len());
            for (p, d) in ps.iter().zip(m.params) {
                assert_eq!(p["id"], d.id);
                assert_eq!(p["default"], d.default_value().to_json());
                for key in ["kind", "range", "unit", "log", "doc"] {
                    assert!(!p[key].is_null(), "{} {} {key}", m.id, d.id);
                }
            }
        }
    }

    #[test]
    fn text_names_every_model_and_parameter() {
        let t = catalogue_text();
        for m in catalogue().iter() {
            assert!(t.contains(&format!("\n{}  ({})", m.id, m.name)), "{}", m.id);
            for d in m.params {
                assert!(t.contains(d.id) && t.contains(d.doc), "{} {}", m.id, d.id);
            }
        }
        // Lambert's albedo: grey default printed as one number.
        assert!(t.contains("albedo  color  rgb, each 0..1  0.5"), "{t}");
    }
}
