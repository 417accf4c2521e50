//! One module per model of the catalogue (SPEC §2). Each declares `INFO`, its
//! id, parameter list and constructor; [`CATALOGUE`] lists them in the order
//! the CLI and the GUI present them.

use crate::registry::ModelInfo;

pub mod banks;
pub mod blinn_phong;
pub mod lafortune;
pub mod lambert;
pub mod lobes;
pub mod modified_phong;
pub mod phong;
pub mod ward;

/// Every model, in presentation order.
pub static CATALOGUE: &[&ModelInfo] = &[
    &lambert::INFO,
    &phong::INFO,
    &blinn_phong::INFO,
    &modified_phong::INFO,
    &ward::INFO,
    &lafortune::INFO,
    &banks::INFO,
];
