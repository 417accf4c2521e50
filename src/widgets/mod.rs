//! egui widgets shared by the window's panel and the views: file dialogs
//! ([`files`]) and the parameter editors generated from a model's declaration
//! ([`params_ui`]).

pub mod files;
pub mod params_ui;
