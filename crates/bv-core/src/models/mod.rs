//! One module per built-in model. Each declares everything about its model in
//! one `INFO` ([`ModelInfo`]: id, parameters and aliases, constructor, GPU
//! port); [`BUILT_IN`] lists them in the order the CLI and the GUI present
//! them. Adding a model: its module here, its WGSL file under
//! `shaders/models/`, and one line in [`BUILT_IN`].

use crate::model::ModelInfo;

pub mod ashikhmin_shirley;
pub mod banks;
pub mod blinn_phong;
pub mod coated;
pub mod cook_torrance;
pub mod disney;
pub mod glass;
pub mod hapke;
pub mod lafortune;
pub mod lambert;
pub mod lobes;
pub mod merl;
pub mod mirror;
pub mod mix;
pub mod modified_phong;
pub mod oren_nayar;
pub mod phong;
pub mod rgl;
pub mod rough_dielectric;
pub mod ward;

#[cfg(test)]
pub(crate) mod testkit;

/// Every built-in model, in presentation order.
pub static BUILT_IN: &[&ModelInfo] = &[
    &lambert::INFO,
    &phong::INFO,
    &blinn_phong::INFO,
    &modified_phong::INFO,
    &ward::INFO,
    &lafortune::INFO,
    &banks::INFO,
    &cook_torrance::INFO,
    &ashikhmin_shirley::INFO,
    &oren_nayar::INFO,
    &hapke::INFO,
    &disney::INFO,
    &mirror::INFO,
    &glass::INFO,
    &rough_dielectric::INFO,
    &coated::INFO,
    &merl::INFO,
    &rgl::INFO,
    &mix::INFO,
];
