//! Error type of the core: every failure a user or a file can cause is one of these.

use thiserror::Error;

/// Everything that can go wrong when building or evaluating a model, parsing
/// parameters or reading measured data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BvError {
    /// The model id is not in the catalogue.
    #[error("unknown model `{id}` (known models: {known})")]
    UnknownModel {
        /// The id that was asked for.
        id: String,
        /// Comma-separated list of known ids.
        known: String,
    },
    /// A parameter name that the model does not declare.
    #[error("model `{model}` has no parameter `{param}` (its parameters: {known})")]
    UnknownParam {
        /// Model id.
        model: String,
        /// The parameter name that was given.
        param: String,
        /// Comma-separated list of declared parameter names.
        known: String,
    },
    /// A numeric value outside the declared range.
    #[error(
        "parameter `{param}` = {} is out of range [{}, {}]",
        fmt_num(*.value),
        fmt_num(*.min),
        fmt_num(*.max)
    )]
    OutOfRange {
        /// Parameter name.
        param: String,
        /// The offending value.
        value: f64,
        /// Smallest accepted value.
        min: f64,
        /// Largest accepted value.
        max: f64,
    },
    /// A value of the wrong shape (e.g. text for a number, four colour channels).
    #[error("parameter `{param}`: {reason}")]
    BadValue {
        /// Parameter name.
        param: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A direction that is not finite or not of unit length.
    #[error("bad direction `{name}`: {reason}")]
    BadDirection {
        /// `wi` or `wo`.
        name: String,
        /// What is wrong with it.
        reason: String,
    },
    /// A malformed request that is not about one parameter.
    #[error("{0}")]
    Invalid(String),
    /// A measured-data or scene file that cannot be read.
    #[error("{path}: {reason}")]
    File {
        /// The file's path as given.
        path: String,
        /// What is wrong with it.
        reason: String,
    },
}

/// Result alias used across the core.
pub type Result<T, E = BvError> = std::result::Result<T, E>;

/// A number for messages: the shortest digits that read back as `x`, in
/// exponent form when very large or very small (`1e300`, not 301 digits).
pub fn fmt_num(x: f64) -> String {
    let a = x.abs();
    if x == 0.0 || !x.is_finite() || (1e-5..1e16).contains(&a) {
        format!("{x}")
    } else {
        format!("{x:e}")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn numbers_in_messages_are_short() {
        assert_eq!(fmt_num(0.25), "0.25");
        assert_eq!(fmt_num(2.0), "2");
        assert_eq!(fmt_num(1e300), "1e300");
        assert_eq!(fmt_num(-1e-300), "-1e-300");
        assert_eq!(fmt_num(f64::NAN), "NaN");
        let e = BvError::OutOfRange {
            param: "albedo".into(),
            value: 1e300,
            min: 0.0,
            max: 1.0,
        };
        assert_eq!(
            e.to_string(),
            "parameter `albedo` = 1e300 is out of range [0, 1]"
        );
    }
}
