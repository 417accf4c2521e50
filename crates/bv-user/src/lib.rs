//! # bv-user
//!
//! User BRDF files (`.brdf`, Disney's BRDF Explorer format, and bv's native
//! variant with a `wgsl` section) as first-class bv models: the front end
//! ([`front`]: GLSL or WGSL in a generated prelude, to a validated naga
//! module), the GPU port ([`port`]: WGSL out, wrapped as a bv shader module),
//! the CPU evaluator ([`cpu`]), safety limits ([`safety`]), catalogue
//! registration and the by-path resolver ([`catalogue`]), hot reload
//! ([`watch`]) and a file's own importance sampler ([`sampler`]).
//!
//! The container itself (sections, parameter lines) is parsed by
//! `bv_core::user::brdf_file`; bv-core stays free of naga.

pub mod bounds;
pub mod catalogue;
pub mod compile;
pub mod cpu;
pub mod error;
pub mod front;
pub mod port;
pub mod safety;
pub mod sampler;
pub mod source_map;
pub mod watch;

pub use catalogue::{install, is_file_name, load, model_id, open, path_of};
pub use compile::{Compiled, compile};
pub use error::{Place, Result, UserError};
