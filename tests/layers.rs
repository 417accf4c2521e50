//! The shape of the code, checked: the top-level folders of `src/` are layers
//! that import only downwards, and no view, figure-export or command-line code
//! names a model of the catalogue (what a model is, is declared with the model
//! in bv-core).

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

use std::collections::{BTreeMap, BTreeSet};
use std::path::{Path, PathBuf};

/// The layers, lowest first: a folder may import the folders before it.
const LAYERS: &[&str] = &[
    "session", "derive", "gpu", "widgets", "views", "export", "cli", "app",
];

fn rust_files(dir: &Path, out: &mut Vec<PathBuf>) {
    let mut entries: Vec<_> = std::fs::read_dir(dir)
        .unwrap()
        .map(|e| e.unwrap().path())
        .collect();
    entries.sort();
    for p in entries {
        if p.is_dir() {
            rust_files(&p, out);
        } else if p.extension().is_some_and(|e| e == "rs") {
            out.push(p);
        }
    }
}

/// The code of a file without comments (line and doc comments; string
/// contents are kept).
fn without_comments(text: &str) -> String {
    let mut out = String::with_capacity(text.len());
    let b = text.as_bytes();
    let mut i = 0;
    let mut in_str = false;
    while i < b.len() {
        let c = b[i];
        if in_str {
            out.push(c as char);
            if c == b'\\' && i + 1 < b.len() {
                out.push(b[i + 1] as char);
                i += 2;
                continue;
            }
            if c == b'"' {
                in_str = false;
            }
            i += 1;
            continue;
        }
        if c == b'"' && (i == 0 || b[i - 1] != b'\'') {
            in_str = true;
            out.push('"');
            i += 1;
            continue;
        }
        if c == b'/' && i + 1 < b.len() && b[i + 1] == b'/' {
            while i < b.len() && b[i] != b'\n' {
                i += 1;
            }
            continue;
        }
        out.push(c as char);
        i += 1;
    }
    out
}

/// The top-level folders of `src/` a piece of code names (`crate::views::…`,
/// `use crate::{session::…, gpu::…}`).
fn named_folders(code: &str) -> BTreeSet<String> {
    let mut out = BTreeSet::new();
    let mut rest = code;
    while let Some(k) = rest.find("crate::") {
        let after = &rest[k + "crate::".len()..];
        if let Some(group) = after.strip_prefix('{') {
            // Top-level items of the group: split on commas at depth 0.
            let mut depth = 0usize;
            let mut item = String::new();
            for ch in group.chars() {
                match ch {
                    '{' => {
                        depth += 1;
                        item.push(ch);
                    }
                    '}' if depth == 0 => break,
                    '}' => {
                        depth -= 1;
                        item.push(ch);
                    }
                    ',' if depth == 0 => {
                        out.insert(head(&item));
                        item.clear();
                    }
                    _ => item.push(ch),
                }
            }
            out.insert(head(&item));
        } else {
            out.insert(head(after));
        }
        rest = after;
    }
    out.remove("");
    out
}

fn head(path: &str) -> String {
    path.trim()
        .chars()
        .take_while(|c| c.is_ascii_alphanumeric() || *c == '_')
        .collect()
}

/// Folder → the other folders its files name, with one file as evidence.
fn folder_graph() -> BTreeMap<String, BTreeMap<String, String>> {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    let mut graph: BTreeMap<String, BTreeMap<String, String>> = BTreeMap::new();
    for f in files {
        let rel = f.strip_prefix(&src).unwrap();
        let Some(folder) = rel
            .components()
            .next()
            .filter(|_| rel.components().count() > 1)
        else {
            continue; // lib.rs, main.rs: the crate root wires the layers together
        };
        let folder = folder.as_os_str().to_string_lossy().to_string();
        let code = without_comments(&std::fs::read_to_string(&f).unwrap());
        for to in named_folders(&code) {
            if to != folder {
                graph
                    .entry(folder.clone())
                    .or_default()
                    .entry(to)
                    .or_insert_with(|| rel.display().to_string());
            }
        }
    }
    graph
}

#[test]
fn the_folder_scanner_reads_imports() {
    let code = without_comments(
        "use crate::session::state::AppState; // crate::app::nope\n\
         use crate::{gpu::Gpu, views::{self, Scene}};\n\
         let s = \"crate::cli\"; crate::export::save_png(x);",
    );
    let got: Vec<_> = named_folders(&code).into_iter().collect();
    assert_eq!(got, ["cli", "export", "gpu", "session", "views"]);
}

#[test]
fn folders_import_only_the_layers_below_them() {
    let graph = folder_graph();
    let rank = |f: &str| LAYERS.iter().position(|l| *l == f);
    let mut wrong = Vec::new();
    for (from, tos) in &graph {
        let Some(rf) = rank(from) else {
            wrong.push(format!(
                "src/{from}/ is not a declared layer (add it to LAYERS)"
            ));
            continue;
        };
        for (to, file) in tos {
            match rank(to) {
                Some(rt) if rt < rf => {}
                Some(_) => wrong.push(format!(
                    "src/{file} ({from}) imports {to}, which is not below it"
                )),
                // `crate::X` where X is not a folder (a root item): fine.
                None => {}
            }
        }
    }
    assert!(wrong.is_empty(), "layering broken:\n{}", wrong.join("\n"));
}

/// What marks code that computes derived results rather than drawing them:
/// an evaluator of its own, a job, a result cache, a parallel numerical loop.
const COMPUTING: &[(&str, &str)] = &[
    (
        "Brdf for ",
        "implements Brdf (a derived evaluator belongs in derive/)",
    ),
    ("Steps<", "defines a job (jobs belong in derive/)"),
    ("Slots<", "keeps a result cache (derive/ keeps them)"),
    ("jobs::slots(", "keeps a result cache (derive/ keeps them)"),
    (
        "par_iter",
        "runs a parallel numerical loop (analyses belong in derive/)",
    ),
    (
        "par_chunks",
        "runs a parallel numerical loop (analyses belong in derive/)",
    ),
    (
        "rayon::",
        "runs a parallel numerical loop (analyses belong in derive/)",
    ),
];

/// The computing marks in `code` (comments removed), as messages.
fn computing_marks(code: &str) -> Vec<&'static str> {
    let code = without_comments(code);
    // `impl Brdf for X`, `impl bv_core::Brdf for X`, `impl<'a> Brdf for X`.
    let code = code.replace("bv_core::Brdf for ", "Brdf for ");
    COMPUTING
        .iter()
        .filter(|(mark, _)| {
            if *mark == "Brdf for " {
                code.match_indices(mark).any(|(k, _)| {
                    let before = code[..k].trim_end();
                    before.ends_with("impl") || before.ends_with('>')
                })
            } else {
                code.contains(mark)
            }
        })
        .map(|(_, why)| *why)
        .collect()
}

#[test]
fn the_computing_marks_are_recognised() {
    assert_eq!(
        computing_marks("struct S;\nimpl bv_core::Brdf for S { }"),
        ["implements Brdf (a derived evaluator belongs in derive/)"]
    );
    assert_eq!(computing_marks("impl<'a> Brdf for ShBrdf<'a> {}").len(), 1);
    assert!(computing_marks("impl Steps<u32> for Job {}")[0].contains("job"));
    assert!(computing_marks("let v: Vec<_> = x.par_iter().map(f).collect();")[0].contains("loop"));
    // Naming the trait, or a comment about one, is not computing.
    assert!(computing_marks("fn f(b: &dyn Brdf) {} // impl Brdf for X").is_empty());
}

/// Views, widgets and the window draw; what they show is computed in
/// `derive/` (issue 26): a view that implements `Brdf`, defines a job, keeps
/// a result cache or runs a parallel numerical loop fails here, tests
/// included (a test of an analysis belongs with the analysis).
#[test]
fn views_only_draw() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let mut hits = Vec::new();
    for folder in ["views", "widgets", "app", "export"] {
        let mut files = Vec::new();
        rust_files(&src.join(folder), &mut files);
        for f in files {
            for why in computing_marks(&std::fs::read_to_string(&f).unwrap()) {
                hits.push(format!(
                    "{}: {why}",
                    f.strip_prefix(&src).unwrap().display()
                ));
            }
        }
    }
    assert!(
        hits.is_empty(),
        "computing outside derive/:\n{}",
        hits.join("\n")
    );
}

/// `derive/` is shared by the window, figures, the command line and
/// scripts: it knows neither egui nor wgpu.
#[test]
fn derive_knows_no_gui_or_gpu() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src/derive");
    let mut files = Vec::new();
    rust_files(&src, &mut files);
    assert!(!files.is_empty());
    let mut hits = Vec::new();
    for f in files {
        let code = without_comments(&std::fs::read_to_string(&f).unwrap());
        for word in ["egui", "wgpu", "eframe"] {
            if code.contains(word) {
                hits.push(format!("{} names {word}", f.display()));
            }
        }
    }
    assert!(hits.is_empty(), "{}", hits.join("\n"));
}

#[test]
fn no_view_export_or_cli_code_names_a_model() {
    let src = Path::new(env!("CARGO_MANIFEST_DIR")).join("src");
    let ids: Vec<String> = bv_core::catalogue()
        .iter()
        .map(|m| format!("\"{}\"", m.id))
        .collect();
    let mut hits = Vec::new();
    for folder in [
        "views", "export", "cli", "widgets", "app", "session", "derive", "gpu",
    ] {
        let mut files = Vec::new();
        rust_files(&src.join(folder), &mut files);
        for f in files {
            let text = std::fs::read_to_string(&f).unwrap();
            // Tests may build whatever model they like.
            let code = text.split("#[cfg(test)]").next().unwrap_or("");
            let code = without_comments(code);
            for id in &ids {
                if code.contains(id.as_str()) {
                    hits.push(format!("{} names {id}", f.display()));
                }
            }
        }
    }
    assert!(
        hits.is_empty(),
        "model ids outside bv-core (declare the behaviour with the model instead):\n{}",
        hits.join("\n")
    );
}

/// The browser has no `std::time::Instant` (calling it panics there): code
/// that the web build runs takes its clock from `session::platform`. The
/// command line (desktop only) and the platform module itself may use std's.
#[test]
fn code_the_browser_runs_takes_its_clock_from_the_platform_module() {
    let mut files = Vec::new();
    rust_files(Path::new("src"), &mut files);
    let mut offenders = Vec::new();
    for f in files {
        let p = f.to_string_lossy().replace('\\', "/");
        if p.starts_with("src/cli/") || p == "src/session/platform.rs" {
            continue;
        }
        let code = without_comments(&std::fs::read_to_string(&f).unwrap());
        let std_instant = code.contains("std::time::Instant")
            || code.split("use std::time::{").skip(1).any(|rest| {
                rest.split('}')
                    .next()
                    .is_some_and(|l| l.contains("Instant"))
            });
        if std_instant {
            offenders.push(p);
        }
    }
    assert!(offenders.is_empty(), "std::time::Instant in {offenders:?}");
}

/// The files of `src/<folder>/` and the other files of the folder each one
/// names (`super::x`, `crate::<folder>::x`), comments and test modules left
/// out (a test's `use super::*` is its own file).
fn file_graph(folder: &str) -> BTreeMap<String, BTreeSet<String>> {
    let dir = Path::new(env!("CARGO_MANIFEST_DIR"))
        .join("src")
        .join(folder);
    let mut files = Vec::new();
    rust_files(&dir, &mut files);
    let stem = |p: &Path| p.file_stem().unwrap().to_string_lossy().to_string();
    let names: BTreeSet<String> = files.iter().map(|f| stem(f)).collect();
    let mut graph = BTreeMap::new();
    for f in &files {
        let text = std::fs::read_to_string(f).unwrap();
        let code = without_comments(text.split("#[cfg(test)]").next().unwrap_or(""));
        let mut to = BTreeSet::new();
        for prefix in ["super::".to_string(), format!("crate::{folder}::")] {
            for (k, _) in code.match_indices(&prefix) {
                let rest = &code[k + prefix.len()..];
                let mut heads = vec![head(rest)];
                if let Some(group) = rest.strip_prefix('{') {
                    heads = group
                        .split('}')
                        .next()
                        .unwrap_or("")
                        .split(',')
                        .map(head)
                        .collect();
                }
                for h in heads {
                    if names.contains(&h) && h != stem(f) {
                        to.insert(h);
                    }
                }
            }
        }
        graph.insert(stem(f), to);
    }
    graph
}

/// The cycles of a graph, each as the path that closes it.
fn cycles(graph: &BTreeMap<String, BTreeSet<String>>) -> Vec<String> {
    fn visit(
        n: &str,
        graph: &BTreeMap<String, BTreeSet<String>>,
        path: &mut Vec<String>,
        done: &mut BTreeSet<String>,
        out: &mut Vec<String>,
    ) {
        if let Some(k) = path.iter().position(|p| p == n) {
            out.push(format!("{} → {n}", path[k..].join(" → ")));
            return;
        }
        if done.contains(n) {
            return;
        }
        path.push(n.to_string());
        for m in graph.get(n).into_iter().flatten() {
            visit(m, graph, path, done, out);
        }
        path.pop();
        done.insert(n.to_string());
    }
    let mut out = Vec::new();
    let mut done = BTreeSet::new();
    for n in graph.keys() {
        visit(n, graph, &mut Vec::new(), &mut done, &mut out);
    }
    out
}

#[test]
fn the_cycle_finder_finds_cycles() {
    let g: BTreeMap<String, BTreeSet<String>> = [
        ("a", vec!["b"]),
        ("b", vec!["c"]),
        ("c", vec!["a"]),
        ("d", vec!["a"]),
    ]
    .into_iter()
    .map(|(k, v)| (k.to_string(), v.into_iter().map(String::from).collect()))
    .collect();
    assert_eq!(cycles(&g), ["a → b → c → a"]);
    let mut acyclic = g.clone();
    acyclic.get_mut("c").unwrap().clear();
    assert!(cycles(&acyclic).is_empty());
}

/// The session's files import one way too (issue 26: the state, user files,
/// commands and scene files were a 4-file cycle): a new cycle fails here.
#[test]
fn session_files_form_no_cycle() {
    let g = file_graph("session");
    assert!(g.contains_key("state") && !g["state"].is_empty(), "{g:?}");
    let c = cycles(&g);
    assert!(
        c.is_empty(),
        "file cycles in src/session/:\n{}",
        c.join("\n")
    );
}

/// The derive layer's files import one way.
#[test]
fn derive_files_form_no_cycle() {
    let c = cycles(&file_graph("derive"));
    assert!(
        c.is_empty(),
        "file cycles in src/derive/:\n{}",
        c.join("\n")
    );
}

/// The files of `tests/` that no test binary compiles: not a `mod` of
/// `tests/suite.rs` and not the `path` of a `[[test]]` in Cargo.toml (the
/// package sets `autotests = false`, so cargo would skip such a file
/// silently). `files` are the names of `tests/*.rs`.
fn tests_left_out(files: &[String], suite: &str, manifest: &str) -> Vec<String> {
    let suite = without_comments(suite);
    let mods: BTreeSet<&str> = suite
        .lines()
        .filter_map(|l| l.trim().strip_prefix("mod ")?.strip_suffix(';'))
        .map(str::trim)
        .collect();
    let targets: BTreeSet<&str> = manifest
        .lines()
        .filter_map(|l| {
            let (key, value) = l.split_once('=')?;
            (key.trim() == "path").then(|| value.trim().trim_matches('"'))
        })
        .filter_map(|p| p.strip_prefix("tests/")?.strip_suffix(".rs"))
        .collect();
    files
        .iter()
        .filter(|f| !mods.contains(f.as_str()) && !targets.contains(f.as_str()))
        .cloned()
        .collect()
}

#[test]
fn the_left_out_test_finder_finds_them() {
    let files: Vec<String> = ["suite", "a", "b", "c"].map(String::from).to_vec();
    let suite = "//! mod c;\nmod a;\n";
    let manifest = "[[test]]\nname = \"suite\"\npath = \"tests/suite.rs\"\n\
                    [[bin]]\npath = \"src/b.rs\"\n";
    assert_eq!(tests_left_out(&files, suite, manifest), ["b", "c"]);
    let manifest = format!("{manifest}[[test]]\nname = \"b\"\npath = \"tests/b.rs\"\n");
    assert_eq!(
        tests_left_out(&files, "mod a;\nmod c;\n", &manifest),
        Vec::<String>::new()
    );
}

#[test]
fn every_test_file_is_compiled() {
    let root = Path::new(env!("CARGO_MANIFEST_DIR"));
    let mut files: Vec<String> = std::fs::read_dir(root.join("tests"))
        .unwrap()
        .map(|e| e.unwrap().path())
        .filter(|p| p.is_file() && p.extension().is_some_and(|e| e == "rs"))
        .map(|p| p.file_stem().unwrap().to_string_lossy().into_owned())
        .collect();
    files.sort();
    assert!(files.len() > 10, "{files:?}");
    let suite = std::fs::read_to_string(root.join("tests/suite.rs")).unwrap();
    let manifest = std::fs::read_to_string(root.join("Cargo.toml")).unwrap();
    let left_out = tests_left_out(&files, &suite, &manifest);
    assert!(
        left_out.is_empty(),
        "tests/{{{}}}.rs: not a `mod` of tests/suite.rs nor a [[test]] in Cargo.toml, so no test binary compiles them",
        left_out.join(",")
    );
}
