//! The GPU side: every renderer of bv and the plumbing they share.
//!
//! - Renderers, each usable every frame by a GUI view and once by `bv render`:
//!   [`lit_sphere`] (spheres under one light), [`env`](mod@env) (progressive
//!   environment lighting), [`lobe`] (the 3D lobe view's meshes and lines),
//!   and [`eval`] (batch evaluation of f for the parity tests).
//! - Shaders: [`shaders`] composes `shaders/` with naga_oil, including the
//!   generated modules [`layout`] (parameter offsets from the declarations)
//!   and [`colormap`] (the lobe's colour map table); [`pack`] packs models'
//!   parameters and MERL tables into the buffers they read; [`specialised`]
//!   keeps a renderer's pipelines compiled per model and follows a changed
//!   catalogue by rebuilding only what changed.
//! - Plumbing, one of each: [`context`] (the headless device opener, limits,
//!   offscreen targets), [`readback`] (texture and buffer read-back),
//!   [`fullscreen`] (full-screen triangle pipelines and passes), [`errors`]
//!   (error scopes, size checks, the no-adapter message), [`pipeline_cache`]
//!   (the driver's pipeline cache kept on disk between runs).
//! - CPU data and references: [`envmap`] (environment maps and their
//!   sampling CDFs), [`display`] (tone map and sRGB), [`sphere`] (the lit
//!   sphere's geometry).
//!
//! bv-core stays free of wgpu: it only provides the layout and packer
//! ([`bv_core::params::gpu_layout`], [`bv_core::params::pack_model`]) and the
//! lobe meshes. Nothing here depends on the GUI (`views`, `app`).

pub mod colormap;
pub mod context;
pub mod dispatch;
pub mod display;
pub mod env;
pub mod envmap;
pub mod errors;
pub mod eval;
pub mod fullscreen;
pub mod layout;
pub mod lit_sphere;
pub mod lobe;
pub mod pack;
pub mod pipeline_cache;
pub mod plane;
pub mod readback;
pub mod shaders;
pub mod specialised;
pub mod sphere;

pub use context::{Gpu, Headless, Target, gpu_for_test};
pub use display::ToneMap;
pub use env::{EnvRenderer, EnvSettings};
pub use envmap::EnvironmentMap;
pub use eval::GpuEvaluator;
pub use lit_sphere::{Background, LitSphereRenderer, LitSphereSettings};
pub use lobe::LobeRenderer;
