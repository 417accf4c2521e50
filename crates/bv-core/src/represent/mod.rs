//! Representations of a BRDF (lecture: tabulated, basis functions, analytic).
//! The tabulated form lives in [`crate::measured`]; this module holds the
//! basis-function form: projection of a lobe onto spherical harmonics.

pub mod factor;
pub mod sh;
pub mod sh_table;

pub use sh::{Domain, ShLobe};
