//! Measured BRDF data: the MERL half/difference-angle tables of
//! Matusik et al. 2003, "A Data-Driven Reflectance Model", and the RGL
//! materials of Dupuy & Jakob 2018 (`.bsdf` tensor files: [`tensor`],
//! [`marginal`], [`rgl`]). `bv info`
//! estimates ρhd and reciprocity of a table with [`crate::analysis`].

pub mod marginal;
pub mod merl;
pub mod rgl;
pub mod rgl_write;
pub mod tensor;

pub use merl::{Interpolation, MerlDims, MerlTable, MerlWarnings};
