//! Errors of a user BRDF file, placed at the user's file, line and column.

use std::fmt;

/// Where in the user's file something went wrong (1-based).
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Place {
    /// The file as the user named it (or `<text>` for text compiled directly).
    pub file: String,
    /// 1-based line in the user's file.
    pub line: usize,
    /// 1-based column.
    pub column: usize,
}

impl fmt::Display for Place {
    fn fmt(&self, f: &mut fmt::Formatter<'_>) -> fmt::Result {
        write!(f, "{}:{}:{}", self.file, self.line, self.column)
    }
}

/// Why a user file cannot be used.
#[derive(Debug, Clone, thiserror::Error)]
pub enum UserError {
    /// The file could not be read.
    #[error("{file}: {reason}")]
    Read {
        /// The file.
        file: String,
        /// What the system said.
        reason: String,
    },
    /// The container (sections, parameter lines) is malformed; bv-core's
    /// parser says where.
    #[error("{file}: {reason}")]
    Container {
        /// The file.
        file: String,
        /// The parser's message (it starts with the line and column).
        reason: String,
    },
    /// The shader does not compile, or is refused for safety, at a place.
    #[error("{place}: {reason}")]
    Compile {
        /// Where (the first place the compiler named).
        place: Place,
        /// The compiler's message.
        reason: String,
    },
    /// The shader compiled but the file as a whole is unusable (no BRDF
    /// function, a wrong signature, a limit exceeded) and no single place is
    /// to blame.
    #[error("{file}: {reason}")]
    Model {
        /// The file.
        file: String,
        /// What is wrong.
        reason: String,
    },
}

impl UserError {
    /// The place of a compile error, if the error has one.
    pub fn place(&self) -> Option<&Place> {
        match self {
            UserError::Compile { place, .. } => Some(place),
            _ => None,
        }
    }
}

impl From<UserError> for bv_core::BvError {
    fn from(e: UserError) -> Self {
        bv_core::BvError::Invalid(e.to_string())
    }
}

/// A result with a [`UserError`].
pub type Result<T, E = UserError> = std::result::Result<T, E>;
