//! Writing results to stdout and messages to stderr, without panicking:
//! `println!` and `eprintln!` panic when the stream cannot be written
//! (`bv info F > /dev/full`, `bv eval 2>/dev/full`). Results go through
//! [`print()`], which returns a [`StreamError`] that `main` reports with exit
//! status 1; messages go through [`eprint()`], best effort (if stderr itself
//! is gone there is nobody to tell). The command line and the window share
//! them.

use std::io::{self, Write};

/// A read or write of a standard stream that failed.
#[derive(Debug)]
pub struct StreamError {
    /// What was being done: "write to stdout", "read stdin".
    pub action: &'static str,
    /// What the system said.
    pub error: io::Error,
}

impl std::fmt::Display for StreamError {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "cannot {}: {}", self.action, self.error)
    }
}

// No `source()`: the message already holds the system's text, and `main`
// prints the whole chain.
impl std::error::Error for StreamError {}

/// `e`, from writing stdout, as the error `main` reports.
pub fn stdout_error(e: io::Error) -> anyhow::Error {
    StreamError {
        action: "write to stdout",
        error: e,
    }
    .into()
}

/// Writes `text` to stdout in one go and flushes it.
pub fn print(text: &str) -> anyhow::Result<()> {
    let mut out = io::stdout().lock();
    out.write_all(text.as_bytes())
        .and_then(|()| out.flush())
        .map_err(stdout_error)
}

/// Writes `text` to stderr, best effort: a message that cannot be shown is
/// dropped (never a panic).
pub fn eprint(text: &str) {
    let mut err = io::stderr().lock();
    let _ = err.write_all(text.as_bytes());
    let _ = err.flush();
}

/// `bv: warning: {msg}` on stderr, best effort.
pub fn warn(msg: &str) {
    eprint(&format!("bv: warning: {msg}\n"));
}
