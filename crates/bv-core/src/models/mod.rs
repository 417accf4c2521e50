//! One module per model of the catalogue (SPEC §2). Each declares `INFO`, its
//! id, parameter list and constructor; [`CATALOGUE`] lists them in the order
//! the CLI and the GUI present them.

use crate::registry::ModelInfo;

pub mod lambert;
pub mod merl;

/// Every model, in presentation order.
pub static CATALOGUE: &[&ModelInfo] = &[&lambert::INFO, &merl::INFO];
