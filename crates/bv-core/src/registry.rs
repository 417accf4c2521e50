//! The model catalogue: every model id with its parameter declaration and its
//! constructor (SPEC §2).

use crate::params::{ParamDecl, Params};
use crate::{Brdf, BvError, Result, models};

/// One model of the catalogue.
#[derive(Debug, Clone, Copy)]
pub struct ModelInfo {
    /// Stable id (`cook-torrance`).
    pub id: &'static str,
    /// Display name (`Cook-Torrance`).
    pub name: &'static str,
    /// One-line description.
    pub summary: &'static str,
    /// Where the formula comes from (paper, equation).
    pub citation: &'static str,
    /// The parameter declaration: the one source the CLI, scenes and GUI read.
    pub params: &'static [ParamDecl],
    /// Builds an evaluator from a complete, validated parameter set.
    pub build: fn(&Params) -> Result<Box<dyn Brdf>>,
}

impl ModelInfo {
    /// The declaration of parameter `id`, or an error listing the known ones.
    pub fn param(&self, id: &str) -> Result<&'static ParamDecl> {
        self.params
            .iter()
            .find(|d| d.id == id)
            .ok_or_else(|| BvError::UnknownParam {
                model: self.id.to_string(),
                param: id.to_string(),
                known: self
                    .params
                    .iter()
                    .map(|d| d.id)
                    .collect::<Vec<_>>()
                    .join(", "),
            })
    }
}

/// Every model, in catalogue order.
pub fn catalogue() -> &'static [&'static ModelInfo] {
    models::CATALOGUE
}

/// The model with id `id`.
pub fn find(id: &str) -> Result<&'static ModelInfo> {
    catalogue()
        .iter()
        .copied()
        .find(|m| m.id == id)
        .ok_or_else(|| BvError::UnknownModel {
            id: id.to_string(),
            known: catalogue()
                .iter()
                .map(|m| m.id)
                .collect::<Vec<_>>()
                .join(", "),
        })
}
