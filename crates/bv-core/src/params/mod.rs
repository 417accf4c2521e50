//! Model parameters as data.
//!
//! - [`decl`]: the declarations every model makes once (kinds, ranges,
//!   defaults) — a leaf the model files import;
//! - [`value`]: validated values and [`ModelSpec`] (a model with its values);
//! - [`spec`]: parsing and validating values from JSON and command-line text;
//! - [`gpu`]: where each parameter sits in the shaders' flat buffer.

pub mod decl;
mod gpu;
pub mod spec;
pub mod value;

pub use decl::{Applies, ColorSpec, FloatSpec, ParamDecl, ParamKind};
pub use gpu::{
    COMPONENT_ENTRY_SLOTS, DerivedSlots, GpuLayout, GpuModelRef, GpuParam, GpuSlot, MAX_SLOTS,
    gpu_layout, gpu_model_index, pack_model, pack_model_with,
};
pub use spec::{check_value, cli_text_to_json, parse_value};
pub use value::{Component, ModelSpec, ParamValue, Params};

/// How deeply `mix` components may nest (a mix of mixes of …), so that a hostile
/// scene cannot overflow the stack.
pub const MAX_NESTING: usize = 4;
