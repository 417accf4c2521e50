//! One module per model of the catalogue (SPEC §2). Each declares `INFO`, its
//! id, parameter list and constructor; [`CATALOGUE`] lists them in the order
//! the CLI and the GUI present them.

use crate::registry::ModelInfo;

pub mod ashikhmin_shirley;
pub mod hapke;
pub mod lambert;
pub mod mix;
pub mod oren_nayar;

#[cfg(test)]
pub(crate) mod testkit;

/// Every model, in presentation order.
pub static CATALOGUE: &[&ModelInfo] = &[
    &lambert::INFO,
    &ashikhmin_shirley::INFO,
    &oren_nayar::INFO,
    &hapke::INFO,
    &mix::INFO,
];
