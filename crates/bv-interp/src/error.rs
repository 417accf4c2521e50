//! What can go wrong when a module is prepared or a function is called.

/// An error from preparing a module ([`crate::Program::new`]) or running one of
/// its functions ([`crate::Program::call`]). Messages are meant for the person
/// who wrote the shader.
#[derive(Debug, Clone, PartialEq, Eq, thiserror::Error)]
pub enum InterpError {
    /// The module uses something the CPU interpreter cannot evaluate.
    #[error("`{function}` uses {what}, which the CPU interpreter does not support")]
    Unsupported {
        /// The feature (e.g. "texture sampling", "64-bit integers").
        what: String,
        /// Where it is used: a function name, or "module scope".
        function: String,
    },
    /// The call ran more statements and expressions than its limit allows
    /// (an endless or very long loop).
    #[error("the shader ran more than {steps} steps (an endless or very long loop?)")]
    StepBudget {
        /// The limit that was reached.
        steps: u64,
    },
    /// Calls nested deeper than the limit.
    #[error("function calls nested deeper than {depth}")]
    CallDepth {
        /// The limit that was reached.
        depth: u32,
    },
    /// The call's variables need more memory than the limit allows.
    #[error(
        "the shader needs {bytes} bytes for its variables and intermediate values in one \
         evaluation; the limit is {limit} bytes"
    )]
    Memory {
        /// The bytes the call would have needed at that point.
        bytes: usize,
        /// The limit it ran into.
        limit: usize,
    },
    /// A value given to the interpreter does not have the type the shader
    /// declares.
    #[error("{what}: expected {expected}, got {found}")]
    Type {
        /// Which value (an argument, a global).
        what: String,
        /// The type the shader declares.
        expected: String,
        /// What was given.
        found: String,
    },
    /// No callable (non-entry-point) function has this name.
    #[error("the shader has no function named `{0}`")]
    UnknownFunction(String),
    /// No settable module-scope variable has this name.
    #[error("the shader has no module-scope variable named `{0}`")]
    UnknownGlobal(String),
    /// The module failed naga's validation.
    #[error("the shader is invalid: {0}")]
    Invalid(String),
    /// The shader executed `discard` (a fragment kill), which has no meaning
    /// for a BRDF evaluated on the CPU.
    #[error("the shader executed `discard`")]
    Kill,
    /// A bug in the interpreter (it was caught instead of crashing).
    #[error("internal interpreter error: {0}")]
    Internal(String),
}

impl InterpError {
    /// An [`InterpError::Unsupported`] for `what` in `function`.
    pub(crate) fn unsupported(what: impl Into<String>, function: &str) -> Self {
        InterpError::Unsupported {
            what: what.into(),
            function: function.to_string(),
        }
    }
}
