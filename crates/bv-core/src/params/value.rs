//! Parameter values: one [`ParamValue`] per declared parameter, a complete
//! validated set ([`Params`]), and a model with its values ([`ModelSpec`]).
//! Values are validated when they are made (`super::spec`); these types keep
//! that invariant by not exposing their insides for mutation.

use super::decl::ParamDecl;
use crate::model::ModelInfo;
use crate::{BvError, Result};
use serde_json::{Map, Value};
use std::collections::BTreeMap;

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
                        m.insert("model".into(), Value::String(c.spec.id().to_string()));
                        m.insert("params".into(), c.spec.params().to_json());
                        Value::Object(m)
                    })
                    .collect(),
            ),
        }
    }
}

/// Parameter values keyed by parameter id: complete and validated when they
/// belong to a [`ModelSpec`], whose values change only through its
/// validating setters.
#[derive(Debug, Clone, PartialEq, Default)]
pub struct Params(BTreeMap<String, ParamValue>);

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

    /// Sets a value already validated against its declaration (this crate's
    /// parsers only: outside it values change through `ModelSpec::set`).
    pub(crate) fn insert(&mut self, id: String, value: ParamValue) {
        self.0.insert(id, value);
    }

    /// Sets a value without checking it against any declaration: for code
    /// that builds raw values to hand to a validating parser (tests,
    /// generators). A [`ModelSpec`]'s values cannot be changed this way.
    pub fn set_unvalidated(&mut self, id: &str, value: ParamValue) {
        self.0.insert(id.to_string(), value);
    }

    /// A value to edit in place (widgets editing a copy before handing it to
    /// a validating setter). A [`ModelSpec`]'s values are not reachable
    /// this way: it hands out only `&Params`.
    pub fn get_mut(&mut self, id: &str) -> Option<&mut ParamValue> {
        self.0.get_mut(id)
    }

    /// Every value by parameter id.
    pub fn iter(&self) -> impl Iterator<Item = (&str, &ParamValue)> {
        self.0.iter().map(|(k, v)| (k.as_str(), v))
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

/// A model with a full set of validated parameters: what the GUI holds, what
/// scene files store (by the model's id), and what [`ModelSpec::build`] turns
/// into an evaluator. Its fields are private: a spec is made by validating
/// values against its model's declaration (`ModelSpec::new`, `from_json`,
/// `set`), and cannot be changed around that validation.
#[derive(Debug, Clone)]
pub struct ModelSpec {
    info: &'static ModelInfo,
    params: Params,
}

impl PartialEq for ModelSpec {
    /// Same catalogue entry (a reloaded user model is a new entry) and the
    /// same values.
    fn eq(&self, other: &Self) -> bool {
        std::ptr::eq(self.info, other.info) && self.params == other.params
    }
}

impl ModelSpec {
    /// A spec of `info` with its declared defaults (cannot fail).
    pub fn defaults(info: &'static ModelInfo) -> Self {
        Self {
            info,
            params: Params::defaults(info.params),
        }
    }

    /// A spec from values already validated against `info`'s declaration.
    pub(crate) fn from_parts(info: &'static ModelInfo, params: Params) -> Self {
        Self { info, params }
    }

    /// The model.
    pub fn model(&self) -> &'static ModelInfo {
        self.info
    }

    /// The model's id.
    pub fn id(&self) -> &'static str {
        self.info.id
    }

    /// The parameter values (complete and validated).
    pub fn params(&self) -> &Params {
        &self.params
    }

    /// Mutable values, for the validating setters of this crate only.
    pub(crate) fn params_mut(&mut self) -> &mut Params {
        &mut self.params
    }

    /// Builds the evaluator.
    pub fn build(&self) -> Result<Box<dyn crate::Brdf>> {
        self.info.build.call(&self.params)
    }

    /// Rewrites every non-empty file path of the spec (mix components and
    /// list items included) with `f`: what a scene file does to make paths
    /// relative to its folder and back. A path has no range to leave, so the
    /// spec stays valid.
    pub fn map_paths(&mut self, f: &dyn Fn(&str) -> String) {
        fn walk(info: &'static ModelInfo, params: &mut Params, f: &dyn Fn(&str) -> String) {
            walk_decls(info.params, params, f);
        }
        fn walk_decls(decls: &[ParamDecl], params: &mut Params, f: &dyn Fn(&str) -> String) {
            for d in decls {
                match (&d.kind, params.0.get_mut(d.id)) {
                    (super::ParamKind::Path { .. }, Some(ParamValue::Text(t)))
                        if !t.trim().is_empty() =>
                    {
                        *t = f(t);
                    }
                    (super::ParamKind::List { fields, .. }, Some(ParamValue::List(items))) => {
                        for item in items {
                            walk_decls(fields, item, f);
                        }
                    }
                    (super::ParamKind::Components { .. }, Some(ParamValue::Components(cs))) => {
                        for c in cs {
                            walk(c.spec.info, &mut c.spec.params, f);
                        }
                    }
                    _ => {}
                }
            }
        }
        walk(self.info, &mut self.params, f);
    }

    /// `{"model": …, "params": {…}}`.
    pub fn to_json(&self) -> Value {
        let mut m = Map::new();
        m.insert("model".into(), Value::String(self.info.id.to_string()));
        m.insert("params".into(), self.params.to_json());
        Value::Object(m)
    }
}

pub(crate) fn json_number(x: f64) -> Value {
    serde_json::Number::from_f64(x).map_or(Value::Null, Value::Number)
}
