//! What a file's shader text may cost, checked before any compiler sees it.
//!
//! naga's front ends, validator and WGSL writer, and bv-interp's compiler,
//! walk expressions recursively, and naga's GLSL front end spends time
//! quadratic in the number of expressions of a function (its typifier).
//! Nothing a BRDF needs comes near these limits, but a hostile or generated
//! file can: a 7,000-term sum or 6,000 nested parentheses overflowed the
//! stack, 40 lines of `#define aN (aN-1 + aN-1)` expanded to 2^40 tokens,
//! 40,000 statements took 8 s to compile. So the text is measured first, by
//! a scanner that shares nothing with those compilers and does not recurse:
//!
//! - **characters**: shader code is ASCII (a no-break space or a curly quote
//!   pasted from a document is named, with its line and column); comments
//!   may hold any text but a NUL;
//! - **macros**: `#define`s are expanded by a stack machine that counts the
//!   tokens it would produce, so a macro that doubles per line is refused
//!   after [`MAX_TOKENS`] tokens, in microseconds and a few kilobytes;
//!   `#include` and unknown directives are refused by name;
//! - **size**: at most [`MAX_TOKENS`] tokens after expansion (compile time
//!   stays under a second), brackets nested at most [`MAX_NESTING`] deep
//!   and at most [`MAX_OPERATORS`] operators in one statement (the depth of
//!   every recursive walk downstream is bounded by these two).
//!
//! The limits are checked on the expanded token stream, so a macro cannot
//! hide a 7,000-term sum in one line; a refusal is placed at the user's line
//! and column (for tokens a macro produced, at the macro's use).

use crate::error::{Place, Result, UserError};
use bv_core::user::brdf_file::{Language, Section};
use std::collections::HashMap;
use std::rc::Rc;

/// Most tokens a file's shader may have after macro expansion (its
/// `shader` and `isFunc` sections together). Disney's largest file has a
/// few thousand; naga's GLSL front end compiles this many in about half a
/// second on a 2-core EPYC.
pub const MAX_TOKENS: usize = 1 << 16;
/// Deepest nesting of `(`, `[` and `{`.
pub const MAX_NESTING: usize = 128;
/// Most operators in one statement (between `;`, `{` and `}`): the depth of
/// the longest expression chain.
pub const MAX_OPERATORS: usize = 512;
/// Most tokens the macro expander may read, copy or produce in all: a
/// bound on its time and memory even where a macro expands to nothing.
const MAX_WORK: usize = 1 << 20;
/// Deepest nesting of macro expansions (a macro is active at most once, so
/// this is also a bound on a chain of aliases).
const MAX_MACRO_DEPTH: usize = 4096;

/// A token of the scanner: enough to count, nest and expand.
#[derive(Debug, Clone, PartialEq)]
enum Tok {
    Ident(Rc<str>),
    /// A number literal.
    Number,
    /// One punctuation or operator token, as written (`(`, `+=`, `&&`).
    Punct(&'static str),
    /// A preprocessor directive's position in the stream (an index into
    /// the scan's directives), applied when the expander reaches it.
    Directive(usize),
    /// A macro argument in a substituted body: its raw tokens and the stack
    /// index of the frame the macro was called from.
    Arg(Rc<Vec<Tok>>, usize),
}

/// Where a token came from: 0-based section, line and column (columns in
/// characters, 1-based).
#[derive(Debug, Clone, Copy)]
struct At {
    section: usize,
    line: usize,
    column: usize,
}

/// A directive line.
#[derive(Debug)]
enum Directive {
    Define {
        name: Rc<str>,
        params: Option<Vec<Rc<str>>>,
        body: Rc<Vec<Tok>>,
    },
    Undef(Rc<str>),
    /// A directive that changes nothing this scanner counts (`#if`,
    /// `#pragma`, `#extension`, …).
    Other,
}

/// Operators and punctuation, longest first so that the scanner takes the
/// longest match.
const PUNCT: &[&str] = &[
    "<<=", ">>=", "<<", ">>", "<=", ">=", "==", "!=", "&&", "||", "^^", "++", "--", "+=", "-=",
    "*=", "/=", "%=", "&=", "|=", "^=", "->", "##", "(", ")", "[", "]", "{", "}", ".", ",", ";",
    ":", "?", "+", "-", "*", "/", "%", "<", ">", "=", "!", "~", "&", "|", "^", "@", "#",
];

/// Whether a punctuation token is an operator (counts toward
/// [`MAX_OPERATORS`]).
fn is_operator(p: &str) -> bool {
    !matches!(p, "(" | ")" | "[" | "]" | "{" | "}" | "," | ";" | "@" | "#")
}

/// A human name for a character that shader code cannot hold.
fn char_name(c: char) -> String {
    let name = match c {
        '\u{a0}' => " (a no-break space)",
        '\u{feff}' => " (a byte-order mark)",
        '\u{200b}' => " (a zero-width space)",
        '\u{2018}' | '\u{2019}' => " (a curly single quote)",
        '\u{201c}' | '\u{201d}' => " (a curly double quote)",
        '\u{2013}' => " (an en dash)",
        '\u{2014}' => " (an em dash)",
        '\u{2212}' => " (a minus sign; write `-`)",
        '\u{d7}' => " (a multiplication sign; write `*`)",
        '\0' => " (a NUL byte)",
        c if c.is_control() => " (a control character)",
        _ => "",
    };
    format!("U+{:04X}{name}", c as u32)
}

/// The scan of the sections: tokens with their places, and directives.
struct Scan {
    toks: Vec<Tok>,
    at: Vec<At>,
    directives: Vec<Directive>,
}

/// Errors of the scan, placed by (section, line, column).
struct Refusal {
    at: At,
    reason: String,
}

fn refuse<T>(at: At, reason: impl Into<String>) -> std::result::Result<T, Refusal> {
    Err(Refusal {
        at,
        reason: reason.into(),
    })
}

/// A lexer over one section's text that tracks lines and columns.
struct Lexer<'a> {
    chars: std::iter::Peekable<std::str::Chars<'a>>,
    section: usize,
    line: usize,
    column: usize,
}

impl Lexer<'_> {
    fn at(&self) -> At {
        At {
            section: self.section,
            line: self.line,
            column: self.column,
        }
    }

    fn bump(&mut self) -> Option<char> {
        let c = self.chars.next()?;
        if c == '\n' {
            self.line += 1;
            self.column = 1;
        } else {
            self.column += 1;
        }
        Some(c)
    }

    fn peek(&mut self) -> Option<char> {
        self.chars.peek().copied()
    }
}

/// Scans the sections (in order, as one text), separating directives.
fn scan(sections: &[&str], language: Language) -> std::result::Result<Scan, Refusal> {
    let mut out = Scan {
        toks: Vec::new(),
        at: Vec::new(),
        directives: Vec::new(),
    };
    for (section, text) in sections.iter().enumerate() {
        let mut lx = Lexer {
            chars: text.chars().peekable(),
            section,
            line: 0,
            column: 1,
        };
        // Whether the next token is the first of its (logical) line.
        let mut line_start = true;
        // The directive being gathered: its tokens, its place.
        let mut directive: Option<(Vec<Tok>, At)> = None;
        // Where the last token ended, and whether a directive's `(` came
        // right after its second token (a function-like `#define`).
        let mut last_end = (usize::MAX, 0);
        let mut glued_paren = false;
        loop {
            let at = lx.at();
            let Some(c) = lx.peek() else { break };
            let token: Option<Tok> = match c {
                '\n' => {
                    lx.bump();
                    line_start = true;
                    if let Some((toks, at)) = directive.take() {
                        let index = out.directives.len();
                        out.directives.push(parse_directive(toks, glued_paren, at)?);
                        out.toks.push(Tok::Directive(index));
                        out.at.push(at);
                    }
                    None
                }
                '\\' => {
                    // A line continuation joins the next line to this one.
                    lx.bump();
                    if lx.peek() == Some('\r') {
                        lx.bump();
                    }
                    if lx.peek() == Some('\n') {
                        lx.bump();
                    } else {
                        return refuse(at, "a `\\` outside a line continuation");
                    }
                    None
                }
                c if c == ' ' || c == '\t' || c == '\r' || c == '\x0b' || c == '\x0c' => {
                    lx.bump();
                    None
                }
                '/' => {
                    lx.bump();
                    match lx.peek() {
                        Some('/') => {
                            while let Some(c) = lx.peek() {
                                if c == '\n' {
                                    break;
                                }
                                if c == '\0' {
                                    return refuse(lx.at(), "a NUL byte in a comment");
                                }
                                lx.bump();
                            }
                            None
                        }
                        Some('*') => {
                            lx.bump();
                            let mut star = false;
                            loop {
                                let here = lx.at();
                                match lx.bump() {
                                    None => return refuse(at, "a `/*` comment that never ends"),
                                    Some('\0') => {
                                        return refuse(here, "a NUL byte in a comment");
                                    }
                                    Some('/') if star => break,
                                    Some(c) => star = c == '*',
                                }
                            }
                            None
                        }
                        _ => {
                            if lx.peek() == Some('=') {
                                lx.bump();
                                Some(Tok::Punct("/="))
                            } else {
                                Some(Tok::Punct("/"))
                            }
                        }
                    }
                }
                '"' => {
                    // A string, which only `#include` and `#line` take.
                    lx.bump();
                    loop {
                        match lx.bump() {
                            Some('"') => break,
                            None | Some('\n') => {
                                return refuse(at, "a `\"` string that never ends");
                            }
                            Some(_) => {}
                        }
                    }
                    Some(Tok::Number)
                }
                c if c.is_ascii_alphabetic() || c == '_' => {
                    let mut s = String::new();
                    while let Some(c) = lx.peek() {
                        if c.is_ascii_alphanumeric() || c == '_' {
                            s.push(c);
                            lx.bump();
                        } else {
                            break;
                        }
                    }
                    Some(Tok::Ident(s.into()))
                }
                c if c.is_ascii_digit() => {
                    // Digits, letters (suffixes, hex, exponents), points and
                    // an exponent's sign.
                    let mut prev = ' ';
                    while let Some(c) = lx.peek() {
                        let sign = (c == '+' || c == '-') && (prev == 'e' || prev == 'E');
                        if c.is_ascii_alphanumeric() || c == '.' || c == '_' || sign {
                            prev = c;
                            lx.bump();
                        } else {
                            break;
                        }
                    }
                    Some(Tok::Number)
                }
                '.' => {
                    lx.bump();
                    if lx.peek().is_some_and(|c| c.is_ascii_digit()) {
                        let mut prev = '.';
                        while let Some(c) = lx.peek() {
                            let sign = (c == '+' || c == '-') && (prev == 'e' || prev == 'E');
                            if c.is_ascii_alphanumeric() || sign {
                                prev = c;
                                lx.bump();
                            } else {
                                break;
                            }
                        }
                        Some(Tok::Number)
                    } else {
                        Some(Tok::Punct("."))
                    }
                }
                c if c.is_ascii_punctuation() => {
                    // The longest operator that the text starts with.
                    let rest: String = {
                        let mut probe = lx.chars.clone();
                        (0..3).filter_map(|_| probe.next()).collect()
                    };
                    match PUNCT.iter().find(|p| rest.starts_with(**p)) {
                        Some(p) => {
                            for _ in 0..p.len() {
                                lx.bump();
                            }
                            Some(Tok::Punct(p))
                        }
                        None => {
                            return refuse(
                                at,
                                format!("the character `{c}` has no meaning in shader code"),
                            );
                        }
                    }
                }
                c => {
                    return refuse(
                        at,
                        format!(
                            "{} cannot appear in shader code (outside comments, only ASCII \
                             characters are allowed)",
                            char_name(c)
                        ),
                    );
                }
            };
            let Some(token) = token else { continue };
            let first = std::mem::replace(&mut line_start, false);
            let glued = last_end == (at.line, at.column);
            last_end = (lx.line, lx.column);
            if let Some((toks, _)) = &mut directive {
                if toks.len() == 2 {
                    glued_paren = glued && token == Tok::Punct("(");
                }
                toks.push(token);
            } else if first && token == Tok::Punct("#") && language == Language::Glsl {
                directive = Some((Vec::new(), at));
            } else {
                out.toks.push(token);
                out.at.push(at);
            }
        }
        if let Some((toks, at)) = directive.take() {
            let index = out.directives.len();
            out.directives.push(parse_directive(toks, glued_paren, at)?);
            out.toks.push(Tok::Directive(index));
            out.at.push(at);
        }
    }
    Ok(out)
}

/// A directive's meaning, from its tokens after the `#`; `glued_paren`:
/// its third token is a `(` with no space before it.
fn parse_directive(
    toks: Vec<Tok>,
    glued_paren: bool,
    at: At,
) -> std::result::Result<Directive, Refusal> {
    let Some(Tok::Ident(word)) = toks.first() else {
        // A lone `#` is the null directive.
        return if toks.is_empty() {
            Ok(Directive::Other)
        } else {
            refuse(at, "a `#` that starts no preprocessor directive")
        };
    };
    match &**word {
        "define" => {
            let Some(Tok::Ident(name)) = toks.get(1) else {
                return refuse(at, "`#define` needs a macro name");
            };
            // A function-like macro has `(` right after its name, with no
            // space (`#define F (x)` is an object-like macro).
            let (params, body_start) = if glued_paren && toks.get(2) == Some(&Tok::Punct("(")) {
                let close = toks
                    .iter()
                    .skip(3)
                    .position(|t| *t == Tok::Punct(")"))
                    .map(|k| k + 3);
                match close {
                    Some(close) => {
                        let params = toks[3..close]
                            .iter()
                            .filter_map(|t| match t {
                                Tok::Ident(p) => Some(p.clone()),
                                _ => None,
                            })
                            .collect();
                        (Some(params), close + 1)
                    }
                    None => (None, 2),
                }
            } else {
                (None, 2)
            };
            Ok(Directive::Define {
                name: name.clone(),
                params,
                body: Rc::new(toks[body_start..].to_vec()),
            })
        }
        "undef" => match toks.get(1) {
            Some(Tok::Ident(name)) => Ok(Directive::Undef(name.clone())),
            _ => refuse(at, "`#undef` needs a macro name"),
        },
        "include" => refuse(
            at,
            "`#include` is not supported: a .brdf file is self-contained (paste the included \
             code into the section)",
        ),
        "if" | "ifdef" | "ifndef" | "elif" | "else" | "endif" | "error" | "pragma"
        | "extension" | "line" | "version" => Ok(Directive::Other),
        other => refuse(at, format!("`#{other}` is not a preprocessor directive")),
    }
}

/// A macro as the expander holds it.
struct Macro {
    params: Option<Vec<Rc<str>>>,
    body: Rc<Vec<Tok>>,
}

/// One level of the expander's stack: a token list, the next position, the
/// macro it expands (none for the source and for an argument) and the
/// source position its expansion stands for.
struct Frame {
    toks: Rc<Vec<Tok>>,
    pos: usize,
    expanding: Option<Rc<str>>,
    /// Index in the source of the token the expansion started at (for the
    /// source itself: unused, each token is its own place).
    origin: usize,
    /// For an argument of a function-like macro: the stack index of the
    /// frame the macro was called from. An argument is expanded as C's
    /// preprocessor (and pp-rs) expands it, before substitution, where the
    /// called macro is not yet active.
    arg_base: Option<usize>,
}

/// The running counts the limits apply to.
#[derive(Default)]
struct Counts {
    tokens: usize,
    depth: usize,
    operators: usize,
    work: usize,
    /// The last three tokens, as far as `[ - number ]` is concerned.
    recent: [u8; 3],
}

impl Counts {
    /// Takes one token of the expanded stream.
    fn take(&mut self, t: &Tok) -> std::result::Result<(), String> {
        self.tokens += 1;
        // `[-4]`: naga's message ("int constant overflows") names its own
        // unsigned conversion, not the user's mistake.
        if *t == Tok::Punct("]") && self.recent == [b'[', b'-', b'0'] {
            return Err("an array size or index cannot be negative".into());
        }
        let code = match t {
            Tok::Punct("[") => b'[',
            Tok::Punct("-") => b'-',
            Tok::Number => b'0',
            _ => b' ',
        };
        self.recent = [self.recent[1], self.recent[2], code];
        if self.tokens > MAX_TOKENS {
            return Err(format!(
                "the shader is more than {MAX_TOKENS} tokens long (after macro expansion); \
                 a BRDF needs far fewer"
            ));
        }
        if let Tok::Punct(p) = t {
            match *p {
                "(" | "[" | "{" => {
                    self.depth += 1;
                    if self.depth > MAX_NESTING {
                        return Err(format!(
                            "brackets nest more than {MAX_NESTING} levels deep here; \
                             split the expression with local variables"
                        ));
                    }
                }
                ")" | "]" | "}" => self.depth = self.depth.saturating_sub(1),
                _ => {}
            }
            if matches!(*p, ";" | "{" | "}") {
                self.operators = 0;
            } else if is_operator(p) {
                self.operators += 1;
                if self.operators > MAX_OPERATORS {
                    return Err(format!(
                        "this statement has more than {MAX_OPERATORS} operators; split it \
                         into several statements with local variables"
                    ));
                }
            }
        }
        Ok(())
    }

    fn work(&mut self, n: usize) -> std::result::Result<(), String> {
        self.work += n;
        if self.work > MAX_WORK {
            return Err(format!(
                "the macros expand to more than {MAX_TOKENS} tokens; a BRDF needs far fewer"
            ));
        }
        Ok(())
    }
}

/// The next token of the expander's stream, entering arguments, and the
/// source position it stands for.
fn next(stack: &mut Vec<Frame>) -> Option<(Tok, usize)> {
    loop {
        let top = stack.last_mut()?;
        if top.pos < top.toks.len() {
            let t = top.toks[top.pos].clone();
            let origin = if top.expanding.is_none() && top.arg_base.is_none() {
                top.pos
            } else {
                top.origin
            };
            top.pos += 1;
            if let Tok::Arg(toks, base) = t {
                stack.push(Frame {
                    toks,
                    pos: 0,
                    expanding: None,
                    origin,
                    arg_base: Some(base),
                });
                continue;
            }
            return Some((t, origin));
        }
        if stack.len() == 1 {
            return None;
        }
        stack.pop();
    }
}

/// The next token without taking it (an argument's first token, or what
/// follows an empty one, is not looked into: only `(` matters here).
fn peek(stack: &[Frame]) -> Option<&Tok> {
    stack.iter().rev().find_map(|f| f.toks.get(f.pos))
}

/// Whether macro `name` is being expanded where the top of the stack is:
/// inside an argument, only the frames above it and those of the call site
/// count.
fn active(stack: &[Frame], name: &str) -> bool {
    let mut i = stack.len();
    while i > 0 {
        i -= 1;
        let f = &stack[i];
        if f.expanding.as_deref() == Some(name) {
            return true;
        }
        if let Some(base) = f.arg_base {
            i = base.min(i) + 1;
        }
    }
    false
}

/// Why a word of shader code cannot work in a BRDF file, for the words
/// whose compiler message would name internal tokens or stages.
fn unsupported_word(word: &str, language: Language) -> Option<String> {
    const GLSL_TEXTURES: &[&str] = &[
        "sampler1D",
        "sampler2D",
        "sampler3D",
        "samplerCube",
        "sampler2DShadow",
        "sampler2DArray",
        "samplerCubeShadow",
        "isampler2D",
        "usampler2D",
        "image2D",
        "texture",
        "texture2D",
        "textureCube",
        "textureLod",
        "texelFetch",
        "textureSize",
    ];
    const WGSL_TEXTURES: &[&str] = &[
        "texture_1d",
        "texture_2d",
        "texture_3d",
        "texture_cube",
        "texture_2d_array",
        "texture_depth_2d",
        "sampler",
        "sampler_comparison",
        "textureSample",
        "textureSampleLevel",
        "textureLoad",
        "textureDimensions",
    ];
    const GLSL_DERIVATIVES: &[&str] = &[
        "dFdx",
        "dFdy",
        "fwidth",
        "dFdxFine",
        "dFdyFine",
        "dFdxCoarse",
        "dFdyCoarse",
    ];
    const WGSL_DERIVATIVES: &[&str] = &[
        "dpdx",
        "dpdy",
        "fwidth",
        "dpdxFine",
        "dpdyFine",
        "dpdxCoarse",
        "dpdyCoarse",
    ];
    let (textures, derivatives) = match language {
        Language::Glsl => (GLSL_TEXTURES, GLSL_DERIVATIVES),
        Language::Wgsl => (WGSL_TEXTURES, WGSL_DERIVATIVES),
    };
    if textures.contains(&word) {
        return Some(format!(
            "`{word}`: textures and samplers are not supported; a BRDF file's inputs are the \
             parameters of its `parameters` section"
        ));
    }
    if derivatives.contains(&word) {
        return Some(format!(
            "`{word}`: screen-space derivatives have no meaning for a BRDF, which is evaluated \
             at one pair of directions at a time"
        ));
    }
    if language == Language::Glsl
        && matches!(
            word,
            "uniform" | "buffer" | "attribute" | "varying" | "layout"
        )
    {
        return Some(format!(
            "`{word}` declarations are not supported; a BRDF file's inputs are the parameters \
             of its `parameters` section (bv declares each as a variable of its name)"
        ));
    }
    None
}

/// Expands and counts the scanned stream.
fn expand(scan: &Scan, language: Language) -> std::result::Result<(), Refusal> {
    let mut macros: HashMap<Rc<str>, Macro> = HashMap::new();
    let mut counts = Counts::default();
    let mut stack = vec![Frame {
        toks: Rc::new(scan.toks.clone()),
        pos: 0,
        expanding: None,
        origin: 0,
        arg_base: None,
    }];
    let fail = |origin: usize, reason: String| Refusal {
        at: scan.at[origin.min(scan.at.len().saturating_sub(1))],
        reason,
    };
    while let Some((tok, origin)) = next(&mut stack) {
        counts.work(1).map_err(|r| fail(origin, r))?;
        match &tok {
            Tok::Directive(k) => match &scan.directives[*k] {
                Directive::Define { name, params, body } => {
                    macros.insert(
                        name.clone(),
                        Macro {
                            params: params.clone(),
                            body: body.clone(),
                        },
                    );
                }
                Directive::Undef(name) => {
                    macros.remove(name);
                }
                Directive::Other => {}
            },
            Tok::Ident(name) => {
                // A macro is not expanded inside its own expansion (the
                // frame that produced this name may be spent but is still
                // on the stack, as C's preprocessor paints it).
                let Some(m) = macros.get(name).filter(|_| !active(&stack, name)) else {
                    if let Some(why) = unsupported_word(name, language) {
                        return Err(fail(origin, why));
                    }
                    counts.take(&tok).map_err(|r| fail(origin, r))?;
                    continue;
                };
                if stack.len() > MAX_MACRO_DEPTH {
                    return Err(fail(
                        origin,
                        format!("macros nest more than {MAX_MACRO_DEPTH} levels deep"),
                    ));
                }
                let body = match &m.params {
                    None => m.body.clone(),
                    Some(params) => {
                        if peek(&stack) != Some(&Tok::Punct("(")) {
                            // A function-like macro's name without arguments
                            // is a plain name.
                            counts.take(&tok).map_err(|r| fail(origin, r))?;
                            continue;
                        }
                        let (params, body) = (params.clone(), m.body.clone());
                        next(&mut stack);
                        // The arguments, raw, split at top-level commas.
                        let mut args: Vec<Rc<Vec<Tok>>> = Vec::new();
                        let mut arg: Vec<Tok> = Vec::new();
                        let mut depth = 0usize;
                        while let Some((t, o)) = next(&mut stack) {
                            counts.work(1).map_err(|r| fail(o, r))?;
                            match t {
                                Tok::Punct("(") => depth += 1,
                                Tok::Punct(")") if depth == 0 => break,
                                Tok::Punct(")") => depth -= 1,
                                Tok::Punct(",") if depth == 0 => {
                                    args.push(Rc::new(std::mem::take(&mut arg)));
                                    continue;
                                }
                                _ => {}
                            }
                            arg.push(t);
                        }
                        args.push(Rc::new(arg));
                        let base = stack.len() - 1;
                        let mut out = Vec::with_capacity(body.len());
                        for t in body.iter() {
                            counts.work(1).map_err(|r| fail(origin, r))?;
                            let k = match t {
                                Tok::Ident(p) => params.iter().position(|q| q == p),
                                _ => None,
                            };
                            out.push(match k {
                                Some(k) => Tok::Arg(args.get(k).cloned().unwrap_or_default(), base),
                                None => t.clone(),
                            });
                        }
                        Rc::new(out)
                    }
                };
                stack.push(Frame {
                    toks: body,
                    pos: 0,
                    expanding: Some(name.clone()),
                    origin,
                    arg_base: None,
                });
            }
            _ => counts.take(&tok).map_err(|r| fail(origin, r))?,
        }
    }
    Ok(())
}

/// Checks the file's code sections (its `shader`, then its `isFunc`):
/// characters, directives, size after macro expansion, nesting and
/// expression size. `name` is the file name errors carry.
pub fn check(language: Language, sections: &[&Section], name: &str) -> Result<()> {
    let texts: Vec<&str> = sections.iter().map(|s| s.text.as_str()).collect();
    let place = |r: Refusal| {
        let first_line = sections.get(r.at.section).map_or(1, |s| s.first_line);
        UserError::Compile {
            place: Place {
                file: name.to_string(),
                line: first_line + r.at.line,
                column: r.at.column,
            },
            reason: r.reason,
        }
    };
    let scanned = scan(&texts, language).map_err(place)?;
    expand(&scanned, language).map_err(place)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn section(text: &str) -> Section {
        Section {
            text: text.to_string(),
            first_line: 10,
        }
    }

    fn glsl(text: &str) -> Result<()> {
        check(Language::Glsl, &[&section(text)], "f.brdf")
    }

    fn reason(r: Result<()>) -> (usize, usize, String) {
        match r {
            Err(UserError::Compile { place, reason }) => (place.line, place.column, reason),
            other => panic!("expected a placed refusal, got {other:?}"),
        }
    }

    #[test]
    fn ordinary_code_passes() {
        glsl(
            "#define PI 3.14159265\n#define SQR(x) ((x)*(x))\nfloat f(float a) {\n  \
             return SQR(a) / PI; // π, “quoted” in a comment\n}\n/* ünïcödé */\n",
        )
        .unwrap();
    }

    #[test]
    fn characters_outside_comments_are_named_and_placed() {
        let (line, column, why) = reason(glsl("float a;\nfloat\u{a0}b;\n"));
        assert_eq!((line, column), (11, 6));
        assert!(why.contains("U+00A0 (a no-break space)"), "{why}");
        let (_, _, why) = reason(glsl("float a;\0\n"));
        assert!(why.contains("NUL"), "{why}");
        let (_, _, why) = reason(glsl("// x\0\n"));
        assert!(why.contains("NUL"), "{why}");
        let (_, _, why) = reason(glsl("float a = 1.0 \u{2212} 2.0;"));
        assert!(why.contains("minus sign"), "{why}");
    }

    #[test]
    fn doubling_macros_are_refused_quickly() {
        let mut text = String::from("#define a0 (n)\n");
        for i in 1..=40 {
            text.push_str(&format!("#define a{i} (a{} + a{})\n", i - 1, i - 1));
        }
        text.push_str("float f() { return a40; }\n");
        let (line, _, why) = reason(glsl(&text));
        assert_eq!(line, 10 + 41, "placed at the use of a40");
        // One statement: its operators reach their limit first.
        assert!(why.contains("operators"), "{why}");
        // Doubling statements instead reach the token limit.
        let mut text = String::from("#define s0 x = x * 0.5;\n");
        for i in 1..=40 {
            text.push_str(&format!("#define s{i} s{} s{}\n", i - 1, i - 1));
        }
        text.push_str("void f() { s40 }\n");
        assert!(reason(glsl(&text)).2.contains("tokens"));
        // The same through a function-like macro, whose arguments pp-rs
        // expands eagerly.
        let mut text = String::from("#define D(x) (x + x)\n#define b0 n\n");
        for i in 1..=40 {
            text.push_str(&format!("#define b{i} D(b{})\n", i - 1));
        }
        text.push_str("float f() { return b40; }\n");
        assert!(reason(glsl(&text)).2.contains("operators"));
        // And through a name that becomes a function-like macro only once
        // expanded, its arguments taken from the source after it.
        let mut text = String::from("#define F(x) x x x x\n#define G F\n");
        text.push_str(&"G(".repeat(60));
        text.push('n');
        text.push_str(&")".repeat(60));
        assert!(reason(glsl(&text)).2.contains("tokens"));
        // A macro that expands to nothing still costs its expansion.
        let mut text = String::from("#define e0\n");
        for i in 1..=40 {
            text.push_str(&format!("#define e{i} e{} e{}\n", i - 1, i - 1));
        }
        text.push_str("e40\n");
        assert!(reason(glsl(&text)).2.contains("macros expand"));
    }

    #[test]
    fn long_sums_and_deep_nesting_are_refused() {
        let sum = format!(
            "float f(float a) {{ return {}; }}",
            vec!["a"; 7000].join("+")
        );
        let (_, _, why) = reason(glsl(&sum));
        assert!(why.contains("operators"), "{why}");
        let nest = format!(
            "float f(float a) {{ return {}a{}; }}",
            "(".repeat(6000),
            ")".repeat(6000)
        );
        let (_, column, why) = reason(glsl(&nest));
        assert!(why.contains("nest"), "{why}");
        assert_eq!(column, 26 + MAX_NESTING);
        // A macro cannot hide the sum.
        let hidden = format!(
            "#define S {}\nfloat f(float a) {{ return S+S+S+S+S+S+S+S+S+S; }}",
            vec!["a"; 100].join("+")
        );
        assert!(reason(glsl(&hidden)).2.contains("operators"));
        // Many statements of a few operators each are fine.
        glsl(&"x = x * 0.5 + 0.25;\n".repeat(2000)).unwrap();
    }

    #[test]
    fn directives_a_file_cannot_use_are_named() {
        let (line, _, why) = reason(glsl("float a;\n#include \"x.glsl\"\n"));
        assert_eq!(line, 11);
        assert!(why.contains("#include"), "{why}");
        assert!(reason(glsl("#foo\n")).2.contains("`#foo`"));
        // Conditionals and the rest pass.
        glsl("#ifdef X\n#else\n#endif\n#pragma optimize(on)\n#\n").unwrap();
    }

    #[test]
    fn words_that_cannot_work_in_a_brdf_are_named() {
        let (line, column, why) = reason(glsl("uniform sampler2D tex;\n"));
        assert_eq!((line, column), (10, 1));
        assert!(why.contains("`uniform` declarations"), "{why}");
        assert!(
            reason(glsl("float f() { return dFdx(1.0); }"))
                .2
                .contains("derivatives")
        );
        assert!(
            reason(glsl("vec4 t = texture(s, vec2(0));"))
                .2
                .contains("textures")
        );
        // In a comment, or as part of a longer name, they are fine.
        glsl("// uniform sampler2D\nfloat textureScale = 1.0;\n").unwrap();
        let s = section("fn f(p: f32) -> f32 { return dpdx(p); }");
        assert!(
            reason(check(Language::Wgsl, &[&s], "f.brdf"))
                .2
                .contains("derivatives")
        );
    }

    #[test]
    fn an_undefined_macro_stops_expanding() {
        // `#undef` ends the macro: the doubling below never runs.
        let mut text = String::from("#define a0 (n)\n");
        for i in 1..=40 {
            text.push_str(&format!(
                "#define a{i} (a{} + a{})\n#undef a{}\n",
                i - 1,
                i - 1,
                i - 1
            ));
        }
        text.push_str("float f() { return a40; }\n");
        glsl(&text).unwrap();
    }

    #[test]
    fn wgsl_has_no_directives_but_the_same_limits() {
        let s = section(&format!(
            "fn f(a: f32) -> f32 {{ return {}; }}",
            vec!["a"; 600].join("*")
        ));
        assert!(
            reason(check(Language::Wgsl, &[&s], "f.brdf"))
                .2
                .contains("operators")
        );
        let s = section("@must_use fn f(a: f32) -> f32 { return a; }");
        check(Language::Wgsl, &[&s], "f.brdf").unwrap();
    }
}
