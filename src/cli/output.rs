//! Writing results to stdout and messages to stderr, without panicking.
//!
//! `println!` and `eprintln!` panic when the stream cannot be written
//! (`bv info F > /dev/full`, `bv eval 2>/dev/full`). Results go through
//! [`print()`], which returns a [`StreamError`] that `main` reports as
//! `bv: cannot write to stdout: No space left on device (os error 28)` with
//! exit status 1; messages go through [`eprint()`], best effort (if stderr
//! itself is gone there is nobody to tell). A closed pipe (`bv models |
//! head`) is a quiet exit ([`is_broken_pipe`]).

use std::io;

pub use crate::session::console::{StreamError, eprint, print, stdout_error, warn};

/// What `--out FILE` does with what is already there (every command that
/// writes a file goes through `bv_core::fsio::write_atomic`).
pub const OUT_HELP: &str = "Output file, written atomically (a temporary file beside it, then \
renamed over it: a failed write leaves the old file whole). A symbolic link is written \
through to its target, which must exist; a directory, FIFO, socket, device or read-only \
file is refused; a replaced file keeps its permissions. Missing folders are not created.";

/// `e`, from reading stdin, as the error `main` reports.
pub fn stdin_error(e: io::Error) -> anyhow::Error {
    StreamError {
        action: "read stdin",
        error: e,
    }
    .into()
}

/// Whether `e` (or anything in its chain) is a write to a closed pipe: the
/// reader went away (`bv models | head`), so there is nobody left to tell.
pub fn is_broken_pipe(e: &anyhow::Error) -> bool {
    e.chain().any(|c| {
        let kind = c
            .downcast_ref::<io::Error>()
            .map(io::Error::kind)
            .or_else(|| c.downcast_ref::<StreamError>().map(|s| s.error.kind()));
        kind == Some(io::ErrorKind::BrokenPipe)
    })
}

/// The message of `e` with its causes, as `main` prints it: each layer of
/// the chain adds only what the layers before it have not said. A context
/// that names a file followed by an error that starts with the same name
/// (`x.toml` then `x.toml: Is a directory`) shows the name once; a cause
/// whose text is already in the message (a system error quoted by the
/// layer above) is left out.
pub fn message(e: &anyhow::Error) -> String {
    let mut out = String::new();
    for layer in e.chain() {
        let mut text = layer.to_string();
        if text.is_empty() || out.contains(&text) {
            continue;
        }
        // Drop leading `prefix: ` parts already said (a path named twice).
        while let Some((head, rest)) = text.split_once(": ") {
            if contains_token(&out, head) {
                text = rest.to_string();
            } else {
                break;
            }
        }
        if out.contains(&text) {
            continue;
        }
        if !out.is_empty() {
            out.push_str(": ");
        }
        out.push_str(&text);
    }
    out
}

/// Whether `needle` occurs in `hay` as a whole word: between the ends, spaces
/// or a `:` (so that a path `x` is not found inside `x.toml`).
fn contains_token(hay: &str, needle: &str) -> bool {
    if needle.is_empty() {
        return false;
    }
    hay.match_indices(needle).any(|(i, _)| {
        let before = hay[..i].chars().next_back();
        let after = hay[i + needle.len()..].chars().next();
        before.is_none_or(|c| c == ' ') && after.is_none_or(|c| c == ' ' || c == ':')
    })
}

/// A number as JSON, or `null` when it is not finite (JSON has no NaN or inf).
pub fn json_f64(x: f64) -> serde_json::Value {
    serde_json::Number::from_f64(x).map_or(serde_json::Value::Null, serde_json::Value::Number)
}

#[cfg(test)]
mod tests {
    use super::*;
    use anyhow::Context as _;

    #[test]
    fn each_layer_adds_only_news() {
        let io = io::Error::from_raw_os_error(21);
        let inner = anyhow::Error::new(io).context("dir.toml: Is a directory (os error 21)");
        let e = inner.context("dir.toml");
        assert_eq!(message(&e), "dir.toml: Is a directory (os error 21)");
        let e: anyhow::Result<()> =
            Err(anyhow::anyhow!("x.toml: bad value")).context("--scene x.toml");
        assert_eq!(message(&e.unwrap_err()), "--scene x.toml: bad value");
        let e = anyhow::anyhow!("no parameter `alpha`").context("--param alpha=0.1");
        assert_eq!(message(&e), "--param alpha=0.1: no parameter `alpha`");
        // `x` is not the `x.toml` said before.
        let e = anyhow::anyhow!("x: gone").context("x.toml");
        assert_eq!(message(&e), "x.toml: x: gone");
    }

    #[test]
    fn stream_errors_read_as_one_sentence() {
        let e = stdout_error(io::Error::from_raw_os_error(28));
        assert_eq!(
            message(&e),
            "cannot write to stdout: No space left on device (os error 28)"
        );
        assert!(!is_broken_pipe(&e));
        assert!(is_broken_pipe(&stdout_error(
            io::ErrorKind::BrokenPipe.into()
        )));
    }
}
