//! The vocabulary of parameter declarations: what kind of value a parameter
//! takes, its range, default and presentation hints. Every model declares its
//! parameters once, as a static list of [`ParamDecl`]; the CLI, scene files,
//! the GUI's sliders and the GPU layout all read that one list.

use super::value::{Component, ParamValue, Params};
use crate::model::FileFormat;

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
    /// A file a file-backed model reads (a MERL `.binary`), of a declared
    /// format.
    Path {
        /// Default path ("" for none).
        default: &'static str,
        /// How files of this parameter are read.
        format: &'static dyn FileFormat,
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
    /// When the value matters (the GUI hides a parameter that does not apply
    /// to the current choices, e.g. `k` while the Fresnel term is a
    /// dielectric's); values are accepted and kept either way.
    pub applies: Applies,
}

/// When a parameter's value affects the model.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Applies {
    /// Always.
    Always,
    /// Only while the choice parameter `param` of the same record has one of
    /// the values `any_of`.
    When {
        /// Id of a [`ParamKind::Choice`] parameter declared beside this one.
        param: &'static str,
        /// The choices under which this parameter matters.
        any_of: &'static [&'static str],
    },
    /// Only while the float parameter `param` of the same record is above 0
    /// (a lobe's option that matters only while the lobe has weight).
    Positive {
        /// Id of a [`ParamKind::Float`] parameter declared beside this one.
        param: &'static str,
    },
}

impl ParamDecl {
    /// The same declaration, mattering only while choice `param` is one of
    /// `any_of`.
    pub const fn applies_when(
        mut self,
        param: &'static str,
        any_of: &'static [&'static str],
    ) -> Self {
        self.applies = Applies::When { param, any_of };
        self
    }

    /// The condition in words (`fresnel is dielectric or conductor`), `None`
    /// for a parameter that always matters.
    pub fn applies_text(&self) -> Option<String> {
        match self.applies {
            Applies::Always => None,
            Applies::When { param, any_of } => Some(format!("{param} is {}", any_of.join(" or "))),
            Applies::Positive { param } => Some(format!("{param} > 0")),
        }
    }

    /// Whether the value matters for the record `values` (the parameters of
    /// one model, or of one list item). A condition naming a parameter the
    /// record does not hold as text counts as met, so that a declaration
    /// error never hides a control.
    pub fn applies_to(&self, values: &Params) -> bool {
        match self.applies {
            Applies::Always => true,
            Applies::When { param, any_of } => match values.get(param) {
                Ok(ParamValue::Text(v)) => any_of.contains(&v.as_str()),
                _ => true,
            },
            Applies::Positive { param } => match values.get(param) {
                Ok(ParamValue::Float(x)) => *x > 0.0,
                _ => true,
            },
        }
    }

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
            ParamKind::Path { default, .. } => ParamValue::Text(default.to_string()),
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::ModelSpec;

    /// Every condition of every built-in declaration (and of list items)
    /// names a choice parameter of the same record, and only values it offers.
    #[test]
    fn conditions_name_choices_of_their_record() {
        fn check(model: &str, decls: &[ParamDecl]) -> usize {
            let mut n = 0;
            for d in decls {
                if let ParamKind::List { fields, .. } = d.kind {
                    n += check(model, fields);
                }
                if let Applies::Positive { param } = d.applies {
                    let owner = decls.iter().find(|o| o.id == param);
                    assert!(
                        matches!(owner.map(|o| o.kind), Some(ParamKind::Float(_))),
                        "{model}: `{}` depends on `{param}` > 0, not a float beside it",
                        d.id
                    );
                    n += 1;
                    continue;
                }
                let Applies::When { param, any_of } = d.applies else {
                    continue;
                };
                let owner = decls.iter().find(|o| o.id == param);
                let Some(ParamKind::Choice { options, .. }) = owner.map(|o| o.kind) else {
                    panic!(
                        "{model}: `{}` depends on `{param}`, not a choice beside it",
                        d.id
                    );
                };
                assert!(!any_of.is_empty(), "{model}: `{}` never applies", d.id);
                for v in any_of {
                    assert!(
                        options.contains(v),
                        "{model}: `{}`: `{param}` has no `{v}`",
                        d.id
                    );
                }
                n += 1;
            }
            n
        }
        let n: usize = crate::catalogue()
            .iter()
            .map(|m| check(m.id, m.params))
            .sum();
        // eta, k and f0 of Cook-Torrance and of the mirror.
        assert!(n >= 6, "{n} conditions");
    }

    /// The Fresnel parameters follow the choice: eta for the exact terms, k
    /// for conductors only, f0 for Schlick only.
    #[test]
    fn fresnel_parameters_follow_the_choice() {
        let mut spec = ModelSpec::new("cook-torrance").unwrap();
        let shown = |spec: &ModelSpec| {
            ["eta", "k", "f0"].map(|id| spec.model().param(id).unwrap().applies_to(spec.params()))
        };
        for (choice, want) in [
            ("none", [false, false, false]),
            ("dielectric", [true, false, false]),
            ("conductor", [true, true, false]),
            ("schlick", [false, false, true]),
        ] {
            spec.set_str("fresnel", choice).unwrap();
            assert_eq!(shown(&spec), want, "fresnel = {choice}");
        }
        let k = spec.model().param("k").unwrap();
        assert_eq!(k.applies_text().as_deref(), Some("fresnel is conductor"));
        assert_eq!(spec.model().param("kd").unwrap().applies_text(), None);
    }
}
