//! Making specs: a model's values parsed from JSON (scene files, `bv eval`),
//! from command-line text (`--param alpha=0.3`) or set one by one (the GUI),
//! each validated against the model's declaration with errors that name the
//! parameter and its accepted range. Models are found by id in the catalogue
//! (mix components name theirs), which is why this sits above the registry.

use super::MAX_NESTING;
use super::decl::{ParamDecl, ParamKind};
use super::value::{Component, ModelSpec, ParamValue, Params, json_number};
use crate::error::quote;
use crate::{BvError, Result, registry};
use serde_json::{Map, Value};

impl ModelSpec {
    /// The model with all defaults. A path whose extension a file format
    /// declares (`steel.bsdf`, `gold.binary`) stands for the model that
    /// reads it, with its file parameter set to the path
    /// ([`registry::file_model`]).
    pub fn new(model: &str) -> Result<Self> {
        if let Some((info, param)) = registry::file_model(model) {
            let mut spec = Self::defaults(info);
            spec.params_mut()
                .insert(param.to_string(), ParamValue::Text(model.to_string()));
            return Ok(spec);
        }
        Ok(Self::defaults(registry::find(model)?))
    }

    /// The model with the given JSON parameters over its defaults (the JSON form:
    /// scalars for grey colours, `alpha` for `alpha_x = alpha_y`).
    pub fn from_json(model: &str, params: &Value) -> Result<Self> {
        Self::from_json_nested(model, params, 0)
    }

    fn from_json_nested(model: &str, params: &Value, depth: usize) -> Result<Self> {
        let mut spec = Self::new(model)?;
        match params {
            Value::Null => {}
            Value::Object(map) => spec.apply_json(map, depth)?,
            other => {
                return Err(BvError::Invalid(format!(
                    "`params` must be an object, found {other}"
                )));
            }
        }
        Ok(spec)
    }

    /// Sets the given values over the current ones, validating each.
    pub fn apply_json(&mut self, map: &Map<String, Value>, depth: usize) -> Result<()> {
        let info = self.model();
        // Aliases first, so that explicit values of what they stand for win
        // (`alpha` = 0.3 with `alpha_y` = 0.1 is `alpha_x` = 0.3, `alpha_y` = 0.1).
        let mut entries: Vec<(&String, &Value)> = map.iter().collect();
        entries.sort_by_key(|(k, _)| info.alias(k).is_none());
        // Validate everything before changing anything: a refused value
        // leaves the spec as it was.
        let mut next = self.params().clone();
        for (key, value) in entries {
            if let Some(alias) = info.alias(key).filter(|_| info.param(key).is_err()) {
                for id in alias.sets {
                    let decl = info.param(id)?;
                    let v = parse_value(decl, value, depth).map_err(|e| rename(e, key))?;
                    next.insert((*id).to_string(), v);
                }
                continue;
            }
            let decl = info.param(key)?;
            let v = parse_value(decl, value, depth)?;
            next.insert(key.clone(), v);
        }
        *self.params_mut() = next;
        Ok(())
    }

    /// Sets one parameter from its JSON value.
    pub fn set_json(&mut self, id: &str, value: &Value) -> Result<()> {
        let mut m = Map::new();
        m.insert(id.to_string(), value.clone());
        self.apply_json(&m, 0)
    }

    /// Sets one parameter from a command-line string (`0.3`, `0.2,0.92,1.1`,
    /// `ggx`, or JSON for lists).
    pub fn set_str(&mut self, id: &str, text: &str) -> Result<()> {
        let info = self.model();
        // An alias is typed like the first parameter it stands for.
        let key = match info.alias(id).filter(|_| info.param(id).is_err()) {
            Some(alias) => alias.sets.first().copied().unwrap_or(id),
            None => id,
        };
        // A refusal names what the user typed (`alpha`), not the axis it
        // stands for on models that have one.
        let decl = info.param(key).map_err(|e| match e {
            BvError::UnknownParam { model, known, .. } => BvError::UnknownParam {
                model,
                param: id.to_string(),
                known,
            },
            other => other,
        })?;
        let value = cli_text_to_json(decl, text).map_err(|e| rename(e, id))?;
        self.set_json(id, &value)
    }

    /// Sets one already-typed value after validating it against the
    /// declaration (what the GUI calls), without a trip through JSON. An
    /// alias sets every parameter it stands for. A refused value leaves the
    /// spec as it was.
    pub fn set(&mut self, id: &str, value: ParamValue) -> Result<()> {
        let info = self.model();
        let targets: Vec<&'static ParamDecl> =
            match info.alias(id).filter(|_| info.param(id).is_err()) {
                Some(alias) => alias
                    .sets
                    .iter()
                    .map(|t| info.param(t))
                    .collect::<Result<_>>()?,
                None => vec![info.param(id)?],
            };
        let mut checked = Vec::with_capacity(targets.len());
        for d in targets {
            let v = check_value(d, value.clone(), 0).map_err(|e| rename(e, id))?;
            checked.push((d.id, v));
        }
        for (k, v) in checked {
            self.params_mut().insert(k.to_string(), v);
        }
        Ok(())
    }
}

/// Levels of mixes inside a spec (0 for a model that is not a mix), counted
/// without recursion.
fn mix_depth(spec: &ModelSpec) -> usize {
    let mut deepest = 0;
    let mut stack = vec![(spec, 0usize)];
    while let Some((s, depth)) = stack.pop() {
        for (_, v) in s.params().iter() {
            if let ParamValue::Components(cs) = v {
                deepest = deepest.max(depth + 1);
                if depth + 1 > MAX_NESTING {
                    return depth + 1;
                }
                stack.extend(cs.iter().map(|c| (&c.spec, depth + 1)));
            }
        }
    }
    deepest
}

/// Validates a typed value against its declaration (the typed twin of
/// [`parse_value`]) and returns it in canonical form (a grey number for a
/// colour becomes `[x, x, x]`; a list item's missing fields get their
/// defaults). `depth` counts the mixes around the value.
pub fn check_value(decl: &ParamDecl, v: ParamValue, depth: usize) -> Result<ParamValue> {
    let id = decl.id;
    let bad = |reason: String| BvError::BadValue {
        param: id.to_string(),
        reason,
    };
    match (decl.kind, v) {
        (ParamKind::Float(s), ParamValue::Float(x)) => {
            Ok(ParamValue::Float(check_range(id, x, s.min, s.max)?))
        }
        (ParamKind::Color(s), ParamValue::Float(x)) => {
            check_range(id, x, s.min, s.max)?;
            Ok(ParamValue::Color([x; 3]))
        }
        (ParamKind::Color(s), ParamValue::Color(c)) => {
            for x in c {
                check_range(id, x, s.min, s.max)?;
            }
            Ok(ParamValue::Color(c))
        }
        (ParamKind::Choice { options, .. }, ParamValue::Text(t)) => {
            if options.contains(&t.as_str()) {
                Ok(ParamValue::Text(t))
            } else {
                Err(bad(format!(
                    "`{}` is not one of {}",
                    quote(&t),
                    options.join(", ")
                )))
            }
        }
        (ParamKind::Bool { .. }, ParamValue::Bool(b)) => Ok(ParamValue::Bool(b)),
        (ParamKind::Path { .. }, ParamValue::Text(t)) => Ok(ParamValue::Text(t)),
        (
            ParamKind::List {
                fields,
                min_items,
                max_items,
                ..
            },
            ParamValue::List(items),
        ) => {
            if items.len() < min_items || items.len() > max_items {
                return Err(bad(format!(
                    "has {} items; between {min_items} and {max_items} are accepted",
                    items.len()
                )));
            }
            let mut out = Vec::with_capacity(items.len());
            for (i, item) in items.into_iter().enumerate() {
                if let Some((k, _)) = item
                    .iter()
                    .find(|(k, _)| !fields.iter().any(|f| f.id == *k))
                {
                    return Err(bad(format!(
                        "item {i} has unknown field `{k}` (fields: {})",
                        fields.iter().map(|f| f.id).collect::<Vec<_>>().join(", ")
                    )));
                }
                let mut p = Params::defaults(fields);
                for f in fields {
                    if let Ok(x) = item.get(f.id) {
                        let x = check_value(f, x.clone(), depth)
                            .map_err(|e| rename(e, &format!("{id}[{i}].{}", f.id)))?;
                        p.insert(f.id.to_string(), x);
                    }
                }
                out.push(p);
            }
            Ok(ParamValue::List(out))
        }
        (
            ParamKind::Components {
                max_items, weight, ..
            },
            ParamValue::Components(cs),
        ) => {
            if cs.is_empty() || cs.len() > max_items {
                return Err(bad(format!(
                    "has {} components; between 1 and {max_items} are accepted",
                    cs.len()
                )));
            }
            for (i, c) in cs.iter().enumerate() {
                let key = format!("{id}[{i}].weight");
                check_range(&key, c.weight, weight.min, weight.max)?;
                // Components are specs, validated when they were made; only
                // the nesting is left to bound.
                if depth + 1 + mix_depth(&c.spec) > MAX_NESTING {
                    return Err(bad(format!("mixes nest deeper than {MAX_NESTING} levels")));
                }
            }
            Ok(ParamValue::Components(cs))
        }
        (_, other) => Err(bad(format!(
            "expected {}, found {}",
            decl.range_text(),
            quote(&other.to_json().to_string())
        ))),
    }
}

fn rename(e: BvError, to: &str) -> BvError {
    match e {
        BvError::OutOfRange {
            value, min, max, ..
        } => BvError::OutOfRange {
            param: to.to_string(),
            value,
            min,
            max,
        },
        BvError::BadValue { reason, .. } => BvError::BadValue {
            param: to.to_string(),
            reason,
        },
        other => other,
    }
}

/// Turns a command-line value into the JSON the parser takes: numbers and
/// comma-separated numbers for floats and colours, the text itself for choices and
/// paths, JSON for lists and components.
pub fn cli_text_to_json(decl: &ParamDecl, text: &str) -> Result<Value> {
    let bad = |reason: String| BvError::BadValue {
        param: decl.id.to_string(),
        reason,
    };
    let number = |s: &str| -> Result<Value> {
        let x: f64 = s
            .trim()
            .parse()
            .map_err(|_| bad(format!("`{}` is not a number", quote(s))))?;
        if !x.is_finite() {
            return Err(bad(format!("`{}` is not a finite number", quote(s))));
        }
        Ok(json_number(x))
    };
    match decl.kind {
        ParamKind::Float(_) => number(text),
        ParamKind::Color(_) => {
            let parts: Vec<&str> = text.split(',').collect();
            if parts.len() == 1 {
                number(parts[0])
            } else {
                Ok(Value::Array(
                    parts.into_iter().map(number).collect::<Result<Vec<_>>>()?,
                ))
            }
        }
        ParamKind::Choice { .. } | ParamKind::Path { .. } => Ok(Value::String(text.to_string())),
        ParamKind::Bool { .. } => match text.trim() {
            "true" | "1" | "yes" | "on" => Ok(Value::Bool(true)),
            "false" | "0" | "no" | "off" => Ok(Value::Bool(false)),
            other => Err(bad(format!("`{}` is not true or false", quote(other)))),
        },
        ParamKind::List { .. } | ParamKind::Components { .. } => {
            serde_json::from_str(text).map_err(|e| bad(format!("expected a JSON list ({e})")))
        }
    }
}

fn check_range(id: &str, x: f64, min: f64, max: f64) -> Result<f64> {
    if !x.is_finite() {
        return Err(BvError::BadValue {
            param: id.to_string(),
            reason: format!("{x} is not a finite number"),
        });
    }
    if x < min || x > max {
        return Err(BvError::OutOfRange {
            param: id.to_string(),
            value: x,
            min,
            max,
        });
    }
    Ok(x)
}

fn as_f64(id: &str, v: &Value) -> Result<f64> {
    v.as_f64().ok_or_else(|| BvError::BadValue {
        param: id.to_string(),
        reason: format!("expected a number, found {}", quote(&v.to_string())),
    })
}

/// Parses and validates one JSON value against its declaration.
pub fn parse_value(decl: &ParamDecl, v: &Value, depth: usize) -> Result<ParamValue> {
    let id = decl.id;
    let bad = |reason: String| BvError::BadValue {
        param: id.to_string(),
        reason,
    };
    match decl.kind {
        ParamKind::Float(s) => Ok(ParamValue::Float(check_range(
            id,
            as_f64(id, v)?,
            s.min,
            s.max,
        )?)),
        ParamKind::Color(s) => {
            let c = match v {
                Value::Number(_) => [as_f64(id, v)?; 3],
                Value::Array(a) if a.len() == 3 => {
                    [as_f64(id, &a[0])?, as_f64(id, &a[1])?, as_f64(id, &a[2])?]
                }
                other => {
                    return Err(bad(format!(
                        "expected a number or [r, g, b], found {other}"
                    )));
                }
            };
            for x in c {
                check_range(id, x, s.min, s.max)?;
            }
            Ok(ParamValue::Color(c))
        }
        ParamKind::Choice { options, .. } => {
            let s = v.as_str().ok_or_else(|| {
                bad(format!(
                    "expected one of {}, found {}",
                    options.join(", "),
                    quote(&v.to_string())
                ))
            })?;
            if options.contains(&s) {
                Ok(ParamValue::Text(s.to_string()))
            } else {
                Err(bad(format!(
                    "`{}` is not one of {}",
                    quote(s),
                    options.join(", ")
                )))
            }
        }
        ParamKind::Bool { .. } => v.as_bool().map(ParamValue::Bool).ok_or_else(|| {
            bad(format!(
                "expected true or false, found {}",
                quote(&v.to_string())
            ))
        }),
        ParamKind::Path { .. } => v
            .as_str()
            .map(|s| ParamValue::Text(s.to_string()))
            .ok_or_else(|| {
                bad(format!(
                    "expected a path string, found {}",
                    quote(&v.to_string())
                ))
            }),
        ParamKind::List {
            fields,
            min_items,
            max_items,
            ..
        } => {
            let items = v
                .as_array()
                .ok_or_else(|| bad(format!("expected a list, found {}", quote(&v.to_string()))))?;
            if items.len() < min_items || items.len() > max_items {
                return Err(bad(format!(
                    "has {} items; between {min_items} and {max_items} are accepted",
                    items.len()
                )));
            }
            let mut out = Vec::with_capacity(items.len());
            for (i, item) in items.iter().enumerate() {
                let obj = item
                    .as_object()
                    .ok_or_else(|| bad(format!("item {i} is not an object")))?;
                let mut p = Params::defaults(fields);
                for (k, x) in obj {
                    let f = fields.iter().find(|f| f.id == k).ok_or_else(|| {
                        bad(format!(
                            "item {i} has unknown field `{k}` (fields: {})",
                            fields.iter().map(|f| f.id).collect::<Vec<_>>().join(", ")
                        ))
                    })?;
                    let val = parse_value(f, x, depth)
                        .map_err(|e| rename(e, &format!("{id}[{i}].{k}")))?;
                    p.insert(k.clone(), val);
                }
                out.push(p);
            }
            Ok(ParamValue::List(out))
        }
        ParamKind::Components {
            max_items, weight, ..
        } => {
            if depth >= MAX_NESTING {
                return Err(bad(format!("mixes nest deeper than {MAX_NESTING} levels")));
            }
            let items = v.as_array().ok_or_else(|| {
                bad(format!(
                    "expected a list of components, found {}",
                    quote(&v.to_string())
                ))
            })?;
            if items.is_empty() || items.len() > max_items {
                return Err(bad(format!(
                    "has {} components; between 1 and {max_items} are accepted",
                    items.len()
                )));
            }
            let mut out = Vec::with_capacity(items.len());
            for (i, item) in items.iter().enumerate() {
                let obj = item
                    .as_object()
                    .ok_or_else(|| bad(format!("component {i} is not an object")))?;
                for k in obj.keys() {
                    if !matches!(k.as_str(), "weight" | "model" | "params") {
                        return Err(bad(format!(
                            "component {i} has unknown field `{k}` (fields: weight, model, params)"
                        )));
                    }
                }
                let w = match obj.get("weight") {
                    Some(x) => check_range(
                        &format!("{id}[{i}].weight"),
                        as_f64(&format!("{id}[{i}].weight"), x)?,
                        weight.min,
                        weight.max,
                    )?,
                    None => weight.default,
                };
                let model = obj
                    .get("model")
                    .and_then(Value::as_str)
                    .ok_or_else(|| bad(format!("component {i} needs a `model` id")))?;
                let spec = ModelSpec::from_json_nested(
                    model,
                    obj.get("params").unwrap_or(&Value::Null),
                    depth + 1,
                )?;
                out.push(Component { weight: w, spec });
            }
            Ok(ParamValue::Components(out))
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::params::decl::{ColorSpec, FloatSpec};
    use serde_json::json;

    const DECLS: &[ParamDecl] = &[
        ParamDecl {
            id: "e",
            label: "e",
            doc: "exponent",
            kind: ParamKind::Float(FloatSpec::log(0.0, 10000.0, 20.0, 1.0, 1000.0)),
            applies: crate::Applies::Always,
        },
        ParamDecl {
            id: "kd",
            label: "kd",
            doc: "diffuse",
            kind: ParamKind::Color(ColorSpec::unit_range([0.5; 3])),
            applies: crate::Applies::Always,
        },
    ];

    #[test]
    fn defaults_and_ranges() {
        let p = Params::defaults(DECLS);
        assert_eq!(p.float("e").unwrap(), 20.0);
        assert_eq!(p.color("kd").unwrap(), glam::DVec3::splat(0.5));
        let err = parse_value(&DECLS[0], &json!(-1.0), 0).unwrap_err();
        assert_eq!(
            err.to_string(),
            "parameter `e` = -1 is out of range [0, 10000]"
        );
        assert!(parse_value(&DECLS[1], &json!([0.1, 0.2]), 0).is_err());
        assert_eq!(
            parse_value(&DECLS[1], &json!(0.25), 0).unwrap(),
            ParamValue::Color([0.25; 3])
        );
        assert!(parse_value(&DECLS[1], &json!([0.1, 2.0, 0.3]), 0).is_err());
    }

    #[test]
    fn typed_set_agrees_with_the_json_parser() {
        // The same values through `set` (typed) and `set_json` (parsed):
        // accepted or refused alike, and equal when accepted.
        let cases: Vec<(&str, &str, ParamValue)> = vec![
            ("cook-torrance", "alpha_x", ParamValue::Float(0.3)),
            ("cook-torrance", "alpha_x", ParamValue::Float(-1.0)),
            ("cook-torrance", "alpha_x", ParamValue::Float(f64::NAN)),
            ("cook-torrance", "alpha", ParamValue::Float(0.2)),
            ("cook-torrance", "kd", ParamValue::Float(0.5)),
            ("cook-torrance", "kd", ParamValue::Color([0.1, 0.2, 0.3])),
            ("cook-torrance", "kd", ParamValue::Color([0.1, 2.0, 0.3])),
            (
                "cook-torrance",
                "distribution",
                ParamValue::Text("ggx".into()),
            ),
            (
                "cook-torrance",
                "distribution",
                ParamValue::Text("gauss".into()),
            ),
            ("cook-torrance", "ks", ParamValue::Text("ggx".into())),
            ("lafortune", "lobes", ParamValue::List(vec![])),
            ("mix", "components", ParamValue::Components(vec![])),
        ];
        for (model, id, v) in cases {
            let mut a = ModelSpec::new(model).unwrap();
            let mut b = a.clone();
            let ra = a.set(id, v.clone());
            let rb = b.set_json(id, &v.to_json());
            assert_eq!(
                ra.is_ok(),
                rb.is_ok(),
                "{model}.{id} = {v:?}: {ra:?} vs {rb:?}"
            );
            assert_eq!(a, b, "{model}.{id} = {v:?}");
        }
        // A list item gets its missing fields' defaults, as the parser does.
        let mut a = ModelSpec::new("lafortune").unwrap();
        let mut b = a.clone();
        let item = serde_json::json!([{"n": 5.0}]);
        b.set_json("lobes", &item).unwrap();
        let ParamValue::List(items) = b.params().get("lobes").unwrap().clone() else {
            panic!("lobes is a list");
        };
        a.set("lobes", ParamValue::List(items)).unwrap();
        assert_eq!(a, b);
        // A nest deeper than allowed is refused by the typed setter too.
        let mut deep = ModelSpec::new("lambert").unwrap();
        for _ in 0..MAX_NESTING {
            let mut m = ModelSpec::new("mix").unwrap();
            m.set(
                "components",
                ParamValue::Components(vec![Component {
                    weight: 1.0,
                    spec: deep.clone(),
                }]),
            )
            .unwrap();
            deep = m;
        }
        let mut top = ModelSpec::new("mix").unwrap();
        let err = top
            .set(
                "components",
                ParamValue::Components(vec![Component {
                    weight: 1.0,
                    spec: deep,
                }]),
            )
            .unwrap_err();
        assert!(err.to_string().contains("nest deeper"), "{err}");
    }

    #[test]
    fn cli_text_forms() {
        assert_eq!(cli_text_to_json(&DECLS[0], "0.3").unwrap(), json!(0.3));
        assert_eq!(
            cli_text_to_json(&DECLS[1], "0.2,0.92,1.1").unwrap(),
            json!([0.2, 0.92, 1.1])
        );
        assert!(cli_text_to_json(&DECLS[0], "abc").is_err());
        let nan = cli_text_to_json(&DECLS[0], "nan").unwrap_err().to_string();
        assert_eq!(nan, "parameter `e`: `nan` is not a finite number");
    }
}
