//! Measured BRDF data: the MERL half/difference-angle tables of
//! Matusik et al. 2003, "A Data-Driven Reflectance Model" . `bv info`
//! estimates ρhd and reciprocity of a table with [`crate::analysis`].

pub mod merl;

pub use merl::{Interpolation, MerlDims, MerlTable, MerlWarnings};
