//! Model parameters as data (issue 2, item 3).
//!
//! Every model declares its parameters once, as a static list of [`ParamDecl`]:
//! an id, a label, a doc line and a [`ParamKind`] (range, default, unit, log-scale
//! hint, …). The CLI, scene files and the GUI's sliders all read this one
//! declaration; values are parsed and validated against it here, with errors that
//! name the parameter and its accepted range.

use crate::{BvError, Result, registry};
use serde_json::{Map, Value};
use std::collections::BTreeMap;

mod gpu;
pub use gpu::{
    COMPONENT_ENTRY_SLOTS, DerivedSlots, GpuLayout, GpuModelRef, GpuParam, GpuSlot, MAX_SLOTS,
    gpu_layout, gpu_model_index, pack_model, pack_model_with,
};

/// How deeply `mix` components may nest (a mix of mixes of …), so that a hostile
/// scene cannot overflow the stack.
pub const MAX_NESTING: usize = 4;

/// A float parameter's range, default and presentation hints.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct FloatSpec {
    /// Smallest accepted value.
    pub min: f64,
    /// Largest accepted value.
    pub max: f64,
    /// Default value.
    pub default: f64,
    /// Unit shown next to the value ("" when dimensionless, "rad", "1/sr", …).
    pub unit: &'static str,
    /// Whether a slider should move logarithmically (exponents, roughness).
    pub log: bool,
    /// Lower end of the slider's default span (within `min..=max`).
    pub slider_min: f64,
    /// Upper end of the slider's default span (within `min..=max`).
    pub slider_max: f64,
}

impl FloatSpec {
    /// A linear parameter whose slider covers the whole accepted range.
    pub const fn linear(min: f64, max: f64, default: f64) -> Self {
        Self {
            min,
            max,
            default,
            unit: "",
            log: false,
            slider_min: min,
            slider_max: max,
        }
    }

    /// A logarithmic parameter (slider span given separately).
    pub const fn log(min: f64, max: f64, default: f64, slider_min: f64, slider_max: f64) -> Self {
        Self {
            min,
            max,
            default,
            unit: "",
            log: true,
            slider_min,
            slider_max,
        }
    }

    /// The same spec with a unit.
    pub const fn with_unit(mut self, unit: &'static str) -> Self {
        self.unit = unit;
        self
    }
}

/// A colour parameter: linear RGB, each channel in `min..=max`; a scalar means grey.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ColorSpec {
    /// Smallest accepted channel value.
    pub min: f64,
    /// Largest accepted channel value.
    pub max: f64,
    /// Default value.
    pub default: [f64; 3],
    /// Unit ("" for reflectances).
    pub unit: &'static str,
}

impl ColorSpec {
    /// A reflectance colour in 0..1.
    pub const fn unit_range(default: [f64; 3]) -> Self {
        Self {
            min: 0.0,
            max: 1.0,
            default,
            unit: "",
        }
    }

    /// A colour with an explicit range.
    pub const fn range(min: f64, max: f64, default: [f64; 3]) -> Self {
        Self {
            min,
            max,
            default,
            unit: "",
        }
    }

    /// Whether the range is the 0..1 of a reflectance (a colour picker fits it).
    pub fn is_reflectance(&self) -> bool {
        self.min == 0.0 && self.max == 1.0
    }
}

/// What kind of value a parameter takes.
#[derive(Debug, Clone, Copy)]
pub enum ParamKind {
    /// A real number in a range.
    Float(FloatSpec),
    /// A linear-RGB triple.
    Color(ColorSpec),
    /// One of a fixed set of names.
    Choice {
        /// Accepted names.
        options: &'static [&'static str],
        /// Default name.
        default: &'static str,
    },
    /// A flag.
    Bool {
        /// Default.
        default: bool,
    },
    /// A list of records, each with the given fields (e.g. Lafortune lobes).
    List {
        /// Fields of one item.
        fields: &'static [ParamDecl],
        /// Fewest items accepted.
        min_items: usize,
        /// Most items accepted.
        max_items: usize,
        /// How many items (each all defaults) the default list has.
        default_items: usize,
    },
    /// A file path (e.g. a MERL `.binary`).
    Path {
        /// Default path ("" for none).
        default: &'static str,
    },
    /// A list of `{weight, model, params}` components (the `mix` model).
    Components {
        /// Most components accepted.
        max_items: usize,
        /// Weight range of one component.
        weight: FloatSpec,
        /// Builds the default component list.
        default: fn() -> Vec<Component>,
    },
}

/// One declared parameter of a model.
#[derive(Debug, Clone, Copy)]
pub struct ParamDecl {
    /// Stable id used by the CLI, scene files and tests (`alpha_x`).
    pub id: &'static str,
    /// Short label for the GUI (`α x`).
    pub label: &'static str,
    /// One-line description (tooltip, `bv models`).
    pub doc: &'static str,
    /// The value's kind, range and default.
    pub kind: ParamKind,
}

impl ParamDecl {
    /// The declared default value.
    pub fn default_value(&self) -> ParamValue {
        match self.kind {
            ParamKind::Float(s) => ParamValue::Float(s.default),
            ParamKind::Color(s) => ParamValue::Color(s.default),
            ParamKind::Choice { default, .. } => ParamValue::Text(default.to_string()),
            ParamKind::Bool { default } => ParamValue::Bool(default),
            ParamKind::List {
                fields,
                default_items,
                ..
            } => ParamValue::List(vec![Params::defaults(fields); default_items]),
            ParamKind::Path { default } => ParamValue::Text(default.to_string()),
            ParamKind::Components { default, .. } => ParamValue::Components(default()),
        }
    }

    /// A short human description of the accepted values (`0..10000`, `one of a, b`).
    pub fn range_text(&self) -> String {
        match self.kind {
            ParamKind::Float(s) => format!("{}..{}", s.min, s.max),
            ParamKind::Color(s) => format!("rgb, each {}..{}", s.min, s.max),
            ParamKind::Choice { options, .. } => format!("one of {}", options.join(", ")),
            ParamKind::Bool { .. } => "true or false".to_string(),
            ParamKind::List {
                min_items,
                max_items,
                fields,
                ..
            } => format!(
                "{min_items}..{max_items} items of {{{}}}",
                fields.iter().map(|f| f.id).collect::<Vec<_>>().join(", ")
            ),
            ParamKind::Path { .. } => "a file path".to_string(),
            ParamKind::Components { max_items, .. } => {
                format!("1..{max_items} items of {{weight, model, params}}")
            }
        }
    }

    /// Unit text, empty when none.
    pub fn unit(&self) -> &'static str {
        match self.kind {
            ParamKind::Float(s) => s.unit,
            ParamKind::Color(s) => s.unit,
            _ => "",
        }
    }
}

/// One weighted component of a `mix`.
#[derive(Debug, Clone, PartialEq)]
pub struct Component {
    /// Weight of this component (0..10).
    pub weight: f64,
    /// Model id and parameters of the component.
    pub spec: ModelSpec,
}

/// A parameter value, already checked against its declaration.
#[derive(Debug, Clone, PartialEq)]
pub enum ParamValue {
    /// Float.
    Float(f64),
    /// Linear RGB.
    Color([f64; 3]),
    /// Choice name or path.
    Text(String),
    /// Flag.
    Bool(bool),
    /// List of records.
    List(Vec<Params>),
    /// Mix components.
    Components(Vec<Component>),
}

impl ParamValue {
    /// This value as JSON (the form `bv eval`, scene files and `bv models` use).
    pub fn to_json(&self) -> Value {
        match self {
            ParamValue::Float(x) => json_number(*x),
            ParamValue::Color(c) => Value::Array(c.iter().map(|x| json_number(*x)).collect()),
            ParamValue::Text(s) => Value::String(s.clone()),
            ParamValue::Bool(b) => Value::Bool(*b),
            ParamValue::List(items) => Value::Array(items.iter().map(Params::to_json).collect()),
            ParamValue::Components(items) => Value::Array(
                items
                    .iter()
                    .map(|c| {
                        let mut m = Map::new();
                        m.insert("weight".into(), json_number(c.weight));
                        m.insert("model".into(), Value::String(c.spec.model.clone()));
                        m.insert("params".into(), c.spec.params.to_json());
                        Value::Object(m)
                    })
                    .collect(),
            ),
        }
    }
}

fn json_number(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}

/// A complete, validated set of parameter values, keyed by parameter id.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Params(pub BTreeMap<String, ParamValue>);

impl Params {
    /// All declared defaults.
    pub fn defaults(decls: &[ParamDecl]) -> Self {
        Params(
            decls
                .iter()
                .map(|d| (d.id.to_string(), d.default_value()))
                .collect(),
        )
    }

    /// The value of `id`, or an error if it is missing.
    pub fn get(&self, id: &str) -> Result<&ParamValue> {
        self.0.get(id).ok_or_else(|| BvError::BadValue {
            param: id.to_string(),
            reason: "missing".to_string(),
        })
    }

    /// A float parameter.
    pub fn float(&self, id: &str) -> Result<f64> {
        match self.get(id)? {
            ParamValue::Float(x) => Ok(*x),
            other => Err(wrong_type(id, "a number", other)),
        }
    }

    /// A colour parameter as a vector.
    pub fn color(&self, id: &str) -> Result<glam::DVec3> {
        match self.get(id)? {
            ParamValue::Color(c) => Ok(glam::DVec3::from_array(*c)),
            ParamValue::Float(x) => Ok(glam::DVec3::splat(*x)),
            other => Err(wrong_type(id, "a colour", other)),
        }
    }

    /// A choice or path parameter.
    pub fn text(&self, id: &str) -> Result<&str> {
        match self.get(id)? {
            ParamValue::Text(s) => Ok(s),
            other => Err(wrong_type(id, "a name", other)),
        }
    }

    /// A flag.
    pub fn bool(&self, id: &str) -> Result<bool> {
        match self.get(id)? {
            ParamValue::Bool(b) => Ok(*b),
            other => Err(wrong_type(id, "true or false", other)),
        }
    }

    /// A list parameter.
    pub fn list(&self, id: &str) -> Result<&[Params]> {
        match self.get(id)? {
            ParamValue::List(l) => Ok(l),
            other => Err(wrong_type(id, "a list", other)),
        }
    }

    /// The components of a mix.
    pub fn components(&self, id: &str) -> Result<&[Component]> {
        match self.get(id)? {
            ParamValue::Components(c) => Ok(c),
            other => Err(wrong_type(id, "a list of components", other)),
        }
    }

    /// All values as one JSON object.
    pub fn to_json(&self) -> Value {
        Value::Object(
            self.0
                .iter()
                .map(|(k, v)| (k.clone(), v.to_json()))
                .collect(),
        )
    }
}

fn wrong_type(id: &str, want: &str, got: &ParamValue) -> BvError {
    BvError::BadValue {
        param: id.to_string(),
        reason: format!("expected {want}, found {}", got.to_json()),
    }
}

/// A model id with a full set of validated parameters: what the GUI holds, what
/// scene files store, and what [`ModelSpec::build`] turns into an evaluator.
#[derive(Debug, Clone, PartialEq)]
pub struct ModelSpec {
    /// Model id from the catalogue.
    pub model: String,
    /// All of its parameters.
    pub params: Params,
}

impl ModelSpec {
    /// The model with all defaults.
    pub fn new(model: &str) -> Result<Self> {
        let info = registry::find(model)?;
        Ok(Self {
            model: info.id.to_string(),
            params: Params::defaults(info.params),
        })
    }

    /// The model with the given JSON parameters over its defaults (SPEC §5 form:
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
        let info = registry::find(&self.model)?;
        // `alpha` is shorthand for `alpha_x = alpha_y` (SPEC §2); explicit axes win.
        let has = |id: &str| info.params.iter().any(|d| d.id == id);
        let mut entries: Vec<(&String, &Value)> = map.iter().collect();
        entries.sort_by_key(|(k, _)| k.as_str() != "alpha");
        for (key, value) in entries {
            if key == "alpha" && !has("alpha") && has("alpha_x") && has("alpha_y") {
                for axis in ["alpha_x", "alpha_y"] {
                    let decl = info.param(axis)?;
                    let v = parse_value(decl, value, depth).map_err(|e| rename(e, "alpha"))?;
                    self.params.0.insert(axis.to_string(), v);
                }
                continue;
            }
            let decl = info.param(key)?;
            let v = parse_value(decl, value, depth)?;
            self.params.0.insert(key.clone(), v);
        }
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
        let info = registry::find(&self.model)?;
        let key = if id == "alpha" && info.param("alpha").is_err() {
            "alpha_x"
        } else {
            id
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

    /// Sets one already-typed value after validating it (what the GUI calls).
    pub fn set(&mut self, id: &str, value: ParamValue) -> Result<()> {
        self.set_json(id, &value.to_json())
    }

    /// Builds the evaluator.
    pub fn build(&self) -> Result<Box<dyn crate::Brdf>> {
        let info = registry::find(&self.model)?;
        (info.build)(&self.params)
    }

    /// `{"model": …, "params": {…}}`.
    pub fn to_json(&self) -> Value {
        let mut m = Map::new();
        m.insert("model".into(), Value::String(self.model.clone()));
        m.insert("params".into(), self.params.to_json());
        Value::Object(m)
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
            .map_err(|_| bad(format!("`{s}` is not a number")))?;
        if !x.is_finite() {
            return Err(bad(format!("`{s}` is not a finite number")));
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
            other => Err(bad(format!("`{other}` is not true or false"))),
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
        reason: format!("expected a number, found {v}"),
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
            let s = v
                .as_str()
                .ok_or_else(|| bad(format!("expected one of {}, found {v}", options.join(", "))))?;
            if options.contains(&s) {
                Ok(ParamValue::Text(s.to_string()))
            } else {
                Err(bad(format!("`{s}` is not one of {}", options.join(", "))))
            }
        }
        ParamKind::Bool { .. } => v
            .as_bool()
            .map(ParamValue::Bool)
            .ok_or_else(|| bad(format!("expected true or false, found {v}"))),
        ParamKind::Path { .. } => v
            .as_str()
            .map(|s| ParamValue::Text(s.to_string()))
            .ok_or_else(|| bad(format!("expected a path string, found {v}"))),
        ParamKind::List {
            fields,
            min_items,
            max_items,
            ..
        } => {
            let items = v
                .as_array()
                .ok_or_else(|| bad(format!("expected a list, found {v}")))?;
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
                    p.0.insert(k.clone(), val);
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
            let items = v
                .as_array()
                .ok_or_else(|| bad(format!("expected a list of components, found {v}")))?;
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
    use serde_json::json;

    const DECLS: &[ParamDecl] = &[
        ParamDecl {
            id: "e",
            label: "e",
            doc: "exponent",
            kind: ParamKind::Float(FloatSpec::log(0.0, 10000.0, 20.0, 1.0, 1000.0)),
        },
        ParamDecl {
            id: "kd",
            label: "kd",
            doc: "diffuse",
            kind: ParamKind::Color(ColorSpec::unit_range([0.5; 3])),
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
