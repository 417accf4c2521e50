//! The integration tests of the application, as one binary: every file of
//! `tests/` is a module here unless it changes or reads what is
//! process-wide (the model catalogue, the user-file resolver, the
//! environment, the counts of computed results, its children's peak
//! memory), in which case it is its own `[[test]]` in Cargo.toml, with the
//! reason. `tests/layers.rs` checks that no file is left out of both. One
//! binary instead of one per file: each linked the whole of bv with wgpu
//! and egui.
//!
//! The modules share one process id, so each names its scratch folders
//! after itself (`bv-hostile-files-<pid>-…`), and a test that runs one of
//! its own as a child names it with its module path.
//!
//! Run one file's tests with `cargo test --test suite <file>::`.

// Test and benchmark code: a panic is how a failure is reported.
#![allow(clippy::unwrap_used, clippy::expect_used)]

// RGL test files shared by `gpu_env` and `gpu_parity` (and bv-core's
// `tests/rgl.rs`, which includes the file by path too).
#[path = "support/rgl_files.rs"]
mod rgl_files;

mod bad_input;
mod cli;
mod cli_scripts;
mod deck_lecture;
mod export_gui;
mod fit_cli;
mod fit_job;
mod glyphs;
mod gpu_env;
mod gpu_lit_sphere;
mod gpu_parity;
mod gpu_readback;
mod gpu_torus;
mod gui;
mod gui_factor;
mod gui_fit;
mod gui_lit;
mod gui_merl;
mod hostile_files;
mod layers;
mod merl_cli;
mod optics_views;
mod presentation;
mod presets_cli;
mod render;
mod render_bands;
mod render_deck;
mod render_sizes;
mod rgl_cli;
mod scene;
mod shader_validation;
mod simulate_cli;
mod whole_sphere;
