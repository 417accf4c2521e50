//! The GPU side (issue 4): WGSL ports of bv-core's models composed from
//! `shaders/`, their parameter layout generated from the declarations, and
//! offscreen renderers (lit sphere, environment lighting) that a GUI view can
//! call every frame and `bv render` once.
//!
//! bv-core stays free of wgpu: it only provides the layout and packer
//! ([`bv_core::params::gpu_layout`], [`bv_core::params::pack_model`]).

pub mod context;
pub mod dispatch;
pub mod display;
pub mod env;
pub mod errors;
pub mod eval;
pub mod layout;
pub mod lit_sphere;
pub mod pack;
pub mod shaders;
pub mod sphere;

pub use context::{Gpu, Target, gpu_for_test};
pub use display::ToneMap;
pub use env::{EnvRenderer, EnvSettings, EnvironmentMap};
pub use eval::GpuEvaluator;
pub use lit_sphere::{Background, LitSphereRenderer, LitSphereSettings};
