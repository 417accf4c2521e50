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
    // Several of one model: each is named by the parameters that tell it
    // from the others ("Modified Phong (e = 200)", "Cook-Torrance (D =
    // ggx)"): a legend reading "Modified Phong 2" left the audience to
    // guess which curve had e = 200. Numbered where that does not tell them
    // apart (equal parameters, or more than two that differ).
    if same.len() > 1 {
        let group: Vec<&BrdfEntry> = state
            .brdfs
            .iter()
            .filter(|b| same.contains(&b.id))
            .collect();
        let by_params = |b: &BrdfEntry| differing_params(b, &group);
        if let Some(mine) = by_params(e)
            && group
                .iter()
                .filter(|b| b.id != e.id)
                .all(|b| by_params(b).as_deref() != Some(mine.as_str()))
        {
            return format!("{name} ({mine})");
        }
    }
    match same.iter().position(|&id| id == e.id) {
        Some(0) | None => name.to_string(),
        Some(k) => format!("{name} {}", k + 1),
    }
}

/// The parameters of `e` whose values differ within `group` (entries of
/// its model), as "label = value", in declaration order; `None` when none
/// or more than two differ (too long for a legend).
fn differing_params(e: &BrdfEntry, group: &[&BrdfEntry]) -> Option<String> {
    let info = e.spec.model();
    let mut parts = Vec::new();
    for d in info.params {
        if !d.applies_to(e.spec.params()) {
            continue;
        }
        let Ok(v) = e.spec.params().get(d.id) else {
            continue;
        };
        if group
            .iter()
            .any(|b| b.spec.params().get(d.id).ok() != Some(v))
        {
            parts.push(format!("{} = {}", d.label, param_text(v)));
        }
    }
    (!parts.is_empty() && parts.len() <= 2).then(|| parts.join(", "))
}

/// Four significant digits without trailing zeros ("0.15", not "0.1500").
fn fmt_number(x: f64) -> String {
    let s = bv_core::text::fmt_value(x);
    if s.contains('.') && !s.contains('e') {
        s.trim_end_matches('0').trim_end_matches('.').to_string()
    } else {
        s
    }
}

/// A parameter's value as a caption or a name shows it.
fn param_text(v: &bv_core::ParamValue) -> String {
    use bv_core::ParamValue;
    match v {
        ParamValue::Float(x) => fmt_number(*x),
        ParamValue::Color([r, g, b]) if r == g && g == b => fmt_number(*r),
        ParamValue::Color([r, g, b]) => {
            format!(
                "({}, {}, {})",
                fmt_number(*r),
                fmt_number(*g),
                fmt_number(*b)
            )
        }
        ParamValue::Text(t) => std::path::Path::new(t)
            .file_name()
            .map_or_else(|| t.clone(), |f| f.to_string_lossy().into_owned()),
        ParamValue::Bool(b) => if *b { "on" } else { "off" }.to_string(),
        ParamValue::List(items) => format!("{} items", items.len()),
        ParamValue::Components(c) => format!("{} components", c.len()),
    }
}

/// A figure's caption: one line per drawn BRDF (its name, its model when the
/// name is not the model's, and the parameters that apply, in declaration
/// order) and the light's direction.
pub fn figure_caption(state: &AppState) -> String {
    use bv_core::text::fmt_deg;
    let mut lines: Vec<String> = state
        .brdfs
        .iter()
        .filter(|e| state.is_drawn(e))
        .map(|e| {
            let info = e.spec.model();
            let name = display_name(state, e);
            let params: Vec<String> = info
                .params
                .iter()
                .filter(|d| d.applies_to(e.spec.params()))
                .filter_map(|d| {
                    let v = e.spec.params().get(d.id).ok()?;
                    Some(format!("{} = {}", d.label, param_text(v)))
                })
                .collect();
            let model = if name.starts_with(info.name) {
                String::new()
            } else {
                format!(" ({})", info.name)
            };
            format!("{name}{model}: {}", params.join(", "))
        })
        .collect();
    lines.push(format!(
        "light at θi = {}°, φi = {}°",
        fmt_deg(state.incident.theta_deg),
        fmt_deg(state.incident.phi_deg)
    ));
    lines.join("\n")
}

#[cfg(test)]
mod caption_tests {
    use super::*;
    use bv_core::ModelSpec;

    #[test]
    fn several_of_one_model_are_named_by_what_differs() {
        let mut s = AppState::default();
        let spec = |e: f64| {
            ModelSpec::from_json("modified-phong", &serde_json::json!({"kd": 0.0, "e": e})).unwrap()
        };
        let a = s.add(spec(10.0));
        let b = s.add(spec(200.0));
        let name = |s: &AppState, id| display_name(s, s.entry(id).unwrap());
        assert_eq!(name(&s, a), "Modified Phong (e = 10)");
        assert_eq!(name(&s, b), "Modified Phong (e = 200)");
        // Equal parameters cannot tell them apart: numbered.
        let c = s.add(spec(200.0));
        assert_eq!(name(&s, a), "Modified Phong (e = 10)");
        assert_eq!(name(&s, b), "Modified Phong 2");
        assert_eq!(name(&s, c), "Modified Phong 3");
        // A choice names itself.
        let mut s = AppState::default();
        let ct = |d: &str| {
            ModelSpec::from_json("cook-torrance", &serde_json::json!({"distribution": d})).unwrap()
        };
        let g = s.add(ct("ggx"));
        let k = s.add(ct("beckmann"));
        assert_eq!(name(&s, g), "Cook-Torrance (D = ggx)");
        assert_eq!(name(&s, k), "Cook-Torrance (D = beckmann)");
    }

    #[test]
    fn the_caption_names_models_parameters_and_the_light() {
        let mut s = AppState::default();
        s.add(
            ModelSpec::from_json("lambert", &serde_json::json!({"albedo": [0.2, 0.4, 0.6]}))
                .unwrap(),
        );
        s.add(
            ModelSpec::from_json(
                "cook-torrance",
                &serde_json::json!({"alpha_x": 0.3, "alpha_y": 0.3, "fresnel": "conductor"}),
            )
            .unwrap(),
        );
        s.incident.theta_deg = 30.0;
        let c = figure_caption(&s);
        let lines: Vec<&str> = c.lines().collect();
        assert_eq!(lines.len(), 3, "{c}");
        assert!(
            lines[0].starts_with("Lambert: ") && lines[0].contains("(0.2, 0.4, 0.6)"),
            "{c}"
        );
        assert!(
            lines[1].contains("Fresnel = conductor") && lines[1].contains("k = "),
            "{c}"
        );
        // f0 does not apply to a conductor.
        assert!(!lines[1].contains("F0"), "{c}");
        assert_eq!(lines[2], "light at θi = 30°, φi = 0°");
    }
}
