//! Error type of the core: every failure a user or a file can cause is one of these.

use thiserror::Error;

/// Everything that can go wrong when building or evaluating a model, parsing
/// parameters or reading measured data.
#[derive(Debug, Error, Clone, PartialEq)]
pub enum BvError {
    /// The model id is not in the catalogue.
    #[error("unknown model `{}` (known models: {known})", quote(.id))]
    UnknownModel {
        /// The id that was asked for.
        id: String,
        /// Comma-separated list of known ids.
        known: String,
    },
    /// A parameter name that the model does not declare.
    #[error(
        "model `{model}` has no parameter `{}` (its parameters: {known})",
        quote(.param)
    )]
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
        "parameter `{}` = {} is out of range [{}, {}]",
        quote(.param),
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
    #[error("parameter `{}`: {reason}", quote(.param))]
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

/// Most characters of a user's input that a message quotes.
pub const QUOTE_CHARS: usize = 60;

/// `text` as a message quotes it: whole when it is short, else its first
/// [`QUOTE_CHARS`] characters, `…` and its size (`aaaa… (102400 bytes)`), so
/// that a mistyped 100 KB value is not echoed back whole (a terminal, a log
/// or a status line has no room for it, and the start says which it was).
pub fn quote(text: &str) -> std::borrow::Cow<'_, str> {
    match text.char_indices().nth(QUOTE_CHARS) {
        None => std::borrow::Cow::Borrowed(text),
        Some((cut, _)) => format!("{}… ({} bytes)", &text[..cut], text.len()).into(),
    }
}

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
    fn long_input_is_quoted_short() {
        assert_eq!(quote("alpha"), "alpha");
        let exact = "x".repeat(QUOTE_CHARS);
        assert_eq!(quote(&exact), exact);
        let long = "é".repeat(100_000);
        let q = quote(&long);
        assert_eq!(q, format!("{}… (200000 bytes)", "é".repeat(QUOTE_CHARS)));
        let e = BvError::UnknownParam {
            model: "lambert".into(),
            param: "p".repeat(100_000),
            known: "albedo".into(),
        }
        .to_string();
        assert!(e.len() < 200 && e.contains("(100000 bytes)"), "{e}");
    }

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
