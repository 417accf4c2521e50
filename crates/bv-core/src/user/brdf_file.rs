//! The `.brdf` container of Disney's BRDF Explorer (Burley's `src/brdfs/`
//! files), read unchanged, plus bv's native variant with a WGSL section.
//!
//! ```text
//! analytic
//! # comments start with '#'
//! ::begin parameters
//! float n 1 1000 100     # a trailing comment is the tooltip
//! bool normalized 1
//! color Kd 0.5 0.5 0.5
//! ::end parameters
//! ::begin shader
//! vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { … }
//! ::end shader
//! ::begin isFunc         (optional: a sampling function)
//! ::end isFunc
//! ```
//!
//! The first line that is not blank or a comment must be `analytic`
//! (Explorer's "measured" and "image" types are not supported). Sections may
//! come in any order; `parameters` is optional, and exactly one of `shader`
//! (GLSL) and `wgsl` (bv's native variant: a
//! `fn brdf(wi: vec3f, wo: vec3f, n: vec3f, x: vec3f, y: vec3f) -> vec3f`)
//! must be present. Section text is kept verbatim with the line number it
//! starts on, so that a compiler's error can be reported at the user's line.
//!
//! Everything a hostile file could make large is bounded: the file size
//! ([`MAX_FILE_BYTES`]), the number of parameters ([`MAX_PARAMS`]) and the
//! length of a parameter name.

use crate::params::decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
use crate::{BvError, Result};

/// Largest `.brdf` file read (the shipped files are a few kB).
pub const MAX_FILE_BYTES: usize = 1 << 20;

/// Most parameters one file may declare.
pub const MAX_PARAMS: usize = 256;

/// Longest parameter name.
pub const MAX_NAME: usize = 64;

/// A section's text and where it starts.
#[derive(Debug, Clone, PartialEq, Eq)]
pub struct Section {
    /// The lines between `::begin` and `::end`, verbatim, joined with `\n`.
    pub text: String,
    /// 1-based line number of the section's first text line in the file.
    pub first_line: usize,
}

/// What kind of value a file parameter takes, with its range and default.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum FileParamKind {
    /// `float NAME MIN MAX DEFAULT`.
    Float {
        /// Smallest value.
        min: f64,
        /// Largest value.
        max: f64,
        /// Default value.
        default: f64,
    },
    /// `bool NAME 0|1`.
    Bool {
        /// Default value.
        default: bool,
    },
    /// `color NAME R G B`.
    Color {
        /// Default colour.
        default: [f64; 3],
    },
}

/// One declared parameter of a `.brdf` file.
#[derive(Debug, Clone, PartialEq)]
pub struct FileParam {
    /// The name the shader uses.
    pub name: String,
    /// Kind, range, default.
    pub kind: FileParamKind,
    /// The trailing comment of its line, if any.
    pub tooltip: Option<String>,
    /// 1-based line number.
    pub line: usize,
}

/// Which language the model's function is written in.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Language {
    /// GLSL: `vec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y)`.
    Glsl,
    /// WGSL: `fn brdf(wi, wo, n, x, y) -> vec3f`.
    Wgsl,
}

/// A parsed `.brdf` file.
#[derive(Debug, Clone, PartialEq)]
pub struct BrdfFile {
    /// Declared parameters, in file order.
    pub params: Vec<FileParam>,
    /// The model's function and its helpers.
    pub source: Section,
    /// The language of [`BrdfFile::source`].
    pub language: Language,
    /// The optional sampling function (`isFunc`, GLSL).
    pub is_func: Option<Section>,
}

/// An error at a place in the file (1-based line and column).
fn at(line: usize, column: usize, reason: impl Into<String>) -> BvError {
    BvError::Invalid(format!("line {line}, column {column}: {}", reason.into()))
}

/// The part of a line before its comment, and the comment's text.
fn split_comment(line: &str) -> (&str, Option<&str>) {
    match line.find('#') {
        Some(i) => (&line[..i], Some(line[i + 1..].trim())),
        None => (line, None),
    }
}

fn is_identifier(s: &str) -> bool {
    let mut c = s.chars();
    c.next()
        .is_some_and(|first| first.is_ascii_alphabetic() || first == '_')
        && c.all(|ch| ch.is_ascii_alphanumeric() || ch == '_')
}

/// Parses the text of a `.brdf` file.
pub fn parse(text: &str) -> Result<BrdfFile> {
    if text.len() > MAX_FILE_BYTES {
        return Err(BvError::Invalid(format!(
            "the file is {} bytes; at most {MAX_FILE_BYTES} are read",
            text.len()
        )));
    }
    // A byte-order mark, which some editors write at the start of a UTF-8
    // file, is not part of the text.
    let text = text.strip_prefix('\u{feff}').unwrap_or(text);
    let mut kind_seen = false;
    let mut params: Vec<FileParam> = Vec::new();
    let mut sections: Vec<(String, Section, usize)> = Vec::new();
    // The open section: name, its lines, the line of its `::begin`.
    let mut open: Option<(String, Vec<&str>, usize, usize)> = None;
    for (i, raw) in text.lines().enumerate() {
        let n = i + 1;
        let trimmed = raw.trim();
        if let Some(rest) = trimmed.strip_prefix("::end") {
            let name = rest.trim();
            match open.take() {
                Some((open_name, lines, begin, first)) if open_name == name => {
                    let section = Section {
                        text: lines.join("\n"),
                        first_line: first,
                    };
                    if open_name == "parameters" {
                        parse_params(&section, &mut params)?;
                    }
                    if sections.iter().any(|(s, _, _)| *s == open_name) {
                        return Err(at(begin, 1, format!("a second `{open_name}` section")));
                    }
                    sections.push((open_name, section, begin));
                }
                Some((open_name, ..)) => {
                    return Err(at(
                        n,
                        1,
                        format!("`::end {name}` inside the `{open_name}` section"),
                    ));
                }
                None => return Err(at(n, 1, format!("`::end {name}` without `::begin`"))),
            }
            continue;
        }
        if let Some((_, lines, _, _)) = &mut open {
            if trimmed.starts_with("::begin") {
                return Err(at(n, 1, "`::begin` inside another section"));
            }
            lines.push(raw);
            continue;
        }
        if let Some(rest) = trimmed.strip_prefix("::begin") {
            let name = rest.trim();
            if !matches!(name, "parameters" | "shader" | "isFunc" | "wgsl") {
                return Err(at(
                    n,
                    1,
                    format!(
                        "unknown section `{name}` (sections: parameters, shader, isFunc, wgsl)"
                    ),
                ));
            }
            if !kind_seen {
                return Err(at(n, 1, "the file must start with `analytic`"));
            }
            open = Some((name.to_string(), Vec::new(), n, n + 1));
            continue;
        }
        let (code, _) = split_comment(trimmed);
        let code = code.trim();
        if code.is_empty() {
            continue;
        }
        if !kind_seen {
            match code {
                "analytic" => kind_seen = true,
                "measured" | "image" => {
                    return Err(at(
                        n,
                        1,
                        format!("`{code}` files are not supported; bv reads `analytic` ones"),
                    ));
                }
                other => {
                    return Err(at(
                        n,
                        1,
                        format!("expected `analytic` as the first line, found `{other}`"),
                    ));
                }
            }
            continue;
        }
        return Err(at(n, 1, format!("text outside a section: `{code}`")));
    }
    if let Some((name, _, begin, _)) = open {
        return Err(at(
            begin,
            1,
            format!("the `{name}` section has no `::end {name}`"),
        ));
    }
    if !kind_seen {
        return Err(BvError::Invalid(
            "the file is empty (no `analytic` line)".into(),
        ));
    }
    let take = |name: &str| {
        sections
            .iter()
            .find(|(s, _, _)| s == name)
            .map(|(_, sec, _)| sec.clone())
    };
    let (source, language) = match (take("shader"), take("wgsl")) {
        (Some(s), None) => (s, Language::Glsl),
        (None, Some(w)) => (w, Language::Wgsl),
        (Some(_), Some(_)) => {
            return Err(BvError::Invalid(
                "the file has both a `shader` and a `wgsl` section; keep one".into(),
            ));
        }
        (None, None) => {
            return Err(BvError::Invalid(
                "the file has no `::begin shader` section with the BRDF function".into(),
            ));
        }
    };
    if source.text.trim().is_empty() {
        return Err(at(source.first_line, 1, "the shader section is empty"));
    }
    Ok(BrdfFile {
        params,
        source,
        language,
        is_func: take("isFunc"),
    })
}

fn parse_params(section: &Section, out: &mut Vec<FileParam>) -> Result<()> {
    for (k, raw) in section.text.lines().enumerate() {
        let line = section.first_line + k;
        let (code, comment) = split_comment(raw);
        let words: Vec<&str> = code.split_whitespace().collect();
        let Some(&kind) = words.first() else {
            continue;
        };
        let column = raw.find(kind).map_or(1, |c| c + 1);
        let name = *words
            .get(1)
            .ok_or_else(|| at(line, column, format!("`{kind}` needs a parameter name")))?;
        if !is_identifier(name) || name.len() > MAX_NAME {
            return Err(at(
                line,
                column,
                format!(
                    "`{name}` is not a parameter name (letters, digits, _; at most {MAX_NAME})"
                ),
            ));
        }
        if out.iter().any(|p| p.name == name) {
            return Err(at(
                line,
                column,
                format!("parameter `{name}` is declared twice"),
            ));
        }
        if out.len() >= MAX_PARAMS {
            return Err(at(
                line,
                column,
                format!("more than {MAX_PARAMS} parameters"),
            ));
        }
        let numbers = || -> Result<Vec<f64>> {
            words[2..]
                .iter()
                .map(|w| {
                    w.parse::<f64>()
                        .ok()
                        .filter(|x| x.is_finite())
                        .ok_or_else(|| at(line, column, format!("`{w}` is not a number")))
                })
                .collect()
        };
        let want = |n: usize, form: &str| -> Result<Vec<f64>> {
            let v = numbers()?;
            if v.len() != n {
                return Err(at(
                    line,
                    column,
                    format!(
                        "`{kind} {name}` takes {n} numbers ({form}), found {}",
                        v.len()
                    ),
                ));
            }
            Ok(v)
        };
        let kind = match kind {
            "float" => {
                let v = want(3, "MIN MAX DEFAULT")?;
                let (min, max, default) = (v[0], v[1], v[2]);
                if min > max {
                    return Err(at(
                        line,
                        column,
                        format!("`{name}`: MIN {min} is above MAX {max}"),
                    ));
                }
                if !(min..=max).contains(&default) {
                    return Err(at(
                        line,
                        column,
                        format!("`{name}`: default {default} is outside [{min}, {max}]"),
                    ));
                }
                FileParamKind::Float { min, max, default }
            }
            "bool" => {
                let v = want(1, "0 or 1")?;
                let default = match v[0] {
                    0.0 => false,
                    1.0 => true,
                    x => {
                        return Err(at(
                            line,
                            column,
                            format!("`{name}`: a bool's default is 0 or 1, found {x}"),
                        ));
                    }
                };
                FileParamKind::Bool { default }
            }
            "color" => {
                let v = want(3, "R G B")?;
                if v.iter().any(|x| *x < 0.0) {
                    return Err(at(
                        line,
                        column,
                        format!("`{name}`: a colour is not negative"),
                    ));
                }
                FileParamKind::Color {
                    default: [v[0], v[1], v[2]],
                }
            }
            other => {
                return Err(at(
                    line,
                    column,
                    format!("unknown parameter kind `{other}` (kinds: float, bool, color)"),
                ));
            }
        };
        out.push(FileParam {
            name: name.to_string(),
            kind,
            tooltip: comment.filter(|c| !c.is_empty()).map(str::to_string),
            line,
        });
    }
    Ok(())
}

impl FileParam {
    /// The parameter as bv declares parameters. The strings are leaked: a
    /// declaration lives as long as the catalogue entry that holds it (the
    /// process), and a file's declaration is a few hundred bytes.
    pub fn to_decl(&self) -> ParamDecl {
        let id: &'static str = Box::leak(self.name.clone().into_boxed_str());
        let doc: &'static str = match &self.tooltip {
            Some(t) => Box::leak(t.clone().into_boxed_str()),
            None => "",
        };
        let kind = match self.kind {
            FileParamKind::Float { min, max, default } => {
                ParamKind::Float(FloatSpec::linear(min, max, default))
            }
            FileParamKind::Bool { default } => ParamKind::Bool { default },
            FileParamKind::Color { default } => {
                // Explorer's colour pickers run 0..1; a brighter default
                // widens the range rather than being clamped.
                let max = default.iter().copied().fold(1.0, f64::max);
                ParamKind::Color(ColorSpec {
                    max,
                    ..ColorSpec::unit_range(default)
                })
            }
        };
        ParamDecl {
            id,
            label: id,
            doc,
            kind,
            applies: Applies::Always,
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    const PHONG: &str = "\
analytic

# Phong, as the Explorer ships it (written here for the test)
::begin parameters
float n 1 1000 100   # exponent
bool normalized 1
color Kd 0.5 0.25 0.125
::end parameters

::begin shader
const float PI = 3.14159265358979323846;
vec3 BRDF( vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y )
{
    vec3 R = reflect(-L, N);
    float val = pow(max(0, dot(R, V)), n);
    if (normalized) val *= (n + 2) / (2 * PI);
    return vec3(val);
}
::end shader
";

    #[test]
    fn reads_every_feature_of_the_format() {
        let f = parse(PHONG).unwrap();
        assert_eq!(f.language, Language::Glsl);
        assert_eq!(f.params.len(), 3);
        assert_eq!(
            f.params[0],
            FileParam {
                name: "n".into(),
                kind: FileParamKind::Float {
                    min: 1.0,
                    max: 1000.0,
                    default: 100.0
                },
                tooltip: Some("exponent".into()),
                line: 5,
            }
        );
        assert_eq!(f.params[1].kind, FileParamKind::Bool { default: true });
        assert_eq!(f.params[1].tooltip, None);
        assert_eq!(
            f.params[2].kind,
            FileParamKind::Color {
                default: [0.5, 0.25, 0.125]
            }
        );
        // The shader's first line is line 11 of the file, kept verbatim.
        assert_eq!(f.source.first_line, 11);
        assert!(f.source.text.starts_with("const float PI"));
        assert!(f.source.text.contains("vec3 BRDF( vec3 L"));
        assert!(f.is_func.is_none());
        let d = f.params[0].to_decl();
        assert_eq!((d.id, d.doc), ("n", "exponent"));
        assert!(matches!(d.kind, ParamKind::Float(s) if s.min == 1.0 && s.default == 100.0));
    }

    #[test]
    fn the_native_variant_and_is_func() {
        let text = "# header comment\nanalytic\n::begin wgsl\nfn brdf(wi: vec3f, wo: vec3f, n: vec3f, x: vec3f, y: vec3f) -> vec3f { return vec3f(0.3); }\n::end wgsl\n::begin isFunc\nvec3 sample(float u, float v) { return vec3(0); }\n::end isFunc\n";
        let f = parse(text).unwrap();
        assert_eq!(f.language, Language::Wgsl);
        assert_eq!(f.source.first_line, 4);
        assert!(f.params.is_empty());
        assert_eq!(f.is_func.unwrap().first_line, 7);
    }

    /// The message of the error for `text`.
    fn error(text: &str) -> String {
        parse(text).unwrap_err().to_string()
    }

    #[test]
    fn broken_files_are_refused_with_their_place() {
        let shader = "::begin shader\nvec3 BRDF(vec3 L, vec3 V, vec3 N, vec3 X, vec3 Y) { return vec3(1); }\n::end shader\n";
        let cases: Vec<(String, &str)> = vec![
            (String::new(), "empty"),
            (format!("measured\n{shader}"), "not supported"),
            (format!("lambert\n{shader}"), "expected `analytic`"),
            ("analytic\n".into(), "no `::begin shader`"),
            (
                "analytic\n::begin shader\nvec3 BRDF() {}\n".into(),
                "line 2, column 1: the `shader` section has no `::end shader`",
            ),
            (
                format!("analytic\n::begin parameters\nint k 1 2 3\n::end parameters\n{shader}"),
                "line 3, column 1: unknown parameter kind `int`",
            ),
            (
                format!("analytic\n::begin parameters\nfloat k 2 1 1\n::end parameters\n{shader}"),
                "MIN 2 is above MAX 1",
            ),
            (
                format!("analytic\n::begin parameters\nfloat k 0 1 5\n::end parameters\n{shader}"),
                "default 5 is outside [0, 1]",
            ),
            (
                format!("analytic\n::begin parameters\nfloat k 0 1\n::end parameters\n{shader}"),
                "takes 3 numbers",
            ),
            (
                format!(
                    "analytic\n::begin parameters\n  float k 0 x 1\n::end parameters\n{shader}"
                ),
                "line 3, column 3: `x` is not a number",
            ),
            (
                format!("analytic\n::begin parameters\nbool b 2\n::end parameters\n{shader}"),
                "0 or 1",
            ),
            (
                format!("analytic\n::begin parameters\ncolor c 1 -1 0\n::end parameters\n{shader}"),
                "not negative",
            ),
            (
                format!("analytic\n::begin parameters\nfloat 9x 0 1 0\n::end parameters\n{shader}"),
                "not a parameter name",
            ),
            (
                format!(
                    "analytic\n::begin parameters\nfloat a 0 1 0\nfloat a 0 1 0\n::end parameters\n{shader}"
                ),
                "declared twice",
            ),
            (
                format!("analytic\n::begin fancy\n::end fancy\n{shader}"),
                "unknown section `fancy`",
            ),
            (
                format!("analytic\nfloat a 0 1 0\n{shader}"),
                "outside a section",
            ),
            (
                format!("analytic\n{shader}{shader}"),
                "a second `shader` section",
            ),
            ("analytic\n::begin shader\n\n::end shader\n".into(), "empty"),
            (
                format!("analytic\n{shader}::begin wgsl\nfn brdf() {{}}\n::end wgsl\n"),
                "both",
            ),
            ("analytic\n::end shader\n".into(), "without `::begin`"),
            (
                "analytic\n::begin shader\n::begin wgsl\n".into(),
                "inside another section",
            ),
        ];
        for (text, want) in cases {
            let e = error(&text);
            assert!(e.contains(want), "{text:?}: {e}");
        }
    }

    #[test]
    fn hostile_sizes_are_bounded() {
        let huge = format!(
            "analytic\n::begin shader\n{}\n::end shader\n",
            "x".repeat(MAX_FILE_BYTES)
        );
        assert!(error(&huge).contains("at most"));
        let mut many = String::from("analytic\n::begin parameters\n");
        for i in 0..=MAX_PARAMS {
            many.push_str(&format!("float p{i} 0 1 0\n"));
        }
        many.push_str("::end parameters\n::begin shader\nvec3 BRDF() {}\n::end shader\n");
        assert!(error(&many).contains("more than"));
        let long = format!(
            "analytic\n::begin parameters\nfloat {} 0 1 0\n::end parameters\n::begin shader\nx\n::end shader\n",
            "a".repeat(MAX_NAME + 1)
        );
        assert!(error(&long).contains("not a parameter name"));
    }

    #[test]
    fn a_bright_colour_default_widens_its_range() {
        let p = FileParam {
            name: "c".into(),
            kind: FileParamKind::Color {
                default: [2.0, 0.5, 0.0],
            },
            tooltip: None,
            line: 1,
        };
        let ParamKind::Color(s) = p.to_decl().kind else {
            panic!("a colour");
        };
        assert_eq!((s.min, s.max, s.default), (0.0, 2.0, [2.0, 0.5, 0.0]));
    }
}
