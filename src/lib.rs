//! The `bv` application over `bv-core`. Its folders are layers, each importing
//! only those below it (see `ARCHITECTURE.md`):
//!
//! - [`session`]: the state, commands, evaluators, scene files, per-frame scene
//!   (no drawing);
//! - [`derive`]: derived results (albedo, properties, projections,
//!   histograms), computed once per process, cached, cancellable;
//! - [`gpu`]: the wgpu renderers and shaders (bv-core only);
//! - [`widgets`]: egui widgets shared by the panel and the views;
//! - [`views`]: the views, each drawing one [`session::Scene`];
//! - [`export`]: figures (PNG, SVG, meshes) drawn offscreen;
//! - [`cli`]: the command line;
//! - [`app`]: the eframe window, on top of everything.

pub mod app;
pub mod cli;
pub mod derive;
pub mod export;
pub mod gpu;
pub mod session;
pub mod views;
pub mod widgets;
