//! `bv eval`: evaluate f(wi, wo) for JSON Lines queries .
//!
//! Each non-blank line of stdin is one query
//! `{"model": "ward", "params": {...}, "wi": [x, y, z], "wo": [x, y, z]}`
//! and gets exactly one line on stdout, in order: `{"f": [r, g, b]}` or
//! `{"error": "..."}`. Blank lines are skipped and get no answer. The run goes
//! on after a bad query; the exit status is 1 if any query failed, 0 otherwise.

use super::output::{eprint, stdin_error, stdout_error};
use bv_core::{Brdf, ModelSpec, Rgb, frame};
use serde_json::{Map, Value};
use std::io::{self, BufRead, BufReader, BufWriter, IsTerminal, Read, Write};
use std::process::ExitCode;

/// The keys a query may have; any other key is refused (a typo such as
/// `"param"` would otherwise be silently ignored and evaluate the defaults).
const KEYS: [&str; 4] = ["model", "params", "wi", "wo"];

/// Longest accepted query line. A longer line is answered with an error
/// instead of being held in memory whole.
pub const MAX_LINE: usize = 1 << 20;

/// How much of an offending value an error message quotes.
const QUOTE_LEN: usize = 80;

/// Options of `bv eval` (it has none besides `--help`).
#[derive(Debug, Clone, clap::Args)]
#[command(
    long_about = "Evaluate f(wi, wo) for JSON Lines queries read from stdin.\n\n\
    One query per line:\n  \
    {\"model\": \"lambert\", \"params\": {\"albedo\": 0.5}, \"wi\": [0,0,1], \"wo\": [0.6,0,0.8]}\n\
    One answer per query, in order: {\"f\": [r, g, b]} (1/sr, no cosine factor) or \
    {\"error\": \"...\"}. `params` may be omitted (defaults); a colour may be a \
    number (grey) or [r, g, b]; `alpha` sets alpha_x = alpha_y. Directions are \
    normalised when within 1e-3 of unit length and refused otherwise. Blank \
    lines are skipped. Exit status 1 if any query failed, 0 otherwise."
)]
pub struct EvalArgs {}

/// Runs `bv eval` on the process's stdin and stdout.
pub fn run(_args: &EvalArgs) -> anyhow::Result<ExitCode> {
    let stdin = io::stdin();
    if stdin.is_terminal() {
        eprint("bv eval: reading JSON Lines queries from stdin (end with Ctrl-D)\n");
    }
    let stdout = io::stdout();
    // On a terminal every answer is shown at once; in a pipe answers are
    // buffered but still flushed whenever the input runs dry (see `eval_stream`).
    let flush_each = stdout.is_terminal();
    let input = BufReader::with_capacity(64 * 1024, stdin.lock());
    let mut out = BufWriter::with_capacity(64 * 1024, stdout.lock());
    let summary = eval_stream(input, &mut out, flush_each)?;
    if summary.failed > 0 {
        eprint(&format!(
            "bv eval: {} of {} queries failed\n",
            summary.failed, summary.answered
        ));
        Ok(ExitCode::from(1))
    } else {
        Ok(ExitCode::SUCCESS)
    }
}

/// Counts of one `eval` run.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub struct Summary {
    /// Queries answered (blank lines excluded).
    pub answered: usize,
    /// Queries answered with an error.
    pub failed: usize,
}

/// Answers every query of `input` on `out`, one line each.
///
/// Streams: a line is answered before the next one is read. Answers are
/// buffered for speed, and flushed whenever `input` has no buffered bytes left
/// (the next read may block, so a program that writes one query and waits for
/// its answer is not left waiting), after every line when `flush_each`, and at
/// the end. Only I/O errors end the run early (reported as a failed read of
/// stdin or write of stdout).
pub fn eval_stream<R: Read, W: Write>(
    mut input: BufReader<R>,
    out: &mut W,
    flush_each: bool,
) -> anyhow::Result<Summary> {
    let mut evaluator = Evaluator::default();
    let mut summary = Summary::default();
    let mut line = Vec::new();
    let mut lines_read = 0usize;
    loop {
        if input.buffer().is_empty() {
            out.flush().map_err(stdout_error)?;
        }
        let read = read_line_limited(&mut input, &mut line).map_err(stdin_error)?;
        lines_read += 1;
        let answer = match read {
            Line::End => break,
            Line::TooLong => Err(format!("query line longer than {MAX_LINE} bytes; refused")),
            Line::Complete => match std::str::from_utf8(&line) {
                Err(e) => Err(format!("query line is not valid UTF-8 ({e})")),
                Ok(text) => {
                    // A byte-order mark some editors put at the start of a file.
                    let text = if lines_read == 1 {
                        text.trim_start_matches('\u{feff}')
                    } else {
                        text
                    };
                    if text.trim().is_empty() {
                        continue;
                    }
                    evaluator.answer(text)
                }
            },
        };
        summary.answered += 1;
        let json = match answer {
            Ok(f) => serde_json::json!({ "f": [f.x, f.y, f.z] }),
            Err(msg) => {
                summary.failed += 1;
                serde_json::json!({ "error": msg })
            }
        };
        serde_json::to_writer(&mut *out, &json)
            .map_err(io::Error::from)
            .and_then(|()| out.write_all(b"\n"))
            .and_then(|()| if flush_each { out.flush() } else { Ok(()) })
            .map_err(stdout_error)?;
    }
    out.flush().map_err(stdout_error)?;
    Ok(summary)
}

/// What [`read_line_limited`] found.
enum Line {
    /// A line (without its terminator) is in the buffer.
    Complete,
    /// The line was longer than [`MAX_LINE`]; it has been skipped.
    TooLong,
    /// End of input.
    End,
}

/// Reads one line into `buf` (terminator and a trailing `\r` removed), holding
/// at most [`MAX_LINE`] bytes of it; the rest of a longer line is skipped.
fn read_line_limited<R: BufRead>(input: &mut R, buf: &mut Vec<u8>) -> io::Result<Line> {
    buf.clear();
    let n = input
        .by_ref()
        .take(MAX_LINE as u64 + 1)
        .read_until(b'\n', buf)?;
    if n == 0 {
        return Ok(Line::End);
    }
    if buf.last() == Some(&b'\n') {
        buf.pop();
        if buf.last() == Some(&b'\r') {
            buf.pop();
        }
        return Ok(Line::Complete);
    }
    if buf.len() <= MAX_LINE {
        // The last line of the input, without a terminator.
        return Ok(Line::Complete);
    }
    // Skip the rest of the over-long line without keeping it.
    buf.clear();
    loop {
        let chunk = input.fill_buf()?;
        if chunk.is_empty() {
            break;
        }
        if let Some(i) = chunk.iter().position(|&b| b == b'\n') {
            input.consume(i + 1);
            break;
        }
        let len = chunk.len();
        input.consume(len);
    }
    Ok(Line::TooLong)
}

/// Answers queries, keeping the last model built: consecutive queries with the
/// same model and parameters (the usual case: a sweep over directions) reuse
/// it, since building can be costly (normalisation integrals, measured data).
#[derive(Debug, Default)]
pub struct Evaluator {
    /// The last build, if any.
    cache: Option<Built>,
}

/// One model build: its key (model id and raw `params`) and what it gave.
#[derive(Debug)]
struct Built {
    model: String,
    params: Value,
    result: Result<Box<dyn Brdf>, String>,
}

impl Evaluator {
    /// Answers one query line: `f(wi, wo)` or a message saying what is wrong.
    pub fn answer(&mut self, line: &str) -> Result<Rgb, String> {
        // Duplicate keys are refused: JSON leaves them undefined, and
        // silently taking the last `wi` evaluates something else than asked.
        let StrictValue(v) =
            serde_json::from_str(line).map_err(|e| format!("invalid JSON: {e}"))?;
        let Value::Object(obj) = v else {
            return Err(format!(
                "a query must be a JSON object {{\"model\", \"params\", \"wi\", \"wo\"}}, found {}",
                quote(&v)
            ));
        };
        if let Some(k) = obj.keys().find(|k| !KEYS.contains(&k.as_str())) {
            return Err(format!(
                "unknown key `{k}` in query (keys: {})",
                KEYS.join(", ")
            ));
        }
        let model = match obj.get("model") {
            Some(Value::String(s)) => s.as_str(),
            Some(other) => {
                return Err(format!(
                    "`model` must be a model id string, found {}",
                    quote(other)
                ));
            }
            None => return Err("missing `model` (a model id, see `bv models`)".to_string()),
        };
        let params = obj.get("params").unwrap_or(&Value::Null);
        let wi = direction(&obj, "wi")?;
        let wo = direction(&obj, "wo")?;
        let brdf = self.model(model, params)?;
        // A failed evaluation (a user's shader past its step budget) is this
        // query's error, not a 0.
        let f = brdf.try_eval(wi, wo).map_err(|e| e.to_string())?;
        if !f.is_finite() {
            return Err(format!(
                "model `{model}` gave a non-finite value {f} at wi = {wi}, wo = {wo}"
            ));
        }
        Ok(f)
    }

    /// The evaluator for `model` with `params`, built unless it is the last one.
    fn model(&mut self, model: &str, params: &Value) -> Result<&dyn Brdf, String> {
        let hit = matches!(&self.cache, Some(b) if b.model == model && &b.params == params);
        if !hit {
            let result = ModelSpec::from_json(model, params)
                .and_then(|spec| spec.build())
                .map_err(|e| e.to_string());
            self.cache = Some(Built {
                model: model.to_string(),
                params: params.clone(),
                result,
            });
        }
        match self.cache.as_ref().map(|b| &b.result) {
            Some(Ok(b)) => Ok(b.as_ref()),
            Some(Err(e)) => Err(e.clone()),
            None => Err("internal error: no model".to_string()),
        }
    }
}

/// The direction `name` of a query, checked by the core (finite, unit length
/// within 1e-3, then normalised).
fn direction(obj: &Map<String, Value>, name: &str) -> Result<glam::DVec3, String> {
    let v = obj
        .get(name)
        .ok_or_else(|| format!("missing `{name}` (a direction [x, y, z])"))?;
    let bad = || {
        format!(
            "`{name}` must be [x, y, z] of 3 numbers, found {}",
            quote(v)
        )
    };
    let items = v.as_array().filter(|a| a.len() == 3).ok_or_else(bad)?;
    let mut xyz = [0.0; 3];
    for (x, item) in xyz.iter_mut().zip(items) {
        *x = item.as_f64().ok_or_else(bad)?;
    }
    frame::checked_direction(name, xyz).map_err(|e| e.to_string())
}

/// A JSON value parsed with every object's keys unique (serde_json's own
/// `Value` keeps the last of repeated keys without a word).
struct StrictValue(Value);

impl<'de> serde::Deserialize<'de> for StrictValue {
    fn deserialize<D: serde::Deserializer<'de>>(d: D) -> Result<Self, D::Error> {
        d.deserialize_any(StrictVisitor).map(StrictValue)
    }
}

struct StrictVisitor;

impl<'de> serde::de::Visitor<'de> for StrictVisitor {
    type Value = Value;

    fn expecting(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        f.write_str("a JSON value")
    }
    fn visit_bool<E>(self, v: bool) -> Result<Value, E> {
        Ok(Value::Bool(v))
    }
    fn visit_i64<E>(self, v: i64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_u64<E>(self, v: u64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_f64<E>(self, v: f64) -> Result<Value, E> {
        Ok(Value::from(v))
    }
    fn visit_str<E>(self, v: &str) -> Result<Value, E> {
        Ok(Value::String(v.to_string()))
    }
    fn visit_string<E>(self, v: String) -> Result<Value, E> {
        Ok(Value::String(v))
    }
    fn visit_unit<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_none<E>(self) -> Result<Value, E> {
        Ok(Value::Null)
    }
    fn visit_seq<A: serde::de::SeqAccess<'de>>(self, mut seq: A) -> Result<Value, A::Error> {
        let mut items = Vec::new();
        while let Some(StrictValue(v)) = seq.next_element()? {
            items.push(v);
        }
        Ok(Value::Array(items))
    }
    fn visit_map<A: serde::de::MapAccess<'de>>(self, mut map: A) -> Result<Value, A::Error> {
        let mut out = Map::new();
        while let Some(key) = map.next_key::<String>()? {
            if out.contains_key(&key) {
                return Err(serde::de::Error::custom(format!(
                    "duplicate key `{}`",
                    quote(&Value::String(key)).trim_matches('"')
                )));
            }
            let StrictValue(v) = map.next_value()?;
            out.insert(key, v);
        }
        Ok(Value::Object(out))
    }
}

/// A JSON value for an error message, cut short if it is long.
fn quote(v: &Value) -> String {
    let s = v.to_string();
    if s.chars().count() <= QUOTE_LEN {
        s
    } else {
        let cut: String = s.chars().take(QUOTE_LEN).collect();
        format!("{cut}…")
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn run_text(input: &str) -> (Vec<Value>, Summary) {
        let mut out = Vec::new();
        let s = eval_stream(BufReader::new(input.as_bytes()), &mut out, false).unwrap();
        let lines = String::from_utf8(out)
            .unwrap()
            .lines()
            .map(|l| serde_json::from_str(l).unwrap())
            .collect();
        (lines, s)
    }

    #[test]
    fn lambert_value_is_albedo_over_pi() {
        let (out, s) = run_text(
            r#"{"model": "lambert", "params": {"albedo": 0.5}, "wi": [0,0,1], "wo": [0.6,0,0.8]}"#,
        );
        assert_eq!(
            s,
            Summary {
                answered: 1,
                failed: 0
            }
        );
        let f = out[0]["f"].as_array().unwrap();
        for c in f {
            // 0.5/π to the last bits (Lambert multiplies by a rounded 1/π).
            assert!((c.as_f64().unwrap() - 0.5 / std::f64::consts::PI).abs() < 1e-16);
        }
    }

    #[test]
    fn blank_lines_crlf_and_missing_final_newline() {
        let q = r#"{"model":"lambert","wi":[0,0,1],"wo":[0,0,1]}"#;
        let (out, s) = run_text(&format!("\u{feff}{q}\r\n\n   \n{q}\r\n{q}"));
        assert_eq!(
            s,
            Summary {
                answered: 3,
                failed: 0
            }
        );
        assert_eq!(out.len(), 3);
        // Defaults apply when `params` is absent: albedo 0.5.
        assert!((out[0]["f"][1].as_f64().unwrap() - 0.5 / std::f64::consts::PI).abs() < 1e-16);
    }

    #[test]
    fn every_bad_query_gets_its_own_error() {
        let cases = [
            ("not json", "invalid JSON"),
            ("[1, 2]", "must be a JSON object"),
            (r#"{"model":"lambert","wi":[0,0,1]}"#, "missing `wo`"),
            (r#"{"wi":[0,0,1],"wo":[0,0,1]}"#, "missing `model`"),
            (
                r#"{"model":3,"wi":[0,0,1],"wo":[0,0,1]}"#,
                "`model` must be",
            ),
            (
                r#"{"model":"lambert","param":{},"wi":[0,0,1],"wo":[0,0,1]}"#,
                "unknown key `param`",
            ),
            (
                r#"{"model":"nope","wi":[0,0,1],"wo":[0,0,1]}"#,
                "unknown model `nope`",
            ),
            (
                r#"{"model":"lambert","params":{"rho":1},"wi":[0,0,1],"wo":[0,0,1]}"#,
                "no parameter `rho`",
            ),
            (
                r#"{"model":"lambert","params":{"albedo":1.5},"wi":[0,0,1],"wo":[0,0,1]}"#,
                "out of range",
            ),
            (
                r#"{"model":"lambert","wi":[0,0,2],"wo":[0,0,1]}"#,
                "bad direction `wi`",
            ),
            (
                r#"{"model":"lambert","wi":[0,0,1],"wo":[0,1]}"#,
                "`wo` must be [x, y, z]",
            ),
            (
                r#"{"model":"lambert","wi":[0,0,"1"],"wo":[0,0,1]}"#,
                "`wi` must be",
            ),
            (
                r#"{"model":"lambert","wi":[0,0,1],"wo":[0,0,1],"wi":[1,0,0]}"#,
                "duplicate key `wi`",
            ),
            (
                r#"{"model":"lambert","params":{"albedo":0.1,"albedo":0.9},"wi":[0,0,1],"wo":[0,0,1]}"#,
                "duplicate key `albedo`",
            ),
        ];
        let good = r#"{"model":"lambert","wi":[0,0,1],"wo":[0,0,1]}"#;
        let mut input = String::new();
        for (q, _) in &cases {
            input.push_str(q);
            input.push('\n');
            input.push_str(good);
            input.push('\n');
        }
        let (out, s) = run_text(&input);
        assert_eq!(s.answered, 2 * cases.len());
        assert_eq!(s.failed, cases.len());
        for (i, (q, want)) in cases.iter().enumerate() {
            let err = out[2 * i]["error"]
                .as_str()
                .unwrap_or_else(|| panic!("{q}"));
            assert!(err.contains(want), "{q}: {err}");
            assert!(out[2 * i + 1]["f"].is_array(), "good line after {q}");
        }
    }

    #[test]
    fn over_long_line_is_refused_and_skipped() {
        let good = r#"{"model":"lambert","wi":[0,0,1],"wo":[0,0,1]}"#;
        let long = "x".repeat(MAX_LINE + 10);
        let (out, s) = run_text(&format!("{long}\n{good}\n"));
        assert_eq!(
            s,
            Summary {
                answered: 2,
                failed: 1
            }
        );
        assert!(out[0]["error"].as_str().unwrap().contains("longer than"));
        assert!(out[1]["f"].is_array());
    }

    #[test]
    fn cache_is_keyed_on_model_and_params() {
        let mut e = Evaluator::default();
        let q = |albedo: f64| {
            format!(
                r#"{{"model":"lambert","params":{{"albedo":{albedo}}},"wi":[0,0,1],"wo":[0,0,1]}}"#
            )
        };
        let a = e.answer(&q(0.2)).unwrap();
        let b = e.answer(&q(0.4)).unwrap();
        let c = e.answer(&q(0.4)).unwrap();
        assert_eq!(b, 2.0 * a);
        assert_eq!(b, c);
        // A failed build is remembered for the same key and forgotten for another.
        assert!(e.answer(&q(3.0)).is_err());
        assert!(e.answer(&q(3.0)).is_err());
        assert_eq!(e.answer(&q(0.2)).unwrap(), a);
    }
}
