//! One module per model of the catalogue (SPEC §2). Each declares `INFO`, its
//! id, parameter list and constructor; [`CATALOGUE`] lists them in the order
//! the CLI and the GUI present them.

use crate::registry::ModelInfo;

pub mod cook_torrance;
pub mod disney;
pub mod glass;
pub mod lambert;
pub mod mirror;

/// Every model, in presentation order.
pub static CATALOGUE: &[&ModelInfo] = &[
    &lambert::INFO,
    &cook_torrance::INFO,
    &mirror::INFO,
    &glass::INFO,
    &disney::INFO,
];
