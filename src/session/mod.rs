//! The session: everything the viewer knows that is not drawing. The state
//! that is saved between runs ([`state`], [`lighting`]), the commands that
//! change it ([`command`]), the evaluators built from it ([`runtime`]), the
//! background reads of file-backed models ([`loader`]), the scene file format
//! ([`scene_file`]) and lecture decks of scenes ([`deck`]), presentation
//! mode's sizes ([`presentation`]), user BRDF files ([`user_models`], their
//! hot reload [`reload`] and their names in saved state [`model_names`]), the
//! names of BRDFs ([`naming`]) and of views ([`views`]), the per-frame scene
//! every view reads ([`frame`]), what differs in a browser ([`platform`]),
//! the scene as a link ([`link`]) and writing to stdout and stderr without
//! panicking ([`console`]).
//!
//! Nothing here draws: no egui, no wgpu. The window (`app`), the views, the
//! figure export and the command line all build on this layer, and it imports
//! none of them.

pub mod command;
pub mod console;
pub mod deck;
pub mod frame;
pub mod lighting;
pub mod link;
pub mod loader;
pub mod model_names;
pub mod naming;
pub mod platform;
pub mod presentation;
pub mod reload;
pub mod runtime;
pub mod scene_file;
pub mod state;
pub mod user_models;
pub mod views;
pub mod workspace;

pub use command::Command;
pub use frame::{Scene, SceneBrdf, build_scene};
pub use state::AppState;
