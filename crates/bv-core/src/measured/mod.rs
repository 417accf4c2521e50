//! Measured BRDF data (issue 5): the MERL half/difference-angle tables of
//! Matusik et al. 2003, "A Data-Driven Reflectance Model" (SPEC §4). `bv info`
//! estimates ρhd and reciprocity of a table with [`crate::analysis`].

pub mod merl;

pub use merl::{Interpolation, MerlDims, MerlTable, MerlWarnings};
